//! `chain export FILE --values VALUES.yaml --controller NAME
//! [--grid VAR=V1,V2,...|VAR=LO:HI:N]... [--axes AXES.csv] [--step MM]
//! [--param NAME=VALUE]... [--out DIR] [--format table|json|csv]`.
//!
//! Compensation for a controller (measured-machines spec, section 6).
//!
//! - `grid`: [`chain_core::compensation::grid::export`] at the nodes of the
//!   machine file's `reliability.grid` (each axis replaceable by `--grid`, as
//!   in `chain map`) or at the rows of `--axes`. With `--out DIR` the file
//!   goes to `DIR/<machine>_grid.csv` and the summary to stdout (in
//!   `--format`, table by default); without it the file itself goes to
//!   stdout, unless `--format` asks for the summary. See `docs/export.md`.
//! - `beckhoff`, `linuxcnc`, `siemens-cec`, `klipper`:
//!   [`chain_core::compensation::controllers::export`], each axis sampled
//!   over its travel (the machine file's `reliability.grid` range, or
//!   `--grid`'s smallest and largest value) every `--step` mm. With
//!   `--out DIR` the files go to DIR and the report ([`FormatReport`]:
//!   what the format expresses, what it leaves and how large) to stdout;
//!   without it a one-file format writes its file to stdout and a
//!   several-file format is refused. See `docs/export-controllers.md`.

use std::path::PathBuf;

use chain_core::built::{BuiltMachine, Points};
use chain_core::compensation::controllers::{
    self, Controller, ControllerError, ExportOptions, FormatReport, Term,
    BECKHOFF_DEFAULT_MAX_RECORDS, CEC_DEFAULT_MAX_POINTS, DEFAULT_STEP,
};
use chain_core::compensation::grid::{self, GridCompensation};
use chain_core::compensation::ExportedFile;
use chain_core::kinematics::Kinematics;
use chain_core::values::Values;
use miette::MietteDiagnostic;
use reliability::machine;
use serde::Serialize;

use super::args::ParamArgs;
use super::args::{parse_grid_axis, ControllerName};
use super::csv_input::axes_points;
use super::diagnostics::export_error;
use super::loaded::Loaded;
use super::report::{self, Csv, Report};

/// Output formats of `chain export`'s summary.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ExportFormat {
    /// The summary in words.
    Table,
    /// The summary as JSON.
    Json,
    /// The exported grid CSV (`--controller grid` only).
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
    /// `VAR=LO:HI:N` (repeatable). For the per-axis table formats it gives
    /// the axis's travel (its smallest and largest value; any further
    /// values must be nodes of the table, see --step).
    #[arg(long = "grid", value_name = "VAR=V1,V2,...|VAR=LO:HI:N", value_parser = parse_grid_axis)]
    pub grid: Vec<(String, Vec<f64>)>,
    /// Nodes from a CSV of commanded poses instead of the grid: a header
    /// naming every axis variable (rotary in radians), an optional leading
    /// `t`; `-` reads stdin.
    #[arg(long, value_name = "AXES.csv", conflicts_with = "grid")]
    pub axes: Option<PathBuf>,
    /// The largest table step (mm) of the per-axis table formats: each
    /// axis is sampled at the largest step not above it that divides its
    /// travel into whole intervals [default: 10].
    #[arg(long, value_name = "MM")]
    pub step: Option<f64>,
    /// The points a Sinumerik CEC table may have (`MD18342`; the 828D's
    /// 200 by default).
    #[arg(long, value_name = "N")]
    pub cec_max_points: Option<usize>,
    /// The Beckhoff `vol_comp[i].max_records` the records must fit in
    /// (the vendor example's 2000 by default).
    #[arg(long, value_name = "N")]
    pub beckhoff_max_records: Option<usize>,
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
    check_options(&args)?;
    let loaded = Loaded::new(&args.file)?;
    let m = &loaded.machine;
    let values = Values::read(&args.values, m)?;
    let params = machine::parameters(m, &args.param.params).map_err(|e| loaded.report(e))?;
    match args.controller.tables() {
        None => exec_grid(&args, &loaded, values, params),
        Some(c) => {
            let built = BuiltMachine::compile(m, values, params)
                .map_err(|e| miette::miette!("{}: {e}", args.values.display()))?;
            exec_tables(&args, c, &loaded, &built)
        }
    }
}

/// Refuses the options the chosen controller does not take, before anything
/// is read.
fn check_options(args: &ExportArgs) -> miette::Result<()> {
    let c = args.controller.name();
    let refuse = |option: &str, why: &str| {
        let d = MietteDiagnostic::new(format!("--controller {c} does not take {option}"))
            .with_code("chain::export::option")
            .with_help(why.to_string());
        Err(miette::Report::new(d))
    };
    if args.controller == ControllerName::Grid {
        if args.step.is_some() {
            return refuse(
                "--step",
                "the grid export corrects at the grid's nodes: give them with --grid VAR=LO:HI:N",
            );
        }
        if args.cec_max_points.is_some() || args.beckhoff_max_records.is_some() {
            return refuse(
                "--cec-max-points or --beckhoff-max-records",
                "they limit the siemens-cec and beckhoff tables",
            );
        }
    } else {
        if args.axes.is_some() {
            return refuse(
                "--axes",
                "a per-axis table samples each axis over its travel: give the travel with --grid VAR=LO,HI and the table step with --step; --axes gives the nodes of --controller grid",
            );
        }
        if args.format == Some(ExportFormat::Csv) {
            return refuse(
                "--format csv",
                "--format csv is the grid CSV of --controller grid; this controller writes its own files (--out DIR) and its report as table or json",
            );
        }
        if args.cec_max_points.is_some() && args.controller != ControllerName::SiemensCec {
            return refuse("--cec-max-points", "it limits the siemens-cec tables");
        }
        if args.beckhoff_max_records.is_some() && args.controller != ControllerName::Beckhoff {
            return refuse("--beckhoff-max-records", "it limits the beckhoff tables");
        }
    }
    Ok(())
}

/// `--controller grid`.
fn exec_grid(
    args: &ExportArgs,
    loaded: &Loaded,
    values: Values,
    params: Vec<f64>,
) -> miette::Result<()> {
    let m = &loaded.machine;
    let points = match &args.axes {
        Some(path) => Points::list(m.variables.len(), axes_points(path, m)?)
            .map_err(|e| miette::miette!("{}: {e}", path.display()))?,
        None => {
            let file = args.file.display().to_string();
            let axes = chain::ops::resolve::grid_axes(m, &file, &args.grid)?;
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
            write_files(dir, std::slice::from_ref(&file))?;
            report::emit(&doc, args.format.unwrap_or(ExportFormat::Table).into())
        }
        None => match args.format {
            None => report::write_stdout(&file.text),
            Some(f) => report::emit(&doc, f.into()),
        },
    }
}

/// The per-axis table formats.
fn exec_tables(
    args: &ExportArgs,
    controller: Controller,
    loaded: &Loaded,
    built: &BuiltMachine,
) -> miette::Result<()> {
    let options = ExportOptions {
        step: args.step.unwrap_or(DEFAULT_STEP),
        travel: travel_of(&args.grid),
        cec_max_points: args.cec_max_points.unwrap_or(CEC_DEFAULT_MAX_POINTS),
        beckhoff_max_records: args
            .beckhoff_max_records
            .unwrap_or(BECKHOFF_DEFAULT_MAX_RECORDS),
    };
    let export = table_export(
        controller,
        built,
        loaded,
        &options,
        &args.grid,
        &args.values,
    )?;
    let doc = TablesDoc {
        values_file: args.values.display().to_string(),
        report: export.report,
    };
    match (&args.out, args.format) {
        (Some(dir), format) => {
            write_files(dir, &export.files)?;
            report::emit(&doc, format.unwrap_or(ExportFormat::Table).into())
        }
        (None, Some(format)) => report::emit(&doc, format.into()),
        (None, None) => match export.files.as_slice() {
            [one] => report::write_stdout(&one.text),
            files => {
                let names: Vec<&str> = files.iter().map(|f| f.name.as_str()).collect();
                let d = MietteDiagnostic::new(format!(
                    "--controller {} writes {} files ({}): give --out DIR",
                    controller.name(),
                    files.len(),
                    names.join(", ")
                ))
                .with_code("chain::export::needs_out")
                .with_help("or --format table|json for the report alone");
                Err(miette::Report::new(d))
            }
        },
    }
}

/// The per-axis export of `controller` with `options`, its errors rendered,
/// and `--grid`'s values checked against the table nodes it gives (a value
/// between nodes is refused, not dropped). Shared with `chain map
/// --compensated`.
pub(crate) fn table_export(
    controller: Controller,
    built: &BuiltMachine,
    loaded: &Loaded,
    options: &ExportOptions,
    grid: &[(String, Vec<f64>)],
    values: &std::path::Path,
) -> miette::Result<controllers::Export> {
    let export = controllers::export(controller, built, &loaded.machine, options)
        .map_err(|e| controller_error(e, values))?;
    for (name, given) in grid {
        let Some(a) = export.report.axes.iter().find(|a| a.variable == *name) else {
            continue;
        };
        let off_node = given.iter().find(|&&v| {
            let k = ((v - a.min) / a.step).round();
            (v - (a.min + k * a.step)).abs() > 1e-9 * a.step.max(1.0)
        });
        let what = match off_node {
            Some(v) => format!("{v} is not one of its nodes"),
            None if given.len() > 2 && given.len() != a.points => {
                format!("it has {} values", given.len())
            }
            None => continue,
        };
        {
            let d = MietteDiagnostic::new(format!(
                "--grid {name}=...: the {} tables sample `{name}` at {} nodes every {} mm from {} to {}, and {what}",
                controller.name(),
                a.points,
                a.step,
                a.min,
                a.max
            ))
            .with_code("chain::export::grid_nodes")
            .with_help(
                "give the travel alone (--grid VAR=LO,HI) and the table step with --step",
            );
            return Err(miette::Report::new(d));
        }
    }
    Ok(export)
}

/// `--grid` values as travels: each axis's smallest and largest value.
pub(crate) fn travel_of(grid: &[(String, Vec<f64>)]) -> Vec<(String, [f64; 2])> {
    grid.iter()
        .map(|(n, v)| {
            let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            (n.clone(), [lo, hi])
        })
        .collect()
}

/// Writes `files` into `dir` (created if missing), naming each on stderr.
fn write_files(dir: &std::path::Path, files: &[ExportedFile]) -> miette::Result<()> {
    std::fs::create_dir_all(dir)
        .map_err(|e| miette::miette!("cannot create {}: {e}", dir.display()))?;
    for f in files {
        let path = dir.join(&f.name);
        super::atomic::write(&path, f.text.as_bytes())
            .map_err(|e| miette::miette!("cannot write {}: {e}", path.display()))?;
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}

/// A controller export error, rendered with its code and help (a table
/// that does not cover the travel names the values file).
pub(crate) fn controller_error(e: ControllerError, values: &std::path::Path) -> miette::Report {
    match &e {
        ControllerError::OutOfTable {
            variable,
            lo,
            hi,
            source,
        } => {
            let d = MietteDiagnostic::new(format!(
                "the table of `{}` ({}) covers {} = {} to {}, and the export needs {} = {} (sampling axis `{variable}` over {lo} to {hi}, the other axes at their travel's start)",
                source.name, source.table, source.variable, source.lo, source.hi, source.variable, source.value
            ))
            .with_code("chain::export::out_of_table")
            .with_help(format!(
                "the values file {} does not cover the travel: give a travel inside the table (--grid {}={},{}), measure the table over the whole travel, or add `extrapolate: hold` to its entry; nothing is extrapolated",
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

/// The report of a per-axis table export.
#[derive(Serialize)]
struct TablesDoc {
    values_file: String,
    #[serde(flatten)]
    report: FormatReport,
}

impl Report for TablesDoc {
    fn table(&self) -> String {
        use std::fmt::Write;
        let r = &self.report;
        let mut out = String::new();
        let _ = writeln!(
            out,
            "Compensation of {} for controller {}, values {}",
            r.machine,
            r.controller.name(),
            self.values_file
        );
        let _ = writeln!(out, "files: {}", r.files.join(", "));
        let _ = writeln!(out);
        let _ = writeln!(
            out,
            "{:<8} {:>5} {:>12} {:>12} {:>10} {:>7}",
            "axis", "along", "min (mm)", "max (mm)", "step (mm)", "points"
        );
        for a in &r.axes {
            let _ = writeln!(
                out,
                "{:<8} {:>5} {:>12} {:>12} {:>10} {:>7}",
                a.variable, a.axis, a.min, a.max, a.step, a.points
            );
        }
        let terms = |out: &mut String, title: &str, terms: &[Term]| {
            let _ = writeln!(out);
            let _ = writeln!(out, "{title}");
            if terms.is_empty() {
                let _ = writeln!(out, "  (none)");
                return;
            }
            let _ = writeln!(
                out,
                "  {:<52} {:>14} {:>16}",
                "term", "position (µm)", "orientation (µrad)"
            );
            for t in terms {
                let _ = writeln!(
                    out,
                    "  {:<52} {:>14.4} {:>16.4}",
                    t.name,
                    t.position * 1e3,
                    t.orientation * 1e6
                );
            }
        };
        terms(
            &mut out,
            "expressed (removed by the controller), largest effect over the check grid:",
            &r.expressed,
        );
        terms(
            &mut out,
            "remaining (not expressed by the format):",
            &r.remaining,
        );
        let _ = writeln!(out);
        let _ = writeln!(
            out,
            "left after compensation: position {:.4} µm, orientation {:.4} µrad (largest over the check grid)",
            r.residual.position * 1e3,
            r.residual.orientation * 1e6
        );
        if !r.axes.is_empty() && r.controller != Controller::Klipper {
            let _ = writeln!(
                out,
                "linear resampling between table nodes: at most {:.4e} (mm, or rad for angular columns)",
                r.resampling
            );
        }
        for d in &r.directions {
            let _ = if d.bidirectional {
                writeln!(
                    out,
                    "{} ({}): forward and reverse columns from the two approach directions; mean reversal {:.4} µm (BACKLASH {:.6} mm without the COMP_FILE)",
                    d.variable,
                    d.error,
                    d.mean_reversal * 1e3,
                    d.backlash
                )
            } else {
                writeln!(
                    out,
                    "{} ({}): the same trim in both columns (no reverse direction in the values)",
                    d.variable, d.error
                )
            };
        }
        let grid: Vec<String> = (r.check_grid.iter())
            .map(|(n, v)| format!("{n} {} nodes", v.len()))
            .collect();
        let _ = writeln!(out, "check grid: {}", grid.join(", "));
        out
    }
}
