//! `chain sobol FILE [--at VAR=V,...] [--samples N] [--seed S] [--bootstrap B]
//! [--confidence L] [--grid VAR=V1,...] [--param NAME=VALUE] [--format table|json|csv]`.
//!
//! First-order and total Sobol indices (Saltelli et al. 2010, Table 2 (b)
//! and (f)) of every toleranced component and of `|p|` with respect to every
//! error parameter, with bootstrap percentile intervals: at one point with
//! `--at`, otherwise pooled over the reliability grid (the grid-summed
//! variance decomposition; `reliability::sobol`, docs/sobol.md).

use std::path::PathBuf;

use reliability::document::SobolDocument;
use reliability::sobol::{Estimate, Sobol, SobolError};
use reliability::{machine, Study};

use super::args::parse_axis;
use super::args::ParamArgs;
use super::args::{parse_point, AtPoint};
use super::loaded::resolve_at;
use super::loaded::Loaded;
use super::report::{self, Csv, Report};

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
    /// Replace the grid values of one axis, `VAR=v1,v2,...` (repeatable; not with --at).
    #[arg(long = "grid", value_name = "VAR=V1,V2,...", value_parser = parse_axis)]
    pub grid: Vec<(String, Vec<f64>)>,
    #[command(flatten)]
    pub param: ParamArgs,
    /// Output format.
    #[arg(long, value_enum, default_value = "table")]
    pub format: SobolFormat,
}

/// Runs `chain sobol`.
pub fn exec(args: SobolArgs) -> miette::Result<()> {
    let settings = settings(&args)?;
    let loaded = Loaded::new(&args.file)?;
    let (study, at) = match &args.at {
        None => {
            let (study, _) = loaded.study_with(&args.param.params, &args.grid, None, None, None)?;
            (study, false)
        }
        Some(AtPoint(coords)) => {
            if !args.grid.is_empty() {
                return Err(chain::ops::resolve::ResolveError::AtWithGrid {
                    grid_for: "the pooled indices",
                }
                .into());
            }
            let point = resolve_at(coords, &loaded)?;
            let m = &loaded.machine;
            let spec = machine::spec(m, None).map_err(|e| loaded.report(e))?;
            let inputs = machine::inputs(m).map_err(|e| loaded.report(e))?;
            let values =
                machine::parameters(m, &args.param.params).map_err(|e| loaded.report(e))?;
            let model = chain_core::compile(m);
            let study = Study::at_points(&model, &values, inputs, spec, vec![point])
                .map_err(|e| loaded.report(e))?;
            (study, true)
        }
    };
    let result = settings
        .run_study(&study)
        .map_err(|e| sobol_error(&args.file, e))?;
    let doc = SobolDocument::new(&loaded.machine.name, &study, at, &result);
    report::emit(&doc, args.format.into())
}

/// The analysis of the options, every value checked with its option named.
fn settings(args: &SobolArgs) -> miette::Result<Sobol> {
    let s = Sobol {
        samples: usize::try_from(args.samples).unwrap_or(usize::MAX),
        seed: args.seed,
        bootstrap: usize::try_from(args.bootstrap).unwrap_or(usize::MAX),
        confidence: args.confidence,
    };
    // The library's checks, reported with the option's name.
    match s.validate() {
        Err(SobolError::InvalidSetting { what, rule, found }) => {
            Err(miette::miette!("--{what} {found}: must be {rule}"))
        }
        Err(e) => Err(miette::Report::new(e)),
        Ok(()) => Ok(s),
    }
}

/// A rendered library error (correlated inputs, a constant output).
fn sobol_error(file: &std::path::Path, e: SobolError) -> miette::Report {
    let file = file.display().to_string();
    miette::Report::new(e).wrap_err(format!("{file}: chain sobol"))
}

fn cell(v: f64) -> String {
    format!("{v:.6}")
}

fn exact_cell(e: &Estimate) -> String {
    e.exact.map_or_else(|| "-".to_string(), cell)
}

impl Report for SobolDocument<'_> {
    fn table(&self) -> String {
        use std::fmt::Write as _;
        let mut out = String::new();
        let where_ = match &self.at {
            Some(a) => format!(
                "at {}",
                a.0.iter()
                    .map(|(n, v)| format!("{n} = {v}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
            None => format!(
                "pooled over the {} grid points (sum of variances)",
                self.points
            ),
        };
        let _ = writeln!(
            out,
            "{}: Sobol indices (Saltelli 2010 first order, Jansen total), {where_}",
            self.machine
        );
        let _ = writeln!(
            out,
            "N = {} base samples ({} evaluations per point), seed {}, {} % bootstrap percentile intervals ({} replicates over {} blocks)",
            self.samples,
            self.evaluations_per_point,
            self.seed,
            self.confidence * 100.0,
            self.bootstrap,
            self.blocks
        );
        for o in &self.result.outputs {
            let name = match o.output {
                reliability::Target::Volumetric => "|p| (volumetric)".to_string(),
                t => t.name().to_string(),
            };
            let _ = writeln!(
                out,
                "\n{name}: variance {:.6e}, sum S = {} [{}, {}], sum T = {} [{}, {}]; sorted by T:",
                o.variance,
                cell(o.sum_first.value),
                cell(o.sum_first.low),
                cell(o.sum_first.high),
                cell(o.sum_total.value),
                cell(o.sum_total.low),
                cell(o.sum_total.high),
            );
            let _ = writeln!(
                out,
                "  {:<8} {:>9} {:>21} {:>9} {:>21} {:>9}",
                "error", "S", "interval", "T", "interval", "exact"
            );
            let mut order: Vec<usize> = (0..o.errors.len()).collect();
            order.sort_by(|&a, &b| o.errors[b].total.value.total_cmp(&o.errors[a].total.value));
            for i in order {
                let e = &o.errors[i];
                let _ = writeln!(
                    out,
                    "  {:<8} {:>9} {:>21} {:>9} {:>21} {:>9}",
                    e.error,
                    cell(e.first.value),
                    format!("[{}, {}]", cell(e.first.low), cell(e.first.high)),
                    cell(e.total.value),
                    format!("[{}, {}]", cell(e.total.low), cell(e.total.high)),
                    exact_cell(&e.first),
                );
            }
        }
        out
    }

    fn csv(&self) -> Option<Csv> {
        let mut c = Csv::new([
            "output",
            "error",
            "first",
            "first_low",
            "first_high",
            "total",
            "total_low",
            "total_high",
            "exact",
        ]);
        let num = |v: f64| format!("{v:?}");
        for o in &self.result.outputs {
            for e in &o.errors {
                c.row([
                    o.output.name().to_string(),
                    e.error.clone(),
                    num(e.first.value),
                    num(e.first.low),
                    num(e.first.high),
                    num(e.total.value),
                    num(e.total.low),
                    num(e.total.high),
                    e.first.exact.map(num).unwrap_or_default(),
                ]);
            }
        }
        Some(c)
    }
}
