//! The target coefficient of variation as a stopping rule (`--cov`) for
//! every sampler: Monte Carlo, importance sampling, directional and subset
//! simulation.
//!
//! What is checked: the reported CoV is at most the target; the sample
//! count is what the rule implies — `N* = Var₁/(p_f²·c²)` with the
//! per-sample variance `Var₁` (for Monte Carlo `p(1 − p)`, exact `p`;
//! otherwise from a long fixed-size run) — within one block; one block
//! fewer would not have met the target; the stopped estimate equals a fixed
//! run of the same seed and size; a budget too small stops with
//! `converged: false`.

use chain_core::model::Sided;
use reliability::normal;
use reliability::simulation::BLOCK;
use reliability::{
    DirectionalSimulation, Event, Form, ImportanceSampling, Inputs, Marginal, MonteCarlo,
    ReliabilityError, Sampler, Stop, SubsetSimulation, ToleranceLimitState,
};

fn normals(n: usize) -> Inputs {
    let names = (0..n).map(|i| format!("e{i}")).collect();
    Inputs::new(
        names,
        (0..n)
            .map(|_| Marginal::normal(0.0, 1.0).unwrap())
            .collect(),
    )
    .unwrap()
}

#[test]
fn monte_carlo_stops_at_the_target() {
    let inp = normals(3);
    let beta = 2.326;
    let g = ToleranceLimitState::component(vec![0.0, 0.6, 0.8], beta, Sided::Upper).unwrap();
    let event = Event::new(&inp, g).unwrap();
    let p = normal::sf(beta);
    let target = 0.02;
    let mc = MonteCarlo {
        samples: 100 * BLOCK,
        seed: 3,
        cov: None,
    };
    let r = MonteCarlo {
        cov: Some(target),
        ..mc
    }
    .run_cases(std::slice::from_ref(&event), &())
    .unwrap()
    .remove(0);
    let st = r.stopping.unwrap();
    assert!(st.converged && st.stopped_by == Stop::TargetCov && st.target_cov == Some(target));
    assert!(r.cov <= target, "{}", r.cov);
    let implied = (1.0 - p) / (p * target * target);
    assert!(
        (r.samples as f64 - implied).abs() <= BLOCK as f64,
        "{} vs {implied}",
        r.samples
    );
    assert_eq!(r.samples % BLOCK, 0);
    // The same as a fixed run of that size; one block fewer misses the target.
    let fixed = MonteCarlo {
        samples: r.samples,
        seed: 3,
        cov: None,
    }
    .run(&event)
    .unwrap();
    assert_eq!((fixed.pf, fixed.std_error), (r.pf, r.std_error));
    assert!(fixed.stopping.is_none());
    let fewer = MonteCarlo {
        samples: r.samples - BLOCK,
        seed: 3,
        cov: None,
    }
    .run(&event)
    .unwrap();
    assert!(fewer.cov > target, "{}", fewer.cov);
    // A budget of one block: not converged.
    let small = MonteCarlo {
        samples: BLOCK,
        seed: 3,
        cov: None,
    };
    let r = MonteCarlo {
        cov: Some(target),
        ..small
    }
    .run_cases(std::slice::from_ref(&event), &())
    .unwrap()
    .remove(0);
    let st = r.stopping.unwrap();
    assert!(!st.converged && st.stopped_by == Stop::Budget);
    assert!(r.cov > target);
}

#[test]
fn importance_sampling_stops_at_the_target() {
    // Uniform and normal inputs, two-sided: IS has a non-zero variance.
    let inp = Inputs::new(
        vec!["a".into(), "b".into()],
        vec![
            Marginal::uniform(-1.0, 1.0).unwrap(),
            Marginal::normal(0.0, 0.5).unwrap(),
        ],
    )
    .unwrap();
    let g = ToleranceLimitState::component(vec![1.0, 1.0], 1.9, Sided::Two).unwrap();
    let event = Event::new(&inp, g).unwrap();
    let is = ImportanceSampling {
        samples: 8 * BLOCK,
        seed: 1,
        form: Form::default(),
        cov: None,
    };
    let long = is.run(&event).unwrap();
    let var1 = long.std_error.powi(2) * long.samples as f64;
    let target = (var1 / (2.5 * BLOCK as f64)).sqrt() / long.pf;
    let form = Form::default().run(&event).unwrap();
    let r = ImportanceSampling {
        cov: Some(target),
        ..is
    }
    .run_cases_with(std::slice::from_ref(&event), vec![form], &())
    .unwrap()
    .remove(0);
    assert_eq!(r.stopping.unwrap().stopped_by, Stop::TargetCov);
    assert!(r.cov <= target);
    let implied = var1 / (long.pf * target).powi(2);
    assert!(
        (r.samples as f64 - implied).abs() <= BLOCK as f64,
        "{} vs {implied}",
        r.samples
    );
    let fewer = ImportanceSampling {
        samples: r.samples - BLOCK,
        ..is
    }
    .run(&event)
    .unwrap();
    assert!(fewer.cov > target);
}

#[test]
fn importance_sampling_on_a_linear_normal_case_stops_after_one_block() {
    let inp = normals(2);
    let g = ToleranceLimitState::component(vec![1.0, 1.0], 6.0, Sided::Upper).unwrap();
    let event = Event::new(&inp, g).unwrap();
    let is = ImportanceSampling {
        samples: 10 * BLOCK,
        seed: 1,
        form: Form::default(),
        cov: None,
    };
    let form = Form::default().run(&event).unwrap();
    let r = ImportanceSampling {
        cov: Some(0.01),
        ..is
    }
    .run_cases_with(std::slice::from_ref(&event), vec![form], &())
    .unwrap()
    .remove(0);
    assert_eq!(r.samples, BLOCK);
    assert!(r.stopping.unwrap().converged);
    assert!((r.pf - normal::sf(6.0 / 2f64.sqrt())).abs() < 1e-12 * r.pf);
}

#[test]
fn directional_simulation_stops_at_the_target() {
    use reliability::directional::BLOCK as DBLOCK;
    let inp = normals(4);
    let g = ToleranceLimitState::component(vec![1.0, -0.5, 0.3, 0.2], 3.2, Sided::Two).unwrap();
    let event = Event::new(&inp, g).unwrap();
    let long = DirectionalSimulation {
        samples: 50 * DBLOCK,
        seed: 2,
        cov: None,
    }
    .run(&event)
    .unwrap();
    let var1 = long.std_error.powi(2) * long.samples as f64;
    let target = (var1 / (6.5 * DBLOCK as f64)).sqrt() / long.pf;
    let d = DirectionalSimulation {
        samples: 100 * DBLOCK,
        seed: 2,
        cov: Some(target),
    };
    let r = d.run(&event).unwrap();
    assert_eq!(r.stopping.unwrap().stopped_by, Stop::TargetCov);
    assert!(r.cov <= target);
    let implied = var1 / (long.pf * target).powi(2);
    assert!(
        (r.samples as f64 - implied).abs() <= 1.5 * DBLOCK as f64,
        "{} vs {implied}",
        r.samples
    );
    let fewer = DirectionalSimulation {
        samples: r.samples - DBLOCK,
        seed: 2,
        cov: None,
    }
    .run(&event)
    .unwrap();
    assert!(fewer.cov > target);
    let exact = event.exact_pf().unwrap();
    assert!((r.pf - exact).abs() < 3.0 * r.std_error);
    // Budget too small.
    let d = DirectionalSimulation {
        samples: DBLOCK,
        seed: 2,
        cov: Some(target),
    };
    let st = d.run(&event).unwrap().stopping.unwrap();
    assert!(!st.converged && st.stopped_by == Stop::Budget);
}

#[test]
fn subset_simulation_repeats_runs_to_the_target() {
    // p_f = Φ(−3.43) ≈ 3.0e-4: four levels per run (0.1³ · 0.3).
    let inp = normals(3);
    let beta = 3.43;
    let g = ToleranceLimitState::component(vec![0.0, 0.6, 0.8], beta, Sided::Upper).unwrap();
    let event = Event::new(&inp, g).unwrap();
    let mut s = SubsetSimulation::new(500, 4);
    s.cov = Some(0.05);
    s.budget = 10_000_000;
    let r = s.run(&event).unwrap();
    assert!(r.stopping.converged && r.stopping.stopped_by == Stop::TargetCov);
    assert!(
        r.cov <= 0.05 && r.runs > 1,
        "{} after {} runs",
        r.cov,
        r.runs
    );
    assert!(r.samples.is_multiple_of(500));
    assert!((r.pf - normal::sf(beta)).abs() < 3.0 * r.std_error);
    // A budget one run short: not converged (the runs are the same).
    s.budget = r.samples - 1;
    let short = s.run(&event).unwrap();
    assert!(!short.stopping.converged && short.stopping.stopped_by == Stop::Budget);
    assert!(short.runs < r.runs && short.cov > 0.05);
}

#[test]
fn a_target_outside_zero_one_is_refused() {
    let inp = normals(1);
    let g = ToleranceLimitState::component(vec![1.0], 2.0, Sided::Upper).unwrap();
    let event = Event::new(&inp, g).unwrap();
    for bad in [0.0, -0.1, 1.5, f64::NAN, f64::INFINITY] {
        let mc = MonteCarlo {
            samples: BLOCK,
            seed: 1,
            cov: None,
        };
        let e = MonteCarlo {
            cov: Some(bad),
            ..mc
        }
        .run_cases(std::slice::from_ref(&event), &())
        .unwrap_err();
        assert!(matches!(e, ReliabilityError::InvalidTargetCov(_)), "{e:?}");
        let d = DirectionalSimulation {
            samples: 10,
            seed: 1,
            cov: Some(bad),
        };
        assert!(matches!(
            d.run(&event),
            Err(ReliabilityError::InvalidTargetCov(_))
        ));
    }
}
