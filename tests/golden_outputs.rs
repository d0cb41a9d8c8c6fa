//! The CLI's outputs before and after the architecture change (issue 11).
//!
//! `tests/golden/commands.txt` lists commands whose outputs were recorded with
//! the binary built from the commit before the change (`tests/golden/NAME`).
//! Each is run again and compared:
//!
//! - `derive`, `sensitivity` (both kinds), `allocate`, `compensate`,
//!   `inverse` and `motion`: byte for byte, in every format;
//! - `reliability` and `path` (FORM): the recorded output must be contained in
//!   the new one. JSON: every recorded key with the same value (numbers and
//!   strings to the last digit), arrays of the same length; new keys are
//!   allowed (FORM's termination and call counts). Tables: every recorded
//!   line, in order (new lines are allowed). CSV: every recorded column with
//!   the same cells, row for row (new columns are allowed).
//!
//! The sampling methods are not recorded: their results may move with the
//! random streams, within their standard errors (their checks are in
//! `reliability_gantry.rs`, `reliability_cli.rs` and `path.rs`).

mod common;

use std::path::Path;

use common::cli::{chain, success};
use serde_json::Value;

/// Commands whose outputs may only gain content.
fn additive(name: &str) -> bool {
    name.starts_with("reliability_") || name.starts_with("path_")
}

/// `recorded ⊆ new` as JSON documents; `Err` names the first difference.
fn contained(recorded: &Value, new: &Value, at: &str) -> Result<(), String> {
    match (recorded, new) {
        (Value::Object(a), Value::Object(b)) => {
            for (k, v) in a {
                let w = b.get(k).ok_or_else(|| format!("{at}.{k}: missing"))?;
                contained(v, w, &format!("{at}.{k}"))?;
            }
            Ok(())
        }
        (Value::Array(a), Value::Array(b)) => {
            if a.len() != b.len() {
                return Err(format!("{at}: {} elements, now {}", a.len(), b.len()));
            }
            for (i, (v, w)) in a.iter().zip(b).enumerate() {
                contained(v, w, &format!("{at}[{i}]"))?;
            }
            Ok(())
        }
        (a, b) if a == b => Ok(()),
        (a, b) => Err(format!("{at}: {a}, now {b}")),
    }
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

/// Every line of `recorded`, in order, among the lines of `new`.
fn lines_contained(recorded: &str, new: &str) -> Result<(), String> {
    let mut new_lines = new.lines();
    for (i, line) in recorded.lines().enumerate() {
        if !new_lines.any(|l| l == line) {
            return Err(format!("line {}: {line:?} is missing", i + 1));
        }
    }
    Ok(())
}

/// Every recorded CSV column, with the same cells, in `new`.
fn columns_contained(recorded: &str, new: &str) -> Result<(), String> {
    let split = |text: &str| -> Vec<Vec<String>> {
        text.lines()
            .map(|l| l.split(',').map(str::to_string).collect())
            .collect()
    };
    let (a, b) = (split(recorded), split(new));
    if a.len() != b.len() {
        return Err(format!("{} rows, now {}", a.len(), b.len()));
    }
    for (c, name) in a[0].iter().enumerate() {
        let d = b[0]
            .iter()
            .position(|n| n == name)
            .ok_or_else(|| format!("column {name} is missing"))?;
        for (r, (ra, rb)) in a.iter().zip(&b).enumerate().skip(1) {
            if ra.get(c) != rb.get(d) {
                return Err(format!(
                    "row {r}, column {name}: {:?}, now {:?}",
                    ra.get(c),
                    rb.get(d)
                ));
            }
        }
    }
    Ok(())
}

#[test]
fn outputs_match_those_recorded_before_the_architecture_change() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden");
    let list = std::fs::read_to_string(dir.join("commands.txt")).unwrap();
    let mut failures = Vec::new();
    let mut count = 0;
    for line in list
        .lines()
        .filter(|l| !l.starts_with('#') && !l.is_empty())
    {
        let (name, args) = line.split_once('\t').expect("NAME<TAB>ARGS");
        let args: Vec<&str> = args.split(' ').collect();
        let recorded = std::fs::read_to_string(dir.join(name)).unwrap();
        let new = String::from_utf8(success(chain(&args)).stdout).unwrap();
        count += 1;
        let verdict = if !additive(name) {
            identical(&recorded, &new)
        } else if name.ends_with(".json") {
            let a: Value = serde_json::from_str(&recorded).unwrap();
            let b: Value = serde_json::from_str(&new)
                .map_err(|e| e.to_string())
                .unwrap();
            contained(&a, &b, "$")
        } else if name.ends_with(".csv") {
            columns_contained(&recorded, &new)
        } else {
            lines_contained(&recorded, &new)
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
    let a: Value = serde_json::json!({"r": [{"pf": 0.1}], "m": "form"});
    let more: Value = serde_json::json!({"r": [{"pf": 0.1, "calls": 2}], "m": "form"});
    let other: Value = serde_json::json!({"r": [{"pf": 0.10000000001}], "m": "form"});
    assert!(contained(&a, &more, "$").is_ok());
    assert!(contained(&more, &a, "$").is_err());
    assert!(contained(&a, &other, "$").is_err());
    assert!(identical("a\nb\n", "a\nb\n").is_ok());
    assert!(identical("a\nb\n", "a\nb \n").is_err());
    assert!(lines_contained("a\nc\n", "a\nb\nc\n").is_ok());
    assert!(lines_contained("c\na\n", "a\nb\nc\n").is_err());
    assert!(columns_contained("x,y\n1,2\n", "x,z,y\n1,0,2\n").is_ok());
    assert!(columns_contained("x,y\n1,2\n", "x,y\n1,3\n").is_err());
}
