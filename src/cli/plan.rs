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

use chain_core::measured::{Layout, Measurements};
use chain_core::plan::{self, Kind, PlanDocument, PlanError};
use miette::MietteDiagnostic;

use super::args::ParamArgs;
use super::loaded::Loaded;
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
    /// The tool-point deviation `px, py, pz` (three rows per candidate); the
    /// file must not have `ux,uy,uz`.
    Point,
    /// The deviation along the candidate's `ux, uy, uz` (one row); the file
    /// must have them.
    Direction,
}

/// Arguments of `chain plan`.
#[derive(Debug, clap::Args)]
pub struct PlanArgs {
    /// Machine file (YAML).
    pub file: PathBuf,
    /// Candidate poses (CSV): the measurement CSV's columns without the
    /// measured values: a column per axis variable (rotary in radians),
    /// optional columns of parameters given per row, `ux,uy,uz` for
    /// direction measurements, optionally `std`; `-` reads stdin.
    #[arg(long, value_name = "C.csv")]
    pub candidates: PathBuf,
    /// How many candidates to choose.
    #[arg(long, value_name = "K")]
    pub count: usize,
    /// What each candidate measures (default: `direction` when the file has
    /// `ux,uy,uz`, else `point`; a `--kind` that contradicts the file is
    /// refused).
    #[arg(long, value_enum)]
    pub kind: Option<KindArg>,
    #[command(flatten)]
    pub param: ParamArgs,
    /// Output format.
    #[arg(long, value_enum, default_value = "table")]
    pub format: PlanFormat,
}

/// Runs `chain plan`.
pub fn exec(args: PlanArgs) -> miette::Result<()> {
    let loaded = Loaded::new(&args.file)?;
    let m = &loaded.machine;
    args.param.check_names(m)?;
    let name = display(&args.candidates);
    let candidates = if args.candidates.as_os_str() == "-" {
        let (_, bytes) =
            super::csv_input::read_input(&args.candidates, chain_core::bounded::MEASUREMENT_BYTES)?;
        let text = String::from_utf8(bytes)
            .map_err(|e| miette::miette!(code = "chain::utf8", "{name}: not UTF-8 text ({e})"))?;
        Measurements::parse(&text, &name, m, &args.param.params, Layout::Candidates)?
    } else {
        Measurements::read(&args.candidates, m, &args.param.params, Layout::Candidates)?
    };
    // The file decides what each candidate measures (`ux,uy,uz` present:
    // every row a direction); `--kind` must agree with it.
    let asked = args.kind.map(|k| match k {
        KindArg::Point => Kind::Point,
        KindArg::Direction => Kind::Direction,
    });
    let kind = Kind::of(&candidates, asked)
        .map_err(|e| miette::miette!("{e}"))?
        .unwrap_or(Kind::Point);
    let doc =
        plan::plan_document(m, &candidates, args.count, kind).map_err(|e| plan_error(e, &name))?;
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

// ---------------------------------------------------------------------------
// Output.

impl Report for PlanDocument {
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
            match self.kind {
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
            "expected std {}:\n{:<14} {:>14} {:>14} {:>8}",
            if p.weighted {
                "(the candidates' std column: in the errors' units)"
            } else {
                "per unit measurement std"
            },
            "parameter",
            "D-optimal",
            "even",
            "ratio"
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
        let _ = writeln!(out, "chosen candidates (line of {}):", self.candidates_file);
        let header: Vec<String> = std::iter::once("line".to_string())
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
            let mut cells = vec![format!("{:>12}", self.lines[i])];
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
