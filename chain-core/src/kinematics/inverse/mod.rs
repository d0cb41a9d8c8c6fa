//! Inverse kinematics: the axis values that put the tool point at a target
//! position with the tool axis (the tool frame's +z) along a target
//! direction, both in the workpiece frame — every solution branch.
//!
//! [`Inverse::for_machine`] picks the method: the closed form ([`Solver`])
//! when the chain allows it, otherwise damped Newton with the exact Jacobian
//! ([`NewtonSolver`]).
//!
//! The closed form works on any machine whose free variables (after `fixed`
//! ones are held) are two rotary and three prismatic, and whose nominal
//! rotation has the product form `R(a, b) = Rot(u, a) · R0 · Rot(v, b)`
//! (checked numerically: `u` is the outer rotary axis in the workpiece frame,
//! `v` the inner one in the tool frame) and does not depend on the prismatic
//! variables. Then:
//!
//! 1. the inner angle `b` from `u · R0 Rot(v, b) z = u · t` (a sinusoid in `b`:
//!    two branches by `atan2` / `acos`),
//! 2. the outer angle `a` as the rotation about `u` that maps `R0 Rot(v, b) z`
//!    onto `t`,
//! 3. the prismatic variables from the position, which is affine in them and
//!    linear in `(1, cos, sin)` of each angle: a 3×3 linear system whose
//!    coefficients are fitted once from `nominal()` and verified.
//!
//! Every solution is verified; rotary angles are wrapped to (−π, π]. When the
//! tool axis is along a rotary axis the free angle is held at the previous
//! value and the row is `Singular`.

#![allow(clippy::needless_range_loop)]

mod newton;

pub use newton::{NewtonSolver, STEPS_PER_POSE};

use crate::kinematics::{Kinematics, NominalPose};
use crate::model::{JointKind, Machine};

use crate::geometry::{
    col, cross, det, dot, log_so3, mat_vec, mul, mul_t_vec, norm, quarter_axis, rodrigues,
    rodrigues_vec, scale, solve3, sub, tr, M3, V3,
};

/// Off-grid sample poses `(a, b, l)` at which a fitted closed form is checked
/// against the model before it is used (angles in rad, tool vector in mm).
const CHECKS: [(f64, f64, [f64; 3]); 3] = [
    (0.7, -1.3, [10.0, -20.0, 30.0]),
    (-2.1, 2.9, [-50.0, 5.0, 1.0]),
    (3.0, 0.4, [0.0, 100.0, -7.0]),
];

/// Why a machine cannot be handled by [`Solver`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[cfg_attr(feature = "miette", derive(miette::Diagnostic))]
pub enum InverseError {
    /// The free variables are not two rotary and three prismatic ones.
    #[error("the closed-form inverse needs 2 free rotary and 3 free prismatic variables, found {rotary} rotary and {prismatic} prismatic")]
    #[cfg_attr(
        feature = "miette",
        diagnostic(
            code(chain::inverse::shape),
            help("hold the extra variables at fixed values (e.g. mu = 0)")
        )
    )]
    Shape {
        /// Free rotary variables.
        rotary: usize,
        /// Free prismatic variables.
        prismatic: usize,
    },
    /// The orientation is not of the form `Rot(u, a) R0 Rot(v, b)` or depends
    /// on a prismatic variable.
    #[error("the tool orientation of this machine is not a product of two fixed-axis rotations independent of the linear axes; the closed-form solver does not apply")]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::inverse::not_closed_form)))]
    NotClosedForm,
    /// A held variable's index is not a variable of the machine.
    #[error("variable index {index} is out of range (the machine has {count} variables)")]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::inverse::unknown_variable)))]
    UnknownVariable {
        /// The index given.
        index: usize,
        /// The number of variables.
        count: usize,
    },
    /// No free variable moves the tool.
    #[error("no free axis variable moves the tool point or the tool axis")]
    #[cfg_attr(feature = "miette", diagnostic(
        code(chain::inverse::no_free_variable),
        help("hold fewer variables, or check that the axes move the tool relative to the workpiece")
    ))]
    NoFreeVariable,
    /// The linear axes cannot move the tool point in three independent directions.
    #[error("the linear axes do not span three directions")]
    #[cfg_attr(
        feature = "miette",
        diagnostic(code(chain::inverse::degenerate_linear))
    )]
    DegenerateLinear,
}

/// Status of one solved pose.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Status {
    /// At least one verified solution, none singular.
    Ok,
    /// No axis values reproduce the pose.
    Unreachable,
    /// The tool axis lies along a rotary axis; the free angle was held.
    Singular,
}

impl Status {
    /// `ok`, `unreachable` or `singular`: the name in every output.
    pub fn name(self) -> &'static str {
        match self {
            Status::Ok => "ok",
            Status::Unreachable => "unreachable",
            Status::Singular => "singular",
        }
    }
}

/// The solutions of one pose.
#[derive(Debug, Clone, PartialEq)]
pub struct Solution {
    /// Status of the pose.
    pub status: Status,
    /// Full variable vectors (in the model's variable order), nearest to the
    /// previous values first.
    pub solutions: Vec<Vec<f64>>,
    /// True when the damped-Newton search gave up on the pose at its budget
    /// ([`STEPS_PER_POSE`] iterations) before it had tried
    /// every start: `Unreachable` then means none was found, not that none
    /// exists, and other solutions may exist.
    pub stopped: bool,
}

/// The inverse kinematics of one machine, by the best method that applies.
#[derive(Debug, Clone, PartialEq)]
pub struct Inverse {
    method: Method,
    kinematics: Kinematics,
    params: Vec<f64>,
    rotary: Vec<bool>,
    /// Free rotary variables that move neither the tool point nor the tool
    /// axis (a spindle's spin), with the sign `σ` of their turn about the tool
    /// axis: `R(q + s e_k) = Rot(t, σ s) R(q)`.
    spin: Vec<(usize, f64)>,
}

/// The solver behind an [`Inverse`].
#[derive(Debug, Clone, PartialEq)]
enum Method {
    ClosedForm(Box<Solver>),
    Newton(Box<NewtonSolver>),
}

impl Inverse {
    /// Derives the machine and prepares its solver: the closed form if the
    /// chain allows it, damped Newton otherwise. `params` are the parameter
    /// values, `fixed` the held variables `(index, value)`.
    pub fn for_machine(
        machine: &Machine,
        params: &[f64],
        fixed: &[(usize, f64)],
    ) -> Result<Inverse, InverseError> {
        let kinematics = Kinematics::from_machine(machine);
        let kinds: Vec<JointKind> = machine.variables.iter().map(|v| v.kind).collect();
        let method = match Solver::new(&kinematics, &kinds, params, fixed) {
            Ok(solver) => Method::ClosedForm(Box::new(solver)),
            Err(InverseError::UnknownVariable { index, count }) => {
                return Err(InverseError::UnknownVariable { index, count })
            }
            Err(_) => Method::Newton(Box::new(NewtonSolver::new(
                kinematics.clone(),
                params,
                fixed,
            )?)),
        };
        let Held { base, idle, .. } = held_variables(&kinematics, kinds.len(), params, fixed)?;
        let spin = idle
            .into_iter()
            .filter(|&k| kinds[k] == JointKind::Rotary)
            .map(|k| {
                // The sign of the turn about the tool axis.
                let r0 = kinematics.pose(&base, params).rotation;
                let mut q = base.clone();
                q[k] += 0.5;
                let r1 = kinematics.pose(&q, params).rotation;
                let w = log_so3(&mul(&r1, &tr(&r0)));
                (k, dot(w, col(&r0, 2)).signum())
            })
            .collect();
        Ok(Inverse {
            method,
            kinematics,
            params: params.to_vec(),
            rotary: kinds.iter().map(|k| *k == JointKind::Rotary).collect(),
            spin,
        })
    }

    /// `closed-form` or `newton`.
    pub fn method(&self) -> &'static str {
        match self.method {
            Method::ClosedForm(_) => "closed-form",
            Method::Newton(_) => "newton",
        }
    }

    /// All solutions for tool point `point` and tool axis `axis`; `prev` are
    /// the previous row's values (model order).
    pub fn solve(&self, point: V3, axis: V3, prev: &[f64]) -> Solution {
        match &self.method {
            Method::ClosedForm(s) => s.solve(point, axis, prev),
            Method::Newton(s) => s.solve(point, axis, prev),
        }
    }

    /// All solutions for a full tool pose: point `point` and orientation
    /// `rotation` (the tool frame in the workpiece frame, row-major). The
    /// point and axis are solved as in [`Inverse::solve`]; then a spin
    /// variable (one that turns the tool about its own axis, `mu` of
    /// `cnc5_bevel`) takes the remaining turn, or, without one, a solution is
    /// kept only if its orientation already matches (to 1e-7 rad).
    pub fn solve_pose(&self, point: V3, rotation: &M3, prev: &[f64]) -> Solution {
        let axis = col(rotation, 2);
        let first = self.solve(point, axis, prev);
        let singular = first.status == Status::Singular;
        let mut out: Vec<Vec<f64>> = Vec::new();
        for mut q in first.solutions.iter().cloned() {
            if let Some(&(k, sign)) = self.spin.first() {
                let r = self.kinematics.pose(&q, &self.params).rotation;
                let w = log_so3(&mul(rotation, &tr(&r)));
                q[k] = wrap(q[k] + sign * dot(w, axis));
            }
            let r = self.kinematics.pose(&q, &self.params).rotation;
            let off = norm(log_so3(&mul(rotation, &tr(&r))));
            if off <= FRAME_TOLERANCE && !out.iter().any(|o| close(o, &q, &self.rotary)) {
                out.push(q);
            }
        }
        let mut solution = Solution::ranked(out, prev, &self.rotary, singular);
        solution.stopped = first.stopped;
        solution
    }
}

/// The unit tool axis, or `None` when the axis is zero or anything is not
/// finite (such a target is unreachable).
fn unit_axis(point: V3, axis: V3) -> Option<V3> {
    let na = norm(axis);
    (na.is_finite() && na > 0.0 && point.iter().all(|x| x.is_finite()))
        .then(|| scale(axis, 1.0 / na))
}

impl Solution {
    /// No solution.
    fn unreachable() -> Solution {
        Solution {
            status: Status::Unreachable,
            solutions: Vec::new(),
            stopped: false,
        }
    }

    /// The solutions found, nearest to `prev` first (rotary differences
    /// wrapped to (−π, π]); `Unreachable` when there is none.
    fn ranked(
        mut solutions: Vec<Vec<f64>>,
        prev: &[f64],
        rotary: &[bool],
        singular: bool,
    ) -> Solution {
        if solutions.is_empty() {
            return Solution::unreachable();
        }
        let dist = |s: &Vec<f64>| -> f64 {
            s.iter()
                .zip(prev)
                .zip(rotary)
                .map(|((x, p), r)| {
                    let d = if *r { wrap(x - p) } else { x - p };
                    d * d
                })
                .sum()
        };
        solutions.sort_by(|x, y| dist(x).total_cmp(&dist(y)));
        Solution {
            status: if singular {
                Status::Singular
            } else {
                Status::Ok
            },
            solutions,
            stopped: false,
        }
    }
}

/// A closed-form inverse-kinematics solver for one machine.
#[derive(Debug, Clone, PartialEq)]
pub struct Solver {
    params: Vec<f64>,
    base: Vec<f64>,
    rotary: Vec<bool>,
    outer: usize,
    inner: usize,
    lin: [usize; 3],
    u: V3,
    v: V3,
    r0: [[f64; 3]; 3],
    /// Position model `p = Σ_αβ f_α(a) g_β(b) (offset[α][β] + gain[α][β]·l)`
    /// with `f = (1, cos a, sin a)`, `g = (1, cos b, sin b)`.
    offset: [[V3; 3]; 3],
    gain: [[[[f64; 3]; 3]; 3]; 3],
    /// `(α, β, γ)` of `u · R0 Rot(v, b) z = γ + α cos b + β sin b`.
    sinusoid: [f64; 3],
}

const SING: f64 = 1e-9;

/// How far (rad) the reached tool frame may be from a full-pose target: the
/// axis is solved exactly, so this bounds the turn about it that no axis
/// takes up — loose enough for rotations written with 8 decimals.
const FRAME_TOLERANCE: f64 = 1e-7;

impl Solver {
    /// Prepares the solver: `kinds` are the variables' joint kinds (model
    /// order), `params` the parameter values, `fixed` the held variables
    /// `(index, value)`.
    pub fn new<M: NominalPose + ?Sized>(
        model: &M,
        kinds: &[JointKind],
        params: &[f64],
        fixed: &[(usize, f64)],
    ) -> Result<Self, InverseError> {
        let n = kinds.len();
        let Held { base, held, .. } = held_variables(model, n, params, fixed)?;
        let free: Vec<bool> = held.iter().map(|h| !h).collect();
        let rot: Vec<usize> = (0..n)
            .filter(|&i| free[i] && kinds[i] == JointKind::Rotary)
            .collect();
        let lin: Vec<usize> = (0..n)
            .filter(|&i| free[i] && kinds[i] == JointKind::Prismatic)
            .collect();
        if rot.len() != 2 || lin.len() != 3 {
            return Err(InverseError::Shape {
                rotary: rot.len(),
                prismatic: lin.len(),
            });
        }
        let lin = [lin[0], lin[1], lin[2]];
        let rotary = kinds.iter().map(|k| *k == JointKind::Rotary).collect();
        let mut s = Solver {
            params: params.to_vec(),
            base,
            rotary,
            outer: rot[0],
            inner: rot[1],
            lin,
            u: [0.0; 3],
            v: [0.0; 3],
            r0: [[0.0; 3]; 3],
            offset: [[[0.0; 3]; 3]; 3],
            gain: [[[[0.0; 3]; 3]; 3]; 3],
            sinusoid: [0.0; 3],
        };
        for (o, i) in [(rot[0], rot[1]), (rot[1], rot[0])] {
            s.outer = o;
            s.inner = i;
            if s.fit(model) {
                if !s.fit_position(model) {
                    return Err(InverseError::NotClosedForm);
                }
                if det(&s.linear_model(0.3, -0.7).0).abs() < 1e-12 {
                    return Err(InverseError::DegenerateLinear);
                }
                // u · R0 (z_par + cos b z_perp + sin b (v × z)), z_par = (v·z) v.
                let ez = [0.0, 0.0, 1.0];
                let w = mul_t_vec(&s.r0, s.u);
                let zpar = scale(s.v, dot(s.v, ez));
                s.sinusoid = [dot(w, sub(ez, zpar)), dot(w, cross(s.v, ez)), dot(w, zpar)];
                return Ok(s);
            }
        }
        Err(InverseError::NotClosedForm)
    }

    fn q(&self, a: f64, b: f64, l: V3) -> Vec<f64> {
        let mut q = self.base.clone();
        q[self.outer] = a;
        q[self.inner] = b;
        for k in 0..3 {
            q[self.lin[k]] = l[k];
        }
        q
    }

    fn rot<M: NominalPose + ?Sized>(&self, model: &M, a: f64, b: f64, l: V3) -> [[f64; 3]; 3] {
        model.nominal_pose(&self.q(a, b, l), &self.params).rotation
    }

    /// Fits `u`, `R0`, `v` for the current outer/inner choice and checks the
    /// product form at a few points.
    fn fit<M: NominalPose + ?Sized>(&mut self, model: &M) -> bool {
        let z = [0.0; 3];
        let r0 = self.rot(model, 0.0, 0.0, z);
        let ra = self.rot(model, std::f64::consts::FRAC_PI_2, 0.0, z);
        let rb = self.rot(model, 0.0, std::f64::consts::FRAC_PI_2, z);
        self.r0 = r0;
        self.u = quarter_axis(&mul(&ra, &tr(&r0)));
        self.v = quarter_axis(&mul(&tr(&r0), &rb));
        if norm(self.u) < 0.5 || norm(self.v) < 0.5 {
            return false;
        }
        CHECKS.iter().all(|&(a, b, l)| {
            let got = self.rot(model, a, b, l);
            let want = mul(&mul(&rodrigues(self.u, a), &self.r0), &rodrigues(self.v, b));
            (0..3).all(|i| (0..3).all(|j| (got[i][j] - want[i][j]).abs() < 1e-9))
        })
    }

    fn position<M: NominalPose + ?Sized>(&self, model: &M, a: f64, b: f64, l: V3) -> V3 {
        model.nominal_pose(&self.q(a, b, l), &self.params).position
    }

    /// Fits the position model from `nominal()` at the quarter turns
    /// `a, b ∈ {0, π/2, π}` and unit steps of the linear axes (36
    /// evaluations), then checks it at three other configurations. The model
    /// is exact for any serial chain: each rotary joint appears once, so the
    /// position is linear in `(1, cos, sin)` of each angle and affine in the
    /// linear variables.
    fn fit_position<M: NominalPose + ?Sized>(&mut self, model: &M) -> bool {
        use std::f64::consts::{FRAC_PI_2, PI};
        let angles = [0.0, FRAC_PI_2, PI];
        // Values at the three angles -> coefficients of (1, cos, sin):
        // v(0) = c1 + cc, v(π/2) = c1 + cs, v(π) = c1 − cc.
        let coefficients = |v: [f64; 3]| -> [f64; 3] {
            let c1 = 0.5 * (v[0] + v[2]);
            [c1, 0.5 * (v[0] - v[2]), v[1] - c1]
        };
        let mut values = [[[[0.0; 3]; 4]; 3]; 3]; // [ia][ib][step][row]
        for (ia, &a) in angles.iter().enumerate() {
            for (ib, &b) in angles.iter().enumerate() {
                let p0 = self.position(model, a, b, [0.0; 3]);
                values[ia][ib][0] = p0;
                for k in 0..3 {
                    let mut l = [0.0; 3];
                    l[k] = 1.0;
                    values[ia][ib][k + 1] = sub(self.position(model, a, b, l), p0);
                }
            }
        }
        for step in 0..4 {
            for row in 0..3 {
                // Coefficients in b for each a sample, then in a.
                let mut in_b = [[0.0; 3]; 3]; // [ia][β]
                for ia in 0..3 {
                    in_b[ia] = coefficients([
                        values[ia][0][step][row],
                        values[ia][1][step][row],
                        values[ia][2][step][row],
                    ]);
                }
                for beta in 0..3 {
                    let c = coefficients([in_b[0][beta], in_b[1][beta], in_b[2][beta]]);
                    for alpha in 0..3 {
                        if step == 0 {
                            self.offset[alpha][beta][row] = c[alpha];
                        } else {
                            self.gain[alpha][beta][row][step - 1] = c[alpha];
                        }
                    }
                }
            }
        }
        CHECKS.iter().all(|&(a, b, l)| {
            let want = self.position(model, a, b, l);
            let (m, p0) = self.linear_model(a, b);
            let got = [
                p0[0] + dot(m[0], l),
                p0[1] + dot(m[1], l),
                p0[2] + dot(m[2], l),
            ];
            norm(sub(got, want)) <= 1e-9 * 1.0f64.max(norm(want))
        })
    }

    /// The position model at angles `(a, b)`: `p = p0 + m·l`.
    fn linear_model(&self, a: f64, b: f64) -> ([[f64; 3]; 3], V3) {
        let (sa, ca) = a.sin_cos();
        let (sb, cb) = b.sin_cos();
        self.linear_model_trig([1.0, ca, sa], [1.0, cb, sb])
    }

    fn linear_model_trig(&self, f: [f64; 3], g: [f64; 3]) -> ([[f64; 3]; 3], V3) {
        let mut m = [[0.0; 3]; 3];
        let mut p0 = [0.0; 3];
        for alpha in 0..3 {
            for beta in 0..3 {
                let w = f[alpha] * g[beta];
                let off = &self.offset[alpha][beta];
                let gain = &self.gain[alpha][beta];
                for row in 0..3 {
                    p0[row] += w * off[row];
                    for k in 0..3 {
                        m[row][k] += w * gain[row][k];
                    }
                }
            }
        }
        (m, p0)
    }

    /// All solutions for tool point `point` and tool axis `axis` (normalised
    /// here); `prev` are the previous row's values (model order), used for the
    /// branch order and the held angle of a singular pose.
    pub fn solve(&self, point: V3, axis: V3, prev: &[f64]) -> Solution {
        let unreachable = Solution::unreachable();
        let Some(t) = unit_axis(point, axis) else {
            return unreachable;
        };
        let (u, v) = (self.u, self.v);
        let ez = [0.0, 0.0, 1.0];
        let [alpha, beta, gamma] = self.sinusoid;
        let rho = alpha.hypot(beta);
        let rhs = dot(u, t) - gamma;
        let mut singular = false;
        // At most two inner angles.
        let (bs, count) = if rho < SING {
            singular = true;
            if rhs.abs() > 1e-9 {
                return unreachable;
            }
            ([prev.get(self.inner).copied().unwrap_or(0.0), 0.0], 1)
        } else {
            let c = rhs / rho;
            if c.abs() > 1.0 + 1e-9 {
                return unreachable;
            }
            let phi = beta.atan2(alpha);
            let d = c.clamp(-1.0, 1.0).acos();
            ([phi + d, phi - d], 2)
        };
        let tperp = sub(t, scale(u, dot(u, t)));
        let mut sols: Vec<Vec<f64>> = Vec::with_capacity(count);
        for &b in &bs[..count] {
            let b = wrap(b);
            let q = mat_vec(&self.r0, rodrigues_vec(v, b, ez));
            let qperp = sub(q, scale(u, dot(u, q)));
            let a = if norm(tperp) < SING || norm(qperp) < SING {
                singular = true;
                prev.get(self.outer).copied().unwrap_or(0.0)
            } else {
                dot(u, cross(qperp, tperp)).atan2(dot(qperp, tperp))
            };
            let a = wrap(a);
            if let Some(s) = self.linear(a, b, q, point, t) {
                if !sols.iter().any(|o| close(o, &s, &self.rotary)) {
                    sols.push(s);
                }
            }
        }
        Solution::ranked(sols, prev, &self.rotary, singular)
    }

    /// The prismatic values for angles `(a, b)`, verified against the pose
    /// (the tool axis from the rotation model, the point from the position
    /// model, both checked against `nominal()` when the solver was built);
    /// `inner_axis` is `R0 Rot(v, b) z`.
    fn linear(&self, a: f64, b: f64, inner_axis: V3, point: V3, t: V3) -> Option<Vec<f64>> {
        let (sa, ca) = a.sin_cos();
        let (sb, cb) = b.sin_cos();
        let (m, p0) = self.linear_model_trig([1.0, ca, sa], [1.0, cb, sb]);
        let l = solve3(&m, sub(point, p0))?;
        let axis = rodrigues_vec(self.u, a, inner_axis);
        let reached = [
            p0[0] + dot(m[0], l),
            p0[1] + dot(m[1], l),
            p0[2] + dot(m[2], l),
        ];
        let ok = norm(sub(reached, point)) <= 1e-9 * 1.0f64.max(norm(point))
            && norm(sub(axis, t)) <= 1e-9
            && l.iter().all(|x| x.is_finite());
        ok.then(|| self.q(a, b, l))
    }
}

/// The variables a pose leaves alone: the `fixed` ones at their values, and
/// every other variable that moves neither the tool point nor the tool axis
/// (a spindle's spin), held at 0 (the spec's default for a held variable).
struct Held {
    /// Values of the held variables (0 for the free ones).
    base: Vec<f64>,
    /// Per variable: held (fixed or idle).
    held: Vec<bool>,
    /// The idle variables found (not in `fixed`).
    idle: Vec<usize>,
}

fn held_variables<M: NominalPose + ?Sized>(
    model: &M,
    count: usize,
    params: &[f64],
    fixed: &[(usize, f64)],
) -> Result<Held, InverseError> {
    let mut base = vec![0.0; count];
    let mut held = vec![false; count];
    for &(index, value) in fixed {
        if index >= count {
            return Err(InverseError::UnknownVariable { index, count });
        }
        base[index] = value;
        held[index] = true;
    }
    let idle: Vec<usize> = (0..count)
        .filter(|&i| !held[i] && !moves_tool(model, params, &base, i))
        .collect();
    for &i in &idle {
        held[i] = true;
    }
    Ok(Held { base, held, idle })
}

/// Whether variable `i` changes the tool point or the tool axis (checked at
/// two configurations).
fn moves_tool<M: NominalPose + ?Sized>(model: &M, params: &[f64], base: &[f64], i: usize) -> bool {
    [0.37, -1.9].iter().any(|&s| {
        let mut q: Vec<f64> = base
            .iter()
            .enumerate()
            .map(|(k, b)| b + s * (k as f64 + 1.0) * 0.61)
            .collect();
        let p1 = model.nominal_pose(&q, params);
        q[i] += 0.9;
        let p2 = model.nominal_pose(&q, params);
        let a1 = [p1.rotation[0][2], p1.rotation[1][2], p1.rotation[2][2]];
        let a2 = [p2.rotation[0][2], p2.rotation[1][2], p2.rotation[2][2]];
        norm(sub(a1, a2)) > 1e-12
            || norm(sub(p1.position, p2.position)) > 1e-12 * 1.0f64.max(norm(p1.position))
    })
}

/// Wraps an angle to (−π, π].
pub fn wrap(x: f64) -> f64 {
    use std::f64::consts::PI;
    let mut y = x.rem_euclid(2.0 * PI);
    if y > PI {
        y -= 2.0 * PI;
    }
    if y <= -PI {
        y += 2.0 * PI;
    }
    y
}

fn close(a: &[f64], b: &[f64], rotary: &[bool]) -> bool {
    a.iter().zip(b).zip(rotary).all(|((x, y), r)| {
        let d = if *r { wrap(x - y) } else { x - y };
        d.abs() < 1e-9 * 1.0f64.max(x.abs())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn status_names_are_their_serialised_form() {
        for s in [Status::Ok, Status::Unreachable, Status::Singular] {
            assert_eq!(
                serde_json::to_string(&s).unwrap(),
                format!("\"{}\"", s.name())
            );
        }
        assert_eq!(Status::Unreachable.name(), "unreachable");
    }
}
