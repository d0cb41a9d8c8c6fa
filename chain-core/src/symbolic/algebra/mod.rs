//! The ring the derivation works in: canonical polynomials ([`Poly`]) and
//! first-order duals over them ([`Dual`]), and rigid transforms over duals
//! ([`Transform`]).

mod dual;
mod poly;

pub use dual::{Dual, Transform};
pub use poly::{format_number, Monomial, Poly, Symbol};

use crate::model::{BasisFn, Expr, FixedRotation, Machine};

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

/// A function slot's basis function `b(q)` of axis variable `var` as an exact
/// canonical polynomial (measured-machines spec, section 1): `q^k`; Legendre
/// and Chebyshev polynomials of `t = a·q + b` (`a = 2/(hi − lo)`,
/// `b = −(lo + hi)/(hi − lo)`) by their three-term recurrences, expanded in
/// `q`; `cos kq = T_k(cos q)` and `sin kq = sin q · U_{k−1}(cos q)` (the
/// Chebyshev polynomials of the first and second kind in `cos q`), so Fourier
/// harmonics are polynomials in `sin q`, `cos q` like every rotary term.
pub fn basis_poly(b: &BasisFn, var: u16) -> Poly {
    let q = || Poly::symbol(Symbol::Var(var));
    let t = |range: [f64; 2]| {
        let [lo, hi] = range;
        q().scale(2.0 / (hi - lo))
            .add(&Poly::constant(-(lo + hi) / (hi - lo)))
    };
    // A three-term recurrence p_{n+1} = step(n, p_n, p_{n−1}) from p_0 = 1 and p_1.
    let recur = |p1: Poly, k: u32, step: &dyn Fn(u32, &Poly, &Poly) -> Poly| {
        if k == 0 {
            return Poly::constant(1.0);
        }
        let (mut a, mut b) = (Poly::constant(1.0), p1);
        for n in 1..k {
            let c = step(n, &b, &a);
            a = b;
            b = c;
        }
        b
    };
    match *b {
        BasisFn::Power(k) => q().pow(k),
        BasisFn::Legendre { k, range } => {
            let x = t(range);
            recur(x.clone(), k, &|n, pn, pm| {
                let n = f64::from(n);
                x.mul(pn)
                    .scale((2.0 * n + 1.0) / (n + 1.0))
                    .sub(&pm.scale(n / (n + 1.0)))
            })
        }
        BasisFn::Chebyshev { k, range } => {
            let x = t(range);
            recur(x.clone(), k, &|_, pn, pm| x.mul(pn).scale(2.0).sub(pm))
        }
        BasisFn::Cos(k) => {
            let c = Poly::symbol(Symbol::Cos(var));
            recur(c.clone(), k, &|_, pn, pm| c.mul(pn).scale(2.0).sub(pm))
        }
        BasisFn::Sin(k) => {
            let c = Poly::symbol(Symbol::Cos(var));
            // U_0 = 1, U_1 = 2c, U_{n+1} = 2c U_n − U_{n−1}; sin kq = sin q · U_{k−1}.
            let u = if k == 0 {
                Poly::zero()
            } else {
                recur(c.scale(2.0), k - 1, &|_, pn, pm| {
                    c.mul(pn).scale(2.0).sub(pm)
                })
            };
            Poly::symbol(Symbol::Sin(var)).mul(&u)
        }
    }
}

/// The weight of error `j` in the slots that hold it: its basis function
/// (a polynomial in its joint variable) for a function slot's coefficient,
/// 1 for a constant error parameter.
pub fn error_weight(machine: &Machine, j: usize) -> Poly {
    match machine.coefficient_of(j) {
        Some((f, b)) => basis_poly(&b, index_u16(f.variable)),
        None => Poly::constant(1.0),
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
