//! Function slots: deriving a five-axis machine whose 30 error
//! motions are cubic Legendre series (`examples/machines/legendre5.yaml`, 131
//! error parameters) and evaluating its 6×131 sensitivity, with the runtime
//! tape and with the code `machine!` generates for it
//! (`benches/generated/legendre5.rs`, kept current by a unit test of
//! `emit.rs`). Figures in docs/performance.md, "Function slots".
//! Run with `cargo bench -p chain-core --bench function_slots`.

use std::hint::black_box;
use std::path::Path;

use chain_core::ErrorModel;
use criterion::{criterion_group, criterion_main, Criterion};

/// The facade path the generated code names (`crate::shim::core::ErrorModel`).
mod shim {
    pub use chain_core as core;
}

// The bench uses only some of the generated type's items.
#[allow(dead_code)]
mod generated {
    include!("generated/legendre5.rs");
}

fn machine_text(name: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../examples/machines")
        .join(name);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn derivation(c: &mut Criterion) {
    for name in ["legendre5.yaml", "ac_trunnion.yaml"] {
        let text = machine_text(name);
        let machine = chain_core::load_str(&text, name).expect("valid machine");
        c.bench_function(&format!("function_slots/yaml_to_model/{name}"), |b| {
            b.iter(|| {
                let machine = chain_core::load_str(black_box(&text), name).expect("valid machine");
                black_box(chain_core::derive(&machine))
            })
        });
        c.bench_function(&format!("function_slots/derive/{name}"), |b| {
            b.iter(|| black_box(chain_core::derive(black_box(&machine))))
        });
        // The cross-check route keeps every coefficient (and its basis
        // weight) inside the product: what the matrix route would cost
        // without deriving each slot once.
        c.bench_function(&format!("function_slots/derive_dmm/{name}"), |b| {
            b.iter(|| {
                black_box(chain_core::dmm::derive_dmm(
                    black_box(&machine),
                    machine.frame,
                ))
            })
        });
        c.bench_function(&format!("function_slots/compile/{name}"), |b| {
            b.iter(|| black_box(chain_core::compile(black_box(&machine))))
        });
    }
}

fn sensitivity(c: &mut Criterion) {
    let q = [120.0, 0.7, -2.1, -250.0, 310.0];
    let p = [150.0, 200.0];
    for name in ["legendre5.yaml", "ac_trunnion.yaml"] {
        let machine = chain_core::load_str(&machine_text(name), name).expect("valid machine");
        let model = chain_core::compile(&machine);
        let n = model.errors().len();
        let mut out = vec![0.0; 6 * n];
        c.bench_function(&format!("function_slots/tape_sensitivity/{name}"), |b| {
            b.iter(|| {
                model.sensitivity(black_box(&q), black_box(&p), &mut out);
                black_box(&out);
            })
        });
    }
    c.bench_function("function_slots/generated_sensitivity/legendre5.yaml", |b| {
        b.iter(|| {
            black_box(generated::Legendre5::sensitivity(
                black_box(&q),
                black_box(&p),
            ))
        })
    });
    let e = [1e-4; 131];
    c.bench_function("function_slots/generated_error/legendre5.yaml", |b| {
        b.iter(|| {
            black_box(generated::Legendre5::error(
                black_box(&q),
                black_box(&p),
                &e,
            ))
        })
    });
}

criterion_group!(benches, derivation, sensitivity);
criterion_main!(benches);
