//! Allocation against the whole-machine acceptance probability
//! (`chain allocate --target acceptance --level L`, spec reliability-v2 §4):
//! the same two strategies as the requirement target, with the acceptance
//! probability `P(σ)` of [`crate::acceptance`] and its sensitivities
//! `∂P/∂σ` in place of the per-case FORM reliabilities.
//!
//! - [`Strategy::Optimal`]: `min Σ wᵢ (σ0ᵢ/σᵢ − 1)` subject to `P(σ) ≥ L`,
//!   `min_stdᵢ ≤ σᵢ ≤ σ0ᵢ`, in `tᵢ = ln(σ0ᵢ/σᵢ)` (the cost is convex there)
//!   by sequential linearisation of the one constraint: at `t`, with
//!   `gᵢ = ∂P/∂tᵢ = −σᵢ·∂P/∂σᵢ`, the subproblem `min Σ wᵢ(e^{tᵢ'} − 1)`
//!   s.t. `P + g·(t' − t) ≥ L + margin` has the KKT solution
//!   `tᵢ'(λ) = clamp(ln(λ·gᵢ/wᵢ), 0, t_maxᵢ)`, `λ` by bisection; steps are
//!   limited to 1 in `t` (a trust region), and it stops when the
//!   re-evaluated `P` is within `[L + margin, L + margin + slack]`. A fixed
//!   point satisfies the KKT conditions of the original problem with the
//!   gradient at the solution. The margin is three standard errors of the
//!   estimate, so that an independent re-evaluation finds the level met.
//! - [`Strategy::Paper`]: Wang & Yuan's rounds with the acceptance
//!   sensitivity as the ranking: every error with `|∂P/∂σ|` at least a
//!   fraction of the largest is tightened by one step until `P ≥ L`.
//!
//! Every evaluation uses the same seed (common random numbers), so `P(σ)`
//! is a smooth function along the iterations.

use chain_core::ErrorModel;
use serde::Serialize;

use super::{component_summaries, evaluate, step_std};
use super::{AllocateError, Allocation, ErrorBounds, Paper, Step};
use crate::acceptance::{Acceptance, AcceptanceResult, Rectangles, Sampler};
use crate::error::ReliabilityError;
use crate::study::Study;

/// How to allocate against the acceptance probability.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Strategy {
    /// Least cost (sequential linearisation).
    Optimal,
    /// The paper's rounds ranked by `|∂P/∂σ|`.
    Paper(Paper),
}

/// The acceptance part of an [`Allocation`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AcceptanceAllocation {
    /// The required level `L`.
    pub level: f64,
    /// The acceptance probability with the initial standard deviations.
    pub initial: f64,
    /// The acceptance probability with the allocated ones (a fresh,
    /// independent evaluation: another seed).
    pub probability: f64,
    /// Its standard error.
    pub std_error: f64,
    /// Whether that evaluation converged.
    pub converged: bool,
    /// Evaluations of `P` (with sensitivities) during the allocation.
    pub evaluations: usize,
}

/// Samples per evaluation of `P` for non-normal inputs (2¹⁹).
const MC_SAMPLES: u64 = 1 << 19;

fn evaluate_p(
    system: &Rectangles,
    stds: &[f64],
    acc: &Acceptance,
) -> Result<AcceptanceResult, ReliabilityError> {
    let mut inputs = system.inputs().clone();
    for (j, &s) in stds.iter().enumerate() {
        let mean = inputs.means()[j];
        inputs = inputs.with_moments(j, mean, s)?;
    }
    acc.run(&system.with_inputs(inputs)?)
}

/// Allocates the standard deviations of `study`'s inputs so that the
/// acceptance probability reaches `level` (in (0, 1)).
pub fn acceptance<M: ErrorModel + ?Sized>(
    model: &M,
    parameters: &[f64],
    study: &Study,
    bounds: &[ErrorBounds],
    level: f64,
    strategy: Strategy,
) -> Result<Allocation, AllocateError> {
    if !(level > 0.0 && level < 1.0) {
        return Err(AllocateError::Unsupported(format!(
            "the acceptance level must be in (0, 1) (found {level})"
        )));
    }
    let system = Rectangles::from_study(study)?;
    let acc = if study.inputs().is_affine() {
        Acceptance {
            tolerance: 3e-4,
            ..Acceptance::default()
        }
    } else {
        // Monte Carlo: a fixed count with common random numbers, so that
        // `P(σ)` and its conditional derivatives move smoothly along the
        // iterations (a tolerance of 3e-4 would need ~10⁷ samples per
        // evaluation); the margin (3 standard errors, ~1.2e-3 at P = 0.9)
        // covers the re-evaluation with another seed.
        Acceptance {
            samples: Some(MC_SAMPLES),
            sampler: Sampler::MonteCarlo,
            ..Acceptance::default()
        }
    };
    let n = bounds.len();
    let std0: Vec<f64> = bounds.iter().map(|b| b.std0).collect();
    let (_, first) = evaluate(model, parameters, study, &std0)?;
    let initial_summaries = component_summaries(&first);
    let start = evaluate_p(&system, &std0, &acc)?;
    let mut evaluations = 1;
    let mut stds = std0.clone();
    let mut steps = Vec::new();
    let mut current = start.clone();
    match strategy {
        Strategy::Optimal => {
            let margin = |r: &AcceptanceResult| 3.0 * r.std_error;
            let slack = 2e-3;
            let tmax: Vec<f64> = bounds
                .iter()
                .map(|b| {
                    if b.min_std > 0.0 {
                        (b.std0 / b.min_std).ln().max(0.0)
                    } else {
                        (1e6f64).ln()
                    }
                })
                .collect();
            let mut t = vec![0.0; n];
            let mut done = current.probability >= level + margin(&current);
            let mut iter = 0;
            while !done {
                iter += 1;
                if iter > 40 {
                    return Err(AllocateError::NotConverged(format!(
                        "the acceptance allocation did not reach {level} within 40 linearisations (P = {})",
                        current.probability
                    )));
                }
                let g: Vec<f64> = (0..n)
                    .map(|i| (-stds[i] * current.sensitivity[i].dr_dstd).max(0.0))
                    .collect();
                let need = level + margin(&current) + 0.25 * slack - current.probability;
                let gt: f64 = g.iter().zip(&t).map(|(a, b)| a * b).sum();
                let at = |lambda: f64| -> Vec<f64> {
                    (0..n)
                        .map(|i| {
                            if g[i] <= 0.0 {
                                return t[i].min(tmax[i]);
                            }
                            let w = bounds[i].cost_weight.max(1e-300);
                            (lambda * g[i] / w).ln().clamp(0.0, tmax[i])
                        })
                        .collect()
                };
                let gain =
                    |tt: &[f64]| -> f64 { g.iter().zip(tt).map(|(a, b)| a * b).sum::<f64>() - gt };
                // Bisection on ln λ: the gain increases with λ.
                let (mut lo, mut hi) = (-700.0f64, 700.0f64);
                if gain(&at(hi.exp())) < need {
                    lo = hi;
                }
                for _ in 0..200 {
                    let mid = 0.5 * (lo + hi);
                    if gain(&at(mid.exp())) >= need {
                        hi = mid;
                    } else {
                        lo = mid;
                    }
                }
                let mut next = at(hi.exp());
                // Damped (half the step) within a trust region of 1 in t:
                // P saturates in each tᵢ, so the full linearised step
                // over-rewards the steepest errors and oscillates.
                let mut moved = 0.0f64;
                for i in 0..n {
                    let step = (0.5 * (next[i] - t[i])).clamp(-1.0, 1.0);
                    moved = moved.max(step.abs());
                    next[i] = t[i] + step;
                }
                t = next;
                for i in 0..n {
                    stds[i] = bounds[i].std0 * (-t[i]).exp();
                }
                current = evaluate_p(&system, &stds, &acc)?;
                evaluations += 1;
                let target = level + margin(&current);
                if current.probability >= target
                    && (current.probability <= target + slack || moved < 1e-3)
                {
                    done = true;
                } else if t.iter().zip(&tmax).all(|(a, b)| a >= b) && current.probability < target {
                    return Err(infeasible(bounds, level, current.probability));
                }
            }
        }
        Strategy::Paper(options) => {
            let mut round = 0;
            while current.probability < level + 3.0 * current.std_error {
                round += 1;
                if round > options.max_rounds {
                    break;
                }
                let score: Vec<f64> = current
                    .sensitivity
                    .iter()
                    .map(|s| s.dr_dstd.abs())
                    .collect();
                let can: Vec<bool> = (0..n)
                    .map(|j| stds[j] > bounds[j].min_std * (1.0 + 1e-12) && stds[j] > 0.0)
                    .collect();
                let max = (0..n)
                    .filter(|&j| can[j])
                    .map(|j| score[j])
                    .fold(0.0, f64::max);
                if max <= 0.0 {
                    return Err(AllocateError::Stalled {
                        round: round - 1,
                        component: "acceptance".into(),
                        errors: bounds
                            .iter()
                            .filter(|b| b.min_std > 0.0)
                            .map(|b| b.error.as_str())
                            .collect::<Vec<_>>()
                            .join(", "),
                    });
                }
                let mut tightened = Vec::new();
                let mut changed = Vec::new();
                for j in 0..n {
                    if !(can[j] && score[j] >= options.threshold * max) {
                        continue;
                    }
                    let d = step_std(bounds[j].kind, options.step);
                    let mut s = (stds[j] - d).max(bounds[j].min_std);
                    if s <= 0.0 {
                        s = 0.5 * stds[j];
                    }
                    stds[j] = s;
                    tightened.push(bounds[j].error.clone());
                    changed.push((bounds[j].error.clone(), s));
                }
                current = evaluate_p(&system, &stds, &acc)?;
                evaluations += 1;
                let (_, r) = evaluate(model, parameters, study, &stds)?;
                steps.push(Step {
                    round,
                    tightened,
                    std: changed,
                    summaries: component_summaries(&r),
                });
            }
        }
    }
    // The independent re-evaluation (another seed).
    let check = evaluate_p(
        &system,
        &stds,
        &Acceptance {
            seed: acc.seed + 1,
            sensitivity: false,
            ..acc.clone()
        },
    )?;
    let (_, last) = evaluate(model, parameters, study, &stds)?;
    let strategy_name = match strategy {
        Strategy::Optimal => "optimal",
        Strategy::Paper(_) => "paper",
    };
    let mut out = Allocation::new(
        strategy_name,
        initial_summaries,
        steps,
        bounds,
        &stds,
        component_summaries(&last),
        None,
    );
    out.met = check.probability >= level;
    out.acceptance = Some(AcceptanceAllocation {
        level,
        initial: start.probability,
        probability: check.probability,
        std_error: check.std_error,
        converged: check.converged,
        evaluations,
    });
    Ok(out)
}

fn infeasible(bounds: &[ErrorBounds], level: f64, best: f64) -> AllocateError {
    AllocateError::Infeasible {
        component: "acceptance".into(),
        what: "probability",
        at: None,
        best,
        required: level,
        binding: bounds
            .iter()
            .filter(|b| b.min_std > 0.0)
            .map(|b| format!("{} (min_std {:e})", b.error, b.min_std))
            .collect(),
    }
}
