//! `chain positioning RUNS.csv [--k 2] [--rotary] [--format table|json|csv]
//! [--plot DIR]`: the ISO 230-2 evaluation of an axis's bidirectional
//! positioning runs (`../shared/spec/positioning.md`, `docs/positioning.md`),
//! through [`chain_core::measured::positioning`].

use std::path::PathBuf;

use chain::ops::positioning as ops;
use chain_core::measured::positioning::{Coverage, Runs};

use crate::cli::{plot, report};

/// Output formats of `chain positioning`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum PositioningFormat {
    /// The per-target statistics and the axis values.
    Table,
    /// The document of the positioning spec.
    Json,
    /// One row per target.
    Csv,
}

report::formats!(PositioningFormat: Table, Json, Csv);

/// Arguments of `chain positioning`.
#[derive(Debug, clap::Args)]
pub struct PositioningArgs {
    /// The run file (CSV): `target`, `direction` (`up`/`down`, `+`/`-`),
    /// `run` (1..n), and `measured` (the reached position) or `deviation`
    /// (reached minus target); mm, or degrees with `--rotary`.
    pub runs: PathBuf,
    /// The coverage factor k: 2 (ISO 230-2:1997-2014) or 3 (the 1988
    /// edition, VDI/DGQ 3441); any number > 0.
    #[arg(long, default_value = "2", value_parser = coverage)]
    pub k: Coverage,
    /// A rotary axis: targets and deviations in degrees, statistics in
    /// arcseconds.
    #[arg(long)]
    pub rotary: bool,
    /// Output format.
    #[arg(long, value_enum, default_value = "table")]
    pub format: PositioningFormat,
    /// Write the standard's chart (mean deviation per direction with the
    /// ±k·s band, each run's points, the reversal) into DIR as PNG and SVG.
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
    /// Write the run into a values file: the mean deviation per approach
    /// direction and its standard deviation per target, in the error motion
    /// `--slot` of the machine `--machine` (docs/positioning.md).
    #[arg(long, value_name = "VALUES.yaml", requires_all = ["machine", "slot"])]
    pub values_out: Option<PathBuf>,
    /// The machine file the values are for (with `--values-out`).
    #[arg(long, value_name = "FILE", requires = "values_out")]
    pub machine: Option<PathBuf>,
    /// The machine's name for the axis's positioning error, e.g. `EXX`
    /// (with `--values-out`).
    #[arg(long, value_name = "NAME", requires = "values_out")]
    pub slot: Option<String>,
    /// Correct the runs to 20 °C: the axis's (scale's) temperature during
    /// the runs (°C; docs/positioning.md, "At 20 °C").
    #[arg(long, value_name = "C", requires = "axis_expansion")]
    pub axis_temperature: Option<f64>,
    /// The scale's expansion coefficient (µm/(m·K); steel about 11.5).
    #[arg(long, value_name = "PPM", requires = "axis_temperature")]
    pub axis_expansion: Option<f64>,
    /// The instrument's (material sensor's) temperature [default: 20].
    #[arg(long, value_name = "C", requires = "axis_temperature")]
    pub instrument_temperature: Option<f64>,
    /// The expansion coefficient the instrument compensates with
    /// (µm/(m·K)) [default: 0, no compensation].
    #[arg(long, value_name = "PPM", requires = "axis_temperature")]
    pub instrument_expansion: Option<f64>,
    /// The standard uncertainty of each temperature (K) [default: 0.1].
    #[arg(long, value_name = "K", requires = "axis_temperature")]
    pub temperature_uncertainty: Option<f64>,
    /// The relative half-width of each expansion coefficient [default: 0.1,
    /// ±10 %].
    #[arg(long, value_name = "FRACTION", requires = "axis_temperature")]
    pub expansion_uncertainty: Option<f64>,
}

/// `--k`: a number the library takes as a coverage factor.
fn coverage(text: &str) -> Result<Coverage, String> {
    let k: f64 = text
        .parse()
        .map_err(|_| format!("`{text}` is not a number"))?;
    Coverage::new(k).map_err(|e| e.to_string())
}

/// Runs `chain positioning` ([`chain::ops::positioning`]).
pub fn exec(args: PositioningArgs) -> miette::Result<()> {
    let runs = Runs::read(&args.runs, ops::axis_kind(args.rotary))?;
    let machine = match &args.machine {
        Some(file) => Some(chain_core::load_file(file)?),
        None => None,
    };
    let machine_file = args.machine.as_ref().map(|f| f.display().to_string());
    let runs_file = args.runs.display().to_string();
    let values_out = match (&machine, &machine_file, &args.slot) {
        (Some(machine), Some(machine_file), Some(slot)) => Some(ops::ValuesOut {
            machine,
            machine_file,
            slot,
            runs_file: &runs_file,
        }),
        _ => None,
    };
    let temperatures = match (args.axis_temperature, args.axis_expansion) {
        (Some(axis), Some(axis_expansion)) => Some(ops::temperatures(
            axis,
            axis_expansion,
            args.instrument_temperature,
            args.instrument_expansion,
            args.temperature_uncertainty,
            args.expansion_uncertainty,
        )),
        _ => None,
    };
    let done = ops::run(&ops::PositioningRequest {
        runs: &runs,
        k: args.k,
        values_out,
        temperatures,
    })?;
    let doc = done.document;
    if let (Some(out), Some(text)) = (&args.values_out, &done.values_text) {
        crate::cli::atomic::write(out, text.as_bytes())
            .map_err(|e| miette::miette!("cannot write {}: {e}", out.display()))?;
        let slot = args.slot.as_deref().unwrap_or_default();
        eprintln!("wrote {} ({slot})", out.display());
    }
    if let Some(dir) = &args.plot {
        for f in plot::write(dir, &chain::plot::positioning::charts(&doc))? {
            eprintln!("wrote {}", f.display());
        }
    }
    report::emit(&doc, args.format.into())
}
