//! Other marginals: crude Monte Carlo with conditional derivatives, or
//! subset simulation of the small side when the pilot finds it rare
//! ([`super::rare`]; the module documentation of [`super`], "Other
//! marginals").

use super::rare::{self, AcceptanceSubset, RareSide};
use super::{
    Acceptance, AcceptanceMethod, AcceptanceResult, AcceptanceSampling, AcceptanceSensitivity,
    Rectangles, PILOT_BLOCKS, RARE_EVENTS,
};
use crate::error::ReliabilityError;
use crate::inputs::{Inputs, Marginal};
use crate::normal;
use crate::par::prelude::*;
use crate::rng::CaseRng;
use crate::util::dot;

/// Monte Carlo block size.
const BLOCK: u64 = 8192;

impl Acceptance {
    /// The acceptance probability of `system` with inputs of any marginal.
    pub(super) fn monte_carlo(
        &self,
        system: &Rectangles,
    ) -> Result<AcceptanceResult, ReliabilityError> {
        let inputs = system.inputs();
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
            // A fixed input (`carried_by`) has no spread to be sensitive to.
            (0..n)
                .filter(|&j| inputs.stds()[j] > 0.0)
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
            constraints: system.constraints(),
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
