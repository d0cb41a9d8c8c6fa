//! `chain allocate FILE [--strategy optimal|paper] [--step TOL] [--format table|json]`.
//!
//! Precision allocation (Wang & Yuan 2021, Section 3.3, Tables 5-7): the paper's
//! fixed-step tightening of the most sensitive errors, or the least-cost
//! standard deviations that meet the requirement (with a KKT check). An
//! infeasible requirement is an error naming the component, the case and the
//! bounds that bind. See `docs/allocation.md`.

use std::path::PathBuf;

use chain::ops::allocate::{self as ops, AllocateOpsError, AllocateRequest, AllocationTarget};
use chain::ops::choice::{parser, Rank};
use miette::MietteDiagnostic;
use reliability::allocate::StrategyName;

use crate::cli::args::ModelArgs;
use crate::cli::loaded::Loaded;
use crate::cli::{plot, report};

/// Output formats of `chain allocate`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum AllocateFormat {
    /// Rounds like Wang & Yuan 2021's Tables 5-7, the final tolerances and the KKT check.
    Table,
    /// The spec's JSON document.
    Json,
}

report::formats!(AllocateFormat: Table, Json);

/// `--threshold`, checked while parsing by [`ops::check_threshold`].
fn threshold(text: &str) -> Result<f64, String> {
    let t: f64 = (text.trim().parse()).map_err(|_| format!("`{text}` is not a number"))?;
    ops::check_threshold(t).map_err(|e| e.message)
}

/// Arguments of `chain allocate`.
#[derive(Debug, clap::Args)]
pub struct AllocateArgs {
    /// Machine file (YAML) with `statistics` and a `reliability` section with a `requirement`.
    pub file: PathBuf,
    /// Allocation strategy.
    #[arg(long, value_parser = parser::<StrategyName>(), default_value = "optimal")]
    pub strategy: StrategyName,
    /// Step of `--strategy paper` in the tolerance units of Wang & Yuan 2021's Table 1 (σ decreases by
    /// step/6 mm, step/6000 rad for angular and step/3000 rad for squareness errors).
    #[arg(long, value_name = "TOL", default_value_t = 0.005)]
    pub step: f64,
    /// Sensitivity threshold of `--strategy paper`, as a fraction of the largest, in [0, 1].
    #[arg(long, default_value_t = 0.1, value_parser = threshold, allow_negative_numbers = true)]
    pub threshold: f64,
    /// Ranking of `--strategy paper`.
    #[arg(long, value_parser = parser::<Rank>(), default_value = "component")]
    pub rank: Rank,
    /// What to allocate for.
    #[arg(long, value_parser = parser::<AllocationTarget>(), default_value = "requirement")]
    pub target: AllocationTarget,
    /// The acceptance probability to reach with `--target acceptance`, in (0, 1).
    #[arg(long, value_name = "L")]
    pub level: Option<f64>,
    /// Output format.
    #[arg(long, value_enum, default_value = "table")]
    pub format: AllocateFormat,
    #[command(flatten)]
    pub model: ModelArgs,
    /// Write before/after reliability charts per component and a chart of
    /// the tightening per error (PNG and SVG) into DIR.
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
}

/// Runs `chain allocate` ([`chain::ops::allocate`]).
pub fn exec(args: AllocateArgs) -> miette::Result<()> {
    let request = AllocateRequest {
        strategy: args.strategy,
        step: args.step,
        threshold: args.threshold,
        pooled: args.rank.pooled(),
        target: args.target,
        level: args.level,
        params: &args.model.param.params,
        sided: args.model.sided,
    };
    ops::check(&request)?;
    let loaded = Loaded::new(&args.file)?;
    let run = ops::run(&loaded.machine, loaded.file_name(), &request).map_err(|e| match e {
        AllocateOpsError::Study(e) => loaded.study_error(*e),
        AllocateOpsError::Reliability(e) => loaded.report(e),
        e => match e.location() {
            Some((origin, label)) => loaded.located(&e, origin, label),
            None => miette::Report::new(e),
        },
    })?;
    if let Some(dir) = &args.plot {
        let charts = chain::plot::allocate::charts(&run).map_err(|e| loaded.report(e))?;
        for f in plot::write(dir, &charts)? {
            eprintln!("wrote {}", f.display());
        }
    }
    report::emit(&run, args.format.into())?;
    match run.not_met() {
        Some(message) => Err(miette::Report::new(
            MietteDiagnostic::new(message).with_code("chain::allocate::not_met"),
        )),
        None => Ok(()),
    }
}
