//! Klipper `[skew_correction]` factors (`docs/export-controllers.md`,
//! Klipper section; source: `klippy/extras/skew_correction.py`,
//! `docs/Skew_Correction.md`, `docs/G-Codes.md` of Klipper).
//!
//! Klipper's model of a skewed machine (`calc_unskew`) is a shear of the
//! commanded coordinates `K`: the tool lands at
//! `(K_x + xy·K_y + xz·K_z, K_y + yz·K_z, K_z)`, and `calc_skew`, its exact
//! inverse, is applied to every commanded position. chain's coordinates
//! `K` are the tool point's nominal motion, `K = J q` (the axis variables,
//! each along its frame axis with its sign). chain's squareness errors are
//! constant small rotations of the axes' bodies: a `squareness` term (after
//! the joint: it tilts the travel of the axes below the body, vmc3's `EC0Y`
//! tilts X against Y) or an angular `location_errors` term (before the joint:
//! it tilts the body's own travel, vmc3's `EA0Z`, `EB0Z` tilt Z). Their
//! tool-point error is affine in `q`; the factors are its shear part,
//! `xy = ∂e_x/∂K_y`, `xz = ∂e_x/∂K_z`, `yz = ∂e_y/∂K_z` (derived from the
//! model's exact coefficients, so the mapping to each squareness name is the
//! model's own and is written into the file). The rest of the squareness
//! error (an offset such as a tilted tool's `−L·EB0Z`, the other shear
//! entries, the orientation) stays.

use super::{num, Context, ControllerError, Export};
use crate::compensation::{opening_line, Correction, ExportedFile};
use crate::model::{ErrorKind, Machine};
use crate::model_trait::{ErrorModel, OutOfRange};
use serde::Serialize;

/// Klipper's three skew factors (tangents; Klipper calls them radians).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SkewFactors {
    /// `xy_skew`.
    pub xy: f64,
    /// `xz_skew`.
    pub xz: f64,
    /// `yz_skew`.
    pub yz: f64,
}

impl SkewFactors {
    /// `calc_skew` (`skew_correction.py`): the position Klipper sends to the
    /// kinematics for commanded `K`.
    pub fn skew(&self, k: [f64; 3]) -> [f64; 3] {
        [
            k[0] - k[1] * self.xy - k[2] * (self.xz - self.xy * self.yz),
            k[1] - k[2] * self.yz,
            k[2],
        ]
    }
}

/// `SET_SKEW` lengths `(AC, BD, AD)` on a square of side `l` that make
/// Klipper's `calc_skew_factor` return `f`: `cos θ = f/√(1 + f²)`,
/// `AC = l·√(2 + 2 cos θ)`, `BD = l·√(2 − 2 cos θ)`, `AD = l`
/// (parallelogram law; `docs/export-controllers.md`).
pub fn set_skew_lengths(f: f64, l: f64) -> [f64; 3] {
    let c = f / (1.0 + f * f).sqrt();
    [l * (2.0 + 2.0 * c).sqrt(), l * (2.0 - 2.0 * c).sqrt(), l]
}

/// What Klipper adds to the commanded axes: `J⁻¹ (calc_skew(J q) − J q)`.
#[derive(Debug, Clone, PartialEq)]
pub struct KlipperCorrection {
    /// Per Klipper axis X, Y, Z: the machine variable and its sign.
    pub axes: [(usize, f64); 3],
    /// The factors.
    pub factors: SkewFactors,
}

impl Correction for KlipperCorrection {
    fn delta(&self, q: &[f64], delta: &mut [f64]) -> Result<(), OutOfRange> {
        for d in delta.iter_mut() {
            *d = 0.0;
        }
        let k: [f64; 3] = std::array::from_fn(|i| self.axes[i].1 * q[self.axes[i].0]);
        let s = self.factors.skew(k);
        for i in 0..3 {
            delta[self.axes[i].0] = self.axes[i].1 * (s[i] - k[i]);
        }
        Ok(())
    }
}

/// The errors Klipper's factors are made of, in the machine's error order:
/// every `squareness` term, and the angular `location_errors` (`ex, ey, ez`
/// before the joint: a tilt of the travel direction) of the axes' `bodies`.
/// Translational location errors are offsets (no shear); a function slot's
/// coefficient is not a constant angle.
fn squareness_errors<'m>(machine: &'m Machine, bodies: &[usize]) -> Vec<&'m str> {
    let located: Vec<usize> = bodies
        .iter()
        .flat_map(|&b| {
            machine.bodies[b].location_errors.slots[3..]
                .iter()
                .flatten()
                .copied()
        })
        .collect();
    machine
        .errors
        .iter()
        .enumerate()
        .filter(|(j, e)| {
            machine.coefficient_of(*j).is_none()
                && (e.kind == ErrorKind::Squareness || located.contains(j))
        })
        .map(|(_, e)| e.name.as_str())
        .collect()
}

pub(super) fn export<M: ErrorModel + Sync>(
    ctx: &Context<'_, M>,
) -> Result<Export, ControllerError> {
    let axes: [(usize, f64); 3] = std::array::from_fn(|k| {
        let a = ctx
            .axis_along(k)
            .expect("three aligned axes, one per frame axis");
        (a.variable, a.sign)
    });
    let bodies: Vec<usize> = ctx.axes.iter().map(|a| a.body).collect();
    let squareness = squareness_errors(ctx.machine, &bodies);
    if squareness.is_empty() {
        return Err(ControllerError::NothingToExport {
            controller: ctx.name(),
            what: "skew factors from the squareness errors",
            machine: ctx.machine.name.clone(),
        });
    }
    // Per squareness error, its factors per unit value: the derivative of
    // its tool-point coefficient along K_y and K_z, over the travel (the
    // coefficient is affine in q for prismatic axes).
    let per_unit = |name: &str| -> SkewFactors {
        let slope = |k: usize, comp: usize| {
            let (v, sign) = axes[k];
            let a = &ctx.axes[v];
            let (lo, hi) = (a.nodes[0], a.nodes[a.nodes.len() - 1]);
            let mut q = ctx.reference.clone();
            q[v] = lo;
            let c0 = ctx.coefficient(name, &q)[comp];
            q[v] = hi;
            let c1 = ctx.coefficient(name, &q)[comp];
            (c1 - c0) / (sign * (hi - lo))
        };
        SkewFactors {
            xy: slope(1, 0),
            xz: slope(2, 0),
            yz: slope(2, 1),
        }
    };
    let units: Vec<(String, SkewFactors)> = squareness
        .iter()
        .map(|n| (n.to_string(), per_unit(n)))
        .collect();
    let parts = ctx
        .parts(&ctx.reference)
        .map_err(|e| ControllerError::OutOfTable {
            variable: e.variable.clone(),
            lo: e.value,
            hi: e.value,
            source: Box::new(e),
        })?;
    let value = |n: &str| {
        parts
            .iter()
            .find(|p| p.name == n)
            .map(|p| p.value)
            .unwrap_or(0.0)
    };
    let mut f = SkewFactors {
        xy: 0.0,
        xz: 0.0,
        yz: 0.0,
    };
    for (n, u) in &units {
        let v = value(n);
        f.xy += u.xy * v;
        f.xz += u.xz * v;
        f.yz += u.yz * v;
    }
    let formula = |pick: &dyn Fn(&SkewFactors) -> f64| {
        let terms: Vec<String> = units
            .iter()
            .filter(|(_, u)| pick(u).abs() > 1e-12)
            .map(|(n, u)| format!("{}·{n}", num(pick(u))))
            .collect();
        if terms.is_empty() {
            "0 (no squareness error of the machine acts here)".to_string()
        } else {
            terms.join(" + ")
        }
    };
    let var = |k: usize| &ctx.machine.variables[axes[k].0].name;
    let mut text = String::from("[skew_correction]\n\n[skew_correction chain]\n");
    text.push_str(&format!(
        "# {}\n",
        opening_line(
            &ctx.options.provenance,
            &format!(
                "machine `{}`; load with SKEW_PROFILE LOAD=chain (after homing)",
                ctx.machine.name
            )
        )
    ));
    text.push_str(&format!(
        "# Klipper X, Y, Z = the machine's axes `{}`, `{}`, `{}` (tool motion along the workpiece frame's X, Y, Z)\n",
        var(0),
        var(1),
        var(2)
    ));
    text.push_str("# factors: tangents (Klipper's \"radians\"), Klipper's shear: the tool lands at (x + xy*y + xz*z, y + yz*z, z) uncorrected\n");
    text.push_str("# sign: error = actual - nominal; from chain's model of the squareness errors (values in rad):\n");
    text.push_str(&format!("#   xy_skew = {}\n", formula(&|u| u.xy)));
    text.push_str(&format!("#   xz_skew = {}\n", formula(&|u| u.xz)));
    text.push_str(&format!("#   yz_skew = {}\n", formula(&|u| u.yz)));
    for (plane, v) in [("XY", f.xy), ("XZ", f.xz), ("YZ", f.yz)] {
        let [ac, bd, ad] = set_skew_lengths(v, 100.0);
        text.push_str(&format!(
            "# the same as a command: SET_SKEW {plane}={ac:.9},{bd:.9},{ad:.0}\n"
        ));
    }
    text.push_str(&format!(
        "xy_skew = {}\nxz_skew = {}\nyz_skew = {}\n",
        num(f.xy),
        num(f.xz),
        num(f.yz)
    ));
    let files = vec![ExportedFile {
        name: "skew_correction.cfg".into(),
        text,
    }];
    let accounting = ctx.account(
        &|q, part| {
            let (_, u) = units.iter().find(|(n, _)| *n == part.name)?;
            let k: [f64; 3] = std::array::from_fn(|i| axes[i].1 * q[axes[i].0]);
            let v = part.value;
            Some([
                v * (u.xy * k[1] + u.xz * k[2]),
                v * u.yz * k[2],
                0.0,
                0.0,
                0.0,
                0.0,
            ])
        },
        &|_, _| None,
    )?;
    let correction = KlipperCorrection { axes, factors: f };
    Ok(ctx.finish(files, accounting, 0.0, Box::new(correction)))
}
