//! The `chain` binary's adapter over [`chain::ops`]: the subcommands in
//! `commands/` (one file each, clap arguments → a request → `ops` → the
//! document to `report::emit`; no command imports another), the shared
//! argument groups in `args.rs`, the table and CSV forms of the documents in
//! `render/`, the charts of `chain::plot` written by `plot.rs`.

mod args;
mod atomic;
mod commands;
mod csv_input;
mod loaded;
pub mod plot;
mod progress;
mod render;
pub mod report;
mod study_text;

use commands::{
    allocate, circular, compensate, derive, export, identify, inverse, map, motion, path, plan,
    positioning, reliability, sensitivity, sobol, thermal,
};

use clap::{Parser, Subcommand};

/// Geometric-error models, machining-accuracy reliability and precision
/// allocation for machine tools.
#[derive(Debug, Parser)]
#[command(name = "chain", version, about)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Derive the exact first-order error model of a machine file.
    Derive(derive::DeriveArgs),
    /// Machining-accuracy reliability over the workspace grid (FORM, importance sampling, Monte Carlo; Wang & Yuan 2021).
    Reliability(reliability::ReliabilityArgs),
    /// Reliability sensitivity (default) or geometric sensitivity coefficients (`--kind geometric`, Fan et al. 2020).
    Sensitivity(sensitivity::SensitivityArgs),
    /// Global sensitivity: first-order and total Sobol indices (Saltelli 2010, Jansen) of each toleranced component and of |p|, with bootstrap intervals, at a point or pooled over the grid.
    Sobol(sobol::SobolArgs),
    /// Precision allocation: Wang & Yuan 2021's tightening or the least-cost tolerances.
    Allocate(allocate::AllocateArgs),
    /// Identify and compensate a swing-angle error from tool-tip heights (Xiao et al. 2020).
    Compensate(compensate::CompensateArgs),
    /// Inverse kinematics: every axis solution of tool poses (point and axis) from a CSV.
    Inverse(inverse::InverseArgs),
    /// Error and reliability along a path (axis values or tool poses) at every instant.
    Path(path::PathArgs),
    /// The volumetric error map of a built machine: its error values (a values file) through the model over a grid or a list of points.
    Map(map::MapArgs),
    /// Identify the error parameters from measurements (tool-point deviations or deviations along directions): weighted least squares through an SVD, what the data cannot separate, residuals and outliers.
    Identify(identify::IdentifyArgs),
    /// Where to measure: the D-optimal K of a set of candidate poses, against K taken evenly (greedy + Fedorov exchange).
    Plan(plan::PlanArgs),
    /// Compensation for a controller: the axis corrections that cancel a built machine's error (the universal grid CSV; controller formats), with the residual they leave.
    Export(export::ExportArgs),
    /// ISO 230-2 positioning: the statistics of an axis's bidirectional positioning runs (mean deviation per direction, reversal, repeatability, accuracy).
    Positioning(positioning::PositioningArgs),
    /// ISO 230-3 thermal drift: the drift of each displacement channel, the temperatures, sensor-pair tilts, and with --fit a thermal model per channel from the temperature sensors (and lagged loads) with its held-out prediction.
    Thermal(thermal::ThermalArgs),
    /// ISO 230-4 circular test (ballbar): per run and direction the circular deviation G, the radial deviations F_max and F_min about the least-squares centre, and with both directions G(b) and the hysteresis H.
    Circular(circular::CircularArgs),
    /// The calibration report a lab hands over: one self-contained HTML page (positioning per axis against tolerances, the volumetric map before and after compensation, the identification and its held-out prediction, the controller's files, a circular test, the inputs' checksums) from a calibration file.
    Report(commands::report::ReportArgs),
    /// Motion conversion ("Precision Machining Technology of Jewelry on CNC Machine Tool", 2022): CNC axis motions reproducing a cradle-type generator's roll, and their Maclaurin series.
    Motion(motion::MotionArgs),
}

/// Runs the parsed command line.
pub fn run(cli: Cli) -> miette::Result<()> {
    match cli.command {
        Command::Derive(args) => derive::exec(args),
        Command::Reliability(args) => reliability::exec(args),
        Command::Sensitivity(args) => sensitivity::exec(args),
        Command::Sobol(args) => sobol::exec(args),
        Command::Allocate(args) => allocate::exec(args),
        Command::Compensate(args) => compensate::exec(args),
        Command::Inverse(args) => inverse::exec(args),
        Command::Path(args) => path::exec(args),
        Command::Motion(args) => motion::exec(args),
        Command::Map(args) => map::exec(args),
        Command::Identify(args) => identify::exec(args),
        Command::Plan(args) => plan::exec(args),
        Command::Export(args) => export::exec(args),
        Command::Positioning(args) => positioning::exec(args),
        Command::Thermal(args) => thermal::exec(args),
        Command::Circular(args) => circular::exec(args),
        Command::Report(args) => commands::report::exec(args),
    }
}
