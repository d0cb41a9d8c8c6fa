//! `chain report CALIBRATION.yaml [--out report.html] [--format html|json]`:
//! the calibration report a lab hands over, one self-contained HTML page
//! (`docs/report.md`), through [`chain::report`].

use std::path::PathBuf;

use chain::report::{self, Calibration};

use crate::cli::report as emit;

/// Output formats of `chain report`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ReportFormat {
    /// The HTML page.
    Html,
    /// Every section's document (the report's JSON).
    Json,
}

/// Arguments of `chain report`.
#[derive(Debug, clap::Args)]
pub struct ReportArgs {
    /// The calibration file (YAML, docs/report.md): the machine file, the
    /// positioning runs per axis with their tolerances, the values file,
    /// the identification's measurements, the controller exported to, a
    /// circular test, and the cover's free text.
    pub calibration: PathBuf,
    /// Write the HTML page here (otherwise it goes to standard output).
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// What goes to standard output: the page (without --out) or the
    /// report's JSON.
    #[arg(long, value_enum, default_value = "html")]
    pub format: ReportFormat,
}

/// Runs `chain report` ([`chain::report::run`]).
pub fn exec(args: ReportArgs) -> miette::Result<()> {
    let calibration = Calibration::read(&args.calibration)?;
    let done = report::run(&calibration, &args.calibration)?;
    if let Some(out) = &args.out {
        crate::cli::atomic::write(out, report::html(&done).as_bytes())
            .map_err(|e| miette::miette!("cannot write {}: {e}", out.display()))?;
        eprintln!("wrote {}", out.display());
    }
    match (args.format, &args.out) {
        (ReportFormat::Json, _) => emit::emit(&done, emit::Format::Json),
        (ReportFormat::Html, None) => emit::emit(&done, emit::Format::Table),
        (ReportFormat::Html, Some(_)) => Ok(()),
    }
}
