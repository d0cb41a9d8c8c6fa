//! An independent, purely numeric implementation of the kinematic semantics of
//! `shared/spec/machine-format.md` section 1, used to check the symbolic engine.
//!
//! Nothing here is linearised: every body transform is the full 4×4 product
//!
//! ```text
//! T(parent -> body) = Trans(offset) · Rot(rotation) · E(location_errors) · J(q) · E(errors + squareness)
//! ```
//!
//! with `E(d, ε)` the exact rigid transform whose rotation is `exp([ε×])`
//! (Rodrigues) and whose translation is `d`; to first order this is the spec's
//! `[[1, -ez, ey, dx], [ez, 1, -ex, dy], [-ey, ex, 1, dz], [0, 0, 0, 1]]`.
//! `T_wt = inv(P(workpiece)) · P(tool)`, `p = T_wt(q, e)·tp - T_wt(q, 0)·tp`,
//! `o = vee(skew(R_wt(q, e) · R_wt(q, 0)ᵀ))`, rotated by `R_wt(q, 0)ᵀ` for
//! `frame: tool`. The first-order model is the derivative of these at `e = 0`,
//! which [`Exact::fd_sensitivity`] estimates by a 5-point central difference.
//!
//! A function slot (measured-machines spec, section 1) holds
//! `F(q) = Σ_k F_k b_k(q)` of its body's own variable; its value enters `E`
//! like any slot value, with `b_k(q)` from `BasisFn::value` (numeric
//! recurrences and `cos`/`sin`, not the symbolic engine's polynomials).
//!
//! It reads the validated [`Machine`] directly and shares no code with
//! `chain-core`'s derivation (only `Expr::eval` for offsets and tool points
//! and `BasisFn::value` for function slots).
//!
//! Index conventions inside this module: `q` is indexed like
//! `machine.variables`, `p` like `machine.parameters`, `e` like
//! `machine.errors`. The model under test has its own name lists; the helpers
//! [`by_names`] and [`Exact::model_sensitivity`] translate by name.
//!
//! Shared by the other tests too: [`root`], [`example_file`] and
//! [`example_path`] locate the example files, and the submodule [`cli`] runs
//! the `chain` binary and makes the scratch files it is given.
// Matrix code reads best with explicit indices.
#![allow(dead_code, clippy::needless_range_loop)]

pub mod cli;
pub mod wang_yuan_2021;

use chain_core::model::{
    Basis, ErrorFunction, ErrorKind, ErrorParam, ErrorSlots, Frame, JointKind, Machine, Slot,
};
use chain_core::ErrorModel;

/// Row-major 3×3 matrix.
pub type Mat3 = [[f64; 3]; 3];
/// Row-major homogeneous 4×4 matrix.
pub type Mat4 = [[f64; 4]; 4];

/// The 4×4 identity.
pub fn identity4() -> Mat4 {
    let mut m = [[0.0; 4]; 4];
    for (i, row) in m.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    m
}

/// `a · b` for 4×4 matrices.
pub fn mul4(a: &Mat4, b: &Mat4) -> Mat4 {
    let mut m = [[0.0; 4]; 4];
    for i in 0..4 {
        for j in 0..4 {
            m[i][j] = (0..4).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    m
}

/// `a · b` for 3×3 matrices.
pub fn mul3(a: &Mat3, b: &Mat3) -> Mat3 {
    let mut m = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            m[i][j] = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    m
}

/// `aᵀ`.
pub fn transpose3(a: &Mat3) -> Mat3 {
    std::array::from_fn(|i| std::array::from_fn(|j| a[j][i]))
}

/// `a · v`.
pub fn apply3(a: &Mat3, v: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| (0..3).map(|k| a[i][k] * v[k]).sum())
}

/// The homogeneous transform with rotation `r` and translation `t`.
pub fn rigid(r: &Mat3, t: [f64; 3]) -> Mat4 {
    let mut m = identity4();
    for i in 0..3 {
        for j in 0..3 {
            m[i][j] = r[i][j];
        }
        m[i][3] = t[i];
    }
    m
}

/// Rotation block of a homogeneous transform.
pub fn rotation(m: &Mat4) -> Mat3 {
    std::array::from_fn(|i| std::array::from_fn(|j| m[i][j]))
}

/// Translation column of a homogeneous transform.
pub fn translation(m: &Mat4) -> [f64; 3] {
    [m[0][3], m[1][3], m[2][3]]
}

/// `m · (v, 1)`.
pub fn transform_point(m: &Mat4, v: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2] + m[i][3])
}

/// Inverse of a rigid transform: `[Rᵀ, -Rᵀ t]`.
pub fn rigid_inverse(m: &Mat4) -> Mat4 {
    let rt = transpose3(&rotation(m));
    let t = apply3(&rt, translation(m));
    rigid(&rt, [-t[0], -t[1], -t[2]])
}

/// The elementary rotation by `angle` (right-hand rule) about axis `k`
/// (0 = x, 1 = y, 2 = z).
pub fn rot_axis(k: usize, angle: f64) -> Mat3 {
    let (s, c) = angle.sin_cos();
    match k {
        0 => [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]],
        1 => [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]],
        _ => [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]],
    }
}

/// `exp([w×])` by Rodrigues' formula (series for tiny angles).
pub fn exp_so3(w: [f64; 3]) -> Mat3 {
    let theta2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
    let theta = theta2.sqrt();
    let (a, b) = if theta < 1e-6 {
        (1.0 - theta2 / 6.0, 0.5 - theta2 / 24.0)
    } else {
        (theta.sin() / theta, (1.0 - theta.cos()) / theta2)
    };
    let k = [[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]];
    let k2 = mul3(&k, &k);
    std::array::from_fn(|i| {
        std::array::from_fn(|j| f64::from(u8::from(i == j)) + a * k[i][j] + b * k2[i][j])
    })
}

/// The exact small-error transform `E(dx, dy, dz, ex, ey, ez)`: rotation
/// `exp([ε×])`, translation `d`.
pub fn error_transform(v: [f64; 6]) -> Mat4 {
    rigid(&exp_so3([v[3], v[4], v[5]]), [v[0], v[1], v[2]])
}

/// `vee(skew(m))`: the `o` with `skew(m) = [o×]`.
pub fn vee_skew(m: &Mat3) -> [f64; 3] {
    [
        0.5 * (m[2][1] - m[1][2]),
        0.5 * (m[0][2] - m[2][0]),
        0.5 * (m[1][0] - m[0][1]),
    ]
}

/// A standard normal deviate (Box–Muller over the tests' generator).
pub fn gauss(rng: &mut Rng) -> f64 {
    let u1 = rng.unit().max(1e-300);
    let u2 = rng.unit();
    (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
}

/// Point records as a measurement CSV: `header` (the pose columns, then
/// `dpx,dpy,dpz`), each row the pose then the measured values, in full
/// precision.
pub fn point_csv(header: &str, records: &[chain_core::measured::Measurement]) -> String {
    let mut csv = format!("{header}\n");
    for r in records {
        let cells: Vec<String> =
            r.q.iter()
                .chain(&r.values)
                .map(|v| format!("{v:?}"))
                .collect();
        csv.push_str(&(cells.join(",") + "\n"));
    }
    csv
}

/// `[mean, max, rms]` of per-record squared 3-vector errors, as
/// `chain identify`'s prediction reports them (mean and max of `|dp|`, rms
/// over the scalar rows).
fn point_error_stats(squares: &[f64]) -> [f64; 3] {
    let mean = squares.iter().map(|s| s.sqrt()).sum::<f64>() / squares.len() as f64;
    let max = squares.iter().map(|s| s.sqrt()).fold(0.0, f64::max);
    let rms = (squares.iter().sum::<f64>() / (3 * squares.len()) as f64).sqrt();
    [mean, max, rms]
}

/// The held-out error statistics `[mean, max, rms]` of point records
/// before correction (the measured values) and after it (less the exact
/// product's deviation with the values `x` at each record's pose): the
/// independent computation `chain identify`'s prediction is checked
/// against.
pub fn held_out_stats(
    exact: &Exact,
    records: &[&chain_core::measured::Measurement],
    x: &[f64],
) -> ([f64; 3], [f64; 3]) {
    let (mut before, mut after) = (Vec::new(), Vec::new());
    for r in records {
        let predicted = exact.exact_error(&r.q, &r.p, x);
        before.push(r.values.iter().map(|v| v * v).sum::<f64>());
        after.push(
            (0..3)
                .map(|c| (r.values[c] - predicted[c]).powi(2))
                .sum::<f64>(),
        );
    }
    (point_error_stats(&before), point_error_stats(&after))
}

/// Random axis values: angles in [-angle, angle) rad, slides in
/// [-500, 500) mm.
pub fn random_q(kinds: &[JointKind], rng: &mut Rng, angle: f64) -> Vec<f64> {
    kinds
        .iter()
        .map(|k| match k {
            JointKind::Rotary => rng.range(-angle, angle),
            JointKind::Prismatic => rng.range(-500.0, 500.0),
        })
        .collect()
}

/// A small deterministic generator (SplitMix64) for random test points.
#[derive(Debug, Clone)]
pub struct Rng(u64);

impl Rng {
    /// A generator from a seed.
    pub fn new(seed: u64) -> Rng {
        Rng(seed)
    }

    /// Next raw 64-bit value.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`.
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in `[lo, hi)`.
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
}

/// Values for the names of `names` (a model's variable, parameter or error
/// list), looked up by name.
pub fn by_names(names: &[&str], value: impl Fn(&str) -> f64) -> Vec<f64> {
    names.iter().map(|n| value(n)).collect()
}

/// The exact numeric machine.
pub struct Exact<'m> {
    /// The validated machine.
    pub machine: &'m Machine,
}

impl<'m> Exact<'m> {
    /// Wraps a machine.
    pub fn new(machine: &'m Machine) -> Exact<'m> {
        Exact { machine }
    }

    /// Parameter values from the file (`NaN` for symbolic ones), in
    /// `machine.parameters` order.
    pub fn file_parameters(&self) -> Vec<f64> {
        self.machine
            .parameters
            .iter()
            .map(|p| p.value.unwrap_or(f64::NAN))
            .collect()
    }

    /// The weight of error `j` at `q`: `b_k(q_v)` if it is the coefficient of
    /// basis function `b_k` of a function slot of variable `v`, else 1.
    pub fn weight(&self, j: usize, q: &[f64]) -> f64 {
        for f in &self.machine.functions {
            for (k, b) in &f.coefficients {
                if *k == j {
                    return b.value(q[f.variable]);
                }
            }
        }
        1.0
    }

    /// Summed slot values of an error-slot set: `Σ_j w_j(q)·e_j` per slot.
    fn slot_values(&self, slots: &ErrorSlots, q: &[f64], e: &[f64]) -> [f64; 6] {
        std::array::from_fn(|s| {
            slots.slots[s]
                .iter()
                .map(|&j| self.weight(j, q) * e[j])
                .sum()
        })
    }

    /// `T(parent -> body)`, exact.
    pub fn body_transform(&self, b: usize, q: &[f64], p: &[f64], e: &[f64]) -> Mat4 {
        let body = &self.machine.bodies[b];
        let offset: [f64; 3] = std::array::from_fn(|i| body.offset[i].eval(p));
        let mut t = rigid(&rot_axis(0, 0.0), offset);
        for r in &body.rotation {
            t = mul4(&t, &rigid(&rot_axis(r.about.index(), r.angle), [0.0; 3]));
        }
        t = mul4(
            &t,
            &error_transform(self.slot_values(&body.location_errors, q, e)),
        );
        if let Some(joint) = &body.joint {
            let k = joint.axis.axis.index();
            let v = joint.axis.sign() * q[joint.variable];
            let j = match joint.kind {
                JointKind::Prismatic => {
                    let mut d = [0.0; 3];
                    d[k] = v;
                    rigid(&rot_axis(0, 0.0), d)
                }
                JointKind::Rotary => rigid(&rot_axis(k, v), [0.0; 3]),
            };
            t = mul4(&t, &j);
        }
        mul4(&t, &error_transform(self.slot_values(&body.errors, q, e)))
    }

    /// `P(b)`: the product of the body transforms from the root to `b`
    /// (the root's own transform included; it cancels in `T_wt`).
    pub fn pose(&self, b: usize, q: &[f64], p: &[f64], e: &[f64]) -> Mat4 {
        self.machine
            .path_from_root(b)
            .into_iter()
            .fold(identity4(), |acc, k| {
                mul4(&acc, &self.body_transform(k, q, p, e))
            })
    }

    /// `T_wt(q, e) = inv(P(workpiece)) · P(tool)`.
    pub fn t_wt(&self, q: &[f64], p: &[f64], e: &[f64]) -> Mat4 {
        let w = self.pose(self.machine.workpiece, q, p, e);
        let t = self.pose(self.machine.tool, q, p, e);
        mul4(&rigid_inverse(&w), &t)
    }

    /// The tool point in the tool frame.
    pub fn tool_point(&self, p: &[f64]) -> [f64; 3] {
        std::array::from_fn(|i| self.machine.tool_point[i].eval(p))
    }

    /// `R_wt(q, 0)` and `T_wt(q, 0) · tool_point`.
    pub fn nominal(&self, q: &[f64], p: &[f64]) -> (Mat3, [f64; 3]) {
        let zero = vec![0.0; self.machine.errors.len()];
        let t = self.t_wt(q, p, &zero);
        (rotation(&t), transform_point(&t, self.tool_point(p)))
    }

    /// The full (non-linearised) error `[px, py, pz, ox, oy, oz]` at error
    /// values `e`, in the machine's frame.
    pub fn exact_error(&self, q: &[f64], p: &[f64], e: &[f64]) -> [f64; 6] {
        self.exact_error_in(self.machine.frame, q, p, e)
    }

    /// The full error in a given frame.
    pub fn exact_error_in(&self, frame: Frame, q: &[f64], p: &[f64], e: &[f64]) -> [f64; 6] {
        let zero = vec![0.0; self.machine.errors.len()];
        let t0 = self.t_wt(q, p, &zero);
        let te = self.t_wt(q, p, e);
        let tp = self.tool_point(p);
        let a = transform_point(&te, tp);
        let b = transform_point(&t0, tp);
        let pos = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
        let r0 = rotation(&t0);
        let ori = vee_skew(&mul3(&rotation(&te), &transpose3(&r0)));
        let (pos, ori) = match frame {
            Frame::Workpiece => (pos, ori),
            Frame::Tool => {
                let r0t = transpose3(&r0);
                (apply3(&r0t, pos), apply3(&r0t, ori))
            }
        };
        [pos[0], pos[1], pos[2], ori[0], ori[1], ori[2]]
    }

    /// The 6×N sensitivity (row-major, `machine.errors` order) by a 5-point
    /// central difference of [`Exact::exact_error`] at `e = 0` with step `h`
    /// (truncation `O(h⁴)`).
    pub fn fd_sensitivity(&self, q: &[f64], p: &[f64], h: f64) -> Vec<f64> {
        self.fd_sensitivity_in(self.machine.frame, q, p, h)
    }

    /// [`Exact::fd_sensitivity`] in a given frame.
    pub fn fd_sensitivity_in(&self, frame: Frame, q: &[f64], p: &[f64], h: f64) -> Vec<f64> {
        let n = self.machine.errors.len();
        let mut out = vec![0.0; 6 * n];
        let mut e = vec![0.0; n];
        for j in 0..n {
            // A coefficient moves its slot by w_j(q)·e_j: the step is scaled so
            // that the slot moves by h (1 for constant errors: unchanged).
            let h = h / self.weight(j, q).abs().max(1.0);
            let mut at = |s: f64| {
                e[j] = s * h;
                let v = self.exact_error_in(frame, q, p, &e);
                e[j] = 0.0;
                v
            };
            let (m2, m1, p1, p2) = (at(-2.0), at(-1.0), at(1.0), at(2.0));
            for c in 0..6 {
                out[c * n + j] = (m2[c] - 8.0 * m1[c] + 8.0 * p1[c] - p2[c]) / (12.0 * h);
            }
        }
        out
    }

    /// A length scale of the machine at a point: 1 + the sum of the absolute
    /// offsets, tool point and prismatic axis values. Used for absolute
    /// tolerance floors.
    pub fn length_scale(&self, q: &[f64], p: &[f64]) -> f64 {
        let mut s = 1.0;
        for b in &self.machine.bodies {
            s += b.offset.iter().map(|x| x.eval(p).abs()).sum::<f64>();
            if let Some(j) = &b.joint {
                if j.kind == JointKind::Prismatic {
                    s += q[j.variable].abs();
                }
            }
        }
        s + self.tool_point(p).iter().map(|v| v.abs()).sum::<f64>()
    }

    /// `q` in the model's variable order from machine-ordered values.
    pub fn q_for<M: ErrorModel + ?Sized>(&self, model: &M, q: &[f64]) -> Vec<f64> {
        by_names(model.variables(), |n| {
            self.machine.variable_index(n).map_or(f64::NAN, |i| q[i])
        })
    }

    /// `p` in the model's parameter order from machine-ordered values.
    pub fn p_for<M: ErrorModel + ?Sized>(&self, model: &M, p: &[f64]) -> Vec<f64> {
        by_names(model.parameters(), |n| {
            self.machine.parameter_index(n).map_or(f64::NAN, |i| p[i])
        })
    }

    /// `e` in the model's error order from machine-ordered values.
    pub fn e_for<M: ErrorModel + ?Sized>(&self, model: &M, e: &[f64]) -> Vec<f64> {
        by_names(model.errors(), |n| {
            self.machine.error_index(n).map_or(f64::NAN, |i| e[i])
        })
    }

    /// The model's sensitivity at machine-ordered `q`, `p`, re-indexed to
    /// `machine.errors` order (row-major 6×N). Panics if the model's error
    /// names are not exactly the machine's.
    pub fn model_sensitivity<M: ErrorModel + ?Sized>(
        &self,
        model: &M,
        q: &[f64],
        p: &[f64],
    ) -> Vec<f64> {
        let names = model.errors();
        let n = self.machine.errors.len();
        assert_eq!(names.len(), n, "model and machine error counts differ");
        let mut s = vec![0.0; 6 * n];
        model.sensitivity(&self.q_for(model, q), &self.p_for(model, p), &mut s);
        let mut out = vec![0.0; 6 * n];
        for (k, name) in names.iter().enumerate() {
            let j = self
                .machine
                .error_index(name)
                .unwrap_or_else(|| panic!("model error {name} not in the machine"));
            for c in 0..6 {
                out[c * n + j] = s[c * n + k];
            }
        }
        out
    }

    /// Compares the model's sensitivity with the finite difference of the exact
    /// product: `|model - fd| <= rel · max(|model|, |fd|) + floor · scale · w_j`
    /// (`w_j = max(1, |b_k(q)|)` for a coefficient, 1 for a constant error).
    /// Returns a description of the first mismatch.
    pub fn check_sensitivity<M: ErrorModel + ?Sized>(
        &self,
        model: &M,
        q: &[f64],
        p: &[f64],
        rel: f64,
        floor: f64,
    ) -> Result<(), String> {
        let n = self.machine.errors.len();
        let s = self.model_sensitivity(model, q, p);
        let fd = self.fd_sensitivity(q, p, 1e-3);
        let scale = self.length_scale(q, p);
        for j in 0..n {
            // A coefficient's column is its weight times a plain error's:
            // so is the floor (1 for constant errors: unchanged).
            let floor = floor * self.weight(j, q).abs().max(1.0);
            for c in 0..6 {
                let (a, b) = (s[c * n + j], fd[c * n + j]);
                let tol = rel * a.abs().max(b.abs()) + floor * scale;
                if !within(a - b, tol) {
                    return Err(format!(
                        "d{}/d{} at q = {q:?}, p = {p:?}: model {a}, finite difference {b} (tol {tol})",
                        ["px", "py", "pz", "ox", "oy", "oz"][c],
                        self.machine.errors[j].name
                    ));
                }
            }
        }
        Ok(())
    }

    /// Checks `error(q, p, e) = sensitivity(q, p) · e` (to `rel` of the sum of
    /// the absolute terms) and `nominal()` against the exact product (to `rel`
    /// of the length scale).
    pub fn check_error_and_nominal<M: ErrorModel + ?Sized>(
        &self,
        model: &M,
        q: &[f64],
        p: &[f64],
        e: &[f64],
        rel: f64,
    ) -> Result<(), String> {
        let n = self.machine.errors.len();
        let s = self.model_sensitivity(model, q, p);
        let mut out = [0.0; 6];
        model.error(
            &self.q_for(model, q),
            &self.p_for(model, p),
            &self.e_for(model, e),
            &mut out,
        );
        for c in 0..6 {
            let expect: f64 = (0..n).map(|j| s[c * n + j] * e[j]).sum();
            let mag: f64 = (0..n).map(|j| (s[c * n + j] * e[j]).abs()).sum();
            if !within(out[c] - expect, rel * mag + 1e-300) {
                return Err(format!(
                    "error()[{c}] = {} but sensitivity · e = {expect} at q = {q:?}",
                    out[c]
                ));
            }
        }
        let pose = model.nominal(&self.q_for(model, q), &self.p_for(model, p));
        let (r, pos) = self.nominal(q, p);
        let scale = self.length_scale(q, p);
        for i in 0..3 {
            for j in 0..3 {
                if !within(pose.rotation[i][j] - r[i][j], rel) {
                    return Err(format!(
                        "nominal rotation[{i}][{j}] = {} but the exact product gives {} at q = {q:?}",
                        pose.rotation[i][j], r[i][j]
                    ));
                }
            }
            if !within(pose.position[i] - pos[i], rel * scale) {
                return Err(format!(
                    "nominal position[{i}] = {} but the exact product gives {} at q = {q:?}",
                    pose.position[i], pos[i]
                ));
            }
        }
        Ok(())
    }
}

/// Standard normal CDF `Φ(x) = erfc(-x/√2)/2`, with `erfc` from W. J. Cody's
/// rational Chebyshev approximations (relative error below 1e-14).
pub fn normal_cdf(x: f64) -> f64 {
    0.5 * erfc(-x / std::f64::consts::SQRT_2)
}

/// Complementary error function (Cody 1969).
pub fn erfc(x: f64) -> f64 {
    let ax = x.abs();
    let r = if ax < 0.5 {
        // erf for small |x|
        const A: [f64; 5] = [
            3.161_123_743_870_565_6,
            113.864_154_151_050_16,
            377.485_237_685_302,
            3_209.377_589_138_469_4,
            0.185_777_706_184_603_15,
        ];
        const B: [f64; 4] = [
            23.601_290_952_344_122,
            244.024_637_934_444_17,
            1_282.616_526_077_372_3,
            2_844.236_833_439_171,
        ];
        let y = x * x;
        let mut num = A[4] * y;
        let mut den = y;
        for i in 0..3 {
            num = (num + A[i]) * y;
            den = (den + B[i]) * y;
        }
        return 1.0 - x * (num + A[3]) / (den + B[3]);
    } else if ax <= 4.0 {
        const C: [f64; 9] = [
            0.564_188_496_988_670_1,
            8.883_149_794_388_376,
            66.119_190_637_141_63,
            298.635_138_197_400_1,
            881.952_221_241_769,
            1_712.047_612_634_070_7,
            2_051.078_377_826_071_6,
            1_230.339_354_797_997_2,
            2.153_115_354_744_038_5e-8,
        ];
        const D: [f64; 8] = [
            15.744_926_110_709_835,
            117.693_950_891_312_5,
            537.181_101_862_009_9,
            1_621.389_574_566_690_3,
            3_290.799_235_733_459_7,
            4_362.619_090_143_247,
            3_439.367_674_143_721_6,
            1_230.339_354_803_749_5,
        ];
        let mut num = C[8] * ax;
        let mut den = ax;
        for i in 0..7 {
            num = (num + C[i]) * ax;
            den = (den + D[i]) * ax;
        }
        let r = (num + C[7]) / (den + D[7]);
        let ysq = (ax * 16.0).trunc() / 16.0;
        let del = (ax - ysq) * (ax + ysq);
        (-ysq * ysq).exp() * (-del).exp() * r
    } else {
        const P: [f64; 6] = [
            0.305_326_634_961_232_36,
            0.360_344_899_949_804_45,
            0.125_781_726_111_229_25,
            0.016_083_785_148_742_275,
            6.587_491_615_298_378e-4,
            0.016_315_387_137_302_097,
        ];
        const Q: [f64; 5] = [
            2.568_520_192_289_822,
            1.872_952_849_923_460_4,
            0.527_905_102_951_428_4,
            0.060_518_341_312_441_32,
            0.002_335_204_976_268_691_8,
        ];
        let y = 1.0 / (ax * ax);
        let mut num = P[5] * y;
        let mut den = y;
        for i in 0..4 {
            num = (num + P[i]) * y;
            den = (den + Q[i]) * y;
        }
        let r = y * (num + P[4]) / (den + Q[4]);
        let r = (1.0 / std::f64::consts::PI.sqrt() - r) / ax;
        let ysq = (ax * 16.0).trunc() / 16.0;
        let del = (ax - ysq) * (ax + ysq);
        (-ysq * ysq).exp() * (-del).exp() * r
    };
    if x < 0.0 {
        2.0 - r
    } else {
        r
    }
}

/// The package root (`CARGO_MANIFEST_DIR`).
pub fn root() -> &'static std::path::Path {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// Path of an example file, `examples/<path>` (e.g. `paths/gantry_path.csv`).
pub fn example_file(path: &str) -> std::path::PathBuf {
    root().join("examples").join(path)
}

/// The constant errors of a values file under `examples/` in
/// `machine.errors` order (mm, rad; every error must be given).
pub fn values_of(m: &Machine, file: &str) -> Vec<f64> {
    let values = chain_core::values::Values::read(&example_file(file), m)
        .unwrap_or_else(|d| panic!("{file} does not read:\n{d}"));
    let by_name: std::collections::HashMap<&str, f64> = values
        .errors()
        .iter()
        .map(String::as_str)
        .zip(values.constants().iter().copied())
        .collect();
    m.errors
        .iter()
        .map(|e| match by_name.get(e.name.as_str()) {
            Some(&v) => v,
            None => panic!("{file} gives no value of {}", e.name),
        })
        .collect()
}

/// The least-squares subset's estimates (value, std) of the JSON in
/// `machine.errors` order (a fixed error: its nominal 0 and std 0).
pub fn subset_estimates(m: &Machine, json: &serde_json::Value) -> (Vec<f64>, Vec<f64>) {
    let est = &json["subset"]["estimates"];
    m.errors
        .iter()
        .map(|e| {
            let x = &est[e.name.as_str()];
            (
                x["value"].as_f64().expect("value"),
                x["std"].as_f64().unwrap_or(0.0),
            )
        })
        .unzip()
}

/// Each estimated error's combination of the truth: `e_k + Σ_j
/// c_jk e_j` over the fixed errors' relations of the JSON; a fixed error's
/// entry is its nominal 0.
pub fn subset_combinations(m: &Machine, json: &serde_json::Value, e: &[f64]) -> Vec<f64> {
    let sub = &json["subset"];
    let mut t = vec![0.0; m.errors.len()];
    for name in sub["estimated"].as_array().expect("estimated") {
        let k = m.error_index(name.as_str().unwrap()).unwrap();
        t[k] = e[k];
    }
    for f in sub["fixed"].as_array().expect("fixed") {
        let j = m.error_index(f["error"].as_str().unwrap()).unwrap();
        for (name, c) in f["relation"].as_object().expect("relation") {
            let k = m.error_index(name).unwrap();
            t[k] += c.as_f64().unwrap() * e[j];
        }
    }
    t
}

/// Path of an example machine file, `examples/machines/<file>`.
pub fn example_path(file: &str) -> std::path::PathBuf {
    example_file("machines").join(file)
}

/// The gantry grinder's text with `dxx` lognormal (mean 0.002, shift
/// −0.03), `dyy` truncated normal on [−0.01, 0.012], the other inputs as in
/// Table 1 and no correlation section (callers append one): the non-normal
/// case of `reliability/benches/sorm.rs`.
pub fn gantry_nonnormal_text() -> String {
    let text = std::fs::read_to_string(example_path("gantry_grinder.yaml"))
        .unwrap()
        .replace(
            "  dxx: {dist: normal, mean: 0, std: 0.05/6}",
            "  dxx: {dist: lognormal, mean: 0.002, std: 0.05/6, shift: -0.03}",
        )
        .replace(
            "  dyy: {dist: normal, mean: 0, std: 0.05/6}",
            "  dyy: {dist: truncated_normal, mean: 0, std: 0.05/6, min: -0.01, max: 0.012}",
        );
    assert!(text.contains("lognormal") && text.contains("truncated_normal"));
    text
}

/// Loads an example machine file, panicking with the rendered diagnostics.
pub fn load_example(file: &str) -> Machine {
    match chain_core::load_file(&example_path(file)) {
        Ok(m) => m,
        Err(d) => panic!("{file} does not load:\n{d}"),
    }
}

/// `|d| <= tol`, false for NaN.
pub fn within(d: f64, tol: f64) -> bool {
    d.abs() <= tol
}

/// `|a - b| <= rel · max(|a|, |b|) + abs` (false if either is NaN).
pub fn close(a: f64, b: f64, rel: f64, abs: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()) + abs
}

/// A copy of `machine` in which the motion errors that `choose` picks become
/// function slots, built by hand (no loader): `choose(machine, body, slot,
/// error)` is asked for every linear or angular error that occurs exactly
/// once in the whole machine, in the `errors` of a jointed body, and returns
/// the basis of its function (named after the error) or `None` to keep it
/// constant. The function's coefficients `<name>_<suffix>` take the error's
/// place in `Machine::errors` and in its slot, of the error's kind; the
/// error's statistics entry (if any) is dropped.
pub fn with_function_slots(
    machine: &Machine,
    mut choose: impl FnMut(&Machine, usize, Slot, usize) -> Option<Basis>,
) -> Machine {
    let n = machine.errors.len();
    let mut uses = vec![0usize; n];
    for b in &machine.bodies {
        for slots in [&b.location_errors, &b.errors] {
            for slot in &slots.slots {
                for &j in slot {
                    uses[j] += 1;
                }
            }
        }
    }
    // Basis (and variable) per error to convert.
    let mut convert: Vec<Option<(Basis, usize)>> = vec![None; n];
    for (b, body) in machine.bodies.iter().enumerate() {
        let Some(joint) = &body.joint else { continue };
        for slot in Slot::ALL {
            for &j in &body.errors.slots[slot.index()] {
                let kind = machine.errors[j].kind;
                if uses[j] == 1 && kind != ErrorKind::Squareness {
                    if let Some(basis) = choose(machine, b, slot, j) {
                        convert[j] = Some((basis, joint.variable));
                    }
                }
            }
        }
    }
    let mut m = machine.clone();
    m.errors.clear();
    m.functions.clear();
    let mut map: Vec<Vec<usize>> = Vec::with_capacity(n);
    for (j, e) in machine.errors.iter().enumerate() {
        match &convert[j] {
            None => {
                map.push(vec![m.errors.len()]);
                m.errors.push(e.clone());
            }
            Some((basis, variable)) => {
                let mut coefficients = Vec::new();
                for b in basis.terms() {
                    coefficients.push((m.errors.len(), b));
                    m.errors.push(ErrorParam {
                        name: format!("{}_{}", e.name, b.suffix()),
                        kind: e.kind,
                        origin: e.origin.clone(),
                        sensor: None,
                    });
                }
                map.push(coefficients.iter().map(|(k, _)| *k).collect());
                m.functions.push(ErrorFunction {
                    name: e.name.clone(),
                    basis: basis.clone(),
                    variable: *variable,
                    coefficients,
                    sensors: Vec::new(),
                    origin: e.origin.clone(),
                });
            }
        }
    }
    for body in &mut m.bodies {
        for slots in [&mut body.location_errors, &mut body.errors] {
            for slot in &mut slots.slots {
                *slot = slot.iter().flat_map(|&j| map[j].iter().copied()).collect();
            }
        }
    }
    m.statistics.retain(|s| convert[s.error].is_none());
    for s in &mut m.statistics {
        s.error = map[s.error][0];
    }
    m
}

/// A small deterministic generator of points (xorshift64), in `[-range, range]`
/// (the batch and `_into` equality tests).
pub struct Points(pub u64);

impl Points {
    /// The next value.
    pub fn next(&mut self, range: f64) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0) * range
    }
    /// Fills `out` with values in `[-range, range]`.
    pub fn fill(&mut self, out: &mut [f64], range: f64) {
        out.iter_mut().for_each(|x| *x = self.next(range));
    }
}

/// Every machine file of examples/machines, sorted.
pub fn example_machines() -> Vec<std::path::PathBuf> {
    let dir = example_file("machines");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .expect("examples/machines exists")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "yaml"))
        .collect();
    files.sort();
    files
}

/// `a` and `b` (at `at`) equal but for numbers that agree up to round-off
/// (relative 1e-14, or both below 1e-14): the first difference, located.
pub fn json_to_roundoff(
    a: &serde_json::Value,
    b: &serde_json::Value,
    at: &str,
) -> Result<(), String> {
    match (a, b) {
        (serde_json::Value::Number(x), serde_json::Value::Number(y)) => {
            let (x, y) = (x.as_f64().unwrap(), y.as_f64().unwrap());
            if roundoff(x, y) {
                Ok(())
            } else {
                Err(format!("{at}: {x}, now {y}"))
            }
        }
        (serde_json::Value::Object(x), serde_json::Value::Object(y)) => {
            if x.keys().ne(y.keys()) {
                return Err(format!("{at}: keys differ"));
            }
            x.iter()
                .zip(y.values())
                .try_for_each(|((k, v), w)| json_to_roundoff(v, w, &format!("{at}.{k}")))
        }
        (serde_json::Value::Array(x), serde_json::Value::Array(y)) if x.len() == y.len() => x
            .iter()
            .zip(y)
            .enumerate()
            .try_for_each(|(i, (v, w))| json_to_roundoff(v, w, &format!("{at}[{i}]"))),
        (x, y) if x == y => Ok(()),
        (x, y) => Err(format!("{at}: {x}, now {y}")),
    }
}

/// Two printed numbers equal up to round-off (relative 1e-14, or both
/// below 1e-14).
pub fn roundoff(a: f64, b: f64) -> bool {
    a == b || close(a, b, 1e-14, 0.0) || a.abs().max(b.abs()) < 1e-14
}
