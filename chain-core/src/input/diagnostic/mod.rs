//! Located diagnostics: the refusals of every file chain-core reads
//! (machine files, values files and their CSV tables, the settings files of
//! `chain motion`, measurement, candidate and positioning run files).
//!
//! Every diagnostic is a typed problem, and its wording lives in one place:
//! each rule a file can break is one variant, worded by one match arm of
//! [`Problem::describe`] (headline, note, help, span label, code). The rules
//! of the machine-file contract are variants of [`Problem`] itself: the YAML
//! loader ([`crate::load`]) attaches a problem to an [`Origin`](crate::model::Origin) (file, line,
//! column, key path) to make a [`LoadError`], and the `machine!` macro can
//! attach the same problem to a token span, so both front ends say the same
//! thing about the same mistake. The readers of the other files share the
//! rules they have in common (unknown key, wrong type, ...) and word their
//! own through their subject's enum, a variant of [`Problem`] worded in this
//! module's file of that subject: [`ValuesProblem`] (`values.rs`),
//! [`SettingsProblem`] (`settings.rs`), [`MeasurementsProblem`] and
//! [`PositioningProblem`] (`measured.rs`); a CSV file's shape and cells are
//! [`CsvProblem`]s ([`crate::tabular`], whose wording the command line's CSV
//! messages share). A crate that reads files of its own words its problems
//! the same way, as an enum implementing [`Describe`], wrapped by
//! [`Problem::foreign`].
//!
//! [`Diagnostics`] is the error type of [`crate::load_str`], of
//! [`crate::settings::load_settings_str`] and their friends: a non-empty list
//! of [`LoadError`]s for one file. Its `Display` names the file,
//! line, column and key of the first error on its own; through
//! [`miette::Diagnostic`] it also carries the file text (labels at the spans)
//! and the remaining errors as `related()` diagnostics.

mod located;
mod measured;
mod names;
mod settings;
#[cfg(feature = "miette")]
mod snippet;
mod values;

use std::fmt;
use std::sync::Arc;

pub use located::{Diagnostics, LoadError};
#[cfg(feature = "csv")]
pub(crate) use measured::RUN_FILE_HEADER;
pub use measured::{CircularProblem, DriftProblem, MeasurementsProblem, PositioningProblem};
#[cfg(feature = "csv")]
pub(crate) use measured::{CIRCULAR_FILE_HEADER, DRIFT_FILE_HEADER};
pub use names::{closest, shortened, QUOTED_CHARS};
pub use settings::SettingsProblem;
#[cfg(feature = "miette")]
pub use snippet::Snippet;
pub use values::ValuesProblem;

use crate::model::ErrorKind;
use crate::tabular::CsvProblem;

/// One thing wrong with a machine description (or another file chain-core
/// reads), independent of where it is.
///
/// `Display` gives the full message (headline plus the parenthesised note);
/// [`Problem::describe`] gives all its parts (headline, note, help, span
/// label, code) from one match arm per variant, and [`Problem::headline`],
/// [`Problem::note`], [`Problem::help`], [`Problem::label`] and
/// [`Problem::code`] each one of them.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Problem {
    /// The file could not be read.
    Io {
        /// The operating system's message.
        message: String,
    },
    /// The file is larger than the loader accepts.
    TooLarge {
        /// The limit in bytes.
        limit: usize,
    },
    /// The file contains a NUL byte.
    Binary {
        /// Byte offset of the first NUL.
        offset: usize,
    },
    /// The file is not valid UTF-8.
    InvalidUtf8 {
        /// Byte offset of the first invalid byte.
        offset: usize,
    },
    /// The file holds no YAML document (or only `null`).
    Empty,
    /// The YAML parser rejected the text.
    Syntax {
        /// The parser's message.
        message: String,
    },
    /// The file holds more than one YAML document.
    MultipleDocuments,
    /// Collections nested deeper than the loader accepts.
    TooDeep {
        /// The nesting limit.
        limit: usize,
    },
    /// The file expands to more nodes than the loader accepts; alias uses
    /// count their whole anchor, so an alias bomb stops here.
    AliasLimit {
        /// The node limit.
        limit: usize,
    },
    /// An alias refers to a collection that contains it.
    RecursiveAlias,
    /// A mapping key that is a mapping or a sequence.
    NonScalarKey,
    /// A key given twice in one mapping.
    DuplicateKey {
        /// The key.
        key: String,
        /// 1-based line of its first occurrence.
        first_line: usize,
    },
    /// The top level of the file is not a mapping.
    TopLevelNotMapping {
        /// What was found (`a sequence`, `a string `abc``, ...).
        found: String,
    },
    /// A value of the wrong shape.
    WrongType {
        /// What was expected (`a mapping`, `a name`, ...).
        expected: &'static str,
        /// What was found.
        found: String,
    },
    /// A key that is not valid at this place.
    UnknownKey {
        /// The key as written.
        key: String,
        /// The valid keys here.
        expected: &'static [&'static str],
        /// The closest valid key, if one is close.
        suggestion: Option<String>,
    },
    /// A required key is missing.
    MissingKey {
        /// The missing key.
        key: &'static str,
    },
    /// A name that is not an identifier.
    InvalidName {
        /// The name as written.
        name: String,
        /// What it names (`variable`, `parameter`, `error`).
        what: &'static str,
    },
    /// A name reserved by the expression language (`pi`, `sin`, `cos`).
    ReservedName {
        /// The name.
        name: String,
    },
    /// A keyword value outside its set (joint type, axis, dist, sided, frame,
    /// component).
    UnknownValue {
        /// What the value is (`joint type`, `axis`, ...).
        what: &'static str,
        /// The value as written.
        found: String,
        /// The valid values.
        expected: &'static [&'static str],
        /// The closest valid value, if one is close.
        suggestion: Option<String>,
    },
    /// `bodies` is empty.
    NoBodies,
    /// A reference to a body that does not exist.
    UnknownBody {
        /// What refers to it (`parent`, `workpiece`, `tool`).
        role: &'static str,
        /// The name as written.
        name: String,
        /// The closest body name, if one is close.
        suggestion: Option<String>,
    },
    /// The parent links form a cycle.
    Cycle {
        /// The bodies of the cycle, each followed by its parent, the first
        /// repeated at the end.
        bodies: Vec<String>,
    },
    /// A second body without a parent.
    SecondRoot {
        /// The first root.
        first: String,
        /// The second root.
        second: String,
    },
    /// No body without a parent.
    NoRoot,
    /// `workpiece` and `tool` name the same body.
    WorkpieceIsTool {
        /// The body.
        name: String,
    },
    /// An axis variable that drives two joints.
    DuplicateVariable {
        /// The variable.
        name: String,
        /// The body whose joint it already drives.
        body: String,
    },
    /// A declared body with the name a `dh` / `mdh` row gives its extra
    /// frame.
    GeneratedBodyName {
        /// The name.
        name: String,
        /// The body whose DH row generates it.
        body: String,
    },
    /// Two kinds of names that must differ are the same.
    NameCollision {
        /// The name.
        name: String,
        /// What it is here (`variable`, `error`).
        what: &'static str,
        /// What it already is (`parameter`, `axis variable`).
        other: &'static str,
    },
    /// An expression uses a name that is not a declared parameter.
    UnknownName {
        /// The name.
        name: String,
        /// Extra explanation (`x` is an axis variable, ...).
        hint: Option<String>,
    },
    /// An expression that does not parse.
    Expression {
        /// The parser's message.
        message: String,
    },
    /// A parameter in a divisor.
    ParameterInDivisor {
        /// The parameter.
        name: String,
    },
    /// A parameter raised to a negative power.
    NegativePowerOfParameter {
        /// The parameter.
        name: String,
    },
    /// A name where only numbers are allowed.
    NameInNumber {
        /// The name.
        name: String,
    },
    /// A number that must be positive and finite but is not.
    NotPositive {
        /// What the number is (`std`, `tolerance`, ...).
        what: &'static str,
        /// Its value.
        value: f64,
    },
    /// A number that must be finite but is not.
    NotFinite {
        /// What the number is.
        what: &'static str,
    },
    /// A number outside its range.
    OutOfRange {
        /// What the number is.
        what: &'static str,
        /// Its value.
        value: f64,
        /// The allowed range, e.g. `(0, 1]`.
        range: &'static str,
    },
    /// A uniform distribution with `min >= max`.
    UniformBounds {
        /// Lower bound.
        min: f64,
        /// Upper bound.
        max: f64,
    },
    /// Parameters of a distribution that do not define one (`min ≥ max`, a
    /// mode outside `[min, max]`, a mean not above the shift, …).
    DistributionParameters {
        /// The distribution.
        dist: &'static str,
        /// What is wrong, with the values.
        detail: String,
    },
    /// A `correlation` entry that does not define one.
    BadCorrelation {
        /// What is wrong.
        detail: String,
    },
    /// Two keys that exclude each other.
    Conflict {
        /// The key given first.
        first: &'static str,
        /// The key given second.
        second: &'static str,
    },
    /// A distribution without its spread.
    MissingSpread {
        /// The distribution.
        dist: &'static str,
    },
    /// A statistics key that does not apply to the distribution.
    KeyNotForDistribution {
        /// The key.
        key: &'static str,
        /// The distribution.
        dist: &'static str,
    },
    /// Statistics for an error the machine does not have.
    UnknownError {
        /// The name.
        name: String,
        /// The closest error name, if one is close.
        suggestion: Option<String>,
    },
    /// An error name used as two different kinds of quantity.
    ErrorKindConflict {
        /// The error name.
        name: String,
        /// The kind of its first use.
        first: ErrorKind,
        /// The kind of this use.
        second: ErrorKind,
        /// 1-based line of the first use.
        first_line: usize,
    },
    /// A grid key that is not an axis variable.
    UnknownVariable {
        /// The name.
        name: String,
        /// The closest variable, if one is close.
        suggestion: Option<String>,
    },
    /// A list that must not be empty.
    EmptyList {
        /// What the list is.
        what: &'static str,
    },
    /// A list of the wrong length.
    WrongLength {
        /// Expected number of items.
        expected: usize,
        /// Found number of items.
        found: usize,
    },
    /// A function slot (a mapping in an `errors` slot) on a body without a
    /// joint: there is no variable for it to vary along.
    FunctionWithoutJoint {
        /// The body.
        body: String,
    },
    /// A thermal term (`per:`) names a sensor the machine does not declare.
    UnknownSensor {
        /// The name.
        name: String,
        /// The declared sensors.
        sensors: Vec<String>,
        /// The closest sensor, if one is close.
        suggestion: Option<String>,
    },
    /// A sensor declared twice.
    SensorTwice {
        /// The name.
        name: String,
        /// The line of the first declaration.
        line: usize,
    },
    /// A sensor named twice in one `per`.
    DuplicateSensor {
        /// The name.
        name: String,
    },
    /// An allocation key in a sensor's `statistics` entry.
    SensorStatisticKey {
        /// The key.
        key: &'static str,
        /// The sensor.
        sensor: String,
    },
    /// A thermal term in `squareness`.
    ThermalNotAllowed,
    /// A function slot in `location_errors` or `squareness`, which take
    /// error names only.
    FunctionNotAllowed {
        /// The group (`location_errors`, `squareness`).
        group: &'static str,
    },
    /// A Fourier basis on a prismatic joint.
    FourierOnPrismatic {
        /// The body.
        body: String,
    },
    /// A Legendre or Chebyshev basis without its `range`.
    MissingRange {
        /// The basis.
        basis: &'static str,
    },
    /// A basis range `[lo, hi]` with `lo >= hi`.
    RangeOrder {
        /// Lower end.
        lo: f64,
        /// Upper end.
        hi: f64,
    },
    /// A degree, harmonic count, power or `from` that is not a whole number
    /// from 0 to [`crate::load::MAX_ORDER`].
    BadOrder {
        /// What the number is (`the degree`, `a power`, ...).
        what: &'static str,
        /// Its value.
        value: f64,
    },
    /// A power listed twice in `powers`.
    DuplicatePower {
        /// The power.
        power: u32,
        /// Its first position in the list (0-based).
        first: usize,
    },
    /// `from` above `degree`.
    FromAboveDegree {
        /// `from`.
        from: u32,
        /// `degree`.
        degree: u32,
    },
    /// A key of a function slot that its basis does not use.
    KeyNotForBasis {
        /// The key.
        key: &'static str,
        /// The basis (`powers`, `legendre`, ...).
        basis: &'static str,
    },
    /// A function slot with neither `powers` nor `basis`.
    MissingBasis,
    /// `basis: powers`: the power basis is written `powers: [..]`, without
    /// `basis`.
    PowersAsBasis,
    /// A function name declared again with a different basis, on another
    /// axis or in a slot of another kind.
    FunctionRedeclared {
        /// The function.
        name: String,
        /// How this declaration differs from the first.
        difference: String,
        /// Where the first declaration is: `on line 8` (a file) or
        /// ``at `bodies.x_slide.errors.dy.name` `` (the inline `machine!`
        /// form, whose tokens have no lines).
        first: String,
    },
    /// A function or coefficient name that is already another name of the
    /// machine, or a name that is already a function or coefficient.
    FunctionClash {
        /// What the name is here (`coefficient `EYX_1` of function `EYX``).
        what: String,
        /// What it already is (`the error parameter `EYX_1` (line 7)`).
        other: String,
    },
    /// Statistics keyed by a function's name instead of its coefficients.
    FunctionStatistics {
        /// The function.
        name: String,
        /// Its coefficients.
        coefficients: Vec<String>,
    },
    /// `errors: iso` on a body without a joint.
    IsoWithoutJoint {
        /// The body.
        body: String,
    },
    /// `errors:` a scalar other than `iso`.
    ErrorsScalar {
        /// The value as written.
        found: String,
        /// `iso`, if the value is close to it.
        suggestion: Option<String>,
    },
    /// `iso` as the value of `location_errors` or `squareness`.
    IsoNotAllowed {
        /// The group.
        group: &'static str,
    },
    /// Two bodies whose `errors: iso` give the same names (their variables
    /// differ only in case).
    IsoClash {
        /// The name.
        name: String,
        /// This body.
        body: String,
        /// The body that named it first.
        other: String,
    },
    // The other files' rules, each subject's enum boxed so that a
    // `Problem` stays small.
    /// A rule of a values file or of a CSV table it names.
    Values(Box<ValuesProblem>),
    /// A CSV file's shape or one of its cells (every CSV reader).
    Csv(Box<CsvProblem>),
    /// A rule of a settings file of `chain motion`.
    Settings(Box<SettingsProblem>),
    /// A rule of a measurement or candidate file.
    Measurements(Box<MeasurementsProblem>),
    /// A rule of a positioning run file.
    Positioning(Box<PositioningProblem>),
    /// A rule of an ISO 230-3 drift-test file.
    Drift(Box<DriftProblem>),
    /// A rule of an ISO 230-4 circular-test file.
    Circular(Box<CircularProblem>),
    /// A rule of a file read by a crate outside chain-core, worded by that
    /// crate's own typed problem ([`Describe`]).
    Foreign(Foreign),
}

/// A typed problem that words itself: every part of its message from one
/// match arm per variant, as [`Problem::describe`] words chain-core's. A
/// crate reading files of its own implements it for its problem enum and
/// reports through [`Problem::foreign`].
pub trait Describe: fmt::Debug + Send + Sync + 'static {
    /// Every part of the message of this problem.
    fn describe(&self) -> Description;
}

/// A problem of a crate outside chain-core: the payload of
/// [`Problem::Foreign`]. Two are equal when they read the same.
#[derive(Debug, Clone)]
pub struct Foreign(Arc<dyn Describe>);

impl Foreign {
    /// The problem itself.
    pub fn get(&self) -> &dyn Describe {
        &*self.0
    }
}

impl PartialEq for Foreign {
    fn eq(&self, other: &Foreign) -> bool {
        self.0.describe() == other.0.describe()
    }
}

impl From<ValuesProblem> for Problem {
    fn from(problem: ValuesProblem) -> Problem {
        Problem::Values(Box::new(problem))
    }
}

impl From<CsvProblem> for Problem {
    fn from(problem: CsvProblem) -> Problem {
        Problem::Csv(Box::new(problem))
    }
}

impl From<SettingsProblem> for Problem {
    fn from(problem: SettingsProblem) -> Problem {
        Problem::Settings(Box::new(problem))
    }
}

impl From<MeasurementsProblem> for Problem {
    fn from(problem: MeasurementsProblem) -> Problem {
        Problem::Measurements(Box::new(problem))
    }
}

impl From<DriftProblem> for Problem {
    fn from(problem: DriftProblem) -> Problem {
        Problem::Drift(Box::new(problem))
    }
}

impl From<CircularProblem> for Problem {
    fn from(problem: CircularProblem) -> Problem {
        Problem::Circular(Box::new(problem))
    }
}

impl From<PositioningProblem> for Problem {
    fn from(problem: PositioningProblem) -> Problem {
        Problem::Positioning(Box::new(problem))
    }
}

fn kind_name(kind: ErrorKind) -> &'static str {
    match kind {
        ErrorKind::Linear => "a linear error (dx, dy, dz)",
        ErrorKind::Angular => "an angular error (ex, ey, ez)",
        ErrorKind::Squareness => "a squareness term",
    }
}

fn one_of(expected: &[&str]) -> String {
    format!("expected one of {}", expected.join(", "))
}

fn did_you_mean(suggestion: &Option<String>) -> Option<String> {
    suggestion.as_ref().map(|s| format!("did you mean `{s}`?"))
}

/// The parts of a [`Problem`]'s message, all from one place
/// ([`Problem::describe`]): adding a variant means writing one arm there.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Description {
    /// The main message, without the parenthesised note.
    pub headline: String,
    /// The parenthesised note that follows the headline (and the key), if
    /// any: the valid alternatives or the closest one.
    pub note: Option<String>,
    /// A longer hint for the reader, if one helps.
    pub help: Option<String>,
    /// A short label for the span in a rendered snippet.
    pub label: &'static str,
    /// A stable machine-readable code, e.g. `chain::unknown_key`.
    pub code: &'static str,
}

impl Description {
    /// A description with its code, span label and headline; no note, no help.
    pub fn new(
        code: &'static str,
        label: &'static str,
        headline: impl Into<String>,
    ) -> Description {
        Description {
            headline: headline.into(),
            note: None,
            help: None,
            label,
            code,
        }
    }

    /// With a note (`None` leaves it out).
    pub fn note(mut self, note: impl Into<Option<String>>) -> Description {
        self.note = note.into();
        self
    }

    /// With a hint (`None` leaves it out).
    pub fn help(mut self, help: impl Into<Option<String>>) -> Description {
        self.help = help.into();
        self
    }

    /// The headline `text`, ending with `(did you mean `…`?)` when there is
    /// a closest valid name.
    pub fn suggesting(text: impl Into<String>, suggestion: &Option<String>) -> String {
        let text = text.into();
        match did_you_mean(suggestion) {
            Some(s) => format!("{text} ({s})"),
            None => text,
        }
    }
}

impl Problem {
    /// Every part of the message of this problem: headline, note, help, span
    /// label and code, worded in one match arm per variant.
    pub fn describe(&self) -> Description {
        use Description as D;
        match self {
            Problem::Io { message } => D::new(
                "chain::io",
                "file",
                format!("cannot read the file: {message}"),
            ),
            Problem::TooLarge { limit } => D::new(
                "chain::too_large",
                "file",
                format!(
                    "the file is too large (more than {})",
                    crate::bounded::describe(*limit)
                ),
            ),
            Problem::Binary { offset } => D::new(
                "chain::binary",
                "NUL byte",
                format!("not a text file (NUL byte at byte offset {offset})"),
            ),
            Problem::InvalidUtf8 { offset } => D::new(
                "chain::invalid_utf8",
                "invalid UTF-8",
                format!("the file is not valid UTF-8 (invalid byte at byte offset {offset})"),
            ),
            Problem::Empty => D::new("chain::empty", "empty", "the machine file is empty")
                .note("expected a mapping with at least `machine` and `bodies`".to_string()),
            Problem::Syntax { message } => D::new(
                "chain::yaml_syntax",
                "syntax error",
                format!("YAML syntax error: {message}"),
            ),
            Problem::MultipleDocuments => D::new(
                "chain::multiple_documents",
                "second document",
                "more than one YAML document in the file",
            )
            .note("a machine file holds exactly one".to_string()),
            Problem::TooDeep { limit } => D::new(
                "chain::too_deep",
                "too deep",
                format!("nested more than {limit} levels deep"),
            ),
            Problem::AliasLimit { limit } => D::new(
                "chain::alias_limit",
                "alias",
                format!("the file expands to more than {limit} YAML nodes"),
            )
            .note("each use of an alias counts its whole anchor; an alias bomb?".to_string()),
            Problem::RecursiveAlias => D::new(
                "chain::recursive_alias",
                "alias",
                "an alias refers to a collection that contains it",
            ),
            Problem::NonScalarKey => D::new(
                "chain::non_scalar_key",
                "not a name",
                "a mapping key must be a plain name",
            ),
            Problem::DuplicateKey { key, first_line } => D::new(
                "chain::duplicate_key",
                "duplicate key",
                format!("duplicate key `{key}` (first given on line {first_line})"),
            ),
            Problem::TopLevelNotMapping { found } => D::new(
                "chain::top_level",
                "wrong type",
                format!("the top level must be a mapping, found {found}"),
            ),
            Problem::WrongType { expected, found } => D::new(
                "chain::wrong_type",
                "wrong type",
                format!("expected {expected}, found {found}"),
            ),
            Problem::UnknownKey {
                key,
                expected,
                suggestion,
            } => D::new(
                "chain::unknown_key",
                "unknown key",
                format!("unknown key `{key}`"),
            )
            .note(alternatives(expected, suggestion)),
            Problem::MissingKey { key } => D::new(
                "chain::missing_key",
                "missing key",
                format!("missing required key `{key}`"),
            ),
            Problem::InvalidName { name, what } => D::new(
                "chain::invalid_name",
                "invalid name",
                format!("`{name}` is not a valid {what} name"),
            )
            .note("use letters, digits and `_`, starting with a letter or `_`".to_string()),
            Problem::ReservedName { name } => D::new(
                "chain::reserved_name",
                "invalid name",
                format!("`{name}` is reserved by the expression language"),
            )
            .note("pi, sin and cos are reserved".to_string()),
            Problem::UnknownValue {
                what,
                found,
                expected,
                suggestion,
            } => D::new(
                "chain::unknown_value",
                "unknown value",
                format!("unknown {what} `{found}`"),
            )
            .note(alternatives(expected, suggestion)),
            Problem::NoBodies => D::new("chain::no_bodies", "no bodies", "`bodies` is empty"),
            Problem::UnknownBody {
                role,
                name,
                suggestion,
            } => D::new(
                "chain::unknown_body",
                "unknown body",
                format!("{role} `{name}` is not a body of this machine"),
            )
            .note(did_you_mean(suggestion)),
            Problem::Cycle { bodies } => {
                let path: Vec<String> = bodies.iter().map(|b| format!("`{b}`")).collect();
                D::new(
                    "chain::cycle",
                    "cycle",
                    format!("the parent links form a cycle: {}", path.join(" -> ")),
                )
                .help("exactly one body (the bed) has no `parent`".to_string())
            }
            Problem::SecondRoot { first, second } => D::new(
                "chain::second_root",
                "root",
                format!(
                    "`{second}` is a second root body: both `{first}` and `{second}` have no parent"
                ),
            )
            .help(format!(
                "give `{second}` a `parent`; exactly one body (the bed) has none"
            )),
            Problem::NoRoot => D::new(
                "chain::no_root",
                "root",
                "no root body: every body has a parent",
            )
            .help("exactly one body (the bed) has no `parent`".to_string()),
            Problem::WorkpieceIsTool { name } => D::new(
                "chain::workpiece_is_tool",
                "same body",
                format!("the workpiece and the tool are the same body `{name}`"),
            ),
            Problem::DuplicateVariable { name, body } => D::new(
                "chain::duplicate_variable",
                "duplicate variable",
                format!("variable `{name}` already drives the joint of body `{body}`"),
            ),
            Problem::GeneratedBodyName { name, body } => D::new(
                "chain::generated_body_name",
                "name taken",
                format!(
                    "body `{name}` has the name of the extra frame of body `{body}`'s DH row"
                ),
            )
            .help(
                "a `dh` row of body NAME adds the frame NAME.joint and an `mdh` row \
                 NAME.link; rename this body"
                    .to_string(),
            ),
            Problem::NameCollision { name, what, other } => D::new(
                "chain::name_collision",
                "name collision",
                format!("{what} `{name}` has the same name as a {other}"),
            )
            .help(
                "variables, parameters and error parameters share one namespace in the model"
                    .to_string(),
            ),
            Problem::UnknownName { name, hint } => D::new(
                "chain::unknown_name",
                "unknown name",
                format!("unknown name `{name}`: not a declared parameter"),
            )
            .note(hint.clone())
            .help("declare it under `parameters` (null makes it symbolic)".to_string()),
            Problem::Expression { message } => D::new(
                "chain::expression",
                "here",
                format!("cannot parse the expression: {message}"),
            ),
            Problem::ParameterInDivisor { name } => D::new(
                "chain::parameter_in_divisor",
                "parameter",
                format!("parameter `{name}` is in a divisor"),
            )
            .note(POLYNOMIALS.to_string()),
            Problem::NegativePowerOfParameter { name } => D::new(
                "chain::negative_power",
                "parameter",
                format!("parameter `{name}` is raised to a negative power"),
            )
            .note(POLYNOMIALS.to_string()),
            Problem::NameInNumber { name } => D::new(
                "chain::name_in_number",
                "not a number",
                format!(
                    "`{}` is a name, but only numbers are allowed here",
                    shortened(name)
                ),
            ),
            Problem::NotPositive { what, value } => D::new(
                "chain::not_positive",
                "out of range",
                format!("{what} must be positive and finite, got {value}"),
            ),
            Problem::NotFinite { what } => D::new(
                "chain::not_finite",
                "out of range",
                format!("{what} must be finite"),
            ),
            Problem::OutOfRange { what, value, range } => D::new(
                "chain::out_of_range",
                "out of range",
                format!("{what} must be in {range}, got {value}"),
            ),
            Problem::UniformBounds { min, max } => D::new(
                "chain::uniform_bounds",
                "out of range",
                format!("a uniform distribution needs min < max, got min = {min}, max = {max}"),
            ),
            Problem::DistributionParameters { dist, detail } => D::new(
                "chain::distribution_parameters",
                "out of range",
                format!("a {dist} distribution needs {detail}"),
            ),
            Problem::BadCorrelation { detail } => {
                D::new("chain::correlation", "bad correlation", detail.clone())
            }
            Problem::Conflict { first, second } => D::new(
                "chain::conflicting_keys",
                "conflicting key",
                format!("`{first}` and `{second}` cannot both be given"),
            )
            .help(
                (*first == "std" && *second == "tolerance")
                    .then(|| "std = tolerance / sigma_rule; give one of them".to_string()),
            ),
            Problem::MissingSpread { dist } => D::new(
                "chain::missing_spread",
                "no spread",
                if *dist == "uniform" {
                    "a uniform distribution needs `min` and `max`, or `std` or `tolerance`"
                        .to_string()
                } else {
                    format!("a {dist} distribution needs `std` or `tolerance`")
                },
            ),
            Problem::KeyNotForDistribution { key, dist } => D::new(
                "chain::key_not_for_distribution",
                "not for this distribution",
                format!("`{key}` does not apply to a {dist} distribution"),
            ),
            Problem::UnknownError { name, suggestion } => D::new(
                "chain::unknown_error",
                "unknown error",
                format!(
                    "statistics for `{name}`, but no body uses an error parameter of that name"
                ),
            )
            .note(did_you_mean(suggestion))
            .help("statistics entries are keyed by error names used in the bodies".to_string()),
            Problem::ErrorKindConflict {
                name,
                first,
                second,
                first_line,
            } => D::new(
                "chain::error_kind_conflict",
                "kind conflict",
                if *first_line > 0 {
                    format!(
                        "error `{name}` is used as {} here but as {} on line {first_line}",
                        kind_name(*second),
                        kind_name(*first)
                    )
                } else {
                    // The inline `machine!` form: tokens have no lines.
                    format!(
                        "error `{name}` is used as {} here but as {} before",
                        kind_name(*second),
                        kind_name(*first)
                    )
                },
            ),
            Problem::UnknownVariable { name, suggestion } => D::new(
                "chain::unknown_variable",
                "unknown variable",
                format!("`{name}` is not an axis variable of this machine"),
            )
            .note(did_you_mean(suggestion)),
            Problem::EmptyList { what } => D::new(
                "chain::empty_list",
                "empty",
                format!("{what} must not be empty"),
            ),
            Problem::WrongLength { expected, found } => D::new(
                "chain::wrong_length",
                "wrong length",
                format!("expected a list of {expected} items, found {found}"),
            ),
            Problem::FunctionWithoutJoint { body } => D::new(
                "chain::function_without_joint",
                "no joint",
                format!("body `{body}` has no joint, so its errors cannot vary along an axis"),
            )
            .help(
                "a function slot is a function of the body's own joint variable; give the body a \
                 `joint`, or write a constant error name"
                    .to_string(),
            ),
            Problem::UnknownSensor {
                name,
                sensors,
                suggestion,
            } => D::new(
                "chain::unknown_sensor",
                "unknown sensor",
                format!("`{name}` is not a declared sensor"),
            )
            .note(did_you_mean(suggestion))
            .help(if sensors.is_empty() {
                "a thermal term's `per` names sensors declared under the top-level `sensors:` \
                 (e.g. `sensors: {T_spindle: 20}`)"
                    .to_string()
            } else {
                format!("the declared sensors: {}", sensors.join(", "))
            }),
            Problem::SensorTwice { name, line } => D::new(
                "chain::sensor_twice",
                "declared twice",
                format!("sensor `{name}` is declared twice (first on line {line})"),
            )
            .help("each sensor is declared once under `sensors:`".to_string()),
            Problem::DuplicateSensor { name } => D::new(
                "chain::duplicate_sensor",
                "named twice",
                format!("sensor `{name}` is named twice in this `per`"),
            )
            .help("each sensor of a thermal term is named once".to_string()),
            Problem::SensorStatisticKey { key, sensor } => D::new(
                "chain::sensor_statistic_key",
                "not for a sensor",
                format!("`{key}` is an allocation key of an error; `{sensor}` is a sensor, whose entry is its temperature's distribution"),
            )
            .help("a sensor's statistics entry takes `dist` and the distribution's keys (°C)".to_string()),
            Problem::ThermalNotAllowed => D::new(
                "chain::thermal_not_allowed",
                "not a name",
                "`squareness` takes error names only, not a thermal term".to_string(),
            )
            .help(
                "a tilt that grows with temperature is an angular thermal term `{name: …, per: …}` \
                 in the body's `errors` or `location_errors`"
                    .to_string(),
            ),
            Problem::FunctionNotAllowed { group } => D::new(
                "chain::function_not_allowed",
                "not a name",
                format!("`{group}` takes error names only, not a function of the axis"),
            )
            .help(
                "functions of the joint variable go in the body's `errors` (the motion errors)"
                    .to_string(),
            ),
            Problem::FourierOnPrismatic { body } => D::new(
                "chain::fourier_on_prismatic",
                "prismatic joint",
                format!("a fourier basis needs a rotary joint, but body `{body}` is prismatic"),
            )
            .help(
                "along a linear axis use `powers`, `basis: legendre` or `basis: chebyshev` over \
                 the axis range"
                    .to_string(),
            ),
            Problem::MissingRange { basis } => D::new(
                "chain::missing_range",
                "no range",
                format!("a {basis} basis needs `range: [lo, hi]`"),
            )
            .help(
                "the range is mapped onto [-1, 1]: t = (2q - lo - hi) / (hi - lo); give the \
                 axis travel"
                    .to_string(),
            ),
            Problem::RangeOrder { lo, hi } => D::new(
                "chain::range_order",
                "empty range",
                format!("a basis range `[lo, hi]` needs lo < hi, got lo = {lo}, hi = {hi}"),
            ),
            Problem::BadOrder { what, value } => D::new(
                "chain::bad_order",
                "out of range",
                format!(
                    "{what} must be a whole number from 0 to {}, got {value}",
                    crate::load::MAX_ORDER
                ),
            ),
            Problem::DuplicatePower { power, first } => D::new(
                "chain::duplicate_power",
                "duplicate power",
                format!("power {power} is listed twice (first as item {first})"),
            )
            .help("each power has one coefficient; list it once".to_string()),
            Problem::FromAboveDegree { from, degree } => D::new(
                "chain::from_above_degree",
                "out of range",
                format!("`from` ({from}) is above `degree` ({degree})"),
            )
            .note("the coefficients are k = from..degree".to_string()),
            Problem::KeyNotForBasis { key, basis } => D::new(
                "chain::key_not_for_basis",
                "not for this basis",
                format!("`{key}` does not apply to a {basis} basis"),
            )
            .note(basis_keys(basis)),
            Problem::MissingBasis => D::new(
                "chain::missing_basis",
                "no basis",
                "a function slot needs `powers: [..]` or `basis: legendre | chebyshev | fourier`",
            ),
            Problem::PowersAsBasis => D::new(
                "chain::unknown_value",
                "unknown value",
                "unknown basis `powers`",
            )
            .help("the power basis is written `powers: [1, 2]`, without `basis`".to_string()),
            Problem::FunctionRedeclared {
                name,
                difference,
                first,
            } => D::new(
                "chain::function_redeclared",
                "redeclared",
                format!("function `{name}` is declared again {difference}"),
            )
            .note(format!("first declared {first}"))
            .help(
                "a function declared twice must be the same function: same basis, same axis, \
                 same kind of slot; otherwise give it another name"
                    .to_string(),
            ),
            Problem::FunctionClash { what, other } => D::new(
                "chain::name_collision",
                "name collision",
                format!("{what} has the same name as {other}"),
            )
            .help(
                "a function `F`'s coefficients are error parameters named `F_<k>`; variables, \
                 parameters, error parameters, functions and coefficients share one namespace"
                    .to_string(),
            ),
            Problem::FunctionStatistics { name, coefficients } => D::new(
                "chain::unknown_error",
                "function",
                format!(
                    "statistics for `{name}`, a function slot, not an error parameter"
                ),
            )
            .note(coefficients.first().map(|c| format!("did you mean `{c}`?")))
            .help(format!(
                "statistics go on the coefficients of `{name}`: {}",
                coefficients.join(", ")
            )),
            Problem::IsoWithoutJoint { body } => D::new(
                "chain::iso_without_joint",
                "no joint",
                format!(
                    "`errors: iso` names the errors after the joint variable, but body `{body}` has no joint"
                ),
            )
            .help("give the body a `joint`, or name its errors slot by slot".to_string()),
            Problem::ErrorsScalar { found, suggestion } => D::new(
                "chain::errors_value",
                "unknown value",
                format!("`errors` must be a mapping of slots or `iso`, found `{found}`"),
            )
            .note(did_you_mean(suggestion)),
            Problem::IsoNotAllowed { group } => D::new(
                "chain::iso_not_allowed",
                "not here",
                format!("`{group}` cannot be `iso`"),
            )
            .help(
                "`iso` names the six motion errors of a joint and is written `errors: iso`"
                    .to_string(),
            ),
            Problem::IsoClash { name, body, other } => D::new(
                "chain::iso_clash",
                "name collision",
                format!(
                    "`errors: iso` of body `{body}` names `{name}`, as does `errors: iso` of body `{other}`"
                ),
            )
            .help(
                "the two joint variables upper-case alike; rename one, or name the errors slot \
                 by slot"
                    .to_string(),
            ),
            Problem::Values(p) => p.describe(),
            Problem::Csv(p) => p.describe(),
            Problem::Settings(p) => p.describe(),
            Problem::Measurements(p) => p.describe(),
            Problem::Positioning(p) => p.describe(),
            Problem::Drift(p) => p.describe(),
            Problem::Circular(p) => p.describe(),
            Problem::Foreign(p) => p.0.describe(),
        }
    }

    /// The problem of a crate outside chain-core, worded by its own
    /// [`Describe`].
    pub fn foreign(problem: impl Describe) -> Problem {
        Problem::Foreign(Foreign(Arc::new(problem)))
    }

    /// The main message, without the parenthesised note
    /// ([`Description::headline`]).
    pub fn headline(&self) -> String {
        self.describe().headline
    }

    /// The parenthesised note that follows the headline (and the key), if any
    /// ([`Description::note`]).
    pub fn note(&self) -> Option<String> {
        self.describe().note
    }

    /// A longer hint for the reader, if one helps ([`Description::help`]).
    pub fn help(&self) -> Option<String> {
        self.describe().help
    }

    /// A short label for the span in a rendered snippet
    /// ([`Description::label`]).
    pub fn label(&self) -> &'static str {
        self.describe().label
    }

    /// A stable machine-readable code, e.g. `chain::unknown_key`
    /// ([`Description::code`]).
    pub fn code(&self) -> &'static str {
        self.describe().code
    }
}

/// The note of a parameter in a divisor or under a negative power.
const POLYNOMIALS: &str = "the derivation needs polynomials in the parameters";

/// The note of a key that does not apply to a basis: the keys it takes.
fn basis_keys(basis: &str) -> String {
    let keys = match basis {
        "powers" => "name, powers",
        "fourier" => "name, basis, harmonics",
        _ => "name, basis, degree, range, from",
    };
    format!("a {basis} basis takes {keys}")
}

/// The note of an unknown key or value: the closest valid one, then all.
fn alternatives(expected: &[&str], suggestion: &Option<String>) -> String {
    match did_you_mean(suggestion) {
        Some(s) => format!("{s} {}", one_of(expected)),
        None => one_of(expected),
    }
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.headline())?;
        if let Some(note) = self.note() {
            write!(f, " ({note})")?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_description_gives_every_part() {
        let p = Problem::UnknownKey {
            key: "tolerence".into(),
            expected: &["tolerance", "grid"],
            suggestion: Some("tolerance".into()),
        };
        assert_eq!(
            p.describe(),
            Description {
                headline: "unknown key `tolerence`".into(),
                note: Some("did you mean `tolerance`? expected one of tolerance, grid".into()),
                help: None,
                label: "unknown key",
                code: "chain::unknown_key",
            }
        );
        assert_eq!(
            p.to_string(),
            "unknown key `tolerence` (did you mean `tolerance`? expected one of tolerance, grid)"
        );
        let c = Problem::Conflict {
            first: "std",
            second: "tolerance",
        };
        assert_eq!(
            c.help().as_deref(),
            Some("std = tolerance / sigma_rule; give one of them")
        );
        let m = Problem::from(SettingsProblem::UnknownName {
            name: "x".into(),
            generator: "g".into(),
            within: "`values`",
            names: vec!["y".into(), "z".into()],
            suggestion: Some("y".into()),
        });
        let d = m.describe();
        assert_eq!(
            d.headline,
            "`x` is not a parameter or variable of the generator `g` (did you mean `y`?)"
        );
        assert_eq!(d.note, None);
        assert_eq!(
            d.help.as_deref(),
            Some("`values` names the generator's parameters and variables: y, z")
        );
        assert_eq!(
            (d.label, d.code),
            ("unknown name", "chain::settings::unknown_name")
        );
    }
}
