//! `chain export` over a values file or dict, through `chain::ops::export`
//! (the CLI's request, checks and document): the summary document as JSON
//! text and the files the controller reads, by name.

use chain::ops::export::{self, ExportController, ExportOpsError, ExportRequest};
use chain::ops::resolve::AxisPoints;
use chain::ops::Worded;
use numpy::PyReadonlyArray2;
use pyo3::prelude::*;

use crate::measured::read_values;
use crate::{choice, resolve_error, study_error, to_json, value_error, Model};

/// The compensation of the built machine `values` (a file `values_path`,
/// or the text `values_text` named `values_file`) for `controller`; `grid`,
/// `points` (rows in the machine's variable order, `--axes`), `step`,
/// `cec_max_points`, `beckhoff_max_records`, `angles` and `params` as the CLI's
/// options. Returns the summary document and the files `(name, text)`.
#[pyfunction]
#[pyo3(signature = (model, values_path, values_text, values_file, controller, grid, points, step, cec_max_points, beckhoff_max_records, angles, params, temperatures))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn export_json(
    py: Python<'_>,
    model: &Model,
    values_path: Option<&str>,
    values_text: Option<&str>,
    values_file: &str,
    controller: &str,
    grid: Vec<(String, Vec<f64>)>,
    points: Option<PyReadonlyArray2<'_, f64>>,
    step: Option<f64>,
    cec_max_points: Option<usize>,
    beckhoff_max_records: Option<usize>,
    angles: bool,
    params: Vec<(String, f64)>,
    temperatures: Vec<(String, f64)>,
) -> PyResult<(String, Vec<(String, String)>)> {
    let controller = choice::<ExportController>(controller)?;
    let rows = match &points {
        Some(q) => Some(("points".to_string(), model.points(q)?.0.to_vec())),
        None => None,
    };
    let points = AxisPoints::new(&grid, rows).map_err(|e| resolve_error(py, model, e))?;
    let request = ExportRequest {
        controller,
        params: &params,
        points,
        step,
        cec_max_points,
        beckhoff_max_records,
        angles,
        temperatures: &temperatures,
    };
    let refused = |e: ExportOpsError| match e {
        ExportOpsError::Reliability(e) => study_error(py, &e, &model.file),
        ExportOpsError::Resolve(e) => resolve_error(py, model, e),
        e => value_error(e.with_help()),
    };
    export::check(&request).map_err(refused)?;
    let m = &model.machine;
    let (values, name) = read_values(py, m, values_path, values_text, values_file)?;
    let doc = py
        .allow_threads(|| export::run(m, &model.file, values, &name, &request))
        .map_err(refused)?;
    let files = (doc.files().iter())
        .map(|f| (f.name.clone(), f.text.clone()))
        .collect();
    Ok((to_json(&doc)?, files))
}
