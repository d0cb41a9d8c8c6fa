//! `chain compensate --format json` (seed 003's swing-angle workflow): the
//! measurements from a path or as CSV text, read by the library reader the
//! CLI uses (`chain::compensate::records`), run by `chain::ops::compensate`
//! with the CLI's request.

use std::path::Path;

use chain::compensate::{records, Options, SelectionRule};
use chain::ops::compensate::{self, CompensateRequest};
use chain::ops::study::OptionError;
use pyo3::prelude::*;

use crate::{to_json, value_error};

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
    let rule = select
        .parse::<SelectionRule>()
        .map_err(|message| value_error(OptionError::new("select", message).to_string()))?;
    let measurements = match (path, text) {
        (Some(path), None) => records::read_measurements(Path::new(path)),
        (None, Some(text)) => records::parse_measurements(name, text.as_bytes()),
        _ => {
            return Err(value_error(
                "give the measurements as a path or as their columns, not both",
            ))
        }
    }
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
