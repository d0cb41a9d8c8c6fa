//! The allocation binding (issue 16): `chain allocate` with every option.
//!
//! Returns the library's [`AllocationDocument`] as JSON text, the document
//! the CLI prints with `--format json` for the same input, computed by
//! [`document::allocation`], the function the CLI calls.

use pyo3::prelude::*;
use reliability::allocate::{self, AcceptanceStrategy, AllocateError, Paper};
use reliability::document::{self, AllocationDocument};

use crate::{study_error, to_json, value_error, Model};

/// `chain allocate --format json`: `strategy` `optimal` (least cost, with
/// the KKT check) or `paper` (Wang & Yuan 2021's rounds: `step` in Table
/// 1's tolerance units, `threshold` a fraction of the largest sensitivity,
/// `rank` `component` or `pooled`), for the reliability section's
/// requirement or, with `level`, the whole-machine acceptance probability.
/// An allocation that does not meet its target is returned (its
/// `final.met` is false; the CLI exits non-zero after printing it).
#[pyfunction]
#[pyo3(signature = (model, strategy, step, threshold, rank, level, params, sided))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn allocate_json(
    py: Python<'_>,
    model: &Model,
    strategy: &str,
    step: f64,
    threshold: f64,
    rank: &str,
    level: Option<f64>,
    params: Vec<(String, f64)>,
    sided: Option<&str>,
) -> PyResult<String> {
    let pooled = match rank {
        "component" => false,
        "pooled" => true,
        other => {
            return Err(value_error(format!(
                "invalid value {other:?} for `rank` [possible values: component, pooled]"
            )))
        }
    };
    let paper = Paper {
        step,
        threshold,
        pooled,
        ..Paper::default()
    };
    let strategy = match strategy {
        "optimal" => AcceptanceStrategy::Optimal,
        "paper" => AcceptanceStrategy::Paper(paper),
        other => {
            return Err(value_error(format!(
                "invalid value {other:?} for `strategy` [possible values: optimal, paper]"
            )))
        }
    };
    if let Some(l) = level.filter(|l| !(*l > 0.0 && *l < 1.0)) {
        return Err(value_error(format!(
            "invalid value for `level`: {l} (an acceptance probability strictly between 0 and 1)"
        )));
    }
    let study = model.study(py, &[], &params, sided)?;
    let values = model.parameter_vector(py, &params)?;
    let m = &model.machine;
    let bounds = allocate::bounds(m, &study).map_err(|e| study_error(py, &e, &model.file))?;
    let result = py
        .allow_threads(|| {
            document::allocation(&model.model, &values, &study, &bounds, strategy, level)
        })
        .map_err(|e| match e {
            AllocateError::Reliability(e) => study_error(py, &e, &model.file),
            e => value_error(format!("{}: {e}", m.name)),
        })?;
    to_json(&AllocationDocument::new(
        &m.name,
        study.spec().requirement,
        &bounds,
        &result,
    ))
}
