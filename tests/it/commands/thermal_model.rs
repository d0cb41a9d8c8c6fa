//! Temperature in the machine model (`docs/thermal.md`, "Temperature in the
//! machine model"): sensors, thermal terms, `--temperature` in `map`,
//! `export`, `reliability` and `identify`, each against the test's own
//! closed form, and every refusal located.

use crate::common;

use common::cli::{fails, ok_json, ok_stdout, scratch, unwrapped, write};
use common::Rng;
use serde_json::Value;

/// One X axis with a scale growth `EXT_1_T_x · x · (T_x − 20)`, and a
/// spindle growing in z with two sensors (`T_sp` referenced at 21 °C).
const MACHINE: &str = "\
machine: scale1
sensors:
  T_x: 20
  T_sp: {reference: 21}
  T_col:
bodies:
  bed: {}
  x_slide:
    parent: bed
    joint: {type: prismatic, axis: +x, variable: x}
    errors:
      dx: [EXX, {name: EXT, powers: [1], per: T_x}]
  spindle:
    parent: x_slide
    offset: [0, 0, 100]
    errors: {dz: {name: EZS, per: [T_sp, T_col]}}
    location_errors: {ex: {name: EAC, per: T_col}}
workpiece: bed
tool: spindle
reliability:
  tolerance: {px: 0.05}
  grid: {x: [0, 250, 500]}
statistics:
  EXX: {dist: normal, mean: 0, std: 0.002}
  EXT_1_T_x: {dist: normal, mean: 11.5e-6, std: 0.5e-6}
  EZS_T_sp: {dist: normal, mean: 0, std: 0.001}
  EZS_T_col: {dist: normal, mean: 0, std: 0.001}
  EAC_T_col: {dist: normal, mean: 0, std: 1e-6}
";

const VALUES: &str = "\
machine: scale1
values:
  EXX: 0.001
  EXT_1_T_x: 11.5e-6
  EZS_T_sp: 0.0031
  EZS_T_col: -0.0008
  EAC_T_col: 2e-6
";

fn files(name: &str) -> (std::path::PathBuf, std::path::PathBuf) {
    let dir = scratch(name);
    (
        write(&dir, "m.yaml", MACHINE),
        write(&dir, "v.yaml", VALUES),
    )
}

fn example(path: &str) -> String {
    common::example_file(path).display().to_string()
}

fn s(p: &std::path::Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn the_map_at_a_thermal_state_is_the_growth_per_kelvin_times_the_deviation() {
    let (m, v) = files("thermal-map");
    let doc = ok_json(&[
        "map",
        s(&m),
        "--values",
        s(&v),
        "--grid",
        "x=0,125,500",
        "--temperature",
        "T_x=28,T_sp=25",
        "--temperature",
        "T_col=17.5",
        "--format",
        "json",
    ]);
    assert_eq!(doc["temperatures"]["T_x"], 28.0);
    assert_eq!(doc["temperatures"]["T_col"], 17.5);
    for p in doc["points"].as_array().unwrap() {
        let x = p["point"]["x"].as_f64().unwrap();
        let e = &p["error"];
        // px = EXX + α·x·ΔT_x, ΔT_x = 28 − 20.
        let px = 0.001 + 11.5e-6 * x * 8.0;
        assert!((e["px"].as_f64().unwrap() - px).abs() < 1e-15, "{x}: {e}");
        // pz = 3.1 µm/K · (25 − 21) − 0.8 µm/K · (17.5 − 20).
        let pz = 0.0031 * 4.0 - 0.0008 * -2.5;
        assert!((e["pz"].as_f64().unwrap() - pz).abs() < 1e-15);
        // ox = 2 µrad/K · (17.5 − 20).
        assert!((e["ox"].as_f64().unwrap() - 2e-6 * -2.5).abs() < 1e-18);
    }
    // At the reference state every thermal term is zero, with or without
    // `--temperature`; a machine with sensors names its state.
    let reference = ok_json(&["map", s(&m), "--values", s(&v), "--format", "json"]);
    assert_eq!(reference["temperatures"]["T_sp"], 21.0);
    for p in reference["points"].as_array().unwrap() {
        assert_eq!(p["error"]["px"], 0.001);
        assert_eq!(p["error"]["pz"], 0.0);
    }
    let table = ok_stdout(&["map", s(&m), "--values", s(&v), "--temperature", "T_x=28"]);
    assert!(
        table.contains("thermal state: T_x = 28 °C, T_sp = 21 °C, T_col = 20 °C"),
        "{table}"
    );
}

#[test]
fn the_thermal_terms_are_derived_as_the_geometry_and_named() {
    let (m, _) = files("thermal-derive");
    let text = ok_stdout(&["derive", s(&m)]);
    assert!(
        text.contains("EXT(x) = EXT_1_T_x*x*(T_x - 20)  (powers [1])"),
        "{text}"
    );
    assert!(text.contains("EZS_T_sp per K of T_sp - 21"), "{text}");
    let json = ok_json(&["derive", s(&m), "--format", "json"]);
    assert_eq!(
        json["errors"],
        serde_json::json!(["EXX", "EXT_1_T_x", "EAC_T_col", "EZS_T_sp", "EZS_T_col"])
    );
    assert_eq!(
        json["thermal"]["EZS_T_sp"],
        serde_json::json!({"sensor": "T_sp", "reference": 21.0})
    );
    assert!(json["thermal"].get("EXX").is_none());
    // The coefficients are the geometry's (the factor acts on the value).
    assert_eq!(json["components"]["px"]["EXT_1_T_x"], "x");
    assert_eq!(json["components"]["pz"]["EZS_T_col"], "1");
}

/// `Φ` by the error function's series in `common`.
fn phi(x: f64) -> f64 {
    common::normal_cdf(x)
}

#[test]
fn reliability_at_a_thermal_state_is_the_closed_form_of_the_scaled_inputs() {
    let (m, _) = files("thermal-reliability");
    for (t, dt) in [("28", 8.0), ("14", -6.0)] {
        let doc = ok_json(&[
            "reliability",
            s(&m),
            "--temperature",
            &format!("T_x={t}"),
            "--format",
            "json",
        ]);
        let cases = doc["results"].as_array().unwrap();
        assert_eq!(cases.len(), 3);
        for c in cases {
            let x = c["point"]["x"].as_f64().unwrap();
            // px = EXX + x·ΔT·EXT_1_T_x: normal, mean x·ΔT·11.5e-6, std
            // √(0.002² + (x·ΔT·0.5e-6)²); upper-sided: β = (0.05 − mean)/std
            // and R = Φ(β).
            let mean = x * dt * 11.5e-6;
            let std = (0.002f64.powi(2) + (x * dt * 0.5e-6).powi(2)).sqrt();
            let beta = (0.05 - mean) / std;
            let got = c["beta"].as_f64().unwrap();
            assert!(
                (got - beta).abs() < 1e-9 * beta,
                "T_x = {t}, x = {x}: {got} vs {beta}"
            );
            let r = c["reliability"].as_f64().unwrap();
            assert!((r - phi(beta)).abs() < 1e-7, "{r} vs {}", phi(beta));
        }
    }
}

#[test]
fn identification_at_several_thermal_states_recovers_the_growth_per_kelvin() {
    let dir = scratch("thermal-identify");
    let m = write(&dir, "m.yaml", MACHINE);
    // A laser along x and a probe along z at three X-scale temperatures and
    // two spindle temperatures; 0.5 µm noise.
    let mut rng = Rng::new(7);
    let mut csv = String::from("x,T_x,T_sp,ux,uy,uz,d,std\n");
    let noise = |rng: &mut Rng| {
        let (u, v) = (rng.unit().max(1e-300), rng.unit());
        5e-4 * (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    };
    for t in [20.0, 24.0, 28.0] {
        for k in 0..=10 {
            let x = 50.0 * k as f64;
            for t_sp in [21.0, 26.0] {
                let d = 0.001 + 11.5e-6 * x * (t - 20.0) + noise(&mut rng);
                csv.push_str(&format!("{x},{t},{t_sp},1,0,0,{d},0.0005\n"));
                let dz = 0.0031 * (t_sp - 21.0) + noise(&mut rng);
                csv.push_str(&format!("{x},{t},{t_sp},0,0,1,{dz},0.0005\n"));
            }
        }
    }
    let meas = write(&dir, "meas.csv", &csv);
    let out = dir.join("identified.yaml");
    let doc = ok_json(&[
        "identify",
        s(&m),
        "--measurements",
        s(&meas),
        "--format",
        "json",
        "--values-out",
        s(&out),
    ]);
    let est = &doc["estimates"];
    for (name, truth) in [("EXT_1_T_x", 11.5e-6), ("EZS_T_sp", 0.0031), ("EXX", 0.001)] {
        let (v, sd) = (
            est[name]["value"].as_f64().unwrap(),
            est[name]["std"].as_f64().unwrap(),
        );
        assert!(
            (v - truth).abs() < 3.0 * sd,
            "{name}: {v} ± {sd} vs {truth}"
        );
    }
    // The values written map at a thermal state: the identified growth.
    let map = ok_json(&[
        "map",
        s(&m),
        "--values",
        s(&out),
        "--grid",
        "x=500",
        "--temperature",
        "T_x=30",
        "--format",
        "json",
    ]);
    let px = map["points"][0]["error"]["px"].as_f64().unwrap();
    let expected = est["EXX"]["value"].as_f64().unwrap()
        + est["EXT_1_T_x"]["value"].as_f64().unwrap() * 500.0 * 10.0;
    assert!((px - expected).abs() < 1e-12, "{px} vs {expected}");
    // Without a column, `--temperature` is every record's state: the
    // spindle's sensor held at 26 °C makes the z rows all ΔT = 5.
    let fixed: String = csv
        .lines()
        .map(|l| {
            let c: Vec<&str> = l.split(',').collect();
            format!("{},{},{}\n", c[0], c[1], c[3..].join(","))
        })
        .collect();
    let fixed = write(&dir, "fixed.csv", &fixed);
    let doc = ok_json(&[
        "identify",
        s(&m),
        "--measurements",
        s(&fixed),
        "--temperature",
        "T_sp=26",
        "--format",
        "json",
    ]);
    // The z rows' mean is 3.1·2.5 µm over ΔT = 5: 1.55 µm/K.
    let v = doc["estimates"]["EZS_T_sp"]["value"].as_f64().unwrap();
    assert!((v - 0.00155).abs() < 2e-4, "{v}");
}

#[test]
fn thermal_refusals_are_located() {
    let dir = scratch("thermal-refusals");
    let bad = write(&dir, "bad.yaml", &MACHINE.replace("per: T_x}", "per: T_y}"));
    let e = unwrapped(&fails(&["derive", s(&bad)]));
    assert!(e.contains("bad.yaml:12:47: `T_y` is not a declared sensor at key `bodies.x_slide.errors.dx[1].per` (did you mean `T_x`?)"), "{e}");
    let twice = write(
        &dir,
        "twice.yaml",
        &MACHINE.replace("[T_sp, T_col]", "[T_sp, T_sp]"),
    );
    let e = unwrapped(&fails(&["derive", s(&twice)]));
    assert!(
        e.contains("sensor `T_sp` is named twice in this `per`"),
        "{e}"
    );
    let clash = write(
        &dir,
        "clash.yaml",
        "machine: a\nparameters: {L: 1}\nsensors: [L, x]\nbodies:\n  bed: {}\n  s: {parent: bed, joint: {type: prismatic, axis: +x, variable: x}, squareness: {ez: {name: S, per: x}}}\nworkpiece: bed\ntool: s\n",
    );
    let e = unwrapped(&fails(&["derive", s(&clash)]));
    assert!(
        e.contains("clash.yaml:3:11: sensor `L` has the same name as a parameter"),
        "{e}"
    );
    assert!(
        e.contains("clash.yaml:3:14: sensor `x` has the same name as a axis variable"),
        "{e}"
    );
    assert!(
        e.contains("`squareness` takes error names only, not a thermal term"),
        "{e}"
    );
    let (m, v) = files("thermal-refusals-options");
    let e = unwrapped(&fails(&[
        "map",
        s(&m),
        "--values",
        s(&v),
        "--temperature",
        "T_q=28",
    ]));
    assert!(e.contains("--temperature: `T_q` is not a sensor of machine `scale1` (did you mean `T_x`?) (its sensors: T_x, T_sp, T_col)"), "{e}");
    let e = unwrapped(&fails(&["reliability", s(&m), "--temperature", "T_x=-300"]));
    assert!(
        e.contains("--temperature: `T_x` = -300 °C is not a temperature"),
        "{e}"
    );
    let e = unwrapped(&fails(&[
        "map",
        s(&m),
        "--values",
        s(&v),
        "--temperature",
        "T_x=20,T_x=21",
    ]));
    assert!(e.contains("`T_x` is given twice (20 and 21 °C)"), "{e}");
    let plain = example("machines/vmc3.yaml");
    let e = unwrapped(&fails(&[
        "map",
        &plain,
        "--values",
        &example("values/vmc3.yaml"),
        "--temperature",
        "T=21",
    ]));
    assert!(e.contains("machine `vmc3` declares no sensors"), "{e}");
    let table = write(
        &dir,
        "table.yaml",
        "machine: scale1\nvalues:\n  EXT: {points: [[0, 0], [500, 1]]}\n",
    );
    let e = unwrapped(&fails(&["map", s(&m), "--values", s(&table)]));
    assert!(
        e.contains("table.yaml:3:3: `EXT` cannot take a table: it is thermal (per kelvin of T_x)"),
        "{e}"
    );
    let e = unwrapped(&fails(&[
        "sensitivity",
        s(&m),
        "--kind",
        "geometric",
        "--temperature",
        "T_x=25",
    ]));
    assert!(
        e.contains("--kind geometric does not take --temperature"),
        "{e}"
    );
    let meas = write(&dir, "cold.csv", "x,T_x,ux,uy,uz,d\n0,-280,1,0,0,0.001\n");
    let e = unwrapped(&fails(&["identify", s(&m), "--measurements", s(&meas)]));
    assert!(
        e.contains("cold.csv:2:3: -280 °C is below absolute zero"),
        "{e}"
    );
}

#[test]
fn a_machine_without_sensors_reads_and_maps_as_before() {
    // The example's map is the golden one; its JSON has no thermal state.
    let doc: Value = ok_json(&[
        "map",
        &example("machines/vmc3.yaml"),
        "--values",
        &example("values/vmc3.yaml"),
        "--grid",
        "x=0,800",
        "--grid",
        "y=0",
        "--grid",
        "z=0",
        "--format",
        "json",
    ]);
    assert!(doc.get("temperatures").is_none());
}

/// A spindle on one Z axis, its growth `EZS` per kelvin of three sensors
/// and a tilt `EAS` per kelvin of one.
const SPINDLE: &str = "\
machine: spindle1
sensors: [T_a, T_b, T_c]
bodies:
  bed: {}
  z_head:
    parent: bed
    joint: {type: prismatic, axis: +z, variable: z}
  spindle:
    parent: z_head
    errors: {dz: {name: EZS, per: [T_a, T_b, T_c]}}
    location_errors: {ex: {name: EAS, per: T_a}}
workpiece: bed
tool: spindle
";

/// A drift test (2 h every 60 s, T_a and T_b rising at different rates, T_c
/// cycling, the spindle started at 30 min) whose Z channel is
/// `3·ΔT_a + 1.2·ΔT_b` µm exactly, X `0.5·ΔT_c` mm, and R the spindle
/// rotor's growth, a 10 min lag of its speed (2e-4 µm/rpm).
fn drift_csv() -> String {
    let mut csv = String::from("time(s),Z(um),X(mm),R(um),T_a(°C),T_b(°C),T_c(°C),spindle(rpm)\n");
    let mut lag = 0.0;
    let mut speed = 0.0;
    for k in 0..=120 {
        let t = 60.0 * k as f64;
        if k > 0 {
            lag += (speed - lag) * (1.0 - (-60.0f64 / 600.0).exp());
        }
        speed = if t >= 1800.0 { 8000.0 } else { 0.0 };
        let h = t / 3600.0;
        let (a, b) = (20.0 + 4.0 * (1.0 - (-h).exp()), 21.0 + 0.8 * h * h);
        let c = 19.5 + 0.5 * (std::f64::consts::TAU * h).sin();
        let z = 3.0 * (a - 20.0) + 1.2 * (b - 21.0);
        let x = 0.5 * (c - 19.5);
        csv.push_str(&format!("{t},{z},{x},{},{a},{b},{c},{speed}\n", 2e-4 * lag));
    }
    csv
}

#[test]
fn a_fitted_drift_model_is_written_as_the_machine_s_thermal_coefficients() {
    let dir = scratch("thermal-values-out");
    let m = write(&dir, "spindle.yaml", SPINDLE);
    let run = write(&dir, "drift.csv", &drift_csv());
    let out = dir.join("spindle_values.yaml");
    let doc = ok_json(&[
        "thermal",
        s(&run),
        "--fit",
        "--sensors",
        "2",
        "--values-out",
        s(&out),
        "--machine",
        s(&m),
        "--slot",
        "EZS=Z(um)",
        "--format",
        "json",
    ]);
    let written = &doc["values"]["terms"][0];
    assert_eq!(written["slot"], "EZS");
    let coefficient = |sensor: &str| {
        (written["coefficients"].as_array().unwrap().iter())
            .find(|c| c["sensor"] == sensor)
            .unwrap()
            .clone()
    };
    // The fit recovers the exact linear drift; the unchosen sensor is 0.
    assert!((coefficient("T_a")["value"].as_f64().unwrap() - 3.0).abs() < 1e-9);
    assert!((coefficient("T_b")["value"].as_f64().unwrap() - 1.2).abs() < 1e-9);
    assert_eq!(coefficient("T_c")["value"], 0.0);
    assert_eq!(coefficient("T_a")["column"], "T_a(°C)");
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(
        text.contains("EZS_T_c: 0  # µm/K: T_c is not in the fitted model"),
        "{text}"
    );
    // `chain map` reads them at a thermal state: pz = Σ a_s ΔT_s.
    let map = ok_json(&[
        "map",
        s(&m),
        "--values",
        s(&out),
        "--grid",
        "z=0",
        "--temperature",
        "T_a=25,T_b=22,T_c=30",
        "--format",
        "json",
    ]);
    let pz = map["points"][0]["error"]["pz"].as_f64().unwrap();
    assert!((pz - (3.0 * 5.0 + 1.2 * 2.0) * 1e-3).abs() < 1e-11, "{pz}");
    // A channel in mm is written in µm/K: X = 0.5 mm/K of T_c.
    let doc = ok_json(&[
        "thermal",
        s(&run),
        "--fit",
        "--sensors",
        "1",
        "--values-out",
        s(&out),
        "--machine",
        s(&m),
        "--slot",
        "EZS=X(mm)",
        "--format",
        "json",
    ]);
    let x = &doc["values"]["terms"][0]["coefficients"][2];
    assert_eq!(x["sensor"], "T_c");
    assert!((x["value"].as_f64().unwrap() - 500.0).abs() < 1e-6, "{x}");
}

#[test]
fn a_drift_model_that_does_not_fit_the_machine_is_refused() {
    let dir = scratch("thermal-values-refusals");
    let m = write(&dir, "spindle.yaml", SPINDLE);
    let run = write(&dir, "drift.csv", &drift_csv());
    let out = dir.join("v.yaml");
    // `chain thermal RUN --values-out OUT` with `args` (the fit, the
    // machine, the slot), refused.
    let refused = |args: &[&str]| -> String {
        let mut all = vec!["thermal", s(&run), "--values-out", s(&out)];
        all.extend_from_slice(args);
        unwrapped(&fails(&all))
    };
    let base = |slot: &str, extra: &[&str]| -> String {
        let mut args = vec!["--fit", "--machine", s(&m), "--slot", slot];
        args.extend_from_slice(extra);
        refused(&args)
    };
    let e = base("EZX=Z(um)", &[]);
    assert!(e.contains("--slot: `EZX` is not a thermal term `{name, per}` of machine `spindle1` (did you mean `EZS`?) (its thermal terms: EAS, EZS)"), "{e}");
    let e = base("EAS=Z(um)", &[]);
    assert!(
        e.contains("--slot: `EAS` is an angular thermal term"),
        "{e}"
    );
    let e = base("EZS=Z(mm)", &[]);
    assert!(
        e.contains("`Z(mm)` is not a displacement channel of"),
        "{e}"
    );
    assert!(
        e.contains("(did you mean `Z(um)`?) (its channels: Z(um), X(mm), R(um))"),
        "{e}"
    );
    let e = base("EZS=R(um)", &["--lag"]);
    assert!(
        e.contains(
            "--slot: the model of `R(um)` has a lag term (a response to `spindle(rpm)` in time)"
        ),
        "{e}"
    );
    let other = write(
        &dir,
        "other.yaml",
        &SPINDLE.replace("per: [T_a, T_b, T_c]", "per: [T_b, T_c]"),
    );
    let e = refused(&[
        "--fit",
        "--sensors",
        "2",
        "--machine",
        s(&other),
        "--slot",
        "EZS=Z(um)",
    ]);
    assert!(e.contains("the model of `Z(um)` uses `T_a(°C)`, sensor `T_a`, which `EZS` is not per (its sensors: T_b, T_c)"), "{e}");
    let e = refused(&["--machine", s(&m), "--slot", "EZS=Z(um)"]);
    assert!(
        e.contains("--values-out writes the fitted models: give --fit"),
        "{e}"
    );
    let without = SPINDLE
        .replace("[T_a, T_b, T_c]", "[T_b, T_c]")
        .replace("per: T_a", "per: T_b");
    let without = write(&dir, "without.yaml", &without);
    let e = refused(&[
        "--fit",
        "--sensors",
        "2",
        "--machine",
        s(&without),
        "--slot",
        "EZS=Z(um)",
    ]);
    assert!(
        e.contains("uses `T_a(°C)`, which names no sensor of the machine (a column's header without its unit is the sensor's name; its sensors: T_b, T_c)"),
        "{e}"
    );
    let e = base("EZS", &[]);
    assert!(e.contains("--slot EZS: expected NAME=CHANNEL"), "{e}");
}

#[test]
fn the_thermal_example_values_are_current() {
    // examples/thermal/README.md's command; the header comment names the
    // drift file as given, so the values from `machine:` on are compared.
    let dir = scratch("thermal-example");
    let out = dir.join("spindle_values.yaml");
    ok_json(&[
        "thermal",
        &example("thermal/spindle_drift.csv"),
        "--fit",
        "--holdout",
        "0.25",
        "--values-out",
        s(&out),
        "--machine",
        &example("thermal/vmc3_thermal.yaml"),
        "--slot",
        "EZS=Z(um)",
        "--format",
        "json",
    ]);
    let body = |t: &str| t[t.find("machine:").unwrap()..].to_string();
    let written = std::fs::read_to_string(&out).unwrap();
    let example_file = common::example_file("thermal/spindle_values.yaml");
    if std::env::var_os("CHAIN_REGENERATE").is_some() {
        let old = std::fs::read_to_string(&example_file).unwrap();
        let head = &old[..old.find("machine:").unwrap()];
        std::fs::write(&example_file, format!("{head}{}", body(&written))).unwrap();
    }
    let example_text = std::fs::read_to_string(&example_file).unwrap();
    assert_eq!(
        body(&written),
        body(&example_text),
        "rerun with CHAIN_REGENERATE=1"
    );
}

/// One X axis whose scale grows with a random room temperature
/// (`tests/data/thermal_room.yaml`, which the Python tests read too).
fn room() -> String {
    std::fs::read_to_string(common::root().join("tests/data/thermal_room.yaml")).unwrap()
}

/// `p_f(x) = ∫ Φ(−(0.05 − μ(T))/σ(T)) dT/12` over `T ∈ [16, 28]`:
/// conditional on T, px is normal with mean `x·ΔT·11.5e-6` and std
/// `√(0.002² + (x·ΔT·0.5e-6)²)`; composite Simpson on 200,000 intervals.
fn room_pf(x: f64) -> f64 {
    let n = 200_000;
    let h = 12.0 / n as f64;
    let f = |t: f64| {
        let dt = t - 20.0;
        let (mean, std) = (
            x * dt * 11.5e-6,
            (0.002f64.powi(2) + (x * dt * 0.5e-6).powi(2)).sqrt(),
        );
        common::normal_cdf(-(0.05 - mean) / std) / 12.0
    };
    let mut sum = f(16.0) + f(28.0);
    for k in 1..n {
        sum += f(16.0 + k as f64 * h) * if k % 2 == 1 { 4.0 } else { 2.0 };
    }
    sum * h / 3.0
}

#[test]
fn reliability_over_a_random_room_temperature_is_the_integral_of_the_conditional_one() {
    let dir = scratch("thermal-room");
    let m = write(&dir, "room.yaml", &room());
    let doc = ok_json(&["reliability", s(&m), "--format", "json"]);
    assert_eq!(doc["temperatures"]["random"][0]["sensor"], "T_x");
    assert_eq!(doc["temperatures"]["random"][0]["dist"], "uniform");
    assert_eq!(doc["temperatures"]["quadrature"]["converged"], true);
    for c in doc["results"].as_array().unwrap() {
        let x = c["point"]["x"].as_f64().unwrap();
        let (got, want) = (c["pf"].as_f64().unwrap(), room_pf(x));
        assert!(
            (got - want).abs() <= 1e-6 * want,
            "x = {x}: {got} vs {want}"
        );
        let beta = c["beta"].as_f64().unwrap();
        assert!((common::normal_cdf(-beta) / got - 1.0).abs() < 1e-9);
    }
    // Monte Carlo at each temperature: the same integral within its
    // standard error (a bound: the temperatures' runs share the streams).
    let mc = ok_json(&[
        "reliability",
        s(&m),
        "--method",
        "mc",
        "--samples",
        "20000",
        "--grid",
        "x=500",
        "--format",
        "json",
    ]);
    let c = &mc["results"][0];
    let (pf, se) = (c["pf"].as_f64().unwrap(), c["std_error"].as_f64().unwrap());
    assert!(
        (pf - room_pf(500.0)).abs() < 4.0 * se,
        "{pf} ± {se} vs {}",
        room_pf(500.0)
    );
    // `--temperature` fixes it: the study at that state.
    let fixed = ok_json(&[
        "reliability",
        s(&m),
        "--temperature",
        "T_x=28",
        "--format",
        "json",
    ]);
    assert_eq!(fixed["temperatures"]["fixed"]["T_x"], 28.0);
    assert!(fixed["temperatures"].get("random").is_none());
    // What is not integrated is refused.
    let e = unwrapped(&fails(&["reliability", s(&m), "--acceptance"]));
    assert!(e.contains("the acceptance probability is not integrated over the random temperature of T_x: fix it with --temperature"), "{e}");
    let two = room()
        .replace("sensors: {T_x: 20}", "sensors: {T_x: 20, T_y: 20}")
        .replace(
            "  T_x: {dist",
            "  T_y: {dist: normal, mean: 20, std: 1}\n  T_x: {dist",
        );
    let two = write(&dir, "two.yaml", &two);
    let e = unwrapped(&fails(&["reliability", s(&two)]));
    assert!(
        e.contains("2 sensors have a distribution (T_y, T_x); one is integrated over"),
        "{e}"
    );
    let bad = write(
        &dir,
        "bad.yaml",
        &room().replace("min: 16, max: 28}", "min: 16, max: 28, cost_weight: 2}"),
    );
    let e = unwrapped(&fails(&["derive", s(&bad)]));
    assert!(
        e.contains("`cost_weight` is an allocation key of an error; `T_x` is a sensor"),
        "{e}"
    );
}

#[test]
fn a_path_at_a_thermal_state_is_the_grid_study_there() {
    let (m, _) = files("thermal-path");
    let dir = scratch("thermal-path-axes");
    let axes = write(&dir, "axes.csv", "x\n0\n250\n500\n");
    let path = ok_json(&[
        "path",
        s(&m),
        "--axes",
        s(&axes),
        "--temperature",
        "T_x=28",
        "--format",
        "json",
    ]);
    let grid = ok_json(&[
        "reliability",
        s(&m),
        "--temperature",
        "T_x=28",
        "--format",
        "json",
    ]);
    let instants = path["instants"].as_array().unwrap();
    for (i, c) in grid["results"].as_array().unwrap().iter().enumerate() {
        let r = instants[i]["reliability"]["px"].as_f64().unwrap();
        assert!(
            (r - c["reliability"].as_f64().unwrap()).abs() < 1e-15,
            "{i}: {r} vs {c}"
        );
    }
}

/// `c*(V1-20)+c*(V2-20)…` (a written formula) with each variable's value
/// from `var`.
fn formula_with(text: &str, var: &dyn Fn(&str) -> f64) -> f64 {
    if text == "0" {
        return 0.0;
    }
    text.split('+')
        .map(|term| {
            let (c, rest) = term.split_once("*(").unwrap();
            let (v, reference) = rest.trim_end_matches(')').split_once('-').unwrap();
            c.parse::<f64>().unwrap() * (var(v) - reference.parse::<f64>().unwrap())
        })
        .sum()
}

/// A Siemens formula at temperatures `t` (°C by R parameter, 1-based).
fn formula(text: &str, t: &[f64]) -> f64 {
    formula_with(text, &|v: &str| {
        t[v.trim_start_matches('R').parse::<usize>().unwrap() - 1]
    })
}

/// The thermal part of vmc3_thermal's error at `state` (`T=V,...`) over
/// `grid` (`--grid` arguments): per point, its axis values by name and
/// `E(q, T) − E(q, T_ref)` (mm), from `chain map --temperature`.
fn thermal_part(state: &str, grid: &[&str]) -> Vec<(Value, [f64; 3])> {
    let file = example("thermal/vmc3_thermal.yaml");
    let values = example("thermal/vmc3_thermal_values.yaml");
    let map = |temps: Option<&str>| {
        let mut args = vec!["map", &file, "--values", &values, "--format", "json"];
        if let Some(t) = temps {
            args.extend_from_slice(&["--temperature", t]);
        }
        args.extend_from_slice(grid);
        ok_json(&args)
    };
    let (hot, cold) = (map(Some(state)), map(None));
    let points = |d: &Value| d["points"].as_array().unwrap().clone();
    points(&hot)
        .into_iter()
        .zip(points(&cold))
        .map(|(h, c)| {
            let e = |k: &str| h["error"][k].as_f64().unwrap() - c["error"][k].as_f64().unwrap();
            (h["point"].clone(), [e("px"), e("py"), e("pz")])
        })
        .collect()
}

#[test]
fn the_siemens_temperature_compensation_applied_as_the_controller_applies_it_leaves_the_stated_remainder(
) {
    use chain_core::compensation::thermal::{fit, ThermalFormat};
    let file = common::example_file("thermal/vmc3_thermal.yaml");
    let values_file = common::example_file("thermal/vmc3_thermal_values.yaml");
    let machine = chain_core::load_file(&file).unwrap();
    let model = chain_core::compile(&machine);
    let values = chain_core::values::Values::read(&values_file, &machine).unwrap();
    let grid = [
        ("x", [0.0, 200.0, 400.0, 600.0, 800.0]),
        ("y", [0.0, 125.0, 250.0, 375.0, 500.0]),
        ("z", [0.0, 125.0, 250.0, 375.0, 500.0]),
    ];
    let mut points = Vec::new();
    for &y in &grid[1].1 {
        for &x in &grid[0].1 {
            for &z in &grid[2].1 {
                points.push(vec![y, x, z]);
            }
        }
    }
    assert_eq!(
        machine
            .variables
            .iter()
            .map(|v| v.name.as_str())
            .collect::<Vec<_>>(),
        ["y", "x", "z"]
    );
    let law = fit(&machine, &model, &[150.0], &values, &points).unwrap();
    let spf = &law.files(ThermalFormat::Siemens, "test")[0].text;
    let sensors: Vec<String> = law.axes[0].lines.iter().map(|l| l.sensor.clone()).collect();
    // Per axis its K0, tanβ and P0 as the SPF writes them.
    let setting = |name: &str, axis: char| -> String {
        let key = format!("$SA_TEMP_COMP_{name}[{axis}1]=");
        spf.lines()
            .find_map(|l| l.strip_prefix(&key))
            .unwrap()
            .to_string()
    };
    let grid_args = [
        "--grid",
        "x=0,200,400,600,800",
        "--grid",
        "y=0,125,250,375,500",
        "--grid",
        "z=0,125,250,375,500",
    ];
    for (i, r) in law.remainder.iter().enumerate() {
        // Sensor i alone 5 K above its reference.
        let mut t: Vec<f64> = law.axes[0].lines.iter().map(|l| l.reference).collect();
        t[i] += 5.0;
        let state: Vec<String> = sensors
            .iter()
            .zip(&t)
            .map(|(n, v)| format!("{n}={v}"))
            .collect();
        let joined = state.join(",");
        let mut largest = 0.0f64;
        for (point, part) in thermal_part(&joined, &grid_args) {
            // The thermal part of the error, and the controller's
            // ΔK = K0 + tanβ·(P − P0) added to each axis's command: the
            // tool moves by ΔK along the axis (vmc3's nominal tool point
            // relative to the table is (x, y, z + …), its machine file).
            let mut left = part;
            for (axis, var, sign, k) in [('X', "x", 1.0, 0), ('Y', "y", 1.0, 1), ('Z', "z", 1.0, 2)]
            {
                let p = point[var].as_f64().unwrap();
                let k0 = formula(&setting("ABS_VALUE", axis), &t);
                let slope = formula(&setting("SLOPE", axis), &t);
                let p0: f64 = setting("REF_POSITION", axis).parse().unwrap();
                left[k] += sign * (k0 + slope * (p - p0));
            }
            largest = largest.max(left.iter().map(|v| v * v).sum::<f64>().sqrt());
        }
        assert!(
            (largest - 5.0 * r.after).abs() < 1e-9 * r.before.max(1e-12) + 1e-12,
            "{}: {largest} vs {}",
            r.sensor,
            5.0 * r.after
        );
        assert!(r.after <= r.before);
    }
    // The X scale's growth is a slope of X alone: held exactly; the
    // column's tilt (z-dependent along Y) is not a line of Y.
    let x = law.axes.iter().find(|a| a.axis == 'X').unwrap();
    let tx = x.lines.iter().find(|l| l.sensor == "T_x").unwrap();
    assert!((tx.slope - 11.5e-6).abs() < 1e-15, "{}", tx.slope);
    let rx = law.remainder.iter().find(|r| r.sensor == "T_x").unwrap();
    assert!(rx.after < 1e-12, "{rx:?}");
    let rc = law
        .remainder
        .iter()
        .find(|r| r.sensor == "T_coltop")
        .unwrap();
    assert!(rc.after > 1e-6, "{rc:?}");
}

#[test]
fn the_linuxcnc_thermal_component_applied_as_hal_applies_it_leaves_the_stated_remainder() {
    use chain_core::compensation::thermal::{fit, ThermalFormat};
    let file = common::example_file("thermal/vmc3_thermal.yaml");
    let values_file = common::example_file("thermal/vmc3_thermal_values.yaml");
    let machine = chain_core::load_file(&file).unwrap();
    let model = chain_core::compile(&machine);
    let values = chain_core::values::Values::read(&values_file, &machine).unwrap();
    let mut points = Vec::new();
    for y in [0.0, 250.0, 500.0] {
        for x in [0.0, 400.0, 800.0] {
            for z in [0.0, 250.0, 500.0] {
                points.push(vec![y, x, z]);
            }
        }
    }
    let law = fit(&machine, &model, &[150.0], &values, &points).unwrap();
    let files = law.files(ThermalFormat::Linuxcnc, "test");
    let text = |name: &str| files.iter().find(|f| f.name == name).unwrap().text.clone();
    let (comp, hal, ini) = (
        text("thermal_comp.comp"),
        text("thermal_comp.hal"),
        text("thermal_comp.ini"),
    );
    // The HAL wiring of the external offsets (docs/src/motion/external-offsets.adoc).
    for a in ["x", "y", "z"] {
        assert!(
            hal.contains(&format!(
                "net tc-counts-{a} thermal-comp.counts-{a} => axis.{a}.eoffset-counts"
            )),
            "{hal}"
        );
        assert!(hal.contains(&format!(
            "net tc-pos-{a} axis.{a}.pos-cmd => thermal-comp.pos-{a}"
        )));
        assert!(hal.contains(&format!("setp axis.{a}.eoffset-scale 0.00001")));
        assert!(ini.contains(&format!(
            "[AXIS_{}]\nOFFSET_AV_RATIO = 0.1",
            a.to_uppercase()
        )));
    }
    assert!(comp.contains("pin in float temp_t_front = 20 "), "{comp}");
    assert!(comp.contains("if (!is_on || !homed) d = 0;"));
    // Each axis's `d = (K0) + (m)*(pos_a - P0);` as the component computes
    // it, its counts rounded at k = 100000 per mm, the offset added to the
    // command (axis.c: the external offset adds to the axis position).
    let t = [
        ("T_x", 27.0),
        ("T_front", 31.0),
        ("T_rear", 26.0),
        ("T_head", 24.0),
        ("T_coltop", 22.5),
    ];
    let temp = |v: &str| -> f64 {
        t.iter()
            .find(|(n, _)| format!("temp_{}", n.to_lowercase()) == v)
            .unwrap()
            .1
    };
    let d_line = |a: char| -> (String, String, f64) {
        let l = comp
            .lines()
            .find(|l| l.trim_start().starts_with("d = (") && l.contains(&format!("pos_{a} - ")))
            .unwrap();
        let l = l.trim().trim_start_matches("d = (").trim_end_matches(");");
        let (k0, rest) = l.split_once(") + (").unwrap();
        let (m, p0) = rest.split_once(&format!(")*(pos_{a} - ")).unwrap();
        (k0.to_string(), m.to_string(), p0.parse().unwrap())
    };
    let state: Vec<String> = t.iter().map(|(n, v)| format!("{n}={v}")).collect();
    let joined = state.join(",");
    let grid = [
        "--grid",
        "x=0,400,800",
        "--grid",
        "y=0,250,500",
        "--grid",
        "z=0,250,500",
    ];
    // What the law leaves at this state, from its per-sensor parts: the
    // remainder is linear in ΔT, so the test's own sum bounds it.
    let bound: f64 = law
        .remainder
        .iter()
        .map(|r| r.after * (t.iter().find(|(n, _)| *n == r.sensor).unwrap().1 - 20.0).abs())
        .sum();
    let mut largest = 0.0f64;
    let mut thermal = 0.0f64;
    for (point, part) in thermal_part(&joined, &grid) {
        let mut left = part;
        thermal = thermal.max(left.iter().map(|v| v * v).sum::<f64>().sqrt());
        for (k, a) in ['x', 'y', 'z'].into_iter().enumerate() {
            let (k0, m, p0) = d_line(a);
            let pos = point[a.to_string()].as_f64().unwrap();
            let d = formula_with(&k0, &temp) + formula_with(&m, &temp) * (pos - p0);
            let counts = if d >= 0.0 {
                (d * 1e5 + 0.5).trunc()
            } else {
                (d * 1e5 - 0.5).trunc()
            };
            left[k] += counts * 1e-5;
        }
        largest = largest.max(left.iter().map(|v| v * v).sum::<f64>().sqrt());
    }
    // The counts' rounding adds at most half a count per axis.
    assert!(
        largest <= bound + 0.5e-5 * 3f64.sqrt() + 1e-12,
        "{largest} vs {bound}"
    );
    assert!(largest < 0.2 * thermal, "{largest} of {thermal}");
}

#[test]
fn the_thermal_formats_are_export_controllers() {
    let file = example("thermal/vmc3_thermal.yaml");
    let values = example("thermal/vmc3_thermal_values.yaml");
    let dir = scratch("thermal-export-cli");
    let grid = [
        "--grid",
        "x=0,400,800",
        "--grid",
        "y=0,250,500",
        "--grid",
        "z=0,250,500",
    ];
    for (controller, names) in [
        ("siemens-thermal", vec!["TEMP_COMP.SPF"]),
        (
            "linuxcnc-thermal",
            vec!["thermal_comp.comp", "thermal_comp.hal", "thermal_comp.ini"],
        ),
    ] {
        let out = dir.join(controller);
        let mut args = vec![
            "export",
            &file,
            "--values",
            &values,
            "--controller",
            controller,
            "--out",
            s(&out),
            "--format",
            "json",
        ];
        args.extend_from_slice(&grid);
        let doc = ok_json(&args);
        assert_eq!(doc["files"], serde_json::json!(names));
        for n in &names {
            let text = std::fs::read_to_string(out.join(n)).unwrap();
            assert!(
                text.contains(&format!("chain export --controller {controller}")),
                "{n}"
            );
        }
        // The document is the library's law over the same grid.
        let x = (doc["axes"].as_array().unwrap().iter())
            .find(|a| a["axis"] == "X")
            .unwrap();
        let tx = (x["lines"].as_array().unwrap().iter())
            .find(|l| l["sensor"] == "T_x")
            .unwrap();
        assert!((tx["slope"].as_f64().unwrap() - 11.5e-6).abs() < 1e-15);
        let mut args = vec![
            "export",
            &file,
            "--values",
            &values,
            "--controller",
            controller,
            "--out",
            s(&out),
        ];
        args.extend_from_slice(&grid);
        let table = ok_stdout(&args);
        assert!(
            table.contains("T_x") && table.contains("11.5000"),
            "{table}"
        );
    }
    let e = unwrapped(&fails(&[
        "export",
        &file,
        "--values",
        &values,
        "--controller",
        "siemens-thermal",
        "--temperature",
        "T_x=25",
        "--out",
        s(&dir),
    ]));
    assert!(
        e.contains("--controller siemens-thermal does not take --temperature"),
        "{e}"
    );
    let e = unwrapped(&fails(&[
        "export",
        &example("machines/vmc3.yaml"),
        "--values",
        &example("values/vmc3.yaml"),
        "--controller",
        "linuxcnc-thermal",
        "--out",
        s(&dir),
    ]));
    assert!(e.contains("machine `vmc3` has no thermal terms"), "{e}");
    let e = unwrapped(&fails(&[
        "map",
        &file,
        "--values",
        &values,
        "--compensated",
        "siemens-thermal",
    ]));
    assert!(
        e.contains("--compensated siemens-thermal does not take a map"),
        "{e}"
    );
}
