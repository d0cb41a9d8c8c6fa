//! Denavit–Hartenberg bodies: a `dh` / `mdh` row derives
//! to the model of the Denavit–Hartenberg product itself.
//!
//! The DH tables are written out here, not read from the files, and each
//! link is the textbook matrix with every parameter perturbed by its error:
//!
//! ```text
//! standard (dh):  A_i = Rot_z(θ + Δθ + q)·Trans_z(d + Δd)·Trans_x(a + Δa)·Rot_x(α + Δα)·Rot_y(β)
//! modified (mdh): A_i = Rot_x(α + Δα)·Trans_x(a + Δa)·Rot_y(β)·Rot_z(θ + Δθ + q)·Trans_z(d + Δd)
//! ```
//!
//! (β: Hayati's rotation for nearly parallel axes). For the two example arms
//! and a made-up table with what they lack (θ offsets, a prismatic row, β
//! on every row of both forms, a fixed row), at random joint values:
//!
//! - the nominal tool point and rotation of the loaded file through the
//!   numeric product of `tests/it/common` (the machine as offsets and
//!   rotations) equal the DH product's, and with finite errors of every DH
//!   parameter and β so do the deviations (each is one error slot, exactly);
//! - the derived model's sensitivity equals a 5-point central difference of
//!   the DH product in each error.
//!
//! Then the worked example of `examples/robots/`: the simulated
//! laser-tracker calibration of the PUMA 560 (written by `generate.py` with
//! its own DH product) is the truth plus the stated noise through the numeric
//! product, and `chain identify` recovers the truth's identifiable
//! combinations with the redundancies the DH analysis predicts.

#![allow(clippy::needless_range_loop)]

use crate::common;

use chain::core::Machine;
use common::cli::ok_json;
use common::{
    example_file, gauss, mul3, mul4, rigid, rot_axis, rotation, subset_combinations,
    subset_estimates, transform_point, transpose3, values_of, vee_skew, Exact, Mat4, Rng,
};

/// One row of a DH table: nominal θ, d, a, α (mm, rad) and whether a joint
/// drives it.
#[derive(Clone, Copy)]
struct Row {
    theta: f64,
    d: f64,
    a: f64,
    alpha: f64,
    joint: bool,
    /// A prismatic joint (its variable adds to d, not to θ).
    prismatic: bool,
}

/// A row with a rotary joint (`joint`) or none.
const fn row(theta: f64, d: f64, a: f64, alpha: f64, joint: bool) -> Row {
    Row {
        theta,
        d,
        a,
        alpha,
        joint,
        prismatic: false,
    }
}

/// A row with a prismatic joint.
const fn slide(theta: f64, d: f64, a: f64, alpha: f64) -> Row {
    Row {
        theta,
        d,
        a,
        alpha,
        joint: true,
        prismatic: true,
    }
}

const H: f64 = std::f64::consts::FRAC_PI_2;

/// PUMA 560, standard DH (Corke & Armstrong-Hélouvry 1994), mm.
const PUMA: [Row; 6] = [
    row(0.0, 672.0, 0.0, H, true),
    row(0.0, 0.0, 431.8, 0.0, true),
    row(0.0, 150.05, 20.3, -H, true),
    row(0.0, 431.8, 0.0, H, true),
    row(0.0, 0.0, 0.0, -H, true),
    row(0.0, 0.0, 0.0, 0.0, true),
];

/// Franka Emika Panda, modified DH (Franka's table), mm; the flange row
/// has no joint.
const PANDA: [Row; 8] = [
    row(0.0, 333.0, 0.0, 0.0, true),
    row(0.0, 0.0, 0.0, -H, true),
    row(0.0, 316.0, 0.0, H, true),
    row(0.0, 0.0, 82.5, H, true),
    row(0.0, 384.0, -82.5, -H, true),
    row(0.0, 0.0, 0.0, H, true),
    row(0.0, 0.0, 88.0, H, true),
    row(0.0, 107.0, 0.0, 0.0, false),
];

/// A robot as its DH table: the convention, the rows, the names of each
/// row's errors (Δθ, Δd, Δa, Δα, β; `None`: not an error of the file) and
/// the tool point with its error names (in the last frame).
struct Dh {
    file: &'static str,
    /// The machine text, when it is not the example `file`.
    yaml: Option<String>,
    modified: bool,
    rows: Vec<Row>,
    errors: Vec<[Option<String>; 5]>,
    tool: [f64; 3],
    tool_errors: [Option<&'static str>; 3],
}

fn puma() -> Dh {
    Dh {
        file: "robots/puma560_dh.yaml",
        yaml: None,
        modified: false,
        rows: PUMA.to_vec(),
        errors: (1..=6)
            .map(|i| {
                [
                    Some(format!("DT{i}")),
                    Some(format!("DD{i}")),
                    Some(format!("DA{i}")),
                    Some(format!("DAL{i}")),
                    (i == 2).then(|| "B2".to_string()),
                ]
            })
            .collect(),
        tool: [40.0, 0.0, 90.0],
        tool_errors: [Some("TX"), Some("TY"), Some("TZ")],
    }
}

fn panda() -> Dh {
    Dh {
        file: "robots/panda_mdh.yaml",
        yaml: None,
        modified: true,
        rows: PANDA.to_vec(),
        errors: (1..=8)
            .map(|i| {
                if i == 8 {
                    return [None, None, None, None, None];
                }
                [
                    Some(format!("DT{i}")),
                    Some(format!("DD{i}")),
                    Some(format!("DA{i}")),
                    Some(format!("DAL{i}")),
                    None,
                ]
            })
            .collect(),
        tool: [0.0, 0.0, 0.0],
        tool_errors: [None; 3],
    }
}

/// A table with what the two arms lack: θ offsets, a prismatic row, β on
/// every row (in `mdh` too), a fixed last row and a tool point off every
/// axis; written as `dh` or `mdh` rows.
fn mixed(modified: bool) -> Dh {
    let rows = vec![
        row(0.3, 100.0, 50.0, 0.4, true),
        slide(-0.7, 20.0, 300.0, -H),
        row(1.1, 0.0, 40.0, H, true),
        row(0.2, 80.0, 10.0, -0.5, false),
    ];
    let form = if modified { "mdh" } else { "dh" };
    let mut yaml = String::from("machine: mixed\nbodies:\n  base: {}\n");
    let mut parent = "base".to_string();
    for (i, r) in rows.iter().enumerate() {
        let k = i + 1;
        let joint = match (r.joint, r.prismatic) {
            (false, _) => String::new(),
            (true, false) => format!(", joint: rotary, variable: q{k}"),
            (true, true) => format!(", joint: prismatic, variable: q{k}"),
        };
        yaml += &format!(
            "  l{k}:\n    parent: {parent}\n    {form}: {{theta: {}, d: {}, a: {}, alpha: {}{joint},\n      errors: {{theta: DT{k}, d: DD{k}, a: DA{k}, alpha: DAL{k}, beta: B{k}}}}}\n",
            r.theta, r.d, r.a, r.alpha
        );
        parent = format!("l{k}");
    }
    yaml += &format!(
        "  tip: {{parent: {parent}, offset: [15, -25, 35]}}\nworkpiece: base\ntool: tip\n"
    );
    Dh {
        file: if modified {
            "mixed (mdh)"
        } else {
            "mixed (dh)"
        },
        yaml: Some(yaml),
        modified,
        errors: (1..=rows.len())
            .map(|k| ["DT", "DD", "DA", "DAL", "B"].map(|p| Some(format!("{p}{k}"))))
            .collect(),
        rows,
        tool: [15.0, -25.0, 35.0],
        tool_errors: [None; 3],
    }
}

/// Every table the tests check.
fn robots() -> [Dh; 4] {
    [puma(), panda(), mixed(false), mixed(true)]
}

fn rot4(k: usize, angle: f64) -> Mat4 {
    rigid(&rot_axis(k, angle), [0.0; 3])
}

fn trans4(t: [f64; 3]) -> Mat4 {
    rigid(&rot_axis(0, 0.0), t)
}

impl Dh {
    fn load(&self) -> Machine {
        match &self.yaml {
            Some(text) => chain::core::load_str(text, self.file).unwrap_or_else(|d| panic!("{d}")),
            None => chain::core::load_file(&example_file(self.file)).expect("the example loads"),
        }
    }

    /// The DH product to the tool, with the errors `e` (machine order;
    /// `None`: all zero) at joint values `q` (one per jointed row).
    fn product(&self, m: &Machine, q: &[f64], e: Option<&[f64]>) -> Mat4 {
        let err = |name: &Option<String>| match (name, e) {
            (Some(n), Some(e)) => e[m.error_index(n).expect("error name")],
            _ => 0.0,
        };
        let mut t = trans4([0.0; 3]);
        let mut joint = 0;
        for (r, names) in self.rows.iter().zip(&self.errors) {
            let q = if r.joint {
                joint += 1;
                q[joint - 1]
            } else {
                0.0
            };
            let [dt, dd, da, dal, beta] = names.each_ref().map(err);
            let (q_theta, q_d) = if r.prismatic { (0.0, q) } else { (q, 0.0) };
            let theta = rot4(2, r.theta + dt + q_theta);
            let d = trans4([0.0, 0.0, r.d + dd + q_d]);
            let a = trans4([r.a + da, 0.0, 0.0]);
            let alpha = rot4(0, r.alpha + dal);
            let beta = rot4(1, beta);
            for f in if self.modified {
                [alpha, a, beta, theta, d]
            } else {
                [theta, d, a, alpha, beta]
            } {
                t = mul4(&t, &f);
            }
        }
        let tool: [f64; 3] = std::array::from_fn(|c| {
            let de = match (self.tool_errors[c], e) {
                (Some(n), Some(e)) => e[m.error_index(n).expect("tool error")],
                _ => 0.0,
            };
            self.tool[c] + de
        });
        mul4(&t, &trans4(tool))
    }

    /// The deviation `[px, py, pz, ox, oy, oz]` of the DH product with `e`
    /// from the nominal one (base frame, as the files' `workpiece: base`).
    fn deviation(&self, m: &Machine, q: &[f64], e: &[f64]) -> [f64; 6] {
        let t0 = self.product(m, q, None);
        let te = self.product(m, q, Some(e));
        let p0 = transform_point(&t0, [0.0; 3]);
        let pe = transform_point(&te, [0.0; 3]);
        let o = vee_skew(&mul3(&rotation(&te), &transpose3(&rotation(&t0))));
        [
            pe[0] - p0[0],
            pe[1] - p0[1],
            pe[2] - p0[2],
            o[0],
            o[1],
            o[2],
        ]
    }
}

fn random_joints(rng: &mut Rng, n: usize) -> Vec<f64> {
    (0..n)
        .map(|_| rng.range(-std::f64::consts::PI, std::f64::consts::PI))
        .collect()
}

/// The loaded file through the tests' numeric product (offsets, rotations,
/// location errors: the machine format's semantics) is the DH product:
/// nominal pose, and the deviation with finite errors of every DH
/// parameter and β.
#[test]
fn dh_and_mdh_files_are_the_dh_product() {
    for robot in robots() {
        let m = robot.load();
        let exact = Exact::new(&m);
        let mut rng = Rng::new(33);
        let joints = m.variables.len();
        for _ in 0..20 {
            let q = random_joints(&mut rng, joints);
            // Nominal: 1e-9 mm on a ~1.5 m arm; rotation to 1e-12.
            let (r, p) = exact.nominal(&q, &[]);
            let t = robot.product(&m, &q, None);
            let pd = transform_point(&t, [0.0; 3]);
            let rd = rotation(&t);
            for c in 0..3 {
                assert!(
                    (p[c] - pd[c]).abs() < 1e-9,
                    "{}: p{c} {} vs {}",
                    robot.file,
                    p[c],
                    pd[c]
                );
                for k in 0..3 {
                    assert!((r[c][k] - rd[c][k]).abs() < 1e-12, "{}: R", robot.file);
                }
            }
            // Finite errors of 1e-3 (rad or mm) on every parameter and β:
            // each is exactly one error slot of its row's bodies.
            let e: Vec<f64> = m.errors.iter().map(|_| 1e-3 * gauss(&mut rng)).collect();
            let a = exact.exact_error(&q, &[], &e);
            let b = robot.deviation(&m, &q, &e);
            for c in 0..6 {
                assert!(
                    (a[c] - b[c]).abs() < 1e-9,
                    "{}: component {c}: {} vs {}",
                    robot.file,
                    a[c],
                    b[c]
                );
            }
        }
    }
}

/// The derived model's sensitivity is the derivative of the DH product in
/// each error (a 5-point central difference, h = 1e-4: truncation ~1e-13 of
/// the arm's length, rounding ~1e-11 of it).
#[test]
fn dh_and_mdh_models_are_the_derivative_of_the_dh_product() {
    for robot in robots() {
        let m = robot.load();
        let model = chain::core::compile(&m);
        let exact = Exact::new(&m);
        let n = m.errors.len();
        let mut rng = Rng::new(34);
        for _ in 0..10 {
            let q = random_joints(&mut rng, m.variables.len());
            let s = exact.model_sensitivity(&model, &q, &[]);
            let h = 1e-4;
            for j in 0..n {
                let at = |step: f64| {
                    let mut e = vec![0.0; n];
                    e[j] = step * h;
                    robot.deviation(&m, &q, &e)
                };
                let (m2, m1, p1, p2) = (at(-2.0), at(-1.0), at(1.0), at(2.0));
                for c in 0..6 {
                    let fd = (m2[c] - 8.0 * m1[c] + 8.0 * p1[c] - p2[c]) / (12.0 * h);
                    let got = s[c * n + j];
                    assert!(
                        (got - fd).abs() < 1e-6 * (1.0 + fd.abs()),
                        "{}: d{c}/d{}: model {got}, DH product {fd}",
                        robot.file,
                        m.errors[j].name
                    );
                }
            }
        }
    }
}

/// The CSV rows of a tracker file: joints, measured deviation, std.
fn tracker_rows(file: &str) -> Vec<(Vec<f64>, [f64; 3], f64)> {
    let text = std::fs::read_to_string(example_file(file)).expect("example CSV");
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with('q') && !l.is_empty())
        .map(|l| {
            let f: Vec<f64> = l.split(',').map(|v| v.parse().expect("number")).collect();
            (f[..6].to_vec(), [f[6], f[7], f[8]], f[9])
        })
        .collect()
}

/// `generate.py`'s data are the truth through the tests' numeric product of
/// the DH file plus noise of the stated std (the rms of the standardised
/// differences within 12 % of 1 over 330 values, none beyond 4.5): the
/// generator's DH product and the file agree.
#[test]
fn puma_tracker_data_are_the_truth_plus_noise() {
    let m = puma().load();
    let e = values_of(&m, "robots/puma560_truth.yaml");
    let exact = Exact::new(&m);
    let (mut sum, mut count, mut worst) = (0.0, 0usize, 0.0f64);
    for file in ["robots/puma560_tracker.csv", "robots/puma560_validate.csv"] {
        for (q, measured, std) in tracker_rows(file) {
            let predicted = exact.exact_error(&q, &[], &e);
            for c in 0..3 {
                let t = (measured[c] - predicted[c]) / std;
                sum += t * t;
                count += 1;
                worst = worst.max(t.abs());
            }
        }
    }
    assert_eq!(count, 330);
    let rms = (sum / count as f64).sqrt();
    assert!((rms - 1.0).abs() < 0.12, "standardised noise rms {rms}");
    assert!(worst < 4.5, "a noise value of {worst} std");
}

/// `chain identify` of the PUMA 560's simulated tracker data, validated on
/// its 30 held-out poses, with `extra` options; the JSON document.
fn identify_puma(extra: &[&str]) -> serde_json::Value {
    let file = example_file("robots/puma560_dh.yaml");
    let measurements = example_file("robots/puma560_tracker.csv");
    let validate = example_file("robots/puma560_validate.csv");
    let mut args = vec![
        "identify",
        file.to_str().unwrap(),
        "--measurements",
        measurements.to_str().unwrap(),
        "--validate",
        validate.to_str().unwrap(),
        "--format",
        "json",
    ];
    args.extend_from_slice(extra);
    ok_json(&args)
}

/// `chain identify` on the simulated calibration: rank 23 of 28, the five
/// redundancies of the DH analysis (parallel joints 2 and 3 share `d`; the
/// last joint's `a`, `d`, `θ`, `α` act as the reflector's offsets), every
/// estimated combination within 4 std of the truth's, the scatter that of
/// the stated noise, and the 30 validation poses predicted to the noise.
#[test]
fn puma_calibration_recovers_the_truth() {
    let m = puma().load();
    let e = values_of(&m, "robots/puma560_truth.yaml");
    let json = identify_puma(&[]);
    assert_eq!(json["rank"], 23, "{json:#}");
    let mut groups: Vec<Vec<String>> = json["groups"]
        .as_array()
        .map(|g| {
            g.iter()
                .map(|x| {
                    let mut v: Vec<String> = x["errors"]
                        .as_array()
                        .expect("errors")
                        .iter()
                        .map(|s| s.as_str().unwrap().to_string())
                        .collect();
                    v.sort();
                    v
                })
                .collect()
        })
        .unwrap_or_default();
    groups.sort();
    let want: Vec<Vec<&str>> = vec![
        vec!["DA6", "TX"],
        vec!["DAL6", "DT6", "TY"],
        vec!["DD2", "DD3"],
        vec!["DD6", "TZ"],
    ];
    assert_eq!(groups, want, "{json:#}");

    let (value, std) = subset_estimates(&m, &json);
    let truth = subset_combinations(&m, &json, &e);
    let estimated = json["subset"]["estimated"].as_array().expect("estimated");
    assert_eq!(estimated.len(), 23);
    for name in estimated {
        let k = m.error_index(name.as_str().unwrap()).unwrap();
        let z = (value[k] - truth[k]) / std[k];
        assert!(
            z.abs() < 4.0,
            "{}: {} against the truth's {} (std {})",
            m.errors[k].name,
            value[k],
            truth[k],
            std[k]
        );
    }
    let ratio = json["residual"]["scale"].as_f64().expect("scatter");
    assert!((ratio - 1.0).abs() < 0.15, "scatter / std {ratio}");

    // Before: the DH errors' ~1 mm; after: the noise (0.02 mm per
    // coordinate) plus the estimates' own spread.
    let after = &json["validation"]["after"];
    let before = &json["validation"]["before"];
    assert!(before["rms"].as_f64().unwrap() > 0.5, "{before}");
    let rms = after["rms"].as_f64().unwrap();
    assert!(rms > 0.015 && rms < 0.03, "validation rms {rms}");

    // The numbers docs/identify.md and examples/robots/README.md quote
    // ("Worked example: a PUMA 560"), to their printed digits.
    let number = |v: &serde_json::Value| v.as_f64().expect("a number");
    let close = |got: f64, want: f64, tol: f64, what: &str| {
        assert!(
            (got - want).abs() <= tol,
            "{what}: {got} against the documented {want}"
        );
    };
    close(number(&json["condition"]), 21.8, 0.05, "condition");
    close(
        number(&json["residual"]["rms"]),
        0.0198,
        5e-5,
        "residual rms",
    );
    close(ratio, 1.04, 0.005, "scatter / std");
    close(
        number(&json["first_order"]["max"]),
        0.0039,
        1e-4,
        "first-order difference",
    );
    for (set, key, want, tol) in [
        (before, "mean", 1.094, 5e-4),
        (before, "max", 1.968, 5e-4),
        (before, "rms", 0.682, 5e-4),
        (after, "mean", 0.0356, 5e-5),
        (after, "max", 0.0740, 5e-5),
        (after, "rms", 0.0224, 5e-5),
    ] {
        close(number(&set[key]), want, tol, key);
    }
    // The four combinations (value ± std), where DD2, DD6, DA6 and DT6
    // stand for their groups.
    for (name, want, want_std) in [
        ("DD2", 0.2000, 0.0167),
        ("DD6", 0.7499, 0.0032),
        ("DA6", 0.4016, 0.0025),
        ("DT6", -4.324e-3, 7.1e-5),
    ] {
        let k = m.error_index(name).unwrap();
        close(value[k], want, want.abs() * 1e-3 + 1e-4, name);
        close(std[k], want_std, want_std * 0.02, name);
    }
    // --iterate: converged in 4 Levenberg–Marquardt iterations; the
    // prediction moves by less than 1e-4 mm.
    let iterated = identify_puma(&["--iterate"]);
    assert_eq!(iterated["iteration"]["converged"], true);
    assert_eq!(iterated["iteration"]["iterations"], 4);
    for key in ["mean", "max", "rms"] {
        let moved = number(&iterated["validation"]["after"][key]) - number(&after[key]);
        assert!(
            moved.abs() < 1e-4,
            "--iterate moved the held-out {key} by {moved}"
        );
    }
}
