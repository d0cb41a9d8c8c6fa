//! `chain inverse --format json` over an array of poses, through
//! `chain::ops::inverse` (the CLI's request, checks and document).

use chain::ops::inverse::{self, InverseOpsError, InverseRequest, PoseRow};
use chain::ops::tables;
use numpy::{PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;

use crate::{
    check_finite, resolve_error, study_error, table_error, to_json, value_error, FileInput, Model,
};

/// The poses of an `(N, width)` array (`width` 6 or 12), a row refused as
/// `poses row K: ...` (0-based), the width as `poses: ...`.
pub(crate) fn pose_rows(flat: &[f64], width: usize) -> PyResult<Vec<PoseRow>> {
    inverse::pose_rows(flat, width).map_err(|(row, e)| match row {
        Some(k) => value_error(format!("poses row {k}: {e}")),
        None => value_error(format!("poses: {e}")),
    })
}

/// The inverse kinematics of `poses` (`(N, 6)`: `px, py, pz, i, j, k`, or
/// `(N, 12)`: `px, py, pz, r11 … r33`) or of the pose CSV `poses_file`
/// (`(path, text, name)`: read as `chain inverse --pose` reads it), `fix`
/// and `params` as `--fix` and `--param`.
#[pyfunction]
#[pyo3(signature = (model, poses, fix, params, poses_file=None))]
pub(crate) fn inverse_json(
    py: Python<'_>,
    model: &Model,
    poses: Option<PyReadonlyArray2<'_, f64>>,
    fix: Vec<(String, f64)>,
    params: Vec<(String, f64)>,
    poses_file: Option<FileInput>,
) -> PyResult<String> {
    let rows = match (poses, poses_file) {
        (Some(poses), None) => {
            let width = poses.shape()[1];
            let flat = poses.as_slice()?;
            check_finite(flat, width, "poses")?;
            pose_rows(flat, width)?
        }
        (None, Some(file)) => {
            let source = file.source()?;
            let read = py.allow_threads(|| tables::read_poses(source));
            read.map_err(|e| table_error(py, model, e))?.1
        }
        _ => {
            return Err(value_error(
                "give the poses as an array or a file, one of them",
            ))
        }
    };
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
