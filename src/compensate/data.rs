//! The measured points as typed rows.
//!
//! The library takes a measurement file already split into records (the
//! `chain` binary reads CSV with its shared input module, `src/cli/csv_input.rs`):
//! the first record is the header, the others the data rows, each with the
//! line it starts on. [`Measurements::from_records`] resolves the columns and
//! checks every cell.

use serde::Serialize;

use super::CompensateError;

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

/// One record of a measurement file as read: its line (1-based) and its
/// fields (trimmed).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RawRecord {
    /// Line the record starts on (1-based, as an editor shows it).
    pub line: u64,
    /// The fields, in file order.
    pub fields: Vec<String>,
}

impl RawRecord {
    /// A record at `line` with these fields.
    pub fn new<I, S>(line: u64, fields: I) -> RawRecord
    where
        I: IntoIterator<Item = S>,
        S: Into<String>,
    {
        RawRecord {
            line,
            fields: fields.into_iter().map(Into::into).collect(),
        }
    }
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

    /// The measurements of a file given as records (the first is the header).
    ///
    /// The header names the columns `theta_deg`, `z1`, `z3` and optionally
    /// `z2`, in any order and case; other columns are ignored. Every data row
    /// has as many fields as the header, every cell is a finite number and
    /// every angle lies in the open interval (0°, 90°). `file` names the
    /// source in error messages, with the records' lines.
    pub fn from_records<I>(file: &str, records: I) -> Result<Measurements, CompensateError>
    where
        I: IntoIterator<Item = RawRecord>,
    {
        let mut records = records.into_iter();
        let Some(header) = records.next() else {
            return Err(CompensateError::Empty {
                file: file.to_string(),
            });
        };
        let header_line = header.line;
        let names: Vec<String> = header
            .fields
            .iter()
            .map(|n| n.to_ascii_lowercase())
            .collect();
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
                    .fields
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

        let mut rows = Vec::new();
        for row in records {
            let line = row.line;
            if row.fields.len() != header.fields.len() {
                return Err(CompensateError::Ragged {
                    file: file.to_string(),
                    line,
                    fields: row.fields.len(),
                    columns: header.fields.len(),
                });
            }
            let cell = |index: usize, column: &'static str| -> Result<f64, CompensateError> {
                let text = row.fields.get(index).map_or("", String::as_str);
                use chain_core::tabular::{number, CsvProblem};
                number(text, column).map_err(|problem| match problem {
                    CsvProblem::EmptyCell { .. } => CompensateError::EmptyCell {
                        file: file.to_string(),
                        line,
                        column,
                    },
                    CsvProblem::NotFinite { .. } => CompensateError::NotFinite {
                        file: file.to_string(),
                        line,
                        column,
                        value: text.to_string(),
                    },
                    _ => CompensateError::NotNumeric {
                        file: file.to_string(),
                        line,
                        column,
                        value: text.to_string(),
                    },
                })
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
            rows.push(Record {
                line,
                theta_deg,
                z1,
                z2,
                z3,
            });
        }
        if rows.is_empty() {
            return Err(CompensateError::NoData {
                file: file.to_string(),
                header_line,
            });
        }
        Ok(Measurements {
            source: file.to_string(),
            header_line,
            records: rows,
        })
    }
}
