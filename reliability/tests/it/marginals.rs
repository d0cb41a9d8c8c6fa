//! The marginal families of `reliability-v2.md` §1: distribution functions
//! against `statrs` and closed forms, the transform `x = F⁻¹(Φ(u))` and its
//! tails to `β = 8`, its derivatives against finite differences, the
//! moments against quadrature, and the loader's located errors.

use chain_core::load_str;
use reliability::inputs::{Family, Marginal};
use reliability::normal;
use statrs::distribution::{ContinuousCDF, Gumbel, LogNormal, Triangular, Weibull};

/// `Φ(−8)` (mpmath, 17 digits; `normal.rs`' reference value).
const P8: f64 = 6.220_960_574_271_785e-16;

fn all() -> Vec<(&'static str, Marginal)> {
    vec![
        ("normal", Marginal::normal(0.3, 1.5).unwrap()),
        ("uniform", Marginal::uniform(-1.0, 2.0).unwrap()),
        ("lognormal", Marginal::lognormal(2.0, 0.7, 0.0).unwrap()),
        (
            "lognormal+shift",
            Marginal::lognormal(2.0, 0.7, -1.0).unwrap(),
        ),
        (
            "truncated [0, ∞)",
            Marginal::truncated_normal(0.0, 1.0, Some(0.0), None).unwrap(),
        ),
        (
            "truncated [-1, 2]",
            Marginal::truncated_normal(0.5, 1.2, Some(-1.0), Some(2.0)).unwrap(),
        ),
        (
            "truncated (-∞, 0.4]",
            Marginal::truncated_normal(1.0, 0.5, None, Some(0.4)).unwrap(),
        ),
        ("weibull k=1.7", Marginal::weibull(2.0, 1.7, 0.0).unwrap()),
        ("weibull k=0.8", Marginal::weibull(1.0, 0.8, 0.0).unwrap()),
        ("weibull+shift", Marginal::weibull(1.0, 2.5, 0.5).unwrap()),
        ("gumbel", Marginal::gumbel(1.0, 0.4).unwrap()),
        ("triangular", Marginal::triangular(0.0, 0.3, 1.0).unwrap()),
        (
            "triangular mode=min",
            Marginal::triangular(0.0, 0.0, 2.0).unwrap(),
        ),
        ("rayleigh", Marginal::rayleigh(0.8, 0.0).unwrap()),
    ]
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(f64::MIN_POSITIVE)
}

/// `T⁻¹(T(u)) = u` for `u ∈ [−8, 8]`, to `1e-10` plus the conditioning of
/// `x` itself (`16·ε·|x|/(dx/du)`: near a finite bound away from 0, `x`
/// cannot resolve `x − bound`; where the bound is 0 or infinite the
/// tolerance stays ~1e-10), and the tail probabilities `F(T(u)) = Φ(u)`
/// below the median, `1 − F = Φ(−u)` above, to the same `u` tolerance times
/// `u` (relative error of `Φ(u)` ≈ `|u|·Δu`).
#[test]
fn transform_round_trips_and_tails_to_beta_8() {
    for (name, m) in all() {
        for i in -160..=160 {
            let u = i as f64 / 20.0;
            let x = m.to_physical(u);
            let back = m.to_standard(x);
            let tol = 1e-10 + 16.0 * f64::EPSILON * x.abs() / m.dx_du(u);
            assert!(
                (back - u).abs() < tol,
                "{name}: u {u} → x {x} → {back} (tol {tol:e})"
            );
            let (lo, hi) = m.support();
            assert!(x >= lo && x <= hi, "{name}: {x} outside {lo}..{hi}");
            if u <= 0.0 {
                let p = m.cdf(x);
                let t = 1e-12 + 2.0 * (1.0 + u.abs()) * tol;
                assert!(rel(p, normal::cdf(u)) < t, "{name}: F({x}) = {p} at u {u}");
            } else {
                let q = m.sf(x);
                let t = 1e-12 + 2.0 * (1.0 + u.abs()) * tol;
                assert!(
                    rel(q, normal::sf(u)) < t,
                    "{name}: 1 − F({x}) = {q} at u {u}"
                );
            }
        }
    }
}

/// The values at `u = ±8` against each family's closed-form quantile at
/// `p = Φ(−8)` and `1 − p` (independent formulas; relative 1e-12, the
/// expansions `−ln(1 − p) = p + p²/2` and `erf(x/√2) = x·√(2/π)` exact to
/// that order at `p ≈ 6e-16`).
#[test]
fn tail_values_against_closed_form_quantiles() {
    let p = P8;
    let close = |a: f64, b: f64, what: &str| assert!(rel(a, b) < 1e-12, "{what}: {a} vs {b}");
    // Weibull: x = λ·(−ln(1 − F))^{1/k}.
    let w = Marginal::weibull(2.0, 1.7, 0.0).unwrap();
    close(w.to_physical(-8.0), 2.0 * p.powf(1.0 / 1.7), "weibull low");
    close(
        w.to_physical(8.0),
        2.0 * (-p.ln()).powf(1.0 / 1.7),
        "weibull high",
    );
    // Rayleigh: x = σ·√(−2 ln(1 − F)).
    let r = Marginal::rayleigh(0.8, 0.0).unwrap();
    close(r.to_physical(-8.0), 0.8 * (2.0 * p).sqrt(), "rayleigh low");
    close(
        r.to_physical(8.0),
        0.8 * (-2.0 * p.ln()).sqrt(),
        "rayleigh high",
    );
    // Gumbel: x = mode − β·ln(−ln F).
    let g = Marginal::gumbel(1.0, 0.4).unwrap();
    close(
        g.to_physical(-8.0),
        1.0 - 0.4 * (-p.ln()).ln(),
        "gumbel low",
    );
    close(g.to_physical(8.0), 1.0 - 0.4 * p.ln(), "gumbel high");
    // Triangular: a + √(F·(b − a)(c − a)), b − √((1 − F)(b − a)(b − c)).
    let t = Marginal::triangular(0.0, 0.3, 1.0).unwrap();
    close(t.to_physical(-8.0), (p * 0.3).sqrt(), "triangular low");
    let t = Marginal::triangular(-1.0, -0.7, 0.0).unwrap();
    close(t.to_physical(8.0), -(p * 0.7).sqrt(), "triangular high");
    // Half-normal [0, ∞): F = erf(x/√2), so x ≈ p·√(π/2) at F = p; at
    // 1 − F = p, Φ(−x) = p/2.
    let h = Marginal::truncated_normal(0.0, 1.0, Some(0.0), None).unwrap();
    close(
        h.to_physical(-8.0),
        p * (std::f64::consts::PI / 2.0).sqrt(),
        "half-normal low",
    );
    close(
        h.to_physical(8.0),
        -normal::inverse_cdf(p / 2.0),
        "half-normal high",
    );
    // Lognormal: x = exp(λ + ζu) with ζ² = ln(1 + cv²), λ = ln μ − ζ²/2.
    let l = Marginal::lognormal(2.0, 0.7, 0.0).unwrap();
    let z2 = (1.0f64 + 0.35 * 0.35).ln();
    close(
        l.to_physical(-8.0),
        (2f64.ln() - z2 / 2.0 - 8.0 * z2.sqrt()).exp(),
        "lognormal low",
    );
}

/// The distribution functions against statrs 0.19 at interior points,
/// relative 1e-10 (statrs 0.19.1's `erfc`, behind its lognormal, is off by
/// up to ~5e-11 relative, `normal.rs`; the others agree to 1e-13).
#[test]
fn cdfs_agree_with_statrs() {
    let l = Marginal::lognormal(2.0, 0.7, 0.0).unwrap();
    let z2 = (1.0f64 + 0.35 * 0.35).ln();
    let sl = LogNormal::new(2f64.ln() - z2 / 2.0, z2.sqrt()).unwrap();
    let w = Marginal::weibull(2.0, 1.7, 0.0).unwrap();
    let sw = Weibull::new(1.7, 2.0).unwrap();
    let g = Marginal::gumbel(1.0, 0.4).unwrap();
    let sg = Gumbel::new(1.0, 0.4).unwrap();
    let t = Marginal::triangular(0.0, 0.3, 1.0).unwrap();
    let st = Triangular::new(0.0, 1.0, 0.3).unwrap();
    for i in 1..40 {
        let q = i as f64 / 40.0;
        for (name, m, f) in [
            ("lognormal", l, sl.cdf(l.quantile(q))),
            ("weibull", w, sw.cdf(w.quantile(q))),
            ("gumbel", g, sg.cdf(g.quantile(q))),
            ("triangular", t, st.cdf(t.quantile(q))),
        ] {
            let x = m.quantile(q);
            let tol = if name == "lognormal" { 1e-10 } else { 1e-13 };
            assert!(
                rel(m.cdf(x), f) < tol,
                "{name} at {x}: {} vs statrs {f}",
                m.cdf(x)
            );
            assert!(rel(f, q) < tol, "{name}: statrs F(F⁻¹({q})) = {f}");
        }
    }
}

/// Mean and std against quadrature of `T(u)·φ(u)` (trapezoid, 48,001 nodes on
/// `[−12, 12]`: relative 1e-9; the triangular's `T` has a kink at the mode,
/// so 1e-7 there), and the density as the derivative of the distribution
/// function (`f(x)·dx/du = φ(u)`, relative 1e-12).
#[test]
fn moments_and_density() {
    for (name, m) in all() {
        let n = 48_000;
        let h = 24.0 / n as f64;
        let (mut s1, mut s2) = (0.0, 0.0);
        for i in 0..=n {
            let u = -12.0 + i as f64 * h;
            let w = if i == 0 || i == n { 0.5 } else { 1.0 } * h * normal::pdf(u);
            let x = m.to_physical(u);
            s1 += w * x;
            s2 += w * x * x;
        }
        let std = (s2 - s1 * s1).sqrt();
        let tol = if m.family() == Family::Triangular || m.family() == Family::Uniform {
            1e-7
        } else {
            1e-9
        };
        assert!(
            (s1 - m.mean()).abs() < tol * m.std().max(m.mean().abs()),
            "{name}: mean {s1} vs {}",
            m.mean()
        );
        assert!(rel(std, m.std()) < tol, "{name}: std {std} vs {}", m.std());
        for u in [-5.0, -1.3, 0.2, 2.0, 6.0] {
            let x = m.to_physical(u);
            let lhs = m.pdf(x) * m.dx_du(u);
            assert!(
                rel(lhs, normal::pdf(u)) < 1e-9,
                "{name} at u {u}: f·dx/du = {lhs}"
            );
        }
    }
}

/// `dx/du`, `d²x/du²` against central differences at `|u| ≤ 4` (step 1e-4
/// for the second derivative, 1e-6 for the first; relative 1e-6: beyond,
/// a bounded support's `x` cannot resolve the difference) and `∂x/∂μ`,
/// `∂x/∂σ` at fixed `u` against central differences through
/// [`Marginal::with_moments`] (step 1e-6·σ; relative 1e-6 or 1e-8 absolute).
#[test]
fn derivatives_against_finite_differences() {
    for (name, m) in all() {
        for u in [-4.0, -2.5, -0.7, 0.1, 0.9, 3.0, 4.0] {
            let h = 1e-6;
            let fd = (m.to_physical(u + h) - m.to_physical(u - h)) / (2.0 * h);
            // Plus the rounding of x in the difference, 4ε|x|/h.
            let noise = 4.0 * f64::EPSILON * m.to_physical(u).abs() / h;
            assert!(
                (m.dx_du(u) - fd).abs() < 1e-6 * fd.abs() + noise,
                "{name} dx/du at {u}: {} vs {fd}",
                m.dx_du(u)
            );
            let h2 = 1e-4;
            let fd2 = (m.dx_du(u + h2) - m.dx_du(u - h2)) / (2.0 * h2);
            let d2 = m.d2x_du2(u);
            assert!(
                (d2 - fd2).abs() < 1e-6 * fd2.abs().max(m.dx_du(u)),
                "{name} d²x/du² at {u}: {d2} vs {fd2}"
            );
            let (mu, s) = (m.mean(), m.std());
            let e = 1e-6 * s;
            let at = |mean: f64, std: f64| m.with_moments(mean, std).unwrap().to_physical(u);
            let fm = (at(mu + e, s) - at(mu - e, s)) / (2.0 * e);
            let fs = (at(mu, s + e) - at(mu, s - e)) / (2.0 * e);
            let (dm, ds) = (m.dx_dmean(u), m.dx_dstd(u));
            assert!(
                (dm - fm).abs() < 1e-6 * fm.abs().max(1e-2),
                "{name} ∂x/∂μ at {u}: {dm} vs {fm}"
            );
            assert!(
                (ds - fs).abs() < 1e-6 * fs.abs().max(1e-2),
                "{name} ∂x/∂σ at {u}: {ds} vs {fs}"
            );
        }
        // The moments are those asked for, the family kept.
        let moved = m
            .with_moments(m.mean() + 0.1 * m.std(), 0.9 * m.std())
            .unwrap();
        assert_eq!(moved.family(), m.family(), "{name}");
        assert!(
            rel(moved.mean(), m.mean() + 0.1 * m.std()) < 1e-10
                || (moved.mean() - m.mean() - 0.1 * m.std()).abs() < 1e-12,
            "{name}"
        );
        assert!(rel(moved.std(), 0.9 * m.std()) < 1e-10, "{name}");
    }
}

// ------------------------------------------------------------------ loading

const BASE: &str = "\
machine: m
bodies:
  bed: {}
  x_slide:
    parent: bed
    joint: {type: prismatic, axis: +x, variable: x}
    errors: {dx: dxx, ey: eyx}
workpiece: bed
tool: x_slide
statistics:
";

fn load_err(stat: &str) -> String {
    let text = format!("{BASE}  dxx: {stat}\n  eyx: {{std: 1.0e-6}}\n");
    match load_str(&text, "bad.yaml") {
        Ok(_) => panic!("loaded: {stat}"),
        Err(d) => {
            assert_eq!(d.len(), 1, "{stat}: {d:#}");
            d.to_string()
        }
    }
}

/// Every family loads from the file, arithmetic strings included, and gives
/// the marginal with the same moments as chain-core's `Distribution`.
#[test]
fn every_family_loads() {
    let cases = [
        (
            "{dist: lognormal, mean: 2.0e-6, std: 0.5e-6}",
            Family::Lognormal,
        ),
        (
            "{dist: lognormal, mean: '2 * 1e-6', std: 0.5e-6, shift: -1e-6}",
            Family::Lognormal,
        ),
        (
            "{dist: truncated_normal, mean: 0, std: 1e-6, min: -1e-6}",
            Family::TruncatedNormal,
        ),
        (
            "{dist: truncated_normal, std: 1e-6, min: -1e-6, max: '3e-6 / 2'}",
            Family::TruncatedNormal,
        ),
        (
            "{dist: weibull, scale: 1e-6, shape: 1.5, shift: 0}",
            Family::Weibull,
        ),
        ("{dist: gumbel, mode: 0, scale: 1e-6}", Family::Gumbel),
        (
            "{dist: triangular, min: -1e-6, mode: 0, max: 2e-6}",
            Family::Triangular,
        ),
        ("{dist: rayleigh, scale: 1e-6}", Family::Rayleigh),
    ];
    for (stat, family) in cases {
        let text = format!("{BASE}  dxx: {stat}\n  eyx: {{std: 1.0e-6}}\n");
        let m = load_str(&text, "ok.yaml").unwrap_or_else(|d| panic!("{stat}: {d:#}"));
        let d = m.statistics[0].distribution;
        let inputs = reliability::machine::inputs(&m).unwrap();
        let mg = inputs.marginals()[0];
        assert_eq!(mg.family(), family, "{stat}");
        assert!(
            rel(mg.mean(), d.mean()) < 1e-12 || (mg.mean() - d.mean()).abs() < 1e-18,
            "{stat}"
        );
        assert!(
            rel(mg.std(), d.std()) < 1e-12,
            "{stat}: {} vs {}",
            mg.std(),
            d.std()
        );
    }
}

/// Bad statistics: one error each, at `bad.yaml:LINE:COL`, naming the key.
#[test]
fn bad_statistics_are_located() {
    // `at`: 'o' the owner `dxx` (a missing key), 'k' the key, 'v' its value.
    let check = |stat: &str, at: char, key: &str, needle: &str| {
        let msg = load_err(stat);
        let last = key.rsplit('.').next().unwrap();
        let k = 8 + stat.find(&format!("{last}:")).unwrap_or(0);
        let at = match at {
            'o' => 3,
            'k' => k,
            _ => k + last.len() + 2,
        };
        let prefix = format!("bad.yaml:11:{at}: ");
        assert!(
            msg.starts_with(&prefix),
            "{stat}: expected {prefix}, got\n{msg}"
        );
        assert!(
            msg.contains(&format!("at key `{key}`")),
            "{stat}: key {key}\n{msg}"
        );
        assert!(msg.contains(needle), "{stat}: {needle:?}\n{msg}");
    };
    // Unknown family (with a suggestion).
    check(
        "{dist: lognormel, mean: 1, std: 1}",
        'v',
        "statistics.dxx.dist",
        "lognormel",
    );
    // Missing field.
    check(
        "{dist: weibull, scale: 1e-6}",
        'o',
        "statistics.dxx",
        "shape",
    );
    check(
        "{dist: triangular, min: 0, max: 1}",
        'o',
        "statistics.dxx",
        "mode",
    );
    check("{dist: lognormal, std: 1}", 'o', "statistics.dxx", "mean");
    check(
        "{dist: truncated_normal, std: 1}",
        'o',
        "statistics.dxx",
        "min",
    );
    // min ≥ max.
    check(
        "{dist: triangular, min: 1, mode: 1, max: 1}",
        'v',
        "statistics.dxx.max",
        "min < max",
    );
    check(
        "{dist: truncated_normal, std: 1, min: 2, max: 1}",
        'v',
        "statistics.dxx.max",
        "min < max",
    );
    // Mode outside [min, max].
    check(
        "{dist: triangular, min: 0, mode: 2, max: 1}",
        'v',
        "statistics.dxx.mode",
        "mode",
    );
    // Non-positive scale / shape / std.
    check(
        "{dist: weibull, scale: 0, shape: 1}",
        'v',
        "statistics.dxx.scale",
        "positive",
    );
    check(
        "{dist: weibull, scale: 1, shape: -2}",
        'v',
        "statistics.dxx.shape",
        "positive",
    );
    check(
        "{dist: gumbel, mode: 0, scale: '-1 * 2'}",
        'v',
        "statistics.dxx.scale",
        "positive",
    );
    check(
        "{dist: lognormal, mean: 1, std: 0}",
        'v',
        "statistics.dxx.std",
        "positive",
    );
    // A mean not above the shift.
    check(
        "{dist: lognormal, mean: 1, std: 1, shift: 1}",
        'v',
        "statistics.dxx.mean",
        "shift",
    );
    // Fields of another family.
    check(
        "{dist: gumbel, mode: 0, scale: 1, shape: 2}",
        'k',
        "statistics.dxx.shape",
        "does not apply",
    );
    check(
        "{dist: rayleigh, scale: 1, mean: 0}",
        'k',
        "statistics.dxx.mean",
        "does not apply",
    );
    check(
        "{dist: normal, std: 1, scale: 2}",
        'k',
        "statistics.dxx.scale",
        "does not apply",
    );
    check(
        "{dist: triangular, min: 0, mode: 0, max: 1, std: 1}",
        'k',
        "statistics.dxx.std",
        "does not apply",
    );
}
