//! Reliability, sensitivity and allocation over the coefficients of a
//! function slot, on `examples/machines/spread_along_axis.yaml`: a three-axis
//! machine whose X positioning error is `EXX(x) = EXX_0 + EXX_1·x` with
//! normal `EXX_0 ~ N(0, σ0)`, `EXX_1 ~ N(μ1, σ1)`.
//!
//! In the tool frame `px = −EXX_0 − x·EXX_1` (checked first), so px is
//! normal with mean `μ(x) = −x·μ1` and standard deviation
//! `σ(x) = √(σ0² + x²σ1²)`; FORM on this affine upper-sided limit state
//! `g = I − px` is exact: `R(x) = Φ((I − μ(x))/σ(x))`, and with
//! `β = (I − μ)/σ` the reliability sensitivities are
//! `∂R/∂μ_j = −φ(β)·c_j/σ`, `∂R/∂σ_j = −φ(β)·β·c_j²σ_j/σ²` with
//! `c = (−1, −x)`, importance `c_j²σ_j²/σ²`. Every expected number below is
//! that closed form, with `Φ` from Cody's `erfc` in `tests/it/common` (not the
//! library's).

use crate::common;

use chain_core::model::Component;
use common::cli::ok_json;
use common::{example_path, load_example, normal_cdf};
use reliability::{machine, Algorithm, Form, Target};
use serde_json::Value;

const FILE: &str = "spread_along_axis.yaml";
/// Tolerance of px, mm.
const I: f64 = 0.01;
const SIGMA0: f64 = 0.002;
const MU1: f64 = -5.0e-6;
const SIGMA1: f64 = 3.0e-6;

fn sigma(x: f64, s0: f64, s1: f64) -> f64 {
    (s0 * s0 + x * x * s1 * s1).sqrt()
}

/// `R(x) = Φ((I − μ(x))/σ(x))` with `μ(x) = −x·μ1`.
fn closed_form_reliability(x: f64, s0: f64, s1: f64) -> f64 {
    normal_cdf((I + x * MU1) / sigma(x, s0, s1))
}

fn phi(b: f64) -> f64 {
    (-0.5 * b * b).exp() / (2.0 * std::f64::consts::PI).sqrt()
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()) + 1e-300
}

fn file() -> String {
    example_path(FILE).to_str().unwrap().to_string()
}

#[test]
fn px_is_the_slot_times_its_basis() {
    let m = load_example(FILE);
    let model = chain_core::derive(&m);
    let text = |c: Component, name: &str| {
        let j = m.error_index(name).unwrap();
        model.coefficient(c, j).to_text(&|s| model.symbol_name(s))
    };
    assert_eq!(text(Component::Px, "EXX_0"), "-1");
    assert_eq!(text(Component::Px, "EXX_1"), "-x");
    assert_eq!(text(Component::Pz, "EZX_2"), "-x^2");
    assert_eq!(text(Component::Py, "EXX_1"), "0");
}

#[test]
fn px_spread_and_reliability_along_x_are_the_closed_forms() {
    let m = load_example(FILE);
    let model = chain_core::compile(&m);
    let study = machine::study(&m, &model, &[], None).expect("study");
    let ix = study.variables().iter().position(|v| v == "x").unwrap();
    let r = study
        .run(&Algorithm::Form(Form::default()), &())
        .expect("form");
    let np = study.points().len();
    assert_eq!(np, 20);
    let t = study
        .targets()
        .iter()
        .position(|t| *t == Target::Component(Component::Px))
        .unwrap();
    let mut by_x: Vec<(f64, f64)> = Vec::new();
    for (p, point) in study.points().iter().enumerate() {
        let x = point[ix];
        let moments = study.moments(p).unwrap();
        let s = sigma(x, SIGMA0, SIGMA1);
        assert!(
            close(moments.std(Component::Px), s, 1e-14),
            "std of px at x = {x}: {} vs sqrt(σ0² + x²σ1²) = {s}",
            moments.std(Component::Px)
        );
        assert!(close(moments.mean[0], -x * MU1, 1e-14), "mean of px at {x}");
        let case = &r.cases[t * np + p];
        let want = closed_form_reliability(x, SIGMA0, SIGMA1);
        assert!(
            close(1.0 - case.reliability, 1.0 - want, 1e-9),
            "R at x = {x}: FORM {} vs Φ((I − μ)/σ) = {want}",
            case.reliability
        );
        if !by_x.iter().any(|(v, _)| *v == x) {
            by_x.push((x, case.reliability));
        }
    }
    // The spread grows along x, so the reliability falls: 100.00 % at x = 0
    // down to 91.72 % at x = 1000.
    by_x.sort_by(|a, b| a.0.total_cmp(&b.0));
    assert_eq!(by_x.len(), 5);
    for w in by_x.windows(2) {
        assert!(w[1].1 < w[0].1, "R falls along x: {by_x:?}");
    }
    assert!((by_x[4].1 - 0.9172).abs() < 1e-4, "{by_x:?}");
    assert!(by_x[0].1 > 1.0 - 3e-7);
    // The study of the generated type for the same file is the same study.
    let generated = machine::study(&m, &SpreadAlongAxis, &[], None).expect("study");
    let g = generated
        .run(&Algorithm::Form(Form::default()), &())
        .expect("form");
    for (a, b) in g.cases.iter().zip(&r.cases) {
        assert!(close(a.reliability, b.reliability, 1e-15));
    }
}

chain::machine!(SpreadAlongAxis = "examples/machines/spread_along_axis.yaml");

/// The `px` results of `chain reliability --format json`, `(x, R)`.
fn cli_px(doc: &Value) -> Vec<(f64, f64)> {
    doc["results"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|r| r["component"] == "px")
        .map(|r| {
            (
                r["point"]["x"].as_f64().unwrap(),
                r["reliability"].as_f64().unwrap(),
            )
        })
        .collect()
}

#[test]
fn cli_reliability_runs_over_the_coefficients() {
    let f = file();
    let doc = ok_json(&["reliability", &f, "--format", "json"]);
    let px = cli_px(&doc);
    assert_eq!(px.len(), 20);
    for (x, r) in px {
        let want = closed_form_reliability(x, SIGMA0, SIGMA1);
        assert!(close(1.0 - r, 1.0 - want, 1e-9), "x = {x}: {r} vs {want}");
    }
    let min = doc["summary"]["px"]["min"].as_f64().unwrap();
    assert!(close(
        min,
        closed_form_reliability(1000.0, SIGMA0, SIGMA1),
        1e-12
    ));
    assert_eq!(doc["summary"]["px"]["met"], false);
}

#[test]
fn cli_sensitivity_to_the_coefficients_is_the_closed_form() {
    let f = file();
    for x in [250.0, 1000.0] {
        let at = format!("x={x},y=0,z=0");
        let doc = ok_json(&["sensitivity", &f, "--at", &at, "--format", "json"]);
        let px = doc["components"]["px"].as_array().unwrap();
        let entry = |name: &str| px.iter().find(|e| e["error"] == name).unwrap().clone();
        let s = sigma(x, SIGMA0, SIGMA1);
        let beta = (I + x * MU1) / s;
        for (name, c, sj) in [("EXX_0", -1.0, SIGMA0), ("EXX_1", -x, SIGMA1)] {
            let e = entry(name);
            let dr_dmean = -phi(beta) * c / s;
            let dr_dstd = -phi(beta) * beta * c * c * sj / (s * s);
            let importance = c * c * sj * sj / (s * s);
            let got = |k: &str| e[k].as_f64().unwrap();
            assert!(close(got("dr_dmean"), dr_dmean, 1e-9), "{name} at {x}: {e}");
            assert!(close(got("dr_dstd"), dr_dstd, 1e-9), "{name} at {x}: {e}");
            assert!(close(got("importance"), importance, 1e-12), "{name}: {e}");
        }
        // At x = 1000 the scale coefficient dominates: 9/13 of the variance.
        if x == 1000.0 {
            assert_eq!(px[0]["error"], "EXX_1");
        }
    }
}

#[test]
fn geometric_sensitivity_sizes_a_coefficient_by_its_travel() {
    // e of EXX_1 is 0.001 mm over the largest |x| of the grid (1000 mm), so
    // at x = 1000 both coefficients move px by 0.001 mm: C = 50 % each.
    let f = file();
    let doc = ok_json(&[
        "sensitivity",
        &f,
        "--kind",
        "geometric",
        "--at",
        "x=1000,y=0,z=0",
        "--format",
        "json",
    ]);
    let px = doc["components"]["px"].as_array().unwrap();
    let entry = |name: &str| px.iter().find(|e| e["error"] == name).unwrap().clone();
    let (e0, e1) = (entry("EXX_0"), entry("EXX_1"));
    assert_eq!(e1["s"].as_f64().unwrap(), 1000.0);
    assert!(close(e1["e"].as_f64().unwrap(), 1e-6, 1e-15));
    assert!(close(e0["c"].as_f64().unwrap(), 0.5, 1e-12), "{e0}");
    assert!(close(e1["c"].as_f64().unwrap(), 0.5, 1e-12), "{e1}");
    // pz's sag EZX_2·x²: e = 0.001/1000², S = x².
    let pz = doc["components"]["pz"].as_array().unwrap();
    let sag = pz.iter().find(|e| e["error"] == "EZX_2").unwrap();
    assert!(close(sag["e"].as_f64().unwrap(), 1e-9, 1e-15), "{sag}");
}

#[test]
fn cli_allocation_tightens_the_coefficients_to_the_requirement() {
    let f = file();
    let doc = ok_json(&["allocate", &f, "--format", "json"]);
    let fin = &doc["final"];
    assert_eq!(fin["met"], true);
    let std = |name: &str| fin["std"][name].as_f64().unwrap();
    let (s0, s1) = (std("EXX_0"), std("EXX_1"));
    // Only px misses the requirement (min 95 % at x = 1000): the optimum
    // tightens the scale coefficient most and leaves the others.
    assert!(s1 < SIGMA1 && s0 <= SIGMA0, "{fin}");
    assert!(SIGMA1 / s1 > SIGMA0 / s0);
    for other in ["EZX_2", "EZZ", "EYY"] {
        let initial = doc["initial"]["std"][other].as_f64().unwrap();
        assert_eq!(std(other), initial, "{other}");
    }
    // Recomputed from the closed form with the allocated stds: the minimum
    // (at x = 1000) is the requirement, 95 %, and the mean over the grid's
    // five x values is above 97 %.
    let r: Vec<f64> = [0.0, 250.0, 500.0, 750.0, 1000.0]
        .iter()
        .map(|&x| closed_form_reliability(x, s0, s1))
        .collect();
    assert!((r[4] - 0.95).abs() < 1e-8, "{r:?}");
    assert!(r.iter().sum::<f64>() / 5.0 > 0.97, "{r:?}");
    let summary_min = fin["summary"]["px"]["min"].as_f64().unwrap();
    assert!(close(summary_min, r[4], 1e-9));
    // The cost Σ (σ0/σ − 1) over the two tightened coefficients.
    let cost = SIGMA0 / s0 - 1.0 + SIGMA1 / s1 - 1.0;
    assert!(close(fin["cost"].as_f64().unwrap(), cost, 1e-9), "{fin}");
}
