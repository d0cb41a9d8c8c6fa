//! `chain positioning --format json` (spec `positioning.md`): the run file
//! from a path or as its text, read and evaluated by the library the CLI
//! uses; refusals are the CLI's messages (`MachineError`, located).

use chain::ops::positioning as ops;
use chain::ops::source as ops_source;
use chain_core::measured::positioning::Coverage;
use pyo3::prelude::*;

use crate::{load_error, source, to_json, value_error, Model};

/// The run's temperatures as Python passes them: axis, its expansion,
/// then the optional instrument temperature and expansion and the two
/// uncertainties.
type Temperatures = (f64, f64, Option<f64>, Option<f64>, Option<f64>, Option<f64>);

/// The positioning document of the runs at `path`, or of `text` named
/// `file`; `k` the coverage factor, `rotary` as `--rotary`. With `model`
/// and `slot` (`--machine`, `--slot`), also the values file `--values-out`
/// writes.
#[pyfunction]
#[pyo3(signature = (path, text, file, k, rotary, model, slot, temperatures=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn positioning_json(
    py: Python<'_>,
    path: Option<&str>,
    text: Option<&str>,
    file: &str,
    k: f64,
    rotary: bool,
    model: Option<&Model>,
    slot: Option<&str>,
    temperatures: Option<Temperatures>,
) -> PyResult<(String, Option<String>)> {
    let k = Coverage::new(k).map_err(|e| value_error(e.to_string()))?;
    let kind = ops::axis_kind(rotary);
    let source = source(path, text, file)?;
    let runs = py
        .allow_threads(|| ops_source::read_runs(source, kind))
        .map_err(|e| load_error(py, e.diagnostics()))?;
    let runs_file = source.name();
    let values_out = match (model, slot) {
        (Some(model), Some(slot)) => Some(ops::ValuesOut {
            machine: &model.machine,
            machine_file: &model.file,
            slot,
            runs_file: &runs_file,
        }),
        (None, None) => None,
        _ => return Err(value_error("give machine and slot together")),
    };
    let done = ops::run(&ops::PositioningRequest {
        runs: &runs,
        k,
        values_out,
        temperatures: temperatures.map(|t| ops::temperatures(t.0, t.1, t.2, t.3, t.4, t.5)),
    })
    .map_err(|e| value_error(e.to_string()))?;
    let (doc, values) = (done.document, done.values_text);
    Ok((to_json(&doc)?, values))
}
