//! Forward kinematics from the symbolic engine (`chain_core::kinematics`)
//! against the independent numeric product of `tests/it/common` (spec section 1,
//! full rigid transforms):
//!
//! - the pose equals `R_wt(q, 0)`, `T_wt(q, 0)·tool_point` (1e-12 relative);
//! - the exact Jacobian (order-1 jets) equals a 5-point central difference of
//!   the numeric pose: `∂p/∂q_k` and `ω_k = vee(∂R/∂q_k · Rᵀ)` (1e-7 relative
//!   to the machine's length scale; the difference's truncation error with
//!   h = 1e-3 is ~1e-12·scale, its rounding ~1e-13·scale/h);
//! - the Taylor series of the pose along a motion converges to the exact pose
//!   with error O(t^{n+1}).
//!
//! Every example machine, at random points of a ±π / ±500 mm box.

#![allow(clippy::needless_range_loop)]

use crate::common;

use chain_core::jet::Jet;
use chain_core::kinematics::Kinematics;
use chain_core::model::{JointKind, Machine};
use common::{load_example, Exact, Rng};

const MACHINES: [&str; 5] = [
    "gantry_grinder.yaml",
    "internal_grinder.yaml",
    "cnc5_bevel.yaml",
    "ac_trunnion.yaml",
    "head_head_bc.yaml",
];

fn random_q(machine: &Machine, rng: &mut Rng) -> Vec<f64> {
    machine
        .variables
        .iter()
        .map(|v| match v.kind {
            JointKind::Rotary => rng.range(-std::f64::consts::PI, std::f64::consts::PI),
            JointKind::Prismatic => rng.range(-500.0, 500.0),
        })
        .collect()
}

#[test]
fn pose_equals_the_numeric_product() {
    let mut rng = Rng::new(11);
    for file in MACHINES {
        let machine = load_example(file);
        let exact = Exact::new(&machine);
        let params = exact.file_parameters();
        let kin = Kinematics::from_machine(&machine);
        for _ in 0..50 {
            let q = random_q(&machine, &mut rng);
            let pose = kin.pose(&q, &params);
            let (r, p) = exact.nominal(&q, &params);
            let scale = 1.0 + p.iter().map(|v| v.abs()).fold(0.0, f64::max);
            for i in 0..3 {
                assert!((pose.position[i] - p[i]).abs() <= 1e-12 * scale, "{file}");
                for j in 0..3 {
                    assert!((pose.rotation[i][j] - r[i][j]).abs() <= 1e-13, "{file}");
                }
            }
        }
    }
}

#[test]
fn jacobian_equals_central_differences_of_the_numeric_pose() {
    let mut rng = Rng::new(12);
    let h = 1e-3;
    for file in MACHINES {
        let machine = load_example(file);
        let exact = Exact::new(&machine);
        let params = exact.file_parameters();
        let kin = Kinematics::from_machine(&machine);
        let mut worst = 0.0f64;
        for _ in 0..30 {
            let q = random_q(&machine, &mut rng);
            let jac = kin.jacobian(&q, &params);
            let (r, p) = exact.nominal(&q, &params);
            let scale = 1.0 + p.iter().map(|v| v.abs()).fold(0.0, f64::max) + 500.0;
            for k in 0..q.len() {
                let at = |d: f64| {
                    let mut qq = q.clone();
                    qq[k] += d;
                    exact.nominal(&qq, &params)
                };
                let (r1, p1) = at(h);
                let (r_1, p_1) = at(-h);
                let (r2, p2) = at(2.0 * h);
                let (r_2, p_2) = at(-2.0 * h);
                let five = |f2: f64, f1: f64, f_1: f64, f_2: f64| {
                    (-f2 + 8.0 * f1 - 8.0 * f_1 + f_2) / (12.0 * h)
                };
                let mut dr = [[0.0; 3]; 3];
                for i in 0..3 {
                    let dp = five(p2[i], p1[i], p_1[i], p_2[i]);
                    worst = worst.max((jac[k][i] - dp).abs() / scale);
                    assert!(
                        (jac[k][i] - dp).abs() <= 1e-7 * scale,
                        "{file} d p{i}/d q{k}"
                    );
                    for j in 0..3 {
                        dr[i][j] = five(r2[i][j], r1[i][j], r_1[i][j], r_2[i][j]);
                    }
                }
                // W = dR Rᵀ is skew; ω = vee(W).
                let w = |a: usize, b: usize| (0..3).map(|m| dr[a][m] * r[b][m]).sum::<f64>();
                let omega = [w(2, 1), w(0, 2), w(1, 0)];
                for i in 0..3 {
                    assert!(
                        (jac[k][3 + i] - omega[i]).abs() <= 1e-8,
                        "{file} ω{i} of q{k}"
                    );
                }
            }
        }
        eprintln!("{file}: worst relative Jacobian difference {worst:.1e}");
    }
}

#[test]
fn pose_series_converges_with_the_expected_order() {
    // Along q(t) = q0 + v t the order-n Taylor polynomial of the pose differs
    // from the exact pose by O(t^{n+1}): halving t divides the error by about
    // 2^{n+1}.
    let machine = load_example("ac_trunnion.yaml");
    let exact = Exact::new(&machine);
    let params = exact.file_parameters();
    let kin = Kinematics::from_machine(&machine);
    let q0 = [10.0, 0.4, -1.1, 30.0, -20.0];
    let v = [5.0, 0.8, 1.3, -4.0, 2.0];
    let n = 6;
    let jets: Vec<Jet> = q0
        .iter()
        .zip(&v)
        .map(|(a, b)| Jet::variable(*a, *b, n))
        .collect();
    let series = kin.pose_series(&jets, &params);
    let error_at = |t: f64| {
        let q: Vec<f64> = q0.iter().zip(&v).map(|(a, b)| a + b * t).collect();
        let (_, p) = exact.nominal(&q, &params);
        (0..3)
            .map(|i| (series.position[i].eval(t) - p[i]).abs())
            .fold(0.0, f64::max)
    };
    let (e1, e2) = (error_at(0.1), error_at(0.05));
    let observed = (e1 / e2).log2();
    assert!(e1 > 0.0 && e1 < 1e-3, "{e1:e}");
    assert!(
        (observed - (n as f64 + 1.0)).abs() < 0.3,
        "observed order {observed}"
    );
}
