//! A study that keeps the model instead of every point's
//! sensitivities (`Study::on_demand`, what every study command builds) gives
//! the results of one that keeps them (`Study::new`) bit for bit, on every
//! example machine with a reliability section and on a grid larger than one
//! block of cases.

use std::path::PathBuf;
use std::sync::Arc;

use chain_core::{CompiledModel, Machine};
use common::example_file;
use reliability::{
    machine, Algorithm, DirectionalSimulation, Form, ImportanceSampling, MonteCarlo, Sobol, Study,
    StudySpec, SubsetSimulation, System,
};

use crate::common;
use reliability::sorm::Sorm;

/// Every example machine with a reliability section and statistics for
/// all its errors.
fn machines() -> Vec<(PathBuf, Machine)> {
    let files = common::example_machines();
    files
        .into_iter()
        .filter_map(|f| {
            let m = chain_core::load_file(&f).expect("example loads");
            let ready = m.reliability.is_some() && machine::inputs(&m).is_ok();
            ready.then_some((f, m))
        })
        .collect()
}

/// The study that keeps its sensitivities and the one that evaluates them
/// when asked, over `spec`.
fn both(machine: &Machine, model: &CompiledModel, spec: StudySpec) -> (Study, Study) {
    let inputs = machine::inputs(machine).expect("inputs");
    let params = machine::parameters(machine, &[]).expect("parameters");
    let kept = Study::new(model, &params, inputs.clone(), spec.clone()).expect("kept study");
    let shared = Arc::new(model.clone());
    let lazy = Study::on_demand(shared, &params, inputs, spec).expect("on-demand study");
    (kept, lazy)
}

#[test]
fn on_demand_studies_equal_kept_ones_on_every_example_machine() {
    let found = machines();
    assert!(found.len() >= 3, "expected the paper machines: {found:?}");
    let algorithms = [
        Algorithm::Form(Form::default()),
        Algorithm::Sorm(Sorm::default()),
        Algorithm::ImportanceSampling(ImportanceSampling {
            samples: 200,
            seed: 3,
            form: Form::default(),
            cov: None,
        }),
        Algorithm::MonteCarlo(MonteCarlo {
            samples: 300,
            seed: 5,
            cov: None,
        }),
        Algorithm::Directional(DirectionalSimulation {
            samples: 50,
            seed: 7,
            cov: None,
        }),
        Algorithm::Subset(SubsetSimulation::new(100, 11)),
    ];
    for (file, m) in &found {
        let model = chain_core::compile(m);
        for system in [None, Some(System::Series)] {
            let spec = machine::spec(m, system).expect("spec");
            let (kept, lazy) = both(m, &model, spec);
            assert!(
                kept.points().iter().eq(lazy.points().iter()),
                "{}",
                file.display()
            );
            for p in 0..kept.points().len() {
                assert_eq!(kept.moments(p), lazy.moments(p), "{}", file.display());
            }
            for a in &algorithms {
                let k = kept.run(a, &()).expect("kept run");
                let l = lazy.run(a, &()).expect("on-demand run");
                assert_eq!(k, l, "{} with {:?}", file.display(), a.method());
            }
            let form = Form::default();
            assert_eq!(
                kept.sensitivity_mean(&form).expect("kept sensitivities"),
                lazy.sensitivity_mean(&form)
                    .expect("on-demand sensitivities"),
                "{}",
                file.display()
            );
            let sobol = Sobol {
                samples: 256,
                seed: 1,
                bootstrap: 20,
                confidence: 0.9,
            };
            assert_eq!(
                sobol.run_study(&kept).expect("kept Sobol"),
                sobol.run_study(&lazy).expect("on-demand Sobol"),
                "{}",
                file.display()
            );
        }
    }
}

#[test]
fn on_demand_form_equals_kept_across_case_blocks() {
    // 17 × 17 × 17 = 4913 points: more than one block of 4096 cases per
    // target, and blocks that straddle two targets.
    let file = example_file("machines/gantry_grinder.yaml");
    let m = chain_core::load_file(&file).expect("gantry loads");
    let model = chain_core::compile(&m);
    let mut spec = machine::spec(&m, Some(System::Series)).expect("spec");
    for (_, values) in &mut spec.grid.axes {
        let (lo, hi) = (values[0], values[values.len() - 1]);
        *values = (0..17).map(|i| lo + (hi - lo) * i as f64 / 16.0).collect();
    }
    let (kept, lazy) = both(&m, &model, spec);
    assert_eq!(kept.points().len(), 4913);
    let form = Algorithm::Form(Form::default());
    let k = kept.run(&form, &()).expect("kept FORM");
    let l = lazy.run(&form, &()).expect("on-demand FORM");
    assert_eq!(k.cases.len(), 4 * 4913);
    assert_eq!(k, l);
}

/// A gibibyte, the peak memory a million-point command must stay under.
const GIB: u64 = 1 << 30;

/// The million-point runs of docs/performance.md under 1 GiB each (`map`
/// and FORM `reliability` over a 100³ grid of the gantry grinder, and FORM
/// `path` along 10⁶ instants of a raster through the same box, every output
/// format). Ignored in the test command (about three minutes on two cores);
/// `cargo test --profile ci --test it -- --ignored million` runs it,
/// `scripts/peak_memory.sh` prints the figures.
#[test]
#[ignore]
fn a_million_point_map_reliability_and_path_stay_under_a_gibibyte() {
    let grid = [
        "--grid",
        "x=0:1000:100",
        "--grid",
        "y=-1500:1500:100",
        "--grid",
        "z=600:1400:100",
    ];
    let gantry = "examples/machines/gantry_grinder.yaml";
    let values = "examples/values/gantry_grinder.yaml";
    for format in ["table", "csv", "json"] {
        for command in ["map", "reliability"] {
            let mut args = vec![command, gantry];
            if command == "map" {
                args.extend(["--values", values]);
            }
            args.extend(grid);
            args.extend(["--format", format]);
            let (code, peak) = common::cli::peak_memory(&args);
            assert_eq!(code, 0, "{args:?}");
            eprintln!("{command} --format {format}: {} MB", peak >> 20);
            assert!(peak < GIB, "{args:?}: {} MB", peak >> 20);
        }
    }
    // The raster of scripts/peak_memory.sh: x fastest, 100 values per axis.
    let mut text = String::from("t,x,y,z\n");
    for k in 0..1_000_000usize {
        let (i, j, m) = (k / 10_000, (k / 100) % 100, k % 100);
        let (x, y, z) = (
            1000.0 * m as f64 / 99.0,
            -1500.0 + 3000.0 * j as f64 / 99.0,
            600.0 + 800.0 * i as f64 / 99.0,
        );
        text.push_str(&format!("{:.3},{x:?},{y:?},{z:?}\n", k as f64 * 0.001));
    }
    let axes = common::cli::scratch_file("gantry_1e6.csv", &text);
    drop(text);
    let axes = axes.to_str().expect("UTF-8 path");
    for format in ["table", "csv", "json"] {
        let args = ["path", gantry, "--axes", axes, "--format", format];
        let (code, peak) = common::cli::peak_memory(&args);
        assert_eq!(code, 0, "{args:?}");
        eprintln!("path --format {format}: {} MB", peak >> 20);
        assert!(peak < GIB, "{args:?}: {} MB", peak >> 20);
    }
}

/// FORM and SORM, which draw no samples, tell the progress sink of their
/// cases, a block at a time, so that `chain reliability` and `chain path`
/// can show how far a large grid has come.
#[test]
fn form_and_sorm_report_every_case_to_the_progress_sink() {
    use std::sync::atomic::{AtomicU64, Ordering};
    let file = example_file("machines/gantry_grinder.yaml");
    let m = chain_core::load_file(&file).expect("gantry loads");
    let model = chain_core::compile(&m);
    let mut spec = machine::spec(&m, None).expect("spec");
    spec.grid.axes[0].1 = (0..400).map(f64::from).collect();
    let (_, lazy) = both(&m, &model, spec);
    let cases = 3 * 400 * 25;
    for algorithm in [
        Algorithm::Form(Form::default()),
        Algorithm::Sorm(Sorm::default()),
    ] {
        let done = AtomicU64::new(0);
        let calls = AtomicU64::new(0);
        let progress = |n: u64| {
            done.fetch_add(n, Ordering::Relaxed);
            calls.fetch_add(1, Ordering::Relaxed);
        };
        lazy.run(&algorithm, &progress).expect("run");
        assert_eq!(done.into_inner(), cases);
        // 30,000 cases in blocks of 4,096.
        assert_eq!(calls.into_inner(), 8);
    }
}

/// `chain path`'s study (`PathStudy::on_demand`) gives the records of one
/// that keeps the sensitivities (`PathStudy::new`) bit for bit, with an
/// instant without axis values among them, for FORM and a sampler.
#[test]
fn on_demand_paths_equal_kept_ones() {
    use chain_core::inverse::Status;
    use reliability::{PathInstant, PathStudy, PathSummary};
    let file = example_file("machines/gantry_grinder.yaml");
    let m = chain_core::load_file(&file).expect("gantry loads");
    let model = chain_core::compile(&m);
    let spec = machine::spec(&m, Some(System::Volumetric { tolerance: 0.04 })).expect("spec");
    let inputs = machine::inputs(&m).expect("inputs");
    // 5,000 instants along a diagonal (x, z, y: the model's order), the
    // 7th unreachable.
    let instants: Vec<PathInstant> = (0..5000)
        .map(|k| {
            let s = k as f64 / 4999.0;
            let reachable = k != 6;
            PathInstant {
                row: k + 1,
                t: 0.01 * k as f64,
                status: if reachable {
                    Status::Ok
                } else {
                    Status::Unreachable
                },
                axes: reachable.then(|| vec![1000.0 * s, 600.0 + 800.0 * s, -1500.0 + 3000.0 * s]),
            }
        })
        .collect();
    let kept = PathStudy::new(&model, &[], inputs.clone(), spec.clone(), instants.clone())
        .expect("kept path");
    let lazy = PathStudy::on_demand(Arc::new(model.clone()), &[], inputs, spec, instants)
        .expect("on-demand path");
    for algorithm in [
        Algorithm::Form(Form::default()),
        Algorithm::MonteCarlo(MonteCarlo {
            samples: 100,
            seed: 2,
            cov: None,
        }),
        // A stop rule: each case stops at its own count.
        Algorithm::MonteCarlo(MonteCarlo {
            samples: 4000,
            seed: 4,
            cov: Some(0.5),
        }),
        Algorithm::Directional(DirectionalSimulation {
            samples: 8,
            seed: 6,
            cov: None,
        }),
    ] {
        let k = kept.run(&algorithm, &()).expect("kept run");
        let l = lazy.run(&algorithm, &()).expect("on-demand run");
        assert_eq!(k.evaluated(), 4999);
        assert_eq!(k, l);
        // The path runs its study a block of instants at a time (each case
        // on the streams of its index in the whole study): the cases are
        // those of the whole study run at once, bit for bit.
        let whole = lazy
            .study()
            .expect("study")
            .run(&algorithm, &())
            .expect("whole");
        assert_eq!(l.study.as_ref(), Some(&whole));
        // The blocks as `chain path` writes them: the same records, and
        // the summary added up block by block is the whole result's.
        let mut summary = PathSummary::new(l.targets.len(), whole.requirement);
        let mut records = Vec::new();
        let (mut blocks, mut before) = (0, 0);
        for block in lazy.blocks(&algorithm, &()) {
            let block = block.expect("block");
            summary.add(&block);
            for rec in &block.records {
                let cases: Vec<_> = match &rec.result {
                    Some(e) => block.cases_of(e).cloned().collect(),
                    None => Vec::new(),
                };
                let mut rec = rec.clone();
                if let Some(e) = &mut rec.result {
                    e.evaluated += before;
                }
                records.push((rec, cases));
            }
            before += block.evaluated();
            blocks += 1;
        }
        assert!(blocks >= 2, "5,000 instants make more than one block");
        assert_eq!(summary, PathSummary::of(&l));
        assert_eq!(records.len(), l.records.len());
        for (rec, (streamed, cases)) in l.records.iter().zip(&records) {
            assert_eq!(rec, streamed);
            let whole: Vec<_> = match &rec.result {
                Some(e) => l.cases_of(e).cloned().collect(),
                None => Vec::new(),
            };
            assert_eq!(&whole, cases);
        }
    }
}

/// `chain reliability` writes its CSV and JSON as it runs, a block of
/// cases at a time (`Prepared::output`): for every method, on a grid of
/// 1,536 points × 3 targets (4,608 cases, more than one block of 4,096),
/// both equal the run kept in memory (`--plot`, which needs every case,
/// keeps it) byte for byte.
#[test]
fn streamed_reliability_output_equals_the_run_in_memory_for_every_method() {
    use common::cli::{ok_stdout, scratch};
    let gantry = example_file("machines/gantry_grinder.yaml");
    let gantry = gantry.to_str().expect("UTF-8 path");
    let plots = scratch("streamed-reliability-plots");
    let plots = plots.to_str().expect("UTF-8 path");
    let grid = [
        "--grid",
        "x=0:1000:16",
        "--grid",
        "y=-1500:1500:16",
        "--grid",
        "z=600:1400:6",
    ];
    for method in [
        vec!["--method", "form"],
        vec!["--method", "sorm"],
        vec!["--method", "mc", "--samples", "100"],
        vec!["--method", "mc", "--samples", "400", "--cov", "0.5"],
        vec!["--method", "is", "--samples", "100"],
        vec!["--method", "directional", "--samples", "20"],
        vec!["--method", "subset", "--samples", "100"],
    ] {
        for format in ["csv", "json"] {
            let mut args = vec!["reliability", gantry, "--format", format];
            args.extend(&grid);
            args.extend(&method);
            let streamed = ok_stdout(&args);
            args.extend(["--plot", plots]);
            let kept = ok_stdout(&args);
            assert!(streamed.len() > 100_000, "{method:?} {format}");
            assert!(
                streamed == kept,
                "{method:?} --format {format}: streamed differs"
            );
        }
    }
}

/// The table of a grid of more than 10,000 points shows per target its
/// least reliable points and its most reliable one, equal to the extremes
/// of the JSON's every case, and says where the cut is.
#[test]
fn a_large_grid_s_table_shows_the_extreme_points() {
    use common::cli::{ok_json, ok_stdout};
    let gantry = example_file("machines/gantry_grinder.yaml");
    let gantry = gantry.to_str().expect("UTF-8 path");
    let grid = [
        "--grid",
        "x=0:1000:30",
        "--grid",
        "y=-1500:1500:30",
        "--grid",
        "z=600:1400:12",
    ];
    let mut args = vec!["reliability", gantry];
    args.extend(&grid);
    let table = ok_stdout(&args);
    assert!(
        table.contains("grid of 10800 points: more than 10000, so per target its 5 least reliable points and its most reliable one (--format csv or json lists every point)"),
        "{table}"
    );
    args.extend(["--format", "json"]);
    let doc = ok_json(&args);
    for target in ["px", "py", "pz"] {
        let mut rs: Vec<f64> = (doc["results"].as_array().unwrap().iter())
            .filter(|c| c["component"] == target)
            .map(|c| c["reliability"].as_f64().unwrap())
            .collect();
        assert_eq!(rs.len(), 10_800);
        rs.sort_by(f64::total_cmp);
        let section = table
            .split(&format!("\n{target}: reliability (%)\n"))
            .nth(1)
            .unwrap();
        let shown: Vec<f64> = section
            .lines()
            .take(6)
            .map(|l| {
                l.split_whitespace()
                    .find_map(|w| w.parse::<f64>().ok())
                    .unwrap()
            })
            .collect();
        for (k, v) in shown[..5].iter().enumerate() {
            assert!(
                (v - 100.0 * rs[k]).abs() < 0.006,
                "{target} {k}: {v} vs {}",
                rs[k]
            );
        }
        assert!((shown[5] - 100.0 * rs[rs.len() - 1]).abs() < 0.006);
        let s = &doc["summary"][target];
        let line = section.lines().find(|l| l.contains("summary:")).unwrap();
        assert!(
            line.contains(&format!("min {:.2} %", 100.0 * s["min"].as_f64().unwrap())),
            "{line}"
        );
    }
}
