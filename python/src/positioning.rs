//! `chain positioning --format json` (spec `positioning.md`): the run file
//! from a path or as its text, read and evaluated by the library the CLI
//! uses; refusals are the CLI's messages (`MachineError`, located).

use std::path::Path;

use chain_core::measured::positioning::{self, AxisKind, Coverage, Runs};
use pyo3::prelude::*;

use crate::{load_error, to_json, value_error};

/// The positioning document of the runs at `path`, or of `text` named
/// `file`; `k` the coverage factor, `rotary` as `--rotary`.
#[pyfunction]
#[pyo3(signature = (path, text, file, k, rotary))]
pub(crate) fn positioning_json(
    py: Python<'_>,
    path: Option<&str>,
    text: Option<&str>,
    file: &str,
    k: f64,
    rotary: bool,
) -> PyResult<String> {
    let k = Coverage::new(k).map_err(|e| value_error(e.to_string()))?;
    let kind = if rotary {
        AxisKind::Rotary
    } else {
        AxisKind::Linear
    };
    let runs = match (path, text) {
        (Some(path), None) => Runs::read(Path::new(path), kind),
        (None, Some(text)) => Runs::parse(text, file, kind),
        _ => {
            return Err(value_error(
                "give the runs as a path or as their text, not both",
            ))
        }
    }
    .map_err(|e| load_error(py, e.diagnostics()))?;
    to_json(&positioning::evaluate(&runs, k))
}
