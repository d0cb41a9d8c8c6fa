//! `chain derive FILE [--frame tool|workpiece] [--format text|json|latex|rust]`:
//! [`chain::ops::derive`] rendered in the format asked.

use std::path::PathBuf;

use chain::ops::derive::{self, DeriveRequest};
use chain_core::emit::{emit_pretty, EmitOptions};
use chain_core::export;
use chain_core::model::Frame;

use crate::cli::report;

/// Output formats of `chain derive`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum DeriveFormat {
    /// A readable report.
    Text,
    /// The spec's JSON document.
    Json,
    /// LaTeX (`align*`).
    Latex,
    /// Rust source, exactly what `machine!` emits for the file.
    Rust,
}

/// Arguments of `chain derive`.
#[derive(Debug, clap::Args)]
pub struct DeriveArgs {
    /// Machine file (YAML).
    pub file: PathBuf,
    /// Frame of `p` and `o` (default: the file's `frame`).
    #[arg(long, value_parser = chain::ops::choice::parser::<Frame>())]
    pub frame: Option<Frame>,
    /// Output format.
    #[arg(long, value_enum, default_value = "text")]
    pub format: DeriveFormat,
}

/// Runs `chain derive` ([`chain::ops::derive`]).
pub fn exec(args: DeriveArgs) -> miette::Result<()> {
    let machine = chain_core::load_file(&args.file)?;
    let request = DeriveRequest { frame: args.frame };
    let derivation = derive::run(&machine, &request);
    let model = &derivation.model;
    let out = match args.format {
        DeriveFormat::Text => export::to_text(model),
        DeriveFormat::Latex => export::to_latex(model),
        DeriveFormat::Json => report::json(&derivation)?,
        DeriveFormat::Rust => emit_pretty(model, &EmitOptions::for_model(model)),
    };
    report::write_stdout(&out)
}
