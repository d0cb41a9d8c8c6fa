//! `chain reliability --method subset|directional` and `--cov` end to end on
//! the gantry grinder (seed 000's Table 1 inputs, normal): every component
//! is one upper tolerance in normal inputs, so FORM's `Φ(−β)` is the exact
//! p_f of every case (Eq. 21, 31), the reference here. Tolerance: at least
//! 97 % of the 375 cases within 3 of the sampler's standard errors and every
//! case within 5 (375 normal deviates exceed 3σ about once).

use crate::common;

use common::cli::{fails, ok_json, ok_stdout};
use common::example_path;
use serde_json::Value;

fn gantry() -> String {
    example_path("gantry_grinder.yaml")
        .to_str()
        .unwrap()
        .to_string()
}

fn json(extra: &[&str]) -> Value {
    let g = gantry();
    let mut args = vec!["reliability", g.as_str(), "--format", "json"];
    args.extend_from_slice(extra);
    ok_json(&args)
}

fn against_form(doc: &Value) {
    let form = json(&[]);
    let (a, b) = (
        doc["results"].as_array().unwrap(),
        form["results"].as_array().unwrap(),
    );
    assert_eq!(a.len(), 375);
    let mut within3 = 0;
    for (s, f) in a.iter().zip(b) {
        assert_eq!(s["point"], f["point"]);
        let (p, se, exact) = (
            s["pf"].as_f64().unwrap(),
            s["std_error"].as_f64().unwrap(),
            f["pf"].as_f64().unwrap(),
        );
        let z = (p - exact).abs() / se;
        assert!(z < 5.0, "{s} vs {exact}");
        within3 += usize::from(z < 3.0);
        assert_eq!(s["converged"], true, "{s}");
        assert!(s["samples"].as_u64().unwrap() > 0);
    }
    assert!(
        within3 as f64 >= 0.97 * 375.0,
        "{within3} of 375 within 3 se"
    );
}

#[test]
fn subset_on_the_gantry_matches_the_exact_pf_and_reports_its_levels() {
    let doc = json(&["--method", "subset", "--samples", "2000", "--seed", "1"]);
    assert_eq!(doc["method"], "subset");
    against_form(&doc);
    let first = &doc["results"][0];
    let levels = first["levels"].as_array().unwrap();
    assert!(!levels.is_empty());
    assert_eq!(levels.last().unwrap()["threshold"], 0.0);
    assert!(levels[0]["acceptance_rate"].is_null());
    assert_eq!(first["sampling"]["stopped_by"], "samples");
    // The table names the method and the levels.
    let g = gantry();
    let t = ok_stdout(&["reliability", &g, "--method", "subset", "--samples", "500"]);
    assert!(
        t.contains("(subset simulation, upper)") && t.contains("; subset: "),
        "{t}"
    );
}

#[test]
fn directional_on_the_gantry_matches_the_exact_pf() {
    let doc = json(&[
        "--method",
        "directional",
        "--samples",
        "4000",
        "--seed",
        "2",
    ]);
    assert_eq!(doc["method"], "directional");
    against_form(&doc);
}

#[test]
fn cov_stops_each_case_at_its_target_or_marks_it_not_converged() {
    let doc = json(&["--method", "mc", "--cov", "0.02"]);
    for c in doc["results"].as_array().unwrap() {
        assert!(c["cov"].as_f64().unwrap() <= 0.02, "{c}");
        assert_eq!(c["sampling"]["stopped_by"], "target_cov");
        assert_eq!(c["sampling"]["target_cov"], 0.02);
        assert_eq!(c["converged"], true);
    }
    // A budget of 70,000 samples: the small-p_f cases run out.
    let doc = json(&["--method", "mc", "--cov", "0.01", "--samples", "70000"]);
    let bad: Vec<&Value> = doc["results"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|c| c["converged"] == false)
        .collect();
    assert!(!bad.is_empty());
    for c in &bad {
        assert_eq!(c["sampling"]["stopped_by"], "budget");
        assert!(c["cov"].as_f64().unwrap() > 0.01);
        assert_eq!(c["samples"], 70000);
    }
    let g = gantry();
    let csv = ok_stdout(&[
        "reliability",
        &g,
        "--method",
        "mc",
        "--cov",
        "0.01",
        "--samples",
        "70000",
        "--format",
        "csv",
    ]);
    assert!(csv
        .lines()
        .next()
        .unwrap()
        .ends_with(",stopped_by,sampler_converged"));
    assert!(csv.contains(",budget,false"));
    let table = ok_stdout(&[
        "reliability",
        &g,
        "--method",
        "mc",
        "--cov",
        "0.01",
        "--samples",
        "70000",
    ]);
    assert!(table.contains("* not converged at") && table.contains("without meeting its rule"));
    // The importance sampling is exact here: one block, target met.
    let doc = json(&["--method", "is", "--cov", "0.01"]);
    let c = &doc["results"][0];
    assert_eq!(c["sampling"]["stopped_by"], "target_cov");
    assert_eq!(c["samples"], 65536);
    assert_eq!(c["converged"], true); // FORM's (it centred the sampling)
    assert_eq!(c["sampling"]["converged"], true);
}

#[test]
fn bad_cov_is_refused_with_the_option_named() {
    let g = gantry();
    for v in ["0", "-0.1", "NaN", "1.5", "inf", "x"] {
        let err = fails(&["reliability", &g, "--method", "mc", "--cov", v]);
        assert!(err.contains("--cov"), "{v}: {err}");
    }
    let err = fails(&["reliability", &g, "--cov", "0.1"]);
    assert!(err.contains("--cov") && err.contains("FORM"), "{err}");
    let err = fails(&["reliability", &g, "--method", "subset", "--samples", "1005"]);
    assert!(err.contains("multiple of 1/p0"), "{err}");
}

/// The sampler options that need no model are refused before the load,
/// with the option named: SORM draws no samples (so `--cov` with it is an
/// error, not ignored), subset's samples per level are a multiple of
/// 1/p0 = 10.
#[test]
fn sampler_options_are_checked_with_their_name() {
    let g = gantry();
    let err = fails(&["reliability", &g, "--method", "sorm", "--cov", "0.1"]);
    assert!(
        err.contains("'--cov'") && err.contains("SORM draws no samples"),
        "{err}"
    );
    for n in ["5", "1005"] {
        let err = fails(&["reliability", &g, "--method", "subset", "--samples", n]);
        assert!(
            err.contains("'--samples'") && err.contains(&format!("(found {n})")),
            "{n}: {err}"
        );
    }
    // Checked before the machine file is read: a missing file is not reached.
    let err = fails(&[
        "reliability",
        "no/such.yaml",
        "--method",
        "sorm",
        "--cov",
        "0.1",
    ]);
    assert!(err.contains("'--cov'"), "{err}");
    // The sample count and the target's range too, for every command that
    // samples, before the model is built.
    for (command, args) in [
        ("reliability", &["--method", "mc", "--samples", "0"][..]),
        (
            "reliability",
            &["--method", "directional", "--samples", "0"],
        ),
        (
            "path",
            &["--axes", "x.csv", "--method", "is", "--samples", "0"],
        ),
        ("reliability", &["--method", "mc", "--cov", "1.5"]),
        ("path", &["--axes", "x.csv", "--method", "mc", "--cov", "0"]),
    ] {
        let err = fails(&[&[command, "no/such.yaml"][..], args].concat());
        let err = err
            .split_whitespace()
            .filter(|w| *w != "│")
            .collect::<Vec<_>>()
            .join(" ");
        let option = if args.contains(&"--cov") {
            "'--cov'"
        } else {
            "'--samples'"
        };
        assert!(err.contains(option), "{command} {args:?}: {err}");
        assert!(!err.contains("no/such.yaml"), "{command} {args:?}: {err}");
        assert!(
            err.contains("the number of samples must be between 1 and 68719476736 (found 0)")
                || err.contains("the target coefficient of variation must be in (0, 1]"),
            "{command} {args:?}: {err}"
        );
    }
}
