//! The non-normal marginal families of `reliability-v2.md` §1: the
//! distribution function, density and the isoprobabilistic transform
//! `x = F⁻¹(Φ(u))` (Rosenblatt / Nataf marginal transform; Hohenbichler &
//! Rackwitz 1981, Lemaire *Structural Reliability* 2009 §4.3) with its exact
//! derivatives `dx/du`, `d²x/du²` and the derivatives at fixed `u` with
//! respect to the variable's mean and standard deviation (the family and the
//! other moment held) — the generalisation of the grinder paper's Eq. 32-33
//! to non-normal inputs.
//!
//! Each family keeps its tail probabilities to full relative accuracy down
//! to `Φ(−8) ≈ 6.2·10⁻¹⁶` on both sides: the probability level is taken as
//! `Φ(u)` below the median and `Φ(−u)` above it, `ln(1 − p)` as
//! `ln_1p(−p)`, `1 − e^{−z}` as `−expm1(−z)`, never by a subtraction from 1.
//!
//! Holding "the family and the other moment": a location-scale family
//! (uniform, Gumbel, triangular, Rayleigh with its shift) keeps its shape,
//! so `∂x/∂μ = 1` and `∂x/∂σ = (x − μ)/σ`. A family with a fixed end of its
//! support (lognormal and Weibull with their `shift`, the truncated normal
//! with its bounds) keeps that end: its native parameters `θ` are functions
//! of `(μ, σ)` and `∂x/∂(μ, σ) = ∂x/∂θ · [∂(μ, σ)/∂θ]⁻¹` (the inverse of
//! the exact moment Jacobian).

use std::f64::consts::{PI, SQRT_2};

use serde::Serialize;

use crate::error::ReliabilityError;
use crate::normal;

/// Euler–Mascheroni constant `γ` (the mean of the standard Gumbel).
const EULER_GAMMA: f64 = 0.577_215_664_901_532_9;

fn invalid(msg: String) -> ReliabilityError {
    ReliabilityError::InvalidDistribution(msg)
}

/// `u` of a probability level given both as `p = F` and `q = 1 − F` (each
/// computed without cancellation): `Φ⁻¹(p)` below the median, `−Φ⁻¹(q)`
/// above.
fn u_of(p: f64, q: f64) -> f64 {
    if p <= q {
        normal::inverse_cdf(p)
    } else {
        -normal::inverse_cdf(q)
    }
}

/// `Φ(b) − Φ(a)` for `a ≤ b`: as half a difference of `erf` when both lie
/// in `[−1, 1]` (where `erf` has no cancellation and a bound at 0 is
/// exact), otherwise [`normal::interval`].
fn mass(a: f64, b: f64) -> f64 {
    if a.abs() <= 1.0 && b.abs() <= 1.0 {
        0.5 * (libm::erf(b / SQRT_2) - libm::erf(a / SQRT_2))
    } else {
        normal::interval(a, b)
    }
}

/// `p·a^k`, zero at an infinite `a` (where the density factor `p` is 0).
fn tail(p: f64, a: f64, k: i32) -> f64 {
    if a.is_finite() {
        p * a.powi(k)
    } else {
        0.0
    }
}

/// `t = −ln(1 − Φ(u))`, the cumulative hazard of a Weibull-type
/// transform, accurate on both sides.
fn cum_hazard(u: f64) -> f64 {
    if u < 0.0 {
        -libm::log1p(-normal::cdf(u))
    } else {
        -normal::sf(u).ln()
    }
}

/// `h(u) = φ(u)/Φ(−u) = dt/du` (the normal hazard rate); `h' = h·(h − u)`.
fn hazard(u: f64) -> f64 {
    normal::pdf(u) / normal::sf(u)
}

/// Solves the 2×2 system `J·d = r` (row-major `J`).
fn solve2(j: [[f64; 2]; 2], r: [f64; 2]) -> [f64; 2] {
    let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
    [
        (r[0] * j[1][1] - r[1] * j[0][1]) / det,
        (j[0][0] * r[1] - j[1][0] * r[0]) / det,
    ]
}

/// `(∂x/∂μ, ∂x/∂σ)` from the native derivatives `∂x/∂θ` and the moment
/// Jacobian `J = ∂(μ, σ)/∂θ`: `∂x/∂(μ,σ) = (∂x/∂θ)·J⁻¹`, i.e. `Jᵀ·d = ∂x/∂θ`.
fn chain_moments(j: [[f64; 2]; 2], dx_dtheta: [f64; 2]) -> [f64; 2] {
    solve2([[j[0][0], j[1][0]], [j[0][1], j[1][1]]], dx_dtheta)
}

// ---------------------------------------------------------------- lognormal

/// Lognormal: `x = shift + exp(λ + ζ·u)` with `ζ² = ln(1 + σ²/(μ − shift)²)`,
/// `λ = ln(μ − shift) − ζ²/2` (the moments `μ`, `σ` of `x`; Ang & Tang 2007
/// Eq. 3.32).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub(crate) struct Lognormal {
    pub(crate) mean: f64,
    pub(crate) std: f64,
    pub(crate) shift: f64,
    #[serde(skip)]
    pub(crate) lambda: f64,
    #[serde(skip)]
    pub(crate) zeta: f64,
}

impl Lognormal {
    pub(crate) fn new(mean: f64, std: f64, shift: f64) -> Result<Lognormal, ReliabilityError> {
        if !(mean.is_finite() && std.is_finite() && shift.is_finite())
            || std <= 0.0
            || mean <= shift
        {
            return Err(invalid(format!(
                "lognormal(mean {mean}, std {std}, shift {shift}): needs finite values, std > 0 and mean > shift"
            )));
        }
        let a = mean - shift;
        let zeta2 = libm::log1p((std / a).powi(2));
        Ok(Lognormal {
            mean,
            std,
            shift,
            lambda: a.ln() - 0.5 * zeta2,
            zeta: zeta2.sqrt(),
        })
    }
    pub(crate) fn x(&self, u: f64) -> f64 {
        self.shift + (self.lambda + self.zeta * u).exp()
    }
    pub(crate) fn u(&self, x: f64) -> f64 {
        if x <= self.shift {
            return f64::NEG_INFINITY;
        }
        ((x - self.shift).ln() - self.lambda) / self.zeta
    }
    pub(crate) fn pdf(&self, x: f64) -> f64 {
        if x <= self.shift {
            return 0.0;
        }
        normal::pdf(self.u(x)) / (self.zeta * (x - self.shift))
    }
    pub(crate) fn dx_du(&self, u: f64) -> f64 {
        self.zeta * (self.lambda + self.zeta * u).exp()
    }
    pub(crate) fn d2x_du2(&self, u: f64) -> f64 {
        self.zeta * self.zeta * (self.lambda + self.zeta * u).exp()
    }
    /// `(∂x/∂μ, ∂x/∂σ)` at fixed `u` (shift held): with `a = μ − shift`,
    /// `∂ζ/∂a = −σ²/(ζ·a·(a² + σ²))`, `∂λ/∂a = 1/a − ζ·∂ζ/∂a`,
    /// `∂ζ/∂σ = σ/(ζ·(a² + σ²))`, `∂λ/∂σ = −ζ·∂ζ/∂σ`.
    pub(crate) fn dx_dmoments(&self, u: f64) -> [f64; 2] {
        let (a, s, z) = (self.mean - self.shift, self.std, self.zeta);
        let e = (self.lambda + z * u).exp();
        let dz_da = -s * s / (z * a * (a * a + s * s));
        let dl_da = 1.0 / a - z * dz_da;
        let dz_ds = s / (z * (a * a + s * s));
        let dl_ds = -z * dz_ds;
        [e * (dl_da + u * dz_da), e * (dl_ds + u * dz_ds)]
    }
}

// --------------------------------------------------------- truncated normal

/// A normal `N(m, s²)` (the parent) truncated to `[min, max]`:
/// `x = m + s·z`, `Φ(z) = Φ(α)·Φ(−u) + Φ(β)·Φ(u)` with `α = (min − m)/s`,
/// `β = (max − m)/s` (the inverse of `F(x) = (Φ(z) − Φ(α))/(Φ(β) − Φ(α))`,
/// written as a convex combination so that neither tail cancels).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub(crate) struct TruncatedNormal {
    /// Mean of the parent.
    pub(crate) mean: f64,
    /// Standard deviation of the parent.
    pub(crate) std: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(crate) min: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(crate) max: Option<f64>,
    #[serde(skip)]
    pub(crate) alpha: f64,
    #[serde(skip)]
    pub(crate) beta: f64,
    /// `Φ(β) − Φ(α)`.
    #[serde(skip)]
    pub(crate) z: f64,
    /// `(E Z, E Z²)` of the standardised truncated variable.
    #[serde(skip)]
    pub(crate) m: [f64; 2],
}

impl TruncatedNormal {
    pub(crate) fn new(
        mean: f64,
        std: f64,
        min: Option<f64>,
        max: Option<f64>,
    ) -> Result<TruncatedNormal, ReliabilityError> {
        let lo = min.unwrap_or(f64::NEG_INFINITY);
        let hi = max.unwrap_or(f64::INFINITY);
        let finite_or_absent = |v: Option<f64>| v.is_none_or(f64::is_finite);
        if !(mean.is_finite() && std.is_finite() && finite_or_absent(min) && finite_or_absent(max))
            || std <= 0.0
            || lo >= hi
            || (min.is_none() && max.is_none())
        {
            return Err(invalid(format!(
                "truncated_normal(mean {mean}, std {std}, min {lo}, max {hi}): needs finite values, std > 0, at least one bound and min < max"
            )));
        }
        let alpha = (lo - mean) / std;
        let beta = (hi - mean) / std;
        let z = mass(alpha, beta);
        if z.is_nan() || z <= 0.0 {
            return Err(invalid(format!(
                "truncated_normal(mean {mean}, std {std}, min {lo}, max {hi}): the interval holds no probability of the parent (Φ(β) − Φ(α) = {z:e})"
            )));
        }
        // Johnson, Kotz & Balakrishnan (1994), Eq. 13.134-13.135.
        let (pa, pb) = (normal::pdf(alpha) / z, normal::pdf(beta) / z);
        let m1 = pa - pb;
        let m2 = 1.0 + tail(pa, alpha, 1) - tail(pb, beta, 1);
        Ok(TruncatedNormal {
            mean,
            std,
            min,
            max,
            alpha,
            beta,
            z,
            m: [m1, m2],
        })
    }
    pub(crate) fn lo(&self) -> f64 {
        self.min.unwrap_or(f64::NEG_INFINITY)
    }
    pub(crate) fn hi(&self) -> f64 {
        self.max.unwrap_or(f64::INFINITY)
    }
    pub(crate) fn moments(&self) -> [f64; 2] {
        let [m1, m2] = self.m;
        [
            self.mean + self.std * m1,
            self.std * (m2 - m1 * m1).max(0.0).sqrt(),
        ]
    }
    /// The standardised value `z(u)`.
    fn zu(&self, u: f64) -> f64 {
        let (p, q) = (normal::cdf(u), normal::sf(u));
        let lower = normal::cdf(self.alpha) * q + normal::cdf(self.beta) * p;
        let mut z = if lower <= 0.5 {
            normal::inverse_cdf(lower)
        } else {
            -normal::inverse_cdf(normal::sf(self.alpha) * q + normal::sf(self.beta) * p)
        };
        // One Newton step on the mass between the nearer bound and z (no
        // cancellation near a bound at the parent's mean: `mass`).
        if u < 0.0 && self.alpha.is_finite() {
            z -= (mass(self.alpha, z.max(self.alpha)) - p * self.z) / normal::pdf(z);
        } else if u >= 0.0 && self.beta.is_finite() {
            z += (mass(z.min(self.beta), self.beta) - q * self.z) / normal::pdf(z);
        }
        z.clamp(self.alpha, self.beta)
    }
    pub(crate) fn x(&self, u: f64) -> f64 {
        self.mean + self.std * self.zu(u)
    }
    pub(crate) fn u(&self, x: f64) -> f64 {
        let z = ((x - self.mean) / self.std).clamp(self.alpha, self.beta);
        u_of(mass(self.alpha, z) / self.z, mass(z, self.beta) / self.z)
    }
    pub(crate) fn pdf(&self, x: f64) -> f64 {
        if x < self.lo() || x > self.hi() {
            return 0.0;
        }
        normal::pdf((x - self.mean) / self.std) / (self.std * self.z)
    }
    /// `z' = Z·φ(u)/φ(z)`.
    fn dz(&self, u: f64, z: f64) -> f64 {
        self.z * normal::pdf(u) / normal::pdf(z)
    }
    pub(crate) fn dx_du(&self, u: f64) -> f64 {
        self.std * self.dz(u, self.zu(u))
    }
    /// From `φ(z)·z' = Z·φ(u)`: `z'' = z'·(z·z' − u)`.
    pub(crate) fn d2x_du2(&self, u: f64) -> f64 {
        let z = self.zu(u);
        let d = self.dz(u, z);
        self.std * d * (z * d - u)
    }
    /// `∂(mean, std)/∂(m, s)` (rows: mean, std; columns: parent m, s), from
    /// `∂E[h(Z)]/∂α = p_α·(E h − h(α))`, `∂E[h(Z)]/∂β = p_β·(h(β) − E h)`,
    /// `p_α = φ(α)/Z`, `p_β = φ(β)/Z`, and `∂α/∂m = −1/s`, `∂α/∂s = −α/s`.
    fn moment_jacobian(&self) -> [[f64; 2]; 2] {
        let (a, b) = (self.alpha, self.beta);
        let (pa, pb) = (normal::pdf(a) / self.z, normal::pdf(b) / self.z);
        let [m1, m2] = self.m;
        // ∂m_k/∂α, ∂m_k/∂β; and α·∂m_k/∂α, β·∂m_k/∂β (0 at an infinite bound).
        let d1a = pa * m1 - tail(pa, a, 1);
        let d1b = tail(pb, b, 1) - pb * m1;
        let d2a = pa * m2 - tail(pa, a, 2);
        let d2b = tail(pb, b, 2) - pb * m2;
        let ad1a = tail(pa, a, 1) * m1 - tail(pa, a, 2);
        let bd1b = tail(pb, b, 2) - tail(pb, b, 1) * m1;
        let ad2a = tail(pa, a, 1) * m2 - tail(pa, a, 3);
        let bd2b = tail(pb, b, 3) - tail(pb, b, 1) * m2;
        let v = (m2 - m1 * m1).max(f64::MIN_POSITIVE);
        let sv = v.sqrt();
        let dva = d2a - 2.0 * m1 * d1a;
        let dvb = d2b - 2.0 * m1 * d1b;
        let adva = ad2a - 2.0 * m1 * ad1a;
        let bdvb = bd2b - 2.0 * m1 * bd1b;
        [
            [1.0 - (d1a + d1b), m1 - (ad1a + bd1b)],
            [-(dva + dvb) / (2.0 * sv), sv - (adva + bdvb) / (2.0 * sv)],
        ]
    }
    /// `(∂x/∂mean, ∂x/∂std)` at fixed `u`, the bounds held: `∂x/∂m = 1 −
    /// ∂z/∂α − ∂z/∂β`, `∂x/∂s = z − α·∂z/∂α − β·∂z/∂β` with `∂z/∂α =
    /// φ(α)·Φ(−u)/φ(z)`, `∂z/∂β = φ(β)·Φ(u)/φ(z)`, chained through the
    /// inverse moment Jacobian.
    pub(crate) fn dx_dmoments(&self, u: f64) -> [f64; 2] {
        let z = self.zu(u);
        let fz = normal::pdf(z);
        let dza = normal::pdf(self.alpha) * normal::sf(u) / fz;
        let dzb = normal::pdf(self.beta) * normal::cdf(u) / fz;
        let az = if self.alpha.is_finite() {
            self.alpha * dza
        } else {
            0.0
        };
        let bz = if self.beta.is_finite() {
            self.beta * dzb
        } else {
            0.0
        };
        let native = [1.0 - dza - dzb, z - az - bz];
        chain_moments(self.moment_jacobian(), native)
    }
    /// The parent `(m, s)` whose truncation to the same bounds has the given
    /// mean and std (Newton on the exact moment Jacobian).
    pub(crate) fn with_moments(
        &self,
        mean: f64,
        std: f64,
    ) -> Result<TruncatedNormal, ReliabilityError> {
        let [m0, s0] = self.moments();
        let mut t = TruncatedNormal::new(
            self.mean + (mean - m0),
            self.std * std / s0,
            self.min,
            self.max,
        )
        .unwrap_or(*self);
        for _ in 0..100 {
            let [m, s] = t.moments();
            let r = [mean - m, std - s];
            if r[0].abs() <= 1e-14 * std.max(mean.abs()) && r[1].abs() <= 1e-14 * std {
                return Ok(t);
            }
            let d = solve2(t.moment_jacobian(), r);
            let mut step = 1.0;
            loop {
                let cand = TruncatedNormal::new(
                    t.mean + step * d[0],
                    t.std + step * d[1],
                    self.min,
                    self.max,
                );
                match cand {
                    Ok(c) if c.std > 0.0 && c.z > 0.0 => {
                        t = c;
                        break;
                    }
                    _ if step > 1e-12 => step *= 0.5,
                    _ => break,
                }
            }
        }
        let [m, s] = t.moments();
        if (m - mean).abs() <= 1e-10 * std.max(mean.abs()) && (s - std).abs() <= 1e-10 * std {
            return Ok(t);
        }
        Err(invalid(format!(
            "truncated_normal on [{}, {}]: no parent normal gives mean {mean} and std {std}",
            self.lo(),
            self.hi()
        )))
    }
}

// ------------------------------------------------------------------ weibull

/// `Γ(1 + 1/k)`, `Γ(1 + 2/k)` and the coefficient of variation
/// `√(Γ(1 + 2/k)/Γ(1 + 1/k)² − 1)` (without cancellation).
fn weibull_gammas(k: f64) -> (f64, f64, f64) {
    let l1 = libm::lgamma(1.0 + 1.0 / k);
    let l2 = libm::lgamma(1.0 + 2.0 / k);
    (l1.exp(), l2.exp(), libm::expm1(l2 - 2.0 * l1).sqrt())
}

/// Weibull: `x = shift + λ·t^{1/k}`, `t = −ln(1 − Φ(u))`; mean
/// `shift + λ·Γ(1 + 1/k)`, std `λ·√(Γ(1 + 2/k) − Γ(1 + 1/k)²)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub(crate) struct Weibull {
    pub(crate) scale: f64,
    pub(crate) shape: f64,
    pub(crate) shift: f64,
}

impl Weibull {
    pub(crate) fn new(scale: f64, shape: f64, shift: f64) -> Result<Weibull, ReliabilityError> {
        if !(scale.is_finite() && shape.is_finite() && shift.is_finite())
            || scale <= 0.0
            || shape <= 0.0
        {
            return Err(invalid(format!(
                "weibull(scale {scale}, shape {shape}, shift {shift}): needs finite values, scale > 0 and shape > 0"
            )));
        }
        Ok(Weibull {
            scale,
            shape,
            shift,
        })
    }
    pub(crate) fn moments(&self) -> [f64; 2] {
        let (g1, _, cv) = weibull_gammas(self.shape);
        [self.shift + self.scale * g1, self.scale * g1 * cv]
    }
    pub(crate) fn x(&self, u: f64) -> f64 {
        self.shift + self.scale * cum_hazard(u).powf(1.0 / self.shape)
    }
    pub(crate) fn u(&self, x: f64) -> f64 {
        if x <= self.shift {
            return f64::NEG_INFINITY;
        }
        let t = ((x - self.shift) / self.scale).powf(self.shape);
        u_of(-libm::expm1(-t), (-t).exp())
    }
    pub(crate) fn pdf(&self, x: f64) -> f64 {
        if x <= self.shift {
            return 0.0;
        }
        let (k, y) = (self.shape, (x - self.shift) / self.scale);
        k / self.scale * y.powf(k - 1.0) * (-y.powf(k)).exp()
    }
    /// `dx/du = (λ/k)·t^{1/k − 1}·h`, `h = φ(u)/Φ(−u) = dt/du`.
    pub(crate) fn dx_du(&self, u: f64) -> f64 {
        let (t, h, k) = (cum_hazard(u), hazard(u), self.shape);
        self.scale / k * t.powf(1.0 / k - 1.0) * h
    }
    /// `d²x/du² = (λ/k)·[(1/k − 1)·t^{1/k − 2}·h² + t^{1/k − 1}·h·(h − u)]`.
    pub(crate) fn d2x_du2(&self, u: f64) -> f64 {
        let (t, h, k) = (cum_hazard(u), hazard(u), self.shape);
        self.scale / k
            * ((1.0 / k - 1.0) * t.powf(1.0 / k - 2.0) * h * h
                + t.powf(1.0 / k - 1.0) * h * (h - u))
    }
    /// `(∂x/∂mean, ∂x/∂std)`, shift held: `∂x/∂λ = t^{1/k}`,
    /// `∂x/∂k = −λ·t^{1/k}·ln t/k²`, chained through the inverse of
    /// `∂(mean, std)/∂(λ, k)` (`ψ` the digamma function):
    /// `∂mean/∂λ = Γ₁`, `∂mean/∂k = −λΓ₁ψ(1 + 1/k)/k²`, `∂std/∂λ = s`,
    /// `∂std/∂k = λ·(Γ₁²ψ(1 + 1/k) − Γ₂ψ(1 + 2/k))/(k²·s)`.
    pub(crate) fn dx_dmoments(&self, u: f64) -> [f64; 2] {
        let (l, k) = (self.scale, self.shape);
        let t = cum_hazard(u);
        let tk = t.powf(1.0 / k);
        let native = [tk, -l * tk * t.ln() / (k * k)];
        chain_moments(self.moment_jacobian(), native)
    }
    fn moment_jacobian(&self) -> [[f64; 2]; 2] {
        let (l, k) = (self.scale, self.shape);
        let (g1, g2, cv) = weibull_gammas(k);
        let s = g1 * cv;
        let p1 = statrs::function::gamma::digamma(1.0 + 1.0 / k);
        let p2 = statrs::function::gamma::digamma(1.0 + 2.0 / k);
        [
            [g1, -l * g1 * p1 / (k * k)],
            [s, l * (g1 * g1 * p1 - g2 * p2) / (k * k * s)],
        ]
    }
    /// The `(λ, k)` with the given mean and std, shift held: `k` from the
    /// coefficient of variation `σ/(μ − shift)` (decreasing in `k`;
    /// bisection in `ln k`), then `λ = (μ − shift)/Γ(1 + 1/k)`.
    pub(crate) fn with_moments(&self, mean: f64, std: f64) -> Result<Weibull, ReliabilityError> {
        let a = mean - self.shift;
        let bad = || {
            invalid(format!(
                "weibull with shift {}: no shape gives mean {mean} and std {std} (needs mean > shift, std > 0)",
                self.shift
            ))
        };
        if !(a > 0.0 && std > 0.0 && a.is_finite() && std.is_finite()) {
            return Err(bad());
        }
        let target = std / a;
        let cv = |lk: f64| weibull_gammas(lk.exp()).2;
        let (mut lo, mut hi) = ((0.05f64).ln(), (1e4f64).ln());
        if !(cv(lo) >= target && cv(hi) <= target) {
            return Err(bad());
        }
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if cv(mid) > target {
                lo = mid;
            } else {
                hi = mid;
            }
            if hi - lo < 1e-15 {
                break;
            }
        }
        let k = (0.5 * (lo + hi)).exp();
        Weibull::new(a / weibull_gammas(k).0, k, self.shift)
    }
}

// ------------------------------------------------------------------- gumbel

/// Gumbel (maximum): `x = mode + β·w`, `w = −ln(−ln Φ(u))`; mean
/// `mode + γβ`, std `πβ/√6`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub(crate) struct Gumbel {
    pub(crate) mode: f64,
    pub(crate) scale: f64,
}

/// `t = −ln Φ(u)`, accurate on both sides.
fn gumbel_t(u: f64) -> f64 {
    if u > 0.0 {
        -libm::log1p(-normal::sf(u))
    } else {
        -normal::cdf(u).ln()
    }
}

impl Gumbel {
    pub(crate) fn new(mode: f64, scale: f64) -> Result<Gumbel, ReliabilityError> {
        if !(mode.is_finite() && scale.is_finite()) || scale <= 0.0 {
            return Err(invalid(format!(
                "gumbel(mode {mode}, scale {scale}): needs finite values and scale > 0"
            )));
        }
        Ok(Gumbel { mode, scale })
    }
    pub(crate) fn moments(&self) -> [f64; 2] {
        [
            self.mode + EULER_GAMMA * self.scale,
            self.scale * PI / 6f64.sqrt(),
        ]
    }
    pub(crate) fn with_moments(mean: f64, std: f64) -> Result<Gumbel, ReliabilityError> {
        let scale = std * 6f64.sqrt() / PI;
        Gumbel::new(mean - EULER_GAMMA * scale, scale)
    }
    pub(crate) fn x(&self, u: f64) -> f64 {
        self.mode - self.scale * gumbel_t(u).ln()
    }
    pub(crate) fn u(&self, x: f64) -> f64 {
        let e = (-(x - self.mode) / self.scale).exp();
        u_of((-e).exp(), -libm::expm1(-e))
    }
    pub(crate) fn pdf(&self, x: f64) -> f64 {
        let y = (x - self.mode) / self.scale;
        (-(y + (-y).exp())).exp() / self.scale
    }
    /// `dw/du = r/t`, `r = φ(u)/Φ(u)`.
    pub(crate) fn dx_du(&self, u: f64) -> f64 {
        self.scale * normal::pdf(u) / normal::cdf(u) / gumbel_t(u)
    }
    /// `d²w/du² = (r² − r·(u + r)·t)/t²` (`r' = −r·(u + r)`).
    pub(crate) fn d2x_du2(&self, u: f64) -> f64 {
        let (r, t) = (normal::pdf(u) / normal::cdf(u), gumbel_t(u));
        self.scale * (r * r - r * (u + r) * t) / (t * t)
    }
    /// Location-scale: `∂x/∂σ = (x − mean)/σ = (√6/π)·(w − γ)`.
    pub(crate) fn dx_dstd(&self, u: f64) -> f64 {
        6f64.sqrt() / PI * (-gumbel_t(u).ln() - EULER_GAMMA)
    }
}

// --------------------------------------------------------------- triangular

/// Triangular on `[a, b]` with mode `c`: `x = a + √(p·(b − a)(c − a))` for
/// `p = Φ(u) ≤ (c − a)/(b − a)`, else `x = b − √(q·(b − a)(b − c))`,
/// `q = Φ(−u)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub(crate) struct Triangular {
    pub(crate) min: f64,
    pub(crate) mode: f64,
    pub(crate) max: f64,
}

impl Triangular {
    pub(crate) fn new(min: f64, mode: f64, max: f64) -> Result<Triangular, ReliabilityError> {
        if !(min.is_finite() && mode.is_finite() && max.is_finite())
            || min >= max
            || mode < min
            || mode > max
        {
            return Err(invalid(format!(
                "triangular(min {min}, mode {mode}, max {max}): needs finite values with min ≤ mode ≤ max and min < max"
            )));
        }
        Ok(Triangular { min, mode, max })
    }
    pub(crate) fn moments(&self) -> [f64; 2] {
        let (a, c, b) = (self.min, self.mode, self.max);
        [
            (a + b + c) / 3.0,
            ((a * a + b * b + c * c - a * b - a * c - b * c) / 18.0).sqrt(),
        ]
    }
    /// Translated and scaled about its mean (the shape held).
    pub(crate) fn with_moments(&self, mean: f64, std: f64) -> Result<Triangular, ReliabilityError> {
        let [m, s] = self.moments();
        let f = |v: f64| mean + (v - m) * std / s;
        Triangular::new(f(self.min), f(self.mode), f(self.max))
    }
    fn lower(&self, p: f64) -> bool {
        p * (self.max - self.min) < self.mode - self.min
    }
    pub(crate) fn x(&self, u: f64) -> f64 {
        let (a, c, b) = (self.min, self.mode, self.max);
        let (p, q) = (normal::cdf(u), normal::sf(u));
        // Away from its own end, each branch is written without the
        // cancellation of `b − √(q·K₂)` at `q ≈ 1`:
        // `x − a = (b − a)·((c − a) + p·(b − c))/((b − a) + √(q·K₂))`.
        if self.lower(p) {
            let r = (p * (b - a) * (c - a)).sqrt();
            if p <= 0.5 {
                a + r
            } else {
                b - (b - a) * ((b - c) + q * (c - a)) / ((b - a) + r)
            }
        } else {
            let r = (q * (b - a) * (b - c)).sqrt();
            if q <= 0.5 {
                b - r
            } else {
                a + (b - a) * ((c - a) + p * (b - c)) / ((b - a) + r)
            }
        }
    }
    pub(crate) fn u(&self, x: f64) -> f64 {
        let (a, c, b) = (self.min, self.mode, self.max);
        if x <= a {
            return f64::NEG_INFINITY;
        }
        if x >= b {
            return f64::INFINITY;
        }
        // Both tails as sums of positive terms:
        // `1 − F = ((c − a)(b − c) + (c − x)((c − a) + (x − a)))/((b − a)(c − a))`
        // below the mode, `F = ((b − c)(c − a) + (x − c)((b − c) + (b − x)))/((b − a)(b − c))`
        // above.
        if x <= c {
            let k = (b - a) * (c - a);
            let p = (x - a) * (x - a) / k;
            let q = ((c - a) * (b - c) + (c - x) * ((c - a) + (x - a))) / k;
            u_of(p, q)
        } else {
            let k = (b - a) * (b - c);
            let q = (b - x) * (b - x) / k;
            let p = ((b - c) * (c - a) + (x - c) * ((b - c) + (b - x))) / k;
            u_of(p, q)
        }
    }
    pub(crate) fn pdf(&self, x: f64) -> f64 {
        let (a, c, b) = (self.min, self.mode, self.max);
        if x < a || x > b {
            0.0
        } else if x < c {
            2.0 * (x - a) / ((b - a) * (c - a))
        } else if x > c {
            2.0 * (b - x) / ((b - a) * (b - c))
        } else {
            2.0 / (b - a)
        }
    }
    pub(crate) fn dx_du(&self, u: f64) -> f64 {
        let (a, c, b) = (self.min, self.mode, self.max);
        let (p, f) = (normal::cdf(u), normal::pdf(u));
        if self.lower(p) {
            ((b - a) * (c - a)).sqrt() * f / (2.0 * p.sqrt())
        } else {
            ((b - a) * (b - c)).sqrt() * f / (2.0 * normal::sf(u).sqrt())
        }
    }
    pub(crate) fn d2x_du2(&self, u: f64) -> f64 {
        let (a, c, b) = (self.min, self.mode, self.max);
        let (p, f) = (normal::cdf(u), normal::pdf(u));
        if self.lower(p) {
            ((b - a) * (c - a)).sqrt() / 2.0 * (-u * f / p.sqrt() - f * f / (2.0 * p.powf(1.5)))
        } else {
            let q = normal::sf(u);
            ((b - a) * (b - c)).sqrt() / 2.0 * (-u * f / q.sqrt() + f * f / (2.0 * q.powf(1.5)))
        }
    }
}

// ----------------------------------------------------------------- rayleigh

/// `√(π/2)`, the mean of the standard Rayleigh.
const RAYLEIGH_MEAN: f64 = 1.253_314_137_315_500_3;
/// `√((4 − π)/2)`, its standard deviation.
const RAYLEIGH_STD: f64 = 0.655_136_377_562_033_6;

/// Rayleigh: `x = shift + σ·√(2t)`, `t = −ln(1 − Φ(u))` (a Weibull with
/// `λ = σ√2`, `k = 2`); mean `shift + σ√(π/2)`, std `σ√((4 − π)/2)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub(crate) struct Rayleigh {
    pub(crate) scale: f64,
    pub(crate) shift: f64,
}

impl Rayleigh {
    pub(crate) fn new(scale: f64, shift: f64) -> Result<Rayleigh, ReliabilityError> {
        if !(scale.is_finite() && shift.is_finite()) || scale <= 0.0 {
            return Err(invalid(format!(
                "rayleigh(scale {scale}, shift {shift}): needs finite values and scale > 0"
            )));
        }
        Ok(Rayleigh { scale, shift })
    }
    pub(crate) fn moments(&self) -> [f64; 2] {
        [
            self.shift + self.scale * RAYLEIGH_MEAN,
            self.scale * RAYLEIGH_STD,
        ]
    }
    /// Scale from the std, the shift from the mean (the shape held).
    pub(crate) fn with_moments(mean: f64, std: f64) -> Result<Rayleigh, ReliabilityError> {
        let scale = std / RAYLEIGH_STD;
        Rayleigh::new(scale, mean - scale * RAYLEIGH_MEAN)
    }
    pub(crate) fn x(&self, u: f64) -> f64 {
        self.shift + self.scale * (2.0 * cum_hazard(u)).sqrt()
    }
    pub(crate) fn u(&self, x: f64) -> f64 {
        if x <= self.shift {
            return f64::NEG_INFINITY;
        }
        let t = 0.5 * ((x - self.shift) / self.scale).powi(2);
        u_of(-libm::expm1(-t), (-t).exp())
    }
    pub(crate) fn pdf(&self, x: f64) -> f64 {
        if x <= self.shift {
            return 0.0;
        }
        let y = (x - self.shift) / self.scale;
        y / self.scale * (-0.5 * y * y).exp()
    }
    /// `dx/du = σ·h/√(2t)`.
    pub(crate) fn dx_du(&self, u: f64) -> f64 {
        self.scale * hazard(u) / (2.0 * cum_hazard(u)).sqrt()
    }
    /// `d²x/du² = (σ/√2)·[−½·t^{−3/2}·h² + t^{−1/2}·h·(h − u)]`.
    pub(crate) fn d2x_du2(&self, u: f64) -> f64 {
        let (t, h) = (cum_hazard(u), hazard(u));
        self.scale / SQRT_2 * (-0.5 * t.powf(-1.5) * h * h + h * (h - u) / t.sqrt())
    }
    /// Location-scale: `∂x/∂σ_x = (√(2t) − √(π/2))/√((4 − π)/2)`.
    pub(crate) fn dx_dstd(&self, u: f64) -> f64 {
        ((2.0 * cum_hazard(u)).sqrt() - RAYLEIGH_MEAN) / RAYLEIGH_STD
    }
}
