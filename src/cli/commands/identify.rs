//! `chain identify FILE (--measurements M.csv [--setup ball] | --spheres S.csv
//! | --circular RUNS.csv (--centre NAME=VALUE,... | --axes) [--radius R] [--feed F]
//! [--plane P] [--arc DEG])
//! [--prior] [--validate M2.csv]
//! [--holdout FRACTION [--seed S]] [--rank-tol TOL]
//! [--fix NAME,... | --estimate NAME,...] [--iterate]
//! [--param NAME=VALUE]... [--format table|json] [--values-out VALUES.yaml]`.
//!
//! The error parameters of a built machine from measurements
//! (measured-machines spec, section 4) through
//! [`chain::ops::identify`]: the measurement CSV read against the
//! machine ([`chain_core::measured::Measurements`]), the exact sensitivity
//! rows as the design matrix, weighted least squares through an SVD (or the
//! posterior of the `statistics` prior). See `docs/identify.md`.

use std::path::PathBuf;

use chain::ops::identify::{CircleRequest, IdentifyRequest};
use chain::ops::source::Source;
use chain_core::measured::SetupKind;

use crate::cli::args::{ParamArgs, RunFileArgs, ThermalArgs};
use crate::cli::loaded::Loaded;
use crate::cli::report;

/// Output formats of `chain identify`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum IdentifyFormat {
    /// Estimates, what the data cannot separate (in words), residuals.
    Table,
    /// The spec's JSON document.
    Json,
}

report::formats!(IdentifyFormat: Table, Json);

/// Arguments of `chain identify`.
#[derive(Debug, clap::Args)]
pub struct IdentifyArgs {
    /// Machine file (YAML).
    pub file: PathBuf,
    /// The measurement CSV: the axis variables (the pose; rotary in
    /// radians), any parameters per row, `dpx,dpy,dpz` or `ux,uy,uz,d`,
    /// optionally `std`.
    #[arg(long, value_name = "M.csv")]
    pub measurements: Option<PathBuf>,
    /// A sphere-probing CSV instead of measurements: every axis variable
    /// (rotary ones in degrees) at which the probe centre sits at the
    /// sphere centre, optionally `sphere` and `std`; each sphere's position
    /// on the table is estimated beside the errors.
    #[arg(long, value_name = "S.csv")]
    pub spheres: Option<PathBuf>,
    /// A circular-test file (a ballbar's runs, `chain circular`'s) instead
    /// of measurements: each sample a measurement along the nominal
    /// ball-to-ball direction, each run's table-ball offset and bar length
    /// estimated beside the errors; with --centre or --axes.
    #[arg(long, value_name = "RUNS.csv")]
    pub circular: Option<PathBuf>,
    /// The circle's centre as the machine's variables, NAME=VALUE
    /// (comma-separated; rotary ones in degrees, every other at 0): a
    /// sample at angle θ moves the variables named after the plane's axes
    /// by R cos θ, R sin θ.
    #[arg(long, value_name = "NAME=VALUE", value_delimiter = ',', value_parser = crate::cli::args::parse_param)]
    pub centre: Option<Vec<(String, f64)>>,
    /// Read each sample's pose of --circular from the run file's columns
    /// named after the machine's variables (rotary ones in degrees): any
    /// path, e.g. a rotary axis interpolating with a linear one.
    #[arg(long)]
    pub axes: bool,
    #[command(flatten)]
    pub run: RunFileArgs,
    /// `ball`: an R-test: the measurement records are taken against one
    /// ball whose three set-up offsets on the table are estimated beside
    /// the errors.
    #[arg(long, value_name = "KIND", value_parser = chain::ops::choice::parser::<SetupKind>())]
    pub setup: Option<SetupKind>,
    /// Use the machine file's `statistics` as a Gaussian prior (the answer
    /// is the posterior mean and covariance).
    #[arg(long)]
    pub prior: bool,
    /// Measurements held out of the fit (the same columns as
    /// `--measurements`): the error they show before and after the
    /// estimates' correction.
    #[arg(long, value_name = "M2.csv")]
    pub validate: Option<PathBuf>,
    /// A fixed relative tolerance on the singular values of the
    /// equilibrated design instead of the noise rule (directions above
    /// TOL × the largest are estimated).
    #[arg(long, value_name = "TOL")]
    pub rank_tol: Option<f64>,
    /// Fix these error parameters at 0 and estimate every other one
    /// (instead of the elimination's choice).
    #[arg(long, value_name = "NAME,...", value_delimiter = ',')]
    pub fix: Option<Vec<String>>,
    /// Estimate only these error parameters, every other one fixed at 0.
    #[arg(long, value_name = "NAME,...", value_delimiter = ',')]
    pub estimate: Option<Vec<String>>,
    /// Hold this fraction of the measurement records out of the fit (a
    /// seeded shuffle) and report the estimates' prediction at them.
    #[arg(long, value_name = "FRACTION")]
    pub holdout: Option<f64>,
    /// The seed of `--holdout`'s split (default 1).
    #[arg(long, value_name = "S")]
    pub seed: Option<u64>,
    /// Fit the exact (not linearised) kinematics by Levenberg–Marquardt
    /// from the linear estimate, for errors too large for first order.
    #[arg(long)]
    pub iterate: bool,
    #[command(flatten)]
    pub param: ParamArgs,
    /// The thermal state of the records whose file has no column for a
    /// sensor (a column named after a sensor gives each record's).
    #[command(flatten)]
    pub thermal: ThermalArgs,
    /// Output format.
    #[arg(long, value_enum, default_value = "table")]
    pub format: IdentifyFormat,
    /// Write the estimates as a values file (with `std` per constant and a
    /// `correlation` list) that `chain map --values` and `chain reliability
    /// --values` read.
    #[arg(long, value_name = "VALUES.yaml")]
    pub values_out: Option<PathBuf>,
}

/// Runs `chain identify` ([`chain::ops::identify`]): the options checked
/// before the machine file is read.
pub fn exec(args: IdentifyArgs) -> miette::Result<()> {
    let request = IdentifyRequest {
        measurements: args.measurements.as_deref().map(Source::Path),
        spheres: args.spheres.as_deref().map(Source::Path),
        setup: args.setup,
        validate: args.validate.as_deref().map(Source::Path),
        params: &args.param.params,
        prior: args.prior,
        rank_tol: args.rank_tol,
        fix: args.fix,
        estimate: args.estimate,
        holdout: args.holdout,
        seed: args.seed,
        iterate: args.iterate,
        temperatures: &args.thermal.temperatures,
        circular: args.circular.as_deref().map(Source::Path),
        circle: CircleRequest {
            centre: args.centre.as_deref(),
            axes: args.axes,
            radius: args.run.radius,
            feed: args.run.feed,
            plane: args.run.plane.as_deref(),
            arc: args.run.arc,
        },
    };
    let checked = request.check()?;
    let loaded = Loaded::new(&args.file)?;
    let run = checked.run(&loaded.machine)?;
    if let Some(path) = &args.values_out {
        crate::cli::atomic::write(path, run.values_text.as_bytes())
            .map_err(|e| miette::miette!("cannot write {}: {e}", path.display()))?;
        eprintln!("wrote {}", path.display());
    }
    report::emit(&run, args.format.into())
}
