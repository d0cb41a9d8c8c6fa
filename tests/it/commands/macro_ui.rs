//! Compile-fail cases of `chain::machine!`, run by trybuild in a generated
//! crate outside the workspace that depends on `chain` alone. Each `.stderr`
//! pins the message: the inline form points at the offending token with the
//! YAML loader's wording; the file form names the file, line and key.
//!
//! The compile-pass cases (`tests/ui/pass_*.rs`) are compiled into this
//! binary and run as tests below: with no pass case, trybuild only checks
//! (`cargo check`, no code generated for its crate's dependencies), which
//! halves this test's time (docs/performance.md, "Build and test times").
//! `downstream` compiles `pass_downstream.rs` again as a crate of its own on
//! `chain` without default features.

#[path = "../../ui/pass_downstream.rs"]
mod pass_downstream;
#[path = "../../ui/pass_function_slots.rs"]
mod pass_function_slots;

/// `tests/ui/pass_downstream.rs`: `machine!` inline and from a file, FORM on
/// the generated model.
#[test]
fn pass_downstream() {
    pass_downstream::main();
}

/// `tests/ui/pass_function_slots.rs`: function slots and `errors: iso` in
/// both forms of `machine!`.
#[test]
fn pass_function_slots() {
    pass_function_slots::main();
}

#[test]
fn machine_macro_ui() {
    // The generated crate lives under target/; file-form paths resolve against
    // this package instead (see `CHAIN_MACRO_MANIFEST_DIR` in docs/macro.md).
    std::env::set_var("CHAIN_MACRO_MANIFEST_DIR", env!("CARGO_MANIFEST_DIR"));
    // trybuild checks its crate in the dev profile, whose build scripts and
    // proc macros (chain-macro and chain-core with it) carry full debug info
    // by default; none is needed (docs/performance.md, "Build and test
    // times"). The variable reaches the cargo that trybuild starts; a
    // caller's own setting is kept.
    if std::env::var_os("CARGO_PROFILE_DEV_DEBUG").is_none() {
        std::env::set_var("CARGO_PROFILE_DEV_DEBUG", "0");
    }
    let t = trybuild::TestCases::new();
    t.compile_fail("tests/ui/unknown_key.rs");
    t.compile_fail("tests/ui/unknown_axis.rs");
    t.compile_fail("tests/ui/cycle.rs");
    t.compile_fail("tests/ui/two_roots.rs");
    t.compile_fail("tests/ui/duplicate_variable.rs");
    t.compile_fail("tests/ui/unknown_parent.rs");
    t.compile_fail("tests/ui/bad_expression.rs");
    t.compile_fail("tests/ui/missing_tool.rs");
    t.compile_fail("tests/ui/missing_workpiece.rs");
    t.compile_fail("tests/ui/bad_frame.rs");
    t.compile_fail("tests/ui/file_not_found.rs");
    t.compile_fail("tests/ui/bad_yaml_in_file.rs");
    t.compile_fail("tests/ui/bad_key_in_file.rs");
    t.compile_fail("tests/ui/negative_std.rs");
    t.compile_fail("tests/ui/syntax.rs");
    // Function slots and `errors: iso` (measured-machines spec, section 1).
    t.compile_fail("tests/ui/fourier_on_prismatic.rs");
    t.compile_fail("tests/ui/legendre_without_range.rs");
    t.compile_fail("tests/ui/degree_above_12.rs");
    t.compile_fail("tests/ui/coefficient_clash.rs");
    t.compile_fail("tests/ui/iso_without_joint.rs");
    t.compile_fail("tests/ui/function_slot_in_file.rs");
}
