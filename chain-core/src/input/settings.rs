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

use std::path::{Path, PathBuf};

use crate::diagnostic::{closest, Diagnostics, Problem, SettingsProblem};
use crate::load::{
    self,
    reader::{index, join, start_origin, TreeReader},
};
use crate::model::{JointKind, Machine, Origin};
use crate::motion::{Law, Matching, MotionSpec};
use crate::yaml::{self, Node};

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

/// The text of `examples/machines/cradle_generator.yaml` (a byte-identical
/// copy inside this crate, so that it packages), the generator used when a
/// settings file names none.
pub const BUILTIN_GENERATOR: &str = include_str!("cradle_generator.yaml");

/// The file name under which the built-in generator is reported.
pub const BUILTIN_GENERATOR_NAME: &str = "cradle_generator.yaml (built-in)";

/// Settings files larger than this are refused.
pub const MAX_SETTINGS_BYTES: usize = crate::bounded::SETTINGS_BYTES;

// ---------------------------------------------------------------------------
// Diagnostics

/// Every problem found in one settings file: the [`Diagnostics`] of the
/// machine loader, never empty. `Display` gives the first problem
/// (`file:line:column: message at key `k``) and how many more there are;
/// `{:#}` lists them all; as a [`miette::Diagnostic`] it carries the file
/// text with a label at the span and the other problems as related
/// diagnostics. The shared rules (unknown key, wrong type, ...) keep their
/// machine-file wording and codes; the settings' own rules are
/// [`SettingsProblem`]s with codes `chain::settings::*`.
pub type SettingsError = Diagnostics;

/// Why a machine named by a settings file could not be loaded.
#[derive(Debug, thiserror::Error)]
#[cfg_attr(feature = "miette", derive(miette::Diagnostic))]
pub enum ReferenceError {
    /// The path in the settings file cannot be read (located in the settings
    /// file).
    #[error(transparent)]
    #[cfg_attr(feature = "miette", diagnostic(transparent))]
    Path(SettingsError),
    /// The machine file itself has errors (located in that file).
    #[error(transparent)]
    #[cfg_attr(feature = "miette", diagnostic(transparent))]
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
    let bytes = load::read_file(path, &file, MAX_SETTINGS_BYTES)?;
    let base = path
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from("."));
    load_settings_str(load::decode(&bytes, &file)?, &file, &base)
}

/// Loads settings from text; `file` names it in messages, `base` is the
/// directory relative paths are resolved against.
pub fn load_settings_str(text: &str, file: &str, base: &Path) -> Result<Settings, SettingsError> {
    // A NUL byte: not a text file.
    load::decode(text.as_bytes(), file)?;
    let parsed = yaml::parse(text);
    let mut r = Reader {
        problems: (parsed.errors.into_iter())
            .map(|(span, key, problem)| (span.origin(key), problem))
            .collect(),
    };
    let settings = match &parsed.root {
        Some(root) if r.problems.is_empty() => r.settings(root, text, file, base),
        Some(_) => None,
        None => {
            if r.problems.is_empty() {
                let empty = SettingsProblem::Empty.into();
                r.problems.push((start_origin(""), empty));
            }
            None
        }
    };
    match (settings, Diagnostics::located(file, text, r.problems)) {
        (_, Some(e)) => Err(e),
        (Some(s), None) => Ok(s),
        (None, None) => {
            let invalid = SettingsProblem::Invalid.into();
            Err(Diagnostics::single(file, text, start_origin(""), invalid))
        }
    }
}

/// The reader of a settings file: the problems found so far.
struct Reader {
    problems: Vec<(Origin, Problem)>,
}

impl TreeReader for Reader {
    fn problems(&mut self) -> &mut Vec<(Origin, Problem)> {
        &mut self.problems
    }
}

impl Reader {
    /// A string that is not blank.
    fn string(&mut self, node: &Node, path: &str, expected: &'static str) -> Option<String> {
        self.text(node, path, expected, |t| !t.trim().is_empty())
    }

    /// A path to a file, with its origin.
    fn file(&mut self, node: &Node, path: &str) -> Option<(String, Origin)> {
        let p = self.string(node, path, "a file path")?;
        Some((p, node.span.origin(path)))
    }

    /// A number or an angle (`<expr>deg`, `D°M′S″`), finite.
    fn value(&mut self, node: &Node, path: &str) -> Option<Value> {
        let expected = "a number or an angle (`2.5deg`, `\"46°33′\"`)";
        let text = self.text(node, path, expected, |_| true)?;
        let t = text.trim();
        let (value, angle) = if let Some(prefix) = t.strip_suffix("deg") {
            (self.number_in(node, prefix, path)?.to_radians(), true)
        } else if t.contains('°') {
            match parse_dms(t) {
                Ok(deg) => (deg.to_radians(), true),
                Err(message) => {
                    let (text, reason) = (t.to_string(), message);
                    let bad = SettingsProblem::Angle { text, reason };
                    self.report(node.span, path, bad.into());
                    return None;
                }
            }
        } else {
            (self.constant(node, &text, path)?, false)
        };
        if !value.is_finite() {
            self.report(node.span, path, Problem::NotFinite { what: "the value" });
            return None;
        }
        Some(Value {
            value,
            angle,
            origin: node.span.origin(path),
        })
    }

    /// A plain number (no angle units).
    fn plain_number(&mut self, node: &Node, path: &str) -> Option<f64> {
        let v = self.value(node, path)?;
        if v.angle {
            self.wrong_type(node, path, "a plain number (no angle units)");
            return None;
        }
        Some(v.value)
    }

    /// `name: value` entries.
    fn named(&mut self, node: &Node, path: &str) -> Vec<Named> {
        let Some(entries) = self.entries(node, path) else {
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
        let top = self.top(root, TOP_KEYS)?;
        let name = self.required(&top, "settings");
        let name = name.and_then(|v| self.string(v, "settings", "a name"));
        let description = top.get("description");
        let description = description.and_then(|v| self.string(v, "description", "a string"));
        let generator = top.get("generator").and_then(|v| self.file(v, "generator"));
        let (values, values_origin) = match top.entry("values") {
            Some((k, v)) => (self.named(v, "values"), k.span.origin("values")),
            None => (Vec::new(), start_origin("values")),
        };
        let mut omega_c = None;
        let mut interval = None;
        let mut drive = Vec::new();
        let mut drive_origin = start_origin("roll.drive");
        match top.entry("roll") {
            Some((k, v)) => {
                if let Some(roll) = self.fields(v, k.span, "roll", ROLL_KEYS) {
                    omega_c = self
                        .required(&roll, "omega_c")
                        .and_then(|n| self.omega_c(n));
                    interval = self
                        .required(&roll, "interval")
                        .and_then(|n| self.interval(n));
                    match roll.entry("drive") {
                        Some((dk, n)) => {
                            drive_origin = dk.span.origin("roll.drive");
                            drive = self.drive(n);
                        }
                        None => self.missing(&roll, "drive"),
                    }
                }
            }
            None => self.missing(&top, "roll"),
        }
        let mut cnc_machine = None;
        let mut cnc_parameters = Vec::new();
        let mut matching = Some(Matching::Pose);
        let mut fix = Vec::new();
        let mut fix_origin = None;
        let mut start = Vec::new();
        let cnc = top.entry("cnc");
        if let Some(cnc) = cnc.and_then(|(k, v)| self.fields(v, k.span, "cnc", CNC_KEYS)) {
            cnc_machine = cnc.get("machine").and_then(|n| self.file(n, "cnc.machine"));
            if let Some(n) = cnc.get("parameters") {
                cnc_parameters = self.named(n, "cnc.parameters");
            }
            if let Some(n) = cnc.get("match") {
                matching = self
                    .string(n, "cnc.match", "`pose` or `point_axis`")
                    .and_then(|t| self.choice(n, "cnc.match", t, "match", MATCH_VALUES))
                    .map(|m| match m {
                        "pose" => Matching::Pose,
                        _ => Matching::PointAxis,
                    });
            }
            if let Some((k, n)) = cnc.entry("fix") {
                fix_origin = Some(k.span.origin("cnc.fix"));
                fix = self.named(n, "cnc.fix");
            }
            if let Some(n) = cnc.get("start") {
                start = self.named(n, "cnc.start");
            }
        }
        if let (Some(Matching::Pose), Some(origin)) = (matching, &fix_origin) {
            if !fix.is_empty() {
                let pose = SettingsProblem::FixNeedsPointAxis.into();
                self.problems.push((origin.clone(), pose));
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

    /// `roll.omega_c`: positive.
    fn omega_c(&mut self, node: &Node) -> Option<f64> {
        let path = "roll.omega_c";
        let value = self.value(node, path)?.value;
        if value > 0.0 {
            return Some(value);
        }
        let what = "the cradle angular velocity omega_c";
        self.report(node.span, path, Problem::NotPositive { what, value });
        None
    }

    fn interval(&mut self, node: &Node) -> Option<(f64, f64)> {
        let path = "roll.interval";
        let [a, b] = self.items(node, path, "a list [t0, t1]")?;
        let t0 = self.plain_number(a, &index(path, 0));
        let t1 = self.plain_number(b, &index(path, 1));
        let (t0, t1) = (t0?, t1?);
        if t0 < t1 {
            return Some((t0, t1));
        }
        let empty = SettingsProblem::Interval { t0, t1 };
        self.report(node.span, path, empty.into());
        None
    }

    fn drive(&mut self, node: &Node) -> Vec<Drive> {
        let Some(entries) = self.entries(node, "roll.drive") else {
            return Vec::new();
        };
        if entries.is_empty() {
            let what = "`roll.drive` (the generator variables that move)";
            self.report(node.span, "roll.drive", Problem::EmptyList { what });
        }
        let mut out = Vec::new();
        for (k, v) in entries {
            let name = k.as_str().unwrap_or("").to_string();
            let path = join("roll.drive", &name);
            let Some(fields) = self.fields(v, k.span, &path, DRIVE_KEYS) else {
                continue;
            };
            let start = fields.get("start");
            let start = start.and_then(|n| self.value(n, &fields.path("start")));
            let ratio = match fields.get("ratio") {
                Some(n) => self.plain_number(n, &fields.path("ratio")),
                None => Some(1.0),
            };
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
        what: &'static str,
    ) -> Result<Machine, ReferenceError> {
        if let Err(e) = std::fs::File::open(path) {
            let unread = SettingsProblem::MachineFile {
                what,
                path: path.display().to_string(),
                reason: e.to_string(),
            };
            let (file, source) = (&self.file, &self.source);
            let error = Diagnostics::single(file, source, origin.clone(), unread.into());
            return Err(ReferenceError::Path(error));
        }
        crate::load_file(path).map_err(ReferenceError::Machine)
    }

    /// Checks every name against the generator and the CNC machine and
    /// builds the motion specification. `cnc_overrides` (the run's
    /// parameter values, `NAME=VALUE`) replace `cnc.parameters` entries.
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
        let unknown = |name: &str, key: &Origin, within: &'static str| -> Issue {
            let problem = SettingsProblem::UnknownName {
                name: name.to_string(),
                generator: gname.clone(),
                within,
                names: all_names.iter().map(|n| n.to_string()).collect(),
                suggestion: closest(name, all_names.iter().copied()).map(str::to_string),
            };
            (key.clone(), problem.into())
        };
        for n in &self.values {
            if let Some(i) = duplicate(&seen, &n.name, &n.key) {
                issues.push(i);
                continue;
            }
            if let Some(k) = generator.parameters.iter().position(|p| p.name == n.name) {
                if n.value.angle {
                    issues.push(angle_on_length(
                        &n.name,
                        "a parameter (a length) of the generator",
                        &n.value,
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
                    let problem = SettingsProblem::DriveParameter {
                        name: d.name.clone(),
                        generator: gname.clone(),
                    };
                    issues.push((d.key.clone(), problem.into()));
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
                let name = p.name.clone();
                let missing = SettingsProblem::GeneratorParameterMissing { name };
                issues.push((self.values_origin.clone(), missing.into()));
            }
        }
        for (k, v) in generator.variables.iter().enumerate() {
            if laws[k].is_none() && !suggested.contains(&v.name.as_str()) {
                let name = v.name.clone();
                let missing = SettingsProblem::GeneratorVariableMissing { name };
                issues.push((self.values_origin.clone(), missing.into()));
            }
        }
        if !laws.iter().flatten().any(|l| l.rate != 0.0) && !self.drive.is_empty() {
            let problem = SettingsProblem::NoMotion.into();
            issues.push((self.drive_origin.clone(), problem));
        }

        // CNC side.
        let cname = &cnc.name;
        let mut cparams: Vec<Option<f64>> = cnc.parameters.iter().map(|p| p.value).collect();
        let not_a_parameter = |name: &str, command_line: bool, key: &Origin| -> Issue {
            let close = closest(name, cnc.parameters.iter().map(|p| p.name.as_str()));
            let problem = SettingsProblem::UnknownParameter {
                name: name.to_string(),
                machine: cname.clone(),
                command_line,
                suggestion: close.map(str::to_string),
            };
            (key.clone(), problem.into())
        };
        for n in &self.cnc_parameters {
            match cnc.parameters.iter().position(|p| p.name == n.name) {
                Some(k) => {
                    if n.value.angle {
                        let what = format!("a parameter (a length) of `{cname}`");
                        issues.push(angle_on_length(&n.name, &what, &n.value));
                    }
                    cparams[k] = Some(n.value.value);
                }
                None => issues.push(not_a_parameter(&n.name, false, &n.key)),
            }
        }
        for (name, v) in cnc_overrides {
            match cnc.parameters.iter().position(|p| p.name == *name) {
                Some(k) => cparams[k] = Some(*v),
                None => issues.push(not_a_parameter(name, true, &Origin::default())),
            }
        }
        for (k, p) in cnc.parameters.iter().enumerate() {
            if cparams[k].is_none() {
                let missing = SettingsProblem::CncParameterMissing {
                    name: p.name.clone(),
                    machine: cname.clone(),
                };
                issues.push((start_origin("cnc.parameters"), missing.into()));
            }
        }
        let cnc_variable =
            |n: &Named, within: &'static str, issues: &mut Vec<Issue>| -> Option<usize> {
                match cnc.variables.iter().position(|v| v.name == n.name) {
                    Some(k) => {
                        if let Some(i) = angle_on_prismatic(cnc, k, &n.name, &n.value) {
                            issues.push(i);
                        }
                        Some(k)
                    }
                    None => {
                        let close = closest(&n.name, cnc.variables.iter().map(|v| v.name.as_str()));
                        let problem = SettingsProblem::UnknownVariable {
                            name: n.name.clone(),
                            within,
                            machine: cname.clone(),
                            suggestion: close.map(str::to_string),
                        };
                        issues.push((n.key.clone(), problem.into()));
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
        if let Some(e) = Diagnostics::located(&self.file, &self.source, issues) {
            return Err(e);
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

/// A located problem of [`Settings::bind`].
type Issue = (Origin, Problem);

/// The issue of a name given twice (`values` and `roll.drive`).
fn duplicate(seen: &[(&str, &Origin)], name: &str, key: &Origin) -> Option<Issue> {
    let (_, first) = seen.iter().find(|(n, _)| *n == name)?;
    let problem = SettingsProblem::Duplicate {
        name: name.to_string(),
        first_line: first.line,
    };
    Some((key.clone(), problem.into()))
}

/// The issue of angle units on `name`, which is `what` (a length).
fn angle_on_length(name: &str, what: &str, value: &Value) -> Issue {
    let problem = SettingsProblem::AngleOnLength {
        name: name.to_string(),
        what: what.to_string(),
    };
    (value.origin.clone(), problem.into())
}

fn angle_on_prismatic(machine: &Machine, k: usize, name: &str, value: &Value) -> Option<Issue> {
    (value.angle && machine.variables[k].kind == JointKind::Prismatic).then(|| {
        let what = format!("a prismatic (linear) variable of `{}`", machine.name);
        angle_on_length(name, &what, value)
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
