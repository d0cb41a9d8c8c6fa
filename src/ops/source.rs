//! A file a command reads, given as a path or as bytes the caller read (the
//! CLI's stdin, a Python string), and the one reader of each kind of input
//! file: measurements and candidates (`identify`, `plan`), values files
//! (`map`, `export`), motion settings (`motion`), positioning runs
//! (`positioning`), drift tests (`thermal`) and swing-angle measurements
//! (`compensate`); the numeric
//! tables are [`super::tables`]'. A path is read with its kind's bound and
//! relative paths inside the file (a values file's tables, a settings
//! file's machines) are resolved against its directory; bytes are named by
//! the caller and their relative paths resolved against the working
//! directory. Either way the file is checked as text (no NUL byte, valid
//! UTF-8) and refused in its reader's words.

use std::path::Path;

use chain_core::measured::circular::{CircularFileError, CircularTest};
use chain_core::measured::positioning::{AxisKind, Runs, RunsFileError};
use chain_core::measured::thermal::{DriftFileError, DriftTest, Roles};
use chain_core::measured::{Layout, Measurements, MeasurementsError};
use chain_core::settings::{self, Settings, SettingsError};
use chain_core::values::{Values, ValuesError};
use chain_core::Machine;

use crate::compensate::{self, CompensateError};

/// Where a file comes from.
#[derive(Debug, Clone, Copy)]
pub enum Source<'a> {
    /// A file, read up to its kind's bound.
    Path(&'a Path),
    /// Bytes the caller read, named `name` in messages.
    Bytes {
        /// The name messages give the file (`<stdin>`, a Python caller's).
        name: &'a str,
        /// The file's bytes.
        bytes: &'a [u8],
    },
}

/// A [`Source`] given as both a path and a text, or as neither.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{name}: give a path or the text, one of them")]
pub struct SourceError {
    /// The name the input was given.
    pub name: String,
}

impl<'a> Source<'a> {
    /// A file given as a `path` or as its `text` (named `name`), exactly
    /// one of them: the way Python passes every file.
    pub fn given(
        path: Option<&'a str>,
        text: Option<&'a str>,
        name: &'a str,
    ) -> Result<Source<'a>, SourceError> {
        match (path, text) {
            (Some(path), None) => Ok(Source::Path(Path::new(path))),
            (None, Some(text)) => Ok(Source::Bytes {
                name,
                bytes: text.as_bytes(),
            }),
            _ => Err(SourceError {
                name: name.to_string(),
            }),
        }
    }

    /// The name messages give the file: the path as given, or the caller's.
    pub fn name(&self) -> String {
        match self {
            Source::Path(path) => path.display().to_string(),
            Source::Bytes { name, .. } => name.to_string(),
        }
    }
}

/// A measurement or candidate CSV for `machine` (`params`: `--param`, for
/// the parameters without a column).
pub fn read_measurements(
    source: Source<'_>,
    machine: &Machine,
    params: &[(String, f64)],
    layout: Layout,
) -> Result<Measurements, MeasurementsError> {
    match source {
        Source::Path(path) => Measurements::read(path, machine, params, layout),
        Source::Bytes { name, bytes } => {
            Measurements::from_bytes(bytes, name, machine, params, layout)
        }
    }
}

/// A sphere-probing CSV for `machine` (five-axis spec).
pub fn read_spheres(
    source: Source<'_>,
    machine: &Machine,
    params: &[(String, f64)],
) -> Result<Measurements, MeasurementsError> {
    match source {
        Source::Path(path) => Measurements::read_spheres(path, machine, params),
        Source::Bytes { name, bytes } => {
            Measurements::spheres_from_bytes(bytes, name, machine, params)
        }
    }
}

/// A values file for `machine`.
pub fn read_values(source: Source<'_>, machine: &Machine) -> Result<Values, ValuesError> {
    match source {
        Source::Path(path) => Values::read(path, machine),
        Source::Bytes { name, bytes } => {
            let text = chain_core::load::decode(bytes, name)?;
            Values::parse(text, name, Path::new("."), machine)
        }
    }
}

/// The settings of `chain motion`.
pub fn read_settings(source: Source<'_>) -> Result<Settings, SettingsError> {
    match source {
        Source::Path(path) => settings::load_settings_file(path),
        Source::Bytes { name, bytes } => {
            let text = chain_core::load::decode(bytes, name)?;
            settings::load_settings_str(text, name, Path::new("."))
        }
    }
}

/// The positioning runs of one axis of kind `kind`.
pub fn read_runs(source: Source<'_>, kind: AxisKind) -> Result<Runs, RunsFileError> {
    match source {
        Source::Path(path) => Runs::read(path, kind),
        Source::Bytes { name, bytes } => {
            let text = chain_core::load::decode(bytes, name).map_err(RunsFileError)?;
            Runs::parse(text, name, kind)
        }
    }
}

/// The drift test of `chain thermal`, its columns' roles as given.
pub fn read_drift(source: Source<'_>, roles: &Roles) -> Result<DriftTest, DriftFileError> {
    match source {
        Source::Path(path) => DriftTest::read(path, roles),
        Source::Bytes { name, bytes } => {
            let text = chain_core::load::decode(bytes, name).map_err(DriftFileError)?;
            DriftTest::parse(text, name, roles)
        }
    }
}

/// The run file of `chain circular`, read with `options`.
pub fn read_circular(
    source: Source<'_>,
    options: &chain_core::measured::circular::RunOptions,
) -> Result<CircularTest, CircularFileError> {
    match source {
        Source::Path(path) => CircularTest::read(path, options),
        Source::Bytes { name, bytes } => {
            let text = chain_core::load::decode(bytes, name).map_err(CircularFileError)?;
            CircularTest::parse(text, name, options)
        }
    }
}

/// A circular-test file as identification records of `machine`
/// ([`Measurements::read_circular`]).
pub fn read_circular_records(
    source: Source<'_>,
    machine: &Machine,
    overrides: &[(String, f64)],
    options: &chain_core::measured::circular::RunOptions,
    pose: chain_core::measured::circular::records::CirclePose<'_>,
) -> Result<Measurements, MeasurementsError> {
    match source {
        Source::Path(path) => Measurements::read_circular(path, machine, overrides, options, pose),
        Source::Bytes { name, bytes } => {
            Measurements::circular_from_bytes(bytes, name, machine, overrides, options, pose)
        }
    }
}

/// The swing-angle measurements of `chain compensate`.
pub fn read_swing(source: Source<'_>) -> Result<compensate::Measurements, CompensateError> {
    match source {
        Source::Path(path) => compensate::records::read_measurements(path),
        Source::Bytes { name, bytes } => compensate::records::parse_measurements(name, bytes),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_is_a_path_or_a_text() {
        assert!(matches!(
            Source::given(Some("a.csv"), None, "x"),
            Ok(Source::Path(p)) if p == Path::new("a.csv")
        ));
        let text = Source::given(None, Some("x\n1\n"), "<runs>").unwrap();
        assert_eq!(text.name(), "<runs>");
        assert_eq!(
            Source::given(Some("a.csv"), Some("x"), "<runs>")
                .unwrap_err()
                .to_string(),
            "<runs>: give a path or the text, one of them"
        );
        assert!(Source::given(None, None, "<runs>").is_err());
    }
}
