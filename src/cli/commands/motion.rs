//! `chain motion FILE --settings SETTINGS.yaml [--order N] [--tolerance TOL]
//! [--samples K] [--format table|json|csv] [--plot DIR]`.
//!
//! The motion conversion of the five-axis jewelry machining paper (2022):
//! the CNC axis motions of `FILE` that
//! reproduce, at every instant of the roll, the tool pose of the generator
//! described by the settings file (`docs/motion.md`), checked instant by
//! instant, and their Maclaurin expansion at `t = 0` with its truncation error
//! over the roll and the order a tolerance needs.

use std::path::PathBuf;

use chain::ops::motion::{self, MotionRequest};
use chain::ops::source::{self, Source};

use crate::cli::args::{parse_assignment, parse_param};
use crate::cli::{plot, report};

/// Output formats of `chain motion`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum MotionFormat {
    /// Settings, coefficients, truncation errors and the required order.
    Table,
    /// One JSON document (docs/motion.md).
    Json,
    /// The exact motion: header `t,<CNC variables>`, one line per instant
    /// (feeds `chain path FILE --axes motion.csv`).
    Csv,
}

/// Arguments of `chain motion`.
///
/// Converts the roll of a generating machine (by default the cradle-type
/// generator of "Precision Machining Technology of Jewelry on CNC Machine
/// Tool", 2022) into the motions of the CNC machine FILE, so that both
/// give the same tool pose relative to the workpiece at every instant, and
/// expands every axis motion in its Maclaurin series.
#[derive(Debug, clap::Args)]
pub struct MotionArgs {
    /// The CNC machine file (YAML).
    pub file: PathBuf,
    /// The machine settings and the roll (docs/motion.md).
    #[arg(long, value_name = "SETTINGS.yaml")]
    pub settings: PathBuf,
    /// Order n of the Maclaurin series.
    #[arg(long, default_value_t = 8, value_name = "N")]
    pub order: usize,
    /// Accuracy wanted of the series over the roll interval, in model units
    /// (mm for linear axes; also rad for rotary ones unless
    /// --angular-tolerance is given): reports the smallest order that meets it.
    #[arg(long, value_name = "TOL")]
    pub tolerance: Option<f64>,
    /// Accuracy wanted of the rotary axes (rad); default --tolerance.
    #[arg(long, value_name = "RAD")]
    pub angular_tolerance: Option<f64>,
    /// Highest order searched for --tolerance.
    #[arg(long, default_value_t = 40, value_name = "N")]
    pub max_order: usize,
    /// Instants, evenly spaced over the roll interval (both ends included).
    #[arg(long, default_value_t = 1000, value_name = "K")]
    pub samples: usize,
    /// Output format.
    #[arg(long, value_enum, default_value = "table")]
    pub format: MotionFormat,
    /// Write the axis motions and the truncation error against the order
    /// (PNG and SVG) into DIR.
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
    /// Value of a CNC machine parameter, `NAME=VALUE` (repeatable; overrides
    /// the settings file's `cnc.parameters`).
    #[arg(long = "param", value_name = "NAME=VALUE", value_parser = parse_param)]
    pub params: Vec<(String, f64)>,
    /// Hold a CNC variable, `NAME=VALUE` (repeatable): matches the tool point
    /// and axis only (`match: point_axis`), as in face milling with `mu=0`.
    #[arg(long = "fix", value_name = "NAME=VALUE", value_parser = parse_assignment)]
    pub fix: Vec<(String, f64)>,
}

/// Runs `chain motion` ([`chain::ops::motion`]).
pub fn exec(args: MotionArgs) -> miette::Result<()> {
    let request = MotionRequest {
        order: args.order,
        max_order: args.max_order,
        samples: args.samples,
        tolerance: args.tolerance,
        angular_tolerance: args.angular_tolerance,
        params: &args.params,
        fix: &args.fix,
    };
    motion::check(&request)?;
    let settings = source::read_settings(Source::Path(&args.settings))?;
    let cnc = chain_core::load_file(&args.file)?;
    let mut doc = motion::run(&cnc, settings, &request)?;
    if let Some(dir) = &args.plot {
        doc.written = plot::write(dir, &chain::plot::motion::charts(&doc))?
            .iter()
            .map(|p| p.display().to_string())
            .collect();
    }
    if args.format == MotionFormat::Csv {
        // The CSV is the motion alone: the files go to stderr.
        for f in &doc.written {
            eprintln!("wrote {f}");
        }
    }
    report::emit(&doc, args.format.into())
}

report::formats!(MotionFormat: Table, Json, Csv);
