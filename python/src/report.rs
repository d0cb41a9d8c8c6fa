//! `chain report` (docs/report.md): the calibration file at `path` run by
//! the library the CLI uses; the page and the report's JSON. A refusal is
//! the CLI's message: located problems of the calibration file or of a file
//! it names as `MachineError`, the others as `ValueError`.

use chain::ops::identify::IdentifyOpsError;
use chain::ops::Worded;
use chain::report::{self, Calibration, ReportError};
use pyo3::prelude::*;

use crate::{load_error, to_json, value_error};

/// The HTML page and the JSON of `chain report` of the calibration file at
/// `path`.
#[pyfunction]
pub(crate) fn report_html(py: Python<'_>, path: &str) -> PyResult<(String, String)> {
    let file = std::path::Path::new(path);
    let done = py.allow_threads(|| {
        let calibration = Calibration::read(file)?;
        report::run(&calibration, file)
    });
    let done = done.map_err(|e| match e {
        ReportError::Calibration(e) => load_error(py, &e.0),
        ReportError::File(d) => load_error(py, &d),
        ReportError::Runs(e) => load_error(py, &e.0),
        ReportError::Values(e) => load_error(py, e.diagnostics()),
        ReportError::CircularFile(e) => load_error(py, e.diagnostics()),
        ReportError::DriftFile(e) => load_error(py, &e.0),
        ReportError::Identify(e) => match *e {
            IdentifyOpsError::Measurements(m) => load_error(py, m.diagnostics()),
            e => value_error(e.with_help()),
        },
        ReportError::Map(e) => value_error(e.with_help()),
        ReportError::Export(e) => value_error(e.with_help()),
        ReportError::Circular(e) => value_error(e.with_help()),
        ReportError::Thermal(e) => value_error(e.with_help()),
        e => value_error(e.to_string()),
    })?;
    Ok((report::html(&done), to_json(&done)?))
}
