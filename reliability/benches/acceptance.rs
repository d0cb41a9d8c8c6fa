//! Criterion benchmarks of the whole-machine acceptance probability
//! (`reliability::acceptance`) on the gantry grinder of seed 000: the 375
//! constraints (125 points × px, py, pz) to an absolute error of 1e-3
//! (three standard errors), with and without the sensitivities.
//!
//! Run with `cargo bench -p reliability --bench acceptance`; the figures are
//! in `docs/performance.md` ("Whole-machine acceptance probability").

use std::hint::black_box;
use std::path::Path;

use criterion::{criterion_group, criterion_main, Criterion};
use reliability::acceptance::{Acceptance, Rectangles};
use reliability::machine;

fn bench(c: &mut Criterion) {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/machines/gantry_grinder.yaml");
    let m = chain_core::load_file(&path).expect("gantry_grinder.yaml");
    let model = chain_core::compile(&m);
    let study = machine::study(&m, &model, &[], None).expect("study");
    let system = Rectangles::from_study(&study).expect("constraints");
    let mut g = c.benchmark_group("acceptance");
    g.sample_size(20);
    g.bench_function("gantry_375/abs_1e-3/with_sensitivities", |b| {
        b.iter(|| black_box(Acceptance::default().run(&system).unwrap()))
    });
    let plain = Acceptance {
        sensitivity: false,
        ..Acceptance::default()
    };
    g.bench_function("gantry_375/abs_1e-3/probability_only", |b| {
        b.iter(|| black_box(plain.run(&system).unwrap()))
    });
    g.bench_function("gantry_375/from_study", |b| {
        b.iter(|| black_box(Rectangles::from_study(&study).unwrap()))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
