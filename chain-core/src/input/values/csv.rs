//! The CSV tables of a values file (`{table: FILE.csv, column: NAME}`), read
//! with the `csv` crate (feature `csv`).
//!
//! The conventions are the command line's (`chain compensate`'s records): a
//! leading byte-order mark is dropped, lines starting with `#` and blank lines
//! are skipped, fields are trimmed, the first record is the header, and every
//! row has as many fields as the header. Every cell keeps its origin (byte
//! span, line, column, and the header name as its key), so a bad cell is
//! reported as `x_axis.csv:7:9: … at key `EBX``.

use std::path::Path;

use crate::diagnostic::{Diagnostics, Problem};

/// The most refused rows a reader of a CSV file reports
/// ([`CsvFile::read_rows`]).
pub const MAX_ROW_PROBLEMS: usize = 20;
use crate::model::Origin;
use crate::tabular::CsvProblem;

/// CSV tables larger than this are refused.
pub const MAX_TABLE_BYTES: usize = crate::bounded::TABLE_BYTES;

/// One CSV file as located cells: the one place the `csv` crate's records
/// become cells with their origins (values tables, measurement and
/// candidate files, and the command line's pose and axes CSVs).
///
/// The data cells are kept compactly (their texts one after another, and
/// per cell where it is; a cell's [`Origin`] is formed when its row is read
/// through [`CsvFile::rows`]): a million-row file costs about its size
/// again, not a string and an origin per cell.
#[derive(Debug, Clone)]
pub struct CsvFile {
    /// Its text (for the diagnostics' snippets).
    pub text: String,
    /// Header names with their origins.
    pub header: Vec<(String, Origin)>,
    /// The data cells' texts, one after another, row by row.
    cells: String,
    /// Per data cell, row by row (each row as wide as the header).
    spans: Vec<CellSpan>,
    /// Per data row, its 1-based line.
    lines: Vec<usize>,
}

/// Where a data cell of a [`CsvFile`] is.
#[derive(Debug, Clone, Copy)]
struct CellSpan {
    /// The end of its text in [`CsvFile::cells`] (it starts where the
    /// previous cell's ends).
    end: usize,
    /// Its byte offset in the file's text.
    offset: usize,
    /// Its length there (quotes included).
    len: usize,
    /// Its 1-based column in characters.
    column: usize,
}

/// Why a CSV file could not be used at all.
#[derive(Debug)]
pub(crate) enum CsvOpenError {
    /// It cannot be read (missing, too large, a directory): reported in the
    /// values file, at the `table` key.
    Unreadable(String),
    /// Its text is not a CSV table (located in the CSV file).
    Invalid(Diagnostics),
}

/// What a values table's header names (the help of an empty table).
const TABLE_HEADER: &str =
    "the header names the axis variable and the value columns, e.g. `x,EXX,EYX`";

impl CsvFile {
    /// Reads the CSV file at `path`, named `name` in messages.
    pub(crate) fn read(path: &Path, name: &str) -> Result<CsvFile, CsvOpenError> {
        let bytes = crate::load::read_file(path, name, MAX_TABLE_BYTES)
            .map_err(|d| CsvOpenError::Unreadable(d.first().problem.headline()))?;
        let text = crate::load::decode(&bytes, name).map_err(CsvOpenError::Invalid)?;
        CsvFile::parse(text, name).map_err(CsvOpenError::Invalid)
    }

    /// Parses CSV bytes: checked as text first (no NUL byte, valid UTF-8,
    /// the first bad byte located, as every input is), then
    /// [`CsvFile::parse_with`].
    pub fn parse_bytes(
        bytes: &[u8],
        name: &str,
        header_help: &'static str,
    ) -> Result<CsvFile, Diagnostics> {
        let text = crate::load::decode(bytes, name)?;
        CsvFile::parse_with(text, name, header_help)
    }

    /// Parses the CSV text of a values table.
    pub(crate) fn parse(text: &str, name: &str) -> Result<CsvFile, Diagnostics> {
        CsvFile::parse_with(text, name, TABLE_HEADER)
    }

    /// Parses CSV text (header, then at least one data row, every row as
    /// wide as the header; refusals worded by [`CsvProblem`]);
    /// `header_help` says what the header of this kind of
    /// file names (the help of an empty file or an unnamed column).
    pub fn parse_with(text: &str, name: &str, header_help: &str) -> Result<CsvFile, Diagnostics> {
        let bom = if text.starts_with('\u{feff}') { 3 } else { 0 };
        let data = &text.as_bytes()[bom..];
        let mut reader = ::csv::ReaderBuilder::new()
            .has_headers(false)
            .flexible(true)
            .trim(::csv::Trim::All)
            .comment(Some(b'#'))
            .from_reader(data);
        let located = |origin: Origin, problem: CsvProblem| {
            Diagnostics::single(name, text, origin, problem.into())
        };
        let mut header: Vec<(String, Origin)> = Vec::new();
        // The header's names, for the repeated-name check (a hash, not a
        // scan per column: 100,000 columns are checked at once).
        let mut seen: std::collections::HashMap<String, usize> = Default::default();
        let (mut cells, mut cell_spans, mut lines) = (String::new(), Vec::new(), Vec::new());
        for record in reader.records() {
            let record = record.map_err(|e| {
                let line = e.position().map_or(1, ::csv::Position::line);
                let message = match e.kind() {
                    ::csv::ErrorKind::Utf8 { err, .. } => {
                        format!("the line is not valid UTF-8 ({err})")
                    }
                    _ => e.to_string(),
                };
                located(line_origin(text, line), CsvProblem::Malformed { message })
            })?;
            let Some(pos) = record.position() else {
                continue;
            };
            let (start, line) = record_start(data, pos);
            let spans = field_spans(data, start);
            // Each field's 1-based column in characters, counted once along
            // the line (not from the line's start for every field: a line
            // of 100,000 fields is linear, not quadratic).
            let line_start = data[..start]
                .iter()
                .rposition(|&b| b == b'\n')
                .map_or(0, |p| p + 1);
            let mut columns = Vec::with_capacity(spans.len());
            let (mut at, mut column) = (line_start, 1);
            for &(offset, _) in &spans {
                column += String::from_utf8_lossy(&data[at..offset.max(at)])
                    .chars()
                    .count();
                at = offset.max(at);
                columns.push(column);
            }
            let span = |k: usize| -> CellSpan {
                let (offset, len) = spans.get(k).copied().unwrap_or((start, 0));
                let column = columns.get(k).copied().unwrap_or_else(|| {
                    String::from_utf8_lossy(&data[line_start..offset])
                        .chars()
                        .count()
                        + 1
                });
                CellSpan {
                    end: 0,
                    offset,
                    len,
                    column,
                }
            };
            let cell = |k: usize, key: &str| -> Origin {
                let s = span(k);
                Origin {
                    offset: s.offset + bom,
                    len: s.len,
                    line,
                    column: s.column,
                    key: key.to_string(),
                }
            };
            if header.is_empty() {
                for (k, field) in record.iter().enumerate() {
                    let origin = cell(k, field);
                    if field.is_empty() {
                        let empty = CsvProblem::UnnamedColumn {
                            column: k + 1,
                            header: header_help.to_string(),
                        };
                        return Err(located(origin, empty));
                    }
                    if let Some(first) = seen.get(field).map(|&i| &header[i].1) {
                        let twice = CsvProblem::RepeatedColumn {
                            name: field.to_string(),
                            first: first.column,
                        };
                        return Err(located(origin, twice));
                    }
                    seen.insert(field.to_string(), header.len());
                    header.push((field.to_string(), origin));
                }
                continue;
            }
            if record.len() != header.len() {
                let problem = CsvProblem::Ragged {
                    fields: record.len(),
                    columns: header.len(),
                };
                return Err(located(cell(0, ""), problem));
            }
            for (k, field) in record.iter().enumerate() {
                cells.push_str(field);
                cell_spans.push(CellSpan {
                    end: cells.len(),
                    offset: span(k).offset + bom,
                    ..span(k)
                });
            }
            lines.push(line);
        }
        if header.is_empty() {
            let empty = CsvProblem::Empty {
                header: header_help.to_string(),
            };
            return Err(located(line_origin(text, 1), empty));
        }
        if lines.is_empty() {
            let first = &header[0].1;
            let origin = line_origin(text, first.line as u64);
            return Err(located(origin, CsvProblem::NoData));
        }
        Ok(CsvFile {
            text: text.to_string(),
            header,
            cells,
            spans: cell_spans,
            lines,
        })
    }

    /// The number of data rows.
    pub fn len(&self) -> usize {
        self.lines.len()
    }

    /// Whether there is no data row (never, for a parsed file).
    pub fn is_empty(&self) -> bool {
        self.lines.is_empty()
    }

    /// Every data row read by `read`, in order; or the problems of the rows
    /// it refuses, in file order, at most [`MAX_ROW_PROBLEMS`] (a reader
    /// reports the first ones rather than every row of a broken file).
    pub fn read_rows<T>(
        &self,
        mut read: impl FnMut(&[(String, Origin)]) -> Result<T, Box<(Origin, Problem)>>,
    ) -> Result<Vec<T>, Vec<(Origin, Problem)>> {
        let mut rows = Vec::with_capacity(self.len());
        let mut problems = Vec::new();
        for cells in self.rows() {
            match read(&cells) {
                Ok(row) => rows.push(row),
                Err(p) => problems.push(*p),
            }
            if problems.len() >= MAX_ROW_PROBLEMS {
                break;
            }
        }
        if problems.is_empty() {
            Ok(rows)
        } else {
            Err(problems)
        }
    }

    /// The data rows in order, each as its cells' texts and origins (key:
    /// the cell's column name), formed as the row is read.
    pub fn rows(&self) -> impl ExactSizeIterator<Item = Vec<(String, Origin)>> + '_ {
        let width = self.header.len();
        (0..self.lines.len()).map(move |r| {
            let line = self.lines[r];
            (r * width..(r + 1) * width)
                .zip(&self.header)
                .map(|(k, (name, _))| {
                    let s = self.spans[k];
                    let from = if k == 0 { 0 } else { self.spans[k - 1].end };
                    let origin = Origin {
                        offset: s.offset,
                        len: s.len,
                        line,
                        column: s.column,
                        key: name.clone(),
                    };
                    (self.cells[from..s.end].to_string(), origin)
                })
                .collect()
        })
    }

    /// The index of the column named `name`.
    pub(crate) fn column(&self, name: &str) -> Option<usize> {
        self.header.iter().position(|(h, _)| h == name)
    }

    /// The header names.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.header.iter().map(|(h, _)| h.as_str())
    }

    /// The origin of the header line.
    pub(crate) fn header_origin(&self) -> Origin {
        let first = &self.header[0].1;
        let last = &self.header[self.header.len() - 1].1;
        Origin {
            offset: first.offset,
            len: last.offset + last.len - first.offset,
            line: first.line,
            column: first.column,
            key: String::new(),
        }
    }
}

/// The origin of a whole line (1-based) of `text`.
fn line_origin(text: &str, line: u64) -> Origin {
    let line = usize::try_from(line.max(1)).unwrap_or(1);
    let start: usize = text
        .split_inclusive('\n')
        .take(line - 1)
        .map(str::len)
        .sum();
    let len = text[start.min(text.len())..]
        .split('\n')
        .next()
        .map_or(0, |l| l.trim_end_matches('\r').len());
    Origin {
        offset: start.min(text.len()),
        len,
        line,
        column: 1,
        key: String::new(),
    }
}

/// Where a record really starts: the reader reports where it started
/// reading, before any comment or blank lines it skipped. Returns the byte
/// offset and the 1-based line. (Also the CLI's CSV inputs' line numbers.)
pub fn record_start(data: &[u8], pos: &::csv::Position) -> (usize, usize) {
    let mut line = usize::try_from(pos.line()).unwrap_or(usize::MAX);
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
    (i.min(data.len()), line)
}

/// The byte spans of the fields of the record starting at `start`, trimmed
/// of blanks (quotes included in a quoted field's span).
fn field_spans(data: &[u8], start: usize) -> Vec<(usize, usize)> {
    let mut spans = Vec::new();
    let mut field = start;
    let mut quoted = false;
    let mut i = start;
    let trimmed = |a: usize, b: usize| {
        let s = &data[a..b];
        let lead = s.iter().take_while(|c| c.is_ascii_whitespace()).count();
        let tail = s[lead..]
            .iter()
            .rev()
            .take_while(|c| c.is_ascii_whitespace())
            .count();
        (a + lead, s.len() - lead - tail)
    };
    while i < data.len() {
        match data[i] {
            b'"' => quoted = !quoted,
            b',' if !quoted => {
                spans.push(trimmed(field, i));
                field = i + 1;
            }
            b'\n' | b'\r' if !quoted => break,
            _ => {}
        }
        i += 1;
    }
    spans.push(trimmed(field, i));
    spans
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cells_keep_their_line_column_and_column_name() {
        let text = "\u{feff}# measured 2024-05-02\nx, EXX ,EYX\n\n0,1.5,2\n# note\n100,\"3\" ,4\n";
        let f = CsvFile::parse(text, "t.csv").unwrap();
        assert_eq!(f.names().collect::<Vec<_>>(), ["x", "EXX", "EYX"]);
        assert_eq!(f.header[1].1.line, 2);
        assert_eq!(f.header[1].1.column, 4);
        assert_eq!(f.len(), 2);
        let rows: Vec<_> = f.rows().collect();
        let (text0, o) = &rows[1][1];
        assert_eq!(text0, "3");
        assert_eq!((o.line, o.column, o.key.as_str()), (6, 5, "EXX"));
        assert_eq!(&text[o.offset..o.offset + o.len], "\"3\"");
        let (_, o) = &rows[0][2];
        assert_eq!((o.line, o.column), (4, 7));
    }

    /// 100,000 columns: the repeated-name check and the cells' columns are
    /// linear in the width (they were quadratic: 22 s for this header).
    #[test]
    fn a_hundred_thousand_columns_are_read_with_their_columns() {
        let n = 100_000;
        let names: Vec<String> = (0..n).map(|k| format!("c{k}")).collect();
        let cells: Vec<String> = (0..n).map(|k| format!("{}", k % 10)).collect();
        let text = format!("{}\n{}\n", names.join(","), cells.join(", "));
        let f = CsvFile::parse(&text, "wide.csv").unwrap();
        let row = f.rows().next().unwrap();
        assert_eq!(row.len(), n);
        // Cell k starts after k cells of one digit, each followed by ", ".
        for k in [0, 1, 99_999] {
            let (cell, o) = &row[k];
            assert_eq!(cell, &format!("{}", k % 10));
            assert_eq!((o.column, o.key.as_str()), (1 + 3 * k, names[k].as_str()));
            assert_eq!(&text[o.offset..o.offset + o.len], cell);
        }
        let twice = format!("{},c7\n{}\n", names.join(","), vec!["1"; n + 1].join(","));
        let err = CsvFile::parse(&twice, "wide.csv").unwrap_err();
        let headline = err.first().problem.headline();
        assert!(headline.contains("`c7` appears twice"), "{headline}");
        // `c0,c1,…,` : `c7` starts at character 1 + 3·7.
        assert!(headline.contains("first in column 22"), "{headline}");
    }

    #[test]
    fn refusals_name_the_line() {
        let twice = CsvFile::parse("x,a,a\n1,2,3\n", "t.csv").unwrap_err();
        assert_eq!(twice.first().origin.line, 1);
        assert_eq!(twice.first().origin.column, 5);
        assert!(twice.to_string().contains("appears twice"), "{twice}");
        let short = CsvFile::parse("x,a\n1,2\n3\n", "t.csv").unwrap_err();
        assert_eq!(short.first().origin.line, 3);
        assert!(short.to_string().contains("has 1 field but"), "{short}");
        let empty = CsvFile::parse("# only a comment\n", "t.csv").unwrap_err();
        assert!(empty.to_string().contains("empty"), "{empty}");
    }
}
