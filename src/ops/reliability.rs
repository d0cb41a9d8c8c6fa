//! `chain reliability` as a request and a document (spec reliability-v2;
//! docs/reliability.md): the machining-accuracy reliability of every
//! toleranced component (and a system target) over the grid, from the
//! machine's statistics or a calibration's posterior, with the
//! whole-machine acceptance probability when asked. The CLI and
//! `Machine.reliability` both [`prepare`] the study, [`Prepared::run`] it
//! and print or return the same [`ReliabilityRun`] (or the CLI writes
//! [`Prepared::output`], the study run a block of cases at a time as it is
//! written), whose JSON is the [`ReliabilityDocument`] (with its
//! [`AcceptanceDocument`]).

use std::cell::{Ref, RefCell};
use std::path::Path;

use chain_core::model::{Distribution, Sided};
use chain_core::named::NameMap;
use chain_core::values::Approach;
use chain_core::{CompiledModel, Machine};
use reliability::acceptance::{AcceptanceResult, AcceptanceSubset};
use reliability::conditional::{self, Quadrature};
use reliability::study::Algorithm;
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

/// The thermal state's document, with the rule that integrated over a
/// random temperature.
fn temperatures(
    thermal: Option<&Thermal>,
    quadrature: Option<Quadrature>,
) -> Option<TemperaturesDocument> {
    thermal.map(|t| TemperaturesDocument {
        fixed: NameMap(t.fixed.clone()),
        random: (t.random.iter())
            .map(|r| RandomTemperature {
                sensor: r.name.clone(),
                distribution: r.distribution,
            })
            .collect(),
        quadrature,
    })
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

    /// The output of the study run a block of cases at a time as it is
    /// written, each block dropped once written ([`ReliabilityOutput`]):
    /// `None` when the run needs every case at once (the acceptance
    /// probability, a random temperature's mixture).
    pub fn output<'a>(&'a self, progress: &'a dyn Progress) -> Option<ReliabilityOutput<'a>> {
        let random = self.thermal.as_ref().is_some_and(|t| t.random.is_some());
        if self.acceptance.is_some() || random {
            return None;
        }
        Some(ReliabilityOutput {
            machine: &self.machine,
            study: &self.study,
            method: self.algorithm.method,
            columns: CaseColumns::of(self.algorithm.method, self.algorithm.cov.is_some(), false),
            posterior: self.posterior.as_ref(),
            acceptance: None,
            temperatures: temperatures(self.thermal.as_ref(), None),
            cases: Cases::Streamed {
                algorithm: self.algorithm.algorithm(),
                progress,
            },
            done: RefCell::new(None),
            failed: RefCell::new(None),
        })
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
        let temperatures = temperatures(self.thermal.as_ref(), quadrature.clone());
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
        let columns = CaseColumns::of(
            self.algorithm.method,
            self.algorithm.cov.is_some(),
            acceptance.is_some(),
        );
        Ok(ReliabilityRun {
            columns,
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
    /// What the cases carry beyond FORM's account.
    pub columns: CaseColumns,
}

impl ReliabilityRun {
    /// The output of the run, its cases in memory.
    pub fn output(&self) -> ReliabilityOutput<'_> {
        ReliabilityOutput {
            machine: &self.machine,
            study: &self.study,
            method: self.result.method,
            columns: self.columns,
            posterior: self.posterior.as_ref(),
            acceptance: self.acceptance.as_ref(),
            temperatures: self.temperatures.clone(),
            cases: Cases::Kept(&self.result),
            done: RefCell::new(None),
            failed: RefCell::new(None),
        }
    }
}

impl Serialize for ReliabilityRun {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        self.output().serialize(serializer)
    }
}

/// What the cases of a run carry beyond FORM's account, known from the
/// algorithm before any case runs (the CSV's columns): a sampler's standard
/// error, CoV and samples; how it stopped (subset and directional
/// simulation, a `--cov` target); subset simulation's levels; SORM's
/// formulas.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CaseColumns {
    /// A sampler's `std_error`, `cov`, `samples` (or the acceptance row's).
    pub sampled: bool,
    /// How the sampler stopped.
    pub stopped: bool,
    /// Subset simulation's levels.
    pub leveled: bool,
    /// SORM's three formulas.
    pub sorm: bool,
}

impl CaseColumns {
    /// The columns of `method` (with a target CoV: `cov`; with the
    /// acceptance probability's row: `acceptance`).
    pub fn of(method: Method, cov: bool, acceptance: bool) -> CaseColumns {
        let sampler = !matches!(method, Method::Form | Method::Sorm);
        CaseColumns {
            sampled: sampler || acceptance,
            stopped: matches!(method, Method::Subset | Method::Directional) || (sampler && cov),
            leveled: method == Method::Subset,
            sorm: method == Method::Sorm,
        }
    }
}

/// The output of `chain reliability`, whatever its format: the cases a
/// block at a time ([`ReliabilityOutput::each_block`]; computed as they are
/// written when the study is streamed, [`Prepared::output`]), then what
/// they add up to ([`Done`]). Its `Serialize` is the spec's JSON; the CLI's
/// table and CSV read it.
pub struct ReliabilityOutput<'a> {
    /// The machine's name.
    pub machine: &'a str,
    /// The study.
    pub study: &'a Study,
    /// The algorithm's method.
    pub method: Method,
    /// What the cases carry.
    pub columns: CaseColumns,
    /// The posterior of `--values`.
    pub posterior: Option<&'a Posterior>,
    /// The whole-machine acceptance probability (a run in memory).
    pub acceptance: Option<&'a AcceptanceResult>,
    /// The thermal state (a machine with sensors).
    pub temperatures: Option<TemperaturesDocument>,
    cases: Cases<'a>,
    done: RefCell<Option<Done>>,
    failed: RefCell<Option<ReliabilityError>>,
}

/// Where a [`ReliabilityOutput`]'s cases come from.
enum Cases<'a> {
    /// A run in memory: one block.
    Kept(&'a StudyResult),
    /// The study, run [`STREAM_BLOCK`] cases at a time.
    Streamed {
        algorithm: Algorithm,
        progress: &'a dyn Progress,
    },
}

/// The cases a streamed run runs and writes at a time.
pub const STREAM_BLOCK: usize = 4096;

/// The most points whose every reliability a table shows (the maps of the
/// paper's Tables 2-4); a larger grid's table shows its extreme points.
pub const TABLE_POINTS: usize = 10_000;

/// The least reliable points a target keeps for a large grid's table.
pub const EXTREME_POINTS: usize = 5;

/// What the cases of a [`ReliabilityOutput`] add up to: the summaries, the
/// account of every case and of each target's, its extreme points.
pub type Done = reliability::study::Totals;

/// A streamed run's end: the study's error or the consumer's.
enum Halt<E> {
    Run(ReliabilityError),
    Consumer(E),
}

impl<E> From<ReliabilityError> for Halt<E> {
    fn from(e: ReliabilityError) -> Self {
        Halt::Run(e)
    }
}

impl ReliabilityOutput<'_> {
    /// Hands every block of cases (in case order: target-major) to `f` and
    /// keeps what they add up to ([`ReliabilityOutput::done`]). A run that
    /// fails keeps its error ([`ReliabilityOutput::take_error`]) and ends
    /// the blocks with `stop`'s value of it; `f`'s error ends them too.
    pub fn each_block<E>(
        &self,
        mut f: impl FnMut(&[CaseResult]) -> Result<(), E>,
        stop: impl Fn(&ReliabilityError) -> E,
    ) -> Result<(), E> {
        let mut adding = reliability::study::Adding::new(self.study, EXTREME_POINTS);
        let result = match &self.cases {
            Cases::Kept(r) => {
                adding.add(&r.cases);
                f(&r.cases)?;
                StudyResult {
                    method: r.method,
                    variables: r.variables.clone(),
                    cases: Vec::new(),
                    summaries: r.summaries.clone(),
                    requirement: r.requirement,
                }
            }
            Cases::Streamed {
                algorithm,
                progress,
            } => {
                // Every point read first, so that a refused one ends the
                // run before a row is written.
                let run = self.study.check().map_err(Halt::Run).and_then(|()| {
                    self.study
                        .run_blocks(algorithm, *progress, STREAM_BLOCK, |b| {
                            adding.add(b);
                            f(b).map_err(Halt::Consumer)
                        })
                });
                match run {
                    Ok(r) => r,
                    Err(Halt::Consumer(e)) => return Err(e),
                    Err(Halt::Run(e)) => {
                        let out = stop(&e);
                        *self.failed.borrow_mut() = Some(e);
                        return Err(out);
                    }
                }
            }
        };
        *self.done.borrow_mut() = Some(adding.finish(result));
        Ok(())
    }

    /// Runs the study and keeps only what its cases add up to
    /// ([`ReliabilityOutput::done`]), no case handed out: what a large
    /// grid's table shows ([`reliability::study::Study::run_totals`]: where FORM takes the
    /// closed form, one pass over the grid for every target). A run that
    /// fails keeps its error ([`ReliabilityOutput::take_error`]).
    pub fn add_up(&self) {
        let totals = match &self.cases {
            Cases::Kept(_) => return self.each_block(|_| Ok::<(), ()>(()), |_| ()).unwrap_or(()),
            Cases::Streamed {
                algorithm,
                progress,
            } => self.study.run_totals(algorithm, *progress, EXTREME_POINTS),
        };
        match totals {
            Ok(t) => *self.done.borrow_mut() = Some(t),
            Err(e) => *self.failed.borrow_mut() = Some(e),
        }
    }

    /// The run's result with every case, when the run is in memory.
    pub fn kept(&self) -> Option<&StudyResult> {
        match &self.cases {
            Cases::Kept(r) => Some(r),
            Cases::Streamed { .. } => None,
        }
    }

    /// What the cases added up to, once every block is handed out.
    pub fn done(&self) -> Option<Ref<'_, Done>> {
        Ref::filter_map(self.done.borrow(), Option::as_ref).ok()
    }

    /// The error that ended the run, if one did.
    pub fn take_error(&self) -> Option<ReliabilityError> {
        self.failed.borrow_mut().take()
    }

    /// The notes and warnings of a streamed run, once its blocks are
    /// handed out: FORM's limits and the cases that did not converge.
    pub fn notes(&self) -> Vec<String> {
        let mut notes = Vec::new();
        if self.method == Method::Form {
            notes.extend(study::form_limits_note(self.study));
        }
        if let Some(d) = self.done() {
            notes.extend(study::unconverged_warnings(
                &d.tally,
                d.result.method,
                self.study.variables(),
            ));
        }
        notes
    }

    /// The grid's axes in file order, with their index in the model's
    /// variables.
    pub fn axes(&self) -> Vec<(&str, usize)> {
        (self.study.spec().grid.axes.iter())
            .filter_map(|(n, _)| {
                let i = self.study.variables().iter().position(|v| v == n)?;
                Some((n.as_str(), i))
            })
            .collect()
    }
}

impl Serialize for ReliabilityOutput<'_> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        ReliabilityDocument {
            machine: self.machine,
            method: self.method,
            sided: self.study.spec().sided,
            results: CaseDocuments(self),
            summary: Summaries(self),
            requirement: self.study.spec().requirement.map(|_| Requirement(self)),
            posterior: self.posterior,
            acceptance: self.acceptance.map(AcceptanceDocument::of),
            temperatures: self.temperatures.as_ref(),
        }
        .serialize(serializer)
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

/// The document of a grid study (the spec's `reliability` JSON contract),
/// formed as it is written: the cases as they come, then what they add up
/// to.
#[derive(Serialize)]
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
    pub summary: Summaries<'a>,
    /// The requirement and whether every target meets it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub requirement: Option<Requirement<'a>>,
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

impl<'a> CaseDocument<'a> {
    /// The document of case `c`, its point on the grid's `axes` (file
    /// order, each with its index in the model's variables).
    pub fn of(c: &'a CaseResult, axes: &[(&'a str, usize)]) -> CaseDocument<'a> {
        CaseDocument {
            component: c.target,
            point: NameMap(axes.iter().map(|&(n, i)| (n, c.point[i])).collect()),
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
        }
    }
}

/// The cases of a [`ReliabilityDocument`]: serialised as the list of their
/// [`CaseDocument`]s, each formed when it is written, a block at a time, so
/// that a document of a million cases is never a copy of them (nor,
/// streamed, a first one).
pub struct CaseDocuments<'a>(&'a ReliabilityOutput<'a>);

impl Serialize for CaseDocuments<'_> {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::{Error, SerializeSeq};
        let axes = self.0.axes();
        let mut seq = serializer.serialize_seq(None)?;
        self.0.each_block(
            |block| {
                (block.iter()).try_for_each(|c| seq.serialize_element(&CaseDocument::of(c, &axes)))
            },
            |e| S::Error::custom(e),
        )?;
        seq.end()
    }
}

/// Each target's summary of a [`ReliabilityDocument`], read once its cases
/// are written.
pub struct Summaries<'a>(&'a ReliabilityOutput<'a>);

impl Serialize for Summaries<'_> {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::Error;
        let done = (self.0.done()).ok_or_else(|| S::Error::custom("the run did not finish"))?;
        NameMap(
            (done.result.summaries.iter())
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
        )
        .serialize(serializer)
    }
}

/// The requirement of a [`ReliabilityDocument`] and whether every target
/// meets it, read once its cases are written.
pub struct Requirement<'a>(&'a ReliabilityOutput<'a>);

impl Serialize for Requirement<'_> {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::Error;
        let done = (self.0.done()).ok_or_else(|| S::Error::custom("the run did not finish"))?;
        RequirementDocument::of(&done.result).serialize(serializer)
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
