//! `chain path` as a request and a document (docs/path.md): at every
//! instant of a path (axis values, or tool poses solved by the inverse
//! kinematics of `chain inverse`) the nominal tool point, the mean and
//! standard deviation of every error component (exact linear propagation of
//! the machine's error statistics through `E = S(q)·e`), those of the
//! volumetric position error `|p|`, and the reliability of every toleranced
//! component of the file's `reliability` section through
//! [`reliability::Study::at_points`]. The CLI reads the path from a CSV,
//! Python from arrays; both build a [`PathRequest`] and get the same
//! [`PathDocument`].

use std::sync::Arc;

use chain_core::inverse::Status;
use chain_core::model::Sided;
use chain_core::named::NameMap;
use chain_core::Machine;
use reliability::document::RequirementDocument;
use reliability::{
    machine, Calls, Extreme, FormCase, InstantResult, Method, PathInstant, PathResult, PathStudy,
    Progress, Quantity, ReliabilityError, Target, Termination,
};
use serde::{Serialize, Serializer};

use super::inverse::{solve_rows, NoInverse, PoseRow};
use super::resolve::{self, AxesColumns, ResolveError};
use super::study::{self, AlgorithmOptions, OptionError, SystemChoice};

/// Where the path's instants come from.
#[derive(Debug, Clone, Copy)]
pub enum PathInput<'a> {
    /// A table of axis values: a header naming every axis variable (any
    /// order; an optional first column `t`) and rows of numbers in the
    /// header's order ([`AxesColumns`]).
    Axes {
        /// The table's name in messages (a file, `<stdin>`, `axes`).
        source: &'a str,
        /// The column names.
        header: &'a [String],
        /// The data rows.
        rows: &'a [Vec<f64>],
    },
    /// Tool poses, solved by the inverse kinematics.
    Poses {
        /// The poses' name in messages.
        source: &'a str,
        /// Whether the poses carry their instant `t`.
        has_t: bool,
        /// The poses, in order.
        rows: &'a [PoseRow],
    },
}

impl PathInput<'_> {
    /// `axes` or `pose` (the document's `input`).
    fn kind(&self) -> &'static str {
        match self {
            PathInput::Axes { .. } => "axes",
            PathInput::Poses { .. } => "pose",
        }
    }

    fn source(&self) -> &str {
        match self {
            PathInput::Axes { source, .. } | PathInput::Poses { source, .. } => source,
        }
    }
}

/// The request of `chain path`.
#[derive(Debug, Clone, Copy)]
pub struct PathRequest<'a> {
    /// `--param NAME=VALUE`.
    pub params: &'a [(String, f64)],
    /// `--fix NAME=VALUE`: a variable without a column (axes) or one the
    /// pose does not determine (poses).
    pub fix: &'a [(String, f64)],
    /// `--sided`: overrides the file's.
    pub sided: Option<Sided>,
    /// `--system`.
    pub system: Option<SystemChoice>,
    /// `--method`, `--samples`, `--seed`, `--cov`.
    pub algorithm: AlgorithmOptions,
    /// `--axes` or `--pose`.
    pub input: PathInput<'a>,
}

/// Why `chain path` cannot run.
#[derive(Debug, thiserror::Error)]
pub enum PathOpsError {
    /// An option does not match the machine, or a column of the axes.
    #[error(transparent)]
    Resolve(#[from] ResolveError),
    /// The machine's statistics or reliability section, or the study
    /// (located in the machine file by `reliability::document::describe`).
    #[error(transparent)]
    Reliability(#[from] ReliabilityError),
    /// A sampler option.
    #[error(transparent)]
    Option(#[from] OptionError),
    /// The machine has no inverse kinematics for these poses.
    #[error(transparent)]
    Machine(#[from] NoInverse),
}

/// The document of `chain path`: the library's [`PathResult`] with what the
/// command knows of its input (JSON: docs/path.md).
#[derive(Debug, Clone)]
pub struct PathDocument {
    /// The machine.
    pub machine: String,
    /// The frame of the errors (`workpiece`, ...).
    pub frame: &'static str,
    /// `axes` or `pose`.
    pub input: &'static str,
    /// The input's name (`<stdin>` for standard input).
    pub source: String,
    /// The axis variables, in a point's order.
    pub variables: Vec<String>,
    /// Whether the input gave the instants `t` (otherwise the row numbers).
    pub has_t: bool,
    /// The records and summaries.
    pub result: PathResult,
    /// Notes and warnings on the run (FORM's limits, non-normal inputs,
    /// cases that did not converge), each a line `note: …` or `warning: …`;
    /// not part of the JSON.
    pub notes: Vec<String>,
}

/// Runs `chain path`.
pub fn run(
    machine: &Machine,
    request: &PathRequest<'_>,
    progress: &dyn Progress,
) -> Result<PathDocument, PathOpsError> {
    let m = machine;
    request.algorithm.check()?;
    resolve::check_parameters(m, request.params)?;
    let system = study::system(m, request.system)?;
    let mut spec = machine::spec(m, system)?;
    if let Some(s) = request.sided {
        spec.sided = s;
    }
    let inputs = machine::inputs(m)?;
    let params = machine::parameters(m, request.params)?;
    let fixed = resolve::fixed(m, request.fix)?;
    let (has_t, instants) = match request.input {
        PathInput::Axes {
            source,
            header,
            rows,
        } => axes_instants(m, source, header, rows, &fixed)?,
        PathInput::Poses { has_t, rows, .. } => {
            let solver = super::inverse::solver(m, &params, &fixed)?;
            let instants = solve_rows(&solver, rows, m.variables.len(), &fixed)
                .into_iter()
                .zip(rows)
                .enumerate()
                .map(|(k, (s, row))| PathInstant {
                    row: k + 1,
                    t: row.t.unwrap_or((k + 1) as f64),
                    status: s.status,
                    axes: s.solutions.into_iter().next(),
                })
                .collect();
            (has_t, instants)
        }
    };
    // The study keeps the model, not every instant's sensitivities
    // (issue 36): a path of a million instants holds its points only.
    let model = Arc::new(chain_core::compile(m));
    let path = PathStudy::on_demand(model, &params, inputs, spec, instants)?;
    let mut notes = Vec::new();
    match path.study() {
        None => notes
            .push("note: no instant of the path has axis values; nothing to evaluate".to_string()),
        Some(study) => {
            if request.algorithm.method == Method::Form {
                notes.extend(study::form_limits_note(study));
            }
            if !study.inputs().is_affine() {
                notes.push(
                    "note: non-normal inputs: the mean and std of |p| are those of the normal law with the same mean and covariance (the component moments are exact)"
                        .to_string(),
                );
            }
        }
    }
    let result = path.run(&request.algorithm.algorithm(), progress)?;
    if let (Some(study), Some(r)) = (path.study(), &result.study) {
        notes.extend(study::unconverged_warnings(r, study.variables()));
    }
    Ok(PathDocument {
        machine: m.name.clone(),
        frame: m.frame.name(),
        input: request.input.kind(),
        source: request.input.source().to_string(),
        variables: m.variables.iter().map(|v| v.name.clone()).collect(),
        has_t,
        result,
        notes,
    })
}

/// The instants of a table of axis values; whether it gave `t`.
fn axes_instants(
    m: &Machine,
    source: &str,
    header: &[String],
    rows: &[Vec<f64>],
    fixed: &[(usize, f64)],
) -> Result<(bool, Vec<PathInstant>), ResolveError> {
    let columns = AxesColumns::resolve(m, source, header, Some(fixed))?;
    let instants = (rows.iter().enumerate())
        .map(|(k, values)| PathInstant {
            row: k + 1,
            t: if columns.has_t {
                values[0]
            } else {
                (k + 1) as f64
            },
            status: Status::Ok,
            axes: Some(columns.point(values)),
        })
        .collect();
    Ok((columns.has_t, instants))
}

// ---------------------------------------------------------------------------
// The JSON document.

/// `{"row": …, "t": …}`: where an extreme occurs.
#[derive(Serialize)]
struct AtJson {
    row: usize,
    t: f64,
}

impl PathDocument {
    /// Where an extreme occurs.
    fn at(&self, e: &Extreme) -> AtJson {
        let i = &self.result.records[e.record].instant;
        AtJson { row: i.row, t: i.t }
    }

    /// The targets, in case order.
    pub fn targets(&self) -> impl Iterator<Item = Target> + '_ {
        self.result.targets.iter().map(|t| t.target)
    }

    fn per_target<V>(&self, values: impl Iterator<Item = V>) -> NameMap<Target, V> {
        NameMap(self.targets().zip(values).collect())
    }
}

/// The JSON document.
#[derive(Serialize)]
struct PathJson<'a> {
    machine: &'a str,
    method: Method,
    input: &'a str,
    frame: &'a str,
    sided: Sided,
    tolerances: NameMap<Target, f64>,
    variables: &'a [String],
    instants: InstantsJson<'a>,
    summary: SummaryJson,
}

/// The instants of [`PathJson`], each object formed as it is written (a
/// million instants are not a second list in memory; issue 36).
struct InstantsJson<'a>(&'a PathDocument);

impl Serialize for InstantsJson<'_> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let doc = self.0;
        serializer.collect_seq(doc.result.records.iter().map(|rec| doc.instant_json(rec)))
    }
}

/// One instant of [`PathJson`]; the results are `null` for an instant
/// without axis values.
#[derive(Serialize)]
struct InstantJson<'a> {
    row: usize,
    t: f64,
    axes: Option<NameMap<&'a str, f64>>,
    status: Status,
    nominal: Option<[f64; 3]>,
    mean: Option<NameMap<Quantity, f64>>,
    std: Option<NameMap<Quantity, f64>>,
    reliability: Option<NameMap<Target, f64>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    std_error: Option<NameMap<Target, f64>>,
    /// How each target's case was computed (FORM's termination, calls).
    #[serde(skip_serializing_if = "Option::is_none")]
    cases: Option<NameMap<Target, CaseJson>>,
}

/// FORM's account and the calls of one case.
#[derive(Serialize)]
struct CaseJson {
    #[serde(flatten)]
    form: Option<FormCase>,
    calls: Calls,
}

#[derive(Serialize)]
struct SummaryJson {
    instants: usize,
    evaluated: usize,
    unreachable: usize,
    singular: usize,
    reliability: NameMap<Target, Option<TargetJson>>,
    error: NameMap<Quantity, Option<ErrorJson>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    requirement: Option<RequirementDocument>,
    /// How many cases FORM solved and how (FORM and the importance sampling).
    #[serde(skip_serializing_if = "Option::is_none")]
    form: Option<FormSummaryJson>,
    /// Limit-state calls over every case.
    calls: Calls,
}

#[derive(Serialize)]
struct TargetJson {
    min: f64,
    mean: f64,
    worst: AtJson,
    #[serde(skip_serializing_if = "Option::is_none")]
    met: Option<bool>,
}

/// The extremes of one quantity; a component's mean key is `max_abs_mean`,
/// that of `|p|` is `max_mean`.
struct ErrorJson {
    volumetric: bool,
    mean: f64,
    mean_at: AtJson,
    std: f64,
    std_at: AtJson,
}

impl Serialize for ErrorJson {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let key = if self.volumetric {
            "max_mean"
        } else {
            "max_abs_mean"
        };
        let mut map = serializer.serialize_map(Some(4))?;
        map.serialize_entry(key, &self.mean)?;
        map.serialize_entry(&format!("{key}_at"), &self.mean_at)?;
        map.serialize_entry("max_std", &self.std)?;
        map.serialize_entry("max_std_at", &self.std_at)?;
        map.end()
    }
}

#[derive(Serialize)]
struct FormSummaryJson {
    cases: usize,
    converged: usize,
    terminations: NameMap<Termination, usize>,
}

impl Serialize for PathDocument {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        self.json().serialize(serializer)
    }
}

impl PathDocument {
    /// The JSON object of one instant.
    fn instant_json<'a>(&'a self, rec: &'a reliability::PathRecord) -> InstantJson<'a> {
        let r = &self.result;
        let i = &rec.instant;
        let e = rec.result.as_ref();
        let moments = |pick: fn(&InstantResult, Quantity) -> f64| {
            e.map(|e| NameMap(Quantity::ALL.iter().map(|&q| (q, pick(e, q))).collect()))
        };
        InstantJson {
            row: i.row,
            t: i.t,
            axes: i.axes.as_ref().map(|q| {
                NameMap::zip(self.variables.iter().map(String::as_str), q.iter().copied())
            }),
            status: i.status,
            nominal: e.map(|e| e.nominal),
            mean: moments(InstantResult::mean),
            std: moments(InstantResult::std),
            reliability: e.map(|e| self.per_target(r.cases_of(e).map(|c| c.reliability))),
            std_error: e.and_then(|e| {
                let se: Option<Vec<f64>> = r.cases_of(e).map(|c| c.std_error).collect();
                se.map(|se| self.per_target(se.into_iter()))
            }),
            cases: e.map(|e| {
                self.per_target(r.cases_of(e).map(|c| CaseJson {
                    form: c.form,
                    calls: c.calls,
                }))
            }),
        }
    }

    fn json(&self) -> PathJson<'_> {
        let r = &self.result;
        let instants = InstantsJson(self);
        let reliability = self.per_target((0..r.targets.len()).map(|t| {
            r.summary(t).map(|s| TargetJson {
                min: s.min.value,
                mean: s.mean,
                worst: self.at(&s.min),
                met: s.met,
            })
        }));
        let error = NameMap(
            Quantity::ALL
                .iter()
                .map(|&q| {
                    let doc = match (r.max_mean(q), r.max_std(q)) {
                        (Some(m), Some(s)) => Some(ErrorJson {
                            volumetric: q == Quantity::Volumetric,
                            mean: m.value,
                            mean_at: self.at(&m),
                            std: s.value,
                            std_at: self.at(&s),
                        }),
                        _ => None,
                    };
                    (q, doc)
                })
                .collect(),
        );
        let forms: Vec<&FormCase> = r.cases().filter_map(|c| c.form.as_ref()).collect();
        let form = (!forms.is_empty()).then(|| FormSummaryJson {
            cases: forms.len(),
            converged: forms.iter().filter(|f| f.converged).count(),
            terminations: NameMap(
                Termination::ALL
                    .iter()
                    .map(|&t| (t, forms.iter().filter(|f| f.termination == t).count()))
                    .filter(|(_, n)| *n > 0)
                    .collect(),
            ),
        });
        let calls = r.cases().fold(Calls::default(), |a, c| Calls {
            values: a.values + c.calls.values,
            gradients: a.gradients + c.calls.gradients,
        });
        let summary = SummaryJson {
            instants: r.records.len(),
            evaluated: r.evaluated(),
            unreachable: r.count(Status::Unreachable),
            singular: r.count(Status::Singular),
            reliability,
            error,
            requirement: r.study.as_ref().and_then(RequirementDocument::of),
            form,
            calls,
        };
        PathJson {
            machine: &self.machine,
            method: r.method,
            input: self.input,
            frame: self.frame,
            sided: r.sided,
            tolerances: NameMap(
                r.targets
                    .iter()
                    .filter_map(|t| t.tolerance.map(|v| (t.target, v)))
                    .collect(),
            ),
            variables: &self.variables,
            instants,
            summary,
        }
    }
}
