//! The machine-file loader: YAML text → validated [`Machine`].
//!
//! [`load_str`], [`load_bytes`] and [`load_file`] parse a machine file
//! (contract: `docs/yaml.md` and the machine-format spec, section 2), check
//! every rule of the contract and either return the [`Machine`] or *all* the
//! errors found as [`Diagnostics`], each naming file, line, column and key.
//! One mistake gives one message: a body with an unknown parent is not also
//! reported as unreachable, statistics for an error whose slot was misspelt
//! are not also reported as unknown, and so on.
//!
//! The validation works on the located tree of [`crate::yaml`] and is exposed
//! as [`from_tree`], so another front end that builds such a tree can reuse it.
//!
//! Orders of the produced machine:
//! - bodies in tree pre-order from the root, children in file order (index 0
//!   is the root, parents come before children);
//! - variables in that body order;
//! - errors in order of first use, walking the bodies in that order and,
//!   within a body, `location_errors` (`dx..ez`), then `errors` (`dx..ez`),
//!   then `squareness` (`ex, ey, ez`); a function slot's coefficients in
//!   its basis order at the place of its first use, `errors: iso` as the
//!   six slots `dx..ez`;
//! - function slots in order of first declaration, in the same walk;
//! - parameters, statistics, reliability tolerances and grid axes in file
//!   order.

mod bodies;
pub(crate) mod reader;
mod sections;

use std::collections::{HashMap, HashSet};
use std::path::Path;

use crate::diagnostic::{closest, Diagnostics, LoadError, Problem};
use crate::expr;
use crate::model::{Expr, Frame, Machine, Origin, Parameter};
use crate::yaml::{self, Node};
use reader::{index, join, start_origin, Fields, TreeReader};

/// Files larger than this many bytes are refused by [`load_file`].
pub const MAX_FILE_BYTES: usize = crate::bounded::MACHINE_BYTES;

/// Keys allowed at the top level of a machine file.
pub const TOP_KEYS: &[&str] = &[
    "machine",
    "description",
    "parameters",
    "bodies",
    "workpiece",
    "tool",
    "tool_point",
    "frame",
    "statistics",
    "correlation",
    "reliability",
    "sensors",
];

/// The highest degree, harmonic count or power of a function slot
/// (measured-machines spec, section 1).
pub const MAX_ORDER: u32 = 12;

/// The largest magnitude of a length or a parameter in a machine file
/// (offsets, the tool point, DH `a`/`d`, parameter values; and `--param`):
/// 10⁶, a kilometre in mm (a million degrees for an angle). Nothing a
/// machine holds comes near it; a value beyond it is a slip (a unit or an
/// exponent) and would make every tolerance of the inverse kinematics and
/// the reliability meaningless, so it is refused where it is written.
pub const PHYSICAL_SIZE: f64 = 1e6;

/// The range [`PHYSICAL_SIZE`] allows, in words.
pub const PHYSICAL_RANGE: &str = "[-1e6, 1e6] (a kilometre in mm: beyond any machine)";

/// Names the expression language reserves.
pub const RESERVED: &[&str] = &["pi", "sin", "cos"];

/// Loads a machine from YAML text. `file` names the text in diagnostics.
pub fn load_str(text: &str, file: &str) -> Result<Machine, Diagnostics> {
    if let Some(offset) = text.find('\0') {
        return Err(binary(text.as_bytes(), offset, file));
    }
    let parsed = yaml::parse(text);
    let mut errors: Vec<LoadError> = parsed
        .errors
        .into_iter()
        .map(|(span, key, problem)| LoadError::new(file, span.origin(key), problem))
        .collect();
    let machine = match &parsed.root {
        None => {
            if errors.is_empty() {
                errors.push(LoadError::new(file, start_origin(""), Problem::Empty));
            }
            None
        }
        Some(root) => match from_tree(root) {
            Ok(m) => Some(m),
            Err(found) => {
                errors.extend(
                    found
                        .into_iter()
                        .map(|(origin, problem)| LoadError::new(file, origin, problem)),
                );
                None
            }
        },
    };
    match (machine, Diagnostics::new(file, text, errors)) {
        (_, Some(d)) => Err(d),
        (Some(mut m), None) => {
            m.file = Some(file.to_string());
            Ok(m)
        }
        (None, None) => Err(Diagnostics::single(
            file,
            text,
            start_origin(""),
            Problem::Empty,
        )),
    }
}

/// Loads a machine from the bytes of a file: a NUL byte (binary file) or
/// invalid UTF-8 is a diagnostic, like every other problem.
pub fn load_bytes(bytes: &[u8], file: &str) -> Result<Machine, Diagnostics> {
    load_str(decode(bytes, file)?, file)
}

/// Loads a machine file. A file that cannot be read (missing, a directory,
/// larger than [`MAX_FILE_BYTES`]) is a diagnostic too.
pub fn load_file(path: &Path) -> Result<Machine, Diagnostics> {
    load_file_with_text(path).map(|(machine, _)| machine)
}

/// [`load_file`], with the file's text read once for the messages that
/// quote it later (a reliability error located in the file).
pub fn load_file_with_text(path: &Path) -> Result<(Machine, String), Diagnostics> {
    let file = path.display().to_string();
    let bytes = read_file(path, &file, MAX_FILE_BYTES)?;
    let machine = load_str(decode(&bytes, &file)?, &file)?;
    // `decode` accepted the bytes as UTF-8.
    let text = String::from_utf8(bytes).unwrap_or_default();
    Ok((machine, text))
}

/// The bytes of the file at `path` (named `file` in diagnostics), at most
/// `limit` of them: a file that cannot be read or is larger is a diagnostic.
pub(crate) fn read_file(path: &Path, file: &str, limit: usize) -> Result<Vec<u8>, Diagnostics> {
    crate::bounded::read_path(path, limit).map_err(|e| {
        let problem = match e {
            crate::bounded::ReadError::TooLarge { limit } => Problem::TooLarge { limit },
            crate::bounded::ReadError::Io(e) => Problem::Io {
                message: e.to_string(),
            },
        };
        Diagnostics::single(file, "", Origin::default(), problem)
    })
}

/// The text of a file's bytes: a NUL byte (binary file) or invalid UTF-8 is
/// a located diagnostic.
pub fn decode<'b>(bytes: &'b [u8], file: &str) -> Result<&'b str, Diagnostics> {
    if let Some(offset) = bytes.iter().position(|&b| b == 0) {
        return Err(binary(bytes, offset, file));
    }
    std::str::from_utf8(bytes).map_err(|e| {
        let offset = e.valid_up_to();
        let lossy = String::from_utf8_lossy(bytes).into_owned();
        Diagnostics::single(
            file,
            lossy,
            byte_origin(bytes, offset, 1),
            Problem::InvalidUtf8 { offset },
        )
    })
}

/// The origin of byte `offset` of raw bytes (line and column counted on the
/// lossily decoded prefix).
fn byte_origin(bytes: &[u8], offset: usize, len: usize) -> Origin {
    let prefix = bytes.get(..offset).unwrap_or(bytes);
    let line_start = prefix
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(0, |p| p + 1);
    let line = prefix.iter().filter(|&&b| b == b'\n').count() + 1;
    let column = String::from_utf8_lossy(prefix.get(line_start..).unwrap_or(&[]))
        .chars()
        .count()
        + 1;
    Origin {
        offset,
        len,
        line,
        column,
        key: String::new(),
    }
}

fn binary(bytes: &[u8], offset: usize, file: &str) -> Diagnostics {
    Diagnostics::single(
        file,
        String::new(),
        byte_origin(bytes, offset, 1),
        Problem::Binary { offset },
    )
}

/// Validates a located YAML tree (the document root) and builds the machine.
/// Returns every problem found, each with its origin. `Machine::file` is left
/// `None`.
pub fn from_tree(root: &Node) -> Result<Machine, Vec<(Origin, Problem)>> {
    let mut l = Loader::default();
    let machine = l.machine(root);
    match machine {
        Some(m) if l.errors.is_empty() => Ok(m),
        _ => {
            if l.errors.is_empty() {
                // Defensive: a rule failed without saying why.
                l.errors.push((
                    root.span.origin(""),
                    Problem::WrongType {
                        expected: "a valid machine",
                        found: root.describe(),
                    },
                ));
            }
            Err(l.errors)
        }
    }
}

/// True for `[A-Za-z_][A-Za-z0-9_]*`.
pub fn is_identifier(name: &str) -> bool {
    let mut chars = name.chars();
    chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// Validation state: problems found and what is known so far.
#[derive(Default)]
struct Loader {
    errors: Vec<(Origin, Problem)>,
    parameters: Vec<Parameter>,
    /// Parameter name → index into `parameters`.
    parameter_index: HashMap<String, usize>,
    /// Variable names seen in any joint, valid or not (no-cascade checks).
    seen_variables: HashSet<String>,
    /// Error names seen in any slot, valid or not (no-cascade checks).
    seen_errors: HashSet<String>,
    /// Names of function slots that were refused (already reported): neither
    /// they nor `<name>_…` are reported again in `statistics`.
    failed_functions: HashSet<String>,
    /// The `sensors` section (read before the bodies, whose thermal terms
    /// name them).
    sensors: Vec<crate::model::Sensor>,
    /// The `statistics` entries of sensors.
    sensor_statistics: Vec<crate::model::SensorStatistic>,
}

impl TreeReader for Loader {
    fn problems(&mut self) -> &mut Vec<(Origin, Problem)> {
        &mut self.errors
    }
}

impl Loader {
    /// A name usable in expressions: an identifier, not reserved.
    fn ident(&mut self, node: &Node, path: &str, what: &'static str) -> Option<String> {
        let name = self.name(node, path, "a name")?;
        if !is_identifier(&name) {
            self.report(node.span, path, Problem::InvalidName { name, what });
            return None;
        }
        if RESERVED.contains(&name.as_str()) {
            self.report(node.span, path, Problem::ReservedName { name });
            return None;
        }
        Some(name)
    }

    /// A positive, finite number.
    fn positive(&mut self, node: &Node, path: &str, what: &'static str) -> Option<f64> {
        let v = self.number(node, path)?;
        if v > 0.0 && v.is_finite() {
            Some(v)
        } else {
            self.report(node.span, path, Problem::NotPositive { what, value: v });
            None
        }
    }

    /// A finite number.
    fn finite(&mut self, node: &Node, path: &str, what: &'static str) -> Option<f64> {
        let v = self.number(node, path)?;
        if v.is_finite() {
            Some(v)
        } else {
            self.report(node.span, path, Problem::NotFinite { what });
            None
        }
    }

    /// An expression over numbers and parameters.
    fn expr(&mut self, node: &Node, path: &str) -> Option<Expr> {
        let text = self.text(node, path, "a number or an expression", |_| true)?;
        let ast = match expr::parse(&text) {
            Ok(a) => a,
            Err(e) => {
                self.expr_error(node, path, e);
                return None;
            }
        };
        let params = &self.parameters;
        let index = &self.parameter_index;
        let seen_errors = &self.seen_errors;
        let variables = &self.seen_variables;
        let resolved = expr::resolve(&ast, |name| {
            if let Some(&i) = index.get(name) {
                return Ok(Some(i));
            }
            let hint = if variables.contains(name) {
                Some(format!(
                    "`{name}` is an axis variable; offsets and the tool point cannot depend on axis variables"
                ))
            } else if seen_errors.contains(name) {
                Some(format!(
                    "`{name}` is an error parameter; errors go in `errors`, not in expressions"
                ))
            } else {
                closest(name, params.iter().map(|p| p.name.as_str()))
                    .map(|s| format!("did you mean `{s}`?"))
            };
            Err(Problem::UnknownName {
                name: name.to_string(),
                hint,
            })
        });
        match resolved {
            Ok(e) => {
                if let Expr::Num(v) = e {
                    if !v.is_finite() {
                        self.report(node.span, path, Problem::NotFinite { what: "the value" });
                        return None;
                    }
                    if v.abs() > PHYSICAL_SIZE {
                        let problem = Problem::OutOfRange {
                            what: "a length (mm)",
                            value: v,
                            range: PHYSICAL_RANGE,
                        };
                        self.report(node.span, path, problem);
                        return None;
                    }
                }
                Some(e)
            }
            Err(errs) => {
                for (offset, p) in errs {
                    self.report(node.span_at(offset), path, p);
                }
                None
            }
        }
    }

    /// A list of three expressions (`offset`, `tool_point`); absent is zero.
    fn vec3(&mut self, node: Option<&Node>, path: &str) -> Option<[Expr; 3]> {
        let Some(node) = node else {
            return Some([Expr::Num(0.0), Expr::Num(0.0), Expr::Num(0.0)]);
        };
        let [a, b, c] = self.items(node, path, "a list of 3 numbers or expressions")?;
        let x = self.expr(a, &index(path, 0));
        let y = self.expr(b, &index(path, 1));
        let z = self.expr(c, &index(path, 2));
        Some([x?, y?, z?])
    }

    /// The whole machine.
    fn machine(&mut self, root: &Node) -> Option<Machine> {
        let top = self.top(root, TOP_KEYS)?;

        let name = self.required(&top, "machine");
        let name = name.and_then(|n| self.name(n, "machine", "a name"));
        let description = match top.get("description") {
            Some(n) => match n.as_str() {
                Some(s) => Some(s.to_string()),
                None => {
                    self.report(
                        n.span,
                        "description",
                        Problem::WrongType {
                            expected: "a string",
                            found: n.describe(),
                        },
                    );
                    None
                }
            },
            None => None,
        };

        if let Some(p) = top.get("parameters") {
            self.parameters_section(p);
        }
        if let Some(n) = top.get("sensors") {
            self.sensors_section(n);
        }

        let tree = match top.entry("bodies") {
            Some((k, v)) => self.bodies_section(k, v),
            None => {
                self.missing(&top, "bodies");
                None
            }
        };
        let workpiece = self.body_ref(&top, "workpiece", tree.as_ref());
        let tool = self.body_ref(&top, "tool", tree.as_ref());
        if let (Some(w), Some(t)) = (&workpiece, &tool) {
            if w == t {
                let node = top.get("tool").map_or(top.owner, |n| n.span);
                self.report(node, "tool", Problem::WorkpieceIsTool { name: t.clone() });
            }
        }

        let tool_point = self.vec3(top.get("tool_point"), "tool_point");
        let frame = match top.get("frame") {
            Some(n) => match self.keyword(n, "frame", "frame", &["workpiece", "tool"]) {
                Some("tool") => Some(Frame::Tool),
                Some(_) => Some(Frame::Workpiece),
                None => None,
            },
            None => Some(Frame::Workpiece),
        };

        let statistics = match top.get("statistics") {
            Some(n) => self.statistics_section(n, tree.as_ref()),
            None => Some(Vec::new()),
        };
        let correlations = match top.get("correlation") {
            Some(n) => self.correlation_section(n, statistics.as_deref(), tree.as_ref()),
            None => Some(Vec::new()),
        };
        let reliability = match top.entry("reliability") {
            Some((k, v)) => self.reliability_section(k, v, tree.as_ref()).map(Some),
            None => Some(None),
        };

        let tree = tree.filter(|t| t.ok)?;
        let workpiece = tree.index_of(&workpiece?)?;
        let tool = tree.index_of(&tool?)?;
        Some(Machine {
            name: name?,
            description,
            file: None,
            parameters: std::mem::take(&mut self.parameters),
            variables: tree.variables,
            errors: tree.errors,
            functions: tree.functions,
            bodies: tree.bodies,
            workpiece,
            tool,
            tool_point: tool_point?,
            frame: frame?,
            statistics: statistics?,
            reliability: reliability?,
            correlations: correlations?,
            sensors: std::mem::take(&mut self.sensors),
            sensor_statistics: std::mem::take(&mut self.sensor_statistics),
        })
    }

    /// `workpiece` / `tool`: the body name, if given and a body of the
    /// machine (or if the bodies could not be checked).
    fn body_ref(
        &mut self,
        top: &Fields<'_>,
        key: &'static str,
        tree: Option<&bodies::Tree>,
    ) -> Option<String> {
        let Some(node) = top.get(key) else {
            self.missing(top, key);
            return None;
        };
        let name = self.name(node, key, "a body name")?;
        let Some(tree) = tree else {
            return Some(name);
        };
        if tree.all_names.contains(&name) {
            return Some(name);
        }
        let suggestion =
            closest(&name, tree.all_names.iter().map(String::as_str)).map(str::to_string);
        self.report(
            node.span,
            key,
            Problem::UnknownBody {
                role: key,
                name,
                suggestion,
            },
        );
        None
    }
}

#[cfg(test)]
mod tests;
