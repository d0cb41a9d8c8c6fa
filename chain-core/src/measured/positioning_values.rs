//! A positioning run as the error values of a built machine
//! (what `chain positioning` writes; docs/positioning.md, "Into a values
//! file"; docs/values.md, "Direction").
//!
//! The run measures one error motion: the positioning error of the axis, the
//! error along the axis's own direction (ISO 230-1:2012 3.4.6; `EXX` of a
//! prismatic x axis, `ECC` of a rotary C axis). [`slot`] finds and checks the
//! machine's name for it, [`values_file`] writes the run's mean deviation per
//! approach direction (`points`, `reverse_points`) and its standard deviation
//! per target (`std_points`, `reverse_std_points`) into it.
//!
//! Signs. A deviation is `P_ij − P_i` in the axis coordinate `q` (ISO
//! 230-2:2014 2.8); the error slot is a translation along (or rotation
//! about) the body's own `+x`, `+y` or `+z` after the joint moves it
//! (machine-format spec: `E(errors)` follows `J(q)`). A joint along `+x`
//! moves the body by `+q`, so the slot's value is the deviation; a joint
//! along `−x` moves it by `−q`, so the slot's value is minus the deviation.
//! Either way the ↑ direction (approached with `q` increasing) is the
//! table's main values.

use serde::Serialize;

use super::positioning::{AxisKind, PositioningDocument, Unit};
use crate::diagnostic::closest;
use crate::model::{JointKind, Machine};
use crate::values::{motion_variable, NotAMotion};

/// The name a positioning run is written into, and the axis it belongs to.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PositioningSlot {
    /// The error motion or function slot (`EXX`).
    pub name: String,
    /// The axis variable (`x`).
    pub variable: String,
    /// The body the joint moves.
    pub body: String,
    /// The joint's signed axis (`+x`).
    pub axis: String,
    /// The error slot that holds it (`dx`, or `ez` for a rotary axis about z).
    pub slot: &'static str,
    /// `+1` or `−1`: the slot's value per unit of deviation (the joint
    /// axis's sign).
    pub sign: f64,
}

/// Why a name cannot take a positioning run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[cfg_attr(feature = "miette", derive(miette::Diagnostic))]
pub enum SlotError {
    /// Not a name of the machine.
    #[error("`{name}` is not an error parameter or function slot of machine `{machine}`{}", suggestion.as_ref().map(|s| format!(" (did you mean `{s}`?)")).unwrap_or_default())]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::positioning::unknown_slot)))]
    Unknown {
        /// The name given.
        name: String,
        /// The machine.
        machine: String,
        /// The closest name.
        suggestion: Option<String>,
    },
    /// Not an error motion along an axis.
    #[error("`{name}` cannot take a positioning run: {reason}")]
    #[cfg_attr(
        feature = "miette",
        diagnostic(
            code(chain::positioning::not_a_motion),
            help("a positioning run is an error motion: the error in the `errors` of one jointed body along (or about) its own joint axis")
        )
    )]
    NotAMotion {
        /// The name.
        name: String,
        /// Why.
        reason: NotAMotion,
    },
    /// A function slot without a constant term (it cannot take a table).
    #[error("`{name}` cannot take a positioning run: its basis has no constant term, so it cannot follow a measured curve (docs/values.md)")]
    #[cfg_attr(
        feature = "miette",
        diagnostic(code(chain::positioning::no_constant_term))
    )]
    NoConstantTerm {
        /// The name.
        name: String,
    },
    /// An error motion of the axis, but not along its direction.
    #[error("`{name}` is in the `{slot}` slot of body `{body}`, whose joint moves along {axis}: the positioning error of that axis is its `{expected}` slot{}", alternatives.is_empty().then(String::new).unwrap_or_else(|| format!(" ({})", alternatives.join(", "))))]
    #[cfg_attr(
        feature = "miette",
        diagnostic(
            code(chain::positioning::not_along_axis),
            help("a positioning run measures the error along the axis's own direction (ISO 230-1 EXX, EYY, EZZ; ECC for a rotary C axis); straightness and angular errors need other instruments")
        )
    )]
    NotAlongAxis {
        /// The name.
        name: String,
        /// The body.
        body: String,
        /// Its slot.
        slot: &'static str,
        /// The joint's signed axis.
        axis: String,
        /// The slot a positioning error goes in.
        expected: &'static str,
        /// The names in that slot, if any (`EXX in dx`).
        alternatives: Vec<String>,
    },
    /// A linear run for a rotary axis or the other way round.
    #[error("`{name}` is an error of the {joint} axis `{variable}`, but the runs are of a {} axis", runs.name())]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::positioning::axis_kind)))]
    KindMismatch {
        /// The name.
        name: String,
        /// The variable.
        variable: String,
        /// `prismatic` or `rotary`.
        joint: &'static str,
        /// The kind of axis the runs were read as.
        runs: AxisKind,
    },
}

/// The machine's name `name` as the positioning error of the axis the runs
/// of `kind` were taken on.
/// (The error is boxed: its largest variant carries the names of a slot.)
pub fn slot(
    machine: &Machine,
    name: &str,
    kind: AxisKind,
) -> Result<PositioningSlot, Box<SlotError>> {
    let m = machine;
    // The error the table writes (a function slot's constant coefficient).
    let (error, variable) = if let Some(fi) = m.function_index(name) {
        let f = &m.functions[fi];
        let Some(&(j0, _)) = f.coefficients.iter().find(|(_, b)| b.is_constant()) else {
            return Err(Box::new(SlotError::NoConstantTerm {
                name: name.to_string(),
            }));
        };
        (j0, f.variable)
    } else {
        let Some(j) = m.error_index(name) else {
            let names = (m.errors.iter().map(|e| e.name.as_str()))
                .chain(m.functions.iter().map(|f| f.name.as_str()));
            return Err(Box::new(SlotError::Unknown {
                name: name.to_string(),
                machine: m.name.clone(),
                suggestion: closest(name, names).map(str::to_string),
            }));
        };
        match motion_variable(m, j) {
            Ok(v) => (j, v),
            Err(reason) => {
                return Err(Box::new(SlotError::NotAMotion {
                    name: name.to_string(),
                    reason,
                }))
            }
        }
    };
    let holds = |b: &&crate::model::Body| b.errors.slots.iter().any(|s| s.contains(&error));
    let body = (m.bodies.iter())
        .filter(|b| b.joint.as_ref().is_some_and(|j| j.variable == variable))
        .find(holds)
        .ok_or_else(|| {
            Box::new(SlotError::NotAMotion {
                name: name.to_string(),
                reason: NotAMotion::Squareness,
            })
        })?;
    let joint = body.joint.as_ref().expect("found by its joint");
    let (joint_kind, runs_kind) = match (joint.kind, kind) {
        (JointKind::Prismatic, AxisKind::Linear) | (JointKind::Rotary, AxisKind::Rotary) => {
            (None, None)
        }
        (j, k) => (Some(j), Some(k)),
    };
    if let (Some(j), Some(k)) = (joint_kind, runs_kind) {
        return Err(Box::new(SlotError::KindMismatch {
            name: name.to_string(),
            variable: m.variables[variable].name.clone(),
            joint: match j {
                JointKind::Prismatic => "prismatic",
                JointKind::Rotary => "rotary",
            },
            runs: k,
        }));
    }
    let offset = if joint.kind == JointKind::Prismatic {
        0
    } else {
        3
    };
    let expected = crate::model::Slot::ALL[offset + joint.axis.axis.index()];
    let at = (crate::model::Slot::ALL.iter())
        .find(|s| body.errors.slots[s.index()].contains(&error))
        .copied()
        .expect("the body holds it");
    if at != expected {
        return Err(Box::new(SlotError::NotAlongAxis {
            name: name.to_string(),
            body: body.name.clone(),
            slot: at.name(),
            axis: joint.axis.to_string(),
            expected: expected.name(),
            alternatives: body.errors.slots[expected.index()]
                .iter()
                .map(|&j| match m.coefficient_of(j) {
                    Some((f, _)) => format!("`{}` is there", f.name),
                    None => format!("`{}` is there", m.errors[j].name),
                })
                .collect(),
        }));
    }
    Ok(PositioningSlot {
        name: name.to_string(),
        variable: m.variables[variable].name.clone(),
        body: body.name.clone(),
        axis: joint.axis.to_string(),
        slot: expected.name(),
        sign: joint.axis.sign(),
    })
}

/// A number as the shortest text that reads back to the same `f64`.
fn num(v: f64) -> String {
    let v = if v == 0.0 { 0.0 } else { v }; // no `-0`
    format!("{v:?}")
}

/// The values file of one positioning run in `slot` (measured-machines spec
/// section 2 with the direction keys of docs/values.md): the mean deviation
/// per target approached moving up (`points`) and down (`reverse_points`),
/// and `s↑`, `s↓` (`std_points`, `reverse_std_points`); deviations in µm
/// (arcseconds on a rotary axis), positions in the machine's units (mm, or
/// radians: the run's degrees converted). `runs` names the run file.
pub fn values_file(
    doc: &PositioningDocument,
    machine: &Machine,
    slot: &PositioningSlot,
    runs: &str,
) -> String {
    use std::fmt::Write;
    let (unit, scale, units) = match doc.unit {
        Unit::Mm => ("µm", 1000.0, "{linear: um}"),
        Unit::Arcsec => ("arcsec", 1.0, "{angular: arcsec}"),
    };
    let position = |p: f64| match doc.unit {
        Unit::Mm => p,
        Unit::Arcsec => p.to_radians(),
    };
    let list = |f: &dyn Fn(&super::positioning::TargetStats) -> f64, signed: bool| {
        let items: Vec<String> = (doc.targets.iter())
            .map(|t| {
                let sign = if signed { slot.sign } else { 1.0 };
                format!(
                    "[{}, {}]",
                    num(position(t.target)),
                    num(sign * f(t) * scale)
                )
            })
            .collect();
        format!("[{}]", items.join(", "))
    };
    let mut out = String::new();
    let _ = writeln!(
        out,
        "# written by chain positioning from {runs}: ISO 230-2:2014, {} targets, {} runs per direction",
        doc.targets.len(),
        doc.runs
    );
    let _ = writeln!(
        out,
        "# {}: the positioning error of axis `{}` (body `{}`, joint along {}, slot {})",
        slot.name, slot.variable, slot.body, slot.axis, slot.slot
    );
    let _ = writeln!(
        out,
        "#   points: mean deviation approached moving up (x̄↑), reverse_points: moving down (x̄↓);"
    );
    let _ = writeln!(
        out,
        "#   std_points, reverse_std_points: their run-to-run standard deviations s↑, s↓ (n − 1)"
    );
    let _ = writeln!(
        out,
        "#   values in {unit}{}; positions in {}",
        if slot.sign < 0.0 {
            ", negated: the joint moves along its axis's negative direction"
        } else {
            ""
        },
        match doc.unit {
            Unit::Mm => "mm",
            Unit::Arcsec => "rad (the run's targets in degrees, converted)",
        }
    );
    let _ = writeln!(out, "machine: '{}'", machine.name.replace('\'', "''"));
    let _ = writeln!(
        out,
        "description: 'ISO 230-2 positioning of {} from {}'",
        slot.variable,
        runs.replace('\'', "''")
    );
    let _ = writeln!(out, "units: {units}");
    let _ = writeln!(out, "values:");
    let _ = writeln!(out, "  {}:", slot.name);
    let _ = writeln!(out, "    points: {}", list(&|t| t.mean_up, true));
    let _ = writeln!(out, "    reverse_points: {}", list(&|t| t.mean_down, true));
    let _ = writeln!(out, "    std_points: {}", list(&|t| t.s_up, false));
    let _ = writeln!(
        out,
        "    reverse_std_points: {}",
        list(&|t| t.s_down, false)
    );
    out
}
