//! `chain thermal` as a request and a document (spec `thermal.md`,
//! `docs/thermal.md`): the ISO 230-3 drift test's evaluation and, with a
//! fit, the thermal model per displacement channel and its prediction, and
//! with `into_machine` those models as a machine's thermal coefficients.
//! The CLI and `chain.thermal` run it.

use serde::Serialize;

use chain_core::measured::thermal::{self, DriftTest, Pair, ThermalDocument, ThermalError};
use chain_core::measured::thermal_fit::{self, FitError, FitOptions, Prediction};
use chain_core::measured::thermal_values::{self, ThermalValues, ThermalValuesError};

use super::worded::{diagnostic, Worded};

/// The request of `chain thermal`.
#[derive(Debug, Clone)]
pub struct ThermalRequest<'a> {
    /// The drift test, read (and checked) from a file or text.
    pub test: &'a DriftTest,
    /// `--pair X1:X2=L`.
    pub pairs: &'a [Pair],
    /// `--fit` and its options.
    pub fit: Option<FitOptions>,
    /// `--values-out` with `--machine` and `--slot`: the fitted models into
    /// a machine's thermal terms.
    pub into_machine: Option<IntoMachine<'a>>,
}

/// `--machine F --slot NAME=CHANNEL,...`: which channel's model each
/// thermal term of the machine takes (docs/thermal.md).
#[derive(Debug, Clone, Copy)]
pub struct IntoMachine<'a> {
    /// The machine.
    pub machine: &'a chain_core::Machine,
    /// `(term, channel)` per `--slot`.
    pub slots: &'a [(String, String)],
}

/// What `chain thermal` gives: the document (its JSON), and with a fit the
/// measured and predicted drift of every channel at every sample (its
/// CSV).
#[derive(Debug, Clone, Serialize)]
pub struct Thermal {
    /// The document of the spec.
    #[serde(flatten)]
    pub document: ThermalDocument,
    /// Per displacement channel, with a fit: the drift and the model's
    /// prediction at every sample.
    #[serde(skip)]
    pub predictions: Vec<Prediction>,
    /// The samples' times (s).
    #[serde(skip)]
    pub time: Vec<f64>,
    /// The thermal coefficients written for the machine (`--values-out`):
    /// per term its coefficients (µm/K) and the intercept left out.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub values: Option<ThermalValues>,
}

/// Why `chain thermal` cannot run as asked.
#[derive(Debug, thiserror::Error)]
pub enum ThermalOpsError {
    /// A `--pair` that does not fit the file (its message is the
    /// library's, not shown again as a cause).
    #[error("--pair: {0}")]
    Pair(ThermalError),
    /// The fit's options or data.
    #[error("--fit: {0}")]
    Fit(FitError),
    /// `--slot`: a fitted model that does not go into the machine's term.
    #[error("--slot: {0}")]
    Slot(Box<ThermalValuesError>),
    /// `--slot` that is not `NAME=CHANNEL`.
    #[error("--slot {0}: expected NAME=CHANNEL (a thermal term of the machine and a displacement channel)")]
    SlotText(String),
    /// `--values-out` without `--fit`, or without `--machine` and `--slot`.
    #[error("{0}")]
    ValuesOut(&'static str),
    /// A `--pair` that is not `X1:X2=L`.
    #[error("--pair {text}: {reason}")]
    PairText {
        /// As given.
        text: String,
        /// What is wrong.
        reason: String,
    },
}

impl From<ThermalError> for ThermalOpsError {
    fn from(e: ThermalError) -> Self {
        ThermalOpsError::Pair(e)
    }
}

impl From<FitError> for ThermalOpsError {
    fn from(e: FitError) -> Self {
        ThermalOpsError::Fit(e)
    }
}

impl Worded for ThermalOpsError {
    fn own_code(&self) -> Option<&'static str> {
        Some(match self {
            ThermalOpsError::Pair(_) | ThermalOpsError::PairText { .. } => "chain::thermal::pair",
            ThermalOpsError::Fit(_) => "chain::thermal::fit",
            ThermalOpsError::Slot(_) | ThermalOpsError::SlotText(_) => "chain::thermal::slot",
            ThermalOpsError::ValuesOut(_) => "chain::thermal::values_out",
        })
    }

    fn own_help(&self) -> Option<String> {
        match self {
            ThermalOpsError::Pair(_) | ThermalOpsError::PairText { .. } => Some(
                "a pair is two displacement channels and their distance in mm: --pair 'X1(um):X2(um)=100', the first the sensor nearer the spindle nose".to_string(),
            ),
            ThermalOpsError::Fit(e) => e.help(),
            ThermalOpsError::Slot(_) | ThermalOpsError::SlotText(_) | ThermalOpsError::ValuesOut(_) => Some(
                "--values-out V --machine F --slot EZS='Z(um)' writes the model of channel Z(um) as the coefficients of the machine's thermal term `{name: EZS, per: [...]}` (docs/thermal.md)".to_string(),
            ),
        }
    }
}

diagnostic!(ThermalOpsError);

/// A pair `X1:X2=L` (the sensors' names and their distance in mm).
pub fn parse_pair(text: &str) -> Result<Pair, ThermalOpsError> {
    let refuse = |reason: &str| ThermalOpsError::PairText {
        text: text.to_string(),
        reason: reason.to_string(),
    };
    let (names, distance) = text
        .rsplit_once('=')
        .ok_or_else(|| refuse("expected X1:X2=L (L the sensors' distance in mm)"))?;
    let distance: f64 = distance
        .trim()
        .parse()
        .map_err(|_| refuse(&format!("`{}` is not a distance in mm", distance.trim())))?;
    let parts: Vec<&str> = names.split(':').collect();
    let [first, second] = parts[..] else {
        return Err(refuse("expected two channel names separated by one `:`"));
    };
    Ok(Pair {
        first: first.trim().to_string(),
        second: second.trim().to_string(),
        distance,
    })
}

/// Runs `chain thermal`.
pub fn run(request: &ThermalRequest<'_>) -> Result<Thermal, ThermalOpsError> {
    let mut document = thermal::evaluate(request.test, request.pairs)?;
    let mut predictions = Vec::new();
    if let Some(options) = &request.fit {
        let fitted = thermal_fit::fit(request.test, options)?;
        fitted.into_document(&mut document);
        predictions = fitted.predictions;
    }
    let values = match request.into_machine {
        Some(into) => {
            if request.fit.is_none() {
                return Err(ThermalOpsError::ValuesOut(
                    "--values-out writes the fitted models: give --fit",
                ));
            }
            if into.slots.is_empty() {
                return Err(ThermalOpsError::ValuesOut(
                    "--values-out needs --slot NAME=CHANNEL: which thermal term takes which channel's model",
                ));
            }
            Some(
                thermal_values::thermal_values(into.machine, &document, into.slots)
                    .map_err(|e| ThermalOpsError::Slot(Box::new(e)))?,
            )
        }
        None => None,
    };
    Ok(Thermal {
        document,
        predictions,
        time: request.test.time.clone(),
        values,
    })
}

/// `--slot NAME=CHANNEL`.
pub fn parse_slot(text: &str) -> Result<(String, String), ThermalOpsError> {
    match text.split_once('=') {
        Some((name, channel)) if !name.trim().is_empty() && !channel.trim().is_empty() => {
            Ok((name.trim().to_string(), channel.trim().to_string()))
        }
        _ => Err(ThermalOpsError::SlotText(text.to_string())),
    }
}
