//! ISO 230-2 at 20 °C: the positioning runs of a linear axis measured at
//! another temperature, corrected by the nominal differential expansion
//! (NDE) of the axis's scale against the instrument, and that correction's
//! contribution to the uncertainty (`docs/positioning.md`, "At 20 °C";
//! sources and what is unconfirmed: `docs/iso230-2-temperature-sources.md`).
//!
//! With the scale at `T_s` (expansion coefficient `α_s`) and the instrument
//! (a laser's material sensor, its compensation coefficient `α_i`; 0 for an
//! instrument that compensates nothing) at `T_i`, a target `L` from the
//! datum (the smallest target) is reached `L·(α_s·ΔT_s − α_i·ΔT_i)` further
//! than at 20 °C (`ΔT = T − 20 °C`, ISO 1's reference temperature): the
//! corrected deviation is `x′ = x − L·(α_s·ΔT_s − α_i·ΔT_i)` (the same
//! correction both directions, so the reversal and the repeatability are
//! unchanged; a shift of the datum moves every deviation alike, so E, M, A
//! are unchanged by it). The standard uncertainty of the correction over
//! the measured length `L = P_max − P_min`, its parts combined by root sum
//! of squares (GUM): the temperatures' `α·L·u(T)` each, the coefficients'
//! `L·|ΔT|·r·α/√3` (a relative half-width `r`, rectangular); the document
//! states it expanded by the coverage factor `k`.

use serde::Serialize;

use super::positioning::{AxisKind, Coverage, Runs};

/// What a run was measured at (temperatures in °C, expansion coefficients
/// in µm/(m·K), i.e. 10⁻⁶/K).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Temperatures {
    /// The scale's (axis's) temperature.
    pub axis: f64,
    /// The scale's expansion coefficient.
    pub axis_expansion: f64,
    /// The instrument's (material sensor's) temperature.
    pub instrument: f64,
    /// The expansion coefficient the instrument compensates with (0: none).
    pub instrument_expansion: f64,
    /// The standard uncertainty of each temperature (K).
    pub temperature_uncertainty: f64,
    /// The relative half-width of each expansion coefficient (0.1: ±10 %).
    pub expansion_uncertainty: f64,
}

/// The correction applied and its uncertainty contribution.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TemperatureCorrection {
    /// What the run was measured at.
    #[serde(flatten)]
    pub at: Temperatures,
    /// The datum: the target from which lengths count (mm).
    pub datum: f64,
    /// `α_s·ΔT_s − α_i·ΔT_i` (µm/m): the deviation removed per metre.
    pub per_metre: f64,
    /// The correction at the farthest target (mm, subtracted).
    pub largest: f64,
    /// The standard uncertainties of the correction over the measured
    /// length (mm): the scale's temperature, the instrument's, the
    /// coefficients'.
    pub u_axis_temperature: f64,
    /// See [`TemperatureCorrection::u_axis_temperature`].
    pub u_instrument_temperature: f64,
    /// See [`TemperatureCorrection::u_axis_temperature`].
    pub u_expansion: f64,
    /// Their combination expanded by `k` (mm): the correction's
    /// contribution to the uncertainty of E, M and A.
    pub expanded: f64,
}

/// Why a run cannot be corrected to 20 °C.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[cfg_attr(feature = "miette", derive(miette::Diagnostic))]
#[non_exhaustive]
pub enum TemperatureError {
    /// A rotary axis: angles do not scale with expansion.
    #[error("a rotary axis's angles do not change with its temperature; the correction to 20 °C is a linear axis's")]
    Rotary,
    /// A value that is not a finite number, or a negative uncertainty.
    #[error("{what} {value} is not {need}")]
    Value {
        /// Which input.
        what: &'static str,
        /// As given.
        value: f64,
        /// What it must be.
        need: &'static str,
    },
}

/// `runs` corrected to 20 °C (module docs) and the correction's account.
pub fn correct(
    runs: &Runs,
    at: &Temperatures,
    k: Coverage,
) -> Result<(Runs, TemperatureCorrection), TemperatureError> {
    if runs.kind == AxisKind::Rotary {
        return Err(TemperatureError::Rotary);
    }
    for (what, value, nonnegative) in [
        ("the axis temperature", at.axis, false),
        ("the axis expansion coefficient", at.axis_expansion, false),
        ("the instrument temperature", at.instrument, false),
        (
            "the instrument expansion coefficient",
            at.instrument_expansion,
            false,
        ),
        (
            "the temperature uncertainty",
            at.temperature_uncertainty,
            true,
        ),
        ("the expansion uncertainty", at.expansion_uncertainty, true),
    ] {
        if !value.is_finite() || (nonnegative && value < 0.0) {
            let need = if nonnegative {
                "a finite number ≥ 0"
            } else {
                "a finite number"
            };
            return Err(TemperatureError::Value { what, value, need });
        }
    }
    let (ds, di) = (at.axis - 20.0, at.instrument - 20.0);
    // µm/m = 1e-6 mm per mm.
    let per_metre = at.axis_expansion * ds - at.instrument_expansion * di;
    let datum = runs.targets[0].target;
    let span = runs.targets[runs.targets.len() - 1].target - datum;
    let mut corrected = runs.clone();
    for t in &mut corrected.targets {
        let c = (t.target - datum) * per_metre * 1e-6;
        t.up.iter_mut()
            .chain(t.down.iter_mut())
            .for_each(|x| *x -= c);
    }
    let u_axis = at.axis_expansion * 1e-6 * span * at.temperature_uncertainty;
    let u_instrument = at.instrument_expansion * 1e-6 * span * at.temperature_uncertainty;
    let rect = at.expansion_uncertainty / 3f64.sqrt();
    let u_expansion = span
        * 1e-6
        * ((at.axis_expansion * ds * rect).powi(2) + (at.instrument_expansion * di * rect).powi(2))
            .sqrt();
    let u = (u_axis.powi(2) + u_instrument.powi(2) + u_expansion.powi(2)).sqrt();
    Ok((
        corrected,
        TemperatureCorrection {
            at: *at,
            datum,
            per_metre,
            largest: span * per_metre * 1e-6,
            u_axis_temperature: u_axis,
            u_instrument_temperature: u_instrument,
            u_expansion,
            expanded: k.get() * u,
        },
    ))
}
