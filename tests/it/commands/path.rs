//! `chain path`: the error and its reliability at every instant of a path
//! (docs/path.md). Cross-checks against `chain reliability`'s grid study
//! through the library, against a Monte Carlo estimate of the error moments,
//! and against `chain inverse`; the JSON/CSV shapes; bad input.

use crate::common;

use std::path::{Path, PathBuf};

use chain_core::model::{Component, Sided};
use chain_core::{CompiledModel, ErrorModel, Machine};
use common::cli::{chain_stdin, fails, ok_json, ok_stdout, scratch, success_json, write};
use common::{example_file, example_path};
use reliability::rng::CaseRng;
use reliability::{machine, Algorithm, Form, System};
use serde_json::Value;

fn gantry() -> PathBuf {
    example_path("gantry_grinder.yaml")
}

fn bevel() -> PathBuf {
    example_file("paths/cnc5_bevel_stats.yaml")
}

/// `examples/paths/<name>`.
fn example(name: &str) -> PathBuf {
    example_file("paths").join(name)
}

fn load(path: &Path) -> (Machine, CompiledModel) {
    let m = chain_core::load_file(path).expect("machine loads");
    let model = chain_core::compile(&m);
    (m, model)
}

fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

/// The five-axis example with statistics, and `chain path` on it along
/// `examples/paths/cnc5_bevel_axes.csv`.
fn bevel_along_its_axes() -> (Machine, CompiledModel, Value) {
    let file = bevel();
    let (m, model) = load(&file);
    let doc = path_json(&file, &example("cnc5_bevel_axes.csv"), &[]);
    (m, model, doc)
}

/// `chain path <machine> --axes <axes> --format json` with `extra`, which
/// must succeed; returns the document.
fn path_json(machine: &Path, axes: &Path, extra: &[&str]) -> Value {
    let mut args = vec!["path", s(machine), "--axes", s(axes), "--format", "json"];
    args.extend_from_slice(extra);
    ok_json(&args)
}

fn f(v: &Value) -> f64 {
    v.as_f64()
        .unwrap_or_else(|| panic!("expected a number, found {v}"))
}

/// The instants' axis values in the model's variable order.
fn axes_of(doc: &Value, variables: &[&str]) -> Vec<Option<Vec<f64>>> {
    doc["instants"]
        .as_array()
        .unwrap()
        .iter()
        .map(|i| {
            i["axes"]
                .as_object()
                .map(|a| variables.iter().map(|v| f(&a[*v])).collect())
        })
        .collect()
}

#[test]
fn gantry_path_reliability_equals_the_grid_study_at_grid_points() {
    let file = gantry();
    let (m, model) = load(&file);
    let path = example("gantry_path.csv");
    for (extra, system, sided_two) in [
        (vec![], None, false),
        (
            vec!["--system", "volumetric"],
            Some(System::Volumetric { tolerance: 0.03 }),
            false,
        ),
        (vec!["--sided", "two"], None, true),
    ] {
        let doc = path_json(&file, &path, &extra);
        // The grid study of `chain reliability`, through the library.
        let mut spec = machine::spec(&m, system).unwrap();
        if sided_two {
            spec.sided = Sided::Two;
        }
        let study =
            reliability::Study::new(&model, &[], machine::inputs(&m).unwrap(), spec).unwrap();
        let grid = study.run(&Algorithm::Form(Form::default()), &()).unwrap();
        let np = study.points().len();
        let vars: Vec<&str> = model.variables().to_vec();
        let mut matched = 0;
        for (k, q) in axes_of(&doc, &vars).into_iter().enumerate() {
            let q = q.expect("every gantry instant has axes");
            let Some(p) = study.points().iter().position(|g| *g == *q) else {
                continue;
            };
            matched += 1;
            let inst = &doc["instants"][k];
            for (t, target) in study.targets().iter().enumerate() {
                let want = grid.cases[t * np + p].reliability;
                let got = f(&inst["reliability"][target.name()]);
                assert!(
                    (got - want).abs() <= 1e-12,
                    "{extra:?} instant {k} {}: path {got} vs grid {want}",
                    target.name()
                );
            }
        }
        // Rows 1, 3, 6, 8, 10, 12 and 13 of the example are grid points.
        assert_eq!(matched, 7, "{extra:?}");
    }
    // Table 2 of seed 000 at (y, z) = (-1500, 600): 88.83 % printed, the
    // model gives 88.73 %.
    let doc = path_json(&file, &path, &[]);
    let r = f(&doc["instants"][0]["reliability"]["px"]);
    assert!((100.0 * r - 88.73).abs() < 0.005, "{r}");
}

/// Sample mean, sample std and their standard errors.
struct Estimate {
    mean: f64,
    std: f64,
    mean_se: f64,
    std_se: f64,
}

fn estimate(xs: &[f64]) -> Estimate {
    let n = xs.len() as f64;
    let mean = xs.iter().sum::<f64>() / n;
    let m2 = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    let m4 = xs.iter().map(|x| (x - mean).powi(4)).sum::<f64>() / n;
    let std = m2.sqrt();
    // Var(s²) ≈ (m4 − s⁴)/n, and Var(s) ≈ Var(s²)/(4 s²).
    let std_se = ((m4 - m2 * m2) / n).max(0.0).sqrt() / (2.0 * std);
    Estimate {
        mean,
        std,
        mean_se: std / n.sqrt(),
        std_se,
    }
}

#[test]
fn mean_and_std_by_linear_propagation_equal_a_monte_carlo_estimate() {
    // The five-axis example has two errors with a systematic (non-zero) mean.
    let (m, model, doc) = bevel_along_its_axes();
    let inputs = machine::inputs(&m).unwrap();
    // Inputs in the model's error order.
    let order: Vec<usize> = model
        .errors()
        .iter()
        .map(|e| inputs.index(e).expect("every error has statistics"))
        .collect();
    let params = machine::parameters(&m, &[]).unwrap();
    let vars: Vec<&str> = model.variables().to_vec();
    let axes = axes_of(&doc, &vars);
    let samples = 100_000;
    let mut worst: f64 = 0.0;
    for k in [0usize, 10, 20] {
        let q = axes[k].clone().unwrap();
        let inst = &doc["instants"][k];
        let mut rng = CaseRng::new(7, k as u32, 0);
        let mut x = vec![0.0; inputs.len()];
        let mut e = vec![0.0; inputs.len()];
        let mut out = [0.0; 6];
        let mut values: Vec<Vec<f64>> = (0..7).map(|_| Vec::with_capacity(samples)).collect();
        for _ in 0..samples {
            inputs.sample(&mut rng, &mut x);
            for (slot, &j) in e.iter_mut().zip(&order) {
                *slot = x[j];
            }
            model.error(&q, &params, &e, &mut out);
            for c in 0..6 {
                values[c].push(out[c]);
            }
            values[6].push((out[0] * out[0] + out[1] * out[1] + out[2] * out[2]).sqrt());
        }
        for (c, name) in ["px", "py", "pz", "ox", "oy", "oz", "volumetric"]
            .iter()
            .enumerate()
        {
            let est = estimate(&values[c]);
            let mean = f(&inst["mean"][name]);
            let std = f(&inst["std"][name]);
            let zm = (est.mean - mean) / est.mean_se;
            let zs = (est.std - std) / est.std_se;
            worst = worst.max(zm.abs()).max(zs.abs());
            assert!(
                zm.abs() < 4.5,
                "instant {k} {name}: mean {mean} vs MC {} (z {zm})",
                est.mean
            );
            assert!(
                zs.abs() < 4.5,
                "instant {k} {name}: std {std} vs MC {} (z {zs})",
                est.std
            );
        }
        // The propagated mean is far from zero (the systematic errors), so
        // the comparison checks the means, not only the spreads.
        let px = f(&inst["mean"]["px"]);
        let se = f(&inst["std"]["px"]) / (samples as f64).sqrt();
        assert!(px.abs() > 100.0 * se, "{px}");
    }
    eprintln!("largest |z| of the Monte Carlo check: {worst:.2}");
}

#[test]
fn pose_path_axes_equal_chain_inverse_first_solutions() {
    let file = bevel();
    let dir = scratch("pose");
    // `chain inverse` takes the header without `t`.
    let with_t = std::fs::read_to_string(example("cnc5_bevel_pose.csv")).unwrap();
    let without_t: String = with_t
        .lines()
        .map(|l| l.split_once(',').unwrap().1.to_string() + "\n")
        .collect();
    let bare = write(&dir, "pose.csv", &without_t);
    let inverse = ok_json(&["inverse", s(&file), "--pose", s(&bare), "--fix", "mu=0"]);
    let path = ok_json(&[
        "path",
        s(&file),
        "--pose",
        s(&example("cnc5_bevel_pose.csv")),
        "--fix",
        "mu=0",
        "--format",
        "json",
    ]);
    let (m, model) = load(&file);
    let vars: Vec<&str> = model.variables().to_vec();
    let rows = inverse["rows"].as_array().unwrap();
    let instants = path["instants"].as_array().unwrap();
    assert_eq!(rows.len(), 21);
    assert_eq!(instants.len(), 21);
    // The axis values the poses were generated from.
    let generating = path_json(&file, &example("cnc5_bevel_axes.csv"), &[]);
    let params = machine::parameters(&m, &[]).unwrap();
    for (k, (row, inst)) in rows.iter().zip(instants).enumerate() {
        assert_eq!(inst["status"], "ok");
        assert_eq!(inst["status"], row["status"]);
        assert!((f(&inst["t"]) - 0.1 * k as f64).abs() < 1e-12);
        let first = &row["solutions"][0];
        for v in &vars {
            assert_eq!(inst["axes"][v], first[v], "row {k} {v}");
            let want = f(&generating["instants"][k]["axes"][v]);
            assert!((f(&inst["axes"][v]) - want).abs() < 1e-9, "row {k} {v}");
        }
        // The nominal tool point is the pose's point.
        let q: Vec<f64> = vars.iter().map(|v| f(&inst["axes"][v])).collect();
        let pose: Vec<f64> = with_t
            .lines()
            .nth(k + 1)
            .unwrap()
            .split(',')
            .skip(1)
            .map(|x| x.parse().unwrap())
            .collect();
        let nominal = model.nominal(&q, &params).position;
        for c in 0..3 {
            assert!((f(&inst["nominal"][c]) - pose[c]).abs() < 1e-9);
            // (JSON parsing is exact to about 1 ulp.)
            assert!((f(&inst["nominal"][c]) - nominal[c]).abs() <= 1e-15 * nominal[c].abs());
        }
        // Same axes, same error statistics as the --axes path.
        for name in ["px", "py", "pz", "volumetric"] {
            let a = f(&inst["std"][name]);
            let b = f(&generating["instants"][k]["std"][name]);
            assert!((a - b).abs() < 1e-9 * b, "{name}: {a} vs {b}");
        }
    }
}

/// A machine whose tool axis reaches only a cone (a B head tilted 30° on a
/// vertical C axis: axes within 60° of +z), with statistics.
const CONE: &str = "machine: cone
parameters: {}
bodies:
  bed: {}
  x_slide: {parent: bed, joint: {type: prismatic, axis: +x, variable: x}, errors: {dx: exx, dy: eyx}}
  y_slide: {parent: x_slide, joint: {type: prismatic, axis: +y, variable: y}, errors: {dy: eyy}}
  z_slide: {parent: y_slide, joint: {type: prismatic, axis: +z, variable: z}, errors: {dz: ezz, ex: axz}}
  c_head: {parent: z_slide, joint: {type: rotary, axis: +z, variable: C}}
  b_head: {parent: c_head, rotation: [{about: x, angle: 30deg}], joint: {type: rotary, axis: +z, variable: B}, errors: {ex: abb}}
  tool: {parent: b_head, rotation: [{about: x, angle: 30deg}]}
workpiece: bed
tool: tool
tool_point: [0, 0, -100]
statistics:
  exx: {dist: normal, mean: 0, std: 0.002}
  eyx: {dist: normal, mean: 0, std: 0.002}
  eyy: {dist: normal, mean: 0.001, std: 0.002}
  ezz: {dist: normal, mean: 0, std: 0.002}
  axz: {dist: normal, mean: 0, std: 0.00002}
  abb: {dist: normal, mean: 0, std: 0.00003}
reliability:
  tolerance: {px: 0.01, py: 0.01, pz: 0.01}
  sided: two
";

#[test]
fn unreachable_rows_are_reported_not_dropped() {
    let dir = scratch("cone");
    let file = write(&dir, "cone.yaml", CONE);
    let pose = write(
        &dir,
        "pose.csv",
        "px,py,pz,i,j,k\n1,2,3,0.5,0,0.8660254037844386\n1,2,3,0,0,-1\n4,5,6,0,0.5,0.8660254037844386\n",
    );
    let doc = ok_json(&["path", s(&file), "--pose", s(&pose), "--format", "json"]);
    let inst = doc["instants"].as_array().unwrap();
    assert_eq!(inst.len(), 3);
    assert_eq!(inst[0]["status"], "ok");
    assert_eq!(inst[1]["status"], "unreachable");
    assert_eq!(inst[2]["status"], "ok");
    assert_eq!(inst[1]["row"], 2);
    assert_eq!(f(&inst[1]["t"]), 2.0);
    for key in ["axes", "nominal", "mean", "std", "reliability"] {
        assert!(inst[1][key].is_null(), "{key}");
        assert!(!inst[0][key].is_null(), "{key}");
    }
    let summary = &doc["summary"];
    assert_eq!(summary["instants"], 3);
    assert_eq!(summary["evaluated"], 2);
    assert_eq!(summary["unreachable"], 1);
    // Reliabilities are probabilities, the two-sided mean shift is seen.
    for i in [0, 2] {
        for c in ["px", "py", "pz"] {
            let r = f(&inst[i]["reliability"][c]);
            assert!(r > 0.5 && r < 1.0, "{c}: {r}");
        }
        assert!(f(&inst[i]["mean"]["py"]).abs() > 1e-4);
    }
    // CSV: one line per instant, empty cells for the unreachable one; never NaN.
    let text = ok_stdout(&["path", s(&file), "--pose", s(&pose), "--format", "csv"]);
    assert!(!text.to_lowercase().contains("nan"), "{text}");
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 4);
    let width = lines[0].split(',').count();
    assert!(lines.iter().all(|l| l.split(',').count() == width));
    let row2: Vec<&str> = lines[2].split(',').collect();
    assert_eq!(&row2[..2], ["2", "2.0"]);
    assert!(row2.contains(&"unreachable"));
    assert!(row2.iter().filter(|c| c.is_empty()).count() >= width - 3);
    // The table says so too.
    let text = ok_stdout(&["path", s(&file), "--pose", s(&pose)]);
    assert!(
        text.contains("unreachable") && text.contains("1 unreachable"),
        "{text}"
    );
}

#[test]
fn cli_json_shape_and_csv_rows() {
    let file = gantry();
    let path = example("gantry_path.csv");
    let mc = [
        "--method",
        "mc",
        "--samples",
        "2000",
        "--seed",
        "3",
        "--system",
        "volumetric",
    ];
    let doc = path_json(&file, &path, &mc);
    let keys: Vec<&str> = doc
        .as_object()
        .unwrap()
        .keys()
        .map(String::as_str)
        .collect();
    assert_eq!(
        keys,
        [
            "machine",
            "method",
            "input",
            "frame",
            "sided",
            "tolerances",
            "variables",
            "instants",
            "summary"
        ]
    );
    assert_eq!(doc["machine"], "gantry_grinder");
    assert_eq!(doc["method"], "mc");
    assert_eq!(doc["input"], "axes");
    assert_eq!(doc["frame"], "tool");
    assert_eq!(doc["sided"], "upper");
    assert_eq!(f(&doc["tolerances"]["volumetric"]), 0.03);
    assert_eq!(doc["variables"], serde_json::json!(["x", "z", "y"]));
    let instants = doc["instants"].as_array().unwrap();
    assert_eq!(instants.len(), 13);
    let i4 = &instants[4];
    let keys: Vec<&str> = i4.as_object().unwrap().keys().map(String::as_str).collect();
    assert_eq!(
        keys,
        [
            "row",
            "t",
            "axes",
            "status",
            "nominal",
            "mean",
            "std",
            "reliability",
            "std_error",
            "cases"
        ]
    );
    // Monte Carlo has no FORM account; its calls are the samples.
    for t in ["px", "volumetric"] {
        let c = &i4["cases"][t];
        assert!(c.get("termination").is_none(), "{c}");
        assert_eq!(c["calls"]["values"], 2000);
    }
    assert!(doc["summary"].get("form").is_none());
    assert_eq!(
        doc["summary"]["calls"]["values"].as_u64(),
        Some(13 * 4 * 2000)
    );
    assert_eq!(i4["row"], 5);
    assert_eq!(f(&i4["t"]), 4.0);
    assert_eq!(
        i4["axes"],
        serde_json::json!({"x": 500.0, "z": 700.0, "y": -1125.0})
    );
    // The gantry's nominal tool point is (-x, y, z) (seed 000, Eq. 7-8).
    assert_eq!(i4["nominal"], serde_json::json!([-500.0, -1125.0, 700.0]));
    let quantities = ["px", "py", "pz", "ox", "oy", "oz", "volumetric"];
    for key in ["mean", "std"] {
        let o = i4[key].as_object().unwrap();
        assert_eq!(o.keys().map(String::as_str).collect::<Vec<_>>(), quantities);
    }
    let targets = ["px", "py", "pz", "volumetric"];
    for key in ["reliability", "std_error"] {
        let o = i4[key].as_object().unwrap();
        assert_eq!(o.keys().map(String::as_str).collect::<Vec<_>>(), targets);
    }
    // Summary: min and mean over the instants, the worst instant.
    let summary = &doc["summary"];
    for t in targets {
        let rs: Vec<f64> = instants.iter().map(|i| f(&i["reliability"][t])).collect();
        let min = rs.iter().copied().fold(f64::INFINITY, f64::min);
        let mean = rs.iter().sum::<f64>() / rs.len() as f64;
        let o = &summary["reliability"][t];
        assert_eq!(f(&o["min"]), min);
        assert!((f(&o["mean"]) - mean).abs() < 1e-15);
        let worst = o["worst"]["row"].as_u64().unwrap() as usize;
        assert_eq!(f(&instants[worst - 1]["reliability"][t]), min);
        assert_eq!(o["met"], false);
    }
    let e = &summary["error"]["px"];
    let max_std = instants
        .iter()
        .map(|i| f(&i["std"]["px"]))
        .fold(0.0, f64::max);
    assert_eq!(f(&e["max_std"]), max_std);
    assert!(summary["error"]["volumetric"]["max_mean"].is_number());
    assert_eq!(summary["requirement"]["met"], false);
    // Reproducible with the seed.
    let again = path_json(&file, &path, &mc);
    assert_eq!(doc, again);

    // CSV: a header and one row per instant, the same numbers.
    let text = ok_stdout(&["path", s(&file), "--axes", s(&path), "--format", "csv"]);
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 14);
    let header: Vec<&str> = lines[0].split(',').collect();
    assert_eq!(&header[..6], ["row", "t", "x", "z", "y", "status"]);
    assert!(header.contains(&"std_volumetric") && header.contains(&"reliability_pz"));
    let form = path_json(&file, &path, &[]);
    let col = header.iter().position(|h| *h == "reliability_px").unwrap();
    for (k, line) in lines[1..].iter().enumerate() {
        let cells: Vec<&str> = line.split(',').collect();
        assert_eq!(cells.len(), header.len());
        let r: f64 = cells[col].parse().unwrap();
        assert!((r - f(&form["instants"][k]["reliability"]["px"])).abs() <= 1e-15);
    }
    // FORM's account, appended: per-target termination and calls columns.
    let last = &header[header.len() - 3..];
    assert_eq!(
        last,
        [
            "gradient_calls_px",
            "gradient_calls_py",
            "gradient_calls_pz"
        ]
    );
    let term = header.iter().position(|h| *h == "termination_px").unwrap();
    assert!(lines[1..]
        .iter()
        .all(|l| l.split(',').nth(term) == Some("closed_form")));
    // And in the FORM JSON: every case closed form, converged, exact.
    assert_eq!(form["summary"]["form"]["cases"], 13 * 3);
    assert_eq!(form["summary"]["form"]["converged"], 13 * 3);
    assert_eq!(
        form["summary"]["form"]["terminations"],
        serde_json::json!({"closed_form": 39})
    );
    let c = &form["instants"][0]["cases"]["py"];
    assert_eq!(c["termination"], "closed_form");
    assert_eq!(c["exact"], true);
    assert_eq!(c["converged"], true);
}

#[test]
fn header_order_fix_and_stdin() {
    let file = gantry();
    let dir = scratch("fix");
    let reference = path_json(&file, &example("gantry_path.csv"), &[]);
    // Without t (the row number is the instant), other column order, z held.
    let csv = write(&dir, "xy.csv", "y,x\n-1500,0\n-750,500\n");
    let held = path_json(&file, &csv, &["--fix", "z=600"]);
    let inst = held["instants"].as_array().unwrap();
    assert_eq!(f(&inst[1]["t"]), 2.0);
    assert_eq!(
        inst[0]["reliability"],
        reference["instants"][0]["reliability"]
    );
    assert_eq!(
        inst[1]["axes"],
        serde_json::json!({"x": 500.0, "z": 600.0, "y": -750.0})
    );
    // `-` reads stdin: what `chain motion --format csv` prints (t, variables).
    let doc = success_json(chain_stdin(
        &["path", s(&file), "--axes", "-", "--format", "json"],
        b"t,x,z,y\n0.5,0,600,-1500\n",
    ));
    assert_eq!(f(&doc["instants"][0]["t"]), 0.5);
    assert_eq!(
        doc["instants"][0]["reliability"],
        reference["instants"][0]["reliability"]
    );
}

#[test]
fn bad_input_is_a_clear_error_naming_file_and_line() {
    let file = gantry();
    let g = s(&file);
    let dir = scratch("bad");
    // Writes `name` and gives it to `chain path` as the last argument of
    // `args`; the command must fail naming each of `needles`.
    let rejects = |args: &[&str], name: &str, text: &str, needles: &[&str]| {
        let bad = write(&dir, name, text);
        let mut args = args.to_vec();
        args.push(s(&bad));
        let err = fails(&args);
        for n in needles {
            assert!(err.contains(n), "{name}: `{n}` not in\n{err}");
        }
    };
    let on_axes = ["path", g, "--axes"];
    rejects(
        &on_axes,
        "cell.csv",
        "t,x,y,z\n0,0,0,600\n1,oops,0,600\n",
        &["cell.csv:3:", "oops", "`x`"],
    );
    rejects(
        &on_axes,
        "inf.csv",
        "x,y,z\n0,0,inf\n",
        &["inf.csv:2:", "not finite"],
    );
    rejects(
        &on_axes,
        "ragged.csv",
        "x,y,z\n0,0,600\n0,0\n",
        &["ragged.csv:3:"],
    );
    rejects(
        &on_axes,
        "unknown.csv",
        "t,x,yy,z\n0,0,0,600\n",
        &["unknown.csv:1:", "`yy`", "`y`"],
    );
    rejects(
        &on_axes,
        "missing.csv",
        "x,y\n0,0\n",
        &["missing.csv:1:", "`z`", "--fix"],
    );
    rejects(
        &on_axes,
        "twice.csv",
        "x,y,z,x\n0,0,600,0\n",
        &["twice.csv:1:", "twice"],
    );

    let both = write(&dir, "both.csv", "x,y,z\n0,0,600\n");
    let err = fails(&["path", g, "--axes", s(&both), "--fix", "z=1"]);
    assert!(err.contains("`z`") && err.contains("--fix"), "{err}");

    let err = fails(&["path", g, "--axes", s(&both), "--fix", "w=1"]);
    assert!(err.contains("`w`"), "{err}");

    rejects(
        &on_axes,
        "header_only.csv",
        "x,y,z\n",
        &["header_only.csv:1:", "chain::csv::no_data"],
    );
    rejects(&on_axes, "empty.csv", "", &["empty.csv:1:"]);

    let err = fails(&["path", g, "--axes", s(&dir.join("absent.csv"))]);
    assert!(err.contains("absent.csv"), "{err}");

    // Poses: header, zero axis.
    let b = bevel();
    let on_poses = ["path", s(&b), "--fix", "mu=0", "--pose"];
    rejects(
        &on_poses,
        "pose_header.csv",
        "x,y,z,i,j,k\n1,2,3,0,0,1\n",
        &["pose_header.csv:1:", "px,py,pz,i,j,k"],
    );
    rejects(
        &on_poses,
        "pose_zero.csv",
        "px,py,pz,i,j,k\n1,2,3,0,0,1\n1,2,3,0,0,0\n",
        &["pose_zero.csv:3:", "zero"],
    );

    // Neither or both inputs.
    fails(&["path", g]);
    fails(&["path", g, "--axes", s(&both), "--pose", s(&both)]);

    // A machine without a reliability section, or without statistics.
    let plain = example_path("cnc5_bevel.yaml");
    let err = fails(&[
        "path",
        s(&plain),
        "--axes",
        s(&example("cnc5_bevel_axes.csv")),
    ]);
    assert!(err.contains("reliability"), "{err}");
    let no_stats: String = CONE
        .lines()
        .filter(|l| !l.starts_with("statistics:") && !l.starts_with("  e") && !l.starts_with("  a"))
        .map(|l| format!("{l}\n"))
        .collect();
    let no_stats = write(&dir, "no_stats.yaml", &no_stats);
    let axes = write(&dir, "cone_axes.csv", "x,y,z,C,B\n0,0,0,0,0\n");
    let err = fails(&["path", s(&no_stats), "--axes", s(&axes)]);
    assert!(err.contains("statistics"), "{err}");
}

#[test]
fn plot_writes_reliability_and_std_charts() {
    let dir = scratch("plot");
    // Only the JSON document on stdout.
    path_json(
        &bevel(),
        &example("cnc5_bevel_axes.csv"),
        &["--plot", s(&dir)],
    );
    for stem in ["path_reliability", "path_std"] {
        for ext in ["png", "svg"] {
            let p = dir.join(format!("{stem}.{ext}"));
            let len = std::fs::metadata(&p).map(|m| m.len()).unwrap_or(0);
            assert!(len > 1000, "{} has {len} bytes", p.display());
        }
    }
    // No orientation tolerance: no angular chart.
    assert!(!dir.join("path_std_angular.png").exists());
}

#[test]
fn moments_follow_the_sensitivity_rows() {
    // std(px) at an instant is √(Σ_j S_pxj² σ_j²) of the model's exact
    // sensitivities (an independent evaluation of the same formula).
    let (m, model, doc) = bevel_along_its_axes();
    let inputs = machine::inputs(&m).unwrap();
    let params = machine::parameters(&m, &[]).unwrap();
    let vars: Vec<&str> = model.variables().to_vec();
    let n = model.errors().len();
    for (k, q) in axes_of(&doc, &vars).into_iter().enumerate() {
        let q = q.unwrap();
        let mut sens = vec![0.0; 6 * n];
        model.sensitivity(&q, &params, &mut sens);
        for c in Component::ALL {
            let (mut mean, mut var) = (0.0, 0.0);
            for (j, e) in model.errors().iter().enumerate() {
                let i = inputs.index(e).unwrap();
                let sij = sens[c.index() * n + j];
                mean += sij * inputs.means()[i];
                var += sij * sij * inputs.stds()[i].powi(2);
            }
            let inst = &doc["instants"][k];
            let (gm, gs) = (f(&inst["mean"][c.name()]), f(&inst["std"][c.name()]));
            assert!(
                (gm - mean).abs() <= 1e-12 * var.sqrt().max(1e-300),
                "{k} {c:?}"
            );
            assert!((gs - var.sqrt()).abs() <= 1e-12 * var.sqrt(), "{k} {c:?}");
        }
    }
}

#[test]
fn chain_motion_csv_feeds_chain_path_directly() {
    // The bridge from motion to path: the converted bevel-gear motion
    // (`chain motion --format csv`, header `t,<variables>`) read by
    // `chain path --axes -`.
    let text = ok_stdout(&[
        "motion",
        s(&example_path("cnc5_bevel.yaml")),
        "--settings",
        s(&example_file("settings/seed002_concave.yaml")),
        "--format",
        "csv",
        "--samples",
        "5",
    ]);
    let doc = success_json(chain_stdin(
        &["path", s(&bevel()), "--axes", "-", "--format", "json"],
        text.as_bytes(),
    ));
    let lines: Vec<&str> = text.lines().collect();
    let header: Vec<&str> = lines[0].split(',').collect();
    let instants = doc["instants"].as_array().unwrap();
    assert_eq!(instants.len(), lines.len() - 1);
    for (inst, line) in instants.iter().zip(&lines[1..]) {
        let cells: Vec<f64> = line.split(',').map(|c| c.parse().unwrap()).collect();
        assert_eq!(inst["status"], "ok");
        assert!((f(&inst["t"]) - cells[0]).abs() <= 1e-15 * cells[0].abs());
        for (name, value) in header.iter().zip(&cells).skip(1) {
            assert!((f(&inst["axes"][name]) - value).abs() <= 1e-15 * value.abs().max(1.0));
        }
        let r = f(&inst["reliability"]["px"]);
        assert!(r > 0.5 && r < 1.0, "{r}");
    }
}
