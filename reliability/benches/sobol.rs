//! Criterion benchmark of `reliability::sobol` on the gantry grinder of seed
//! 000 (`examples/machines/gantry_grinder.yaml`) at the point
//! (x, y, z) = (500, 1500, 600): N = 10⁵ base samples, 21 inputs, the outputs
//! px, py, pz and |p| (N·(k + 2) = 2.3·10⁶ evaluations of each), first-order
//! and total indices with bootstrap intervals.
//!
//! - `sobol/n1e5_b100/{1,2}_threads`: 100 bootstrap replicates (OpenTURNS'
//!   default bootstrap size, the case `openturns_sobol.py` times);
//! - `sobol/n1e5_b1000/2_threads`: the CLI's default 1000 replicates.
//!
//! Run with `cargo bench -p reliability --bench sobol`; figures in
//! `docs/performance.md`.

use std::hint::black_box;
use std::path::Path;

use criterion::{criterion_group, criterion_main, Criterion};
use reliability::sobol::Sobol;
use reliability::{machine, Study};

fn study() -> Study {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/machines/gantry_grinder.yaml");
    let m = chain_core::load_file(&path).expect("gantry_grinder.yaml");
    let model = chain_core::compile(&m);
    let point: Vec<f64> = m
        .variables
        .iter()
        .map(|v| match v.name.as_str() {
            "x" => 500.0,
            "y" => 1500.0,
            _ => 600.0,
        })
        .collect();
    let spec = machine::spec(&m, None).expect("spec");
    let inputs = machine::inputs(&m).expect("inputs");
    let params = machine::parameters(&m, &[]).expect("parameters");
    Study::at_points(&model, &params, inputs, spec, vec![point]).expect("study")
}

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool")
}

fn benches(c: &mut Criterion) {
    let study = study();
    let mut g = c.benchmark_group("sobol");
    g.sample_size(10);
    for (name, bootstrap, threads) in [
        ("n1e5_b100/1_threads", 100, 1),
        ("n1e5_b100/2_threads", 100, 2),
        ("n1e5_b1000/2_threads", 1000, 2),
    ] {
        let s = Sobol {
            samples: 100_000,
            seed: 1,
            bootstrap,
            confidence: 0.95,
        };
        let p = pool(threads);
        g.bench_function(name, |b| {
            b.iter(|| p.install(|| black_box(s.run_study(&study).expect("sobol"))))
        });
    }
    g.finish();
}

criterion_group!(sobol, benches);
criterion_main!(sobol);
