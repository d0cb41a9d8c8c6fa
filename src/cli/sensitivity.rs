//! `chain sensitivity FILE [--kind reliability|geometric] [--at x=..,y=..,z=..]
//! [--format table|json] [--plot DIR]`.
//!
//! `--kind reliability` (the default): the reliability sensitivity of each component to the mean and standard
//! deviation of every error parameter (seed 000, Eq. 32-33) and its FORM
//! importance factor: at one point with `--at`, otherwise the mean over the
//! file's reliability grid (the paper's Figures 6-8). Lists are sorted by
//! `|∂R/∂σ|`, largest first; `--plot DIR` draws them as bar charts (the
//! charts of `chain reliability --plot`).
//!
//! `--kind geometric`: the geometric error sensitivity coefficients of seed
//! 004 (Eq. 4-6), `S = |∂E_u/∂e_v|` and `C = S·e / Σ S·e` per direction,
//! at `--at` or averaged over the reliability grid (or `--grid`), with
//! `--values` giving the nominal error sizes and `--plot DIR` bar charts like
//! the paper's Figures 3-5 (see `docs/geometric_sensitivity.md`).

#[path = "geometric_plot.rs"]
mod geometric_plot;

use std::path::PathBuf;

use chain_core::geometric::{
    self, GeometricDocument, GeometricSensitivity, GridAxisError, NominalSizes, Where,
};
use reliability::document::{self, SensitivityDocument};
use reliability::{machine, Form, ReliabilityError};
use serde::Serialize;

use super::args::{parse_axis, parse_point, AtPoint, ModelArgs};
use super::loaded::{resolve_at, Loaded};
use super::reliability_plot;
use super::report::{self, Report};

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
    #[command(flatten)]
    pub model: ModelArgs,
    /// What to compute.
    #[arg(long, value_enum, default_value = "reliability")]
    pub kind: SensitivityKind,
    /// `--kind reliability`: a values file with the posterior of a calibration
    /// (means, `std`, `correlation`; docs/posterior.md). `--kind geometric`:
    /// nominal error sizes `linear=MM,angular=ANGLE[,squareness=ANGLE]`,
    /// angles in radians or with a `deg` suffix (default `linear=0.001,angular=0.001deg`).
    /// An argument with `=` is nominal sizes, any other a values file.
    #[arg(long, value_name = "VALUES.yaml | KIND=VALUE,...", value_parser = parse_values)]
    pub values: Option<ValuesArg>,
    /// `--kind reliability` with a values file: which approach direction of
    /// its bidirectional tables to read, `up`, `down`, `mean` (the default)
    /// or per axis `x=up,y=down` (docs/values.md, "Direction").
    #[arg(long, value_name = "DIR|VAR=DIR,...", value_parser = chain_core::values::parse_approaches, requires = "values")]
    pub approach: Vec<Vec<(Option<String>, chain_core::values::Approach)>>,
    /// Replace the grid values of one axis for the grid mean, `VAR=v1,v2,...` (repeatable).
    #[arg(long = "grid", value_name = "VAR=V1,V2,...", value_parser = parse_axis)]
    pub grid: Vec<(String, Vec<f64>)>,
    /// Write bar charts (PNG and SVG) into DIR: `|∂R/∂σ|` per component
    /// (`--kind reliability`, like Figures 6-8 of Wang & Yuan 2021) or the
    /// geometric coefficients (`--kind geometric`).
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
}

/// What `--values` gives.
#[derive(Debug, Clone)]
pub enum ValuesArg {
    /// Nominal error sizes (`--kind geometric`).
    Nominal(NominalSizes),
    /// A values file: the posterior (`--kind reliability`).
    File(PathBuf),
}

/// Parses `--values`: nominal sizes when it has a `=`, a values file otherwise.
fn parse_values(s: &str) -> Result<ValuesArg, String> {
    if s.contains('=') {
        NominalSizes::default().parse(s).map(ValuesArg::Nominal)
    } else {
        Ok(ValuesArg::File(PathBuf::from(s)))
    }
}

/// Runs `chain sensitivity`.
pub fn exec(args: SensitivityArgs) -> miette::Result<()> {
    if args.kind == SensitivityKind::Geometric {
        return exec_geometric(args);
    }
    let file = match &args.values {
        Some(ValuesArg::Nominal(_)) => {
            return Err(miette::miette!(
                help = "add --kind geometric, or give a values file for the posterior",
                "--values applies only to --kind geometric when it gives nominal sizes (KIND=VALUE)"
            ))
        }
        Some(ValuesArg::File(f)) => Some(f.as_path()),
        None => None,
    };
    let loaded = Loaded::new(&args.file)?;
    let posterior = loaded.posterior(file, &args.approach)?;
    let (study, model) = loaded.study_with(
        &args.model.param.params,
        &args.grid,
        args.model.sided,
        None,
        posterior.as_ref(),
    )?;
    let form = Form::default();
    let point = match &args.at {
        None => None,
        Some(AtPoint(coords)) => Some(resolve_at(coords, &loaded)?),
    };
    let values = machine::parameters(&loaded.machine, &args.model.param.params)
        .map_err(|e| loaded.report(e))?;
    let (at, result) = document::sensitivity(&study, &model, &values, point.as_deref(), &form)
        .map_err(|e| loaded.report(e))?;
    if let Some(dir) = &args.plot {
        let where_ = match &at {
            Some(a) => at_text(a),
            None => "grid mean".to_string(),
        };
        let files = reliability_plot::write_sensitivity(
            dir,
            &loaded.machine.name,
            study.inputs().names(),
            &result,
            &where_,
        )?;
        for f in files {
            eprintln!("wrote {}", f.display());
        }
    }
    let doc = SensitivityDocument::new(&loaded.machine.name, at, &result, posterior.as_ref());
    report::emit(&SensitivityDoc(doc), args.format.into())
}

report::formats!(SensitivityFormat: Table, Json);

/// `at x = 0, y = 1500, z = 600`.
fn at_text(a: &[(String, f64)]) -> String {
    format!(
        "at {}",
        a.iter()
            .map(|(n, v)| format!("{n} = {v}"))
            .collect::<Vec<_>>()
            .join(", ")
    )
}

/// The document of `chain sensitivity --kind reliability` (the library's
/// [`SensitivityDocument`]) with its table.
#[derive(Serialize)]
#[serde(transparent)]
struct SensitivityDoc<'a>(SensitivityDocument<'a>);

impl Report for SensitivityDoc<'_> {
    fn table(&self) -> String {
        use std::fmt::Write as _;
        let d = &self.0;
        let mut out = String::new();
        let where_ = match &d.at {
            Some(a) => at_text(&a.0),
            None => "mean over the reliability grid".to_string(),
        };
        let _ = writeln!(
            out,
            "{}: reliability sensitivity (Eq. 32-33), {where_}",
            d.machine
        );
        if let Some(p) = d.posterior {
            let _ = write!(out, "{}", super::study_text::posterior_lines(p));
            if !p.correlations.is_empty() {
                let _ = writeln!(
                    out,
                    "dR/dstd with the correlations held fixed; importance: Der Kiureghian's gamma^2 (docs/posterior.md)"
                );
            }
        }
        for t in d.result {
            let _ = writeln!(
                out,
                "\n{} ({}), sorted by |dR/dstd|:",
                t.target,
                t.method.name()
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
}

// ---------------------------------------------------------------------------
// `--kind geometric` (seed 004, Eq. 4-6).

fn unknown_variable(loaded: &Loaded, name: &str) -> miette::Report {
    let m = &loaded.machine;
    loaded.report(ReliabilityError::unknown(
        "axis variable",
        name,
        m.variables.iter().map(|v| v.name.as_str()),
    ))
}

fn exec_geometric(args: SensitivityArgs) -> miette::Result<()> {
    if !args.approach.is_empty() {
        return Err(miette::miette!(
            help = "--approach chooses the direction of a values file's tables: use it with --kind reliability --values VALUES.yaml",
            "--kind geometric does not take --approach"
        ));
    }
    let loaded = Loaded::new(&args.file)?;
    let m = &loaded.machine;
    let params = machine::parameters(m, &args.model.param.params).map_err(|e| loaded.report(e))?;
    let model = chain_core::compile(m);
    let nominal = match args.values {
        None => NominalSizes::default(),
        Some(ValuesArg::Nominal(n)) => n,
        Some(ValuesArg::File(f)) => {
            return Err(miette::miette!(
                help = "give nominal sizes, e.g. --values linear=0.001,angular=0.001deg, or use --kind reliability for a posterior",
                "--values {}: a values file applies to --kind reliability (the posterior of a calibration)",
                f.display()
            ))
        }
    };
    let sizes = nominal.of(m);
    let vars: Vec<&str> = m.variables.iter().map(|v| v.name.as_str()).collect();
    let where_ = match &args.at {
        Some(AtPoint(coords)) => {
            if !args.grid.is_empty() {
                return Err(miette::miette!(
                    help =
                        "--at evaluates at one point, --grid sets the grid of the mean; give one",
                    "--grid cannot be combined with --at"
                ));
            }
            let point = resolve_at(coords, &loaded)?;
            Where::At(
                vars.iter()
                    .zip(&point)
                    .map(|(n, x)| (n.to_string(), *x))
                    .collect(),
            )
        }
        None => Where::Grid(geometric::grid_axes(m, &args.grid).map_err(|e| match e {
            GridAxisError::UnknownVariable(name) => unknown_variable(&loaded, &name),
            GridAxisError::NoValues(v) => miette::miette!(
                help = format!(
                    "evaluate at one point with --at {}, or give the grid with --grid {v}=V1,V2,...",
                    vars.iter().map(|v| format!("{v}=…")).collect::<Vec<_>>().join(",")
                ),
                "{}: no grid values for axis variable `{v}` (key `reliability.grid.{v}`)",
                loaded.machine.file.as_deref().unwrap_or("machine")
            ),
        })?),
    };
    let result = geometric::evaluate(&model, &where_, &params, &sizes);
    if let Some(dir) = &args.plot {
        let files = geometric_plot::write_all(dir, &m.name, &where_text(&where_), &result)?;
        for f in files {
            eprintln!("wrote {}", f.display());
        }
    }
    let doc = GeometricDoc(GeometricDocument::new(&m.name, &where_, &nominal, &result));
    report::emit(&doc, args.format.into())
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

/// The document of `chain sensitivity --kind geometric` (the library's
/// [`GeometricDocument`]) with its table.
#[derive(Serialize)]
#[serde(transparent)]
struct GeometricDoc<'a>(GeometricDocument<'a>);

impl Report for GeometricDoc<'_> {
    fn table(&self) -> String {
        geometric_table(self.0.machine, self.0.where_, self.0.values, self.0.result)
    }
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
