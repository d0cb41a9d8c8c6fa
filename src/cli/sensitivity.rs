//! `chain sensitivity FILE [--kind reliability|geometric] [--at x=..,y=..,z=..]
//! [--format table|json]`.
//!
//! `--kind reliability` (the default): the reliability sensitivity of each component to the mean and standard
//! deviation of every error parameter (seed 000, Eq. 32-33) and its FORM
//! importance factor: at one point with `--at`, otherwise the mean over the
//! file's reliability grid (the paper's Figures 6-8). Lists are sorted by
//! `|∂R/∂σ|`, largest first.
//!
//! `--kind geometric`: the geometric error sensitivity coefficients of seed
//! 004 (Eq. 4-6), `S = |∂E_u/∂e_v|` and `C = S·e / Σ S·e` per direction,
//! at `--at` or averaged over the reliability grid (or `--grid`), with
//! `--values` giving the nominal error sizes and `--plot DIR` bar charts like
//! the paper's Figures 3-5 (see `docs/geometric_sensitivity.md`).

#[path = "geometric_plot.rs"]
mod geometric_plot;

use std::path::PathBuf;

use chain_core::geometric::{self, GeometricSensitivity, NominalSizes};
use reliability::{machine, Form, ReliabilityError, SensitivityMethod, TargetSensitivity};
use serde_json::{json, Map, Value};

use super::reliability::{parse_assignment, parse_axis, Loaded, SidedArg};
use super::report::write_stdout;

/// What `chain sensitivity` computes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum SensitivityKind {
    /// Reliability sensitivity to each error's mean and standard deviation.
    #[default]
    Reliability,
    /// Geometric error sensitivity coefficients `S = |∂E/∂e|`, `C = S·e/ΣS·e` (seed 004).
    Geometric,
}

/// Output formats of `chain sensitivity`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum SensitivityFormat {
    /// One ranked table per component.
    Table,
    /// The spec's JSON document.
    Json,
}

/// Arguments of `chain sensitivity`.
#[derive(Debug, clap::Args)]
pub struct SensitivityArgs {
    /// Machine file (YAML) with `statistics` and `reliability` sections.
    pub file: PathBuf,
    /// Evaluate at one point, e.g. `x=0,y=1500,z=600` (every axis variable);
    /// without it, the mean over the reliability grid.
    #[arg(long, value_name = "VAR=VALUE,...", value_parser = parse_point)]
    pub at: Option<AtPoint>,
    /// Output format.
    #[arg(long, value_enum, default_value = "table")]
    pub format: SensitivityFormat,
    /// Value of a parameter, `NAME=VALUE` (repeatable; required for symbolic ones).
    #[arg(long = "param", value_name = "NAME=VALUE", value_parser = parse_assignment)]
    pub params: Vec<(String, f64)>,
    /// Override the file's `sided`.
    #[arg(long, value_enum)]
    pub sided: Option<SidedArg>,
    /// What to compute.
    #[arg(long, value_enum, default_value = "reliability")]
    pub kind: SensitivityKind,
    /// Nominal error sizes for `--kind geometric`: `linear=MM,angular=ANGLE[,squareness=ANGLE]`,
    /// angles in radians or with a `deg` suffix (default `linear=0.001,angular=0.001deg`).
    #[arg(long, value_name = "KIND=VALUE,...", value_parser = parse_values)]
    pub values: Option<NominalSizes>,
    /// Replace the grid values of one axis for the grid mean, `VAR=v1,v2,...` (repeatable).
    #[arg(long = "grid", value_name = "VAR=V1,V2,...", value_parser = parse_axis)]
    pub grid: Vec<(String, Vec<f64>)>,
    /// Write bar charts of the coefficients (PNG and SVG) into DIR (`--kind geometric`).
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
}

/// Parses `--values`.
fn parse_values(s: &str) -> Result<NominalSizes, String> {
    NominalSizes::default().parse(s)
}

/// The coordinates of `--at`, `(variable, value)` in the order given.
#[derive(Debug, Clone, PartialEq)]
pub struct AtPoint(pub Vec<(String, f64)>);

/// Parses `x=0,y=1500,z=600`.
fn parse_point(s: &str) -> Result<AtPoint, String> {
    s.split(',')
        .filter(|p| !p.trim().is_empty())
        .map(parse_assignment)
        .collect::<Result<Vec<_>, _>>()
        .map(AtPoint)
}

/// Runs `chain sensitivity`.
pub fn exec(args: SensitivityArgs) -> miette::Result<()> {
    if args.kind == SensitivityKind::Geometric {
        return exec_geometric(args);
    }
    if args.values.is_some() {
        return Err(miette::miette!(
            help = "add --kind geometric",
            "--values applies only to --kind geometric"
        ));
    }
    if args.plot.is_some() {
        return Err(miette::miette!(
            help = "`chain reliability --plot DIR` draws the reliability sensitivities; or add --kind geometric",
            "--plot applies only to --kind geometric"
        ));
    }
    let loaded = Loaded::new(&args.file)?;
    let (study, model) = loaded.study(&args.params, &args.grid, args.sided, None)?;
    let form = Form::default();
    let (at, result) = match &args.at {
        None => (
            None,
            study
                .sensitivity_mean(&form)
                .map_err(|e| loaded.report(e))?,
        ),
        Some(AtPoint(coords)) => {
            let vars = study.variables();
            let point = resolve_at(coords, &loaded)?;
            let values =
                machine::parameters(&loaded.machine, &args.params).map_err(|e| loaded.report(e))?;
            let r = study
                .sensitivity_point(&model, &values, &point, &form)
                .map_err(|e| loaded.report(e))?;
            // Report the point in the grid's axis order (x, y, z), then any other.
            let mut order: Vec<usize> = super::reliability::axes(&study)
                .iter()
                .map(|(_, i)| *i)
                .collect();
            let rest: Vec<usize> = (0..vars.len()).filter(|i| !order.contains(i)).collect();
            order.extend(rest);
            let at: Vec<(String, f64)> =
                order.iter().map(|&i| (vars[i].clone(), point[i])).collect();
            (Some(at), r)
        }
    };
    let text = match args.format {
        SensitivityFormat::Json => {
            let mut s = serde_json::to_string_pretty(&to_json(
                &loaded.machine.name,
                at.as_deref(),
                &result,
            ))
            .map_err(|e| miette::miette!("cannot serialise the result: {e}"))?;
            s.push('\n');
            s
        }
        SensitivityFormat::Table => to_table(&loaded.machine.name, at.as_deref(), &result),
    };
    write_stdout(&text)
}

fn method_name(m: SensitivityMethod) -> &'static str {
    match m {
        SensitivityMethod::Exact => "exact",
        SensitivityMethod::Form => "form",
    }
}

fn to_json(machine: &str, at: Option<&[(String, f64)]>, result: &[TargetSensitivity]) -> Value {
    let mut components = Map::new();
    let mut methods = Map::new();
    for t in result {
        let list: Vec<Value> = t
            .errors
            .iter()
            .map(|e| {
                let mut o = Map::new();
                o.insert("error".into(), json!(e.error));
                o.insert("dr_dstd".into(), json!(e.dr_dstd));
                o.insert("dr_dmean".into(), json!(e.dr_dmean));
                o.insert("importance".into(), json!(e.importance));
                if at.is_none() {
                    o.insert("mean_abs_dr_dstd".into(), json!(e.mean_abs_dr_dstd));
                    o.insert("mean_abs_dr_dmean".into(), json!(e.mean_abs_dr_dmean));
                }
                Value::Object(o)
            })
            .collect();
        components.insert(t.target.into(), Value::Array(list));
        methods.insert(t.target.into(), json!(method_name(t.method)));
    }
    let at = at.map_or(Value::Null, |a| {
        Value::Object(a.iter().map(|(n, v)| (n.clone(), json!(v))).collect())
    });
    json!({"machine": machine, "at": at, "methods": methods, "components": components})
}

fn to_table(machine: &str, at: Option<&[(String, f64)]>, result: &[TargetSensitivity]) -> String {
    use std::fmt::Write as _;
    let mut out = String::new();
    let where_ = match at {
        Some(a) => format!(
            "at {}",
            a.iter()
                .map(|(n, v)| format!("{n} = {v}"))
                .collect::<Vec<_>>()
                .join(", ")
        ),
        None => "mean over the reliability grid".to_string(),
    };
    let _ = writeln!(
        out,
        "{machine}: reliability sensitivity (Eq. 32-33), {where_}"
    );
    for t in result {
        let _ = writeln!(
            out,
            "\n{} ({}), sorted by |dR/dstd|:",
            t.target,
            method_name(t.method)
        );
        let _ = writeln!(
            out,
            "  {:<8} {:>14} {:>14} {:>11}",
            "error", "dR/dstd", "dR/dmean", "importance"
        );
        for e in &t.errors {
            let _ = writeln!(
                out,
                "  {:<8} {:>14.6e} {:>14.6e} {:>11.6}",
                e.error, e.dr_dstd, e.dr_dmean, e.importance
            );
        }
    }
    out
}

// ---------------------------------------------------------------------------
// `--kind geometric` (seed 004, Eq. 4-6).

/// Where the geometric coefficients were evaluated.
enum Where {
    /// One point, `(variable, value)` in the model's variable order.
    At(Vec<(String, f64)>),
    /// The mean over a grid, `(variable, values)` in the model's variable order.
    Grid(Vec<(String, Vec<f64>)>),
}

fn unknown_variable(loaded: &Loaded, name: &str) -> miette::Report {
    let m = &loaded.machine;
    loaded.report(ReliabilityError::UnknownName {
        kind: "axis variable",
        name: name.to_string(),
        hint: chain_core::diagnostic::closest(name, m.variables.iter().map(|v| v.name.as_str()))
            .map(str::to_string),
    })
}

/// The values of `--at` in the machine's variable order: every axis
/// variable once (a repeated name: the last value), no unknown name.
fn resolve_at(coords: &[(String, f64)], loaded: &Loaded) -> miette::Result<Vec<f64>> {
    let vars: Vec<&str> = loaded
        .machine
        .variables
        .iter()
        .map(|v| v.name.as_str())
        .collect();
    if let Some((name, _)) = coords.iter().find(|(n, _)| !vars.contains(&n.as_str())) {
        return Err(unknown_variable(loaded, name));
    }
    vars.iter()
        .map(|v| {
            coords
                .iter()
                .rev()
                .find(|(n, _)| n == v)
                .map(|(_, x)| *x)
                .ok_or_else(|| {
                    let every: Vec<String> = vars.iter().map(|v| format!("{v}=…")).collect();
                    miette::miette!(
                        help = format!("give every axis variable: --at {}", every.join(",")),
                        "--at has no value for axis variable `{v}`"
                    )
                })
        })
        .collect()
}

fn exec_geometric(args: SensitivityArgs) -> miette::Result<()> {
    let loaded = Loaded::new(&args.file)?;
    let m = &loaded.machine;
    let params = machine::parameters(m, &args.params).map_err(|e| loaded.report(e))?;
    let model = chain_core::compile(m);
    let nominal = args.values.unwrap_or_default();
    let sizes = nominal.of(m);
    let vars: Vec<&str> = m.variables.iter().map(|v| v.name.as_str()).collect();
    let (where_, result) = match &args.at {
        Some(AtPoint(coords)) => {
            if !args.grid.is_empty() {
                return Err(miette::miette!(
                    help =
                        "--at evaluates at one point, --grid sets the grid of the mean; give one",
                    "--grid cannot be combined with --at"
                ));
            }
            let point = resolve_at(coords, &loaded)?;
            let r = geometric::at_point(&model, &point, &params, &sizes);
            let at = vars
                .iter()
                .zip(&point)
                .map(|(n, x)| (n.to_string(), *x))
                .collect();
            (Where::At(at), r)
        }
        None => {
            let mut axes: Vec<(String, Vec<f64>)> = m
                .reliability
                .as_ref()
                .map(|r| {
                    r.grid
                        .iter()
                        .map(|(i, v)| (vars[*i].to_string(), v.clone()))
                        .collect()
                })
                .unwrap_or_default();
            for (name, values) in &args.grid {
                if !vars.contains(&name.as_str()) {
                    return Err(unknown_variable(&loaded, name));
                }
                match axes.iter_mut().find(|(n, _)| n == name) {
                    Some(axis) => axis.1 = values.clone(),
                    None => axes.push((name.clone(), values.clone())),
                }
            }
            let ordered = vars
                .iter()
                .map(|v| {
                    let values = axes.iter().find(|(n, _)| n == v).map(|(_, x)| x.clone());
                    match values {
                        Some(x) if !x.is_empty() => Ok((v.to_string(), x)),
                        _ => Err(miette::miette!(
                            help = format!(
                                "evaluate at one point with --at {}, or give the grid with --grid {v}=V1,V2,...",
                                vars.iter().map(|v| format!("{v}=…")).collect::<Vec<_>>().join(",")
                            ),
                            "{}: no grid values for axis variable `{v}` (key `reliability.grid.{v}`)",
                            loaded.machine.file.as_deref().unwrap_or("machine")
                        )),
                    }
                })
                .collect::<miette::Result<Vec<_>>>()?;
            let values: Vec<Vec<f64>> = ordered.iter().map(|(_, x)| x.clone()).collect();
            let points = geometric::grid_points(&values);
            let r = geometric::mean_over(&model, points, &params, &sizes);
            (Where::Grid(ordered), r)
        }
    };
    if let Some(dir) = &args.plot {
        let files = geometric_plot::write_all(dir, &m.name, &where_text(&where_), &result)?;
        for f in files {
            eprintln!("wrote {}", f.display());
        }
    }
    let text = match args.format {
        SensitivityFormat::Json => {
            let mut s =
                serde_json::to_string_pretty(&geometric_json(&m.name, &where_, &nominal, &result))
                    .map_err(|e| miette::miette!("cannot serialise the result: {e}"))?;
            s.push('\n');
            s
        }
        SensitivityFormat::Table => geometric_table(&m.name, &where_, &nominal, &result),
    };
    write_stdout(&text)
}

fn where_text(w: &Where) -> String {
    match w {
        Where::At(a) => format!(
            "at {}",
            a.iter()
                .map(|(n, v)| format!("{n} = {v}"))
                .collect::<Vec<_>>()
                .join(", ")
        ),
        Where::Grid(g) => format!(
            "mean over {} grid points",
            g.iter().map(|(_, v)| v.len()).product::<usize>()
        ),
    }
}

fn geometric_json(
    machine: &str,
    where_: &Where,
    nominal: &NominalSizes,
    r: &GeometricSensitivity,
) -> Value {
    let mut components = Map::new();
    let mut totals = Map::new();
    for c in &r.components {
        let list: Vec<Value> = c
            .ranked
            .iter()
            .map(|e| {
                let mut o = Map::new();
                o.insert("error".into(), json!(e.error));
                o.insert("s".into(), json!(e.s));
                o.insert("c".into(), json!(e.c));
                o.insert("e".into(), json!(e.e));
                if let Where::Grid(_) = where_ {
                    o.insert("c_min".into(), json!(e.c_min));
                    o.insert("c_max".into(), json!(e.c_max));
                }
                Value::Object(o)
            })
            .collect();
        components.insert(c.component.name().into(), Value::Array(list));
        totals.insert(c.component.name().into(), json!(c.total));
    }
    let (at, grid) = match where_ {
        Where::At(a) => (
            Value::Object(a.iter().map(|(n, v)| (n.clone(), json!(v))).collect()),
            Value::Null,
        ),
        Where::Grid(g) => (
            Value::Null,
            Value::Object(g.iter().map(|(n, v)| (n.clone(), json!(v))).collect()),
        ),
    };
    let mut doc = Map::new();
    doc.insert("machine".into(), json!(machine));
    doc.insert("kind".into(), json!("geometric"));
    doc.insert("at".into(), at);
    if !grid.is_null() {
        doc.insert("grid".into(), grid);
        doc.insert("points".into(), json!(r.points));
    }
    doc.insert("normalisation".into(), json!("c = s*e / sum(s*e)"));
    doc.insert(
        "values".into(),
        json!({"linear": nominal.linear, "angular": nominal.angular, "squareness": nominal.squareness}),
    );
    doc.insert("totals".into(), Value::Object(totals));
    doc.insert("components".into(), Value::Object(components));
    Value::Object(doc)
}

fn geometric_table(
    machine: &str,
    where_: &Where,
    nominal: &NominalSizes,
    r: &GeometricSensitivity,
) -> String {
    use std::fmt::Write as _;
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{machine}: geometric error sensitivity (seed 004 Eq. 5-6), {}",
        where_text(where_)
    );
    let _ = writeln!(
        out,
        "S = |dE/de|, C = S·e / sum(S·e); e = {} (linear), {:.6e} rad = {}° (angular), {:.6e} rad (squareness)",
        nominal.linear,
        nominal.angular,
        round(nominal.angular.to_degrees()),
        nominal.squareness
    );
    let grid = matches!(where_, Where::Grid(_));
    for c in &r.components {
        let shown: Vec<_> = c.ranked.iter().filter(|e| e.s > 0.0).collect();
        if shown.is_empty() {
            let _ = writeln!(
                out,
                "\n{}: no error acts in this direction",
                c.component.name()
            );
            continue;
        }
        let _ = writeln!(
            out,
            "\n{} (sum of S·e = {:.6e}), sorted by C:",
            c.component.name(),
            c.total
        );
        if grid {
            let _ = writeln!(
                out,
                "  {:>4} {:<10} {:>14} {:>9} {:>9} {:>9}",
                "rank", "error", "S (mean)", "C %", "min %", "max %"
            );
        } else {
            let _ = writeln!(
                out,
                "  {:>4} {:<10} {:>14} {:>9}",
                "rank", "error", "S", "C %"
            );
        }
        for (i, e) in shown.iter().enumerate() {
            if grid {
                let _ = writeln!(
                    out,
                    "  {:>4} {:<10} {:>14.6} {:>9.2} {:>9.2} {:>9.2}",
                    i + 1,
                    e.error,
                    e.s,
                    100.0 * e.c,
                    100.0 * e.c_min,
                    100.0 * e.c_max
                );
            } else {
                let _ = writeln!(
                    out,
                    "  {:>4} {:<10} {:>14.6} {:>9.2}",
                    i + 1,
                    e.error,
                    e.s,
                    100.0 * e.c
                );
            }
        }
        let zero = c.ranked.len() - shown.len();
        if zero > 0 {
            let _ = writeln!(out, "  ({zero} errors with S = 0 not listed)");
        }
    }
    out
}

/// Rounds to 10 significant digits (no float noise in printed degrees).
fn round(x: f64) -> f64 {
    format!("{x:.9e}").parse().unwrap_or(x)
}
