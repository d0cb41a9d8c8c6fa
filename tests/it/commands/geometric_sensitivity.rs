//! Geometric error sensitivity coefficients of seed 004 (Fan et al. 2020,
//! Eq. 4-6, Section 5.2, Figures 3-5) on `examples/machines/internal_grinder.yaml`,
//! and `chain sensitivity --kind geometric` (the JSON contract of
//! shared/spec/machine-format.md). See docs/geometric_sensitivity.md.

use crate::common;

use std::path::PathBuf;

use chain::core::geometric::{self, GeometricSensitivity, NominalSizes};
use chain::core::model::Component;
use chain::core::{CompiledModel, Machine};
use common::cli::{fails, ok_json, ok_stdout, scratch, unwrapped};
use common::example_path;
use serde_json::Value;

fn grinder_file() -> PathBuf {
    example_path("internal_grinder.yaml")
}

fn grinder() -> (Machine, CompiledModel) {
    let m = chain::core::load_file(&grinder_file()).expect("load the grinder");
    let model = chain::core::compile(&m);
    (m, model)
}

/// Parameter values of the file, with `L` replaced.
fn params(m: &Machine, l: f64) -> Vec<f64> {
    m.parameters
        .iter()
        .map(|p| if p.name == "L" { l } else { p.value.unwrap() })
        .collect()
}

/// The paper's case point (x1, x2, z) = (-100, 0, 40).
const CASE: [f64; 3] = [-100.0, 0.0, 40.0];

fn at_case(l: f64, sizes: NominalSizes) -> GeometricSensitivity {
    let (m, model) = grinder();
    assert_eq!(
        m.variables
            .iter()
            .map(|v| v.name.as_str())
            .collect::<Vec<_>>(),
        ["x1", "x2", "z"]
    );
    geometric::at_point(&model, &CASE, &params(&m, l), &sizes.of(&m))
}

/// Equal numbers for both kinds (0.001 mm, 0.001 rad): C = S / ΣS, Eq. 6 as printed.
fn equal() -> NominalSizes {
    NominalSizes::default()
        .parse("linear=0.001,angular=0.001")
        .unwrap()
}

fn pct(r: &GeometricSensitivity, c: Component, error: &str) -> f64 {
    100.0 * r.component(c).get(error).expect(error).c
}

fn top(r: &GeometricSensitivity, c: Component, n: usize) -> Vec<&str> {
    r.component(c).ranked[..n]
        .iter()
        .map(|e| e.error.as_str())
        .collect()
}

fn sorted(mut v: Vec<&str>) -> Vec<&str> {
    v.sort_unstable();
    v
}

/// The paper's lists: (direction, [(error, printed share %)]).
const PAPER_Y: [(&str, f64); 3] = [("ez_x1", 29.0), ("ez_x2", 20.0), ("ez_z", 20.0)];
const PAPER_Z: [(&str, f64); 4] = [
    ("ey_x1", 30.0),
    ("ey_x2", 20.0),
    ("ey_z", 20.0),
    ("e_x2z", 20.0),
];

fn check_paper_lists(r: &GeometricSensitivity, tol_pp: f64) {
    // y: εz(x1) first, then εz(x2) and εz(z).
    assert_eq!(top(r, Component::Py, 1), ["ez_x1"]);
    assert_eq!(sorted(top(r, Component::Py, 3)), ["ez_x1", "ez_x2", "ez_z"]);
    for (e, paper) in PAPER_Y {
        let got = pct(r, Component::Py, e);
        assert!(
            (got - paper).abs() <= tol_pp,
            "py {e}: {got:.2} % vs {paper} %"
        );
    }
    // z: εy(x1) first, then εy(x2), εy(z), εx2z.
    assert_eq!(top(r, Component::Pz, 1), ["ey_x1"]);
    assert_eq!(
        sorted(top(r, Component::Pz, 4)),
        ["e_x2z", "ey_x1", "ey_x2", "ey_z"]
    );
    for (e, paper) in PAPER_Z {
        let got = pct(r, Component::Pz, e);
        assert!(
            (got - paper).abs() <= tol_pp,
            "pz {e}: {got:.2} % vs {paper} %"
        );
    }
}

#[test]
fn paper_case_with_the_papers_error_sizes_matches_figures_4_and_5() {
    // 0.001 mm and 0.001° (the defaults): C = S·e / ΣS·e.
    let r = at_case(100.0, NominalSizes::default());
    check_paper_lists(&r, 5.0);
    // Exactly: ez_x1 = 300·e_a / (1000·e_a + 3·e_l) with e_a = 0.001° in rad.
    let ea = 0.001f64.to_radians();
    let total = 1000.0 * ea + 3.0 * 0.001;
    assert!((pct(&r, Component::Py, "ez_x1") - 100.0 * 300.0 * ea / total).abs() < 1e-9);
    assert!((pct(&r, Component::Pz, "e_x2z") - 100.0 * 200.0 * ea / total).abs() < 1e-9);
}

#[test]
fn paper_case_with_equal_sizes_is_eq_6_as_printed() {
    // C = S / ΣS over all 22 errors: 300/1003, 200/1003 — within 1 pp.
    let r = at_case(100.0, equal());
    check_paper_lists(&r, 1.0);
    assert!((pct(&r, Component::Py, "ez_x1") - 100.0 * 300.0 / 1003.0).abs() < 1e-9);
    assert!((pct(&r, Component::Py, "ez_x2") - 100.0 * 200.0 / 1003.0).abs() < 1e-9);
    assert!((pct(&r, Component::Pz, "ey_x1") - 100.0 * 300.0 / 1003.0).abs() < 1e-9);
    // S itself does not depend on the sizes.
    let d = at_case(100.0, NominalSizes::default());
    for (a, b) in r.components.iter().zip(&d.components) {
        for e in &a.ranked {
            assert_eq!(e.s, b.get(&e.error).unwrap().s);
        }
    }
}

#[test]
fn coefficients_sum_to_one_per_direction() {
    for sizes in [NominalSizes::default(), equal()] {
        let r = at_case(100.0, sizes);
        assert_eq!(r.components.len(), 6);
        for c in &r.components {
            assert_eq!(c.ranked.len(), 22);
            let sum: f64 = c.ranked.iter().map(|e| e.c).sum();
            assert!((sum - 1.0).abs() < 1e-12, "{:?}: {sum}", c.component);
            assert!(c.ranked.windows(2).all(|w| w[0].c >= w[1].c));
        }
    }
}

#[test]
fn x_direction_of_the_derived_model_not_the_printed_one() {
    // The paper's x list (εz(x2), εz(z) "nearly 25 %" together... each 200/804
    // of the printed E_x) comes from printed E_x terms -L(εz(x2)+εz(z)) +
    // q5x(εz(x2)+εz(z)), which belong to E_y (docs/errata.md 004-3): about z,
    // a point moves along x by -(its y offset)·ε = -q5y·ε = 0 here.
    let r = at_case(100.0, equal());
    let px = r.component(Component::Px);
    assert_eq!(px.get("ez_x2").unwrap().s, 0.0);
    assert_eq!(px.get("ez_z").unwrap().s, 0.0);
    // What the derived model gives: εy(x1), εx1z, εy(x2), εx2z, each 60/263.
    assert_eq!(
        sorted(top(&r, Component::Px, 4)),
        ["e_x1z", "e_x2z", "ey_x1", "ey_x2"]
    );
    for e in ["ey_x1", "e_x1z", "ey_x2", "e_x2z"] {
        assert!((pct(&r, Component::Px, e) - 100.0 * 60.0 / 263.0).abs() < 1e-9);
    }
    assert!((pct(&r, Component::Px, "ey_z") - 100.0 * 20.0 / 263.0).abs() < 1e-9);
    // With 0.001 mm / 0.001°, the three dx terms come close behind the four
    // 60 mm/rad angles: 13.9 % each vs 13.3 % each; εy(z) 4.6 %.
    let d = at_case(100.0, NominalSizes::default());
    let ea = 0.001f64.to_radians();
    let total = 260.0 * ea + 3.0 * 0.001;
    assert_eq!(
        sorted(top(&d, Component::Px, 4)),
        ["e_x1z", "e_x2z", "ey_x1", "ey_x2"]
    );
    assert!((pct(&d, Component::Px, "ey_x1") - 100.0 * 60.0 * ea / total).abs() < 1e-9);
    assert!((pct(&d, Component::Px, "dx_x1") - 100.0 * 0.001 / total).abs() < 1e-9);

    // The printed E_x at the case, coefficient by coefficient (Section 4.3,
    // q2 = (200,0,0), q5 = (300,0,0), r = 20, z = 40, L = 100), normalised the
    // same way (Eq. 6): εz(x2) and εz(z) come out at 200/804 = 24.9 % each,
    // the paper's figure 3.
    let printed: [(&str, f64); 14] = [
        ("dx_x2", 1.0),
        ("dx_x1", 1.0),
        ("dx_z", 1.0),
        ("dy_z", 1.0),
        ("e_x2z", 60.0),
        ("ey_x2", 60.0),
        ("ey_z", 20.0),
        ("ex_x2", 60.0),
        ("ex_z", 20.0),
        ("e_yz", 60.0),
        ("e_x1z", 60.0),
        ("ey_x1", 60.0),
        ("ez_x2", 200.0),
        ("ez_z", 200.0),
    ];
    let sum: f64 = printed.iter().map(|p| p.1).sum();
    assert_eq!(sum, 804.0);
    assert!((100.0 * 200.0 / sum - 24.9).abs() < 0.05);
}

#[test]
fn ranking_depends_on_l() {
    let case = |l: f64| at_case(l, equal());
    // E_x has no L: the x direction is the same for every L.
    let base = case(100.0);
    for l in [0.0, 30.0, 250.0, 300.0, 500.0] {
        let r = case(l);
        for e in &base.component(Component::Px).ranked {
            let other = r.component(Component::Px).get(&e.error).unwrap();
            assert!((e.s - other.s).abs() < 1e-12 && (e.c - other.c).abs() < 1e-12);
        }
    }
    // y: S(εz(x1)) = |L - 400|, S(εz(x2)) = S(εz(z)) = |300 - L|,
    // S(εx1y) = |L - 200| at the case point (z: εy(x1), εy(x2) = εy(z) = εx2z,
    // εx1z likewise).
    for l in [0.0, 30.0, 100.0, 200.0, 250.0, 300.0, 500.0] {
        let r = case(l);
        let s = |c: Component, e: &str| r.component(c).get(e).unwrap().s;
        assert!((s(Component::Py, "ez_x1") - (l - 400.0).abs()).abs() < 1e-9);
        assert!((s(Component::Py, "ez_x2") - (300.0 - l).abs()).abs() < 1e-9);
        assert!((s(Component::Py, "ez_z") - (300.0 - l).abs()).abs() < 1e-9);
        assert!((s(Component::Py, "e_x1y") - (l - 200.0).abs()).abs() < 1e-9);
        assert!((s(Component::Pz, "ey_x1") - (400.0 - l).abs()).abs() < 1e-9);
        assert!((s(Component::Pz, "e_x2z") - (l - 300.0).abs()).abs() < 1e-9);
        assert!((s(Component::Pz, "e_x1z") - (200.0 - l).abs()).abs() < 1e-9);
    }
    // For L up to about 200 the paper's order holds: εz(x1) first, then εz(x2),
    // εz(z) (from L ≈ 240 the 60 mm/rad εx terms pass εz(x2), εz(z))…
    for l in [0.0, 30.0, 100.0, 150.0] {
        let r = case(l);
        assert_eq!(top(&r, Component::Py, 1), ["ez_x1"], "L = {l}");
        assert_eq!(
            sorted(top(&r, Component::Py, 3)),
            ["ez_x1", "ez_x2", "ez_z"]
        );
        assert_eq!(
            sorted(top(&r, Component::Pz, 4)),
            ["e_x2z", "ey_x1", "ey_x2", "ey_z"]
        );
    }
    // …and the printed 29/20/20 and 30/20/20/20 hold within 1 pp only near L = 100.
    let near = |l: f64| {
        let r = case(l);
        PAPER_Y
            .iter()
            .map(|(e, p)| (pct(&r, Component::Py, e) - p).abs())
            .chain(
                PAPER_Z
                    .iter()
                    .map(|(e, p)| (pct(&r, Component::Pz, e) - p).abs()),
            )
            .fold(0.0, f64::max)
    };
    assert!(near(100.0) < 1.0);
    assert!(near(30.0) > 2.0);
    assert!(near(200.0) > 5.0);
    // At L = 300 the grinding point has no x offset from the x2 and z slide
    // frames (q5x - L = 0): εz(x2), εz(z) (y) and εy(x2), εy(z), εx2z (z) drop out.
    let r = case(300.0);
    for (c, e) in [
        (Component::Py, "ez_x2"),
        (Component::Py, "ez_z"),
        (Component::Pz, "ey_x2"),
        (Component::Pz, "ey_z"),
        (Component::Pz, "e_x2z"),
    ] {
        assert_eq!(r.component(c).get(e).unwrap().c, 0.0, "{e}");
    }
    // Beyond L = 400 (a wheel reaching behind O1) εx1y, |L - 200|, leads.
    let r = case(500.0);
    assert_eq!(top(&r, Component::Py, 1), ["e_x1y"]);
}

#[test]
fn grid_mean_averages_the_pointwise_coefficients() {
    let (m, model) = grinder();
    let p = params(&m, 100.0);
    let sizes = NominalSizes::default().of(&m);
    let axes = vec![vec![-200.0, -100.0], vec![0.0, 50.0], vec![40.0]];
    let points = geometric::grid_points(&axes);
    assert_eq!(points.len(), 4);
    let mean = geometric::mean_over(&model, points.clone(), &p, &sizes);
    assert_eq!(mean.points, 4);
    let each: Vec<_> = points
        .iter()
        .map(|q| geometric::at_point(&model, q, &p, &sizes))
        .collect();
    for c in &mean.components {
        let sum: f64 = c.ranked.iter().map(|e| e.c).sum();
        assert!((sum - 1.0).abs() < 1e-12);
        for e in &c.ranked {
            let cs: Vec<f64> = each
                .iter()
                .map(|r| r.component(c.component).get(&e.error).unwrap().c)
                .collect();
            let avg = cs.iter().sum::<f64>() / 4.0;
            assert!((e.c - avg).abs() < 1e-12);
            assert_eq!(e.c_min, cs.iter().copied().fold(f64::INFINITY, f64::min));
            assert_eq!(
                e.c_max,
                cs.iter().copied().fold(f64::NEG_INFINITY, f64::max)
            );
        }
    }
    // A one-point grid is the point.
    let one = geometric::mean_over(&model, [CASE.to_vec()], &p, &sizes);
    assert_eq!(one, geometric::at_point(&model, &CASE, &p, &sizes));
}

#[test]
fn values_parsing() {
    let d = NominalSizes::default();
    assert_eq!(d.linear, 0.001);
    assert!((d.angular - 0.001f64.to_radians()).abs() < 1e-18);
    let v = d.parse("linear=0.002,angular=0.5deg").unwrap();
    assert_eq!(v.linear, 0.002);
    assert!((v.angular - 0.5f64.to_radians()).abs() < 1e-15);
    assert_eq!(v.squareness, v.angular);
    let v = d.parse("angular=1e-5rad,squareness=2e-5").unwrap();
    assert_eq!((v.linear, v.angular, v.squareness), (0.001, 1e-5, 2e-5));
    for bad in [
        "linear=abc",
        "linear=0",
        "angular=-1deg",
        "angular=xdeg",
        "linear=0.001deg",
        "volume=1",
        "linear",
        "",
        "linear=inf",
    ] {
        assert!(d.parse(bad).is_err(), "{bad}");
    }
}

// ---------------------------------------------------------------------------
// CLI.

fn file() -> String {
    grinder_file().display().to_string()
}

/// `chain sensitivity <grinder> --kind geometric --format json` with `extra`,
/// which must succeed; returns the document.
fn geometric_json(extra: &[&str]) -> Value {
    let f = file();
    let mut args = vec!["sensitivity", &f, "--kind", "geometric", "--format", "json"];
    args.extend_from_slice(extra);
    ok_json(&args)
}

fn check_components(doc: &Value) {
    let comps = doc["components"].as_object().unwrap();
    assert_eq!(
        comps.keys().collect::<Vec<_>>(),
        ["px", "py", "pz", "ox", "oy", "oz"]
    );
    for (name, list) in comps {
        let list = list.as_array().unwrap();
        assert_eq!(list.len(), 22, "{name}");
        let mut sum = 0.0;
        let mut last = f64::INFINITY;
        for e in list {
            assert!(e["error"].is_string());
            let s = e["s"].as_f64().unwrap();
            let c = e["c"].as_f64().unwrap();
            assert!(s >= 0.0 && (0.0..=1.0).contains(&c));
            assert!(c <= last, "{name} sorted by c");
            last = c;
            sum += c;
        }
        assert!((sum - 1.0).abs() < 1e-9, "{name}: {sum}");
    }
}

#[test]
fn cli_json_at_the_case_point() {
    let doc = geometric_json(&["--at", "x1=-100,x2=0,z=40"]);
    assert_eq!(doc["machine"], "internal_grinder");
    assert_eq!(doc["kind"], "geometric");
    assert_eq!(
        doc["at"],
        serde_json::json!({"x1": -100.0, "x2": 0.0, "z": 40.0})
    );
    check_components(&doc);
    let py = &doc["components"]["py"][0];
    assert_eq!(py["error"], "ez_x1");
    assert!((py["s"].as_f64().unwrap() - 300.0).abs() < 1e-9);
    assert_eq!(doc["components"]["pz"][0]["error"], "ey_x1");

    // Equal sizes: Eq. 6 as printed, 300/1003.
    let doc = geometric_json(&[
        "--at",
        "x1=-100,x2=0,z=40",
        "--values",
        "linear=0.001,angular=0.001",
    ]);
    let c = doc["components"]["py"][0]["c"].as_f64().unwrap();
    assert!((c - 300.0 / 1003.0).abs() < 1e-12);
    assert_eq!(doc["values"]["angular"], 0.001);
}

#[test]
fn cli_grid_mean_and_plot() {
    // A directory that does not exist yet: --plot makes it.
    let dir = scratch("plot");
    let _ = std::fs::remove_dir_all(&dir);
    let doc = geometric_json(&["--plot", dir.to_str().unwrap()]);
    assert!(doc["at"].is_null());
    assert_eq!(doc["points"], 75); // 5 × 3 × 5, the file's reliability grid
    assert_eq!(doc["grid"]["x2"], serde_json::json!([-50.0, 0.0, 50.0]));
    check_components(&doc);
    for c in ["px", "py", "pz", "ox", "oy", "oz"] {
        for ext in ["png", "svg"] {
            let f = dir.join(format!("geometric_{c}.{ext}"));
            assert!(
                std::fs::metadata(&f).map(|m| m.len() > 0).unwrap_or(false),
                "{f:?}"
            );
        }
    }
    let _ = std::fs::remove_dir_all(&dir);

    // --grid replaces an axis; a one-point grid is that point.
    let grid = geometric_json(&["--grid", "x1=-100", "--grid", "x2=0", "--grid", "z=40"]);
    assert_eq!(grid["points"], 1);
    let at = geometric_json(&["--at", "x1=-100,x2=0,z=40"]);
    let strip = |doc: &Value| -> Vec<(String, String, f64, f64)> {
        doc["components"]
            .as_object()
            .unwrap()
            .iter()
            .flat_map(|(k, list)| {
                list.as_array().unwrap().iter().map(move |e| {
                    (
                        k.clone(),
                        e["error"].as_str().unwrap().to_string(),
                        e["s"].as_f64().unwrap(),
                        e["c"].as_f64().unwrap(),
                    )
                })
            })
            .collect()
    };
    assert_eq!(strip(&grid), strip(&at));
}

#[test]
fn cli_table() {
    let text = ok_stdout(&[
        "sensitivity",
        &file(),
        "--kind",
        "geometric",
        "--at",
        "x1=-100,x2=0,z=40",
    ]);
    assert!(text.contains("py (sum of S·e"), "{text}");
    assert!(text.contains("ez_x1"), "{text}");
}

/// Runs a command that must fail ([`fails`]) with a message containing each
/// of `needles`.
fn fails_naming(args: &[&str], needles: &[&str]) {
    // miette wraps long messages: compare with the frame and line breaks removed.
    let err = unwrapped(&fails(args));
    for n in needles {
        assert!(err.contains(n), "{args:?}: `{n}` not in\n{err}");
    }
}

#[test]
fn cli_errors() {
    let f = file();
    let g = ["sensitivity", &f, "--kind", "geometric"];
    let with = |extra: &[&'static str]| -> Vec<String> {
        g.iter()
            .map(|s| s.to_string())
            .chain(extra.iter().map(|s| s.to_string()))
            .collect()
    };
    let run = |extra: &[&'static str], needles: &[&str]| {
        let args = with(extra);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        fails_naming(&args, needles);
    };
    // An unknown variable in --at, with a hint.
    run(
        &["--at", "x1=-100,x3=0,z=40"],
        &["--at: `x3` is not an axis variable", "x1"],
    );
    // A missing one.
    run(
        &["--at", "x1=-100,z=40"],
        &["no value for axis variable `x2`"],
    );
    // Bad --values.
    run(
        &["--at", "x1=-100,x2=0,z=40", "--values", "linear=abc"],
        &["--values", "not a length"],
    );
    run(
        &["--at", "x1=-100,x2=0,z=40", "--values", "angular=-1deg"],
        &["--values", "positive"],
    );
    run(
        &["--at", "x1=-100,x2=0,z=40", "--values", "volume=1"],
        &["--values", "unknown error kind `volume`"],
    );
    // A bad --grid axis.
    run(&["--grid", "w=1,2"], &["unknown axis variable `w`"]);
    // --values is for the geometric kind only.
    fails_naming(
        &["sensitivity", &f, "--values", "linear=0.001"],
        &["--values applies only to --kind geometric"],
    );
}
