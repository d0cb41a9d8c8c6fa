//! Seed 004 (Fan et al. 2020, CNC internal cylindrical compound grinder): the
//! model derived from `examples/machines/internal_grinder.yaml` against the
//! paper's printed geometric error model E_x, E_y, E_z (Section 4.3, Eq. 3).
//!
//! Findings (docs/errata.md, "Seed 004"):
//! - E_y is printed correctly: it equals the derived model term by term, for
//!   any values of q2, q5, L, r.
//! - E_z's first-order part is correct, but it keeps two second-order products,
//!   δ_x(z)·(ε_x1z + ε_y(x1)) and -δ_y(z)·ε_x(x1).
//! - E_x has a zero-order `+q5y`, a spurious `+δ_y(z)`, spurious terms in the
//!   x-rotations (-r(ε_x(x2)+ε_x(z)+ε_yz) - z(ε_x(x2)+ε_yz)) and in the
//!   z-rotations ((q5x - L)(ε_z(x2)+ε_z(z))) — all of them E_y's terms — and
//!   misses q5y·ε_z(x1) and q5y·ε_x1y.
//!
//! The paper's sensitivity shares (Section 5.2, Figures 3-5) are reproduced
//! with L = 100: E_y and E_z from the derived model, E_x only from the
//! printed (wrong) E_x.

// Matrix and component loops read best with explicit indices.
#![allow(clippy::needless_range_loop)]

use crate::common;

use chain_core::model::Machine;
use chain_core::ErrorModel;
use common::{close, load_example, Exact, Rng};

/// The 22 error parameters (Table 1) as named in the machine file.
const ERRORS: [&str; 22] = [
    "dx_x1", "dy_x1", "dz_x1", "ex_x1", "ey_x1", "ez_x1", "dx_x2", "dy_x2", "dz_x2", "ex_x2",
    "ey_x2", "ez_x2", "dx_z", "dy_z", "dz_z", "ex_z", "ey_z", "ez_z", "e_x1z", "e_x1y", "e_yz",
    "e_x2z",
];

/// Values of the 22 errors, indexed like [`ERRORS`].
#[derive(Debug, Clone, Copy)]
struct Errs([f64; 22]);

impl Errs {
    fn get(&self, name: &str) -> f64 {
        let i = ERRORS
            .iter()
            .position(|n| *n == name)
            .unwrap_or_else(|| panic!("not a seed-004 error: {name}"));
        self.0[i]
    }

    fn unit(name: &str) -> Errs {
        Errs(std::array::from_fn(|i| {
            f64::from(u8::from(ERRORS[i] == name))
        }))
    }

    fn zero() -> Errs {
        Errs([0.0; 22])
    }
}

/// Structural parameters (Section 4.2-4.3).
#[derive(Debug, Clone, Copy)]
struct Params {
    q2x: f64,
    q2y: f64,
    q2z: f64,
    q5x: f64,
    q5y: f64,
    q5z: f64,
    l: f64,
    r: f64,
}

impl Params {
    /// Section 5.2's case, with L = 100 (see the machine file).
    fn case() -> Params {
        Params {
            q2x: 200.0,
            q2y: 0.0,
            q2z: 0.0,
            q5x: 300.0,
            q5y: 0.0,
            q5z: 0.0,
            l: 100.0,
            r: 20.0,
        }
    }

    fn random(rng: &mut Rng) -> Params {
        Params {
            q2x: rng.range(-400.0, 400.0),
            q2y: rng.range(-100.0, 100.0),
            q2z: rng.range(-100.0, 100.0),
            q5x: rng.range(-400.0, 400.0),
            q5y: rng.range(-100.0, 100.0),
            q5z: rng.range(-100.0, 100.0),
            l: rng.range(0.0, 300.0),
            r: rng.range(5.0, 50.0),
        }
    }

    /// Values in `machine.parameters` order (R = 40 does not enter the model).
    fn values(&self, machine: &Machine) -> Vec<f64> {
        machine
            .parameters
            .iter()
            .map(|p| match p.name.as_str() {
                "q2x" => self.q2x,
                "q2y" => self.q2y,
                "q2z" => self.q2z,
                "q5x" => self.q5x,
                "q5y" => self.q5y,
                "q5z" => self.q5z,
                "L" => self.l,
                "r" => self.r,
                "R" => 40.0,
                other => panic!("unexpected parameter {other}"),
            })
            .collect()
    }
}

/// The printed E_x (Section 4.3), transcribed term by term.
fn ex_printed(x1: f64, x2: f64, z: f64, k: &Params, e: &Errs) -> f64 {
    let _ = (x1, x2);
    let g = |n: &str| e.get(n);
    g("dx_x2") - g("dx_x1")
        + g("dx_z")
        + g("dy_z")
        + k.q5y
        + k.q5z * (g("e_x2z") + g("ey_x2") + g("ey_z"))
        - k.r * (g("ex_x2") + g("ex_z") + g("e_yz"))
        + k.r * (g("e_x2z") + g("ey_x2") + g("ey_z"))
        - (g("e_x1z") + g("ey_x1")) * (k.q5z + k.r + z)
        - g("e_x1y") * k.q2y
        + g("e_x1z") * k.q2z
        - k.l * (g("ez_x2") + g("ez_z"))
        + k.q5x * (g("ez_x2") + g("ez_z"))
        - k.q5y * (g("ez_x2") + g("ez_z"))
        + z * (g("e_x2z") + g("ey_x2"))
        - z * (g("ex_x2") + g("e_yz"))
}

/// The printed E_y (Section 4.3).
fn ey_printed(x1: f64, x2: f64, z: f64, k: &Params, e: &Errs) -> f64 {
    let g = |n: &str| e.get(n);
    g("dy_x2") - g("dy_x1") + g("dy_z")
        - k.q5z * (g("ex_x2") + g("ex_z") + g("e_yz"))
        - k.r * (g("ex_x2") + g("ex_z") + g("e_yz"))
        + g("e_x1y") * k.q2x
        + g("e_x1y") * x1
        + g("ez_x1") * x1
        - (g("e_x1y") + g("ez_x1")) * (k.q5x - k.l + x2)
        + g("ex_x1") * (k.q5z + k.r + z)
        - k.l * (g("ez_x2") + g("ez_z"))
        + k.q5x * (g("ez_x2") + g("ez_z"))
        - z * (g("ex_x2") + g("e_yz"))
}

/// The printed E_z (Section 4.3), including its two second-order products.
fn ez_printed(x1: f64, x2: f64, z: f64, k: &Params, e: &Errs) -> f64 {
    let _ = z;
    let g = |n: &str| e.get(n);
    g("dz_x2") - g("dz_x1") + g("dz_z") + k.q5y * (g("ex_x2") + g("ex_z") + g("e_yz"))
        - k.q5x * (g("e_x2z") + g("ey_x2") + g("ey_z"))
        - g("e_x1z") * k.q2x
        - g("e_x1z") * x1
        - g("ey_x1") * x1
        + (g("e_x1z") + g("ey_x1")) * (g("dx_z") - k.l + k.q5x + x2)
        - g("ex_x1") * (g("dy_z") + k.q5y)
        + k.l * (g("e_x2z") + g("ey_x2") + g("ey_z"))
}

type Printed = fn(f64, f64, f64, &Params, &Errs) -> f64;
const PRINTED: [Printed; 3] = [ex_printed, ey_printed, ez_printed];

/// The first-order coefficient of the printed equation `c` for `name`:
/// E(unit) - E(0) (the products of two errors vanish on a unit vector).
fn printed_coefficient(c: usize, q: (f64, f64, f64), k: &Params, name: &str) -> f64 {
    let f = PRINTED[c];
    f(q.0, q.1, q.2, k, &Errs::unit(name)) - f(q.0, q.1, q.2, k, &Errs::zero())
}

/// Exactly what the derivation has that the printed first-order coefficients
/// lack (derived - printed), per component and error.
fn erratum(c: usize, q: (f64, f64, f64), k: &Params, name: &str) -> f64 {
    let z = q.2;
    match (c, name) {
        // E_x: δ_y(z) is printed but a y translation cannot move x.
        (0, "dy_z") => -1.0,
        // E_x: -r(ε_x(x2)+ε_x(z)+ε_yz) - z(ε_x(x2)+ε_yz) are printed (they are
        // E_y's terms); a rotation about x moves no point along x.
        (0, "ex_x2") | (0, "e_yz") => k.r + z,
        (0, "ex_z") => k.r,
        // E_x: (q5x - L)(ε_z(x2)+ε_z(z)) is printed (E_y's term); about z the
        // x-displacement is -ε·(y offset) = -q5y·ε, which is printed too.
        (0, "ez_x2") | (0, "ez_z") => k.l - k.q5x,
        // E_x: missing +q5y·ε_z(x1) and the q5y part of (q5y - q2y)·ε_x1y.
        (0, "ez_x1") | (0, "e_x1y") => k.q5y,
        _ => 0.0,
    }
}

fn grinder() -> Machine {
    load_example("internal_grinder.yaml")
}

/// Axis values in `machine.variables` order.
fn q_of(machine: &Machine, x1: f64, x2: f64, z: f64) -> Vec<f64> {
    machine
        .variables
        .iter()
        .map(|v| match v.name.as_str() {
            "x1" => x1,
            "x2" => x2,
            "z" => z,
            other => panic!("unexpected variable {other}"),
        })
        .collect()
}

fn random_axes(rng: &mut Rng) -> (f64, f64, f64) {
    (
        rng.range(-300.0, 100.0),
        rng.range(-100.0, 100.0),
        rng.range(-50.0, 150.0),
    )
}

const COMPONENTS: [&str; 3] = ["E_x", "E_y", "E_z"];

#[test]
fn the_machine_has_the_22_errors_of_table_1_and_the_case_parameters() {
    let m = grinder();
    let mut names: Vec<&str> = m.errors.iter().map(|e| e.name.as_str()).collect();
    names.sort_unstable();
    let mut expect = ERRORS.to_vec();
    expect.sort_unstable();
    assert_eq!(
        names, expect,
        "Table 1: 18 motion errors + 4 perpendicularities"
    );
    let value = |n: &str| m.parameters[m.parameter_index(n).unwrap()].value;
    // Section 5.2: (q2x, q2y, q2z) = (200, 0, 0), (q5x, q5y, q5z) = (300, 0, 0),
    // bore phi 80 (R = 40), wheel phi 40 (r = 20); L = 100 (machine file).
    assert_eq!(value("q2x"), Some(200.0));
    assert_eq!(value("q5x"), Some(300.0));
    assert_eq!(value("q5y"), Some(0.0));
    assert_eq!(value("r"), Some(20.0));
    assert_eq!(value("R"), Some(40.0));
    assert_eq!(value("L"), Some(100.0));
}

#[test]
fn nominal_grinding_point_is_the_tool_point_through_both_branches() {
    // {P_ideal}: wheel point {-L 0 r} through S03_s·S34_s·S45_p, seen from the
    // workpiece frame S01_s·S12_p: (x2 + q5x - L - x1 - q2x, q5y - q2y,
    // z + q5z + r - q2z).
    let m = grinder();
    let model = chain_core::compile(&m);
    let ex = Exact::new(&m);
    let mut rng = Rng::new(40);
    for _ in 0..50 {
        let k = Params::random(&mut rng);
        let (x1, x2, z) = random_axes(&mut rng);
        let q = q_of(&m, x1, x2, z);
        let p = k.values(&m);
        let pose = model.nominal(&ex.q_for(&model, &q), &ex.p_for(&model, &p));
        let expect = [
            x2 + k.q5x - k.l - x1 - k.q2x,
            k.q5y - k.q2y,
            z + k.q5z + k.r - k.q2z,
        ];
        for i in 0..3 {
            assert!(close(pose.position[i], expect[i], 1e-12, 1e-12));
        }
    }
}

#[test]
fn printed_model_against_derived_term_by_term() {
    let m = grinder();
    let model = chain_core::compile(&m);
    let ex = Exact::new(&m);
    let n = m.errors.len();
    let mut rng = Rng::new(41);
    for _ in 0..200 {
        // General parameters (not only the case's zeros) so that every
        // printed term is exercised.
        let k = Params::random(&mut rng);
        let (x1, x2, z) = random_axes(&mut rng);
        let s = ex.model_sensitivity(&model, &q_of(&m, x1, x2, z), &k.values(&m));
        for c in 0..3 {
            for name in ERRORS {
                let j = m.error_index(name).unwrap();
                let derived = s[c * n + j];
                let printed = printed_coefficient(c, (x1, x2, z), &k, name);
                let expect = erratum(c, (x1, x2, z), &k, name);
                assert!(
                    close(derived - printed, expect, 1e-11, 1e-9),
                    "{}: d/d{name} derived {derived}, printed {printed}, difference {} but the erratum says {expect}",
                    COMPONENTS[c],
                    derived - printed
                );
            }
        }
    }
}

#[test]
fn printed_e_y_is_exact() {
    // No erratum in E_y: derived == printed for every error, any parameters.
    let mut rng = Rng::new(42);
    for _ in 0..100 {
        let k = Params::random(&mut rng);
        let q = random_axes(&mut rng);
        for name in ERRORS {
            assert_eq!(erratum(1, q, &k, name), 0.0);
        }
    }
    let m = grinder();
    let model = chain_core::compile(&m);
    let ex = Exact::new(&m);
    let n = m.errors.len();
    let k = Params::random(&mut rng);
    let (x1, x2, z) = (-100.0, 0.0, 40.0);
    let s = ex.model_sensitivity(&model, &q_of(&m, x1, x2, z), &k.values(&m));
    let mut nonzero = 0;
    for name in ERRORS {
        let j = m.error_index(name).unwrap();
        let printed = printed_coefficient(1, (x1, x2, z), &k, name);
        assert!(close(s[n + j], printed, 1e-11, 1e-9), "{name}");
        nonzero += usize::from(printed != 0.0);
    }
    // δ_y ×3, ε_x ×4 (x1, x2, z, yz), ε_z ×3, ε_x1y: 11 terms.
    assert_eq!(nonzero, 11);
}

#[test]
fn full_printed_equations_against_the_derived_error() {
    // The whole printed expressions, second-order products and the stray
    // zero-order q5y included, against the derived first-order error
    // E = S·e (error()):
    //   E_x(derived) = E_x(printed) - q5y - δ_y(z) + r(ε_x(x2)+ε_x(z)+ε_yz)
    //                  + z(ε_x(x2)+ε_yz) - (q5x - L)(ε_z(x2)+ε_z(z))
    //                  + q5y(ε_z(x1) + ε_x1y)
    //   E_y(derived) = E_y(printed)
    //   E_z(derived) = E_z(printed) - δ_x(z)(ε_x1z + ε_y(x1)) + δ_y(z)ε_x(x1)
    let m = grinder();
    let model = chain_core::compile(&m);
    let ex = Exact::new(&m);
    let mut rng = Rng::new(43);
    for _ in 0..200 {
        let k = Params::random(&mut rng);
        let (x1, x2, z) = random_axes(&mut rng);
        let e = Errs(std::array::from_fn(|i| {
            if ERRORS[i].starts_with('d') {
                rng.range(-0.01, 0.01)
            } else {
                rng.range(-1e-4, 1e-4)
            }
        }));
        let e_m: Vec<f64> = m.errors.iter().map(|v| e.get(&v.name)).collect();
        let q = q_of(&m, x1, x2, z);
        let p = k.values(&m);
        let mut out = [0.0; 6];
        model.error(
            &ex.q_for(&model, &q),
            &ex.p_for(&model, &p),
            &ex.e_for(&model, &e_m),
            &mut out,
        );
        let g = |n: &str| e.get(n);
        let fix_x = -k.q5y - g("dy_z")
            + k.r * (g("ex_x2") + g("ex_z") + g("e_yz"))
            + z * (g("ex_x2") + g("e_yz"))
            - (k.q5x - k.l) * (g("ez_x2") + g("ez_z"))
            + k.q5y * (g("ez_x1") + g("e_x1y"));
        let fix_z = -g("dx_z") * (g("e_x1z") + g("ey_x1")) + g("dy_z") * g("ex_x1");
        let expect = [
            ex_printed(x1, x2, z, &k, &e) + fix_x,
            ey_printed(x1, x2, z, &k, &e),
            ez_printed(x1, x2, z, &k, &e) + fix_z,
        ];
        for c in 0..3 {
            assert!(
                close(out[c], expect[c], 1e-9, 1e-12),
                "{}: derived {} printed+erratum {}",
                COMPONENTS[c],
                out[c],
                expect[c]
            );
        }
        // The two second-order products of E_z are really there (and are
        // what separates it from a first-order model).
        assert!(fix_z != 0.0);
    }
}

/// Sensitivity coefficients C = S/ΣS (Eq. 5-6) of one component over the
/// 22 errors, largest first.
fn shares(coefficients: &[(String, f64)]) -> Vec<(String, f64)> {
    let total: f64 = coefficients.iter().map(|(_, s)| s.abs()).sum();
    let mut v: Vec<(String, f64)> = coefficients
        .iter()
        .map(|(n, s)| (n.clone(), s.abs() / total))
        .collect();
    v.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
    v
}

#[test]
fn section_5_2_sensitivity_shares_fix_l_at_100() {
    // Section 5.2: at (x1, x2, z) = (-100, 0, 40) with the case parameters,
    // "x direction: ε_z(x2), ε_z(z) ... nearly 25 %"; "y direction: ε_z(x1),
    // ε_z(x2), ε_z(z) ... 29 %, 20 %, 20 %"; "z direction: ε_y(x1), ε_y(x2),
    // ε_y(z), ε_x2z ... 30 %, 20 %, 20 %, 20 %".
    let m = grinder();
    let model = chain_core::compile(&m);
    let ex = Exact::new(&m);
    let n = m.errors.len();
    let k = Params::case();
    let q = (-100.0, 0.0, 40.0);
    let s = ex.model_sensitivity(&model, &q_of(&m, q.0, q.1, q.2), &k.values(&m));
    let row = |c: usize| -> Vec<(String, f64)> {
        m.errors
            .iter()
            .enumerate()
            .map(|(j, e)| (e.name.clone(), s[c * n + j]))
            .collect()
    };
    // y: |S| = 300 (ε_z(x1): L - q5x + x1 - x2), 200, 200 (q5x - L) of 1003.
    let y = shares(&row(1));
    assert_eq!(y[0].0, "ez_x1");
    assert!(close(y[0].1, 300.0 / 1003.0, 1e-12, 0.0));
    assert_eq!((y[1].0.as_str(), y[2].0.as_str()), ("ez_x2", "ez_z"));
    assert!(close(y[1].1, 200.0 / 1003.0, 1e-12, 0.0));
    assert!((y[0].1 - 0.29).abs() < 0.01 && (y[1].1 - 0.20).abs() < 0.01);
    // z: 300, 200, 200, 200 of 1003.
    let z = shares(&row(2));
    assert_eq!(z[0].0, "ey_x1");
    assert!(close(z[0].1, 300.0 / 1003.0, 1e-12, 0.0));
    let mut next: Vec<&str> = z[1..4].iter().map(|(n, _)| n.as_str()).collect();
    next.sort_unstable();
    assert_eq!(next, ["e_x2z", "ey_x2", "ey_z"]);
    for (_, c) in &z[1..4] {
        assert!(close(*c, 200.0 / 1003.0, 1e-12, 0.0));
    }
    assert!((z[0].1 - 0.30).abs() < 0.01);
    // x, printed E_x: ε_z(x2), ε_z(z) each |q5x - L| = 200 of 804 = 24.9 %.
    let printed_x: Vec<(String, f64)> = ERRORS
        .iter()
        .map(|name| (name.to_string(), printed_coefficient(0, q, &k, name)))
        .collect();
    let x_printed = shares(&printed_x);
    assert_eq!(
        (x_printed[0].0.as_str(), x_printed[1].0.as_str()),
        ("ez_x2", "ez_z")
    );
    assert!(close(x_printed[0].1, 200.0 / 804.0, 1e-12, 0.0));
    // x, derived: ε_z(x2), ε_z(z) do not enter E_x at all (q5y = 0); the
    // largest are ε_y(x1), ε_y(x2), ε_x1z, ε_x2z with |S| = q5z + r + z = 60
    // of 263 (22.8 % each).
    let x = shares(&row(0));
    let ez_x2 = x.iter().find(|(n, _)| n == "ez_x2").unwrap().1;
    assert_eq!(ez_x2, 0.0);
    let mut top: Vec<&str> = x[..4].iter().map(|(n, _)| n.as_str()).collect();
    top.sort_unstable();
    assert_eq!(top, ["e_x1z", "e_x2z", "ey_x1", "ey_x2"]);
    assert!(close(x[0].1, 60.0 / 263.0, 1e-12, 0.0));
    // Other L values break the paper's z shares: at L = 30 ε_y(x1) is 27.3 %.
    let mut k30 = k;
    k30.l = 30.0;
    let s30 = ex.model_sensitivity(&model, &q_of(&m, q.0, q.1, q.2), &k30.values(&m));
    let z30 = shares(
        &m.errors
            .iter()
            .enumerate()
            .map(|(j, e)| (e.name.clone(), s30[2 * n + j]))
            .collect::<Vec<_>>(),
    );
    assert!(close(z30[0].1, 370.0 / 1353.0, 1e-12, 0.0));
}

#[test]
fn exact_product_confirms_the_derived_model() {
    // Independent numeric check (tests/it/common): finite differences of the full
    // 4×4 product [S01]_p[S01]_pe[S01]_s[S01]_se… with exact rigid error
    // transforms, at the case point and at random points and parameters.
    let m = grinder();
    let model = chain_core::compile(&m);
    let ex = Exact::new(&m);
    let mut rng = Rng::new(44);
    let mut points = vec![(Params::case(), (-100.0, 0.0, 40.0))];
    for _ in 0..50 {
        points.push((Params::random(&mut rng), random_axes(&mut rng)));
    }
    for (k, (x1, x2, z)) in points {
        let q = q_of(&m, x1, x2, z);
        let p = k.values(&m);
        if let Err(msg) = ex.check_sensitivity(&model, &q, &p, 1e-6, 1e-9) {
            panic!("{msg}");
        }
        // At tiny error values the exact product and the first-order model
        // agree to second order: |E_exact - S·e| ~ |v|·|e|² ≪ |S·e|.
        let e: Vec<f64> = m
            .errors
            .iter()
            .map(|v| {
                if v.name.starts_with('d') {
                    rng.range(-1e-6, 1e-6)
                } else {
                    rng.range(-1e-8, 1e-8)
                }
            })
            .collect();
        let exact = ex.exact_error(&q, &p, &e);
        let mut first = [0.0; 6];
        model.error(
            &ex.q_for(&model, &q),
            &ex.p_for(&model, &p),
            &ex.e_for(&model, &e),
            &mut first,
        );
        for c in 0..3 {
            assert!(
                close(exact[c], first[c], 1e-4, 1e-12),
                "{}: exact {} first-order {}",
                COMPONENTS[c],
                exact[c],
                first[c]
            );
        }
        // And the exact product disagrees with the printed E_x wherever the
        // erratum terms are non-zero.
        let errs = Errs(std::array::from_fn(|i| {
            e[m.error_index(ERRORS[i]).unwrap()]
        }));
        let printed = ex_printed(x1, x2, z, &k, &errs) - k.q5y;
        let fix = (errs.get("ex_x2") + errs.get("e_yz")) * (k.r + z) + errs.get("ex_z") * k.r
            - errs.get("dy_z")
            + (k.l - k.q5x) * (errs.get("ez_x2") + errs.get("ez_z"))
            + k.q5y * (errs.get("ez_x1") + errs.get("e_x1y"));
        assert!(close(exact[0], printed + fix, 1e-4, 1e-12));
    }
}
