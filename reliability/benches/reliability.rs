//! Criterion benchmarks of the reliability engine on the gantry grinder of
//! seed 000 (`examples/machines/gantry_grinder.yaml`).
//!
//! Run with `cargo bench -p reliability`; figures and how they compare with
//! the targets and with OpenTURNS are in `docs/performance.md`.
//!
//! - `form/375_cases`: FORM on every (point, component) case of the 5×5×5
//!   grid, sensitivities already evaluated (`Study::run` with FORM);
//! - `study/new`: evaluating the model's sensitivities at the 125 points;
//! - `is/px/{1,2}_threads`: the importance sampling on px at the worst corner
//!   (7 active errors, 6 sampled coordinates per sample), 2²⁰ samples;
//! - `mc/px_21_vars/{1,2}_threads`: crude Monte Carlo on the same limit state,
//!   drawing all 21 errors per sample, 2²⁰ samples.

use std::hint::black_box;
use std::path::Path;

use chain_core::model::{Component, Sided};
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use reliability::{
    machine, Algorithm, Event, Form, ImportanceSampling, MonteCarlo, Sampler, Study,
    ToleranceLimitState,
};

fn gantry() -> (chain_core::Machine, chain_core::CompiledModel) {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/machines/gantry_grinder.yaml");
    let machine = chain_core::load_file(&path).expect("gantry_grinder.yaml");
    let model = chain_core::compile(&machine);
    (machine, model)
}

fn corner(study: &Study) -> usize {
    let v = |n: &str| {
        study
            .variables()
            .iter()
            .position(|x| x == n)
            .expect("variable")
    };
    let (x, y, z) = (v("x"), v("y"), v("z"));
    study
        .points()
        .iter()
        .position(|p| p[x] == 1000.0 && p[y] == 1500.0 && p[z] == 1400.0)
        .expect("corner")
}

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool")
}

fn benches(c: &mut Criterion) {
    let (machine, model) = gantry();
    let study = machine::study(&machine, &model, &[], None).expect("study");

    let mut g = c.benchmark_group("form");
    g.throughput(Throughput::Elements(375));
    let one = pool(1);
    g.bench_function("375_cases", |b| {
        one.install(|| {
            b.iter(|| {
                black_box(
                    study
                        .run(&Algorithm::Form(Form::default()), &())
                        .expect("form"),
                )
            })
        })
    });
    g.finish();

    let mut g = c.benchmark_group("study");
    g.bench_function("new", |b| {
        b.iter(|| black_box(machine::study(&machine, &model, &[], None).expect("study")))
    });
    g.finish();

    let p = corner(&study);
    let ls = ToleranceLimitState::component(
        study.row(p, Component::Px).unwrap().to_vec(),
        0.03,
        Sided::Upper,
    )
    .expect("limit state");
    let event = Event::new(study.inputs(), ls).expect("event");
    const SAMPLES: u64 = 1 << 20;

    let mut g = c.benchmark_group("is/px");
    g.sample_size(20);
    g.throughput(Throughput::Elements(SAMPLES));
    for threads in [1, 2] {
        let pool = pool(threads);
        let is = ImportanceSampling {
            samples: SAMPLES,
            seed: 1,
            form: Form::default(),
            cov: None,
        };
        g.bench_with_input(BenchmarkId::new("threads", threads), &threads, |b, _| {
            pool.install(|| b.iter(|| black_box(is.run(&event).expect("is"))))
        });
    }
    g.finish();

    let mut g = c.benchmark_group("mc/px_21_vars");
    g.sample_size(20);
    g.throughput(Throughput::Elements(SAMPLES));
    for threads in [1, 2] {
        let pool = pool(threads);
        let mc = MonteCarlo {
            samples: SAMPLES,
            seed: 1,
            cov: None,
        };
        g.bench_with_input(BenchmarkId::new("threads", threads), &threads, |b, _| {
            pool.install(|| b.iter(|| black_box(mc.run(&event).expect("mc"))))
        });
    }
    g.finish();
}

criterion_group!(reliability_benches, benches);
criterion_main!(reliability_benches);
