//! `chain map` and the built-machine library API (measured-machines spec,
//! section 3) against an independent computation: `E(q) = Σ_j c_j(q)·v_j(q)`
//! with `c_j` the finite difference of the exact numeric 4×4 product of
//! `tests/it/common` (not chain's derivation) and `v_j` the test's own reading
//! and interpolation of the example tables (`tests/it/reference`), at the knots
//! and between them; the JSON document's shape, the CSV and table forms,
//! grids, `--axes`, out-of-range points and `extrapolate: hold`, units,
//! plots, the generated `machine!` type, and results independent of the
//! thread count.

// Component loops read best with explicit indices.
#![allow(clippy::needless_range_loop)]

use crate::common;
use crate::reference;

use std::collections::HashMap;

use chain::core::built::{full_factorial, BuiltMachine, MapError, PartKind, Points};
use chain::core::values::Values;
use chain::core::{ErrorModel, Machine};
use common::cli::{chain, fails, ok_json, ok_stdout, scratch, success, unwrapped, write};
use common::{example_file, example_path, load_example, Exact};
use reference::{linear, read_table, Spline};
use serde_json::Value;

chain::machine!(Vmc3 = "examples/machines/vmc3.yaml");

const MACHINE: &str = "examples/machines/vmc3.yaml";
const VALUES: &str = "examples/values/vmc3.yaml";
const LEGENDRE: &str = "examples/values/vmc3_legendre.yaml";

/// The straightness motions of examples/values/vmc3.yaml, read by cubic
/// splines (the file says so; the others are linear).
const CUBIC: [&str; 5] = ["EYX", "EZX", "EZY", "EXZ", "EYZ"];

/// One error's value as a function of the machine-ordered axis values.
type Motion = Box<dyn Fn(&[f64]) -> f64>;

/// The test's own `v(q)` for the vmc3 values files: per machine error, a
/// function of the machine-ordered axis values.
struct Reference {
    machine: Machine,
    values: Vec<Motion>,
}

impl Reference {
    /// `legendre`: examples/values/vmc3_legendre.yaml (EYX by its
    /// coefficients) instead of examples/values/vmc3.yaml.
    fn vmc3(legendre: bool) -> Reference {
        let machine = load_example("vmc3.yaml");
        let mut values: Vec<Motion> = (0..machine.errors.len())
            .map(|_| Box::new(|_: &[f64]| 0.0) as Box<_>)
            .collect();
        let index = |n: &str| machine.error_index(n).unwrap_or_else(|| panic!("{n}"));
        for (name, urad) in [("EC0Y", 15.0), ("EA0Z", 8.0), ("EB0Z", -10.0)] {
            values[index(name)] = Box::new(move |_| urad * 1e-6);
        }
        for axis in ["x", "y", "z"] {
            let (header, columns) = read_table(&example_file(&format!("values/{axis}_axis.csv")));
            let var = machine.variable_index(axis).unwrap();
            for (c, name) in header.iter().enumerate().skip(1) {
                if legendre && name == "EYX" {
                    continue;
                }
                let unit = if name[1..2].contains(['A', 'B', 'C']) {
                    1e-6
                } else {
                    1e-3
                };
                let q = columns[0].clone();
                let v: Vec<f64> = columns[c].iter().map(|x| x * unit).collect();
                let j = machine
                    .error_index(name)
                    .unwrap_or_else(|| index(&format!("{name}_0")));
                values[j] = if CUBIC.contains(&name.as_str()) {
                    let s = Spline::new(&q, &v);
                    Box::new(move |p: &[f64]| s.eval(p[var]))
                } else {
                    Box::new(move |p: &[f64]| linear(&q, &v, p[var]))
                };
            }
        }
        if legendre {
            values[index("EYX_0")] = Box::new(|_| -8e-3 / 3.0);
            values[index("EYX_2")] = Box::new(|_| 8e-3 / 3.0);
        }
        Reference { machine, values }
    }

    /// `Σ_j c_j(q)·v_j(q)` with `c_j` from the finite difference of the exact
    /// product, and `Σ_j |c_j v_j|` per component (the scale of rounding).
    fn error(&self, q: &[f64]) -> ([f64; 6], [f64; 6]) {
        let exact = Exact::new(&self.machine);
        let p = exact.file_parameters();
        let n = self.machine.errors.len();
        let s = exact.fd_sensitivity(q, &p, 1e-3);
        let v: Vec<f64> = self.values.iter().map(|f| f(q)).collect();
        let mut e = [0.0; 6];
        let mut mag = [0.0; 6];
        for c in 0..6 {
            for j in 0..n {
                e[c] += s[c * n + j] * v[j];
                mag[c] += (s[c * n + j] * v[j]).abs();
            }
        }
        (e, mag)
    }
}

/// The machine-ordered axis values of a JSON point `{"y": .., "x": .., "z": ..}`.
fn q_of(m: &Machine, point: &Value) -> Vec<f64> {
    m.variables
        .iter()
        .map(|v| point[&v.name].as_f64().unwrap())
        .collect()
}

fn components(e: &Value) -> [f64; 6] {
    std::array::from_fn(|c| e[["px", "py", "pz", "ox", "oy", "oz"][c]].as_f64().unwrap())
}

/// At the knots (x every 40 mm, y and z every 25 mm) and between them, the
/// ends included.
const GRID: [&str; 6] = [
    "--grid",
    "x=0,40,77.7,400,612.25,800",
    "--grid",
    "y=0,12.5,250,487.3,500",
    "--grid",
    "z=0,3.3,250,500",
];

fn map_json(values: &str, extra: &[&str]) -> Value {
    let mut args = vec!["map", MACHINE, "--values", values, "--format", "json"];
    args.extend_from_slice(extra);
    ok_json(&args)
}

#[test]
fn the_map_is_the_sum_of_coefficients_times_tabulated_values() {
    for legendre in [false, true] {
        let reference = Reference::vmc3(legendre);
        let m = &reference.machine;
        let doc = map_json(if legendre { LEGENDRE } else { VALUES }, &GRID);
        let points = doc["points"].as_array().unwrap();
        assert_eq!(points.len(), 6 * 5 * 4);
        let mut largest = 0.0f64;
        for p in points {
            let q = q_of(m, &p["point"]);
            let got = components(&p["error"]);
            let (expect, mag) = reference.error(&q);
            for c in 0..6 {
                assert!(
                    (got[c] - expect[c]).abs() <= 1e-9 * mag[c] + 1e-13,
                    "legendre {legendre}, component {c} at {q:?}: chain {} vs {}",
                    got[c],
                    expect[c]
                );
                largest = largest.max(expect[c].abs());
            }
            let vol = p["volumetric"].as_f64().unwrap();
            let hypot = got[0].hypot(got[1]).hypot(got[2]);
            assert!((vol - hypot).abs() <= 1e-15 * hypot, "{vol} vs {hypot}");
        }
        // The errors are of the size the tables say (some 10 µm), not zero.
        assert!(largest > 5e-3, "{largest}");
    }
}

#[test]
fn the_summary_is_that_of_the_points() {
    let doc = map_json(VALUES, &GRID);
    let points = doc["points"].as_array().unwrap();
    let n = points.len() as f64;
    for (c, name) in ["px", "py", "pz", "ox", "oy", "oz"].iter().enumerate() {
        let v: Vec<f64> = points.iter().map(|p| components(&p["error"])[c]).collect();
        let s = &doc["summary"][name];
        let min = v.iter().copied().fold(f64::INFINITY, f64::min);
        let max = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let rms = (v.iter().map(|x| x * x).sum::<f64>() / n).sqrt();
        assert_eq!(s["min"].as_f64().unwrap(), min, "{name}");
        assert_eq!(s["max"].as_f64().unwrap(), max, "{name}");
        assert!(
            (s["rms"].as_f64().unwrap() - rms).abs() <= 1e-15 * rms,
            "{name}"
        );
    }
    let vol: Vec<f64> = points
        .iter()
        .map(|p| p["volumetric"].as_f64().unwrap())
        .collect();
    let (at, max) =
        vol.iter().enumerate().fold(
            (0, f64::NEG_INFINITY),
            |(i, m), (k, &v)| if v > m { (k, v) } else { (i, m) },
        );
    let s = &doc["summary"]["volumetric"];
    assert_eq!(s["max"].as_f64().unwrap(), max);
    assert_eq!(s["at"], points[at]["point"]);
    let rms = (vol.iter().map(|x| x * x).sum::<f64>() / n).sqrt();
    assert!((s["rms"].as_f64().unwrap() - rms).abs() <= 1e-15 * rms);
}

#[test]
fn the_json_document_has_exactly_the_spec_keys() {
    let doc = map_json(
        VALUES,
        &["--grid", "x=0,800", "--grid", "y=0", "--grid", "z=0,500"],
    );
    let keys = |v: &Value| v.as_object().unwrap().keys().cloned().collect::<Vec<_>>();
    assert_eq!(keys(&doc), ["machine", "frame", "points", "summary"]);
    assert_eq!(doc["machine"], "vmc3");
    assert_eq!(doc["frame"], "workpiece");
    let p = &doc["points"][0];
    assert_eq!(keys(p), ["point", "error", "volumetric"]);
    assert_eq!(keys(&p["point"]), ["y", "x", "z"]);
    assert_eq!(keys(&p["error"]), ["px", "py", "pz", "ox", "oy", "oz"]);
    assert_eq!(
        keys(&doc["summary"]),
        ["px", "py", "pz", "ox", "oy", "oz", "volumetric"]
    );
    for c in ["px", "py", "pz", "ox", "oy", "oz"] {
        assert_eq!(keys(&doc["summary"][c]), ["min", "max", "rms"]);
    }
    assert_eq!(keys(&doc["summary"]["volumetric"]), ["max", "at", "rms"]);
    assert_eq!(keys(&doc["summary"]["volumetric"]["at"]), ["y", "x", "z"]);
    // The full factorial, the machine's last variable fastest.
    let pts: Vec<Vec<f64>> = doc["points"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| q_of(&load_example("vmc3.yaml"), &p["point"]))
        .collect();
    assert_eq!(
        pts,
        [
            [0.0, 0.0, 0.0],
            [0.0, 0.0, 500.0],
            [0.0, 800.0, 0.0],
            [0.0, 800.0, 500.0]
        ]
    );
}

#[test]
fn csv_and_table_say_what_the_json_says() {
    let doc = map_json(VALUES, &GRID);
    let mut args = vec!["map", MACHINE, "--values", VALUES, "--format", "csv"];
    args.extend_from_slice(&GRID);
    let csv = ok_stdout(&args);
    let mut lines = csv.lines();
    assert_eq!(lines.next().unwrap(), "y,x,z,px,py,pz,ox,oy,oz,volumetric");
    let points = doc["points"].as_array().unwrap();
    let rows: Vec<&str> = lines.collect();
    assert_eq!(rows.len(), points.len());
    for (row, p) in rows.iter().zip(points) {
        let cells: Vec<f64> = row.split(',').map(|c| c.parse().unwrap()).collect();
        let q = q_of(&load_example("vmc3.yaml"), &p["point"]);
        assert_eq!(&cells[..3], &q[..]);
        // serde_json reads numbers to within an ulp; the CSV to the bit.
        let close = |a: f64, b: f64| (a - b).abs() <= 5e-16 * a.abs().max(b.abs());
        let e = components(&p["error"]);
        for c in 0..6 {
            assert!(close(cells[3 + c], e[c]), "{} vs {}", cells[3 + c], e[c]);
        }
        assert!(close(cells[9], p["volumetric"].as_f64().unwrap()));
    }
    // The table: the summary in µm and µrad, the largest volumetric error
    // and where; the points of a small map.
    let table = ok_stdout(&["map", MACHINE, "--values", VALUES]);
    let full = map_json(VALUES, &[]);
    let s = &full["summary"];
    assert!(
        table.contains(
            "324 points: y 0 … 500 (6 values), x 0 … 800 (9 values), z 0 … 500 (6 values)"
        ),
        "{table}"
    );
    assert!(
        table.contains(
            "values: 18 tabulated error motions, 3 constants; all 24 error parameters given"
        ),
        "{table}"
    );
    let px = &s["px"];
    let line = format!(
        "{:<12} {:>12.3} {:>12.3} {:>12.3}",
        "px (µm)",
        px["min"].as_f64().unwrap() * 1e3,
        px["max"].as_f64().unwrap() * 1e3,
        px["rms"].as_f64().unwrap() * 1e3
    );
    assert!(table.contains(&line), "no `{line}` in\n{table}");
    let oy = &s["oy"];
    let line = format!(
        "{:<12} {:>12.3} {:>12.3} {:>12.3}",
        "oy (µrad)",
        oy["min"].as_f64().unwrap() * 1e6,
        oy["max"].as_f64().unwrap() * 1e6,
        oy["rms"].as_f64().unwrap() * 1e6
    );
    assert!(table.contains(&line), "no `{line}` in\n{table}");
    let at = &s["volumetric"]["at"];
    let volumetric = format!(
        "volumetric |p|: max {:.3} µm at y = {}, x = {}, z = {}; rms {:.3} µm",
        s["volumetric"]["max"].as_f64().unwrap() * 1e3,
        at["y"].as_f64().unwrap(),
        at["x"].as_f64().unwrap(),
        at["z"].as_f64().unwrap(),
        s["volumetric"]["rms"].as_f64().unwrap() * 1e3
    );
    assert!(table.contains(&volumetric), "no `{volumetric}` in\n{table}");
    // 324 points: no point list; 4 points: listed.
    assert!(!table.contains("|p| (µm)"));
    let small = ok_stdout(&[
        "map", MACHINE, "--values", VALUES, "--grid", "x=0,800", "--grid", "y=0", "--grid",
        "z=0,500",
    ]);
    assert!(small.contains("|p| (µm)"), "{small}");
    assert_eq!(
        small
            .lines()
            .filter(|l| l.trim_start().starts_with("0  "))
            .count(),
        4,
        "{small}"
    );
}

#[test]
fn grids_come_from_the_file_and_the_command_line() {
    let doc = map_json(VALUES, &[]);
    assert_eq!(doc["points"].as_array().unwrap().len(), 9 * 6 * 6);
    // A range form: 81 x values, 0 to 800 every 10 mm.
    let doc = map_json(
        VALUES,
        &[
            "--grid",
            "x=0:800:81",
            "--grid",
            "y=250",
            "--grid",
            "z=100:300:3",
        ],
    );
    let points = doc["points"].as_array().unwrap();
    assert_eq!(points.len(), 81 * 3);
    let m = load_example("vmc3.yaml");
    let xs: Vec<f64> = points
        .iter()
        .step_by(3)
        .map(|p| q_of(&m, &p["point"])[1])
        .collect();
    assert_eq!(xs.len(), 81);
    for (k, x) in xs.iter().enumerate() {
        assert!((x - 10.0 * k as f64).abs() < 1e-12, "{k}: {x}");
    }
    // A variable without a grid, and an unknown one.
    let dir = scratch("no_grid");
    let text = std::fs::read_to_string(example_path("vmc3.yaml")).unwrap();
    let cut = text.find("reliability:").unwrap();
    let machine = write(&dir, "vmc3.yaml", &text[..cut]);
    let values = std::fs::read_to_string(example_file("values/vmc3.yaml"))
        .unwrap()
        .replace(
            "table: ",
            &format!("table: {}/", example_file("values").display()),
        );
    let values = write(&dir, "values.yaml", &values);
    let (m, v) = (machine.to_str().unwrap(), values.to_str().unwrap());
    let err = unwrapped(&fails(&[
        "map", m, "--values", v, "--grid", "x=0", "--grid", "z=0",
    ]));
    assert!(
        err.contains("no grid values for axis variable `y`"),
        "{err}"
    );
    assert!(err.contains("--grid y=V1,V2,..."), "{err}");
    assert!(err.contains("chain::map::missing_grid"), "{err}");
    let err = unwrapped(&fails(&[
        "map", MACHINE, "--values", VALUES, "--grid", "xx=1",
    ]));
    assert!(
        err.contains("`xx`") && err.contains("did you mean `x`"),
        "{err}"
    );
    let ok = ok_json(&[
        "map", m, "--values", v, "--grid", "x=0", "--grid", "z=0", "--grid", "y=1", "--format",
        "json",
    ]);
    assert_eq!(ok["points"].as_array().unwrap().len(), 1);
    for bad in ["x=0:800:1", "x=0:800", "x=a,b"] {
        let err = fails(&["map", MACHINE, "--values", VALUES, "--grid", bad]);
        assert!(err.contains("--grid"), "{bad}: {err}");
    }
}

#[test]
fn points_from_an_axes_file_are_the_grid_points() {
    let dir = scratch("axes");
    let axes = write(
        &dir,
        "axes.csv",
        "t,z,x,y\n0,0,0,0\n1,250,612.25,487.3\n2,500,800,500\n",
    );
    let doc = map_json(VALUES, &["--axes", axes.to_str().unwrap()]);
    let points = doc["points"].as_array().unwrap();
    assert_eq!(points.len(), 3);
    let reference = Reference::vmc3(false);
    for (p, q) in points.iter().zip([
        [0.0, 0.0, 0.0],
        [487.3, 612.25, 250.0],
        [500.0, 800.0, 500.0],
    ]) {
        assert_eq!(q_of(&reference.machine, &p["point"]), q);
        let (expect, mag) = reference.error(&q);
        let got = components(&p["error"]);
        for c in 0..6 {
            assert!((got[c] - expect[c]).abs() <= 1e-9 * mag[c] + 1e-13);
        }
    }
    let bad = write(&dir, "bad.csv", "x,y\n0,0\n");
    let err = fails(&[
        "map",
        MACHINE,
        "--values",
        VALUES,
        "--axes",
        bad.to_str().unwrap(),
    ]);
    assert!(err.contains("no column for axis variable `z`"), "{err}");
    let other = write(&dir, "other.csv", "x,y,z,w\n0,0,0,0\n");
    let err = fails(&[
        "map",
        MACHINE,
        "--values",
        VALUES,
        "--axes",
        other.to_str().unwrap(),
    ]);
    assert!(err.contains("column `w` is not an axis variable"), "{err}");
    let err = fails(&[
        "map",
        MACHINE,
        "--values",
        VALUES,
        "--axes",
        axes.to_str().unwrap(),
        "--grid",
        "x=1",
    ]);
    assert!(
        err.contains("--grid cannot be combined with --axes"),
        "{err}"
    );
}

/// A values file of one table from the example's x_axis.csv, written in a
/// scratch directory (the table by its absolute path).
fn one_table(name: &str, entry: &str) -> std::path::PathBuf {
    let dir = scratch(name);
    let csv = example_file("values/x_axis.csv");
    let text = format!(
        "machine: vmc3\nunits: {{linear: um, angular: urad}}\nvalues:\n  EXX: {{table: {}, {entry}}}\n",
        csv.display()
    );
    write(&dir, "values.yaml", &text)
}

#[test]
fn outside_a_table_is_an_error_unless_it_holds() {
    let v = one_table("out_of_range", "column: EXX");
    let err = unwrapped(&fails(&[
        "map",
        MACHINE,
        "--values",
        v.to_str().unwrap(),
        "--grid",
        "x=0,850",
        "--grid",
        "y=0",
        "--grid",
        "z=0",
    ]));
    assert!(
        err.contains("at point 2 (y = 0, x = 850, z = 0): x = 850 is outside the table of `EXX`"),
        "{err}"
    );
    assert!(err.contains("x_axis.csv, column EXX"), "{err}");
    assert!(
        err.contains("extrapolate: hold") && err.contains("chain::map::out_of_range"),
        "{err}"
    );
    // Held: px = −EXX (the table moves along −x) takes the end value.
    let v = one_table("hold", "column: EXX, extrapolate: hold");
    let doc = map_json(
        v.to_str().unwrap(),
        &[
            "--grid",
            "x=-30,0,800,850",
            "--grid",
            "y=0",
            "--grid",
            "z=0",
        ],
    );
    let px: Vec<f64> = doc["points"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["error"]["px"].as_f64().unwrap())
        .collect();
    let (_, columns) = read_table(&example_file("values/x_axis.csv"));
    let (first, last) = (columns[1][0] * 1e-3, columns[1][20] * 1e-3);
    assert_eq!(px, [-first, -first, -last, -last]);
    assert!(last > 0.01, "{last}");
}

/// The squareness errors alone, in closed form (ISO 230-1: the squareness of
/// Z to X and Y is a tilt of the Z travel, an X / Y error proportional to
/// z). EC0Y on the Y saddle turns the X table about +z: `px = y·EC0Y`,
/// `oz = −EC0Y`. EA0Z, EB0Z before the Z joint turn the head and its travel
/// about the column's point: the tool point, `(0, 0, z − L)` from there,
/// moves by `(EA0Z, EB0Z, 0) × (0, 0, z − L)`, `px = (z − L)·EB0Z`,
/// `py = −(z − L)·EA0Z`, and the tool turns with them, `ox = EA0Z`,
/// `oy = EB0Z`. With L = 150 and 15, 8, −10 µrad.
#[test]
fn the_squareness_errors_tilt_the_z_travel() {
    let dir = scratch("squareness");
    let values = write(
        &dir,
        "squareness.yaml",
        "machine: vmc3\nunits: {angular: urad}\nvalues:\n  EC0Y: 15\n  EA0Z: 8\n  EB0Z: -10\n",
    );
    let doc = map_json(
        values.to_str().unwrap(),
        &[
            "--grid",
            "x=0,800",
            "--grid",
            "y=0,500",
            "--grid",
            "z=0,150,500",
        ],
    );
    let points = doc["points"].as_array().unwrap();
    assert_eq!(points.len(), 12);
    let (c, a, b) = (15e-6, 8e-6, -10e-6);
    for p in points {
        let at = |v: &str| p["point"][v].as_f64().unwrap();
        let (y, z) = (at("y"), at("z"));
        let want = [y * c + (z - 150.0) * b, -(z - 150.0) * a, 0.0, a, b, -c];
        let got = components(&p["error"]);
        for k in 0..6 {
            assert!(
                (got[k] - want[k]).abs() <= 1e-15,
                "at {}: {got:?} vs {want:?}",
                p["point"]
            );
        }
    }
}

#[test]
fn units_do_not_change_the_map() {
    let dir = scratch("units");
    let (_, columns) = read_table(&example_file("values/x_axis.csv"));
    let points = |col: usize, factor: f64| {
        let p: Vec<String> = (0..21)
            .map(|i| format!("[{}, {:e}]", columns[0][i], columns[col][i] * factor))
            .collect();
        format!("[{}]", p.join(", "))
    };
    let file = |name: &str, units: &str, lin: f64, ang: f64, sq: f64| {
        let text = format!(
            "machine: vmc3\nunits: {units}\nvalues:\n  EXX: {{points: {}}}\n  EBX: {{points: {}, interpolation: cubic}}\n  EC0Y: {sq:e}\n",
            points(1, lin),
            points(5, ang)
        );
        write(&dir, name, &text)
    };
    let micro = file("micro.yaml", "{linear: um, angular: urad}", 1.0, 1.0, 15.0);
    let base = file("base.yaml", "{linear: mm, angular: rad}", 1e-3, 1e-6, 15e-6);
    let arcsec = 180.0 * 3600.0 / std::f64::consts::PI;
    let arc = file(
        "arcsec.yaml",
        "{angular: arcsec}",
        1e-3,
        1e-6 * arcsec,
        15e-6 * arcsec,
    );
    let grid = [
        "--grid",
        "x=0:800:17",
        "--grid",
        "y=0,500",
        "--grid",
        "z=0,500",
    ];
    let a = map_json(micro.to_str().unwrap(), &grid);
    for other in [base, arc] {
        let b = map_json(other.to_str().unwrap(), &grid);
        for (p, q) in a["points"]
            .as_array()
            .unwrap()
            .iter()
            .zip(b["points"].as_array().unwrap())
        {
            let (x, y) = (components(&p["error"]), components(&q["error"]));
            for c in 0..6 {
                // The conversions round differently; the sums cancel.
                assert!(
                    (x[c] - y[c]).abs() <= 1e-14 * x[c].abs() + 1e-17,
                    "{x:?} vs {y:?}"
                );
            }
        }
    }
}

// ------------------------------------------------------------------ library

fn built() -> BuiltMachine {
    let m = load_example("vmc3.yaml");
    let values = Values::read(&example_file("values/vmc3.yaml"), &m).unwrap();
    BuiltMachine::compile(&m, values, vec![150.0]).unwrap()
}

#[test]
fn the_map_does_not_depend_on_the_thread_count() {
    let b = built();
    let axes = [
        (0..=40).map(|k| 12.5 * f64::from(k)).collect::<Vec<_>>(),
        (0..=50).map(|k| 16.0 * f64::from(k)).collect(),
        (0..=20).map(|k| 25.0 * f64::from(k)).collect(),
    ];
    let grid = Points::Grid(axes.to_vec());
    let flat = full_factorial(&axes);
    assert_eq!(flat.len(), 3 * 41 * 51 * 21);
    let list = Points::list(3, flat.clone()).unwrap();
    let run = |threads: usize, points: &Points| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| {
                (
                    b.map(points.clone()).unwrap(),
                    b.summary(points, &|_| {}).unwrap(),
                )
            })
    };
    let (one, summary) = run(1, &grid);
    for threads in [2, 3] {
        let (other, s) = run(threads, &grid);
        assert_eq!(one.errors, other.errors);
        assert_eq!(one.summary, other.summary);
        assert_eq!(s, summary);
    }
    // The summary alone is the map's; a list of the same points maps the same.
    assert_eq!(summary, one.summary);
    let (listed, _) = run(2, &list);
    assert_eq!(listed.errors, one.errors);
    assert_eq!(listed.summary, one.summary);
    // Point by point, as BuiltMachine::error gives it (every table evaluated).
    for i in (0..one.len()).step_by(997) {
        assert_eq!(one.point(i), flat[3 * i..3 * i + 3]);
        assert_eq!(b.error(&one.point(i)).unwrap(), one.errors[i]);
    }
    let counted = std::sync::atomic::AtomicUsize::new(0);
    b.map_with_progress(grid, &|n| {
        counted.fetch_add(n, std::sync::atomic::Ordering::Relaxed);
    })
    .unwrap();
    assert_eq!(counted.into_inner(), one.len());
}

#[test]
fn the_parts_add_up_to_the_error() {
    let b = built();
    let reference = Reference::vmc3(false);
    let m = &reference.machine;
    for q in [[0.0, 0.0, 0.0], [123.0, 456.0, 78.9], [500.0, 800.0, 500.0]] {
        let parts = b.parts(&q).unwrap();
        // 17 plain motions + 3 squareness + the EYX function.
        assert_eq!(parts.len(), m.errors.len() - 4 + 1);
        let e = b.error(&q).unwrap();
        for c in 0..6 {
            let sum: f64 = parts.iter().map(|p| p.error[c]).sum();
            assert!((sum - e[c]).abs() <= 1e-15, "{c}: {sum} vs {}", e[c]);
        }
        let eyx = parts.iter().find(|p| p.name == "EYX").unwrap();
        assert_eq!(eyx.kind, PartKind::Function);
        let j0 = m.error_index("EYX_0").unwrap();
        assert!((eyx.value - (reference.values[j0])(&q)).abs() < 1e-17);
        // The horizontal straightness of X acts in py only: py = −EYX(x).
        assert!((eyx.error[1] + eyx.value).abs() < 1e-18);
        assert_eq!(eyx.error[0], 0.0);
    }
}

#[test]
fn the_generated_type_gives_the_same_map() {
    let m = load_example("vmc3.yaml");
    let values = Values::read(&example_file("values/vmc3.yaml"), &m).unwrap();
    let generated = BuiltMachine::new(&m, Vmc3, values.clone(), vec![150.0]).unwrap();
    let compiled = BuiltMachine::compile(&m, values, vec![150.0]).unwrap();
    let points = Points::Grid(vec![
        vec![0.0, 250.0, 500.0],
        vec![0.0, 333.0, 800.0],
        vec![0.0, 100.0, 500.0],
    ]);
    let (a, b) = (
        generated.map(points.clone()).unwrap(),
        compiled.map(points).unwrap(),
    );
    for (x, y) in a.errors.iter().zip(&b.errors) {
        for c in 0..6 {
            assert!((x[c] - y[c]).abs() <= 1e-15, "{x:?} vs {y:?}");
        }
    }
    assert_eq!(Vmc3.errors().len(), 24);
}

#[test]
fn the_library_refuses_what_does_not_fit() {
    let b = built();
    assert!(matches!(
        b.map(Points::list(3, vec![]).unwrap()),
        Err(MapError::NoPoints)
    ));
    assert!(matches!(
        b.map(Points::Grid(vec![vec![0.0], vec![], vec![0.0]])),
        Err(MapError::NoPoints)
    ));
    assert!(matches!(
        Points::list(3, vec![1.0, 2.0]),
        Err(MapError::Ragged {
            len: 2,
            variables: 3
        })
    ));
    assert!(matches!(
        b.map(Points::Grid(vec![vec![0.0]])),
        Err(MapError::Dimension {
            found: 1,
            variables: 3
        })
    ));
    match b.map(Points::list(3, vec![0.0, 0.0, 0.0, 0.0, 900.0, 0.0]).unwrap()) {
        Err(MapError::OutOfRange {
            point: 1, source, ..
        }) => assert_eq!(source.value, 900.0),
        other => panic!("{other:?}"),
    }
    let m = load_example("vmc3.yaml");
    let gantry = load_example("gantry_grinder.yaml");
    let err = BuiltMachine::compile(&gantry, Values::zero(&m), vec![]).unwrap_err();
    assert!(
        err.to_string()
            .contains("for machine `vmc3`, not `gantry_grinder`"),
        "{err}"
    );
    let err = BuiltMachine::compile(&m, Values::zero(&m), vec![]).unwrap_err();
    assert!(
        err.to_string()
            .contains("0 parameter values for the 1 parameters"),
        "{err}"
    );
}

// ---------------------------------------------------------- other machines

/// Asserts a map point's error is `S(q)·v` with the numeric product's
/// sensitivities `s` (6 × n) and the values `v`, to 1e-9 of the terms'
/// magnitude; returns the largest `|S·v|` component.
fn assert_is_s_times_v(got: &[f64; 6], s: &[f64], v: &[f64], q: &[f64]) -> f64 {
    let n = v.len();
    let mut largest = 0.0f64;
    for c in 0..6 {
        let expect: f64 = (0..n).map(|j| s[c * n + j] * v[j]).sum();
        let mag: f64 = (0..n).map(|j| (s[c * n + j] * v[j]).abs()).sum();
        assert!(
            (got[c] - expect).abs() <= 1e-9 * mag + 1e-13,
            "{c} at {q:?}: {} vs {expect}",
            got[c]
        );
        largest = largest.max(expect.abs());
    }
    largest
}

#[test]
fn the_gantry_grinder_maps_like_its_numeric_product() {
    let m = load_example("gantry_grinder.yaml");
    let dir = scratch("gantry");
    let text = "machine: gantry_grinder\nunits: {linear: um, angular: arcsec}\nvalues:\n  dxx: {points: [[0, 0], [500, 3.1], [1000, 5.2]], interpolation: cubic}\n  eyx: {points: [[0, 1], [1000, -2]]}\n  ezz: {points: [[600, 0.5], [1400, 1.5]]}\n  Sxy: 4\n  dyy: 2\n";
    let v = write(&dir, "values.yaml", text);
    let doc = ok_json(&[
        "map",
        "examples/machines/gantry_grinder.yaml",
        "--values",
        v.to_str().unwrap(),
        "--format",
        "json",
    ]);
    assert_eq!(doc["frame"], "tool");
    let points = doc["points"].as_array().unwrap();
    assert_eq!(points.len(), 125);
    let exact = Exact::new(&m);
    let arcsec = std::f64::consts::PI / 648_000.0;
    let spline = Spline::new(&[0.0, 500.0, 1000.0], &[0.0, 3.1e-3, 5.2e-3]);
    let mut by_name: HashMap<&str, Motion> = HashMap::new();
    let x = m.variable_index("x").unwrap();
    let z = m.variable_index("z").unwrap();
    by_name.insert("dxx", Box::new(move |q| spline.eval(q[x])));
    by_name.insert(
        "eyx",
        Box::new(move |q| linear(&[0.0, 1000.0], &[arcsec, -2.0 * arcsec], q[x])),
    );
    by_name.insert(
        "ezz",
        Box::new(move |q| linear(&[600.0, 1400.0], &[0.5 * arcsec, 1.5 * arcsec], q[z])),
    );
    by_name.insert("Sxy", Box::new(move |_| 4.0 * arcsec));
    by_name.insert("dyy", Box::new(|_| 2e-3));
    for p in points {
        let q = q_of(&m, &p["point"]);
        let s = exact.fd_sensitivity(&q, &[], 1e-3);
        let v: Vec<f64> = m
            .errors
            .iter()
            .map(|e| by_name.get(e.name.as_str()).map_or(0.0, |f| f(&q)))
            .collect();
        assert_is_s_times_v(&components(&p["error"]), &s, &v, &q);
    }
}

/// examples/values/gantry_grinder.yaml (the million-point map of
/// docs/performance.md): its constants, read here line by line, times the
/// numeric product's sensitivities.
#[test]
fn the_example_gantry_values_map_like_the_numeric_product() {
    let m = load_example("gantry_grinder.yaml");
    let file = example_file("values/gantry_grinder.yaml");
    let text = std::fs::read_to_string(&file).unwrap();
    let constants: HashMap<String, f64> = text
        .lines()
        .skip_while(|l| !l.starts_with("values:"))
        .skip(1)
        .filter(|l| !l.trim_start().starts_with('#'))
        .map(|l| {
            let (name, value) = l.trim().split_once(": ").unwrap();
            (name.to_string(), value.parse::<f64>().unwrap())
        })
        .collect();
    assert_eq!(constants.len(), 21);
    let doc = ok_json(&[
        "map",
        "examples/machines/gantry_grinder.yaml",
        "--values",
        file.to_str().unwrap(),
        "--grid",
        "x=0:1000:3",
        "--grid",
        "y=-1500:1500:3",
        "--grid",
        "z=600:1400:3",
        "--format",
        "json",
    ]);
    let points = doc["points"].as_array().unwrap();
    assert_eq!(points.len(), 27);
    let exact = Exact::new(&m);
    // units: {linear: um, angular: urad}; the names starting with `d` are
    // the translations.
    let v: Vec<f64> = (m.errors.iter())
        .map(|e| {
            let value = constants[e.name.as_str()];
            value * if e.name.starts_with('d') { 1e-3 } else { 1e-6 }
        })
        .collect();
    let mut largest = 0.0f64;
    for p in points {
        let q = q_of(&m, &p["point"]);
        let s = exact.fd_sensitivity(&q, &[], 1e-3);
        let got = components(&p["error"]);
        largest = largest.max(assert_is_s_times_v(&got, &s, &v, &q));
    }
    // Some tens of µm at the corners, as one-sigma errors over metres give.
    assert!(largest > 0.01 && largest < 0.1, "{largest}");
}

// -------------------------------------------------------------------- plots

#[test]
fn plots_are_heat_maps_and_a_distorted_grid() {
    let dir = scratch("plots");
    let out = success(chain(&[
        "map",
        MACHINE,
        "--values",
        VALUES,
        "--grid",
        "x=0:800:17",
        "--grid",
        "y=0:500:11",
        "--plot",
        dir.to_str().unwrap(),
        "--format",
        "json",
    ]));
    serde_json::from_slice::<Value>(&out.stdout).unwrap();
    let stems = [
        "map_px",
        "map_py",
        "map_pz",
        "map_ox",
        "map_oy",
        "map_oz",
        "map_volumetric",
        "map_distortion",
    ];
    for stem in stems {
        for ext in ["png", "svg"] {
            assert!(dir.join(format!("{stem}.{ext}")).is_file(), "{stem}.{ext}");
        }
        let png = png::Decoder::new(std::io::BufReader::new(
            std::fs::File::open(dir.join(format!("{stem}.png"))).unwrap(),
        ));
        let info = png.read_info().unwrap();
        let (w, h) = (info.info().width, info.info().height);
        assert!(w == 1000 && h >= 500, "{stem}: {w}×{h}");
    }
    // The slice through the middle of z (0 … 500, 6 values: 200), and the
    // magnification in the distorted grid's title.
    let px = std::fs::read_to_string(dir.join("map_px.svg")).unwrap();
    assert!(
        px.contains("vmc3: px (µm) at z = 200"),
        "title of map_px.svg"
    );
    let grid = std::fs::read_to_string(dir.join("map_distortion.svg")).unwrap();
    assert!(
        grid.contains("displacement ×"),
        "title of map_distortion.svg"
    );
    // One varying axis: charts along it.
    let dir = scratch("plots_line");
    success(chain(&[
        "map",
        MACHINE,
        "--values",
        VALUES,
        "--grid",
        "x=0:800:9",
        "--grid",
        "y=0",
        "--grid",
        "z=0",
        "--plot",
        dir.to_str().unwrap(),
    ]));
    for stem in ["map_position", "map_orientation"] {
        assert!(dir.join(format!("{stem}.png")).is_file(), "{stem}");
    }
}
