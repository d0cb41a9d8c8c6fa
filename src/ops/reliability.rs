//! `chain reliability` as a request and a document (spec reliability-v2;
//! docs/reliability.md): the machining-accuracy reliability of every
//! toleranced component (and a system target) over the grid, from the
//! machine's statistics or a calibration's posterior, with the
//! whole-machine acceptance probability when asked. The CLI and
//! `Machine.reliability` both [`prepare`] the study, [`Prepared::run`] it
//! and print or return the same [`ReliabilityRun`].

use std::path::Path;

use chain_core::model::Sided;
use chain_core::values::Approach;
use chain_core::{CompiledModel, Machine};
use reliability::acceptance::AcceptanceResult;
use reliability::document::{AcceptanceDocument, ReliabilityDocument};
use reliability::{CaseTally, Method, Posterior, Progress, ReliabilityError, Study, StudyResult};
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
    /// The run (located in the machine file by
    /// `reliability::document::describe`).
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
                let a = reliability::document::acceptance(&self.study, tolerance, seed)?;
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
