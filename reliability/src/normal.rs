//! The standard normal distribution: density, distribution function and its
//! inverse, computed so that tail probabilities keep their relative accuracy.
//!
//! `Φ(−β)` is evaluated as `½·erfc(β/√2)` (the complementary error function of
//! the `libm` port of fdlibm, accurate to about one ulp), never as `1 − Φ(β)`,
//! so a failure probability of `Φ(−8) ≈ 6.2·10⁻¹⁶` keeps all its digits. This
//! is the `R = Φ(β)` of the paper's Eq. 31.

use std::f64::consts::FRAC_1_SQRT_2;

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
/// Relative accuracy is kept in the lower tail: `cdf(-8.0)` is
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

/// The quantile `Φ⁻¹(p)` for `p ∈ (0, 1)`; `−∞` at 0, `+∞` at 1, NaN outside.
///
/// Acklam's rational approximation (relative error below 1.2·10⁻⁹) refined by
/// one Halley step on `Φ(x) − p` evaluated with `erfc`, which brings it to
/// within a few ulps, also deep in the lower tail.
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
    if p == 0.0 {
        return f64::NEG_INFINITY;
    }
    if p == 1.0 {
        return f64::INFINITY;
    }
    // Work in the tail where p is represented accurately.
    if p > 0.5 {
        return -lower_quantile(1.0 - p);
    }
    lower_quantile(p)
}

/// The generalised reliability index `β = −Φ⁻¹(p_f)` of a failure probability,
/// accurate for tiny `p_f`.
pub fn beta_from_pf(pf: f64) -> f64 {
    -inverse_cdf(pf)
}

/// `Φ⁻¹(p)` for `0 < p ≤ 0.5`.
fn lower_quantile(p: f64) -> f64 {
    const A: [f64; 6] = [
        -3.969_683_028_665_376e1,
        2.209_460_984_245_205e2,
        -2.759_285_104_469_687e2,
        1.383_577_518_672_69e2,
        -3.066_479_806_614_716e1,
        2.506_628_277_459_239,
    ];
    const B: [f64; 5] = [
        -5.447_609_879_822_406e1,
        1.615_858_368_580_409e2,
        -1.556_989_798_598_866e2,
        6.680_131_188_771_972e1,
        -1.328_068_155_288_572e1,
    ];
    const C: [f64; 6] = [
        -7.784_894_002_430_293e-3,
        -3.223_964_580_411_365e-1,
        -2.400_758_277_161_838,
        -2.549_732_539_343_734,
        4.374_664_141_464_968,
        2.938_163_982_698_783,
    ];
    const D: [f64; 4] = [
        7.784_695_709_041_462e-3,
        3.224_671_290_700_398e-1,
        2.445_134_137_142_996,
        3.754_408_661_907_416,
    ];
    const P_LOW: f64 = 0.024_25;
    let x = if p < P_LOW {
        let q = (-2.0 * p.ln()).sqrt();
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    } else {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    };
    // One Halley step: e = Φ(x) − p, u = e/φ(x), x ← x − u/(1 + x·u/2).
    // Two steps when far in the tail keep the few-ulp accuracy.
    let mut x = x;
    for _ in 0..2 {
        let e = cdf(x) - p;
        let d = pdf(x);
        if d == 0.0 || !e.is_finite() {
            break;
        }
        let u = e / d;
        x -= u / (1.0 + 0.5 * x * u);
    }
    x
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
    fn interval_mass() {
        assert!((interval(-1.0, 1.0) - 0.682_689_492_137_085_9).abs() < 1e-15);
        assert!((interval(6.0, 7.0) / (sf(6.0) - sf(7.0)) - 1.0).abs() < 1e-15);
        assert_eq!(interval(1.0, -1.0), 0.0);
    }
}
