//! `chain circular RUNS.csv [--radius R] [--feed F] [--plane xy|yz|zx]
//! [--arc DEG] [--format table|json] [--plot DIR]`: an ISO 230-4 circular test
//! (ballbar) evaluated per run and direction (`../shared/spec/circular.md`,
//! `docs/circular.md`), through [`chain::ops::circular`].

use std::path::PathBuf;

use chain::ops::circular as ops;
use chain::ops::source::{self, Source};

use crate::cli::args::RunFileArgs;
use crate::cli::{plot, report};

/// Output formats of `chain circular`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum CircularFormat {
    /// Per run and direction G, F_max, F_min and the centre; G(b) and H.
    Table,
    /// The document of the circular spec.
    Json,
}

report::formats!(CircularFormat: Table, Json);

/// Arguments of `chain circular`.
#[derive(Debug, clap::Args)]
pub struct CircularArgs {
    /// The run file (CSV): `angle` (degrees), `direction` (`ccw`, `cw`),
    /// `deviation` (mm; `deviation(um)` for µm), and optionally `run`,
    /// `radius`, `feed`, `plane`.
    pub runs: PathBuf,
    #[command(flatten)]
    pub run: RunFileArgs,
    /// The pitch (mm) of an axis's cyclic error, as AXIS=MM (e.g. x=10, a
    /// ballscrew's lead): that axis's cyclic error is diagnosed. Repeat
    /// for each axis.
    #[arg(long, value_name = "AXIS=MM", value_parser = pitch)]
    pub pitch: Vec<(String, f64)>,
    /// The window after each reversal, in degrees, that the diagnosis's
    /// fit leaves out and reads the reversal spike from (default 4).
    #[arg(long, value_name = "DEG")]
    pub window: Option<f64>,
    /// Output format.
    #[arg(long, value_enum, default_value = "table")]
    pub format: CircularFormat,
    /// Write each run's polar plot (both directions about their
    /// least-squares centres, the deviation magnified on a ring) into DIR
    /// as PNG and SVG (`circular_<run>`).
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
}

/// `AXIS=MM` of `--pitch`, split (what the pair must be is the library's
/// rule: [`ops::diagnosis_options`]).
fn pitch(text: &str) -> Result<(String, f64), String> {
    let (axis, mm) = text
        .split_once('=')
        .ok_or_else(|| format!("{text}: expected AXIS=MM, e.g. x=10"))?;
    let mm = (mm.trim().parse::<f64>())
        .map_err(|_| format!("{text}: the pitch {mm:?} is not a number (mm)"))?;
    Ok((axis.trim().to_string(), mm))
}

/// Runs `chain circular` ([`chain::ops::circular`]).
pub fn exec(args: CircularArgs) -> miette::Result<()> {
    let r = &args.run;
    let options = ops::options(r.radius, r.feed, r.plane.as_deref(), r.arc)?;
    let diagnosis = ops::diagnosis_options(&args.pitch, args.window)?;
    let test = source::read_circular(Source::Path(&args.runs), &options)?;
    let done = ops::run(&test, &diagnosis);
    if let Some(dir) = &args.plot {
        for f in plot::write(dir, &chain::plot::circular::charts(&test, &done))? {
            eprintln!("wrote {}", f.display());
        }
    }
    report::emit(&done, args.format.into())
}
