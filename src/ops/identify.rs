//! `chain identify` as a request and a document (measured-machines spec
//! §4; docs/identify.md): the error parameters of a built machine from
//! measurements, by weighted least squares through an SVD or the posterior
//! of the `statistics` prior, with the values file `--values-out` writes.
//! The measurements are read by the adapter (a file for the CLI, a path or
//! columns for Python) through `chain_core::measured::Measurements`.

use chain_core::measured::document::{
    identify_document, values_file, DocumentError, IdentifyDocument,
};
use chain_core::measured::{Holdout, HoldoutError, Identification, IdentifyOptions, Measurements};
use chain_core::Machine;
use serde::{Serialize, Serializer};

/// The request of `chain identify`.
#[derive(Debug, Clone, Default)]
pub struct IdentifyRequest<'a> {
    /// `--prior`: the machine file's `statistics` as a Gaussian prior.
    pub prior: bool,
    /// `--rank-tol`, `--fix`, `--estimate`: the rank rule and the
    /// estimated subset.
    pub options: IdentifyOptions,
    /// `--iterate`: fit the exact kinematics from the linear estimate.
    pub iterate: bool,
    /// `--holdout FRACTION --seed S`: records of the measurements held out
    /// of the fit, where the estimates' prediction is reported (not with
    /// `validation`).
    pub holdout: Option<Holdout>,
    /// `--validate`: measurements held out of the fit, where the estimates'
    /// prediction is reported.
    pub validation: Option<&'a Measurements>,
}

/// The document of `chain identify` (JSON: [`IdentifyDocument`]) with the
/// identification and the values file it gives.
#[derive(Debug, Clone)]
pub struct IdentifyRun {
    /// The spec's document.
    pub document: IdentifyDocument,
    /// The identification.
    pub result: Identification,
    /// The values file of the estimates (`--values-out`).
    pub values_text: String,
}

impl Serialize for IdentifyRun {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        self.document.serialize(serializer)
    }
}

/// The checks of `chain identify`'s options that need no file (the CLI
/// and Python run them before reading the machine and the measurements):
/// `--rank-tol`, `--fix`/`--estimate` with `--prior`, `--iterate` with
/// `--prior`, `--holdout` with `--validate` (the fraction is checked where
/// the [`Holdout`] is made).
pub fn check_options(
    prior: bool,
    options: &IdentifyOptions,
    iterate: bool,
    holdout: Option<Holdout>,
    validate: bool,
) -> Result<(), DocumentError> {
    options.check(prior)?;
    if iterate && prior {
        return Err(chain_core::measured::IdentifyError::IterateWithPrior.into());
    }
    if holdout.is_some() && validate {
        return Err(HoldoutError {
            message: "cannot be given with --validate (one holds records of the measurements out, the other reads them from a file)".into(),
        }
        .into());
    }
    Ok(())
}

/// Runs `chain identify` of `machine` over `measurements`.
pub fn run(
    machine: &Machine,
    measurements: &Measurements,
    request: &IdentifyRequest<'_>,
) -> Result<IdentifyRun, DocumentError> {
    check_options(
        request.prior,
        &request.options,
        request.iterate,
        request.holdout,
        request.validation.is_some(),
    )?;
    let split = match request.holdout {
        Some(h) => Some(measurements.holdout(h.fraction, h.seed)?),
        None => None,
    };
    let (fitted, validation) = match &split {
        Some((fit, held)) => (fit, Some(held)),
        None => (measurements, request.validation),
    };
    let mut identified = identify_document(
        machine,
        fitted,
        request.prior,
        &request.options,
        request.iterate,
        validation,
    )?;
    if let (Some(v), Some((_, held))) = (identified.document.validation.as_mut(), &split) {
        v.holdout = request.holdout;
        v.lines = Some(held.rows.iter().map(|r| r.line).collect());
    }
    let values_text = values_file(machine, &measurements.file, &identified);
    Ok(IdentifyRun {
        document: identified.document,
        result: identified.result,
        values_text,
    })
}
