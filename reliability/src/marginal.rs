//! The marginal distribution of one input ([`Marginal`], its [`Family`]):
//! validated constructors, the moments, the support and the map from
//! standard normal space `x = F⁻¹(Φ(u))` with its derivatives. [`Inputs`]
//! joins marginals into the joint distribution; [`crate::nataf`] adjusts a
//! correlation between two of them.
//!
//! [`Inputs`]: crate::inputs::Inputs

use serde::Serialize;

use crate::error::ReliabilityError;
use crate::families::{Gumbel, Lognormal, Rayleigh, Triangular, TruncatedNormal, Weibull};
use crate::normal;
use crate::rng::CaseRng;

/// `√3`: half-width of a uniform law over its standard deviation.
pub(crate) const SQRT_3: f64 = 1.732_050_807_568_877_2;

/// The marginal distribution of one input.
///
/// Built only through the validating constructors ([`Marginal::normal`],
/// [`Marginal::uniform`], [`Marginal::lognormal`],
/// [`Marginal::truncated_normal`], [`Marginal::weibull`],
/// [`Marginal::gumbel`], [`Marginal::triangular`], [`Marginal::rayleigh`]
/// and [`Marginal::with_moments`]; the law is private), so every `Marginal`
/// has a finite mean and a positive spread, except the one degenerate law
/// [`Marginal::fixed`] (spread 0, an error whose spread other inputs carry); [`Marginal::family`] and the
/// accessors read it back. It serialises as its family's name under `dist`
/// and that family's parameters: `{"dist": "normal", "mean": …, "std": …}`,
/// `{"dist": "uniform", "min": …, "max": …}`,
/// `{"dist": "lognormal", "mean": …, "std": …, "shift": …}`, and so on
/// (a truncated normal's absent bound is left out).
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
#[serde(rename_all = "snake_case")]
#[non_exhaustive]
pub enum Family {
    /// Normal: `x = μ + σ·u`.
    Normal,
    /// Uniform on `[min, max]`: `x = min + (max − min)·Φ(u)`.
    Uniform,
    /// Lognormal with the mean and std of the variable and a shift.
    Lognormal,
    /// Normal truncated to `[min, max]` (either bound may be infinite).
    TruncatedNormal,
    /// Weibull (scale, shape, shift).
    Weibull,
    /// Gumbel, maximum type (mode, scale).
    Gumbel,
    /// Triangular (min, mode, max).
    Triangular,
    /// Rayleigh (scale, shift).
    Rayleigh,
    /// A fixed value, the degenerate normal `x = v + 0·u`: an error whose
    /// spread other inputs already carry (a values file's `carried_by`,
    /// docs/posterior.md).
    Fixed,
}

/// The validated law behind a [`Marginal`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "dist", rename_all = "snake_case")]
enum Law {
    /// Normal with mean `μ` and standard deviation `σ > 0`.
    Normal { mean: f64, std: f64 },
    /// Uniform on `[min, max]`, `min < max`.
    Uniform { min: f64, max: f64 },
    /// Lognormal (the variable's mean and std, a shift; `reliability-v2.md`
    /// §1, `crate::families`).
    Lognormal(Lognormal),
    /// Truncated normal (parent mean and std, bounds).
    TruncatedNormal(TruncatedNormal),
    /// Weibull.
    Weibull(Weibull),
    /// Gumbel (maximum).
    Gumbel(Gumbel),
    /// Triangular.
    Triangular(Triangular),
    /// Rayleigh.
    Rayleigh(Rayleigh),
    /// A fixed value (no spread).
    Fixed { value: f64 },
}

impl Marginal {
    /// A validated normal marginal: a finite `mean` and `std > 0`.
    pub fn normal(mean: f64, std: f64) -> Result<Marginal, ReliabilityError> {
        if !mean.is_finite() || !std.is_finite() || std <= 0.0 {
            return Err(ReliabilityError::InvalidDistribution(format!(
                "normal(mean {mean}, std {std}): the mean must be finite and the std positive"
            )));
        }
        Ok(Marginal(Law::Normal { mean, std }))
    }

    /// A fixed value `v` (finite): the degenerate normal `x = v + 0·u` of an
    /// error whose spread is carried by other inputs (docs/posterior.md,
    /// "Fixed and carried"). It has no density; its `u` does not move it,
    /// so every method sees it as the constant it is.
    pub fn fixed(value: f64) -> Result<Marginal, ReliabilityError> {
        if !value.is_finite() {
            return Err(ReliabilityError::InvalidDistribution(format!(
                "fixed({value}): the value must be finite"
            )));
        }
        Ok(Marginal(Law::Fixed { value }))
    }

    /// A validated uniform marginal: finite bounds, `min < max`.
    pub fn uniform(min: f64, max: f64) -> Result<Marginal, ReliabilityError> {
        if !min.is_finite() || !max.is_finite() || min >= max {
            return Err(ReliabilityError::InvalidDistribution(format!(
                "uniform(min {min}, max {max}): the bounds must be finite with min < max"
            )));
        }
        Ok(Marginal(Law::Uniform { min, max }))
    }

    /// A validated lognormal marginal: `mean` and `std` of the variable
    /// itself, support `(shift, ∞)` (`mean > shift`).
    pub fn lognormal(mean: f64, std: f64, shift: f64) -> Result<Marginal, ReliabilityError> {
        Ok(Marginal(Law::Lognormal(Lognormal::new(mean, std, shift)?)))
    }

    /// A validated truncated normal: the parent's `mean` and `std`, truncated
    /// to `[min, max]` (either bound may be absent, not both).
    pub fn truncated_normal(
        mean: f64,
        std: f64,
        min: Option<f64>,
        max: Option<f64>,
    ) -> Result<Marginal, ReliabilityError> {
        Ok(Marginal(Law::TruncatedNormal(TruncatedNormal::new(
            mean, std, min, max,
        )?)))
    }

    /// A validated Weibull: `F(x) = 1 − exp(−((x − shift)/scale)^shape)`.
    pub fn weibull(scale: f64, shape: f64, shift: f64) -> Result<Marginal, ReliabilityError> {
        Ok(Marginal(Law::Weibull(Weibull::new(scale, shape, shift)?)))
    }

    /// A validated Gumbel (maximum type): `F(x) = exp(−exp(−(x − mode)/scale))`.
    pub fn gumbel(mode: f64, scale: f64) -> Result<Marginal, ReliabilityError> {
        Ok(Marginal(Law::Gumbel(Gumbel::new(mode, scale)?)))
    }

    /// A validated triangular on `[min, max]` (`min < max`) with its mode in
    /// between (`min ≤ mode ≤ max`).
    pub fn triangular(min: f64, mode: f64, max: f64) -> Result<Marginal, ReliabilityError> {
        Ok(Marginal(Law::Triangular(Triangular::new(min, mode, max)?)))
    }

    /// A validated Rayleigh: `F(x) = 1 − exp(−(x − shift)²/(2·scale²))`.
    pub fn rayleigh(scale: f64, shift: f64) -> Result<Marginal, ReliabilityError> {
        Ok(Marginal(Law::Rayleigh(Rayleigh::new(scale, shift)?)))
    }

    /// The mean.
    pub fn mean(&self) -> f64 {
        match self.0 {
            Law::Normal { mean, .. } => mean,
            Law::Fixed { value } => value,
            Law::Uniform { min, max } => 0.5 * (min + max),
            _ => self.moments()[0],
        }
    }

    /// The standard deviation.
    pub fn std(&self) -> f64 {
        match self.0 {
            Law::Normal { std, .. } => std,
            Law::Fixed { .. } => 0.0,
            Law::Uniform { min, max } => (max - min) / (2.0 * SQRT_3),
            _ => self.moments()[1],
        }
    }

    /// `[mean, std]`.
    fn moments(&self) -> [f64; 2] {
        match &self.0 {
            Law::Normal { mean, std } => [*mean, *std],
            Law::Fixed { value } => [*value, 0.0],
            Law::Uniform { .. } => [self.mean(), self.std()],
            Law::Lognormal(l) => [l.mean, l.std],
            Law::TruncatedNormal(t) => t.moments(),
            Law::Weibull(w) => w.moments(),
            Law::Gumbel(g) => g.moments(),
            Law::Triangular(t) => t.moments(),
            Law::Rayleigh(r) => r.moments(),
        }
    }

    /// The family.
    pub fn family(&self) -> Family {
        match self.0 {
            Law::Normal { .. } => Family::Normal,
            Law::Uniform { .. } => Family::Uniform,
            Law::Lognormal(_) => Family::Lognormal,
            Law::TruncatedNormal(_) => Family::TruncatedNormal,
            Law::Weibull(_) => Family::Weibull,
            Law::Gumbel(_) => Family::Gumbel,
            Law::Triangular(_) => Family::Triangular,
            Law::Rayleigh(_) => Family::Rayleigh,
            Law::Fixed { .. } => Family::Fixed,
        }
    }

    /// The support `(lower, upper)`: `(−∞, +∞)` for a normal and a Gumbel,
    /// `(min, max)` for a uniform and a triangular, `(shift, ∞)` for a
    /// lognormal, Weibull and Rayleigh, the bounds of a truncated normal,
    /// `(v, v)` for a fixed value.
    pub fn support(&self) -> (f64, f64) {
        let inf = f64::INFINITY;
        match self.0 {
            Law::Normal { .. } | Law::Gumbel(_) => (-inf, inf),
            Law::Uniform { min, max } => (min, max),
            Law::Lognormal(l) => (l.shift, inf),
            Law::TruncatedNormal(t) => (t.lo(), t.hi()),
            Law::Weibull(w) => (w.shift, inf),
            Law::Triangular(t) => (t.min, t.max),
            Law::Rayleigh(r) => (r.shift, inf),
            Law::Fixed { value } => (value, value),
        }
    }

    /// The distribution function `F(x)`; see [`Marginal::sf`] for the upper
    /// tail.
    pub fn cdf(&self, x: f64) -> f64 {
        match self.0 {
            Law::Uniform { min, max } => ((x - min) / (max - min)).clamp(0.0, 1.0),
            Law::Fixed { value } => f64::from(u8::from(x >= value)),
            _ => normal::cdf(self.to_standard(x)),
        }
    }

    /// The upper tail `1 − F(x)`, computed without cancellation.
    pub fn sf(&self, x: f64) -> f64 {
        match self.0 {
            Law::Uniform { min, max } => ((max - x) / (max - min)).clamp(0.0, 1.0),
            Law::Fixed { value } => f64::from(u8::from(x < value)),
            _ => normal::sf(self.to_standard(x)),
        }
    }

    /// The density `f(x)` (0 for a fixed value, a point mass without one).
    pub fn pdf(&self, x: f64) -> f64 {
        match &self.0 {
            Law::Fixed { .. } => 0.0,
            Law::Normal { mean, std } => normal::pdf((x - mean) / std) / std,
            Law::Uniform { min, max } => {
                if (*min..=*max).contains(&x) {
                    1.0 / (max - min)
                } else {
                    0.0
                }
            }
            Law::Lognormal(l) => l.pdf(x),
            Law::TruncatedNormal(t) => t.pdf(x),
            Law::Weibull(w) => w.pdf(x),
            Law::Gumbel(g) => g.pdf(x),
            Law::Triangular(t) => t.pdf(x),
            Law::Rayleigh(r) => r.pdf(x),
        }
    }

    /// The quantile `F⁻¹(p)`, `p ∈ (0, 1)` (= `T(Φ⁻¹(p))`).
    pub fn quantile(&self, p: f64) -> f64 {
        self.to_physical(normal::inverse_cdf(p))
    }

    /// True for a normal marginal and a fixed value, its degenerate case
    /// (the transformation is affine).
    pub fn is_normal(&self) -> bool {
        matches!(self.0, Law::Normal { .. } | Law::Fixed { .. })
    }

    /// The same family with another mean and standard deviation.
    ///
    /// Location-scale families (uniform, Gumbel, triangular, Rayleigh) are
    /// translated and scaled; the lognormal and Weibull keep their shift,
    /// the truncated normal its bounds (its parent is solved for; an
    /// unreachable pair of moments is refused).
    pub fn with_moments(&self, mean: f64, std: f64) -> Result<Marginal, ReliabilityError> {
        if !(mean.is_finite() && std.is_finite() && std > 0.0) {
            return Err(ReliabilityError::InvalidDistribution(format!(
                "{:?} with mean {mean} and std {std}: the mean must be finite and the std positive",
                self.family()
            )));
        }
        Ok(Marginal(match &self.0 {
            Law::Normal { .. } | Law::Fixed { .. } => return Marginal::normal(mean, std),
            Law::Uniform { .. } => {
                return Marginal::uniform(mean - SQRT_3 * std, mean + SQRT_3 * std)
            }
            Law::Lognormal(l) => Law::Lognormal(Lognormal::new(mean, std, l.shift)?),
            Law::TruncatedNormal(t) => Law::TruncatedNormal(t.with_moments(mean, std)?),
            Law::Weibull(w) => Law::Weibull(w.with_moments(mean, std)?),
            Law::Gumbel(_) => Law::Gumbel(Gumbel::with_moments(mean, std)?),
            Law::Triangular(t) => Law::Triangular(t.with_moments(mean, std)?),
            Law::Rayleigh(_) => Law::Rayleigh(Rayleigh::with_moments(mean, std)?),
        }))
    }

    /// `x = T(u)`, the physical value of a standard normal coordinate.
    #[inline]
    pub fn to_physical(&self, u: f64) -> f64 {
        match &self.0 {
            Law::Normal { mean, std } => mean + std * u,
            Law::Fixed { value } => *value,
            Law::Uniform { min, max } => min + (max - min) * normal::cdf(u),
            Law::Lognormal(l) => l.x(u),
            Law::TruncatedNormal(t) => t.x(u),
            Law::Weibull(w) => w.x(u),
            Law::Gumbel(g) => g.x(u),
            Law::Triangular(t) => t.x(u),
            Law::Rayleigh(r) => r.x(u),
        }
    }

    /// `u = T⁻¹(x) = Φ⁻¹(F(x))`, from whichever tail does not cancel (for
    /// a fixed value every `u` gives `v`: 0 there, `±∞` elsewhere).
    pub fn to_standard(&self, x: f64) -> f64 {
        match &self.0 {
            Law::Normal { mean, std } => (x - mean) / std,
            Law::Fixed { value } => {
                if x == *value {
                    0.0
                } else {
                    f64::INFINITY.copysign(x - value)
                }
            }
            Law::Uniform { min, max } => normal::inverse_cdf((x - min) / (max - min)),
            Law::Lognormal(l) => l.u(x),
            Law::TruncatedNormal(t) => t.u(x),
            Law::Weibull(w) => w.u(x),
            Law::Gumbel(g) => g.u(x),
            Law::Triangular(t) => t.u(x),
            Law::Rayleigh(r) => r.u(x),
        }
    }

    /// `dx/du` at `u`.
    #[inline]
    pub fn dx_du(&self, u: f64) -> f64 {
        match &self.0 {
            Law::Normal { std, .. } => *std,
            Law::Fixed { .. } => 0.0,
            Law::Uniform { min, max } => (max - min) * normal::pdf(u),
            Law::Lognormal(l) => l.dx_du(u),
            Law::TruncatedNormal(t) => t.dx_du(u),
            Law::Weibull(w) => w.dx_du(u),
            Law::Gumbel(g) => g.dx_du(u),
            Law::Triangular(t) => t.dx_du(u),
            Law::Rayleigh(r) => r.dx_du(u),
        }
    }

    /// `d²x/du²` at `u` (0 for a normal; `−(max − min)·u·φ(u)` for a
    /// uniform; `crate::families` for the others).
    #[inline]
    pub fn d2x_du2(&self, u: f64) -> f64 {
        match &self.0 {
            Law::Normal { .. } | Law::Fixed { .. } => 0.0,
            Law::Uniform { min, max } => -(max - min) * u * normal::pdf(u),
            Law::Lognormal(l) => l.d2x_du2(u),
            Law::TruncatedNormal(t) => t.d2x_du2(u),
            Law::Weibull(w) => w.d2x_du2(u),
            Law::Gumbel(g) => g.d2x_du2(u),
            Law::Triangular(t) => t.d2x_du2(u),
            Law::Rayleigh(r) => r.d2x_du2(u),
        }
    }

    /// `∂x/∂μ` at fixed `u` (the marginal parametrised by mean and std, the
    /// family and the std held): 1 for the location-scale families,
    /// `crate::families` for the lognormal, Weibull and truncated normal.
    pub fn dx_dmean(&self, u: f64) -> f64 {
        match &self.0 {
            Law::Lognormal(l) => l.dx_dmoments(u)[0],
            Law::TruncatedNormal(t) => t.dx_dmoments(u)[0],
            Law::Weibull(w) => w.dx_dmoments(u)[0],
            _ => 1.0,
        }
    }

    /// `∂x/∂σ` at fixed `u` (the marginal parametrised by mean and std, the
    /// mean held): `u` for a normal and a fixed value (the normal at
    /// `σ = 0`), `√3·(2Φ(u) − 1)` for a uniform,
    /// `(x − μ)/σ` for the other location-scale families, `crate::families`
    /// for the lognormal, Weibull and truncated normal.
    pub fn dx_dstd(&self, u: f64) -> f64 {
        match &self.0 {
            Law::Normal { .. } | Law::Fixed { .. } => u,
            Law::Uniform { .. } => SQRT_3 * (2.0 * normal::cdf(u) - 1.0),
            Law::Lognormal(l) => l.dx_dmoments(u)[1],
            Law::TruncatedNormal(t) => t.dx_dmoments(u)[1],
            Law::Weibull(w) => w.dx_dmoments(u)[1],
            Law::Gumbel(g) => g.dx_dstd(u),
            Law::Triangular(t) => {
                let [m, s] = t.moments();
                (t.x(u) - m) / s
            }
            Law::Rayleigh(r) => r.dx_dstd(u),
        }
    }

    /// One physical sample: `μ + σ·z` for a normal and `min + (max − min)·U`
    /// for a uniform (a standard normal `z`, a uniform `U` on `[0, 1)`), `T(u)`
    /// of a standard normal draw for the other families (a fixed value takes
    /// its draw too, so the other inputs' streams do not depend on it).
    #[inline]
    pub fn sample(&self, rng: &mut CaseRng) -> f64 {
        match self.0 {
            Law::Normal { mean, std } => mean + std * rng.normal(),
            Law::Uniform { min, max } => min + (max - min) * rng.uniform(),
            _ => self.to_physical(rng.normal()),
        }
    }
}
