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

/// `c*(V1-20)+c*(V2-20)-c*(V3-20)…` (a written formula) with each variable's value
/// from `var`.
fn formula_with(text: &str, var: &dyn Fn(&str) -> f64) -> f64 {
    if text == "0" {
        return 0.0;
    }
    // The terms: split before each sign outside parentheses.
    let mut terms = vec![String::new()];
    let mut depth = 0;
    for c in text.chars() {
        match c {
            '(' => depth += 1,
            ')' => depth -= 1,
            '+' | '-'
                if depth == 0
                    && !terms.last().unwrap().is_empty()
                    && !terms.last().unwrap().ends_with('e') =>
            {
                terms.push(String::new())
            }
            _ => {}
        }
        terms.last_mut().unwrap().push(c);
    }
    (terms.iter())
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

/// The `format` law of vmc3_thermal over the grid `x`, `y`, `z`
/// (`[xs, ys, zs]`), spindle offset 150.
fn vmc3_law(
    format: chain_core::compensation::thermal::ThermalFormat,
    grid: [&[f64]; 3],
) -> chain_core::compensation::thermal::ThermalLaw {
    let file = common::example_file("thermal/vmc3_thermal.yaml");
    let values_file = common::example_file("thermal/vmc3_thermal_values.yaml");
    let machine = chain_core::load_file(&file).unwrap();
    let model = chain_core::compile(&machine);
    let values = chain_core::values::Values::read(&values_file, &machine).unwrap();
    let names: Vec<&str> = machine.variables.iter().map(|v| v.name.as_str()).collect();
    assert_eq!(names, ["y", "x", "z"]);
    let mut points = Vec::new();
    for &y in grid[1] {
        for &x in grid[0] {
            for &z in grid[2] {
                points.push(vec![y, x, z]);
            }
        }
    }
    chain_core::compensation::thermal::fit(&machine, &model, &[150.0], &values, &points, format)
        .unwrap()
}

/// The 3×3×3 grid of the thermal export tests, and its `--grid` arguments.
const COARSE: [&[f64]; 3] = [
    &[0.0, 400.0, 800.0],
    &[0.0, 250.0, 500.0],
    &[0.0, 250.0, 500.0],
];
const COARSE_ARGS: [&str; 6] = [
    "--grid",
    "x=0,400,800",
    "--grid",
    "y=0,250,500",
    "--grid",
    "z=0,250,500",
];

#[test]
fn the_siemens_temperature_compensation_applied_as_the_controller_applies_it_leaves_the_stated_remainder(
) {
    use chain_core::compensation::thermal::ThermalFormat;
    let law = vmc3_law(
        ThermalFormat::Siemens,
        [
            &[0.0, 200.0, 400.0, 600.0, 800.0],
            &[0.0, 125.0, 250.0, 375.0, 500.0],
            &[0.0, 125.0, 250.0, 375.0, 500.0],
        ],
    );
    let spf = &law.files("test")[0].text;
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
    use chain_core::compensation::thermal::ThermalFormat;
    let law = vmc3_law(ThermalFormat::Linuxcnc, COARSE);
    let files = law.files("test");
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
    let temp = |v: &str| -> f64 {
        HOT.iter()
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
    let (largest, thermal, bound) = applied(&law, &|point| {
        std::array::from_fn(|k| {
            let a = ['x', 'y', 'z'][k];
            let (k0, m, p0) = d_line(a);
            let pos = point[a.to_string()].as_f64().unwrap();
            let d = formula_with(&k0, &temp) + formula_with(&m, &temp) * (pos - p0);
            let counts = if d >= 0.0 {
                (d * 1e5 + 0.5).trunc()
            } else {
                (d * 1e5 - 0.5).trunc()
            };
            counts * 1e-5
        })
    });
    // The counts' rounding adds at most half a count per axis.
    assert!(
        largest <= bound + 0.5e-5 * 3f64.sqrt() + 1e-12,
        "{largest} vs {bound}"
    );
    assert!(largest < 0.2 * thermal, "{largest} of {thermal}");
}

#[test]
fn the_spindle_model_s_controller_examples_are_current() {
    // examples/thermal/README.md's commands: the drift test's spindle
    // model as a SINUMERIK and a LinuxCNC temperature compensation, over
    // the machine's grid.
    let dir = scratch("thermal-spindle-examples");
    for (controller, folder, names) in [
        ("siemens-thermal", "spindle_siemens", vec!["TEMP_COMP.SPF"]),
        (
            "linuxcnc-thermal",
            "spindle_linuxcnc",
            vec!["thermal_comp.comp", "thermal_comp.hal", "thermal_comp.ini"],
        ),
    ] {
        let out = dir.join(folder);
        let doc = ok_json(&[
            "export",
            &example("thermal/vmc3_thermal.yaml"),
            "--values",
            &example("thermal/spindle_values.yaml"),
            "--controller",
            controller,
            "--out",
            s(&out),
            "--format",
            "json",
        ]);
        // The spindle's growth along Z is a constant per kelvin of each
        // sensor: the line holds it whole.
        for r in doc["remainder"].as_array().unwrap() {
            assert!(r["after"].as_f64().unwrap() < 1e-12, "{r}");
        }
        for n in names {
            let written = std::fs::read_to_string(out.join(n)).unwrap();
            let example_file = common::example_file(&format!("thermal/{folder}/{n}"));
            if std::env::var_os("CHAIN_REGENERATE").is_some() {
                std::fs::write(&example_file, &written).unwrap();
            }
            let example_text = std::fs::read_to_string(&example_file).unwrap();
            assert_eq!(written, example_text, "{n}: rerun with CHAIN_REGENERATE=1");
        }
    }
}

/// The thermal state of the export tests (°C).
const HOT: [(&str, f64); 5] = [
    ("T_x", 27.0),
    ("T_front", 31.0),
    ("T_rear", 26.0),
    ("T_head", 24.0),
    ("T_coltop", 22.5),
];

/// A controller's correction applied over the coarse grid at [`HOT`]:
/// `correct(point)` is the tool point's move along X, Y, Z the controller
/// makes there. Returns the largest error left, the largest thermal error
/// before, and the bound the law states (the remainder is linear in ΔT:
/// `Σ_s after_s·|ΔT_s|`).
fn applied(
    law: &chain_core::compensation::thermal::ThermalLaw,
    correct: &dyn Fn(&Value) -> [f64; 3],
) -> (f64, f64, f64) {
    let state: Vec<String> = HOT.iter().map(|(n, v)| format!("{n}={v}")).collect();
    let bound: f64 = (law.remainder.iter())
        .map(|r| r.after * (HOT.iter().find(|(n, _)| *n == r.sensor).unwrap().1 - 20.0).abs())
        .sum();
    let norm = |v: &[f64; 3]| v.iter().map(|v| v * v).sum::<f64>().sqrt();
    let (mut largest, mut thermal) = (0.0f64, 0.0f64);
    for (point, part) in thermal_part(&state.join(","), &COARSE_ARGS) {
        let mut left = part;
        thermal = thermal.max(norm(&left));
        for (l, d) in left.iter_mut().zip(correct(&point)) {
            *l += d;
        }
        largest = largest.max(norm(&left));
    }
    (largest, thermal, bound)
}

/// A Structured Text sum of `c*(NAME - R)` terms (` + `, ` - ` between
/// them), each name's value from `var`.
fn st_sum(text: &str, var: &dyn Fn(&str) -> f64) -> f64 {
    if text == "0.0" {
        return 0.0;
    }
    (text
        .replace(") + ", ")|+")
        .replace(") - ", ")|-")
        .split('|'))
    .map(|term| {
        let (c, rest) = term.split_once("*(").unwrap();
        let (v, r) = rest.trim_end_matches(')').split_once(" - ").unwrap();
        c.parse::<f64>().unwrap() * (var(v) - r.parse::<f64>().unwrap())
    })
    .sum()
}

#[test]
fn the_beckhoff_temperature_compensation_applied_as_the_cnc_applies_it_leaves_the_stated_remainder()
{
    use chain_core::compensation::thermal::ThermalFormat;
    let law = vmc3_law(ThermalFormat::Beckhoff, COARSE);
    let files = law.files("test");
    let text = |name: &str| files.iter().find(|f| f.name == name).unwrap().text.clone();
    let (lis, st) = (text("temp_comp_axes.lis"), text("FB_TempComp.st"));
    // Per axis its block of the axis list (P-AXIS-00271..00274).
    let block = |a: char| {
        lis.split(&format!("# axis {a} "))
            .nth(1)
            .unwrap()
            .to_string()
    };
    let key = |a: char, k: &str| -> f64 {
        (block(a).lines())
            .find_map(|l| l.strip_prefix(&format!("lr_param.{k} ")))
            .unwrap()
            .trim()
            .parse()
            .unwrap()
    };
    let assigned = |name: String| -> String {
        (st.lines())
            .find_map(|l| l.strip_prefix(&format!("{name} := ")))
            .unwrap()
            .trim_end_matches(';')
            .to_string()
    };
    let temp = |v: &str| HOT.iter().find(|(n, _)| *n == v).unwrap().1;
    let (largest, thermal, bound) = applied(&law, &|point| {
        std::array::from_fn(|k| {
            let a = ['X', 'Y', 'Z'][k];
            assert_eq!(key(a, "temp_comp"), 1.0);
            let offset = assigned(format!("offset_0_{a}"));
            let offset = offset
                .strip_prefix("LREAL_TO_DINT(")
                .unwrap()
                .strip_suffix(')')
                .unwrap();
            // LREAL_TO_DINT rounds to the nearest integer, halves away
            // from zero (Beckhoff Infosys, "REAL/LREAL_TO_<type>").
            let offset = st_sum(offset, &temp).round();
            let coefficient = st_sum(&assigned(format!("coefficient_{a}")), &temp);
            let s0 = key(a, "temp_comp_position_0");
            let s = point[a.to_ascii_lowercase().to_string()].as_f64().unwrap();
            // Δs = offset_0 + coefficient·(s − s0): 0.1 µm, µm/m, added
            // to the command (vmc3's axes move the tool along +X, +Y, +Z).
            offset * 1e-4 + coefficient * 1e-6 * (s - s0 * 1e-4)
        })
    });
    // offset_0's rounding adds at most 0.05 µm per axis.
    assert!(
        largest <= bound + 0.5e-4 * 3f64.sqrt() + 1e-12,
        "{largest} vs {bound}"
    );
    assert!(largest < 0.2 * thermal, "{largest} of {thermal}");
}

/// A TEMPCOMP formula's value (`ĉ*W486-ĉ*W488+K`), each word's value from
/// `word`.
fn tempcomp_value(text: &str, word: &dyn Fn(&str) -> f64) -> f64 {
    let b = text.as_bytes();
    let mut terms = Vec::new();
    let mut start = 0;
    for i in 1..b.len() {
        if (b[i] == b'+' || b[i] == b'-') && b[i - 1] != b'e' {
            terms.push(&text[start..i]);
            start = i;
        }
    }
    terms.push(&text[start..]);
    (terms.iter())
        .map(|t| match t.split_once('*') {
            Some((c, w)) => c.parse::<f64>().unwrap() * word(w),
            None => t.parse::<f64>().unwrap(),
        })
        .sum()
}

#[test]
fn the_heidenhain_tempcomp_formulas_evaluated_as_the_tnc_does_leave_the_stated_remainder() {
    use chain_core::compensation::thermal::{ThermalFormat, TEMPCOMP_CHARS};
    let law = vmc3_law(ThermalFormat::Heidenhain, COARSE);
    let files = law.files("test");
    let text = |name: &str| files.iter().find(|f| f.name == name).unwrap().text.clone();
    let (tab, readme) = (
        text("KINEMATICS_TEMPCOMP.TAB"),
        text("KINEMATICS_TEMPCOMP-README.txt"),
    );
    // The words the PLC fills, by the README.
    let words: Vec<(String, String)> = (readme.lines())
        .filter_map(|l| l.trim().split_once(" = "))
        .filter(|(w, _)| w.starts_with('W'))
        .map(|(w, s)| (w.to_string(), s.to_string()))
        .collect();
    assert_eq!(words.len(), 5, "{readme}");
    // Per row: Trans, its axis, COORD 0 and the formula.
    let rows: Vec<(char, String)> = (tab.lines().skip(2))
        .take_while(|l| *l != "[END]")
        .map(|l| {
            let f: Vec<&str> = l.split_whitespace().collect();
            assert_eq!((f[1], f[3]), ("Trans", "0"), "{l}");
            assert!(f[4].len() <= TEMPCOMP_CHARS, "{l}");
            (f[2].chars().next().unwrap(), f[4].to_string())
        })
        .collect();
    assert_eq!(rows.len(), 3, "{tab}");
    assert!(tab.starts_with("BEGIN KINEMATICS_TEMPCOMP.TAB MM\nNR"));
    let at = |t: &[f64]| -> [f64; 3] {
        let word = |w: &str| {
            let s = &words.iter().find(|(x, _)| x == w).unwrap().1;
            let i = law.remainder.iter().position(|r| &r.sensor == s).unwrap();
            t[i]
        };
        std::array::from_fn(|k| {
            let axis = ['X', 'Y', 'Z'][k];
            let (_, f) = rows.iter().find(|(a, _)| *a == axis).unwrap();
            tempcomp_value(f, &word)
        })
    };
    // 0 at the references: the constant is exact.
    for v in at(&[20.0; 5]) {
        assert!(v.abs() < 1e-15, "{v}");
    }
    // Sensor by sensor 5 K above its reference: the rows displace the
    // table (the workpiece side), the tool point's error moves by them;
    // what is left is five times the stated remainder.
    for (i, r) in law.remainder.iter().enumerate() {
        let mut t = [20.0; 5];
        t[i] += 5.0;
        let state: Vec<String> = (law.remainder.iter().zip(&t))
            .map(|(r, v)| format!("{}={v}", r.sensor))
            .collect();
        let d = at(&t);
        let mut largest = 0.0f64;
        for (_, part) in thermal_part(&state.join(","), &COARSE_ARGS) {
            let left: Vec<f64> = (0..3).map(|k| part[k] + d[k]).collect();
            largest = largest.max(left.iter().map(|v| v * v).sum::<f64>().sqrt());
        }
        assert!(
            (largest - 5.0 * r.after).abs() < 1e-9 * r.before + 1e-12,
            "{}: {largest} vs {}",
            r.sensor,
            5.0 * r.after
        );
    }
    // The spindle's growth along Z from T_front and T_rear is held (a
    // constant per kelvin); T_head's does not fit the 31 characters; the
    // X scale growth is a slope TEMPCOMP cannot hold (half of it left).
    let after = |s: &str| {
        law.remainder
            .iter()
            .find(|r| r.sensor == s)
            .unwrap()
            .clone()
    };
    assert!(after("T_front").after < 1e-12);
    assert!((after("T_head").after - after("T_head").before).abs() < 1e-15);
    assert!((after("T_x").after - 0.5 * after("T_x").before).abs() < 1e-12);
    assert!(law.notes.iter().any(|n| n.contains("no room for T_head")));
}

#[test]
fn klipper_s_z_thermal_adjust_applied_from_the_homing_temperature_leaves_the_stated_remainder() {
    use chain_core::compensation::thermal::ThermalFormat;
    let law = vmc3_law(ThermalFormat::Klipper, COARSE);
    let cfg = &law.files("test")[0].text;
    assert!(cfg.contains("\n[z_thermal_adjust]\ntemp_coeff: "), "{cfg}");
    let coeff: f64 = (cfg.lines())
        .find_map(|l| l.strip_prefix("temp_coeff: "))
        .unwrap()
        .parse()
        .unwrap();
    // One sensor on Z: the spindle's front bearing, 2.5 µm/K of growth
    // (examples/thermal/vmc3_thermal_values.yaml).
    assert_eq!(law.axes.len(), 1);
    assert_eq!(law.axes[0].axis, 'Z');
    assert_eq!(law.axes[0].lines.len(), 1);
    assert_eq!(law.axes[0].lines[0].sensor, "T_front");
    assert!((coeff - 0.0025).abs() < 1e-15, "{coeff}");
    // Homed at 23 °C (front) and 21 °C (rear), run at 29 and 27:
    // z_thermal_adjust.py moves Z by −temp_coeff·(T − T_ref), T_ref the
    // front sensor at homing; homing took up the error there.
    let state = |front: f64, rear: f64| {
        format!("T_x=20,T_front={front},T_rear={rear},T_head=20,T_coltop=20")
    };
    let homed = thermal_part(&state(23.0, 21.0), &COARSE_ARGS);
    let hot = thermal_part(&state(29.0, 27.0), &COARSE_ARGS);
    let mut largest = 0.0f64;
    for ((_, h), (_, r)) in homed.iter().zip(&hot) {
        let mut left: Vec<f64> = (0..3).map(|k| r[k] - h[k]).collect();
        left[2] += -coeff * (29.0 - 23.0);
        largest = largest.max(left.iter().map(|v| v * v).sum::<f64>().sqrt());
    }
    // The front's growth is held; the rear's 6 K are left whole.
    let rear = law.remainder.iter().find(|r| r.sensor == "T_rear").unwrap();
    let front = law
        .remainder
        .iter()
        .find(|r| r.sensor == "T_front")
        .unwrap();
    assert!(front.after < 1e-12, "{front:?}");
    assert_eq!(rear.after, rear.before);
    assert!(
        (largest - 6.0 * rear.after).abs() < 1e-12,
        "{largest} vs {}",
        6.0 * rear.after
    );
}

#[test]
fn the_thermal_formats_are_export_controllers() {
    let file = example("thermal/vmc3_thermal.yaml");
    let values = example("thermal/vmc3_thermal_values.yaml");
    let dir = scratch("thermal-export-cli");
    let grid = COARSE_ARGS;
    use chain_core::compensation::thermal::ThermalFormat;
    for (format, names) in [
        (ThermalFormat::Siemens, vec!["TEMP_COMP.SPF"]),
        (
            ThermalFormat::Linuxcnc,
            vec!["thermal_comp.comp", "thermal_comp.hal", "thermal_comp.ini"],
        ),
        (
            ThermalFormat::Beckhoff,
            vec!["temp_comp_axes.lis", "FB_TempComp.st"],
        ),
        (
            ThermalFormat::Heidenhain,
            vec!["KINEMATICS_TEMPCOMP.TAB", "KINEMATICS_TEMPCOMP-README.txt"],
        ),
        (ThermalFormat::Klipper, vec!["z_thermal_adjust.cfg"]),
    ] {
        let controller = format!("{}-thermal", format.name());
        let out = dir.join(&controller);
        let mut args = vec![
            "export",
            &file,
            "--values",
            &values,
            "--controller",
            &controller,
            "--out",
            s(&out),
            "--format",
            "json",
        ];
        args.extend_from_slice(&grid);
        let doc = ok_json(&args);
        assert_eq!(doc["files"], serde_json::json!(names));
        for n in names.iter().filter(|n| !n.ends_with(".TAB")) {
            let text = std::fs::read_to_string(out.join(n)).unwrap();
            assert!(
                text.contains(&format!("chain export --controller {controller}")),
                "{n}"
            );
        }
        // The document is the library's law over the same grid.
        let law = serde_json::to_value(vmc3_law(format, COARSE)).unwrap();
        for key in ["format", "holds", "axes", "remainder", "notes"] {
            common::json_to_roundoff(&law[key], &doc[key], key)
                .unwrap_or_else(|e| panic!("{controller}: {e}"));
        }
        let mut args = vec![
            "export",
            &file,
            "--values",
            &values,
            "--controller",
            &controller,
            "--out",
            s(&out),
        ];
        args.extend_from_slice(&grid);
        let table = ok_stdout(&args);
        assert!(
            table.contains("T_front") && table.contains(doc["holds"].as_str().unwrap()),
            "{table}"
        );
        if format != ThermalFormat::Klipper && format != ThermalFormat::Heidenhain {
            assert!(table.contains("11.5000"), "{table}");
        }
    }
    // Klipper corrects Z, and this machine has X only.
    let (m, v) = files("thermal-klipper-no-z");
    let e = unwrapped(&fails(&[
        "export",
        s(&m),
        "--values",
        s(&v),
        "--controller",
        "klipper-thermal",
        "--grid",
        "x=0,250,500",
        "--out",
        s(&dir),
    ]));
    assert!(
        e.contains("machine `scale1` has no linear axis along Z: Klipper's [z_thermal_adjust] corrects Z only"),
        "{e}"
    );
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
