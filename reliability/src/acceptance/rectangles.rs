//! The series system the acceptance probability is taken over: every
//! toleranced component at every point as linear constraints on the inputs.

use std::collections::HashMap;

use chain_core::model::Sided;

use crate::error::ReliabilityError;
use crate::inputs::Inputs;
use crate::study::Study;
use crate::util::dot;

/// The series system of linear constraints `lower_i ≤ S_i·x ≤ upper_i`
/// over the inputs (every point × every toleranced component of a study).
///
/// ```
/// use reliability::{acceptance::Rectangles, Inputs, Marginal};
/// let inputs = Inputs::new(vec!["a".into()], vec![Marginal::normal(0.0, 1.0).unwrap()]).unwrap();
/// // −1 ≤ a ≤ 1 and a ≤ 0.5: one merged interval.
/// let r = Rectangles::new(inputs, vec![1.0, 1.0], vec![-1.0, f64::NEG_INFINITY], vec![1.0, 0.5]).unwrap();
/// assert_eq!((r.constraints(), r.distinct()), (2, 1));
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Rectangles {
    inputs: Inputs,
    /// Distinct rows, `k × n` row-major.
    rows: Vec<f64>,
    lower: Vec<f64>,
    upper: Vec<f64>,
    /// Constraints before merging duplicates.
    constraints: usize,
}

impl Rectangles {
    /// The constraints `lower_i ≤ rows_i·x ≤ upper_i` (`rows` is `K × n`
    /// row-major, `n = inputs.len()`; `lower` may be `−∞`, `upper` `+∞`).
    /// Rows equal bit for bit are merged (their intervals intersected).
    pub fn new(
        inputs: Inputs,
        rows: Vec<f64>,
        lower: Vec<f64>,
        upper: Vec<f64>,
    ) -> Result<Rectangles, ReliabilityError> {
        let n = inputs.len();
        let k = lower.len();
        if n == 0 {
            return Err(ReliabilityError::Dimension {
                what: "acceptance inputs",
                expected: 1,
                found: 0,
            });
        }
        if rows.len() != k * n {
            return Err(ReliabilityError::Dimension {
                what: "acceptance rows",
                expected: k * n,
                found: rows.len(),
            });
        }
        if upper.len() != k {
            return Err(ReliabilityError::Dimension {
                what: "acceptance upper bounds",
                expected: k,
                found: upper.len(),
            });
        }
        if k == 0 {
            return Err(ReliabilityError::EmptyGrid(
                "no acceptance constraint".into(),
            ));
        }
        if rows.iter().any(|v| !v.is_finite())
            || lower.iter().chain(&upper).any(|v| v.is_nan())
            || lower.contains(&f64::INFINITY)
            || upper.contains(&f64::NEG_INFINITY)
        {
            return Err(ReliabilityError::NonFinite("the acceptance constraints"));
        }
        let mut index: HashMap<Vec<u64>, usize> = HashMap::new();
        let (mut r, mut lo, mut hi) = (Vec::new(), Vec::new(), Vec::new());
        for i in 0..k {
            let row = &rows[i * n..(i + 1) * n];
            // +0.0 and −0.0 are the same coefficient.
            let key: Vec<u64> = row.iter().map(|v| (v + 0.0).to_bits()).collect();
            match index.get(&key) {
                Some(&d) => {
                    lo[d] = f64::max(lo[d], lower[i]);
                    hi[d] = f64::min(hi[d], upper[i]);
                }
                None => {
                    index.insert(key, lo.len());
                    r.extend_from_slice(row);
                    lo.push(lower[i]);
                    hi.push(upper[i]);
                }
            }
        }
        Ok(Rectangles {
            inputs,
            rows: r,
            lower: lo,
            upper: hi,
            constraints: k,
        })
    }

    /// Every toleranced component at every point of `study`:
    /// `E_c ≤ I_c` (one-sided) or `−I_c ≤ E_c ≤ I_c` (two-sided).
    pub fn from_study(study: &Study) -> Result<Rectangles, ReliabilityError> {
        if study.varies() {
            // One rectangle set over one set of inputs: a posterior whose
            // inputs differ from point to point has no such set.
            return Err(ReliabilityError::InvalidOption {
                option: "acceptance",
                message: "the inputs differ from point to point (tables in the values); the whole-machine acceptance needs one set of inputs for every point: give the values as constants, or leave acceptance out".into(),
            });
        }
        let spec = study.spec();
        let n = study.inputs().len();
        let np = study.points().len();
        let k = np * spec.tolerances.len();
        let mut rows = Vec::with_capacity(k * n);
        let (mut lower, mut upper) = (Vec::with_capacity(k), Vec::with_capacity(k));
        for p in 0..np {
            for &(c, t) in &spec.tolerances {
                rows.extend_from_slice(&study.row(p, c)?);
                upper.push(t);
                lower.push(match spec.sided {
                    Sided::Upper => f64::NEG_INFINITY,
                    Sided::Two => -t,
                });
            }
        }
        Rectangles::new(study.inputs().clone(), rows, lower, upper)
    }

    /// The same constraints over other inputs (the same names and count:
    /// other means, standard deviations or families).
    pub fn with_inputs(&self, inputs: Inputs) -> Result<Rectangles, ReliabilityError> {
        if inputs.len() != self.inputs.len() {
            return Err(ReliabilityError::Dimension {
                what: "acceptance inputs",
                expected: self.inputs.len(),
                found: inputs.len(),
            });
        }
        Ok(Rectangles {
            inputs,
            ..self.clone()
        })
    }

    /// The inputs.
    pub fn inputs(&self) -> &Inputs {
        &self.inputs
    }

    /// The constraints as given (points × components).
    pub fn constraints(&self) -> usize {
        self.constraints
    }

    /// The distinct constraints after merging equal rows.
    pub fn distinct(&self) -> usize {
        self.lower.len()
    }

    /// Distinct row `i` and its interval.
    pub fn row(&self, i: usize) -> (&[f64], f64, f64) {
        let n = self.inputs.len();
        (&self.rows[i * n..(i + 1) * n], self.lower[i], self.upper[i])
    }

    /// True when `x` satisfies every constraint.
    pub fn accepts(&self, x: &[f64]) -> bool {
        (0..self.distinct()).all(|i| {
            let (row, lo, hi) = self.row(i);
            let v = dot(row, x);
            v >= lo && v <= hi
        })
    }
}
