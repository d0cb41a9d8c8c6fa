//! The page of `chain report` ([`chain::report::Report`]): its "table" form
//! is the HTML page the library renders ([`chain::report::html`]).

use chain::report::Report as CalibrationReport;

use crate::cli::report::Report;

impl Report for CalibrationReport {
    fn table(&self) -> String {
        chain::report::html(self)
    }
}
