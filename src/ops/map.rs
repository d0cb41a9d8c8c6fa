//! `chain map` as a request and a document (measured-machines spec §3;
//! docs/map.md): the values read for the chosen approach, the parameters,
//! the points (the grid over `reliability.grid`, or rows) and the built
//! machine that maps them ([`prepare`]); then the map, or its summary alone,
//! and with `--compensated` the map after a controller's compensation
//! ([`PreparedMap::run`]; docs/export.md). The CLI and
//! `Machine.map` run it.

use chain_core::built::{BuiltMachine, MapError, MapSummary, Points};
use chain_core::compensation::controllers::{ExportOptions, DEFAULT_STEP};
use chain_core::compensation::grid::GridError;
use chain_core::compensation::CompensationError;
use chain_core::kinematics::Kinematics;
use chain_core::model::Frame;
use chain_core::named::NameMap;
use chain_core::values::{Approach, ApproachError, Entry, EntryKind, Reversal, Values};
use chain_core::{Machine, MapResult};
use reliability::ReliabilityError;
use serde::Serialize;

use super::export::{self, ExportController, ExportOpsError};
use super::resolve::{self, AxisPoints, Parameters, ResolveError};
use super::worded::{diagnostic, Worded};

/// `--compensated CONTROLLER`: the map after the controller's
/// compensation, exported from the same values.
#[derive(Debug, Clone)]
pub struct CompensationRequest<'a> {
    /// The controller.
    pub controller: ExportController,
    /// `--compensation-grid`: the grid correction's nodes per axis (default:
    /// the map's grid), or a per-axis table's travel.
    pub grid: &'a [(String, Vec<f64>)],
    /// `--compensation-step`: a per-axis format's largest table step (mm).
    pub step: Option<f64>,
    /// `--compensation-angles`: heidenhain's angle rows.
    pub angles: bool,
}

/// The request of `chain map`.
#[derive(Debug, Clone)]
pub struct MapRequest<'a> {
    /// `--param NAME=VALUE`.
    pub params: &'a [(String, f64)],
    /// `--approach`.
    pub approach: &'a [(Option<String>, Approach)],
    /// The points: the grid, or rows (`--axes`, an array).
    pub points: AxisPoints<'a>,
    /// `--compensated`.
    pub compensated: Option<CompensationRequest<'a>>,
    /// Keep every point's error (`false`: the summary alone, for a large
    /// map's table; the document then has no JSON form).
    pub keep_points: bool,
    /// `--temperature NAME=VALUE`: the thermal state (°C; sensors not named
    /// at their reference).
    pub temperatures: &'a [(String, f64)],
}

/// Where the points of a map came from.
pub use super::resolve::PointsInput as MapInput;

/// A map ready to run.
#[derive(Debug, Clone)]
pub struct PreparedMap {
    /// The built machine.
    pub built: BuiltMachine,
    /// The points.
    pub points: Points,
    /// Where they came from.
    pub input: MapInput,
    /// The machine file's name.
    pub file: String,
    /// The values file's name.
    pub values_file: String,
    /// The thermal state mapped (every sensor, °C; empty for a machine
    /// without sensors).
    pub temperatures: Vec<(String, f64)>,
}

/// Why a map cannot be prepared.
#[derive(Debug, thiserror::Error)]
pub enum MapOpsError {
    /// An option does not match the machine.
    #[error(transparent)]
    Resolve(#[from] ResolveError),
    /// The parameters (located in the machine file).
    #[error(transparent)]
    Reliability(#[from] ReliabilityError),
    /// `--approach` names what the values do not have.
    #[error("--approach: {error} (values {values})")]
    Approach {
        /// The values file.
        values: String,
        /// What is wrong.
        error: ApproachError,
    },
    /// The values and the machine do not go together.
    #[error("{values}: {message}")]
    Built {
        /// The values file.
        values: String,
        /// What is wrong.
        message: String,
    },
    /// The map itself (a point outside a values table, no points).
    #[error("{}", map_message(error))]
    Map {
        /// The values file.
        values: String,
        /// What went wrong.
        error: Box<MapError>,
    },
    /// `--compensation-step` with a correction that takes no table step
    /// (the grid correction, a rotary format), `--compensation-angles` with
    /// one that has no angle rows.
    #[error("--compensated {controller} does not take {option}")]
    Option {
        /// The correction.
        controller: &'static str,
        /// The option.
        option: &'static str,
        /// Why not, and what to give instead.
        why: &'static str,
    },
    /// The compensation's export.
    #[error(transparent)]
    Export(Box<ExportOpsError>),
    /// The grid correction of the exported deltas.
    #[error(transparent)]
    Correction(Box<GridError>),
}

/// A [`MapError`]'s message: a point outside a values table names the point,
/// the value and the table.
fn map_message(e: &MapError) -> String {
    match e {
        MapError::OutOfRange { point, at, source } => format!(
            "at point {} ({at}): {} = {} is outside the table of `{}` ({})",
            point + 1,
            source.variable,
            source.value,
            source.name,
            source.table
        ),
        other => other.to_string(),
    }
}

impl From<ExportOpsError> for MapOpsError {
    fn from(e: ExportOpsError) -> Self {
        MapOpsError::Export(Box::new(e))
    }
}

impl Worded for MapOpsError {
    fn own_code(&self) -> Option<&'static str> {
        match self {
            MapOpsError::Map { error, .. } => Some(match **error {
                MapError::OutOfRange { .. } => "chain::map::out_of_range",
                MapError::NoPoints => "chain::map::no_points",
                _ => "chain::map::points",
            }),
            MapOpsError::Option { .. } => Some("chain::map::option"),
            MapOpsError::Export(e) => e.own_code(),
            _ => None,
        }
    }

    fn own_help(&self) -> Option<String> {
        match self {
            MapOpsError::Map { values, error } => match &**error {
                MapError::OutOfRange { source, .. } => Some(format!(
                    "the table of `{}` in {values} covers {} = {} to {}; map inside it (--grid), extend the table, or add `extrapolate: hold` to its entry to hold the end values",
                    source.name, source.variable, source.lo, source.hi
                )),
                MapError::NoPoints => {
                    Some("give the points with --grid VAR=... or --axes AXES.csv".into())
                }
                _ => None,
            },
            MapOpsError::Option { why, .. } => Some(why.to_string()),
            MapOpsError::Export(e) => e.own_help(),
            MapOpsError::Resolve(e) => e.own_help(),
            _ => None,
        }
    }

    #[cfg(feature = "cli")]
    fn inner(&self) -> Option<&dyn miette::Diagnostic> {
        match self {
            MapOpsError::Resolve(e) => Some(e),
            MapOpsError::Export(e) => Some(&**e),
            MapOpsError::Correction(e) => Some(&**e),
            _ => None,
        }
    }
}

diagnostic!(MapOpsError);

/// Prepares `chain map` of `machine` (`file` names it) with `values` (read
/// from `values_file`).
pub fn prepare(
    machine: &Machine,
    file: &str,
    mut values: Values,
    values_file: &str,
    request: &MapRequest<'_>,
) -> Result<PreparedMap, MapOpsError> {
    let m = machine;
    if !request.approach.is_empty() {
        values
            .choose_approach(request.approach)
            .map_err(|error| MapOpsError::Approach {
                values: values_file.to_string(),
                error,
            })?;
    }
    let params = Parameters::new(m, request.params)?.values()?;
    let (points, input) = request.points.resolve(m, file)?;
    let (values, temperatures) = resolve::at_thermal_state(m, values, request.temperatures)?;
    let built = BuiltMachine::compile(m, values, params).map_err(|e| MapOpsError::Built {
        values: values_file.to_string(),
        message: e.to_string(),
    })?;
    Ok(PreparedMap {
        built,
        points,
        input,
        file: file.to_string(),
        values_file: values_file.to_string(),
        temperatures,
    })
}

/// What a map computed: every point's error, or the summary alone.
#[derive(Debug, Clone)]
pub enum Mapped {
    /// The library's whole result.
    Full(MapResult),
    /// The summary, and the points it is of.
    Summary {
        /// The summary.
        summary: MapSummary,
        /// The points.
        points: Points,
    },
}

impl Mapped {
    /// The summary.
    pub fn summary(&self) -> &MapSummary {
        match self {
            Mapped::Full(r) => &r.summary,
            Mapped::Summary { summary, .. } => summary,
        }
    }

    /// The points.
    pub fn points(&self) -> &Points {
        match self {
            Mapped::Full(r) => &r.points,
            Mapped::Summary { points, .. } => points,
        }
    }
}

/// The error left after a controller's compensation, at the map's points.
#[derive(Debug, Clone)]
pub struct Compensated {
    /// The controller's name.
    pub controller: &'static str,
    /// The nodes of the correction grid (`grid`), or the points of the
    /// tables (per-axis formats; 0 for Klipper's factors).
    pub nodes: usize,
    /// Where the correction comes from, in words (the table's heading).
    pub source: String,
    /// The residual map.
    pub result: MapResult,
}

/// The document of `chain map`: the library's [`MapResult`] (its JSON is the
/// spec's document, with `compensated` added) and what the command knows of
/// its input.
#[derive(Debug, Clone)]
pub struct MapDocument {
    /// The values file.
    pub values_file: String,
    /// The values file's entries.
    pub entries: Vec<Entry>,
    /// The machine's error parameters.
    pub errors: usize,
    /// Error parameters the values file does not give (zero).
    pub unset: usize,
    /// The machine's name.
    pub machine: String,
    /// The frame of the error.
    pub frame: Frame,
    /// The axis variables, in a point's order.
    pub variables: Vec<String>,
    /// Where the points came from.
    pub input: MapInput,
    /// The map.
    pub result: Mapped,
    /// The map after compensation (`--compensated`).
    pub compensated: Option<Compensated>,
    /// Per bidirectional table, the reversal the approach read leaves out.
    pub reversals: Vec<Reversal>,
    /// The thermal state (every sensor, °C; empty without sensors).
    pub temperatures: Vec<(String, f64)>,
}

impl MapDocument {
    /// The whole result (`None` when the request kept the summary alone).
    pub fn full(&self) -> Option<&MapResult> {
        match &self.result {
            Mapped::Full(r) => Some(r),
            Mapped::Summary { .. } => None,
        }
    }
}

/// `compensated` of the JSON document.
#[derive(Serialize)]
struct CompensatedJson<'a> {
    controller: &'a str,
    correction_nodes: usize,
    #[serde(flatten)]
    map: &'a MapResult,
}

/// The spec's JSON document, with `compensated` (`--compensated`) added.
#[derive(Serialize)]
struct MapJson<'a> {
    /// The thermal state (a machine with sensors).
    #[serde(skip_serializing_if = "Option::is_none")]
    temperatures: Option<NameMap<&'a str, f64>>,
    #[serde(flatten)]
    map: &'a MapResult,
    #[serde(skip_serializing_if = "Option::is_none")]
    compensated: Option<CompensatedJson<'a>>,
}

impl Serialize for MapDocument {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let Some(map) = self.full() else {
            return Err(serde::ser::Error::custom("the map kept no point"));
        };
        MapJson {
            temperatures: (!self.temperatures.is_empty()).then(|| {
                NameMap(
                    self.temperatures
                        .iter()
                        .map(|(n, t)| (n.as_str(), *t))
                        .collect(),
                )
            }),
            map,
            compensated: self.compensated.as_ref().map(|c| CompensatedJson {
                controller: c.controller,
                correction_nodes: c.nodes,
                map: &c.result,
            }),
        }
        .serialize(s)
    }
}

impl PreparedMap {
    /// Maps the points (telling `progress` how many points each block
    /// covered), after the compensation's map when the request asks for
    /// one, and gathers the document.
    pub fn run(
        &self,
        machine: &Machine,
        request: &MapRequest<'_>,
        progress: &(dyn Fn(usize) + Sync),
    ) -> Result<MapDocument, MapOpsError> {
        let m = machine;
        let compensated = match &request.compensated {
            Some(c) => Some(self.compensate(m, request, c)?),
            None => None,
        };
        let map_error = |error: MapError| MapOpsError::Map {
            values: self.values_file.clone(),
            error: Box::new(error),
        };
        let result = if request.keep_points {
            let r = self.built.map_with_progress(self.points.clone(), progress);
            Mapped::Full(r.map_err(map_error)?)
        } else {
            let summary = self.built.summary(&self.points, progress);
            Mapped::Summary {
                summary: summary.map_err(map_error)?,
                points: self.points.clone(),
            }
        };
        let values = self.built.values();
        // Error parameters the file gave a value: a function's table gives
        // all its coefficients.
        let given: usize = (values.entries().iter())
            .map(|e| match e.kind {
                EntryKind::Function => m
                    .function_index(&e.name)
                    .map_or(1, |f| m.functions[f].coefficients.len()),
                _ => 1,
            })
            .sum();
        Ok(MapDocument {
            values_file: self.values_file.clone(),
            entries: values.entries().to_vec(),
            errors: m.errors.len(),
            unset: m.errors.len().saturating_sub(given),
            machine: m.name.clone(),
            frame: m.frame,
            variables: self.built.variables().to_vec(),
            input: self.input.clone(),
            result,
            compensated,
            reversals: values.reversals(),
            temperatures: self.temperatures.clone(),
        })
    }

    /// The map after `c`'s compensation, at the map's points.
    fn compensate(
        &self,
        m: &Machine,
        request: &MapRequest<'_>,
        c: &CompensationRequest<'_>,
    ) -> Result<Compensated, MapOpsError> {
        let built = &self.built;
        let map_grid = request.points.grid();
        let compensation_error = |error: CompensationError| {
            MapOpsError::from(ExportOpsError::Compensation {
                values: self.values_file.clone(),
                error: Box::new(error),
            })
        };
        let controller = c.controller.name();
        if let ExportController::Thermal(_) = c.controller {
            return Err(MapOpsError::Option {
                controller,
                option: "a map",
                why: "a temperature compensation is a law of the temperatures: `chain export --controller siemens-thermal | linuxcnc-thermal` states what it leaves per kelvin of each sensor (the map of a compensated thermal state is to come)",
            });
        }
        if let ExportController::Tables(tables) = c.controller {
            if c.step.is_some() && !export::step_applies(tables) {
                let (option, why) = ("--compensation-step", export::STEP_WHY);
                return Err(MapOpsError::Option {
                    controller,
                    option,
                    why,
                });
            }
            if c.angles && !tables.capabilities().angles {
                let (option, why) = ("--compensation-angles", export::ANGLES_WHY);
                return Err(MapOpsError::Option {
                    controller,
                    option,
                    why,
                });
            }
            // The map's own range of an axis, where it is one (a single
            // value keeps the machine file's travel); the compensation grid
            // over it.
            let mut travel = export::travel_of(map_grid);
            travel.retain(|(_, [lo, hi])| lo < hi);
            for t in export::travel_of(c.grid) {
                travel.retain(|(n, _)| *n != t.0);
                travel.push(t);
            }
            let options = ExportOptions {
                step: c.step.unwrap_or(DEFAULT_STEP),
                travel,
                angles: c.angles,
                ..ExportOptions::default()
            };
            let export =
                export::table_export(tables, built, m, &options, c.grid, &self.values_file)?;
            let result = built
                .compensated_map(export.correction.as_ref(), self.points.clone())
                .map_err(compensation_error)?;
            let capabilities = tables.capabilities();
            let (nodes, source) = match capabilities.tables {
                false => (
                    0,
                    format!("{}, docs/export-controllers.md", capabilities.holds),
                ),
                true => {
                    let points: Vec<String> = (export.report.axes.iter())
                        .map(|a| format!("{} {}", a.variable, a.points))
                        .collect();
                    (
                        export.report.axes.iter().map(|a| a.points).sum(),
                        format!(
                            "table points {}, docs/export-controllers.md",
                            points.join(", ")
                        ),
                    )
                }
            };
            return Ok(Compensated {
                controller,
                nodes,
                source,
                result,
            });
        }
        if c.step.is_some() || c.angles {
            let (option, why) = match c.step {
                Some(_) => (
                    "--compensation-step",
                    "the grid correction is exported at the nodes of --compensation-grid VAR=LO:HI:N",
                ),
                None => ("--compensation-angles", export::ANGLES_WHY),
            };
            return Err(MapOpsError::Option {
                controller,
                option,
                why,
            });
        }
        // The correction grid: the map's (or the file's), each axis
        // replaceable.
        let mut overrides = map_grid.to_vec();
        overrides.extend(c.grid.iter().cloned());
        let axes = resolve::grid_axes(m, &self.file, &overrides)?;
        let nodes: usize = axes.iter().map(|(_, v)| v.len()).product();
        let source = format!("{nodes} correction nodes, docs/export.md");
        let kin = Kinematics::from_machine(m);
        let grid = chain_core::compensation::grid::export(
            built,
            &kin,
            Points::Grid(axes.iter().map(|(_, v)| v.clone()).collect()),
        )
        .map_err(compensation_error)?;
        let correction = grid
            .correction()
            .map_err(|e| MapOpsError::Correction(Box::new(e)))?;
        let result = built
            .compensated_map(&correction, self.points.clone())
            .map_err(compensation_error)?;
        Ok(Compensated {
            controller,
            nodes,
            source,
            result,
        })
    }
}
