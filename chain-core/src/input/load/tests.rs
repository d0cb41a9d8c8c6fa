//! Unit tests of the loader on the spec's example and on ordering rules.

use super::*;
use crate::model::{Basis, Distribution, ErrorKind, JointKind, Sided};

const GANTRY: &str = r#"machine: gantry_grinder                # identifier
description: Large CNC gantry guide-rail grinder
parameters: {}
bodies:
  bed: {}
  x_slide:
    parent: bed
    joint: {type: prismatic, axis: +x, variable: x}
    errors: {dx: dxx, dy: dyx, dz: dzx, ex: exx, ey: eyx, ez: ezx}
    squareness: {ez: Sxy}
  table: {parent: x_slide}
  z_slide:
    parent: bed
    joint: {type: prismatic, axis: +z, variable: z}
    errors: {dx: dxz, dy: dyz, dz: dzz, ex: exz, ey: eyz, ez: ezz}
    squareness: {ex: Syz, ey: Sxz}
  y_slide:
    parent: z_slide
    joint: {type: prismatic, axis: +y, variable: y}
    errors: {dx: dxy, dy: dyy, dz: dzy, ex: exy, ey: eyy, ez: ezy}
  tool: {parent: y_slide}
workpiece: table
tool: tool
tool_point: [0, 0, 0]                  # in the tool frame; default origin
frame: tool                            # tool | workpiece (default workpiece)

statistics:
  dxx: {dist: normal, mean: 0, std: 0.05/6}
  eyx: {dist: normal, mean: 0, tolerance: 0.06/1000, sigma_rule: 6}
  exx: {dist: normal, mean: 0, std: 0.03/6000}
reliability:
  tolerance: {px: 0.03, py: 0.03, pz: 0.03}
  sided: upper
  grid: {x: [0, 250, 500, 750, 1000], y: [-1500, -750, 0, 750, 1500], z: [600, 800, 1000, 1200, 1400]}
  requirement: {min: 0.95, mean: 0.97}
"#;

#[test]
fn spec_example_loads() {
    let m = load_str(GANTRY, "gantry.yaml").unwrap();
    assert_eq!(m.name, "gantry_grinder");
    assert_eq!(m.file.as_deref(), Some("gantry.yaml"));
    let names: Vec<&str> = m.bodies.iter().map(|b| b.name.as_str()).collect();
    assert_eq!(
        names,
        ["bed", "x_slide", "table", "z_slide", "y_slide", "tool"]
    );
    let vars: Vec<&str> = m.variables.iter().map(|v| v.name.as_str()).collect();
    assert_eq!(vars, ["x", "z", "y"]);
    assert_eq!(m.variables[2].body, 4);
    assert_eq!(m.variables[0].kind, JointKind::Prismatic);
    let errs: Vec<&str> = m.errors.iter().map(|e| e.name.as_str()).collect();
    assert_eq!(
        errs,
        [
            "dxx", "dyx", "dzx", "exx", "eyx", "ezx", "Sxy", "dxz", "dyz", "dzz", "exz", "eyz",
            "ezz", "Syz", "Sxz", "dxy", "dyy", "dzy", "exy", "eyy", "ezy"
        ]
    );
    assert_eq!(m.errors[0].kind, ErrorKind::Linear);
    assert_eq!(m.errors[3].kind, ErrorKind::Angular);
    assert_eq!(m.errors[6].kind, ErrorKind::Squareness);
    // Squareness joins the motion-error transform's ez slot.
    assert_eq!(m.bodies[1].errors.slots[5], vec![5, 6]);
    assert_eq!(m.bodies[4].parent, Some(3));
    assert_eq!(m.workpiece, 2);
    assert_eq!(m.tool, 5);
    assert_eq!(m.frame, Frame::Tool);
    assert_eq!(m.statistics.len(), 3);
    assert_eq!(m.statistics[1].error, 4);
    assert_eq!(
        m.statistics[1].distribution,
        Distribution::Normal {
            mean: 0.0,
            std: 0.06 / 1000.0 / 6.0
        }
    );
    let r = m.reliability.unwrap();
    assert_eq!(r.sided, Sided::Upper);
    assert_eq!(r.tolerance.len(), 3);
    assert_eq!(r.grid[1].0, 2); // y is the third variable
    assert_eq!(r.requirement.unwrap().mean, 0.97);
}

#[test]
fn offsets_rotations_and_parameters() {
    let text = "machine: m\nparameters: {L: 100, h: null}\nbodies:\n  bed: {}\n  a:\n    parent: bed\n    offset: [L/2, 0, -h]\n    rotation: [{about: z, angle: 90deg}, {about: x, angle: pi/2}]\n    joint: {type: rotary, axis: -z, variable: C}\n    location_errors: {ex: eC}\n    errors: {ex: [eC, exC]}\nworkpiece: bed\ntool: a\ntool_point: [0, 0, 2*L]\n";
    let m = load_str(text, "m.yaml").unwrap();
    assert_eq!(m.parameters.len(), 2);
    assert_eq!(m.parameters[1].value, None);
    let a = &m.bodies[1];
    assert_eq!(a.offset[0].eval(&[100.0, 5.0]), 50.0);
    assert_eq!(a.offset[2].eval(&[100.0, 5.0]), -5.0);
    assert!((a.rotation[0].angle - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
    assert_eq!(a.joint.as_ref().unwrap().axis.sign(), -1.0);
    assert_eq!(a.location_errors.slots[3], vec![0]);
    assert_eq!(a.errors.slots[3], vec![0, 1]);
    assert_eq!(m.tool_point[2].eval(&[100.0, 0.0]), 200.0);
}

#[test]
fn collects_several_errors() {
    let text = "machine: m\nbodies:\n  bed: {}\n  a: {parent: bde, joint: {type: prismatic, axis: +w, variable: x}}\nworkpiece: bed\ntool: a\nfoo: 1\n";
    let d = load_str(text, "m.yaml").unwrap_err();
    assert_eq!(d.len(), 3, "{d:#}");
}

/// The inline `machine!` form of a token string: the same located tree as
/// YAML, through [`crate::inline::Converter`].
fn inline(tokens: &str) -> Result<Machine, Vec<(Origin, Problem)>> {
    let stream: proc_macro2::TokenStream = tokens.parse().expect("tokens");
    let mut conv = crate::inline::Converter::default();
    let root = conv
        .mapping(stream, proc_macro2::Span::call_site())
        .expect("inline syntax");
    from_tree(&root)
}

#[test]
fn inline_form_takes_function_slots_and_iso() {
    let m = inline(
        "machine: m,
         bodies {
             bed {},
             x_slide {
                 parent: bed,
                 joint: { type: prismatic, axis: +x, variable: x },
                 errors: {
                     dy: [dyc, { name: EYX, powers: [1, 2] }],
                     dz: { name: EZX, basis: legendre, degree: 2, range: [-500, 500] },
                     ez: { name: ECX, basis: chebyshev, degree: 2, range: [0, 1e3], from: 1 },
                 },
             },
             table {
                 parent: bed,
                 joint: { type: rotary, axis: +z, variable: C },
                 errors: iso,
                 location_errors: { ex: { name: EAC, basis: fourier, harmonics: 1 } },
             },
         },
         workpiece: table,
         tool: x_slide,",
    );
    // `location_errors` takes names only: one error, then the valid form.
    let problems = m.unwrap_err();
    assert_eq!(problems.len(), 1, "{problems:?}");
    assert_eq!(problems[0].0.key, "bodies.table.location_errors.ex");
    assert_eq!(problems[0].1.code(), "chain::function_not_allowed");

    let m = inline(
        "machine: m,
         bodies {
             bed {},
             x_slide {
                 parent: bed,
                 joint: { type: prismatic, axis: +x, variable: x },
                 errors: {
                     dy: [dyc, { name: EYX, powers: [1, 2] }],
                     dz: { name: EZX, basis: legendre, degree: 2, range: [-500, 500] },
                     ez: { name: ECX, basis: chebyshev, degree: 2, range: [0, 1e3], from: 1 },
                 },
             },
             table {
                 parent: bed,
                 joint: { type: rotary, axis: +z, variable: C },
                 errors: iso,
                 squareness: { ex: Sxz },
             },
             spindle { parent: table, joint: { type: rotary, axis: +x, variable: A },
                       errors: { ex: { name: EAA, basis: fourier, harmonics: 1 } } },
         },
         workpiece: spindle,
         tool: x_slide,",
    )
    .unwrap();
    let names: Vec<&str> = m.errors.iter().map(|e| e.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "dyc", "EYX_1", "EYX_2", "EZX_0", "EZX_1", "EZX_2", "ECX_1", "ECX_2", "EXC", "EYC",
            "EZC", "EAC", "EBC", "ECC", "Sxz", "EAA_0", "EAA_c1", "EAA_s1"
        ]
    );
    let f: Vec<(&str, &Basis)> = m
        .functions
        .iter()
        .map(|f| (f.name.as_str(), &f.basis))
        .collect();
    assert_eq!(
        f,
        [
            ("EYX", &Basis::Powers { powers: vec![1, 2] }),
            (
                "EZX",
                &Basis::Legendre {
                    degree: 2,
                    range: [-500.0, 500.0],
                    from: 0
                }
            ),
            (
                "ECX",
                &Basis::Chebyshev {
                    degree: 2,
                    range: [0.0, 1000.0],
                    from: 1
                }
            ),
            ("EAA", &Basis::Fourier { harmonics: 1 }),
        ]
    );
    assert_eq!(m.functions[3].variable, m.variable_index("A").unwrap());
}
