//! Bounded reads: a device or a FIFO given as an input
//! file is refused, with the file's name and its bound, after at
//! most the bound's bytes were read (`chain_core::bounded`).

use std::process::Command;

const HEAD_HEAD: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/examples/machines/head_head_bc.yaml"
);
const GANTRY: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/examples/machines/gantry_grinder.yaml"
);

/// Runs the binary; returns its stderr after checking a non-zero exit (1:
/// an input refused, not a panic). `/dev/zero` never ends, so a refusal at
/// all shows the read stopped at its bound.
fn refused(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_chain"))
        .args(args)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1), "{args:?}: {out:?}");
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
    let err = flat(&refused(&["inverse", HEAD_HEAD, "--pose", "/dev/zero"]));
    assert!(
        err.contains("/dev/zero: the file is too large (more than 256 MiB = 268435456 bytes)"),
        "{err}"
    );
    assert!(err.contains("chain::too_large"), "{err}");
}

#[test]
fn path_axes_from_dev_zero_is_refused_at_its_bound() {
    let err = flat(&refused(&["path", GANTRY, "--axes", "/dev/zero"]));
    assert!(
        err.contains("/dev/zero: the file is too large (more than 256 MiB = 268435456 bytes)"),
        "{err}"
    );
}

#[test]
fn compensate_from_dev_zero_is_refused_at_its_bound() {
    let err = flat(&refused(&["compensate", "/dev/zero", "--length", "500"]));
    assert!(
        err.contains("/dev/zero: the file is too large (more than 16 MiB = 16777216 bytes)"),
        "{err}"
    );
    assert!(err.contains("chain::too_large"), "{err}");
}

#[test]
fn a_machine_file_from_dev_zero_is_refused_at_its_bound() {
    let err = flat(&refused(&["derive", "/dev/zero"]));
    assert!(
        err.contains("the file is too large (more than 16 MiB = 16777216 bytes)"),
        "{err}"
    );
}

/// Feeds a FIFO to `chain compensate` and counts what it accepted: the
/// reader takes at most its bound plus one byte, so what was written is at
/// most that plus what the pipe holds unread, never the whole stream.
#[test]
fn a_fifo_is_read_no_further_than_its_bound() {
    use std::io::Write;
    const BOUND: usize = 16 << 20;
    let dir = std::env::temp_dir().join(format!("chain-fifo-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let fifo = dir.join("runs.csv");
    let _ = std::fs::remove_file(&fifo);
    let path = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
    // SAFETY: a valid NUL-terminated path.
    assert_eq!(unsafe { libc::mkfifo(path.as_ptr(), 0o600) }, 0);
    let child = Command::new(env!("CARGO_BIN_EXE_chain"))
        .args(["compensate", fifo.to_str().unwrap(), "--length", "500"])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // Opened for writing once the child opened it for reading (blocking).
    let mut pipe = std::fs::OpenOptions::new().write(true).open(&fifo).unwrap();
    let chunk = vec![b'1'; 1 << 16];
    let mut written = 0usize;
    while written < 4 * BOUND {
        match pipe.write(&chunk) {
            Ok(n) => written += n,
            Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => break,
            Err(e) => panic!("{e}"),
        }
    }
    drop(pipe);
    let out = child.wait_with_output().unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(out.status.code(), Some(1), "{out:?}");
    let err = flat(&String::from_utf8_lossy(&out.stderr));
    assert!(
        err.contains("the file is too large (more than 16 MiB"),
        "{err}"
    );
    // Linux pipes hold at most /proc/sys/fs/pipe-max-size (1 MiB) unread.
    assert!(
        written > BOUND && written <= BOUND + 1 + (1 << 20),
        "{written} bytes written against a bound of {BOUND}"
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
