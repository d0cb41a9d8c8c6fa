//! `chain sensitivity FILE [--at x=..,y=..,z=..] [--format table|json]`.
//!
//! The reliability sensitivity of each component to the mean and standard
//! deviation of every error parameter (seed 000, Eq. 32-33) and its FORM
//! importance factor: at one point with `--at`, otherwise the mean over the
//! file's reliability grid (the paper's Figures 6-8). Lists are sorted by
//! `|∂R/∂σ|`, largest first.

use std::path::PathBuf;

use reliability::{machine, Form, ReliabilityError, SensitivityMethod, TargetSensitivity};
use serde_json::{json, Map, Value};

use super::reliability::{parse_assignment, write_stdout, Loaded, SidedArg};

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
    let loaded = Loaded::new(&args.file)?;
    let (study, model) = loaded.study(&args.params, &[], args.sided, None)?;
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
            for (name, _) in coords {
                if !vars.iter().any(|v| v == name) {
                    return Err(loaded.report(ReliabilityError::UnknownName {
                        kind: "axis variable",
                        name: name.clone(),
                        hint: chain_core::diagnostic::closest(
                            name,
                            vars.iter().map(String::as_str),
                        )
                        .map(str::to_string),
                    }));
                }
            }
            let point = vars
                .iter()
                .map(|v| {
                    coords
                        .iter()
                        .rev()
                        .find(|(n, _)| n == v)
                        .map(|(_, x)| *x)
                        .ok_or_else(|| {
                            miette::miette!(
                                help = format!(
                                    "give every axis variable: --at {}",
                                    vars.iter()
                                        .map(|v| format!("{v}=…"))
                                        .collect::<Vec<_>>()
                                        .join(",")
                                ),
                                "--at has no value for axis variable `{v}`"
                            )
                        })
                })
                .collect::<miette::Result<Vec<f64>>>()?;
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
