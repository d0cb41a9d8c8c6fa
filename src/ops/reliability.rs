//! `chain reliability` as a request and a document (spec reliability-v2;
//! docs/reliability.md): the machining-accuracy reliability of every
//! toleranced component (and a system target) over the grid, from the
//! machine's statistics or a calibration's posterior, with the
//! whole-machine acceptance probability when asked. The CLI and
//! `Machine.reliability` both [`prepare`] the study, [`Prepared::run`] it
//! and print or return the same [`ReliabilityRun`], whose JSON is the
//! [`ReliabilityDocument`] (with its [`AcceptanceDocument`]).

use std::path::Path;

use chain_core::model::{Distribution, Sided};
use chain_core::named::NameMap;
use chain_core::values::Approach;
use chain_core::{CompiledModel, Machine};
use reliability::acceptance::{AcceptanceResult, AcceptanceSubset};
use reliability::conditional::{self, Quadrature};
use reliability::{
    Acceptance, Calls, CaseResult, CaseTally, FormCase, Method, Posterior, Progress, Rectangles,
    ReliabilityError, SormCase, Stopping, Study, StudyResult, SubsetLevel, Target,
};
use serde::{Serialize, Serializer};

use super::resolve::ResolveError;
use super::study::{self, AlgorithmOptions, OptionError, StudyError, StudyOptions, SystemChoice};

/// The default absolute error of the acceptance probability.
pub const ACCEPTANCE_TOLERANCE: f64 = 1e-3;

/// The request of `chain reliability`.
#[derive(Debug, Clone, Copy)]
pub struct ReliabilityRequest<'a> {
    /// `--param NAME=VALUE`.
    pub params: &'a [(String, f64)],
    /// `--grid VAR=...`: replaces (or adds) an axis of `reliability.grid`.
    pub grid: &'a [(String, Vec<f64>)],
    /// `--sided`: overrides the file's.
    pub sided: Option<Sided>,
    /// `--system`.
    pub system: Option<SystemChoice>,
    /// `--method`, `--samples`, `--seed`, `--cov`.
    pub algorithm: AlgorithmOptions,
    /// `--values`: a values file with a calibration's posterior or a built
    /// machine's measured tables.
    pub values: Option<&'a Path>,
    /// `--approach`: which direction of the values' tables to read.
    pub approach: &'a [(Option<String>, Approach)],
    /// `--acceptance` (also when the file's `reliability.acceptance` asks).
    pub acceptance: bool,
    /// `--acceptance-tolerance`: the acceptance probability's absolute
    /// error (three standard errors), in (0, 1).
    pub acceptance_tolerance: f64,
    /// `--temperature NAME=VALUE`: the thermal state (docs/thermal.md).
    pub temperatures: &'a [(String, f64)],
}

impl Default for ReliabilityRequest<'_> {
    /// FORM over the file's grid, the CLI's defaults.
    fn default() -> Self {
        ReliabilityRequest {
            params: &[],
            grid: &[],
            sided: None,
            system: None,
            algorithm: AlgorithmOptions::default(),
            values: None,
            approach: &[],
            acceptance: false,
            acceptance_tolerance: ACCEPTANCE_TOLERANCE,
            temperatures: &[],
        }
    }
}

/// Why `chain reliability` cannot run.
#[derive(Debug, thiserror::Error)]
pub enum ReliabilityOpsError {
    /// An option refused before any model is built.
    #[error(transparent)]
    Option(#[from] OptionError),
    /// The study (the machine's sections, the options against it, the
    /// posterior).
    #[error(transparent)]
    Study(Box<StudyError>),
    /// The run (located in the machine file by [`study::describe`]).
    #[error(transparent)]
    Reliability(#[from] ReliabilityError),
}

impl From<StudyError> for ReliabilityOpsError {
    fn from(e: StudyError) -> ReliabilityOpsError {
        ReliabilityOpsError::Study(Box::new(e))
    }
}

/// A study ready to run, with the posterior its inputs came from.
#[derive(Debug)]
pub struct Prepared {
    /// The machine's name.
    pub machine: String,
    /// The study.
    pub study: Study,
    /// The posterior of `--values`.
    pub posterior: Option<Posterior>,
    /// The compiled model the study evaluates (kept for the plots'
    /// sensitivities).
    pub model: CompiledModel,
    algorithm: AlgorithmOptions,
    acceptance: Option<(f64, u64)>,
    /// The thermal state: the fixed temperatures and the random ones with
    /// the studies at the quadrature's nodes.
    thermal: Option<Thermal>,
}

/// The temperatures of a study of a machine with sensors
/// (`docs/thermal.md`): the fixed state and, for a sensor with a
/// `statistics` entry that `--temperature` does not fix, what the studies at
/// its temperatures are built from ([`reliability::conditional`]).
#[derive(Debug)]
struct Thermal {
    /// Every sensor not random, °C.
    fixed: Vec<(String, f64)>,
    /// The random one, its distribution and marginal, and what its studies
    /// are built from.
    random: Option<RandomSensor>,
}

/// A random temperature and what a study at one of its values is built
/// from.
#[derive(Debug)]
struct RandomSensor {
    name: String,
    distribution: Distribution,
    marginal: reliability::Marginal,
    machine: Machine,
    checked: study::Checked,
}

impl RandomSensor {
    /// The study at `fixed` and this sensor at `t` °C.
    fn study_at(
        &self,
        fixed: &[(String, f64)],
        t: f64,
        model: &CompiledModel,
        posterior: Option<&Posterior>,
    ) -> Result<Study, ReliabilityError> {
        let mut at = fixed.to_vec();
        at.push((self.name.clone(), t));
        let options = StudyOptions {
            posterior,
            temperatures: &at,
            ..StudyOptions::default()
        };
        let built = (self.checked.clone().at_temperatures(&self.machine, &at))
            .and_then(|c| study::build(&self.machine, model, c, &options));
        built.map_err(|e| match e {
            StudyError::Reliability(e) => e,
            other => {
                ReliabilityError::InvalidDistribution(format!("`{}` at {t} °C: {other}", self.name))
            }
        })
    }
}

/// A sensor's random temperature in the document.
#[derive(Debug, Clone, Serialize)]
pub struct RandomTemperature {
    /// The sensor.
    pub sensor: String,
    /// Its distribution (°C).
    #[serde(flatten)]
    pub distribution: Distribution,
}

/// The thermal state of a study (a machine with sensors): the JSON's
/// `temperatures`.
#[derive(Debug, Clone, Serialize)]
pub struct TemperaturesDocument {
    /// Every sensor that is not random, °C.
    pub fixed: NameMap<String, f64>,
    /// The random ones (`statistics` entries of sensors), integrated over.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub random: Vec<RandomTemperature>,
    /// The rule that integrated over them and its error estimate.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub quadrature: Option<Quadrature>,
}

/// The thermal state of `machine` under `temperatures` and its random
/// temperature, if any.
fn thermal(
    machine: &Machine,
    request: &ReliabilityRequest<'_>,
    checked: &study::Checked,
    wanted_acceptance: bool,
) -> Result<Option<Thermal>, ReliabilityOpsError> {
    if machine.sensors.is_empty() {
        return Ok(None);
    }
    let state = machine
        .temperatures(request.temperatures)
        .map_err(|e| StudyError::from(ResolveError::Temperature(e)))?;
    let given = |name: &str| request.temperatures.iter().any(|(n, _)| n == name);
    let random: Vec<(String, Distribution)> = (machine.sensor_statistics.iter())
        .map(|s| (machine.sensors[s.sensor].name.clone(), s.distribution))
        .filter(|(n, _)| !given(n))
        .collect();
    let fixed: Vec<(String, f64)> = (machine.sensors.iter().zip(&state))
        .filter(|(s, _)| !random.iter().any(|(n, _)| *n == s.name))
        .map(|(s, t)| (s.name.clone(), *t))
        .collect();
    let names = || {
        random
            .iter()
            .map(|(n, _)| n.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    };
    let random = match random.as_slice() {
        [] => None,
        [(name, distribution)] => {
            if wanted_acceptance {
                return Err(OptionError::new(
                    "acceptance",
                    format!("the acceptance probability is not integrated over the random temperature of {}: fix it with --temperature", names()),
                )
                .into());
            }
            Some(RandomSensor {
                name: name.clone(),
                distribution: *distribution,
                marginal: reliability::machine::marginal(distribution)?,
                machine: machine.clone(),
                checked: checked.clone(),
            })
        }
        _ => {
            return Err(OptionError::new(
                "temperature",
                format!(
                    "{} sensors have a distribution ({}); one is integrated over: fix the others with --temperature NAME=VALUE",
                    random.len(),
                    names()
                ),
            )
            .into())
        }
    };
    Ok(Some(Thermal { fixed, random }))
}

/// Checks the options and builds the study of `machine` (`file` names it).
pub fn prepare(
    machine: &Machine,
    file: &str,
    request: &ReliabilityRequest<'_>,
) -> Result<Prepared, ReliabilityOpsError> {
    request.algorithm.check()?;
    study::check_approach(request.values, request.approach)?;
    let t = request.acceptance_tolerance;
    if !(t.is_finite() && t > 0.0 && t < 1.0) {
        return Err(OptionError::new(
            "acceptance-tolerance",
            format!("{t} (an absolute error in (0, 1))"),
        )
        .into());
    }
    let system = study::system(machine, request.system)?;
    let posterior = match request.values {
        Some(path) => Some(study::read_posterior(machine, path, request.approach)?),
        None => None,
    };
    let options = StudyOptions {
        params: request.params,
        grid: request.grid,
        sided: request.sided,
        system,
        posterior: posterior.as_ref(),
        temperatures: request.temperatures,
    };
    // `study::study`'s steps, the checked study kept for the studies at a
    // random temperature's values.
    let checked = study::check(machine, file, &options)?;
    let model = chain_core::compile(machine);
    let study = study::build(machine, &model, checked.clone(), &options)?;
    let wanted = request.acceptance || (machine.reliability.as_ref()).is_some_and(|r| r.acceptance);
    let thermal = thermal(machine, request, &checked, wanted)?;
    Ok(Prepared {
        machine: machine.name.clone(),
        study,
        posterior,
        model,
        algorithm: request.algorithm,
        acceptance: wanted.then_some((t, request.algorithm.seed)),
        thermal,
    })
}

impl Prepared {
    /// The cases the algorithm runs: targets × points.
    pub fn cases(&self) -> u64 {
        (self.study.targets().len() * self.study.points().len()) as u64
    }

    /// The samples every case draws when the count is known in advance
    /// (`None`: FORM and SORM draw none; subset simulation and a `--cov`
    /// target find theirs as they run).
    pub fn planned_samples(&self) -> Option<u64> {
        let a = &self.algorithm;
        let fixed =
            !matches!(a.method, Method::Form | Method::Sorm | Method::Subset) && a.cov.is_none();
        fixed.then(|| study::samples(a.method, a.samples, false).saturating_mul(self.cases()))
    }

    /// Whether the algorithm draws samples (all but FORM and SORM).
    pub fn samples_anything(&self) -> bool {
        !matches!(self.algorithm.method, Method::Form | Method::Sorm)
    }

    /// What the run's progress counts: the samples (with their total when
    /// it is known in advance, [`Prepared::planned_samples`]), or for FORM
    /// and SORM, which draw none, the cases.
    pub fn progress_plan(&self) -> ProgressPlan {
        if self.samples_anything() {
            ProgressPlan {
                total: self.planned_samples(),
                verb: "sampling",
                unit: "samples",
            }
        } else {
            ProgressPlan {
                total: Some(self.cases()),
                verb: self.algorithm.method.title(),
                unit: "cases",
            }
        }
    }

    /// Runs the study (and the acceptance probability when asked),
    /// reporting the samples drawn to `progress`.
    pub fn run(self, progress: &dyn Progress) -> Result<ReliabilityRun, ReliabilityError> {
        let algorithm = self.algorithm.algorithm();
        let mut quadrature = None;
        let mut shown = self.study;
        let result = match self
            .thermal
            .as_ref()
            .and_then(|t| t.random.as_ref().map(|r| (t, r)))
        {
            Some((t, r)) => {
                let posterior = self.posterior.as_ref();
                let (mixed, account) =
                    conditional::integrate(&shown, &r.marginal, |temperature| {
                        r.study_at(&t.fixed, temperature, &self.model, posterior)?
                            .run(&algorithm, &())
                    })?;
                quadrature = Some(account);
                // The tables and plots read the study at the median
                // temperature (at the reference, a thermal term is zero).
                shown = r.study_at(&t.fixed, r.marginal.quantile(0.5), &self.model, posterior)?;
                mixed
            }
            None => shown.run(&algorithm, progress)?,
        };
        let temperatures = self.thermal.as_ref().map(|t| TemperaturesDocument {
            fixed: NameMap(t.fixed.clone()),
            random: (t.random.iter())
                .map(|r| RandomTemperature {
                    sensor: r.name.clone(),
                    distribution: r.distribution,
                })
                .collect(),
            quadrature: quadrature.clone(),
        });
        let mut notes = Vec::new();
        if let Some(q) = quadrature.as_ref().filter(|q| !q.converged) {
            notes.push(format!(
                "warning: the integral over the random temperature stopped at {} intervals ({} studies) with an estimated relative error of {:.2e} (> {:.0e})",
                q.intervals, q.studies, q.max_relative, conditional::RELATIVE_TOLERANCE
            ));
        }
        if self.algorithm.method == Method::Form {
            notes.extend(study::form_limits_note(&shown));
        }
        notes.extend(study::unconverged_warnings(
            &CaseTally::of(&result.cases),
            result.method,
            shown.variables(),
        ));
        let acceptance = match self.acceptance {
            Some((tolerance, seed)) => {
                let a = acceptance(&shown, tolerance, seed)?;
                if !a.converged {
                    notes.push(format!(
                        "warning: the acceptance probability did not converge: 3 standard errors = {:.2e} > {tolerance:.2e} after {} samples",
                        3.0 * a.std_error,
                        a.samples
                    ));
                }
                Some(a)
            }
            None => None,
        };
        Ok(ReliabilityRun {
            machine: self.machine,
            study: shown,
            model: self.model,
            result,
            posterior: self.posterior,
            acceptance,
            temperatures,
            notes,
        })
    }
}

/// What a run's progress counts ([`Prepared::progress_plan`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ProgressPlan {
    /// The total, when it is known in advance.
    pub total: Option<u64>,
    /// What is being done (`sampling`, `FORM`).
    pub verb: &'static str,
    /// What is counted (`samples`, `cases`).
    pub unit: &'static str,
}

/// The document of `chain reliability`: the study, its result, the
/// posterior and the acceptance probability; serialised as the spec's JSON
/// ([`ReliabilityDocument`]).
#[derive(Debug)]
pub struct ReliabilityRun {
    /// The machine's name.
    pub machine: String,
    /// The study that ran.
    pub study: Study,
    /// The compiled model the study evaluates.
    pub model: CompiledModel,
    /// Every case's result and the summaries.
    pub result: StudyResult,
    /// The posterior of `--values`.
    pub posterior: Option<Posterior>,
    /// The whole-machine acceptance probability, when asked.
    pub acceptance: Option<AcceptanceResult>,
    /// The thermal state (a machine with sensors).
    pub temperatures: Option<TemperaturesDocument>,
    /// Notes and warnings on the run (FORM's limits, cases that did not
    /// converge, an acceptance probability short of its tolerance), each a
    /// line `note: …` or `warning: …`; not part of the JSON.
    pub notes: Vec<String>,
}

impl ReliabilityRun {
    /// The spec's document of the run.
    pub fn document(&self) -> ReliabilityDocument<'_> {
        let mut doc = ReliabilityDocument::new(&self.machine, &self.study, &self.result);
        doc.posterior = self.posterior.as_ref();
        doc.acceptance = self.acceptance.as_ref().map(AcceptanceDocument::of);
        doc.temperatures = self.temperatures.as_ref();
        doc
    }
}

impl Serialize for ReliabilityRun {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        self.document().serialize(serializer)
    }
}

/// Runs `chain reliability` of `machine` (`file` names it).
pub fn run(
    machine: &Machine,
    file: &str,
    request: &ReliabilityRequest<'_>,
    progress: &dyn Progress,
) -> Result<ReliabilityRun, ReliabilityOpsError> {
    Ok(prepare(machine, file, request)?.run(progress)?)
}

/// The acceptance probability of every point × toleranced component of
/// `study` at once, to an absolute error `tolerance` (three standard
/// errors), with its sensitivities ([`Acceptance`] over
/// [`Rectangles::from_study`]).
fn acceptance(
    study: &Study,
    tolerance: f64,
    seed: u64,
) -> Result<AcceptanceResult, ReliabilityError> {
    let system = Rectangles::from_study(study)?;
    Acceptance {
        tolerance,
        seed,
        ..Acceptance::default()
    }
    .run(&system)
}

/// The document of a grid study (the spec's `reliability` JSON contract).
#[derive(Debug, Serialize)]
pub struct ReliabilityDocument<'a> {
    /// The machine's name.
    pub machine: &'a str,
    /// The algorithm.
    pub method: Method,
    /// One- or two-sided tolerances.
    pub sided: Sided,
    /// Every case, target-major (each case's document formed as it is
    /// written).
    pub results: CaseDocuments<'a>,
    /// Each target's summary over the grid.
    pub summary: NameMap<Target, SummaryDocument>,
    /// The requirement and whether every target meets it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub requirement: Option<RequirementDocument>,
    /// The posterior the inputs came from (a calibration's values file), when given.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub posterior: Option<&'a Posterior>,
    /// The whole-machine acceptance probability (`--acceptance`), when run.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub acceptance: Option<AcceptanceDocument<'a>>,
    /// The thermal state of a machine with sensors (fixed and random
    /// temperatures, the rule over the random ones).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub temperatures: Option<&'a TemperaturesDocument>,
}

/// One case (target at a grid point) of a [`ReliabilityDocument`].
#[derive(Debug, Serialize)]
pub struct CaseDocument<'a> {
    /// The target.
    pub component: Target,
    /// The grid point: the grid's axes in file order.
    pub point: NameMap<&'a str, f64>,
    /// The reliability `1 − pf`.
    pub reliability: f64,
    /// The failure probability.
    pub pf: f64,
    /// The reliability index (infinite for a component the errors do not reach: JSON `null`).
    pub beta: f64,
    /// The standard error of a sampled `pf`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub std_error: Option<f64>,
    /// The samples drawn.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub samples: Option<u64>,
    /// The coefficient of variation of a sampled `pf`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cov: Option<f64>,
    /// FORM's account (termination, iterations, exactness), when FORM ran.
    #[serde(flatten)]
    pub form: Option<FormCase>,
    /// The sampler's convergence where FORM's does not occupy the key
    /// (subset, directional, mc with `--cov`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub converged: Option<bool>,
    /// Limit-state calls.
    pub calls: Calls,
    /// How the sampler stopped (subset, directional, or `--cov`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sampling: Option<Stopping>,
    /// Subset simulation's levels.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub levels: Option<&'a [SubsetLevel]>,
    /// SORM's three formulas and curvatures (`--method sorm`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sorm: Option<&'a SormCase>,
}

/// The cases of a [`ReliabilityDocument`]: serialised as the list of their
/// [`CaseDocument`]s, each formed when it is written, so that a document of
/// a million cases is not a second copy of them.
#[derive(Debug)]
pub struct CaseDocuments<'a> {
    /// The grid's axes in file order, with their index in the model's
    /// variables.
    axes: Vec<(&'a str, usize)>,
    /// The cases, target-major.
    cases: &'a [CaseResult],
}

impl<'a> CaseDocuments<'a> {
    /// The number of cases.
    pub fn len(&self) -> usize {
        self.cases.len()
    }

    /// True when there is no case.
    pub fn is_empty(&self) -> bool {
        self.cases.is_empty()
    }

    /// Each case's document, target-major.
    pub fn iter(&self) -> impl Iterator<Item = CaseDocument<'a>> + '_ {
        self.cases.iter().map(|c| CaseDocument {
            component: c.target,
            point: NameMap(self.axes.iter().map(|&(n, i)| (n, c.point[i])).collect()),
            reliability: c.reliability,
            pf: c.pf,
            beta: c.beta,
            std_error: c.std_error,
            samples: c.samples,
            cov: c.cov,
            form: c.form,
            converged: match (&c.form, &c.stopping) {
                (None, Some(st)) => Some(st.converged),
                _ => None,
            },
            calls: c.calls,
            sampling: c.stopping,
            levels: c.levels.as_deref(),
            sorm: c.sorm.as_deref(),
        })
    }
}

impl Serialize for CaseDocuments<'_> {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_seq(self.iter())
    }
}

/// One target's summary of a [`ReliabilityDocument`].
#[derive(Debug, Serialize)]
pub struct SummaryDocument {
    /// Mean reliability over the grid.
    pub mean: f64,
    /// Smallest reliability over the grid.
    pub min: f64,
    /// Largest reliability over the grid.
    pub max: f64,
    /// Whether the target meets the requirement (when there is one).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub met: Option<bool>,
}

/// The requirement of a study and whether every target meets it.
#[derive(Debug, Serialize)]
pub struct RequirementDocument {
    /// The smallest reliability required at any point.
    pub min: f64,
    /// The mean reliability required over the grid.
    pub mean: f64,
    /// Whether every target meets both.
    pub met: bool,
}

impl RequirementDocument {
    /// The requirement of a study result, if it has one.
    pub fn of(r: &StudyResult) -> Option<RequirementDocument> {
        r.requirement.map(|req| RequirementDocument {
            min: req.min,
            mean: req.mean,
            met: r.requirement_met(),
        })
    }
}

impl<'a> ReliabilityDocument<'a> {
    /// The document of a study's result (no posterior: set
    /// [`ReliabilityDocument::posterior`] when the inputs came from one).
    pub fn new(machine: &'a str, study: &'a Study, r: &'a StudyResult) -> Self {
        let ax: Vec<(&'a str, usize)> = study
            .spec()
            .grid
            .axes
            .iter()
            .filter_map(|(n, _)| {
                let i = study.variables().iter().position(|v| v == n)?;
                Some((n.as_str(), i))
            })
            .collect();
        let results = CaseDocuments {
            axes: ax,
            cases: &r.cases,
        };
        let summary = NameMap(
            r.summaries
                .iter()
                .map(|s| {
                    let doc = SummaryDocument {
                        mean: s.mean,
                        min: s.min,
                        max: s.max,
                        met: s.met,
                    };
                    (s.target, doc)
                })
                .collect(),
        );
        ReliabilityDocument {
            machine,
            method: r.method,
            sided: study.spec().sided,
            results,
            summary,
            requirement: RequirementDocument::of(r),
            posterior: None,
            acceptance: None,
            temperatures: None,
        }
    }
}

/// The `acceptance` object of a [`ReliabilityDocument`] (spec §4:
/// probability, std_error, method, sensitivity; then samples, converged,
/// tolerance, constraints, rank).
#[derive(Debug, Serialize)]
pub struct AcceptanceDocument<'a> {
    /// P(every toleranced component within tolerance at every point).
    pub probability: f64,
    /// Its standard error.
    pub std_error: f64,
    /// `genz-bretz-qmc` or `monte-carlo`.
    pub method: &'static str,
    /// ∂P/∂σ and ∂P/∂μ of every error parameter.
    pub sensitivity: Vec<AcceptanceSensitivityDocument<'a>>,
    /// Integrand evaluations.
    pub samples: u64,
    /// Whether three standard errors are below the tolerance.
    pub converged: bool,
    /// The absolute error asked for.
    pub tolerance: Option<f64>,
    /// Constraints (points × toleranced components).
    pub constraints: usize,
    /// The rank of the constraints' rows.
    pub rank: usize,
    /// Levels, CoV and pilot of subset simulation (method `subset` only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub subset: Option<&'a AcceptanceSubset>,
}

/// One error parameter of [`AcceptanceDocument::sensitivity`].
#[derive(Debug, Serialize)]
pub struct AcceptanceSensitivityDocument<'a> {
    /// The error parameter.
    pub error: &'a str,
    /// ∂P/∂σ.
    pub dr_dstd: f64,
    /// ∂P/∂μ.
    pub dr_dmean: f64,
    /// The standard error of ∂P/∂σ.
    pub dr_dstd_std_error: f64,
    /// The standard error of ∂P/∂μ.
    pub dr_dmean_std_error: f64,
}

impl<'a> AcceptanceDocument<'a> {
    /// The document of an acceptance result.
    pub fn of(a: &'a AcceptanceResult) -> AcceptanceDocument<'a> {
        AcceptanceDocument {
            probability: a.probability,
            std_error: a.std_error,
            method: a.method.name(),
            sensitivity: a
                .sensitivity
                .iter()
                .map(|s| AcceptanceSensitivityDocument {
                    error: &s.error,
                    dr_dstd: s.dr_dstd,
                    dr_dmean: s.dr_dmean,
                    dr_dstd_std_error: s.dr_dstd_std_error,
                    dr_dmean_std_error: s.dr_dmean_std_error,
                })
                .collect(),
            samples: a.samples,
            converged: a.converged,
            tolerance: a.tolerance,
            constraints: a.constraints,
            rank: a.rank,
            subset: a.subset.as_ref(),
        }
    }
}
