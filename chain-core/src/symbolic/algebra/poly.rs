//! Canonical polynomials in axis variables, parameters and `sin`/`cos` of
//! rotary variables.
//!
//! A [`Poly`] is a sorted list of `(Monomial, coefficient)` terms with no zero
//! coefficient and no repeated monomial. The trigonometric identity
//! `sin² q + cos² q = 1` is folded on every product by rewriting `sin² q` as
//! `1 − cos² q`, so a monomial never holds `sin q` to a power above one. With
//! that rule two polynomials are equal as functions exactly when they are equal
//! term by term, which is what makes the derivation's output canonical.

use std::cmp::Ordering;
use std::fmt::Write as _;

/// An indeterminate of the ring.
///
/// The order of the variants fixes the order of factors in printed monomials:
/// parameters, then linear axis variables, then `cos`, then `sin`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Symbol {
    /// A machine parameter, by index into `Machine::parameters`.
    Param(u16),
    /// A prismatic axis variable, by index into `Machine::variables`.
    Var(u16),
    /// `cos` of a rotary axis variable.
    Cos(u16),
    /// `sin` of a rotary axis variable.
    Sin(u16),
}

/// A product of symbol powers: sorted by symbol, exponents ≥ 1, and the
/// exponent of any `Sin` is exactly 1.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
pub struct Monomial(pub Vec<(Symbol, u16)>);

impl Monomial {
    /// The constant monomial `1`.
    pub fn one() -> Monomial {
        Monomial(Vec::new())
    }

    /// A single symbol.
    pub fn symbol(s: Symbol) -> Monomial {
        Monomial(vec![(s, 1)])
    }

    /// True for the constant monomial.
    pub fn is_one(&self) -> bool {
        self.0.is_empty()
    }

    /// Splits off one factor of the last symbol: `m = rest · s`. `None` for
    /// the constant monomial. Builders of evaluation code use it to compute
    /// each monomial from a shorter one with one multiplication.
    pub fn split_last(&self) -> Option<(Monomial, Symbol)> {
        let mut rest = self.0.clone();
        let last = rest.last_mut()?;
        let sym = last.0;
        if last.1 == 1 {
            rest.pop();
        } else {
            last.1 -= 1;
        }
        Some((Monomial(rest), sym))
    }

    /// Total degree.
    pub fn degree(&self) -> u32 {
        self.0.iter().map(|&(_, e)| u32::from(e)).sum()
    }

    /// Product of two monomials (not yet canonical in `sin`).
    fn mul_raw(&self, other: &Monomial) -> Monomial {
        let (a, b) = (&self.0, &other.0);
        let mut out = Vec::with_capacity(a.len() + b.len());
        let (mut i, mut j) = (0, 0);
        while i < a.len() && j < b.len() {
            match a[i].0.cmp(&b[j].0) {
                Ordering::Less => {
                    out.push(a[i]);
                    i += 1;
                }
                Ordering::Greater => {
                    out.push(b[j]);
                    j += 1;
                }
                Ordering::Equal => {
                    out.push((a[i].0, a[i].1 + b[j].1));
                    i += 1;
                    j += 1;
                }
            }
        }
        out.extend_from_slice(&a[i..]);
        out.extend_from_slice(&b[j..]);
        Monomial(out)
    }

    /// Evaluates with a symbol-value lookup.
    pub fn eval(&self, value: &impl Fn(Symbol) -> f64) -> f64 {
        self.0
            .iter()
            .map(|&(s, e)| value(s).powi(i32::from(e)))
            .product()
    }
}

/// A canonical polynomial with `f64` coefficients.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Poly {
    terms: Vec<(Monomial, f64)>,
}

/// Relative size below which a sum of like terms is taken as an exact
/// cancellation (the inputs' rounding, not a real coefficient).
const CANCEL: f64 = 1e-13;

impl Poly {
    /// The zero polynomial.
    pub fn zero() -> Poly {
        Poly { terms: Vec::new() }
    }

    /// A constant.
    pub fn constant(c: f64) -> Poly {
        if c == 0.0 {
            Poly::zero()
        } else {
            Poly {
                terms: vec![(Monomial::one(), c)],
            }
        }
    }

    /// A single symbol.
    pub fn symbol(s: Symbol) -> Poly {
        Poly {
            terms: vec![(Monomial::symbol(s), 1.0)],
        }
    }

    /// The terms, sorted by monomial.
    pub fn terms(&self) -> &[(Monomial, f64)] {
        &self.terms
    }

    /// True for the zero polynomial.
    pub fn is_zero(&self) -> bool {
        self.terms.is_empty()
    }

    /// The value if the polynomial is a constant.
    pub fn as_constant(&self) -> Option<f64> {
        match self.terms.as_slice() {
            [] => Some(0.0),
            [(m, c)] if m.is_one() => Some(*c),
            _ => None,
        }
    }

    /// Builds a canonical polynomial from arbitrary terms: folds `sin²`,
    /// merges like monomials and drops cancelled ones.
    pub fn from_terms(raw: Vec<(Monomial, f64)>) -> Poly {
        let mut expanded: Vec<(Monomial, f64, f64)> = Vec::with_capacity(raw.len());
        for (m, c) in raw {
            if c != 0.0 {
                fold_sin(m, c, &mut expanded);
            }
        }
        expanded.sort_by(|a, b| a.0.cmp(&b.0));
        let mut terms: Vec<(Monomial, f64)> = Vec::with_capacity(expanded.len());
        let mut magnitude = 0.0;
        for (m, c, mag) in expanded {
            match terms.last_mut() {
                Some((last, sum)) if *last == m => {
                    *sum += c;
                    magnitude += mag;
                }
                _ => {
                    if let Some((_, sum)) = terms.last() {
                        if sum.abs() <= CANCEL * magnitude {
                            terms.pop();
                        }
                    }
                    terms.push((m, c));
                    magnitude = mag;
                }
            }
        }
        if let Some((_, sum)) = terms.last() {
            if sum.abs() <= CANCEL * magnitude {
                terms.pop();
            }
        }
        Poly { terms }
    }

    /// Sum.
    pub fn add(&self, other: &Poly) -> Poly {
        if other.is_zero() {
            return self.clone();
        }
        if self.is_zero() {
            return other.clone();
        }
        let mut raw = Vec::with_capacity(self.terms.len() + other.terms.len());
        raw.extend(self.terms.iter().cloned());
        raw.extend(other.terms.iter().cloned());
        Poly::from_terms(raw)
    }

    /// Difference.
    pub fn sub(&self, other: &Poly) -> Poly {
        self.add(&other.neg())
    }

    /// Negation.
    pub fn neg(&self) -> Poly {
        Poly {
            terms: self.terms.iter().map(|(m, c)| (m.clone(), -c)).collect(),
        }
    }

    /// Multiplication by a number.
    pub fn scale(&self, k: f64) -> Poly {
        if k == 0.0 {
            return Poly::zero();
        }
        Poly {
            terms: self.terms.iter().map(|(m, c)| (m.clone(), c * k)).collect(),
        }
    }

    /// Product.
    pub fn mul(&self, other: &Poly) -> Poly {
        if self.is_zero() || other.is_zero() {
            return Poly::zero();
        }
        if let Some(k) = self.as_constant() {
            return other.scale(k);
        }
        if let Some(k) = other.as_constant() {
            return self.scale(k);
        }
        let mut raw = Vec::with_capacity(self.terms.len() * other.terms.len());
        for (ma, ca) in &self.terms {
            for (mb, cb) in &other.terms {
                raw.push((ma.mul_raw(mb), ca * cb));
            }
        }
        Poly::from_terms(raw)
    }

    /// Integer power `n ≥ 0`.
    pub fn pow(&self, n: u32) -> Poly {
        let mut out = Poly::constant(1.0);
        for _ in 0..n {
            out = out.mul(self);
        }
        out
    }

    /// Evaluates with a symbol-value lookup.
    pub fn eval(&self, value: &impl Fn(Symbol) -> f64) -> f64 {
        self.terms.iter().map(|(m, c)| c * m.eval(value)).sum()
    }

    /// The symbols that occur.
    pub fn symbols(&self) -> Vec<Symbol> {
        let mut s: Vec<Symbol> = self
            .terms
            .iter()
            .flat_map(|(m, _)| m.0.iter().map(|&(s, _)| s))
            .collect();
        s.sort();
        s.dedup();
        s
    }

    /// Prints the polynomial in the plain syntax of the JSON export
    /// (`-z*cos(A) + 2*x^2`), readable by SymPy's `sympify` and MATLAB.
    pub fn to_text(&self, names: &impl Fn(Symbol) -> String) -> String {
        self.render(names, &PLAIN)
    }

    /// Prints the polynomial as LaTeX math.
    pub fn to_latex(&self, names: &impl Fn(Symbol) -> String) -> String {
        self.render(names, &LATEX)
    }

    fn render(&self, names: &impl Fn(Symbol) -> String, style: &Style) -> String {
        if self.terms.is_empty() {
            return "0".to_string();
        }
        // Highest degree first reads best; ties keep the canonical order.
        let mut order: Vec<&(Monomial, f64)> = self.terms.iter().collect();
        order.sort_by_key(|(m, _)| std::cmp::Reverse(m.degree()));
        let mut out = String::new();
        for (k, (m, c)) in order.into_iter().enumerate() {
            let negative = *c < 0.0;
            let mag = c.abs();
            if k == 0 {
                if negative {
                    out.push('-');
                }
            } else {
                out.push_str(if negative { " - " } else { " + " });
            }
            let factors: Vec<String> =
                m.0.iter()
                    .map(|&(s, e)| {
                        let base = names(s);
                        if e == 1 {
                            base
                        } else {
                            (style.power)(&base, e)
                        }
                    })
                    .collect();
            if factors.is_empty() {
                out.push_str(&format_number(mag));
            } else {
                if mag != 1.0 {
                    out.push_str(&format_number(mag));
                    out.push_str(style.times);
                }
                out.push_str(&factors.join(style.times));
            }
        }
        out
    }
}

struct Style {
    times: &'static str,
    power: fn(&str, u16) -> String,
}

const PLAIN: Style = Style {
    times: "*",
    power: |b, e| format!("{b}^{e}"),
};

const LATEX: Style = Style {
    times: " ",
    power: |b, e| {
        let mut s = String::new();
        let _ = write!(s, "{b}^{{{e}}}");
        s
    },
};

/// Formats a number as a plain decimal that round-trips (`1`, `0.5`,
/// `1.6666666666666667e-5` is printed as `0.000016666666666666667`).
pub fn format_number(v: f64) -> String {
    let s = format!("{v}");
    if s.contains('e') || s.contains("inf") || s.contains("NaN") {
        format!("{v:e}")
    } else {
        s
    }
}

/// Appends `c·m` to `out` with every `sin^k` (k ≥ 2) rewritten through
/// `sin² = 1 − cos²`. The third field carries `|c|` for cancellation tests.
fn fold_sin(m: Monomial, c: f64, out: &mut Vec<(Monomial, f64, f64)>) {
    let Some(pos) =
        m.0.iter()
            .position(|&(s, e)| matches!(s, Symbol::Sin(_)) && e >= 2)
    else {
        out.push((m, c, c.abs()));
        return;
    };
    let (sym, e) = m.0[pos];
    let Symbol::Sin(v) = sym else { return };
    // s^e = s^(e-2) (1 - c^2)
    let mut reduced = m.0.clone();
    if e == 2 {
        reduced.remove(pos);
    } else {
        reduced[pos].1 = e - 2;
    }
    let base = Monomial(reduced);
    let cos2 = Monomial(vec![(Symbol::Cos(v), 2)]);
    fold_sin(base.clone(), c, out);
    fold_sin(base.mul_raw(&cos2), -c, out);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sin_squared_plus_cos_squared_is_one() {
        let s = Poly::symbol(Symbol::Sin(0));
        let c = Poly::symbol(Symbol::Cos(0));
        let one = s.mul(&s).add(&c.mul(&c));
        assert_eq!(one, Poly::constant(1.0));
    }

    #[test]
    fn cancellation_is_exact() {
        let x = Poly::symbol(Symbol::Var(0));
        assert!(x.sub(&x).is_zero());
        let a = x.scale(0.1).add(&x.scale(0.2)).sub(&x.scale(0.3));
        assert!(a.is_zero(), "{a:?}");
    }

    #[test]
    fn printing() {
        let names = |s: Symbol| match s {
            Symbol::Var(_) => "x".to_string(),
            Symbol::Sin(_) => "sin(A)".to_string(),
            Symbol::Cos(_) => "cos(A)".to_string(),
            Symbol::Param(_) => "L".to_string(),
        };
        let x = Poly::symbol(Symbol::Var(0));
        let c = Poly::symbol(Symbol::Cos(0));
        let p = x
            .mul(&x)
            .scale(2.0)
            .sub(&c.mul(&Poly::symbol(Symbol::Param(0))));
        assert_eq!(p.to_text(&names), "-L*cos(A) + 2*x^2");
        assert_eq!(p.to_latex(&names), "-L cos(A) + 2 x^{2}");
    }

    #[test]
    fn sin_cubed_folds() {
        let s = Poly::symbol(Symbol::Sin(0));
        let c = Poly::symbol(Symbol::Cos(0));
        let s3 = s.pow(3);
        let expected = s.sub(&s.mul(&c).mul(&c));
        assert_eq!(s3, expected);
        let v = |sym: Symbol| match sym {
            Symbol::Sin(_) => 0.3f64.sin(),
            Symbol::Cos(_) => 0.3f64.cos(),
            _ => 0.0,
        };
        assert!((s3.eval(&v) - 0.3f64.sin().powi(3)).abs() < 1e-15);
    }
}
