//! Compensation of a built machine for a controller (measured-machines
//! spec, section 6; `docs/export.md`): what a controller adds to the
//! commanded axes so that the tool point lands where the command aimed, and
//! the files each controller reads.
//!
//! One interface joins the exporters, the round trips and `chain map
//! --compensated`: a [`Correction`] gives, at commanded axis values `q`,
//! the corrections `δq` the controller adds to them (the machine's
//! variables, in their order and units: mm, rad). The grid export
//! (`grid.rs`) and each controller format (`controllers/`) produce one;
//! the residual after compensation is the built machine's error at
//! `q + δq` plus the nominal motion `δq` causes, against the tool point the
//! uncorrected command aimed at.

use crate::model_trait::OutOfRange;
use serde::Serialize;

/// What a controller adds to the commanded axis values (module docs).
pub trait Correction: Sync {
    /// Writes into `delta` (one entry per machine variable, in the
    /// machine's order) the correction the controller adds at the commanded
    /// axis values `q`. A `q` outside what the correction covers is an
    /// error, never clamped or extrapolated silently (a controller that
    /// holds its end values says so in its own implementation).
    fn delta(&self, q: &[f64], delta: &mut [f64]) -> Result<(), OutOfRange>;
}

/// One file an export writes: its name (relative to the output folder) and
/// its whole text, comment lines with the sign convention included.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct ExportedFile {
    /// The file name, e.g. `X.comp` or `compensation.csv`.
    pub name: String,
    /// The file's text.
    pub text: String,
}
pub mod controllers;
