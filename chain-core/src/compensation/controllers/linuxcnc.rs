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
//! own axis), the same for both directions (a values file has no reversal
//! data). LinuxCNC stops reading at the first line that is not three numbers,
//! so the comments (units, sign) come after the data.

use super::{interpolate_held, num, Context, ControllerError, Export, AXIS};
use crate::compensation::{Correction, ExportedFile};
use crate::model_trait::{ErrorModel, OutOfRange};

/// What LinuxCNC adds to the commanded joints: per table, the trim
/// interpolated linearly at the commanded position and held at its end
/// values outside the table (`control.c` `compute_screw_comp`, `motion.c`'s
/// sentinels).
#[derive(Debug, Clone, PartialEq)]
pub struct LinuxcncCorrection {
    /// Variables of the machine.
    pub variables: usize,
    /// Per table: the joint (machine variable index), the nominals and the
    /// trims.
    pub tables: Vec<(usize, Vec<f64>, Vec<f64>)>,
}

impl Correction for LinuxcncCorrection {
    fn delta(&self, q: &[f64], delta: &mut [f64]) -> Result<(), OutOfRange> {
        for d in delta.iter_mut() {
            *d = 0.0;
        }
        for (v, nodes, trims) in &self.tables {
            delta[*v] += interpolate_held(nodes, trims, q[*v]);
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
    for axis in &ctx.axes {
        let Some(motion) = axis.motions.iter().find(|m| m.slot == axis.joint_axis) else {
            continue;
        };
        let find = |parts: &[crate::built::Part]| {
            parts
                .iter()
                .find(|p| p.name == motion.name)
                .map(|p| axis.sign * p.error[axis.frame_axis])
                .unwrap_or(0.0)
        };
        let u: Vec<f64> = ctx.along(axis)?.iter().map(|p| find(p)).collect();
        let trims: Vec<f64> = u.iter().map(|v| -v).collect();
        for (w, parts) in axis.nodes.windows(2).zip(ctx.midpoints(axis)?) {
            let x = 0.5 * (w[0] + w[1]);
            let lin = -interpolate_held(&axis.nodes, &trims, x);
            resampling = resampling.max((find(&parts) - lin).abs());
        }
        let joint = axis.variable;
        let mut text = String::new();
        for (x, t) in axis.nodes.iter().zip(&trims) {
            text.push_str(&format!("{} {} {}\n", num(*x), num(*t), num(*t)));
        }
        text.push_str(&format!(
            "# chain export --controller linuxcnc: machine `{}`, joint {joint} (axis variable `{}`, the tool moves along {}{} as it increases)\n",
            ctx.machine.name,
            axis.name,
            if axis.sign > 0.0 { "+" } else { "-" },
            AXIS[axis.frame_axis]
        ));
        text.push_str("# [JOINT_n] COMP_FILE_TYPE = 1: columns nominal (commanded joint position) | trim moving + | trim moving -\n");
        text.push_str(&format!(
            "# trim = -u, u = the positioning error `{}` seen at the tool point along the joint's axis (actual - nominal); LinuxCNC adds the trim to the command\n",
            motion.name
        ));
        text.push_str(&format!(
            "# units: machine units, mm; step {} mm; the same trim both directions (no reversal data); held at the end values outside {} to {}\n",
            num(axis.step),
            num(axis.nodes[0]),
            num(axis.nodes[axis.nodes.len() - 1])
        ));
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
        tables.push((axis.variable, axis.nodes.clone(), trims));
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
        "chain export --controller linuxcnc: machine `{}`\n\nOne COMP_FILE per joint that has a positioning error. In the INI file:\n\n",
        ctx.machine.name
    );
    for (v, _, _) in &tables {
        readme.push_str(&format!(
            "[JOINT_{v}]\nCOMP_FILE = {}.comp\nCOMP_FILE_TYPE = 1\n\n",
            ctx.machine.variables[*v].name
        ));
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
    Ok(ctx.finish(files, accounting, resampling, Box::new(correction)))
}
