//! `chain sensitivity`.

/// Arguments of `chain sensitivity`.
#[derive(Debug, clap::Args)]
pub struct SensitivityArgs {
    /// Machine file (YAML).
    pub file: std::path::PathBuf,
}

/// Runs `chain sensitivity`.
pub fn exec(_args: SensitivityArgs) -> miette::Result<()> {
    Err(miette::miette!("sensitivity: under construction"))
}
