//! A reliability study from a machine and the options every study command
//! takes (`--param`, `--grid`, `--sided`, `--system`, `--values`): built by
//! one function for the CLI's `reliability`, `sensitivity`, `sobol`,
//! `allocate`, `acceptance`, `path` and Python's methods over them.

use chain_core::model::Sided;
use chain_core::{ErrorModel, Machine};
use reliability::{Posterior, PosteriorError, ReliabilityError, Study, System};

use super::resolve::{self, ResolveError};

/// The options of a study.
#[derive(Debug, Clone, Copy, Default)]
pub struct StudyOptions<'a> {
    /// `--param NAME=VALUE`.
    pub params: &'a [(String, f64)],
    /// `--grid VAR=...`: replaces (or adds) an axis of `reliability.grid`.
    pub grid: &'a [(String, Vec<f64>)],
    /// `--sided`: overrides the file's.
    pub sided: Option<Sided>,
    /// `--system`.
    pub system: Option<System>,
    /// `--values`: the inputs of a posterior (`None`: the `statistics`).
    pub posterior: Option<&'a Posterior>,
}

/// Why a study cannot be built.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    /// An option does not match the machine.
    #[error(transparent)]
    Resolve(#[from] ResolveError),
    /// The machine's reliability section or the study (located in the
    /// machine file by `reliability::document::describe`).
    #[error(transparent)]
    Reliability(#[from] ReliabilityError),
    /// The posterior's inputs (located in the values file).
    #[error(transparent)]
    Posterior(PosteriorError),
}

impl From<PosteriorError> for StudyError {
    fn from(e: PosteriorError) -> StudyError {
        match e {
            PosteriorError::Reliability(e) => StudyError::Reliability(e),
            other => StudyError::Posterior(other),
        }
    }
}

/// The study of `machine`'s reliability section (evaluated through
/// `model`, compiled from it) with `options`; `file` names the machine
/// file in messages.
pub fn study<M: ErrorModel + ?Sized>(
    machine: &Machine,
    file: &str,
    model: &M,
    options: &StudyOptions<'_>,
) -> Result<Study, StudyError> {
    let mut spec = reliability::machine::spec(machine, options.system)?;
    if let Some(s) = options.sided {
        spec.sided = s;
    }
    resolve::check_grid_overrides(machine, file, options.grid)?;
    for (name, values) in options.grid {
        match spec.grid.axes.iter_mut().find(|(n, _)| n == name) {
            Some(axis) => axis.1 = values.clone(),
            None => spec.grid.axes.push((name.clone(), values.clone())),
        }
    }
    let inputs = match options.posterior {
        None => reliability::machine::inputs(machine)?,
        Some(p) => p.inputs(machine)?,
    };
    let parameters = reliability::machine::parameters(machine, options.params)?;
    let study = Study::new(model, &parameters, inputs, spec)?;
    Ok(match options.posterior {
        Some(p) => p.apply(machine, study)?,
        None => study,
    })
}
