//! `chain motion` over a settings file or dict, through `chain::ops::motion`
//! (the CLI's request, checks and document): the document as JSON text and
//! the exact motion (the instants and the CNC axes at each, the CLI's
//! `--format csv`).

use chain::ops::motion::{self, MotionOpsError, MotionRequest};
use chain::ops::source as ops_source;
use chain::ops::Worded;
use chain_core::settings::ReferenceError;
use pyo3::prelude::*;

use crate::{load_error, resolve_error, source, to_json, value_error, Model};

/// The motion conversion of the settings (a file `path`, or the text
/// `text` named `file`, whose relative paths are resolved against the
/// working directory) onto the CNC machine `model`; the options are the
/// CLI's. Returns the document, the instants and the exact axes (row-major,
/// one row of the machine's variables per instant).
#[pyfunction]
#[pyo3(signature = (model, path, text, file, order, max_order, samples, tolerance, angular_tolerance, params, fix))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn motion_json(
    py: Python<'_>,
    model: &Model,
    path: Option<&str>,
    text: Option<&str>,
    file: &str,
    order: usize,
    max_order: usize,
    samples: usize,
    tolerance: Option<f64>,
    angular_tolerance: Option<f64>,
    params: Vec<(String, f64)>,
    fix: Vec<(String, f64)>,
) -> PyResult<(String, Vec<f64>, Vec<f64>)> {
    let request = MotionRequest {
        order,
        max_order,
        samples,
        tolerance,
        angular_tolerance,
        params: &params,
        fix: &fix,
    };
    let refused = |e: MotionOpsError| match e {
        MotionOpsError::Settings(d)
        | MotionOpsError::Generator(ReferenceError::Path(d) | ReferenceError::Machine(d)) => {
            load_error(py, &d)
        }
        MotionOpsError::Resolve(e) => resolve_error(py, model, e),
        e => value_error(e.with_help()),
    };
    motion::check(&request).map_err(refused)?;
    let source = source(path, text, file)?;
    let settings = py
        .allow_threads(|| ops_source::read_settings(source))
        .map_err(|d| load_error(py, &d))?;
    let doc = py
        .allow_threads(|| motion::run(&model.machine, settings, &request))
        .map_err(refused)?;
    let run = &doc.conversion;
    let exact = run.exact.iter().flatten().copied().collect();
    Ok((to_json(&doc)?, run.times.clone(), exact))
}
