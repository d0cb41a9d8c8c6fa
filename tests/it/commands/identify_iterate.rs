//! The exact kinematics of `chain identify` against the
//! independent numeric 4×4 product of `tests/it/common`: the deviation with
//! finite errors and its derivatives (central differences of that
//! product); the first-order check; `--iterate` on errors large enough that
//! first order is visibly wrong, and on small ones.

#![allow(clippy::needless_range_loop)]

use crate::common;

use chain::core::measured::exact::ExactChain;
use chain::core::Machine;
use common::{example_file, gauss, load_example, Exact, Rng};

/// Random poses and errors of `size` (mm, and 1e-3 × size rad).
fn random_case(m: &Machine, rng: &mut Rng, size: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let q: Vec<f64> = m
        .variables
        .iter()
        .map(|_| rng.range(-1.5, 1.5) * 200.0)
        .collect();
    let p = Exact::new(m).file_parameters();
    let e: Vec<f64> = m
        .errors
        .iter()
        .map(|x| {
            let s = if x.kind == chain::core::model::ErrorKind::Linear {
                size
            } else {
                1e-3 * size
            };
            rng.range(-s, s)
        })
        .collect();
    (q, p, e)
}

/// The deviation with finite errors equals the independent product's, and
/// each derivative equals its central difference, on machines with
/// prismatic and rotary joints, location errors, squareness, function
/// slots and both frames.
#[test]
fn the_exact_deviation_and_its_derivatives_are_the_products() {
    let machines: Vec<Machine> = vec![
        load_example("head_head_bc.yaml"),
        load_example("gantry_grinder.yaml"),
        load_example("vmc3.yaml"),
        load_example("legendre5.yaml"),
        chain::core::load_file(&example_file("robots/arm6_offsets.yaml")).unwrap(),
    ];
    let mut rng = Rng::new(31);
    for m in &machines {
        let exact = Exact::new(m);
        let chain = ExactChain::new(m);
        for _ in 0..5 {
            // Rotary variables near ±1.5 rad, slides ±300 mm.
            let (mut q, p, e) = random_case(m, &mut rng, 0.5);
            for (k, v) in m.variables.iter().enumerate() {
                if v.kind == chain::core::model::JointKind::Rotary {
                    q[k] /= 200.0;
                }
            }
            let want = exact.exact_error(&q, &p, &e);
            let (got, jac) = chain.deviation_and_jacobian(&q, &p, &e);
            let plain = chain.deviation(&q, &p, &e);
            for c in 0..3 {
                assert!(
                    (got[c] - want[c]).abs() < 1e-10,
                    "{}: {got:?} vs {want:?}",
                    m.name
                );
                assert_eq!(got[c], plain[c]);
            }
            for j in 0..m.errors.len() {
                // Steps where the central difference's truncation (h²/6 times a
                // third derivative of at most a 1e3 mm lever) and its round-off
                // (1e-13 mm of coordinates near 1e3 mm, over 2h) are both
                // below 1e-7.
                let h = if m.errors[j].kind == chain::core::model::ErrorKind::Linear {
                    1e-3
                } else {
                    1e-5
                };
                let mut up = e.clone();
                up[j] += h;
                let mut down = e.clone();
                down[j] -= h;
                let (a, b) = (
                    exact.exact_error(&q, &p, &up),
                    exact.exact_error(&q, &p, &down),
                );
                for c in 0..3 {
                    let fd = (a[c] - b[c]) / (2.0 * h);
                    let scale = jac.column(j).amax().max(1.0);
                    assert!(
                        (jac[(c, j)] - fd).abs() < 1e-6 * scale,
                        "{} {} row {c}: {} vs {fd}",
                        m.name,
                        m.errors[j].name,
                        jac[(c, j)]
                    );
                }
            }
        }
    }
}

use chain::core::measured::{IdentifyOptions, Measurement, Measurements, Observed, SubsetChoice};
use chain::ops::identify::identify_document;

/// The example arm.
fn arm() -> Machine {
    chain::core::load_file(&example_file("robots/arm6_offsets.yaml")).unwrap()
}

/// The 27 errors the elimination keeps on the arm (position-only data):
/// with the others at 0 the truth is one the model represents exactly,
/// to all orders.
const KEPT: [&str; 27] = [
    "DX1", "DY1", "DZ1", "EX1", "EY1", "EZ1", "DX2", "DY2", "EX2", "DX3", "DZ3", "EX3", "EZ3",
    "DX4", "DZ4", "EX4", "EY4", "EZ4", "DY5", "DZ5", "EZ5", "DX6", "DZ6", "EX6", "EY6", "EZ6",
    "TZ",
];

/// `count` arm poses through the exact product with noise σ, as the
/// measurements of a file.
fn measured(m: &Machine, e: &[f64], count: usize, sigma: f64, rng: &mut Rng) -> Measurements {
    let exact = Exact::new(m);
    let p = exact.file_parameters();
    let rows = (0..count)
        .map(|i| {
            let q: Vec<f64> = [3.0, 1.5, 1.5, 3.0, 2.0, 3.0]
                .iter()
                .map(|r| rng.range(-r, *r))
                .collect();
            let err = exact.exact_error(&q, &p, e);
            Measurement {
                line: i + 2,
                q,
                p: p.clone(),
                observed: Observed::Point,
                values: (0..3).map(|c| err[c] + sigma * gauss(rng)).collect(),
                std: None,
                setup: None,
                temperatures: Vec::new(),
            }
        })
        .collect();
    Measurements {
        file: "arm.csv".into(),
        machine: m.name.clone(),
        weighted: false,
        rows,
        setups: Vec::new(),
    }
}

/// `count` records of the arm with its kept errors at `size` (σ = 1e-3
/// mm, from `seed`), and their CSV written to a scratch directory `name`.
fn arm_file(
    m: &Machine,
    size: f64,
    count: usize,
    seed: u64,
    name: &str,
) -> (Vec<f64>, Measurements, std::path::PathBuf) {
    let mut rng = Rng::new(seed);
    let e = truth(m, size, &mut rng);
    let data = measured(m, &e, count, 1e-3, &mut rng);
    let csv = common::point_csv("q1,q2,q3,q4,q5,q6,dpx,dpy,dpz", &data.rows);
    let file = common::cli::write(&common::cli::scratch(name), "arm.csv", &csv);
    (e, data, file)
}

/// The arm's kept errors at `size` × (1 mm, 5e-3 rad), the others 0.
fn truth(m: &Machine, size: f64, rng: &mut Rng) -> Vec<f64> {
    m.errors
        .iter()
        .map(|x| {
            if !KEPT.contains(&x.name.as_str()) {
                0.0
            } else if x.kind == chain::core::model::ErrorKind::Linear {
                size * gauss(rng)
            } else {
                5e-3 * size * gauss(rng)
            }
        })
        .collect()
}

#[test]
fn iterate_reaches_the_truth_where_first_order_does_not() {
    let m = arm();
    let mut rng = Rng::new(41);
    let mut e = truth(&m, 1.0, &mut rng);
    let ez1 = m.error_index("EZ1").unwrap();
    e[ez1] = 0.015; // a joint offset beyond the first-order range
    let data = measured(&m, &e, 300, 1e-3, &mut rng);
    let options = IdentifyOptions {
        rank_tol: None,
        subset: SubsetChoice::Estimate(KEPT.iter().map(|s| s.to_string()).collect()),
    };
    let done = identify_document(&m, &data, false, &options, true, None).unwrap();
    let it = done.iteration.as_ref().unwrap();
    let sub = done.result.subset.as_ref().unwrap();
    // The exact model is visibly not first order here: its difference
    // from the linear fit exceeds the noise, and the large angles are named.
    assert!(done.check.exceeds_noise, "{:?}", done.check);
    let flagged: Vec<&str> = done
        .check
        .large_angles
        .iter()
        .map(|(n, _)| n.as_str())
        .collect();
    assert!(flagged.contains(&"EZ1"), "{flagged:?}");
    assert!(
        it.converged && it.iterations < 20,
        "{} iterations",
        it.iterations
    );
    // The exact fit's residual is the noise: RSS/(m − k) = σ² within 10 %.
    let s2 = it.rss / (900 - 27) as f64;
    assert!((s2 / 1e-6 - 1.0).abs() < 0.1, "s² {s2}");
    let mut worst_lin = 0.0f64;
    let mut worst_it = 0.0f64;
    for &j in &sub.estimated {
        let std = it.estimates[j].std.unwrap();
        worst_it = worst_it.max((it.estimates[j].value - e[j]).abs() / std);
        worst_lin = worst_lin.max((sub.estimates[j].value - e[j]).abs() / std);
    }
    // Every iterated value within 4 std of the truth; the linear estimate
    // is off by far more.
    assert!(worst_it < 4.0, "iterated: {worst_it} std from the truth");
    assert!(worst_lin > 50.0, "linear: {worst_lin} std from the truth");
    // The document and the values file say so.
    let doc = &done.document;
    assert!(
        doc.first_order.words.contains("EZ1 (0.01498 rad)"),
        "{}",
        doc.first_order.words
    );
    let values = chain::ops::identify::values_file(&m, "arm.csv", &done);
    assert!(
        values.contains("# --iterate: Levenberg-Marquardt"),
        "{values}"
    );
    assert!(values.contains("# EZ1 reaches 1.49"), "{values}");
}

/// On small errors (1e-4 mm, 5e-7 rad, noise 1e-5 mm: second order about
/// 1e-9 mm) the first-order fit is adequate and `--iterate` moves no
/// estimate by more than 1e-9 (mm or rad). (At 0.02 mm and 1e-4 rad with
/// noise 1e-3 mm the move is already 0.19 of a std: second order is not
/// negligible against good data long before it is visible in a residual.)
#[test]
fn iterate_changes_nothing_on_small_errors() {
    let m = arm();
    let mut rng = Rng::new(43);
    let e = truth(&m, 1e-4, &mut rng);
    let data = measured(&m, &e, 300, 1e-5, &mut rng);
    let options = IdentifyOptions {
        rank_tol: None,
        subset: SubsetChoice::Estimate(KEPT.iter().map(|s| s.to_string()).collect()),
    };
    let done = identify_document(&m, &data, false, &options, true, None).unwrap();
    let it = done.iteration.as_ref().unwrap();
    let sub = done.result.subset.as_ref().unwrap();
    assert!(!done.check.exceeds_noise, "{:?}", done.check);
    assert!(done.document.first_order.words.contains("within the noise"));
    assert!(it.converged);
    for &j in &sub.estimated {
        assert!(
            it.change[j].abs() <= 1e-9,
            "{}: moved by {}",
            m.errors[j].name,
            it.change[j]
        );
    }
}

/// `--iterate` through the CLI gives the library's exact fit; with
/// `--prior` it is refused naming both options.
#[test]
fn the_cli_iterates_as_the_library_does() {
    use common::cli::{fails, ok_json, unwrapped};
    let m = arm();
    let (_, data, file) = arm_file(&m, 1.0, 150, 47, "identify-iterate");
    let machine = example_file("robots/arm6_offsets.yaml");
    let kept = KEPT.join(",");
    let args = [
        "identify",
        machine.to_str().unwrap(),
        "--measurements",
        file.to_str().unwrap(),
        "--estimate",
        &kept,
        "--iterate",
    ];
    let json = ok_json(&[&args[..], &["--format", "json"]].concat());
    let options = IdentifyOptions {
        rank_tol: None,
        subset: SubsetChoice::Estimate(KEPT.iter().map(|s| s.to_string()).collect()),
    };
    let lib = identify_document(&m, &data, false, &options, true, None).unwrap();
    let it = lib.iteration.as_ref().unwrap();
    assert_eq!(
        json["iteration"]["iterations"].as_u64(),
        Some(it.iterations as u64)
    );
    for (j, x) in m.errors.iter().enumerate() {
        let got = json["iteration"]["estimates"][&x.name]["value"]
            .as_f64()
            .unwrap();
        let want = it.estimates[j].value;
        assert!(
            (got - want).abs() <= 1e-9 * want.abs().max(1e-9),
            "{}",
            x.name
        );
    }
    assert_eq!(json["first_order"]["exceeds_noise"], true);
    // Without --estimate (which --prior refuses by itself).
    let err = unwrapped(&fails(&[&args[..4], &["--iterate", "--prior"]].concat()));
    assert!(
        err.contains(
            "--iterate fits the exact kinematics by least squares; it does not take --prior"
        ),
        "{err}"
    );
}

/// `--holdout 0.2 --seed 3` on the simulated arm: the held-out records are
/// the JSON's `validation.lines` (a fifth of them, none fitted), and the
/// prediction numbers there equal an independent computation, the tests'
/// 4×4 product with the written values: through the exact kinematics
/// (`--iterate`) to 1e-9 mm, and the first-order prediction to the second
/// order of the errors (2e-5 mm at 0.02 mm and 2e-5 rad). A seed alone, a
/// fraction outside (0, 1) and `--holdout` with `--validate` are refused.
#[test]
fn held_out_records_are_predicted_as_the_product_predicts_them() {
    use common::cli::{fails, ok_json, unwrapped};
    let m = arm();
    let (_, data, file) = arm_file(&m, 0.02, 200, 53, "identify-holdout");
    let machine = example_file("robots/arm6_offsets.yaml");
    let base = [
        "identify",
        machine.to_str().unwrap(),
        "--measurements",
        file.to_str().unwrap(),
        "--holdout",
        "0.2",
        "--seed",
        "3",
        "--format",
        "json",
    ];
    let exact = Exact::new(&m);
    for (iterate, tolerance) in [(true, 1e-9), (false, 2e-5)] {
        let args: Vec<&str> = if iterate {
            [&base[..], &["--iterate"]].concat()
        } else {
            base.to_vec()
        };
        let json = ok_json(&args);
        let v = &json["validation"];
        let lines: Vec<usize> = (v["lines"].as_array().unwrap().iter())
            .map(|l| l.as_u64().unwrap() as usize)
            .collect();
        assert_eq!(lines.len(), 40);
        assert_eq!(json["measurements"].as_u64(), Some(160));
        assert_eq!(v["holdout"]["seed"].as_u64(), Some(3));
        let values = if iterate {
            &json["iteration"]["estimates"]
        } else {
            &json["subset"]["estimates"]
        };
        let x: Vec<f64> = (m.errors.iter())
            .map(|er| values[&er.name]["value"].as_f64().unwrap())
            .collect();
        let held: Vec<&Measurement> = (data.rows.iter())
            .filter(|r| lines.contains(&r.line))
            .collect();
        let (before, after) = common::held_out_stats(&exact, &held, &x);
        for (key, expected, tol) in [("before", before, 1e-12), ("after", after, tolerance)] {
            for (k, field) in ["mean", "max", "rms"].iter().enumerate() {
                let got = v[key][field].as_f64().unwrap();
                assert!(
                    (got - expected[k]).abs() <= tol,
                    "iterate {iterate}: {key}.{field} {got} vs the product's {}",
                    expected[k]
                );
            }
        }
        // The correction takes the held-out error to the noise.
        assert!(v["after"]["rms"].as_f64().unwrap() < 1.3e-3);
    }
    let with = |extra: &[&str]| -> String {
        let mut a: Vec<&str> = base[..4].to_vec();
        a.extend_from_slice(extra);
        unwrapped(&fails(&a))
    };
    assert!(with(&["--seed", "3"])
        .contains("--holdout: --seed chooses the records --holdout holds out"));
    assert!(with(&["--holdout", "1.5"]).contains("--holdout: 1.5 is not a fraction in (0, 1)"));
    assert!(with(&["--holdout", "0.001"]).contains("both sides need a record"));
    assert!(
        with(&["--holdout", "0.2", "--validate", file.to_str().unwrap()])
            .contains("--holdout: cannot be given with --validate")
    );
}

/// The option checks that need no file run before any file is read: with
/// a measurement file that does not exist, each bad option is still the
/// refusal (not the missing file).
#[test]
fn bad_options_are_refused_before_the_files_are_read() {
    use common::cli::{fails, unwrapped};
    let machine = example_file("robots/arm6_offsets.yaml");
    let base = [
        "identify",
        machine.to_str().unwrap(),
        "--measurements",
        "/nonexistent/arm.csv",
    ];
    for (extra, wanted) in [
        (
            &["--rank-tol", "2"][..],
            "--rank-tol: 2 is not a relative tolerance",
        ),
        (
            &["--fix", "DY2", "--prior"][..],
            "--fix chooses the parameters of a least-squares fit",
        ),
        (
            &["--iterate", "--prior"][..],
            "--iterate fits the exact kinematics",
        ),
        (
            &["--holdout", "0"][..],
            "--holdout: 0 is not a fraction in (0, 1)",
        ),
        (
            &["--holdout", "0.2", "--validate", "/nonexistent/v.csv"][..],
            "--holdout: cannot be given with --validate",
        ),
    ] {
        let args: Vec<&str> = base.iter().chain(extra).copied().collect();
        let err = unwrapped(&fails(&args));
        assert!(err.contains(wanted), "{extra:?}: {err}");
        assert!(!err.contains("nonexistent"), "{extra:?}: {err}");
    }
}

/// The large-angle flag is per error motion: a function slot's whole value
/// `Σ_k w_k(q) x_k`, named by the function, not each coefficient. An X
/// slide's roll `EAX = c0 + c1·x` with `c0 = 0.006` rad and `c1·800 mm =
/// 0.006` rad reaches 0.012 rad at x = 800 (beyond the 0.01 rad limit)
/// though neither coefficient's term does; a yaw whose terms cancel
/// (0.008 − 0.008·x/800, at most 0.008 rad) is not flagged though its
/// constant alone nearly is and its slope term reaches 0.008.
#[test]
fn the_large_angle_flag_is_per_error_motion() {
    let text = "machine: roll
bodies:
  bed: {}
  x_slide:
    parent: bed
    joint: {type: prismatic, axis: +x, variable: x}
    errors:
      ex: {name: EAX, powers: [0, 1]}
      ez: {name: ECX, powers: [0, 1]}
      dy: EYX
  tool: {parent: x_slide, offset: [0, 0, 300]}
workpiece: bed
tool: tool
";
    let m = chain::core::load_str(text, "roll.yaml").unwrap();
    let mut e = vec![0.0; m.errors.len()];
    for (name, v) in [
        ("EAX_0", 0.006),
        ("EAX_1", 0.006 / 800.0),
        ("ECX_0", 0.008),
        ("ECX_1", -0.008 / 800.0),
    ] {
        e[m.error_index(name).unwrap()] = v;
    }
    let exact = Exact::new(&m);
    let p = exact.file_parameters();
    let records: Vec<Measurement> = (0..=8)
        .map(|i| {
            let q = vec![100.0 * i as f64];
            let err = exact.exact_error(&q, &p, &e);
            Measurement {
                line: i + 2,
                q,
                p: p.clone(),
                observed: Observed::Point,
                values: err[..3].to_vec(),
                std: None,
                setup: None,
                temperatures: Vec::new(),
            }
        })
        .collect();
    let model = chain::core::compile(&m);
    let design = chain::core::measured::Design::new(&model, &m, &records).unwrap();
    let r = chain::core::measured::identify(&design, None, &IdentifyOptions::default()).unwrap();
    let check = chain::core::measured::iterate::check(&m, &records, &design, &r, &e);
    assert_eq!(check.large_angles.len(), 1, "{:?}", check.large_angles);
    assert_eq!(check.large_angles[0].0, "EAX");
    assert!((check.large_angles[0].1 - 0.012).abs() < 1e-12);
}
