//! LinuxCNC `[JOINT_n]COMP_FILE` tables (`docs/export-controllers.md`,
//! LinuxCNC section; sources: `docs/src/config/ini-config.adoc` and
//! `src/emc/motion/{usrmotintf.cc, command.c, control.c, motion.c}` of
//! LinuxCNC).
//!
//! One file per joint that has a positioning error, `COMP_FILE_TYPE = 1`:
//! lines `nominal forward_trim reverse_trim`, the trim being what LinuxCNC
//! adds to the commanded joint position (`usrmotLoadComp`: type 1 takes the
//! trims as written). chain writes `trim = −u(nominal)`, `u` the joint's
//! positioning error at the tool point (actual − nominal, along the joint's
//! own axis). LinuxCNC uses the forward trim while the joint's commanded
//! velocity is positive and the reverse trim while it is negative
//! (`control.c`, `compute_screw_comp`): when the error's table has a reverse
//! direction (docs/values.md, "Direction") the forward column is `−u↑` and
//! the reverse column `−u↓`; otherwise both are the same. LinuxCNC stops
//! reading at the first line that is not three numbers, so the comments
//! (units, sign, directions) come after the data.

use super::{
    interpolate_held, num, Context, ControllerError, DirectionReport, Export, LinearAxis, AXIS,
};
use crate::compensation::{opening_line, Correction, ExportedFile};
use crate::model_trait::{ErrorModel, OutOfRange};
use crate::values::{Approach, Given, Values};

/// What LinuxCNC adds to the commanded joints: per table, the trim
/// interpolated linearly at the commanded position and held at its end
/// values outside the table (`control.c` `compute_screw_comp`, `motion.c`'s
/// sentinels), the forward column moving up and the reverse column moving
/// down. A point has no direction of motion, so [`Correction::delta`] takes
/// the column of the approach the values were read for: forward for `up`,
/// reverse for `down`, their mean for `mean`.
#[derive(Debug, Clone, PartialEq)]
pub struct LinuxcncCorrection {
    /// Variables of the machine.
    pub variables: usize,
    /// The tables.
    pub tables: Vec<LinuxcncTable>,
}

/// One joint's `COMP_FILE`.
#[derive(Debug, Clone, PartialEq)]
pub struct LinuxcncTable {
    /// The joint (machine variable index).
    pub joint: usize,
    /// The nominal positions.
    pub nominal: Vec<f64>,
    /// The trims moving up.
    pub forward: Vec<f64>,
    /// The trims moving down.
    pub reverse: Vec<f64>,
    /// The approach the values were read for (which column `delta` uses).
    pub approach: Approach,
}

impl Correction for LinuxcncCorrection {
    fn delta(&self, q: &[f64], delta: &mut [f64]) -> Result<(), OutOfRange> {
        for d in delta.iter_mut() {
            *d = 0.0;
        }
        for t in &self.tables {
            let x = q[t.joint];
            let (f, r) = (&t.forward, &t.reverse);
            delta[t.joint] += match t.approach {
                Approach::Up => interpolate_held(&t.nominal, f, x),
                Approach::Down => interpolate_held(&t.nominal, r, x),
                Approach::Mean => {
                    0.5 * (interpolate_held(&t.nominal, f, x) + interpolate_held(&t.nominal, r, x))
                }
            };
        }
        Ok(())
    }
}

pub(super) fn export<M: ErrorModel + Sync>(
    ctx: &Context<'_, M>,
) -> Result<Export, ControllerError> {
    let mut files = Vec::new();
    let mut tables = Vec::new();
    let mut exported: Vec<(String, usize)> = Vec::new(); // (part, frame axis)
    let mut resampling: f64 = 0.0;
    let mut directions = Vec::new();
    let mut sampling = Vec::new();
    for axis in &ctx.axes {
        let Some(motion) = axis.motions.iter().find(|m| m.slot == axis.joint_axis) else {
            continue;
        };
        // LinuxCNC's nominals need not be evenly spaced: the nodes of the
        // step grid and the positions of the error's own table, so that a
        // measured (linear) table is written exactly.
        let axis = &with_table_positions(axis, ctx.built.values().table_positions(&motion.name));
        let find = |parts: &[crate::built::Part]| {
            parts
                .iter()
                .find(|p| p.name == motion.name)
                .map(|p| axis.sign * p.error[axis.frame_axis])
                .unwrap_or(0.0)
        };
        // The values read moving up and moving down, if its table has two
        // directions.
        let values = ctx.built.values();
        let model_variable = ctx.built_variable(axis.variable);
        let bidirectional = values.entries().iter().any(|e| {
            e.name == motion.name
                && matches!(
                    e.given,
                    Given::Table {
                        reverse: Some(_),
                        ..
                    }
                )
        });
        let read = |approach: Approach| {
            let mut v: Values = values.clone();
            v.set_approach(model_variable, approach);
            v
        };
        // One column per direction read; a one-direction table is read once
        // and its trims written in both columns.
        let reads: Vec<std::borrow::Cow<'_, Values>> = if bidirectional {
            vec![
                std::borrow::Cow::Owned(read(Approach::Up)),
                std::borrow::Cow::Owned(read(Approach::Down)),
            ]
        } else {
            vec![std::borrow::Cow::Borrowed(values)]
        };
        let mut columns = Vec::new();
        for v in &reads {
            let u: Vec<f64> = ctx.along_with(axis, v)?.iter().map(|p| find(p)).collect();
            let trims: Vec<f64> = u.iter().map(|v| -v).collect();
            for (w, parts) in axis.nodes.windows(2).zip(ctx.midpoints_with(axis, v)?) {
                let x = 0.5 * (w[0] + w[1]);
                let lin = -interpolate_held(&axis.nodes, &trims, x);
                resampling = resampling.max((find(&parts) - lin).abs());
            }
            columns.push(trims);
        }
        let forward = columns.remove(0);
        let reverse = columns.pop().unwrap_or_else(|| forward.clone());
        // B̄ = mean(u↑ − u↓) = mean(reverse − forward).
        let mean_reversal = (forward.iter().zip(&reverse))
            .map(|(f, r)| r - f)
            .sum::<f64>()
            / forward.len() as f64;
        if bidirectional {
            directions.push(DirectionReport {
                variable: axis.name.clone(),
                error: motion.name.clone(),
                bidirectional,
                mean_reversal,
                backlash: -mean_reversal,
            });
        }
        let joint = axis.variable;
        let mut text = String::new();
        for ((x, f), r) in axis.nodes.iter().zip(&forward).zip(&reverse) {
            text.push_str(&format!("{} {} {}\n", num(*x), num(*f), num(*r)));
        }
        let opening = format!(
            "machine `{}`, joint {joint} (axis variable `{}`, the tool moves along {}{} as it increases)",
            ctx.machine.name,
            axis.name,
            if axis.sign > 0.0 { "+" } else { "-" },
            AXIS[axis.frame_axis]
        );
        text.push_str(&format!(
            "# {}\n",
            opening_line(&ctx.options.provenance, &opening)
        ));
        text.push_str("# [JOINT_n] COMP_FILE_TYPE = 1: columns nominal (commanded joint position) | trim moving + | trim moving -\n");
        text.push_str(&format!(
            "# trim = -u, u = the positioning error `{}` seen at the tool point along the joint's axis (actual - nominal); LinuxCNC adds the trim to the command\n",
            motion.name
        ));
        if bidirectional {
            text.push_str(&format!(
                "# units: machine units, mm; step {} mm; held at the end values outside {} to {}\n",
                num(axis.step),
                num(axis.nodes[0]),
                num(axis.nodes[axis.nodes.len() - 1])
            ));
            text.push_str(&format!(
                "# directions: forward = -u approached moving up, reverse = -u approached moving down (the values' `{}` and its reverse direction); mean reversal at the tool point {} mm\n",
                motion.name,
                num(mean_reversal)
            ));
        } else {
            text.push_str(&format!(
                "# units: machine units, mm; step {} mm; the same trim both directions (no reversal data); held at the end values outside {} to {}\n",
                num(axis.step),
                num(axis.nodes[0]),
                num(axis.nodes[axis.nodes.len() - 1])
            ));
        }
        text.push_str("# these comments must stay below the data: LinuxCNC stops reading at the first line that is not three numbers\n");
        if axis.nodes.len() > super::LINUXCNC_MAX_POINTS {
            return Err(ControllerError::TooManyPoints {
                controller: "LinuxCNC (EMCMOT_COMP_SIZE)",
                variable: axis.name.clone(),
                lo: axis.nodes[0],
                hi: axis.nodes[axis.nodes.len() - 1],
                step: axis.step,
                points: axis.nodes.len(),
                limit: super::LINUXCNC_MAX_POINTS,
                hint: "; give a larger step",
            });
        }
        files.push(ExportedFile {
            name: format!("{}.comp", axis.name),
            text,
        });
        sampling.push((axis.variable, axis.nodes.len()));
        tables.push(LinuxcncTable {
            joint: axis.variable,
            nominal: axis.nodes.clone(),
            forward,
            reverse,
            approach: values.approaches()[model_variable],
        });
        exported.push((motion.name.clone(), axis.frame_axis));
    }
    if tables.is_empty() {
        return Err(ControllerError::NothingToExport {
            controller: ctx.name(),
            what: "a COMP_FILE per joint from its positioning error (the error slot along the joint's own axis)",
            machine: ctx.machine.name.clone(),
        });
    }
    let mut readme = format!(
        "{}\n\nOne COMP_FILE per joint that has a positioning error. In the INI file:\n\n",
        opening_line(
            &ctx.options.provenance,
            &format!("machine `{}`", ctx.machine.name)
        )
    );
    for t in &tables {
        let name = &ctx.machine.variables[t.joint].name;
        readme.push_str(&format!(
            "[JOINT_{}]\nCOMP_FILE = {name}.comp\nCOMP_FILE_TYPE = 1\n",
            t.joint
        ));
        if let Some(d) = directions.iter().find(|d| d.variable == *name) {
            readme.push_str(&format!(
                "# forward and reverse columns from the two approach directions of `{}`; without the COMP_FILE, BACKLASH = {} would correct the mean reversal alone\n",
                d.error,
                num(d.backlash)
            ));
        }
        readme.push('\n');
    }
    readme.push_str(
        "Joint numbers are the machine file's axis variables in order (0 = the first); renumber them to your\n\
         configuration's joints. Give COMP_FILE an absolute path if the working directory of LinuxCNC's task\n\
         is not the configuration directory. BACKLASH is not used for a joint with a COMP_FILE.\n\n\
         Sign: trim = nominal - actual = -(positioning error at the tool point); LinuxCNC adds it to the\n\
         commanded position. Units: machine units (mm). The correction is first order: the trim is looked up\n\
         at the commanded position, not at the corrected one.\n",
    );
    files.push(ExportedFile {
        name: "linuxcnc-README.txt".into(),
        text: readme,
    });
    let accounting = ctx.account(&|_, part| super::slot_share(&exported, part), &|_, _| None)?;
    let correction = LinuxcncCorrection {
        variables: ctx.axes.len(),
        tables,
    };
    let mut export = ctx.finish(files, accounting, resampling, Box::new(correction));
    export.report.directions = directions;
    for (v, points) in sampling {
        let name = &ctx.machine.variables[v].name;
        if let Some(a) = export.report.axes.iter_mut().find(|a| a.variable == *name) {
            a.points = points;
        }
    }
    Ok(export)
}

/// `axis` with the positions of its error's table inside its travel added to
/// its nodes (a position within 1e-9 mm of a node is that node).
fn with_table_positions(axis: &LinearAxis, positions: Option<Vec<f64>>) -> LinearAxis {
    let mut out = axis.clone();
    let (lo, hi) = (axis.nodes[0], axis.nodes[axis.nodes.len() - 1]);
    for q in positions.unwrap_or_default() {
        if q > lo && q < hi && axis.nodes.iter().all(|n| (n - q).abs() > 1e-9) {
            out.nodes.push(q);
        }
    }
    out.nodes.sort_by(f64::total_cmp);
    out
}
