//! The ring the derivation works in: canonical polynomials ([`Poly`]) and
//! first-order duals over them ([`Dual`]), and rigid transforms over duals
//! ([`Transform`]).

mod dual;
mod poly;

pub use dual::{Dual, Transform};
pub use poly::{format_number, Monomial, Poly, Symbol};

use crate::model::{Axis, Expr, FixedRotation, Machine};

/// Converts a model expression to a polynomial in the parameters.
///
/// Division is only by expressions free of parameters (the loader rejects
/// anything else); such a divisor is evaluated to a number.
pub fn expr_to_poly(expr: &Expr) -> Poly {
    match expr {
        Expr::Num(v) => Poly::constant(*v),
        Expr::Param(i) => Poly::symbol(Symbol::Param(index_u16(*i))),
        Expr::Neg(a) => expr_to_poly(a).neg(),
        Expr::Add(a, b) => expr_to_poly(a).add(&expr_to_poly(b)),
        Expr::Sub(a, b) => expr_to_poly(a).sub(&expr_to_poly(b)),
        Expr::Mul(a, b) => expr_to_poly(a).mul(&expr_to_poly(b)),
        Expr::Div(a, b) => {
            let d = expr_to_poly(b).as_constant().unwrap_or(f64::NAN);
            expr_to_poly(a).scale(1.0 / d)
        }
        Expr::Pow(a, n) => {
            let base = expr_to_poly(a);
            if *n >= 0 {
                base.pow(n.unsigned_abs())
            } else {
                let c = base.as_constant().unwrap_or(f64::NAN);
                Poly::constant(c.powi(*n))
            }
        }
    }
}

/// Symbol indices are stored as `u16`; models never come near that size.
pub(crate) fn index_u16(i: usize) -> u16 {
    u16::try_from(i).unwrap_or(u16::MAX)
}

/// Cosine and sine of a fixed angle, with values within 1e-15 of 0 or ±1
/// snapped so that multiples of 90° give exact matrices.
pub fn exact_cos_sin(angle: f64) -> (f64, f64) {
    let snap = |v: f64| {
        if v.abs() < 1e-15 {
            0.0
        } else if (v.abs() - 1.0).abs() < 1e-15 {
            v.signum()
        } else {
            v
        }
    };
    (snap(angle.cos()), snap(angle.sin()))
}

/// The transform of a fixed rotation.
pub fn fixed_rotation(rot: &FixedRotation) -> Transform {
    let (c, s) = exact_cos_sin(rot.angle);
    Transform::rotation(rot.about.index(), Dual::constant(c), Dual::constant(s))
}

/// The name of a symbol in a machine's terms: `x`, `L`, `cos(A)`, `sin(A)`.
pub fn symbol_name(machine: &Machine, s: Symbol) -> String {
    let var = |i: u16| {
        machine
            .variables
            .get(usize::from(i))
            .map_or("?", |v| v.name.as_str())
    };
    match s {
        Symbol::Param(i) => machine
            .parameters
            .get(usize::from(i))
            .map_or("?".to_string(), |p| p.name.clone()),
        Symbol::Var(i) => var(i).to_string(),
        Symbol::Cos(i) => format!("cos({})", var(i)),
        Symbol::Sin(i) => format!("sin({})", var(i)),
    }
}

/// Unit vector of an axis.
pub fn axis_unit(axis: Axis) -> [f64; 3] {
    let mut u = [0.0; 3];
    u[axis.index()] = 1.0;
    u
}
