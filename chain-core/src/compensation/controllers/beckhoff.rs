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

use super::{num, Context, ControllerError, Export, AXIS, SLOT_LETTER};
use crate::built::BuiltMachine;
use crate::compensation::{opening_line, Correction, ExportedFile};
use crate::eval::CompiledModel;
use crate::model::JointKind;
use crate::model_trait::{ErrorModel, OutOfRange};
use crate::values::{Extrapolation, Interpolation, Table, ValuesBuilder};

/// What the controller adds to the commanded axes: `δq = −J⁻¹ Ê_p(q)`,
/// `Ê` the tool-point error of chain's model with the exported values (the
/// tables read linearly), at the commanded position (first order). A
/// position outside the tables is refused (the vendor's behaviour there is
/// not documented).
pub struct BeckhoffCorrection {
    built: BuiltMachine<CompiledModel>,
    /// Per machine variable: (frame axis, sign).
    axes: Vec<(usize, f64)>,
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
        for (v, (k, s)) in self.axes.iter().enumerate() {
            delta[v] = -s * e[*k];
        }
        Ok(())
    }
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
                    let isg = format!("{}0{}", SLOT_LETTER[s], AXIS[axis.frame_axis]);
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
    csv.push_str("// units: values mm (linear) and rad (angular); arguments X, Y, Z in mm; tables read linearly (Interpolation GRID)\n");
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
        let letter = AXIS[axis.frame_axis];
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
            "// axis {letter}: machine axis `{}`, {} to {} mm at {} mm; {}{}\n",
            axis.name,
            num(axis.nodes[0]),
            num(axis.nodes[axis.nodes.len() - 1]),
            num(axis.step),
            mapped.join(", "),
            if mapped.len() < 6 {
                "; the other columns: not in the machine's model (0)"
            } else {
                ""
            }
        ));
        csv.push(letter);
        for (c, _) in &columns {
            csv.push(' ');
            csv.push_str(c);
        }
        csv.push('\n');
        for (x, parts) in axis.nodes.iter().zip(&along) {
            csv.push_str(&num(*x));
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
    lis.push_str("# X, Y, Z: logical axis numbers = the machine file's axis variables in order (renumber to your CNC's)\n");
    let workpiece_side: Vec<&str> = ctx
        .axes
        .iter()
        .filter(|a| m.path_from_root(m.workpiece).contains(&a.body))
        .map(|a| a.name.as_str())
        .collect();
    lis.push_str(&format!(
        "# `chain` and `workpiece_axes` are left at their defaults (their meaning for this layout is UNCONFIRMED); the machine's workpiece-side axes: {}\n",
        if workpiece_side.is_empty() { "none".to_string() } else { workpiece_side.join(", ") }
    ));
    lis.push_str("# switch on in NC code: #VOLCOMP ON [ID0]; reload after an update: #VOLCOMP OFF [ID0], #VOLCOMP [ID0 UPDATE]\n");
    for k in 0..3 {
        if let Some(a) = ctx.axis_along(k) {
            lis.push_str(&format!("{:<24} {}\n", AXIS[k], a.variable + 1));
        }
    }
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
    debug_assert!(m.variables.iter().all(|v| v.kind == JointKind::Prismatic));
    let correction = BeckhoffCorrection {
        built: seen,
        axes: ctx.axes.iter().map(|a| (a.frame_axis, a.sign)).collect(),
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
