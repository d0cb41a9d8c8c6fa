//! `chain reliability` as a request and a document (spec reliability-v2;
//! docs/reliability.md): the machining-accuracy reliability of every
//! toleranced component (and a system target) over the grid, from the
//! machine's statistics or a calibration's posterior, with the
//! whole-machine acceptance probability when asked. The CLI and
//! `Machine.reliability` both [`prepare`] the study, [`Prepared::run`] it
//! and print or return the same [`ReliabilityRun`], whose JSON is the
//! [`ReliabilityDocument`] (with its [`AcceptanceDocument`]).

use std::path::Path;

use chain_core::model::Sided;
use chain_core::named::NameMap;
use chain_core::values::Approach;
use chain_core::{CompiledModel, Machine};
use reliability::acceptance::{AcceptanceResult, AcceptanceSubset};
use reliability::{
    Acceptance, Calls, CaseResult, CaseTally, FormCase, Method, Posterior, Progress, Rectangles,
    ReliabilityError, SormCase, Stopping, Study, StudyResult, SubsetLevel, Target,
};
use serde::{Serialize, Serializer};

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
    let (study, model) = study::study(machine, file, &options)?;
    let wanted = request.acceptance || (machine.reliability.as_ref()).is_some_and(|r| r.acceptance);
    Ok(Prepared {
        machine: machine.name.clone(),
        study,
        posterior,
        model,
        algorithm: request.algorithm,
        acceptance: wanted.then_some((t, request.algorithm.seed)),
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
        let result = self.study.run(&self.algorithm.algorithm(), progress)?;
        let mut notes = Vec::new();
        if self.algorithm.method == Method::Form {
            notes.extend(study::form_limits_note(&self.study));
        }
        notes.extend(study::unconverged_warnings(
            &CaseTally::of(&result.cases),
            result.method,
            self.study.variables(),
        ));
        let acceptance = match self.acceptance {
            Some((tolerance, seed)) => {
                let a = acceptance(&self.study, tolerance, seed)?;
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
            study: self.study,
            model: self.model,
            result,
            posterior: self.posterior,
            acceptance,
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
