//! Forward kinematics from the symbolic engine: the nominal tool pose relative
//! to the workpiece, its exact Jacobian with respect to the axis variables, and
//! its Taylor expansion along a motion.
//!
//! The nominal pose `R_wt(q, 0)`, `T_wt(q, 0)·tool_point` of a
//! [`SymbolicModel`] is a set of canonical polynomials in the axis variables,
//! the parameters and `sin`/`cos` of rotary variables. [`Kinematics`]
//! evaluates those polynomials over any [`Scalar`]: plain `f64` for the pose,
//! and truncated Taylor series ([`Jet`]) for derivatives — order-1 jets give
//! the exact Jacobian, order-`n` jets along a motion `q(t)` give the exact
//! Taylor coefficients of the pose. One evaluation routine serves all three.
//!
//! ```
//! use chain_core::kinematics::Kinematics;
//! let yaml = "machine: m\nbodies:\n  bed: {}\n  table: {parent: bed, joint: {type: rotary, axis: +z, variable: C}}\n  arm: {parent: table, offset: [100, 0, 0]}\nworkpiece: bed\ntool: arm\n";
//! let machine = chain_core::load_str(yaml, "m.yaml").unwrap();
//! let kin = Kinematics::from_machine(&machine);
//! let j = kin.jacobian(&[0.5], &[]);
//! // d position / dC = 100·(−sin C, cos C, 0); angular velocity +z
//! assert!((j[0][0] + 100.0 * 0.5f64.sin()).abs() < 1e-12);
//! assert!((j[0][5] - 1.0).abs() < 1e-15);
//! ```

use crate::algebra::{Poly, Symbol};
use crate::jet::Jet;
use crate::model::{JointKind, Machine};
use crate::{ErrorModel, Pose, SymbolicModel};

/// Anything that gives the nominal pose of a machine: every [`ErrorModel`]
/// (its `nominal()`) and [`Kinematics`]. The inverse-kinematics solvers need
/// no more than this.
pub trait NominalPose {
    /// `R_wt(q, 0)` and `T_wt(q, 0)·tool_point` at axis values `q` and
    /// parameter values `p`.
    fn nominal_pose(&self, q: &[f64], p: &[f64]) -> Pose;
}

impl<M: ErrorModel + ?Sized> NominalPose for M {
    fn nominal_pose(&self, q: &[f64], p: &[f64]) -> Pose {
        self.nominal(q, p)
    }
}

impl NominalPose for Kinematics {
    fn nominal_pose(&self, q: &[f64], p: &[f64]) -> Pose {
        Kinematics::pose(self, q, p)
    }
}

/// A number type the pose polynomials can be evaluated over.
pub trait Scalar: Clone {
    /// The constant `value` with no further structure (a jet of order 0).
    fn constant(value: f64) -> Self;
    /// The constant `value`, shaped like `self` (same jet order).
    fn constant_like(&self, value: f64) -> Self;
    /// `self + other`.
    fn plus(&self, other: &Self) -> Self;
    /// `self · other`.
    fn times(&self, other: &Self) -> Self;
    /// `k · self`.
    fn times_f64(&self, k: f64) -> Self;
    /// `(sin self, cos self)`.
    fn sin_cos(&self) -> (Self, Self);
}

impl Scalar for f64 {
    fn constant(value: f64) -> f64 {
        value
    }
    fn constant_like(&self, value: f64) -> f64 {
        value
    }
    fn plus(&self, other: &f64) -> f64 {
        self + other
    }
    fn times(&self, other: &f64) -> f64 {
        self * other
    }
    fn times_f64(&self, k: f64) -> f64 {
        self * k
    }
    fn sin_cos(&self) -> (f64, f64) {
        f64::sin_cos(*self)
    }
}

impl Scalar for Jet {
    fn constant(value: f64) -> Jet {
        Jet::constant(value, 0)
    }
    fn constant_like(&self, value: f64) -> Jet {
        Jet::constant(value, self.order())
    }
    fn plus(&self, other: &Jet) -> Jet {
        self + other
    }
    fn times(&self, other: &Jet) -> Jet {
        self * other
    }
    fn times_f64(&self, k: f64) -> Jet {
        self.scale(k)
    }
    fn sin_cos(&self) -> (Jet, Jet) {
        Jet::sin_cos(self)
    }
}

/// A pose over a scalar type: rotation (row-major) and position.
#[derive(Debug, Clone, PartialEq)]
pub struct PoseOf<S> {
    /// `R_wt`, row-major.
    pub rotation: [[S; 3]; 3],
    /// `T_wt · tool_point`.
    pub position: [S; 3],
}

/// The nominal forward kinematics of a machine.
#[derive(Debug, Clone, PartialEq)]
pub struct Kinematics {
    variables: Vec<(String, JointKind)>,
    parameters: Vec<(String, Option<f64>)>,
    rotation: [[Poly; 3]; 3],
    position: [Poly; 3],
}

impl Kinematics {
    /// The kinematics of a derived model.
    pub fn new(model: &SymbolicModel) -> Kinematics {
        Kinematics {
            variables: model.variables.clone(),
            parameters: model.parameters.clone(),
            rotation: model.nominal_rotation.clone(),
            position: model.nominal_position.clone(),
        }
    }

    /// Derives the machine and keeps its nominal pose.
    pub fn from_machine(machine: &Machine) -> Kinematics {
        Kinematics::new(&crate::derive(machine))
    }

    /// Axis variable names and joint kinds, in `q` order.
    pub fn variables(&self) -> &[(String, JointKind)] {
        &self.variables
    }

    /// Parameter names and the values given with the machine.
    pub fn parameters(&self) -> &[(String, Option<f64>)] {
        &self.parameters
    }

    /// The nominal pose over any scalar: `q` one value per variable, `p` one
    /// per parameter. Missing entries evaluate as `NaN`.
    pub fn pose_of<S: Scalar>(&self, q: &[S], p: &[f64]) -> PoseOf<S> {
        let like = q.first().cloned();
        let konst = |v: f64| -> S {
            match &like {
                Some(s) => s.constant_like(v),
                None => S::constant(v),
            }
        };
        let trig: Vec<Option<(S, S)>> = self
            .variables
            .iter()
            .enumerate()
            .map(|(i, (_, kind))| {
                (*kind == JointKind::Rotary)
                    .then(|| q.get(i).map(S::sin_cos))
                    .flatten()
            })
            .collect();
        let symbol = |s: Symbol| -> S {
            let at = |i: u16| usize::from(i);
            match s {
                Symbol::Param(i) => konst(p.get(at(i)).copied().unwrap_or(f64::NAN)),
                Symbol::Var(i) => q.get(at(i)).cloned().unwrap_or_else(|| konst(f64::NAN)),
                Symbol::Cos(i) => trig
                    .get(at(i))
                    .and_then(|t| t.as_ref().map(|t| t.1.clone()))
                    .unwrap_or_else(|| konst(f64::NAN)),
                Symbol::Sin(i) => trig
                    .get(at(i))
                    .and_then(|t| t.as_ref().map(|t| t.0.clone()))
                    .unwrap_or_else(|| konst(f64::NAN)),
            }
        };
        let eval = |poly: &Poly| -> S {
            let mut sum = konst(0.0);
            for (monomial, coefficient) in poly.terms() {
                let mut term = konst(*coefficient);
                for &(s, power) in &monomial.0 {
                    let v = symbol(s);
                    for _ in 0..power {
                        term = term.times(&v);
                    }
                }
                sum = sum.plus(&term);
            }
            sum
        };
        PoseOf {
            rotation: std::array::from_fn(|i| std::array::from_fn(|j| eval(&self.rotation[i][j]))),
            position: std::array::from_fn(|i| eval(&self.position[i])),
        }
    }

    /// The nominal pose at axis values `q` and parameter values `p`.
    pub fn pose(&self, q: &[f64], p: &[f64]) -> Pose {
        let pose = self.pose_of(q, p);
        Pose {
            rotation: pose.rotation,
            position: pose.position,
        }
    }

    /// The exact Jacobian of the nominal pose: one column per variable,
    /// `[∂p/∂q_k, ω_k]` where `ω_k` is the angular velocity of the tool
    /// relative to the workpiece per unit `q_k` (workpiece frame,
    /// `∂R/∂q_k = [ω_k]× R`). The tool axis moves as `∂z/∂q_k = ω_k × z`.
    pub fn jacobian(&self, q: &[f64], p: &[f64]) -> Vec<[f64; 6]> {
        (0..q.len())
            .map(|k| {
                let jets: Vec<Jet> = q
                    .iter()
                    .enumerate()
                    .map(|(i, &v)| Jet::variable(v, if i == k { 1.0 } else { 0.0 }, 1))
                    .collect();
                let pose = self.pose_of(&jets, p);
                let r: [[f64; 3]; 3] =
                    std::array::from_fn(|i| std::array::from_fn(|j| pose.rotation[i][j].value()));
                let dr: [[f64; 3]; 3] = std::array::from_fn(|i| {
                    std::array::from_fn(|j| pose.rotation[i][j].coefficients()[1])
                });
                // W = dR Rᵀ (skew); ω = vee(W).
                let w = |a: usize, b: usize| -> f64 { (0..3).map(|m| dr[a][m] * r[b][m]).sum() };
                [
                    pose.position[0].coefficients()[1],
                    pose.position[1].coefficients()[1],
                    pose.position[2].coefficients()[1],
                    0.5 * (w(2, 1) - w(1, 2)),
                    0.5 * (w(0, 2) - w(2, 0)),
                    0.5 * (w(1, 0) - w(0, 1)),
                ]
            })
            .collect()
    }

    /// The Taylor expansion of the pose along a motion whose axis values are
    /// the jets `q` (all of one order): every entry's coefficients up to that
    /// order.
    pub fn pose_series(&self, q: &[Jet], p: &[f64]) -> PoseOf<Jet> {
        self.pose_of(q, p)
    }
}
