//! `chain identify` benchmarks (docs/performance.md, "chain identify (issue
//! 13)"), on the cubic-Legendre five-axis machine
//! (examples/machines/legendre5.yaml, 131 error parameters) with 10⁴
//! tool-point measurements (3·10⁴ design rows) over its travel, simulated
//! through the compiled model with known errors. Run with
//! `cargo bench --bench identify`.
//!
//! - `identify/end_to_end_1e4`: what `chain identify` does before it writes:
//!   load the machine, parse the measurement CSV text, derive and compile the
//!   model, build the design and identify (SVD, null space, covariance,
//!   leverages);
//! - `identify/design_1e4`, `identify/solve_1e4`: the design matrix and the
//!   identification alone.

use std::hint::black_box;
use std::path::Path;
use std::time::Duration;

use chain::core::measured::{identify, Design, Layout, Measurements};
use chain::core::ErrorModel;
use criterion::{criterion_group, criterion_main, Criterion};

fn machine_path() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/machines/legendre5.yaml")
}

/// 10⁴ measurements as CSV text: the poses on a deterministic pseudo-random
/// spread of the travel, the deviations of fixed errors.
fn csv_text(count: usize) -> String {
    let machine = chain::core::load_file(&machine_path()).unwrap();
    let model = chain::core::compile(&machine);
    let n = model.errors().len();
    let e: Vec<f64> = (0..n)
        .map(|j| 1e-5 * ((j * 7919 % 97) as f64 - 48.0) / 48.0)
        .collect();
    let vars: Vec<&str> = model.variables().to_vec();
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut unit = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let p: Vec<f64> = machine
        .parameters
        .iter()
        .map(|p| p.value.unwrap())
        .collect();
    let mut s = vars.join(",");
    s.push_str(",dpx,dpy,dpz,std\n");
    for _ in 0..count {
        let q: Vec<f64> = vars
            .iter()
            .map(|v| match *v {
                "A" => (unit() * 2.0 - 1.0) * 2.0,
                "C" => (unit() * 2.0 - 1.0) * 3.1,
                _ => (unit() * 2.0 - 1.0) * 390.0,
            })
            .collect();
        let mut out = [0.0; 6];
        model.error(&q, &p, &e, &mut out);
        for v in &q {
            s.push_str(&format!("{v},"));
        }
        s.push_str(&format!("{},{},{},0.001\n", out[0], out[1], out[2]));
    }
    s
}

fn bench(c: &mut Criterion) {
    let text = csv_text(10_000);
    let path = machine_path();
    let mut g = c.benchmark_group("identify");
    g.sample_size(10).measurement_time(Duration::from_secs(20));
    g.bench_function("end_to_end_1e4", |b| {
        b.iter(|| {
            let m = chain::core::load_file(&path).unwrap();
            let meas = Measurements::parse(&text, "m.csv", &m, &[], Layout::Measurements).unwrap();
            let model = chain::core::compile(&m);
            let design = Design::new(&model, &m, &meas.rows).unwrap();
            black_box(identify(&design, None).unwrap())
        })
    });
    let m = chain::core::load_file(&path).unwrap();
    let meas = Measurements::parse(&text, "m.csv", &m, &[], Layout::Measurements).unwrap();
    let model = chain::core::compile(&m);
    g.bench_function("design_1e4", |b| {
        b.iter(|| black_box(Design::new(&model, &m, &meas.rows).unwrap()))
    });
    let design = Design::new(&model, &m, &meas.rows).unwrap();
    g.bench_function("solve_1e4", |b| {
        b.iter(|| black_box(identify(&design, None).unwrap()))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
