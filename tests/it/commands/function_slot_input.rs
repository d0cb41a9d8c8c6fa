//! Function slots (error motions that vary along their axis) and `errors:
//! iso` in machine files (measured-machines spec, section 1): the valid
//! forms give exactly the named coefficients, kinds and function records;
//! every refusal is one located diagnostic naming the file, line and key, and
//! `chain derive` exits non-zero on it. The v1 example machines (without
//! function slots) load exactly to their recorded machines.

use crate::common;

use chain_core::model::{Basis, BasisFn, Component, ErrorKind, Machine};
use chain_core::{load_str, Diagnostics, SymbolicModel};
use common::cli::{fails, ok_json, scratch_file, unwrapped};

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

/// The serialised machine of every v1 example, recorded by a loader without
/// function slots and `iso` (`tests/data/function_slots/v1/`): the loader
/// builds exactly the same machines.
#[test]
fn v1_example_machines_load_exactly_as_before() {
    // The six v1 example machines, those recorded under
    // `tests/data/function_slots/v1/` (the other examples are not v1 files).
    let v1 = [
        "ac_trunnion",
        "cnc5_bevel",
        "cradle_generator",
        "gantry_grinder",
        "head_head_bc",
        "internal_grinder",
    ];
    for stem in v1 {
        let file = format!("examples/machines/{stem}.yaml");
        let path = common::root().join(&file);
        let m = load_str(&std::fs::read_to_string(&path).unwrap(), &file).unwrap();
        let got = serde_json::to_string_pretty(&m).unwrap() + "\n";
        let recorded = common::root().join(format!("tests/data/function_slots/v1/{stem}.json"));
        let want = std::fs::read_to_string(&recorded).unwrap();
        assert!(got == want, "{file} loads differently from {recorded:?}");
        assert!(m.functions.is_empty());
    }
}

// ---------------------------------------------------------------- refusals

/// Where the marker `⟨` is in `marked` (1-based line, column in
/// characters), and the text without it.
fn locate(marked: &str) -> (String, usize, usize) {
    let at = marked.find('⟨').expect("a ⟨ marks where the error points");
    let before = &marked[..at];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().unwrap_or("").chars().count() + 1;
    (marked.replacen('⟨', "", 1), line, column)
}

/// The one error of `text`, which must not load.
#[track_caller]
fn diagnose(text: &str) -> Diagnostics {
    match load_str(text, "fs.yaml") {
        Ok(m) => panic!("expected an error, loaded {:?}", m.name),
        Err(d) => d,
    }
}

/// Asserts that the marked text is refused with exactly one error, at the
/// marker, naming `key`, with code `code` and `needle` in its message; and
/// that `chain derive` on it exits non-zero naming the file, line, column,
/// key and code. Returns the message.
#[track_caller]
fn refused(marked: &str, key: &str, code: &str, needle: &str) -> String {
    let (text, line, column) = locate(marked);
    let d = diagnose(&text);
    assert_eq!(d.len(), 1, "expected one error, got:\n{d:#}");
    let msg = d.to_string();
    let prefix = format!("fs.yaml:{line}:{column}: ");
    assert!(msg.starts_with(&prefix), "expected {prefix:?}, got:\n{msg}");
    assert!(
        msg.contains(&format!("at key `{key}`")),
        "expected key `{key}`, got:\n{msg}"
    );
    // The headline and its note, without the location between them.
    let problem = d.first().problem.to_string();
    assert!(problem.contains(needle), "expected {needle:?} in:\n{msg}");
    assert_eq!(d.first().problem.code(), code, "{msg}");

    // The CLI: non-zero exit, nothing on stdout, the location on stderr.
    let name = format!("{}.yaml", code.replace("::", "_"));
    let path = scratch_file(&format!("{}-{line}-{column}", name), &text);
    let path = path.to_str().unwrap();
    let stderr = unwrapped(&fails(&["derive", path]));
    assert!(
        stderr.contains(&format!("{path}:{line}:{column}")),
        "stderr:\n{stderr}"
    );
    assert!(stderr.contains(key), "stderr:\n{stderr}");
    assert!(stderr.contains(code), "stderr:\n{stderr}");
    msg
}

/// A valid machine with a prismatic (`x`) and a rotary (`C`) axis; `SLOT`
/// (line 8) and `TABLE` (line 12) are replaced by the tests.
const TEMPLATE: &str = "\
machine: m
parameters: {L: 100}
bodies:
  bed: {}
  x_slide:
    parent: bed
    joint: {type: prismatic, axis: +x, variable: x}
    errors: {dx: dxx, dy: SLOT}
  c_table:
    parent: bed
    joint: {type: rotary, axis: +z, variable: C}
    errors: {ex: TABLE}
workpiece: bed
tool: x_slide
";

/// `TEMPLATE` with the `dy` slot of `x_slide` (line 8) set to `slot`.
fn x_dy(slot: &str) -> String {
    TEMPLATE.replace("SLOT", slot).replace("TABLE", "exc")
}

/// `TEMPLATE` with the `ex` slot of `c_table` (line 12) set to `slot`.
fn c_ex(slot: &str) -> String {
    TEMPLATE.replace("SLOT", "dyx").replace("TABLE", slot)
}

#[test]
fn template_loads() {
    let m = load(&x_dy("{name: EYX, powers: [1, 2]}"));
    assert_eq!(m.functions.len(), 1);
    let m = load(&c_ex("{name: EAC, basis: fourier, harmonics: 1}"));
    assert_eq!(m.functions[0].coefficients.len(), 3);
}

#[test]
fn ranges_and_orders_are_numbers_or_arithmetic() {
    // A rotary axis in radians: `pi` is allowed, as in every number.
    let m = load(&c_ex(
        "{name: EAC, basis: legendre, degree: 1+1, range: [-pi/2, pi/2], from: 1}",
    ));
    let h = std::f64::consts::FRAC_PI_2;
    assert_eq!(
        m.functions[0].basis,
        Basis::Legendre {
            degree: 2,
            range: [-h, h],
            from: 1
        }
    );
    assert_eq!(m.functions[0].variable, m.variable_index("C").unwrap());
    // `degree: 0` and `harmonics: 0` are the constant alone.
    let m = load(&c_ex("{name: EAC, basis: fourier, harmonics: 0}"));
    assert_eq!(m.functions[0].coefficients, [(2, BasisFn::Cos(0))]);
    assert_eq!(m.errors[2].name, "EAC_0");
}

#[test]
fn function_slot_on_a_body_without_a_joint() {
    let text = TEMPLATE
        .replace(
            "  bed: {}",
            "  bed: {errors: {dy: ⟨{name: EYB, powers: [1]}}}",
        )
        .replace("SLOT", "dyx")
        .replace("TABLE", "exc");
    let msg = refused(
        &text,
        "bodies.bed.errors.dy",
        "chain::function_without_joint",
        "body `bed` has no joint",
    );
    assert!(msg.contains("cannot vary along an axis"), "{msg}");
}

#[test]
fn function_slot_in_location_errors_or_squareness() {
    let text = x_dy("dyx}\n    location_errors: {dz: ⟨{name: F, powers: [1]}");
    refused(
        &text,
        "bodies.x_slide.location_errors.dz",
        "chain::function_not_allowed",
        "`location_errors` takes error names only",
    );
    let text = x_dy("dyx}\n    squareness: {ez: [Sxy, ⟨{name: F, powers: [1]}]");
    refused(
        &text,
        "bodies.x_slide.squareness.ez[1]",
        "chain::function_not_allowed",
        "`squareness` takes error names only",
    );
}

#[test]
fn fourier_on_a_prismatic_joint() {
    let msg = refused(
        &x_dy("{name: EYX, basis: ⟨fourier, harmonics: 2}"),
        "bodies.x_slide.errors.dy.basis",
        "chain::fourier_on_prismatic",
        "a fourier basis needs a rotary joint, but body `x_slide` is prismatic",
    );
    assert!(!msg.contains("harmonics"), "{msg}");
}

#[test]
fn legendre_or_chebyshev_without_range() {
    for basis in ["legendre", "chebyshev"] {
        refused(
            &x_dy(&format!("⟨{{name: EYX, basis: {basis}, degree: 3}}")),
            "bodies.x_slide.errors.dy",
            "chain::missing_range",
            &format!("a {basis} basis needs `range: [lo, hi]`"),
        );
    }
}

#[test]
fn empty_or_reversed_range() {
    refused(
        &x_dy("{name: EYX, basis: legendre, degree: 3, range: ⟨[1000, 0]}"),
        "bodies.x_slide.errors.dy.range",
        "chain::range_order",
        "needs lo < hi, got lo = 1000, hi = 0",
    );
    refused(
        &x_dy("{name: EYX, basis: chebyshev, degree: 3, range: ⟨[5, 5]}"),
        "bodies.x_slide.errors.dy.range",
        "chain::range_order",
        "got lo = 5, hi = 5",
    );
}

#[test]
fn non_finite_or_malformed_range() {
    refused(
        &x_dy("{name: EYX, basis: legendre, degree: 3, range: [0, ⟨.inf]}"),
        "bodies.x_slide.errors.dy.range[1]",
        "chain::not_finite",
        "a range end must be finite",
    );
    refused(
        &x_dy("{name: EYX, basis: legendre, degree: 3, range: ⟨[0, 1, 2]}"),
        "bodies.x_slide.errors.dy.range",
        "chain::wrong_length",
        "expected a list of 2 items, found 3",
    );
}

#[test]
fn degree_or_harmonics_negative_fractional_or_above_12() {
    for bad in ["-1", "2.5", "13"] {
        refused(
            &x_dy(&format!(
                "{{name: EYX, basis: legendre, degree: ⟨{bad}, range: [0, 1]}}"
            )),
            "bodies.x_slide.errors.dy.degree",
            "chain::bad_order",
            &format!("the degree must be a whole number from 0 to 12, got {bad}"),
        );
        refused(
            &c_ex(&format!("{{name: EAC, basis: fourier, harmonics: ⟨{bad}}}")),
            "bodies.c_table.errors.ex.harmonics",
            "chain::bad_order",
            &format!("the harmonic count must be a whole number from 0 to 12, got {bad}"),
        );
    }
    // 12 is the limit, and included.
    let m = load(&x_dy(
        "{name: EYX, basis: legendre, degree: 12, range: [0, 1]}",
    ));
    assert_eq!(m.errors.len(), 1 + 13 + 1);
    let m = load(&c_ex("{name: EAC, basis: fourier, harmonics: 12}"));
    assert_eq!(m.functions[0].coefficients.len(), 25);
}

#[test]
fn power_lists() {
    refused(
        &x_dy("{name: EYX, powers: ⟨[]}"),
        "bodies.x_slide.errors.dy.powers",
        "chain::empty_list",
        "the power list must not be empty",
    );
    let msg = refused(
        &x_dy("{name: EYX, powers: [1, 2, ⟨1]}"),
        "bodies.x_slide.errors.dy.powers[2]",
        "chain::duplicate_power",
        "power 1 is listed twice (first as item 0)",
    );
    assert!(!msg.contains("power 2"), "{msg}");
    refused(
        &x_dy("{name: EYX, powers: [1, ⟨-2]}"),
        "bodies.x_slide.errors.dy.powers[1]",
        "chain::bad_order",
        "a power must be a whole number from 0 to 12, got -2",
    );
    refused(
        &x_dy("{name: EYX, powers: [⟨1.5]}"),
        "bodies.x_slide.errors.dy.powers[0]",
        "chain::bad_order",
        "got 1.5",
    );
    refused(
        &x_dy("{name: EYX, powers: ⟨2}"),
        "bodies.x_slide.errors.dy.powers",
        "chain::wrong_type",
        "expected a list of powers, found `2`",
    );
}

#[test]
fn from_above_degree() {
    refused(
        &x_dy("{name: EYX, basis: chebyshev, degree: 2, range: [0, 1], from: ⟨3}"),
        "bodies.x_slide.errors.dy.from",
        "chain::from_above_degree",
        "`from` (3) is above `degree` (2)",
    );
    // from = degree leaves one coefficient.
    let m = load(&x_dy(
        "{name: EYX, basis: chebyshev, degree: 2, range: [0, 1], from: 2}",
    ));
    assert_eq!(m.errors[1].name, "EYX_2");
    assert_eq!(m.functions[0].coefficients.len(), 1);
}

#[test]
fn unknown_key_in_a_function_slot() {
    // The misspelt `powers` is not also reported as a missing basis.
    refused(
        &x_dy("{name: EYX, ⟨power: [1, 2]}"),
        "bodies.x_slide.errors.dy.power",
        "chain::unknown_key",
        "unknown key `power` (did you mean `powers`?",
    );
    refused(
        &x_dy("{name: EYX, basis: legendre, ⟨ragne: [0, 1], degree: 2}"),
        "bodies.x_slide.errors.dy.ragne",
        "chain::unknown_key",
        "did you mean `range`?",
    );
}

#[test]
fn keys_that_do_not_belong_to_the_basis() {
    refused(
        &x_dy("{name: EYX, powers: [1], ⟨range: [0, 1]}"),
        "bodies.x_slide.errors.dy.range",
        "chain::key_not_for_basis",
        "`range` does not apply to a powers basis (a powers basis takes name, powers)",
    );
    refused(
        &x_dy("{name: EYX, basis: legendre, degree: 2, range: [0, 1], ⟨harmonics: 2}"),
        "bodies.x_slide.errors.dy.harmonics",
        "chain::key_not_for_basis",
        "`harmonics` does not apply to a legendre basis",
    );
    refused(
        &c_ex("{name: EAC, basis: fourier, harmonics: 2, ⟨degree: 2}"),
        "bodies.c_table.errors.ex.degree",
        "chain::key_not_for_basis",
        "`degree` does not apply to a fourier basis (a fourier basis takes name, basis, harmonics)",
    );
}

#[test]
fn both_powers_and_basis_or_neither() {
    refused(
        &x_dy("{name: EYX, powers: [1], ⟨basis: legendre}"),
        "bodies.x_slide.errors.dy.basis",
        "chain::conflicting_keys",
        "`powers` and `basis` cannot both be given",
    );
    refused(
        &x_dy("⟨{name: EYX}"),
        "bodies.x_slide.errors.dy",
        "chain::missing_basis",
        "a function slot needs `powers: [..]` or `basis: legendre | chebyshev | fourier`",
    );
}

#[test]
fn unknown_basis() {
    refused(
        &x_dy("{name: EYX, basis: ⟨legendr, degree: 2, range: [0, 1]}"),
        "bodies.x_slide.errors.dy.basis",
        "chain::unknown_value",
        "unknown basis `legendr` (did you mean `legendre`? expected one of legendre, chebyshev, fourier)",
    );
    let (text, _, _) = locate(&x_dy("{name: EYX, basis: ⟨powers}"));
    let d = diagnose(&text);
    assert_eq!(d.len(), 1, "{d:#}");
    assert_eq!(
        d.first().problem.help().as_deref(),
        Some("the power basis is written `powers: [1, 2]`, without `basis`")
    );
}

#[test]
fn missing_or_invalid_function_name() {
    refused(
        &x_dy("⟨{powers: [1, 2]}"),
        "bodies.x_slide.errors.dy",
        "chain::missing_key",
        "missing required key `name`",
    );
    refused(
        &x_dy("{name: ⟨2EYX, powers: [1, 2]}"),
        "bodies.x_slide.errors.dy.name",
        "chain::invalid_name",
        "`2EYX` is not a valid function name",
    );
}

#[test]
fn coefficient_name_clashes() {
    // With an error parameter used earlier.
    let msg = refused(
        &x_dy("{name: ⟨EYX, powers: [1, 2]}").replace("dx: dxx", "dx: EYX_2"),
        "bodies.x_slide.errors.dy.name",
        "chain::name_collision",
        "coefficient `EYX_2` of function `EYX` has the same name as the error parameter `EYX_2` (first used on line 8)",
    );
    assert!(!msg.contains("EYX_1"), "{msg}");
    // With an error parameter used later: the plain use is refused.
    refused(
        &x_dy("{name: EYX, powers: [1, 2]}").replace("ex: exc", "ex: ⟨EYX_1"),
        "bodies.c_table.errors.ex",
        "chain::name_collision",
        "error parameter `EYX_1` has the same name as a coefficient of function `EYX` (declared on line 8)",
    );
    // With a parameter and an axis variable.
    refused(
        &c_ex("{name: E, powers: [1]}")
            .replace("variable: C", "variable: E_1")
            .replace("{name: E", "{name: ⟨E"),
        "bodies.c_table.errors.ex.name",
        "chain::name_collision",
        "coefficient `E_1` of function `E` has the same name as the axis variable `E_1`",
    );
    refused(
        &x_dy("{name: ⟨L, powers: [1]}"),
        "bodies.x_slide.errors.dy.name",
        "chain::name_collision",
        "function `L` has the same name as the parameter `L`",
    );
    refused(
        &x_dy("{name: ⟨C, powers: [1]}"),
        "bodies.x_slide.errors.dy.name",
        "chain::name_collision",
        "function `C` has the same name as the axis variable `C`",
    );
    // The function's own name is no error parameter either.
    refused(
        &x_dy("{name: ⟨dxx, powers: [1]}"),
        "bodies.x_slide.errors.dy.name",
        "chain::name_collision",
        "function `dxx` has the same name as the error parameter `dxx` (first used on line 8)",
    );
    refused(
        &x_dy("{name: EYX, powers: [1]}").replace("ex: exc", "ex: ⟨EYX"),
        "bodies.c_table.errors.ex",
        "chain::name_collision",
        "error parameter `EYX` has the same name as function `EYX` (declared on line 8)",
    );
    // A function named like another function's coefficient.
    refused(
        &x_dy("[{name: E, powers: [1]}, {name: ⟨E_1, powers: [1]}]"),
        "bodies.x_slide.errors.dy[1].name",
        "chain::name_collision",
        "function `E_1` has the same name as a coefficient of function `E` (declared on line 8)",
    );
}

#[test]
fn a_function_declared_twice_differently() {
    let first = "{name: EYX, powers: [1, 2]}";
    refused(
        &x_dy(first).replace("dx: dxx", "dx: dxx, dz: {name: ⟨EYX, powers: [1]}"),
        "bodies.x_slide.errors.dz.name",
        "chain::function_redeclared",
        "function `EYX` is declared again with a different basis (powers [1] here, powers [1, 2] first) (first declared on line 8)",
    );
    refused(
        &x_dy(first).replace("ex: exc", "ex: exc, dx: {name: ⟨EYX, powers: [1, 2]}"),
        "bodies.c_table.errors.dx.name",
        "chain::function_redeclared",
        "function `EYX` is declared again on another axis (variable `C` here, `x` first)",
    );
    refused(
        &x_dy(first).replace("dx: dxx", "dx: dxx, ez: {name: ⟨EYX, powers: [1, 2]}"),
        "bodies.x_slide.errors.ez.name",
        "chain::function_redeclared",
        "in a slot of another kind (an angular slot (ex, ey, ez) here, a linear slot (dx, dy, dz) first)",
    );
    refused(
        &x_dy("{name: EYX, basis: legendre, degree: 2, range: [0, 1000]}").replace(
            "dx: dxx",
            "dx: dxx, dz: {name: ⟨EYX, basis: legendre, degree: 2, range: [0, 999]}",
        ),
        "bodies.x_slide.errors.dz.name",
        "chain::function_redeclared",
        "(legendre degree 2 on [0, 999] here, legendre degree 2 on [0, 1000] first)",
    );
}

#[test]
fn statistics_on_a_function_name_point_at_its_coefficients() {
    let text = x_dy("{name: EYX, powers: [1, 2]}") + "statistics:\n  ⟨EYX: {std: 1e-6}\n";
    let msg = refused(
        &text,
        "statistics.EYX",
        "chain::unknown_error",
        "statistics for `EYX`, a function slot, not an error parameter (did you mean `EYX_1`?)",
    );
    let (text, _, _) = locate(&text);
    let d = diagnose(&text);
    assert_eq!(
        d.first().problem.help().as_deref(),
        Some("statistics go on the coefficients of `EYX`: EYX_1, EYX_2"),
        "{msg}"
    );
    // A coefficient the function does not have.
    let text = x_dy("{name: EYX, powers: [1, 2]}") + "statistics:\n  ⟨EYX_3: {std: 1e-6}\n";
    refused(
        &text,
        "statistics.EYX_3",
        "chain::unknown_error",
        "did you mean `EYX_1`?",
    );
    // Also when a second declaration of the function was refused.
    let text = x_dy("{name: EYX, powers: [1, 2]}")
        .replace("dx: dxx", "dx: dxx, dz: {name: EYX, powers: [-1]}")
        + "statistics:\n  EYX: {std: 1e-6}\n";
    let codes: Vec<&str> = diagnose(&text).iter().map(|e| e.problem.code()).collect();
    assert_eq!(codes, ["chain::bad_order", "chain::unknown_error"]);
}

#[test]
fn a_refused_function_does_not_cascade() {
    // Statistics on the coefficients of a refused function, a misspelt
    // `joint`: one message each.
    let text = x_dy("{name: EYX, basis: legendre, degree: ⟨13, range: [0, 1]}")
        + "statistics:\n  EYX_1: {std: 1e-6}\n  EYX: {std: 1e-6}\n";
    refused(
        &text,
        "bodies.x_slide.errors.dy.degree",
        "chain::bad_order",
        "got 13",
    );
    let text = x_dy("{name: EYX, powers: [1]}").replacen("    joint:", "    ⟨jiont:", 1)
        + "statistics:\n  EYX_1: {std: 1e-6}\n";
    refused(
        &text,
        "bodies.x_slide.jiont",
        "chain::unknown_key",
        "did you mean `joint`?",
    );
    let text = x_dy("dyx")
        .replacen("    joint:", "    ⟨jiont:", 1)
        .replace("{dx: dxx, dy: dyx}", "iso");
    refused(
        &text,
        "bodies.x_slide.jiont",
        "chain::unknown_key",
        "did you mean `joint`?",
    );
}

#[test]
fn several_refusals_are_reported_at_once() {
    let text = x_dy("{name: EYX, basis: fourier, harmonics: 2}")
        .replace(
            "ex: exc",
            "ex: {name: EAC, basis: chebyshev, degree: 14, range: [1, 0]}",
        )
        .replace("  bed: {}", "  bed: {errors: iso}");
    let d = diagnose(&text);
    let found: Vec<(usize, &str, &str)> = d
        .iter()
        .map(|e| (e.origin.line, e.origin.key.as_str(), e.problem.code()))
        .collect();
    assert_eq!(
        found,
        [
            (4, "bodies.bed.errors", "chain::iso_without_joint"),
            (
                8,
                "bodies.x_slide.errors.dy.basis",
                "chain::fourier_on_prismatic"
            ),
            (12, "bodies.c_table.errors.ex.degree", "chain::bad_order"),
            (12, "bodies.c_table.errors.ex.range", "chain::range_order"),
        ],
        "{d:#}"
    );
}

// ---------------------------------------------------------- errors: iso refusals

#[test]
fn iso_on_a_body_without_a_joint() {
    let text = x_dy("dyx").replace("  bed: {}", "  bed: {errors: ⟨iso}");
    refused(
        &text,
        "bodies.bed.errors",
        "chain::iso_without_joint",
        "`errors: iso` names the errors after the joint variable, but body `bed` has no joint",
    );
}

#[test]
fn another_scalar_than_iso() {
    refused(
        &x_dy("dyx").replace("errors: {dx: dxx, dy: dyx}", "errors: ⟨ISO"),
        "bodies.x_slide.errors",
        "chain::errors_value",
        "`errors` must be a mapping of slots or `iso`, found `ISO` (did you mean `iso`?)",
    );
    let msg = refused(
        &x_dy("dyx").replace("errors: {dx: dxx, dy: dyx}", "errors: ⟨dxx"),
        "bodies.x_slide.errors",
        "chain::errors_value",
        "found `dxx`",
    );
    assert!(!msg.contains("did you mean"), "{msg}");
}

#[test]
fn iso_only_as_errors() {
    refused(
        &x_dy("dyx}\n    location_errors: ⟨iso\n    squareness: {ez: S"),
        "bodies.x_slide.location_errors",
        "chain::iso_not_allowed",
        "`location_errors` cannot be `iso`",
    );
}

#[test]
fn iso_of_two_variables_that_upper_case_alike() {
    let text = x_dy("dyx")
        .replace("errors: {dx: dxx, dy: dyx}", "errors: iso")
        .replace(
            "variable: C}\n    errors: {ex: exc}",
            "variable: X}\n    errors: ⟨iso",
        );
    let (plain, _, _) = locate(&text);
    let d = diagnose(&plain);
    // One message per clashing name (all six), at the second `iso`.
    assert_eq!(d.len(), 6, "{d:#}");
    let first = refused_first(&d);
    assert!(
        first.contains(
            "`errors: iso` of body `c_table` names `EXX`, as does `errors: iso` of body `x_slide`"
        ),
        "{first}"
    );
    let (_, line, column) = locate(&text);
    assert!(
        first.starts_with(&format!("fs.yaml:{line}:{column}: ")),
        "{first}"
    );
}

fn refused_first(d: &Diagnostics) -> String {
    d.first().to_string()
}

#[test]
fn iso_names_clash_like_any_name() {
    // `EXX` of `errors: iso` is also a parameter.
    refused(
        &x_dy("dyx")
            .replace("parameters: {L: 100}", "parameters: {EXX: 1}")
            .replace("errors: {dx: dxx, dy: dyx}", "errors: ⟨iso"),
        "bodies.x_slide.errors",
        "chain::name_collision",
        "error `EXX` has the same name as a parameter",
    );
}

// -------------------------------------------------------------------- the CLI

#[test]
fn derive_json_lists_the_coefficients_in_errors() {
    let path = scratch_file("functions.yaml", FUNCTIONS);
    let json = ok_json(&["derive", path.to_str().unwrap(), "--format", "json"]);
    let names: Vec<&str> = json["errors"]
        .as_array()
        .expect("errors is a list")
        .iter()
        .map(|e| e.as_str().expect("a name"))
        .collect();
    let m = load(FUNCTIONS);
    let want: Vec<&str> = m.errors.iter().map(|e| e.name.as_str()).collect();
    assert_eq!(names, want);
    assert!(names.contains(&"EAC_s2") && names.contains(&"EZX_3"));
}
