//! `chain plan` as a request and a document (measured-machines spec §5;
//! docs/plan.md): `count` of the candidate poses maximising `det(AᵀA)` on
//! the identifiable subspace, against `count` taken evenly (the D-optimal
//! design is [`chain_core::plan::plan`]). The candidates are read by the
//! adapter (a file or stdin for the CLI, a path or columns for Python)
//! through `chain_core::measured::Measurements` (a candidate file, or
//! sphere-probing candidates whose spheres' positions are unknowns of the
//! plan as of the fit: `docs/five-axis.md`); the kind, the document and
//! every refusal in the options' words are this module's.

use chain_core::measured::{Design, Measurements};
use chain_core::plan::{self, Kind, KindError, Plan, PlanError, Rows};
use chain_core::{ErrorModel, Machine};
use serde::Serialize;

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
    #[error("{}", kind_words(.0))]
    Kind(#[from] KindError),
    /// The plan (named by the candidate file).
    #[error("{file}: {}", plan_words(error))]
    Plan {
        /// The candidate file.
        file: String,
        /// What went wrong.
        error: PlanError,
    },
}

/// A contradicting `--kind` in the option's words.
fn kind_words(e: &KindError) -> String {
    match e {
        KindError::PointWithDirections { file } => format!(
            "{file}:1: columns `ux,uy,uz` give directions, but --kind point measures px, py, pz; pass --kind direction or remove them"
        ),
        KindError::DirectionWithout { file } => format!(
            "{file}:1: --kind direction needs the columns `ux,uy,uz` (the unit direction of each measurement)"
        ),
    }
}

/// The plan's refusal, a count in `--count`'s words.
fn plan_words(e: &PlanError) -> String {
    match e {
        PlanError::Count { count, candidates } => {
            format!("--count {count} is not a count of candidates: choose 1 to {candidates}")
        }
        PlanError::TooFew {
            count,
            rows,
            rank,
            minimum,
        } => format!(
            "{count} candidates give {rows} design rows, fewer than the {rank} dimensions the candidates can identify; choose --count {minimum} or more"
        ),
        e => e.to_string(),
    }
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

/// The document of `chain plan` (`--format json`, and what the Python
/// package returns): the library's [`Plan`] with what the command knows of
/// its input; `lines` and `poses` are for the table only.
#[derive(Debug, Clone, Serialize)]
pub struct PlanDocument {
    /// The machine's name.
    pub machine: String,
    /// The candidate file as named in messages.
    pub candidates_file: String,
    /// What each candidate measures.
    pub kind: Kind,
    /// The axis variables, in model order.
    pub variables: Vec<String>,
    /// Each candidate's CSV line.
    #[serde(skip)]
    pub lines: Vec<usize>,
    /// Each candidate's pose.
    #[serde(skip)]
    pub poses: Vec<Vec<f64>>,
    /// The plan.
    #[serde(flatten)]
    pub plan: Plan,
}

/// Runs `chain plan` of `machine` over `candidates` (read with
/// `Layout::Candidates`): the kind checked against the file, the count
/// checked before the model is compiled, then [`plan::plan`] over the
/// candidates' design rows.
pub fn run(
    machine: &Machine,
    candidates: &Measurements,
    request: &PlanRequest,
) -> Result<PlanDocument, PlanOpsError> {
    let kind = Kind::of(candidates, request.kind)?.unwrap_or(Kind::Point);
    let refused = |error| PlanOpsError::Plan {
        file: candidates.file.clone(),
        error,
    };
    let count = request.count;
    if count == 0 || count > candidates.rows.len() {
        return Err(refused(PlanError::Count {
            count,
            candidates: candidates.rows.len(),
        }));
    }
    let model = chain_core::compile(machine);
    // Sphere-probing candidates bring their spheres' positions as unknowns
    // (counted in the plan, as the fit will estimate them).
    let design = Design::of(&model, machine, candidates).map_err(|e| refused(e.into()))?;
    let rows = Rows::from_design(&design).map_err(refused)?;
    let result = plan::plan(&rows, count).map_err(refused)?;
    Ok(PlanDocument {
        machine: machine.name.clone(),
        candidates_file: candidates.file.clone(),
        kind,
        variables: model.variables().iter().map(|v| v.to_string()).collect(),
        lines: candidates.rows.iter().map(|c| c.line).collect(),
        poses: candidates.rows.iter().map(|c| c.q.clone()).collect(),
        plan: result,
    })
}
