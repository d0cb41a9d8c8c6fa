//! `chain sobol FILE [--at VAR=V,...] [--samples N] [--seed S] [--bootstrap B]
//! [--confidence L] [--grid VAR=V1,...] [--param NAME=VALUE] [--format table|json|csv]`.
//!
//! First-order and total Sobol indices (Saltelli et al. 2010, Table 2 (b)
//! and (f)) of every toleranced component and of `|p|` with respect to every
//! error parameter, with bootstrap percentile intervals: at one point with
//! `--at`, otherwise pooled over the reliability grid (the grid-summed
//! variance decomposition; `reliability::sobol`, docs/sobol.md).

use std::path::PathBuf;

use chain::ops::sobol::{self, SobolOpsError, SobolRequest};

use crate::cli::args::parse_grid_axis;
use crate::cli::args::ParamArgs;
use crate::cli::args::{parse_point, AtPoint};
use crate::cli::loaded::Loaded;
use crate::cli::report;

/// Output formats of `chain sobol`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum SobolFormat {
    /// One table per output, sorted by the total index.
    Table,
    /// The JSON document (docs/sobol.md).
    Json,
    /// One row per output and error.
    Csv,
}

report::formats!(SobolFormat: Table, Json, Csv);

/// Arguments of `chain sobol`.
#[derive(Debug, clap::Args)]
pub struct SobolArgs {
    /// Machine file (YAML) with `statistics` and `reliability` sections.
    pub file: PathBuf,
    /// Evaluate at one point, e.g. `x=0,y=1500,z=600` (every axis variable);
    /// without it, the indices pooled over the reliability grid.
    #[arg(long, value_name = "VAR=VALUE,...", value_parser = parse_point)]
    pub at: Option<AtPoint>,
    /// Base samples N (rows of each of the matrices A and B; N·(k+2) model
    /// evaluations per point).
    #[arg(long, default_value_t = 10_000)]
    pub samples: u64,
    /// Seed of the random streams (results do not depend on the thread count).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Bootstrap replicates of the confidence intervals.
    #[arg(long, default_value_t = 1000)]
    pub bootstrap: u64,
    /// Confidence level of the bootstrap percentile intervals, in (0, 1).
    #[arg(long, default_value_t = 0.95)]
    pub confidence: f64,
    /// Replace the grid values of one axis, `VAR=V1,V2,...`, or `VAR=LO:HI:N` for N evenly spaced values from LO to HI (repeatable; not with --at).
    #[arg(long = "grid", value_name = "VAR=V1,V2,...|VAR=LO:HI:N", value_parser = parse_grid_axis)]
    pub grid: Vec<(String, Vec<f64>)>,
    #[command(flatten)]
    pub param: ParamArgs,
    /// Output format.
    #[arg(long, value_enum, default_value = "table")]
    pub format: SobolFormat,
}

/// Runs `chain sobol` ([`chain::ops::sobol`]).
pub fn exec(args: SobolArgs) -> miette::Result<()> {
    let request = SobolRequest {
        at: args.at.as_ref().map(|AtPoint(c)| c.as_slice()),
        samples: args.samples,
        seed: args.seed,
        bootstrap: args.bootstrap,
        confidence: args.confidence,
        grid: &args.grid,
        params: &args.param.params,
    };
    sobol::settings(&request, &args.file.display().to_string())?;
    let loaded = Loaded::new(&args.file)?;
    let run = sobol::run(&loaded.machine, loaded.file_name(), &request).map_err(|e| match e {
        SobolOpsError::Study(e) => loaded.study_error(*e),
        SobolOpsError::Reliability(e) => loaded.report(e),
        e => miette::Report::new(e),
    })?;
    report::emit(&run, args.format.into())
}
