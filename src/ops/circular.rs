//! `chain circular` as a request and a document (spec `circular.md`,
//! `docs/circular.md`): an ISO 230-4 circular test evaluated per run and
//! direction. The CLI and `chain.circular` run it.

use serde::Serialize;

use chain_core::measured::circular::diagnosis::{self, Diagnosed, DiagnosisOptions, PlaneFit};
use chain_core::measured::circular::{self, CircularTest, Plane, RunOptions, RunResult};

use super::worded::{diagnostic, Worded};

/// What `chain circular` gives: the document of the spec.
#[derive(Debug, Clone, Serialize)]
pub struct Circular {
    /// The run file as named in messages.
    pub file: String,
    /// The unit of every length (`mm`).
    pub unit: &'static str,
    /// The centre each direction is evaluated about: `least_squares`
    /// (ISO 230-4's LSC; the set-up offset removed).
    pub centre: &'static str,
    /// The arc each direction covers (degrees).
    pub arc: f64,
    /// Each run evaluated, in the file's order.
    pub runs: Vec<RunResult>,
    /// Every error diagnosed (`docs/circular.md`, "The fit"), plane by
    /// plane: its value, unit, uncertainty, sign convention and share of G.
    pub diagnosis: Vec<Diagnosed>,
    /// Each plane's fit: the samples, what was not fitted and why, what the
    /// runs separate only weakly, each run's centres, radius offset and
    /// residual.
    pub fit: Vec<PlaneFit>,
}

/// Why the options of `chain circular` are refused.
#[derive(Debug, thiserror::Error)]
pub enum CircularOpsError {
    /// A `--radius`, `--feed` or `--arc` out of its range.
    #[error("--{option} {value}: {rule}")]
    Option {
        /// The option, without its dashes.
        option: &'static str,
        /// As given.
        value: f64,
        /// What it must be.
        rule: &'static str,
    },
    /// A `--plane` other than `xy`, `yz`, `zx`.
    #[error("--plane {0}: expected xy, yz or zx")]
    Plane(String),
    /// A `--pitch` naming no axis, or one twice, or not a positive length.
    #[error("--pitch {axis}={pitch}: {rule}")]
    Pitch {
        /// The axis as given.
        axis: String,
        /// The pitch as given.
        pitch: f64,
        /// What it must be.
        rule: &'static str,
    },
}

impl Worded for CircularOpsError {
    fn own_code(&self) -> Option<&'static str> {
        Some("chain::circular::option")
    }

    fn own_help(&self) -> Option<String> {
        Some("--radius R (mm) and --feed F (mm/min) apply to runs whose file gives none; --arc DEG (at most 360) the arc every direction covers; --pitch AXIS=MM the pitch of an axis's cyclic error (x, y or z, once each); --window DEG the spike window after each reversal (more than 0, less than 45)".to_string())
    }
}

diagnostic!(CircularOpsError);

/// The options every run takes where the file gives none, checked.
pub fn options(
    radius: Option<f64>,
    feed: Option<f64>,
    plane: Option<&str>,
    arc: Option<f64>,
) -> Result<RunOptions, CircularOpsError> {
    let positive = |option: &'static str, v: Option<f64>| match v {
        Some(x) if !(x.is_finite() && x > 0.0) => Err(CircularOpsError::Option {
            option,
            value: x,
            rule: "must be a positive number",
        }),
        _ => Ok(v),
    };
    let arc = match arc {
        Some(a) if !(a.is_finite() && (circular::MIN_ARC..=360.0).contains(&a)) => {
            return Err(CircularOpsError::Option {
                option: "arc",
                value: a,
                rule: "must be in [45, 360] degrees",
            })
        }
        Some(a) => a,
        None => 360.0,
    };
    let plane = match plane {
        Some(p) => Plane::parse(p).ok_or_else(|| CircularOpsError::Plane(p.to_string()))?,
        None => Plane::Xy,
    };
    Ok(RunOptions {
        radius: positive("radius", radius)?,
        feed: positive("feed", feed)?,
        plane,
        arc,
    })
}

/// The options of the diagnosis, checked: per machine axis (`x`, `y`,
/// `z`, once each) the pitch (mm) of its cyclic error, and the spike window
/// (degrees, default [`diagnosis::SPIKE_WINDOW`]).
pub fn diagnosis_options(
    pitch: &[(String, f64)],
    window: Option<f64>,
) -> Result<DiagnosisOptions, CircularOpsError> {
    let mut options = DiagnosisOptions::default();
    for (axis, p) in pitch {
        let refuse = |rule| CircularOpsError::Pitch {
            axis: axis.clone(),
            pitch: *p,
            rule,
        };
        let i = match axis.to_ascii_lowercase().as_str() {
            "x" => 0,
            "y" => 1,
            "z" => 2,
            _ => return Err(refuse("the axis must be x, y or z")),
        };
        if !(p.is_finite() && *p > 0.0) {
            return Err(refuse("the pitch must be a positive length (mm)"));
        }
        if options.pitch[i].replace(*p).is_some() {
            return Err(refuse("the axis is given twice"));
        }
    }
    if let Some(w) = window {
        if !(w.is_finite() && w > 0.0 && w < 45.0) {
            return Err(CircularOpsError::Option {
                option: "window",
                value: w,
                rule: "must be more than 0 and less than 45 degrees",
            });
        }
        options.window = w;
    }
    Ok(options)
}

/// Runs `chain circular` on a read run file: the evaluation and the
/// diagnosis.
pub fn run(test: &CircularTest, options: &DiagnosisOptions) -> Circular {
    let runs = circular::evaluate(test);
    let diagnosis = diagnosis::diagnose(test, &runs, options);
    Circular {
        file: test.file.clone(),
        unit: "mm",
        centre: "least_squares",
        arc: test.arc,
        runs,
        diagnosis: diagnosis.entries,
        fit: diagnosis.planes,
    }
}
