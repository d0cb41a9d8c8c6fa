//! The result documents of a reliability study: what `chain reliability
//! --format json` prints and what the Python package's `to_dict()` returns,
//! built in one place from a [`Study`] and its [`StudyResult`].
//!
//! The documents are plain serialisable structs (their fields, in
//! declaration order, are the JSON keys); the binary adds its table and CSV
//! forms on top, the Python bindings serialise them as they are.
//!
//! The same holds for the whole-machine acceptance object
//! ([`AcceptanceDocument`], `chain reliability --acceptance`) and the Sobol
//! indices ([`SobolDocument`], `chain sobol`); [`volumetric`] is the
//! `--system volumetric` target.
//!
//! [`sensitivity`] runs `chain sensitivity --kind reliability` (at a point
//! or the grid mean) and [`SensitivityDocument`] is its JSON.
//!
//! [`allocation`] runs `chain allocate` and [`AllocationDocument`] is its JSON.
//!
//! [`describe`] is the one wording of a [`ReliabilityError`] against the
//! machine file it concerns (message, location, label, help), shared by the
//! binary's diagnostics and the Python exceptions.

use chain_core::model::{Origin, Requirement, Sided};
use chain_core::named::NameMap;
use serde::Serialize;

use chain_core::model::Machine;

use crate::acceptance::{Acceptance, AcceptanceResult, Rectangles};
use crate::allocate::{
    self, AcceptanceAllocation, AcceptanceStrategy, AllocateError, Allocation, ErrorBounds, Optimal,
};
use crate::sobol::{Estimate, OutputIndices, SobolResult};
use crate::{
    Calls, CaseResult, ErrorModel, Form, FormCase, Method, Posterior, ReliabilityError,
    SensitivityMethod, SormCase, Stopping, Study, StudyResult, SubsetLevel, Summary, System,
    Target, TargetSensitivity,
};

/// The document of a grid study (the spec's `reliability` JSON contract).
#[derive(Debug, Serialize)]
pub struct ReliabilityDocument<'a> {
    /// The machine's name.
    pub machine: &'a str,
    /// The algorithm.
    pub method: Method,
    /// One- or two-sided tolerances.
    pub sided: Sided,
    /// Every case, target-major (each case's document formed as it is
    /// written).
    pub results: CaseDocuments<'a>,
    /// Each target's summary over the grid.
    pub summary: NameMap<Target, SummaryDocument>,
    /// The requirement and whether every target meets it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub requirement: Option<RequirementDocument>,
    /// The posterior the inputs came from (a calibration's values file), when given.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub posterior: Option<&'a Posterior>,
    /// The whole-machine acceptance probability (`--acceptance`), when run.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub acceptance: Option<AcceptanceDocument<'a>>,
}

/// One case (target at a grid point) of a [`ReliabilityDocument`].
#[derive(Debug, Serialize)]
pub struct CaseDocument<'a> {
    /// The target.
    pub component: Target,
    /// The grid point: the grid's axes in file order.
    pub point: NameMap<&'a str, f64>,
    /// The reliability `1 − pf`.
    pub reliability: f64,
    /// The failure probability.
    pub pf: f64,
    /// The reliability index (infinite for a component the errors do not reach: JSON `null`).
    pub beta: f64,
    /// The standard error of a sampled `pf`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub std_error: Option<f64>,
    /// The samples drawn.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub samples: Option<u64>,
    /// The coefficient of variation of a sampled `pf`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cov: Option<f64>,
    /// FORM's account (termination, iterations, exactness), when FORM ran.
    #[serde(flatten)]
    pub form: Option<FormCase>,
    /// The sampler's convergence where FORM's does not occupy the key
    /// (subset, directional, mc with `--cov`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub converged: Option<bool>,
    /// Limit-state calls.
    pub calls: Calls,
    /// How the sampler stopped (subset, directional, or `--cov`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sampling: Option<Stopping>,
    /// Subset simulation's levels.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub levels: Option<&'a [SubsetLevel]>,
    /// SORM's three formulas and curvatures (`--method sorm`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sorm: Option<&'a SormCase>,
}

/// The cases of a [`ReliabilityDocument`]: serialised as the list of their
/// [`CaseDocument`]s, each formed when it is written, so that a document of
/// a million cases is not a second copy of them.
#[derive(Debug)]
pub struct CaseDocuments<'a> {
    /// The grid's axes in file order, with their index in the model's
    /// variables.
    axes: Vec<(&'a str, usize)>,
    /// The cases, target-major.
    cases: &'a [CaseResult],
}

impl<'a> CaseDocuments<'a> {
    /// The number of cases.
    pub fn len(&self) -> usize {
        self.cases.len()
    }

    /// True when there is no case.
    pub fn is_empty(&self) -> bool {
        self.cases.is_empty()
    }

    /// Each case's document, target-major.
    pub fn iter(&self) -> impl Iterator<Item = CaseDocument<'a>> + '_ {
        self.cases.iter().map(|c| CaseDocument {
            component: c.target,
            point: NameMap(self.axes.iter().map(|&(n, i)| (n, c.point[i])).collect()),
            reliability: c.reliability,
            pf: c.pf,
            beta: c.beta,
            std_error: c.std_error,
            samples: c.samples,
            cov: c.cov,
            form: c.form,
            converged: match (&c.form, &c.stopping) {
                (None, Some(st)) => Some(st.converged),
                _ => None,
            },
            calls: c.calls,
            sampling: c.stopping,
            levels: c.levels.as_deref(),
            sorm: c.sorm.as_deref(),
        })
    }
}

impl Serialize for CaseDocuments<'_> {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_seq(self.iter())
    }
}

/// One target's summary of a [`ReliabilityDocument`].
#[derive(Debug, Serialize)]
pub struct SummaryDocument {
    /// Mean reliability over the grid.
    pub mean: f64,
    /// Smallest reliability over the grid.
    pub min: f64,
    /// Largest reliability over the grid.
    pub max: f64,
    /// Whether the target meets the requirement (when there is one).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub met: Option<bool>,
}

/// The requirement of a study and whether every target meets it.
#[derive(Debug, Serialize)]
pub struct RequirementDocument {
    /// The smallest reliability required at any point.
    pub min: f64,
    /// The mean reliability required over the grid.
    pub mean: f64,
    /// Whether every target meets both.
    pub met: bool,
}

impl RequirementDocument {
    /// The requirement of a study result, if it has one.
    pub fn of(r: &StudyResult) -> Option<RequirementDocument> {
        r.requirement.map(|req| RequirementDocument {
            min: req.min,
            mean: req.mean,
            met: r.requirement_met(),
        })
    }
}

impl<'a> ReliabilityDocument<'a> {
    /// The document of a study's result (no posterior: set
    /// [`ReliabilityDocument::posterior`] when the inputs came from one).
    pub fn new(machine: &'a str, study: &'a Study, r: &'a StudyResult) -> Self {
        let ax: Vec<(&'a str, usize)> = study
            .spec()
            .grid
            .axes
            .iter()
            .filter_map(|(n, _)| {
                let i = study.variables().iter().position(|v| v == n)?;
                Some((n.as_str(), i))
            })
            .collect();
        let results = CaseDocuments {
            axes: ax,
            cases: &r.cases,
        };
        let summary = NameMap(
            r.summaries
                .iter()
                .map(|s| {
                    let doc = SummaryDocument {
                        mean: s.mean,
                        min: s.min,
                        max: s.max,
                        met: s.met,
                    };
                    (s.target, doc)
                })
                .collect(),
        );
        ReliabilityDocument {
            machine,
            method: r.method,
            sided: study.spec().sided,
            results,
            summary,
            requirement: RequirementDocument::of(r),
            posterior: None,
            acceptance: None,
        }
    }
}

// ---------------------------------------------------------------------------
// The algorithm of a method name's options.

/// The `--system volumetric` target: `√(px² + py² + pz²) ≤ tolerance`,
/// by default the smallest position tolerance of the reliability section.
pub fn volumetric(machine: &Machine, tolerance: Option<f64>) -> Result<System, ReliabilityError> {
    let tolerance = match tolerance {
        Some(t) => t,
        None => machine
            .reliability
            .as_ref()
            .ok_or(ReliabilityError::NoReliabilitySection)?
            .tolerance
            .iter()
            .filter(|(c, _)| c.index() < 3)
            .map(|(_, t)| *t)
            .fold(f64::INFINITY, f64::min),
    };
    Ok(System::Volumetric { tolerance })
}

// ---------------------------------------------------------------------------
// The whole-machine acceptance probability (spec reliability-v2 §4).

/// The acceptance probability of every point × toleranced component of
/// `study` at once, to an absolute error `tolerance` (three standard
/// errors), with its sensitivities, as `chain reliability --acceptance`
/// runs it ([`Acceptance`] over [`Rectangles::from_study`]).
pub fn acceptance(
    study: &Study,
    tolerance: f64,
    seed: u64,
) -> Result<AcceptanceResult, ReliabilityError> {
    let system = Rectangles::from_study(study)?;
    Acceptance {
        tolerance,
        seed,
        ..Acceptance::default()
    }
    .run(&system)
}

/// The `acceptance` object of a [`ReliabilityDocument`] (spec §4:
/// probability, std_error, method, sensitivity; then samples, converged,
/// tolerance, constraints, rank).
#[derive(Debug, Serialize)]
pub struct AcceptanceDocument<'a> {
    /// P(every toleranced component within tolerance at every point).
    pub probability: f64,
    /// Its standard error.
    pub std_error: f64,
    /// `genz-bretz-qmc` or `monte-carlo`.
    pub method: &'static str,
    /// ∂P/∂σ and ∂P/∂μ of every error parameter.
    pub sensitivity: Vec<AcceptanceSensitivityDocument<'a>>,
    /// Integrand evaluations.
    pub samples: u64,
    /// Whether three standard errors are below the tolerance.
    pub converged: bool,
    /// The absolute error asked for.
    pub tolerance: Option<f64>,
    /// Constraints (points × toleranced components).
    pub constraints: usize,
    /// The rank of the constraints' rows.
    pub rank: usize,
    /// Levels, CoV and pilot of subset simulation (method `subset` only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub subset: Option<&'a crate::acceptance::AcceptanceSubset>,
}

/// One error parameter of [`AcceptanceDocument::sensitivity`].
#[derive(Debug, Serialize)]
pub struct AcceptanceSensitivityDocument<'a> {
    /// The error parameter.
    pub error: &'a str,
    /// ∂P/∂σ.
    pub dr_dstd: f64,
    /// ∂P/∂μ.
    pub dr_dmean: f64,
    /// The standard error of ∂P/∂σ.
    pub dr_dstd_std_error: f64,
    /// The standard error of ∂P/∂μ.
    pub dr_dmean_std_error: f64,
}

impl<'a> AcceptanceDocument<'a> {
    /// The document of an acceptance result.
    pub fn of(a: &'a AcceptanceResult) -> AcceptanceDocument<'a> {
        AcceptanceDocument {
            probability: a.probability,
            std_error: a.std_error,
            method: a.method.name(),
            sensitivity: a
                .sensitivity
                .iter()
                .map(|s| AcceptanceSensitivityDocument {
                    error: &s.error,
                    dr_dstd: s.dr_dstd,
                    dr_dmean: s.dr_dmean,
                    dr_dstd_std_error: s.dr_dstd_std_error,
                    dr_dmean_std_error: s.dr_dmean_std_error,
                })
                .collect(),
            samples: a.samples,
            converged: a.converged,
            tolerance: a.tolerance,
            constraints: a.constraints,
            rank: a.rank,
            subset: a.subset.as_ref(),
        }
    }
}

// ---------------------------------------------------------------------------
// Sobol indices (`chain sobol`, docs/sobol.md).

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
                study
                    .points()
                    .first()
                    .into_iter()
                    .flat_map(|q| q.iter())
                    .copied(),
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

/// A [`ReliabilityError`] worded against the machine file it concerns.
#[derive(Debug, Clone, PartialEq)]
pub struct Described<'e> {
    /// The message, starting with the file (and `:line:column` when located).
    pub message: String,
    /// Where in the file, when the error is located.
    pub origin: Option<&'e Origin>,
    /// The label of the location (empty when not located).
    pub label: &'static str,
    /// How to fix it (empty when there is nothing to add).
    pub help: String,
}

/// The one wording of a reliability error against `file` (the machine file's name).
pub fn describe<'e>(err: &'e ReliabilityError, file: &str) -> Described<'e> {
    let (message, origin, label, help): (String, Option<&Origin>, &str, String) = match err {
        ReliabilityError::MissingStatistic { name, origin } => (
            format!(
                "{file}{}: missing key `statistics.{name}`: error parameter `{name}` has no statistics entry",
                at(origin)
            ),
            Some(origin),
            "used here",
            format!(
                "every error needs a distribution for reliability, e.g.\nstatistics:\n  {name}: {{dist: normal, mean: 0, std: 0.01}}"
            ),
        ),
        ReliabilityError::NoReliabilitySection => (
            format!("{file}: missing key `reliability`: the machine has no reliability section"),
            None,
            "",
            "add, e.g.\nreliability:\n  tolerance: {px: 0.03, py: 0.03, pz: 0.03}\n  sided: upper\n  grid: {x: [0, 500, 1000]}"
                .to_string(),
        ),
        ReliabilityError::SymbolicParameter { name, origin } => (
            format!(
                "{file}{}: parameter `{name}` is symbolic (null) and has no value",
                at(origin)
            ),
            Some(origin),
            "declared without a value",
            format!("give it one on the command line: --param {name}=VALUE"),
        ),
        ReliabilityError::MissingCoordinate(v) => (
            format!("{file}: the reliability grid has no values for axis variable `{v}` (key `reliability.grid.{v}`)"),
            None,
            "",
            format!("add `{v}: [...]` to reliability.grid, or pass --grid {v}=VALUE"),
        ),
        ReliabilityError::GridTooLarge {
            points,
            limit,
            strategy,
            why,
            origin,
        } => (
            format!(
                "{file}{}: key `reliability.grid`: the grid has {points} points; {strategy} runs on at most {limit} ({why})",
                at(origin)
            ),
            Some(origin),
            "the grid of this section",
            format!(
                "allocate on a coarser grid (a copy of the file with at most {limit} grid points), then check the allocated standard deviations on this grid: put them in `statistics` and run `chain reliability`"
            ),
        ),
        other => (format!("{file}: {other}"), None, "", String::new()),
    };
    Described {
        message,
        origin,
        label,
        help,
    }
}

fn at(origin: &Origin) -> String {
    if origin.line > 0 {
        format!(":{}:{}", origin.line, origin.column)
    } else {
        String::new()
    }
}

/// The reliability sensitivities of `chain sensitivity --kind reliability`:
/// at `point` (axis values in the model's variable order) or, with `None`,
/// the mean over the study's grid (FORM settings `form`). With a point, the
/// point is also returned as `(variable, value)` pairs in the grid's axis
/// order, then any other variable (the order the document lists it in).
#[allow(clippy::type_complexity)]
pub fn sensitivity<M: ErrorModel + ?Sized>(
    study: &Study,
    model: &M,
    parameters: &[f64],
    point: Option<&[f64]>,
    form: &Form,
) -> Result<(Option<Vec<(String, f64)>>, Vec<TargetSensitivity>), ReliabilityError> {
    let Some(point) = point else {
        return Ok((None, study.sensitivity_mean(form)?));
    };
    let result = study.sensitivity_point(model, parameters, point, form)?;
    let vars = study.variables();
    let at = study
        .display_order()
        .iter()
        .map(|&i| (vars[i].clone(), point[i]))
        .collect();
    Ok((Some(at), result))
}

/// The document of `chain sensitivity --kind reliability`.
#[derive(Debug, Serialize)]
pub struct SensitivityDocument<'a> {
    /// The machine's name.
    pub machine: &'a str,
    /// The point, or `null` for the grid mean.
    pub at: Option<NameMap<String, f64>>,
    /// Each target's route (exact or FORM).
    pub methods: NameMap<Target, SensitivityMethod>,
    /// Each target's errors, sorted by `|∂R/∂σ|`, largest first.
    pub components: NameMap<Target, Vec<SensitivityErrorDocument<'a>>>,
    /// The posterior the inputs came from (`--values`), when given.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub posterior: Option<&'a Posterior>,
    /// The sensitivities the document was built from (for tables).
    #[serde(skip)]
    pub result: &'a [TargetSensitivity],
}

/// One error of a [`SensitivityDocument`]; the grid mean also has the mean
/// absolute values.
#[derive(Debug, Serialize)]
pub struct SensitivityErrorDocument<'a> {
    /// The error parameter.
    pub error: &'a str,
    /// `∂R/∂σ` (Eq. 33).
    pub dr_dstd: f64,
    /// `∂R/∂μ` (Eq. 32).
    pub dr_dmean: f64,
    /// The FORM importance factor.
    pub importance: f64,
    /// The grid mean of `|∂R/∂σ|` (grid mean only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mean_abs_dr_dstd: Option<f64>,
    /// The grid mean of `|∂R/∂μ|` (grid mean only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mean_abs_dr_dmean: Option<f64>,
}

impl<'a> SensitivityDocument<'a> {
    /// The document of the sensitivities `result`, at the point `at` (or
    /// the grid mean, which adds the mean absolute values), with the
    /// posterior `posterior` when the inputs came from one.
    pub fn new(
        machine: &'a str,
        at: Option<Vec<(String, f64)>>,
        result: &'a [TargetSensitivity],
        posterior: Option<&'a Posterior>,
    ) -> SensitivityDocument<'a> {
        let mean = at.is_none();
        let errors = |t: &'a TargetSensitivity| -> Vec<SensitivityErrorDocument<'a>> {
            t.errors
                .iter()
                .map(|e| SensitivityErrorDocument {
                    error: &e.error,
                    dr_dstd: e.dr_dstd,
                    dr_dmean: e.dr_dmean,
                    importance: e.importance,
                    mean_abs_dr_dstd: mean.then_some(e.mean_abs_dr_dstd),
                    mean_abs_dr_dmean: mean.then_some(e.mean_abs_dr_dmean),
                })
                .collect()
        };
        SensitivityDocument {
            machine,
            at: at.map(NameMap),
            methods: result.iter().map(|t| (t.target, t.method)).collect(),
            components: result.iter().map(|t| (t.target, errors(t))).collect(),
            posterior,
            result,
        }
    }
}

// ---------------------------------------------------------------------------
// `chain allocate`.

/// Runs `chain allocate`: the `strategy` (least cost, or the paper's rounds
/// with their options) for the reliability section's requirement, or, with
/// `level`, for the whole-machine acceptance probability to reach `level`.
pub fn allocation<M: ErrorModel + ?Sized>(
    model: &M,
    parameters: &[f64],
    study: &Study,
    bounds: &[ErrorBounds],
    strategy: AcceptanceStrategy,
    level: Option<f64>,
) -> Result<Allocation, AllocateError> {
    match (level, strategy) {
        (Some(level), strategy) => {
            allocate::acceptance(model, parameters, study, bounds, level, strategy)
        }
        (None, AcceptanceStrategy::Optimal) => {
            allocate::optimal(model, parameters, study, bounds, &Optimal::default())
        }
        (None, AcceptanceStrategy::Paper(paper)) => {
            allocate::paper(model, parameters, study, bounds, &paper)
        }
    }
}

/// The document of `chain allocate` (docs/allocation.md; field order = key order).
#[derive(Debug, Serialize)]
pub struct AllocationDocument<'a> {
    /// The machine's name.
    pub machine: &'a str,
    /// `optimal` or `paper`.
    pub strategy: crate::allocate::StrategyName,
    /// The reliability section's requirement.
    pub requirement: Option<Requirement>,
    /// The standard deviations and summaries before allocation.
    pub initial: InitialDocument<'a>,
    /// The paper's rounds (empty for the optimal strategy).
    pub steps: Vec<StepDocument<'a>>,
    /// The allocated standard deviations, cost and summaries.
    #[serde(rename = "final")]
    pub last: FinalDocument<'a>,
    /// The KKT check (optimal strategy).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub kkt: Option<KktDocument<'a>>,
    /// `--target acceptance`: level, initial and allocated probability.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub acceptance: Option<&'a AcceptanceAllocation>,
}

/// One component's reliability over the grid in an [`AllocationDocument`].
#[derive(Debug, Serialize)]
pub struct AllocationSummaryDocument {
    /// Mean reliability over the grid.
    pub mean: f64,
    /// Smallest reliability.
    pub min: f64,
    /// Largest reliability.
    pub max: f64,
    /// Whether the requirement is met (`null` without one).
    pub met: Option<bool>,
}

/// The starting point of an [`AllocationDocument`].
#[derive(Debug, Serialize)]
pub struct InitialDocument<'a> {
    /// The initial standard deviation of every error.
    pub std: NameMap<&'a str, f64>,
    /// Each component's reliability over the grid.
    pub summary: NameMap<String, AllocationSummaryDocument>,
}

/// One round of the paper's procedure in an [`AllocationDocument`].
#[derive(Debug, Serialize)]
pub struct StepDocument<'a> {
    /// 1, 2, …
    pub round: usize,
    /// The errors tightened this round.
    pub tightened: &'a [String],
    /// Their new standard deviations.
    pub std: NameMap<&'a str, f64>,
    /// Each component's reliability after the round.
    pub summary: NameMap<String, AllocationSummaryDocument>,
}

/// The outcome of an [`AllocationDocument`].
#[derive(Debug, Serialize)]
pub struct FinalDocument<'a> {
    /// The allocated standard deviations.
    pub std: NameMap<&'a str, f64>,
    /// `Σ w (σ0/σ − 1)`.
    pub cost: f64,
    /// Whether the requirement (or the acceptance level) is met.
    pub met: bool,
    /// Each component's reliability (FORM re-evaluation).
    pub summary: NameMap<String, AllocationSummaryDocument>,
}

/// The KKT check of an [`AllocationDocument`].
#[derive(Debug, Serialize)]
pub struct KktDocument<'a> {
    /// `‖∇f − Σ λₖ∇gₖ − z‖∞`.
    pub stationarity: f64,
    /// `max |λₖ gₖ|` and the bounds'.
    pub complementarity: f64,
    /// Constraint and bound violations.
    pub feasibility: f64,
    /// Wrong-signed multipliers.
    pub dual_feasibility: f64,
    /// The largest of the four.
    pub residual: f64,
    /// Whether the active-set Newton polish converged.
    pub polished: bool,
    /// Newton iterations.
    pub iterations: usize,
    /// The active constraints.
    pub active: Vec<ActiveDocument<'a>>,
    /// The errors at a bound.
    pub at_bound: Vec<AtBoundDocument<'a>>,
}

/// An active constraint of a [`KktDocument`].
#[derive(Debug, Serialize)]
pub struct ActiveDocument<'a> {
    /// The constraint.
    pub constraint: &'a str,
    /// Its multiplier.
    pub multiplier: f64,
}

/// An error at a bound in a [`KktDocument`].
#[derive(Debug, Serialize)]
pub struct AtBoundDocument<'a> {
    /// The error.
    pub error: &'a str,
    /// `unchanged` or `min_std`.
    pub bound: &'a str,
    /// The bound's multiplier.
    pub multiplier: f64,
}

/// `{target: {mean, min, max, met}}` of a list of summaries.
fn allocation_summaries(s: &[Summary]) -> NameMap<String, AllocationSummaryDocument> {
    s.iter()
        .map(|s| {
            (
                s.target.to_string(),
                AllocationSummaryDocument {
                    mean: s.mean,
                    min: s.min,
                    max: s.max,
                    met: s.met,
                },
            )
        })
        .collect()
}

/// `{error: std}` of a list of named standard deviations.
fn named_stds(s: &[(String, f64)]) -> NameMap<&str, f64> {
    s.iter().map(|(n, v)| (n.as_str(), *v)).collect()
}

impl<'a> AllocationDocument<'a> {
    /// The document of the allocation `r` of the machine `machine`, started
    /// from `bounds`, for the requirement `requirement`.
    pub fn new(
        machine: &'a str,
        requirement: Option<Requirement>,
        bounds: &'a [ErrorBounds],
        r: &'a Allocation,
    ) -> AllocationDocument<'a> {
        AllocationDocument {
            machine,
            strategy: r.strategy,
            requirement,
            initial: InitialDocument {
                std: bounds.iter().map(|b| (b.error.as_str(), b.std0)).collect(),
                summary: allocation_summaries(&r.initial),
            },
            steps: r
                .steps
                .iter()
                .map(|s| StepDocument {
                    round: s.round,
                    tightened: &s.tightened,
                    std: named_stds(&s.std),
                    summary: allocation_summaries(&s.summaries),
                })
                .collect(),
            last: FinalDocument {
                std: named_stds(&r.std),
                cost: r.cost,
                met: r.met,
                summary: allocation_summaries(&r.summaries),
            },
            kkt: r.kkt.as_ref().map(|k| KktDocument {
                stationarity: k.stationarity,
                complementarity: k.complementarity,
                feasibility: k.feasibility,
                dual_feasibility: k.dual_feasibility,
                residual: k.residual(),
                polished: k.polished,
                iterations: k.iterations,
                active: k
                    .active
                    .iter()
                    .map(|(n, l)| ActiveDocument {
                        constraint: n,
                        multiplier: *l,
                    })
                    .collect(),
                at_bound: k
                    .at_bound
                    .iter()
                    .map(|(n, b, z)| AtBoundDocument {
                        error: n,
                        bound: b,
                        multiplier: *z,
                    })
                    .collect(),
            }),
            acceptance: r.acceptance.as_ref(),
        }
    }
}
