//! `chain reliability FILE [--values VALUES.yaml] [--method form|is|mc]
//! [--samples N] [--seed S] [--format table|json|csv] [--plot DIR]`.
//!
//! With `--values` the inputs are the posterior of a calibration
//! (`docs/posterior.md`, [`reliability::Posterior`]): the values file's
//! constants as means, their `std` and `correlation` as a correlated normal,
//! the `statistics` section for the errors the file does not give.
//!
//! Machining-accuracy reliability of every listed component (and optionally
//! a series or volumetric system) over the file's grid, like Tables 2-4 of
//! seed 000. The helpers shared with `chain sensitivity` (loading, building
//! the study, rendering errors against the file) live here too.

use std::io::IsTerminal;
use std::path::PathBuf;

use reliability::document::{AcceptanceDocument, ReliabilityDocument};
use reliability::{Form, Stopping, Study, StudyResult, SubsetLevel};
use serde::Serialize;

use super::args::{parse_axis, system_of, AlgorithmArgs, MethodArg, ModelArgs, SystemArgs};
use super::loaded::Loaded;
use super::reliability_plot;
use super::report::{self, Csv, Report};
use super::study_text::{
    calls_text, fmt_num, note_form_limits, posterior_lines, requirement_text, sided_title,
    target_map, warn_unconverged,
};

/// Output formats of `chain reliability`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ReliabilityFormat {
    /// Maps like the paper's Tables 2-4 and a summary.
    Table,
    /// The spec's JSON document.
    Json,
    /// One row per (target, point).
    Csv,
}

/// Arguments of `chain reliability`.
#[derive(Debug, clap::Args)]
pub struct ReliabilityArgs {
    /// Machine file (YAML) with `statistics` and `reliability` sections.
    pub file: PathBuf,
    #[command(flatten)]
    pub algorithm: AlgorithmArgs,
    /// Output format.
    #[arg(long, value_enum, default_value = "table")]
    pub format: ReliabilityFormat,
    /// Write heat maps and sensitivity bar charts (PNG and SVG) into DIR.
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
    #[command(flatten)]
    pub model: ModelArgs,
    /// Replace the grid values of one axis, `VAR=v1,v2,...` (repeatable).
    #[arg(long = "grid", value_name = "VAR=V1,V2,...", value_parser = parse_axis)]
    pub grid: Vec<(String, Vec<f64>)>,
    #[command(flatten)]
    pub system: SystemArgs,
    /// A values file with the posterior of a calibration (means, `std` per
    /// constant, `correlation: [[NAME, NAME, rho], ...]`) or a built
    /// machine's measured tables (a positioning run's means and
    /// repeatability); errors it does not give keep their `statistics`
    /// (docs/posterior.md).
    #[arg(long, value_name = "VALUES.yaml")]
    pub values: Option<PathBuf>,
    /// Which approach direction of the values' bidirectional tables to
    /// read: `up`, `down` or `mean` (the default), or per axis
    /// `x=up,y=down` (docs/values.md, "Direction").
    #[arg(long, value_name = "DIR|VAR=DIR,...", value_parser = chain_core::values::parse_approaches, requires = "values")]
    pub approach: Vec<Vec<(Option<String>, chain_core::values::Approach)>>,
    /// Also the whole-machine acceptance probability: every toleranced
    /// component within tolerance at every grid point at once, with its
    /// sensitivities (as `reliability.acceptance: true`; docs/acceptance.md).
    #[arg(long)]
    pub acceptance: bool,
    /// Absolute error of the acceptance probability (three standard errors).
    #[arg(long, value_name = "ABS", default_value_t = 1e-3)]
    pub acceptance_tolerance: f64,
}

/// Runs `chain reliability`.
pub fn exec(args: ReliabilityArgs) -> miette::Result<()> {
    args.algorithm.check()?;
    let loaded = Loaded::new(&args.file)?;
    let system = system_of(&loaded.machine, &args.system).map_err(|e| loaded.report(e))?;
    let posterior = loaded.posterior(args.values.as_deref(), &args.approach)?;
    let (study, _model) = loaded.study_with(
        &args.model.param.params,
        &args.grid,
        args.model.sided,
        system,
        posterior.as_ref(),
    )?;
    let samples = args
        .algorithm
        .method
        .samples(args.algorithm.samples, args.algorithm.cov.is_some());
    let bar = if !args.algorithm.method.samples_anything() {
        ProgressBar(None)
    } else {
        let known = args.algorithm.cov.is_none() && args.algorithm.method != MethodArg::Subset;
        let total = known.then(|| samples.saturating_mul(study_cases(&study)));
        ProgressBar::new(total, args.format)
    };
    let result = study.run(&args.algorithm.algorithm(), &|n| bar.inc(n));
    bar.finish();
    let result = result.map_err(|e| loaded.report(e))?;
    if args.algorithm.method == MethodArg::Form {
        note_form_limits(&study);
    }
    warn_unconverged(&result, study.variables());
    if let Some(dir) = &args.plot {
        let sens = study
            .sensitivity_mean(&Form::default())
            .map_err(|e| loaded.report(e))?;
        let files = reliability_plot::write_all(dir, &loaded.machine.name, &study, &result, &sens)?;
        for f in files {
            eprintln!("wrote {}", f.display());
        }
    }
    let wanted = args.acceptance
        || loaded
            .machine
            .reliability
            .as_ref()
            .is_some_and(|r| r.acceptance);
    let acceptance = if wanted {
        Some(super::acceptance::run(
            &loaded,
            &study,
            args.acceptance_tolerance,
            args.algorithm.seed,
        )?)
    } else {
        None
    };
    let mut doc = ReliabilityDoc::new(&loaded.machine.name, &study, &result);
    doc.doc.posterior = posterior.as_ref();
    doc.doc.acceptance = acceptance.as_ref().map(AcceptanceDocument::of);
    doc.acceptance = acceptance.as_ref();
    report::emit(&doc, args.format.into())
}

report::formats!(ReliabilityFormat: Table, Json, Csv);

fn study_cases(study: &Study) -> u64 {
    (study.targets().len() * study.points().len()) as u64
}

/// A progress bar on stderr, only when stderr is a terminal and the output is
/// not JSON.
struct ProgressBar(Option<indicatif::ProgressBar>);

impl ProgressBar {
    /// A bar over `total` samples when the count is known in advance (the
    /// fixed-count samplers); otherwise (subset simulation, whose levels are
    /// found as it runs, and every sampler stopped by `--cov`) a counter of
    /// the samples drawn, since any total would be a guess.
    fn new(total: Option<u64>, format: ReliabilityFormat) -> ProgressBar {
        if format == ReliabilityFormat::Json || !std::io::stderr().is_terminal() {
            return ProgressBar(None);
        }
        let bar = indicatif::ProgressBar::with_draw_target(
            total,
            indicatif::ProgressDrawTarget::stderr(),
        );
        let template = if total.is_some() {
            "{spinner} sampling [{bar:40}] {percent:>3}% {human_pos}/{human_len} samples, eta {eta}"
        } else {
            "{spinner} sampling: {human_pos} samples drawn, {elapsed}"
        };
        if let Ok(style) = indicatif::ProgressStyle::with_template(template) {
            bar.set_style(style.progress_chars("=> "));
        }
        ProgressBar(Some(bar))
    }

    fn inc(&self, n: u64) {
        if let Some(b) = &self.0 {
            b.inc(n);
        }
    }

    fn finish(&self) {
        if let Some(b) = &self.0 {
            b.finish_and_clear();
        }
    }
}

// ---------------------------------------------------------------------------
// Output.

/// The grid axes in file order, as (name, index in the model's variables).
pub(crate) fn axes(study: &Study) -> Vec<(String, usize)> {
    study
        .spec()
        .grid
        .axes
        .iter()
        .filter_map(|(n, _)| {
            study
                .variables()
                .iter()
                .position(|v| v == n)
                .map(|i| (n.clone(), i))
        })
        .collect()
}

/// The document of `chain reliability`: the library's
/// [`ReliabilityDocument`] (the spec's JSON) with its table and CSV.
#[derive(Serialize)]
pub(crate) struct ReliabilityDoc<'a> {
    #[serde(flatten)]
    pub(crate) doc: ReliabilityDocument<'a>,
    /// The whole-machine acceptance probability (`--acceptance`) for the
    /// table and CSV (the JSON has the document's `acceptance`).
    #[serde(skip)]
    pub(crate) acceptance: Option<&'a reliability::AcceptanceResult>,
    #[serde(skip)]
    study: &'a Study,
    #[serde(skip)]
    result: &'a StudyResult,
}

impl<'a> ReliabilityDoc<'a> {
    /// The document of a study's result.
    pub(crate) fn new(machine: &'a str, study: &'a Study, r: &'a StudyResult) -> Self {
        ReliabilityDoc {
            doc: ReliabilityDocument::new(machine, study, r),
            acceptance: None,
            study,
            result: r,
        }
    }
}

impl Report for ReliabilityDoc<'_> {
    fn table(&self) -> String {
        let mut table = to_table(self.doc.machine, self.study, self.result);
        if let Some(a) = self.acceptance {
            table.push_str(&super::acceptance::table(self.study, a));
        }
        match self.doc.posterior {
            None => table,
            Some(p) => format!("{}{table}", posterior_lines(p)),
        }
    }

    fn csv(&self) -> Option<Csv> {
        let (study, r) = (self.study, self.result);
        let ax = axes(study);
        // With the acceptance row, the sampling columns are always there
        // (empty for FORM cases).
        let sampled =
            r.cases.first().is_some_and(|c| c.samples.is_some()) || self.acceptance.is_some();
        let mut header = vec!["component".to_string()];
        header.extend(ax.iter().map(|(n, _)| n.clone()));
        header.extend(["reliability", "pf", "beta"].map(String::from));
        if sampled {
            header.extend(["std_error", "cov", "samples"].map(String::from));
        }
        header.extend(
            [
                "termination",
                "converged",
                "iterations",
                "exact",
                "value_calls",
                "gradient_calls",
            ]
            .map(String::from),
        );
        // The sampler's stopping rule, when it reports one (v1 runs do not).
        let stopped = r.cases.iter().any(|c| c.stopping.is_some());
        let leveled = r.cases.iter().any(|c| c.levels.is_some());
        if stopped {
            header.extend(["stopped_by", "sampler_converged"].map(String::from));
        }
        if leveled {
            header.push("levels".to_string());
        }
        // SORM's three formulas (`--method sorm`), last.
        let sorm = r.cases.iter().any(|c| c.sorm.is_some());
        if sorm {
            header.extend(
                [
                    "beta_breitung",
                    "beta_hohenbichler_rackwitz",
                    "beta_tvedt",
                    "sorm_converged",
                ]
                .map(String::from),
            );
        }
        let width = header.len();
        let mut csv = Csv::new(header);
        for c in &r.cases {
            let mut row = vec![c.target.to_string()];
            row.extend(ax.iter().map(|(_, i)| fmt_num(c.point[*i])));
            row.extend([c.reliability, c.pf, c.beta].map(csv_number));
            if sampled && self.acceptance.is_some() {
                row.push(c.std_error.map_or(String::new(), csv_number));
                row.push(c.cov.map_or(String::new(), csv_number));
                row.push(c.samples.map_or(String::new(), |v| v.to_string()));
            } else if sampled {
                row.push(format!("{:?}", c.std_error.unwrap_or(0.0)));
                row.push(format!("{:?}", c.cov.unwrap_or(0.0)));
                row.push(c.samples.unwrap_or(0).to_string());
            }
            match &c.form {
                Some(f) => row.extend([
                    f.termination.to_string(),
                    f.converged.to_string(),
                    f.iterations.to_string(),
                    f.exact.to_string(),
                ]),
                None => row.extend((0..4).map(|_| String::new())),
            }
            row.push(c.calls.values.to_string());
            row.push(c.calls.gradients.to_string());
            if stopped {
                match &c.stopping {
                    Some(st) => row.extend([st.stopped_by.to_string(), st.converged.to_string()]),
                    None => row.extend([String::new(), String::new()]),
                }
            }
            if leveled {
                row.push(
                    c.levels
                        .as_ref()
                        .map_or(String::new(), |l| l.len().to_string()),
                );
            }
            if sorm {
                match &c.sorm {
                    Some(so) => {
                        row.extend(
                            [
                                so.beta_breitung,
                                so.beta_hohenbichler_rackwitz,
                                so.beta_tvedt,
                            ]
                            .map(csv_number),
                        );
                        row.push(so.converged.to_string());
                    }
                    None => row.extend((0..4).map(|_| String::new())),
                }
            }
            csv.row(row);
        }
        if let Some(a) = self.acceptance {
            let mut row = super::acceptance::csv_row(a, ax.len());
            row.resize(width.max(row.len()), String::new());
            csv.row(row);
        }
        Some(csv)
    }
}

fn to_table(machine: &str, study: &Study, r: &StudyResult) -> String {
    use std::fmt::Write as _;
    let mut out = String::new();
    let sided = sided_title(study.spec().sided);
    let _ = writeln!(
        out,
        "{machine}: machining-accuracy reliability ({}, {sided})",
        r.method.title()
    );
    let mut marked = false;
    for (t, target) in study.targets().iter().enumerate() {
        let map = target_map(study, r, t);
        let over = match (&map.rows, &map.cols) {
            (Some(a), Some(b)) => format!(" over ({}, {})", a.0, b.0),
            (Some(a), None) => format!(" over {}", a.0),
            _ => String::new(),
        };
        let _ = writeln!(out, "\n{target}: reliability (%){over}");
        for ((label, m), u) in map.maps.iter().zip(&map.unconverged) {
            if !label.is_empty() {
                let _ = writeln!(out, "  at {label}");
            }
            let corner = match (&map.rows, &map.cols) {
                (Some(a), Some(b)) => format!("{} \\ {}", a.0, b.0),
                (Some(a), None) => a.0.clone(),
                _ => String::new(),
            };
            let _ = write!(out, "  {corner:>10}");
            match &map.cols {
                Some((_, vals)) => vals.iter().for_each(|v| {
                    let _ = write!(out, " {:>9}", fmt_num(*v));
                }),
                None => {
                    let _ = write!(out, " {:>9}", "");
                }
            }
            out.push('\n');
            for (i, row) in m.iter().enumerate() {
                let head = map
                    .rows
                    .as_ref()
                    .map_or(String::new(), |(_, v)| fmt_num(v[i]));
                let _ = write!(out, "  {head:>10}");
                for v in row {
                    let _ = write!(out, " {:>9.2}", 100.0 * v);
                }
                out.push('\n');
            }
            // The cells FORM did not converge on, listed under the map (the
            // map's own lines stay those of a converged study).
            let mut bad = Vec::new();
            for (i, urow) in u.iter().enumerate() {
                for (j, unconverged) in urow.iter().enumerate() {
                    if *unconverged {
                        let coords: Vec<String> = [(&map.rows, i), (&map.cols, j)]
                            .iter()
                            .filter_map(|(axis, k)| {
                                axis.as_ref()
                                    .map(|(n, v)| format!("{n} = {}", fmt_num(v[*k])))
                            })
                            .collect();
                        bad.push(if coords.is_empty() {
                            "the point".to_string()
                        } else {
                            format!("({})", coords.join(", "))
                        });
                    }
                }
            }
            if !bad.is_empty() {
                marked = true;
                let _ = writeln!(out, "  * not converged at {}", bad.join(", "));
            }
        }
        if let Some(s) = r.summaries.get(t) {
            let _ = write!(
                out,
                "  summary: mean {:.2} %, min {:.2} %, max {:.2} %",
                100.0 * s.mean,
                100.0 * s.min,
                100.0 * s.max
            );
            if let (Some(req), Some(met)) = (r.requirement, s.met) {
                out.push_str(&requirement_text(&req, met));
            }
            out.push('\n');
        }
        let cases = r.target_cases(t);
        let se = cases
            .iter()
            .filter_map(|c| c.std_error)
            .fold(None, |m: Option<f64>, v| Some(m.map_or(v, |m| m.max(v))));
        let rule = cases.iter().filter_map(|c| c.stopping).next();
        match (se, cases.first().and_then(|c| c.samples), rule) {
            (Some(se), Some(n), None) => {
                let _ = writeln!(
                    out,
                    "  sampling: {n} samples per point, largest standard error {:.2e}",
                    se
                );
            }
            (Some(se), Some(_), Some(rule)) => {
                let _ = writeln!(out, "  {}", sampling_text(cases, rule, se));
            }
            _ => {}
        }
        let _ = writeln!(out, "  {}", calls_text(cases.iter(), r.method));
    }
    if marked {
        let sampler = r.cases.iter().any(|c| !c.sampler_converged());
        let form = r.cases.iter().any(|c| c.form.is_some_and(|f| !f.converged));
        if form {
            let _ = writeln!(
                out,
                "\n* FORM stopped at the iteration limit there: the value shown is the last iterate's, not a converged reliability"
            );
        }
        if sampler {
            let _ = writeln!(
                out,
                "\n* the {} stopped there without meeting its rule (sample budget or levels exhausted): the value shown is not a converged estimate",
                r.method.title()
            );
        }
    }
    out
}

/// The table line of a sampler that reports its stopping: the samples used
/// (a range when the rule stopped the points apart), the target and how
/// many points met it, the largest standard error; for subset simulation
/// the levels and the chains' mean acceptance rate.
fn sampling_text(cases: &[reliability::CaseResult], rule: Stopping, se: f64) -> String {
    let ns: Vec<u64> = cases.iter().filter_map(|c| c.samples).collect();
    let (lo, hi) = (
        ns.iter().copied().min().unwrap_or(0),
        ns.iter().copied().max().unwrap_or(0),
    );
    let samples = if lo == hi {
        format!("{lo} samples per point")
    } else {
        format!("{lo} to {hi} samples per point")
    };
    let met = cases.iter().filter(|c| c.sampler_converged()).count();
    let target = match rule.target_cov {
        Some(t) => format!(", target CoV {t} met at {met} of {} points", cases.len()),
        None if met < cases.len() => format!(", converged at {met} of {} points", cases.len()),
        None => String::new(),
    };
    let mut text = format!("sampling: {samples}{target}, largest standard error {se:.2e}");
    let levels: Vec<&Vec<SubsetLevel>> = cases.iter().filter_map(|c| c.levels.as_ref()).collect();
    if !levels.is_empty() {
        let counts = levels.iter().map(|l| l.len());
        let (lmin, lmax) = (counts.clone().min().unwrap_or(0), counts.max().unwrap_or(0));
        let rates: Vec<f64> = levels
            .iter()
            .flat_map(|l| l.iter().filter_map(|x| x.acceptance_rate))
            .collect();
        let levels = if lmin == lmax {
            format!("{lmin} levels")
        } else {
            format!("{lmin} to {lmax} levels")
        };
        text.push_str(&format!("; subset: {levels}"));
        if !rates.is_empty() {
            let mean = rates.iter().sum::<f64>() / rates.len() as f64;
            text.push_str(&format!(", mean acceptance {mean:.2}"));
        }
    }
    text
}

/// A CSV cell of a number: shortest round-trip form when finite, an empty
/// cell otherwise, as the JSON writes `null` (a sampled `pf` of exactly 1
/// has `beta = −∞`; `docs/robustness.md`).
fn csv_number(v: f64) -> String {
    if v.is_finite() {
        format!("{v:?}")
    } else {
        String::new()
    }
}
