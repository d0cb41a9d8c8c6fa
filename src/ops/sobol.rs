//! `chain sobol` as a request and a document (docs/sobol.md): first-order
//! and total Sobol indices (Saltelli et al. 2010, Table 2 (b) and (f)) of
//! every toleranced component and of `|p|` with respect to every error
//! parameter, with bootstrap percentile intervals, at one point (`--at`) or
//! pooled over the reliability grid. Run by the CLI and `Machine.sobol`.

use chain_core::named::NameMap;
use chain_core::Machine;
use reliability::sobol::{Estimate, OutputIndices, Sobol, SobolError, SobolResult};
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
    /// The machine's sections (located by [`study::describe`]).
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

/// The run of `chain sobol` (JSON: its [`SobolDocument`]).
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
    /// The document of the run.
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

/// The document of `chain sobol` (docs/sobol.md): the settings, then per
/// output its variance, the sums of the indices and every error's first
/// and total index with its interval.
#[derive(Debug, Serialize)]
pub struct SobolDocument<'a> {
    /// The machine's name.
    pub machine: &'a str,
    /// `saltelli-jansen`: Saltelli 2010 Table 2 (b) and (f).
    pub method: &'static str,
    /// The point, or `null` when the indices pool the grid.
    pub at: Option<NameMap<String, f64>>,
    /// The grid pooled (absent at a point).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub grid: Option<NameMap<String, Vec<f64>>>,
    /// Points evaluated.
    pub points: usize,
    /// Base samples `N`.
    pub samples: usize,
    /// The seed.
    pub seed: u64,
    /// Bootstrap replicates.
    pub bootstrap: usize,
    /// Confidence level of the intervals.
    pub confidence: f64,
    /// Bootstrap blocks.
    pub blocks: usize,
    /// Model evaluations per point, `N·(k + 2)`.
    pub evaluations_per_point: u64,
    /// Each output's indices, by name.
    pub outputs: NameMap<&'static str, SobolOutputDocument<'a>>,
    /// The result the document shows (for the table and CSV forms).
    #[serde(skip)]
    pub result: &'a SobolResult,
}

/// One output of a [`SobolDocument`].
#[derive(Debug, Serialize)]
pub struct SobolOutputDocument<'a> {
    /// The output's variance (summed over the grid when pooled).
    pub variance: f64,
    /// Σ of the first-order indices.
    pub sum_first: &'a Estimate,
    /// Σ of the total indices.
    pub sum_total: &'a Estimate,
    /// Every error's indices.
    pub errors: Vec<SobolErrorDocument<'a>>,
}

/// One error of a [`SobolOutputDocument`].
#[derive(Debug, Serialize)]
pub struct SobolErrorDocument<'a> {
    /// The error parameter.
    pub error: &'a str,
    /// Its first-order index.
    pub first: &'a Estimate,
    /// Its total index.
    pub total: &'a Estimate,
}

impl<'a> SobolOutputDocument<'a> {
    fn of(o: &'a OutputIndices) -> SobolOutputDocument<'a> {
        SobolOutputDocument {
            variance: o.variance,
            sum_first: &o.sum_first,
            sum_total: &o.sum_total,
            errors: o
                .errors
                .iter()
                .map(|e| SobolErrorDocument {
                    error: &e.error,
                    first: &e.first,
                    total: &e.total,
                })
                .collect(),
        }
    }
}

impl<'a> SobolDocument<'a> {
    /// The document of `result`, the indices of `study`: at its one point
    /// when `at_point` (a [`Study::at_points`] study), otherwise pooled
    /// over its grid.
    pub fn new(
        machine: &'a str,
        study: &Study,
        at_point: bool,
        result: &'a SobolResult,
    ) -> SobolDocument<'a> {
        let at = at_point.then(|| {
            NameMap::zip(
                study.variables().iter().cloned(),
                (study.points().iter().next().into_iter()).flat_map(|q| q.to_vec()),
            )
        });
        let grid = (!at_point).then(|| NameMap(study.spec().grid.axes.clone()));
        SobolDocument {
            machine,
            method: "saltelli-jansen",
            at,
            grid,
            points: result.points,
            samples: result.settings.samples,
            seed: result.settings.seed,
            bootstrap: result.settings.bootstrap,
            confidence: result.settings.confidence,
            blocks: result.blocks,
            evaluations_per_point: result.evaluations_per_point,
            outputs: NameMap(
                result
                    .outputs
                    .iter()
                    .map(|o| (o.output.name(), SobolOutputDocument::of(o)))
                    .collect(),
            ),
            result,
        }
    }
}
