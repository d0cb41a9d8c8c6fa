//! Error and reliability along a tool path: the bridge from kinematics to
//! accuracy.
//!
//! A [`PathStudy`] takes the instants of a path (axis values, or the
//! unreachable and singular poses an inverse kinematics reported) and, at
//! every instant with axis values,
//!
//! - the nominal tool point `T_wt(q, 0)·tool_point`;
//! - the mean and covariance of the six error components, propagated exactly
//!   through the linear model `E = S(q)·e` ([`ErrorMoments`](crate::ErrorMoments)), and the mean
//!   and standard deviation of the volumetric position error `|p|`
//!   ([`VolumetricMoments`]);
//! - the reliability of every target, through [`Study::at_points`] (the same
//!   cases, in the same order, as a grid study at those points).
//!
//! [`PathResult`] is the typed, serialisable outcome: one [`PathRecord`] per
//! instant and the extremes over the path ([`PathResult::summary`],
//! [`PathResult::max_mean`], [`PathResult::max_std`]).

use chain_core::inverse::Status;
use chain_core::model::{Component, Requirement, Sided};
use chain_core::ErrorModel;
use serde::Serialize;

use crate::error::ReliabilityError;
use crate::inputs::Inputs;
use crate::par::prelude::*;
use crate::simulation::Progress;
use crate::study::{
    Algorithm, CaseResult, Method, SharedModel, Study, StudyResult, StudySpec, System, Target,
    VolumetricMoments,
};

/// One instant of a path, as given.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PathInstant {
    /// 1-based data row of the input.
    pub row: usize,
    /// The instant (the input's `t`, or the row number).
    pub t: f64,
    /// `ok` for axis values; the inverse-kinematics status for a pose.
    pub status: Status,
    /// The axis values (the model's variable order), when the instant has them.
    pub axes: Option<Vec<f64>>,
}

/// A reported error quantity: one of the six components or `|p|`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Quantity {
    /// An error component.
    Component(Component),
    /// The volumetric position error `|p| = √(px² + py² + pz²)`.
    Volumetric,
}

impl Quantity {
    /// `px, py, pz, ox, oy, oz, volumetric`, in that order.
    pub const ALL: [Quantity; 7] = [
        Quantity::Component(Component::Px),
        Quantity::Component(Component::Py),
        Quantity::Component(Component::Pz),
        Quantity::Component(Component::Ox),
        Quantity::Component(Component::Oy),
        Quantity::Component(Component::Oz),
        Quantity::Volumetric,
    ];

    /// `px`, …, `oz`, `volumetric`.
    pub fn name(self) -> &'static str {
        match self {
            Quantity::Component(c) => c.name(),
            Quantity::Volumetric => "volumetric",
        }
    }
}

impl std::fmt::Display for Quantity {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl Serialize for Quantity {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(self.name())
    }
}

/// What is computed at an instant with axis values.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct InstantResult {
    /// `T_wt(q, 0)·tool_point` (a negative zero is written as 0).
    pub nominal: [f64; 3],
    /// The means of the six components (`px, py, pz, ox, oy, oz`), from
    /// their exact moments ([`Study::moments`], which also has the
    /// covariance this record does not keep).
    pub component_mean: [f64; 6],
    /// Their standard deviations.
    pub component_std: [f64; 6],
    /// Mean and standard deviation of `|p|`.
    pub volumetric: VolumetricMoments,
    /// The instant's place among the evaluated ones: its cases (one per
    /// target) are [`PathResult::cases_of`], kept once in
    /// [`PathResult::study`] rather than copied here.
    pub evaluated: usize,
}

impl InstantResult {
    /// The mean of a quantity (`E[E_c]`, or `E|p|`).
    pub fn mean(&self, q: Quantity) -> f64 {
        match q {
            Quantity::Component(c) => self.component_mean[c.index()],
            Quantity::Volumetric => self.volumetric.mean,
        }
    }

    /// The standard deviation of a quantity.
    pub fn std(&self, q: Quantity) -> f64 {
        match q {
            Quantity::Component(c) => self.component_std[c.index()],
            Quantity::Volumetric => self.volumetric.std,
        }
    }
}

/// One instant and, when it has axis values, what was computed there.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PathRecord {
    /// The instant.
    pub instant: PathInstant,
    /// The results (`None` for an instant without axis values).
    pub result: Option<InstantResult>,
}

/// A target of a path study and its allowable value (`None` for the series
/// system, whose tolerances are its components').
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PathTarget {
    /// The target.
    pub target: Target,
    /// Its tolerance.
    pub tolerance: Option<f64>,
}

/// The extreme of a value over the evaluated instants.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Extreme {
    /// The extreme value.
    pub value: f64,
    /// The index of its record (the first on ties).
    pub record: usize,
}

/// One target's reliability over the path.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TargetSummary {
    /// The smallest reliability, and where.
    pub min: Extreme,
    /// The mean over the evaluated instants.
    pub mean: f64,
    /// Whether the requirement (min and mean) holds, if there is one.
    pub met: Option<bool>,
}

/// The outcome of a [`PathStudy`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PathResult {
    /// The algorithm.
    pub method: Method,
    /// One- or two-sided tolerances.
    pub sided: Sided,
    /// The targets, in case order.
    pub targets: Vec<PathTarget>,
    /// One record per instant, in input order.
    pub records: Vec<PathRecord>,
    /// The engine's result over the evaluated instants, every case
    /// target-major (`None` when no instant has axis values).
    pub study: Option<StudyResult>,
}

impl PathResult {
    /// The number of instants with results.
    pub fn evaluated(&self) -> usize {
        self.records.iter().filter(|r| r.result.is_some()).count()
    }

    /// The number of instants with this status.
    pub fn count(&self, status: Status) -> usize {
        self.records
            .iter()
            .filter(|r| r.instant.status == status)
            .count()
    }

    /// The requirement, if the study has one.
    pub fn requirement(&self) -> Option<Requirement> {
        self.study.as_ref().and_then(|s| s.requirement)
    }

    /// Where `value` is largest over the evaluated instants (the first on
    /// ties); `None` when no instant is evaluated.
    pub fn arg_max(&self, value: impl Fn(&InstantResult) -> f64) -> Option<Extreme> {
        self.records
            .iter()
            .enumerate()
            .filter_map(|(k, r)| r.result.as_ref().map(|e| (k, value(e))))
            .fold(None, |best, (k, v)| match best {
                Some(Extreme { value: b, .. }) if b >= v => best,
                _ => Some(Extreme {
                    value: v,
                    record: k,
                }),
            })
    }

    /// The largest `|mean|` of a component (the largest mean of `|p|`).
    pub fn max_mean(&self, q: Quantity) -> Option<Extreme> {
        match q {
            Quantity::Volumetric => self.arg_max(|e| e.mean(q)),
            Quantity::Component(_) => self.arg_max(|e| e.mean(q).abs()),
        }
    }

    /// The largest standard deviation of a quantity.
    pub fn max_std(&self, q: Quantity) -> Option<Extreme> {
        self.arg_max(|e| e.std(q))
    }

    /// The case of target `t` (its index in [`PathResult::targets`]) at an
    /// evaluated instant.
    pub fn case(&self, e: &InstantResult, t: usize) -> &CaseResult {
        let r = self
            .study
            .as_ref()
            .expect("an evaluated instant has a study result");
        let np = r.cases.len() / self.targets.len().max(1);
        &r.cases[t * np + e.evaluated]
    }

    /// The cases of an evaluated instant, one per target in
    /// [`PathResult::targets`] order.
    pub fn cases_of<'a>(
        &'a self,
        e: &'a InstantResult,
    ) -> impl ExactSizeIterator<Item = &'a CaseResult> + Clone + 'a {
        (0..self.targets.len()).map(move |t| self.case(e, t))
    }

    /// The reliability of target `t` (its index in [`PathResult::targets`])
    /// over the evaluated instants.
    pub fn summary(&self, t: usize) -> Option<TargetSummary> {
        let worst = self.arg_max(|e| -self.case(e, t).reliability)?;
        let values: Vec<f64> = self
            .records
            .iter()
            .filter_map(|r| r.result.as_ref().map(|e| self.case(e, t).reliability))
            .collect();
        Some(TargetSummary {
            min: Extreme {
                value: -worst.value,
                record: worst.record,
            },
            mean: values.iter().sum::<f64>() / values.len() as f64,
            met: self
                .study
                .as_ref()
                .and_then(|s| s.summaries.get(t))
                .and_then(|s| s.met),
        })
    }

    /// Every case of every evaluated instant (instant by instant).
    pub fn cases(&self) -> impl Iterator<Item = &CaseResult> + Clone {
        self.records
            .iter()
            .filter_map(|r| r.result.as_ref())
            .flat_map(|e| self.cases_of(e))
    }
}

/// The study of a path, ready to run.
#[derive(Debug, Clone)]
pub struct PathStudy {
    instants: Vec<PathInstant>,
    targets: Vec<PathTarget>,
    sided: Sided,
    /// Per evaluated instant, the nominal tool point.
    nominal: Vec<[f64; 3]>,
    /// `None` when no instant has axis values.
    study: Option<Study>,
}

impl PathStudy {
    /// Evaluates the model's sensitivities at every instant with axis values
    /// and keeps them.
    ///
    /// `parameters`, `inputs` and `spec` are as in [`Study::new`] (`spec.grid`
    /// is not used). An instant without axis values is kept and reported
    /// without results; when no instant has any, nothing is evaluated (and
    /// the targets are those the spec would give).
    pub fn new<M: ErrorModel + ?Sized>(
        model: &M,
        parameters: &[f64],
        inputs: Inputs,
        spec: StudySpec,
        instants: Vec<PathInstant>,
    ) -> Result<PathStudy, ReliabilityError> {
        PathStudy::build(
            model,
            instants,
            spec,
            |spec, points| Study::at_points(model, parameters, inputs, spec, points),
            parameters,
        )
    }

    /// [`PathStudy::new`] over a study that keeps the model instead of the
    /// sensitivities ([`Study::at_points_on_demand`]): what `chain path`
    /// builds, so that a path of a million instants holds no `6 × N` matrix
    /// per instant. The results are [`PathStudy::new`]'s.
    pub fn on_demand(
        model: SharedModel,
        parameters: &[f64],
        inputs: Inputs,
        spec: StudySpec,
        instants: Vec<PathInstant>,
    ) -> Result<PathStudy, ReliabilityError> {
        let shared = model.clone();
        PathStudy::build(
            &*model,
            instants,
            spec,
            |spec, points| Study::at_points_on_demand(shared, parameters, inputs, spec, points),
            parameters,
        )
    }

    /// The shared part of the constructors: the nominal points and the
    /// study `study(spec, points)` of the instants with axis values.
    fn build<M: ErrorModel + ?Sized>(
        model: &M,
        instants: Vec<PathInstant>,
        spec: StudySpec,
        study: impl FnOnce(StudySpec, Vec<Vec<f64>>) -> Result<Study, ReliabilityError>,
        parameters: &[f64],
    ) -> Result<PathStudy, ReliabilityError> {
        let points: Vec<Vec<f64>> = instants.iter().filter_map(|i| i.axes.clone()).collect();
        let sided = spec.sided;
        if points.is_empty() {
            return Ok(PathStudy {
                instants,
                targets: spec_targets(&spec),
                sided,
                nominal: Vec::new(),
                study: None,
            });
        }
        let study = study(spec, points)?;
        let nominal = (study.points().iter())
            .map(|q| {
                let at = model.nominal(q, parameters).position.map(|x| x + 0.0);
                match at.iter().all(|x| x.is_finite()) {
                    true => Ok(at),
                    false => Err(ReliabilityError::Overflow {
                        at: crate::study::point_text(study.variables(), q),
                        what: "nominal tool point".into(),
                    }),
                }
            })
            .collect::<Result<_, _>>()?;
        let targets = study
            .targets()
            .iter()
            .map(|&target| PathTarget {
                target,
                tolerance: study.tolerance(target),
            })
            .collect();
        Ok(PathStudy {
            instants,
            targets,
            sided,
            nominal,
            study: Some(study),
        })
    }

    /// The study over the evaluated instants (`None` when there is none).
    pub fn study(&self) -> Option<&Study> {
        self.study.as_ref()
    }

    /// The instants, in input order.
    pub fn instants(&self) -> &[PathInstant] {
        &self.instants
    }

    /// The targets, in case order.
    pub fn targets(&self) -> &[PathTarget] {
        &self.targets
    }

    /// Runs `algorithm` at every evaluated instant and assembles the records.
    pub fn run(
        &self,
        algorithm: &Algorithm,
        progress: &dyn Progress,
    ) -> Result<PathResult, ReliabilityError> {
        let study_result = match &self.study {
            Some(study) => Some(study.run(algorithm, progress)?),
            None => None,
        };
        // The moments of the evaluated instants, a block at a time in
        // parallel (in instant order whatever the threads).
        let mut records = Vec::with_capacity(self.instants.len());
        let mut k = 0;
        for block in self.instants.chunks(MOMENT_BLOCK) {
            let from = k;
            let to = from + block.iter().filter(|i| i.axes.is_some()).count();
            k = to;
            let mut results = match (&self.study, &study_result) {
                (Some(study), Some(_)) => (from..to)
                    .into_par_iter()
                    .map(|k| {
                        let moments = study.moments(k);
                        InstantResult {
                            nominal: self.nominal[k],
                            component_mean: moments.mean,
                            component_std: Component::ALL.map(|c| moments.std(c)),
                            volumetric: moments.volumetric(),
                            evaluated: k,
                        }
                    })
                    .collect(),
                _ => Vec::new(),
            }
            .into_iter();
            for instant in block {
                let result = match instant.axes {
                    Some(_) => results.next(),
                    None => None,
                };
                records.push(PathRecord {
                    instant: instant.clone(),
                    result,
                });
            }
        }
        Ok(PathResult {
            method: algorithm.method(),
            sided: self.sided,
            targets: self.targets.clone(),
            records,
            study: study_result,
        })
    }
}

/// The instants whose moments are computed at a time ([`PathStudy::run`]).
const MOMENT_BLOCK: usize = 4096;

/// The targets a study of this spec would have, with their tolerances.
fn spec_targets(spec: &StudySpec) -> Vec<PathTarget> {
    let mut out: Vec<PathTarget> = spec
        .tolerances
        .iter()
        .map(|(c, t)| PathTarget {
            target: Target::Component(*c),
            tolerance: Some(*t),
        })
        .collect();
    match spec.system {
        Some(System::Series) => out.push(PathTarget {
            target: Target::Series,
            tolerance: None,
        }),
        Some(System::Volumetric { tolerance }) => out.push(PathTarget {
            target: Target::Volumetric,
            tolerance: Some(tolerance),
        }),
        None => {}
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::form::Form;
    use crate::machine;
    use crate::util::fixtures::gantry;

    fn instant(row: usize, axes: Option<Vec<f64>>) -> PathInstant {
        PathInstant {
            row,
            t: 0.5 * row as f64,
            status: if axes.is_some() {
                Status::Ok
            } else {
                Status::Unreachable
            },
            axes,
        }
    }

    #[test]
    fn records_match_a_direct_propagation_and_the_point_study() {
        let (m, model) = gantry();
        let system = Some(System::Volumetric { tolerance: 0.04 });
        let spec = machine::spec(&m, system).unwrap();
        let mut inputs = machine::inputs(&m).unwrap();
        let j = inputs.index("dxz").unwrap();
        let std = inputs.stds()[j];
        inputs = inputs.with_moments(j, 0.003, std).unwrap();
        // (x, z, y): the model's variable order.
        let points = [vec![250.0, 1200.0, -750.0], vec![1000.0, 700.0, 600.0]];
        let instants = vec![
            instant(1, Some(points[0].clone())),
            instant(2, None),
            instant(3, Some(points[1].clone())),
        ];
        let path =
            PathStudy::new(&model, &[], inputs.clone(), spec.clone(), instants.clone()).unwrap();
        let form = Algorithm::Form(Form::default());
        let r = path.run(&form, &()).unwrap();
        assert_eq!(r.records.len(), 3);
        assert_eq!(r.evaluated(), 2);
        assert_eq!(r.count(Status::Unreachable), 1);
        assert!(r.records[1].result.is_none());
        let names: Vec<&str> = r.targets.iter().map(|t| t.target.name()).collect();
        assert_eq!(names, ["px", "py", "pz", "volumetric"]);
        assert_eq!(r.targets[3].tolerance, Some(0.04));

        // The same points as a plain point study: identical cases.
        let at = Study::at_points(&model, &[], inputs.clone(), spec, points.to_vec()).unwrap();
        let direct = at.form(&Form::default()).unwrap();
        let n = model.errors().len();
        let (means, stds) = (inputs.means().to_vec(), inputs.stds().to_vec());
        for (k, rec) in [&r.records[0], &r.records[2]].into_iter().enumerate() {
            let e = rec.result.as_ref().unwrap();
            let moments = path.study().unwrap().moments(k);
            assert_eq!(r.cases_of(e).len(), 4);
            for (t, c) in r.cases_of(e).enumerate() {
                assert_eq!(c, &direct.cases[t * 2 + k]);
            }
            // Independent propagation: S from the model, then S·μ and S·Σ·Sᵀ.
            let mut s = vec![0.0; 6 * n];
            model.sensitivity(&points[k], &[], &mut s);
            let names = model.errors();
            for a in 0..6 {
                let ra = &s[a * n..(a + 1) * n];
                let mean: f64 = (0..n)
                    .map(|i| ra[i] * means[inputs.index(names[i]).unwrap()])
                    .sum();
                assert!((e.component_mean[a] - mean).abs() <= 1e-15 + 1e-12 * mean.abs());
                for b in 0..6 {
                    let rb = &s[b * n..(b + 1) * n];
                    let cov: f64 = (0..n)
                        .map(|i| {
                            let sd = stds[inputs.index(names[i]).unwrap()];
                            ra[i] * rb[i] * sd * sd
                        })
                        .sum();
                    let got = moments.covariance[a][b];
                    assert!(
                        (got - cov).abs() <= 1e-12 * cov.abs().max(1e-20),
                        "{got} {cov}"
                    );
                }
            }
            for c in Component::ALL {
                assert_eq!(e.component_std[c.index()], moments.std(c));
                assert!(e.component_std[c.index()] > 0.0 || c.index() >= 3);
            }
            assert!(e.mean(Quantity::Component(Component::Px)).abs() > 1e-3);
            assert_eq!(
                e.std(Quantity::Volumetric),
                moments.volumetric().std,
                "|p| moments"
            );
            let pose = model.nominal(&points[k], &[]);
            assert_eq!(e.nominal, pose.position.map(|x| x + 0.0));
        }
        // Extremes point at records, not at evaluated indices.
        let worst = r.summary(0).unwrap();
        let rel = |k: usize| r.case(r.records[k].result.as_ref().unwrap(), 0).reliability;
        assert_eq!(worst.min.value, rel(0).min(rel(2)));
        assert!(worst.min.record == 0 || worst.min.record == 2);
        assert!((worst.mean - 0.5 * (rel(0) + rel(2))).abs() < 1e-15);
        let big = r.max_std(Quantity::Volumetric).unwrap();
        assert_ne!(big.record, 1);
    }

    #[test]
    fn a_path_without_axis_values_has_records_and_no_results() {
        let (m, model) = gantry();
        let spec = machine::spec(&m, Some(System::Series)).unwrap();
        let inputs = machine::inputs(&m).unwrap();
        let path = PathStudy::new(&model, &[], inputs, spec, vec![instant(1, None)]).unwrap();
        assert!(path.study().is_none());
        let r = path.run(&Algorithm::Form(Form::default()), &()).unwrap();
        assert_eq!(r.evaluated(), 0);
        assert!(r.summary(0).is_none() && r.max_std(Quantity::Volumetric).is_none());
        assert_eq!(r.targets.last().unwrap().target, Target::Series);
        assert_eq!(r.targets.last().unwrap().tolerance, None);
        assert!(r.study.is_none());
    }
}
