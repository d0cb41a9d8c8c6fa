//! A model at a thermal state (`docs/thermal.md`, "Temperature in the
//! machine model"): the error of a machine with sensors is
//! `E(q, T) = Σ_j c_j(q) · g_j(T) · e_j`, where `c_j(q)` are the geometric
//! model's coefficients and `g_j(T)` the thermal factor of error `j`
//! ([`crate::Machine::thermal_factors`]: `T_s − reference_s` for a thermal
//! coefficient of sensor `s`, 1 otherwise). The state acts on the values
//! side, so the derivation, the generated kernels and the tape are those of
//! the geometry; [`AtState`] applies the factors to any [`ErrorModel`] (the
//! columns of its sensitivity, the values of its errors), and
//! [`crate::values::Values::at_thermal_state`] to a built machine's values.

use crate::model_trait::{BatchError, ErrorModel, Pose};

/// An [`ErrorModel`] at a thermal state: `model`'s sensitivity with column
/// `j` multiplied by `factors[j]`, its error of `e` that of `f ∘ e`.
#[derive(Debug, Clone)]
pub struct AtState<M> {
    model: M,
    factors: Vec<f64>,
    /// Every factor 1 (the reference state): nothing to scale.
    identity: bool,
}

impl<M: ErrorModel> AtState<M> {
    /// `model` at the state whose factors are `factors` (one per error of
    /// the model, in its order; missing ones are 1).
    pub fn new(model: M, mut factors: Vec<f64>) -> AtState<M> {
        factors.resize(model.errors().len(), 1.0);
        let identity = factors.iter().all(|f| *f == 1.0);
        AtState {
            model,
            factors,
            identity,
        }
    }

    /// The model at the reference state.
    pub fn inner(&self) -> &M {
        &self.model
    }

    /// The factors, one per error.
    pub fn factors(&self) -> &[f64] {
        &self.factors
    }

    /// Multiplies every `6 × N` matrix in `out` column by column.
    fn scale_matrices(&self, out: &mut [f64]) {
        let n = self.factors.len();
        if self.identity || n == 0 {
            return;
        }
        for row in out.chunks_exact_mut(n) {
            for (v, f) in row.iter_mut().zip(&self.factors) {
                *v *= f;
            }
        }
    }
}

impl<M: ErrorModel> ErrorModel for AtState<M> {
    fn variables(&self) -> &[&str] {
        self.model.variables()
    }

    fn parameters(&self) -> &[&str] {
        self.model.parameters()
    }

    fn errors(&self) -> &[&str] {
        self.model.errors()
    }

    fn error(&self, q: &[f64], p: &[f64], e: &[f64], out: &mut [f64; 6]) {
        if self.identity {
            return self.model.error(q, p, e, out);
        }
        let scaled: Vec<f64> = e.iter().zip(&self.factors).map(|(e, f)| e * f).collect();
        self.model.error(q, p, &scaled, out);
    }

    fn sensitivity(&self, q: &[f64], p: &[f64], out: &mut [f64]) {
        self.model.sensitivity(q, p, out);
        self.scale_matrices(out);
    }

    fn sparsity(&self) -> Option<&[(usize, usize)]> {
        self.model.sparsity()
    }

    fn sensitivity_nonzeros(&self, q: &[f64], p: &[f64], out: &mut [f64]) -> bool {
        if !self.model.sensitivity_nonzeros(q, p, out) {
            return false;
        }
        if let Some(nonzeros) = self.model.sparsity() {
            for (v, (_, j)) in out.iter_mut().zip(nonzeros) {
                *v *= self.factors.get(*j).copied().unwrap_or(1.0);
            }
        }
        true
    }

    fn sensitivity_points(&self, qs: &[f64], p: &[f64], out: &mut [f64]) -> Result<(), BatchError> {
        self.model.sensitivity_points(qs, p, out)?;
        self.scale_matrices(out);
        Ok(())
    }

    fn nominal(&self, q: &[f64], p: &[f64]) -> Pose {
        self.model.nominal(q, p)
    }
}
