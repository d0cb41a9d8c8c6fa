//! The log-barrier interior-point path: a strictly feasible start on the ray
//! towards the bounds, then damped Newton on
//! `f(t) − μ Σ ln gₖ(t) − μ Σ ln tᵢ − μ Σ ln(tmaxᵢ − tᵢ)` for decreasing `μ`.

use nalgebra::{DMatrix, DVector};

use super::problem::Problem;
use crate::allocate::AllocateError;

/// The barrier path of `problem` from a strictly feasible start (`big` caps
/// the unbounded `tᵢ`): the final point, barrier parameter and Newton
/// iterations.
pub(super) fn central_path(
    problem: &Problem,
    big: f64,
) -> Result<(Vec<f64>, f64, usize), AllocateError> {
    let n = problem.n();
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
    Ok((t, mu, iterations))
}

/// `H d = −g` with `H` made positive definite by a growing multiple of `I`:
/// the first shift `δ ∈ {0, 10⁻¹⁰·max|Hᵢᵢ|, 10× …}` for which nalgebra's
/// Cholesky factorisation of `H + δI` exists and gives a finite direction.
fn newton_direction(h: &[f64], g: &[f64]) -> Vec<f64> {
    let n = g.len();
    let h = DMatrix::from_row_slice(n, n, h);
    let rhs = -DVector::from_column_slice(g);
    let diag = h.diagonal().amax().max(1e-12);
    let mut delta = 0.0;
    loop {
        let shifted = &h + DMatrix::from_diagonal_element(n, n, delta);
        if let Some(d) = shifted.cholesky().map(|c| c.solve(&rhs)) {
            if d.iter().all(|x| x.is_finite()) {
                return d.as_slice().to_vec();
            }
        }
        delta = if delta == 0.0 {
            1e-10 * diag
        } else {
            delta * 10.0
        };
    }
}
