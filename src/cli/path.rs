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
use chain_core::model::{Machine, Sided};
use reliability::document::RequirementDocument;
use reliability::{
    machine, Calls, Extreme, FormCase, InstantResult, Method, PathInstant, PathResult, PathStudy,
    Quantity, Target,
};
use serde::Serialize;

use super::args::{parse_assignment, system_of, MethodArg};
use super::args::{AlgorithmArgs, ModelArgs, SystemArgs};
use super::csv_input::{numeric_rows, open_csv, read_poses, variable_list};
use super::loaded::{resolve_fixed, Loaded};
use super::report::{self, Csv, Report};
use super::study_text::{
    calls_text, note_form_limits, requirement_text, sided_title, warn_unconverged, Pairs,
};
use chain::ops::inverse::solve_rows;

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
    let loaded = Loaded::new(&args.file)?;
    let m = &loaded.machine;
    let system =
        system_of(m, args.system.system, args.system.tolerance).map_err(|e| loaded.report(e))?;
    let mut spec = machine::spec(m, system).map_err(|e| loaded.report(e))?;
    if let Some(s) = args.model.sided {
        spec.sided = s.into();
    }
    let inputs = machine::inputs(m).map_err(|e| loaded.report(e))?;
    let params = machine::parameters(m, &args.model.param.params).map_err(|e| loaded.report(e))?;
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
    let path =
        PathStudy::new(&model, &params, inputs, spec, instants).map_err(|e| loaded.report(e))?;
    match path.study() {
        None => eprintln!("note: no instant of the path has axis values; nothing to evaluate"),
        Some(study) => {
            if args.algorithm.method == MethodArg::Form {
                note_form_limits(study);
            }
            if !study.inputs().is_affine() {
                eprintln!(
                    "note: non-normal inputs: the mean and std of |p| are those of the normal law with the same mean and covariance (the component moments are exact)"
                );
            }
        }
    }
    args.algorithm.check()?;
    let result = path
        .run(&args.algorithm.algorithm(), &())
        .map_err(|e| loaded.report(e))?;
    if let (Some(study), Some(r)) = (path.study(), &result.study) {
        warn_unconverged(r, study.variables());
    }
    let doc = PathDoc {
        machine: m.name.clone(),
        frame: m.frame.name(),
        input,
        source: if source.as_os_str() == "-" {
            "<stdin>".to_string()
        } else {
            source.display().to_string()
        },
        variables: m.variables.iter().map(|v| v.name.clone()).collect(),
        has_t,
        result,
    };
    if let Some(dir) = &args.plot {
        for f in path_plot::write_all(dir, &doc)? {
            eprintln!("wrote {}", f.display());
        }
    }
    report::emit(&doc, args.format.into())
}

report::formats!(PathFormat: Table, Json, Csv);

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
) -> miette::Result<(bool, Vec<PathInstant>)> {
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
            PathInstant {
                row: k + 1,
                t: if has_t { values[0] } else { (k + 1) as f64 },
                status: Status::Ok,
                axes: Some(q),
            }
        })
        .collect();
    Ok((has_t, instants))
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
) -> miette::Result<(bool, Vec<PathInstant>)> {
    let (has_t, rows) = read_poses(path)?;
    let solver =
        Inverse::for_machine(m, params, fixed).map_err(|error| super::inverse::OnMachine {
            machine: m.name.clone(),
            error,
        })?;
    let instants = solve_rows(&solver, &rows, m.variables.len(), fixed)
        .into_iter()
        .zip(&rows)
        .enumerate()
        .map(|(k, (s, row))| PathInstant {
            row: k + 1,
            t: row.t.unwrap_or((k + 1) as f64),
            status: s.status,
            axes: s.solutions.into_iter().next(),
        })
        .collect();
    Ok((has_t, instants))
}

// ---------------------------------------------------------------------------
// Output.

/// The report of `chain path`: the library's [`PathResult`] with what the
/// command knows of its input (the JSON document of `docs/path.md`).
pub(crate) struct PathDoc {
    pub(crate) machine: String,
    frame: &'static str,
    input: &'static str,
    source: String,
    variables: Vec<String>,
    pub(crate) has_t: bool,
    pub(crate) result: PathResult,
}

/// `{"row": …, "t": …}`: where an extreme occurs.
#[derive(Serialize)]
struct AtDoc {
    row: usize,
    t: f64,
}

impl PathDoc {
    fn at(&self, e: &Extreme) -> AtDoc {
        let i = &self.result.records[e.record].instant;
        AtDoc { row: i.row, t: i.t }
    }

    fn targets(&self) -> impl Iterator<Item = Target> + '_ {
        self.result.targets.iter().map(|t| t.target)
    }

    fn per_target<V: Serialize>(&self, values: impl Iterator<Item = V>) -> Pairs<Target, V> {
        Pairs(self.targets().zip(values).collect())
    }
}

/// The JSON document.
#[derive(Serialize)]
struct PathJson<'a> {
    machine: &'a str,
    method: Method,
    input: &'a str,
    frame: &'a str,
    sided: Sided,
    tolerances: Pairs<Target, f64>,
    variables: &'a [String],
    instants: Vec<InstantDoc<'a>>,
    summary: SummaryDoc,
}

/// One instant of [`PathJson`]; the results are `null` for an instant
/// without axis values.
#[derive(Serialize)]
struct InstantDoc<'a> {
    row: usize,
    t: f64,
    axes: Option<Pairs<&'a str, f64>>,
    status: Status,
    nominal: Option<[f64; 3]>,
    mean: Option<Pairs<Quantity, f64>>,
    std: Option<Pairs<Quantity, f64>>,
    reliability: Option<Pairs<Target, f64>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    std_error: Option<Pairs<Target, f64>>,
    /// How each target's case was computed (FORM's termination, calls).
    #[serde(skip_serializing_if = "Option::is_none")]
    cases: Option<Pairs<Target, CaseInfo>>,
}

/// FORM's account and the calls of one case.
#[derive(Serialize)]
struct CaseInfo {
    #[serde(flatten)]
    form: Option<FormCase>,
    calls: Calls,
}

#[derive(Serialize)]
struct SummaryDoc {
    instants: usize,
    evaluated: usize,
    unreachable: usize,
    singular: usize,
    reliability: Pairs<Target, Option<TargetDoc>>,
    error: Pairs<Quantity, Option<ErrorDoc>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    requirement: Option<RequirementDocument>,
    /// How many cases FORM solved and how (FORM and the importance sampling).
    #[serde(skip_serializing_if = "Option::is_none")]
    form: Option<FormSummaryDoc>,
    /// Limit-state calls over every case.
    calls: Calls,
}

#[derive(Serialize)]
struct TargetDoc {
    min: f64,
    mean: f64,
    worst: AtDoc,
    #[serde(skip_serializing_if = "Option::is_none")]
    met: Option<bool>,
}

/// The extremes of one quantity; a component's mean key is `max_abs_mean`,
/// that of `|p|` is `max_mean`.
struct ErrorDoc {
    volumetric: bool,
    mean: f64,
    mean_at: AtDoc,
    std: f64,
    std_at: AtDoc,
}

impl Serialize for ErrorDoc {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let key = if self.volumetric {
            "max_mean"
        } else {
            "max_abs_mean"
        };
        let mut map = serializer.serialize_map(Some(4))?;
        map.serialize_entry(key, &self.mean)?;
        map.serialize_entry(&format!("{key}_at"), &self.mean_at)?;
        map.serialize_entry("max_std", &self.std)?;
        map.serialize_entry("max_std_at", &self.std_at)?;
        map.end()
    }
}

#[derive(Serialize)]
struct FormSummaryDoc {
    cases: usize,
    converged: usize,
    terminations: Pairs<Termination, usize>,
}

use reliability::Termination;

impl Serialize for PathDoc {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        self.json().serialize(serializer)
    }
}

impl PathDoc {
    fn json(&self) -> PathJson<'_> {
        let r = &self.result;
        let instants = r
            .records
            .iter()
            .map(|rec| {
                let i = &rec.instant;
                let e = rec.result.as_ref();
                let moments = |pick: fn(&InstantResult, Quantity) -> f64| {
                    e.map(|e| Pairs(Quantity::ALL.iter().map(|&q| (q, pick(e, q))).collect()))
                };
                InstantDoc {
                    row: i.row,
                    t: i.t,
                    axes: i.axes.as_ref().map(|q| {
                        Pairs(
                            self.variables
                                .iter()
                                .map(String::as_str)
                                .zip(q.iter().copied())
                                .collect(),
                        )
                    }),
                    status: i.status,
                    nominal: e.map(|e| e.nominal),
                    mean: moments(InstantResult::mean),
                    std: moments(InstantResult::std),
                    reliability: e.map(|e| self.per_target(e.cases.iter().map(|c| c.reliability))),
                    std_error: e.and_then(|e| {
                        let se: Option<Vec<f64>> = e.cases.iter().map(|c| c.std_error).collect();
                        se.map(|se| self.per_target(se.into_iter()))
                    }),
                    cases: e.map(|e| {
                        self.per_target(e.cases.iter().map(|c| CaseInfo {
                            form: c.form,
                            calls: c.calls,
                        }))
                    }),
                }
            })
            .collect();
        let reliability = self.per_target((0..r.targets.len()).map(|t| {
            r.summary(t).map(|s| TargetDoc {
                min: s.min.value,
                mean: s.mean,
                worst: self.at(&s.min),
                met: s.met,
            })
        }));
        let error = Pairs(
            Quantity::ALL
                .iter()
                .map(|&q| {
                    let doc = match (r.max_mean(q), r.max_std(q)) {
                        (Some(m), Some(s)) => Some(ErrorDoc {
                            volumetric: q == Quantity::Volumetric,
                            mean: m.value,
                            mean_at: self.at(&m),
                            std: s.value,
                            std_at: self.at(&s),
                        }),
                        _ => None,
                    };
                    (q, doc)
                })
                .collect(),
        );
        let forms: Vec<&FormCase> = r.cases().filter_map(|c| c.form.as_ref()).collect();
        let form = (!forms.is_empty()).then(|| FormSummaryDoc {
            cases: forms.len(),
            converged: forms.iter().filter(|f| f.converged).count(),
            terminations: Pairs(
                Termination::ALL
                    .iter()
                    .map(|&t| (t, forms.iter().filter(|f| f.termination == t).count()))
                    .filter(|(_, n)| *n > 0)
                    .collect(),
            ),
        });
        let calls = r.cases().fold(Calls::default(), |a, c| Calls {
            values: a.values + c.calls.values,
            gradients: a.gradients + c.calls.gradients,
        });
        let summary = SummaryDoc {
            instants: r.records.len(),
            evaluated: r.evaluated(),
            unreachable: r.count(Status::Unreachable),
            singular: r.count(Status::Singular),
            reliability,
            error,
            requirement: r.study.as_ref().and_then(RequirementDocument::of),
            form,
            calls,
        };
        PathJson {
            machine: &self.machine,
            method: r.method,
            input: self.input,
            frame: self.frame,
            sided: r.sided,
            tolerances: Pairs(
                r.targets
                    .iter()
                    .filter_map(|t| t.tolerance.map(|v| (t.target, v)))
                    .collect(),
            ),
            variables: &self.variables,
            instants,
            summary,
        }
    }
}

impl Report for PathDoc {
    fn table(&self) -> String {
        to_table(self)
    }

    fn csv(&self) -> Option<Csv> {
        let r = &self.result;
        let sampled = r.cases().any(|c| c.std_error.is_some());
        let names: Vec<&str> = r.targets.iter().map(|t| t.target.name()).collect();
        let mut header = vec!["row".to_string(), "t".to_string()];
        header.extend(self.variables.iter().cloned());
        header.push("status".into());
        header.extend(["nominal_x", "nominal_y", "nominal_z"].map(String::from));
        header.extend(Quantity::ALL.iter().map(|q| format!("mean_{q}")));
        header.extend(Quantity::ALL.iter().map(|q| format!("std_{q}")));
        header.extend(names.iter().map(|t| format!("reliability_{t}")));
        if sampled {
            header.extend(names.iter().map(|t| format!("std_error_{t}")));
        }
        for key in [
            "termination",
            "converged",
            "iterations",
            "value_calls",
            "gradient_calls",
        ] {
            header.extend(names.iter().map(|t| format!("{key}_{t}")));
        }
        let width = header.len();
        let mut csv = Csv::new(header);
        for rec in &r.records {
            let i = &rec.instant;
            let mut row = vec![i.row.to_string(), format!("{:?}", i.t)];
            match &i.axes {
                Some(q) => row.extend(q.iter().map(|x| format!("{x:?}"))),
                None => row.extend(self.variables.iter().map(|_| String::new())),
            }
            row.push(i.status.name().into());
            if let Some(e) = &rec.result {
                row.extend(e.nominal.iter().map(|x| format!("{x:?}")));
                row.extend(Quantity::ALL.iter().map(|&q| format!("{:?}", e.mean(q))));
                row.extend(Quantity::ALL.iter().map(|&q| format!("{:?}", e.std(q))));
                row.extend(e.cases.iter().map(|c| format!("{:?}", c.reliability)));
                if sampled {
                    match e
                        .cases
                        .iter()
                        .map(|c| c.std_error)
                        .collect::<Option<Vec<_>>>()
                    {
                        Some(se) => row.extend(se.iter().map(|x| format!("{x:?}"))),
                        None => row.extend(names.iter().map(|_| String::new())),
                    }
                }
                let form = |f: fn(&FormCase) -> String| {
                    e.cases
                        .iter()
                        .map(move |c| c.form.as_ref().map(f).unwrap_or_default())
                };
                row.extend(form(|f| f.termination.to_string()));
                row.extend(form(|f| f.converged.to_string()));
                row.extend(form(|f| f.iterations.to_string()));
                row.extend(e.cases.iter().map(|c| c.calls.values.to_string()));
                row.extend(e.cases.iter().map(|c| c.calls.gradients.to_string()));
            }
            row.resize(width, String::new());
            csv.row(row);
        }
        Some(csv)
    }
}

/// A compact number for the table: integers as such, others with up to six
/// decimals.
fn num(v: f64) -> String {
    match report::whole(v) {
        Some(i) => i.to_string(),
        None => {
            let s = format!("{v:.6}");
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        }
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

fn at_text(i: &PathInstant, has_t: bool) -> String {
    if has_t {
        format!("row {} (t = {})", i.row, num(i.t))
    } else {
        format!("row {}", i.row)
    }
}

/// `|p|` for the volumetric quantity, the component's name otherwise.
pub(crate) fn label(q: Quantity) -> &'static str {
    match q {
        Quantity::Volumetric => "|p|",
        Quantity::Component(c) => c.name(),
    }
}

fn to_table(doc: &PathDoc) -> String {
    use std::fmt::Write as _;
    let r = &doc.result;
    let mut out = String::new();
    let sided = sided_title(r.sided);
    let _ = writeln!(
        out,
        "{}: error and reliability along a path ({} instants from {}, {}, {sided}, frame {})",
        doc.machine,
        r.records.len(),
        doc.source,
        r.method.title(),
        doc.frame
    );
    let tol: Vec<String> = r
        .targets
        .iter()
        .filter_map(|t| t.tolerance.map(|v| format!("{} {}", t.target, num(v))))
        .collect();
    let _ = writeln!(out, "tolerances: {}", tol.join(", "));
    // Which error quantities to show: the toleranced components and |p|.
    let shown: Vec<Quantity> = Quantity::ALL
        .iter()
        .copied()
        .filter(|q| *q == Quantity::Volumetric || doc.targets().any(|t| t.name() == q.name()))
        .collect();
    let _ = writeln!(
        out,
        "\nmean and standard deviation of the error (lengths in the file's unit, angles in rad)"
    );
    let _ = write!(out, "{:>5} {:>10}", "row", if doc.has_t { "t" } else { "" });
    for v in &doc.variables {
        let _ = write!(out, " {v:>10}");
    }
    let _ = write!(out, "  {:<11}", "status");
    for &q in &shown {
        let _ = write!(out, " {:>11} {:>10}", format!("{} mean", label(q)), "std");
    }
    out.push('\n');
    for rec in &r.records {
        let i = &rec.instant;
        let t = if doc.has_t { num(i.t) } else { String::new() };
        let _ = write!(out, "{:>5} {t:>10}", i.row);
        match &i.axes {
            Some(q) => q.iter().for_each(|x| {
                let _ = write!(out, " {:>10}", num(*x));
            }),
            None => doc.variables.iter().for_each(|_| {
                let _ = write!(out, " {:>10}", "-");
            }),
        }
        let _ = write!(out, "  {:<11}", i.status.name());
        if let Some(e) = &rec.result {
            for &q in &shown {
                let _ = write!(out, " {:>11} {:>10}", sci(e.mean(q)), sci(e.std(q)));
            }
        }
        out.push('\n');
    }
    let _ = writeln!(out, "\nreliability (%)");
    let _ = write!(out, "{:>5} {:>10}", "row", if doc.has_t { "t" } else { "" });
    for t in doc.targets() {
        let _ = write!(out, " {:>10}", t.name());
    }
    out.push('\n');
    let mut bad = Vec::new();
    for rec in &r.records {
        let i = &rec.instant;
        let t = if doc.has_t { num(i.t) } else { String::new() };
        let _ = write!(out, "{:>5} {t:>10}", i.row);
        match &rec.result {
            Some(e) => e.cases.iter().for_each(|c| {
                let _ = write!(out, " {:>10.3}", 100.0 * c.reliability);
                if !c.converged() {
                    bad.push(format!("{} at {}", c.target, at_text(i, doc.has_t)));
                }
            }),
            None => {
                let _ = write!(out, " {}", i.status.name());
            }
        }
        out.push('\n');
    }
    if !bad.is_empty() {
        let _ = writeln!(
            out,
            "* FORM stopped at the iteration limit (the value shown is the last iterate's, not a converged reliability): {}",
            bad.join(", ")
        );
    }
    let _ = writeln!(
        out,
        "\nsummary over {} instants ({} evaluated, {} unreachable, {} singular)",
        r.records.len(),
        r.evaluated(),
        r.count(Status::Unreachable),
        r.count(Status::Singular)
    );
    for (t, target) in doc.targets().enumerate() {
        if let Some(s) = r.summary(t) {
            let worst = &r.records[s.min.record].instant;
            let _ = write!(
                out,
                "  {:<10} reliability min {:.3} % at {}, mean {:.3} %",
                target.name(),
                100.0 * s.min.value,
                at_text(worst, doc.has_t),
                100.0 * s.mean
            );
            if let (Some(req), Some(met)) = (r.requirement(), s.met) {
                out.push_str(&requirement_text(&req, met));
            }
            out.push('\n');
        }
    }
    for &q in &shown {
        if let (Some(m), Some(s)) = (r.max_mean(q), r.max_std(q)) {
            let what = if q == Quantity::Volumetric {
                "max mean"
            } else {
                "max |mean|"
            };
            let _ = writeln!(
                out,
                "  {:<10} {what} {} at {}, max std {} at {}",
                label(q),
                sci(m.value),
                at_text(&r.records[m.record].instant, doc.has_t),
                sci(s.value),
                at_text(&r.records[s.record].instant, doc.has_t)
            );
        }
    }
    if let Some(se) = r.cases().filter_map(|c| c.std_error).reduce(f64::max) {
        let _ = writeln!(out, "  sampling: largest standard error of p_f {se:.2e}");
    }
    if r.evaluated() > 0 {
        let _ = writeln!(out, "  {}", calls_text(r.cases(), r.method));
    }
    out
}
