//! Compile-fail (and one compile-pass) cases of `chain::machine!`, run by
//! trybuild in a generated crate outside the workspace that depends on `chain`
//! alone. Each `.stderr` pins the message: the inline form points at the
//! offending token with the YAML loader's wording; the file form names the
//! file, line and key.

#[test]
fn machine_macro_ui() {
    // The generated crate lives under target/; file-form paths resolve against
    // this package instead (see `CHAIN_MACRO_MANIFEST_DIR` in docs/macro.md).
    std::env::set_var("CHAIN_MACRO_MANIFEST_DIR", env!("CARGO_MANIFEST_DIR"));
    let t = trybuild::TestCases::new();
    t.pass("tests/ui/pass_downstream.rs");
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
    t.pass("tests/ui/pass_function_slots.rs");
    t.compile_fail("tests/ui/fourier_on_prismatic.rs");
    t.compile_fail("tests/ui/legendre_without_range.rs");
    t.compile_fail("tests/ui/degree_above_12.rs");
    t.compile_fail("tests/ui/coefficient_clash.rs");
    t.compile_fail("tests/ui/iso_without_joint.rs");
    t.compile_fail("tests/ui/function_slot_in_file.rs");
}
