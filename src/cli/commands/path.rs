//! `chain path FILE (--axes AXES.csv | --pose POSE.csv [--fix NAME=VALUE]...)
//! [--param NAME=VALUE]... [--method form|is|mc] [--samples N] [--seed S]
//! [--sided upper|two] [--system series|volumetric] [--system-tolerance T]
//! [--format table|json|csv] [--plot DIR]`: error and reliability along a
//! path ([`chain::ops::path`], docs/path.md).

use std::path::PathBuf;

use chain::ops::path::{self, PathInput, PathOpsError, PathRequest};
use reliability::Method;

use crate::cli::args::parse_assignment;
use crate::cli::args::{AlgorithmArgs, ModelArgs, SystemArgs, ThermalArgs};
use crate::cli::csv_input::{numeric_table, read_poses};
use crate::cli::loaded::Loaded;
use crate::cli::progress::Progress;
use crate::cli::{plot, report};

/// Output formats of `chain path`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum PathFormat {
    /// One row per instant (error statistics, then reliability) and a summary.
    Table,
    /// The JSON document of `docs/path.md`.
    Json,
    /// One row per instant.
    Csv,
}

/// Arguments of `chain path`.
#[derive(Debug, clap::Args)]
#[command(group(clap::ArgGroup::new("path").required(true).args(["axes", "pose"])))]
pub struct PathArgs {
    /// Machine file (YAML) with `statistics` and `reliability` sections.
    pub file: PathBuf,
    /// Axis values along the path: CSV whose header names every axis
    /// variable (any order; rotary ones in radians) with an optional leading
    /// column `t`; `-` reads stdin.
    #[arg(long, value_name = "AXES.csv")]
    pub axes: Option<PathBuf>,
    /// Tool poses along the path: CSV with header `px,py,pz,i,j,k` or
    /// `px,py,pz,r11,…,r33` (optional leading `t`), solved by the inverse
    /// kinematics; `-` reads stdin.
    #[arg(long, value_name = "POSE.csv")]
    pub pose: Option<PathBuf>,
    /// Hold a variable at a value, `NAME=VALUE` (repeatable): a variable
    /// without a column (`--axes`) or one a pose does not determine (`--pose`).
    #[arg(long = "fix", value_name = "NAME=VALUE", value_parser = parse_assignment)]
    pub fix: Vec<(String, f64)>,
    #[command(flatten)]
    pub model: ModelArgs,
    #[command(flatten)]
    pub thermal: ThermalArgs,
    #[command(flatten)]
    pub algorithm: AlgorithmArgs,
    #[command(flatten)]
    pub system: SystemArgs,
    /// Output format.
    #[arg(long, value_enum, default_value = "table")]
    pub format: PathFormat,
    /// Write the reliability and the error standard deviations along the
    /// path (PNG and SVG) into DIR.
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
}

/// Runs `chain path`.
pub fn exec(args: PathArgs) -> miette::Result<()> {
    // Refused before the machine file is read.
    args.algorithm.check()?;
    let system = args.system.choice()?;
    let loaded = Loaded::new(&args.file)?;
    let (source, table, poses);
    let input = match (&args.axes, &args.pose) {
        (Some(file), _) => {
            table = numeric_table(file)?;
            PathInput::Axes {
                source: &table.name,
                header: &table.header,
                rows: &table.rows,
            }
        }
        (None, Some(file)) => {
            let (has_t, read) = read_poses(file)?;
            poses = read;
            source = match file.as_os_str() == "-" {
                true => "<stdin>".to_string(),
                false => file.display().to_string(),
            };
            PathInput::Poses {
                source: &source,
                has_t,
                rows: &poses,
            }
        }
        (None, None) => miette::bail!("give the path with --axes AXES.csv or --pose POSE.csv"),
    };
    let request = PathRequest {
        params: &args.model.param.params,
        fix: &args.fix,
        sided: args.model.sided,
        system,
        algorithm: args.algorithm.options(),
        input,
        temperatures: &args.thermal.temperatures,
    };
    let report = |e: PathOpsError| match e {
        PathOpsError::Reliability(e) => loaded.report(e),
        PathOpsError::Resolve(e) => miette::Report::new(e),
        PathOpsError::Option(e) => miette::Report::new(e),
        PathOpsError::Machine(e) => miette::Report::new(e),
    };
    let prepared = path::prepare(&loaded.machine, &request).map_err(report)?;
    for note in &prepared.notes {
        eprintln!("{note}");
    }
    // A counter of the cases (FORM, SORM) or samples done: the instants
    // with axis values are known only once the path is solved.
    let (verb, unit) = match request.algorithm.method {
        Method::Form | Method::Sorm => (request.algorithm.method.title(), "cases"),
        _ => ("sampling", "samples"),
    };
    let bar = Progress::new(args.format != PathFormat::Json, None, verb, unit);
    let format = args.format.into();
    if let Some(dir) = &args.plot {
        // The charts need every record: the path is run in memory.
        let printed = prepared.notes.len();
        let doc = prepared.run(&|n| bar.inc(n));
        bar.finish();
        let doc = doc.map_err(report)?;
        for f in plot::write(dir, &chain::plot::path::charts(&doc))? {
            eprintln!("wrote {}", f.display());
        }
        report::emit(&doc.output(), format)?;
        for note in &doc.notes[printed..] {
            eprintln!("{note}");
        }
        return Ok(());
    }
    // Otherwise each block of instants is written as it is done and only
    // the summary is kept.
    let progress = |n| bar.inc(n);
    let output = prepared.output(&progress);
    let written = report::emit(&output, format);
    bar.finish();
    if let Some(e) = output.take_error() {
        return Err(loaded.report(e));
    }
    written?;
    if let Some(summary) = output.summary() {
        for note in output.head.run_notes(&summary) {
            eprintln!("{note}");
        }
    }
    Ok(())
}

report::formats!(PathFormat: Table, Json, Csv);
