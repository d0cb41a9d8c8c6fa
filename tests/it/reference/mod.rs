//! The tests' own reading of the example tables and their own interpolation,
//! independent of chain-core's: CSV columns read with the `csv` crate, linear
//! interpolation written out, and a natural cubic spline solved densely by
//! nalgebra's LU and evaluated in the polynomial form of Burden & Faires
//! (chain-core solves the tridiagonal system by elimination and evaluates
//! Numerical Recipes' form).

// Each test binary uses only some of these helpers.
#![allow(dead_code)]
// Index loops over knots read best with explicit indices.
#![allow(clippy::needless_range_loop)]

use std::path::Path;

/// A CSV table of the examples: header and columns (comment lines skipped).
pub fn read_table(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let mut r = csv::ReaderBuilder::new()
        .comment(Some(b'#'))
        .trim(csv::Trim::All)
        .from_path(path)
        .unwrap();
    let header: Vec<String> = r.headers().unwrap().iter().map(String::from).collect();
    let mut columns = vec![Vec::new(); header.len()];
    for rec in r.records() {
        for (k, f) in rec.unwrap().iter().enumerate() {
            columns[k].push(f.parse::<f64>().unwrap());
        }
    }
    (header, columns)
}

/// Linear interpolation, written out.
pub fn linear(q: &[f64], v: &[f64], x: f64) -> f64 {
    let i = (0..q.len() - 1).find(|&i| x <= q[i + 1]).unwrap();
    let w = (x - q[i]) / (q[i + 1] - q[i]);
    (1.0 - w) * v[i] + w * v[i + 1]
}

/// The natural cubic spline in polynomial form (Burden & Faires, Numerical
/// Analysis, Algorithm 3.4): `S_i(x) = a_i + b_i d + c_i d² + d_i d³`,
/// `d = x − x_i`, with the `c_i` of the dense tridiagonal system solved by
/// nalgebra's LU.
pub struct Spline {
    x: Vec<f64>,
    a: Vec<f64>,
    b: Vec<f64>,
    c: Vec<f64>,
    d: Vec<f64>,
}

impl Spline {
    pub fn new(x: &[f64], y: &[f64]) -> Spline {
        let n = x.len();
        let h: Vec<f64> = (0..n - 1).map(|i| x[i + 1] - x[i]).collect();
        let mut m = nalgebra::DMatrix::<f64>::zeros(n, n);
        let mut r = nalgebra::DVector::<f64>::zeros(n);
        m[(0, 0)] = 1.0;
        m[(n - 1, n - 1)] = 1.0;
        for i in 1..n - 1 {
            m[(i, i - 1)] = h[i - 1];
            m[(i, i)] = 2.0 * (h[i - 1] + h[i]);
            m[(i, i + 1)] = h[i];
            r[i] = 3.0 * (y[i + 1] - y[i]) / h[i] - 3.0 * (y[i] - y[i - 1]) / h[i - 1];
        }
        let c = m.lu().solve(&r).unwrap();
        let mut b = vec![0.0; n - 1];
        let mut d = vec![0.0; n - 1];
        for i in 0..n - 1 {
            b[i] = (y[i + 1] - y[i]) / h[i] - h[i] * (c[i + 1] + 2.0 * c[i]) / 3.0;
            d[i] = (c[i + 1] - c[i]) / (3.0 * h[i]);
        }
        Spline {
            x: x.to_vec(),
            a: y.to_vec(),
            b,
            c: c.iter().copied().collect(),
            d,
        }
    }

    pub fn eval(&self, x: f64) -> f64 {
        let n = self.x.len();
        let i = (0..n - 1).find(|&i| x <= self.x[i + 1]).unwrap();
        let t = x - self.x[i];
        self.a[i] + self.b[i] * t + self.c[i] * t * t + self.d[i] * t * t * t
    }
}
