//! Reading the measurement CSV of `chain compensate` (feature `records`:
//! the `csv` crate): the records of a file or of its bytes, leniently, with
//! the lines they start on; [`crate::compensate::Measurements::from_records`]
//! types and checks them. The CLI and Python read through it.

use std::path::Path;

use chain_core::bounded;

use super::{CompensateError, Measurements, RawRecord};

/// The measurements of the CSV file at `path`.
pub fn read_measurements(path: &Path) -> Result<Measurements, CompensateError> {
    let name = path.display().to_string();
    Measurements::from_records(&name, read_records(path).map_err(RecordsError::into_error)?)
}

/// The measurements of CSV bytes named `name`.
pub fn parse_measurements(name: &str, data: &[u8]) -> Result<Measurements, CompensateError> {
    Measurements::from_records(
        name,
        parse_records(name, data).map_err(RecordsError::into_error)?,
    )
}

/// Why [`read_records`] could not read a file.
#[derive(Debug)]
enum RecordsError {
    /// The file could not be read.
    Io {
        /// The file as named.
        name: String,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The file is larger than its bound (`chain_core::bounded`).
    TooLarge {
        /// The file as named.
        name: String,
        /// The bound in bytes.
        limit: usize,
    },
    /// A line is not well-formed CSV (bad UTF-8).
    Malformed {
        /// The file as named.
        name: String,
        /// The line (1-based).
        line: u64,
        /// What is wrong.
        message: String,
    },
}

/// Reads every record of a CSV file leniently, the header included: a
/// leading byte-order mark is dropped, lines starting with `#` and blank lines
/// are skipped, fields are trimmed and rows may differ in length (the caller
/// checks them). Each record carries the line it starts on (1-based, after the
/// comments and blank lines before it). `chain compensate` reads its
/// measurements with it.
fn read_records(path: &Path) -> Result<Vec<RawRecord>, RecordsError> {
    let name = path.display().to_string();
    let data = bounded::read_path(path, bounded::COMPENSATE_BYTES).map_err(|e| match e {
        bounded::ReadError::Io(source) => RecordsError::Io {
            name: name.clone(),
            source,
        },
        bounded::ReadError::TooLarge { limit } => RecordsError::TooLarge {
            name: name.clone(),
            limit,
        },
    })?;
    parse_records(&name, &data)
}

/// [`read_records`] over bytes already read; `name` names the source.
fn parse_records(name: &str, data: &[u8]) -> Result<Vec<RawRecord>, RecordsError> {
    let data = data.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(data);
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .from_reader(data);
    let malformed = |e: csv::Error| RecordsError::Malformed {
        name: name.to_string(),
        line: e.position().map_or(1, csv::Position::line),
        message: csv_error_message(&e),
    };
    let mut out = Vec::new();
    for (i, row) in reader.records().enumerate() {
        let row = row.map_err(malformed)?;
        // The header of a file whose reader reports no position is line 1.
        let fallback = if i == 0 { 1 } else { 0 };
        let line = row.position().map_or(fallback, |p| record_line(data, p));
        out.push(RawRecord::new(line, row.iter()));
    }
    Ok(out)
}

/// The line a record starts on (after the comment and blank lines the
/// reader skipped): the values files' rule, `chain_core::values::csv`.
fn record_line(data: &[u8], pos: &csv::Position) -> u64 {
    let (_, line) = chain_core::values::csv::record_start(data, pos);
    u64::try_from(line).unwrap_or(u64::MAX)
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

impl RecordsError {
    /// The error in the library's words (the analysis errors' messages and
    /// codes).
    fn into_error(self) -> CompensateError {
        match self {
            RecordsError::Io { name, source } => CompensateError::Io { file: name, source },
            RecordsError::TooLarge { name, limit } => {
                CompensateError::TooLarge { file: name, limit }
            }
            RecordsError::Malformed {
                name,
                line,
                message,
            } => CompensateError::Malformed {
                file: name,
                line,
                message,
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use crate::compensate::{CompensateError, Measurements};

    /// What the reader makes of the bytes of a file named `name`.
    fn parse(name: &str, data: &[u8]) -> Result<Measurements, CompensateError> {
        super::parse_measurements(name, data)
    }

    #[test]
    fn reader_skips_comments_blank_lines_and_a_byte_order_mark() {
        let m = parse(
            "mem.csv",
            b"# comment\n\nZ3, note, THETA_DEG ,z1\r\n-171.1,\"a, b\",1,-170.99\n\n# again\n-171.4275,b,2,-170.99\n",
        )
        .unwrap();
        assert_eq!(m.header_line, 3);
        assert_eq!(m.records.iter().map(|r| r.line).collect::<Vec<_>>(), [4, 7]);
        assert_eq!(m.records[1].theta_deg, 2.0);
        assert_eq!(m.records[1].z3, -171.4275);
        let m = parse("bom.csv", b"\xEF\xBB\xBFtheta_deg,z1,z3\n1,0,-0.1\n").unwrap();
        assert_eq!((m.header_line, m.records[0].line), (1, 2));
    }

    #[test]
    fn reader_errors_name_the_file_and_line() {
        let e = parse("bad.csv", b"theta_deg,z1,z3\n1,0,\xFF\n").unwrap_err();
        assert!(
            matches!(e, CompensateError::Malformed { line: 2, .. }),
            "{e}"
        );
        assert!(
            e.to_string()
                .starts_with("bad.csv:2: the line is not valid UTF-8"),
            "{e}"
        );
        let e = parse("empty.csv", b"# only a comment\n\n").unwrap_err();
        assert_eq!(
            e.to_string(),
            "empty.csv:1: the file is empty; expected a header line `theta_deg,z1,z3` (optionally with `z2`)"
        );
        let e = parse("short.csv", b"theta_deg,z1,z3\n1,0,-0.1\n2,0\n").unwrap_err();
        assert_eq!(
            e.to_string(),
            "short.csv:3: this row has 2 fields but the header has 3 columns"
        );
        let e = super::read_measurements(Path::new("/nonexistent/swing.csv")).unwrap_err();
        assert!(matches!(e, CompensateError::Io { .. }), "{e}");
        assert!(e
            .to_string()
            .starts_with("/nonexistent/swing.csv: cannot read the file: "));
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(256))]

        /// No byte string makes the reader or the row checks panic.
        #[test]
        fn reader_never_panics(bytes in proptest::collection::vec(proptest::prelude::any::<u8>(), 0..200)) {
            let _ = parse("fuzz.csv", &bytes);
        }
    }
}
