//! The gantry guide-rail grinder of seed 000 (Wang & Yuan 2021, Section 3):
//! FORM, importance sampling, Monte Carlo and sensitivities against the
//! paper's Tables 1-4 and Figures 6-8.
//!
//! Table 1's "variance" column is read as standard deviations (tolerance/6;
//! squareness tolerance/3 over 1000 mm), as `examples/machines/gantry_grinder.yaml`
//! records.

use crate::common;

use chain_core::model::{Component, Machine, Sided};
use chain_core::CompiledModel;
use common::example_path;
use common::wang_yuan_2021::{TABLE2, TABLE3, TABLE4};
use reliability::{
    machine, normal, sensitivity, Algorithm, Criterion, Event, Form, ImportanceSampling, Inputs,
    MonteCarlo, Sampler, SensitivityMethod, Study, System, Target, ToleranceLimitState,
};

fn gantry() -> (Machine, CompiledModel) {
    let machine = chain_core::load_file(&example_path("gantry_grinder.yaml"))
        .expect("gantry_grinder.yaml loads");
    let model = chain_core::compile(&machine);
    (machine, model)
}

fn study(system: Option<System>) -> (Machine, CompiledModel, Study) {
    let (machine, model) = gantry();
    let study = machine::study(&machine, &model, &[], system).expect("study");
    (machine, model, study)
}

const X: [f64; 5] = [0.0, 250.0, 500.0, 750.0, 1000.0];
const Y: [f64; 5] = [-1500.0, -750.0, 0.0, 750.0, 1500.0];
const Z: [f64; 5] = [600.0, 800.0, 1000.0, 1200.0, 1400.0];

/// The largest `|model − table|` over a table's cells, asserting each is
/// within `tol` percentage points. `axes` are the row axis, the column axis
/// and the axis the table does not depend on; `value(row, col, free)` is the
/// model's percentage at one grid point; cells where `skip(row, col)` holds
/// are left to the caller.
fn compare(
    table: &[[f64; 5]; 5],
    label: &str,
    axes: [&[f64; 5]; 3],
    tol: f64,
    value: impl Fn(f64, f64, f64) -> f64,
    skip: impl Fn(f64, f64) -> bool,
) -> f64 {
    let mut worst = 0.0f64;
    for (i, &a) in axes[0].iter().enumerate() {
        for (j, &b) in axes[1].iter().enumerate() {
            if skip(a, b) {
                continue;
            }
            for &c in axes[2] {
                let v = value(a, b, c);
                let d = (v - table[i][j]).abs();
                assert!(
                    d <= tol,
                    "{label} = ({a}, {b}): {v:.3} vs the paper's {}",
                    table[i][j]
                );
                worst = worst.max(d);
            }
        }
    }
    worst
}

/// Index of the grid point (x, y, z) in the study (x slowest, as in the file).
fn point(study: &Study, x: f64, y: f64, z: f64) -> usize {
    let [ix, iy, iz] = xyz(study);
    study
        .points()
        .iter()
        .position(|p| p[ix] == x && p[iy] == y && p[iz] == z)
        .expect("grid point")
}

/// Positions of x, y and z in the model's variable order (bodies in tree
/// pre-order: x, z, y for this machine).
fn xyz(study: &Study) -> [usize; 3] {
    ["x", "y", "z"].map(|v| {
        study
            .variables()
            .iter()
            .position(|n| n == v)
            .expect("variable")
    })
}

/// Reliability (%) of component `c` at (x, y, z) from a study result.
fn percent(
    study: &Study,
    r: &reliability::StudyResult,
    c: Component,
    x: f64,
    y: f64,
    z: f64,
) -> f64 {
    let np = study.points().len();
    let t = study
        .targets()
        .iter()
        .position(|t| *t == Target::Component(c))
        .expect("target");
    100.0 * r.cases[t * np + point(study, x, y, z)].reliability
}

#[test]
fn form_reproduces_tables_2_to_4() {
    let (_, _, study) = study(None);
    assert_eq!(study.points().len(), 125);
    let r = study
        .run(&Algorithm::Form(Form::default()), &())
        .expect("form");
    assert_eq!(r.cases.len(), 375);
    let (study, r) = (&study, &r);
    let value = |c: Component| move |x: f64, y: f64, z: f64| percent(study, r, c, x, y, z);
    let (px, py, pz) = (
        value(Component::Px),
        value(Component::Py),
        value(Component::Pz),
    );
    // Table 2: px depends on (y, z) only (Eq. 34); every x gives it. Within
    // 0.25 percentage points.
    let dx = compare(
        &TABLE2,
        "px (z, y)",
        [&Z, &Y, &X],
        0.25,
        |z, y, x| px(x, y, z),
        |_, _| false,
    );
    // Table 3, within 0.45 percentage points.
    let dy = compare(
        &TABLE3,
        "py (x, z)",
        [&X, &Z, &Y],
        0.45,
        |x, z, y| py(x, y, z),
        |_, _| false,
    );
    // Table 4, within 0.25 percentage points, but for (0, ±750): Table 4
    // prints 96.44 there, out of line with its column (97.18, 96.71, 95.89,
    // 94.82 below it, which decrease with x): the model gives 97.45. See
    // docs/errata.md, "Seed 000 reliability tables".
    let misprint = |x: f64, y: f64| x == 0.0 && y.abs() == 750.0;
    let dz = compare(&TABLE4, "pz (x, y)", [&X, &Y, &Z], 0.25, pz, misprint);
    for y in [-750.0, 750.0] {
        for &z in &Z {
            let v = pz(0.0, y, z);
            assert!((v - 97.45).abs() < 0.01, "pz at (0, {y}): {v:.3}");
        }
    }
    eprintln!("max |FORM - paper| (percentage points): px {dx:.3}, py {dy:.3}, pz {dz:.3}");
}

#[test]
fn summaries_match_the_text_of_section_3_3() {
    let (_, _, study) = study(None);
    let r = study
        .run(&Algorithm::Form(Form::default()), &())
        .expect("form");
    // Section 3.3: "minimum ... 86.07 %, average ... 92.16 %" (x), 93.45/96.75
    // (y), 91.21/95.08 (z); each within 0.35 percentage points.
    let paper = [
        ("px", 86.07, 92.16),
        ("py", 93.45, 96.75),
        ("pz", 91.21, 95.08),
    ];
    for (name, min, mean) in paper {
        let s = r
            .summaries
            .iter()
            .find(|s| s.target.name() == name)
            .expect("summary");
        eprintln!(
            "{name}: min {:.3} (paper {min}), mean {:.3} (paper {mean})",
            100.0 * s.min,
            100.0 * s.mean
        );
        assert!((100.0 * s.min - min).abs() <= 0.35, "{name} min {}", s.min);
        assert!(
            (100.0 * s.mean - mean).abs() <= 0.35,
            "{name} mean {}",
            s.mean
        );
        // "The minimum and mean values of reliability in all directions do
        // not meet the design requirements" (95 % / 97 %).
        assert_eq!(s.met, Some(false));
    }
}

/// σ_E² of px, py, pz at (x, y, z) straight from Eq. 34 and Table 1 (with the
/// −y·εzz term of Eq. 17 in px), independently of the derived model.
fn sigma_e(c: usize, x: f64, y: f64, z: f64) -> f64 {
    let lin = |t: f64| t / 6.0;
    let ang = |t: f64| t / 6000.0;
    let sq = |t: f64| t / 3000.0;
    let terms: Vec<f64> = match c {
        // px = -δxx - z εyx + y εzx + δxz + δxy + y Sxy - y εzz
        0 => vec![
            lin(0.05),
            z * ang(0.06),
            y * ang(0.05),
            lin(0.03),
            lin(0.04),
            y * sq(0.03),
            y * ang(0.03),
        ],
        // py = -δyx + z εxx + x εzx + δyz + δyy + x Sxy
        1 => vec![
            lin(0.05),
            z * ang(0.03),
            x * ang(0.05),
            lin(0.03),
            lin(0.05),
            x * sq(0.03),
        ],
        // pz = -δzx - y εxx - x εyx + δzz + y εxz + δzy + y Syz
        _ => vec![
            lin(0.05),
            y * ang(0.03),
            x * ang(0.06),
            lin(0.05),
            y * ang(0.03),
            lin(0.04),
            y * sq(0.02),
        ],
    };
    terms.iter().map(|t| t * t).sum::<f64>().sqrt()
}

#[test]
fn form_equals_the_closed_form_and_is_has_zero_variance() {
    let (_, _, study) = study(None);
    let form = study
        .run(&Algorithm::Form(Form::default()), &())
        .expect("form");
    let is = study
        .run(
            &Algorithm::ImportanceSampling(ImportanceSampling {
                samples: 2_000,
                seed: 2021,
                form: Form::default(),
                cov: None,
            }),
            &(),
        )
        .expect("is");
    let np = study.points().len();
    let [ix, iy, iz] = xyz(&study);
    for (i, (f, s)) in form.cases.iter().zip(&is.cases).enumerate() {
        let p = &f.point;
        // Eq. 21/31 for Z = I − E with zero means: R = Φ(I/σ_E).
        let exact = normal::cdf(0.03 / sigma_e(i / np, p[ix], p[iy], p[iz]));
        assert!(
            (f.reliability - exact).abs() < 1e-9,
            "case {i}: {} vs {exact}",
            f.reliability
        );
        // Eq. 23-28 on a linear limit state in normal inputs: every sample
        // gives h = β, so the estimate is FORM's with zero variance.
        assert!((s.reliability - f.reliability).abs() < 1e-9, "case {i}");
        assert!(s.std_error.expect("std error") < 1e-12, "case {i}");
        assert_eq!(s.samples, Some(2_000));
    }
}

#[test]
fn monte_carlo_agrees_within_four_standard_errors() {
    let (_, _, study) = study(None);
    let form = study
        .run(&Algorithm::Form(Form::default()), &())
        .expect("form");
    let mc = study
        .run(
            &Algorithm::MonteCarlo(MonteCarlo {
                samples: 40_000,
                seed: 7,
                cov: None,
            }),
            &(),
        )
        .expect("mc");
    let mut worst = 0.0f64;
    for (f, m) in form.cases.iter().zip(&mc.cases) {
        let se = m.std_error.expect("std error");
        assert!(se > 0.0);
        let z = (m.pf - f.pf).abs() / se;
        worst = worst.max(z);
        // Tables 2-4 by crude Monte Carlo: within 4 standard errors of FORM
        // (exact here).
        assert!(
            z < 4.0,
            "{} at {:?}: mc {} form {} se {se}",
            f.target,
            f.point,
            m.pf,
            f.pf
        );
    }
    eprintln!("Monte Carlo vs FORM over 375 cases: worst {worst:.2} standard errors");
}

#[test]
fn nonlinear_limit_states_importance_sampling_vs_ten_million_monte_carlo() {
    let (_, _, study) = study(Some(System::Volumetric { tolerance: 0.05 }));
    // The worst corner of the workspace.
    let p = point(&study, 1000.0, 1500.0, 1400.0);
    let n = study.inputs().len();
    let volumetric = study.event(Target::Volumetric, p).expect("event");
    let two_sided = Event::new(
        study.inputs(),
        ToleranceLimitState::component(
            study.row(p, Component::Px).unwrap().to_vec(),
            0.03,
            Sided::Two,
        )
        .expect("ls"),
    )
    .expect("event");
    let mut rows = Vec::new();
    for c in [Component::Px, Component::Py, Component::Pz] {
        rows.extend_from_slice(&study.row(p, c).unwrap());
    }
    let series = Event::new(
        study.inputs(),
        ToleranceLimitState::new(n, rows, vec![0.03; 3], Criterion::Each(Sided::Two)).expect("ls"),
    )
    .expect("event");
    let events = [volumetric, two_sided, series];
    let mc = MonteCarlo {
        samples: 10_000_000,
        seed: 1,
        cov: None,
    }
    .run_cases(&events, &())
    .expect("mc");
    let is = ImportanceSampling {
        samples: 200_000,
        seed: 1,
        form: Form::default(),
        cov: None,
    }
    .run_cases(&events, &())
    .expect("is");
    for ((name, m), s) in ["volumetric", "two-sided px", "series two-sided"]
        .iter()
        .zip(&mc)
        .zip(&is)
    {
        let form = s.form.as_ref().expect("form");
        let se = (m.std_error.powi(2) + s.std_error.powi(2)).sqrt();
        eprintln!(
            "{name}: FORM {:.6}  IS {:.6} ± {:.2e}  MC {:.6} ± {:.2e}",
            form.pf, s.pf, s.std_error, m.pf, m.std_error
        );
        assert_eq!(m.samples, 10_000_000);
        // The importance sampling inside 3 standard errors of 10⁷ Monte Carlo.
        assert!(
            (s.pf - m.pf).abs() < 3.0 * se,
            "{name}: IS {} MC {} se {se}",
            s.pf,
            m.pf
        );
        // FORM is not exact here: it misses the far side / the other components.
        assert!(!form.exact);
        assert!(
            (form.pf - m.pf).abs() > 10.0 * m.std_error,
            "{name}: FORM {} MC {}",
            form.pf,
            m.pf
        );
    }
    // Two-sided px is still linear: IS along α is exact, 2·Φ(−β) at zero mean.
    let exact = events[1].exact_pf().expect("closed form");
    assert!((is[1].pf - exact).abs() < 1e-12 && is[1].std_error < 1e-12);
}

#[test]
fn non_normal_inputs_use_the_root_finder() {
    // Table 1 with every angular error uniform (same σ): FORM runs HL-RF and
    // the importance sampling solves g = 0 along α numerically.
    let (_, _, study) = study(None);
    let p = point(&study, 1000.0, 1500.0, 1400.0);
    let base = study.inputs();
    let marginals = base
        .marginals()
        .iter()
        .zip(base.names())
        .map(|(m, name)| {
            if name.starts_with('e') || name.starts_with('S') {
                let h = 3f64.sqrt() * m.std();
                reliability::Marginal::uniform(m.mean() - h, m.mean() + h)
            } else {
                Ok(*m)
            }
        })
        .collect::<Result<Vec<_>, _>>()
        .expect("marginals");
    let inputs = Inputs::new(base.names().to_vec(), marginals).expect("inputs");
    let event = Event::new(
        &inputs,
        ToleranceLimitState::component(
            study.row(p, Component::Px).unwrap().to_vec(),
            0.03,
            Sided::Upper,
        )
        .expect("ls"),
    )
    .expect("event");
    let form = Form::default().run(&event).expect("form");
    assert_eq!(form.termination, reliability::Termination::Converged);
    let is = ImportanceSampling {
        samples: 20_000,
        seed: 5,
        form: Form::default(),
        cov: None,
    }
    .run(&event)
    .expect("is");
    let mc = MonteCarlo {
        samples: 2_000_000,
        seed: 5,
        cov: None,
    }
    .run(&event)
    .expect("mc");
    let se = (is.std_error.powi(2) + mc.std_error.powi(2)).sqrt();
    eprintln!(
        "uniform angular errors, px at the corner: FORM {:.5} IS {:.5} ± {:.1e} MC {:.5} ± {:.1e}",
        form.pf, is.pf, is.std_error, mc.pf, mc.std_error
    );
    assert!(
        (is.pf - mc.pf).abs() < 4.0 * se,
        "IS {} MC {} se {se}",
        is.pf,
        mc.pf
    );
}

#[test]
fn sensitive_sets_of_figures_6_to_8() {
    let (_, _, study) = study(None);
    let sens = study
        .sensitivity_mean(&Form::default())
        .expect("sensitivity");
    // Figures 6-8 (Section 3.3): the errors whose variance the reliability is
    // sensitive to.
    let paper: [(&str, &[&str]); 3] = [
        ("px", &["eyx", "ezx", "ezz", "Sxy"]),
        ("py", &["exx", "ezx", "Sxy"]),
        ("pz", &["exx", "eyx", "exz", "Syz"]),
    ];
    for (name, expected) in paper {
        let t = sens
            .iter()
            .find(|t| t.target.name() == name)
            .expect("target");
        assert_eq!(t.method, SensitivityMethod::Exact);
        let top = t.errors[0].mean_abs_dr_dstd;
        let mut set: Vec<&str> = t
            .errors
            .iter()
            .filter(|e| e.mean_abs_dr_dstd >= 0.01 * top)
            .map(|e| e.error.as_str())
            .collect();
        set.sort_unstable();
        let mut want = expected.to_vec();
        want.sort_unstable();
        assert_eq!(set, want, "{name}");
        // Sorted by |∂R/∂σ|, largest first; a larger σ lowers R.
        for w in t.errors.windows(2) {
            assert!(w[0].dr_dstd.abs() >= w[1].dr_dstd.abs());
        }
        assert!(t.errors[0].dr_dstd < 0.0);
        let imp: f64 = t.errors.iter().map(|e| e.importance).sum();
        assert!((imp - 1.0).abs() < 1e-9);
    }
}

#[test]
fn analytic_sensitivities_equal_central_differences() {
    let (_, _, study) = study(None);
    let form = Form::default();
    let reliability_of = |inputs: &Inputs, row: &[f64], sided: Sided| -> f64 {
        let e = Event::new(
            inputs,
            ToleranceLimitState::component(row.to_vec(), 0.03, sided).unwrap(),
        )
        .unwrap();
        1.0 - e.exact_pf().unwrap()
    };
    let mut checked = 0;
    for (c, (x, y, z)) in [
        (Component::Px, (0.0, 1500.0, 1400.0)),
        (Component::Py, (1000.0, 0.0, 600.0)),
        (Component::Pz, (500.0, -750.0, 1000.0)),
    ] {
        let p = point(&study, x, y, z);
        let row = study.row(p, c).unwrap().to_vec();
        // A non-zero mean on two inputs makes ∂R/∂μ non-trivial.
        let base = study
            .inputs()
            .with_moments(0, 0.002, study.inputs().stds()[0])
            .and_then(|i| i.with_moments(4, 2e-6, i.stds()[4]))
            .expect("inputs");
        for sided in [Sided::Upper, Sided::Two] {
            let e = Event::new(
                &base,
                ToleranceLimitState::component(row.clone(), 0.03, sided).unwrap(),
            )
            .unwrap();
            let s = sensitivity(&e, &form.run(&e).unwrap()).unwrap();
            assert_eq!(s.method, SensitivityMethod::Exact);
            let scale = s
                .inputs
                .iter()
                .map(|v| v.dr_dstd.abs().max(v.dr_dmean.abs()))
                .fold(0.0, f64::max);
            for j in 0..base.len() {
                let (mu, sd) = (base.means()[j], base.stds()[j]);
                let h = 1e-4 * sd;
                let fd_std =
                    (reliability_of(&base.with_moments(j, mu, sd + h).unwrap(), &row, sided)
                        - reliability_of(&base.with_moments(j, mu, sd - h).unwrap(), &row, sided))
                        / (2.0 * h);
                let fd_mean =
                    (reliability_of(&base.with_moments(j, mu + h, sd).unwrap(), &row, sided)
                        - reliability_of(&base.with_moments(j, mu - h, sd).unwrap(), &row, sided))
                        / (2.0 * h);
                // Eq. 32-33 against central differences of R: 1e-6 relative
                // (absolute 1e-9 of the largest derivative for those that vanish).
                for (a, fd) in [
                    (s.inputs[j].dr_dstd, fd_std),
                    (s.inputs[j].dr_dmean, fd_mean),
                ] {
                    assert!(
                        (a - fd).abs() <= 1e-6 * fd.abs() + 1e-9 * scale,
                        "{c:?} {sided:?} input {j}: analytic {a} vs fd {fd}"
                    );
                    checked += 1;
                }
            }
        }
    }
    assert_eq!(checked, 3 * 2 * 21 * 2);
}

#[test]
fn results_are_reproducible_whatever_the_thread_count() {
    let (_, _, study) = study(Some(System::Series));
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool")
            .install(|| {
                let mc = study
                    .run(
                        &Algorithm::MonteCarlo(MonteCarlo {
                            samples: 3_000,
                            seed: 3,
                            cov: None,
                        }),
                        &(),
                    )
                    .expect("mc");
                let is = study
                    .run(
                        &Algorithm::ImportanceSampling(ImportanceSampling {
                            samples: 3_000,
                            seed: 3,
                            form: Form::default(),
                            cov: None,
                        }),
                        &(),
                    )
                    .expect("is");
                (mc, is)
            })
    };
    assert_eq!(run(1), run(2));
}
