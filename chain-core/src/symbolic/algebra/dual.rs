//! First-order dual numbers over [`Poly`], and rigid transforms over them.
//!
//! A [`Dual`] is `value + Σ_j slope_j · e_j`: the value and every slope are
//! canonical polynomials, `e_j` are the error parameters. The product drops
//! `e_i · e_j`, so a matrix product over duals is the exact first-order
//! expansion in the errors, and the slopes are the exact partial derivatives.

// Index loops read like the matrix formulas they implement.
#![allow(clippy::needless_range_loop)]

use super::poly::Poly;

/// `value + Σ slope_j e_j`, with the slopes sparse and sorted by error index.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Dual {
    /// The nominal part.
    pub value: Poly,
    /// `(error index, ∂/∂e_j)`, sorted, no zero slope.
    pub slopes: Vec<(usize, Poly)>,
}

impl Dual {
    /// Zero.
    pub fn zero() -> Dual {
        Dual::default()
    }

    /// A nominal value with no error part.
    pub fn nominal(value: Poly) -> Dual {
        Dual {
            value,
            slopes: Vec::new(),
        }
    }

    /// A constant.
    pub fn constant(c: f64) -> Dual {
        Dual::nominal(Poly::constant(c))
    }

    /// `Σ sign·e_j` over the given errors.
    pub fn errors(errors: &[usize], sign: f64) -> Dual {
        let mut d = Dual::zero();
        for &j in errors {
            d = d.add(&Dual {
                value: Poly::zero(),
                slopes: vec![(j, Poly::constant(sign))],
            });
        }
        d
    }

    /// `Σ sign·w_j·e_j` over the given errors with polynomial weights.
    pub fn weighted(errors: &[usize], sign: f64, weight: impl Fn(usize) -> Poly) -> Dual {
        let mut d = Dual::zero();
        for &j in errors {
            d = d.add(&Dual {
                value: Poly::zero(),
                slopes: vec![(j, weight(j).scale(sign))],
            });
        }
        d
    }

    /// True if value and all slopes are zero.
    pub fn is_zero(&self) -> bool {
        self.value.is_zero() && self.slopes.is_empty()
    }

    /// The slope of error `j` (zero if absent).
    pub fn slope(&self, j: usize) -> Poly {
        self.slopes
            .binary_search_by_key(&j, |(k, _)| *k)
            .map(|i| self.slopes[i].1.clone())
            .unwrap_or_default()
    }

    /// Sum.
    pub fn add(&self, other: &Dual) -> Dual {
        Dual {
            value: self.value.add(&other.value),
            slopes: merge(&self.slopes, &other.slopes, |a, b| a.add(b)),
        }
    }

    /// Difference.
    pub fn sub(&self, other: &Dual) -> Dual {
        self.add(&other.neg())
    }

    /// Negation.
    pub fn neg(&self) -> Dual {
        Dual {
            value: self.value.neg(),
            slopes: self.slopes.iter().map(|(j, p)| (*j, p.neg())).collect(),
        }
    }

    /// First-order product: `(a + a'e)(b + b'e) = ab + (ab' + a'b)e`.
    pub fn mul(&self, other: &Dual) -> Dual {
        let value = self.value.mul(&other.value);
        let left: Vec<(usize, Poly)> = if self.value.is_zero() {
            Vec::new()
        } else {
            other
                .slopes
                .iter()
                .map(|(j, s)| (*j, self.value.mul(s)))
                .filter(|(_, p)| !p.is_zero())
                .collect()
        };
        let right: Vec<(usize, Poly)> = if other.value.is_zero() {
            Vec::new()
        } else {
            self.slopes
                .iter()
                .map(|(j, s)| (*j, s.mul(&other.value)))
                .filter(|(_, p)| !p.is_zero())
                .collect()
        };
        Dual {
            value,
            slopes: merge(&left, &right, |a, b| a.add(b)),
        }
    }
}

/// Merges two sparse sorted slope lists, combining equal indices with `f` and
/// dropping zeros.
fn merge(
    a: &[(usize, Poly)],
    b: &[(usize, Poly)],
    f: impl Fn(&Poly, &Poly) -> Poly,
) -> Vec<(usize, Poly)> {
    let mut out = Vec::with_capacity(a.len() + b.len());
    let (mut i, mut k) = (0, 0);
    while i < a.len() || k < b.len() {
        if k == b.len() || (i < a.len() && a[i].0 < b[k].0) {
            out.push(a[i].clone());
            i += 1;
        } else if i == a.len() || b[k].0 < a[i].0 {
            out.push(b[k].clone());
            k += 1;
        } else {
            let s = f(&a[i].1, &b[k].1);
            if !s.is_zero() {
                out.push((a[i].0, s));
            }
            i += 1;
            k += 1;
        }
    }
    out
}

/// A rigid transform `[R t; 0 1]` over duals (the bottom row is implicit).
#[derive(Debug, Clone, PartialEq)]
pub struct Transform {
    /// Rotation part, row-major.
    pub r: [[Dual; 3]; 3],
    /// Translation part.
    pub t: [Dual; 3],
}

impl Transform {
    /// The identity.
    pub fn identity() -> Transform {
        let one = || Dual::constant(1.0);
        Transform {
            r: [
                [one(), Dual::zero(), Dual::zero()],
                [Dual::zero(), one(), Dual::zero()],
                [Dual::zero(), Dual::zero(), one()],
            ],
            t: [Dual::zero(), Dual::zero(), Dual::zero()],
        }
    }

    /// A pure translation.
    pub fn translation(t: [Dual; 3]) -> Transform {
        Transform {
            t,
            ..Transform::identity()
        }
    }

    /// A rotation about coordinate axis `axis` (0, 1, 2) with the given
    /// cosine and sine.
    pub fn rotation(axis: usize, cos: Dual, sin: Dual) -> Transform {
        let mut m = Transform::identity();
        let (i, j) = ((axis + 1) % 3, (axis + 2) % 3);
        m.r[i][i] = cos.clone();
        m.r[j][j] = cos;
        m.r[i][j] = sin.neg();
        m.r[j][i] = sin;
        m
    }

    /// The first-order small-error transform
    /// `[[1, -ez, ey, dx], [ez, 1, -ex, dy], [-ey, ex, 1, dz]]`.
    pub fn small_error(d: [Dual; 3], e: [Dual; 3]) -> Transform {
        let [ex, ey, ez] = e;
        let one = || Dual::constant(1.0);
        Transform {
            r: [
                [one(), ez.neg(), ey.clone()],
                [ez, one(), ex.neg()],
                [ey.neg(), ex, one()],
            ],
            t: d,
        }
    }

    /// Product `self · other`.
    pub fn mul(&self, other: &Transform) -> Transform {
        let mut r: [[Dual; 3]; 3] = Default::default();
        let mut t: [Dual; 3] = Default::default();
        for i in 0..3 {
            for j in 0..3 {
                let mut s = Dual::zero();
                for k in 0..3 {
                    if !self.r[i][k].is_zero() && !other.r[k][j].is_zero() {
                        s = s.add(&self.r[i][k].mul(&other.r[k][j]));
                    }
                }
                r[i][j] = s;
            }
            let mut s = self.t[i].clone();
            for k in 0..3 {
                if !self.r[i][k].is_zero() && !other.t[k].is_zero() {
                    s = s.add(&self.r[i][k].mul(&other.t[k]));
                }
            }
            t[i] = s;
        }
        Transform { r, t }
    }

    /// The inverse `[Rᵀ, −Rᵀt]`, exact to first order in the errors because
    /// `R` is a rotation to first order.
    pub fn inverse(&self) -> Transform {
        let mut r: [[Dual; 3]; 3] = Default::default();
        for (i, row) in r.iter_mut().enumerate() {
            for (j, entry) in row.iter_mut().enumerate() {
                *entry = self.r[j][i].clone();
            }
        }
        let t = std::array::from_fn(|i| {
            let mut s = Dual::zero();
            for k in 0..3 {
                s = s.sub(&r[i][k].mul(&self.t[k]));
            }
            s
        });
        Transform { r, t }
    }

    /// Applies to a point: `R p + t`.
    pub fn apply(&self, p: &[Dual; 3]) -> [Dual; 3] {
        std::array::from_fn(|i| {
            let mut s = self.t[i].clone();
            for k in 0..3 {
                s = s.add(&self.r[i][k].mul(&p[k]));
            }
            s
        })
    }
}
