//! `chain reliability FILE [--values VALUES.yaml] [--method form|is|mc]
//! [--samples N] [--seed S] [--format table|json|csv] [--plot DIR]`.
//!
//! With `--values` the inputs are the posterior of a calibration
//! (`docs/posterior.md`, [`reliability::Posterior`]): the values file's
//! constants as means, their `std` and `correlation` as a correlated normal,
//! the `statistics` section for the errors the file does not give.
//!
//! Machining-accuracy reliability of every listed component (and optionally
//! a series or volumetric system) over the file's grid, like Tables 2-4 of
//! seed 000 ([`chain::ops::reliability`]; the table and CSV in
//! `cli/render/reliability.rs`).

use std::path::PathBuf;

use chain::ops::reliability::{self, ReliabilityOpsError, ReliabilityRequest};

use crate::cli::args::{parse_grid_axis, AlgorithmArgs, ModelArgs, SystemArgs, ThermalArgs};
use crate::cli::loaded::Loaded;
use crate::cli::progress::Progress;
use crate::cli::report;

/// Output formats of `chain reliability`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ReliabilityFormat {
    /// Maps like the paper's Tables 2-4 and a summary.
    Table,
    /// The spec's JSON document.
    Json,
    /// One row per (target, point).
    Csv,
}

/// Arguments of `chain reliability`.
#[derive(Debug, clap::Args)]
pub struct ReliabilityArgs {
    /// Machine file (YAML) with `statistics` and `reliability` sections.
    pub file: PathBuf,
    #[command(flatten)]
    pub algorithm: AlgorithmArgs,
    /// Output format.
    #[arg(long, value_enum, default_value = "table")]
    pub format: ReliabilityFormat,
    /// Write heat maps and sensitivity bar charts (PNG and SVG) into DIR.
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
    #[command(flatten)]
    pub model: ModelArgs,
    #[command(flatten)]
    pub thermal: ThermalArgs,
    /// Replace the grid values of one axis, `VAR=V1,V2,...`, or `VAR=LO:HI:N` for N evenly spaced values from LO to HI (repeatable).
    #[arg(long = "grid", value_name = "VAR=V1,V2,...|VAR=LO:HI:N", value_parser = parse_grid_axis)]
    pub grid: Vec<(String, Vec<f64>)>,
    #[command(flatten)]
    pub system: SystemArgs,
    /// A values file with the posterior of a calibration (means, `std` per
    /// constant, `correlation: [[NAME, NAME, rho], ...]`) or a built
    /// machine's measured tables (a positioning run's means and
    /// repeatability); errors it does not give keep their `statistics`
    /// (docs/posterior.md).
    #[arg(long, value_name = "VALUES.yaml")]
    pub values: Option<PathBuf>,
    /// Which approach direction of the values' bidirectional tables to
    /// read: `up`, `down` or `mean` (the default), or per axis
    /// `x=up,y=down` (docs/values.md, "Direction").
    #[arg(long, value_name = "DIR|VAR=DIR,...", value_parser = chain_core::values::parse_approaches)]
    pub approach: Vec<Vec<(Option<String>, chain_core::values::Approach)>>,
    /// Also the whole-machine acceptance probability: every toleranced
    /// component within tolerance at every grid point at once, with its
    /// sensitivities (as `reliability.acceptance: true`; docs/acceptance.md).
    #[arg(long)]
    pub acceptance: bool,
    /// Absolute error of the acceptance probability (three standard errors).
    #[arg(long, value_name = "ABS", default_value_t = 1e-3)]
    pub acceptance_tolerance: f64,
}

/// Runs `chain reliability` ([`chain::ops::reliability`]).
pub fn exec(args: ReliabilityArgs) -> miette::Result<()> {
    args.algorithm.check()?;
    // Refused before the machine file is read.
    let system = args.system.choice()?;
    let approach: Vec<_> = args.approach.iter().flatten().cloned().collect();
    chain::ops::study::check_approach(args.values.as_deref(), &approach)?;
    let loaded = Loaded::new(&args.file)?;
    let request = ReliabilityRequest {
        params: &args.model.param.params,
        grid: &args.grid,
        sided: args.model.sided,
        system,
        algorithm: args.algorithm.options(),
        values: args.values.as_deref(),
        approach: &approach,
        acceptance: args.acceptance,
        acceptance_tolerance: args.acceptance_tolerance,
        temperatures: &args.thermal.temperatures,
    };
    let refused = |e: ReliabilityOpsError| match e {
        ReliabilityOpsError::Option(e) => miette::Report::new(e),
        ReliabilityOpsError::Study(e) => loaded.study_error(*e),
        ReliabilityOpsError::Reliability(e) => loaded.report(e),
    };
    let prepared =
        reliability::prepare(&loaded.machine, loaded.file_name(), &request).map_err(refused)?;
    // A bar over the samples when their count is known in advance (the
    // fixed-count samplers) or over the cases (FORM, SORM), else a counter
    // (subset simulation, whose levels are found as it runs, and every
    // sampler stopped by `--cov`).
    let plan = prepared.progress_plan();
    let bar = Progress::new(
        args.format != ReliabilityFormat::Json,
        plan.total,
        plan.verb,
        plan.unit,
    );
    // Written as it runs, a block of cases at a time, unless the output
    // needs every case at once (the charts, a small grid's maps).
    let maps = args.format == ReliabilityFormat::Table
        && prepared.study.points().len() <= chain::ops::reliability::TABLE_POINTS;
    let inc = |n| bar.inc(n);
    if let Some(output) = (args.plot.is_none() && !maps)
        .then(|| prepared.output(&inc))
        .flatten()
    {
        let written = report::emit(&output, args.format.into());
        bar.finish();
        if let Some(e) = output.take_error() {
            return Err(loaded.report(e));
        }
        for note in output.notes() {
            eprintln!("{note}");
        }
        return written;
    }
    let run = prepared.run(&inc);
    bar.finish();
    let run = run.map_err(|e| loaded.report(e))?;
    for note in &run.notes {
        eprintln!("{note}");
    }
    if let Some(dir) = &args.plot {
        let charts = chain::plot::reliability::charts(&run).map_err(|e| loaded.report(e))?;
        for f in crate::cli::plot::write(dir, &charts)? {
            eprintln!("wrote {}", f.display());
        }
    }
    report::emit(&run, args.format.into())
}

report::formats!(ReliabilityFormat: Table, Json, Csv);
