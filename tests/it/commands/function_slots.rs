//! Function slots (measured-machines spec, section 1) through the derivation,
//! the runtime tape, the exports and the generated code, against independent
//! computations:
//!
//! - the basis functions against their closed forms, and the engine's exact
//!   polynomials (`basis_poly`) against the numeric recurrences
//!   (`BasisFn::value`) for every degree up to 12;
//! - the derived coefficients (through the compiled tape) against the finite
//!   difference of the exact numeric 4×4 product of `tests/it/common`, whose
//!   slot value is `Σ_k e_k·b_k(q)` from `BasisFn::value`, for every basis on
//!   prismatic and rotary axes, at random points;
//! - the matrix route (basis weights multiplied in after the transform
//!   product) against the differential-motion-matrix route (weights inside
//!   the product);
//! - closed forms by hand on a rotary table whose slot is a polynomial in the
//!   table's angle.

// Matrix and component loops read best with explicit indices.
#![allow(clippy::needless_range_loop)]

use crate::common;

use std::f64::consts::PI;

use chain_core::algebra::{basis_poly, Poly, Symbol};
use chain_core::model::{Basis, BasisFn, Component, Frame, JointKind, Machine, Slot};
use chain_core::ErrorModel;
use common::{load_example, with_function_slots, Exact, Rng};

// ---------------------------------------------------------------- basis values

/// `Σ |c_m · m(q)|` of a polynomial in one variable: the scale of the
/// rounding in evaluating its expanded form.
fn magnitude(p: &Poly, value: &impl Fn(Symbol) -> f64) -> f64 {
    p.terms()
        .iter()
        .map(|(m, c)| (c * m.eval(value)).abs())
        .sum()
}

#[test]
fn basis_values_equal_their_closed_forms() {
    let mut rng = Rng::new(12);
    for _ in 0..200 {
        let q = rng.range(-3.0, 1003.0);
        let range = [0.0, 1000.0];
        let t = (2.0 * q - 1000.0) / 1000.0;
        let p3 = BasisFn::Legendre { k: 3, range }.value(q);
        assert!(
            (p3 - (5.0 * t.powi(3) - 3.0 * t) / 2.0).abs() < 1e-14,
            "P_3({t})"
        );
        let p2 = BasisFn::Legendre { k: 2, range }.value(q);
        assert!((p2 - (3.0 * t * t - 1.0) / 2.0).abs() < 1e-14, "P_2({t})");
        let p4 = BasisFn::Legendre { k: 4, range }.value(q);
        let p4_closed = (35.0 * t.powi(4) - 30.0 * t * t + 3.0) / 8.0;
        assert!((p4 - p4_closed).abs() < 1e-14, "P_4({t})");
        let t2 = BasisFn::Chebyshev { k: 2, range }.value(q);
        assert!((t2 - (2.0 * t * t - 1.0)).abs() < 1e-14, "T_2({t})");
        let t3 = BasisFn::Chebyshev { k: 3, range }.value(q);
        assert!((t3 - (4.0 * t.powi(3) - 3.0 * t)).abs() < 1e-14, "T_3({t})");
        // Inside [lo, hi], T_k(t) = cos(k·acos t).
        if t.abs() <= 1.0 {
            let t7 = BasisFn::Chebyshev { k: 7, range }.value(q);
            assert!((t7 - (7.0 * t.acos()).cos()).abs() < 1e-12, "T_7({t})");
        }
        let a = rng.range(-PI, PI);
        let c2 = BasisFn::Cos(2).value(a);
        assert!((c2 - (2.0 * a.cos().powi(2) - 1.0)).abs() < 1e-15);
        let s2 = BasisFn::Sin(2).value(a);
        assert!((s2 - 2.0 * a.sin() * a.cos()).abs() < 1e-15);
        assert_eq!(BasisFn::Cos(0).value(a), 1.0);
        assert_eq!(BasisFn::Power(3).value(q), q * q * q);
    }
    // The ends of the range map to t = ±1: P_k(±1) = (±1)^k, T_k(±1) = (±1)^k.
    for k in 0..=12 {
        let range = [-300.0, 100.0];
        let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
        for b in [
            BasisFn::Legendre { k, range },
            BasisFn::Chebyshev { k, range },
        ] {
            assert!((b.value(100.0) - 1.0).abs() < 1e-13, "{b:?} at hi");
            assert!((b.value(-300.0) - sign).abs() < 1e-13, "{b:?} at lo");
        }
    }
}

#[test]
fn exact_basis_polynomials_equal_the_numeric_recurrences() {
    let mut rng = Rng::new(0xba5e);
    let mut worst: f64 = 0.0;
    for k in 0..=12u32 {
        let prismatic = [
            (BasisFn::Power(k), [-2.0, 2.0]),
            (
                BasisFn::Legendre {
                    k,
                    range: [0.0, 1000.0],
                },
                [0.0, 1000.0],
            ),
            (
                BasisFn::Legendre {
                    k,
                    range: [-1.0, 1.0],
                },
                [-1.0, 1.0],
            ),
            (
                BasisFn::Legendre {
                    k,
                    range: [-300.0, 100.0],
                },
                [-320.0, 120.0],
            ),
            (
                BasisFn::Chebyshev {
                    k,
                    range: [0.0, 1000.0],
                },
                [0.0, 1000.0],
            ),
            (
                BasisFn::Chebyshev {
                    k,
                    range: [-1.0, 1.0],
                },
                [-1.0, 1.0],
            ),
            (
                BasisFn::Chebyshev {
                    k,
                    range: [-300.0, 100.0],
                },
                [-320.0, 120.0],
            ),
        ];
        for (b, [lo, hi]) in prismatic {
            let poly = basis_poly(&b, 0);
            for _ in 0..50 {
                let q = rng.range(lo, hi);
                let value = |s: Symbol| match s {
                    Symbol::Var(0) => q,
                    _ => f64::NAN,
                };
                let (exact, numeric) = (poly.eval(&value), b.value(q));
                // The expanded form's rounding is relative to the size of its
                // terms (that of the recurrence is ~1e-16 of |b| ≤ 1 + …).
                let scale = magnitude(&poly, &value).max(1.0);
                let d = (exact - numeric).abs() / scale;
                worst = worst.max(d);
                assert!(
                    d < 1e-14,
                    "{b:?} at q = {q}: polynomial {exact}, recurrence {numeric} (scale {scale})"
                );
            }
        }
        let trig = [BasisFn::Cos(k), BasisFn::Sin(k.max(1))];
        for b in trig {
            let poly = basis_poly(&b, 3);
            // A polynomial in sin and cos of the variable, sin at most linear.
            assert!(poly
                .symbols()
                .iter()
                .all(|s| matches!(s, Symbol::Cos(3) | Symbol::Sin(3))));
            for _ in 0..50 {
                let a = rng.range(-PI, PI);
                let value = |s: Symbol| match s {
                    Symbol::Cos(3) => a.cos(),
                    Symbol::Sin(3) => a.sin(),
                    _ => f64::NAN,
                };
                let (exact, numeric) = (poly.eval(&value), b.value(a));
                assert!(
                    (exact - numeric).abs() < 1e-12,
                    "{b:?} at {a}: polynomial {exact}, cos/sin {numeric}"
                );
            }
        }
    }
    // The expanded forms are exact up to rounding (worst relative to the
    // size of the terms, printed for the record).
    println!("worst relative rounding of the expanded bases: {worst:e}");
}

#[test]
fn basis_polynomials_are_the_printed_closed_forms() {
    let text = |b: BasisFn| {
        basis_poly(&b, 0).to_text(&|s| match s {
            Symbol::Var(_) => "x".to_string(),
            Symbol::Cos(_) => "cos(A)".to_string(),
            Symbol::Sin(_) => "sin(A)".to_string(),
            Symbol::Param(_) => "?".to_string(),
        })
    };
    assert_eq!(text(BasisFn::Power(2)), "x^2");
    let unit = [-1.0, 1.0];
    assert_eq!(
        text(BasisFn::Legendre { k: 3, range: unit }),
        "2.5*x^3 - 1.5*x"
    );
    assert_eq!(text(BasisFn::Chebyshev { k: 2, range: unit }), "2*x^2 - 1");
    // t = x/500 - 1 on [0, 1000]: P_1 = 0.002 x - 1.
    assert_eq!(
        text(BasisFn::Legendre {
            k: 1,
            range: [0.0, 1000.0]
        }),
        "0.002*x - 1"
    );
    assert_eq!(text(BasisFn::Cos(2)), "2*cos(A)^2 - 1");
    assert_eq!(text(BasisFn::Sin(2)), "2*cos(A)*sin(A)");
    // sin 3A = sin A (4 cos² A − 1).
    assert_eq!(text(BasisFn::Sin(3)), "4*cos(A)^2*sin(A) - sin(A)");
}

// --------------------------------------------- derivation vs the exact product

/// The working range of each axis of the five-axis example machines.
fn axis_range(name: &str) -> [f64; 2] {
    match name {
        "x" | "y" | "z" => [-400.0, 400.0],
        _ => [-PI, PI],
    }
}

/// The gantry's ranges (seed 000, section 3.3).
fn gantry_range(name: &str) -> [f64; 2] {
    match name {
        "x" => [0.0, 1000.0],
        "y" => [-1500.0, 1500.0],
        _ => [600.0, 1400.0],
    }
}

/// One basis per kind of test: built per axis range.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    Powers,
    Legendre,
    Chebyshev,
    ChebyshevFrom1,
    Fourier,
}

fn basis(kind: Kind, range: [f64; 2]) -> Basis {
    match kind {
        Kind::Powers => Basis::Powers {
            powers: vec![0, 1, 3],
        },
        Kind::Legendre => Basis::Legendre {
            degree: 3,
            range,
            from: 0,
        },
        Kind::Chebyshev => Basis::Chebyshev {
            degree: 4,
            range,
            from: 0,
        },
        Kind::ChebyshevFrom1 => Basis::Chebyshev {
            degree: 2,
            range,
            from: 1,
        },
        Kind::Fourier => Basis::Fourier { harmonics: 2 },
    }
}

/// Every motion error of `m` as a function of `kind` (Fourier only on
/// rotary axes; prismatic axes keep powers there).
fn functionalize(m: &Machine, kind: Kind, range: &dyn Fn(&str) -> [f64; 2]) -> Machine {
    with_function_slots(m, |m, b, _, _| {
        let joint = m.bodies[b].joint.as_ref()?;
        let var = &m.variables[joint.variable];
        let kind = match (kind, var.kind) {
            (Kind::Fourier, JointKind::Prismatic) => Kind::Powers,
            (k, _) => k,
        };
        Some(basis(kind, range(&var.name)))
    })
}

fn random_q(m: &Machine, rng: &mut Rng, range: &dyn Fn(&str) -> [f64; 2]) -> Vec<f64> {
    m.variables
        .iter()
        .map(|v| {
            let [lo, hi] = range(&v.name);
            rng.range(lo, hi)
        })
        .collect()
}

/// Random error values, scaled so that every slot value stays small
/// (±0.01 linear, ±1e-4 angular, over the largest weight at any point).
fn random_e(m: &Machine, rng: &mut Rng, q: &[f64]) -> Vec<f64> {
    let ex = Exact::new(m);
    (0..m.errors.len())
        .map(|j| {
            let w = ex.weight(j, q).abs().max(1.0);
            match m.errors[j].kind {
                chain_core::model::ErrorKind::Linear => rng.range(-0.01, 0.01) / w,
                _ => rng.range(-1e-4, 1e-4) / w,
            }
        })
        .collect()
}

/// The compiled model of `m` against the exact product at `points` random
/// points: sensitivity (1e-6 relative, floor 1e-9 × length scale) and
/// `error = S·e`, `nominal`.
fn check_against_exact(m: &Machine, points: usize, range: &dyn Fn(&str) -> [f64; 2], seed: u64) {
    let model = chain_core::compile(m);
    assert_eq!(
        model.errors(),
        m.errors.iter().map(|e| e.name.as_str()).collect::<Vec<_>>()
    );
    let ex = Exact::new(m);
    let p = ex.file_parameters();
    let mut rng = Rng::new(seed);
    for _ in 0..points {
        let q = random_q(m, &mut rng, range);
        if let Err(msg) = ex.check_sensitivity(&model, &q, &p, 1e-6, 1e-9) {
            panic!("{}: {msg}", m.name);
        }
        let e = random_e(m, &mut rng, &q);
        if let Err(msg) = ex.check_error_and_nominal(&model, &q, &p, &e, 1e-10) {
            panic!("{}: {msg}", m.name);
        }
    }
}

const KINDS: [Kind; 5] = [
    Kind::Powers,
    Kind::Legendre,
    Kind::Chebyshev,
    Kind::ChebyshevFrom1,
    Kind::Fourier,
];

#[test]
fn prismatic_function_slots_match_the_exact_product() {
    let gantry = load_example("gantry_grinder.yaml");
    for kind in KINDS {
        if kind == Kind::Fourier {
            continue; // refused on prismatic joints
        }
        let m = functionalize(&gantry, kind, &gantry_range);
        assert_eq!(m.functions.len(), 18, "{kind:?}: 18 motion errors");
        check_against_exact(&m, 40, &gantry_range, 7);
    }
}

#[test]
fn rotary_function_slots_match_the_exact_product() {
    // Two rotary axes (A, C); powers, Legendre and Chebyshev slots there are
    // polynomials in the angle itself, Fourier slots in its sin and cos.
    let trunnion = load_example("ac_trunnion.yaml");
    for kind in KINDS {
        let m = functionalize(&trunnion, kind, &axis_range);
        assert_eq!(m.functions.len(), 30, "{kind:?}: 30 motion errors");
        check_against_exact(&m, 30, &axis_range, 11);
    }
    let cnc5 = load_example("cnc5_bevel.yaml");
    let m = functionalize(&cnc5, Kind::Legendre, &axis_range);
    check_against_exact(&m, 20, &axis_range, 13);
}

#[test]
fn mixed_slots_shared_functions_and_multiplicities_match_the_exact_product() {
    // Bases mixed per slot; a slot holding a function and a squareness term
    // (the gantry's x slide ez: ezx and Sxy); one function's coefficients in
    // two slots of its body, and an error twice in one slot (the derivation
    // groups errors by their slots: both must keep their multiplicity).
    let gantry = load_example("gantry_grinder.yaml");
    let mut k = 0;
    let mut m = with_function_slots(&gantry, |m, b, _, _| {
        k += 1;
        let var = &m.variables[m.bodies[b].joint.as_ref()?.variable];
        let kinds = [
            Kind::Powers,
            Kind::Legendre,
            Kind::Chebyshev,
            Kind::ChebyshevFrom1,
        ];
        (k % 5 != 0).then(|| basis(kinds[k % 4], gantry_range(&var.name)))
    });
    let x = m.body_index("x_slide").unwrap();
    let ez = &m.bodies[x].errors.slots[Slot::Ez.index()];
    assert!(ez.len() >= 2, "ez of the x slide holds a function and Sxy");
    let f = m.functions[0].clone();
    let dz = Slot::Dz.index();
    for (j, _) in &f.coefficients {
        m.bodies[x].errors.slots[dz].push(*j);
    }
    let again = m.bodies[x].errors.slots[Slot::Ex.index()][0];
    m.bodies[x].errors.slots[Slot::Ex.index()].push(again);
    check_against_exact(&m, 40, &gantry_range, 17);
    assert_routes_agree(&m);
}

// ------------------------------------------------------------ the two routes

/// The matrix route (weights multiplied in after the product, errors of one
/// slot derived once) and the differential-motion-matrix route (weights in
/// the product) give the same canonical polynomials bit for bit (`rel` = 0:
/// the same errors, monomials and coefficients), or as functions to `rel`:
/// every coefficient of their difference within `rel` of the frame's
/// largest coefficient (arbitrary fixed rotations leave round-off residues,
/// e.g. `3e-19·cos q·sin q`, that one route cancels and the other keeps).
fn assert_routes_agree_to(m: &Machine, rel: f64) -> usize {
    let mut compared = 0;
    for frame in [Frame::Tool, Frame::Workpiece] {
        let model = chain_core::derive_in(m, frame);
        let dmm = chain_core::dmm::derive_dmm(m, frame);
        for c in Component::ALL {
            let (a, b) = (&model.components[c.index()], &dmm[c.index()]);
            let show = |p: &Poly| p.to_text(&|s| model.symbol_name(s));
            if rel == 0.0 {
                let names = |v: &[(usize, Poly)]| v.iter().map(|(j, _)| *j).collect::<Vec<_>>();
                assert_eq!(names(a), names(b), "{} {frame:?} {}", m.name, c.name());
                for ((j, pa), (_, pb)) in a.iter().zip(b) {
                    assert!(
                        pa == pb,
                        "{} {frame:?} d{}/d{}:\n  matrix: {}\n  dmm:    {}",
                        m.name,
                        c.name(),
                        m.errors[*j].name,
                        show(pa),
                        show(pb)
                    );
                    compared += 1;
                }
                continue;
            }
            // The frame's largest coefficient over every component: a
            // component whose terms are all round-off (an orientation the
            // machine barely has) is measured against the model's scale,
            // not against its own residue.
            let scale = (model.components.iter().chain(dmm.iter()))
                .flat_map(|v| v.iter())
                .flat_map(|(_, p)| p.terms().iter().map(|(_, k)| k.abs()))
                .fold(0.0, f64::max);
            let get = |v: &[(usize, Poly)], j: usize| {
                v.iter()
                    .find(|(k, _)| *k == j)
                    .map(|(_, p)| p.clone())
                    .unwrap_or_default()
            };
            let mut errors: Vec<usize> = a.iter().chain(b).map(|(j, _)| *j).collect();
            errors.sort_unstable();
            errors.dedup();
            for j in errors {
                let (pa, pb) = (get(a, j), get(b, j));
                let worst = pa
                    .sub(&pb)
                    .terms()
                    .iter()
                    .map(|(_, k)| k.abs())
                    .fold(0.0, f64::max);
                assert!(
                    worst <= rel * scale,
                    "{} {frame:?} d{}/d{}:\n  matrix: {}\n  dmm:    {}",
                    m.name,
                    c.name(),
                    m.errors[j].name,
                    show(&pa),
                    show(&pb)
                );
                compared += 1;
            }
        }
    }
    compared
}

/// [`assert_routes_agree_to`] bit for bit.
fn assert_routes_agree(m: &Machine) -> usize {
    assert_routes_agree_to(m, 0.0)
}

#[test]
fn both_derivation_routes_agree_on_every_basis() {
    for (file, range) in [
        (
            "gantry_grinder.yaml",
            &gantry_range as &dyn Fn(&str) -> [f64; 2],
        ),
        ("ac_trunnion.yaml", &axis_range),
        ("cnc5_bevel.yaml", &axis_range),
        ("internal_grinder.yaml", &|_: &str| [-300.0, 150.0]),
    ] {
        let machine = load_example(file);
        for kind in KINDS {
            let m = functionalize(&machine, kind, range);
            let compared = assert_routes_agree(&m);
            assert!(compared > 100, "{file} {kind:?}: {compared} coefficients");
        }
    }
}

// ----------------------------------------------- a rotary table, by hand

/// A rotary table (about +z, variable `C`) carrying the workpiece, and a
/// fixed tool at `[L, 0, 0]` (L = 100) on the bed; the table's `dx` slot is
/// `F(C) = F_1·C + F_2·C²` and its `ez` slot a Legendre function of `C` on
/// [−π, π].
fn rotary_table() -> Machine {
    let yaml = "machine: rot\nparameters: {L: 100}\nbodies:\n  bed: {}\n  table: {parent: bed, joint: {type: rotary, axis: +z, variable: C}, errors: {dx: F, ez: G}}\n  tool: {parent: bed, offset: [L, 0, 0]}\nworkpiece: table\ntool: tool\n";
    let m = chain_core::load_str(yaml, "rot.yaml").expect("valid machine");
    with_function_slots(&m, |_, _, slot, _| {
        Some(match slot {
            Slot::Dx => Basis::Powers { powers: vec![1, 2] },
            _ => Basis::Legendre {
                degree: 2,
                range: [-PI, PI],
                from: 0,
            },
        })
    })
}

#[test]
fn rotary_table_with_a_polynomial_slot_by_hand() {
    // T_wt = inv(Rz(C)·E)·Trans(L): a table error E(dx, ez) moves the
    // workpiece, so the tool moves by −E relative to it:
    // p = −(dx, 0, 0) − ez × p0 with p0 = (L cos C, −L sin C, 0).
    // With dx = F_1 C + F_2 C² and ez = Σ G_k P_k(C/π):
    //   ∂px/∂F_k = −C^k, ∂px/∂G_k = −L sin C · P_k(C/π),
    //   ∂py/∂G_k = −L cos C · P_k(C/π), ∂oz/∂G_k = −P_k(C/π).
    let m = rotary_table();
    let names: Vec<&str> = m.errors.iter().map(|e| e.name.as_str()).collect();
    assert_eq!(names, ["F_1", "F_2", "G_0", "G_1", "G_2"]);
    let model = chain_core::derive(&m);
    let text = |c: Component, j: usize| model.coefficient(c, j).to_text(&|s| model.symbol_name(s));
    assert_eq!(text(Component::Px, 0), "-C");
    assert_eq!(text(Component::Px, 1), "-C^2");
    assert_eq!(text(Component::Py, 0), "0");
    assert_eq!(text(Component::Oz, 2), "-1");
    assert_eq!(text(Component::Px, 2), "-L*sin(C)");
    let compiled = chain_core::compile(&m);
    let n = compiled.errors().len();
    let mut s = vec![0.0; 6 * n];
    let l = 100.0;
    for c in [-3.0, -1.2, 0.4, 2.5] {
        compiled.sensitivity(&[c], &[l], &mut s);
        let t: f64 = c / PI;
        let p = [1.0, t, 1.5 * t * t - 0.5];
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * (1.0 + b.abs());
        assert!(close(s[0], -c), "dpx/dF_1 at C = {c}: {}", s[0]);
        assert!(close(s[1], -c * c), "dpx/dF_2 at C = {c}: {}", s[1]);
        for k in 0..3 {
            let j = 2 + k;
            assert!(close(s[j], -l * c.sin() * p[k]), "dpx/dG_{k}: {}", s[j]);
            assert!(
                close(s[n + j], -l * c.cos() * p[k]),
                "dpy/dG_{k}: {}",
                s[n + j]
            );
            assert!(close(s[5 * n + j], -p[k]), "doz/dG_{k}: {}", s[5 * n + j]);
        }
    }
    check_against_exact(&m, 20, &|_| [-PI, PI], 3);
    assert_routes_agree(&m);
}

#[test]
fn exports_show_functions_of_a_rotary_variable() {
    let m = rotary_table();
    let model = chain_core::derive(&m);
    let text = chain_core::export::to_text(&model);
    assert!(
        text.contains("functions (2):\n  F(C) = F_1*C + F_2*C^2  (powers [1, 2])\n"),
        "{text}"
    );
    assert!(
        text.contains(
            "  G(C) = G_0 + G_1*P_1(t) + G_2*P_2(t), t = 2*C/6.283185307179586  (legendre, degree 2, range [-3.141592653589793, 3.141592653589793])\n"
        ),
        "{text}"
    );
    assert!(
        text.contains("px = -C*F_1 - C^2*F_2 - L*sin(C)*G_0"),
        "{text}"
    );
    let tex = chain_core::export::to_latex(&model);
    assert!(
        tex.contains("F(C) &= \\mathit{F\\_1}\\, C + \\mathit{F\\_2}\\, C^{2} \\\\\n"),
        "{tex}"
    );
    assert!(tex.contains("\\frac{2C}{6.283185307179586}"), "{tex}");
    let json = serde_json::to_value(chain_core::export::to_json(&model)).unwrap();
    assert_eq!(
        json["functions"][0],
        serde_json::json!({
            "name": "F", "variable": "C", "basis": "powers", "powers": [1, 2],
            "coefficients": ["F_1", "F_2"], "basis_functions": ["C", "C^2"]
        })
    );
    let g = &json["functions"][1];
    assert_eq!(g["basis"], "legendre");
    assert_eq!(g["degree"], 2);
    assert_eq!(g["from"], 0);
    assert_eq!(g["range"], serde_json::json!([-PI, PI]));
    assert_eq!(g["coefficients"], serde_json::json!(["G_0", "G_1", "G_2"]));
    assert_eq!(g["basis_functions"][0], "1");
    assert_eq!(g["basis_functions"][1], format!("{}*C", 1.0 / PI));
    // The coefficients are ordinary errors in `errors` and `components`.
    assert_eq!(
        json["errors"],
        serde_json::json!(["F_1", "F_2", "G_0", "G_1", "G_2"])
    );
    assert_eq!(json["components"]["px"]["F_2"], "-C^2");
    // The keys come in the documented order, `functions` after `errors`.
    let keys: Vec<&String> = json.as_object().unwrap().keys().collect();
    assert_eq!(
        keys,
        [
            "machine",
            "frame",
            "variables",
            "parameters",
            "parameter_values",
            "errors",
            "functions",
            "nominal",
            "components"
        ]
    );
    // A machine without function slots has no `functions` key, line or row.
    let plain = chain_core::derive(&load_example("gantry_grinder.yaml"));
    let json = serde_json::to_value(chain_core::export::to_json(&plain)).unwrap();
    assert!(json.get("functions").is_none());
    assert!(!chain_core::export::to_text(&plain).contains("functions"));
}

#[test]
fn emitted_code_reads_a_rotary_variable_for_a_polynomial_slot() {
    let m = rotary_table();
    let model = chain_core::derive(&m);
    let code =
        chain_core::emit::emit_pretty(&model, &chain_core::emit::EmitOptions::for_model(&model));
    assert!(code.contains("let v_C = q[0];"), "{code}");
    assert!(
        code.contains("let (sin_C, cos_C) = q[0].sin_cos();"),
        "{code}"
    );
    assert!(code.contains("pub fn error_at("), "{code}");
    assert!(code.contains("F(C) = F_1*C + F_2*C^2"), "{code}");
    // Without function slots: no `error_at` (the generated code of every
    // machine without them is unchanged).
    let plain = chain_core::derive(&load_example("gantry_grinder.yaml"));
    let code =
        chain_core::emit::emit_pretty(&plain, &chain_core::emit::EmitOptions::for_model(&plain));
    assert!(!code.contains("error_at"));
}

// ----------------------------------------------------- machine files (loader)

/// Every basis of the spec in one machine file: a rotary table C on an X
/// slide, the tool on a Z slide; Chebyshev with and without `from`, and a
/// powers and a Legendre slot on the rotary axis.
const ALL_BASES: &str = "\
machine: all_bases
parameters: {L: 120}
bodies:
  bed: {}
  x_slide:
    parent: bed
    joint: {type: prismatic, axis: +x, variable: x}
    errors:
      dx: {name: EXX, basis: chebyshev, degree: 3, range: [0, 1000]}
      dy: {name: EYX, powers: [1, 2]}
      dz: {name: EZX, basis: legendre, degree: 3, range: [0, 1000]}
      ez: {name: ECX, basis: chebyshev, degree: 2, range: [0, 1000], from: 1}
    squareness: {ez: Sxy}
  c_table:
    parent: x_slide
    offset: [0, 0, 50]
    location_errors: {dx: EX0C, ey: EB0C}
    joint: {type: rotary, axis: +z, variable: C}
    errors:
      dx: {name: EXC, powers: [0, 1, 2]}
      dy: {name: EYC, basis: legendre, degree: 2, range: [-3.2, 3.2], from: 1}
      ex: {name: EAC, basis: fourier, harmonics: 2}
      ez: ECC
  z_slide:
    parent: bed
    joint: {type: prismatic, axis: -z, variable: z}
    errors: {dx: EXZ, ey: {name: EBZ, basis: legendre, degree: 2, range: [-100, 500]}}
  tool: {parent: z_slide, offset: [0, L, 0]}
workpiece: c_table
tool: tool
tool_point: [10, 0, L]
";

fn all_bases_range(name: &str) -> [f64; 2] {
    match name {
        "x" => [0.0, 1000.0],
        "z" => [-100.0, 500.0],
        _ => [-PI, PI],
    }
}

#[test]
fn machine_files_with_function_slots_match_the_exact_product() {
    let m = chain_core::load_str(ALL_BASES, "all_bases.yaml").unwrap_or_else(|d| panic!("{d}"));
    let names: Vec<&str> = m.errors.iter().map(|e| e.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "EXX_0", "EXX_1", "EXX_2", "EXX_3", "EYX_1", "EYX_2", "EZX_0", "EZX_1", "EZX_2",
            "EZX_3", "ECX_1", "ECX_2", "Sxy", "EX0C", "EB0C", "EXC_0", "EXC_1", "EXC_2", "EYC_1",
            "EYC_2", "EAC_0", "EAC_c1", "EAC_s1", "EAC_c2", "EAC_s2", "ECC", "EXZ", "EBZ_0",
            "EBZ_1", "EBZ_2"
        ]
    );
    assert_eq!(m.functions.len(), 8);
    for frame in [Frame::Tool, Frame::Workpiece] {
        let mut m = m.clone();
        m.frame = frame;
        check_against_exact(&m, 40, &all_bases_range, 23);
        assert!(assert_routes_agree(&m) > 100);
    }
    // The two example files.
    let legendre5 = load_example("legendre5.yaml");
    assert_eq!(legendre5.errors.len(), 131);
    assert_eq!(legendre5.functions.len(), 30);
    let range = |v: &str| match v {
        "A" => [-2.1, 2.1],
        "C" => [-PI, PI],
        _ => [-400.0, 400.0],
    };
    check_against_exact(&legendre5, 20, &range, 29);
    let spread = load_example("spread_along_axis.yaml");
    check_against_exact(&spread, 20, &gantry_range, 31);
}

#[test]
fn iso_names_reach_the_derived_model() {
    // `errors: iso` names the six component errors after the variable,
    // upper-cased (spec section 1), and they are the model's error names.
    let yaml = "machine: iso\nbodies:\n  bed: {}\n  x_slide: {parent: bed, joint: {type: prismatic, axis: +x, variable: x}, errors: iso}\n  table: {parent: bed, joint: {type: rotary, axis: +z, variable: c}, errors: iso}\nworkpiece: table\ntool: x_slide\ntool_point: [0, 0, 100]\n";
    let m = chain_core::load_str(yaml, "iso.yaml").unwrap_or_else(|d| panic!("{d}"));
    let json = serde_json::to_value(chain_core::export::to_json(&chain_core::derive(&m))).unwrap();
    assert_eq!(
        json["errors"],
        serde_json::json!([
            "EXX", "EYX", "EZX", "EAX", "EBX", "ECX", "EXC", "EYC", "EZC", "EAC", "EBC", "ECC"
        ])
    );
    assert!(json.get("functions").is_none());
    // In the (rotating) workpiece frame the x slide's EXX is seen along
    // Rz(-c)·x = (cos c, -sin c, 0); the table's own EXC moves the
    // workpiece, so the tool moves by -EXC relative to it.
    assert_eq!(json["components"]["px"]["EXX"], "cos(c)");
    assert_eq!(json["components"]["py"]["EXX"], "-sin(c)");
    assert_eq!(json["components"]["px"]["EXC"], "-1");
    check_against_exact(
        &m,
        10,
        &|v| if v == "x" { [0.0, 500.0] } else { [-PI, PI] },
        37,
    );
}

// ------------------------------------------------------------ random machines

use proptest::prelude::*;

/// One slot of a generated body: empty, a constant, or a function.
#[derive(Debug, Clone)]
enum GenSlot {
    Empty,
    Constant,
    /// Exponents as a bit set of 0..=4 (non-empty), written reversed if set.
    Powers(u8, bool),
    /// (Chebyshev instead of Legendre, degree, from, lo, width).
    Orthogonal(bool, u32, u32, f64, f64),
    /// Harmonics (rotary joints only; powers on prismatic ones).
    Fourier(u32),
}

#[derive(Debug, Clone)]
struct GenBody {
    parent: usize,
    offset: [f64; 3],
    rotation: Option<(usize, f64)>,
    /// (rotary, axis, negative)
    joint: Option<(bool, usize, bool)>,
    errors: [GenSlot; 6],
    location: [bool; 6],
}

#[derive(Debug, Clone)]
struct GenMachine {
    bodies: Vec<GenBody>,
    workpiece: usize,
    tool: usize,
    tool_point: [f64; 3],
    tool_frame: bool,
}

const SLOTS: [&str; 6] = ["dx", "dy", "dz", "ex", "ey", "ez"];
const AXES: [&str; 3] = ["x", "y", "z"];

impl GenMachine {
    fn yaml(&self) -> String {
        let n = self.bodies.len();
        let wp = self.workpiece % n;
        let mut tool = self.tool % n;
        if tool == wp {
            tool = (tool + 1) % n;
        }
        let mut y = String::from("machine: random_functions\nbodies:\n  b0: {}\n");
        for (b, body) in self.bodies.iter().enumerate().skip(1) {
            y.push_str(&format!("  b{b}:\n    parent: b{}\n", body.parent % b));
            let [ox, oy, oz] = body.offset;
            y.push_str(&format!("    offset: [{ox}, {oy}, {oz}]\n"));
            if let Some((axis, angle)) = body.rotation {
                y.push_str(&format!(
                    "    rotation: [{{about: {}, angle: {angle}}}]\n",
                    AXES[axis]
                ));
            }
            let location: Vec<String> = (0..6)
                .filter(|&s| body.location[s])
                .map(|s| format!("{}: l{b}{}", SLOTS[s], SLOTS[s]))
                .collect();
            if !location.is_empty() {
                y.push_str(&format!(
                    "    location_errors: {{{}}}\n",
                    location.join(", ")
                ));
            }
            let mut errors = Vec::new();
            for (s, slot) in body.errors.iter().enumerate() {
                let name = format!("F{b}{}", SLOTS[s]);
                let entry = match (slot, body.joint) {
                    (GenSlot::Empty, _) => continue,
                    (GenSlot::Constant, _) | (_, None) => format!("e{b}{}", SLOTS[s]),
                    (GenSlot::Powers(bits, reversed), _) => {
                        let mut p: Vec<String> =
                            (0..5).filter(|k| bits & (1 << k) != 0).map(|k| k.to_string()).collect();
                        if *reversed {
                            p.reverse();
                        }
                        format!("{{name: {name}, powers: [{}]}}", p.join(", "))
                    }
                    (GenSlot::Orthogonal(cheb, degree, from, lo, width), _) => format!(
                        "{{name: {name}, basis: {}, degree: {degree}, range: [{lo}, {}], from: {}}}",
                        if *cheb { "chebyshev" } else { "legendre" },
                        lo + width,
                        from.min(degree)
                    ),
                    (GenSlot::Fourier(h), Some((true, _, _))) => {
                        format!("{{name: {name}, basis: fourier, harmonics: {h}}}")
                    }
                    (GenSlot::Fourier(h), Some((false, _, _))) => {
                        format!("{{name: {name}, powers: [{}]}}", h % 5)
                    }
                };
                errors.push(format!("{}: {entry}", SLOTS[s]));
            }
            if let Some((rotary, axis, negative)) = body.joint {
                y.push_str(&format!(
                    "    joint: {{type: {}, axis: {}{}, variable: q{b}}}\n",
                    if rotary { "rotary" } else { "prismatic" },
                    if negative { "-" } else { "+" },
                    AXES[axis]
                ));
            }
            if !errors.is_empty() {
                y.push_str("    errors:\n");
                for e in errors {
                    y.push_str(&format!("      {e}\n"));
                }
            }
        }
        let [tx, ty, tz] = self.tool_point;
        y.push_str(&format!(
            "workpiece: b{wp}\ntool: b{tool}\ntool_point: [{tx}, {ty}, {tz}]\nframe: {}\n",
            if self.tool_frame { "tool" } else { "workpiece" }
        ));
        y
    }
}

fn gen_slot() -> impl Strategy<Value = GenSlot> {
    prop_oneof![
        2 => Just(GenSlot::Empty),
        1 => Just(GenSlot::Constant),
        2 => (1u8..32, any::<bool>()).prop_map(|(b, r)| GenSlot::Powers(b, r)),
        2 => (any::<bool>(), 0u32..5, 0u32..3, -500i32..500, 10i32..1000).prop_map(
            |(c, d, f, lo, w)| GenSlot::Orthogonal(c, d, f, f64::from(lo), f64::from(w))
        ),
        2 => (0u32..4).prop_map(GenSlot::Fourier),
    ]
}

fn gen_body() -> impl Strategy<Value = GenBody> {
    (
        any::<usize>(),
        [-300i32..300, -300i32..300, -300i32..300],
        prop::option::weighted(0.3, (0usize..3, -3.0f64..3.0)),
        prop::option::weighted(0.85, (any::<bool>(), 0usize..3, any::<bool>())),
        [
            gen_slot(),
            gen_slot(),
            gen_slot(),
            gen_slot(),
            gen_slot(),
            gen_slot(),
        ],
        any::<[bool; 6]>(),
    )
        .prop_map(
            |(parent, offset, rotation, joint, errors, location)| GenBody {
                parent,
                offset: offset.map(f64::from),
                rotation,
                joint,
                errors,
                location,
            },
        )
}

fn gen_machine() -> impl Strategy<Value = GenMachine> {
    (
        prop::collection::vec(gen_body(), 2..=6),
        0usize..6,
        0usize..6,
        [-200i32..200, -200i32..200, -200i32..200],
        any::<bool>(),
    )
        .prop_map(|(bodies, workpiece, tool, tp, tool_frame)| GenMachine {
            bodies,
            workpiece,
            tool,
            tool_point: tp.map(f64::from),
            tool_frame,
        })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

    /// Random tree machines with random function slots of every basis, as
    /// machine files: the compiled model equals the finite difference of the
    /// exact product, and the two derivation routes agree.
    #[test]
    fn random_machines_with_function_slots_match_the_exact_product(
        g in gen_machine(),
        seed in any::<u64>(),
    ) {
        let yaml = g.yaml();
        let m = match chain_core::load_str(&yaml, "random.yaml") {
            Ok(m) => m,
            Err(d) => panic!("generated machine does not load:\n{d}\n---\n{yaml}"),
        };
        let range = |name: &str| {
            let v = m.variable_index(name).expect("variable");
            match m.variables[v].kind {
                JointKind::Prismatic => [-300.0, 300.0],
                JointKind::Rotary => [-PI, PI],
            }
        };
        let model = chain_core::compile(&m);
        let ex = Exact::new(&m);
        let mut rng = Rng::new(seed);
        for _ in 0..3 {
            let q = random_q(&m, &mut rng, &range);
            if let Err(msg) = ex.check_sensitivity(&model, &q, &[], 1e-6, 1e-9) {
                panic!("{msg}\n---\n{yaml}");
            }
            let e = random_e(&m, &mut rng, &q);
            if let Err(msg) = ex.check_error_and_nominal(&model, &q, &[], &e, 1e-10) {
                panic!("{msg}\n---\n{yaml}");
            }
        }
        // Arbitrary fixed rotations round differently along the two routes.
        assert_routes_agree_to(&m, 1e-12);
    }
}

// ------------------------------------------------------- generated code (macro)

chain::machine!(pub Legendre5 = "examples/machines/legendre5.yaml");

chain::machine! {
    pub RotaryPolynomial {
        parameters: { L: 100 },
        bodies {
            bed {},
            table {
                parent: bed,
                joint: { type: rotary, axis: +z, variable: C },
                errors: {
                    dx: { name: F, powers: [1, 2] },
                    dy: { name: H, basis: fourier, harmonics: 1 },
                    ez: { name: G, basis: legendre, degree: 2, range: [-3.2, 3.2] },
                },
            },
            tool { parent: bed, offset: [L, 0, 0] },
        },
        workpiece: table,
        tool: tool,
    }
}

const ROTARY_POLYNOMIAL: &str = "machine: rotary_polynomial\nparameters: {L: 100}\nbodies:\n  bed: {}\n  table:\n    parent: bed\n    joint: {type: rotary, axis: +z, variable: C}\n    errors:\n      dx: {name: F, powers: [1, 2]}\n      dy: {name: H, basis: fourier, harmonics: 1}\n      ez: {name: G, basis: legendre, degree: 2, range: [-3.2, 3.2]}\n  tool: {parent: bed, offset: [L, 0, 0]}\nworkpiece: table\ntool: tool\n";

#[test]
fn generated_types_of_function_slots_match_the_tape_and_the_exact_product() {
    assert_eq!(
        RotaryPolynomial::ERRORS,
        ["F_1", "F_2", "H_0", "H_c1", "H_s1", "G_0", "G_1", "G_2"]
    );
    let m = chain_core::load_str(ROTARY_POLYNOMIAL, "rp.yaml").unwrap();
    let tape = chain_core::compile(&m);
    let ex = Exact::new(&m);
    let mut rng = Rng::new(41);
    for _ in 0..50 {
        let c = rng.range(-PI, PI);
        let s = RotaryPolynomial::sensitivity(&[c], &[100.0]);
        let mut t = vec![0.0; 6 * 8];
        tape.sensitivity(&[c], &[100.0], &mut t);
        for (a, b) in s.iter().flatten().zip(&t) {
            assert!(
                (a - b).abs() <= 1e-12 * (1.0 + b.abs()),
                "generated {a}, tape {b}"
            );
        }
        // dpx/dF_2 = -C² (the generated code reads the angle itself).
        assert!((s[0][1] + c * c).abs() < 1e-12, "{} at C = {c}", s[0][1]);
        ex.check_sensitivity(&RotaryPolynomial, &[c], &[100.0], 1e-6, 1e-9)
            .unwrap();
    }
    // The five-axis file: 131 errors, against the tape and the exact product.
    let m = load_example("legendre5.yaml");
    let tape = chain_core::compile(&m);
    assert_eq!(Legendre5::ERRORS.len(), 131);
    assert_eq!(Legendre5::ERRORS.as_slice(), tape.errors());
    let ex = Exact::new(&m);
    let p = ex.file_parameters();
    for _ in 0..20 {
        let q = [
            rng.range(-400.0, 400.0),
            rng.range(-2.1, 2.1),
            rng.range(-PI, PI),
            rng.range(-400.0, 400.0),
            rng.range(-400.0, 400.0),
        ];
        assert_eq!(Legendre5::VARIABLES, ["y", "A", "C", "x", "z"]);
        let s = Legendre5::sensitivity(&q, &[150.0, 200.0]);
        let mut t = vec![0.0; 6 * 131];
        tape.sensitivity(&q, &p, &mut t);
        for (a, b) in s.iter().flatten().zip(&t) {
            assert!(
                (a - b).abs() <= 1e-10 * (1.0 + b.abs()),
                "generated {a}, tape {b}"
            );
        }
        ex.check_sensitivity(&Legendre5, &q, &p, 1e-6, 1e-9)
            .unwrap();
    }
}

/// Error values from a table that covers `C ∈ [−1, 1]` only.
struct Covered;

impl chain::core::ErrorValues for Covered {
    fn values_at(&self, q: &[f64], out: &mut [f64]) -> Result<(), chain::core::OutOfRange> {
        if q[0].abs() > 1.0 {
            return Err(chain::core::OutOfRange {
                name: "F".into(),
                table: "points".into(),
                variable: "C".into(),
                value: q[0],
                lo: -1.0,
                hi: 1.0,
            });
        }
        out.fill(1e-3);
        Ok(())
    }
}

#[test]
fn error_at_takes_a_closure_or_any_error_values() {
    // Values that vary along the axis: F_1 = 1e-3·(1 + C), the others fixed.
    let values = |q: &[f64], e: &mut [f64]| {
        for (j, v) in e.iter_mut().enumerate() {
            *v = 1e-4 * (j as f64 + 1.0);
        }
        e[RotaryPolynomial::ERR_F_1] = 1e-3 * (1.0 + q[0]);
    };
    for c in [-2.0, 0.0, 0.7] {
        let mut e = [0.0; 8];
        values(&[c], &mut e);
        let direct = RotaryPolynomial::error(&[c], &[100.0], &e);
        let at = RotaryPolynomial::error_at(&[c], &[100.0], &values).unwrap();
        assert_eq!(at, direct);
        // The same through the trait, with the caller's scratch.
        let (mut scratch, mut out) = ([0.0; 8], [0.0; 6]);
        RotaryPolynomial
            .error_with(&[c], &[100.0], &values, &mut scratch, &mut out)
            .unwrap();
        assert_eq!(out, direct);
        // And it is S·e of the exact sensitivity.
        let s = RotaryPolynomial::sensitivity(&[c], &[100.0]);
        let px: f64 = (0..8).map(|j| s[0][j] * e[j]).sum();
        assert!((at[0] - px).abs() < 1e-15, "{} vs {px}", at[0]);
    }
    // A table that does not cover the point: the error, not a number.
    assert!(RotaryPolynomial::error_at(&[0.5], &[100.0], &Covered).is_ok());
    let err = RotaryPolynomial::error_at(&[1.5], &[100.0], &Covered).unwrap_err();
    assert_eq!(err.value, 1.5);
    assert!(
        err.to_string().contains("outside the table of `F`"),
        "{err}"
    );
    let dynamic: &dyn chain::core::ErrorValues = &Covered;
    assert!(RotaryPolynomial::error_at(&[-1.5], &[100.0], dynamic).is_err());
}
