//! Output errors: a closed pipe ends every command
//! quietly (no panic, no message), a full device is a clear message and
//! exit 1. Every subcommand that writes a result to stdout: derive,
//! reliability, sensitivity, allocate, inverse, path, map, compensate,
//! export, identify, plan, sobol, motion.

use std::io::Read;
use std::process::{Command, Stdio};

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

fn commands() -> Vec<Vec<String>> {
    let m = |f: &str| format!("{ROOT}/examples/{f}");
    let s = |v: &[&str]| v.iter().map(|x| x.to_string()).collect::<Vec<_>>();
    vec![
        s(&["derive", &m("machines/gantry_grinder.yaml")]),
        s(&["reliability", &m("machines/gantry_grinder.yaml")]),
        s(&[
            "sensitivity",
            &m("machines/gantry_grinder.yaml"),
            "--kind",
            "geometric",
        ]),
        s(&[
            "path",
            &m("machines/gantry_grinder.yaml"),
            "--axes",
            &m("paths/gantry_path.csv"),
        ]),
        s(&[
            "compensate",
            &m("data/swing_htm50200.csv"),
            "--length",
            "577.11",
        ]),
        s(&[
            "compensate",
            &m("data/swing_htm50200.csv"),
            "--length",
            "577.11",
            "--format",
            "json",
        ]),
        s(&["allocate", &m("machines/gantry_grinder.yaml")]),
        s(&[
            "inverse",
            &m("machines/cnc5_bevel.yaml"),
            "--pose",
            &m("paths/cnc5_bevel_pose.csv"),
        ]),
        s(&[
            "map",
            &m("machines/vmc3.yaml"),
            "--values",
            &m("values/vmc3.yaml"),
        ]),
        s(&[
            "export",
            &m("machines/vmc3.yaml"),
            "--values",
            &m("values/vmc3.yaml"),
            "--controller",
            "grid",
        ]),
        s(&[
            "sobol",
            &m("machines/gantry_grinder.yaml"),
            "--at",
            "x=500,y=1500,z=600",
            "--samples",
            "2000",
        ]),
        s(&[
            "motion",
            &m("machines/cnc5_bevel.yaml"),
            "--settings",
            &m("settings/seed002_concave.yaml"),
            "--samples",
            "5",
        ]),
        s(&[
            "identify",
            &m("measurements/vmc3_probe.yaml"),
            "--measurements",
            &m("measurements/ballplate.csv"),
        ]),
        s(&[
            "plan",
            &m("measurements/vmc3_probe.yaml"),
            "--candidates",
            &m("measurements/candidates.csv"),
            "--count",
            "40",
        ]),
    ]
}

#[test]
fn a_closed_pipe_ends_quietly() {
    for args in commands() {
        let mut child = Command::new(env!("CARGO_BIN_EXE_chain"))
            .args(&args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let mut stdout = child.stdout.take().unwrap();
        let mut one = [0u8; 1];
        stdout
            .read_exact(&mut one)
            .unwrap_or_else(|e| panic!("{args:?}: no output ({e})"));
        drop(stdout);
        let out = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_ne!(out.status.code(), Some(101), "{args:?} panicked: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        assert!(!err.contains("cannot write"), "{args:?}: not quiet: {err}");
    }
}

#[test]
fn a_full_device_is_a_clear_error() {
    if !std::path::Path::new("/dev/full").exists() {
        return;
    }
    for args in commands() {
        let full = std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap();
        let out = Command::new(env!("CARGO_BIN_EXE_chain"))
            .args(&args)
            .stdout(full)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        assert!(!err.trim().is_empty(), "{args:?}: no message");
    }
}
