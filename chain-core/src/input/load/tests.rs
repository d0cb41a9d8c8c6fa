//! Unit tests of the loader on the spec's example and on ordering rules.

use super::*;
use crate::model::{Axis, Basis, Distribution, ErrorKind, JointKind, Sided};

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

/// A body's structure without origins: name, parent's name, offset at the
/// parameter values `p`, rotations, location slots, joint, error slots, all
/// by name.
fn structure(m: &Machine, p: &[f64]) -> Vec<String> {
    let names = |slots: &crate::model::ErrorSlots| -> Vec<Vec<String>> {
        slots
            .slots
            .iter()
            .map(|s| s.iter().map(|&e| m.errors[e].name.clone()).collect())
            .collect()
    };
    m.bodies
        .iter()
        .map(|b| {
            let offset: Vec<f64> = b.offset.iter().map(|e| e.eval(p)).collect();
            let rotation: Vec<(Axis, f64)> =
                b.rotation.iter().map(|r| (r.about, r.angle)).collect();
            let joint = b.joint.as_ref().map(|j| {
                (
                    j.kind,
                    j.axis,
                    m.variables[j.variable].name.clone(),
                )
            });
            format!(
                "{} <- {:?} offset {offset:?} rotation {rotation:?} location {:?} joint {joint:?} errors {:?}",
                b.name,
                b.parent.map(|i| &m.bodies[i].name),
                names(&b.location_errors),
                names(&b.errors),
            )
        })
        .collect()
}

/// Loads `text`, panicking with the diagnostics.
fn load_ok(text: &str) -> Machine {
    match load_str(text, "m.yaml") {
        Ok(m) => m,
        Err(d) => panic!("{d:#}"),
    }
}

/// A standard and a modified DH row load as the two bodies docs/yaml.md
/// writes out by hand (split_dh): the same names, parents, offsets,
/// rotations, slots, joints and error order.
#[test]
fn dh_rows_load_as_their_hand_expansion() {
    let dh = "machine: m\nparameters: {L: 300}\nbodies:
  base: {}
  l1:
    parent: base
    dh: {theta: 90deg, d: L/2, a: 25, alpha: -pi/2, joint: rotary, variable: q1,
         errors: {theta: T1, d: D1, a: A1, alpha: AL1, beta: B1}}
    errors: {ez: EC1}
  l2:
    parent: l1
    dh: {theta: 0, d: 0, a: L, alpha: 0, joint: prismatic, variable: q2, errors: {d: D2, a: A2}}
    squareness: {ex: S2}
  tip: {parent: l2, offset: [0, 0, 10]}
workpiece: base\ntool: tip\n";
    let dh_expanded = "machine: m\nparameters: {L: 300}\nbodies:
  base: {}
  l1.joint:
    parent: base
    rotation: [{about: z, angle: 90deg}]
    location_errors: {dz: D1, ez: T1}
    joint: {type: rotary, axis: +z, variable: q1}
    errors: {ez: EC1}
  l1:
    parent: l1.joint
    offset: [25, 0, L/2]
    rotation: [{about: x, angle: -pi/2}]
    location_errors: {dx: A1, ex: AL1}
    errors: {ey: B1}
  l2.joint:
    parent: l1
    location_errors: {dz: D2}
    joint: {type: prismatic, axis: +z, variable: q2}
    squareness: {ex: S2}
  l2:
    parent: l2.joint
    offset: [L, 0, 0]
    location_errors: {dx: A2}
  tip: {parent: l2, offset: [0, 0, 10]}
workpiece: base\ntool: tip\n";
    let p = [300.0];
    let a = load_ok(dh);
    let b = load_ok(dh_expanded);
    assert_eq!(structure(&a, &p), structure(&b, &p));
    let names = |m: &Machine| m.errors.iter().map(|e| e.name.clone()).collect::<Vec<_>>();
    assert_eq!(
        names(&a),
        ["D1", "T1", "EC1", "A1", "AL1", "B1", "D2", "S2", "A2"]
    );
    assert_eq!(names(&a), names(&b));
    let kinds: Vec<ErrorKind> = a.errors.iter().map(|e| e.kind).collect();
    assert_eq!(kinds, b.errors.iter().map(|e| e.kind).collect::<Vec<_>>());

    let mdh = "machine: m\nbodies:
  base: {}
  l1:
    parent: base
    mdh: {theta: 0.1, d: 5, a: 25, alpha: 30deg, joint: rotary, variable: q1,
          errors: {theta: T1, d: D1, a: A1, alpha: AL1, beta: B1}}
    errors: iso
  flange:
    parent: l1
    mdh: {theta: 0, d: 107, a: 0, alpha: 0}
workpiece: base\ntool: flange\n";
    let mdh_expanded = "machine: m\nbodies:
  base: {}
  l1.link:
    parent: base
    offset: [25, 0, 0]
    rotation: [{about: x, angle: 30deg}]
    location_errors: {dx: A1, ex: AL1}
    errors: {ey: B1}
  l1:
    parent: l1.link
    offset: [0, 0, 5]
    rotation: [{about: z, angle: 0.1}]
    location_errors: {dz: D1, ez: T1}
    joint: {type: rotary, axis: +z, variable: q1}
    errors: iso
  flange.link:
    parent: l1
  flange:
    parent: flange.link
    offset: [0, 0, 107]
workpiece: base\ntool: flange\n";
    let a = load_ok(mdh);
    let b = load_ok(mdh_expanded);
    assert_eq!(structure(&a, &[]), structure(&b, &[]));
    assert_eq!(
        names(&a),
        ["A1", "AL1", "B1", "D1", "T1", "EXQ1", "EYQ1", "EZQ1", "EAQ1", "EBQ1", "ECQ1"]
    );
    assert_eq!(names(&a), names(&b));
}

/// What a DH row refuses, each named by its key.
#[test]
fn dh_rows_refuse_what_they_replace_and_what_they_lack() {
    let body = |row: &str| {
        format!("machine: m\nbodies:\n  base: {{}}\n  l1:\n    parent: base\n{row}workpiece: base\ntool: l1\n")
    };
    let cases: &[(&str, &str, &str)] = &[
        (
            "    dh: {theta: 0, d: 0, a: 1, alpha: 0}\n    offset: [0, 0, 1]\n",
            "bodies.l1.offset",
            "chain::conflicting_keys",
        ),
        (
            "    dh: {theta: 0, d: 0, a: 1, alpha: 0}\n    location_errors: {dx: A}\n",
            "bodies.l1.location_errors",
            "chain::conflicting_keys",
        ),
        (
            "    dh: {theta: 0, d: 0, a: 1, alpha: 0}\n    mdh: {theta: 0, d: 0, a: 1, alpha: 0}\n",
            "bodies.l1.mdh",
            "chain::conflicting_keys",
        ),
        (
            "    dh: {theta: 0, d: 0, alpha: 0}\n",
            "bodies.l1.dh",
            "chain::missing_key",
        ),
        (
            "    dh: {theta: 0, d: 0, a: 1, alpha: 0, joint: rotary}\n",
            "bodies.l1.dh",
            "chain::missing_key",
        ),
        (
            "    dh: {theta: 0, d: 0, a: 1, alpha: 0, variable: q}\n",
            "bodies.l1.dh",
            "chain::missing_key",
        ),
        (
            "    dh: {theta: 0, d: 0, a: 1, alpha: 0, joint: helical, variable: q}\n",
            "bodies.l1.dh.joint",
            "chain::unknown_value",
        ),
        (
            "    dh: {theta: 0, d: 0, a: 1, alpha: 0, joint: rotary, variable: q,\n         errors: {a: {name: A, powers: [1]}}}\n",
            "bodies.l1.dh.errors.a",
            "chain::function_not_allowed",
        ),
        (
            "    dh: {theta: 0, d: 0, a: 1, alpha: 0, errors: {gamma: G}}\n",
            "bodies.l1.dh.errors.gamma",
            "chain::unknown_key",
        ),
    ];
    for (row, key, code) in cases {
        let problems = from_tree(&yaml::parse(&body(row)).root.expect("yaml")).expect_err(row);
        assert_eq!(problems.len(), 1, "{row}: {problems:?}");
        assert_eq!(problems[0].0.key, *key, "{row}");
        assert_eq!(problems[0].1.code(), *code, "{row}");
    }
    // Names under a refused key or row are not reported again where
    // `statistics` names them.
    for row in [
        "    dh: {theta: 0, d: 0, a: 1, alpha: 0}\n    location_errors: {dx: A}\n",
        "    dh: {theta: 0, d: 0, a: 1, alpha: 0, errors: {a: A}}\n    mdh: {theta: 0, d: 0, a: 1, alpha: 0}\n",
    ] {
        let text = format!("{}statistics: {{A: {{std: 1}}}}\n", body(row));
        let problems = from_tree(&yaml::parse(&text).root.expect("yaml")).expect_err(row);
        assert_eq!(problems.len(), 1, "{row}: {problems:?}");
        assert_eq!(problems[0].1.code(), "chain::conflicting_keys", "{row}");
    }
    // A declared body named like a row's generated frame.
    let text = "machine: m\nbodies:\n  base: {}\n  l1:\n    parent: base\n    dh: {theta: 0, d: 0, a: 1, alpha: 0}\n  l1.joint: {parent: base}\nworkpiece: base\ntool: l1\n";
    let problems = from_tree(&yaml::parse(text).root.expect("yaml")).unwrap_err();
    assert_eq!(problems.len(), 1, "{problems:?}");
    assert_eq!(problems[0].0.key, "bodies.l1.joint");
    assert_eq!(problems[0].1.code(), "chain::generated_body_name");
}
