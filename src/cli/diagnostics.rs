//! Library errors rendered with a code and help for more than one command
//! (until their wording moves into the libraries' typed errors).

use chain_core::compensation::CompensationError;
use miette::MietteDiagnostic;

/// A compensation error, rendered with its code and help.
pub(crate) fn export_error(e: CompensationError, values: &std::path::Path) -> miette::Report {
    match &e {
        CompensationError::OutOfRange { point, at, source } => {
            let d = MietteDiagnostic::new(format!(
                "at node {} ({at}): {} = {} is outside the table of `{}` ({}, {} = {} to {})",
                point + 1,
                source.variable,
                source.value,
                source.name,
                source.table,
                source.variable,
                source.lo,
                source.hi
            ))
            .with_code("chain::export::out_of_range")
            .with_help(format!(
                "the values file {} does not cover the requested nodes: export inside {} = {} to {} (--grid), extend the table, or add `extrapolate: hold` to its entry",
                values.display(),
                source.variable,
                source.lo,
                source.hi
            ));
            miette::Report::new(d)
        }
        _ => miette::Report::new(e),
    }
}
