//! `chain identify` and the identification library (measured-machines spec,
//! section 4) against independent computations: measurements simulated from
//! known errors through the exact numeric 4×4 product of `tests/it/common` (not
//! chain's derivation) with Gaussian noise of known std; the gantry
//! grinder's analytic null space from the structure of its design columns
//! (identical, opposite and zero columns of the numeric product's finite
//! differences); the prior's limits; the values file written back through
//! `Values::read` and the map; bad input through the CLI.

#![allow(clippy::needless_range_loop)]

use crate::common;

use chain::core::built::{BuiltMachine, Points};
use chain::core::measured::identify::Prior;
use chain::core::measured::{identify, Design, IdentifyOptions, Measurement, Observed};
use chain::core::values::{Values, ValuesBuilder};
use chain::core::{ErrorModel, Machine};
use chain::reliability::Posterior;
use common::cli::{fails, ok_json, ok_stdout, scratch, unwrapped, write};
use common::{gauss, load_example, Exact, Rng};
use nalgebra::DMatrix;

/// A three-axis machine with constants and function-slot coefficients
/// (Legendre and powers), measured with several tool offsets per row.
const XYZ: &str = "machine: xyz3
parameters: {tx: 0, ty: 0, tz: 100}
bodies:
  bed: {}
  x_slide:
    parent: bed
    joint: {type: prismatic, axis: +x, variable: x}
    errors:
      dx: {name: EXX, basis: legendre, degree: 3, range: [0, 800]}
      dy: {name: EYX, powers: [1, 2]}
      ez: ECX
  y_slide:
    parent: x_slide
    joint: {type: prismatic, axis: +y, variable: y}
    errors:
      dy: {name: EYY, powers: [1, 2, 3]}
      ex: EAY
      dz: {name: EZY, basis: chebyshev, degree: 2, range: [0, 600]}
  tool: {parent: y_slide}
workpiece: bed
tool: tool
tool_point: [tx, ty, tz]
statistics:
  EXX_0: {dist: normal, mean: 0, std: 0.01}
  EXX_1: {dist: normal, mean: 0, std: 0.01}
  EXX_2: {dist: normal, mean: 0, std: 0.01}
  EXX_3: {dist: normal, mean: 0, std: 0.01}
  EYX_1: {dist: normal, mean: 0, std: 1e-5}
  EYX_2: {dist: normal, mean: 0, std: 1e-8}
  ECX: {dist: normal, mean: 0, std: 1e-4}
  EYY_1: {dist: normal, mean: 0, std: 1e-5}
  EYY_2: {dist: normal, mean: 0, std: 1e-8}
  EYY_3: {dist: normal, mean: 0, std: 1e-11}
  EAY: {dist: normal, mean: 0, std: 1e-4}
  EZY_0: {dist: normal, mean: 0, std: 0.01}
  EZY_1: {dist: normal, mean: 0, std: 0.01}
  EZY_2: {dist: normal, mean: 0, std: 0.01}
";

/// The known errors of the recovery test, by name.
fn truth(name: &str) -> f64 {
    match name {
        "EXX_0" => 0.004,
        "EXX_1" => -0.003,
        "EXX_2" => 0.0015,
        "EXX_3" => -0.0007,
        "EYX_1" => 2.0e-6,
        "EYX_2" => -3.0e-9,
        "ECX" => 1.5e-5,
        "EYY_1" => -4.0e-6,
        "EYY_2" => 5.0e-9,
        "EYY_3" => -2.0e-12,
        "EAY" => -2.5e-5,
        "EZY_0" => 0.002,
        "EZY_1" => 0.001,
        "EZY_2" => -0.0008,
        other => panic!("no truth for {other}"),
    }
}

/// The fixed rank tolerance (`--rank-tol 1e-6`): the full-rank least
/// squares the recovery tests below check. At these noise levels the
/// weakest combination of the cubic and quadratic coefficients is within
/// the noise, and the noise rule would leave it out
/// (`tests/it/commands/identify_subset.rs` tests the rule).
fn full_rank() -> IdentifyOptions {
    IdentifyOptions {
        rank_tol: Some(chain::core::measured::identify::RANK_TOLERANCE),
        ..Default::default()
    }
}

fn xyz() -> Machine {
    chain::core::load_str(XYZ, "xyz3.yaml").expect("xyz3 loads")
}

/// `count` poses with tool offsets, deterministic.
fn poses(count: usize) -> Vec<(Vec<f64>, Vec<f64>)> {
    let mut rng = Rng::new(7);
    (0..count)
        .map(|_| {
            let q = vec![rng.range(0.0, 800.0), rng.range(0.0, 600.0)];
            let p = vec![
                rng.range(-50.0, 50.0),
                rng.range(-50.0, 50.0),
                rng.range(50.0, 200.0),
            ];
            (q, p)
        })
        .collect()
}

/// Tool-point deviations simulated through the exact product with noise.
fn simulate(
    m: &Machine,
    poses: &[(Vec<f64>, Vec<f64>)],
    e: &[f64],
    sigma: f64,
    rng: &mut Rng,
) -> Vec<Measurement> {
    let exact = Exact::new(m);
    poses
        .iter()
        .enumerate()
        .map(|(i, (q, p))| {
            let err = exact.exact_error(q, p, e);
            Measurement {
                line: i + 2,
                q: q.clone(),
                p: p.clone(),
                observed: Observed::Point,
                values: (0..3).map(|c| err[c] + sigma * gauss(rng)).collect(),
                std: Some(sigma),
                setup: None,
                temperatures: Vec::new(),
            }
        })
        .collect()
}

#[test]
fn recovers_constants_and_coefficients_with_honest_std() {
    let m = xyz();
    let model = chain::core::compile(&m);
    let names: Vec<&str> = m.errors.iter().map(|e| e.name.as_str()).collect();
    let e: Vec<f64> = names.iter().map(|n| truth(n)).collect();
    let sigma = 1e-3;
    let poses = poses(150);
    let mut rng = Rng::new(42);
    let records = simulate(&m, &poses, &e, sigma, &mut rng);
    let design = Design::new(&model, &m, &records).unwrap();
    let r = identify(&design, None, &full_rank()).unwrap();
    assert_eq!(r.parameters, 14);
    assert_eq!(
        r.rank, 14,
        "the design is full rank: {:?}",
        r.unidentifiable
    );
    for (j, (name, est)) in r.estimates.0.iter().enumerate() {
        let std = est.std.unwrap();
        assert!(std > 0.0);
        assert!(
            (est.value - e[j]).abs() < 4.0 * std,
            "{name}: {} vs truth {} (std {std})",
            est.value,
            e[j]
        );
    }
    // The reported std against the spread over 200 repeated data sets.
    let reported: Vec<f64> = r.estimates.0.iter().map(|(_, e)| e.std.unwrap()).collect();
    let runs = 200;
    let mut samples = vec![Vec::with_capacity(runs); e.len()];
    for _ in 0..runs {
        let records = simulate(&m, &poses, &e, sigma, &mut rng);
        let design = Design::new(&model, &m, &records).unwrap();
        let r = identify(&design, None, &full_rank()).unwrap();
        for (j, (_, est)) in r.estimates.0.iter().enumerate() {
            samples[j].push(est.value);
        }
    }
    for j in 0..e.len() {
        let mean = samples[j].iter().sum::<f64>() / runs as f64;
        let var = samples[j].iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (runs - 1) as f64;
        let spread = var.sqrt();
        let ratio = spread / reported[j];
        assert!(
            (ratio - 1.0).abs() < 0.15,
            "{}: spread {spread} vs reported {} (ratio {ratio})",
            names[j],
            reported[j]
        );
        // Unbiased: the mean within 4 standard errors of the truth.
        assert!(
            (mean - e[j]).abs() < 4.0 * reported[j] / (runs as f64).sqrt(),
            "{}: mean {mean} vs {}",
            names[j],
            e[j]
        );
    }
}

#[test]
fn without_std_the_covariance_is_scaled_by_the_residual() {
    let m = xyz();
    let model = chain::core::compile(&m);
    let e: Vec<f64> = m.errors.iter().map(|x| truth(&x.name)).collect();
    let mut rng = Rng::new(3);
    let sigma = 2e-3;
    let mut records = simulate(&m, &poses(120), &e, sigma, &mut rng);
    let weighted = identify(
        &Design::new(&model, &m, &records).unwrap(),
        None,
        &Default::default(),
    )
    .unwrap();
    for r in &mut records {
        r.std = None;
    }
    let plain = identify(
        &Design::new(&model, &m, &records).unwrap(),
        None,
        &Default::default(),
    )
    .unwrap();
    let s = plain.residual.scale.unwrap();
    // s² = RSS/(m − rank) by hand.
    let rss: f64 = plain.residuals.iter().map(|r| r * r).sum();
    let dof = (plain.rows - plain.rank) as f64;
    assert!(((rss / dof).sqrt() - s).abs() < 1e-15);
    assert!((s / sigma - 1.0).abs() < 0.1, "s {s}");
    for ((_, w), (_, p)) in weighted.estimates.0.iter().zip(&plain.estimates.0) {
        assert!((w.value - p.value).abs() < 1e-8 * w.std.unwrap());
        let ratio = p.std.unwrap() / w.std.unwrap();
        assert!((ratio - s / sigma).abs() < 1e-9, "{ratio}");
    }
}

/// The gantry's design columns by finite differences of the exact product.
fn gantry_columns(m: &Machine, q: &[Vec<f64>]) -> DMatrix<f64> {
    let exact = Exact::new(m);
    let n = m.errors.len();
    let rows = 3 * q.len();
    DMatrix::from_fn(rows, n, |i, j| {
        let (k, c) = (i / 3, i % 3);
        let h = 1e-6;
        let mut e = vec![0.0; n];
        e[j] = h;
        let plus = exact.exact_error(&q[k], &[], &e)[c];
        e[j] = -h;
        let minus = exact.exact_error(&q[k], &[], &e)[c];
        (plus - minus) / (2.0 * h)
    })
}

#[test]
fn gantry_position_only_null_space_is_the_analytic_one() {
    let m = load_example("gantry_grinder.yaml");
    let model = chain::core::compile(&m);
    let mut rng = Rng::new(11);
    let q: Vec<Vec<f64>> = (0..80)
        .map(|_| {
            vec![
                rng.range(0.0, 1000.0),
                rng.range(-1500.0, 1500.0),
                rng.range(600.0, 1400.0),
            ]
        })
        .collect();
    let records: Vec<Measurement> = q
        .iter()
        .enumerate()
        .map(|(i, q)| Measurement {
            line: i + 2,
            q: q.clone(),
            p: vec![],
            observed: Observed::Point,
            values: vec![0.0; 3],
            std: None,
            setup: None,
            temperatures: Vec::new(),
        })
        .collect();
    let r = identify(
        &Design::new(&model, &m, &records).unwrap(),
        None,
        &Default::default(),
    )
    .unwrap();
    // The analytic null space from the structure of the columns: zero
    // columns, and columns identical or opposite to an earlier one.
    let a = gantry_columns(&m, &q);
    let n = m.errors.len();
    let mut vectors: Vec<Vec<f64>> = Vec::new();
    let mut representative: Vec<usize> = Vec::new();
    'col: for j in 0..n {
        let cj = a.column(j);
        if cj.amax() < 1e-6 {
            let mut v = vec![0.0; n];
            v[j] = 1.0;
            vectors.push(v);
            continue;
        }
        for &k in &representative {
            let ck = a.column(k);
            for s in [1.0, -1.0] {
                if (cj - ck * s).amax() < 1e-6 * ck.amax() {
                    let mut v = vec![0.0; n];
                    v[k] = s;
                    v[j] = -1.0;
                    vectors.push(v);
                    continue 'col;
                }
            }
        }
        representative.push(j);
    }
    // The representatives are independent: the structure is the whole story.
    let reps = DMatrix::from_fn(a.nrows(), representative.len(), |i, c| {
        a[(i, representative[c])] / a.column(representative[c]).norm()
    });
    let sv = reps.clone().svd(false, false).singular_values;
    assert!(sv.min() > 1e-3 * sv.max(), "{sv}");
    assert_eq!(r.rank, representative.len());
    assert_eq!(r.null_space.ncols(), vectors.len());
    assert_eq!(vectors.len(), 13);
    let analytic = DMatrix::from_fn(n, vectors.len(), |i, c| vectors[c][i]);
    let qa = analytic.qr().q();
    // sin of the principal angles: singular values of (I − Q_a Q_aᵀ) N.
    let resid = &r.null_space - &qa * (qa.transpose() * &r.null_space);
    let sines = resid.svd(false, false).singular_values;
    assert!(sines.max() < 1e-8, "principal angles {sines}");
    // And N is orthonormal.
    let gram = r.null_space.transpose() * &r.null_space;
    assert!((gram - DMatrix::identity(13, 13)).amax() < 1e-12);
    // Components below 1e-9 are omitted; the offset group is one group.
    assert!(r
        .unidentifiable
        .iter()
        .all(|v| v.0.iter().all(|(_, c)| c.abs() >= 1e-9)));

    // The table names the aliased groups.
    let dir = scratch("gantry");
    let mut csv = String::from("x,y,z,dpx,dpy,dpz\n");
    for (i, q) in q.iter().enumerate() {
        csv.push_str(&format!(
            "{},{},{},{},{},{}\n",
            q[0],
            q[1],
            q[2],
            1e-4 * (i % 3) as f64,
            0,
            0
        ));
    }
    let file = write(&dir, "m.csv", &csv);
    let out = ok_stdout(&[
        "identify",
        "examples/machines/gantry_grinder.yaml",
        "--measurements",
        file.to_str().unwrap(),
    ]);
    for words in [
        "dxx, dxz and dxy only act as one offset in px",
        "dyx, dyz and dyy only act as one offset in py",
        "dzx, dzz and dzy only act as one offset in pz",
        "ezx and Sxy only act as",
        "eyz has no effect on these measurements",
    ] {
        assert!(out.contains(words), "missing `{words}` in\n{out}");
    }
    let json = ok_json(&[
        "identify",
        "examples/machines/gantry_grinder.yaml",
        "--measurements",
        file.to_str().unwrap(),
        "--format",
        "json",
    ]);
    for key in [
        "machine",
        "measurements",
        "parameters",
        "rank",
        "condition",
        "estimates",
        "unidentifiable",
        "residual",
    ] {
        assert!(json.get(key).is_some(), "no key {key}");
    }
    assert_eq!(json["rank"], 8);
    assert_eq!(json["measurements"], 80);
    assert_eq!(json["parameters"], 21);
    assert_eq!(json["unidentifiable"].as_array().unwrap().len(), 13);
    assert!(json["estimates"]["dxx"]["std"].is_number());
    assert!(json["residual"]["rms"].is_number() && json["residual"]["max"].is_number());
}

#[test]
fn prior_without_data_is_the_prior_and_with_much_data_the_least_squares() {
    let m = xyz();
    let model = chain::core::compile(&m);
    let names: Vec<String> = m.errors.iter().map(|e| e.name.clone()).collect();
    let prior = Prior::from_machine(&m, &names).unwrap();
    let empty = Design::new(&model, &m, &[]).unwrap();
    let r = identify(&empty, Some(&prior), &Default::default()).unwrap();
    for (j, (_, est)) in r.estimates.0.iter().enumerate() {
        assert_eq!(est.value, prior.mean[j]);
        assert!((est.std.unwrap() / prior.std[j] - 1.0).abs() < 1e-12);
    }
    assert_eq!(r.unidentifiable.len(), names.len(), "nothing informed");

    let e: Vec<f64> = names.iter().map(|n| truth(n)).collect();
    let mut rng = Rng::new(5);
    let records = simulate(&m, &poses(3000), &e, 1e-4, &mut rng);
    let design = Design::new(&model, &m, &records).unwrap();
    let ls = identify(&design, None, &Default::default()).unwrap();
    let post = identify(&design, Some(&prior), &Default::default()).unwrap();
    assert!(post.unidentifiable.is_empty(), "{:?}", post.unidentifiable);
    for ((name, a), (_, b)) in ls.estimates.0.iter().zip(&post.estimates.0) {
        let (sa, sb) = (a.std.unwrap(), b.std.unwrap());
        assert!(
            (a.value - b.value).abs() < 0.05 * sa,
            "{name}: {} vs {}",
            a.value,
            b.value
        );
        assert!(sb <= sa && sb > 0.95 * sa, "{name}: {sb} vs {sa}");
    }
}

#[test]
fn values_out_reads_back_and_maps_like_the_estimates() {
    let m = xyz();
    let model = chain::core::compile(&m);
    let e: Vec<f64> = m.errors.iter().map(|x| truth(&x.name)).collect();
    let mut rng = Rng::new(9);
    let records = simulate(&m, &poses(60), &e, 1e-3, &mut rng);
    let dir = scratch("values-out");
    let machine = write(&dir, "xyz3.yaml", XYZ);
    let mut csv = String::from("x,y,tx,ty,tz,dpx,dpy,dpz,std\n");
    for r in &records {
        csv.push_str(&format!(
            "{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?}\n",
            r.q[0], r.q[1], r.p[0], r.p[1], r.p[2], r.values[0], r.values[1], r.values[2], 1e-3
        ));
    }
    let mcsv = write(&dir, "m.csv", &csv);
    let out = dir.join("v.yaml");
    let json = ok_json(&[
        "identify",
        machine.to_str().unwrap(),
        "--measurements",
        mcsv.to_str().unwrap(),
        "--format",
        "json",
        "--values-out",
        out.to_str().unwrap(),
    ]);
    let values = Values::read(&out, &m).expect("the written values file reads back");
    // The library's answer on the same records.
    let lib = identify(
        &Design::new(&model, &m, &records).unwrap(),
        None,
        &Default::default(),
    )
    .unwrap();
    // The file holds the least-squares subset's values.
    let (solution, _) = lib.solution();
    let mut b = ValuesBuilder::new(&m);
    for (j, (name, est)) in lib.estimates.0.iter().enumerate() {
        b.constant(name, solution[j]).unwrap();
        let cli = json["estimates"][name]["value"].as_f64().unwrap();
        assert!((cli - est.value).abs() <= 1e-12 * est.value.abs(), "{name}");
        let sub = json["subset"]["estimates"][name]["value"].as_f64().unwrap();
        assert!(
            (sub - solution[j]).abs() <= 1e-12 * solution[j].abs(),
            "{name}"
        );
    }
    let params = vec![0.0, 0.0, 100.0];
    let grid = Points::Grid(vec![vec![0.0, 400.0, 800.0], vec![0.0, 300.0, 600.0]]);
    let a = BuiltMachine::compile(&m, values, params.clone())
        .unwrap()
        .map(grid.clone())
        .unwrap();
    let want = BuiltMachine::compile(&m, b.build(), params)
        .unwrap()
        .map(grid)
        .unwrap();
    assert_eq!(a.errors.len(), 9);
    for (p, w) in a.errors.iter().zip(&want.errors) {
        for c in 0..6 {
            assert!((p[c] - w[c]).abs() < 1e-15, "{p:?} vs {w:?}");
        }
    }
    // And the map is the model's error with the estimates.
    let est = solution;
    let mut direct = [0.0; 6];
    model.error(&[800.0, 600.0], &[0.0, 0.0, 100.0], &est, &mut direct);
    let last = a.errors[8];
    for c in 0..6 {
        assert!(
            (last[c] - direct[c]).abs() < 1e-15,
            "{last:?} vs {direct:?}"
        );
    }
    // The posterior `chain reliability --values` reads from the same file:
    // each std and each correlation is the library's covariance (to the
    // 17 digits written), and together they are positive definite.
    let post = Posterior::read(&out, &m).expect("the posterior reads the written file");
    let n = lib.errors.len();
    let (_, covariance) = lib.solution();
    let sd: Vec<f64> = (0..n).map(|j| covariance[(j, j)].sqrt()).collect();
    for (j, name) in lib.errors.iter().enumerate() {
        let v = post.value(name).expect("every unknown is written");
        assert_eq!(v.mean, est[j], "{name}");
        assert_eq!(v.std, Some(sd[j]).filter(|s| *s > 0.0), "{name}");
    }
    let index = |x: &str| lib.errors.iter().position(|e| e == x).unwrap();
    let mut seen = vec![vec![false; n]; n];
    for c in &post.correlations {
        let (i, j) = (index(&c.a), index(&c.b));
        let rho = covariance[(i, j)] / (sd[i] * sd[j]);
        assert!(
            (c.rho - rho).abs() < 1e-15,
            "{} {}: {} vs {rho}",
            c.a,
            c.b,
            c.rho
        );
        seen[i][j] = true;
    }
    for i in 0..n {
        for j in i + 1..n {
            assert!(
                seen[i][j] || covariance[(i, j)] == 0.0,
                "pair {} {} missing",
                lib.errors[i],
                lib.errors[j]
            );
        }
    }
    post.inputs(&m)
        .expect("a full-rank posterior is positive definite");
}

/// A bad measurement CSV: located message, non-zero exit, nothing on stdout.
#[track_caller]
fn refused(csv: &str, wants: &[&str]) {
    let dir = scratch("bad");
    let file = write(&dir, "bad.csv", csv);
    let err = unwrapped(&fails(&[
        "identify",
        "examples/machines/gantry_grinder.yaml",
        "--measurements",
        file.to_str().unwrap(),
    ]));
    for w in wants {
        assert!(err.contains(w), "missing `{w}` in\n{err}");
    }
}

#[test]
fn bad_input_is_refused_with_its_location() {
    refused(
        "x,y,z,dpx,dpy,dpz,dqx\n0,0,600,0,0,0,1\n",
        &["bad.csv:1:", "column `dqx` is neither"],
    );
    refused(
        "x,y,dpx,dpy,dpz\n0,0,0,0,0\n",
        &["bad.csv:1:", "`z`", "whole pose"],
    );
    refused(
        "x,y,z,dpx,dpy,dpz\n0,0,600,0,0,0\n10,0,600,NaN,0,0\n",
        &["bad.csv:3:", "column `dpx`: `NaN` is not finite"],
    );
    refused(
        "x,y,z,dpx,dpy,dpz\n0,0,600,0,0,0\n10,0,inf,0,0,0\n",
        &["bad.csv:3:", "is not finite"],
    );
    refused(
        "x,y,z,dpx,dpy,dpz,std\n0,0,600,0,0,0,0.001\n1,0,600,0,0,0,0\n",
        &["bad.csv:3:", "standard deviation must be positive"],
    );
    refused(
        "x,y,z,dpx,dpy,dpz,std\n0,0,600,0,0,0,-1\n",
        &["bad.csv:2:", "standard deviation must be positive"],
    );
    refused("", &["bad.csv:1:", "empty"]);
    refused("x,y,z,dpx,dpy,dpz\n", &["bad.csv:1:", "no data row"]);
    refused(
        "x,y,z,dpx,dpy,dpz\n0,0,600,0,0,0\n1,2,3\n",
        &["bad.csv:3:", "has 3 fields but the header has 6 columns"],
    );
    refused(
        "x,y,z,dpx,dpy\n0,0,600,0,0\n",
        &["bad.csv:1:", "only some of `dpx,dpy,dpz`"],
    );
    refused(
        "x,y,z,ux,uy,uz,d\n0,0,600,1,1,0,0.1\n",
        &["bad.csv:2:", "not 1"],
    );
    refused(
        "x,y,z,dpx,dpy,dpz\n0,0,600,abc,0,0\n",
        &["bad.csv:2:", "column `dpx`: `abc` is not a number"],
    );
    let err = fails(&[
        "identify",
        "examples/machines/gantry_grinder.yaml",
        "--measurements",
        "/nonexistent/m.csv",
    ]);
    assert!(err.contains("m.csv"), "{err}");
    let dir = scratch("noprior");
    let file = write(&dir, "m.csv", "x,y,z,dpx,dpy,dpz\n0,0,600,0,0,0\n");
    let err = fails(&[
        "identify",
        "examples/machines/legendre5.yaml",
        "--measurements",
        file.to_str().unwrap(),
    ]);
    assert!(unwrapped(&err).contains("m.csv:1:"), "{err}");
}

#[test]
fn directions_identify_like_points() {
    // The same errors measured along directions (three unit axes and a body
    // diagonal per pose): the estimate agrees with the truth within 4 std.
    let m = xyz();
    let model = chain::core::compile(&m);
    let e: Vec<f64> = m.errors.iter().map(|x| truth(&x.name)).collect();
    let exact = Exact::new(&m);
    let mut rng = Rng::new(13);
    let s3 = 1.0 / 3f64.sqrt();
    let dirs = [
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [s3, s3, s3],
    ];
    let mut records = Vec::new();
    for (q, p) in poses(150) {
        let err = exact.exact_error(&q, &p, &e);
        for u in dirs {
            let d = u[0] * err[0] + u[1] * err[1] + u[2] * err[2];
            records.push(Measurement {
                line: 0,
                q: q.clone(),
                p: p.clone(),
                observed: Observed::Direction { u },
                values: vec![d + 1e-3 * gauss(&mut rng)],
                std: Some(1e-3),
                setup: None,
                temperatures: Vec::new(),
            });
        }
    }
    let r = identify(
        &Design::new(&model, &m, &records).unwrap(),
        None,
        &full_rank(),
    )
    .unwrap();
    assert_eq!(r.rank, 14);
    for (j, (name, est)) in r.estimates.0.iter().enumerate() {
        assert!((est.value - e[j]).abs() < 4.0 * est.std.unwrap(), "{name}");
    }
    let _ = model.errors();
}

/// Records as a measurement CSV: the pose by `vars`, the parameters by
/// `params`, then `dpx,dpy,dpz` or `ux,uy,uz,d`, and `std` when the records
/// have one (every value in full precision).
fn records_csv(records: &[Measurement], vars: &[&str], params: &[&str]) -> String {
    let direction = matches!(records[0].observed, Observed::Direction { .. });
    let weighted = records[0].std.is_some();
    let mut head: Vec<&str> = vars.iter().chain(params).copied().collect();
    head.extend(if direction {
        &["ux", "uy", "uz", "d"][..]
    } else {
        &["dpx", "dpy", "dpz"][..]
    });
    if weighted {
        head.push("std");
    }
    let mut csv = head.join(",") + "\n";
    for r in records {
        let mut cells: Vec<f64> = r.q.iter().chain(&r.p).copied().collect();
        if let Observed::Direction { u } = r.observed {
            cells.extend(u);
        }
        cells.extend(&r.values);
        cells.extend(r.std);
        let cells: Vec<String> = cells.iter().map(|v| format!("{v:?}")).collect();
        csv.push_str(&(cells.join(",") + "\n"));
    }
    csv
}

/// Every CLI estimate equals the library's to round-off.
#[track_caller]
fn same_estimates(json: &serde_json::Value, lib: &chain::core::measured::Identification) {
    assert_eq!(json["rank"].as_u64().unwrap() as usize, lib.rank);
    for (name, est) in &lib.estimates.0 {
        let value = json["estimates"][name]["value"].as_f64().unwrap();
        let std = json["estimates"][name]["std"].as_f64().unwrap();
        let tol = 1e-9 * (est.value.abs() + est.std.unwrap());
        assert!(
            (value - est.value).abs() <= tol,
            "{name}: {value} vs {}",
            est.value
        );
        assert!(
            (std / est.std.unwrap() - 1.0).abs() < 1e-9,
            "{name}: std {std} vs {:?}",
            est.std
        );
    }
}

#[test]
fn a_planted_outlier_is_flagged_first() {
    // 120 point records with σ = 1e-3 mm; one component of record 37 is
    // shifted by 20 σ. Its standardised residual is the largest, above the
    // limit, and flagged; at most a few of the other 359 rows pass |t| > 3
    // by chance (expected 360 · 0.0027 ≈ 1).
    let m = xyz();
    let model = chain::core::compile(&m);
    let e: Vec<f64> = m.errors.iter().map(|x| truth(&x.name)).collect();
    let mut rng = Rng::new(21);
    let mut records = simulate(&m, &poses(120), &e, 1e-3, &mut rng);
    records[37].values[1] += 20e-3;
    let r = identify(
        &Design::new(&model, &m, &records).unwrap(),
        None,
        &Default::default(),
    )
    .unwrap();
    let first = &r.largest_residuals[0];
    assert_eq!((first.row / 3, first.component), (37, "dpy"), "{first:?}");
    assert!(
        first.outlier && first.standardised.abs() > 10.0,
        "{first:?}"
    );
    assert!((1..=4).contains(&r.outliers), "{} flagged", r.outliers);
    // Without the planted error the same data flag at most a few rows and
    // none of them is that row.
    records[37].values[1] -= 20e-3;
    let clean = identify(
        &Design::new(&model, &m, &records).unwrap(),
        None,
        &Default::default(),
    )
    .unwrap();
    assert!(clean.outliers <= 3, "{} flagged", clean.outliers);
    assert!(clean
        .largest_residuals
        .iter()
        .all(|s| !(s.outlier && s.row / 3 == 37 && s.component == "dpy")));
}

#[test]
fn cli_directions_and_prior_without_std_are_the_library_answer() {
    let m = xyz();
    let model = chain::core::compile(&m);
    let e: Vec<f64> = m.errors.iter().map(|x| truth(&x.name)).collect();
    let exact = Exact::new(&m);
    let dir = scratch("cli-directions");
    let machine = write(&dir, "xyz3.yaml", XYZ);
    // Directions `ux,uy,uz,d` with a std column (one axis or a face
    // diagonal per record, written with unit norm).
    let s2 = 0.5f64.sqrt();
    let dirs = [
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [s2, 0.0, s2],
        [0.0, s2, -s2],
    ];
    let mut rng = Rng::new(17);
    let mut records = Vec::new();
    for (k, (q, p)) in poses(200).into_iter().enumerate() {
        let u = dirs[k % dirs.len()];
        let err = exact.exact_error(&q, &p, &e);
        records.push(Measurement {
            line: k + 2,
            q,
            p,
            observed: Observed::Direction { u },
            values: vec![u[0] * err[0] + u[1] * err[1] + u[2] * err[2] + 1e-3 * gauss(&mut rng)],
            std: Some(1e-3),
            setup: None,
            temperatures: Vec::new(),
        });
    }
    let csv = write(
        &dir,
        "d.csv",
        &records_csv(&records, &["x", "y"], &["tx", "ty", "tz"]),
    );
    let args = |file: &std::path::Path, prior: bool| {
        let mut a = vec![
            "identify".to_string(),
            machine.to_str().unwrap().to_string(),
            "--measurements".to_string(),
            file.to_str().unwrap().to_string(),
            "--format".to_string(),
            "json".to_string(),
        ];
        if prior {
            a.push("--prior".to_string());
        }
        a
    };
    let run = |a: Vec<String>| ok_json(&a.iter().map(String::as_str).collect::<Vec<_>>());
    let lib = identify(
        &Design::new(&model, &m, &records).unwrap(),
        None,
        &Default::default(),
    )
    .unwrap();
    assert_eq!(lib.noise.structural_rank, 14);
    let json = run(args(&csv, false));
    assert_eq!(json["rank"].as_u64(), Some(lib.rank as u64));
    same_estimates(&json, &lib);
    assert_eq!(json["measurements"].as_u64(), Some(200));

    // `--prior` on points without a std column: the noise is the
    // least-squares fit's s, the prior the machine file's statistics.
    let mut rng = Rng::new(19);
    let mut points = simulate(&m, &poses(40), &e, 2e-3, &mut rng);
    for r in &mut points {
        r.std = None;
    }
    let csv = write(
        &dir,
        "p.csv",
        &records_csv(&points, &["x", "y"], &["tx", "ty", "tz"]),
    );
    let names: Vec<String> = m.errors.iter().map(|x| x.name.clone()).collect();
    let prior = Prior::from_machine(&m, &names).unwrap();
    let lib = identify(
        &Design::new(&model, &m, &points).unwrap(),
        Some(&prior),
        &Default::default(),
    )
    .unwrap();
    let json = run(args(&csv, true));
    same_estimates(&json, &lib);
    assert_eq!(json["prior"].as_bool(), Some(true));
    let scale = lib.residual.scale.unwrap();
    assert!((scale / 2e-3 - 1.0).abs() < 0.25, "s = {scale}");
}

#[test]
fn reliability_after_calibration_reads_the_identified_posterior() {
    // The whole workflow on the gantry grinder: measure tool-point
    // deviations (tool point 0, position only: rank deficient), identify,
    // write the values, run `chain reliability --values`. Without a prior
    // the values are the least-squares subset's;
    // with `--prior` it is full rank; both run through the reliability.
    let m = load_example("gantry_grinder.yaml");
    let means: Vec<f64> = m
        .errors
        .iter()
        .map(|x| x.name.len() as f64 * 1e-4)
        .collect();
    let mut rng = Rng::new(23);
    let q: Vec<(Vec<f64>, Vec<f64>)> = (0..60)
        .map(|_| {
            let q = vec![
                rng.range(0.0, 1000.0),
                rng.range(600.0, 1400.0),
                rng.range(-1500.0, 1500.0),
            ];
            (q, vec![])
        })
        .collect();
    let records = simulate(&m, &q, &means, 1e-3, &mut rng);
    let vars: Vec<&str> = m.variables.iter().map(|v| v.name.as_str()).collect();
    let dir = scratch("after-calibration");
    let csv = write(&dir, "g.csv", &records_csv(&records, &vars, &[]));
    let machine = common::example_path("gantry_grinder.yaml");
    let identify_to = |out: &std::path::Path, prior: bool| {
        let mut a = vec![
            "identify",
            machine.to_str().unwrap(),
            "--measurements",
            csv.to_str().unwrap(),
            "--format",
            "json",
            "--values-out",
            out.to_str().unwrap(),
        ];
        if prior {
            a.push("--prior");
        }
        ok_json(&a)
    };
    // Each case's β is the closed form of the correlated normal posterior:
    // g = t − a·e (upper-sided, t = 0.03 mm), β = (t − a·μ) / √(aᵀ Σ a),
    // Σ = D R D from the file's std and correlation triples; an error
    // written without a std (fixed by the least-squares subset) keeps its
    // statistics spread about the written value, unless it is
    // `carried_by` estimated errors (redundant: exact, spread 0).
    let n = m.errors.len();
    let index = |x: &str| m.errors.iter().position(|e| e.name == x).unwrap();
    let model = chain::core::compile(&m);
    let check = |file: &std::path::Path| {
        let out = ok_json(&[
            "reliability",
            machine.to_str().unwrap(),
            "--values",
            file.to_str().unwrap(),
            "--format",
            "json",
        ]);
        let posterior = Posterior::read(file, &m).unwrap();
        posterior.inputs(&m).expect("a regular posterior");
        let mu: Vec<f64> = m
            .errors
            .iter()
            .map(|x| posterior.value(&x.name).unwrap().mean)
            .collect();
        let sd: Vec<f64> = m
            .errors
            .iter()
            .enumerate()
            .map(|(j, x)| {
                let v = posterior.value(&x.name).unwrap();
                match v.std {
                    Some(s) => s,
                    None if !v.carried_by.is_empty() => 0.0,
                    None => m.statistic(j).unwrap().distribution.std(),
                }
            })
            .collect();
        let mut cov = DMatrix::from_fn(n, n, |i, j| if i == j { sd[i] * sd[i] } else { 0.0 });
        for c in &posterior.correlations {
            let (i, j) = (index(&c.a), index(&c.b));
            cov[(i, j)] = c.rho * sd[i] * sd[j];
            cov[(j, i)] = cov[(i, j)];
        }
        let results = out["results"].as_array().unwrap();
        assert_eq!(results.len(), 3 * 125);
        let mut s = vec![0.0; 6 * n];
        for r in results {
            let c = ["px", "py", "pz"]
                .iter()
                .position(|c| r["component"] == *c)
                .unwrap();
            let q: Vec<f64> = vars
                .iter()
                .map(|v| r["point"][*v].as_f64().unwrap())
                .collect();
            model.sensitivity(&q, &[], &mut s);
            let a = nalgebra::DVector::from_column_slice(&s[c * n..(c + 1) * n]);
            let mean: f64 = (0..n).map(|j| a[j] * mu[j]).sum();
            let beta = (0.03 - mean) / (a.dot(&(&cov * &a))).sqrt();
            let got = r["beta"].as_f64().unwrap();
            assert!((got / beta - 1.0).abs() < 1e-9, "{r}: β {got} vs {beta}");
        }
    };
    // Without a prior: the least-squares subset, the fixed errors written
    // without a std (a comment says why) and no ±1 correlation.
    let ls = dir.join("ls.yaml");
    let json = identify_to(&ls, false);
    assert!(json["rank"].as_u64().unwrap() < m.errors.len() as u64);
    let text = std::fs::read_to_string(&ls).unwrap();
    assert!(text.contains("fixed at their nominal value 0"), "{text}");
    // The grinder's redundant errors are written carried by their carriers.
    assert!(text.contains("carried_by: ["), "{text}");
    assert!(
        !text.contains(", 1.0]") && !text.contains(", -1.0]"),
        "{text}"
    );
    check(&ls);

    let post = dir.join("post.yaml");
    let json = identify_to(&post, true);
    assert_eq!(json["prior"].as_bool(), Some(true));
    check(&post);
}

/// `--validate`: the estimates' prediction at poses held
/// out of the fit, against an independent computation: the error before is
/// the measured deviations themselves, the error after is the measured
/// deviations less the exact numeric product of `tests/it/common` with the
/// identified values (not chain's first-order rows; the two differ by the
/// second order of errors of 1e-3 mm and 1e-5 rad, far below 1e-7 mm).
#[test]
fn held_out_poses_are_predicted_as_the_exact_product_predicts_them() {
    let m = xyz();
    let names: Vec<&str> = m.errors.iter().map(|e| e.name.as_str()).collect();
    let e: Vec<f64> = names.iter().map(|n| truth(n)).collect();
    let sigma = 1e-3;
    let mut rng = Rng::new(5);
    let all = poses(120);
    let (fit, held) = all.split_at(80);
    let fit_records = simulate(&m, fit, &e, sigma, &mut rng);
    let held_records = simulate(&m, held, &e, sigma, &mut rng);
    let dir = scratch("identify_validate");
    let machine = write(&dir, "xyz3.yaml", XYZ);
    let csv = |records: &[Measurement]| records_csv(records, &["x", "y"], &["tx", "ty", "tz"]);
    let fit_csv = write(&dir, "fit.csv", &csv(&fit_records));
    let held_csv = write(&dir, "held.csv", &csv(&held_records));
    let args = [
        "identify",
        machine.to_str().unwrap(),
        "--measurements",
        fit_csv.to_str().unwrap(),
        "--validate",
        held_csv.to_str().unwrap(),
    ];
    let doc = ok_json(&[&args[..], &["--format", "json"]].concat());
    let v = &doc["validation"];
    assert_eq!(v["file"], held_csv.to_str().unwrap());
    assert_eq!(
        (v["measurements"].as_u64(), v["rows"].as_u64()),
        (Some(40), Some(120))
    );
    // The prediction is that of the least-squares subset (the values
    // `--values-out` writes).
    let x: Vec<f64> = (names.iter())
        .map(|n| doc["subset"]["estimates"][n]["value"].as_f64().unwrap())
        .collect();
    let held: Vec<&Measurement> = held_records.iter().collect();
    let (before, after) = common::held_out_stats(&Exact::new(&m), &held, &x);
    for (key, expected, tolerance) in [("before", before, 1e-12), ("after", after, 1e-7)] {
        for (k, field) in ["mean", "max", "rms"].iter().enumerate() {
            let got = v[key][field].as_f64().unwrap();
            assert!(
                (got - expected[k]).abs() <= tolerance,
                "{key}.{field}: {got} vs the exact product's {}",
                expected[k]
            );
        }
    }
    // The correction takes the held-out error down to the noise
    // (σ per coordinate), from several times it.
    let rms_after = v["after"]["rms"].as_f64().unwrap();
    let rms_before = v["before"]["rms"].as_f64().unwrap();
    assert!(
        rms_after < 1.3 * sigma && rms_before > 3.0 * sigma,
        "{rms_before} → {rms_after}"
    );
    // The table says it in words.
    let table = ok_stdout(&args);
    assert!(
        table.contains("(40 measurements held out of the fit, 120 rows)"),
        "{table}"
    );
    assert!(table.contains("  after  mean |error|"), "{table}");
}
