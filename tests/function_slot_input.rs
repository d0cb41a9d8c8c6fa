//! Function slots (error motions that vary along their axis) and `errors:
//! iso` in machine files (measured-machines spec, section 1): the valid
//! forms give exactly the named coefficients, kinds and function records;
//! every refusal is one located diagnostic naming the file, line and key, and
//! `chain derive` exits non-zero on it. The v1 example machines load exactly
//! as they did before function slots existed.

mod common;

use chain_core::model::{Basis, BasisFn, Component, ErrorKind, Machine};
use chain_core::{load_str, SymbolicModel};

/// Loads `text` as `fs.yaml`, which must be valid.
#[track_caller]
fn load(text: &str) -> Machine {
    match load_str(text, "fs.yaml") {
        Ok(m) => m,
        Err(d) => panic!("expected a machine, got:\n{d:#}"),
    }
}

/// The error names and kinds of a machine, in its order.
fn errors(m: &Machine) -> Vec<(&str, ErrorKind)> {
    m.errors.iter().map(|e| (e.name.as_str(), e.kind)).collect()
}

/// Error indices by name.
fn ix(m: &Machine, names: &[&str]) -> Vec<usize> {
    names
        .iter()
        .map(|n| m.error_index(n).unwrap_or_else(|| panic!("no error {n}")))
        .collect()
}

/// A linear slide and a rotary table, with every kind of function slot.
const FUNCTIONS: &str = "\
machine: fm
parameters: {L: 100}
bodies:
  bed: {}
  x_slide:
    parent: bed
    joint: {type: prismatic, axis: -x, variable: x}
    errors:
      dx: EXX
      dy: [dyc, {name: EYX, powers: [1, 2]}]
      dz: {name: EZX, basis: legendre, degree: 3, range: [0, 1000]}
      ez: {name: ECX, basis: chebyshev, degree: 2, range: [-500, 500], from: 1}
    squareness: {ez: Sxy}
  table:
    parent: bed
    offset: [L, 0, 0]
    joint: {type: rotary, axis: +z, variable: C}
    errors:
      dx: [dxc, {name: EXC, powers: [2, 0]}]
      ex: {name: EAC, basis: fourier, harmonics: 2}
workpiece: table
tool: x_slide
tool_point: [0, 0, 50]
statistics:
  EYX_1: {dist: normal, mean: 0, std: 1e-6}
  EAC_s2: {dist: uniform, min: -1e-5, max: 1e-5}
";

// ---------------------------------------------------------------- valid files

#[test]
fn coefficients_are_error_parameters_in_order_of_first_use() {
    let m = load(FUNCTIONS);
    use ErrorKind::{Angular as A, Linear as L, Squareness as S};
    assert_eq!(
        errors(&m),
        [
            ("EXX", L),
            ("dyc", L),
            ("EYX_1", L),
            ("EYX_2", L),
            ("EZX_0", L),
            ("EZX_1", L),
            ("EZX_2", L),
            ("EZX_3", L),
            ("ECX_1", A),
            ("ECX_2", A),
            ("Sxy", S),
            ("dxc", L),
            ("EXC_2", L),
            ("EXC_0", L),
            ("EAC_0", A),
            ("EAC_c1", A),
            ("EAC_s1", A),
            ("EAC_c2", A),
            ("EAC_s2", A),
        ]
    );
    // The slots hold the coefficients like any error name.
    let x = &m.bodies[1].errors.slots;
    assert_eq!(x[1], ix(&m, &["dyc", "EYX_1", "EYX_2"]));
    assert_eq!(x[2], ix(&m, &["EZX_0", "EZX_1", "EZX_2", "EZX_3"]));
    assert_eq!(x[5], ix(&m, &["ECX_1", "ECX_2", "Sxy"]));
    let table = &m.bodies[2].errors.slots;
    assert_eq!(table[0], ix(&m, &["dxc", "EXC_2", "EXC_0"]));
    assert_eq!(
        table[3],
        ix(&m, &["EAC_0", "EAC_c1", "EAC_s1", "EAC_c2", "EAC_s2"])
    );
}

#[test]
fn function_records() {
    let m = load(FUNCTIONS);
    let names: Vec<&str> = m.functions.iter().map(|f| f.name.as_str()).collect();
    assert_eq!(names, ["EYX", "EZX", "ECX", "EXC", "EAC"]);
    let x = m.variable_index("x").unwrap();
    let c = m.variable_index("C").unwrap();
    let by = |n: &str| &m.functions[m.function_index(n).unwrap()];

    let eyx = by("EYX");
    assert_eq!(eyx.basis, Basis::Powers { powers: vec![1, 2] });
    assert_eq!(eyx.variable, x);
    assert_eq!(
        eyx.coefficients,
        [
            (ix(&m, &["EYX_1"])[0], BasisFn::Power(1)),
            (ix(&m, &["EYX_2"])[0], BasisFn::Power(2)),
        ]
    );
    assert_eq!(eyx.origin.line, 10);
    assert_eq!(eyx.origin.key, "bodies.x_slide.errors.dy[1].name");

    let range = [0.0, 1000.0];
    let ezx = by("EZX");
    assert_eq!(
        ezx.basis,
        Basis::Legendre {
            degree: 3,
            range,
            from: 0
        }
    );
    let legendre: Vec<BasisFn> = (0..=3).map(|k| BasisFn::Legendre { k, range }).collect();
    assert_eq!(
        ezx.coefficients,
        ix(&m, &["EZX_0", "EZX_1", "EZX_2", "EZX_3"])
            .into_iter()
            .zip(legendre)
            .collect::<Vec<_>>()
    );

    let ecx = by("ECX");
    let range = [-500.0, 500.0];
    assert_eq!(
        ecx.basis,
        Basis::Chebyshev {
            degree: 2,
            range,
            from: 1
        }
    );
    assert_eq!(
        ecx.coefficients,
        [
            (ix(&m, &["ECX_1"])[0], BasisFn::Chebyshev { k: 1, range }),
            (ix(&m, &["ECX_2"])[0], BasisFn::Chebyshev { k: 2, range }),
        ]
    );

    // Powers keep the order written.
    let exc = by("EXC");
    assert_eq!(exc.variable, c);
    assert_eq!(
        exc.coefficients,
        [
            (ix(&m, &["EXC_2"])[0], BasisFn::Power(2)),
            (ix(&m, &["EXC_0"])[0], BasisFn::Power(0)),
        ]
    );

    let eac = by("EAC");
    assert_eq!(eac.basis, Basis::Fourier { harmonics: 2 });
    assert_eq!(eac.variable, c);
    let fourier = [
        BasisFn::Cos(0),
        BasisFn::Cos(1),
        BasisFn::Sin(1),
        BasisFn::Cos(2),
        BasisFn::Sin(2),
    ];
    assert_eq!(
        eac.coefficients,
        ix(&m, &["EAC_0", "EAC_c1", "EAC_s1", "EAC_c2", "EAC_s2"])
            .into_iter()
            .zip(fourier)
            .collect::<Vec<_>>()
    );
    // Each coefficient knows its function.
    let (f, b) = m.coefficient_of(ix(&m, &["EAC_s1"])[0]).unwrap();
    assert_eq!((f.name.as_str(), b), ("EAC", BasisFn::Sin(1)));
    assert!(m.coefficient_of(ix(&m, &["dyc"])[0]).is_none());
}

#[test]
fn statistics_on_coefficients() {
    let m = load(FUNCTIONS);
    assert_eq!(m.statistics.len(), 2);
    assert_eq!(m.statistics[0].error, ix(&m, &["EYX_1"])[0]);
    assert_eq!(m.statistics[0].distribution.std(), 1e-6);
    assert_eq!(m.statistics[1].error, ix(&m, &["EAC_s2"])[0]);
    assert_eq!(m.statistics[1].distribution.mean(), 0.0);
}

/// Legendre `P_k(t)` and Chebyshev `T_k(t)` in closed form (Abramowitz &
/// Stegun 22.3), independent of the library's recurrences.
fn legendre(k: u32, t: f64) -> f64 {
    match k {
        0 => 1.0,
        1 => t,
        2 => (3.0 * t * t - 1.0) / 2.0,
        3 => (5.0 * t.powi(3) - 3.0 * t) / 2.0,
        _ => unreachable!(),
    }
}

fn chebyshev(k: u32, t: f64) -> f64 {
    match k {
        1 => t,
        2 => 2.0 * t * t - 1.0,
        _ => unreachable!(),
    }
}

/// Loader to derivation: the derived coefficient of each function
/// coefficient is its basis function (evaluated here in closed form) times
/// the coefficient of a constant error in the same slot (spec section 1), at
/// several poses. (The runtime tape's handling of a power of a rotary
/// variable belongs to the derivation's tests.)
#[test]
fn derived_coefficients_are_the_slot_times_the_basis_function() {
    // Constant errors `dzc`, `ezc`, `exc` share the slots of the functions.
    let text = FUNCTIONS
        .replace("dz: {name: EZX", "dz: [dzc, {name: EZX")
        .replace("range: [0, 1000]}", "range: [0, 1000]}]")
        .replace("ez: {name: ECX", "ez: [ezc, {name: ECX")
        .replace("from: 1}", "from: 1}]")
        .replace("ex: {name: EAC", "ex: [exc, {name: EAC")
        .replace("harmonics: 2}", "harmonics: 2}]");
    let m = load(&text);
    let model = chain_core::derive(&m);
    let col = |name: &str| m.error_index(name).unwrap();
    for (x, c) in [(0.0, 0.0), (250.0, 0.7), (640.0, -2.1), (1000.0, 3.0)] {
        let (q, p) = ([x, c], [100.0]);
        let value = |s| SymbolicModel::symbol_value(s, &q, &p);
        let coefficient = |c: Component, name: &str| model.coefficient(c, col(name)).eval(&value);
        let check = |name: &str, constant: &str, b: f64| {
            for comp in Component::ALL {
                let got = coefficient(comp, name);
                let want = b * coefficient(comp, constant);
                assert!(
                    (got - want).abs() <= 1e-12 * (1.0 + want.abs()),
                    "{name} {} at x = {x}, C = {c}: {got} vs {want}",
                    comp.name()
                );
            }
        };
        check("EYX_1", "dyc", x);
        check("EYX_2", "dyc", x * x);
        let t = (2.0 * x - 1000.0) / 1000.0;
        for k in 0..=3 {
            check(&format!("EZX_{k}"), "dzc", legendre(k, t));
        }
        let t = (2.0 * x) / 1000.0;
        check("ECX_1", "ezc", chebyshev(1, t));
        check("ECX_2", "ezc", chebyshev(2, t));
        check("EXC_2", "dxc", c * c);
        check("EXC_0", "dxc", 1.0);
        check("EAC_0", "exc", 1.0);
        check("EAC_c1", "exc", c.cos());
        check("EAC_s1", "exc", c.sin());
        check("EAC_c2", "exc", (2.0 * c).cos());
        check("EAC_s2", "exc", (2.0 * c).sin());
        // The constant slot errors themselves act (the checks are not 0 = 0).
        for constant in ["dyc", "dzc", "ezc", "dxc", "exc"] {
            let acts = Component::ALL
                .iter()
                .any(|&comp| coefficient(comp, constant) != 0.0);
            assert!(acts, "{constant} does not act");
        }
    }
}

#[test]
fn a_function_declared_twice_reuses_its_coefficients() {
    let text = "\
machine: m
bodies:
  bed: {}
  x_slide:
    parent: bed
    joint: {type: prismatic, axis: +x, variable: x}
    errors:
      dy: {name: EYX, powers: [1, 2]}
      dz: [{name: EYX, powers: [1, 2]}, dzx]
workpiece: bed
tool: x_slide
";
    let m = load(text);
    assert_eq!(
        errors(&m),
        [
            ("EYX_1", ErrorKind::Linear),
            ("EYX_2", ErrorKind::Linear),
            ("dzx", ErrorKind::Linear)
        ]
    );
    assert_eq!(m.functions.len(), 1);
    assert_eq!(m.functions[0].origin.line, 8);
    assert_eq!(m.bodies[1].errors.slots[1], [0, 1]);
    assert_eq!(m.bodies[1].errors.slots[2], [0, 1, 2]);
}

// ---------------------------------------------------------------- errors: iso

const ISO: &str = "\
machine: iso
bodies:
  bed: {}
  x_slide:
    parent: bed
    joint: {type: prismatic, axis: +x, variable: x}
    errors: iso
    squareness: {ez: Sxy}
  spindle:
    parent: bed
    joint: {type: rotary, axis: +z, variable: c2}
    errors: iso
workpiece: x_slide
tool: spindle
statistics:
  EYX: {std: 0.001}
  ECC2: {std: 1e-5}
";

#[test]
fn iso_names_the_six_component_errors_after_the_variable() {
    let m = load(ISO);
    use ErrorKind::{Angular as A, Linear as L, Squareness as S};
    assert_eq!(
        errors(&m),
        [
            ("EXX", L),
            ("EYX", L),
            ("EZX", L),
            ("EAX", A),
            ("EBX", A),
            ("ECX", A),
            ("Sxy", S),
            // A multi-letter variable is upper-cased whole.
            ("EXC2", L),
            ("EYC2", L),
            ("EZC2", L),
            ("EAC2", A),
            ("EBC2", A),
            ("ECC2", A),
        ]
    );
    assert!(m.functions.is_empty());
    let slots = &m.bodies[1].errors.slots;
    for (s, slot) in slots.iter().enumerate() {
        let want: Vec<usize> = if s == 5 { vec![5, 6] } else { vec![s] };
        assert_eq!(*slot, want, "slot {s}");
    }
    assert_eq!(m.errors[0].origin.line, 7);
    assert_eq!(m.errors[0].origin.key, "bodies.x_slide.errors");
    assert_eq!(m.statistics[0].error, 1);
    assert_eq!(m.statistics[1].error, 12);
}

// ------------------------------------------------------------- v1 unchanged

/// The serialised machine of every v1 example, recorded before function
/// slots and `iso` existed (`tests/data/function_slots/v1/`): the loader
/// builds exactly the same machines.
#[test]
fn v1_example_machines_load_exactly_as_before() {
    let dir = common::root().join("examples/machines");
    let mut count = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().and_then(|e| e.to_str()) != Some("yaml") {
            continue;
        }
        let stem = path.file_stem().unwrap().to_str().unwrap().to_string();
        let file = format!("examples/machines/{stem}.yaml");
        let m = load_str(&std::fs::read_to_string(&path).unwrap(), &file).unwrap();
        let got = serde_json::to_string_pretty(&m).unwrap() + "\n";
        let recorded = common::root().join(format!("tests/data/function_slots/v1/{stem}.json"));
        let want = std::fs::read_to_string(&recorded).unwrap();
        assert!(got == want, "{file} loads differently from {recorded:?}");
        assert!(m.functions.is_empty());
        count += 1;
    }
    assert_eq!(count, 6);
}
