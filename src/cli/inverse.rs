//! `chain inverse FILE --pose POSE.csv [--fix mu=0] [--param NAME=VALUE] [--format json|csv]`.
//!
//! Inverse kinematics of every pose of a CSV (`px,py,pz,i,j,k`: tool point and
//! tool axis in the workpiece frame; or `px,py,pz,r11,…,r33`: tool point and
//! the whole tool frame), printed as the spec's JSON document.

use std::path::PathBuf;

use chain_core::inverse::{Inverse, Solution, Status};
use serde_json::{json, Map, Value};

use super::csv_input::{read_poses, Orientation, PoseRow};
use super::reliability::{parse_assignment, resolve_fixed, Loaded};
use super::report::write_stdout;

/// Arguments of `chain inverse`.
#[derive(Debug, clap::Args)]
pub struct InverseArgs {
    /// Machine file (YAML).
    pub file: PathBuf,
    /// Poses, CSV with header `px,py,pz,i,j,k` (tool point and axis) or
    /// `px,py,pz,r11,r12,r13,r21,r22,r23,r31,r32,r33` (tool point and frame),
    /// optionally after a first column `t`, which is ignored; `-` reads stdin.
    #[arg(long, value_name = "POSE.csv")]
    pub pose: PathBuf,
    /// Hold a variable the pose does not determine, `NAME=VALUE` (repeatable).
    #[arg(long = "fix", value_name = "NAME=VALUE", value_parser = parse_assignment)]
    pub fix: Vec<(String, f64)>,
    /// Value of a parameter, `NAME=VALUE` (repeatable; required for symbolic ones).
    #[arg(long = "param", value_name = "NAME=VALUE", value_parser = parse_assignment)]
    pub params: Vec<(String, f64)>,
    /// Output format: the spec's JSON document, or CSV with one line per
    /// solution (`row,status,solution,<variables>`; an unreachable row has
    /// one line with empty values).
    #[arg(long, value_enum, default_value = "json")]
    pub format: InverseFormat,
}

/// Output formats of `chain inverse`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum InverseFormat {
    /// The spec's JSON document.
    Json,
    /// One line per solution.
    Csv,
}

/// Runs `chain inverse`.
pub fn exec(args: InverseArgs) -> miette::Result<()> {
    let loaded = Loaded::new(&args.file)?;
    let m = &loaded.machine;
    let params = reliability::machine::parameters(m, &args.params).map_err(|e| loaded.report(e))?;
    let fixed = resolve_fixed(m, &args.fix)?;
    let (_, poses) = read_poses(&args.pose)?;
    let solver = Inverse::for_machine(m, &params, &fixed)
        .map_err(|e| miette::miette!("machine `{}`: {e}", m.name))?;
    let mut rows = Vec::with_capacity(poses.len());
    let mut csv_text = String::from("row,status,solution");
    for v in &m.variables {
        csv_text.push(',');
        csv_text.push_str(&v.name);
    }
    csv_text.push('\n');
    for (k, s) in solve_rows(&solver, &poses, m.variables.len(), &fixed)
        .into_iter()
        .enumerate()
    {
        let sols: Vec<Value> = s
            .solutions
            .iter()
            .map(|q| {
                let mut o = Map::new();
                for (var, x) in m.variables.iter().zip(q) {
                    o.insert(var.name.clone(), json!(x));
                }
                Value::Object(o)
            })
            .collect();
        let status = match s.status {
            Status::Ok => "ok",
            Status::Unreachable => "unreachable",
            Status::Singular => "singular",
        };
        if s.solutions.is_empty() {
            csv_text.push_str(&format!("{},{status},", k + 1));
            csv_text.push_str(&",".repeat(m.variables.len()));
            csv_text.push('\n');
        }
        for (j, q) in s.solutions.iter().enumerate() {
            csv_text.push_str(&format!("{},{status},{}", k + 1, j + 1));
            for x in q {
                csv_text.push_str(&format!(",{x}"));
            }
            csv_text.push('\n');
        }
        rows.push(json!({"row": k + 1, "status": status, "solutions": sols}));
    }
    if args.format == InverseFormat::Csv {
        return write_stdout(&csv_text);
    }
    let doc = json!({
        "machine": m.name,
        "method": solver.method(),
        "variables": m.variables.iter().map(|v| v.name.clone()).collect::<Vec<_>>(),
        "rows": rows,
    });
    let mut text = serde_json::to_string_pretty(&doc)
        .map_err(|e| miette::miette!("cannot serialise the result: {e}"))?;
    text.push('\n');
    write_stdout(&text)
}

/// Solves the pose rows in order, each row's solutions sorted by their
/// distance to the previous row's first solution (the first row: to the
/// fixed values, 0 elsewhere), so a smooth path stays on one branch.
pub(crate) fn solve_rows(
    solver: &Inverse,
    rows: &[PoseRow],
    variables: usize,
    fixed: &[(usize, f64)],
) -> Vec<Solution> {
    let mut prev = vec![0.0; variables];
    for &(i, v) in fixed {
        if let Some(p) = prev.get_mut(i) {
            *p = v;
        }
    }
    rows.iter()
        .map(|row| {
            let s = match row.orientation {
                Orientation::Axis(axis) => solver.solve(row.point, axis, &prev),
                Orientation::Rotation(r) => solver.solve_pose(row.point, &r, &prev),
            };
            if let Some(first) = s.solutions.first() {
                prev.clone_from(first);
            }
            s
        })
        .collect()
}
