//! Normal inputs: Genz's separation of variables in the inputs' own
//! coordinates, randomised quasi-Monte Carlo, and the score-function
//! sensitivities on the same points (the module documentation of
//! [`super`], "Normal inputs").

use super::{Acceptance, AcceptanceMethod, AcceptanceResult, AcceptanceSensitivity, Rectangles};
use crate::error::ReliabilityError;
use crate::inputs::Inputs;
use crate::normal;
use crate::par::prelude::*;
use crate::rng::CaseRng;
use crate::util::dot;

/// A residual row this small relative to its row is in the span.
const SPAN_TOL: f64 = 1e-9;

impl Acceptance {
    /// The acceptance probability of `system` with normal inputs.
    pub(super) fn qmc(&self, system: &Rectangles) -> Result<AcceptanceResult, ReliabilityError> {
        let inputs = system.inputs();
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
            constraints: system.constraints(),
            distinct: system.distinct(),
            rank: r,
            pivots: plan.pivots.clone(),
            sensitivity: Vec::new(),
            subset: None,
        };
        let names = inputs.names();
        let zero_sens = || {
            (names.iter().zip(inputs.stds()))
                .filter(|(_, s)| **s > 0.0)
                .map(|(e, _)| AcceptanceSensitivity {
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
            // A fixed input (`carried_by`) has no spread to be sensitive to.
            (0..n)
                .filter(|&j| inputs.stds()[j] > 0.0)
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
        let inputs = system.inputs();
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
        // A fixed input's row and column of B are zero, and so are its
        // entries of Q (it is no direction of u the constraints see): a 1 on
        // its diagonal inverts the rest unchanged and leaves its scores 0.
        let mut invertible = bmat.clone();
        for j in (0..n).filter(|&j| inputs.stds()[j] == 0.0) {
            invertible[(j, j)] = 1.0;
        }
        let binv = invertible
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
    /// `((B⁻ᵀQᵀw)_j(BQᵀw)_j − κ_j)/σ_j` (0 for a fixed input).
    #[inline]
    fn scores(&self, w: &[f64], mean: &mut Vec<f64>, std: &mut Vec<f64>) {
        mean.resize(self.n, 0.0);
        std.resize(self.n, 0.0);
        let r = self.r;
        for j in 0..self.n {
            let a = dot(&self.c[j * r..(j + 1) * r], w);
            let b = dot(&self.d[j * r..(j + 1) * r], w);
            mean[j] = a;
            // 0 for a fixed input: the probability is even in its σ.
            std[j] = if self.stds[j] > 0.0 {
                (a * b - self.kappa[j]) / self.stds[j]
            } else {
                0.0
            };
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
