//! `chain plan`'s library: K = 50 of 10⁴ candidate poses (the target: under
//! 1 s), on the gantry grinder (21 errors) and the cubic-Legendre 5-axis
//! machine (131 errors): the design rows (`measured::Design`, the exact
//! sensitivity at every candidate) and the D-optimal search, separately and
//! together. Rerun: `cargo bench --offline --bench plan`.

use chain::core::measured::{Design, Measurement, Observed};
use chain::core::plan::{self, Rows};
use chain::core::Machine;
use criterion::{criterion_group, criterion_main, Criterion};

/// Point candidates of `m` (machine order): a deterministic spread (a Weyl
/// sequence) over ±500 mm and ±1 rad.
fn candidates(m: &Machine, p: &[f64], n: usize) -> Vec<Measurement> {
    let golden = [
        0.754_877_666,
        0.569_840_291,
        0.430_159_709,
        0.324_717_957,
        0.245_122_334,
        0.185_037_6,
    ];
    (0..n)
        .map(|i| Measurement {
            line: i + 2,
            q: (m.variables.iter().enumerate())
                .map(|(k, v)| {
                    let t = ((i as f64 + 0.5) * golden[k % 6]).fract() * 2.0 - 1.0;
                    if v.name.chars().next().is_some_and(char::is_uppercase) {
                        t
                    } else {
                        500.0 * t
                    }
                })
                .collect(),
            p: p.to_vec(),
            observed: Observed::Point,
            values: vec![],
            std: None,
            setup: None,
            temperatures: Vec::new(),
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    for file in ["gantry_grinder.yaml", "legendre5.yaml"] {
        let m = chain::core::load_file(std::path::Path::new(&format!("examples/machines/{file}")))
            .unwrap();
        let model = chain::core::compile(&m);
        let p: Vec<f64> = m
            .parameters
            .iter()
            .map(|p| p.value.unwrap_or(0.0))
            .collect();
        let cands = candidates(&m, &p, 10_000);
        let rows = Rows::of(&model, &m, &cands).unwrap();
        let mut g = c.benchmark_group("plan");
        g.sample_size(10);
        g.bench_function(format!("{file} K=50 of 10^4 (rows + plan)"), |b| {
            b.iter(|| {
                let rows = Rows::of(&model, &m, &cands).unwrap();
                plan::plan(&rows, 50).unwrap()
            })
        });
        g.bench_function(format!("{file} 10^4 design rows"), |b| {
            b.iter(|| Design::new(&model, &m, &cands).unwrap())
        });
        g.bench_function(format!("{file} K=50 of 10^4 (plan only)"), |b| {
            b.iter(|| plan::plan(&rows, 50).unwrap())
        });
        g.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
