//! Inverse-kinematics throughput (the target: at least 10^6 poses per second
//! per core for closed-form chains; figures in docs/performance.md). Run with
//! `cargo bench -p chain-core --bench inverse`.

use std::hint::black_box;
use std::path::Path;

use chain_core::inverse::Solver;
use chain_core::model::JointKind;
use chain_core::ErrorModel;
use criterion::{criterion_group, criterion_main, Criterion, Throughput};

const POSES: usize = 10_000;

fn closed_form(c: &mut Criterion) {
    let mut group = c.benchmark_group("inverse");
    group.throughput(Throughput::Elements(POSES as u64));
    for (name, fixed) in [
        ("ac_trunnion", None),
        ("head_head_bc", None),
        ("cnc5_bevel", Some("mu")),
    ] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../examples/machines")
            .join(format!("{name}.yaml"));
        let machine = chain_core::load_file(&path).expect("valid machine");
        let model = chain_core::compile(&machine);
        let kinds: Vec<JointKind> = machine.variables.iter().map(|v| v.kind).collect();
        let params: Vec<f64> = model
            .parameter_values()
            .iter()
            .map(|v| v.unwrap_or(0.0))
            .collect();
        let fixed: Vec<(usize, f64)> = fixed
            .map(|f| {
                machine
                    .variables
                    .iter()
                    .position(|v| v.name == f)
                    .expect("variable")
            })
            .map(|i| (i, 0.0))
            .into_iter()
            .collect();
        let solver = Solver::new(&model, &kinds, &params, &fixed).expect("closed form");
        // Reachable poses from pseudo-random axis values (a fixed LCG).
        let mut state = 0x2545_F491_4F6C_DD1Du64;
        let mut uniform = move || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let poses: Vec<([f64; 3], [f64; 3])> = (0..POSES)
            .map(|_| {
                let q: Vec<f64> = kinds
                    .iter()
                    .enumerate()
                    .map(|(i, k)| match k {
                        _ if fixed.iter().any(|f| f.0 == i) => 0.0,
                        JointKind::Rotary => (uniform() - 0.5) * 6.0,
                        JointKind::Prismatic => (uniform() - 0.5) * 1000.0,
                    })
                    .collect();
                let pose = model.nominal(&q, &params);
                let r = pose.rotation;
                (pose.position, [r[0][2], r[1][2], r[2][2]])
            })
            .collect();
        let start = vec![0.0; kinds.len()];
        group.bench_function(format!("closed_form/{name}"), |b| {
            b.iter(|| {
                let mut found = 0usize;
                for (point, axis) in &poses {
                    found += solver
                        .solve(black_box(*point), black_box(*axis), &start)
                        .solutions
                        .len();
                }
                black_box(found)
            })
        });
    }
    group.finish();
}

criterion_group!(benches, closed_form);
criterion_main!(benches);
