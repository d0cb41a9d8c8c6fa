//! `chain sensitivity FILE [--kind reliability|geometric] [--at x=..,y=..,z=..]
//! [--format table|json] [--plot DIR]`.
//!
//! `--kind reliability` (the default): the reliability sensitivity of each component to the mean and standard
//! deviation of every error parameter (seed 000, Eq. 32-33) and its FORM
//! importance factor: at one point with `--at`, otherwise the mean over the
//! file's reliability grid (the paper's Figures 6-8). Lists are sorted by
//! `|∂R/∂σ|`, largest first; `--plot DIR` draws them as bar charts (the
//! charts of `chain reliability --plot`).
//!
//! `--kind geometric`: the geometric error sensitivity coefficients of seed
//! 004 (Eq. 4-6), `S = |∂E_u/∂e_v|` and `C = S·e / Σ S·e` per direction,
//! at `--at` or averaged over the reliability grid (or `--grid`), with
//! `--values` giving the nominal error sizes and `--plot DIR` bar charts like
//! the paper's Figures 3-5 (see `docs/geometric_sensitivity.md`).

use std::path::PathBuf;

use chain::ops::sensitivity::{
    self, SensitivityKind as Kind, SensitivityOpsError, SensitivityRequest, SensitivityValues,
};
use chain_core::geometric::NominalSizes;

use crate::cli::args::{parse_grid_axis, parse_point, AtPoint, ModelArgs, ThermalArgs};
use crate::cli::loaded::Loaded;
use crate::cli::report;

/// What `chain sensitivity` computes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum SensitivityKind {
    /// Reliability sensitivity to each error's mean and standard deviation.
    #[default]
    Reliability,
    /// Geometric error sensitivity coefficients `S = |∂E/∂e|`, `C = S·e/ΣS·e` (seed 004).
    Geometric,
}

/// Output formats of `chain sensitivity`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum SensitivityFormat {
    /// One ranked table per component.
    Table,
    /// The spec's JSON document.
    Json,
}

/// Arguments of `chain sensitivity`.
#[derive(Debug, clap::Args)]
pub struct SensitivityArgs {
    /// Machine file (YAML) with `statistics` and `reliability` sections.
    pub file: PathBuf,
    /// Evaluate at one point, e.g. `x=0,y=1500,z=600` (every axis variable);
    /// without it, the mean over the reliability grid.
    #[arg(long, value_name = "VAR=VALUE,...", value_parser = parse_point)]
    pub at: Option<AtPoint>,
    /// Output format.
    #[arg(long, value_enum, default_value = "table")]
    pub format: SensitivityFormat,
    #[command(flatten)]
    pub model: ModelArgs,
    /// `--kind reliability`: the thermal state of a machine with sensors.
    #[command(flatten)]
    pub thermal: ThermalArgs,
    /// What to compute.
    #[arg(long, value_enum, default_value = "reliability")]
    pub kind: SensitivityKind,
    /// `--kind reliability`: a values file with the posterior of a calibration
    /// (means, `std`, `correlation`; docs/posterior.md). `--kind geometric`:
    /// nominal error sizes `linear=MM,angular=ANGLE[,squareness=ANGLE]`,
    /// angles in radians or with a `deg` suffix (default `linear=0.001,angular=0.001deg`).
    /// An argument with `=` is nominal sizes, any other a values file.
    #[arg(long, value_name = "VALUES.yaml | KIND=VALUE,...", value_parser = parse_values)]
    pub values: Option<ValuesArg>,
    /// `--kind reliability` with a values file: which approach direction of
    /// its bidirectional tables to read, `up`, `down`, `mean` (the default)
    /// or per axis `x=up,y=down` (docs/values.md, "Direction").
    #[arg(long, value_name = "DIR|VAR=DIR,...", value_parser = chain_core::values::parse_approaches)]
    pub approach: Vec<Vec<(Option<String>, chain_core::values::Approach)>>,
    /// Replace the grid values of one axis for the grid mean, `VAR=V1,V2,...`, or `VAR=LO:HI:N` for N evenly spaced values from LO to HI (repeatable).
    #[arg(long = "grid", value_name = "VAR=V1,V2,...|VAR=LO:HI:N", value_parser = parse_grid_axis)]
    pub grid: Vec<(String, Vec<f64>)>,
    /// Write bar charts (PNG and SVG) into DIR: `|∂R/∂σ|` per component
    /// (`--kind reliability`, like Figures 6-8 of Wang & Yuan 2021) or the
    /// geometric coefficients (`--kind geometric`).
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
}

/// What `--values` gives.
#[derive(Debug, Clone)]
pub enum ValuesArg {
    /// Nominal error sizes (`--kind geometric`).
    Nominal(NominalSizes),
    /// A values file: the posterior (`--kind reliability`).
    File(PathBuf),
}

/// Parses `--values`: nominal sizes when it has a `=`, a values file otherwise.
fn parse_values(s: &str) -> Result<ValuesArg, String> {
    if s.contains('=') {
        NominalSizes::default().parse(s).map(ValuesArg::Nominal)
    } else {
        Ok(ValuesArg::File(PathBuf::from(s)))
    }
}

/// Runs `chain sensitivity` ([`chain::ops::sensitivity`]).
pub fn exec(args: SensitivityArgs) -> miette::Result<()> {
    let approach: Vec<_> = args.approach.iter().flatten().cloned().collect();
    let request = SensitivityRequest {
        kind: match args.kind {
            SensitivityKind::Reliability => Kind::Reliability,
            SensitivityKind::Geometric => Kind::Geometric,
        },
        at: args.at.as_ref().map(|AtPoint(c)| c.as_slice()),
        params: &args.model.param.params,
        sided: args.model.sided,
        grid: &args.grid,
        values: args.values.as_ref().map(|v| match v {
            ValuesArg::File(f) => SensitivityValues::File(f),
            ValuesArg::Nominal(n) => SensitivityValues::Nominal(*n),
        }),
        approach: &approach,
        temperatures: &args.thermal.temperatures,
    };
    sensitivity::check(&request)?;
    let loaded = Loaded::new(&args.file)?;
    let doc =
        sensitivity::run(&loaded.machine, loaded.file_name(), &request).map_err(|e| match e {
            SensitivityOpsError::Study(e) => loaded.study_error(*e),
            SensitivityOpsError::Reliability(e) => loaded.report(e),
            e => miette::Report::new(e),
        })?;
    if let Some(dir) = &args.plot {
        let charts = chain::plot::sensitivity::charts(&doc);
        for f in crate::cli::plot::write(dir, &charts)? {
            eprintln!("wrote {}", f.display());
        }
    }
    report::emit(&doc, args.format.into())
}

report::formats!(SensitivityFormat: Table, Json);
