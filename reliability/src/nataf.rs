//! The Nataf model (Gaussian copula) of correlated non-normal inputs
//! (`reliability-v2.md` §2): `x_i = F_i⁻¹(Φ(z_i))` with `z = L·u` standard
//! normal of correlation `R₀ = L·Lᵀ`, where each `ρ₀_ij` is the solution of
//! the Nataf integral equation (Liu & Der Kiureghian 1986, "Multivariate
//! distribution models with prescribed marginals and covariances",
//! *Probabilistic Engineering Mechanics* 1(2), Eq. 13):
//!
//! `ρ_ij = ∫∫ (x_i − μ_i)/σ_i · (x_j − μ_j)/σ_j · φ₂(z_i, z_j; ρ₀_ij) dz_i dz_j`.
//!
//! The integral is a 2-D Gauss–Hermite product rule in independent
//! `(v₁, v₂)`, `z_i = v₁`, `z_j = ρ₀·v₁ + √(1 − ρ₀²)·v₂` (the nodes and
//! weights of the probabilists' Hermite polynomials by Golub & Welsch 1969,
//! the eigen-decomposition of the Jacobi matrix), and `ρ₀` is found by a
//! safeguarded secant (Illinois) root search on `(−1, 1)`: `ρ(ρ₀)` is
//! increasing (Liu & Der Kiureghian, §3). Closed forms where they exist
//! (their Table 2 and Eq. 20-21): normal–normal `ρ₀ = ρ`; normal–lognormal
//! `ρ₀ = ρ·δ/ζ`; lognormal–lognormal `ρ₀ = ln(1 + ρ·δ_i·δ_j)/(ζ_i·ζ_j)`
//! with `δ = σ/(μ − shift)`, `ζ = √(ln(1 + δ²))`; uniform–uniform
//! `ρ₀ = 2·sin(πρ/6)` (Pearson 1907, the rank correlation of the normal).

use std::sync::OnceLock;

use crate::marginal::{Family, Marginal};

/// Gauss–Hermite nodes per dimension (the 2-D rule has its square). 96
/// nodes integrate the smooth families' products to ~1e-12 and the kinked
/// ones (triangular, truncated) to ~1e-6 in `ρ`.
const NODES: usize = 96;

/// The probabilists' Gauss–Hermite rule: nodes `v_k` and weights `w_k`
/// (`Σ w_k = 1`, `Σ w_k·f(v_k) ≈ E f(V)`, `V ~ N(0, 1)`).
pub(crate) fn gauss_hermite() -> &'static (Vec<f64>, Vec<f64>) {
    static RULE: OnceLock<(Vec<f64>, Vec<f64>)> = OnceLock::new();
    RULE.get_or_init(|| crate::normal::gauss_hermite(NODES))
}

/// The physical (Pearson) correlation of `x_a`, `x_b` when their normal
/// images have correlation `rho0` (the Nataf integral, 2-D Gauss–Hermite).
pub fn physical_correlation(a: &Marginal, b: &Marginal, rho0: f64) -> f64 {
    let (v, w) = gauss_hermite();
    let (ma, sa, mb, sb) = (a.mean(), a.std(), b.mean(), b.std());
    let c = (1.0 - rho0 * rho0).max(0.0).sqrt();
    let mut sum = 0.0;
    for (v1, w1) in v.iter().zip(w) {
        let ha = (a.to_physical(*v1) - ma) / sa;
        let mut inner = 0.0;
        for (v2, w2) in v.iter().zip(w) {
            inner += w2 * (b.to_physical(rho0 * v1 + c * v2) - mb) / sb;
        }
        sum += w1 * ha * inner;
    }
    sum
}

/// `(δ, ζ)` of a lognormal: `δ = σ/(μ − shift)`, `ζ = √(ln(1 + δ²))`.
fn lognormal_dz(m: &Marginal) -> (f64, f64) {
    let delta = m.std() / (m.mean() - m.support().0);
    (delta, libm::log1p(delta * delta).sqrt())
}

/// The Gaussian correlation `ρ₀` that gives the physical correlation `rho`
/// between `a` and `b`, or why none does (the attainable range of `ρ` for
/// these marginals, `[ρ(−1), ρ(1)]`, does not contain it).
pub fn adjusted_correlation(a: &Marginal, b: &Marginal, rho: f64) -> Result<f64, String> {
    if rho == 0.0 {
        return Ok(0.0);
    }
    let unattainable = |lo: f64, hi: f64| {
        format!(
            "a physical correlation of {rho} is not attainable between a {:?} and a {:?} marginal (attainable: [{lo:.6}, {hi:.6}])",
            a.family(),
            b.family()
        )
    };
    let check = |r0: f64| {
        if r0.is_finite() && r0.abs() < 1.0 {
            Ok(r0)
        } else {
            let (lo, hi) = (
                physical_correlation(a, b, -1.0),
                physical_correlation(a, b, 1.0),
            );
            Err(unattainable(lo, hi))
        }
    };
    match (a.family(), b.family()) {
        (Family::Normal, Family::Normal) => return Ok(rho),
        (Family::Normal, Family::Lognormal) => {
            let (d, z) = lognormal_dz(b);
            return check(rho * d / z);
        }
        (Family::Lognormal, Family::Normal) => {
            let (d, z) = lognormal_dz(a);
            return check(rho * d / z);
        }
        (Family::Lognormal, Family::Lognormal) => {
            let ((da, za), (db, zb)) = (lognormal_dz(a), lognormal_dz(b));
            let arg = 1.0 + rho * da * db;
            return check(if arg > 0.0 {
                arg.ln() / (za * zb)
            } else {
                f64::NAN
            });
        }
        (Family::Uniform, Family::Uniform) => {
            return check(2.0 * (std::f64::consts::PI * rho / 6.0).sin());
        }
        _ => {}
    }
    let f = |r0: f64| physical_correlation(a, b, r0) - rho;
    let (mut lo, mut hi) = (-1.0, 1.0);
    let (mut flo, mut fhi) = (f(lo), f(hi));
    if flo > 0.0 || fhi < 0.0 {
        return Err(unattainable(flo + rho, fhi + rho));
    }
    // Illinois (modified regula falsi), bracketing.
    let mut side = 0;
    for _ in 0..200 {
        let x = (lo * fhi - hi * flo) / (fhi - flo);
        let fx = f(x);
        if fx.abs() < 1e-14 || hi - lo < 1e-14 {
            return check(x);
        }
        if fx < 0.0 {
            lo = x;
            flo = fx;
            if side == -1 {
                fhi *= 0.5;
            }
            side = -1;
        } else {
            hi = x;
            fhi = fx;
            if side == 1 {
                flo *= 0.5;
            }
            side = 1;
        }
    }
    check(0.5 * (lo + hi))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_rule_integrates_normal_moments() {
        // E V^2k = (2k − 1)!! exactly for 2k ≤ 2·NODES − 1.
        let (v, w) = gauss_hermite();
        let m = |k: i32| v.iter().zip(w).map(|(v, w)| w * v.powi(k)).sum::<f64>();
        assert!((m(0) - 1.0).abs() < 1e-14);
        assert!((m(2) - 1.0).abs() < 1e-12);
        assert!((m(4) - 3.0).abs() < 1e-11);
        assert!((m(8) - 105.0).abs() < 1e-9);
    }

    #[test]
    fn closed_forms_agree_with_the_quadrature() {
        let n = Marginal::normal(1.0, 2.0).unwrap();
        let l = Marginal::lognormal(2.0, 0.8, 0.0).unwrap();
        let l2 = Marginal::lognormal(1.0, 0.3, -0.5).unwrap();
        let u = Marginal::uniform(0.0, 1.0).unwrap();
        for (a, b) in [(n, l), (l, n), (l, l2), (u, u)] {
            for rho in [-0.5, 0.3, 0.7] {
                let r0 = adjusted_correlation(&a, &b, rho).unwrap();
                let back = physical_correlation(&a, &b, r0);
                assert!((back - rho).abs() < 1e-9, "{rho}: {r0} → {back}");
            }
        }
    }
}
