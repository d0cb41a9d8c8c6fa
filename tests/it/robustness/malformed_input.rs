//! Malformed machine files: every rule of the machine-file contract gives one
//! located diagnostic naming the file, line, column and key; nothing panics,
//! nothing hangs. The last tests run the `chain` binary on files under
//! `tests/data/malformed/`.

use crate::common;

use std::path::Path;

use chain_core::diagnostic::Problem;
use chain_core::model::{Distribution, ErrorKind, Frame, JointKind, Sided};
use chain_core::{load_bytes, load_file, load_str, Diagnostics};
use common::cli::fails;
use common::example_file;

/// Loads `text` as `bad.yaml` and returns the diagnostics.
fn diagnose(text: &str) -> Diagnostics {
    match load_str(text, "bad.yaml") {
        Ok(m) => panic!("expected an error, loaded {:?}", m.name),
        Err(d) => d,
    }
}

/// Asserts exactly one error, at `line:column`, naming `key` and containing
/// `needle`; returns the message.
#[track_caller]
fn one(text: &str, line: usize, column: usize, key: &str, needle: &str) -> String {
    let d = diagnose(text);
    let msg = d.to_string();
    assert_eq!(d.len(), 1, "expected one error, got:\n{d:#}");
    let prefix = format!("bad.yaml:{line}:{column}: ");
    assert!(msg.starts_with(&prefix), "expected {prefix:?}, got:\n{msg}");
    if !key.is_empty() {
        assert!(
            msg.contains(&format!("at key `{key}`")),
            "expected key `{key}`, got:\n{msg}"
        );
    }
    assert!(msg.contains(needle), "expected {needle:?} in:\n{msg}");
    msg
}

/// A valid machine, lines numbered for the tests that patch it.
const BASE: &str = "\
machine: m
bodies:
  bed: {}
  x_slide:
    parent: bed
    joint: {type: prismatic, axis: +x, variable: x}
    errors: {dx: dxx, ey: eyx}
workpiece: bed
tool: x_slide
";

/// `BASE` plus more top-level text.
fn base_with(extra: &str) -> String {
    format!("{BASE}{extra}")
}

// ---------------------------------------------------------------- valid files

#[test]
fn base_machine_loads() {
    let m = load_str(BASE, "base.yaml").unwrap();
    assert_eq!(m.name, "m");
    assert_eq!(m.file.as_deref(), Some("base.yaml"));
    assert_eq!(m.bodies.len(), 2);
    assert_eq!(m.bodies[1].parent, Some(0));
    assert_eq!(m.variables[0].name, "x");
    assert_eq!(m.variables[0].kind, JointKind::Prismatic);
    assert_eq!(m.variables[0].origin.line, 6);
    assert_eq!(m.variables[0].origin.key, "bodies.x_slide.joint.variable");
    let errors: Vec<_> = m.errors.iter().map(|e| (e.name.as_str(), e.kind)).collect();
    assert_eq!(
        errors,
        [("dxx", ErrorKind::Linear), ("eyx", ErrorKind::Angular)]
    );
    assert_eq!(m.workpiece, 0);
    assert_eq!(m.tool, 1);
    assert_eq!(m.frame, Frame::Workpiece);
    assert!(m.tool_point.iter().all(|e| e.is_zero()));
    assert!(m.statistics.is_empty());
    assert!(m.reliability.is_none());
}

#[test]
fn small_machine_fields() {
    let text = "\
machine: spindle
description: a test
parameters: {L: 250, h: null}
bodies:
  tool_body:
    parent: c_axis
    offset: [0, 0, -L]
  bed: {}
  c_axis:
    parent: bed
    offset: [0, 0, h + 10]
    rotation: [{about: x, angle: 90deg}]
    joint: {type: rotary, axis: -z, variable: C}
    location_errors: {ex: a_c, dx: x_c}
    errors: {ez: ezc}
    squareness: {ex: a_c}
workpiece: bed
tool: tool_body
tool_point: [0, 0, L/2]
frame: tool
statistics:
  ezc: {dist: uniform, min: -0.001, max: 0.001}
  a_c: {tolerance: 0.06/1000, sigma_rule: 3, cost_weight: 2, min_std: 1e-6}
  x_c: {mean: 0.001, std: 0.002}
reliability:
  tolerance: {px: 0.03, oz: 0.001}
  sided: two
  grid: {C: [0, pi/2]}
  requirement: {min: 0.9, mean: 0.95}
";
    let m = load_str(text, "spindle.yaml").unwrap();
    assert_eq!(m.description.as_deref(), Some("a test"));
    // Pre-order from the root, children in file order.
    let bodies: Vec<_> = m.bodies.iter().map(|b| b.name.as_str()).collect();
    assert_eq!(bodies, ["bed", "c_axis", "tool_body"]);
    assert_eq!(m.bodies[2].parent, Some(1));
    assert_eq!(m.tool, 2);
    assert_eq!(m.parameters[0].value, Some(250.0));
    assert_eq!(m.parameters[1].value, None);
    assert_eq!(m.bodies[1].offset[2].eval(&[0.0, 5.0]), 15.0);
    assert_eq!(m.bodies[2].offset[2].eval(&[250.0, 0.0]), -250.0);
    assert!((m.bodies[1].rotation[0].angle - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
    let joint = m.bodies[1].joint.as_ref().unwrap();
    assert_eq!(
        (joint.kind, joint.axis.to_string()),
        (JointKind::Rotary, "-z".into())
    );
    // location_errors (dx..ez), then errors, then squareness.
    let errors: Vec<_> = m.errors.iter().map(|e| e.name.as_str()).collect();
    assert_eq!(errors, ["x_c", "a_c", "ezc"]);
    // An angle used as a location error and as squareness is squareness.
    assert_eq!(m.errors[1].kind, ErrorKind::Squareness);
    assert_eq!(m.bodies[1].location_errors.slots[0], vec![0]);
    assert_eq!(m.bodies[1].location_errors.slots[3], vec![1]);
    assert_eq!(m.bodies[1].errors.slots[3], vec![1]);
    assert_eq!(m.bodies[1].errors.slots[5], vec![2]);
    assert_eq!(m.tool_point[2].eval(&[250.0, 0.0]), 125.0);
    assert_eq!(m.frame, Frame::Tool);
    // Statistics in file order.
    assert_eq!(m.statistics[0].error, 2);
    assert_eq!(
        m.statistics[0].distribution,
        Distribution::Uniform {
            min: -0.001,
            max: 0.001
        }
    );
    assert_eq!(m.statistics[1].distribution.std(), 0.06 / 1000.0 / 3.0);
    assert_eq!(m.statistics[1].cost_weight, 2.0);
    assert_eq!(m.statistics[1].min_std, Some(1e-6));
    assert_eq!(m.statistics[2].distribution.mean(), 0.001);
    assert_eq!(m.statistics[2].cost_weight, 1.0);
    let r = m.reliability.unwrap();
    assert_eq!(r.sided, Sided::Two);
    assert_eq!(r.tolerance.len(), 2);
    assert_eq!(r.grid, vec![(0, vec![0.0, std::f64::consts::FRAC_PI_2])]);
    assert_eq!(r.requirement.unwrap().min, 0.9);
}

#[test]
fn example_machines_load() {
    for entry in std::fs::read_dir(example_file("machines")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "yaml") {
            load_file(&path).unwrap_or_else(|d| panic!("{d:#}"));
        }
    }
}

// ------------------------------------------------------------ file and syntax

#[test]
fn empty_file() {
    let msg = one("", 1, 1, "", "empty");
    assert!(msg.contains("`machine`"));
    one("# only a comment\n", 1, 1, "", "empty");
}

#[test]
fn binary_file() {
    let path = std::env::temp_dir().join(format!("chain-binary-{}.yaml", std::process::id()));
    std::fs::write(&path, b"machine: m\nbodies: \x00\x01\x02\x00").unwrap();
    let d = load_file(&path).unwrap_err();
    let _ = std::fs::remove_file(&path);
    let msg = d.to_string();
    assert!(msg.contains(&format!("{}:2:9:", path.display())), "{msg}");
    assert!(msg.contains("not a text file"), "{msg}");
}

#[test]
fn invalid_utf8() {
    let d = load_bytes(b"machine: m\xff\n", "latin.yaml").unwrap_err();
    let msg = d.to_string();
    assert!(msg.starts_with("latin.yaml:1:11: "), "{msg}");
    assert!(msg.contains("UTF-8"), "{msg}");
}

#[test]
fn missing_file() {
    let d = load_file(Path::new("/nonexistent/dir/machine.yaml")).unwrap_err();
    let msg = d.to_string();
    assert!(
        msg.starts_with("/nonexistent/dir/machine.yaml: cannot read"),
        "{msg}"
    );
}

#[test]
fn yaml_syntax_error() {
    let msg = one(
        "machine: m\nbodies:\n  bed: {parent: [a, b}\n",
        3,
        22,
        "bodies.bed.parent[2]",
        "YAML syntax error",
    );
    assert!(!msg.contains("panicked"));
}

#[test]
fn top_level_not_a_mapping() {
    one(
        "- machine\n- bodies\n",
        1,
        1,
        "",
        "top level must be a mapping, found a list",
    );
}

#[test]
fn two_documents() {
    one(
        &format!("{BASE}---\nmachine: n\n"),
        10,
        1,
        "",
        "more than one YAML document",
    );
}

#[test]
fn duplicate_key() {
    one(
        "machine: m\nbodies:\n  bed: {}\n  bed: {parent: bed}\n  x: {parent: bed}\nworkpiece: bed\ntool: x\n",
        4,
        3,
        "bodies.bed",
        "duplicate key `bed` (first given on line 3)",
    );
}

#[test]
fn alias_bomb_fails_fast() {
    let mut text =
        String::from("machine: m\nlol0: &a0 [lol, lol, lol, lol, lol, lol, lol, lol, lol]\n");
    for i in 1..30 {
        let p = i - 1;
        let refs = vec![format!("*a{p}"); 9].join(", ");
        text.push_str(&format!("lol{i}: &a{i} [{refs}]\n"));
    }
    // 9^30 nodes if expanded: the refusal at the node bound is what keeps
    // the parse finite.
    let d = diagnose(&text);
    let msg = d.to_string();
    assert!(
        msg.contains(&format!(
            "expands to more than {} YAML nodes",
            chain_core::yaml::MAX_NODES
        )),
        "{msg}"
    );
    assert!(msg.starts_with("bad.yaml:"), "{msg}");
}

#[test]
fn deep_nesting_fails_fast() {
    let text = format!("machine: {}\n", "[".repeat(200_000));
    let d = diagnose(&text);
    assert!(d.to_string().starts_with("bad.yaml:1:"), "{d}");
}

// ---------------------------------------------------------------- unknown keys

#[test]
fn unknown_top_level_key_suggests() {
    one(
        &base_with("framee: tool\n"),
        10,
        1,
        "framee",
        "(did you mean `frame`? expected one of machine,",
    );
}

#[test]
fn unknown_top_level_key_lists_valid_keys() {
    let msg = one(
        &base_with("colour: red\n"),
        10,
        1,
        "colour",
        "unknown key `colour`",
    );
    assert!(msg.contains("expected one of machine, description, parameters, bodies"));
}

#[test]
fn unknown_body_key() {
    one(
        "machine: m\nbodies:\n  bed: {}\n  a: {parnet: bed}\nworkpiece: bed\ntool: a\n",
        4,
        7,
        "bodies.a.parnet",
        "did you mean `parent`?",
    );
}

#[test]
fn unknown_joint_key() {
    one(
        &BASE.replace("axis: +x", "axes: +x"),
        6,
        30,
        "bodies.x_slide.joint.axes",
        "did you mean `axis`?",
    );
}

#[test]
fn unknown_rotation_key() {
    one(
        &BASE.replace(
            "    parent: bed\n",
            "    parent: bed\n    rotation: [{about: z, angel: 1}]\n",
        ),
        6,
        27,
        "bodies.x_slide.rotation[0].angel",
        "did you mean `angle`?",
    );
}

#[test]
fn unknown_error_slot() {
    one(
        &BASE.replace("ey: eyx", "ee: eyx"),
        7,
        23,
        "bodies.x_slide.errors.ee",
        "unknown key `ee`",
    );
}

#[test]
fn squareness_takes_angles_only() {
    let msg = one(
        &BASE.replace("    errors:", "    squareness: {dx: sxy}\n    errors:"),
        7,
        18,
        "bodies.x_slide.squareness.dx",
        "unknown key `dx`",
    );
    assert!(msg.contains("ex, ey, ez"), "{msg}");
}

#[test]
fn unknown_statistics_key() {
    one(
        &base_with("statistics:\n  dxx: {stdev: 0.1}\n"),
        11,
        9,
        "statistics.dxx.stdev",
        "did you mean `std`?",
    );
}

#[test]
fn unknown_reliability_and_requirement_keys() {
    one(
        &base_with("reliability:\n  tolerance: {px: 0.1}\n  side: two\n"),
        12,
        3,
        "reliability.side",
        "did you mean `sided`?",
    );
    one(
        &base_with(
            "reliability:\n  tolerance: {px: 0.1}\n  requirement: {minimum: 0.9, mean: 0.9}\n",
        ),
        12,
        17,
        "reliability.requirement.minimum",
        "unknown key `minimum`",
    );
}

// ------------------------------------------------------------ required parts

#[test]
fn missing_machine() {
    one(
        &BASE.replace("machine: m\n", ""),
        1,
        1,
        "",
        "missing required key `machine`",
    );
}

#[test]
fn missing_bodies() {
    one(
        "machine: m\nworkpiece: bed\ntool: x\n",
        1,
        1,
        "",
        "missing required key `bodies`",
    );
}

#[test]
fn empty_bodies() {
    one(
        "machine: m\nbodies: {}\nworkpiece: bed\ntool: x\n",
        2,
        1,
        "bodies",
        "`bodies` is empty",
    );
}

#[test]
fn body_not_a_mapping() {
    one(
        &BASE.replace("bed: {}", "bed: 5"),
        3,
        8,
        "bodies.bed",
        "expected a mapping, found `5`",
    );
}

#[test]
fn missing_joint_variable() {
    one(
        &BASE.replace(", variable: x", ""),
        6,
        5,
        "bodies.x_slide.joint",
        "missing required key `variable`",
    );
}

// ------------------------------------------------------------------- joints

#[test]
fn unknown_joint_type() {
    one(
        &BASE.replace("prismatic", "linear"),
        6,
        19,
        "bodies.x_slide.joint.type",
        "unknown joint type `linear` at key `bodies.x_slide.joint.type` (expected one of prismatic, rotary)",
    );
}

#[test]
fn unknown_axis() {
    one(
        &BASE.replace("+x", "+w"),
        6,
        36,
        "bodies.x_slide.joint.axis",
        "unknown axis `+w` at key `bodies.x_slide.joint.axis` (expected one of +x, -x, +y, -y, +z, -z)",
    );
}

#[test]
fn axis_without_sign() {
    one(
        &BASE.replace("+x", "x"),
        6,
        36,
        "bodies.x_slide.joint.axis",
        "did you mean `+x`?",
    );
}

#[test]
fn invalid_variable_name() {
    one(
        &BASE.replace("variable: x", "variable: x-1"),
        6,
        50,
        "bodies.x_slide.joint.variable",
        "`x-1` is not a valid variable name",
    );
}

#[test]
fn reserved_variable_name() {
    one(
        &BASE.replace("variable: x", "variable: pi"),
        6,
        50,
        "bodies.x_slide.joint.variable",
        "reserved",
    );
}

#[test]
fn variable_used_by_two_joints() {
    one(
        &BASE.replace(
            "workpiece:",
            "  y_slide:\n    parent: x_slide\n    joint: {type: prismatic, axis: +y, variable: x}\nworkpiece:",
        ),
        10,
        50,
        "bodies.y_slide.joint.variable",
        "variable `x` already drives the joint of body `x_slide`",
    );
}

#[test]
fn variable_collides_with_parameter() {
    one(
        &BASE.replace("bodies:", "parameters: {x: 1}\nbodies:"),
        7,
        50,
        "bodies.x_slide.joint.variable",
        "variable `x` has the same name as a parameter",
    );
}

#[test]
fn error_collides_with_parameter_or_variable() {
    one(
        &BASE.replace("bodies:", "parameters: {dxx: 1}\nbodies:"),
        8,
        18,
        "bodies.x_slide.errors.dx",
        "error `dxx` has the same name as a parameter",
    );
    one(
        &BASE.replace("dx: dxx", "dx: x"),
        7,
        18,
        "bodies.x_slide.errors.dx",
        "error `x` has the same name as a axis variable",
    );
}

// ------------------------------------------------------------------- the tree

#[test]
fn unknown_parent() {
    one(
        &BASE.replace("parent: bed", "parent: bde"),
        5,
        13,
        "bodies.x_slide.parent",
        "parent `bde` is not a body of this machine at key `bodies.x_slide.parent` (did you mean `bed`?)",
    );
}

#[test]
fn unknown_parent_does_not_cascade() {
    // The child of a body with a bad parent is not reported too.
    let text = BASE
        .replace("parent: bed", "parent: nowhere")
        .replace("workpiece:", "  y_slide: {parent: x_slide}\nworkpiece:");
    one(&text, 5, 13, "bodies.x_slide.parent", "`nowhere`");
}

#[test]
fn cycle_is_named() {
    let text = "machine: m\nbodies:\n  bed: {}\n  a: {parent: b}\n  b: {parent: c}\n  c: {parent: a}\n  d: {parent: c}\nworkpiece: bed\ntool: d\n";
    one(
        text,
        4,
        3,
        "bodies.a",
        "the parent links form a cycle: `a` -> `b` -> `c` -> `a`",
    );
}

#[test]
fn self_parent_is_a_cycle() {
    one(
        &BASE.replace("parent: bed", "parent: x_slide"),
        4,
        3,
        "bodies.x_slide",
        "cycle: `x_slide` -> `x_slide`",
    );
}

#[test]
fn second_root() {
    one(
        &BASE.replace("    parent: bed\n", ""),
        4,
        3,
        "bodies.x_slide",
        "`x_slide` is a second root body: both `bed` and `x_slide` have no parent",
    );
}

#[test]
fn missing_workpiece() {
    one(
        &BASE.replace("workpiece: bed\n", ""),
        1,
        1,
        "",
        "missing required key `workpiece`",
    );
}

#[test]
fn unknown_tool() {
    one(
        &BASE.replace("tool: x_slide", "tool: x_slid"),
        9,
        7,
        "tool",
        "tool `x_slid` is not a body of this machine at key `tool` (did you mean `x_slide`?)",
    );
}

#[test]
fn workpiece_is_tool() {
    one(
        &BASE.replace("workpiece: bed", "workpiece: x_slide"),
        9,
        7,
        "tool",
        "the workpiece and the tool are the same body `x_slide`",
    );
}

// ------------------------------------------------------------ expressions

#[test]
fn undeclared_parameter() {
    one(
        &BASE.replace(
            "    parent: bed\n",
            "    parent: bed\n    offset: [0, 2*L, 0]\n",
        ),
        6,
        19,
        "bodies.x_slide.offset[1]",
        "unknown name `L`: not a declared parameter",
    );
}

#[test]
fn axis_variable_in_offset() {
    one(
        &BASE.replace(
            "    parent: bed\n",
            "    parent: bed\n    offset: [x, 0, 0]\n",
        ),
        6,
        14,
        "bodies.x_slide.offset[0]",
        "`x` is an axis variable",
    );
}

#[test]
fn parameter_with_non_numeric_value() {
    one(
        &BASE.replace("bodies:", "parameters:\n  L: long\nbodies:"),
        3,
        6,
        "parameters.L",
        "`long` is a name, but only numbers are allowed here",
    );
    one(
        &BASE.replace("bodies:", "parameters:\n  L: [1, 2]\nbodies:"),
        3,
        6,
        "parameters.L",
        "expected a number, found a list",
    );
}

#[test]
fn expression_syntax_error_points_inside_the_string() {
    one(
        &BASE.replace(
            "    parent: bed\n",
            "    parent: bed\n    offset: [0, \"L + * 2\", 0]\n",
        ),
        6,
        22,
        "bodies.x_slide.offset[1]",
        "cannot parse the expression: expected a number, a name or `(`, found `*`",
    );
}

#[test]
fn parameter_in_divisor() {
    one(
        &BASE
            .replace("bodies:", "parameters: {L: 1}\nbodies:")
            .replace(
                "    parent: bed\n",
                "    parent: bed\n    offset: [0, 0, 1/L]\n",
            ),
        7,
        22,
        "bodies.x_slide.offset[2]",
        "parameter `L` is in a divisor",
    );
}

#[test]
fn offset_of_wrong_length() {
    one(
        &BASE.replace("    parent: bed\n", "    parent: bed\n    offset: [0, 0]\n"),
        6,
        13,
        "bodies.x_slide.offset",
        "expected a list of 3 items, found 2",
    );
}

#[test]
fn bad_rotation_angle() {
    one(
        &BASE.replace(
            "    parent: bed\n",
            "    parent: bed\n    rotation: [{about: z, angle: 90 degrees}]\n",
        ),
        6,
        37,
        "bodies.x_slide.rotation[0].angle",
        "expected an operator, found `degrees`",
    );
}

#[test]
fn bad_rotation_axis() {
    one(
        &BASE.replace(
            "    parent: bed\n",
            "    parent: bed\n    rotation: [{about: w, angle: 1}]\n",
        ),
        6,
        24,
        "bodies.x_slide.rotation[0].about",
        "expected one of x, y, z",
    );
}

#[test]
fn tool_point_checks() {
    one(
        &base_with("tool_point: [0, 0]\n"),
        10,
        13,
        "tool_point",
        "expected a list of 3 items",
    );
    one(
        &base_with("tool_point: 5\n"),
        10,
        13,
        "tool_point",
        "expected a list of 3 numbers or expressions, found `5`",
    );
    one(
        &base_with("tool_point: [0, 0, zz]\n"),
        10,
        20,
        "tool_point[2]",
        "unknown name `zz`",
    );
}

#[test]
fn unknown_frame() {
    one(
        &base_with("frame: tol\n"),
        10,
        8,
        "frame",
        "unknown frame `tol` at key `frame` (did you mean `tool`? expected one of workpiece, tool)",
    );
}

// ------------------------------------------------------------------ errors

#[test]
fn error_kind_conflict() {
    one(
        &BASE.replace("ey: eyx", "ey: dxx"),
        7,
        27,
        "bodies.x_slide.errors.ey",
        "error `dxx` is used as an angular error (ex, ey, ez) here but as a linear error (dx, dy, dz) on line 7",
    );
}

#[test]
fn invalid_error_name() {
    one(
        &BASE.replace("dx: dxx", "dx: 1.5"),
        7,
        18,
        "bodies.x_slide.errors.dx",
        "`1.5` is not a valid error name",
    );
}

// -------------------------------------------------------------- statistics

#[test]
fn negative_std() {
    one(
        &base_with("statistics:\n  dxx: {dist: normal, mean: 0, std: -0.05/6}\n"),
        11,
        37,
        "statistics.dxx.std",
        "std must be positive and finite, got -0.008",
    );
}

#[test]
fn zero_std() {
    one(
        &base_with("statistics:\n  dxx: {std: 0}\n"),
        11,
        14,
        "statistics.dxx.std",
        "std must be positive and finite, got 0",
    );
}

#[test]
fn nan_and_infinite_std() {
    one(
        &base_with("statistics:\n  dxx: {std: .nan}\n"),
        11,
        14,
        "statistics.dxx.std",
        "got NaN",
    );
    one(
        &base_with("statistics:\n  dxx: {std: .inf}\n"),
        11,
        14,
        "statistics.dxx.std",
        "got inf",
    );
    one(
        &base_with("statistics:\n  dxx: {std: 1/0}\n"),
        11,
        14,
        "statistics.dxx.std",
        "got inf",
    );
}

#[test]
fn non_numeric_std() {
    one(
        &base_with("statistics:\n  dxx: {std: small}\n"),
        11,
        14,
        "statistics.dxx.std",
        "`small` is a name, but only numbers are allowed here",
    );
    one(
        &base_with("statistics:\n  dxx: {std: \"0.05/\"}\n"),
        11,
        20,
        "statistics.dxx.std",
        "cannot parse the expression",
    );
}

#[test]
fn bad_tolerance_sigma_rule_cost_weight_min_std() {
    one(
        &base_with("statistics:\n  dxx: {tolerance: -1}\n"),
        11,
        20,
        "statistics.dxx.tolerance",
        "tolerance must be positive",
    );
    one(
        &base_with("statistics:\n  dxx: {tolerance: 1, sigma_rule: 0}\n"),
        11,
        35,
        "statistics.dxx.sigma_rule",
        "sigma_rule must be positive",
    );
    one(
        &base_with("statistics:\n  dxx: {std: 1, cost_weight: -2}\n"),
        11,
        30,
        "statistics.dxx.cost_weight",
        "cost_weight must be positive",
    );
    one(
        &base_with("statistics:\n  dxx: {std: 1, min_std: .inf}\n"),
        11,
        26,
        "statistics.dxx.min_std",
        "min_std must be positive and finite, got inf",
    );
}

#[test]
fn uniform_min_not_below_max() {
    one(
        &base_with("statistics:\n  dxx: {dist: uniform, min: 0.01, max: -0.01}\n"),
        11,
        40,
        "statistics.dxx.max",
        "a uniform distribution needs min < max, got min = 0.01, max = -0.01",
    );
}

#[test]
fn unknown_distribution() {
    one(
        &base_with("statistics:\n  dxx: {dist: gauss, std: 1}\n"),
        11,
        15,
        "statistics.dxx.dist",
        "unknown distribution `gauss`",
    );
}

#[test]
fn both_std_and_tolerance() {
    one(
        &base_with("statistics:\n  dxx: {std: 1, tolerance: 6}\n"),
        11,
        17,
        "statistics.dxx.tolerance",
        "`std` and `tolerance` cannot both be given",
    );
}

#[test]
fn neither_std_nor_tolerance() {
    one(
        &base_with("statistics:\n  dxx: {dist: normal, mean: 0}\n"),
        11,
        3,
        "statistics.dxx",
        "a normal distribution needs `std` or `tolerance`",
    );
}

#[test]
fn min_max_with_normal() {
    one(
        &base_with("statistics:\n  dxx: {std: 1, min: 0}\n"),
        11,
        17,
        "statistics.dxx.min",
        "`min` does not apply to a normal distribution",
    );
}

#[test]
fn statistics_for_unknown_error() {
    one(
        &base_with("statistics:\n  dxy: {std: 1}\n"),
        11,
        3,
        "statistics.dxy",
        "statistics for `dxy`, but no body uses an error parameter of that name at key `statistics.dxy` (did you mean `dxx`?)",
    );
}

#[test]
fn misspelt_slot_does_not_cascade_into_statistics() {
    one(
        &(BASE.replace("ey: eyx", "ee: eyx") + "statistics:\n  eyx: {std: 1}\n"),
        7,
        23,
        "bodies.x_slide.errors.ee",
        "unknown key `ee`",
    );
}

// ------------------------------------------------------------- reliability

#[test]
fn reliability_tolerance_keys_and_values() {
    one(
        &base_with("reliability:\n  tolerance: {pw: 0.03}\n"),
        11,
        15,
        "reliability.tolerance.pw",
        "unknown component `pw`",
    );
    one(
        &base_with("reliability:\n  tolerance: {px: -0.03}\n"),
        11,
        19,
        "reliability.tolerance.px",
        "a tolerance must be positive and finite, got -0.03",
    );
    one(
        &base_with("reliability:\n  sided: upper\n"),
        10,
        1,
        "reliability",
        "missing required key `tolerance`",
    );
}

#[test]
fn reliability_sided() {
    one(
        &base_with("reliability:\n  tolerance: {px: 1}\n  sided: both\n"),
        12,
        10,
        "reliability.sided",
        "unknown `sided` value `both` at key `reliability.sided` (expected one of upper, two)",
    );
}

#[test]
fn reliability_grid() {
    one(
        &base_with("reliability:\n  tolerance: {px: 1}\n  grid: {w: [0, 1]}\n"),
        12,
        10,
        "reliability.grid.w",
        "`w` is not an axis variable of this machine",
    );
    one(
        &base_with("reliability:\n  tolerance: {px: 1}\n  grid: {x: []}\n"),
        12,
        13,
        "reliability.grid.x",
        "a grid must not be empty",
    );
    one(
        &base_with("reliability:\n  tolerance: {px: 1}\n  grid: {x: [0, far]}\n"),
        12,
        17,
        "reliability.grid.x[1]",
        "`far` is a name",
    );
}

#[test]
fn reliability_requirement_range() {
    one(
        &base_with("reliability:\n  tolerance: {px: 1}\n  requirement: {min: 0, mean: 0.9}\n"),
        12,
        22,
        "reliability.requirement.min",
        "a required reliability must be in (0, 1], got 0",
    );
    one(
        &base_with("reliability:\n  tolerance: {px: 1}\n  requirement: {min: 0.9, mean: 1.5}\n"),
        12,
        33,
        "reliability.requirement.mean",
        "got 1.5",
    );
}

// ----------------------------------------------------------- many errors

#[test]
fn all_errors_are_collected_in_source_order() {
    let text = BASE
        .replace("+x", "+q")
        .replace("parent: bed", "parent: bde")
        .replace("tool: x_slide", "tool: x_slide\nframe: sideways");
    let d = diagnose(&text);
    assert_eq!(d.len(), 3, "{d:#}");
    let lines: Vec<usize> = d.iter().map(|e| e.origin.line).collect();
    assert_eq!(lines, [5, 6, 10]);
    let all = format!("{d:#}");
    assert_eq!(all.lines().count(), 3);
    assert!(d.to_string().ends_with("(and 2 more errors)"), "{d}");
    assert!(matches!(d.first().problem, Problem::UnknownBody { .. }));
}

#[test]
fn miette_report_carries_source_and_related() {
    use miette::Diagnostic;
    let d = diagnose(
        &BASE
            .replace("+x", "+q")
            .replace("parent: bed", "parent: bde"),
    );
    assert!(d.source_code().is_some());
    let labels: Vec<_> = d.labels().unwrap().collect();
    assert_eq!(labels.len(), 1);
    assert_eq!(labels[0].offset(), BASE.find("parent: bed").unwrap() + 8);
    assert_eq!(d.related().unwrap().count(), 1);
    assert!(d.code().unwrap().to_string().starts_with("chain::"));
}

#[test]
fn garbage_never_panics() {
    let samples = [
        "{",
        "}",
        "[",
        "]]",
        ":",
        "- - -",
        "? ? ?",
        "&a *a",
        "*b",
        "!!binary x",
        "%YAML 9\n---\n",
        "machine: [",
        "bodies: {a: {parent: {b: c}}}",
        "machine: m\nbodies: [1, 2]\n",
        "machine: m\nbodies:\n  bed: {joint: 5, errors: [1], offset: {x: 1}, rotation: 7}\n",
        "\t\tmachine: m",
        "machine: m\n  bodies: x\n",
        "\u{feff}machine: m",
        "'",
        "\"\\u12\"",
        "machine: m\nbodies:\n  ? [a]\n  : {}\n",
        "machine: m\nbodies:\n  bed: &x {parent: *x}\n",
    ];
    for s in samples {
        // Refused, every refusal in the file, the same from text and bytes.
        let text = match load_str(s, "g.yaml") {
            Ok(m) => panic!("{s:?} loaded as {:?}", m.name),
            Err(d) => d.to_string(),
        };
        assert!(text.starts_with("g.yaml:"), "{s:?}: {text}");
        let bytes = load_bytes(s.as_bytes(), "g.yaml").map(|m| m.name);
        assert_eq!(bytes.map_err(|d| d.to_string()), Err(text), "{s:?}");
    }
    // Every prefix of a valid file is refused in place, but for the one that
    // lacks only the last line break.
    for end in 0..BASE.len() {
        match load_str(&BASE[..end], "prefix.yaml") {
            Ok(_) => assert_eq!(end, BASE.len() - 1, "{:?} loaded", &BASE[..end]),
            Err(d) => {
                assert!(d.to_string().starts_with("prefix.yaml:"), "{d}");
                let lines = BASE[..end].lines().count().max(1);
                assert!(d.iter().all(|e| e.origin.line <= lines + 1), "{d}");
            }
        }
    }
}

// ------------------------------------------------------------------ the CLI

/// Runs `chain derive tests/data/malformed/<file>` (from the package root)
/// and checks the contract: non-zero exit, empty stdout, no panic, stderr
/// naming the file, line and key.
#[track_caller]
fn cli(file: &str, line: usize, key: &str) {
    let rel = format!("tests/data/malformed/{file}");
    let stderr = fails(&["derive", &rel]);
    assert!(
        stderr.contains(&format!("{rel}:{line}:")),
        "stderr:\n{stderr}"
    );
    assert!(stderr.contains(key), "stderr:\n{stderr}");
}

#[test]
fn cli_unknown_axis() {
    cli("unknown_axis.yaml", 6, "bodies.x_slide.joint.axis");
}

#[test]
fn cli_cycle() {
    cli("cycle.yaml", 5, "bodies.y_slide");
}

#[test]
fn cli_negative_std() {
    cli("negative_std.yaml", 12, "statistics.dxx.std");
}

#[test]
fn cli_unknown_key() {
    cli("unknown_key.yaml", 5, "bodies.x_slide.parnet");
}

#[test]
fn cli_alias_bomb() {
    cli("alias_bomb.yaml", 7, "lol4");
    // The refusal names the node bound that kept the expansion finite.
    let stderr = fails(&["derive", "tests/data/malformed/alias_bomb.yaml"]);
    let bound = chain_core::yaml::MAX_NODES.to_string();
    assert!(stderr.split_whitespace().any(|w| w == bound), "{stderr}");
}

// --------------------------------------------------------------- robustness

mod fuzz {
    use proptest::prelude::*;

    fn example() -> String {
        let path = super::common::example_path("gantry_grinder.yaml");
        std::fs::read_to_string(path).unwrap_or_else(|_| super::BASE.to_string())
    }

    proptest! {
        /// Byte-level edits of a real machine file never panic, and every
        /// diagnostic is located inside the text.
        #[test]
        fn mutated_files_never_panic(
            edits in proptest::collection::vec((any::<prop::sample::Index>(), 0u8..6, any::<u8>()), 1..6)
        ) {
            let mut bytes = example().into_bytes();
            for (at, op, byte) in edits {
                if bytes.is_empty() {
                    break;
                }
                let i = at.index(bytes.len());
                let pick = b" :-[]{}&*,\n\"'#xq0.-+/"[usize::from(byte) % 21];
                match op {
                    0 => { bytes.remove(i); }
                    1 => bytes.insert(i, pick),
                    2 => bytes[i] = pick,
                    3 => bytes.truncate(i),
                    4 => { let line: Vec<u8> = bytes[i..].iter().copied().take_while(|&b| b != b'\n').collect(); bytes.splice(i..i, line); }
                    _ => bytes[i] = byte,
                }
            }
            if let Err(d) = chain_core::load_bytes(&bytes, "fuzz.yaml") {
                for e in d.iter() {
                    prop_assert!(e.origin.offset <= bytes.len());
                    prop_assert!(e.to_string().starts_with("fuzz.yaml:"));
                    // Line numbers agree with byte offsets (what miette shows).
                    if e.origin.line > 0 && !bytes.contains(&b'\r') {
                        let before = bytes.get(..e.origin.offset).unwrap_or(&[]);
                        let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
                        prop_assert_eq!(line, e.origin.line, "{}", e);
                    }
                }
            }
        }
    }
}

#[test]
fn misspelt_variable_key_does_not_cascade_into_the_grid() {
    one(
        &(BASE.replace("variable: x", "varaible: x")
            + "reliability:\n  tolerance: {px: 1}\n  grid: {x: [0, 1]}\n"),
        6,
        40,
        "bodies.x_slide.joint.varaible",
        "did you mean `variable`?",
    );
}
