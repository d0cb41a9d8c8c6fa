//! `chain compensate --format json` (seed 003's swing-angle workflow): the
//! measurements from a path or as CSV text, read by the reader the CLI uses
//! (`chain::ops::source::read_swing`), run by `chain::ops::compensate` with
//! the CLI's request.

use chain::compensate::{Options, SelectionRule};
use chain::ops::compensate::{self, CompensateRequest};
use chain::ops::source as ops_source;
use pyo3::prelude::*;

use crate::{choice, source, to_json, value_error};

/// The analysis of the measurements at `path`, or of CSV `text` named
/// `name`, as `chain compensate FILE --length L ... --format json`.
#[pyfunction]
#[pyo3(signature = (path, text, name, length, min_order, max_order, select, order))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn compensate_json(
    py: Python<'_>,
    path: Option<&str>,
    text: Option<&str>,
    name: &str,
    length: f64,
    min_order: usize,
    max_order: usize,
    select: &str,
    order: Option<usize>,
) -> PyResult<String> {
    let rule = choice::<SelectionRule>(select)?;
    let source = source(path, text, name)?;
    let measurements = py
        .allow_threads(|| ops_source::read_swing(source))
        .map_err(|e| value_error(e.to_string()))?;
    let request = CompensateRequest {
        options: Options {
            length,
            min_order,
            max_order,
            rule,
            fixed_order: order,
        },
        table: None,
    };
    let run = py
        .allow_threads(|| compensate::run(&measurements, &request))
        .map_err(|e| value_error(e.to_string()))?;
    to_json(&run)
}
