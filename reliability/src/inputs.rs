//! The random inputs of an event: one marginal distribution per error
//! parameter and the transformation to independent standard normal space.
//!
//! FORM, the importance sampling and the sensitivities all work in the
//! standard normal space `U` of the paper's Section 3.1 ("transforming basic
//! random variable X space into independent standard normal random variable Y
//! space"). [`Inputs`] owns that transformation `x = T(u)`: callers only use
//! [`Inputs::to_physical`], [`Inputs::jacobian`] and the parameter
//! derivatives, so adding marginals (lognormal, truncated normal) or a
//! correlation (Nataf: `u → L·u → Φ → F⁻¹`) changes this file only.

use serde::Serialize;

use crate::error::ReliabilityError;
use crate::normal;
use crate::rng::CaseRng;

/// `√3`: half-width of a uniform law over its standard deviation.
const SQRT_3: f64 = 1.732_050_807_568_877_2;

/// The marginal distribution of one input.
///
/// Built only through the validating constructors [`Marginal::normal`] and
/// [`Marginal::uniform`] (the law is private), so every `Marginal` has a
/// finite mean and a positive spread; [`Marginal::family`] and the accessors
/// read it back. It serialises as `{"dist": "normal", "mean": …, "std": …}` or
/// `{"dist": "uniform", "min": …, "max": …}`.
///
/// ```
/// use reliability::inputs::{Family, Marginal};
/// let m = Marginal::uniform(-1.0, 2.0).unwrap();
/// assert_eq!(m.family(), Family::Uniform);
/// assert_eq!(m.support(), (-1.0, 2.0));
/// assert!(Marginal::normal(0.0, -1.0).is_err());
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(transparent)]
pub struct Marginal(Law);

/// The family of a [`Marginal`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
#[non_exhaustive]
pub enum Family {
    /// Normal: `x = μ + σ·u`.
    Normal,
    /// Uniform on `[min, max]`: `x = min + (max − min)·Φ(u)`.
    Uniform,
}

/// The validated law behind a [`Marginal`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "dist", rename_all = "lowercase")]
enum Law {
    /// Normal with mean `μ` and standard deviation `σ > 0`.
    Normal { mean: f64, std: f64 },
    /// Uniform on `[min, max]`, `min < max`.
    Uniform { min: f64, max: f64 },
}

impl Marginal {
    /// A validated normal marginal.
    pub fn normal(mean: f64, std: f64) -> Result<Marginal, ReliabilityError> {
        if !mean.is_finite() || !std.is_finite() || std <= 0.0 {
            return Err(ReliabilityError::InvalidDistribution(format!(
                "normal(mean {mean}, std {std}): the mean must be finite and the std positive"
            )));
        }
        Ok(Marginal(Law::Normal { mean, std }))
    }

    /// A validated uniform marginal.
    pub fn uniform(min: f64, max: f64) -> Result<Marginal, ReliabilityError> {
        if !min.is_finite() || !max.is_finite() || min >= max {
            return Err(ReliabilityError::InvalidDistribution(format!(
                "uniform(min {min}, max {max}): the bounds must be finite with min < max"
            )));
        }
        Ok(Marginal(Law::Uniform { min, max }))
    }

    /// The mean.
    pub fn mean(&self) -> f64 {
        match self.0 {
            Law::Normal { mean, .. } => mean,
            Law::Uniform { min, max } => 0.5 * (min + max),
        }
    }

    /// The standard deviation.
    pub fn std(&self) -> f64 {
        match self.0 {
            Law::Normal { std, .. } => std,
            Law::Uniform { min, max } => (max - min) / (2.0 * SQRT_3),
        }
    }

    /// The family (normal or uniform).
    pub fn family(&self) -> Family {
        match self.0 {
            Law::Normal { .. } => Family::Normal,
            Law::Uniform { .. } => Family::Uniform,
        }
    }

    /// The support `(lower, upper)`: `(−∞, +∞)` for a normal, `(min, max)`
    /// for a uniform.
    pub fn support(&self) -> (f64, f64) {
        match self.0 {
            Law::Normal { .. } => (f64::NEG_INFINITY, f64::INFINITY),
            Law::Uniform { min, max } => (min, max),
        }
    }

    /// True for a normal marginal (its transformation is affine).
    pub fn is_normal(&self) -> bool {
        matches!(self.0, Law::Normal { .. })
    }

    /// The same family with another mean and standard deviation.
    pub fn with_moments(&self, mean: f64, std: f64) -> Result<Marginal, ReliabilityError> {
        match self.0 {
            Law::Normal { .. } => Marginal::normal(mean, std),
            Law::Uniform { .. } => Marginal::uniform(mean - SQRT_3 * std, mean + SQRT_3 * std),
        }
    }

    /// `x = T(u)`, the physical value of a standard normal coordinate.
    #[inline]
    pub fn to_physical(&self, u: f64) -> f64 {
        match self.0 {
            Law::Normal { mean, std } => mean + std * u,
            Law::Uniform { min, max } => min + (max - min) * normal::cdf(u),
        }
    }

    /// `u = T⁻¹(x)`.
    pub fn to_standard(&self, x: f64) -> f64 {
        match self.0 {
            Law::Normal { mean, std } => (x - mean) / std,
            Law::Uniform { min, max } => normal::inverse_cdf((x - min) / (max - min)),
        }
    }

    /// `dx/du` at `u`.
    #[inline]
    pub fn dx_du(&self, u: f64) -> f64 {
        match self.0 {
            Law::Normal { std, .. } => std,
            Law::Uniform { min, max } => (max - min) * normal::pdf(u),
        }
    }

    /// `∂x/∂μ` at fixed `u` (the marginal parametrised by mean and std).
    pub fn dx_dmean(&self, _u: f64) -> f64 {
        1.0
    }

    /// `∂x/∂σ` at fixed `u` (the marginal parametrised by mean and std):
    /// `u` for a normal, `√3·(2Φ(u) − 1)` for a uniform.
    pub fn dx_dstd(&self, u: f64) -> f64 {
        match self.0 {
            Law::Normal { .. } => u,
            Law::Uniform { .. } => SQRT_3 * (2.0 * normal::cdf(u) - 1.0),
        }
    }

    /// One physical sample.
    #[inline]
    pub fn sample(&self, rng: &mut CaseRng) -> f64 {
        match self.0 {
            Law::Normal { mean, std } => mean + std * rng.normal(),
            Law::Uniform { min, max } => min + (max - min) * rng.uniform(),
        }
    }
}

/// The joint distribution of the inputs: independent marginals, named.
///
/// ```
/// use reliability::{Inputs, Marginal};
/// let inputs = Inputs::new(
///     vec!["a".into(), "b".into()],
///     vec![Marginal::normal(0.0, 2.0).unwrap(), Marginal::uniform(-1.0, 1.0).unwrap()],
/// ).unwrap();
/// let mut x = [0.0; 2];
/// inputs.to_physical(&[1.0, 0.0], &mut x);
/// assert_eq!(x, [2.0, 0.0]);
/// ```
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Inputs {
    names: Vec<String>,
    marginals: Vec<Marginal>,
    all_normal: bool,
    #[serde(skip)]
    means: Vec<f64>,
    #[serde(skip)]
    stds: Vec<f64>,
}

impl Inputs {
    /// Independent inputs with the given names and marginals.
    pub fn new(names: Vec<String>, marginals: Vec<Marginal>) -> Result<Inputs, ReliabilityError> {
        if names.len() != marginals.len() {
            return Err(ReliabilityError::Dimension {
                what: "input names",
                expected: marginals.len(),
                found: names.len(),
            });
        }
        let all_normal = marginals.iter().all(Marginal::is_normal);
        let means = marginals.iter().map(Marginal::mean).collect();
        let stds = marginals.iter().map(Marginal::std).collect();
        Ok(Inputs {
            names,
            marginals,
            all_normal,
            means,
            stds,
        })
    }

    /// Number of inputs.
    pub fn len(&self) -> usize {
        self.marginals.len()
    }

    /// True when there are no inputs.
    pub fn is_empty(&self) -> bool {
        self.marginals.is_empty()
    }

    /// The names, in input order.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The marginals, in input order.
    pub fn marginals(&self) -> &[Marginal] {
        &self.marginals
    }

    /// Index of a named input.
    pub fn index(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }

    /// True when the map `u → x` is affine (every marginal normal, no
    /// correlation), so that straight lines in `U` stay straight in `X`.
    pub fn is_affine(&self) -> bool {
        self.all_normal
    }

    /// The means.
    pub fn means(&self) -> &[f64] {
        &self.means
    }

    /// The standard deviations.
    pub fn stds(&self) -> &[f64] {
        &self.stds
    }

    /// A copy with input `j`'s mean and standard deviation replaced.
    pub fn with_moments(&self, j: usize, mean: f64, std: f64) -> Result<Inputs, ReliabilityError> {
        let mut marginals = self.marginals.clone();
        let m = marginals.get_mut(j).ok_or(ReliabilityError::Dimension {
            what: "input index",
            expected: self.len(),
            found: j,
        })?;
        *m = m.with_moments(mean, std)?;
        Inputs::new(self.names.clone(), marginals)
    }

    /// `x = T(u)`.
    #[inline]
    pub fn to_physical(&self, u: &[f64], x: &mut [f64]) {
        for ((x, u), m) in x.iter_mut().zip(u).zip(&self.marginals) {
            *x = m.to_physical(*u);
        }
    }

    /// `u = T⁻¹(x)`.
    pub fn to_standard(&self, x: &[f64], u: &mut [f64]) {
        for ((u, x), m) in u.iter_mut().zip(x).zip(&self.marginals) {
            *u = m.to_standard(*x);
        }
    }

    /// The diagonal Jacobian `dx_j/du_j` at `u`.
    #[inline]
    pub fn jacobian(&self, u: &[f64], out: &mut [f64]) {
        for ((o, u), m) in out.iter_mut().zip(u).zip(&self.marginals) {
            *o = m.dx_du(*u);
        }
    }

    /// One physical sample of every input.
    #[inline]
    pub fn sample(&self, rng: &mut CaseRng, x: &mut [f64]) {
        if self.all_normal {
            rng.fill_normal(x);
            for ((x, m), s) in x.iter_mut().zip(&self.means).zip(&self.stds) {
                *x = m + s * *x;
            }
        } else {
            for (x, m) in x.iter_mut().zip(&self.marginals) {
                *x = m.sample(rng);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn marginals_are_validated_and_serialise_by_family() {
        assert!(Marginal::normal(0.0, 0.0).is_err());
        assert!(Marginal::normal(f64::NAN, 1.0).is_err());
        assert!(Marginal::uniform(1.0, 1.0).is_err());
        assert!(Marginal::uniform(0.0, f64::INFINITY).is_err());
        let n = Marginal::normal(0.5, 2.0).unwrap();
        let u = Marginal::uniform(-1.0, 3.0).unwrap();
        assert_eq!((n.family(), u.family()), (Family::Normal, Family::Uniform));
        assert_eq!((n.mean(), n.std()), (0.5, 2.0));
        assert_eq!(u.support(), (-1.0, 3.0));
        assert!((u.std() - 4.0 / (2.0 * SQRT_3)).abs() < 1e-15);
        // A moved moment keeps the family and is validated again.
        assert!(u.with_moments(0.0, -1.0).is_err());
        assert_eq!(u.with_moments(1.0, 1.0).unwrap().family(), Family::Uniform);
        assert_eq!(
            serde_json::to_string(&n).unwrap(),
            r#"{"dist":"normal","mean":0.5,"std":2.0}"#
        );
        assert_eq!(
            serde_json::to_string(&u).unwrap(),
            r#"{"dist":"uniform","min":-1.0,"max":3.0}"#
        );
    }
}
