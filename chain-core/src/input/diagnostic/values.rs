//! The rules of a values file and of the CSV tables it names (codes
//! `chain::values::*`).

use super::Description as D;
use crate::values::{BindError, NotAMotion, TableError};

/// One thing wrong with a values file (or a CSV table it names), worded by
/// [`ValuesProblem::describe`].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum ValuesProblem {
    /// The file holds no YAML document (or only `null`).
    Empty,
    /// A name that cannot take what it was given (the machine's rules).
    Bind(BindError),
    /// `machine` names another machine.
    MachineMismatch {
        /// The machine the file names.
        found: String,
        /// The machine's own name.
        machine: String,
    },
    /// A key of a table beside a constant `value`.
    KeyNotForConstant {
        /// The key.
        key: &'static str,
        /// The entry.
        name: String,
    },
    /// `carried_by` beside a `std`.
    CarriedWithStd {
        /// The entry.
        name: String,
    },
    /// `carried_by` that is not a non-empty list of names.
    CarriersNotList {
        /// The entry.
        name: String,
    },
    /// A carrier that is the entry itself or is named twice.
    CarrierTwice {
        /// The entry.
        name: String,
        /// The carrier.
        carrier: String,
    },
    /// A carrier that is no error parameter or coefficient of the machine.
    UnknownCarrier {
        /// The entry.
        name: String,
        /// The carrier as written.
        carrier: String,
        /// The closest name of the machine, if one is close.
        suggestion: Option<String>,
    },
    /// `carried_by` beside a table.
    CarriedOfTable {
        /// The entry.
        name: String,
    },
    /// `std` a number beside a CSV `table` (there it names a column).
    StdOfTable {
        /// The entry.
        name: String,
    },
    /// `std` beside `points`.
    StdOfPoints {
        /// The entry.
        name: String,
    },
    /// A key of a CSV `table` beside `points`.
    KeyNotForPoints {
        /// The key.
        key: &'static str,
        /// The entry.
        name: String,
        /// The key `points` takes instead.
        instead: &'static str,
    },
    /// A key of `points` beside a CSV `table`.
    KeyNotForCsv {
        /// The key.
        key: &'static str,
        /// The entry.
        name: String,
        /// The key a CSV `table` takes instead.
        instead: &'static str,
    },
    /// A negative standard deviation in a table.
    NegativeStd {
        /// Its value, in the file's units.
        value: f64,
    },
    /// A mapping without `value`, `points` or `table`.
    NoValue {
        /// The entry.
        name: String,
    },
    /// Points that are not a table.
    Table(TableError),
    /// A CSV table that cannot be read.
    TableFile {
        /// The path as written.
        file: String,
        /// The path read (relative to the values file's directory).
        path: String,
        /// Why.
        reason: String,
    },
    /// A CSV table without a column for the entry's axis variable.
    CsvNoVariable {
        /// The axis variable.
        variable: String,
        /// The entry.
        name: String,
        /// The values file that asks for it.
        file: String,
        /// The line of the values file that asks for it.
        line: usize,
        /// The header's names.
        columns: Vec<String>,
        /// The closest header name, if one is close.
        suggestion: Option<String>,
    },
    /// A CSV table without the column an entry names.
    CsvNoColumn {
        /// The CSV file.
        file: String,
        /// The column.
        column: String,
        /// The header's names.
        columns: Vec<String>,
        /// The closest header name, if one is close.
        suggestion: Option<String>,
        /// Whether the entry names it with `column` (else it is the entry's
        /// name).
        named: bool,
    },
    /// A CSV table in a build without the `csv` feature.
    CsvFeature,
}

impl ValuesProblem {
    /// Every part of the message of this problem: one match arm per
    /// variant.
    pub fn describe(&self) -> D {
        match self {
            ValuesProblem::Empty => D::new("chain::values::empty", "empty", "the values file is empty")
                .help("expected a mapping with `machine` and `values`".to_string()),
            ValuesProblem::Bind(e) => bind(e),
            ValuesProblem::MachineMismatch { found, machine } => D::new(
                "chain::values::machine_mismatch",
                "other machine",
                format!("these values are for machine `{found}`, not `{machine}`"),
            )
            .help(format!(
                "a values file belongs to one machine file; this one's `machine` is `{machine}`"
            )),
            ValuesProblem::KeyNotForConstant { key, name } => D::new(
                "chain::values::key_not_for_constant",
                "not a table",
                format!("`{key}` belongs to a table; `{name}` is given a `value`"),
            ),
            ValuesProblem::CarriedWithStd { name } => D::new(
                "chain::values::carried_with_std",
                "carried and a std",
                format!("`{name}` is given both a `std` and `carried_by`"),
            )
            .help("`carried_by` says its spread is held by the estimates it names (an error identification fixed because others carry its effect); a `std` gives it a spread of its own: keep one".to_string()),
            ValuesProblem::CarriersNotList { name } => D::new(
                "chain::values::carriers_not_list",
                "not a list of names",
                format!("`carried_by` of `{name}` must be a list of error names"),
            )
            .help("write `carried_by: [NAME, ...]`, the estimated errors that carry its effect".to_string()),
            ValuesProblem::CarrierTwice { name, carrier } => D::new(
                "chain::values::carrier_twice",
                "named again",
                if carrier == name {
                    format!("`{name}` cannot carry itself")
                } else {
                    format!("`{carrier}` is named twice in `carried_by` of `{name}`")
                },
            ),
            ValuesProblem::UnknownCarrier { name, carrier, suggestion } => {
                let d = D::new(
                    "chain::values::unknown_carrier",
                    "unknown error",
                    format!("`{carrier}` in `carried_by` of `{name}` is not an error parameter of this machine"),
                );
                match suggestion {
                    Some(s) => d.help(format!("did you mean `{s}`?")),
                    None => d.help("`carried_by` names error parameters or coefficients of the machine file".to_string()),
                }
            }
            ValuesProblem::CarriedOfTable { name } => D::new(
                "chain::values::carried_of_table",
                "not a constant",
                format!("`carried_by` belongs to a constant `value`; `{name}` is given a table"),
            ),
            ValuesProblem::StdOfTable { name } => D::new(
                "chain::values::key_not_for_table",
                "not a column name",
                format!("`std` of a CSV table names the column of standard deviations; `{name}` is given a table, not a constant `value`"),
            )
            .help("write `std: COLUMN` (a column of per-position standard deviations), or give a constant as `{value: V, std: S}`".to_string()),
            ValuesProblem::StdOfPoints { name } => D::new(
                "chain::values::key_not_for_table",
                "not a constant",
                format!("`std` belongs to a constant `value` or a CSV `table`; `{name}` is given `points`"),
            )
            .help("per-position standard deviations of `points` are `std_points: [[q, s], ...]`".to_string()),
            ValuesProblem::KeyNotForPoints { key, name, instead } => D::new(
                "chain::values::key_not_for_points",
                "not a CSV table",
                format!("`{key}` belongs to a CSV `table`; `{name}` is given `points`"),
            )
            .help(format!("with `points`, write `{instead}`")),
            ValuesProblem::KeyNotForCsv { key, name, instead } => D::new(
                "chain::values::key_not_for_csv",
                "not points",
                format!("`{key}` belongs to `points`; `{name}` is given a CSV `table`"),
            )
            .help(format!("with `table`, write `{instead}`")),
            ValuesProblem::NegativeStd { value } => D::new(
                "chain::values::negative_std",
                "negative",
                format!("a standard deviation must be ≥ 0, got {value}"),
            ),
            ValuesProblem::NoValue { name } => D::new(
                "chain::values::no_value",
                "no value",
                format!("`{name}` needs a `value`, `points` or a `table`"),
            )
            .help("write a number, `{value: V}`, `{points: [[q, v], ...]}` or `{table: FILE.csv, column: NAME}`".to_string()),
            ValuesProblem::Table(e) => table(e),
            ValuesProblem::TableFile { file, path, reason } => D::new(
                "chain::values::table_file",
                "table file",
                format!("cannot read the table `{file}` ({path}): {reason}"),
            )
            .help("table paths are relative to the values file's directory".to_string()),
            ValuesProblem::CsvNoVariable {
                variable,
                name,
                file,
                line,
                columns,
                suggestion,
            } => D::new(
                "chain::values::csv_no_variable",
                "header",
                D::suggesting(
                    format!("the header has no column `{variable}` for the axis variable of `{name}` (asked for in {file}:{line})"),
                    suggestion,
                ),
            )
            .help(format!(
                "the header names the axis variable `{variable}` (positions in the machine's units) and the value columns; it has {}",
                columns.join(", ")
            )),
            ValuesProblem::CsvNoColumn {
                file,
                column,
                columns,
                suggestion,
                named,
            } => D::new(
                "chain::values::csv_no_column",
                "no such column",
                D::suggesting(format!("`{file}` has no column `{column}`"), suggestion),
            )
            .help(format!(
                "its header has {}{}",
                columns.join(", "),
                if *named {
                    ""
                } else {
                    "; without `column`, the column is the entry's name"
                }
            )),
            ValuesProblem::CsvFeature => D::new(
                "chain::values::csv_feature",
                "CSV table",
                "reading a CSV table needs chain-core's `csv` feature, which this build does not have",
            )
            .help("enable the feature (`chain-core = { features = [\"csv\"] }`; the `chain` binary has it), or give the table as `points: [[q, v], ...]`".to_string()),
        }
    }
}

/// A [`BindError`] as a values file's message: its `Display` as the
/// headline.
fn bind(e: &BindError) -> D {
    let text = e.to_string();
    match e {
        BindError::UnknownName { suggestion, .. } => D::new(
            "chain::values::unknown_name",
            "unknown name",
            D::suggesting(text, suggestion),
        )
        .help("values names the machine's error parameters, coefficients (`<F>_<k>`) and function slots (`F`)".to_string()),
        BindError::FunctionConstant { name, coefficients } => D::new(
            "chain::values::function_constant",
            "function slot",
            text,
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
                NotAMotion::Thermal { .. } => "give each thermal coefficient a number, its value per kelvin (docs/thermal.md); the error at a temperature is that value times the sensor's deviation from its reference".to_string(),
                _ => "only an error motion (an error in the `errors` of one body with a joint) varies along an axis; give a number".to_string(),
            };
            D::new("chain::values::not_a_motion", "not an error motion", text).help(help)
        }
        BindError::NoConstantTerm { .. } => D::new(
            "chain::values::no_constant_term",
            "no constant term",
            text,
        )
        .help("give its coefficients instead, or give the slot a constant term in the machine file (`powers` with 0, or `from: 0`)".to_string()),
        BindError::CoefficientAndFunction { .. } => D::new(
            "chain::values::coefficient_and_function",
            "given twice",
            text,
        )
        .help("a function slot is either tabulated as a whole or given by its coefficients".to_string()),
        BindError::NotFinite { .. } => D::new("chain::values::not_finite", "not finite", text),
        BindError::ReverseStdWithoutReverse { .. } => D::new(
            "chain::values::reverse_std_without_reverse",
            "no reverse direction",
            text,
        )
        .help("give the reverse direction too (`reverse` or `reverse_points`), or one `std` for both directions".to_string()),
        BindError::ReverseStdWithoutStd { .. } => D::new(
            "chain::values::reverse_std_without_std",
            "no main std",
            text,
        )
        .help("give the main direction's standard deviations too (`std` or `std_points`)".to_string()),
        BindError::NegativeStd { .. } => D::new("chain::values::negative_std", "negative std", text),
    }
}

/// Why points are not a table, as a values file's message.
fn table(e: &TableError) -> D {
    match *e {
        TableError::TooFewPoints { found } => D::new(
            "chain::values::too_few_points",
            "table",
            format!("a table needs at least 2 points to interpolate between, found {found}"),
        )
        .help("a constant error is a number, not a table".to_string()),
        TableError::NotFinite { .. } => D::new("chain::values::not_finite", "table", e.to_string()),
        TableError::NotIncreasing { q, previous, .. } if q == previous => D::new(
            "chain::values::duplicate_position",
            "table",
            format!("position q = {q} appears twice"),
        )
        .help(INCREASING.to_string()),
        TableError::NotIncreasing { q, previous, .. } => D::new(
            "chain::values::unsorted_positions",
            "table",
            format!("the positions must increase: q = {q} comes after q = {previous}"),
        )
        .help(INCREASING.to_string()),
    }
}

/// The help of positions out of order.
const INCREASING: &str = "list the points by increasing q, each position once";
