//! Precision allocation (`chain allocate`, seed 000 Section 3.3, Tables 5-7):
//! the paper's procedure against Tables 5 and 7, the least-cost allocation
//! (requirement met by an independent FORM evaluation, KKT residual, cost
//! against the paper's final tolerances), an analytic optimum, and the
//! infeasible case.

use crate::common;

use std::path::PathBuf;

use chain_core::model::Machine;
use chain_core::CompiledModel;
use common::cli::{chain, fails, ok, ok_json, scratch};
use common::example_path;
use reliability::allocate::{self, AllocateError, ErrorBounds, Optimal, Paper};
use reliability::{machine, normal, Algorithm, Form, Study, Summary};

fn gantry_path() -> PathBuf {
    example_path("gantry_grinder.yaml")
}

fn load(text: &str) -> (Machine, CompiledModel, Study) {
    let machine = chain_core::load_str(text, "test.yaml").expect("machine loads");
    let model = chain_core::compile(&machine);
    let study = machine::study(&machine, &model, &[], None).expect("study");
    (machine, model, study)
}

fn gantry() -> (Machine, CompiledModel, Study) {
    load(&std::fs::read_to_string(gantry_path()).expect("gantry file"))
}

fn summary<'a>(s: &'a [Summary], target: &str) -> &'a Summary {
    s.iter()
        .find(|s| s.target.name() == target)
        .expect("component")
}

fn std_of(b: &[ErrorBounds], stds: &[(String, f64)], name: &str) -> (f64, f64) {
    let j = b.iter().position(|x| x.error == name).expect("error");
    (b[j].std0, stds[j].1)
}

/// Table 5 rounds 1-3 (px) and Table 7 round 1 (pz), mean/min in %.
const TABLE5: [(f64, f64); 3] = [(93.66, 88.49), (95.15, 91.01), (96.46, 93.43)];
const TABLE7_ROUND1: (f64, f64) = (96.24, 93.26);

#[test]
fn paper_strategy_reproduces_tables_5_and_7() {
    let (m, model, study) = gantry();
    let b = allocate::bounds(&m, &study).unwrap();
    let r = allocate::paper(&model, &[], &study, &b, &Paper::default()).unwrap();
    assert!(r.met);
    assert!(r.steps.len() >= 3);
    for (step, (mean, min)) in r.steps.iter().zip(TABLE5) {
        let px = summary(&step.summaries, "px");
        assert!(
            (px.mean * 100.0 - mean).abs() < 0.1 && (px.min * 100.0 - min).abs() < 0.1,
            "round {}: px {:.2}/{:.2} vs Table 5 {mean}/{min}",
            step.round,
            px.mean * 100.0,
            px.min * 100.0
        );
    }
    let pz = summary(&r.steps[0].summaries, "pz");
    assert!((pz.mean * 100.0 - TABLE7_ROUND1.0).abs() < 0.1);
    assert!((pz.min * 100.0 - TABLE7_ROUND1.1).abs() < 0.1);
    // Round 1 tightens the per-component sets of Figures 6-8 / Tables 5-7:
    // px {eyx, ezx, ezz, Sxy}, py {exx, ezx, Sxy}, pz {exx, eyx, exz, Syz}.
    let mut first = r.steps[0].tightened.clone();
    first.sort();
    assert_eq!(first, ["Sxy", "Syz", "exx", "exz", "eyx", "ezx", "ezz"]);
    // Table 5's rows: one step (0.005/6000 rad, 0.005/3000 for Sxy) a round.
    let (s0, _) = std_of(&b, &r.std, "eyx");
    let eyx1 = r.steps[0].std.iter().find(|(n, _)| n == "eyx").unwrap().1;
    assert!((eyx1 - (s0 - 0.005 / 6000.0)).abs() < 1e-18);
    let sxy1 = r.steps[0].std.iter().find(|(n, _)| n == "Sxy").unwrap().1;
    assert!((sxy1 - 0.025 / 3000.0).abs() < 1e-18);
}

#[test]
fn paper_strategy_per_component_matches_each_table_alone() {
    // Each table of the paper tightens one component's errors only; with a
    // study of pz alone the first round is still Table 7's.
    let (m, model, study) = gantry();
    let b = allocate::bounds(&m, &study).unwrap();
    let mut spec = study.spec().clone();
    spec.tolerances.retain(|(c, _)| c.name() == "pz");
    let alone = Study::new(&model, &[], study.inputs().clone(), spec).unwrap();
    let r = allocate::paper(&model, &[], &alone, &b, &Paper::default()).unwrap();
    let mut first = r.steps[0].tightened.clone();
    first.sort();
    assert_eq!(first, ["Syz", "exx", "exz", "eyx"]);
    let pz = summary(&r.steps[0].summaries, "pz");
    assert!((pz.mean * 100.0 - TABLE7_ROUND1.0).abs() < 0.1);
    assert!((pz.min * 100.0 - TABLE7_ROUND1.1).abs() < 0.1);
}

/// The paper's final tolerances (Tables 5-7 combined, from Table 1's
/// values: Table 7 tightens three rounds from Table 1, erratum 000-4),
/// `(error, tolerance, divisor)`.
const PAPER_FINAL: [(&str, f64, f64); 7] = [
    ("eyx", 0.04, 6000.0),
    ("ezx", 0.03, 6000.0),
    ("ezz", 0.01, 6000.0),
    ("Sxy", 0.01, 3000.0),
    ("exx", 0.015, 6000.0),
    ("exz", 0.015, 6000.0),
    ("Syz", 0.005, 3000.0),
];

#[test]
fn optimal_meets_the_requirement_at_far_less_cost_with_kkt() {
    let (m, model, study) = gantry();
    let b = allocate::bounds(&m, &study).unwrap();
    let r = allocate::optimal(&model, &[], &study, &b, &Optimal::default()).unwrap();
    let kkt = r.kkt.as_ref().expect("kkt");
    assert!(kkt.polished, "{kkt:?}");
    assert!(kkt.residual() < 1e-6, "{kkt:?}");
    // Independent evaluation: a fresh study with the allocated σ, FORM.
    let stds: Vec<f64> = r.std.iter().map(|(_, s)| *s).collect();
    let inputs = allocate::with_stds(&study, &stds).unwrap();
    let check = Study::new(&model, &[], inputs, study.spec().clone()).unwrap();
    let res = check.run(&Algorithm::Form(Form::default()), &()).unwrap();
    for c in ["px", "py", "pz"] {
        let s = summary(&res.summaries, c);
        assert!(s.min >= 0.95 && s.mean >= 0.97, "{c}: {s:?}");
    }
    // Bounds: only tightened.
    for (bb, s) in b.iter().zip(&stds) {
        assert!(*s <= bb.std0 * (1.0 + 1e-12) && *s > 0.0);
    }
    // The paper's final tolerances under the same cost model.
    let mut paper = b.iter().map(|x| x.std0).collect::<Vec<_>>();
    for (name, tol, div) in PAPER_FINAL {
        let j = b.iter().position(|x| x.error == name).unwrap();
        paper[j] = tol / div;
    }
    let paper_cost = allocate::cost(&b, &paper);
    assert!((paper_cost - 61.0 / 6.0).abs() < 1e-9, "{paper_cost}");
    assert!(r.cost < 0.5 * paper_cost, "{} vs {paper_cost}", r.cost);
    // Binding: the worst px and pz cases.
    assert!(kkt.active.iter().any(|(n, _)| n.starts_with("px min")));
    assert!(kkt.active.iter().any(|(n, _)| n.starts_with("pz min")));
    // Optimality against the paper procedure's own result too.
    let p = allocate::paper(&model, &[], &study, &b, &Paper::default()).unwrap();
    assert!(r.cost < p.cost);
}

const TWO: &str = "
machine: two_errors
bodies:
  bed: {}
  slide:
    parent: bed
    joint: {type: prismatic, axis: +x, variable: x}
    errors: {dx: a, ez: b}
  tool: {parent: slide}
workpiece: bed
tool: tool
tool_point: [0, 100, 0]
frame: workpiece
statistics:
  a: {dist: normal, mean: 0, std: 0.02}
  b: {dist: normal, mean: 0, std: 0.0002, cost_weight: 2}
reliability:
  tolerance: {px: 0.03}
  sided: upper
  grid: {x: [0]}
  requirement: {min: 0.99, mean: 0.99}
";

#[test]
fn one_component_two_errors_hits_the_analytic_optimum() {
    // px = a − 100·b. min Σ wᵢ(σ0ᵢ/σᵢ − 1) s.t. σa² + 100²σb² = (I/z)²,
    // z = Φ⁻¹(0.99): σᵢ = k (wᵢσ0ᵢ/cᵢ²)^(1/3).
    let (m, model, study) = load(TWO);
    let b = allocate::bounds(&m, &study).unwrap();
    let r = allocate::optimal(&model, &[], &study, &b, &Optimal { margin: 0.0 }).unwrap();
    let z = normal::inverse_cdf(0.99);
    let bb = (0.03 / z).powi(2);
    let c2: [f64; 2] = [1.0, 1e4];
    let u = [(1.0 * 0.02 / c2[0]).cbrt(), (2.0 * 0.0002 / c2[1]).cbrt()];
    let k = (bb / (c2[0] * u[0] * u[0] + c2[1] * u[1] * u[1])).sqrt();
    for (i, (name, s)) in r.std.iter().enumerate() {
        let want = k * u[i];
        assert!(
            ((s - want) / want).abs() < 1e-8,
            "{name}: {s:e} vs analytic {want:e}"
        );
    }
    let kkt = r.kkt.unwrap();
    assert!(kkt.residual() < 1e-10, "{kkt:?}");
    let want_cost = 0.02 / (k * u[0]) - 1.0 + 2.0 * (0.0002 / (k * u[1]) - 1.0);
    assert!((r.cost - want_cost).abs() < 1e-8 * want_cost);
}

#[test]
fn min_std_bound_binds_and_is_reported() {
    // b cannot go below 1.2e-4 (the free optimum is 1.01e-4): a carries the rest.
    let text = TWO.replace("cost_weight: 2}", "cost_weight: 2, min_std: 0.00012}");
    let (m, model, study) = load(&text);
    let b = allocate::bounds(&m, &study).unwrap();
    let r = allocate::optimal(&model, &[], &study, &b, &Optimal { margin: 0.0 }).unwrap();
    let kkt = r.kkt.unwrap();
    assert!(kkt.residual() < 1e-10, "{kkt:?}");
    assert!((r.std[1].1 - 0.00012).abs() < 1e-15);
    assert!(kkt
        .at_bound
        .iter()
        .any(|(n, w, z)| n == "b" && *w == "min_std" && *z > 0.0));
    let z = normal::inverse_cdf(0.99);
    let sa = ((0.03 / z).powi(2) - 1e4 * 0.00012f64.powi(2)).sqrt();
    assert!(((r.std[0].1 - sa) / sa).abs() < 1e-8);
}

#[test]
fn infeasible_requirement_names_component_and_errors() {
    let text = TWO
        .replace("std: 0.02}", "std: 0.02, min_std: 0.015}")
        .replace("cost_weight: 2}", "cost_weight: 2, min_std: 0.00015}");
    let (m, model, study) = load(&text);
    let b = allocate::bounds(&m, &study).unwrap();
    let e = allocate::optimal(&model, &[], &study, &b, &Optimal::default()).unwrap_err();
    match &e {
        AllocateError::Infeasible {
            component, binding, ..
        } => {
            assert_eq!(component, "px");
            assert!(binding[0].starts_with('a') && binding[1].starts_with('b'));
        }
        other => panic!("{other:?}"),
    }
}

/// Asserts that `err` contains every one of `needles`.
#[track_caller]
fn mentions(err: &str, needles: &[&str]) {
    for n in needles {
        assert!(err.contains(n), "{n:?} is missing from:\n{err}");
    }
}

/// `chain allocate` on the machine file `text` (written as `NAME.yaml`) must
/// fail; its stderr.
fn allocate_fails_on(name: &str, text: &str) -> String {
    let file = scratch(name).join(format!("{name}.yaml"));
    std::fs::write(&file, text).unwrap();
    fails(&["allocate", file.to_str().unwrap()])
}

#[test]
fn cli_infeasible_exits_non_zero_naming_component_and_errors() {
    // The gantry with every σ bounded at 90 % of Table 1 and min ≥ 99.99 %.
    let text = std::fs::read_to_string(gantry_path()).unwrap();
    let mut out = String::new();
    for line in text.lines() {
        if let (true, Some(i)) = (line.contains("dist: normal"), line.find("std: ")) {
            let expr = line[i + 5..].trim_end_matches('}').trim();
            out.push_str(&line.replacen('}', &format!(", min_std: 0.9*{expr}}}"), 1));
        } else if line.trim_start().starts_with("requirement:") {
            out.push_str("  requirement: {min: 0.9999, mean: 0.9999}");
        } else {
            out.push_str(line);
        }
        out.push('\n');
    }
    let err = allocate_fails_on("gantry_tight", &out);
    mentions(
        &err,
        &[
            "infeasible",
            "px",
            "eyx",
            "min_std",
            "chain::allocate::infeasible",
            "gantry_grinder: the requirement is infeasible",
        ],
    );
}

/// Every standard deviation pinned at its `min_std`: nothing can be
/// tightened. The paper's procedure stalls on `px` at round 0 and the
/// least-cost allocation finds the requirement infeasible; each refusal
/// names the file, line and column of the statistics entry of the error it
/// lists first, and shows it (not the machine alone).
#[test]
fn cli_stalled_and_infeasible_allocations_point_at_the_statistics_entry() {
    let text = std::fs::read_to_string(gantry_path()).unwrap();
    let pinned: String = text
        .lines()
        .map(
            |line| match (line.contains("dist: normal"), line.find("std: ")) {
                (true, Some(i)) => {
                    let expr = line[i + 5..].trim_end_matches('}').trim();
                    format!(
                        "{}\n",
                        line.replacen('}', &format!(", min_std: {expr}}}"), 1)
                    )
                }
                _ => format!("{line}\n"),
            },
        )
        .collect();
    let file = scratch("gantry_pinned").join("pinned.yaml");
    std::fs::write(&file, &pinned).unwrap();
    let f = file.to_str().unwrap();
    // Where each error's entry is, counted here from the text.
    let entry = |name: &str| {
        let line = 1 + pinned
            .lines()
            .position(|l| l.starts_with(&format!("  {name}: {{dist")))
            .expect("entry");
        format!("{f}:{line}:3: gantry_grinder: ")
    };
    let err = fails(&["allocate", f, "--strategy", "paper"]);
    mentions(
        &err,
        &[
            "chain::allocate::stalled",
            "stops after round 0: px misses the requirement",
            "its statistics entry",
        ],
    );
    // The first of the ranked errors, as the message lists them.
    let first = err
        .split("further (")
        .nth(1)
        .and_then(|r| r.split(',').next())
        .expect("ranked errors")
        .trim()
        .to_string();
    let flat = err.split_whitespace().collect::<Vec<_>>().join(" ");
    let at = entry(&first);
    assert!(flat.contains(&at), "{at:?} is missing from:\n{err}");
    let err = fails(&["allocate", f]);
    mentions(
        &err,
        &["chain::allocate::infeasible", "its statistics entry"],
    );
    let first = err
        .split("binding bounds: ")
        .nth(1)
        .and_then(|r| r.split(" (").next())
        .expect("binding errors")
        .trim()
        .to_string();
    let flat = err.split_whitespace().collect::<Vec<_>>().join(" ");
    let at = entry(&first);
    assert!(flat.contains(&at), "{at:?} is missing from:\n{err}");
}

#[test]
fn cli_allocation_errors_have_their_own_codes() {
    // No requirement: its own code and the hint, no catch-all code.
    let text = std::fs::read_to_string(gantry_path()).unwrap();
    let out: String = text
        .lines()
        .filter(|l| !l.trim_start().starts_with("requirement:"))
        .map(|l| format!("{l}\n"))
        .collect();
    let err = allocate_fails_on("gantry_no_requirement", &out);
    mentions(
        &err,
        &[
            "chain::allocate::no_requirement",
            "requirement: {min: 0.95, mean: 0.97}",
        ],
    );
    assert!(!err.contains("chain::allocate::error"), "{err}");
    // Steps too small for the paper's procedure to finish in its rounds:
    // the table is written, then the exit is non-zero.
    let out = chain(&[
        "allocate",
        gantry_path().to_str().unwrap(),
        "--strategy",
        "paper",
        "--step",
        "0.00001",
    ]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stdout).contains("round 200"));
    let err = String::from_utf8_lossy(&out.stderr);
    mentions(
        &err,
        &[
            "chain::allocate::not_met",
            "the requirement is not met after 200 rounds",
        ],
    );
}

#[test]
fn cli_json_follows_the_contract() {
    let file = gantry_path();
    for strategy in ["optimal", "paper"] {
        let doc = ok_json(&[
            "allocate",
            file.to_str().unwrap(),
            "--strategy",
            strategy,
            "--format",
            "json",
        ]);
        assert_eq!(doc["machine"], "gantry_grinder");
        assert_eq!(doc["strategy"], strategy);
        assert_eq!(doc["requirement"]["min"], 0.95);
        assert_eq!(doc["final"]["met"], true);
        assert!(doc["final"]["cost"].as_f64().unwrap() > 0.0);
        assert!(doc["final"]["std"]["eyx"].as_f64().unwrap() < 0.06 / 6000.0);
        for c in ["px", "py", "pz"] {
            assert!(doc["final"]["summary"][c]["min"].as_f64().unwrap() >= 0.95);
            assert!(doc["final"]["summary"][c]["mean"].as_f64().unwrap() >= 0.97);
        }
        let steps = doc["steps"].as_array().unwrap();
        if strategy == "paper" {
            assert_eq!(steps[0]["round"], 1);
            let px = steps[0]["summary"]["px"]["mean"].as_f64().unwrap();
            assert!((px * 100.0 - 93.66).abs() < 0.1);
            assert!(steps[0]["tightened"].as_array().unwrap().len() == 7);
            assert!(steps[0]["std"]["eyx"].is_number());
        } else {
            assert!(doc["kkt"]["residual"].as_f64().unwrap() < 1e-6);
        }
    }
}

/// docs/errata.md 000-6 and 000-7: Table 5's fourth round and Table 7's
/// rounds 2-3 against the model (from Table 1, one step a round).
#[test]
fn errata_000_6_and_000_7() {
    let (m, model, study) = gantry();
    let b = allocate::bounds(&m, &study).unwrap();
    let with = |changes: &[(&str, f64)]| {
        let mut s: Vec<f64> = b.iter().map(|x| x.std0).collect();
        for (name, v) in changes {
            let j = b.iter().position(|x| x.error == *name).unwrap();
            s[j] = *v;
        }
        allocate::evaluate(&model, &[], &study, &s)
            .unwrap()
            .1
            .summaries
    };
    let near = |s: &[Summary], c: &str, mean: f64, min: f64| {
        let x = summary(s, c);
        assert!(
            (x.mean * 100.0 - mean).abs() < 0.006 && (x.min * 100.0 - min).abs() < 0.006,
            "{c}: {:.3}/{:.3} vs {mean}/{min}",
            x.mean * 100.0,
            x.min * 100.0
        );
    };
    // 000-6: Table 5 round 4 prints 97.76/96.52.
    let s = with(&[
        ("eyx", 0.04 / 6000.0),
        ("ezx", 0.03 / 6000.0),
        ("ezz", 0.01 / 6000.0),
        ("Sxy", 0.01 / 3000.0),
    ]);
    near(&s, "px", 97.54, 95.49);
    // 000-7: Table 7 from Table 1, k steps on exx, eyx, exz, Syz.
    for (k, (mean, min)) in [(2, (97.16, 95.12)), (3, (97.79, 96.50))] {
        let d = 0.005 * k as f64;
        let s = with(&[
            ("exx", (0.03 - d) / 6000.0),
            ("eyx", (0.06 - d) / 6000.0),
            ("exz", (0.03 - d) / 6000.0),
            ("Syz", (0.02 - d) / 3000.0),
        ]);
        near(&s, "pz", mean, min);
    }
}

#[test]
fn cli_plot_writes_maps_and_the_tightening_chart() {
    let dir = scratch("plot");
    let file = gantry_path();
    ok(&[
        "allocate",
        file.to_str().unwrap(),
        "--strategy",
        "paper",
        "--plot",
        dir.to_str().unwrap(),
    ]);
    for stem in [
        "allocate_px",
        "allocate_py",
        "allocate_pz",
        "allocate_tightening",
    ] {
        for ext in ["png", "svg"] {
            let f = dir.join(format!("{stem}.{ext}"));
            assert!(
                std::fs::metadata(&f)
                    .map(|m| m.len() > 1000)
                    .unwrap_or(false),
                "{f:?}"
            );
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A requirement that already holds: nothing is tightened, so `--plot`
/// writes the before/after maps, no tightening chart, and says why (it
/// failed with `chain::plot::no_data`), for both strategies.
#[test]
fn cli_plot_with_nothing_tightened_writes_the_maps_and_says_so() {
    let text = std::fs::read_to_string(gantry_path()).unwrap();
    let easy = text.replace(
        "requirement: {min: 0.95, mean: 0.97}",
        "requirement: {min: 0.5, mean: 0.5}",
    );
    assert_ne!(easy, text, "the gantry's requirement line");
    let file = scratch("easy").join("easy.yaml");
    std::fs::write(&file, easy).unwrap();
    for strategy in ["paper", "optimal"] {
        let dir = scratch(&format!("plot-easy-{strategy}"));
        let out = ok(&[
            "allocate",
            file.to_str().unwrap(),
            "--strategy",
            strategy,
            "--plot",
            dir.to_str().unwrap(),
        ]);
        let err = String::from_utf8_lossy(&out.stderr);
        mentions(&err, &["no error was tightened", "allocate_px.png"]);
        assert!(dir.join("allocate_pz.svg").exists(), "{err}");
        assert!(!dir.join("allocate_tightening.png").exists(), "{err}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}

/// The gantry grinder with an `nx × ny × nz` grid over its strokes and
/// `parameters` for its empty parameter section (a scratch file).
fn gantry_grid(name: &str, n: [usize; 3], parameters: &str) -> PathBuf {
    let text = std::fs::read_to_string(gantry_path()).unwrap();
    let axis = |lo: f64, hi: f64, n: usize| {
        let v: Vec<String> = (0..n)
            .map(|i| format!("{}", lo + (hi - lo) * i as f64 / (n - 1) as f64))
            .collect();
        format!("[{}]", v.join(", "))
    };
    let grid = format!(
        "    x: {}\n    y: {}\n    z: {}\n",
        axis(0.0, 1000.0, n[0]),
        axis(-1500.0, 1500.0, n[1]),
        axis(600.0, 1400.0, n[2])
    );
    let start = text.find("    x: [0, 250").unwrap();
    let end = start + text[start..].find("  requirement").unwrap();
    let text = format!("{}{grid}{}", &text[..start], &text[end..]);
    let text = text.replacen("parameters: {}", parameters, 1);
    common::cli::scratch_file(name, &text)
}

/// Each allocation refuses a grid larger than it runs on
/// within about a minute, from the machine file before the derivation (a
/// symbolic parameter, which the study would refuse, is not reached),
/// naming the reliability section, the counts and what to do instead.
#[test]
fn allocations_refuse_grids_too_large_for_them_before_deriving() {
    let cases = [
        ([60, 60, 14], vec![], 50_400, 50_000, "--strategy optimal"),
        (
            [60, 60, 28],
            vec!["--strategy", "paper"],
            100_800,
            100_000,
            "--strategy paper",
        ),
        (
            [40, 40, 19],
            vec!["--target", "acceptance", "--level", "0.9"],
            30_400,
            30_000,
            "--target acceptance",
        ),
    ];
    for (n, options, points, limit, what) in cases {
        // A symbolic parameter nobody gives a value.
        let file = gantry_grid(
            &format!("allocate_grid_{points}.yaml"),
            n,
            "parameters: {unused: null}",
        );
        let mut args = vec!["allocate", file.to_str().unwrap()];
        args.extend(options.iter().copied());
        let err = common::cli::unwrapped(&fails(&args));
        mentions(
            &err,
            &[
                "chain::reliability::grid_too_large",
                "key `reliability.grid`",
                &format!("the grid has {points} points"),
                &format!("runs on at most {limit}"),
                what,
                "allocate on a coarser grid",
                "chain reliability",
            ],
        );
        assert!(err.contains(":88:1"), "located at `reliability:`: {err}");
        assert!(!err.contains("unused"), "refused before the study: {err}");
    }
    // At the limit the grid is taken (the paper's tightening, the fastest).
    let file = gantry_grid("allocate_grid_ok.yaml", [50, 50, 40], "parameters: {}");
    ok(&["allocate", file.to_str().unwrap(), "--strategy", "paper"]);
}
