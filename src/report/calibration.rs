//! The calibration file of `chain report` (`docs/report.md`): what was
//! measured and computed for one machine, and the free text of the
//! report's cover, read from YAML with every refusal located (file, line,
//! key): an unknown or missing key, a value of the wrong kind, a file that
//! cannot be read (at the calibration file's line naming it), a controller
//! or figure that does not exist.

use std::path::{Path, PathBuf};

use chain_core::diagnostic::{closest, Describe, Description, Diagnostics, Problem};
use chain_core::measured::circular::Plane;
use chain_core::measured::positioning::Coverage;
use chain_core::measured::positioning_temperature::Temperatures;
use chain_core::measured::Holdout;
use chain_core::model::Origin;
use chain_core::yaml::{self, Node};
use serde::Serialize;

use crate::ops::choice::Choice;
use crate::ops::export::ExportController;

/// The largest calibration file read.
pub const MAX_CALIBRATION_BYTES: usize = 1 << 20;

/// The ISO 230-2 figures a tolerance may be given for: the names of
/// [`super::FIGURES`].
const FIGURE_NAMES: [&str; 12] = {
    let mut names = [""; 12];
    let mut i = 0;
    while i < 12 {
        names[i] = super::FIGURES[i].0;
        i += 1;
    }
    names
};

/// The cover of the report: who, what, with what, when, at what
/// temperatures (free text, as the calibration file gives it).
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct Cover {
    /// `title`.
    pub title: Option<String>,
    /// `customer`.
    pub customer: Option<String>,
    /// `machine_serial`.
    pub machine_serial: Option<String>,
    /// `instrument`.
    pub instrument: Option<String>,
    /// `operator`.
    pub operator: Option<String>,
    /// `date`.
    pub date: Option<String>,
    /// `temperatures`: name and °C, in the file's order.
    pub temperatures: Vec<(String, f64)>,
    /// `notes`.
    pub notes: Option<String>,
}

/// One axis's ISO 230-2 positioning runs.
#[derive(Debug, Clone, PartialEq)]
pub struct AxisRuns {
    /// The axis's name (the report's heading; a machine variable's name
    /// for the reader, not checked against the machine).
    pub axis: String,
    /// The run file.
    pub runs: PathBuf,
    /// A rotary axis (targets in degrees, deviations in arcsec).
    pub rotary: bool,
    /// The coverage factor `k` (default 2).
    pub k: Coverage,
    /// The tolerances of the figures given (figure, tolerance in the
    /// deviations' unit).
    pub tolerances: Vec<(String, f64)>,
    /// The correction of a linear axis's runs to 20 °C
    /// (`docs/positioning.md`, "At 20 °C").
    pub temperature: Option<Temperatures>,
}

/// The identification's records and how their prediction is checked.
#[derive(Debug, Clone, PartialEq)]
pub struct IdentifyPart {
    /// The model identified, when it is not the calibration's machine file
    /// (a richer parametrisation of the same machine: its error motions as
    /// functions of the axes).
    pub machine: Option<PathBuf>,
    /// The measurement CSV.
    pub measurements: PathBuf,
    /// The fraction held out (a seeded split), where the prediction is
    /// reported.
    pub holdout: Option<f64>,
    /// Its seed.
    pub seed: Option<u64>,
    /// Measurements held out in a file of their own.
    pub validate: Option<PathBuf>,
}

/// A circular test.
#[derive(Debug, Clone, PartialEq)]
pub struct CircularPart {
    /// The run file.
    pub runs: PathBuf,
    /// The radius (mm) of runs whose file gives none.
    pub radius: Option<f64>,
    /// The feed (mm/min) of runs whose file gives none.
    pub feed: Option<f64>,
    /// The plane of runs whose file gives none.
    pub plane: Option<String>,
}

/// An ISO 230-3 thermal drift test.
#[derive(Debug, Clone, PartialEq)]
pub struct ThermalPart {
    /// The drift file.
    pub runs: PathBuf,
    /// Fit the thermal model of each channel (default true).
    pub fit: bool,
    /// The fraction of the test's duration held out of the fit.
    pub holdout: Option<f64>,
    /// Consider lag responses to the loads.
    pub lag: bool,
    /// The most temperature sensors per channel.
    pub sensors: Option<usize>,
}

/// A calibration file, read and checked.
#[derive(Debug, Clone, PartialEq)]
pub struct Calibration {
    /// The file as named in messages.
    pub file: String,
    /// The cover.
    pub cover: Cover,
    /// The machine file.
    pub machine: PathBuf,
    /// The machine's parameters (`params`).
    pub params: Vec<(String, f64)>,
    /// Per axis, its positioning runs.
    pub positioning: Vec<AxisRuns>,
    /// The built machine's values file.
    pub values: Option<PathBuf>,
    /// The identification.
    pub identify: Option<IdentifyPart>,
    /// The controller the values were exported to.
    pub export: Option<ExportController>,
    /// A circular test.
    pub circular: Option<CircularPart>,
    /// A thermal drift test.
    pub thermal: Option<ThermalPart>,
    /// Every file named, with its role, in the file's order.
    pub inputs: Vec<(String, PathBuf)>,
}

/// Why a calibration file was refused: its problems, located.
#[derive(Debug, thiserror::Error)]
#[cfg_attr(feature = "cli", derive(miette::Diagnostic))]
#[error(transparent)]
#[cfg_attr(feature = "cli", diagnostic(transparent))]
pub struct CalibrationError(pub Diagnostics);

/// A rule of the calibration file.
#[derive(Debug, Clone, PartialEq)]
enum CalibrationProblem {
    /// The document, or a section, is not a mapping.
    NotMapping { what: String },
    /// A key the place does not take.
    UnknownKey {
        key: String,
        allowed: &'static [&'static str],
    },
    /// A required key is missing.
    MissingKey { key: &'static str, at: String },
    /// A value of the wrong kind.
    WrongType {
        expected: &'static str,
        found: String,
    },
    /// A file that cannot be read.
    Unreadable { path: String, message: String },
    /// A number out of its range.
    Range { value: f64, rule: &'static str },
    /// A controller that does not exist.
    Controller { message: String },
    /// The export without a values file.
    ExportWithoutValues,
    /// An axis named twice.
    AxisTwice { axis: String },
    /// A value the library refuses, in its words.
    Refused { message: String },
    /// Two keys that do not go together.
    Conflict {
        key: &'static str,
        with: &'static str,
        why: &'static str,
    },
}

impl Describe for CalibrationProblem {
    fn describe(&self) -> Description {
        use CalibrationProblem as P;
        let help = "docs/report.md: the calibration file's keys";
        match self {
            P::NotMapping { what } => Description::new(
                "chain::report::not_mapping",
                "here",
                format!("{what} must be a mapping of keys to values"),
            )
            .help(help.to_string()),
            P::UnknownKey { key, allowed } => Description::new(
                "chain::report::unknown_key",
                "unknown key",
                format!("unknown key `{key}`"),
            )
            .note(match closest(key, allowed.iter().copied()) {
                Some(c) => format!("did you mean `{c}`?"),
                None => format!("expected one of {}", allowed.join(", ")),
            }),
            P::MissingKey { key, at } => Description::new(
                "chain::report::missing_key",
                "here",
                format!("{at} has no `{key}`"),
            )
            .help(help.to_string()),
            P::WrongType { expected, found } => Description::new(
                "chain::report::wrong_type",
                "value",
                format!("expected {expected}, found {found}"),
            ),
            P::Unreadable { path, message } => Description::new(
                "chain::report::unreadable",
                "file",
                format!("cannot read {path}: {message}"),
            )
            .help("a path is relative to the calibration file's folder".to_string()),
            P::Range { value, rule } => {
                Description::new("chain::report::range", "value", format!("{value}: {rule}"))
            }
            P::Controller { message } => {
                Description::new("chain::report::controller", "controller", message.clone())
            }
            P::ExportWithoutValues => Description::new(
                "chain::report::export_without_values",
                "export",
                "the export writes a values file's errors for a controller: give `values` too",
            ),
            P::Refused { message } => {
                Description::new("chain::report::refused", "value", message.clone())
            }
            P::Conflict { key, with, why } => Description::new(
                "chain::report::conflict",
                "here",
                format!("`{key}` with `{with}`: {why}"),
            ),
            P::AxisTwice { axis } => Description::new(
                "chain::report::axis_twice",
                "axis",
                format!("axis `{axis}` has positioning runs twice"),
            ),
        }
    }
}

const TOP: &[&str] = &[
    "title",
    "customer",
    "machine_serial",
    "instrument",
    "operator",
    "date",
    "temperatures",
    "notes",
    "machine",
    "params",
    "positioning",
    "values",
    "identify",
    "export",
    "circular",
    "thermal",
];
const AXIS: &[&str] = &["axis", "runs", "rotary", "k", "tolerances", "temperature"];
const TEMPERATURE: &[&str] = &[
    "axis",
    "expansion",
    "instrument",
    "instrument_expansion",
    "temperature_uncertainty",
    "expansion_uncertainty",
];
const IDENTIFY: &[&str] = &["machine", "measurements", "holdout", "seed", "validate"];
const EXPORT: &[&str] = &["controller"];
const CIRCULAR: &[&str] = &["runs", "radius", "feed", "plane"];
const THERMAL: &[&str] = &["runs", "fit", "holdout", "lag", "sensors"];

/// The reader: the file's folder and the problems found.
struct Reader<'a> {
    dir: &'a Path,
    problems: Vec<(Origin, Problem)>,
    inputs: Vec<(String, PathBuf)>,
}

impl Reader<'_> {
    fn refuse(&mut self, node: &Node, key: &str, problem: CalibrationProblem) {
        self.problems
            .push((node.span.origin(key), Problem::foreign(problem)));
    }

    /// The entries of a mapping, each unknown key refused.
    fn mapping<'n>(
        &mut self,
        node: &'n Node,
        key: &str,
        what: &str,
        allowed: &'static [&'static str],
    ) -> Option<Vec<(&'n str, &'n Node)>> {
        let Some(entries) = node.as_mapping() else {
            let what = what.to_string();
            self.refuse(node, key, CalibrationProblem::NotMapping { what });
            return None;
        };
        let mut out = Vec::new();
        for (k, v) in entries {
            let name = k.as_str().unwrap_or_default();
            if allowed.contains(&name) {
                out.push((name, v));
            } else {
                let problem = CalibrationProblem::UnknownKey {
                    key: name.to_string(),
                    allowed,
                };
                self.refuse(k, &join(key, name), problem);
            }
        }
        Some(out)
    }

    /// `node` is not of the kind `expected`.
    fn wrong(&mut self, node: &Node, key: &str, expected: &'static str) {
        let found = node.describe();
        self.refuse(node, key, CalibrationProblem::WrongType { expected, found });
    }

    /// A required entry of a mapping (`at`: the mapping in words), refused
    /// at the mapping's node when missing.
    fn required<'n>(
        &mut self,
        value: Option<&'n Node>,
        mapping: &Node,
        key: &str,
        name: &'static str,
        at: &str,
    ) -> Option<&'n Node> {
        if value.is_none() {
            let problem = CalibrationProblem::MissingKey {
                key: name,
                at: at.to_string(),
            };
            self.refuse(mapping, key, problem);
        }
        value
    }

    /// A whole number at least `least`.
    fn whole(&mut self, node: &Node, key: &str, least: f64, rule: &'static str) -> Option<u64> {
        let v = self.number(node, key)?;
        if v >= least && v == v.trunc() && v < 1.8e19 {
            Some(v as u64)
        } else {
            self.refuse(node, key, CalibrationProblem::Range { value: v, rule });
            None
        }
    }

    fn text(&mut self, node: &Node, key: &str) -> Option<String> {
        match node.as_scalar() {
            Some(s) if !s.is_null() => Some(s.text.clone()),
            _ => {
                self.wrong(node, key, "text");
                None
            }
        }
    }

    fn number(&mut self, node: &Node, key: &str) -> Option<f64> {
        let value = node.as_str().and_then(|t| t.trim().parse::<f64>().ok());
        match value {
            Some(v) if v.is_finite() => Some(v),
            _ => {
                self.wrong(node, key, "a finite number");
                None
            }
        }
    }

    fn positive(&mut self, node: &Node, key: &str) -> Option<f64> {
        let v = self.number(node, key)?;
        if v > 0.0 {
            Some(v)
        } else {
            let rule = "must be positive";
            self.refuse(node, key, CalibrationProblem::Range { value: v, rule });
            None
        }
    }

    fn boolean(&mut self, node: &Node, key: &str) -> Option<bool> {
        match node.as_str() {
            Some("true") => Some(true),
            Some("false") => Some(false),
            _ => {
                self.wrong(node, key, "true or false");
                None
            }
        }
    }

    /// A file named relative to the calibration file's folder, refused at
    /// its line when it cannot be read.
    fn file(&mut self, node: &Node, key: &str) -> Option<PathBuf> {
        let text = self.text(node, key)?;
        let path = self.dir.join(&text);
        match std::fs::metadata(&path) {
            Ok(m) if m.is_file() => {
                self.inputs.push((key.to_string(), path.clone()));
                Some(path)
            }
            Ok(_) => {
                let problem = CalibrationProblem::Unreadable {
                    path: path.display().to_string(),
                    message: "not a file".into(),
                };
                self.refuse(node, key, problem);
                None
            }
            Err(e) => {
                let problem = CalibrationProblem::Unreadable {
                    path: path.display().to_string(),
                    message: e.to_string(),
                };
                self.refuse(node, key, problem);
                None
            }
        }
    }

    /// `{name: number, ...}`, in order.
    fn named_numbers(&mut self, node: &Node, key: &str) -> Vec<(String, f64)> {
        let Some(entries) = node.as_mapping() else {
            let what = format!("`{key}`");
            self.refuse(node, key, CalibrationProblem::NotMapping { what });
            return Vec::new();
        };
        let mut out = Vec::new();
        for (k, v) in entries {
            let name = k.as_str().unwrap_or_default().to_string();
            if let Some(x) = self.number(v, &join(key, &name)) {
                out.push((name, x));
            }
        }
        out
    }
}

fn join(key: &str, name: &str) -> String {
    if key.is_empty() {
        name.to_string()
    } else {
        format!("{key}.{name}")
    }
}

impl Calibration {
    /// Reads the calibration file at `path`.
    pub fn read(path: &Path) -> Result<Calibration, CalibrationError> {
        let file = path.display().to_string();
        let bytes = chain_core::bounded::read_path(path, MAX_CALIBRATION_BYTES).map_err(|e| {
            let problem = match e {
                chain_core::bounded::ReadError::TooLarge { limit } => Problem::TooLarge { limit },
                chain_core::bounded::ReadError::Io(e) => Problem::Io {
                    message: e.to_string(),
                },
            };
            CalibrationError(Diagnostics::single(&file, "", Origin::default(), problem))
        })?;
        let text = chain_core::load::decode(&bytes, &file).map_err(CalibrationError)?;
        let dir = path.parent().unwrap_or(Path::new("."));
        Calibration::parse(text, &file, dir)
    }

    /// A calibration file's `text`, named `file`, its paths relative to
    /// `dir`.
    pub fn parse(text: &str, file: &str, dir: &Path) -> Result<Calibration, CalibrationError> {
        let fail = |problems: Vec<(Origin, Problem)>| {
            CalibrationError(Diagnostics::located(file, text, problems).expect("a problem"))
        };
        let parsed = yaml::parse(text);
        if !parsed.errors.is_empty() {
            let problems = (parsed.errors.into_iter())
                .map(|(span, key, problem)| (span.origin(key), problem))
                .collect();
            return Err(fail(problems));
        }
        let Some(root) = parsed.root else {
            return Err(fail(vec![(Origin::default(), Problem::Empty)]));
        };
        let mut r = Reader {
            dir,
            problems: Vec::new(),
            inputs: Vec::new(),
        };
        let entries = r
            .mapping(&root, "", "the calibration file", TOP)
            .unwrap_or_default();
        let get = |k: &str| entries.iter().find(|(n, _)| *n == k).map(|(_, v)| *v);
        let mut cover = Cover::default();
        let text_of = |r: &mut Reader, k: &str| get(k).and_then(|v| r.text(v, k));
        cover.title = text_of(&mut r, "title");
        cover.customer = text_of(&mut r, "customer");
        cover.machine_serial = text_of(&mut r, "machine_serial");
        cover.instrument = text_of(&mut r, "instrument");
        cover.operator = text_of(&mut r, "operator");
        cover.date = text_of(&mut r, "date");
        cover.notes = text_of(&mut r, "notes");
        if let Some(t) = get("temperatures") {
            cover.temperatures = r.named_numbers(t, "temperatures");
        }
        let machine = r
            .required(get("machine"), &root, "", "machine", "the calibration file")
            .and_then(|m| r.file(m, "machine"));
        let params = get("params").map_or_else(Vec::new, |p| r.named_numbers(p, "params"));
        let mut positioning: Vec<AxisRuns> = Vec::new();
        if let Some(list) = get("positioning") {
            match list.as_sequence() {
                Some(items) => {
                    for (i, item) in items.iter().enumerate() {
                        let key = format!("positioning[{i}]");
                        if let Some(a) = axis_runs(&mut r, item, &key) {
                            if positioning.iter().any(|p| p.axis == a.axis) {
                                let axis = a.axis.clone();
                                r.refuse(item, &key, CalibrationProblem::AxisTwice { axis });
                            } else {
                                positioning.push(a);
                            }
                        }
                    }
                }
                None => r.wrong(list, "positioning", "a list of axes"),
            }
        }
        let values = get("values").and_then(|v| r.file(v, "values"));
        let identify = get("identify").and_then(|node| {
            let entries = r.mapping(node, "identify", "`identify`", IDENTIFY)?;
            let field = |k: &str| entries.iter().find(|(n, _)| *n == k).map(|(_, v)| *v);
            let measurements = r
                .required(field("measurements"), node, "identify", "measurements", "`identify`")
                .and_then(|f| r.file(f, "identify.measurements"));
            let seed = field("seed")
                .and_then(|s| r.whole(s, "identify.seed", 0.0, "a whole number, 0 or more"));
            // The holdout's own rule (`Holdout::check`), located here.
            let holdout = field("holdout").and_then(|h| {
                let fraction = r.number(h, "identify.holdout")?;
                let split = Holdout {
                    fraction,
                    seed: seed.unwrap_or(Holdout::DEFAULT_SEED),
                };
                match split.check() {
                    Ok(()) => Some(fraction),
                    Err(e) => {
                        let message = e.to_string();
                        r.refuse(h, "identify.holdout", CalibrationProblem::Refused { message });
                        None
                    }
                }
            });
            if let (Some(s), None) = (field("seed"), field("holdout")) {
                let problem = CalibrationProblem::Conflict {
                    key: "seed",
                    with: "no holdout",
                    why: "the seed chooses the records the holdout holds out: give `holdout` too",
                };
                r.refuse(s, "identify.seed", problem);
            }
            if let (Some(h), Some(_)) = (field("holdout"), field("validate")) {
                let problem = CalibrationProblem::Conflict {
                    key: "holdout",
                    with: "validate",
                    why: "one holds records of the measurements out, the other reads them from a file: give one",
                };
                r.refuse(h, "identify.holdout", problem);
            }
            let validate = field("validate").and_then(|v| r.file(v, "identify.validate"));
            let machine = field("machine").and_then(|v| r.file(v, "identify.machine"));
            Some(IdentifyPart {
                machine,
                measurements: measurements?,
                holdout,
                seed,
                validate,
            })
        });
        let export = get("export").and_then(|node| {
            let entries = r.mapping(node, "export", "`export`", EXPORT)?;
            let field = entries
                .iter()
                .find(|(n, _)| *n == "controller")
                .map(|(_, v)| *v);
            let c = r.required(field, node, "export", "controller", "`export`")?;
            let name = r.text(c, "export.controller")?;
            match ExportController::parse(&name) {
                Ok(controller) => {
                    if get("values").is_none() {
                        r.refuse(node, "export", CalibrationProblem::ExportWithoutValues);
                    }
                    Some(controller)
                }
                Err(e) => {
                    let message = e.to_string();
                    r.refuse(
                        c,
                        "export.controller",
                        CalibrationProblem::Controller { message },
                    );
                    None
                }
            }
        });
        let circular = get("circular").and_then(|node| {
            let entries = r.mapping(node, "circular", "`circular`", CIRCULAR)?;
            let field = |k: &str| entries.iter().find(|(n, _)| *n == k).map(|(_, v)| *v);
            let runs = r
                .required(field("runs"), node, "circular", "runs", "`circular`")
                .and_then(|f| r.file(f, "circular.runs"));
            let radius = field("radius").and_then(|v| r.positive(v, "circular.radius"));
            let feed = field("feed").and_then(|v| r.positive(v, "circular.feed"));
            let plane = field("plane").and_then(|v| {
                let text = r.text(v, "circular.plane")?;
                if Plane::parse(&text).is_some() {
                    Some(text)
                } else {
                    r.wrong(v, "circular.plane", "a plane: xy, yz or zx");
                    None
                }
            });
            Some(CircularPart {
                runs: runs?,
                radius,
                feed,
                plane,
            })
        });
        let thermal = get("thermal").and_then(|node| {
            let entries = r.mapping(node, "thermal", "`thermal`", THERMAL)?;
            let field = |k: &str| entries.iter().find(|(n, _)| *n == k).map(|(_, v)| *v);
            let runs = r
                .required(field("runs"), node, "thermal", "runs", "`thermal`")
                .and_then(|f| r.file(f, "thermal.runs"));
            let fit = field("fit")
                .and_then(|v| r.boolean(v, "thermal.fit"))
                .unwrap_or(true);
            let lag = field("lag")
                .and_then(|v| r.boolean(v, "thermal.lag"))
                .unwrap_or(false);
            let holdout = field("holdout").and_then(|h| {
                let v = r.number(h, "thermal.holdout")?;
                if v > 0.0 && v < 1.0 {
                    Some(v)
                } else {
                    let rule = "a fraction in (0, 1)";
                    r.refuse(
                        h,
                        "thermal.holdout",
                        CalibrationProblem::Range { value: v, rule },
                    );
                    None
                }
            });
            let sensors = field("sensors").and_then(|s| {
                let v = r.number(s, "thermal.sensors")?;
                if v >= 1.0 && v == v.trunc() && v < 1e9 {
                    Some(v as usize)
                } else {
                    let rule = "a whole number, 1 or more";
                    r.refuse(
                        s,
                        "thermal.sensors",
                        CalibrationProblem::Range { value: v, rule },
                    );
                    None
                }
            });
            Some(ThermalPart {
                runs: runs?,
                fit,
                holdout,
                lag,
                sensors,
            })
        });
        if !r.problems.is_empty() {
            return Err(fail(r.problems));
        }
        Ok(Calibration {
            file: file.to_string(),
            cover,
            machine: machine.expect("refused above when missing"),
            params,
            positioning,
            values,
            identify,
            export,
            circular,
            thermal,
            inputs: r.inputs,
        })
    }
}

/// One item of `positioning`.
fn axis_runs(r: &mut Reader<'_>, node: &Node, key: &str) -> Option<AxisRuns> {
    let entries = r.mapping(node, key, &format!("`{key}`"), AXIS)?;
    let field = |k: &str| entries.iter().find(|(n, _)| *n == k).map(|(_, v)| *v);
    let at = format!("`{key}`");
    let axis = r
        .required(field("axis"), node, key, "axis", &at)
        .and_then(|a| r.text(a, &join(key, "axis")));
    let runs = r
        .required(field("runs"), node, key, "runs", &at)
        .and_then(|f| r.file(f, &join(key, "runs")));
    let rotary = field("rotary")
        .and_then(|v| r.boolean(v, &join(key, "rotary")))
        .unwrap_or(false);
    let k = match field("k") {
        Some(v) => {
            let given = r.positive(v, &join(key, "k"));
            given.and_then(|k| Coverage::new(k).ok())
        }
        None => Some(Coverage::ISO),
    };
    let mut tolerances = Vec::new();
    if let Some(t) = field("tolerances") {
        let tkey = join(key, "tolerances");
        if let Some(entries) = r.mapping(t, &tkey, &format!("`{tkey}`"), &FIGURE_NAMES) {
            for (name, v) in entries {
                if let Some(x) = r.positive(v, &join(&tkey, name)) {
                    tolerances.push((name.to_string(), x));
                }
            }
        }
    }
    let temperature = match field("temperature") {
        Some(t) => {
            let tkey = join(key, "temperature");
            let entries = r.mapping(t, &tkey, &format!("`{tkey}`"), TEMPERATURE)?;
            let value = |r: &mut Reader, name: &'static str| {
                let v = entries.iter().find(|(n, _)| *n == name).map(|(_, v)| *v)?;
                r.number(v, &join(&tkey, name))
            };
            let at = format!("`{tkey}`");
            let axis_t = r
                .required(
                    entries.iter().find(|(n, _)| *n == "axis").map(|(_, v)| *v),
                    t,
                    &tkey,
                    "axis",
                    &at,
                )
                .and_then(|v| r.number(v, &join(&tkey, "axis")));
            let expansion = r
                .required(
                    entries
                        .iter()
                        .find(|(n, _)| *n == "expansion")
                        .map(|(_, v)| *v),
                    t,
                    &tkey,
                    "expansion",
                    &at,
                )
                .and_then(|v| r.number(v, &join(&tkey, "expansion")));
            Some(crate::ops::positioning::temperatures(
                axis_t?,
                expansion?,
                value(r, "instrument"),
                value(r, "instrument_expansion"),
                value(r, "temperature_uncertainty"),
                value(r, "expansion_uncertainty"),
            ))
        }
        None => None,
    };
    Some(AxisRuns {
        axis: axis?,
        runs: runs?,
        rotary,
        k: k?,
        tolerances,
        temperature,
    })
}
