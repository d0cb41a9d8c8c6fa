//! Derivation and runtime-evaluator benchmarks (targets and figures in
//! docs/performance.md). Run with `cargo bench -p chain-core --bench derive`.

use std::hint::black_box;
use std::path::Path;

use chain_core::ErrorModel;
use criterion::{criterion_group, criterion_main, Criterion};

fn machine_text(name: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../examples/machines")
        .join(name);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn derive_from_text(c: &mut Criterion) {
    for name in [
        "gantry_grinder.yaml",
        "cnc5_bevel.yaml",
        "internal_grinder.yaml",
    ] {
        let text = machine_text(name);
        c.bench_function(&format!("yaml_to_model/{name}"), |b| {
            b.iter(|| {
                let machine = chain_core::load_str(black_box(&text), name).expect("valid machine");
                black_box(chain_core::derive(&machine))
            })
        });
    }
}

fn evaluator(c: &mut Criterion) {
    let text = machine_text("gantry_grinder.yaml");
    let machine = chain_core::load_str(&text, "gantry_grinder.yaml").expect("valid machine");
    let model = chain_core::compile(&machine);
    let n = model.errors().len();
    let mut out = vec![0.0; 6 * n];
    let q = [500.0, 750.0, 1000.0];
    c.bench_function("compiled/gantry_sensitivity_6x21", |b| {
        b.iter(|| {
            model.sensitivity(black_box(&q), black_box(&[]), &mut out);
            black_box(&out);
        })
    });
    let e = vec![1e-3; n];
    let mut err = [0.0; 6];
    c.bench_function("compiled/gantry_error", |b| {
        b.iter(|| {
            model.error(black_box(&q), black_box(&[]), black_box(&e), &mut err);
            black_box(&err);
        })
    });

    let text = machine_text("cnc5_bevel.yaml");
    let machine = chain_core::load_str(&text, "cnc5_bevel.yaml").expect("valid machine");
    let params: Vec<f64> = machine
        .parameters
        .iter()
        .map(|p| p.value.unwrap_or(100.0))
        .collect();
    let model = chain_core::compile(&machine);
    let q: Vec<f64> = (0..model.variables().len())
        .map(|i| 0.3 + i as f64)
        .collect();
    let mut out = vec![0.0; 6 * model.errors().len()];
    c.bench_function("compiled/cnc5_bevel_sensitivity", |b| {
        b.iter(|| {
            model.sensitivity(black_box(&q), black_box(&params), &mut out);
            black_box(&out);
        })
    });
}

criterion_group!(benches, derive_from_text, evaluator);
criterion_main!(benches);
