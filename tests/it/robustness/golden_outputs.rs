//! The CLI's outputs against recorded reference outputs.
//!
//! `tests/golden/commands.txt` lists commands whose outputs are recorded in
//! `tests/golden/NAME` from an earlier build of the binary (see that file's
//! header). Each is run again and compared byte for byte, in every format.
//!
//! The `reliability` and `path` (FORM) recordings, of 6 Dec 2026, include
//! FORM's termination and call counts, the cases that did not converge and
//! the path's volumetric columns; every line, JSON key and CSV column of the
//! recording they replace was checked to be contained, unchanged, in them.
//! They too must come out byte for byte.
//!
//! One exception to byte identity: the least-cost allocation
//! (`allocate_optimal.*`). Its linear solves are nalgebra's LU and Cholesky
//! (no hand-written linear algebra), and the optimum differs from the
//! recording by round-off (the stds by 1-3 ulp, the KKT residuals between
//! 6.7e-16 and 8.9e-16). Those files are compared number by number: equal to
//! 1e-14 relative, or both below 1e-14 in magnitude (round-off residuals);
//! every other byte identical.
//!
//! A second exception: the path on the five-axis machine (`path_cnc5.*`)
//! is compared to the same round-off where its numbers are JSON. The
//! runtime tape takes `sin`/`cos` of the rotary axes from the vectorised
//! kernel of `chain_core::lanes` (≤ 2 ulp from the standard library's,
//! docs/macro.md), and its means differ from the recording by an ulp.
//!
//! The sampling methods are not in that list: the recording's binary drew
//! other random streams, and their results differ within their standard
//! errors (their checks are in `papers/reliability_gantry.rs`,
//! `commands/reliability_cli.rs` and `commands/path.rs`).
//!
//! `tests/golden/ops/commands.txt` lists every command on the example
//! inputs, the seeded samplers with and without a target CoV included,
//! recorded with the binary of commit aa98b10 (the exceptions are noted in
//! that file): the one application layer `chain::ops` under the CLI and
//! Python, and the samplers behind one trait and one driver, must reproduce
//! each output byte for byte.

use crate::common;

use std::path::Path;

use common::cli::{chain, success};
use serde_json::Value;

/// Commands whose numbers may move by round-off (see the header).
fn roundoff(name: &str) -> bool {
    name.starts_with("allocate_optimal") || name.starts_with("path_cnc5")
}

/// `recorded` and `new` equal but for numbers that agree up to round-off
/// (JSON numbers, or number tokens in text).
fn equal_to_roundoff(recorded: &str, new: &str, json: bool) -> Result<(), String> {
    if json {
        let a: Value = serde_json::from_str(recorded).unwrap();
        let b: Value = serde_json::from_str(new).map_err(|e| e.to_string())?;
        return common::json_to_roundoff(&a, &b, "$");
    }
    let (a, b): (Vec<&str>, Vec<&str>) = (recorded.lines().collect(), new.lines().collect());
    if a.len() != b.len() {
        return Err(format!("{} lines, now {}", a.len(), b.len()));
    }
    for (i, (la, lb)) in a.iter().zip(&b).enumerate() {
        let (ta, tb): (Vec<&str>, Vec<&str>) = (
            la.split_whitespace().collect(),
            lb.split_whitespace().collect(),
        );
        let same = ta.len() == tb.len()
            && ta.iter().zip(&tb).all(|(x, y)| {
                let strip = |t: &str| t.trim_end_matches([',', ';', ')']).to_string();
                x == y
                    || matches!((strip(x).parse::<f64>(), strip(y).parse::<f64>()),
                        (Ok(p), Ok(q)) if common::roundoff(p, q))
            });
        if !same {
            return Err(format!("line {}: {la:?}, now {lb:?}", i + 1));
        }
    }
    Ok(())
}

/// `recorded == new`; `Err` names the first line that differs.
fn identical(recorded: &str, new: &str) -> Result<(), String> {
    if recorded == new {
        return Ok(());
    }
    let (a, b): (Vec<&str>, Vec<&str>) = (recorded.lines().collect(), new.lines().collect());
    let i = (0..a.len().max(b.len()))
        .find(|&i| a.get(i) != b.get(i))
        .unwrap_or(a.len());
    Err(format!(
        "line {}: {:?}, now {:?}",
        i + 1,
        a.get(i),
        b.get(i)
    ))
}

/// The recorded commands of `dir/commands.txt`: name, arguments, the
/// recorded output and the output now.
fn rerun(dir: &Path) -> Vec<(String, Vec<String>, String, String)> {
    let list = std::fs::read_to_string(dir.join("commands.txt")).unwrap();
    list.lines()
        .filter(|l| !l.starts_with('#') && !l.is_empty())
        .map(|line| {
            let (name, args) = line.split_once('\t').expect("NAME<TAB>ARGS");
            let args: Vec<String> = args.split(' ').map(String::from).collect();
            let argv: Vec<&str> = args.iter().map(String::as_str).collect();
            let recorded = std::fs::read_to_string(dir.join(name)).unwrap();
            let new = String::from_utf8(success(chain(&argv)).stdout).unwrap();
            (name.to_string(), args, recorded, new)
        })
        .collect()
}

#[test]
fn ops_outputs_match_those_recorded_before_issue_31() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden/ops");
    let runs = rerun(&dir);
    let failures: Vec<String> = (runs.iter())
        .filter_map(|(name, args, recorded, new)| {
            let why = identical(recorded, new).err()?;
            Some(format!("{name} (chain {}): {why}", args.join(" ")))
        })
        .collect();
    assert!(runs.len() >= 40, "only {} recorded commands", runs.len());
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn outputs_match_those_recorded_before_the_architecture_change() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden");
    let mut failures = Vec::new();
    let mut count = 0;
    for (name, args, recorded, new) in rerun(&dir) {
        let name = name.as_str();
        let (recorded, new) = (recorded.as_str(), new.as_str());
        count += 1;
        let verdict = if roundoff(name) {
            equal_to_roundoff(recorded, new, name.ends_with(".json"))
        } else {
            identical(recorded, new)
        };
        if let Err(why) = verdict {
            failures.push(format!("{name} (chain {}): {why}", args.join(" ")));
        }
    }
    assert!(count >= 40, "only {count} recorded commands");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn the_comparisons_catch_a_change() {
    let json = |v: serde_json::Value| v.to_string();
    let a = json(serde_json::json!({"r": [{"pf": 0.1}], "m": "form"}));
    let more = json(serde_json::json!({"r": [{"pf": 0.1, "calls": 2}], "m": "form"}));
    let other = json(serde_json::json!({"r": [{"pf": 0.10000000001}], "m": "form"}));
    let ulp = json(serde_json::json!({"r": [{"pf": 0.10000000000000002}], "m": "form"}));
    assert!(equal_to_roundoff(&a, &more, true).is_err());
    assert!(equal_to_roundoff(&more, &a, true).is_err());
    assert!(equal_to_roundoff(&a, &other, true).is_err());
    assert!(equal_to_roundoff(&a, &ulp, true).is_ok());
    assert!(identical(&a, &ulp).is_err());
    assert!(equal_to_roundoff("s 8.88e-16, x 0.1", "s 6.66e-16, x 0.1", false).is_ok());
    assert!(equal_to_roundoff("x 0.1", "x 0.1000000001", false).is_err());
    assert!(equal_to_roundoff("x 0.1", "x 0.1\ny 2", false).is_err());
    assert!(equal_to_roundoff(
        "{\"a\": 0.00677424086163459}",
        "{\"a\": 0.006774240861634587}",
        true
    )
    .is_ok());
    assert!(equal_to_roundoff("{\"a\": 1.0}", "{\"a\": 1.00001}", true).is_err());
    assert!(identical("a\nb\n", "a\nb\n").is_ok());
    assert!(identical("a\nb\n", "a\nb \n").is_err());
    assert!(identical("a\nc\n", "a\nb\nc\n").is_err());
}
