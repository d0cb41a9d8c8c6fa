//! The per-axis controller formats of `chain export` (measured-machines
//! spec, section 6; `docs/export-controllers.md`): each written file parsed
//! back by this test's own small parsers and checked field by field against
//! the values file; the correction applied as the controller applies it
//! (this test's own reading of the file: LinuxCNC's and CEC's linear tables
//! held at their ends, Klipper's `calc_skew`, Beckhoff's parametric model
//! through the numeric product) and the residual measured through the
//! independent numeric transform product of `tests/it/common` on vmc3 with
//! `examples/values/vmc3.yaml`: each format removes exactly the terms it can
//! express, and the report's residual is what the round trip leaves. Bad
//! input; and the examples under `examples/export/` regenerated
//! (`CHAIN_REGENERATE=1` rewrites them).

#![allow(clippy::needless_range_loop)]

use crate::common;

use chain::core::built::BuiltMachine;
use chain::core::compensation::controllers::{
    export, Controller, ControllerError, Export, ExportOptions, Takes,
};
use chain::core::values::Values;
use chain::core::{ErrorValues, Machine};
use chain::ops::export::ExportController;
use common::{example_file, load_example, Exact};

/// The formats of per-axis tables (the linear machines' formats).
fn per_axis() -> impl Iterator<Item = Controller> {
    (Controller::ALL.into_iter())
        .filter(|c| matches!(c.capabilities().takes, Takes::LinearAxes { .. }))
}

/// vmc3 and its example values.
fn vmc3() -> (Machine, Values) {
    let machine = load_example("vmc3.yaml");
    let values = Values::read(&example_file("values/vmc3.yaml"), &machine).unwrap();
    (machine, values)
}

/// The machine index of axis variable `name` (vmc3 lists y, x, z).
fn var(machine: &Machine, name: &str) -> usize {
    machine.variable_index(name).unwrap()
}

/// The export of `controller` with the default options, its files opening
/// with the words `chain export` writes.
fn run(controller: Controller, machine: &Machine, values: Values) -> Export {
    let built = BuiltMachine::compile(machine, values, vec![150.0]).unwrap();
    let options = ExportOptions {
        provenance: ExportController::Tables(controller).provenance(),
        ..ExportOptions::default()
    };
    export(controller, &built, machine, &options).unwrap()
}

fn file<'e>(export: &'e Export, name: &str) -> &'e str {
    &export
        .files
        .iter()
        .find(|f| f.name == name)
        .unwrap_or_else(|| panic!("no file {name}"))
        .text
}

/// The machine-ordered error values of the values file at `q`, with the
/// names in `zero` set to zero.
fn errors_at(machine: &Machine, values: &Values, q: &[f64], zero: &[&str]) -> Vec<f64> {
    let mut e = vec![0.0; machine.errors.len()];
    values.values_at(q, &mut e).unwrap();
    for z in zero {
        for (j, err) in machine.errors.iter().enumerate() {
            if err.name == *z || err.name.starts_with(&format!("{z}_")) {
                e[j] = 0.0;
            }
        }
    }
    e
}

/// The round trip through the numeric product: the tool point at
/// `q + δq` with the machine's errors there, against the nominal point of
/// `q`; position and orientation error.
fn residual(machine: &Machine, values: &Values, q: &[f64], dq: &[f64]) -> [f64; 6] {
    let exact = Exact::new(machine);
    let p = [150.0];
    let qc: Vec<f64> = q.iter().zip(dq).map(|(a, b)| a + b).collect();
    // The machine's own errors a few µm beyond its measured tables: held
    // (the corrected command may leave the travel by the correction).
    let travel = |i: usize| {
        if machine.variables[i].name == "x" {
            800.0
        } else {
            500.0
        }
    };
    let held_q: Vec<f64> = (0..qc.len()).map(|i| qc[i].clamp(0.0, travel(i))).collect();
    let e = errors_at(machine, values, &held_q, &[]);
    let t = exact.t_wt(&qc, &p, &e);
    let tp = exact.tool_point(&p);
    let a = common::transform_point(&t, tp);
    let (r0, b) = exact.nominal(q, &p);
    let ori = common::vee_skew(&common::mul3(
        &common::rotation(&t),
        &common::transpose3(&r0),
    ));
    [
        a[0] - b[0],
        a[1] - b[1],
        a[2] - b[2],
        ori[0],
        ori[1],
        ori[2],
    ]
}

/// The exact error of the machine at `q` with the names in `zero` zeroed.
fn error_without(machine: &Machine, values: &Values, q: &[f64], zero: &[&str]) -> [f64; 6] {
    let e = errors_at(machine, values, q, zero);
    Exact::new(machine).exact_error(q, &[150.0], &e)
}

/// The nominal tool-point motion per unit of each axis, by the numeric
/// product (finite difference over 100 mm: exact for a prismatic machine).
fn axis_directions(machine: &Machine) -> Vec<[f64; 3]> {
    let exact = Exact::new(machine);
    let q0 = vec![0.0; machine.variables.len()];
    (0..q0.len())
        .map(|i| {
            let mut q1 = q0.clone();
            q1[i] = 100.0;
            let a = exact.nominal(&q0, &[150.0]).1;
            let b = exact.nominal(&q1, &[150.0]).1;
            std::array::from_fn(|c| (b[c] - a[c]) / 100.0)
        })
        .collect()
}

/// Every node of the report's check grid (machine order).
fn check_points(export: &Export) -> Vec<Vec<f64>> {
    let grid = &export.report.check_grid;
    let mut points = vec![vec![]];
    for (_, g) in grid {
        points = points
            .into_iter()
            .flat_map(|p| {
                g.iter().map(move |x| {
                    let mut p = p.clone();
                    p.push(*x);
                    p
                })
            })
            .collect();
    }
    points
}

fn norm3(e: &[f64]) -> f64 {
    (e[0] * e[0] + e[1] * e[1] + e[2] * e[2]).sqrt()
}

/// Linear interpolation holding the end values (the test's own).
pub(crate) fn held(x: &[f64], v: &[f64], at: f64) -> f64 {
    if at <= x[0] {
        return v[0];
    }
    if at >= x[x.len() - 1] {
        return v[v.len() - 1];
    }
    let k = x.iter().position(|&t| t > at).unwrap();
    v[k - 1] + (v[k] - v[k - 1]) * (at - x[k - 1]) / (x[k] - x[k - 1])
}

/// The values file's value of error motion `name` at axis value `x` of
/// axis `var` (the other axes at 0).
fn value_of(machine: &Machine, values: &Values, name: &str, var: usize, x: f64) -> f64 {
    let mut q = vec![0.0; machine.variables.len()];
    q[var] = x;
    let e = errors_at(machine, values, &q, &[]);
    let j = machine
        .error_index(name)
        .or_else(|| machine.error_index(&format!("{name}_0")))
        .unwrap();
    e[j]
}

/// Checks the library's correction against the test's own application.
fn same_correction(export: &Export, q: &[f64], mine: &[f64], tol: f64) {
    let mut d = vec![0.0; q.len()];
    export.correction.delta(q, &mut d).unwrap();
    for i in 0..q.len() {
        assert!(
            (d[i] - mine[i]).abs() <= tol,
            "at {q:?}: correction {d:?}, the test's {mine:?}"
        );
    }
}

// ---------------------------------------------------------------------------
// LinuxCNC

/// The triplets LinuxCNC reads: lines of three numbers until the first line
/// that is not (`usrmotLoadComp`).
fn linuxcnc_triplets(text: &str) -> Vec<[f64; 3]> {
    let mut out = Vec::new();
    for line in text.lines() {
        let f: Vec<Option<f64>> = line
            .split_whitespace()
            .take(3)
            .map(|t| t.parse().ok())
            .collect();
        if f.len() != 3 || f.iter().any(Option::is_none) {
            break;
        }
        out.push([f[0].unwrap(), f[1].unwrap(), f[2].unwrap()]);
    }
    out
}

#[test]
fn linuxcnc_round_trip_removes_the_positioning_errors() {
    let (machine, values) = vmc3();
    let ex = run(Controller::Linuxcnc, &machine, values.clone());
    let dirs = axis_directions(&machine);
    // Field by field: positions 0..travel step 10, trims both directions
    // equal, trim = −(positioning error at the tool point) = −(J col ·
    // the error's translation), units mm.
    let mut tables = Vec::new();
    for (v, name, travel, axis) in [
        ("x", "EXX", 800.0, 0),
        ("y", "EYY", 500.0, 1),
        ("z", "EZZ", 500.0, 2),
    ] {
        let var = var(&machine, v);
        let text = file(&ex, &format!("{v}.comp"));
        let t = linuxcnc_triplets(text);
        // The entries: every 10 mm, and the measured table's own positions
        // between (LinuxCNC's nominals need not be evenly spaced).
        let measured =
            crate::reference::read_table(&example_file(&format!("values/{v}_axis.csv"))).1;
        let mut nominals: Vec<f64> = (0..=(travel / 10.0) as usize)
            .map(|k| 10.0 * k as f64)
            .collect();
        nominals.extend(
            measured[0]
                .iter()
                .copied()
                .filter(|q| *q < travel && q % 10.0 != 0.0),
        );
        nominals.sort_by(f64::total_cmp);
        assert_eq!(t.iter().map(|r| r[0]).collect::<Vec<_>>(), nominals, "{v}");
        assert!(text.contains("COMP_FILE_TYPE = 1"));
        assert!(text.lines().next().unwrap().starts_with("0 "), "data first");
        // How the error enters the tool point, by the numeric product.
        let mut e = vec![0.0; machine.errors.len()];
        e[machine.error_index(name).unwrap()] = 1e-3;
        let effect = Exact::new(&machine).exact_error(&[100.0, 100.0, 100.0], &[150.0], &e);
        let sign = (effect[axis] * dirs[var][axis]).signum();
        assert!((effect[axis].abs() - 1e-3).abs() < 1e-12);
        for row in &t {
            assert_eq!(row[1], row[2]);
            let want = -sign * value_of(&machine, &values, name, var, row[0]);
            assert!((row[1] - want).abs() < 1e-15, "{v} {row:?} {want}");
        }
        tables.push((var, t));
    }
    // Round trip on the check grid: the residual is the error without the
    // positioning errors, to second order (≤ 1 nm here, the error 20 µm).
    let mut worst: f64 = 0.0;
    let mut largest: f64 = 0.0;
    for q in check_points(&ex) {
        let mut dq = vec![0.0; 3];
        for (var, t) in &tables {
            let x: Vec<f64> = t.iter().map(|r| r[0]).collect();
            let v: Vec<f64> = t.iter().map(|r| r[1]).collect();
            dq[*var] = held(&x, &v, q[*var]);
        }
        same_correction(&ex, &q, &dq, 1e-15);
        let r = residual(&machine, &values, &q, &dq);
        let want = error_without(&machine, &values, &q, &["EXX", "EYY", "EZZ"]);
        let d: Vec<f64> = (0..3).map(|c| r[c] - want[c]).collect();
        assert!(norm3(&d) < 1e-6, "at {q:?}: {r:?} vs {want:?}");
        worst = worst.max(norm3(&r));
        largest = largest.max(norm3(&error_without(&machine, &values, &q, &[])));
    }
    assert!(
        (ex.report.residual.position - worst).abs() < 1e-6,
        "{} vs {worst}",
        ex.report.residual.position
    );
    assert!(
        largest > worst + 1e-3,
        "the positioning errors matter: {largest} vs {worst}"
    );
    let mut names: Vec<&str> = ex
        .report
        .expressed
        .iter()
        .map(|t| t.name.as_str())
        .collect();
    names.sort();
    assert_eq!(names, ["EXX", "EYY", "EZZ"]);
    assert!(ex.report.remaining.iter().any(|t| t.name == "EC0Y"));
    // Outside the table LinuxCNC holds its end values.
    let mut d = [0.0; 3];
    let (vx, vy) = (var(&machine, "x"), var(&machine, "y"));
    let mut q = [0.0; 3];
    q[vx] = 900.0;
    q[vy] = -50.0;
    ex.correction.delta(&q, &mut d).unwrap();
    let table = |v: usize| &tables.iter().find(|t| t.0 == v).unwrap().1;
    assert_eq!(d[vx], table(vx).last().unwrap()[1]);
    assert_eq!(d[vy], table(vy)[0][1]);
}

// ---------------------------------------------------------------------------
// Sinumerik CEC

#[derive(Debug, Default, Clone)]
struct CecTable {
    input: usize,
    output: usize,
    step: f64,
    min: f64,
    max: f64,
    values: Vec<(usize, f64)>,
}

/// `$AN_CEC...` assignments of the program, by table.
fn cec_tables(text: &str) -> Vec<CecTable> {
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "%_N_NC_CEC_INI");
    assert_eq!(lines[1], "CHANDATA(1)");
    assert_eq!(*lines.last().unwrap(), "M17");
    let mut tables: Vec<CecTable> = Vec::new();
    for line in &lines[2..lines.len() - 1] {
        let code = line.split(';').next().unwrap().trim();
        if code.is_empty() {
            continue;
        }
        let (lhs, rhs) = code.split_once('=').unwrap();
        let (var, index) = lhs.split_once('[').unwrap();
        let index = index.trim_end_matches(']');
        let (t, n) = match index.split_once(',') {
            Some((t, n)) => (
                t.parse::<usize>().unwrap(),
                Some(n.parse::<usize>().unwrap()),
            ),
            None => (index.parse::<usize>().unwrap(), None),
        };
        if tables.len() <= t {
            tables.resize(t + 1, CecTable::default());
        }
        let tab = &mut tables[t];
        let ax = |r: &str| {
            r.trim_start_matches("(AX")
                .trim_end_matches(')')
                .parse::<usize>()
                .unwrap()
                - 1
        };
        match var {
            "$AN_CEC" => tab.values.push((n.unwrap(), rhs.parse().unwrap())),
            "$AN_CEC_INPUT_AXIS" => tab.input = ax(rhs),
            "$AN_CEC_OUTPUT_AXIS" => tab.output = ax(rhs),
            "$AN_CEC_STEP" => tab.step = rhs.parse().unwrap(),
            "$AN_CEC_MIN" => tab.min = rhs.parse().unwrap(),
            "$AN_CEC_MAX" => tab.max = rhs.parse().unwrap(),
            "$AN_CEC_DIRECTION" | "$AN_CEC_MULT_BY_TABLE" | "$AN_CEC_IS_MODULO" => {
                assert_eq!(rhs, "0")
            }
            other => panic!("unexpected {other}"),
        }
    }
    tables
}

#[test]
fn cec_round_trip_removes_the_straightness_errors() {
    let (machine, values) = vmc3();
    let ex = run(Controller::SiemensCec, &machine, values.clone());
    let tables = cec_tables(file(&ex, "NC_CEC.INI"));
    let dirs = axis_directions(&machine);
    let expect = [
        ("EXY", "y", "x", 500.0),
        ("EZY", "y", "z", 500.0),
        ("EYX", "x", "y", 800.0),
        ("EZX", "x", "z", 800.0),
        ("EXZ", "z", "x", 500.0),
        ("EYZ", "z", "y", 500.0),
    ];
    assert_eq!(tables.len(), expect.len());
    for (t, (name, input, output, travel)) in tables.iter().zip(expect) {
        let (input, output) = (var(&machine, input), var(&machine, output));
        let frame_axis = |v: usize| (0..3).find(|&c| dirs[v][c] != 0.0).unwrap();
        assert_eq!((t.input, t.output), (input, output), "{name}");
        assert_eq!((t.min, t.max, t.step), (0.0, travel, 10.0), "{name}");
        let n = t.values.len();
        assert_eq!(t.max, t.min + (n - 1) as f64 * t.step);
        assert!(n <= 200, "MD18342 of the 828D");
        let mut e = vec![0.0; machine.errors.len()];
        let j = machine
            .error_index(name)
            .or_else(|| machine.error_index(&format!("{name}_0")))
            .unwrap();
        e[j] = 1e-3;
        let effect = Exact::new(&machine).exact_error(&[100.0, 100.0, 100.0], &[150.0], &e);
        let k = frame_axis(output);
        let sign = effect[k].signum() * dirs[output][k].signum();
        for (k, (idx, v)) in t.values.iter().enumerate() {
            assert_eq!(*idx, k);
            let want = sign * value_of(&machine, &values, name, input, t.min + k as f64 * t.step);
            assert!((v - want).abs() < 1e-15, "{name}[{k}] {v} {want}");
        }
    }
    let straightness = ["EYX", "EZX", "EXY", "EZY", "EXZ", "EYZ"];
    let mut worst: f64 = 0.0;
    for q in check_points(&ex) {
        let mut dq = vec![0.0; 3];
        for t in &tables {
            let x: Vec<f64> = (0..t.values.len())
                .map(|k| t.min + k as f64 * t.step)
                .collect();
            let v: Vec<f64> = t.values.iter().map(|p| p.1).collect();
            dq[t.output] -= held(&x, &v, q[t.input]);
        }
        same_correction(&ex, &q, &dq, 1e-15);
        let r = residual(&machine, &values, &q, &dq);
        let want = error_without(&machine, &values, &q, &straightness);
        let d: Vec<f64> = (0..3).map(|c| r[c] - want[c]).collect();
        assert!(norm3(&d) < 1e-6, "at {q:?}: {r:?} vs {want:?}");
        worst = worst.max(norm3(&r));
    }
    assert!((ex.report.residual.position - worst).abs() < 1e-6);
    // Between the nodes the controller's linear reading differs from the
    // cubic-spline straightness by what the report says, and no more.
    assert!(
        ex.report.resampling > 0.0 && ex.report.resampling < 1e-4,
        "{}",
        ex.report.resampling
    );
}

// ---------------------------------------------------------------------------
// Klipper

fn klipper_factors(text: &str) -> [f64; 3] {
    let get = |key: &str| -> f64 {
        text.lines()
            .find_map(|l| l.strip_prefix(&format!("{key} = ")))
            .unwrap_or_else(|| panic!("{key}"))
            .parse()
            .unwrap()
    };
    [get("xy_skew"), get("xz_skew"), get("yz_skew")]
}

/// Klipper's `calc_skew_factor` (skew_correction.py), ported.
fn calc_skew_factor(ac: f64, bd: f64, ad: f64) -> f64 {
    let side = (2.0 * ac * ac + 2.0 * bd * bd - 4.0 * ad * ad).sqrt() / 2.0;
    (std::f64::consts::FRAC_PI_2 - ((ac * ac - side * side - ad * ad) / (2.0 * side * ad)).acos())
        .tan()
}

#[test]
fn klipper_round_trip_removes_the_squareness_errors() {
    let (machine, values) = vmc3();
    let ex = run(Controller::Klipper, &machine, values.clone());
    let text = file(&ex, "skew_correction.cfg");
    let [xy, xz, yz] = klipper_factors(text);
    // The sign mapping, from the numeric product with only the squareness
    // errors: Klipper's model is e_x = xy·y + xz·z, e_y = yz·z.
    let only_sq = |q: &[f64]| {
        let mut e = vec![0.0; machine.errors.len()];
        for n in ["EC0Y", "EA0Z", "EB0Z"] {
            let j = machine.error_index(n).unwrap();
            let mut all = vec![0.0; machine.errors.len()];
            values.values_at(q, &mut all).unwrap();
            e[j] = all[j];
        }
        Exact::new(&machine).exact_error(q, &[150.0], &e)
    };
    let o = only_sq(&[0.0, 0.0, 0.0]);
    let slope = |v: &str, c: usize| {
        let mut q = [0.0; 3];
        q[var(&machine, v)] = 500.0;
        (only_sq(&q)[c] - o[c]) / 500.0
    };
    // The product is exact and the factors are first order: the slopes
    // differ by products of two of the angles, at most 15 · 10 µrad² =
    // 1.5e-10 (the X table's turn EC0Y carries the Z tilt −EA0Z·z into x:
    // xz's slope is EB0Z − EC0Y·EA0Z).
    let second = 2e-10;
    assert!(
        (xy - slope("y", 0)).abs() < second,
        "{xy} {}",
        slope("y", 0)
    );
    assert!(
        (xz - slope("z", 0)).abs() < second,
        "{xz} {}",
        slope("z", 0)
    );
    assert!(
        (yz - slope("z", 1)).abs() < second,
        "{yz} {}",
        slope("z", 1)
    );
    assert!((slope("z", 0) - (-10e-6 - 15e-6 * 8e-6)).abs() < 1e-14);
    // The named mapping for vmc3, in closed form. EC0Y (on the Y saddle,
    // after the Y joint) rotates the X table about +z: the tool relative to
    // the table is at x + EC0Y·y, so xy = EC0Y. EA0Z and EB0Z are location
    // errors of the Z head (before the Z joint): the head's frame is
    // rotated by (EA0Z, EB0Z, 0) about the column's point (0, 0, 250), and
    // the tool point, (0, 0, z − L) from there, moves by
    // (EA0Z, EB0Z, 0) × (0, 0, z − L) = ((z − L)·EB0Z, −(z − L)·EA0Z, 0):
    // xz = EB0Z, yz = −EA0Z (the constants −L·EB0Z, L·EA0Z stay). With the
    // values file's 15, 8, −10 µrad: xy = 15e-6, xz = −10e-6, yz = −8e-6;
    // the file's comment names the same mapping.
    assert!((xy - 15e-6).abs() < 1e-15, "{xy}");
    assert!((xz + 10e-6).abs() < 1e-15, "{xz}");
    assert!((yz + 8e-6).abs() < 1e-15, "{yz}");
    assert!(text.contains("#   xy_skew = 1·EC0Y\n"), "{text}");
    assert!(text.contains("#   xz_skew = 1·EB0Z\n"), "{text}");
    assert!(text.contains("#   yz_skew = -1·EA0Z\n"), "{text}");
    assert!(slope("x", 0).abs() < 1e-12);
    assert!(slope("x", 1).abs() < second && slope("y", 1).abs() < second);
    // The constant part left: the tilted tool, o = (−L·EB0Z, L·EA0Z, 0)
    // with L = 150 (y = 0 puts EC0Y's part at 0), to second order in the
    // angles times L: 150 mm · 1.5e-10 = 2.25e-8 mm.
    assert!((o[0] - 150.0 * 10e-6).abs() < 150.0 * second, "{o:?}");
    assert!((o[1] - 150.0 * 8e-6).abs() < 150.0 * second, "{o:?}");
    // The SET_SKEW lines give the same factors through Klipper's formula.
    for (plane, f) in [("XY", xy), ("XZ", xz), ("YZ", yz)] {
        let line = text
            .lines()
            .find(|l| l.contains(&format!("SET_SKEW {plane}=")))
            .unwrap();
        let v: Vec<f64> = line
            .split('=')
            .nth(1)
            .unwrap()
            .split(',')
            .map(|s| s.trim().parse().unwrap())
            .collect();
        assert!(
            (calc_skew_factor(v[0], v[1], v[2]) - f).abs() < 1e-9,
            "{plane}"
        );
    }
    // Round trip: Klipper's calc_skew applied to the command.
    let mut worst: f64 = 0.0;
    for q in check_points(&ex) {
        let (vx, vy, vz) = (var(&machine, "x"), var(&machine, "y"), var(&machine, "z"));
        let mut dq = vec![0.0; 3];
        dq[vx] = -q[vy] * xy - q[vz] * (xz - xy * yz);
        dq[vy] = -q[vz] * yz;
        same_correction(&ex, &q, &dq, 1e-12);
        let r = residual(&machine, &values, &q, &dq);
        let want = error_without(&machine, &values, &q, &["EC0Y", "EA0Z", "EB0Z"]);
        // What chain's squareness leaves besides the shear: its value at 0.
        let d: Vec<f64> = (0..3).map(|c| r[c] - want[c] - o[c]).collect();
        assert!(norm3(&d) < 1e-6, "at {q:?}: {r:?} vs {want:?}");
        worst = worst.max(norm3(&r));
    }
    assert!((ex.report.residual.position - worst).abs() < 1e-6);
}

// ---------------------------------------------------------------------------
// Beckhoff

/// The blocks of an ISG_CSV file: `//` comments skipped, `#` breaks; each a
/// header and rows.
pub(crate) fn isg_blocks(text: &str) -> Vec<(Vec<String>, Vec<Vec<f64>>)> {
    let mut blocks: Vec<(Vec<String>, Vec<Vec<f64>>)> = Vec::new();
    let mut current: Option<(Vec<String>, Vec<Vec<f64>>)> = None;
    for line in text.lines() {
        if line.starts_with("//") || line.trim().is_empty() {
            continue;
        }
        if line.starts_with('#') {
            blocks.extend(current.take());
            continue;
        }
        let fields: Vec<&str> = line.split_whitespace().collect();
        match &mut current {
            None => current = Some((fields.iter().map(|s| s.to_string()).collect(), vec![])),
            Some((h, rows)) => {
                assert_eq!(fields.len(), h.len(), "{line}");
                rows.push(fields.iter().map(|s| s.parse().unwrap()).collect());
            }
        }
    }
    blocks.extend(current);
    blocks
}

#[test]
fn beckhoff_round_trip_removes_the_position_error() {
    let (machine, values) = vmc3();
    let ex = run(Controller::Beckhoff, &machine, values.clone());
    let lis = file(&ex, "vol_comp_0.lis");
    assert!(lis.contains("file[0]                  chain_volcomp.csv"));
    assert!(lis.contains("file_format[0]           ISG_CSV"));
    let blocks = isg_blocks(file(&ex, "chain_volcomp.csv"));
    assert_eq!(blocks.len(), 4);
    // Single values, rad, ISO names without the E.
    let (h, rows) = &blocks[0];
    assert_eq!(rows.len(), 1);
    for (isg, chain) in [("C0Y", "EC0Y"), ("A0Z", "EA0Z"), ("B0Z", "EB0Z")] {
        let k = h.iter().position(|n| n == isg).unwrap();
        assert_eq!(rows[0][k], value_of(&machine, &values, chain, 0, 0.0));
    }
    // Tables: the argument first, mm; values the values file's at the nodes.
    let mut tables: Vec<(usize, Vec<String>, Vec<Vec<f64>>)> = Vec::new();
    for (b, (axis, v, travel)) in [("Y", "y", 500.0), ("X", "x", 800.0), ("Z", "z", 500.0)]
        .iter()
        .enumerate()
    {
        let var = &var(&machine, v);
        let (h, rows) = &blocks[b + 1];
        let want: Vec<String> = ["", "EX", "EY", "EZ", "EA", "EB", "EC"]
            .iter()
            .map(|p| {
                if p.is_empty() {
                    axis.to_string()
                } else {
                    format!("{p}{axis}")
                }
            })
            .collect();
        assert_eq!(h, &want);
        assert_eq!(rows.len(), (travel / 10.0) as usize + 1);
        for (k, row) in rows.iter().enumerate() {
            assert_eq!(row[0], 10.0 * k as f64);
            for c in 1..7 {
                let v = value_of(&machine, &values, &h[c], *var, row[0]);
                assert_eq!(row[c], v, "{} at {}", h[c], row[0]);
            }
        }
        tables.push((*var, h.clone(), rows.clone()));
    }
    // The controller's model: the parsed tables read linearly, the numeric
    // product; δq = −J⁻¹ Ê_p at the commanded position.
    let exact = Exact::new(&machine);
    let dirs = axis_directions(&machine);
    let seen = |q: &[f64]| {
        let mut e = vec![0.0; machine.errors.len()];
        for (k, name) in h.iter().enumerate() {
            let chain = format!("E{name}");
            e[machine.error_index(&chain).unwrap()] = rows[0][k];
        }
        for (var, h, rows) in &tables {
            let x: Vec<f64> = rows.iter().map(|r| r[0]).collect();
            for c in 1..7 {
                let v: Vec<f64> = rows.iter().map(|r| r[c]).collect();
                let j = machine
                    .error_index(&h[c])
                    .or_else(|| machine.error_index(&format!("{}_0", h[c])))
                    .unwrap();
                e[j] = held(&x, &v, q[*var]);
            }
        }
        exact.exact_error(q, &[150.0], &e)
    };
    let mut worst_o: f64 = 0.0;
    let mut mid: f64 = 0.0;
    let points = check_points(&ex);
    for (n, q) in points.iter().enumerate() {
        // The check nodes, and the same points shifted half a step (5 mm)
        // where the table's linear reading differs from the values' own.
        for shift in [0.0, 5.0] {
            let q: Vec<f64> = q
                .iter()
                .map(|x| if *x + shift > 500.0 { *x } else { x + shift })
                .collect();
            let e = seen(&q);
            let dq: Vec<f64> = (0..3)
                .map(|i| -(0..3).map(|c| dirs[i][c] * e[c]).sum::<f64>())
                .collect();
            same_correction(&ex, &q, &dq, 1e-6);
            let r = residual(&machine, &values, &q, &dq);
            let want = error_without(&machine, &values, &q, &[]);
            if shift == 0.0 {
                // Second order: the angular errors over the correction and
                // the exact product's ε² terms, ~1 nm of a ~20 µm error.
                assert!(norm3(&r) < 5e-6, "at {q:?}: position left {r:?}");
                for c in 3..6 {
                    assert!((r[c] - want[c]).abs() < 1e-9, "orientation stays");
                }
                worst_o = worst_o.max(norm3(&r[3..]));
            } else {
                mid = mid.max(norm3(&r));
                assert!(norm3(&r) < ex.report.resampling * 3.0 + 5e-6, "{n}: {r:?}");
            }
        }
    }
    assert!(ex.report.residual.position < 1e-12);
    assert!((ex.report.residual.orientation - worst_o).abs() < 1e-9);
    assert!(mid > 0.0);
}

// ---------------------------------------------------------------------------
// Bad input

fn err(
    controller: Controller,
    yaml: &str,
    values: &str,
    options: &ExportOptions,
) -> ControllerError {
    let machine = chain::core::load_str(yaml, "m.yaml").unwrap();
    let values = Values::parse(values, "v.yaml", ".".as_ref(), &machine).unwrap();
    let built = BuiltMachine::compile(&machine, values, vec![]).unwrap();
    export(controller, &built, &machine, options).unwrap_err()
}

const SQUARE_ONLY: &str = "machine: m\nbodies:\n  bed: {}\n  y: {parent: bed, joint: {type: prismatic, axis: +y, variable: y}, squareness: {ez: EC0Y}}\n  x: {parent: y, joint: {type: prismatic, axis: +x, variable: x}, errors: {dy: EYX}}\n  z: {parent: x, joint: {type: prismatic, axis: +z, variable: z}}\nworkpiece: bed\ntool: z\nreliability:\n  tolerance: {px: 0.01}\n  grid: {x: [0, 100], y: [0, 100], z: [0, 50]}\n";

#[test]
fn bad_input_is_refused_with_a_clear_message() {
    let none = ExportOptions::default();
    let e = err(
        Controller::Linuxcnc,
        SQUARE_ONLY,
        "machine: m\nvalues: {EC0Y: 1e-5}\n",
        &none,
    );
    assert!(matches!(e, ControllerError::NothingToExport { .. }), "{e}");
    assert!(e.to_string().contains("positioning error"), "{e}");
    let no_sq = SQUARE_ONLY.replace(", squareness: {ez: EC0Y}", "");
    let e = err(
        Controller::Klipper,
        &no_sq,
        "machine: m\nvalues: {}\n",
        &none,
    );
    assert!(e.to_string().contains("squareness"), "{e}");
    let rotary = "machine: r\nbodies:\n  bed: {}\n  c: {parent: bed, joint: {type: rotary, axis: +z, variable: c}, errors: iso}\nworkpiece: bed\ntool: c\ntool_point: [10, 0, 0]\n";
    for c in per_axis() {
        let e = err(c, rotary, "machine: r\nvalues: {}\n", &none);
        if c == Controller::Beckhoff {
            // Rotary axes besides three linear ones.
            assert!(
                matches!(e, ControllerError::AxisCount { found: 0, .. }),
                "{e}"
            );
            assert!(
                e.to_string().contains("and up to 3 rotary axes, one about each of X, Y, Z; machine `r` has 0 linear axes"),
                "{e}"
            );
            continue;
        }
        assert!(matches!(e, ControllerError::RotaryAxis { .. }), "{e}");
        assert!(e.to_string().contains("axis `c` is rotary"), "{e}");
    }
    // The rotary formats name the kind they take.
    let e = err(
        Controller::LinuxcncTrt,
        rotary,
        "machine: r\nvalues: {}\n",
        &none,
    );
    assert!(matches!(e, ControllerError::MachineKind { .. }), "{e}");
    assert!(
        e.to_string().contains("table-table five-axis machine")
            && e.to_string().contains("0 linear and 1 rotary"),
        "{e}"
    );
    // Two axes: Klipper and Beckhoff need three.
    let two = "machine: t\nbodies:\n  bed: {}\n  x: {parent: bed, joint: {type: prismatic, axis: +x, variable: x}, errors: iso, squareness: {ez: S}}\n  y: {parent: x, joint: {type: prismatic, axis: +y, variable: y}, errors: iso}\nworkpiece: bed\ntool: y\nreliability:\n  tolerance: {px: 0.01}\n  grid: {x: [0, 100], y: [0, 100]}\n";
    for c in [Controller::Klipper, Controller::Beckhoff] {
        let e = err(c, two, "machine: t\nvalues: {}\n", &none);
        assert!(
            matches!(e, ControllerError::AxisCount { found: 2, .. }),
            "{e}"
        );
    }
    // A table that does not cover the travel asked.
    let (machine, values) = vmc3();
    let built = BuiltMachine::compile(&machine, values, vec![150.0]).unwrap();
    let wide = ExportOptions {
        travel: vec![("x".into(), [0.0, 900.0])],
        ..ExportOptions::default()
    };
    for c in per_axis() {
        let e = export(c, &built, &machine, &wide).unwrap_err();
        let msg = e.to_string();
        assert!(
            matches!(e, ControllerError::OutOfTable { .. }),
            "{c:?}: {msg}"
        );
        assert!(
            msg.contains("x_axis.csv")
                && msg.contains("covers 0 to 800")
                && msg.contains("0 to 900"),
            "{msg}"
        );
    }
    // Options.
    let e = export(
        Controller::Linuxcnc,
        &built,
        &machine,
        &ExportOptions {
            step: 0.0,
            ..ExportOptions::default()
        },
    )
    .unwrap_err();
    assert!(matches!(e, ControllerError::BadStep { .. }), "{e}");
    let e = export(
        Controller::Linuxcnc,
        &built,
        &machine,
        &ExportOptions {
            step: 1.0,
            ..ExportOptions::default()
        },
    )
    .unwrap_err();
    assert!(
        e.to_string().contains("501 points") && e.to_string().contains("at most 256"),
        "{e}"
    );
    let e = export(
        Controller::SiemensCec,
        &built,
        &machine,
        &ExportOptions {
            step: 2.0,
            ..ExportOptions::default()
        },
    )
    .unwrap_err();
    assert!(e.to_string().contains("MD18342"), "{e}");
    let e = export(
        Controller::Linuxcnc,
        &built,
        &machine,
        &ExportOptions {
            travel: vec![("w".into(), [0.0, 1.0])],
            ..ExportOptions::default()
        },
    )
    .unwrap_err();
    assert!(matches!(e, ControllerError::UnknownAxis { .. }), "{e}");
    assert!(Controller::from_name("fanuc").is_none());
    assert_eq!(
        Controller::from_name("siemens-cec"),
        Some(Controller::SiemensCec)
    );
}

// ---------------------------------------------------------------------------
// Examples

#[test]
fn examples_are_the_current_export() {
    let (machine, values) = vmc3();
    let regenerate = std::env::var_os("CHAIN_REGENERATE").is_some();
    for c in per_axis() {
        let ex = run(c, &machine, values.clone());
        let dir = example_file("export").join(c.name());
        for f in &ex.files {
            let path = dir.join(&f.name);
            if regenerate {
                std::fs::create_dir_all(&dir).unwrap();
                std::fs::write(&path, &f.text).unwrap();
            } else {
                let committed = std::fs::read_to_string(&path).unwrap_or_else(|_| {
                    panic!(
                        "{} is missing; rerun with CHAIN_REGENERATE=1",
                        path.display()
                    )
                });
                assert!(
                    committed == f.text,
                    "{} differs from the export; rerun with CHAIN_REGENERATE=1",
                    path.display()
                );
            }
        }
    }
}
