//! The CLI's file inputs: bounded bytes of a file or stdin (`-`), and the
//! numeric tables of `chain inverse`, `chain path`, `chain map` and `chain
//! export` read through [`chain::ops::tables`] (stdin read here); every
//! error names the file, the line and the column.

use std::path::Path;

use chain::ops::inverse::PoseRow;
use chain::ops::source::Source;
use chain::ops::tables::{self, NumericTable, TableError};
use chain_core::bounded;

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
        Err(e) => Err(TableError::of_read(&name, e).into()),
    }
}

/// Runs `read` on the table at `path` (`-`: stdin, read here up to
/// [`bounded::PATH_BYTES`]): the CLI's way into [`chain::ops::tables`].
pub(crate) fn with_table<T>(
    path: &Path,
    read: impl FnOnce(Source<'_>) -> Result<T, TableError>,
) -> miette::Result<T> {
    if path.as_os_str() != "-" {
        return Ok(read(Source::Path(path))?);
    }
    let name = "<stdin>";
    let bytes = bounded::read_from(std::io::stdin().lock(), bounded::PATH_BYTES)
        .map_err(|e| TableError::of_read(name, e))?;
    Ok(read(Source::Bytes {
        name,
        bytes: &bytes,
    })?)
}

/// The numbers of the table at `path` (`-`: stdin; [`tables::read_numbers`]).
pub(crate) fn numeric_table(path: &Path) -> miette::Result<NumericTable> {
    with_table(path, tables::read_numbers)
}

/// The poses of `path` (`-`: stdin; [`tables::read_poses`]).
pub(crate) fn read_poses(path: &Path) -> miette::Result<(bool, Vec<PoseRow>)> {
    with_table(path, tables::read_poses)
}

/// The points of `--axes` (`-`: stdin; [`tables::axes_points`]).
pub(crate) fn axes_points(path: &Path, m: &chain_core::Machine) -> miette::Result<Vec<f64>> {
    with_table(path, |source| tables::axes_points(source, m))
}
