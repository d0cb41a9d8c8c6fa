//! The builder: the machine's rules for names (which names exist, which
//! take a table), the way to give a built machine's values from Rust.

use serde::Serialize;

use super::{Approach, Entry, EntryKind, Given, Motion, Sourced, Table, Tabulated, Units, Values};
use crate::diagnostic::closest;
use crate::model::{ErrorKind, Machine, Origin};

/// Why an error parameter cannot take a table: it is not an error motion of
/// one jointed body.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub enum NotAMotion {
    /// It is (also) a location error, placed before a joint: a constant.
    Location {
        /// The body whose `location_errors` hold it.
        body: String,
    },
    /// It is a squareness term: a constant.
    Squareness,
    /// It is in the `errors` of a body without a joint: no axis to vary along.
    NoJoint {
        /// The body.
        body: String,
    },
    /// It is in the `errors` of several jointed bodies, whose variables differ.
    SeveralBodies {
        /// The bodies.
        bodies: Vec<String>,
    },
    /// It is a coefficient of a function slot: a constant by definition.
    Coefficient {
        /// The function.
        function: String,
    },
    /// It is a thermal term (per kelvin of its sensors): its values are
    /// coefficients, constants by definition (`docs/thermal.md`).
    Thermal {
        /// Its sensors.
        sensors: Vec<String>,
    },
}

impl std::fmt::Display for NotAMotion {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            NotAMotion::Location { body } => write!(
                f,
                "it is a location error of body `{body}` (placed before the joint: a constant)"
            ),
            NotAMotion::Squareness => write!(f, "it is a squareness term (a constant)"),
            NotAMotion::Thermal { sensors } => write!(
                f,
                "it is thermal (per kelvin of {}), and a thermal term's values are constants per kelvin",
                sensors.join(", ")
            ),
            NotAMotion::NoJoint { body } => write!(
                f,
                "it is an error of body `{body}`, which has no joint to vary along"
            ),
            NotAMotion::SeveralBodies { bodies } => write!(
                f,
                "it is an error motion of several bodies ({}), whose axis variables differ",
                bodies.join(", ")
            ),
            NotAMotion::Coefficient { function } => write!(
                f,
                "it is a coefficient of the function slot `{function}` (a constant); a table goes on `{function}` itself"
            ),
        }
    }
}

/// Why a name cannot take what it was given (the rules of spec section 2
/// that concern the machine).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum BindError {
    /// Not an error parameter, coefficient or function of the machine.
    #[error("`{name}` is not an error parameter or function slot of machine `{machine}`")]
    UnknownName {
        /// The name.
        name: String,
        /// The machine.
        machine: String,
        /// The closest name, if one is close.
        suggestion: Option<String>,
    },
    /// A function slot's name given a single number.
    #[error("`{name}` is a function slot; a single number goes on one of its coefficients ({})", coefficients.join(", "))]
    FunctionConstant {
        /// The function.
        name: String,
        /// Its coefficients.
        coefficients: Vec<String>,
    },
    /// A table for an error that is not an error motion.
    #[error("`{name}` cannot take a table: {reason}")]
    NotAMotion {
        /// The error parameter.
        name: String,
        /// Why.
        reason: NotAMotion,
    },
    /// A table for a function slot without a constant basis term.
    #[error("`{name}` cannot take a table: its basis ({basis}) has no constant term, so `{name}` vanishes where all its basis functions do and cannot follow a measured curve")]
    NoConstantTerm {
        /// The function.
        name: String,
        /// Its basis (`powers [1, 2]`, `legendre from 1`, ...).
        basis: String,
    },
    /// A function slot given as a table and one of its coefficients given
    /// too.
    #[error("`{coefficient}` is a coefficient of `{function}`, which is given as a table; give one or the other")]
    CoefficientAndFunction {
        /// The coefficient.
        coefficient: String,
        /// The function.
        function: String,
    },
    /// A standard deviation of the reverse direction without a reverse
    /// direction.
    #[error("`{name}` has a reverse standard deviation but no reverse direction")]
    ReverseStdWithoutReverse {
        /// The name.
        name: String,
    },
    /// A standard deviation of the reverse direction without one of the
    /// main direction.
    #[error("`{name}` has a reverse standard deviation but none for its main direction")]
    ReverseStdWithoutStd {
        /// The name.
        name: String,
    },
    /// A negative standard deviation in a table.
    #[error("the standard deviations of `{name}` ({table}) must be ≥ 0: point {index} is {value}")]
    NegativeStd {
        /// The name.
        name: String,
        /// Where the table came from.
        table: String,
        /// The point (0-based).
        index: usize,
        /// Its value.
        value: f64,
    },
    /// A constant that is infinite or NaN.
    #[error("the value of `{name}` must be finite, got {value}")]
    NotFinite {
        /// The name.
        name: String,
        /// The value.
        value: f64,
    },
}

// ---------------------------------------------------------------------------
// The builder: the machine's rules for names

/// Gives a built machine's error values name by name, with the rules of spec
/// section 2 that concern the machine (which names exist, which take a
/// table). Values are in the machine's units (mm, rad).
#[derive(Debug, Clone)]
pub struct ValuesBuilder<'m> {
    pub(super) machine: &'m Machine,
    pub(super) file: Option<String>,
    pub(super) units: Units,
    constants: Vec<f64>,
    tables: Vec<Tabulated>,
    entries: Vec<Entry>,
    /// Per function slot, whether it was given as a table.
    function_tables: Vec<bool>,
    /// Per error, whether it was given (as a constant or by a table).
    given: Vec<bool>,
}

impl<'m> ValuesBuilder<'m> {
    /// Every error zero so far.
    pub fn new(machine: &'m Machine) -> ValuesBuilder<'m> {
        ValuesBuilder {
            machine,
            file: None,
            units: Units::default(),
            constants: vec![0.0; machine.errors.len()],
            tables: Vec::new(),
            entries: Vec::new(),
            function_tables: vec![false; machine.functions.len()],
            given: vec![false; machine.errors.len()],
        }
    }

    /// A constant error parameter or coefficient (mm or rad). Given again,
    /// the later value holds.
    pub fn constant(&mut self, name: &str, value: f64) -> Result<(), BindError> {
        self.constant_with(name, value, None, Vec::new(), None)
    }

    pub(super) fn constant_with(
        &mut self,
        name: &str,
        value: f64,
        std: Option<f64>,
        carried_by: Vec<String>,
        origin: Option<Origin>,
    ) -> Result<(), BindError> {
        let m = self.machine;
        let Some(j) = m.error_index(name) else {
            return Err(match m.function_index(name) {
                Some(f) => BindError::FunctionConstant {
                    name: name.to_string(),
                    coefficients: m.functions[f]
                        .coefficients
                        .iter()
                        .map(|(j, _)| m.errors[*j].name.clone())
                        .collect(),
                },
                None => self.unknown(name),
            });
        };
        if !value.is_finite() {
            return Err(BindError::NotFinite {
                name: name.to_string(),
                value,
            });
        }
        let kind = match m.coefficient_of(j) {
            Some((f, _)) => {
                let fi = m.function_index(&f.name).unwrap_or(usize::MAX);
                if self.function_tables.get(fi).copied().unwrap_or(false) {
                    return Err(BindError::CoefficientAndFunction {
                        coefficient: name.to_string(),
                        function: f.name.clone(),
                    });
                }
                EntryKind::Coefficient
            }
            None => EntryKind::Error,
        };
        // A constant replaces a table given before for the same error.
        self.tables.retain(|t| t.error != j);
        self.constants[j] = value;
        self.given[j] = true;
        self.record(Entry {
            name: name.to_string(),
            kind,
            given: Given::Constant {
                value,
                std,
                carried_by,
            },
            origin,
        });
        Ok(())
    }

    /// A table along the axis of an error motion (a plain error parameter in
    /// the `errors` of one jointed body) or of a function slot `F` (then the
    /// table is `F(q)`). `source` says where its points came from (for
    /// messages). Values in mm or rad; positions in the axis variable's
    /// units.
    pub fn table(&mut self, name: &str, table: Table, source: &str) -> Result<(), BindError> {
        self.motion_with(name, Motion::single(table, source), None)
    }

    /// A bidirectional error motion (docs/values.md, "Direction"): where
    /// [`ValuesBuilder::table`] takes one table, this takes the two approach
    /// directions and their scatter.
    pub fn motion(&mut self, name: &str, motion: Motion) -> Result<(), BindError> {
        self.motion_with(name, motion, None)
    }

    pub(super) fn motion_with(
        &mut self,
        name: &str,
        motion: Motion,
        origin: Option<Origin>,
    ) -> Result<(), BindError> {
        if motion.std_down.is_some() && motion.down.is_none() {
            return Err(BindError::ReverseStdWithoutReverse {
                name: name.to_string(),
            });
        }
        if motion.std_down.is_some() && motion.std_up.is_none() {
            return Err(BindError::ReverseStdWithoutStd {
                name: name.to_string(),
            });
        }
        for s in motion.std_up.iter().chain(&motion.std_down) {
            if let Some((index, &value)) =
                (s.table.values().iter().enumerate()).find(|(_, v)| **v < 0.0)
            {
                return Err(BindError::NegativeStd {
                    name: name.to_string(),
                    table: s.source.clone(),
                    index,
                    value,
                });
            }
        }
        let (error, variable, kind, function) = self.table_target(name)?;
        if let Some(fi) = function {
            self.function_tables[fi] = true;
        }
        let m = self.machine;
        self.tables.retain(|t| t.error != error);
        self.constants[error] = 0.0;
        self.given[error] = true;
        let table = &motion.up.table;
        let (lo, hi) = table.range();
        let source = |s: &Option<Sourced>| s.as_ref().map(|s| s.source.clone());
        self.record(Entry {
            name: name.to_string(),
            kind,
            given: Given::Table {
                variable: m.variables[variable].name.clone(),
                source: motion.up.source.clone(),
                points: table.positions().len(),
                range: [lo, hi],
                interpolation: table.interpolation(),
                extrapolation: table.extrapolation(),
                reverse: source(&motion.down),
                std: source(&motion.std_up),
                reverse_std: source(&motion.std_down),
            },
            origin,
        });
        self.tables.push(Tabulated {
            name: name.to_string(),
            source: motion.up.source,
            error,
            variable,
            table: motion.up.table,
            reverse: motion.down.map(|s| s.table),
            std: motion.std_up.map(|s| s.table),
            reverse_std: motion.std_down.map(|s| s.table),
            approach: Approach::default(),
            unit: match m.errors[error].kind {
                ErrorKind::Linear => "mm",
                ErrorKind::Angular | ErrorKind::Squareness => "rad",
            },
        });
        Ok(())
    }

    /// The error a table for `name` writes, the axis it reads, what `name`
    /// is and its function slot, if it is one.
    pub(super) fn table_target(
        &self,
        name: &str,
    ) -> Result<(usize, usize, EntryKind, Option<usize>), BindError> {
        let m = self.machine;
        if let Some(fi) = m.function_index(name) {
            let f = &m.functions[fi];
            if !f.sensors.is_empty() {
                return Err(BindError::NotAMotion {
                    name: name.to_string(),
                    reason: NotAMotion::Thermal {
                        sensors: (f.sensors.iter())
                            .filter_map(|&s| m.sensors.get(s).map(|x| x.name.clone()))
                            .collect(),
                    },
                });
            }
            let Some(&(j0, _)) = f.coefficients.iter().find(|(_, b)| b.is_constant()) else {
                return Err(BindError::NoConstantTerm {
                    name: name.to_string(),
                    basis: describe_basis(&f.basis),
                });
            };
            if let Some(&(j, _)) = f.coefficients.iter().find(|(j, _)| self.given[*j]) {
                return Err(BindError::CoefficientAndFunction {
                    coefficient: m.errors[j].name.clone(),
                    function: name.to_string(),
                });
            }
            return Ok((j0, f.variable, EntryKind::Function, Some(fi)));
        }
        let Some(j) = m.error_index(name) else {
            return Err(self.unknown(name));
        };
        match motion_variable(m, j) {
            Ok(v) => Ok((j, v, EntryKind::Error, None)),
            Err(reason) => Err(BindError::NotAMotion {
                name: name.to_string(),
                reason,
            }),
        }
    }

    fn unknown(&self, name: &str) -> BindError {
        let m = self.machine;
        let names = (m.errors.iter().map(|e| e.name.as_str()))
            .chain(m.functions.iter().map(|f| f.name.as_str()));
        BindError::UnknownName {
            name: name.to_string(),
            machine: m.name.clone(),
            suggestion: closest(name, names).map(str::to_string),
        }
    }

    fn record(&mut self, entry: Entry) {
        self.entries.retain(|e| e.name != entry.name);
        self.entries.push(entry);
    }

    /// The values.
    pub fn build(self) -> Values {
        let m = self.machine;
        Values {
            machine: m.name.clone(),
            file: self.file,
            units: self.units,
            variables: m.variables.iter().map(|v| v.name.clone()).collect(),
            errors: m.errors.iter().map(|e| e.name.clone()).collect(),
            constants: self.constants,
            tables: self.tables,
            entries: self.entries,
            approaches: vec![Approach::default(); m.variables.len()],
        }
    }
}

/// `powers [1, 2]`, `legendre from 1`, ...: a basis without a constant term,
/// in words.
fn describe_basis(basis: &crate::model::Basis) -> String {
    use crate::model::Basis;
    match basis {
        Basis::Powers { powers } => format!(
            "powers [{}]",
            powers
                .iter()
                .map(u32::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
        Basis::Legendre { from, .. } | Basis::Chebyshev { from, .. } => {
            format!("{} from {from}", basis.name())
        }
        Basis::Fourier { .. } => "fourier".to_string(),
    }
}

/// The variable along which plain error `j` is an error motion: it must be
/// in the `errors` slots of exactly one body, which has a joint, and nowhere
/// else.
pub fn motion_variable(machine: &Machine, j: usize) -> Result<usize, NotAMotion> {
    if let Some(s) = machine.errors[j].sensor {
        return Err(NotAMotion::Thermal {
            sensors: machine
                .sensors
                .get(s)
                .map(|x| x.name.clone())
                .into_iter()
                .collect(),
        });
    }
    if let Some((f, _)) = machine.coefficient_of(j) {
        return Err(NotAMotion::Coefficient {
            function: f.name.clone(),
        });
    }
    if machine.errors[j].kind == ErrorKind::Squareness {
        return Err(NotAMotion::Squareness);
    }
    let holds = |slots: &crate::model::ErrorSlots| slots.slots.iter().any(|s| s.contains(&j));
    if let Some(b) = machine.bodies.iter().find(|b| holds(&b.location_errors)) {
        return Err(NotAMotion::Location {
            body: b.name.clone(),
        });
    }
    let bodies: Vec<&crate::model::Body> =
        machine.bodies.iter().filter(|b| holds(&b.errors)).collect();
    match bodies.as_slice() {
        [b] => match &b.joint {
            Some(joint) => Ok(joint.variable),
            None => Err(NotAMotion::NoJoint {
                body: b.name.clone(),
            }),
        },
        [] => Err(NotAMotion::Squareness),
        several => Err(NotAMotion::SeveralBodies {
            bodies: several.iter().map(|b| b.name.clone()).collect(),
        }),
    }
}
