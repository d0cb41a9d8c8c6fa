//! FORM, the improved first-order second-moment method of the paper's
//! Section 3.1 (Eq. 19-22, 31).
//!
//! The limit state is linearised at the design point `u*`, the point of the
//! failure surface nearest to the origin of standard normal space:
//!
//! - Eq. 21: `β = μ_ZL/σ_ZL`, the distance from the origin to the linearised
//!   surface; in standard space `β = α·u*` with
//! - Eq. 22: `α = −∇_u g/|∇_u g|`, the unit normal pointing into failure;
//!   the importance factors are `α_j²` (they sum to 1; for correlated
//!   normal inputs, the squares of Der Kiureghian's importance vector
//!   `γ = L⁻ᵀα`, normalised: [`Inputs::importance`](crate::Inputs::importance));
//! - Eq. 31: `R = Φ(β)`, `p_f = Φ(−β)` (computed with `erfc`, see
//!   [`crate::normal`]).
//!
//! For a tolerance limit state in normal inputs every branch is linear in
//! `u` and the design point has a closed form; otherwise (non-normal inputs,
//! the volumetric norm, or a user's limit state) the improved HL-RF iteration
//! of Zhang & Der Kiureghian (1995) finds it with exact gradients. A limit
//! state that is a minimum of branches (two-sided tolerances, series systems)
//! gets one design point per branch and FORM keeps the nearest; the others
//! are reported in [`FormResult::branches`]. FORM is exact only when the
//! failure set is a single half-space in `u` ([`FormResult::exact`]).

use serde::Serialize;

use crate::error::ReliabilityError;
use crate::limit_state::{Event, LimitState};
use crate::normal;
use crate::util::{dot, norm};

/// The FORM algorithm and its stopping rules.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Form {
    /// Maximum HL-RF iterations per branch.
    pub max_iterations: usize,
    /// Convergence tolerance on the distance `|g|/|∇_u g|` to the surface.
    pub tolerance: f64,
}

impl Default for Form {
    fn default() -> Form {
        Form {
            max_iterations: 200,
            tolerance: 1e-10,
        }
    }
}

/// Why a design-point search stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Termination {
    /// Linear branch in normal inputs: closed form, no iteration.
    ClosedForm,
    /// HL-RF converged.
    Converged,
    /// HL-RF reached the iteration limit (the last iterate is reported).
    MaxIterations,
    /// The gradient vanishes: `g` does not depend on the inputs (`β = ±∞`).
    Degenerate,
}

impl Termination {
    /// `closed_form`, `converged`, `max_iterations` or `degenerate` (the
    /// JSON spelling).
    pub fn name(self) -> &'static str {
        match self {
            Termination::ClosedForm => "closed_form",
            Termination::Converged => "converged",
            Termination::MaxIterations => "max_iterations",
            Termination::Degenerate => "degenerate",
        }
    }

    /// Its position in [`Termination::ALL`].
    pub fn index(self) -> usize {
        match self {
            Termination::ClosedForm => 0,
            Termination::Converged => 1,
            Termination::MaxIterations => 2,
            Termination::Degenerate => 3,
        }
    }

    /// Every termination, in declaration order.
    pub const ALL: [Termination; 4] = [
        Termination::ClosedForm,
        Termination::Converged,
        Termination::MaxIterations,
        Termination::Degenerate,
    ];
}

impl std::fmt::Display for Termination {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Function-call counts (the argmin / OpenTURNS habit).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct Calls {
    /// Limit-state evaluations.
    pub values: u64,
    /// Gradient evaluations (each also gives the value).
    pub gradients: u64,
}

/// The design point of one branch.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BranchResult {
    /// Branch index (see [`LimitState::branches`]).
    pub branch: usize,
    /// Its reliability index.
    pub beta: f64,
    /// `Φ(−β)`.
    pub pf: f64,
    /// HL-RF iterations (0 for the closed form).
    pub iterations: usize,
    /// Why the search stopped.
    pub termination: Termination,
    /// Its design point in standard normal space (for SORM; not serialised).
    #[serde(skip)]
    pub design_point_u: Vec<f64>,
}

/// The result of [`Form::run`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FormResult {
    /// The Hasofer-Lind reliability index `β` (Eq. 21) of the nearest branch.
    pub beta: f64,
    /// `p_f = Φ(−β)`.
    pub pf: f64,
    /// `R = Φ(β)` (Eq. 31).
    pub reliability: f64,
    /// The design point in standard normal space, `u* = β·α`.
    pub design_point_u: Vec<f64>,
    /// The design point in physical space, `x* = T(u*)`.
    pub design_point_x: Vec<f64>,
    /// `α = −∇_u g/|∇_u g|` at `u*` (Eq. 22), pointing into failure.
    pub alpha: Vec<f64>,
    /// Importance factors `α_j²` (independent inputs) or `γ_j²` (with
    /// correlated normals, [`crate::Inputs::importance`]); they sum to 1.
    pub importance: Vec<f64>,
    /// `|∇_u g(u*)|`, the scale of the FORM sensitivities.
    pub gradient_norm: f64,
    /// The branch whose design point is nearest.
    pub branch: usize,
    /// Every branch's design point summary.
    pub branches: Vec<BranchResult>,
    /// Calls to the limit state.
    pub calls: Calls,
    /// Why the nearest branch's search stopped.
    pub termination: Termination,
    /// True when `Φ(−β)` is the exact failure probability (one linear
    /// branch in normal inputs).
    pub exact: bool,
}

struct Branch {
    beta: f64,
    u: Vec<f64>,
    alpha: Vec<f64>,
    gradient_norm: f64,
    iterations: usize,
    termination: Termination,
}

impl Form {
    /// Runs FORM on an event.
    ///
    /// ```
    /// use reliability::{Event, Form, Inputs, Marginal, ToleranceLimitState};
    /// use chain_core::model::Sided;
    /// let inputs = Inputs::new(vec!["e".into()], vec![Marginal::normal(0.0, 0.01).unwrap()]).unwrap();
    /// let g = ToleranceLimitState::component(vec![1.0], 0.03, Sided::Upper).unwrap();
    /// let r = Form::default().run(&Event::new(&inputs, g).unwrap()).unwrap();
    /// assert!((r.beta - 3.0).abs() < 1e-12 && r.exact);
    /// ```
    pub fn run<L: LimitState>(&self, event: &Event<'_, L>) -> Result<FormResult, ReliabilityError> {
        let n = event.inputs.len();
        let nb = event.limit_state.branches();
        let mut calls = Calls::default();
        let affine = event.affine();
        let mut branches = Vec::with_capacity(nb);
        for b in 0..nb {
            // A half-space branch in normal inputs: the closed form.
            let half_space = affine
                .as_ref()
                .and_then(|a| a.view.criterion().half_space(b).map(|cs| (a, cs)));
            let branch = match half_space {
                Some((a, (c, sign))) => {
                    closed_form(a.row(c), a.mean[c], a.view.tolerances()[c], sign)
                }
                None => self.hlrf(event, b, &mut calls)?,
            };
            branches.push(branch);
        }
        // The nearest branch (smallest β; ties keep the first).
        let best = branches.iter().enumerate().fold(0, |best, (i, br)| {
            if br.beta < branches[best].beta {
                i
            } else {
                best
            }
        });
        let Branch {
            beta,
            u,
            alpha,
            gradient_norm,
            termination,
            ..
        } = &branches[best];
        let mut x = vec![0.0; n];
        event.inputs.to_physical(u, &mut x);
        let exact = affine.as_ref().is_some_and(|a| a.view.is_half_space());
        let summary = branches
            .iter()
            .enumerate()
            .map(|(i, br)| BranchResult {
                branch: i,
                beta: br.beta,
                pf: normal::sf(br.beta),
                iterations: br.iterations,
                termination: br.termination,
                design_point_u: br.u.clone(),
            })
            .collect();
        Ok(FormResult {
            beta: *beta,
            pf: normal::sf(*beta),
            reliability: normal::cdf(*beta),
            design_point_u: u.clone(),
            design_point_x: x,
            importance: event.inputs.importance(alpha),
            alpha: alpha.clone(),
            gradient_norm: *gradient_norm,
            branch: best,
            branches: summary,
            calls,
            termination: *termination,
            exact,
        })
    }

    /// The improved HL-RF iteration on branch `b`.
    fn hlrf<L: LimitState>(
        &self,
        event: &Event<'_, L>,
        b: usize,
        calls: &mut Calls,
    ) -> Result<Branch, ReliabilityError> {
        let n = event.inputs.len();
        let mut work = Work::new(n);
        let mut u = vec![0.0; n];
        let mut g = work.eval(event, b, &u, calls);
        let mut gn = norm(&work.grad_u);
        if !gn.is_finite() || gn <= 0.0 {
            // The origin can be a kink (the volumetric norm at zero mean):
            // start a little off it, the same way every time.
            u.iter_mut().for_each(|v| *v = 0.1 / (n as f64).sqrt());
            g = work.eval(event, b, &u, calls);
            gn = norm(&work.grad_u);
        }
        if !g.is_finite() {
            return Err(ReliabilityError::NonFinite("the limit state"));
        }
        if !gn.is_finite() || gn <= 0.0 {
            let beta = if g > 0.0 {
                f64::INFINITY
            } else {
                f64::NEG_INFINITY
            };
            return Ok(Branch {
                beta,
                u: vec![0.0; n],
                alpha: vec![0.0; n],
                gradient_norm: 0.0,
                iterations: 0,
                termination: Termination::Degenerate,
            });
        }
        let mut grad = work.grad_u.clone();
        let mut beta_prev = f64::NAN;
        let mut target = vec![0.0; n];
        let mut trial = vec![0.0; n];
        let mut termination = Termination::MaxIterations;
        let mut iterations = 0;
        for it in 1..=self.max_iterations {
            iterations = it;
            // HL-RF target: the design point of the surface linearised at u.
            let gu: f64 = dot(&grad, &u);
            let scale = (gu - g) / (gn * gn);
            for (t, d) in target.iter_mut().zip(&grad) {
                *t = scale * d;
            }
            // Merit m(v) = ½|v|² + c·|g(v)| (Zhang & Der Kiureghian 1995).
            let un = norm(&u);
            let tn = norm(&target);
            let mut c = un / gn;
            if g != 0.0 {
                c = c.max(0.5 * tn * tn / g.abs());
            }
            c *= 2.0;
            let merit0 = 0.5 * un * un + c * g.abs();
            let mut lambda = 1.0;
            let (mut g_new, mut grad_new) = (g, grad.clone());
            for _ in 0..40 {
                for ((v, u), t) in trial.iter_mut().zip(&u).zip(&target) {
                    *v = u + lambda * (t - u);
                }
                g_new = work.eval(event, b, &trial, calls);
                grad_new.copy_from_slice(&work.grad_u);
                let vn = norm(&trial);
                if g_new.is_finite() && 0.5 * vn * vn + c * g_new.abs() < merit0 {
                    break;
                }
                lambda *= 0.5;
            }
            if !g_new.is_finite() {
                return Err(ReliabilityError::NonFinite("the limit state"));
            }
            u.copy_from_slice(&trial);
            g = g_new;
            grad.copy_from_slice(&grad_new);
            gn = norm(&grad);
            if !gn.is_finite() || gn <= 0.0 {
                break;
            }
            // Convergence: on the surface, and u aligned with −∇g.
            let beta = -dot(&grad, &u) / gn;
            let un = norm(&u);
            let on_surface = g.abs() / gn <= self.tolerance * un.max(1.0);
            let misalign = (un * un - beta * beta).max(0.0).sqrt();
            let aligned = misalign <= 1e-6 * un.max(1.0)
                || (beta - beta_prev).abs() <= 1e-14 * beta.abs().max(1.0);
            beta_prev = beta;
            if on_surface && aligned {
                termination = Termination::Converged;
                break;
            }
        }
        let alpha: Vec<f64> = grad.iter().map(|d| -d / gn).collect();
        let beta = dot(&alpha, &u);
        // Report the design point on the ray of α (u* = β·α).
        let u = alpha.iter().map(|a| beta * a).collect();
        Ok(Branch {
            beta,
            u,
            alpha,
            gradient_norm: gn,
            iterations,
            termination,
        })
    }
}

/// The closed form of Eq. 21-22 for the linear branch
/// `g = I − s·(m + a·u)`: `β = (I − s·m)/|a|`, `α = s·a/|a|`.
fn closed_form(a: &[f64], m: f64, tolerance: f64, sign: f64) -> Branch {
    let n = a.len();
    let (beta, sigma, termination) = closed_beta(a, m, tolerance, sign);
    if termination == Termination::Degenerate {
        return Branch {
            beta,
            u: vec![0.0; n],
            alpha: vec![0.0; n],
            gradient_norm: 0.0,
            iterations: 0,
            termination,
        };
    }
    let alpha: Vec<f64> = a.iter().map(|v| sign * v / sigma).collect();
    Branch {
        beta,
        u: alpha.iter().map(|v| beta * v).collect(),
        alpha,
        gradient_norm: sigma,
        iterations: 0,
        termination,
    }
}

/// The index of [`closed_form`]'s branch alone, allocating nothing: `(β,
/// σ = |a|, termination)`, `β = (I − sign·m)/σ`, or `±∞` (degenerate) when
/// `σ` is zero or NaN. What a grid study's closed-form cases compute, bit
/// for bit as [`Form::run`] does.
pub(crate) fn closed_beta(a: &[f64], m: f64, tolerance: f64, sign: f64) -> (f64, f64, Termination) {
    let sigma = norm(a);
    let mu_z = tolerance - sign * m;
    if sigma.is_nan() || sigma <= 0.0 {
        let beta = if mu_z > 0.0 {
            f64::INFINITY
        } else {
            f64::NEG_INFINITY
        };
        return (beta, sigma, Termination::Degenerate);
    }
    (mu_z / sigma, sigma, Termination::ClosedForm)
}

/// Scratch buffers of the HL-RF evaluation.
struct Work {
    x: Vec<f64>,
    grad_x: Vec<f64>,
    grad_u: Vec<f64>,
}

impl Work {
    fn new(n: usize) -> Work {
        Work {
            x: vec![0.0; n],
            grad_x: vec![0.0; n],
            grad_u: vec![0.0; n],
        }
    }

    /// `g_b(T(u))` and `∇_u g_b = (∂x/∂u)ᵀ·∇_x g_b` (into `grad_u`).
    fn eval<L: LimitState>(
        &mut self,
        event: &Event<'_, L>,
        b: usize,
        u: &[f64],
        calls: &mut Calls,
    ) -> f64 {
        event.inputs.to_physical(u, &mut self.x);
        let g = event.limit_state.branch(b, &self.x, Some(&mut self.grad_x));
        calls.values += 1;
        calls.gradients += 1;
        event.inputs.gradient_u(u, &self.grad_x, &mut self.grad_u);
        g
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_termination_s_index_is_its_place_in_all() {
        for (k, t) in Termination::ALL.iter().enumerate() {
            assert_eq!(t.index(), k, "{t}");
        }
    }

    use super::*;
    use crate::inputs::{Inputs, Marginal};
    use crate::limit_state::Criterion;
    use crate::limit_state::ToleranceLimitState;
    use crate::sampler::Sampler;
    use chain_core::model::Sided;

    fn inputs(stds: &[f64]) -> Inputs {
        Inputs::new(
            (0..stds.len()).map(|i| format!("e{i}")).collect(),
            stds.iter()
                .map(|&s| Marginal::normal(0.0, s).unwrap())
                .collect(),
        )
        .unwrap()
    }

    #[test]
    fn closed_form_matches_hlrf_on_a_user_limit_state() {
        // The same linear limit state through the generic trait (no structure).
        struct Linear(ToleranceLimitState);
        impl LimitState for Linear {
            fn dim(&self) -> usize {
                self.0.dim()
            }
            fn branch(&self, b: usize, x: &[f64], g: Option<&mut [f64]>) -> f64 {
                self.0.branch(b, x, g)
            }
        }
        let inp = inputs(&[0.01, 0.02, 1e-5]);
        let ls =
            ToleranceLimitState::component(vec![-1.0, 1.0, 1200.0], 0.03, Sided::Upper).unwrap();
        let exact = Form::default()
            .run(&Event::new(&inp, ls.clone()).unwrap())
            .unwrap();
        let it = Form::default()
            .run(&Event::new(&inp, Linear(ls)).unwrap())
            .unwrap();
        assert_eq!(exact.termination, Termination::ClosedForm);
        assert_eq!(it.termination, Termination::Converged);
        assert!((exact.beta - it.beta).abs() < 1e-12);
        for (a, b) in exact.alpha.iter().zip(&it.alpha) {
            assert!((a - b).abs() < 1e-12);
        }
        assert!((exact.importance.iter().sum::<f64>() - 1.0).abs() < 1e-14);
    }

    #[test]
    fn a_user_limit_state_offering_an_affine_view_gets_the_fast_paths() {
        struct Offered(ToleranceLimitState);
        impl LimitState for Offered {
            fn dim(&self) -> usize {
                self.0.dim()
            }
            fn branches(&self) -> usize {
                self.0.branches()
            }
            fn branch(&self, b: usize, x: &[f64], g: Option<&mut [f64]>) -> f64 {
                self.0.branch(b, x, g)
            }
            fn affine(&self) -> Option<crate::limit_state::AffineView<'_>> {
                Some(self.0.view())
            }
        }
        let inp = inputs(&[0.01, 0.02, 1e-5]);
        let rows = vec![-1.0, 1.0, 1200.0, 0.5, 0.0, -300.0];
        let ls = ToleranceLimitState::new(3, rows, vec![0.03, 0.02], Criterion::Each(Sided::Two))
            .unwrap();
        let reference = Form::default()
            .run(&Event::new(&inp, ls.clone()).unwrap())
            .unwrap();
        let event = Event::new(&inp, Offered(ls)).unwrap();
        let offered = Form::default().run(&event).unwrap();
        assert_eq!(offered, reference);
        assert_eq!(offered.termination, Termination::ClosedForm);
        assert_eq!(offered.calls, Calls::default());
        assert!(!offered.exact && offered.branches.len() == 4);
        // The importance sampling takes the exact line kernel too: the same
        // estimate as the tolerance limit state's, bit for bit.
        let is = crate::simulation::ImportanceSampling {
            samples: 2000,
            seed: 3,
            form: Form::default(),
            cov: None,
        };
        let a = is.run(&event).unwrap();
        let b = is
            .run(&Event::new(&inp, event.limit_state.0.clone()).unwrap())
            .unwrap();
        assert_eq!(a.pf, b.pf);
        assert_eq!(a.std_error, b.std_error);
    }

    #[test]
    fn criterion_geometry_agrees_with_the_branches() {
        // Along a line E(t) = b + t·d, `safe_interval` must be where every
        // branch is positive, and `fails` the complement.
        let rows = vec![1.0, 0.0, 0.0, 1.0];
        for criterion in [
            Criterion::Each(Sided::Upper),
            Criterion::Each(Sided::Two),
            Criterion::Norm,
        ] {
            let tol = match criterion {
                Criterion::Norm => vec![1.5],
                _ => vec![1.0, 2.0],
            };
            let ls = ToleranceLimitState::new(2, rows.clone(), tol.clone(), criterion).unwrap();
            let (b, d) = ([0.3, -0.4], [0.8, 0.6]);
            let (lo, hi) = criterion
                .safe_interval(&tol, 2, |c| b[c], &d)
                .expect("the origin side is safe");
            for k in -400..400 {
                let t = k as f64 * 0.01;
                let x = [b[0] + t * d[0], b[1] + t * d[1]];
                let g = ls.value(&x);
                let fails = criterion.fails(&tol, 2, |c| x[c]);
                assert_eq!(fails, g <= 0.0, "{criterion:?} t = {t}");
                if (t - lo).abs() > 1e-9 && (t - hi).abs() > 1e-9 {
                    assert_eq!(t > lo && t < hi, g > 0.0, "{criterion:?} t = {t}");
                }
            }
        }
    }

    #[test]
    fn volumetric_design_point_is_the_top_singular_direction() {
        // E = (u0, 2·u1) with σ = 1: ‖E‖ ≤ 3 first fails along u1 at β = 1.5.
        let inp = inputs(&[1.0, 1.0]);
        let ls = ToleranceLimitState::new(2, vec![1.0, 0.0, 0.0, 2.0], vec![3.0], Criterion::Norm)
            .unwrap();
        let r = Form::default().run(&Event::new(&inp, ls).unwrap()).unwrap();
        assert!((r.beta - 1.5).abs() < 1e-9, "{r:?}");
        assert!(r.alpha[1].abs() > 0.999_999);
        assert!(!r.exact);
    }

    #[test]
    fn uniform_inputs_converge() {
        let inp = crate::util::fixtures::inputs(vec![
            Marginal::uniform(-1.0, 1.0).unwrap(),
            Marginal::normal(0.0, 0.5).unwrap(),
        ]);
        let ls = ToleranceLimitState::component(vec![1.0, 1.0], 1.5, Sided::Two).unwrap();
        let r = Form::default().run(&Event::new(&inp, ls).unwrap()).unwrap();
        assert_eq!(r.termination, Termination::Converged);
        assert_eq!(r.branches.len(), 2);
        // Symmetric problem: both branches at the same distance.
        assert!((r.branches[0].beta - r.branches[1].beta).abs() < 1e-8);
        assert!(r.beta > 1.0 && r.beta < 4.0);
    }
}
