//! `chain positioning` as a request and a document (spec `positioning.md`):
//! the ISO 230-2 evaluation of a run, and with a machine and a slot the
//! values file `--values-out` writes. The CLI and `chain.positioning` run
//! it.

use chain_core::measured::positioning::{self, AxisKind, Coverage, PositioningDocument, Runs};
use chain_core::measured::positioning_temperature::{self, TemperatureError, Temperatures};
use chain_core::measured::positioning_values::{self, SlotError};
use chain_core::Machine;

/// Where the run's values go (`--values-out --machine --slot`).
#[derive(Debug, Clone, Copy)]
pub struct ValuesOut<'a> {
    /// The machine.
    pub machine: &'a Machine,
    /// The machine file as messages name it.
    pub machine_file: &'a str,
    /// The machine's name for the axis's positioning error.
    pub slot: &'a str,
    /// The run file as the values file's comments name it.
    pub runs_file: &'a str,
}

/// The request of `chain positioning`.
#[derive(Debug, Clone, Copy)]
pub struct PositioningRequest<'a> {
    /// The runs, read (and checked) from a file or an array.
    pub runs: &'a Runs,
    /// `--k`.
    pub k: Coverage,
    /// `--values-out`.
    pub values_out: Option<ValuesOut<'a>>,
    /// `--axis-temperature` and the rest: correct the runs to 20 °C.
    pub temperatures: Option<Temperatures>,
}

/// What `chain positioning` gives: the document and, with `values_out`,
/// the values file's text.
#[derive(Debug, Clone)]
pub struct Positioned {
    /// The ISO 230-2 document.
    pub document: PositioningDocument,
    /// The values file (`--values-out`).
    pub values_text: Option<String>,
}

/// Why `chain positioning` cannot run as asked.
#[derive(Debug, thiserror::Error)]
#[cfg_attr(feature = "cli", derive(miette::Diagnostic))]
pub enum PositioningError {
    /// The values file's slot cannot take the run.
    #[error("--slot {slot} (machine {file}): {error}{}", rotary_hint(error))]
    #[cfg_attr(feature = "cli", diagnostic(forward(error)))]
    Slot {
        /// The slot given.
        slot: String,
        /// The machine file.
        file: String,
        /// Why the slot cannot take the run.
        error: Box<SlotError>,
    },
    /// The correction to 20 °C cannot be made.
    #[error("--axis-temperature: {0}")]
    #[cfg_attr(
        feature = "cli",
        diagnostic(
            code(chain::positioning::temperature),
            help("give the scale's temperature and expansion coefficient (µm/(m·K)) of a linear axis; docs/positioning.md, \"At 20 °C\"")
        )
    )]
    Temperature(TemperatureError),
}

/// What a slot of a rotary axis refused for linear runs adds: the option
/// that reads the runs as a rotary axis's.
fn rotary_hint(error: &SlotError) -> &'static str {
    match error {
        SlotError::KindMismatch {
            runs: AxisKind::Linear,
            ..
        } => " (give --rotary for a rotary axis's runs)",
        _ => "",
    }
}

/// The axis kind of `--rotary`.
pub fn axis_kind(rotary: bool) -> AxisKind {
    if rotary {
        AxisKind::Rotary
    } else {
        AxisKind::Linear
    }
}

/// The default standard uncertainty of a temperature (K).
pub const TEMPERATURE_UNCERTAINTY: f64 = 0.1;
/// The default relative half-width of an expansion coefficient.
pub const EXPANSION_UNCERTAINTY: f64 = 0.1;

/// The temperatures of a run with the options' defaults: the instrument at
/// 20 °C compensating nothing, 0.1 K, ±10 %.
pub fn temperatures(
    axis: f64,
    axis_expansion: f64,
    instrument: Option<f64>,
    instrument_expansion: Option<f64>,
    temperature_uncertainty: Option<f64>,
    expansion_uncertainty: Option<f64>,
) -> Temperatures {
    Temperatures {
        axis,
        axis_expansion,
        instrument: instrument.unwrap_or(20.0),
        instrument_expansion: instrument_expansion.unwrap_or(0.0),
        temperature_uncertainty: temperature_uncertainty.unwrap_or(TEMPERATURE_UNCERTAINTY),
        expansion_uncertainty: expansion_uncertainty.unwrap_or(EXPANSION_UNCERTAINTY),
    }
}

/// Runs `chain positioning`.
pub fn run(request: &PositioningRequest<'_>) -> Result<Positioned, PositioningError> {
    let document = match &request.temperatures {
        None => positioning::evaluate(request.runs, request.k),
        Some(at) => {
            let (runs, correction) = positioning_temperature::correct(request.runs, at, request.k)
                .map_err(PositioningError::Temperature)?;
            let mut document = positioning::evaluate(&runs, request.k);
            document.temperature = Some(correction);
            document
        }
    };
    let values_text = match request.values_out {
        None => None,
        Some(out) => {
            let slot = positioning_values::slot(out.machine, out.slot, request.runs.kind).map_err(
                |e| PositioningError::Slot {
                    slot: out.slot.to_string(),
                    file: out.machine_file.to_string(),
                    error: e,
                },
            )?;
            Some(positioning_values::values_file(
                &document,
                out.machine,
                &slot,
                out.runs_file,
            ))
        }
    };
    Ok(Positioned {
        document,
        values_text,
    })
}
