//! Options checked by the parser, with their name in the message, before any
//! file is read.

use std::process::Command;

fn refused(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_chain"))
        .args(args)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2), "{args:?}: {out:?}");
    String::from_utf8_lossy(&out.stderr).into_owned()
}

const GANTRY: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/examples/machines/gantry_grinder.yaml"
);

#[test]
fn allocate_threshold_is_a_fraction() {
    for v in ["nan", "2", "inf", "-0.1", "x"] {
        let err = refused(&["allocate", GANTRY, "--strategy", "paper", "--threshold", v]);
        assert!(err.contains("--threshold"), "{v}: {err}");
    }
}

#[test]
fn a_coordinate_given_twice_in_at_is_refused() {
    let err = refused(&["sensitivity", GANTRY, "--at", "x=0,y=0,z=0,x=1000"]);
    assert!(
        err.contains("--at") && err.contains("`x` is given twice"),
        "{err}"
    );
}
