//! `--plot DIR`: the charts [`chain::plot`] computes from a command's
//! document, written into the directory given, each file atomically
//! (`cli/atomic.rs`), the notes on charts left out shown on stderr.

use std::path::{Path, PathBuf};

use chain::plot::{Figures, Files, PlotError};

/// Writes each file to a temporary file beside it and renames it into place.
struct Atomic;

impl Files for Atomic {
    fn write(
        &self,
        path: &Path,
        fill: &mut dyn FnMut(&Path) -> Result<(), PlotError>,
    ) -> Result<(), PlotError> {
        crate::cli::atomic::write_via(path, fill, |source| PlotError::Write {
            path: path.display().to_string(),
            source,
        })
    }
}

/// Shows the notes of `figures` and writes their charts into `dir` (PNG
/// and SVG of each); returns the files written.
pub(crate) fn write(dir: &Path, figures: &Figures) -> Result<Vec<PathBuf>, PlotError> {
    for note in &figures.notes {
        eprintln!("{note}");
    }
    figures.write(dir, &Atomic)
}
