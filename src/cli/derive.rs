//! `chain derive`.

/// Arguments of `chain derive`.
#[derive(Debug, clap::Args)]
pub struct DeriveArgs {
    /// Machine file (YAML).
    pub file: std::path::PathBuf,
}

/// Runs `chain derive`.
pub fn exec(_args: DeriveArgs) -> miette::Result<()> {
    Err(miette::miette!("derive: under construction"))
}
