//! Motion conversion: the CNC axis motions that reproduce, instant by instant,
//! the tool–workpiece pose of a generating machine (seed 002, Eq. 1-2), and
//! their Maclaurin (Taylor at `t = 0`) expansion.
//!
//! Two machines of the spec's YAML format take part: the *generator* (the
//! mechanical cradle-type machine of `examples/machines/cradle_generator.yaml`,
//! say) whose variables follow linear laws `v(t) = start + rate·t`
//! ([`Law`]: the cradle angle `q = θ0 + ω_c t`, the blank roll
//! `φ_p = R_ap ω_c t`, the held settings with rate 0), and the *CNC machine*
//! whose axes are unknown. Both give the pose of their tool frame relative to
//! their workpiece frame, `T_wt = inv(P(workpiece)) · P(tool)` (spec section
//! 1); the conversion makes them equal.
//!
//! - [`Matching::Pose`]: the full pose — rotation and position (the paper's
//!   `L_pt^(G) = L_pt^(C)` and `(O_p O_t)_p^(G) = (O_p O_t)_p^(C)`). Six
//!   conditions; a spindle angle (`mu`) is determined too.
//! - [`Matching::PointAxis`]: the tool point and the tool axis (the tool
//!   frame's `+z`) only, with the variables a pose does not determine held
//!   (`fix`, e.g. `mu = 0` in face milling). Five conditions.
//!
//! Method, for any pair of machines:
//!
//! 1. at `t = 0` from no guess: the closed-form point+axis solutions of
//!    [`crate::inverse::Solver`] (when the CNC machine has its shape) and the
//!    `start` guess, each polished by Newton's method on the chosen
//!    conditions with the exact Jacobian ([`Kinematics::jacobian`]); the
//!    converged solution nearest to `start` (rotary angles compared modulo
//!    2π) is the branch;
//! 2. along `t`: Newton from the previous instant (continuation, with the
//!    step halved when Newton fails or a rotary axis jumps by more than
//!    0.5 rad), so the motion is continuous and stays on the branch of
//!    `t = 0`;
//! 3. the Maclaurin series: the generator pose is evaluated on Taylor jets
//!    ([`Kinematics::pose_of`]) and the CNC axes are solved *as jets*, one
//!    order at a time (Newton's method on power series with the Jacobian at
//!    `t = 0`): with the coefficients `a_0 … a_{k−1}` known and `a_k = 0`,
//!    the residual `F` of the conditions, evaluated on jets, has the order-`k`
//!    coefficient `F_k = J(0)·a_k` exactly, so `a_k = J(0)⁺ F_k` (one QR
//!    factorisation of `J(0)`, and one refinement pass with `a_k` in place).
//!    `n` such steps give the coefficients up to order `n` — exact up to
//!    rounding, no finite differences. (Iterating `Q ← Q + J(0)⁺ F(Q)` on whole series
//!    converges too, but its intermediate iterates carry geometrically
//!    decaying garbage in the high orders whose rounding never cancels; the
//!    order-by-order form computes each coefficient once, from exact lower
//!    orders.)
//!
//! The pose residual of [`Matching::Pose`] is `[p_G − p_C, log(R_G R_Cᵀ)]` in
//! Newton (the rotation vector) and `[p_G − p_C, vee(R_G R_Cᵀ − R_C R_Gᵀ)/2]`
//! on jets; both have the Jacobian `[∂p/∂q_k; ω_k]` at the solution.

use crate::inverse::{wrap, Solver};
use crate::jet::Jet;
use crate::kinematics::{Kinematics, PoseOf};
use crate::model::{JointKind, Machine};
use crate::Pose;
use nalgebra::{DMatrix, DVector};

use crate::geometry::{basis, col, cross, dot, log_so3, mul, norm, sub, tr, V3};

/// What the CNC machine must reproduce of the generator's pose.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Matching {
    /// Rotation and position of the tool frame (6 conditions).
    Pose,
    /// Tool point and tool axis (5 conditions), held variables fixed.
    PointAxis,
}

impl Matching {
    /// `pose` or `point_axis`.
    pub fn name(self) -> &'static str {
        match self {
            Matching::Pose => "pose",
            Matching::PointAxis => "point_axis",
        }
    }

    fn rows(self) -> usize {
        match self {
            Matching::Pose => 6,
            Matching::PointAxis => 5,
        }
    }
}

/// A linear time law `v(t) = start + rate · t` of one generator variable.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Law {
    /// Value at `t = 0`.
    pub start: f64,
    /// Rate per unit time (0 for a held setting).
    pub rate: f64,
}

impl Law {
    /// The value at `t`.
    pub fn at(&self, t: f64) -> f64 {
        self.start + self.rate * t
    }
}

/// Everything a [`Motion`] needs besides the two machines (the output of
/// [`crate::settings::Settings::bind`]).
#[derive(Debug, Clone, PartialEq)]
pub struct MotionSpec {
    /// Values of the generator's parameters, in the generator machine's order.
    pub generator_parameters: Vec<f64>,
    /// One law per generator variable, in the generator machine's order.
    pub laws: Vec<Law>,
    /// Values of the CNC machine's parameters, in its order.
    pub cnc_parameters: Vec<f64>,
    /// What is matched.
    pub matching: Matching,
    /// CNC variables held (index in the CNC machine's order, value);
    /// [`Matching::PointAxis`] only.
    pub fixed: Vec<(usize, f64)>,
    /// Initial guess at `t = 0`, one value per CNC variable (picks the branch).
    pub start: Vec<f64>,
    /// The roll interval `[t0, t1]`.
    pub interval: (f64, f64),
}

/// Why a motion cannot be set up or solved.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[cfg_attr(feature = "miette", derive(miette::Diagnostic))]
pub enum MotionError {
    /// The specification has not one law per generator variable.
    #[error("{laws} laws for the {variables} variables of the generator `{generator}`")]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::motion::law_count)))]
    LawCount {
        /// Laws given.
        laws: usize,
        /// Variables of the generator.
        variables: usize,
        /// The generator machine.
        generator: String,
    },
    /// The parameter or start vectors of the specification do not have the
    /// machines' lengths.
    #[error("parameter or start vectors do not match the machines")]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::motion::vector_lengths)))]
    VectorLengths,
    /// A machine's derived kinematics names variables or parameters the
    /// machine does not have.
    #[error("the derived model's names differ from the machine's")]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::motion::name_mismatch)))]
    NameMismatch,
    /// A held variable's index is not a CNC variable.
    #[error("a fixed variable index is out of range")]
    #[cfg_attr(
        feature = "miette",
        diagnostic(code(chain::motion::fixed_out_of_range))
    )]
    FixedOutOfRange,
    /// Variables are held while the full pose is matched.
    #[error("held variables need matching of the tool point and axis (point_axis)")]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::motion::held_with_pose)))]
    HeldWithPose,
    /// A setting, parameter, start value, law or interval end is not finite.
    #[error("a setting, parameter or start value is not finite")]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::motion::not_finite)))]
    NotFinite,
    /// An instant asked of the trajectory is not finite.
    #[error("instant {t} is not finite")]
    #[cfg_attr(
        feature = "miette",
        diagnostic(code(chain::motion::instant_not_finite))
    )]
    InstantNotFinite {
        /// The instant.
        t: f64,
    },
    /// More free CNC variables than conditions.
    #[error("the CNC machine `{machine}` has {free} free variables but matching the {what} gives {rows} conditions")]
    #[cfg_attr(
        feature = "miette",
        diagnostic(
            code(chain::motion::underdetermined),
            help("hold the others at fixed values (e.g. mu = 0) or match the full pose")
        )
    )]
    Underdetermined {
        /// The CNC machine.
        machine: String,
        /// Free variables.
        free: usize,
        /// Conditions.
        rows: usize,
        /// `pose` or `tool point and axis`.
        what: &'static str,
    },
    /// A rotary generator law turns by more than [`MAX_TURN_PER_INSTANT`]
    /// between consecutive instants ([`Motion::check_instants`]).
    #[error("the roll turns `{variable}` by {turn:.4} rad between instants ({total:.4} rad over the roll interval, {instants} instants): more than a quarter turn (π/2 rad), so the CNC axes cannot be followed from one instant to the next (a whole turn between instants would go unseen); it needs at least {needed} instants")]
    #[cfg_attr(feature = "miette", diagnostic(
        code(chain::motion::too_few_instants),
        help("raise the number of instants, or check the roll: the law's `ratio` and `omega_c` (a roll ratio is a tooth ratio, a few units to a few tens), or a shorter `roll.interval`")
    ))]
    TooFewInstants {
        /// The generator variable.
        variable: String,
        /// Its largest turn between consecutive instants (rad).
        turn: f64,
        /// Its turn over the interval (rad).
        total: f64,
        /// The instants asked for.
        instants: usize,
        /// The instants it needs.
        needed: u64,
    },
    /// No axis values reproduce the generator's pose at an instant.
    #[error("at t = {t}: the CNC machine cannot reproduce the generator's {what} (best residual: position {position:.3e}, angle {angle:.3e} rad)")]
    #[cfg_attr(feature = "miette", diagnostic(
        code(chain::motion::unreachable),
        help("check the settings against the CNC machine's parameters and strokes, or its `start` guess")
    ))]
    Unreachable {
        /// The instant.
        t: f64,
        /// `pose` or `tool point and axis`.
        what: &'static str,
        /// Remaining position error.
        position: f64,
        /// Remaining angle error (rad).
        angle: f64,
    },
    /// The motion cannot be followed continuously: near `t` a rotary axis
    /// jumps however small the step (a singularity on the path).
    #[error("near t = {t}: the CNC axes cannot follow the generator's {what} continuously (a rotary axis jumps however small the step: a singular configuration on the roll)")]
    #[cfg_attr(feature = "miette", diagnostic(
        code(chain::motion::discontinuous),
        help(
            "shorten the roll interval so that it stays on one side of the singular configuration"
        )
    ))]
    Discontinuous {
        /// The instant.
        t: f64,
        /// `pose` or `tool point and axis`.
        what: &'static str,
    },
    /// The Jacobian of the conditions is singular at `t = 0`: the series is
    /// not defined by the method.
    #[error("the CNC axes are singular at t = 0 (the Jacobian of the {what} has rank below the number of free variables); no Maclaurin series")]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::motion::singular)))]
    Singular {
        /// `pose` or `tool point and axis`.
        what: &'static str,
    },
}

/// The residual of a solution: how far the CNC pose is from the generator's.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct PoseError {
    /// Distance between the two tool points.
    pub position: f64,
    /// Angle of `R_G R_Cᵀ` (rad): the whole rotation.
    pub rotation: f64,
    /// Angle between the two tool axes (rad).
    pub axis: f64,
}

/// The Maclaurin series of the CNC axes.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// One jet per CNC variable (model order): `a_0 … a_n`.
    pub axes: Vec<Jet>,
}

impl Series {
    /// The order `n`.
    pub fn order(&self) -> usize {
        self.axes.first().map_or(0, Jet::order)
    }

    /// The partial sum of order `m ≤ n` of axis `k` at `t`.
    pub fn partial_sum(&self, k: usize, m: usize, t: f64) -> f64 {
        let c = self.axes[k].coefficients();
        let m = m.min(c.len() - 1);
        c[..=m].iter().rev().fold(0.0, |acc, a| acc * t + a)
    }

    /// All partial sums `s_0 … s_n` of axis `k` at `t`.
    pub fn partial_sums(&self, k: usize, t: f64) -> Vec<f64> {
        let mut out = Vec::with_capacity(self.order() + 1);
        let mut s = 0.0;
        let mut p = 1.0;
        for a in self.axes[k].coefficients() {
            s += a * p;
            p *= t;
            out.push(s);
        }
        out
    }
}

/// The generator → CNC motion conversion of one pair of machines.
#[derive(Debug, Clone)]
pub struct Motion {
    generator_name: String,
    cnc_name: String,
    generator: Kinematics,
    gen_params: Vec<f64>,
    laws: Vec<Law>,
    gen_names: Vec<String>,
    gen_kinds: Vec<JointKind>,
    cnc: Kinematics,
    cnc_params: Vec<f64>,
    names: Vec<String>,
    kinds: Vec<JointKind>,
    matching: Matching,
    fixed: Vec<(usize, f64)>,
    free: Vec<usize>,
    start: Vec<f64>,
    interval: (f64, f64),
}

/// Newton iterations per solve.
const MAX_NEWTON: usize = 60;
/// The largest turn (rad) of a rotary generator law between consecutive
/// instants (`t = 0` among them) that [`Motion::check_instants`] accepts:
/// the continuation ([`Motion::trajectory`]) compares consecutive instants
/// and halves its step when a rotary axis jumps by more than 0.5 rad, so a
/// turn of about 2π between instants would pass for none (the axes would
/// be reported a whole turn off); a quarter turn keeps far from that, and
/// lets the paper's rolls run on as few as two instants.
pub const MAX_TURN_PER_INSTANT: f64 = std::f64::consts::FRAC_PI_2;
/// A solution is accepted when the position error is below this times
/// `max(1, |p|)` and the angle error below this (rad).
pub const ACCEPT: f64 = 1e-10;

impl Motion {
    /// Sets up the conversion: derives both machines' nominal poses.
    pub fn new(
        generator: &Machine,
        cnc: &Machine,
        spec: MotionSpec,
    ) -> Result<Motion, MotionError> {
        let gk = Kinematics::from_machine(generator);
        let ck = Kinematics::from_machine(cnc);
        if spec.laws.len() != generator.variables.len() {
            return Err(MotionError::LawCount {
                laws: spec.laws.len(),
                variables: generator.variables.len(),
                generator: generator.name.clone(),
            });
        }
        if spec.generator_parameters.len() != generator.parameters.len()
            || spec.cnc_parameters.len() != cnc.parameters.len()
            || spec.start.len() != cnc.variables.len()
        {
            return Err(MotionError::VectorLengths);
        }
        // Machine order → kinematics order, by name.
        let by_name = reorder;
        let gvar_names: Vec<String> = generator.variables.iter().map(|v| v.name.clone()).collect();
        let gpar_names: Vec<String> = generator
            .parameters
            .iter()
            .map(|p| p.name.clone())
            .collect();
        let cvar_names: Vec<String> = cnc.variables.iter().map(|v| v.name.clone()).collect();
        let cpar_names: Vec<String> = cnc.parameters.iter().map(|p| p.name.clone()).collect();
        let mismatch = || MotionError::NameMismatch;
        let gen_params = by_name(&gpar_names, gk.parameters(), &spec.generator_parameters)
            .ok_or_else(mismatch)?;
        let cnc_params =
            by_name(&cpar_names, ck.parameters(), &spec.cnc_parameters).ok_or_else(mismatch)?;
        let laws: Vec<Law> = gk
            .variables()
            .iter()
            .map(|(n, _)| gvar_names.iter().position(|m| m == n).map(|i| spec.laws[i]))
            .collect::<Option<Vec<Law>>>()
            .ok_or_else(mismatch)?;
        let perm: Vec<usize> = ck
            .variables()
            .iter()
            .map(|(n, _)| cvar_names.iter().position(|m| m == n))
            .collect::<Option<Vec<usize>>>()
            .ok_or_else(mismatch)?;
        // kinematics index of machine index i
        let to_kin = |i: usize| perm.iter().position(|&p| p == i).unwrap_or(i);
        let start: Vec<f64> = perm.iter().map(|&i| spec.start[i]).collect();
        let fixed: Vec<(usize, f64)> = spec.fixed.iter().map(|&(i, v)| (to_kin(i), v)).collect();
        if fixed.iter().any(|&(i, _)| i >= perm.len()) {
            return Err(MotionError::FixedOutOfRange);
        }
        if spec.matching == Matching::Pose && !fixed.is_empty() {
            return Err(MotionError::HeldWithPose);
        }
        let all_finite = gen_params
            .iter()
            .chain(&cnc_params)
            .chain(&start)
            .all(|v| v.is_finite())
            && laws
                .iter()
                .all(|l| l.start.is_finite() && l.rate.is_finite())
            && spec.interval.0.is_finite()
            && spec.interval.1.is_finite();
        if !all_finite {
            return Err(MotionError::NotFinite);
        }
        let n = ck.variables().len();
        let free: Vec<usize> = (0..n)
            .filter(|i| !fixed.iter().any(|f| f.0 == *i))
            .collect();
        let what = what(spec.matching);
        if free.len() > spec.matching.rows() {
            return Err(MotionError::Underdetermined {
                machine: cnc.name.clone(),
                free: free.len(),
                rows: spec.matching.rows(),
                what,
            });
        }
        let mut start = start;
        for &(i, v) in &fixed {
            start[i] = v;
        }
        Ok(Motion {
            generator_name: generator.name.clone(),
            cnc_name: cnc.name.clone(),
            gen_names: gk.variables().iter().map(|v| v.0.clone()).collect(),
            gen_kinds: gk.variables().iter().map(|v| v.1).collect(),
            names: ck.variables().iter().map(|v| v.0.clone()).collect(),
            kinds: ck.variables().iter().map(|v| v.1).collect(),
            generator: gk,
            gen_params,
            laws,
            cnc: ck,
            cnc_params,
            matching: spec.matching,
            fixed,
            free,
            start,
            interval: spec.interval,
        })
    }

    /// The generator's name.
    pub fn generator_name(&self) -> &str {
        &self.generator_name
    }

    /// The CNC machine's name.
    pub fn cnc_name(&self) -> &str {
        &self.cnc_name
    }

    /// The CNC variables, in the order of every axis vector here (the CNC
    /// machine's model order).
    pub fn variables(&self) -> &[String] {
        &self.names
    }

    /// The CNC variables' joint kinds.
    pub fn kinds(&self) -> &[JointKind] {
        &self.kinds
    }

    /// The generator's variables, in the order of [`Motion::generator_values`].
    pub fn generator_variables(&self) -> &[String] {
        &self.gen_names
    }

    /// The generator's laws, in [`Motion::generator_variables`] order.
    pub fn laws(&self) -> &[Law] {
        &self.laws
    }

    /// What is matched.
    pub fn matching(&self) -> Matching {
        self.matching
    }

    /// The held CNC variables (index, value).
    pub fn fixed(&self) -> &[(usize, f64)] {
        &self.fixed
    }

    /// The roll interval.
    pub fn interval(&self) -> (f64, f64) {
        self.interval
    }

    /// `k` instants evenly spaced over the roll interval, both ends included
    /// (one instant: the middle).
    pub fn sample_times(&self, k: usize) -> Vec<f64> {
        let (a, b) = self.interval;
        match k {
            0 => Vec::new(),
            1 => vec![0.5 * (a + b)],
            _ => (0..k)
                .map(|i| a + (b - a) * i as f64 / (k - 1) as f64)
                .collect(),
        }
    }

    /// Checks that no rotary generator law turns by more than
    /// [`MAX_TURN_PER_INSTANT`] between consecutive instants of `times`
    /// (with `t = 0`, where the continuation starts): from the laws alone,
    /// before any solve. A roll that turns too fast for its instants (a roll
    /// ratio of 1e5 turns the blank through 41,900 rad over the paper's
    /// interval: 42 rad between 1,000 instants) is refused at once, with the
    /// number of instants it needs, where it took minutes of continuation
    /// and could alias whole turns.
    pub fn check_instants(&self, times: &[f64]) -> Result<(), MotionError> {
        let mut ts: Vec<f64> = times.iter().copied().chain([0.0]).collect();
        ts.sort_by(f64::total_cmp);
        let gap = ts.windows(2).map(|w| w[1] - w[0]).fold(0.0, f64::max);
        let (a, b) = self.interval;
        let worst = (0..self.laws.len())
            .filter(|&k| self.gen_kinds[k] == JointKind::Rotary)
            .map(|k| (k, self.laws[k].rate.abs()))
            .max_by(|x, y| x.1.total_cmp(&y.1));
        match worst {
            Some((k, rate)) if rate * gap > MAX_TURN_PER_INSTANT => {
                let needed = (rate * (b - a) / MAX_TURN_PER_INSTANT).ceil() + 1.0;
                Err(MotionError::TooFewInstants {
                    variable: self.gen_names[k].clone(),
                    turn: rate * gap,
                    total: rate * (b - a),
                    instants: times.len(),
                    needed: if needed < 1e15 {
                        needed as u64
                    } else {
                        u64::MAX
                    },
                })
            }
            _ => Ok(()),
        }
    }

    /// The generator's variable values at `t`.
    pub fn generator_values(&self, t: f64) -> Vec<f64> {
        self.laws.iter().map(|l| l.at(t)).collect()
    }

    /// The generator's tool pose relative to its workpiece at `t`.
    pub fn generator_pose(&self, t: f64) -> Pose {
        self.generator
            .pose(&self.generator_values(t), &self.gen_params)
    }

    /// The generator's pose as Taylor series in `t` to order `order`.
    pub fn generator_series(&self, order: usize) -> PoseOf<Jet> {
        let q: Vec<Jet> = self
            .laws
            .iter()
            .map(|l| Jet::variable(l.start, l.rate, order))
            .collect();
        self.generator.pose_of(&q, &self.gen_params)
    }

    /// The CNC machine's tool pose at axis values `q`.
    pub fn cnc_pose(&self, q: &[f64]) -> Pose {
        self.cnc.pose(q, &self.cnc_params)
    }

    /// How far the CNC pose at `q` is from the generator's at `t`.
    pub fn pose_error(&self, q: &[f64], t: f64) -> PoseError {
        let g = self.generator_pose(t);
        let c = self.cnc_pose(q);
        pose_difference(&g, &c)
    }

    fn is_rotary(&self, k: usize) -> bool {
        self.kinds[k] == JointKind::Rotary
    }

    /// Residual rows and the Jacobian rows (free columns) at `q`.
    fn linearise(
        &self,
        q: &[f64],
        target: &Pose,
        with_jacobian: bool,
    ) -> (Vec<f64>, Vec<Vec<f64>>) {
        let c = self.cnc_pose(q);
        let dp = sub(target.position, c.position);
        let mut rows: Vec<f64> = dp.to_vec();
        let zc = col(&c.rotation, 2);
        let (e1, e2) = basis(zc);
        match self.matching {
            Matching::Pose => {
                let w = log_so3(&mul(&target.rotation, &tr(&c.rotation)));
                rows.extend_from_slice(&w);
            }
            Matching::PointAxis => {
                let dz = sub(col(&target.rotation, 2), zc);
                rows.push(dot(e1, dz));
                rows.push(dot(e2, dz));
            }
        }
        let jac = if with_jacobian {
            let j = self.cnc.jacobian(q, &self.cnc_params);
            let m = self.matching.rows();
            let mut a = vec![vec![0.0; self.free.len()]; m];
            for (col_i, &k) in self.free.iter().enumerate() {
                let jk = j[k];
                for r in 0..3 {
                    a[r][col_i] = jk[r];
                }
                let w = [jk[3], jk[4], jk[5]];
                match self.matching {
                    Matching::Pose => {
                        for r in 0..3 {
                            a[3 + r][col_i] = w[r];
                        }
                    }
                    Matching::PointAxis => {
                        let wz = cross(w, zc);
                        a[3][col_i] = dot(e1, wz);
                        a[4][col_i] = dot(e2, wz);
                    }
                }
            }
            a
        } else {
            Vec::new()
        };
        (rows, jac)
    }

    /// Newton's method from `q` towards the generator's pose at `t`.
    /// Returns the axes and whether they were accepted.
    fn newton(&self, q: &[f64], target: &Pose) -> (Vec<f64>, bool) {
        let scale = 1.0f64.max(norm(target.position));
        let merit = |r: &[f64]| -> f64 {
            let p = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
            let a: f64 = r[3..].iter().map(|x| x * x).sum();
            p + scale * scale * a
        };
        let mut q = q.to_vec();
        for &(i, v) in &self.fixed {
            q[i] = v;
        }
        let (mut r, _) = self.linearise(&q, target, false);
        let mut m = merit(&r);
        for _ in 0..MAX_NEWTON {
            if !m.is_finite() {
                break;
            }
            let (_, a) = self.linearise(&q, target, true);
            let Some(d) = qr_of(&a).and_then(|qr| least_squares(&qr, &r)) else {
                break;
            };
            let mut lambda = 1.0;
            let mut accepted = false;
            while lambda > 1e-4 {
                let mut trial = q.clone();
                for (ci, &k) in self.free.iter().enumerate() {
                    trial[k] += lambda * d[ci];
                }
                let (rt, _) = self.linearise(&trial, target, false);
                let mt = merit(&rt);
                if mt < m {
                    let gain = m - mt;
                    q = trial;
                    r = rt;
                    m = mt;
                    accepted = gain > 1e-30 * scale * scale;
                    break;
                }
                lambda *= 0.5;
            }
            if !accepted {
                break;
            }
        }
        // The point-and-axis residual also vanishes for the reversed axis
        // (z_C = −z_G): accept only a tool axis on the target's side.
        let z = col(&self.cnc_pose(&q).rotation, 2);
        let ok = self.accepted(&r, scale) && dot(z, col(&target.rotation, 2)) > 0.0;
        (q, ok)
    }

    fn accepted(&self, r: &[f64], scale: f64) -> bool {
        let p = norm([r[0], r[1], r[2]]);
        let a: f64 = r[3..].iter().map(|x| x * x).sum::<f64>().sqrt();
        p <= ACCEPT * scale && a <= ACCEPT
    }

    fn unreachable(&self, q: &[f64], t: f64) -> MotionError {
        let e = self.pose_error(q, t);
        MotionError::Unreachable {
            t,
            what: what(self.matching),
            position: e.position,
            angle: match self.matching {
                Matching::Pose => e.rotation,
                Matching::PointAxis => e.axis,
            },
        }
    }

    /// Rotary angles of `q` moved by whole turns to be nearest `reference`.
    fn nearest_turn(&self, q: &mut [f64], reference: &[f64]) {
        for k in 0..q.len() {
            if self.is_rotary(k) {
                q[k] = reference[k] + wrap(q[k] - reference[k]);
            }
        }
    }

    fn distance(&self, a: &[f64], b: &[f64]) -> f64 {
        a.iter()
            .zip(b)
            .enumerate()
            .map(|(k, (x, y))| {
                if self.is_rotary(k) {
                    wrap(x - y).powi(2)
                } else {
                    1e-6 * (x - y).powi(2)
                }
            })
            .sum()
    }

    /// The CNC axes at `t` without a previous instant: every closed-form
    /// point+axis solution and the `start` guess, polished by Newton; the one
    /// nearest `start` (angles modulo 2π, moved to the turn nearest `start`).
    pub fn solve_cold(&self, t: f64) -> Result<Vec<f64>, MotionError> {
        let target = self.generator_pose(t);
        let mut candidates: Vec<Vec<f64>> = vec![self.start.clone()];
        let held: Vec<(usize, f64)> = match self.matching {
            Matching::Pose => Vec::new(),
            Matching::PointAxis => self.fixed.clone(),
        };
        if let Ok(solver) = Solver::new(&self.cnc, &self.kinds, &self.cnc_params, &held) {
            let s = solver.solve(target.position, col(&target.rotation, 2), &self.start);
            candidates.extend(s.solutions);
        }
        let mut best: Option<(f64, Vec<f64>)> = None;
        // The failed candidate with the smallest residual, for the message.
        let mut closest_failure: Option<(f64, Vec<f64>)> = None;
        for c in candidates {
            let (mut q, ok) = self.newton(&c, &target);
            if !ok {
                let e = self.pose_error(&q, t);
                let angle = match self.matching {
                    Matching::Pose => e.rotation,
                    Matching::PointAxis => e.axis,
                };
                let size = e.position / 1.0f64.max(norm(target.position)) + angle;
                if closest_failure.as_ref().is_none_or(|(s, _)| size < *s) {
                    closest_failure = Some((size, q));
                }
                continue;
            }
            self.nearest_turn(&mut q, &self.start);
            let d = self.distance(&q, &self.start);
            if best.as_ref().is_none_or(|(bd, _)| d < *bd) {
                best = Some((d, q));
            }
        }
        best.map(|b| b.1).ok_or_else(|| {
            let q = closest_failure.map_or_else(|| self.start.clone(), |f| f.1);
            self.unreachable(&q, t)
        })
    }

    /// The CNC axes at `t` by Newton from `guess` (the previous instant);
    /// `None` if Newton does not converge from there.
    pub fn solve_from(&self, t: f64, guess: &[f64]) -> Option<Vec<f64>> {
        let target = self.generator_pose(t);
        let (q, ok) = self.newton(guess, &target);
        ok.then_some(q)
    }

    fn follow(&self, ta: f64, qa: &[f64], tb: f64, depth: usize) -> Result<Vec<f64>, MotionError> {
        if let Some(q) = self.solve_from(tb, qa) {
            let jump = (0..q.len())
                .filter(|&k| self.is_rotary(k))
                .map(|k| (q[k] - qa[k]).abs())
                .fold(0.0, f64::max);
            if jump <= 0.5 {
                return Ok(q);
            }
        }
        if depth >= 40 {
            // The step has shrunk to nothing and a rotary axis still jumps
            // (or Newton still fails): the motion crosses a singularity.
            return Err(MotionError::Discontinuous {
                t: tb,
                what: what(self.matching),
            });
        }
        let mid = 0.5 * (ta + tb);
        let qm = self.follow(ta, qa, mid, depth + 1)?;
        self.follow(mid, &qm, tb, depth + 1)
    }

    /// The exact CNC motion at the instants `times` (any order): the branch
    /// of [`Motion::solve_cold`] at `t = 0`, followed continuously outwards.
    /// Returns one axis vector per instant, in the order of `times`.
    pub fn trajectory(&self, times: &[f64]) -> Result<Vec<Vec<f64>>, MotionError> {
        let q0 = self.solve_cold(0.0)?;
        self.trajectory_from(&q0, times)
    }

    /// [`Motion::trajectory`] from a known solution `q0` at `t = 0`.
    pub fn trajectory_from(&self, q0: &[f64], times: &[f64]) -> Result<Vec<Vec<f64>>, MotionError> {
        let mut out = vec![Vec::new(); times.len()];
        let mut up: Vec<usize> = (0..times.len()).filter(|&i| times[i] >= 0.0).collect();
        let mut down: Vec<usize> = (0..times.len()).filter(|&i| times[i] < 0.0).collect();
        up.sort_by(|&a, &b| times[a].total_cmp(&times[b]));
        down.sort_by(|&a, &b| times[b].total_cmp(&times[a]));
        for side in [up, down] {
            let (mut t, mut q) = (0.0, q0.to_vec());
            for i in side {
                if !times[i].is_finite() {
                    return Err(MotionError::InstantNotFinite { t: times[i] });
                }
                q = self.follow(t, &q, times[i], 0)?;
                t = times[i];
                out[i] = q.clone();
            }
        }
        Ok(out)
    }

    /// The Maclaurin series of every CNC axis to order `order`, on the branch
    /// of [`Motion::solve_cold`].
    pub fn series(&self, order: usize) -> Result<Series, MotionError> {
        let q0 = self.solve_cold(0.0)?;
        self.series_from(&q0, order)
    }

    /// The Maclaurin series from the solution `q0` at `t = 0`, one order at a
    /// time: with the coefficients up to `k − 1` known and `a_k = 0`, the
    /// residual's order-`k` coefficient is `F_k = J(0)·a_k` exactly.
    pub fn series_from(&self, q0: &[f64], order: usize) -> Result<Series, MotionError> {
        let target0 = self.generator_pose(0.0);
        let (_, a) = self.linearise(q0, &target0, true);
        let qr = qr_of(&a).ok_or(MotionError::Singular {
            what: what(self.matching),
        })?;
        let g = self.generator_series(order);
        let zc0 = col(&self.cnc_pose(q0).rotation, 2);
        let (e1, e2) = basis(zc0);
        // coefficients[k][i]: a_i of variable k; a_0 from the solution at t = 0.
        let mut coefficients: Vec<Vec<f64>> = q0.iter().map(|&v| vec![v]).collect();
        for k in 1..=order {
            // The series known to order k − 1, with a_k = 0: its residual's
            // order-k coefficient F_k fixes a_k by J(0) a_k = F_k. A second
            // pass with a_k in place refines it (iterative refinement: the
            // residual is evaluated exactly, only the solve rounds).
            for v in &mut coefficients {
                v.push(0.0);
            }
            for _pass in 0..2 {
                let rhs = self.order_residual(&coefficients, &g, k, (e1, e2));
                let d = least_squares(&qr, &rhs).ok_or(MotionError::Singular {
                    what: what(self.matching),
                })?;
                for (ci, &f) in self.free.iter().enumerate() {
                    coefficients[f][k] += d[ci];
                }
            }
        }
        let q: Vec<Jet> = coefficients
            .into_iter()
            .map(Jet::from_coefficients)
            .collect();
        Ok(Series { axes: q })
    }
    /// The order-`k` coefficients of the residual rows for the CNC series
    /// `coefficients` (each of length `k + 1`) against the generator series.
    fn order_residual(
        &self,
        coefficients: &[Vec<f64>],
        g: &PoseOf<Jet>,
        k: usize,
        (e1, e2): (V3, V3),
    ) -> Vec<f64> {
        let q: Vec<Jet> = coefficients
            .iter()
            .map(|c| Jet::from_coefficients(c.clone()))
            .collect();
        let truncate = |j: &Jet| Jet::from_coefficients(j.coefficients()[..=k].to_vec());
        let c = self.cnc.pose_of(&q, &self.cnc_params);
        let gp: Vec<Jet> = g.position.iter().map(truncate).collect();
        let gr: Vec<Vec<Jet>> = g
            .rotation
            .iter()
            .map(|row| row.iter().map(truncate).collect())
            .collect();
        let top = |j: Jet| j.coefficients()[k];
        let mut rhs: Vec<f64> = (0..3).map(|i| top(&gp[i] - &c.position[i])).collect();
        match self.matching {
            Matching::Pose => {
                // M = R_G R_Cᵀ; vee of its skew part.
                let m = |i: usize, j: usize| -> Jet {
                    (1..3).fold(&gr[i][0] * &c.rotation[j][0], |s, l| {
                        &s + &(&gr[i][l] * &c.rotation[j][l])
                    })
                };
                let half = |a: Jet, b: Jet| 0.5 * top(&a - &b);
                rhs.push(half(m(2, 1), m(1, 2)));
                rhs.push(half(m(0, 2), m(2, 0)));
                rhs.push(half(m(1, 0), m(0, 1)));
            }
            Matching::PointAxis => {
                let dz: Vec<f64> = (0..3).map(|i| top(&gr[i][2] - &c.rotation[i][2])).collect();
                for e in [e1, e2] {
                    rhs.push(e[0] * dz[0] + e[1] * dz[1] + e[2] * dz[2]);
                }
            }
        }
        rhs
    }
}

/// `max |exact − s_m|` per order `m = 0..=n` and axis over the instants:
/// `errors[m][k]`. `exact[i]` are the axes at `times[i]`.
pub fn truncation_errors(series: &Series, times: &[f64], exact: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let n = series.order();
    let axes = series.axes.len();
    let mut out = vec![vec![0.0f64; axes]; n + 1];
    for (t, e) in times.iter().zip(exact) {
        for k in 0..axes {
            for (m, s) in series.partial_sums(k, *t).into_iter().enumerate() {
                let d = (e[k] - s).abs();
                // NaN-propagating max: a non-finite sum must show.
                if d > out[m][k] || d.is_nan() {
                    out[m][k] = d;
                }
            }
        }
    }
    out
}

/// The smallest order whose error meets the tolerance, per axis and for all
/// axes together (`None`: not within the orders computed).
/// `errors[m][k]` as from [`truncation_errors`], `tolerance[k]` per axis.
pub fn required_orders(
    errors: &[Vec<f64>],
    tolerance: &[f64],
) -> (Option<usize>, Vec<Option<usize>>) {
    let axes = tolerance.len();
    let per_axis: Vec<Option<usize>> = (0..axes)
        .map(|k| errors.iter().position(|e| e[k] <= tolerance[k]))
        .collect();
    let all = errors
        .iter()
        .position(|e| (0..axes).all(|k| e[k] <= tolerance[k]));
    (all, per_axis)
}

/// `values` (in the order of `names`) in the order of `want`.
fn reorder<T>(names: &[String], want: &[(String, T)], values: &[f64]) -> Option<Vec<f64>> {
    want.iter()
        .map(|(n, _)| names.iter().position(|m| m == n).map(|i| values[i]))
        .collect()
}

fn what(m: Matching) -> &'static str {
    match m {
        Matching::Pose => "pose",
        Matching::PointAxis => "tool point and axis",
    }
}

/// The differences between two poses.
pub fn pose_difference(a: &Pose, b: &Pose) -> PoseError {
    let w = log_so3(&mul(&a.rotation, &tr(&b.rotation)));
    let za = col(&a.rotation, 2);
    let zb = col(&b.rotation, 2);
    PoseError {
        position: norm(sub(a.position, b.position)),
        rotation: norm(w),
        axis: norm(cross(za, zb)).atan2(dot(za, zb)),
    }
}

/// nalgebra's QR factorisation `A = Q·R` of `a` (given by rows, `m × n`,
/// `m ≥ n`), unpacked into the thin `Q` (`m × n`) and `R` (`n × n`); `None`
/// if `m < n` or the columns are (numerically) dependent: a diagonal entry
/// of `R` below `1e-11` of the largest.
fn qr_of(a: &[Vec<f64>]) -> Option<(DMatrix<f64>, DMatrix<f64>)> {
    let m = a.len();
    let n = a.first().map_or(0, Vec::len);
    if m < n || n == 0 || a.iter().any(|row| row.len() != n) {
        return None;
    }
    let (q, r) = DMatrix::from_fn(m, n, |i, j| a[i][j]).qr().unpack();
    let big = (0..n).map(|k| r[(k, k)].abs()).fold(0.0, f64::max);
    if !(big.is_finite() && big > 0.0) || (0..n).any(|k| r[(k, k)].abs() <= 1e-11 * big) {
        return None;
    }
    Some((q, r))
}

/// The least-squares solution of `A x = b` from `(Q, R)` of [`qr_of`]:
/// `R x = Qᵀ b` (`Q` formed explicitly, which keeps the motion outputs of
/// the recorded runs to the last digit; applying the Householder reflectors
/// with `QR::q_tr_mul` instead moves their last digits).
fn least_squares((q, r): &(DMatrix<f64>, DMatrix<f64>), b: &[f64]) -> Option<Vec<f64>> {
    if b.len() != q.nrows() {
        return None;
    }
    let x = r.solve_upper_triangular(&q.tr_mul(&DVector::from_column_slice(b)))?;
    x.iter()
        .all(|v| v.is_finite())
        .then(|| x.iter().copied().collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn qr_solves_square_and_least_squares() {
        let a = vec![vec![2.0, 1.0], vec![1.0, 3.0], vec![0.0, 1.0]];
        let qr = qr_of(&a).unwrap();
        // consistent right-hand side
        let x = least_squares(&qr, &[4.0, 7.0, 2.0]).unwrap();
        assert!(
            (x[0] - 1.0).abs() < 1e-12 && (x[1] - 2.0).abs() < 1e-12,
            "{x:?}"
        );
        // inconsistent: the normal equations' solution
        let x = least_squares(&qr, &[1.0, 0.0, 0.0]).unwrap();
        let ata = [[5.0, 5.0], [5.0, 11.0]];
        let atb = [2.0, 1.0];
        for i in 0..2 {
            let r = ata[i][0] * x[0] + ata[i][1] * x[1] - atb[i];
            assert!(r.abs() < 1e-12, "{x:?}");
        }
        assert!(qr_of(&[vec![1.0, 2.0], vec![2.0, 4.0]]).is_none());
    }
}
