//! The standard normal distribution: density, distribution function and its
//! inverse, computed so that tail probabilities keep their relative accuracy.
//!
//! `Φ(−β)` is evaluated as `½·erfc(β/√2)` (the complementary error function of
//! the `libm` port of fdlibm, accurate to about one ulp), never as `1 − Φ(β)`,
//! so a failure probability of `Φ(−8) ≈ 6.2·10⁻¹⁶` keeps all its digits. This
//! is the `R = Φ(β)` of the paper's Eq. 31.
//!
//! Which crate computes what was measured (the rule: `statrs` unless a kernel
//! is at least 1.3× faster or measurably more accurate in the tails, β up to
//! 8). Accuracy against mpmath (80 digits) at 2,321 points `x ∈ [−8, 8]` and
//! 7,940 points `p ∈ [10⁻¹⁶, 1 − 10⁻¹⁶]`; speed from `benches/kernels.rs`,
//! 1024 evaluations, one run:
//!
//! | function | kept | accuracy (max / mean ulp) | speed |
//! |---|---|---|---|
//! | `cdf`, `sf` | `libm::erfc` | 75 / 5.2 (libm) vs 886,252 / 155,082 (statrs 0.19.1 `erfc`: ~5·10⁻¹¹ relative on `|x| ∈ [0.7, 1.8]`) | statrs 1.9× faster |
//! | `pdf` | the formula | 15 / 2.66 vs 16 / 2.69 (statrs `Normal::pdf`) | formula 1.19× faster |
//! | `inverse_cdf` | `statrs` `erfc_inv` | 3 / 0.64 (statrs) vs 204 / 0.75 (hand-written Acklam + Halley) | statrs 7.0× faster |
//!
//! The `cdf`/`sf` error of both is dominated by the rounding of `x/√2`
//! (`erfc` amplifies a relative argument error by `2y²`, ≈ 60 at `x = 8`);
//! statrs' own error comes from its truncated interval constants (fixed
//! upstream after 0.19.1). `statrs`' pdf divides by `√(2π)` instead of
//! multiplying by `1/√(2π)`, which is no more accurate and moves the last
//! printed digit of the sensitivity and allocation outputs, so the one-line
//! formula stays.

use std::f64::consts::{FRAC_1_SQRT_2, SQRT_2};

/// `1/√(2π)`.
const FRAC_1_SQRT_2PI: f64 = 0.398_942_280_401_432_7;

/// The standard normal density `φ(x) = exp(−x²/2)/√(2π)` (the `∂R/∂β` of Eq. 33).
///
/// ```
/// assert!((reliability::normal::pdf(0.0) - 0.398_942_280_401_432_7).abs() < 1e-16);
/// ```
pub fn pdf(x: f64) -> f64 {
    FRAC_1_SQRT_2PI * (-0.5 * x * x).exp()
}

/// The standard normal distribution function `Φ(x) = ½·erfc(−x/√2)`.
///
/// `libm`'s `erfc`, not `statrs`' (see the module documentation: statrs 0.19.1
/// is 1.9× faster but off by up to ~10⁶ ulp). Relative accuracy is kept in the lower tail: `cdf(-8.0)` is
/// `6.220960574271785e-16` to about one ulp.
///
/// ```
/// let p = reliability::normal::cdf(-8.0);
/// assert!((p / 6.220_960_574_271_785e-16 - 1.0).abs() < 1e-13);
/// ```
pub fn cdf(x: f64) -> f64 {
    0.5 * libm::erfc(-x * FRAC_1_SQRT_2)
}

/// The upper tail `1 − Φ(x) = Φ(−x)`, computed directly (no cancellation):
/// the failure probability `p_f = Φ(−β)` of a reliability index `β`.
pub fn sf(x: f64) -> f64 {
    0.5 * libm::erfc(x * FRAC_1_SQRT_2)
}

/// The mass `Φ(b) − Φ(a)` of the interval `[a, b]` (`a ≤ b`), computed on the
/// side of zero where it does not cancel.
pub fn interval(a: f64, b: f64) -> f64 {
    if a >= b {
        0.0
    } else if a >= 0.0 {
        sf(a) - sf(b)
    } else if b <= 0.0 {
        cdf(b) - cdf(a)
    } else {
        1.0 - cdf(a) - sf(b)
    }
}

/// The quantile `Φ⁻¹(p) = −√2·erfc⁻¹(2p)` for `p ∈ (0, 1)`; `−∞` at 0, `+∞`
/// at 1, NaN outside (`statrs`' `Normal::inverse_cdf` panics there, so the
/// inverse error function is called directly).
///
/// `statrs::function::erf::erfc_inv` (Boost's rational approximations):
/// against mpmath at 7,940 points `p ∈ [10⁻¹⁶, 1 − 10⁻¹⁶]` its largest error is
/// 3 ulp (mean 0.64), where a hand-written Acklam + two Halley steps
/// (`benches/kernels.rs`) reach 204 ulp near `p = ½` (mean 0.75); see
/// `docs/performance.md`.
///
/// ```
/// use reliability::normal::{cdf, inverse_cdf};
/// for p in [1e-300, 1e-12, 0.025, 0.5, 0.9] {
///     assert!((cdf(inverse_cdf(p)) / p - 1.0).abs() < 1e-12);
/// }
/// ```
pub fn inverse_cdf(p: f64) -> f64 {
    if p.is_nan() || !(0.0..=1.0).contains(&p) {
        return f64::NAN;
    }
    -SQRT_2 * statrs::function::erf::erfc_inv(2.0 * p)
}

/// The generalised reliability index `β = −Φ⁻¹(p_f)` of a failure probability,
/// accurate for tiny `p_f`.
pub fn beta_from_pf(pf: f64) -> f64 {
    -inverse_cdf(pf)
}

/// The probabilists' Gauss–Hermite rule of `n` nodes by Golub & Welsch
/// (1969): the eigenvalues of the Jacobi matrix of `He_k` (zero diagonal,
/// off-diagonal `√k`) and the squared first components of its eigenvectors,
/// the weights normalised to sum to 1 (`Σ w_k f(v_k) ≈ E f(V)`,
/// `V ~ N(0, 1)`, exact for polynomials of degree `2n − 1`).
pub fn gauss_hermite(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut j = nalgebra::DMatrix::<f64>::zeros(n, n);
    for k in 1..n {
        let b = (k as f64).sqrt();
        j[(k - 1, k)] = b;
        j[(k, k - 1)] = b;
    }
    let eig = nalgebra::SymmetricEigen::new(j);
    let mut pairs: Vec<(f64, f64)> = (0..n)
        .map(|k| (eig.eigenvalues[k], eig.eigenvectors[(0, k)].powi(2)))
        .collect();
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let total: f64 = pairs.iter().map(|p| p.1).sum();
    (
        pairs.iter().map(|p| p.0).collect(),
        pairs.iter().map(|p| p.1 / total).collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tail_values() {
        // Reference values of Φ(−β) (Abramowitz & Stegun 26.2; mpmath to 17 digits).
        let refs = [
            (1.0, 0.158_655_253_931_457_05),
            (3.0, 1.349_898_031_630_094_5e-3),
            (5.0, 2.866_515_718_791_939e-7),
            (8.0, 6.220_960_574_271_785e-16),
        ];
        for (b, p) in refs {
            assert!((sf(b) / p - 1.0).abs() < 1e-13, "beta {b}");
            assert!((cdf(-b) / p - 1.0).abs() < 1e-13, "beta {b}");
        }
    }

    #[test]
    fn quantile_round_trip() {
        for &p in &[1e-200, 1e-20, 1e-8, 0.001, 0.02425, 0.3, 0.5, 0.7, 0.999] {
            let x = inverse_cdf(p);
            let back = if p > 0.5 { 1.0 - sf(x) } else { cdf(x) };
            assert!((back / p - 1.0).abs() < 1e-12, "p {p}");
        }
        assert!((beta_from_pf(sf(7.5)) - 7.5).abs() < 1e-12);
        assert!(inverse_cdf(2.0).is_nan());
    }

    #[test]
    fn quantile_and_cdf_against_mpmath() {
        // mpmath (60 digits): √2·erfinv(2p − 1) and ncdf.
        let q = [
            (1e-16, -8.222_082_216_130_435),
            (3e-9, -5.816_757_740_125_828),
            (0.024_25, -1.972_961_051_311_884_8),
            (0.3, -0.524_400_512_708_040_8),
            (0.999_999, 4.753_424_308_817_088),
        ];
        for (p, want) in q {
            let got = inverse_cdf(p);
            assert!(
                (got / want - 1.0).abs() < 4.0 * f64::EPSILON,
                "p {p}: {got}"
            );
        }
        assert_eq!(inverse_cdf(0.5), 0.0);
        assert_eq!(inverse_cdf(0.0), f64::NEG_INFINITY);
        assert_eq!(inverse_cdf(1.0), f64::INFINITY);
        // Where statrs 0.19.1's erfc is off by ~5e-11 (|x| in [0.7, 1.8]): libm
        // keeps Φ to a few ulps.
        for (x, want) in [
            (-0.75, 0.226_627_352_376_868_2),
            (1.0, 0.841_344_746_068_542_9),
            (-1.5, 0.066_807_201_268_858_07),
        ] {
            assert!((cdf(x) / want - 1.0).abs() < 4.0 * f64::EPSILON, "x {x}");
        }
    }

    #[test]
    fn interval_mass() {
        assert!((interval(-1.0, 1.0) - 0.682_689_492_137_085_9).abs() < 1e-15);
        assert!((interval(6.0, 7.0) / (sf(6.0) - sf(7.0)) - 1.0).abs() < 1e-15);
        assert_eq!(interval(1.0, -1.0), 0.0);
    }
}
