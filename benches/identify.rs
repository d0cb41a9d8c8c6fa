//! `chain identify` benchmarks (docs/performance.md, "chain identify"), on
//! the cubic-Legendre five-axis machine
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
//!   identification alone;
//! - the same three with the suffix `_173`: the machine with degree-5
//!   Legendre series on the linear axes and degree 4 on C (18·6 + 6·4 +
//!   6·5 + 11 = 173 unknowns, above the 170-unknown target), the same 10⁴
//!   measurements.

use std::hint::black_box;
use std::path::Path;
use std::time::Duration;

use chain::core::measured::{identify, Design, Layout, Measurements};
use chain::core::ErrorModel;
use criterion::{criterion_group, criterion_main, Criterion};

fn machine_path() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/machines/legendre5.yaml")
}

/// The machine file's text: legendre5 as it is (131 unknowns), or with
/// degree 5 on the linear axes and degree 4 on C (173 unknowns).
fn machine_text(large: bool) -> String {
    let text = std::fs::read_to_string(machine_path()).unwrap();
    if !large {
        return text;
    }
    text.lines()
        .map(|l| {
            if l.contains("range: [-400, 400]") {
                l.replace("degree: 3", "degree: 5")
            } else if l.contains("range: [-3.14") {
                l.replace("degree: 3", "degree: 4")
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
}

fn load(text: &str) -> chain::core::Machine {
    chain::core::load_str(text, "legendre5.yaml").unwrap()
}

/// 10⁴ measurements as CSV text: the poses on a deterministic pseudo-random
/// spread of the travel, the deviations of fixed errors.
fn csv_text(machine_text: &str, count: usize) -> String {
    let machine = load(machine_text);
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
    let mut g = c.benchmark_group("identify");
    g.sample_size(10).measurement_time(Duration::from_secs(20));
    for (large, suffix) in [(false, ""), (true, "_173")] {
        let machine = machine_text(large);
        let text = csv_text(&machine, 10_000);
        let m = load(&machine);
        assert_eq!(m.errors.len(), if large { 173 } else { 131 });
        g.bench_function(format!("end_to_end_1e4{suffix}"), |b| {
            b.iter(|| {
                let m = load(&machine);
                let meas =
                    Measurements::parse(&text, "m.csv", &m, &[], Layout::Measurements).unwrap();
                let model = chain::core::compile(&m);
                let design = Design::new(&model, &m, &meas.rows).unwrap();
                black_box(identify(&design, None, &Default::default()).unwrap())
            })
        });
        let meas = Measurements::parse(&text, "m.csv", &m, &[], Layout::Measurements).unwrap();
        let model = chain::core::compile(&m);
        g.bench_function(format!("design_1e4{suffix}"), |b| {
            b.iter(|| black_box(Design::new(&model, &m, &meas.rows).unwrap()))
        });
        let design = Design::new(&model, &m, &meas.rows).unwrap();
        g.bench_function(format!("solve_1e4{suffix}"), |b| {
            b.iter(|| black_box(identify(&design, None, &Default::default()).unwrap()))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
