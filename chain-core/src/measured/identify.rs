//! Identification of the error parameters from measurements
//! (measured-machines spec, section 4; `docs/identify.md`).
//!
//! # Formulas
//!
//! With the design `A` (rows: [`super::Design`]), the measured values `b`
//! and each row's standard deviation `σ_i` (the `std` column; `1` without
//! it), the weighted rows are `B = diag(1/σ) A`, `y = b/σ`. The columns are
//! equilibrated, `D = diag(1/|B_j|)` (a zero column keeps `1`), so the
//! singular values of `B D` do not depend on the units of the unknowns
//! (mm against rad). `(B D)ᵀ(B D) = V Λ Vᵀ` (nalgebra's SVD of the
//! symmetric `n × n` information matrix: its singular values are the
//! squares of those of `B D`; `n` the unknowns).
//!
//! - **rank**: the count of singular values `s_i = √λ_i` of `B D` above
//!   [`RANK_TOLERANCE`] `× s_max`; **condition**: `s_max / s_rank`, the
//!   condition number of the equilibrated design on its identifiable part.
//! - **null space**: `N` = an orthonormal basis of `span(D V_null)`, split
//!   into the groups of unknowns it couples (see [`grouped_basis`]).
//! - **estimate**: the minimum-norm least-squares solution
//!   `x = P D V_r Λ_r⁻¹ V_rᵀ D Bᵀ y`, `P = I − N Nᵀ` (the unique solution
//!   orthogonal to the null space, i.e. `B⁺ y`).
//! - **covariance**: `(Aᵀ W A)⁺ = P D V_r Λ_r⁻¹ V_rᵀ D P` with a `std`
//!   column (`W = diag(1/σ²)`, spec section 4); without one it is scaled by
//!   `s² = RSS/(m − rank)` (`RSS = |b − A x|²`, `m` scalar rows).
//! - **prior** (`statistics` as independent Gaussians `N(μ₀_j, σ₀_j²)`,
//!   a uniform entry by its mean and standard deviation): the posterior
//!   precision `Λ_post = Aᵀ W A + Σ₀⁻¹` and mean
//!   `Λ_post⁻¹ (Aᵀ W b + Σ₀⁻¹ μ₀)` (Cholesky); without a `std` column
//!   `W = I/s²` with `s²` of the least-squares fit. What the data did not
//!   inform: the eigen-directions `w` of the prior-standardised data
//!   information `L Aᵀ W A L` (`L = diag σ₀`) whose posterior standard
//!   deviation along them is above [`UNINFORMED`] × the prior's
//!   (eigenvalue below `1/0.9² − 1`), mapped back as `L w`.
//! - **outliers**: the standardised residual `t_i = r_i / (σ_i √(1 − h_ii))`,
//!   `h_ii = ã_i Σ ã_iᵀ` (`ã_i = a_i/σ_i`, `σ_i` the row's std or `s`,
//!   `Σ` the reported covariance); `|t_i| >` [`OUTLIER_LIMIT`] flags a likely
//!   outlier.

use nalgebra::{DMatrix, DVector};
use serde::Serialize;

use super::measurements::Design;
use super::subset::{self, Problem, Subset, SubsetChoice};
use crate::model::Machine;
use crate::named::NameMap;

pub use super::estimate::{Estimate, IdentifyError, SubsetProblem, SubsetSide};

/// Singular values of the equilibrated weighted design below this fraction
/// of the largest count as zero. The singular values come from the
/// information matrix, whose rounding is about `n ε λ_max` (`ε` = 2.2e-16),
/// i.e. `√(n ε) ≈ 2e-7` relative on `s`; 1e-6 stays above that.
pub const RANK_TOLERANCE: f64 = 1e-6;
/// Null-space components below this are omitted from the reported vectors.
pub const COMPONENT_CUTOFF: f64 = 1e-9;
/// With a prior, a direction whose posterior std is above this fraction of
/// its prior std is reported as not informed by the data.
pub const UNINFORMED: f64 = 0.9;
/// Standardised residuals above this in magnitude are flagged as likely
/// outliers.
pub const OUTLIER_LIMIT: f64 = 3.0;
/// How many of the largest standardised residuals are reported.
pub const LARGEST_RESIDUALS: usize = 10;

/// Options of [`identify`].
#[derive(Debug, Clone, Default, PartialEq)]
pub struct IdentifyOptions {
    /// A fixed rank tolerance: count the singular values above this
    /// fraction of the largest as determined (a manual override of the
    /// noise rule; in `(0, 1)`). `None`: [`RANK_TOLERANCE`] for the
    /// structural rank, then the noise rule ([`noise_rank`]).
    pub rank_tol: Option<f64>,
    /// Which unknowns are estimated.
    pub subset: SubsetChoice,
}

impl IdentifyOptions {
    /// The checks that need no data: a chosen subset naming some error,
    /// the rank tolerance in `(0, 1)`, no chosen subset with a prior.
    /// [`identify`] runs them; front ends run them before reading any file.
    pub fn check(&self, prior: bool) -> Result<(), IdentifyError> {
        let chosen = self.subset.chosen();
        if let Some((side, names)) = chosen {
            if names.iter().all(|n| n.trim().is_empty()) {
                return Err(IdentifyError::Subset {
                    side,
                    problem: SubsetProblem::NoName,
                });
            }
        }
        if let Some(t) = self.rank_tol {
            if !(t > 0.0 && t < 1.0) {
                return Err(IdentifyError::RankTolerance(t));
            }
        }
        match chosen {
            Some((side, _)) if prior => Err(IdentifyError::SubsetWithPrior { side }),
            _ => Ok(()),
        }
    }
}

/// How the count of determined directions (the reported rank) was decided.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct NoiseRule {
    /// `deviation` (the noise rule) or `rank-tol` (a fixed tolerance:
    /// [`IdentifyOptions::rank_tol`], or with a prior, or without a residual degree of
    /// freedom to measure the noise with).
    pub rule: &'static str,
    /// The relative tolerance on the singular values that gave the
    /// structural rank.
    pub tolerance: f64,
    /// The count of singular values above it.
    pub structural_rank: usize,
    /// The noise `σ̂` in units of the rows' stated std (1 without a `std`
    /// column: then in the measurement units), from the residual outside
    /// the structural rank.
    pub noise: Option<f64>,
    /// `‖y‖`: the whole measured deviation, in the same units.
    pub deviation: f64,
    /// The singular-value threshold `σ̂ √r₀ / ‖y‖` of the noise rule (for
    /// unit-norm columns, like the singular values).
    pub threshold: Option<f64>,
    /// The directions left out as weakly determined (structural rank less
    /// the rank).
    pub weak: usize,
}

/// The Gaussian prior of the unknowns, in the design's error order.
#[derive(Debug, Clone, PartialEq)]
pub struct Prior {
    /// Prior means.
    pub mean: Vec<f64>,
    /// Prior standard deviations (> 0).
    pub std: Vec<f64>,
}

impl Prior {
    /// The prior with `count` more unknowns without one (mean 0, infinite
    /// std: weight 0), the set-ups' positions after the machine's errors.
    pub fn with_free(mut self, count: usize) -> Prior {
        self.mean.extend(std::iter::repeat_n(0.0, count));
        self.std.extend(std::iter::repeat_n(f64::INFINITY, count));
        self
    }

    /// The `statistics` section of `machine` as independent Gaussians for
    /// `errors` (normal entries as given; uniform ones by their mean and
    /// standard deviation). Every error needs an entry.
    pub fn from_machine(machine: &Machine, errors: &[String]) -> Result<Prior, IdentifyError> {
        let mut mean = Vec::with_capacity(errors.len());
        let mut std = Vec::with_capacity(errors.len());
        let mut missing = Vec::new();
        for name in errors {
            match machine.error_index(name).and_then(|j| machine.statistic(j)) {
                Some(s) => {
                    mean.push(s.distribution.mean());
                    std.push(s.distribution.std());
                }
                None => missing.push(name.clone()),
            }
        }
        if missing.is_empty() {
            Ok(Prior { mean, std })
        } else {
            Err(IdentifyError::NoPrior {
                machine: machine.name.clone(),
                missing,
            })
        }
    }
}

/// The residual of the fit.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Residual {
    /// Root mean square of `b − A x` over the scalar rows.
    pub rms: f64,
    /// The largest `|b − A x|`.
    pub max: f64,
    /// `Σ ((b − A x)/σ)²` (`σ = 1` without a `std` column).
    pub rss: f64,
    /// The residual degrees of freedom `m − rank`.
    pub dof: usize,
    /// The noise scale `s = √(RSS/dof)` (in the measurement units without a
    /// `std` column; with one, the ratio of the scatter to the stated std).
    pub scale: Option<f64>,
}

/// A standardised residual.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Standardised {
    /// The scalar row (0-based) in the design.
    pub row: usize,
    /// The component ([`super::measurements::MeasuredComponent::name`]:
    /// `dpx`, `dpy`, `dpz` or `d`).
    pub component: &'static str,
    /// `b − A x`.
    pub residual: f64,
    /// `t = r / (σ √(1 − h))`.
    pub standardised: f64,
    /// The row's leverage `h`.
    pub leverage: f64,
    /// `|t| >` [`OUTLIER_LIMIT`].
    pub outlier: bool,
}

/// A group of unknowns the null space couples, and its basis vectors.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AliasGroup {
    /// The unknowns of the group (indices into the errors).
    pub members: Vec<usize>,
    /// The group's size less its vectors: for a null space, the rank of
    /// the design's columns of the group.
    pub column_rank: usize,
    /// The indices of the group's vectors in the basis.
    pub vectors: Vec<usize>,
    /// How many of those are weak directions (seen by the measurements,
    /// but only within their noise: left out by the noise rule) rather
    /// than directions the measurements cannot see at all.
    pub weak: usize,
}

/// The result of [`identify`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Identification {
    /// Scalar measurement rows `m`.
    pub rows: usize,
    /// Unknowns `n`.
    pub parameters: usize,
    /// The rank of the design.
    pub rank: usize,
    /// The condition number of the equilibrated design on its identifiable
    /// part.
    pub condition: f64,
    /// The singular values of the equilibrated weighted design, largest
    /// first.
    pub singular_values: Vec<f64>,
    /// Whether the rows had their standard deviations.
    pub weighted: bool,
    /// Whether a prior was used.
    pub prior: bool,
    /// The unknowns' names.
    pub errors: Vec<String>,
    /// The estimates, by name.
    pub estimates: NameMap<String, Estimate>,
    /// The covariance of the estimates (`n × n`; NaN where undefined).
    #[serde(skip)]
    pub covariance: DMatrix<f64>,
    /// Orthonormal basis of what the data cannot tell (the null space; with
    /// a prior, the directions it did not inform), `n × k`.
    #[serde(skip)]
    pub null_space: DMatrix<f64>,
    /// The same as `{error: component}` maps, components below
    /// [`COMPONENT_CUTOFF`] omitted.
    pub unidentifiable: Vec<NameMap<String, f64>>,
    /// The groups of unknowns the basis couples (each vector in one group).
    pub groups: Vec<AliasGroup>,
    /// The residual.
    pub residual: Residual,
    /// The residuals `b − A x`, one per row.
    #[serde(skip)]
    pub residuals: Vec<f64>,
    /// The largest standardised residuals (at most [`LARGEST_RESIDUALS`]),
    /// largest first.
    pub largest_residuals: Vec<Standardised>,
    /// How many standardised residuals exceed [`OUTLIER_LIMIT`].
    pub outliers: usize,
    /// How the rank was decided.
    pub noise: NoiseRule,
    /// The estimated subset and its least-squares solution (`None` with a
    /// prior; in the document as `subset`).
    #[serde(skip)]
    pub subset: Option<Subset>,
}

impl Identification {
    /// The values and covariance a calibration uses: the subset's
    /// least-squares solution, or with a prior the posterior.
    pub fn solution(&self) -> (Vec<f64>, &DMatrix<f64>) {
        match &self.subset {
            Some(s) => (s.values(), &s.covariance),
            None => (
                self.estimates.0.iter().map(|(_, e)| e.value).collect(),
                &self.covariance,
            ),
        }
    }
}

/// Data coordinates along a direction at least this many standard
/// deviations from zero count as determined, however weak the direction
/// ([`noise_rule`]).
pub const SIGNIFICANT: f64 = 5.0;

/// The noise rule: which of the structural directions
/// of the equilibrated weighted design (singular values `s`, largest first;
/// `c_i = u_iᵀ y` the data's coordinate along each) the data do not
/// determine beyond their noise.
///
/// The noise is `σ̂ = √(RSS_⊥ / (m − r₀))`, from the residual outside the
/// `r₀ = s.len()` structural directions (in the rows' weighted units: the
/// stated std's with a `std` column, the measurement units without). Along
/// the `i`-th direction the estimate's standard deviation, as an effect on
/// the measurements (the norm over the rows of what the errors along it do
/// alone, each error's column scaled to unit norm), is `σ̂ / s_i`, and the
/// estimate is `c_i / s_i`. A direction is **weakly determined** when
///
/// - its standard deviation exceeds a direction's share of the measured
///   deviation, `σ̂ / s_i > ‖y‖ / √r₀`: one standard deviation of noise
///   alone would give the errors along it effects larger than each of the
///   `r₀` directions would carry if the whole deviation `‖y‖` the machine
///   shows were spread evenly over them (a Tikhonov filter factor below
///   1/2 for the spread `τ = ‖y‖/√r₀` of the equilibrated errors); and
/// - its estimate is within [`SIGNIFICANT`] standard deviations of zero,
///   `|c_i| < 5 σ̂`: the data do not show it either.
///
/// Such a direction's estimate says nothing about the machine; it is left
/// out (the errors it moves are fixed, [`super::subset`]). Returns the weak
/// flags and `σ̂`; `None` when there is no residual degree of freedom
/// (`m ≤ r₀`), no noise (`RSS_⊥ = 0`) or no deviation: then every
/// structural direction counts.
pub fn noise_rule(
    s: &[f64],
    c: &[f64],
    rss_perp: f64,
    m: usize,
    deviation: f64,
) -> Option<(Vec<bool>, f64)> {
    let r0 = s.len();
    let positive = |v: f64| v > 0.0 && v.is_finite();
    if r0 == 0 || m <= r0 || !positive(rss_perp) || !positive(deviation) {
        return None;
    }
    let sigma = (rss_perp / (m - r0) as f64).sqrt();
    let share = deviation / (r0 as f64).sqrt();
    let weak = s
        .iter()
        .zip(c)
        .map(|(&si, &ci)| si * share < sigma && ci.abs() < SIGNIFICANT * sigma)
        .collect();
    Some((weak, sigma))
}

/// Identifies the unknowns of `design` (spec section 4): the minimum-norm
/// weighted least-squares estimate, or with `prior` the posterior mean and
/// covariance. See the module's formulas; `options` set the rank rule and
/// the estimated subset ([`subset`]).
pub fn identify(
    design: &Design,
    prior: Option<&Prior>,
    options: &IdentifyOptions,
) -> Result<Identification, IdentifyError> {
    let (m, n) = design.a.shape();
    options.check(prior.is_some())?;
    let tolerance = options.rank_tol.unwrap_or(RANK_TOLERANCE);
    if m == 0 && prior.is_none() {
        return Err(IdentifyError::NoRows);
    }
    if let Some(p) = prior {
        if p.mean.len() != n || p.std.len() != n {
            return Err(IdentifyError::PriorSize {
                prior: p.mean.len(),
                unknowns: n,
            });
        }
    }
    if design.a.iter().chain(&design.b).any(|v| !v.is_finite()) {
        return Err(IdentifyError::NotFinite);
    }
    let weighted = design.std.is_some();
    let inv_sigma: Vec<f64> = match &design.std {
        Some(s) => s.iter().map(|s| 1.0 / s).collect(),
        None => vec![1.0; m],
    };
    // B = diag(1/σ) A, y = b/σ.
    // Column by column: contiguous in nalgebra's column-major storage
    // (scaling row by row strides through memory and took 40 ms at
    // 3·10⁴ × 173).
    let mut bm = design.a.clone();
    if design.std.is_some() {
        let w = DVector::from_column_slice(&inv_sigma);
        for mut col in bm.column_iter_mut() {
            col.component_mul_assign(&w);
        }
    }
    let y = DVector::from_iterator(m, design.b.iter().zip(&inv_sigma).map(|(b, w)| b * w));
    let info = gram(&bm);
    let g = bm.tr_mul(&y);
    let Spectrum {
        d,
        lambda,
        vectors: v,
        rank: structural,
    } = spectrum_with(&info, tolerance);
    let s_max = lambda.first().copied().unwrap_or(0.0).max(0.0).sqrt();
    let singular: Vec<f64> = lambda.iter().map(|l| l.max(0.0).sqrt()).collect();
    // The data's coordinates along the structural directions, c_i = u_iᵀ y
    // = v_iᵀ D g / s_i, and the residual outside them.
    let dg0 = DVector::from_fn(n, |i, _| d[i] * g[i]);
    let coords: Vec<f64> = (0..structural)
        .map(|k| v.column(k).dot(&dg0) / singular[k])
        .collect();
    // The residual itself, y − B·D·Σ_k v_k c_k/s_k (‖y‖² − Σc² would lose
    // the digits of a clean fit to cancellation).
    let x_perp = DVector::from_fn(n, |i, _| {
        d[i] * (0..structural)
            .map(|k| v[(i, k)] * coords[k] / singular[k])
            .sum::<f64>()
    });
    let rss_perp = (&y - &bm * &x_perp).norm_squared();
    let deviation = y.norm();
    let noisy = if options.rank_tol.is_none() && prior.is_none() {
        noise_rule(&singular[..structural], &coords, rss_perp, m, deviation)
    } else {
        None
    };
    let weak: Vec<bool> = match &noisy {
        Some((w, _)) => w.clone(),
        None => vec![false; structural],
    };
    // The determined directions first (largest first), then the weak ones,
    // then those beyond the structural rank: every "leading `rank`" below
    // is the determined set.
    let order: Vec<usize> = (0..structural)
        .filter(|&k| !weak[k])
        .chain((0..structural).filter(|&k| weak[k]))
        .chain(structural..n)
        .collect();
    let rank = structural - weak.iter().filter(|&&w| w).count();
    let lambda: Vec<f64> = order.iter().map(|&k| lambda[k]).collect();
    let v = DMatrix::from_fn(n, n, |i, c| v[(i, order[c])]);
    let noise_rule = NoiseRule {
        rule: if noisy.is_some() {
            "deviation"
        } else {
            "rank-tol"
        },
        tolerance,
        structural_rank: structural,
        noise: noisy.as_ref().map(|(_, s)| *s),
        deviation,
        threshold: noisy
            .as_ref()
            .map(|(_, s)| s * (structural as f64).sqrt() / deviation),
        weak: structural - rank,
    };
    let condition = if rank > 0 {
        s_max / lambda[rank - 1].max(0.0).sqrt()
    } else {
        f64::INFINITY
    };
    // What the data cannot tell, in the unknowns' own coordinates:
    // span(D V_rest) over the weak and the structural null directions,
    // orthonormalised (reported); the structural null space alone is what
    // the minimum-norm solution is orthogonal to (a weak direction moves
    // the prediction, so projecting along it would change the fit: it is
    // left at zero in the equilibrated coordinates instead).
    let basis_of = |from: usize| {
        orthonormal(&DMatrix::from_fn(n, n - from, |i, k| {
            d[i] * v[(i, from + k)]
        }))
    };
    let unseen = basis_of(rank);
    let null = basis_of(structural);
    let project = |x: &DVector<f64>| -> DVector<f64> {
        if null.ncols() == 0 {
            x.clone()
        } else {
            x - &null * (null.tr_mul(x))
        }
    };
    // x = P D V_r Λ_r⁻¹ V_rᵀ D g.
    let dg = DVector::from_fn(n, |i, _| d[i] * g[i]);
    let mut xs = DVector::zeros(n);
    for (k, l) in lambda.iter().enumerate().take(rank) {
        let vk = v.column(k);
        xs += vk * (vk.dot(&dg) / l);
    }
    let x_ls = project(&DVector::from_fn(n, |i, _| d[i] * xs[i]));
    // (Aᵀ W A)⁺ = P D V_r Λ_r⁻¹ V_rᵀ D P.
    let vr = DMatrix::from_fn(n, rank, |i, k| d[i] * v[(i, k)] / lambda[k].sqrt());
    let mut cov_unit = &vr * vr.transpose();
    if null.ncols() > 0 {
        let p = DMatrix::identity(n, n) - &null * null.transpose();
        cov_unit = &p * cov_unit * &p;
    }
    let residuals_of = |x: &DVector<f64>| -> Vec<f64> {
        let ax = &design.a * x;
        design.b.iter().zip(ax.iter()).map(|(b, a)| b - a).collect()
    };
    let ls_residuals = residuals_of(&x_ls);
    let ls_rss: f64 = (ls_residuals.iter().zip(&inv_sigma))
        .map(|(r, w)| (r * w) * (r * w))
        .sum();
    let dof = m.saturating_sub(rank);
    let ls_scale = (dof > 0).then(|| (ls_rss / dof as f64).sqrt());

    let (x, cov, unidentifiable_basis, noise) = match prior {
        None => {
            let (cov, noise) = if weighted {
                (cov_unit, Some(1.0))
            } else {
                match ls_scale {
                    Some(s) => (cov_unit * (s * s), Some(s)),
                    None => (DMatrix::from_element(n, n, f64::NAN), None),
                }
            };
            // An unknown the data cannot see at all (its unit vector lies in
            // the null space) has exactly 0 in the minimum-norm solution
            // and in its covariance; set it so, not the projection's
            // round-off (1e-20).
            let mut x = x_ls;
            let mut cov = cov;
            for j in 0..n {
                let inside: f64 = (0..null.ncols()).map(|k| null[(j, k)] * null[(j, k)]).sum();
                if inside > 1.0 - 1e-12 {
                    x[j] = 0.0;
                    cov.row_mut(j).fill(0.0);
                    cov.column_mut(j).fill(0.0);
                }
            }
            (x, cov, unseen, noise)
        }
        Some(p) => {
            // The noise: the stated std, or s of the least-squares fit.
            let s2 = if weighted || m == 0 {
                1.0
            } else {
                match ls_scale {
                    Some(s) => s * s,
                    None => return Err(IdentifyError::NoNoiseScale { rows: m, rank }),
                }
            };
            let fisher = &info / s2;
            let mut precision = fisher.clone();
            let mut rhs = &g / s2;
            for j in 0..n {
                let w0 = 1.0 / (p.std[j] * p.std[j]);
                precision[(j, j)] += w0;
                rhs[j] += w0 * p.mean[j];
            }
            // Equilibrated Cholesky of the (full-rank) posterior precision.
            let e: Vec<f64> = (0..n).map(|j| 1.0 / precision[(j, j)].sqrt()).collect();
            let scaled = DMatrix::from_fn(n, n, |i, j| e[i] * precision[(i, j)] * e[j]);
            let chol = nalgebra::Cholesky::new(scaled).ok_or(IdentifyError::NotFinite)?;
            let inv = chol.inverse();
            let cov = DMatrix::from_fn(n, n, |i, j| e[i] * inv[(i, j)] * e[j]);
            let x = &cov * rhs;
            // Directions the data did not inform (prior-standardised), over
            // the machine's errors: the set-ups' positions (no prior) are
            // profiled out of the information first.
            let ne = n - 3 * design.setups.len();
            let fisher_e = profiled(&fisher, ne);
            let k = DMatrix::from_fn(ne, ne, |i, j| p.std[i] * fisher_e[(i, j)] * p.std[j]);
            let (kappa, w) = symmetric_svd(&k);
            let limit = 1.0 / (UNINFORMED * UNINFORMED) - 1.0;
            let dirs: Vec<usize> = (0..ne).filter(|&i| kappa[i] < limit).collect();
            let raw = DMatrix::from_fn(n, dirs.len(), |i, c| {
                if i < ne {
                    p.std[i] * w[(i, dirs[c])]
                } else {
                    0.0
                }
            });
            (x, cov, orthonormal(&raw), Some(s2.sqrt()))
        }
    };
    let residuals = residuals_of(&x);
    let rss: f64 = (residuals.iter().zip(&inv_sigma))
        .map(|(r, w)| (r * w) * (r * w))
        .sum();
    let rms = if m > 0 {
        (residuals.iter().map(|r| r * r).sum::<f64>() / m as f64).sqrt()
    } else {
        0.0
    };
    let max = residuals.iter().fold(0.0f64, |a, r| a.max(r.abs()));
    // Standardised residuals: σ_i the row's std (times 1) or s.
    let mut largest = Vec::new();
    if let Some(s) = noise {
        let unit = if weighted { 1.0 } else { s };
        if unit > 0.0 && m > 0 {
            let cov_unit = &cov / (unit * unit);
            for (i, h) in leverages(&bm, &cov_unit).into_iter().enumerate() {
                if h < 1.0 - 1e-10 && h.is_finite() {
                    let sigma = unit / inv_sigma[i];
                    let ti = residuals[i] / (sigma * (1.0 - h).sqrt());
                    largest.push(Standardised {
                        row: i,
                        component: design.origin.get(i).map_or("", |o| o.1.name()),
                        residual: residuals[i],
                        standardised: ti,
                        leverage: h,
                        outlier: ti.abs() > OUTLIER_LIMIT,
                    });
                }
            }
        }
    }
    let outliers = largest.iter().filter(|s| s.outlier).count();
    largest.sort_by(|a, b| b.standardised.abs().total_cmp(&a.standardised.abs()));
    largest.truncate(LARGEST_RESIDUALS);

    let subset = if prior.is_none() {
        let problem = Problem {
            a: &design.a,
            b: &design.b,
            inv_sigma: &inv_sigma,
            weighted,
            info: &info,
            g: &g,
            d: &d,
            lambda: &lambda,
            vectors: &v,
            s_max,
            tolerance,
            names: &design.errors,
            structural,
            forced: 3 * design.setups.len(),
            scales: &design.scales,
        };
        let (by, kept) = subset::choose(&problem, rank, structural, &options.subset)?;
        // The elimination solves in the determined directions; a chosen
        // subset in the structural ones (the choice is the user's).
        let directions = if by == subset::ChosenBy::Elimination {
            rank
        } else {
            structural
        };
        Some(subset::solve(&problem, by, &kept, directions))
    } else {
        None
    };
    let (basis, mut groups) = grouped_basis(&unidentifiable_basis);
    if prior.is_none() && rank < structural {
        // Each group's vectors inside the structural null space: the
        // singular values of Nᵀ G equal to 1; the others are weak.
        for g in &mut groups {
            let gv = DMatrix::from_fn(n, g.vectors.len(), |i, c| basis[(i, g.vectors[c])]);
            let inside = if null.ncols() == 0 {
                0
            } else {
                let m = null.tr_mul(&gv);
                let svd = nalgebra::SVD::new(m, false, false);
                svd.singular_values
                    .iter()
                    .filter(|s| **s > 1.0 - 1e-6)
                    .count()
            };
            g.weak = g.vectors.len() - inside;
        }
    }
    let unidentifiable = (0..basis.ncols())
        .map(|k| {
            (0..n)
                .filter(|&i| basis[(i, k)].abs() >= COMPONENT_CUTOFF)
                .map(|i| (design.errors[i].clone(), basis[(i, k)]))
                .collect()
        })
        .collect();
    let estimates = (0..n)
        .map(|j| {
            let var = cov[(j, j)];
            let std = var.is_finite().then(|| var.max(0.0).sqrt());
            (design.errors[j].clone(), Estimate { value: x[j], std })
        })
        .collect();
    Ok(Identification {
        rows: m,
        parameters: n,
        rank,
        condition,
        singular_values: singular,
        weighted,
        prior: prior.is_some(),
        errors: design.errors.clone(),
        estimates,
        covariance: cov,
        null_space: basis,
        unidentifiable,
        groups,
        residual: Residual {
            rms,
            max,
            rss,
            dof,
            scale: if weighted {
                ls_scale
            } else {
                noise.filter(|_| dof > 0)
            },
        },
        residuals,
        largest_residuals: largest,
        outliers,
        noise: noise_rule,
        subset,
    })
}

/// The information on the first `ne` unknowns with the others profiled
/// out: the Schur complement `F_ee − F_es F_ss⁺ F_se` (the others' block
/// through nalgebra's pseudo-inverse); `F` itself when there are no others.
fn profiled(f: &DMatrix<f64>, ne: usize) -> DMatrix<f64> {
    let n = f.nrows();
    if ne == n {
        return f.clone();
    }
    let fee = f.view((0, 0), (ne, ne));
    let fes = f.view((0, ne), (ne, n - ne));
    let fss = f.view((ne, ne), (n - ne, n - ne)).into_owned();
    let inv = fss
        .pseudo_inverse(1e-14)
        .unwrap_or_else(|_| DMatrix::zeros(n - ne, n - ne));
    fee - fes * inv * fes.transpose()
}

/// Rows per block of [`gram`] and [`leverages`]: the unit of parallel work
/// (2048 rows of 173 unknowns are 2.8 MB).
const ROW_BLOCK: usize = 2048;

/// The row blocks `[start, end)` of an `m`-row matrix.
fn row_blocks(m: usize) -> Vec<(usize, usize)> {
    (0..m.div_ceil(ROW_BLOCK))
        .map(|k| (k * ROW_BLOCK, ((k + 1) * ROW_BLOCK).min(m)))
        .collect()
}

/// Maps each row block through `f`, on rayon's threads with the `parallel`
/// feature.
fn per_block<T: Send>(m: usize, f: impl Fn(usize, usize) -> T + Sync) -> Vec<T> {
    let blocks = row_blocks(m);
    #[cfg(feature = "parallel")]
    {
        use rayon::prelude::*;
        blocks.into_par_iter().map(|(a, b)| f(a, b)).collect()
    }
    #[cfg(not(feature = "parallel"))]
    {
        blocks.into_iter().map(|(a, b)| f(a, b)).collect()
    }
}

/// The information matrix `Bᵀ B = Σ_blocks B_kᵀ B_k`, each block through an
/// explicit transpose so that its product runs on nalgebra's blocked matrix
/// multiplication (`tr_mul` is a dot product per entry, several times
/// slower here), the blocks in parallel.
pub(crate) fn gram(b: &DMatrix<f64>) -> DMatrix<f64> {
    let (m, n) = b.shape();
    per_block(m, |r0, r1| {
        let block = b.rows(r0, r1 - r0);
        let bt = block.transpose();
        bt * block
    })
    .into_iter()
    .fold(DMatrix::zeros(n, n), |mut acc, g| {
        acc += g;
        acc
    })
}

/// The leverages `h_i = b_iᵀ Σ b_i` of the rows of `b` (the diagonal of the
/// hat matrix `B Σ Bᵀ`), one product `B_k Σ` per row block, in parallel.
fn leverages(b: &DMatrix<f64>, cov: &DMatrix<f64>) -> Vec<f64> {
    let m = b.nrows();
    per_block(m, |r0, r1| {
        let block = b.rows(r0, r1 - r0);
        let t = block * cov;
        (0..r1 - r0)
            .map(|i| t.row(i).dot(&block.row(i)))
            .collect::<Vec<f64>>()
    })
    .concat()
}

/// The spectrum of a column-equilibrated information matrix: the one rank
/// rule of `identify` and `plan`.
pub(crate) struct Spectrum {
    /// The equilibration `d_j = 1/√(AᵀWA)_jj` (1 for a zero column).
    pub d: Vec<f64>,
    /// The eigenvalues of `D AᵀWA D`, largest first (the squared singular
    /// values of `B D`).
    pub lambda: Vec<f64>,
    /// Its eigenvectors, in the same order.
    pub vectors: DMatrix<f64>,
    /// The count of singular values above [`RANK_TOLERANCE`] `× s_max`.
    pub rank: usize,
}

/// [`Spectrum`] of the information matrix `info = AᵀWA`: equilibrated by
/// its diagonal (a linear error in mm and an angular one in rad weigh
/// alike), decomposed through nalgebra's SVD.
pub(crate) fn spectrum(info: &DMatrix<f64>) -> Spectrum {
    spectrum_with(info, RANK_TOLERANCE)
}

/// [`spectrum`] with the relative rank tolerance `tolerance`.
pub(crate) fn spectrum_with(info: &DMatrix<f64>, tolerance: f64) -> Spectrum {
    let n = info.nrows();
    let d: Vec<f64> = (0..n)
        .map(|j| {
            let c = info[(j, j)].sqrt();
            if c > 0.0 {
                1.0 / c
            } else {
                1.0
            }
        })
        .collect();
    let scaled = DMatrix::from_fn(n, n, |i, j| d[i] * info[(i, j)] * d[j]);
    let (lambda, vectors) = symmetric_svd(&scaled);
    let s_max = lambda.first().copied().unwrap_or(0.0).max(0.0).sqrt();
    let rank = if s_max > 0.0 {
        lambda
            .iter()
            .filter(|l| l.max(0.0).sqrt() > tolerance * s_max)
            .count()
    } else {
        0
    };
    Spectrum {
        d,
        lambda,
        vectors,
        rank,
    }
}

/// Eigenvalues (largest first) and eigenvectors of a symmetric positive
/// semi-definite matrix, through nalgebra's SVD (for such a matrix the
/// singular values are the eigenvalues and `U = V`).
fn symmetric_svd(m: &DMatrix<f64>) -> (Vec<f64>, DMatrix<f64>) {
    let n = m.nrows();
    if n == 0 {
        return (Vec::new(), DMatrix::zeros(0, 0));
    }
    let svd = nalgebra::SVD::new(m.clone(), true, false);
    let u = svd.u.unwrap_or_else(|| DMatrix::identity(n, n));
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| svd.singular_values[b].total_cmp(&svd.singular_values[a]));
    let values = order.iter().map(|&k| svd.singular_values[k]).collect();
    let vectors = DMatrix::from_fn(n, n, |i, c| u[(i, order[c])]);
    (values, vectors)
}

/// An orthonormal basis of the column span of `m` (full column rank
/// assumed: its columns come from an orthonormal set scaled by a positive
/// diagonal), through nalgebra's SVD.
fn orthonormal(m: &DMatrix<f64>) -> DMatrix<f64> {
    let (n, k) = m.shape();
    if k == 0 {
        return DMatrix::zeros(n, 0);
    }
    let svd = nalgebra::SVD::new(m.clone(), true, false);
    let u = svd.u.unwrap_or_else(|| DMatrix::zeros(n, k));
    u.columns(0, k).into_owned()
}

/// Splits the span of the orthonormal `basis` into the groups of unknowns
/// it couples: unknowns `i`, `j` are linked when the projector `N Nᵀ` has
/// `|P_ij| ≥` [`COMPONENT_CUTOFF`]; the projector is block diagonal over
/// the connected groups, and each block's eigenvectors of eigenvalue 1
/// (nalgebra's SVD of the block) are the group's vectors. The vectors are
/// orthonormal, span the same space, and each lives on one group; each has
/// its largest component positive.
pub fn grouped_basis(basis: &DMatrix<f64>) -> (DMatrix<f64>, Vec<AliasGroup>) {
    let (n, k) = basis.shape();
    if k == 0 {
        return (DMatrix::zeros(n, 0), Vec::new());
    }
    let p = basis * basis.transpose();
    let mut group = vec![usize::MAX; n];
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for start in 0..n {
        if group[start] != usize::MAX || p[(start, start)] < COMPONENT_CUTOFF {
            continue;
        }
        let id = groups.len();
        let mut members = vec![start];
        group[start] = id;
        let mut at = 0;
        while at < members.len() {
            let i = members[at];
            for j in 0..n {
                if group[j] == usize::MAX && p[(i, j)].abs() >= COMPONENT_CUTOFF {
                    group[j] = id;
                    members.push(j);
                }
            }
            at += 1;
        }
        members.sort_unstable();
        groups.push(members);
    }
    let mut columns: Vec<DVector<f64>> = Vec::new();
    let mut out = Vec::new();
    for members in groups {
        let block = DMatrix::from_fn(members.len(), members.len(), |a, b| {
            p[(members[a], members[b])]
        });
        let dim = block.trace().round() as usize;
        let (_, vecs) = symmetric_svd(&block);
        let mut indices = Vec::new();
        for c in 0..dim.min(members.len()) {
            let mut full = DVector::zeros(n);
            for (a, &i) in members.iter().enumerate() {
                full[i] = vecs[(a, c)];
            }
            let big = full
                .iter()
                .fold(0.0f64, |m, v| if v.abs() > m.abs() { *v } else { m });
            if big < 0.0 {
                full.neg_mut();
            }
            indices.push(columns.len());
            columns.push(full);
        }
        out.push(AliasGroup {
            column_rank: members.len() - indices.len(),
            members,
            vectors: indices,
            weak: 0,
        });
    }
    let m = if columns.is_empty() {
        DMatrix::zeros(n, 0)
    } else {
        DMatrix::from_columns(&columns)
    };
    (m, out)
}
