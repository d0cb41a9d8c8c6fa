//! `chain circular` (spec `circular.md`, `docs/circular.md`): the ISO
//! 230-4 evaluation of simulated ballbar runs against the test's own
//! arithmetic (a centre offset, an ellipse, a direction-dependent radius),
//! the document's keys, and every refusal of a run file or option located.

use crate::common;

use common::cli::{fails, ok_json, ok_stdout, scratch_file, unwrapped};
use serde_json::Value;

/// A run file (µm) of two runs: run A at R = 100 mm, feed 1000, plane xy,
/// both directions, 720 samples each, with a set-up offset (12, −7) µm, an
/// ellipse 4 µm · cos 2θ and the clockwise path 1.5 µm outside; run B at
/// R = 150 mm in zx, counter-clockwise only, round about an offset (3, 4).
fn two_runs() -> String {
    let mut s = String::from("run,radius,feed,plane,angle,direction,deviation(um)\n");
    let offset = |c1: f64, c2: f64, r: f64, t: f64| {
        // The exact radial deviation of a circle whose centre is (c1, c2).
        let (sn, cs) = t.to_radians().sin_cos();
        let across = -c1 * sn + c2 * cs;
        (r * r - across * across).sqrt() + c1 * cs + c2 * sn - r
    };
    for (dir, ccw) in [("ccw", true), ("cw", false)] {
        for k in 0..720 {
            let t = if ccw {
                0.5 * k as f64
            } else {
                360.0 - 0.5 * k as f64
            };
            let d = offset(0.012, -0.007, 100.0, t)
                + 0.004 * (2.0 * t.to_radians()).cos()
                + if ccw { 0.0 } else { 0.0015 };
            s.push_str(&format!("A,100,1000,xy,{t},{dir},{}\n", d * 1e3));
        }
    }
    for k in 0..360 {
        let t = k as f64;
        let d = offset(0.003, 0.004, 150.0, t);
        s.push_str(&format!("B,150,2000,zx,{t},ccw,{}\n", d * 1e3));
    }
    s
}

fn num(v: &Value) -> f64 {
    v.as_f64().expect("a number")
}

#[test]
fn the_evaluation_is_the_test_s_own_arithmetic() {
    let file = scratch_file("two_runs.csv", &two_runs());
    let file = file.to_str().unwrap();
    let doc = ok_json(&["circular", file, "--format", "json"]);
    assert_eq!(doc["unit"], "mm");
    assert_eq!(doc["centre"], "least_squares");
    let runs = doc["runs"].as_array().unwrap();
    assert_eq!(runs.len(), 2);
    let a = &runs[0];
    assert_eq!(
        (a["run"].as_str(), a["plane"].as_str()),
        (Some("A"), Some("xy"))
    );
    assert_eq!((num(&a["radius"]), num(&a["feed"])), (100.0, 1000.0));
    // The ellipse about the removed offset: G = 2·4 µm, F = ±4 µm (+1.5
    // clockwise), to first order: the offset's and the ellipse's cross
    // terms are about |c|·A/R = 14 µm · 4 µm / 100 mm ≈ 0.6 nm, so 1 nm.
    for (dir, shift) in [("ccw", 0.0), ("cw", 0.0015)] {
        let d = &a["directions"][dir];
        let keys: Vec<&String> = d.as_object().unwrap().keys().collect();
        for k in ["G", "F_max", "F_min", "centre"] {
            assert!(keys.iter().any(|x| *x == k), "{dir}: {keys:?}");
        }
        assert!((num(&d["G"]) - 0.008).abs() < 1e-6, "{dir}: {d}");
        assert!(
            (num(&d["F_max"]) - (0.004 + shift)).abs() < 1e-6,
            "{dir}: {d}"
        );
        assert!(
            (num(&d["F_min"]) - (shift - 0.004)).abs() < 1e-6,
            "{dir}: {d}"
        );
        assert!((num(&d["centre"][0]) - 0.012).abs() < 1e-6, "{d}");
        assert!((num(&d["centre"][1]) + 0.007).abs() < 1e-6, "{d}");
    }
    assert!((num(&a["H"]) - 0.0015).abs() < 1e-6, "{a}");
    assert!((num(&a["G_b"]) - 0.0095).abs() < 1e-6, "{a}");
    // Run B: one direction, round: no G(b), no H.
    let b = &runs[1];
    assert_eq!(
        (b["plane"].as_str(), num(&b["radius"])),
        (Some("zx"), 150.0)
    );
    let ccw = &b["directions"]["ccw"];
    assert!(num(&ccw["G"]) < 1e-9 && (num(&ccw["centre"][1]) - 0.004).abs() < 1e-9);
    assert!(b["directions"].get("cw").is_none() && b["G_b"].is_null() && b["H"].is_null());
    // The table says the same, in µm.
    let table = ok_stdout(&["circular", file]);
    assert!(
        table.contains("run A: plane xy, radius 100 mm, feed 1000 mm/min"),
        "{table}"
    );
    assert!(
        table.contains("G(b) 9.50, circular hysteresis H 1.50"),
        "{table}"
    );
    assert!(
        table.contains("      8.00       4.00      -4.00      12.00      -7.00      720"),
        "{table}"
    );
}

#[test]
fn every_refusal_is_located() {
    let good = two_runs();
    let check = |name: &str, text: &str, args: &[&str], needles: &[&str]| {
        let file = scratch_file(name, text);
        let mut all = vec!["circular", file.to_str().unwrap()];
        all.extend_from_slice(args);
        let err = unwrapped(&fails(&all));
        for n in needles {
            assert!(err.contains(n), "{name}: `{n}` missing from {err}");
        }
    };
    check(
        "no_direction.csv",
        "angle,deviation\n0,1\n",
        &["--radius", "100"],
        &[
            "no_direction.csv:1:",
            "no `direction` column",
            "chain::circular::missing_column",
        ],
    );
    check(
        "direction.csv",
        &good.replacen(",ccw,", ",up,", 1),
        &[],
        &["direction.csv:2:", "`up` is not a direction"],
    );
    check(
        "plane.csv",
        &good.replacen(",xy,", ",xq,", 1),
        &[],
        &["plane.csv:2:", "`xq` is not a plane"],
    );
    check(
        "radius.csv",
        &good.replacen("A,100,", "A,-100,", 1),
        &[],
        &["radius.csv:2:", "the radius must be positive, got -100"],
    );
    // Line 5 of the file: the fourth sample of run A.
    let lines: Vec<String> = good.lines().map(str::to_string).collect();
    let mut changed = lines.clone();
    changed[4] = changed[4].replacen("A,100,", "A,101,", 1);
    check(
        "differs.csv",
        &(changed.join("\n") + "\n"),
        &[],
        &[
            "differs.csv:5:",
            "run A: radius 101 differs from its first row's 100 (line 2)",
        ],
    );
    let gap: String = lines
        .iter()
        .filter(|l| {
            let cells: Vec<&str> = l.split(',').collect();
            let t: f64 = cells[4].parse().unwrap_or(-1.0);
            !(cells[0] == "B" && t > 30.0 && t < 60.0)
        })
        .map(|l| format!("{l}\n"))
        .collect();
    check(
        "gap.csv",
        &gap,
        &[],
        &[
            "run B, ccw: no sample between 30° and 60°",
            "widest gap allowed is 10°",
        ],
    );
    let mut nan = lines.clone();
    nan[2] = format!("{},nan", nan[2].rsplit_once(',').unwrap().0);
    check(
        "nan.csv",
        &(nan.join("\n") + "\n"),
        &[],
        &["nan.csv:3:", "deviation(um)"],
    );
    let no_radius = "angle,direction,deviation\n".to_string()
        + &(0..36)
            .map(|k| format!("{},ccw,0\n", 10 * k))
            .collect::<String>();
    check(
        "no_radius.csv",
        &no_radius,
        &[],
        &[
            "no_radius.csv:1:",
            "run 1 has no radius",
            "a `radius` column",
        ],
    );
    // µm in a column read as mm: a deviation of a tenth of the radius.
    check(
        "large.csv",
        &no_radius.replacen("\n20,ccw,0\n", "\n20,ccw,12\n", 1),
        &["--radius", "100"],
        &[
            "large.csv:4:",
            "a deviation of 12 mm on a radius of 100 mm",
            "deviation(um)",
        ],
    );
    // Enough rows, too few distinct angles.
    let two_angles = "angle,direction,deviation\n".to_string()
        + &(0..40)
            .map(|k| format!("{},ccw,0\n", if k % 2 == 0 { 0 } else { 180 }))
            .collect::<String>();
    check(
        "two_angles.csv",
        &two_angles,
        &["--radius", "100"],
        &["run 1, ccw: 2 distinct angle(s); a circle needs at least 8"],
    );
    // The options, named.
    check(
        "opt.csv",
        &no_radius,
        &["--radius", "100", "--arc", "400"],
        &["--arc 400", "[45, 360]"],
    );
    check(
        "opt2.csv",
        &no_radius,
        &["--radius", "100", "--plane", "ab"],
        &["--plane ab"],
    );
    check(
        "opt3.csv",
        &no_radius,
        &["--radius=-1"],
        &["--radius -1", "positive"],
    );
    check(
        "opt4.csv",
        &no_radius,
        &["--radius", "100", "--pitch", "w=5"],
        &["--pitch w=5", "x, y or z"],
    );
    check(
        "opt5.csv",
        &no_radius,
        &["--radius", "100", "--pitch", "x=5", "--pitch", "X=6"],
        &["--pitch X=6", "given twice"],
    );
    check(
        "opt6.csv",
        &no_radius,
        &["--radius", "100", "--pitch", "x=0"],
        &["--pitch x=0", "positive length"],
    );
    check(
        "opt7.csv",
        &no_radius,
        &["--radius", "100", "--pitch", "x10"],
        &["--pitch", "expected AXIS=MM"],
    );
    check(
        "opt8.csv",
        &no_radius,
        &["--radius", "100", "--window", "45"],
        &["--window 45", "less than 45"],
    );
}

/// The example runs (examples/circular/generate.py: a time-domain
/// simulation with stated errors): each run's least-squares centre is its
/// stated set-up offset within 0.1 µm (the lag turns it by |c|·ωτ), and
/// its radius offset the stated `r0` (the servo lag's `−v²τ²/(2R)`
/// mostly) within 0.1 µm, in both directions.
#[test]
fn the_example_runs_read_their_stated_set_up() {
    let file = common::example_file("circular/runs.csv");
    let text = std::fs::read_to_string(&file).unwrap();
    let offsets: Vec<(String, [f64; 2])> = text
        .lines()
        .find(|l| l.starts_with("# truth: set-up offset"))
        .unwrap()
        .split_whitespace()
        .filter_map(|w| {
            let (run, c) = w.split_once("=(")?;
            let (a, b) = c.trim_end_matches(')').split_once(',')?;
            Some((run.to_string(), [a.parse().ok()?, b.parse().ok()?]))
        })
        .collect();
    assert_eq!(offsets.len(), 6);
    let r0 = |run: &str| -> f64 {
        let (plane, feed) = run.split_once('_').unwrap();
        let line = text
            .lines()
            .find(|l| l.starts_with(&format!("# derived {plane}:")))
            .unwrap();
        let at = line.find(&format!("{feed}=")).unwrap() + feed.len() + 1;
        line[at..]
            .split_whitespace()
            .next()
            .unwrap()
            .parse()
            .unwrap()
    };
    let doc = ok_json(&["circular", file.to_str().unwrap(), "--format", "json"]);
    let runs = doc["runs"].as_array().unwrap();
    assert_eq!(runs.len(), 6);
    for run in runs {
        let id = run["run"].as_str().unwrap();
        let c = offsets.iter().find(|(r, _)| r == id).unwrap().1;
        for dir in ["ccw", "cw"] {
            let d = &run["directions"][dir];
            for k in 0..2 {
                let got = 1e3 * num(&d["centre"][k]);
                assert!(
                    (got - c[k]).abs() < 0.1,
                    "{id} {dir}: centre {got} µm, stated {}",
                    c[k]
                );
            }
            let got = 1e3 * num(&d["radius_offset"]);
            assert!(
                (got - r0(id)).abs() < 0.1,
                "{id} {dir}: r0 {got} µm, stated {}",
                r0(id)
            );
        }
    }
}

/// The diagnosis of the example reads the generator's stated machine
/// (`examples/circular/runs.csv`'s `# derived` lines, from
/// `examples/circular/generate.py`): per plane squareness, scale mismatch,
/// each axis's backlash, servo mismatch and the gain term, each within
/// three of its standard errors plus an allowance for what the first-order
/// model leaves (docs/circular.md, "Checked against simulation": the
/// backlash step's delay and ramp 1 %, the servo's higher orders 1 %), and
/// each run's radius offset within 0.1 µm.
#[test]
fn the_example_diagnosis_reads_the_generator_s_machine() {
    let file = common::example_file("circular/runs.csv");
    let text = std::fs::read_to_string(&file).unwrap();
    let doc = ok_json(&["circular", file.to_str().unwrap(), "--format", "json"]);
    let diagnosis = doc["diagnosis"].as_array().unwrap();
    for plane in ["xy", "yz", "zx"] {
        let line = text
            .lines()
            .find(|l| l.starts_with(&format!("# derived {plane}:")))
            .unwrap();
        let stated = |key: &str| -> f64 {
            let part = (line.split(", "))
                .find(|p| {
                    p.trim_start_matches(&format!("# derived {plane}: "))
                        .starts_with(&format!("{key}="))
                })
                .unwrap_or_else(|| panic!("{key} in {line}"));
            let value = part.rsplit('=').next().unwrap();
            value.split_whitespace().next().unwrap().parse().unwrap()
        };
        let axes = match plane {
            "xy" => ["x", "y"],
            "yz" => ["y", "z"],
            _ => ["z", "x"],
        };
        let got = |error: &str, axes: &[&str]| -> (f64, f64, &'static str) {
            let e = (diagnosis.iter())
                .find(|e| {
                    e["plane"] == plane
                        && e["error"] == error
                        && e["axes"] == serde_json::json!(axes)
                })
                .unwrap_or_else(|| panic!("{plane} {error} {axes:?}"));
            let unit = match e["unit"].as_str().unwrap() {
                "urad" => "urad",
                "ppm" => "ppm",
                "um" => "um",
                "ms" => "ms",
                _ => "ms^2",
            };
            (num(&e["value"]), num(&e["uncertainty"]), unit)
        };
        for (error, key, axes, allowance) in [
            ("squareness", "S", &axes[..], 0.1),
            ("scale_mismatch", "de", &axes[..], 0.1),
            ("backlash", "B_a", &axes[..1], 0.02),
            ("backlash", "B_b", &axes[1..], 0.02),
            ("servo_mismatch", "dt", &axes[..], 0.01),
            ("gain_mismatch", "q", &axes[..], 0.02),
        ] {
            let (value, se, unit) = got(error, axes);
            let truth = stated(key);
            // Relative allowances for backlash, servo and gain; absolute
            // (µrad, ppm) for the geometry.
            let allowance = if matches!(unit, "urad" | "ppm") {
                allowance
            } else {
                allowance * truth.abs()
            };
            assert!(
                (value - truth).abs() <= 3.0 * se + allowance,
                "{plane} {error} {axes:?}: {value} ± {se} {unit}, stated {truth}"
            );
        }
        // The servo mismatch explains most of every run's G (the lag
        // difference at 1000 and 3000 mm/min), squareness a part of it:
        // shares are of G, between 0 and 1.
        let share = |error: &str| -> f64 {
            let e = (diagnosis.iter())
                .find(|e| e["plane"] == plane && e["error"] == error)
                .unwrap();
            num(&e["share"])
        };
        assert!(share("servo_mismatch") > 0.5 && share("servo_mismatch") <= 1.0);
        assert!(share("squareness") > 0.02 && share("squareness") < 0.5);
    }
    // Two feeds and both directions: everything separated, only the
    // cyclic errors (no pitch given) not fitted.
    for fit in doc["fit"].as_array().unwrap() {
        for n in fit["not_fitted"].as_array().unwrap() {
            assert_eq!(n["reason"], "no_pitch", "{n}");
        }
        assert_eq!(fit["correlated"], serde_json::json!([]), "{fit}");
    }
}

/// `--plot DIR`: one polar plot per run, PNG and SVG, both directions with
/// their G and F in the legend, G(b) and H in the title, the rings' scale.
#[test]
fn the_polar_plots_are_one_per_run() {
    let file = common::example_file("circular/runs.csv");
    let dir = common::cli::scratch("circular-plot");
    ok_stdout(&[
        "circular",
        file.to_str().unwrap(),
        "--plot",
        dir.to_str().unwrap(),
    ]);
    let doc = ok_json(&["circular", file.to_str().unwrap(), "--format", "json"]);
    for run in doc["runs"].as_array().unwrap() {
        let id = run["run"].as_str().unwrap();
        let svg = std::fs::read_to_string(dir.join(format!("circular_{id}.svg"))).unwrap();
        let g = |dir: &str| 1e3 * num(&run["directions"][dir]["G"]);
        for label in [
            format!("run {id}: "),
            format!("ccw (G {:.2} µm", g("ccw")),
            format!("cw (G {:.2} µm", g("cw")),
            format!(
                "G(b) {:.2} µm, H {:.2} µm",
                1e3 * num(&run["G_b"]),
                1e3 * num(&run["H"])
            ),
            "nominal radius (0 µm)".to_string(),
        ] {
            assert!(svg.contains(&label), "{id}: `{label}`");
        }
        // The diagnosis in the legend: the run's plane's servo mismatch
        // (most of G in these runs) with its value and share of this run's G.
        let servo = (doc["diagnosis"].as_array().unwrap().iter())
            .find(|e| e["error"] == "servo_mismatch" && e["plane"] == run["plane"])
            .unwrap();
        let share = (servo["shares"].as_array().unwrap().iter())
            .find(|s| s["run"] == id)
            .unwrap();
        let label = format!(
            "servo mismatch {} {:.3} ms ({:.0}% of G)",
            servo["axes"]
                .as_array()
                .unwrap()
                .iter()
                .map(|a| a.as_str().unwrap())
                .collect::<Vec<_>>()
                .join("-"),
            num(&servo["value"]),
            100.0 * num(&share["share"])
        );
        assert!(svg.contains(&label), "{id}: `{label}`");
        let png = std::fs::read(dir.join(format!("circular_{id}.png"))).unwrap();
        assert!(
            png.starts_with(b"\x89PNG") && png.len() > 20_000,
            "{}",
            png.len()
        );
    }
}

/// A serial X-Y-Z machine with a scale error per axis (`E<i><i>_1`, ppm
/// as a slope) and the three squareness errors: EC0Y (about z, after X:
/// the Y travel is (−EC0Y, 1, 0)), EA0Z and EB0Z (after Y: the Z travel is
/// (EB0Z, −EA0Z, 1)), right-hand rotations.
const BALLBAR_XYZ: &str = "machine: ballbar_xyz
bodies:
  bed: {}
  x_slide:
    parent: bed
    joint: {type: prismatic, axis: +x, variable: x}
    errors: {dx: {name: EXX, powers: [1]}}
    squareness: {ez: EC0Y}
  y_slide:
    parent: x_slide
    joint: {type: prismatic, axis: +y, variable: y}
    errors: {dy: {name: EYY, powers: [1]}}
    squareness: {ex: EA0Z, ey: EB0Z}
  z_slide:
    parent: y_slide
    joint: {type: prismatic, axis: +z, variable: z}
    errors: {dz: {name: EZZ, powers: [1]}}
  tool: {parent: z_slide}
workpiece: bed
tool: tool
tool_point: [0, 0, 0]
frame: workpiece
";

/// The simulated truth: scales (1), squareness (rad), and per plane the
/// table ball's offset along a, b and the bar's length offset (mm).
const SCALE: [f64; 3] = [10e-6, -5e-6, 0.0];
const SQUARE: [(&str, f64); 3] = [("EC0Y", 20e-6), ("EA0Z", -15e-6), ("EB0Z", 10e-6)];
const SETUP: [(&str, [f64; 3]); 3] = [
    ("xy", [0.003, -0.002, 0.0015]),
    ("yz", [-0.001, 0.004, -0.001]),
    ("zx", [0.002, 0.001, 0.002]),
];

/// The ballbar runs of that machine about the centre (200, 150, 100), R =
/// 100 mm, xy, yz and zx, both directions, a sample a degree: the exact
/// distance between the tool ball (each axis's travel scaled and tilted as
/// the machine's errors say, to first order in the errors) and the table
/// ball (at the centre plus its offset), less R, plus the bar's offset.
/// With `axes`, each sample's pose in columns `x`, `y`, `z`.
fn ballbar_runs(axes: bool) -> String {
    let [ex, ey, ez] = SCALE;
    let (c, a, b) = (SQUARE[0].1, SQUARE[1].1, SQUARE[2].1);
    let tool = |q: [f64; 3]| {
        let [x, y, z] = q;
        [
            x * (1.0 + ex) - c * y + b * z,
            y * (1.0 + ey) - a * z,
            z * (1.0 + ez),
        ]
    };
    let centre = [200.0, 150.0, 100.0];
    let mut s = String::from(if axes {
        "run,radius,plane,angle,direction,deviation(um),x,y,z\n"
    } else {
        "run,radius,plane,angle,direction,deviation(um)\n"
    });
    for (plane, [sa, sb, length]) in SETUP {
        let (ia, ib) = match plane {
            "xy" => (0, 1),
            "yz" => (1, 2),
            _ => (2, 0),
        };
        for (d, name) in [(1i32, "ccw"), (-1, "cw")] {
            for k in 0..360 {
                let deg = (d * k).rem_euclid(360);
                let t = f64::from(deg).to_radians();
                let mut q = centre;
                q[ia] += 100.0 * t.cos();
                q[ib] += 100.0 * t.sin();
                let p = tool(q);
                let mut ball = centre;
                ball[ia] += sa;
                ball[ib] += sb;
                let dist = ((0..3).map(|i| (p[i] - ball[i]).powi(2)).sum::<f64>()).sqrt();
                let dev = (dist - 100.0 + length) * 1e3;
                s.push_str(&format!("{plane},100,{plane},{deg},{name},{dev:.7}"));
                if axes {
                    s.push_str(&format!(",{},{},{}", q[0], q[1], q[2]));
                }
                s.push('\n');
            }
        }
    }
    s
}

/// `chain identify --circular`: the runs of three planes recover the
/// machine's three squareness errors and (with z's scale fixed, as a laser
/// would give it: the bar's length takes each run's mean scale) the scale
/// errors of x and y, and each run's table-ball offset and bar length; the
/// same from the poses in the file's columns (`--axes`).
#[test]
fn identify_reads_a_circular_test() {
    let dir = common::cli::scratch("circular-identify");
    let machine = common::cli::write(&dir, "ballbar_xyz.yaml", BALLBAR_XYZ);
    let machine = machine.to_str().unwrap();
    let runs = common::cli::write(&dir, "runs.csv", &ballbar_runs(false));
    let posed = common::cli::write(&dir, "posed.csv", &ballbar_runs(true));
    // The runs placed by their centre, by the file's pose columns, and the
    // exact kinematics fitted from there (`--iterate`: the circle's length
    // column is the record's own direction there too).
    let identify = |args: &[&str]| {
        let head = ["identify", machine, "--circular"];
        let tail = ["--fix", "EZZ_1", "--format", "json"];
        ok_json(&[&head[..], args, &tail[..]].concat())
    };
    let (runs, posed) = (runs.to_str().unwrap(), posed.to_str().unwrap());
    let by_centre = identify(&[runs, "--centre", "x=200,y=150,z=100"]);
    let by_axes = identify(&[posed, "--axes"]);
    let iterated = identify(&[runs, "--centre", "x=200,y=150,z=100", "--iterate"]);
    assert_eq!(iterated["iteration"]["converged"], true, "{iterated}");
    for doc in [&by_centre, &by_axes, &iterated] {
        let estimate = |name: &str| -> f64 {
            let e = if doc["iteration"].is_object() {
                &doc["iteration"]["estimates"]
            } else {
                &doc["subset"]["estimates"]
            };
            let v = e.get(name).map(|v| &v["value"]).unwrap_or(&Value::Null);
            v.as_f64()
                .or_else(|| doc["estimates"][name]["value"].as_f64())
                .unwrap_or_else(|| panic!("{name}: {doc}"))
        };
        // First order in the errors (products of 1e-5 over 100 mm: 1e-8 mm).
        for (name, truth) in [("EXX_1", SCALE[0]), ("EYY_1", SCALE[1])]
            .into_iter()
            .chain(SQUARE)
        {
            let got = estimate(name);
            assert!((got - truth).abs() < 1e-8, "{name}: {got} against {truth}");
        }
        let setups = doc["setups"].as_array().unwrap();
        assert_eq!(setups.len(), 3);
        for (plane, truth) in SETUP {
            let s = setups.iter().find(|s| s["name"] == plane).unwrap();
            assert_eq!(s["kind"], "circle");
            assert_eq!(s["unknowns"][2], format!("circle {plane}.length"));
            // 1 nm: the linearisation about the nominal ball-to-ball
            // direction leaves terms of the offsets times the errors.
            for k in 0..3 {
                let got = num(&s["position"][k]);
                assert!(
                    (got - truth[k]).abs() < 1e-6,
                    "{plane} {k}: {got} against {}",
                    truth[k]
                );
            }
        }
    }
}

/// Every refusal of `--circular` and its options, named.
#[test]
fn identify_circular_refusals_are_named() {
    let dir = common::cli::scratch("circular-identify-refusals");
    let machine = common::cli::write(&dir, "ballbar_xyz.yaml", BALLBAR_XYZ);
    let machine = machine.to_str().unwrap();
    let runs = common::cli::write(&dir, "runs.csv", &ballbar_runs(false));
    let runs = runs.to_str().unwrap();
    let check_on = |machine: &str, args: &[&str], words: &[&str]| {
        let mut all = vec!["identify", machine];
        all.extend_from_slice(args);
        let err = unwrapped(&fails(&all));
        for w in words {
            assert!(err.contains(w), "{args:?}: `{w}` not in {err}");
        }
    };
    let check = |args: &[&str], words: &[&str]| check_on(machine, args, words);
    check(
        &["--circular", runs],
        &["--circular", "--centre", "--axes", "one of them"],
    );
    check(
        &["--circular", runs, "--centre", "x=1", "--axes"],
        &["--circular", "not both"],
    );
    check(&["--centre", "x=1"], &["give --circular RUNS.csv"]);
    check(
        &["--circular", runs, "--centre", "w=1"],
        &["--centre", "`w`", "not a variable of machine `ballbar_xyz`"],
    );
    check(
        &["--circular", runs, "--centre", "x=1", "--setup", "ball"],
        &["--setup", "already set-ups"],
    );
    check(
        &[
            "--circular",
            runs,
            "--measurements",
            runs,
            "--centre",
            "x=1",
        ],
        &["one of them, not both"],
    );
    // The run file's poses without the columns, and off the circle.
    check(
        &["--circular", runs, "--axes"],
        &["runs.csv:1", "no column for the axis variables `x`, `y`"],
    );
    let wrong = ballbar_runs(true).replace(",100,xy,", ",90,xy,");
    let wrong = common::cli::write(&dir, "wrong.csv", &wrong);
    check(
        &["--circular", wrong.to_str().unwrap(), "--axes"],
        &["wrong.csv:2", "run xy", "not the run's radius 90 mm"],
    );
    check(
        &["--circular", runs, "--centre", "x=1,x=2"],
        &["--centre", "gives `x` twice"],
    );
    check(
        &["--circular", runs, "--centre", "x=NaN"],
        &["--centre", "not a finite number"],
    );
    // Poses on one line, and a circle out of the run's plane.
    let line: String = ballbar_runs(true)
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if i == 0 || !l.starts_with("xy,") {
                return format!("{l}\n");
            }
            let mut cells: Vec<String> = l.split(',').map(str::to_string).collect();
            cells[7] = "150".into(); // y fixed: the poses on a line
            format!("{}\n", cells.join(","))
        })
        .collect();
    let line = common::cli::write(&dir, "line.csv", &line);
    check(
        &["--circular", line.to_str().unwrap(), "--axes"],
        &["line.csv:2", "run xy", "on one line"],
    );
    let tilted = ballbar_runs(true).replace(",xy,", ",yz,").replacen(
        "run,radius,yz,",
        "run,radius,plane,",
        1,
    );
    let tilted = common::cli::write(&dir, "tilted.csv", &tilted);
    check(
        &["--circular", tilted.to_str().unwrap(), "--axes"],
        &["tilted.csv:2", "tilted 90.00° from the run's plane yz"],
    );
    // A machine without a linear variable named after a plane's axis.
    let uvw = common::cli::write(
        &dir,
        "uvw.yaml",
        &BALLBAR_XYZ.replace("variable: x", "variable: u"),
    );
    check_on(
        uvw.to_str().unwrap(),
        &["--circular", runs, "--centre", "u=0"],
        &[
            "runs.csv:2",
            "machine `ballbar_xyz` has no linear variable named `x`",
        ],
    );
    // A run file refused as `chain circular` refuses it.
    let bad = common::cli::write(&dir, "bad.csv", "angle,direction,deviation\n0,up,0\n");
    check(
        &[
            "--circular",
            bad.to_str().unwrap(),
            "--centre",
            "x=0",
            "--radius",
            "100",
        ],
        &["bad.csv:2", "`up` is not a direction"],
    );
}
