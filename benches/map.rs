//! `chain map` benchmarks (docs/performance.md, "chain map"), on
//! the example vmc3 (examples/machines/vmc3.yaml: 3 axes, 24 error
//! parameters) with its values (examples/values/vmc3.yaml: 18 tabulated
//! error motions, 21 positions each, and 3 squareness constants) over a
//! 100 × 100 × 100 grid. Run with `cargo bench --bench map`.
//!
//! - `map/end_to_end_1e6`: what `chain map` does before it writes: load and
//!   validate the machine file, read the values file and its three CSV
//!   tables, derive and compile the model, build the 10⁶ grid points,
//!   evaluate them all (rayon, every core) and summarise;
//! - `map/end_to_end_summary_1e6`: the same, keeping only the summary (what
//!   `chain map --format table` does for a large map);
//! - `map/evaluate_1e6`, `map/evaluate_summary_1e6`: the evaluation and
//!   summary alone (`_one_thread`: on one thread, the cost per point;
//!   `evaluate_list_1e6`: the same points as an explicit list;
//!   `_generated_one_thread`: through the `machine!` type instead of the
//!   compiled tape);
//! - `map/json_1e6`, `map/csv_1e6`: writing the result (serde_json's pretty
//!   JSON; the CSV rows), the I/O part, measured separately;
//! - `point/...`: one point, one thread: the values (`values_at`), the
//!   compiled model's error and sensitivity, and the `machine!`-generated
//!   type's.

use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::time::Duration;

use chain::core::built::{BuiltMachine, Points};
use chain::core::values::Values;
use chain::core::{ErrorModel, ErrorValues};
use criterion::{criterion_group, criterion_main, BatchSize, Criterion};

chain::machine!(Vmc3 = "examples/machines/vmc3.yaml");

fn example(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples")
        .join(path)
}

/// The 100 × 100 × 100 grid in the machine's variable order (y, x, z).
fn grid() -> Points {
    let axis = |hi: f64| {
        (0..100)
            .map(|k| hi * f64::from(k) / 99.0)
            .collect::<Vec<_>>()
    };
    Points::Grid(vec![axis(500.0), axis(800.0), axis(500.0)])
}

/// The grid's points, flat (a list in the same order).
fn full_factorial_of(points: &Points) -> Vec<f64> {
    match points {
        Points::Grid(axes) => chain::core::built::full_factorial(axes),
        Points::List { values, .. } => values.clone(),
    }
}

fn built() -> BuiltMachine {
    let machine = chain::core::load_file(&example("machines/vmc3.yaml")).unwrap();
    let values = Values::read(&example("values/vmc3.yaml"), &machine).unwrap();
    BuiltMachine::compile(&machine, values, vec![150.0]).unwrap()
}

fn map(c: &mut Criterion) {
    let mut g = c.benchmark_group("map");
    g.sample_size(20).measurement_time(Duration::from_secs(20));
    g.bench_function("end_to_end_1e6", |b| {
        b.iter(|| {
            let machine = chain::core::load_file(&example("machines/vmc3.yaml")).unwrap();
            let values = Values::read(&example("values/vmc3.yaml"), &machine).unwrap();
            let built = BuiltMachine::compile(&machine, values, vec![150.0]).unwrap();
            black_box(built.map(grid()).unwrap().summary)
        })
    });
    g.bench_function("end_to_end_summary_1e6", |b| {
        b.iter(|| {
            let machine = chain::core::load_file(&example("machines/vmc3.yaml")).unwrap();
            let values = Values::read(&example("values/vmc3.yaml"), &machine).unwrap();
            let built = BuiltMachine::compile(&machine, values, vec![150.0]).unwrap();
            black_box(built.summary(&grid(), &|_| {}).unwrap())
        })
    });
    let b1 = built();
    let points = grid();
    g.bench_function("evaluate_1e6", |b| {
        b.iter(|| black_box(b1.map(points.clone()).unwrap().summary))
    });
    g.bench_function("evaluate_summary_1e6", |b| {
        b.iter(|| black_box(b1.summary(&points, &|_| {}).unwrap()))
    });
    // One thread: the cost per point.
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    g.bench_function("evaluate_1e6_one_thread", |b| {
        b.iter(|| one.install(|| black_box(b1.map(points.clone()).unwrap().summary)))
    });
    // The same map through the `machine!`-generated type.
    let machine = chain::core::load_file(&example("machines/vmc3.yaml")).unwrap();
    let values = Values::read(&example("values/vmc3.yaml"), &machine).unwrap();
    let generated = BuiltMachine::new(&machine, Vmc3, values, vec![150.0]).unwrap();
    g.bench_function("evaluate_1e6_generated_one_thread", |b| {
        b.iter(|| one.install(|| black_box(generated.map(points.clone()).unwrap().summary)))
    });
    let list = Points::list(3, full_factorial_of(&points)).unwrap();
    g.bench_function("evaluate_list_1e6", |b| {
        b.iter_batched(
            || list.clone(),
            |p| black_box(b1.map(p).unwrap().summary),
            BatchSize::LargeInput,
        )
    });
    let result = b1.map(points).unwrap();
    g.sample_size(10);
    g.bench_function("json_1e6", |b| {
        b.iter(|| black_box(serde_json::to_string_pretty(&result).unwrap().len()))
    });
    g.bench_function("csv_1e6", |b| {
        b.iter(|| {
            let mut w = csv::Writer::from_writer(Vec::with_capacity(100 << 20));
            for i in 0..result.len() {
                let mut row: Vec<String> = result.point(i).iter().map(|x| format!("{x}")).collect();
                row.extend(result.errors[i].iter().map(|x| format!("{x}")));
                row.push(format!("{}", result.volumetric(i)));
                w.write_record(&row).unwrap();
            }
            black_box(w.into_inner().unwrap().len())
        })
    });
    g.finish();
}

fn point(c: &mut Criterion) {
    let b1 = built();
    let model = b1.model();
    let values = b1.values();
    let n = model.errors().len();
    let q = [333.3, 444.4, 222.2];
    let p = [150.0];
    let mut e = vec![0.0; n];
    let mut out = [0.0; 6];
    let mut s = vec![0.0; 6 * n];
    let mut g = c.benchmark_group("point");
    g.bench_function("values_at", |b| {
        b.iter(|| {
            values.values_at(black_box(&q), &mut e).unwrap();
            black_box(&e);
        })
    });
    values.values_at(&q, &mut e).unwrap();
    g.bench_function("compiled_error", |b| {
        b.iter(|| {
            model.error(black_box(&q), &p, black_box(&e), &mut out);
            black_box(&out);
        })
    });
    g.bench_function("compiled_sensitivity", |b| {
        b.iter(|| {
            model.sensitivity(black_box(&q), &p, &mut s);
            black_box(&s);
        })
    });
    g.bench_function("generated_error", |b| {
        b.iter(|| {
            Vmc3.error(black_box(&q), &p, black_box(&e), &mut out);
            black_box(&out);
        })
    });
    g.bench_function("generated_sensitivity", |b| {
        b.iter(|| {
            Vmc3.sensitivity(black_box(&q), &p, &mut s);
            black_box(&s);
        })
    });
    g.bench_function("built_error_into", |b| {
        b.iter(|| {
            b1.error_into(black_box(&q), &mut e, &mut out).unwrap();
            black_box(&out);
        })
    });
    g.finish();
}

criterion_group!(benches, point, map);
criterion_main!(benches);
