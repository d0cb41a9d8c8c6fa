//! The measured machine (measured-machines spec): `chain map`, `chain
//! identify` and `chain plan`, each returning the document the CLI prints
//! with `--format json` for the same input, built by the same library
//! function.
//!
//! Inputs the CLI reads from files come as a path or as their text (the
//! Python side writes numpy arrays as the CSV the CLI would read, so that
//! one parser checks both); every refusal is the CLI's message, located
//! (`MachineError` with file, line, column, key) where the library locates
//! it, a `ValueError` otherwise.

use chain::ops::identify::{CircleRequest, IdentifyOpsError, IdentifyRequest};
use chain::ops::plan::{self, PlanRequest};
use chain::ops::Worded;
use chain_core::measured::{Layout, Measurements, MeasurementsError, SetupKind};
use chain_core::model::Machine;
use chain_core::plan::Kind;
use chain_core::values::{Values, ValuesError};
use numpy::PyReadonlyArray2;
use pyo3::prelude::*;

use chain::ops::map::{MapOpsError, MapRequest};
use chain::ops::resolve::AxisPoints;
use chain::ops::source as ops_source;

use crate::{
    choice, load_error, resolve_error, source, study_error, to_json, value_error, FileInput, Model,
};

/// A measurement or candidate CSV: read from `path`, or parsed from `text`
/// named `file` ([`chain::ops::source::read_measurements`], the GIL
/// released).
fn read_measurements(
    py: Python<'_>,
    m: &Machine,
    path: Option<&str>,
    text: Option<&str>,
    file: &str,
    params: &[(String, f64)],
    layout: Layout,
) -> PyResult<Measurements> {
    let source = source(path, text, file)?;
    let read = py.allow_threads(|| ops_source::read_measurements(source, m, params, layout));
    read.map_err(|e: MeasurementsError| load_error(py, e.diagnostics()))
}

/// A values file and its name: read from `path` (tables relative to it),
/// or parsed from `text` named `file` (tables relative to the working
/// directory) ([`chain::ops::source::read_values`], the GIL released).
pub(crate) fn read_values(
    py: Python<'_>,
    m: &Machine,
    path: Option<&str>,
    text: Option<&str>,
    file: &str,
) -> PyResult<(Values, String)> {
    let source = source(path, text, file)?;
    let read = py.allow_threads(|| ops_source::read_values(source, m));
    let values = read.map_err(|e: ValuesError| load_error(py, e.diagnostics()))?;
    Ok((values, source.name()))
}

/// `chain identify --format json` (and the values file `--values-out`
/// writes): the measurement CSV `measurements`, the sphere-probing CSV
/// `spheres` or the circular-test file `circular` (each a path, or text
/// and its name; the latter placed by `centre` or `axes` and read with
/// `radius`, `feed`, `plane`, `arc`), `setup` (`--setup`,
/// `"ball"`); the held-out records of `--validate`, if any, from
/// `validate`, read as the fitted ones are.
#[pyfunction]
#[pyo3(signature = (model, measurements, spheres, setup, params, prior, validate=None, rank_tol=None, fix=None, estimate=None, iterate=false, holdout=None, seed=None, temperatures=Vec::new(), circular=None, centre=None, axes=false, radius=None, feed=None, plane=None, arc=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn identify_json(
    py: Python<'_>,
    model: &Model,
    measurements: Option<FileInput>,
    spheres: Option<FileInput>,
    setup: Option<&str>,
    params: Vec<(String, f64)>,
    prior: bool,
    validate: Option<FileInput>,
    rank_tol: Option<f64>,
    fix: Option<Vec<String>>,
    estimate: Option<Vec<String>>,
    iterate: bool,
    holdout: Option<f64>,
    seed: Option<u64>,
    temperatures: Vec<(String, f64)>,
    circular: Option<FileInput>,
    centre: Option<Vec<(String, f64)>>,
    axes: bool,
    radius: Option<f64>,
    feed: Option<f64>,
    plane: Option<&str>,
    arc: Option<f64>,
) -> PyResult<(String, String)> {
    let request = IdentifyRequest {
        measurements: measurements.as_ref().map(FileInput::source).transpose()?,
        spheres: spheres.as_ref().map(FileInput::source).transpose()?,
        setup: setup.map(choice::<SetupKind>).transpose()?,
        validate: validate.as_ref().map(FileInput::source).transpose()?,
        params: &params,
        prior,
        rank_tol,
        fix,
        estimate,
        holdout,
        seed,
        iterate,
        temperatures: &temperatures,
        circular: circular.as_ref().map(FileInput::source).transpose()?,
        circle: CircleRequest {
            centre: centre.as_deref(),
            axes,
            radius,
            feed,
            plane,
            arc,
        },
    };
    let checked = request.check().map_err(|e| value_error(e.with_help()))?;
    let m = &model.machine;
    let run = py.allow_threads(|| checked.run(m)).map_err(|e| match e {
        IdentifyOpsError::Resolve(e) => resolve_error(py, model, e),
        IdentifyOpsError::Measurements(e) => load_error(py, e.diagnostics()),
        e => value_error(e.with_help()),
    })?;
    Ok((to_json(&run)?, run.values_text))
}

/// `chain plan --format json`: `count` of the candidates from `path` or
/// `text` (named `file`); `kind`: `None`, `"point"` or `"direction"`.
#[pyfunction]
#[pyo3(signature = (model, path, text, file, count, kind, params, spheres=false))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn plan_json(
    py: Python<'_>,
    model: &Model,
    path: Option<&str>,
    text: Option<&str>,
    file: &str,
    count: usize,
    kind: Option<&str>,
    params: Vec<(String, f64)>,
    spheres: bool,
) -> PyResult<String> {
    let m = &model.machine;
    let kind = kind.map(choice::<Kind>).transpose()?;
    chain::ops::resolve::check_parameters(m, &params).map_err(|e| resolve_error(py, model, e))?;
    let candidates = if spheres {
        let source = source(path, text, file)?;
        let read = py.allow_threads(|| ops_source::read_spheres(source, m, &params));
        read.map_err(|e: MeasurementsError| load_error(py, e.diagnostics()))?
    } else {
        read_measurements(py, m, path, text, file, &params, Layout::Candidates)?
    };
    let request = PlanRequest { count, kind };
    let doc = py
        .allow_threads(|| plan::run(m, &candidates, &request))
        .map_err(|e| value_error(e.with_help()))?;
    to_json(&doc)
}

/// `chain map --format json`: the error map of the built machine (values
/// from `values_path` or `values_text` named `values_file`) over the grid
/// (`grid` overriding the file's) or at the rows of `points` (`(N, V)`).
#[pyfunction]
#[pyo3(signature = (model, values_path, values_text, values_file, grid, points, params, approach, temperatures))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn map_json(
    py: Python<'_>,
    model: &Model,
    values_path: Option<&str>,
    values_text: Option<&str>,
    values_file: &str,
    grid: Vec<(String, Vec<f64>)>,
    points: Option<PyReadonlyArray2<'_, f64>>,
    params: Vec<(String, f64)>,
    approach: Option<&str>,
    temperatures: Vec<(String, f64)>,
) -> PyResult<String> {
    let m = &model.machine;
    let (values, name) = read_values(py, m, values_path, values_text, values_file)?;
    let choices = crate::study::parse_approach(approach)?;
    let rows = match &points {
        Some(q) => Some(("points".to_string(), model.points(q)?.0.to_vec())),
        None => None,
    };
    let points = AxisPoints::new(&grid, rows).map_err(|e| resolve_error(py, model, e))?;
    let request = MapRequest {
        params: &params,
        approach: &choices,
        points,
        compensated: None,
        keep_points: true,
        temperatures: &temperatures,
    };
    let ops_error = |e: MapOpsError| match e {
        MapOpsError::Reliability(e) => study_error(py, &e, &model.file),
        MapOpsError::Resolve(e) => resolve_error(py, model, e),
        other => value_error(other.with_help()),
    };
    let prepared =
        chain::ops::map::prepare(m, &model.file, values, &name, &request).map_err(ops_error)?;
    let doc = py
        .allow_threads(|| prepared.run(m, &request, &|_| {}).map_err(Box::new))
        .map_err(|e| ops_error(*e))?;
    to_json(&doc)
}
