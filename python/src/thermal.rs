//! `chain thermal --format json` (spec `thermal.md`): the drift-test file
//! from a path or as its text, read, evaluated and fitted by the library
//! the CLI uses; refusals are the CLI's messages (`MachineError`, located,
//! or `ValueError` with the CLI's words for the options).

use chain::ops::source::read_drift;
use chain::ops::thermal as ops;
use chain::ops::Worded;
use chain_core::measured::thermal::Roles;
use chain_core::measured::thermal_fit::{FitOptions, Split, DEFAULT_SENSORS};
use numpy::{IntoPyArray, PyArray1};
use pyo3::prelude::*;

use crate::{load_error, source, to_json, value_error, Model};

/// The drift test's document, the samples' times and, per displacement
/// channel with a fit, `(channel, measured, predicted)`.
type ThermalOut<'py> = (
    String,
    Bound<'py, PyArray1<f64>>,
    Vec<(String, Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>)>,
    Option<String>,
);

/// `chain thermal` of the file at `path`, or of `text` named `file`:
/// `displacements`, `temperatures`, `loads`, `pairs` (`X1:X2=L`) and the
/// fit's options as the CLI's (`fit`, `sensors`, `lag`, `holdout`,
/// `fit_until`); with `model` and `slots` (`--machine`, `--slot`) the
/// fitted models as the machine's thermal coefficients, whose values file
/// text is returned last (`--values-out`).
#[pyfunction]
#[pyo3(signature = (path, text, file, displacements, temperatures, loads, pairs, fit, sensors, lag, holdout, fit_until, model=None, slots=Vec::new()))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn thermal_json<'py>(
    py: Python<'py>,
    path: Option<&str>,
    text: Option<&str>,
    file: &str,
    displacements: Vec<String>,
    temperatures: Vec<String>,
    loads: Vec<String>,
    pairs: Vec<String>,
    fit: bool,
    sensors: Option<usize>,
    lag: bool,
    holdout: Option<f64>,
    fit_until: Option<f64>,
    model: Option<PyRef<'py, Model>>,
    slots: Vec<(String, String)>,
) -> PyResult<ThermalOut<'py>> {
    let refused = |e: ops::ThermalOpsError| value_error(e.with_help());
    let pairs = (pairs.iter())
        .map(|p| ops::parse_pair(p))
        .collect::<Result<Vec<_>, _>>()
        .map_err(refused)?;
    if !fit && (sensors.is_some() || lag || holdout.is_some() || fit_until.is_some()) {
        return Err(value_error(
            "sensors, lag, holdout and fit_until are options of the fit: give fit=True",
        ));
    }
    let split = match (holdout, fit_until) {
        (Some(_), Some(_)) => return Err(value_error("give holdout or fit_until, not both")),
        (Some(f), None) => Split::Holdout(f),
        (None, Some(t)) => Split::Until(t),
        (None, None) => Split::None,
    };
    let roles = Roles {
        displacements,
        temperatures,
        loads,
    };
    let source = source(path, text, file)?;
    let test = py
        .allow_threads(|| read_drift(source, &roles))
        .map_err(|e| load_error(py, e.diagnostics()))?;
    let request = ops::ThermalRequest {
        test: &test,
        pairs: &pairs,
        fit: fit.then(|| FitOptions {
            sensors: sensors.unwrap_or(DEFAULT_SENSORS),
            lag,
            split,
        }),
        into_machine: model.as_ref().map(|m| ops::IntoMachine {
            machine: &m.machine,
            slots: &slots,
        }),
    };
    let done = py.allow_threads(|| ops::run(&request)).map_err(refused)?;
    let json = to_json(&done)?;
    let predictions = (done.predictions.into_iter())
        .map(|p| {
            (
                p.channel,
                p.measured.into_pyarray(py),
                p.predicted.into_pyarray(py),
            )
        })
        .collect();
    let values = done.values.map(|v| v.text);
    Ok((json, done.time.into_pyarray(py), predictions, values))
}
