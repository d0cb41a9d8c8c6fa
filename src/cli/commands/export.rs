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

use chain::ops::export::{self, ExportController, ExportOpsError, ExportRequest};
use chain::ops::resolve::AxisPoints;
use chain::ops::source::{self, Source};
use chain_core::compensation::ExportedFile;
use miette::MietteDiagnostic;

use crate::cli::args::parse_grid_axis;
use crate::cli::args::{ParamArgs, ThermalArgs};
use crate::cli::csv_input::axes_points;
use crate::cli::loaded::Loaded;
use crate::cli::report;

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
    #[arg(long, value_parser = chain::ops::choice::parser::<ExportController>())]
    pub controller: ExportController,
    /// Replace (or add) the grid values of one axis: `VAR=V1,V2,...`, or
    /// `VAR=LO:HI:N` (repeatable). For the per-axis table formats it gives
    /// the axis's travel (its smallest and largest value; any further
    /// values must be nodes of the table, see --step).
    #[arg(long = "grid", value_name = "VAR=V1,V2,...|VAR=LO:HI:N", value_parser = parse_grid_axis)]
    pub grid: Vec<(String, Vec<f64>)>,
    /// Nodes from a CSV of commanded poses instead of the grid: a header
    /// naming every axis variable (rotary in radians), an optional leading
    /// `t`; `-` reads stdin.
    #[arg(long, value_name = "AXES.csv")]
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
    /// heidenhain: write the rotary axes' angle rows (each axis line's
    /// tilts, `B0C`, `C0A`, ...) besides their position rows.
    #[arg(long)]
    pub angles: bool,
    #[command(flatten)]
    pub param: ParamArgs,
    #[command(flatten)]
    pub thermal: ThermalArgs,
    /// Write the exported file(s) into DIR (created if missing) and the
    /// summary to stdout; without it the file goes to stdout.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// The summary's format (with --out: table by default; without --out,
    /// asks for the summary instead of the file).
    #[arg(long, value_enum)]
    pub format: Option<ExportFormat>,
}

/// Runs `chain export` ([`chain::ops::export`]).
pub fn exec(args: ExportArgs) -> miette::Result<()> {
    let controller = args.controller;
    // The rows are read once the machine is: the options refuse `--axes`
    // with `--grid` or a per-axis format before anything is read.
    let rows = (args.axes.as_ref()).map(|p| (p.display().to_string(), Vec::new()));
    let mut request = ExportRequest {
        controller,
        params: &args.param.params,
        points: AxisPoints::new(&args.grid, rows)?,
        step: args.step,
        cec_max_points: args.cec_max_points,
        beckhoff_max_records: args.beckhoff_max_records,
        angles: args.angles,
        temperatures: &args.thermal.temperatures,
    };
    export::check(&request)?;
    if controller != ExportController::Grid && args.format == Some(ExportFormat::Csv) {
        let d = MietteDiagnostic::new(format!(
            "--controller {} does not take --format csv",
            controller.name()
        ))
        .with_code("chain::export::option")
        .with_help("--format csv is the grid CSV of --controller grid; this controller writes its own files (--out DIR) and its report as table or json");
        return Err(miette::Report::new(d));
    }
    let loaded = Loaded::new(&args.file)?;
    let m = &loaded.machine;
    let values = source::read_values(Source::Path(&args.values), m)?;
    if let (Some(path), AxisPoints::Rows { values: rows, .. }) = (&args.axes, &mut request.points) {
        *rows = axes_points(path, m)?;
    }
    let file = args.file.display().to_string();
    let values_file = args.values.display().to_string();
    let doc = export::run(m, &file, values, &values_file, &request).map_err(|e| match e {
        ExportOpsError::Reliability(e) => loaded.report(e),
        e => miette::Report::new(e),
    })?;
    match (&args.out, args.format) {
        (Some(dir), format) => {
            write_files(dir, doc.files())?;
            report::emit(&doc, format.unwrap_or(ExportFormat::Table).into())
        }
        (None, Some(format)) => report::emit(&doc, format.into()),
        (None, None) => match doc.files() {
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

/// Writes `files` into `dir` (created if missing), naming each on stderr.
fn write_files(dir: &std::path::Path, files: &[ExportedFile]) -> miette::Result<()> {
    std::fs::create_dir_all(dir)
        .map_err(|e| miette::miette!("cannot create {}: {e}", dir.display()))?;
    for f in files {
        let path = dir.join(&f.name);
        crate::cli::atomic::write(&path, f.text.as_bytes())
            .map_err(|e| miette::miette!("cannot write {}: {e}", path.display()))?;
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}
