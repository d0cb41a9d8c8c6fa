//! Exports of a [`SymbolicModel`]: plain text, JSON (the spec's `derive`
//! contract) and LaTeX. Rust code is emitted by [`crate::emit`].
//!
//! Expressions use decimal numbers, variable and parameter names, `+ - * ^`
//! and `sin(name)`, `cos(name)`: SymPy's `sympify` and MATLAB read them as
//! they are.

use serde::Serialize;
#[cfg(feature = "json")]
use serde_json::{Map, Value};

use crate::algebra::{Poly, Symbol};
use crate::derive::SymbolicModel;
use crate::model::Component;

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
    /// `R_wt(q,0)` and `T_wt(q,0)·tool_point`.
    pub nominal: NominalJson,
    /// Per component, every error with a non-zero coefficient → coefficient.
    pub components: Map<String, Value>,
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
        nominal: NominalJson {
            rotation: std::array::from_fn(|i| {
                std::array::from_fn(|j| text(&model.nominal_rotation[i][j]))
            }),
            position: std::array::from_fn(|i| text(&model.nominal_position[i])),
        },
        components,
    }
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
        "errors ({}): {}\n\n",
        model.errors.len(),
        list(model.errors.clone())
    ));
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
