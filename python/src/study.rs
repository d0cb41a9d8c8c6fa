//! The study commands' bindings: `chain reliability` with every option of
//! the command line (methods form, is, mc, sorm, subset, directional;
//! `cov`; `system`; `values`; `acceptance`) and `chain sobol`, and the
//! study options `chain path` and `chain sensitivity` share with them
//! (method, samples, seed and target; system; approach).
//!
//! Each returns the document the CLI prints with `--format json` for the
//! same input: `chain reliability`'s through `chain::ops::reliability` (the
//! CLI's request, checks and run), [`SobolDocument`] through the library
//! functions the CLI calls. Every option is checked before any work and
//! refused with the CLI's wording.

use std::path::Path;

use chain::ops::reliability::{self as ops_reliability, ReliabilityOpsError, ReliabilityRequest};
use chain::ops::sobol::{self, SobolOpsError, SobolRequest};
use chain::ops::study::{AlgorithmOptions, SystemChoice, SystemKind};
use chain_core::values::Approach;
use pyo3::prelude::*;
use reliability::Method;

use crate::{
    choice, resolve_error, sided_named, study_error, study_failure, to_json, value_error, Model,
};

/// `method`, `samples`, `seed` and `cov` as the CLI's `--method`,
/// `--samples`, `--seed` and `--cov`, checked by the same rule
/// ([`AlgorithmOptions::check`]).
pub(crate) fn algorithm_options(
    method: &str,
    samples: Option<u64>,
    seed: u64,
    cov: Option<f64>,
) -> PyResult<AlgorithmOptions> {
    let options = AlgorithmOptions {
        method: choice::<Method>(method)?,
        samples,
        seed,
        cov,
    };
    options.check().map_err(|e| value_error(e.to_string()))?;
    Ok(options)
}

/// `system` (`series` or `volumetric`) and `system_tolerance` (the
/// volumetric target's allowable error) as the CLI's `--system` and
/// `--system-tolerance`.
pub(crate) fn system_choice(
    system: Option<&str>,
    tolerance: Option<f64>,
) -> PyResult<Option<SystemChoice>> {
    let kind = system.map(choice::<SystemKind>).transpose()?;
    SystemChoice::new(kind, tolerance).map_err(|e| value_error(e.to_string()))
}

/// `approach` (`up`, `down`, `mean` or `x=up,...`) as `--approach` parses it.
pub(crate) fn parse_approach(approach: Option<&str>) -> PyResult<Vec<(Option<String>, Approach)>> {
    match approach {
        Some(text) => chain_core::values::parse_approaches(text)
            .map_err(|e| value_error(format!("approach: {e}"))),
        None => Ok(Vec::new()),
    }
}

/// `chain reliability --format json` with every option (`None`: the
/// option not given; the defaults are the CLI's).
///
/// `method`: `form`, `is`, `mc`, `subset`, `directional` or `sorm`;
/// `samples` per case (for subset per level); `cov` the target coefficient
/// of variation in (0, 1] (samples then the budget); `system`: `series` or
/// `volumetric` (`system_tolerance`: its allowable error); `values`: a
/// values file with a calibration's posterior; `acceptance`: also the
/// whole-machine acceptance probability (also when the file asks for it),
/// to `acceptance_tolerance`.
#[pyfunction]
#[pyo3(signature = (model, method, samples, seed, cov, grid, params, sided, system, system_tolerance, values, acceptance, acceptance_tolerance, approach, temperatures))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn reliability_json(
    py: Python<'_>,
    model: &Model,
    method: &str,
    samples: Option<u64>,
    seed: u64,
    cov: Option<f64>,
    grid: Vec<(String, Vec<f64>)>,
    params: Vec<(String, f64)>,
    sided: Option<&str>,
    system: Option<&str>,
    system_tolerance: Option<f64>,
    values: Option<&str>,
    acceptance: bool,
    acceptance_tolerance: f64,
    approach: Option<&str>,
    temperatures: Vec<(String, f64)>,
) -> PyResult<String> {
    let algorithm = algorithm_options(method, samples, seed, cov)?;
    let system = system_choice(system, system_tolerance)?;
    let sided = sided_named(sided)?;
    let approach = parse_approach(approach)?;
    let request = ReliabilityRequest {
        params: &params,
        grid: &grid,
        sided,
        system,
        algorithm,
        values: values.map(Path::new),
        approach: &approach,
        acceptance,
        acceptance_tolerance,
        temperatures: &temperatures,
    };
    let run = py
        .allow_threads(|| ops_reliability::run(&model.machine, &model.file, &request, &()))
        .map_err(|e| match e {
            ReliabilityOpsError::Option(e) => value_error(e.to_string()),
            ReliabilityOpsError::Study(e) => study_failure(py, model, *e),
            ReliabilityOpsError::Reliability(e) => study_error(py, &e, &model.file),
        })?;
    to_json(&run)
}

/// `chain sobol --format json`: first-order and total Sobol indices
/// (Saltelli 2010 Table 2 (b), (f)) at the point `at` (every axis
/// variable), or pooled over the reliability grid (`grid` replacing axes;
/// not with `at`).
#[pyfunction]
#[pyo3(signature = (model, at, samples, seed, bootstrap, confidence, grid, params))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn sobol_json(
    py: Python<'_>,
    model: &Model,
    at: Option<Vec<(String, f64)>>,
    samples: u64,
    seed: u64,
    bootstrap: u64,
    confidence: f64,
    grid: Vec<(String, Vec<f64>)>,
    params: Vec<(String, f64)>,
) -> PyResult<String> {
    let request = SobolRequest {
        at: at.as_deref(),
        samples,
        seed,
        bootstrap,
        confidence,
        grid: &grid,
        params: &params,
    };
    let run = py
        .allow_threads(|| sobol::run(&model.machine, &model.file, &request))
        .map_err(|e| match e {
            SobolOpsError::Study(e) => study_failure(py, model, *e),
            SobolOpsError::Reliability(e) => study_error(py, &e, &model.file),
            SobolOpsError::Resolve(e) => resolve_error(py, model, e),
            e => value_error(e.to_string()),
        })?;
    to_json(&run)
}
