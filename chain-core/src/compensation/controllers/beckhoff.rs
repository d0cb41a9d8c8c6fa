//! Beckhoff TwinCAT CNC (TF5280) / ISG volumetric compensation tables in
//! `ISG_CSV` form (`docs/export-controllers.md`, Beckhoff section; sources:
//! the ISG kernel / Beckhoff Infosys pages "Volumetric compensation",
//! "ISG_CSV format", "List of parameters supported").
//!
//! `chain_volcomp.csv` holds the ISO 230-1 error parameters (not
//! corrections): a block of single values (squareness and location errors,
//! named `<direction>0<axis>`, e.g. `C0Y` for chain's squareness `ez` on the
//! Y axis' body), then one table per linear axis, argument column first
//! (`X EXX EYX EZX EAX EBX ECX`), blocks separated by `#` file breaks,
//! comments `//`; values in mm and rad, arguments in mm. `vol_comp_0.lis` is
//! the list file that names it. The controller computes the tool-point
//! position error from its parametric model and corrects the axis setpoints;
//! it does not correct the tool orientation. [`BeckhoffCorrection`] emulates
//! that with chain's model of the machine fed by the exported tables, read
//! linearly (`Interpolation GRID`); that ISG's model and sign equal chain's
//! is UNCONFIRMED (`negate XYZ` in the list file flips it).

#![allow(clippy::needless_range_loop)] // component loops read best with indices

use super::{num, Context, ControllerError, Export, LinearAxis, AXIS, SLOT_LETTER};
use crate::built::BuiltMachine;
use crate::compensation::{opening_line, Correction, ExportedFile};
use crate::eval::CompiledModel;
use crate::kinematics::forward::Kinematics;
use crate::model::{Frame, JointKind};
use crate::model_trait::{ErrorModel, OutOfRange};
use crate::values::{Extrapolation, Interpolation, Table, ValuesBuilder};
use nalgebra::{Matrix3, Vector3};

/// What the controller adds to the commanded linear axes: `δq = −J⁻¹
/// Ê_p(q)`, `J` the nominal Jacobian of the tool point's position in the
/// linear axes at `q` and `Ê` the tool-point error of chain's model with the
/// exported values (the tables read linearly), at the commanded position
/// (first order); the rotary axes are left as commanded (TF5280 "only
/// compensates for tool position"). A position outside the tables is
/// refused (the vendor's behaviour there is not documented).
pub struct BeckhoffCorrection {
    built: BuiltMachine<CompiledModel>,
    /// The nominal kinematics and their parameters.
    kin: Kinematics,
    params: Vec<f64>,
    /// The error is in the tool's frame (the machine file's `frame: tool`).
    tool_frame: bool,
    /// The linear variables (machine order).
    linear: Vec<usize>,
    /// Machine variable index → built variable index.
    to_built: Vec<usize>,
}

impl BeckhoffCorrection {
    /// The machine as the controller sees it (the exported values).
    pub fn built(&self) -> &BuiltMachine<CompiledModel> {
        &self.built
    }

    /// `Ê(q)` at machine-ordered `q`.
    pub fn error(&self, q: &[f64]) -> Result<[f64; 6], OutOfRange> {
        let mut qb = vec![0.0; q.len()];
        for (i, &b) in self.to_built.iter().enumerate() {
            qb[b] = q[i];
        }
        self.built.error(&qb)
    }
}

impl Correction for BeckhoffCorrection {
    fn delta(&self, q: &[f64], delta: &mut [f64]) -> Result<(), OutOfRange> {
        let e = self.error(q)?;
        let jac = self.kin.jacobian(q, &self.params);
        let rot = self.kin.pose(q, &self.params).rotation;
        let mut j = Matrix3::zeros();
        for (c, &v) in self.linear.iter().enumerate() {
            for r in 0..3 {
                j[(r, c)] = match self.tool_frame {
                    false => jac[v][r],
                    true => (0..3).map(|k| rot[k][r] * jac[v][k]).sum(),
                };
            }
        }
        let x = j
            .try_inverse()
            .map(|inv| inv * -Vector3::new(e[0], e[1], e[2]))
            .unwrap_or_else(|| Vector3::repeat(f64::NAN));
        delta.iter_mut().for_each(|d| *d = 0.0);
        for (c, &v) in self.linear.iter().enumerate() {
            delta[v] = x[c];
        }
        Ok(())
    }
}

/// An axis's letter in ISG's names: X, Y, Z for a linear axis, A, B, C for
/// a rotary one.
fn letter_of(axis: &LinearAxis) -> char {
    match axis.rotary {
        false => AXIS[axis.frame_axis],
        true => ['A', 'B', 'C'][axis.frame_axis],
    }
}

/// The axes from the workpiece to the tool (ISG's `chain`) and how many of
/// them carry the workpiece (`workpiece_axes`).
fn kinematic_chain<'c, M>(ctx: &'c Context<'_, M>) -> (Vec<&'c LinearAxis>, usize) {
    let m = ctx.machine;
    let on = |bodies: &[usize]| -> Vec<&'c LinearAxis> {
        (bodies.iter())
            .filter_map(|b| ctx.axes.iter().find(|a| a.body == *b))
            .collect()
    };
    let mut workpiece = m.path_from_root(m.workpiece);
    workpiece.reverse();
    let mut chain = on(&workpiece);
    let count = chain.len();
    chain.extend(on(&m.path_from_root(m.tool)));
    (chain, count)
}

pub(super) fn export<M: ErrorModel + Sync>(
    ctx: &Context<'_, M>,
) -> Result<Export, ControllerError> {
    let m = ctx.machine;
    // Single values: squareness and location errors of the axes' bodies.
    let mut singles: Vec<(String, String)> = Vec::new(); // (ISG name, chain name)
    for axis in &ctx.axes {
        let body = &m.bodies[axis.body];
        let groups = [&body.location_errors.slots, &body.errors.slots];
        for (g, slots) in groups.iter().enumerate() {
            for (s, slot) in slots.iter().enumerate() {
                for &j in slot {
                    let e = &m.errors[j];
                    let single = if g == 0 {
                        true
                    } else {
                        e.kind == crate::model::ErrorKind::Squareness
                    };
                    if !single {
                        continue;
                    }
                    let isg = format!("{}0{}", SLOT_LETTER[s], letter_of(axis));
                    if let Some((_, other)) =
                        singles.iter().find(|(n, c)| *n == isg && *c != e.name)
                    {
                        return Err(ControllerError::NameClash {
                            controller: ctx.name(),
                            name: isg,
                            first: other.clone(),
                            second: e.name.clone(),
                        });
                    }
                    if !singles.iter().any(|(_, c)| *c == e.name) {
                        singles.push((isg, e.name.clone()));
                    }
                }
            }
        }
    }
    let mut records = usize::from(!singles.is_empty());
    let reference = ctx.parts(&ctx.reference).map_err(|e| {
        let a = &ctx.axes[m.variable_index(&e.variable).unwrap_or(0)];
        ControllerError::OutOfTable {
            variable: a.name.clone(),
            lo: a.nodes[0],
            hi: a.nodes[a.nodes.len() - 1],
            source: Box::new(e),
        }
    })?;
    let value_of = |parts: &[crate::built::Part], n: &str| {
        parts
            .iter()
            .find(|p| p.name == n)
            .map(|p| p.value)
            .unwrap_or(0.0)
    };
    let mut csv = String::new();
    csv.push_str(&format!(
        "// {}\n",
        opening_line(
            &ctx.options.provenance,
            &format!(
                "machine `{}`, ISG_CSV volumetric compensation parameters",
                m.name
            )
        )
    ));
    csv.push_str("// ISO 230-1 error parameters, error = actual - nominal (not corrections): the controller derives the corrections\n");
    csv.push_str("// (sign convention of ISG's model UNCONFIRMED: if the compensation doubles the error, set `negate XYZ` in the list file)\n");
    csv.push_str("// units: values mm (linear) and rad (angular); arguments X, Y, Z in mm, A, B, C in degrees; tables read linearly (Interpolation GRID)\n");
    let mut builder = ValuesBuilder::new(m);
    let mut exported: Vec<String> = Vec::new();
    if !singles.is_empty() {
        csv.push_str("// single values (squareness / location errors): ");
        csv.push_str(
            &singles
                .iter()
                .map(|(i, c)| format!("{i} = {c}"))
                .collect::<Vec<_>>()
                .join(", "),
        );
        csv.push('\n');
        csv.push_str(
            &singles
                .iter()
                .map(|(i, _)| i.as_str())
                .collect::<Vec<_>>()
                .join(" "),
        );
        csv.push('\n');
        let vals: Vec<String> = singles
            .iter()
            .map(|(_, c)| num(value_of(&reference, c)))
            .collect();
        csv.push_str(&vals.join(" "));
        csv.push('\n');
        for (_, c) in &singles {
            // The machine's own names: accepted by construction.
            let _ = builder.constant(c, value_of(&reference, c));
            exported.push(c.clone());
        }
    }
    for axis in &ctx.axes {
        let along = ctx.along(axis)?;
        let letter = letter_of(axis);
        // The argument: mm, or degrees for a rotary axis (ISG: "in degrees
        // (e.g. [0°, 360°]) for rotation axes").
        let (unit, arg) = match axis.rotary {
            false => ("mm", 1.0),
            true => ("deg", 180.0 / std::f64::consts::PI),
        };
        csv.push_str("#\n");
        let columns: Vec<(String, Option<&str>)> = (0..6)
            .map(|s| {
                (
                    format!("E{}{letter}", SLOT_LETTER[s]),
                    axis.motions
                        .iter()
                        .find(|mo| mo.slot == s)
                        .map(|mo| mo.name.as_str()),
                )
            })
            .collect();
        let mapped: Vec<String> = columns
            .iter()
            .filter_map(|(c, n)| n.map(|n| format!("{c} = {n}")))
            .collect();
        csv.push_str(&format!(
            "// axis {letter}: machine axis `{}`, {} to {} {unit} at {} {unit}; {}{}\n",
            axis.name,
            num(axis.nodes[0] * arg),
            num(axis.nodes[axis.nodes.len() - 1] * arg),
            num(axis.step * arg),
            mapped.join(", "),
            match mapped.len() {
                0 => "no error motion in the machine's model (0)",
                6 => "",
                _ => "; the other columns: not in the machine's model (0)",
            }
        ));
        csv.push(letter);
        for (c, _) in &columns {
            csv.push(' ');
            csv.push_str(c);
        }
        csv.push('\n');
        for (x, parts) in axis.nodes.iter().zip(&along) {
            csv.push_str(&num(*x * arg));
            for (_, n) in &columns {
                csv.push(' ');
                csv.push_str(&num(n.map(|n| value_of(parts, n)).unwrap_or(0.0)));
            }
            csv.push('\n');
        }
        records += axis.nodes.len();
        for (_, n) in &columns {
            if let Some(n) = n {
                let points: Vec<(f64, f64)> = axis
                    .nodes
                    .iter()
                    .zip(&along)
                    .map(|(x, p)| (*x, value_of(p, n)))
                    .collect();
                if let Ok(t) = Table::new(points, Interpolation::Linear, Extrapolation::Error) {
                    let _ = builder.table(n, t, &format!("chain_volcomp.csv, column E..{letter}"));
                }
                exported.push(n.to_string());
            }
        }
    }
    if records > ctx.options.beckhoff_max_records {
        let a = &ctx.axes[0];
        return Err(ControllerError::TooManyPoints {
            controller: "Beckhoff vol_comp[i].max_records",
            variable: a.name.clone(),
            lo: a.nodes[0],
            hi: a.nodes[a.nodes.len() - 1],
            step: a.step,
            points: records,
            limit: ctx.options.beckhoff_max_records,
            hint: " records in all; give a larger step or raise max_records",
        });
    }
    let mut lis = String::new();
    lis.push_str(&format!(
        "# {}\n",
        opening_line(
            &ctx.options.provenance,
            &format!(
                "machine `{}`; list file of volumetric compensation 0",
                m.name
            )
        )
    ));
    lis.push_str(&format!(
        "# start-up list (hochlauf.lis): vol_comp[0].file_name <folder>\\vol_comp_0.lis and vol_comp[0].max_records >= {records}\n"
    ));
    lis.push_str("# X, Y, Z (A, B, C): logical axis numbers = the machine file's axis variables in order (renumber to your CNC's)\n");
    let (chain, workpiece_axes) = kinematic_chain(ctx);
    lis.push_str(&format!(
        "# chain: the axes from the workpiece to the tool ({}), the first {workpiece_axes} on the workpiece side (TF5280: an XYZBC table-table machine is `CBYXZ`)\n",
        (chain.iter())
            .map(|a| format!("{} = {}", letter_of(a), a.name))
            .collect::<Vec<_>>()
            .join(", ")
    ));
    lis.push_str("# switch on in NC code: #VOLCOMP ON [ID0]; reload after an update: #VOLCOMP OFF [ID0], #VOLCOMP [ID0 UPDATE]\n");
    for rotary in [false, true] {
        for k in 0..3 {
            let axis = (ctx.axes.iter()).find(|a| a.frame_axis == k && a.rotary == rotary);
            if let Some(a) = axis {
                lis.push_str(&format!("{:<24} {}\n", letter_of(a), a.variable + 1));
            }
        }
    }
    let letters: String = chain.iter().map(|a| letter_of(a)).collect();
    lis.push_str(&format!("{:<24} {letters}\n", "chain"));
    lis.push_str(&format!("{:<24} {workpiece_axes}\n", "workpiece_axes"));
    lis.push_str(&format!("{:<24} GRID\n", "Interpolation"));
    lis.push_str(&format!("{:<24} chain_volcomp.csv\n", "file[0]"));
    lis.push_str(&format!("{:<24} ISG_CSV\n", "file_format[0]"));
    let files = vec![
        ExportedFile {
            name: "vol_comp_0.lis".into(),
            text: lis,
        },
        ExportedFile {
            name: "chain_volcomp.csv".into(),
            text: csv,
        },
    ];
    // The controller's view: chain's model with the exported values.
    let params: Vec<f64> = m
        .parameters
        .iter()
        .map(|p| {
            ctx.built
                .model()
                .parameters()
                .iter()
                .position(|n| *n == p.name)
                .map(|k| ctx.built.parameters()[k])
                .unwrap_or(f64::NAN)
        })
        .collect();
    let seen = BuiltMachine::compile(m, builder.build(), params)
        .expect("the machine's own values and parameters");
    let to_built: Vec<usize> = m
        .variables
        .iter()
        .map(|v| {
            seen.variables()
                .iter()
                .position(|b| *b == v.name)
                .unwrap_or(0)
        })
        .collect();
    let kin = Kinematics::from_machine(m);
    let correction = BeckhoffCorrection {
        params: crate::compensation::kinematics_parameters(&kin, ctx.built),
        kin,
        tool_frame: m.frame == Frame::Tool,
        built: seen,
        linear: (0..m.variables.len())
            .filter(|&v| m.variables[v].kind == JointKind::Prismatic)
            .collect(),
        to_built,
    };
    // Resampling: the controller's position error against the exported
    // terms' own, at the midpoints between nodes.
    let mut resampling: f64 = 0.0;
    for axis in &ctx.axes {
        let mut q = ctx.reference.clone();
        for (w, parts) in axis.nodes.windows(2).zip(ctx.midpoints(axis)?) {
            q[axis.variable] = 0.5 * (w[0] + w[1]);
            let e = correction
                .error(&q)
                .map_err(|e| ControllerError::OutOfTable {
                    variable: axis.name.clone(),
                    lo: axis.nodes[0],
                    hi: axis.nodes[axis.nodes.len() - 1],
                    source: Box::new(e),
                })?;
            let mut d = [e[0], e[1], e[2]];
            for p in parts.iter().filter(|p| exported.contains(&p.name)) {
                for c in 0..3 {
                    d[c] -= p.error[c];
                }
            }
            resampling = resampling.max((d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt());
        }
    }
    let accounting = ctx.account(
        &|_, part| {
            exported
                .contains(&part.name)
                .then(|| super::translation(&part.error))
        },
        &|_, _| None,
    )?;
    Ok(ctx.finish(files, accounting, resampling, Box::new(correction)))
}
