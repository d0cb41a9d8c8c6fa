//! Allocation against the whole-machine acceptance probability reaching a
//! level `L` (spec reliability-v2 §4):
//! the same two strategies as the requirement target, with the acceptance
//! probability `P(σ)` of [`crate::acceptance`] and its sensitivities
//! `∂P/∂σ` in place of the per-case FORM reliabilities.
//!
//! - [`Strategy::Optimal`]: `min Σ wᵢ (σ0ᵢ/σᵢ − 1)` subject to `P(σ) ≥ L`,
//!   `min_stdᵢ ≤ σᵢ ≤ σ0ᵢ`, in `tᵢ = ln(σ0ᵢ/σᵢ)` (the cost is convex there)
//!   by sequential linearisation of the one constraint: at `t`, with
//!   `gᵢ = ∂P/∂tᵢ = −σᵢ·∂P/∂σᵢ`, the subproblem `min Σ wᵢ(e^{tᵢ'} − 1)`
//!   s.t. `P + g·(t' − t) ≥ L + margin` has the KKT solution
//!   `tᵢ'(λ) = clamp(ln(λ·gᵢ/wᵢ), 0, t_maxᵢ)`, `λ` by bisection; half of
//!   that step is taken within a trust region (radius 1 in `t`, halved when
//!   the linear model mispredicts the change of `P` beyond the noise,
//!   doubled back when it predicts well), and it stops when the
//!   re-evaluated `P` is within `[L + margin, L + margin + slack]`; when the
//!   region shrinks below 1e-3 or the linearisations run out, the cheapest
//!   point found that meets the level is the answer, or, if none did, the
//!   last point tightened along the errors that raise `P` until it does
//!   (`restore`: near the level the estimated gradient's noise makes the
//!   linearisations trade errors without gaining `P`). A fixed
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
use crate::acceptance::{Acceptance, AcceptanceResult, AcceptanceSampling, Rectangles};
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
/// Linearisations of the optimal strategy before it gives up (or returns
/// the best point found that meets the level).
const MAX_LINEARISATIONS: usize = 25;

fn evaluate_p(
    system: &Rectangles,
    stds: &[f64],
    acc: &Acceptance,
) -> Result<AcceptanceResult, ReliabilityError> {
    let inputs = system.inputs().with_stds(stds)?;
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
            sampling: AcceptanceSampling::MonteCarlo,
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
            // The cost `Σ wᵢ (e^{tᵢ} − 1)`, the best point meeting the level
            // so far (cost, stds, P) and the trust region's radius in t.
            let cost = |t: &[f64]| -> f64 {
                t.iter()
                    .zip(bounds)
                    .map(|(t, b)| b.cost_weight * (t.exp() - 1.0))
                    .sum()
            };
            let restore_from = |t: &[f64], at: &AcceptanceResult, evaluations: &mut usize| {
                let dp_dstd: Vec<f64> = at.sensitivity.iter().map(|s| s.dr_dstd).collect();
                let context = (&system, bounds, &tmax[..], &acc);
                restore(context, t, &dp_dstd, level, evaluations)
            };
            let mut best: Option<(f64, Vec<f64>, AcceptanceResult)> = None;
            let mut radius = 1.0f64;
            let mut iter = 0;
            while !done {
                iter += 1;
                if iter > MAX_LINEARISATIONS {
                    // The best point that meets the level, else the
                    // current one tightened until it does.
                    if let Some((_, s, _)) = best.take() {
                        stds = s;
                    } else {
                        (stds, _) = restore_from(&t, &current, &mut evaluations)?;
                    }
                    break;
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
                // Damped (half the step) within a trust region of `radius`
                // in t: P saturates in each tᵢ, so the full linearised step
                // over-rewards the steepest errors and oscillates.
                let mut moved = 0.0f64;
                for i in 0..n {
                    let step = (0.5 * (next[i] - t[i])).clamp(-radius, radius);
                    moved = moved.max(step.abs());
                    next[i] = t[i] + step;
                }
                let predicted: f64 = g
                    .iter()
                    .zip(next.iter().zip(&t))
                    .map(|(g, (a, b))| g * (a - b))
                    .sum();
                let before = current.probability;
                t = next;
                for i in 0..n {
                    stds[i] = bounds[i].std0 * (-t[i]).exp();
                }
                current = evaluate_p(&system, &stds, &acc)?;
                evaluations += 1;
                let target = level + margin(&current);
                if current.probability >= target {
                    let c = cost(&t);
                    if best.as_ref().is_none_or(|(bc, _, _)| c < *bc) {
                        best = Some((c, stds.clone(), current.clone()));
                    }
                }
                // The trust region: halved when the linear model mispredicts
                // the change of P (wrong sign or less than a quarter of it,
                // beyond the noise of the two estimates), so that the
                // iteration cannot cycle around the level; doubled back (up
                // to 1) when it predicts well.
                let actual = current.probability - before;
                let noise = 2.0 * current.std_error;
                let agrees = predicted.abs() <= noise
                    || (actual * predicted > 0.0 && actual.abs() >= 0.25 * predicted.abs());
                radius = if agrees {
                    (2.0 * radius).min(1.0)
                } else {
                    0.5 * radius
                };
                if current.probability >= target
                    && (current.probability <= target + slack || moved < 1e-3)
                {
                    done = true;
                } else if t.iter().zip(&tmax).all(|(a, b)| a >= b) && current.probability < target {
                    return Err(infeasible(bounds, level, current.probability));
                } else if radius < 1e-3 {
                    // The region has shrunk to nothing: the best point that
                    // meets the level (there is one unless the level is out
                    // of reach of these steps).
                    match best.take() {
                        Some((_, s, r)) => {
                            stds = s;
                            current = r;
                            done = true;
                        }
                        None => {
                            (stds, current) = restore_from(&t, &current, &mut evaluations)?;
                            done = true;
                        }
                    }
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
                            .map(|b| b.error.clone())
                            .collect(),
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
        Strategy::Optimal => super::StrategyName::Optimal,
        Strategy::Paper(_) => super::StrategyName::Paper,
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

/// Feasibility restoration of the optimal strategy, when the linearisations
/// end below the level (near it the noise of the estimated gradient makes
/// them trade errors against each other without gaining `P`): every error
/// whose tightening raises `P` (`∂P/∂σᵢ < 0`) is tightened by the same `δ`
/// in `tᵢ = ln(σ0ᵢ/σᵢ)` (within its bound), `δ` doubled from 0.01 until `P`
/// meets `L` + 3 standard errors and then bisected five times. `P` grows
/// with `δ`, so this ends, or the bounds are reached and the level is
/// infeasible.
fn restore(
    (system, bounds, tmax, acc): (&Rectangles, &[ErrorBounds], &[f64], &Acceptance),
    t: &[f64],
    dp_dstd: &[f64],
    level: f64,
    evaluations: &mut usize,
) -> Result<(Vec<f64>, AcceptanceResult), AllocateError> {
    let stds_at = |delta: f64| -> Vec<f64> {
        (0..t.len())
            .map(|i| {
                let ti = if dp_dstd[i] < 0.0 {
                    (t[i] + delta).min(tmax[i]).max(t[i])
                } else {
                    t[i]
                };
                bounds[i].std0 * (-ti).exp()
            })
            .collect()
    };
    let meets = |r: &AcceptanceResult| r.probability >= level + 3.0 * r.std_error;
    let mut lo = 0.0f64;
    let mut hi = 0.01f64;
    let found = loop {
        let stds = stds_at(hi);
        let r = evaluate_p(system, &stds, acc)?;
        *evaluations += 1;
        if meets(&r) {
            break (stds, r);
        }
        let saturated = (0..t.len()).all(|i| dp_dstd[i] >= 0.0 || t[i] + hi >= tmax[i]);
        if saturated || hi > 64.0 {
            return Err(infeasible(bounds, level, r.probability));
        }
        lo = hi;
        hi *= 2.0;
    };
    let mut best = found;
    for _ in 0..5 {
        let mid = 0.5 * (lo + hi);
        let stds = stds_at(mid);
        let r = evaluate_p(system, &stds, acc)?;
        *evaluations += 1;
        if meets(&r) {
            hi = mid;
            best = (stds, r);
        } else {
            lo = mid;
        }
    }
    Ok(best)
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
