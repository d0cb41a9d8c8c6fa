//! The acceptance probability of non-normal inputs (docs/acceptance.md):
//! subset simulation of the small side, chosen by the crude Monte Carlo
//! pilot, against closed forms of independent products; the sensitivities
//! of Nataf-correlated non-normal inputs against finite differences of `P`
//! with common random numbers (the test's own generator and counting).

use reliability::acceptance::{
    Acceptance, AcceptanceMethod, AcceptanceSampling, RareSide, Rectangles,
};
use reliability::inputs::Correlation;
use reliability::{normal, Inputs, Marginal};

/// `Φ(−β)` of a lognormal's `x = exp(λ + ζβ)` (Ang & Tang 2007 Eq. 3.32,
/// computed here): the threshold with upper-tail probability `Φ(−β)`.
fn lognormal_quantile(mean: f64, std: f64, beta: f64) -> f64 {
    let zeta2 = (1.0 + (std / mean).powi(2)).ln();
    let lambda = mean.ln() - 0.5 * zeta2;
    (lambda + zeta2.sqrt() * beta).exp()
}

fn names(k: usize) -> Vec<String> {
    ["a", "b", "c"][..k].iter().map(|s| s.to_string()).collect()
}

/// Rejection ≈ 8.4e-6: lognormal `a ≤ t_a` with `P(a > t_a) = Φ(−4.5)`,
/// uniform `b ≤ 1 − 5·10⁻⁶` on (0, 1). `1 − P = 1 − (1 − Φ(−4.5))(1 − 5·10⁻⁶)`.
/// The pilot sees ~1 rejected sample of 131,072, so subset simulation runs
/// on the rejection side; the answer is within 3 of its standard errors
/// and its CoV near the 10 % target.
#[test]
fn small_rejection_by_subset_simulation_equals_the_closed_form() {
    let inputs = Inputs::new(
        names(2),
        vec![
            Marginal::lognormal(1.0, 0.2, 0.0).unwrap(),
            Marginal::uniform(0.0, 1.0).unwrap(),
        ],
    )
    .unwrap();
    let (qa, qb) = (normal::sf(4.5), 5e-6);
    let ta = lognormal_quantile(1.0, 0.2, 4.5);
    let system = Rectangles::new(
        inputs,
        vec![1.0, 0.0, 0.0, 1.0],
        vec![f64::NEG_INFINITY; 2],
        vec![ta, 1.0 - qb],
    )
    .unwrap();
    let r = Acceptance::default().run(&system).unwrap();
    assert_eq!(r.method, AcceptanceMethod::Subset);
    let s = r.subset.as_ref().expect("subset account");
    assert_eq!(s.side, RareSide::Rejection);
    assert!(s.pilot_events < 100 && s.pilot_samples == 131_072, "{s:?}");
    assert!(s.levels.len() >= 4, "{:?}", s.levels);
    let exact = 1.0 - (1.0 - qa) * (1.0 - qb);
    assert!(
        ((1.0 - r.probability) - exact).abs() <= 3.0 * r.std_error,
        "rejection {} ± {} vs {exact}",
        1.0 - r.probability,
        r.std_error
    );
    assert!(s.cov <= 0.1 && s.cov > 0.02, "{s:?}");
    assert!(r.converged);
    // Crude Monte Carlo over the same pilot cannot see it: the binomial
    // standard error of ~1 event is of the size of the answer itself.
    let mc = Acceptance {
        sampling: AcceptanceSampling::MonteCarlo,
        max_samples: 131_072,
        sensitivity: false,
        ..Acceptance::default()
    }
    .run(&system)
    .unwrap();
    assert_eq!(mc.method, AcceptanceMethod::MonteCarlo);
    assert!(
        mc.std_error > 0.3 * exact || mc.probability == 1.0,
        "{mc:?}"
    );
}

/// Acceptance ≈ 4·10⁻⁶ (the small side is `P` itself): lognormal
/// `a ≥ t_a` with `P(a ≥ t_a) = Φ(−3)`, uniform `b ≥ 1 − 3·10⁻³` on (0, 1):
/// `P = Φ(−3)·3·10⁻³`, subset simulation on the acceptance side.
#[test]
fn small_acceptance_by_subset_simulation_equals_the_closed_form() {
    let inputs = Inputs::new(
        names(2),
        vec![
            Marginal::lognormal(1.0, 0.2, 0.0).unwrap(),
            Marginal::uniform(0.0, 1.0).unwrap(),
        ],
    )
    .unwrap();
    let ta = lognormal_quantile(1.0, 0.2, 3.0);
    let system = Rectangles::new(
        inputs,
        vec![1.0, 0.0, 0.0, 1.0],
        vec![ta, 1.0 - 3e-3],
        vec![f64::INFINITY; 2],
    )
    .unwrap();
    let r = Acceptance {
        sensitivity: false,
        ..Acceptance::default()
    }
    .run(&system)
    .unwrap();
    assert_eq!(r.method, AcceptanceMethod::Subset);
    let s = r.subset.as_ref().unwrap();
    assert_eq!(s.side, RareSide::Acceptance);
    let exact = normal::sf(3.0) * 3e-3;
    assert!(
        (r.probability - exact).abs() <= 3.0 * r.std_error,
        "P {} ± {} vs {exact}",
        r.probability,
        r.std_error
    );
    assert!(r.std_error <= 0.12 * exact, "{r:?}");
}

/// The selection itself: a rejection of 2·10⁻³ (~260 pilot events, above
/// the threshold of 100) stays crude Monte Carlo and equals its closed
/// form; one of 3·10⁻⁴ (~40 events) goes to subset simulation;
/// `AcceptanceSampling::MonteCarlo` and `AcceptanceSampling::Subset` force either; a bad target
/// CoV is refused naming it.
#[test]
fn the_pilot_selects_subset_simulation_below_one_hundred_events() {
    let system = |q: f64| {
        let inputs = Inputs::new(names(1), vec![Marginal::uniform(0.0, 1.0).unwrap()]).unwrap();
        Rectangles::new(inputs, vec![1.0], vec![f64::NEG_INFINITY], vec![1.0 - q]).unwrap()
    };
    let plain = Acceptance {
        sensitivity: false,
        ..Acceptance::default()
    };
    let r = plain.run(&system(2e-3)).unwrap();
    assert_eq!(r.method, AcceptanceMethod::MonteCarlo);
    assert!(((1.0 - r.probability) - 2e-3).abs() <= 3.0 * r.std_error);
    let r = plain.run(&system(3e-4)).unwrap();
    assert_eq!(r.method, AcceptanceMethod::Subset, "{r:?}");
    let s = r.subset.as_ref().unwrap();
    assert!(s.pilot_events < 100 && s.pilot_events > 10, "{s:?}");
    assert!(((1.0 - r.probability) - 3e-4).abs() <= 3.0 * r.std_error);
    let forced = Acceptance {
        sampling: AcceptanceSampling::MonteCarlo,
        ..plain.clone()
    }
    .run(&system(3e-4))
    .unwrap();
    assert_eq!(forced.method, AcceptanceMethod::MonteCarlo);
    assert!(forced.subset.is_none());
    let forced = Acceptance {
        sampling: AcceptanceSampling::Subset,
        ..plain.clone()
    }
    .run(&system(0.2))
    .unwrap();
    assert_eq!(forced.method, AcceptanceMethod::Subset);
    assert!(((1.0 - forced.probability) - 0.2).abs() <= 3.0 * forced.std_error);
    let e = Acceptance {
        rare_cov: 0.0,
        ..plain
    }
    .run(&system(0.2))
    .unwrap_err();
    assert!(e.to_string().contains("rare_cov"), "{e}");
}

/// The test's own generator: splitmix64 + Box–Muller, independent of the
/// library's xoshiro256++ streams.
struct SplitMix(u64);

impl SplitMix {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut x = self.0;
        x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        x ^ (x >> 31)
    }
    fn uniform(&mut self) -> f64 {
        ((self.next() >> 11) + 1) as f64 / (1u64 << 53) as f64
    }
    fn normals(&mut self, out: &mut [f64]) {
        for pair in out.chunks_mut(2) {
            let r = (-2.0 * self.uniform().ln()).sqrt();
            let t = 2.0 * std::f64::consts::PI * self.uniform();
            pair[0] = r * t.cos();
            if pair.len() > 1 {
                pair[1] = r * t.sin();
            }
        }
    }
}

/// The central difference `(P(θ + h) − P(θ − h))/2h` with common random
/// numbers: the same standard normal draws `u` mapped through both inputs'
/// `x = T(u)`, the per-sample difference of the indicators counted, so
/// its standard error is the sample one. Returns `(estimate, std_error)`.
fn crn_difference(
    system: &Rectangles,
    plus: &Inputs,
    minus: &Inputs,
    h: f64,
    n: u64,
) -> (f64, f64) {
    let dim = plus.len();
    let threads = 2u64;
    let (s1, s2): (f64, f64) = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..threads)
            .map(|t| {
                scope.spawn(move || {
                    let mut rng = SplitMix(0xACCE_5700 + t);
                    let (mut u, mut xp, mut xm) = (vec![0.0; dim], vec![0.0; dim], vec![0.0; dim]);
                    let (mut s1, mut s2) = (0.0, 0.0);
                    for _ in 0..n / threads {
                        rng.normals(&mut u);
                        plus.to_physical(&u, &mut xp);
                        minus.to_physical(&u, &mut xm);
                        let d = f64::from(u8::from(system.accepts(&xp)))
                            - f64::from(u8::from(system.accepts(&xm)));
                        s1 += d;
                        s2 += d * d;
                    }
                    (s1, s2)
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().unwrap())
            .fold((0.0, 0.0), |a, b| (a.0 + b.0, a.1 + b.1))
    });
    let total = (n / threads * threads) as f64;
    let mean = s1 / total;
    let var = (s2 / total - mean * mean).max(0.0);
    (mean / (2.0 * h), (var / total).sqrt() / (2.0 * h))
}

/// Correlated non-normal inputs: a lognormal and a Weibull with ρ = 0.5
/// (Nataf), an independent uniform; `a + b + c ≤ 2.6`, `−0.6 ≤ a − b ≤
/// 0.6`. Every `∂P/∂μ_j`, `∂P/∂σ_j` (the copula matrix `R₀` held, as
/// `Inputs::with_moments` holds it) equals the common-random-number central
/// difference (h = 2 % of σ) within 3 combined standard errors.
#[test]
fn correlated_non_normal_sensitivities_equal_finite_differences() {
    let marginals = vec![
        Marginal::lognormal(1.0, 0.3, 0.0).unwrap(),
        Marginal::weibull(1.0, 3.0, 0.0).unwrap(),
        Marginal::uniform(-0.5, 0.5).unwrap(),
    ];
    let inputs = Inputs::correlated(
        names(3),
        marginals,
        &[Correlation {
            a: 0,
            b: 1,
            rho: 0.5,
        }],
    )
    .unwrap();
    let system = Rectangles::new(
        inputs.clone(),
        vec![1.0, 1.0, 1.0, 1.0, -1.0, 0.0],
        vec![f64::NEG_INFINITY, -0.6],
        vec![2.6, 0.6],
    )
    .unwrap();
    let r = Acceptance {
        samples: Some(1 << 21),
        ..Acceptance::default()
    }
    .run(&system)
    .unwrap();
    assert_eq!(r.method, AcceptanceMethod::MonteCarlo);
    assert!(r.probability > 0.5 && r.probability < 0.95, "{r:?}");
    let mut checked = 0;
    for j in 0..3 {
        let (mu, sd) = (inputs.means()[j], inputs.stds()[j]);
        let h = 0.02 * sd;
        let s = &r.sensitivity[j];
        for (what, got, se, (pm, ps), (mm, ms)) in [
            (
                "mean",
                s.dr_dmean,
                s.dr_dmean_std_error,
                (mu + h, sd),
                (mu - h, sd),
            ),
            (
                "std",
                s.dr_dstd,
                s.dr_dstd_std_error,
                (mu, sd + h),
                (mu, sd - h),
            ),
        ] {
            let plus = inputs.with_moments(j, pm, ps).unwrap();
            let minus = inputs.with_moments(j, mm, ms).unwrap();
            let (fd, fd_se) = crn_difference(&system, &plus, &minus, h, 4_000_000);
            let tol = 3.0 * (se * se + fd_se * fd_se).sqrt();
            assert!(
                (got - fd).abs() <= tol,
                "∂P/∂{what}_{j}: {got} ± {se} vs finite difference {fd} ± {fd_se}"
            );
            // Not trivially zero, and resolved.
            assert!(
                fd.abs() > 4.0 * fd_se && got.abs() > 4.0 * se,
                "{what} {j}: {got} {fd}"
            );
            checked += 1;
        }
    }
    assert_eq!(checked, 6);
}
