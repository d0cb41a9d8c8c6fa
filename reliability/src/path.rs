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
    Algorithm, CaseResult, CaseTally, Method, SharedModel, Study, StudyResult, StudySpec, System,
    Target, VolumetricMoments,
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
    /// That instant's input row.
    pub row: usize,
    /// That instant's `t`.
    pub t: f64,
}

impl Extreme {
    /// `value` at `record` if it beats `best` (larger; the first on ties).
    fn larger(
        best: Option<Extreme>,
        value: f64,
        record: usize,
        i: &PathInstant,
    ) -> Option<Extreme> {
        match best {
            Some(b) if b.value >= value => best,
            _ => Some(Extreme {
                value,
                record,
                row: i.row,
                t: i.t,
            }),
        }
    }
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

    /// Every case of every evaluated instant (instant by instant).
    pub fn cases(&self) -> impl Iterator<Item = &CaseResult> + Clone {
        self.records
            .iter()
            .filter_map(|r| r.result.as_ref())
            .flat_map(|e| self.cases_of(e))
    }
}

/// The summary of a path, added up record by record as the records come
/// (a path run a block of instants at a time keeps this, not its records):
/// the instants by status, each target's smallest and mean
/// reliability, the largest mean and standard deviation of every error
/// quantity, and the [`CaseTally`] of the cases (instant by instant, each
/// instant's targets in order).
#[derive(Debug, Clone, PartialEq)]
pub struct PathSummary {
    /// The instants added.
    pub instants: usize,
    /// Those with results.
    pub evaluated: usize,
    /// Those the inverse kinematics could not reach.
    pub unreachable: usize,
    /// Those at a singular pose.
    pub singular: usize,
    /// The cases' account.
    pub tally: CaseTally,
    requirement: Option<Requirement>,
    /// Per target: the smallest reliability (as the largest `−R`) and the
    /// running sum of `R`.
    worst: Vec<(Option<Extreme>, f64)>,
    /// Per [`Quantity::ALL`]: the largest `|mean|` (mean of `|p|`) and std.
    max_mean: [Option<Extreme>; 7],
    max_std: [Option<Extreme>; 7],
}

impl PathSummary {
    /// An empty summary of `targets` targets under `requirement`.
    pub fn new(targets: usize, requirement: Option<Requirement>) -> PathSummary {
        PathSummary {
            instants: 0,
            evaluated: 0,
            unreachable: 0,
            singular: 0,
            tally: CaseTally::default(),
            requirement,
            worst: vec![(None, 0.0); targets],
            max_mean: [None; 7],
            max_std: [None; 7],
        }
    }

    /// The summary of a whole result.
    pub fn of(r: &PathResult) -> PathSummary {
        let requirement = r.study.as_ref().and_then(|s| s.requirement);
        let mut out = PathSummary::new(r.targets.len(), requirement);
        out.add(r);
        out
    }

    /// Adds the records of `block`, the path's next records (a block's
    /// [`PathResult`] from [`PathStudy::blocks`], or a whole result).
    pub fn add(&mut self, block: &PathResult) {
        for rec in &block.records {
            let k = self.instants;
            let i = &rec.instant;
            self.instants += 1;
            match i.status {
                Status::Unreachable => self.unreachable += 1,
                Status::Singular => self.singular += 1,
                _ => {}
            }
            let Some(e) = &rec.result else { continue };
            self.evaluated += 1;
            for (t, c) in block.cases_of(e).enumerate() {
                let (worst, sum) = &mut self.worst[t];
                *worst = Extreme::larger(*worst, -c.reliability, k, i);
                *sum += c.reliability;
                self.tally.add(c);
            }
            for (n, &q) in Quantity::ALL.iter().enumerate() {
                let mean = match q {
                    Quantity::Volumetric => e.mean(q),
                    Quantity::Component(_) => e.mean(q).abs(),
                };
                self.max_mean[n] = Extreme::larger(self.max_mean[n], mean, k, i);
                self.max_std[n] = Extreme::larger(self.max_std[n], e.std(q), k, i);
            }
        }
    }

    /// The reliability of target `t` (its index in [`PathResult::targets`])
    /// over the evaluated instants; `None` when none is evaluated.
    pub fn target(&self, t: usize) -> Option<TargetSummary> {
        let (worst, sum) = self.worst.get(t)?;
        let worst = (*worst)?;
        let min = Extreme {
            value: -worst.value,
            ..worst
        };
        let mean = sum / self.evaluated as f64;
        Some(TargetSummary {
            min,
            mean,
            met: self
                .requirement
                .map(|r| min.value >= r.min && mean >= r.mean),
        })
    }

    /// The largest `|mean|` of a component (the largest mean of `|p|`).
    pub fn max_mean(&self, q: Quantity) -> Option<Extreme> {
        self.max_mean[Quantity::ALL.iter().position(|x| *x == q)?]
    }

    /// The largest standard deviation of a quantity.
    pub fn max_std(&self, q: Quantity) -> Option<Extreme> {
        self.max_std[Quantity::ALL.iter().position(|x| *x == q)?]
    }

    /// The requirement, if the study has one.
    pub fn requirement(&self) -> Option<Requirement> {
        self.requirement
    }

    /// Whether every target meets the requirement (`None` without one, or
    /// when no instant is evaluated).
    pub fn requirement_met(&self) -> Option<bool> {
        self.requirement?;
        let met: Option<Vec<bool>> = (0..self.worst.len())
            .map(|t| self.target(t).and_then(|s| s.met))
            .collect();
        met.map(|m| m.iter().all(|&x| x))
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
                let at = model.nominal(&q, parameters).position.map(|x| x + 0.0);
                match at.iter().all(|x| x.is_finite()) {
                    true => Ok(at),
                    false => Err(ReliabilityError::Overflow {
                        at: crate::study::point_text(study.variables(), &q),
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

    /// Runs `algorithm` at every evaluated instant and assembles the records:
    /// [`PathStudy::blocks`] gathered into one result (the cases, target-major
    /// over the whole path, and the study's summaries as [`Study::run`]
    /// gives them).
    pub fn run(
        &self,
        algorithm: &Algorithm,
        progress: &dyn Progress,
    ) -> Result<PathResult, ReliabilityError> {
        let nt = self.targets.len();
        let mut records = Vec::with_capacity(self.instants.len());
        let mut per_target: Vec<Vec<CaseResult>> = vec![Vec::new(); nt];
        let mut evaluated = 0;
        for block in self.blocks(algorithm, progress) {
            let block = block?;
            let here = block.evaluated();
            if let Some(r) = block.study {
                let n = r.cases.len() / nt.max(1);
                let mut cases = r.cases.into_iter();
                for target in per_target.iter_mut() {
                    target.extend(cases.by_ref().take(n));
                }
            }
            records.extend(block.records.into_iter().map(|mut rec| {
                if let Some(e) = &mut rec.result {
                    e.evaluated += evaluated;
                }
                rec
            }));
            evaluated += here;
        }
        let study = self
            .study
            .as_ref()
            .map(|s| s.finish(algorithm.method(), per_target.concat()));
        Ok(PathResult {
            method: algorithm.method(),
            sided: self.sided,
            targets: self.targets.clone(),
            records,
            study,
        })
    }

    /// The path's records a block of instants at a time, each block run as
    /// its instants' part of [`PathStudy::run`] (the same cases bit for bit:
    /// a sampler's case draws the streams of its index in the whole study),
    /// computed when the iterator is advanced: what `chain path` writes as
    /// the blocks come, keeping a [`PathSummary`] instead of the records.
    ///
    /// A block is a [`PathResult`] of its records: its `study` holds the
    /// block's cases, target-major within the block, and no summaries;
    /// [`InstantResult::evaluated`] counts within the block.
    pub fn blocks<'a>(
        &'a self,
        algorithm: &'a Algorithm,
        progress: &'a dyn Progress,
    ) -> PathBlocks<'a> {
        PathBlocks {
            path: self,
            algorithm,
            progress,
            next: 0,
            evaluated: 0,
        }
    }
}

/// The iterator of [`PathStudy::blocks`].
pub struct PathBlocks<'a> {
    path: &'a PathStudy,
    algorithm: &'a Algorithm,
    progress: &'a dyn Progress,
    /// The first instant of the next block.
    next: usize,
    /// The evaluated instants before it.
    evaluated: usize,
}

impl PathBlocks<'_> {
    /// The block of instants `from..to`, whose evaluated instants start at
    /// `first` among the study's points.
    fn block(&self, from: usize, to: usize, first: usize) -> Result<PathResult, ReliabilityError> {
        let path = self.path;
        let block = &path.instants[from..to];
        let n = block.iter().filter(|i| i.axes.is_some()).count();
        let study = match &path.study {
            Some(study) if n > 0 => {
                let np = study.points().len();
                let ids: Vec<usize> = (0..path.targets.len())
                    .flat_map(|t| t * np + first..t * np + first + n)
                    .collect();
                let cases = study.run_cases(self.algorithm, &ids, self.progress)?;
                Some((study, cases))
            }
            _ => None,
        };
        // The moments of the evaluated instants, in parallel (in instant
        // order whatever the threads).
        let mut results = match &study {
            Some((study, _)) => (0..n)
                .into_par_iter()
                .map(|k| {
                    let moments = study.moments(first + k)?;
                    Ok(InstantResult {
                        nominal: path.nominal[first + k],
                        component_mean: moments.mean,
                        component_std: Component::ALL.map(|c| moments.std(c)),
                        volumetric: moments.volumetric(),
                        evaluated: k,
                    })
                })
                .collect::<Result<_, ReliabilityError>>()?,
            None => Vec::new(),
        }
        .into_iter();
        let records = block
            .iter()
            .map(|instant| PathRecord {
                instant: instant.clone(),
                result: instant.axes.as_ref().and_then(|_| results.next()),
            })
            .collect();
        Ok(PathResult {
            method: self.algorithm.method(),
            sided: path.sided,
            targets: path.targets.clone(),
            records,
            study: study.map(|(study, cases)| StudyResult {
                method: self.algorithm.method(),
                variables: study.variables().to_vec(),
                cases,
                summaries: Vec::new(),
                requirement: study.spec().requirement,
            }),
        })
    }
}

impl Iterator for PathBlocks<'_> {
    type Item = Result<PathResult, ReliabilityError>;

    fn next(&mut self) -> Option<Self::Item> {
        let total = self.path.instants.len();
        if self.next >= total {
            return None;
        }
        let (from, to) = (self.next, (self.next + PATH_BLOCK).min(total));
        let first = self.evaluated;
        self.next = to;
        self.evaluated += (self.path.instants[from..to].iter())
            .filter(|i| i.axes.is_some())
            .count();
        Some(self.block(from, to, first))
    }
}

/// The instants of a block of [`PathStudy::blocks`].
const PATH_BLOCK: usize = 4096;

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
        let direct = at.run(&Algorithm::Form(Form::default()), &()).unwrap();
        let n = model.errors().len();
        let (means, stds) = (inputs.means().to_vec(), inputs.stds().to_vec());
        for (k, rec) in [&r.records[0], &r.records[2]].into_iter().enumerate() {
            let e = rec.result.as_ref().unwrap();
            let moments = path.study().unwrap().moments(k).unwrap();
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
        let summary = PathSummary::of(&r);
        let worst = summary.target(0).unwrap();
        let rel = |k: usize| r.case(r.records[k].result.as_ref().unwrap(), 0).reliability;
        assert_eq!(worst.min.value, rel(0).min(rel(2)));
        assert!(worst.min.record == 0 || worst.min.record == 2);
        let at = &r.records[worst.min.record].instant;
        assert_eq!((worst.min.row, worst.min.t), (at.row, at.t));
        assert!((worst.mean - 0.5 * (rel(0) + rel(2))).abs() < 1e-15);
        let big = summary.max_std(Quantity::Volumetric).unwrap();
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
        let summary = PathSummary::of(&r);
        assert!(summary.target(0).is_none() && summary.max_std(Quantity::Volumetric).is_none());
        assert_eq!(summary.requirement_met(), None);
        assert_eq!(r.targets.last().unwrap().target, Target::Series);
        assert_eq!(r.targets.last().unwrap().tolerance, None);
        assert!(r.study.is_none());
    }
}
