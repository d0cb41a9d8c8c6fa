//! Precision allocation (seed 000, Section 3.3, Tables 5-7): which standard
//! deviations to tighten so that every toleranced component meets the
//! requirement on its minimum and mean reliability over the grid.
//!
//! Two strategies:
//!
//! - [`paper()`] (`paper.rs`): the paper's procedure. Each round ranks the errors of every
//!   component that misses the requirement by their grid-mean `|∂R/∂σ|`
//!   (per component, as Tables 5-7 do), tightens every error whose
//!   sensitivity is at least a fraction (10 %) of that component's largest by
//!   one step in the units of Table 1 (`step/6` mm for linear errors,
//!   `step/6000` rad for angular, `step/3000` rad for squareness), and
//!   re-evaluates with FORM.
//! - [`optimal()`] (`optimal/`): the least-cost standard deviations,
//!   `min Σ wᵢ (σ0ᵢ/σᵢ − 1)` subject to `R_case(σ) ≥ R_min` for every grid
//!   case of every component and `mean R(σ) ≥ R_mean` per component, with
//!   `min_stdᵢ ≤ σᵢ ≤ σ0ᵢ`. It works in `tᵢ = ln(σ0ᵢ/σᵢ)` (the cost is
//!   convex there), with the exact reliability `Φ(c/√V)` of a linear
//!   component in normal inputs and its exact first and second derivatives,
//!   by a log-barrier interior-point method (damped Newton per barrier
//!   parameter, strictly feasible iterates), then a Newton polish of the
//!   KKT system on the identified active set. The KKT conditions are checked
//!   and reported ([`Kkt`]). `optimal/problem.rs` holds the problem (cases,
//!   constraints and their exact derivatives), `optimal/barrier.rs` the
//!   log-barrier Newton path and `optimal/kkt.rs` the active-set polish and
//!   the KKT check.
//!
//! Infeasibility is exact, not a best effort: each reliability is increasing
//! in every `tᵢ`, so the requirement is feasible if and only if it holds with
//! every error at its lower bound (`min_std`); when it does not, the result
//! is [`AllocateError::Infeasible`] naming the component, the case and the
//! bounds that bind.

// Dense linear algebra over small index ranges reads best with indices.
#![allow(clippy::needless_range_loop)]

use chain_core::model::{ErrorKind, Machine};
use chain_core::ErrorModel;
use serde::Serialize;

use crate::error::ReliabilityError;
use crate::form::Form;
use crate::inputs::Inputs;
use crate::study::{Algorithm, Study, StudyResult, Summary, Target};

mod acceptance;
mod optimal;
mod paper;

pub use acceptance::{acceptance, AcceptanceAllocation, Strategy as AcceptanceStrategy};
pub use optimal::optimal;
pub use paper::paper;

/// What an allocation runs, for the size of grid it takes
/// ([`check_grid`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GridUse {
    /// [`optimal()`] for the requirement.
    Optimal,
    /// [`paper()`] for the requirement.
    Paper,
    /// [`acceptance()`] (either strategy) for the whole-machine acceptance.
    Acceptance,
}

impl GridUse {
    /// The most grid points the allocation takes: what it runs on within
    /// about a minute on two cores (docs/performance.md, "Allocation on
    /// large grids", with the measured times).
    pub fn limit(self) -> usize {
        match self {
            GridUse::Optimal => 50_000,
            GridUse::Paper => 100_000,
            GridUse::Acceptance => 30_000,
        }
    }

    /// The allocation, as a message names it.
    pub fn name(self) -> &'static str {
        match self {
            GridUse::Optimal => "the least-cost allocation",
            GridUse::Paper => "the paper's tightening",
            GridUse::Acceptance => "the allocation for the acceptance",
        }
    }

    /// Why it has a limit.
    pub fn why(self) -> &'static str {
        match self {
            GridUse::Optimal => {
                "its interior-point method carries a constraint per point and component: 40 s at 43,000 points, growing faster than the grid"
            }
            GridUse::Paper => {
                "each round keeps every case's FORM result for its sensitivities: about 4.8 KB a point, 460 MB at 97,000 points"
            }
            GridUse::Acceptance => {
                "every step estimates the probability that all points hold at once: 9 s at 27,000 points"
            }
        }
    }
}

impl std::fmt::Display for GridUse {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Refuses a machine whose reliability grid is larger than `what` takes
/// ([`GridUse::limit`]), from the machine file alone: before the model is
/// derived. A machine without a reliability section passes (the study
/// refuses it).
pub fn check_grid(machine: &Machine, what: GridUse) -> Result<(), ReliabilityError> {
    let Some(r) = &machine.reliability else {
        return Ok(());
    };
    let points = (r.grid.iter()).fold(1usize, |n, (_, v)| n.saturating_mul(v.len()));
    if points > what.limit() {
        return Err(ReliabilityError::GridTooLarge {
            points,
            limit: what.limit(),
            allocation: what,
            origin: r.origin.clone(),
        });
    }
    Ok(())
}

/// The allocation data of one error parameter.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ErrorBounds {
    /// The error parameter.
    pub error: String,
    /// Linear, angular or squareness (sets the step of [`paper()`]).
    pub kind: ErrorKind,
    /// The initial (largest allowed) standard deviation.
    pub std0: f64,
    /// The smallest allowed standard deviation (0 when unbounded).
    pub min_std: f64,
    /// The weight `wᵢ` of the cost.
    pub cost_weight: f64,
}

/// The bounds of every input of `study`, in its input order, from the
/// machine's `statistics` entries.
pub fn bounds(machine: &Machine, study: &Study) -> Result<Vec<ErrorBounds>, ReliabilityError> {
    let inputs = study.inputs();
    inputs
        .names()
        .iter()
        .zip(inputs.marginals())
        .map(|(name, m)| {
            let j = machine
                .error_index(name)
                .ok_or_else(|| ReliabilityError::MissingInput(name.clone()))?;
            let stat = machine
                .statistic(j)
                .ok_or_else(|| ReliabilityError::MissingStatistic {
                    name: name.clone(),
                    origin: machine.errors[j].origin.clone(),
                })?;
            Ok(ErrorBounds {
                error: name.clone(),
                kind: machine.errors[j].kind,
                std0: m.std(),
                min_std: stat.min_std.unwrap_or(0.0),
                cost_weight: stat.cost_weight,
            })
        })
        .collect()
}

/// The cost `Σ wᵢ (σ0ᵢ/σᵢ − 1)` of a set of standard deviations.
pub fn cost(bounds: &[ErrorBounds], stds: &[f64]) -> f64 {
    bounds
        .iter()
        .zip(stds)
        .map(|(b, s)| b.cost_weight * (b.std0 / s - 1.0))
        .sum()
}

/// Options of the paper's procedure.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Paper {
    /// The step, in the paper's tolerance units (0.005).
    pub step: f64,
    /// Tighten every error whose sensitivity is at least this fraction of
    /// the largest (0.1).
    pub threshold: f64,
    /// Rank over all unmet components pooled instead of per component.
    pub pooled: bool,
    /// Give up after this many rounds.
    pub max_rounds: usize,
}

impl Default for Paper {
    fn default() -> Paper {
        Paper {
            step: 0.005,
            threshold: 0.1,
            pooled: false,
            max_rounds: 200,
        }
    }
}

/// Options of the least-cost allocation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Optimal {
    /// The requirement is imposed with this margin (so that an independent
    /// evaluation finds it met despite round-off).
    pub margin: f64,
}

impl Default for Optimal {
    fn default() -> Optimal {
        Optimal { margin: 1e-10 }
    }
}

/// One round of the paper's procedure.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Step {
    /// 1, 2, …
    pub round: usize,
    /// The errors tightened this round, in input order.
    pub tightened: Vec<String>,
    /// Their new standard deviations.
    pub std: Vec<(String, f64)>,
    /// The component summaries after the round.
    pub summaries: Vec<Summary>,
}

/// The KKT conditions at the optimum (in the variables `tᵢ = ln(σ0ᵢ/σᵢ)`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Kkt {
    /// `‖∇f − Σ λₖ∇gₖ − z‖∞` (z: bound multipliers).
    pub stationarity: f64,
    /// `max |λₖ gₖ|` and `max |zᵢ (tᵢ − boundᵢ)|`.
    pub complementarity: f64,
    /// `max(0, −gₖ)` (in reliability) and bound violations.
    pub feasibility: f64,
    /// `max(0, −λₖ)` and wrong-signed bound multipliers.
    pub dual_feasibility: f64,
    /// The active constraints with their multipliers.
    pub active: Vec<(String, f64)>,
    /// Errors at a bound: `(name, "unchanged" | "min_std", multiplier)`.
    pub at_bound: Vec<(String, &'static str, f64)>,
    /// Newton iterations (barrier and polish).
    pub iterations: usize,
    /// Whether the active-set Newton polish converged (else the barrier
    /// solution is reported).
    pub polished: bool,
}

impl Kkt {
    /// The largest of the four residuals.
    pub fn residual(&self) -> f64 {
        self.stationarity
            .max(self.complementarity)
            .max(self.feasibility)
            .max(self.dual_feasibility)
    }
}

/// Which strategy allocated (serialised `optimal` or `paper`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum StrategyName {
    /// Least cost.
    Optimal,
    /// The paper's rounds.
    Paper,
}

impl std::fmt::Display for StrategyName {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl StrategyName {
    /// `optimal` or `paper`.
    pub fn name(self) -> &'static str {
        match self {
            StrategyName::Optimal => "optimal",
            StrategyName::Paper => "paper",
        }
    }
}

/// The outcome of an allocation.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Allocation {
    /// `optimal` or `paper`.
    pub strategy: StrategyName,
    /// The initial component summaries.
    pub initial: Vec<Summary>,
    /// The paper's rounds (empty for the optimal strategy).
    pub steps: Vec<Step>,
    /// The final standard deviations, in input order.
    pub std: Vec<(String, f64)>,
    /// Their cost.
    pub cost: f64,
    /// Whether every component meets the requirement (FORM re-evaluation).
    pub met: bool,
    /// The final component summaries (FORM re-evaluation).
    pub summaries: Vec<Summary>,
    /// The KKT check (optimal strategy).
    pub kkt: Option<Kkt>,
    /// The acceptance target's outcome ([`acceptance()`]; then `met` is
    /// whether the level is reached).
    pub acceptance: Option<AcceptanceAllocation>,
}

impl Allocation {
    /// The allocation of `stds` (one per bound, in input order) with the
    /// final summaries of its FORM re-evaluation: the cost and whether the
    /// requirement is met follow from them.
    pub(crate) fn new(
        strategy: StrategyName,
        initial: Vec<Summary>,
        steps: Vec<Step>,
        bounds: &[ErrorBounds],
        stds: &[f64],
        summaries: Vec<Summary>,
        kkt: Option<Kkt>,
    ) -> Allocation {
        Allocation {
            strategy,
            initial,
            steps,
            std: bounds
                .iter()
                .zip(stds)
                .map(|(b, s)| (b.error.clone(), *s))
                .collect(),
            cost: cost(bounds, stds),
            met: all_met(&summaries),
            summaries,
            kkt,
            acceptance: None,
        }
    }
}

/// Why an allocation failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AllocateError {
    /// From the reliability engine.
    #[error(transparent)]
    Reliability(#[from] ReliabilityError),
    /// The machine has no `requirement`.
    #[error("the reliability section has no `requirement` (min and mean) to allocate for")]
    NoRequirement,
    /// The least-cost allocation takes normal inputs only.
    #[error("the optimal allocation needs normal inputs; `{error}` is not normal")]
    NotNormal {
        /// The first error parameter whose input is not normal.
        error: String,
    },
    /// A setting the strategy does not handle.
    #[error("{0}")]
    Unsupported(String),
    /// The requirement cannot be met within the bounds.
    #[error(
        "the requirement is infeasible: {component} {what}{} reaches at most {:.4} % with every error at its bound (required {:.4} %); binding bounds: {}",
        at.as_ref().map(|a| format!(" at {a}")).unwrap_or_default(),
        best * 100.0,
        required * 100.0,
        binding.join(", ")
    )]
    Infeasible {
        /// The component.
        component: String,
        /// `minimum reliability` or `mean reliability`.
        what: &'static str,
        /// The grid point of the failing case.
        at: Option<String>,
        /// The best reachable value.
        best: f64,
        /// The required value.
        required: f64,
        /// The errors at their `min_std` that drive the component, largest
        /// contribution first (`name (min_std …)`).
        binding: Vec<String>,
    },
    /// The paper's procedure can tighten nothing more.
    #[error("the paper's procedure stops after round {round}: {component} misses the requirement and none of its errors can be tightened further ({} at min_std or zero)", errors.join(", "))]
    Stalled {
        /// The last round.
        round: usize,
        /// The component.
        component: String,
        /// Its ranked errors.
        errors: Vec<String>,
    },
    /// The optimiser did not converge.
    #[error("the optimiser did not converge: {0}")]
    NotConverged(String),
}

impl AllocateError {
    /// The error parameter the refusal names first, whose statistics entry
    /// (its `min_std`) a message can point at: a stalled round's first
    /// ranked error, an infeasible requirement's first binding error.
    pub fn statistic(&self) -> Option<&str> {
        match self {
            AllocateError::Stalled { errors, .. } => errors.first().map(String::as_str),
            // Each binding entry is `name (min_std …)`.
            AllocateError::Infeasible { binding, .. } => {
                binding.first().and_then(|b| b.split(" (").next())
            }
            _ => None,
        }
    }

    /// The code of the refusal (`chain::allocate::…`).
    pub fn code(&self) -> &'static str {
        match self {
            AllocateError::Reliability(_) => "chain::allocate::reliability",
            AllocateError::NoRequirement => "chain::allocate::no_requirement",
            AllocateError::NotNormal { .. } | AllocateError::Unsupported(_) => {
                "chain::allocate::unsupported"
            }
            AllocateError::Infeasible { .. } => "chain::allocate::infeasible",
            AllocateError::Stalled { .. } => "chain::allocate::stalled",
            AllocateError::NotConverged(_) => "chain::allocate::not_converged",
        }
    }

    /// What to do about it, in the terms of this crate, where there is
    /// something to say.
    pub fn help(&self) -> Option<&'static str> {
        match self {
            AllocateError::NoRequirement => {
                Some("add, e.g., `requirement: {min: 0.95, mean: 0.97}` to the reliability section")
            }
            AllocateError::Infeasible { .. } => {
                Some("lower the requirement, or lower (remove) `min_std` of the binding errors")
            }
            AllocateError::Stalled { .. } => {
                Some("lower (remove) `min_std` of its errors, or use the least-cost allocation")
            }
            _ => None,
        }
    }
}

#[cfg(feature = "miette")]
impl miette::Diagnostic for AllocateError {
    fn code<'a>(&'a self) -> Option<Box<dyn std::fmt::Display + 'a>> {
        Some(Box::new(AllocateError::code(self)))
    }

    fn help<'a>(&'a self) -> Option<Box<dyn std::fmt::Display + 'a>> {
        AllocateError::help(self).map(|h| Box::new(h) as Box<dyn std::fmt::Display>)
    }
}

/// The study's inputs with other standard deviations: families, means and
/// correlations held ([`Inputs::with_stds`]).
pub fn with_stds(study: &Study, stds: &[f64]) -> Result<Inputs, ReliabilityError> {
    study.inputs().with_stds(stds)
}

/// FORM over the study's grid with other standard deviations.
pub fn evaluate<M: ErrorModel + ?Sized>(
    model: &M,
    parameters: &[f64],
    study: &Study,
    stds: &[f64],
) -> Result<(Study, StudyResult), ReliabilityError> {
    let s = Study::new(
        model,
        parameters,
        with_stds(study, stds)?,
        study.spec().clone(),
    )?;
    let r = s.run(&Algorithm::Form(Form::default()), &())?;
    Ok((s, r))
}

pub(crate) fn component_summaries(r: &StudyResult) -> Vec<Summary> {
    r.summaries
        .iter()
        .filter(|s| matches!(s.target, crate::Target::Component(_)))
        .cloned()
        .collect()
}

pub(crate) fn all_met(s: &[Summary]) -> bool {
    s.iter().all(|s| s.met.unwrap_or(true))
}

/// One step of `kind` in standard-deviation units (Table 1's units).
pub fn step_std(kind: ErrorKind, step: f64) -> f64 {
    match kind {
        ErrorKind::Linear => step / 6.0,
        ErrorKind::Angular => step / 6000.0,
        ErrorKind::Squareness => step / 3000.0,
    }
}

/// The targets of a study that allocation handles (its components).
pub fn components(study: &Study) -> Vec<Target> {
    study
        .targets()
        .iter()
        .copied()
        .filter(|t| matches!(t, Target::Component(_)))
        .collect()
}

#[cfg(test)]
mod tests {
    use crate::inputs::{Correlation, Inputs};
    use crate::util::fixtures::gantry;
    use crate::{machine, Study};

    /// Re-evaluating a study at its own standard deviations reproduces its
    /// FORM results: the correlations are held, not dropped (with them
    /// dropped the correlated pair's cases move).
    #[test]
    fn evaluate_holds_the_correlations() {
        let (m, model) = gantry();
        let independent = machine::study(&m, &model, &[], None).unwrap();
        let inputs = independent.inputs();
        let names = inputs.names();
        let at = |n: &str| names.iter().position(|x| x == n).unwrap();
        let pair = [Correlation {
            a: at("dxx"),
            b: at("ezx"),
            rho: 0.8,
        }];
        let correlated =
            Inputs::correlated(names.to_vec(), inputs.marginals().to_vec(), &pair).unwrap();
        let study = Study::new(&model, &[], correlated, independent.spec().clone()).unwrap();
        let own = study
            .run(&crate::Algorithm::Form(crate::Form::default()), &())
            .unwrap();
        let (_, again) = super::evaluate(&model, &[], &study, study.inputs().stds()).unwrap();
        let plain = independent
            .run(&crate::Algorithm::Form(crate::Form::default()), &())
            .unwrap();
        let mut moved = 0.0f64;
        for ((a, b), c) in own.cases.iter().zip(&again.cases).zip(&plain.cases) {
            assert!((a.beta - b.beta).abs() <= 1e-12 * a.beta.abs().max(1.0));
            moved = moved.max((a.beta - c.beta).abs());
        }
        assert!(moved > 1e-3, "the correlation changes some case: {moved}");
        let held = super::with_stds(&study, study.inputs().stds()).unwrap();
        assert_eq!(held.correlations(), &pair[..]);
    }
}
