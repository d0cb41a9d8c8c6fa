//! `chain circular` as a request and a document (spec `circular.md`,
//! `docs/circular.md`): an ISO 230-4 circular test evaluated per run and
//! direction. The CLI and `chain.circular` run it.

use serde::Serialize;

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
}

impl Worded for CircularOpsError {
    fn own_code(&self) -> Option<&'static str> {
        Some("chain::circular::option")
    }

    fn own_help(&self) -> Option<String> {
        Some("--radius R (mm) and --feed F (mm/min) apply to runs whose file gives none; --arc DEG (at most 360) the arc every direction covers".to_string())
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

/// Runs `chain circular` on a read run file.
pub fn run(test: &CircularTest) -> Circular {
    Circular {
        file: test.file.clone(),
        unit: "mm",
        centre: "least_squares",
        arc: test.arc,
        runs: circular::evaluate(test),
    }
}
