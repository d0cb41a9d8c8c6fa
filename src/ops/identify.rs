//! `chain identify` as a request and a document (measured-machines spec
//! §4; docs/identify.md): the error parameters of a built machine from
//! measurements, by weighted least squares through an SVD or the posterior
//! of the `statistics` prior, with the values file `--values-out` writes.
//!
//! One entry for the CLI and Python: an [`IdentifyRequest`] holds the
//! options as given and where the measurement files come from (a path, or
//! bytes the caller holds: Python's CSV text); [`IdentifyRequest::check`]
//! assembles and checks the options with no file read and no machine, so
//! that both refuse a bad option first; [`CheckedIdentify::run`] checks
//! the parameters against the machine, reads the measurement files and
//! runs. Every refusal is worded here in the options' names
//! ([`IdentifyOpsError`]), the library's error kept for its code. The
//! document and the values file are [`document`]'s.

pub mod document;

#[cfg(feature = "records")]
use chain_core::measured::circular::records::{centre_pose, CirclePose};
#[cfg(feature = "records")]
use chain_core::measured::circular::RunOptions;
use chain_core::measured::SetupKind;
use chain_core::measured::{
    DesignError, HoldoutError, Identification, IdentifyError, IdentifyOptions, MeasurementsError,
    SubsetSide,
};
#[cfg(feature = "records")]
use chain_core::measured::{Holdout, Layout, Measurements, Setup, SubsetChoice};
#[cfg(feature = "records")]
use chain_core::Machine;
use serde::{Serialize, Serializer};

pub use document::{identify_document, values_file, Identified, IdentifyDocument};

use super::resolve::ResolveError;
#[cfg(feature = "records")]
use super::source::Source;
use super::worded::{diagnostic, Worded};

/// The request of `chain identify`: the options as the CLI and Python take
/// them, and the measurement files.
#[cfg(feature = "records")]
#[derive(Debug, Clone)]
pub struct IdentifyRequest<'a> {
    /// `--measurements`: the measurement CSV (this or `spheres`).
    pub measurements: Option<Source<'a>>,
    /// `--spheres`: a sphere-probing CSV (five-axis spec), whose spheres'
    /// positions are estimated beside the errors (this or
    /// `measurements`).
    pub spheres: Option<Source<'a>>,
    /// `--setup ball`: every measurement record is taken against one
    /// R-test ball whose set-up offsets are estimated (with
    /// `measurements` only).
    pub setup: Option<SetupKind>,
    /// `--validate`: records held out of the fit (the same columns as the
    /// fitted file, the same spheres), where the estimates' prediction is
    /// reported.
    pub validate: Option<Source<'a>>,
    /// `--param NAME=VALUE`: the parameters the CSVs have no column for.
    pub params: &'a [(String, f64)],
    /// `--prior`: the machine file's `statistics` as a Gaussian prior.
    pub prior: bool,
    /// `--rank-tol`: a fixed relative tolerance on the singular values
    /// instead of the noise rule.
    pub rank_tol: Option<f64>,
    /// `--fix`: the error parameters fixed at 0, every other one estimated.
    pub fix: Option<Vec<String>>,
    /// `--estimate`: the only error parameters estimated.
    pub estimate: Option<Vec<String>>,
    /// `--holdout`: the fraction of the records held out of the fit, where
    /// the estimates' prediction is reported (not with `validate`).
    pub holdout: Option<f64>,
    /// `--seed`: the seed of the holdout's split (only with `holdout`;
    /// default [`Holdout::DEFAULT_SEED`]).
    pub seed: Option<u64>,
    /// `--iterate`: fit the exact kinematics from the linear estimate.
    pub iterate: bool,
    /// `--temperature NAME=VALUE`: the thermal state of the records whose
    /// file has no column for a sensor (docs/thermal.md).
    pub temperatures: &'a [(String, f64)],
    /// `--circular`: a circular-test file (spec `circular.md`, "Into
    /// identification"): each sample a record along the nominal
    /// ball-to-ball direction, each run's table-ball offset and bar length
    /// estimated beside the errors (this, `measurements` or `spheres`).
    pub circular: Option<Source<'a>>,
    /// Where the circular test's samples are and how its runs are read.
    pub circle: CircleRequest<'a>,
}

/// The options of a circular test read for identification.
#[cfg(feature = "records")]
#[derive(Debug, Clone, Copy, Default)]
pub struct CircleRequest<'a> {
    /// `--centre NAME=VALUE,...`: the circle's centre as the machine's
    /// variables (rotary ones in degrees, every other at 0).
    pub centre: Option<&'a [(String, f64)]>,
    /// `--axes`: each sample's pose in the run file's columns named after
    /// the machine's variables.
    pub axes: bool,
    /// `--radius` (mm) of runs whose file gives none.
    pub radius: Option<f64>,
    /// `--feed` (mm/min) of runs whose file gives none.
    pub feed: Option<f64>,
    /// `--plane` of runs whose file gives none.
    pub plane: Option<&'a str>,
    /// `--arc` (degrees) every direction covers.
    pub arc: Option<f64>,
}

#[cfg(feature = "records")]
impl CircleRequest<'_> {
    /// Whether any of its options is given.
    fn given(&self) -> bool {
        self.centre.is_some()
            || self.axes
            || self.radius.is_some()
            || self.feed.is_some()
            || self.plane.is_some()
            || self.arc.is_some()
    }
}

/// An [`IdentifyRequest`] whose options are checked: what
/// [`CheckedIdentify::run`] reads and runs.
#[cfg(feature = "records")]
#[derive(Debug, Clone)]
pub struct CheckedIdentify<'a> {
    records: Records<'a>,
    validate: Option<Source<'a>>,
    params: &'a [(String, f64)],
    temperatures: &'a [(String, f64)],
    prior: bool,
    options: IdentifyOptions,
    iterate: bool,
    holdout: Option<Holdout>,
}

/// Which records a checked request reads.
#[cfg(feature = "records")]
#[derive(Debug, Clone, Copy)]
enum Records<'a> {
    /// A measurement CSV, each record against the set-up if one is given.
    Measurements(Source<'a>, Option<SetupKind>),
    /// A sphere-probing CSV.
    Spheres(Source<'a>),
    /// A circular-test file, its runs read with the options, its samples
    /// placed by the centre (`Some`) or the file's pose columns.
    Circular(Source<'a>, RunOptions, Option<&'a [(String, f64)]>),
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

/// Why `chain identify` cannot run, in the options' words.
#[derive(Debug, thiserror::Error)]
pub enum IdentifyOpsError {
    /// None of `--measurements`, `--spheres`, `--circular`, or more than
    /// one.
    #[error("--measurements: give the measurement CSV (--measurements M.csv) or a sphere-probing CSV (--spheres S.csv) or a circular test (--circular RUNS.csv), {}", if *.both { "one of them, not both" } else { "one of them" })]
    Records {
        /// More than one was given.
        both: bool,
    },
    /// `--setup` with `--spheres`.
    #[error("--setup: the spheres of --spheres are already set-ups whose positions are estimated; --setup ball is for the records of --measurements")]
    SetupWithSpheres,
    /// `--setup` with `--circular`.
    #[error("--setup: the runs of --circular are already set-ups (each run's table-ball offset and bar length are estimated); --setup ball is for the records of --measurements")]
    SetupWithCircular,
    /// `--circular` without `--centre` or `--axes`, or with both.
    #[error("--circular: give the circle's centre (--centre NAME=VALUE,...) or each sample's pose in the run file's columns (--axes), {}", if *.both { "not both" } else { "one of them" })]
    CircleAt {
        /// Both were given.
        both: bool,
    },
    /// A circular test's option without `--circular`.
    #[error("--centre, --axes, --radius, --feed, --plane and --arc read a circular test: give --circular RUNS.csv")]
    CircleWithout,
    /// A circular test's run option refused.
    #[error(transparent)]
    Circular(#[from] super::circular::CircularOpsError),
    /// `--centre` naming no variable, one twice, or a non-finite value.
    #[error("--centre: {0}")]
    Centre(#[from] chain_core::measured::circular::records::CentreError),
    /// A held-out record on a set-up the fit does not have.
    #[error("{file}: line {line}: {kind} `{name}` is not among the fitted file's, so its position is not known; hold out probings of the fitted spheres")]
    UnknownSetup {
        /// The held-out file.
        file: String,
        /// The record's line.
        line: usize,
        /// `sphere` or `ball`.
        kind: &'static str,
        /// Its identifier.
        name: String,
    },
    /// `--fix` with `--estimate`.
    #[error("--fix: cannot be given with --estimate (one names the fixed parameters, the other the estimated ones)")]
    FixWithEstimate,
    /// `--seed` without `--holdout`: it would choose nothing.
    #[error(
        "--holdout: --seed chooses the records --holdout holds out; give --holdout FRACTION too"
    )]
    SeedWithoutHoldout,
    /// `--holdout` with `--validate`.
    #[error("--holdout: cannot be given with --validate (one holds records of the measurements out, the other reads them from a file)")]
    HoldoutWithValidate,
    /// The held-out fraction, or the split it makes of the records.
    #[error("--holdout: {}", holdout_words(.0))]
    Holdout(HoldoutError),
    /// The options against each other or the data, the prior, the solve.
    #[error("{}", identify_words(.0))]
    Identify(IdentifyError),
    /// A `--param` that is not the machine's.
    #[error(transparent)]
    Resolve(#[from] ResolveError),
    /// A measurement file refused (located).
    #[error(transparent)]
    Measurements(#[from] MeasurementsError),
    /// The records do not give a design (named by their file).
    #[error("{file}: {reason}")]
    Design {
        /// The measurement file.
        file: String,
        /// The design's refusal.
        reason: DesignError,
    },
}

/// The option that chooses a subset's list.
fn subset_option(side: SubsetSide) -> &'static str {
    match side {
        SubsetSide::Fixed => "--fix",
        SubsetSide::Estimated => "--estimate",
    }
}

/// A holdout's refusal after `--holdout: `.
fn holdout_words(e: &HoldoutError) -> String {
    match e {
        HoldoutError::Fraction(f) => format!("{f} is not a fraction in (0, 1)"),
        e => e.to_string(),
    }
}

/// The library's refusal in the options' words.
fn identify_words(e: &IdentifyError) -> String {
    match e {
        IdentifyError::NoPrior { machine, missing } => format!(
            "--prior needs a statistics entry for every error parameter; machine `{machine}` has none for {}",
            missing.join(", ")
        ),
        IdentifyError::NoNoiseScale { rows, rank } => format!(
            "--prior without a `std` column estimates the measurement noise from the least-squares residual, but there are {rows} rows for rank {rank}"
        ),
        IdentifyError::Subset { side, problem } => {
            format!("{}: {problem}", subset_option(*side))
        }
        IdentifyError::SubsetWithPrior { side } => format!(
            "{} chooses the parameters of a least-squares fit; with --prior every parameter is estimated from the data and its statistics",
            subset_option(*side)
        ),
        IdentifyError::IterateWithPrior => {
            "--iterate fits the exact kinematics by least squares; it does not take --prior".into()
        }
        IdentifyError::RankTolerance(t) => {
            format!("--rank-tol: {t} is not a relative tolerance in (0, 1)")
        }
        e => e.to_string(),
    }
}

/// What to do about a subset option's refusal.
const SUBSET_HELP: &str = "--fix and --estimate take error parameter names separated by commas; `chain identify` without them shows which parameters the measurements can separate";

/// What to do about a holdout's refusal.
const HOLDOUT_HELP: &str = "--holdout takes the fraction of the records to hold out of the fit, e.g. --holdout 0.2 (with --seed S to choose another split)";

impl Worded for IdentifyOpsError {
    fn own_code(&self) -> Option<&'static str> {
        match self {
            IdentifyOpsError::FixWithEstimate => Some("chain::identify::subset"),
            IdentifyOpsError::Records { .. }
            | IdentifyOpsError::SetupWithSpheres
            | IdentifyOpsError::SetupWithCircular => Some("chain::identify::records"),
            IdentifyOpsError::CircleAt { .. }
            | IdentifyOpsError::CircleWithout
            | IdentifyOpsError::Centre(_) => Some("chain::identify::circular"),
            IdentifyOpsError::Circular(e) => e.own_code(),
            IdentifyOpsError::UnknownSetup { .. } => Some("chain::identify::setup"),
            IdentifyOpsError::SeedWithoutHoldout | IdentifyOpsError::HoldoutWithValidate => {
                Some("chain::identify::holdout")
            }
            _ => None,
        }
    }

    fn own_help(&self) -> Option<String> {
        let help = match self {
            IdentifyOpsError::FixWithEstimate => SUBSET_HELP,
            IdentifyOpsError::Records { .. }
            | IdentifyOpsError::SetupWithSpheres
            | IdentifyOpsError::SetupWithCircular => {
                "measurements along the tool point or a direction go in --measurements (with --setup ball for an R-test); sphere probings (rotary axes in degrees) in --spheres; a ballbar's circular test in --circular"
            }
            IdentifyOpsError::CircleAt { .. }
            | IdentifyOpsError::CircleWithout
            | IdentifyOpsError::Centre(_) => {
                "--circular RUNS.csv --centre x=400,y=250,z=200 places each run's circle about that pose, moving the variables named after the plane's axes; --axes reads each sample's pose from the run file's columns named after the machine's variables (rotary ones in degrees)"
            }
            IdentifyOpsError::Circular(e) => return e.own_help(),
            IdentifyOpsError::UnknownSetup { .. } => {
                "--validate takes probings of the spheres of the fitted file at other positions"
            }
            IdentifyOpsError::SeedWithoutHoldout
            | IdentifyOpsError::HoldoutWithValidate
            | IdentifyOpsError::Holdout(_) => HOLDOUT_HELP,
            IdentifyOpsError::Identify(e) => match e {
                IdentifyError::NoPrior { .. } => {
                    "add them to the machine file's `statistics`, or identify without --prior"
                }
                IdentifyError::NoNoiseScale { .. } => {
                    "give each measurement its standard deviation (a `std` column), or more measurements"
                }
                IdentifyError::Subset { .. } => SUBSET_HELP,
                IdentifyError::SubsetWithPrior { .. } => "leave out --prior, or the subset option",
                IdentifyError::IterateWithPrior => {
                    "identify with --iterate alone, or with --prior alone"
                }
                IdentifyError::RankTolerance(_) => {
                    "e.g. --rank-tol 1e-6 (singular values of the equilibrated design below 1e-6 × the largest count as zero)"
                }
                _ => return None,
            },
            IdentifyOpsError::Resolve(e) => return e.own_help(),
            IdentifyOpsError::Measurements(_) | IdentifyOpsError::Design { .. } => return None,
        };
        Some(help.to_string())
    }

    #[cfg(feature = "cli")]
    fn inner(&self) -> Option<&dyn miette::Diagnostic> {
        match self {
            IdentifyOpsError::Holdout(e) => Some(e),
            IdentifyOpsError::Identify(e) => Some(e),
            IdentifyOpsError::Resolve(e) => Some(e),
            IdentifyOpsError::Measurements(e) => Some(e),
            _ => None,
        }
    }
}

diagnostic!(IdentifyOpsError);

/// The identification's options against each other, one rule each: the
/// library's ([`IdentifyOptions::check`]: a subset list naming some error,
/// the rank tolerance, no subset with the prior), then `--iterate` without
/// `--prior`.
fn check_fit(
    prior: bool,
    options: &IdentifyOptions,
    iterate: bool,
) -> Result<(), IdentifyOpsError> {
    options.check(prior).map_err(IdentifyOpsError::Identify)?;
    if iterate && prior {
        return Err(IdentifyOpsError::Identify(IdentifyError::IterateWithPrior));
    }
    Ok(())
}

#[cfg(feature = "records")]
impl<'a> IdentifyRequest<'a> {
    /// Every check of the options that needs no file and no machine (the
    /// CLI and Python run it before reading the machine file): `--fix` or
    /// `--estimate`, `--seed` only with `--holdout` and the fraction in
    /// (0, 1), the identification's options ([`IdentifyOptions::check`],
    /// `--iterate` without `--prior`), `--holdout` without `--validate`.
    pub fn check(self) -> Result<CheckedIdentify<'a>, IdentifyOpsError> {
        let subset = match (self.fix, self.estimate) {
            (Some(_), Some(_)) => return Err(IdentifyOpsError::FixWithEstimate),
            (Some(names), None) => SubsetChoice::Fix(names),
            (None, Some(names)) => SubsetChoice::Estimate(names),
            (None, None) => SubsetChoice::Elimination,
        };
        let holdout = match (self.holdout, self.seed) {
            (None, Some(_)) => return Err(IdentifyOpsError::SeedWithoutHoldout),
            (None, None) => None,
            (Some(fraction), seed) => {
                let h = Holdout {
                    fraction,
                    seed: seed.unwrap_or(Holdout::DEFAULT_SEED),
                };
                h.check().map_err(IdentifyOpsError::Holdout)?;
                Some(h)
            }
        };
        let options = IdentifyOptions {
            rank_tol: self.rank_tol,
            subset,
        };
        check_fit(self.prior, &options, self.iterate)?;
        if holdout.is_some() && self.validate.is_some() {
            return Err(IdentifyOpsError::HoldoutWithValidate);
        }
        if self.circular.is_none() && self.circle.given() {
            return Err(IdentifyOpsError::CircleWithout);
        }
        let records = match (self.measurements, self.spheres, self.circular) {
            (Some(m), None, None) => Records::Measurements(m, self.setup),
            (None, Some(s), None) if self.setup.is_none() => Records::Spheres(s),
            (None, Some(_), None) => return Err(IdentifyOpsError::SetupWithSpheres),
            (None, None, Some(_)) if self.setup.is_some() => {
                return Err(IdentifyOpsError::SetupWithCircular)
            }
            (None, None, Some(c)) => {
                let circle = &self.circle;
                let options =
                    super::circular::options(circle.radius, circle.feed, circle.plane, circle.arc)?;
                match (circle.centre, circle.axes) {
                    (Some(centre), false) => Records::Circular(c, options, Some(centre)),
                    (None, true) => Records::Circular(c, options, None),
                    (centre, _) => {
                        return Err(IdentifyOpsError::CircleAt {
                            both: centre.is_some(),
                        })
                    }
                }
            }
            (m, s, c) => {
                let given = [m.is_some(), s.is_some(), c.is_some()];
                return Err(IdentifyOpsError::Records {
                    both: given.into_iter().filter(|g| *g).count() > 1,
                });
            }
        };
        Ok(CheckedIdentify {
            records,
            validate: self.validate,
            params: self.params,
            temperatures: self.temperatures,
            prior: self.prior,
            options,
            iterate: self.iterate,
            holdout,
        })
    }
}

#[cfg(feature = "records")]
impl CheckedIdentify<'_> {
    /// Runs `chain identify` of `machine`: the `--param` names and values
    /// checked, the measurements (and those of `--validate`) read, the
    /// holdout's split, the identification, its document and values file.
    pub fn run(&self, machine: &Machine) -> Result<IdentifyRun, IdentifyOpsError> {
        super::resolve::check_parameters(machine, self.params)?;
        super::resolve::thermal_factors(machine, self.temperatures)?;
        let measurements = self.read(None, machine)?;
        let validation = (self.validate)
            .map(|v| {
                let held = self.read(Some(v), machine)?;
                let file = held.file.clone();
                held.onto_setups(&measurements.setups)
                    .map_err(|(line, setup)| IdentifyOpsError::UnknownSetup {
                        file,
                        line,
                        kind: setup.kind.name(),
                        name: setup.name,
                    })
            })
            .transpose()?;
        let split = match self.holdout {
            Some(h) => Some(
                (measurements.holdout(h.fraction, h.seed)).map_err(IdentifyOpsError::Holdout)?,
            ),
            None => None,
        };
        let (fitted, validation) = match &split {
            Some((fit, held)) => (fit, Some(held)),
            None => (&measurements, validation.as_ref()),
        };
        let mut identified = identify_document(
            machine,
            fitted,
            self.prior,
            &self.options,
            self.iterate,
            validation,
        )?;
        if let (Some(v), Some((_, held))) = (identified.document.validation.as_mut(), &split) {
            v.holdout = self.holdout;
            v.lines = Some(held.rows.iter().map(|r| r.line).collect());
        }
        let values_text = values_file(machine, &measurements.file, &identified);
        Ok(IdentifyRun {
            document: identified.document,
            result: identified.result,
            values_text,
        })
    }
}

#[cfg(feature = "records")]
impl CheckedIdentify<'_> {
    /// The records of the request (or, with `validate`, that file read as
    /// the request's records are) for `machine`: a measurement CSV on its
    /// set-up, or a sphere-probing CSV.
    fn read(
        &self,
        validate: Option<Source<'_>>,
        machine: &Machine,
    ) -> Result<Measurements, IdentifyOpsError> {
        let params = self.params;
        // A sensor without a column takes the state of `--temperature`:
        // the parameters' rule (a column, else the caller's value).
        let overrides: Vec<(String, f64)> =
            params.iter().chain(self.temperatures).cloned().collect();
        let mut read = match self.records {
            Records::Measurements(source, setup) => {
                let source = validate.unwrap_or(source);
                let read = super::source::read_measurements(
                    source,
                    machine,
                    &overrides,
                    Layout::Measurements,
                )?;
                match setup {
                    Some(kind) => read.on_setup(Setup::new(kind.name(), kind)),
                    None => read,
                }
            }
            Records::Spheres(source) => {
                super::source::read_spheres(validate.unwrap_or(source), machine, params)?
            }
            Records::Circular(source, options, centre) => {
                let centre = centre.map(|c| centre_pose(machine, c)).transpose()?;
                let pose = match &centre {
                    Some(q) => CirclePose::Centre(q),
                    None => CirclePose::Columns,
                };
                super::source::read_circular_records(
                    validate.unwrap_or(source),
                    machine,
                    &overrides,
                    &options,
                    pose,
                )?
            }
        };
        // A sphere file has no sensor column: its records are at the state.
        if !machine.sensors.is_empty() {
            let state = machine
                .temperatures(self.temperatures)
                .map_err(super::resolve::ResolveError::Temperature)?;
            for r in read.rows.iter_mut().filter(|r| r.temperatures.is_empty()) {
                r.temperatures = state.clone();
            }
        }
        Ok(read)
    }
}
