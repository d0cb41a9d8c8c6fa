//! The sensitivity bindings: `chain sensitivity --kind reliability` and
//! `--kind geometric`, through `chain::ops::sensitivity` (the CLI's
//! request, checks and document), as JSON text.

use std::path::Path;

use chain::ops::sensitivity::{
    self, SensitivityKind, SensitivityOpsError, SensitivityRequest, SensitivityValues,
};
use chain::ops::Worded;
use chain_core::geometric::NominalSizes;
use pyo3::prelude::*;

use crate::study::parse_approach;
use crate::{resolve_error, sided_named, study_error, study_failure, to_json, value_error, Model};

/// Runs the request and returns its document's JSON.
fn run(py: Python<'_>, model: &Model, request: &SensitivityRequest<'_>) -> PyResult<String> {
    let doc = py
        .allow_threads(|| sensitivity::run(&model.machine, &model.file, request))
        .map_err(|e| match e {
            SensitivityOpsError::Study(e) => study_failure(py, model, *e),
            SensitivityOpsError::Reliability(e) => study_error(py, &e, &model.file),
            SensitivityOpsError::Resolve(e) => resolve_error(py, model, e),
            e => value_error(e.with_help()),
        })?;
    to_json(&doc)
}

/// `chain sensitivity --kind reliability --format json`: the reliability
/// sensitivity of each component to every error's mean and standard
/// deviation (Eq. 32-33) with its FORM importance factor, at the point
/// `at` (every axis variable) or, without it, the mean over the
/// reliability grid (`grid` replacing axes). `values`: a values file with
/// a calibration's posterior (`--values`), its tables read for `approach`.
#[pyfunction]
#[pyo3(signature = (model, at, grid, params, sided, values, approach, temperatures))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn sensitivity_reliability_json(
    py: Python<'_>,
    model: &Model,
    at: Option<Vec<(String, f64)>>,
    grid: Vec<(String, Vec<f64>)>,
    params: Vec<(String, f64)>,
    sided: Option<&str>,
    values: Option<&str>,
    approach: Option<&str>,
    temperatures: Vec<(String, f64)>,
) -> PyResult<String> {
    let approach = parse_approach(approach)?;
    let request = SensitivityRequest {
        kind: SensitivityKind::Reliability,
        at: at.as_deref(),
        params: &params,
        sided: sided_named(sided)?,
        grid: &grid,
        values: values.map(|v| SensitivityValues::File(Path::new(v))),
        approach: &approach,
        temperatures: &temperatures,
    };
    run(py, model, &request)
}

/// `chain sensitivity --kind geometric --format json`: the geometric error
/// sensitivity coefficients `S = |∂E/∂e|`, `C = S·e / ΣS·e` (Fan et al.
/// 2020 Eq. 5-6) at the point `at` (every axis variable) or averaged over
/// the reliability grid (`grid` replacing or adding axes; not with `at`).
/// `sizes`: the nominal error sizes as `--values` spells them
/// (`linear=0.001,angular=0.001deg[,squareness=…]`; `None`: the paper's).
#[pyfunction]
#[pyo3(signature = (model, at, grid, params, sizes))]
pub(crate) fn geometric_json(
    py: Python<'_>,
    model: &Model,
    at: Option<Vec<(String, f64)>>,
    grid: Vec<(String, Vec<f64>)>,
    params: Vec<(String, f64)>,
    sizes: Option<&str>,
) -> PyResult<String> {
    let nominal = match sizes {
        None => None,
        Some(text) => Some(
            NominalSizes::default()
                .parse(text)
                .map_err(|e| value_error(format!("invalid value {text:?} for `sizes`: {e}")))?,
        ),
    };
    let request = SensitivityRequest {
        kind: SensitivityKind::Geometric,
        at: at.as_deref(),
        params: &params,
        sided: None,
        grid: &grid,
        values: nominal.map(SensitivityValues::Nominal),
        approach: &[],
        temperatures: &[],
    };
    run(py, model, &request)
}
