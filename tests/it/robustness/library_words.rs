//! The libraries speak in their own terms: no source line of `chain-core`
//! or `reliability` outside a comment names a command-line option
//! (`--values`, `--fix`, ...). Options are the CLI's words, put on the
//! libraries' typed errors by `chain::ops` (issue 49: one rule in one
//! place; docs/python.md: Python raises the same words through ops).

use std::path::{Path, PathBuf};

/// Every `.rs` file under `dir`.
fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            sources(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The option a line names outside its comment, if any: `--` followed by
/// two lowercase letters.
fn option_in(line: &str) -> Option<&str> {
    let code = match line.find("//") {
        Some(at) => &line[..at],
        None => line,
    };
    let at = code.find("--")?;
    let rest = &code[at + 2..];
    let word = rest
        .split(|c: char| !(c.is_ascii_lowercase() || c == '-'))
        .next()
        .unwrap_or("");
    (word.len() >= 2).then_some(&code[at..at + 2 + word.len()])
}

#[test]
fn no_library_source_names_an_option() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    for dir in ["chain-core/src", "reliability/src"] {
        sources(&root.join(dir), &mut files);
    }
    assert!(files.len() > 50, "{} files", files.len());
    let mut found = Vec::new();
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        for (i, line) in text.lines().enumerate() {
            if let Some(option) = option_in(line) {
                found.push(format!("{}:{}: {option}", f.display(), i + 1));
            }
        }
    }
    assert!(found.is_empty(), "{found:#?}");
}

#[test]
fn the_check_sees_an_option_and_skips_comments() {
    assert_eq!(option_in(r#"    "use --values here""#), Some("--values"));
    assert_eq!(option_in("    // see --values"), None);
    assert_eq!(option_in("    let a = b--c;"), None);
    assert_eq!(
        option_in(r#"    format!("{x} --rank-tol")"#),
        Some("--rank-tol")
    );
}
