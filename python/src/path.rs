//! `chain path --format json` over arrays, through `chain::ops::path` (the
//! CLI's request, checks and document): axis values with named columns, or
//! tool poses solved by the inverse kinematics.

use chain::ops::path::{self, PathInput, PathOpsError, PathRequest};
use chain::ops::tables;
use numpy::{PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;

use crate::inverse::pose_rows;
use crate::study::{algorithm_options, system_choice};
use crate::{
    check_finite, resolve_error, sided_named, study_error, table_error, to_json, value_error,
    FileInput, Model,
};

/// Error and reliability along a path. Exactly one of `axes` (an `(N, C)`
/// array whose columns `header` names: axis variables in any order, an
/// optional first `t`), `poses` (`(N, 6)` or `(N, 12)`, as `inverse`; `t`
/// their instants), `axes_file` and `poses_file` (`(path, text, name)`: the
/// CSV `--axes` or `--pose` reads) is given; the other keywords are the
/// CLI's options.
#[pyfunction]
#[pyo3(signature = (model, header, axes, poses, t, fix, params, method, samples, seed, cov, sided, system, system_tolerance, axes_file=None, poses_file=None, temperatures=Vec::new()))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn path_json(
    py: Python<'_>,
    model: &Model,
    header: Vec<String>,
    axes: Option<PyReadonlyArray2<'_, f64>>,
    poses: Option<PyReadonlyArray2<'_, f64>>,
    t: Option<PyReadonlyArray1<'_, f64>>,
    fix: Vec<(String, f64)>,
    params: Vec<(String, f64)>,
    method: &str,
    samples: Option<u64>,
    seed: u64,
    cov: Option<f64>,
    sided: Option<&str>,
    system: Option<&str>,
    system_tolerance: Option<f64>,
    axes_file: Option<FileInput>,
    poses_file: Option<FileInput>,
    temperatures: Vec<(String, f64)>,
) -> PyResult<String> {
    let algorithm = algorithm_options(method, samples, seed, cov)?;
    let sided = sided_named(sided)?;
    let system = system_choice(system, system_tolerance)?;
    let (rows, poses_read, table, file_name);
    let input = match (&axes, &poses, &axes_file, &poses_file) {
        (None, None, Some(file), None) => {
            let source = file.source()?;
            let read = py.allow_threads(|| tables::read_numbers(source));
            table = read.map_err(|e| table_error(py, model, e))?;
            PathInput::Axes {
                source: &table.name,
                header: &table.header,
                rows: &table.rows,
            }
        }
        (None, None, None, Some(file)) => {
            let source = file.source()?;
            let read = py.allow_threads(|| tables::read_poses(source));
            let (has_t, read) = read.map_err(|e| table_error(py, model, e))?;
            poses_read = read;
            file_name = source.name();
            PathInput::Poses {
                source: &file_name,
                has_t,
                rows: &poses_read,
            }
        }
        (Some(a), None, None, None) => {
            let width = a.shape()[1];
            if width != header.len() {
                return Err(value_error(format!(
                    "axes has {width} columns but {} names",
                    header.len()
                )));
            }
            let flat = a.as_slice()?;
            check_finite(flat, width, "axes")?;
            rows = match width {
                0 => vec![Vec::new(); a.shape()[0]],
                _ => flat.chunks_exact(width).map(<[f64]>::to_vec).collect(),
            };
            PathInput::Axes {
                source: "axes",
                header: &header,
                rows: &rows,
            }
        }
        (None, Some(p), None, None) => {
            let width = p.shape()[1];
            let flat = p.as_slice()?;
            check_finite(flat, width, "poses")?;
            let mut read = pose_rows(flat, width)?;
            if let Some(t) = &t {
                let t = t.as_slice()?;
                if t.len() != read.len() {
                    return Err(value_error(format!(
                        "t has {} values for {} poses",
                        t.len(),
                        read.len()
                    )));
                }
                check_finite(t, 0, "t")?;
                for (row, &t) in read.iter_mut().zip(t) {
                    row.t = Some(t);
                }
            }
            poses_read = read;
            PathInput::Poses {
                source: "poses",
                has_t: t.is_some(),
                rows: &poses_read,
            }
        }
        _ => {
            return Err(value_error(
                "give the path as axes=... or poses=... (one of them)",
            ))
        }
    };
    let request = PathRequest {
        params: &params,
        fix: &fix,
        sided,
        system,
        algorithm,
        input,
        temperatures: &temperatures,
    };
    let doc = py
        .allow_threads(|| path::run(&model.machine, &request, &()))
        .map_err(|e| match e {
            PathOpsError::Reliability(e) => study_error(py, &e, &model.file),
            PathOpsError::Resolve(e) => resolve_error(py, model, e),
            e @ (PathOpsError::Option(_) | PathOpsError::Machine(_)) => value_error(e.to_string()),
        })?;
    to_json(&doc)
}
