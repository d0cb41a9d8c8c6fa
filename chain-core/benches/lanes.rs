//! `chain_core::lanes::sin_cos` (four lanes, written to vectorise) against
//! `wide`'s `f64x4::sin_cos` (the same algorithm) and four calls of the
//! standard library's `sin_cos`: why the batched kernels use their own
//! (docs/performance.md, "Batched generated kernels"). Run with
//! `cargo bench -p chain-core --bench lanes`.

use std::hint::black_box;

use chain_core::lanes::sin_cos;
use criterion::{criterion_group, criterion_main, Criterion, Throughput};

/// 1,024 angles over ±3 turns.
fn angles() -> Vec<[f64; 4]> {
    (0..256)
        .map(|g| {
            std::array::from_fn(|l| {
                ((g * 4 + l) as f64 * 0.618_033_988_749_895).fract() * 37.0 - 18.5
            })
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let xs = angles();
    for x in &xs {
        let (s, co) = sin_cos(*x);
        let (ws, wc) = wide::f64x4::new(*x).sin_cos();
        for l in 0..4 {
            assert!(
                (s[l] - ws.to_array()[l]).abs() < 1e-15 && (co[l] - wc.to_array()[l]).abs() < 1e-15
            );
        }
    }
    let mut g = c.benchmark_group("sin_cos");
    g.throughput(Throughput::Elements(1024));
    g.bench_function("lanes", |b| {
        b.iter(|| {
            for x in &xs {
                black_box(sin_cos(black_box(*x)));
            }
        })
    });
    #[cfg(target_arch = "x86_64")]
    if std::is_x86_feature_detected!("avx2") {
        /// The same kernel compiled for AVX2 (four lanes per instruction).
        #[target_feature(enable = "avx2")]
        unsafe fn all_avx2(xs: &[[f64; 4]]) {
            for x in xs {
                black_box(sin_cos(black_box(*x)));
            }
        }
        g.bench_function("lanes_avx2", |b| {
            // SAFETY: AVX2 was detected above.
            b.iter(|| unsafe { all_avx2(&xs) })
        });
    }
    g.bench_function("wide_f64x4", |b| {
        b.iter(|| {
            for x in &xs {
                black_box(wide::f64x4::new(black_box(*x)).sin_cos());
            }
        })
    });
    g.bench_function("std_per_value", |b| {
        b.iter(|| {
            for x in &xs {
                for v in black_box(*x) {
                    black_box(v.sin_cos());
                }
            }
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
