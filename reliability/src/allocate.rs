//! Precision allocation (seed 000, Section 3.3, Tables 5-7): which standard
//! deviations to tighten so that every toleranced component meets the
//! requirement on its minimum and mean reliability over the grid.
//!
//! Two strategies:
//!
//! - [`paper`]: the paper's procedure. Each round ranks the errors of every
//!   component that misses the requirement by their grid-mean `|∂R/∂σ|`
//!   (per component, as Tables 5-7 do), tightens every error whose
//!   sensitivity is at least a fraction (10 %) of that component's largest by
//!   one step in the units of Table 1 (`step/6` mm for linear errors,
//!   `step/6000` rad for angular, `step/3000` rad for squareness), and
//!   re-evaluates with FORM.
//! - [`optimal`]: the least-cost standard deviations,
//!   `min Σ wᵢ (σ0ᵢ/σᵢ − 1)` subject to `R_case(σ) ≥ R_min` for every grid
//!   case of every component and `mean R(σ) ≥ R_mean` per component, with
//!   `min_stdᵢ ≤ σᵢ ≤ σ0ᵢ`. It works in `tᵢ = ln(σ0ᵢ/σᵢ)` (the cost is
//!   convex there), with the exact reliability `Φ(c/√V)` of a linear
//!   component in normal inputs and its exact first and second derivatives,
//!   by a log-barrier interior-point method (damped Newton per barrier
//!   parameter, strictly feasible iterates), then a Newton polish of the
//!   KKT system on the identified active set. The KKT conditions are checked
//!   and reported ([`Kkt`]).
//!
//! Infeasibility is exact, not a best effort: each reliability is increasing
//! in every `tᵢ`, so the requirement is feasible if and only if it holds with
//! every error at its lower bound (`min_std`); when it does not, the result
//! is [`AllocateError::Infeasible`] naming the component, the case and the
//! bounds that bind.

// Dense linear algebra over small index ranges reads best with indices.
#![allow(clippy::needless_range_loop)]

use chain_core::model::{Component, ErrorKind, Machine, Sided};
use chain_core::ErrorModel;
use serde::Serialize;

use crate::error::ReliabilityError;
use crate::form::Form;
use crate::inputs::{Inputs, Marginal};
use crate::normal;
use crate::study::{Study, StudyResult, Summary, Target};

/// The allocation data of one error parameter.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ErrorBounds {
    /// The error parameter.
    pub error: String,
    /// Linear, angular or squareness (sets the step of [`paper`]).
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

/// The outcome of an allocation.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Allocation {
    /// `optimal` or `paper`.
    pub strategy: &'static str,
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
    #[error("the paper's procedure stops after round {round}: {component} misses the requirement and none of its errors can be tightened further ({errors} at min_std or zero)")]
    Stalled {
        /// The last round.
        round: usize,
        /// The component.
        component: String,
        /// Its ranked errors.
        errors: String,
    },
    /// The optimiser did not converge.
    #[error("the optimiser did not converge: {0}")]
    NotConverged(String),
}

/// The study's inputs with other standard deviations (same families and means).
pub fn with_stds(study: &Study, stds: &[f64]) -> Result<Inputs, ReliabilityError> {
    let inputs = study.inputs();
    let marginals = inputs
        .marginals()
        .iter()
        .zip(stds)
        .map(|(m, &s)| m.with_moments(m.mean(), s))
        .collect::<Result<Vec<Marginal>, _>>()?;
    Inputs::new(inputs.names().to_vec(), marginals)
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
    let r = s.form(&Form::default())?;
    Ok((s, r))
}

fn component_summaries(r: &StudyResult) -> Vec<Summary> {
    r.summaries
        .iter()
        .filter(|s| matches!(s.target, crate::Target::Component(_)))
        .cloned()
        .collect()
}

fn all_met(s: &[Summary]) -> bool {
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

/// The paper's procedure (Tables 5-7).
pub fn paper<M: ErrorModel + ?Sized>(
    model: &M,
    parameters: &[f64],
    study: &Study,
    bounds: &[ErrorBounds],
    options: &Paper,
) -> Result<Allocation, AllocateError> {
    if study.spec().requirement.is_none() {
        return Err(AllocateError::NoRequirement);
    }
    if !(options.step > 0.0 && options.step.is_finite()) {
        return Err(AllocateError::Unsupported(format!(
            "the step must be positive (found {})",
            options.step
        )));
    }
    let mut stds: Vec<f64> = bounds.iter().map(|b| b.std0).collect();
    let (mut current, result) = evaluate(model, parameters, study, &stds)?;
    let initial = component_summaries(&result);
    let mut summaries = initial.clone();
    let mut steps = Vec::new();
    let form = Form::default();
    let mut round = 0;
    while !all_met(&summaries) && round < options.max_rounds {
        round += 1;
        let sens = current.sensitivity_mean(&form)?;
        let unmet: Vec<crate::Target> = summaries
            .iter()
            .filter(|s| s.met == Some(false))
            .map(|s| s.target)
            .collect();
        let n = stds.len();
        // Per-error score lists, one per ranking group.
        let mut groups: Vec<(String, Vec<f64>)> = Vec::new();
        for t in sens.iter().filter(|t| unmet.contains(&t.target)) {
            let mut score = vec![0.0; n];
            for e in &t.errors {
                if let Some(j) = bounds.iter().position(|b| b.error == e.error) {
                    score[j] = e.mean_abs_dr_dstd;
                }
            }
            if options.pooled {
                match groups.first_mut() {
                    Some((name, g)) => {
                        name.push('+');
                        name.push_str(t.target.name());
                        for (a, b) in g.iter_mut().zip(&score) {
                            *a += b;
                        }
                    }
                    None => groups.push((t.target.to_string(), score)),
                }
            } else {
                groups.push((t.target.to_string(), score));
            }
        }
        let mut chosen = vec![false; n];
        for (name, score) in &groups {
            // Only errors that can still be tightened compete.
            let can = |j: usize| stds[j] > bounds[j].min_std * (1.0 + 1e-12) && stds[j] > 0.0;
            let max = (0..n)
                .filter(|&j| can(j))
                .map(|j| score[j])
                .fold(0.0, f64::max);
            if max <= 0.0 {
                let mut ranked: Vec<usize> = (0..n).filter(|&j| score[j] > 0.0).collect();
                ranked.sort_by(|&a, &b| score[b].total_cmp(&score[a]));
                return Err(AllocateError::Stalled {
                    round: round - 1,
                    component: name.clone(),
                    errors: ranked
                        .iter()
                        .map(|&j| bounds[j].error.as_str())
                        .collect::<Vec<_>>()
                        .join(", "),
                });
            }
            for j in 0..n {
                if can(j) && score[j] >= options.threshold * max {
                    chosen[j] = true;
                }
            }
        }
        let mut tightened = Vec::new();
        let mut changed = Vec::new();
        for j in 0..n {
            if !chosen[j] {
                continue;
            }
            let d = step_std(bounds[j].kind, options.step);
            let mut s = (stds[j] - d).max(bounds[j].min_std);
            if s <= 0.0 {
                // Never to zero: halve what is left instead.
                s = 0.5 * stds[j];
            }
            stds[j] = s;
            tightened.push(bounds[j].error.clone());
            changed.push((bounds[j].error.clone(), s));
        }
        let (next, result) = evaluate(model, parameters, study, &stds)?;
        current = next;
        summaries = component_summaries(&result);
        steps.push(Step {
            round,
            tightened,
            std: changed,
            summaries: summaries.clone(),
        });
    }
    Ok(Allocation {
        strategy: "paper",
        initial,
        steps,
        std: bounds
            .iter()
            .zip(&stds)
            .map(|(b, s)| (b.error.clone(), *s))
            .collect(),
        cost: cost(bounds, &stds),
        met: all_met(&summaries),
        summaries,
        kkt: None,
    })
}

// ---------------------------------------------------------------------------
// The least-cost allocation.

/// One distinct grid case of one component.
#[derive(Debug, Clone)]
struct Case {
    comp: usize,
    /// `aⱼ²` over the variables.
    a2: Vec<f64>,
    /// Variance of the fixed errors' contribution.
    vfix: f64,
    /// `R = Σ sign·Φ(c/√V)`.
    terms: Vec<(f64, f64)>,
    /// Multiplicity / number of grid points.
    weight: f64,
    /// The first grid point with these coefficients.
    point: usize,
}

#[derive(Debug, Clone, Copy)]
enum Con {
    /// Case `k` reaches `level`.
    Case(usize, f64),
    /// The grid mean of component `c` reaches `level`.
    Mean(usize, f64),
}

struct Problem {
    /// Input index of each variable.
    var: Vec<usize>,
    w: Vec<f64>,
    s0: Vec<f64>,
    tmax: Vec<f64>,
    cases: Vec<Case>,
    comps: Vec<&'static str>,
    cons: Vec<Con>,
}

/// Values and derivatives of one case at `t`.
struct CaseEval {
    r: f64,
    grad: Vec<f64>,
    hess: Vec<f64>,
}

impl Problem {
    fn n(&self) -> usize {
        self.var.len()
    }

    fn case(&self, k: usize, t: &[f64], second: bool) -> CaseEval {
        let c = &self.cases[k];
        let n = self.n();
        let v: Vec<f64> = (0..n)
            .map(|j| c.a2[j] * self.s0[j] * self.s0[j] * (-2.0 * t[j]).exp())
            .collect();
        let vv = c.vfix + v.iter().sum::<f64>();
        let mut grad = vec![0.0; n];
        let mut hess = if second { vec![0.0; n * n] } else { Vec::new() };
        if vv <= 0.0 {
            let r = c
                .terms
                .iter()
                .map(|&(s, cc)| if cc > 0.0 { s } else { 0.0 })
                .sum();
            return CaseEval { r, grad, hess };
        }
        let mut r = 0.0;
        for &(sign, cc) in &c.terms {
            let beta = cc / vv.sqrt();
            r += sign * normal::cdf(beta);
            let phi = sign * normal::pdf(beta) * beta;
            if phi == 0.0 {
                continue;
            }
            for j in 0..n {
                grad[j] += phi * v[j] / vv;
            }
            if second {
                let a = (3.0 - beta * beta) / (vv * vv);
                for j in 0..n {
                    for l in 0..n {
                        hess[j * n + l] += phi * a * v[j] * v[l];
                    }
                    hess[j * n + j] -= phi * 2.0 * v[j] / vv;
                }
            }
        }
        CaseEval { r, grad, hess }
    }

    /// `g`, `∇g` and (optionally) `∇²g` of every constraint.
    fn constraints(&self, t: &[f64], second: bool) -> Vec<CaseEval> {
        let n = self.n();
        let evals: Vec<CaseEval> = (0..self.cases.len())
            .map(|k| self.case(k, t, second))
            .collect();
        self.cons
            .iter()
            .map(|con| match *con {
                Con::Case(k, level) => CaseEval {
                    r: evals[k].r - level,
                    grad: evals[k].grad.clone(),
                    hess: evals[k].hess.clone(),
                },
                Con::Mean(c, level) => {
                    let mut out = CaseEval {
                        r: -level,
                        grad: vec![0.0; n],
                        hess: if second { vec![0.0; n * n] } else { Vec::new() },
                    };
                    for (case, e) in self.cases.iter().zip(&evals) {
                        if case.comp != c {
                            continue;
                        }
                        out.r += case.weight * e.r;
                        for (a, b) in out.grad.iter_mut().zip(&e.grad) {
                            *a += case.weight * b;
                        }
                        for (a, b) in out.hess.iter_mut().zip(&e.hess) {
                            *a += case.weight * b;
                        }
                    }
                    out
                }
            })
            .collect()
    }

    fn cost(&self, t: &[f64]) -> f64 {
        self.w.iter().zip(t).map(|(w, t)| w * (t.exp() - 1.0)).sum()
    }

    /// The barrier function, `+∞` outside the domain.
    fn barrier(&self, t: &[f64], mu: f64) -> f64 {
        let mut phi = self.cost(t);
        for (j, &x) in t.iter().enumerate() {
            if x <= 0.0 || x >= self.tmax[j] {
                return f64::INFINITY;
            }
            phi -= mu * x.ln();
            if self.tmax[j].is_finite() {
                phi -= mu * (self.tmax[j] - x).ln();
            }
        }
        for g in self.constraints(t, false) {
            if g.r <= 0.0 {
                return f64::INFINITY;
            }
            phi -= mu * g.r.ln();
        }
        phi
    }

    fn con_name(&self, study: &Study, con: Con) -> String {
        match con {
            Con::Case(k, _) => {
                let c = &self.cases[k];
                format!(
                    "{} min at {}",
                    self.comps[c.comp],
                    point_name(study, c.point)
                )
            }
            Con::Mean(c, _) => format!("{} mean", self.comps[c]),
        }
    }
}

fn point_name(study: &Study, p: usize) -> String {
    // In the grid's axis order (x, y, z), then any other variable.
    let vars = study.variables();
    let mut order: Vec<usize> = study
        .spec()
        .grid
        .axes
        .iter()
        .filter_map(|(name, _)| vars.iter().position(|v| v == name))
        .collect();
    order.extend(
        (0..vars.len())
            .filter(|i| !order.contains(i))
            .collect::<Vec<_>>(),
    );
    order
        .iter()
        .map(|&i| format!("{}={}", vars[i], study.points()[p][i]))
        .collect::<Vec<_>>()
        .join(", ")
}

/// A short number: 6 significant digits, trailing zeros trimmed.
fn short(x: f64) -> String {
    let s = format!("{x:.5e}");
    match s.split_once('e') {
        Some((m, e)) if m.contains('.') => {
            format!("{}e{e}", m.trim_end_matches('0').trim_end_matches('.'))
        }
        _ => s,
    }
}

/// Solves `A x = b` (dense, row-major `n × n`) by Gaussian elimination with
/// partial pivoting; `None` when singular.
fn solve(mut a: Vec<f64>, mut b: Vec<f64>) -> Option<Vec<f64>> {
    let n = b.len();
    let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs())).max(1e-300);
    for col in 0..n {
        let piv =
            (col..n).max_by(|&i, &j| a[i * n + col].abs().total_cmp(&a[j * n + col].abs()))?;
        if a[piv * n + col].abs() <= 1e-14 * scale {
            return None;
        }
        if piv != col {
            for k in 0..n {
                a.swap(col * n + k, piv * n + k);
            }
            b.swap(col, piv);
        }
        for i in col + 1..n {
            let f = a[i * n + col] / a[col * n + col];
            if f != 0.0 {
                for k in col..n {
                    a[i * n + k] -= f * a[col * n + k];
                }
                b[i] -= f * b[col];
            }
        }
    }
    let mut x = vec![0.0; n];
    for i in (0..n).rev() {
        let s: f64 = (i + 1..n).map(|k| a[i * n + k] * x[k]).sum();
        x[i] = (b[i] - s) / a[i * n + i];
    }
    Some(x)
}

/// Cholesky solve of a symmetric positive definite system; `None` when not
/// positive definite.
fn cholesky_solve(a: &[f64], b: &[f64]) -> Option<Vec<f64>> {
    let n = b.len();
    let mut l = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..=i {
            let s: f64 = (0..j).map(|k| l[i * n + k] * l[j * n + k]).sum();
            if i == j {
                let d = a[i * n + i] - s;
                if d <= 0.0 || !d.is_finite() {
                    return None;
                }
                l[i * n + i] = d.sqrt();
            } else {
                l[i * n + j] = (a[i * n + j] - s) / l[j * n + j];
            }
        }
    }
    let mut y = vec![0.0; n];
    for i in 0..n {
        let s: f64 = (0..i).map(|k| l[i * n + k] * y[k]).sum();
        y[i] = (b[i] - s) / l[i * n + i];
    }
    let mut x = vec![0.0; n];
    for i in (0..n).rev() {
        let s: f64 = (i + 1..n).map(|k| l[k * n + i] * x[k]).sum();
        x[i] = (y[i] - s) / l[i * n + i];
    }
    Some(x)
}

/// `H d = −g` with `H` made positive definite by a growing multiple of `I`.
fn newton_direction(h: &[f64], g: &[f64]) -> Vec<f64> {
    let n = g.len();
    let rhs: Vec<f64> = g.iter().map(|x| -x).collect();
    let diag = (0..n)
        .fold(0.0f64, |m, i| m.max(h[i * n + i].abs()))
        .max(1e-12);
    let mut delta = 0.0;
    loop {
        let mut a = h.to_vec();
        for i in 0..n {
            a[i * n + i] += delta;
        }
        if let Some(d) = cholesky_solve(&a, &rhs) {
            return d;
        }
        delta = if delta == 0.0 {
            1e-10 * diag
        } else {
            delta * 10.0
        };
    }
}

fn build(study: &Study, bounds: &[ErrorBounds]) -> Result<Problem, AllocateError> {
    let spec = study.spec();
    let req = spec.requirement.ok_or(AllocateError::NoRequirement)?;
    let inputs = study.inputs();
    if let Some(j) = inputs.marginals().iter().position(|m| !m.is_normal()) {
        return Err(AllocateError::Unsupported(format!(
            "the optimal allocation needs normal inputs; `{}` is not normal (use --strategy paper)",
            inputs.names()[j]
        )));
    }
    let np = study.points().len();
    let ne = inputs.len();
    let comps: Vec<Component> = spec.tolerances.iter().map(|(c, _)| *c).collect();
    // Which errors drive a toleranced component.
    let mut used = vec![false; ne];
    for &c in &comps {
        for p in 0..np {
            for (j, a) in study.row(p, c).iter().enumerate() {
                if *a != 0.0 {
                    used[j] = true;
                }
            }
        }
    }
    let mut var = Vec::new();
    for j in 0..ne {
        let b = &bounds[j];
        if used[j] && b.min_std < b.std0 {
            if !(b.cost_weight > 0.0 && b.cost_weight.is_finite()) {
                return Err(AllocateError::Unsupported(format!(
                    "cost_weight of `{}` must be positive for the optimal allocation (found {})",
                    b.error, b.cost_weight
                )));
            }
            var.push(j);
        }
    }
    let means = inputs.means();
    let stds = inputs.stds();
    let mut cases: Vec<Case> = Vec::new();
    let mut keys: Vec<Vec<u64>> = Vec::new();
    for (ci, &(c, tol)) in spec.tolerances.iter().enumerate() {
        for p in 0..np {
            let row = study.row(p, c);
            let m: f64 = row.iter().zip(means).map(|(a, mu)| a * mu).sum();
            let a2: Vec<f64> = var.iter().map(|&j| row[j] * row[j]).collect();
            let vfix: f64 = (0..ne)
                .filter(|j| !var.contains(j))
                .map(|j| row[j] * row[j] * stds[j] * stds[j])
                .sum();
            let terms = match spec.sided {
                Sided::Upper => vec![(1.0, tol - m)],
                Sided::Two => vec![(1.0, tol - m), (-1.0, -tol - m)],
            };
            let mut key: Vec<u64> = vec![ci as u64, vfix.to_bits()];
            key.extend(a2.iter().map(|x| x.to_bits()));
            key.extend(terms.iter().map(|(_, c)| c.to_bits()));
            match keys.iter().position(|k| *k == key) {
                Some(k) => cases[k].weight += 1.0 / np as f64,
                None => {
                    keys.push(key);
                    cases.push(Case {
                        comp: ci,
                        a2,
                        vfix,
                        terms,
                        weight: 1.0 / np as f64,
                        point: p,
                    });
                }
            }
        }
    }
    let mut cons = Vec::new();
    for ci in 0..comps.len() {
        let ks: Vec<usize> = (0..cases.len()).filter(|&k| cases[k].comp == ci).collect();
        if ks.len() == 1 {
            // One distinct case: its mean is the case itself.
            cons.push(Con::Case(ks[0], req.min.max(req.mean)));
        } else {
            for &k in &ks {
                cons.push(Con::Case(k, req.min));
            }
            cons.push(Con::Mean(ci, req.mean));
        }
    }
    Ok(Problem {
        w: var.iter().map(|&j| bounds[j].cost_weight).collect(),
        s0: var.iter().map(|&j| bounds[j].std0).collect(),
        tmax: var
            .iter()
            .map(|&j| {
                let b = &bounds[j];
                if b.min_std > 0.0 {
                    (b.std0 / b.min_std).ln()
                } else {
                    f64::INFINITY
                }
            })
            .collect(),
        var,
        cases,
        comps: comps.iter().map(|c| c.name()).collect(),
        cons,
    })
}

/// The least-cost standard deviations meeting the requirement.
pub fn optimal<M: ErrorModel + ?Sized>(
    model: &M,
    parameters: &[f64],
    study: &Study,
    bounds: &[ErrorBounds],
    options: &Optimal,
) -> Result<Allocation, AllocateError> {
    let mut problem = build(study, bounds)?;
    let initial = component_summaries(&study.form(&Form::default())?);
    let n = problem.n();
    let stds0: Vec<f64> = bounds.iter().map(|b| b.std0).collect();
    // Impose the requirement with a small margin.
    let levels: Vec<f64> = problem
        .cons
        .iter()
        .map(|c| match *c {
            Con::Case(_, l) | Con::Mean(_, l) => l,
        })
        .collect();
    for c in problem.cons.iter_mut() {
        match c {
            Con::Case(_, l) | Con::Mean(_, l) => *l = (*l + options.margin).min(1.0),
        }
    }
    // Already met: nothing to tighten.
    let zero = vec![0.0; n];
    if problem.constraints(&zero, false).iter().all(|g| g.r >= 0.0) {
        return finish(model, parameters, study, bounds, initial, stds0, None);
    }
    // Feasibility at the bounds (every reliability increases with every t).
    let big = 40.0;
    let t_hi: Vec<f64> = problem.tmax.iter().map(|&m| m.min(big)).collect();
    let g_hi = problem.constraints(&t_hi, false);
    if let Some((k, g)) = g_hi.iter().enumerate().find(|(_, g)| g.r < 0.0) {
        let con = problem.cons[k];
        let (comp, what, at, required) = match con {
            Con::Case(i, _) => {
                let c = &problem.cases[i];
                (
                    c.comp,
                    "minimum reliability",
                    Some(point_name(study, c.point)),
                    levels[k],
                )
            }
            Con::Mean(c, _) => (c, "mean reliability", None, levels[k]),
        };
        // The bounded errors that drive this component, by contribution.
        let mut contrib: Vec<(usize, f64)> = Vec::new();
        for case in problem.cases.iter().filter(|c| c.comp == comp) {
            for (i, &j) in problem.var.iter().enumerate() {
                let v = case.a2[i] * bounds[j].min_std * bounds[j].min_std;
                if v > 0.0 {
                    match contrib.iter_mut().find(|(x, _)| *x == j) {
                        Some(e) => e.1 = e.1.max(v),
                        None => contrib.push((j, v)),
                    }
                }
            }
        }
        // Errors held fixed (min_std ≥ std) bind too.
        let tol = study.spec().tolerances[comp].0;
        for j in 0..bounds.len() {
            if !problem.var.contains(&j)
                && (0..study.points().len()).any(|p| study.row(p, tol)[j] != 0.0)
            {
                contrib.push((j, f64::MAX));
            }
        }
        contrib.sort_by(|a, b| b.1.total_cmp(&a.1));
        return Err(AllocateError::Infeasible {
            component: problem.comps[comp].to_string(),
            what,
            at,
            best: g.r + levels[k] + options.margin,
            required,
            binding: contrib
                .iter()
                .map(|&(j, _)| {
                    format!("{} (min_std {})", bounds[j].error, short(bounds[j].min_std))
                })
                .collect(),
        });
    }
    // A strictly feasible start on the ray t = s·t_hi (reliabilities increase with s).
    let inner = |s: f64| -> Vec<f64> {
        problem
            .tmax
            .iter()
            .map(|&m| {
                let hi = if m.is_finite() { m * (1.0 - 1e-9) } else { big };
                s * hi
            })
            .collect()
    };
    let feasible = |t: &[f64]| problem.constraints(t, false).iter().all(|g| g.r > 0.0);
    if !feasible(&inner(1.0)) {
        return Err(AllocateError::NotConverged(
            "the feasible set has no interior (the requirement is met only with errors exactly at min_std)"
                .into(),
        ));
    }
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if feasible(&inner(mid)) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let s = (hi * 1.05).min(0.5 * (hi + 1.0)).max(hi);
    let mut t = inner(if feasible(&inner(s)) { s } else { 1.0 });
    // Barrier path.
    let m_total = problem.cons.len() + n + problem.tmax.iter().filter(|m| m.is_finite()).count();
    let mut mu = (0.1 * problem.cost(&t).max(1.0) / m_total as f64).max(1e-6);
    let mut iterations = 0;
    loop {
        for _ in 0..200 {
            iterations += 1;
            let gs = problem.constraints(&t, true);
            let mut grad: Vec<f64> = (0..n).map(|j| problem.w[j] * t[j].exp()).collect();
            let mut h = vec![0.0; n * n];
            for j in 0..n {
                h[j * n + j] = problem.w[j] * t[j].exp();
                grad[j] -= mu / t[j];
                h[j * n + j] += mu / (t[j] * t[j]);
                if problem.tmax[j].is_finite() {
                    let u = problem.tmax[j] - t[j];
                    grad[j] += mu / u;
                    h[j * n + j] += mu / (u * u);
                }
            }
            for g in &gs {
                for j in 0..n {
                    grad[j] -= mu * g.grad[j] / g.r;
                    for l in 0..n {
                        h[j * n + l] +=
                            mu * (g.grad[j] * g.grad[l] / (g.r * g.r) - g.hess[j * n + l] / g.r);
                    }
                }
            }
            let d = newton_direction(&h, &grad);
            let slope: f64 = grad.iter().zip(&d).map(|(a, b)| a * b).sum();
            if -slope < 1e-13 * (1.0 + problem.cost(&t)) {
                break;
            }
            let phi0 = problem.barrier(&t, mu);
            let mut alpha = 1.0;
            let mut moved = false;
            for _ in 0..60 {
                let trial: Vec<f64> = t.iter().zip(&d).map(|(x, y)| x + alpha * y).collect();
                if problem.barrier(&trial, mu) <= phi0 + 1e-4 * alpha * slope {
                    t = trial;
                    moved = true;
                    break;
                }
                alpha *= 0.5;
            }
            if !moved {
                break;
            }
        }
        if mu * m_total as f64 <= 1e-11 {
            break;
        }
        mu *= 0.1;
    }
    // Multipliers of the barrier solution.
    let gs = problem.constraints(&t, false);
    let lambda: Vec<f64> = gs.iter().map(|g| mu / g.r).collect();
    let (t, lambda, polished, extra) = match polish(&problem, &t, &lambda, &gs, mu) {
        Some((t, l, it)) => (t, l, true, it),
        None => (t, lambda, false, 0),
    };
    let kkt = kkt(
        &problem,
        study,
        &t,
        &lambda,
        polished,
        mu,
        iterations + extra,
    );
    let mut stds = stds0.clone();
    for (i, &j) in problem.var.iter().enumerate() {
        stds[j] = problem.s0[i] * (-t[i]).exp();
        if bounds[j].min_std > 0.0 {
            stds[j] = stds[j].max(bounds[j].min_std);
        }
    }
    finish(model, parameters, study, bounds, initial, stds, Some(kkt))
}

/// Newton on the KKT system of the active set identified by the barrier
/// solution; `None` if it does not converge to a KKT point.
fn polish(
    p: &Problem,
    t0: &[f64],
    lambda0: &[f64],
    gs: &[CaseEval],
    mu: f64,
) -> Option<(Vec<f64>, Vec<f64>, usize)> {
    let n = p.n();
    let active: Vec<usize> = (0..gs.len()).filter(|&k| lambda0[k] > gs[k].r).collect();
    // Variables at a bound: 0 = free, 1 = lower (t = 0), 2 = upper (t = tmax).
    let fixed: Vec<u8> = (0..n)
        .map(|j| {
            if mu / t0[j] > t0[j] {
                1
            } else if p.tmax[j].is_finite() && mu / (p.tmax[j] - t0[j]) > p.tmax[j] - t0[j] {
                2
            } else {
                0
            }
        })
        .collect();
    let free: Vec<usize> = (0..n).filter(|&j| fixed[j] == 0).collect();
    let mut t: Vec<f64> = (0..n)
        .map(|j| match fixed[j] {
            1 => 0.0,
            2 => p.tmax[j],
            _ => t0[j],
        })
        .collect();
    let mut lam: Vec<f64> = active.iter().map(|&k| lambda0[k]).collect();
    let nf = free.len();
    let na = active.len();
    let dim = nf + na;
    let mut it = 0;
    let mut converged = false;
    for _ in 0..50 {
        it += 1;
        let gs = p.constraints(&t, true);
        let mut r = vec![0.0; dim];
        let mut kmat = vec![0.0; dim * dim];
        for (a, &j) in free.iter().enumerate() {
            r[a] = p.w[j] * t[j].exp();
            kmat[a * dim + a] += p.w[j] * t[j].exp();
            for (b, &k) in active.iter().enumerate() {
                r[a] -= lam[b] * gs[k].grad[j];
                kmat[a * dim + nf + b] = -gs[k].grad[j];
                kmat[(nf + b) * dim + a] = gs[k].grad[j];
                for (c, &l) in free.iter().enumerate() {
                    kmat[a * dim + c] -= lam[b] * gs[k].hess[j * n + l];
                }
            }
        }
        for (b, &k) in active.iter().enumerate() {
            r[nf + b] = gs[k].r;
        }
        let norm = r.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        if norm < 1e-14 {
            converged = true;
            break;
        }
        let d = solve(kmat, r.iter().map(|x| -x).collect())?;
        for (a, &j) in free.iter().enumerate() {
            t[j] += d[a];
        }
        for b in 0..na {
            lam[b] += d[nf + b];
        }
        if !t.iter().all(|x| x.is_finite()) {
            return None;
        }
    }
    if !converged {
        // Accept a stalled Newton only at round-off level.
        let gs = p.constraints(&t, false);
        if active.iter().any(|&k| gs[k].r.abs() > 1e-12) {
            return None;
        }
    }
    let mut full = vec![0.0; gs.len()];
    for (b, &k) in active.iter().enumerate() {
        full[k] = lam[b];
    }
    // A KKT point: multipliers ≥ 0, inactive constraints and bounds hold.
    let g = p.constraints(&t, false);
    let ok_l = lam.iter().all(|&l| l >= -1e-10);
    let ok_g = g.iter().all(|g| g.r >= -1e-12);
    let ok_t = (0..n).all(|j| t[j] >= -1e-12 && t[j] <= p.tmax[j] + 1e-12);
    if !(ok_l && ok_g && ok_t) {
        return None;
    }
    let (st, _, _, dual) = residuals(p, &t, &full);
    if st > 1e-8 || dual > 1e-8 {
        return None;
    }
    Some((t, full, it))
}

/// Stationarity, complementarity, feasibility and dual feasibility, with
/// bound multipliers taken from the stationarity residual of variables at a
/// bound.
fn residuals(p: &Problem, t: &[f64], lambda: &[f64]) -> (f64, f64, f64, f64) {
    let n = p.n();
    let gs = p.constraints(t, false);
    let mut st = 0.0f64;
    let mut comp = 0.0f64;
    let mut feas = 0.0f64;
    let mut dual = 0.0f64;
    for (g, l) in gs.iter().zip(lambda) {
        comp = comp.max((l * g.r).abs());
        feas = feas.max(-g.r);
        dual = dual.max(-l);
    }
    for j in 0..n {
        let mut r = p.w[j] * t[j].exp();
        for (g, l) in gs.iter().zip(lambda) {
            r -= l * g.grad[j];
        }
        feas = feas.max(-t[j]).max(t[j] - p.tmax[j]);
        let at_lower = t[j] <= 1e-9;
        let at_upper = p.tmax[j].is_finite() && p.tmax[j] - t[j] <= 1e-9;
        if at_lower {
            // r = z ≥ 0.
            dual = dual.max(-r);
            comp = comp.max((r * t[j]).abs());
        } else if at_upper {
            // r = −z_u ≤ 0.
            dual = dual.max(r);
            comp = comp.max((r * (p.tmax[j] - t[j])).abs());
        } else {
            st = st.max(r.abs());
        }
    }
    (st, comp, feas.max(0.0), dual.max(0.0))
}

fn kkt(
    p: &Problem,
    study: &Study,
    t: &[f64],
    lambda: &[f64],
    polished: bool,
    mu: f64,
    iterations: usize,
) -> Kkt {
    let (stationarity, complementarity, feasibility, dual_feasibility) = if polished {
        residuals(p, t, lambda)
    } else {
        // The barrier point: bound multipliers μ/t and μ/(tmax − t).
        let n = p.n();
        let gs = p.constraints(t, false);
        let mut st = 0.0f64;
        for j in 0..n {
            let mut r = p.w[j] * t[j].exp() - mu / t[j];
            if p.tmax[j].is_finite() {
                r += mu / (p.tmax[j] - t[j]);
            }
            for (g, l) in gs.iter().zip(lambda) {
                r -= l * g.grad[j];
            }
            st = st.max(r.abs());
        }
        let feas = gs.iter().fold(0.0f64, |m, g| m.max(-g.r));
        (st, mu, feas, 0.0)
    };
    let mut active: Vec<(String, f64)> = p
        .cons
        .iter()
        .zip(lambda)
        .filter(|(_, &l)| l > 1e-12)
        .map(|(&c, &l)| (p.con_name(study, c), l))
        .collect();
    active.sort_by(|a, b| b.1.total_cmp(&a.1));
    let gs = p.constraints(t, false);
    let at_bound = (0..p.n())
        .filter_map(|j| {
            let name = study.inputs().names()[p.var[j]].clone();
            let mut r = p.w[j] * t[j].exp();
            for (g, l) in gs.iter().zip(lambda) {
                r -= l * g.grad[j];
            }
            if t[j] <= 1e-9 {
                Some((name, "unchanged", r))
            } else if p.tmax[j].is_finite() && p.tmax[j] - t[j] <= 1e-9 {
                Some((name, "min_std", -r))
            } else {
                None
            }
        })
        .collect();
    Kkt {
        stationarity,
        complementarity,
        feasibility,
        dual_feasibility,
        active,
        at_bound,
        iterations,
        polished,
    }
}

fn finish<M: ErrorModel + ?Sized>(
    model: &M,
    parameters: &[f64],
    study: &Study,
    bounds: &[ErrorBounds],
    initial: Vec<Summary>,
    stds: Vec<f64>,
    kkt: Option<Kkt>,
) -> Result<Allocation, AllocateError> {
    let (_, result) = evaluate(model, parameters, study, &stds)?;
    let summaries = component_summaries(&result);
    Ok(Allocation {
        strategy: "optimal",
        initial,
        steps: Vec::new(),
        std: bounds
            .iter()
            .zip(&stds)
            .map(|(b, s)| (b.error.clone(), *s))
            .collect(),
        cost: cost(bounds, &stds),
        met: all_met(&summaries),
        summaries,
        kkt,
    })
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
    use super::*;
    use crate::sensitivity::sensitivity;

    const YAML: &str = "
machine: m
bodies:
  bed: {}
  xs: {parent: bed, joint: {type: prismatic, axis: +x, variable: x}, errors: {dx: a, ez: b}}
  ys: {parent: xs, joint: {type: prismatic, axis: +y, variable: y}, errors: {dx: c}}
workpiece: bed
tool: ys
statistics:
  a: {dist: normal, mean: 0.001, std: 0.01}
  b: {dist: normal, mean: 0, std: 0.00005}
  c: {dist: normal, mean: -0.002, std: 0.008, min_std: 0.001}
reliability:
  tolerance: {px: 0.03}
  sided: SIDED
  grid: {x: [0], y: [100, 300, 500]}
  requirement: {min: 0.9, mean: 0.95}
";

    fn setup(sided: &str) -> (chain_core::CompiledModel, Study, Vec<ErrorBounds>) {
        let m = chain_core::load_str(&YAML.replace("SIDED", sided), "m.yaml").unwrap();
        let model = chain_core::compile(&m);
        let study = crate::machine::study(&m, &model, &[], None).unwrap();
        let b = bounds(&m, &study).unwrap();
        (model, study, b)
    }

    #[test]
    fn case_derivatives_match_finite_differences_and_the_sensitivities() {
        for sided in ["upper", "two"] {
            let (_, study, b) = setup(sided);
            let p = build(&study, &b).unwrap();
            let n = p.n();
            assert_eq!(n, 3);
            let t = [0.3, 0.7, 0.2];
            for k in 0..p.cases.len() {
                let e = p.case(k, &t, true);
                for j in 0..n {
                    let h = 1e-6;
                    let mut tp = t;
                    let mut tm = t;
                    tp[j] += h;
                    tm[j] -= h;
                    let (ep, em) = (p.case(k, &tp, true), p.case(k, &tm, true));
                    let fd = (ep.r - em.r) / (2.0 * h);
                    assert!((fd - e.grad[j]).abs() < 1e-7, "{sided} grad {k} {j}");
                    for l in 0..n {
                        let fd = (ep.grad[l] - em.grad[l]) / (2.0 * h);
                        assert!((fd - e.hess[j * n + l]).abs() < 1e-6, "{sided} hess");
                    }
                }
            }
        }
        // ∂R/∂t = −σ ∂R/∂σ with the engine's exact sensitivities (upper).
        let (_, study, b) = setup("upper");
        let p = build(&study, &b).unwrap();
        let zero = [0.0; 3];
        for (k, case) in p.cases.iter().enumerate() {
            let ev = study
                .event(Target::Component(Component::Px), case.point)
                .unwrap();
            let f = Form::default().run(&ev).unwrap();
            let s = sensitivity(&ev, &f).unwrap();
            let e = p.case(k, &zero, false);
            assert!((e.r - f.reliability).abs() < 1e-12);
            for (i, &j) in p.var.iter().enumerate() {
                let want = -b[j].std0 * s.inputs[j].dr_dstd;
                assert!((e.grad[i] - want).abs() < 1e-9 * (1.0 + want.abs()));
            }
        }
    }

    #[test]
    fn optimum_is_kkt_and_bounds_hold_with_nonzero_means() {
        for sided in ["upper", "two"] {
            let (model, study, b) = setup(sided);
            let r = optimal(&model, &[], &study, &b, &Optimal::default()).unwrap();
            let k = r.kkt.as_ref().unwrap();
            assert!(k.residual() < 1e-8, "{sided}: {k:?}");
            for (bb, (_, s)) in b.iter().zip(&r.std) {
                assert!(*s <= bb.std0 && *s >= bb.min_std);
            }
            assert!(r.cost > 0.0 && r.met);
        }
    }
}
