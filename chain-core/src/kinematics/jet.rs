//! Truncated Taylor series ("jets"): Taylor-mode automatic differentiation.
//!
//! A [`Jet`] of order `n` holds the Taylor coefficients `a_0 … a_n` of a
//! function of one variable `t` at `t = 0`: `a(t) = Σ a_k t^k + O(t^{n+1})`.
//! Arithmetic and the elementary functions below propagate all coefficients
//! exactly (up to rounding) by the standard recurrences (Griewank & Walther,
//! *Evaluating Derivatives*, ch. 13), so a composite expression evaluated on
//! jets yields its exact derivatives `f^{(k)}(0) = k!·a_k` without finite
//! differences. Order 1 is forward-mode differentiation (a dual number).
//!
//! ```
//! use chain_core::jet::Jet;
//! // sin(t) to order 5: t − t³/6 + t⁵/120
//! let t = Jet::variable(0.0, 1.0, 5);
//! let (s, _) = t.sin_cos();
//! assert!((s.coefficients()[3] + 1.0 / 6.0).abs() < 1e-15);
//! assert!((s.coefficients()[5] - 1.0 / 120.0).abs() < 1e-15);
//! ```

use std::ops::{Add, Mul, Neg, Sub};

/// A truncated Taylor series `Σ_{k=0..=n} a_k t^k`.
#[derive(Debug, Clone, PartialEq)]
pub struct Jet {
    c: Vec<f64>,
}

impl Jet {
    /// The constant `value` as a jet of order `order`.
    pub fn constant(value: f64, order: usize) -> Jet {
        let mut c = vec![0.0; order + 1];
        c[0] = value;
        Jet { c }
    }

    /// The affine function `value + slope·t` as a jet of order `order`.
    pub fn variable(value: f64, slope: f64, order: usize) -> Jet {
        let mut j = Jet::constant(value, order);
        if order >= 1 {
            j.c[1] = slope;
        }
        j
    }

    /// A jet from its coefficients `a_0 … a_n` (at least one).
    ///
    /// # Panics
    /// If `coefficients` is empty.
    pub fn from_coefficients(coefficients: Vec<f64>) -> Jet {
        assert!(!coefficients.is_empty(), "a jet has at least a_0");
        Jet { c: coefficients }
    }

    /// The order `n`.
    pub fn order(&self) -> usize {
        self.c.len() - 1
    }

    /// The Taylor coefficients `a_0 … a_n`.
    pub fn coefficients(&self) -> &[f64] {
        &self.c
    }

    /// The value `a_0`.
    pub fn value(&self) -> f64 {
        self.c[0]
    }

    /// The `k`-th derivative at 0, `k!·a_k` (0 beyond the order).
    pub fn derivative(&self, k: usize) -> f64 {
        let factorial: f64 = (1..=k).map(|i| i as f64).product();
        self.c.get(k).map_or(0.0, |a| a * factorial)
    }

    /// The truncated series evaluated at `t`.
    pub fn eval(&self, t: f64) -> f64 {
        self.c.iter().rev().fold(0.0, |acc, a| acc * t + a)
    }

    /// `k·s`.
    pub fn scale(&self, k: f64) -> Jet {
        Jet {
            c: self.c.iter().map(|a| a * k).collect(),
        }
    }

    /// The derivative series `a'(t)` (one order lower; order 0 stays a zero
    /// constant).
    fn derivative_series(&self) -> Vec<f64> {
        if self.c.len() == 1 {
            return vec![0.0];
        }
        (1..self.c.len()).map(|k| k as f64 * self.c[k]).collect()
    }

    /// The jet whose derivative is `d` (coefficients of order `n − 1`) and
    /// whose value is `value`.
    fn integrate(value: f64, d: &[f64], order: usize) -> Jet {
        let mut c = vec![0.0; order + 1];
        c[0] = value;
        for (k, ck) in c.iter_mut().enumerate().skip(1) {
            *ck = d.get(k - 1).copied().unwrap_or(0.0) / k as f64;
        }
        Jet { c }
    }

    /// `self / other`.
    pub fn div(&self, other: &Jet) -> Jet {
        let n = self.order().min(other.order());
        let (a, b) = (&self.c, &other.c);
        let mut h = vec![0.0; n + 1];
        for k in 0..=n {
            let mut s = a[k];
            for j in 1..=k {
                s -= b[j] * h[k - j];
            }
            h[k] = s / b[0];
        }
        Jet { c: h }
    }

    /// `(sin self, cos self)`.
    pub fn sin_cos(&self) -> (Jet, Jet) {
        let n = self.order();
        let a = &self.c;
        let mut s = vec![0.0; n + 1];
        let mut c = vec![0.0; n + 1];
        (s[0], c[0]) = a[0].sin_cos();
        for k in 1..=n {
            let (mut sk, mut ck) = (0.0, 0.0);
            for j in 1..=k {
                let ja = j as f64 * a[j];
                sk += ja * c[k - j];
                ck -= ja * s[k - j];
            }
            s[k] = sk / k as f64;
            c[k] = ck / k as f64;
        }
        (Jet { c: s }, Jet { c })
    }

    /// `√self` (the series is not finite when `a_0 = 0` and the order ≥ 1).
    pub fn sqrt(&self) -> Jet {
        let n = self.order();
        let a = &self.c;
        let mut h = vec![0.0; n + 1];
        h[0] = a[0].sqrt();
        for k in 1..=n {
            let mut s = a[k];
            for j in 1..k {
                s -= h[j] * h[k - j];
            }
            h[k] = s / (2.0 * h[0]);
        }
        Jet { c: h }
    }

    /// `atan2(self, x)`, the angle of the point `(x, self)`.
    pub fn atan2(&self, x: &Jet) -> Jet {
        let y = self;
        let n = y.order().min(x.order());
        // (x y' − y x') / (x² + y²)
        let dy = Jet {
            c: y.derivative_series(),
        };
        let dx = Jet {
            c: x.derivative_series(),
        };
        let num = &(x * &dy) - &(y * &dx);
        let den = &(x * x) + &(y * y);
        let d = num.div(&den);
        Jet::integrate(y.c[0].atan2(x.c[0]), &d.c, n)
    }

    /// `asin(self)` (not finite at `|a_0| = 1` for order ≥ 1).
    pub fn asin(&self) -> Jet {
        let n = self.order();
        let one_minus_sq = &Jet::constant(1.0, n) - &(self * self);
        let da = Jet {
            c: self.derivative_series(),
        };
        let d = da.div(&one_minus_sq.sqrt());
        Jet::integrate(self.c[0].asin(), &d.c, n)
    }

    /// `acos(self)` (not finite at `|a_0| = 1` for order ≥ 1).
    pub fn acos(&self) -> Jet {
        let a = self.asin();
        let mut c: Vec<f64> = a.c.iter().map(|v| -v).collect();
        c[0] = self.c[0].acos();
        Jet { c }
    }

    /// `self^k` for a non-negative integer power.
    pub fn powi(&self, k: u32) -> Jet {
        let mut out = Jet::constant(1.0, self.order());
        for _ in 0..k {
            out = &out * self;
        }
        out
    }
}

impl Add for &Jet {
    type Output = Jet;
    fn add(self, other: &Jet) -> Jet {
        let n = self.c.len().min(other.c.len());
        Jet {
            c: (0..n).map(|k| self.c[k] + other.c[k]).collect(),
        }
    }
}

impl Sub for &Jet {
    type Output = Jet;
    fn sub(self, other: &Jet) -> Jet {
        let n = self.c.len().min(other.c.len());
        Jet {
            c: (0..n).map(|k| self.c[k] - other.c[k]).collect(),
        }
    }
}

impl Mul for &Jet {
    type Output = Jet;
    fn mul(self, other: &Jet) -> Jet {
        let n = self.c.len().min(other.c.len());
        let mut c = vec![0.0; n];
        for (k, ck) in c.iter_mut().enumerate() {
            *ck = (0..=k).map(|j| self.c[j] * other.c[k - j]).sum();
        }
        Jet { c }
    }
}

impl Neg for &Jet {
    type Output = Jet;
    fn neg(self) -> Jet {
        self.scale(-1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: &[f64], b: &[f64], tol: f64) {
        assert_eq!(a.len(), b.len());
        for (x, y) in a.iter().zip(b) {
            assert!((x - y).abs() <= tol, "{a:?} vs {b:?}");
        }
    }

    #[test]
    fn sin_cos_of_affine_argument() {
        // sin(1 + 2t) = sin1 + 2cos1 t − 2 sin1 t² − (4/3) cos1 t³
        let t = Jet::variable(1.0, 2.0, 3);
        let (s, c) = t.sin_cos();
        let (s1, c1) = 1.0f64.sin_cos();
        close(
            s.coefficients(),
            &[s1, 2.0 * c1, -2.0 * s1, -4.0 / 3.0 * c1],
            1e-15,
        );
        close(
            c.coefficients(),
            &[c1, -2.0 * s1, -2.0 * c1, 4.0 / 3.0 * s1],
            1e-15,
        );
    }

    #[test]
    fn division_and_sqrt_invert_multiplication() {
        let a = Jet::from_coefficients(vec![2.0, -1.0, 0.5, 3.0, -0.25]);
        let b = Jet::from_coefficients(vec![1.5, 0.3, -0.7, 0.1, 2.0]);
        close((&a * &b).div(&b).coefficients(), a.coefficients(), 1e-14);
        let r = a.sqrt();
        close((&r * &r).coefficients(), a.coefficients(), 1e-14);
    }

    #[test]
    fn inverse_trigonometric_functions_invert_sin_cos() {
        let t = Jet::from_coefficients(vec![0.4, 0.9, -0.3, 0.2, 0.05, -0.1]);
        let (s, c) = t.sin_cos();
        close(s.asin().coefficients(), t.coefficients(), 1e-13);
        close(c.acos().coefficients(), t.coefficients(), 1e-13);
        close(s.atan2(&c).coefficients(), t.coefficients(), 1e-13);
        // atan2 with a common positive factor is unchanged
        let k = Jet::from_coefficients(vec![3.0, 1.0, 0.5, 0.0, 0.2, 0.1]);
        close(
            (&s * &k).atan2(&(&c * &k)).coefficients(),
            t.coefficients(),
            1e-13,
        );
    }

    #[test]
    fn derivatives_and_evaluation() {
        // e.g. (1 + t)^3 = 1 + 3t + 3t² + t³
        let p = Jet::variable(1.0, 1.0, 3).powi(3);
        close(p.coefficients(), &[1.0, 3.0, 3.0, 1.0], 0.0);
        assert_eq!(p.derivative(2), 6.0);
        assert_eq!(p.derivative(3), 6.0);
        assert_eq!(p.derivative(4), 0.0);
        assert_eq!(p.eval(0.5), 1.5f64.powi(3));
    }
}
