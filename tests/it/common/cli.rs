//! Running the `chain` binary from the integration tests, and the scratch
//! files they hand it.
//!
//! Every run has the package root as its working directory and `NO_COLOR=1`,
//! so that what a test reads on stdout and stderr depends neither on where the
//! tests were started nor on the terminal.

// Each test binary uses only some of these helpers.
#![allow(dead_code)]

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

use serde_json::Value;

/// `chain args`, not yet run.
fn command(args: &[&str]) -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_chain"));
    command
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env("NO_COLOR", "1");
    command
}

/// Runs `chain args` and returns its exit status, stdout and stderr.
pub fn chain(args: &[&str]) -> Output {
    command(args).output().expect("run chain")
}

/// Runs `chain args` with its output thrown away and returns its exit code
/// and peak resident memory in bytes (its own `ru_maxrss`, from `wait4`).
// The child is reaped by wait4 below, which std's `Child::wait` cannot
// replace: it does not return the rusage.
#[allow(clippy::zombie_processes)]
pub fn peak_memory(args: &[&str]) -> (i32, u64) {
    let child = command(args)
        .stdout(Stdio::null())
        .stderr(Stdio::inherit())
        .spawn()
        .expect("run chain");
    let pid = child.id() as libc::pid_t;
    let mut status = 0;
    // SAFETY: an all-zero `rusage` is a valid value for wait4 to fill.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: `pid` is our own child, not yet waited for; both pointers
    // are to live locals.
    let waited = unsafe { libc::wait4(pid, &mut status, 0, &mut usage) };
    assert_eq!(waited, pid, "wait4 on chain");
    let code = if libc::WIFEXITED(status) {
        libc::WEXITSTATUS(status)
    } else {
        -1
    };
    // Linux reports ru_maxrss in kilobytes.
    (code, usage.ru_maxrss as u64 * 1024)
}

/// Runs `chain args` with `input` on its stdin.
pub fn chain_stdin(args: &[&str], input: &[u8]) -> Output {
    let mut child = command(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run chain");
    child
        .stdin
        .take()
        .expect("chain's stdin")
        .write_all(input)
        .expect("write chain's stdin");
    child.wait_with_output().expect("run chain")
}

/// Asserts that `out` is a successful run, showing its stderr if it is not.
#[track_caller]
pub fn success(out: Output) -> Output {
    assert!(
        out.status.success(),
        "chain failed ({}):\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// Asserts that `out` is a successful run and parses its stdout, which must
/// be one JSON document and nothing else.
#[track_caller]
pub fn success_json(out: Output) -> Value {
    serde_json::from_slice(&success(out).stdout).expect("stdout is one JSON document")
}

/// Runs `chain args`, which must succeed.
#[track_caller]
pub fn ok(args: &[&str]) -> Output {
    success(chain(args))
}

/// Runs `chain args`, which must succeed; returns stdout as text.
#[track_caller]
pub fn ok_stdout(args: &[&str]) -> String {
    String::from_utf8(ok(args).stdout).expect("stdout is UTF-8")
}

/// Runs `chain args`, which must succeed printing one JSON document on
/// stdout; returns the document.
#[track_caller]
pub fn ok_json(args: &[&str]) -> Value {
    success_json(chain(args))
}

/// Runs `chain args`, which must fail cleanly: non-zero exit, nothing on
/// stdout, no panic. Returns stderr.
#[track_caller]
pub fn fails(args: &[&str]) -> String {
    let out = chain(args);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(
        !out.status.success(),
        "{args:?} succeeded ({}):\n{err}",
        out.status
    );
    assert!(
        out.stdout.is_empty(),
        "{args:?} wrote to stdout:\n{}",
        String::from_utf8_lossy(&out.stdout)
    );
    assert!(!err.contains("panicked"), "{args:?} panicked:\n{err}");
    err
}

/// `stderr` with miette's frame (`│`) and the line breaks of its wrapping
/// removed, runs of white space made one space: what a test looks for cannot
/// be split by where the message wraps, which moves with the length of the
/// paths in it.
pub fn unwrapped(stderr: &str) -> String {
    stderr
        .replace('│', " ")
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
}

/// A fresh, empty scratch directory unique to this process, the calling test
/// module (its file's stem: the modules of `tests/it/`
/// share one process) and `name` (whatever an earlier run left there is
/// removed first).
#[track_caller]
pub fn scratch(name: &str) -> PathBuf {
    let module = Path::new(std::panic::Location::caller().file())
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let dir = std::env::temp_dir().join(format!("chain-{}-{module}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

/// Writes `text` to `dir/name`; returns the path.
pub fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).expect("write scratch file");
    path
}

/// Writes `text` to a file `name` in a fresh scratch directory of its own
/// ([`scratch`]`(name)`, unique to the calling module); returns the path.
#[track_caller]
pub fn scratch_file(name: &str, text: &str) -> PathBuf {
    write(&scratch(name), name, text)
}
