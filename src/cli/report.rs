//! The CLI's one report layer.
//!
//! Every subcommand turns its library results into a typed, serialisable
//! document (a struct implementing [`Report`]) and hands it here. The three
//! formats are rendered in one place each:
//!
//! - JSON: [`json`], `serde_json` over the document itself (the document's
//!   fields, in declaration order, are the JSON keys; non-finite numbers
//!   become `null`);
//! - CSV: [`Csv`], one writer (the `csv` crate) over the rows the document
//!   lists in [`Report::csv`];
//! - tables: [`Report::table`], the human-readable text of each document.
//!
//! [`emit`] renders a document in the chosen format and writes it to stdout
//! with one error rule ([`write_stdout`]): a closed pipe ends the output
//! quietly, any other write error is reported and the exit is non-zero.

use std::io::Write;

use miette::IntoDiagnostic;
use serde::Serialize;

/// The formats a [`Report`] renders to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// The human-readable table or text report.
    Table,
    /// The JSON document (the spec's contract where it defines one).
    Json,
    /// CSV, one row per record.
    Csv,
}

/// `impl From<E> for Format` for a command's own `--format` enum `E` (its
/// help texts are the command's), whose variants are named like
/// [`Format`]'s: `report::formats!(PathFormat: Table, Json, Csv);`.
macro_rules! formats {
    ($ty:ident: $($variant:ident),+) => {
        impl From<$ty> for $crate::cli::report::Format {
            fn from(f: $ty) -> Self {
                match f {
                    $($ty::$variant => $crate::cli::report::Format::$variant,)+
                }
            }
        }
    };
}
pub(crate) use formats;

/// `v` as an integer when it is a whole number below 1e15 in magnitude: how
/// the tables print whole numbers.
pub(crate) fn whole(v: f64) -> Option<i64> {
    (v == v.trunc() && v.abs() < 1e15).then_some(v as i64)
}

/// A command's result document: serialisable (its JSON form) with a table and,
/// optionally, a CSV form.
pub trait Report: Serialize {
    /// The human-readable table (ends with a newline).
    fn table(&self) -> String;

    /// The CSV form, for documents that have one (`None`: the command does
    /// not offer `--format csv`).
    fn csv(&self) -> Option<Csv> {
        None
    }
}

/// A CSV table: a header and rows of already formatted cells.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Csv {
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl Csv {
    /// A table with these column names and no row yet.
    pub fn new<I, S>(header: I) -> Csv
    where
        I: IntoIterator<Item = S>,
        S: Into<String>,
    {
        Csv {
            header: header.into_iter().map(Into::into).collect(),
            rows: Vec::new(),
        }
    }

    /// Appends one row (as many cells as the header has columns).
    pub fn row<I, S>(&mut self, cells: I)
    where
        I: IntoIterator<Item = S>,
        S: Into<String>,
    {
        let row: Vec<String> = cells.into_iter().map(Into::into).collect();
        debug_assert_eq!(row.len(), self.header.len(), "CSV row width");
        self.rows.push(row);
    }

    /// The CSV text (RFC 4180 quoting, `\n` line ends).
    pub fn render(&self) -> miette::Result<String> {
        let mut w = csv::Writer::from_writer(Vec::new());
        let err = |e: csv::Error| miette::miette!("cannot write CSV: {e}");
        w.write_record(&self.header).map_err(err)?;
        for row in &self.rows {
            w.write_record(row).map_err(err)?;
        }
        let bytes = w
            .into_inner()
            .map_err(|e| miette::miette!("cannot write CSV: {e}"))?;
        String::from_utf8(bytes).into_diagnostic()
    }
}

/// The pretty-printed JSON of any serialisable document, with a final newline.
pub fn json<T: Serialize + ?Sized>(doc: &T) -> miette::Result<String> {
    let mut s = serde_json::to_string_pretty(doc)
        .map_err(|e| miette::miette!("cannot serialise the result: {e}"))?;
    s.push('\n');
    Ok(s)
}

/// A document rendered in `format`.
pub fn render<R: Report>(doc: &R, format: Format) -> miette::Result<String> {
    match format {
        Format::Table => Ok(doc.table()),
        Format::Json => json(doc),
        Format::Csv => match doc.csv() {
            Some(csv) => csv.render(),
            None => Err(miette::miette!("this command has no CSV output")),
        },
    }
}

/// Renders a document in `format` and writes it to stdout.
pub fn emit<R: Report>(doc: &R, format: Format) -> miette::Result<()> {
    write_stdout(&render(doc, format)?)
}

/// Writes to stdout; a closed pipe (`| head`) ends the output quietly, any
/// other failure (a full disk, `> /dev/full`) is an error.
pub fn write_stdout(text: &str) -> miette::Result<()> {
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        Err(e) => Err(miette::miette!("cannot write the output: {e}")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Serialize)]
    struct Doc {
        name: &'static str,
        value: f64,
    }

    impl Report for Doc {
        fn table(&self) -> String {
            format!("{} = {}\n", self.name, self.value)
        }
        fn csv(&self) -> Option<Csv> {
            let mut c = Csv::new(["name", "value"]);
            c.row([self.name.to_string(), format!("{:?}", self.value)]);
            Some(c)
        }
    }

    #[test]
    fn one_document_three_formats() {
        let d = Doc {
            name: "a,b",
            value: 0.5,
        };
        assert_eq!(render(&d, Format::Table).unwrap(), "a,b = 0.5\n");
        assert_eq!(
            render(&d, Format::Json).unwrap(),
            "{\n  \"name\": \"a,b\",\n  \"value\": 0.5\n}\n"
        );
        assert_eq!(
            render(&d, Format::Csv).unwrap(),
            "name,value\n\"a,b\",0.5\n"
        );
    }
}
