//! The sensitivity bindings (issue 16): `chain sensitivity --kind
//! reliability` and `--kind geometric`.
//!
//! Each returns the library's document as JSON text, the document the CLI
//! prints with `--format json` for the same input, built by the functions
//! the CLI calls: [`document::sensitivity`] and [`SensitivityDocument`],
//! [`geometric::grid_axes`], [`geometric::evaluate`] and
//! [`GeometricDocument`].

use chain_core::geometric::{self, GeometricDocument, GridAxisError, NominalSizes, Where};
use pyo3::prelude::*;
use reliability::document::{self, SensitivityDocument};
use reliability::{Form, ReliabilityError};

use crate::reliability_v2::{read_posterior, resolve_at};
use crate::{study_error, to_json, value_error, Model};

/// `chain sensitivity --kind reliability --format json`: the reliability
/// sensitivity of each component to every error's mean and standard
/// deviation (Eq. 32-33) with its FORM importance factor, at the point
/// `at` (every axis variable) or, without it, the mean over the
/// reliability grid (`grid` replacing axes). `values`: a values file with
/// a calibration's posterior (`--values`).
#[pyfunction]
#[pyo3(signature = (model, at, grid, params, sided, values, approach))]
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
) -> PyResult<String> {
    let posterior = read_posterior(py, model, values, approach)?;
    let study = model.study_with(py, &grid, &params, sided, None, posterior.as_ref())?;
    let point = match &at {
        None => None,
        Some(coords) => Some(resolve_at(py, model, coords)?),
    };
    let parameters = model.parameter_vector(py, &params)?;
    let (at, result) = py
        .allow_threads(|| {
            document::sensitivity(
                &study,
                &model.model,
                &parameters,
                point.as_deref(),
                &Form::default(),
            )
        })
        .map_err(|e| study_error(py, &e, &model.file))?;
    to_json(&SensitivityDocument::new(
        &model.machine.name,
        at,
        &result,
        posterior.as_ref(),
    ))
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
    let m = &model.machine;
    let nominal = match sizes {
        None => NominalSizes::default(),
        Some(text) => NominalSizes::default()
            .parse(text)
            .map_err(|e| value_error(format!("invalid value {text:?} for `sizes`: {e}")))?,
    };
    let parameters = model.parameter_vector(py, &params)?;
    let vars: Vec<&str> = m.variables.iter().map(|v| v.name.as_str()).collect();
    for (name, values) in &grid {
        if let Some(x) = values.iter().find(|x| !x.is_finite()) {
            return Err(value_error(format!(
                "grid axis `{name}` has a non-finite value ({x})"
            )));
        }
    }
    let where_ = match &at {
        Some(coords) => {
            if !grid.is_empty() {
                return Err(value_error(
                    "grid cannot be combined with at (at evaluates at one point, grid sets the grid of the mean; give one)",
                ));
            }
            let point = resolve_at(py, model, coords)?;
            Where::At(
                vars.iter()
                    .zip(&point)
                    .map(|(n, x)| (n.to_string(), *x))
                    .collect(),
            )
        }
        None => Where::Grid(geometric::grid_axes(m, &grid).map_err(|e| match e {
            GridAxisError::UnknownVariable(name) => {
                let e = ReliabilityError::unknown("axis variable", &name, vars.iter().copied());
                study_error(py, &e, &model.file)
            }
            GridAxisError::NoValues(v) => value_error(format!(
                "{}: no grid values for axis variable `{v}` (key `reliability.grid.{v}`); evaluate at one point with at=, or give grid={{{v:?}: [...]}}",
                model.file
            )),
        })?),
    };
    let sizes = nominal.of(m);
    let result =
        py.allow_threads(|| geometric::evaluate(&model.model, &where_, &parameters, &sizes));
    to_json(&GeometricDocument::new(&m.name, &where_, &nominal, &result))
}
