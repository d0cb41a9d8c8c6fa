//! `chain compensate`.

/// Arguments of `chain compensate`.
#[derive(Debug, clap::Args)]
pub struct CompensateArgs {
    /// Measurement CSV.
    pub file: std::path::PathBuf,
}

/// Runs `chain compensate`.
pub fn exec(_args: CompensateArgs) -> miette::Result<()> {
    Err(miette::miette!("compensate: under construction"))
}
