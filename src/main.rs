//! The `chain` command-line tool.

mod cli;

use clap::error::{ContextKind, ContextValue};
use clap::Parser;

/// The command line, parsed; a refusal exits as clap's (status 2, usage on
/// stderr) with the value or argument it quotes shortened to 40
/// characters and `…` (`chain_core::diagnostic::shortened`: a 5,000
/// character option value is not echoed whole; docs/robustness.md).
fn parse() -> cli::Cli {
    cli::Cli::try_parse().unwrap_or_else(|mut e| {
        for kind in [
            ContextKind::InvalidValue,
            ContextKind::InvalidArg,
            ContextKind::InvalidSubcommand,
        ] {
            if let Some(ContextValue::String(v)) = e.get(kind) {
                let short = chain_core::diagnostic::shortened(v).into_owned();
                if short != *v {
                    e.insert(kind, ContextValue::String(short));
                }
            }
        }
        e.exit()
    })
}

fn main() -> std::process::ExitCode {
    let cli = parse();
    match cli::run(cli) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(report) => {
            eprintln!("{report:?}");
            std::process::ExitCode::FAILURE
        }
    }
}
