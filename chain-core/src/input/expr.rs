//! Arithmetic expressions of machine files: `-L`, `q2x + 10`, `0.05/6`,
//! `pi/2`, `2*L^2`.
//!
//! [`parse`] turns text into an [`Ast`] (numbers such as `1e-3`, names,
//! `+ - * /`, `^` with an integer exponent, unary minus, parentheses); errors
//! carry a byte offset into the text ([`ExprError`]), so any front end can
//! locate them. [`resolve`] then binds names to parameters and produces a
//! [`model::Expr`](crate::model::Expr), rejecting parameters in divisors and
//! negative powers of parameters (the derivation needs polynomials in the
//! parameters); [`eval_const`] evaluates a numbers-only expression. Constant
//! sub-expressions are folded, and the name `pi` is the constant π.

use std::fmt;

use crate::diagnostic::Problem;
use crate::model::Expr;

/// Maximum number of tokens in one expression.
pub const MAX_TOKENS: usize = 1000;

/// Maximum nesting of parentheses and unary operators.
pub const MAX_NESTING: usize = 64;

/// Largest allowed absolute value of an exponent.
pub const MAX_EXPONENT: i32 = 64;

/// A parsed, unresolved expression.
#[derive(Debug, Clone, PartialEq)]
pub enum Ast {
    /// A number literal.
    Num(f64),
    /// A name, with its byte offset in the text.
    Name {
        /// The name.
        name: String,
        /// Byte offset of its first character.
        offset: usize,
    },
    /// Unary minus.
    Neg(Box<Ast>),
    /// Sum.
    Add(Box<Ast>, Box<Ast>),
    /// Difference.
    Sub(Box<Ast>, Box<Ast>),
    /// Product.
    Mul(Box<Ast>, Box<Ast>),
    /// Quotient.
    Div(Box<Ast>, Box<Ast>),
    /// Integer power.
    Pow(Box<Ast>, i32),
}

/// A syntax error in an expression: where (byte offset into the text) and
/// what.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ExprError {
    /// Byte offset into the expression text.
    pub offset: usize,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for ExprError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} (at byte {})", self.message, self.offset)
    }
}

impl std::error::Error for ExprError {}

#[derive(Debug, Clone, PartialEq)]
enum Tok {
    Num(f64, bool),
    Name(String),
    Op(char),
    End,
}

fn describe(t: &Tok) -> String {
    match t {
        Tok::Num(..) => "a number".into(),
        Tok::Name(n) => format!("`{n}`"),
        Tok::Op(c) => format!("`{c}`"),
        Tok::End => "the end".into(),
    }
}

fn err(offset: usize, message: impl Into<String>) -> ExprError {
    ExprError {
        offset,
        message: message.into(),
    }
}

fn lex(text: &str) -> Result<Vec<(Tok, usize)>, ExprError> {
    let bytes = text.as_bytes();
    let mut toks = Vec::new();
    let mut i = 0;
    while let Some(&b) = bytes.get(i) {
        if toks.len() > MAX_TOKENS {
            return Err(err(
                i,
                format!("expression too long (more than {MAX_TOKENS} tokens)"),
            ));
        }
        let start = i;
        match b {
            b' ' | b'\t' => i += 1,
            b'+' | b'-' | b'*' | b'/' | b'^' | b'(' | b')' => {
                toks.push((Tok::Op(char::from(b)), start));
                i += 1;
            }
            b'0'..=b'9' | b'.' => {
                let digits = |i: &mut usize| {
                    let s = *i;
                    while bytes.get(*i).is_some_and(u8::is_ascii_digit) {
                        *i += 1;
                    }
                    *i - s
                };
                let mut n = digits(&mut i);
                let mut integer = true;
                if bytes.get(i) == Some(&b'.') {
                    i += 1;
                    integer = false;
                    n += digits(&mut i);
                }
                if n == 0 {
                    return Err(err(start, "expected digits"));
                }
                if matches!(bytes.get(i), Some(b'e' | b'E')) {
                    let mut j = i + 1;
                    if matches!(bytes.get(j), Some(b'+' | b'-')) {
                        j += 1;
                    }
                    if bytes.get(j).is_some_and(u8::is_ascii_digit) {
                        i = j;
                        digits(&mut i);
                        integer = false;
                    }
                }
                let lit = text.get(start..i).unwrap_or("");
                let v: f64 = lit
                    .parse()
                    .map_err(|_| err(start, format!("invalid number `{lit}`")))?;
                toks.push((Tok::Num(v, integer), start));
            }
            b'a'..=b'z' | b'A'..=b'Z' | b'_' => {
                while bytes
                    .get(i)
                    .is_some_and(|c| c.is_ascii_alphanumeric() || *c == b'_')
                {
                    i += 1;
                }
                toks.push((Tok::Name(text.get(start..i).unwrap_or("").into()), start));
            }
            _ => {
                let c = text
                    .get(start..)
                    .and_then(|r| r.chars().next())
                    .unwrap_or('?');
                return Err(err(start, format!("unexpected character `{c}`")));
            }
        }
    }
    toks.push((Tok::End, text.len()));
    Ok(toks)
}

struct P {
    toks: Vec<(Tok, usize)>,
    pos: usize,
    depth: usize,
}

impl P {
    fn peek(&self) -> (&Tok, usize) {
        match self.toks.get(self.pos) {
            Some((t, o)) => (t, *o),
            None => (&Tok::End, self.toks.last().map_or(0, |t| t.1)),
        }
    }

    fn bump(&mut self) {
        self.pos += 1;
    }

    fn is_op(&self, c: char) -> bool {
        matches!(self.peek().0, Tok::Op(o) if *o == c)
    }

    fn enter(&mut self) -> Result<(), ExprError> {
        self.depth += 1;
        if self.depth > MAX_NESTING {
            return Err(err(self.peek().1, "expression nested too deeply"));
        }
        Ok(())
    }

    fn expr(&mut self) -> Result<Ast, ExprError> {
        let mut lhs = self.term()?;
        loop {
            let add = if self.is_op('+') {
                true
            } else if self.is_op('-') {
                false
            } else {
                return Ok(lhs);
            };
            self.bump();
            let rhs = self.term()?;
            lhs = if add {
                Ast::Add(Box::new(lhs), Box::new(rhs))
            } else {
                Ast::Sub(Box::new(lhs), Box::new(rhs))
            };
        }
    }

    fn term(&mut self) -> Result<Ast, ExprError> {
        let mut lhs = self.unary()?;
        loop {
            let mul = if self.is_op('*') {
                true
            } else if self.is_op('/') {
                false
            } else {
                return Ok(lhs);
            };
            self.bump();
            let rhs = self.unary()?;
            lhs = if mul {
                Ast::Mul(Box::new(lhs), Box::new(rhs))
            } else {
                Ast::Div(Box::new(lhs), Box::new(rhs))
            };
        }
    }

    fn unary(&mut self) -> Result<Ast, ExprError> {
        if self.is_op('-') || self.is_op('+') {
            let neg = self.is_op('-');
            self.bump();
            self.enter()?;
            let inner = self.unary()?;
            self.depth -= 1;
            return Ok(if neg {
                Ast::Neg(Box::new(inner))
            } else {
                inner
            });
        }
        self.power()
    }

    fn power(&mut self) -> Result<Ast, ExprError> {
        let base = self.atom()?;
        if !self.is_op('^') {
            return Ok(base);
        }
        self.bump();
        let mut negative = false;
        if self.is_op('-') || self.is_op('+') {
            negative = self.is_op('-');
            self.bump();
        }
        let (tok, off) = self.peek();
        let n = match tok {
            Tok::Num(v, true) if *v <= f64::from(MAX_EXPONENT) => {
                // An integer literal no larger than MAX_EXPONENT: exact.
                let n = *v as i32;
                if negative {
                    -n
                } else {
                    n
                }
            }
            Tok::Num(_, true) => {
                return Err(err(
                    off,
                    format!("exponent too large (at most {MAX_EXPONENT})"),
                ))
            }
            _ => {
                return Err(err(
                    off,
                    "the exponent after `^` must be an integer literal",
                ))
            }
        };
        self.bump();
        if self.is_op('^') {
            return Err(err(self.peek().1, "write `(a^m)^n` explicitly"));
        }
        Ok(Ast::Pow(Box::new(base), n))
    }

    fn atom(&mut self) -> Result<Ast, ExprError> {
        let (tok, off) = self.peek();
        match tok.clone() {
            Tok::Num(v, _) => {
                self.bump();
                Ok(Ast::Num(v))
            }
            Tok::Name(name) => {
                self.bump();
                if self.is_op('(') {
                    return Err(err(
                        off,
                        format!("functions such as `{name}(…)` are not supported"),
                    ));
                }
                Ok(Ast::Name { name, offset: off })
            }
            Tok::Op('(') => {
                self.bump();
                self.enter()?;
                let inner = self.expr()?;
                self.depth -= 1;
                if !self.is_op(')') {
                    let (t, o) = self.peek();
                    return Err(err(o, format!("expected `)`, found {}", describe(t))));
                }
                self.bump();
                Ok(inner)
            }
            Tok::End if off == 0 => Err(err(0, "empty expression")),
            t => Err(err(
                off,
                format!("expected a number, a name or `(`, found {}", describe(&t)),
            )),
        }
    }
}

/// Parses an expression. Whitespace (spaces and tabs) between tokens is
/// ignored. Never panics.
pub fn parse(text: &str) -> Result<Ast, ExprError> {
    let toks = lex(text)?;
    let mut p = P {
        toks,
        pos: 0,
        depth: 0,
    };
    if matches!(p.peek().0, Tok::End) {
        return Err(err(0, "empty expression"));
    }
    let ast = p.expr()?;
    let (t, o) = p.peek();
    match t {
        Tok::End => Ok(ast),
        Tok::Op(')') => Err(err(o, "unmatched `)`")),
        t => Err(err(
            o,
            format!("expected an operator, found {}", describe(t)),
        )),
    }
}

/// An error found while resolving names: byte offset into the text and the
/// problem.
pub type ResolveError = (usize, Problem);

/// Resolves the names of `ast`: `pi` is π; every other name goes to
/// `lookup`, which returns `Ok(Some(index))` for a parameter (index into
/// [`Machine::parameters`](crate::model::Machine::parameters)), `Ok(None)` for
/// a name that is wrong but already reported (it resolves to 0 without a new
/// error), or `Err(problem)`.
///
/// Constant sub-expressions are folded. All errors are collected.
pub fn resolve<F>(ast: &Ast, mut lookup: F) -> Result<Expr, Vec<ResolveError>>
where
    F: FnMut(&str) -> Result<Option<usize>, Problem>,
{
    let mut errors = Vec::new();
    let (expr, _) = resolve_in(ast, &mut lookup, &mut errors);
    if errors.is_empty() {
        Ok(expr)
    } else {
        Err(errors)
    }
}

/// Evaluates a numbers-only expression (`pi` allowed). A name is
/// [`Problem::NameInNumber`].
pub fn eval_const(ast: &Ast) -> Result<f64, Vec<ResolveError>> {
    let expr = resolve(ast, |name| {
        Err(Problem::NameInNumber {
            name: name.to_string(),
        })
    })?;
    match expr {
        Expr::Num(v) => Ok(v),
        // Without parameters everything folds; keep a defensive answer.
        other => Ok(other.eval(&[])),
    }
}

/// The first parameter of a resolved sub-expression: name and offset.
type FirstParam = Option<(String, usize)>;

fn resolve_in<F>(ast: &Ast, lookup: &mut F, errors: &mut Vec<ResolveError>) -> (Expr, FirstParam)
where
    F: FnMut(&str) -> Result<Option<usize>, Problem>,
{
    fn first(a: FirstParam, b: FirstParam) -> FirstParam {
        a.or(b)
    }
    match ast {
        Ast::Num(v) => (Expr::Num(*v), None),
        Ast::Name { name, offset } => {
            if name == "pi" {
                return (Expr::Num(std::f64::consts::PI), None);
            }
            match lookup(name) {
                Ok(Some(i)) => (Expr::Param(i), Some((name.clone(), *offset))),
                Ok(None) => (Expr::Num(0.0), None),
                Err(p) => {
                    errors.push((*offset, p));
                    (Expr::Num(0.0), None)
                }
            }
        }
        Ast::Neg(a) => {
            let (a, pa) = resolve_in(a, lookup, errors);
            let e = match a {
                Expr::Num(v) => Expr::Num(-v),
                a => Expr::Neg(Box::new(a)),
            };
            (e, pa)
        }
        Ast::Add(a, b) | Ast::Sub(a, b) | Ast::Mul(a, b) | Ast::Div(a, b) => {
            let (ea, pa) = resolve_in(a, lookup, errors);
            let (eb, pb) = resolve_in(b, lookup, errors);
            if let (Ast::Div(..), Some((name, offset))) = (ast, &pb) {
                errors.push((*offset, Problem::ParameterInDivisor { name: name.clone() }));
            }
            let e = match (ast, ea, eb) {
                (Ast::Add(..), Expr::Num(x), Expr::Num(y)) => Expr::Num(x + y),
                (Ast::Sub(..), Expr::Num(x), Expr::Num(y)) => Expr::Num(x - y),
                (Ast::Mul(..), Expr::Num(x), Expr::Num(y)) => Expr::Num(x * y),
                (Ast::Div(..), Expr::Num(x), Expr::Num(y)) => Expr::Num(x / y),
                (Ast::Add(..), x, y) => Expr::Add(Box::new(x), Box::new(y)),
                (Ast::Sub(..), x, y) => Expr::Sub(Box::new(x), Box::new(y)),
                (Ast::Mul(..), x, y) => Expr::Mul(Box::new(x), Box::new(y)),
                (_, x, y) => Expr::Div(Box::new(x), Box::new(y)),
            };
            (e, first(pa, pb))
        }
        Ast::Pow(a, n) => {
            let (ea, pa) = resolve_in(a, lookup, errors);
            if *n < 0 {
                if let Some((name, offset)) = &pa {
                    errors.push((
                        *offset,
                        Problem::NegativePowerOfParameter { name: name.clone() },
                    ));
                }
            }
            let e = match ea {
                Expr::Num(x) => Expr::Num(x.powi(*n)),
                x => Expr::Pow(Box::new(x), *n),
            };
            (e, pa)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn num(text: &str) -> f64 {
        eval_const(&parse(text).unwrap()).unwrap()
    }

    #[test]
    fn numbers_and_precedence() {
        assert_eq!(num("1e-3"), 1e-3);
        assert_eq!(num("0.05/6"), 0.05 / 6.0);
        assert_eq!(num("-2^2"), -4.0);
        assert_eq!(num("2*(3+4)"), 14.0);
        assert_eq!(num("2^-1"), 0.5);
        assert_eq!(num(".5 + 5."), 5.5);
        assert_eq!(num("10 - 2 - 3"), 5.0);
        assert_eq!(num("8 / 2 / 2"), 2.0);
        assert_eq!(num("pi"), std::f64::consts::PI);
        assert_eq!(num("--1"), 1.0);
    }

    #[test]
    fn syntax_errors_have_offsets() {
        assert_eq!(parse("1 + * 2").unwrap_err().offset, 4);
        assert_eq!(parse("(1 + 2").unwrap_err().offset, 6);
        assert_eq!(parse("1 + 2)").unwrap_err().offset, 5);
        assert_eq!(parse("2L").unwrap_err().offset, 1);
        assert_eq!(parse("").unwrap_err().offset, 0);
        assert_eq!(parse("  ").unwrap_err().offset, 0);
        assert_eq!(parse("x^y").unwrap_err().offset, 2);
        assert_eq!(parse("x^1.5").unwrap_err().offset, 2);
        assert_eq!(parse("1 $ 2").unwrap_err().offset, 2);
        assert_eq!(parse("sin(x)").unwrap_err().offset, 0);
    }

    #[test]
    fn limits() {
        assert!(parse(&"(".repeat(100_000)).is_err());
        assert!(parse(&"-".repeat(100_000)).is_err());
        assert!(parse(&"1+".repeat(100_000)).is_err());
        assert!(parse("x^100000000000").is_err());
    }

    #[test]
    fn resolve_parameters() {
        let ast = parse("2*L - q/4").unwrap();
        let e = resolve(&ast, |n| Ok(["L", "q"].iter().position(|p| *p == n))).unwrap();
        assert_eq!(e.eval(&[1.0, 8.0]), 0.0);
    }

    #[test]
    fn parameter_in_divisor() {
        let ast = parse("1/(2*L)").unwrap();
        let errs = resolve(&ast, |_| Ok(Some(0))).unwrap_err();
        assert_eq!(errs[0].0, 5);
        assert!(matches!(errs[0].1, Problem::ParameterInDivisor { .. }));
        let ast = parse("L^-2").unwrap();
        let errs = resolve(&ast, |_| Ok(Some(0))).unwrap_err();
        assert!(matches!(
            errs[0].1,
            Problem::NegativePowerOfParameter { .. }
        ));
    }

    #[test]
    fn unknown_names_are_collected() {
        let ast = parse("a + b").unwrap();
        let errs = resolve(&ast, |n| {
            Err(Problem::UnknownName {
                name: n.into(),
                hint: None,
            })
        })
        .unwrap_err();
        assert_eq!(errs.len(), 2);
        assert_eq!(errs[1].0, 4);
    }
}
