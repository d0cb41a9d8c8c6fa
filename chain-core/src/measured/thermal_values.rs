//! A drift test's fitted models into a machine's thermal coefficients
//! (`docs/thermal.md`, "From a drift test into the model"): `chain thermal
//! --fit --values-out V --machine F --slot NAME=CHANNEL`.
//!
//! A channel's model `δ = c₀ + Σ_i a_i · ΔT_i(t)` (`ΔT_i` from the test's
//! start) gives a thermal term constant along the axis, `{name: NAME, per:
//! [sensors]}` (coefficients `NAME_<sensor>`, each per kelvin of the
//! sensor's deviation from its reference): `NAME_<sensor_i> = a_i`, the
//! term's sensors the fit did not choose 0. A sensor is the drift file's
//! temperature column whose header, without its unit (`T_spindle(°C)` →
//! `T_spindle`), is the sensor's name. The coefficients are per kelvin
//! whatever the origin of ΔT, so the model holds at the machine's reference
//! as at the test's start; the intercept `c₀` (the drift at the start, zero
//! up to the fit) is no machine error and is not written (the file says
//! so). A lag term is a response in time, not a function of a thermal
//! state: a channel whose model has one is refused.

use serde::Serialize;

use crate::diagnostic::closest;
use crate::model::{ErrorKind, Machine};

use super::thermal::ThermalDocument;
use super::thermal_fit::TermKind;

/// One coefficient written.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WrittenCoefficient {
    /// The error parameter (`EZS_T_spindle`).
    pub name: String,
    /// Its sensor.
    pub sensor: String,
    /// The drift file's column it came from (`None`: the fit did not
    /// choose the sensor, written as 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub column: Option<String>,
    /// µm per K.
    pub value: f64,
    /// Its standard error, µm per K (0 for a sensor not chosen).
    pub std: f64,
}

/// One `--slot NAME=CHANNEL` written.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WrittenTerm {
    /// The thermal term.
    pub slot: String,
    /// The displacement channel.
    pub channel: String,
    /// Its coefficients, in the term's sensor order.
    pub coefficients: Vec<WrittenCoefficient>,
    /// The intercept left out (the channel's unit).
    pub intercept: f64,
}

/// The values file of the fitted terms.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ThermalValues {
    /// The machine.
    pub machine: String,
    /// Per slot, what was written.
    pub terms: Vec<WrittenTerm>,
    /// The values file's text.
    #[serde(skip)]
    pub text: String,
}

/// Why the fitted models cannot be written into a machine's values.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ThermalValuesError {
    /// Not a thermal term of the machine constant along the axis.
    #[error("`{name}` is not a thermal term `{{name, per}}` of machine `{machine}`{} ({})", suggestion.as_ref().map(|s| format!(" (did you mean `{s}`?)")).unwrap_or_default(), if terms.is_empty() { "it has none".to_string() } else { format!("its thermal terms: {}", terms.join(", ")) })]
    UnknownSlot {
        /// The name given.
        name: String,
        /// The machine.
        machine: String,
        /// Its thermal terms constant along the axis.
        terms: Vec<String>,
        /// The closest, if one is close.
        suggestion: Option<String>,
    },
    /// An angular term: a displacement channel is a length.
    #[error("`{name}` is an angular thermal term; a displacement channel's model is a length (a tilt per kelvin is fitted from a sensor pair's difference over its distance)")]
    Angular {
        /// The term.
        name: String,
    },
    /// Not a displacement channel of the drift file.
    #[error("`{channel}` is not a displacement channel of {file}{} (its channels: {})", suggestion.as_ref().map(|s| format!(" (did you mean `{s}`?)")).unwrap_or_default(), channels.join(", "))]
    UnknownChannel {
        /// The name given.
        channel: String,
        /// The drift file.
        file: String,
        /// Its displacement channels.
        channels: Vec<String>,
        /// The closest, if one is close.
        suggestion: Option<String>,
    },
    /// The channel's model has a lag term.
    #[error("the model of `{channel}` has a lag term (a response to `{load}` in time), which no thermal state gives; fit it without lag terms to write it into the machine")]
    Lag {
        /// The channel.
        channel: String,
        /// The load.
        load: String,
    },
    /// A sensor of the model the term is not per.
    #[error("the model of `{channel}` uses `{column}`, {}", match sensor { Some(s) => format!("sensor `{s}`, which `{slot}` is not per (its sensors: {})", sensors.join(", ")), None => format!("which names no sensor of the machine (a column's header without its unit is the sensor's name; its sensors: {})", sensors.join(", ")) })]
    Sensor {
        /// The term.
        slot: String,
        /// The channel.
        channel: String,
        /// The drift file's column.
        column: String,
        /// The machine's sensor it names, if any.
        sensor: Option<String>,
        /// The term's sensors (or the machine's, when the column names
        /// none).
        sensors: Vec<String>,
    },
    /// A term given twice.
    #[error("`{name}` is given twice")]
    SlotTwice {
        /// The term.
        name: String,
    },
    /// The document has no fit.
    #[error("the drift test has no fitted model")]
    NotFitted,
}

/// A temperature column's header without its unit: `T_spindle(°C)` →
/// `T_spindle`.
pub fn sensor_name(header: &str) -> &str {
    match header.rfind('(') {
        Some(i) if header.ends_with(')') => header[..i].trim(),
        _ => header.trim(),
    }
}

/// The machine's thermal terms constant along the axis: name → its
/// coefficients `(error, sensor)`, in order of first use.
fn thermal_terms(machine: &Machine) -> Vec<(String, Vec<(usize, usize)>)> {
    let mut out: Vec<(String, Vec<(usize, usize)>)> = Vec::new();
    for (j, e) in machine.errors.iter().enumerate() {
        let Some(s) = e.sensor else { continue };
        if machine.coefficient_of(j).is_some() {
            continue;
        }
        let Some(sensor) = machine.sensors.get(s) else {
            continue;
        };
        let Some(term) = e.name.strip_suffix(&format!("_{}", sensor.name)) else {
            continue;
        };
        match out.iter_mut().find(|(n, _)| n == term) {
            Some((_, c)) => c.push((j, s)),
            None => out.push((term.to_string(), vec![(j, s)])),
        }
    }
    out
}

/// The fitted models of `document` written as thermal coefficients of
/// `machine`'s terms, `slots` as `(term, channel)` (module docs).
pub fn thermal_values(
    machine: &Machine,
    document: &ThermalDocument,
    slots: &[(String, String)],
) -> Result<ThermalValues, ThermalValuesError> {
    let fit = document.fit.as_ref().ok_or(ThermalValuesError::NotFitted)?;
    let terms = thermal_terms(machine);
    let mut written: Vec<WrittenTerm> = Vec::new();
    for (slot, channel) in slots {
        if written.iter().any(|w| w.slot == *slot) {
            return Err(ThermalValuesError::SlotTwice { name: slot.clone() });
        }
        let Some((_, coefficients)) = terms.iter().find(|(n, _)| n == slot) else {
            return Err(ThermalValuesError::UnknownSlot {
                name: slot.clone(),
                machine: machine.name.clone(),
                terms: terms.iter().map(|(n, _)| n.clone()).collect(),
                suggestion: closest(slot, terms.iter().map(|(n, _)| n.as_str()))
                    .map(str::to_string),
            });
        };
        if coefficients
            .iter()
            .any(|(j, _)| machine.errors[*j].kind != ErrorKind::Linear)
        {
            return Err(ThermalValuesError::Angular { name: slot.clone() });
        }
        let Some(drift) = document.channels.iter().find(|c| c.name == *channel) else {
            let channels: Vec<String> = document.channels.iter().map(|c| c.name.clone()).collect();
            return Err(ThermalValuesError::UnknownChannel {
                channel: channel.clone(),
                file: document.file.clone(),
                suggestion: closest(channel, channels.iter().map(String::as_str))
                    .map(str::to_string),
                channels,
            });
        };
        let model = drift.model.as_ref().ok_or(ThermalValuesError::NotFitted)?;
        let um = if drift.unit == "mm" { 1e3 } else { 1.0 };
        let sensor_of = |s: usize| machine.sensors[s].name.clone();
        let mut out: Vec<WrittenCoefficient> = coefficients
            .iter()
            .map(|&(j, s)| WrittenCoefficient {
                name: machine.errors[j].name.clone(),
                sensor: sensor_of(s),
                column: None,
                value: 0.0,
                std: 0.0,
            })
            .collect();
        for term in &model.terms {
            let column = match (term.kind, &term.sensor, &term.load) {
                (TermKind::Temperature, Some(c), _) => c,
                (_, _, load) => {
                    return Err(ThermalValuesError::Lag {
                        channel: channel.clone(),
                        load: load.clone().unwrap_or_default(),
                    })
                }
            };
            let name = sensor_name(column);
            let Some(c) = out.iter_mut().find(|c| c.sensor == name) else {
                let known = machine.sensor_index(name).is_some();
                return Err(ThermalValuesError::Sensor {
                    slot: slot.clone(),
                    channel: channel.clone(),
                    column: column.clone(),
                    sensor: known.then(|| name.to_string()),
                    sensors: if known {
                        coefficients.iter().map(|&(_, s)| sensor_of(s)).collect()
                    } else {
                        machine.sensors.iter().map(|s| s.name.clone()).collect()
                    },
                });
            };
            c.column = Some(column.clone());
            c.value = term.coefficient * um;
            c.std = term.std * um;
        }
        written.push(WrittenTerm {
            slot: slot.clone(),
            channel: channel.clone(),
            coefficients: out,
            intercept: model.intercept,
        });
    }
    let text = values_text(machine, document, fit, &written);
    Ok(ThermalValues {
        machine: machine.name.clone(),
        terms: written,
        text,
    })
}

/// The values file (`docs/values.md`) of the written terms.
fn values_text(
    machine: &Machine,
    document: &ThermalDocument,
    fit: &super::thermal_fit::FitPeriod,
    terms: &[WrittenTerm],
) -> String {
    use std::fmt::Write;
    let mut out = String::new();
    let _ = writeln!(
        out,
        "# Thermal coefficients fitted from the drift test {} (fit period {} s to {} s, {} samples),",
        document.file, fit.from, fit.until, fit.samples
    );
    out.push_str(
        "# each per kelvin of its sensor's deviation from its reference (docs/thermal.md). Each\n\
         # channel's intercept (its drift at the start of the test) is no machine error and is\n\
         # not written.\n",
    );
    let _ = writeln!(out, "machine: {}", machine.name);
    out.push_str("units: {linear: um, angular: urad}\nvalues:\n");
    for t in terms {
        let _ = writeln!(
            out,
            "  # {}: the model of {} (intercept {} left out)",
            t.slot, t.channel, t.intercept
        );
        for c in &t.coefficients {
            match &c.column {
                Some(column) => {
                    let _ = writeln!(
                        out,
                        "  {}: {{value: {}, std: {}}}  # µm/K, {column}",
                        c.name, c.value, c.std
                    );
                }
                None => {
                    let _ = writeln!(
                        out,
                        "  {}: 0  # µm/K: {} is not in the fitted model",
                        c.name, c.sensor
                    );
                }
            }
        }
    }
    out
}
