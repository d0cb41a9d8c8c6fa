//! Reliability sensitivity: `∂R/∂μ_j`, `∂R/∂σ_j` and the FORM importance
//! factors (the paper's Section 3.2, Eq. 32-33).
//!
//! Eq. 32 chains the derivative through the linearised margin
//! `Z_L` with mean `μ_ZL` and standard deviation `σ_ZL`:
//!
//! - `∂R/∂μ_j = ∂R/∂β · ∂β/∂μ_ZL · ∂μ_ZL/∂μ_j`,
//! - `∂R/∂σ_j = ∂R/∂β · ∂β/∂σ_ZL · ∂σ_ZL/∂σ_j`,
//!
//! with (Eq. 33) `∂R/∂β = φ(β)`, `∂β/∂μ_ZL = 1/σ_ZL`,
//! `∂β/∂σ_ZL = −μ_ZL/σ_ZL²`. For the tolerance limit state `Z = I − S·e`
//! in normal inputs, `∂μ_ZL/∂μ_j = −S_j` and `∂σ_ZL/∂σ_j = S_j²σ_j/σ_ZL`:
//! this is [`SensitivityMethod::Exact`], exact because `R = Φ(β)` is. A
//! two-sided tolerance in normal inputs also has an exact closed form,
//! `R = Φ((I − m)/s) − Φ((−I − m)/s)`, differentiated the same way.
//!
//! With correlated normal inputs (`x_B = μ_B + D_B·L·u_B`) the derivatives
//! are taken with the correlation matrix `R` held fixed: `σ_ZL² = SᵀD R D S`
//! gives `∂σ_ZL/∂σ_j = S_j·(R D S)_j/σ_ZL`, and at fixed `u`
//! `∂x_j/∂σ_j = (L·u_B)_j` ([`crate::Inputs::dx_dstd`]). The importance
//! factors are then Der Kiureghian's `γ_j²` ([`crate::Inputs::importance`]).
//!
//! Otherwise ([`SensitivityMethod::Form`]) the derivative of the FORM index
//! at the design point `u*` of the nearest branch is used:
//! `∂β/∂θ = (∂g(T(u*; θ))/∂θ) / |∇_u g(u*)|`, and `∂R/∂θ = φ(β)·∂β/∂θ`.

use chain_core::model::Sided;
use serde::Serialize;

use crate::error::ReliabilityError;
use crate::form::FormResult;
use crate::limit_state::{Criterion, Event, LimitState};
use crate::normal;

/// How the derivatives were obtained.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum SensitivityMethod {
    /// Closed form (one component, normal inputs).
    Exact,
    /// The FORM design point.
    Form,
}

impl SensitivityMethod {
    /// `exact` or `form`, as serialised.
    pub fn name(self) -> &'static str {
        match self {
            SensitivityMethod::Exact => "exact",
            SensitivityMethod::Form => "form",
        }
    }
}

/// The sensitivities of one input.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct InputSensitivity {
    /// `∂R/∂μ_j`.
    pub dr_dmean: f64,
    /// `∂R/∂σ_j`.
    pub dr_dstd: f64,
    /// The FORM importance factor `α_j²`.
    pub importance: f64,
}

/// The sensitivities of one event.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SensitivityResult {
    /// The reliability the derivatives are of (exact or FORM).
    pub reliability: f64,
    /// How they were obtained.
    pub method: SensitivityMethod,
    /// One entry per input, in input order.
    pub inputs: Vec<InputSensitivity>,
}

/// The reliability sensitivities of an event, given its FORM result.
///
/// ```
/// use reliability::{sensitivity, Event, Form, Inputs, Marginal, ToleranceLimitState};
/// use chain_core::model::Sided;
/// let inputs = Inputs::new(vec!["e".into()], vec![Marginal::normal(0.0, 0.01).unwrap()]).unwrap();
/// let event = Event::new(&inputs, ToleranceLimitState::component(vec![1.0], 0.03, Sided::Upper).unwrap()).unwrap();
/// let s = sensitivity(&event, &Form::default().run(&event).unwrap()).unwrap();
/// // R = Φ(0.03/σ): ∂R/∂σ = −φ(3)·3/σ.
/// let expected = -reliability::normal::pdf(3.0) * 3.0 / 0.01;
/// assert!((s.inputs[0].dr_dstd / expected - 1.0).abs() < 1e-12);
/// ```
pub fn sensitivity<L: LimitState>(
    event: &Event<'_, L>,
    form: &FormResult,
) -> Result<SensitivityResult, ReliabilityError> {
    let n = event.inputs.len();
    if form.alpha.len() != n {
        return Err(ReliabilityError::Dimension {
            what: "FORM result",
            expected: n,
            found: form.alpha.len(),
        });
    }
    let importance = |j: usize| form.importance[j];
    if let Some(aff) = event.affine() {
        let ls = aff.view;
        if ls.components() == 1 {
            if let Criterion::Each(sided) = ls.criterion() {
                let row = ls.row(0);
                let s = aff.std(0);
                let m = aff.mean[0];
                let i = ls.tolerances()[0];
                let stds = event.inputs.stds();
                let (reliability, dr_dm, dr_ds) = if s > 0.0 {
                    match sided {
                        Sided::Upper => {
                            // Eq. 32-33 with μ_ZL = I − m, σ_ZL = s.
                            let mu_z = i - m;
                            let beta = mu_z / s;
                            let phi = normal::pdf(beta);
                            (normal::cdf(beta), -phi / s, -phi * mu_z / (s * s))
                        }
                        Sided::Two => {
                            let b1 = (i - m) / s;
                            let b2 = (-i - m) / s;
                            let (p1, p2) = (normal::pdf(b1), normal::pdf(b2));
                            (
                                normal::interval(b2, b1),
                                (-p1 + p2) / s,
                                (-p1 * b1 + p2 * b2) / s,
                            )
                        }
                    }
                } else {
                    let safe = match sided {
                        Sided::Upper => m < i,
                        Sided::Two => m.abs() < i,
                    };
                    (if safe { 1.0 } else { 0.0 }, 0.0, 0.0)
                };
                let inputs = (0..n)
                    .map(|j| InputSensitivity {
                        // ∂m/∂μ_j = S_j; ∂s/∂σ_j = S_j²σ_j/s, and with
                        // correlated normals (R fixed) S_j·(R·D·S)_j/s.
                        dr_dmean: dr_dm * row[j],
                        dr_dstd: if s <= 0.0 {
                            0.0
                        } else if event.inputs.is_correlated(j) {
                            dr_ds * row[j] * event.inputs.covariance_weight(row, j) / s
                        } else {
                            dr_ds * row[j] * row[j] * stds[j] / s
                        },
                        importance: importance(j),
                    })
                    .collect();
                return Ok(SensitivityResult {
                    reliability,
                    method: SensitivityMethod::Exact,
                    inputs,
                });
            }
        }
    }
    // The FORM route at the nearest branch's design point.
    let mut grad = vec![0.0; n];
    let beta = form.beta;
    let usable = beta.is_finite() && form.gradient_norm > 0.0;
    if usable {
        event
            .limit_state
            .branch(form.branch, &form.design_point_x, Some(&mut grad));
    }
    let phi = if usable { normal::pdf(beta) } else { 0.0 };
    let scale = if usable {
        phi / form.gradient_norm
    } else {
        0.0
    };
    let u = &form.design_point_u;
    let inputs = event
        .inputs
        .marginals()
        .iter()
        .enumerate()
        .map(|(j, _)| InputSensitivity {
            dr_dmean: scale * grad[j] * event.inputs.dx_dmean(j, u),
            dr_dstd: scale * grad[j] * event.inputs.dx_dstd(j, u),
            importance: importance(j),
        })
        .collect();
    Ok(SensitivityResult {
        reliability: form.reliability,
        method: SensitivityMethod::Form,
        inputs,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::form::Form;

    #[test]
    fn method_names_are_the_serialised_ones() {
        for m in [SensitivityMethod::Exact, SensitivityMethod::Form] {
            assert_eq!(serde_json::to_value(m).unwrap(), m.name());
        }
    }
    use crate::inputs::{Inputs, Marginal};
    use crate::limit_state::ToleranceLimitState;

    fn form_reliability(inputs: &Inputs, ls: &ToleranceLimitState) -> f64 {
        let e = Event::new(inputs, ls.clone()).unwrap();
        Form::default().run(&e).unwrap().reliability
    }

    #[test]
    fn form_route_matches_central_differences() {
        // Volumetric ‖(e0, e1)‖ ≤ 0.05 with a uniform and a normal input: the
        // FORM route (∂β/∂θ = ∂g/∂θ / |∇_u g| at u*) against central
        // differences of the FORM reliability.
        let inputs = crate::util::fixtures::inputs(vec![
            Marginal::uniform(-0.02, 0.03).unwrap(),
            Marginal::normal(0.004, 0.015).unwrap(),
        ]);
        let ls = ToleranceLimitState::new(2, vec![1.0, 0.3, 0.2, 1.0], vec![0.05], Criterion::Norm)
            .unwrap();
        let e = Event::new(&inputs, ls.clone()).unwrap();
        let f = Form::default().run(&e).unwrap();
        let s = sensitivity(&e, &f).unwrap();
        assert_eq!(s.method, SensitivityMethod::Form);
        for j in 0..2 {
            let (mu, sd) = (inputs.means()[j], inputs.stds()[j]);
            let h = 1e-5 * sd;
            let r = |m: f64, s: f64| form_reliability(&inputs.with_moments(j, m, s).unwrap(), &ls);
            let fd_std = (r(mu, sd + h) - r(mu, sd - h)) / (2.0 * h);
            let fd_mean = (r(mu + h, sd) - r(mu - h, sd)) / (2.0 * h);
            let a = s.inputs[j];
            assert!(
                (a.dr_dstd - fd_std).abs() <= 1e-5 * fd_std.abs(),
                "{j}: {} vs {fd_std}",
                a.dr_dstd
            );
            assert!(
                (a.dr_dmean - fd_mean).abs() <= 1e-5 * fd_mean.abs(),
                "{j}: {} vs {fd_mean}",
                a.dr_dmean
            );
        }
    }
}
