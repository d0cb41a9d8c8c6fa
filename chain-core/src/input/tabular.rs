//! The one wording of the CSV readers' refusals: every CSV input
//! of the toolkit — values tables, measurement and candidate files (located
//! diagnostics, `file:line:column: …` with a snippet), and the command
//! line's `chain inverse --pose`, `chain path --axes` and `chain compensate
//! FILE` (`file:line: …`) — words a header-only file, a ragged row and a
//! bad cell with the same [`CsvProblem`], under the same `chain::csv::*`
//! code. A cell's message names its column: ``column `y`: `abc` is not a
//! number``.

use crate::diagnostic::shortened;
use std::fmt;

/// One refusal of a CSV input.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum CsvProblem {
    /// No header line (the file is empty, or only comments and blank lines).
    Empty,
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
    /// The diagnostic code: `chain::csv::…`.
    pub fn code(&self) -> &'static str {
        match self {
            CsvProblem::Empty => "chain::csv::empty",
            CsvProblem::NoData => "chain::csv::no_data",
            CsvProblem::Ragged { .. } => "chain::csv::ragged",
            CsvProblem::NotANumber { .. } => "chain::csv::not_a_number",
            CsvProblem::NotFinite { .. } => "chain::csv::not_finite",
            CsvProblem::EmptyCell { .. } => "chain::csv::empty_cell",
        }
    }

    /// The short label of a snippet.
    pub fn label(&self) -> &'static str {
        match self {
            CsvProblem::Empty => "empty",
            CsvProblem::NoData => "no data row",
            CsvProblem::Ragged { .. } => "row",
            CsvProblem::NotANumber { .. } => "not a number",
            CsvProblem::NotFinite { .. } => "not finite",
            CsvProblem::EmptyCell { .. } => "empty",
        }
    }

    /// The message located at `file:line`: `file:line: column `y`: …`.
    pub fn at(&self, file: &str, line: u64) -> String {
        format!("{file}:{line}: {self}")
    }
}

impl fmt::Display for CsvProblem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CsvProblem::Empty => write!(f, "the file is empty; expected a header line"),
            CsvProblem::NoData => write!(f, "the header is followed by no data row"),
            CsvProblem::Ragged { fields, columns } => write!(
                f,
                "this row has {} but the header has {}",
                plural(*fields, "field"),
                plural(*columns, "column")
            ),
            CsvProblem::NotANumber { column, text } => {
                write!(
                    f,
                    "column `{column}`: `{}` is not a number",
                    shortened(text)
                )
            }
            CsvProblem::NotFinite { column, text } => {
                write!(f, "column `{column}`: `{}` is not finite", shortened(text))
            }
            CsvProblem::EmptyCell { column } => write!(f, "column `{column}`: the cell is empty"),
        }
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
