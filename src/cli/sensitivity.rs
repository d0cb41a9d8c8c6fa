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

use chain_core::geometric::{self, Coefficient, GeometricSensitivity, NominalSizes};
use chain_core::model::Component;
use reliability::{
    machine, Form, Posterior, ReliabilityError, SensitivityMethod, Target, TargetSensitivity,
};
use serde::Serialize;

use super::args::ModelArgs;
use super::reliability::reliability_plot;
use super::reliability::{parse_assignment, parse_axis, Loaded, Pairs};
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

/// The coordinates of `--at`, `(variable, value)` in the order given.
#[derive(Debug, Clone, PartialEq)]
pub struct AtPoint(pub Vec<(String, f64)>);

/// Parses `x=0,y=1500,z=600`.
pub(crate) fn parse_point(s: &str) -> Result<AtPoint, String> {
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
    let posterior = loaded.posterior(file)?;
    let (study, model) = loaded.study_with(
        &args.model.param.params,
        &args.grid,
        args.model.sided,
        None,
        posterior.as_ref(),
    )?;
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
            let values = machine::parameters(&loaded.machine, &args.model.param.params)
                .map_err(|e| loaded.report(e))?;
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
    let mut doc = SensitivityDoc::new(&loaded.machine.name, at, &result);
    doc.posterior = posterior.as_ref();
    report::emit(&doc, args.format.into())
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

/// The document of `chain sensitivity --kind reliability`.
#[derive(Serialize)]
struct SensitivityDoc<'a> {
    machine: &'a str,
    /// The point, or `null` for the grid mean.
    at: Option<Pairs<String, f64>>,
    methods: Pairs<Target, SensitivityMethod>,
    components: Pairs<Target, Vec<ErrorDoc<'a>>>,
    /// The posterior of `--values`, when given.
    #[serde(skip_serializing_if = "Option::is_none")]
    posterior: Option<&'a Posterior>,
    #[serde(skip)]
    result: &'a [TargetSensitivity],
}

/// One error of [`SensitivityDoc`]; the grid mean also has the mean
/// absolute values.
#[derive(Serialize)]
struct ErrorDoc<'a> {
    error: &'a str,
    dr_dstd: f64,
    dr_dmean: f64,
    importance: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    mean_abs_dr_dstd: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    mean_abs_dr_dmean: Option<f64>,
}

impl<'a> SensitivityDoc<'a> {
    /// The document of the sensitivities `result`, at the point `at` (or the
    /// grid mean, which adds the mean absolute values).
    fn new(
        machine: &'a str,
        at: Option<Vec<(String, f64)>>,
        result: &'a [TargetSensitivity],
    ) -> SensitivityDoc<'a> {
        let mean = at.is_none();
        let errors = |t: &'a TargetSensitivity| -> Vec<ErrorDoc<'a>> {
            t.errors
                .iter()
                .map(|e| ErrorDoc {
                    error: &e.error,
                    dr_dstd: e.dr_dstd,
                    dr_dmean: e.dr_dmean,
                    importance: e.importance,
                    mean_abs_dr_dstd: mean.then_some(e.mean_abs_dr_dstd),
                    mean_abs_dr_dmean: mean.then_some(e.mean_abs_dr_dmean),
                })
                .collect()
        };
        SensitivityDoc {
            machine,
            at: at.map(Pairs),
            methods: Pairs(result.iter().map(|t| (t.target, t.method)).collect()),
            components: Pairs(result.iter().map(|t| (t.target, errors(t))).collect()),
            posterior: None,
            result,
        }
    }
}

impl Report for SensitivityDoc<'_> {
    fn table(&self) -> String {
        use std::fmt::Write as _;
        let mut out = String::new();
        let where_ = match &self.at {
            Some(a) => at_text(&a.0),
            None => "mean over the reliability grid".to_string(),
        };
        let _ = writeln!(
            out,
            "{}: reliability sensitivity (Eq. 32-33), {where_}",
            self.machine
        );
        if let Some(p) = self.posterior {
            let _ = write!(out, "{}", super::reliability::posterior_lines(p));
            if !p.correlations.is_empty() {
                let _ = writeln!(
                    out,
                    "dR/dstd with the correlations held fixed; importance: Der Kiureghian's gamma^2 (docs/posterior.md)"
                );
            }
        }
        for t in self.result {
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

/// Where the geometric coefficients were evaluated.
enum Where {
    /// One point, `(variable, value)` in the model's variable order.
    At(Vec<(String, f64)>),
    /// The mean over a grid, `(variable, values)` in the model's variable order.
    Grid(Vec<(String, Vec<f64>)>),
}

fn unknown_variable(loaded: &Loaded, name: &str) -> miette::Report {
    let m = &loaded.machine;
    loaded.report(ReliabilityError::unknown(
        "axis variable",
        name,
        m.variables.iter().map(|v| v.name.as_str()),
    ))
}

/// The values of `--at` in the machine's variable order: every axis
/// variable once (a repeated name: the last value), no unknown name.
pub(crate) fn resolve_at(coords: &[(String, f64)], loaded: &Loaded) -> miette::Result<Vec<f64>> {
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
    let doc = GeometricDoc::new(&m.name, &where_, &nominal, &result);
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

/// The document of `chain sensitivity --kind geometric`.
#[derive(Serialize)]
struct GeometricDoc<'a> {
    machine: &'a str,
    kind: &'static str,
    /// The point, or `null` for the grid mean.
    at: Option<Pairs<&'a str, f64>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    grid: Option<Pairs<&'a str, &'a [f64]>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    points: Option<usize>,
    normalisation: &'static str,
    values: &'a NominalSizes,
    totals: Pairs<Component, f64>,
    components: Pairs<Component, Vec<CoefficientDoc<'a>>>,
    #[serde(skip)]
    where_: &'a Where,
    #[serde(skip)]
    result: &'a GeometricSensitivity,
}

/// One coefficient of [`GeometricDoc`]; the grid mean also has the range.
#[derive(Serialize)]
struct CoefficientDoc<'a> {
    error: &'a str,
    s: f64,
    c: f64,
    e: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    c_min: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    c_max: Option<f64>,
}

impl<'a> GeometricDoc<'a> {
    fn new(
        machine: &'a str,
        where_: &'a Where,
        nominal: &'a NominalSizes,
        r: &'a GeometricSensitivity,
    ) -> GeometricDoc<'a> {
        let grid = matches!(where_, Where::Grid(_));
        let coefficient = |e: &'a Coefficient| CoefficientDoc {
            error: &e.error,
            s: e.s,
            c: e.c,
            e: e.e,
            c_min: grid.then_some(e.c_min),
            c_max: grid.then_some(e.c_max),
        };
        GeometricDoc {
            machine,
            kind: "geometric",
            at: match where_ {
                Where::At(a) => Some(Pairs(a.iter().map(|(n, v)| (n.as_str(), *v)).collect())),
                Where::Grid(_) => None,
            },
            grid: match where_ {
                Where::Grid(g) => Some(Pairs(
                    g.iter().map(|(n, v)| (n.as_str(), v.as_slice())).collect(),
                )),
                Where::At(_) => None,
            },
            points: grid.then_some(r.points),
            normalisation: "c = s*e / sum(s*e)",
            values: nominal,
            totals: Pairs(
                r.components
                    .iter()
                    .map(|c| (c.component, c.total))
                    .collect(),
            ),
            components: Pairs(
                r.components
                    .iter()
                    .map(|c| (c.component, c.ranked.iter().map(coefficient).collect()))
                    .collect(),
            ),
            where_,
            result: r,
        }
    }
}

impl Report for GeometricDoc<'_> {
    fn table(&self) -> String {
        geometric_table(self.machine, self.where_, self.values, self.result)
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
