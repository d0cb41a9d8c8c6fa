//! Criterion benchmark of subset simulation (`reliability::subset`) to
//! p_f ≈ 1e-6 at a coefficient of variation of about 10 %, the case of
//! `openturns_subset.py` (OpenTURNS' `SubsetSampling` on the same limit
//! state, for the time ratio in `docs/performance.md`).
//!
//! The case: px of the gantry grinder (seed 000, Table 1 inputs) at the
//! corner (x, y, z) = (1000, 1500, 1400), its tolerance set to
//! `4.7534·σ_px` so that `p_f = Φ(−4.7534) = 1.00e-6` exactly (one upper
//! tolerance in normal inputs). N = 10,000 samples per level, p0 = 0.1:
//! six levels, CoV ≈ 0.10 (printed once before timing).
//!
//! Run: `cargo bench -p reliability --bench subset` (`SUBSET_RUNS=n` in the
//! environment: n untimed runs, for callgrind); with `PRINT_CASE=1` in the
//! environment it prints the standard-space coefficients for the script.

use std::hint::black_box;
use std::path::Path;

use chain_core::model::{Component, Sided};
use criterion::{criterion_group, criterion_main, Criterion};
use reliability::{machine, normal, Event, Sampler, Study, SubsetSimulation, ToleranceLimitState};

const BETA: f64 = 4.7534;

fn case() -> (Study, usize) {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/machines/gantry_grinder.yaml");
    let m = chain_core::load_file(&path).expect("gantry_grinder.yaml");
    let model = chain_core::compile(&m);
    let study = machine::study(&m, &model, &[], None).expect("study");
    let v = |n: &str| study.variables().iter().position(|x| x == n).unwrap();
    let (x, y, z) = (v("x"), v("y"), v("z"));
    let p = study
        .points()
        .iter()
        .position(|q| q[x] == 1000.0 && q[y] == 1500.0 && q[z] == 1400.0)
        .expect("corner");
    (study, p)
}

fn benches(c: &mut Criterion) {
    let (study, p) = case();
    let row = study.row(p, Component::Px).unwrap().to_vec();
    let a: Vec<f64> = row
        .iter()
        .zip(study.inputs().stds())
        .map(|(s, d)| s * d)
        .collect();
    let sigma = a.iter().map(|v| v * v).sum::<f64>().sqrt();
    if std::env::var_os("PRINT_CASE").is_some() {
        let nz: Vec<String> = a
            .iter()
            .filter(|v| **v != 0.0)
            .map(|v| format!("{v:e}"))
            .collect();
        println!("a = [{}]  # px row · std at the corner", nz.join(", "));
        println!("tolerance = {:e}", BETA * sigma);
    }
    let ls = ToleranceLimitState::component(row, BETA * sigma, Sided::Upper).expect("ls");
    let event = Event::new(study.inputs(), ls).expect("event");
    let ss = SubsetSimulation::new(10_000, 1);
    let r = ss.run(&event).expect("subset");
    eprintln!(
        "subset: pf {:.3e} (exact {:.3e}), CoV {:.3}, {} levels, {} calls",
        r.pf,
        normal::sf(BETA),
        r.cov,
        r.levels.len(),
        r.calls
    );
    // `SUBSET_RUNS=n`: n runs and no timing, for instruction counts
    // (`valgrind --tool=callgrind`, docs/performance.md).
    if let Some(n) = std::env::var("SUBSET_RUNS")
        .ok()
        .and_then(|v| v.parse::<u32>().ok())
    {
        for _ in 0..n {
            black_box(ss.run(&event).expect("subset"));
        }
        return;
    }
    let mut g = c.benchmark_group("subset");
    g.sample_size(20);
    g.bench_function("px_pf_1e-6_N10000", |b| {
        b.iter(|| black_box(ss.run(&event).expect("subset")))
    });
    g.finish();
}

criterion_group!(group, benches);
criterion_main!(group);
