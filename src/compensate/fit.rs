//! Least-squares polynomials of every order, with their goodness-of-fit
//! figures and the overall F-test.

use super::fdist::f_survival;
use super::{FitError, MAX_SUPPORTED_ORDER};
use nalgebra::{DMatrix, DVector};
use serde::Serialize;

/// A least-squares polynomial `y ≈ Σ c_k x^k` with its goodness-of-fit figures.
///
/// The fit is computed by Householder QR of the Vandermonde matrix in the
/// scaled abscissa `u = (x − centre)/scale ∈ [−1, 1]`; evaluation uses that
/// basis, and [`PolyFit::coefficients`] are its exact re-expansion in powers of
/// `x`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PolyFit {
    /// Polynomial order `p`.
    pub order: usize,
    /// Coefficient of determination `R² = 1 − RSS/TSS` (1 when `TSS = 0`;
    /// sums of squares at the rounding-noise level of `y` count as 0).
    pub r2: f64,
    /// Coefficients `c_0 … c_p` in ascending powers of `x`.
    pub coefficients: Vec<f64>,
    /// Adjusted `R² = 1 − (1 − R²)(n − 1)/(n − p − 1)`.
    pub adjusted_r2: f64,
    /// Root-mean-square residual `√(RSS/n)`.
    pub rmse: f64,
    /// Residual standard error `√(RSS/(n − p − 1))`.
    pub residual_std: f64,
    /// Leave-one-out prediction error sum of squares `Σ (e_i / (1 − h_ii))²`.
    pub press: f64,
    /// Leave-one-out root-mean-square prediction error `√(PRESS/n)`.
    pub loocv_rmse: f64,
    /// Small-sample Akaike criterion (Gaussian errors, `k = p + 2` parameters);
    /// `None` when `n ≤ p + 3`.
    pub aicc: Option<f64>,
    /// Bayesian information criterion (Gaussian errors, `k = p + 2`).
    pub bic: f64,
    /// p-value of the overall F-test of this fit against the constant model
    /// (`None` for order 0 and for data without variance).
    pub f_test_p: Option<f64>,
    /// Number of points.
    pub n: usize,
    #[serde(skip)]
    centre: f64,
    #[serde(skip)]
    scale: f64,
    #[serde(skip)]
    scaled: Vec<f64>,
}

impl PolyFit {
    /// The polynomial at `x`.
    pub fn eval(&self, x: f64) -> f64 {
        let u = (x - self.centre) / self.scale;
        self.scaled.iter().rev().fold(0.0, |acc, &a| acc * u + a)
    }

    /// The derivative `dy/dx` at `x`.
    pub fn derivative(&self, x: f64) -> f64 {
        let u = (x - self.centre) / self.scale;
        let d = self
            .scaled
            .iter()
            .enumerate()
            .skip(1)
            .rev()
            .fold(0.0, |acc, (k, &a)| acc * u + k as f64 * a);
        d / self.scale
    }
}

/// Fits a polynomial of order `order` to `(x, y)` by least squares.
///
/// Needs `order + 2` distinct abscissae or more (so that the fit has a residual
/// and every leave-one-out refit is determined) and finite data.
pub fn fit_polynomial(x: &[f64], y: &[f64], order: usize) -> Result<PolyFit, FitError> {
    if x.len() != y.len() {
        return Err(FitError::LengthMismatch {
            x: x.len(),
            y: y.len(),
        });
    }
    if x.iter().chain(y).any(|v| !v.is_finite()) {
        return Err(FitError::NotFinite);
    }
    if order > MAX_SUPPORTED_ORDER {
        return Err(FitError::OrderTooHigh { order });
    }
    let distinct = distinct_count(x);
    if distinct < order + 2 {
        return Err(FitError::TooFewPoints {
            order,
            needed: order + 2,
            got: distinct,
        });
    }
    let n = x.len();
    let cols = order + 1;
    let (lo, hi) = x
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        });
    let centre = 0.5 * (lo + hi);
    let half = 0.5 * (hi - lo);
    let scale = if half > 0.0 { half } else { 1.0 };
    let design = DMatrix::from_fn(n, cols, |i, j| ((x[i] - centre) / scale).powi(j as i32));
    let qr = design.qr();
    let q = qr.q();
    let r = qr.r();
    let r_max = (0..cols).map(|j| r[(j, j)].abs()).fold(0.0, f64::max);
    let tolerance = r_max * (n.max(cols) as f64) * f64::EPSILON * 16.0;
    if (0..cols).any(|j| r[(j, j)].abs() <= tolerance) {
        return Err(FitError::RankDeficient { order });
    }
    let yv = DVector::from_column_slice(y);
    let qty = q.transpose() * &yv;
    let scaled_coef = r
        .solve_upper_triangular(&qty)
        .ok_or(FitError::RankDeficient { order })?;
    let fitted = &q * &qty;
    let residual = &yv - &fitted;
    // Sums of squares at the level of rounding noise of y are zero: a fit of
    // exact (or constant) data must not rank orders by noise.
    let y_max = y.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let noise_floor = n as f64 * (1e3 * f64::EPSILON * y_max).powi(2);
    let denoise = |ss: f64| if ss <= noise_floor { 0.0 } else { ss };
    let rss = denoise(residual.iter().map(|e| e * e).sum());
    let mean = y.iter().sum::<f64>() / n as f64;
    let tss = denoise(y.iter().map(|v| (v - mean) * (v - mean)).sum());
    let r2 = if tss > 0.0 { 1.0 - rss / tss } else { 1.0 };
    let nf = n as f64;
    let dof = (n - cols) as f64;
    let adjusted_r2 = 1.0 - (1.0 - r2) * (nf - 1.0) / dof;
    let mut press = 0.0;
    for i in 0..n {
        let leverage: f64 = (0..cols).map(|j| q[(i, j)] * q[(i, j)]).sum();
        let denominator = 1.0 - leverage;
        if denominator <= 1e-12 {
            return Err(FitError::RankDeficient { order });
        }
        press += (residual[i] / denominator).powi(2);
    }
    let press = if rss == 0.0 { 0.0 } else { press };
    let k = (order + 2) as f64;
    let log_likelihood_term = nf * (rss.max(f64::MIN_POSITIVE) / nf).ln();
    let aicc = (nf > k + 1.0)
        .then(|| log_likelihood_term + 2.0 * k + 2.0 * k * (k + 1.0) / (nf - k - 1.0));
    let bic = log_likelihood_term + k * nf.ln();
    // The overall F-test needs variance to explain; an exact fit of varying
    // data has p = 0.
    let f_test_p = (order > 0 && tss > 0.0).then(|| {
        if rss == 0.0 {
            0.0
        } else {
            let d1 = order as f64;
            let f = (r2 / d1) / ((1.0 - r2) / dof);
            f_survival(f.max(0.0), d1, dof)
        }
    });
    let scaled: Vec<f64> = scaled_coef.iter().copied().collect();
    let coefficients = expand_scaled(&scaled, centre, scale);
    Ok(PolyFit {
        order,
        r2,
        coefficients,
        adjusted_r2,
        rmse: (rss / nf).sqrt(),
        residual_std: (rss / dof).sqrt(),
        press,
        loocv_rmse: (press / nf).sqrt(),
        aicc,
        bic,
        f_test_p,
        n,
        centre,
        scale,
        scaled,
    })
}

/// Number of distinct values (exact comparison).
pub(super) fn distinct_count(x: &[f64]) -> usize {
    let mut sorted: Vec<f64> = x.to_vec();
    sorted.sort_by(f64::total_cmp);
    sorted.dedup();
    sorted.len()
}

/// Re-expands `Σ a_k ((x − c)/s)^k` in powers of `x`.
fn expand_scaled(scaled: &[f64], centre: f64, scale: f64) -> Vec<f64> {
    let mut out = vec![0.0; scaled.len()];
    for (k, &a) in scaled.iter().enumerate() {
        let factor = a / scale.powi(k as i32);
        let mut binomial = 1.0;
        for (j, slot) in out.iter_mut().enumerate().take(k + 1) {
            *slot += factor * binomial * (-centre).powi((k - j) as i32);
            binomial = binomial * (k - j) as f64 / (j + 1) as f64;
        }
    }
    out
}
