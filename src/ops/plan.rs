//! `chain plan` as a request and a document (measured-machines spec §5;
//! docs/plan.md): `count` of the candidate poses maximising `det(AᵀA)` on
//! the identifiable subspace, against `count` taken evenly. The candidates
//! are read by the adapter (a file or stdin for the CLI, a path or columns
//! for Python) through `chain_core::measured::Measurements`; the kind, the
//! plan and every refusal are this module's.

use chain_core::measured::Measurements;
use chain_core::plan::{self, Kind, KindError, PlanDocument, PlanError};
use chain_core::Machine;

use super::worded::{diagnostic, Worded};

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

impl Worded for PlanOpsError {
    fn own_code(&self) -> Option<&'static str> {
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

    fn own_help(&self) -> Option<String> {
        let help = match self {
            PlanOpsError::Plan { error, .. } => match error {
                PlanError::Count { .. } | PlanError::TooFew { .. } => {
                    "pass --count with a number of candidates that can inform every identifiable direction"
                }
                PlanError::Uninformative => {
                    "the machine's errors do not act on what the candidates measure"
                }
                PlanError::Singular { .. } => {
                    "choose more candidates (--count) or add candidates that vary every axis"
                }
                _ => return None,
            },
            PlanOpsError::Kind(_) => return None,
        };
        Some(help.to_string())
    }

    #[cfg(feature = "cli")]
    fn inner(&self) -> Option<&dyn miette::Diagnostic> {
        match self {
            PlanOpsError::Kind(e) => Some(e),
            PlanOpsError::Plan { .. } => None,
        }
    }
}

diagnostic!(PlanOpsError);

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
