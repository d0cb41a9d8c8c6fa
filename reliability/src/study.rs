//! Reliability over a workspace grid: the paper's Section 3.3 procedure
//! (Tables 2-4 and Figures 6-8) for any [`ErrorModel`].
//!
//! A [`Study`] evaluates the model's sensitivity matrix once per grid point
//! (the model is linear in the errors, so that is all it needs), builds one
//! [`Event`] per target and point (a case), and runs FORM, the importance
//! sampling or Monte Carlo over all cases, in parallel. Cases are ordered
//! target-major (every point of the first target, then the next), and case
//! `i` always samples random stream `i`.
//!
//! [`Study::at_points`] builds the same study at an explicit list of points
//! (the instants of a tool path) instead of a grid, and [`Study::moments`]
//! gives the mean and covariance of the error components at a point (exact
//! linear propagation), with [`VolumetricMoments`] for the norm `|p|`.

use std::borrow::Cow;
use std::ops::Range;
use std::sync::Arc;

use chain_core::model::{Component, Requirement, Sided};
use chain_core::ErrorModel;
use serde::Serialize;

use crate::directional::DirectionalSimulation;
use crate::error::ReliabilityError;
use crate::form::{Calls, Form, FormResult, Termination};
use crate::inputs::Inputs;
use crate::limit_state::{Criterion, Event, ToleranceLimitState};
pub use crate::method::Method;
use crate::normal;
use crate::par::prelude::*;
use crate::sampler::{Progress, Sampler, SimulationResult, Stopping, Streams};
use crate::sensitivity::{sensitivity, SensitivityMethod, SensitivityResult};
use crate::simulation::{ImportanceSampling, MonteCarlo};
use crate::sorm::{Sorm, SormResult};
use crate::subset::{SubsetLevel, SubsetSimulation};

/// The axis values to evaluate: the cartesian product of the axes, first axis
/// slowest.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Grid {
    /// `(variable name, values)`, in order.
    pub axes: Vec<(String, Vec<f64>)>,
}

impl Grid {
    /// Checks the grid against the model's variables (names; the model is
    /// not needed, so callers check before deriving it): every axis a
    /// variable, none empty or with a non-finite value, every variable an
    /// axis, at least one axis when there are variables.
    pub fn check(&self, variables: &[String]) -> Result<(), ReliabilityError> {
        self.axis_of(variables).map(|_| ())
    }

    /// Per variable, the index of its axis ([`Grid::check`]'s rules).
    fn axis_of(&self, variables: &[String]) -> Result<Vec<Option<usize>>, ReliabilityError> {
        let mut axis_of = vec![None; variables.len()];
        for (a, (name, values)) in self.axes.iter().enumerate() {
            let v = variables.iter().position(|x| x == name).ok_or_else(|| {
                ReliabilityError::unknown("variable", name, variables.iter().map(String::as_str))
            })?;
            if values.is_empty() {
                return Err(ReliabilityError::EmptyGrid(format!(
                    "axis `{name}` has no value"
                )));
            }
            if values.iter().any(|x| !x.is_finite()) {
                return Err(ReliabilityError::NonFinite("the grid"));
            }
            axis_of[v] = Some(a);
        }
        if let Some(v) = axis_of.iter().position(Option::is_none) {
            return Err(ReliabilityError::MissingCoordinate(variables[v].clone()));
        }
        if self.is_empty() && !variables.is_empty() {
            return Err(ReliabilityError::EmptyGrid("no axis".into()));
        }
        Ok(axis_of)
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        if self.axes.is_empty() {
            return 0;
        }
        self.axes.iter().map(|(_, v)| v.len()).product()
    }

    /// True when the grid has no point.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The multi-index of point `p` (one index per axis).
    pub fn index(&self, mut p: usize) -> Vec<usize> {
        let mut idx = vec![0; self.axes.len()];
        for (a, (_, values)) in self.axes.iter().enumerate().rev() {
            let len = values.len().max(1);
            idx[a] = p % len;
            p /= len;
        }
        idx
    }
}

/// The points of a study: a grid kept as its axes (each point formed when
/// it is asked for, so a grid of 10⁷ points holds no point), or a list.
#[derive(Debug, Clone)]
pub enum Points {
    /// The cartesian product of the axes, first axis slowest.
    Grid {
        /// The axes' values, in grid order.
        axes: Vec<Vec<f64>>,
        /// Per model variable, its axis.
        of: Vec<usize>,
        /// The number of points.
        count: usize,
    },
    /// Explicit points, in the model's variable order.
    Listed(Vec<Arc<[f64]>>),
}

impl Points {
    /// The number of points.
    pub fn len(&self) -> usize {
        match self {
            Points::Grid { count, .. } => *count,
            Points::Listed(l) => l.len(),
        }
    }

    /// True when there is no point.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Point `p`'s axis values (model variable order) into `out`.
    pub fn fill(&self, p: usize, out: &mut [f64]) {
        match self {
            Points::Grid { axes, of, .. } => {
                // The multi-index, last axis fastest ([`Grid::index`]).
                let mut rest = p;
                let mut idx = [0usize; 16];
                let mut big = Vec::new();
                let idx: &mut [usize] = if axes.len() <= 16 {
                    &mut idx[..axes.len()]
                } else {
                    big.resize(axes.len(), 0);
                    &mut big
                };
                for (a, values) in axes.iter().enumerate().rev() {
                    let len = values.len().max(1);
                    idx[a] = rest % len;
                    rest /= len;
                }
                for (o, &a) in out.iter_mut().zip(of) {
                    *o = axes[a][idx[a]];
                }
            }
            Points::Listed(l) => out.copy_from_slice(&l[p]),
        }
    }

    /// Point `p`'s axis values, in the model's variable order.
    pub fn point(&self, p: usize) -> Arc<[f64]> {
        match self {
            Points::Grid { of, .. } => {
                let mut q = vec![0.0; of.len()];
                self.fill(p, &mut q);
                q.into()
            }
            Points::Listed(l) => Arc::clone(&l[p]),
        }
    }

    /// Every point, in order.
    pub fn iter(&self) -> impl Iterator<Item = Arc<[f64]>> + '_ {
        (0..self.len()).map(|p| self.point(p))
    }

    /// The points `range`, one after another (`range.len() × variables`
    /// values).
    pub fn flat(&self, range: Range<usize>) -> Vec<f64> {
        let nv = self.variables();
        let mut out = vec![0.0; range.len() * nv];
        if nv > 0 {
            for (p, q) in range.zip(out.chunks_exact_mut(nv)) {
                self.fill(p, q);
            }
        }
        out
    }

    /// The number of variables of a point.
    fn variables(&self) -> usize {
        match self {
            Points::Grid { of, .. } => of.len(),
            Points::Listed(l) => l.first().map_or(0, |q| q.len()),
        }
    }
}

/// A system limit state over several components.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum System {
    /// All listed components within their tolerances at once (series).
    Series,
    /// `√(px² + py² + pz²) ≤ tolerance` over the listed position components.
    Volumetric {
        /// The allowable volumetric error.
        tolerance: f64,
    },
}

/// What a [`Study`] assesses.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StudySpec {
    /// Allowable error `I` per component (Eq. 30).
    pub tolerances: Vec<(Component, f64)>,
    /// One- or two-sided tolerances.
    pub sided: Sided,
    /// The grid.
    pub grid: Grid,
    /// The requirement on the minimum and mean reliability.
    pub requirement: Option<Requirement>,
    /// An optional system target, assessed after the components.
    pub system: Option<System>,
}

/// One target of a study. It serialises (and displays) as its name: `px`,
/// …, `series`, `volumetric`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Target {
    /// One component.
    Component(Component),
    /// The series system of all components.
    Series,
    /// The volumetric norm of the position components.
    Volumetric,
}

impl Target {
    /// `px`, …, `series`, `volumetric`.
    pub fn name(&self) -> &'static str {
        match self {
            Target::Component(c) => c.name(),
            Target::Series => "series",
            Target::Volumetric => "volumetric",
        }
    }
}

impl std::fmt::Display for Target {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl Serialize for Target {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(self.name())
    }
}

/// One of the study's algorithms with its settings (see [`Study::run`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Algorithm {
    /// FORM.
    Form(Form),
    /// The advanced importance sampling.
    ImportanceSampling(ImportanceSampling),
    /// Crude Monte Carlo.
    MonteCarlo(MonteCarlo),
    /// Subset simulation ([`crate::subset`]).
    Subset(SubsetSimulation),
    /// Directional simulation ([`crate::directional`]).
    Directional(DirectionalSimulation),
    /// SORM ([`crate::sorm`]).
    Sorm(Sorm),
}

impl Algorithm {
    /// Checks its settings without running it: a sampler's sample count
    /// (1 to [`crate::MAX_SAMPLES`]), its target coefficient of variation
    /// (in (0, 1]), subset simulation's levels and samples per level. FORM
    /// and SORM have nothing to check. The same checks run again when a
    /// sampler runs, so a caller may refuse bad settings before any model
    /// is built.
    pub fn check(&self) -> Result<(), ReliabilityError> {
        let sampler = |samples: u64, cov: Option<f64>| {
            cov.map_or(Ok(()), crate::sampler::check_cov)?;
            crate::sampler::check_samples(samples)
        };
        match self {
            Algorithm::Form(_) | Algorithm::Sorm(_) => Ok(()),
            Algorithm::ImportanceSampling(a) => sampler(a.samples, a.cov),
            Algorithm::MonteCarlo(a) => sampler(a.samples, a.cov),
            Algorithm::Directional(a) => sampler(a.samples, a.cov),
            Algorithm::Subset(a) => a.check().map(|_| ()),
        }
    }

    /// The method it is.
    pub fn method(&self) -> Method {
        match self {
            Algorithm::Form(_) => Method::Form,
            Algorithm::ImportanceSampling(_) => Method::ImportanceSampling,
            Algorithm::MonteCarlo(_) => Method::MonteCarlo,
            Algorithm::Subset(_) => Method::Subset,
            Algorithm::Directional(_) => Method::Directional,
            Algorithm::Sorm(_) => Method::Sorm,
        }
    }
}

/// Why FORM is only a first-order approximation for a study (it is exact
/// when every case is one half-space in normal inputs, Eq. 21, 31).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FormLimit {
    /// Two-sided tolerances: FORM keeps the nearer side only.
    TwoSided,
    /// A system limit state (series or volumetric).
    System,
    /// Some input is not normal: the limit state is not linear in `u`.
    NonNormal,
}

impl FormLimit {
    /// The reason, in words.
    pub fn reason(self) -> &'static str {
        match self {
            FormLimit::TwoSided => "two-sided tolerances (the far side is not counted)",
            FormLimit::System => "a system limit state",
            FormLimit::NonNormal => "non-normal inputs",
        }
    }
}

/// What FORM reports about one case: how its design-point searches ended
/// and what they cost (see [`FormResult`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct FormCase {
    /// Why the nearest branch's search stopped.
    pub termination: Termination,
    /// False when some branch stopped at the iteration limit: its `β` is the
    /// last iterate's, not a design point.
    pub converged: bool,
    /// HL-RF iterations, summed over the branches (0 for the closed form).
    pub iterations: usize,
    /// True when `Φ(−β)` is the exact failure probability (one half-space
    /// in normal inputs, [`FormResult::exact`]).
    pub exact: bool,
}

impl FormCase {
    /// The account of one FORM result.
    pub fn of(r: &FormResult) -> FormCase {
        FormCase {
            termination: r.termination,
            converged: r
                .branches
                .iter()
                .all(|b| b.termination != Termination::MaxIterations),
            iterations: r.branches.iter().map(|b| b.iterations).sum(),
            exact: r.exact,
        }
    }
}

/// A study ready to run: inputs, grid points and the sensitivities there.
#[derive(Debug, Clone)]
pub struct Study {
    inputs: Inputs,
    /// Per point, its own inputs, when they differ from point to point
    /// ([`Study::with_point_inputs`]).
    point_inputs: Option<Vec<Inputs>>,
    variables: Vec<String>,
    spec: StudySpec,
    /// The points: a grid kept as its axes, or a list.
    points: Points,
    /// Per point, the `6 × N` sensitivity matrix `∂E/∂e`: kept, or
    /// evaluated when a case needs it.
    rows: Rows,
    targets: Vec<Target>,
}

/// A model a study evaluates when its cases run ([`Study::on_demand`]).
pub type SharedModel = Arc<dyn ErrorModel + Send + Sync>;

/// Where a study's sensitivity matrices come from.
#[derive(Clone)]
enum Rows {
    /// `∂E/∂e` at every point, flat: point `p`, component `c`, error `j` at
    /// `(p·6 + c)·n + j` (one allocation; `n` = the number of errors).
    Stored(Vec<f64>),
    /// Evaluated a block of points at a time when cases, moments or rows
    /// ask for them, and dropped with the block (so a million-point grid
    /// keeps no `6 × N` matrix per point).
    OnDemand {
        model: SharedModel,
        parameters: Vec<f64>,
    },
}

impl std::fmt::Debug for Rows {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Rows::Stored(s) => write!(f, "Stored({} values)", s.len()),
            Rows::OnDemand { parameters, .. } => {
                write!(f, "OnDemand {{ parameters: {parameters:?} }}")
            }
        }
    }
}

/// The outcome of one case.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CaseResult {
    /// The target.
    pub target: Target,
    /// The axis values, in the model's variable order (shared with the
    /// study's point and the other targets' cases there).
    pub point: Arc<[f64]>,
    /// `R = 1 − p_f`.
    pub reliability: f64,
    /// `p_f`.
    pub pf: f64,
    /// `β` (FORM) or the generalised index `−Φ⁻¹(p_f)` (sampling).
    pub beta: f64,
    /// Standard error of `p_f` (sampling only).
    pub std_error: Option<f64>,
    /// Coefficient of variation of `p_f` (sampling only).
    pub cov: Option<f64>,
    /// Samples drawn (sampling only).
    pub samples: Option<u64>,
    /// FORM's account of the case (FORM, and the FORM that centred the
    /// importance sampling; `None` for Monte Carlo).
    pub form: Option<FormCase>,
    /// Every limit-state call of the case (FORM's and the sampler's; a
    /// sampler's calls count as values).
    pub calls: Calls,
    /// How the sampler stopped and whether it converged (subset and
    /// directional simulation, and any sampler run to a target CoV).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stopping: Option<Stopping>,
    /// Subset simulation's levels (of its first run).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub levels: Option<Vec<SubsetLevel>>,
    /// SORM's account of the case ([`Algorithm::Sorm`]; boxed: a FORM case
    /// carries no room for it).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sorm: Option<Box<SormCase>>,
}

/// SORM's account of one case: the three asymptotic formulas and the
/// nearest branch's curvatures ([`crate::sorm::SormResult`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SormCase {
    /// Breitung's generalised index.
    pub beta_breitung: f64,
    /// Hohenbichler–Rackwitz's generalised index.
    pub beta_hohenbichler_rackwitz: f64,
    /// Tvedt's generalised index (the case's `beta`).
    pub beta_tvedt: f64,
    /// Breitung's `p_f`.
    pub pf_breitung: f64,
    /// Hohenbichler–Rackwitz's `p_f`.
    pub pf_hohenbichler_rackwitz: f64,
    /// The nearest branch's main curvatures, ascending.
    pub curvatures: Vec<f64>,
    /// FORM converged on the nearest branch and every `1 + β·κ_i > 0`.
    pub converged: bool,
}

impl SormCase {
    /// The account of a SORM result.
    pub fn of(r: &SormResult) -> SormCase {
        SormCase {
            beta_breitung: r.beta_breitung,
            beta_hohenbichler_rackwitz: r.beta_hohenbichler_rackwitz,
            beta_tvedt: r.beta_tvedt,
            pf_breitung: r.pf_breitung,
            pf_hohenbichler_rackwitz: r.pf_hohenbichler_rackwitz,
            curvatures: r.curvatures.clone(),
            converged: r.converged,
        }
    }
}

impl CaseResult {
    /// False when FORM did not converge on this case (its reliability is
    /// then not a FORM result but the last iterate's), or when its sampler
    /// stopped without meeting its rule ([`CaseResult::stopping`]).
    pub fn converged(&self) -> bool {
        self.form.is_none_or(|f| f.converged)
            && self.sampler_converged()
            && self.sorm.as_ref().is_none_or(|s| s.converged)
    }

    /// False when the sampler stopped without meeting its rule (budget or
    /// levels exhausted); true for FORM and plain sample counts.
    pub fn sampler_converged(&self) -> bool {
        self.stopping.is_none_or(|s| s.converged)
    }
}

/// What a run's cases add up to, added case by case: the limit-state calls,
/// how FORM ended, the largest standard error, and the cases that did not
/// converge (how many, and the first of each kind). The one account of the
/// cases behind the summaries of a grid study and of a path, which a path
/// run a block of instants at a time adds up as its blocks finish.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CaseTally {
    /// The cases added.
    pub cases: usize,
    /// Their calls, summed.
    pub calls: Calls,
    /// The cases with a FORM account (FORM, SORM, the importance sampling).
    pub forms: usize,
    /// How many of those FORM runs ended in each [`Termination::ALL`].
    pub terminations: [usize; Termination::ALL.len()],
    /// How many of those converged.
    pub forms_converged: usize,
    /// The first case whose FORM did not converge.
    pub first_form_unconverged: Option<CaseResult>,
    /// The largest standard error of `p_f` (sampling only).
    pub max_std_error: Option<f64>,
    /// The cases whose sampler stopped without meeting its rule.
    pub sampler_unconverged: usize,
    /// The first of them.
    pub first_sampler_unconverged: Option<CaseResult>,
}

impl CaseTally {
    /// The tally of `cases`, in their order.
    pub fn of<'a>(cases: impl IntoIterator<Item = &'a CaseResult>) -> CaseTally {
        let mut tally = CaseTally::default();
        cases.into_iter().for_each(|c| tally.add(c));
        tally
    }

    /// Adds one case.
    pub fn add(&mut self, c: &CaseResult) {
        self.add_parts(
            Parts {
                calls: c.calls,
                form: c.form.as_ref(),
                std_error: c.std_error,
                sampler_converged: c.sampler_converged(),
            },
            || c.clone(),
        );
    }

    /// Adds closed-form FORM cases ([`Study::run_totals`]), `counts[k]`
    /// of them ended in [`Termination::ALL`]`[k]`: what [`CaseTally::add`]
    /// makes of each (converged, no calls, no sampler).
    fn add_closed(&mut self, counts: &[usize; Termination::ALL.len()]) {
        let n: usize = counts.iter().sum();
        self.cases += n;
        self.forms += n;
        self.forms_converged += n;
        for (t, c) in self.terminations.iter_mut().zip(counts) {
            *t += c;
        }
    }

    /// Adds one case given by its parts, `case` forming it when the tally
    /// keeps it (the first of a kind that did not converge).
    fn add_parts(&mut self, c: Parts<'_>, case: impl Fn() -> CaseResult) {
        self.cases += 1;
        self.calls.values += c.calls.values;
        self.calls.gradients += c.calls.gradients;
        if let Some(f) = c.form {
            self.forms += 1;
            self.terminations[f.termination.index()] += 1;
            if f.converged {
                self.forms_converged += 1;
            } else if self.first_form_unconverged.is_none() {
                self.first_form_unconverged = Some(case());
            }
        }
        if let Some(se) = c.std_error {
            self.max_std_error = Some(self.max_std_error.map_or(se, |m| m.max(se)));
        }
        if !c.sampler_converged {
            self.sampler_unconverged += 1;
            if self.first_sampler_unconverged.is_none() {
                self.first_sampler_unconverged = Some(case());
            }
        }
    }

    /// The FORM terminations that occurred and how often, in
    /// [`Termination::ALL`] order.
    pub fn terminations(&self) -> impl Iterator<Item = (Termination, usize)> + '_ {
        (Termination::ALL.iter().copied())
            .zip(self.terminations)
            .filter(|(_, n)| *n > 0)
    }

    /// The cases whose FORM did not converge.
    pub fn form_unconverged(&self) -> usize {
        self.forms - self.forms_converged
    }
}

/// What [`CaseTally`] reads of a case.
#[derive(Clone, Copy)]
struct Parts<'a> {
    calls: Calls,
    form: Option<&'a FormCase>,
    std_error: Option<f64>,
    sampler_converged: bool,
}

/// What a run's cases add up to without keeping them
/// ([`Study::run_totals`], or [`Adding`] over the blocks of
/// [`Study::run_blocks`]): what a grid's summary table shows.
#[derive(Debug, Clone)]
pub struct Totals {
    /// The summaries and the requirement (`cases` empty).
    pub result: StudyResult,
    /// Every case's account.
    pub tally: CaseTally,
    /// Per target: its cases' account and its extreme cases.
    pub targets: Vec<TargetTotals>,
}

/// One target's cases added up.
#[derive(Debug, Clone, Default)]
pub struct TargetTotals {
    /// Its cases' account (calls, largest standard error, convergence).
    pub tally: CaseTally,
    /// Its least reliable cases (as many as asked for), least first (the
    /// first of equal ones first).
    pub lowest: Vec<CaseResult>,
    /// Its most reliable case (the first of equal ones).
    pub highest: Option<CaseResult>,
    /// The fewest and most samples of a case.
    pub samples: Option<(u64, u64)>,
}

impl TargetTotals {
    /// Adds a case given by its parts; `case` forms it when it is kept.
    fn add_parts(
        &mut self,
        parts: Parts<'_>,
        reliability: f64,
        samples: Option<u64>,
        keep: usize,
        case: impl Fn() -> CaseResult,
    ) {
        self.tally.add_parts(parts, &case);
        self.keep_extreme(reliability, samples, keep, case);
    }

    /// Keeps a case of reliability `r` among the extremes when it is one
    /// (`case` forms it then), and its samples.
    fn keep_extreme(
        &mut self,
        reliability: f64,
        samples: Option<u64>,
        keep: usize,
        case: impl Fn() -> CaseResult,
    ) {
        // Where it would go among the least reliable (after equal ones),
        // and whether it is the most reliable so far: the case is formed
        // only when either holds.
        let at = self
            .lowest
            .partition_point(|k| k.reliability <= reliability);
        let highest = (self.highest.as_ref()).is_none_or(|h| reliability > h.reliability);
        if at < keep || highest {
            let c = case();
            if at < keep {
                self.lowest.insert(at, c.clone());
                self.lowest.truncate(keep);
            }
            if highest {
                self.highest = Some(c);
            }
        }
        if let Some(n) = samples {
            self.samples = Some(
                self.samples
                    .map_or((n, n), |(lo, hi)| (lo.min(n), hi.max(n))),
            );
        }
    }
}

/// [`Totals`] being added up, block by block in case order.
#[derive(Debug, Clone)]
pub struct Adding {
    tally: CaseTally,
    targets: Vec<TargetTotals>,
    points: usize,
    seen: usize,
    keep: usize,
}

impl Adding {
    /// Nothing added yet for `study`'s cases, keeping `keep` least
    /// reliable cases per target.
    pub fn new(study: &Study, keep: usize) -> Adding {
        Adding {
            tally: CaseTally::default(),
            targets: vec![TargetTotals::default(); study.targets.len()],
            points: study.points.len().max(1),
            seen: 0,
            keep,
        }
    }

    /// Adds the next cases (in the study's case order).
    pub fn add(&mut self, cases: &[CaseResult]) {
        for c in cases {
            self.add_case(self.seen / self.points, c);
            self.seen += 1;
        }
    }

    /// Adds case `c` of target `t` (each target's cases in their order).
    fn add_case(&mut self, t: usize, c: &CaseResult) {
        let parts = Parts {
            calls: c.calls,
            form: c.form.as_ref(),
            std_error: c.std_error,
            sampler_converged: c.sampler_converged(),
        };
        self.add_parts(t, parts, c.reliability, c.samples, || c.clone());
    }

    /// Adds a case of target `t` given by its parts.
    fn add_parts(
        &mut self,
        t: usize,
        parts: Parts<'_>,
        reliability: f64,
        samples: Option<u64>,
        case: impl Fn() -> CaseResult,
    ) {
        self.tally.add_parts(parts, &case);
        self.targets[t].add_parts(parts, reliability, samples, self.keep, case);
    }

    /// The totals, with the run's summaries `result`.
    pub fn finish(self, result: StudyResult) -> Totals {
        Totals {
            result,
            tally: self.tally,
            targets: self.targets,
        }
    }
}

/// The summary of a target over the grid (the paper's "minimum and average
/// reliability").
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Summary {
    /// The target.
    pub target: Target,
    /// Mean reliability over the grid.
    pub mean: f64,
    /// Minimum reliability over the grid.
    pub min: f64,
    /// Maximum reliability over the grid.
    pub max: f64,
    /// Whether the requirement (min and mean) holds, if there is one.
    pub met: Option<bool>,
}

/// The outcome of a study.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StudyResult {
    /// The algorithm.
    pub method: Method,
    /// The model's axis variables.
    pub variables: Vec<String>,
    /// Every case, target-major.
    pub cases: Vec<CaseResult>,
    /// One summary per target.
    pub summaries: Vec<Summary>,
    /// The requirement.
    pub requirement: Option<Requirement>,
}

impl StudyResult {
    /// The cases of target `t` (its index in the study's targets).
    pub fn target_cases(&self, t: usize) -> &[CaseResult] {
        let np = self.cases.len() / self.summaries.len().max(1);
        &self.cases[t * np..(t + 1) * np]
    }

    /// The cases on which FORM did not converge.
    pub fn unconverged(&self) -> impl Iterator<Item = &CaseResult> {
        self.cases.iter().filter(|c| !c.converged())
    }

    /// True when every summary's requirement holds (or there is none).
    pub fn requirement_met(&self) -> bool {
        self.summaries.iter().all(|s| s.met != Some(false))
    }
}

/// The grid-mean sensitivities of one error for one target.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ErrorSensitivity {
    /// The error parameter.
    pub error: String,
    /// Mean `∂R/∂σ`.
    pub dr_dstd: f64,
    /// Mean `∂R/∂μ`.
    pub dr_dmean: f64,
    /// Mean importance factor `α²`.
    pub importance: f64,
    /// Mean `|∂R/∂σ|`.
    pub mean_abs_dr_dstd: f64,
    /// Mean `|∂R/∂μ|`.
    pub mean_abs_dr_dmean: f64,
}

/// The sensitivities of one target, sorted by `|∂R/∂σ|`, largest first.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TargetSensitivity {
    /// The target.
    pub target: Target,
    /// Exact or FORM (the FORM route if any point needed it).
    pub method: SensitivityMethod,
    /// Per error, sorted.
    pub errors: Vec<ErrorSensitivity>,
}

/// The first two moments of the six error components at one point,
/// propagated exactly through the linear model `E = S(q)·e` with inputs of
/// means `μ_j` and standard deviations `σ_j` (any marginals), independent
/// or with correlated normals (`Cov(E_a, E_b) = S_aᵀΣS_b`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ErrorMoments {
    /// `E[E_c] = Σ_j S_cj·μ_j`, in `px, py, pz, ox, oy, oz` order.
    pub mean: [f64; 6],
    /// `Cov(E_a, E_b) = Σ_j S_aj·S_bj·σ_j²`, same order.
    pub covariance: [[f64; 6]; 6],
}

impl ErrorMoments {
    /// The standard deviation of component `c`.
    pub fn std(&self, c: Component) -> f64 {
        let i = c.index();
        self.covariance[i][i].max(0.0).sqrt()
    }

    /// The mean and standard deviation of the volumetric position error
    /// `|p| = √(px² + py² + pz²)` when `(px, py, pz)` is normal with this
    /// mean and covariance (exact for normal inputs; for other marginals, the
    /// normal approximation with the same two moments). See
    /// [`VolumetricMoments::normal`].
    pub fn volumetric(&self) -> VolumetricMoments {
        let m = [self.mean[0], self.mean[1], self.mean[2]];
        let c = &self.covariance;
        let cov = [
            [c[0][0], c[0][1], c[0][2]],
            [c[1][0], c[1][1], c[1][2]],
            [c[2][0], c[2][1], c[2][2]],
        ];
        VolumetricMoments::normal(m, cov)
    }
}

/// Mean and standard deviation of the norm `|p|` of a normal 3-vector.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct VolumetricMoments {
    /// `E|p|`.
    pub mean: f64,
    /// `√(E|p|² − (E|p|)²)`, with `E|p|² = |μ|² + tr Σ` (exact for any law).
    pub std: f64,
}

impl VolumetricMoments {
    /// `E|p|` and the standard deviation of `|p|` for `p ~ N(μ, Σ)` in three
    /// dimensions (Σ positive semi-definite, possibly singular).
    ///
    /// `|p| = √Q` with `Q = |p|²`, and `√x = (4π)^{-1/2} ∫_0^∞ (1 − e^{−sx})
    /// s^{−3/2} ds`, so `E|p| = (4π)^{-1/2} ∫_0^∞ (1 − M(s)) s^{−3/2} ds` with
    /// the Laplace transform of the Gaussian quadratic form
    /// `M(s) = E e^{−sQ} = det(I + 2sΣ)^{−1/2} exp(−s μᵀ(I + 2sΣ)^{−1}μ)`.
    /// After `s = e^t / E[Q]` the integrand is analytic in a strip of
    /// half-width π about the real axis and decays like `e^{−|t|/2}`, so the
    /// trapezoidal rule with step 0.25 on `t ∈ [−76, 80]` (625 nodes) is
    /// accurate to rounding: the chi, non-central chi, Rayleigh and
    /// half-normal means are met to 1e-13 relative (unit tests).
    pub fn normal(mean: [f64; 3], cov: [[f64; 3]; 3]) -> VolumetricMoments {
        let mu2: f64 = mean.iter().map(|m| m * m).sum();
        let trace = cov[0][0] + cov[1][1] + cov[2][2];
        let q_mean = mu2 + trace;
        if q_mean <= 0.0 {
            // p = 0 almost surely.
            return VolumetricMoments {
                mean: 0.0,
                std: 0.0,
            };
        }
        // det(I + A) = 1 + tr A + (sum of principal 2×2 minors of A) + det A
        // for A = 2sΣ: the coefficients of the cubic in 2s.
        let minors = cov[0][0] * cov[1][1] - cov[0][1] * cov[1][0] + cov[0][0] * cov[2][2]
            - cov[0][2] * cov[2][0]
            + cov[1][1] * cov[2][2]
            - cov[1][2] * cov[2][1];
        let det = chain_core::geometry::det(&cov);
        let one_minus_m = |s: f64| -> f64 {
            let a = 2.0 * s;
            let x = a * trace + a * a * minors + a * a * a * det;
            let ln_det = x.max(0.0).ln_1p();
            let b: [[f64; 3]; 3] = std::array::from_fn(|i| {
                std::array::from_fn(|j| a * cov[i][j] + if i == j { 1.0 } else { 0.0 })
            });
            let adj = adjugate3(&b);
            let quad: f64 = (0..3)
                .map(|i| (0..3).map(|j| mean[i] * adj[i][j] * mean[j]).sum::<f64>())
                .sum();
            let quad = (quad / (1.0 + x.max(0.0))).max(0.0);
            -(-(0.5 * ln_det + s * quad)).exp_m1()
        };
        const STEP: f64 = 0.25;
        const LOW: f64 = -76.0;
        const HIGH: f64 = 80.0;
        let steps = ((HIGH - LOW) / STEP).round() as usize;
        let mut sum = 0.0;
        for k in 0..=steps {
            let t = LOW + k as f64 * STEP;
            let w = if k == 0 || k == steps { 0.5 } else { 1.0 };
            sum += w * one_minus_m(t.exp() / q_mean) * (-0.5 * t).exp();
        }
        let mean_norm = q_mean.sqrt() * STEP * sum / (4.0 * std::f64::consts::PI).sqrt();
        VolumetricMoments {
            mean: mean_norm,
            std: (q_mean - mean_norm * mean_norm).max(0.0).sqrt(),
        }
    }
}

fn adjugate3(m: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let c =
        |r0: usize, r1: usize, c0: usize, c1: usize| m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0];
    [
        [c(1, 2, 1, 2), -c(0, 2, 1, 2), c(0, 1, 1, 2)],
        [-c(1, 2, 0, 2), c(0, 2, 0, 2), -c(0, 1, 0, 2)],
        [c(1, 2, 0, 1), -c(0, 2, 0, 1), c(0, 1, 0, 1)],
    ]
}

impl Study {
    /// Evaluates the model's sensitivities over the grid and keeps them.
    ///
    /// `parameters` are the model's parameter values (in
    /// [`ErrorModel::parameters`] order); `inputs` must name every error of
    /// the model (any order).
    pub fn new<M: ErrorModel + ?Sized>(
        model: &M,
        parameters: &[f64],
        inputs: Inputs,
        spec: StudySpec,
    ) -> Result<Study, ReliabilityError> {
        let (inputs, variables) = checked_inputs(model, parameters, inputs)?;
        let points = grid_points(&spec.grid, &variables)?;
        let targets = targets(&spec)?;
        Study::kept(model, parameters, inputs, variables, spec, points, targets)
    }

    /// The study of checked points that keeps `model`'s sensitivities,
    /// every point's checked here ([`check_moments`]).
    fn kept<M: ErrorModel + ?Sized>(
        model: &M,
        parameters: &[f64],
        inputs: Inputs,
        variables: Vec<String>,
        spec: StudySpec,
        points: Points,
        targets: Vec<Target>,
    ) -> Result<Study, ReliabilityError> {
        let rows = evaluate(
            model,
            parameters,
            (&inputs, &variables),
            &points,
            0..points.len(),
        )?;
        Ok(Study::assemble(
            inputs,
            variables,
            spec,
            points,
            Rows::Stored(rows),
            targets,
        ))
    }

    /// The grid study of [`Study::new`] that keeps the model instead of the
    /// sensitivities: a block of points is evaluated when its cases run
    /// (and a point's when its moments, rows or events are asked for), so
    /// the study holds per point only the point. For a model whose
    /// [`ErrorModel::sensitivity_points`] equals its per-point values bit
    /// for bit (the runtime tape), every result equals [`Study::new`]'s.
    ///
    /// Each point's sensitivities are checked when they are read (a point
    /// whose values are not finite is refused as [`Study::new`] refuses it,
    /// by the run, the moments or the rows that read it); [`Study::check`]
    /// reads them all first.
    pub fn on_demand(
        model: SharedModel,
        parameters: &[f64],
        inputs: Inputs,
        spec: StudySpec,
    ) -> Result<Study, ReliabilityError> {
        let (inputs, variables) = checked_inputs(&*model, parameters, inputs)?;
        let points = grid_points(&spec.grid, &variables)?;
        let targets = targets(&spec)?;
        Ok(Study::lazy(
            model, parameters, inputs, variables, spec, points, targets,
        ))
    }

    /// The study of checked points that evaluates `model` when asked (each
    /// point checked when it is read).
    fn lazy(
        model: SharedModel,
        parameters: &[f64],
        inputs: Inputs,
        variables: Vec<String>,
        spec: StudySpec,
        points: Points,
        targets: Vec<Target>,
    ) -> Study {
        let rows = Rows::OnDemand {
            model,
            parameters: parameters.to_vec(),
        };
        Study::assemble(inputs, variables, spec, points, rows, targets)
    }

    /// Evaluates the model's sensitivities at an explicit list of points
    /// (axis values in the model's variable order), e.g. the instants of a
    /// tool path, instead of a grid.
    ///
    /// Everything else is as in [`Study::new`] (the same validation, targets,
    /// case order and results); `spec.grid` is not used and the study's
    /// [`Study::spec`] has an empty grid. An empty list, a point of the wrong
    /// length or a non-finite coordinate is an error.
    pub fn at_points<M: ErrorModel + ?Sized>(
        model: &M,
        parameters: &[f64],
        inputs: Inputs,
        spec: StudySpec,
        points: Vec<Vec<f64>>,
    ) -> Result<Study, ReliabilityError> {
        let (inputs, variables) = checked_inputs(model, parameters, inputs)?;
        let (spec, points, targets) = listed_points(spec, points, &variables)?;
        Study::kept(model, parameters, inputs, variables, spec, points, targets)
    }

    /// [`Study::at_points`] keeping the model instead of the sensitivities,
    /// as [`Study::on_demand`] does for a grid; every point is checked here
    /// ([`Study::check`]: a path is written as it runs).
    pub fn at_points_on_demand(
        model: SharedModel,
        parameters: &[f64],
        inputs: Inputs,
        spec: StudySpec,
        points: Vec<Vec<f64>>,
    ) -> Result<Study, ReliabilityError> {
        let (inputs, variables) = checked_inputs(&*model, parameters, inputs)?;
        let (spec, points, targets) = listed_points(spec, points, &variables)?;
        let study = Study::lazy(model, parameters, inputs, variables, spec, points, targets);
        study.check()?;
        Ok(study)
    }

    /// The shared part of the constructors, after their checks.
    fn assemble(
        inputs: Inputs,
        variables: Vec<String>,
        spec: StudySpec,
        points: Points,
        rows: Rows,
        targets: Vec<Target>,
    ) -> Study {
        Study {
            inputs,
            variables,
            spec,
            points,
            rows,
            targets,
            point_inputs: None,
        }
    }

    /// The inputs, in the model's error order. With inputs per point
    /// ([`Study::with_point_inputs`]) these are the common ones (names,
    /// families), and [`Study::inputs_at`] gives a point's.
    pub fn inputs(&self) -> &Inputs {
        &self.inputs
    }

    /// The inputs at point `p`: its own, or the common ones.
    pub fn inputs_at(&self, p: usize) -> &Inputs {
        match &self.point_inputs {
            Some(each) => &each[p],
            None => &self.inputs,
        }
    }

    /// True when the inputs differ from point to point.
    pub fn varies(&self) -> bool {
        self.point_inputs.is_some()
    }

    /// The study with inputs of its own at every point (in
    /// [`Study::points`] order, the same errors in the same order): a built
    /// machine whose measured error motions have a mean and a repeatability
    /// that vary along the axes (a posterior of a values file with
    /// tables, docs/posterior.md). Every case's event and moments use its
    /// point's inputs.
    pub fn with_point_inputs(mut self, each: Vec<Inputs>) -> Result<Study, ReliabilityError> {
        if each.len() != self.points.len() {
            return Err(ReliabilityError::Dimension {
                what: "inputs per point",
                expected: self.points.len(),
                found: each.len(),
            });
        }
        if let Some(bad) = each.iter().find(|i| i.names() != self.inputs.names()) {
            return Err(ReliabilityError::Dimension {
                what: "inputs of a point (the study's errors)",
                expected: self.inputs.len(),
                found: bad.len(),
            });
        }
        for (p, inputs) in each.iter().enumerate() {
            let rows = self.sensitivities(p..p + 1)?;
            check_moments(inputs, &self.variables, &self.points, p..p + 1, &rows)?;
        }
        self.point_inputs = Some(each);
        Ok(self)
    }

    /// The model's axis variables.
    pub fn variables(&self) -> &[String] {
        &self.variables
    }

    /// The variables' indices in the order a point is shown: the grid's
    /// axes first (x, y, z as the file lists them), then any other variable.
    pub fn display_order(&self) -> Vec<usize> {
        let vars = &self.variables;
        let mut order: Vec<usize> = self
            .spec
            .grid
            .axes
            .iter()
            .filter_map(|(name, _)| vars.iter().position(|v| v == name))
            .collect();
        order.extend(
            (0..vars.len())
                .filter(|i| !order.contains(i))
                .collect::<Vec<_>>(),
        );
        order
    }

    /// The specification.
    pub fn spec(&self) -> &StudySpec {
        &self.spec
    }

    /// The grid points, in the model's variable order.
    pub fn points(&self) -> &Points {
        &self.points
    }

    /// The targets, in case order.
    pub fn targets(&self) -> &[Target] {
        &self.targets
    }

    /// Why FORM is only a first-order approximation on this study (empty
    /// when it is exact on every case: one-sided components in normal
    /// inputs, no system).
    pub fn form_limits(&self) -> Vec<FormLimit> {
        let mut out = Vec::new();
        if self.spec.sided == Sided::Two {
            out.push(FormLimit::TwoSided);
        }
        if self.spec.system.is_some() {
            out.push(FormLimit::System);
        }
        let each = self.point_inputs.iter().flatten();
        if !self.inputs.is_affine() || each.clone().any(|i| !i.is_affine()) {
            out.push(FormLimit::NonNormal);
        }
        out
    }

    /// The allowable value of `target` (`None` for the series system, whose
    /// tolerances are its components').
    pub fn tolerance(&self, target: Target) -> Option<f64> {
        match target {
            Target::Series => None,
            Target::Volumetric => match self.spec.system {
                Some(System::Volumetric { tolerance }) => Some(tolerance),
                _ => None,
            },
            Target::Component(c) => self
                .spec
                .tolerances
                .iter()
                .find(|(x, _)| *x == c)
                .map(|(_, t)| *t),
        }
    }

    /// The sensitivity matrices (`6 × N` each, component-major) of the
    /// points `range`: borrowed when the study keeps them, evaluated
    /// otherwise ([`Study::on_demand`]).
    ///
    /// # Errors
    /// A point whose sensitivities, or the mean or variance of an error
    /// component they give, are not finite (a study that keeps its model
    /// checks each point when it is read; [`Study::check`] reads them all).
    pub fn sensitivities(&self, range: Range<usize>) -> Result<Cow<'_, [f64]>, ReliabilityError> {
        let n6 = 6 * self.inputs.len();
        match &self.rows {
            Rows::Stored(s) => Ok(Cow::Borrowed(&s[range.start * n6..range.end * n6])),
            Rows::OnDemand { model, parameters } => {
                let checked = (&self.inputs, &self.variables[..]);
                let s = evaluate(&**model, parameters, checked, &self.points, range)?;
                Ok(Cow::Owned(s))
            }
        }
    }

    /// Reads every point's sensitivities once ([`Study::sensitivities`],
    /// a block at a time on every core) to refuse a point whose values are
    /// not finite before anything is run: for a caller that writes results
    /// as they come and wants no refusal half-way. A study that keeps its
    /// sensitivities was checked when it was built.
    ///
    /// # Errors
    /// The first point (in order) whose values are not finite.
    pub fn check(&self) -> Result<(), ReliabilityError> {
        if let Rows::Stored(_) = self.rows {
            return Ok(());
        }
        let np = self.points.len();
        let blocks: Vec<Range<usize>> = (0..np)
            .step_by(POINT_CHUNK)
            .map(|s| s..(s + POINT_CHUNK).min(np))
            .collect();
        // The first refusal in point order: each block's, in order.
        let refusals: Vec<Option<ReliabilityError>> = blocks
            .into_par_iter()
            .map(|b| self.sensitivities(b).err())
            .collect();
        match refusals.into_iter().flatten().next() {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }

    /// The sensitivity row `∂E_c/∂e` at point `p` ([`Study::sensitivities`]'
    /// refusals).
    pub fn row(&self, p: usize, c: Component) -> Result<Cow<'_, [f64]>, ReliabilityError> {
        let n = self.inputs.len();
        let at = c.index() * n..(c.index() + 1) * n;
        Ok(match self.sensitivities(p..p + 1)? {
            Cow::Borrowed(s) => Cow::Borrowed(&s[at]),
            Cow::Owned(s) => Cow::Owned(s[at].to_vec()),
        })
    }

    /// The mean and covariance of the six error components at point `p`
    /// (exact linear propagation of the inputs' means and covariance:
    /// `Cov(E_a, E_b) = S_aᵀΣS_b`, [`Inputs::covariance`], the diagonal sum
    /// alone for independent inputs).
    ///
    /// # Errors
    /// [`Study::sensitivities`]' refusals.
    pub fn moments(&self, p: usize) -> Result<ErrorMoments, ReliabilityError> {
        let inputs = self.inputs_at(p);
        let means = inputs.means();
        let s = self.sensitivities(p..p + 1)?;
        let n = self.inputs.len();
        let row = |c: Component| &s[c.index() * n..(c.index() + 1) * n];
        let mut mean = [0.0; 6];
        let mut covariance = [[0.0; 6]; 6];
        for a in Component::ALL {
            let ra = row(a);
            mean[a.index()] = ra.iter().zip(means).map(|(s, m)| s * m).sum();
            for b in Component::ALL {
                covariance[a.index()][b.index()] = inputs.covariance(ra, row(b));
            }
        }
        Ok(ErrorMoments { mean, covariance })
    }

    /// The limit state of `target` at point `p`.
    pub fn limit_state(
        &self,
        target: Target,
        p: usize,
    ) -> Result<ToleranceLimitState, ReliabilityError> {
        self.limit_state_of(target, &self.sensitivities(p..p + 1)?)
    }

    /// The limit state of `target` at the point whose `6 × N` sensitivity
    /// matrix is `s`.
    fn limit_state_of(
        &self,
        target: Target,
        s: &[f64],
    ) -> Result<ToleranceLimitState, ReliabilityError> {
        let n = self.inputs.len();
        let row = |c: &Component| &s[c.index() * n..(c.index() + 1) * n];
        let tol = &self.spec.tolerances;
        match target {
            Target::Component(c) => {
                let i = tol.iter().find(|(x, _)| *x == c).map(|(_, t)| *t).ok_or(
                    ReliabilityError::UnknownName {
                        kind: "component",
                        name: c.name().into(),
                        hint: None,
                    },
                )?;
                ToleranceLimitState::component(row(&c).to_vec(), i, self.spec.sided)
            }
            Target::Series => {
                let rows = tol.iter().flat_map(|(c, _)| row(c).to_vec()).collect();
                let t = tol.iter().map(|(_, t)| *t).collect();
                ToleranceLimitState::new(n, rows, t, Criterion::Each(self.spec.sided))
            }
            Target::Volumetric => {
                let tolerance = match self.spec.system {
                    Some(System::Volumetric { tolerance }) => tolerance,
                    _ => tol.iter().map(|(_, t)| *t).fold(f64::INFINITY, f64::min),
                };
                let rows = tol
                    .iter()
                    .filter(|(c, _)| matches!(c, Component::Px | Component::Py | Component::Pz))
                    .flat_map(|(c, _)| row(c).to_vec())
                    .collect();
                ToleranceLimitState::new(n, rows, vec![tolerance], Criterion::Norm)
            }
        }
    }

    /// The event of `target` at point `p`.
    pub fn event(&self, target: Target, p: usize) -> Result<Event<'_>, ReliabilityError> {
        Event::new(self.inputs_at(p), self.limit_state(target, p)?)
    }

    /// Every case's event, target-major.
    pub fn events(&self) -> Result<Vec<Event<'_>>, ReliabilityError> {
        self.events_of(0..self.targets.len() * self.points.len())
    }

    /// The events of the cases `cases` (target-major indices), the
    /// sensitivities of each target's run of points evaluated (or borrowed)
    /// once, [`CASE_BLOCK`] points at a time.
    fn events_of(&self, cases: Range<usize>) -> Result<Vec<Event<'_>>, ReliabilityError> {
        let np = self.points.len();
        let n6 = 6 * self.inputs.len();
        let mut out = Vec::with_capacity(cases.len());
        let mut i = cases.start;
        while i < cases.end {
            let (t, p) = (i / np, i % np);
            let last = (cases.end - t * np).min(np).min(p + CASE_BLOCK);
            let s = self.sensitivities(p..last)?;
            for k in 0..last - p {
                let state = self.limit_state_of(self.targets[t], &s[k * n6..(k + 1) * n6])?;
                out.push(Event::new(self.inputs_at(p + k), state)?);
            }
            i = t * np + last;
        }
        Ok(out)
    }

    /// FORM on the cases of `set`, telling `progress` of each block of
    /// cases done.
    fn form_cases(
        &self,
        form: &Form,
        set: CaseSet<'_>,
        progress: &dyn Progress,
    ) -> Result<Vec<CaseResult>, ReliabilityError> {
        let keep = |i: usize, r: FormResult| {
            let mut c = self.case(i, r.reliability, r.pf, r.beta);
            c.form = Some(FormCase::of(&r));
            c.calls = r.calls;
            c
        };
        let plans: Vec<Option<Vec<(usize, f64)>>> =
            self.targets.iter().map(|&t| self.closed_plan(t)).collect();
        if plans.iter().all(Option::is_none) {
            return self.cases_in_blocks(set, progress, |e| form.run(e), keep);
        }
        // Where FORM takes the closed form (every branch a half-space in
        // normal inputs), each case computes what `Form::run` computes for
        // it, without forming its event: the projection, `β` per branch,
        // the nearest. A block of cases at a time, each run of consecutive
        // points of one target from one evaluation of their sensitivities.
        let (n, np) = (self.inputs.len(), self.points.len());
        let n6 = 6 * n;
        let total = set.len();
        let mut cases = Vec::with_capacity(total);
        let mut start = 0;
        while start < total {
            let end = (start + CASE_BLOCK).min(total);
            let mut k = start;
            while k < end {
                let first = set.id(k);
                let (t, p) = (first / np, first % np);
                let mut e = k + 1;
                while e < end && set.id(e) == set.id(e - 1) + 1 && set.id(e) / np == t {
                    e += 1;
                }
                let s = self.sensitivities(p..p + (e - k))?;
                let run: Result<Vec<CaseResult>, ReliabilityError> = (0..e - k)
                    .into_par_iter()
                    .map_init(
                        || vec![0.0; n],
                        |a, j| {
                            let rows = &s[j * n6..(j + 1) * n6];
                            let inputs = self.inputs_at(p + j);
                            match &plans[t] {
                                Some(plan) if inputs.is_affine() => {
                                    Ok(self.closed_case(first + j, inputs, rows, plan, a))
                                }
                                _ => {
                                    let state = self.limit_state_of(self.targets[t], rows)?;
                                    Ok(keep(first + j, form.run(&Event::new(inputs, state)?)?))
                                }
                            }
                        },
                    )
                    .collect();
                cases.extend(run?);
                k = e;
            }
            progress.advance((end - start) as u64);
            start = end;
        }
        Ok(cases)
    }

    /// The components (index, tolerance) of `target` when FORM takes the
    /// closed form on it in normal inputs: every branch a half-space (a
    /// component or the series system; not the volumetric norm), every
    /// tolerance valid (else the event's own refusal is wanted).
    fn closed_plan(&self, target: Target) -> Option<Vec<(usize, f64)>> {
        let tol = &self.spec.tolerances;
        let plan: Vec<(usize, f64)> = match target {
            Target::Component(c) => vec![(c.index(), tol.iter().find(|(x, _)| *x == c)?.1)],
            Target::Series => tol.iter().map(|(c, t)| (c.index(), *t)).collect(),
            Target::Volumetric => return None,
        };
        let valid = !plan.is_empty()
            && !self.inputs.is_empty()
            && plan.iter().all(|(_, t)| t.is_finite() && *t > 0.0);
        valid.then_some(plan)
    }

    /// Case `i` in the closed form ([`Study::closed_plan`]'s `plan`) at the
    /// point whose `6 × N` sensitivities are `rows`: FORM's branches
    /// `g_b = I_c − sign·E_c` in `Form::run`'s order (per component `+`,
    /// then `−` when two-sided), the nearest (the first of equal ones).
    fn closed_case(
        &self,
        i: usize,
        inputs: &Inputs,
        rows: &[f64],
        plan: &[(usize, f64)],
        a: &mut [f64],
    ) -> CaseResult {
        let (beta, termination) = self.closed_best(inputs, rows, plan, a);
        let mut c = self.case(i, normal::cdf(beta), normal::sf(beta), beta);
        c.form = Some(self.closed_form_case(termination, plan));
        c
    }

    /// The index `β` of a closed-form case ([`Study::closed_case`]) and how
    /// its nearest branch ended, `a` scratch of `N` values.
    fn closed_best(
        &self,
        inputs: &Inputs,
        rows: &[f64],
        plan: &[(usize, f64)],
        a: &mut [f64],
    ) -> (f64, Termination) {
        let n = inputs.len();
        let signs: &[f64] = match self.spec.sided {
            Sided::Upper => &[1.0],
            Sided::Two => &[1.0, -1.0],
        };
        let mut best: Option<(f64, Termination)> = None;
        for &(c, tolerance) in plan {
            let m = inputs.project(&rows[c * n..(c + 1) * n], a);
            for &sign in signs {
                let (beta, _, termination) = crate::form::closed_beta(a, m, tolerance, sign);
                if best.is_none_or(|(b, _)| beta < b) {
                    best = Some((beta, termination));
                }
            }
        }
        best.unwrap_or((f64::NAN, Termination::Degenerate))
    }

    /// FORM's account of a closed-form case of `plan`.
    fn closed_form_case(&self, termination: Termination, plan: &[(usize, f64)]) -> FormCase {
        FormCase {
            termination,
            converged: true,
            iterations: 0,
            exact: plan.len() == 1 && self.spec.sided == Sided::Upper,
        }
    }

    /// Runs `run` on the event of every case of `set` and keeps `keep` of
    /// its result (given the case's index in the study), a block of
    /// [`CASE_BLOCK`] cases at a time (in parallel within the block): an
    /// event and its full result (design point, direction cosines) live only
    /// while their block runs, so a study of a million points keeps only its
    /// cases. The cases come in the set's order whatever
    /// the blocks.
    fn cases_in_blocks<T: Send>(
        &self,
        set: CaseSet<'_>,
        progress: &dyn Progress,
        run: impl Fn(&Event<'_>) -> Result<T, ReliabilityError> + Sync + Send,
        keep: impl Fn(usize, T) -> CaseResult,
    ) -> Result<Vec<CaseResult>, ReliabilityError> {
        let total = set.len();
        let mut cases = Vec::with_capacity(total);
        let mut start = 0;
        while start < total {
            let end = (start + CASE_BLOCK).min(total);
            let events = self.events_in(set, start..end)?;
            let results = per_event(&events, &run)?;
            cases.extend(
                results
                    .into_iter()
                    .enumerate()
                    .map(|(k, r)| keep(set.id(start + k), r)),
            );
            progress.advance((end - start) as u64);
            start = end;
        }
        Ok(cases)
    }

    /// The events of the cases at `positions` of `set`, each consecutive
    /// run of case indices through [`Study::events_of`].
    fn events_in(
        &self,
        set: CaseSet<'_>,
        positions: Range<usize>,
    ) -> Result<Vec<Event<'_>>, ReliabilityError> {
        let ids = match set {
            CaseSet::All(_) => return self.events_of(positions),
            CaseSet::Ids(ids) => &ids[positions],
        };
        let mut out = Vec::with_capacity(ids.len());
        let mut k = 0;
        while k < ids.len() {
            let mut e = k + 1;
            while e < ids.len() && ids[e] == ids[e - 1] + 1 {
                e += 1;
            }
            out.extend(self.events_of(ids[k]..ids[e - 1] + 1)?);
            k = e;
        }
        Ok(out)
    }

    /// SORM on the cases of `set`, telling `progress` of each block of
    /// cases done.
    fn sorm_cases(
        &self,
        sorm: &Sorm,
        set: CaseSet<'_>,
        progress: &dyn Progress,
    ) -> Result<Vec<CaseResult>, ReliabilityError> {
        self.cases_in_blocks(
            set,
            progress,
            |e| sorm.run(e),
            |i, r: SormResult| {
                let mut c = self.case(i, r.reliability, r.pf, r.beta);
                c.form = Some(FormCase::of(&r.form));
                c.calls = r.form.calls;
                c.sorm = Some(Box::new(SormCase::of(&r)));
                c
            },
        )
    }

    /// `sampler` on the cases of `set`, each on the streams of its index in
    /// the study.
    fn sampled_cases<S: Sampler<Output = SimulationResult>>(
        &self,
        sampler: &S,
        set: CaseSet<'_>,
        progress: &dyn Progress,
    ) -> Result<Vec<CaseResult>, ReliabilityError> {
        let events = self.events_in(set, 0..set.len())?;
        let results = sampler.run_streams(&events, set.streams(), progress)?;
        Ok(self.sampled(set, &results))
    }

    /// Runs `algorithm` on every case: FORM (exact for one-sided components
    /// in normal inputs) and SORM (FORM, then the exact curvatures at its
    /// design point, [`crate::sorm`]; the case's probability is Tvedt's) a
    /// block of cases at a time, a sampler under its own stop rule with each
    /// case on the random streams of its index. `progress` hears of the
    /// samples drawn, or for FORM and SORM, which draw none, of the cases
    /// done.
    pub fn run(
        &self,
        algorithm: &Algorithm,
        progress: &dyn Progress,
    ) -> Result<StudyResult, ReliabilityError> {
        let cases = self.run_set(algorithm, self.all_cases(), progress)?;
        Ok(self.finish(algorithm.method(), cases))
    }

    /// Runs `algorithm` on the cases `ids` (indices in the study, target-major,
    /// ascending), each exactly as [`Study::run`] runs it (a sampler's case
    /// draws the streams of its index in the study): what a path run a
    /// block of instants at a time runs.
    pub fn run_cases(
        &self,
        algorithm: &Algorithm,
        ids: &[usize],
        progress: &dyn Progress,
    ) -> Result<Vec<CaseResult>, ReliabilityError> {
        let total = self.targets.len() * self.points.len();
        if let Some(&bad) = ids.iter().find(|&&i| i >= total) {
            return Err(ReliabilityError::Dimension {
                what: "case index",
                expected: total,
                found: bad,
            });
        }
        self.run_set(algorithm, CaseSet::Ids(ids), progress)
    }

    fn all_cases(&self) -> CaseSet<'static> {
        CaseSet::All(self.targets.len() * self.points.len())
    }

    fn run_set(
        &self,
        algorithm: &Algorithm,
        set: CaseSet<'_>,
        progress: &dyn Progress,
    ) -> Result<Vec<CaseResult>, ReliabilityError> {
        match algorithm {
            Algorithm::Form(form) => self.form_cases(form, set, progress),
            Algorithm::Sorm(sorm) => self.sorm_cases(sorm, set, progress),
            Algorithm::Subset(ss) => self.subset_cases(ss, set, progress),
            Algorithm::ImportanceSampling(is) => self.sampled_cases(is, set, progress),
            Algorithm::MonteCarlo(mc) => self.sampled_cases(mc, set, progress),
            Algorithm::Directional(ds) => self.sampled_cases(ds, set, progress),
        }
    }

    fn subset_cases(
        &self,
        ss: &SubsetSimulation,
        set: CaseSet<'_>,
        progress: &dyn Progress,
    ) -> Result<Vec<CaseResult>, ReliabilityError> {
        let events = self.events_in(set, 0..set.len())?;
        let results = ss.run_streams(&events, set.streams(), progress)?;
        Ok(results
            .into_iter()
            .enumerate()
            .map(|(k, r)| {
                let mut c = self.case(set.id(k), r.reliability, r.pf, r.beta);
                c.std_error = Some(r.std_error);
                c.cov = Some(r.cov);
                c.samples = Some(r.samples);
                c.calls = Calls {
                    values: r.calls,
                    gradients: 0,
                };
                c.stopping = Some(r.stopping);
                c.levels = Some(r.levels);
                c
            })
            .collect())
    }

    fn sampled(&self, set: CaseSet<'_>, results: &[SimulationResult]) -> Vec<CaseResult> {
        results
            .iter()
            .enumerate()
            .map(|(k, r)| {
                let mut c = self.case(set.id(k), r.reliability, r.pf, r.beta);
                c.std_error = Some(r.std_error);
                c.cov = Some(r.cov);
                c.samples = Some(r.samples);
                c.form = r.form.as_ref().map(FormCase::of);
                c.stopping = r.stopping;
                let form_calls = r.form.as_ref().map(|f| f.calls).unwrap_or_default();
                c.calls = Calls {
                    values: form_calls.values + r.calls,
                    gradients: form_calls.gradients,
                };
                c
            })
            .collect()
    }

    fn case(&self, i: usize, reliability: f64, pf: f64, beta: f64) -> CaseResult {
        let np = self.points.len();
        CaseResult {
            target: self.targets[i / np],
            point: self.points.point(i % np),
            reliability,
            pf,
            beta,
            std_error: None,
            cov: None,
            samples: None,
            form: None,
            calls: Calls::default(),
            stopping: None,
            levels: None,
            sorm: None,
        }
    }

    /// The study's result from its cases, every case in order (its
    /// summaries and requirement from the cases' reliabilities).
    pub fn finish(&self, method: Method, cases: Vec<CaseResult>) -> StudyResult {
        let mut running = Running::new(self.targets.len(), self.points.len());
        running.add(0, &cases);
        let mut result = self.finish_running(method, &running);
        result.cases = cases;
        result
    }

    /// The result of a run whose cases `running` added up, without the
    /// cases.
    fn finish_running(&self, method: Method, running: &Running) -> StudyResult {
        let summaries = (self.targets.iter().zip(&running.targets))
            .map(|(target, r)| {
                let mean = r.sum / r.count.max(1) as f64;
                Summary {
                    target: *target,
                    mean,
                    min: r.min,
                    max: r.max,
                    met: self
                        .spec
                        .requirement
                        .map(|req| r.min >= req.min && mean >= req.mean),
                }
            })
            .collect();
        StudyResult {
            method,
            variables: self.variables.clone(),
            cases: Vec::new(),
            summaries,
            requirement: self.spec.requirement,
        }
    }

    /// Runs `algorithm` on every case in [`Study::run`]'s order, `block`
    /// cases at a time (each block's cases exactly as `run` runs them: a
    /// sampler's case on the streams of its index), hands each block to
    /// `f` and keeps only the summaries: a study of 10⁷ points runs in the
    /// memory of one block. The result's summaries equal `run`'s bit for
    /// bit (the same sums in the same order); its `cases` are empty.
    ///
    /// # Errors
    /// The first error of a block's run, or of `f`, ends the run.
    pub fn run_blocks<E: From<ReliabilityError>>(
        &self,
        algorithm: &Algorithm,
        progress: &dyn Progress,
        block: usize,
        mut f: impl FnMut(&[CaseResult]) -> Result<(), E>,
    ) -> Result<StudyResult, E> {
        let total = self.targets.len() * self.points.len();
        let mut running = Running::new(self.targets.len(), self.points.len());
        let mut start = 0;
        while start < total {
            let end = (start + block.max(1)).min(total);
            let ids: Vec<usize> = (start..end).collect();
            let cases = self.run_set(algorithm, CaseSet::Ids(&ids), progress)?;
            running.add(start, &cases);
            f(&cases)?;
            start = end;
        }
        Ok(self.finish_running(algorithm.method(), &running))
    }

    /// Runs `algorithm` on every case and adds them up without keeping
    /// them ([`Totals`], `keep` least reliable cases per target): what
    /// [`Adding`] makes of [`Study::run_blocks`]'s blocks, bit for bit,
    /// in the memory of one block.
    ///
    /// Where FORM takes the closed form for every target (every input
    /// normal and the same at every point, every branch a half-space,
    /// [`Study::closed_plan`]), the grid is passed once, a block of points
    /// at a time: one evaluation of the sensitivities serves every target,
    /// the cases are computed in parallel without forming them, and a case
    /// is formed only when it is one of the extremes kept.
    ///
    /// # Errors
    /// The first error of the run.
    pub fn run_totals(
        &self,
        algorithm: &Algorithm,
        progress: &dyn Progress,
        keep: usize,
    ) -> Result<Totals, ReliabilityError> {
        if let Algorithm::Form(_) = algorithm {
            let plans: Option<Vec<Vec<(usize, f64)>>> =
                self.targets.iter().map(|&t| self.closed_plan(t)).collect();
            if let Some(plans) =
                plans.filter(|_| self.point_inputs.is_none() && self.inputs.is_affine())
            {
                return self.closed_totals(&plans, progress, keep);
            }
        }
        let mut adding = Adding::new(self, keep);
        let result = self.run_blocks(algorithm, progress, CASE_BLOCK, |b| {
            adding.add(b);
            Ok::<(), ReliabilityError>(())
        })?;
        Ok(adding.finish(result))
    }

    /// [`Study::run_totals`] where every target's cases are closed-form
    /// (`plans`, one per target).
    fn closed_totals(
        &self,
        plans: &[Vec<(usize, f64)>],
        progress: &dyn Progress,
        keep: usize,
    ) -> Result<Totals, ReliabilityError> {
        let (nt, np, n) = (self.targets.len(), self.points.len(), self.inputs.len());
        let n6 = 6 * n;
        let mut running = Running::new(nt, np);
        let mut adding = Adding::new(self, keep);
        let mut rows = vec![0.0; POINT_BLOCK.min(np) * n6];
        let mut closed = vec![(0.0, 0.0, Termination::ClosedForm); POINT_BLOCK.min(np) * nt];
        for start in (0..np).step_by(POINT_BLOCK) {
            let len = POINT_BLOCK.min(np - start);
            let (rows, closed) = (&mut rows[..len * n6], &mut closed[..len * nt]);
            // Per chunk of points: their sensitivities, then per point and
            // target `β`, `R = Φ(β)` and how the nearest branch ended.
            (rows.par_chunks_mut(POINT_CHUNK * n6.max(1)))
                .zip(closed.par_chunks_mut(POINT_CHUNK * nt))
                .enumerate()
                .map_init(
                    || (vec![0.0; n], Vec::new()),
                    |(a, qs), (k, (rows, closed))| {
                        let first = start + k * POINT_CHUNK;
                        let m = closed.len() / nt.max(1);
                        self.sensitivities_into(first..first + m, qs, rows)?;
                        for (j, out) in closed.chunks_exact_mut(nt.max(1)).enumerate() {
                            let s = &rows[j * n6..(j + 1) * n6];
                            for (o, plan) in out.iter_mut().zip(plans) {
                                let (beta, termination) =
                                    self.closed_best(&self.inputs, s, plan, a);
                                *o = (beta, normal::cdf(beta), termination);
                            }
                        }
                        Ok(())
                    },
                )
                .collect::<Vec<Result<(), ReliabilityError>>>()
                .into_iter()
                // The first refusal in point order, whatever the threads.
                .collect::<Result<(), ReliabilityError>>()?;
            // In case order per target: the sums, the extremes, the tally.
            for (t, plan) in plans.iter().enumerate() {
                let mut counts = [0; Termination::ALL.len()];
                let target = &mut adding.targets[t];
                for j in 0..len {
                    let (beta, reliability, termination) = closed[j * nt + t];
                    running.add_case(t, reliability);
                    counts[termination.index()] += 1;
                    target.keep_extreme(reliability, None, keep, || {
                        let i = t * np + start + j;
                        let mut c = self.case(i, normal::cdf(beta), normal::sf(beta), beta);
                        c.form = Some(self.closed_form_case(termination, plan));
                        c
                    });
                }
                target.tally.add_closed(&counts);
                adding.tally.add_closed(&counts);
            }
            progress.advance((len * nt) as u64);
        }
        Ok(adding.finish(self.finish_running(Method::Form, &running)))
    }

    /// The sensitivities of the points `range` into `out` (`qs` scratch
    /// for the points): copied when the study keeps them, evaluated
    /// otherwise (and refused when not finite).
    fn sensitivities_into(
        &self,
        range: Range<usize>,
        qs: &mut Vec<f64>,
        out: &mut [f64],
    ) -> Result<(), ReliabilityError> {
        let n6 = 6 * self.inputs.len();
        match &self.rows {
            Rows::Stored(s) => {
                out.copy_from_slice(&s[range.start * n6..range.end * n6]);
                Ok(())
            }
            Rows::OnDemand { model, parameters } => {
                evaluate_into(&**model, parameters, &self.points, range.clone(), qs, out)?;
                check_moments(&self.inputs, &self.variables, &self.points, range, out)
            }
        }
    }

    /// The sensitivities of every target at point `p`.
    pub fn sensitivity_at(
        &self,
        p: usize,
        form: &Form,
    ) -> Result<Vec<(Target, SensitivityResult)>, ReliabilityError> {
        self.targets
            .iter()
            .map(|&t| {
                let e = self.event(t, p)?;
                let f = form.run(&e)?;
                Ok((t, sensitivity(&e, &f)?))
            })
            .collect()
    }

    /// The sensitivities of every target, averaged over the grid (the
    /// paper's Figures 6-8), each list sorted by `|∂R/∂σ|`, largest first.
    pub fn sensitivity_mean(
        &self,
        form: &Form,
    ) -> Result<Vec<TargetSensitivity>, ReliabilityError> {
        // A block of points at a time (in parallel within it), their
        // sums added in point order: a grid of 10⁷ points holds one block.
        let np = self.points.len();
        let mut sums = Averaging::new(self.targets.len(), self.inputs.len());
        for start in (0..np).step_by(CASE_BLOCK) {
            let block: Vec<Vec<(Target, SensitivityResult)>> = (start
                ..(start + CASE_BLOCK).min(np))
                .into_par_iter()
                .map(|p| self.sensitivity_at(p, form))
                .collect::<Result<_, _>>()?;
            sums.add(&block);
        }
        Ok(self.average(sums))
    }

    /// The sensitivities of every target at an arbitrary point (axis values in
    /// the model's variable order), sorted like [`Study::sensitivity_mean`].
    /// A study whose inputs differ from point to point has no inputs at an
    /// arbitrary point ([`ReliabilityError::InputsVaryAtPoint`]); a study
    /// on a one-point grid has them.
    pub fn sensitivity_point<M: ErrorModel + ?Sized>(
        &self,
        model: &M,
        parameters: &[f64],
        point: &[f64],
        form: &Form,
    ) -> Result<Vec<TargetSensitivity>, ReliabilityError> {
        if point.len() != self.variables.len() {
            return Err(ReliabilityError::Dimension {
                what: "point coordinates",
                expected: self.variables.len(),
                found: point.len(),
            });
        }
        if self.varies() {
            return Err(ReliabilityError::InputsVaryAtPoint);
        }
        let single = Study::at_points(
            model,
            parameters,
            self.inputs.clone(),
            self.spec.clone(),
            vec![point.to_vec()],
        )?;
        let mut sums = Averaging::new(single.targets.len(), single.inputs.len());
        sums.add(&[single.sensitivity_at(0, form)?]);
        Ok(single.average(sums))
    }

    /// The means of the sums `sums` (per target, its errors sorted by
    /// `|∂R/∂σ|`).
    fn average(&self, sums: Averaging) -> Vec<TargetSensitivity> {
        let np = sums.points.max(1) as f64;
        self.targets
            .iter()
            .zip(sums.targets)
            .map(|(&target, (acc, method))| {
                let mut errors: Vec<ErrorSensitivity> = acc
                    .iter()
                    .zip(self.inputs.names())
                    .map(|(a, name)| ErrorSensitivity {
                        error: name.clone(),
                        dr_dstd: a[0] / np,
                        dr_dmean: a[1] / np,
                        importance: a[2] / np,
                        mean_abs_dr_dstd: a[3] / np,
                        mean_abs_dr_dmean: a[4] / np,
                    })
                    .collect();
                errors.sort_by(|a, b| b.dr_dstd.abs().total_cmp(&a.dr_dstd.abs()));
                TargetSensitivity {
                    target,
                    method,
                    errors,
                }
            })
            .collect()
    }
}

/// Per target, the sums over the points of each error's sensitivities
/// (`∂R/∂σ`, `∂R/∂μ`, importance and the two absolute values) and how they
/// were obtained: what [`Study::sensitivity_mean`] averages.
struct Averaging {
    targets: Vec<(Vec<[f64; 5]>, SensitivityMethod)>,
    points: usize,
}

impl Averaging {
    fn new(targets: usize, inputs: usize) -> Averaging {
        Averaging {
            targets: vec![(vec![[0.0; 5]; inputs], SensitivityMethod::Exact); targets],
            points: 0,
        }
    }

    /// Adds the next points' sensitivities (per point, per target).
    fn add(&mut self, per_point: &[Vec<(Target, SensitivityResult)>]) {
        for point in per_point {
            for ((acc, method), (_, r)) in self.targets.iter_mut().zip(point) {
                if r.method == SensitivityMethod::Form {
                    *method = SensitivityMethod::Form;
                }
                for (a, s) in acc.iter_mut().zip(&r.inputs) {
                    a[0] += s.dr_dstd;
                    a[1] += s.dr_dmean;
                    a[2] += s.importance;
                    a[3] += s.dr_dstd.abs();
                    a[4] += s.dr_dmean.abs();
                }
            }
            self.points += 1;
        }
    }
}

/// The parameter count checked and the inputs put in the model's error order;
/// returns them with the model's variable names.
fn checked_inputs<M: ErrorModel + ?Sized>(
    model: &M,
    parameters: &[f64],
    inputs: Inputs,
) -> Result<(Inputs, Vec<String>), ReliabilityError> {
    let errors = model.errors();
    if parameters.len() != model.parameters().len() {
        return Err(ReliabilityError::Dimension {
            what: "parameter values",
            expected: model.parameters().len(),
            found: parameters.len(),
        });
    }
    let order = errors
        .iter()
        .map(|e| {
            inputs
                .index(e)
                .ok_or_else(|| ReliabilityError::MissingInput((*e).to_string()))
        })
        .collect::<Result<Vec<usize>, _>>()?;
    let inputs = inputs.select(&order)?;
    let variables = model.variables().iter().map(|v| v.to_string()).collect();
    Ok((inputs, variables))
}

/// An explicit list of points checked against the model's variables (none
/// empty, each of the model's length, finite), with the spec (its grid
/// emptied) and its targets.
#[allow(clippy::type_complexity)]
fn listed_points(
    spec: StudySpec,
    points: Vec<Vec<f64>>,
    variables: &[String],
) -> Result<(StudySpec, Points, Vec<Target>), ReliabilityError> {
    if points.is_empty() {
        return Err(ReliabilityError::EmptyGrid("no point is given".into()));
    }
    for q in &points {
        if q.len() != variables.len() {
            return Err(ReliabilityError::Dimension {
                what: "point coordinates",
                expected: variables.len(),
                found: q.len(),
            });
        }
        if q.iter().any(|x| !x.is_finite()) {
            return Err(ReliabilityError::NonFinite("the points"));
        }
    }
    let spec = StudySpec {
        grid: Grid { axes: Vec::new() },
        ..spec
    };
    let targets = targets(&spec)?;
    Ok((
        spec,
        Points::Listed(points.into_iter().map(Arc::from).collect()),
        targets,
    ))
}

/// The targets of `spec` in case order (its toleranced components, then its
/// system), the tolerances and the system checked.
fn targets(spec: &StudySpec) -> Result<Vec<Target>, ReliabilityError> {
    if spec.tolerances.is_empty() {
        return Err(ReliabilityError::EmptyGrid("no tolerance is given".into()));
    }
    for (c, t) in &spec.tolerances {
        if !t.is_finite() || *t <= 0.0 {
            return Err(ReliabilityError::InvalidTolerance {
                component: c.name().into(),
                value: *t,
            });
        }
    }
    let mut targets: Vec<Target> = spec
        .tolerances
        .iter()
        .map(|(c, _)| Target::Component(*c))
        .collect();
    match spec.system {
        Some(System::Series) => targets.push(Target::Series),
        Some(System::Volumetric { tolerance }) => {
            if !tolerance.is_finite() || tolerance <= 0.0 {
                return Err(ReliabilityError::InvalidTolerance {
                    component: "volumetric".into(),
                    value: tolerance,
                });
            }
            if !spec
                .tolerances
                .iter()
                .any(|(c, _)| matches!(c, Component::Px | Component::Py | Component::Pz))
            {
                return Err(ReliabilityError::UnknownName {
                    kind: "component",
                    name: "volumetric (needs px, py or pz in the tolerances)".into(),
                    hint: None,
                });
            }
            targets.push(Target::Volumetric)
        }
        None => {}
    }
    Ok(targets)
}

/// The `6 × N` sensitivity matrices of the points `range` (checked against
/// the model's variables), flat, through the model's batch entry point (a
/// compiled model's tape over blocks of points, a `machine!` type's batched
/// kernels; the values of `sensitivity` point by point, to rounding), each
/// point refused by [`check_moments`] when a value or a moment is not
/// finite.
fn evaluate<M: ErrorModel + ?Sized>(
    model: &M,
    parameters: &[f64],
    (inputs, variables): (&Inputs, &[String]),
    points: &Points,
    range: Range<usize>,
) -> Result<Vec<f64>, ReliabilityError> {
    let mut flat = vec![0.0; range.len() * 6 * model.errors().len()];
    evaluate_into(
        model,
        parameters,
        points,
        range.clone(),
        &mut Vec::new(),
        &mut flat,
    )?;
    check_moments(inputs, variables, points, range, &flat)?;
    Ok(flat)
}

/// The sensitivities of the points `range` into `out` (`range.len()`
/// matrices of `6 × N`), the points formed in `qs` (both reused by the
/// caller from block to block), unchecked: [`check_moments`] refuses a
/// point with a non-finite value, naming it.
fn evaluate_into<M: ErrorModel + ?Sized>(
    model: &M,
    parameters: &[f64],
    points: &Points,
    range: Range<usize>,
    qs: &mut Vec<f64>,
    out: &mut [f64],
) -> Result<(), ReliabilityError> {
    let n6 = 6 * model.errors().len();
    let nv = points.variables();
    qs.clear();
    qs.resize(range.len() * nv, 0.0);
    if nv > 0 {
        for (p, q) in range.zip(qs.chunks_exact_mut(nv)) {
            points.fill(p, q);
        }
    }
    if model.sensitivity_points(qs, parameters, out).is_err() {
        // The points were checked against the model's variables; a model
        // whose lengths still disagree is evaluated point by point.
        for (k, s) in out.chunks_exact_mut(n6.max(1)).enumerate() {
            model.sensitivity(&qs[k * nv..(k + 1) * nv], parameters, s);
        }
    }
    Ok(())
}

/// Whether every value of `s` is finite, and the largest `|s|` (NaN
/// skipped): one pass in four lanes (what the compiler vectorises).
fn scan(s: &[f64]) -> (bool, f64) {
    let (mut big, mut bad) = ([0.0f64; 4], [false; 4]);
    let mut chunks = s.chunks_exact(4);
    for c in &mut chunks {
        for k in 0..4 {
            let v = c[k].abs();
            bad[k] |= !v.is_finite();
            big[k] = if v > big[k] { v } else { big[k] };
        }
    }
    for &v in chunks.remainder() {
        let v = v.abs();
        bad[0] |= !v.is_finite();
        big[0] = if v > big[0] { v } else { big[0] };
    }
    (
        !(bad[0] | bad[1] | bad[2] | bad[3]),
        big[0].max(big[1]).max(big[2].max(big[3])),
    )
}

/// Refuses a point whose error moments are not finite: the mean `Σ s·μ` or
/// the variance `SᵀΣS` of a component (what [`Study::moments`] and every
/// method compute) at `points` (the `6 × N` matrices `rows`).
fn check_moments(
    inputs: &Inputs,
    variables: &[String],
    points: &Points,
    range: Range<usize>,
    rows: &[f64],
) -> Result<(), ReliabilityError> {
    let n = inputs.len();
    let means = inputs.means();
    // A bound first: every partial sum of `Σ s·μ` is at most
    // `max|s|·Σ|μ|` and of the independent variance `Σ s²σ²` at most
    // `max s²·Σσ²`; below 1e300 both sums are finite, so only a point past
    // the bound (or with correlated inputs) is summed here.
    let (mu, var) = (
        means.iter().map(|m| m.abs()).sum::<f64>(),
        inputs.stds().iter().map(|s| s * s).sum::<f64>(),
    );
    let bounded = inputs.correlations().is_empty() && mu.is_finite() && var.is_finite();
    for (p, s) in range.zip(rows.chunks_exact((6 * n).max(1))) {
        let (finite, big) = scan(s);
        if bounded && finite && big * mu < 1e300 && big * big * var < 1e300 {
            continue;
        }
        for c in Component::ALL {
            let row = &s[c.index() * n..(c.index() + 1) * n];
            let mean: f64 = row.iter().zip(means).map(|(s, m)| s * m).sum();
            let what = if !mean.is_finite() {
                "mean"
            } else if !inputs.covariance(row, row).is_finite() {
                "standard deviation"
            } else {
                continue;
            };
            return Err(ReliabilityError::Overflow {
                at: point_text(variables, &points.point(p)),
                what: format!("{what} of {}", c.name()),
            });
        }
    }
    Ok(())
}

/// `x = 1, y = 2.5e300`: a point by its variables (values beyond a million
/// in exponent form).
pub(crate) fn point_text(variables: &[String], q: &[f64]) -> String {
    (variables.iter().zip(q))
        .map(|(v, x)| match x.abs() < 1e6 {
            true => format!("{v} = {x}"),
            false => format!("{v} = {x:e}"),
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// The points of a grid in the model's variable order (first grid axis
/// slowest), kept as its axes; a model without variables has the one empty
/// point.
fn grid_points(grid: &Grid, variables: &[String]) -> Result<Points, ReliabilityError> {
    let axis_of = grid.axis_of(variables)?;
    Ok(Points::Grid {
        axes: grid.axes.iter().map(|(_, v)| v.clone()).collect(),
        // Every variable has its axis ([`Grid::axis_of`] refuses one without).
        of: axis_of.iter().map(|a| a.unwrap_or(0)).collect(),
        count: grid.len().max(1),
    })
}

/// `Φ(I/σ_E)`: the closed-form reliability of one upper tolerance on a
/// zero-mean normal component with standard deviation `σ_E` (Eq. 21, 31).
pub fn closed_form_reliability(tolerance: f64, sigma_e: f64) -> f64 {
    normal::cdf(tolerance / sigma_e)
}

/// Each target's reliabilities added up case by case, in case order: the
/// one account behind [`Study::finish`] and [`Study::run_blocks`].
#[derive(Debug, Clone)]
struct Running {
    targets: Vec<RunningTarget>,
    points: usize,
}

/// One target's running sum, least and largest reliability.
#[derive(Debug, Clone)]
struct RunningTarget {
    sum: f64,
    min: f64,
    max: f64,
    count: usize,
}

impl Running {
    fn new(targets: usize, points: usize) -> Running {
        Running {
            targets: vec![
                RunningTarget {
                    // `Iterator::sum`'s start for floats: the same sums.
                    sum: -0.0,
                    min: f64::INFINITY,
                    max: f64::NEG_INFINITY,
                    count: 0,
                };
                targets
            ],
            points,
        }
    }

    /// The cases `cases`, the first of them case `first` of the study.
    fn add(&mut self, first: usize, cases: &[CaseResult]) {
        for (k, c) in cases.iter().enumerate() {
            self.add_case((first + k) / self.points.max(1), c.reliability);
        }
    }

    /// A case of target `t` (the target's cases added in their order).
    fn add_case(&mut self, t: usize, reliability: f64) {
        let t = &mut self.targets[t];
        t.sum += reliability;
        t.min = t.min.min(reliability);
        t.max = t.max.max(reliability);
        t.count += 1;
    }
}

/// The cases a run covers: every case of the study (`All(n)`), or the
/// listed ones (`Ids`: indices in the study, target-major, ascending).
#[derive(Debug, Clone, Copy)]
enum CaseSet<'a> {
    All(usize),
    Ids(&'a [usize]),
}

impl CaseSet<'_> {
    fn len(&self) -> usize {
        match self {
            CaseSet::All(n) => *n,
            CaseSet::Ids(ids) => ids.len(),
        }
    }

    /// The study index of the set's `k`-th case.
    fn id(&self, k: usize) -> usize {
        match self {
            CaseSet::All(_) => k,
            CaseSet::Ids(ids) => ids[k],
        }
    }

    /// The random streams of the set's cases: their study indices.
    fn streams(&self) -> Streams<'_> {
        match self {
            CaseSet::All(_) => Streams::ALL,
            CaseSet::Ids(ids) => Streams::of(ids),
        }
    }
}

/// The cases [`Study::run`] runs at a time with FORM or SORM.
const CASE_BLOCK: usize = 4096;

/// The points [`Study::run_totals`]'s closed-form pass evaluates at a time
/// (every target's cases of them), and per task within the block.
const POINT_BLOCK: usize = 4096;
const POINT_CHUNK: usize = 256;

/// `f` on every event: in parallel from 64 events on (below that the
/// threads cost more than they save); results in event order.
fn per_event<T: Send>(
    events: &[Event<'_>],
    f: impl Fn(&Event<'_>) -> Result<T, ReliabilityError> + Sync + Send,
) -> Result<Vec<T>, ReliabilityError> {
    if events.len() < 64 {
        events.iter().map(f).collect()
    } else {
        events.par_iter().map(f).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::machine;
    use crate::util::fixtures::gantry;

    #[test]
    fn form_and_sorm_in_blocks_equal_each_event_run_alone() {
        // A grid of 12 × 12 × 12 points with the volumetric system: 4 targets,
        // 6,912 cases, so the cases cross a block boundary (CASE_BLOCK = 4096).
        let (m, model) = gantry();
        let system = Some(System::Volumetric { tolerance: 0.04 });
        let mut spec = machine::spec(&m, system).unwrap();
        let axis = |lo: f64, hi: f64| (0..12).map(|k| lo + (hi - lo) * k as f64 / 11.0).collect();
        spec.grid = Grid {
            axes: vec![
                ("x".into(), axis(0.0, 1000.0)),
                ("y".into(), axis(-1500.0, 1500.0)),
                ("z".into(), axis(600.0, 1400.0)),
            ],
        };
        let inputs = machine::inputs(&m).unwrap();
        let params = machine::parameters(&m, &[]).unwrap();
        let study = Study::new(&model, &params, inputs, spec).unwrap();
        let total = study.targets().len() * study.points().len();
        assert!(total > CASE_BLOCK, "{total} cases");
        let form = Form::default();
        let r = study.run(&Algorithm::Form(form), &()).unwrap();
        let events = study.events().unwrap();
        assert_eq!(r.cases.len(), events.len());
        for (c, e) in r.cases.iter().zip(&events) {
            let alone = form.run(e).unwrap();
            assert_eq!(c.reliability.to_bits(), alone.reliability.to_bits());
            assert_eq!(c.beta.to_bits(), alone.beta.to_bits());
            assert_eq!(c.calls, alone.calls);
        }
        // Every case names its own target and point, in case order.
        let np = study.points().len();
        for (i, c) in r.cases.iter().enumerate() {
            assert_eq!(c.target, study.targets()[i / np]);
            assert_eq!(c.point, study.points().point(i % np));
        }
        let sorm = Sorm::default();
        let s = study.run(&Algorithm::Sorm(sorm), &()).unwrap();
        for i in [0, CASE_BLOCK - 1, CASE_BLOCK, total - 1] {
            let alone = sorm.run(&events[i]).unwrap();
            assert_eq!(s.cases[i].pf.to_bits(), alone.pf.to_bits(), "case {i}");
        }
    }

    #[test]
    fn the_closed_form_cases_equal_form_run_on_their_events_bit_for_bit() {
        // One- and two-sided, the series system (several half-space
        // branches): every case as `Form::run` gives it on its event.
        let (m, model) = gantry();
        for sided in [Sided::Upper, Sided::Two] {
            let mut spec = machine::spec(&m, Some(System::Series)).unwrap();
            spec.sided = sided;
            spec.grid = Grid {
                axes: vec![
                    ("x".into(), vec![0.0, 500.0, 1000.0]),
                    ("y".into(), vec![-1500.0, 0.0, 700.0, 1500.0]),
                    ("z".into(), vec![600.0, 1400.0]),
                ],
            };
            let inputs = machine::inputs(&m).unwrap();
            let params = machine::parameters(&m, &[]).unwrap();
            let study = Study::new(&model, &params, inputs, spec).unwrap();
            assert_eq!(study.targets().len(), 4);
            let form = Form::default();
            let r = study.run(&Algorithm::Form(form), &()).unwrap();
            let events = study.events().unwrap();
            for (c, e) in r.cases.iter().zip(&events) {
                let alone = form.run(e).unwrap();
                assert_eq!(c.reliability.to_bits(), alone.reliability.to_bits());
                assert_eq!(c.pf.to_bits(), alone.pf.to_bits());
                assert_eq!(c.beta.to_bits(), alone.beta.to_bits());
                assert_eq!(c.form, Some(FormCase::of(&alone)), "{sided:?}");
                assert_eq!(c.calls, alone.calls);
            }
        }
    }

    #[test]
    fn a_run_in_blocks_hands_out_the_run_s_cases_and_summaries_bit_for_bit() {
        // 4 × 3 × 3 points, the series system: 4 targets, 144 cases in
        // blocks of 7 (the last short), every method.
        let (m, model) = gantry();
        let mut spec = machine::spec(&m, Some(System::Series)).unwrap();
        spec.grid = Grid {
            axes: vec![
                ("x".into(), vec![0.0, 300.0, 700.0, 1000.0]),
                ("y".into(), vec![-1500.0, 0.0, 1500.0]),
                ("z".into(), vec![600.0, 1000.0, 1400.0]),
            ],
        };
        spec.requirement = Some(Requirement {
            min: 0.9,
            mean: 0.95,
        });
        let inputs = machine::inputs(&m).unwrap();
        let params = machine::parameters(&m, &[]).unwrap();
        let model: SharedModel = Arc::new(model);
        let study = Study::on_demand(model, &params, inputs, spec).unwrap();
        let algorithms = [
            Algorithm::Form(Form::default()),
            Algorithm::Sorm(Sorm::default()),
            Algorithm::MonteCarlo(MonteCarlo {
                samples: 200,
                seed: 3,
                cov: None,
            }),
            Algorithm::ImportanceSampling(ImportanceSampling {
                samples: 200,
                seed: 5,
                form: Form::default(),
                cov: None,
            }),
            Algorithm::Directional(DirectionalSimulation {
                samples: 50,
                seed: 11,
                cov: Some(0.5),
            }),
            Algorithm::Subset(SubsetSimulation::new(200, 7)),
        ];
        for a in &algorithms {
            let whole = study.run(a, &()).unwrap();
            let mut cases = Vec::new();
            let mut blocks = 0;
            let streamed = study
                .run_blocks(a, &(), 7, |b: &[CaseResult]| {
                    assert!(b.len() <= 7);
                    cases.extend_from_slice(b);
                    blocks += 1;
                    Ok::<(), ReliabilityError>(())
                })
                .unwrap();
            assert_eq!(blocks, 144usize.div_ceil(7), "{:?}", a.method());
            assert!(streamed.cases.is_empty());
            assert_eq!(cases, whole.cases, "{:?}", a.method());
            for (x, y) in streamed.summaries.iter().zip(&whole.summaries) {
                assert_eq!(x.mean.to_bits(), y.mean.to_bits(), "{:?}", a.method());
                assert_eq!((x.min, x.max, x.met), (y.min, y.max, y.met));
            }
            assert_eq!(streamed.requirement_met(), whole.requirement_met());
        }
        // An error of the consumer ends the run.
        let mut seen = 0;
        let stopped = study.run_blocks(&algorithms[0], &(), 7, |_: &[CaseResult]| {
            seen += 1;
            if seen == 3 {
                Err(ReliabilityError::NonFinite("stop"))
            } else {
                Ok(())
            }
        });
        assert!(stopped.is_err());
        assert_eq!(seen, 3);
    }

    /// [`Study::run_totals`] against [`Adding`] over [`Study::run_blocks`]'
    /// blocks: the closed-form pass (one pass over a grid of more than one
    /// [`POINT_BLOCK`], every target from one evaluation) and the blocks
    /// give the same sums, tallies and extremes, bit for bit; kept and
    /// on-demand sensitivities, one- and two-sided, components and the
    /// series system, and a sampler (the blocks' own path).
    #[test]
    fn totals_equal_the_blocks_added_up_bit_for_bit() {
        let (m, model) = gantry();
        let params = machine::parameters(&m, &[]).unwrap();
        let shared: SharedModel = Arc::new(model.clone());
        let x: Vec<f64> = (0..47).map(|i| 1000.0 * i as f64 / 46.0).collect();
        let y: Vec<f64> = (0..11).map(|i| -1500.0 + 300.0 * i as f64).collect();
        let grid = Grid {
            axes: vec![
                ("x".into(), x),
                ("y".into(), y),
                // (1000 twice: equal cases, the first of them kept.)
                (
                    "z".into(),
                    vec![
                        600.0, 700.0, 800.0, 900.0, 1000.0, 1000.0, 1200.0, 1300.0, 1400.0,
                    ],
                ),
            ],
        };
        let mut checked = 0;
        for (sided, system) in [(Sided::Upper, None), (Sided::Two, Some(System::Series))] {
            let mut spec = machine::spec(&m, system).unwrap();
            spec.grid = grid.clone();
            spec.sided = sided;
            spec.requirement = Some(Requirement {
                min: 0.9,
                mean: 0.95,
            });
            let inputs = machine::inputs(&m).unwrap();
            let kept = Study::new(&model, &params, inputs.clone(), spec.clone()).unwrap();
            let lazy = Study::on_demand(shared.clone(), &params, inputs, spec).unwrap();
            assert!(kept.points().len() > POINT_BLOCK);
            for study in [&kept, &lazy] {
                for keep in [0, 1, 5] {
                    let a = Algorithm::Form(Form::default());
                    let fast = study.run_totals(&a, &(), keep).unwrap();
                    let mut adding = Adding::new(study, keep);
                    let result = study
                        .run_blocks(&a, &(), 1000, |b: &[CaseResult]| {
                            adding.add(b);
                            Ok::<(), ReliabilityError>(())
                        })
                        .unwrap();
                    let slow = adding.finish(result);
                    same_totals(&fast, &slow);
                    assert_eq!(
                        fast.tally.cases,
                        study.targets().len() * study.points().len()
                    );
                    assert_eq!(fast.targets[0].lowest.len(), keep);
                    checked += 1;
                }
            }
        }
        assert_eq!(checked, 12);
        // A sampler adds up its blocks (a small grid).
        let mut spec = machine::spec(&m, Some(System::Series)).unwrap();
        spec.grid.axes[0].1.truncate(2);
        let study = Study::on_demand(shared, &params, machine::inputs(&m).unwrap(), spec).unwrap();
        let mc = Algorithm::MonteCarlo(MonteCarlo {
            samples: 300,
            seed: 1,
            cov: None,
        });
        let totals = study.run_totals(&mc, &(), 3).unwrap();
        let mut whole = study.run(&mc, &()).unwrap();
        let mut adding = Adding::new(&study, 3);
        adding.add(&whole.cases);
        whole.cases.clear();
        same_totals(&totals, &adding.finish(whole));
        assert_eq!(totals.targets[0].samples, Some((300, 300)));
    }

    fn same_totals(a: &Totals, b: &Totals) {
        for (x, y) in a.result.summaries.iter().zip(&b.result.summaries) {
            assert_eq!(x.mean.to_bits(), y.mean.to_bits());
            assert_eq!((x.min, x.max, x.met), (y.min, y.max, y.met));
        }
        assert_eq!(a.tally, b.tally);
        for (x, y) in a.targets.iter().zip(&b.targets) {
            assert_eq!(x.tally, y.tally);
            assert_eq!(x.lowest, y.lowest);
            assert_eq!(x.highest, y.highest);
            assert_eq!(x.samples, y.samples);
        }
    }

    /// A point whose moments overflow is refused by the closed-form pass
    /// and by [`Study::check`] as by a run, naming the point.
    #[test]
    fn a_point_past_the_bound_is_refused_by_every_reader() {
        let (m, model) = gantry();
        let params = machine::parameters(&m, &[]).unwrap();
        let mut spec = machine::spec(&m, None).unwrap();
        spec.grid.axes[0].1 = vec![0.0, 1e300];
        let study =
            Study::on_demand(Arc::new(model), &params, machine::inputs(&m).unwrap(), spec).unwrap();
        let form = Algorithm::Form(Form::default());
        let run = study.run(&form, &()).unwrap_err().to_string();
        assert!(
            run.contains("x = 1e300") && run.contains("not finite"),
            "{run}"
        );
        assert_eq!(study.check().unwrap_err().to_string(), run);
        assert_eq!(
            study.run_totals(&form, &(), 5).unwrap_err().to_string(),
            run
        );
        // A study that keeps its sensitivities refuses it when built.
        let mut spec = machine::spec(&m, None).unwrap();
        spec.grid.axes[0].1 = vec![0.0, 1e300];
        let (_, model) = gantry();
        let kept = Study::new(&model, &params, machine::inputs(&m).unwrap(), spec);
        assert_eq!(kept.unwrap_err().to_string(), run);
        // Within the bound, the sums decide (1e100 mm: variances of 1e200·σ²).
        assert_eq!(
            super::scan(&[1.0, -3.0, f64::INFINITY]),
            (false, f64::INFINITY)
        );
        assert_eq!(super::scan(&[1.0, -3.0, 2.0, 0.5, -7.0]), (true, 7.0));
        assert!(!super::scan(&[f64::NAN, 0.0, 0.0, 0.0]).0);
    }

    #[test]
    fn at_points_equals_the_grid_study_at_the_same_points() {
        let (m, model) = gantry();
        let system = Some(System::Volumetric { tolerance: 0.04 });
        let grid = machine::study(&m, &model, &[], system).unwrap();
        // Every 7th grid point, in a shuffled order.
        let picked: Vec<usize> = (0..grid.points().len()).step_by(7).rev().collect();
        let points = picked
            .iter()
            .map(|&p| grid.points().point(p).to_vec())
            .collect();
        let spec = machine::spec(&m, system).unwrap();
        let inputs = machine::inputs(&m).unwrap();
        let at = Study::at_points(&model, &[], inputs, spec, points).unwrap();
        assert!(at.spec().grid.axes.is_empty());
        assert_eq!(at.targets(), grid.targets());
        let form = Form::default();
        let (rg, ra) = (
            grid.run(&Algorithm::Form(form), &()).unwrap(),
            at.run(&Algorithm::Form(form), &()).unwrap(),
        );
        let (ng, na) = (grid.points().len(), at.points().len());
        for t in 0..grid.targets().len() {
            for (k, &p) in picked.iter().enumerate() {
                let (a, b) = (&rg.cases[t * ng + p], &ra.cases[t * na + k]);
                assert_eq!(a.point, b.point);
                assert_eq!(a.target, b.target);
                assert_eq!(a.reliability, b.reliability);
                assert_eq!(a.beta, b.beta);
                assert_eq!(grid.moments(p).unwrap(), at.moments(k).unwrap());
            }
        }
    }

    #[test]
    fn an_unknown_grid_axis_gets_a_close_name_or_no_hint() {
        let (m, model) = gantry();
        let inputs = machine::inputs(&m).unwrap();
        let run = |axis: &str| {
            let mut spec = machine::spec(&m, None).unwrap();
            spec.grid.axes[0].0 = axis.to_string();
            Study::new(&model, &[], inputs.clone(), spec).unwrap_err()
        };
        let hint = |e: ReliabilityError| match e {
            ReliabilityError::UnknownName { hint, .. } => hint,
            other => panic!("{other:?}"),
        };
        // The variables are x, z, y: `zz` is close to `z`, `spindle` to none
        // (the first variable is not a suggestion).
        assert_eq!(hint(run("zz")), Some("z".to_string()));
        assert_eq!(hint(run("spindle")), None);
        let e = run("spindle");
        #[cfg(feature = "miette")]
        assert_eq!(
            miette::Diagnostic::code(&e).map(|c| c.to_string()),
            Some("chain::reliability::unknown_name".to_string())
        );
        assert_eq!(e.to_string(), "unknown variable `spindle`");
    }

    #[test]
    fn at_points_rejects_bad_points() {
        let (m, model) = gantry();
        let spec = machine::spec(&m, None).unwrap();
        let inputs = machine::inputs(&m).unwrap();
        let run = |points: Vec<Vec<f64>>| {
            Study::at_points(&model, &[], inputs.clone(), spec.clone(), points).unwrap_err()
        };
        assert!(matches!(run(vec![]), ReliabilityError::EmptyGrid(_)));
        assert_eq!(
            run(vec![vec![0.0, 1.0]]),
            ReliabilityError::Dimension {
                what: "point coordinates",
                expected: 3,
                found: 2
            }
        );
        assert_eq!(
            run(vec![vec![0.0, f64::NAN, 1.0]]),
            ReliabilityError::NonFinite("the points")
        );
        // The shared checks of `new` apply too.
        let mut bad = spec.clone();
        bad.tolerances[0].1 = -1.0;
        let err =
            Study::at_points(&model, &[], inputs.clone(), bad, vec![vec![0.0; 3]]).unwrap_err();
        assert!(matches!(err, ReliabilityError::InvalidTolerance { .. }));
        let err = Study::at_points(&model, &[1.0], inputs, spec, vec![vec![0.0; 3]]).unwrap_err();
        assert!(matches!(err, ReliabilityError::Dimension { .. }));
    }

    #[test]
    fn moments_match_the_events_affine_view_with_nonzero_means() {
        let (m, model) = gantry();
        let mut inputs = machine::inputs(&m).unwrap();
        // Shift two means so that the mean error is not zero.
        for (name, mean) in [("eyx", 2e-6), ("dxz", 0.004)] {
            let j = inputs.index(name).unwrap();
            let std = inputs.stds()[j];
            inputs = inputs.with_moments(j, mean, std).unwrap();
        }
        let spec = machine::spec(&m, None).unwrap();
        // (x, z, y): the model's variable order.
        let points = vec![vec![250.0, 1200.0, -750.0], vec![1000.0, 1500.0, 600.0]];
        let study = Study::at_points(&model, &[], inputs, spec, points).unwrap();
        for p in 0..2 {
            let mo = study.moments(p).unwrap();
            for c in [Component::Px, Component::Py, Component::Pz] {
                let event = study.event(Target::Component(c), p).unwrap();
                let affine = event.affine().unwrap();
                let scale = affine.std(0);
                assert!((mo.mean[c.index()] - affine.mean[0]).abs() <= 1e-15 + 1e-12 * scale);
                assert!((mo.std(c) - scale).abs() <= 1e-12 * scale);
            }
            assert!(mo.mean[0].abs() > 5e-4, "{:?}", mo.mean);
            // Symmetric, positive semi-definite diagonal.
            for a in 0..6 {
                assert!(mo.covariance[a][a] >= 0.0);
                for b in 0..6 {
                    assert_eq!(mo.covariance[a][b], mo.covariance[b][a]);
                }
            }
        }
    }

    fn erf(x: f64) -> f64 {
        2.0 * normal::cdf(x * std::f64::consts::SQRT_2) - 1.0
    }

    #[test]
    fn volumetric_moments_reproduce_closed_forms() {
        let pi = std::f64::consts::PI;
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-13 * b.abs().max(1e-300);
        // Zero-mean isotropic: the chi distribution with 3 degrees of freedom.
        let s = 0.007;
        let iso = [[s * s, 0.0, 0.0], [0.0, s * s, 0.0], [0.0, 0.0, s * s]];
        let v = VolumetricMoments::normal([0.0; 3], iso);
        assert!(close(v.mean, 2.0 * s * (2.0 / pi).sqrt()), "{v:?}");
        assert!(close(v.std, s * (3.0 - 8.0 / pi).sqrt()), "{v:?}");
        // Non-central isotropic (non-central chi, k = 3).
        for nu in [0.3, 1.0, 2.5, 8.0] {
            let m = [nu * s * 0.6, 0.0, nu * s * 0.8];
            let v = VolumetricMoments::normal(m, iso);
            let want = s
                * ((2.0 / pi).sqrt() * (-nu * nu / 2.0).exp()
                    + (nu + 1.0 / nu) * erf(nu / std::f64::consts::SQRT_2));
            assert!(close(v.mean, want), "nu {nu}: {} vs {want}", v.mean);
        }
        // Zero-mean, two equal variances, one zero: Rayleigh.
        let flat = [[s * s, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, s * s]];
        let v = VolumetricMoments::normal([0.0; 3], flat);
        assert!(close(v.mean, s * (pi / 2.0).sqrt()), "{v:?}");
        // One variance: half-normal.
        let line = [[0.0, 0.0, 0.0], [0.0, s * s, 0.0], [0.0, 0.0, 0.0]];
        let v = VolumetricMoments::normal([0.0; 3], line);
        assert!(close(v.mean, s * (2.0 / pi).sqrt()), "{v:?}");
        // Deterministic: |μ|, no spread.
        let v = VolumetricMoments::normal([0.003, -0.004, 0.0], [[0.0; 3]; 3]);
        assert!(close(v.mean, 0.005) && v.std < 1e-9, "{v:?}");
        assert_eq!(
            VolumetricMoments::normal([0.0; 3], [[0.0; 3]; 3]),
            VolumetricMoments {
                mean: 0.0,
                std: 0.0
            }
        );
    }

    #[test]
    fn volumetric_moments_are_rotation_invariant() {
        // Σ = R·diag·Rᵀ and μ = R·m give the same |p| law as (diag, m).
        let d = [4e-4, 1e-4, 2.5e-5];
        let m = [0.01, -0.002, 0.005];
        let (a, b) = (0.7f64, -1.1f64);
        let rz = [
            [a.cos(), -a.sin(), 0.0],
            [a.sin(), a.cos(), 0.0],
            [0.0, 0.0, 1.0],
        ];
        let rx = [
            [1.0, 0.0, 0.0],
            [0.0, b.cos(), -b.sin()],
            [0.0, b.sin(), b.cos()],
        ];
        let r: [[f64; 3]; 3] = std::array::from_fn(|i| {
            std::array::from_fn(|j| (0..3).map(|k| rz[i][k] * rx[k][j]).sum())
        });
        let cov: [[f64; 3]; 3] = std::array::from_fn(|i| {
            std::array::from_fn(|j| (0..3).map(|k| r[i][k] * d[k] * r[j][k]).sum())
        });
        let mr: [f64; 3] = std::array::from_fn(|i| (0..3).map(|k| r[i][k] * m[k]).sum());
        let diag = [[d[0], 0.0, 0.0], [0.0, d[1], 0.0], [0.0, 0.0, d[2]]];
        let (v1, v2) = (
            VolumetricMoments::normal(m, diag),
            VolumetricMoments::normal(mr, cov),
        );
        assert!((v1.mean - v2.mean).abs() < 1e-14 * v1.mean, "{v1:?} {v2:?}");
        assert!((v1.std - v2.std).abs() < 1e-12 * v1.std, "{v1:?} {v2:?}");
        // And it is neither |μ| nor √(E|p|²): the spread matters.
        let rms = (m.iter().map(|x| x * x).sum::<f64>() + d.iter().sum::<f64>()).sqrt();
        assert!(v1.mean < rms && v1.mean > 0.0);
    }
}
