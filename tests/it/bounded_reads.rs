//! Bounded reads (issue 18, point 2): a device or a FIFO given as an input
//! file is refused quickly, with the file's name and its bound, after at
//! most the bound's bytes were read (`chain_core::bounded`).

use std::process::Command;
use std::time::{Duration, Instant};

const HEAD_HEAD: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/examples/machines/head_head_bc.yaml"
);
const GANTRY: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/examples/machines/gantry_grinder.yaml"
);

/// Runs the binary; returns its stderr after checking a non-zero exit (1:
/// an input refused, not a panic) within `seconds`.
fn refused_within(args: &[&str], seconds: u64) -> String {
    let start = Instant::now();
    let out = Command::new(env!("CARGO_BIN_EXE_chain"))
        .args(args)
        .output()
        .unwrap();
    let took = start.elapsed();
    assert_eq!(out.status.code(), Some(1), "{args:?}: {out:?}");
    assert!(
        took < Duration::from_secs(seconds),
        "{args:?} took {took:?}"
    );
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn flat(s: &str) -> String {
    s.split_whitespace()
        .filter(|w| *w != "│")
        .collect::<Vec<_>>()
        .join(" ")
}

#[test]
fn inverse_pose_from_dev_zero_is_refused_at_its_bound() {
    let err = flat(&refused_within(
        &["inverse", HEAD_HEAD, "--pose", "/dev/zero"],
        20,
    ));
    assert!(
        err.contains("/dev/zero: the file is too large (more than 256 MiB = 268435456 bytes)"),
        "{err}"
    );
    assert!(err.contains("chain::too_large"), "{err}");
}

#[test]
fn path_axes_from_dev_zero_is_refused_at_its_bound() {
    let err = flat(&refused_within(
        &["path", GANTRY, "--axes", "/dev/zero"],
        20,
    ));
    assert!(
        err.contains("/dev/zero: the file is too large (more than 256 MiB = 268435456 bytes)"),
        "{err}"
    );
}

#[test]
fn compensate_from_dev_zero_is_refused_at_its_bound() {
    let err = flat(&refused_within(
        &["compensate", "/dev/zero", "--length", "500"],
        10,
    ));
    assert!(
        err.contains("/dev/zero: the file is too large (more than 16 MiB = 16777216 bytes)"),
        "{err}"
    );
    assert!(err.contains("chain::too_large"), "{err}");
}

#[test]
fn a_machine_file_from_dev_zero_is_refused_at_its_bound() {
    let err = flat(&refused_within(&["derive", "/dev/zero"], 10));
    assert!(
        err.contains("the file is too large (more than 16 MiB = 16777216 bytes)"),
        "{err}"
    );
}

#[test]
fn the_bound_is_exact() {
    use chain::core::bounded::{read_from, ReadError};
    let limit = 1000;
    let at = vec![b'a'; limit];
    assert_eq!(read_from(&at[..], limit).unwrap(), at);
    let over = vec![b'a'; limit + 1];
    assert!(matches!(
        read_from(&over[..], limit),
        Err(ReadError::TooLarge { limit: 1000 })
    ));
}

/// The machine file is read once: `load_file_with_text` gives the machine
/// `load_file` gives and the file's text for the messages that quote it
/// (the CLI's `Loaded`); a file that cannot be read is the same diagnostic.
#[test]
fn a_machine_file_is_read_once_with_its_text() {
    let path = std::path::Path::new(GANTRY);
    let (machine, text) = chain_core::load_file_with_text(path).unwrap();
    assert_eq!(machine, chain_core::load_file(path).unwrap());
    assert_eq!(text, std::fs::read_to_string(path).unwrap());
    let missing = std::path::Path::new("/nonexistent/m.yaml");
    assert_eq!(
        chain_core::load_file_with_text(missing)
            .unwrap_err()
            .to_string(),
        chain_core::load_file(missing).unwrap_err().to_string()
    );
}
