//! The workflow of one measurement file: `Δθ` per point (Eq. 5), the fits of
//! every order, the selected order and the law, with the residual predicted
//! after compensation.

use serde::Serialize;

use super::fit::distinct_count;
use super::law::{acos_argument, polynomial_text, swing_angle_error_deg, theoretical_drop};
use super::{
    fit_polynomial, CompensateError, Compensation, Measurements, PolyFit, Selection, SelectionRule,
    MAX_SUPPORTED_ORDER,
};

/// Settings of [`analyze`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// Distance `L` from the rotation centre to the tool tip (mm).
    pub length: f64,
    /// Lowest order fitted (the seed: 2).
    pub min_order: usize,
    /// Highest order fitted (the seed: 6).
    pub max_order: usize,
    /// Rule that selects the order of the law.
    pub rule: SelectionRule,
    /// An order to use instead of the rule's choice (must be fitted).
    pub fixed_order: Option<usize>,
}

impl Options {
    /// The seed's settings for a given length: orders 2 to 6, selected by
    /// leave-one-out cross-validation.
    pub fn new(length: f64) -> Self {
        Options {
            length,
            min_order: 2,
            max_order: 6,
            rule: SelectionRule::Loocv,
            fixed_order: None,
        }
    }
}

/// One processed measurement (a row of the seed's Table 2, and more).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Point {
    /// Commanded angle `θ` (degrees).
    pub theta_deg: f64,
    /// Swing-angle error `Δθ` (degrees, Eq. 5).
    pub delta_theta_deg: f64,
    /// Line of the row in its file.
    pub line: u64,
    /// Reference height `Z1` (mm).
    pub z1: f64,
    /// Theoretical height `Z2` as given in the file (mm).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub z2: Option<f64>,
    /// Measured height `Z3` (mm).
    pub z3: f64,
    /// Measured drop `h' = Z1 − Z3` (mm, Eq. 2).
    pub z1_minus_z3: f64,
    /// `Z1 − Z2` from the file's `z2` (mm).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub z1_minus_z2: Option<f64>,
    /// `Z2 − Z3` from the file's `z2` (mm).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub z2_minus_z3: Option<f64>,
    /// Theoretical drop `h = L(1 − cos θ)` (mm, Eq. 1).
    pub h_mm: f64,
    /// `ΔZ = Z2 − Z3` with the theoretical `Z2 = Z1 − h` (mm, Eq. 3); the
    /// value Eq. 5 uses.
    pub delta_z_mm: f64,
    /// The selected law's `Δθ(θ)` (degrees).
    pub fitted_deg: f64,
    /// `Δθ − Δθ(θ)`: the error predicted to remain after compensation (degrees).
    pub residual_deg: f64,
}

/// Minimum, maximum and root-mean-square of a set of angle errors.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Spread {
    /// Smallest value (degrees).
    pub min_deg: f64,
    /// Largest value (degrees).
    pub max_deg: f64,
    /// Largest absolute value (degrees).
    pub max_abs_deg: f64,
    /// Root mean square about zero (degrees).
    pub rms_deg: f64,
}

impl Spread {
    /// The spread of `values` (all zeros for an empty slice).
    pub fn of(values: &[f64]) -> Spread {
        if values.is_empty() {
            return Spread {
                min_deg: 0.0,
                max_deg: 0.0,
                max_abs_deg: 0.0,
                rms_deg: 0.0,
            };
        }
        let min_deg = values.iter().copied().fold(f64::INFINITY, f64::min);
        let max_deg = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let rms_deg = (values.iter().map(|v| v * v).sum::<f64>() / values.len() as f64).sqrt();
        Spread {
            min_deg,
            max_deg,
            max_abs_deg: min_deg.abs().max(max_deg.abs()),
            rms_deg,
        }
    }
}

/// The swing-angle error before and (predicted) after compensation, at the
/// measured angles.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ResidualSummary {
    /// The measured `Δθ`.
    pub before: Spread,
    /// The residuals `Δθ − Δθ(θ)` of the law at the measured angles.
    pub after: Spread,
    /// Leave-one-out RMS of the law: the residual to expect at an angle whose
    /// measurement did not shape the law (degrees).
    pub loocv_rms_deg: f64,
}

/// Everything [`analyze`] derives from a measurement file.
///
/// Serialises to the `chain compensate --format json` document: `length`,
/// `points`, `fits`, `selected_order` as the spec fixes them, then `selection`,
/// `compensation` and `file`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Analysis {
    /// `L` (mm).
    pub length: f64,
    /// The processed points in file order.
    pub points: Vec<Point>,
    /// One fit per order, ascending.
    pub fits: Vec<PolyFit>,
    /// Order of the compensation law.
    pub selected_order: usize,
    /// How the order was selected.
    pub selection: Selection,
    /// The compensation law.
    pub compensation: Compensation,
    /// The source file.
    pub file: String,
}

impl Analysis {
    /// The fit of `order`, if it was fitted.
    pub fn fit(&self, order: usize) -> Option<&PolyFit> {
        self.fits.iter().find(|f| f.order == order)
    }

    /// Smallest and largest measured angle (degrees).
    pub fn angle_range(&self) -> [f64; 2] {
        self.compensation.fitted_range_deg
    }
}

/// The longest swing arm `L` (mm) accepted: 1 km, far beyond any machine,
/// and small enough that `L·(1 − cos θ)` and its derivatives stay finite.
pub const MAX_LENGTH_MM: f64 = 1e6;

/// Processes measurements: `Δθ` per point (Eq. 5), least-squares fits of
/// orders `min_order..=max_order`, the selected order and the law.
pub fn analyze(m: &Measurements, options: &Options) -> Result<Analysis, CompensateError> {
    let file = m.source.clone();
    let length = options.length;
    if !(length > 0.0 && length <= MAX_LENGTH_MM) {
        return Err(CompensateError::InvalidLength { length });
    }
    if options.min_order > options.max_order {
        return Err(CompensateError::InvalidOrders {
            message: format!(
                "--min-order {} is above --max-order {}",
                options.min_order, options.max_order
            ),
        });
    }
    if options.max_order > MAX_SUPPORTED_ORDER {
        return Err(CompensateError::InvalidOrders {
            message: format!(
                "--max-order {} is above the supported maximum {MAX_SUPPORTED_ORDER}",
                options.max_order
            ),
        });
    }
    if let Some(order) = options.fixed_order {
        if order < options.min_order || order > options.max_order {
            return Err(CompensateError::InvalidOrders {
                message: format!(
                    "--order {order} is not among the fitted orders {}..={}",
                    options.min_order, options.max_order
                ),
            });
        }
    }
    let first = m.records.first().ok_or_else(|| CompensateError::NoData {
        file: file.clone(),
        header_line: m.header_line,
    })?;
    let (first_line, last_line) = (first.line, m.records.last().map_or(first.line, |r| r.line));

    let mut delta = Vec::with_capacity(m.records.len());
    for r in &m.records {
        let d = swing_angle_error_deg(r.theta_deg, r.z1, r.z3, length).ok_or_else(|| {
            CompensateError::AcosDomain {
                file: file.clone(),
                line: r.line,
                theta_deg: r.theta_deg,
                drop: r.z1 - r.z3,
                length,
                argument: acos_argument(r.z1, r.z3, length),
            }
        })?;
        delta.push(d);
    }
    let theta: Vec<f64> = m.records.iter().map(|r| r.theta_deg).collect();
    let distinct = distinct_count(&theta);
    if distinct < options.max_order + 2 {
        return Err(CompensateError::TooFewPoints {
            file,
            first_line,
            last_line,
            order: options.max_order,
            needed: options.max_order + 2,
            got: distinct,
        });
    }
    let fits = (options.min_order..=options.max_order)
        .map(|order| fit_polynomial(&theta, &delta, order))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|source| CompensateError::Fit {
            file: file.clone(),
            source,
        })?;
    let by_rule: std::collections::BTreeMap<String, usize> = SelectionRule::ALL
        .iter()
        .filter_map(|r| r.select(&fits).map(|o| (r.name().to_string(), o)))
        .collect();
    let (selected_order, selection) = match options.fixed_order {
        Some(order) => (
            order,
            Selection {
                rule: "fixed".to_string(),
                description: format!("order {order} imposed by the user"),
                by_rule,
            },
        ),
        None => {
            let order = options.rule.select(&fits).ok_or_else(|| CompensateError::InvalidOrders {
                message: format!(
                    "rule `{}` is undefined for every fitted order (too few points for it); choose another rule or lower --max-order",
                    options.rule
                ),
            })?;
            (
                order,
                Selection {
                    rule: options.rule.name().to_string(),
                    description: options.rule.description().to_string(),
                    by_rule,
                },
            )
        }
    };
    let fit = fits
        .iter()
        .find(|f| f.order == selected_order)
        .cloned()
        .ok_or_else(|| CompensateError::InvalidOrders {
            message: format!("order {selected_order} was not fitted"),
        })?;

    let points: Vec<Point> = m
        .records
        .iter()
        .zip(&delta)
        .map(|(r, &d)| {
            let h = theoretical_drop(r.theta_deg, length);
            let fitted = fit.eval(r.theta_deg);
            Point {
                theta_deg: r.theta_deg,
                delta_theta_deg: d,
                line: r.line,
                z1: r.z1,
                z2: r.z2,
                z3: r.z3,
                z1_minus_z3: r.z1 - r.z3,
                z1_minus_z2: r.z2.map(|z2| r.z1 - z2),
                z2_minus_z3: r.z2.map(|z2| z2 - r.z3),
                h_mm: h,
                delta_z_mm: (r.z1 - r.z3) - h,
                fitted_deg: fitted,
                residual_deg: d - fitted,
            }
        })
        .collect();
    let residuals: Vec<f64> = points.iter().map(|p| p.residual_deg).collect();
    let lo = theta.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = theta.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let compensation = Compensation {
        order: fit.order,
        coefficients: fit.coefficients.clone(),
        law: format!("delta_theta = {}", polynomial_text(&fit.coefficients, "theta")),
        usage: "theta and delta_theta in degrees; commanding theta_t leaves the axis at theta_a = theta_t + delta_theta(theta_t) (Eq. 7); to reach theta_t, command the c with c + delta_theta(c) = theta_t (about theta_t - delta_theta(theta_t))".to_string(),
        fitted_range_deg: [lo, hi],
        residual: ResidualSummary {
            before: Spread::of(&delta),
            after: Spread::of(&residuals),
            loocv_rms_deg: fit.loocv_rmse,
        },
        fit,
    };
    Ok(Analysis {
        length,
        points,
        fits,
        selected_order,
        selection,
        compensation,
        file,
    })
}
