//! `chain positioning --format json` (spec `positioning.md`): the run file
//! from a path or as its text, read and evaluated by the library the CLI
//! uses; refusals are the CLI's messages (`MachineError`, located).

use std::path::Path;

use chain_core::measured::positioning::{self, AxisKind, Coverage, Runs};
use chain_core::measured::positioning_values;
use pyo3::prelude::*;

use crate::{load_error, to_json, value_error, Model};

/// The positioning document of the runs at `path`, or of `text` named
/// `file`; `k` the coverage factor, `rotary` as `--rotary`. With `model`
/// and `slot` (`--machine`, `--slot`), also the values file `--values-out`
/// writes.
#[pyfunction]
#[pyo3(signature = (path, text, file, k, rotary, model, slot))]
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
) -> PyResult<(String, Option<String>)> {
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
    let doc = positioning::evaluate(&runs, k);
    let values = match (model, slot) {
        (Some(model), Some(name)) => {
            let m = &model.machine;
            let slot = positioning_values::slot(m, name, kind)
                .map_err(|e| value_error(format!("slot `{name}` (machine {}): {e}", model.file)))?;
            Some(positioning_values::values_file(
                &doc,
                m,
                &slot,
                path.unwrap_or(file),
            ))
        }
        (None, None) => None,
        _ => return Err(value_error("give machine and slot together")),
    };
    Ok((to_json(&doc)?, values))
}
