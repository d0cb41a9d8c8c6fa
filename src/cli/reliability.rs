//! `chain reliability`.

/// Arguments of `chain reliability`.
#[derive(Debug, clap::Args)]
pub struct ReliabilityArgs {
    /// Machine file (YAML).
    pub file: std::path::PathBuf,
}

/// Runs `chain reliability`.
pub fn exec(_args: ReliabilityArgs) -> miette::Result<()> {
    Err(miette::miette!("reliability: under construction"))
}
