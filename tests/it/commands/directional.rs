//! Directional simulation (reliability::directional) against closed forms.
//!
//! Sources: the volumetric norm of three independent normal components of
//! equal σ is a (non-central) χ with 3 degrees of freedom: central,
//! `P(χ²₃ ≥ x) = 2Φ(−√x) + √(2x/π)·e^{−x/2}` (Abramowitz & Stegun 26.4.5);
//! non-central, the Poisson mixture
//! `P(χ'²₃(λ) ≥ x) = Σ_j e^{−λ/2}(λ/2)^j/j! · Q(3/2 + j, x/2)` (A&S 26.4.25),
//! summed here with statrs' incomplete gamma; the two-sided component
//! `Φ(−(I − m)/s) + Φ(−(I + m)/s)`; a user limit state in non-normal inputs,
//! a brute-force Monte Carlo with its standard error.
//! Tolerance: 3 standard errors (combined with the Monte Carlo's where it
//! is the reference); the zero-variance isotropic case to 1e-12 relative.

use chain_core::model::Sided;
use reliability::normal;
use reliability::{
    Criterion, DirectionalSimulation, Event, Inputs, LimitState, Marginal, MonteCarlo, Sampler,
    Stop, ToleranceLimitState,
};
use statrs::function::gamma::gamma_ur;

fn inputs(means: &[f64], std: f64) -> Inputs {
    let names = (0..means.len()).map(|i| format!("e{i}")).collect();
    Inputs::new(
        names,
        means
            .iter()
            .map(|&m| Marginal::normal(m, std).unwrap())
            .collect(),
    )
    .unwrap()
}

fn volumetric(tolerance: f64) -> ToleranceLimitState {
    let rows = vec![1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
    ToleranceLimitState::new(3, rows, vec![tolerance], Criterion::Norm).unwrap()
}

fn ds(samples: u64, seed: u64) -> DirectionalSimulation {
    DirectionalSimulation {
        samples,
        seed,
        cov: None,
    }
}

#[test]
fn central_volumetric_is_the_chi2_tail_exactly() {
    // Every direction meets the sphere |u| = I/σ: zero variance.
    let s = 0.004f64;
    let r = 5.0f64;
    let x = r * r;
    let exact = 2.0 * normal::sf(r) + (2.0 * x / std::f64::consts::PI).sqrt() * (-0.5 * x).exp();
    let inp = inputs(&[0.0; 3], s);
    let event = Event::new(&inp, volumetric(r * s)).unwrap();
    let res = ds(1000, 1).run(&event).unwrap();
    assert!(
        (res.pf - exact).abs() < 1e-12 * exact,
        "{} vs {exact}",
        res.pf
    );
    assert!(res.std_error < 1e-12 * exact);
    let st = res.stopping.unwrap();
    assert!(st.converged && st.stopped_by == Stop::Samples);
}

#[test]
fn non_central_volumetric_is_within_three_standard_errors() {
    let s = 0.004f64;
    let mu = [0.006, -0.004, 0.002];
    let tol = 0.02f64;
    let lambda: f64 = mu.iter().map(|m| (m / s).powi(2)).sum();
    let x = (tol / s).powi(2);
    let mut exact = 0.0;
    let mut w = (-0.5 * lambda).exp();
    for j in 0..200 {
        exact += w * gamma_ur(1.5 + j as f64, 0.5 * x);
        w *= 0.5 * lambda / (j as f64 + 1.0);
    }
    let inp = inputs(&mu, s);
    let event = Event::new(&inp, volumetric(tol)).unwrap();
    let res = ds(200_000, 2).run(&event).unwrap();
    assert!(exact > 1e-4 && exact < 1e-2, "{exact}");
    assert!(
        (res.pf - exact).abs() < 3.0 * res.std_error,
        "{} ± {} vs {exact}",
        res.pf,
        res.std_error
    );
    assert!(res.cov < 0.05, "{}", res.cov);
}

#[test]
fn two_sided_component_is_within_three_standard_errors() {
    let inp = inputs(&[0.001, 0.0, -0.002, 0.0005], 0.01);
    let row = vec![1.0, -2.0, 0.5, 1.5];
    let g = ToleranceLimitState::component(row, 0.09, Sided::Two).unwrap();
    let event = Event::new(&inp, g).unwrap();
    let exact = event.exact_pf().unwrap();
    let res = ds(100_000, 3).run(&event).unwrap();
    assert!(exact > 1e-5 && exact < 1e-2, "{exact}");
    assert!(
        (res.pf - exact).abs() < 3.0 * res.std_error,
        "{} ± {} vs {exact}",
        res.pf,
        res.std_error
    );
    assert_eq!(res.samples, 100_000);
}

/// No affine view: the ray is scanned and the roots refined.
struct Quadratic;
impl LimitState for Quadratic {
    fn dim(&self) -> usize {
        2
    }
    fn branch(&self, _b: usize, x: &[f64], _g: Option<&mut [f64]>) -> f64 {
        2.4 - x[0] - x[1] * x[1]
    }
}

#[test]
fn a_general_limit_state_in_non_normal_inputs_agrees_with_monte_carlo() {
    let inp = Inputs::new(
        vec!["a".into(), "b".into()],
        vec![
            Marginal::uniform(-1.0, 1.0).unwrap(),
            Marginal::normal(0.0, 0.5).unwrap(),
        ],
    )
    .unwrap();
    let event = Event::new(&inp, Quadratic).unwrap();
    let d = ds(50_000, 4).run(&event).unwrap();
    let mc = MonteCarlo {
        samples: 4_000_000,
        seed: 4,
        cov: None,
    }
    .run(&event)
    .unwrap();
    let se = (d.std_error.powi(2) + mc.std_error.powi(2)).sqrt();
    assert!(
        (d.pf - mc.pf).abs() < 3.0 * se,
        "{} ± {} vs {} ± {}",
        d.pf,
        d.std_error,
        mc.pf,
        mc.std_error
    );
    // The scan costs more than one call per direction.
    assert!(d.calls > 10 * d.samples);
}

#[test]
fn the_general_path_equals_the_closed_form_path() {
    // The same two-sided component through a wrapper without the affine
    // view: the scanned roots equal the closed-form ones.
    struct Opaque(ToleranceLimitState);
    impl LimitState for Opaque {
        fn dim(&self) -> usize {
            self.0.dim()
        }
        fn branch(&self, b: usize, x: &[f64], g: Option<&mut [f64]>) -> f64 {
            self.0.branch(b, x, g)
        }
        fn branches(&self) -> usize {
            self.0.branches()
        }
    }
    let inp = inputs(&[0.001, 0.0, -0.002], 0.01);
    let g = ToleranceLimitState::component(vec![1.0, -2.0, 0.5], 0.07, Sided::Two).unwrap();
    let a = ds(5000, 5)
        .run(&Event::new(&inp, g.clone()).unwrap())
        .unwrap();
    let b = ds(5000, 5)
        .run(&Event::new(&inp, Opaque(g)).unwrap())
        .unwrap();
    assert!((a.pf - b.pf).abs() < 1e-9 * a.pf, "{} vs {}", a.pf, b.pf);
}
