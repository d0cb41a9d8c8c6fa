//! The errors of the swing-angle workflow, each naming its file and line.
//!
//! The library returns them; only the `chain` binary renders them (miette,
//! with the `cli` feature).

use super::MAX_SUPPORTED_ORDER;
use chain_core::diagnostic::shortened;

/// A refusal of the shared CSV reader: `file:line: message`, with the
/// reader's diagnostic code (`chain::csv::ragged`, ...).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{file}:{line}: {message}")]
pub struct TableRefusal {
    /// The file.
    pub file: String,
    /// The line (1-based).
    pub line: usize,
    /// What is wrong (the reader's headline).
    pub message: String,
    /// The reader's code.
    pub code: &'static str,
}

impl TableRefusal {
    /// The first refusal of the reader's diagnostics.
    pub fn of(file: &str, d: &chain_core::diagnostic::Diagnostics) -> TableRefusal {
        let first = d.first();
        TableRefusal {
            file: file.to_string(),
            line: first.origin.line,
            message: first.problem.headline(),
            code: first.problem.code(),
        }
    }
}

#[cfg(feature = "cli")]
impl miette::Diagnostic for TableRefusal {
    fn code<'a>(&'a self) -> Option<Box<dyn std::fmt::Display + 'a>> {
        Some(Box::new(self.code))
    }
}

/// Errors of reading, analysing and exporting swing-angle measurements.
///
/// Every error about the input names the file and, where there is one, the
/// line (1-based, as an editor shows it) and the column.
#[derive(Debug, thiserror::Error)]
#[cfg_attr(feature = "cli", derive(miette::Diagnostic))]
#[non_exhaustive]
pub enum CompensateError {
    /// The file could not be read (reported by the reader that hands its
    /// rows to [`Measurements::from_records`](super::Measurements::from_records)).
    #[error("{file}: cannot read the file: {source}")]
    #[cfg_attr(feature = "cli", diagnostic(code(chain::compensate::io)))]
    Io {
        /// The file.
        file: String,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// The file is larger than the bound of its kind
    /// (`chain_core::bounded::COMPENSATE_BYTES`).
    #[error("{file}: the file is too large (more than {})", chain_core::bounded::describe(*limit))]
    #[cfg_attr(feature = "cli", diagnostic(code(chain::too_large)))]
    TooLarge {
        /// The file.
        file: String,
        /// The bound in bytes.
        limit: usize,
    },
    /// The file has no header line.
    #[error("{file}:1: the file is empty; expected a header line `theta_deg,z1,z3` (optionally with `z2`)")]
    #[cfg_attr(feature = "cli", diagnostic(code(chain::csv::empty)))]
    Empty {
        /// The file.
        file: String,
    },
    /// The file is not a CSV table (not UTF-8 text, malformed, a row of
    /// another width than the header, a header name missing or repeated):
    /// a refusal of the reader every CSV input shares
    /// (`chain_core::values::csv::CsvFile`), in its words and with its code.
    #[error(transparent)]
    #[cfg_attr(feature = "cli", diagnostic(transparent))]
    Table(#[from] TableRefusal),
    /// A row has another number of fields than the header.
    #[error("{file}:{line}: {}", chain_core::tabular::CsvProblem::Ragged { fields: *fields, columns: *columns })]
    #[cfg_attr(feature = "cli", diagnostic(code(chain::csv::ragged)))]
    Ragged {
        /// The file.
        file: String,
        /// The line.
        line: u64,
        /// The row's fields.
        fields: usize,
        /// The header's columns.
        columns: usize,
    },
    /// A cell is empty.
    #[error("{file}:{line}: column `{column}`: the cell is empty")]
    #[cfg_attr(feature = "cli", diagnostic(code(chain::csv::empty_cell)))]
    EmptyCell {
        /// The file.
        file: String,
        /// The line.
        line: u64,
        /// The column.
        column: &'static str,
    },
    /// A required column is missing from the header.
    #[error("{file}:{line}: the header has no column `{column}` (found: {found}); expected `theta_deg,z1,z3` with an optional `z2`")]
    #[cfg_attr(feature = "cli", diagnostic(code(chain::compensate::missing_column)))]
    MissingColumn {
        /// The file.
        file: String,
        /// The header line.
        line: u64,
        /// The missing column.
        column: &'static str,
        /// The columns the header has.
        found: String,
    },
    /// A known column appears twice in the header.
    #[error("{file}:{line}: column `{column}` appears twice in the header")]
    #[cfg_attr(feature = "cli", diagnostic(code(chain::compensate::duplicate_column)))]
    DuplicateColumn {
        /// The file.
        file: String,
        /// The header line.
        line: u64,
        /// The repeated column.
        column: String,
    },
    /// A cell is not a number.
    #[error("{file}:{line}: column `{column}`: `{}` is not a number", shortened(.value))]
    #[cfg_attr(feature = "cli", diagnostic(code(chain::csv::not_a_number)))]
    NotNumeric {
        /// The file.
        file: String,
        /// The line.
        line: u64,
        /// The column.
        column: &'static str,
        /// The cell as written.
        value: String,
    },
    /// A cell is NaN or infinite.
    #[error("{file}:{line}: column `{column}`: `{}` is not finite", shortened(.value))]
    #[cfg_attr(feature = "cli", diagnostic(code(chain::csv::not_finite)))]
    NotFinite {
        /// The file.
        file: String,
        /// The line.
        line: u64,
        /// The column.
        column: &'static str,
        /// The cell as written.
        value: String,
    },
    /// A commanded angle is not in the open interval (0°, 90°).
    #[error("{file}:{line}: column `theta_deg`: swing angle {theta_deg}° is outside (0°, 90°)")]
    #[cfg_attr(feature = "cli", diagnostic(
        code(chain::compensate::angle_out_of_range),
        help("Eq. 5 divides by sin θ in effect: at θ = 0 a height change says nothing about the angle")
    ))]
    AngleOutOfRange {
        /// The file.
        file: String,
        /// The line.
        line: u64,
        /// The angle (degrees).
        theta_deg: f64,
    },
    /// `cos θ − ΔZ/L` is outside `[-1, 1]`, so Eq. 5 has no solution.
    #[error("{file}:{line}: cos θ − ΔZ/L = {argument:.9} is outside [−1, 1] (θ = {theta_deg}°, z1 − z3 = {drop:.6} mm, L = {length} mm); the measured drop z1 − z3 must lie in [0, 2L]")]
    #[cfg_attr(feature = "cli", diagnostic(
        code(chain::compensate::acos_domain),
        help("check the sign convention (z3 is the measured tip height, below z1 for θ > 0) and --length")
    ))]
    AcosDomain {
        /// The file.
        file: String,
        /// The line.
        line: u64,
        /// The angle (degrees).
        theta_deg: f64,
        /// `z1 − z3` (mm).
        drop: f64,
        /// `L` (mm).
        length: f64,
        /// `cos θ − ΔZ/L`.
        argument: f64,
    },
    /// The header is followed by no data row.
    #[error("{file}:{header_line}: the header is followed by no data row")]
    #[cfg_attr(feature = "cli", diagnostic(code(chain::csv::no_data)))]
    NoData {
        /// The file.
        file: String,
        /// The header line.
        header_line: u64,
    },
    /// Too few points (at distinct angles) for the highest order asked for.
    #[error("{file}:{first_line}-{last_line}: a polynomial of order {order} needs points at {needed} distinct angles or more (one more than its coefficients, so that it has a residual and a cross-validation error), but these lines give {got}")]
    #[cfg_attr(
        feature = "cli",
        diagnostic(
            code(chain::compensate::too_few_points),
            help("lower --max-order or measure more angles")
        )
    )]
    TooFewPoints {
        /// The file.
        file: String,
        /// First data line.
        first_line: u64,
        /// Last data line.
        last_line: u64,
        /// The order asked for.
        order: usize,
        /// Distinct angles needed.
        needed: usize,
        /// Distinct angles present.
        got: usize,
    },
    /// `--length` is not a positive number of at most
    /// [`MAX_LENGTH_MM`](super::analysis::MAX_LENGTH_MM).
    #[error(
        "--length must be a positive number of millimetres of at most 1e6 (1 km), got {length}"
    )]
    #[cfg_attr(feature = "cli", diagnostic(code(chain::compensate::invalid_length)))]
    InvalidLength {
        /// The value given.
        length: f64,
    },
    /// The order range or the fixed order is not usable.
    #[error("{message}")]
    #[cfg_attr(feature = "cli", diagnostic(code(chain::compensate::invalid_orders)))]
    InvalidOrders {
        /// What is wrong.
        message: String,
    },
    /// The compensation grid is not usable.
    #[error("--grid: {message}")]
    #[cfg_attr(feature = "cli", diagnostic(code(chain::compensate::invalid_grid)))]
    InvalidGrid {
        /// What is wrong.
        message: String,
    },
    /// A least-squares fit failed (numerically rank-deficient design).
    #[error("{file}: {source}")]
    #[cfg_attr(feature = "cli", diagnostic(code(chain::compensate::fit)))]
    Fit {
        /// The file.
        file: String,
        /// The fit error.
        #[source]
        source: FitError,
    },
    /// The law `c + Δθ(c) = θt` has no unique solution near `θt`.
    #[error("the compensation law cannot be inverted at θ = {theta_deg}°: 1 + dΔθ/dθ is not positive there, so no command reaches that angle uniquely")]
    #[cfg_attr(feature = "cli", diagnostic(code(chain::compensate::not_invertible)))]
    NotInvertible {
        /// The target angle (degrees).
        theta_deg: f64,
    },
    /// An output file could not be written.
    #[error("{file}: cannot write: {source}")]
    #[cfg_attr(feature = "cli", diagnostic(code(chain::compensate::write)))]
    Write {
        /// The file.
        file: String,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
}

/// Errors of [`fit_polynomial`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[cfg_attr(feature = "cli", derive(miette::Diagnostic))]
#[non_exhaustive]
pub enum FitError {
    /// `x` and `y` differ in length.
    #[error("x has {x} values and y has {y}")]
    LengthMismatch {
        /// Length of `x`.
        x: usize,
        /// Length of `y`.
        y: usize,
    },
    /// A value is NaN or infinite.
    #[error("the data contain a value that is not finite")]
    NotFinite,
    /// The order is above [`MAX_SUPPORTED_ORDER`].
    #[error("order {order} is above the supported maximum {MAX_SUPPORTED_ORDER}")]
    OrderTooHigh {
        /// The order asked for.
        order: usize,
    },
    /// Fewer distinct abscissae than the order needs (`order + 2`).
    #[error("a polynomial of order {order} needs {needed} distinct abscissae, got {got}")]
    TooFewPoints {
        /// The order asked for.
        order: usize,
        /// Distinct abscissae needed.
        needed: usize,
        /// Distinct abscissae present.
        got: usize,
    },
    /// The scaled design matrix is numerically rank-deficient.
    #[error("the least-squares problem of order {order} is numerically rank-deficient")]
    RankDeficient {
        /// The order asked for.
        order: usize,
    },
}
