//! Swing-angle error identification and compensation (seed 003).
//!
//! A swing head of length `L` (rotation centre to tool tip) is commanded to
//! angles `θ`; at each angle the height of the tool tip is probed. With `Z1`
//! the height of the vertical tool, `Z2 = Z1 − L(1 − cos θ)` the height the tip
//! would have at exactly `θ`, and `Z3` the measured height, the seed's
//! equations 1-5 give the swing-angle error
//!
//! ```text
//! L(1 − cos θ)      = h  = Z1 − Z2            (Eq. 1)
//! L(1 − cos(θ+Δθ))  = h' = Z1 − Z3            (Eq. 2)
//! Δθ = acos(cos θ − ΔZ/L) − θ,   ΔZ = Z2 − Z3 (Eq. 5)
//! ```
//!
//! `Δθ > 0` means the head turned further than commanded (the measured tip is
//! lower than the theoretical one, `Z3 < Z2`). Because `Z2` is the theoretical
//! height, `cos θ − ΔZ/L = 1 − (Z1 − Z3)/L`, so only `Z1` and `Z3` are needed;
//! this module evaluates the equivalent, better-conditioned
//! `θ + Δθ = 2 asin(√((Z1 − Z3)/(2L)))`.
//!
//! The errors are then fitted by least-squares polynomials in `θ` (degrees) of
//! every order in a range ([`fit_polynomial`], Householder QR on a basis scaled
//! to `[-1, 1]`), one order is selected by a stated rule ([`SelectionRule`],
//! leave-one-out cross-validation by default), and the selected polynomial is
//! the compensation law ([`Compensation`]): the axis reaches
//! `θa = θt + Δθ(θt)` (Eq. 7) when `θt` is commanded, so the command that
//! reaches `θt` is the `c` with `c + Δθ(c) = θt`.
//!
//! The entry points are [`read_csv`] / [`parse_csv`] (records with their line
//! numbers), [`analyze`] (points, fits, selection, law) and
//! [`Compensation::table`] (a controller's compensation table).

use std::fmt;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::str::FromStr;

use nalgebra::{DMatrix, DVector};
use serde::Serialize;

use crate::plot::{self, PlotError, Series, XyChart};

/// Highest polynomial order [`analyze`] and [`fit_polynomial`] accept.
pub const MAX_SUPPORTED_ORDER: usize = 10;

/// Most rows a compensation-table grid may have.
pub const MAX_GRID_POINTS: usize = 100_000;

/// Errors of reading, analysing and exporting swing-angle measurements.
///
/// Every error about the input names the file and, where there is one, the
/// line (1-based, as an editor shows it) and the column.
#[derive(Debug, thiserror::Error, miette::Diagnostic)]
#[non_exhaustive]
pub enum CompensateError {
    /// The file could not be read.
    #[error("{file}: cannot read the file: {source}")]
    #[diagnostic(code(chain::compensate::io))]
    Io {
        /// The file.
        file: String,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// The file has no header line.
    #[error("{file}, line 1: the file is empty; expected a header `theta_deg,z1,z3` (optionally with `z2`)")]
    #[diagnostic(code(chain::compensate::empty))]
    Empty {
        /// The file.
        file: String,
    },
    /// A line is not well-formed CSV (bad UTF-8, wrong number of fields).
    #[error("{file}, line {line}: {message}")]
    #[diagnostic(code(chain::compensate::malformed))]
    Malformed {
        /// The file.
        file: String,
        /// The line.
        line: u64,
        /// What is wrong.
        message: String,
    },
    /// A required column is missing from the header.
    #[error("{file}, line {line}: the header has no column `{column}` (found: {found}); expected `theta_deg,z1,z3` with an optional `z2`")]
    #[diagnostic(code(chain::compensate::missing_column))]
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
    #[error("{file}, line {line}: column `{column}` appears twice in the header")]
    #[diagnostic(code(chain::compensate::duplicate_column))]
    DuplicateColumn {
        /// The file.
        file: String,
        /// The header line.
        line: u64,
        /// The repeated column.
        column: String,
    },
    /// A cell is not a number.
    #[error("{file}, line {line}, column `{column}`: `{value}` is not a number")]
    #[diagnostic(code(chain::compensate::not_numeric))]
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
    #[error("{file}, line {line}, column `{column}`: `{value}` is not a finite number")]
    #[diagnostic(code(chain::compensate::not_finite))]
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
    #[error(
        "{file}, line {line}, column `theta_deg`: swing angle {theta_deg}° is outside (0°, 90°)"
    )]
    #[diagnostic(
        code(chain::compensate::angle_out_of_range),
        help("Eq. 5 divides by sin θ in effect: at θ = 0 a height change says nothing about the angle")
    )]
    AngleOutOfRange {
        /// The file.
        file: String,
        /// The line.
        line: u64,
        /// The angle (degrees).
        theta_deg: f64,
    },
    /// `cos θ − ΔZ/L` is outside `[-1, 1]`, so Eq. 5 has no solution.
    #[error("{file}, line {line}: cos θ − ΔZ/L = {argument:.9} is outside [−1, 1] (θ = {theta_deg}°, z1 − z3 = {drop:.6} mm, L = {length} mm); the measured drop z1 − z3 must lie in [0, 2L]")]
    #[diagnostic(
        code(chain::compensate::acos_domain),
        help("check the sign convention (z3 is the measured tip height, below z1 for θ > 0) and --length")
    )]
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
    #[error("{file}, line {header_line}: the header is followed by no data row")]
    #[diagnostic(code(chain::compensate::no_data))]
    NoData {
        /// The file.
        file: String,
        /// The header line.
        header_line: u64,
    },
    /// Too few points (at distinct angles) for the highest order asked for.
    #[error("{file}, lines {first_line}-{last_line}: a polynomial of order {order} needs points at {needed} distinct angles or more (one more than its coefficients, so that it has a residual and a cross-validation error), but these lines give {got}")]
    #[diagnostic(
        code(chain::compensate::too_few_points),
        help("lower --max-order or measure more angles")
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
    /// `--length` is not a positive finite number.
    #[error("--length must be a positive finite number of millimetres, got {length}")]
    #[diagnostic(code(chain::compensate::invalid_length))]
    InvalidLength {
        /// The value given.
        length: f64,
    },
    /// The order range or the fixed order is not usable.
    #[error("{message}")]
    #[diagnostic(code(chain::compensate::invalid_orders))]
    InvalidOrders {
        /// What is wrong.
        message: String,
    },
    /// The compensation grid is not usable.
    #[error("--grid: {message}")]
    #[diagnostic(code(chain::compensate::invalid_grid))]
    InvalidGrid {
        /// What is wrong.
        message: String,
    },
    /// A least-squares fit failed (numerically rank-deficient design).
    #[error("{file}: {source}")]
    #[diagnostic(code(chain::compensate::fit))]
    Fit {
        /// The file.
        file: String,
        /// The fit error.
        #[source]
        source: FitError,
    },
    /// The law `c + Δθ(c) = θt` has no unique solution near `θt`.
    #[error("the compensation law cannot be inverted at θ = {theta_deg}°: 1 + dΔθ/dθ is not positive there, so no command reaches that angle uniquely")]
    #[diagnostic(code(chain::compensate::not_invertible))]
    NotInvertible {
        /// The target angle (degrees).
        theta_deg: f64,
    },
    /// An output file could not be written.
    #[error("{file}: cannot write: {source}")]
    #[diagnostic(code(chain::compensate::write))]
    Write {
        /// The file.
        file: String,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
}

/// Errors of [`fit_polynomial`].
#[derive(Debug, Clone, PartialEq, thiserror::Error, miette::Diagnostic)]
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

// ---------------------------------------------------------------------------
// Input
// ---------------------------------------------------------------------------

/// One measurement row.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Record {
    /// Line of the row in its file (1-based).
    pub line: u64,
    /// Commanded swing angle `θ` (degrees).
    pub theta_deg: f64,
    /// Reference tool-tip height `Z1` of the vertical tool (mm).
    pub z1: f64,
    /// Theoretical tool-tip height `Z2` at `θ` (mm), if the file has it.
    pub z2: Option<f64>,
    /// Measured tool-tip height `Z3` (mm).
    pub z3: f64,
}

/// The rows of one measurement file.
#[derive(Debug, Clone, PartialEq)]
pub struct Measurements {
    /// Name of the source (the path as given), used in error messages.
    pub source: String,
    /// Line of the header (1-based).
    pub header_line: u64,
    /// The data rows in file order.
    pub records: Vec<Record>,
}

impl Measurements {
    /// Whether the file has a `z2` column.
    pub fn has_z2(&self) -> bool {
        self.records.first().is_some_and(|r| r.z2.is_some())
    }
}

/// Reads a measurement CSV (see [`parse_csv`]) from a file.
pub fn read_csv(path: &Path) -> Result<Measurements, CompensateError> {
    let file = path.display().to_string();
    let data = std::fs::read(path).map_err(|source| CompensateError::Io {
        file: file.clone(),
        source,
    })?;
    parse_csv(&file, &data)
}

/// Parses a measurement CSV.
///
/// The header names the columns `theta_deg`, `z1`, `z3` and optionally `z2`,
/// in any order and case; other columns are ignored. Lines starting with `#`
/// and blank lines are skipped; fields are trimmed. Every cell must be a finite
/// number and every angle must lie in the open interval (0°, 90°). `file`
/// names the source in error messages.
pub fn parse_csv(file: &str, data: &[u8]) -> Result<Measurements, CompensateError> {
    let data = data.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(data);
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .from_reader(data);
    let mut rows = reader.records();
    let csv_error = |e: csv::Error| match e.position() {
        Some(pos) => CompensateError::Malformed {
            file: file.to_string(),
            line: pos.line(),
            message: csv_error_message(&e),
        },
        None => CompensateError::Malformed {
            file: file.to_string(),
            line: 1,
            message: csv_error_message(&e),
        },
    };
    let header = match rows.next() {
        None => {
            return Err(CompensateError::Empty {
                file: file.to_string(),
            })
        }
        Some(h) => h.map_err(csv_error)?,
    };
    let header_line = header.position().map_or(1, |p| record_line(data, p));
    let names: Vec<String> = header.iter().map(str::to_ascii_lowercase).collect();
    let find = |column: &'static str| -> Result<Option<usize>, CompensateError> {
        let mut hits = names.iter().enumerate().filter(|(_, n)| *n == column);
        let first = hits.next().map(|(i, _)| i);
        if hits.next().is_some() {
            return Err(CompensateError::DuplicateColumn {
                file: file.to_string(),
                line: header_line,
                column: column.to_string(),
            });
        }
        Ok(first)
    };
    let require = |column: &'static str| -> Result<usize, CompensateError> {
        find(column)?.ok_or_else(|| CompensateError::MissingColumn {
            file: file.to_string(),
            line: header_line,
            column,
            found: header
                .iter()
                .map(|n| format!("`{n}`"))
                .collect::<Vec<_>>()
                .join(", "),
        })
    };
    let i_theta = require("theta_deg")?;
    let i_z1 = require("z1")?;
    let i_z3 = require("z3")?;
    let i_z2 = find("z2")?;

    let mut records = Vec::new();
    for row in rows {
        let row = row.map_err(csv_error)?;
        let line = row.position().map_or(0, |p| record_line(data, p));
        if row.len() != header.len() {
            return Err(CompensateError::Malformed {
                file: file.to_string(),
                line,
                message: format!(
                    "expected {} fields as in the header (line {header_line}), found {}",
                    header.len(),
                    row.len()
                ),
            });
        }
        let cell = |index: usize, column: &'static str| -> Result<f64, CompensateError> {
            let text = row.get(index).unwrap_or("");
            let value: f64 = text.parse().map_err(|_| CompensateError::NotNumeric {
                file: file.to_string(),
                line,
                column,
                value: text.to_string(),
            })?;
            if value.is_finite() {
                Ok(value)
            } else {
                Err(CompensateError::NotFinite {
                    file: file.to_string(),
                    line,
                    column,
                    value: text.to_string(),
                })
            }
        };
        let theta_deg = cell(i_theta, "theta_deg")?;
        let z1 = cell(i_z1, "z1")?;
        let z2 = i_z2.map(|i| cell(i, "z2")).transpose()?;
        let z3 = cell(i_z3, "z3")?;
        if !(theta_deg > 0.0 && theta_deg < 90.0) {
            return Err(CompensateError::AngleOutOfRange {
                file: file.to_string(),
                line,
                theta_deg,
            });
        }
        records.push(Record {
            line,
            theta_deg,
            z1,
            z2,
            z3,
        });
    }
    if records.is_empty() {
        return Err(CompensateError::NoData {
            file: file.to_string(),
            header_line,
        });
    }
    Ok(Measurements {
        source: file.to_string(),
        header_line,
        records,
    })
}

/// The line a record starts on. The reader reports where it started reading,
/// which is before any comment or blank lines it skipped; skip them here too.
fn record_line(data: &[u8], pos: &csv::Position) -> u64 {
    let mut line = pos.line();
    let mut i = usize::try_from(pos.byte()).unwrap_or(usize::MAX);
    while let Some(&b) = data.get(i) {
        match b {
            b'#' => match data[i..].iter().position(|&c| c == b'\n') {
                Some(end) => {
                    i += end + 1;
                    line += 1;
                }
                None => break,
            },
            b'\n' => {
                i += 1;
                line += 1;
            }
            b'\r' => {
                i += 1;
                if data.get(i) == Some(&b'\n') {
                    i += 1;
                }
                line += 1;
            }
            _ => break,
        }
    }
    line
}

fn csv_error_message(e: &csv::Error) -> String {
    match e.kind() {
        csv::ErrorKind::Utf8 { err, .. } => format!("the line is not valid UTF-8 ({err})"),
        csv::ErrorKind::UnequalLengths {
            expected_len, len, ..
        } => format!("expected {expected_len} fields, found {len}"),
        _ => e.to_string(),
    }
}

// ---------------------------------------------------------------------------
// Eq. 1-5
// ---------------------------------------------------------------------------

/// Theoretical drop of the tool tip `h = L(1 − cos θ)` (Eq. 1), in the units of
/// `length`, evaluated as `2L sin²(θ/2)`.
pub fn theoretical_drop(theta_deg: f64, length: f64) -> f64 {
    let s = (theta_deg.to_radians() / 2.0).sin();
    2.0 * length * s * s
}

/// The argument `cos θ − ΔZ/L` of Eq. 5 for a measured drop `z1 − z3`, with
/// `ΔZ = Z2 − Z3` and the theoretical `Z2 = Z1 − L(1 − cos θ)`; it equals
/// `1 − (z1 − z3)/L` whatever `θ`.
pub fn acos_argument(z1: f64, z3: f64, length: f64) -> f64 {
    1.0 - (z1 - z3) / length
}

/// Swing-angle error `Δθ` (degrees) from the commanded angle `θ` (degrees), the
/// reference height `z1` and the measured height `z3` (Eq. 5 with the
/// theoretical `Z2`).
///
/// Evaluated as `2 asin(√((z1 − z3)/(2L))) − θ`, which equals
/// `acos(cos θ − ΔZ/L) − θ` but keeps full precision at small angles. Returns
/// `None` when `cos θ − ΔZ/L` is outside `[−1, 1]` (the drop `z1 − z3` is
/// outside `[0, 2L]`) or `length` is not positive.
pub fn swing_angle_error_deg(theta_deg: f64, z1: f64, z3: f64, length: f64) -> Option<f64> {
    if !(length > 0.0 && length.is_finite()) {
        return None;
    }
    let half_ratio = (z1 - z3) / (2.0 * length);
    if !(0.0..=1.0).contains(&half_ratio) {
        return None;
    }
    let actual = 2.0 * half_ratio.sqrt().asin();
    Some(actual.to_degrees() - theta_deg)
}

/// Eq. 5 as printed, `Δθ = acos(cos θ − ΔZ/L) − θ` (degrees), for an explicit
/// `ΔZ = Z2 − Z3` (mm). Returns `None` when the argument of `acos` is outside
/// `[−1, 1]`.
pub fn swing_angle_error_from_delta_z_deg(
    theta_deg: f64,
    delta_z: f64,
    length: f64,
) -> Option<f64> {
    let argument = theta_deg.to_radians().cos() - delta_z / length;
    if !(-1.0..=1.0).contains(&argument) {
        return None;
    }
    Some(argument.acos().to_degrees() - theta_deg)
}

// ---------------------------------------------------------------------------
// Least squares
// ---------------------------------------------------------------------------

/// A least-squares polynomial `y ≈ Σ c_k x^k` with its goodness-of-fit figures.
///
/// The fit is computed by Householder QR of the Vandermonde matrix in the
/// scaled abscissa `u = (x − centre)/scale ∈ [−1, 1]`; evaluation uses that
/// basis, and [`PolyFit::coefficients`] are its exact re-expansion in powers of
/// `x`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PolyFit {
    /// Polynomial order `p`.
    pub order: usize,
    /// Coefficient of determination `R² = 1 − RSS/TSS` (1 when `TSS = 0`;
    /// sums of squares at the rounding-noise level of `y` count as 0).
    pub r2: f64,
    /// Coefficients `c_0 … c_p` in ascending powers of `x`.
    pub coefficients: Vec<f64>,
    /// Adjusted `R² = 1 − (1 − R²)(n − 1)/(n − p − 1)`.
    pub adjusted_r2: f64,
    /// Root-mean-square residual `√(RSS/n)`.
    pub rmse: f64,
    /// Residual standard error `√(RSS/(n − p − 1))`.
    pub residual_std: f64,
    /// Leave-one-out prediction error sum of squares `Σ (e_i / (1 − h_ii))²`.
    pub press: f64,
    /// Leave-one-out root-mean-square prediction error `√(PRESS/n)`.
    pub loocv_rmse: f64,
    /// Small-sample Akaike criterion (Gaussian errors, `k = p + 2` parameters);
    /// `None` when `n ≤ p + 3`.
    pub aicc: Option<f64>,
    /// Bayesian information criterion (Gaussian errors, `k = p + 2`).
    pub bic: f64,
    /// p-value of the overall F-test of this fit against the constant model
    /// (`None` for order 0 and for data without variance).
    pub f_test_p: Option<f64>,
    /// Number of points.
    pub n: usize,
    #[serde(skip)]
    centre: f64,
    #[serde(skip)]
    scale: f64,
    #[serde(skip)]
    scaled: Vec<f64>,
}

impl PolyFit {
    /// The polynomial at `x`.
    pub fn eval(&self, x: f64) -> f64 {
        let u = (x - self.centre) / self.scale;
        self.scaled.iter().rev().fold(0.0, |acc, &a| acc * u + a)
    }

    /// The derivative `dy/dx` at `x`.
    pub fn derivative(&self, x: f64) -> f64 {
        let u = (x - self.centre) / self.scale;
        let d = self
            .scaled
            .iter()
            .enumerate()
            .skip(1)
            .rev()
            .fold(0.0, |acc, (k, &a)| acc * u + k as f64 * a);
        d / self.scale
    }
}

/// Fits a polynomial of order `order` to `(x, y)` by least squares.
///
/// Needs `order + 2` distinct abscissae or more (so that the fit has a residual
/// and every leave-one-out refit is determined) and finite data.
pub fn fit_polynomial(x: &[f64], y: &[f64], order: usize) -> Result<PolyFit, FitError> {
    if x.len() != y.len() {
        return Err(FitError::LengthMismatch {
            x: x.len(),
            y: y.len(),
        });
    }
    if x.iter().chain(y).any(|v| !v.is_finite()) {
        return Err(FitError::NotFinite);
    }
    if order > MAX_SUPPORTED_ORDER {
        return Err(FitError::OrderTooHigh { order });
    }
    let distinct = distinct_count(x);
    if distinct < order + 2 {
        return Err(FitError::TooFewPoints {
            order,
            needed: order + 2,
            got: distinct,
        });
    }
    let n = x.len();
    let cols = order + 1;
    let (lo, hi) = x
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        });
    let centre = 0.5 * (lo + hi);
    let half = 0.5 * (hi - lo);
    let scale = if half > 0.0 { half } else { 1.0 };
    let design = DMatrix::from_fn(n, cols, |i, j| ((x[i] - centre) / scale).powi(j as i32));
    let qr = design.qr();
    let q = qr.q();
    let r = qr.r();
    let r_max = (0..cols).map(|j| r[(j, j)].abs()).fold(0.0, f64::max);
    let tolerance = r_max * (n.max(cols) as f64) * f64::EPSILON * 16.0;
    if (0..cols).any(|j| r[(j, j)].abs() <= tolerance) {
        return Err(FitError::RankDeficient { order });
    }
    let yv = DVector::from_column_slice(y);
    let qty = q.transpose() * &yv;
    let scaled_coef = r
        .solve_upper_triangular(&qty)
        .ok_or(FitError::RankDeficient { order })?;
    let fitted = &q * &qty;
    let residual = &yv - &fitted;
    // Sums of squares at the level of rounding noise of y are zero: a fit of
    // exact (or constant) data must not rank orders by noise.
    let y_max = y.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let noise_floor = n as f64 * (1e3 * f64::EPSILON * y_max).powi(2);
    let denoise = |ss: f64| if ss <= noise_floor { 0.0 } else { ss };
    let rss = denoise(residual.iter().map(|e| e * e).sum());
    let mean = y.iter().sum::<f64>() / n as f64;
    let tss = denoise(y.iter().map(|v| (v - mean) * (v - mean)).sum());
    let r2 = if tss > 0.0 { 1.0 - rss / tss } else { 1.0 };
    let nf = n as f64;
    let dof = (n - cols) as f64;
    let adjusted_r2 = 1.0 - (1.0 - r2) * (nf - 1.0) / dof;
    let mut press = 0.0;
    for i in 0..n {
        let leverage: f64 = (0..cols).map(|j| q[(i, j)] * q[(i, j)]).sum();
        let denominator = 1.0 - leverage;
        if denominator <= 1e-12 {
            return Err(FitError::RankDeficient { order });
        }
        press += (residual[i] / denominator).powi(2);
    }
    let press = if rss == 0.0 { 0.0 } else { press };
    let k = (order + 2) as f64;
    let log_likelihood_term = nf * (rss.max(f64::MIN_POSITIVE) / nf).ln();
    let aicc = (nf > k + 1.0)
        .then(|| log_likelihood_term + 2.0 * k + 2.0 * k * (k + 1.0) / (nf - k - 1.0));
    let bic = log_likelihood_term + k * nf.ln();
    // The overall F-test needs variance to explain; an exact fit of varying
    // data has p = 0.
    let f_test_p = (order > 0 && tss > 0.0).then(|| {
        if rss == 0.0 {
            0.0
        } else {
            let d1 = order as f64;
            let f = (r2 / d1) / ((1.0 - r2) / dof);
            f_survival(f.max(0.0), d1, dof)
        }
    });
    let scaled: Vec<f64> = scaled_coef.iter().copied().collect();
    let coefficients = expand_scaled(&scaled, centre, scale);
    Ok(PolyFit {
        order,
        r2,
        coefficients,
        adjusted_r2,
        rmse: (rss / nf).sqrt(),
        residual_std: (rss / dof).sqrt(),
        press,
        loocv_rmse: (press / nf).sqrt(),
        aicc,
        bic,
        f_test_p,
        n,
        centre,
        scale,
        scaled,
    })
}

/// Number of distinct values (exact comparison).
fn distinct_count(x: &[f64]) -> usize {
    let mut sorted: Vec<f64> = x.to_vec();
    sorted.sort_by(f64::total_cmp);
    sorted.dedup();
    sorted.len()
}

/// Re-expands `Σ a_k ((x − c)/s)^k` in powers of `x`.
fn expand_scaled(scaled: &[f64], centre: f64, scale: f64) -> Vec<f64> {
    let mut out = vec![0.0; scaled.len()];
    for (k, &a) in scaled.iter().enumerate() {
        let factor = a / scale.powi(k as i32);
        let mut binomial = 1.0;
        for (j, slot) in out.iter_mut().enumerate().take(k + 1) {
            *slot += factor * binomial * (-centre).powi((k - j) as i32);
            binomial = binomial * (k - j) as f64 / (j + 1) as f64;
        }
    }
    out
}

// ---------------------------------------------------------------------------
// F distribution (for the overall F-test)
// ---------------------------------------------------------------------------

/// Survival function `P(F > f)` of the F distribution with `d1`, `d2` degrees
/// of freedom (via the regularized incomplete beta function). Returns NaN for
/// non-positive degrees of freedom or a NaN `f`.
pub fn f_survival(f: f64, d1: f64, d2: f64) -> f64 {
    if !(d1 > 0.0 && d2 > 0.0) || f.is_nan() {
        return f64::NAN;
    }
    if f <= 0.0 {
        return 1.0;
    }
    if f.is_infinite() {
        return 0.0;
    }
    regularized_beta(d2 / 2.0, d1 / 2.0, d2 / (d2 + d1 * f))
}

/// `ln Γ(x)` for `x > 0` (Lanczos, g = 7, 9 terms).
fn ln_gamma(x: f64) -> f64 {
    const G: f64 = 7.0;
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        // Reflection: Γ(x) Γ(1 − x) = π / sin(πx).
        let pi = std::f64::consts::PI;
        return (pi / (pi * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = C[0];
    let t = x + G + 0.5;
    for (i, &c) in C.iter().enumerate().skip(1) {
        a += c / (x + i as f64);
    }
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// Regularized incomplete beta `I_x(a, b)`.
fn regularized_beta(a: f64, b: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if x >= 1.0 {
        return 1.0;
    }
    let front =
        (ln_gamma(a + b) - ln_gamma(a) - ln_gamma(b) + a * x.ln() + b * (1.0 - x).ln()).exp();
    if x < (a + 1.0) / (a + b + 2.0) {
        front * beta_continued_fraction(a, b, x) / a
    } else {
        1.0 - front * beta_continued_fraction(b, a, 1.0 - x) / b
    }
}

/// Continued fraction of the incomplete beta function (modified Lentz).
fn beta_continued_fraction(a: f64, b: f64, x: f64) -> f64 {
    const TINY: f64 = 1e-300;
    let mut c = 1.0;
    let mut d = 1.0 - (a + b) * x / (a + 1.0);
    if d.abs() < TINY {
        d = TINY;
    }
    d = 1.0 / d;
    let mut h = d;
    for m in 1..=500 {
        let m = m as f64;
        let m2 = 2.0 * m;
        let even = m * (b - m) * x / ((a + m2 - 1.0) * (a + m2));
        d = 1.0 + even * d;
        if d.abs() < TINY {
            d = TINY;
        }
        c = 1.0 + even / c;
        if c.abs() < TINY {
            c = TINY;
        }
        d = 1.0 / d;
        h *= d * c;
        let odd = -(a + m) * (a + b + m) * x / ((a + m2) * (a + m2 + 1.0));
        d = 1.0 + odd * d;
        if d.abs() < TINY {
            d = TINY;
        }
        c = 1.0 + odd / c;
        if c.abs() < TINY {
            c = TINY;
        }
        d = 1.0 / d;
        let delta = d * c;
        h *= delta;
        if (delta - 1.0).abs() < 1e-15 {
            break;
        }
    }
    h
}

// ---------------------------------------------------------------------------
// Order selection
// ---------------------------------------------------------------------------

/// How [`analyze`] chooses the order of the compensation law among the fits.
///
/// The default, [`SelectionRule::Loocv`], picks the order with the smallest
/// leave-one-out prediction error: the quantity a compensation law is for
/// (the error left at an angle when the law was fitted without that angle's
/// measurement). `R²` never decreases with the order, so it cannot choose.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum SelectionRule {
    /// Smallest leave-one-out cross-validation error (PRESS); ties go to the
    /// lower order.
    #[default]
    Loocv,
    /// Largest adjusted `R²`.
    AdjustedR2,
    /// Smallest small-sample Akaike criterion (orders where it is undefined
    /// are skipped).
    Aicc,
    /// Smallest Bayesian information criterion.
    Bic,
}

impl SelectionRule {
    /// Every rule, in the order of their names in [`SelectionRule::name`].
    pub const ALL: [SelectionRule; 4] = [
        SelectionRule::Loocv,
        SelectionRule::AdjustedR2,
        SelectionRule::Aicc,
        SelectionRule::Bic,
    ];

    /// The rule's name on the command line and in JSON.
    pub fn name(self) -> &'static str {
        match self {
            SelectionRule::Loocv => "loocv",
            SelectionRule::AdjustedR2 => "adjusted-r2",
            SelectionRule::Aicc => "aicc",
            SelectionRule::Bic => "bic",
        }
    }

    /// One sentence saying what the rule does.
    pub fn description(self) -> &'static str {
        match self {
            SelectionRule::Loocv => {
                "smallest leave-one-out cross-validation error (PRESS); ties go to the lower order"
            }
            SelectionRule::AdjustedR2 => "largest adjusted R² = 1 − (1 − R²)(n − 1)/(n − p − 1)",
            SelectionRule::Aicc => {
                "smallest AICc = n ln(RSS/n) + 2k + 2k(k + 1)/(n − k − 1), k = p + 2"
            }
            SelectionRule::Bic => "smallest BIC = n ln(RSS/n) + k ln n, k = p + 2",
        }
    }

    /// The order this rule picks among `fits` (`None` if no fit has a value
    /// for the rule's criterion, or `fits` is empty).
    pub fn select(self, fits: &[PolyFit]) -> Option<usize> {
        // Lower is better for every score; ties (within a relative 1e-12) go
        // to the lower order, which comes first.
        let score = |f: &PolyFit| -> Option<f64> {
            match self {
                SelectionRule::Loocv => Some(f.press),
                SelectionRule::AdjustedR2 => Some(-f.adjusted_r2),
                SelectionRule::Aicc => f.aicc,
                SelectionRule::Bic => Some(f.bic),
            }
        };
        let mut best: Option<(usize, f64)> = None;
        for fit in fits {
            let Some(s) = score(fit).filter(|s| s.is_finite()) else {
                continue;
            };
            match best {
                Some((_, b)) if s >= b - 1e-12 * b.abs().max(f64::MIN_POSITIVE) => {}
                _ => best = Some((fit.order, s)),
            }
        }
        best.map(|(order, _)| order)
    }
}

impl fmt::Display for SelectionRule {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for SelectionRule {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        SelectionRule::ALL
            .into_iter()
            .find(|r| r.name() == s)
            .ok_or_else(|| {
                format!(
                    "unknown selection rule `{s}` (expected one of: {})",
                    SelectionRule::ALL.map(SelectionRule::name).join(", ")
                )
            })
    }
}

// ---------------------------------------------------------------------------
// Analysis
// ---------------------------------------------------------------------------

/// Settings of [`analyze`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// Distance `L` from the rotation centre to the tool tip (mm).
    pub length: f64,
    /// Lowest order fitted (the seed: 2).
    pub min_order: usize,
    /// Highest order fitted (the seed: 6).
    pub max_order: usize,
    /// Rule that selects the order of the law.
    pub rule: SelectionRule,
    /// An order to use instead of the rule's choice (must be fitted).
    pub fixed_order: Option<usize>,
}

impl Options {
    /// The seed's settings for a given length: orders 2 to 6, selected by
    /// leave-one-out cross-validation.
    pub fn new(length: f64) -> Self {
        Options {
            length,
            min_order: 2,
            max_order: 6,
            rule: SelectionRule::Loocv,
            fixed_order: None,
        }
    }
}

/// One processed measurement (a row of the seed's Table 2, and more).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Point {
    /// Commanded angle `θ` (degrees).
    pub theta_deg: f64,
    /// Swing-angle error `Δθ` (degrees, Eq. 5).
    pub delta_theta_deg: f64,
    /// Line of the row in its file.
    pub line: u64,
    /// Reference height `Z1` (mm).
    pub z1: f64,
    /// Theoretical height `Z2` as given in the file (mm).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub z2: Option<f64>,
    /// Measured height `Z3` (mm).
    pub z3: f64,
    /// Measured drop `h' = Z1 − Z3` (mm, Eq. 2).
    pub z1_minus_z3: f64,
    /// `Z1 − Z2` from the file's `z2` (mm).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub z1_minus_z2: Option<f64>,
    /// `Z2 − Z3` from the file's `z2` (mm).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub z2_minus_z3: Option<f64>,
    /// Theoretical drop `h = L(1 − cos θ)` (mm, Eq. 1).
    pub h_mm: f64,
    /// `ΔZ = Z2 − Z3` with the theoretical `Z2 = Z1 − h` (mm, Eq. 3); the
    /// value Eq. 5 uses.
    pub delta_z_mm: f64,
    /// The selected law's `Δθ(θ)` (degrees).
    pub fitted_deg: f64,
    /// `Δθ − Δθ(θ)`: the error predicted to remain after compensation (degrees).
    pub residual_deg: f64,
}

/// Minimum, maximum and root-mean-square of a set of angle errors.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Spread {
    /// Smallest value (degrees).
    pub min_deg: f64,
    /// Largest value (degrees).
    pub max_deg: f64,
    /// Largest absolute value (degrees).
    pub max_abs_deg: f64,
    /// Root mean square about zero (degrees).
    pub rms_deg: f64,
}

impl Spread {
    /// The spread of `values` (all zeros for an empty slice).
    pub fn of(values: &[f64]) -> Spread {
        if values.is_empty() {
            return Spread {
                min_deg: 0.0,
                max_deg: 0.0,
                max_abs_deg: 0.0,
                rms_deg: 0.0,
            };
        }
        let min_deg = values.iter().copied().fold(f64::INFINITY, f64::min);
        let max_deg = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let rms_deg = (values.iter().map(|v| v * v).sum::<f64>() / values.len() as f64).sqrt();
        Spread {
            min_deg,
            max_deg,
            max_abs_deg: min_deg.abs().max(max_deg.abs()),
            rms_deg,
        }
    }
}

/// The swing-angle error before and (predicted) after compensation, at the
/// measured angles.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ResidualSummary {
    /// The measured `Δθ`.
    pub before: Spread,
    /// The residuals `Δθ − Δθ(θ)` of the law at the measured angles.
    pub after: Spread,
    /// Leave-one-out RMS of the law: the residual to expect at an angle whose
    /// measurement did not shape the law (degrees).
    pub loocv_rms_deg: f64,
}

/// The compensation law: the selected polynomial `Δθ(θ)` and its use.
///
/// Commanding `θt` leaves the axis at `θa = θt + Δθ(θt)` (Eq. 7); the command
/// that reaches a target `θt` is the `c` with `c + Δθ(c) = θt`
/// ([`Compensation::command_deg`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Compensation {
    /// Order of the law.
    pub order: usize,
    /// Coefficients of `Δθ(θ)` in ascending powers of `θ`, both in degrees.
    pub coefficients: Vec<f64>,
    /// The law as text (`delta_theta = … ` in powers of `theta`, degrees).
    pub law: String,
    /// What the law means for the axis and for the command.
    pub usage: String,
    /// Range of measured angles the law was fitted on (degrees).
    pub fitted_range_deg: [f64; 2],
    /// The error before and after compensation.
    pub residual: ResidualSummary,
    #[serde(skip)]
    fit: PolyFit,
}

impl Compensation {
    /// The law's swing-angle error `Δθ(θ)` (degrees) at commanded angle `θ`.
    pub fn delta_theta_deg(&self, theta_deg: f64) -> f64 {
        self.fit.eval(theta_deg)
    }

    /// The angle the axis reaches when `θt` is commanded: `θt + Δθ(θt)` (Eq. 7).
    pub fn actual_deg(&self, commanded_deg: f64) -> f64 {
        commanded_deg + self.fit.eval(commanded_deg)
    }

    /// The command `c` that makes the axis reach `target_deg`: the solution of
    /// `c + Δθ(c) = target` nearest `target − Δθ(target)` (Newton). `None` if
    /// `1 + dΔθ/dθ` is not positive on the way or Newton does not converge.
    pub fn command_deg(&self, target_deg: f64) -> Option<f64> {
        if !target_deg.is_finite() {
            return None;
        }
        let mut c = target_deg - self.fit.eval(target_deg);
        for _ in 0..100 {
            let g = c + self.fit.eval(c) - target_deg;
            let slope = 1.0 + self.fit.derivative(c);
            if slope.is_nan() || slope <= 1e-6 || !c.is_finite() {
                return None;
            }
            if g.abs() <= 1e-13 * (1.0 + target_deg.abs()) {
                return Some(c);
            }
            c -= g / slope;
        }
        None
    }

    /// The compensation table on `grid` (commanded/target angles, degrees).
    ///
    /// Every angle must lie in (0°, 90°) and, unless `allow_extrapolation`, in
    /// the range of measured angles the law was fitted on.
    pub fn table(
        &self,
        grid: &[f64],
        allow_extrapolation: bool,
    ) -> Result<Vec<TableRow>, CompensateError> {
        let [lo, hi] = self.fitted_range_deg;
        let slack = 1e-9 * (1.0 + hi.abs());
        grid.iter()
            .map(|&theta_deg| {
                if !(theta_deg > 0.0 && theta_deg < 90.0) {
                    return Err(CompensateError::InvalidGrid {
                        message: format!("angle {theta_deg}° is outside (0°, 90°)"),
                    });
                }
                if !allow_extrapolation && (theta_deg < lo - slack || theta_deg > hi + slack) {
                    return Err(CompensateError::InvalidGrid {
                        message: format!(
                            "angle {theta_deg}° is outside the measured range [{lo}°, {hi}°]; a polynomial law is not trustworthy there (allow it explicitly to extrapolate)"
                        ),
                    });
                }
                let command_deg = self
                    .command_deg(theta_deg)
                    .ok_or(CompensateError::NotInvertible { theta_deg })?;
                Ok(TableRow {
                    theta_deg,
                    delta_theta_deg: self.delta_theta_deg(theta_deg),
                    actual_deg: self.actual_deg(theta_deg),
                    command_deg,
                    correction_deg: command_deg - theta_deg,
                })
            })
            .collect()
    }

    /// The polynomial fit behind the law.
    pub fn fit(&self) -> &PolyFit {
        &self.fit
    }
}

/// One row of a compensation table.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TableRow {
    /// Nominal angle `θt` (degrees): the target, and the uncompensated command.
    pub theta_deg: f64,
    /// The law's error `Δθ(θt)` (degrees).
    pub delta_theta_deg: f64,
    /// `θt + Δθ(θt)` (Eq. 7): where the axis goes when `θt` is commanded
    /// uncompensated (degrees).
    pub actual_deg: f64,
    /// The command `c` with `c + Δθ(c) = θt`: what to send to reach `θt`
    /// (degrees).
    pub command_deg: f64,
    /// `c − θt`: the offset a controller adds to the command (degrees).
    pub correction_deg: f64,
}

/// Header of [`write_table_csv`]'s output.
pub const TABLE_HEADER: &str = "theta_deg,delta_theta_deg,actual_deg,command_deg,correction_deg";

/// Writes a compensation table as CSV (header [`TABLE_HEADER`], 9 decimals).
pub fn write_table_csv<W: Write>(rows: &[TableRow], mut out: W) -> std::io::Result<()> {
    writeln!(out, "{TABLE_HEADER}")?;
    for r in rows {
        writeln!(
            out,
            "{},{:.9},{:.9},{:.9},{:.9}",
            r.theta_deg, r.delta_theta_deg, r.actual_deg, r.command_deg, r.correction_deg
        )?;
    }
    out.flush()
}

/// Everything [`analyze`] derives from a measurement file.
///
/// Serialises to the `chain compensate --format json` document: `length`,
/// `points`, `fits`, `selected_order` as the spec fixes them, then `selection`,
/// `compensation` and `file`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Analysis {
    /// `L` (mm).
    pub length: f64,
    /// The processed points in file order.
    pub points: Vec<Point>,
    /// One fit per order, ascending.
    pub fits: Vec<PolyFit>,
    /// Order of the compensation law.
    pub selected_order: usize,
    /// How the order was selected.
    pub selection: Selection,
    /// The compensation law.
    pub compensation: Compensation,
    /// The source file.
    pub file: String,
}

/// How the order of the law was chosen, and what each rule would choose.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Selection {
    /// `fixed` when an order was imposed, else the rule's name.
    pub rule: String,
    /// What the rule does.
    pub description: String,
    /// The order each rule picks on these data (by rule name).
    pub by_rule: std::collections::BTreeMap<String, usize>,
}

impl Analysis {
    /// The fit of the selected order.
    pub fn selected_fit(&self) -> &PolyFit {
        &self.compensation.fit
    }

    /// The fit of `order`, if it was fitted.
    pub fn fit(&self, order: usize) -> Option<&PolyFit> {
        self.fits.iter().find(|f| f.order == order)
    }

    /// Smallest and largest measured angle (degrees).
    pub fn angle_range(&self) -> [f64; 2] {
        self.compensation.fitted_range_deg
    }
}

/// Processes measurements: `Δθ` per point (Eq. 5), least-squares fits of
/// orders `min_order..=max_order`, the selected order and the law.
pub fn analyze(m: &Measurements, options: &Options) -> Result<Analysis, CompensateError> {
    let file = m.source.clone();
    let length = options.length;
    if !(length > 0.0 && length.is_finite()) {
        return Err(CompensateError::InvalidLength { length });
    }
    if options.min_order > options.max_order {
        return Err(CompensateError::InvalidOrders {
            message: format!(
                "--min-order {} is above --max-order {}",
                options.min_order, options.max_order
            ),
        });
    }
    if options.max_order > MAX_SUPPORTED_ORDER {
        return Err(CompensateError::InvalidOrders {
            message: format!(
                "--max-order {} is above the supported maximum {MAX_SUPPORTED_ORDER}",
                options.max_order
            ),
        });
    }
    if let Some(order) = options.fixed_order {
        if order < options.min_order || order > options.max_order {
            return Err(CompensateError::InvalidOrders {
                message: format!(
                    "--order {order} is not among the fitted orders {}..={}",
                    options.min_order, options.max_order
                ),
            });
        }
    }
    let first = m.records.first().ok_or_else(|| CompensateError::NoData {
        file: file.clone(),
        header_line: m.header_line,
    })?;
    let (first_line, last_line) = (first.line, m.records.last().map_or(first.line, |r| r.line));

    let mut delta = Vec::with_capacity(m.records.len());
    for r in &m.records {
        let d = swing_angle_error_deg(r.theta_deg, r.z1, r.z3, length).ok_or_else(|| {
            CompensateError::AcosDomain {
                file: file.clone(),
                line: r.line,
                theta_deg: r.theta_deg,
                drop: r.z1 - r.z3,
                length,
                argument: acos_argument(r.z1, r.z3, length),
            }
        })?;
        delta.push(d);
    }
    let theta: Vec<f64> = m.records.iter().map(|r| r.theta_deg).collect();
    let distinct = distinct_count(&theta);
    if distinct < options.max_order + 2 {
        return Err(CompensateError::TooFewPoints {
            file,
            first_line,
            last_line,
            order: options.max_order,
            needed: options.max_order + 2,
            got: distinct,
        });
    }
    let fits = (options.min_order..=options.max_order)
        .map(|order| fit_polynomial(&theta, &delta, order))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|source| CompensateError::Fit {
            file: file.clone(),
            source,
        })?;
    let by_rule: std::collections::BTreeMap<String, usize> = SelectionRule::ALL
        .iter()
        .filter_map(|r| r.select(&fits).map(|o| (r.name().to_string(), o)))
        .collect();
    let (selected_order, selection) = match options.fixed_order {
        Some(order) => (
            order,
            Selection {
                rule: "fixed".to_string(),
                description: format!("order {order} imposed by the user"),
                by_rule,
            },
        ),
        None => {
            let order = options.rule.select(&fits).ok_or_else(|| CompensateError::InvalidOrders {
                message: format!(
                    "rule `{}` is undefined for every fitted order (too few points for it); choose another rule or lower --max-order",
                    options.rule
                ),
            })?;
            (
                order,
                Selection {
                    rule: options.rule.name().to_string(),
                    description: options.rule.description().to_string(),
                    by_rule,
                },
            )
        }
    };
    let fit = fits
        .iter()
        .find(|f| f.order == selected_order)
        .cloned()
        .ok_or_else(|| CompensateError::InvalidOrders {
            message: format!("order {selected_order} was not fitted"),
        })?;

    let points: Vec<Point> = m
        .records
        .iter()
        .zip(&delta)
        .map(|(r, &d)| {
            let h = theoretical_drop(r.theta_deg, length);
            let fitted = fit.eval(r.theta_deg);
            Point {
                theta_deg: r.theta_deg,
                delta_theta_deg: d,
                line: r.line,
                z1: r.z1,
                z2: r.z2,
                z3: r.z3,
                z1_minus_z3: r.z1 - r.z3,
                z1_minus_z2: r.z2.map(|z2| r.z1 - z2),
                z2_minus_z3: r.z2.map(|z2| z2 - r.z3),
                h_mm: h,
                delta_z_mm: (r.z1 - r.z3) - h,
                fitted_deg: fitted,
                residual_deg: d - fitted,
            }
        })
        .collect();
    let residuals: Vec<f64> = points.iter().map(|p| p.residual_deg).collect();
    let lo = theta.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = theta.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let compensation = Compensation {
        order: fit.order,
        coefficients: fit.coefficients.clone(),
        law: format!("delta_theta = {}", polynomial_text(&fit.coefficients, "theta")),
        usage: "theta and delta_theta in degrees; commanding theta_t leaves the axis at theta_a = theta_t + delta_theta(theta_t) (Eq. 7); to reach theta_t, command the c with c + delta_theta(c) = theta_t (about theta_t - delta_theta(theta_t))".to_string(),
        fitted_range_deg: [lo, hi],
        residual: ResidualSummary {
            before: Spread::of(&delta),
            after: Spread::of(&residuals),
            loocv_rms_deg: fit.loocv_rmse,
        },
        fit,
    };
    Ok(Analysis {
        length,
        points,
        fits,
        selected_order,
        selection,
        compensation,
        file,
    })
}

/// A polynomial in ascending coefficients as text readable by SymPy and
/// MATLAB, e.g. `0.18 - 0.0295*theta + 0.00231*theta^2`.
pub fn polynomial_text(coefficients: &[f64], variable: &str) -> String {
    let mut out = String::new();
    for (k, &c) in coefficients.iter().enumerate() {
        let magnitude = format!("{:.6e}", c.abs());
        let term = match k {
            0 => magnitude,
            1 => format!("{magnitude}*{variable}"),
            _ => format!("{magnitude}*{variable}^{k}"),
        };
        if out.is_empty() {
            if c < 0.0 {
                out.push('-');
            }
            out.push_str(&term);
        } else {
            out.push_str(if c < 0.0 { " - " } else { " + " });
            out.push_str(&term);
        }
    }
    if out.is_empty() {
        out.push('0');
    }
    out
}

// ---------------------------------------------------------------------------
// Grid
// ---------------------------------------------------------------------------

/// An angle grid `START:STEP:END` (degrees, `END` included when it falls on
/// the grid).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    /// First angle.
    pub start: f64,
    /// Spacing (positive).
    pub step: f64,
    /// Last angle (inclusive bound).
    pub end: f64,
}

impl Grid {
    /// A grid with unit steps over `[start, end]`.
    pub fn unit(start: f64, end: f64) -> Grid {
        Grid {
            start,
            step: 1.0,
            end,
        }
    }

    /// The grid's angles.
    pub fn points(&self) -> Result<Vec<f64>, CompensateError> {
        let bad = |message: String| CompensateError::InvalidGrid { message };
        if !(self.start.is_finite() && self.step.is_finite() && self.end.is_finite()) {
            return Err(bad("start, step and end must be finite".into()));
        }
        if self.step <= 0.0 {
            return Err(bad(format!("step {} must be positive", self.step)));
        }
        if self.end < self.start {
            return Err(bad(format!(
                "end {} is below start {}",
                self.end, self.start
            )));
        }
        let count = ((self.end - self.start) / self.step * (1.0 + 1e-12) + 1e-9).floor() + 1.0;
        if count.is_nan() || count > MAX_GRID_POINTS as f64 {
            return Err(bad(format!(
                "{count} angles is more than {MAX_GRID_POINTS}"
            )));
        }
        Ok((0..count as usize)
            .map(|i| self.start + i as f64 * self.step)
            .collect())
    }
}

impl FromStr for Grid {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let parts: Vec<&str> = s.split(':').map(str::trim).collect();
        let [start, step, end] = parts.as_slice() else {
            return Err(format!("`{s}` is not START:STEP:END (degrees)"));
        };
        let number = |t: &str| -> Result<f64, String> {
            t.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| format!("`{t}` in `{s}` is not a finite number"))
        };
        Ok(Grid {
            start: number(start)?,
            step: number(step)?,
            end: number(end)?,
        })
    }
}

impl fmt::Display for Grid {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}:{}", self.start, self.step, self.end)
    }
}

// ---------------------------------------------------------------------------
// Plots
// ---------------------------------------------------------------------------

/// Writes the figures of an analysis into `dir` (created if missing), each as
/// PNG and SVG, and returns the paths written:
///
/// - `swing_fit_order{p}`: measured `Δθ` and the order-`p` fit, one per order
///   (the seed's Figures 4-8);
/// - `swing_fits`: the measured `Δθ` and every fit (Figure 9);
/// - `swing_residuals`: `Δθ` before and the residual predicted after
///   compensation with the selected law.
pub fn write_plots(analysis: &Analysis, dir: &Path) -> Result<Vec<PathBuf>, PlotError> {
    let measured: Vec<(f64, f64)> = analysis
        .points
        .iter()
        .map(|p| (p.theta_deg, p.delta_theta_deg))
        .collect();
    let [lo, hi] = analysis.angle_range();
    let curve = |fit: &PolyFit| -> Vec<(f64, f64)> {
        (0..=240)
            .map(|i| {
                let x = lo + (hi - lo) * i as f64 / 240.0;
                (x, fit.eval(x))
            })
            .collect()
    };
    let x_label = "commanded swing angle θ (°)";
    let y_label = "swing-angle error Δθ (°)";
    let mut written = Vec::new();
    for (i, fit) in analysis.fits.iter().enumerate() {
        let chart = XyChart::new(
            format!("Order-{} fit of Δθ (R² = {:.4})", fit.order, fit.r2),
            x_label,
            y_label,
        )
        .series(Series::points("measured Δθ", measured.clone()).color(plot::GREY))
        .series(
            Series::line(format!("order {} fit", fit.order), curve(fit))
                .color(plot::color(i))
                .width(3),
        )
        .hline(0.0);
        written.extend(chart.write(dir, &format!("swing_fit_order{}", fit.order))?);
    }
    let mut all = XyChart::new("Δθ fitted by polynomials of each order", x_label, y_label)
        .series(Series::points("measured Δθ", measured.clone()).color(plot::GREY))
        .hline(0.0);
    for (i, fit) in analysis.fits.iter().enumerate() {
        all = all.series(
            Series::line(
                format!("order {} (R² {:.4})", fit.order, fit.r2),
                curve(fit),
            )
            .color(plot::color(i))
            .width(2),
        );
    }
    written.extend(all.write(dir, "swing_fits")?);
    let residuals: Vec<(f64, f64)> = analysis
        .points
        .iter()
        .map(|p| (p.theta_deg, p.residual_deg))
        .collect();
    let residual_chart = XyChart::new(
        format!(
            "Δθ before and predicted after order-{} compensation",
            analysis.selected_order
        ),
        x_label,
        "error (°)",
    )
    .series(Series::line_points("before: measured Δθ", measured).color(plot::GREY))
    .series(
        Series::line_points(
            format!(
                "after: residual of the order-{} law",
                analysis.selected_order
            ),
            residuals,
        )
        .color(plot::color(0)),
    )
    .hline(0.0);
    written.extend(residual_chart.write(dir, "swing_residuals")?);
    Ok(written)
}
