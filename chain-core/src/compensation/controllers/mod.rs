//! Per-axis compensation tables for real controllers (measured-machines
//! spec, section 6; `docs/export-controllers.md` gives every field's source
//! and marks what is unconfirmed).
//!
//! | [`Controller`] | files | what the format expresses |
//! |---|---|---|
//! | [`Controller::Beckhoff`] | `vol_comp_0.lis`, `chain_volcomp.csv` (`ISG_CSV`) | the ISO 230-1 error parameters of the three linear axes: the tool-point position error (not the orientation) |
//! | [`Controller::Linuxcnc`] | `<variable>.comp` per joint (`COMP_FILE_TYPE = 1`), `linuxcnc-README.txt` | each joint's positioning error along its own axis, forward and reverse columns from the values' two approach directions where its table has them |
//! | [`Controller::SiemensCec`] | `NC_CEC.INI` (`%_N_NC_CEC_INI`) | each straightness error, as a cross-axis table (base axis → compensation axis) |
//! | [`Controller::Klipper`] | `skew_correction.cfg` | the squareness errors, as Klipper's shear factors `xy`, `xz`, `yz` |
//! | [`Controller::LinuxcncTrt`] | `xyz?c-trt-kins.hal`, its README, rotary `<variable>.comp` | the rotary axis lines' positions (HAL pins), their zeros (`HOME_OFFSET`) and positioning errors |
//! | [`Controller::Heidenhain`] | `KINEMATICS_ROTARY.TAB`, its README | the rotary axis lines' positions (`Trans` rows; with `angles` their tilts) |
//! | [`Controller::SiemensCarr`] | `TC_CARR.SPF` | the rotary axis lines' positions, directions and zeros (`$TC_CARR`, type P) |
//! | [`Controller::FanucTcp`] | `TCP.PRM`, its README | the rotary axis lines' positions (parameters 19700-19705) |
//!
//! The rotary formats take a table-table five-axis machine and fit their
//! controller's kinematics over the travel (`rotary.rs`).
//!
//! # API
//!
//! [`export`] takes a [`BuiltMachine`] (model, values, parameters), its
//! [`Machine`] and [`ExportOptions`] (the travel and the table step) and
//! returns an [`Export`]: the files ([`ExportedFile`]), a typed
//! [`FormatReport`] (the sampling of each axis, which error terms the format
//! expresses and which remain, each with its largest tool-point effect over
//! the travel, and the residual the format leaves) and a
//! [`Correction`]: what the controller adds to the commanded axes when it
//! applies the files, following its documented interpolation and its
//! behaviour outside the table (LinuxCNC and Sinumerik CEC hold their end
//! values; Klipper's shear covers every position; the Beckhoff emulation
//! refuses a position outside the tables, which its documentation leaves
//! open).
//!
//! # Machines
//!
//! The four formats take linear axes: every variable of the machine must be
//! prismatic, no body may carry a fixed rotation, and the nominal Jacobian of
//! the tool point must move each axis along one frame axis (X, Y or Z, each
//! used once). Beckhoff and Klipper need exactly three such axes. Values are
//! in the machine's units (mm, rad); the "error of an axis" is
//! `u = J⁻¹ · e`, the tool-point error `e` (actual − nominal, the frame of
//! the machine file) expressed as axis motion, so a controller that adds
//! `−u` to the commanded axis cancels it to first order.
//!
//! # Sampling
//!
//! Each axis is sampled on its travel ([`ExportOptions::travel`], else the smallest and largest node of the
//! machine file's `reliability.grid`) at equal steps: the largest step not
//! above [`ExportOptions::step`] that divides the travel into whole
//! intervals. A function slot is evaluated exactly at the nodes; a measured
//! table only inside its range: a node outside it is refused
//! ([`ControllerError::OutOfTable`], naming the values file's table and its
//! range), never extrapolated (unless the values entry says
//! `extrapolate: hold`).

mod beckhoff;
mod fanuc_tcp;
mod heidenhain;
pub(crate) use heidenhain::tnc_table;
mod klipper;
mod linuxcnc;
mod linuxcnc_trt;
mod rotary;
mod siemens_carr;
mod siemens_cec;

use serde::Serialize;

use crate::built::BuiltMachine;
use crate::compensation::{Correction, ExportedFile};
use crate::kinematics::forward::Kinematics;
use crate::model::{ErrorKind, JointKind, Machine};
use crate::model_trait::{ErrorModel, OutOfRange};
use crate::values::Values;

pub use beckhoff::BeckhoffCorrection;
pub use klipper::{KlipperCorrection, SkewFactors};
pub use linuxcnc::{LinuxcncCorrection, LinuxcncTable};
pub use linuxcnc_trt::{TrtModule, TrtPins};
pub use rotary::{KinematicsCorrection, KinematicsParameter, KinematicsReport};
pub use siemens_cec::CecCorrection;

/// The default table step (mm): [`ExportOptions::step`].
pub const DEFAULT_STEP: f64 = 10.0;
/// LinuxCNC's limit of triplets per joint (`EMCMOT_COMP_SIZE`,
/// `src/emc/motion/motion.h`).
pub const LINUXCNC_MAX_POINTS: usize = 256;
/// The default limit of points per CEC table: the SINUMERIK 828D's 200
/// interpolation points (`MD18342`, Function Manual K3); the 840D sl limit is
/// unconfirmed, so a larger one is the user's to give.
pub const CEC_DEFAULT_MAX_POINTS: usize = 200;
/// The largest step (degrees) of a rotary axis's table: a LinuxCNC rotary
/// `COMP_FILE`, the Beckhoff rotary terms.
pub const ROTARY_STEP_DEG: f64 = 2.0;
/// The Beckhoff vendor example's `vol_comp[i].max_records` (2000).
pub const BECKHOFF_DEFAULT_MAX_RECORDS: usize = 2000;

/// A controller format of this module.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Controller {
    /// Beckhoff TwinCAT CNC / ISG volumetric compensation (`ISG_CSV`).
    Beckhoff,
    /// LinuxCNC `[JOINT_n]COMP_FILE`.
    Linuxcnc,
    /// Sinumerik CEC (sag / cross-axis) tables.
    SiemensCec,
    /// Klipper `[skew_correction]` / `SET_SKEW`.
    Klipper,
    /// LinuxCNC `xyzac-trt-kins` / `xyzbc-trt-kins` (HAL pins).
    LinuxcncTrt,
    /// HEIDENHAIN TNC kinematics description (`Trans` rows of the rotary
    /// axes).
    Heidenhain,
    /// SINUMERIK swivel data record `$TC_CARR` (kinematic type P).
    SiemensCarr,
    /// FANUC tool centre point control, table rotation type (parameters
    /// 19680-19705).
    FanucTcp,
}

impl Controller {
    /// Every format, in the specs' table order (measured-machines §6, then
    /// five-axis "Output").
    pub const ALL: [Controller; 8] = [
        Controller::Beckhoff,
        Controller::Linuxcnc,
        Controller::SiemensCec,
        Controller::Klipper,
        Controller::LinuxcncTrt,
        Controller::Heidenhain,
        Controller::SiemensCarr,
        Controller::FanucTcp,
    ];

    /// The format's name (`beckhoff`, `linuxcnc`, `siemens-cec`,
    /// `klipper`): what reports and error messages call it.
    pub fn name(self) -> &'static str {
        match self {
            Controller::Beckhoff => "beckhoff",
            Controller::Linuxcnc => "linuxcnc",
            Controller::SiemensCec => "siemens-cec",
            Controller::Klipper => "klipper",
            Controller::LinuxcncTrt => "linuxcnc-trt",
            Controller::Heidenhain => "heidenhain",
            Controller::SiemensCarr => "siemens-carr",
            Controller::FanucTcp => "fanuc-tcp",
        }
    }

    /// The controller of a [`Controller::name`].
    pub fn from_name(name: &str) -> Option<Controller> {
        Controller::ALL.into_iter().find(|c| c.name() == name)
    }

    /// What the format can hold: the one statement the shared code decides
    /// from (which machines it takes, whether it writes tables along the
    /// axes, the option that limits its tables), so that a new format is
    /// one file and one arm here.
    pub fn capabilities(self) -> Capabilities {
        let linear = |count| Takes::LinearAxes { count, rotary: 0 };
        match self {
            Controller::Beckhoff => Capabilities {
                summary: "Beckhoff TwinCAT / ISG volumetric compensation (`ISG_CSV`)",
                holds: "the ISO 230-1 errors of the three linear axes and of up to three rotary axes, as tables along them",
                takes: Takes::LinearAxes {
                    count: Some(3),
                    rotary: 3,
                },
                tables: true,
                limit: Some(Limit::BeckhoffRecords),
                angles: false,
            },
            Controller::Linuxcnc => Capabilities {
                summary: "LinuxCNC `COMP_FILE` per joint",
                holds: "each joint's positioning error along its own axis, as a table",
                takes: linear(None),
                tables: true,
                limit: None,
                angles: false,
            },
            Controller::SiemensCec => Capabilities {
                summary: "Sinumerik CEC sag / cross-axis tables",
                holds: "each straightness error, as a cross-axis table",
                takes: linear(None),
                tables: true,
                limit: Some(Limit::CecPoints),
                angles: false,
            },
            Controller::Klipper => Capabilities {
                summary: "Klipper `SET_SKEW`",
                holds: "shear factors",
                takes: linear(Some(3)),
                tables: false,
                limit: None,
                angles: false,
            },
            Controller::LinuxcncTrt => Capabilities {
                summary: "LinuxCNC `xyzac-trt-kins` / `xyzbc-trt-kins` pins and rotary HOME_OFFSET",
                holds: "the positions of the two rotary axis lines and their zeros",
                takes: Takes::TableTable,
                tables: false,
                limit: None,
                angles: false,
            },
            Controller::Heidenhain => Capabilities {
                summary: "HEIDENHAIN kinematics description: the rotary axes' `Trans` rows",
                holds: "the positions of the two rotary axis lines, and with the angle rows their tilts",
                takes: Takes::TableTable,
                tables: false,
                limit: None,
                angles: true,
            },
            Controller::SiemensCarr => Capabilities {
                summary: "SINUMERIK swivel data record `$TC_CARR` (type P) as a part program",
                holds: "the positions and directions of the two rotary axis lines and their zeros",
                takes: Takes::TableTable,
                tables: false,
                limit: None,
                angles: false,
            },
            Controller::FanucTcp => Capabilities {
                summary:
                    "FANUC tool centre point control, table rotation type (parameters 19680-19705)",
                holds: "the positions of the two rotary axis lines",
                takes: Takes::TableTable,
                tables: false,
                limit: None,
                angles: false,
            },
        }
    }
}

/// What a controller format can hold ([`Controller::capabilities`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Capabilities {
    /// The format in a few words (the help of the controller's name).
    pub summary: &'static str,
    /// What it expresses, in a few words.
    pub holds: &'static str,
    /// The machines it describes.
    pub takes: Takes,
    /// True when it writes tables sampled along the axes (a table step and
    /// travel apply, and linear resampling between nodes costs accuracy);
    /// false when it holds constants only.
    pub tables: bool,
    /// The limit its tables must fit in, when the format has one the user
    /// may give.
    pub limit: Option<Limit>,
    /// True when the format writes the axis lines' tilts on request
    /// (`--angles`); the others hold them always or never.
    pub angles: bool,
}

/// The machines a format describes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Takes {
    /// Linear axes only, each moving the tool point along one of X, Y, Z
    /// (each used once), no fixed rotation in the chain; `count`: exactly
    /// that many.
    LinearAxes {
        /// The number of linear axes, when the format needs a given one.
        count: Option<usize>,
        /// The most rotary axes it takes besides (each about one of X, Y,
        /// Z, each used once).
        rotary: usize,
    },
    /// A table-table five-axis machine: three linear axes along X, Y, Z
    /// and two rotary axes carrying the workpiece, the tilting one
    /// carrying the rotary table (`rotary.rs`).
    TableTable,
}

impl Takes {
    /// The machines it takes, in words (for a refusal).
    pub fn words(self) -> String {
        match self {
            Takes::LinearAxes { count, rotary } => {
                let linear = match count {
                    Some(n) => format!("{n} linear axes, one along each of X, Y, Z"),
                    None => "linear axes, each along one of X, Y, Z".to_string(),
                };
                match rotary {
                    0 => linear,
                    r => format!("{linear}, and up to {r} rotary axes, one about each of X, Y, Z"),
                }
            }
            Takes::TableTable => "a table-table five-axis machine (X, Y, Z along the frame's axes; a tilting axis carrying a rotary table, both carrying the workpiece)".to_string(),
        }
    }
}

/// A limit on a format's tables that the export options set.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Limit {
    /// The points of a CEC table ([`ExportOptions::cec_max_points`]).
    CecPoints,
    /// The Beckhoff records ([`ExportOptions::beckhoff_max_records`]).
    BeckhoffRecords,
}

/// How an export samples the axes.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ExportOptions {
    /// The largest table step (mm); the step used divides the travel into
    /// whole intervals.
    pub step: f64,
    /// The travel `[min, max]` (mm) per axis variable, by name; an axis not
    /// listed takes the machine file's `reliability.grid` range.
    pub travel: Vec<(String, [f64; 2])>,
    /// The points a CEC table may have (`MD18342`).
    pub cec_max_points: usize,
    /// The Beckhoff `vol_comp[i].max_records` the records must fit in.
    pub beckhoff_max_records: usize,
    /// The words that open the first comment line of every file written,
    /// naming what wrote it (a command line, say); empty (the default),
    /// that line opens with the machine.
    pub provenance: String,
    /// `heidenhain`: write the rotary axis lines' angle rows (their tilts)
    /// besides the position rows ([`Capabilities::angles`]).
    pub angles: bool,
}

impl Default for ExportOptions {
    fn default() -> ExportOptions {
        ExportOptions {
            step: DEFAULT_STEP,
            travel: Vec::new(),
            cec_max_points: CEC_DEFAULT_MAX_POINTS,
            beckhoff_max_records: BECKHOFF_DEFAULT_MAX_RECORDS,
            provenance: String::new(),
            angles: false,
        }
    }
}

/// Why a machine, its values or the options cannot be exported for a
/// controller.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[cfg_attr(feature = "miette", derive(miette::Diagnostic))]
#[non_exhaustive]
pub enum ControllerError {
    /// A rotary axis, where the format takes linear axes only.
    #[error("`{controller}` takes {takes}, and axis `{variable}` is rotary")]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::export::rotary_axis)))]
    RotaryAxis {
        /// The format.
        controller: &'static str,
        /// The machines it takes, in words ([`Takes::words`]).
        takes: String,
        /// The rotary variable.
        variable: String,
    },
    /// An axis that does not move the tool point along one frame axis.
    #[error("`{controller}` needs every axis along one of X, Y, Z: {reason}")]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::export::axes)))]
    NotAligned {
        /// The format.
        controller: &'static str,
        /// What is not aligned.
        reason: String,
    },
    /// A machine of another kind than the format describes.
    #[error("`{controller}` takes {takes}; machine `{machine}` is not one: {reason}")]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::export::machine_kind)))]
    MachineKind {
        /// The format.
        controller: &'static str,
        /// The machines it takes, in words ([`Takes::words`]).
        takes: String,
        /// The machine.
        machine: String,
        /// Why not.
        reason: String,
    },
    /// Not the number of axes the format takes.
    #[error("`{controller}` takes {takes}; machine `{machine}` has {found} linear axes")]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::export::axis_count)))]
    AxisCount {
        /// The format.
        controller: &'static str,
        /// The machines it takes, in words ([`Takes::words`]).
        takes: String,
        /// The machine.
        machine: String,
        /// Its number of linear axis variables.
        found: usize,
    },
    /// The machine has none of the error terms the format expresses.
    #[error("`{controller}` writes {what}, and machine `{machine}` has none")]
    #[cfg_attr(
        feature = "miette",
        diagnostic(
            code(chain::export::nothing_to_export),
            help("add the error to the machine file (e.g. `errors: iso` on the axis's body, or a `squareness` map) or choose another controller")
        )
    )]
    NothingToExport {
        /// The format.
        controller: &'static str,
        /// What it writes.
        what: &'static str,
        /// The machine.
        machine: String,
    },
    /// No travel for an axis.
    #[error("no travel for axis `{variable}`: the export options give none and the machine file's `reliability.grid` has no values for it")]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::export::no_travel)))]
    NoTravel {
        /// The variable.
        variable: String,
    },
    /// A travel that is not an interval.
    #[error("the travel of axis `{variable}` is {lo} to {hi}: it must be finite with min < max")]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::export::travel)))]
    BadTravel {
        /// The variable.
        variable: String,
        /// Its minimum.
        lo: f64,
        /// Its maximum.
        hi: f64,
    },
    /// A travel given for a name that is not an axis of the machine.
    #[error("`{name}` is not an axis variable of machine `{machine}` (its axes: {axes})")]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::export::unknown_axis)))]
    UnknownAxis {
        /// The name.
        name: String,
        /// The machine.
        machine: String,
        /// Its variables.
        axes: String,
    },
    /// A step that is not a positive finite length.
    #[error("the table step {step} is not a positive finite length (mm)")]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::export::step)))]
    BadStep {
        /// The step.
        step: f64,
    },
    /// More table points than the controller takes.
    #[error("axis `{variable}` over {lo} to {hi} at step {step} mm needs {points} points; {controller} takes at most {limit}{hint}")]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::export::too_many_points)))]
    TooManyPoints {
        /// The format (and its limit's name).
        controller: &'static str,
        /// The axis.
        variable: String,
        /// Its travel.
        lo: f64,
        /// Its travel.
        hi: f64,
        /// The step.
        step: f64,
        /// Points needed.
        points: usize,
        /// The limit.
        limit: usize,
        /// What to do.
        hint: &'static str,
    },
    /// A measured table that does not cover the travel asked.
    #[error("exporting axis `{variable}` over its travel {lo} to {hi}: {source}")]
    #[cfg_attr(
        feature = "miette",
        diagnostic(
            code(chain::export::out_of_table),
            help("give a travel inside the table, or measure the table over the whole travel; nothing is extrapolated")
        )
    )]
    OutOfTable {
        /// The axis being sampled.
        variable: String,
        /// Its travel.
        lo: f64,
        /// Its travel.
        hi: f64,
        /// The table, its range and the value.
        source: Box<OutOfRange>,
    },
    /// Two errors of the machine would take one name of the format.
    #[error("`{controller}`: errors `{first}` and `{second}` of the machine would both be written as `{name}`")]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::export::name_clash)))]
    NameClash {
        /// The format.
        controller: &'static str,
        /// The format's name.
        name: String,
        /// One error.
        first: String,
        /// The other.
        second: String,
    },
    /// A slot of an axis that holds more than one error motion.
    #[error("`{controller}`: slot `{slot}` of axis `{variable}` holds several error motions ({names}); the format has one value per slot")]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::export::shared_slot)))]
    SharedSlot {
        /// The format.
        controller: &'static str,
        /// The axis.
        variable: String,
        /// The slot.
        slot: &'static str,
        /// The motions.
        names: String,
    },
}

/// How one axis was sampled.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AxisSampling {
    /// The axis variable.
    pub variable: String,
    /// The frame axis it moves the tool along (`X`, `Y`, `Z`), or turns it
    /// about (`A`, `B`, `C`: a rotary axis).
    pub axis: char,
    /// First node (mm; degrees for a rotary axis).
    pub min: f64,
    /// Last node (mm; degrees for a rotary axis).
    pub max: f64,
    /// The step used (mm; degrees for a rotary axis).
    pub step: f64,
    /// The number of nodes.
    pub points: usize,
}

/// One error term and its size over the check grid.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Term {
    /// The error parameter or function slot (or a description of a part of
    /// one, such as the non-shear part of the squareness errors).
    pub name: String,
    /// Its largest tool-point position effect `|(px, py, pz)|` (mm).
    pub position: f64,
    /// Its largest orientation effect `|(ox, oy, oz)|` (rad).
    pub orientation: f64,
}

/// What a format expresses, what remains, and how large.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FormatReport {
    /// The format.
    pub controller: Controller,
    /// The machine.
    pub machine: String,
    /// The files written.
    pub files: Vec<String>,
    /// How each axis was sampled.
    pub axes: Vec<AxisSampling>,
    /// The terms the format expresses (their effect, which it removes).
    pub expressed: Vec<Term>,
    /// The terms it leaves, each with its effect.
    pub remaining: Vec<Term>,
    /// The error left at the check grid's nodes, `E(q)` minus what the
    /// format expresses, to first order: its largest position and
    /// orientation norm.
    pub residual: Term,
    /// The largest difference, at the midpoints between table nodes, between
    /// an expressed term and its linear interpolation (what resampling the
    /// values for the controller's linear tables costs; mm, or rad for
    /// angular columns). Zero for Klipper (no table).
    pub resampling: f64,
    /// The check grid (every variable's nodes, machine order): a subset of
    /// the table nodes, at most 11 per axis, where the sizes above are
    /// taken.
    pub check_grid: Vec<(String, Vec<f64>)>,
    /// Per table of a format with a column per approach direction
    /// (LinuxCNC), what its directions hold (serialised only when there
    /// are any).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub directions: Vec<DirectionReport>,
    /// For a format that holds a controller's kinematics (the rotary
    /// formats): the parameters written and the checks of the controller's
    /// own kinematics.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub kinematics: Option<KinematicsReport>,
}

/// What one table's approach-direction columns hold (LinuxCNC's forward and
/// reverse trims; docs/export-controllers.md).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DirectionReport {
    /// The axis variable.
    pub variable: String,
    /// The positioning error the table is made from.
    pub error: String,
    /// True when the two columns come from the values' two approach
    /// directions (a table with a reverse direction); false when both hold
    /// the same values.
    pub bidirectional: bool,
    /// The mean reversal at the tool point along the axis over the table's
    /// nodes, `B̄ = mean(u↑ − u↓)` (mm; ISO 230-2:2014 2.16 with `u` the
    /// positioning error at the tool point): 0 without a reverse direction.
    pub mean_reversal: f64,
    /// LinuxCNC's `[JOINT_n]BACKLASH` that gives the same mean reversal
    /// correction, `−B̄` (LinuxCNC adds `±BACKLASH/2` moving up/down,
    /// `control.c`); LinuxCNC ignores it when a `COMP_FILE` is given.
    pub backlash: f64,
}

/// The result of [`export`]: files, report and the correction the
/// controller applies.
pub struct Export {
    /// The files, named relative to the output folder.
    pub files: Vec<ExportedFile>,
    /// What the format expresses and leaves.
    pub report: FormatReport,
    /// What the controller adds to the commanded axes when it applies the
    /// files (machine variable order).
    pub correction: Box<dyn Correction + Send>,
}

impl std::fmt::Debug for Export {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Export")
            .field("files", &self.files)
            .field("report", &self.report)
            .finish_non_exhaustive()
    }
}

/// Writes `built`'s compensation for `controller` (module docs).
pub fn export<M: ErrorModel + Sync>(
    controller: Controller,
    built: &BuiltMachine<M>,
    machine: &Machine,
    options: &ExportOptions,
) -> Result<Export, ControllerError> {
    let axes = || Context::new(controller, built, machine, options);
    let table_table = || rotary::TableTable::new(controller, built, machine, options);
    match controller {
        Controller::Beckhoff => beckhoff::export(&axes()?),
        Controller::Linuxcnc => linuxcnc::export(&axes()?),
        Controller::SiemensCec => siemens_cec::export(&axes()?),
        Controller::Klipper => klipper::export(&axes()?),
        Controller::LinuxcncTrt => linuxcnc_trt::export(&table_table()?),
        Controller::Heidenhain => heidenhain::export(&table_table()?, options.angles),
        Controller::SiemensCarr => siemens_carr::export(&table_table()?),
        Controller::FanucTcp => fanuc_tcp::export(&table_table()?),
    }
}

// ---------------------------------------------------------------------------
// What the formats share

/// One error motion of a linear axis: the slot it is in and its parts' name.
#[derive(Debug, Clone)]
pub(crate) struct SlotMotion {
    /// `dx..ez` index.
    pub slot: usize,
    /// The part's name (error parameter or function slot).
    pub name: String,
}

/// One linear axis of the machine.
#[derive(Debug, Clone)]
pub(crate) struct LinearAxis {
    /// Machine variable index.
    pub variable: usize,
    /// Its name.
    pub name: String,
    /// The frame axis (0, 1, 2) its Jacobian column lies along.
    pub frame_axis: usize,
    /// The sign of that column (+1: the tool moves along +axis).
    pub sign: f64,
    /// The body whose joint it is.
    pub body: usize,
    /// The joint's own axis in the body's parent frame (0, 1, 2).
    pub joint_axis: usize,
    /// The error motions of the body (squareness excluded), by slot.
    pub motions: Vec<SlotMotion>,
    /// The table nodes.
    pub nodes: Vec<f64>,
    /// The step used.
    pub step: f64,
    /// A rotary axis (`frame_axis` the axis it turns the tool about, the
    /// nodes in radians every [`ROTARY_STEP_DEG`] at most).
    pub rotary: bool,
}

/// The machine's axes, sampled, and its parts at the nodes.
pub(crate) struct Context<'a, M> {
    pub controller: Controller,
    pub built: &'a BuiltMachine<M>,
    pub machine: &'a Machine,
    pub options: &'a ExportOptions,
    pub axes: Vec<LinearAxis>,
    /// Machine variable index → built (model) variable index.
    to_built: Vec<usize>,
    /// The reference point (each axis at its travel's start), machine order.
    pub reference: Vec<f64>,
}

/// Frame axis letters.
pub(crate) const AXIS: [char; 3] = ['X', 'Y', 'Z'];
/// Slot direction letters in ISO 230-1 names (`E<letter><axis>`).
pub(crate) const SLOT_LETTER: [char; 6] = ['X', 'Y', 'Z', 'A', 'B', 'C'];
/// Slot names.
pub(crate) const SLOT_NAME: [&str; 6] = ["dx", "dy", "dz", "ex", "ey", "ez"];

impl<'a, M: ErrorModel + Sync> Context<'a, M> {
    fn new(
        controller: Controller,
        built: &'a BuiltMachine<M>,
        machine: &'a Machine,
        options: &'a ExportOptions,
    ) -> Result<Context<'a, M>, ControllerError> {
        let name = controller.name();
        if !(options.step.is_finite() && options.step > 0.0) {
            return Err(ControllerError::BadStep { step: options.step });
        }
        let takes = controller.capabilities().takes;
        let Takes::LinearAxes { count, rotary } = takes else {
            return Err(ControllerError::MachineKind {
                controller: name,
                takes: takes.words(),
                machine: machine.name.clone(),
                reason: "the format is not one of per-axis tables".to_string(),
            });
        };
        let turning = (machine.variables.iter()).filter(|v| v.kind == JointKind::Rotary);
        if let Some(v) = turning.clone().nth(rotary) {
            return Err(ControllerError::RotaryAxis {
                controller: name,
                takes: takes.words(),
                variable: v.name.clone(),
            });
        }
        let linear = machine.variables.len() - turning.count();
        if count.is_some_and(|n| n != linear) {
            return Err(ControllerError::AxisCount {
                controller: name,
                takes: takes.words(),
                machine: machine.name.clone(),
                found: linear,
            });
        }
        for (n, _) in &options.travel {
            if machine.variable_index(n).is_none() {
                return Err(ControllerError::UnknownAxis {
                    name: n.clone(),
                    machine: machine.name.clone(),
                    axes: machine
                        .variables
                        .iter()
                        .map(|v| v.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", "),
                });
            }
        }
        if let Some(b) = machine.bodies.iter().find(|b| !b.rotation.is_empty()) {
            return Err(ControllerError::NotAligned {
                controller: name,
                reason: format!("body `{}` has a fixed rotation", b.name),
            });
        }
        let to_built = built_order(machine, built);
        let travels = travels(machine, options)?;
        let reference: Vec<f64> = travels.iter().map(|t| t.0).collect();
        // The nominal Jacobian at the reference point, the rotary axes at
        // their zero (where the linear axes are along X, Y, Z).
        let kin = Kinematics::from_machine(machine);
        let p = crate::compensation::kinematics_parameters(&kin, built);
        let at: Vec<f64> = (machine.variables.iter().zip(&reference))
            .map(|(v, &r)| if v.kind == JointKind::Rotary { 0.0 } else { r })
            .collect();
        let jac = kin.jacobian(&at, &p);
        let rot = kin.pose(&at, &p).rotation;
        // Per kind (linear, rotary), the frame axes taken.
        let mut used = [[false; 3]; 2];
        let mut axes = Vec::new();
        for (i, v) in machine.variables.iter().enumerate() {
            let turns = v.kind == JointKind::Rotary;
            let from = if turns { 3 } else { 0 };
            let mut col = [jac[i][from], jac[i][from + 1], jac[i][from + 2]];
            if machine.frame == crate::model::Frame::Tool {
                col = std::array::from_fn(|r| (0..3).map(|c| rot[c][r] * col[c]).sum());
            }
            let used = &mut used[usize::from(turns)];
            let aligned = along_one_axis(col).filter(|&(k, _)| !used[k]);
            let Some((k, sign)) = aligned else {
                let (moves, unit) = match turns {
                    false => ("moves the tool point along", "mm"),
                    true => ("turns the tool about", "rad"),
                };
                return Err(ControllerError::NotAligned {
                    controller: name,
                    reason: format!(
                        "axis `{}` {moves} ({:.6}, {:.6}, {:.6}) per {unit}",
                        v.name, col[0], col[1], col[2]
                    ),
                });
            };
            used[k] = true;
            let body = v.body;
            let joint = machine.bodies[body]
                .joint
                .as_ref()
                .map(|j| j.axis.axis.index());
            let mut motions: Vec<SlotMotion> = Vec::new();
            for (s, slot) in machine.bodies[body].errors.slots.iter().enumerate() {
                let mut names = slot_motions(machine, slot);
                if names.len() > 1 {
                    return Err(ControllerError::SharedSlot {
                        controller: name,
                        variable: v.name.clone(),
                        slot: SLOT_NAME[s],
                        names: names.join(", "),
                    });
                }
                if let Some(n) = names.pop() {
                    motions.push(SlotMotion { slot: s, name: n });
                }
            }
            let (lo, hi) = travels[i];
            let largest = match turns {
                false => options.step,
                true => ROTARY_STEP_DEG.to_radians(),
            };
            let intervals = ((hi - lo) / largest - 1e-9).ceil().max(1.0) as usize;
            let step = (hi - lo) / intervals as f64;
            let nodes = (0..=intervals)
                .map(|k| {
                    if k == intervals {
                        hi
                    } else {
                        lo + k as f64 * step
                    }
                })
                .collect();
            axes.push(LinearAxis {
                variable: i,
                name: v.name.clone(),
                frame_axis: k,
                sign,
                body,
                joint_axis: joint.unwrap_or(k),
                motions,
                nodes,
                step,
                rotary: turns,
            });
        }
        Ok(Context {
            controller,
            built,
            machine,
            options,
            axes,
            to_built,
            reference,
        })
    }

    /// The format's name.
    pub fn name(&self) -> &'static str {
        self.controller.name()
    }

    /// Machine-ordered `q` in the built model's variable order.
    pub fn built_q(&self, q: &[f64]) -> Vec<f64> {
        in_built_order(&self.to_built, q)
    }

    /// The built machine's parts at machine-ordered `q`, by name.
    pub fn parts(&self, q: &[f64]) -> Result<Vec<crate::built::Part>, OutOfRange> {
        self.built.parts(&self.built_q(q))
    }

    /// The derived coefficient `c_j(q)` (6 components) of the model's error
    /// named `name` at machine-ordered `q`.
    pub fn coefficient(&self, name: &str, q: &[f64]) -> [f64; 6] {
        let model = self.built.model();
        let n = model.errors().len();
        let mut s = vec![0.0; 6 * n];
        model.sensitivity(&self.built_q(q), self.built.parameters(), &mut s);
        match model.errors().iter().position(|e| *e == name) {
            Some(j) => std::array::from_fn(|c| s[c * n + j]),
            None => [0.0; 6],
        }
    }

    /// The parts at each node of `axis` (the other axes at the reference
    /// point): `[node][part]`, a node outside a table refused.
    pub fn along(
        &self,
        axis: &LinearAxis,
    ) -> Result<Vec<Vec<crate::built::Part>>, ControllerError> {
        self.along_with(axis, self.built.values())
    }

    /// [`Context::along`] with other values for the built machine's model
    /// (another approach direction).
    pub fn along_with(
        &self,
        axis: &LinearAxis,
        values: &Values,
    ) -> Result<Vec<Vec<crate::built::Part>>, ControllerError> {
        self.sample(axis, values, axis.nodes.clone())
    }

    /// The parts at the midpoints between the nodes of `axis`.
    pub fn midpoints(
        &self,
        axis: &LinearAxis,
    ) -> Result<Vec<Vec<crate::built::Part>>, ControllerError> {
        self.midpoints_with(axis, self.built.values())
    }

    /// [`Context::midpoints`] with other values.
    pub fn midpoints_with(
        &self,
        axis: &LinearAxis,
        values: &Values,
    ) -> Result<Vec<Vec<crate::built::Part>>, ControllerError> {
        let mids = axis.nodes.windows(2).map(|w| 0.5 * (w[0] + w[1])).collect();
        self.sample(axis, values, mids)
    }

    /// The parts at each of `xs` along `axis` (the others at the reference).
    fn sample(
        &self,
        axis: &LinearAxis,
        values: &Values,
        xs: Vec<f64>,
    ) -> Result<Vec<Vec<crate::built::Part>>, ControllerError> {
        let mut q = self.reference.clone();
        xs.into_iter()
            .map(|x| {
                q[axis.variable] = x;
                (self.built.parts_with(&self.built_q(&q), values))
                    .map_err(|e| self.out_of_table(axis, e))
            })
            .collect()
    }

    /// The built model's index of machine variable `v`.
    pub fn built_variable(&self, v: usize) -> usize {
        self.to_built[v]
    }

    fn out_of_table(&self, axis: &LinearAxis, e: OutOfRange) -> ControllerError {
        ControllerError::OutOfTable {
            variable: axis.name.clone(),
            lo: axis.nodes[0],
            hi: axis.nodes[axis.nodes.len() - 1],
            source: Box::new(e),
        }
    }

    /// The axis moving along frame axis `k`.
    pub fn axis_along(&self, k: usize) -> Option<&LinearAxis> {
        self.axes.iter().find(|a| a.frame_axis == k)
    }

    /// The sampling of each axis, for the report.
    pub fn sampling(&self) -> Vec<AxisSampling> {
        self.axes
            .iter()
            .map(|a| {
                let (letter, unit) = match a.rotary {
                    false => (AXIS[a.frame_axis], 1.0),
                    true => (['A', 'B', 'C'][a.frame_axis], 180.0 / std::f64::consts::PI),
                };
                AxisSampling {
                    variable: a.name.clone(),
                    axis: letter,
                    min: a.nodes[0] * unit,
                    max: a.nodes[a.nodes.len() - 1] * unit,
                    step: a.step * unit,
                    points: a.nodes.len(),
                }
            })
            .collect()
    }

    /// The check grid: every `m`-th node of each axis (and its last), at
    /// most 11 per axis.
    pub fn check_grid(&self) -> Vec<(String, Vec<f64>)> {
        self.axes
            .iter()
            .map(|a| {
                let k = a.nodes.len() - 1;
                let m = k.div_ceil(10).max(1);
                let mut g: Vec<f64> = (0..=k).step_by(m).map(|i| a.nodes[i]).collect();
                if (k % m) != 0 {
                    g.push(a.nodes[k]);
                }
                (a.name.clone(), g)
            })
            .collect()
    }

    /// The report's terms and residual over the check grid. `expressed(q,
    /// parts)` gives, per part, the share of its error the format removes
    /// (`None`: none of it) as a 6-vector; the residual is `E(q)` minus
    /// their sum, plus `extra(q)` (a share the format removes that is not
    /// one part's, such as Klipper's shear, negative).
    #[allow(clippy::type_complexity, clippy::needless_range_loop)]
    pub fn account(
        &self,
        expressed: &dyn Fn(&[f64], &crate::built::Part) -> Option<[f64; 6]>,
        whole: &dyn Fn(&[f64], &[crate::built::Part]) -> Option<(String, [f64; 6])>,
    ) -> Result<Accounting, ControllerError> {
        let grid = self.check_grid();
        let total: usize = grid.iter().map(|g| g.1.len()).product();
        let mut expr_terms: Vec<Term> = Vec::new();
        let mut rem_terms: Vec<Term> = Vec::new();
        let mut residual = Term {
            name: "residual".into(),
            position: 0.0,
            orientation: 0.0,
        };
        let bump = |terms: &mut Vec<Term>, name: &str, e: &[f64; 6]| {
            let p = (e[0] * e[0] + e[1] * e[1] + e[2] * e[2]).sqrt();
            let o = (e[3] * e[3] + e[4] * e[4] + e[5] * e[5]).sqrt();
            match terms.iter_mut().find(|t| t.name == name) {
                Some(t) => {
                    t.position = t.position.max(p);
                    t.orientation = t.orientation.max(o);
                }
                None => terms.push(Term {
                    name: name.to_string(),
                    position: p,
                    orientation: o,
                }),
            }
        };
        let mut q = self.reference.clone();
        for idx in 0..total {
            let mut r = idx;
            for (a, (_, g)) in self.axes.iter().zip(&grid).rev() {
                q[a.variable] = g[r % g.len()];
                r /= g.len();
            }
            let parts = self.parts(&q).map_err(|e| {
                let a = &self.axes[self.machine.variable_index(&e.variable).unwrap_or(0)];
                self.out_of_table(a, e)
            })?;
            let mut left = [0.0; 6];
            for part in &parts {
                let share = expressed(&q, part);
                let mut rest = part.error;
                if let Some(s) = share {
                    bump(&mut expr_terms, &part.name, &s);
                    for c in 0..6 {
                        rest[c] -= s[c];
                    }
                }
                if rest.iter().any(|v| *v != 0.0) || share.is_none() {
                    let label = if share.is_some() {
                        format!("{} (the part the format cannot express)", part.name)
                    } else {
                        part.name.clone()
                    };
                    bump(&mut rem_terms, &label, &rest);
                }
                for c in 0..6 {
                    left[c] += rest[c];
                }
            }
            if let Some((label, extra)) = whole(&q, &parts) {
                bump(&mut expr_terms, &label, &extra);
                for c in 0..6 {
                    left[c] -= extra[c];
                }
            }
            let p = (left[0] * left[0] + left[1] * left[1] + left[2] * left[2]).sqrt();
            let o = (left[3] * left[3] + left[4] * left[4] + left[5] * left[5]).sqrt();
            residual.position = residual.position.max(p);
            residual.orientation = residual.orientation.max(o);
        }
        rem_terms.retain(|t| t.position > 0.0 || t.orientation > 0.0);
        Ok(Accounting {
            expressed: expr_terms,
            remaining: rem_terms,
            residual,
            check_grid: grid,
        })
    }

    /// The [`Export`] of `files`, with the report of `accounting` and
    /// `resampling`, and the controller's `correction`.
    pub fn finish(
        &self,
        files: Vec<ExportedFile>,
        accounting: Accounting,
        resampling: f64,
        correction: Box<dyn Correction + Send>,
    ) -> Export {
        Export {
            report: FormatReport {
                controller: self.controller,
                machine: self.machine.name.clone(),
                files: files.iter().map(|f| f.name.clone()).collect(),
                axes: self.sampling(),
                expressed: accounting.expressed,
                remaining: accounting.remaining,
                residual: accounting.residual,
                resampling,
                check_grid: accounting.check_grid,
                directions: Vec::new(),
                kinematics: None,
            },
            files,
            correction,
        }
    }
}

/// Each variable's travel `(min, max)`, machine order: the options' or the
/// machine file's `reliability.grid` range; refused when neither gives one
/// or it is not an interval.
pub(crate) fn travels(
    machine: &Machine,
    options: &ExportOptions,
) -> Result<Vec<(f64, f64)>, ControllerError> {
    let mut travels = Vec::new();
    for (i, v) in machine.variables.iter().enumerate() {
        let given = options.travel.iter().find(|(n, _)| *n == v.name);
        let (lo, hi) = match given {
            Some((_, [lo, hi])) => (*lo, *hi),
            None => {
                let grid = machine
                    .reliability
                    .as_ref()
                    .and_then(|r| r.grid.iter().find(|(k, _)| *k == i))
                    .map(|(_, g)| g);
                match grid {
                    Some(g) if !g.is_empty() => (
                        g.iter().copied().fold(f64::INFINITY, f64::min),
                        g.iter().copied().fold(f64::NEG_INFINITY, f64::max),
                    ),
                    _ => {
                        return Err(ControllerError::NoTravel {
                            variable: v.name.clone(),
                        })
                    }
                }
            }
        };
        if !(lo.is_finite() && hi.is_finite() && lo < hi) {
            return Err(ControllerError::BadTravel {
                variable: v.name.clone(),
                lo,
                hi,
            });
        }
        travels.push((lo, hi));
    }
    Ok(travels)
}

/// Machine variable index → the built model's index of the same name
/// (`usize::MAX` for one the model lacks).
pub(crate) fn built_order<M: ErrorModel>(machine: &Machine, built: &BuiltMachine<M>) -> Vec<usize> {
    (machine.variables.iter())
        .map(|v| {
            (built.variables().iter())
                .position(|b| *b == v.name)
                .unwrap_or(usize::MAX)
        })
        .collect()
}

/// Machine-ordered `q` in the built model's order ([`built_order`]).
pub(crate) fn in_built_order(to_built: &[usize], q: &[f64]) -> Vec<f64> {
    let mut qb = vec![0.0; q.len()];
    for (i, &b) in to_built.iter().enumerate() {
        if let Some(x) = qb.get_mut(b) {
            *x = q[i];
        }
    }
    qb
}

/// The frame axis (0, 1, 2) and sign of a tool-point column that moves
/// the tool point along one axis by exactly its own length (to 1e-9), else
/// `None`: an axis a per-axis table or a controller's joint can stand for.
pub(crate) fn along_one_axis(col: [f64; 3]) -> Option<(usize, f64)> {
    let k = (0..3)
        .max_by(|&a, &b| col[a].abs().total_cmp(&col[b].abs()))
        .unwrap_or(0);
    let off: f64 = (0..3).filter(|&c| c != k).map(|c| col[c].abs()).sum();
    ((col[k].abs() - 1.0).abs() <= 1e-9 && off <= 1e-9).then(|| (k, col[k].signum()))
}

/// The error motions of an error slot (its error parameters, a function
/// slot's coefficients by the function's name), each once, squareness left
/// out.
pub(crate) fn slot_motions(machine: &Machine, slot: &[usize]) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    for &j in slot {
        if machine.errors[j].kind == ErrorKind::Squareness {
            continue;
        }
        let n = match machine.coefficient_of(j) {
            Some((f, _)) => f.name.clone(),
            None => machine.errors[j].name.clone(),
        };
        if !names.contains(&n) {
            names.push(n);
        }
    }
    names
}

/// What [`Context::account`] finds over the check grid.
pub(crate) struct Accounting {
    /// The terms the format expresses.
    pub expressed: Vec<Term>,
    /// The terms it leaves.
    pub remaining: Vec<Term>,
    /// The error left.
    pub residual: Term,
    /// The check grid.
    pub check_grid: Vec<(String, Vec<f64>)>,
}

/// The share a per-slot table removes from a part: the one slot `k` of
/// the part's error where `exported` lists the part as `(name, k)`
/// (LinuxCNC's positioning errors, CEC's straightness errors).
pub(crate) fn slot_share(
    exported: &[(String, usize)],
    part: &crate::built::Part,
) -> Option<[f64; 6]> {
    let (_, k) = exported.iter().find(|(n, _)| *n == part.name)?;
    let mut s = [0.0; 6];
    s[*k] = part.error[*k];
    Some(s)
}

/// `v` linearly interpolated in the equidistant table `values` over
/// `[min, min + step·(n−1)]`, holding the end values outside (LinuxCNC,
/// CEC).
pub(crate) fn interpolate_held(nodes: &[f64], values: &[f64], x: f64) -> f64 {
    let n = nodes.len();
    if x.is_nan() {
        return f64::NAN;
    }
    if x <= nodes[0] {
        return values[0];
    }
    if x >= nodes[n - 1] {
        return values[n - 1];
    }
    let k = nodes.partition_point(|&t| t <= x).clamp(1, n - 1);
    let (x0, x1) = (nodes[k - 1], nodes[k]);
    values[k - 1] + (values[k] - values[k - 1]) * (x - x0) / (x1 - x0)
}

/// A number in a file: the shortest text that reads back as the same `f64`.
/// `v` with at most `places` decimals, trailing zeros dropped (`-0` is
/// `0`): a value written at a format's resolution.
pub(crate) fn decimals(v: f64, places: usize) -> String {
    let s = format!("{v:.places$}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        s.as_str()
    };
    if s == "-0" {
        "0".into()
    } else {
        s.to_string()
    }
}

pub(crate) fn num(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else {
        format!("{v}")
    }
}

/// `e`'s translation part as a vector.
pub(crate) fn translation(e: &[f64; 6]) -> [f64; 6] {
    [e[0], e[1], e[2], 0.0, 0.0, 0.0]
}
