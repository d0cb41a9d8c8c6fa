//! Reading the measurement CSV of `chain compensate` (feature `records`):
//! the records of a file or of its bytes through the reader every CSV input
//! shares (`chain_core::values::csv::CsvFile`), with the lines they start
//! on; [`crate::compensate::Measurements::from_records`] types and checks
//! them. The CLI and Python read through it.

use std::path::Path;

use chain_core::bounded;

use chain_core::values::csv::CsvFile;

use super::error::TableRefusal;
use super::{CompensateError, Measurements, RawRecord};

/// What the header of a swing-angle file names (the help of an empty file
/// or an unnamed column).
const HEADER_HELP: &str = "the header names the columns `theta_deg,z1,z3` (optionally `z2`)";

/// The measurements of the CSV file at `path`.
pub fn read_measurements(path: &Path) -> Result<Measurements, CompensateError> {
    let name = path.display().to_string();
    let data = bounded::read_path(path, bounded::COMPENSATE_BYTES).map_err(|e| match e {
        bounded::ReadError::Io(source) => CompensateError::Io {
            file: name.clone(),
            source,
        },
        bounded::ReadError::TooLarge { limit } => CompensateError::TooLarge {
            file: name.clone(),
            limit,
        },
    })?;
    parse_measurements(&name, &data)
}

/// The measurements of CSV bytes named `name`: read by the reader every CSV
/// input shares (`CsvFile`: a leading byte-order mark dropped, `#` comment
/// and blank lines skipped, cells trimmed, every row as wide as the header,
/// every refusal at its line), then typed and checked by
/// [`Measurements::from_records`].
pub fn parse_measurements(name: &str, data: &[u8]) -> Result<Measurements, CompensateError> {
    let csv = CsvFile::parse_bytes(data, name, HEADER_HELP).map_err(|d| {
        let refusal = TableRefusal::of(name, &d);
        match refusal.code {
            // The swing-angle files' own words for these two.
            "chain::csv::empty" => CompensateError::Empty {
                file: name.to_string(),
            },
            "chain::csv::no_data" => CompensateError::NoData {
                file: name.to_string(),
                header_line: refusal.line as u64,
            },
            _ => CompensateError::Table(refusal),
        }
    })?;
    let header = RawRecord::new(
        csv.header.first().map_or(1, |(_, o)| o.line as u64),
        csv.names(),
    );
    let rows = csv.rows().map(|cells| {
        let line = cells.first().map_or(0, |(_, o)| o.line as u64);
        RawRecord::new(line, cells.into_iter().map(|(text, _)| text))
    });
    Measurements::from_records(name, std::iter::once(header).chain(rows))
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
        // The shared reader's words and codes (`CsvFile`).
        let e = parse("bad.csv", b"theta_deg,z1,z3\n1,0,\xFF\n").unwrap_err();
        assert!(
            matches!(&e, CompensateError::Table(t) if t.line == 2 && t.code == "chain::invalid_utf8"),
            "{e:?}"
        );
        assert_eq!(
            e.to_string(),
            "bad.csv:2: the file is not valid UTF-8 (invalid byte at byte offset 20)"
        );
        let e = parse("twice.csv", b"theta_deg,z1,z3,z1\n1,0,-0.1,0\n").unwrap_err();
        assert_eq!(
            e.to_string(),
            "twice.csv:1: column `z1` appears twice in the header (first in column 11)",
            "{e:?}"
        );
        // Names differing in case only: the swing-angle columns' own check.
        let e = parse("case.csv", b"theta_deg,z1,z3,Z1\n1,0,-0.1,0\n").unwrap_err();
        assert_eq!(
            e.to_string(),
            "case.csv:1: column `z1` appears twice in the header"
        );
        let e = parse("header.csv", b"theta_deg,z1,z3\n").unwrap_err();
        assert!(
            matches!(e, CompensateError::NoData { header_line: 1, .. }),
            "{e:?}"
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
        assert!(
            matches!(&e, CompensateError::Table(t) if t.code == "chain::csv::ragged"),
            "{e:?}"
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
