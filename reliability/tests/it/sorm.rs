//! SORM against OpenTURNS 1.27's `SORM` (Breitung, Hohenbichler–Rackwitz,
//! Tvedt) on three non-normal cases; the numbers come from
//! `reliability/benches/openturns_sorm.py` (run by hand; CI has no
//! OpenTURNS). Tolerance: 1e-6 relative in each generalised index (the
//! required agreement; OpenTURNS' Abdo–Rackwitz stops at 1e-12 and its
//! Hessian is its symbolic one, ours exact).

use chain_core::model::Sided;
use reliability::sorm::Sorm;
use reliability::{Criterion, Event, Inputs, Marginal, ToleranceLimitState};

/// `(form, breitung, hr, tvedt)` printed by `openturns_sorm.py`.
type Ot = (f64, f64, f64, f64);

fn check(inputs: &Inputs, ls: ToleranceLimitState, ot: Ot, name: &str) {
    let event = Event::new(inputs, ls).unwrap();
    let r = Sorm::default().run(&event).unwrap();
    assert!(r.converged, "{name}");
    let rel = |a: f64, b: f64| ((a - b) / b).abs();
    let got = [
        ("form", r.form.beta, ot.0),
        ("breitung", r.beta_breitung, ot.1),
        ("hr", r.beta_hohenbichler_rackwitz, ot.2),
        ("tvedt", r.beta_tvedt, ot.3),
    ];
    for (what, a, b) in got {
        assert!(
            rel(a, b) < 1e-6,
            "{name} {what}: {a} vs OpenTURNS {b} (curvatures {:?})",
            r.curvatures
        );
    }
    assert_eq!(r.beta, r.beta_tvedt);
}

fn names(n: usize) -> Vec<String> {
    (0..n).map(|i| format!("x{i}")).collect()
}

#[test]
fn lognormal_weibull_gumbel_component() {
    let m = vec![
        Marginal::lognormal(1.0, 0.3, 0.0).unwrap(),
        Marginal::weibull(1.2, 2.5, 0.0).unwrap(),
        Marginal::gumbel(0.5, 0.2).unwrap(),
    ];
    let inputs = Inputs::new(names(3), m).unwrap();
    let ls = ToleranceLimitState::component(vec![1.0, 0.8, 1.1], 4.2, Sided::Upper).unwrap();
    let ot = (
        2.786292458307894e+00,
        2.625382599956072e+00,
        2.598017697720645e+00,
        2.614303866275532e+00,
    );
    check(&inputs, ls, ot, "lognormal-weibull-gumbel");
}

#[test]
fn truncated_triangular_rayleigh_normal_component() {
    let m = vec![
        Marginal::truncated_normal(0.0, 1.0, Some(-1.0), Some(3.0)).unwrap(),
        Marginal::triangular(0.0, 0.4, 2.0).unwrap(),
        Marginal::rayleigh(0.5, 0.0).unwrap(),
        Marginal::normal(0.2, 0.3).unwrap(),
    ];
    let inputs = Inputs::new(names(4), m).unwrap();
    let ls = ToleranceLimitState::component(vec![1.0, 1.0, 0.7, -0.5], 4.0, Sided::Upper).unwrap();
    let ot = (
        2.475667441137938e+00,
        2.52208848883342e+00,
        2.526888584179131e+00,
        2.528272218475197e+00,
    );
    check(&inputs, ls, ot, "truncated-triangular-rayleigh-normal");
}

#[test]
fn volumetric_norm_lognormal_rayleigh_weibull() {
    let m = vec![
        Marginal::lognormal(0.1, 0.05, -0.2).unwrap(),
        Marginal::rayleigh(0.3, 0.0).unwrap(),
        Marginal::weibull(0.5, 1.8, 0.0).unwrap(),
    ];
    let inputs = Inputs::new(names(3), m).unwrap();
    let rows = vec![1.0, 0.5, 0.0, -0.3, 0.0, 1.0];
    let ls = ToleranceLimitState::new(3, rows, vec![1.6], Criterion::Norm).unwrap();
    let ot = (
        3.44183521816662e+00,
        3.427589152914319e+00,
        3.426466700987701e+00,
        3.426569385882482e+00,
    );
    check(&inputs, ls, ot, "volumetric-lognormal-rayleigh-weibull");
}
