//! Reliability over a workspace grid: the paper's Section 3.3 procedure
//! (Tables 2-4 and Figures 6-8) for any [`ErrorModel`].
//!
//! A [`Study`] evaluates the model's sensitivity matrix once per grid point
//! (the model is linear in the errors, so that is all it needs), builds one
//! [`Event`] per target and point (a case), and runs FORM, the importance
//! sampling or Monte Carlo over all cases, in parallel. Cases are ordered
//! target-major (every point of the first target, then the next), and case
//! `i` always samples random stream `i`.

use chain_core::model::{Component, Requirement, Sided};
use chain_core::ErrorModel;
use serde::Serialize;

use crate::error::ReliabilityError;
use crate::form::{Form, FormResult};
use crate::inputs::Inputs;
use crate::limit_state::{Criterion, Event, ToleranceLimitState};
use crate::normal;
use crate::sensitivity::{sensitivity, SensitivityMethod, SensitivityResult};
use crate::simulation::{ImportanceSampling, MonteCarlo, Progress, SimulationResult};
use rayon::prelude::*;

/// The axis values to evaluate: the cartesian product of the axes, first axis
/// slowest.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Grid {
    /// `(variable name, values)`, in order.
    pub axes: Vec<(String, Vec<f64>)>,
}

impl Grid {
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

/// One target of a study.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
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

/// A study ready to run: inputs, grid points and the sensitivities there.
#[derive(Debug, Clone)]
pub struct Study {
    inputs: Inputs,
    variables: Vec<String>,
    spec: StudySpec,
    points: Vec<Vec<f64>>,
    /// Per point, the `6 × N` sensitivity matrix.
    sensitivities: Vec<Vec<f64>>,
    targets: Vec<Target>,
}

/// The outcome of one case.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CaseResult {
    /// The target's name.
    pub target: &'static str,
    /// The axis values, in the model's variable order.
    pub point: Vec<f64>,
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
}

/// The summary of a target over the grid (the paper's "minimum and average
/// reliability").
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Summary {
    /// The target's name.
    pub target: &'static str,
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
    /// `form`, `is` or `mc`.
    pub method: &'static str,
    /// The model's axis variables.
    pub variables: Vec<String>,
    /// Every case, target-major.
    pub cases: Vec<CaseResult>,
    /// One summary per target.
    pub summaries: Vec<Summary>,
    /// The requirement.
    pub requirement: Option<Requirement>,
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
    /// The target's name.
    pub target: &'static str,
    /// Exact or FORM (the FORM route if any point needed it).
    pub method: SensitivityMethod,
    /// Per error, sorted.
    pub errors: Vec<ErrorSensitivity>,
}

impl Study {
    /// Evaluates the model's sensitivities over the grid.
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
        let errors = model.errors();
        let n = errors.len();
        if parameters.len() != model.parameters().len() {
            return Err(ReliabilityError::Dimension {
                what: "parameter values",
                expected: model.parameters().len(),
                found: parameters.len(),
            });
        }
        // Inputs in the model's error order.
        let mut names = Vec::with_capacity(n);
        let mut marginals = Vec::with_capacity(n);
        for e in errors {
            let j = inputs
                .index(e)
                .ok_or_else(|| ReliabilityError::MissingInput((*e).to_string()))?;
            names.push((*e).to_string());
            marginals.push(inputs.marginals()[j]);
        }
        let inputs = Inputs::new(names, marginals)?;
        let variables: Vec<String> = model.variables().iter().map(|v| v.to_string()).collect();
        // Resolve the grid axes.
        let mut axis_of = vec![None; variables.len()];
        for (a, (name, values)) in spec.grid.axes.iter().enumerate() {
            let v = variables.iter().position(|x| x == name).ok_or_else(|| {
                ReliabilityError::UnknownName {
                    kind: "variable",
                    name: name.clone(),
                    hint: variables.first().cloned(),
                }
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
        if spec.grid.is_empty() && !variables.is_empty() {
            return Err(ReliabilityError::EmptyGrid("no axis".into()));
        }
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
        let count = spec.grid.len().max(1);
        let mut points = Vec::with_capacity(count);
        let mut sensitivities = Vec::with_capacity(count);
        for p in 0..count {
            let idx = spec.grid.index(p);
            let q: Vec<f64> = axis_of
                .iter()
                .map(|a| a.map_or(0.0, |a| spec.grid.axes[a].1[idx[a]]))
                .collect();
            let mut s = vec![0.0; 6 * n];
            model.sensitivity(&q, parameters, &mut s);
            if s.iter().any(|v| !v.is_finite()) {
                return Err(ReliabilityError::NonFinite("the model's sensitivities"));
            }
            points.push(q);
            sensitivities.push(s);
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
        Ok(Study {
            inputs,
            variables,
            spec,
            points,
            sensitivities,
            targets,
        })
    }

    /// The inputs, in the model's error order.
    pub fn inputs(&self) -> &Inputs {
        &self.inputs
    }

    /// The model's axis variables.
    pub fn variables(&self) -> &[String] {
        &self.variables
    }

    /// The specification.
    pub fn spec(&self) -> &StudySpec {
        &self.spec
    }

    /// The grid points, in the model's variable order.
    pub fn points(&self) -> &[Vec<f64>] {
        &self.points
    }

    /// The targets, in case order.
    pub fn targets(&self) -> &[Target] {
        &self.targets
    }

    /// The sensitivity row `∂E_c/∂e` at point `p`.
    pub fn row(&self, p: usize, c: Component) -> &[f64] {
        let n = self.inputs.len();
        &self.sensitivities[p][c.index() * n..(c.index() + 1) * n]
    }

    /// The limit state of `target` at point `p`.
    pub fn limit_state(
        &self,
        target: Target,
        p: usize,
    ) -> Result<ToleranceLimitState, ReliabilityError> {
        let n = self.inputs.len();
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
                ToleranceLimitState::component(self.row(p, c).to_vec(), i, self.spec.sided)
            }
            Target::Series => {
                let rows = tol
                    .iter()
                    .flat_map(|(c, _)| self.row(p, *c).to_vec())
                    .collect();
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
                    .flat_map(|(c, _)| self.row(p, *c).to_vec())
                    .collect();
                ToleranceLimitState::new(n, rows, vec![tolerance], Criterion::Norm)
            }
        }
    }

    /// The event of `target` at point `p`.
    pub fn event(&self, target: Target, p: usize) -> Result<Event<'_>, ReliabilityError> {
        Event::new(&self.inputs, self.limit_state(target, p)?)
    }

    /// Every case's event, target-major.
    pub fn events(&self) -> Result<Vec<Event<'_>>, ReliabilityError> {
        let mut out = Vec::with_capacity(self.targets.len() * self.points.len());
        for &t in &self.targets {
            for p in 0..self.points.len() {
                out.push(self.event(t, p)?);
            }
        }
        Ok(out)
    }

    /// FORM on every case (exact for one-sided components in normal inputs).
    pub fn form(&self, form: &Form) -> Result<StudyResult, ReliabilityError> {
        let events = self.events()?;
        let results = self.run_form(&events, form)?;
        let cases = results
            .iter()
            .enumerate()
            .map(|(i, r)| self.case(i, r.reliability, r.pf, r.beta))
            .collect();
        Ok(self.finish("form", cases))
    }

    /// The importance sampling on every case.
    pub fn importance_sampling(
        &self,
        is: &ImportanceSampling,
        progress: &dyn Progress,
    ) -> Result<StudyResult, ReliabilityError> {
        let events = self.events()?;
        let forms = self.run_form(&events, &is.form)?;
        let results = is.run_cases_with(&events, forms, progress)?;
        Ok(self.finish("is", self.sampled(&results)))
    }

    /// Crude Monte Carlo on every case.
    pub fn monte_carlo(
        &self,
        mc: &MonteCarlo,
        progress: &dyn Progress,
    ) -> Result<StudyResult, ReliabilityError> {
        let events = self.events()?;
        let results = mc.run_cases(&events, progress)?;
        Ok(self.finish("mc", self.sampled(&results)))
    }

    fn run_form(
        &self,
        events: &[Event<'_>],
        form: &Form,
    ) -> Result<Vec<FormResult>, ReliabilityError> {
        if events.len() < 64 {
            events.iter().map(|e| form.run(e)).collect()
        } else {
            events.par_iter().map(|e| form.run(e)).collect()
        }
    }

    fn sampled(&self, results: &[SimulationResult]) -> Vec<CaseResult> {
        results
            .iter()
            .enumerate()
            .map(|(i, r)| {
                let mut c = self.case(i, r.reliability, r.pf, r.beta);
                c.std_error = Some(r.std_error);
                c.cov = Some(r.cov);
                c.samples = Some(r.samples);
                c
            })
            .collect()
    }

    fn case(&self, i: usize, reliability: f64, pf: f64, beta: f64) -> CaseResult {
        let np = self.points.len();
        CaseResult {
            target: self.targets[i / np].name(),
            point: self.points[i % np].clone(),
            reliability,
            pf,
            beta,
            std_error: None,
            cov: None,
            samples: None,
        }
    }

    fn finish(&self, method: &'static str, cases: Vec<CaseResult>) -> StudyResult {
        let np = self.points.len();
        let summaries = self
            .targets
            .iter()
            .enumerate()
            .map(|(t, target)| {
                let rs: Vec<f64> = cases[t * np..(t + 1) * np]
                    .iter()
                    .map(|c| c.reliability)
                    .collect();
                let mean = rs.iter().sum::<f64>() / rs.len().max(1) as f64;
                let min = rs.iter().copied().fold(f64::INFINITY, f64::min);
                let max = rs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                Summary {
                    target: target.name(),
                    mean,
                    min,
                    max,
                    met: self
                        .spec
                        .requirement
                        .map(|r| min >= r.min && mean >= r.mean),
                }
            })
            .collect();
        StudyResult {
            method,
            variables: self.variables.clone(),
            cases,
            summaries,
            requirement: self.spec.requirement,
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
        let per_point: Vec<Vec<(Target, SensitivityResult)>> = (0..self.points.len())
            .into_par_iter()
            .map(|p| self.sensitivity_at(p, form))
            .collect::<Result<_, _>>()?;
        Ok(self.average(&per_point))
    }

    /// The sensitivities of every target at an arbitrary point (axis values in
    /// the model's variable order), sorted like [`Study::sensitivity_mean`].
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
        let spec = StudySpec {
            grid: Grid {
                axes: self
                    .variables
                    .iter()
                    .zip(point)
                    .map(|(v, x)| (v.clone(), vec![*x]))
                    .collect(),
            },
            ..self.spec.clone()
        };
        let single = Study::new(model, parameters, self.inputs.clone(), spec)?;
        let at = single.sensitivity_at(0, form)?;
        Ok(single.average(&[at]))
    }

    fn average(&self, per_point: &[Vec<(Target, SensitivityResult)>]) -> Vec<TargetSensitivity> {
        let n = self.inputs.len();
        let np = per_point.len().max(1) as f64;
        self.targets
            .iter()
            .enumerate()
            .map(|(t, &target)| {
                let mut acc = vec![[0.0f64; 5]; n];
                let mut method = SensitivityMethod::Exact;
                for point in per_point {
                    let r = &point[t].1;
                    if r.method == SensitivityMethod::Form {
                        method = SensitivityMethod::Form;
                    }
                    for (a, s) in acc.iter_mut().zip(&r.inputs) {
                        a[0] += s.dr_dstd;
                        a[1] += s.dr_dmean;
                        a[2] += s.importance;
                        a[3] += s.dr_dstd.abs();
                        a[4] += s.dr_dmean.abs();
                    }
                }
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
                    target: target.name(),
                    method,
                    errors,
                }
            })
            .collect()
    }
}

/// `Φ(I/σ_E)`: the closed-form reliability of one upper tolerance on a
/// zero-mean normal component with standard deviation `σ_E` (Eq. 21, 31).
pub fn closed_form_reliability(tolerance: f64, sigma_e: f64) -> f64 {
    normal::cdf(tolerance / sigma_e)
}
