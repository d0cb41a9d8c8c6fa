//! End-to-end tests of `chain reliability` and `chain sensitivity` on the
//! gantry grinder of seed 000 (the CLI + JSON contract of
//! shared/spec/machine-format.md, section 3).

use crate::common;

use std::path::{Path, PathBuf};

use common::cli::{chain, fails, ok, ok_json, ok_stdout, scratch, unwrapped};
use common::example_path;
use serde_json::Value;

fn gantry() -> PathBuf {
    example_path("gantry_grinder.yaml")
}

/// `chain <command> <gantry> --format json` with `extra`, which must succeed;
/// returns the document.
fn gantry_json(command: &str, extra: &[&str]) -> Value {
    let file = gantry();
    let mut args = vec![command, file.to_str().unwrap(), "--format", "json"];
    args.extend_from_slice(extra);
    ok_json(&args)
}

#[test]
fn form_json_follows_the_contract_and_table_2() {
    let doc = gantry_json("reliability", &[]);
    assert_eq!(doc["machine"], "gantry_grinder");
    assert_eq!(doc["method"], "form");
    let results = doc["results"].as_array().expect("results");
    assert_eq!(results.len(), 375);
    let first = &results[0];
    assert_eq!(first["component"], "px");
    assert_eq!(first["point"]["x"], 0.0);
    assert_eq!(first["point"]["y"], -1500.0);
    assert_eq!(first["point"]["z"], 600.0);
    // Table 2 prints 88.83 % at (y, z) = (-1500, 600); the model gives 88.73 %.
    let r = first["reliability"].as_f64().unwrap();
    assert!((100.0 * r - 88.83).abs() < 0.25, "{r}");
    assert!((first["pf"].as_f64().unwrap() - (1.0 - r)).abs() < 1e-12);
    assert!((first["beta"].as_f64().unwrap() - 1.2123).abs() < 1e-3);
    assert!(first.get("std_error").is_none());
    // Section 3.3: px min 86.07 %, mean 92.16 %.
    let px = &doc["summary"]["px"];
    assert!((100.0 * px["min"].as_f64().unwrap() - 86.07).abs() < 0.35);
    assert!((100.0 * px["mean"].as_f64().unwrap() - 92.16).abs() < 0.35);
    assert_eq!(px["met"], false);
    assert_eq!(doc["requirement"]["met"], false);
}

#[test]
fn sampling_methods_add_std_error_and_samples_and_are_reproducible() {
    let file = gantry();
    let args = [
        "reliability",
        file.to_str().unwrap(),
        "--method",
        "mc",
        "--samples",
        "5000",
        "--seed",
        "42",
        "--format",
        "json",
    ];
    let a = ok(&args);
    let b = chain(&args);
    assert_eq!(a.stdout, b.stdout, "same seed, same output");
    let doc: Value = serde_json::from_slice(&a.stdout).unwrap();
    assert_eq!(doc["method"], "mc");
    let r = &doc["results"][0];
    assert_eq!(r["samples"], 5000);
    assert!(r["std_error"].as_f64().unwrap() > 0.0);
    // No progress bar or note leaks into the output streams when not a terminal.
    assert!(
        a.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&a.stderr)
    );

    let doc = gantry_json("reliability", &["--method", "is", "--samples", "500"]);
    assert_eq!(doc["method"], "is");
    // Linear limit state in normal inputs: zero variance (Eq. 28 with h = β).
    for r in doc["results"].as_array().unwrap() {
        assert!(r["std_error"].as_f64().unwrap() < 1e-12);
        assert_eq!(r["samples"], 500);
    }
}

#[test]
fn csv_and_table_formats() {
    let file = gantry();
    let text = ok_stdout(&["reliability", file.to_str().unwrap(), "--format", "csv"]);
    let mut lines = text.lines();
    // FORM's account is appended after the contract's columns.
    assert_eq!(
        lines.next(),
        Some("component,x,y,z,reliability,pf,beta,termination,converged,iterations,exact,value_calls,gradient_calls")
    );
    assert_eq!(lines.count(), 375);
    assert!(text.contains("\npx,0,-1500,600,0.88729"));

    let text = ok_stdout(&["reliability", file.to_str().unwrap()]);
    // The maps of Tables 2-4 and the summary lines.
    assert!(text.contains("px: reliability (%) over (y, z)"));
    assert!(text.contains("88.73"));
    assert!(text.contains("summary: mean 92.18 %, min 85.98 %"));
    assert!(text.contains("NOT met"));
}

#[test]
fn system_targets_and_overrides() {
    let file = gantry();
    let doc = gantry_json(
        "reliability",
        &[
            "--method",
            "is",
            "--samples",
            "2000",
            "--system",
            "volumetric",
            "--system-tolerance",
            "0.05",
            "--grid",
            "x=1000",
            "--grid",
            "y=1500",
            "--grid",
            "z=1400",
        ],
    );
    let results = doc["results"].as_array().unwrap();
    assert_eq!(results.len(), 4);
    let vol = &results[3];
    assert_eq!(vol["component"], "volumetric");
    // Inside 4 standard errors of the 10⁷-sample Monte Carlo value 0.2069
    // (tests/it/papers/reliability_gantry.rs) at the corner (1000, 1500, 1400).
    let pf = vol["pf"].as_f64().unwrap();
    let se = vol["std_error"].as_f64().unwrap();
    assert!((pf - 0.2069).abs() < 4.0 * se + 2e-4, "{pf} ± {se}");

    let out = ok(&[
        "reliability",
        file.to_str().unwrap(),
        "--sided",
        "two",
        "--format",
        "json",
    ]);
    // FORM is not exact for two-sided tolerances: a note on stderr, not stdout.
    assert!(String::from_utf8_lossy(&out.stderr).contains("first-order approximation"));
    let doc: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(doc["sided"], "two");
}

#[test]
fn clear_errors_name_the_file_and_the_missing_key() {
    let dir = scratch("errors");
    let src = std::fs::read_to_string(gantry()).unwrap();
    let nostat = dir.join("nostat.yaml");
    std::fs::write(
        &nostat,
        src.replace("  eyx: {dist: normal, mean: 0, std: 0.06/6000}\n", ""),
    )
    .unwrap();
    let norel = dir.join("norel.yaml");
    std::fs::write(
        &norel,
        &src[..src.find("reliability:\n  tolerance").unwrap()],
    )
    .unwrap();
    let symbolic = dir.join("symbolic.yaml");
    std::fs::write(
        &symbolic,
        src.replace("parameters: {}", "parameters: {L: null}")
            .replace("tool_point: [0, 0, 0]", "tool_point: [0, 0, -L]"),
    )
    .unwrap();
    let cases: [(&Path, &str, &[&str]); 3] = [
        (&nostat, "statistics.eyx", &["nostat.yaml"]),
        (&norel, "`reliability`", &["norel.yaml"]),
        (&symbolic, "--param L=", &["symbolic.yaml", "parameter `L`"]),
    ];
    for (file, key, more) in cases {
        for cmd in ["reliability", "sensitivity"] {
            let err = fails(&[cmd, file.to_str().unwrap(), "--format", "json"]);
            assert!(err.contains(key), "{cmd}: {err}");
            for m in more {
                assert!(err.contains(m), "{cmd}: {err}");
            }
        }
    }
    // With a value the symbolic machine runs.
    ok(&[
        "reliability",
        symbolic.to_str().unwrap(),
        "--param",
        "L=100",
        "--format",
        "json",
    ]);
    // Bad command-line values are errors, not panics.
    for args in [
        vec!["reliability", "--grid", "x=a,b"],
        vec!["reliability", "--grid", "w=1"],
        vec!["reliability", "--method", "mc", "--samples", "0"],
        vec!["sensitivity", "--at", "x=0,y=0"],
    ] {
        let mut full = vec![args[0], file_str(&gantry())];
        full.extend_from_slice(&args[1..]);
        fails(&full);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

fn file_str(p: &Path) -> &'static str {
    Box::leak(p.to_string_lossy().into_owned().into_boxed_str())
}

#[test]
fn plots_are_valid_non_trivial_png_and_svg() {
    let dir = scratch("plots");
    // JSON only on stdout.
    gantry_json("reliability", &["--plot", dir.to_str().unwrap()]);
    for stem in [
        "reliability_px",
        "reliability_py",
        "reliability_pz",
        "sensitivity_px",
        "sensitivity_py",
        "sensitivity_pz",
    ] {
        let png = dir.join(format!("{stem}.png"));
        let bytes = std::fs::read(&png).unwrap_or_else(|_| panic!("{} exists", png.display()));
        assert!(bytes.len() > 10_000, "{stem}.png is {} bytes", bytes.len());
        let decoder = png::Decoder::new(std::io::Cursor::new(&bytes));
        let mut reader = decoder.read_info().expect("valid PNG");
        let mut buf = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut buf).expect("PNG frame");
        assert!(info.width >= 800 && info.height >= 500);
        let px = info.color_type.samples();
        let pixels = &buf[..info.buffer_size()];
        let mut colours = std::collections::HashSet::new();
        let mut non_white = 0usize;
        for p in pixels.chunks_exact(px) {
            colours.insert(p[..3].to_vec());
            if p[..3] != [255, 255, 255] {
                non_white += 1;
            }
        }
        let total = (info.width * info.height) as usize;
        // A heat map is mostly coloured cells; a bar chart has bars and text.
        assert!(colours.len() >= 10, "{stem}: {} colours", colours.len());
        assert!(
            non_white * 20 > total,
            "{stem}: {non_white} of {total} pixels drawn"
        );

        let svg = std::fs::read_to_string(dir.join(format!("{stem}.svg"))).expect("svg");
        assert!(svg.len() > 5_000, "{stem}.svg is {} bytes", svg.len());
        assert!(svg.contains("<svg") && svg.trim_end().ends_with("</svg>"));
        assert!(svg.matches("<rect").count() >= 10, "{stem}.svg");
        assert!(svg.contains("<text"), "{stem}.svg has text");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn sensitivity_json_is_sorted_and_finds_figures_6_to_8() {
    let file = gantry();
    let doc = gantry_json("sensitivity", &[]);
    assert_eq!(doc["machine"], "gantry_grinder");
    assert!(doc["at"].is_null());
    // Figure 6 (x-direction): eyx, ezx, ezz, Sxy are the sensitive errors.
    let px = doc["components"]["px"].as_array().unwrap();
    assert_eq!(px.len(), 21);
    let mut top: Vec<&str> = px[..4]
        .iter()
        .map(|e| e["error"].as_str().unwrap())
        .collect();
    top.sort_unstable();
    assert_eq!(top, ["Sxy", "eyx", "ezx", "ezz"]);
    let abs: Vec<f64> = px
        .iter()
        .map(|e| e["dr_dstd"].as_f64().unwrap().abs())
        .collect();
    assert!(abs.windows(2).all(|w| w[0] >= w[1]), "sorted by |dr_dstd|");
    let imp: f64 = px.iter().map(|e| e["importance"].as_f64().unwrap()).sum();
    assert!((imp - 1.0).abs() < 1e-9);

    let doc = gantry_json("sensitivity", &["--at", "x=0,y=1500,z=600"]);
    assert_eq!(doc["at"]["y"], 1500.0);
    let px = doc["components"]["px"].as_array().unwrap();
    // At (y, z) = (1500, 600): ∂R/∂σ = −φ(β)·β·S²σ/σ_E² (Eq. 32-33); the
    // largest is Sxy (coefficient y = 1500, σ = 0.03/3000).
    assert_eq!(px[0]["error"], "Sxy");
    assert!(px[0]["dr_dstd"].as_f64().unwrap() < 0.0);

    let text = ok_stdout(&["sensitivity", file.to_str().unwrap()]);
    assert!(text.contains("px (exact), sorted by |dR/dstd|"));
}

/// The PNG and SVG of `stem` in `dir` are valid, non-empty charts.
fn assert_chart(dir: &Path, stem: &str, bars: usize) {
    let png = dir.join(format!("{stem}.png"));
    let bytes = std::fs::read(&png).unwrap_or_else(|_| panic!("{} exists", png.display()));
    let decoder = png::Decoder::new(std::io::Cursor::new(&bytes));
    let mut reader = decoder.read_info().expect("valid PNG");
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).expect("PNG frame");
    assert!(info.width >= 800 && info.height >= 500, "{stem}.png size");
    let px = info.color_type.samples();
    let drawn = buf[..info.buffer_size()]
        .chunks_exact(px)
        .filter(|p| p[..3] != [255, 255, 255])
        .count();
    assert!(
        drawn * 20 > (info.width * info.height) as usize,
        "{stem}.png"
    );
    let svg = std::fs::read_to_string(dir.join(format!("{stem}.svg"))).expect("svg");
    assert!(svg.contains("<svg") && svg.trim_end().ends_with("</svg>"));
    assert!(svg.matches("<rect").count() >= bars, "{stem}.svg has bars");
}

#[test]
fn sensitivity_plot_draws_the_reliability_sensitivity_charts() {
    let file = gantry();
    // The grid mean (Figures 6-8) and one point.
    for (name, extra) in [
        ("sens_plot_mean", vec![]),
        ("sens_plot_at", vec!["--at", "x=0,y=1500,z=600"]),
    ] {
        let dir = scratch(name);
        let mut args = vec![
            "sensitivity",
            file.to_str().unwrap(),
            "--format",
            "json",
            "--plot",
            dir.to_str().unwrap(),
        ];
        args.extend_from_slice(&extra);
        let out = common::cli::success(chain(&args));
        // JSON alone on stdout, the files named on stderr.
        let doc: Value = serde_json::from_slice(&out.stdout).expect("JSON");
        assert!(doc["components"]["px"].is_array());
        let err = String::from_utf8_lossy(&out.stderr);
        for stem in ["sensitivity_px", "sensitivity_py", "sensitivity_pz"] {
            // At one point few errors act on a component.
            assert_chart(&dir, stem, if extra.is_empty() { 10 } else { 3 });
            assert!(err.contains(&format!("{stem}.png")), "{err}");
        }
        let svg = std::fs::read_to_string(dir.join("sensitivity_px.svg")).unwrap();
        if extra.is_empty() {
            assert!(svg.contains("grid mean"), "title says where");
        } else {
            assert!(svg.contains("at x = 0"), "title says where");
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}

#[test]
fn form_reports_termination_and_calls_in_every_format() {
    let file = gantry();
    // One-sided components in normal inputs: closed form, exact, no call.
    let doc = gantry_json("reliability", &[]);
    for case in doc["results"].as_array().unwrap() {
        assert_eq!(case["termination"], "closed_form");
        assert_eq!(case["converged"], true);
        assert_eq!(case["iterations"], 0);
        assert_eq!(case["exact"], true);
        assert_eq!(case["calls"]["values"], 0);
        assert_eq!(case["calls"]["gradients"], 0);
    }
    // Two-sided: closed form per branch, not exact (the far side).
    let doc = gantry_json("reliability", &["--sided", "two"]);
    assert_eq!(doc["results"][0]["exact"], false);
    assert_eq!(doc["results"][0]["termination"], "closed_form");

    // The volumetric norm is iterated (HL-RF): calls are counted, and the
    // cases where the search stopped at the iteration limit are flagged.
    let args = [
        "reliability",
        file.to_str().unwrap(),
        "--system",
        "volumetric",
    ];
    let mut json_args = args.to_vec();
    json_args.extend(["--format", "json"]);
    let out = common::cli::success(chain(&json_args));
    let doc: Value = serde_json::from_slice(&out.stdout).unwrap();
    let vol: Vec<&Value> = doc["results"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|c| c["component"] == "volumetric")
        .collect();
    assert_eq!(vol.len(), 125);
    let mut unconverged = 0;
    for c in &vol {
        let calls = c["calls"]["gradients"].as_u64().unwrap();
        let iterations = c["iterations"].as_u64().unwrap();
        assert!(calls > iterations && iterations > 0, "{c}");
        assert_eq!(c["exact"], false);
        match c["termination"].as_str().unwrap() {
            "converged" => assert_eq!(c["converged"], true),
            "max_iterations" => {
                assert_eq!(c["converged"], false);
                assert_eq!(iterations, 200);
                unconverged += 1;
            }
            other => panic!("{other}"),
        }
    }
    let stderr = String::from_utf8_lossy(&out.stderr);
    if unconverged > 0 {
        assert!(
            stderr.contains(&format!(
                "warning: FORM did not converge on {unconverged} of 500 cases"
            )),
            "{stderr}"
        );
    } else {
        assert!(!stderr.contains("did not converge"), "{stderr}");
    }

    // CSV: the same facts in columns appended at the end.
    let mut csv_args = args.to_vec();
    csv_args.extend(["--format", "csv"]);
    let csv = ok_stdout(&csv_args);
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(
        &header[header.len() - 6..],
        [
            "termination",
            "converged",
            "iterations",
            "exact",
            "value_calls",
            "gradient_calls"
        ]
    );
    let flagged = lines
        .filter(|l| l.starts_with("volumetric,") && l.contains(",max_iterations,false,"))
        .count();
    assert_eq!(flagged, unconverged);

    // Table: one line per target on how FORM ended, and the unconverged
    // cells listed under their map.
    let table = ok_stdout(&args);
    assert!(table.contains(
        "  FORM: 125 of 125 cases converged (closed form 125); limit-state calls: 0 values, 0 gradients"
    ));
    let line = table
        .lines()
        .rfind(|l| l.starts_with("  FORM: "))
        .expect("volumetric FORM line");
    assert!(
        line.starts_with(&format!(
            "  FORM: {} of 125 cases converged (",
            125 - unconverged
        )),
        "{line}"
    );
    assert_eq!(
        table.contains("  * not converged at ("),
        unconverged > 0,
        "{table}"
    );
}

#[test]
fn sampling_reports_its_calls_and_the_centring_form() {
    let file = gantry();
    let doc = gantry_json("reliability", &["--method", "is", "--samples", "1000"]);
    let c = &doc["results"][0];
    assert_eq!(c["samples"], 1000);
    assert_eq!(c["termination"], "closed_form");
    assert_eq!(c["calls"]["values"], 1000);
    let doc = gantry_json("reliability", &["--method", "mc", "--samples", "1000"]);
    let c = &doc["results"][0];
    assert!(c.get("termination").is_none() && c.get("converged").is_none());
    assert_eq!(c["calls"]["values"], 1000);
    let table = ok_stdout(&[
        "reliability",
        file.to_str().unwrap(),
        "--method",
        "mc",
        "--samples",
        "1000",
    ]);
    // 125 grid points per target, 1000 samples each.
    assert!(table.contains("  limit-state calls: 125000 values, 0 gradients"));
}

#[test]
fn unknown_names_get_a_close_suggestion_or_none() {
    let file = gantry();
    let out = chain(&["reliability", file.to_str().unwrap(), "--grid", "yy=0,1"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("did you mean `y`?"), "{err}");
    assert!(err.contains("chain::reliability::unknown_name"), "{err}");
    let out = chain(&[
        "reliability",
        file.to_str().unwrap(),
        "--grid",
        "spindle=0,1",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("did you mean"), "{err}");
    // Every error has its own code (no generic fallback).
    let out = chain(&[
        "reliability",
        file.to_str().unwrap(),
        "--method",
        "mc",
        "--samples",
        "0",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("chain::reliability::invalid_samples"), "{err}");
}

/// `--system-tolerance` is the volumetric target's allowable error: given
/// with `--system series` it is refused (not dropped), and a value that is
/// not a positive length is refused naming the option
/// (`chain::ops::study::SystemChoice::new`, the rule Python shares).
#[test]
fn system_tolerance_is_refused_where_it_does_not_apply() {
    let file = gantry();
    let file = file.to_str().unwrap();
    let err = unwrapped(&fails(&[
        "reliability",
        file,
        "--system",
        "series",
        "--system-tolerance",
        "0.05",
    ]));
    assert!(
        err.contains("invalid value for '--system-tolerance': the allowable error of --system volumetric, not series"),
        "{err}"
    );
    assert!(err.contains("chain::cli::invalid_option"), "{err}");
    for bad in ["-5", "0", "nan", "inf"] {
        let err = unwrapped(&fails(&[
            "reliability",
            file,
            "--system",
            "volumetric",
            "--system-tolerance",
            bad,
        ]));
        assert!(
            err.contains("invalid value for '--system-tolerance'")
                && err.contains("a positive allowable volumetric error"),
            "{bad}: {err}"
        );
    }
}

/// The `--system-tolerance` refusal comes before the machine file is read:
/// a missing file is not what the user hears about.
#[test]
fn system_tolerance_is_refused_before_the_machine_is_read() {
    for command in [
        &["reliability"][..],
        &["path", "--axes", "/nonexistent/axes.csv"],
    ] {
        let err = unwrapped(&fails(
            &[
                command,
                &[
                    "/nonexistent/machine.yaml",
                    "--system",
                    "series",
                    "--system-tolerance",
                    "0.05",
                ],
            ]
            .concat(),
        ));
        assert!(
            err.contains("invalid value for '--system-tolerance'") && !err.contains("nonexistent"),
            "{command:?}: {err}"
        );
    }
}

#[test]
fn grid_ranges_are_the_same_grid_as_the_listed_values() {
    // `--grid VAR=LO:HI:N` (as in `chain map`) against the values listed:
    // the same document, for reliability, sensitivity and sobol alike.
    for command in ["reliability", "sensitivity"] {
        let range = gantry_json(command, &["--grid", "x=0:1000:3", "--grid", "z=600:1400:5"]);
        let listed = gantry_json(
            command,
            &[
                "--grid",
                "x=0,500,1000",
                "--grid",
                "z=600,800,1000,1200,1400",
            ],
        );
        assert_eq!(range, listed, "{command}");
    }
    let doc = gantry_json("reliability", &["--grid", "x=0:1000:3"]);
    // 3 x values × 5 y × 5 z, three components.
    assert_eq!(doc["results"].as_array().unwrap().len(), 3 * 25 * 3);
    // sobol reads ranges with the same parser: its refusal of a one-value range.
    let err = fails(&["sobol", gantry().to_str().unwrap(), "--grid", "x=0:1000:1"]);
    assert!(err.contains("N ≥ 2"), "{err}");
}

/// What a study needs from the machine file and the
/// options is checked with no model (`chain::ops::study::check`, which every
/// study command runs before the derivation): a grid axis missing from the
/// file, an empty `--grid` axis, an unknown `--param`, an error without
/// statistics.
#[test]
fn study_checks_need_no_derivation() {
    use chain::ops::study::{check, StudyError, StudyOptions};
    use reliability::ReliabilityError;
    let text = std::fs::read_to_string(gantry()).unwrap();
    let load = |text: &str| chain_core::load_str(text, "gantry.yaml").expect("loads");
    // The grid without its z axis.
    let no_z = load(&text.replace("    z: [600, 800, 1000, 1200, 1400]\n", ""));
    let err = check(&no_z, "gantry.yaml", &StudyOptions::default()).unwrap_err();
    assert!(
        matches!(&err, StudyError::Reliability(ReliabilityError::MissingCoordinate(v)) if v == "z"),
        "{err:?}"
    );
    let m = load(&text);
    let empty = [("x".to_string(), Vec::new())];
    let options = StudyOptions {
        grid: &empty,
        ..StudyOptions::default()
    };
    let err = check(&m, "gantry.yaml", &options).unwrap_err();
    assert!(
        err.to_string().contains("--grid x: the axis has no value"),
        "{err}"
    );
    let params = [("nope".to_string(), 1.0)];
    let options = StudyOptions {
        params: &params,
        ..StudyOptions::default()
    };
    assert!(matches!(
        check(&m, "gantry.yaml", &options),
        Err(StudyError::Resolve(_) | StudyError::Reliability(_))
    ));
    let no_stat = load(&text.replace("  dxx: {dist: normal, mean: 0, std: 0.05/6}\n", ""));
    let err = check(&no_stat, "gantry.yaml", &StudyOptions::default()).unwrap_err();
    assert!(err.to_string().contains("dxx"), "{err}");
    // And the whole file passes.
    check(&m, "gantry.yaml", &StudyOptions::default()).expect("the example checks");
}

/// `--approach` without `--values` is refused by the application layer's
/// one rule (the words Python uses), never dropped, for both commands that
/// take it, before the machine file is read.
#[test]
fn an_approach_without_values_is_refused_by_one_rule() {
    for command in ["reliability", "sensitivity"] {
        for file in [gantry().to_str().unwrap(), "no/such.yaml"] {
            let err = unwrapped(&fails(&[command, file, "--approach", "up"]));
            assert!(
                err.contains("invalid value for '--approach': the direction of a values file's tables: give --values VALUES.yaml too"),
                "{command} {file}: {err}"
            );
        }
    }
}
