//! A measured error motion `v(q)`: a table of `(q, v)` points along one axis,
//! interpolated linearly or by a natural cubic spline (measured-machines
//! spec, section 2).
//!
//! Everything that does not depend on the query is computed once, when the
//! table is built: the second derivative at every knot (cubic), each
//! interval's polynomial in `d = q − q_i` (degree 1 or 3), and whether the
//! knots are evenly spaced. [`Table::eval`] then finds the interval in `O(1)`
//! for evenly spaced knots (one multiplication, corrected by at most a step
//! either way against round-off) and by binary search otherwise, and
//! evaluates its polynomial (a cubic by Estrin's scheme); it takes `&self`,
//! allocates nothing and keeps no state, so one table serves any number of
//! threads.

use serde::Serialize;

/// How a table is read between its points.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Interpolation {
    /// Straight lines between neighbouring points (the default).
    #[default]
    Linear,
    /// The natural cubic spline through the points: twice continuously
    /// differentiable, zero second derivative at both ends.
    Cubic,
}

impl Interpolation {
    /// `linear` or `cubic`, as written in a values file.
    pub fn name(self) -> &'static str {
        match self {
            Interpolation::Linear => "linear",
            Interpolation::Cubic => "cubic",
        }
    }
}

/// What a table gives outside its first and last position.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Extrapolation {
    /// Nothing: a position outside the table is an error (the default; no
    /// silent extrapolation).
    #[default]
    Error,
    /// The end value, held constant beyond each end (`extrapolate: hold`).
    Hold,
}

impl Extrapolation {
    /// `error` or `hold`, as written in a values file.
    pub fn name(self) -> &'static str {
        match self {
            Extrapolation::Error => "error",
            Extrapolation::Hold => "hold",
        }
    }
}

/// Why a list of points is not a table.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum TableError {
    /// Fewer than two points: nothing to interpolate between.
    #[error("a table needs at least 2 points, found {found}")]
    TooFewPoints {
        /// The number of points given.
        found: usize,
    },
    /// A position or value that is infinite or NaN.
    #[error("point {index} is not finite (q = {q}, value = {value})")]
    NotFinite {
        /// Index of the point (0-based).
        index: usize,
        /// Its position.
        q: f64,
        /// Its value.
        value: f64,
    },
    /// A position that is not above the one before it (unsorted or repeated).
    #[error("the positions must increase: point {index} has q = {q} after q = {previous}")]
    NotIncreasing {
        /// Index of the point (0-based).
        index: usize,
        /// Its position.
        q: f64,
        /// The position of the point before it.
        previous: f64,
    },
}

/// Knots closer to even spacing than this (relative to the spacing) are
/// treated as evenly spaced for the interval lookup; the lookup is corrected
/// against the knots themselves either way, so this only decides the speed.
const UNIFORM_TOLERANCE: f64 = 1e-9;

/// A measured error motion along one axis: positions `q_0 < … < q_{n−1}`,
/// values `v_i`, read between them by [`Interpolation`] and beyond them by
/// [`Extrapolation`].
///
/// # Formulas
///
/// Linear: `v(q) = v_i + s_i (q − q_i)` on `[q_i, q_{i+1}]`,
/// `s_i = (v_{i+1} − v_i)/h_i`, `h_i = q_{i+1} − q_i`.
///
/// Natural cubic spline (Press et al., *Numerical Recipes*, 3rd ed., §3.3,
/// Eqs. 3.3.3 and 3.3.7): on `[q_i, q_{i+1}]`, with `a = (q_{i+1} − q)/h_i`
/// and `b = 1 − a`,
///
/// ```text
/// v(q) = a v_i + b v_{i+1} + ((a³ − a) m_i + (b³ − b) m_{i+1}) h_i² / 6
/// ```
///
/// where the second derivatives `m_i` solve the tridiagonal system
/// `h_{i−1} m_{i−1} + 2 (h_{i−1} + h_i) m_i + h_i m_{i+1} = 6 (s_i − s_{i−1})`
/// for `i = 1 … n−2`, with `m_0 = m_{n−1} = 0` (the natural end conditions).
/// The system is strictly diagonally dominant, so elimination without
/// pivoting (the Thomas algorithm) is stable. With two points the spline is
/// the straight line. Expanded in `d = q − q_i`, the same cubic is
/// `v_i + (s_i − h_i (2 m_i + m_{i+1})/6) d + (m_i/2) d² + ((m_{i+1} − m_i)/(6 h_i)) d³`,
/// the form [`Table::eval`] evaluates (it is `v_i` at the knot itself).
///
/// # Example
///
/// ```
/// use chain_core::values::{Extrapolation, Interpolation, Table};
/// let t = Table::new(
///     vec![(0.0, 0.0), (500.0, 0.0031), (1000.0, 0.0052)],
///     Interpolation::Linear,
///     Extrapolation::Error,
/// )
/// .unwrap();
/// assert_eq!(t.eval(250.0), Some(0.00155));
/// assert_eq!(t.eval(1200.0), None); // outside: no silent extrapolation
/// ```
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Table {
    q: Vec<f64>,
    v: Vec<f64>,
    /// Cubic: the second derivative at each knot (`n`); linear: empty.
    #[serde(skip)]
    m: Vec<f64>,
    /// Per interval, the polynomial in `d = q − q_i`: `[c0, c1, c2, c3]`.
    #[serde(skip)]
    poly: Vec<[f64; 4]>,
    interpolation: Interpolation,
    extrapolation: Extrapolation,
    /// `1/h` when the knots are evenly spaced (step `h`).
    #[serde(skip)]
    inverse_step: Option<f64>,
}

impl Table {
    /// A table through `points` `(q, v)`: at least two, finite, with strictly
    /// increasing `q`.
    pub fn new(
        points: Vec<(f64, f64)>,
        interpolation: Interpolation,
        extrapolation: Extrapolation,
    ) -> Result<Table, TableError> {
        if points.len() < 2 {
            return Err(TableError::TooFewPoints {
                found: points.len(),
            });
        }
        for (index, &(q, value)) in points.iter().enumerate() {
            if !q.is_finite() || !value.is_finite() {
                return Err(TableError::NotFinite { index, q, value });
            }
            if index > 0 {
                let previous = points[index - 1].0;
                // `!(q > previous)`, so that nothing unordered slips through.
                if q <= previous {
                    return Err(TableError::NotIncreasing { index, q, previous });
                }
            }
        }
        let (q, v): (Vec<f64>, Vec<f64>) = points.into_iter().unzip();
        let slopes: Vec<f64> = (0..q.len() - 1)
            .map(|i| (v[i + 1] - v[i]) / (q[i + 1] - q[i]))
            .collect();
        let m = match interpolation {
            Interpolation::Linear => Vec::new(),
            Interpolation::Cubic => natural_second_derivatives(&q, &slopes),
        };
        let poly = (0..q.len() - 1)
            .map(|i| match interpolation {
                Interpolation::Linear => [v[i], slopes[i], 0.0, 0.0],
                Interpolation::Cubic => {
                    let h = q[i + 1] - q[i];
                    [
                        v[i],
                        slopes[i] - h * (2.0 * m[i] + m[i + 1]) / 6.0,
                        m[i] / 2.0,
                        (m[i + 1] - m[i]) / (6.0 * h),
                    ]
                }
            })
            .collect();
        let n = q.len();
        let step = (q[n - 1] - q[0]) / (n - 1) as f64;
        let uniform = q
            .iter()
            .enumerate()
            .all(|(i, &x)| (x - (q[0] + i as f64 * step)).abs() <= UNIFORM_TOLERANCE * step);
        Ok(Table {
            q,
            v,
            m,
            poly,
            interpolation,
            extrapolation,
            inverse_step: uniform.then_some(1.0 / step),
        })
    }

    /// The positions `q_i`, increasing.
    pub fn positions(&self) -> &[f64] {
        &self.q
    }

    /// The values `v_i` at the positions.
    pub fn values(&self) -> &[f64] {
        &self.v
    }

    /// The second derivatives `m_i` of the cubic spline at the positions
    /// (`None` for a linear table).
    pub fn second_derivatives(&self) -> Option<&[f64]> {
        (self.interpolation == Interpolation::Cubic).then_some(&self.m[..])
    }

    /// How the table is read between its points.
    pub fn interpolation(&self) -> Interpolation {
        self.interpolation
    }

    /// What it gives outside its range.
    pub fn extrapolation(&self) -> Extrapolation {
        self.extrapolation
    }

    /// `(q_0, q_{n−1})`.
    pub fn range(&self) -> (f64, f64) {
        (self.q[0], self.q[self.q.len() - 1])
    }

    /// `v(q)`; `None` when `q` is outside the table and it does not hold its
    /// end values, or when `q` is NaN.
    #[inline]
    pub fn eval(&self, q: f64) -> Option<f64> {
        let n = self.q.len();
        let (lo, hi) = (self.q[0], self.q[n - 1]);
        if !(q >= lo && q < hi) {
            // The last knot exactly (the polynomial of the last interval
            // would give it to rounding only), or outside.
            return match self.extrapolation {
                _ if q == hi => Some(self.v[n - 1]),
                Extrapolation::Hold if q < lo => Some(self.v[0]),
                Extrapolation::Hold if q > hi => Some(self.v[n - 1]),
                _ => None,
            };
        }
        let i = self.interval(q);
        let d = q - self.q[i];
        let [c0, c1, c2, c3] = self.poly[i];
        Some(match self.interpolation {
            Interpolation::Linear => c0 + c1 * d,
            // Estrin's scheme: the two halves and d² in parallel.
            Interpolation::Cubic => (c0 + c1 * d) + (d * d) * (c2 + c3 * d),
        })
    }

    /// The interval `i` with `q_i ≤ q ≤ q_{i+1}`, for `q` in `[q_0, q_{n−1})`.
    #[inline]
    fn interval(&self, q: f64) -> usize {
        let last = self.q.len() - 2;
        match self.inverse_step {
            Some(inv) => {
                // `q ≥ q_0`, so the cast truncates a non-negative number.
                let mut i = (((q - self.q[0]) * inv) as usize).min(last);
                // Round-off can put the guess one interval off either way.
                while i > 0 && q < self.q[i] {
                    i -= 1;
                }
                while i < last && q > self.q[i + 1] {
                    i += 1;
                }
                i
            }
            None => (self.q.partition_point(|&k| k <= q)).clamp(1, last + 1) - 1,
        }
    }
}

/// The second derivatives of the natural cubic spline through knots `q` whose
/// interval slopes are `slopes` (Numerical Recipes §3.3, Eq. 3.3.7, solved by
/// the Thomas algorithm; `m_0 = m_{n−1} = 0`).
fn natural_second_derivatives(q: &[f64], slopes: &[f64]) -> Vec<f64> {
    let n = q.len();
    let mut m = vec![0.0; n];
    if n < 3 {
        return m;
    }
    let h = |i: usize| q[i + 1] - q[i];
    // Forward elimination over the unknowns m_1 … m_{n−2}: row i reads
    // h_{i−1} m_{i−1} + 2(h_{i−1} + h_i) m_i + h_i m_{i+1} = r_i.
    let mut diag = vec![0.0; n];
    let mut rhs = vec![0.0; n];
    for i in 1..n - 1 {
        diag[i] = 2.0 * (h(i - 1) + h(i));
        rhs[i] = 6.0 * (slopes[i] - slopes[i - 1]);
        if i > 1 {
            let w = h(i - 1) / diag[i - 1];
            diag[i] -= w * h(i - 1);
            rhs[i] -= w * rhs[i - 1];
        }
    }
    // Back substitution.
    for i in (1..n - 1).rev() {
        let upper = if i + 1 < n - 1 { h(i) * m[i + 1] } else { 0.0 };
        m[i] = (rhs[i] - upper) / diag[i];
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(points: &[(f64, f64)], i: Interpolation, e: Extrapolation) -> Table {
        Table::new(points.to_vec(), i, e).unwrap()
    }

    #[test]
    fn linear_reads_between_and_at_the_points() {
        let t = table(
            &[(0.0, 1.0), (2.0, 3.0), (3.0, 0.0)],
            Interpolation::Linear,
            Extrapolation::Error,
        );
        assert_eq!(t.eval(0.0), Some(1.0));
        assert_eq!(t.eval(1.0), Some(2.0));
        assert_eq!(t.eval(2.0), Some(3.0));
        assert_eq!(t.eval(2.5), Some(1.5));
        assert_eq!(t.eval(3.0), Some(0.0));
        assert_eq!(t.eval(-1e-12), None);
        assert_eq!(t.eval(3.0 + 1e-12), None);
        assert_eq!(t.eval(f64::NAN), None);
    }

    #[test]
    fn hold_gives_the_end_values() {
        let t = table(
            &[(0.0, 1.0), (1.0, 3.0)],
            Interpolation::Cubic,
            Extrapolation::Hold,
        );
        assert_eq!(t.eval(-5.0), Some(1.0));
        assert_eq!(t.eval(7.0), Some(3.0));
        assert_eq!(t.eval(f64::NAN), None);
        // Two points: the spline is the line.
        assert_eq!(t.eval(0.25), Some(1.5));
    }

    #[test]
    fn three_knot_spline_has_the_closed_form_second_derivative() {
        // Knots 0, 1, 3 (h0 = 1, h1 = 2), values 0, 2, 0: the one unknown m1
        // solves 2(h0 + h1) m1 = 6 (s1 − s0), s0 = 2, s1 = −1 → m1 = −3.
        let t = table(
            &[(0.0, 0.0), (1.0, 2.0), (3.0, 0.0)],
            Interpolation::Cubic,
            Extrapolation::Error,
        );
        let m = t.second_derivatives().unwrap();
        assert_eq!(m, [0.0, -3.0, 0.0]);
        // On [0, 1]: v = 2q + (q³ − q)·m1/6 = 2q − (q³ − q)/2.
        let q = 0.4;
        let expected = 2.0 * q - (q * q * q - q) / 2.0;
        assert!((t.eval(q).unwrap() - expected).abs() < 1e-15);
    }

    #[test]
    fn evenly_spaced_lookup_equals_the_binary_search() {
        let points: Vec<(f64, f64)> = (0..41)
            .map(|i| (-100.0 + 12.5 * f64::from(i), (f64::from(i) * 0.7).sin()))
            .collect();
        let even = table(&points, Interpolation::Cubic, Extrapolation::Error);
        assert!(even.inverse_step.is_some());
        let mut general = even.clone();
        general.inverse_step = None;
        for k in 0..=4000 {
            let q = -100.0 + 500.0 * f64::from(k) / 4000.0;
            assert_eq!(even.eval(q), general.eval(q), "q = {q}");
        }
        for &(q, _) in &points {
            assert_eq!(even.interval(q), general.interval(q));
        }
    }

    #[test]
    fn refusals() {
        let lin = Interpolation::Linear;
        let err = Extrapolation::Error;
        assert_eq!(
            Table::new(vec![(0.0, 1.0)], lin, err),
            Err(TableError::TooFewPoints { found: 1 })
        );
        assert!(matches!(
            Table::new(vec![(0.0, 1.0), (1.0, f64::NAN)], lin, err),
            Err(TableError::NotFinite { index: 1, .. })
        ));
        assert_eq!(
            Table::new(vec![(0.0, 1.0), (0.0, 2.0)], lin, err),
            Err(TableError::NotIncreasing {
                index: 1,
                q: 0.0,
                previous: 0.0
            })
        );
        assert_eq!(
            Table::new(vec![(0.0, 1.0), (2.0, 2.0), (1.0, 0.0)], lin, err),
            Err(TableError::NotIncreasing {
                index: 2,
                q: 1.0,
                previous: 2.0
            })
        );
    }
}
