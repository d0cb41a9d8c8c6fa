//! `chain positioning` as a request and a document (spec `positioning.md`):
//! the ISO 230-2 evaluation of a run, and with a machine and a slot the
//! values file `--values-out` writes. The CLI and `chain.positioning` run
//! it.

use chain_core::measured::positioning::{self, AxisKind, Coverage, PositioningDocument, Runs};
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

/// Why `chain positioning` cannot write its values file.
#[derive(Debug, thiserror::Error)]
#[error("--slot {slot} (machine {file}): {error}{}", rotary_hint(error))]
#[cfg_attr(
    feature = "cli",
    derive(miette::Diagnostic),
    diagnostic(forward(error))
)]
pub struct PositioningError {
    /// The slot given.
    pub slot: String,
    /// The machine file.
    pub file: String,
    /// Why the slot cannot take the run.
    pub error: Box<SlotError>,
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

/// Runs `chain positioning`.
pub fn run(request: &PositioningRequest<'_>) -> Result<Positioned, PositioningError> {
    let document = positioning::evaluate(request.runs, request.k);
    let values_text = match request.values_out {
        None => None,
        Some(out) => {
            let slot = positioning_values::slot(out.machine, out.slot, request.runs.kind).map_err(
                |e| PositioningError {
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
