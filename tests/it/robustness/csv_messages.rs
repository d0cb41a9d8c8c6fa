//! One message shape for every CSV reader: a header-only
//! file, a ragged row and a non-numeric cell are worded the same by `chain
//! inverse --pose`, `chain path --axes`, `chain compensate`, measurement
//! CSVs (`chain identify`) and values tables (`chain map --values`), under
//! the same `chain::csv::*` code. The command line's tables are
//! `file:line: …`; the located readers add the column number and a snippet.

use std::path::{Path, PathBuf};
use std::process::Command;

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// A fresh directory for one test's files.
fn scratch(name: &str) -> PathBuf {
    let dir =
        std::env::temp_dir().join(format!("chain-csv-messages-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs the binary in `dir`; checks exit status 1; returns stderr with
/// miette's frame characters and line wrapping flattened.
fn refused(dir: &Path, args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_chain"))
        .current_dir(dir)
        .env("NO_COLOR", "1")
        .args(args)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1), "{args:?}: {out:?}");
    String::from_utf8_lossy(&out.stderr)
        .split_whitespace()
        .filter(|w| *w != "│")
        .collect::<Vec<_>>()
        .join(" ")
}

fn check(err: &str, message: &str, code: &str) {
    assert!(err.contains(message), "expected `{message}` in: {err}");
    assert!(err.contains(code), "expected `{code}` in: {err}");
}

const NO_DATA: &str = "the header is followed by no data row";

/// `(file contents, expected message, code)` for one reader's three cases.
fn cases(
    header: &str,
    short: &str,
    bad: &str,
    col: &str,
    fields: usize,
    columns: usize,
) -> [(String, String, &'static str); 3] {
    [
        (
            format!("{header}\n"),
            format!(":1: {NO_DATA}"),
            "chain::csv::no_data",
        ),
        (
            format!("{header}\n{short}\n"),
            format!(":2: this row has {fields} fields but the header has {columns} columns"),
            "chain::csv::ragged",
        ),
        (
            format!("{header}\n{bad}\n"),
            format!(":2: column `{col}`: `abc` is not a number"),
            "chain::csv::not_a_number",
        ),
    ]
}

#[test]
fn inverse_pose() {
    let dir = scratch("inverse");
    let machine = format!("{ROOT}/examples/machines/head_head_bc.yaml");
    for (k, (text, message, code)) in cases("px,py,pz,i,j,k", "1,2", "1,2,3,0,abc,1", "j", 2, 6)
        .into_iter()
        .enumerate()
    {
        let file = format!("p{k}.csv");
        std::fs::write(dir.join(&file), text).unwrap();
        let err = refused(&dir, &["inverse", &machine, "--pose", &file]);
        check(&err, &format!("{file}{message}"), code);
    }
}

#[test]
fn path_axes() {
    let dir = scratch("path");
    let machine = format!("{ROOT}/examples/machines/gantry_grinder.yaml");
    for (k, (text, message, code)) in cases("x,y,z", "0,0", "0,abc,0", "y", 2, 3)
        .into_iter()
        .enumerate()
    {
        let file = format!("a{k}.csv");
        std::fs::write(dir.join(&file), text).unwrap();
        let err = refused(&dir, &["path", &machine, "--axes", &file]);
        check(&err, &format!("{file}{message}"), code);
    }
}

#[test]
fn compensate_measurements() {
    let dir = scratch("compensate");
    for (k, (text, message, code)) in cases("theta_deg,z1,z3", "10,1", "10,abc,3", "z1", 2, 3)
        .into_iter()
        .enumerate()
    {
        let file = format!("c{k}.csv");
        std::fs::write(dir.join(&file), text).unwrap();
        let err = refused(&dir, &["compensate", &file, "--length", "500"]);
        check(&err, &format!("{file}{message}"), code);
    }
}

#[test]
fn identify_measurements() {
    let dir = scratch("identify");
    let machine = format!("{ROOT}/examples/measurements/vmc3_probe.yaml");
    let header = "x,y,z,tx,ty,tz,dpx,dpy,dpz,std";
    let short = "100,50,50,0,0,-150,0.003,0.003";
    let bad = "100,abc,50,0,0,-150,0.003,0.003,0.002,0.001";
    // Located: `file:line:column: …`.
    let expected = [
        (
            ":1:1: the header is followed by no data row",
            "chain::csv::no_data",
        ),
        (
            ":2:1: this row has 8 fields but the header has 10 columns",
            "chain::csv::ragged",
        ),
        (
            ":2:5: column `y`: `abc` is not a number",
            "chain::csv::not_a_number",
        ),
    ];
    let texts = [
        format!("{header}\n"),
        format!("{header}\n{short}\n"),
        format!("{header}\n{bad}\n"),
    ];
    for (k, (text, (message, code))) in texts.iter().zip(expected).enumerate() {
        let file = format!("m{k}.csv");
        std::fs::write(dir.join(&file), text).unwrap();
        let err = refused(&dir, &["identify", &machine, "--measurements", &file]);
        check(&err, &format!("{file}{message}"), code);
    }
}

#[test]
fn values_tables() {
    let dir = scratch("values");
    let machine = format!("{ROOT}/examples/machines/vmc3.yaml");
    let values = std::fs::read_to_string(format!("{ROOT}/examples/values/vmc3.yaml")).unwrap();
    for axis in ["y_axis.csv", "z_axis.csv"] {
        std::fs::copy(format!("{ROOT}/examples/values/{axis}"), dir.join(axis)).unwrap();
    }
    let header = "x,EXX,EYX,EZX,EAX,EBX,ECX";
    let texts = [
        format!("{header}\n"),
        format!("{header}\n0,1\n"),
        format!("{header}\n0,abc,0,0,0,0,0\n800,0,0,0,0,0,0\n"),
    ];
    let expected = [
        (
            ":1:1: the header is followed by no data row",
            "chain::csv::no_data",
        ),
        (
            ":2:1: this row has 2 fields but the header has 7 columns",
            "chain::csv::ragged",
        ),
        (
            ":2:3: column `EXX`: `abc` is not a number",
            "chain::csv::not_a_number",
        ),
    ];
    for (k, (text, (message, code))) in texts.iter().zip(expected).enumerate() {
        let file = format!("x{k}.csv");
        std::fs::write(dir.join(&file), text).unwrap();
        let yaml = format!("v{k}.yaml");
        std::fs::write(dir.join(&yaml), values.replace("x_axis.csv", &file)).unwrap();
        let err = refused(&dir, &["map", &machine, "--values", &yaml]);
        check(&err, &format!("{file}{message}"), code);
    }
}

/// A refused huge value is quoted shortened (its first
/// 40 characters and `…`, `chain_core::diagnostic::shortened`), not printed
/// in full: a 5,000-character cell in a CSV of `path`, `compensate` and a
/// values table, and a 5,000-character name where a number belongs in a
/// machine file.
#[test]
fn huge_refused_values_are_quoted_shortened() {
    let dir = scratch("huge");
    let huge = format!("1{}", "x".repeat(4999));
    let machine = format!("{ROOT}/examples/machines/gantry_grinder.yaml");
    std::fs::write(dir.join("axes.csv"), format!("x,y,z\n0,{huge},0\n")).unwrap();
    std::fs::write(
        dir.join("comp.csv"),
        format!("theta_deg,z1,z3\n10,{huge},3\n20,1,3\n"),
    )
    .unwrap();
    let name = "a".repeat(5000);
    let text = std::fs::read_to_string(&machine).unwrap().replacen(
        "x: [0, 250, 500, 750, 1000]",
        &format!("x: [{name}]"),
        1,
    );
    std::fs::write(dir.join("long_name.yaml"), text).unwrap();
    let shown = format!("{}…", &huge[..40]);
    let runs: [(&[&str], String); 3] = [
        (
            &["path", &machine, "--axes", "axes.csv"],
            format!("axes.csv:2: column `y`: `{shown}` is not a number"),
        ),
        (
            &["compensate", "comp.csv", "--length", "500"],
            format!("comp.csv:2: column `z1`: `{shown}` is not a number"),
        ),
        (
            &["reliability", "long_name.yaml"],
            format!(
                "`{}…` is a name, but only numbers are allowed here",
                &name[..40]
            ),
        ),
    ];
    for (args, message) in runs {
        let err = refused(&dir, args);
        assert!(
            err.contains(&message),
            "{args:?}: expected `{message}` in {err}"
        );
        assert!(
            !err.contains(&huge[..200]) && !err.contains(&name[..200]),
            "{args:?} echoes the value in full: {} bytes",
            err.len()
        );
    }
}

/// A huge option value, argument or subcommand refused by the command-line
/// parser is quoted shortened too (clap's own message echoes it whole), with
/// clap's exit status 2.
#[test]
fn huge_command_line_values_are_quoted_shortened() {
    let huge = "9".repeat(5000);
    let gantry = format!("{ROOT}/examples/machines/gantry_grinder.yaml");
    let assignment = format!("a=x{huge}");
    let option = format!("--{huge}");
    let runs: [(Vec<&str>, String); 4] = [
        (
            vec!["path", &gantry, "--axes", "x.csv", "--samples", &huge],
            format!("invalid value '{}…' for '--samples", &huge[..40]),
        ),
        (
            vec!["path", &gantry, "--axes", "x.csv", "--param", &assignment],
            format!("`x{}…` is not a number", &huge[..39]),
        ),
        (
            vec![&option],
            format!("unexpected argument '--{}…'", &huge[..38]),
        ),
        (
            vec![&huge],
            format!("unrecognized subcommand '{}…'", &huge[..40]),
        ),
    ];
    for (args, message) in runs {
        let out = Command::new(env!("CARGO_BIN_EXE_chain"))
            .args(&args)
            .env("NO_COLOR", "1")
            .output()
            .expect("chain runs");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(err.contains(&message), "expected `{message}` in {err}");
        assert!(
            !err.contains(&huge[..200]),
            "echoes the value in full: {} bytes",
            err.len()
        );
    }
}
