//! Values files: the errors of one built machine, measured or identified
//! (measured-machines spec, section 2; `docs/values.md`).
//!
//! ```yaml
//! machine: vmc3                       # must equal the machine file's `machine`
//! units: {linear: um, angular: urad}  # optional; linear: mm | um; angular: rad | urad | arcsec | deg
//! values:
//!   EC0Y: 12.0                        # a constant error parameter or coefficient
//!   EYX_1: {value: 1.5e-3, std: 2e-4} # the same with its standard deviation
//!   EXX: {points: [[0, 0.0], [400, 3.1], [800, 5.2]]}            # a measured error motion
//!   EBX: {table: x_axis.csv, column: EBX}                        # from a CSV (paths relative
//!   ECX: {table: x_axis.csv, column: ECX, interpolation: cubic}  #   to this file)
//!   EAX: {table: x_axis.csv, column: EAX, extrapolate: hold}
//! correlation: ...                    # written by `chain identify`; ignored here
//! ```
//!
//! Every value is in the file's `units` (linear values and the
//! coefficients of linear error motions in `linear`, angular ones and
//! squareness in `angular`); table positions `q` are in the machine's own
//! units (mm for a prismatic axis, rad for a rotary one). [`Values`] converts
//! everything to the machine's mm and rad.
//!
//! Reading is one pass over the located YAML tree of [`crate::yaml`] with
//! the readers the machine and settings loaders share, so every refusal is
//! located (file, line, column, key) and reported together with the others
//! (codes `chain::values::*`); a CSV table's problems are located in the CSV
//! file (line, column, header name). The names are checked against the
//! machine by [`ValuesBuilder`], which is also the way to give a built
//! machine's values from Rust.
//!
//! [`Values`] implements [`crate::ErrorValues`]: `v(q)` for every error
//! parameter of the machine, constants filled once, each table evaluated at
//! its axis value without allocating.
//!
//! By subject: this file holds the values themselves ([`Values`], their
//! units and errors); `entry.rs` what an entry gives (constants, tables,
//! approach directions); `bind.rs` the machine's rules for names
//! ([`ValuesBuilder`]); `yaml.rs` the reader of a values file; `table.rs`
//! the interpolated tables and `csv.rs` the CSV reader of every input.

mod bind;
#[cfg(feature = "csv")]
pub mod csv;
mod entry;
mod table;
mod yaml;

use serde::Serialize;

pub use bind::{motion_variable, BindError, NotAMotion, ValuesBuilder};
pub use entry::{
    parse_approaches, Approach, Entry, EntryKind, Given, Motion, Reversal, Sourced, APPROACHES,
};
pub use table::{Extrapolation, Interpolation, Table, TableError};
pub use yaml::{
    ANGULAR_UNITS, ENTRY_KEYS, EXTRAPOLATIONS, INTERPOLATIONS, LINEAR_UNITS, TOP_KEYS, UNITS_KEYS,
};

use crate::diagnostic::{closest, Diagnostics};
use crate::model::{ErrorKind, Machine};
use crate::model_trait::{ErrorValues, OutOfRange};

/// Values files larger than this are refused.
pub const MAX_VALUES_BYTES: usize = crate::bounded::VALUES_BYTES;

// ---------------------------------------------------------------------------
// Units

/// The unit of linear values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum LinearUnit {
    /// Millimetres (the machine's unit).
    #[default]
    Mm,
    /// Micrometres.
    Um,
}

/// The unit of angular values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum AngularUnit {
    /// Radians (the machine's unit).
    #[default]
    Rad,
    /// Microradians.
    Urad,
    /// Seconds of arc.
    Arcsec,
    /// Degrees.
    Deg,
}

/// The units of a values file's values (`units: {linear, angular}`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
pub struct Units {
    /// Unit of linear errors and of the coefficients of linear error motions.
    pub linear: LinearUnit,
    /// Unit of angular and squareness errors and of the coefficients of
    /// angular error motions.
    pub angular: AngularUnit,
}

impl Units {
    /// The factor from this unit to the machine's (mm, rad) for a value of
    /// an error of `kind`.
    pub fn factor(&self, kind: ErrorKind) -> f64 {
        match kind {
            ErrorKind::Linear => match self.linear {
                LinearUnit::Mm => 1.0,
                LinearUnit::Um => 1e-3,
            },
            ErrorKind::Angular | ErrorKind::Squareness => match self.angular {
                AngularUnit::Rad => 1.0,
                AngularUnit::Urad => 1e-6,
                AngularUnit::Arcsec => std::f64::consts::PI / (180.0 * 3600.0),
                AngularUnit::Deg => std::f64::consts::PI / 180.0,
            },
        }
    }
}

/// One table of a [`Values`]: which value it writes and which axis it reads.
#[derive(Debug, Clone, PartialEq)]
struct Tabulated {
    /// The name of the entry (an error motion or a function slot).
    name: String,
    /// Where its points came from.
    source: String,
    /// The value it writes (an error parameter, or a function's constant
    /// coefficient), in [`Values::errors`] order.
    error: usize,
    /// The axis it reads, in [`Values::variables`] order.
    variable: usize,
    /// `v↑`, or the only table.
    table: Table,
    /// `v↓`.
    reverse: Option<Table>,
    /// `s↑` (or `s` for both directions).
    std: Option<Table>,
    /// `s↓`.
    reverse_std: Option<Table>,
    /// The direction read (its axis's).
    approach: Approach,
    /// `mm` or `rad`: the unit of the value it writes.
    unit: &'static str,
}

impl Tabulated {
    /// `v(q)` for the chosen approach: `None` outside a table in use.
    #[inline]
    fn eval(&self, x: f64) -> Option<f64> {
        match (&self.reverse, self.approach) {
            (None, _) | (Some(_), Approach::Up) => self.table.eval(x),
            (Some(r), Approach::Down) => r.eval(x),
            (Some(r), Approach::Mean) => Some(0.5 * (self.table.eval(x)? + r.eval(x)?)),
        }
    }

    /// `s(q)` for the chosen approach (0 without a scatter): `s↑` or `s↓`,
    /// and for `mean` the root mean square `√((s↑² + s↓²)/2)`, the scatter of
    /// a position approached from either side with equal probability once
    /// the reversal is left out (docs/values.md).
    fn std_eval(&self, x: f64) -> Option<f64> {
        let Some(up) = &self.std else {
            return Some(0.0);
        };
        match (&self.reverse_std, self.approach) {
            (None, _) | (Some(_), Approach::Up) => up.eval(x),
            (Some(d), Approach::Down) => d.eval(x),
            (Some(d), Approach::Mean) => {
                let (a, b) = (up.eval(x)?, d.eval(x)?);
                Some((0.5 * (a * a + b * b)).sqrt())
            }
        }
    }

    /// The range in which the tables read for the chosen approach are
    /// read (their common range): the values' tables, or (`std`) the
    /// standard deviations'.
    fn range(&self, std: bool) -> (f64, f64) {
        let (main, reverse) = if std {
            (self.std.as_ref(), self.reverse_std.as_ref())
        } else {
            (Some(&self.table), self.reverse.as_ref())
        };
        let read: Vec<&Table> = match (main, reverse, self.approach) {
            (Some(m), None, _) | (Some(m), Some(_), Approach::Up) => vec![m],
            (_, Some(r), Approach::Down) => vec![r],
            (Some(m), Some(r), Approach::Mean) => vec![m, r],
            (None, _, _) => vec![&self.table],
        };
        read.iter()
            .map(|t| t.range())
            .fold((f64::NEG_INFINITY, f64::INFINITY), |(lo, hi), (a, b)| {
                (lo.max(a), hi.min(b))
            })
    }

    /// The reversal `max |v↑ − v↓|` over both tables' positions in their
    /// common range, if the motion has two directions.
    fn reversal(&self, variable: &str) -> Option<Reversal> {
        let r = self.reverse.as_ref()?;
        let (lo, hi) = {
            let (a, b) = self.table.range();
            let (c, d) = r.range();
            (a.max(c), b.min(d))
        };
        let mut best = (0.0_f64, lo);
        for &q in self.table.positions().iter().chain(r.positions()) {
            if !(lo..=hi).contains(&q) {
                continue;
            }
            if let (Some(u), Some(d)) = (self.table.eval(q), r.eval(q)) {
                if (u - d).abs() > best.0 {
                    best = ((u - d).abs(), q);
                }
            }
        }
        Some(Reversal {
            name: self.name.clone(),
            variable: variable.to_string(),
            approach: self.approach,
            largest: best.0,
            at: best.1,
            left_out: match self.approach {
                Approach::Mean => 0.5 * best.0,
                Approach::Up | Approach::Down => best.0,
            },
            unit: self.unit,
        })
    }
}

// ---------------------------------------------------------------------------
// Values

/// The error values of one built machine: `v(q)`, one value per error
/// parameter, constants and tables along the axes (spec section 2).
///
/// Built by [`Values::read`] / [`Values::parse`] from a values file, or by
/// [`ValuesBuilder`] from Rust. As an [`ErrorValues`] it writes the values
/// in [`Values::errors`] order from axis values in [`Values::variables`]
/// order (the machine's; [`Values::reordered`] adapts it to a model with
/// another order).
///
/// A table for a function slot `F` sets `F(q)`: it writes `F(q)` on `F`'s
/// constant coefficient (the one whose basis function is 1) and leaves the
/// others zero, so `Σ_k b_k(q) e_k = F(q)` exactly.
///
/// # Example
///
/// ```
/// use chain_core::values::{Extrapolation, Interpolation, Table, ValuesBuilder};
/// use chain_core::ErrorValues;
/// let yaml = "machine: m\nbodies:\n  bed: {}\n  x_slide: {parent: bed, joint: {type: prismatic, axis: +x, variable: x}, errors: {dx: dxx}, squareness: {ez: Sxy}}\nworkpiece: bed\ntool: x_slide\n";
/// let machine = chain_core::load_str(yaml, "m.yaml").unwrap();
/// let mut b = ValuesBuilder::new(&machine);
/// b.constant("Sxy", 2e-5).unwrap();
/// let t = Table::new(vec![(0.0, 0.0), (1000.0, 0.005)], Interpolation::Linear, Extrapolation::Error).unwrap();
/// b.table("dxx", t, "points").unwrap();
/// let values = b.build();
/// let mut e = [0.0; 2];
/// values.values_at(&[400.0], &mut e).unwrap();
/// assert_eq!(e, [0.002, 2e-5]);
/// assert!(values.values_at(&[1200.0], &mut e).is_err()); // outside the table
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Values {
    machine: String,
    file: Option<String>,
    units: Units,
    variables: Vec<String>,
    errors: Vec<String>,
    constants: Vec<f64>,
    tables: Vec<Tabulated>,
    entries: Vec<Entry>,
    /// Per variable, the approach direction read.
    approaches: Vec<Approach>,
}

/// A choice of approach direction that names what these values do not have
/// (`chain map --approach`).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ApproachError {
    /// Not an axis variable of the machine.
    #[error("`{name}` is not an axis variable of machine `{machine}`{} (its variables: {})", suggestion.as_ref().map(|s| format!(" (did you mean `{s}`?)")).unwrap_or_default(), variables.join(", "))]
    UnknownVariable {
        /// The name given.
        name: String,
        /// The machine.
        machine: String,
        /// Its variables.
        variables: Vec<String>,
        /// The closest variable, if one is close.
        suggestion: Option<String>,
    },
    /// An axis without a table that has a reverse direction.
    #[error("no table along `{variable}` has a reverse direction, so there is no approach to choose for it")]
    NotDirectional {
        /// The variable.
        variable: String,
    },
    /// No table at all has a reverse direction.
    #[error("no table of these values has a reverse direction (`reverse` or `reverse_points`), so there is no approach to choose")]
    NoDirection,
}

/// A model's variable or error names are not the machine's (by name).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("the model's {what} ({}) are not the machine's ({})", model.join(", "), machine.join(", "))]
pub struct OrderError {
    /// `variables` or `errors`.
    pub what: &'static str,
    /// The model's names.
    pub model: Vec<String>,
    /// The machine's names.
    pub machine: Vec<String>,
}

impl Values {
    /// Every error of `machine` zero (a perfect machine).
    pub fn zero(machine: &Machine) -> Values {
        ValuesBuilder::new(machine).build()
    }

    /// The machine these values are for.
    pub fn machine(&self) -> &str {
        &self.machine
    }

    /// The values file they were read from, if any.
    pub fn file(&self) -> Option<&str> {
        self.file.as_deref()
    }

    /// The file's units (the values are converted from them).
    pub fn units(&self) -> Units {
        self.units
    }

    /// The axis variables, in the order [`ErrorValues::values_at`] reads them.
    pub fn variables(&self) -> &[String] {
        &self.variables
    }

    /// The error parameters, in the order [`ErrorValues::values_at`] writes them.
    pub fn errors(&self) -> &[String] {
        &self.errors
    }

    /// What was given, one entry per name, in the order given.
    pub fn entries(&self) -> &[Entry] {
        &self.entries
    }

    /// The constant part of `v(q)`: every constant, zero where a table writes.
    pub fn constants(&self) -> &[f64] {
        &self.constants
    }

    /// The number of tables.
    pub fn table_count(&self) -> usize {
        self.tables.len()
    }

    /// The same values for a model whose variables and errors are these
    /// names (the machine's, in another order).
    pub fn reordered(&self, variables: &[&str], errors: &[&str]) -> Result<Values, OrderError> {
        let permutation = |what: &'static str, ours: &[String], theirs: &[&str]| {
            let mismatch = || OrderError {
                what,
                model: theirs.iter().map(|s| s.to_string()).collect(),
                machine: ours.to_vec(),
            };
            if ours.len() != theirs.len() {
                return Err(mismatch());
            }
            ours.iter()
                .map(|n| theirs.iter().position(|t| t == n).ok_or_else(mismatch))
                .collect::<Result<Vec<usize>, OrderError>>()
        };
        let var = permutation("variables", &self.variables, variables)?;
        let err = permutation("errors", &self.errors, errors)?;
        let mut out = self.clone();
        out.variables = variables.iter().map(|s| s.to_string()).collect();
        out.errors = errors.iter().map(|s| s.to_string()).collect();
        for (j, &c) in self.constants.iter().enumerate() {
            out.constants[err[j]] = c;
        }
        for (v, &a) in self.approaches.iter().enumerate() {
            out.approaches[var[v]] = a;
        }
        for t in &mut out.tables {
            t.error = err[t.error];
            t.variable = var[t.variable];
        }
        Ok(out)
    }
}

impl Values {
    /// These values at a thermal state: each constant multiplied by its
    /// error's thermal factor ([`Machine::thermal_factors`], in
    /// [`Values::errors`] order): a thermal coefficient's per-kelvin value
    /// becomes its contribution `g_j(T) · e_j` at the state, every other
    /// value (factor 1) is unchanged (`docs/thermal.md`). Tables never hold
    /// a thermal coefficient (refused when bound), so only constants scale.
    pub fn at_thermal_state(mut self, factors: &[f64]) -> Values {
        for (c, f) in self.constants.iter_mut().zip(factors) {
            if *f != 1.0 {
                *c *= f;
            }
        }
        self
    }
}

impl ErrorValues for Values {
    /// `v(q)`: the constants, then every table at its axis value. `q` is in
    /// [`Values::variables`] order, `out` in [`Values::errors`] order (a
    /// shorter `out` receives the first values; a missing axis value is NaN,
    /// outside every table).
    #[inline]
    fn values_at(&self, q: &[f64], out: &mut [f64]) -> Result<(), OutOfRange> {
        for (o, c) in out.iter_mut().zip(&self.constants) {
            *o = *c;
        }
        self.write(self.tables.iter(), q, out, Tabulated::eval, false)
    }
}

impl Values {
    /// `v(q)` into `out`, which holds `v(previous)` of these values: only the
    /// tables whose axis value differs from `previous` are evaluated (the
    /// constants are already there). Consecutive points of a grid differ in
    /// few axes, so [`crate::BuiltMachine::map`] evaluates them this way; the
    /// result is the same as [`ErrorValues::values_at`]'s, bit for bit.
    #[inline]
    pub fn update(&self, previous: &[f64], q: &[f64], out: &mut [f64]) -> Result<(), OutOfRange> {
        // NaN is never equal: it is evaluated, and refused.
        let moved = (self.tables.iter()).filter(|t| {
            previous.get(t.variable) != Some(&q.get(t.variable).copied().unwrap_or(f64::NAN))
        });
        self.write(moved, q, out, Tabulated::eval, false)
    }

    /// The approach direction read along each variable, in
    /// [`Values::variables`] order (all [`Approach::Mean`] unless chosen).
    pub fn approaches(&self) -> &[Approach] {
        &self.approaches
    }

    /// Reads every bidirectional table along `variable` (an index into
    /// [`Values::variables`]) for `approach`.
    pub fn set_approach(&mut self, variable: usize, approach: Approach) {
        if let Some(a) = self.approaches.get_mut(variable) {
            *a = approach;
        }
        for t in self.tables.iter_mut().filter(|t| t.variable == variable) {
            t.approach = approach;
        }
    }

    /// Applies a choice of approach: `(None, a)` for every variable with a
    /// bidirectional table, `(Some(x), a)` for variable `x` (later choices
    /// win). Naming a variable without a bidirectional table, or choosing
    /// when no table has two directions, is an error: the choice would
    /// change nothing.
    pub fn choose_approach(
        &mut self,
        choices: &[(Option<String>, Approach)],
    ) -> Result<(), ApproachError> {
        let directional = |v: usize| {
            self.tables
                .iter()
                .any(|t| t.variable == v && t.reverse.is_some())
        };
        let mut set = Vec::new();
        for (name, approach) in choices {
            match name {
                None => {
                    let all: Vec<usize> = (0..self.variables.len())
                        .filter(|&v| directional(v))
                        .collect();
                    if all.is_empty() {
                        return Err(ApproachError::NoDirection);
                    }
                    set.extend(all.into_iter().map(|v| (v, *approach)));
                }
                Some(name) => {
                    let Some(v) = self.variables.iter().position(|x| x == name) else {
                        return Err(ApproachError::UnknownVariable {
                            name: name.clone(),
                            machine: self.machine.clone(),
                            variables: self.variables.clone(),
                            suggestion: closest(name, self.variables.iter().map(String::as_str))
                                .map(str::to_string),
                        });
                    };
                    if !directional(v) {
                        return Err(ApproachError::NotDirectional {
                            variable: name.clone(),
                        });
                    }
                    set.push((v, *approach));
                }
            }
        }
        for (v, a) in set {
            self.set_approach(v, a);
        }
        Ok(())
    }

    /// Per bidirectional table, the reversal the chosen approach leaves out.
    pub fn reversals(&self) -> Vec<Reversal> {
        (self.tables.iter())
            .filter_map(|t| t.reversal(&self.variables[t.variable]))
            .collect()
    }

    /// The positions of the tables of entry `name` (both approach
    /// directions), increasing, each once; `None` if `name` is not given as
    /// a table.
    pub fn table_positions(&self, name: &str) -> Option<Vec<f64>> {
        let t = self.tables.iter().find(|t| t.name == name)?;
        let mut q: Vec<f64> = t.table.positions().to_vec();
        q.extend(t.reverse.iter().flat_map(|r| r.positions().iter().copied()));
        q.sort_by(f64::total_cmp);
        q.dedup();
        Some(q)
    }

    /// The errors written by tables (in [`Values::errors`] order), each with
    /// whether its table gives a standard deviation per position.
    pub fn tabulated(&self) -> Vec<(usize, bool)> {
        (self.tables.iter())
            .map(|t| (t.error, t.std.is_some()))
            .collect()
    }

    /// True if some table gives a standard deviation per position.
    pub fn has_repeatability(&self) -> bool {
        self.tables.iter().any(|t| t.std.is_some())
    }

    /// The standard deviation of each error at `q` for the chosen approach:
    /// 0 for constants and tables without one (docs/values.md,
    /// "Direction"). Orders as [`ErrorValues::values_at`].
    pub fn repeatability_at(&self, q: &[f64], out: &mut [f64]) -> Result<(), OutOfRange> {
        out.iter_mut().for_each(|o| *o = 0.0);
        let scattered = self.tables.iter().filter(|t| t.std.is_some());
        self.write(scattered, q, out, Tabulated::std_eval, true)
    }

    /// Writes `eval` of each of `tables` at its axis value into its error's
    /// place in `out`; the first table `q` is outside of is the error.
    #[inline]
    fn write<'t>(
        &self,
        tables: impl Iterator<Item = &'t Tabulated>,
        q: &[f64],
        out: &mut [f64],
        eval: impl Fn(&Tabulated, f64) -> Option<f64>,
        std: bool,
    ) -> Result<(), OutOfRange> {
        for t in tables {
            let x = q.get(t.variable).copied().unwrap_or(f64::NAN);
            match eval(t, x) {
                Some(v) => {
                    if let Some(o) = out.get_mut(t.error) {
                        *o = v;
                    }
                }
                None => return Err(self.out_of_range(t, x, std)),
            }
        }
        Ok(())
    }

    #[cold]
    fn out_of_range(&self, t: &Tabulated, value: f64, std: bool) -> OutOfRange {
        let (lo, hi) = t.range(std);
        OutOfRange {
            name: t.name.clone(),
            table: t.source.clone(),
            variable: self.variables[t.variable].clone(),
            value,
            lo,
            hi,
        }
    }
}

// ---------------------------------------------------------------------------
// Errors of a values file

/// Why a values file could not be read: problems located in the values file
/// itself, or in a CSV table it names. As a [`miette::Diagnostic`] (feature
/// `miette`) either renders like a machine file's errors.
#[derive(Debug, thiserror::Error)]
#[cfg_attr(feature = "miette", derive(miette::Diagnostic))]
pub enum ValuesError {
    /// Every problem of the values file (file, line, column, key).
    #[error(transparent)]
    #[cfg_attr(feature = "miette", diagnostic(transparent))]
    File(Diagnostics),
    /// The problems of a CSV table (file, line, column, header name).
    #[error(transparent)]
    #[cfg_attr(feature = "miette", diagnostic(transparent))]
    Table(Diagnostics),
}

impl From<Diagnostics> for ValuesError {
    fn from(d: Diagnostics) -> ValuesError {
        ValuesError::File(d)
    }
}

impl ValuesError {
    /// The located problems.
    pub fn diagnostics(&self) -> &Diagnostics {
        match self {
            ValuesError::File(d) | ValuesError::Table(d) => d,
        }
    }
}
