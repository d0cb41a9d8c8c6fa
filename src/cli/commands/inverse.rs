//! `chain inverse FILE --pose POSE.csv [--fix mu=0] [--param NAME=VALUE] [--format json|csv]`.
//!
//! Inverse kinematics of every pose of a CSV (`px,py,pz,i,j,k`: tool point and
//! tool axis in the workpiece frame; or `px,py,pz,r11,…,r33`: tool point and
//! the whole tool frame), printed as the spec's JSON document.

use std::path::PathBuf;

use chain::ops::inverse::{self, InverseDocument, InverseOpsError, InverseRequest};

use crate::cli::args::{parse_assignment, ParamArgs};
use crate::cli::csv_input::read_poses;
use crate::cli::loaded::Loaded;
use crate::cli::report::{self, Csv, Report};

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
    #[command(flatten)]
    pub param: ParamArgs,
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

/// Runs `chain inverse` ([`chain::ops::inverse`]).
pub fn exec(args: InverseArgs) -> miette::Result<()> {
    let loaded = Loaded::new(&args.file)?;
    let (_, poses) = read_poses(&args.pose)?;
    let request = InverseRequest {
        params: &args.param.params,
        fix: &args.fix,
        poses: &poses,
    };
    let doc = inverse::run(&loaded.machine, &request).map_err(|e| match e {
        InverseOpsError::Reliability(e) => loaded.report(e),
        InverseOpsError::Resolve(e) => miette::Report::new(e),
        InverseOpsError::Machine(e) => miette::Report::new(e),
    })?;
    for note in doc.notes() {
        eprintln!("{note}");
    }
    report::emit(&doc, args.format.into())
}

report::formats!(InverseFormat: Json, Csv);

impl Report for InverseDocument {
    /// `chain inverse` has no table: its text form is the JSON document.
    fn table(&self) -> String {
        report::json(self).unwrap_or_default()
    }

    /// `row,status,solution,<variables>`, one line per solution; an
    /// unreachable row has one line with empty values.
    fn csv(&self, out: &mut Csv<'_>) -> Option<()> {
        out.header(
            ["row", "status", "solution"]
                .into_iter()
                .chain(self.variables.iter().map(String::as_str)),
        );
        for (k, s) in self.rows.iter().enumerate() {
            let (row, status) = ((k + 1).to_string(), s.status.name());
            if s.solutions.is_empty() {
                out.row(
                    [row.clone(), status.to_string(), String::new()]
                        .into_iter()
                        .chain(self.variables.iter().map(|_| String::new())),
                );
            }
            for (j, q) in s.solutions.iter().enumerate() {
                out.row(
                    [row.clone(), status.to_string(), (j + 1).to_string()]
                        .into_iter()
                        .chain(q.iter().map(f64::to_string)),
                );
            }
        }
        Some(())
    }
}
