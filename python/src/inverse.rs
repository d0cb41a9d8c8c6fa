//! `chain inverse --format json` over an array of poses, through
//! `chain::ops::inverse` (the CLI's request, checks and document).

use chain::ops::inverse::{self, InverseOpsError, InverseRequest, Orientation, PoseRow};
use numpy::{PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;

use crate::{check_finite, resolve_error, study_error, to_json, value_error, Model};

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
    if width != 6 && width != 12 {
        return Err(value_error(format!(
            "poses must have 6 columns (px, py, pz, i, j, k) or 12 (px, py, pz, r11 … r33), found {width}"
        )));
    }
    let flat = poses.as_slice()?;
    check_finite(flat, width, "poses")?;
    let rows = flat
        .chunks_exact(width)
        .enumerate()
        .map(|(k, v)| {
            let orientation = if width == 12 {
                Orientation::rotation(std::array::from_fn(|i| {
                    std::array::from_fn(|j| v[3 + 3 * i + j])
                }))
            } else {
                Orientation::axis([v[3], v[4], v[5]])
            };
            orientation
                .map(|orientation| PoseRow {
                    t: None,
                    point: [v[0], v[1], v[2]],
                    orientation,
                })
                .map_err(|e| value_error(format!("poses row {k}: {e}")))
        })
        .collect::<PyResult<Vec<_>>>()?;
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
            e @ InverseOpsError::Machine { .. } => value_error(e.to_string()),
        })?;
    to_json(&doc)
}
