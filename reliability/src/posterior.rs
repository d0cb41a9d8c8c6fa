//! The posterior of a calibration as reliability inputs (`docs/posterior.md`).
//!
//! A values file (measured-machines spec, section 2) read by
//! [`chain_core::values::Values`], plus the two extras the spec lets an
//! identification's values file carry and other readers ignore: a `std` per
//! constant, and a `correlation` list of triples
//!
//! ```yaml
//! machine: gantry_grinder
//! values:
//!   dxx: {value: 0.0012, std: 0.0001}
//!   dxz: {value: -0.0004, std: 0.00008}
//!   eyx: 2.0e-6                          # a mean only: the statistics spread kept
//! correlation:
//!   - [dxx, dxz, -0.45]                  # [NAME, NAME, ρ], ρ in (−1, 1)
//! ```
//!
//! The inputs of a study ([`Posterior::inputs`]), error by error in the
//! machine's order:
//!
//! - a constant with `std`: normal with the value as mean and that std;
//! - a constant without `std`: the `statistics` marginal of the error, same
//!   family and spread, its mean moved to the value;
//! - a constant with `carried_by: [NAME, ...]` (a redundant error an
//!   identification fixed, whose effect the named estimates carry): the
//!   fixed value ([`Marginal::fixed`]), its spread being theirs;
//! - an error the file does not give: its `statistics` marginal, unchanged;
//! - the errors named in `correlation` (each with a `std` in the file) form
//!   one correlated normal block, `x_B = μ_B + D_B·L·u_B` with `L` the
//!   Cholesky factor of the correlation matrix ([`crate::Inputs::correlated`]);
//!   pairs not listed are uncorrelated; every other input independent.
//!
//! Refused, located in the values file (file, line, column, key; codes
//! `chain::posterior::*`): a table (an error motion varies along its axis,
//! a posterior mean is a constant), a `std` of 0, a correlation entry that
//! is not `[NAME, NAME, ρ]`, an unknown name (with the closest), a name with
//! no `std` in the file (in `correlation` or `carried_by`), a name paired with itself, a pair given twice,
//! `|ρ| ≥ 1` or a non-finite `ρ`, and a correlation matrix that is not
//! positive definite (at `correlation`, naming the errors and the smallest
//! eigenvalue). Everything the values file itself refuses is refused first
//! ([`PosteriorError::Values`]).

use std::path::Path;

use chain_core::diagnostic::{closest, Describe, Description, Problem};
use chain_core::model::{Machine, Origin};
use chain_core::values::{EntryKind, Given, Values, ValuesError};
use chain_core::yaml::{self, Node};
use chain_core::Diagnostics;
use serde::Serialize;

use crate::error::ReliabilityError;
use crate::inputs::{Correlation, Inputs, Marginal};
use crate::study::Study;

/// Why a posterior could not be read or used.
#[derive(Debug, thiserror::Error)]
#[cfg_attr(feature = "miette", derive(miette::Diagnostic))]
pub enum PosteriorError {
    /// The values file itself is refused (its own rules, spec section 2).
    #[error(transparent)]
    #[cfg_attr(feature = "miette", diagnostic(transparent))]
    Values(ValuesError),
    /// The posterior's problems, located in the values file.
    #[error(transparent)]
    #[cfg_attr(feature = "miette", diagnostic(transparent))]
    File(Diagnostics),
    /// The inputs cannot be built (an error without statistics, ...).
    #[error(transparent)]
    #[cfg_attr(feature = "miette", diagnostic(transparent))]
    Reliability(ReliabilityError),
    /// A point where the tables give no input: outside a table, or a
    /// repeatability of 0 there.
    #[error("{file}: {message}")]
    #[cfg_attr(
        feature = "miette",
        diagnostic(
            code(chain::posterior::table_point),
            help("study the points inside the tables, extend them, or add `extrapolate: hold` to the entry")
        )
    )]
    Point {
        /// The values file.
        file: String,
        /// What is wrong, naming the table and the point.
        message: String,
    },
}

/// One error parameter the posterior gives.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PosteriorValue {
    /// The error parameter (or coefficient).
    pub name: String,
    /// The mean, in the machine's units.
    pub mean: f64,
    /// Its standard deviation, if the file gives one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub std: Option<f64>,
    /// The estimates that carry its spread (`carried_by`): it is then a
    /// fixed input at `mean` (docs/posterior.md, "Fixed and carried").
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub carried_by: Vec<String>,
}

/// A tabulated error's input at one point: `(error index, mean, std)`
/// (without `std`: the `statistics` spread about the mean).
type AtPoint = (usize, f64, Option<f64>);

/// One error motion the posterior gives as a table.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PosteriorTable {
    /// The entry (error motion or function slot).
    pub name: String,
    /// Its axis variable.
    pub variable: String,
    /// True when it gives a standard deviation per position (a normal input
    /// with that repeatability); false: its `statistics` spread.
    pub repeatability: bool,
    /// The approach direction read along its axis.
    pub approach: chain_core::values::Approach,
}

/// One correlation coefficient of the posterior.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PosteriorCorrelation {
    /// The first error.
    pub a: String,
    /// The second error.
    pub b: String,
    /// `ρ`.
    pub rho: f64,
}

/// The posterior of a calibration: means, standard deviations and
/// correlations of some error parameters (module docs).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Posterior {
    /// The values file, if read from one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub file: Option<String>,
    /// The errors given, in the file's order.
    pub values: Vec<PosteriorValue>,
    /// The correlations, in the file's order.
    pub correlations: Vec<PosteriorCorrelation>,
    /// The error motions given as tables (their input varies along the
    /// axis: [`Posterior::inputs_at`]), in the file's order.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub tables: Vec<String>,
    /// The values, kept when some error is a table.
    #[serde(skip)]
    built: Option<Values>,
}

/// One thing wrong with a values file read as a posterior (codes
/// `chain::posterior::*`), worded by its [`Describe`] implementation.
#[derive(Debug, Clone, PartialEq)]
enum PosteriorProblem {
    /// The file cannot be read again for its `correlation`.
    Read { file: String, reason: String },
    /// A standard deviation of 0.
    ZeroStd { name: String },
    /// `correlation` is not a list.
    CorrelationNotList { found: String },
    /// An entry of `correlation` that is not `[NAME, NAME, rho]`.
    CorrelationEntry { path: String, found: String },
    /// A name of `correlation` that is not an error of the machine.
    UnknownName {
        name: String,
        suggestion: Option<String>,
    },
    /// A name of `correlation` without a `std`.
    NoStd { name: String },
    /// A carrier of `carried_by` not given with a `std` in this file.
    CarrierWithoutStd { name: String, carrier: String },
    /// A correlation outside (-1, 1).
    Range { rho: f64 },
    /// An error correlated with itself.
    SelfCorrelation { name: String },
    /// A pair given twice.
    DuplicatePair { a: String, b: String },
    /// A correlation matrix that is not positive definite.
    NotPositiveDefinite { detail: String },
}

impl Describe for PosteriorProblem {
    fn describe(&self) -> Description {
        use Description as D;
        match self {
            PosteriorProblem::Read { file, reason } => D::new(
                "chain::posterior::read",
                "unreadable",
                format!("cannot read `{file}`: {reason}"),
            ),
            PosteriorProblem::ZeroStd { name } => D::new(
                "chain::posterior::zero_std",
                "std 0",
                format!("`{name}` has std 0: a posterior standard deviation must be positive"),
            )
            .help("leave `std` out to keep the statistics spread around the value, or give the identified std".to_string()),
            PosteriorProblem::CorrelationNotList { found } => D::new(
                "chain::posterior::correlation_entry",
                "not a list",
                format!("`correlation` is {found}: expected a list of `[NAME, NAME, rho]`"),
            ),
            PosteriorProblem::CorrelationEntry { path, found } => D::new(
                "chain::posterior::correlation_entry",
                "not [NAME, NAME, rho]",
                format!("`{path}` is {found}: expected `[NAME, NAME, rho]`"),
            )
            .help("e.g. `correlation: [[dxx, dxz, -0.45]]`".to_string()),
            PosteriorProblem::UnknownName { name, suggestion } => D::new(
                "chain::posterior::unknown_name",
                "unknown name",
                D::suggesting(format!("unknown name `{name}`"), suggestion),
            )
            .help("correlation names the error parameters and coefficients given in `values` with a `std`".to_string()),
            PosteriorProblem::NoStd { name } => D::new(
                "chain::posterior::no_std",
                "no std",
                format!("`{name}` has no `std` in this values file: a correlation needs the standard deviations of both errors"),
            )
            .help(format!("give it as `{name}: {{value: V, std: S}}` under `values`")),
            PosteriorProblem::CarrierWithoutStd { name, carrier } => D::new(
                "chain::posterior::carrier_without_std",
                "carrier without std",
                format!("`{name}` is carried by `{carrier}`, which has no `std` in this values file"),
            )
            .help(format!("a carried error is taken as exact because its carriers' std holds its spread: give `{carrier}: {{value: V, std: S}}`, or drop `carried_by` to keep `{name}`'s statistics spread")),
            PosteriorProblem::Range { rho } => D::new(
                "chain::posterior::correlation_range",
                "out of range",
                format!("correlation {rho} is out of range: it must be strictly between -1 and 1"),
            )
            .help("ρ = ±1 makes one error a copy of the other: drop one of them, or give its std alone; from a rank-deficient identification (errors that only act together), identify with the statistics as a prior".to_string()),
            PosteriorProblem::SelfCorrelation { name } => D::new(
                "chain::posterior::self_correlation",
                "the same name twice",
                format!("`{name}` is correlated with itself"),
            )
            .help("a correlation pairs two different errors (an error's own is 1)".to_string()),
            PosteriorProblem::DuplicatePair { a, b } => D::new(
                "chain::posterior::duplicate_pair",
                "given before",
                format!("the correlation of `{a}` and `{b}` is given twice"),
            ),
            PosteriorProblem::NotPositiveDefinite { detail } => D::new(
                "chain::posterior::not_positive_definite",
                "not positive definite",
                detail.clone(),
            )
            .help("a correlation matrix must be positive definite: a rank-deficient identification (see `unidentifiable`) needs the statistics as a prior, or correlations that are consistent with each other".to_string()),
        }
    }
}

impl From<PosteriorProblem> for Problem {
    fn from(problem: PosteriorProblem) -> Problem {
        Problem::foreign(problem)
    }
}

impl Posterior {
    /// Reads a values file for `machine` as a posterior.
    pub fn read(path: &Path, machine: &Machine) -> Result<Posterior, PosteriorError> {
        let values = Values::read(path, machine).map_err(PosteriorError::Values)?;
        let file = path.display().to_string();
        // `Values::read` has read and decoded it: it exists and is UTF-8.
        let text = chain_core::bounded::read_path(path, chain_core::bounded::VALUES_BYTES)
            .map_err(|e| e.to_string())
            .and_then(|b| String::from_utf8(b).map_err(|e| e.to_string()))
            .map_err(|e| {
                let m = PosteriorProblem::Read {
                    file: file.clone(),
                    reason: e,
                };
                PosteriorError::File(Diagnostics::single(
                    file.clone(),
                    "",
                    origin_at(0, ""),
                    m.into(),
                ))
            })?;
        Posterior::from_values(&values, &text, &file, machine)
    }

    /// The posterior of values-file text named `file` (`base`: the
    /// directory its tables are relative to).
    pub fn parse(
        text: &str,
        file: &str,
        base: &Path,
        machine: &Machine,
    ) -> Result<Posterior, PosteriorError> {
        let values = Values::parse(text, file, base, machine).map_err(PosteriorError::Values)?;
        Posterior::from_values(&values, text, file, machine)
    }

    /// The posterior of `values` (already read from `text`, named `file`):
    /// the constants and the `correlation` list.
    fn from_values(
        values: &Values,
        text: &str,
        file: &str,
        machine: &Machine,
    ) -> Result<Posterior, PosteriorError> {
        let mut problems: Vec<(Origin, Problem)> = Vec::new();
        let mut given = Vec::new();
        let mut tables = Vec::new();
        for e in values.entries() {
            let origin = e.origin.clone().unwrap_or_else(|| origin_at(0, "values"));
            match (&e.given, e.kind) {
                (
                    Given::Constant {
                        value,
                        std,
                        carried_by,
                    },
                    EntryKind::Error | EntryKind::Coefficient,
                ) => {
                    if *std == Some(0.0) {
                        let name = e.name.clone();
                        problems.push((origin, PosteriorProblem::ZeroStd { name }.into()));
                    }
                    given.push(PosteriorValue {
                        name: e.name.clone(),
                        mean: *value,
                        std: *std,
                        carried_by: carried_by.clone(),
                    });
                }
                (Given::Table { .. }, _) => tables.push(e.name.clone()),
                (Given::Constant { .. }, EntryKind::Function) => {}
            }
        }
        // A carried error's spread is its carriers' std: each needs one.
        for e in values.entries() {
            let Given::Constant { carried_by, .. } = &e.given else {
                continue;
            };
            for carrier in carried_by {
                if !given.iter().any(|v| v.name == *carrier && v.std.is_some()) {
                    let origin = e.origin.clone().unwrap_or_else(|| origin_at(0, "values"));
                    let (name, carrier) = (e.name.clone(), carrier.clone());
                    let problem = PosteriorProblem::CarrierWithoutStd { name, carrier };
                    problems.push((origin, problem.into()));
                }
            }
        }
        let parsed = yaml::parse(text);
        let mut correlations = Vec::new();
        let node = parsed.root.as_ref().and_then(|r| {
            r.as_mapping()?
                .iter()
                .find(|(k, _)| k.as_str() == Some("correlation"))
        });
        if let Some((key, list)) = node {
            correlations = read_correlation(key, list, &given, machine, &mut problems);
            if problems.is_empty() {
                if let Err(m) = positive_definite(&given, &correlations) {
                    problems.push((key.span.origin("correlation"), m.into()));
                }
            }
        }
        if let Some(d) = Diagnostics::located(file, text, problems) {
            return Err(PosteriorError::File(d));
        }
        let built = (!tables.is_empty()).then(|| values.clone());
        Ok(Posterior {
            file: Some(file.to_string()),
            values: given,
            correlations,
            tables,
            built,
        })
    }

    /// The value of error `name`, if the posterior gives it.
    pub fn value(&self, name: &str) -> Option<&PosteriorValue> {
        self.values.iter().find(|v| v.name == name)
    }

    /// The inputs of every error of `machine`, in [`Machine::errors`] order
    /// (module docs): the posterior where it speaks, the `statistics`
    /// section elsewhere. An error the posterior gives without `std`, or
    /// does not give, needs a `statistics` entry
    /// ([`ReliabilityError::MissingStatistic`]).
    ///
    /// An error given as a table varies along its axis: its input is the
    /// point's ([`Posterior::inputs_at`]), and a standard normal stands in
    /// for it here (a study built from these inputs takes each point's with
    /// `Study::with_point_inputs`).
    pub fn inputs(&self, machine: &Machine) -> Result<Inputs, PosteriorError> {
        let tabulated: Vec<AtPoint> = match &self.built {
            Some(v) => (v.tabulated().into_iter())
                .map(|(j, _)| (j, 0.0, Some(1.0)))
                .collect(),
            None => Vec::new(),
        };
        self.inputs_with(machine, &tabulated)
    }

    /// The tables, with what each gives and the approach read.
    pub fn table_inputs(&self) -> Vec<PosteriorTable> {
        let Some(v) = &self.built else {
            return Vec::new();
        };
        (v.entries().iter())
            .filter_map(|e| match &e.given {
                Given::Table { variable, std, .. } => Some(PosteriorTable {
                    name: e.name.clone(),
                    variable: variable.clone(),
                    repeatability: std.is_some(),
                    approach: (v.variables().iter())
                        .position(|x| x == variable)
                        .map(|k| v.approaches()[k])
                        .unwrap_or_default(),
                }),
                Given::Constant { .. } => None,
            })
            .collect()
    }

    /// True when some error is a table: its input differs from point to
    /// point.
    pub fn varies(&self) -> bool {
        !self.tables.is_empty()
    }

    /// Reads every bidirectional table for these approach directions
    /// ([`Values::choose_approach`]).
    pub fn choose_approach(
        &mut self,
        choices: &[(Option<String>, chain_core::values::Approach)],
    ) -> Result<(), chain_core::values::ApproachError> {
        match &mut self.built {
            Some(v) => v.choose_approach(choices),
            None => Err(chain_core::values::ApproachError::NoDirection),
        }
    }

    /// The inputs at axis values `q` (the machine's variable order;
    /// docs/posterior.md, "Tables"): a table with a standard deviation per
    /// position gives a normal input with the table's value (for the chosen
    /// approach) as mean and its interpolated standard deviation, the run's
    /// repeatability; a table without one gives its `statistics` marginal
    /// with the mean moved to the table's value; everything else as
    /// [`Posterior::inputs`]. A `q` outside a table is an error naming it.
    pub fn inputs_at(&self, machine: &Machine, q: &[f64]) -> Result<Inputs, PosteriorError> {
        let Some(values) = &self.built else {
            return self.inputs(machine);
        };
        let n = machine.errors.len();
        let (mut v, mut s) = (vec![0.0; n], vec![0.0; n]);
        let file = self.file.clone().unwrap_or_else(|| "values".into());
        let outside = |e: chain_core::OutOfRange| PosteriorError::Point {
            file: file.clone(),
            message: e.to_string(),
        };
        chain_core::ErrorValues::values_at(values, q, &mut v).map_err(outside)?;
        values.repeatability_at(q, &mut s).map_err(outside)?;
        let mut tabulated = Vec::new();
        for (j, has_std) in values.tabulated() {
            if has_std && (s[j] <= 0.0 || s[j].is_nan()) {
                let at: Vec<String> = (machine.variables.iter().zip(q))
                    .map(|(var, x)| format!("{} = {x}", var.name))
                    .collect();
                return Err(PosteriorError::Point {
                    file,
                    message: format!(
                        "`{}`: its table's standard deviation is {} at {}; a repeatability must be positive where the study evaluates it",
                        machine.errors[j].name,
                        s[j],
                        at.join(", ")
                    ),
                });
            }
            tabulated.push((j, v[j], has_std.then_some(s[j])));
        }
        self.inputs_with(machine, &tabulated)
    }

    /// `study` (built from [`Posterior::inputs`]) with each point's inputs
    /// ([`Posterior::inputs_at`]) when some error is a table; unchanged
    /// otherwise. The one place a study meets a varying posterior: the
    /// command line and Python both call it.
    pub fn apply(&self, machine: &Machine, study: Study) -> Result<Study, PosteriorError> {
        if !self.varies() {
            return Ok(study);
        }
        // A point in the model's variable order; the values' in the
        // machine's.
        let order: Vec<usize> = (machine.variables.iter())
            .map(|v| {
                (study.variables().iter())
                    .position(|n| *n == v.name)
                    .ok_or_else(|| ReliabilityError::MissingCoordinate(v.name.clone()))
            })
            .collect::<Result<_, _>>()
            .map_err(PosteriorError::Reliability)?;
        let each = (study.points().iter())
            .map(|q| self.inputs_at(machine, &order.iter().map(|&k| q[k]).collect::<Vec<_>>()))
            .collect::<Result<Vec<_>, _>>()?;
        study
            .with_point_inputs(each)
            .map_err(PosteriorError::Reliability)
    }

    /// The inputs with the errors of `tabulated` given `(mean, std)` there.
    fn inputs_with(
        &self,
        machine: &Machine,
        tabulated: &[AtPoint],
    ) -> Result<Inputs, PosteriorError> {
        let err = PosteriorError::Reliability;
        let mut names = Vec::with_capacity(machine.errors.len());
        let mut marginals = Vec::with_capacity(machine.errors.len());
        for (j, e) in machine.errors.iter().enumerate() {
            let table = tabulated.iter().find(|(k, _, _)| *k == j);
            let given = match table {
                Some(&(_, mean, std)) => Some(PosteriorValue {
                    name: e.name.clone(),
                    mean,
                    std,
                    carried_by: Vec::new(),
                }),
                None => self.value(&e.name).cloned(),
            };
            let marginal = match &given {
                Some(PosteriorValue {
                    mean,
                    std: Some(std),
                    ..
                }) => Marginal::normal(*mean, *std),
                Some(PosteriorValue {
                    mean, carried_by, ..
                }) if !carried_by.is_empty() => Marginal::fixed(*mean),
                _ => {
                    let stat =
                        machine
                            .statistic(j)
                            .ok_or_else(|| ReliabilityError::MissingStatistic {
                                name: e.name.clone(),
                                origin: e.origin.clone(),
                            });
                    let stat = stat.map_err(err)?;
                    let prior = crate::machine::marginal(&stat.distribution);
                    match (prior, &given) {
                        (Ok(p), Some(v)) => p.with_moments(v.mean, p.std()),
                        (p, _) => p,
                    }
                }
            }
            .map_err(|e2| match e2 {
                ReliabilityError::InvalidDistribution(msg) => {
                    ReliabilityError::InvalidDistribution(format!("`{}`: {msg}", e.name))
                }
                other => other,
            })
            .map_err(err)?;
            names.push(e.name.clone());
            marginals.push(marginal);
        }
        let index = |n: &str| names.iter().position(|x| x == n);
        let pairs: Vec<Correlation> = self
            .correlations
            .iter()
            .filter_map(|c| {
                Some(Correlation {
                    a: index(&c.a)?,
                    b: index(&c.b)?,
                    rho: c.rho,
                })
            })
            .collect();
        Inputs::correlated(names, marginals, &pairs).map_err(err)
    }
}

fn origin_at(offset: usize, key: &str) -> Origin {
    Origin {
        offset,
        len: 0,
        line: 1,
        column: 1,
        key: key.to_string(),
    }
}

/// Reads `correlation: [[NAME, NAME, ρ], ...]`, every problem located.
fn read_correlation(
    key: &Node,
    list: &Node,
    given: &[PosteriorValue],
    machine: &Machine,
    problems: &mut Vec<(Origin, Problem)>,
) -> Vec<PosteriorCorrelation> {
    let mut out: Vec<PosteriorCorrelation> = Vec::new();
    if list.is_null() {
        return out;
    }
    let Some(items) = list.as_sequence() else {
        let m = PosteriorProblem::CorrelationNotList {
            found: list.describe(),
        };
        problems.push((key.span.origin("correlation"), m.into()));
        return out;
    };
    let names = || machine.errors.iter().map(|e| e.name.as_str());
    for (i, item) in items.iter().enumerate() {
        let path = format!("correlation[{i}]");
        let shape = || PosteriorProblem::CorrelationEntry {
            path: path.clone(),
            found: item.describe(),
        };
        let Some([a, b, r]) = item
            .as_sequence()
            .and_then(|s| <&[Node; 3]>::try_from(s).ok())
        else {
            problems.push((item.span.origin(path.clone()), shape().into()));
            continue;
        };
        let mut ok = true;
        let mut name_of = |node: &Node, k: usize| -> Option<String> {
            let p = format!("{path}[{k}]");
            let Some(n) = node.as_str() else {
                problems.push((node.span.origin(p), shape().into()));
                return None;
            };
            if !names().any(|x| x == n) {
                let m = PosteriorProblem::UnknownName {
                    name: n.to_string(),
                    suggestion: closest(n, names()).map(str::to_string),
                };
                problems.push((node.span.origin(p), m.into()));
                return None;
            }
            if !given.iter().any(|v| v.name == n && v.std.is_some()) {
                let m = PosteriorProblem::NoStd {
                    name: n.to_string(),
                };
                problems.push((node.span.origin(p), m.into()));
                return None;
            }
            Some(n.to_string())
        };
        let (na, nb) = (name_of(a, 0), name_of(b, 1));
        let rho = r
            .as_scalar()
            .filter(|_| r.as_sequence().is_none())
            .and_then(|s| chain_core::expr::parse(&s.text).ok())
            .and_then(|ast| chain_core::expr::eval_const(&ast).ok());
        let rpath = format!("{path}[2]");
        match rho {
            None => {
                problems.push((r.span.origin(rpath), shape().into()));
                ok = false;
            }
            Some(v) if !v.is_finite() || v.abs() >= 1.0 => {
                let m = PosteriorProblem::Range { rho: v };
                problems.push((r.span.origin(rpath), m.into()));
                ok = false;
            }
            Some(_) => {}
        }
        let (Some(na), Some(nb), Some(rho), true) = (na, nb, rho, ok) else {
            continue;
        };
        if na == nb {
            let m = PosteriorProblem::SelfCorrelation { name: na };
            problems.push((item.span.origin(path), m.into()));
            continue;
        }
        if out
            .iter()
            .any(|c| (c.a == na && c.b == nb) || (c.a == nb && c.b == na))
        {
            let m = PosteriorProblem::DuplicatePair { a: na, b: nb };
            problems.push((item.span.origin(path), m.into()));
            continue;
        }
        out.push(PosteriorCorrelation { a: na, b: nb, rho });
    }
    out
}

/// Refuses a correlation matrix that is not positive definite (the
/// Cholesky factorisation fails), naming its errors and smallest eigenvalue.
fn positive_definite(
    given: &[PosteriorValue],
    correlations: &[PosteriorCorrelation],
) -> Result<(), PosteriorProblem> {
    let names: Vec<String> = given.iter().map(|v| v.name.clone()).collect();
    let marginals = vec![Marginal::normal(0.0, 1.0).expect("unit normal"); names.len()];
    let index = |n: &str| names.iter().position(|x| x == n).unwrap_or_default();
    let pairs: Vec<Correlation> = correlations
        .iter()
        .map(|c| Correlation {
            a: index(&c.a),
            b: index(&c.b),
            rho: c.rho,
        })
        .collect();
    match Inputs::correlated(names, marginals, &pairs) {
        Ok(_) => Ok(()),
        Err(e) => Err(PosteriorProblem::NotPositiveDefinite {
            detail: match e {
                ReliabilityError::InvalidDistribution(msg) => msg,
                other => other.to_string(),
            },
        }),
    }
}
