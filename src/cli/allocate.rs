//! `chain allocate FILE [--strategy optimal|paper] [--step TOL] [--format table|json]`.
//!
//! Precision allocation (seed 000, Section 3.3, Tables 5-7): the paper's
//! fixed-step tightening of the most sensitive errors, or the least-cost
//! standard deviations that meet the requirement (with a KKT check). An
//! infeasible requirement is an error naming the component, the case and the
//! bounds that bind. See `docs/allocation.md`.

use std::path::PathBuf;

use miette::MietteDiagnostic;
use reliability::allocate::{self, AllocateError, Allocation, ErrorBounds, Optimal, Paper};
use reliability::Summary;
use serde_json::{json, Map, Value};

use super::reliability::{parse_assignment, Loaded, SidedArg};
use super::report::write_stdout;

/// `--strategy`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum StrategyArg {
    /// Least cost `Σ w (σ0/σ − 1)` subject to the requirement (interior point + KKT check).
    Optimal,
    /// The paper's procedure: tighten the errors within 10 % of the largest sensitivity by one step a round.
    Paper,
}

/// `--rank` of the paper's procedure.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum RankArg {
    /// Rank each unmet component's errors separately (Tables 5-7).
    Component,
    /// Rank the summed sensitivities of all unmet components.
    Pooled,
}

/// Output formats of `chain allocate`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum AllocateFormat {
    /// Rounds like Tables 5-7, the final tolerances and the KKT check.
    Table,
    /// The spec's JSON document.
    Json,
}

/// Arguments of `chain allocate`.
#[derive(Debug, clap::Args)]
pub struct AllocateArgs {
    /// Machine file (YAML) with `statistics` and a `reliability` section with a `requirement`.
    pub file: PathBuf,
    /// Allocation strategy.
    #[arg(long, value_enum, default_value = "optimal")]
    pub strategy: StrategyArg,
    /// Step of `--strategy paper` in Table 1's tolerance units (σ decreases by
    /// step/6 mm, step/6000 rad for angular and step/3000 rad for squareness errors).
    #[arg(long, value_name = "TOL", default_value_t = 0.005)]
    pub step: f64,
    /// Sensitivity threshold of `--strategy paper`, as a fraction of the largest.
    #[arg(long, default_value_t = 0.1)]
    pub threshold: f64,
    /// Ranking of `--strategy paper`.
    #[arg(long, value_enum, default_value = "component")]
    pub rank: RankArg,
    /// Output format.
    #[arg(long, value_enum, default_value = "table")]
    pub format: AllocateFormat,
    /// Value of a parameter, `NAME=VALUE` (repeatable; required for symbolic ones).
    #[arg(long = "param", value_name = "NAME=VALUE", value_parser = parse_assignment)]
    pub params: Vec<(String, f64)>,
    /// Override the file's `sided`.
    #[arg(long, value_enum)]
    pub sided: Option<SidedArg>,
    /// Write before/after reliability charts per component and a chart of
    /// the tightening per error (PNG and SVG) into DIR.
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
}

/// Runs `chain allocate`.
pub fn exec(args: AllocateArgs) -> miette::Result<()> {
    let loaded = Loaded::new(&args.file)?;
    let (study, model) = loaded.study(&args.params, &[], args.sided, None)?;
    let values = reliability::machine::parameters(&loaded.machine, &args.params)
        .map_err(|e| loaded.report(e))?;
    let bounds = allocate::bounds(&loaded.machine, &study).map_err(|e| loaded.report(e))?;
    let result = match args.strategy {
        StrategyArg::Optimal => {
            allocate::optimal(&model, &values, &study, &bounds, &Optimal::default())
        }
        StrategyArg::Paper => allocate::paper(
            &model,
            &values,
            &study,
            &bounds,
            &Paper {
                step: args.step,
                threshold: args.threshold,
                pooled: args.rank == RankArg::Pooled,
                ..Paper::default()
            },
        ),
    };
    let result = result.map_err(|e| report(&loaded, e))?;
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
        )
        .map_err(|e| miette::miette!("{e}"))?;
        for f in files {
            eprintln!("wrote {}", f.display());
        }
    }
    let req = study.spec().requirement;
    let text = match args.format {
        AllocateFormat::Json => {
            let doc = to_json(&loaded.machine.name, req, &bounds, &result);
            let mut s = serde_json::to_string_pretty(&doc)
                .map_err(|e| miette::miette!("cannot serialise the result: {e}"))?;
            s.push('\n');
            s
        }
        AllocateFormat::Table => to_table(&loaded.machine.name, req, &bounds, &result),
    };
    write_stdout(&text)?;
    if !result.met {
        return Err(miette::miette!(
            "the requirement is not met after {} rounds",
            result.steps.len()
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

fn report(loaded: &Loaded, err: AllocateError) -> miette::Report {
    match err {
        AllocateError::Reliability(e) => loaded.report(e),
        AllocateError::Infeasible { .. } => miette::Report::new(
            MietteDiagnostic::new(format!("{}: {err}", loaded.machine.name))
                .with_code("chain::allocate::infeasible")
                .with_help(
                    "lower the requirement, or lower (remove) `min_std` of the binding errors",
                ),
        ),
        AllocateError::NoRequirement => miette::Report::new(
            MietteDiagnostic::new(format!("{}: {err}", loaded.machine.name))
                .with_code("chain::allocate::no_requirement")
                .with_help(
                    "add, e.g., `requirement: {min: 0.95, mean: 0.97}` to the reliability section",
                ),
        ),
        other => miette::Report::new(
            MietteDiagnostic::new(format!("{}: {other}", loaded.machine.name))
                .with_code("chain::allocate::error"),
        ),
    }
}

fn summary_json(s: &[Summary]) -> Value {
    Value::Object(
        s.iter()
            .map(|s| {
                (
                    s.target.to_string(),
                    json!({"mean": s.mean, "min": s.min, "max": s.max, "met": s.met}),
                )
            })
            .collect(),
    )
}

fn std_json(s: &[(String, f64)]) -> Value {
    Value::Object(s.iter().map(|(n, v)| (n.clone(), json!(v))).collect())
}

fn to_json(
    machine: &str,
    req: Option<chain_core::model::Requirement>,
    bounds: &[ErrorBounds],
    r: &Allocation,
) -> Value {
    let steps: Vec<Value> = r
        .steps
        .iter()
        .map(|s| {
            json!({"round": s.round, "tightened": s.tightened, "std": std_json(&s.std),
                   "summary": summary_json(&s.summaries)})
        })
        .collect();
    let initial: Vec<(String, f64)> = bounds.iter().map(|b| (b.error.clone(), b.std0)).collect();
    let mut doc = Map::new();
    doc.insert("machine".into(), json!(machine));
    doc.insert("strategy".into(), json!(r.strategy));
    doc.insert(
        "requirement".into(),
        req.map_or(Value::Null, |q| json!({"min": q.min, "mean": q.mean})),
    );
    doc.insert(
        "initial".into(),
        json!({"std": std_json(&initial), "summary": summary_json(&r.initial)}),
    );
    doc.insert("steps".into(), Value::Array(steps));
    doc.insert(
        "final".into(),
        json!({"std": std_json(&r.std), "cost": r.cost, "met": r.met,
               "summary": summary_json(&r.summaries)}),
    );
    if let Some(k) = &r.kkt {
        doc.insert(
            "kkt".into(),
            json!({
                "stationarity": k.stationarity,
                "complementarity": k.complementarity,
                "feasibility": k.feasibility,
                "dual_feasibility": k.dual_feasibility,
                "residual": k.residual(),
                "polished": k.polished,
                "iterations": k.iterations,
                "active": k.active.iter().map(|(n, l)| json!({"constraint": n, "multiplier": l})).collect::<Vec<_>>(),
                "at_bound": k.at_bound.iter().map(|(n, b, z)| json!({"error": n, "bound": b, "multiplier": z})).collect::<Vec<_>>(),
            }),
        );
    }
    Value::Object(doc)
}

/// σ in Table 1's tolerance units (σ·6 mm, σ·6000 or σ·3000 for angles).
fn tolerance_units(b: &ErrorBounds, s: f64) -> f64 {
    s / allocate::step_std(b.kind, 1.0)
}

fn to_table(
    machine: &str,
    req: Option<chain_core::model::Requirement>,
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
    if r.strategy == "optimal" {
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
