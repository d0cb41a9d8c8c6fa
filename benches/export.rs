//! `chain export --controller grid` benchmarks (docs/performance.md,
//! "chain export --controller grid"), on the example five-axis
//! ac_trunnion (examples/machines/ac_trunnion.yaml: y, A, C, x, z; 41 error
//! parameters) with a values file of its 41 errors (40 constants of
//! 10 µm / 10 µrad class and the X positioning error as a 3-point table)
//! over a 10 × 10 × 100 × 10 × 10 = 10⁶ node grid (y, A, C, x, z). Run with
//! `cargo bench --bench export`.
//!
//! - `export/grid_1e6`: the whole export of the 10⁶ nodes (rayon, every
//!   core): per node the error, the nominal pose and its exact Jacobian
//!   (one pass of dual numbers), the hierarchical solve, and the residual
//!   through the model at `q + δq`, then the summary;
//! - `export/grid_1e5_one_thread`: 10⁵ nodes on one thread (the cost per
//!   node);
//! - `node/jacobian_dual`, `node/jacobian_jets`: one node's exact Jacobian
//!   by the dual pass the export uses and by `Kinematics::jacobian` (the
//!   reference it is tested against);
//! - `export/csv_1e5`: writing 10⁵ nodes' CSV.

use std::hint::black_box;
use std::path::Path;
use std::time::Duration;

use chain::core::built::{BuiltMachine, Points};
use chain::core::compensation::grid;
use chain::core::kinematics::Kinematics;
use chain::core::values::Values;
use chain::core::Machine;
use criterion::{criterion_group, criterion_main, Criterion};

fn machine() -> Machine {
    chain::core::load_file(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/machines/ac_trunnion.yaml"),
    )
    .unwrap()
}

/// The values: every error a constant of ±10 µm / ±10 µrad, EXX a table.
fn built(m: &Machine) -> BuiltMachine {
    let mut text = String::from("machine: ac_trunnion\nvalues:\n");
    for (k, e) in m.errors.iter().enumerate() {
        let linear = matches!(e.name.as_bytes().get(1), Some(b'X' | b'Y' | b'Z'));
        let size = if linear { 0.010 } else { 10e-6 };
        let v = size * ((k as f64 * 0.7).sin());
        if e.name == "EXX" {
            text.push_str("  EXX: {points: [[-10, 0], [400, 0.006], [810, 0.010]]}\n");
        } else {
            text.push_str(&format!("  {}: {v:e}\n", e.name));
        }
    }
    let values = Values::parse(&text, "bench.yaml", Path::new("."), m).unwrap();
    let params = m.parameters.iter().map(|p| p.value.unwrap()).collect();
    BuiltMachine::compile(m, values, params).unwrap()
}

fn axis(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| lo + (hi - lo) * k as f64 / (n - 1) as f64)
        .collect()
}

/// The grid in the machine's variable order, `fine` nodes of C: 10⁴·`fine` nodes.
fn grid(m: &Machine, fine: usize) -> Points {
    Points::Grid(
        (m.variables.iter())
            .map(|v| match v.name.as_str() {
                "y" => axis(-200.0, 300.0, 10),
                "A" => axis(-1.0, 0.5, 10),
                "C" => axis(-3.0, 3.0, fine),
                "x" => axis(0.0, 800.0, 10),
                _ => axis(-300.0, 0.0, 10),
            })
            .collect(),
    )
}

fn benches(c: &mut Criterion) {
    let m = machine();
    let b = built(&m);
    let kin = Kinematics::from_machine(&m);
    let mut g = c.benchmark_group("export");
    g.sample_size(10).measurement_time(Duration::from_secs(20));
    g.bench_function("grid_1e6", |bench| {
        bench.iter(|| black_box(grid::export(&b, &kin, grid(&m, 100)).unwrap()))
    });
    g.bench_function("grid_1e5_one_thread", |bench| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        bench.iter(|| pool.install(|| black_box(grid::export(&b, &kin, grid(&m, 10)).unwrap())))
    });
    let small = grid::export(&b, &kin, grid(&m, 10)).unwrap();
    g.bench_function("csv_1e5", |bench| bench.iter(|| black_box(small.csv(""))));
    g.finish();
    let mut g = c.benchmark_group("node");
    let q = [100.0, 0.3, 1.2, 400.0, -100.0];
    let p = [150.0, 200.0];
    g.bench_function("jacobian_dual", |bench| {
        bench.iter(|| black_box(grid::pose_and_jacobian(&kin, black_box(&q), &p)))
    });
    let mut scratch = b.scratch();
    g.bench_function("error", |bench| {
        bench.iter(|| {
            let mut e = [0.0; 6];
            b.error_into(black_box(&q), &mut scratch, &mut e).unwrap();
            black_box(e)
        })
    });
    g.bench_function("jacobian_jets", |bench| {
        bench.iter(|| black_box(kin.jacobian(black_box(&q), &p)))
    });
    g.finish();
}

criterion_group!(export, benches);
criterion_main!(export);
