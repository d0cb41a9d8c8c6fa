//! Atomic file writes: every file is written to a
//! temporary file beside it and renamed into place, so a failed write leaves
//! no partial file (`src/cli/atomic.rs`).

use std::path::{Path, PathBuf};
use std::process::Command;

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("chain-atomic-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    v.sort();
    v
}

fn compensate(table_out: &Path) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_chain"))
        .args([
            "compensate",
            &format!("{ROOT}/examples/data/swing_htm50200.csv"),
            "--length",
            "577.11",
            "--table-out",
        ])
        .arg(table_out)
        .output()
        .unwrap()
}

#[test]
fn a_table_whose_name_is_a_directory_is_refused_and_leaves_nothing() {
    let dir = scratch("blocked");
    let blocked = dir.join("table.csv");
    std::fs::create_dir(&blocked).unwrap();
    let out = compensate(&blocked);
    assert_eq!(out.status.code(), Some(1), "{out:?}");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("table.csv") && err.contains("cannot write"),
        "{err}"
    );
    // Only the directory that was in the way: no temporary file left.
    assert_eq!(names(&dir), ["table.csv"]);
    assert!(blocked.is_dir());
}

#[test]
fn a_normal_write_is_whole_and_replaces_the_old_file() {
    let dir = scratch("normal");
    let target = dir.join("table.csv");
    std::fs::write(&target, "old content that is longer than nothing\n").unwrap();
    let out = compensate(&target);
    assert!(out.status.success(), "{out:?}");
    let first = std::fs::read(&target).unwrap();
    assert!(first.starts_with(b"theta_deg,delta_theta_deg,"));
    assert!(!String::from_utf8_lossy(&first).contains("old content"));
    // The same run writes the same bytes, and nothing else is left.
    let out = compensate(&target);
    assert!(out.status.success(), "{out:?}");
    assert_eq!(std::fs::read(&target).unwrap(), first);
    assert_eq!(names(&dir), ["table.csv"]);
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(&target).unwrap().permissions().mode();
        assert_ne!(
            mode & 0o044,
            0,
            "readable by others as a created file is: {mode:o}"
        );
    }
}

#[test]
fn plots_where_a_file_is_in_the_way_fail_clearly() {
    // `--plot` creates its directory; a plain file in its place is refused.
    let dir = scratch("plots");
    let file = dir.join("plots");
    std::fs::write(&file, "x").unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_chain"))
        .args([
            "compensate",
            &format!("{ROOT}/examples/data/swing_htm50200.csv"),
            "--length",
            "577.11",
            "--plot",
        ])
        .arg(&file)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1), "{out:?}");
    assert_eq!(names(&dir), ["plots"]);
    assert_eq!(std::fs::read(&file).unwrap(), b"x");
}
