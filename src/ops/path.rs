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

use std::cell::RefCell;
use std::sync::Arc;

use chain_core::inverse::Status;
use chain_core::model::Sided;
use chain_core::named::NameMap;
use chain_core::Machine;
use reliability::{
    machine, Algorithm, Calls, Extreme, FormCase, InstantResult, Method, PathInstant, PathResult,
    PathStudy, PathSummary, PathTarget, Progress, Quantity, ReliabilityError, Target, Termination,
};
use serde::{Serialize, Serializer};

use super::inverse::{solve_rows, NoInverse, PoseRow};
use super::reliability::RequirementDocument;
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
    /// `--temperature NAME=VALUE`: the thermal state along the path
    /// (docs/thermal.md).
    pub temperatures: &'a [(String, f64)],
}

/// Why `chain path` cannot run.
#[derive(Debug, thiserror::Error)]
pub enum PathOpsError {
    /// An option does not match the machine, or a column of the axes.
    #[error(transparent)]
    Resolve(#[from] ResolveError),
    /// The machine's statistics or reliability section, or the study
    /// (located in the machine file by [`study::describe`]).
    #[error(transparent)]
    Reliability(#[from] ReliabilityError),
    /// A sampler option.
    #[error(transparent)]
    Option(#[from] OptionError),
    /// The machine has no inverse kinematics for these poses.
    #[error(transparent)]
    Machine(#[from] NoInverse),
}

/// What `chain path` knows of its output before it runs: the machine, the
/// input, the method and the targets (the JSON's head, the table's title).
#[derive(Debug, Clone)]
pub struct PathHead {
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
    /// The instants of the path.
    pub instants: usize,
    /// The algorithm.
    pub method: Method,
    /// One- or two-sided tolerances.
    pub sided: Sided,
    /// The targets, in case order.
    pub targets: Vec<PathTarget>,
    /// Whether the cases carry a sampler's standard error (a sampling
    /// method and at least one instant with axis values).
    pub sampled: bool,
}

impl PathHead {
    /// The targets, in case order.
    pub fn target_names(&self) -> impl Iterator<Item = Target> + '_ {
        self.targets.iter().map(|t| t.target)
    }
}

/// The document of `chain path` kept in memory (Python, `--plot`): the
/// library's [`PathResult`] with what the command knows of its input (JSON:
/// docs/path.md, through [`PathOutput`]).
#[derive(Debug, Clone)]
pub struct PathDocument {
    /// The head.
    pub head: PathHead,
    /// The records and the whole study's result.
    pub result: PathResult,
    /// Notes and warnings on the run (FORM's limits, non-normal inputs,
    /// cases that did not converge), each a line `note: …` or `warning: …`;
    /// not part of the JSON.
    pub notes: Vec<String>,
}

/// `chain path` checked and its study built, ready to run in memory
/// ([`PreparedPath::run`]) or a block of instants at a time as its output is
/// written ([`PreparedPath::output`]).
pub struct PreparedPath {
    /// The head of its output.
    pub head: PathHead,
    /// The notes known before the run (FORM's limits, non-normal inputs).
    pub notes: Vec<String>,
    path: PathStudy,
    algorithm: Algorithm,
}

/// Runs `chain path` in memory.
pub fn run(
    machine: &Machine,
    request: &PathRequest<'_>,
    progress: &dyn Progress,
) -> Result<PathDocument, PathOpsError> {
    prepare(machine, request)?.run(progress)
}

/// Checks `chain path`'s request and builds its study.
pub fn prepare(machine: &Machine, request: &PathRequest<'_>) -> Result<PreparedPath, PathOpsError> {
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
    let factors = resolve::thermal_factors(m, request.temperatures)?;
    let mut stopped = None;
    let (has_t, instants) = match request.input {
        PathInput::Axes {
            source,
            header,
            rows,
        } => axes_instants(m, source, header, rows, &fixed)?,
        PathInput::Poses { has_t, rows, .. } => {
            let solver = super::inverse::solver(m, &params, &fixed)?;
            let solved = solve_rows(&solver, rows, m.variables.len(), &fixed);
            stopped = super::inverse::stopped_note(&solved);
            let instants = solved
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
    // The study keeps the model, not every instant's sensitivities: a
    // path of a million instants holds its points only.
    let compiled = chain_core::compile(m);
    let model: reliability::study::SharedModel = if factors.iter().all(|f| *f == 1.0) {
        Arc::new(compiled)
    } else {
        Arc::new(chain_core::thermal_state::AtState::new(compiled, factors))
    };
    let sided = spec.sided;
    let path = PathStudy::on_demand(model, &params, inputs, spec, instants)?;
    let algorithm = request.algorithm.algorithm();
    let mut notes: Vec<String> = stopped.into_iter().collect();
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
    let method = algorithm.method();
    let head = PathHead {
        machine: m.name.clone(),
        frame: m.frame.name(),
        input: request.input.kind(),
        source: request.input.source().to_string(),
        variables: m.variables.iter().map(|v| v.name.clone()).collect(),
        has_t,
        instants: path.instants().len(),
        method,
        sided,
        targets: path.targets().to_vec(),
        sampled: !matches!(method, Method::Form | Method::Sorm) && path.study().is_some(),
    };
    Ok(PreparedPath {
        head,
        notes,
        path,
        algorithm,
    })
}

impl PreparedPath {
    /// Runs the whole path and keeps every record.
    pub fn run(self, progress: &dyn Progress) -> Result<PathDocument, PathOpsError> {
        let result = self.path.run(&self.algorithm, progress)?;
        let mut notes = self.notes;
        notes.extend(self.head.run_notes(&PathSummary::of(&result)));
        Ok(PathDocument {
            head: self.head,
            result,
            notes,
        })
    }

    /// The output of the path run a block of instants at a time as it is
    /// written (each block's records dropped once written).
    pub fn output<'a>(&'a self, progress: &'a dyn Progress) -> PathOutput<'a> {
        PathOutput {
            head: &self.head,
            records: Records::Streamed {
                path: &self.path,
                algorithm: &self.algorithm,
                progress,
            },
            summary: RefCell::new(None),
            failed: RefCell::new(None),
        }
    }
}

impl PathHead {
    /// The warnings on the cases that did not converge.
    pub fn run_notes(&self, summary: &PathSummary) -> Vec<String> {
        study::unconverged_warnings(&summary.tally, self.method, &self.variables)
    }
}

impl PathDocument {
    /// Its output (the records it keeps).
    pub fn output(&self) -> PathOutput<'_> {
        PathOutput {
            head: &self.head,
            records: Records::Kept(&self.result),
            summary: RefCell::new(None),
            failed: RefCell::new(None),
        }
    }
}

/// Where a [`PathOutput`]'s records come from.
enum Records<'a> {
    /// A result in memory: one block.
    Kept(&'a PathResult),
    /// The study, run a block at a time.
    Streamed {
        path: &'a PathStudy,
        algorithm: &'a Algorithm,
        progress: &'a dyn Progress,
    },
}

/// The output of `chain path`, whatever its format: the head, then the
/// records a block at a time ([`PathOutput::each_block`]; computed as they
/// are written when the path is streamed), then the [`PathSummary`] they add
/// up to. The JSON (its `Serialize`) and the CLI's table and CSV read it.
pub struct PathOutput<'a> {
    /// The head.
    pub head: &'a PathHead,
    records: Records<'a>,
    summary: RefCell<Option<PathSummary>>,
    failed: RefCell<Option<ReliabilityError>>,
}

impl PathOutput<'_> {
    /// Hands every block of records to `f`, with the index of its first
    /// record, and keeps the summary they add up to
    /// ([`PathOutput::summary`]). A run that fails keeps its error
    /// ([`PathOutput::take_error`]) and ends the blocks with `stop`'s value
    /// of it; `f`'s error ends them too.
    pub fn each_block<E>(
        &self,
        mut f: impl FnMut(&PathResult, usize) -> Result<(), E>,
        stop: impl Fn(&ReliabilityError) -> E,
    ) -> Result<(), E> {
        let h = self.head;
        let requirement = match &self.records {
            Records::Kept(r) => r.requirement(),
            Records::Streamed { path, .. } => path.study().and_then(|s| s.spec().requirement),
        };
        let mut summary = PathSummary::new(h.targets.len(), requirement);
        match &self.records {
            Records::Kept(r) => {
                f(r, 0)?;
                summary.add(r);
            }
            Records::Streamed {
                path,
                algorithm,
                progress,
            } => {
                for block in path.blocks(algorithm, *progress) {
                    let block = match block {
                        Ok(b) => b,
                        Err(e) => {
                            let out = stop(&e);
                            *self.failed.borrow_mut() = Some(e);
                            return Err(out);
                        }
                    };
                    f(&block, summary.instants)?;
                    summary.add(&block);
                }
            }
        }
        *self.summary.borrow_mut() = Some(summary);
        Ok(())
    }

    /// The summary, once every block is handed out.
    pub fn summary(&self) -> Option<PathSummary> {
        self.summary.borrow().clone()
    }

    /// The error that ended the run, if one did.
    pub fn take_error(&self) -> Option<ReliabilityError> {
        self.failed.borrow_mut().take()
    }
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

impl AtJson {
    fn of(e: &Extreme) -> AtJson {
        AtJson { row: e.row, t: e.t }
    }
}

impl PathHead {
    fn per_target<V>(&self, values: impl Iterator<Item = V>) -> NameMap<Target, V> {
        NameMap(self.target_names().zip(values).collect())
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
    summary: SummaryJson<'a>,
}

/// The instants of [`PathJson`], each object formed as it is written, a
/// block at a time (a million instants are neither a second list in memory
/// nor, streamed, a first one).
struct InstantsJson<'a>(&'a PathOutput<'a>);

impl Serialize for InstantsJson<'_> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::{Error, SerializeSeq};
        let out = self.0;
        let mut seq = serializer.serialize_seq(None)?;
        out.each_block(
            |block, _| {
                (block.records.iter())
                    .try_for_each(|rec| seq.serialize_element(&instant_json(out.head, block, rec)))
            },
            |e| S::Error::custom(e),
        )?;
        seq.end()
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

/// The JSON object of one instant of `block`.
fn instant_json<'a>(
    head: &'a PathHead,
    block: &PathResult,
    rec: &reliability::PathRecord,
) -> InstantJson<'a> {
    let i = &rec.instant;
    let e = rec.result.as_ref();
    let moments = |pick: fn(&InstantResult, Quantity) -> f64| {
        e.map(|e| NameMap(Quantity::ALL.iter().map(|&q| (q, pick(e, q))).collect()))
    };
    InstantJson {
        row: i.row,
        t: i.t,
        axes: i
            .axes
            .as_ref()
            .map(|q| NameMap::zip(head.variables.iter().map(String::as_str), q.iter().copied())),
        status: i.status,
        nominal: e.map(|e| e.nominal),
        mean: moments(InstantResult::mean),
        std: moments(InstantResult::std),
        reliability: e.map(|e| head.per_target(block.cases_of(e).map(|c| c.reliability))),
        std_error: e.and_then(|e| {
            let se: Option<Vec<f64>> = block.cases_of(e).map(|c| c.std_error).collect();
            se.map(|se| head.per_target(se.into_iter()))
        }),
        cases: e.map(|e| {
            head.per_target(block.cases_of(e).map(|c| CaseJson {
                form: c.form,
                calls: c.calls,
            }))
        }),
    }
}

/// The summary of [`PathJson`], read when it is written: after the
/// instants, whose blocks add it up.
struct SummaryJson<'a>(&'a PathOutput<'a>);

impl Serialize for SummaryJson<'_> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::Error;
        let summary = (self.0.summary())
            .ok_or_else(|| S::Error::custom("the path's summary before its instants"))?;
        summary_json(self.0.head, &summary).serialize(serializer)
    }
}

#[derive(Serialize)]
struct SummaryFields {
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

fn summary_json(head: &PathHead, s: &PathSummary) -> SummaryFields {
    let reliability = head.per_target((0..head.targets.len()).map(|t| {
        s.target(t).map(|s| TargetJson {
            min: s.min.value,
            mean: s.mean,
            worst: AtJson::of(&s.min),
            met: s.met,
        })
    }));
    let error = NameMap(
        Quantity::ALL
            .iter()
            .map(|&q| {
                let doc = match (s.max_mean(q), s.max_std(q)) {
                    (Some(m), Some(sd)) => Some(ErrorJson {
                        volumetric: q == Quantity::Volumetric,
                        mean: m.value,
                        mean_at: AtJson::of(&m),
                        std: sd.value,
                        std_at: AtJson::of(&sd),
                    }),
                    _ => None,
                };
                (q, doc)
            })
            .collect(),
    );
    let tally = &s.tally;
    let form = (tally.forms > 0).then(|| FormSummaryJson {
        cases: tally.forms,
        converged: tally.forms_converged,
        terminations: NameMap(tally.terminations().collect()),
    });
    SummaryFields {
        instants: s.instants,
        evaluated: s.evaluated,
        unreachable: s.unreachable,
        singular: s.singular,
        reliability,
        error,
        requirement: s.requirement().and_then(|req| {
            Some(RequirementDocument {
                min: req.min,
                mean: req.mean,
                met: s.requirement_met()?,
            })
        }),
        form,
        calls: tally.calls,
    }
}

impl Serialize for PathOutput<'_> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let h = self.head;
        PathJson {
            machine: &h.machine,
            method: h.method,
            input: h.input,
            frame: h.frame,
            sided: h.sided,
            tolerances: NameMap(
                h.targets
                    .iter()
                    .filter_map(|t| t.tolerance.map(|v| (t.target, v)))
                    .collect(),
            ),
            variables: &h.variables,
            instants: InstantsJson(self),
            summary: SummaryJson(self),
        }
        .serialize(serializer)
    }
}

impl Serialize for PathDocument {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        self.output().serialize(serializer)
    }
}
