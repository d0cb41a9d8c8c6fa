//! Small numeric kernels shared by the algorithms.

/// `a·b` with four independent accumulators (vectorises; the summation order
/// is fixed, so results are reproducible).
#[inline]
pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let mut acc = [0.0f64; 4];
    let mut ca = a.chunks_exact(4);
    let mut cb = b.chunks_exact(4);
    for (x, y) in (&mut ca).zip(&mut cb) {
        acc[0] += x[0] * y[0];
        acc[1] += x[1] * y[1];
        acc[2] += x[2] * y[2];
        acc[3] += x[3] * y[3];
    }
    let mut tail = 0.0;
    for (x, y) in ca.remainder().iter().zip(cb.remainder()) {
        tail += x * y;
    }
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
}

/// `|a|`.
#[inline]
pub(crate) fn norm(a: &[f64]) -> f64 {
    dot(a, a).sqrt()
}

#[cfg(test)]
mod tests {
    #[test]
    fn dot_matches_naive() {
        let a: Vec<f64> = (0..23).map(|i| i as f64 * 0.5 - 3.0).collect();
        let b: Vec<f64> = (0..23).map(|i| 1.0 / (i as f64 + 1.0)).collect();
        let naive: f64 = a.iter().zip(&b).map(|(x, y)| x * y).sum();
        assert!((super::dot(&a, &b) - naive).abs() < 1e-13);
        assert_eq!(super::dot(&[], &[]), 0.0);
    }
}

#[cfg(test)]
pub(crate) mod fixtures {
    use chain_core::{CompiledModel, Machine};

    use crate::inputs::{Inputs, Marginal};

    /// Inputs named `a`, `b`, `c`, … with these marginals.
    pub(crate) fn inputs(marginals: Vec<Marginal>) -> Inputs {
        let names = (0..marginals.len())
            .map(|i| char::from(b'a' + i as u8).to_string())
            .collect();
        Inputs::new(names, marginals).unwrap()
    }

    /// The gantry grinder of Wang & Yuan 2021 (the workspace's example file)
    /// and its compiled model: the fixture of the unit tests.
    pub(crate) fn gantry() -> (Machine, CompiledModel) {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../examples/machines/gantry_grinder.yaml"
        );
        let m = chain_core::load_file(std::path::Path::new(path)).expect("gantry loads");
        let model = chain_core::compile(&m);
        (m, model)
    }
}
