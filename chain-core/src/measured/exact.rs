//! The exact (not linearised) tool-point deviation of a machine with finite
//! error values, and its exact derivatives in the errors: what
//! `chain identify` checks its first-order fit against and
//! what its exact-kinematics iteration solves.
//!
//! # Formulas
//!
//! Each body is placed by `Trans(offset) · Rot(rotation) · E(v_loc) · J(q) ·
//! E(v_err)` (machine-format spec §1), each slot value `v_s = Σ_j w_j(q) e_j`
//! (`w_j` the basis function of a function-slot coefficient at its joint
//! variable, else 1). The spec defines `E` to first order; the exact
//! transform of finite errors is taken as `E(d, ω) = [exp([ω×]), d]`
//! (rotation by the rotation vector `ω = (ex, ey, ez)`, then the
//! translation `d`), whose first order is the spec's. The deviation is
//! `p(q, e) = T_wt(q, e)·t − T_wt(q, 0)·t` (`T_wt = P(workpiece)⁻¹ P(tool)`,
//! `t` the tool point), in the tool frame `R_wt(q, 0)ᵀ p` with `frame:
//! tool`.
//!
//! Derivatives, one error factor at a time (a factor `E` between the
//! prefix `L` and the suffix `R` of its branch):
//!
//! - tool branch, `x = P_w⁻¹ L E R t`: `∂x/∂d_s = P_w⁻¹ L_rot e_s`,
//!   `∂x/∂ω_s = P_w⁻¹ L_rot ((J_l(ω) e_s) × (exp([ω×]) y))`, `y = R t`;
//! - workpiece branch, `x = R⁻¹ E⁻¹ L⁻¹ z` (`z = P_t t`, `u = L⁻¹ z − d`):
//!   `∂x/∂d_s = −R⁻¹_rot exp([ω×])ᵀ e_s`, `∂x/∂ω_s = −R⁻¹_rot ((J_l(−ω)
//!   e_s) × (exp([ω×])ᵀ u))`;
//!
//! with the left Jacobian of SO(3), `J_l(ω) = I + (1 − cos θ)/θ² [ω×] +
//! (θ − sin θ)/θ³ [ω×]²` (`θ = |ω|`; Taylor series below θ = 1e-4), since
//! `∂/∂ω_s exp([ω×]) y = (J_l(ω) e_s) × exp([ω×]) y`. Each slot's
//! derivative is then spread over its errors by the weights `w_j(q)`.

use nalgebra::{DMatrix, Matrix3, Rotation3, Vector3};

use crate::model::{ErrorSlots, Frame, JointKind, Machine};

/// A rigid transform: rotation and translation.
#[derive(Debug, Clone, Copy)]
struct Rigid {
    r: Matrix3<f64>,
    t: Vector3<f64>,
}

impl Rigid {
    fn identity() -> Rigid {
        Rigid {
            r: Matrix3::identity(),
            t: Vector3::zeros(),
        }
    }
    fn then(&self, o: &Rigid) -> Rigid {
        Rigid {
            r: self.r * o.r,
            t: self.r * o.t + self.t,
        }
    }
    fn inverse(&self) -> Rigid {
        let rt = self.r.transpose();
        Rigid {
            r: rt,
            t: -(rt * self.t),
        }
    }
    fn apply(&self, x: &Vector3<f64>) -> Vector3<f64> {
        self.r * x + self.t
    }
}

/// `[ω×]`.
fn skew(w: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -w.z, w.y, w.z, 0.0, -w.x, -w.y, w.x, 0.0)
}

/// The left Jacobian of SO(3) at the rotation vector `w`.
fn left_jacobian(w: &Vector3<f64>) -> Matrix3<f64> {
    let th2 = w.norm_squared();
    let th = th2.sqrt();
    let (a, b) = if th < 1e-4 {
        (0.5 - th2 / 24.0, 1.0 / 6.0 - th2 / 120.0)
    } else {
        ((1.0 - th.cos()) / th2, (th - th.sin()) / (th2 * th))
    };
    let k = skew(w);
    Matrix3::identity() + k * a + k * k * b
}

/// The exact error transform `E(d, ω)`.
fn error_transform(v: &[f64; 6]) -> Rigid {
    let w = Vector3::new(v[3], v[4], v[5]);
    Rigid {
        r: *Rotation3::from_scaled_axis(w).matrix(),
        t: Vector3::new(v[0], v[1], v[2]),
    }
}

/// One factor of a branch product: fixed, or an error factor with its
/// slot values and which error slots feed it.
enum Factor<'a> {
    Fixed(Rigid),
    Error([f64; 6], &'a ErrorSlots),
}

/// The nominal tool point at a pose and the rotation into the machine
/// file's frame ([`ExactChain::nominal`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Nominal {
    /// `T_wt(q, 0) · t`: the tool point in the workpiece frame.
    pub point: [f64; 3],
    /// `P(tool)(q, 0) · t`: the tool point in the root body's (the bed's)
    /// frame, where the axes move it.
    pub in_root: [f64; 3],
    /// From the workpiece frame into the machine file's: `I` with `frame:
    /// workpiece`, `R_wt(q, 0)ᵀ` with `frame: tool` (machine-format spec
    /// §1).
    pub to_frame: [[f64; 3]; 3],
}

impl Nominal {
    /// A workpiece-frame vector `v` in the machine file's frame.
    pub fn in_frame(&self, v: [f64; 3]) -> [f64; 3] {
        let r = &self.to_frame;
        std::array::from_fn(|i| r[i][0] * v[0] + r[i][1] * v[1] + r[i][2] * v[2])
    }
}

/// The exact kinematics of a machine with finite error values.
#[derive(Debug, Clone, Copy)]
pub struct ExactChain<'m> {
    machine: &'m Machine,
}

impl<'m> ExactChain<'m> {
    /// The evaluator of `machine`.
    pub fn new(machine: &'m Machine) -> ExactChain<'m> {
        ExactChain { machine }
    }

    /// The weight `w_j(q)` of every error in its slots: the basis function
    /// of a function-slot coefficient at its joint variable, else 1. A
    /// thermal coefficient's thermal factor is the caller's to apply (to
    /// the errors and the Jacobian's columns, as
    /// [`crate::thermal_state::AtState`] does): the chain is the geometry's.
    pub fn weights(&self, q: &[f64]) -> Vec<f64> {
        let mut w = vec![1.0; self.machine.errors.len()];
        for f in &self.machine.functions {
            for (k, b) in &f.coefficients {
                w[*k] = b.value(q[f.variable]);
            }
        }
        w
    }

    /// The factors of `P(b)` from the root.
    fn factors(&self, b: usize, q: &[f64], p: &[f64], e: &[f64], w: &[f64]) -> Vec<Factor<'m>> {
        let slot = |s: &ErrorSlots| -> [f64; 6] {
            std::array::from_fn(|k| s.slots[k].iter().map(|&j| w[j] * e[j]).sum())
        };
        let mut out = Vec::new();
        for k in self.machine.path_from_root(b) {
            let body = &self.machine.bodies[k];
            let mut fixed = Rigid {
                r: Matrix3::identity(),
                t: Vector3::from_fn(|i, _| body.offset[i].eval(p)),
            };
            for rot in &body.rotation {
                let axis = Vector3::ith(rot.about.index(), 1.0);
                fixed = fixed.then(&Rigid {
                    r: *Rotation3::from_scaled_axis(axis * rot.angle).matrix(),
                    t: Vector3::zeros(),
                });
            }
            out.push(Factor::Fixed(fixed));
            out.push(Factor::Error(
                slot(&body.location_errors),
                &body.location_errors,
            ));
            if let Some(joint) = &body.joint {
                let a = joint.axis.axis.index();
                let v = joint.axis.sign() * q[joint.variable];
                let j = match joint.kind {
                    JointKind::Prismatic => Rigid {
                        r: Matrix3::identity(),
                        t: Vector3::ith(a, v),
                    },
                    JointKind::Rotary => Rigid {
                        r: *Rotation3::from_scaled_axis(Vector3::ith(a, v)).matrix(),
                        t: Vector3::zeros(),
                    },
                };
                out.push(Factor::Fixed(j));
            }
            out.push(Factor::Error(slot(&body.errors), &body.errors));
        }
        out
    }

    /// The product of `factors`.
    fn product(factors: &[Factor<'_>]) -> Rigid {
        factors.iter().fold(Rigid::identity(), |acc, f| match f {
            Factor::Fixed(t) => acc.then(t),
            Factor::Error(v, _) => acc.then(&error_transform(v)),
        })
    }

    /// `T_wt(q, e)` and the tool point.
    fn pose(&self, q: &[f64], p: &[f64], e: &[f64]) -> (Rigid, Vector3<f64>) {
        let w = self.weights(q);
        let pw = Self::product(&self.factors(self.machine.workpiece, q, p, e, &w));
        let pt = Self::product(&self.factors(self.machine.tool, q, p, e, &w));
        let tp = Vector3::from_fn(|i, _| self.machine.tool_point[i].eval(p));
        (pw.inverse().then(&pt), tp)
    }

    /// The nominal tool point and the rotation into the machine's frame at
    /// `(q, p)`.
    pub fn nominal(&self, q: &[f64], p: &[f64]) -> Nominal {
        let zero = vec![0.0; self.machine.errors.len()];
        let (t0, tp) = self.pose(q, p, &zero);
        let x = t0.apply(&tp);
        let w = self.weights(q);
        let root = Self::product(&self.factors(self.machine.tool, q, p, &zero, &w)).apply(&tp);
        let to_frame = match self.machine.frame {
            Frame::Workpiece => Matrix3::identity(),
            Frame::Tool => t0.r.transpose(),
        };
        Nominal {
            point: [x.x, x.y, x.z],
            in_root: [root.x, root.y, root.z],
            to_frame: std::array::from_fn(|i| std::array::from_fn(|j| to_frame[(i, j)])),
        }
    }

    /// The exact tool-point deviation `p(q, e)` in the machine's frame
    /// (module docs).
    pub fn deviation(&self, q: &[f64], p: &[f64], e: &[f64]) -> [f64; 3] {
        let zero = vec![0.0; self.machine.errors.len()];
        let (t0, tp) = self.pose(q, p, &zero);
        let (te, _) = self.pose(q, p, e);
        let d = te.apply(&tp) - t0.apply(&tp);
        let d = match self.machine.frame {
            Frame::Workpiece => d,
            Frame::Tool => t0.r.transpose() * d,
        };
        [d.x, d.y, d.z]
    }

    /// The deviation and its exact derivatives `∂p/∂e_j` (3 × n, in the
    /// machine's frame) at `(q, p, e)` (module docs).
    pub fn deviation_and_jacobian(
        &self,
        q: &[f64],
        p: &[f64],
        e: &[f64],
    ) -> ([f64; 3], DMatrix<f64>) {
        let n = self.machine.errors.len();
        let w = self.weights(q);
        let zero = vec![0.0; n];
        let (t0, tp) = self.pose(q, p, &zero);
        let wf = self.factors(self.machine.workpiece, q, p, e, &w);
        let tf = self.factors(self.machine.tool, q, p, e, &w);
        let pw = Self::product(&wf);
        let pt = Self::product(&tf);
        let pw_inv = pw.inverse();
        let x = pw_inv.then(&pt).apply(&tp);
        let d = x - t0.apply(&tp);
        let to_frame = match self.machine.frame {
            Frame::Workpiece => Matrix3::identity(),
            Frame::Tool => t0.r.transpose(),
        };
        let d = to_frame * d;
        let mut jac = DMatrix::zeros(3, n);
        let mut add = |slots: &ErrorSlots, grads: [Vector3<f64>; 6]| {
            for (s, g) in grads.iter().enumerate() {
                let g = to_frame * g;
                for &j in &slots.slots[s] {
                    for r in 0..3 {
                        jac[(r, j)] += w[j] * g[r];
                    }
                }
            }
        };
        // Tool branch: x = P_w⁻¹ L E R t.
        let mut prefix = Rigid::identity();
        for (i, f) in tf.iter().enumerate() {
            match f {
                Factor::Fixed(t) => prefix = prefix.then(t),
                Factor::Error(v, slots) => {
                    let e_t = error_transform(v);
                    let y = Self::product(&tf[i + 1..]).apply(&tp);
                    let lr = pw_inv.r * prefix.r;
                    let jl = left_jacobian(&Vector3::new(v[3], v[4], v[5]));
                    let ry = e_t.r * y;
                    let grads: [Vector3<f64>; 6] = std::array::from_fn(|s| {
                        if s < 3 {
                            lr * Vector3::ith(s, 1.0)
                        } else {
                            lr * (jl * Vector3::ith(s - 3, 1.0)).cross(&ry)
                        }
                    });
                    add(slots, grads);
                    prefix = prefix.then(&e_t);
                }
            }
        }
        // Workpiece branch: x = R⁻¹ E⁻¹ L⁻¹ z.
        let z = pt.apply(&tp);
        let mut prefix = Rigid::identity();
        for (i, f) in wf.iter().enumerate() {
            match f {
                Factor::Fixed(t) => prefix = prefix.then(t),
                Factor::Error(v, slots) => {
                    let e_t = error_transform(v);
                    let rest_inv = Self::product(&wf[i + 1..]).inverse();
                    let u = prefix.inverse().apply(&z) - e_t.t;
                    let ert = e_t.r.transpose();
                    let jr = left_jacobian(&-Vector3::new(v[3], v[4], v[5]));
                    let rtu = ert * u;
                    let grads: [Vector3<f64>; 6] = std::array::from_fn(|s| {
                        if s < 3 {
                            -(rest_inv.r * ert * Vector3::ith(s, 1.0))
                        } else {
                            -(rest_inv.r * (jr * Vector3::ith(s - 3, 1.0)).cross(&rtu))
                        }
                    });
                    add(slots, grads);
                    prefix = prefix.then(&e_t);
                }
            }
        }
        ([d.x, d.y, d.z], jac)
    }
}
