//! The one wording of the CSV readers' refusals: every CSV input
//! of the toolkit — values tables, measurement and candidate files (located
//! diagnostics, `file:line:column: …` with a snippet), and the command
//! line's `chain inverse --pose`, `chain path --axes` and `chain compensate
//! FILE` (`file:line: …`) — words a malformed or header-only file, a bad
//! header, a ragged row and a bad cell with the same [`CsvProblem`]
//! ([`CsvProblem::describe`], also [`crate::diagnostic::Problem::Csv`]'s
//! wording), under the same code. A cell's message names its column:
//! ``column `y`: `abc` is not a number``.

use crate::diagnostic::{shortened, Description};
use std::fmt;

/// One refusal of a CSV input, worded by [`CsvProblem::describe`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum CsvProblem {
    /// Not CSV: a record the CSV reader refuses (a line that is not valid
    /// UTF-8, ...).
    Malformed {
        /// The reader's message.
        message: String,
    },
    /// No header line (the file is empty, or only comments and blank lines).
    Empty {
        /// What the header of this kind of file names (the help).
        header: String,
    },
    /// A header column without a name.
    UnnamedColumn {
        /// Its 1-based position.
        column: usize,
        /// What the header of this kind of file names (the help).
        header: String,
    },
    /// A name given twice in the header.
    RepeatedColumn {
        /// The name.
        name: String,
        /// The 1-based column of its first occurrence.
        first: usize,
    },
    /// A header and no data row.
    NoData,
    /// A row with another number of fields than the header.
    Ragged {
        /// The row's fields.
        fields: usize,
        /// The header's columns.
        columns: usize,
    },
    /// A cell that does not parse as a number.
    NotANumber {
        /// The column's name.
        column: String,
        /// The cell as written.
        text: String,
    },
    /// A cell that parses to NaN or an infinity (or overflows `f64`).
    NotFinite {
        /// The column's name.
        column: String,
        /// The cell as written.
        text: String,
    },
    /// An empty cell where a number is needed.
    EmptyCell {
        /// The column's name.
        column: String,
    },
}

impl CsvProblem {
    /// Every part of the message of this refusal (headline, help, span
    /// label, code): one match arm per variant.
    pub fn describe(&self) -> Description {
        use Description as D;
        match self {
            CsvProblem::Malformed { message } => D::new(
                "chain::values::csv_malformed",
                "malformed",
                format!("malformed CSV: {message}"),
            ),
            CsvProblem::Empty { header } => D::new(
                "chain::csv::empty",
                "empty",
                "the file is empty; expected a header line",
            )
            .help(header.clone()),
            CsvProblem::UnnamedColumn { column, header } => D::new(
                "chain::values::csv_header",
                "no name",
                format!("column {column} of the header has no name"),
            )
            .help(header.clone()),
            CsvProblem::RepeatedColumn { name, first } => D::new(
                "chain::values::csv_header",
                "repeated",
                format!("column `{name}` appears twice in the header (first in column {first})"),
            ),
            CsvProblem::NoData => D::new(
                "chain::csv::no_data",
                "no data row",
                "the header is followed by no data row",
            )
            .help("each row after the header is one record".to_string()),
            CsvProblem::Ragged { fields, columns } => D::new(
                "chain::csv::ragged",
                "row",
                format!(
                    "this row has {} but the header has {}",
                    plural(*fields, "field"),
                    plural(*columns, "column")
                ),
            ),
            CsvProblem::NotANumber { column, text } => D::new(
                "chain::csv::not_a_number",
                "not a number",
                format!("column `{column}`: `{}` is not a number", shortened(text)),
            ),
            CsvProblem::NotFinite { column, text } => D::new(
                "chain::csv::not_finite",
                "not finite",
                format!("column `{column}`: `{}` is not finite", shortened(text)),
            ),
            CsvProblem::EmptyCell { column } => D::new(
                "chain::csv::empty_cell",
                "empty",
                format!("column `{column}`: the cell is empty"),
            ),
        }
    }

    /// The diagnostic code: `chain::csv::…` ([`Description::code`]).
    pub fn code(&self) -> &'static str {
        self.describe().code
    }

    /// The message located at `file:line`: `file:line: column `y`: …`.
    pub fn at(&self, file: &str, line: u64) -> String {
        format!("{file}:{line}: {self}")
    }
}

impl fmt::Display for CsvProblem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.describe().headline)
    }
}

/// A cell of column `column` as a finite number.
pub fn number(text: &str, column: &str) -> Result<f64, CsvProblem> {
    match text.parse::<f64>() {
        Ok(x) if x.is_finite() => Ok(x),
        Ok(_) => Err(CsvProblem::NotFinite {
            column: column.to_string(),
            text: text.to_string(),
        }),
        Err(_) if text.is_empty() => Err(CsvProblem::EmptyCell {
            column: column.to_string(),
        }),
        Err(_) => Err(CsvProblem::NotANumber {
            column: column.to_string(),
            text: text.to_string(),
        }),
    }
}

/// `1 field`, `3 fields`.
fn plural(n: usize, what: &str) -> String {
    if n == 1 {
        format!("1 {what}")
    } else {
        format!("{n} {what}s")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_wording() {
        assert_eq!(number(" 1.5".trim(), "x"), Ok(1.5));
        let e = number("abc", "y").unwrap_err();
        assert_eq!(
            e.at("a.csv", 3),
            "a.csv:3: column `y`: `abc` is not a number"
        );
        assert_eq!(e.code(), "chain::csv::not_a_number");
        assert_eq!(
            number("1e400", "y").unwrap_err().to_string(),
            "column `y`: `1e400` is not finite"
        );
        assert_eq!(
            CsvProblem::Ragged {
                fields: 2,
                columns: 3
            }
            .to_string(),
            "this row has 2 fields but the header has 3 columns"
        );
    }
}
