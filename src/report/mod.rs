//! `chain report`: one self-contained HTML page a lab hands over
//! (`docs/report.md`). A calibration file ([`Calibration`]) names what was
//! measured and computed for one machine; [`run`] runs each command through
//! [`crate::ops`] as the CLI would (positioning per axis, the map of the
//! values before and after the controller's compensation, the
//! identification with its held-out prediction, the export, a circular
//! test, a thermal drift test) into one typed, serialisable [`Report`]; [`html`] renders it (the
//! one place the page is written), its charts the commands' own `--plot`
//! charts as inline SVG.

pub mod calibration;
mod html;

use std::path::Path;

use serde::Serialize;

use chain_core::diagnostic::Diagnostics;
use chain_core::measured::circular::diagnosis::DiagnosisOptions;
use chain_core::measured::positioning::{AxisStats, PositioningDocument, Runs, RunsFileError};
use chain_core::values::ValuesError;

use crate::ops::circular::{Circular, CircularOpsError};
use crate::ops::export::{ExportDocument, ExportOpsError, ExportRequest};
use crate::ops::identify::{IdentifyOpsError, IdentifyRequest, IdentifyRun};
use crate::ops::map::{CompensationRequest, MapDocument, MapOpsError, MapRequest};
use crate::ops::positioning::{PositioningError, PositioningRequest};
use crate::ops::resolve::AxisPoints;
use crate::ops::source::{self, Source};
use crate::ops::thermal::{Thermal, ThermalOpsError, ThermalRequest};
use crate::plot::{Figures, PlotError};
use chain_core::measured::thermal::{DriftFileError, Roles};
use chain_core::measured::thermal_fit::{FitOptions, Split, DEFAULT_SENSORS};

pub use calibration::{Calibration, CalibrationError, Cover};
pub use html::html;

/// A file the report was made from, or one it lists as written.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FileSum {
    /// What it is (the calibration file's key, or the file's name).
    pub role: String,
    /// Its path as the calibration file gives it (or its name).
    pub path: String,
    /// Its size in bytes.
    pub bytes: usize,
    /// Its SHA-256, lower-case hexadecimal.
    pub sha256: String,
}

impl FileSum {
    fn of(role: &str, path: &str, bytes: &[u8]) -> FileSum {
        use sha2::{Digest, Sha256};
        FileSum {
            role: role.to_string(),
            path: path.to_string(),
            bytes: bytes.len(),
            sha256: format!("{:x}", Sha256::digest(bytes)),
        }
    }
}

/// One ISO 230-2 figure against its tolerance.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Verdict {
    /// `A`, `E`, `R`, `M`, `B`, …
    pub figure: String,
    /// The axis's value (the deviations' unit).
    pub value: f64,
    /// The tolerance.
    pub tolerance: f64,
    /// `|value| ≤ tolerance`.
    pub pass: bool,
}

/// One axis's positioning section.
#[derive(Debug, Clone, Serialize)]
pub struct AxisSection {
    /// The axis.
    pub axis: String,
    /// `chain positioning`'s document.
    pub document: PositioningDocument,
    /// The figures with a tolerance, in the calibration file's order.
    pub verdicts: Vec<Verdict>,
    /// Its charts (SVG).
    #[serde(skip)]
    pub charts: Vec<String>,
}

/// The export's section: its document and the files it writes.
#[derive(Debug, Clone, Serialize)]
pub struct ExportSection {
    /// The controller.
    pub controller: &'static str,
    /// `chain export`'s document.
    pub document: ExportDocument,
    /// The files written for the controller, with their checksums.
    pub files: Vec<FileSum>,
}

/// A section with its document and charts.
#[derive(Debug, Clone, Serialize)]
pub struct Charted<T> {
    /// The command's document.
    pub document: T,
    /// Its charts (SVG).
    #[serde(skip)]
    pub charts: Vec<String>,
}

/// Everything the report shows.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    /// The calibration file.
    pub file: String,
    /// The cover's free text.
    pub cover: Cover,
    /// The version of chain that made it.
    pub chain_version: &'static str,
    /// The machine's name.
    pub machine: String,
    /// The calibration file and every input, with checksums.
    pub inputs: Vec<FileSum>,
    /// Per axis, its positioning runs.
    pub positioning: Vec<AxisSection>,
    /// The map of the values before (and, with an export, after) the
    /// controller's compensation.
    pub map: Option<Charted<MapDocument>>,
    /// The identification.
    pub identify: Option<IdentifyRun>,
    /// The export.
    pub export: Option<ExportSection>,
    /// The circular test.
    pub circular: Option<Charted<Circular>>,
    /// The thermal drift test.
    pub thermal: Option<Charted<Thermal>>,
}

/// Why the report could not be made: the calibration file's problem, or
/// the command's whose input it names.
#[derive(Debug, thiserror::Error)]
#[cfg_attr(feature = "cli", derive(miette::Diagnostic))]
pub enum ReportError {
    /// The calibration file.
    #[error(transparent)]
    #[cfg_attr(feature = "cli", diagnostic(transparent))]
    Calibration(#[from] CalibrationError),
    /// The machine file, or an input file read.
    #[error(transparent)]
    #[cfg_attr(feature = "cli", diagnostic(transparent))]
    File(#[from] Diagnostics),
    /// A positioning run file.
    #[error(transparent)]
    #[cfg_attr(feature = "cli", diagnostic(transparent))]
    Runs(#[from] RunsFileError),
    /// A positioning evaluation.
    #[error(transparent)]
    #[cfg_attr(feature = "cli", diagnostic(transparent))]
    Positioning(Box<PositioningError>),
    /// The values file.
    #[error(transparent)]
    #[cfg_attr(feature = "cli", diagnostic(transparent))]
    Values(#[from] ValuesError),
    /// The map.
    #[error(transparent)]
    #[cfg_attr(feature = "cli", diagnostic(transparent))]
    Map(Box<MapOpsError>),
    /// The export.
    #[error(transparent)]
    #[cfg_attr(feature = "cli", diagnostic(transparent))]
    Export(Box<ExportOpsError>),
    /// The identification.
    #[error(transparent)]
    #[cfg_attr(feature = "cli", diagnostic(transparent))]
    Identify(Box<IdentifyOpsError>),
    /// The circular test's options.
    #[error(transparent)]
    #[cfg_attr(feature = "cli", diagnostic(transparent))]
    Circular(#[from] CircularOpsError),
    /// The circular test's file.
    #[error(transparent)]
    #[cfg_attr(feature = "cli", diagnostic(transparent))]
    CircularFile(#[from] chain_core::measured::circular::CircularFileError),
    /// The thermal drift test's file.
    #[error(transparent)]
    #[cfg_attr(feature = "cli", diagnostic(transparent))]
    DriftFile(#[from] DriftFileError),
    /// The thermal drift test's evaluation or fit.
    #[error(transparent)]
    #[cfg_attr(feature = "cli", diagnostic(transparent))]
    Thermal(Box<ThermalOpsError>),
    /// A chart.
    #[error(transparent)]
    #[cfg_attr(feature = "cli", diagnostic(transparent))]
    Plot(#[from] PlotError),
    /// An input read for its checksum.
    #[error("{path}: cannot read it for its checksum: {message}")]
    Checksum {
        /// The file.
        path: String,
        /// Why.
        message: String,
    },
}

impl From<MapOpsError> for ReportError {
    fn from(e: MapOpsError) -> ReportError {
        ReportError::Map(Box::new(e))
    }
}

impl From<ExportOpsError> for ReportError {
    fn from(e: ExportOpsError) -> ReportError {
        ReportError::Export(Box::new(e))
    }
}

impl From<IdentifyOpsError> for ReportError {
    fn from(e: IdentifyOpsError) -> ReportError {
        ReportError::Identify(Box::new(e))
    }
}

impl From<PositioningError> for ReportError {
    fn from(e: PositioningError) -> ReportError {
        ReportError::Positioning(Box::new(e))
    }
}

impl From<ThermalOpsError> for ReportError {
    fn from(e: ThermalOpsError) -> ReportError {
        ReportError::Thermal(Box::new(e))
    }
}

/// The charts of `figures` as SVG text.
fn svgs(figures: &Figures) -> Result<Vec<String>, PlotError> {
    figures.figures.iter().map(|f| f.chart.svg()).collect()
}

/// The checksum of a file read.
fn sum(role: &str, path: &Path) -> Result<FileSum, ReportError> {
    let name = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| ReportError::Checksum {
        path: name.clone(),
        message: e.to_string(),
    })?;
    Ok(FileSum::of(role, &name, &bytes))
}

/// Runs every command the calibration file names, through [`crate::ops`].
pub fn run(cal: &Calibration, calibration_file: &Path) -> Result<Report, ReportError> {
    let machine = chain_core::load_file(&cal.machine)?;
    let m = &machine;
    let machine_file = cal.machine.display().to_string();
    let mut inputs = vec![sum("calibration", calibration_file)?];
    for (role, path) in &cal.inputs {
        inputs.push(sum(role, path)?);
    }

    let mut positioning = Vec::new();
    for axis in &cal.positioning {
        let kind = crate::ops::positioning::axis_kind(axis.rotary);
        let runs = Runs::read(&axis.runs, kind)?;
        let done = crate::ops::positioning::run(&PositioningRequest {
            runs: &runs,
            k: axis.k,
            values_out: None,
            temperatures: axis.temperature,
        })?;
        let document = done.document;
        let verdicts = (axis.tolerances.iter())
            .filter_map(|(figure, tolerance)| {
                let value = figure_value(&document, figure)?;
                Some(Verdict {
                    figure: figure.clone(),
                    value,
                    tolerance: *tolerance,
                    pass: value.abs() <= *tolerance,
                })
            })
            .collect();
        let charts = svgs(&crate::plot::positioning::charts(&document))?;
        positioning.push(AxisSection {
            axis: axis.axis.clone(),
            document,
            verdicts,
            charts,
        });
    }

    let (mut map, mut export) = (None, None);
    if let Some(values_path) = &cal.values {
        let values_file = values_path.display().to_string();
        let values = source::read_values(Source::Path(values_path), m)?;
        let request = MapRequest {
            params: &cal.params,
            approach: &[],
            points: AxisPoints::Grid(&[]),
            compensated: cal.export.map(|controller| CompensationRequest {
                controller,
                grid: &[],
                step: None,
                angles: false,
            }),
            keep_points: true,
            temperatures: &[],
        };
        let prepared =
            crate::ops::map::prepare(m, &machine_file, values.clone(), &values_file, &request)?;
        let document = prepared.run(m, &request, &|_| {})?;
        let charts = svgs(&crate::plot::map::charts(&document, &prepared.built))?;
        map = Some(Charted { document, charts });
        if let Some(controller) = cal.export {
            let document = crate::ops::export::run(
                m,
                &machine_file,
                values,
                &values_file,
                &ExportRequest {
                    controller,
                    params: &cal.params,
                    points: AxisPoints::Grid(&[]),
                    step: None,
                    cec_max_points: None,
                    beckhoff_max_records: None,
                    angles: false,
                    temperatures: &[],
                },
            )?;
            let files = (document.files().iter())
                .map(|f| FileSum::of(&f.name, &f.name, f.text.as_bytes()))
                .collect();
            export = Some(ExportSection {
                controller: controller.name(),
                document,
                files,
            });
        }
    }

    let identify = match &cal.identify {
        Some(part) => {
            // The calibration's parameters are its machine's; another model
            // takes its own from the measurements' columns.
            let params: &[(String, f64)] = match part.machine {
                Some(_) => &[],
                None => &cal.params,
            };
            let request = IdentifyRequest {
                measurements: Some(Source::Path(&part.measurements)),
                spheres: None,
                setup: None,
                validate: part.validate.as_deref().map(Source::Path),
                params,
                prior: false,
                rank_tol: None,
                fix: None,
                estimate: None,
                holdout: part.holdout,
                seed: part.seed,
                iterate: false,
                temperatures: &[],
                circular: None,
                circle: Default::default(),
            };
            let checked = request.check()?;
            match &part.machine {
                Some(path) => Some(checked.run(&chain_core::load_file(path)?)?),
                None => Some(checked.run(m)?),
            }
        }
        None => None,
    };

    let circular = match &cal.circular {
        Some(part) => {
            let options =
                crate::ops::circular::options(part.radius, part.feed, part.plane.as_deref(), None)?;
            let test = source::read_circular(Source::Path(&part.runs), &options)?;
            let document = crate::ops::circular::run(&test, &DiagnosisOptions::default());
            let charts = svgs(&crate::plot::circular::charts(&test, &document))?;
            Some(Charted { document, charts })
        }
        None => None,
    };

    let thermal = match &cal.thermal {
        Some(part) => {
            let test = source::read_drift(Source::Path(&part.runs), &Roles::default())?;
            let split = part.holdout.map_or(Split::None, Split::Holdout);
            let fit = part.fit.then(|| FitOptions {
                sensors: part.sensors.unwrap_or(DEFAULT_SENSORS),
                lag: part.lag,
                split,
            });
            let document = crate::ops::thermal::run(&ThermalRequest {
                test: &test,
                pairs: &[],
                fit,
                into_machine: None,
            })?;
            let charts = svgs(&crate::plot::thermal::charts(&test, &document))?;
            Some(Charted { document, charts })
        }
        None => None,
    };

    Ok(Report {
        file: cal.file.clone(),
        cover: cal.cover.clone(),
        chain_version: env!("CARGO_PKG_VERSION"),
        machine: m.name.clone(),
        inputs,
        positioning,
        map,
        identify,
        export,
        circular,
        thermal,
    })
}

/// How an ISO 230-2 figure is read from an axis's statistics.
pub type Figure = fn(&AxisStats) -> f64;

/// The ISO 230-2 figures of an axis (spec `positioning.md`, "Output"): name
/// and value, the one table the tolerances, the verdicts and the page read.
pub const FIGURES: [(&str, Figure); 12] = [
    ("A", |a| a.A),
    ("A_up", |a| a.A_up),
    ("A_down", |a| a.A_down),
    ("E", |a| a.E),
    ("E_up", |a| a.E_up),
    ("E_down", |a| a.E_down),
    ("M", |a| a.M),
    ("R", |a| a.R),
    ("R_up", |a| a.R_up),
    ("R_down", |a| a.R_down),
    ("B", |a| a.B),
    ("B_mean", |a| a.B_mean),
];

/// The axis's value of the ISO 230-2 figure `figure` (one of
/// [`FIGURES`]; the calibration file refuses any other).
fn figure_value(doc: &PositioningDocument, figure: &str) -> Option<f64> {
    FIGURES
        .iter()
        .find(|(name, _)| *name == figure)
        .map(|(_, value)| value(&doc.axis))
}
