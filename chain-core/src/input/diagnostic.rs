//! Located diagnostics for machine files and the settings files of `chain
//! motion`.
//!
//! Every rule of the machine-file contract that a file can break has one
//! [`Problem`] variant, and its wording lives here and nowhere else: the YAML
//! loader ([`crate::load`]) attaches a problem to an [`Origin`] (file, line,
//! column, key path) to make a [`LoadError`], and the `machine!` macro can
//! attach the same problem to a token span, so both front ends say the same
//! thing about the same mistake. The settings loader ([`crate::settings`])
//! reads the same located tree and reports through the same types: the
//! shared rules (unknown key, wrong type, ...) with their variants, its own
//! rules (names of its two machines, angles, the roll) as a
//! [`Problem::Message`] that it words itself.
//!
//! [`Diagnostics`] is the error type of [`crate::load_str`], of
//! [`crate::settings::load_settings_str`] and their friends: a non-empty list
//! of [`LoadError`]s for one file. Its `Display` names the file,
//! line, column and key of the first error on its own; through
//! [`miette::Diagnostic`] it also carries the file text (labels at the spans)
//! and the remaining errors as `related()` diagnostics.

use std::fmt;

#[cfg(feature = "miette")]
use miette::{LabeledSpan, NamedSource, SourceCode};

use crate::model::{ErrorKind, Origin};

/// One thing wrong with a machine description (or a settings file),
/// independent of where it is.
///
/// `Display` gives the full message (headline plus the parenthesised note);
/// [`Problem::headline`], [`Problem::note`], [`Problem::help`],
/// [`Problem::label`] and [`Problem::code`] give its parts.
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
    /// A rule of a settings file, worded by its reader.
    Message(Message),
}

/// A problem worded at run time by the reader of a file other than a machine
/// file (the settings of `chain motion`): the payload of [`Problem::Message`].
#[derive(Debug, Clone, PartialEq)]
pub struct Message {
    /// The headline.
    pub text: String,
    /// The closest valid name, if one is close: the headline ends with
    /// `(did you mean ...)`.
    pub suggestion: Option<String>,
    /// A longer hint, if one helps.
    pub help: Option<String>,
    /// The short label of the span.
    pub label: &'static str,
    /// A stable code, e.g. `chain::settings::unknown_name`.
    pub code: &'static str,
}

impl Message {
    /// `text`, with the span's `label` and a stable `code`.
    pub fn new(text: impl Into<String>, label: &'static str, code: &'static str) -> Message {
        Message {
            text: text.into(),
            suggestion: None,
            help: None,
            label,
            code,
        }
    }

    /// With a hint.
    pub fn help(mut self, help: impl Into<String>) -> Message {
        self.help = Some(help.into());
        self
    }

    /// With the closest valid name, if there is one.
    pub fn suggest(mut self, suggestion: Option<&str>) -> Message {
        self.suggestion = suggestion.map(str::to_string);
        self
    }
}

impl From<Message> for Problem {
    fn from(message: Message) -> Problem {
        Problem::Message(message)
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

impl Problem {
    /// The main message, without the parenthesised note.
    pub fn headline(&self) -> String {
        match self {
            Problem::Io { message } => format!("cannot read the file: {message}"),
            Problem::TooLarge { limit } => {
                format!("the file is too large (more than {limit} bytes)")
            }
            Problem::Binary { offset } => {
                format!("not a text file (NUL byte at byte offset {offset})")
            }
            Problem::InvalidUtf8 { offset } => {
                format!("the file is not valid UTF-8 (invalid byte at byte offset {offset})")
            }
            Problem::Empty => "the machine file is empty".into(),
            Problem::Syntax { message } => format!("YAML syntax error: {message}"),
            Problem::MultipleDocuments => "more than one YAML document in the file".into(),
            Problem::TooDeep { limit } => format!("nested more than {limit} levels deep"),
            Problem::AliasLimit { limit } => {
                format!("the file expands to more than {limit} YAML nodes")
            }
            Problem::RecursiveAlias => "an alias refers to a collection that contains it".into(),
            Problem::NonScalarKey => "a mapping key must be a plain name".into(),
            Problem::DuplicateKey { key, first_line } => {
                format!("duplicate key `{key}` (first given on line {first_line})")
            }
            Problem::TopLevelNotMapping { found } => {
                format!("the top level must be a mapping, found {found}")
            }
            Problem::WrongType { expected, found } => format!("expected {expected}, found {found}"),
            Problem::UnknownKey { key, .. } => format!("unknown key `{key}`"),
            Problem::MissingKey { key } => format!("missing required key `{key}`"),
            Problem::InvalidName { name, what } => format!("`{name}` is not a valid {what} name"),
            Problem::ReservedName { name } => {
                format!("`{name}` is reserved by the expression language")
            }
            Problem::UnknownValue { what, found, .. } => format!("unknown {what} `{found}`"),
            Problem::NoBodies => "`bodies` is empty".into(),
            Problem::UnknownBody { role, name, .. } => {
                format!("{role} `{name}` is not a body of this machine")
            }
            Problem::Cycle { bodies } => {
                let path: Vec<String> = bodies.iter().map(|b| format!("`{b}`")).collect();
                format!("the parent links form a cycle: {}", path.join(" -> "))
            }
            Problem::SecondRoot { first, second } => format!(
                "`{second}` is a second root body: both `{first}` and `{second}` have no parent"
            ),
            Problem::NoRoot => "no root body: every body has a parent".into(),
            Problem::WorkpieceIsTool { name } => {
                format!("the workpiece and the tool are the same body `{name}`")
            }
            Problem::DuplicateVariable { name, body } => {
                format!("variable `{name}` already drives the joint of body `{body}`")
            }
            Problem::NameCollision { name, what, other } => {
                format!("{what} `{name}` has the same name as a {other}")
            }
            Problem::UnknownName { name, .. } => {
                format!("unknown name `{name}`: not a declared parameter")
            }
            Problem::Expression { message } => format!("cannot parse the expression: {message}"),
            Problem::ParameterInDivisor { name } => format!("parameter `{name}` is in a divisor"),
            Problem::NegativePowerOfParameter { name } => {
                format!("parameter `{name}` is raised to a negative power")
            }
            Problem::NameInNumber { name } => {
                format!("`{name}` is a name, but only numbers are allowed here")
            }
            Problem::NotPositive { what, value } => {
                format!("{what} must be positive and finite, got {value}")
            }
            Problem::NotFinite { what } => format!("{what} must be finite"),
            Problem::OutOfRange { what, value, range } => {
                format!("{what} must be in {range}, got {value}")
            }
            Problem::UniformBounds { min, max } => {
                format!("a uniform distribution needs min < max, got min = {min}, max = {max}")
            }
            Problem::Conflict { first, second } => {
                format!("`{first}` and `{second}` cannot both be given")
            }
            Problem::MissingSpread { dist } => {
                if *dist == "uniform" {
                    "a uniform distribution needs `min` and `max`, or `std` or `tolerance`".into()
                } else {
                    format!("a {dist} distribution needs `std` or `tolerance`")
                }
            }
            Problem::KeyNotForDistribution { key, dist } => {
                format!("`{key}` does not apply to a {dist} distribution")
            }
            Problem::UnknownError { name, .. } => {
                format!("statistics for `{name}`, but no body uses an error parameter of that name")
            }
            Problem::ErrorKindConflict {
                name,
                first,
                second,
                first_line,
            } => format!(
                "error `{name}` is used as {} here but as {} on line {first_line}",
                kind_name(*second),
                kind_name(*first)
            ),
            Problem::UnknownVariable { name, .. } => {
                format!("`{name}` is not an axis variable of this machine")
            }
            Problem::EmptyList { what } => format!("{what} must not be empty"),
            Problem::WrongLength { expected, found } => {
                format!("expected a list of {expected} items, found {found}")
            }
            Problem::Message(m) => match did_you_mean(&m.suggestion) {
                Some(s) => format!("{} ({s})", m.text),
                None => m.text.clone(),
            },
        }
    }

    /// The parenthesised note that follows the headline (and the key), if any:
    /// the valid alternatives or the closest one.
    pub fn note(&self) -> Option<String> {
        match self {
            Problem::UnknownKey {
                expected,
                suggestion,
                ..
            }
            | Problem::UnknownValue {
                expected,
                suggestion,
                ..
            } => Some(match did_you_mean(suggestion) {
                Some(s) => format!("{s} {}", one_of(expected)),
                None => one_of(expected),
            }),
            Problem::UnknownBody { suggestion, .. }
            | Problem::UnknownError { suggestion, .. }
            | Problem::UnknownVariable { suggestion, .. } => did_you_mean(suggestion),
            Problem::UnknownName { hint, .. } => hint.clone(),
            Problem::InvalidName { .. } => {
                Some("use letters, digits and `_`, starting with a letter or `_`".into())
            }
            Problem::ReservedName { .. } => Some("pi, sin and cos are reserved".into()),
            Problem::ParameterInDivisor { .. } | Problem::NegativePowerOfParameter { .. } => {
                Some("the derivation needs polynomials in the parameters".into())
            }
            Problem::AliasLimit { .. } => {
                Some("each use of an alias counts its whole anchor; an alias bomb?".into())
            }
            Problem::MultipleDocuments => Some("a machine file holds exactly one".into()),
            Problem::Empty => {
                Some("expected a mapping with at least `machine` and `bodies`".into())
            }
            _ => None,
        }
    }

    /// A longer hint for the reader, if one helps.
    pub fn help(&self) -> Option<String> {
        match self {
            Problem::SecondRoot { second, .. } => Some(format!(
                "give `{second}` a `parent`; exactly one body (the bed) has none"
            )),
            Problem::NoRoot | Problem::Cycle { .. } => {
                Some("exactly one body (the bed) has no `parent`".into())
            }
            Problem::UnknownName { .. } => {
                Some("declare it under `parameters` (null makes it symbolic)".into())
            }
            Problem::Conflict { first, second } if *first == "std" && *second == "tolerance" => {
                Some("std = tolerance / sigma_rule; give one of them".into())
            }
            Problem::UnknownError { .. } => {
                Some("statistics entries are keyed by error names used in the bodies".into())
            }
            Problem::NameCollision { .. } => Some(
                "variables, parameters and error parameters share one namespace in the model"
                    .into(),
            ),
            Problem::Message(m) => m.help.clone(),
            _ => None,
        }
    }

    /// A short label for the span in a rendered snippet.
    pub fn label(&self) -> &'static str {
        match self {
            Problem::Io { .. } | Problem::TooLarge { .. } => "file",
            Problem::Binary { .. } => "NUL byte",
            Problem::InvalidUtf8 { .. } => "invalid UTF-8",
            Problem::Empty => "empty",
            Problem::Syntax { .. } => "syntax error",
            Problem::MultipleDocuments => "second document",
            Problem::TooDeep { .. } => "too deep",
            Problem::AliasLimit { .. } | Problem::RecursiveAlias => "alias",
            Problem::NonScalarKey => "not a name",
            Problem::DuplicateKey { .. } => "duplicate key",
            Problem::TopLevelNotMapping { .. } | Problem::WrongType { .. } => "wrong type",
            Problem::UnknownKey { .. } => "unknown key",
            Problem::MissingKey { .. } => "missing key",
            Problem::InvalidName { .. } | Problem::ReservedName { .. } => "invalid name",
            Problem::UnknownValue { .. } => "unknown value",
            Problem::NoBodies => "no bodies",
            Problem::UnknownBody { .. } => "unknown body",
            Problem::Cycle { .. } => "cycle",
            Problem::SecondRoot { .. } | Problem::NoRoot => "root",
            Problem::WorkpieceIsTool { .. } => "same body",
            Problem::DuplicateVariable { .. } => "duplicate variable",
            Problem::NameCollision { .. } => "name collision",
            Problem::UnknownName { .. } => "unknown name",
            Problem::Expression { .. } => "here",
            Problem::ParameterInDivisor { .. } | Problem::NegativePowerOfParameter { .. } => {
                "parameter"
            }
            Problem::NameInNumber { .. } => "not a number",
            Problem::NotPositive { .. }
            | Problem::NotFinite { .. }
            | Problem::OutOfRange { .. }
            | Problem::UniformBounds { .. } => "out of range",
            Problem::Conflict { .. } => "conflicting key",
            Problem::MissingSpread { .. } => "no spread",
            Problem::KeyNotForDistribution { .. } => "not for this distribution",
            Problem::UnknownError { .. } => "unknown error",
            Problem::ErrorKindConflict { .. } => "kind conflict",
            Problem::UnknownVariable { .. } => "unknown variable",
            Problem::EmptyList { .. } => "empty",
            Problem::WrongLength { .. } => "wrong length",
            Problem::Message(m) => m.label,
        }
    }

    /// A stable machine-readable code, e.g. `chain::unknown_key`.
    pub fn code(&self) -> &'static str {
        match self {
            Problem::Io { .. } => "chain::io",
            Problem::TooLarge { .. } => "chain::too_large",
            Problem::Binary { .. } => "chain::binary",
            Problem::InvalidUtf8 { .. } => "chain::invalid_utf8",
            Problem::Empty => "chain::empty",
            Problem::Syntax { .. } => "chain::yaml_syntax",
            Problem::MultipleDocuments => "chain::multiple_documents",
            Problem::TooDeep { .. } => "chain::too_deep",
            Problem::AliasLimit { .. } => "chain::alias_limit",
            Problem::RecursiveAlias => "chain::recursive_alias",
            Problem::NonScalarKey => "chain::non_scalar_key",
            Problem::DuplicateKey { .. } => "chain::duplicate_key",
            Problem::TopLevelNotMapping { .. } => "chain::top_level",
            Problem::WrongType { .. } => "chain::wrong_type",
            Problem::UnknownKey { .. } => "chain::unknown_key",
            Problem::MissingKey { .. } => "chain::missing_key",
            Problem::InvalidName { .. } => "chain::invalid_name",
            Problem::ReservedName { .. } => "chain::reserved_name",
            Problem::UnknownValue { .. } => "chain::unknown_value",
            Problem::NoBodies => "chain::no_bodies",
            Problem::UnknownBody { .. } => "chain::unknown_body",
            Problem::Cycle { .. } => "chain::cycle",
            Problem::SecondRoot { .. } => "chain::second_root",
            Problem::NoRoot => "chain::no_root",
            Problem::WorkpieceIsTool { .. } => "chain::workpiece_is_tool",
            Problem::DuplicateVariable { .. } => "chain::duplicate_variable",
            Problem::NameCollision { .. } => "chain::name_collision",
            Problem::UnknownName { .. } => "chain::unknown_name",
            Problem::Expression { .. } => "chain::expression",
            Problem::ParameterInDivisor { .. } => "chain::parameter_in_divisor",
            Problem::NegativePowerOfParameter { .. } => "chain::negative_power",
            Problem::NameInNumber { .. } => "chain::name_in_number",
            Problem::NotPositive { .. } => "chain::not_positive",
            Problem::NotFinite { .. } => "chain::not_finite",
            Problem::OutOfRange { .. } => "chain::out_of_range",
            Problem::UniformBounds { .. } => "chain::uniform_bounds",
            Problem::Conflict { .. } => "chain::conflicting_keys",
            Problem::MissingSpread { .. } => "chain::missing_spread",
            Problem::KeyNotForDistribution { .. } => "chain::key_not_for_distribution",
            Problem::UnknownError { .. } => "chain::unknown_error",
            Problem::ErrorKindConflict { .. } => "chain::error_kind_conflict",
            Problem::UnknownVariable { .. } => "chain::unknown_variable",
            Problem::EmptyList { .. } => "chain::empty_list",
            Problem::WrongLength { .. } => "chain::wrong_length",
            Problem::Message(m) => m.code,
        }
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

/// The closest candidate to `name` by edit distance, if it is close enough to
/// be a plausible typo (at most a third of the longer name's length, and at
/// least one edit is always allowed; a case-only difference always matches).
/// Failing that, a candidate of at least three characters that is a prefix of
/// `name` (`minimum` → `min`) or that `name` is a prefix of.
pub fn closest<'a, I>(name: &str, candidates: I) -> Option<&'a str>
where
    I: IntoIterator<Item = &'a str>,
{
    let lower = name.to_lowercase();
    let mut best: Option<(usize, &'a str)> = None;
    let mut prefixed: Option<&'a str> = None;
    for cand in candidates {
        if cand == name {
            continue;
        }
        let cl = cand.to_lowercase();
        let d = if cl == lower {
            0
        } else {
            edit_distance(&lower, &cl)
        };
        let longest = name.chars().count().max(cand.chars().count());
        let allowed = (longest / 3).max(1);
        if d <= allowed && best.is_none_or(|(bd, _)| d < bd) {
            best = Some((d, cand));
        }
        let shortest = name.chars().count().min(cand.chars().count());
        if prefixed.is_none() && shortest >= 3 && (lower.starts_with(&cl) || cl.starts_with(&lower))
        {
            prefixed = Some(cand);
        }
    }
    best.map(|(_, c)| c).or(prefixed)
}

/// Optimal-string-alignment distance (Levenshtein plus adjacent transpositions).
fn edit_distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().collect();
    let b: Vec<char> = b.chars().collect();
    let n = b.len();
    let mut prev2 = vec![0usize; n + 1];
    let mut prev: Vec<usize> = (0..=n).collect();
    let mut cur = vec![0usize; n + 1];
    for (i, &ca) in a.iter().enumerate() {
        cur[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let cost = usize::from(ca != cb);
            let mut v = (prev[j] + cost).min(prev[j + 1] + 1).min(cur[j] + 1);
            if i > 0 && j > 0 && a.get(i - 1) == Some(&cb) && b.get(j - 1) == Some(&ca) {
                v = v.min(prev2[j - 1] + 1);
            }
            cur[j + 1] = v;
        }
        std::mem::swap(&mut prev2, &mut prev);
        std::mem::swap(&mut prev, &mut cur);
    }
    prev[n]
}

/// One located error in a machine file (or settings file).
#[derive(Debug, Clone, PartialEq)]
pub struct LoadError {
    /// The file name as given to the loader.
    pub file: String,
    /// Where: byte span, line, column and key path. A `line` of 0 means the
    /// error concerns the file as a whole (it could not be read).
    pub origin: Origin,
    /// What is wrong.
    pub problem: Problem,
}

impl LoadError {
    /// A located error.
    pub fn new(file: impl Into<String>, origin: Origin, problem: Problem) -> LoadError {
        LoadError {
            file: file.into(),
            origin,
            problem,
        }
    }

    #[cfg(feature = "miette")]
    fn label(&self, source_len: usize) -> Option<LabeledSpan> {
        if self.origin.line == 0 {
            return None;
        }
        let offset = self.origin.offset.min(source_len);
        let len = self.origin.len.min(source_len - offset);
        Some(LabeledSpan::new_with_span(
            Some(self.problem.label().to_string()),
            (offset, len),
        ))
    }
}

impl fmt::Display for LoadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:", self.file)?;
        if self.origin.line > 0 {
            write!(f, "{}:{}:", self.origin.line, self.origin.column)?;
        }
        write!(f, " {}", self.problem.headline())?;
        if !self.origin.key.is_empty() {
            write!(f, " at key `{}`", self.origin.key)?;
        }
        if let Some(note) = self.problem.note() {
            write!(f, " ({note})")?;
        }
        Ok(())
    }
}

impl std::error::Error for LoadError {}

#[cfg(feature = "miette")]
impl miette::Diagnostic for LoadError {
    fn code<'a>(&'a self) -> Option<Box<dyn fmt::Display + 'a>> {
        Some(Box::new(self.problem.code()))
    }

    fn help<'a>(&'a self) -> Option<Box<dyn fmt::Display + 'a>> {
        self.problem
            .help()
            .map(|h| Box::new(h) as Box<dyn fmt::Display>)
    }

    fn labels(&self) -> Option<Box<dyn Iterator<Item = LabeledSpan> + '_>> {
        // Related errors render against the parent's source; without it we
        // cannot know the length, so the caller (`Diagnostics`) clamps.
        self.label(usize::MAX)
            .map(|l| Box::new(std::iter::once(l)) as Box<dyn Iterator<Item = LabeledSpan>>)
    }
}

/// A related error rendered against the parent's source text, with its span
/// clamped to that text.
#[cfg_attr(not(feature = "miette"), allow(dead_code))]
#[derive(Debug, Clone)]
struct Related {
    error: LoadError,
    source_len: usize,
}

impl fmt::Display for Related {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.error.fmt(f)
    }
}

impl std::error::Error for Related {}

#[cfg(feature = "miette")]
impl miette::Diagnostic for Related {
    fn code<'b>(&'b self) -> Option<Box<dyn fmt::Display + 'b>> {
        self.error.code()
    }

    fn help<'b>(&'b self) -> Option<Box<dyn fmt::Display + 'b>> {
        self.error.help()
    }

    fn labels(&self) -> Option<Box<dyn Iterator<Item = LabeledSpan> + '_>> {
        if self.source_len == 0 {
            return None;
        }
        self.error
            .label(self.source_len)
            .map(|l| Box::new(std::iter::once(l)) as Box<dyn Iterator<Item = LabeledSpan>>)
    }
}

/// All errors found in one machine file (or settings file): never empty.
///
/// `Display` shows the first error (`file:line:column: message at key `k``)
/// followed by how many more there are; the alternate form (`{:#}`) lists every
/// error, one per line. As a [`miette::Diagnostic`] it renders the first error
/// with a labelled snippet of the file and the others as related diagnostics.
pub struct Diagnostics {
    // Boxed so that `Result<Machine, Diagnostics>` stays small.
    inner: Box<Inner>,
}

#[cfg_attr(not(feature = "miette"), allow(dead_code))]
struct Inner {
    file: String,
    #[cfg(feature = "miette")]
    source: NamedSource<String>,
    source_len: usize,
    errors: Vec<LoadError>,
    related: Vec<Related>,
}

impl fmt::Debug for Diagnostics {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Diagnostics")
            .field("errors", &self.inner.errors)
            .finish_non_exhaustive()
    }
}

impl Diagnostics {
    /// The diagnostics of `file` (whose text is `source`) from a list of
    /// errors; `None` if the list is empty. Errors are sorted by position
    /// (stable, so errors at one place keep their order).
    pub fn new(
        file: impl Into<String>,
        source: impl Into<String>,
        mut errors: Vec<LoadError>,
    ) -> Option<Diagnostics> {
        if errors.is_empty() {
            return None;
        }
        errors.sort_by_key(|e| (e.origin.line, e.origin.column));
        let file = file.into();
        let source = source.into();
        let source_len = source.len();
        let related = errors
            .iter()
            .skip(1)
            .map(|error| Related {
                error: error.clone(),
                source_len,
            })
            .collect();
        Some(Diagnostics {
            inner: Box::new(Inner {
                #[cfg(feature = "miette")]
                source: NamedSource::new(file.clone(), source).with_language("yaml"),
                file,
                source_len,
                errors,
                related,
            }),
        })
    }

    /// The diagnostics of `file` (whose text is `source`) from problems
    /// located in it; `None` if there are none.
    pub fn located(
        file: &str,
        source: impl Into<String>,
        problems: impl IntoIterator<Item = (Origin, Problem)>,
    ) -> Option<Diagnostics> {
        let errors = problems
            .into_iter()
            .map(|(origin, problem)| LoadError::new(file, origin, problem))
            .collect();
        Diagnostics::new(file, source, errors)
    }

    /// A single error.
    pub fn single(
        file: impl Into<String>,
        source: impl Into<String>,
        origin: Origin,
        problem: Problem,
    ) -> Diagnostics {
        let file = file.into();
        let error = LoadError::new(file.clone(), origin, problem);
        let source = source.into();
        let source_len = source.len();
        Diagnostics {
            inner: Box::new(Inner {
                #[cfg(feature = "miette")]
                source: NamedSource::new(file.clone(), source).with_language("yaml"),
                file,
                source_len,
                errors: vec![error],
                related: Vec::new(),
            }),
        }
    }

    /// The file name.
    pub fn file(&self) -> &str {
        &self.inner.file
    }

    /// The errors, in source order.
    pub fn errors(&self) -> &[LoadError] {
        &self.inner.errors
    }

    /// Iterates over the errors in source order.
    pub fn iter(&self) -> std::slice::Iter<'_, LoadError> {
        self.inner.errors.iter()
    }

    /// The first error.
    pub fn first(&self) -> &LoadError {
        // `errors` is never empty by construction; fall back defensively.
        &self.inner.errors[0]
    }

    /// The number of errors (at least 1).
    pub fn len(&self) -> usize {
        self.inner.errors.len()
    }

    /// Always false: a `Diagnostics` holds at least one error.
    pub fn is_empty(&self) -> bool {
        self.inner.errors.is_empty()
    }
}

impl<'a> IntoIterator for &'a Diagnostics {
    type Item = &'a LoadError;
    type IntoIter = std::slice::Iter<'a, LoadError>;

    fn into_iter(self) -> Self::IntoIter {
        self.inner.errors.iter()
    }
}

impl fmt::Display for Diagnostics {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if f.alternate() {
            for (i, e) in self.inner.errors.iter().enumerate() {
                if i > 0 {
                    writeln!(f)?;
                }
                write!(f, "{e}")?;
            }
            return Ok(());
        }
        write!(f, "{}", self.first())?;
        match self.inner.errors.len() {
            0 | 1 => Ok(()),
            2 => write!(f, " (and 1 more error)"),
            n => write!(f, " (and {} more errors)", n - 1),
        }
    }
}

impl std::error::Error for Diagnostics {}

#[cfg(feature = "miette")]
impl miette::Diagnostic for Diagnostics {
    fn code<'a>(&'a self) -> Option<Box<dyn fmt::Display + 'a>> {
        self.first().code()
    }

    fn help<'a>(&'a self) -> Option<Box<dyn fmt::Display + 'a>> {
        self.first().help()
    }

    fn source_code(&self) -> Option<&dyn SourceCode> {
        if self.inner.source_len == 0 {
            None
        } else {
            Some(&self.inner.source)
        }
    }

    fn labels(&self) -> Option<Box<dyn Iterator<Item = LabeledSpan> + '_>> {
        if self.inner.source_len == 0 {
            return None;
        }
        self.first()
            .label(self.inner.source_len)
            .map(|l| Box::new(std::iter::once(l)) as Box<dyn Iterator<Item = LabeledSpan>>)
    }

    fn related<'a>(&'a self) -> Option<Box<dyn Iterator<Item = &'a dyn miette::Diagnostic> + 'a>> {
        if self.inner.related.is_empty() {
            return None;
        }
        Some(Box::new(
            self.inner
                .related
                .iter()
                .map(|r| r as &dyn miette::Diagnostic),
        ))
    }
}
