//! SORM, the second-order reliability method (`reliability-v2.md` §3), on
//! FORM's design point of every branch.
//!
//! The Hessian of each branch in standard space is exact: the error model is
//! linear in `x`, so with `J = ∂x/∂u` ([`Inputs::jacobian_matrix`])
//!
//! `∇²_u g = Jᵀ·∇²_x g·J + Σ_i ∂g/∂x_i·∇²_u x_i`
//!
//! ([`Inputs::add_second_derivatives`]), `∇²_x g = 0` for a component
//! (half-space) branch and, for the volumetric norm `g = I − |S·x|`,
//! `∇²_x g = −(SᵀS − ∇|e|·∇|e|ᵀ)/|e|` (`e = S·x`, `∇|e| = Sᵀe/|e|`). A user's
//! limit state without the tolerance structure gets `∇²_x g` by central
//! differences of its exact gradient ([`HessianSource::GradientDifferences`]).
//!
//! The main curvatures `κ_i` are the eigenvalues of `Pᵀ·∇²_u g·P/|∇_u g|`,
//! `P` an orthonormal basis of the plane orthogonal to `α = −∇_u g/|∇_u g|`
//! (Der Kiureghian 2005, *Engineering Design Reliability Handbook* ch. 14,
//! Eq. 14.28; positive when the failure set curves away from the origin).
//! The probabilities (Lemaire 2009, *Structural Reliability* §7.4):
//!
//! - Breitung (1984): `p_f = Φ(−β)·Π(1 + β·κ_i)^{−1/2}`;
//! - Hohenbichler & Rackwitz (1988): `p_f = Φ(−β)·Π(1 + ψ(β)·κ_i)^{−1/2}`,
//!   `ψ(β) = φ(β)/Φ(−β)`;
//! - Tvedt (1990), the three-term formula: `A₁ + A₂ + A₃` with
//!   `A₁` Breitung's, `A₂ = (βΦ(−β) − φ(β))·[Π(1 + βκ_i)^{−1/2} − Π(1 + (β + 1)κ_i)^{−1/2}]`,
//!   `A₃ = (β + 1)(βΦ(−β) − φ(β))·[Π(1 + βκ_i)^{−1/2} − Re Π(1 + (β + i)κ_i)^{−1/2}]`.
//!
//! Tvedt's is the `reliability`. A branch whose curvature makes
//! `1 + β·κ_i ≤ 0` (the asymptotic formulas do not apply), or whose FORM
//! search did not converge, is not converged.

use serde::Serialize;

use crate::error::ReliabilityError;
use crate::form::{Form, FormResult, Termination};
use crate::inputs::Inputs;
use crate::limit_state::{Criterion, Event, LimitState};
use crate::normal;

/// How `∇²_x g` was obtained.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum HessianSource {
    /// The tolerance limit state's closed form (zero or the norm's).
    Exact,
    /// Central differences of the exact gradient (a user's limit state).
    GradientDifferences,
}

/// The second-order result of one branch.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SormBranch {
    /// Branch index.
    pub branch: usize,
    /// Its FORM index `β`.
    pub beta_form: f64,
    /// The main curvatures at the design point, ascending.
    pub curvatures: Vec<f64>,
    /// Breitung's `p_f`.
    pub pf_breitung: f64,
    /// Hohenbichler–Rackwitz's `p_f`.
    pub pf_hohenbichler_rackwitz: f64,
    /// Tvedt's `p_f`.
    pub pf_tvedt: f64,
    /// FORM converged on this branch and every `1 + β·κ_i > 0`.
    pub converged: bool,
}

/// The result of [`Sorm::run`]: the nearest branch's second-order
/// probabilities (the branch FORM keeps) and every branch's.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SormResult {
    /// Tvedt's `p_f` (the method's answer).
    pub pf: f64,
    /// `1 − p_f`.
    pub reliability: f64,
    /// The generalised index `−Φ⁻¹(p_f)` (Tvedt).
    pub beta: f64,
    /// Breitung's generalised index.
    pub beta_breitung: f64,
    /// Hohenbichler–Rackwitz's generalised index.
    pub beta_hohenbichler_rackwitz: f64,
    /// Tvedt's generalised index (= `beta`).
    pub beta_tvedt: f64,
    /// Breitung's `p_f`.
    pub pf_breitung: f64,
    /// Hohenbichler–Rackwitz's `p_f`.
    pub pf_hohenbichler_rackwitz: f64,
    /// The nearest branch's curvatures.
    pub curvatures: Vec<f64>,
    /// Every branch.
    pub branches: Vec<SormBranch>,
    /// How `∇²_x g` was obtained.
    pub hessian: HessianSource,
    /// The nearest branch converged (FORM and the asymptotic formulas).
    pub converged: bool,
    /// The FORM result it corrects.
    pub form: FormResult,
}

/// SORM: FORM's search, then the curvatures.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Sorm {
    /// The FORM search.
    pub form: Form,
}

/// The three asymptotic probabilities `(Breitung, HR, Tvedt)` at `β` with
/// curvatures `κ`, or `None` when some `1 + β·κ_i ≤ 0`.
pub fn probabilities(beta: f64, kappa: &[f64]) -> Option<(f64, f64, f64)> {
    let phi = normal::sf(beta);
    let dens = normal::pdf(beta);
    let psi = dens / phi;
    let (mut lb, mut lb1, mut lhr) = (0.0, 0.0, 0.0);
    let (mut lmod, mut arg) = (0.0, 0.0);
    for &k in kappa {
        let (a, a1, ahr) = (1.0 + beta * k, 1.0 + (beta + 1.0) * k, 1.0 + psi * k);
        if a <= 0.0 || a1 <= 0.0 || ahr <= 0.0 {
            return None;
        }
        lb += -0.5 * a.ln();
        lb1 += -0.5 * a1.ln();
        lhr += -0.5 * ahr.ln();
        // (1 + βκ + iκ)^{−1/2}: modulus and argument, principal branch.
        lmod += -0.25 * (a * a + k * k).ln();
        arg += -0.5 * k.atan2(a);
    }
    let (pb, pb1) = (lb.exp(), lb1.exp());
    let pc = lmod.exp() * arg.cos();
    let breitung = phi * pb;
    let t = beta * phi - dens;
    let tvedt = breitung + t * (pb - pb1) + (beta + 1.0) * t * (pb - pc);
    Some((breitung, phi * lhr.exp(), tvedt))
}

impl Sorm {
    /// Runs FORM, then the second-order correction on every branch.
    pub fn run<L: LimitState>(&self, event: &Event<'_, L>) -> Result<SormResult, ReliabilityError> {
        let form = self.form.run(event)?;
        let n = event.inputs.len();
        let hessian = if event.limit_state.affine().is_some() {
            HessianSource::Exact
        } else {
            HessianSource::GradientDifferences
        };
        let mut branches = Vec::with_capacity(form.branches.len());
        for br in &form.branches {
            let ok = matches!(
                br.termination,
                Termination::Converged | Termination::ClosedForm
            ) && br.beta.is_finite();
            let kappa = if ok && n > 1 {
                curvatures(event, br.branch, &br.design_point_u)
            } else {
                Vec::new()
            };
            let probs = if ok {
                probabilities(br.beta, &kappa)
            } else {
                None
            };
            let (pb, phr, pt) = probs.unwrap_or((f64::NAN, f64::NAN, f64::NAN));
            branches.push(SormBranch {
                branch: br.branch,
                beta_form: br.beta,
                curvatures: kappa,
                pf_breitung: pb,
                pf_hohenbichler_rackwitz: phr,
                pf_tvedt: pt,
                converged: probs.is_some(),
            });
        }
        let best = &branches[form.branch];
        let b = |p: f64| normal::beta_from_pf(p);
        Ok(SormResult {
            pf: best.pf_tvedt,
            reliability: 1.0 - best.pf_tvedt,
            beta: b(best.pf_tvedt),
            beta_breitung: b(best.pf_breitung),
            beta_hohenbichler_rackwitz: b(best.pf_hohenbichler_rackwitz),
            beta_tvedt: b(best.pf_tvedt),
            pf_breitung: best.pf_breitung,
            pf_hohenbichler_rackwitz: best.pf_hohenbichler_rackwitz,
            curvatures: best.curvatures.clone(),
            converged: best.converged,
            branches,
            hessian,
            form,
        })
    }
}

/// `∇²_x g_b` at `x` (`n × n` row-major) and `∇_x g_b` into `grad`.
fn hessian_x<L: LimitState>(
    ls: &L,
    b: usize,
    x: &[f64],
    grad: &mut [f64],
    inputs: &Inputs,
) -> Vec<f64> {
    let n = x.len();
    let mut h = vec![0.0; n * n];
    ls.branch(b, x, Some(grad));
    if let Some(view) = ls.affine() {
        if view.criterion() == Criterion::Norm {
            let k = view.components();
            let e: Vec<f64> = (0..k)
                .map(|c| view.row(c).iter().zip(x).map(|(s, x)| s * x).sum())
                .collect();
            let norm = e.iter().map(|v| v * v).sum::<f64>().sqrt();
            if norm > 0.0 {
                // ∇|e| = −∇g.
                for p in 0..n {
                    for q in 0..n {
                        let sts: f64 = (0..k).map(|c| view.row(c)[p] * view.row(c)[q]).sum();
                        h[p * n + q] = -(sts - grad[p] * grad[q]) / norm;
                    }
                }
            }
        }
        return h;
    }
    let (mut gp, mut gm) = (vec![0.0; n], vec![0.0; n]);
    let mut xs = x.to_vec();
    for q in 0..n {
        let step = 1e-5 * inputs.stds()[q].max(x[q].abs());
        xs[q] = x[q] + step;
        ls.branch(b, &xs, Some(&mut gp));
        xs[q] = x[q] - step;
        ls.branch(b, &xs, Some(&mut gm));
        xs[q] = x[q];
        for p in 0..n {
            h[p * n + q] = (gp[p] - gm[p]) / (2.0 * step);
        }
    }
    // Symmetrise.
    for p in 0..n {
        for q in 0..p {
            let v = 0.5 * (h[p * n + q] + h[q * n + p]);
            h[p * n + q] = v;
            h[q * n + p] = v;
        }
    }
    h
}

/// The main curvatures of branch `b` at its design point `u`, ascending.
pub fn curvatures<L: LimitState>(event: &Event<'_, L>, b: usize, u: &[f64]) -> Vec<f64> {
    let inputs = event.inputs;
    let n = inputs.len();
    let mut x = vec![0.0; n];
    inputs.to_physical(u, &mut x);
    let mut gx = vec![0.0; n];
    let hx = hessian_x(&event.limit_state, b, &x, &mut gx, inputs);
    let mut j = vec![0.0; n * n];
    inputs.jacobian_matrix(u, &mut j);
    let mut gu = vec![0.0; n];
    inputs.gradient_u(u, &gx, &mut gu);
    let gn = gu.iter().map(|v| v * v).sum::<f64>().sqrt();
    // H_u = Jᵀ H_x J + Σ ∂g/∂x_i ∇²x_i.
    let jm = nalgebra::DMatrix::from_row_slice(n, n, &j);
    let hm = nalgebra::DMatrix::from_row_slice(n, n, &hx);
    let mut hu = jm.transpose() * hm * &jm;
    let mut second = vec![0.0; n * n];
    inputs.add_second_derivatives(u, &gx, &mut second);
    hu += nalgebra::DMatrix::from_row_slice(n, n, &second);
    // An orthonormal basis with α first (Gram–Schmidt on α, e_1, …, e_n).
    let alpha: Vec<f64> = gu.iter().map(|g| -g / gn).collect();
    let mut basis: Vec<Vec<f64>> = vec![alpha];
    for k in 0..n {
        if basis.len() == n {
            break;
        }
        let mut v = vec![0.0; n];
        v[k] = 1.0;
        for _ in 0..2 {
            for e in &basis {
                let d: f64 = e.iter().zip(&v).map(|(a, b)| a * b).sum();
                v.iter_mut().zip(e).for_each(|(v, e)| *v -= d * e);
            }
        }
        let nv = v.iter().map(|v| v * v).sum::<f64>().sqrt();
        if nv > 1e-8 {
            v.iter_mut().for_each(|v| *v /= nv);
            basis.push(v);
        }
    }
    let m = basis.len() - 1;
    let p = nalgebra::DMatrix::from_fn(n, m, |r, c| basis[c + 1][r]);
    let a = p.transpose() * hu * &p / gn;
    let a = (&a + a.transpose()) * 0.5;
    let mut k: Vec<f64> = nalgebra::SymmetricEigen::new(a)
        .eigenvalues
        .iter()
        .copied()
        .collect();
    k.sort_by(f64::total_cmp);
    k
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_curvature_is_form_and_breitung_matches_its_formula() {
        let (b, hr, t) = probabilities(2.5, &[0.0, 0.0]).unwrap();
        let f = normal::sf(2.5);
        assert!((b / f - 1.0).abs() < 1e-15 && (hr / f - 1.0).abs() < 1e-15);
        assert!((t / f - 1.0).abs() < 1e-14);
        let (b, _, _) = probabilities(2.0, &[0.1, -0.2]).unwrap();
        let want = normal::sf(2.0) / (1.2f64 * 0.6).sqrt();
        assert!((b / want - 1.0).abs() < 1e-14);
        assert!(probabilities(2.0, &[-0.6]).is_none());
    }
}
