//! `chain allocate` as a request and a document (docs/allocation.md):
//! precision allocation (Wang & Yuan 2021, Section 3.3, Tables 5-7), the
//! paper's fixed-step tightening of the most sensitive errors or the
//! least-cost standard deviations that meet the requirement (with a KKT
//! check), for the reliability section's requirement or the whole-machine
//! acceptance probability. Run by the CLI and `Machine.allocate`.

use chain_core::model::Sided;
use chain_core::{CompiledModel, Machine};
use reliability::allocate::{
    self, AcceptanceStrategy, AllocateError, Allocation, ErrorBounds, GridUse, Paper, StrategyName,
};
use reliability::document::AllocationDocument;
use reliability::{ReliabilityError, Study};
use serde::{Serialize, Serializer};

use super::resolve::ResolveError;
use super::study::{self, OptionError, StudyError, StudyOptions};
use super::worded::{diagnostic, Worded};

/// What to allocate for (`--target`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum AllocationTarget {
    /// The reliability section's requirement (minimum and mean over the
    /// grid, per component).
    #[default]
    Requirement,
    /// The whole-machine acceptance probability reaches `level`.
    Acceptance,
}

/// The request of `chain allocate`.
#[derive(Debug, Clone, Copy)]
pub struct AllocateRequest<'a> {
    /// `--strategy`.
    pub strategy: StrategyName,
    /// `--step` of the paper's rounds, in Table 1's tolerance units.
    pub step: f64,
    /// `--threshold` of the paper's rounds: a fraction of the largest
    /// sensitivity, in [0, 1].
    pub threshold: f64,
    /// `--rank pooled`: rank the summed sensitivities of all unmet
    /// components (otherwise each component's own).
    pub pooled: bool,
    /// `--target`.
    pub target: AllocationTarget,
    /// `--level`: the acceptance probability to reach, in (0, 1).
    pub level: Option<f64>,
    /// `--param NAME=VALUE`.
    pub params: &'a [(String, f64)],
    /// `--sided`.
    pub sided: Option<Sided>,
}

impl Default for AllocateRequest<'_> {
    /// The CLI's defaults.
    fn default() -> Self {
        AllocateRequest {
            strategy: StrategyName::Optimal,
            step: 0.005,
            threshold: 0.1,
            pooled: false,
            target: AllocationTarget::Requirement,
            level: None,
            params: &[],
            sided: None,
        }
    }
}

/// Why `chain allocate` cannot run.
#[derive(Debug, thiserror::Error)]
pub enum AllocateOpsError {
    /// An option out of range.
    #[error(transparent)]
    Option(#[from] OptionError),
    /// `--level` out of (0, 1).
    #[error(
        "invalid value for `--level`: {0} (an acceptance probability strictly between 0 and 1)"
    )]
    Level(f64),
    /// `--target acceptance` without `--level`.
    #[error("`--target acceptance` needs `--level L`")]
    MissingLevel,
    /// `--level` without `--target acceptance`.
    #[error("`--level` applies to `--target acceptance` only")]
    LevelWithoutAcceptance,
    /// An option does not match the machine.
    #[error(transparent)]
    Resolve(#[from] ResolveError),
    /// The study.
    #[error(transparent)]
    Study(Box<StudyError>),
    /// The machine's sections (located by `reliability::document::describe`).
    #[error(transparent)]
    Reliability(#[from] ReliabilityError),
    /// The allocation itself (an infeasible requirement, a stalled round).
    #[error("{machine}: {error}")]
    Allocate {
        /// The machine.
        machine: String,
        /// What went wrong.
        error: Box<AllocateError>,
    },
}

impl From<StudyError> for AllocateOpsError {
    fn from(e: StudyError) -> AllocateOpsError {
        AllocateOpsError::Study(Box::new(e))
    }
}

impl Worded for AllocateOpsError {
    fn own_code(&self) -> Option<&'static str> {
        match self {
            AllocateOpsError::Level(_) | AllocateOpsError::LevelWithoutAcceptance => {
                Some("chain::allocate::invalid_level")
            }
            AllocateOpsError::MissingLevel => Some("chain::allocate::missing_level"),
            _ => None,
        }
    }

    fn own_help(&self) -> Option<String> {
        match self {
            AllocateOpsError::MissingLevel => Some("e.g. --target acceptance --level 0.9".into()),
            AllocateOpsError::Resolve(e) => e.own_help(),
            _ => None,
        }
    }

    #[cfg(feature = "cli")]
    fn inner(&self) -> Option<&dyn miette::Diagnostic> {
        match self {
            AllocateOpsError::Option(e) => Some(e),
            AllocateOpsError::Resolve(e) => Some(e),
            AllocateOpsError::Allocate { error, .. } => Some(&**error),
            _ => None,
        }
    }
}

diagnostic!(AllocateOpsError);

/// The document of `chain allocate` (JSON: the library's
/// [`AllocationDocument`]).
#[derive(Debug)]
pub struct AllocationRun {
    /// The machine.
    pub machine: String,
    /// The study allocated over.
    pub study: Study,
    /// Its compiled model.
    pub model: CompiledModel,
    /// The parameter values.
    pub parameters: Vec<f64>,
    /// Each error's initial std and bounds.
    pub bounds: Vec<ErrorBounds>,
    /// The allocation.
    pub result: Allocation,
}

impl AllocationRun {
    /// The library's document of the run.
    pub fn document(&self) -> AllocationDocument<'_> {
        AllocationDocument::new(
            &self.machine,
            self.study.spec().requirement,
            &self.bounds,
            &self.result,
        )
    }

    /// The refusal when the allocation misses its target (the CLI prints
    /// the document, then exits non-zero with it).
    pub fn not_met(&self) -> Option<String> {
        let r = &self.result;
        (!r.met).then(|| match &r.acceptance {
            Some(a) => format!(
                "the acceptance level {} is not reached after {} rounds (P = {})",
                a.level,
                r.steps.len(),
                a.probability
            ),
            None => format!("the requirement is not met after {} rounds", r.steps.len()),
        })
    }
}

impl Serialize for AllocationRun {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        self.document().serialize(serializer)
    }
}

/// `--threshold`: a fraction of the largest sensitivity in [0, 1] (above 1
/// no error is ever tightened, and NaN compares false with all).
pub fn check_threshold(t: f64) -> Result<f64, OptionError> {
    if !(0.0..=1.0).contains(&t) {
        return Err(OptionError::new(
            "threshold",
            format!(
                "the threshold is a fraction of the largest sensitivity, in [0, 1] (found `{t}`)"
            ),
        ));
    }
    Ok(t)
}

/// The checks that need no machine: the threshold and the level against
/// the target.
pub fn check(request: &AllocateRequest<'_>) -> Result<(), AllocateOpsError> {
    check_threshold(request.threshold)?;
    match (request.target, request.level) {
        (AllocationTarget::Acceptance, Some(l)) if l > 0.0 && l < 1.0 => Ok(()),
        (AllocationTarget::Acceptance, Some(l)) => Err(AllocateOpsError::Level(l)),
        (AllocationTarget::Acceptance, None) => Err(AllocateOpsError::MissingLevel),
        (AllocationTarget::Requirement, Some(_)) => Err(AllocateOpsError::LevelWithoutAcceptance),
        (AllocationTarget::Requirement, None) => Ok(()),
    }
}

/// Runs `chain allocate` of `machine` (`file` names it).
pub fn run(
    machine: &Machine,
    file: &str,
    request: &AllocateRequest<'_>,
) -> Result<AllocationRun, AllocateOpsError> {
    check(request)?;
    // Refused from the file before the derivation: a grid larger than the
    // target and strategy take.
    let what = match (request.target, request.strategy) {
        (AllocationTarget::Acceptance, _) => GridUse::Acceptance,
        (AllocationTarget::Requirement, StrategyName::Optimal) => GridUse::Optimal,
        (AllocationTarget::Requirement, StrategyName::Paper) => GridUse::Paper,
    };
    allocate::check_grid(machine, what)?;
    let options = StudyOptions {
        params: request.params,
        sided: request.sided,
        ..StudyOptions::default()
    };
    let (study, model) = study::study(machine, file, &options)?;
    let parameters = reliability::machine::parameters(machine, request.params)?;
    let bounds = allocate::bounds(machine, &study)?;
    let strategy = match request.strategy {
        StrategyName::Optimal => AcceptanceStrategy::Optimal,
        StrategyName::Paper => AcceptanceStrategy::Paper(Paper {
            step: request.step,
            threshold: request.threshold,
            pooled: request.pooled,
            ..Paper::default()
        }),
    };
    let result = reliability::document::allocation(
        &model,
        &parameters,
        &study,
        &bounds,
        strategy,
        request.level,
    )
    .map_err(|error| match error {
        AllocateError::Reliability(e) => AllocateOpsError::Reliability(e),
        error => AllocateOpsError::Allocate {
            machine: machine.name.clone(),
            error: Box::new(error),
        },
    })?;
    Ok(AllocationRun {
        machine: machine.name.clone(),
        study,
        model,
        parameters,
        bounds,
        result,
    })
}
