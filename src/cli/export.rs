//! `chain export FILE --values VALUES.yaml --controller NAME
//! [--grid VAR=V1,V2,...|VAR=LO:HI:N]... [--axes AXES.csv]
//! [--param NAME=VALUE]... [--out DIR] [--format table|json|csv]`.
//!
//! Compensation for a controller (measured-machines spec, section 6): the
//! `grid` export through [`chain_core::compensation::grid::export`] at the
//! nodes of the machine file's `reliability.grid` (each axis replaceable by
//! `--grid`, as in `chain map`) or at the rows of `--axes`. With `--out DIR`
//! the file goes to `DIR/<machine>_grid.csv` and the summary to stdout (in
//! `--format`, table by default); without it the file itself goes to
//! stdout, unless `--format` asks for the summary. See `docs/export.md`.

use std::path::PathBuf;

use chain_core::built::{BuiltMachine, Points};
use chain_core::compensation::grid::{self, GridCompensation};
use chain_core::compensation::CompensationError;
use chain_core::kinematics::Kinematics;
use chain_core::values::Values;
use miette::MietteDiagnostic;
use reliability::machine;
use serde::Serialize;

use super::args::ParamArgs;
use super::map::{axes_points, grid_axes, parse_grid_axis};
use super::reliability::Loaded;
use super::report::{self, Csv, Report};

/// The controllers `chain export` writes for (spec section 6's table).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ControllerName {
    /// The universal grid CSV: `δq` at every node and the residual.
    Grid,
    /// Beckhoff TwinCAT / ISG volumetric compensation (`ISG_CSV`).
    Beckhoff,
    /// LinuxCNC `COMP_FILE` per joint.
    Linuxcnc,
    /// Sinumerik CEC sag / cross-axis tables.
    SiemensCec,
    /// Klipper `SET_SKEW`.
    Klipper,
}

impl ControllerName {
    /// The name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            ControllerName::Grid => "grid",
            ControllerName::Beckhoff => "beckhoff",
            ControllerName::Linuxcnc => "linuxcnc",
            ControllerName::SiemensCec => "siemens-cec",
            ControllerName::Klipper => "klipper",
        }
    }
}

/// Output formats of `chain export`'s summary.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ExportFormat {
    /// The summary in words.
    Table,
    /// The summary as JSON.
    Json,
    /// The exported grid CSV.
    Csv,
}

report::formats!(ExportFormat: Table, Json, Csv);

/// Arguments of `chain export`.
#[derive(Debug, clap::Args)]
pub struct ExportArgs {
    /// Machine file (YAML).
    pub file: PathBuf,
    /// The error values of the built machine (a values file).
    #[arg(long, value_name = "VALUES.yaml")]
    pub values: PathBuf,
    /// The controller to write for.
    #[arg(long, value_enum)]
    pub controller: ControllerName,
    /// Replace (or add) the grid values of one axis: `VAR=V1,V2,...`, or
    /// `VAR=LO:HI:N` (repeatable).
    #[arg(long = "grid", value_name = "VAR=V1,V2,...|VAR=LO:HI:N", value_parser = parse_grid_axis)]
    pub grid: Vec<(String, Vec<f64>)>,
    /// Nodes from a CSV of commanded poses instead of the grid: a header
    /// naming every axis variable (rotary in radians), an optional leading
    /// `t`; `-` reads stdin.
    #[arg(long, value_name = "AXES.csv", conflicts_with = "grid")]
    pub axes: Option<PathBuf>,
    #[command(flatten)]
    pub param: ParamArgs,
    /// Write the exported file(s) into DIR (created if missing) and the
    /// summary to stdout; without it the file goes to stdout.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// The summary's format (with --out: table by default; without --out,
    /// asks for the summary instead of the file).
    #[arg(long, value_enum)]
    pub format: Option<ExportFormat>,
}

/// Runs `chain export`.
pub fn exec(args: ExportArgs) -> miette::Result<()> {
    if args.controller != ControllerName::Grid {
        let d = MietteDiagnostic::new(format!(
            "--controller {} is not in this build yet",
            args.controller.name()
        ))
        .with_code("chain::export::not_in_this_build")
        .with_help("this build writes --controller grid (docs/export.md)");
        return Err(miette::Report::new(d));
    }
    let loaded = Loaded::new(&args.file)?;
    let m = &loaded.machine;
    let values = Values::read(&args.values, m)?;
    let params = machine::parameters(m, &args.param.params).map_err(|e| loaded.report(e))?;
    let points = match &args.axes {
        Some(path) => Points::list(m.variables.len(), axes_points(path, m)?)
            .map_err(|e| miette::miette!("{}: {e}", path.display()))?,
        None => {
            let file = args.file.display().to_string();
            let axes = grid_axes(m, &loaded, &file, &args.grid)?;
            Points::Grid(axes.into_iter().map(|(_, v)| v).collect())
        }
    };
    let built = BuiltMachine::compile(m, values, params)
        .map_err(|e| miette::miette!("{}: {e}", args.values.display()))?;
    let kin = Kinematics::from_machine(m);
    let result = grid::export(&built, &kin, points).map_err(|e| export_error(e, &args.values))?;
    let file = result.file();
    let doc = ExportDoc {
        controller: ControllerName::Grid.name(),
        values_file: args.values.display().to_string(),
        files: vec![file.name.clone()],
        grid: result,
    };
    match &args.out {
        Some(dir) => {
            std::fs::create_dir_all(dir)
                .map_err(|e| miette::miette!("cannot create {}: {e}", dir.display()))?;
            let path = dir.join(&file.name);
            std::fs::write(&path, &file.text)
                .map_err(|e| miette::miette!("cannot write {}: {e}", path.display()))?;
            eprintln!("wrote {}", path.display());
            report::emit(&doc, args.format.unwrap_or(ExportFormat::Table).into())
        }
        None => match args.format {
            None => report::write_stdout(&file.text),
            Some(f) => report::emit(&doc, f.into()),
        },
    }
}

/// A compensation error, rendered with its code and help.
pub(crate) fn export_error(e: CompensationError, values: &std::path::Path) -> miette::Report {
    match &e {
        CompensationError::OutOfRange { point, at, source } => {
            let d = MietteDiagnostic::new(format!(
                "at node {} ({at}): {} = {} is outside the table of `{}` ({}, {} = {} to {})",
                point + 1,
                source.variable,
                source.value,
                source.name,
                source.table,
                source.variable,
                source.lo,
                source.hi
            ))
            .with_code("chain::export::out_of_range")
            .with_help(format!(
                "the values file {} does not cover the requested nodes: export inside {} = {} to {} (--grid), extend the table, or add `extrapolate: hold` to its entry",
                values.display(),
                source.variable,
                source.lo,
                source.hi
            ));
            miette::Report::new(d)
        }
        _ => miette::Report::new(e),
    }
}

/// The report of `chain export`.
#[derive(Serialize)]
struct ExportDoc {
    /// The controller (the table's; JSON has the export's own).
    #[serde(skip)]
    controller: &'static str,
    values_file: String,
    /// The files written (with --out) or that would be.
    files: Vec<String>,
    #[serde(flatten)]
    grid: GridCompensation,
}

impl Report for ExportDoc {
    fn table(&self) -> String {
        use std::fmt::Write;
        let g = &self.grid;
        let s = &g.summary;
        let mut out = String::new();
        let _ = writeln!(
            out,
            "Compensation of {} for controller {}, values {}",
            g.machine, self.controller, self.values_file
        );
        let _ = writeln!(out, "{} nodes; file {}", s.nodes, self.files.join(", "));
        let _ = writeln!(out);
        let _ = writeln!(out, "{:<28} {:>12} {:>12}", "", "max", "rms");
        let row = |out: &mut String, name: &str, x: &grid::Spread, f: f64| {
            let _ = writeln!(out, "{name:<28} {:>12.4} {:>12.4}", x.max * f, x.rms * f);
        };
        row(&mut out, "tool point before (µm)", &s.before, 1e3);
        row(&mut out, "tool point after (µm)", &s.residual, 1e3);
        row(&mut out, "tool axis before (µrad)", &s.axis_before, 1e6);
        row(&mut out, "tool axis after (µrad)", &s.axis_residual, 1e6);
        let _ = writeln!(out);
        let at: Vec<String> = (s.residual_at.0.iter())
            .map(|(n, v)| format!("{n} = {v}"))
            .collect();
        let _ = writeln!(
            out,
            "largest residual at {}; max residual / max error = {:.3e}",
            at.join(", "),
            s.ratio
        );
        let deltas: Vec<String> = (s.max_delta.0.iter().zip(&g.rotary))
            .map(|((n, v), r)| {
                if *r {
                    format!("{n} {:.3} µrad", v * 1e6)
                } else {
                    format!("{n} {:.3} µm", v * 1e3)
                }
            })
            .collect();
        let _ = writeln!(out, "largest |δq|: {}", deltas.join(", "));
        if s.axis_not_corrected > 0 {
            let _ = writeln!(
                out,
                "tool axis not fully correctable at {} of {} nodes (the axes leave fewer than two tool-axis directions once the tool point is met)",
                s.axis_not_corrected, s.nodes
            );
        }
        if s.continued > 0 {
            let _ = writeln!(
                out,
                "{} nodes: q + δq leaves a values table by |δq|; their residual continues it linearly (docs/export.md)",
                s.continued
            );
        }
        out
    }

    fn csv(&self) -> Option<Csv> {
        let g = &self.grid;
        let mut csv = Csv::new(g.header());
        let nv = g.variables.len();
        let mut q = vec![0.0; nv];
        for i in 0..g.len() {
            g.points.point_into(i, &mut q);
            let mut row: Vec<String> = q.iter().map(|x| format!("{x}")).collect();
            row.extend(g.delta(i).iter().map(|x| format!("{x}")));
            row.push(format!("{}", g.residuals[i]));
            csv.row(row);
        }
        Some(csv)
    }
}
