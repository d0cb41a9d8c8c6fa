//! Lanes of points for the batched kernels of the `machine!` types
//! (`sensitivity_batch_into` and its siblings; docs/macro.md,
//! "The generated type").
//!
//! A generated batch function takes points in groups of [`LANES`]: `sin`
//! and `cos` of each rotary variable for the whole group at once with
//! [`sin_cos`], then the per-point body with those values. The other
//! helpers load a group's values and check a batch's shape for generated
//! code. The runtime tape (`symbolic::eval`) takes its `sin`/`cos` from
//! here too: [`sin_cos`] over a block's lanes, [`sin_cos_one`] for one
//! point, the same bits either way.
//!
//! [`sin_cos`] is written here, branch-free over four lanes so that LLVM
//! vectorises it, rather than taken from `wide` (whose `f64x4::sin_cos` has
//! the same algorithm): on the baseline x86-64 target `wide` converts the
//! quadrant lane by lane and is not inlined, and measured 1.6× slower (`cargo bench -p chain-core --bench lanes`; docs/performance.md,
//! "Batched generated kernels").

// The constants below keep their published digits (the same doubles).
#![allow(clippy::excessive_precision)]

/// Points per lane group of the batched generated kernels.
pub const LANES: usize = 4;

/// Variable `i` of four points.
#[inline(always)]
pub fn load<const V: usize>(q: &[[f64; V]; LANES], i: usize) -> [f64; LANES] {
    [q[0][i], q[1][i], q[2][i], q[3][i]]
}

/// Four points of `V` variables from `4 · V` consecutive values (a chunk of
/// a flat batch); missing values (a last, partial group) are 0.
#[inline(always)]
pub fn points<const V: usize>(flat: &[f64]) -> [[f64; V]; LANES] {
    core::array::from_fn(|l| core::array::from_fn(|i| flat.get(l * V + i).copied().unwrap_or(0.0)))
}

/// The first `N` values of `flat` as an array (`None` when it is shorter).
#[inline(always)]
pub fn row<const N: usize>(flat: &[f64]) -> Option<&[f64; N]> {
    flat.get(..N).and_then(|r| r.try_into().ok())
}

/// Beyond this |x| (and for NaN and ±∞) [`sin_cos`] takes the standard
/// library's `sin_cos` lane by lane: the three-part reduction below is
/// exact only while `y·DP1` is (|y| < 2²⁹), and its accuracy is tested to
/// here.
pub const SIN_COS_LIMIT: f64 = 65536.0;

/// `1.5 · 2⁵²`: adding it to a value below 2⁵¹ rounds it to an integer,
/// which is then the low bits of the sum's representation.
const ROUND: f64 = 6_755_399_441_055_744.0;

/// π/2 in three parts (Cody–Waite), the first with 24 significant bits so
/// that `y·DP1` is exact; the constants of Agner Fog's vector class library
/// (`vectormath_trig.h`, as in `wide`).
const DP1: f64 = 7.853_981_554_508_209_228_515_625E-1 * 2.0;
const DP2: f64 = 7.946_627_356_147_928_367_14E-9 * 2.0;
const DP3: f64 = 3.061_616_997_868_382_943_07E-17 * 2.0;

/// Minimax coefficients of `sin r = r + r³·S(r²)` and
/// `cos r = 1 − r²/2 + r⁴·C(r²)` on |r| ≤ π/4 (Cephes `sin.c`, as in the
/// vector class library).
const SIN: [f64; 6] = [
    -1.666_666_666_666_663_072_95E-1,
    8.333_333_333_322_118_588_78E-3,
    -1.984_126_982_958_953_859_96E-4,
    2.755_731_362_138_572_452_13E-6,
    -2.505_074_776_285_780_728_66E-8,
    1.589_623_015_765_465_680_60E-10,
];
const COS: [f64; 6] = [
    4.166_666_666_666_659_292_18E-2,
    -1.388_888_888_887_305_641_16E-3,
    2.480_158_728_885_170_453_48E-5,
    -2.755_731_417_929_673_881_12E-7,
    2.087_570_084_197_473_167_78E-9,
    -1.135_853_652_138_768_173_00E-11,
];

/// `c[0] + c[1]·x + … + c[5]·x⁵` (Horner).
#[inline(always)]
fn poly(x: f64, c: &[f64; 6]) -> f64 {
    ((((c[5] * x + c[4]) * x + c[3]) * x + c[2]) * x + c[1]) * x + c[0]
}

/// `(sin x, cos x)` of four values: reduction by the nearest multiple `y`
/// of π/2 (three-part Cody–Waite), the minimax polynomials on the reduced
/// argument, and the quadrant `y mod 4` choosing and signing them, every
/// lane without branches. Within 2 ulp of the standard library's `sin` and
/// `cos` (the test `sin_cos_is_within_two_ulp` says where); a lane with
/// |x| ≥ [`SIN_COS_LIMIT`], NaN or ±∞ is the standard library's. Each
/// lane's value depends on that lane's `x` alone, so [`sin_cos_one`] gives
/// the same bits for one value.
#[inline(always)]
pub fn sin_cos(x: [f64; LANES]) -> ([f64; LANES], [f64; LANES]) {
    let mut s = [0.0; LANES];
    let mut c = [0.0; LANES];
    for l in 0..LANES {
        let xa = x[l].abs();
        let shifted = xa * core::f64::consts::FRAC_2_PI + ROUND;
        let quadrant = shifted.to_bits();
        let y = shifted - ROUND;
        let r = ((xa - y * DP1) - y * DP2) - y * DP3;
        let r2 = r * r;
        let sr = r + r * r2 * poly(r2, &SIN);
        let cr = (1.0 - 0.5 * r2) + r2 * r2 * poly(r2, &COS);
        // Odd quadrants swap sin and cos.
        let swap = (quadrant & 1).wrapping_neg();
        let (sv, cv) = (sr.to_bits(), cr.to_bits());
        let sin_bits = (cv & swap) | (sv & !swap);
        let cos_bits = (sv & swap) | (cv & !swap);
        // sin: negative in quadrants 2 and 3, and for negative x; cos:
        // negative in quadrants 1 and 2.
        let sin_sign = (quadrant << 62) ^ x[l].to_bits();
        let cos_sign = (quadrant.wrapping_add(1) & 2) << 62;
        s[l] = f64::from_bits(sin_bits ^ (sin_sign & SIGN));
        c[l] = f64::from_bits(cos_bits ^ cos_sign);
    }
    let beyond = |v: f64| v.is_nan() || v.abs() >= SIN_COS_LIMIT;
    if x.iter().any(|&v| beyond(v)) {
        for l in 0..LANES {
            if beyond(x[l]) {
                (s[l], c[l]) = x[l].sin_cos();
            }
        }
    }
    (s, c)
}

/// [`sin_cos`] of one value (the same bits as in any lane of a group):
/// the runtime tape's `sin`/`cos`, so that its batched and per-point
/// evaluations agree bit for bit.
#[inline]
pub fn sin_cos_one(x: f64) -> (f64, f64) {
    let (s, c) = sin_cos([x; LANES]);
    (s[0], c[0])
}

/// The sign bit of an `f64`.
const SIGN: u64 = 1 << 63;

/// The batch shape check of [`crate::ErrorModel::sensitivity_points`], for
/// generated code: `(points, 6 · errors)`.
///
/// # Errors
/// [`crate::BatchError`] when a slice does not fit.
pub fn sensitivity_shape(
    variables: usize,
    errors: usize,
    qs_len: usize,
    out_len: usize,
) -> Result<(usize, usize), crate::BatchError> {
    crate::model_trait::sensitivity_shape(variables, errors, qs_len, out_len)
}

/// The batch shape check of [`crate::ErrorModel::error_points`], for
/// generated code: whether one row of error values serves every point.
///
/// # Errors
/// [`crate::BatchError`] when a slice does not fit.
pub fn error_shape(
    variables: usize,
    errors: usize,
    qs_len: usize,
    es_len: usize,
    out_len: usize,
) -> Result<bool, crate::BatchError> {
    crate::model_trait::error_shape(variables, errors, qs_len, es_len, out_len)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Distance in units in the last place between two finite doubles of
    /// the same sign (0 for equal values, ±0 included).
    fn ulps(a: f64, b: f64) -> u64 {
        if a == b {
            return 0;
        }
        if a.signum() != b.signum() {
            return u64::MAX;
        }
        (a.to_bits() as i64 - b.to_bits() as i64).unsigned_abs()
    }

    /// The doubles nearest `k·π/2` (three on each side) for |k| ≤ `kmax`:
    /// where the reduction by π/2 cancels most.
    fn near_multiples(kmax: i32) -> Vec<f64> {
        let mut xs = Vec::new();
        for k in -kmax..=kmax {
            let x = f64::from(k) * std::f64::consts::FRAC_PI_2;
            let (mut up, mut down) = (x, x);
            xs.push(x);
            for _ in 0..3 {
                up = up.next_up();
                down = down.next_down();
                xs.extend([up, down]);
            }
        }
        xs
    }

    /// The largest distance of [`sin_cos`] from `f64::sin_cos` over `xs`,
    /// in ulp and absolute, with the worst argument.
    fn worst(xs: &[f64]) -> (u64, f64, f64) {
        let mut worst = (0u64, 0.0f64, 0.0f64);
        for c in xs.chunks(LANES) {
            let mut x = [0.5; LANES];
            x[..c.len()].copy_from_slice(c);
            let (s, co) = sin_cos(x);
            for (l, &x) in c.iter().enumerate() {
                let (es, ec) = x.sin_cos();
                for (got, want) in [(s[l], es), (co[l], ec)] {
                    let d = ulps(got, want);
                    if d > worst.0 {
                        worst.0 = d;
                        worst.2 = x;
                    }
                    worst.1 = worst.1.max((got - want).abs());
                }
            }
        }
        worst
    }

    /// ≤ 2 ulp from `f64::sin` / `f64::cos` (docs/macro.md): 2·10⁶ points
    /// evenly over ±2π, 10⁶ evenly over ±[`SIN_COS_LIMIT`], and the doubles nearest
    /// every multiple of π/2 up to six turns (±12π). Beyond six turns the
    /// doubles nearest a zero of sin or cos get results below 1e-14 whose
    /// relative error grows (about 1e3 ulp), while the absolute error stays
    /// below one ulp of 1: checked up to 1e3 rad.
    #[test]
    fn sin_cos_is_within_two_ulp() {
        let two_pi = 2.0 * std::f64::consts::PI;
        let n = 2_000_000;
        let turn: Vec<f64> = (0..=n)
            .map(|k| -two_pi + 2.0 * two_pi * f64::from(k) / f64::from(n))
            .collect();
        let wide: Vec<f64> = (0..=1_000_000)
            .map(|k| SIN_COS_LIMIT * (2.0 * f64::from(k) / 1e6 - 1.0))
            .collect();
        for (what, xs) in [
            ("±2π", turn),
            ("±SIN_COS_LIMIT", wide),
            ("near k·π/2, |k| ≤ 24", near_multiples(24)),
        ] {
            let (ulp, _, x) = worst(&xs);
            assert!(ulp <= 2, "{what}: {ulp} ulp at x = {x:e}");
        }
        let (_, abs, _) = worst(&near_multiples(640));
        assert!(
            abs <= f64::EPSILON,
            "near k·π/2, |k| ≤ 640: {abs:e} absolute"
        );
    }

    #[test]
    fn non_finite_input_gives_nan() {
        let (s, c) = sin_cos([f64::NAN, f64::INFINITY, -f64::INFINITY, 0.0]);
        assert!(s[..3].iter().chain(&c[..3]).all(|v| v.is_nan()));
        assert_eq!((s[3], c[3]), (0.0, 1.0));
    }

    /// A lane's value depends on its own argument alone: the same bits
    /// beside NaN, ±∞, an argument beyond [`SIN_COS_LIMIT`] or finite
    /// neighbours, and from [`sin_cos_one`] (what lets the runtime tape's
    /// per-point and batched evaluations agree bit for bit). Beyond the
    /// limit a lane is the standard library's.
    #[test]
    fn lanes_are_independent() {
        let big = 2.0 * SIN_COS_LIMIT;
        // Arguments where the kernel and the standard library differ in
        // the last bits, so that a lane wrongly sent to the standard
        // library is seen.
        let xs: Vec<f64> = (0..2000)
            .map(|k| -7.0 + 14.0 * f64::from(k) / 2000.0)
            .filter(|&x| sin_cos_one(x) != x.sin_cos())
            .take(20)
            .collect();
        assert_eq!(xs.len(), 20);
        let neighbours = [f64::NAN, f64::INFINITY, big, 0.25];
        for &x in &xs {
            let one = sin_cos_one(x);
            for &n in &neighbours {
                let (s, c) = sin_cos([n, x, n, n]);
                assert_eq!(
                    (s[1].to_bits(), c[1].to_bits()),
                    (one.0.to_bits(), one.1.to_bits()),
                    "{x} beside {n}"
                );
            }
        }
        let (s, c) = sin_cos([0.3, big, 0.3, 0.3]);
        assert_eq!((s[1], c[1]), big.sin_cos());
    }
}
