//! Full-pose inverse kinematics (`Inverse::solve_pose`, `chain inverse` with
//! the `px,py,pz,r11..r33` header): the tool point and the whole tool
//! orientation, so a spin variable (`mu` of `cnc5_bevel`) is solved too and a
//! machine without one reaches only the orientations its axes produce.

use crate::common;

use chain_core::inverse::{wrap, Inverse, Status};
use chain_core::kinematics::Kinematics;
use chain_core::model::{JointKind, Machine};
use common::cli::{fails, ok_json, scratch_file, unwrapped};
use common::{example_path, load_example, random_q, Rng};

fn load(name: &str) -> (Machine, Kinematics, Vec<f64>) {
    let m = load_example(&format!("{name}.yaml"));
    let kin = Kinematics::from_machine(&m);
    let params = m
        .parameters
        .iter()
        .map(|p| p.value.expect("numeric"))
        .collect();
    (m, kin, params)
}

fn max_diff(a: &[[f64; 3]; 3], b: &[[f64; 3]; 3]) -> f64 {
    (0..3)
        .flat_map(|i| (0..3).map(move |j| (a[i][j] - b[i][j]).abs()))
        .fold(0.0, f64::max)
}

fn same(a: &[f64], b: &[f64], kinds: &[JointKind]) -> bool {
    a.iter().zip(b).zip(kinds).all(|((x, y), k)| {
        let d = if *k == JointKind::Rotary {
            wrap(x - y)
        } else {
            x - y
        };
        d.abs() < 1e-7
    })
}

/// 10,000 random full poses of a machine: every solution reproduces the
/// point (1e-10 · max(1, |p|)) and the rotation (1e-10), and the generating
/// values are among the solutions.
fn round_trip(name: &str, seed: u64) {
    let (m, kin, params) = load(name);
    let kinds: Vec<JointKind> = m.variables.iter().map(|v| v.kind).collect();
    let inverse = Inverse::for_machine(&m, &params, &[]).expect("solver");
    let mut rng = Rng::new(seed);
    let prev = vec![0.0; kinds.len()];
    for _ in 0..10_000 {
        let q = random_q(&kinds, &mut rng, 3.1);
        let pose = kin.pose(&q, &params);
        let s = inverse.solve_pose(pose.position, &pose.rotation, &prev);
        assert_eq!(s.status, Status::Ok, "{name} q = {q:?}");
        let scale = 1.0f64.max(pose.position.iter().map(|v| v.abs()).fold(0.0, f64::max));
        for sol in &s.solutions {
            let back = kin.pose(sol, &params);
            for i in 0..3 {
                assert!((back.position[i] - pose.position[i]).abs() <= 1e-10 * scale);
            }
            assert!(
                max_diff(&back.rotation, &pose.rotation) <= 1e-10,
                "{name} {sol:?}"
            );
        }
        assert!(
            s.solutions.iter().any(|sol| same(sol, &q, &kinds)),
            "{name}: generating values {q:?} not among {:?}",
            s.solutions
        );
    }
}

#[test]
fn full_pose_round_trip_cnc5_bevel_solves_the_cutter_spin() {
    // mu (the cutter head's spin) is free here: the full rotation fixes it.
    round_trip("cnc5_bevel", 41);
}

#[test]
fn full_pose_round_trip_head_head_bc() {
    round_trip("head_head_bc", 42);
}

#[test]
fn a_turn_about_the_tool_axis_is_unreachable_without_a_spin_axis() {
    // head_head_bc has no spindle-spin variable: turning the tool frame about
    // its own axis gives an orientation no axis values produce.
    let (m, kin, params) = load("head_head_bc");
    let inverse = Inverse::for_machine(&m, &params, &[]).expect("solver");
    let q = [10.0, -20.0, 30.0, 0.4, 0.7];
    let pose = kin.pose(&q, &params);
    let (s, c) = 0.3f64.sin_cos();
    // R · Rz(0.3): the same tool axis, the frame turned about it.
    let rz = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]];
    let r = pose.rotation;
    let turned: [[f64; 3]; 3] =
        std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| r[i][k] * rz[k][j]).sum()));
    let out = inverse.solve_pose(pose.position, &turned, &[0.0; 5]);
    assert_eq!(out.status, Status::Unreachable);
    assert!(out.solutions.is_empty());
    // The point-and-axis problem of the same pose is reachable.
    let axis = [turned[0][2], turned[1][2], turned[2][2]];
    assert_eq!(
        inverse.solve(pose.position, axis, &[0.0; 5]).status,
        Status::Ok
    );
}

#[test]
fn cli_reads_full_rotations() {
    let (m, kin, params) = load("cnc5_bevel");
    let q: Vec<f64> = m
        .variables
        .iter()
        .map(|v| match v.name.as_str() {
            "x" => 120.0,
            "y" => -40.0,
            "z" => 60.0,
            "mu" => 1.1,
            "B" => 0.3,
            "A" => -0.8,
            other => panic!("unexpected variable {other}"),
        })
        .collect();
    let pose = kin.pose(&q, &params);
    let r = pose.rotation;
    let file = example_path("cnc5_bevel.yaml");
    // Written with 17 significant digits, the row solves to the generating
    // values; written with 8 decimals (as CAM output often is) it is
    // orthonormal only to ~1e-8, is replaced by the nearest rotation and
    // solves within that rounding.
    for (name, digits, tolerance) in [
        ("rotation.csv", 17, 1e-8),
        ("rotation_8_digits.csv", 8, 1e-5),
    ] {
        let row: Vec<String> = pose
            .position
            .iter()
            .chain(r.iter().flatten())
            .map(|v| {
                if digits == 17 {
                    format!("{v:.17e}")
                } else {
                    format!("{v:.8}")
                }
            })
            .collect();
        let csv = scratch_file(
            name,
            &format!(
                "px,py,pz,r11,r12,r13,r21,r22,r23,r31,r32,r33\n{}\n",
                row.join(",")
            ),
        );
        let doc = ok_json(&[
            "inverse",
            file.to_str().unwrap(),
            "--pose",
            csv.to_str().unwrap(),
        ]);
        assert_eq!(doc["rows"][0]["status"], "ok", "{name}");
        let sols = doc["rows"][0]["solutions"].as_array().unwrap();
        assert!(
            sols.iter().any(|s| {
                ["x", "y", "z", "mu", "B", "A"]
                    .iter()
                    .zip([120.0, -40.0, 60.0, 1.1, 0.3, -0.8])
                    .all(|(k, want)| (s[*k].as_f64().unwrap() - want).abs() < tolerance)
            }),
            "{name}: {sols:?}"
        );
    }
    // A row that is not a rotation is refused with its line.
    let bad = scratch_file(
        "not_rotation.csv",
        "px,py,pz,r11,r12,r13,r21,r22,r23,r31,r32,r33\n0,0,0,1,0,0,0,1,0,0,0,1\n0,0,0,1,0,0,0,2,0,0,0,1\n",
    );
    let err = unwrapped(&fails(&[
        "inverse",
        file.to_str().unwrap(),
        "--pose",
        bad.to_str().unwrap(),
    ]));
    assert!(err.contains("not_rotation.csv:3"), "{err}");
    assert!(err.contains("is not a rotation"), "{err}");
}

#[test]
fn an_idle_spin_is_held_whatever_else_is_fixed() {
    // cnc5_bevel with B fixed: A and the three slides remain, and the cutter
    // spin mu (which moves neither the point nor the axis) is held at 0 — not
    // taken for a second rotary axis, which would make every row singular.
    let (m, kin, params) = load("cnc5_bevel");
    let index = |name: &str| m.variables.iter().position(|v| v.name == name).unwrap();
    let (b, mu) = (index("B"), index("mu"));
    let inverse = Inverse::for_machine(&m, &params, &[(b, 0.3)]).expect("solver");
    let mut q = vec![0.0; m.variables.len()];
    for (name, value) in [
        ("x", 10.0),
        ("y", 20.0),
        ("z", 30.0),
        ("B", 0.3),
        ("A", 0.5),
    ] {
        q[index(name)] = value;
    }
    let pose = kin.pose(&q, &params);
    let axis = [
        pose.rotation[0][2],
        pose.rotation[1][2],
        pose.rotation[2][2],
    ];
    let mut prev = vec![0.0; q.len()];
    prev[b] = 0.3;
    let s = inverse.solve(pose.position, axis, &prev);
    assert_eq!(s.status, Status::Ok);
    for sol in &s.solutions {
        assert_eq!(sol[mu], 0.0);
        assert_eq!(sol[b], 0.3);
        let back = kin.pose(sol, &params);
        for i in 0..3 {
            assert!((back.position[i] - pose.position[i]).abs() < 1e-9);
        }
    }
    assert!(s
        .solutions
        .iter()
        .any(|sol| (sol[index("A")] - 0.5).abs() < 1e-9));
}

/// A pose of neither 6 nor 12 values is a refusal, not a panic, before any
/// row is read; a bad row is named by its index.
#[test]
fn pose_widths_other_than_6_and_12_are_refused() {
    use chain::ops::inverse::{pose_rows, PoseError, PoseRow};
    for width in [0, 5, 7, 11, 13] {
        let flat = vec![1.0; 2 * width];
        let (row, e) = pose_rows(&flat, width).unwrap_err();
        assert_eq!((row, e.clone()), (None, PoseError::Width { found: width }));
        assert_eq!(
            e.to_string(),
            format!(
                "a pose has 6 values (px, py, pz, i, j, k) or 12 (px, py, pz, r11 … r33), found {width}"
            )
        );
        assert!(matches!(
            PoseRow::from_values(None, &flat[..width]),
            Err(PoseError::Width { found }) if found == width
        ));
    }
    let rows = pose_rows(
        &[0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 2.0, 3.0, 0.0, 0.0, 0.0],
        6,
    );
    assert!(matches!(rows, Err((Some(1), PoseError::ZeroAxis))));
    assert_eq!(
        pose_rows(&[0.0, 0.0, 0.0, 0.0, 0.0, 1.0], 6).unwrap().len(),
        1
    );
}
