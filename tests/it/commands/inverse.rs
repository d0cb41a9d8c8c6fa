//! Inverse kinematics: round trips forward(inverse(pose)) =
//! pose on random reachable poses, a singular and an unreachable pose, and the
//! `chain inverse` CLI (JSON shape, bad CSV).

use crate::common;

use std::path::{Path, PathBuf};

use chain_core::inverse::{wrap, Inverse, NewtonSolver, Solver, Status};
use chain_core::kinematics::Kinematics;
use chain_core::model::{JointKind, Machine};
use chain_core::{CompiledModel, ErrorModel};
use common::cli::{fails, ok_json, ok_stdout, scratch_file};
use common::{example_path, random_q, Rng};

fn machine_path(name: &str) -> PathBuf {
    example_path(&format!("{name}.yaml"))
}

fn load(name: &str) -> (Machine, CompiledModel, Vec<JointKind>, Vec<f64>) {
    let m = chain_core::load_file(&machine_path(name)).expect("load");
    let model = chain_core::compile(&m);
    let kinds = m.variables.iter().map(|v| v.kind).collect();
    let params = m
        .parameters
        .iter()
        .map(|p| p.value.expect("numeric"))
        .collect();
    (m, model, kinds, params)
}

fn axis_of(r: &[[f64; 3]; 3]) -> [f64; 3] {
    [r[0][2], r[1][2], r[2][2]]
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// `a - b` for a joint of `kind`, wrapped to (-π, π] for a rotary one.
fn joint_difference(kind: &JointKind, a: f64, b: f64) -> f64 {
    if *kind == JointKind::Rotary {
        wrap(a - b)
    } else {
        a - b
    }
}

/// Round trip on `n` random poses: the generating axis values are among the
/// solutions, and every solution gives the pose back to 1e-10 (the largest
/// position and axis errors are printed).
fn round_trip(name: &str, fixed: &[(&str, f64)], n: usize, seed: u64) {
    let (m, model, kinds, params) = load(name);
    let fixed: Vec<(usize, f64)> = fixed
        .iter()
        .map(|(v, x)| (m.variables.iter().position(|y| y.name == *v).unwrap(), *x))
        .collect();
    let solver = Solver::new(&model, &kinds, &params, &fixed).expect("closed form applies");
    let mut rng = Rng::new(seed);
    let (mut ep, mut ea) = (0.0f64, 0.0f64);
    let mut prev = vec![0.0; kinds.len()];
    for &(i, x) in &fixed {
        prev[i] = x;
    }
    for _ in 0..n {
        let mut q = prev.clone();
        for (i, k) in kinds.iter().enumerate() {
            if fixed.iter().any(|f| f.0 == i) {
                continue;
            }
            q[i] = match k {
                JointKind::Rotary => rng.range(-std::f64::consts::PI, std::f64::consts::PI),
                JointKind::Prismatic => rng.range(-500.0, 500.0),
            };
        }
        let pose = model.nominal(&q, &params);
        let axis = axis_of(&pose.rotation);
        let s = solver.solve(pose.position, axis, &prev);
        assert_eq!(s.status, Status::Ok, "q = {q:?}");
        assert!(!s.solutions.is_empty());
        let mut found = false;
        for sol in &s.solutions {
            assert!(sol.iter().all(|x| x.is_finite()));
            for (x, k) in sol.iter().zip(&kinds) {
                if *k == JointKind::Rotary {
                    assert!(*x > -std::f64::consts::PI && *x <= std::f64::consts::PI);
                }
            }
            let back = model.nominal(sol, &params);
            ep = ep.max(dist(back.position, pose.position));
            ea = ea.max(dist(axis_of(&back.rotation), axis));
            let same = sol
                .iter()
                .zip(&q)
                .zip(&kinds)
                .all(|((a, b), k)| joint_difference(k, *a, *b).abs() < 1e-7);
            found |= same;
        }
        assert!(found, "the generating axis values are among the solutions");
        // Branch order: the first is the nearest to the previous row.
        prev.clone_from(&s.solutions[0]);
    }
    eprintln!("{name}: max position error {ep:e}, max axis error {ea:e}");
    assert!(ep < 1e-10 && ea < 1e-10, "{ep:e} {ea:e}");
}

#[test]
fn round_trip_ac_trunnion() {
    round_trip("ac_trunnion", &[], 10_000, 1);
}

#[test]
fn round_trip_cnc5_bevel() {
    round_trip("cnc5_bevel", &[("mu", 0.0)], 10_000, 2);
}

#[test]
fn round_trip_head_head_bc() {
    round_trip("head_head_bc", &[], 10_000, 3);
}

#[test]
fn singular_pose_holds_the_free_angle() {
    let (m, model, kinds, params) = load("ac_trunnion");
    let solver = Solver::new(&model, &kinds, &params, &[]).unwrap();
    let c = m.variables.iter().position(|v| v.name == "C").unwrap();
    let mut prev = vec![0.0; kinds.len()];
    prev[c] = 0.75;
    // Tool axis along the C axis (A = 0).
    let s = solver.solve([10.0, 20.0, 30.0], [0.0, 0.0, 1.0], &prev);
    assert_eq!(s.status, Status::Singular);
    assert!(!s.solutions.is_empty());
    for sol in &s.solutions {
        assert!((sol[c] - 0.75).abs() < 1e-12);
        let back = model.nominal(sol, &params);
        assert!(dist(back.position, [10.0, 20.0, 30.0]) < 1e-10);
        assert!(dist(axis_of(&back.rotation), [0.0, 0.0, 1.0]) < 1e-10);
    }
}

#[test]
fn unreachable_pose() {
    // The A/C trunnion reaches every direction; cnc5_bevel with mu fixed does
    // too, so build a machine whose axis cone is limited: a B head tilted
    // 30 degrees from a vertical C axis reaches only axes within 60 degrees of z.
    let yaml = "machine: cone\nparameters: {}\nbodies:\n  bed: {}\n  x_slide: {parent: bed, joint: {type: prismatic, axis: +x, variable: x}}\n  y_slide: {parent: x_slide, joint: {type: prismatic, axis: +y, variable: y}}\n  z_slide: {parent: y_slide, joint: {type: prismatic, axis: +z, variable: z}}\n  c_head: {parent: z_slide, joint: {type: rotary, axis: +z, variable: C}}\n  b_head: {parent: c_head, rotation: [{about: x, angle: 30deg}], joint: {type: rotary, axis: +z, variable: B}}\n  tool: {parent: b_head, rotation: [{about: x, angle: 30deg}]}\nworkpiece: bed\ntool: tool\n";
    let m = match chain_core::load_str(yaml, "cone.yaml") {
        Ok(m) => m,
        Err(e) => panic!("{e:?}"),
    };
    let model = chain_core::compile(&m);
    let kinds: Vec<JointKind> = m.variables.iter().map(|v| v.kind).collect();
    let solver = Solver::new(&model, &kinds, &[], &[]).unwrap();
    let prev = vec![0.0; kinds.len()];
    let s = solver.solve([1.0, 2.0, 3.0], [0.0, 0.0, -1.0], &prev);
    assert_eq!(s.status, Status::Unreachable);
    assert!(s.solutions.is_empty());
    // A reachable direction of the same machine still solves.
    let s = solver.solve([1.0, 2.0, 3.0], [0.5, 0.0, 0.8660254037844386], &prev);
    assert_ne!(s.status, Status::Unreachable);
}

/// The arguments of `chain inverse <machine> --pose <poses>` and `extra`.
fn inverse_args<'a>(machine: &'a Path, poses: &'a Path, extra: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec![
        "inverse",
        machine.to_str().unwrap(),
        "--pose",
        poses.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    args
}

#[test]
fn cli_json_shape() {
    let csv = scratch_file(
        "poses.csv",
        "px,py,pz,i,j,k\n10,20,30,0.6,0,0.8\n10,20,30,0,0,1\n",
    );
    let file = machine_path("cnc5_bevel");
    let v = ok_json(&inverse_args(&file, &csv, &["--fix", "mu=0"]));
    assert_eq!(v["machine"], "cnc5_bevel");
    let vars: Vec<&str> = v["variables"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_str().unwrap())
        .collect();
    assert_eq!(vars, ["x", "y", "mu", "z", "B", "A"]);
    let rows = v["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 2);
    for (k, r) in rows.iter().enumerate() {
        assert_eq!(r["row"], k + 1);
        assert_eq!(r["status"], "ok");
        let sols = r["solutions"].as_array().unwrap();
        assert!(!sols.is_empty());
        for s in sols {
            let o = s.as_object().unwrap();
            assert_eq!(o.keys().map(String::as_str).collect::<Vec<_>>(), vars);
            assert!(o.values().all(|x| x.as_f64().is_some_and(f64::is_finite)));
            assert_eq!(o["mu"], 0.0);
        }
    }
}

#[test]
fn cli_bad_csv_names_the_line() {
    let file = machine_path("ac_trunnion");
    for (name, text, needles) in [
        (
            "bad.csv",
            "px,py,pz,i,j,k\n1,2,3,0,0,1\n1,2,oops,0,0,1\n",
            [":3:", "oops"],
        ),
        (
            "header.csv",
            "x,y,z,i,j,k\n1,2,3,0,0,1\n",
            [":1:", "px,py,pz,i,j,k"],
        ),
    ] {
        let csv = scratch_file(name, text);
        let err = fails(&inverse_args(&file, &csv, &[]));
        for n in needles {
            assert!(err.contains(n), "{name}: `{n}` not in\n{err}");
        }
    }
}

#[test]
fn branch_selection_follows_a_smooth_path() {
    let (_, model, kinds, params) = load("ac_trunnion");
    let solver = Solver::new(&model, &kinds, &params, &[]).unwrap();
    // y, A, C, x, z along a path that crosses C = ±π, with A in [0.2, 1.2]
    // (away from the singular A = 0).
    let path = |t: f64| {
        vec![
            50.0 * t.sin(),
            0.7 + 0.5 * (3.0 * t).sin(),
            wrap(2.5 + 2.0 * t),
            -30.0 + 10.0 * t,
            20.0 * t.cos(),
        ]
    };
    let mut prev = path(0.0);
    for k in 0..=500 {
        let q = path(k as f64 * 0.01);
        let pose = model.nominal(&q, &params);
        let s = solver.solve(pose.position, axis_of(&pose.rotation), &prev);
        assert_eq!(s.status, Status::Ok);
        let first = &s.solutions[0];
        for ((a, b), kind) in first.iter().zip(&q).zip(&kinds) {
            let d = joint_difference(kind, *a, *b);
            assert!(d.abs() < 1e-8, "step {k}: {first:?} vs {q:?}");
        }
        prev.clone_from(first);
    }
}

#[test]
fn undetermined_spin_defaults_to_zero() {
    // Without --fix, the cutter spin mu (it moves neither the tool point nor
    // the tool axis) is held at 0.
    let (m, model, kinds, params) = load("cnc5_bevel");
    let solver = Solver::new(&model, &kinds, &params, &[]).expect("mu is held");
    let mu = m.variables.iter().position(|v| v.name == "mu").unwrap();
    let s = solver.solve([10.0, 20.0, 30.0], [0.6, 0.0, 0.8], &vec![0.0; kinds.len()]);
    assert_eq!(s.status, Status::Ok);
    assert!(s.solutions.iter().all(|q| q[mu] == 0.0));
}

#[test]
fn cli_csv_format() {
    let csv = scratch_file("poses_csv.csv", "px,py,pz,i,j,k\n10,20,30,0.6,0,0.8\n");
    let file = machine_path("ac_trunnion");
    let text = ok_stdout(&inverse_args(&file, &csv, &["--format", "csv"]));
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "row,status,solution,y,A,C,x,z");
    assert_eq!(lines.len(), 3, "{text}");
    assert!(lines[1].starts_with("1,ok,1,") && lines[2].starts_with("1,ok,2,"));
}

#[test]
fn cli_csv_unreachable_row_has_empty_values() {
    // The cone machine of `unreachable_pose`: -z is outside its axis cone.
    let yaml = "machine: cone\nparameters: {}\nbodies:\n  bed: {}\n  x_slide: {parent: bed, joint: {type: prismatic, axis: +x, variable: x}}\n  y_slide: {parent: x_slide, joint: {type: prismatic, axis: +y, variable: y}}\n  z_slide: {parent: y_slide, joint: {type: prismatic, axis: +z, variable: z}}\n  c_head: {parent: z_slide, joint: {type: rotary, axis: +z, variable: C}}\n  b_head: {parent: c_head, rotation: [{about: x, angle: 30deg}], joint: {type: rotary, axis: +z, variable: B}}\n  tool: {parent: b_head, rotation: [{about: x, angle: 30deg}]}\nworkpiece: bed\ntool: tool\n";
    let file = scratch_file("cone.yaml", yaml);
    let csv = scratch_file(
        "cone_poses.csv",
        "px,py,pz,i,j,k\n1,2,3,0,0,-1\n1,2,3,0.5,0,0.8660254037844386\n",
    );
    let text = ok_stdout(&inverse_args(&file, &csv, &["--format", "csv"]));
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "row,status,solution,x,y,z,C,B");
    assert_eq!(lines[1], "1,unreachable,,,,,,");
    assert!(lines[2].starts_with("2,ok,1,"), "{text}");
    let v = ok_json(&inverse_args(&file, &csv, &[]));
    assert_eq!(v["rows"][0]["status"], "unreachable");
    assert_eq!(v["rows"][0]["solutions"].as_array().map(Vec::len), Some(0));
}

#[test]
fn cli_solver_errors_name_the_machine_and_keep_their_code() {
    let csv = scratch_file("one_pose.csv", "px,py,pz,i,j,k\n10,20,30,0,0,1\n");
    let file = machine_path("cnc5_bevel");
    let mut extra = Vec::new();
    for v in ["x=0", "y=0", "z=0", "mu=0", "A=0", "B=0"] {
        extra.extend(["--fix", v]);
    }
    let err = fails(&inverse_args(&file, &csv, &extra));
    assert!(err.contains("chain::inverse::no_free_variable"), "{err}");
    let flat: String = err.split_whitespace().collect::<Vec<_>>().join(" ");
    assert!(
        flat.contains("machine `cnc5_bevel`: no free axis variable moves the tool point or"),
        "{err}"
    );
    assert!(flat.contains("hold fewer variables (--fix)"), "{err}");
}

/// Damped Newton with the exact Jacobian finds every closed-form branch.
fn newton_finds_every_closed_form_solution(name: &str, seed: u64) {
    let (m, model, kinds, params) = load(name);
    let closed = Solver::new(&model, &kinds, &params, &[]).expect("closed form");
    let newton = NewtonSolver::new(Kinematics::from_machine(&m), &params, &[]).expect("newton");
    let mut rng = Rng::new(seed);
    let prev = vec![0.0; kinds.len()];
    for _ in 0..100 {
        let q = random_q(&kinds, &mut rng, 3.0);
        let pose = model.nominal(&q, &params);
        let axis = axis_of(&pose.rotation);
        let a = closed.solve(pose.position, axis, &prev);
        let b = newton.solve(pose.position, axis, &prev);
        assert_eq!(a.status, Status::Ok);
        assert_eq!(b.status, Status::Ok, "{name} q = {q:?}");
        assert_eq!(a.solutions.len(), b.solutions.len(), "{name} q = {q:?}");
        for s in &a.solutions {
            let matched = b.solutions.iter().any(|t| {
                s.iter()
                    .zip(t)
                    .zip(&kinds)
                    .all(|((x, y), k)| joint_difference(k, *x, *y).abs() < 1e-7)
            });
            assert!(
                matched,
                "{name}: closed-form branch {s:?} not found by Newton"
            );
        }
    }
}

#[test]
fn newton_agrees_with_the_closed_form_ac_trunnion() {
    newton_finds_every_closed_form_solution("ac_trunnion", 21);
}

#[test]
fn newton_agrees_with_the_closed_form_head_head_bc() {
    newton_finds_every_closed_form_solution("head_head_bc", 22);
}

/// A chain the closed form does not cover: X and Y slides and three rotary
/// axes (C about z, then A about x, then B about y, each with an offset), so
/// the tool height comes from the angles.
const THREE_ROTARY: &str = "machine: xy_cab\nparameters: {arm: 120, tool: 80}\nbodies:\n  bed: {}\n  x_slide: {parent: bed, joint: {type: prismatic, axis: +x, variable: x}}\n  y_slide: {parent: x_slide, joint: {type: prismatic, axis: +y, variable: y}}\n  c_head: {parent: y_slide, joint: {type: rotary, axis: +z, variable: C}}\n  a_arm: {parent: c_head, offset: [0, 0, 300], joint: {type: rotary, axis: +x, variable: A}}\n  b_wrist: {parent: a_arm, offset: [0, arm, 0], joint: {type: rotary, axis: +y, variable: B}}\n  spindle: {parent: b_wrist, offset: [0, 0, -tool]}\nworkpiece: bed\ntool: spindle\n";

#[test]
fn newton_solves_a_chain_without_closed_form() {
    let m = chain_core::load_str(THREE_ROTARY, "xy_cab.yaml").unwrap_or_else(|e| panic!("{e:?}"));
    let params = [120.0, 80.0];
    let inverse = Inverse::for_machine(&m, &params, &[]).expect("solver");
    assert_eq!(inverse.method(), "newton");
    let kin = Kinematics::from_machine(&m);
    let kinds: Vec<JointKind> = m.variables.iter().map(|v| v.kind).collect();
    let mut rng = Rng::new(23);
    for _ in 0..200 {
        let q = random_q(&kinds, &mut rng, 3.0);
        let pose = kin.pose(&q, &params);
        let axis = axis_of(&pose.rotation);
        // Previous row near the generating values: the first solution is it.
        let prev: Vec<f64> = q.iter().map(|v| v + 1e-3).collect();
        let s = inverse.solve(pose.position, axis, &prev);
        assert_ne!(s.status, Status::Unreachable, "q = {q:?}");
        for sol in &s.solutions {
            let back = kin.pose(sol, &params);
            assert!(dist(back.position, pose.position) < 1e-10, "{sol:?}");
            assert!(dist(axis_of(&back.rotation), axis) < 1e-10, "{sol:?}");
        }
        let first = &s.solutions[0];
        for ((a, b), k) in first.iter().zip(&q).zip(&kinds) {
            let d = joint_difference(k, *a, *b);
            // 1e-6: near B = 0 this chain is ill-conditioned (the pose fixes
            // the values only to ~1e-7 at rounding-level residuals).
            assert!(d.abs() < 1e-6 * a.abs().max(1.0), "{first:?} vs {q:?}");
        }
    }
}

#[test]
fn newton_reports_a_singular_pose() {
    // head_head_bc with B = 0: the tool axis lies along C, whose angle is
    // then free.
    let (m, _, kinds, params) = load("head_head_bc");
    let newton = NewtonSolver::new(Kinematics::from_machine(&m), &params, &[]).expect("newton");
    let s = newton.solve([10.0, 20.0, 30.0], [0.0, 0.0, 1.0], &vec![0.0; kinds.len()]);
    assert_eq!(s.status, Status::Singular);
    assert!(!s.solutions.is_empty());
}

#[test]
fn cli_reports_the_newton_method() {
    let machine = scratch_file("xy_cab.yaml", THREE_ROTARY);
    let csv = scratch_file(
        "poses_newton.csv",
        "px,py,pz,i,j,k\n100,50,250,0.3,0.2,0.9\n",
    );
    let doc = ok_json(&inverse_args(&machine, &csv, &[]));
    assert_eq!(doc["method"], "newton");
    assert_eq!(doc["rows"][0]["status"], "ok");
    assert!(!doc["rows"][0]["solutions"].as_array().unwrap().is_empty());
}

#[test]
fn the_newton_search_gives_up_on_a_pose_at_its_budget_and_says_so() {
    use chain_core::inverse::STEPS_PER_POSE;
    // The Panda: seven rotary joints, a redundant arm, the damped-Newton
    // fallback. Row 1 is out of reach; row 2 is the arm's pose at zero.
    let file = common::example_file("robots/panda_mdh.yaml");
    let m = chain_core::load_file(&file).unwrap();
    let params: Vec<f64> = m.parameters.iter().map(|p| p.value.unwrap()).collect();
    let kin = Kinematics::from_machine(&m);
    let zero = kin.pose(&[0.0; 7], &params);
    let [x, y, z] = zero.position;
    let (i, j, k) = (
        zero.rotation[0][2],
        zero.rotation[1][2],
        zero.rotation[2][2],
    );
    let poses = scratch_file(
        "panda-poses.csv",
        &format!("px,py,pz,i,j,k\n100000,0,0,0,0,1\n{x},{y},{z},{i},{j},{k}\n"),
    );
    let out = common::cli::chain(&inverse_args(&file, &poses, &[]));
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["method"], "newton");
    let rows = v["rows"].as_array().unwrap();
    assert_eq!(rows[0]["status"], "unreachable");
    assert_eq!(rows[0]["stopped"], true, "{}", rows[0]);
    assert_ne!(rows[1]["status"], "unreachable");
    let stderr = String::from_utf8_lossy(&out.stderr);
    // (The reachable row stops too: a redundant arm's starts that do not
    // converge use up the budget before all 257 are tried.)
    assert!(
        stderr.contains(&format!(
            "warning: rows 1, 2: the damped-Newton search gave up after {STEPS_PER_POSE} iterations before trying every start"
        )),
        "{stderr}"
    );
    // The library's solution says so too, and a closed-form machine's
    // rows never do.
    let solver = Inverse::for_machine(&m, &params, &[]).unwrap();
    let s = solver.solve([1e5, 0.0, 0.0], [0.0, 0.0, 1.0], &[0.0; 7]);
    assert!(s.stopped && s.solutions.is_empty());
    let csv = scratch_file("poses-ok.csv", "px,py,pz,i,j,k\n10,20,30,0,0,1\n");
    let v = ok_json(&inverse_args(
        &machine_path("cnc5_bevel"),
        &csv,
        &["--fix", "mu=0"],
    ));
    assert!(v["rows"][0].get("stopped").is_none());
}
