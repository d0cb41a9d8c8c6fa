//! `chain sobol` as a request and a document (docs/sobol.md): first-order
//! and total Sobol indices (Saltelli et al. 2010, Table 2 (b) and (f)) of
//! every toleranced component and of `|p|` with respect to every error
//! parameter, with bootstrap percentile intervals, at one point (`--at`) or
//! pooled over the reliability grid. Run by the CLI and `Machine.sobol`.

use chain_core::Machine;
use reliability::document::SobolDocument;
use reliability::sobol::{Sobol, SobolError, SobolResult};
use reliability::{ReliabilityError, Study};
use serde::{Serialize, Serializer};

use super::resolve::{self, ResolveError};
use super::study::{self, StudyError, StudyOptions};
use super::worded::{diagnostic, Worded};

/// The request of `chain sobol`.
#[derive(Debug, Clone, Copy)]
pub struct SobolRequest<'a> {
    /// `--at`: one point, every axis variable by name; `None`: pooled over
    /// the grid.
    pub at: Option<&'a [(String, f64)]>,
    /// `--samples`: base samples N.
    pub samples: u64,
    /// `--seed`.
    pub seed: u64,
    /// `--bootstrap`: bootstrap replicates.
    pub bootstrap: u64,
    /// `--confidence`: the intervals' level, in (0, 1).
    pub confidence: f64,
    /// `--grid VAR=...`: the grid to pool over (not with `at`).
    pub grid: &'a [(String, Vec<f64>)],
    /// `--param NAME=VALUE`.
    pub params: &'a [(String, f64)],
}

impl Default for SobolRequest<'_> {
    /// The CLI's defaults.
    fn default() -> Self {
        SobolRequest {
            at: None,
            samples: 10_000,
            seed: 0,
            bootstrap: 1000,
            confidence: 0.95,
            grid: &[],
            params: &[],
        }
    }
}

/// Why `chain sobol` cannot run.
#[derive(Debug, thiserror::Error)]
pub enum SobolOpsError {
    /// A setting out of range.
    #[error("--{what} {found}: must be {rule}")]
    Setting {
        /// `samples`, `bootstrap` or `confidence`.
        what: &'static str,
        /// What it must be.
        rule: &'static str,
        /// The value given.
        found: String,
    },
    /// An option does not match the machine.
    #[error(transparent)]
    Resolve(#[from] ResolveError),
    /// The study.
    #[error(transparent)]
    Study(Box<StudyError>),
    /// The machine's sections (located by `reliability::document::describe`).
    #[error(transparent)]
    Reliability(#[from] ReliabilityError),
    /// The analysis (correlated inputs, an output that does not vary).
    #[error("{file}: chain sobol: {error}")]
    Sobol {
        /// The machine file.
        file: String,
        /// What went wrong.
        error: SobolError,
    },
}

impl From<StudyError> for SobolOpsError {
    fn from(e: StudyError) -> SobolOpsError {
        SobolOpsError::Study(Box::new(e))
    }
}

impl Worded for SobolOpsError {
    fn own_code(&self) -> Option<&'static str> {
        match self {
            SobolOpsError::Setting { .. } => Some("chain::sobol::invalid_setting"),
            _ => None,
        }
    }

    fn own_help(&self) -> Option<String> {
        match self {
            SobolOpsError::Resolve(e) => e.own_help(),
            _ => None,
        }
    }

    #[cfg(feature = "cli")]
    fn inner(&self) -> Option<&dyn miette::Diagnostic> {
        match self {
            SobolOpsError::Resolve(e) => Some(e),
            SobolOpsError::Sobol { error, .. } => Some(error),
            _ => None,
        }
    }
}

diagnostic!(SobolOpsError);

/// The document of `chain sobol` (JSON: the library's [`SobolDocument`]).
#[derive(Debug)]
pub struct SobolRun {
    /// The machine.
    pub machine: String,
    /// The study the indices are of (one point with `--at`).
    pub study: Study,
    /// Whether the study is the one point of `--at`.
    pub at_point: bool,
    /// The indices.
    pub result: SobolResult,
}

impl SobolRun {
    /// The library's document of the run.
    pub fn document(&self) -> SobolDocument<'_> {
        SobolDocument::new(&self.machine, &self.study, self.at_point, &self.result)
    }
}

impl Serialize for SobolRun {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        self.document().serialize(serializer)
    }
}

/// The analysis of the request's settings, each checked with its option
/// named (`file` names the machine file in other refusals).
pub fn settings(request: &SobolRequest<'_>, file: &str) -> Result<Sobol, SobolOpsError> {
    let s = Sobol {
        samples: usize::try_from(request.samples).unwrap_or(usize::MAX),
        seed: request.seed,
        bootstrap: usize::try_from(request.bootstrap).unwrap_or(usize::MAX),
        confidence: request.confidence,
    };
    match s.validate() {
        Err(SobolError::InvalidSetting { what, rule, found }) => {
            Err(SobolOpsError::Setting { what, rule, found })
        }
        Err(error) => Err(SobolOpsError::Sobol {
            file: file.to_string(),
            error,
        }),
        Ok(()) => Ok(s),
    }
}

/// Runs `chain sobol` of `machine` (`file` names it).
pub fn run(
    machine: &Machine,
    file: &str,
    request: &SobolRequest<'_>,
) -> Result<SobolRun, SobolOpsError> {
    let settings = settings(request, file)?;
    if request.at.is_some() && !request.grid.is_empty() {
        return Err(ResolveError::AtWithGrid {
            grid_for: "the pooled indices",
        }
        .into());
    }
    resolve::check_parameters(machine, request.params)?;
    let study = match request.at {
        None => {
            let options = StudyOptions {
                params: request.params,
                grid: request.grid,
                ..StudyOptions::default()
            };
            study::study(machine, file, &options)?.0
        }
        Some(coords) => {
            let point = resolve::at_point(machine, file, coords)?;
            let spec = reliability::machine::spec(machine, None)?;
            let inputs = reliability::machine::inputs(machine)?;
            let values = reliability::machine::parameters(machine, request.params)?;
            let model = chain_core::compile(machine);
            Study::at_points(&model, &values, inputs, spec, vec![point])?
        }
    };
    let result = settings
        .run_study(&study)
        .map_err(|error| SobolOpsError::Sobol {
            file: file.to_string(),
            error,
        })?;
    Ok(SobolRun {
        machine: machine.name.clone(),
        study,
        at_point: request.at.is_some(),
        result,
    })
}
