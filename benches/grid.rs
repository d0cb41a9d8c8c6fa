//! `chain reliability` over a grid (issue 54; docs/performance.md, "The main
//! job at the speed of its kernel"), on the gantry grinder
//! (examples/machines/gantry_grinder.yaml: 21 independent normal errors,
//! px, py, pz toleranced one-sided). Run with `cargo bench --bench grid`;
//! the numpy side-by-side is `benches/numpy_grid.py`.
//!
//! - `grid/totals_form_1e6`: what `chain reliability --format table` runs
//!   on a 100 × 100 × 100 grid (3 × 10⁶ closed-form FORM cases) after the
//!   study is built: `Study::run_totals` (one pass, every target from one
//!   evaluation of the compiled tape, on every core);
//!   `_one_thread` on one; `_generated` through the `machine!` type of the
//!   same file instead of the tape;
//! - `grid/is_375_cases`, `grid/mc_375_cases`: the importance sampling and
//!   crude Monte Carlo over the 5 × 5 × 5 grid (375 cases, 4096 samples
//!   each) through `Study::run_totals`, against `is_case_alone`,
//!   `mc_case_alone`: the same sampler on one of those cases (px at the
//!   worst corner) run alone (`Sampler::run` on its event). The issue's
//!   figure: the grid's time per case within 2× of a case alone.

use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Duration;

use chain::core::model::{Component, Sided};
use criterion::{criterion_group, criterion_main, Criterion};
use reliability::study::{Grid, SharedModel, Study};
use reliability::{
    machine, Algorithm, Event, Form, ImportanceSampling, MonteCarlo, Sampler, ToleranceLimitState,
};

chain::machine!(Gantry = "examples/machines/gantry_grinder.yaml");

fn example(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples")
        .join(path)
}

/// The study of the gantry over `n` values per axis, through `model`.
fn study(machine: &chain::core::Machine, model: SharedModel, n: usize) -> Study {
    let axis = |lo: f64, hi: f64| {
        (0..n)
            .map(|k| lo + (hi - lo) * k as f64 / (n - 1) as f64)
            .collect::<Vec<_>>()
    };
    let mut spec = machine::spec(machine, None).expect("spec");
    spec.grid = Grid {
        axes: vec![
            ("x".into(), axis(0.0, 1000.0)),
            ("y".into(), axis(-1500.0, 1500.0)),
            ("z".into(), axis(600.0, 1400.0)),
        ],
    };
    let inputs = machine::inputs(machine).expect("inputs");
    let params = machine::parameters(machine, &[]).expect("parameters");
    Study::on_demand(model, &params, inputs, spec).expect("study")
}

fn grid(c: &mut Criterion) {
    let machine = chain::core::load_file(&example("machines/gantry_grinder.yaml")).unwrap();
    let tape: SharedModel = Arc::new(chain::core::compile(&machine));
    let form = Algorithm::Form(Form::default());
    let mut g = c.benchmark_group("grid");
    g.sample_size(10).measurement_time(Duration::from_secs(10));
    let big = study(&machine, tape.clone(), 100);
    g.bench_function("totals_form_1e6", |b| {
        b.iter(|| black_box(big.run_totals(&form, &(), 5).unwrap().result.summaries))
    });
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    g.bench_function("totals_form_1e6_one_thread", |b| {
        b.iter(|| {
            one.install(|| black_box(big.run_totals(&form, &(), 5).unwrap().result.summaries))
        })
    });
    let generated = study(&machine, Arc::new(Gantry), 100);
    g.bench_function("totals_form_1e6_generated", |b| {
        b.iter(|| {
            black_box(
                generated
                    .run_totals(&form, &(), 5)
                    .unwrap()
                    .result
                    .summaries,
            )
        })
    });

    // The samplers: over the grid, and one case alone.
    let small = study(&machine, tape, 5);
    let v = small.variables();
    let corner = (0..small.points().len())
        .find(|&p| {
            let q = small.points().point(p);
            let at = |n: &str| q[v.iter().position(|x| x == n).unwrap()];
            at("x") == 1000.0 && at("y") == 1500.0 && at("z") == 1400.0
        })
        .expect("corner");
    let ls = ToleranceLimitState::component(
        small.row(corner, Component::Px).unwrap().to_vec(),
        0.03,
        Sided::Upper,
    )
    .unwrap();
    let event = Event::new(small.inputs(), ls).unwrap();
    let is = ImportanceSampling {
        samples: 4096,
        seed: 1,
        form: Form::default(),
        cov: None,
    };
    let mc = MonteCarlo {
        samples: 4096,
        seed: 1,
        cov: None,
    };
    g.bench_function("is_375_cases", |b| {
        b.iter(|| {
            black_box(
                small
                    .run_totals(&Algorithm::ImportanceSampling(is), &(), 5)
                    .unwrap()
                    .result
                    .summaries,
            )
        })
    });
    g.bench_function("is_case_alone", |b| {
        b.iter(|| black_box(is.run(&event).unwrap()))
    });
    g.bench_function("mc_375_cases", |b| {
        b.iter(|| {
            black_box(
                small
                    .run_totals(&Algorithm::MonteCarlo(mc), &(), 5)
                    .unwrap()
                    .result
                    .summaries,
            )
        })
    });
    g.bench_function("mc_case_alone", |b| {
        b.iter(|| black_box(mc.run(&event).unwrap()))
    });
    g.finish();
}

criterion_group!(benches, grid);
criterion_main!(benches);
