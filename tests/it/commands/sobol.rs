//! `reliability::sobol` and `chain sobol` on the gantry grinder (seed 000):
//! the Saltelli-Jansen indices against the closed form of a linear model in
//! independent errors, `|p|` against a brute-force double loop, the thread
//! count, the command line and its refusals.

use crate::common;

use std::path::PathBuf;

use chain_core::model::Component;
use chain_core::{CompiledModel, ErrorModel, Machine};
use common::cli::{fails, ok_json, ok_stdout, scratch, unwrapped};
use common::{example_path, Rng};
use reliability::sobol::{Estimate, Sobol, SobolResult};
use reliability::{machine, Study, Target};

fn gantry_file() -> PathBuf {
    example_path("gantry_grinder.yaml")
}

fn gantry() -> (Machine, CompiledModel) {
    let m = chain_core::load_file(&gantry_file()).expect("gantry_grinder.yaml loads");
    let model = chain_core::compile(&m);
    (m, model)
}

/// The point of the tests, `(x, y, z)`; the model's variable order is read
/// from the machine.
const POINT: [(&str, f64); 3] = [("x", 500.0), ("y", 1500.0), ("z", 600.0)];

fn point(m: &Machine) -> Vec<f64> {
    m.variables
        .iter()
        .map(|v| POINT.iter().find(|(n, _)| *n == v.name).unwrap().1)
        .collect()
}

fn study_at_point() -> (Machine, CompiledModel, Study) {
    let (m, model) = gantry();
    let spec = machine::spec(&m, None).unwrap();
    let inputs = machine::inputs(&m).unwrap();
    let params = machine::parameters(&m, &[]).unwrap();
    let study = Study::at_points(&model, &params, inputs, spec, vec![point(&m)]).unwrap();
    (m, model, study)
}

/// The model's own sensitivity matrix at the point (6 × k, component-major),
/// straight from `ErrorModel::sensitivity`, not through the study.
fn rows_at_point(m: &Machine, model: &CompiledModel) -> Vec<f64> {
    let k = model.errors().len();
    let mut s = vec![0.0; 6 * k];
    let params = machine::parameters(m, &[]).unwrap();
    model.sensitivity(&point(m), &params, &mut s);
    s
}

/// The closed form S_i = T_i = a_i² σ_i² / Σ_j a_j² σ_j² of component `c`.
fn closed_form(rows: &[f64], stds: &[f64], c: Component) -> Vec<f64> {
    let k = stds.len();
    let a = &rows[c.index() * k..(c.index() + 1) * k];
    let v: Vec<f64> = a.iter().zip(stds).map(|(a, s)| a * a * s * s).collect();
    let total: f64 = v.iter().sum();
    v.iter().map(|x| x / total).collect()
}

fn output(r: &SobolResult, t: Target) -> &reliability::sobol::OutputIndices {
    r.outputs.iter().find(|o| o.output == t).unwrap()
}

fn inside(e: &Estimate, x: f64) -> bool {
    e.low <= x && x <= e.high
}

/// Gantry px at (500, 1500, 600), N = 10⁵, 99 % intervals: every closed-form
/// index lies in its bootstrap interval (a miss has probability 1 % per
/// interval: at most 2 of the 28 non-trivial ones may miss, P(> 2) ≈ 0.3 %),
/// and within 0.01 (first order; its standard error is ≈ √S/√N ≤ 0.002) or
/// 4 standard errors `4·T·√(3/N)` (total: Jansen's numerator has relative
/// standard error √(2/N) for a linear normal model, `V̂` √(1/N)) of the
/// estimate; zero rows give exactly zero.
#[test]
fn gantry_px_at_a_point_equals_the_closed_form() {
    let (m, model, study) = study_at_point();
    let rows = rows_at_point(&m, &model);
    let stds = study.inputs().stds().to_vec();
    let r = Sobol {
        samples: 100_000,
        seed: 11,
        bootstrap: 1000,
        confidence: 0.99,
    }
    .run_study(&study)
    .unwrap();
    assert_eq!(r.points, 1);
    assert_eq!(r.inputs, 21);
    assert_eq!(r.evaluations_per_point, 100_000 * 23);
    for c in [Component::Px, Component::Py, Component::Pz] {
        let exact = closed_form(&rows, &stds, c);
        let o = output(&r, Target::Component(c));
        let mut misses = 0;
        let mut nontrivial = 0;
        for (e, x) in o.errors.iter().zip(&exact) {
            assert!((e.first.exact.unwrap() - x).abs() < 1e-12, "{c:?} {e:?}");
            if *x == 0.0 {
                assert_eq!((e.first.value, e.total.value), (0.0, 0.0), "{e:?}");
                continue;
            }
            nontrivial += 2;
            misses += usize::from(!inside(&e.first, *x)) + usize::from(!inside(&e.total, *x));
            assert!((e.first.value - x).abs() < 0.01, "{c:?} {e:?} vs {x}");
            let se_total = x * (3.0 / 100_000f64).sqrt();
            assert!(
                (e.total.value - x).abs() < 4.0 * se_total,
                "{c:?} {e:?} vs {x}"
            );
        }
        assert!(nontrivial >= 10, "{c:?}: {nontrivial}");
        assert!(
            misses <= 2,
            "{c:?}: {misses} of {nontrivial} intervals miss"
        );
        // Additive model: Σ T_i = Σ S_i = 1, inside their intervals.
        assert!(inside(&o.sum_total, 1.0), "{:?}", o.sum_total);
        assert!(inside(&o.sum_first, 1.0), "{:?}", o.sum_first);
        assert!((o.sum_total.value - 1.0).abs() < 0.01, "{:?}", o.sum_total);
        // The variance: Σ a_i² σ_i² within 2 % (its relative standard error
        // is √(2/2N) ≈ 0.3 %).
        let k = stds.len();
        let a = &rows[c.index() * k..(c.index() + 1) * k];
        let v: f64 = a.iter().zip(&stds).map(|(a, s)| a * a * s * s).sum();
        assert!((o.variance / v - 1.0).abs() < 0.02, "{} vs {v}", o.variance);
    }
}

/// Normal(0, 1) by Box-Muller from the tests' own SplitMix64.
fn normal(rng: &mut Rng) -> f64 {
    let u1 = 1.0 - rng.unit();
    let u2 = rng.unit();
    (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
}

/// `|p|` is not linear: its largest first-order index against a brute-force
/// double loop, `S_i = V[E(|p| | x_i)] / V(|p|)` with M₁ = 2000 outer values
/// of `x_i` and M₂ = 2000 inner samples of the others (the inner variance's
/// bias `E[s²]/M₂` removed), drawn from the tests' own generator. Tolerance:
/// 4 combined standard errors (the brute force's from the normal
/// approximation `se(V̂) ≈ V̂·√(2/M₁)` of the outer variance, Saltelli's from
/// its 95 % interval, half-width / 1.96).
#[test]
fn volumetric_first_order_index_against_a_double_loop() {
    let (m, model, study) = study_at_point();
    let rows = rows_at_point(&m, &model);
    let stds = study.inputs().stds().to_vec();
    let means = study.inputs().means().to_vec();
    let k = stds.len();
    let r = Sobol {
        samples: 100_000,
        seed: 5,
        ..Sobol::default()
    }
    .run_study(&study)
    .unwrap();
    let o = output(&r, Target::Volumetric);
    assert!(o.errors.iter().all(|e| e.first.exact.is_none()));
    let (i, e) = o
        .errors
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.first.value.total_cmp(&b.1.first.value))
        .unwrap();
    // Interactions: |p| is not additive, Σ S_i < 1 < Σ T_i... at least not
    // both 1: the total of the leading input is not below its first order.
    assert!(e.total.value >= e.first.value - 0.01, "{e:?}");

    let row = |c: usize| &rows[c * k..(c + 1) * k];
    let (m1, m2) = (2000, 2000);
    let mut rng = Rng::new(20260);
    let (mut cond_means, mut cond_vars) = (Vec::new(), Vec::new());
    let (mut all_sum, mut all_sq, mut count) = (0.0, 0.0, 0.0);
    let mut x = vec![0.0; k];
    for _ in 0..m1 {
        let xi = means[i] + stds[i] * normal(&mut rng);
        let (mut s, mut s2) = (0.0, 0.0);
        for _ in 0..m2 {
            for j in 0..k {
                x[j] = if j == i {
                    xi
                } else {
                    means[j] + stds[j] * normal(&mut rng)
                };
            }
            let p: Vec<f64> = (0..3)
                .map(|c| row(c).iter().zip(&x).map(|(a, x)| a * x).sum())
                .collect();
            let y = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
            s += y;
            s2 += y * y;
        }
        let mean = s / m2 as f64;
        cond_means.push(mean);
        cond_vars.push((s2 - m2 as f64 * mean * mean) / (m2 as f64 - 1.0));
        all_sum += s;
        all_sq += s2;
        count += m2 as f64;
    }
    let total_var = (all_sq - all_sum * all_sum / count) / (count - 1.0);
    let mbar = cond_means.iter().sum::<f64>() / m1 as f64;
    let var_means = cond_means.iter().map(|v| (v - mbar).powi(2)).sum::<f64>() / (m1 as f64 - 1.0);
    let inner = cond_vars.iter().sum::<f64>() / m1 as f64 / m2 as f64;
    let vi = var_means - inner;
    let brute = vi / total_var;
    let se_brute = var_means * (2.0 / m1 as f64).sqrt() / total_var;
    let se_saltelli = (e.first.high - e.first.low) / 2.0 / 1.96;
    let tol = 4.0 * (se_brute * se_brute + se_saltelli * se_saltelli).sqrt();
    assert!(
        (e.first.value - brute).abs() < tol,
        "{}: Saltelli {:?}, brute force {brute} ± {se_brute}",
        e.error,
        e.first
    );
    assert!(brute > 0.05, "the leading index is not trivial: {brute}");
}

/// Over the grid the indices pool the variances: for a component the closed
/// form is Σ_p a_pi² σ_i² / Σ_p Σ_j a_pj² σ_j², computed here from the
/// study's rows; the estimate within 0.02 (N = 2·10⁴).
#[test]
fn grid_pooled_indices_equal_the_pooled_closed_form() {
    let (m, model) = gantry();
    let study = machine::study(&m, &model, &[], None).unwrap();
    let stds = study.inputs().stds().to_vec();
    let r = Sobol {
        samples: 20_000,
        seed: 2,
        bootstrap: 200,
        confidence: 0.95,
    }
    .run_study(&study)
    .unwrap();
    assert_eq!(r.points, 125);
    for c in [Component::Px, Component::Py, Component::Pz] {
        let mut v = vec![0.0; stds.len()];
        for p in 0..study.points().len() {
            for (j, a) in study.row(p, c).unwrap().iter().enumerate() {
                v[j] += a * a * stds[j] * stds[j];
            }
        }
        let total: f64 = v.iter().sum();
        let o = output(&r, Target::Component(c));
        for (e, vj) in o.errors.iter().zip(&v) {
            let x = vj / total;
            assert!((e.first.exact.unwrap() - x).abs() < 1e-12);
            assert!((e.first.value - x).abs() < 0.02, "{c:?} {e:?} vs {x}");
            assert!((e.total.value - x).abs() < 0.01, "{c:?} {e:?} vs {x}");
        }
        assert!((o.sum_total.value - 1.0).abs() < 0.02);
    }
}

/// The same result, bit for bit, on 1 and 2 threads per seed.
#[test]
fn identical_for_one_and_two_threads() {
    let (m, model) = gantry();
    let study = machine::study(&m, &model, &[], None).unwrap();
    let s = Sobol {
        samples: 5_000,
        seed: 9,
        bootstrap: 100,
        confidence: 0.9,
    };
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| s.run_study(&study).unwrap())
    };
    let one = run(1);
    assert_eq!(one, run(2));
    // Another seed draws other samples.
    let other = Sobol { seed: 10, ..s }.run_study(&study).unwrap();
    assert_ne!(
        one.outputs[0].errors[0].first.value,
        other.outputs[0].errors[0].first.value
    );
}

fn at() -> String {
    POINT
        .iter()
        .map(|(n, v)| format!("{n}={v}"))
        .collect::<Vec<_>>()
        .join(",")
}

/// `chain sobol --format json` end to end: the document's fields, the px
/// closed form from the model's own rows (within 0.02 at N = 2·10⁴), the
/// thread count (RAYON_NUM_THREADS 1 and 2: the same document), CSV and table.
#[test]
fn cli_json_end_to_end() {
    let file = gantry_file();
    let f = file.to_str().unwrap();
    let at = at();
    let args = [
        "sobol",
        f,
        "--at",
        &at,
        "--samples",
        "20000",
        "--seed",
        "3",
        "--format",
        "json",
    ];
    let doc = ok_json(&args);
    assert_eq!(doc["machine"], "gantry_grinder");
    assert_eq!(doc["method"], "saltelli-jansen");
    assert_eq!(doc["at"]["y"], 1500.0);
    assert_eq!(doc["points"], 1);
    assert_eq!(doc["samples"], 20000);
    assert_eq!(doc["confidence"], 0.95);
    assert_eq!(doc["evaluations_per_point"], 20000 * 23);
    let outs = doc["outputs"].as_object().unwrap();
    assert_eq!(
        outs.keys().collect::<Vec<_>>(),
        ["px", "py", "pz", "volumetric"]
    );
    let (m, model) = gantry();
    let rows = rows_at_point(&m, &model);
    let stds = machine::inputs(&m).unwrap().stds().to_vec();
    let exact = closed_form(&rows, &stds, Component::Px);
    let errors = outs["px"]["errors"].as_array().unwrap();
    assert_eq!(errors.len(), 21);
    for (e, x) in errors.iter().zip(&exact) {
        let name = e["error"].as_str().unwrap();
        let j = m.errors.iter().position(|x| x.name == name).unwrap();
        assert_eq!(exact[j], *x, "errors in the model's order");
        let s = e["first"]["value"].as_f64().unwrap();
        let t = e["total"]["value"].as_f64().unwrap();
        assert!(
            (s - x).abs() < 0.02 && (t - x).abs() < 0.01,
            "{name}: {s} {t} vs {x}"
        );
        assert!(e["first"]["low"].as_f64().unwrap() <= s);
        assert!(e["first"]["high"].as_f64().unwrap() >= s);
        assert!((e["first"]["exact"].as_f64().unwrap() - x).abs() < 1e-12);
    }
    assert!(outs["volumetric"]["errors"][0]["first"]["exact"].is_null());
    // The thread count does not change the document.
    let run = |threads: &str| {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_chain"))
            .args(args)
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .env("RAYON_NUM_THREADS", threads)
            .output()
            .unwrap();
        assert!(out.status.success());
        out.stdout
    };
    assert_eq!(run("1"), run("2"));
    // CSV: a header and one row per output and error.
    let csv = ok_stdout(&[
        "sobol",
        f,
        "--at",
        &at,
        "--samples",
        "2000",
        "--format",
        "csv",
    ]);
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(
        lines[0],
        "output,error,first,first_low,first_high,total,total_low,total_high,exact"
    );
    assert_eq!(lines.len(), 1 + 4 * 21);
    assert!(lines[1].starts_with("px,"));
    // The grid (pooled) table.
    let table = ok_stdout(&["sobol", f, "--samples", "1000", "--bootstrap", "100"]);
    assert!(table.contains("pooled over the 125 grid points"), "{table}");
    assert!(table.contains("|p| (volumetric)"), "{table}");
}

/// Bad input: located, named, non-zero exit, nothing on stdout.
#[test]
fn bad_input_is_refused_with_its_location() {
    let file = gantry_file();
    let f = file.to_str().unwrap();
    let cases: [(&[&str], &str); 7] = [
        (
            &["--at", "x=0,y=0,w=1"],
            "--at: `w` is not an axis variable",
        ),
        (
            &["--at", "x=0,y=0"],
            "--at has no value for axis variable `z`",
        ),
        (&["--samples", "0"], "--samples 0: must be at least 2"),
        (
            &["--bootstrap", "0"],
            "--bootstrap 0: must be between 10 and 1000000",
        ),
        (
            &["--confidence", "1.5"],
            "--confidence 1.5: must be strictly between 0 and 1",
        ),
        (
            &["--at", "x=0,y=0,z=600", "--grid", "x=1"],
            "--grid cannot be combined with --at",
        ),
        (&["--grid", "w=1"], "unknown axis variable `w`"),
    ];
    for (extra, message) in cases {
        let mut args = vec!["sobol", f];
        args.extend_from_slice(extra);
        let err = unwrapped(&fails(&args));
        assert!(err.contains(message), "{extra:?}: {err}");
    }
    let dir = scratch("sobol-errors");
    let src = std::fs::read_to_string(&file).unwrap();
    let nostat = dir.join("nostat.yaml");
    std::fs::write(
        &nostat,
        src.replace("  eyx: {dist: normal, mean: 0, std: 0.06/6000}\n", ""),
    )
    .unwrap();
    let norel = dir.join("norel.yaml");
    std::fs::write(
        &norel,
        &src[..src.find("reliability:\n  tolerance").unwrap()],
    )
    .unwrap();
    let at = at();
    for extra in [vec![], vec!["--at", at.as_str()]] {
        let mut args = vec!["sobol", nostat.to_str().unwrap()];
        args.extend_from_slice(&extra);
        let err = unwrapped(&fails(&args));
        assert!(err.contains("nostat.yaml:"), "{err}");
        assert!(err.contains("missing key `statistics.eyx`"), "{err}");
        let mut args = vec!["sobol", norel.to_str().unwrap()];
        args.extend_from_slice(&extra);
        let err = unwrapped(&fails(&args));
        assert!(err.contains("missing key `reliability`"), "{err}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

chain::machine!(GantryGenerated = "examples/machines/gantry_grinder.yaml");

/// The `machine!`-generated model gives the runtime model's indices (the
/// same sensitivities to rounding, the same samples): within 1e-9.
#[test]
fn generated_model_equals_runtime_model() {
    let (m, model) = gantry();
    let s = Sobol {
        samples: 4_000,
        seed: 4,
        bootstrap: 100,
        confidence: 0.95,
    };
    let runtime = s
        .run_study(&machine::study(&m, &model, &[], None).unwrap())
        .unwrap();
    let generated = s
        .run_study(&machine::study(&m, &GantryGenerated, &[], None).unwrap())
        .unwrap();
    for (a, b) in runtime.outputs.iter().zip(&generated.outputs) {
        assert_eq!(a.output, b.output);
        for (x, y) in a.errors.iter().zip(&b.errors) {
            assert_eq!(x.error, y.error);
            for (u, v) in [
                (x.first.value, y.first.value),
                (x.total.value, y.total.value),
                (x.first.low, y.first.low),
                (x.total.high, y.total.high),
            ] {
                assert!((u - v).abs() < 1e-9, "{}: {u} vs {v}", x.error);
            }
        }
    }
}

/// Non-normal inputs: the gantry's errors as uniforms of the same standard
/// deviations (half-width √3·σ). The closed form a_i² σ_i² / Σ a_j² σ_j² holds
/// for any independent marginals (the variance of a sum of independent
/// terms); px at the point within 0.01 (first order) and 4 standard errors
/// `4·T·√(3/N)` (total). That bound is the normal one; for uniforms it is
/// conservative: `B_i − A_i` is triangular (kurtosis 2.4 against 3), so
/// Jansen's numerator has relative standard error √(1.4/N) < √(2/N).
#[test]
fn uniform_inputs_follow_the_closed_form() {
    let (m, model, study) = study_at_point();
    let rows = rows_at_point(&m, &model);
    let normal = study.inputs();
    let marginals = normal
        .stds()
        .iter()
        .zip(normal.means())
        .map(|(s, mu)| {
            let h = 3f64.sqrt() * s;
            reliability::Marginal::uniform(mu - h, mu + h).unwrap()
        })
        .collect();
    let uniform = reliability::Inputs::new(normal.names().to_vec(), marginals).unwrap();
    let n = 100_000;
    let r = Sobol {
        samples: n,
        seed: 8,
        ..Sobol::default()
    }
    .run(
        &uniform,
        std::slice::from_ref(&rows),
        &[Target::Component(Component::Px)],
    )
    .unwrap();
    let exact = closed_form(&rows, uniform.stds(), Component::Px);
    for (e, x) in r.outputs[0].errors.iter().zip(&exact) {
        assert!((e.first.value - x).abs() < 0.01, "{e:?} vs {x}");
        let se = x * (3.0 / n as f64).sqrt();
        assert!((e.total.value - x).abs() < 4.0 * se + 1e-15, "{e:?} vs {x}");
    }
}
