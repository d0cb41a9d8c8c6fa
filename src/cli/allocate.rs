//! `chain allocate FILE [--strategy optimal|paper] [--step TOL] [--format table|json]`.
//!
//! Precision allocation (Wang & Yuan 2021, Section 3.3, Tables 5-7): the paper's
//! fixed-step tightening of the most sensitive errors, or the least-cost
//! standard deviations that meet the requirement (with a KKT check). An
//! infeasible requirement is an error naming the component, the case and the
//! bounds that bind. See `docs/allocation.md`.

use std::path::PathBuf;

use chain_core::model::Requirement;
use miette::MietteDiagnostic;
use reliability::allocate::{self, AllocateError, Allocation, ErrorBounds, Paper};
use reliability::document::{self, AllocationDocument};
use reliability::Summary;
use serde::Serialize;

use super::args::ModelArgs;
use super::loaded::Loaded;
use super::report::{self, Report};

/// `--strategy`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum StrategyArg {
    /// Least cost `Σ w (σ0/σ − 1)` subject to the requirement (interior point + KKT check).
    Optimal,
    /// Wang & Yuan 2021's procedure: tighten the errors within 10 % of the largest sensitivity by one step a round.
    Paper,
}

/// `--rank` of the paper's procedure.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum RankArg {
    /// Rank each unmet component's errors separately (Wang & Yuan 2021, Tables 5-7).
    Component,
    /// Rank the summed sensitivities of all unmet components.
    Pooled,
}

/// `--target`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum TargetArg {
    /// The reliability section's `requirement` (minimum and mean over the grid, per component).
    Requirement,
    /// The whole-machine acceptance probability reaches `--level` (docs/acceptance.md).
    Acceptance,
}

/// Output formats of `chain allocate`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum AllocateFormat {
    /// Rounds like Wang & Yuan 2021's Tables 5-7, the final tolerances and the KKT check.
    Table,
    /// The spec's JSON document.
    Json,
}

report::formats!(AllocateFormat: Table, Json);

/// Parses `--threshold`: a fraction of the largest sensitivity in [0, 1]
/// (above 1 no error is ever tightened, and NaN compares false with all).
fn parse_threshold(s: &str) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number"))?;
    if !(0.0..=1.0).contains(&v) {
        return Err(format!(
            "the threshold is a fraction of the largest sensitivity, in [0, 1] (found `{s}`)"
        ));
    }
    Ok(v)
}

/// Arguments of `chain allocate`.
#[derive(Debug, clap::Args)]
pub struct AllocateArgs {
    /// Machine file (YAML) with `statistics` and a `reliability` section with a `requirement`.
    pub file: PathBuf,
    /// Allocation strategy.
    #[arg(long, value_enum, default_value = "optimal")]
    pub strategy: StrategyArg,
    /// Step of `--strategy paper` in the tolerance units of Wang & Yuan 2021's Table 1 (σ decreases by
    /// step/6 mm, step/6000 rad for angular and step/3000 rad for squareness errors).
    #[arg(long, value_name = "TOL", default_value_t = 0.005)]
    pub step: f64,
    /// Sensitivity threshold of `--strategy paper`, as a fraction of the largest, in [0, 1].
    #[arg(long, default_value_t = 0.1, value_parser = parse_threshold, allow_negative_numbers = true)]
    pub threshold: f64,
    /// Ranking of `--strategy paper`.
    #[arg(long, value_enum, default_value = "component")]
    pub rank: RankArg,
    /// What to allocate for.
    #[arg(long, value_enum, default_value = "requirement")]
    pub target: TargetArg,
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

/// Runs `chain allocate`.
pub fn exec(args: AllocateArgs) -> miette::Result<()> {
    let loaded = Loaded::new(&args.file)?;
    let (study, model) = loaded.study(&args.model.param.params, &[], args.model.sided, None)?;
    let values = reliability::machine::parameters(&loaded.machine, &args.model.param.params)
        .map_err(|e| loaded.report(e))?;
    let bounds = allocate::bounds(&loaded.machine, &study).map_err(|e| loaded.report(e))?;
    let paper_options = Paper {
        step: args.step,
        threshold: args.threshold,
        pooled: args.rank == RankArg::Pooled,
        ..Paper::default()
    };
    let level = match (args.target, args.level) {
        (TargetArg::Acceptance, Some(l)) if l > 0.0 && l < 1.0 => Some(l),
        (TargetArg::Acceptance, Some(l)) => {
            return Err(miette::miette!(
            code = "chain::allocate::invalid_level",
            "invalid value for `--level`: {l} (an acceptance probability strictly between 0 and 1)"
        ))
        }
        (TargetArg::Acceptance, None) => {
            return Err(miette::miette!(
                code = "chain::allocate::missing_level",
                help = "e.g. --target acceptance --level 0.9",
                "`--target acceptance` needs `--level L`"
            ))
        }
        (TargetArg::Requirement, Some(_)) => {
            return Err(miette::miette!(
                code = "chain::allocate::invalid_level",
                "`--level` applies to `--target acceptance` only"
            ))
        }
        (TargetArg::Requirement, None) => None,
    };
    let strategy = match args.strategy {
        StrategyArg::Optimal => allocate::AcceptanceStrategy::Optimal,
        StrategyArg::Paper => allocate::AcceptanceStrategy::Paper(paper_options),
    };
    let result = document::allocation(&model, &values, &study, &bounds, strategy, level);
    let result = result.map_err(|e| failure(&loaded, e))?;
    if let Some(dir) = &args.plot {
        let stds: Vec<f64> = result.std.iter().map(|(_, s)| *s).collect();
        let before = study
            .form(&reliability::Form::default())
            .map_err(|e| loaded.report(e))?;
        let (_, after) =
            allocate::evaluate(&model, &values, &study, &stds).map_err(|e| loaded.report(e))?;
        let files = plot(
            dir,
            &loaded.machine.name,
            &study,
            &bounds,
            &result,
            &before,
            &after,
        )?;
        for f in files {
            eprintln!("wrote {}", f.display());
        }
    }
    let doc = AllocationReport {
        document: AllocationDocument::new(
            &loaded.machine.name,
            study.spec().requirement,
            &bounds,
            &result,
        ),
        bounds: &bounds,
        result: &result,
    };
    report::emit(&doc, args.format.into())?;
    if !result.met {
        return Err(miette::Report::new(
            MietteDiagnostic::new(match &result.acceptance {
                Some(a) => format!(
                    "the acceptance level {} is not reached after {} rounds (P = {})",
                    a.level,
                    result.steps.len(),
                    a.probability
                ),
                None => format!(
                    "the requirement is not met after {} rounds",
                    result.steps.len()
                ),
            })
            .with_code("chain::allocate::not_met"),
        ));
    }
    Ok(())
}

/// Before/after reliability over the grid per component, and the tightening
/// `σ0/σ` per error (per round for the paper's procedure).
fn plot(
    dir: &std::path::Path,
    machine: &str,
    study: &reliability::Study,
    bounds: &[ErrorBounds],
    r: &Allocation,
    before: &reliability::StudyResult,
    after: &reliability::StudyResult,
) -> Result<Vec<PathBuf>, crate::cli::plot::PlotError> {
    use crate::cli::plot::{Legend, Series, XyChart};
    let mut files = Vec::new();
    let np = study.points().len();
    let axes: Vec<&str> = study
        .spec()
        .grid
        .axes
        .iter()
        .map(|(n, _)| n.as_str())
        .collect();
    let req = study.spec().requirement;
    for (t, target) in study.targets().iter().enumerate() {
        let pts = |res: &reliability::StudyResult| -> Vec<(f64, f64)> {
            res.cases[t * np..(t + 1) * np]
                .iter()
                .enumerate()
                .map(|(i, c)| ((i + 1) as f64, c.reliability * 100.0))
                .collect()
        };
        let mut chart = XyChart::new(
            format!(
                "{machine}: {} reliability before and after allocation ({})",
                target.name(),
                r.strategy
            ),
            format!("grid point ({} order, first slowest)", axes.join(", ")),
            "reliability (%)",
        )
        .series(Series::line_points("before", pts(before)))
        .series(Series::line_points("after", pts(after)))
        .legend(Legend::LowerRight);
        if let Some(q) = req {
            chart = chart.hline(q.min * 100.0);
        }
        files.extend(chart.write(dir, &format!("allocate_{}", target.name()))?);
    }
    let mut chart = XyChart::new(
        format!("{machine}: tightening per error ({})", r.strategy),
        if r.steps.is_empty() {
            "initial (0) → allocated (1)"
        } else {
            "round"
        },
        "std0 / std",
    )
    .legend(Legend::UpperLeft);
    for (j, b) in bounds.iter().enumerate() {
        let last = r.std[j].1;
        if (last - b.std0).abs() <= 1e-15 * b.std0 {
            continue;
        }
        let mut points = vec![(0.0, 1.0)];
        if r.steps.is_empty() {
            points.push((1.0, b.std0 / last));
        } else {
            let mut s = b.std0;
            for step in &r.steps {
                if let Some((_, v)) = step.std.iter().find(|(n, _)| *n == b.error) {
                    s = *v;
                }
                points.push((step.round as f64, b.std0 / s));
            }
        }
        chart = chart.series(Series::line_points(b.error.clone(), points));
    }
    files.extend(chart.write(dir, "allocate_tightening")?);
    Ok(files)
}

/// An allocation that failed, rendered as the library's error with the
/// machine's name, a stable code and, where one helps, a hint.
///
/// The code and help are [`AllocateError`]'s own (its `miette::Diagnostic`
/// derive, forwarded); the [`AllocateError::Reliability`] case goes through
/// the located renderer of every reliability error instead, [`Loaded::report`].
#[derive(Debug, thiserror::Error, miette::Diagnostic)]
#[error("{machine}: {error}")]
#[diagnostic(forward(error))]
struct AllocateFailure {
    machine: String,
    error: AllocateError,
}

/// The one rendering of an [`AllocateError`]: reliability errors located in
/// the machine file, the others as an [`AllocateFailure`].
fn failure(loaded: &Loaded, error: AllocateError) -> miette::Report {
    match error {
        AllocateError::Reliability(e) => loaded.report(e),
        error => miette::Report::new(AllocateFailure {
            machine: loaded.machine.name.clone(),
            error,
        }),
    }
}

/// The result document of `chain allocate` (the library's
/// [`AllocationDocument`], JSON: docs/allocation.md) with its table.
#[derive(Serialize)]
#[serde(transparent)]
struct AllocationReport<'a> {
    document: AllocationDocument<'a>,
    #[serde(skip)]
    bounds: &'a [ErrorBounds],
    #[serde(skip)]
    result: &'a Allocation,
}

impl Report for AllocationReport<'_> {
    /// Rounds like Tables 5-7, the changed tolerances, the cost and the KKT check.
    fn table(&self) -> String {
        to_table(
            self.document.machine,
            self.document.requirement,
            self.bounds,
            self.result,
        )
    }
}

/// σ in Table 1's tolerance units (σ·6 mm, σ·6000 or σ·3000 for angles).
fn tolerance_units(b: &ErrorBounds, s: f64) -> f64 {
    s / allocate::step_std(b.kind, 1.0)
}

fn to_table(
    machine: &str,
    req: Option<Requirement>,
    bounds: &[ErrorBounds],
    r: &Allocation,
) -> String {
    use std::fmt::Write as _;
    let mut out = String::new();
    let req_text = req.map_or("none".to_string(), |q| {
        format!(
            "min ≥ {:.2} %, mean ≥ {:.2} %",
            q.min * 100.0,
            q.mean * 100.0
        )
    });
    let _ = writeln!(
        out,
        "{machine}: precision allocation ({}), requirement {req_text}",
        r.strategy
    );
    let line = |out: &mut String, label: &str, s: &[Summary]| {
        let cells: Vec<String> = s
            .iter()
            .map(|s| format!("{} {:6.2}/{:6.2}", s.target, s.mean * 100.0, s.min * 100.0))
            .collect();
        let _ = writeln!(out, "  {label:<8} {}", cells.join("   "));
    };
    let _ = writeln!(out, "\nmean/min reliability (%):");
    line(&mut out, "initial", &r.initial);
    for s in &r.steps {
        line(&mut out, &format!("round {}", s.round), &s.summaries);
        let _ = writeln!(out, "           tightened: {}", s.tightened.join(", "));
    }
    if r.strategy == reliability::allocate::StrategyName::Optimal {
        line(&mut out, "optimal", &r.summaries);
    }
    let _ = writeln!(
        out,
        "\n  {:<8} {:>13} {:>13} {:>10} {:>10} {:>8}",
        "error", "std0", "std", "tol0", "tol", "std0/std"
    );
    for (b, (_, s)) in bounds.iter().zip(&r.std) {
        if (s - b.std0).abs() <= 1e-15 * b.std0 {
            continue;
        }
        let _ = writeln!(
            out,
            "  {:<8} {:>13.6e} {:>13.6e} {:>10.5} {:>10.5} {:>8.4}",
            b.error,
            b.std0,
            s,
            tolerance_units(b, b.std0),
            tolerance_units(b, *s),
            b.std0 / s
        );
    }
    let _ = writeln!(
        out,
        "  (tol in Table 1's units: std·6 mm, std·6000 angular, std·3000 squareness; unlisted errors unchanged)"
    );
    let _ = writeln!(
        out,
        "\ncost Σ w (std0/std − 1) = {:.6}; requirement {}",
        r.cost,
        if r.met { "met" } else { "NOT met" }
    );
    if let Some(a) = &r.acceptance {
        let _ = writeln!(
            out,
            "whole-machine acceptance: {:.4} % → {:.4} % ± {:.4} % (level {:.4} %, {}; independent re-evaluation{}; {} evaluations)",
            a.initial * 100.0,
            a.probability * 100.0,
            a.std_error * 100.0,
            a.level * 100.0,
            if r.met { "reached" } else { "NOT reached" },
            if a.converged { "" } else { ", NOT CONVERGED" },
            a.evaluations
        );
    }
    if let Some(k) = &r.kkt {
        let _ = writeln!(
            out,
            "KKT ({}): stationarity {:.2e}, complementarity {:.2e}, feasibility {:.2e}, dual feasibility {:.2e} ({} Newton iterations)",
            if k.polished { "active-set Newton" } else { "barrier" },
            k.stationarity,
            k.complementarity,
            k.feasibility,
            k.dual_feasibility,
            k.iterations
        );
        for (n, l) in &k.active {
            let _ = writeln!(out, "  active: {n:<40} multiplier {l:.6}");
        }
    }
    out
}
