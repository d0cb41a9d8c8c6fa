//! The result documents of a reliability study: what `chain reliability
//! --format json` prints and what the Python package's `to_dict()` returns,
//! built in one place from a [`Study`] and its [`StudyResult`].
//!
//! The documents are plain serialisable structs (their fields, in
//! declaration order, are the JSON keys); the binary adds its table and CSV
//! forms on top, the Python bindings serialise them as they are.
//!
//! [`describe`] is the one wording of a [`ReliabilityError`] against the
//! machine file it concerns (message, location, label, help), shared by the
//! binary's diagnostics and the Python exceptions.

use chain_core::model::{Origin, Sided};
use chain_core::named::NameMap;
use serde::Serialize;

use crate::{
    Calls, FormCase, Method, Posterior, ReliabilityError, SormCase, Stopping, Study, StudyResult,
    SubsetLevel, Target,
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
    /// Every case, target-major.
    pub results: Vec<CaseDocument<'a>>,
    /// Each target's summary over the grid.
    pub summary: NameMap<Target, SummaryDocument>,
    /// The requirement and whether every target meets it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub requirement: Option<RequirementDocument>,
    /// The posterior the inputs came from (a calibration's values file), when given.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub posterior: Option<&'a Posterior>,
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
        let results = r
            .cases
            .iter()
            .map(|c| CaseDocument {
                component: c.target,
                point: NameMap(ax.iter().map(|&(n, i)| (n, c.point[i])).collect()),
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
                sorm: c.sorm.as_ref(),
            })
            .collect();
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
