//! A machine file written as one line of JSON (which YAML accepts) whose
//! located error sits past column 65,535: the diagnostic renderer cuts the
//! snippet to a window around the located key, because rendering a line
//! that wide whole panics ("Formatting argument out of range", exit 101).

use std::process::Command;

fn chain_derive(text: &str, name: &str) -> (i32, String) {
    let dir = std::env::temp_dir().join(format!("chain-wide-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join(format!("{name}.yaml"));
    std::fs::write(&file, text).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_chain"))
        .arg("derive")
        .arg(&file)
        .output()
        .unwrap();
    std::fs::remove_dir_all(&dir).ok();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// One line: a 70,000-character description, then a body with `extra`.
fn one_line(extra: &str) -> String {
    format!(
        r#"{{"machine": "m", "description": "{}", "bodies": {{"bed": {{}}, "s": {{"parent": "bed", "joint": {{"type": "prismatic", "axis": "+x", "variable": "x"}}{extra}}}}}, "workpiece": "bed", "tool": "s", "tool_point": [0, 0, 0]}}"#,
        "x".repeat(70_000)
    )
}

#[test]
fn an_error_far_along_one_line_is_rendered_with_a_cut_snippet() {
    let (code, err) = chain_derive(&one_line(r#", "bogus_key": 1"#), "key");
    assert_eq!(code, 1, "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(err.contains("unknown key `bogus_key`"), "{err}");
    // The message keeps the true column; the snippet shows the key, not
    // 70,000 characters of the line.
    let text = one_line(r#", "bogus_key": 1"#);
    let column = text.find(r#""bogus_key""#).unwrap();
    assert!(
        err.contains(&format!(":1:{}", column + 1)) || err.contains(&format!(":1:{}", column + 2)),
        "{column}: {err}"
    );
    assert!(
        err.lines()
            .any(|l| l.contains("bogus_key") && l.len() < 2000),
        "{err}"
    );
    assert!(err.len() < 20_000, "{} bytes", err.len());
}

#[test]
fn a_wide_located_value_is_rendered_without_a_panic() {
    // The located span itself is wider than the renderer's limit.
    let bad = format!(r#", "errors": {{"dx": "{} !"}}"#, "y".repeat(70_000));
    let (code, err) = chain_derive(&one_line(&bad), "value");
    assert_eq!(code, 1, "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(err.contains("dx"), "{err}");
    // The snippet's lines are cut (the message itself may quote the value).
    assert!(err
        .lines()
        .filter(|l| l.contains('│') || l.contains('·'))
        .all(|l| l.len() < 20_000));
}
