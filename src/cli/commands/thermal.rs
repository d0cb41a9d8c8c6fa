//! `chain thermal RUN.csv [--pair X1:X2=L]... [--fit [--sensors K] [--lag]
//! [--holdout F | --fit-until S]] [--format table|json|csv] [--plot DIR]`:
//! an ISO 230-3 thermal drift test and the thermal model of each
//! displacement channel (`../shared/spec/thermal.md`, `docs/thermal.md`),
//! through [`chain::ops::thermal`].

use std::path::PathBuf;

use chain::ops::source::{self, Source};
use chain::ops::thermal as ops;
use chain_core::measured::thermal::{Pair, Roles};
use chain_core::measured::thermal_fit::{FitOptions, Split, DEFAULT_SENSORS};

use crate::cli::loaded::Loaded;
use crate::cli::{plot, report};

/// Output formats of `chain thermal`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ThermalFormat {
    /// The drift per channel, the temperatures, the pairs and the models.
    Table,
    /// The document of the thermal spec.
    Json,
    /// `time,channel,measured,predicted` for every sample and channel
    /// (with --fit).
    Csv,
}

report::formats!(ThermalFormat: Table, Json, Csv);

/// Arguments of `chain thermal`.
#[derive(Debug, clap::Args)]
pub struct ThermalArgs {
    /// The drift-test file (CSV): `time` (s), displacement channels (a
    /// header ending in `(um)`, `(µm)` or `(mm)`), temperatures (`(°C)`,
    /// `(degC)` or `(C)`), loads (any other column).
    pub run: PathBuf,
    /// Columns that are displacement channels (headers without a unit;
    /// comma-separated or repeated).
    #[arg(long, value_name = "NAMES", value_delimiter = ',')]
    pub displacements: Vec<String>,
    /// Columns that are temperature sensors (°C).
    #[arg(long, value_name = "NAMES", value_delimiter = ',')]
    pub temperatures: Vec<String>,
    /// Columns that are loads (spindle speed, feed, ...).
    #[arg(long, value_name = "NAMES", value_delimiter = ',')]
    pub loads: Vec<String>,
    /// Two displacement sensors in one direction `L` mm apart on the test
    /// mandrel, the first nearer the spindle nose: their tilt (X1 − X2)/L
    /// (repeatable).
    #[arg(long = "pair", value_name = "X1:X2=L", value_parser = pair)]
    pub pairs: Vec<Pair>,
    /// Fit a thermal model per displacement channel (docs/thermal.md).
    #[arg(long)]
    pub fit: bool,
    /// The most temperature sensors a channel's model uses.
    #[arg(long, value_name = "K", requires = "fit")]
    pub sensors: Option<usize>,
    /// Consider first-order lag responses to each load, their time
    /// constants chosen from the data.
    #[arg(long, requires = "fit")]
    pub lag: bool,
    /// Fit on the first (1 − F) of the test's duration and predict the
    /// rest.
    #[arg(long, value_name = "F", requires = "fit", conflicts_with = "fit_until")]
    pub holdout: Option<f64>,
    /// Fit on the samples before SECONDS and predict those at or after it.
    #[arg(long, value_name = "SECONDS", requires = "fit")]
    pub fit_until: Option<f64>,
    /// Output format.
    #[arg(long, value_enum, default_value = "table")]
    pub format: ThermalFormat,
    /// Write the channels and temperatures against time (and the models'
    /// predictions) into DIR as PNG and SVG.
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
    /// Write the fitted models as the thermal coefficients of a machine's
    /// thermal terms, a values file that `chain map --temperature` reads
    /// (with --fit, --machine and --slot).
    #[arg(long, value_name = "VALUES.yaml", requires_all = ["machine", "slots"])]
    pub values_out: Option<PathBuf>,
    /// The machine file whose thermal terms take the models.
    #[arg(long, value_name = "MACHINE.yaml", requires = "values_out")]
    pub machine: Option<PathBuf>,
    /// Which channel's model a thermal term `{name, per}` of the machine
    /// takes: `NAME=CHANNEL` (comma-separated or repeated).
    #[arg(
        long = "slot",
        value_name = "NAME=CHANNEL",
        value_delimiter = ',',
        value_parser = slot,
        requires = "values_out"
    )]
    pub slots: Vec<(String, String)>,
}

/// `--slot`: `NAME=CHANNEL`.
fn slot(text: &str) -> Result<(String, String), String> {
    ops::parse_slot(text).map_err(|e| e.to_string())
}

/// `--pair`: `X1:X2=L`.
fn pair(text: &str) -> Result<Pair, String> {
    ops::parse_pair(text).map_err(|e| e.to_string())
}

/// Runs `chain thermal` ([`chain::ops::thermal`]).
pub fn exec(args: ThermalArgs) -> miette::Result<()> {
    let roles = Roles {
        displacements: args.displacements.clone(),
        temperatures: args.temperatures.clone(),
        loads: args.loads.clone(),
    };
    let test = source::read_drift(Source::Path(&args.run), &roles)?;
    let split = match (args.holdout, args.fit_until) {
        (Some(f), _) => Split::Holdout(f),
        (None, Some(t)) => Split::Until(t),
        (None, None) => Split::None,
    };
    let fit = args.fit.then(|| FitOptions {
        sensors: args.sensors.unwrap_or(DEFAULT_SENSORS),
        lag: args.lag,
        split,
    });
    if fit.is_none() && args.format == ThermalFormat::Csv {
        return Err(miette::miette!(
            code = "chain::thermal::csv",
            help = "the CSV holds the measured and the predicted drift of every sample",
            "--format csv writes the fit's predictions: give --fit"
        ));
    }
    let loaded = match &args.machine {
        Some(path) => Some(Loaded::new(path)?),
        None => None,
    };
    let into_machine = loaded.as_ref().map(|l| ops::IntoMachine {
        machine: &l.machine,
        slots: &args.slots,
    });
    let done = ops::run(&ops::ThermalRequest {
        test: &test,
        pairs: &args.pairs,
        fit,
        into_machine,
    })?;
    if let (Some(path), Some(values)) = (&args.values_out, &done.values) {
        crate::cli::atomic::write(path, values.text.as_bytes())
            .map_err(|e| miette::miette!("cannot write {}: {e}", path.display()))?;
        eprintln!("wrote {}", path.display());
    }
    if let Some(dir) = &args.plot {
        for f in plot::write(dir, &chain::plot::thermal::charts(&test, &done))? {
            eprintln!("wrote {}", f.display());
        }
    }
    report::emit(&done, args.format.into())
}
