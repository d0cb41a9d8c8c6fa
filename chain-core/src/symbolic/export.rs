//! Exports of a [`SymbolicModel`]: plain text, JSON (the spec's `derive`
//! contract) and LaTeX. Rust code is emitted by [`crate::emit`].
//!
//! Expressions use decimal numbers, variable and parameter names, `+ - * ^`
//! and `sin(name)`, `cos(name)`: SymPy's `sympify` and MATLAB read them as
//! they are.
//!
//! A machine with function slots (measured-machines spec, section 1) adds
//! their definitions: a top-level `functions` list in JSON, a `functions`
//! block after the error list in text, one `align*` line each in LaTeX; the
//! coefficients appear in `errors` and `components` as ordinary errors.
//! A machine without function slots gets none of these additions (its
//! outputs are pinned byte for byte by the golden tests;
//! `docs/function-slots-derivation.md`).

use serde::Serialize;
#[cfg(feature = "json")]
use serde_json::{Map, Value};

#[cfg(feature = "json")]
use crate::algebra::{basis_poly, index_u16};
use crate::algebra::{format_number, Poly, Symbol};
use crate::derive::SymbolicModel;
#[cfg(feature = "json")]
use crate::model::Basis;
use crate::model::{BasisFn, Component, ErrorFunction};

/// The JSON document of `chain derive --format json` (spec section 3).
#[cfg(feature = "json")]
#[derive(Debug, Clone, Serialize)]
pub struct DeriveJson {
    /// Machine identifier.
    pub machine: String,
    /// `tool` or `workpiece`.
    pub frame: String,
    /// Axis variable names.
    pub variables: Vec<String>,
    /// Parameter names.
    pub parameters: Vec<String>,
    /// Parameter values from the file (`null`: symbolic). An addition to the spec.
    pub parameter_values: Map<String, Value>,
    /// Error parameter names.
    pub errors: Vec<String>,
    /// The function slots (error motions varying along their axis), present
    /// only when the machine has any. An addition to the spec.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub functions: Vec<FunctionJson>,
    /// The thermal coefficients, present only when the machine has any:
    /// error → `{"sensor": name, "reference": °C}`; the error's value is per
    /// kelvin of `sensor − reference` (docs/thermal.md). An addition to the
    /// spec.
    #[serde(skip_serializing_if = "Map::is_empty")]
    pub thermal: Map<String, Value>,
    /// `R_wt(q,0)` and `T_wt(q,0)·tool_point`.
    pub nominal: NominalJson,
    /// Per component, every error with a non-zero coefficient → coefficient.
    pub components: Map<String, Value>,
}

/// One function slot in the JSON document:
/// `{"name": "EYX", "variable": "x", "basis": "powers", "powers": [1, 2],
/// "coefficients": ["EYX_1", "EYX_2"], "basis_functions": ["x", "x^2"]}`.
///
/// The basis keys are the machine file's (`powers`; `degree`, `range`,
/// `from`; `harmonics`); `basis_functions[k]` is `b_k(q)` of
/// `coefficients[k]` as the engine's exact polynomial (measured-machines
/// spec, section 1), so `F(q) = Σ_k coefficients[k] · basis_functions[k]`.
#[cfg(feature = "json")]
#[derive(Debug, Clone, Serialize)]
pub struct FunctionJson {
    /// The function's name.
    pub name: String,
    /// The joint variable `q` it varies along.
    pub variable: String,
    /// The basis and its keys.
    #[serde(flatten)]
    pub basis: Basis,
    /// The coefficient error parameters, in basis order.
    pub coefficients: Vec<String>,
    /// Each coefficient's basis function as an expression in the variable.
    pub basis_functions: Vec<String>,
}

/// The nominal pose as expressions.
#[derive(Debug, Clone, Serialize)]
pub struct NominalJson {
    /// Rotation, row-major.
    pub rotation: [[String; 3]; 3],
    /// Position.
    pub position: [String; 3],
}

/// Builds the JSON document.
#[cfg(feature = "json")]
pub fn to_json(model: &SymbolicModel) -> DeriveJson {
    let text = |p: &Poly| p.to_text(&|s| model.symbol_name(s));
    let mut components = Map::new();
    for c in Component::ALL {
        let mut entries = Map::new();
        for (j, poly) in &model.components[c.index()] {
            entries.insert(model.errors[*j].clone(), Value::String(text(poly)));
        }
        components.insert(c.name().to_string(), Value::Object(entries));
    }
    DeriveJson {
        machine: model.machine.clone(),
        frame: model.frame.name().to_string(),
        variables: model.variables.iter().map(|v| v.0.clone()).collect(),
        parameters: model.parameters.iter().map(|p| p.0.clone()).collect(),
        parameter_values: model
            .parameters
            .iter()
            .map(|(name, v)| {
                let value = v
                    .and_then(serde_json::Number::from_f64)
                    .map_or(Value::Null, Value::Number);
                (name.clone(), value)
            })
            .collect(),
        errors: model.errors.clone(),
        functions: model
            .functions
            .iter()
            .map(|f| FunctionJson {
                name: f.name.clone(),
                variable: variable_name(model, f).to_string(),
                basis: f.basis.clone(),
                coefficients: f
                    .coefficients
                    .iter()
                    .map(|(j, _)| model.errors[*j].clone())
                    .collect(),
                basis_functions: f
                    .coefficients
                    .iter()
                    .map(|(_, b)| text(&basis_poly(b, index_u16(f.variable))))
                    .collect(),
            })
            .collect(),
        thermal: (model.errors.iter().zip(&model.thermal))
            .filter_map(|(e, t)| {
                let (sensor, reference) = t.as_ref()?;
                Some((
                    e.clone(),
                    serde_json::json!({"sensor": sensor, "reference": reference}),
                ))
            })
            .collect(),
        nominal: NominalJson {
            rotation: std::array::from_fn(|i| {
                std::array::from_fn(|j| text(&model.nominal_rotation[i][j]))
            }),
            position: std::array::from_fn(|i| text(&model.nominal_position[i])),
        },
        components,
    }
}

/// The name of a function's variable.
fn variable_name<'m>(model: &'m SymbolicModel, f: &ErrorFunction) -> &'m str {
    model
        .variables
        .get(f.variable)
        .map_or("?", |v| v.0.as_str())
}

/// How the readable formats write a function.
struct FunctionForm {
    /// `(coefficient name, basis function)` in basis order.
    terms: Vec<(String, Term)>,
    /// The range `[lo, hi]` that defines `t` (Legendre, Chebyshev).
    scaled: Option<[f64; 2]>,
    /// The basis as the machine file has it: `legendre, degree 3, range [0, 1000]`.
    basis: String,
}

/// A basis function as the readable formats write it.
enum Term {
    /// `1`.
    One,
    /// `q^k`, `k ≥ 1`.
    Power(u32),
    /// `P_k(t)` or `T_k(t)`.
    Orthogonal(char, u32),
    /// `cos kq` or `sin kq`, `k ≥ 1`.
    Trig(&'static str, u32),
}

fn function_form(model: &SymbolicModel, f: &ErrorFunction) -> FunctionForm {
    let terms = f
        .coefficients
        .iter()
        .map(|(j, b)| {
            let term = match *b {
                b if b.is_constant() => Term::One,
                BasisFn::Power(k) => Term::Power(k),
                BasisFn::Legendre { k, .. } => Term::Orthogonal('P', k),
                BasisFn::Chebyshev { k, .. } => Term::Orthogonal('T', k),
                BasisFn::Cos(k) => Term::Trig("cos", k),
                BasisFn::Sin(k) => Term::Trig("sin", k),
            };
            (model.errors[*j].clone(), term)
        })
        .collect();
    let list = |v: &[u32]| v.iter().map(u32::to_string).collect::<Vec<_>>().join(", ");
    let (scaled, basis) = match &f.basis {
        crate::model::Basis::Powers { powers } => (None, format!("powers [{}]", list(powers))),
        crate::model::Basis::Legendre {
            degree,
            range,
            from,
        }
        | crate::model::Basis::Chebyshev {
            degree,
            range,
            from,
        } => {
            let from = if *from == 0 {
                String::new()
            } else {
                format!(", from {from}")
            };
            (
                Some(*range),
                format!(
                    "{}, degree {degree}{from}, range [{}, {}]",
                    f.basis.name(),
                    format_number(range[0]),
                    format_number(range[1])
                ),
            )
        }
        crate::model::Basis::Fourier { harmonics } => (
            None,
            format!(
                "fourier, {harmonics} harmonic{}",
                if *harmonics == 1 { "" } else { "s" }
            ),
        ),
    };
    FunctionForm {
        terms,
        scaled,
        basis,
    }
}

/// `t = (2q − lo − hi)/(hi − lo)` with the numbers worked out:
/// `(2*x - 1000)/1000` (plain) or `\frac{2x - 1000}{1000}` (LaTeX).
fn scaled_text(q: &str, range: [f64; 2], latex: bool) -> String {
    let [lo, hi] = range;
    let shift = lo + hi;
    let times = if latex { "" } else { "*" };
    let numerator = if shift == 0.0 {
        format!("2{times}{q}")
    } else if shift > 0.0 {
        format!("2{times}{q} - {}", format_number(shift))
    } else {
        format!("2{times}{q} + {}", format_number(-shift))
    };
    let width = format_number(hi - lo);
    if latex {
        format!("\\frac{{{numerator}}}{{{width}}}")
    } else if shift == 0.0 {
        format!("{numerator}/{width}")
    } else {
        format!("({numerator})/{width}")
    }
}

/// The text line of a function:
/// `EYX(x) = EYX_1*x + EYX_2*x^2  (powers [1, 2])`.
pub(crate) fn function_text(model: &SymbolicModel, f: &ErrorFunction) -> String {
    let q = variable_name(model, f);
    let form = function_form(model, f);
    let terms: Vec<String> = (form.terms.iter().zip(&f.coefficients))
        .map(|((name, term), (j, _))| {
            let text = match term {
                Term::One => name.clone(),
                Term::Power(1) => format!("{name}*{q}"),
                Term::Power(k) => format!("{name}*{q}^{k}"),
                Term::Orthogonal(p, k) => format!("{name}*{p}_{k}(t)"),
                Term::Trig(fun, 1) => format!("{name}*{fun}({q})"),
                Term::Trig(fun, k) => format!("{name}*{fun}({k}*{q})"),
            };
            match model.thermal.get(*j).and_then(Option::as_ref) {
                Some((sensor, reference)) => {
                    format!("{text}*({sensor} - {})", format_number(*reference))
                }
                None => text,
            }
        })
        .collect();
    let t = form
        .scaled
        .map(|r| format!(", t = {}", scaled_text(q, r, false)))
        .unwrap_or_default();
    format!(
        "{}({q}) = {}{t}  ({})",
        f.name,
        terms.join(" + "),
        form.basis
    )
}

/// The LaTeX line of a function (without the line break).
fn function_latex(model: &SymbolicModel, f: &ErrorFunction) -> String {
    let q = latex_ident(variable_name(model, f));
    let form = function_form(model, f);
    let terms: Vec<String> = form
        .terms
        .iter()
        .map(|(name, term)| {
            let name = latex_ident(name);
            match term {
                Term::One => name,
                Term::Power(1) => format!("{name}\\, {q}"),
                Term::Power(k) => format!("{name}\\, {q}^{{{k}}}"),
                Term::Orthogonal(p, k) => format!("{name}\\, {p}_{{{k}}}(t)"),
                Term::Trig(fun, 1) => format!("{name} \\{fun} {q}"),
                Term::Trig(fun, k) => format!("{name} \\{fun} {k}{q}"),
            }
        })
        .collect();
    let t = form
        .scaled
        .map(|r| format!(",\\quad t = {}", scaled_text(&q, r, true)))
        .unwrap_or_default();
    format!("{}({q}) &= {}{t}", latex_ident(&f.name), terms.join(" + "))
}

/// `coefficient · name` as a readable term of a sum, with its sign split off:
/// `(negative, "z*eyx")`.
pub(crate) fn term(coefficient: &str, name: &str) -> (bool, String) {
    let (negative, body) = match coefficient.strip_prefix('-') {
        Some(rest) if !rest.contains(" + ") && !rest.contains(" - ") => (true, rest),
        _ => (false, coefficient),
    };
    let text = if body == "1" {
        name.to_string()
    } else if body.contains(" + ") || body.contains(" - ") {
        format!("({body})*{name}")
    } else {
        format!("{body}*{name}")
    };
    (negative, text)
}

/// Joins signed terms into `a - b + c`.
pub(crate) fn join_terms(terms: &[(bool, String)], separator: (&str, &str)) -> String {
    if terms.is_empty() {
        return "0".to_string();
    }
    let mut out = String::new();
    for (k, (negative, text)) in terms.iter().enumerate() {
        match (k, negative) {
            (0, true) => out.push('-'),
            (0, false) => {}
            (_, true) => out.push_str(separator.1),
            (_, false) => out.push_str(separator.0),
        }
        out.push_str(text);
    }
    out
}

/// The plain-text report of `chain derive --format text`.
pub fn to_text(model: &SymbolicModel) -> String {
    let text = |p: &Poly| p.to_text(&|s| model.symbol_name(s));
    let mut out = String::new();
    out.push_str(&format!(
        "machine {} (frame: {})\n",
        model.machine,
        model.frame.name()
    ));
    let list = |v: Vec<String>| {
        if v.is_empty() {
            "(none)".to_string()
        } else {
            v.join(", ")
        }
    };
    out.push_str(&format!(
        "variables: {}\n",
        list(model.variables.iter().map(|v| v.0.clone()).collect())
    ));
    out.push_str(&format!(
        "parameters: {}\n",
        list(
            model
                .parameters
                .iter()
                .map(|(n, v)| match v {
                    Some(v) => format!("{n} = {v}"),
                    None => n.clone(),
                })
                .collect()
        )
    ));
    out.push_str(&format!(
        "errors ({}): {}\n",
        model.errors.len(),
        list(model.errors.clone())
    ));
    if !model.functions.is_empty() {
        out.push_str(&format!("functions ({}):\n", model.functions.len()));
        for f in &model.functions {
            out.push_str(&format!("  {}\n", function_text(model, f)));
        }
    }
    let thermal: Vec<String> = (model.errors.iter().zip(&model.thermal))
        .filter_map(|(e, t)| {
            let (sensor, reference) = t.as_ref()?;
            Some(format!(
                "{e} per K of {sensor} - {}",
                format_number(*reference)
            ))
        })
        .collect();
    if !thermal.is_empty() {
        out.push_str(&format!(
            "thermal coefficients ({}): {}\n",
            thermal.len(),
            thermal.join(", ")
        ));
    }
    out.push('\n');
    out.push_str("nominal rotation R_wt(q, 0):\n");
    for row in &model.nominal_rotation {
        let cells: Vec<String> = row.iter().map(text).collect();
        out.push_str(&format!("  [{}]\n", cells.join(", ")));
    }
    let pos: Vec<String> = model.nominal_position.iter().map(text).collect();
    out.push_str(&format!(
        "nominal position T_wt(q, 0)·tool_point: [{}]\n\n",
        pos.join(", ")
    ));
    for c in Component::ALL {
        let terms: Vec<(bool, String)> = model.components[c.index()]
            .iter()
            .map(|(j, poly)| term(&text(poly), &model.errors[*j]))
            .collect();
        out.push_str(&format!(
            "{} = {}\n",
            c.name(),
            join_terms(&terms, (" + ", " - "))
        ));
    }
    out
}

/// LaTeX name of an identifier: `eyx` → `\mathit{eyx}`, `x` → `x`.
fn latex_ident(name: &str) -> String {
    let escaped = name.replace('_', "\\_");
    if name.chars().count() == 1 {
        escaped
    } else {
        format!("\\mathit{{{escaped}}}")
    }
}

fn latex_symbol(model: &SymbolicModel, s: Symbol) -> String {
    let var = |i: u16| {
        latex_ident(
            model
                .variables
                .get(usize::from(i))
                .map_or("?", |v| v.0.as_str()),
        )
    };
    match s {
        Symbol::Param(i) => latex_ident(
            model
                .parameters
                .get(usize::from(i))
                .map_or("?", |p| p.0.as_str()),
        ),
        Symbol::Var(i) => var(i),
        Symbol::Cos(i) => format!("\\cos {}", var(i)),
        Symbol::Sin(i) => format!("\\sin {}", var(i)),
    }
}

/// The LaTeX document body of `chain derive --format latex`: an `align*`
/// environment with the nominal pose and the six components.
pub fn to_latex(model: &SymbolicModel) -> String {
    let tex = |p: &Poly| p.to_latex(&|s| latex_symbol(model, s));
    let mut out = String::new();
    out.push_str(&format!(
        "% chain derive: machine {} (frame: {})\n\\begin{{align*}}\n",
        model.machine,
        model.frame.name()
    ));
    for f in &model.functions {
        out.push_str(&function_latex(model, f));
        out.push_str(" \\\\\n");
    }
    out.push_str("R_{wt}(q, 0) &= \\begin{bmatrix}");
    let rows: Vec<String> = model
        .nominal_rotation
        .iter()
        .map(|row| row.iter().map(tex).collect::<Vec<_>>().join(" & "))
        .collect();
    out.push_str(&rows.join(" \\\\ "));
    out.push_str("\\end{bmatrix} \\\\\n");
    let pos: Vec<String> = model.nominal_position.iter().map(tex).collect();
    out.push_str(&format!(
        "T_{{wt}}(q, 0)\\,t &= \\begin{{bmatrix}}{}\\end{{bmatrix}}",
        pos.join(" \\\\ ")
    ));
    for c in Component::ALL {
        let terms: Vec<(bool, String)> = model.components[c.index()]
            .iter()
            .map(|(j, poly)| {
                let coefficient = tex(poly);
                let name = latex_ident(&model.errors[*j]);
                let (negative, body) = match coefficient.strip_prefix('-') {
                    Some(rest) if !rest.contains(" + ") && !rest.contains(" - ") => (true, rest),
                    _ => (false, coefficient.as_str()),
                };
                let text = if body == "1" {
                    name
                } else if body.contains(" + ") || body.contains(" - ") {
                    format!("\\left({body}\\right) {name}")
                } else {
                    format!("{body}\\, {name}")
                };
                (negative, text)
            })
            .collect();
        let name = c.name();
        out.push_str(&format!(
            " \\\\\n{}_{{{}}} &= {}",
            &name[..1],
            &name[1..],
            join_terms(&terms, (" + ", " - "))
        ));
    }
    out.push_str("\n\\end{align*}\n");
    out
}
