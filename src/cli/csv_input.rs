//! CSV input shared by the commands that read tables of numbers (`chain
//! inverse`, `chain path`: a file or stdin (`-`), a header, and rows of finite
//! numbers; `chain compensate`: every record with its line, for the library
//! to check); every error names the file, the line and the column.

use std::path::Path;

use chain::ops::inverse::{PoseRow, AXIS_COLUMNS, ROTATION_COLUMNS};
use chain::ops::resolve::AxesColumns;
use chain_core::bounded;
use chain_core::tabular::{self, CsvProblem};
use chain_core::values::csv::CsvFile;

/// The bytes of an input file (`-`: stdin) and its display name, at most
/// `limit` of them (`chain_core::bounded`): a larger input is refused with
/// its name and the limit.
pub(crate) fn read_input(path: &Path, limit: usize) -> miette::Result<(String, Vec<u8>)> {
    let (name, read) = if path.as_os_str() == "-" {
        (
            "<stdin>".to_string(),
            bounded::read_from(std::io::stdin().lock(), limit),
        )
    } else {
        (path.display().to_string(), bounded::read_path(path, limit))
    };
    match read {
        Ok(bytes) => Ok((name, bytes)),
        Err(e @ bounded::ReadError::TooLarge { .. }) => {
            Err(miette::miette!(code = "chain::too_large", "{name}: {e}"))
        }
        Err(e) => Err(miette::miette!(
            code = "chain::io",
            "cannot read {name}: {e}"
        )),
    }
}

/// An open CSV: display name, its located cells and trimmed header.
pub(crate) struct CsvInput {
    pub(crate) name: String,
    pub(crate) table: CsvFile,
    pub(crate) header: Vec<String>,
}

/// A refusal located at `name:line` in the shared wording, with its code.
fn refusal(name: &str, line: usize, problem: &CsvProblem) -> miette::Report {
    miette::MietteDiagnostic::new(problem.at(name, line as u64))
        .with_code(problem.code())
        .into()
}

/// Opens a CSV file (`-`: stdin; at most [`bounded::PATH_BYTES`]) and reads
/// its header and rows through the one CSV reader
/// (`chain_core::values::csv::CsvFile`): a leading byte-order mark is
/// dropped, `#` lines and blank lines skipped; text that is not UTF-8 or
/// holds a NUL byte, a header-only file and a ragged row refused as
/// `file:line: …`.
pub(crate) fn open_csv(path: &Path) -> miette::Result<CsvInput> {
    let (name, bytes) = read_input(path, bounded::PATH_BYTES)?;
    let table = CsvFile::parse_bytes(
        &bytes,
        &name,
        "the header names the columns, e.g. `t,x,y,z`",
    )
    .map_err(|d| {
        let first = d.first();
        miette::Report::from(
            miette::MietteDiagnostic::new(format!(
                "{name}:{}: {}",
                first.origin.line,
                first.problem.headline()
            ))
            .with_code(first.problem.code()),
        )
    })?;
    drop(bytes);
    let header = table.header.iter().map(|(h, _)| h.clone()).collect();
    Ok(CsvInput {
        name,
        table,
        header,
    })
}

/// Reads every data row as finite numbers: `(line, values)`. Errors are
/// `file:line: column `name`: …` ([`CsvProblem`]).
pub(crate) fn numeric_rows(input: &mut CsvInput) -> miette::Result<Vec<(usize, Vec<f64>)>> {
    let name = &input.name;
    input
        .table
        .rows()
        .map(|row| {
            let line = row.first().map_or(0, |(_, o)| o.line);
            let values = row
                .iter()
                .map(|(text, origin)| {
                    tabular::number(text, &origin.key).map_err(|p| refusal(name, line, &p))
                })
                .collect::<miette::Result<Vec<f64>>>()?;
            Ok((line, values))
        })
        .collect()
}

/// Reads a pose CSV: header `px,py,pz,i,j,k` (tool point and tool axis) or
/// `px,py,pz,r11,…,r33` (tool point and the tool frame's rotation,
/// row-major; refused unless orthonormal to 1e-6 with det +1, then replaced
/// by the nearest rotation), optionally after a first column `t`. Returns whether `t` was
/// given, and the rows.
pub(crate) fn read_poses(path: &Path) -> miette::Result<(bool, Vec<PoseRow>)> {
    let mut input = open_csv(path)?;
    let name = input.name.clone();
    let has_t = input.header.first().is_some_and(|h| h == "t");
    let skip = usize::from(has_t);
    let columns = &input.header[skip..];
    if columns != AXIS_COLUMNS && columns != ROTATION_COLUMNS {
        miette::bail!(
            "{name}:1: expected the header `px,py,pz,i,j,k` or `px,py,pz,r11,r12,r13,r21,r22,r23,r31,r32,r33` (optionally after a first column `t`), found `{}`",
            input.header.join(",")
        );
    }
    let rows = numeric_rows(&mut input)?;
    rows.into_iter()
        .map(|(line, all)| {
            PoseRow::from_values(has_t.then_some(all[0]), &all[skip..])
                .map_err(|e| miette::miette!("{name}:{line}: {e}"))
        })
        .collect::<miette::Result<Vec<_>>>()
        .map(|rows| (has_t, rows))
}

/// The points of `--axes`: every row, in the machine's variable order
/// ([`AxesColumns`]: every variable has a column).
pub(crate) fn axes_points(
    path: &std::path::Path,
    m: &chain_core::Machine,
) -> miette::Result<Vec<f64>> {
    let mut input = open_csv(path)?;
    let columns = AxesColumns::resolve(m, &input.name, &input.header, None)?;
    let rows = numeric_rows(&mut input)?;
    let mut points = Vec::with_capacity(rows.len() * m.variables.len());
    for (_, values) in rows {
        points.extend(columns.point(&values));
    }
    Ok(points)
}
