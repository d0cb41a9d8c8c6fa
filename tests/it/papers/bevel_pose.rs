//! Seed 002 (5-axis spiral-bevel-gear CNC machine, Figure 3): the printed
//! rotation L_pt(μ, φ, ψ) and position (O_p O_t)_p against the nominal pose of
//! `examples/machines/cnc5_bevel.yaml` (variables: B ≡ φ, A ≡ ψ, mu ≡ μ).
//!
//! Findings (docs/errata.md, "Seed 002"):
//! - L_pt is printed correctly; it is Rx(ψ)·Ry(φ)·Rz(μ). With T_wt =
//!   inv(P(workpiece))·P(tool) this needs the workpiece-side joints about -y
//!   (B) and -x (A): the paper's angles are the workpiece's rotations seen
//!   from the tool, opposite to the right-hand rotation of the table frames.
//! - (O_p O_t)_p's third row prints `+z cosψ cosφ`; the rigid-body product
//!   gives `-z cosψ cosφ`. The printed vector's (x, y, z) part is not even a
//!   rotation (its first and third columns are not orthogonal), and the
//!   paper's own inverse solution (L_x, L_y, L_z) inverts the corrected
//!   vector, not the printed one.
//! - The inverse solution prints `L_y = a4 cosψ + a34 sinψ`: `a4` is `a24`.

// Matrix and component loops read best with explicit indices.
#![allow(clippy::needless_range_loop)]

use crate::common;

use chain_core::model::Machine;
use chain_core::ErrorModel;
use common::{close, load_example, Exact, Rng};
use std::f64::consts::PI;

/// Axis values (x, y, z, μ, φ = B, ψ = A).
#[derive(Debug, Clone, Copy)]
struct Axes {
    x: f64,
    y: f64,
    z: f64,
    mu: f64,
    phi: f64,
    psi: f64,
}

impl Axes {
    fn random(rng: &mut Rng, angle_limit: f64) -> Axes {
        Axes {
            x: rng.range(-400.0, 400.0),
            y: rng.range(-400.0, 400.0),
            z: rng.range(-400.0, 400.0),
            mu: rng.range(-PI, PI),
            phi: rng.range(-angle_limit, angle_limit),
            psi: rng.range(-angle_limit, angle_limit),
        }
    }

    /// Values in `machine.variables` order.
    fn q(&self, machine: &Machine) -> Vec<f64> {
        machine
            .variables
            .iter()
            .map(|v| match v.name.as_str() {
                "x" => self.x,
                "y" => self.y,
                "z" => self.z,
                "mu" => self.mu,
                "B" => self.phi,
                "A" => self.psi,
                other => panic!("unexpected variable {other}"),
            })
            .collect()
    }
}

/// The printed L_pt^(C)(μ, φ, ψ): rotation from the tool frame to the blank.
fn l_pt(a: &Axes) -> [[f64; 3]; 3] {
    let (sm, cm) = a.mu.sin_cos();
    let (sf, cf) = a.phi.sin_cos();
    let (ss, cs) = a.psi.sin_cos();
    [
        [cm * cf, -sm * cf, sf],
        [ss * cm * sf + cs * sm, -ss * sf * sm + cs * cm, -ss * cf],
        [-cs * cm * sf + ss * sm, cs * sf * sm + ss * cm, cs * cf],
    ]
}

/// The printed (O_p O_t)_p^(C).
fn o_p_o_t_printed(a: &Axes, l: f64) -> [f64; 3] {
    let (sf, cf) = a.phi.sin_cos();
    let (ss, cs) = a.psi.sin_cos();
    [
        a.x * cf - a.z * sf - l,
        a.x * sf * ss + a.y * cs + a.z * ss * cf,
        -a.x * sf * cs + a.y * ss + a.z * cs * cf,
    ]
}

/// (O_p O_t)_p corrected: the third row's z term is -z cosψ cosφ, i.e.
/// Rx(ψ)·Ry(φ)·(x, y, -z) - (L, 0, 0).
fn o_p_o_t_corrected(a: &Axes, l: f64) -> [f64; 3] {
    let mut v = o_p_o_t_printed(a, l);
    v[2] -= 2.0 * a.z * a.psi.cos() * a.phi.cos();
    v
}

fn cnc5() -> Machine {
    load_example("cnc5_bevel.yaml")
}

fn parameter(m: &Machine, name: &str) -> f64 {
    m.parameters[m.parameter_index(name).unwrap()]
        .value
        .unwrap_or_else(|| panic!("{name} has no value"))
}

#[test]
fn the_machine_has_six_axes_and_over_forty_errors() {
    let m = cnc5();
    let mut vars: Vec<&str> = m.variables.iter().map(|v| v.name.as_str()).collect();
    vars.sort_unstable();
    assert_eq!(vars, ["A", "B", "mu", "x", "y", "z"]);
    // 6 error motions × 6 axes + 3 squareness + 4 location errors × 3 rotary
    // axes.
    assert_eq!(m.errors.len(), 51);
}

#[test]
fn nominal_rotation_is_the_printed_l_pt() {
    let m = cnc5();
    let model = chain_core::compile(&m);
    let ex = Exact::new(&m);
    let p = ex.file_parameters();
    let mut rng = Rng::new(20);
    for _ in 0..500 {
        let a = Axes::random(&mut rng, PI);
        let pose = model.nominal(&ex.q_for(&model, &a.q(&m)), &ex.p_for(&model, &p));
        let l = l_pt(&a);
        for i in 0..3 {
            for j in 0..3 {
                assert!(
                    close(pose.rotation[i][j], l[i][j], 1e-12, 1e-12),
                    "L_pt[{i}][{j}] at {a:?}: model {}, printed {}",
                    pose.rotation[i][j],
                    l[i][j]
                );
            }
        }
    }
}

#[test]
fn nominal_position_is_the_corrected_o_p_o_t() {
    let m = cnc5();
    let model = chain_core::compile(&m);
    let ex = Exact::new(&m);
    let p = ex.file_parameters();
    let l = parameter(&m, "L");
    let mut rng = Rng::new(21);
    for _ in 0..500 {
        let a = Axes::random(&mut rng, PI);
        let pose = model.nominal(&ex.q_for(&model, &a.q(&m)), &ex.p_for(&model, &p));
        let corrected = o_p_o_t_corrected(&a, l);
        let printed = o_p_o_t_printed(&a, l);
        for i in 0..3 {
            assert!(
                close(pose.position[i], corrected[i], 1e-12, 1e-9),
                "(O_p O_t)_p[{i}] at {a:?}: model {}, corrected {}",
                pose.position[i],
                corrected[i]
            );
        }
        // The printed vector differs from the model only in its third row,
        // by exactly +2 z cosψ cosφ.
        assert!(close(printed[0], pose.position[0], 1e-12, 1e-9));
        assert!(close(printed[1], pose.position[1], 1e-12, 1e-9));
        let d = printed[2] - pose.position[2];
        assert!(close(d, 2.0 * a.z * a.psi.cos() * a.phi.cos(), 1e-9, 1e-9));
    }
    // The exact numeric product (tests/it/common) agrees.
    for _ in 0..50 {
        let a = Axes::random(&mut rng, PI);
        let (r, pos) = ex.nominal(&a.q(&m), &p);
        let c = o_p_o_t_corrected(&a, l);
        let lp = l_pt(&a);
        for i in 0..3 {
            assert!(close(pos[i], c[i], 1e-12, 1e-9));
            for j in 0..3 {
                assert!(close(r[i][j], lp[i][j], 1e-12, 1e-12));
            }
        }
    }
}

#[test]
fn printed_o_p_o_t_is_not_a_rigid_motion_of_the_slides() {
    // (O_p O_t)_p = M·(x, y, z) - (L, 0, 0). For any chain of slides and
    // rotary tables M is a rotation up to axis signs, so its columns are
    // orthonormal. The printed M's first and third columns have the dot
    // product -2 sinφ cosφ cos²ψ; the corrected one's is 0.
    let mut rng = Rng::new(22);
    for _ in 0..200 {
        let a = Axes::random(&mut rng, PI);
        let col = |f: &dyn Fn(&Axes, f64) -> [f64; 3], k: usize| -> [f64; 3] {
            let mut unit = Axes {
                x: 0.0,
                y: 0.0,
                z: 0.0,
                ..a
            };
            match k {
                0 => unit.x = 1.0,
                1 => unit.y = 1.0,
                _ => unit.z = 1.0,
            }
            f(&unit, 0.0)
        };
        let dot = |u: [f64; 3], v: [f64; 3]| u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
        let (p1, p3) = (col(&o_p_o_t_printed, 0), col(&o_p_o_t_printed, 2));
        let expect = -2.0 * a.phi.sin() * a.phi.cos() * a.psi.cos().powi(2);
        assert!(close(dot(p1, p3), expect, 1e-12, 1e-15));
        let c: Vec<[f64; 3]> = (0..3).map(|k| col(&o_p_o_t_corrected, k)).collect();
        for i in 0..3 {
            for j in 0..3 {
                let want = if i == j { 1.0 } else { 0.0 };
                assert!(close(dot(c[i], c[j]), want, 1e-12, 1e-12));
            }
        }
    }
}

/// The paper's inverse solution (case 3, "knife tilting"): x, y, z, A, B from
/// the elements a_ij of the pose (a14, a24, a34 = (O_p O_t)_p; a13, a23, a33
/// from L_pt), with `a4` read as `a24`.
fn inverse(r: &[[f64; 3]; 3], p: [f64; 3], l: f64) -> [f64; 5] {
    let (a14, a24, a34) = (p[0], p[1], p[2]);
    let (a13, a23, a33) = (r[0][2], r[1][2], r[2][2]);
    let b = a13.asin();
    let a = -(a23 / a33).atan();
    let (sf, cf) = b.sin_cos();
    let (ss, cs) = a.sin_cos();
    let lx = (a14 + l) * cf - (a34 * cs - a24 * ss) * sf;
    let ly = a24 * cs + a34 * ss;
    let lz = -(a14 + l) * sf - (a34 * cs - a24 * ss) * cf;
    [lx, ly, lz, a, b]
}

#[test]
fn the_papers_inverse_solution_inverts_the_corrected_pose_only() {
    let m = cnc5();
    let model = chain_core::compile(&m);
    let ex = Exact::new(&m);
    let p = ex.file_parameters();
    let l = parameter(&m, "L");
    let mut rng = Rng::new(23);
    for _ in 0..500 {
        // A = -arctan(a23/a33) and B = arcsin(a13) return principal values:
        // keep |φ|, |ψ| < π/2.
        let a = Axes::random(&mut rng, 0.49 * PI);
        let pose = model.nominal(&ex.q_for(&model, &a.q(&m)), &ex.p_for(&model, &p));
        let inv = inverse(&pose.rotation, pose.position, l);
        let want = [a.x, a.y, a.z, a.psi, a.phi];
        for k in 0..5 {
            assert!(
                close(inv[k], want[k], 1e-9, 1e-9),
                "inverse[{k}] at {a:?}: {} vs {}",
                inv[k],
                want[k]
            );
        }
        // Fed the printed (O_p O_t)_p instead (a34 larger by
        // δ = 2 z cosψ cosφ), the same inverse misses x, y and z:
        //   x' - x = -δ cosψ sinφ,  y' - y = δ sinψ,  z' - z = -δ cosψ cosφ.
        let printed = o_p_o_t_printed(&a, l);
        let bad = inverse(&l_pt(&a), printed, l);
        let (sf, cf) = a.phi.sin_cos();
        let (ss, cs) = a.psi.sin_cos();
        assert!(close(
            bad[0] - a.x,
            -2.0 * a.z * cs * cs * cf * sf,
            1e-9,
            1e-8
        ));
        assert!(close(bad[1] - a.y, 2.0 * a.z * cs * cf * ss, 1e-9, 1e-8));
        assert!(close(
            bad[2] - a.z,
            -2.0 * a.z * cs * cs * cf * cf,
            1e-9,
            1e-8
        ));
    }
}
