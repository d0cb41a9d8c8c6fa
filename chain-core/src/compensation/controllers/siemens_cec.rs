//! Sinumerik CEC (sag / cross-axis) tables `$AN_CEC[t,N]`
//! (`docs/export-controllers.md`, Sinumerik section; source: SINUMERIK
//! 840D sl / 828D Function Manual Extended Functions, K3 §4.4.3, 03/2013,
//! and the 802D sl Function Manual §11.3 example).
//!
//! One table per straightness error of a linear axis: the base axis
//! (`_INPUT_AXIS`) is the axis the error moves along, the compensation axis
//! (`_OUTPUT_AXIS`) the axis the straightness deviates in. Equidistant
//! points (`_STEP`, `_MIN`, `_MAX = _MIN + k·_STEP`, `k + 1` values), read
//! linearly by the control and held at the end values outside `_MIN`..`_MAX`.
//! The value is the compensation axis' error at the tool point (actual −
//! nominal): the control is taken to move the axis by −value, as its
//! documented MSEC principle does ("a positive compensation value causes the
//! machine axis to move in the negative direction"); for CEC this is
//! UNCONFIRMED and the file says so.

use super::{interpolate_held, num, Context, ControllerError, Export, AXIS};
use crate::compensation::{opening_line, Correction, ExportedFile};
use crate::model_trait::{ErrorModel, OutOfRange};

/// One CEC table as the control reads it.
#[derive(Debug, Clone, PartialEq)]
pub struct CecTable {
    /// The base axis (machine variable index).
    pub input: usize,
    /// The compensation axis (machine variable index).
    pub output: usize,
    /// The interpolation points' positions (`_MIN + N·_STEP`).
    pub nodes: Vec<f64>,
    /// `$AN_CEC[t, N]`.
    pub values: Vec<f64>,
}

/// What the control adds to the commanded axes: on each compensation axis
/// the sum over its tables of `−value`, linear in the base axis' setpoint,
/// held at the end values outside `_MIN`..`_MAX`.
#[derive(Debug, Clone, PartialEq)]
pub struct CecCorrection {
    /// The tables.
    pub tables: Vec<CecTable>,
}

impl Correction for CecCorrection {
    fn delta(&self, q: &[f64], delta: &mut [f64]) -> Result<(), OutOfRange> {
        for d in delta.iter_mut() {
            *d = 0.0;
        }
        for t in &self.tables {
            delta[t.output] -= interpolate_held(&t.nodes, &t.values, q[t.input]);
        }
        Ok(())
    }
}

pub(super) fn export<M: ErrorModel + Sync>(
    ctx: &Context<'_, M>,
) -> Result<Export, ControllerError> {
    let mut tables: Vec<CecTable> = Vec::new();
    let mut exported: Vec<(String, usize)> = Vec::new();
    let mut names: Vec<String> = Vec::new();
    let mut resampling: f64 = 0.0;
    for axis in &ctx.axes {
        for motion in &axis.motions {
            if motion.slot >= 3 || motion.slot == axis.joint_axis {
                continue;
            }
            let Some(out) = ctx.axis_along(motion.slot) else {
                continue;
            };
            if axis.nodes.len() > ctx.options.cec_max_points {
                return Err(ControllerError::TooManyPoints {
                    controller: "the CEC table (MD18342 $MN_MM_CEC_MAX_POINTS)",
                    variable: axis.name.clone(),
                    lo: axis.nodes[0],
                    hi: axis.nodes[axis.nodes.len() - 1],
                    step: axis.step,
                    points: axis.nodes.len(),
                    limit: ctx.options.cec_max_points,
                    hint: "; give a larger step (or a larger limit, if your control's MD18342 allows it)",
                });
            }
            let value = |parts: &[crate::built::Part]| {
                parts
                    .iter()
                    .find(|p| p.name == motion.name)
                    .map(|p| out.sign * p.error[out.frame_axis])
                    .unwrap_or(0.0)
            };
            let values: Vec<f64> = ctx.along(axis)?.iter().map(|p| value(p)).collect();
            for (w, parts) in axis.nodes.windows(2).zip(ctx.midpoints(axis)?) {
                let lin = interpolate_held(&axis.nodes, &values, 0.5 * (w[0] + w[1]));
                resampling = resampling.max((value(&parts) - lin).abs());
            }
            tables.push(CecTable {
                input: axis.variable,
                output: out.variable,
                nodes: axis.nodes.clone(),
                values,
            });
            exported.push((motion.name.clone(), out.frame_axis));
            names.push(motion.name.clone());
        }
    }
    if tables.is_empty() {
        return Err(ControllerError::NothingToExport {
            controller: ctx.name(),
            what:
                "one cross-axis table per straightness error (an error slot across a linear axis)",
            machine: ctx.machine.name.clone(),
        });
    }
    let var = |v: usize| &ctx.machine.variables[v].name;
    let mut text = String::from("%_N_NC_CEC_INI\nCHANDATA(1)\n");
    text.push_str(&format!(
        "; {}\n",
        opening_line(
            &ctx.options.provenance,
            &format!(
                "machine `{}`, {} tables (one per straightness error)",
                ctx.machine.name,
                tables.len()
            )
        )
    ));
    text.push_str(
        "; units: positions (_STEP, _MIN, _MAX) and values in mm (metric measuring system)\n",
    );
    text.push_str("; value = error of the compensation axis at the tool point (actual - nominal), applied with the opposite sign\n");
    text.push_str(";   (the documented MSEC principle: a positive value moves the axis negative; for CEC UNCONFIRMED:\n");
    text.push_str(
        ";   check with one point of +0.010 and watch the direction the compensation axis moves)\n",
    );
    text.push_str("; axes: AX<n> = the machine file's n-th axis variable; renumber to your control's machine axes\n");
    text.push_str("; load only with MD32710 $MA_CEC_ENABLE = 0; then MD32710 = 1 on each compensation axis, SD41300 $SN_CEC_TABLE_ENABLE[t] = 1\n");
    for (t, (table, name)) in tables.iter().zip(&names).enumerate() {
        let n = table.nodes.len();
        text.push_str(&format!(
            "; table {t}: {name}({}), base axis {} -> compensation axis {} (along {}); needs MD18342[{t}] >= {n}\n",
            var(table.input),
            var(table.input),
            var(table.output),
            AXIS[ctx.axes[table.output].frame_axis]
        ));
        text.push_str(&format!(
            "$AN_CEC_INPUT_AXIS[{t}]=(AX{})\n$AN_CEC_OUTPUT_AXIS[{t}]=(AX{})\n",
            table.input + 1,
            table.output + 1
        ));
        let step = ctx.axes[table.input].step;
        text.push_str(&format!(
            "$AN_CEC_STEP[{t}]={}\n$AN_CEC_MIN[{t}]={}\n$AN_CEC_MAX[{t}]={}\n",
            num(step),
            num(table.nodes[0]),
            num(table.nodes[n - 1])
        ));
        text.push_str(&format!(
            "$AN_CEC_DIRECTION[{t}]=0\n$AN_CEC_MULT_BY_TABLE[{t}]=0\n$AN_CEC_IS_MODULO[{t}]=0\n"
        ));
        for (k, v) in table.values.iter().enumerate() {
            text.push_str(&format!("$AN_CEC[{t},{k}]={}\n", num(*v)));
        }
    }
    text.push_str("M17\n");
    let files = vec![ExportedFile {
        name: "NC_CEC.INI".into(),
        text,
    }];
    let accounting = ctx.account(&|_, part| super::slot_share(&exported, part), &|_, _| None)?;
    let correction = CecCorrection { tables };
    Ok(ctx.finish(files, accounting, resampling, Box::new(correction)))
}
