//! The reader of a values file: one pass over the located YAML tree, every
//! refusal located in the values file or in the CSV table it concerns.

use std::path::{Path, PathBuf};

use super::{
    AngularUnit, BindError, LinearUnit, Motion, Sourced, Table, TableError, Values, ValuesBuilder,
    ValuesError, MAX_VALUES_BYTES,
};
use super::{Extrapolation, Interpolation};
use crate::diagnostic::{closest, Diagnostics, Problem, ValuesProblem};
use crate::load::reader::{index, join, start_origin, Fields, TreeReader};
use crate::model::{Machine, Origin};
use crate::yaml::{self, Node};

/// Keys allowed at the top level of a values file (`correlation`, written by
/// `chain identify`, is accepted and ignored).
pub const TOP_KEYS: &[&str] = &["machine", "description", "units", "values", "correlation"];
/// Keys of `units`.
pub const UNITS_KEYS: &[&str] = &["linear", "angular"];
/// Keys of one entry of `values` given as a mapping; those after `table`
/// are a table's options (refused beside a `value`).
pub const ENTRY_KEYS: &[&str] = &[
    "value",
    "std",
    "carried_by",
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
/// Linear units.
pub const LINEAR_UNITS: &[&str] = &["mm", "um"];
/// Angular units.
pub const ANGULAR_UNITS: &[&str] = &["rad", "urad", "arcsec", "deg"];
/// Values of `interpolation`.
pub const INTERPOLATIONS: &[&str] = &["linear", "cubic"];
/// Values of `extrapolate`.
pub const EXTRAPOLATIONS: &[&str] = &["error", "hold"];

impl Values {
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
                    let empty = ValuesProblem::Empty.into();
                    r.problems.push((start_origin(""), empty));
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
}

/// A located [`BindError`]: the message of a values file.
fn bind_problem(e: &BindError) -> Problem {
    ValuesProblem::Bind(e.clone()).into()
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
    Read(std::rc::Rc<super::csv::CsvFile>),
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
                    let mismatch = ValuesProblem::MachineMismatch {
                        found: name,
                        machine: machine.name.clone(),
                    };
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
            if let Err(e) = b.constant_with(
                name,
                value * factor,
                None,
                Vec::new(),
                Some(key_origin.clone()),
            ) {
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
            // The table's own options: every entry key after `table`.
            let options = ENTRY_KEYS.iter().skip_while(|k| **k != "table").skip(1);
            for &extra in options {
                if let Some((kn, _)) = fields.entry(extra) {
                    let not = ValuesProblem::KeyNotForConstant {
                        key: extra,
                        name: name.to_string(),
                    };
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
            let Some(carried_by) = self.carriers(name, &fields, std.is_some(), m) else {
                return;
            };
            let origin = Some(key_origin.clone());
            if let Err(e) = b.constant_with(name, v * factor, std, carried_by, origin) {
                self.problems.push((key_origin, bind_problem(&e)));
            }
            return;
        }
        if let Some((kn, _)) = fields.entry("carried_by") {
            let name = name.to_string();
            let not = ValuesProblem::CarriedOfTable { name };
            self.report(kn.span, fields.path("carried_by"), not.into());
            return;
        }
        if fields.get("points").is_none() {
            let number = |n: &Node| n.as_str().is_none_or(|t| t.trim().parse::<f64>().is_ok());
            if let Some((_, sn)) = fields.entry("std").filter(|(_, n)| number(n)) {
                let name = name.to_string();
                let not = ValuesProblem::StdOfTable { name };
                self.report(sn.span, fields.path("std"), not.into());
                return;
            }
        } else if let Some((kn, _)) = fields.entry("std") {
            let name = name.to_string();
            let not = ValuesProblem::StdOfPoints { name };
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
                    let value = (spec.points.iter())
                        .find(|((_, v), _)| *v < 0.0)
                        .map_or(0.0, |p| p.0 .1 / factor);
                    let neg = ValuesProblem::NegativeStd { value };
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
    /// The `carried_by` list of constant `name` (docs/posterior.md, "Fixed
    /// and carried"): the machine's error parameters or coefficients, other
    /// than `name`, each named once; refused beside a `std`. `None` when
    /// something was reported.
    fn carriers(
        &mut self,
        name: &str,
        fields: &Fields<'_>,
        has_std: bool,
        m: &Machine,
    ) -> Option<Vec<String>> {
        let Some((kn, list)) = fields.entry("carried_by") else {
            return Some(Vec::new());
        };
        let path = fields.path("carried_by");
        if has_std {
            let name = name.to_string();
            self.report(kn.span, path, ValuesProblem::CarriedWithStd { name }.into());
            return None;
        }
        let Some(items) = list.as_sequence().filter(|items| !items.is_empty()) else {
            let name = name.to_string();
            let not = ValuesProblem::CarriersNotList { name };
            self.report(list.span, path, not.into());
            return None;
        };
        let mut carriers: Vec<String> = Vec::with_capacity(items.len());
        let mut fine = true;
        for (i, item) in items.iter().enumerate() {
            let at = index(&path, i);
            let carrier = item.as_str().unwrap_or("").to_string();
            let problem = if carrier.is_empty() {
                Some(ValuesProblem::CarriersNotList {
                    name: name.to_string(),
                })
            } else if carrier == name || carriers.contains(&carrier) {
                Some(ValuesProblem::CarrierTwice {
                    name: name.to_string(),
                    carrier: carrier.clone(),
                })
            } else if m.error_index(&carrier).is_none() {
                let names = m.errors.iter().map(|e| e.name.as_str());
                Some(ValuesProblem::UnknownCarrier {
                    name: name.to_string(),
                    suggestion: closest(&carrier, names).map(str::to_string),
                    carrier: carrier.clone(),
                })
            } else {
                None
            };
            match problem {
                Some(p) => {
                    self.report(item.span, at, p.into());
                    fine = false;
                }
                None => carriers.push(carrier),
            }
        }
        fine.then_some(carriers)
    }

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
                let (key, name, instead) = (other, name.to_string(), part.key(in_points));
                let problem = if in_points {
                    ValuesProblem::KeyNotForPoints { key, name, instead }
                } else {
                    ValuesProblem::KeyNotForCsv { key, name, instead }
                };
                self.report(kn.span, fields.path(other), problem.into());
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
            let missing = ValuesProblem::NoValue {
                name: name.to_string(),
            };
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
        let index = match *e {
            TableError::TooFewPoints { .. } => None,
            TableError::NotFinite { index, .. } | TableError::NotIncreasing { index, .. } => {
                Some(index)
            }
        };
        let problem: Problem = ValuesProblem::Table(*e).into();
        let at = index
            .and_then(|i| spec.points.get(i))
            .map(|(_, o)| o.clone());
        match at {
            Some(origin) => self.locate(&spec.csv, origin, problem),
            None => {
                let in_points = spec.csv.is_none();
                let key_path = match fields.entry(part.key(in_points)) {
                    Some(_) => part.key(in_points),
                    None if in_points => "points",
                    None => "table",
                };
                let (kn, _) = fields.entry(key_path).map_or((key, key), |e| e);
                self.report(kn.span, fields.path(key_path), problem);
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
        use super::csv::{CsvFile, CsvOpenError};
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
                let unread = ValuesProblem::TableFile {
                    file: file.to_string(),
                    path: shown,
                    reason: why.clone(),
                };
                self.report(table_node.span, fields.path("table"), unread.into());
                return None;
            }
            CsvRead::Invalid => return None,
        };
        let Some(qc) = csv.column(var_name) else {
            let missing = ValuesProblem::CsvNoVariable {
                variable: var_name.to_string(),
                name: name.to_string(),
                file: self.file.clone(),
                line: table_node.span.line,
                columns: csv.names().map(str::to_string).collect(),
                suggestion: crate::diagnostic::closest(var_name, csv.names()).map(str::to_string),
            };
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
            let missing = ValuesProblem::CsvNoColumn {
                file: shown,
                columns: csv.names().map(str::to_string).collect(),
                suggestion: crate::diagnostic::closest(&column, csv.names()).map(str::to_string),
                column,
                named: column_node.is_some(),
            };
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
        let off = ValuesProblem::CsvFeature.into();
        self.report(table_node.span, fields.path("table"), off);
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
            bad.push((origin.clone(), problem.into()));
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
