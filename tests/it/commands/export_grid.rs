//! `chain export --controller grid` (measured-machines spec, section 6)
//! against an independent computation: the exported
//! corrections applied back through the exact numeric 4×4 product of
//! `tests/it/common` (not chain's model), on a 3-axis machine (vmc3) and a
//! 5-axis machine (ac_trunnion), with values files of errors of about
//! 10 µm / 10 µrad written here (constants, coefficients of a function
//! slot, and a linear table the test interpolates itself). The residual is
//! second order: below 1 % of the uncompensated error, and a quarter when
//! the errors are halved. The CSV is parsed back field by field and compared
//! with the library's result; bad input fails cleanly.

// Matrix code reads best with explicit indices.
#![allow(clippy::needless_range_loop)]

use crate::common;

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use chain::core::built::{BuiltMachine, Points};
use chain::core::compensation::grid::{self, GridCompensation};
use chain::core::compensation::Correction;
use chain::core::kinematics::Kinematics;
use chain::core::values::Values;
use chain::core::Machine;
use common::cli::{fails, ok_stdout, scratch, unwrapped, write};
use common::{load_example, transform_point, Exact};

/// The table the values files give `EXX` (positions mm, values mm before
/// scaling): linear, so the test interpolates it itself.
const EXX_TABLE: [(f64, f64); 3] = [(0.0, 0.0), (400.0, 0.006), (800.0, 0.010)];

/// A deterministic value in [−1, 1] per name.
fn unit_of(name: &str) -> f64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in name.bytes() {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    (h >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
}

/// Whether an ISO 230-1 error name is linear (mm): its second letter.
fn linear(name: &str) -> bool {
    matches!(name.as_bytes().get(1), Some(b'X' | b'Y' | b'Z'))
}

/// Every error's constant value at `scale` (10 µm or 10 µrad at 1), `EXX`
/// aside (the table).
fn constants(m: &Machine, scale: f64) -> Vec<(String, f64)> {
    (m.errors.iter())
        .filter(|e| e.name != "EXX")
        .map(|e| {
            let size = if linear(&e.name) { 0.010 } else { 10e-6 };
            (e.name.clone(), scale * size * unit_of(&e.name))
        })
        .collect()
}

/// A values file for `m` at `scale`, in `dir`.
fn values_file(dir: &Path, m: &Machine, scale: f64) -> PathBuf {
    let mut text = format!(
        "machine: {}\nunits: {{linear: mm, angular: rad}}\nvalues:\n",
        m.name
    );
    for (name, v) in constants(m, scale) {
        // Coefficients of a function slot are given as such.
        if m.function_index(&name).is_some() {
            continue;
        }
        text.push_str(&format!("  {name}: {v:e}\n"));
    }
    let points: Vec<String> = (EXX_TABLE.iter())
        .map(|(x, v)| format!("[{x}, {:e}]", v * scale))
        .collect();
    text.push_str(&format!("  EXX: {{points: [{}]}}\n", points.join(", ")));
    write(dir, &format!("values_{scale}.yaml"), &text)
}

/// The test's own error values at machine-ordered `q` (`machine.errors`
/// order): the constants, and `EXX` interpolated linearly (continued past
/// its ends by its end intervals, as chain continues a table over `|δq|`).
fn error_values(m: &Machine, scale: f64, q: &[f64]) -> Vec<f64> {
    let c: HashMap<String, f64> = constants(m, scale).into_iter().collect();
    let x = q[m.variable_index("x").unwrap()];
    let k = if x < EXX_TABLE[1].0 { 0 } else { 1 };
    let (a, b) = (EXX_TABLE[k], EXX_TABLE[k + 1]);
    let exx = scale * (a.1 + (b.1 - a.1) * (x - a.0) / (b.0 - a.0));
    (m.errors.iter())
        .map(|e| match e.name.as_str() {
            "EXX" => exx,
            n => c.get(n).copied().unwrap_or(0.0),
        })
        .collect()
}

/// The exact tool-point error and tool-axis angle at the command `q` with
/// `delta` added (zero: the uncompensated error), against the nominal pose
/// at `q`, through the numeric product (machine-ordered `q`).
fn exact_after(m: &Machine, scale: f64, q: &[f64], delta: &[f64]) -> (f64, f64) {
    let x = Exact::new(m);
    let p = x.file_parameters();
    let qd: Vec<f64> = q.iter().zip(delta).map(|(a, b)| a + b).collect();
    let e = error_values(m, scale, &qd);
    let t = x.t_wt(&qd, &p, &e);
    let (r0, p0) = x.nominal(q, &p);
    let reached = transform_point(&t, x.tool_point(&p));
    let d: Vec<f64> = (0..3).map(|i| reached[i] - p0[i]).collect();
    let z: Vec<f64> = (0..3).map(|i| t[i][2]).collect();
    let z0: Vec<f64> = (0..3).map(|i| r0[i][2]).collect();
    let cross = [
        z[1] * z0[2] - z[2] * z0[1],
        z[2] * z0[0] - z[0] * z0[2],
        z[0] * z0[1] - z[1] * z0[0],
    ];
    let norm = |v: &[f64]| v.iter().map(|a| a * a).sum::<f64>().sqrt();
    (norm(&d), norm(&cross))
}

/// The library's export of `file` with the values at `scale` over `grid`.
fn library(m: &Machine, values: &Path, grid: &[Vec<f64>]) -> GridCompensation {
    let v = Values::read(values, m).unwrap();
    let built = BuiltMachine::compile(m, v, Exact::new(m).file_parameters()).unwrap();
    let kin = Kinematics::from_machine(m);
    grid::export(&built, &kin, Points::Grid(grid.to_vec())).unwrap()
}

/// The grid CSV parsed back: header, rows.
fn parse(text: &str) -> (Vec<String>, Vec<Vec<f64>>) {
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| l.split(',').map(|c| c.parse::<f64>().unwrap()).collect())
        .collect();
    (header, rows)
}

/// `--grid` arguments for a grid.
fn grid_args(m: &Machine, grid: &[Vec<f64>]) -> Vec<String> {
    (m.variables.iter().zip(grid))
        .flat_map(|(v, g)| {
            let list: Vec<String> = g.iter().map(|x| format!("{x}")).collect();
            [
                "--grid".to_string(),
                format!("{}={}", v.name, list.join(",")),
            ]
        })
        .collect()
}

/// Exports through the CLI; checks the CSV against the library field by
/// field; returns, over the nodes, the largest exact uncompensated error,
/// the largest exact residual, and the same two for the tool axis (nodes
/// where the tool axis is correctable only).
fn round_trip(machine: &str, grid: &[Vec<f64>], scale: f64, name: &str) -> [f64; 4] {
    let m = load_example(machine);
    let dir = scratch(name);
    let values = values_file(&dir, &m, scale);
    let mut args: Vec<String> = [
        "export",
        &format!("examples/machines/{machine}"),
        "--values",
        values.to_str().unwrap(),
        "--controller",
        "grid",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    args.extend(grid_args(&m, grid));
    let argv: Vec<&str> = args.iter().map(String::as_str).collect();
    let text = ok_stdout(&argv);
    assert!(
        text.starts_with("# chain export --controller grid"),
        "{text}"
    );
    assert!(text.contains("# sign: command q + delta_q"), "{text}");
    let (header, rows) = parse(&text);
    let lib = library(&m, &values, grid);
    let vars: Vec<&str> = m.variables.iter().map(|v| v.name.as_str()).collect();
    let mut expected: Vec<String> = vars.iter().map(|v| v.to_string()).collect();
    expected.extend(vars.iter().map(|v| format!("delta_{v}")));
    expected.push("residual".into());
    assert_eq!(header, expected);
    assert_eq!(rows.len(), lib.len());
    let nv = vars.len();
    let (mut before, mut after, mut axis_before, mut axis_after) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let mut nodes_with_axis = 0;
    for (i, row) in rows.iter().enumerate() {
        assert_eq!(row.len(), 2 * nv + 1);
        // Field by field: the node, δq and the residual, as the library has them.
        assert_eq!(&row[..nv], lib.points.point(i).as_slice(), "node {i}");
        assert_eq!(&row[nv..2 * nv], lib.delta(i), "δq at node {i}");
        assert_eq!(row[2 * nv], lib.residuals[i], "residual at node {i}");
        let q = &row[..nv];
        let d = &row[nv..2 * nv];
        let (e0, a0) = exact_after(&m, scale, q, &vec![0.0; nv]);
        let (e1, a1) = exact_after(&m, scale, q, d);
        before = before.max(e0);
        after = after.max(e1);
        // The model's residual is the exact one to second order too.
        assert!(
            (e1 - row[2 * nv]).abs() <= 0.01 * e0,
            "node {i}: {e1} vs {}",
            row[2 * nv]
        );
        // A five-axis node off the singularity (A ≠ 0): the tool axis too.
        if m.variable_index("A").is_some_and(|a| q[a].abs() > 0.1) {
            nodes_with_axis += 1;
            axis_before = axis_before.max(a0);
            axis_after = axis_after.max(a1);
        }
    }
    if m.variable_index("A").is_some() {
        assert!(nodes_with_axis > 0);
    }
    [before, after, axis_before, axis_after]
}

fn assert_second_order(machine: &str, grid: &[Vec<f64>], with_axis: bool) {
    let [b1, r1, ab1, ar1] = round_trip(machine, grid, 1.0, "full");
    let [b2, r2, ab2, ar2] = round_trip(machine, grid, 0.5, "half");
    eprintln!("{machine}: error {b1:.3e} → residual {r1:.3e}; halved: {b2:.3e} → {r2:.3e}; tool axis {ab1:.3e} → {ar1:.3e}, halved {ab2:.3e} → {ar2:.3e}");
    // 10 µm-class errors.
    assert!(b1 > 0.005 && b1 < 0.2, "{b1}");
    assert!(r1 < 0.01 * b1, "residual {r1} of {b1}");
    // The exact product is not linear in the errors: 2 to first order.
    assert!((b1 / b2 - 2.0).abs() < 1e-3, "{b1} {b2}");
    let ratio = r1 / r2;
    assert!(
        (3.6..4.4).contains(&ratio),
        "residual ratio {ratio} (first order would be 2)"
    );
    if with_axis {
        assert!(ar1 < 0.01 * ab1, "tool axis {ar1} of {ab1}");
        let ratio = ar1 / ar2;
        assert!((3.6..4.4).contains(&ratio), "tool-axis ratio {ratio}");
    }
}

#[test]
fn three_axis_residual_is_second_order() {
    let grid = vec![
        vec![0.0, 250.0, 500.0],
        vec![0.0, 200.0, 400.0, 600.0, 800.0],
        vec![0.0, 250.0, 500.0],
    ];
    assert_second_order("vmc3.yaml", &grid, false);
}

#[test]
fn five_axis_residual_is_second_order_tool_point_and_axis() {
    let m = load_example("ac_trunnion.yaml");
    let order: Vec<&str> = m.variables.iter().map(|v| v.name.as_str()).collect();
    let grid: Vec<Vec<f64>> = order
        .iter()
        .map(|v| match *v {
            "x" => vec![0.0, 400.0, 800.0],
            "y" => vec![-200.0, 300.0],
            "z" => vec![-300.0, 0.0],
            "A" => vec![-0.8, 0.0, 0.5],
            _ => vec![-2.0, 0.3, 1.5],
        })
        .collect();
    assert_second_order("ac_trunnion.yaml", &grid, true);
}

#[test]
fn the_grid_correction_interpolates_nodes_and_refuses_outside() {
    let m = load_example("vmc3.yaml");
    let dir = scratch("correction");
    let values = values_file(&dir, &m, 1.0);
    let grid = vec![vec![0.0, 500.0], vec![0.0, 400.0, 800.0], vec![0.0, 500.0]];
    let lib = library(&m, &values, &grid);
    let c = lib.correction().unwrap();
    let mut d = [0.0; 3];
    for i in 0..lib.len() {
        c.delta(&lib.points.point(i), &mut d).unwrap();
        assert_eq!(&d[..], lib.delta(i));
    }
    // Halfway between two nodes along x: their mean.
    c.delta(&[0.0, 200.0, 0.0], &mut d).unwrap();
    let (a, b) = (lib.delta(0), lib.delta(2));
    for k in 0..3 {
        assert!((d[k] - 0.5 * (a[k] + b[k])).abs() < 1e-15);
    }
    let err = c.delta(&[0.0, 800.5, 0.0], &mut d).unwrap_err();
    assert_eq!((err.lo, err.hi, err.value), (0.0, 800.0, 800.5));
}

#[test]
fn a_table_that_does_not_cover_the_grid_is_refused() {
    let err = unwrapped(&fails(&[
        "export",
        "examples/machines/vmc3.yaml",
        "--values",
        "examples/values/vmc3.yaml",
        "--controller",
        "grid",
        "--grid",
        "x=0:900:4",
    ]));
    assert!(
        err.contains(
            "x = 900 is outside the table of `EXX` (x_axis.csv, column EXX, x = 0 to 800)"
        ),
        "{err}"
    );
    assert!(
        err.contains("examples/values/vmc3.yaml does not cover"),
        "{err}"
    );
}

#[test]
fn an_unknown_controller_is_refused() {
    let base = [
        "export",
        "examples/machines/vmc3.yaml",
        "--values",
        "examples/values/vmc3.yaml",
        "--controller",
    ];
    let err = fails(&[&base[..], &["fanuc"]].concat());
    assert!(
        err.contains("invalid value 'fanuc' for '--controller <CONTROLLER>'"),
        "{err}"
    );
    assert!(
        err.contains("grid, beckhoff, linuxcnc, siemens-cec, klipper"),
        "{err}"
    );
}

#[test]
fn a_machine_without_a_grid_needs_grid_or_axes() {
    let dir = scratch("nogrid");
    let machine = write(&dir, "m.yaml", "machine: m\nbodies:\n  bed: {}\n  x_slide: {parent: bed, joint: {type: prismatic, axis: +x, variable: x}, errors: {dx: EXX}}\nworkpiece: bed\ntool: x_slide\n");
    let values = write(&dir, "v.yaml", "machine: m\nvalues:\n  EXX: 0.001\n");
    let err = unwrapped(&fails(&[
        "export",
        machine.to_str().unwrap(),
        "--values",
        values.to_str().unwrap(),
        "--controller",
        "grid",
    ]));
    assert!(
        err.contains("no grid values for axis variable `x`"),
        "{err}"
    );
    assert!(err.contains("--grid x=V1,V2,..."), "{err}");
    // Given a grid, one linear axis is corrected exactly: δx = −EXX, no residual.
    let text = ok_stdout(&[
        "export",
        machine.to_str().unwrap(),
        "--values",
        values.to_str().unwrap(),
        "--controller",
        "grid",
        "--grid",
        "x=0,10",
    ]);
    let (_, rows) = parse(&text);
    assert_eq!(rows, vec![vec![0.0, -0.001, 0.0], vec![10.0, -0.001, 0.0]]);
}

#[test]
fn out_writes_the_file_and_the_summary_goes_to_stdout() {
    let dir = scratch("out");
    let json = ok_stdout(&[
        "export",
        "examples/machines/vmc3.yaml",
        "--values",
        "examples/values/vmc3.yaml",
        "--controller",
        "grid",
        "--out",
        dir.to_str().unwrap(),
        "--format",
        "json",
    ]);
    let doc: serde_json::Value = serde_json::from_str(&json).unwrap();
    // One key each (serde_json would keep the last of two silently).
    assert_eq!(json.matches("\"controller\"").count(), 1, "{json}");
    assert_eq!(doc["controller"], "grid");
    assert_eq!(doc["files"][0], "vmc3_grid.csv");
    assert_eq!(doc["summary"]["nodes"], 324);
    let text = std::fs::read_to_string(dir.join("vmc3_grid.csv")).unwrap();
    let (_, rows) = parse(&text);
    assert_eq!(rows.len(), 324);
    let max = rows.iter().map(|r| r[6]).fold(0.0, f64::max);
    assert!(same(
        doc["summary"]["residual"]["max"].as_f64().unwrap(),
        max
    ));
    // Second order on the example values too (errors up to ~19 µm).
    assert!(max < 0.01 * doc["summary"]["before"]["max"].as_f64().unwrap());
}

#[test]
fn map_compensated_shows_the_export_residual_next_to_the_error() {
    let base = [
        "map",
        "examples/machines/vmc3.yaml",
        "--values",
        "examples/values/vmc3.yaml",
    ];
    let plain: serde_json::Value =
        serde_json::from_str(&ok_stdout(&[&base[..], &["--format", "json"]].concat())).unwrap();
    let doc: serde_json::Value = serde_json::from_str(&ok_stdout(
        &[&base[..], &["--format", "json", "--compensated", "grid"]].concat(),
    ))
    .unwrap();
    // The uncompensated part is the plain map, unchanged.
    for key in ["machine", "frame", "points", "summary"] {
        assert_eq!(doc[key], plain[key], "{key}");
    }
    let c = &doc["compensated"];
    assert_eq!(c["controller"], "grid");
    assert_eq!(c["correction_nodes"], 324);
    // At the correction's own nodes the residual is the export's (to the
    // last bit serde_json's float reading may lose).
    let m = load_example("vmc3.yaml");
    let file_grid = &m.reliability.as_ref().unwrap().grid;
    let grid: Vec<Vec<f64>> = (0..m.variables.len())
        .map(|k| file_grid.iter().find(|(i, _)| *i == k).unwrap().1.clone())
        .collect();
    let v = Values::read(&common::example_file("values/vmc3.yaml"), &m).unwrap();
    let built = BuiltMachine::compile(&m, v, Exact::new(&m).file_parameters()).unwrap();
    let lib = grid::export(&built, &Kinematics::from_machine(&m), Points::Grid(grid)).unwrap();
    let points = c["points"].as_array().unwrap();
    assert_eq!(points.len(), lib.len());
    for (i, p) in points.iter().enumerate() {
        assert!(
            same(p["volumetric"].as_f64().unwrap(), lib.residuals[i]),
            "node {i}"
        );
    }
    assert!(same(
        c["summary"]["volumetric"]["max"].as_f64().unwrap(),
        lib.summary.residual.max
    ));
    // The orientation error of a three-axis machine stays: no axis turns the tool.
    for k in ["ox", "oy", "oz"] {
        let (a, b) = (
            c["summary"][k]["rms"].as_f64().unwrap(),
            doc["summary"][k]["rms"].as_f64().unwrap(),
        );
        assert!((a - b).abs() < 1e-3 * b, "{k}: {a} {b}");
    }
    // A coarser correction grid: exact at its nodes, interpolated between.
    let coarse: serde_json::Value = serde_json::from_str(&ok_stdout(
        &[
            &base[..],
            &[
                "--format",
                "json",
                "--compensated",
                "grid",
                "--compensation-grid",
                "x=0:800:3",
            ],
        ]
        .concat(),
    ))
    .unwrap();
    let cp = coarse["compensated"]["points"].as_array().unwrap();
    for (i, p) in cp.iter().enumerate() {
        let x = p["point"]["x"].as_f64().unwrap();
        let r = p["volumetric"].as_f64().unwrap();
        if [0.0, 400.0, 800.0].contains(&x) {
            assert!(same(r, lib.residuals[i]), "node {i}");
        } else {
            assert!(r < 0.2 * lib.summary.before.max, "node {i}: {r}");
        }
    }
    let table = ok_stdout(&[&base[..], &["--compensated", "grid"]].concat());
    assert!(
        table.contains("After grid compensation (324 correction nodes"),
        "{table}"
    );
}

/// Equal to the last bits (a JSON number read back by serde_json).
fn same(a: f64, b: f64) -> bool {
    (a - b).abs() <= 4.0 * f64::EPSILON * b.abs()
}

#[test]
fn the_correction_does_not_depend_on_the_frame_of_the_error() {
    // ac_trunnion with `frame: tool`: E is reported in the tool frame, the
    // solve turns it back; δq and the residual are the same.
    let dir = scratch("frame");
    let text = std::fs::read_to_string(common::example_path("ac_trunnion.yaml")).unwrap();
    assert!(text.contains("frame: workpiece"));
    let tool = write(
        &dir,
        "ac_tool.yaml",
        &text.replace("frame: workpiece", "frame: tool"),
    );
    let mw = load_example("ac_trunnion.yaml");
    let mt = chain::core::load_file(&tool).unwrap();
    let values = values_file(&dir, &mw, 1.0);
    let grid: Vec<Vec<f64>> = (mw.variables.iter())
        .map(|v| match v.name.as_str() {
            "A" => vec![-0.6, 0.4],
            "C" => vec![-1.0, 2.0],
            "x" => vec![100.0, 700.0],
            _ => vec![-100.0, 50.0],
        })
        .collect();
    let a = library(&mw, &values, &grid);
    let b = library(&mt, &values, &grid);
    assert_eq!(b.frame, chain::core::model::Frame::Tool);
    for i in 0..a.len() {
        for (x, y) in a.delta(i).iter().zip(b.delta(i)) {
            assert!(
                (x - y).abs() <= 1e-12 * x.abs().max(1e-9),
                "node {i}: {x} {y}"
            );
        }
        assert!((a.residuals[i] - b.residuals[i]).abs() <= 1e-9 * a.summary.before.max);
    }
    // The compensated map in the tool frame: the residual's norm is frame-free.
    let v = Values::read(&values, &mt).unwrap();
    let built = BuiltMachine::compile(&mt, v, Exact::new(&mt).file_parameters()).unwrap();
    let map = built
        .compensated_map(&b.correction().unwrap(), b.points.clone())
        .unwrap();
    for i in 0..b.len() {
        assert!((map.volumetric(i) - b.residuals[i]).abs() <= 1e-15);
    }
}

#[test]
fn axes_rows_give_the_grid_nodes_corrections() {
    let dir = scratch("axes");
    let rows = "t,x,y,z\n0,0,0,0\n1,800,500,500\n2,300,200,100\n";
    let axes = write(&dir, "axes.csv", rows);
    let args = |extra: &[&str]| {
        let mut a = vec![
            "export",
            "examples/machines/vmc3.yaml",
            "--values",
            "examples/values/vmc3.yaml",
            "--controller",
            "grid",
        ];
        a.extend_from_slice(extra);
        ok_stdout(&a)
    };
    let (header, listed) = parse(&args(&["--axes", axes.to_str().unwrap()]));
    assert_eq!(header[..3], ["y", "x", "z"]);
    assert_eq!(listed.len(), 3);
    // The same nodes from the grid: the same numbers (machine order y, x, z).
    let (_, all) = parse(&args(&[]));
    for row in &listed {
        let same_node = all.iter().find(|r| r[..3] == row[..3]).unwrap();
        assert_eq!(row, same_node);
    }
    // A list of poses has no grid to interpolate: map --compensated with
    // --axes takes the machine file's grid for the correction.
    let doc: serde_json::Value = serde_json::from_str(&ok_stdout(&[
        "map",
        "examples/machines/vmc3.yaml",
        "--values",
        "examples/values/vmc3.yaml",
        "--axes",
        axes.to_str().unwrap(),
        "--format",
        "json",
        "--compensated",
        "grid",
    ]))
    .unwrap();
    let pts = doc["compensated"]["points"].as_array().unwrap();
    for (p, row) in pts.iter().zip(&listed) {
        assert!(same(p["volumetric"].as_f64().unwrap(), row[6]));
    }
}
