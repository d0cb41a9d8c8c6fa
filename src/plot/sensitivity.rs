//! `--plot DIR` of `chain sensitivity`: the reliability sensitivities' bar
//! charts ([`super::reliability::sensitivity_charts`], those of `chain
//! reliability --plot`) or the geometric coefficients'
//! ([`super::geometric::charts`]).

use super::Figures;
use crate::ops::sensitivity::SensitivityReport;

/// The charts of either kind of sensitivity document.
pub fn charts(doc: &SensitivityReport) -> Figures {
    match doc {
        SensitivityReport::Reliability(r) => super::reliability::sensitivity_charts(r),
        SensitivityReport::Geometric(g) => super::geometric::charts(g),
    }
}
