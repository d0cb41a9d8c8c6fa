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
//!
//! [`Inputs`]: crate::inputs::Inputs
//! [`Inputs::correlated`]: crate::inputs::Inputs::correlated
//! [`Inputs::sample`]: crate::inputs::Inputs::sample
//! [`Marginal::dx_dmean`]: crate::inputs::Marginal::dx_dmean
//! [`Marginal::dx_dstd`]: crate::inputs::Marginal::dx_dstd

// Dense kernels over small index ranges read best with indices.
#![allow(clippy::needless_range_loop)]

use serde::Serialize;

use crate::error::ReliabilityError;

mod monte_carlo;
mod qmc;
mod rare;
mod rectangles;

pub use rare::{AcceptanceSubset, RareSide};
pub use rectangles::Rectangles;

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
        if system.inputs().is_affine() {
            self.qmc(system)
        } else {
            self.monte_carlo(system)
        }
    }

    fn tolerance(&self) -> Option<f64> {
        self.samples.is_none().then_some(self.tolerance)
    }
}
