//! `chain thermal` benchmarks (docs/performance.md, "chain thermal"): a
//! drift test of 10⁵ samples (every 1 s, 27.8 h) with 30 temperature
//! channels, 5 displacement channels and one load (the spindle speed),
//! generated here: the sensors lagged responses of the speed and a room
//! cycle with noise, each channel a mix of three sensors and a direct lag.
//! Run with `cargo bench --bench thermal`.
//!
//! - `thermal/read_1e5`: reading and checking the CSV text;
//! - `thermal/fit_1e5_k4_lag`: the fit of the five channels, K = 4 with
//!   lags, 30 % held out (every subset of ≤ 4 of 30 sensors, 31,931, on
//!   10 folds, then the lag stage);
//! - `thermal/whole_1e5_k4_lag`: read, evaluate and fit: the issue's
//!   figure (at most 2 s).

use std::hint::black_box;
use std::time::Duration;

use chain::core::measured::thermal::{self, DriftTest, Roles};
use chain::core::measured::thermal_fit::{self, FitOptions, Split};
use criterion::{criterion_group, criterion_main, Criterion};

/// The drift test's CSV text (module docs), deterministic.
fn drift_text() -> String {
    let n = 100_000;
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut noise = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let speed = |t: f64| -> f64 {
        let h = t / 3600.0;
        if (h as i64) % 3 == 2 {
            0.0
        } else {
            3000.0 * ((h as i64 % 4) + 1) as f64
        }
    };
    let taus: Vec<f64> = (0..30).map(|k| 600.0 * 1.15f64.powi(k)).collect();
    let mut lags = vec![0.0; 30];
    let mut direct = 0.0;
    let mut text = String::from("time(s)");
    for c in 0..5 {
        text.push_str(&format!(",D{c}(um)"));
    }
    for k in 0..30 {
        text.push_str(&format!(",T{k}(°C)"));
    }
    text.push_str(",spindle(rpm)\n");
    for s in 0..n {
        let t = s as f64;
        let u = speed(t) / 1000.0;
        let room = 20.0 + (std::f64::consts::TAU * t / 86400.0).sin();
        let temps: Vec<f64> = (0..30)
            .map(|k| room + 0.5 * lags[k] + 0.02 * noise())
            .collect();
        text.push_str(&format!("{t}"));
        for c in 0..5 {
            let d = 2.0 * temps[c] - 1.0 * temps[c + 7]
                + 0.5 * temps[c + 20]
                + 0.4 * direct
                + 0.3 * noise();
            text.push_str(&format!(",{d:.3}"));
        }
        for v in &temps {
            text.push_str(&format!(",{v:.3}"));
        }
        text.push_str(&format!(",{}\n", speed(t)));
        for k in 0..30 {
            lags[k] += (u - lags[k]) * (1.0 - (-1.0 / taus[k]).exp());
        }
        direct += (u - direct) * (1.0 - (-1.0f64 / 300.0).exp());
    }
    text
}

fn benches(c: &mut Criterion) {
    let text = drift_text();
    let roles = Roles::default();
    let options = FitOptions {
        sensors: 4,
        lag: true,
        split: Split::Holdout(0.3),
    };
    let mut group = c.benchmark_group("thermal");
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(20));
    group.bench_function("read_1e5", |b| {
        b.iter(|| black_box(DriftTest::parse(&text, "bench.csv", &roles).unwrap()))
    });
    let test = DriftTest::parse(&text, "bench.csv", &roles).unwrap();
    group.bench_function("fit_1e5_k4_lag", |b| {
        b.iter(|| black_box(thermal_fit::fit(&test, &options).unwrap()))
    });
    group.bench_function("whole_1e5_k4_lag", |b| {
        b.iter(|| {
            let test = DriftTest::parse(&text, "bench.csv", &roles).unwrap();
            let mut doc = thermal::evaluate(&test, &[]).unwrap();
            let fitted = thermal_fit::fit(&test, &options).unwrap();
            fitted.into_document(&mut doc);
            black_box(doc)
        })
    });
    group.finish();
}

criterion_group!(thermal_benches, benches);
criterion_main!(thermal_benches);
