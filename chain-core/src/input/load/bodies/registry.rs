//! The error parameters and function slots in order of first use, walking
//! the bodies in the machine's order: names, kinds, collisions and
//! redeclarations.

use std::collections::{HashMap, HashSet};

use super::slots::{Item, RawFunction};
use super::{RawBody, Use};
use crate::diagnostic::Problem;
use crate::input::load::{Loader, TreeReader};
use crate::model::{
    Basis, ErrorFunction, ErrorKind, ErrorParam, ErrorSlots, Origin, Slot, Variable,
};

impl Loader {
    /// Error parameters in order of first use, the function slots in order
    /// of first declaration, and each body's slots (`location_errors`,
    /// `errors` + `squareness`), by file index.
    pub(super) fn errors(
        &mut self,
        raws: &[RawBody<'_>],
        order: &[usize],
        variables: &[Variable],
        var_of_body: &[Option<usize>],
    ) -> (
        Vec<ErrorParam>,
        Vec<ErrorFunction>,
        Vec<(ErrorSlots, ErrorSlots)>,
    ) {
        let mut r = Registry {
            variable_names: raws
                .iter()
                .filter_map(|r| r.joint.as_ref()?.variable.as_ref().map(|u| u.name.clone()))
                .collect(),
            variables,
            ..Registry::default()
        };
        // Sensors and axis variables share a measurement file's header.
        for sensor in &self.sensors {
            if r.variable_names.contains(&sensor.name) {
                let problem = Problem::NameCollision {
                    name: sensor.name.clone(),
                    what: "sensor",
                    other: "axis variable",
                };
                self.errors.push((sensor.origin.clone(), problem));
            }
        }
        let mut slots = vec![(ErrorSlots::default(), ErrorSlots::default()); raws.len()];
        for &old in order {
            let Some(raw) = raws.get(old) else { continue };
            let variable = var_of_body.get(old).copied().flatten();
            for (g, group) in raw.slots.iter().enumerate() {
                for (s, items) in group.iter().enumerate() {
                    let Some(&slot) = Slot::ALL.get(s) else {
                        continue;
                    };
                    let kind = if g == 2 {
                        ErrorKind::Squareness
                    } else if slot.is_linear() {
                        ErrorKind::Linear
                    } else {
                        ErrorKind::Angular
                    };
                    let mut indices = Vec::new();
                    for item in items {
                        match item {
                            Item::Name(u) => indices.extend(self.error_use(u, kind, &mut r)),
                            Item::Iso(u) => {
                                if let Some(other) = r.iso_owner.get(&u.name) {
                                    if *other != raw.name {
                                        let problem = Problem::IsoClash {
                                            name: u.name.clone(),
                                            body: raw.name.clone(),
                                            other: other.clone(),
                                        };
                                        self.report(u.span, u.path.clone(), problem);
                                        continue;
                                    }
                                }
                                r.iso_owner.insert(u.name.clone(), raw.name.clone());
                                indices.extend(self.error_use(u, kind, &mut r));
                            }
                            Item::Function(f) => match (&f.basis, variable) {
                                (None, _) => indices.extend(self.thermal_use(f, kind, &mut r)),
                                (Some(basis), Some(v)) => {
                                    indices.extend(self.function_use(f, basis, kind, v, &mut r));
                                }
                                // Without a valid variable the joint was
                                // reported already.
                                (Some(_), None) => {}
                            },
                        }
                    }
                    let Some((loc, err)) = slots.get_mut(old) else {
                        continue;
                    };
                    let target = if g == 0 { loc } else { err };
                    if let Some(list) = target.slots.get_mut(s) {
                        list.extend(indices);
                    }
                }
            }
        }
        (r.errors, r.functions, slots)
    }

    /// Registers one use of an error name; returns its index.
    fn error_use(&mut self, u: &Use, kind: ErrorKind, r: &mut Registry<'_>) -> Option<usize> {
        if r.coefficient_of.contains_key(&u.name) || r.function_by_name.contains_key(&u.name) {
            let other = r.describe(&u.name, &self.parameter_index)?;
            let problem = Problem::FunctionClash {
                what: format!("error parameter `{}`", u.name),
                other,
            };
            self.report(u.span, u.path.clone(), problem);
            return None;
        }
        if let Some(&i) = r.by_name.get(&u.name) {
            let e = r.errors.get_mut(i)?;
            let linear = |k: ErrorKind| k == ErrorKind::Linear;
            if linear(e.kind) != linear(kind) {
                let problem = Problem::ErrorKindConflict {
                    name: u.name.clone(),
                    first: e.kind,
                    second: kind,
                    first_line: e.origin.line,
                };
                self.report(u.span, u.path.clone(), problem);
            } else if kind == ErrorKind::Squareness {
                // An angle used both as a motion error and as squareness is a
                // squareness term.
                e.kind = ErrorKind::Squareness;
            }
            return Some(i);
        }
        if self.parameter_index.contains_key(&u.name) {
            self.report(
                u.span,
                u.path.clone(),
                Problem::NameCollision {
                    name: u.name.clone(),
                    what: "error",
                    other: "parameter",
                },
            );
        } else if r.variable_names.contains(&u.name) {
            self.report(
                u.span,
                u.path.clone(),
                Problem::NameCollision {
                    name: u.name.clone(),
                    what: "error",
                    other: "axis variable",
                },
            );
        }
        Some(r.push(ErrorParam {
            name: u.name.clone(),
            kind,
            origin: u.span.origin(u.path.clone()),
            sensor: None,
        }))
    }

    /// Registers one declaration of a function slot on the joint driven by
    /// variable `variable`, in a slot of `kind`; returns its coefficients'
    /// indices (empty if refused).
    fn function_use(
        &mut self,
        f: &RawFunction,
        basis: &Basis,
        kind: ErrorKind,
        variable: usize,
        r: &mut Registry<'_>,
    ) -> Vec<usize> {
        let name = &f.name.name;
        if let Some(&fi) = r.function_by_name.get(name) {
            let Some(first) = r.functions.get(fi) else {
                return Vec::new();
            };
            let first_kind = first
                .coefficients
                .first()
                .and_then(|(j, _)| r.errors.get(*j))
                .map(|e| e.kind);
            let difference = if first.basis != *basis {
                Some(format!(
                    "with a different basis ({} here, {} first)",
                    describe_basis(basis),
                    describe_basis(&first.basis)
                ))
            } else if first.sensors != f.per {
                Some(format!(
                    "per other sensors ({} here, {} first)",
                    sensor_list(&self.sensors, &f.per),
                    sensor_list(&self.sensors, &first.sensors)
                ))
            } else if first.variable != variable {
                let var = |i: usize| r.variables.get(i).map_or("?", |v| v.name.as_str());
                Some(format!(
                    "on another axis (variable `{}` here, `{}` first)",
                    var(variable),
                    var(first.variable)
                ))
            } else if first_kind
                .is_some_and(|k| (k == ErrorKind::Linear) != (kind == ErrorKind::Linear))
            {
                Some(format!(
                    "in a slot of another kind ({} here, {} first)",
                    slot_kind(kind),
                    slot_kind(first_kind.unwrap_or(kind))
                ))
            } else {
                None
            };
            if self.redeclared(f, difference, &first.origin) {
                return Vec::new();
            }
            return first.coefficients.iter().map(|(j, _)| *j).collect();
        }

        // A new function: its name and every coefficient's must be new. A
        // thermal function has the terms once per sensor of its `per`.
        let sensors: Vec<Option<usize>> = if f.per.is_empty() {
            vec![None]
        } else {
            f.per.iter().copied().map(Some).collect()
        };
        let mut terms = Vec::new();
        let mut names: Vec<String> = Vec::new();
        for &s in &sensors {
            for t in basis.terms() {
                names.push(match s.and_then(|s| self.sensors.get(s)) {
                    Some(sensor) => format!("{name}_{}_{}", t.suffix(), sensor.name),
                    None => format!("{name}_{}", t.suffix()),
                });
                terms.push((t, s));
            }
        }
        if self.clashes(f, "function", &names, r) {
            return Vec::new();
        }
        let origin = f.name.span.origin(f.name.path.clone());
        let coefficients: Vec<(usize, crate::model::BasisFn)> = names
            .into_iter()
            .zip(terms)
            .map(|(c, (t, sensor))| {
                r.coefficient_of.insert(c.clone(), name.clone());
                let j = r.push(ErrorParam {
                    name: c,
                    kind,
                    origin: origin.clone(),
                    sensor,
                });
                (j, t)
            })
            .collect();
        r.function_by_name.insert(name.clone(), r.functions.len());
        let indices = coefficients.iter().map(|(j, _)| *j).collect();
        r.functions.push(ErrorFunction {
            name: name.clone(),
            basis: basis.clone(),
            variable,
            coefficients,
            sensors: f.per.clone(),
            origin,
        });
        indices
    }

    /// Registers one declaration of a thermal term constant along the axis
    /// (`{name, per}`): the constants `<name>_<sensor>`, one per sensor,
    /// each per kelvin of its sensor (`docs/thermal.md`); returns their
    /// indices (empty if refused).
    fn thermal_use(
        &mut self,
        f: &RawFunction,
        kind: ErrorKind,
        r: &mut Registry<'_>,
    ) -> Vec<usize> {
        let name = &f.name.name;
        let names: Vec<String> = (f.per.iter())
            .filter_map(|&s| self.sensors.get(s))
            .map(|s| format!("{name}_{}", s.name))
            .collect();
        if let Some(first) = r.thermal.get(name) {
            let linear = |k: ErrorKind| k == ErrorKind::Linear;
            let difference = if first.sensors != f.per {
                Some(format!(
                    "per other sensors ({} here, {} first)",
                    sensor_list(&self.sensors, &f.per),
                    sensor_list(&self.sensors, &first.sensors)
                ))
            } else if linear(first.kind) != linear(kind) {
                Some(format!(
                    "in a slot of another kind ({} here, {} first)",
                    slot_kind(kind),
                    slot_kind(first.kind)
                ))
            } else {
                None
            };
            if self.redeclared(f, difference, &first.origin) {
                return Vec::new();
            }
            return first.indices.clone();
        }
        if self.clashes(f, "thermal term", &names, r) {
            return Vec::new();
        }
        let origin = f.name.span.origin(f.name.path.clone());
        let indices: Vec<usize> = names
            .into_iter()
            .zip(&f.per)
            .map(|(c, &s)| {
                r.coefficient_of.insert(c.clone(), name.clone());
                r.push(ErrorParam {
                    name: c,
                    kind,
                    origin: origin.clone(),
                    sensor: Some(s),
                })
            })
            .collect();
        r.thermal.insert(
            name.clone(),
            ThermalTerm {
                indices: indices.clone(),
                sensors: f.per.clone(),
                kind,
                origin,
            },
        );
        indices
    }
}

impl Loader {
    /// Reports a redeclaration of `f` that differs from its first (declared
    /// at `first`); true if it does.
    fn redeclared(&mut self, f: &RawFunction, difference: Option<String>, first: &Origin) -> bool {
        let Some(difference) = difference else {
            return false;
        };
        let problem = Problem::FunctionRedeclared {
            name: f.name.name.clone(),
            difference,
            first: place(first),
        };
        self.report(f.name.span, f.name.path.clone(), problem);
        true
    }

    /// Reports every name of a new function or thermal term (`what`) and of
    /// its coefficients `names` that is already something else; true if one
    /// is.
    fn clashes(&mut self, f: &RawFunction, what: &str, names: &[String], r: &Registry<'_>) -> bool {
        let name = &f.name.name;
        let mut clashes = Vec::new();
        if let Some(other) = r.describe(name, &self.parameter_index) {
            clashes.push((format!("{what} `{name}`"), other));
        }
        for c in names {
            if let Some(other) = r.describe(c, &self.parameter_index) {
                clashes.push((format!("coefficient `{c}` of {what} `{name}`"), other));
            }
        }
        for (what, other) in &clashes {
            let problem = Problem::FunctionClash {
                what: what.clone(),
                other: other.clone(),
            };
            self.report(f.name.span, f.name.path.clone(), problem);
        }
        if !clashes.is_empty() {
            self.failed_functions.insert(name.clone());
        }
        !clashes.is_empty()
    }
}

/// The error parameters and function slots found so far, in the walk over
/// the bodies of [`Loader::errors`].
#[derive(Default)]
struct Registry<'v> {
    errors: Vec<ErrorParam>,
    /// Error name → index into `errors`.
    by_name: HashMap<String, usize>,
    functions: Vec<ErrorFunction>,
    /// Function name → index into `functions`.
    function_by_name: HashMap<String, usize>,
    /// Coefficient name → its function's (or thermal term's) name.
    coefficient_of: HashMap<String, String>,
    /// Thermal terms constant along the axis, by name.
    thermal: HashMap<String, ThermalTerm>,
    /// Name given by `errors: iso` → the body whose `iso` gave it.
    iso_owner: HashMap<String, String>,
    /// Every variable name written in a joint.
    variable_names: HashSet<String>,
    /// The valid variables.
    variables: &'v [Variable],
}

/// A thermal term constant along the axis as first declared.
struct ThermalTerm {
    /// Its constants' indices, one per sensor.
    indices: Vec<usize>,
    /// Its sensors.
    sensors: Vec<usize>,
    /// The kind of its first slot.
    kind: ErrorKind,
    /// Where it was first declared.
    origin: Origin,
}

impl Registry<'_> {
    /// Adds an error parameter; returns its index.
    fn push(&mut self, e: ErrorParam) -> usize {
        let i = self.errors.len();
        self.by_name.insert(e.name.clone(), i);
        self.errors.push(e);
        i
    }

    /// What `name` already is, if anything: an error parameter, a
    /// coefficient, a function, a parameter or an axis variable (for the
    /// messages of [`Problem::FunctionClash`]).
    fn describe(&self, name: &str, parameters: &HashMap<String, usize>) -> Option<String> {
        if let Some(function) = self.coefficient_of.get(name) {
            let at = self
                .function_by_name
                .get(function)
                .and_then(|&i| self.functions.get(i))
                .map_or_else(String::new, |f| format!(" (declared {})", place(&f.origin)));
            return Some(format!("a coefficient of function `{function}`{at}"));
        }
        if let Some(t) = self.thermal.get(name) {
            return Some(format!(
                "thermal term `{name}` (declared {})",
                place(&t.origin)
            ));
        }
        if let Some(f) = self
            .function_by_name
            .get(name)
            .and_then(|&i| self.functions.get(i))
        {
            return Some(format!("function `{name}` (declared {})", place(&f.origin)));
        }
        if let Some(e) = self.by_name.get(name).and_then(|&i| self.errors.get(i)) {
            return Some(format!(
                "the error parameter `{name}` (first used {})",
                place(&e.origin)
            ));
        }
        if parameters.contains_key(name) {
            return Some(format!("the parameter `{name}`"));
        }
        if self.variable_names.contains(name) {
            return Some(format!("the axis variable `{name}`"));
        }
        None
    }
}

/// Where an earlier declaration is, for messages: `on line 8` in a file,
/// ``at `bodies.x_slide.errors.dy` `` in the inline `machine!` form (whose
/// tokens have no lines).
fn place(origin: &crate::model::Origin) -> String {
    if origin.line > 0 {
        format!("on line {}", origin.line)
    } else {
        format!("at `{}`", origin.key)
    }
}

/// A basis as it is written, for messages: `powers [1, 2]`, `legendre
/// degree 3 on [0, 1000]`, `fourier with 2 harmonics`.
fn describe_basis(basis: &Basis) -> String {
    match basis {
        Basis::Powers { powers } => {
            let list: Vec<String> = powers.iter().map(u32::to_string).collect();
            format!("powers [{}]", list.join(", "))
        }
        Basis::Legendre {
            degree,
            range,
            from,
        }
        | Basis::Chebyshev {
            degree,
            range,
            from,
        } => {
            let from = if *from == 0 {
                String::new()
            } else {
                format!(" from {from}")
            };
            format!(
                "{} degree {degree}{from} on [{}, {}]",
                basis.name(),
                range[0],
                range[1]
            )
        }
        Basis::Fourier { harmonics } => format!("fourier with {harmonics} harmonics"),
    }
}

/// Sensors by index, for messages: `T_x, T_spindle` (`none`).
fn sensor_list(sensors: &[crate::model::Sensor], per: &[usize]) -> String {
    if per.is_empty() {
        return "none".to_string();
    }
    (per.iter())
        .filter_map(|&s| sensors.get(s).map(|x| x.name.as_str()))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The kind of a slot, for messages.
fn slot_kind(kind: ErrorKind) -> &'static str {
    if kind == ErrorKind::Linear {
        "a linear slot (dx, dy, dz)"
    } else {
        "an angular slot (ex, ey, ez)"
    }
}
