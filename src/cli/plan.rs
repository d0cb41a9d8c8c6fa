//! `chain plan FILE --candidates C.csv --count K [--kind point|direction]
//! [--param NAME=VALUE]... [--format table|json]`.
//!
//! Where to measure (measured-machines spec, section 5): `K` of the candidate
//! poses maximising `det(AᵀA)` on the identifiable subspace, through
//! [`chain_core::plan::plan`], against `K` candidates taken evenly. The
//! candidate CSV has the measurement CSV's columns (section 4) without the
//! measured values: the axis variables, optionally parameters per row, and
//! for direction measurements `ux, uy, uz`. See `docs/plan.md`.

use std::path::{Path, PathBuf};

use chain_core::plan::{self, Candidate, Design, Kind, Plan, PlanError};
use chain_core::ErrorModel;
use miette::MietteDiagnostic;
use serde::Serialize;

use super::args::ParamArgs;
use super::csv_input::{numeric_rows, open_csv};
use super::reliability::Loaded;
use super::report::{self, Report};

/// Output formats of `chain plan`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum PlanFormat {
    /// The chosen candidates and the std per parameter, optimal against even.
    Table,
    /// The whole plan as JSON.
    Json,
}

report::formats!(PlanFormat: Table, Json);

/// What each candidate measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum KindArg {
    /// The tool-point deviation `px, py, pz` (three rows per candidate).
    Point,
    /// The deviation along the candidate's `ux, uy, uz` (one row).
    Direction,
}

/// Arguments of `chain plan`.
#[derive(Debug, clap::Args)]
pub struct PlanArgs {
    /// Machine file (YAML).
    pub file: PathBuf,
    /// Candidate poses (CSV): a column per axis variable (rotary in
    /// radians), optional columns of parameters given per row, and
    /// `ux,uy,uz` for direction measurements; `-` reads stdin.
    #[arg(long, value_name = "C.csv")]
    pub candidates: PathBuf,
    /// How many candidates to choose.
    #[arg(long, value_name = "K")]
    pub count: usize,
    /// What each candidate measures (default: `direction` when the file has
    /// `ux,uy,uz`, else `point`).
    #[arg(long, value_enum)]
    pub kind: Option<KindArg>,
    #[command(flatten)]
    pub param: ParamArgs,
    /// Output format.
    #[arg(long, value_enum, default_value = "table")]
    pub format: PlanFormat,
}

/// The measured-value columns of a measurement CSV, which a candidate file
/// does not have.
const MEASURED: [&str; 5] = ["dpx", "dpy", "dpz", "d", "std"];
/// The direction columns.
const DIRECTION: [&str; 3] = ["ux", "uy", "uz"];

/// Runs `chain plan`.
pub fn exec(args: PlanArgs) -> miette::Result<()> {
    let loaded = Loaded::new(&args.file)?;
    let m = &loaded.machine;
    let model = chain_core::compile(m);
    let (rows, kind) = read_candidates(&args.candidates, m, &model, &args)?;
    let name = display(&args.candidates);
    let design = Design::new(&model, &rows, kind).map_err(|e| plan_error(e, &name))?;
    let result = plan::plan(&design, args.count).map_err(|e| plan_error(e, &name))?;
    let doc = PlanDoc {
        machine: m.name.clone(),
        candidates_file: name,
        variables: model.variables().iter().map(|v| v.to_string()).collect(),
        poses: rows.iter().map(|c| c.q.clone()).collect(),
        plan: result,
    };
    report::emit(&doc, args.format.into())
}

fn display(path: &Path) -> String {
    if path.as_os_str() == "-" {
        "<stdin>".into()
    } else {
        path.display().to_string()
    }
}

/// A library error with the file it is about and a help line.
fn plan_error(e: PlanError, file: &str) -> miette::Report {
    let (code, help) = match &e {
        PlanError::Count { .. } | PlanError::TooFew { .. } => (
            "chain::plan::count",
            "pass --count with a number of candidates that can inform every identifiable direction",
        ),
        PlanError::Uninformative => (
            "chain::plan::uninformative",
            "the machine's errors do not act on what the candidates measure",
        ),
        PlanError::Singular { .. } => (
            "chain::plan::singular",
            "choose more candidates (--count) or add candidates that vary every axis",
        ),
        _ => ("chain::plan::candidates", ""),
    };
    let mut d = MietteDiagnostic::new(format!("{file}: {e}")).with_code(code);
    if !help.is_empty() {
        d = d.with_help(help);
    }
    miette::Report::new(d)
}

/// Reads the candidate CSV: every row's pose, parameters and direction, in
/// the model's orders.
fn read_candidates(
    path: &Path,
    m: &chain_core::Machine,
    model: &chain_core::CompiledModel,
    args: &PlanArgs,
) -> miette::Result<(Vec<Candidate>, Kind)> {
    let mut input = open_csv(path)?;
    let name = input.name.clone();
    let vars = model.variables();
    let pars = model.parameters();
    let mut var_col: Vec<Option<usize>> = vec![None; vars.len()];
    let mut par_col: Vec<Option<usize>> = vec![None; pars.len()];
    let mut dir_col: [Option<usize>; 3] = [None; 3];
    for (k, h) in input.header.iter().enumerate() {
        if let Some(v) = vars.iter().position(|v| v == h) {
            var_col[v] = Some(k);
        } else if let Some(p) = pars.iter().position(|p| p == h) {
            par_col[p] = Some(k);
        } else if let Some(d) = DIRECTION.iter().position(|d| d == h) {
            dir_col[d] = Some(k);
        } else if MEASURED.contains(&h.as_str()) {
            miette::bail!(
                "{name}:1: column `{h}` is a measured value; a candidate file gives only where to measure (the axis variables, parameters per row, and `ux,uy,uz` for direction measurements)"
            );
        } else {
            let known = vars
                .iter()
                .chain(pars.iter())
                .copied()
                .chain(DIRECTION.iter().copied());
            let hint = chain_core::diagnostic::closest(h, known)
                .map(|c| format!(" (did you mean `{c}`?)"))
                .unwrap_or_default();
            miette::bail!(
                "{name}:1: column `{h}` is neither an axis variable, a parameter of machine `{}` nor a direction column{hint}; expected {}{}, and `ux,uy,uz` for direction measurements",
                m.name,
                list(vars),
                if pars.is_empty() {
                    String::new()
                } else {
                    format!(", optionally parameters {}", list(pars))
                }
            );
        }
    }
    let missing: Vec<String> = (vars.iter().zip(&var_col))
        .filter(|(_, c)| c.is_none())
        .map(|(v, _)| format!("`{v}`"))
        .collect();
    if !missing.is_empty() {
        miette::bail!(
            "{name}:1: no column for axis variable{} {}; the header names every axis variable ({})",
            if missing.len() > 1 { "s" } else { "" },
            missing.join(", "),
            list(vars)
        );
    }
    let given = dir_col.iter().filter(|c| c.is_some()).count();
    let kind = match (args.kind, given) {
        (_, 1 | 2) => {
            let absent: Vec<&str> = (DIRECTION.iter().zip(&dir_col))
                .filter(|(_, c)| c.is_none())
                .map(|(d, _)| *d)
                .collect();
            miette::bail!(
                "{name}:1: a direction needs all of `ux,uy,uz`; `{}` missing",
                absent.join("`, `")
            );
        }
        (Some(KindArg::Point), 3) => miette::bail!(
            "{name}:1: columns `ux,uy,uz` give directions, but --kind point measures px, py, pz; pass --kind direction or remove them"
        ),
        (Some(KindArg::Direction), 0) => miette::bail!(
            "{name}:1: --kind direction needs the columns `ux,uy,uz` (the unit direction of each measurement)"
        ),
        (Some(KindArg::Direction), _) | (None, 3) => Kind::Direction,
        _ => Kind::Point,
    };
    // Parameters without a column: --param, else the file's value.
    for (n, _) in &args.param.params {
        if m.parameter_index(n).is_none() {
            miette::bail!(
                "{}: --param {n}: machine `{}` has no parameter `{n}`",
                args.file.display(),
                m.name
            );
        }
    }
    let fixed: Vec<Option<f64>> = (m.parameters.iter())
        .map(|p| {
            (args.param.params.iter().rev())
                .find(|(n, _)| *n == p.name)
                .map(|(_, v)| *v)
                .or(p.value)
        })
        .collect();
    let mut par_value: Vec<Option<f64>> = Vec::with_capacity(pars.len());
    for (k, p) in pars.iter().enumerate() {
        let v = m.parameter_index(p).and_then(|i| fixed[i]);
        if par_col[k].is_none() && v.is_none() {
            miette::bail!(
                "{}: parameter `{p}` has no value: give it a column in {name} (one value per row) or pass --param {p}=VALUE",
                args.file.display()
            );
        }
        par_value.push(v);
    }
    let rows = numeric_rows(&mut input)?;
    let mut out = Vec::with_capacity(rows.len());
    for (line, values) in rows {
        let direction = (kind == Kind::Direction)
            .then(|| std::array::from_fn(|d| dir_col[d].map_or(f64::NAN, |c| values[c])));
        if let Some(u) = direction {
            let length = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
            if (length - 1.0).abs() > plan::UNIT_TOLERANCE {
                miette::bail!(
                    "{name}:{line}: the direction (ux, uy, uz) = ({}, {}, {}) has length {length}, not 1 (to {:e})",
                    u[0],
                    u[1],
                    u[2],
                    plan::UNIT_TOLERANCE
                );
            }
        }
        out.push(Candidate {
            q: var_col
                .iter()
                .map(|c| c.map_or(f64::NAN, |c| values[c]))
                .collect(),
            p: (par_col.iter().zip(&par_value))
                .map(|(c, v)| c.map_or(v.unwrap_or(f64::NAN), |c| values[c]))
                .collect(),
            direction,
        });
    }
    if args.count == 0 || args.count > out.len() {
        return Err(plan_error(
            PlanError::Count {
                count: args.count,
                candidates: out.len(),
            },
            &name,
        ));
    }
    Ok((out, kind))
}

fn list(names: &[&str]) -> String {
    names
        .iter()
        .map(|v| format!("`{v}`"))
        .collect::<Vec<_>>()
        .join(", ")
}

// ---------------------------------------------------------------------------
// Output.

/// The report of `chain plan`: the library's [`Plan`] with the chosen poses.
#[derive(Debug, Serialize)]
pub(crate) struct PlanDoc {
    machine: String,
    candidates_file: String,
    variables: Vec<String>,
    #[serde(skip)]
    poses: Vec<Vec<f64>>,
    #[serde(flatten)]
    plan: Plan,
}

impl Report for PlanDoc {
    fn table(&self) -> String {
        use std::fmt::Write;
        let p = &self.plan;
        let mut out = String::new();
        let _ = writeln!(
            out,
            "Measurement plan for {}: {} of the {} candidates of {} ({} measurements)",
            self.machine,
            p.count,
            p.candidates,
            self.candidates_file,
            match p.kind {
                Kind::Point => "tool-point px, py, pz",
                Kind::Direction => "1-D, along each candidate's direction",
            }
        );
        let aliased = p.aliased.iter().filter(|&&a| a).count();
        let _ = writeln!(
            out,
            "identifiable: rank {} of {} error parameters{}",
            p.rank,
            p.errors.len(),
            if aliased == 0 {
                String::new()
            } else {
                format!(
                    "; {aliased} act only together with others (marked *; their std is that of the minimum-norm estimate)"
                )
            }
        );
        let ld = |x: Option<f64>| x.map_or("-inf (singular)".to_string(), |v| format!("{v:.4}"));
        let _ = writeln!(
            out,
            "ln det on the identifiable subspace: D-optimal {}, even spread {}",
            ld(p.optimal.log_det),
            ld(p.even.log_det)
        );
        if let (Some(a), Some(b)) = (p.optimal.log_det, p.even.log_det) {
            let _ = writeln!(
                out,
                "D-efficiency of the even spread: {:.4} (det ratio^(1/rank))",
                ((b - a) / p.rank as f64).exp()
            );
        }
        let _ = writeln!(
            out,
            "exchange: {} swaps in {} sweeps after the greedy start",
            p.swaps, p.sweeps
        );
        let _ = writeln!(out);
        let _ = writeln!(
            out,
            "expected std per unit measurement std:\n{:<14} {:>14} {:>14} {:>8}",
            "parameter", "D-optimal", "even", "ratio"
        );
        for (j, e) in p.errors.iter().enumerate() {
            let (a, b) = (p.optimal.std[j], p.even.std[j]);
            let f = |x: Option<f64>| x.map_or("-".to_string(), |v| format!("{v:.4e}"));
            let ratio = match (a, b) {
                (Some(a), Some(b)) if a > 0.0 => format!("{:.3}", b / a),
                _ => "-".into(),
            };
            let mark = if p.aliased[j] { "*" } else { "" };
            let _ = writeln!(
                out,
                "{:<14} {:>14} {:>14} {:>8}",
                format!("{e}{mark}"),
                f(a),
                f(b),
                ratio
            );
        }
        let _ = writeln!(out);
        let _ = writeln!(out, "chosen candidates (row of {}):", self.candidates_file);
        let header: Vec<String> = std::iter::once("row".to_string())
            .chain(self.variables.iter().cloned())
            .collect();
        let _ = writeln!(
            out,
            "{}",
            header
                .iter()
                .map(|h| format!("{h:>12}"))
                .collect::<Vec<_>>()
                .join(" ")
        );
        for &i in &p.optimal.candidates {
            let mut cells = vec![format!("{:>12}", i + 2)];
            cells.extend(self.poses[i].iter().map(|x| format!("{:>12}", number(*x))));
            let _ = writeln!(out, "{}", cells.join(" "));
        }
        out
    }
}

fn number(x: f64) -> String {
    match report::whole(x) {
        Some(i) => i.to_string(),
        None => format!("{x:.6}"),
    }
}
