//! `chain map FILE --values VALUES.yaml [--grid VAR=V1,V2,...|VAR=LO:HI:N]...
//! [--axes AXES.csv] [--param NAME=VALUE]... [--format table|json|csv]
//! [--plot DIR] [--compensated CONTROLLER [--compensation-grid VAR=...]...]`.
//!
//! The volumetric error of a built machine (measured-machines spec, section
//! 3): `E(q) = Σ_j c_j(q)·v_j(q)` at every point of the machine file's
//! `reliability.grid` (full factorial, each axis replaceable by `--grid`) or
//! at every row of `--axes`, with the error values `v_j` of a values file
//! (section 2), through [`chain_core::BuiltMachine::map`]. See `docs/map.md`.
//!
//! `--compensated CONTROLLER` adds the map after compensation
//! (`docs/export.md`): the controller's correction
//! ([`chain_core::compensation::Correction`]) added to every commanded point,
//! the residual through [`chain_core::BuiltMachine::compensated_map`], shown
//! next to the uncompensated map (table, JSON `compensated`, CSV columns
//! `*_after`, plots in `DIR/compensated/`).

use std::path::PathBuf;

use chain::ops::export::ExportController;
use chain::ops::map::{CompensationRequest, MapOpsError, MapRequest};
use chain::ops::resolve::AxisPoints;
use chain::ops::source::{self, Source};
use chain_core::values::{parse_approaches, Approach};

use crate::cli::args::parse_grid_axis;
use crate::cli::args::{ParamArgs, ThermalArgs};
use crate::cli::csv_input::axes_points;
use crate::cli::loaded::Loaded;
use crate::cli::progress::Progress;
use crate::cli::render::map::TABLE_POINTS;
use crate::cli::report;

/// Maps with at least this many points show a progress bar (on a terminal).
const PROGRESS_POINTS: usize = 200_000;

/// Output formats of `chain map`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum MapFormat {
    /// The ISO 230-1-style summary (and the points of small maps).
    Table,
    /// The spec's JSON document.
    Json,
    /// One row per point.
    Csv,
}

report::formats!(MapFormat: Table, Json, Csv);

/// Arguments of `chain map`.
#[derive(Debug, clap::Args)]
pub struct MapArgs {
    /// Machine file (YAML).
    pub file: PathBuf,
    /// The error values of the built machine: a values file (YAML; its
    /// tables are relative to it).
    #[arg(long, value_name = "VALUES.yaml")]
    pub values: PathBuf,
    /// Replace (or add) the grid values of one axis: `VAR=V1,V2,...`, or
    /// `VAR=LO:HI:N` for N evenly spaced values from LO to HI (repeatable).
    #[arg(long = "grid", value_name = "VAR=V1,V2,...|VAR=LO:HI:N", value_parser = parse_grid_axis)]
    pub grid: Vec<(String, Vec<f64>)>,
    /// Which approach direction of the bidirectional tables to map:
    /// `up`, `down` or `mean` (the default) for every axis, or per axis
    /// `x=up,y=down` (repeatable; docs/values.md, "Direction").
    #[arg(long, value_name = "DIR|VAR=DIR,...", value_parser = parse_approaches)]
    pub approach: Vec<Vec<(Option<String>, Approach)>>,
    /// Points from a CSV instead of the grid: a header naming every axis
    /// variable (any order; rotary ones in radians), an optional leading
    /// column `t`; `-` reads stdin.
    #[arg(long, value_name = "AXES.csv")]
    pub axes: Option<PathBuf>,
    #[command(flatten)]
    pub param: ParamArgs,
    #[command(flatten)]
    pub thermal: ThermalArgs,
    /// Output format.
    #[arg(long, value_enum, default_value = "table")]
    pub format: MapFormat,
    /// Write heat maps of every component and a magnified distorted-grid
    /// picture (PNG and SVG) into DIR.
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
    /// Also map the error left after this controller's compensation
    /// (exported from the same values; see docs/export.md).
    #[arg(long, value_parser = chain::ops::choice::parser::<ExportController>(), value_name = "CONTROLLER")]
    pub compensated: Option<ExportController>,
    /// The grid the `grid` correction is exported on, per axis (default:
    /// the map's grid, or the machine file's with --axes; repeatable). For
    /// the per-axis table formats: the travel of the axis's table (its
    /// smallest and largest value; default: the map's grid range, else the
    /// machine file's).
    #[arg(long = "compensation-grid", value_name = "VAR=V1,V2,...|VAR=LO:HI:N", value_parser = parse_grid_axis, requires = "compensated")]
    pub compensation_grid: Vec<(String, Vec<f64>)>,
    /// The largest table step (mm) of a per-axis table format's
    /// compensation (as `chain export --step`) [default: 10].
    #[arg(
        long = "compensation-step",
        value_name = "MM",
        requires = "compensated"
    )]
    pub compensation_step: Option<f64>,
    /// heidenhain: compensate with the rotary axes' angle rows too (as
    /// `chain export --angles`).
    #[arg(long = "compensation-angles", requires = "compensated")]
    pub compensation_angles: bool,
}

/// Runs `chain map` ([`chain::ops::map`]).
pub fn exec(args: MapArgs) -> miette::Result<()> {
    // The rows are read once the machine is: `AxisPoints::new` refuses
    // `--axes` with `--grid` before anything is read.
    let rows = (args.axes.as_ref()).map(|p| (p.display().to_string(), Vec::new()));
    let mut points = AxisPoints::new(&args.grid, rows)?;
    let loaded = Loaded::new(&args.file)?;
    let m = &loaded.machine;
    let values = source::read_values(Source::Path(&args.values), m)?;
    let choices: Vec<_> = args.approach.iter().flatten().cloned().collect();
    if let (Some(path), AxisPoints::Rows { values: rows, .. }) = (&args.axes, &mut points) {
        *rows = axes_points(path, m)?;
    }
    let mut request = MapRequest {
        params: &args.param.params,
        approach: &choices,
        points,
        compensated: args.compensated.map(|controller| CompensationRequest {
            controller,
            grid: &args.compensation_grid,
            step: args.compensation_step,
            angles: args.compensation_angles,
        }),
        keep_points: true,
        temperatures: &args.thermal.temperatures,
    };
    let report = |e: MapOpsError| match e {
        MapOpsError::Reliability(e) => loaded.report(e),
        e => miette::Report::new(e),
    };
    let file = args.file.display().to_string();
    let values_file = args.values.display().to_string();
    let prepared =
        chain::ops::map::prepare(m, &file, values, &values_file, &request).map_err(report)?;
    let count = prepared.points.len();
    // The table of a large map shows the summary only: it needs no point's
    // error kept (the plots and the other formats do).
    request.keep_points =
        args.format != MapFormat::Table || args.plot.is_some() || count <= TABLE_POINTS;
    let show = count >= PROGRESS_POINTS && args.format != MapFormat::Json;
    let bar = Progress::new(show, Some(count as u64), "mapping", "points");
    let doc = prepared.run(m, &request, &|n| bar.inc(n as u64));
    bar.finish();
    let doc = doc.map_err(report)?;
    if let Some(dir) = &args.plot {
        let charts = chain::plot::map::charts(&doc, &prepared.built);
        for f in crate::cli::plot::write(dir, &charts)? {
            eprintln!("wrote {}", f.display());
        }
    }
    report::emit(&doc, args.format.into())
}
