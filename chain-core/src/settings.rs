//! `SETTINGS.yaml`: the machine settings of a generating machine and the roll
//! that `chain motion` converts into CNC axis motions (see `docs/motion.md`).
//!
//! ```yaml
//! settings: seed002_concave             # identifier
//! description: pinion concave flank     # optional
//! generator: ../machines/cradle_generator.yaml   # optional (default: the built-in cradle generator)
//! values:                               # every generator parameter and held variable
//!   S_d: 145.6695                       # numbers or arithmetic (mm)
//!   gamma_m: -2.00deg                   # angles: radians, `<n>deg` or `D°M′S″`
//!   j: "-115°39′"
//! roll:
//!   omega_c: 2deg                       # cradle angular velocity, per second (> 0)
//!   interval: [-4, 4]                   # roll interval [t0, t1], seconds
//!   drive:                              # the generator variables that move:
//!     q: {start: "112°12′", ratio: 1}   #   v(t) = start + ratio · omega_c · t
//!     phi_p: {start: 0, ratio: 6.33912}
//! cnc:                                  # optional
//!   machine: ../machines/cnc5_bevel.yaml  # optional (the CLI's FILE takes precedence)
//!   parameters: {L: 200}                # values of the CNC machine's parameters
//!   match: pose                         # pose (default) | point_axis
//!   fix: {mu: 0}                        # point_axis only: CNC variables held
//!   start: {B: 0}                       # initial guess at t = 0 (picks the branch)
//! ```
//!
//! Loading is in two steps, both with located errors (file, line, column,
//! key) on the located YAML tree of [`crate::yaml`]: [`load_settings_str`] /
//! [`load_settings_file`] check the shape of the file, then
//! [`Settings::bind`] checks the names and kinds against the two machines
//! (every generator parameter and variable has exactly one value, angle units
//! only on rotary variables, CNC names exist) and produces the
//! [`MotionSpec`] that [`crate::motion::Motion`] runs.

use std::fmt;
use std::io::Read;
use std::path::{Path, PathBuf};

use miette::{LabeledSpan, NamedSource, SourceCode};

use crate::diagnostic::{closest, Diagnostics, Problem};
use crate::expr;
use crate::model::{JointKind, Machine, Origin};
use crate::motion::{Law, Matching, MotionSpec};
use crate::yaml::{self, Node, Span};

/// Keys allowed at the top level of a settings file.
pub const TOP_KEYS: &[&str] = &[
    "settings",
    "description",
    "generator",
    "values",
    "roll",
    "cnc",
];
/// Keys of `roll`.
pub const ROLL_KEYS: &[&str] = &["omega_c", "interval", "drive"];
/// Keys of one `roll.drive` entry.
pub const DRIVE_KEYS: &[&str] = &["start", "ratio"];
/// Keys of `cnc`.
pub const CNC_KEYS: &[&str] = &["machine", "parameters", "match", "fix", "start"];
/// Values of `cnc.match`.
pub const MATCH_VALUES: &[&str] = &["pose", "point_axis"];

/// The text of `examples/machines/cradle_generator.yaml`, the generator used
/// when a settings file names none.
pub const BUILTIN_GENERATOR: &str = include_str!("../../examples/machines/cradle_generator.yaml");

/// The file name under which the built-in generator is reported.
pub const BUILTIN_GENERATOR_NAME: &str = "cradle_generator.yaml (built-in)";

/// Settings files larger than this are refused.
pub const MAX_SETTINGS_BYTES: usize = 1024 * 1024;

// ---------------------------------------------------------------------------
// Diagnostics

/// One located problem of a settings file.
#[derive(Debug, Clone, PartialEq)]
pub struct Issue {
    /// Where (line 0: the file as a whole) and the dotted key path.
    pub origin: Origin,
    /// The message, without location.
    pub message: String,
    /// A short label for the span.
    pub label: &'static str,
    /// A hint, if one helps.
    pub help: Option<String>,
    /// A stable code, e.g. `chain::settings::unknown_name`.
    pub code: &'static str,
}

impl Issue {
    fn new(
        origin: Origin,
        message: impl Into<String>,
        label: &'static str,
        code: &'static str,
    ) -> Issue {
        Issue {
            origin,
            message: message.into(),
            label,
            help: None,
            code,
        }
    }

    fn with_help(mut self, help: impl Into<String>) -> Issue {
        self.help = Some(help.into());
        self
    }

    fn from_problem(origin: Origin, problem: &Problem) -> Issue {
        Issue {
            origin,
            message: problem.to_string(),
            label: problem.label(),
            help: problem.help(),
            code: problem.code(),
        }
    }

    fn render(&self, file: &str, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{file}:")?;
        if self.origin.line > 0 {
            write!(f, "{}:{}:", self.origin.line, self.origin.column)?;
        }
        write!(f, " {}", self.message)?;
        if !self.origin.key.is_empty() {
            write!(f, " at key `{}`", self.origin.key)?;
        }
        Ok(())
    }

    fn labeled(&self, source_len: usize) -> Option<LabeledSpan> {
        if self.origin.line == 0 || source_len == 0 {
            return None;
        }
        let offset = self.origin.offset.min(source_len);
        let len = self.origin.len.min(source_len - offset);
        Some(LabeledSpan::new_with_span(
            Some(self.label.to_string()),
            (offset, len),
        ))
    }
}

/// Every problem found in one settings file (never empty).
///
/// `Display` gives the first (`file:line:column: message at key `k``) and
/// how many more there are; `{:#}` lists them all. As a
/// [`miette::Diagnostic`] it carries the file text with a label at the span
/// and the other problems as related diagnostics.
pub struct SettingsError {
    // Boxed so that results stay small.
    inner: Box<ErrorInner>,
}

struct ErrorInner {
    file: String,
    source: NamedSource<String>,
    source_len: usize,
    issues: Vec<Issue>,
    related: Vec<RelatedIssue>,
}

impl SettingsError {
    fn new(file: &str, source: &str, mut issues: Vec<Issue>) -> SettingsError {
        issues.sort_by_key(|i| (i.origin.line, i.origin.column));
        let related = issues
            .iter()
            .skip(1)
            .map(|issue| RelatedIssue {
                file: file.to_string(),
                issue: issue.clone(),
                source_len: source.len(),
            })
            .collect();
        SettingsError {
            inner: Box::new(ErrorInner {
                file: file.to_string(),
                source: NamedSource::new(file, source.to_string()).with_language("yaml"),
                source_len: source.len(),
                issues,
                related,
            }),
        }
    }

    /// The file name as given.
    pub fn file(&self) -> &str {
        &self.inner.file
    }

    /// The problems, in source order.
    pub fn issues(&self) -> &[Issue] {
        &self.inner.issues
    }

    /// The first problem.
    pub fn first(&self) -> &Issue {
        &self.inner.issues[0]
    }
}

impl fmt::Debug for SettingsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("SettingsError")
            .field("file", &self.inner.file)
            .field("issues", &self.inner.issues)
            .finish_non_exhaustive()
    }
}

impl fmt::Display for SettingsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if f.alternate() {
            for (k, issue) in self.inner.issues.iter().enumerate() {
                if k > 0 {
                    writeln!(f)?;
                }
                issue.render(&self.inner.file, f)?;
            }
            return Ok(());
        }
        self.first().render(&self.inner.file, f)?;
        match self.inner.issues.len() {
            0 | 1 => Ok(()),
            2 => write!(f, " (and 1 more error)"),
            n => write!(f, " (and {} more errors)", n - 1),
        }
    }
}

impl std::error::Error for SettingsError {}

impl miette::Diagnostic for SettingsError {
    fn code<'a>(&'a self) -> Option<Box<dyn fmt::Display + 'a>> {
        Some(Box::new(self.first().code))
    }

    fn help<'a>(&'a self) -> Option<Box<dyn fmt::Display + 'a>> {
        self.first()
            .help
            .as_ref()
            .map(|h| Box::new(h.clone()) as Box<dyn fmt::Display>)
    }

    fn source_code(&self) -> Option<&dyn SourceCode> {
        (self.inner.source_len > 0).then_some(&self.inner.source as &dyn SourceCode)
    }

    fn labels(&self) -> Option<Box<dyn Iterator<Item = LabeledSpan> + '_>> {
        self.first()
            .labeled(self.inner.source_len)
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

#[derive(Debug, Clone)]
struct RelatedIssue {
    file: String,
    issue: Issue,
    source_len: usize,
}

impl fmt::Display for RelatedIssue {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.issue.render(&self.file, f)
    }
}

impl std::error::Error for RelatedIssue {}

impl miette::Diagnostic for RelatedIssue {
    fn code<'a>(&'a self) -> Option<Box<dyn fmt::Display + 'a>> {
        Some(Box::new(self.issue.code))
    }

    fn help<'a>(&'a self) -> Option<Box<dyn fmt::Display + 'a>> {
        self.issue
            .help
            .as_ref()
            .map(|h| Box::new(h.clone()) as Box<dyn fmt::Display>)
    }

    fn labels(&self) -> Option<Box<dyn Iterator<Item = LabeledSpan> + '_>> {
        self.issue
            .labeled(self.source_len)
            .map(|l| Box::new(std::iter::once(l)) as Box<dyn Iterator<Item = LabeledSpan>>)
    }
}

/// Why a machine named by a settings file could not be loaded.
#[derive(Debug, thiserror::Error, miette::Diagnostic)]
pub enum ReferenceError {
    /// The path in the settings file cannot be read (located in the settings
    /// file).
    #[error(transparent)]
    #[diagnostic(transparent)]
    Path(SettingsError),
    /// The machine file itself has errors (located in that file).
    #[error(transparent)]
    #[diagnostic(transparent)]
    Machine(Diagnostics),
}

// ---------------------------------------------------------------------------
// The file

/// A number as written in the file.
#[derive(Debug, Clone, PartialEq)]
pub struct Value {
    /// The value; radians when written as an angle.
    pub value: f64,
    /// True when written with angle units (`deg`, `°`).
    pub angle: bool,
    /// Where the value is.
    pub origin: Origin,
}

/// A `name: value` entry.
#[derive(Debug, Clone, PartialEq)]
pub struct Named {
    /// The name (the key).
    pub name: String,
    /// Where the key is.
    pub key: Origin,
    /// The value.
    pub value: Value,
}

/// One `roll.drive` entry: `v(t) = start + ratio · omega_c · t`.
#[derive(Debug, Clone, PartialEq)]
pub struct Drive {
    /// The generator variable.
    pub name: String,
    /// Where the key is.
    pub key: Origin,
    /// Its value at `t = 0` (default 0).
    pub start: Option<Value>,
    /// Its rate relative to `omega_c` (default 1).
    pub ratio: f64,
}

/// A validated settings file (shape and numbers; names are checked by
/// [`Settings::bind`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    /// The identifier (`settings:`).
    pub name: String,
    /// The description, if any.
    pub description: Option<String>,
    /// The file name as given to the loader.
    pub file: String,
    /// The file's text (for diagnostics of [`Settings::bind`]).
    pub source: String,
    /// Directory that relative paths are resolved against.
    pub base: PathBuf,
    /// `generator:` as written, with its origin.
    pub generator: Option<(String, Origin)>,
    /// `values:` entries, in file order.
    pub values: Vec<Named>,
    /// Where `values` is (or the top of the file when absent).
    pub values_origin: Origin,
    /// Cradle angular velocity, rad per unit time (> 0).
    pub omega_c: f64,
    /// Roll interval `[t0, t1]`, `t0 < t1`.
    pub interval: (f64, f64),
    /// `roll.drive` entries, in file order.
    pub drive: Vec<Drive>,
    /// Where `roll.drive` is.
    pub drive_origin: Origin,
    /// `cnc.machine` as written, with its origin.
    pub cnc_machine: Option<(String, Origin)>,
    /// `cnc.parameters`.
    pub cnc_parameters: Vec<Named>,
    /// `cnc.match`.
    pub matching: Matching,
    /// `cnc.fix`.
    pub fix: Vec<Named>,
    /// Where `cnc.fix` is.
    pub fix_origin: Option<Origin>,
    /// `cnc.start`.
    pub start: Vec<Named>,
}

/// Loads a settings file. `base` for relative paths is the file's directory.
pub fn load_settings_file(path: &Path) -> Result<Settings, SettingsError> {
    let file = path.display().to_string();
    let io = |message: String| {
        SettingsError::new(
            &file,
            "",
            vec![Issue::from_problem(
                Origin::default(),
                &Problem::Io { message },
            )],
        )
    };
    let handle = std::fs::File::open(path).map_err(|e| io(e.to_string()))?;
    let mut bytes = Vec::new();
    handle
        .take(MAX_SETTINGS_BYTES as u64 + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| io(e.to_string()))?;
    if bytes.len() > MAX_SETTINGS_BYTES {
        return Err(SettingsError::new(
            &file,
            "",
            vec![Issue::from_problem(
                Origin::default(),
                &Problem::TooLarge {
                    limit: MAX_SETTINGS_BYTES,
                },
            )],
        ));
    }
    let text = match String::from_utf8(bytes) {
        Ok(t) => t,
        Err(e) => {
            let offset = e.utf8_error().valid_up_to();
            return Err(SettingsError::new(
                &file,
                "",
                vec![Issue::from_problem(
                    Origin::default(),
                    &Problem::InvalidUtf8 { offset },
                )],
            ));
        }
    };
    let base = path
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from("."));
    load_settings_str(&text, &file, &base)
}

/// Loads settings from text; `file` names it in messages, `base` is the
/// directory relative paths are resolved against.
pub fn load_settings_str(text: &str, file: &str, base: &Path) -> Result<Settings, SettingsError> {
    if let Some(offset) = text.find('\0') {
        return Err(SettingsError::new(
            file,
            "",
            vec![Issue::from_problem(
                Origin::default(),
                &Problem::Binary { offset },
            )],
        ));
    }
    let parsed = yaml::parse(text);
    let mut r = Reader::default();
    for (span, key, problem) in &parsed.errors {
        r.issues
            .push(Issue::from_problem(span.origin(key.clone()), problem));
    }
    let settings = match &parsed.root {
        Some(root) if r.issues.is_empty() => r.settings(root, text, file, base),
        Some(_) => None,
        None => {
            if r.issues.is_empty() {
                r.issues.push(
                    Issue::new(
                        top_origin(""),
                        "the settings file is empty",
                        "empty",
                        "chain::settings::empty",
                    )
                    .with_help("expected a mapping with `settings`, `values` and `roll`"),
                );
            }
            None
        }
    };
    match settings {
        Some(s) if r.issues.is_empty() => Ok(s),
        _ => {
            if r.issues.is_empty() {
                r.issues.push(Issue::new(
                    top_origin(""),
                    "invalid settings file",
                    "here",
                    "chain::settings::invalid",
                ));
            }
            Err(SettingsError::new(file, text, r.issues))
        }
    }
}

fn top_origin(key: &str) -> Origin {
    Origin {
        offset: 0,
        len: 0,
        line: 1,
        column: 1,
        key: key.to_string(),
    }
}

fn join(path: &str, key: &str) -> String {
    if path.is_empty() {
        key.to_string()
    } else {
        format!("{path}.{key}")
    }
}

#[derive(Default)]
struct Reader {
    issues: Vec<Issue>,
    /// Valid keys suggested for unknown ones: a missing key that was
    /// suggested is probably misspelt, so it is not reported again.
    suggested: Vec<&'static str>,
}

impl Reader {
    fn problem(&mut self, span: Span, key: impl Into<String>, problem: Problem) {
        self.issues
            .push(Issue::from_problem(span.origin(key), &problem));
    }

    /// Reports a missing key, unless an unknown key looked like it.
    fn missing(&mut self, span: Span, path: &str, key: &'static str) {
        if !self.suggested.contains(&key) {
            self.problem(span, path, Problem::MissingKey { key });
        }
    }

    /// The entries of a mapping with keys in `allowed`; unknown keys are
    /// reported. `null` is an empty mapping.
    fn fields<'n>(
        &mut self,
        node: &'n Node,
        path: &str,
        allowed: &'static [&'static str],
    ) -> Option<Vec<(&'static str, &'n Node, &'n Node)>> {
        let entries = self.mapping(node, path)?;
        let mut out = Vec::new();
        for (k, v) in entries {
            let key = k.as_str().unwrap_or("");
            match allowed.iter().find(|a| **a == key) {
                Some(&known) => {
                    if !v.is_null() {
                        out.push((known, k, v));
                    }
                }
                None => {
                    let close = closest(key, allowed.iter().copied());
                    self.suggested.extend(close);
                    let suggestion = close.map(str::to_string);
                    self.problem(
                        k.span,
                        join(path, key),
                        Problem::UnknownKey {
                            key: key.to_string(),
                            expected: allowed,
                            suggestion,
                        },
                    );
                }
            }
        }
        Some(out)
    }

    fn mapping<'n>(&mut self, node: &'n Node, path: &str) -> Option<&'n [(Node, Node)]> {
        if node.is_null() {
            return Some(&[]);
        }
        match node.as_mapping() {
            Some(m) => Some(m),
            None => {
                self.problem(
                    node.span,
                    path,
                    Problem::WrongType {
                        expected: "a mapping",
                        found: node.describe(),
                    },
                );
                None
            }
        }
    }

    fn string(&mut self, node: &Node, path: &str, expected: &'static str) -> Option<String> {
        match node.as_scalar() {
            Some(s) if !s.is_null() && !s.text.trim().is_empty() => Some(s.text.clone()),
            _ => {
                self.problem(
                    node.span,
                    path,
                    Problem::WrongType {
                        expected,
                        found: node.describe(),
                    },
                );
                None
            }
        }
    }

    /// A number or an angle (`<expr>deg`, `D°M′S″`), finite.
    fn value(&mut self, node: &Node, path: &str) -> Option<Value> {
        let Some(text) = node
            .as_scalar()
            .filter(|s| !s.is_null())
            .map(|s| s.text.clone())
        else {
            self.problem(
                node.span,
                path,
                Problem::WrongType {
                    expected: "a number or an angle (`2.5deg`, `\"46°33′\"`)",
                    found: node.describe(),
                },
            );
            return None;
        };
        let origin = node.span.origin(path);
        let t = text.trim();
        if let Some(prefix) = t.strip_suffix("deg") {
            let v = self.expression(node, prefix, path)?.to_radians();
            return self.finite(node, path, v, true, origin);
        }
        if t.contains('°') {
            return match parse_dms(t) {
                Ok(deg) => self.finite(node, path, deg.to_radians(), true, origin),
                Err(message) => {
                    self.issues.push(
                        Issue::new(
                            origin,
                            format!("cannot read the angle `{t}`: {message}"),
                            "angle",
                            "chain::settings::angle",
                        )
                        .with_help("write degrees-minutes-seconds as \"-115°39′\" or \"12°30'15\\\"\", or degrees as -115.65deg"),
                    );
                    None
                }
            };
        }
        let special = match t.trim_start_matches(['+', '-']) {
            ".inf" | ".Inf" | ".INF" | "inf" | "infinity" | "Infinity" => Some(f64::INFINITY),
            ".nan" | ".NaN" | ".NAN" | "nan" | "NaN" => Some(f64::NAN),
            _ => None,
        };
        let v = match special {
            Some(v) => v,
            None => self.expression(node, &text, path)?,
        };
        self.finite(node, path, v, false, origin)
    }

    fn finite(
        &mut self,
        node: &Node,
        path: &str,
        v: f64,
        angle: bool,
        origin: Origin,
    ) -> Option<Value> {
        if v.is_finite() {
            Some(Value {
                value: v,
                angle,
                origin,
            })
        } else {
            self.problem(node.span, path, Problem::NotFinite { what: "the value" });
            None
        }
    }

    /// A numbers-only expression (`pi` allowed), errors located in `node`.
    fn expression(&mut self, node: &Node, text: &str, path: &str) -> Option<f64> {
        let ast = match expr::parse(text) {
            Ok(a) => a,
            Err(e) => {
                self.problem(
                    node.span_at(e.offset),
                    path,
                    Problem::Expression { message: e.message },
                );
                return None;
            }
        };
        match expr::eval_const(&ast) {
            Ok(v) => Some(v),
            Err(errs) => {
                for (offset, p) in errs {
                    self.problem(node.span_at(offset), path, p);
                }
                None
            }
        }
    }

    /// A plain number (no angle units).
    fn number(&mut self, node: &Node, path: &str) -> Option<f64> {
        let v = self.value(node, path)?;
        if v.angle {
            self.issues.push(Issue::new(
                v.origin,
                "expected a plain number here, found an angle",
                "angle",
                "chain::settings::angle_not_allowed",
            ));
            return None;
        }
        Some(v.value)
    }

    /// `name: value` entries.
    fn named(&mut self, node: &Node, path: &str) -> Vec<Named> {
        let Some(entries) = self.mapping(node, path) else {
            return Vec::new();
        };
        let mut out = Vec::new();
        for (k, v) in entries {
            let name = k.as_str().unwrap_or("").to_string();
            let key_path = join(path, &name);
            if let Some(value) = self.value(v, &key_path) {
                out.push(Named {
                    name,
                    key: k.span.origin(key_path),
                    value,
                });
            }
        }
        out
    }

    fn settings(&mut self, root: &Node, text: &str, file: &str, base: &Path) -> Option<Settings> {
        if root.as_mapping().is_none() {
            self.problem(
                root.span,
                "",
                Problem::TopLevelNotMapping {
                    found: root.describe(),
                },
            );
            return None;
        }
        let top = self.fields(root, "", TOP_KEYS)?;
        let get = |key: &str| {
            top.iter()
                .find(|(k, _, _)| *k == key)
                .map(|(_, k, v)| (*k, *v))
        };
        let missing = |r: &mut Reader, key: &'static str| r.missing(top_span(), "", key);

        let name = match get("settings") {
            Some((_, v)) => self.string(v, "settings", "a name"),
            None => {
                missing(self, "settings");
                None
            }
        };
        let description = match get("description") {
            Some((_, v)) => self.string(v, "description", "a string"),
            None => None,
        };
        let generator = match get("generator") {
            Some((_, v)) => self
                .string(v, "generator", "a file path")
                .map(|p| (p, v.span.origin("generator"))),
            None => None,
        };
        let (values, values_origin) = match get("values") {
            Some((k, v)) => (self.named(v, "values"), k.span.origin("values")),
            None => (Vec::new(), top_origin("values")),
        };
        let mut omega_c = None;
        let mut interval = None;
        let mut drive = Vec::new();
        let mut drive_origin = top_origin("roll.drive");
        match get("roll") {
            Some((k, v)) => {
                if let Some(roll) = self.fields(v, "roll", ROLL_KEYS) {
                    let rget = |key: &str| {
                        roll.iter()
                            .find(|(k, _, _)| *k == key)
                            .map(|(_, k, v)| (*k, *v))
                    };
                    match rget("omega_c") {
                        Some((_, n)) => {
                            if let Some(w) = self.value(n, "roll.omega_c") {
                                if w.value > 0.0 {
                                    omega_c = Some(w.value);
                                } else {
                                    self.problem(
                                        n.span,
                                        "roll.omega_c",
                                        Problem::NotPositive {
                                            what: "the cradle angular velocity omega_c",
                                            value: w.value,
                                        },
                                    );
                                }
                            }
                        }
                        None => self.missing(k.span, "roll", "omega_c"),
                    }
                    match rget("interval") {
                        Some((_, n)) => interval = self.interval(n),
                        None => self.missing(k.span, "roll", "interval"),
                    }
                    match rget("drive") {
                        Some((dk, n)) => {
                            drive_origin = dk.span.origin("roll.drive");
                            drive = self.drive(n);
                        }
                        None => self.missing(k.span, "roll", "drive"),
                    }
                }
            }
            None => missing(self, "roll"),
        }
        let mut cnc_machine = None;
        let mut cnc_parameters = Vec::new();
        let mut matching = Some(Matching::Pose);
        let mut fix = Vec::new();
        let mut fix_origin = None;
        let mut start = Vec::new();
        if let Some((_, v)) = get("cnc") {
            if let Some(cnc) = self.fields(v, "cnc", CNC_KEYS) {
                for (key, k, n) in cnc {
                    let path = join("cnc", key);
                    match key {
                        "machine" => {
                            cnc_machine = self
                                .string(n, &path, "a file path")
                                .map(|p| (p, n.span.origin(path.clone())));
                        }
                        "parameters" => cnc_parameters = self.named(n, &path),
                        "match" => {
                            matching = match self.string(n, &path, "`pose` or `point_axis`") {
                                Some(t) if t == "pose" => Some(Matching::Pose),
                                Some(t) if t == "point_axis" => Some(Matching::PointAxis),
                                Some(t) => {
                                    let suggestion = closest(&t, MATCH_VALUES.iter().copied())
                                        .map(str::to_string);
                                    self.problem(
                                        n.span,
                                        path,
                                        Problem::UnknownValue {
                                            what: "match",
                                            found: t,
                                            expected: MATCH_VALUES,
                                            suggestion,
                                        },
                                    );
                                    None
                                }
                                None => None,
                            }
                        }
                        "fix" => {
                            fix_origin = Some(k.span.origin(path.clone()));
                            fix = self.named(n, &path);
                        }
                        _ => start = self.named(n, &path),
                    }
                }
            }
        }
        if let (Some(Matching::Pose), Some(origin)) = (matching, &fix_origin) {
            if !fix.is_empty() {
                self.issues.push(
                    Issue::new(
                        origin.clone(),
                        "`cnc.fix` holds variables, which only `match: point_axis` allows (a full pose determines every axis)",
                        "fix",
                        "chain::settings::fix_needs_point_axis",
                    )
                    .with_help("add `match: point_axis` under `cnc`, or remove `fix`"),
                );
            }
        }
        Some(Settings {
            name: name?,
            description,
            file: file.to_string(),
            source: text.to_string(),
            base: base.to_path_buf(),
            generator,
            values,
            values_origin,
            omega_c: omega_c?,
            interval: interval?,
            drive,
            drive_origin,
            cnc_machine,
            cnc_parameters,
            matching: matching?,
            fix,
            fix_origin,
            start,
        })
    }

    fn interval(&mut self, node: &Node) -> Option<(f64, f64)> {
        let path = "roll.interval";
        let Some(items) = node.as_sequence() else {
            self.problem(
                node.span,
                path,
                Problem::WrongType {
                    expected: "a list [t0, t1]",
                    found: node.describe(),
                },
            );
            return None;
        };
        let [a, b] = items else {
            self.problem(
                node.span,
                path,
                Problem::WrongLength {
                    expected: 2,
                    found: items.len(),
                },
            );
            return None;
        };
        let t0 = self.number(a, &format!("{path}[0]"));
        let t1 = self.number(b, &format!("{path}[1]"));
        let (t0, t1) = (t0?, t1?);
        if t0 < t1 {
            Some((t0, t1))
        } else {
            self.issues.push(Issue::new(
                node.span.origin(path),
                format!("the roll interval needs t0 < t1, got [{t0}, {t1}]"),
                "empty interval",
                "chain::settings::interval",
            ));
            None
        }
    }

    fn drive(&mut self, node: &Node) -> Vec<Drive> {
        let Some(entries) = self.mapping(node, "roll.drive") else {
            return Vec::new();
        };
        if entries.is_empty() {
            self.problem(
                node.span,
                "roll.drive",
                Problem::EmptyList {
                    what: "`roll.drive` (the generator variables that move)",
                },
            );
        }
        let mut out = Vec::new();
        for (k, v) in entries {
            let name = k.as_str().unwrap_or("").to_string();
            let path = join("roll.drive", &name);
            let Some(fields) = self.fields(v, &path, DRIVE_KEYS) else {
                continue;
            };
            let mut start = None;
            let mut ratio = Some(1.0);
            for (key, _, n) in fields {
                let p = join(&path, key);
                if key == "start" {
                    start = self.value(n, &p);
                } else {
                    ratio = self.number(n, &p);
                }
            }
            if let Some(ratio) = ratio {
                out.push(Drive {
                    name,
                    key: k.span.origin(path),
                    start,
                    ratio,
                });
            }
        }
        out
    }
}

fn top_span() -> Span {
    Span {
        offset: 0,
        len: 0,
        line: 1,
        column: 1,
    }
}

/// Degrees from `D°`, `D°M′`, `D°M′S″` (ASCII `'` and `"` accepted for the
/// minute and second marks, `−` for the sign). Minutes and seconds must be
/// below 60; the sign applies to the whole angle.
pub fn parse_dms(text: &str) -> Result<f64, String> {
    let t = text.trim();
    let (negative, rest) = if let Some(r) = t.strip_prefix('-') {
        (true, r)
    } else if let Some(r) = t.strip_prefix('−') {
        (true, r)
    } else if let Some(r) = t.strip_prefix('+') {
        (false, r)
    } else {
        (false, t)
    };
    let rest = rest.trim_start();
    let (deg, rest) = rest
        .split_once('°')
        .ok_or_else(|| "expected `°` after the degrees".to_string())?;
    let number = |s: &str, what: &str| -> Result<f64, String> {
        let s = s.trim();
        if s.is_empty() || !s.chars().all(|c| c.is_ascii_digit() || c == '.') {
            return Err(format!("`{s}` is not a number of {what}"));
        }
        s.parse::<f64>()
            .map_err(|_| format!("`{s}` is not a number of {what}"))
    };
    let d = number(deg, "degrees")?;
    let mut total = d;
    let mut rest = rest.trim();
    for (marks, what, div) in [
        (&['′', '\''][..], "minutes", 60.0),
        (&['″', '"'][..], "seconds", 3600.0),
    ] {
        if rest.is_empty() {
            break;
        }
        let Some(pos) = rest.find(|c: char| marks.contains(&c)) else {
            return Err(format!("expected `{}` after the {what}", marks[0]));
        };
        let v = number(&rest[..pos], what)?;
        if v >= 60.0 {
            return Err(format!("{v} {what} is not below 60"));
        }
        total += v / div;
        let mark_len = rest[pos..].chars().next().map_or(1, char::len_utf8);
        rest = rest[pos + mark_len..].trim();
    }
    if !rest.is_empty() {
        return Err(format!("unexpected `{rest}` at the end"));
    }
    Ok(if negative { -total } else { total })
}

// ---------------------------------------------------------------------------
// Binding to the machines

impl Settings {
    /// The generator file named by `generator:`, resolved against the
    /// settings file's directory (`None`: the built-in cradle generator).
    pub fn generator_path(&self) -> Option<PathBuf> {
        self.generator.as_ref().map(|(p, _)| self.base.join(p))
    }

    /// The CNC machine file named by `cnc.machine`, resolved against the
    /// settings file's directory.
    pub fn cnc_path(&self) -> Option<PathBuf> {
        self.cnc_machine.as_ref().map(|(p, _)| self.base.join(p))
    }

    /// Loads the generator machine: the file named by `generator:` or the
    /// built-in cradle generator.
    pub fn load_generator(&self) -> Result<Machine, ReferenceError> {
        match (&self.generator, self.generator_path()) {
            (Some((_, origin)), Some(p)) => self.load_machine(&p, origin, "generator"),
            _ => crate::load_str(BUILTIN_GENERATOR, BUILTIN_GENERATOR_NAME)
                .map_err(ReferenceError::Machine),
        }
    }

    /// Loads the CNC machine named by `cnc.machine`, if any.
    pub fn load_cnc(&self) -> Option<Result<Machine, ReferenceError>> {
        let (_, origin) = self.cnc_machine.as_ref()?;
        let p = self.cnc_path()?;
        Some(self.load_machine(&p, origin, "CNC machine"))
    }

    fn load_machine(
        &self,
        path: &Path,
        origin: &Origin,
        what: &str,
    ) -> Result<Machine, ReferenceError> {
        if let Err(e) = std::fs::File::open(path) {
            return Err(ReferenceError::Path(self.error(vec![Issue::new(
                origin.clone(),
                format!("cannot read the {what} file `{}`: {e}", path.display()),
                "file",
                "chain::settings::machine_file",
            )
            .with_help("paths are relative to the settings file's directory")])));
        }
        crate::load_file(path).map_err(ReferenceError::Machine)
    }

    fn error(&self, issues: Vec<Issue>) -> SettingsError {
        SettingsError::new(&self.file, &self.source, issues)
    }

    /// Checks every name against the generator and the CNC machine and
    /// builds the motion specification. `cnc_overrides` (e.g. `--param`)
    /// replace `cnc.parameters` entries.
    pub fn bind(
        &self,
        generator: &Machine,
        cnc: &Machine,
        cnc_overrides: &[(String, f64)],
    ) -> Result<MotionSpec, SettingsError> {
        let mut issues = Vec::new();
        let gname = &generator.name;
        // Generator parameters: file values, then `values`.
        let mut gparams: Vec<Option<f64>> = generator.parameters.iter().map(|p| p.value).collect();
        let mut laws: Vec<Option<Law>> = vec![None; generator.variables.len()];
        let mut seen: Vec<(&str, &Origin)> = Vec::new();
        let all_names: Vec<&str> = generator
            .parameters
            .iter()
            .map(|p| p.name.as_str())
            .chain(generator.variables.iter().map(|v| v.name.as_str()))
            .collect();
        // Names suggested for a misspelt key are not reported missing again.
        let suggested: Vec<&str> = self
            .values
            .iter()
            .map(|n| n.name.as_str())
            .chain(self.drive.iter().map(|d| d.name.as_str()))
            .filter(|n| !all_names.contains(n))
            .filter_map(|n| closest(n, all_names.iter().copied()))
            .collect();
        let unknown = |name: &str, key: &Origin, what: &str| -> Issue {
            let hint = closest(name, all_names.iter().copied())
                .map(|s| format!(" (did you mean `{s}`?)"))
                .unwrap_or_default();
            Issue::new(
                key.clone(),
                format!("`{name}` is not a parameter or variable of the generator `{gname}`{hint}"),
                "unknown name",
                "chain::settings::unknown_name",
            )
            .with_help(format!(
                "{what} names the generator's parameters and variables: {}",
                all_names.join(", ")
            ))
        };
        for n in &self.values {
            if let Some(i) = duplicate(&seen, &n.name, &n.key) {
                issues.push(i);
                continue;
            }
            if let Some(k) = generator.parameters.iter().position(|p| p.name == n.name) {
                if n.value.angle {
                    issues.push(Issue::new(
                        n.value.origin.clone(),
                        format!("`{}` is a parameter (a length) of the generator; angle units are not allowed", n.name),
                        "angle on a length",
                        "chain::settings::angle_on_length",
                    ));
                }
                gparams[k] = Some(n.value.value);
            } else if let Some(k) = generator.variables.iter().position(|v| v.name == n.name) {
                if let Some(i) = angle_on_prismatic(generator, k, &n.name, &n.value) {
                    issues.push(i);
                }
                laws[k] = Some(Law {
                    start: n.value.value,
                    rate: 0.0,
                });
            } else {
                issues.push(unknown(&n.name, &n.key, "`values`"));
                continue;
            }
            seen.push((&n.name, &n.key));
        }
        for d in &self.drive {
            if let Some(i) = duplicate(&seen, &d.name, &d.key) {
                issues.push(i);
                continue;
            }
            let Some(k) = generator.variables.iter().position(|v| v.name == d.name) else {
                if generator.parameters.iter().any(|p| p.name == d.name) {
                    issues.push(Issue::new(
                        d.key.clone(),
                        format!("`{}` is a parameter of the generator `{gname}`; only its variables can be driven", d.name),
                        "not a variable",
                        "chain::settings::drive_parameter",
                    ).with_help("give it under `values`"));
                } else {
                    issues.push(unknown(&d.name, &d.key, "`roll.drive`"));
                }
                continue;
            };
            if let Some(start) = &d.start {
                if let Some(i) = angle_on_prismatic(generator, k, &d.name, start) {
                    issues.push(i);
                }
            }
            laws[k] = Some(Law {
                start: d.start.as_ref().map_or(0.0, |s| s.value),
                rate: d.ratio * self.omega_c,
            });
            seen.push((&d.name, &d.key));
        }
        for (k, p) in generator.parameters.iter().enumerate() {
            if gparams[k].is_none() && !suggested.contains(&p.name.as_str()) {
                issues.push(
                    Issue::new(
                        self.values_origin.clone(),
                        format!("generator parameter `{}` has no value", p.name),
                        "missing value",
                        "chain::settings::missing_value",
                    )
                    .with_help(format!("add `{}: <value>` under `values`", p.name)),
                );
            }
        }
        for (k, v) in generator.variables.iter().enumerate() {
            if laws[k].is_none() && !suggested.contains(&v.name.as_str()) {
                issues.push(Issue::new(
                    self.values_origin.clone(),
                    format!("generator variable `{}` has no value", v.name),
                    "missing value",
                    "chain::settings::missing_value",
                ).with_help(format!(
                    "hold it with `{}: <value>` under `values`, or move it with `{}: {{start: .., ratio: ..}}` under `roll.drive`",
                    v.name, v.name
                )));
            }
        }
        if !laws.iter().flatten().any(|l| l.rate != 0.0) && !self.drive.is_empty() {
            issues.push(Issue::new(
                self.drive_origin.clone(),
                "no generator variable moves: every `ratio` is 0",
                "no motion",
                "chain::settings::no_motion",
            ));
        }

        // CNC side.
        let cname = &cnc.name;
        let mut cparams: Vec<Option<f64>> = cnc.parameters.iter().map(|p| p.value).collect();
        for n in &self.cnc_parameters {
            match cnc.parameters.iter().position(|p| p.name == n.name) {
                Some(k) => {
                    if n.value.angle {
                        issues.push(Issue::new(
                            n.value.origin.clone(),
                            format!("`{}` is a parameter (a length) of `{cname}`; angle units are not allowed", n.name),
                            "angle on a length",
                            "chain::settings::angle_on_length",
                        ));
                    }
                    cparams[k] = Some(n.value.value);
                }
                None => {
                    let hint = closest(&n.name, cnc.parameters.iter().map(|p| p.name.as_str()))
                        .map(|s| format!(" (did you mean `{s}`?)"))
                        .unwrap_or_default();
                    issues.push(Issue::new(
                        n.key.clone(),
                        format!(
                            "`{}` is not a parameter of the CNC machine `{cname}`{hint}",
                            n.name
                        ),
                        "unknown parameter",
                        "chain::settings::unknown_name",
                    ));
                }
            }
        }
        for (name, v) in cnc_overrides {
            match cnc.parameters.iter().position(|p| p.name == *name) {
                Some(k) => cparams[k] = Some(*v),
                None => issues.push(Issue::new(
                    Origin::default(),
                    format!("--param: `{name}` is not a parameter of the CNC machine `{cname}`"),
                    "unknown parameter",
                    "chain::settings::unknown_name",
                )),
            }
        }
        for (k, p) in cnc.parameters.iter().enumerate() {
            if cparams[k].is_none() {
                issues.push(
                    Issue::new(
                        top_origin("cnc.parameters"),
                        format!(
                            "parameter `{}` of the CNC machine `{cname}` has no value",
                            p.name
                        ),
                        "missing value",
                        "chain::settings::missing_value",
                    )
                    .with_help(format!(
                        "add `cnc: {{parameters: {{{}: <value>}}}}` or pass --param {}=VALUE",
                        p.name, p.name
                    )),
                );
            }
        }
        let cnc_variable = |n: &Named, what: &str, issues: &mut Vec<Issue>| -> Option<usize> {
            match cnc.variables.iter().position(|v| v.name == n.name) {
                Some(k) => {
                    if let Some(i) = angle_on_prismatic(cnc, k, &n.name, &n.value) {
                        issues.push(i);
                    }
                    Some(k)
                }
                None => {
                    let hint = closest(&n.name, cnc.variables.iter().map(|v| v.name.as_str()))
                        .map(|s| format!(" (did you mean `{s}`?)"))
                        .unwrap_or_default();
                    issues.push(Issue::new(
                        n.key.clone(),
                        format!(
                            "`{}` in {what} is not a variable of the CNC machine `{cname}`{hint}",
                            n.name
                        ),
                        "unknown variable",
                        "chain::settings::unknown_variable",
                    ));
                    None
                }
            }
        };
        let mut fixed = Vec::new();
        for n in &self.fix {
            if let Some(k) = cnc_variable(n, "`cnc.fix`", &mut issues) {
                fixed.push((k, n.value.value));
            }
        }
        let mut start = vec![0.0; cnc.variables.len()];
        for n in &self.start {
            if let Some(k) = cnc_variable(n, "`cnc.start`", &mut issues) {
                start[k] = n.value.value;
            }
        }
        for &(k, v) in &fixed {
            start[k] = v;
        }
        if !issues.is_empty() {
            return Err(self.error(issues));
        }
        Ok(MotionSpec {
            generator_parameters: gparams.into_iter().map(|v| v.unwrap_or(f64::NAN)).collect(),
            laws: laws
                .into_iter()
                .map(|l| {
                    l.unwrap_or(Law {
                        start: 0.0,
                        rate: 0.0,
                    })
                })
                .collect(),
            cnc_parameters: cparams.into_iter().map(|v| v.unwrap_or(f64::NAN)).collect(),
            matching: self.matching,
            fixed,
            start,
            interval: self.interval,
        })
    }
}

/// The issue of a name given twice (`values` and `roll.drive`).
fn duplicate(seen: &[(&str, &Origin)], name: &str, key: &Origin) -> Option<Issue> {
    let (_, first) = seen.iter().find(|(n, _)| *n == name)?;
    Some(
        Issue::new(
            key.clone(),
            format!(
                "`{name}` is given twice (first on line {}): in `values` and in `roll.drive`",
                first.line
            ),
            "given twice",
            "chain::settings::duplicate",
        )
        .with_help("a held setting goes in `values`, a moving one in `roll.drive`"),
    )
}

fn angle_on_prismatic(machine: &Machine, k: usize, name: &str, value: &Value) -> Option<Issue> {
    (value.angle && machine.variables[k].kind == JointKind::Prismatic).then(|| {
        Issue::new(
            value.origin.clone(),
            format!(
                "`{name}` is a prismatic (linear) variable of `{}`; angle units are not allowed",
                machine.name
            ),
            "angle on a length",
            "chain::settings::angle_on_length",
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn degrees_minutes_seconds() {
        assert_eq!(parse_dms("46°33′").unwrap(), 46.0 + 33.0 / 60.0);
        assert_eq!(parse_dms("−115°39′").unwrap(), -(115.0 + 39.0 / 60.0));
        assert_eq!(parse_dms("-3°59'").unwrap(), -(3.0 + 59.0 / 60.0));
        assert_eq!(parse_dms("-2.00°").unwrap(), -2.0);
        assert!((parse_dms("1°2′3″").unwrap() - (1.0 + 2.0 / 60.0 + 3.0 / 3600.0)).abs() < 1e-15);
        assert!(parse_dms("1°75′").is_err());
        assert!(parse_dms("1°x′").is_err());
        assert!(parse_dms("1°2").is_err());
    }
}
