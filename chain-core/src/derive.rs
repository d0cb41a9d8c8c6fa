//! The derivation: a validated [`Machine`] → its exact first-order error model
//! ([`SymbolicModel`]).
//!
//! Every body transform
//! `Trans(offset)·Rot(rotation)·E(location_errors)·J(q)·E(errors + squareness)`
//! is built over first-order duals ([`crate::algebra::Dual`]); the branch
//! products from the lowest common ancestor of workpiece and tool give
//! `T_wt = inv(P(workpiece))·P(tool)` (the common part cancels exactly), and
//! the slopes of `T_wt·tool_point` and of `R_wt(q,e)·R_wt(q,0)ᵀ` are the
//! position and orientation coefficients. Nothing is differentiated
//! numerically.

use crate::algebra::{expr_to_poly, fixed_rotation, index_u16, Dual, Poly, Symbol, Transform};
use crate::model::{Component, ErrorKind, ErrorSlots, Frame, JointKind, Machine};

/// The exact first-order error model of a machine.
///
/// `components[c]` lists `(error index, coefficient)` for every error with a
/// non-zero coefficient in component `c` (`px, py, pz, ox, oy, oz` order); the
/// coefficient is the exact partial derivative `∂E_c/∂e_j` as a canonical
/// polynomial in the axis variables, parameters and `sin`/`cos` of rotary
/// variables.
#[derive(Debug, Clone, PartialEq)]
pub struct SymbolicModel {
    /// Machine identifier.
    pub machine: String,
    /// Frame of `p` and `o`.
    pub frame: Frame,
    /// Axis variable names and joint kinds.
    pub variables: Vec<(String, JointKind)>,
    /// Parameter names and their values (`None`: supplied at run time).
    pub parameters: Vec<(String, Option<f64>)>,
    /// Error parameter names.
    pub errors: Vec<String>,
    /// Error parameter kinds.
    pub error_kinds: Vec<ErrorKind>,
    /// `R_wt(q, 0)`, row-major.
    pub nominal_rotation: [[Poly; 3]; 3],
    /// `T_wt(q, 0)·tool_point`.
    pub nominal_position: [Poly; 3],
    /// Sparse coefficients per component.
    pub components: [Vec<(usize, Poly)>; 6],
}

impl SymbolicModel {
    /// The coefficient `∂E_c/∂e_j` (zero if the error does not enter `c`).
    pub fn coefficient(&self, c: Component, j: usize) -> Poly {
        self.components[c.index()]
            .binary_search_by_key(&j, |(k, _)| *k)
            .map(|i| self.components[c.index()][i].1.clone())
            .unwrap_or_default()
    }

    /// The printable name of a symbol: `x`, `L`, `cos(A)`, `sin(A)`.
    pub fn symbol_name(&self, s: Symbol) -> String {
        let var = |i: u16| {
            self.variables
                .get(usize::from(i))
                .map_or("?", |v| v.0.as_str())
        };
        match s {
            Symbol::Param(i) => self
                .parameters
                .get(usize::from(i))
                .map_or_else(|| "?".to_string(), |p| p.0.clone()),
            Symbol::Var(i) => var(i).to_string(),
            Symbol::Cos(i) => format!("cos({})", var(i)),
            Symbol::Sin(i) => format!("sin({})", var(i)),
        }
    }

    /// Value of a symbol at axis values `q` and parameter values `p`.
    pub fn symbol_value(s: Symbol, q: &[f64], p: &[f64]) -> f64 {
        let at = |v: &[f64], i: u16| v.get(usize::from(i)).copied().unwrap_or(f64::NAN);
        match s {
            Symbol::Param(i) => at(p, i),
            Symbol::Var(i) => at(q, i),
            Symbol::Cos(i) => at(q, i).cos(),
            Symbol::Sin(i) => at(q, i).sin(),
        }
    }

    /// Number of non-zero coefficients over all components.
    pub fn nonzero_count(&self) -> usize {
        self.components.iter().map(Vec::len).sum()
    }

    /// The default parameter values (`NaN` for symbolic ones).
    pub fn parameter_values(&self) -> Vec<f64> {
        self.parameters
            .iter()
            .map(|(_, v)| v.unwrap_or(f64::NAN))
            .collect()
    }
}

/// Derives the machine's error model in the frame its file asks for.
pub fn derive(machine: &Machine) -> SymbolicModel {
    derive_in(machine, machine.frame)
}

/// Derives the machine's error model in the given frame.
pub fn derive_in(machine: &Machine, frame: Frame) -> SymbolicModel {
    let t_wt = tool_in_workpiece(machine);
    let tool_point: [Dual; 3] =
        std::array::from_fn(|i| Dual::nominal(expr_to_poly(&machine.tool_point[i])));
    let position = t_wt.apply(&tool_point);

    let r0: [[Poly; 3]; 3] = std::array::from_fn(|i| std::array::from_fn(|j| t_wt.r[i][j].value.clone()));
    let n = machine.errors.len();
    let mut components: [Vec<(usize, Poly)>; 6] = Default::default();
    for j in 0..n {
        let p: [Poly; 3] = std::array::from_fn(|i| position[i].slope(j));
        // R_wt(q,e) R_wt(q,0)^T = I + [o x]: o = vee(R_j R0^T).
        let rj: [[Poly; 3]; 3] = std::array::from_fn(|a| std::array::from_fn(|b| t_wt.r[a][b].slope(j)));
        let m = |a: usize, b: usize| -> Poly {
            let mut s = Poly::zero();
            for k in 0..3 {
                s = s.add(&rj[a][k].mul(&r0[b][k]));
            }
            s
        };
        let o = [m(2, 1), m(0, 2), m(1, 0)];
        let (p, o) = match frame {
            Frame::Workpiece => (p, o),
            Frame::Tool => (transpose_apply(&r0, &p), transpose_apply(&r0, &o)),
        };
        for (c, value) in p.into_iter().chain(o).enumerate() {
            if !value.is_zero() {
                components[c].push((j, value));
            }
        }
    }

    SymbolicModel {
        machine: machine.name.clone(),
        frame,
        variables: machine
            .variables
            .iter()
            .map(|v| (v.name.clone(), v.kind))
            .collect(),
        parameters: machine
            .parameters
            .iter()
            .map(|p| (p.name.clone(), p.value))
            .collect(),
        errors: machine.errors.iter().map(|e| e.name.clone()).collect(),
        error_kinds: machine.errors.iter().map(|e| e.kind).collect(),
        nominal_rotation: r0,
        nominal_position: std::array::from_fn(|i| position[i].value.clone()),
        components,
    }
}

/// `Rᵀ v` for a polynomial matrix and vector.
pub(crate) fn transpose_apply(r: &[[Poly; 3]; 3], v: &[Poly; 3]) -> [Poly; 3] {
    std::array::from_fn(|i| {
        let mut s = Poly::zero();
        for k in 0..3 {
            s = s.add(&r[k][i].mul(&v[k]));
        }
        s
    })
}

/// `T_wt = inv(P(lca → workpiece)) · P(lca → tool)` over duals.
pub fn tool_in_workpiece(machine: &Machine) -> Transform {
    let (wp_path, tool_path) = branches(machine);
    let chain = |path: &[usize]| {
        path.iter().fold(Transform::identity(), |acc, &b| {
            acc.mul(&body_transform(machine, b))
        })
    };
    chain(&wp_path).inverse().mul(&chain(&tool_path))
}

/// The bodies below the lowest common ancestor on the workpiece and the tool
/// branch, each from the ancestor down.
pub(crate) fn branches(machine: &Machine) -> (Vec<usize>, Vec<usize>) {
    let wp = machine.path_from_root(machine.workpiece);
    let tool = machine.path_from_root(machine.tool);
    let common = wp.iter().zip(&tool).take_while(|(a, b)| a == b).count();
    (wp[common..].to_vec(), tool[common..].to_vec())
}

/// The factors of one body's transform, in order, each either nominal or a
/// small-error transform.
pub(crate) enum Factor {
    /// A nominal (error-free) transform.
    Nominal(Transform),
    /// A small-error transform `E(d, e)` with its error slots.
    Error(ErrorSlots),
}

/// `Trans(offset)·Rot(rotation)·E(location_errors)·J(q)·E(errors)` as factors.
pub(crate) fn body_factors(machine: &Machine, b: usize) -> Vec<Factor> {
    let body = &machine.bodies[b];
    let mut f = Vec::new();
    if !body.offset.iter().all(|e| e.is_zero()) {
        f.push(Factor::Nominal(Transform::translation(std::array::from_fn(|i| {
            Dual::nominal(expr_to_poly(&body.offset[i]))
        }))));
    }
    for rot in &body.rotation {
        f.push(Factor::Nominal(fixed_rotation(rot)));
    }
    if !body.location_errors.is_empty() {
        f.push(Factor::Error(body.location_errors.clone()));
    }
    if let Some(joint) = &body.joint {
        let v = index_u16(joint.variable);
        let sign = joint.axis.sign();
        let k = joint.axis.axis.index();
        let t = match joint.kind {
            JointKind::Prismatic => {
                let mut t: [Dual; 3] = Default::default();
                t[k] = Dual::nominal(Poly::symbol(Symbol::Var(v)).scale(sign));
                Transform::translation(t)
            }
            JointKind::Rotary => Transform::rotation(
                k,
                Dual::nominal(Poly::symbol(Symbol::Cos(v))),
                Dual::nominal(Poly::symbol(Symbol::Sin(v)).scale(sign)),
            ),
        };
        f.push(Factor::Nominal(t));
    }
    if !body.errors.is_empty() {
        f.push(Factor::Error(body.errors.clone()));
    }
    f
}

/// The small-error transform of a set of error slots.
pub(crate) fn error_transform(slots: &ErrorSlots) -> Transform {
    let s = |i: usize| Dual::errors(&slots.slots[i], 1.0);
    Transform::small_error([s(0), s(1), s(2)], [s(3), s(4), s(5)])
}

/// The full transform of a body in its parent's frame.
pub(crate) fn body_transform(machine: &Machine, b: usize) -> Transform {
    body_factors(machine, b)
        .iter()
        .fold(Transform::identity(), |acc, f| match f {
            Factor::Nominal(t) => acc.mul(t),
            Factor::Error(slots) => acc.mul(&error_transform(slots)),
        })
}
