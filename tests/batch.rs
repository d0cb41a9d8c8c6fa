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
