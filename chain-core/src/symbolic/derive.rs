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
//!
//! A function slot (measured-machines spec, section 1) holds
//! `F(q) = Σ_k F_k b_k(q)`; its coefficient `F_k` enters the slot with the
//! weight `b_k(q)`, a nominal (error-free) polynomial of the body's own
//! variable. The first-order model is linear in the slot values, so
//! `∂E/∂F_k = b_k(q) · ∂E/∂(slot)`: every coefficient of one function has the
//! coefficient a plain error in the same slots would have, times its basis
//! function. [`derive_in`] uses exactly that: errors that occur in the same
//! slots (with the same multiplicities) are carried through the transform
//! product once, by one representative with unit weight, and each error's
//! coefficient is the representative's times its weight
//! ([`crate::algebra::error_weight`]). The differential-motion-matrix route
//! ([`crate::dmm`]) keeps the weights inside its product, so the two routes
//! cross-check this factoring too.

use crate::algebra::{
    error_weight, expr_to_poly, fixed_rotation, index_u16, Dual, Poly, Symbol, Transform,
};
use crate::model::{Component, ErrorFunction, ErrorKind, ErrorSlots, Frame, JointKind, Machine};

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
    /// The machine's function slots (variable and coefficient indices as in
    /// [`SymbolicModel::variables`] and [`SymbolicModel::errors`]); empty
    /// for a machine without any. The exports list them.
    pub functions: Vec<ErrorFunction>,
    /// Per error, the sensor whose deviation from its reference multiplies
    /// it (a thermal coefficient, `docs/thermal.md`): `(sensor name,
    /// reference °C)`; `None` for a geometric error. The coefficients in
    /// `components` are the geometry's; the thermal factor acts on the
    /// value.
    pub thermal: Vec<Option<(String, f64)>>,
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
///
/// On a machine with function slots, the coefficient of `F_k` is the exact
/// product `b_k(q) · c(q)` of its basis function with the coefficient `c`
/// of its slot (module docs); the errors sharing a slot are derived once.
pub fn derive_in(machine: &Machine, frame: Frame) -> SymbolicModel {
    if machine.functions.is_empty() {
        return derive_direct(machine, frame);
    }
    let representative = representatives(machine);
    let plain = derive_direct(&reduced(machine, &representative), frame);
    let mut components: [Vec<(usize, Poly)>; 6] = Default::default();
    let weights: Vec<Option<Poly>> = (0..machine.errors.len())
        .map(|j| machine.coefficient_of(j).map(|_| error_weight(machine, j)))
        .collect();
    for (c, out) in components.iter_mut().enumerate() {
        let c = Component::ALL[c];
        for (j, (&r, weight)) in representative.iter().zip(&weights).enumerate() {
            let base = plain.coefficient(c, r);
            let value = match weight {
                Some(w) => base.mul(w),
                None => base,
            };
            if !value.is_zero() {
                out.push((j, value));
            }
        }
    }
    SymbolicModel {
        components,
        functions: machine.functions.clone(),
        ..plain
    }
}

/// Per error, the first error (a representative) that occurs in exactly the
/// same slots with the same multiplicities: such errors have the same
/// coefficient up to their weights.
fn representatives(machine: &Machine) -> Vec<usize> {
    // Occurrences as (body, section, slot), in a fixed order; duplicates kept.
    let mut occurrences: Vec<Vec<(usize, usize, usize)>> = vec![Vec::new(); machine.errors.len()];
    for (b, body) in machine.bodies.iter().enumerate() {
        for (section, slots) in [&body.location_errors, &body.errors]
            .into_iter()
            .enumerate()
        {
            for (s, slot) in slots.slots.iter().enumerate() {
                for &j in slot {
                    if let Some(o) = occurrences.get_mut(j) {
                        o.push((b, section, s));
                    }
                }
            }
        }
    }
    let mut first: std::collections::HashMap<&[(usize, usize, usize)], usize> =
        std::collections::HashMap::new();
    occurrences
        .iter()
        .enumerate()
        .map(|(j, o)| *first.entry(o.as_slice()).or_insert(j))
        .collect()
}

/// The machine with unit weights (no function slots) and only the
/// representatives in its slots: every other error of a class is dropped
/// from each slot, which keeps the representative's own multiplicity there.
fn reduced(machine: &Machine, representative: &[usize]) -> Machine {
    let mut m = machine.clone();
    m.functions.clear();
    for body in &mut m.bodies {
        for slots in [&mut body.location_errors, &mut body.errors] {
            for slot in &mut slots.slots {
                slot.retain(|&j| representative.get(j) == Some(&j));
            }
        }
    }
    m
}

/// The derivation proper, every error carried through the transform product
/// with its slot weight.
fn derive_direct(machine: &Machine, frame: Frame) -> SymbolicModel {
    let t_wt = tool_in_workpiece(machine);
    let tool_point: [Dual; 3] =
        std::array::from_fn(|i| Dual::nominal(expr_to_poly(&machine.tool_point[i])));
    let position = t_wt.apply(&tool_point);

    let r0: [[Poly; 3]; 3] =
        std::array::from_fn(|i| std::array::from_fn(|j| t_wt.r[i][j].value.clone()));
    let n = machine.errors.len();
    let mut components: [Vec<(usize, Poly)>; 6] = Default::default();
    for j in 0..n {
        let p: [Poly; 3] = std::array::from_fn(|i| position[i].slope(j));
        // R_wt(q,e) R_wt(q,0)^T = I + [o x]: o = vee(R_j R0^T).
        let rj: [[Poly; 3]; 3] =
            std::array::from_fn(|a| std::array::from_fn(|b| t_wt.r[a][b].slope(j)));
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
        functions: machine.functions.clone(),
        thermal: machine
            .errors
            .iter()
            .map(|e| {
                let s = machine.sensors.get(e.sensor?)?;
                Some((s.name.clone(), s.reference))
            })
            .collect(),
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
    Nominal(Box<Transform>),
    /// A small-error transform `E(d, e)` with its error slots.
    Error(ErrorSlots),
}

/// `Trans(offset)·Rot(rotation)·E(location_errors)·J(q)·E(errors)` as factors.
pub(crate) fn body_factors(machine: &Machine, b: usize) -> Vec<Factor> {
    let body = &machine.bodies[b];
    let mut f = Vec::new();
    if !body.offset.iter().all(|e| e.is_zero()) {
        f.push(Factor::Nominal(Box::new(Transform::translation(
            std::array::from_fn(|i| Dual::nominal(expr_to_poly(&body.offset[i]))),
        ))));
    }
    for rot in &body.rotation {
        f.push(Factor::Nominal(Box::new(fixed_rotation(rot))));
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
        f.push(Factor::Nominal(Box::new(t)));
    }
    if !body.errors.is_empty() {
        f.push(Factor::Error(body.errors.clone()));
    }
    f
}

/// The value of one slot, `Σ sign·w_j(q)·e_j` over the errors it holds: the
/// weight `w_j` is the basis function of a function slot's coefficient, 1
/// for a constant error parameter ([`crate::algebra::error_weight`]).
pub(crate) fn slot_dual(machine: &Machine, errors: &[usize], sign: f64) -> Dual {
    if machine.functions.is_empty() {
        return Dual::errors(errors, sign);
    }
    Dual::weighted(errors, sign, |j| crate::algebra::error_weight(machine, j))
}

/// The small-error transform of a set of error slots.
pub(crate) fn error_transform(machine: &Machine, slots: &ErrorSlots) -> Transform {
    let s = |i: usize| slot_dual(machine, &slots.slots[i], 1.0);
    Transform::small_error([s(0), s(1), s(2)], [s(3), s(4), s(5)])
}

/// The full transform of a body in its parent's frame.
pub(crate) fn body_transform(machine: &Machine, b: usize) -> Transform {
    body_factors(machine, b)
        .iter()
        .fold(Transform::identity(), |acc, f| match f {
            Factor::Nominal(t) => acc.mul(t),
            Factor::Error(slots) => acc.mul(&error_transform(machine, slots)),
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{
        Body, ErrorKind, ErrorParam, Expr, Joint, Origin, Parameter, SignedAxis, Variable,
    };

    /// A rotary table (about +z, variable `C`) carrying the workpiece, and a
    /// fixed tool at `[L, 0, 0]` from the bed; the table has an `ez` motion
    /// error `ezc` and a `dx` motion error `dxc`.
    fn rotary_table() -> Machine {
        let o = Origin::default;
        let slots = |pairs: &[(usize, usize)]| {
            let mut s = ErrorSlots::default();
            for &(slot, err) in pairs {
                s.slots[slot].push(err);
            }
            s
        };
        Machine {
            name: "rot".into(),
            description: None,
            file: None,
            parameters: vec![Parameter {
                name: "L".into(),
                value: Some(100.0),
                origin: o(),
            }],
            variables: vec![Variable {
                name: "C".into(),
                kind: JointKind::Rotary,
                body: 1,
                origin: o(),
            }],
            errors: vec![
                ErrorParam {
                    name: "dxc".into(),
                    kind: ErrorKind::Linear,
                    origin: o(),
                    sensor: None,
                },
                ErrorParam {
                    name: "ezc".into(),
                    kind: ErrorKind::Angular,
                    origin: o(),
                    sensor: None,
                },
            ],
            bodies: vec![
                Body {
                    name: "bed".into(),
                    parent: None,
                    offset: [Expr::Num(0.0), Expr::Num(0.0), Expr::Num(0.0)],
                    rotation: vec![],
                    location_errors: ErrorSlots::default(),
                    joint: None,
                    errors: ErrorSlots::default(),
                    origin: o(),
                },
                Body {
                    name: "table".into(),
                    parent: Some(0),
                    offset: [Expr::Num(0.0), Expr::Num(0.0), Expr::Num(0.0)],
                    rotation: vec![],
                    location_errors: ErrorSlots::default(),
                    joint: Some(Joint {
                        kind: JointKind::Rotary,
                        axis: SignedAxis {
                            axis: crate::model::Axis::Z,
                            negative: false,
                        },
                        variable: 0,
                        origin: o(),
                    }),
                    errors: slots(&[(0, 0), (5, 1)]),
                    origin: o(),
                },
                Body {
                    name: "tool".into(),
                    parent: Some(0),
                    offset: [Expr::Param(0), Expr::Num(0.0), Expr::Num(0.0)],
                    rotation: vec![],
                    location_errors: ErrorSlots::default(),
                    joint: None,
                    errors: ErrorSlots::default(),
                    origin: o(),
                },
            ],
            workpiece: 1,
            tool: 2,
            tool_point: [Expr::Num(0.0), Expr::Num(0.0), Expr::Num(0.0)],
            frame: Frame::Workpiece,
            statistics: vec![],
            reliability: None,
            correlations: Vec::new(),
            sensors: Vec::new(),
            sensor_statistics: Vec::new(),
            functions: vec![],
        }
    }

    #[test]
    fn rotary_table_by_hand() {
        // T_wt = inv(Rz(C) E) Trans(L): the tool sits at Rz(-C)(L,0,0) in the
        // table frame. A table error E(dx=dxc, ez=ezc) moves the workpiece, so
        // the tool moves by -E relative to it: p = -(dxc, 0, 0) - ezc × p0.
        let m = rotary_table();
        let model = derive(&m);
        let name = |p: &Poly| p.to_text(&|s| model.symbol_name(s));
        assert_eq!(name(&model.nominal_position[0]), "L*cos(C)");
        assert_eq!(name(&model.nominal_position[1]), "-L*sin(C)");
        assert_eq!(name(&model.coefficient(Component::Px, 0)), "-1");
        assert_eq!(name(&model.coefficient(Component::Py, 0)), "0");
        // -ezc × (L cos C, -L sin C, 0) = ezc (-L sin C, -L cos C, 0)·(-1)...
        assert_eq!(name(&model.coefficient(Component::Px, 1)), "-L*sin(C)");
        assert_eq!(name(&model.coefficient(Component::Py, 1)), "-L*cos(C)");
        assert_eq!(name(&model.coefficient(Component::Oz, 1)), "-1");
        // The DMM route agrees in both frames.
        for frame in [Frame::Workpiece, Frame::Tool] {
            let a = derive_in(&m, frame).components;
            let b = crate::dmm::derive_dmm(&m, frame);
            assert_eq!(a, b, "{frame:?}");
        }
    }
}
