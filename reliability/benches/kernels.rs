//! Criterion benchmarks of the numerical kernels against the crates that
//! could replace them, in one run (the rule: a hand-written kernel stays only
//! where it is at least 1.3× faster or measurably more accurate).
//!
//! Run with `cargo bench -p reliability --bench kernels`; the figures and the
//! verdicts are in `docs/performance.md` and next to each kernel.
//!
//! - `normal/cdf/*`: `Φ(x) = ½·erfc(−x/√2)` over 1024 points of `[−8, 8]`,
//!   with `libm`'s `erfc` (the library's) and with `statrs`' `erfc`;
//! - `normal/pdf/*`: `φ(x)` as the library's formula and as `statrs`'
//!   `Normal::pdf`;
//! - `normal/quantile/*`: `Φ⁻¹(p)` over 1024 points log-spaced in
//!   `[10⁻¹⁶, ½]` and mirrored into `[½, 1 − 10⁻¹⁶]`, with `statrs`' `erfc_inv`
//!   (the library's) and with a hand-written Acklam + Halley kernel (below
//!   as [`former::inverse_cdf`], for this comparison only);
//! - `variates/normal/*`: 1024 standard normal variates from one ChaCha8
//!   stream, with the library's 32-bit ziggurat (`CaseRng::fill_normal`) and
//!   with `rand_distr::StandardNormal`;
//! - `variates/words/*`: 1024 raw 64-bit words, straight from `rand_chacha`
//!   (the library's) and through a 64-word buffer ([`former::Buffered`]).

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use rand::{Rng, RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use reliability::normal;
use reliability::rng::CaseRng;
use statrs::distribution::{Continuous, Normal};

const N: usize = 1024;

/// Hand-written kernels the library does not use, kept here only to be
/// measured against the library's.
mod former {
    /// A hand-written `Φ⁻¹`: Acklam's rational approximation refined by two
    /// Halley steps on `Φ(x) − p` (with `libm`'s `erfc`).
    pub fn inverse_cdf(p: f64) -> f64 {
        if p.is_nan() || !(0.0..=1.0).contains(&p) {
            return f64::NAN;
        }
        if p == 0.0 {
            return f64::NEG_INFINITY;
        }
        if p == 1.0 {
            return f64::INFINITY;
        }
        if p > 0.5 {
            return -lower_quantile(1.0 - p);
        }
        lower_quantile(p)
    }

    fn lower_quantile(p: f64) -> f64 {
        const A: [f64; 6] = [
            -3.969_683_028_665_376e1,
            2.209_460_984_245_205e2,
            -2.759_285_104_469_687e2,
            1.383_577_518_672_69e2,
            -3.066_479_806_614_716e1,
            2.506_628_277_459_239,
        ];
        const B: [f64; 5] = [
            -5.447_609_879_822_406e1,
            1.615_858_368_580_409e2,
            -1.556_989_798_598_866e2,
            6.680_131_188_771_972e1,
            -1.328_068_155_288_572e1,
        ];
        const C: [f64; 6] = [
            -7.784_894_002_430_293e-3,
            -3.223_964_580_411_365e-1,
            -2.400_758_277_161_838,
            -2.549_732_539_343_734,
            4.374_664_141_464_968,
            2.938_163_982_698_783,
        ];
        const D: [f64; 4] = [
            7.784_695_709_041_462e-3,
            3.224_671_290_700_398e-1,
            2.445_134_137_142_996,
            3.754_408_661_907_416,
        ];
        const P_LOW: f64 = 0.024_25;
        let mut x = if p < P_LOW {
            let q = (-2.0 * p.ln()).sqrt();
            (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
                / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
        } else {
            let q = p - 0.5;
            let r = q * q;
            (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
                / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
        };
        for _ in 0..2 {
            let e = super::normal::cdf(x) - p;
            let d = super::normal::pdf(x);
            if d == 0.0 || !e.is_finite() {
                break;
            }
            let u = e / d;
            x -= u / (1.0 + 0.5 * x * u);
        }
        x
    }

    /// A buffered stream: ChaCha8 output copied into a 64-word buffer.
    pub struct Buffered {
        inner: rand_chacha::ChaCha8Rng,
        buffer: [u64; 64],
        position: usize,
    }

    impl Buffered {
        pub fn new(inner: rand_chacha::ChaCha8Rng) -> Buffered {
            Buffered {
                inner,
                buffer: [0; 64],
                position: 64,
            }
        }

        #[inline(always)]
        pub fn next_u64(&mut self) -> u64 {
            if self.position == 64 {
                self.refill();
            }
            let w = self.buffer[self.position];
            self.position += 1;
            w
        }

        #[inline(never)]
        fn refill(&mut self) {
            use rand::Rng;
            let mut bytes = [0u8; 64 * 8];
            self.inner.fill_bytes(&mut bytes);
            for (w, chunk) in self.buffer.iter_mut().zip(bytes.chunks_exact(8)) {
                let mut b = [0u8; 8];
                b.copy_from_slice(chunk);
                *w = u64::from_le_bytes(b);
            }
            self.position = 0;
        }
    }
}

fn stream() -> ChaCha8Rng {
    let mut r = ChaCha8Rng::seed_from_u64(1);
    r.set_stream(7 << 32);
    r
}

fn benches(c: &mut Criterion) {
    let xs: Vec<f64> = (0..N)
        .map(|i| -8.0 + 16.0 * i as f64 / (N - 1) as f64)
        .collect();
    let half = N / 2;
    let mut ps: Vec<f64> = (0..half)
        .map(|i| 10f64.powf(-16.0 + 16.0 * i as f64 / half as f64) * 0.5)
        .collect();
    let upper: Vec<f64> = ps.iter().map(|p| 1.0 - p).collect();
    ps.extend(upper);
    let statrs_normal = Normal::standard();

    let mut g = c.benchmark_group("normal/cdf");
    g.throughput(Throughput::Elements(N as u64));
    g.bench_function("libm_erfc", |b| {
        b.iter(|| black_box(&xs).iter().map(|&x| normal::cdf(x)).sum::<f64>())
    });
    g.bench_function("statrs_erfc", |b| {
        b.iter(|| {
            black_box(&xs)
                .iter()
                .map(|&x| 0.5 * statrs::function::erf::erfc(-x * std::f64::consts::FRAC_1_SQRT_2))
                .sum::<f64>()
        })
    });
    g.finish();

    let mut g = c.benchmark_group("normal/pdf");
    g.throughput(Throughput::Elements(N as u64));
    g.bench_function("formula", |b| {
        b.iter(|| black_box(&xs).iter().map(|&x| normal::pdf(x)).sum::<f64>())
    });
    g.bench_function("statrs", |b| {
        b.iter(|| {
            black_box(&xs)
                .iter()
                .map(|&x| statrs_normal.pdf(x))
                .sum::<f64>()
        })
    });
    g.finish();

    let mut g = c.benchmark_group("normal/quantile");
    g.throughput(Throughput::Elements(N as u64));
    g.bench_function("statrs_erfc_inv", |b| {
        b.iter(|| {
            black_box(&ps)
                .iter()
                .map(|&p| normal::inverse_cdf(p))
                .sum::<f64>()
        })
    });
    g.bench_function("acklam_halley", |b| {
        b.iter(|| {
            black_box(&ps)
                .iter()
                .map(|&p| former::inverse_cdf(p))
                .sum::<f64>()
        })
    });
    g.finish();

    let mut g = c.benchmark_group("variates/normal");
    g.throughput(Throughput::Elements(N as u64));
    let mut out = vec![0.0; N];
    let mut rng = CaseRng::new(1, 7, 0);
    g.bench_function("ziggurat32", |b| {
        b.iter(|| {
            rng.fill_normal(&mut out);
            black_box(&out);
        })
    });
    let mut rng = CaseRng::new(1, 7, 0);
    g.bench_function("rand_distr", |b| {
        b.iter(|| {
            for o in out.iter_mut() {
                *o = rng.sample(StandardNormal);
            }
            black_box(&out);
        })
    });
    g.finish();

    let mut g = c.benchmark_group("variates/words");
    g.throughput(Throughput::Elements(N as u64));
    let mut words = vec![0u64; N];
    let mut direct = stream();
    g.bench_function("rand_chacha", |b| {
        b.iter(|| {
            for w in words.iter_mut() {
                *w = direct.next_u64();
            }
            black_box(&words);
        })
    });
    let mut buffered = former::Buffered::new(stream());
    g.bench_function("own_buffer", |b| {
        b.iter(|| {
            for w in words.iter_mut() {
                *w = buffered.next_u64();
            }
            black_box(&words);
        })
    });
    g.finish();
}

criterion_group!(kernel_benches, benches);
criterion_main!(kernel_benches);
