//! `chain export` as a request and a document (measured-machines spec §6;
//! docs/export.md, docs/export-controllers.md): the axis corrections that
//! cancel a built machine's error, as the universal grid CSV or a
//! controller's per-axis tables, with what they leave. The CLI writes the
//! files into `--out` (or the one file to stdout) and prints the summary;
//! Python returns both. `chain map --compensated` shares
//! [`table_export`] and [`travel_of`].

use chain_core::built::BuiltMachine;
use chain_core::compensation::controllers::{
    self, Controller, ControllerError, Export, ExportOptions, FormatReport, Limit,
    BECKHOFF_DEFAULT_MAX_RECORDS, CEC_DEFAULT_MAX_POINTS, DEFAULT_STEP,
};
use chain_core::compensation::grid::{self, GridCompensation};
use chain_core::compensation::thermal::{self, ThermalExportError, ThermalFormat, ThermalLaw};
use chain_core::compensation::{CompensationError, ExportedFile};
use chain_core::kinematics::Kinematics;
use chain_core::values::Values;
use chain_core::Machine;
use reliability::ReliabilityError;
use serde::Serialize;

use super::resolve::{AxisPoints, Parameters, ResolveError};
use super::worded::{diagnostic, Worded};

/// What `chain export` writes for (`--controller`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExportController {
    /// The universal grid CSV: `δq` at every node and the residual.
    Grid,
    /// A controller's per-axis tables.
    Tables(Controller),
    /// A controller's temperature compensation of a machine with thermal
    /// terms (`chain_core::compensation::thermal`).
    Thermal(ThermalFormat),
}

impl ExportController {
    /// Every controller, in the order of `--controller`'s values: the grid,
    /// then [`Controller::ALL`].
    pub const ALL: [ExportController; 1 + Controller::ALL.len() + ThermalFormat::ALL.len()] = {
        let mut all =
            [ExportController::Grid; 1 + Controller::ALL.len() + ThermalFormat::ALL.len()];
        let mut i = 0;
        while i < Controller::ALL.len() {
            all[i + 1] = ExportController::Tables(Controller::ALL[i]);
            i += 1;
        }
        let mut j = 0;
        while j < ThermalFormat::ALL.len() {
            all[i + 1 + j] = ExportController::Thermal(ThermalFormat::ALL[j]);
            j += 1;
        }
        all
    };

    /// The name `--controller` takes.
    pub fn name(self) -> &'static str {
        match self {
            ExportController::Grid => "grid",
            ExportController::Tables(c) => c.name(),
            ExportController::Thermal(ThermalFormat::Siemens) => "siemens-thermal",
            ExportController::Thermal(ThermalFormat::Linuxcnc) => "linuxcnc-thermal",
            ExportController::Thermal(ThermalFormat::Beckhoff) => "beckhoff-thermal",
            ExportController::Thermal(ThermalFormat::Heidenhain) => "heidenhain-thermal",
            ExportController::Thermal(ThermalFormat::Klipper) => "klipper-thermal",
        }
    }

    /// The words that open the first comment line of the files written
    /// for it: the command that wrote them, `chain export --controller
    /// NAME` ([`ExportOptions::provenance`]).
    pub fn provenance(self) -> String {
        format!("chain export --controller {}", self.name())
    }
}

/// The request of `chain export`.
#[derive(Debug, Clone)]
pub struct ExportRequest<'a> {
    /// `--controller`.
    pub controller: ExportController,
    /// `--param NAME=VALUE`.
    pub params: &'a [(String, f64)],
    /// The grid export's nodes: `--grid VAR=...` over `reliability.grid`,
    /// or rows of axis values (`--axes`); for the per-axis tables, the
    /// grid's values give each axis's travel and rows are refused.
    pub points: AxisPoints<'a>,
    /// `--step`: the largest table step (mm) of the per-axis tables.
    pub step: Option<f64>,
    /// `--cec-max-points`.
    pub cec_max_points: Option<usize>,
    /// `--beckhoff-max-records`.
    pub beckhoff_max_records: Option<usize>,
    /// `--angles`: the formats that write the rotary axis lines' tilts on
    /// request
    /// (`chain_core::compensation::controllers::Capabilities::angles`).
    pub angles: bool,
    /// `--temperature NAME=VALUE`: the thermal state the tables are for
    /// (°C; sensors not named at their reference).
    pub temperatures: &'a [(String, f64)],
}

/// What the written files say made them: the command, and a machine with
/// sensors' thermal state (`at T_x = 28 °C`).
fn provenance(controller: ExportController, state: &[(String, f64)]) -> String {
    let command = controller.provenance();
    if state.is_empty() {
        return command;
    }
    let at: Vec<String> = state.iter().map(|(n, t)| format!("{n} = {t} °C")).collect();
    format!("{command} at {}", at.join(", "))
}

/// Why `chain export` cannot run.
#[derive(Debug, thiserror::Error)]
pub enum ExportOpsError {
    /// An option the chosen controller does not take.
    #[error("--controller {controller} does not take {option}")]
    Option {
        /// The controller.
        controller: &'static str,
        /// The option(s).
        option: &'static str,
        /// Why not, and what to give instead.
        why: &'static str,
    },
    /// An option does not match the machine.
    #[error(transparent)]
    Resolve(#[from] ResolveError),
    /// The parameters (located in the machine file).
    #[error(transparent)]
    Reliability(#[from] ReliabilityError),
    /// The values and the machine do not go together.
    #[error("{values}: {message}")]
    Built {
        /// The values file.
        values: String,
        /// What is wrong.
        message: String,
    },
    /// The grid export (a node outside a values table, ...).
    #[error("{}", compensation_message(error))]
    Compensation {
        /// The values file.
        values: String,
        /// What went wrong.
        error: Box<CompensationError>,
    },
    /// A per-axis format (an axis it cannot take, a table that does not
    /// cover the travel, ...).
    #[error("{}", controller_message(error))]
    Controller {
        /// The values file.
        values: String,
        /// What went wrong.
        error: Box<ControllerError>,
    },
    /// A temperature compensation the machine cannot take.
    #[error("{values}: {error}")]
    Thermal {
        /// The values file.
        values: String,
        /// What went wrong.
        error: Box<ThermalExportError>,
    },
    /// A `--grid` value that is not a node of the per-axis tables.
    #[error(
        "--grid {variable}=...: the {controller} tables sample `{variable}` at {points} nodes every {step} {unit} from {min} to {max}, and {what}"
    )]
    GridNodes {
        /// The controller.
        controller: &'static str,
        /// The axis variable.
        variable: String,
        /// The table's nodes.
        points: usize,
        /// Its step.
        step: f64,
        /// Its first node.
        min: f64,
        /// Its last node.
        max: f64,
        /// The unit of the step and nodes (`mm`, or `°` for a rotary axis,
        /// whose `--grid` values are radians).
        unit: &'static str,
        /// What does not fit.
        what: String,
    },
}

/// A [`CompensationError`]'s message: a node outside a values table names
/// the table and its range.
fn compensation_message(e: &CompensationError) -> String {
    match e {
        CompensationError::OutOfRange { point, at, source } => format!(
            "at node {} ({at}): {} = {} is outside the table of `{}` ({}, {} = {} to {})",
            point + 1,
            source.variable,
            source.value,
            source.name,
            source.table,
            source.variable,
            source.lo,
            source.hi
        ),
        e => e.to_string(),
    }
}

/// A [`ControllerError`]'s message: a table that does not cover the
/// travel names the table, its range and the value needed; an axis without
/// a travel is told how to give one.
fn controller_message(e: &ControllerError) -> String {
    match e {
        ControllerError::NoTravel { variable } => format!(
            "no travel for axis `{variable}`: give it (e.g. `--grid {variable}=0:800:81`) or add the axis to the machine file's `reliability.grid`"
        ),
        ControllerError::OutOfTable {
            variable,
            lo,
            hi,
            source,
        } => format!(
            "the table of `{}` ({}) covers {} = {} to {}, and the export needs {} = {} (sampling axis `{variable}` over {lo} to {hi}, the other axes at their travel's start)",
            source.name, source.table, source.variable, source.lo, source.hi, source.variable, source.value
        ),
        e => e.to_string(),
    }
}

impl ExportOpsError {
    /// `option` refused for the request's controller, and why.
    fn option(request: &ExportRequest<'_>, option: &'static str, why: &'static str) -> Self {
        ExportOpsError::Option {
            controller: request.controller.name(),
            option,
            why,
        }
    }
}

impl Worded for ExportOpsError {
    fn own_code(&self) -> Option<&'static str> {
        match self {
            ExportOpsError::Option { .. } => Some("chain::export::option"),
            ExportOpsError::GridNodes { .. } => Some("chain::export::grid_nodes"),
            ExportOpsError::Compensation { error, .. } => match **error {
                CompensationError::OutOfRange { .. } => Some("chain::export::out_of_range"),
                _ => None,
            },
            ExportOpsError::Controller { error, .. } => match **error {
                ControllerError::OutOfTable { .. } => Some("chain::export::out_of_table"),
                _ => None,
            },
            _ => None,
        }
    }

    fn own_help(&self) -> Option<String> {
        match self {
            ExportOpsError::Option { why, .. } => Some(why.to_string()),
            ExportOpsError::GridNodes { .. } => Some(
                "give the travel alone (--grid VAR=LO,HI) and the table step with --step".into(),
            ),
            ExportOpsError::Compensation { values, error } => match &**error {
                CompensationError::OutOfRange { source, .. } => Some(format!(
                    "the values file {values} does not cover the requested nodes: export inside {} = {} to {} (--grid), extend the table, or add `extrapolate: hold` to its entry",
                    source.variable, source.lo, source.hi
                )),
                _ => None,
            },
            ExportOpsError::Controller { values, error } => match &**error {
                ControllerError::OutOfTable { source, .. } => Some(format!(
                    "the values file {values} does not cover the travel: give a travel inside the table (--grid {}={},{}), measure the table over the whole travel, or add `extrapolate: hold` to its entry; nothing is extrapolated",
                    source.variable, source.lo, source.hi
                )),
                _ => None,
            },
            ExportOpsError::Resolve(e) => e.own_help(),
            _ => None,
        }
    }

    #[cfg(feature = "cli")]
    fn inner(&self) -> Option<&dyn miette::Diagnostic> {
        match self {
            ExportOpsError::Resolve(e) => Some(e),
            ExportOpsError::Compensation { error, .. } => Some(&**error),
            ExportOpsError::Controller { error, .. } => Some(&**error),
            _ => None,
        }
    }
}

diagnostic!(ExportOpsError);

/// The document of `chain export`: the grid export's summary and file, or
/// a per-axis format's report and files. Its JSON is the summary (the
/// files' names, not their text).
#[derive(Debug, Clone, Serialize)]
#[serde(untagged)]
pub enum ExportDocument {
    /// `--controller grid`.
    Grid(GridExport),
    /// A per-axis table format.
    Tables(TablesExport),
    /// A temperature compensation format.
    Thermal(ThermalExport),
}

/// A temperature compensation's document: the law per axis and sensor and
/// what it leaves (`docs/export-controllers.md`, "Thermal compensation").
#[derive(Debug, Clone, Serialize)]
pub struct ThermalExport {
    /// The values file.
    pub values_file: String,
    /// The files' names.
    pub files: Vec<String>,
    /// The law.
    #[serde(flatten)]
    pub law: ThermalLaw,
    /// The files themselves.
    #[serde(skip)]
    pub written: Vec<ExportedFile>,
}

/// The grid export's document.
#[derive(Debug, Clone, Serialize)]
pub struct GridExport {
    /// The values file.
    pub values_file: String,
    /// The file's name.
    pub files: Vec<String>,
    /// The corrections, residuals and summary.
    #[serde(flatten)]
    pub grid: GridCompensation,
    /// The file itself.
    #[serde(skip)]
    pub file: ExportedFile,
}

/// A per-axis format's document.
#[derive(Debug, Clone, Serialize)]
pub struct TablesExport {
    /// The values file.
    pub values_file: String,
    /// What the format expresses, what it leaves, how large.
    #[serde(flatten)]
    pub report: FormatReport,
    /// The files themselves.
    #[serde(skip)]
    pub files: Vec<ExportedFile>,
}

impl ExportDocument {
    /// The files the export writes.
    pub fn files(&self) -> &[ExportedFile] {
        match self {
            ExportDocument::Grid(g) => std::slice::from_ref(&g.file),
            ExportDocument::Tables(t) => &t.files,
            ExportDocument::Thermal(t) => &t.written,
        }
    }
}

/// Refuses the options the chosen controller does not take, before
/// anything is read.
pub fn check(request: &ExportRequest<'_>) -> Result<(), ExportOpsError> {
    let refuse = |option, why| Err(ExportOpsError::option(request, option, why));
    match request.controller {
        ExportController::Grid => {
            if request.step.is_some() {
                return refuse(
                    "--step",
                    "the grid export corrects at the grid's nodes: give them with --grid VAR=LO:HI:N",
                );
            }
            no_table_options(request)?;
        }
        ExportController::Tables(c) => {
            if let AxisPoints::Rows { .. } = request.points {
                return refuse(
                    "--axes",
                    "a per-axis table samples each axis over its travel: give the travel with --grid VAR=LO,HI and the table step with --step; --axes gives the nodes of --controller grid",
                );
            }
            if request.step.is_some() && !step_applies(c) {
                return refuse("--step", STEP_WHY);
            }
            let limit = c.capabilities().limit;
            if request.cec_max_points.is_some() && limit != Some(Limit::CecPoints) {
                return refuse("--cec-max-points", "it limits the siemens-cec tables");
            }
            if request.beckhoff_max_records.is_some() && limit != Some(Limit::BeckhoffRecords) {
                return refuse("--beckhoff-max-records", "it limits the beckhoff tables");
            }
            if request.angles && !c.capabilities().angles {
                return refuse("--angles", ANGLES_WHY);
            }
        }
        ExportController::Thermal(_) => {
            let why = "a temperature compensation is a law per axis fitted over the grid's points (--grid VAR=V1,V2,... per axis), per kelvin of each sensor";
            if let AxisPoints::Rows { .. } = request.points {
                return refuse("--axes", why);
            }
            if request.step.is_some() {
                return refuse("--step", why);
            }
            no_table_options(request)?;
            if !request.temperatures.is_empty() {
                return refuse(
                    "--temperature",
                    "the law holds at every temperature (the PLC or HAL evaluates it); its remainder is stated per kelvin of each sensor",
                );
            }
        }
    }
    Ok(())
}

/// Refuses the options of the per-axis tables (`--angles`, the table
/// limits) for a format that writes none.
fn no_table_options(request: &ExportRequest<'_>) -> Result<(), ExportOpsError> {
    let refuse = |option, why| Err(ExportOpsError::option(request, option, why));
    if request.angles {
        return refuse("--angles", ANGLES_WHY);
    }
    if request.cec_max_points.is_some() || request.beckhoff_max_records.is_some() {
        return refuse(
            "--cec-max-points or --beckhoff-max-records",
            "they limit the siemens-cec and beckhoff tables",
        );
    }
    Ok(())
}

/// Why a format takes no `--angles`.
pub const ANGLES_WHY: &str = "it writes heidenhain's angle rows of the rotary axes (siemens-carr writes its axis vectors always; the other formats cannot hold an axis tilt)";

/// Why a rotary format takes no table step.
pub const STEP_WHY: &str = "a rotary format fits its controller's kinematics over each axis's travel (--grid VAR=LO,HI) and steps its rotary COMP_FILEs every 2°";

/// Whether a table step acts on `controller`'s export: the per-axis
/// formats sample each axis at it; the rotary formats (a table-table
/// machine) fit over the travel.
pub fn step_applies(controller: Controller) -> bool {
    matches!(
        controller.capabilities().takes,
        chain_core::compensation::controllers::Takes::LinearAxes { .. }
    )
}

/// Runs `chain export` of `machine` (`file` names it) with `values` (read
/// from `values_file`).
pub fn run(
    machine: &Machine,
    file: &str,
    values: Values,
    values_file: &str,
    request: &ExportRequest<'_>,
) -> Result<ExportDocument, ExportOpsError> {
    check(request)?;
    let m = machine;
    let params = Parameters::new(m, request.params)?.values()?;
    // The geometric formats read the values at the thermal state; a
    // thermal law is per kelvin, the values as the file gives them.
    let at_state = |values| -> Result<(Values, String), ExportOpsError> {
        let (values, state) = super::resolve::at_thermal_state(m, values, request.temperatures)?;
        Ok((values, provenance(request.controller, &state)))
    };
    let built_error = |e: chain_core::built::BuiltError| ExportOpsError::Built {
        values: values_file.to_string(),
        message: e.to_string(),
    };
    match request.controller {
        ExportController::Grid => {
            let (values, provenance) = at_state(values)?;
            let (points, _) = request.points.resolve(m, file)?;
            let built = BuiltMachine::compile(m, values, params).map_err(built_error)?;
            let kin = Kinematics::from_machine(m);
            let result = grid::export(&built, &kin, points).map_err(|error| {
                ExportOpsError::Compensation {
                    values: values_file.to_string(),
                    error: Box::new(error),
                }
            })?;
            let file = result.file(&provenance);
            Ok(ExportDocument::Grid(GridExport {
                values_file: values_file.to_string(),
                files: vec![file.name.clone()],
                grid: result,
                file,
            }))
        }
        ExportController::Thermal(format) => {
            thermal_export(m, file, &values, values_file, &params, format, request)
        }
        ExportController::Tables(c) => {
            let (values, provenance) = at_state(values)?;
            let built = BuiltMachine::compile(m, values, params).map_err(built_error)?;
            let options = ExportOptions {
                step: request.step.unwrap_or(DEFAULT_STEP),
                travel: travel_of(request.points.grid()),
                cec_max_points: request.cec_max_points.unwrap_or(CEC_DEFAULT_MAX_POINTS),
                beckhoff_max_records: (request.beckhoff_max_records)
                    .unwrap_or(BECKHOFF_DEFAULT_MAX_RECORDS),
                provenance,
                angles: request.angles,
            };
            let grid = request.points.grid();
            let export = table_export(c, &built, m, &options, grid, values_file)?;
            Ok(ExportDocument::Tables(TablesExport {
                values_file: values_file.to_string(),
                report: export.report,
                files: export.files,
            }))
        }
    }
}

/// A temperature compensation `format` of `m`'s thermal terms over the
/// grid's points (`docs/export-controllers.md`, "Thermal compensation").
fn thermal_export(
    m: &Machine,
    file: &str,
    values: &Values,
    values_file: &str,
    params: &[f64],
    format: ThermalFormat,
    request: &ExportRequest<'_>,
) -> Result<ExportDocument, ExportOpsError> {
    let (points, _) = request.points.resolve(m, file)?;
    let points: Vec<Vec<f64>> = (0..points.len()).map(|i| points.point(i)).collect();
    let model = chain_core::compile(m);
    let law = thermal::fit(m, &model, params, values, &points, format).map_err(|error| {
        ExportOpsError::Thermal {
            values: values_file.to_string(),
            error: Box::new(error),
        }
    })?;
    let written = law.files(&request.controller.provenance());
    Ok(ExportDocument::Thermal(ThermalExport {
        values_file: values_file.to_string(),
        files: written.iter().map(|f| f.name.clone()).collect(),
        law,
        written,
    }))
}

/// The per-axis export of `controller` with `options`, and `grid`'s values
/// checked against the table nodes it gives (a value between nodes is
/// refused, not dropped). Shared with `chain map --compensated`.
pub fn table_export(
    controller: Controller,
    built: &BuiltMachine,
    machine: &Machine,
    options: &ExportOptions,
    grid: &[(String, Vec<f64>)],
    values_file: &str,
) -> Result<Export, ExportOpsError> {
    let export = controllers::export(controller, built, machine, options).map_err(|error| {
        ExportOpsError::Controller {
            values: values_file.to_string(),
            error: Box::new(error),
        }
    })?;
    for (name, given) in grid {
        let Some(a) = export.report.axes.iter().find(|a| a.variable == *name) else {
            continue;
        };
        // The report gives a rotary axis's nodes in degrees.
        let (unit, scale) = match a.axis {
            'A' | 'B' | 'C' => ("°", 180.0 / std::f64::consts::PI),
            _ => ("mm", 1.0),
        };
        let off_node = given.iter().find(|&&v| {
            let v = v * scale;
            let k = ((v - a.min) / a.step).round();
            (v - (a.min + k * a.step)).abs() > 1e-9 * a.step.max(1.0)
        });
        let what = match off_node {
            Some(v) if scale != 1.0 => format!("{v} rad is not one of its nodes"),
            Some(v) => format!("{v} is not one of its nodes"),
            None if given.len() > 2 && given.len() != a.points => {
                format!("it has {} values", given.len())
            }
            None => continue,
        };
        return Err(ExportOpsError::GridNodes {
            controller: controller.name(),
            variable: name.clone(),
            points: a.points,
            step: a.step,
            min: a.min,
            max: a.max,
            unit,
            what,
        });
    }
    Ok(export)
}

/// `--grid` values as travels: each axis's smallest and largest value.
pub fn travel_of(grid: &[(String, Vec<f64>)]) -> Vec<(String, [f64; 2])> {
    grid.iter()
        .map(|(n, v)| {
            let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            (n.clone(), [lo, hi])
        })
        .collect()
}
