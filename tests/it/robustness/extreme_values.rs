//! Numbers that stay numbers: extreme values are refused
//! with their key or option, or written in a finite form, never as `inf` or
//! `NaN` in a successful output.

use std::process::Command;

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

fn run(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_chain"))
        .args(args)
        .output()
        .unwrap()
}

fn flat(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes)
        .split_whitespace()
        .filter(|w| *w != "│")
        .collect::<Vec<_>>()
        .join(" ")
}

fn gantry() -> String {
    std::fs::read_to_string(format!("{ROOT}/examples/machines/gantry_grinder.yaml")).unwrap()
}

fn scratch(name: &str, text: &str) -> String {
    let dir = std::env::temp_dir().join(format!("chain-extreme-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path.display().to_string()
}

#[test]
fn a_std_whose_square_overflows_is_refused_at_load_with_its_key_and_line() {
    let text = gantry().replacen(
        "dxx: {dist: normal, mean: 0, std: 0.05/6}",
        "dxx: {dist: normal, mean: 0, std: 1e155}",
        1,
    );
    let line = text.lines().position(|l| l.contains("std: 1e155")).unwrap() + 1;
    let file = scratch("big_std.yaml", &text);
    let out = run(&[
        "path",
        &file,
        "--axes",
        &format!("{ROOT}/examples/paths/gantry_path.csv"),
    ]);
    assert_eq!(out.status.code(), Some(1), "{out:?}");
    let err = flat(&out.stderr);
    assert!(err.contains(&format!("big_std.yaml:{line}:")), "{err}");
    assert!(
        err.contains("statistics.dxx.std") && err.contains("[-1e100, 1e100]"),
        "{err}"
    );
    assert!(err.contains("chain::out_of_range"), "{err}");
}

#[test]
fn compensate_length_1e308_is_refused_naming_the_option() {
    let out = run(&[
        "compensate",
        &format!("{ROOT}/examples/data/swing_htm50200.csv"),
        "--length",
        "1e308",
    ]);
    assert_eq!(out.status.code(), Some(1), "{out:?}");
    assert!(out.stdout.is_empty());
    let err = flat(&out.stderr);
    assert!(
        err.contains("--length") && err.contains("at most 1e6"),
        "{err}"
    );
    // The largest accepted length still gives finite numbers.
    let out = run(&[
        "compensate",
        &format!("{ROOT}/examples/data/swing_htm50200.csv"),
        "--length",
        "1e6",
        "--format",
        "json",
    ]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(!text.contains("inf") && !text.contains("NaN"), "{text}");
}

#[test]
fn reliability_csv_writes_an_infinite_beta_as_the_json_does() {
    // Every sample fails (mean far beyond the tolerance): pf = 1, beta = −∞.
    let text = gantry().replacen(
        "dxx: {dist: normal, mean: 0, std: 0.05/6}",
        "dxx: {dist: normal, mean: -100, std: 0.05/6}",
        1,
    );
    let file = scratch("pf_one.yaml", &text);
    let args = [
        "reliability",
        &file,
        "--method",
        "mc",
        "--samples",
        "200",
        "--seed",
        "1",
    ];
    let csv = run(&[&args[..], &["--format", "csv"]].concat());
    assert!(csv.status.success(), "{csv:?}");
    let csv = String::from_utf8_lossy(&csv.stdout).into_owned();
    assert!(!csv.contains("inf") && !csv.contains("NaN"), "{csv}");
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let (pf, beta) = (
        header.iter().position(|h| *h == "pf").unwrap(),
        header.iter().position(|h| *h == "beta").unwrap(),
    );
    let first: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(first[pf], "1.0");
    assert_eq!(first[beta], "", "an empty cell, the JSON's null");
    let json = run(&[&args[..], &["--format", "json"]].concat());
    let doc: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
    let case = &doc["results"][0];
    assert_eq!(case["pf"], 1.0);
    assert!(case["beta"].is_null(), "{case}");
}

#[test]
fn nominal_angular_1e308_is_refused_naming_values() {
    let gantry = format!("{ROOT}/examples/machines/gantry_grinder.yaml");
    let out = run(&[
        "sensitivity",
        &gantry,
        "--kind",
        "geometric",
        "--values",
        "angular=1e308",
    ]);
    assert_eq!(out.status.code(), Some(2), "{out:?}");
    let err = flat(&out.stderr);
    assert!(
        err.contains("--values") && err.contains("at most π rad"),
        "{err}"
    );
}

#[test]
fn an_unknown_at_name_blames_at_not_the_machine_file() {
    let gantry = format!("{ROOT}/examples/machines/gantry_grinder.yaml");
    let out = run(&["sensitivity", &gantry, "--at", "q=1"]);
    assert_eq!(out.status.code(), Some(1), "{out:?}");
    let err = flat(&out.stderr);
    assert!(
        err.contains("--at: `q` is not an axis variable (did you mean `x`?)"),
        "{err}"
    );
    assert!(
        !err.contains("gantry_grinder.yaml:"),
        "no location in the machine file: {err}"
    );
}

/// An axis value of 1e300 gives finite sensitivities (about 1e300) whose
/// moments overflow (unchecked, `path` would exit 0 with `inf` in its
/// table). The study refuses the point, naming it (in exponent form) and what
/// overflowed; `reliability` over such a grid likewise.
#[test]
fn axis_values_whose_moments_overflow_are_refused_naming_the_point() {
    let axes = scratch("axes_1e300.csv", "x,y,z\n0,-1500,600\n1e300,-1500,600\n");
    let gantry_file = format!("{ROOT}/examples/machines/gantry_grinder.yaml");
    for args in [
        vec!["path", &gantry_file, "--axes", &axes],
        vec!["reliability", &gantry_file, "--grid", "x=0,1e300"],
    ] {
        let out = run(&args);
        let err = flat(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(out.stdout.is_empty(), "{args:?}");
        for needle in [
            "chain::reliability::overflow",
            "x = 1e300",
            "y = -1500",
            "standard deviation of py is not finite",
        ] {
            assert!(
                err.contains(needle),
                "{args:?}: `{needle}` missing from {err}"
            );
        }
    }
    // A grid past the table's points: its summary pass refuses the first
    // such point as the run does, before writing anything.
    let out = run(&[
        "reliability",
        &gantry_file,
        "--grid",
        "x=0:1e300:10001",
        "--grid",
        "y=-1500",
        "--grid",
        "z=600",
    ]);
    let err = flat(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(out.stdout.is_empty());
    assert!(
        err.contains("x = 1e296") && err.contains("standard deviation of py is not finite"),
        "{err}"
    );
    // Large but harmless values still run: 1e100 mm gives sensitivities of
    // 1e100 and variances of 1e200·σ².
    let axes = scratch("axes_1e100.csv", "x,y,z\n1e100,-1500,600\n");
    let out = run(&["path", &gantry_file, "--axes", &axes, "--format", "json"]);
    assert!(out.status.success(), "{}", flat(&out.stderr));
}

/// An offset, a tool point or a parameter beyond any physical size (a
/// kilometre in mm) is refused at load with its key and line, and so is a
/// `--param` beyond it: such a value is a slip that would make every
/// tolerance of the inverse kinematics meaningless.
#[test]
fn lengths_and_parameters_beyond_any_physical_size_are_refused_with_their_place() {
    let vmc3 = std::fs::read_to_string(format!("{ROOT}/examples/machines/vmc3.yaml")).unwrap();
    let broken = vmc3.replacen("offset: [0, -500, 0]", "offset: [1e15, -500, 0]", 1);
    assert_ne!(broken, vmc3);
    let line = broken.lines().position(|l| l.contains("1e15")).unwrap() + 1;
    let file = scratch("far_offset.yaml", &broken);
    let out = run(&["derive", &file]);
    assert_eq!(out.status.code(), Some(1), "{out:?}");
    let err = flat(&out.stderr);
    assert!(err.contains(&format!("far_offset.yaml:{line}:")), "{err}");
    assert!(
        err.contains("a length (mm) must be in [-1e6, 1e6] (a kilometre in mm: beyond any machine), got 1000000000000000"),
        "{err}"
    );
    assert!(err.contains("offset[0]"), "{err}");
    // A parameter's value in the file, and one given with --param.
    let internal =
        std::fs::read_to_string(format!("{ROOT}/examples/machines/internal_grinder.yaml")).unwrap();
    let (name, value) = {
        let section = internal.split("parameters:").nth(1).unwrap();
        let l = section.lines().find(|l| l.contains(':')).unwrap();
        let (n, v) = l.split_once(':').unwrap();
        (n.trim().to_string(), v.trim().to_string())
    };
    let broken = internal.replacen(&format!("{name}: {value}"), &format!("{name}: 2e9"), 1);
    let line = broken.lines().position(|l| l.contains("2e9")).unwrap() + 1;
    let file = scratch("far_parameter.yaml", &broken);
    let out = run(&["derive", &file]);
    assert_eq!(out.status.code(), Some(1), "{out:?}");
    let err = flat(&out.stderr);
    assert!(
        err.contains(&format!("far_parameter.yaml:{line}:")),
        "{err}"
    );
    assert!(
        err.contains(&format!("parameters.{name}"))
            && err.contains("a parameter value must be in [-1e6, 1e6]"),
        "{err}"
    );
    let out = run(&[
        "reliability",
        &format!("{ROOT}/examples/machines/internal_grinder.yaml"),
        "--param",
        &format!("{name}=1e15"),
    ]);
    assert_eq!(out.status.code(), Some(1), "{out:?}");
    let err = flat(&out.stderr);
    assert!(
        err.contains(&format!(
            "--param {name}: 1e15 is beyond any physical size: a parameter must be in [-1e6, 1e6]"
        )),
        "{err}"
    );
}
