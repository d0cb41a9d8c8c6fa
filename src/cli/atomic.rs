//! Atomic file writes: every file the binary writes (plots, `--table-out`,
//! `--values-out`, export files) is written to a temporary file in the
//! destination's directory and renamed into place (`tempfile`'s
//! `NamedTempFile::persist`), so a failure or an interrupt leaves the old
//! file or none, never a truncated one that looks complete.

use std::io::Write;
use std::path::Path;

/// A temporary file beside `path`, with `path`'s extension (the plot
/// backends choose the image format by it) and the permissions a newly
/// created file gets (0666 less the umask), not `tempfile`'s 0600.
fn beside(path: &Path) -> std::io::Result<tempfile::NamedTempFile> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let suffix = path
        .extension()
        .map(|e| format!(".{}", e.to_string_lossy()))
        .unwrap_or_default();
    let mut builder = tempfile::Builder::new();
    builder.prefix(".chain-").suffix(&suffix);
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    builder.tempfile_in(dir)
}

/// Writes `bytes` to `path` atomically.
pub(crate) fn write(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    write_with(path, |file| file.write_all(bytes))
}

/// Writes `path` atomically through `fill`, which writes the open temporary
/// file.
pub(crate) fn write_with(
    path: &Path,
    fill: impl FnOnce(&mut std::fs::File) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let mut tmp = beside(path)?;
    fill(tmp.as_file_mut())?;
    tmp.as_file().sync_all()?;
    tmp.persist(path).map_err(|e| e.error)?;
    Ok(())
}

/// Writes `path` atomically through `draw`, which writes the file at the
/// temporary path it is given (a plot backend opening the path itself); a
/// drawing error is returned as is, the temporary file removed.
pub(crate) fn write_via<E>(
    path: &Path,
    draw: impl FnOnce(&Path) -> Result<(), E>,
    io: impl Fn(std::io::Error) -> E,
) -> Result<(), E> {
    let tmp = beside(path).map_err(&io)?;
    draw(tmp.path())?;
    tmp.persist(path).map_err(|e| io(e.error))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_failed_write_leaves_no_file_and_a_good_one_is_whole() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("out.csv");
        write(&target, b"a,b\n1,2\n").unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"a,b\n1,2\n");
        // A fill that fails half-way: the old content stays, no temporary.
        let e = write_with(&target, |f| {
            f.write_all(b"partial")?;
            Err(std::io::Error::other("interrupted"))
        })
        .unwrap_err();
        assert_eq!(e.to_string(), "interrupted");
        assert_eq!(std::fs::read(&target).unwrap(), b"a,b\n1,2\n");
        // A directory in the way: refused, nothing left beside it.
        let blocked = dir.path().join("blocked.csv");
        std::fs::create_dir(&blocked).unwrap();
        assert!(write(&blocked, b"x").is_err());
        let names: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        assert_eq!(names.len(), 2, "{names:?}");
    }
}
