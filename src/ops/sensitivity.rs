//! `chain sensitivity` as a request and a document: the reliability
//! sensitivity of each toleranced component to the mean and standard
//! deviation of every error (seed 000, Eq. 32-33; docs/sensitivity.md), or
//! the geometric error sensitivity coefficients `S = |∂E/∂e|`,
//! `C = S·e / ΣS·e` (seed 004, Eq. 4-6; docs/geometric_sensitivity.md), at
//! one point or over the grid. The CLI and `Machine.sensitivity_reliability`
//! / `Machine.geometric_sensitivity` build the same [`SensitivityRequest`].

use std::path::Path;

use chain_core::geometric::{self, GeometricDocument, GeometricSensitivity, NominalSizes, Where};
use chain_core::model::Sided;
use chain_core::named::NameMap;
use chain_core::values::Approach;
use chain_core::Machine;
use reliability::{
    Form, Posterior, ReliabilityError, SensitivityMethod, Target, TargetSensitivity,
};
use serde::{Serialize, Serializer};

use super::resolve::{self, ResolveError};
use super::study::{self, OptionError, StudyError, StudyOptions};
use super::worded::{diagnostic, Worded};

/// What `chain sensitivity` computes (`--kind`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SensitivityKind {
    /// Reliability sensitivity to each error's mean and standard deviation.
    #[default]
    Reliability,
    /// Geometric error sensitivity coefficients (seed 004).
    Geometric,
}

/// What `--values` gives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SensitivityValues<'a> {
    /// A values file: the posterior of a calibration (`--kind reliability`).
    File(&'a Path),
    /// Nominal error sizes (`--kind geometric`).
    Nominal(NominalSizes),
}

/// The request of `chain sensitivity`.
#[derive(Debug, Clone, Copy, Default)]
pub struct SensitivityRequest<'a> {
    /// `--kind`.
    pub kind: SensitivityKind,
    /// `--at`: one point, every axis variable by name; `None`: the grid.
    pub at: Option<&'a [(String, f64)]>,
    /// `--param NAME=VALUE`.
    pub params: &'a [(String, f64)],
    /// `--sided` (`--kind reliability`).
    pub sided: Option<Sided>,
    /// `--grid VAR=...`: the grid of the mean.
    pub grid: &'a [(String, Vec<f64>)],
    /// `--values`.
    pub values: Option<SensitivityValues<'a>>,
    /// `--approach` (`--kind reliability` with a values file).
    pub approach: &'a [(Option<String>, Approach)],
    /// `--temperature NAME=VALUE` (`--kind reliability`): the thermal state.
    pub temperatures: &'a [(String, f64)],
}

/// Why `chain sensitivity` cannot run.
#[derive(Debug, thiserror::Error)]
pub enum SensitivityOpsError {
    /// An option the chosen kind does not take.
    #[error("{message}")]
    Kind {
        /// What is refused.
        message: String,
        /// What to give instead.
        help: &'static str,
    },
    /// An option does not match the machine.
    #[error(transparent)]
    Resolve(#[from] ResolveError),
    /// An option refused before anything is read.
    #[error(transparent)]
    Option(#[from] OptionError),
    /// The study (the machine's sections, the options, the posterior).
    #[error(transparent)]
    Study(Box<StudyError>),
    /// The evaluation (located in the machine file by [`study::describe`]).
    #[error(transparent)]
    Reliability(#[from] ReliabilityError),
}

impl From<StudyError> for SensitivityOpsError {
    fn from(e: StudyError) -> SensitivityOpsError {
        SensitivityOpsError::Study(Box::new(e))
    }
}

impl Worded for SensitivityOpsError {
    fn own_code(&self) -> Option<&'static str> {
        matches!(self, SensitivityOpsError::Kind { .. }).then_some("chain::sensitivity::option")
    }

    fn own_help(&self) -> Option<String> {
        match self {
            SensitivityOpsError::Kind { help, .. } => Some(help.to_string()),
            SensitivityOpsError::Resolve(e) => e.own_help(),
            _ => None,
        }
    }

    #[cfg(feature = "cli")]
    fn inner(&self) -> Option<&dyn miette::Diagnostic> {
        match self {
            SensitivityOpsError::Resolve(e) => Some(e),
            SensitivityOpsError::Option(e) => Some(e),
            _ => None,
        }
    }
}

diagnostic!(SensitivityOpsError);

/// The document of `chain sensitivity`.
#[derive(Debug, Clone)]
pub enum SensitivityReport {
    /// `--kind reliability`.
    Reliability(Box<ReliabilitySensitivity>),
    /// `--kind geometric`.
    Geometric(GeometricReport),
}

/// The reliability sensitivities (JSON: their [`SensitivityDocument`]).
#[derive(Debug, Clone)]
pub struct ReliabilitySensitivity {
    /// The machine.
    pub machine: String,
    /// The point, or `None` for the grid mean.
    pub at: Option<Vec<(String, f64)>>,
    /// Per target, the errors sorted by `|∂R/∂σ|`.
    pub result: Vec<TargetSensitivity>,
    /// The posterior of `--values`.
    pub posterior: Option<Posterior>,
    /// The inputs' names, in the study's order.
    pub inputs: Vec<String>,
}

/// The geometric coefficients (JSON: the library's [`GeometricDocument`]).
#[derive(Debug, Clone)]
pub struct GeometricReport {
    /// The machine.
    pub machine: String,
    /// The point or the grid.
    pub where_: Where,
    /// The nominal error sizes.
    pub nominal: NominalSizes,
    /// The coefficients.
    pub result: GeometricSensitivity,
}

impl Serialize for SensitivityReport {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        match self {
            SensitivityReport::Reliability(r) => {
                SensitivityDocument::new(&r.machine, r.at.clone(), &r.result, r.posterior.as_ref())
                    .serialize(serializer)
            }
            SensitivityReport::Geometric(g) => {
                GeometricDocument::new(&g.machine, &g.where_, &g.nominal, &g.result)
                    .serialize(serializer)
            }
        }
    }
}

/// Runs `chain sensitivity` of `machine` (`file` names it).
pub fn run(
    machine: &Machine,
    file: &str,
    request: &SensitivityRequest<'_>,
) -> Result<SensitivityReport, SensitivityOpsError> {
    check(request)?;
    resolve::check_parameters(machine, request.params)?;
    match request.kind {
        SensitivityKind::Reliability => reliability_kind(machine, file, request),
        SensitivityKind::Geometric => geometric_kind(machine, file, request),
    }
}

/// Refuses the options the chosen kind does not take, before anything is
/// read.
pub fn check(request: &SensitivityRequest<'_>) -> Result<(), SensitivityOpsError> {
    let refuse = |message: String, help| Err(SensitivityOpsError::Kind { message, help });
    match (request.kind, &request.values) {
        (SensitivityKind::Reliability, Some(SensitivityValues::Nominal(_))) => refuse(
            "--values applies only to --kind geometric when it gives nominal sizes (KIND=VALUE)"
                .into(),
            "add --kind geometric, or give a values file for the posterior",
        ),
        (SensitivityKind::Geometric, _) if !request.temperatures.is_empty() => refuse(
            "--kind geometric does not take --temperature".into(),
            "the geometric coefficients S and C are those of the geometry; the thermal state of a study is --kind reliability --temperature NAME=VALUE",
        ),
        (SensitivityKind::Geometric, _) if !request.approach.is_empty() => refuse(
            "--kind geometric does not take --approach".into(),
            "--approach chooses the direction of a values file's tables: use it with --kind reliability --values VALUES.yaml",
        ),
        (SensitivityKind::Geometric, Some(SensitivityValues::File(f))) => refuse(
            format!(
                "--values {}: a values file applies to --kind reliability (the posterior of a calibration)",
                f.display()
            ),
            "give nominal sizes, e.g. --values linear=0.001,angular=0.001deg, or use --kind reliability for a posterior",
        ),
        (SensitivityKind::Geometric, _) if request.at.is_some() && !request.grid.is_empty() => {
            Err(ResolveError::AtWithGrid {
                grid_for: "the mean",
            }
            .into())
        }
        (SensitivityKind::Reliability, None) => {
            Ok(study::check_approach(None, request.approach)?)
        }
        _ => Ok(()),
    }
}

fn reliability_kind(
    machine: &Machine,
    file: &str,
    request: &SensitivityRequest<'_>,
) -> Result<SensitivityReport, SensitivityOpsError> {
    let posterior = match request.values {
        Some(SensitivityValues::File(path)) => {
            Some(study::read_posterior(machine, path, request.approach)?)
        }
        _ => None,
    };
    let options = StudyOptions {
        params: request.params,
        grid: request.grid,
        sided: request.sided,
        system: None,
        posterior: posterior.as_ref(),
        temperatures: request.temperatures,
    };
    let checked = study::check(machine, file, &options)?;
    let point = match request.at {
        Some(coords) => Some(resolve::at_point(machine, file, coords)?),
        None => None,
    };
    let model = chain_core::compile(machine);
    let study = study::build(machine, &model, checked, &options)?;
    let values = reliability::machine::parameters(machine, request.params)?;
    let form = Form::default();
    let (at, result) = match point {
        None => (None, study.sensitivity_mean(&form)?),
        Some(point) => {
            let result =
                (study.sensitivity_point(&model, &values, &point, &form)).map_err(|e| match e {
                    ReliabilityError::InputsVaryAtPoint => ResolveError::AtVaryingInputs.into(),
                    e => SensitivityOpsError::from(e),
                })?;
            // The point as the document lists it: the grid's axes in file
            // order, then any other variable.
            let vars = study.variables();
            let at = (study.display_order().iter())
                .map(|&i| (vars[i].clone(), point[i]))
                .collect();
            (Some(at), result)
        }
    };
    Ok(SensitivityReport::Reliability(Box::new(
        ReliabilitySensitivity {
            machine: machine.name.clone(),
            at,
            result,
            posterior,
            inputs: study.inputs().names().to_vec(),
        },
    )))
}

fn geometric_kind(
    machine: &Machine,
    file: &str,
    request: &SensitivityRequest<'_>,
) -> Result<SensitivityReport, SensitivityOpsError> {
    let m = machine;
    let params = reliability::machine::parameters(m, request.params)?;
    let nominal = match request.values {
        Some(SensitivityValues::Nominal(n)) => n,
        _ => NominalSizes::default(),
    };
    let where_ = match request.at {
        Some(coords) => {
            let point = resolve::at_point(m, file, coords)?;
            Where::At(
                (m.variables.iter().map(|v| v.name.clone()))
                    .zip(point)
                    .collect(),
            )
        }
        None => Where::Grid(resolve::grid_axes(m, file, request.grid)?),
    };
    let model = chain_core::compile(m);
    let result = geometric::evaluate(&model, &where_, &params, &nominal.of(m));
    Ok(SensitivityReport::Geometric(GeometricReport {
        machine: m.name.clone(),
        where_,
        nominal,
        result,
    }))
}

/// The document of `chain sensitivity --kind reliability` (its JSON).
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
