//! The CLI's one report layer.
//!
//! Every subcommand turns its library results into a typed, serialisable
//! document (a struct implementing [`Report`]) and hands it here. The three
//! formats are rendered in one place each:
//!
//! - JSON: [`json`], `serde_json` over the document itself (the document's
//!   fields, in declaration order, are the JSON keys; non-finite numbers
//!   become `null`);
//! - CSV: [`Csv`], one writer (the `csv` crate) that the document's
//!   [`Report::csv`] writes its header and rows into, each as it is formed;
//! - tables: [`Report::table`], the human-readable text of each document.
//!
//! [`emit`] renders a document in the chosen format straight into a buffered
//! stdout (JSON and CSV are never held as one string)
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

    /// Writes the table into `out`: [`Report::table`], unless the document
    /// writes its rows as they come (a streamed path).
    fn write_table(&self, out: &mut dyn Write) -> std::io::Result<()> {
        out.write_all(self.table().as_bytes())
    }

    /// Writes the CSV form into `out`, a header and then each row as it is
    /// formed (nothing is collected, so a million-row map streams);
    /// `None` when the document has no CSV form (the command does not offer
    /// `--format csv`), having written nothing.
    fn csv(&self, out: &mut Csv<'_>) -> Option<()> {
        let _ = out;
        None
    }
}

/// The CSV writer a [`Report::csv`] writes into: a header, then rows of
/// already formatted cells (RFC 4180 quoting, `\n` line ends, through the
/// `csv` crate), each written as it comes. The first write error is kept
/// (the rows after it are dropped unwritten) and returned when the table is
/// finished.
pub struct Csv<'a> {
    writer: csv::Writer<&'a mut dyn Write>,
    width: usize,
    failed: Option<csv::Error>,
}

impl<'a> Csv<'a> {
    /// A CSV table written into `out`.
    pub fn new(out: &'a mut dyn Write) -> Csv<'a> {
        Csv {
            writer: csv::Writer::from_writer(out),
            width: 0,
            failed: None,
        }
    }

    /// Writes the header: the column names.
    pub fn header<I, S>(&mut self, columns: I)
    where
        I: IntoIterator<Item = S>,
        S: AsRef<[u8]>,
    {
        let columns: Vec<S> = columns.into_iter().collect();
        self.width = columns.len();
        self.write(columns);
    }

    /// Writes one row (as many cells as the header has columns).
    pub fn row<I, S>(&mut self, cells: I)
    where
        I: IntoIterator<Item = S>,
        S: AsRef<[u8]>,
    {
        let cells: Vec<S> = cells.into_iter().collect();
        debug_assert_eq!(cells.len(), self.width, "CSV row width");
        self.write(cells);
    }

    fn write<S: AsRef<[u8]>>(&mut self, cells: Vec<S>) {
        if self.failed.is_none() {
            if let Err(e) = self.writer.write_record(cells) {
                self.failed = Some(e);
            }
        }
    }

    /// Flushes the table; the first error of any write.
    fn finish(mut self) -> std::io::Result<()> {
        if let Some(e) = self.failed.take() {
            return Err(csv_io(e));
        }
        self.writer.flush()
    }
}

/// A CSV writer's error as the I/O error it wraps (a record of the wrong
/// width, a bug of the document, as `InvalidData`).
fn csv_io(e: csv::Error) -> std::io::Error {
    match e.into_kind() {
        csv::ErrorKind::Io(io) => io,
        other => std::io::Error::new(std::io::ErrorKind::InvalidData, format!("{other:?}")),
    }
}

/// The pretty-printed JSON of any serialisable document, with a final newline.
pub fn json<T: Serialize + ?Sized>(doc: &T) -> miette::Result<String> {
    let mut out = Vec::new();
    write_json(doc, &mut out).map_err(|e| miette::miette!("cannot serialise the result: {e}"))?;
    String::from_utf8(out).into_diagnostic()
}

/// Writes a document's pretty-printed JSON (and a final newline) into `out`
/// as it is serialised (no string of the whole document is formed).
fn write_json<T: Serialize + ?Sized>(doc: &T, out: &mut dyn Write) -> std::io::Result<()> {
    serde_json::to_writer_pretty(&mut *out, doc)?;
    out.write_all(b"\n")
}

/// Writes a document in `format` into `out`: the one place each format is
/// rendered. `Ok(false)`: the document has no CSV form.
fn write_to<R: Report>(doc: &R, format: Format, out: &mut dyn Write) -> std::io::Result<bool> {
    match format {
        Format::Table => doc.write_table(out)?,
        Format::Json => write_json(doc, out)?,
        Format::Csv => {
            let mut csv = Csv::new(out);
            if doc.csv(&mut csv).is_none() {
                return Ok(false);
            }
            csv.finish()?;
        }
    }
    Ok(true)
}

/// A document rendered in `format`, as a string (what [`emit`] writes).
#[cfg(test)]
pub fn render<R: Report>(doc: &R, format: Format) -> miette::Result<String> {
    let mut out = Vec::new();
    match write_to(doc, format, &mut out) {
        Ok(true) => String::from_utf8(out).into_diagnostic(),
        Ok(false) => Err(no_csv()),
        Err(e) => Err(miette::miette!("cannot render the result: {e}")),
    }
}

fn no_csv() -> miette::Report {
    miette::miette!("this command has no CSV output")
}

/// Renders a document in `format` straight into stdout (buffered; a
/// million-point JSON or CSV document is never held as one string), with
/// [`write_stdout`]'s error rule.
pub fn emit<R: Report>(doc: &R, format: Format) -> miette::Result<()> {
    let stdout = std::io::stdout().lock();
    let mut out = std::io::BufWriter::with_capacity(1 << 16, stdout);
    match write_to(doc, format, &mut out).and_then(|has| out.flush().map(|()| has)) {
        Ok(true) => Ok(()),
        Ok(false) => Err(no_csv()),
        Err(e) => written(e),
    }
}

/// Writes to stdout; a closed pipe (`| head`) ends the output quietly, any
/// other failure (a full disk, `> /dev/full`) is an error.
pub fn write_stdout(text: &str) -> miette::Result<()> {
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Ok(()) => Ok(()),
        Err(e) => written(e),
    }
}

/// The one rule for a failed write to stdout.
fn written(e: std::io::Error) -> miette::Result<()> {
    if e.kind() == std::io::ErrorKind::BrokenPipe {
        Ok(())
    } else {
        Err(miette::miette!("cannot write the output: {e}"))
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
        fn csv(&self, out: &mut Csv<'_>) -> Option<()> {
            out.header(["name", "value"]);
            out.row([self.name.to_string(), format!("{:?}", self.value)]);
            Some(())
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
