//! Values files (measured-machines spec, section 2): the library's reading of
//! the example vmc3 values against the test's own reading of its CSV tables,
//! the interpolation against independent implementations (the test's own
//! linear interpolation; a natural cubic spline solved densely by nalgebra
//! and evaluated in the polynomial form of Burden & Faires, not the library's
//! form), the spline's defining properties, units, `extrapolate: hold`, and
//! every refusal of section 2 through `chain map` (exit code, file, line,
//! column, key or CSV line, code).

// Index loops over knots read best with explicit indices.
#![allow(clippy::needless_range_loop)]

use crate::common;
use crate::reference;

use std::path::{Path, PathBuf};

use reference::{linear, read_table, Spline};

use chain_core::values::{
    BindError, EntryKind, Extrapolation, Given, Interpolation, NotAMotion, Table, TableError,
    Values, ValuesBuilder,
};
use chain_core::ErrorValues;
use common::cli::{fails, scratch, unwrapped, write};
use common::{example_file, load_example, Rng};

fn vmc3_values() -> (chain_core::Machine, Values) {
    let m = load_example("vmc3.yaml");
    let v = Values::read(&example_file("values/vmc3.yaml"), &m).unwrap_or_else(|e| panic!("{e:#}"));
    (m, v)
}

// --------------------------------------------------------- the example file

#[test]
fn the_example_values_are_the_csv_tables_in_mm_and_rad() {
    let (m, values) = vmc3_values();
    assert_eq!(values.machine(), "vmc3");
    assert_eq!(values.entries().len(), 21);
    assert_eq!(values.table_count(), 18);
    // The three squareness constants, µrad → rad.
    for (name, v) in [("EC0Y", 15e-6), ("EA0Z", 8e-6), ("EB0Z", -10e-6)] {
        let j = m.error_index(name).unwrap();
        assert!(
            (values.constants()[j] - v).abs() < 1e-15 * v.abs(),
            "{name}"
        );
    }
    // EYX is a function slot: its table goes on EYX_0 (P_0 = 1).
    let eyx = values.entries().iter().find(|e| e.name == "EYX").unwrap();
    assert_eq!(eyx.kind, EntryKind::Function);
    assert!(matches!(
        &eyx.given,
        Given::Table { variable, points: 21, interpolation: Interpolation::Cubic, .. } if variable == "x"
    ));
    let mut rng = Rng::new(3);
    let n = m.errors.len();
    let mut out = vec![0.0; n];
    for (axis, stroke) in [("x", 800.0), ("y", 500.0), ("z", 500.0)] {
        let (header, columns) = read_table(&example_file(&format!("values/{axis}_axis.csv")));
        assert_eq!(header[0], axis);
        let k = m.variable_index(axis).unwrap();
        let mut q = vec![250.0; 3];
        for step in 0..60 {
            // At the knots, then between them.
            let x = if step < 21 {
                columns[0][step]
            } else {
                rng.range(0.0, stroke)
            };
            q[k] = x;
            values.values_at(&q, &mut out).unwrap();
            for (c, name) in header.iter().enumerate().skip(1) {
                let entry = values.entries().iter().find(|e| &e.name == name).unwrap();
                let cubic = matches!(
                    entry.given,
                    Given::Table {
                        interpolation: Interpolation::Cubic,
                        ..
                    }
                );
                let unit =
                    if name.starts_with("EA") || name.starts_with("EB") || name.starts_with("EC") {
                        1e-6
                    } else {
                        1e-3
                    };
                let col: Vec<f64> = columns[c].iter().map(|v| v * unit).collect();
                let expect = if cubic {
                    Spline::new(&columns[0], &col).eval(x)
                } else {
                    linear(&columns[0], &col, x)
                };
                let j = m
                    .error_index(name)
                    .or_else(|| m.error_index(&format!("{name}_0")))
                    .unwrap();
                let got = out[j];
                if step < 21 {
                    // The table passes through its points exactly.
                    assert!(
                        (got - col[step]).abs() <= 1e-18,
                        "{name} at {x}: {got} vs {}",
                        col[step]
                    );
                }
                let scale = col.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                assert!(
                    (got - expect).abs() <= 1e-14 * scale,
                    "{name} at {axis} = {x}: {got} vs {expect}"
                );
            }
        }
        // The other coefficients of EYX stay zero: Σ b_k e_k = EYX(x).
        for k in 1..=3 {
            assert_eq!(out[m.error_index(&format!("EYX_{k}")).unwrap()], 0.0);
        }
    }
}

#[test]
fn the_legendre_coefficients_are_read_as_constants() {
    let m = load_example("vmc3.yaml");
    let v = Values::read(&example_file("values/vmc3_legendre.yaml"), &m).unwrap();
    let j0 = m.error_index("EYX_0").unwrap();
    let j2 = m.error_index("EYX_2").unwrap();
    assert!((v.constants()[j0] + 8e-3 / 3.0).abs() < 1e-18);
    assert!((v.constants()[j2] - 8e-3 / 3.0).abs() < 1e-18);
    let e = v.entries().iter().find(|e| e.name == "EYX_2").unwrap();
    assert_eq!(e.kind, EntryKind::Coefficient);
    assert_eq!(v.table_count(), 17);
}

// ------------------------------------------------------------ interpolation

/// Irregular knots and values of a few µm.
fn knots() -> (Vec<f64>, Vec<f64>) {
    let x = vec![0.0, 35.0, 80.0, 100.0, 170.0, 260.0, 300.0, 410.0];
    let y = vec![0.0, 2.1, -1.3, -0.4, 3.3, 2.0, -2.5, 1.0];
    (x, y)
}

#[test]
fn the_cubic_spline_is_the_natural_spline() {
    let (x, y) = knots();
    let t = Table::new(
        x.iter().copied().zip(y.iter().copied()).collect(),
        Interpolation::Cubic,
        Extrapolation::Error,
    )
    .unwrap();
    let reference = Spline::new(&x, &y);
    // Through the knots.
    for i in 0..x.len() {
        assert_eq!(t.eval(x[i]), Some(y[i]), "knot {i}");
    }
    // Equal to the independent spline everywhere.
    for k in 0..=4100 {
        let q = 410.0 * f64::from(k) / 4100.0;
        let (a, b) = (t.eval(q).unwrap(), reference.eval(q));
        assert!((a - b).abs() < 1e-12, "q = {q}: {a} vs {b}");
    }
    // Continuous first and second derivatives at the interior knots; zero
    // second derivative at both ends. One-sided differences of step h: the
    // first derivatives differ by h·S'' + O(h²), the second by O(h·S''').
    let s = |q: f64| t.eval(q).unwrap();
    let h = 1e-3;
    for i in 1..x.len() - 1 {
        let xi = x[i];
        let right1 = (s(xi + h) - s(xi)) / h;
        let left1 = (s(xi) - s(xi - h)) / h;
        assert!(
            (right1 - left1).abs() < 1e-4,
            "S' jumps at {xi}: {left1} → {right1}"
        );
        let right2 = (s(xi + 2.0 * h) - 2.0 * s(xi + h) + s(xi)) / (h * h);
        let left2 = (s(xi) - 2.0 * s(xi - h) + s(xi - 2.0 * h)) / (h * h);
        assert!(
            (right2 - left2).abs() < 1e-3,
            "S'' jumps at {xi}: {left2} → {right2}"
        );
        // The library's second derivatives are these.
        let m = t.second_derivatives().unwrap()[i];
        assert!((m - 0.5 * (left2 + right2)).abs() < 1e-3, "m_{i} = {m}");
        // A kink would show: the linear table's slopes differ here.
        let lin = Table::new(
            x.iter().copied().zip(y.iter().copied()).collect(),
            Interpolation::Linear,
            Extrapolation::Error,
        )
        .unwrap();
        let l = |q: f64| lin.eval(q).unwrap();
        assert!(((l(xi + h) - l(xi)) / h - (l(xi) - l(xi - h)) / h).abs() > 1e-3);
    }
    let n = x.len() - 1;
    let end0 = (s(x[0] + 2.0 * h) - 2.0 * s(x[0] + h) + s(x[0])) / (h * h);
    let end1 = (s(x[n]) - 2.0 * s(x[n] - h) + s(x[n] - 2.0 * h)) / (h * h);
    assert!(
        end0.abs() < 1e-3 && end1.abs() < 1e-3,
        "S'' at the ends: {end0}, {end1}"
    );
    let m = t.second_derivatives().unwrap();
    assert_eq!((m[0], m[n]), (0.0, 0.0));
}

#[test]
fn linear_tables_and_hold() {
    let (x, y) = knots();
    let points: Vec<(f64, f64)> = x.iter().copied().zip(y.iter().copied()).collect();
    let t = Table::new(points.clone(), Interpolation::Linear, Extrapolation::Error).unwrap();
    let mut rng = Rng::new(8);
    for _ in 0..500 {
        let q = rng.range(0.0, 410.0);
        let (a, b) = (t.eval(q).unwrap(), linear(&x, &y, q));
        assert!((a - b).abs() < 1e-14, "q = {q}");
    }
    assert_eq!(t.eval(-0.001), None);
    assert_eq!(t.eval(410.001), None);
    for interpolation in [Interpolation::Linear, Interpolation::Cubic] {
        let held = Table::new(points.clone(), interpolation, Extrapolation::Hold).unwrap();
        assert_eq!(held.eval(-50.0), Some(0.0));
        assert_eq!(held.eval(1e9), Some(1.0));
        assert_eq!(held.eval(f64::NAN), None);
    }
    assert_eq!(
        Table::new(
            vec![(1.0, 0.0), (1.0, 1.0)],
            Interpolation::Linear,
            Extrapolation::Error
        ),
        Err(TableError::NotIncreasing {
            index: 1,
            q: 1.0,
            previous: 1.0
        })
    );
}

#[test]
fn outside_a_table_is_an_error_naming_the_table_and_the_value() {
    let (m, values) = vmc3_values();
    let mut out = vec![0.0; m.errors.len()];
    let mut q = vec![0.0; 3];
    q[m.variable_index("x").unwrap()] = 812.5;
    let e = values.values_at(&q, &mut out).unwrap_err();
    assert_eq!(e.variable, "x");
    assert_eq!(e.value, 812.5);
    assert_eq!((e.lo, e.hi), (0.0, 800.0));
    assert_eq!(e.table, "x_axis.csv, column EXX");
    assert_eq!(e.name, "EXX");
    let text = e.to_string();
    assert!(
        text.contains("x = 812.5") && text.contains("extrapolate: hold"),
        "{text}"
    );
}

// -------------------------------------------------------------------- units

#[test]
fn units_convert_to_mm_and_rad() {
    let m = load_example("vmc3.yaml");
    let dir = scratch("units");
    let read = |units: &str, linear: f64, angle: f64| {
        let text = format!(
            "machine: vmc3\nunits: {units}\nvalues:\n  EXX: {{points: [[0, 0], [800, {linear}]]}}\n  EC0Y: {angle}\n  EAX: {angle}\n  EYX_1: {linear}\n"
        );
        let path = write(&dir, "v.yaml", &text);
        let v = Values::read(&path, &m).unwrap();
        let mut out = vec![0.0; m.errors.len()];
        let mut q = vec![0.0; 3];
        q[m.variable_index("x").unwrap()] = 800.0;
        v.values_at(&q, &mut out).unwrap();
        let at = |n: &str| out[m.error_index(n).unwrap()];
        (at("EXX"), at("EC0Y"), at("EAX"), at("EYX_1"))
    };
    let base = read("{linear: mm, angular: rad}", 0.012, 2e-5);
    assert_eq!(base, (0.012, 2e-5, 2e-5, 0.012));
    assert_eq!(
        read("{linear: mm, angular: rad}", 0.012, 2e-5),
        read("{}", 0.012, 2e-5)
    );
    let (a, b, c, d) = read("{linear: um, angular: urad}", 12.0, 20.0);
    assert!((a - 0.012).abs() < 1e-18 && (d - 0.012).abs() < 1e-18);
    assert!((b - 2e-5).abs() < 1e-20 && (c - 2e-5).abs() < 1e-20);
    // 4.125 arcsec = 4.125 π / 648000 rad; 0.5 deg = π / 360 rad.
    let (_, b, _, _) = read("{angular: arcsec}", 0.0, 4.125);
    assert!((b - 4.125 * std::f64::consts::PI / 648_000.0).abs() < 1e-20);
    let (_, b, _, _) = read("{angular: deg}", 0.0, 0.5);
    assert!((b - std::f64::consts::PI / 360.0).abs() < 1e-17);
}

// -------------------------------------------------------- the Rust builder

#[test]
fn the_builder_applies_the_same_rules() {
    let m = load_example("vmc3.yaml");
    let t = || {
        Table::new(
            vec![(0.0, 0.0), (800.0, 1e-3)],
            Interpolation::Linear,
            Extrapolation::Error,
        )
        .unwrap()
    };
    let mut b = ValuesBuilder::new(&m);
    assert!(matches!(
        b.table("EC0Y", t(), "points"),
        Err(BindError::NotAMotion {
            reason: NotAMotion::Squareness,
            ..
        })
    ));
    assert!(matches!(
        b.table("EYX_1", t(), "points"),
        Err(BindError::NotAMotion {
            reason: NotAMotion::Coefficient { .. },
            ..
        })
    ));
    assert!(matches!(
        b.constant("EYX", 1.0),
        Err(BindError::FunctionConstant { .. })
    ));
    match b.constant("EXXX", 1.0) {
        Err(BindError::UnknownName { suggestion, .. }) => {
            assert_eq!(suggestion.as_deref(), Some("EXX"))
        }
        other => panic!("{other:?}"),
    }
    b.constant("EYX_2", 1e-3).unwrap();
    assert!(matches!(
        b.table("EYX", t(), "points"),
        Err(BindError::CoefficientAndFunction { .. })
    ));
    let mut b = ValuesBuilder::new(&m);
    b.table("EYX", t(), "points").unwrap();
    assert!(matches!(
        b.constant("EYX_0", 1e-3),
        Err(BindError::CoefficientAndFunction { .. })
    ));
    assert!(matches!(
        b.constant("EXX", f64::NAN),
        Err(BindError::NotFinite { .. })
    ));
    let v = b.build();
    let mut out = vec![0.0; m.errors.len()];
    let mut q = vec![0.0; 3];
    q[m.variable_index("x").unwrap()] = 400.0;
    v.values_at(&q, &mut out).unwrap();
    assert_eq!(out[m.error_index("EYX_0").unwrap()], 5e-4);
    assert_eq!(Values::zero(&m).constants(), vec![0.0; m.errors.len()]);
}

// ----------------------------------------------------------------- refusals

/// A machine with one of every kind of error: a location error, squareness,
/// an error of a body without a joint, an error shared by two jointed
/// bodies, function slots with and without a constant term.
const MACHINE: &str = "\
machine: m
bodies:
  bed: {}
  fixture: {parent: bed, errors: {dz: Fz}}
  x_slide:
    parent: bed
    joint: {type: prismatic, axis: +x, variable: x}
    location_errors: {dx: Lx}
    errors:
      dx: Ex
      dy: Shared
      dz: {name: EZX, powers: [1, 2]}
      ex: {name: EAX, basis: legendre, degree: 2, range: [0, 100], from: 1}
      ey: {name: EBX, powers: [0, 1]}
    squareness: {ez: Sxy}
  z_slide:
    parent: x_slide
    joint: {type: prismatic, axis: +z, variable: z}
    errors: {dy: Shared, dz: Ez}
  tool: {parent: z_slide, offset: [0, 0, -100]}
workpiece: fixture
tool: tool
";

/// Runs `chain map` on [`MACHINE`] with `values` (and CSV files) in a fresh
/// directory; it must fail. Returns the unwrapped stderr and the directory.
fn refused(name: &str, values: &str, csvs: &[(&str, &str)]) -> (String, PathBuf) {
    let dir = scratch(name);
    let machine = write(&dir, "m.yaml", MACHINE);
    let v = write(&dir, "values.yaml", values);
    for (file, text) in csvs {
        write(&dir, file, text);
    }
    let err = fails(&[
        "map",
        machine.to_str().unwrap(),
        "--values",
        v.to_str().unwrap(),
        "--grid",
        "x=0",
        "--grid",
        "z=0",
    ]);
    (unwrapped(&err), dir)
}

/// Asserts that `err` names `file:line:column`, the key and the code.
#[track_caller]
fn located(err: &str, dir: &Path, file: &str, line_col: &str, key: &str, code: &str) {
    let at = format!("{}:{line_col}:", dir.join(file).display());
    assert!(err.contains(&at), "no `{at}` in:\n{err}");
    if !key.is_empty() {
        assert!(
            err.contains(&format!("at key `{key}`")),
            "no key `{key}` in:\n{err}"
        );
    }
    assert!(err.contains(code), "no code `{code}` in:\n{err}");
}

#[test]
fn a_valid_file_for_the_refusal_machine_is_read() {
    // The machine and a file giving every kind of name what it can take.
    let dir = scratch("valid");
    let machine = write(&dir, "m.yaml", MACHINE);
    let m = chain_core::load_file(&machine).unwrap();
    let text = "machine: m\nvalues:\n  Lx: 1e-3\n  Sxy: 2e-5\n  Fz: 3e-3\n  Shared: 4e-3\n  Ex: {points: [[0, 0], [100, 1e-3]], extrapolate: hold}\n  Ez: {table: z.csv}\n  EZX_1: 1e-6\n  EAX_2: 2e-6\n  EBX: {points: [[0, 1e-3], [100, 2e-3]], interpolation: cubic, extrapolate: hold}\n  correlation_is_not_here: null\ncorrelation: [[1, 0], [0, 1]]\n";
    let text = text.replace("  correlation_is_not_here: null\n", "");
    write(&dir, "z.csv", "z,Ez\n0,0\n50,0.001\n");
    let v = Values::read(&write(&dir, "v.yaml", &text), &m).unwrap_or_else(|e| panic!("{e:#}"));
    let mut out = vec![0.0; m.errors.len()];
    let at = |n: &str| m.error_index(n).unwrap();
    v.values_at(&[50.0, 25.0], &mut out).unwrap();
    assert_eq!(out[at("Ex")], 5e-4);
    assert_eq!(out[at("Ez")], 5e-4);
    assert!((out[at("EBX_0")] - 1.5e-3).abs() < 1e-18); // two points: the line
    assert_eq!(out[at("EBX_1")], 0.0);
    v.values_at(&[150.0, 25.0], &mut out).unwrap();
    assert_eq!(out[at("Ex")], 1e-3); // held
    assert_eq!(out[at("EBX_0")], 2e-3);
    assert_eq!(out[at("Lx")], 1e-3);
    assert_eq!(out[at("EAX_2")], 2e-6);
    assert!(v.values_at(&[50.0, 60.0], &mut out).is_err());
}

#[test]
fn unknown_names_have_a_did_you_mean() {
    let (err, dir) = refused("unknown", "machine: m\nvalues:\n  Exx: 1e-3\n", &[]);
    located(
        &err,
        &dir,
        "values.yaml",
        "3:3",
        "values.Exx",
        "chain::values::unknown_name",
    );
    assert!(err.contains("did you mean `Ex`?"), "{err}");
}

#[test]
fn tables_only_for_error_motions() {
    let cases = [
        ("Lx", "location error of body `x_slide`"),
        ("Sxy", "squareness term"),
        ("Fz", "body `fixture`, which has no joint"),
        ("Shared", "several bodies (x_slide, z_slide)"),
        ("EZX_1", "coefficient of the function slot `EZX`"),
    ];
    for (name, why) in cases {
        let text = format!("machine: m\nvalues:\n  {name}: {{points: [[0, 0], [1, 1]]}}\n");
        let (err, dir) = refused(&format!("motion_{name}"), &text, &[]);
        let key = format!("values.{name}");
        located(
            &err,
            &dir,
            "values.yaml",
            "3:3",
            &key,
            "chain::values::not_a_motion",
        );
        assert!(err.contains(why), "{name}: no `{why}` in {err}");
    }
}

#[test]
fn function_slots_take_a_table_only_with_a_constant_term() {
    for name in ["EZX", "EAX"] {
        let text = format!("machine: m\nvalues:\n  {name}: {{points: [[0, 0], [1, 1]]}}\n");
        let (err, dir) = refused(&format!("constant_term_{name}"), &text, &[]);
        located(
            &err,
            &dir,
            "values.yaml",
            "3:3",
            &format!("values.{name}"),
            "chain::values::no_constant_term",
        );
        assert!(
            err.contains("vanishes where all its basis functions do"),
            "{err}"
        );
    }
    let (err, _) = refused(
        "constant_term_basis",
        "machine: m\nvalues:\n  EAX: {points: [[0, 0], [1, 1]]}\n",
        &[],
    );
    assert!(err.contains("legendre from 1"), "{err}");
    let (err, dir) = refused(
        "function_constant",
        "machine: m\nvalues:\n  EBX: 1e-3\n",
        &[],
    );
    located(
        &err,
        &dir,
        "values.yaml",
        "3:3",
        "values.EBX",
        "chain::values::function_constant",
    );
    assert!(err.contains("EBX_0, EBX_1"), "{err}");
}

#[test]
fn a_function_is_a_table_or_its_coefficients() {
    // Either order in the file: the coefficient is the one reported.
    for (text, line) in [
        (
            "machine: m\nvalues:\n  EBX: {points: [[0, 0], [1, 1]]}\n  EBX_1: 1e-6\n",
            "4:3",
        ),
        (
            "machine: m\nvalues:\n  EBX_1: 1e-6\n  EBX: {points: [[0, 0], [1, 1]]}\n",
            "3:3",
        ),
    ] {
        let (err, dir) = refused("coefficient_and_function", text, &[]);
        located(
            &err,
            &dir,
            "values.yaml",
            line,
            "values.EBX_1",
            "chain::values::coefficient_and_function",
        );
    }
}

#[test]
fn points_must_increase_be_finite_and_at_least_two() {
    let cases = [
        (
            "[[0, 0], [2, 1], [1, 2]]",
            "3:33",
            "values.Ex.points[2]",
            "chain::values::unsorted_positions",
            "q = 1 comes after q = 2",
        ),
        (
            "[[0, 0], [0, 1]]",
            "3:25",
            "values.Ex.points[1]",
            "chain::values::duplicate_position",
            "q = 0 appears twice",
        ),
        (
            "[[0, 0]]",
            "3:8",
            "values.Ex.points",
            "chain::values::too_few_points",
            "at least 2 points",
        ),
        (
            "[[0, .nan], [1, 1]]",
            "3:21",
            "values.Ex.points[0][1]",
            "chain::not_finite",
            "must be finite",
        ),
        (
            "[[0, 1], [.inf, 1]]",
            "3:26",
            "values.Ex.points[1][0]",
            "chain::not_finite",
            "must be finite",
        ),
        (
            "[[0, 1], [1]]",
            "3:25",
            "values.Ex.points[1]",
            "chain::wrong_length",
            "2 items",
        ),
    ];
    for (points, at, key, code, text) in cases {
        let values = format!("machine: m\nvalues:\n  Ex: {{points: {points}}}\n");
        let (err, dir) = refused("points", &values, &[]);
        located(&err, &dir, "values.yaml", at, key, code);
        assert!(err.contains(text), "{points}: no `{text}` in {err}");
    }
    let (err, dir) = refused("inf_constant", "machine: m\nvalues:\n  Lx: .inf\n", &[]);
    located(
        &err,
        &dir,
        "values.yaml",
        "3:7",
        "values.Lx",
        "chain::not_finite",
    );
}

#[test]
fn the_machine_and_the_units_must_be_right() {
    let (err, dir) = refused("mismatch", "machine: vmc3\nvalues: {}\n", &[]);
    located(
        &err,
        &dir,
        "values.yaml",
        "1:10",
        "machine",
        "chain::values::machine_mismatch",
    );
    assert!(err.contains("for machine `vmc3`, not `m`"), "{err}");
    let (err, dir) = refused("unit", "machine: m\nunits: {linear: nm}\nvalues: {}\n", &[]);
    located(
        &err,
        &dir,
        "values.yaml",
        "2:17",
        "units.linear",
        "chain::unknown_value",
    );
    assert!(
        err.contains("did you mean `mm`?") && err.contains("mm, um"),
        "{err}"
    );
    let (err, dir) = refused(
        "angular_unit",
        "machine: m\nunits: {angular: mrad}\nvalues: {}\n",
        &[],
    );
    located(
        &err,
        &dir,
        "values.yaml",
        "2:18",
        "units.angular",
        "chain::unknown_value",
    );
    let (err, dir) = refused("no_machine", "values: {}\n", &[]);
    located(&err, &dir, "values.yaml", "1:1", "", "chain::missing_key");
}

#[test]
fn entry_keys_are_checked() {
    let (err, dir) = refused(
        "unknown_key",
        "machine: m\nvalues:\n  Ex: {pionts: [[0, 0], [1, 1]]}\n",
        &[],
    );
    located(
        &err,
        &dir,
        "values.yaml",
        "3:8",
        "values.Ex.pionts",
        "chain::unknown_key",
    );
    assert!(err.contains("did you mean `points`?"), "{err}");
    let (err, dir) = refused(
        "conflict",
        "machine: m\nvalues:\n  Ex: {value: 1, points: [[0, 0], [1, 1]]}\n",
        &[],
    );
    located(
        &err,
        &dir,
        "values.yaml",
        "3:18",
        "values.Ex.points",
        "chain::conflicting_keys",
    );
    let (err, dir) = refused(
        "negative_std",
        "machine: m\nvalues:\n  Lx: {value: 1e-3, std: -1e-4}\n",
        &[],
    );
    located(
        &err,
        &dir,
        "values.yaml",
        "3:26",
        "values.Lx.std",
        "chain::out_of_range",
    );
    let (err, dir) = refused(
        "interpolation",
        "machine: m\nvalues:\n  Ex: {points: [[0, 0], [1, 1]], interpolation: spline}\n",
        &[],
    );
    located(
        &err,
        &dir,
        "values.yaml",
        "3:49",
        "values.Ex.interpolation",
        "chain::unknown_value",
    );
    let (err, dir) = refused(
        "std_on_table",
        "machine: m\nvalues:\n  Ex: {points: [[0, 0], [1, 1]], std: 1}\n",
        &[],
    );
    located(
        &err,
        &dir,
        "values.yaml",
        "3:34",
        "values.Ex.std",
        "chain::values::key_not_for_table",
    );
}

#[test]
fn several_problems_are_reported_together() {
    let text = "machine: m\nvalues:\n  Exx: 1\n  Sxy: {points: [[0, 0], [1, 1]]}\n  Ex: {points: [[1, 0], [0, 1]]}\n";
    let (err, dir) = refused("several", text, &[]);
    let file = dir.join("values.yaml").display().to_string();
    for at in ["3:3", "4:3", "5:25"] {
        assert!(err.contains(&format!("{file}:{at}:")), "no {at} in {err}");
    }
}

#[test]
fn csv_tables_are_located_by_file_and_line() {
    let values = |entry: &str| format!("machine: m\nvalues:\n  Ex: {entry}\n");
    // No column of the axis variable.
    let (err, dir) = refused(
        "csv_variable",
        &values("{table: t.csv}"),
        &[("t.csv", "q,Ex\n0,0\n1,1\n")],
    );
    located(
        &err,
        &dir,
        "t.csv",
        "1:1",
        "",
        "chain::values::csv_no_variable",
    );
    assert!(err.contains("no column `x`"), "{err}");
    // No column of the given name: located at `column` in the values file.
    let (err, dir) = refused(
        "csv_column",
        &values("{table: t.csv, column: EX}"),
        &[("t.csv", "x,Ex\n0,0\n1,1\n")],
    );
    located(
        &err,
        &dir,
        "values.yaml",
        "3:30",
        "values.Ex.column",
        "chain::values::csv_no_column",
    );
    assert!(err.contains("did you mean `Ex`?"), "{err}");
    // A cell that is not a number, one that is not finite, an empty one.
    let csv = "# measured\nx,Ex\n0,0\n1,abc\n2,inf\n3,\n";
    let (err, dir) = refused("csv_number", &values("{table: t.csv}"), &[("t.csv", csv)]);
    located(&err, &dir, "t.csv", "4:3", "Ex", "chain::csv::not_a_number");
    located(&err, &dir, "t.csv", "5:3", "Ex", "chain::csv::not_finite");
    located(&err, &dir, "t.csv", "6:3", "Ex", "chain::csv::empty_cell");
    assert!(err.contains("column `Ex`: `abc` is not a number"), "{err}");
    // Unsorted and repeated positions: at the CSV line.
    let (err, dir) = refused(
        "csv_sorted",
        &values("{table: t.csv}"),
        &[("t.csv", "x,Ex\n0,0\n2,1\n1,0\n")],
    );
    located(
        &err,
        &dir,
        "t.csv",
        "4:1",
        "x",
        "chain::values::unsorted_positions",
    );
    let (err, dir) = refused(
        "csv_duplicate",
        &values("{table: t.csv}"),
        &[("t.csv", "x,Ex\n0,0\n0,1\n")],
    );
    located(
        &err,
        &dir,
        "t.csv",
        "3:1",
        "x",
        "chain::values::duplicate_position",
    );
    // One row only.
    let (err, dir) = refused(
        "csv_short",
        &values("{table: t.csv}"),
        &[("t.csv", "x,Ex\n0,0\n")],
    );
    located(
        &err,
        &dir,
        "values.yaml",
        "3:8",
        "values.Ex.table",
        "chain::values::too_few_points",
    );
    // A ragged row, a repeated header column.
    let (err, dir) = refused(
        "csv_ragged",
        &values("{table: t.csv}"),
        &[("t.csv", "x,Ex\n0,0\n1\n")],
    );
    located(&err, &dir, "t.csv", "3:1", "", "chain::csv::ragged");
    let (err, dir) = refused(
        "csv_header",
        &values("{table: t.csv}"),
        &[("t.csv", "x,Ex,x\n0,0,0\n")],
    );
    located(&err, &dir, "t.csv", "1:6", "", "chain::values::csv_header");
    // A file that does not exist: at `table` in the values file.
    let (err, dir) = refused("csv_missing", &values("{table: nowhere.csv}"), &[]);
    located(
        &err,
        &dir,
        "values.yaml",
        "3:15",
        "values.Ex.table",
        "chain::values::table_file",
    );
    assert!(err.contains("relative to the values file"), "{err}");
}

#[test]
fn a_csv_file_is_read_once_and_its_problems_reported_once() {
    let dir = scratch("csv_once");
    let m = chain_core::load_file(&write(&dir, "m.yaml", MACHINE)).unwrap();
    write(&dir, "t.csv", "x,Ex,Shared\n0,0,0\n1\n");
    let text = "machine: m\nvalues:\n  Ex: {table: t.csv}\n  EBX: {table: t.csv, column: Ex}\n";
    match Values::read(&write(&dir, "v.yaml", text), &m) {
        Err(chain_core::values::ValuesError::Table(d)) => {
            assert_eq!(d.len(), 1, "{d:#}");
            assert_eq!(d.first().origin.line, 3);
        }
        other => panic!("{other:?}"),
    }
    // A good file shared by two entries gives both their columns.
    write(&dir, "u.csv", "x,Ex,B\n0,0,1\n10,1e-3,2e-3\n");
    let text = "machine: m\nvalues:\n  Ex: {table: u.csv}\n  EBX: {table: u.csv, column: B}\n";
    let v = Values::read(&write(&dir, "w.yaml", text), &m).unwrap();
    let mut out = vec![0.0; m.errors.len()];
    v.values_at(&[5.0, 0.0], &mut out).unwrap();
    assert_eq!(out[m.error_index("Ex").unwrap()], 5e-4);
    assert!((out[m.error_index("EBX_0").unwrap()] - 0.501).abs() < 1e-15);
}

#[test]
fn an_empty_or_unreadable_values_file_is_an_error() {
    let (err, dir) = refused("empty", "", &[]);
    located(&err, &dir, "values.yaml", "1:1", "", "chain::values::empty");
    let (err, _) = refused("syntax", "machine: m\nvalues: {Ex: [\n", &[]);
    assert!(err.contains("values.yaml:"), "{err}");
    let dir = scratch("missing_values");
    let machine = write(&dir, "m.yaml", MACHINE);
    let err = fails(&[
        "map",
        machine.to_str().unwrap(),
        "--values",
        "no/such/values.yaml",
        "--grid",
        "x=0",
        "--grid",
        "z=0",
    ]);
    assert!(
        err.contains("no/such/values.yaml") && err.contains("cannot read"),
        "{err}"
    );
}
