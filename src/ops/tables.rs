//! The numeric CSV tables commands read from a file — the poses of `chain
//! inverse --pose` and `chain path --pose`, the axis values of `chain path
//! --axes`, `chain map --axes` and `chain export --axes` — from a path or
//! from bytes the caller read (the CLI's stdin, a Python string): one
//! reader and one wording whichever way in. Every refusal names the file,
//! the line and, for a cell, the column.
//!
//! The reader is chain-core's one CSV reader
//! ([`chain_core::values::csv::CsvFile`]): a leading byte-order mark is
//! dropped, `#` lines and blank lines skipped; text that is not UTF-8 or
//! holds a NUL byte, a header-only file and a ragged row are refused as
//! `file:line: …`.

use chain_core::bounded::{self, ReadError};
use chain_core::tabular;
use chain_core::values::csv::CsvFile;
use chain_core::Machine;

use super::inverse::{PoseError, PoseRow, AXIS_COLUMNS, ROTATION_COLUMNS};
use super::resolve::{AxesColumns, ResolveError};
use super::source::Source;
use super::worded::{diagnostic, Worded};

/// Why a table cannot be read.
#[derive(Debug, thiserror::Error)]
pub enum TableError {
    /// The input is larger than its bound.
    #[error("{name}: {error}")]
    TooLarge {
        /// The table's name.
        name: String,
        /// The bound.
        error: ReadError,
    },
    /// The input cannot be read.
    #[error("cannot read {name}: {error}")]
    Io {
        /// The table's name.
        name: String,
        /// Why.
        error: ReadError,
    },
    /// The CSV reader's refusal, located `file:line: …`.
    #[error("{message}")]
    Refused {
        /// The located message.
        message: String,
        /// Its code (`chain::csv::…`).
        code: &'static str,
    },
    /// A pose table whose header is neither pose layout.
    #[error("{name}:1: expected the header `px,py,pz,i,j,k` or `px,py,pz,r11,r12,r13,r21,r22,r23,r31,r32,r33` (optionally after a first column `t`), found `{found}`")]
    PoseHeader {
        /// The table's name.
        name: String,
        /// The header found.
        found: String,
    },
    /// A pose row that is not a pose.
    #[error("{name}:{line}: {error}")]
    Pose {
        /// The table's name.
        name: String,
        /// The row's line.
        line: usize,
        /// Why.
        error: PoseError,
    },
    /// Axis columns that do not match the machine.
    #[error(transparent)]
    Resolve(#[from] ResolveError),
}

impl TableError {
    /// A failed read of the input named `name`.
    pub fn of_read(name: &str, error: ReadError) -> TableError {
        let name = name.to_string();
        match error {
            e @ ReadError::TooLarge { .. } => TableError::TooLarge { name, error: e },
            e => TableError::Io { name, error: e },
        }
    }
}

impl Worded for TableError {
    fn own_code(&self) -> Option<&'static str> {
        match self {
            TableError::TooLarge { .. } => Some("chain::too_large"),
            TableError::Io { .. } => Some("chain::io"),
            TableError::Refused { code, .. } => Some(code),
            TableError::PoseHeader { .. } | TableError::Pose { .. } | TableError::Resolve(_) => {
                None
            }
        }
    }

    #[cfg(feature = "cli")]
    fn inner(&self) -> Option<&dyn miette::Diagnostic> {
        match self {
            TableError::Resolve(e) => Some(e),
            _ => None,
        }
    }
}

diagnostic!(TableError);

/// A table read: its name, located cells and trimmed header.
#[derive(Debug)]
pub struct Table {
    /// The name messages give it (the path as given, or the caller's).
    pub name: String,
    /// Its cells.
    pub cells: CsvFile,
    /// The header's names, trimmed.
    pub header: Vec<String>,
}

impl Table {
    /// Reads and parses a table (see the module's documentation).
    pub fn read(source: Source<'_>) -> Result<Table, TableError> {
        let (name, read);
        let bytes = match source {
            Source::Path(path) => {
                name = path.display().to_string();
                read = bounded::read_path(path, bounded::PATH_BYTES)
                    .map_err(|e| TableError::of_read(&name, e))?;
                &read[..]
            }
            Source::Bytes { name: n, bytes } => {
                name = n.to_string();
                bytes
            }
        };
        let cells =
            CsvFile::parse_bytes(bytes, &name, "the header names the columns, e.g. `t,x,y,z`")
                .map_err(|d| {
                    let first = d.first();
                    TableError::Refused {
                        message: format!(
                            "{name}:{}: {}",
                            first.origin.line,
                            first.problem.headline()
                        ),
                        code: first.problem.code(),
                    }
                })?;
        let header = cells.header.iter().map(|(h, _)| h.clone()).collect();
        Ok(Table {
            name,
            cells,
            header,
        })
    }

    /// Every data row as finite numbers, `(line, values)`; a cell that is
    /// not is refused as `file:line: column `name`: …`.
    pub fn numeric_rows(&self) -> Result<Vec<(usize, Vec<f64>)>, TableError> {
        let name = &self.name;
        (self.cells.rows())
            .map(|row| {
                let line = row.first().map_or(0, |(_, o)| o.line);
                let values = (row.iter())
                    .map(|(text, origin)| {
                        tabular::number(text, &origin.key).map_err(|p| TableError::Refused {
                            message: p.at(name, line as u64),
                            code: p.code(),
                        })
                    })
                    .collect::<Result<Vec<f64>, _>>()?;
                Ok((line, values))
            })
            .collect()
    }
}

/// A table of numbers as a command takes it: its name, header and rows.
#[derive(Debug, Clone, PartialEq)]
pub struct NumericTable {
    /// The name messages give it.
    pub name: String,
    /// The header's names, trimmed.
    pub header: Vec<String>,
    /// The data rows, every cell a finite number.
    pub rows: Vec<Vec<f64>>,
}

/// A table whose every cell is a finite number ([`Table::numeric_rows`]):
/// the axis values of `chain path --axes` by named column.
pub fn read_numbers(source: Source<'_>) -> Result<NumericTable, TableError> {
    let table = Table::read(source)?;
    let rows = table.numeric_rows()?;
    Ok(NumericTable {
        name: table.name,
        header: table.header,
        rows: rows.into_iter().map(|(_, r)| r).collect(),
    })
}

/// A pose table: header `px,py,pz,i,j,k` (tool point and tool axis) or
/// `px,py,pz,r11,…,r33` (tool point and the tool frame's rotation,
/// row-major; refused unless orthonormal to 1e-6 with det +1), optionally
/// after a first column `t`. Returns whether `t` was given, and the poses.
pub fn read_poses(source: Source<'_>) -> Result<(bool, Vec<PoseRow>), TableError> {
    let table = Table::read(source)?;
    let has_t = table.header.first().is_some_and(|h| h == "t");
    let skip = usize::from(has_t);
    let columns = &table.header[skip..];
    if columns != AXIS_COLUMNS && columns != ROTATION_COLUMNS {
        return Err(TableError::PoseHeader {
            name: table.name.clone(),
            found: table.header.join(","),
        });
    }
    let rows = table.numeric_rows()?;
    let poses = (rows.into_iter())
        .map(|(line, all)| {
            PoseRow::from_values(has_t.then_some(all[0]), &all[skip..]).map_err(|error| {
                TableError::Pose {
                    name: table.name.clone(),
                    line,
                    error,
                }
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok((has_t, poses))
}

/// The points of an axes table, every row in `m`'s variable order
/// ([`AxesColumns`]: every variable has a column), flat.
pub fn axes_points(source: Source<'_>, m: &Machine) -> Result<Vec<f64>, TableError> {
    let table = Table::read(source)?;
    let columns = AxesColumns::resolve(m, &table.name, &table.header, None)?;
    let rows = table.numeric_rows()?;
    let mut points = Vec::with_capacity(rows.len() * m.variables.len());
    for (_, values) in rows {
        points.extend(columns.point(&values));
    }
    Ok(points)
}
