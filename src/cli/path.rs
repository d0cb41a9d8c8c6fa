//! `chain path FILE (--axes AXES.csv | --pose POSE.csv [--fix NAME=VALUE]...)
//! [--param NAME=VALUE]... [--method form|is|mc] [--samples N] [--seed S]
//! [--sided upper|two] [--system series|volumetric] [--system-tolerance T]
//! [--format table|json|csv] [--plot DIR]`.
//!
//! The bridge from kinematics to accuracy: at every instant of a path (axis
//! values, or tool poses solved by the inverse kinematics of `chain inverse`) the
//! nominal tool point, the mean and standard deviation of every error
//! component (exact linear propagation of the machine's error statistics
//! through `E = S(q)·e`), those of the volumetric position error `|p|`, and
//! the reliability of every toleranced component of the file's `reliability`
//! section (FORM, importance sampling or Monte Carlo) through
//! [`Study::at_points`]. See `docs/path.md`.

#[path = "path_plot.rs"]
mod path_plot;

use std::path::{Path, PathBuf};

use chain_core::inverse::{Inverse, Status};
use chain_core::model::{Component, Machine, Sided};
use chain_core::ErrorModel;
use reliability::{machine, ErrorMoments, Study, StudyResult, System, VolumetricMoments};
use serde_json::{json, Map, Value};

use super::csv_input::{numeric_rows, open_csv, read_poses};
use super::inverse::solve_rows;
use super::reliability::{
    note_form_limits, parse_assignment, requirement_text, resolve_fixed, run_study, system_of,
    Loaded, MethodArg, SidedArg, SystemArg,
};
use super::report::write_stdout;

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
    /// Value of a parameter, `NAME=VALUE` (repeatable; required for symbolic ones).
    #[arg(long = "param", value_name = "NAME=VALUE", value_parser = parse_assignment)]
    pub params: Vec<(String, f64)>,
    /// Reliability algorithm.
    #[arg(long, value_enum, default_value = "form")]
    pub method: MethodArg,
    /// Samples per instant and target (is: 10000, mc: 100000 by default).
    #[arg(long)]
    pub samples: Option<u64>,
    /// Seed of the random streams.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Override the file's `sided`.
    #[arg(long, value_enum)]
    pub sided: Option<SidedArg>,
    /// Also assess a system limit state.
    #[arg(long, value_enum)]
    pub system: Option<SystemArg>,
    /// Allowable volumetric error for `--system volumetric` (default: the
    /// smallest position tolerance).
    #[arg(long, value_name = "T", requires = "system")]
    pub system_tolerance: Option<f64>,
    /// Output format.
    #[arg(long, value_enum, default_value = "table")]
    pub format: PathFormat,
    /// Write the reliability and the error standard deviations along the
    /// path (PNG and SVG) into DIR.
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
}

/// One instant of the path.
struct Instant {
    /// 1-based data row of the input CSV.
    row: usize,
    /// The `t` column, or the row number.
    t: f64,
    /// `ok` for `--axes`; the inverse-kinematics status for `--pose`.
    status: Status,
    /// The axis values (model order), when the row has them.
    q: Option<Vec<f64>>,
}

/// What was computed at an instant with axis values.
struct Evaluated {
    /// `T_wt(q, 0) · tool_point`.
    nominal: [f64; 3],
    /// Mean and covariance of the six components.
    moments: ErrorMoments,
    /// Mean and standard deviation of `|p|`.
    volumetric: VolumetricMoments,
    /// Reliability per target (study order).
    reliability: Vec<f64>,
    /// Standard error of `p_f` per target (sampling only).
    std_error: Option<Vec<f64>>,
}

/// The whole result.
struct PathResult {
    machine: String,
    frame: &'static str,
    input: &'static str,
    source: String,
    variables: Vec<String>,
    /// `(target name, allowable value)`; the series target has none.
    targets: Vec<(&'static str, Option<f64>)>,
    sided: Sided,
    method: &'static str,
    has_t: bool,
    instants: Vec<(Instant, Option<Evaluated>)>,
    /// The engine's result over the evaluated instants, if any.
    study: Option<StudyResult>,
}

/// The six components and the volumetric error, as reported.
const QUANTITIES: [&str; 7] = ["px", "py", "pz", "ox", "oy", "oz", "volumetric"];

/// Runs `chain path`.
pub fn exec(args: PathArgs) -> miette::Result<()> {
    let loaded = Loaded::new(&args.file)?;
    let m = &loaded.machine;
    let system = system_of(m, args.system, args.system_tolerance).map_err(|e| loaded.report(e))?;
    let mut spec = machine::spec(m, system).map_err(|e| loaded.report(e))?;
    if let Some(s) = args.sided {
        spec.sided = match s {
            SidedArg::Upper => Sided::Upper,
            SidedArg::Two => Sided::Two,
        };
    }
    let inputs = machine::inputs(m).map_err(|e| loaded.report(e))?;
    let params = machine::parameters(m, &args.params).map_err(|e| loaded.report(e))?;
    let fixed = resolve_fixed(m, &args.fix)?;
    let model = chain_core::compile(m);
    let (input, source, has_t, instants) = match (&args.axes, &args.pose) {
        (Some(path), _) => {
            let (has_t, instants) = axes_instants(path, m, &fixed)?;
            ("axes", path, has_t, instants)
        }
        (None, Some(path)) => {
            let (has_t, instants) = pose_instants(path, m, &params, &fixed)?;
            ("pose", path, has_t, instants)
        }
        (None, None) => miette::bail!("give the path with --axes AXES.csv or --pose POSE.csv"),
    };
    let points: Vec<Vec<f64>> = instants.iter().filter_map(|i| i.q.clone()).collect();
    let mut evaluated: Vec<Option<Evaluated>> = Vec::with_capacity(instants.len());
    let mut study_result = None;
    let targets;
    if points.is_empty() {
        // Nothing reachable: the instants are still reported.
        eprintln!("note: no instant of the path has axis values; nothing to evaluate");
        targets = target_list(&spec.tolerances, spec.system);
        evaluated.extend(instants.iter().map(|_| None));
    } else {
        let study = Study::at_points(&model, &params, inputs, spec, points)
            .map_err(|e| loaded.report(e))?;
        let samples = args.method.samples(args.samples);
        let result = run_study(&study, args.method, samples, args.seed, &())
            .map_err(|e| loaded.report(e))?;
        if args.method == MethodArg::Form {
            note_form_limits(&study);
        }
        if !study.inputs().is_affine() {
            eprintln!(
                "note: non-normal inputs: the mean and std of |p| are those of the normal law with the same mean and covariance (the component moments are exact)"
            );
        }
        targets = study
            .targets()
            .iter()
            .map(|t| (t.name(), tolerance_of(&study, t.name())))
            .collect();
        let np = study.points().len();
        let mut k = 0;
        for inst in &instants {
            let Some(q) = &inst.q else {
                evaluated.push(None);
                continue;
            };
            let moments = study.moments(k);
            let reliability = (0..study.targets().len())
                .map(|t| result.cases[t * np + k].reliability)
                .collect();
            let std_error = (0..study.targets().len())
                .map(|t| result.cases[t * np + k].std_error)
                .collect::<Option<Vec<f64>>>();
            evaluated.push(Some(Evaluated {
                // `+ 0.0` turns a negative zero into 0.
                nominal: model.nominal(q, &params).position.map(|x| x + 0.0),
                volumetric: moments.volumetric(),
                moments,
                reliability,
                std_error,
            }));
            k += 1;
        }
        study_result = Some(result);
    }
    let result = PathResult {
        machine: m.name.clone(),
        frame: m.frame.name(),
        input,
        source: if source.as_os_str() == "-" {
            "<stdin>".to_string()
        } else {
            source.display().to_string()
        },
        variables: m.variables.iter().map(|v| v.name.clone()).collect(),
        targets,
        sided: match args.sided {
            Some(SidedArg::Two) => Sided::Two,
            Some(SidedArg::Upper) => Sided::Upper,
            None => m.reliability.as_ref().map_or(Sided::Upper, |r| r.sided),
        },
        method: method_name(args.method),
        has_t,
        instants: instants.into_iter().zip(evaluated).collect(),
        study: study_result,
    };
    if let Some(dir) = &args.plot {
        for f in path_plot::write_all(dir, &result)? {
            eprintln!("wrote {}", f.display());
        }
    }
    let text = match args.format {
        PathFormat::Json => {
            let mut s = serde_json::to_string_pretty(&to_json(&result))
                .map_err(|e| miette::miette!("cannot serialise the result: {e}"))?;
            s.push('\n');
            s
        }
        PathFormat::Csv => to_csv(&result)?,
        PathFormat::Table => to_table(&result),
    };
    write_stdout(&text)
}

fn method_name(m: MethodArg) -> &'static str {
    match m {
        MethodArg::Form => "form",
        MethodArg::Is => "is",
        MethodArg::Mc => "mc",
    }
}

/// The targets a study of these tolerances and system would have (used only
/// when no instant is evaluated).
fn target_list(
    tolerances: &[(Component, f64)],
    system: Option<System>,
) -> Vec<(&'static str, Option<f64>)> {
    let mut out: Vec<_> = tolerances
        .iter()
        .map(|(c, t)| (c.name(), Some(*t)))
        .collect();
    match system {
        Some(System::Series) => out.push(("series", None)),
        Some(System::Volumetric { tolerance }) => out.push(("volumetric", Some(tolerance))),
        None => {}
    }
    out
}

fn tolerance_of(study: &Study, target: &str) -> Option<f64> {
    match target {
        "series" => None,
        "volumetric" => match study.spec().system {
            Some(System::Volumetric { tolerance }) => Some(tolerance),
            _ => None,
        },
        name => study
            .spec()
            .tolerances
            .iter()
            .find(|(c, _)| c.name() == name)
            .map(|(_, t)| *t),
    }
}

// ---------------------------------------------------------------------------
// Input.

/// Whether the first column is the instant `t`: it is named `t`, and the
/// machine has no variable `t` or the header names `t` again later.
fn leading_t(header: &[String], m: &Machine) -> bool {
    header.first().is_some_and(|h| h == "t")
        && (m.variable_index("t").is_none() || header[1..].iter().any(|h| h == "t"))
}

/// The instants of `--axes`: returns whether a `t` column was given.
fn axes_instants(
    path: &Path,
    m: &Machine,
    fixed: &[(usize, f64)],
) -> miette::Result<(bool, Vec<Instant>)> {
    let mut input = open_csv(path)?;
    let name = input.name.clone();
    let has_t = leading_t(&input.header, m);
    let skip = usize::from(has_t);
    // Column of each variable.
    let mut column_of: Vec<Option<usize>> = vec![None; m.variables.len()];
    for (k, h) in input.header.iter().enumerate().skip(skip) {
        let Some(v) = m.variable_index(h) else {
            let hint =
                chain_core::diagnostic::closest(h, m.variables.iter().map(|v| v.name.as_str()))
                    .map(|c| format!(" (did you mean `{c}`?)"))
                    .unwrap_or_default();
            let t_note = if h == "t" {
                "; `t` (the instant) must be the first column"
            } else {
                ""
            };
            miette::bail!(
                "{name}:1: column `{h}` is not an axis variable of machine `{}`{hint}{t_note}; expected `t` (optional, first) and {}",
                m.name,
                variable_list(m)
            );
        };
        if fixed.iter().any(|(i, _)| *i == v) {
            miette::bail!(
                "{name}:1: variable `{h}` has a column and a --fix value; give one of them"
            );
        }
        column_of[v] = Some(k);
    }
    let missing: Vec<&str> = m
        .variables
        .iter()
        .enumerate()
        .filter(|(v, _)| column_of[*v].is_none() && !fixed.iter().any(|(i, _)| i == v))
        .map(|(_, x)| x.name.as_str())
        .collect();
    if !missing.is_empty() {
        miette::bail!(
            "{name}:1: no column for axis variable{} {}; add the column or hold it with --fix NAME=VALUE",
            if missing.len() > 1 { "s" } else { "" },
            missing
                .iter()
                .map(|v| format!("`{v}`"))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    let rows = numeric_rows(&mut input)?;
    let instants = rows
        .into_iter()
        .enumerate()
        .map(|(k, (_, values))| {
            let q = column_of
                .iter()
                .enumerate()
                .map(|(v, c)| match c {
                    Some(c) => values[*c],
                    None => fixed.iter().find(|(i, _)| *i == v).map_or(0.0, |(_, x)| *x),
                })
                .collect();
            Instant {
                row: k + 1,
                t: if has_t { values[0] } else { (k + 1) as f64 },
                status: Status::Ok,
                q: Some(q),
            }
        })
        .collect();
    Ok((has_t, instants))
}

fn variable_list(m: &Machine) -> String {
    m.variables
        .iter()
        .map(|v| format!("`{}`", v.name))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The instants of `--pose`, each solved by the inverse kinematics of
/// `chain inverse` ([`Inverse::for_machine`]: the closed form when the chain
/// allows it, damped Newton otherwise); the first solution, the one nearest
/// the previous row's, is the instant's axis values.
fn pose_instants(
    path: &Path,
    m: &Machine,
    params: &[f64],
    fixed: &[(usize, f64)],
) -> miette::Result<(bool, Vec<Instant>)> {
    let (has_t, rows) = read_poses(path)?;
    let solver = Inverse::for_machine(m, params, fixed)
        .map_err(|e| miette::miette!("machine `{}`: {e}", m.name))?;
    let instants = solve_rows(&solver, &rows, m.variables.len(), fixed)
        .into_iter()
        .zip(&rows)
        .enumerate()
        .map(|(k, (s, row))| Instant {
            row: k + 1,
            t: row.t.unwrap_or((k + 1) as f64),
            status: s.status,
            q: s.solutions.into_iter().next(),
        })
        .collect();
    Ok((has_t, instants))
}

// ---------------------------------------------------------------------------
// Output.

fn status_name(s: Status) -> &'static str {
    match s {
        Status::Ok => "ok",
        Status::Unreachable => "unreachable",
        Status::Singular => "singular",
    }
}

/// The mean and standard deviation of quantity `k` of [`QUANTITIES`].
fn quantity(e: &Evaluated, k: usize) -> (f64, f64) {
    if k < 6 {
        (e.moments.mean[k], e.moments.std(Component::ALL[k]))
    } else {
        (e.volumetric.mean, e.volumetric.std)
    }
}

/// The instant where `value` is largest (first on ties), with that value.
fn arg_max(r: &PathResult, value: impl Fn(&Evaluated) -> f64) -> Option<(&Instant, f64)> {
    r.instants
        .iter()
        .filter_map(|(i, e)| e.as_ref().map(|e| (i, value(e))))
        .fold(None, |best, (i, v)| match best {
            Some((_, b)) if b >= v => best,
            _ => Some((i, v)),
        })
}

/// One target's summary over the evaluated instants: (min, mean, worst instant).
fn target_summary(r: &PathResult, t: usize) -> Option<(f64, f64, &Instant)> {
    let (worst, neg_min) = arg_max(r, |e| -e.reliability[t])?;
    let values: Vec<f64> = r
        .instants
        .iter()
        .filter_map(|(_, e)| e.as_ref().map(|e| e.reliability[t]))
        .collect();
    let mean = values.iter().sum::<f64>() / values.len() as f64;
    Some((-neg_min, mean, worst))
}

fn count(r: &PathResult, status: Status) -> usize {
    r.instants
        .iter()
        .filter(|(i, _)| i.status == status)
        .count()
}

fn at_json(i: &Instant) -> Value {
    json!({"row": i.row, "t": i.t})
}

fn to_json(r: &PathResult) -> Value {
    let instants: Vec<Value> = r
        .instants
        .iter()
        .map(|(i, e)| {
            let mut o = Map::new();
            o.insert("row".into(), json!(i.row));
            o.insert("t".into(), json!(i.t));
            o.insert(
                "axes".into(),
                match &i.q {
                    Some(q) => Value::Object(
                        r.variables
                            .iter()
                            .zip(q)
                            .map(|(v, x)| (v.clone(), json!(x)))
                            .collect(),
                    ),
                    None => Value::Null,
                },
            );
            o.insert("status".into(), json!(status_name(i.status)));
            match e {
                Some(e) => {
                    o.insert("nominal".into(), json!(e.nominal));
                    let moments = |pick: fn((f64, f64)) -> f64| -> Value {
                        Value::Object(
                            QUANTITIES
                                .iter()
                                .enumerate()
                                .map(|(k, q)| (q.to_string(), json!(pick(quantity(e, k)))))
                                .collect(),
                        )
                    };
                    o.insert("mean".into(), moments(|m| m.0));
                    o.insert("std".into(), moments(|m| m.1));
                    let per_target = |values: &[f64]| -> Value {
                        Value::Object(
                            r.targets
                                .iter()
                                .zip(values)
                                .map(|((t, _), v)| (t.to_string(), json!(v)))
                                .collect(),
                        )
                    };
                    o.insert("reliability".into(), per_target(&e.reliability));
                    if let Some(se) = &e.std_error {
                        o.insert("std_error".into(), per_target(se));
                    }
                }
                None => {
                    for key in ["nominal", "mean", "std", "reliability"] {
                        o.insert(key.into(), Value::Null);
                    }
                }
            }
            Value::Object(o)
        })
        .collect();
    let mut reliability = Map::new();
    for (t, (name, _)) in r.targets.iter().enumerate() {
        let v = match target_summary(r, t) {
            Some((min, mean, worst)) => {
                let mut o = Map::new();
                o.insert("min".into(), json!(min));
                o.insert("mean".into(), json!(mean));
                o.insert("worst".into(), at_json(worst));
                if let Some(met) = r
                    .study
                    .as_ref()
                    .and_then(|s| s.summaries.get(t))
                    .and_then(|s| s.met)
                {
                    o.insert("met".into(), json!(met));
                }
                Value::Object(o)
            }
            None => Value::Null,
        };
        reliability.insert(name.to_string(), v);
    }
    let mut error = Map::new();
    for (k, q) in QUANTITIES.iter().enumerate() {
        let mean_key = if k < 6 { "max_abs_mean" } else { "max_mean" };
        let v = match (
            arg_max(r, |e| quantity(e, k).0.abs()),
            arg_max(r, |e| quantity(e, k).1),
        ) {
            (Some((im, vm)), Some((is, vs))) => {
                let mut o = Map::new();
                o.insert(mean_key.into(), json!(vm));
                o.insert(format!("{mean_key}_at"), at_json(im));
                o.insert("max_std".into(), json!(vs));
                o.insert("max_std_at".into(), at_json(is));
                Value::Object(o)
            }
            _ => Value::Null,
        };
        error.insert(q.to_string(), v);
    }
    let mut summary = Map::new();
    summary.insert("instants".into(), json!(r.instants.len()));
    summary.insert(
        "evaluated".into(),
        json!(r.instants.iter().filter(|(_, e)| e.is_some()).count()),
    );
    summary.insert("unreachable".into(), json!(count(r, Status::Unreachable)));
    summary.insert("singular".into(), json!(count(r, Status::Singular)));
    summary.insert("reliability".into(), Value::Object(reliability));
    summary.insert("error".into(), Value::Object(error));
    if let Some(req) = r.study.as_ref().and_then(|s| s.requirement) {
        let met = r
            .study
            .as_ref()
            .is_some_and(|s| s.summaries.iter().all(|x| x.met != Some(false)));
        summary.insert(
            "requirement".into(),
            json!({"min": req.min, "mean": req.mean, "met": met}),
        );
    }
    let tolerances: Map<String, Value> = r
        .targets
        .iter()
        .filter_map(|(t, v)| v.map(|v| (t.to_string(), json!(v))))
        .collect();
    json!({
        "machine": r.machine,
        "method": r.method,
        "input": r.input,
        "frame": r.frame,
        "sided": sided_name(r.sided),
        "tolerances": tolerances,
        "variables": r.variables,
        "instants": instants,
        "summary": summary,
    })
}

fn sided_name(s: Sided) -> &'static str {
    match s {
        Sided::Upper => "upper",
        Sided::Two => "two",
    }
}

fn to_csv(r: &PathResult) -> miette::Result<String> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let sampled = r
        .instants
        .iter()
        .any(|(_, e)| e.as_ref().is_some_and(|e| e.std_error.is_some()));
    let mut header = vec!["row".to_string(), "t".to_string()];
    header.extend(r.variables.iter().cloned());
    header.push("status".into());
    header.extend(["nominal_x", "nominal_y", "nominal_z"].map(String::from));
    header.extend(QUANTITIES.iter().map(|q| format!("mean_{q}")));
    header.extend(QUANTITIES.iter().map(|q| format!("std_{q}")));
    header.extend(r.targets.iter().map(|(t, _)| format!("reliability_{t}")));
    if sampled {
        header.extend(r.targets.iter().map(|(t, _)| format!("std_error_{t}")));
    }
    let err = |e: csv::Error| miette::miette!("cannot write CSV: {e}");
    w.write_record(&header).map_err(err)?;
    for (i, e) in &r.instants {
        let mut row = vec![i.row.to_string(), format!("{:?}", i.t)];
        match &i.q {
            Some(q) => row.extend(q.iter().map(|x| format!("{x:?}"))),
            None => row.extend(r.variables.iter().map(|_| String::new())),
        }
        row.push(status_name(i.status).into());
        let width = 3 + 2 * QUANTITIES.len() + r.targets.len() * (1 + usize::from(sampled));
        match e {
            Some(e) => {
                row.extend(e.nominal.iter().map(|x| format!("{x:?}")));
                row.extend((0..QUANTITIES.len()).map(|k| format!("{:?}", quantity(e, k).0)));
                row.extend((0..QUANTITIES.len()).map(|k| format!("{:?}", quantity(e, k).1)));
                row.extend(e.reliability.iter().map(|x| format!("{x:?}")));
                if sampled {
                    match &e.std_error {
                        Some(se) => row.extend(se.iter().map(|x| format!("{x:?}"))),
                        None => row.extend(r.targets.iter().map(|_| String::new())),
                    }
                }
            }
            None => row.extend((0..width).map(|_| String::new())),
        }
        w.write_record(&row).map_err(err)?;
    }
    let bytes = w
        .into_inner()
        .map_err(|e| miette::miette!("cannot write CSV: {e}"))?;
    String::from_utf8(bytes).map_err(|e| miette::miette!("cannot write CSV: {e}"))
}

/// A compact number for the table: integers as such, others with up to six
/// decimals.
fn num(v: f64) -> String {
    if v == v.trunc() && v.abs() < 1e15 {
        format!("{}", v as i64)
    } else {
        let s = format!("{v:.6}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

/// Four significant digits in scientific notation; zero as `0`.
fn sci(v: f64) -> String {
    if v == 0.0 {
        "0".to_string()
    } else {
        format!("{v:.3e}")
    }
}

fn at_text(i: &Instant, has_t: bool) -> String {
    if has_t {
        format!("row {} (t = {})", i.row, num(i.t))
    } else {
        format!("row {}", i.row)
    }
}

fn to_table(r: &PathResult) -> String {
    use std::fmt::Write as _;
    let mut out = String::new();
    let method = match r.method {
        "form" => "FORM",
        "is" => "importance sampling",
        _ => "Monte Carlo",
    };
    let sided = match r.sided {
        Sided::Upper => "upper",
        Sided::Two => "two-sided",
    };
    let _ = writeln!(
        out,
        "{}: error and reliability along a path ({} instants from {}, {method}, {sided}, frame {})",
        r.machine,
        r.instants.len(),
        r.source,
        r.frame
    );
    let tol: Vec<String> = r
        .targets
        .iter()
        .filter_map(|(t, v)| v.map(|v| format!("{t} {}", num(v))))
        .collect();
    let _ = writeln!(out, "tolerances: {}", tol.join(", "));
    // Which error quantities to show: the toleranced components and |p|.
    let shown: Vec<usize> = QUANTITIES
        .iter()
        .enumerate()
        .filter(|(k, q)| *k == 6 || r.targets.iter().any(|(t, _)| t == *q))
        .map(|(k, _)| k)
        .collect();
    let label = |k: usize| if k == 6 { "|p|" } else { QUANTITIES[k] };
    let _ = writeln!(
        out,
        "\nmean and standard deviation of the error (lengths in the file's unit, angles in rad)"
    );
    let _ = write!(out, "{:>5} {:>10}", "row", if r.has_t { "t" } else { "" });
    for v in &r.variables {
        let _ = write!(out, " {v:>10}");
    }
    let _ = write!(out, "  {:<11}", "status");
    for &k in &shown {
        let _ = write!(out, " {:>11} {:>10}", format!("{} mean", label(k)), "std");
    }
    out.push('\n');
    for (i, e) in &r.instants {
        let t = if r.has_t { num(i.t) } else { String::new() };
        let _ = write!(out, "{:>5} {t:>10}", i.row);
        match &i.q {
            Some(q) => q.iter().for_each(|x| {
                let _ = write!(out, " {:>10}", num(*x));
            }),
            None => r.variables.iter().for_each(|_| {
                let _ = write!(out, " {:>10}", "-");
            }),
        }
        let _ = write!(out, "  {:<11}", status_name(i.status));
        if let Some(e) = e {
            for &k in &shown {
                let (m, s) = quantity(e, k);
                let _ = write!(out, " {:>11} {:>10}", sci(m), sci(s));
            }
        }
        out.push('\n');
    }
    let _ = writeln!(out, "\nreliability (%)");
    let _ = write!(out, "{:>5} {:>10}", "row", if r.has_t { "t" } else { "" });
    for (t, _) in &r.targets {
        let _ = write!(out, " {t:>10}");
    }
    out.push('\n');
    for (i, e) in &r.instants {
        let t = if r.has_t { num(i.t) } else { String::new() };
        let _ = write!(out, "{:>5} {t:>10}", i.row);
        match e {
            Some(e) => e.reliability.iter().for_each(|v| {
                let _ = write!(out, " {:>10.3}", 100.0 * v);
            }),
            None => {
                let _ = write!(out, " {}", status_name(i.status));
            }
        }
        out.push('\n');
    }
    let evaluated = r.instants.iter().filter(|(_, e)| e.is_some()).count();
    let _ = writeln!(
        out,
        "\nsummary over {} instants ({evaluated} evaluated, {} unreachable, {} singular)",
        r.instants.len(),
        count(r, Status::Unreachable),
        count(r, Status::Singular)
    );
    for (t, (name, _)) in r.targets.iter().enumerate() {
        if let Some((min, mean, worst)) = target_summary(r, t) {
            let _ = write!(
                out,
                "  {name:<10} reliability min {:.3} % at {}, mean {:.3} %",
                100.0 * min,
                at_text(worst, r.has_t),
                100.0 * mean
            );
            let summary = r.study.as_ref().and_then(|s| s.summaries.get(t));
            if let (Some(req), Some(met)) = (
                r.study.as_ref().and_then(|s| s.requirement),
                summary.and_then(|s| s.met),
            ) {
                out.push_str(&requirement_text(&req, met));
            }
            out.push('\n');
        }
    }
    for &k in &shown {
        if let (Some((im, vm)), Some((is, vs))) = (
            arg_max(r, |e| quantity(e, k).0.abs()),
            arg_max(r, |e| quantity(e, k).1),
        ) {
            let what = if k == 6 { "max mean" } else { "max |mean|" };
            let _ = writeln!(
                out,
                "  {:<10} {what} {} at {}, max std {} at {}",
                label(k),
                sci(vm),
                at_text(im, r.has_t),
                sci(vs),
                at_text(is, r.has_t)
            );
        }
    }
    if let Some(se) = r
        .instants
        .iter()
        .filter_map(|(_, e)| e.as_ref().and_then(|e| e.std_error.as_ref()))
        .flatten()
        .copied()
        .reduce(f64::max)
    {
        let _ = writeln!(out, "  sampling: largest standard error of p_f {se:.2e}");
    }
    out
}
