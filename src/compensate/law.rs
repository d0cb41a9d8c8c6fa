//! The seed's equations: the swing-angle error of one measurement (Eq. 1-5)
//! and the compensation law built on the selected fit (Eq. 7).

use serde::Serialize;

use super::{PolyFit, ResidualSummary};

/// Theoretical drop of the tool tip `h = L(1 − cos θ)` (Eq. 1), in the units of
/// `length`, evaluated as `2L sin²(θ/2)`.
pub fn theoretical_drop(theta_deg: f64, length: f64) -> f64 {
    let s = (theta_deg.to_radians() / 2.0).sin();
    2.0 * length * s * s
}

/// The argument `cos θ − ΔZ/L` of Eq. 5 for a measured drop `z1 − z3`, with
/// `ΔZ = Z2 − Z3` and the theoretical `Z2 = Z1 − L(1 − cos θ)`; it equals
/// `1 − (z1 − z3)/L` whatever `θ`.
pub fn acos_argument(z1: f64, z3: f64, length: f64) -> f64 {
    1.0 - (z1 - z3) / length
}

/// Swing-angle error `Δθ` (degrees) from the commanded angle `θ` (degrees), the
/// reference height `z1` and the measured height `z3` (Eq. 5 with the
/// theoretical `Z2`).
///
/// Evaluated as `2 asin(√((z1 − z3)/(2L))) − θ`, which equals
/// `acos(cos θ − ΔZ/L) − θ` but keeps full precision at small angles. Returns
/// `None` when `cos θ − ΔZ/L` is outside `[−1, 1]` (the drop `z1 − z3` is
/// outside `[0, 2L]`) or `length` is not positive.
pub fn swing_angle_error_deg(theta_deg: f64, z1: f64, z3: f64, length: f64) -> Option<f64> {
    if !(length > 0.0 && length.is_finite()) {
        return None;
    }
    let half_ratio = (z1 - z3) / (2.0 * length);
    if !(0.0..=1.0).contains(&half_ratio) {
        return None;
    }
    let actual = 2.0 * half_ratio.sqrt().asin();
    Some(actual.to_degrees() - theta_deg)
}

/// Eq. 5 as printed, `Δθ = acos(cos θ − ΔZ/L) − θ` (degrees), for an explicit
/// `ΔZ = Z2 − Z3` (mm). Returns `None` when the argument of `acos` is outside
/// `[−1, 1]`.
pub fn swing_angle_error_from_delta_z_deg(
    theta_deg: f64,
    delta_z: f64,
    length: f64,
) -> Option<f64> {
    let argument = theta_deg.to_radians().cos() - delta_z / length;
    if !(-1.0..=1.0).contains(&argument) {
        return None;
    }
    Some(argument.acos().to_degrees() - theta_deg)
}

// ---------------------------------------------------------------------------
// The law (Eq. 7)
// ---------------------------------------------------------------------------

/// The compensation law: the selected polynomial `Δθ(θ)` and its use.
///
/// Commanding `θt` leaves the axis at `θa = θt + Δθ(θt)` (Eq. 7); the command
/// that reaches a target `θt` is the `c` with `c + Δθ(c) = θt`
/// ([`Compensation::command_deg`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Compensation {
    /// Order of the law.
    pub order: usize,
    /// Coefficients of `Δθ(θ)` in ascending powers of `θ`, both in degrees.
    pub coefficients: Vec<f64>,
    /// The law as text (`delta_theta = … ` in powers of `theta`, degrees).
    pub law: String,
    /// What the law means for the axis and for the command.
    pub usage: String,
    /// Range of measured angles the law was fitted on (degrees).
    pub fitted_range_deg: [f64; 2],
    /// The error before and after compensation.
    pub residual: ResidualSummary,
    #[serde(skip)]
    pub(super) fit: PolyFit,
}

impl Compensation {
    /// The law's swing-angle error `Δθ(θ)` (degrees) at commanded angle `θ`.
    pub fn delta_theta_deg(&self, theta_deg: f64) -> f64 {
        self.fit.eval(theta_deg)
    }

    /// The angle the axis reaches when `θt` is commanded: `θt + Δθ(θt)` (Eq. 7).
    pub fn actual_deg(&self, commanded_deg: f64) -> f64 {
        commanded_deg + self.fit.eval(commanded_deg)
    }

    /// The command `c` that makes the axis reach `target_deg`: the solution of
    /// `c + Δθ(c) = target` nearest `target − Δθ(target)` (Newton). `None` if
    /// `1 + dΔθ/dθ` is not positive on the way or Newton does not converge.
    pub fn command_deg(&self, target_deg: f64) -> Option<f64> {
        if !target_deg.is_finite() {
            return None;
        }
        let mut c = target_deg - self.fit.eval(target_deg);
        for _ in 0..100 {
            let g = c + self.fit.eval(c) - target_deg;
            let slope = 1.0 + self.fit.derivative(c);
            if slope.is_nan() || slope <= 1e-6 || !c.is_finite() {
                return None;
            }
            if g.abs() <= 1e-13 * (1.0 + target_deg.abs()) {
                return Some(c);
            }
            c -= g / slope;
        }
        None
    }

    /// The polynomial fit behind the law.
    pub fn fit(&self) -> &PolyFit {
        &self.fit
    }
}

/// A polynomial in ascending coefficients as text readable by SymPy and
/// MATLAB, e.g. `0.18 - 0.0295*theta + 0.00231*theta^2`.
pub fn polynomial_text(coefficients: &[f64], variable: &str) -> String {
    let mut out = String::new();
    for (k, &c) in coefficients.iter().enumerate() {
        let magnitude = format!("{:.6e}", c.abs());
        let term = match k {
            0 => magnitude,
            1 => format!("{magnitude}*{variable}"),
            _ => format!("{magnitude}*{variable}^{k}"),
        };
        if out.is_empty() {
            if c < 0.0 {
                out.push('-');
            }
            out.push_str(&term);
        } else {
            out.push_str(if c < 0.0 { " - " } else { " + " });
            out.push_str(&term);
        }
    }
    if out.is_empty() {
        out.push('0');
    }
    out
}
