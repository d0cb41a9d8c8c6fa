//! `chain motion` as a request and a document (docs/motion.md): the CNC
//! axis motions of a machine that reproduce, at every instant of the roll,
//! the tool pose of the generator a settings file describes, checked
//! instant by instant, and their Maclaurin expansion at `t = 0` with its
//! truncation error and the order a tolerance needs. The CLI reads the
//! settings file; Python a path or a dict; both get the same
//! [`MotionDocument`].

use chain_core::conversion::{Conversion, RunOptions};
use chain_core::model::JointKind;
use chain_core::motion::{Law, Matching, Motion, MotionError};
use chain_core::named::NameMap;
use chain_core::settings::{ReferenceError, Settings, SettingsError};
use chain_core::Machine;
use serde::{Serialize, Serializer};

use super::resolve::{self, ResolveError};
use super::worded::{diagnostic, Worded};

/// Highest order accepted for `--order` and `--max-order`: the JSON lists
/// the derivatives `k!·a_k`, and 171! overflows `f64`.
pub const MAX_ORDER: usize = 170;
/// Most instants accepted for `--samples`.
pub const MAX_SAMPLES: usize = 1_000_000;

/// The request of `chain motion`.
#[derive(Debug, Clone, Copy)]
pub struct MotionRequest<'a> {
    /// `--order`: the order of the Maclaurin series.
    pub order: usize,
    /// `--max-order`: the highest order searched for `tolerance`.
    pub max_order: usize,
    /// `--samples`: instants over the roll (both ends included).
    pub samples: usize,
    /// `--tolerance`: the accuracy wanted of the series (model units).
    pub tolerance: Option<f64>,
    /// `--angular-tolerance`: that of the rotary axes (rad).
    pub angular_tolerance: Option<f64>,
    /// `--param NAME=VALUE`: CNC parameters over `cnc.parameters`.
    pub params: &'a [(String, f64)],
    /// `--fix NAME=VALUE`: CNC variables held (matching then the tool point
    /// and axis only).
    pub fix: &'a [(String, f64)],
}

impl Default for MotionRequest<'_> {
    /// The CLI's defaults.
    fn default() -> Self {
        MotionRequest {
            order: 8,
            max_order: 40,
            samples: 1000,
            tolerance: None,
            angular_tolerance: None,
            params: &[],
            fix: &[],
        }
    }
}

/// Why `chain motion` cannot run.
#[derive(Debug, thiserror::Error)]
pub enum MotionOpsError {
    /// `--order` or `--max-order` above [`MAX_ORDER`].
    #[error("--{option} {value} is above the limit {MAX_ORDER}")]
    Order {
        /// `order` or `max-order`.
        option: &'static str,
        /// The value given.
        value: usize,
    },
    /// `--samples` outside `2..=MAX_SAMPLES`.
    #[error("--samples {0} must be between 2 and {MAX_SAMPLES}")]
    Samples(usize),
    /// A tolerance that is not a positive number.
    #[error("--{option} must be a positive number, got {value}")]
    Tolerance {
        /// `tolerance` or `angular-tolerance`.
        option: &'static str,
        /// The value given.
        value: f64,
    },
    /// `--angular-tolerance` without `--tolerance`.
    #[error("--angular-tolerance needs --tolerance")]
    AngularWithoutTolerance,
    /// The generator file (or the settings' reference to it).
    #[error(transparent)]
    Generator(ReferenceError),
    /// The settings do not fit the two machines (located in the settings).
    #[error(transparent)]
    Settings(SettingsError),
    /// `--param` names no CNC parameter, or `--fix` no CNC variable.
    #[error(transparent)]
    Resolve(#[from] ResolveError),
    /// The motion cannot be set up or solved.
    #[error(transparent)]
    Motion(#[from] MotionError),
    /// An instant is unreachable with the variables `--fix` holds.
    #[error("--fix {fix}: {error}")]
    HeldUnreachable {
        /// The `--fix` values, as given.
        fix: String,
        /// The conversion's refusal.
        error: MotionError,
    },
}

/// The options' code, else the inner diagnostic's code, help, source and
/// labels.
impl Worded for MotionOpsError {
    fn own_code(&self) -> Option<&'static str> {
        match self {
            MotionOpsError::Order { .. }
            | MotionOpsError::Samples(_)
            | MotionOpsError::Tolerance { .. }
            | MotionOpsError::AngularWithoutTolerance => Some("chain::cli::invalid_option"),
            MotionOpsError::HeldUnreachable { .. } => Some("chain::motion::unreachable"),
            _ => None,
        }
    }

    fn own_help(&self) -> Option<String> {
        match self {
            MotionOpsError::HeldUnreachable { .. } => Some(
                "hold fewer variables (--fix), or hold them at values from which the generator's pose is reachable".into(),
            ),
            MotionOpsError::Motion(MotionError::Underdetermined { .. }) => Some(
                "hold the others (cnc.fix / --fix, e.g. mu=0) or match the full pose".into(),
            ),
            _ => None,
        }
    }

    #[cfg(feature = "cli")]
    fn inner(&self) -> Option<&dyn miette::Diagnostic> {
        match self {
            MotionOpsError::Generator(e) => Some(e),
            MotionOpsError::Settings(e) => Some(e),
            MotionOpsError::Resolve(e) => Some(e),
            MotionOpsError::Motion(e) => Some(e),
            _ => None,
        }
    }
}

diagnostic!(MotionOpsError);

/// A conversion that fails on the path, located where its cause was given:
/// an instant the CNC machine cannot reach with the variables held by
/// `--fix` (named) or `cnc.fix`, or else at the generator's settings
/// (`values`); a roll it cannot follow continuously at `roll.drive`; other
/// errors as they are.
fn located(settings: &Settings, fix: &[(String, f64)], e: MotionError) -> MotionOpsError {
    use chain_core::diagnostic::{Diagnostics, Problem};
    if matches!(e, MotionError::Unreachable { .. }) && !fix.is_empty() {
        return MotionOpsError::HeldUnreachable {
            fix: (fix.iter())
                .map(|(n, v)| format!("{n}={v}"))
                .collect::<Vec<_>>()
                .join(" --fix "),
            error: e,
        };
    }
    let message = e.to_string();
    let (origin, problem) = match (&e, &settings.fix_origin) {
        (MotionError::Unreachable { .. }, Some(held)) => (
            held,
            MotionProblem::Unreachable {
                message,
                held: true,
            },
        ),
        (MotionError::Unreachable { .. }, None) => (
            &settings.values_origin,
            MotionProblem::Unreachable {
                message,
                held: false,
            },
        ),
        (MotionError::TooFewInstants { variable, .. }, _) => (
            (settings.drive.iter())
                .find(|d| d.name == *variable)
                .map_or(&settings.drive_origin, |d| &d.key),
            MotionProblem::TooFewInstants { message },
        ),
        (MotionError::Discontinuous { .. }, _) => (
            &settings.drive_origin,
            MotionProblem::Discontinuous { message },
        ),
        _ => return MotionOpsError::Motion(e),
    };
    MotionOpsError::Settings(Diagnostics::single(
        settings.file.clone(),
        settings.source.clone(),
        origin.clone(),
        Problem::foreign(problem),
    ))
}

/// A conversion that fails on the path, as a problem of the settings file
/// (codes `chain::motion::*`): the error's own message, located where its
/// cause was given.
#[derive(Debug)]
enum MotionProblem {
    /// The generator's pose is out of the CNC machine's reach; `held`: with
    /// the variables `cnc.fix` holds (located there), else at the generator's
    /// settings.
    Unreachable { message: String, held: bool },
    /// A roll law needs more instants than the run has.
    TooFewInstants { message: String },
    /// The roll cannot be followed continuously.
    Discontinuous { message: String },
}

impl chain_core::diagnostic::Describe for MotionProblem {
    fn describe(&self) -> chain_core::diagnostic::Description {
        use chain_core::diagnostic::Description as D;
        match self {
            MotionProblem::Unreachable {
                message,
                held: true,
            } => D::new("chain::motion::unreachable", "the held variables", message.clone())
                .help("hold fewer variables, or hold them at values from which the generator's pose is reachable".to_string()),
            MotionProblem::Unreachable {
                message,
                held: false,
            } => D::new("chain::motion::unreachable", "the generator's settings", message.clone())
                .help("check these settings against the CNC machine's parameters and strokes, or its `start` guess (cnc.start)".to_string()),
            MotionProblem::TooFewInstants { message } => D::new(
                "chain::motion::too_few_instants",
                "its roll law",
                message.clone(),
            )
            .help("raise --samples to the instants it needs, or check `ratio` and `roll.omega_c` (a roll ratio is a tooth ratio, a few units to a few tens), or shorten `roll.interval`".to_string()),
            MotionProblem::Discontinuous { message } => D::new(
                "chain::motion::discontinuous",
                "the roll",
                message.clone(),
            )
            .help("shorten the roll interval so that it stays on one side of the singular configuration".to_string()),
        }
    }
}

/// The document of `chain motion`: one conversion run with the settings it
/// came from (JSON: docs/motion.md).
#[derive(Debug, Clone)]
pub struct MotionDocument {
    /// The run: the motion, the instants, the exact axes, the series, the
    /// truncation errors, the required order.
    pub conversion: Conversion,
    /// The settings.
    pub settings: Settings,
    /// The CNC parameters used, by name.
    pub cnc_parameters: Vec<(String, f64)>,
    /// Files the caller wrote from the document (the CLI's `--plot`),
    /// listed in the JSON when any.
    pub written: Vec<String>,
}

/// Refuses the options out of range, before anything is read.
pub fn check(request: &MotionRequest<'_>) -> Result<(), MotionOpsError> {
    for (option, value) in [("order", request.order), ("max-order", request.max_order)] {
        if value > MAX_ORDER {
            return Err(MotionOpsError::Order { option, value });
        }
    }
    if !(2..=MAX_SAMPLES).contains(&request.samples) {
        return Err(MotionOpsError::Samples(request.samples));
    }
    for (option, value) in [
        ("tolerance", request.tolerance),
        ("angular-tolerance", request.angular_tolerance),
    ] {
        if let Some(value) = value {
            if !(value.is_finite() && value > 0.0) {
                return Err(MotionOpsError::Tolerance { option, value });
            }
        }
    }
    if request.angular_tolerance.is_some() && request.tolerance.is_none() {
        return Err(MotionOpsError::AngularWithoutTolerance);
    }
    Ok(())
}

/// Runs `chain motion` of the CNC machine `cnc` with `settings`.
pub fn run(
    cnc: &Machine,
    settings: Settings,
    request: &MotionRequest<'_>,
) -> Result<MotionDocument, MotionOpsError> {
    check(request)?;
    resolve::check_parameters(cnc, request.params)?;
    let generator = settings
        .load_generator()
        .map_err(MotionOpsError::Generator)?;
    let mut spec = settings
        .bind(&generator, cnc, request.params)
        .map_err(MotionOpsError::Settings)?;
    if !request.fix.is_empty() {
        spec.matching = Matching::PointAxis;
        spec.fixed.clear();
        for (i, v) in resolve::fixed(cnc, request.fix)? {
            spec.fixed.push((i, v));
            spec.start[i] = v;
        }
    }
    let cnc_parameters: Vec<(String, f64)> = (cnc.parameters.iter())
        .zip(&spec.cnc_parameters)
        .map(|(p, v)| (p.name.clone(), *v))
        .collect();
    let motion = Motion::new(&generator, cnc, spec)?;
    let conversion = Conversion::run(
        motion,
        &RunOptions {
            samples: request.samples,
            order: request.order,
            max_order: request.max_order,
            tolerance: request.tolerance,
            angular_tolerance: request.angular_tolerance,
        },
    )
    .map_err(|e| located(&settings, request.fix, e))?;
    Ok(MotionDocument {
        conversion,
        settings,
        cnc_parameters,
        written: Vec::new(),
    })
}

/// The unit of an axis of kind `kind`.
pub fn unit(kind: JointKind) -> &'static str {
    match kind {
        JointKind::Rotary => "rad",
        JointKind::Prismatic => "mm",
    }
}

/// A value per CNC axis, keyed by the axis variable.
type PerAxis<'a, V> = NameMap<&'a str, V>;

/// The JSON document (field order = key order; docs/motion.md).
#[derive(Serialize)]
struct MotionDoc<'a> {
    machine: &'a str,
    generator: &'a str,
    settings: &'a str,
    #[serde(rename = "match")]
    matching: Matching,
    variables: &'a [String],
    units: PerAxis<'a, &'static str>,
    parameters: NameMap<&'a str, f64>,
    fixed: PerAxis<'a, f64>,
    generator_laws: NameMap<&'a str, Law>,
    interval: [f64; 2],
    samples: usize,
    equivalence: EquivalenceDoc,
    order: usize,
    at_zero: PerAxis<'a, f64>,
    coefficients: PerAxis<'a, &'a [f64]>,
    derivatives: PerAxis<'a, Vec<f64>>,
    truncation_error: PerAxis<'a, f64>,
    errors_by_order: Vec<OrderDoc<'a>>,
    required_order: Option<RequiredDoc<'a>>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    written: Vec<String>,
}

/// The worst pose difference of the two chains over the roll.
#[derive(Serialize)]
struct EquivalenceDoc {
    max_position_error: f64,
    max_rotation_error: f64,
    max_axis_error: f64,
}

/// The truncation error of one order.
#[derive(Serialize)]
struct OrderDoc<'a> {
    order: usize,
    max_error: PerAxis<'a, f64>,
}

/// The order a tolerance needs.
#[derive(Serialize)]
struct RequiredDoc<'a> {
    tolerance: PerAxis<'a, f64>,
    searched_up_to: usize,
    all: Option<usize>,
    per_axis: PerAxis<'a, Option<usize>>,
}

impl Serialize for MotionDocument {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let run = &self.conversion;
        let m = &run.motion;
        let names = || m.variables().iter().map(String::as_str);
        let n = run.order;
        MotionDoc {
            machine: m.cnc_name(),
            generator: m.generator_name(),
            settings: &self.settings.name,
            matching: m.matching(),
            variables: m.variables(),
            units: NameMap::zip(names(), m.kinds().iter().map(|k| unit(*k))),
            parameters: self
                .cnc_parameters
                .iter()
                .map(|(k, v)| (k.as_str(), *v))
                .collect(),
            fixed: m
                .fixed()
                .iter()
                .map(|&(i, v)| (m.variables()[i].as_str(), v))
                .collect(),
            generator_laws: NameMap::zip(
                m.generator_variables().iter().map(String::as_str),
                m.laws().iter().copied(),
            ),
            interval: [m.interval().0, m.interval().1],
            samples: run.times.len(),
            equivalence: EquivalenceDoc {
                max_position_error: run.worst.position,
                max_rotation_error: run.worst.rotation,
                max_axis_error: run.worst.axis,
            },
            order: n,
            at_zero: NameMap::zip(names(), run.series.axes.iter().map(|j| j.value())),
            coefficients: NameMap::zip(
                names(),
                run.series.axes.iter().map(|j| &j.coefficients()[..=n]),
            ),
            derivatives: NameMap::zip(
                names(),
                run.series
                    .axes
                    .iter()
                    .map(|j| (0..=n).map(|k| j.derivative(k)).collect()),
            ),
            truncation_error: NameMap::zip(names(), run.truncation_error().iter().copied()),
            errors_by_order: run
                .errors
                .iter()
                .enumerate()
                .map(|(order, e)| OrderDoc {
                    order,
                    max_error: NameMap::zip(names(), e.iter().copied()),
                })
                .collect(),
            required_order: run.required.as_ref().map(|r| RequiredDoc {
                tolerance: NameMap::zip(names(), r.tolerance.iter().copied()),
                searched_up_to: r.searched_up_to,
                all: r.all,
                per_axis: NameMap::zip(names(), r.per_axis.iter().copied()),
            }),
            written: self.written.clone(),
        }
        .serialize(serializer)
    }
}
