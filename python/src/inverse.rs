//! `chain inverse --format json` over an array of poses, through
//! `chain::ops::inverse` (the CLI's request, checks and document).

use chain::ops::inverse::{self, InverseOpsError, InverseRequest, PoseRow};
use numpy::{PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;

use crate::{check_finite, resolve_error, study_error, to_json, value_error, Model};

/// The poses of an `(N, width)` array (`width` 6 or 12), a row refused as
/// `poses row K: ...` (0-based), the width as `poses: ...`.
pub(crate) fn pose_rows(flat: &[f64], width: usize) -> PyResult<Vec<PoseRow>> {
    inverse::pose_rows(flat, width).map_err(|(row, e)| match row {
        Some(k) => value_error(format!("poses row {k}: {e}")),
        None => value_error(format!("poses: {e}")),
    })
}

/// The inverse kinematics of `poses` (`(N, 6)`: `px, py, pz, i, j, k`, or
/// `(N, 12)`: `px, py, pz, r11 … r33`), `fix` and `params` as `--fix` and
/// `--param`.
#[pyfunction]
#[pyo3(signature = (model, poses, fix, params))]
pub(crate) fn inverse_json(
    py: Python<'_>,
    model: &Model,
    poses: PyReadonlyArray2<'_, f64>,
    fix: Vec<(String, f64)>,
    params: Vec<(String, f64)>,
) -> PyResult<String> {
    let width = poses.shape()[1];
    let flat = poses.as_slice()?;
    check_finite(flat, width, "poses")?;
    let rows = pose_rows(flat, width)?;
    let request = InverseRequest {
        params: &params,
        fix: &fix,
        poses: &rows,
    };
    let doc = py
        .allow_threads(|| inverse::run(&model.machine, &request))
        .map_err(|e| match e {
            InverseOpsError::Reliability(e) => study_error(py, &e, &model.file),
            InverseOpsError::Resolve(e) => resolve_error(py, model, e),
            e @ InverseOpsError::Machine(_) => value_error(e.to_string()),
        })?;
    to_json(&doc)
}
