//! The allocation binding: `chain allocate` with every option, through
//! `chain::ops::allocate` (the CLI's request, checks and document).

use chain::ops::allocate::{self, AllocateOpsError, AllocateRequest, AllocationTarget};
use chain::ops::choice::Rank;
use chain::ops::Worded;
use pyo3::prelude::*;
use reliability::allocate::StrategyName;

use crate::{
    choice, machine_error, resolve_error, sided_named, study_error, study_failure, to_json,
    value_error, Model,
};

/// `chain allocate --format json`: `strategy` `optimal` (least cost, with
/// the KKT check) or `paper` (Wang & Yuan 2021's rounds: `step` in Table
/// 1's tolerance units, `threshold` a fraction of the largest sensitivity,
/// `rank` `component` or `pooled`), for `target` `requirement` (the
/// reliability section's) or `acceptance` (the whole-machine acceptance
/// probability reaching `level`). An allocation that does not meet its
/// target is returned (its `final.met` is false; the CLI exits non-zero
/// after printing it); one that cannot go on raises the CLI's message, a
/// `MachineError` at the statistics entry it names when there is one.
#[pyfunction]
#[pyo3(signature = (model, strategy, step, threshold, rank, target, level, params, sided))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn allocate_json(
    py: Python<'_>,
    model: &Model,
    strategy: &str,
    step: f64,
    threshold: f64,
    rank: &str,
    target: &str,
    level: Option<f64>,
    params: Vec<(String, f64)>,
    sided: Option<&str>,
) -> PyResult<String> {
    let request = AllocateRequest {
        strategy: choice::<StrategyName>(strategy)?,
        step,
        threshold,
        pooled: choice::<Rank>(rank)?.pooled(),
        target: choice::<AllocationTarget>(target)?,
        level,
        params: &params,
        sided: sided_named(sided)?,
    };
    let run = py
        .allow_threads(|| allocate::run(&model.machine, &model.file, &request))
        .map_err(|e| match e {
            AllocateOpsError::Study(e) => study_failure(py, model, *e),
            AllocateOpsError::Reliability(e) => study_error(py, &e, &model.file),
            AllocateOpsError::Resolve(e) => resolve_error(py, model, e),
            e => match e.location() {
                Some((origin, _)) => machine_error(
                    py,
                    e.with_help(),
                    &model.file,
                    Some(origin),
                    vec![e.to_string()],
                ),
                None => value_error(e.with_help()),
            },
        })?;
    to_json(&run)
}
