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

mod table;

#[cfg(feature = "csv")]
pub mod csv;

use std::path::{Path, PathBuf};

use serde::Serialize;

pub use table::{Extrapolation, Interpolation, Table, TableError};

use crate::diagnostic::{closest, Diagnostics, Message, Problem};
use crate::load::reader::{index, join, start_origin, Fields, TreeReader};
use crate::model::{ErrorKind, Machine, Origin};
use crate::model_trait::{ErrorValues, OutOfRange};
use crate::yaml::{self, Node};

/// Keys allowed at the top level of a values file (`correlation`, written by
/// `chain identify`, is accepted and ignored).
pub const TOP_KEYS: &[&str] = &["machine", "description", "units", "values", "correlation"];
/// Keys of `units`.
pub const UNITS_KEYS: &[&str] = &["linear", "angular"];
/// Keys of one entry of `values` given as a mapping.
pub const ENTRY_KEYS: &[&str] = &[
    "value",
    "std",
    "points",
    "table",
    "column",
    "interpolation",
    "extrapolate",
    "reverse",
    "reverse_std",
    "reverse_points",
    "std_points",
    "reverse_std_points",
];
/// Values of `chain map --approach` and [`Approach`].
pub const APPROACHES: &[&str] = &["up", "down", "mean"];
/// Linear units.
pub const LINEAR_UNITS: &[&str] = &["mm", "um"];
/// Angular units.
pub const ANGULAR_UNITS: &[&str] = &["rad", "urad", "arcsec", "deg"];
/// Values of `interpolation`.
pub const INTERPOLATIONS: &[&str] = &["linear", "cubic"];
/// Values of `extrapolate`.
pub const EXTRAPOLATIONS: &[&str] = &["error", "hold"];

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

// ---------------------------------------------------------------------------
// What a name of the machine is, and what it takes

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
}

impl std::fmt::Display for NotAMotion {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            NotAMotion::Location { body } => write!(
                f,
                "it is a location error of body `{body}` (placed before the joint: a constant)"
            ),
            NotAMotion::Squareness => write!(f, "it is a squareness term (a constant)"),
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

/// What kind of name of the machine an entry is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum EntryKind {
    /// A constant error parameter (or an error motion given as a constant).
    Error,
    /// A coefficient `<F>_<suffix>` of a function slot.
    Coefficient,
    /// A function slot `F` (given as a table of `F(q)`).
    Function,
}

/// What an entry gives.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "given", rename_all = "lowercase")]
pub enum Given {
    /// A constant, in the machine's units.
    Constant {
        /// The value.
        value: f64,
        /// Its standard deviation, if the file gives one (`chain identify`
        /// writes it; nothing here uses it).
        #[serde(skip_serializing_if = "Option::is_none")]
        std: Option<f64>,
    },
    /// A table along an axis.
    Table {
        /// The axis variable.
        variable: String,
        /// Where the points came from: `points` or `FILE.csv, column NAME`.
        source: String,
        /// The number of points.
        points: usize,
        /// The first and last position.
        range: [f64; 2],
        /// How it is read between points.
        interpolation: Interpolation,
        /// What it gives outside its range.
        extrapolation: Extrapolation,
        /// Where the other approach direction's points came from
        /// (`reverse_points` or `FILE.csv, column NAME`), if given.
        #[serde(skip_serializing_if = "Option::is_none")]
        reverse: Option<String>,
        /// Where the per-position standard deviations came from, if given.
        #[serde(skip_serializing_if = "Option::is_none")]
        std: Option<String>,
        /// Where the other direction's standard deviations came from.
        #[serde(skip_serializing_if = "Option::is_none")]
        reverse_std: Option<String>,
    },
}

/// Which approach direction of a bidirectional error motion is read
/// (docs/values.md, "Direction"). A table without a reverse direction reads
/// the same for all three.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Approach {
    /// The position approached moving in the positive direction (ISO 230-2
    /// ↑): the table's main values.
    Up,
    /// Approached moving in the negative direction (↓): its `reverse` values.
    Down,
    /// The mean of the two, `(up + down)/2` (ISO 230-2:2014 2.13, the mean
    /// bidirectional positional deviation `x̄_i`): the default.
    #[default]
    Mean,
}

impl Approach {
    /// `up`, `down` or `mean`.
    pub fn name(self) -> &'static str {
        match self {
            Approach::Up => "up",
            Approach::Down => "down",
            Approach::Mean => "mean",
        }
    }
}

impl std::fmt::Display for Approach {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Approach {
    type Err = String;
    fn from_str(text: &str) -> Result<Approach, String> {
        match text {
            "up" | "+" => Ok(Approach::Up),
            "down" | "-" => Ok(Approach::Down),
            "mean" => Ok(Approach::Mean),
            _ => Err(format!(
                "`{text}` is not an approach direction: expected up, down or mean"
            )),
        }
    }
}

/// A table with where its points came from (for messages and reports).
#[derive(Debug, Clone, PartialEq)]
pub struct Sourced {
    /// The table.
    pub table: Table,
    /// `points`, or `FILE.csv, column NAME`.
    pub source: String,
}

/// A measured error motion with what a bidirectional positioning run gives
/// (docs/values.md, "Direction"): the deviation approached moving up, the
/// one approached moving down, and each one's standard deviation per
/// position (the run-to-run scatter, ISO 230-2:2014 2.17). Only `up` is
/// required; without `down` the motion is the same from either side.
#[derive(Debug, Clone, PartialEq)]
pub struct Motion {
    /// `v↑(q)`, or the only table.
    pub up: Sourced,
    /// `v↓(q)`.
    pub down: Option<Sourced>,
    /// `s↑(q)` (every value ≥ 0); without `std_down` it holds for both
    /// directions.
    pub std_up: Option<Sourced>,
    /// `s↓(q)` (needs `down`).
    pub std_down: Option<Sourced>,
}

impl Motion {
    /// One table, the same from either side, without a scatter.
    pub fn single(table: Table, source: &str) -> Motion {
        Motion {
            up: Sourced {
                table,
                source: source.to_string(),
            },
            down: None,
            std_up: None,
            std_down: None,
        }
    }
}

/// The largest difference between the two approach directions of one
/// bidirectional error motion: what a choice of [`Approach`] leaves out.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Reversal {
    /// The entry (error motion or function slot).
    pub name: String,
    /// Its axis variable.
    pub variable: String,
    /// The approach read.
    pub approach: Approach,
    /// `max |v↑(q) − v↓(q)|` over the positions of both tables inside
    /// their common range, in the machine's units (mm or rad).
    pub largest: f64,
    /// The position where it is largest.
    pub at: f64,
    /// What the choice leaves out at worst: the whole reversal for `up` or
    /// `down`, half of it for `mean`.
    pub left_out: f64,
    /// The unit of `largest` and `left_out`: `mm` or `rad`.
    pub unit: &'static str,
}

/// Parses a choice of approach directions: `DIR` for every axis, or
/// `VAR=DIR`, comma-separated (`x=up,y=down`); `DIR` is `up`, `down` or
/// `mean` (`chain map --approach`).
pub fn parse_approaches(text: &str) -> Result<Vec<(Option<String>, Approach)>, String> {
    text.split(',')
        .map(|item| {
            let item = item.trim();
            match item.split_once('=') {
                Some((var, dir)) if !var.trim().is_empty() => {
                    Ok((Some(var.trim().to_string()), dir.trim().parse()?))
                }
                Some(_) => Err(format!("`{item}` has no variable before `=`")),
                None => Ok((None, item.parse()?)),
            }
        })
        .collect()
}

/// One name of the machine and what the values gave it (for reports).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Entry {
    /// The name as written.
    pub name: String,
    /// What it is in the machine.
    pub kind: EntryKind,
    /// What it was given.
    #[serde(flatten)]
    pub given: Given,
    /// Where it was given (`None` when given from Rust).
    #[serde(skip)]
    pub origin: Option<Origin>,
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

    /// Reads a values file for `machine`. Tables are relative to the file's
    /// directory.
    pub fn read(path: &Path, machine: &Machine) -> Result<Values, ValuesError> {
        let file = path.display().to_string();
        let bytes = crate::load::read_file(path, &file, MAX_VALUES_BYTES)?;
        let text = crate::load::decode(&bytes, &file)?;
        let base = path
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_else(|| PathBuf::from("."));
        Values::parse(text, &file, &base, machine)
    }

    /// Reads values-file text named `file`; `base` is the directory tables
    /// are relative to.
    pub fn parse(
        text: &str,
        file: &str,
        base: &Path,
        machine: &Machine,
    ) -> Result<Values, ValuesError> {
        crate::load::decode(text.as_bytes(), file)?;
        let parsed = yaml::parse(text);
        let mut r = Reader {
            problems: (parsed.errors.into_iter())
                .map(|(span, key, problem)| (span.origin(key), problem))
                .collect(),
            tables: Vec::new(),
            base: base.to_path_buf(),
            file: file.to_string(),
            #[cfg(feature = "csv")]
            csv_files: Vec::new(),
        };
        let mut builder = ValuesBuilder::new(machine);
        builder.file = Some(file.to_string());
        match &parsed.root {
            Some(root) if r.problems.is_empty() => r.values(root, &mut builder),
            Some(_) => {}
            None => {
                if r.problems.is_empty() {
                    let empty =
                        Message::new("the values file is empty", "empty", "chain::values::empty")
                            .help("expected a mapping with `machine` and `values`");
                    r.problems.push((start_origin(""), empty.into()));
                }
            }
        }
        if let Some(e) = Diagnostics::located(file, text, r.problems) {
            return Err(ValuesError::File(e));
        }
        if let Some(e) = r.tables.into_iter().next() {
            return Err(ValuesError::Table(e));
        }
        Ok(builder.build())
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
// The builder: the machine's rules for names

/// Gives a built machine's error values name by name, with the rules of spec
/// section 2 that concern the machine (which names exist, which take a
/// table). Values are in the machine's units (mm, rad).
#[derive(Debug, Clone)]
pub struct ValuesBuilder<'m> {
    machine: &'m Machine,
    file: Option<String>,
    units: Units,
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
        self.constant_with(name, value, None, None)
    }

    fn constant_with(
        &mut self,
        name: &str,
        value: f64,
        std: Option<f64>,
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
            given: Given::Constant { value, std },
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

    fn motion_with(
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
    fn table_target(
        &self,
        name: &str,
    ) -> Result<(usize, usize, EntryKind, Option<usize>), BindError> {
        let m = self.machine;
        if let Some(fi) = m.function_index(name) {
            let f = &m.functions[fi];
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

/// A located [`BindError`]: the message of a values file.
fn bind_problem(e: &BindError) -> Problem {
    let text = e.to_string();
    let message = match e {
        BindError::UnknownName { suggestion, .. } => {
            Message::new(text, "unknown name", "chain::values::unknown_name")
                .suggest(suggestion.as_deref())
                .help("values names the machine's error parameters, coefficients (`<F>_<k>`) and function slots (`F`)")
        }
        BindError::FunctionConstant { name, coefficients } => Message::new(
            text,
            "function slot",
            "chain::values::function_constant",
        )
        .help(format!(
            "give `{name}` a table (`{{points: [[q, v], ...]}}`) or its coefficients: {}",
            coefficients.join(", ")
        )),
        BindError::NotAMotion { reason, .. } => {
            let help = match reason {
                NotAMotion::Coefficient { function } => format!(
                    "give `{function}: {{points: ...}}` or `{function}: {{table: ...}}` instead"
                ),
                _ => "only an error motion (an error in the `errors` of one body with a joint) varies along an axis; give a number".to_string(),
            };
            Message::new(text, "not an error motion", "chain::values::not_a_motion").help(help)
        }
        BindError::NoConstantTerm { .. } => Message::new(
            text,
            "no constant term",
            "chain::values::no_constant_term",
        )
        .help("give its coefficients instead, or give the slot a constant term in the machine file (`powers` with 0, or `from: 0`)"),
        BindError::CoefficientAndFunction { .. } => Message::new(
            text,
            "given twice",
            "chain::values::coefficient_and_function",
        )
        .help("a function slot is either tabulated as a whole or given by its coefficients"),
        BindError::NotFinite { .. } => {
            Message::new(text, "not finite", "chain::values::not_finite")
        }
        BindError::ReverseStdWithoutReverse { .. } => Message::new(
            text,
            "no reverse direction",
            "chain::values::reverse_std_without_reverse",
        )
        .help("give the reverse direction too (`reverse` or `reverse_points`), or one `std` for both directions"),
        BindError::ReverseStdWithoutStd { .. } => Message::new(
            text,
            "no main std",
            "chain::values::reverse_std_without_std",
        )
        .help("give the main direction's standard deviations too (`std` or `std_points`)"),
        BindError::NegativeStd { .. } => {
            Message::new(text, "negative std", "chain::values::negative_std")
        }
    };
    message.into()
}

// ---------------------------------------------------------------------------
// The reader

/// The reader of a values file: the problems found so far (in the values
/// file, and per CSV file).
struct Reader {
    problems: Vec<(Origin, Problem)>,
    /// The diagnostics of CSV tables, one per file with problems.
    tables: Vec<Diagnostics>,
    #[cfg_attr(not(feature = "csv"), allow(dead_code))]
    base: PathBuf,
    #[cfg_attr(not(feature = "csv"), allow(dead_code))]
    file: String,
    /// The CSV files read so far.
    #[cfg(feature = "csv")]
    csv_files: Vec<(PathBuf, CsvRead)>,
}

/// What reading a CSV file gave.
#[cfg(feature = "csv")]
enum CsvRead {
    Read(std::rc::Rc<csv::CsvFile>),
    Unreadable(String),
    /// Not a CSV table: its problems are reported already.
    Invalid,
}

impl TreeReader for Reader {
    fn problems(&mut self) -> &mut Vec<(Origin, Problem)> {
        &mut self.problems
    }
}

/// The tables of one table entry, in [`Motion`]'s order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Part {
    /// `points` / `column`: `v↑`, or the only table.
    Main,
    /// `reverse_points` / `reverse`: `v↓`.
    Reverse,
    /// `std_points` / `std`: `s↑` (or both directions').
    Std,
    /// `reverse_std_points` / `reverse_std`: `s↓`.
    ReverseStd,
}

impl Part {
    const ALL: [Part; 4] = [Part::Main, Part::Reverse, Part::Std, Part::ReverseStd];

    /// Its key in a `points` entry, or (`false`) in a CSV `table` entry.
    fn key(self, points: bool) -> &'static str {
        let (p, c) = match self {
            Part::Main => ("points", "column"),
            Part::Reverse => ("reverse_points", "reverse"),
            Part::Std => ("std_points", "std"),
            Part::ReverseStd => ("reverse_std_points", "reverse_std"),
        };
        if points {
            p
        } else {
            c
        }
    }

    fn is_std(self) -> bool {
        matches!(self, Part::Std | Part::ReverseStd)
    }
}

/// One table of one entry, as read.
struct TableSpec {
    points: Vec<((f64, f64), Origin)>,
    source: String,
    interpolation: Interpolation,
    extrapolation: Extrapolation,
    /// The CSV file (for locating a point's problem), if any.
    csv: Option<(String, String)>,
}

impl Reader {
    fn values(&mut self, root: &Node, b: &mut ValuesBuilder<'_>) {
        let Some(top) = self.top(root, TOP_KEYS) else {
            return;
        };
        let machine = b.machine;
        if let Some(node) = self.required(&top, "machine") {
            if let Some(name) = self.name(node, "machine", "a machine name") {
                if name != machine.name {
                    let text = format!(
                        "these values are for machine `{name}`, not `{}`",
                        machine.name
                    );
                    let help = format!(
                        "a values file belongs to one machine file; this one's `machine` is `{}`",
                        machine.name
                    );
                    let mismatch =
                        Message::new(text, "other machine", "chain::values::machine_mismatch")
                            .help(help);
                    self.report(node.span, "machine", mismatch.into());
                }
            }
        }
        if let Some(d) = top.get("description") {
            self.text(d, "description", "a string", |_| true);
        }
        if let Some((k, node)) = top.entry("units") {
            if let Some(u) = self.fields(node, k.span, "units", UNITS_KEYS) {
                if let Some(n) = u.get("linear") {
                    b.units.linear =
                        match self.keyword(n, "units.linear", "linear unit", LINEAR_UNITS) {
                            Some("um") => LinearUnit::Um,
                            _ => LinearUnit::Mm,
                        };
                }
                if let Some(n) = u.get("angular") {
                    b.units.angular =
                        match self.keyword(n, "units.angular", "angular unit", ANGULAR_UNITS) {
                            Some("urad") => AngularUnit::Urad,
                            Some("arcsec") => AngularUnit::Arcsec,
                            Some("deg") => AngularUnit::Deg,
                            _ => AngularUnit::Rad,
                        };
                }
            }
        }
        let Some(values) = self.required(&top, "values") else {
            return;
        };
        let Some(entries) = self.entries(values, "values") else {
            return;
        };
        // Tables first: a coefficient given with its function's table is
        // reported at the coefficient, whichever comes first in the file.
        let mut order: Vec<&(Node, Node)> = entries.iter().collect();
        order.sort_by_key(|(_, v)| !is_table(v));
        for (k, v) in order {
            let name = k.as_str().unwrap_or("").to_string();
            let path = join("values", &name);
            self.entry(&name, k, v, &path, b);
        }
    }

    fn entry(
        &mut self,
        name: &str,
        key: &Node,
        node: &Node,
        path: &str,
        b: &mut ValuesBuilder<'_>,
    ) {
        let key_origin = key.span.origin(path);
        let m = b.machine;
        // The kind of the value (for its unit): the error's, or the
        // function's coefficients'.
        let kind = m.error_index(name).map(|j| m.errors[j].kind).or_else(|| {
            let f = &m.functions[m.function_index(name)?];
            f.coefficients.first().map(|(j, _)| m.errors[*j].kind)
        });
        let factor = kind.map_or(1.0, |k| b.units.factor(k));
        if node.as_mapping().is_none() {
            // A number.
            let Some(value) = self.number(node, path) else {
                return;
            };
            if !value.is_finite() {
                self.report(node.span, path, Problem::NotFinite { what: "the value" });
                return;
            }
            if let Err(e) = b.constant_with(name, value * factor, None, Some(key_origin.clone())) {
                self.problems.push((key_origin, bind_problem(&e)));
            }
            return;
        }
        let Some(fields) = self.fields(node, key.span, path, ENTRY_KEYS) else {
            return;
        };
        let value = fields.entry("value");
        let table_key = ["points", "table"]
            .into_iter()
            .find(|k| fields.get(k).is_some());
        if let (Some(_), Some(t)) = (value, table_key) {
            let (kn, _) = fields.entry(t).map_or((key, node), |e| e);
            self.report(
                kn.span,
                fields.path(t),
                Problem::Conflict {
                    first: "value",
                    second: if t == "points" { "points" } else { "table" },
                },
            );
            return;
        }
        if let Some((_, vn)) = value {
            for extra in [
                "column",
                "interpolation",
                "extrapolate",
                "reverse",
                "reverse_std",
                "reverse_points",
                "std_points",
                "reverse_std_points",
            ] {
                if let Some((kn, _)) = fields.entry(extra) {
                    let text = format!("`{extra}` belongs to a table; `{name}` is given a `value`");
                    let not =
                        Message::new(text, "not a table", "chain::values::key_not_for_constant");
                    self.report(kn.span, fields.path(extra), not.into());
                }
            }
            let Some(v) = self.number(vn, &fields.path("value")) else {
                return;
            };
            if !v.is_finite() {
                self.report(
                    vn.span,
                    fields.path("value"),
                    Problem::NotFinite { what: "the value" },
                );
                return;
            }
            let std = match fields.get("std") {
                Some(sn) => {
                    let s = self.number(sn, &fields.path("std"));
                    match s {
                        Some(s) if s.is_finite() && s >= 0.0 => Some(s * factor),
                        Some(s) => {
                            let what = "the standard deviation";
                            let bad = Problem::OutOfRange {
                                what,
                                value: s,
                                range: "[0, ∞)",
                            };
                            self.report(sn.span, fields.path("std"), bad);
                            return;
                        }
                        None => return,
                    }
                }
                None => None,
            };
            if let Err(e) = b.constant_with(name, v * factor, std, Some(key_origin.clone())) {
                self.problems.push((key_origin, bind_problem(&e)));
            }
            return;
        }
        if fields.get("points").is_none() {
            let number = |n: &Node| n.as_str().is_none_or(|t| t.trim().parse::<f64>().is_ok());
            if let Some((_, sn)) = fields.entry("std").filter(|(_, n)| number(n)) {
                let text = format!("`std` of a CSV table names the column of standard deviations; `{name}` is given a table, not a constant `value`");
                let not = Message::new(text, "not a column name", "chain::values::key_not_for_table")
                    .help("write `std: COLUMN` (a column of per-position standard deviations), or give a constant as `{value: V, std: S}`");
                self.report(sn.span, fields.path("std"), not.into());
                return;
            }
        } else if let Some((kn, _)) = fields.entry("std") {
            let text = format!(
                "`std` belongs to a constant `value` or a CSV `table`; `{name}` is given `points`"
            );
            let not = Message::new(text, "not a constant", "chain::values::key_not_for_table")
                .help(
                    "per-position standard deviations of `points` are `std_points: [[q, s], ...]`",
                );
            self.report(kn.span, fields.path("std"), not.into());
        }
        let variable = match b.table_target(name) {
            Ok((_, variable, _, _)) => variable,
            Err(e) => {
                self.problems.push((key_origin, bind_problem(&e)));
                return;
            }
        };
        let var_name = m.variables[variable].name.as_str();
        let Some(specs) = self.table_spec(name, &fields, key, factor, var_name) else {
            return;
        };
        let mut parts: [Option<Sourced>; 4] = Default::default();
        let mut ok = true;
        for (part, spec) in &specs {
            if part.is_std() {
                if let Some((_, origin)) = spec.points.iter().find(|((_, v), _)| *v < 0.0) {
                    let text = format!(
                        "a standard deviation must be ≥ 0, got {}",
                        spec.points
                            .iter()
                            .find(|((_, v), _)| *v < 0.0)
                            .map_or(0.0, |p| p.0 .1 / factor)
                    );
                    let neg = Message::new(text, "negative", "chain::values::negative_std");
                    self.locate(&spec.csv, origin.clone(), neg.into());
                    ok = false;
                    continue;
                }
            }
            let points: Vec<(f64, f64)> = spec.points.iter().map(|(p, _)| *p).collect();
            match Table::new(points, spec.interpolation, spec.extrapolation) {
                Ok(table) => {
                    parts[*part as usize] = Some(Sourced {
                        table,
                        source: spec.source.clone(),
                    });
                }
                Err(e) => {
                    self.table_problem(&e, spec, *part, &fields, key);
                    ok = false;
                }
            }
        }
        if !ok {
            return;
        }
        let [Some(up), down, std_up, std_down] = parts else {
            return;
        };
        let motion = Motion {
            up,
            down,
            std_up,
            std_down,
        };
        if let Err(e) = b.motion_with(name, motion, Some(key_origin.clone())) {
            let at = match e {
                BindError::ReverseStdWithoutReverse { .. }
                | BindError::ReverseStdWithoutStd { .. } => {
                    let k = Part::ReverseStd.key(fields.get("points").is_some());
                    fields
                        .entry(k)
                        .map(|(kn, _)| kn.span.origin(fields.path(k)))
                }
                _ => None,
            };
            self.problems
                .push((at.unwrap_or(key_origin), bind_problem(&e)));
        }
    }

    /// A problem at `origin` in the values file, or in the CSV file `csv`.
    fn locate(&mut self, csv: &Option<(String, String)>, origin: Origin, problem: Problem) {
        match csv {
            Some((file, text)) => {
                self.tables
                    .push(Diagnostics::single(file, text.clone(), origin, problem));
            }
            None => self.problems.push((origin, problem)),
        }
    }

    /// The points, sources and reading of a table entry: its main table and
    /// whichever of `reverse`, `std` and `reverse_std` it gives.
    fn table_spec(
        &mut self,
        name: &str,
        fields: &Fields<'_>,
        key: &Node,
        factor: f64,
        variable: &str,
    ) -> Option<Vec<(Part, TableSpec)>> {
        let interpolation = match fields.get("interpolation") {
            Some(n) => match self.keyword(
                n,
                &fields.path("interpolation"),
                "interpolation",
                INTERPOLATIONS,
            )? {
                "cubic" => Interpolation::Cubic,
                _ => Interpolation::Linear,
            },
            None => Interpolation::Linear,
        };
        let extrapolation = match fields.get("extrapolate") {
            Some(n) => match self.keyword(
                n,
                &fields.path("extrapolate"),
                "extrapolation",
                EXTRAPOLATIONS,
            )? {
                "hold" => Extrapolation::Hold,
                _ => Extrapolation::Error,
            },
            None => Extrapolation::Error,
        };
        let spec = |points, source, csv| TableSpec {
            points,
            source,
            interpolation,
            extrapolation,
            csv,
        };
        let in_points = fields.get("points").is_some();
        if let (true, Some((kn, _))) = (in_points, fields.entry("table")) {
            let both = Problem::Conflict {
                first: "points",
                second: "table",
            };
            self.report(kn.span, fields.path("table"), both);
            return None;
        }
        // The keys of the other form.
        let mut wrong = false;
        for part in Part::ALL {
            let other = part.key(!in_points);
            if other == "std" || other == "points" {
                continue; // `std` is checked with the constant; `points` is this form
            }
            if let Some((kn, _)) = fields.entry(other) {
                let (text, label, code) = if in_points {
                    (
                        format!("`{other}` belongs to a CSV `table`; `{name}` is given `points`"),
                        "not a CSV table",
                        "chain::values::key_not_for_points",
                    )
                } else {
                    (
                        format!("`{other}` belongs to `points`; `{name}` is given a CSV `table`"),
                        "not points",
                        "chain::values::key_not_for_csv",
                    )
                };
                let help = format!(
                    "with `{}`, write `{}`",
                    if in_points { "points" } else { "table" },
                    part.key(in_points)
                );
                self.report(
                    kn.span,
                    fields.path(other),
                    Message::new(text, label, code).help(help).into(),
                );
                wrong = true;
            }
        }
        if wrong {
            return None;
        }
        let mut out = Vec::new();
        if in_points {
            for part in Part::ALL {
                let k = part.key(true);
                let Some(pn) = fields.get(k) else {
                    continue;
                };
                let points = self.points(pn, &fields.path(k), factor)?;
                let source = if part == Part::Main {
                    "points".to_string()
                } else {
                    k.to_string()
                };
                out.push((part, spec(points, source, None)));
            }
            return Some(out);
        }
        let Some(tn) = fields.get("table") else {
            let text = format!("`{name}` needs a `value`, `points` or a `table`");
            let missing = Message::new(text, "no value", "chain::values::no_value").help(
                "write a number, `{value: V}`, `{points: [[q, v], ...]}` or `{table: FILE.csv, column: NAME}`",
            );
            self.report(key.span, fields.path.clone(), missing.into());
            return None;
        };
        let file = self.name(tn, &fields.path("table"), "a CSV file path")?;
        for part in Part::ALL {
            let k = part.key(false);
            let column = match fields.get(k) {
                Some(cn) => (
                    self.name(cn, &fields.path(k), "a column name")?,
                    Some((cn, k)),
                ),
                None if part == Part::Main => (name.to_string(), None),
                None => continue,
            };
            // A standard deviation's problem is its own cell's; a
            // position's is the position's.
            let (points, source, csv) = self.csv_points(
                name,
                &file,
                tn,
                column,
                fields,
                (factor, part.is_std()),
                variable,
            )?;
            out.push((part, spec(points, source, Some(csv))));
        }
        Some(out)
    }

    /// `[[q, v], ...]`, with each point's origin.
    fn points(
        &mut self,
        node: &Node,
        path: &str,
        factor: f64,
    ) -> Option<Vec<((f64, f64), Origin)>> {
        let Some(items) = node.as_sequence() else {
            self.wrong_type(node, path, "a list of [q, value] points");
            return None;
        };
        let mut out = Vec::with_capacity(items.len());
        let mut ok = true;
        for (i, item) in items.iter().enumerate() {
            let ipath = index(path, i);
            let Some([qn, vn]) = self.items::<2>(item, &ipath, "a point [q, value]") else {
                ok = false;
                continue;
            };
            let q = self.number(qn, &index(&ipath, 0));
            let v = self.number(vn, &index(&ipath, 1));
            let (Some(q), Some(v)) = (q, v) else {
                ok = false;
                continue;
            };
            for (x, n, k) in [(q, qn, 0), (v, vn, 1)] {
                if !x.is_finite() {
                    let what = if k == 0 {
                        "the position q"
                    } else {
                        "the value"
                    };
                    self.report(n.span, index(&ipath, k), Problem::NotFinite { what });
                    ok = false;
                }
            }
            out.push(((q, v * factor), item.span.origin(ipath)));
        }
        ok.then_some(out)
    }

    /// Reports why the points are not a table, at the offending point.
    fn table_problem(
        &mut self,
        e: &TableError,
        spec: &TableSpec,
        part: Part,
        fields: &Fields<'_>,
        key: &Node,
    ) {
        let (index, text, code, help) = match *e {
            TableError::TooFewPoints { found } => (
                None,
                format!("a table needs at least 2 points to interpolate between, found {found}"),
                "chain::values::too_few_points",
                "a constant error is a number, not a table",
            ),
            TableError::NotFinite { index, .. } => {
                (Some(index), e.to_string(), "chain::values::not_finite", "")
            }
            TableError::NotIncreasing { index, q, previous } => (
                Some(index),
                if q == previous {
                    format!("position q = {q} appears twice")
                } else {
                    format!("the positions must increase: q = {q} comes after q = {previous}")
                },
                if q == previous {
                    "chain::values::duplicate_position"
                } else {
                    "chain::values::unsorted_positions"
                },
                "list the points by increasing q, each position once",
            ),
        };
        let mut message = Message::new(text, "table", code);
        if !help.is_empty() {
            message = message.help(help);
        }
        let at = index
            .and_then(|i| spec.points.get(i))
            .map(|(_, o)| o.clone());
        match at {
            Some(origin) => self.locate(&spec.csv, origin, message.into()),
            None => {
                let in_points = spec.csv.is_none();
                let key_path = match fields.entry(part.key(in_points)) {
                    Some(_) => part.key(in_points),
                    None if in_points => "points",
                    None => "table",
                };
                let (kn, _) = fields.entry(key_path).map_or((key, key), |e| e);
                self.report(kn.span, fields.path(key_path), message.into());
            }
        }
    }

    /// The points of a CSV table: `(points, source, (csv file, csv text))`.
    #[cfg(feature = "csv")]
    #[allow(clippy::too_many_arguments)]
    fn csv_points(
        &mut self,
        name: &str,
        file: &str,
        table_node: &Node,
        (column, column_node): (String, Option<(&Node, &str)>),
        fields: &Fields<'_>,
        (factor, at_value): (f64, bool),
        var_name: &str,
    ) -> Option<CsvPoints> {
        use csv::{CsvFile, CsvOpenError};
        let path = self.base.join(file);
        let shown = path.display().to_string();
        // Each file is read once, however many entries use it.
        let cached = match self.csv_files.iter().position(|(p, _)| *p == path) {
            Some(k) => k,
            None => {
                let read = match CsvFile::read(&path, &shown) {
                    Ok(c) => CsvRead::Read(std::rc::Rc::new(c)),
                    Err(CsvOpenError::Unreadable(why)) => CsvRead::Unreadable(why),
                    Err(CsvOpenError::Invalid(d)) => {
                        // Its problems are reported once.
                        self.tables.push(d);
                        CsvRead::Invalid
                    }
                };
                self.csv_files.push((path.clone(), read));
                self.csv_files.len() - 1
            }
        };
        let csv = match &self.csv_files[cached].1 {
            CsvRead::Read(c) => std::rc::Rc::clone(c),
            CsvRead::Unreadable(why) => {
                let text = format!("cannot read the table `{file}` ({shown}): {why}");
                let unread = Message::new(text, "table file", "chain::values::table_file")
                    .help("table paths are relative to the values file's directory");
                self.report(table_node.span, fields.path("table"), unread.into());
                return None;
            }
            CsvRead::Invalid => return None,
        };
        let Some(qc) = csv.column(var_name) else {
            let text = format!(
                "the header has no column `{var_name}` for the axis variable of `{name}` (asked for in {}:{})",
                self.file, table_node.span.line
            );
            let missing = Message::new(text, "header", "chain::values::csv_no_variable")
                .suggest(closest(var_name, csv.names()))
                .help(format!(
                    "the header names the axis variable `{var_name}` (positions in the machine's units) and the value columns; it has {}",
                    csv.names().collect::<Vec<_>>().join(", ")
                ));
            let d = Diagnostics::single(
                &shown,
                csv.text.clone(),
                csv.header_origin(),
                missing.into(),
            );
            self.tables.push(d);
            return None;
        };
        let Some(vc) = csv.column(&column) else {
            let text = format!("`{shown}` has no column `{column}`");
            let missing = Message::new(text, "no such column", "chain::values::csv_no_column")
                .suggest(closest(&column, csv.names()))
                .help(format!(
                    "its header has {}{}",
                    csv.names().collect::<Vec<_>>().join(", "),
                    if column_node.is_none() {
                        "; without `column`, the column is the entry's name"
                    } else {
                        ""
                    }
                ));
            let (span, key) = match column_node {
                Some((n, k)) => (n.span, fields.path(k)),
                None => (table_node.span, fields.path("table")),
            };
            self.report(span, key, missing.into());
            return None;
        };
        let mut points = Vec::with_capacity(csv.len());
        let mut bad = Vec::new();
        for row in csv.rows() {
            let (qt, qo) = &row[qc];
            let (vt, vo) = &row[vc];
            let q = cell_number(qt, qo, &mut bad);
            let v = cell_number(vt, vo, &mut bad);
            if let (Some(q), Some(v)) = (q, v) {
                points.push(((q, v * factor), if at_value { vo } else { qo }.clone()));
            }
        }
        if let Some(d) = Diagnostics::located(&shown, csv.text.clone(), bad) {
            self.tables.push(d);
            return None;
        }
        Some((
            points,
            format!("{file}, column {column}"),
            (shown, csv.text.clone()),
        ))
    }

    /// Without the `csv` feature a CSV table cannot be read.
    #[cfg(not(feature = "csv"))]
    #[allow(clippy::too_many_arguments)]
    fn csv_points(
        &mut self,
        _name: &str,
        _file: &str,
        table_node: &Node,
        _column: (String, Option<(&Node, &str)>),
        fields: &Fields<'_>,
        _factor: (f64, bool),
        _variable: &str,
    ) -> Option<CsvPoints> {
        let text =
            "reading a CSV table needs chain-core's `csv` feature, which this build does not have";
        let off = Message::new(text, "CSV table", "chain::values::csv_feature")
            .help("enable the feature (`chain-core = { features = [\"csv\"] }`; the `chain` binary has it), or give the table as `points: [[q, v], ...]`");
        self.report(table_node.span, fields.path("table"), off.into());
        None
    }
}

/// The points of a CSV table with their origins, its description
/// (`FILE.csv, column NAME`), and the CSV file's name and text (for locating
/// a point's problem).
type CsvPoints = (Vec<((f64, f64), Origin)>, String, (String, String));

/// True if an entry's node is a table (a mapping with `points` or `table`).
fn is_table(node: &Node) -> bool {
    node.as_mapping().is_some_and(|m| {
        m.iter()
            .any(|(k, _)| matches!(k.as_str(), Some("points" | "table")))
    })
}

/// A CSV cell as a finite number; a problem located at the cell otherwise.
#[cfg(feature = "csv")]
fn cell_number(text: &str, origin: &Origin, bad: &mut Vec<(Origin, Problem)>) -> Option<f64> {
    match crate::tabular::number(text, &origin.key) {
        Ok(v) => Some(v),
        Err(problem) => {
            let message = Message::new(problem.to_string(), problem.label(), problem.code());
            bad.push((origin.clone(), message.into()));
            None
        }
    }
}

#[cfg(all(test, not(feature = "csv")))]
mod without_csv {
    use super::*;

    #[test]
    fn a_csv_table_needs_the_feature() {
        let yaml = "machine: m\nbodies:\n  bed: {}\n  x_slide: {parent: bed, joint: {type: prismatic, axis: +x, variable: x}, errors: {dx: dxx}}\nworkpiece: bed\ntool: x_slide\n";
        let machine = crate::load_str(yaml, "m.yaml").unwrap();
        let text = "machine: m\nvalues:\n  dxx: {table: t.csv}\n";
        let e = Values::parse(text, "v.yaml", Path::new("."), &machine).unwrap_err();
        let first = e.diagnostics().first();
        assert_eq!(first.problem.code(), "chain::values::csv_feature");
        assert_eq!((first.origin.line, first.origin.column), (3, 16));
        assert!(e.to_string().contains("`csv` feature"), "{e}");
        // `points` need no feature.
        let text = "machine: m\nvalues:\n  dxx: {points: [[0, 0], [1, 1]]}\n";
        assert!(Values::parse(text, "v.yaml", Path::new("."), &machine).is_ok());
    }
}
