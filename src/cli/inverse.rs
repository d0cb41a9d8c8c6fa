//! `chain inverse FILE --pose POSE.csv [--fix mu=0] [--param NAME=VALUE] [--format json|csv]`.
//!
//! Inverse kinematics of every pose of a CSV (`px,py,pz,i,j,k`: tool point and
//! tool axis in the workpiece frame), printed as the spec's JSON document.

use std::path::PathBuf;

use chain_core::inverse::{Inverse, Status};
use serde_json::{json, Map, Value};

use super::csv_input::{read_poses, Orientation};
use super::reliability::{parse_assignment, write_stdout, Loaded};

/// Arguments of `chain inverse`.
#[derive(Debug, clap::Args)]
pub struct InverseArgs {
    /// Machine file (YAML).
    pub file: PathBuf,
    /// Poses, CSV with header `px,py,pz,i,j,k` (optionally after a first
    /// column `t`, which is ignored); `-` reads stdin.
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
    let mut params = Vec::with_capacity(m.parameters.len());
    for p in &m.parameters {
        let cli = args.params.iter().rev().find(|(n, _)| *n == p.name);
        match cli.map(|c| c.1).or(p.value) {
            Some(v) => params.push(v),
            None => miette::bail!(
                "parameter `{}` has no value; give --param {}=VALUE",
                p.name,
                p.name
            ),
        }
    }
    for (n, _) in &args.params {
        if !m.parameters.iter().any(|p| p.name == *n) {
            miette::bail!("`{n}` is not a parameter of machine `{}`", m.name);
        }
    }
    let mut fixed = Vec::new();
    for (n, v) in &args.fix {
        let Some(i) = m.variables.iter().position(|x| x.name == *n) else {
            miette::bail!("--fix: `{n}` is not a variable of machine `{}`", m.name);
        };
        fixed.push((i, *v));
    }
    let (_, poses) = read_poses(&args.pose)?;
    let solver = Inverse::for_machine(m, &params, &fixed)
        .map_err(|e| miette::miette!("machine `{}`: {e}", m.name))?;
    let mut prev = vec![0.0; m.variables.len()];
    for &(i, v) in &fixed {
        prev[i] = v;
    }
    let mut rows = Vec::with_capacity(poses.len());
    let mut csv_text = String::from("row,status,solution");
    for v in &m.variables {
        csv_text.push(',');
        csv_text.push_str(&v.name);
    }
    csv_text.push('\n');
    for (k, pose) in poses.iter().enumerate() {
        let s = match pose.orientation {
            Orientation::Axis(axis) => solver.solve(pose.point, axis, &prev),
            Orientation::Rotation(r) => solver.solve_pose(pose.point, &r, &prev),
        };
        if let Some(first) = s.solutions.first() {
            prev.clone_from(first);
        }
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
