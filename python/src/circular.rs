//! `chain circular --format json` (spec `circular.md`): the circular-test
//! file from a path or as its text, read and evaluated by the library the
//! CLI uses; refusals are the CLI's messages (`MachineError`, located, or
//! `ValueError` with the CLI's words for the options).

use chain::ops::circular as ops;
use chain::ops::source::read_circular;
use chain::ops::Worded;
use pyo3::prelude::*;

use crate::{load_error, source, to_json, value_error};

/// `chain circular` of the file at `path`, or of `text` named `file`, with
/// the CLI's `--radius`, `--feed`, `--plane`, `--arc`, `--pitch` (pairs of
/// axis and mm) and `--window`: its JSON.
#[pyfunction]
#[pyo3(signature = (path, text, file, radius=None, feed=None, plane=None, arc=None, pitch=Vec::new(), window=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn circular_json(
    py: Python<'_>,
    path: Option<&str>,
    text: Option<&str>,
    file: &str,
    radius: Option<f64>,
    feed: Option<f64>,
    plane: Option<&str>,
    arc: Option<f64>,
    pitch: Vec<(String, f64)>,
    window: Option<f64>,
) -> PyResult<String> {
    let options = ops::options(radius, feed, plane, arc).map_err(|e| value_error(e.with_help()))?;
    let diagnosis =
        ops::diagnosis_options(&pitch, window).map_err(|e| value_error(e.with_help()))?;
    let source = source(path, text, file)?;
    let test = py
        .allow_threads(|| read_circular(source, &options))
        .map_err(|e| load_error(py, e.diagnostics()))?;
    to_json(&ops::run(&test, &diagnosis))
}
