//! `CompiledModel::sensitivity_batch` against the per-point `sensitivity` on
//! every example machine: whole blocks, a tail block, N = 0 and N = 1, and the
//! refusals of mis-sized buffers.

use std::path::Path;

use chain::core::{compile, BatchError, ErrorModel, BATCH_LANES};

fn machines() -> Vec<(String, chain::core::CompiledModel)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/machines");
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().and_then(|e| e.to_str()) != Some("yaml") {
            continue;
        }
        if let Ok(machine) = chain::core::load::load_file(&path) {
            out.push((path.display().to_string(), compile(&machine)));
        }
    }
    out
}

/// Deterministic points spread over ±500 (prismatic) or several turns (rotary).
fn points(nv: usize, n: usize) -> Vec<f64> {
    (0..n * nv)
        .map(|i| {
            let x = (i as f64 * 0.618_033_988_749_895).fract();
            (x - 0.5) * 1000.0 / (1.0 + (i % 3) as f64 * 50.0)
        })
        .collect()
}

#[test]
fn batch_equals_per_point_on_every_example_machine() {
    let all = machines();
    assert!(all.len() >= 8, "found {} example machines", all.len());
    for (name, model) in &all {
        let nv = model.variables().len();
        let width = 6 * model.errors().len();
        let p: Vec<f64> = model
            .parameter_values()
            .iter()
            .enumerate()
            .map(|(k, v)| v.unwrap_or(100.0 + k as f64))
            .collect();
        for n in [
            0,
            1,
            BATCH_LANES - 1,
            BATCH_LANES,
            3 * BATCH_LANES + 5,
            1000,
        ] {
            let qs = points(nv, n);
            let mut batch = vec![f64::NAN; n * width];
            model.sensitivity_batch(&qs, &p, &mut batch).unwrap();
            let mut one = vec![0.0; width];
            for k in 0..n {
                model.sensitivity(&qs[k * nv..(k + 1) * nv], &p, &mut one);
                for (j, (&a, &b)) in one
                    .iter()
                    .zip(&batch[k * width..(k + 1) * width])
                    .enumerate()
                {
                    assert!(
                        a == b || (a - b).abs() <= 1e-15 * a.abs().max(b.abs()),
                        "{name}: N = {n}, point {k}, entry {j}: {a} vs {b}"
                    );
                }
            }
        }
    }
}

#[test]
fn mis_sized_buffers_are_refused() {
    let (_, model) = machines().pop().unwrap();
    let nv = model.variables().len();
    let width = 6 * model.errors().len();
    let qs = points(nv, 3);
    let mut out = vec![0.0; 3 * width];
    assert_eq!(
        model.sensitivity_batch(&qs[..3 * nv - 1], &[], &mut out),
        Err(BatchError::Points {
            values: 3 * nv - 1,
            variables: nv
        })
    );
    assert_eq!(
        model.sensitivity_batch(&qs, &[], &mut out[1..]),
        Err(BatchError::Output {
            len: 3 * width - 1,
            expected: 3 * width
        })
    );
}

/// Error values of `n` points: distinct per point and per error.
fn error_values(ne: usize, n: usize) -> Vec<f64> {
    (0..n * ne)
        .map(|i| ((i as f64 * 0.754_877_666_246_693).fract() - 0.5) * 1e-3)
        .collect()
}

#[test]
fn batched_errors_and_serial_entry_points_equal_per_point_bit_for_bit() {
    for (name, model) in &machines() {
        let nv = model.variables().len();
        let ne = model.errors().len();
        let width = 6 * ne;
        let p: Vec<f64> = model
            .parameter_values()
            .iter()
            .enumerate()
            .map(|(k, v)| v.unwrap_or(100.0 + k as f64))
            .collect();
        for n in [1, BATCH_LANES + 3, 300] {
            let qs = points(nv, n);
            let es = error_values(ne, n);
            // Per point: the reference.
            let mut s_ref = vec![0.0; n * width];
            let mut e_ref = vec![0.0; n * 6];
            let mut e_one = vec![0.0; n * 6];
            for k in 0..n {
                let q = &qs[k * nv..(k + 1) * nv];
                model.sensitivity(q, &p, &mut s_ref[k * width..(k + 1) * width]);
                let mut row = [0.0; 6];
                model.error(q, &p, &es[k * ne..(k + 1) * ne], &mut row);
                e_ref[k * 6..(k + 1) * 6].copy_from_slice(&row);
                model.error(q, &p, &es[..ne], &mut row);
                e_one[k * 6..(k + 1) * 6].copy_from_slice(&row);
            }
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            let mut s = vec![f64::NAN; n * width];
            model.sensitivity_points(&qs, &p, &mut s).unwrap();
            assert_eq!(
                bits(&s),
                bits(&s_ref),
                "{name}: sensitivity_points, N = {n}"
            );
            let mut e = vec![f64::NAN; n * 6];
            model.error_batch(&qs, &p, &es, &mut e).unwrap();
            assert_eq!(bits(&e), bits(&e_ref), "{name}: error_batch, N = {n}");
            let mut e = vec![f64::NAN; n * 6];
            model.error_points(&qs, &p, &es, &mut e).unwrap();
            assert_eq!(bits(&e), bits(&e_ref), "{name}: error_points, N = {n}");
            let mut e = vec![f64::NAN; n * 6];
            model.error_batch(&qs, &p, &es[..ne], &mut e).unwrap();
            assert_eq!(bits(&e), bits(&e_one), "{name}: one row of e, N = {n}");
            // E = S·e, summed in the sparsity order from S (independent of the
            // tape's error path): within rounding.
            for k in 0..n {
                for c in 0..6 {
                    let direct: f64 = (0..ne)
                        .map(|j| s_ref[k * width + c * ne + j] * es[k * ne + j])
                        .sum();
                    let got = e_ref[k * 6 + c];
                    assert!(
                        (got - direct).abs() <= 1e-12 * (1.0 + direct.abs()),
                        "{name}"
                    );
                }
            }
        }
    }
}

#[test]
fn mis_sized_error_slices_are_refused() {
    let (_, model) = machines().pop().unwrap();
    let nv = model.variables().len();
    let ne = model.errors().len();
    let qs = points(nv, 3);
    let es = error_values(ne, 3);
    let mut out = vec![0.0; 18];
    assert_eq!(
        model.error_batch(&qs, &[], &es[1..], &mut out),
        Err(BatchError::ErrorValues {
            len: 3 * ne - 1,
            errors: ne,
            expected: 3 * ne
        })
    );
    assert_eq!(
        model.error_points(&qs, &[], &es, &mut out[1..]),
        Err(BatchError::Rows {
            len: 17,
            expected: 18
        })
    );
    let mut s = vec![0.0; 3 * 6 * ne + 1];
    assert!(matches!(
        model.sensitivity_points(&qs, &[], &mut s),
        Err(BatchError::Output { .. })
    ));
}
