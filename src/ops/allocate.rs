//! `chain allocate` as a request and a document (docs/allocation.md):
//! precision allocation (Wang & Yuan 2021, Section 3.3, Tables 5-7), the
//! paper's fixed-step tightening of the most sensitive errors or the
//! least-cost standard deviations that meet the requirement (with a KKT
//! check), for the reliability section's requirement or the whole-machine
//! acceptance probability. Run by the CLI and `Machine.allocate`, whose
//! JSON is the [`AllocationDocument`]; a refusal that names an error is
//! located at its statistics entry ([`AllocateOpsError::location`]) for
//! both.

use chain_core::model::{Origin, Requirement, Sided};
use chain_core::named::NameMap;
use chain_core::{CompiledModel, Machine};
use reliability::allocate::{
    self, AcceptanceAllocation, AcceptanceStrategy, AllocateError, Allocation, ErrorBounds,
    GridUse, Optimal, Paper, StrategyName,
};
use reliability::{ReliabilityError, Study, Summary};
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
    /// The machine's sections (located by [`study::describe`]).
    #[error(transparent)]
    Reliability(#[from] ReliabilityError),
    /// The allocation itself (an infeasible requirement, a stalled round),
    /// as `file:line:column: machine: …` when it names an error whose
    /// statistics entry is known.
    #[error(
        "{}{machine}: {error}{}",
        origin.as_ref().map(|o| format!("{file}:{}:{}: ", o.line, o.column)).unwrap_or_default(),
        if matches!(**error, AllocateError::NotNormal { .. }) { " (use --strategy paper)" } else { "" }
    )]
    Allocate {
        /// The machine.
        machine: String,
        /// The machine file.
        file: String,
        /// The statistics entry of the error the refusal names first (a
        /// stalled round's first ranked error, an infeasible requirement's
        /// first binding error: where its `min_std` is set).
        origin: Option<Origin>,
        /// What went wrong.
        error: Box<AllocateError>,
    },
}

impl AllocateOpsError {
    /// Where in the machine file the refusal is, with the label of that
    /// place: the statistics entry an allocation's refusal names.
    pub fn location(&self) -> Option<(&Origin, &'static str)> {
        match self {
            AllocateOpsError::Allocate {
                origin: Some(o), ..
            } => Some((o, "its statistics entry")),
            _ => None,
        }
    }
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
            AllocateOpsError::Allocate { error, .. } => match **error {
                AllocateError::Stalled { .. } => Some(
                    "lower (remove) `min_std` of its errors, or use `--strategy optimal`".into(),
                ),
                ref e => e.help().map(String::from),
            },
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

/// The run of `chain allocate` (JSON: its [`AllocationDocument`]).
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
    /// The document of the run.
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
    let result = match (request.level, strategy) {
        (Some(level), strategy) => {
            allocate::acceptance(&model, &parameters, &study, &bounds, level, strategy)
        }
        (None, AcceptanceStrategy::Optimal) => {
            allocate::optimal(&model, &parameters, &study, &bounds, &Optimal::default())
        }
        (None, AcceptanceStrategy::Paper(paper)) => {
            allocate::paper(&model, &parameters, &study, &bounds, &paper)
        }
    }
    .map_err(|error| match error {
        AllocateError::Reliability(e) => AllocateOpsError::Reliability(e),
        error => located(machine, file, error),
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

/// An allocation's refusal, at the statistics entry of the error it names
/// first when the machine file has one.
fn located(machine: &Machine, file: &str, error: AllocateError) -> AllocateOpsError {
    let origin = error.statistic().and_then(|name| {
        let j = machine.error_index(name)?;
        let stat = machine.statistic(j)?;
        (stat.origin.line > 0).then(|| stat.origin.clone())
    });
    AllocateOpsError::Allocate {
        machine: machine.name.clone(),
        file: file.to_string(),
        origin,
        error: Box::new(error),
    }
}

/// The document of `chain allocate` (docs/allocation.md; field order = key order).
#[derive(Debug, Serialize)]
pub struct AllocationDocument<'a> {
    /// The machine's name.
    pub machine: &'a str,
    /// `optimal` or `paper`.
    pub strategy: StrategyName,
    /// The reliability section's requirement.
    pub requirement: Option<Requirement>,
    /// The standard deviations and summaries before allocation.
    pub initial: InitialDocument<'a>,
    /// The paper's rounds (empty for the optimal strategy).
    pub steps: Vec<StepDocument<'a>>,
    /// The allocated standard deviations, cost and summaries.
    #[serde(rename = "final")]
    pub last: FinalDocument<'a>,
    /// The KKT check (optimal strategy).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub kkt: Option<KktDocument<'a>>,
    /// `--target acceptance`: level, initial and allocated probability.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub acceptance: Option<&'a AcceptanceAllocation>,
}

/// One component's reliability over the grid in an [`AllocationDocument`].
#[derive(Debug, Serialize)]
pub struct AllocationSummaryDocument {
    /// Mean reliability over the grid.
    pub mean: f64,
    /// Smallest reliability.
    pub min: f64,
    /// Largest reliability.
    pub max: f64,
    /// Whether the requirement is met (`null` without one).
    pub met: Option<bool>,
}

/// The starting point of an [`AllocationDocument`].
#[derive(Debug, Serialize)]
pub struct InitialDocument<'a> {
    /// The initial standard deviation of every error.
    pub std: NameMap<&'a str, f64>,
    /// Each component's reliability over the grid.
    pub summary: NameMap<String, AllocationSummaryDocument>,
}

/// One round of the paper's procedure in an [`AllocationDocument`].
#[derive(Debug, Serialize)]
pub struct StepDocument<'a> {
    /// 1, 2, …
    pub round: usize,
    /// The errors tightened this round.
    pub tightened: &'a [String],
    /// Their new standard deviations.
    pub std: NameMap<&'a str, f64>,
    /// Each component's reliability after the round.
    pub summary: NameMap<String, AllocationSummaryDocument>,
}

/// The outcome of an [`AllocationDocument`].
#[derive(Debug, Serialize)]
pub struct FinalDocument<'a> {
    /// The allocated standard deviations.
    pub std: NameMap<&'a str, f64>,
    /// `Σ w (σ0/σ − 1)`.
    pub cost: f64,
    /// Whether the requirement (or the acceptance level) is met.
    pub met: bool,
    /// Each component's reliability (FORM re-evaluation).
    pub summary: NameMap<String, AllocationSummaryDocument>,
}

/// The KKT check of an [`AllocationDocument`].
#[derive(Debug, Serialize)]
pub struct KktDocument<'a> {
    /// `‖∇f − Σ λₖ∇gₖ − z‖∞`.
    pub stationarity: f64,
    /// `max |λₖ gₖ|` and the bounds'.
    pub complementarity: f64,
    /// Constraint and bound violations.
    pub feasibility: f64,
    /// Wrong-signed multipliers.
    pub dual_feasibility: f64,
    /// The largest of the four.
    pub residual: f64,
    /// Whether the active-set Newton polish converged.
    pub polished: bool,
    /// Newton iterations.
    pub iterations: usize,
    /// The active constraints.
    pub active: Vec<ActiveDocument<'a>>,
    /// The errors at a bound.
    pub at_bound: Vec<AtBoundDocument<'a>>,
}

/// An active constraint of a [`KktDocument`].
#[derive(Debug, Serialize)]
pub struct ActiveDocument<'a> {
    /// The constraint.
    pub constraint: &'a str,
    /// Its multiplier.
    pub multiplier: f64,
}

/// An error at a bound in a [`KktDocument`].
#[derive(Debug, Serialize)]
pub struct AtBoundDocument<'a> {
    /// The error.
    pub error: &'a str,
    /// `unchanged` or `min_std`.
    pub bound: &'a str,
    /// The bound's multiplier.
    pub multiplier: f64,
}

/// `{target: {mean, min, max, met}}` of a list of summaries.
fn allocation_summaries(s: &[Summary]) -> NameMap<String, AllocationSummaryDocument> {
    s.iter()
        .map(|s| {
            (
                s.target.to_string(),
                AllocationSummaryDocument {
                    mean: s.mean,
                    min: s.min,
                    max: s.max,
                    met: s.met,
                },
            )
        })
        .collect()
}

/// `{error: std}` of a list of named standard deviations.
fn named_stds(s: &[(String, f64)]) -> NameMap<&str, f64> {
    s.iter().map(|(n, v)| (n.as_str(), *v)).collect()
}

impl<'a> AllocationDocument<'a> {
    /// The document of the allocation `r` of the machine `machine`, started
    /// from `bounds`, for the requirement `requirement`.
    pub fn new(
        machine: &'a str,
        requirement: Option<Requirement>,
        bounds: &'a [ErrorBounds],
        r: &'a Allocation,
    ) -> AllocationDocument<'a> {
        AllocationDocument {
            machine,
            strategy: r.strategy,
            requirement,
            initial: InitialDocument {
                std: bounds.iter().map(|b| (b.error.as_str(), b.std0)).collect(),
                summary: allocation_summaries(&r.initial),
            },
            steps: r
                .steps
                .iter()
                .map(|s| StepDocument {
                    round: s.round,
                    tightened: &s.tightened,
                    std: named_stds(&s.std),
                    summary: allocation_summaries(&s.summaries),
                })
                .collect(),
            last: FinalDocument {
                std: named_stds(&r.std),
                cost: r.cost,
                met: r.met,
                summary: allocation_summaries(&r.summaries),
            },
            kkt: r.kkt.as_ref().map(|k| KktDocument {
                stationarity: k.stationarity,
                complementarity: k.complementarity,
                feasibility: k.feasibility,
                dual_feasibility: k.dual_feasibility,
                residual: k.residual(),
                polished: k.polished,
                iterations: k.iterations,
                active: k
                    .active
                    .iter()
                    .map(|(n, l)| ActiveDocument {
                        constraint: n,
                        multiplier: *l,
                    })
                    .collect(),
                at_bound: k
                    .at_bound
                    .iter()
                    .map(|(n, b, z)| AtBoundDocument {
                        error: n,
                        bound: b,
                        multiplier: *z,
                    })
                    .collect(),
            }),
            acceptance: r.acceptance.as_ref(),
        }
    }
}
