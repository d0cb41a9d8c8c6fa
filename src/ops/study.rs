//! A reliability study from a machine and the options every study command
//! takes (`--param`, `--grid`, `--sided`, `--system`, `--values`): built by
//! one function for the CLI's `reliability`, `sensitivity`, `sobol`,
//! `allocate`, `acceptance`, `path` and Python's methods over them; and
//! [`describe`], the one wording of a study's reliability errors against
//! the machine file.

use std::path::Path;
use std::sync::Arc;

use chain_core::model::{Origin, Sided};
use chain_core::thermal_state::AtState;
use chain_core::values::{Approach, ApproachError};
use chain_core::{CompiledModel, Machine};
use reliability::allocate::GridUse;
use reliability::{
    Algorithm, CaseTally, DirectionalSimulation, Form, ImportanceSampling, Inputs, Method,
    MonteCarlo, Posterior, PosteriorError, ReliabilityError, Study, StudySpec, SubsetSimulation,
    System,
};

use super::resolve::{self, ResolveError};
use super::worded::{diagnostic, Worded};

/// The options of a study.
#[derive(Debug, Clone, Copy, Default)]
pub struct StudyOptions<'a> {
    /// `--param NAME=VALUE`.
    pub params: &'a [(String, f64)],
    /// `--grid VAR=...`: replaces (or adds) an axis of `reliability.grid`.
    pub grid: &'a [(String, Vec<f64>)],
    /// `--sided`: overrides the file's.
    pub sided: Option<Sided>,
    /// `--system`.
    pub system: Option<System>,
    /// `--values`: the inputs of a posterior (`None`: the `statistics`).
    pub posterior: Option<&'a Posterior>,
    /// `--temperature NAME=VALUE`: the thermal state (°C; sensors not named
    /// at their reference), whose factors scale the thermal coefficients'
    /// columns (`docs/thermal.md`).
    pub temperatures: &'a [(String, f64)],
}

/// Why a study cannot be built.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    /// An option does not match the machine.
    #[error(transparent)]
    Resolve(#[from] ResolveError),
    /// The machine's reliability section or the study (located in the
    /// machine file by [`describe`]).
    #[error(transparent)]
    Reliability(#[from] ReliabilityError),
    /// The posterior's inputs (located in the values file).
    #[error(transparent)]
    Posterior(PosteriorError),
    /// `--approach` names what the values do not have.
    #[error("--approach: {error} (values {values})")]
    Approach {
        /// The values file.
        values: String,
        /// What is wrong.
        error: ApproachError,
    },
}

/// The posterior of the values file at `path` (`--values`), its tables
/// read for the `--approach` choices (none: each table's mean).
pub fn read_posterior(
    machine: &Machine,
    path: &Path,
    approach: &[(Option<String>, Approach)],
) -> Result<Posterior, StudyError> {
    let mut posterior = Posterior::read(path, machine)?;
    if !approach.is_empty() {
        posterior
            .choose_approach(approach)
            .map_err(|error| StudyError::Approach {
                values: path.display().to_string(),
                error,
            })?;
    }
    Ok(posterior)
}

/// `--approach` chooses the direction of a values file's tables: without
/// `--values` there are none, and the choice is refused, not dropped.
pub fn check_approach(
    values: Option<&Path>,
    approach: &[(Option<String>, Approach)],
) -> Result<(), OptionError> {
    match (values, approach) {
        (None, [_, ..]) => Err(OptionError::new(
            "approach",
            "the direction of a values file's tables: give --values VALUES.yaml too",
        )),
        _ => Ok(()),
    }
}

impl From<PosteriorError> for StudyError {
    fn from(e: PosteriorError) -> StudyError {
        match e {
            PosteriorError::Reliability(e) => StudyError::Reliability(e),
            other => StudyError::Posterior(other),
        }
    }
}

impl Worded for StudyError {
    /// A point outside a posterior's tables names `--grid`, the option that
    /// chooses the points.
    fn own_help(&self) -> Option<String> {
        match self {
            StudyError::Posterior(PosteriorError::Point { .. }) => Some(
                "study the points inside the tables (--grid), extend them, or add `extrapolate: hold` to the entry"
                    .into(),
            ),
            StudyError::Resolve(e) => e.own_help(),
            _ => None,
        }
    }

    #[cfg(feature = "cli")]
    fn inner(&self) -> Option<&dyn miette::Diagnostic> {
        match self {
            StudyError::Resolve(e) => Some(e),
            StudyError::Reliability(e) => Some(e),
            StudyError::Posterior(e) => Some(e),
            StudyError::Approach { .. } => None,
        }
    }
}

diagnostic!(StudyError);

/// A study's parts resolved from the machine file and the options alone:
/// everything [`study`] checks before the model is derived (a long chain
/// takes a minute to derive; a missing grid axis, an unknown `--param` or a
/// missing statistic is refused before that).
#[derive(Debug, Clone)]
pub struct Checked {
    spec: StudySpec,
    inputs: Inputs,
    parameters: Vec<f64>,
    /// Each error's thermal factor at the state of `--temperature`.
    factors: Vec<f64>,
}

/// Checks the options against `machine` (`file` names it) and resolves the
/// study's specification, inputs and parameter values, with no derivation:
/// the parameters, the grid overrides, the grid itself (every axis a
/// variable of the machine, every variable an axis, no empty or non-finite
/// axis), the statistics (or the posterior's inputs).
pub fn check(
    machine: &Machine,
    file: &str,
    options: &StudyOptions<'_>,
) -> Result<Checked, StudyError> {
    resolve::check_parameters(machine, options.params)?;
    let mut spec = reliability::machine::spec(machine, options.system)?;
    if let Some(s) = options.sided {
        spec.sided = s;
    }
    resolve::check_grid_overrides(machine, file, options.grid)?;
    for (name, values) in options.grid {
        match spec.grid.axes.iter_mut().find(|(n, _)| n == name) {
            Some(axis) => axis.1 = values.clone(),
            None => spec.grid.axes.push((name.clone(), values.clone())),
        }
    }
    let variables: Vec<String> = machine.variables.iter().map(|v| v.name.clone()).collect();
    spec.grid.check(&variables)?;
    let inputs = match options.posterior {
        None => reliability::machine::inputs(machine)?,
        Some(p) => p.inputs(machine)?,
    };
    let parameters = reliability::machine::parameters(machine, options.params)?;
    let factors = resolve::thermal_factors(machine, options.temperatures)?;
    Ok(Checked {
        spec,
        inputs,
        parameters,
        factors,
    })
}

impl Checked {
    /// The same study at the thermal state `temperatures` (°C; the sensors
    /// not named at their reference).
    pub fn at_temperatures(
        mut self,
        machine: &Machine,
        temperatures: &[(String, f64)],
    ) -> Result<Checked, StudyError> {
        self.factors = resolve::thermal_factors(machine, temperatures)?;
        Ok(self)
    }
}

/// The study of a [`check`]ed machine, evaluated through `model` (compiled
/// from it), with the posterior's inputs per point when `options` has one.
///
/// The study keeps a copy of the model, not the sensitivities
/// ([`Study::on_demand`]): every command over it uses each point's a few
/// times at most, and a million-point grid then holds only its points
/// (the tape's blocks equal its points bit for bit, so the results are
/// those of a study that keeps them).
pub fn build(
    machine: &Machine,
    model: &CompiledModel,
    checked: Checked,
    options: &StudyOptions<'_>,
) -> Result<Study, StudyError> {
    let Checked {
        spec,
        inputs,
        parameters,
        factors,
    } = checked;
    let shared: reliability::study::SharedModel = if factors.iter().all(|f| *f == 1.0) {
        Arc::new(model.clone())
    } else {
        Arc::new(AtState::new(model.clone(), factors))
    };
    let study = Study::on_demand(shared, &parameters, inputs, spec)?;
    Ok(match options.posterior {
        Some(p) => p.apply(machine, study)?,
        None => study,
    })
}

/// The study of `machine`'s reliability section with `options` (`file`
/// names the machine file in messages): [`check`], then the derivation
/// (`chain_core::compile`), then [`build`]; returns the compiled model with
/// it.
pub fn study(
    machine: &Machine,
    file: &str,
    options: &StudyOptions<'_>,
) -> Result<(Study, CompiledModel), StudyError> {
    let checked = check(machine, file, options)?;
    let model = chain_core::compile(machine);
    let study = build(machine, &model, checked, options)?;
    Ok((study, model))
}

/// The reliability algorithm of a study command: its method, samples,
/// seed and target coefficient of variation (the CLI's `--method`,
/// `--samples`, `--seed`, `--cov`; Python's keywords of the same names).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AlgorithmOptions {
    /// The method.
    pub method: Method,
    /// Samples per case (for subset simulation per level); `None`: the
    /// method's default ([`samples`]).
    pub samples: Option<u64>,
    /// Seed of the random streams.
    pub seed: u64,
    /// A target coefficient of variation in (0, 1]; `samples` is then the
    /// budget.
    pub cov: Option<f64>,
}

impl Default for AlgorithmOptions {
    /// FORM, the CLI's defaults.
    fn default() -> AlgorithmOptions {
        AlgorithmOptions {
            method: Method::Form,
            samples: None,
            seed: 0,
            cov: None,
        }
    }
}

/// An option refused before any model is built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("invalid value for '--{option}': {message}")]
pub struct OptionError {
    /// The option (the CLI's long name without `--`, Python's keyword).
    pub option: &'static str,
    /// Why.
    pub message: String,
    /// The library's refusal it words, whose code it keeps (`None`: a
    /// rule of this layer, `chain::cli::invalid_option`).
    pub cause: Option<Box<ReliabilityError>>,
}

impl OptionError {
    /// A rule of this layer about `option`.
    pub fn new(option: &'static str, message: impl Into<String>) -> OptionError {
        OptionError {
            option,
            message: message.into(),
            cause: None,
        }
    }

    /// The library's refusal `e` of the value of `option`, in its words
    /// (a sampler's settings without their `invalid sampler settings: `).
    pub fn of(option: &'static str, e: ReliabilityError) -> OptionError {
        let message = match &e {
            ReliabilityError::InvalidSampler(m) => m.clone(),
            e => e.to_string(),
        };
        OptionError {
            option,
            message,
            cause: Some(Box::new(e)),
        }
    }
}

impl Worded for OptionError {
    fn own_code(&self) -> Option<&'static str> {
        self.cause.is_none().then_some("chain::cli::invalid_option")
    }

    #[cfg(feature = "cli")]
    fn inner(&self) -> Option<&dyn miette::Diagnostic> {
        self.cause.as_deref().map(|e| e as &dyn miette::Diagnostic)
    }
}

diagnostic!(OptionError);

/// The samples per case of `method` when `given` is `None` (spec
/// reliability-v2 §2): is 10⁴, mc 10⁵; with a target coefficient of
/// variation (`to_cov`) the budget, mc 10⁷, is and directional 10⁶;
/// subset 10³ per level, directional 10⁴; 0 for FORM and SORM, which draw none.
pub fn samples(method: Method, given: Option<u64>, to_cov: bool) -> u64 {
    match (method, to_cov) {
        (Method::Form | Method::Sorm, _) => 0,
        (Method::ImportanceSampling, false) => given.unwrap_or(10_000),
        (Method::MonteCarlo, false) => given.unwrap_or(100_000),
        (Method::ImportanceSampling, true) => given.unwrap_or(1_000_000),
        (Method::MonteCarlo, true) => given.unwrap_or(10_000_000),
        (Method::Subset, _) => given.unwrap_or(1_000),
        (Method::Directional, false) => given.unwrap_or(10_000),
        (Method::Directional, true) => given.unwrap_or(1_000_000),
    }
}

/// Subset simulation's sample budget with a target coefficient of
/// variation, in levels of its samples per level.
pub const SUBSET_BUDGET_LEVELS: u64 = 1000;

impl AlgorithmOptions {
    /// Every check of the options, none needing a model, so that the CLI
    /// and Python refuse them before any file is read: the target
    /// coefficient of variation in (0, 1] and only for a method that draws
    /// samples, then the algorithm's own settings ([`Algorithm::check`]:
    /// the sample count, subset simulation's samples per level).
    pub fn check(&self) -> Result<(), OptionError> {
        if let Some(c) = self.cov {
            reliability::sampler::check_cov(c).map_err(|e| OptionError::of("cov", e))?;
            if let Method::Form | Method::Sorm = self.method {
                return Err(OptionError::new(
                    "cov",
                    format!(
                        "{} draws no samples; a target coefficient of variation needs method mc, is, subset or directional",
                        self.method.name().to_uppercase()
                    ),
                ));
            }
        }
        self.algorithm()
            .check()
            .map_err(|e| OptionError::of("samples", e))
    }

    /// The library's algorithm for these options: the method with its
    /// samples ([`samples`]: given, or the method's default) and seed, the
    /// target coefficient of variation (the samples then its budget; for
    /// subset simulation the samples per level, [`SUBSET_BUDGET_LEVELS`]
    /// levels' worth at most). FORM and SORM take no target ([`check`]
    /// refuses one).
    ///
    /// [`check`]: AlgorithmOptions::check
    pub fn algorithm(&self) -> Algorithm {
        let (seed, cov) = (self.seed, self.cov);
        let samples = samples(self.method, self.samples, cov.is_some());
        match self.method {
            Method::MonteCarlo => Algorithm::MonteCarlo(MonteCarlo { samples, seed, cov }),
            Method::ImportanceSampling => Algorithm::ImportanceSampling(ImportanceSampling {
                samples,
                seed,
                form: Form::default(),
                cov,
            }),
            Method::Subset => {
                let mut s = SubsetSimulation::new(samples, seed);
                s.cov = cov;
                s.budget = samples.saturating_mul(SUBSET_BUDGET_LEVELS);
                Algorithm::Subset(s)
            }
            Method::Directional => {
                Algorithm::Directional(DirectionalSimulation { samples, seed, cov })
            }
            Method::Form => Algorithm::Form(Form::default()),
            Method::Sorm => Algorithm::Sorm(reliability::sorm::Sorm::default()),
        }
    }
}

/// `--system`: a system target besides the components.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SystemChoice {
    /// Every toleranced component at once.
    Series,
    /// `|p| ≤ tolerance` (`--system-tolerance`; by default the smallest
    /// position tolerance of the reliability section).
    Volumetric(Option<f64>),
}

/// `--system` without its tolerance.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SystemKind {
    /// Every toleranced component at once.
    Series,
    /// `|p| ≤ tolerance`.
    Volumetric,
}

impl SystemChoice {
    /// `--system` and `--system-tolerance` as one choice: the tolerance is
    /// the volumetric target's allowable error, a positive length; given
    /// with `series` or without a system it is refused, not dropped.
    pub fn new(
        kind: Option<SystemKind>,
        tolerance: Option<f64>,
    ) -> Result<Option<SystemChoice>, OptionError> {
        let refuse = |message: String| OptionError::new("system-tolerance", message);
        match (kind, tolerance) {
            (None, None) => Ok(None),
            (None, Some(_)) => Err(refuse(
                "the allowable error of --system volumetric: give --system volumetric too".into(),
            )),
            (Some(SystemKind::Series), Some(_)) => Err(refuse(
                "the allowable error of --system volumetric, not series".into(),
            )),
            (Some(SystemKind::Series), None) => Ok(Some(SystemChoice::Series)),
            (Some(SystemKind::Volumetric), Some(t)) if !(t.is_finite() && t > 0.0) => Err(refuse(
                format!("`{t}` (a positive allowable volumetric error, mm)"),
            )),
            (Some(SystemKind::Volumetric), t) => Ok(Some(SystemChoice::Volumetric(t))),
        }
    }
}

/// The library's system target of `choice` on `machine` (a volumetric
/// target without its tolerance takes the smallest position tolerance of
/// the reliability section).
pub fn system(
    machine: &Machine,
    choice: Option<SystemChoice>,
) -> Result<Option<System>, ReliabilityError> {
    Ok(match choice {
        None => None,
        Some(SystemChoice::Series) => Some(System::Series),
        Some(SystemChoice::Volumetric(tolerance)) => Some(volumetric(machine, tolerance)?),
    })
}

/// The volumetric target `√(px² + py² + pz²) ≤ tolerance`, by default the
/// smallest position tolerance of the reliability section.
fn volumetric(machine: &Machine, tolerance: Option<f64>) -> Result<System, ReliabilityError> {
    let tolerance = match tolerance {
        Some(t) => t,
        None => machine
            .reliability
            .as_ref()
            .ok_or(ReliabilityError::NoReliabilitySection)?
            .tolerance
            .iter()
            .filter(|(c, _)| c.index() < 3)
            .map(|(_, t)| *t)
            .fold(f64::INFINITY, f64::min),
    };
    Ok(System::Volumetric { tolerance })
}

/// `note: FORM is a first-order approximation here (...)` when FORM is
/// not exact for the study (a two-sided component, non-normal inputs).
pub fn form_limits_note(study: &Study) -> Option<String> {
    let limits = study.form_limits();
    (!limits.is_empty()).then(|| {
        let why = (limits.iter())
            .map(|l| l.reason())
            .collect::<Vec<_>>()
            .join(", ");
        format!("note: FORM is a first-order approximation here ({why}); `--method is` corrects it")
    })
}

/// The warnings on a run's cases that did not converge (their
/// [`CaseTally`]): the samplers' (the `--cov` target not reached within the
/// budget, subset simulation out of levels), then FORM's (the iteration
/// limit).
pub fn unconverged_warnings(
    tally: &CaseTally,
    method: Method,
    variables: &[String],
) -> Vec<String> {
    let at = |point: &[f64]| {
        (variables.iter().zip(point))
            .map(|(v, x)| format!("{v} = {x}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let mut out = Vec::new();
    if let Some(first) = &tally.first_sampler_unconverged {
        let why = first.stopping.map_or("", |s| match s.stopped_by {
            reliability::Stop::Levels => "subset simulation ran out of levels",
            _ => "the sample budget ran out before the target coefficient of variation",
        });
        out.push(format!(
            "warning: the {} did not converge on {} of {} cases (first: {} at {}: {why}); their values are not converged estimates (listed under the table, `converged: false` in JSON and CSV)",
            method.title(),
            tally.sampler_unconverged,
            tally.cases,
            first.target,
            at(&first.point)
        ));
    }
    if let Some(first) = &tally.first_form_unconverged {
        out.push(format!(
            "warning: FORM did not converge on {} of {} cases (first: {} at {}); their reliabilities are the last iterates' (listed under the table, `converged: false` in JSON and CSV)",
            tally.form_unconverged(),
            tally.cases,
            first.target,
            at(&first.point)
        ));
    }
    out
}

/// A [`ReliabilityError`] worded against the machine file it concerns.
#[derive(Debug, Clone, PartialEq)]
pub struct Described<'e> {
    /// The message, starting with the file (and `:line:column` when located).
    pub message: String,
    /// Where in the file, when the error is located.
    pub origin: Option<&'e Origin>,
    /// The label of the location (empty when not located).
    pub label: &'static str,
    /// How to fix it (empty when there is nothing to add).
    pub help: String,
}

/// The one wording of a reliability error against `file` (the machine file's
/// name), shared by the CLI's diagnostics and Python's exceptions: the
/// options that supply what the file lacks (`--param`, `--grid`) and the
/// allocation a grid is too large for (`--strategy`, `--target`) named as the
/// CLI spells them.
pub fn describe<'e>(err: &'e ReliabilityError, file: &str) -> Described<'e> {
    let (message, origin, label, help): (String, Option<&Origin>, &str, String) = match err {
        ReliabilityError::MissingStatistic { name, origin } => (
            format!(
                "{file}{}: missing key `statistics.{name}`: error parameter `{name}` has no statistics entry",
                at(origin)
            ),
            Some(origin),
            "used here",
            format!(
                "every error needs a distribution for reliability, e.g.\nstatistics:\n  {name}: {{dist: normal, mean: 0, std: 0.01}}"
            ),
        ),
        ReliabilityError::NoReliabilitySection => (
            format!("{file}: missing key `reliability`: the machine has no reliability section"),
            None,
            "",
            "add, e.g.\nreliability:\n  tolerance: {px: 0.03, py: 0.03, pz: 0.03}\n  sided: upper\n  grid: {x: [0, 500, 1000]}"
                .to_string(),
        ),
        ReliabilityError::SymbolicParameter { name, origin } => (
            format!(
                "{file}{}: parameter `{name}` is symbolic (null) and has no value",
                at(origin)
            ),
            Some(origin),
            "declared without a value",
            format!("give it one on the command line: --param {name}=VALUE"),
        ),
        ReliabilityError::MissingCoordinate(v) => (
            format!("{file}: the reliability grid has no values for axis variable `{v}` (key `reliability.grid.{v}`)"),
            None,
            "",
            format!("add `{v}: [...]` to reliability.grid, or pass --grid {v}=VALUE"),
        ),
        ReliabilityError::GridTooLarge {
            points,
            limit,
            allocation,
            origin,
        } => (
            format!(
                "{file}{}: key `reliability.grid`: the grid has {points} points; {allocation} ({}) runs on at most {limit} ({})",
                at(origin),
                match allocation {
                    GridUse::Optimal => "--strategy optimal",
                    GridUse::Paper => "--strategy paper",
                    GridUse::Acceptance => "--target acceptance",
                },
                allocation.why()
            ),
            Some(origin),
            "the grid of this section",
            format!(
                "allocate on a coarser grid (a copy of the file with at most {limit} grid points), then check the allocated standard deviations on this grid: put them in `statistics` and run `chain reliability`"
            ),
        ),
        other => (format!("{file}: {other}"), None, "", String::new()),
    };
    Described {
        message,
        origin,
        label,
        help,
    }
}

fn at(origin: &Origin) -> String {
    if origin.line > 0 {
        format!(":{}:{}", origin.line, origin.column)
    } else {
        String::new()
    }
}
