//! The active-set Newton polish of the barrier solution and the KKT check
//! of the result.

use nalgebra::{DMatrix, DVector};

use super::problem::{CaseEval, Problem};
use crate::allocate::Kkt;
use crate::study::Study;

/// Solves `A x = b` (dense, row-major `n × n`) by nalgebra's LU
/// factorisation with partial pivoting; `None` when singular: a pivot (a
/// diagonal entry of `U`) at most `10⁻¹⁴` of the largest entry of `A`.
fn solve(a: Vec<f64>, b: Vec<f64>) -> Option<Vec<f64>> {
    let n = b.len();
    let a = DMatrix::from_row_slice(n, n, &a);
    let scale = a.amax().max(1e-300);
    let lu = a.lu();
    if lu.u().diagonal().iter().any(|d| d.abs() <= 1e-14 * scale) {
        return None;
    }
    lu.solve(&DVector::from_vec(b))
        .map(|x| x.as_slice().to_vec())
}

/// Newton on the KKT system of the active set identified by the barrier
/// solution; `None` if it does not converge to a KKT point.
pub(super) fn polish(
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

/// The KKT report of `t` with multipliers `lambda` (of the polish when
/// `polished`, else of the barrier point with parameter `mu`).
pub(super) fn kkt(
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
