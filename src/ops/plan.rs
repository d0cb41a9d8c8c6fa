//! `chain plan` as a request and a document (measured-machines spec §5;
//! docs/plan.md): `count` of the candidate poses maximising `det(AᵀA)` on
//! the identifiable subspace, against `count` taken evenly. The candidates
//! are read by the adapter (a file or stdin for the CLI, a path or columns
//! for Python) through `chain_core::measured::Measurements`; the kind, the
//! plan and every refusal are this module's.

use chain_core::measured::Measurements;
use chain_core::plan::{self, Kind, KindError, PlanDocument, PlanError};
use chain_core::Machine;

/// The request of `chain plan`.
#[derive(Debug, Clone, Copy)]
pub struct PlanRequest {
    /// `--count`: how many candidates to choose.
    pub count: usize,
    /// `--kind`: what each candidate measures; `None`: what the file says
    /// (`ux,uy,uz` present: directions).
    pub kind: Option<Kind>,
}

/// Why `chain plan` cannot run.
#[derive(Debug, thiserror::Error)]
pub enum PlanOpsError {
    /// `--kind` contradicts the candidate file.
    #[error(transparent)]
    Kind(#[from] KindError),
    /// The plan (named by the candidate file).
    #[error("{file}: {error}")]
    Plan {
        /// The candidate file.
        file: String,
        /// What went wrong.
        error: PlanError,
    },
}

impl PlanOpsError {
    /// The diagnostic code.
    pub fn code(&self) -> Option<&'static str> {
        match self {
            PlanOpsError::Kind(_) => None,
            PlanOpsError::Plan { error, .. } => Some(match error {
                PlanError::Count { .. } | PlanError::TooFew { .. } => "chain::plan::count",
                PlanError::Uninformative => "chain::plan::uninformative",
                PlanError::Singular { .. } => "chain::plan::singular",
                _ => "chain::plan::candidates",
            }),
        }
    }

    /// What to do about it.
    pub fn help(&self) -> Option<&'static str> {
        match self {
            PlanOpsError::Plan { error, .. } => match error {
                PlanError::Count { .. } | PlanError::TooFew { .. } => Some(
                    "pass --count with a number of candidates that can inform every identifiable direction",
                ),
                PlanError::Uninformative => {
                    Some("the machine's errors do not act on what the candidates measure")
                }
                PlanError::Singular { .. } => Some(
                    "choose more candidates (--count) or add candidates that vary every axis",
                ),
                _ => None,
            },
            PlanOpsError::Kind(_) => None,
        }
    }

    /// The message with its help, as one text (Python's exceptions).
    pub fn with_help(&self) -> String {
        match self.help() {
            Some(help) => format!("{self}\nhelp: {help}"),
            None => self.to_string(),
        }
    }
}

#[cfg(feature = "cli")]
impl miette::Diagnostic for PlanOpsError {
    fn code<'a>(&'a self) -> Option<Box<dyn std::fmt::Display + 'a>> {
        match self {
            PlanOpsError::Kind(e) => miette::Diagnostic::code(e),
            e => PlanOpsError::code(e).map(|c| Box::new(c) as Box<dyn std::fmt::Display>),
        }
    }

    fn help<'a>(&'a self) -> Option<Box<dyn std::fmt::Display + 'a>> {
        PlanOpsError::help(self).map(|h| Box::new(h) as Box<dyn std::fmt::Display>)
    }
}

/// Runs `chain plan` of `machine` over `candidates` (read with
/// `Layout::Candidates`).
pub fn run(
    machine: &Machine,
    candidates: &Measurements,
    request: &PlanRequest,
) -> Result<PlanDocument, PlanOpsError> {
    let kind = Kind::of(candidates, request.kind)?.unwrap_or(Kind::Point);
    plan::plan_document(machine, candidates, request.count, kind).map_err(|error| {
        PlanOpsError::Plan {
            file: candidates.file.clone(),
            error,
        }
    })
}
