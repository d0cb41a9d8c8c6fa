//! From a validated [`Machine`] to a [`Study`]: inputs from the `statistics`
//! section, tolerances and grid from the `reliability` section, parameter
//! values from `parameters` (with run-time overrides for symbolic ones).

use chain_core::model::{Distribution, Machine};
use chain_core::ErrorModel;

use crate::error::ReliabilityError;
use crate::inputs::{Correlation, Inputs, Marginal};
use crate::study::{Grid, Study, StudySpec, System};

/// The inputs of every error of the machine, in [`Machine::errors`] order.
///
/// An error without a `statistics` entry is a
/// [`ReliabilityError::MissingStatistic`] carrying where the error is used.
pub fn inputs(machine: &Machine) -> Result<Inputs, ReliabilityError> {
    let mut names = Vec::with_capacity(machine.errors.len());
    let mut marginals = Vec::with_capacity(machine.errors.len());
    for (j, e) in machine.errors.iter().enumerate() {
        let stat = machine
            .statistic(j)
            .ok_or_else(|| ReliabilityError::MissingStatistic {
                name: e.name.clone(),
                origin: e.origin.clone(),
            })?;
        let m = marginal(&stat.distribution).map_err(|err| match err {
            ReliabilityError::InvalidDistribution(msg) => {
                ReliabilityError::InvalidDistribution(format!("`{}`: {msg}", e.name))
            }
            other => other,
        })?;
        names.push(e.name.clone());
        marginals.push(m);
    }
    if machine.correlations.is_empty() {
        return Inputs::new(names, marginals);
    }
    // The `correlation` list: the Nataf model (`reliability-v2.md` §2). A
    // refusal (a ρ the marginals cannot attain, a matrix not positive
    // definite after the adjustment) is located at the pair it names.
    let pairs: Vec<Correlation> = machine
        .correlations
        .iter()
        .map(|c| Correlation {
            a: c.a,
            b: c.b,
            rho: c.rho,
        })
        .collect();
    let named = names.clone();
    Inputs::correlated(names, marginals, &pairs).map_err(|err| match err {
        ReliabilityError::InvalidDistribution(msg) => {
            let pair = machine.correlations.iter().find(|c| {
                let (a, b) = (&named[c.a], &named[c.b]);
                [format!("`{a}`–`{b}`"), format!("`{b}`–`{a}`")]
                    .iter()
                    .chain(&[format!("`{a}` and `{b}`"), format!("`{b}` and `{a}`")])
                    .any(|p| msg.contains(p.as_str()))
            });
            match pair {
                Some(c) => ReliabilityError::InvalidDistribution(format!(
                    "{}:{}:{}: {msg} (at key `{}`)",
                    machine.file.as_deref().unwrap_or("<input>"),
                    c.origin.line,
                    c.origin.column,
                    c.origin.key
                )),
                None => ReliabilityError::InvalidDistribution(msg),
            }
        }
        other => other,
    })
}

/// The [`Marginal`] of a loaded [`Distribution`] (every family of
/// `reliability-v2.md` §1).
pub fn marginal(d: &Distribution) -> Result<Marginal, ReliabilityError> {
    match *d {
        Distribution::Normal { mean, std } => Marginal::normal(mean, std),
        Distribution::Uniform { min, max } => Marginal::uniform(min, max),
        Distribution::Lognormal { mean, std, shift } => Marginal::lognormal(mean, std, shift),
        Distribution::TruncatedNormal {
            mean,
            std,
            min,
            max,
        } => Marginal::truncated_normal(mean, std, min, max),
        Distribution::Weibull {
            scale,
            shape,
            shift,
        } => Marginal::weibull(scale, shape, shift),
        Distribution::Gumbel { mode, scale } => Marginal::gumbel(mode, scale),
        Distribution::Triangular { min, mode, max } => Marginal::triangular(min, mode, max),
        Distribution::Rayleigh { scale, shift } => Marginal::rayleigh(scale, shift),
    }
}

/// The parameter values: the file's, overridden by `overrides` (name, value).
/// A symbolic parameter without an override is a
/// [`ReliabilityError::SymbolicParameter`].
pub fn parameters(
    machine: &Machine,
    overrides: &[(String, f64)],
) -> Result<Vec<f64>, ReliabilityError> {
    for (name, _) in overrides {
        if machine.parameter_index(name).is_none() {
            return Err(ReliabilityError::unknown(
                "parameter",
                name,
                machine.parameters.iter().map(|p| p.name.as_str()),
            ));
        }
    }
    machine
        .parameters
        .iter()
        .map(|p| {
            overrides
                .iter()
                .rev()
                .find(|(n, _)| *n == p.name)
                .map(|(_, v)| *v)
                .or(p.value)
                .ok_or_else(|| ReliabilityError::SymbolicParameter {
                    name: p.name.clone(),
                    origin: p.origin.clone(),
                })
        })
        .collect()
}

/// The study specification of the machine's `reliability` section.
pub fn spec(machine: &Machine, system: Option<System>) -> Result<StudySpec, ReliabilityError> {
    let r = machine
        .reliability
        .as_ref()
        .ok_or(ReliabilityError::NoReliabilitySection)?;
    let axes = r
        .grid
        .iter()
        .map(|(v, values)| {
            let name = machine.variables.get(*v).map(|x| x.name.clone()).ok_or(
                ReliabilityError::Dimension {
                    what: "grid variable index",
                    expected: machine.variables.len(),
                    found: *v,
                },
            )?;
            Ok((name, values.clone()))
        })
        .collect::<Result<Vec<_>, ReliabilityError>>()?;
    Ok(StudySpec {
        tolerances: r.tolerance.clone(),
        sided: r.sided,
        grid: Grid { axes },
        requirement: r.requirement,
        system,
    })
}

/// A study of the machine over its own grid with the given model (the
/// machine's compiled model, or a `machine!` type for the same file).
pub fn study<M: ErrorModel + ?Sized>(
    machine: &Machine,
    model: &M,
    overrides: &[(String, f64)],
    system: Option<System>,
) -> Result<Study, ReliabilityError> {
    let spec = spec(machine, system)?;
    let inputs = inputs(machine)?;
    let params = parameters(machine, overrides)?;
    Study::new(model, &params, inputs, spec)
}
