//! The whole-machine acceptance probability (spec reliability-v2 §4): the
//! probability that a machine built with these statistics is within
//! tolerance at every point of the grid and for every toleranced component
//! at once, with its sensitivities to every mean and standard deviation.
//!
//! The event is a series system over `K` = points × components linear
//! constraints `l_i ≤ S_i·x ≤ h_i` (`S_i` the sensitivity row of one
//! component at one point, `l_i = −∞` for one-sided tolerances). The errors
//! are the same random variables at every point, so the events are strongly
//! correlated and the per-point reliabilities do not multiply.
//!
//! # Normal inputs: Genz's separation of variables, quasi-Monte Carlo
//!
//! For normal inputs (independent, or the correlated block of
//! [`Inputs::correlated`]) `x = μ + B·u`, so `S·x = m + A·u` with
//! `A = S·B` (`K × n`, rank `r ≤ n`: 21 errors against 1,125 rows on the
//! gantry grid) and the probability is the multivariate normal rectangle
//! probability `P(l ≤ m + A·u ≤ h)` of a singular covariance `A·Aᵀ`.
//! Following Genz & Bretz (2009), *Computation of Multivariate Normal and t
//! Probabilities*, §2.3 (the singular case, after Genz & Kwong 2000), the
//! integral is taken in the `r` independent coordinates of the inputs, not
//! in the `K` correlated constraints: a pivoted Gram–Schmidt (an LQ
//! factorisation `A = L·Q`, `Q` with `r` orthonormal rows) makes `L` lower
//! trapezoidal, so that constraint `i` involves `w_1 … w_{k(i)}` only,
//! `w = Q·u ~ N(0, I_r)`. The separation of variables (Genz 1992, §2.1 of
//! Genz & Bretz) then writes
//! `P = ∫_{[0,1]^r} Π_k (Φ(b_k) − Φ(a_k)) dz`, with `[a_k, b_k]` the
//! intersection over the constraints of column `k` of
//! `(l_i − Σ_{j<k} L_ij w_j)/L_ik … (h_i − …)/L_ik` and
//! `w_k = Φ⁻¹(Φ(a_k) + z_k·(Φ(b_k) − Φ(a_k)))`. The pivot of column `k` is
//! the constraint with the smallest conditional probability
//! `Φ(b̃) − Φ(ã)` at the expected values of the previous `w` (the
//! variable-prioritisation heuristic of Genz & Bretz §4.1.3); a constraint
//! whose residual row vanishes is assigned to the current column. Exact
//! duplicate rows (a component that does not depend on one grid axis) are
//! merged into one interval first.
//!
//! The integral is estimated by randomised quasi-Monte Carlo (Genz & Bretz
//! §4.2.2): a Richtmyer (Kronecker) sequence `frac(i·√p_k)` over the first
//! `r` primes, `shifts` independent uniform random shifts, the baker's
//! (tent) periodisation `z ↦ 1 − |2z − 1|`, and the standard error of the
//! mean over the shifts. The points per shift double until three standard
//! errors are below the requested absolute error ([`Acceptance::tolerance`]).
//!
//! Sensitivities (the same samples): by the score function in `u`, for
//! `x = μ + B·u`, `∂P/∂μ_j = E[1_safe·(B⁻ᵀu)_j]` and
//! `∂P/∂σ_j = E[1_safe·((B⁻ᵀu)_j·(B·u)_j − 1)]/σ_j` (Rubinstein &
//! Shapiro's likelihood-ratio derivative of `P = E[1_safe]` under
//! `u ↦ B⁻¹(B + δB)u`; the correlation matrix held fixed). The separation of
//! variables gives `∫ f(z)·h(w(z)) dz = E[1_safe·h(u)]` for any `h`
//! (`f·density(w) = φ_r(w)·1_safe`), and the `n − r` coordinates of `u`
//! orthogonal to `Q` are independent of the event and integrate out exactly:
//! with `u_Q = Qᵀw`, `E[(B⁻ᵀu)_j | w] = (B⁻ᵀQᵀw)_j` and
//! `E[(B⁻ᵀu)_j(Bu)_j − 1 | w] = (B⁻ᵀQᵀw)_j(BQᵀw)_j − (B⁻ᵀQᵀQBᵀ)_jj`.
//!
//! # Other marginals: Monte Carlo with conditional derivatives
//!
//! For non-normal inputs the probability is crude Monte Carlo through
//! [`Inputs::sample`] (any marginal of [`Inputs`]), with its binomial
//! standard error. The derivatives of an independent input `j` are
//! conditional Monte Carlo (the smoothed estimator): given the other
//! inputs, every constraint is linear in `x_j`, so the safe set is an
//! interval `[a, b]` of `x_j` (empty unless every violated constraint
//! involves `x_j`), `P = E[F_j(b) − F_j(a)]` and
//! `∂F_j(b)/∂θ = −f_j(b)·∂x/∂θ|_{u = T⁻¹(b)}` with `f_j = φ(u)/(dx/du)`
//! ([`Marginal::dx_dmean`], [`Marginal::dx_dstd`]). Inputs of the correlated
//! normal block use the Gaussian score `Σ_B⁻¹(x_B − μ_B)`.

// Dense kernels over small index ranges read best with indices.
#![allow(clippy::needless_range_loop)]

use std::collections::HashMap;

use chain_core::model::Sided;
use serde::Serialize;

use crate::error::ReliabilityError;
use crate::inputs::{Inputs, Marginal};
use crate::normal;
use crate::par::prelude::*;
use crate::rng::CaseRng;
use crate::study::Study;
use crate::util::dot;

mod rare;

pub use rare::{AcceptanceSubset, RareSide};

/// The series system of linear constraints `lower_i ≤ S_i·x ≤ upper_i`
/// over the inputs (every point × every toleranced component of a study).
///
/// ```
/// use reliability::{acceptance::Rectangles, Inputs, Marginal};
/// let inputs = Inputs::new(vec!["a".into()], vec![Marginal::normal(0.0, 1.0).unwrap()]).unwrap();
/// // −1 ≤ a ≤ 1 and a ≤ 0.5: one merged interval.
/// let r = Rectangles::new(inputs, vec![1.0, 1.0], vec![-1.0, f64::NEG_INFINITY], vec![1.0, 0.5]).unwrap();
/// assert_eq!((r.constraints(), r.distinct()), (2, 1));
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Rectangles {
    inputs: Inputs,
    /// Distinct rows, `k × n` row-major.
    rows: Vec<f64>,
    lower: Vec<f64>,
    upper: Vec<f64>,
    /// Constraints before merging duplicates.
    constraints: usize,
}

impl Rectangles {
    /// The constraints `lower_i ≤ rows_i·x ≤ upper_i` (`rows` is `K × n`
    /// row-major, `n = inputs.len()`; `lower` may be `−∞`, `upper` `+∞`).
    /// Rows equal bit for bit are merged (their intervals intersected).
    pub fn new(
        inputs: Inputs,
        rows: Vec<f64>,
        lower: Vec<f64>,
        upper: Vec<f64>,
    ) -> Result<Rectangles, ReliabilityError> {
        let n = inputs.len();
        let k = lower.len();
        if n == 0 {
            return Err(ReliabilityError::Dimension {
                what: "acceptance inputs",
                expected: 1,
                found: 0,
            });
        }
        if rows.len() != k * n {
            return Err(ReliabilityError::Dimension {
                what: "acceptance rows",
                expected: k * n,
                found: rows.len(),
            });
        }
        if upper.len() != k {
            return Err(ReliabilityError::Dimension {
                what: "acceptance upper bounds",
                expected: k,
                found: upper.len(),
            });
        }
        if k == 0 {
            return Err(ReliabilityError::EmptyGrid(
                "no acceptance constraint".into(),
            ));
        }
        if rows.iter().any(|v| !v.is_finite())
            || lower.iter().chain(&upper).any(|v| v.is_nan())
            || lower.contains(&f64::INFINITY)
            || upper.contains(&f64::NEG_INFINITY)
        {
            return Err(ReliabilityError::NonFinite("the acceptance constraints"));
        }
        let mut index: HashMap<Vec<u64>, usize> = HashMap::new();
        let (mut r, mut lo, mut hi) = (Vec::new(), Vec::new(), Vec::new());
        for i in 0..k {
            let row = &rows[i * n..(i + 1) * n];
            // +0.0 and −0.0 are the same coefficient.
            let key: Vec<u64> = row.iter().map(|v| (v + 0.0).to_bits()).collect();
            match index.get(&key) {
                Some(&d) => {
                    lo[d] = f64::max(lo[d], lower[i]);
                    hi[d] = f64::min(hi[d], upper[i]);
                }
                None => {
                    index.insert(key, lo.len());
                    r.extend_from_slice(row);
                    lo.push(lower[i]);
                    hi.push(upper[i]);
                }
            }
        }
        Ok(Rectangles {
            inputs,
            rows: r,
            lower: lo,
            upper: hi,
            constraints: k,
        })
    }

    /// Every toleranced component at every point of `study`:
    /// `E_c ≤ I_c` (one-sided) or `−I_c ≤ E_c ≤ I_c` (two-sided).
    pub fn from_study(study: &Study) -> Result<Rectangles, ReliabilityError> {
        if study.varies() {
            // One rectangle set over one set of inputs: a posterior whose
            // inputs differ from point to point has no such set.
            return Err(ReliabilityError::InvalidOption {
                option: "acceptance",
                message: "the inputs differ from point to point (tables in the values); the whole-machine acceptance needs one set of inputs for every point: give the values as constants, or leave acceptance out".into(),
            });
        }
        let spec = study.spec();
        let n = study.inputs().len();
        let np = study.points().len();
        let k = np * spec.tolerances.len();
        let mut rows = Vec::with_capacity(k * n);
        let (mut lower, mut upper) = (Vec::with_capacity(k), Vec::with_capacity(k));
        for p in 0..np {
            for &(c, t) in &spec.tolerances {
                rows.extend_from_slice(&study.row(p, c));
                upper.push(t);
                lower.push(match spec.sided {
                    Sided::Upper => f64::NEG_INFINITY,
                    Sided::Two => -t,
                });
            }
        }
        Rectangles::new(study.inputs().clone(), rows, lower, upper)
    }

    /// The same constraints over other inputs (the same names and count:
    /// other means, standard deviations or families).
    pub fn with_inputs(&self, inputs: Inputs) -> Result<Rectangles, ReliabilityError> {
        if inputs.len() != self.inputs.len() {
            return Err(ReliabilityError::Dimension {
                what: "acceptance inputs",
                expected: self.inputs.len(),
                found: inputs.len(),
            });
        }
        Ok(Rectangles {
            inputs,
            ..self.clone()
        })
    }

    /// The inputs.
    pub fn inputs(&self) -> &Inputs {
        &self.inputs
    }

    /// The constraints as given (points × components).
    pub fn constraints(&self) -> usize {
        self.constraints
    }

    /// The distinct constraints after merging equal rows.
    pub fn distinct(&self) -> usize {
        self.lower.len()
    }

    /// Distinct row `i` and its interval.
    pub fn row(&self, i: usize) -> (&[f64], f64, f64) {
        let n = self.inputs.len();
        (&self.rows[i * n..(i + 1) * n], self.lower[i], self.upper[i])
    }

    /// True when `x` satisfies every constraint.
    pub fn accepts(&self, x: &[f64]) -> bool {
        (0..self.distinct()).all(|i| {
            let (row, lo, hi) = self.row(i);
            let v = dot(row, x);
            v >= lo && v <= hi
        })
    }
}

/// The algorithm behind an [`AcceptanceResult`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum AcceptanceMethod {
    /// Genz's separation of variables in the inputs' own coordinates,
    /// randomised quasi-Monte Carlo (normal inputs).
    #[serde(rename = "genz_qmc")]
    GenzQmc,
    /// Crude Monte Carlo, conditional derivatives (other marginals).
    #[serde(rename = "mc")]
    MonteCarlo,
    /// Subset simulation of the small side (other marginals, when a crude
    /// Monte Carlo pilot finds fewer than [`RARE_EVENTS`] samples on it);
    /// the derivatives from the pilot's conditional Monte Carlo.
    #[serde(rename = "subset")]
    Subset,
}

/// How the acceptance probability of non-normal inputs is sampled.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AcceptanceSampling {
    /// Crude Monte Carlo, or subset simulation when the pilot's small side
    /// has fewer than [`RARE_EVENTS`] samples.
    Auto,
    /// Crude Monte Carlo only.
    MonteCarlo,
    /// Subset simulation of the smaller side of the pilot, always.
    Subset,
}

impl AcceptanceMethod {
    /// `genz_qmc` or `mc` (the JSON's spelling).
    pub fn name(self) -> &'static str {
        match self {
            AcceptanceMethod::GenzQmc => "genz_qmc",
            AcceptanceMethod::MonteCarlo => "mc",
            AcceptanceMethod::Subset => "subset",
        }
    }

    /// For reports.
    pub fn title(self) -> &'static str {
        match self {
            AcceptanceMethod::GenzQmc => "Genz separation of variables, randomised QMC",
            AcceptanceMethod::MonteCarlo => "Monte Carlo",
            AcceptanceMethod::Subset => "subset simulation",
        }
    }
}

/// The derivatives of the acceptance probability with respect to one
/// input's mean and standard deviation (the family and the other moment
/// held), with their standard errors.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AcceptanceSensitivity {
    /// The error parameter.
    pub error: String,
    /// `∂P/∂σ`.
    pub dr_dstd: f64,
    /// `∂P/∂μ`.
    pub dr_dmean: f64,
    /// Standard error of `dr_dstd`.
    pub dr_dstd_std_error: f64,
    /// Standard error of `dr_dmean`.
    pub dr_dmean_std_error: f64,
}

/// The acceptance probability of a machine.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AcceptanceResult {
    /// `P(every constraint holds)`.
    pub probability: f64,
    /// Its standard error (over the random shifts for QMC; binomial for
    /// Monte Carlo).
    pub std_error: f64,
    /// The algorithm.
    pub method: AcceptanceMethod,
    /// Integrand evaluations (QMC points × shifts, or samples).
    pub samples: u64,
    /// True when three standard errors are within the requested absolute
    /// error (or a fixed sample count was asked for); false when the sample
    /// limit stopped it first.
    pub converged: bool,
    /// The requested absolute error (`None` for a fixed sample count).
    pub tolerance: Option<f64>,
    /// Constraints (points × components) and distinct constraints.
    pub constraints: usize,
    /// Distinct constraints after merging equal rows.
    pub distinct: usize,
    /// The rank `r` of the constraint rows in the inputs' standard space
    /// (the dimension of the QMC integral; 0 for Monte Carlo).
    pub rank: usize,
    /// The pivot constraints of the QMC columns (distinct-row indices), to
    /// reuse the same ordering ([`Acceptance::pivots`]).
    #[serde(skip)]
    pub pivots: Vec<usize>,
    /// Per input, in input order (empty unless asked for).
    pub sensitivity: Vec<AcceptanceSensitivity>,
    /// The subset-simulation account (method `subset` only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub subset: Option<AcceptanceSubset>,
}

/// Settings of the acceptance probability.
#[derive(Debug, Clone, PartialEq)]
pub struct Acceptance {
    /// The absolute error: the points double until three standard errors
    /// are below it (1e-3).
    pub tolerance: f64,
    /// A fixed number of integrand evaluations instead of the tolerance
    /// (rounded up to a multiple of the shifts / blocks).
    pub samples: Option<u64>,
    /// The largest number of evaluations (10⁷ for QMC, the same for Monte
    /// Carlo).
    pub max_samples: u64,
    /// Independent random shifts of the QMC rule (16).
    pub shifts: u32,
    /// Seed of the shifts / samples.
    pub seed: u64,
    /// Estimate the sensitivities too.
    pub sensitivity: bool,
    /// Reuse this pivot order (from an earlier result's `pivots`), so that
    /// runs at nearby parameters use the same integrand (finite
    /// differences with fixed QMC points).
    pub pivots: Option<Vec<usize>>,
    /// Crude Monte Carlo or subset simulation for non-normal inputs
    /// ([`AcceptanceSampling::Auto`]).
    pub sampling: AcceptanceSampling,
    /// Subset simulation: samples per level (2,000).
    pub subset_samples: u64,
    /// Subset simulation: the target coefficient of variation of the small
    /// side (0.1); runs repeat until it is reached or
    /// [`Acceptance::max_samples`] are spent.
    pub rare_cov: f64,
}

impl Default for Acceptance {
    fn default() -> Acceptance {
        Acceptance {
            tolerance: 1e-3,
            samples: None,
            max_samples: 10_000_000,
            shifts: 16,
            seed: 1,
            sensitivity: true,
            pivots: None,
            sampling: AcceptanceSampling::Auto,
            subset_samples: 2000,
            rare_cov: 0.1,
        }
    }
}

/// Monte Carlo block size.
const BLOCK: u64 = 8192;
/// Blocks of the crude Monte Carlo pilot (16 · 8,192 = 131,072 samples).
pub const PILOT_BLOCKS: u64 = 16;
/// Fewer pilot samples than this on the small side (rejected, or accepted
/// when `P < 1/2`) select subset simulation under [`AcceptanceSampling::Auto`]: the
/// pilot's coefficient of variation of that side is then above 10 %
/// (`√((1 − q)/m)`), the small side below `100/131,072 ≈ 7.6·10⁻⁴`, and crude
/// Monte Carlo would need `100/q` samples for 10 % (10⁷ at `q = 10⁻⁵`), while
/// subset simulation at `p0 = 0.1` needs about `N·log₁₀(1/q)` per run
/// (docs/acceptance.md).
pub const RARE_EVENTS: u64 = 100;
/// A residual row this small relative to its row is in the span.
const SPAN_TOL: f64 = 1e-9;

impl Acceptance {
    /// The acceptance probability of `system` (QMC for affine inputs,
    /// Monte Carlo otherwise).
    pub fn run(&self, system: &Rectangles) -> Result<AcceptanceResult, ReliabilityError> {
        if let Some(s) = self.samples {
            if s == 0 || s > self.max_samples.max(1) {
                return Err(ReliabilityError::InvalidSamples {
                    found: s,
                    max: self.max_samples,
                });
            }
        } else if !(self.tolerance.is_finite() && self.tolerance > 0.0 && self.tolerance < 1.0) {
            return Err(ReliabilityError::InvalidOption {
                option: "acceptance tolerance",
                message: format!("must be in (0, 1), found {}", self.tolerance),
            });
        }
        if self.shifts < 2 {
            return Err(ReliabilityError::InvalidOption {
                option: "acceptance shifts",
                message: format!(
                    "at least 2 are needed for an error estimate, found {}",
                    self.shifts
                ),
            });
        }
        if system.inputs.is_affine() {
            self.qmc(system)
        } else {
            self.monte_carlo(system)
        }
    }

    fn tolerance(&self) -> Option<f64> {
        self.samples.is_none().then_some(self.tolerance)
    }

    fn qmc(&self, system: &Rectangles) -> Result<AcceptanceResult, ReliabilityError> {
        let inputs = &system.inputs;
        let n = inputs.len();
        let plan = Plan::new(system, self.pivots.as_deref())?;
        let r = plan.rank;
        let base = AcceptanceResult {
            probability: 0.0,
            std_error: 0.0,
            method: AcceptanceMethod::GenzQmc,
            samples: 0,
            converged: true,
            tolerance: self.tolerance(),
            constraints: system.constraints,
            distinct: system.distinct(),
            rank: r,
            pivots: plan.pivots.clone(),
            sensitivity: Vec::new(),
            subset: None,
        };
        let names = inputs.names();
        let zero_sens = || {
            names
                .iter()
                .map(|e| AcceptanceSensitivity {
                    error: e.clone(),
                    dr_dstd: 0.0,
                    dr_dmean: 0.0,
                    dr_dstd_std_error: 0.0,
                    dr_dmean_std_error: 0.0,
                })
                .collect()
        };
        if plan.infeasible {
            // A constraint on no input fails for sure.
            let sensitivity = if self.sensitivity {
                zero_sens()
            } else {
                Vec::new()
            };
            return Ok(AcceptanceResult {
                sensitivity,
                ..base
            });
        }
        if r == 0 {
            let sensitivity = if self.sensitivity {
                zero_sens()
            } else {
                Vec::new()
            };
            return Ok(AcceptanceResult {
                probability: 1.0,
                sensitivity,
                ..base
            });
        }
        let sens = if self.sensitivity {
            Some(ScoreMatrices::new(inputs, &plan.q, r)?)
        } else {
            None
        };
        let shifts = self.shifts as usize;
        let mut rng = CaseRng::new(self.seed, u32::MAX, 0);
        let shift_vectors: Vec<Vec<f64>> = (0..shifts)
            .map(|_| (0..r).map(|_| rng.uniform()).collect())
            .collect();
        let generator: Vec<f64> = primes(r)
            .iter()
            .map(|&p| (p as f64).sqrt().fract())
            .collect();
        // Accumulators per shift: [Σf, Σf·g_mean (n), Σf·g_std (n)].
        let width = 1 + 2 * n;
        let mut acc = vec![vec![0.0; width]; shifts];
        let mut per_shift: u64 = 0;
        let mut batch: u64 = match self.samples {
            Some(s) => s.div_ceil(shifts as u64),
            None => 256,
        };
        let max_per_shift = (self.max_samples / shifts as u64).max(1);
        loop {
            let start = per_shift;
            let end = (start + batch).min(max_per_shift.max(start + 1));
            let sums: Vec<Vec<f64>> = (0..shifts)
                .into_par_iter()
                .map(|s| {
                    plan.sum(
                        &generator,
                        &shift_vectors[s],
                        start,
                        end,
                        sens.as_ref(),
                        width,
                    )
                })
                .collect();
            for (a, s) in acc.iter_mut().zip(&sums) {
                for (x, y) in a.iter_mut().zip(s) {
                    *x += y;
                }
            }
            per_shift = end;
            let (_, se) = mean_se(&acc, 0, per_shift);
            if self.samples.is_some()
                || (3.0 * se <= self.tolerance && per_shift >= 512)
                || per_shift >= max_per_shift
            {
                break;
            }
            batch = per_shift;
        }
        let (p, se) = mean_se(&acc, 0, per_shift);
        let converged = self.samples.is_some() || 3.0 * se <= self.tolerance;
        let sensitivity = if sens.is_some() {
            (0..n)
                .map(|j| {
                    let (dm, dm_se) = mean_se(&acc, 1 + j, per_shift);
                    let (ds, ds_se) = mean_se(&acc, 1 + n + j, per_shift);
                    AcceptanceSensitivity {
                        error: names[j].clone(),
                        dr_dstd: ds,
                        dr_dmean: dm,
                        dr_dstd_std_error: ds_se,
                        dr_dmean_std_error: dm_se,
                    }
                })
                .collect()
        } else {
            Vec::new()
        };
        Ok(AcceptanceResult {
            probability: p.clamp(0.0, 1.0),
            std_error: se,
            samples: per_shift * shifts as u64,
            converged,
            sensitivity,
            ..base
        })
    }

    fn monte_carlo(&self, system: &Rectangles) -> Result<AcceptanceResult, ReliabilityError> {
        let inputs = &system.inputs;
        let n = inputs.len();
        let k = system.distinct();
        if self.sampling != AcceptanceSampling::MonteCarlo
            && !(self.rare_cov.is_finite() && self.rare_cov > 0.0 && self.rare_cov < 1.0)
        {
            return Err(ReliabilityError::InvalidOption {
                option: "acceptance rare_cov",
                message: format!("must be in (0, 1), found {}", self.rare_cov),
            });
        }
        // The Gaussian copula of the correlated block: z_B = Φ⁻¹(F(x_B)) is
        // N(0, R₀); given the other z, z_j is N(μ_c, s_c²).
        let copula = if self.sensitivity {
            Copula::new(inputs)?
        } else {
            None
        };
        let width = 1 + 2 * n;
        let run_block = |b: u64| -> Vec<f64> {
            let mut rng = CaseRng::new(self.seed, u32::MAX - 1, b as u32);
            let mut out = vec![0.0; width];
            let mut x = vec![0.0; n];
            let mut v = vec![0.0; k];
            let mut z = copula.as_ref().map(|c| vec![0.0; c.members.len()]);
            let mut bad: Vec<usize> = Vec::new();
            for _ in 0..BLOCK {
                inputs.sample(&mut rng, &mut x);
                bad.clear();
                for i in 0..k {
                    let (row, lo, hi) = system.row(i);
                    v[i] = dot(row, &x);
                    if !(v[i] >= lo && v[i] <= hi) {
                        bad.push(i);
                    }
                }
                if bad.is_empty() {
                    out[0] += 1.0;
                }
                if !self.sensitivity {
                    continue;
                }
                if let (Some(c), Some(z)) = (&copula, z.as_mut()) {
                    for (zi, &m) in z.iter_mut().zip(&c.members) {
                        *zi = inputs.marginals()[m].to_standard(x[m]);
                    }
                }
                for j in 0..n {
                    let mj = inputs.marginals()[j];
                    if bad.iter().any(|&i| system.row(i).0[j] == 0.0) {
                        continue;
                    }
                    // The safe interval of x_j given the other inputs.
                    let (mut a, mut bb) = (f64::NEG_INFINITY, f64::INFINITY);
                    for i in 0..k {
                        let (row, lo, hi) = system.row(i);
                        let c = row[j];
                        if c == 0.0 {
                            continue;
                        }
                        let rest = v[i] - c * x[j];
                        let (t1, t2) = ((lo - rest) / c, (hi - rest) / c);
                        let (l, h) = if c > 0.0 { (t1, t2) } else { (t2, t1) };
                        a = a.max(l);
                        bb = bb.min(h);
                    }
                    if a >= bb {
                        continue;
                    }
                    // The law of u_j = Φ⁻¹(F_j(x_j)) given the others.
                    let (centre, spread) = match (&copula, &z) {
                        (Some(c), Some(z)) => c.conditional(j, z),
                        _ => (0.0, 1.0),
                    };
                    let (dm_b, ds_b) = cdf_derivatives(&mj, bb, centre, spread);
                    let (dm_a, ds_a) = cdf_derivatives(&mj, a, centre, spread);
                    out[1 + j] += dm_b - dm_a;
                    out[1 + n + j] += ds_b - ds_a;
                }
            }
            out
        };
        let mut acc = vec![0.0; width];
        let mut acc2 = vec![0.0; width];
        let mut blocks: u64 = 0;
        let max_blocks = self.max_samples.div_ceil(BLOCK).max(1);
        let mut batch: u64 = match self.samples {
            Some(s) => s.div_ceil(BLOCK),
            None => PILOT_BLOCKS.min(max_blocks),
        };
        let mut rare: Option<AcceptanceSubset> = None;
        loop {
            let end = (blocks + batch).min(max_blocks);
            let sums: Vec<Vec<f64>> = (blocks..end).into_par_iter().map(run_block).collect();
            for s in &sums {
                for w in 0..width {
                    acc[w] += s[w];
                    // Block totals: the variance of the derivative
                    // estimators over blocks.
                    acc2[w] += s[w] * s[w] / BLOCK as f64;
                }
            }
            let first = blocks == 0;
            blocks = end;
            let total = (blocks * BLOCK) as f64;
            let p = acc[0] / total;
            let se = (p * (1.0 - p) / total).sqrt();
            if first && self.samples.is_none() && self.sampling != AcceptanceSampling::MonteCarlo {
                let accepted = acc[0] as u64;
                let drawn = blocks * BLOCK;
                let (side, events) = if 2 * accepted < drawn {
                    (RareSide::Acceptance, accepted)
                } else {
                    (RareSide::Rejection, drawn - accepted)
                };
                if self.sampling == AcceptanceSampling::Subset || events < RARE_EVENTS {
                    let budget = self
                        .max_samples
                        .saturating_sub(drawn)
                        .max(self.subset_samples);
                    let (_, _, mut account) = rare::run(
                        system,
                        side,
                        self.subset_samples,
                        self.rare_cov,
                        budget,
                        self.seed,
                    )?;
                    account.pilot_samples = drawn;
                    account.pilot_events = events;
                    rare = Some(account);
                    break;
                }
            }
            if self.samples.is_some() || 3.0 * se <= self.tolerance || blocks >= max_blocks {
                break;
            }
            batch = blocks;
        }
        let total = (blocks * BLOCK) as f64;
        let (p, se, method, samples, converged) = match &rare {
            None => {
                let p = acc[0] / total;
                let se = (p * (1.0 - p) / total).sqrt();
                let converged = self.samples.is_some() || 3.0 * se <= self.tolerance;
                (
                    p,
                    se,
                    AcceptanceMethod::MonteCarlo,
                    blocks * BLOCK,
                    converged,
                )
            }
            Some(s) => {
                let p = match s.side {
                    RareSide::Rejection => 1.0 - s.probability,
                    RareSide::Acceptance => s.probability,
                };
                let se = s.probability * s.cov;
                let converged = s.stopping.converged && 3.0 * se <= self.tolerance;
                (
                    p,
                    se,
                    AcceptanceMethod::Subset,
                    s.pilot_samples + s.samples,
                    converged,
                )
            }
        };
        let se_of = |w: usize| {
            // The per-sample variance from the block means `T_b/B`:
            // `B·Var(T_b/B) = Σ_b T_b²/(B·n_b) − B·mean²`.
            let mean = acc[w] / total;
            let var = (acc2[w] / blocks as f64 - BLOCK as f64 * mean * mean).max(0.0);
            (var / total).sqrt()
        };
        let sensitivity = if self.sensitivity {
            (0..n)
                .map(|j| AcceptanceSensitivity {
                    error: inputs.names()[j].clone(),
                    dr_dstd: acc[1 + n + j] / total,
                    dr_dmean: acc[1 + j] / total,
                    dr_dstd_std_error: se_of(1 + n + j),
                    dr_dmean_std_error: se_of(1 + j),
                })
                .collect()
        } else {
            Vec::new()
        };
        Ok(AcceptanceResult {
            probability: p,
            std_error: se,
            method,
            samples,
            converged,
            tolerance: self.tolerance(),
            constraints: system.constraints,
            distinct: k,
            rank: 0,
            pivots: Vec::new(),
            sensitivity,
            subset: rare,
        })
    }
}

/// The Gaussian copula of the correlated block as the conditional
/// estimator needs it: the members and the precision `R₀⁻¹` of
/// `z_B = Φ⁻¹(F(x_B))` (`R₀` the Nataf-adjusted matrix, `L·Lᵀ`).
#[derive(Debug, Clone)]
struct Copula {
    /// The inputs of the block, ascending.
    members: Vec<usize>,
    /// Per input, its position in `members`.
    position: Vec<Option<usize>>,
    /// `R₀⁻¹`, `k × k`.
    precision: nalgebra::DMatrix<f64>,
}

impl Copula {
    /// `None` for independent inputs. `L` is read off the Jacobian at
    /// `u = 0`: `∂x_m/∂u_c = (dx_m/dz)(0)·L_ic` ([`Inputs::jacobian_matrix`]).
    fn new(inputs: &Inputs) -> Result<Option<Copula>, ReliabilityError> {
        let n = inputs.len();
        let members: Vec<usize> = (0..n).filter(|&j| inputs.is_correlated(j)).collect();
        if members.is_empty() {
            return Ok(None);
        }
        let kb = members.len();
        let mut jac = vec![0.0; n * n];
        inputs.jacobian_matrix(&vec![0.0; n], &mut jac);
        let mut l = nalgebra::DMatrix::zeros(kb, kb);
        for (i, &m) in members.iter().enumerate() {
            let slope = inputs.marginals()[m].dx_du(0.0);
            for (c, &mc) in members.iter().enumerate().take(i + 1) {
                l[(i, c)] = jac[m * n + mc] / slope;
            }
        }
        let r0 = &l * l.transpose();
        let precision = r0.try_inverse().ok_or(ReliabilityError::NonFinite(
            "the inverse of the correlated block's copula matrix",
        ))?;
        let mut position = vec![None; n];
        for (i, &m) in members.iter().enumerate() {
            position[m] = Some(i);
        }
        Ok(Some(Copula {
            members,
            position,
            precision,
        }))
    }

    /// `(μ_c, s_c)` of `z_j` given the other members' `z`:
    /// `μ_c = z_j − (R₀⁻¹z)_j/(R₀⁻¹)_jj`, `s_c = (R₀⁻¹)_jj^{−1/2}`; `(0, 1)`
    /// outside the block.
    #[inline]
    fn conditional(&self, j: usize, z: &[f64]) -> (f64, f64) {
        let Some(a) = self.position[j] else {
            return (0.0, 1.0);
        };
        let pjj = self.precision[(a, a)];
        let pz: f64 = (0..z.len()).map(|b| self.precision[(a, b)] * z[b]).sum();
        (z[a] - pz / pjj, 1.0 / pjj.sqrt())
    }
}

/// `(∂/∂μ, ∂/∂σ)` of `Φ((T⁻¹(x) − c)/s)` at a fixed physical `x` (the
/// conditional cdf of `x_j` when `u_j ~ N(c, s²)`; `F_j(x)` itself for
/// `c = 0`, `s = 1`): `−φ((u − c)/s)/s·(∂x/∂θ)/(dx/du)` at `u = T⁻¹(x)`,
/// zero outside the interior of the support and at infinite `x`.
fn cdf_derivatives(m: &Marginal, x: f64, centre: f64, spread: f64) -> (f64, f64) {
    let (lo, hi) = m.support();
    if !x.is_finite() || x <= lo || x >= hi {
        return (0.0, 0.0);
    }
    let u = m.to_standard(x);
    let dxdu = m.dx_du(u);
    if !(u.is_finite() && dxdu > 0.0) {
        return (0.0, 0.0);
    }
    let f = normal::pdf((u - centre) / spread) / (spread * dxdu);
    (-f * m.dx_dmean(u), -f * m.dx_dstd(u))
}

/// Mean and standard error over the shifts of accumulator `w`.
fn mean_se(acc: &[Vec<f64>], w: usize, per_shift: u64) -> (f64, f64) {
    let m = acc.len() as f64;
    let means: Vec<f64> = acc.iter().map(|a| a[w] / per_shift as f64).collect();
    let mean = means.iter().sum::<f64>() / m;
    let var = means.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (m - 1.0);
    (mean, (var / m).sqrt())
}

/// The first `r` primes.
fn primes(r: usize) -> Vec<u64> {
    let mut out = Vec::with_capacity(r);
    let mut c = 2u64;
    while out.len() < r {
        if out.iter().take_while(|&&p| p * p <= c).all(|&p| c % p != 0) {
            out.push(c);
        }
        c += 1;
    }
    out
}

/// The constraints of one column of the separation of variables.
#[derive(Debug, Clone)]
struct Column {
    /// Per constraint, `L_i0 … L_ik` (`k + 1` coefficients), row-major.
    coef: Vec<f64>,
    /// `m_i = S_i·μ`.
    mean: Vec<f64>,
    lower: Vec<f64>,
    upper: Vec<f64>,
}

/// The ordered LQ factorisation of the constraint rows in `u`.
#[derive(Debug, Clone)]
struct Plan {
    rank: usize,
    /// A constraint on no input that fails.
    infeasible: bool,
    pivots: Vec<usize>,
    /// The orthonormal rows `q_k` (`r × n`).
    q: Vec<f64>,
    columns: Vec<Column>,
}

impl Plan {
    fn new(system: &Rectangles, pivots: Option<&[usize]>) -> Result<Plan, ReliabilityError> {
        let inputs = &system.inputs;
        let n = inputs.len();
        let kk = system.distinct();
        let mut resid = vec![0.0; kk * n];
        let mut mean = vec![0.0; kk];
        let mut scale = vec![0.0; kk];
        for i in 0..kk {
            let (row, _, _) = system.row(i);
            mean[i] = inputs.project(row, &mut resid[i * n..(i + 1) * n]);
            scale[i] = dot(&resid[i * n..(i + 1) * n], &resid[i * n..(i + 1) * n]).sqrt();
        }
        let mut infeasible = false;
        let mut assigned = vec![false; kk];
        for i in 0..kk {
            if scale[i] == 0.0 {
                assigned[i] = true;
                let (_, lo, hi) = system.row(i);
                if !(mean[i] >= lo && mean[i] <= hi) {
                    infeasible = true;
                }
            }
        }
        // L coefficients of every row, column by column.
        let mut l: Vec<Vec<f64>> = vec![Vec::new(); kk];
        let mut partial = vec![0.0; kk];
        let mut q = Vec::new();
        let mut columns = Vec::new();
        let mut chosen = Vec::new();
        let given = pivots.map(<[usize]>::to_vec);
        for k in 0..n {
            // The pivot: the smallest conditional probability.
            let pivot = match &given {
                Some(g) => match g.get(k) {
                    Some(&p) if p < kk && !assigned[p] => Some(p),
                    Some(&p) => {
                        return Err(ReliabilityError::InvalidOption {
                            option: "acceptance pivots",
                            message: format!("pivot {p} is not a free constraint at column {k}"),
                        })
                    }
                    None => None,
                },
                None => {
                    let mut best: Option<(usize, f64)> = None;
                    for i in 0..kk {
                        if assigned[i] {
                            continue;
                        }
                        let ri = &resid[i * n..(i + 1) * n];
                        let s = dot(ri, ri).sqrt();
                        let (_, lo, hi) = system.row(i);
                        let t = mean[i] + partial[i];
                        let pr = normal::interval((lo - t) / s, (hi - t) / s);
                        if best.is_none_or(|(_, b)| pr < b) {
                            best = Some((i, pr));
                        }
                    }
                    best.map(|(i, _)| i)
                }
            };
            let Some(p) = pivot else { break };
            let rp = resid[p * n..(p + 1) * n].to_vec();
            let s = dot(&rp, &rp).sqrt();
            if s <= SPAN_TOL * scale[p] {
                return Err(ReliabilityError::InvalidOption {
                    option: "acceptance pivots",
                    message: format!("pivot {p} is in the span of the earlier columns"),
                });
            }
            let qk: Vec<f64> = rp.iter().map(|v| v / s).collect();
            let mut col = Column {
                coef: Vec::new(),
                mean: Vec::new(),
                lower: Vec::new(),
                upper: Vec::new(),
            };
            for i in 0..kk {
                if assigned[i] {
                    continue;
                }
                let ri = &mut resid[i * n..(i + 1) * n];
                let c = if i == p { s } else { dot(ri, &qk) };
                for (r, qv) in ri.iter_mut().zip(&qk) {
                    *r -= c * qv;
                }
                l[i].push(c);
                let left = dot(ri, ri).sqrt();
                if i == p || left <= SPAN_TOL * scale[i] {
                    assigned[i] = true;
                    if c.abs() <= SPAN_TOL * scale[i] {
                        // Numerically in the span of earlier columns: its
                        // coefficient here is noise. Keep it as a
                        // constraint on w_k with the noise dropped.
                        l[i][k] = 0.0;
                    }
                    let (_, lo, hi) = system.row(i);
                    col.coef.extend_from_slice(&l[i]);
                    col.mean.push(mean[i]);
                    col.lower.push(lo);
                    col.upper.push(hi);
                }
            }
            // The expected w_k over the column's interval at the expected
            // previous w (Genz & Bretz §4.1.3).
            let (mut a, mut b) = (f64::NEG_INFINITY, f64::INFINITY);
            let w = k + 1;
            for (idx, m) in col.mean.iter().enumerate() {
                let row = &col.coef[idx * w..(idx + 1) * w];
                let t = m + partial_of(row, &chosen_means(&chosen));
                let (lo, hi) = (col.lower[idx], col.upper[idx]);
                let c = row[k];
                if c == 0.0 {
                    continue;
                }
                let (t1, t2) = ((lo - t) / c, (hi - t) / c);
                let (x, y) = if c > 0.0 { (t1, t2) } else { (t2, t1) };
                a = a.max(x);
                b = b.min(y);
            }
            let y = truncated_mean(a, b);
            chosen.push((p, y));
            for i in 0..kk {
                if let Some(&c) = l[i].get(k) {
                    partial[i] += c * y;
                }
            }
            q.extend_from_slice(&qk);
            columns.push(col);
            if assigned.iter().all(|&x| x) {
                break;
            }
        }
        if let Some(i) = assigned.iter().position(|&x| !x) {
            return Err(ReliabilityError::InvalidOption {
                option: "acceptance pivots",
                message: format!("constraint {i} is not in the span of the given pivots"),
            });
        }
        Ok(Plan {
            rank: columns.len(),
            infeasible,
            pivots: chosen.iter().map(|(p, _)| *p).collect(),
            q,
            columns,
        })
    }

    /// `Σ f(z_i)` (and the score sums) over points `start..end` of one
    /// shifted Richtmyer sequence.
    fn sum(
        &self,
        generator: &[f64],
        shift: &[f64],
        start: u64,
        end: u64,
        sens: Option<&ScoreMatrices>,
        width: usize,
    ) -> Vec<f64> {
        let r = self.rank;
        let mut out = vec![0.0; width];
        let mut z = vec![0.0; r];
        let mut w = vec![0.0; r];
        let mut alpha = Vec::new();
        let mut beta = Vec::new();
        for i in start..end {
            let t = (i + 1) as f64;
            for k in 0..r {
                let v = (t * generator[k] + shift[k]).fract();
                z[k] = 1.0 - (2.0 * v - 1.0).abs();
            }
            let f = self.integrand(&z, &mut w);
            if f == 0.0 {
                continue;
            }
            out[0] += f;
            if let Some(sm) = sens {
                sm.scores(&w, &mut alpha, &mut beta);
                let n = alpha.len();
                for j in 0..n {
                    out[1 + j] += f * alpha[j];
                    out[1 + n + j] += f * beta[j];
                }
            }
        }
        out
    }

    /// `f(z) = Π_k (Φ(b_k) − Φ(a_k))`, writing the `w_k` into `w`.
    #[inline]
    fn integrand(&self, z: &[f64], w: &mut [f64]) -> f64 {
        let mut f = 1.0;
        for (k, col) in self.columns.iter().enumerate() {
            let width = k + 1;
            let (mut a, mut b) = (f64::NEG_INFINITY, f64::INFINITY);
            for (idx, m) in col.mean.iter().enumerate() {
                let row = &col.coef[idx * width..(idx + 1) * width];
                let t = m + dot(&row[..k], &w[..k]);
                let c = row[k];
                let (lo, hi) = (col.lower[idx], col.upper[idx]);
                if c == 0.0 {
                    if !(t >= lo && t <= hi) {
                        return 0.0;
                    }
                    continue;
                }
                let (t1, t2) = ((lo - t) / c, (hi - t) / c);
                if c > 0.0 {
                    a = a.max(t1);
                    b = b.min(t2);
                } else {
                    a = a.max(t2);
                    b = b.min(t1);
                }
            }
            if a >= b {
                return 0.0;
            }
            let e = normal::interval(a, b);
            if e <= 0.0 {
                return 0.0;
            }
            f *= e;
            w[k] = truncated_draw(a, b, e, z[k]);
        }
        f
    }
}

/// `Σ_j row_j·y_j` over the previous columns' expected values.
fn partial_of(row: &[f64], y: &[f64]) -> f64 {
    row.iter().zip(y).map(|(a, b)| a * b).sum()
}

fn chosen_means(chosen: &[(usize, f64)]) -> Vec<f64> {
    chosen.iter().map(|(_, y)| *y).collect()
}

/// `E[w | a ≤ w ≤ b]` for `w ~ N(0, 1)`.
fn truncated_mean(a: f64, b: f64) -> f64 {
    if a >= b {
        return 0.5 * (a + b);
    }
    let e = normal::interval(a, b);
    if e <= 0.0 {
        return if a.is_finite() { a } else { b };
    }
    let pa = if a.is_finite() { normal::pdf(a) } else { 0.0 };
    let pb = if b.is_finite() { normal::pdf(b) } else { 0.0 };
    ((pa - pb) / e).clamp(a, b)
}

/// `Φ⁻¹(Φ(a) + z·(Φ(b) − Φ(a)))`, on the side of zero where it does not
/// cancel, clamped into `[a, b]`.
#[inline]
fn truncated_draw(a: f64, b: f64, e: f64, z: f64) -> f64 {
    let w = if a >= 0.0 {
        // Upper tail: Φ(−w) = Φ(−a) − z·e.
        -normal::inverse_cdf((normal::sf(a) - z * e).max(f64::MIN_POSITIVE))
    } else {
        normal::inverse_cdf((normal::cdf(a) + z * e).max(f64::MIN_POSITIVE))
    };
    w.clamp(a, b)
}

/// The score matrices `C = B⁻ᵀQᵀ`, `D = B·Qᵀ` (`n × r`) and `κ_j =
/// (B⁻ᵀQᵀQBᵀ)_jj`, with `x = μ + B·u`.
#[derive(Debug, Clone)]
struct ScoreMatrices {
    n: usize,
    r: usize,
    c: Vec<f64>,
    d: Vec<f64>,
    kappa: Vec<f64>,
    stds: Vec<f64>,
}

impl ScoreMatrices {
    fn new(inputs: &Inputs, q: &[f64], r: usize) -> Result<ScoreMatrices, ReliabilityError> {
        let n = inputs.len();
        // B's columns: x(e_k) − x(0) (the map is affine).
        let mut x0 = vec![0.0; n];
        inputs.to_physical(&vec![0.0; n], &mut x0);
        let mut bmat = nalgebra::DMatrix::zeros(n, n);
        let mut u = vec![0.0; n];
        let mut x = vec![0.0; n];
        for k in 0..n {
            u.iter_mut().for_each(|v| *v = 0.0);
            u[k] = 1.0;
            inputs.to_physical(&u, &mut x);
            for j in 0..n {
                bmat[(j, k)] = x[j] - x0[j];
            }
        }
        let binv = bmat
            .clone()
            .try_inverse()
            .ok_or(ReliabilityError::NonFinite("the inverse of the input map"))?;
        let mut c = vec![0.0; n * r];
        let mut d = vec![0.0; n * r];
        for j in 0..n {
            for k in 0..r {
                let qk = &q[k * n..(k + 1) * n];
                c[j * r + k] = (0..n).map(|l| binv[(l, j)] * qk[l]).sum();
                d[j * r + k] = (0..n).map(|l| bmat[(j, l)] * qk[l]).sum();
            }
        }
        let kappa = (0..n)
            .map(|j| dot(&c[j * r..(j + 1) * r], &d[j * r..(j + 1) * r]))
            .collect();
        Ok(ScoreMatrices {
            n,
            r,
            c,
            d,
            kappa,
            stds: inputs.stds().to_vec(),
        })
    }

    /// The mean scores `(B⁻ᵀQᵀw)_j` and the std scores
    /// `((B⁻ᵀQᵀw)_j(BQᵀw)_j − κ_j)/σ_j`.
    #[inline]
    fn scores(&self, w: &[f64], mean: &mut Vec<f64>, std: &mut Vec<f64>) {
        mean.resize(self.n, 0.0);
        std.resize(self.n, 0.0);
        let r = self.r;
        for j in 0..self.n {
            let a = dot(&self.c[j * r..(j + 1) * r], w);
            let b = dot(&self.d[j * r..(j + 1) * r], w);
            mean[j] = a;
            std[j] = (a * b - self.kappa[j]) / self.stds[j];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn primes_and_truncated_helpers() {
        assert_eq!(primes(6), vec![2, 3, 5, 7, 11, 13]);
        // E[w | w ≥ 0] = √(2/π).
        let m = truncated_mean(0.0, f64::INFINITY);
        assert!((m - (2.0 / std::f64::consts::PI).sqrt()).abs() < 1e-15);
        // The draw at z is the z-quantile of the truncated law.
        for (a, b) in [(-1.0, 2.0), (3.0, 4.0), (-5.0, -4.5)] {
            let e = normal::interval(a, b);
            for z in [0.1, 0.5, 0.9] {
                let w = truncated_draw(a, b, e, z);
                let back = normal::interval(a, w) / e;
                assert!((back - z).abs() < 1e-9, "{a} {b} {z}: {back}");
            }
        }
    }
}
