//! A built machine: an error model with the error values of one machine
//! (measured-machines spec, sections 2-3; `docs/map.md`).
//!
//! [`BuiltMachine`] holds an [`ErrorModel`] (a [`CompiledModel`] or a
//! `machine!`-generated type), the [`Values`] of one built machine and the
//! parameter values. It gives the error of the built machine at any axis
//! values,
//!
//! ```text
//! E(q) = Σ_j c_j(q) · v_j(q)            (spec section 3)
//! ```
//!
//! (`c_j` the derived coefficient of error parameter `j`, a coefficient's
//! already multiplied by its basis function; `v_j` from the values), its
//! parts per error motion ([`BuiltMachine::parts`]), and the volumetric error
//! map over a list of points ([`BuiltMachine::map`]): every point's `E` and
//! `|(px, py, pz)|`, and the ISO 230-1-style summary (per component minimum,
//! maximum and RMS; the largest volumetric error and where; its RMS).
//!
//! The map evaluates the values once per point into one scratch vector per
//! block of [`MAP_BLOCK`] points, so nothing is allocated per point, and the
//! model over runs of up to 256 points at a time through
//! [`ErrorModel::error_points`] (a [`CompiledModel`]'s batched tape, equal
//! bit for bit to [`ErrorModel::error`] point by point); it re-evaluates only the tables whose axis value changed from
//! the previous point ([`Values::update`]: along a grid, mostly one axis);
//! with the `parallel` feature the blocks run on rayon's threads.
//! Each block's summary is computed inside the block and the blocks' are
//! combined in block order, so the result is the same, bit for bit, with or
//! without threads and whatever their number.

use serde::ser::{SerializeMap, SerializeSeq, SerializeStruct};
use serde::{Serialize, Serializer};

use crate::eval::CompiledModel;
use crate::model::{BasisFn, Frame, Machine};
use crate::model_trait::{ErrorModel, OutOfRange};
use crate::named::NameMap;
use crate::values::{OrderError, Values};

/// Points per block of [`BuiltMachine::map`]: the unit of parallel work and
/// of progress reports.
pub const MAP_BLOCK: usize = 4096;

/// Points of a map block evaluated together by
/// [`ErrorModel::error_points`] (the batched tape of a [`CompiledModel`]).
const MAP_CHUNK: usize = 256;

/// The component names, in `E`'s order.
const COMPONENTS: [&str; 6] = crate::model::Component::NAMES;

/// Why a model, values and parameters do not make one built machine.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum BuiltError {
    /// The values are for another machine.
    #[error("the values are for machine `{values}`, not `{machine}`")]
    Machine {
        /// The values' machine.
        values: String,
        /// The model's machine.
        machine: String,
    },
    /// The model's names are not the machine's.
    #[error(transparent)]
    Order(#[from] OrderError),
    /// Not one value per parameter.
    #[error("{found} parameter values for the {expected} parameters of the machine")]
    Parameters {
        /// The number of parameters.
        expected: usize,
        /// The number of values given.
        found: usize,
    },
}

/// Why a map could not be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum MapError {
    /// No point was given.
    #[error("the map has no point")]
    NoPoints,
    /// Points of another dimension than the model's.
    #[error("points of {found} axis values for a model of {variables} axis variables")]
    Dimension {
        /// The points' dimension.
        found: usize,
        /// The number of axis variables.
        variables: usize,
    },
    /// The axis values do not divide into points.
    #[error("{len} axis values do not make whole points of {variables} variables")]
    Ragged {
        /// The number of values given.
        len: usize,
        /// The number of axis variables.
        variables: usize,
    },
    /// A point outside a table that does not hold its end values.
    #[error("at point {} ({at}): {source}", point + 1)]
    OutOfRange {
        /// The point's index (0-based).
        point: usize,
        /// The point, `x = 0, y = 500`.
        at: String,
        /// The table and the value.
        source: Box<OutOfRange>,
    },
}

/// What a part of the error is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum PartKind {
    /// One error parameter (a constant or a tabulated error motion).
    Error,
    /// A function slot, all its coefficients together.
    Function,
}

/// One error motion's share of `E(q)`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Part {
    /// The error parameter or function slot.
    pub name: String,
    /// Which of the two.
    pub kind: PartKind,
    /// Its value at `q`: `v_j(q)`, or `F(q) = Σ_k b_k(q) v_k` for a function.
    pub value: f64,
    /// Its contribution `c_j(q) · v_j(q)` (a function: summed over its
    /// coefficients), `[px, py, pz, ox, oy, oz]`.
    pub error: [f64; 6],
}

/// A motion of the model for [`BuiltMachine::parts`]: an error, or a
/// function's coefficients (model indices, basis functions).
#[derive(Debug, Clone)]
struct Motion {
    name: String,
    kind: PartKind,
    /// `(model error index, basis function, model variable index)`.
    errors: Vec<(usize, Option<(BasisFn, usize)>)>,
}

/// A machine as built: an error model, the error values of one machine and
/// the parameter values (see the [module documentation](self)).
///
/// # Example
///
/// ```
/// use chain_core::built::{BuiltMachine, Points};
/// use chain_core::values::Values;
/// let yaml = "machine: m\nbodies:\n  bed: {}\n  x_slide: {parent: bed, joint: {type: prismatic, axis: +x, variable: x}, errors: {dx: dxx, ey: eyx}}\n  spindle: {parent: x_slide, offset: [0, 0, -100]}\nworkpiece: bed\ntool: spindle\n";
/// let machine = chain_core::load_str(yaml, "m.yaml").unwrap();
/// let values_yaml = "machine: m\nunits: {linear: um, angular: urad}\nvalues:\n  dxx: {points: [[0, 0], [1000, 10]]}\n  eyx: 20\n";
/// let values = Values::parse(values_yaml, "v.yaml", ".".as_ref(), &machine).unwrap();
/// let built = BuiltMachine::compile(&machine, values, vec![]).unwrap();
/// // px = dxx − 100·eyx = 0.005 − 100 · 20e-6 at x = 500
/// let e = built.error(&[500.0]).unwrap();
/// assert!((e[0] - 0.003).abs() < 1e-15);
/// let map = built.map(Points::Grid(vec![vec![0.0, 500.0, 1000.0]])).unwrap();
/// assert!((map.summary.px.max - 0.008).abs() < 1e-15);
/// ```
#[derive(Debug, Clone)]
pub struct BuiltMachine<M = CompiledModel> {
    model: M,
    values: Values,
    parameters: Vec<f64>,
    machine: String,
    frame: Frame,
    variables: Vec<String>,
    motions: Vec<Motion>,
}

impl BuiltMachine<CompiledModel> {
    /// Derives and compiles `machine` and builds it with `values` and
    /// `parameters` (in the machine's parameter order).
    pub fn compile(
        machine: &Machine,
        values: Values,
        parameters: Vec<f64>,
    ) -> Result<BuiltMachine<CompiledModel>, BuiltError> {
        BuiltMachine::new(machine, crate::compile(machine), values, parameters)
    }
}

impl<M: ErrorModel> BuiltMachine<M> {
    /// `model` (of `machine`: a [`CompiledModel`] or a `machine!` type) with
    /// `values` read for `machine` and `parameters` in the machine's
    /// parameter order. The model's variables, parameters and errors may be
    /// in another order than the machine's; they must be the same names.
    pub fn new(
        machine: &Machine,
        model: M,
        values: Values,
        parameters: Vec<f64>,
    ) -> Result<BuiltMachine<M>, BuiltError> {
        if values.machine() != machine.name {
            return Err(BuiltError::Machine {
                values: values.machine().to_string(),
                machine: machine.name.clone(),
            });
        }
        if parameters.len() != machine.parameters.len() {
            return Err(BuiltError::Parameters {
                expected: machine.parameters.len(),
                found: parameters.len(),
            });
        }
        let values = values.reordered(model.variables(), model.errors())?;
        let model_params = model.parameters();
        let names: Vec<String> = machine.parameters.iter().map(|p| p.name.clone()).collect();
        let params = model_params
            .iter()
            .map(|n| {
                machine
                    .parameter_index(n)
                    .map(|i| parameters[i])
                    .ok_or_else(|| OrderError {
                        what: "parameters",
                        model: model_params.iter().map(|s| s.to_string()).collect(),
                        machine: names.clone(),
                    })
            })
            .collect::<Result<Vec<f64>, OrderError>>()?;
        if model_params.len() != names.len() {
            return Err(BuiltError::Order(OrderError {
                what: "parameters",
                model: model_params.iter().map(|s| s.to_string()).collect(),
                machine: names,
            }));
        }
        let model_error = |name: &str| model.errors().iter().position(|e| *e == name);
        let model_variable = |name: &str| model.variables().iter().position(|v| *v == name);
        let mut motions = Vec::new();
        for (j, e) in machine.errors.iter().enumerate() {
            if machine.coefficient_of(j).is_some() {
                continue;
            }
            if let Some(k) = model_error(&e.name) {
                motions.push(Motion {
                    name: e.name.clone(),
                    kind: PartKind::Error,
                    errors: vec![(k, None)],
                });
            }
        }
        for f in &machine.functions {
            let var = model_variable(&machine.variables[f.variable].name).unwrap_or(usize::MAX);
            let errors = (f.coefficients.iter())
                .filter_map(|(j, b)| {
                    model_error(&machine.errors[*j].name).map(|k| (k, Some((*b, var))))
                })
                .collect();
            motions.push(Motion {
                name: f.name.clone(),
                kind: PartKind::Function,
                errors,
            });
        }
        Ok(BuiltMachine {
            variables: model.variables().iter().map(|s| s.to_string()).collect(),
            model,
            values,
            parameters: params,
            machine: machine.name.clone(),
            frame: machine.frame,
            motions,
        })
    }

    /// The model.
    pub fn model(&self) -> &M {
        &self.model
    }

    /// The values, in the model's order.
    pub fn values(&self) -> &Values {
        &self.values
    }

    /// The parameter values, in the model's order.
    pub fn parameters(&self) -> &[f64] {
        &self.parameters
    }

    /// The machine's name.
    pub fn machine(&self) -> &str {
        &self.machine
    }

    /// The frame `E` is expressed in.
    pub fn frame(&self) -> Frame {
        self.frame
    }

    /// The axis variables, in the order a point lists them.
    pub fn variables(&self) -> &[String] {
        &self.variables
    }

    /// A scratch vector for [`BuiltMachine::error_into`] (one value per error).
    pub fn scratch(&self) -> Vec<f64> {
        vec![0.0; self.model.errors().len()]
    }

    /// `E(q) = Σ_j c_j(q) · v_j(q)`, `[px, py, pz, ox, oy, oz]`, with the
    /// caller's scratch (from [`BuiltMachine::scratch`]): no allocation.
    #[inline]
    pub fn error_into(
        &self,
        q: &[f64],
        scratch: &mut [f64],
        out: &mut [f64; 6],
    ) -> Result<(), OutOfRange> {
        self.model
            .error_with(q, &self.parameters, &self.values, scratch, out)
    }

    /// `E(q)` (allocates its scratch; [`BuiltMachine::error_into`] does not).
    pub fn error(&self, q: &[f64]) -> Result<[f64; 6], OutOfRange> {
        let mut e = self.scratch();
        let mut out = [0.0; 6];
        self.error_into(q, &mut e, &mut out)?;
        Ok(out)
    }

    /// `E(q)` error motion by error motion: one [`Part`] per plain error
    /// parameter and per function slot (its coefficients summed), in the
    /// machine's order (plain errors, then functions); their errors add up
    /// to [`BuiltMachine::error`].
    pub fn parts(&self, q: &[f64]) -> Result<Vec<Part>, OutOfRange> {
        self.parts_with(q, &self.values)
    }

    /// [`BuiltMachine::parts`] with other values for the same model: a
    /// clone of [`BuiltMachine::values`] read for another approach
    /// direction ([`Values::set_approach`]; the export of a controller's
    /// forward and reverse columns).
    pub fn parts_with(&self, q: &[f64], values: &Values) -> Result<Vec<Part>, OutOfRange> {
        let n = self.model.errors().len();
        let mut v = vec![0.0; n];
        crate::ErrorValues::values_at(values, q, &mut v)?;
        let mut s = vec![0.0; 6 * n];
        self.model.sensitivity(q, &self.parameters, &mut s);
        Ok(self
            .motions
            .iter()
            .map(|m| {
                let mut error = [0.0; 6];
                let mut value = 0.0;
                for &(k, basis) in &m.errors {
                    for (c, e) in error.iter_mut().enumerate() {
                        *e += s[c * n + k] * v[k];
                    }
                    value += match basis {
                        Some((b, var)) => b.value(q.get(var).copied().unwrap_or(f64::NAN)) * v[k],
                        None => v[k],
                    };
                }
                Part {
                    name: m.name.clone(),
                    kind: m.kind,
                    value,
                    error,
                }
            })
            .collect())
    }
}

impl<M: ErrorModel + Sync> BuiltMachine<M> {
    /// The error map over `points` (a grid or a list, in
    /// [`BuiltMachine::variables`] order): every point's error and the
    /// summary.
    pub fn map(&self, points: Points) -> Result<MapResult, MapError> {
        self.map_with_progress(points, &|_| {})
    }

    /// [`BuiltMachine::map`], telling `progress` how many points each block
    /// finished (from any thread).
    pub fn map_with_progress(
        &self,
        points: Points,
        progress: &(dyn Fn(usize) + Sync),
    ) -> Result<MapResult, MapError> {
        let count = self.check(&points)?;
        let mut errors = vec![[0.0; 6]; count];
        let block = |(b, e): (usize, &mut [[f64; 6]])| {
            let r = self.block(&points, b * MAP_BLOCK, e.len(), Some(e));
            progress(e.len());
            r
        };
        #[cfg(feature = "parallel")]
        let partials: Vec<Result<Partial, MapError>> = {
            use rayon::prelude::*;
            errors
                .par_chunks_mut(MAP_BLOCK)
                .enumerate()
                .map(block)
                .collect()
        };
        #[cfg(not(feature = "parallel"))]
        let partials: Vec<Result<Partial, MapError>> = errors
            .chunks_mut(MAP_BLOCK)
            .enumerate()
            .map(block)
            .collect();
        let summary = self.summary_of(&points, count, partials)?;
        Ok(MapResult {
            machine: self.machine.clone(),
            frame: self.frame,
            variables: self.variables.clone(),
            points,
            errors,
            summary,
            reversals: self.values.reversals(),
        })
    }

    /// The summary of the map over `points` alone, without keeping each
    /// point's error (the same numbers as [`BuiltMachine::map`]'s summary,
    /// bit for bit, in a fixed amount of memory).
    pub fn summary(
        &self,
        points: &Points,
        progress: &(dyn Fn(usize) + Sync),
    ) -> Result<MapSummary, MapError> {
        let count = self.check(points)?;
        let blocks = count.div_ceil(MAP_BLOCK);
        let block = |b: usize| {
            let len = MAP_BLOCK.min(count - b * MAP_BLOCK);
            let r = self.block(points, b * MAP_BLOCK, len, None);
            progress(len);
            r
        };
        #[cfg(feature = "parallel")]
        let partials: Vec<Result<Partial, MapError>> = {
            use rayon::prelude::*;
            (0..blocks).into_par_iter().map(block).collect()
        };
        #[cfg(not(feature = "parallel"))]
        let partials: Vec<Result<Partial, MapError>> = (0..blocks).map(block).collect();
        self.summary_of(points, count, partials)
    }

    /// The number of points, if they fit the model.
    fn check(&self, points: &Points) -> Result<usize, MapError> {
        let nv = self.variables.len();
        if points.dimension() != nv {
            return Err(MapError::Dimension {
                found: points.dimension(),
                variables: nv,
            });
        }
        match points.len() {
            0 => Err(MapError::NoPoints),
            n => Ok(n),
        }
    }

    /// The blocks' summaries combined in block order.
    fn summary_of(
        &self,
        points: &Points,
        count: usize,
        partials: Vec<Result<Partial, MapError>>,
    ) -> Result<MapSummary, MapError> {
        let mut total = Partial::new();
        for p in partials {
            total.merge(&p?);
        }
        let at = total.volumetric_at;
        let mut q = vec![0.0; self.variables.len()];
        points.point_into(at, &mut q);
        let at_point = NameMap::zip(self.variables.iter().cloned(), q);
        Ok(MapSummary::new(&total, count, at_point, at))
    }

    /// Evaluates the points `start..start + len` (into `errors`, if given).
    fn block(
        &self,
        points: &Points,
        start: usize,
        len: usize,
        mut errors: Option<&mut [[f64; 6]]>,
    ) -> Result<Partial, MapError> {
        let nv = self.variables.len();
        let n = self.model.errors().len();
        let mut scratch = self.scratch();
        let mut cursor = points.cursor(start);
        // The previous point: the values of its tables are in `scratch`.
        let mut previous = vec![f64::NAN; nv];
        let mut q = vec![0.0; nv];
        let mut part = Partial::new();
        // Up to `MAP_CHUNK` points' coordinates and error values, evaluated
        // together by the model's batch entry point.
        let chunk = MAP_CHUNK.min(len);
        let mut qs = vec![0.0; chunk * nv];
        let mut es = vec![0.0; chunk * n];
        let mut flat = vec![0.0; chunk * 6];
        for c0 in (0..len).step_by(MAP_CHUNK) {
            let m = MAP_CHUNK.min(len - c0);
            for k in c0..c0 + m {
                let i = start + k;
                cursor.next_into(&mut q);
                let values = if k == 0 {
                    crate::ErrorValues::values_at(&self.values, &q, &mut scratch)
                } else {
                    self.values.update(&previous, &q, &mut scratch)
                };
                if let Err(source) = values {
                    return Err(MapError::OutOfRange {
                        point: i,
                        at: (self.variables.iter().zip(&q))
                            .map(|(n, x)| format!("{n} = {x}"))
                            .collect::<Vec<_>>()
                            .join(", "),
                        source: Box::new(source),
                    });
                }
                let r = k - c0;
                qs[r * nv..(r + 1) * nv].copy_from_slice(&q);
                es[r * n..(r + 1) * n].copy_from_slice(&scratch);
                std::mem::swap(&mut previous, &mut q);
            }
            // The slices hold `m` whole points, so the sizes fit.
            let _ = self.model.error_points(
                &qs[..m * nv],
                &self.parameters,
                &es[..m * n],
                &mut flat[..m * 6],
            );
            for (r, e) in flat[..m * 6].chunks_exact(6).enumerate() {
                let e: [f64; 6] = std::array::from_fn(|c| e[c]);
                part.add(start + c0 + r, &e);
                if let Some(out) = errors.as_deref_mut() {
                    out[c0 + r] = e;
                }
            }
        }
        Ok(part)
    }
}

/// `|(px, py, pz)|`.
#[inline]
fn volumetric(e: &[f64; 6]) -> f64 {
    (e[0] * e[0] + e[1] * e[1] + e[2] * e[2]).sqrt()
}

/// The points of a map: a full-factorial grid (kept as its axes, never
/// expanded) or a list.
#[derive(Debug, Clone, PartialEq)]
pub enum Points {
    /// Every combination of one value per axis (in the model's variable
    /// order), the last axis varying fastest (the order of the reliability
    /// grid).
    Grid(Vec<Vec<f64>>),
    /// Explicit points, flat: point `i` is `values[i·dimension ..
    /// (i+1)·dimension]`.
    List {
        /// The number of axis values per point.
        dimension: usize,
        /// The values.
        values: Vec<f64>,
    },
}

impl Points {
    /// Explicit points of `dimension` values each, flat. Values that do not
    /// make whole points are an error.
    pub fn list(dimension: usize, values: Vec<f64>) -> Result<Points, MapError> {
        if (dimension == 0 && !values.is_empty())
            || (dimension > 0 && values.len() % dimension != 0)
        {
            return Err(MapError::Ragged {
                len: values.len(),
                variables: dimension,
            });
        }
        Ok(Points::List { dimension, values })
    }

    /// The number of axis values per point.
    pub fn dimension(&self) -> usize {
        match self {
            Points::Grid(axes) => axes.len(),
            Points::List { dimension, .. } => *dimension,
        }
    }

    /// The number of points (a grid of no axis has one point, the empty
    /// one).
    pub fn len(&self) -> usize {
        match self {
            Points::Grid(axes) => axes.iter().map(Vec::len).product(),
            Points::List { dimension: 0, .. } => 0,
            Points::List { dimension, values } => values.len() / dimension,
        }
    }

    /// True when there is no point.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Writes point `i` into `out` (`dimension` values).
    pub fn point_into(&self, i: usize, out: &mut [f64]) {
        match self {
            Points::Grid(axes) => {
                let mut rest = i;
                for (o, a) in out.iter_mut().zip(axes).rev() {
                    *o = a[rest % a.len()];
                    rest /= a.len();
                }
            }
            Points::List { dimension, values } => {
                out.copy_from_slice(&values[i * dimension..(i + 1) * dimension]);
            }
        }
    }

    /// Point `i`.
    pub fn point(&self, i: usize) -> Vec<f64> {
        let mut q = vec![0.0; self.dimension()];
        self.point_into(i, &mut q);
        q
    }

    /// The points from `start` on, one after the other without division.
    fn cursor(&self, start: usize) -> Cursor<'_> {
        let index = match self {
            Points::Grid(axes) => {
                let mut idx = vec![0; axes.len()];
                let mut rest = start;
                for (k, a) in idx.iter_mut().zip(axes).rev() {
                    *k = rest % a.len().max(1);
                    rest /= a.len().max(1);
                }
                idx
            }
            Points::List { .. } => vec![start],
        };
        Cursor {
            points: self,
            index,
        }
    }
}

/// Walks the points of a [`Points`] in order.
struct Cursor<'p> {
    points: &'p Points,
    /// Grid: the multi-index of the next point; list: its index.
    index: Vec<usize>,
}

impl Cursor<'_> {
    /// Writes the next point into `out` and advances.
    #[inline]
    fn next_into(&mut self, out: &mut [f64]) {
        match self.points {
            Points::Grid(axes) => {
                for ((o, a), &k) in out.iter_mut().zip(axes).zip(&self.index) {
                    *o = a[k];
                }
                for (k, a) in self.index.iter_mut().zip(axes).rev() {
                    *k += 1;
                    if *k < a.len() {
                        break;
                    }
                    *k = 0;
                }
            }
            Points::List { dimension, values } => {
                let i = self.index[0];
                out.copy_from_slice(&values[i * dimension..(i + 1) * dimension]);
                self.index[0] += 1;
            }
        }
    }
}

/// The running summary of some points. The volumetric error is tracked by
/// its square (`√` is monotonic: the largest `|p|²` is at the largest `|p|`,
/// and `Σ|p|² = Σpx² + Σpy² + Σpz²`), so no point needs a square root.
#[derive(Debug, Clone, Copy)]
struct Partial {
    min: [f64; 6],
    max: [f64; 6],
    squares: [f64; 6],
    volumetric_max_squared: f64,
    volumetric_at: usize,
}

impl Partial {
    fn new() -> Partial {
        Partial {
            min: [f64::INFINITY; 6],
            max: [f64::NEG_INFINITY; 6],
            squares: [0.0; 6],
            volumetric_max_squared: f64::NEG_INFINITY,
            volumetric_at: 0,
        }
    }

    #[inline]
    fn add(&mut self, i: usize, e: &[f64; 6]) {
        for (c, &x) in e.iter().enumerate() {
            // Plain comparisons (a NaN changes nothing, as with f64::min).
            if x < self.min[c] {
                self.min[c] = x;
            }
            if x > self.max[c] {
                self.max[c] = x;
            }
            self.squares[c] += x * x;
        }
        let v2 = e[0] * e[0] + e[1] * e[1] + e[2] * e[2];
        // The first of equal maxima.
        if v2 > self.volumetric_max_squared {
            self.volumetric_max_squared = v2;
            self.volumetric_at = i;
        }
    }

    /// Adds the summary of later points.
    fn merge(&mut self, later: &Partial) {
        for c in 0..6 {
            self.min[c] = self.min[c].min(later.min[c]);
            self.max[c] = self.max[c].max(later.max[c]);
            self.squares[c] += later.squares[c];
        }
        if later.volumetric_max_squared > self.volumetric_max_squared {
            self.volumetric_max_squared = later.volumetric_max_squared;
            self.volumetric_at = later.volumetric_at;
        }
    }
}

/// Minimum, maximum and root mean square of one component over the map.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ComponentSummary {
    /// The smallest value.
    pub min: f64,
    /// The largest value.
    pub max: f64,
    /// `√(Σ E_c² / n)`.
    pub rms: f64,
}

/// The volumetric error `|(px, py, pz)|` over the map.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct VolumetricSummary {
    /// The largest volumetric error.
    pub max: f64,
    /// Where it is (the first such point).
    pub at: NameMap<String, f64>,
    /// `√(Σ |p|² / n)`.
    pub rms: f64,
    /// The index of that point.
    #[serde(skip)]
    pub index: usize,
}

/// The ISO 230-1-style summary of a map (spec section 3).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MapSummary {
    /// `px`.
    pub px: ComponentSummary,
    /// `py`.
    pub py: ComponentSummary,
    /// `pz`.
    pub pz: ComponentSummary,
    /// `ox`.
    pub ox: ComponentSummary,
    /// `oy`.
    pub oy: ComponentSummary,
    /// `oz`.
    pub oz: ComponentSummary,
    /// The volumetric error.
    pub volumetric: VolumetricSummary,
}

impl MapSummary {
    fn new(p: &Partial, n: usize, at: NameMap<String, f64>, index: usize) -> MapSummary {
        let n = n as f64;
        let c = |k: usize| ComponentSummary {
            min: p.min[k],
            max: p.max[k],
            rms: (p.squares[k] / n).sqrt(),
        };
        MapSummary {
            px: c(0),
            py: c(1),
            pz: c(2),
            ox: c(3),
            oy: c(4),
            oz: c(5),
            volumetric: VolumetricSummary {
                max: p.volumetric_max_squared.sqrt(),
                at,
                rms: ((p.squares[0] + p.squares[1] + p.squares[2]) / n).sqrt(),
                index,
            },
        }
    }

    /// The summary of component `c` (`px..oz` order).
    pub fn component(&self, c: usize) -> &ComponentSummary {
        match c {
            0 => &self.px,
            1 => &self.py,
            2 => &self.pz,
            3 => &self.ox,
            4 => &self.oy,
            _ => &self.oz,
        }
    }
}

/// The error map of a built machine: every point's error and volumetric
/// error, and the summary. Serialises as the spec's JSON document (section
/// 3): `{"machine", "frame", "points": [{"point": {..}, "error": {px..oz},
/// "volumetric"}], "summary": {...}}`.
#[derive(Debug, Clone, PartialEq)]
pub struct MapResult {
    /// The machine's name.
    pub machine: String,
    /// The frame of `E`.
    pub frame: Frame,
    /// The axis variables, in a point's order.
    pub variables: Vec<String>,
    /// The points.
    pub points: Points,
    /// `E` at each point.
    pub errors: Vec<[f64; 6]>,
    /// The summary.
    pub summary: MapSummary,
    /// Per bidirectional table of the values, the reversal that the
    /// approach read leaves out (docs/values.md, "Direction"); serialised
    /// as `reversals` after the spec's keys, only when there are any.
    pub reversals: Vec<crate::values::Reversal>,
}

impl MapResult {
    /// The number of points.
    pub fn len(&self) -> usize {
        self.errors.len()
    }

    /// Always false: a map has at least one point.
    pub fn is_empty(&self) -> bool {
        self.errors.is_empty()
    }

    /// The axis values of point `i`.
    pub fn point(&self, i: usize) -> Vec<f64> {
        self.points.point(i)
    }

    /// `|(px, py, pz)|` at point `i`.
    pub fn volumetric(&self, i: usize) -> f64 {
        volumetric(&self.errors[i])
    }
}

impl Serialize for MapResult {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let mut s = serializer.serialize_struct("MapResult", 5)?;
        s.serialize_field("machine", &self.machine)?;
        s.serialize_field("frame", &self.frame)?;
        s.serialize_field("points", &PointList(self))?;
        s.serialize_field("summary", &self.summary)?;
        if self.reversals.is_empty() {
            s.skip_field("reversals")?;
        } else {
            s.serialize_field("reversals", &self.reversals)?;
        }
        s.end()
    }
}

/// The `points` list of a map, serialised without building it.
struct PointList<'a>(&'a MapResult);

impl Serialize for PointList<'_> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let m = self.0;
        let mut seq = serializer.serialize_seq(Some(m.len()))?;
        let mut q = vec![0.0; m.variables.len()];
        let mut cursor = m.points.cursor(0);
        for e in &m.errors {
            cursor.next_into(&mut q);
            seq.serialize_element(&MapPoint {
                point: Named(&m.variables, &q),
                error: Named(&COMPONENTS, e),
                volumetric: volumetric(e),
            })?;
        }
        seq.end()
    }
}

/// One point of the JSON document.
#[derive(Serialize)]
struct MapPoint<'a, A: AsRef<str>, B: AsRef<str>> {
    point: Named<'a, A>,
    error: Named<'a, B>,
    volumetric: f64,
}

/// Names and values serialised as an object, borrowed.
struct Named<'a, N: AsRef<str>>(&'a [N], &'a [f64]);

impl<N: AsRef<str>> Serialize for Named<'_, N> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let mut map = serializer.serialize_map(Some(self.0.len()))?;
        for (n, v) in self.0.iter().zip(self.1) {
            map.serialize_entry(n.as_ref(), v)?;
        }
        map.end()
    }
}

/// The full-factorial grid of `axes` (one list of values per axis variable,
/// in the model's variable order), flat, the last axis varying fastest (the
/// order of the reliability grid and of [`Points::Grid`], which does not
/// expand it).
pub fn full_factorial(axes: &[Vec<f64>]) -> Vec<f64> {
    let nv = axes.len();
    let count: usize = axes.iter().map(Vec::len).product();
    if nv == 0 {
        return Vec::new();
    }
    let mut out = Vec::with_capacity(count * nv);
    let mut idx = vec![0usize; nv];
    for _ in 0..count {
        out.extend(idx.iter().zip(axes).map(|(&i, a)| a[i]));
        for a in (0..nv).rev() {
            idx[a] += 1;
            if idx[a] < axes[a].len() {
                break;
            }
            idx[a] = 0;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn full_factorial_runs_the_last_axis_fastest() {
        let g = full_factorial(&[vec![0.0, 1.0], vec![10.0, 20.0, 30.0]]);
        assert_eq!(
            g,
            [0.0, 10.0, 0.0, 20.0, 0.0, 30.0, 1.0, 10.0, 1.0, 20.0, 1.0, 30.0]
        );
        assert!(full_factorial(&[vec![0.0], vec![]]).is_empty());
    }

    #[test]
    fn partials_merge_like_one_pass() {
        let pts: Vec<[f64; 6]> = (0..10)
            .map(|i| {
                let x = f64::from(i);
                [x.sin(), x.cos(), 0.1 * x, -x, 2.0, (3.0 * x).sin()]
            })
            .collect();
        let mut one = Partial::new();
        for (i, e) in pts.iter().enumerate() {
            one.add(i, e);
        }
        let (mut a, mut b) = (Partial::new(), Partial::new());
        for (i, e) in pts.iter().enumerate() {
            if i < 4 { &mut a } else { &mut b }.add(i, e);
        }
        a.merge(&b);
        assert_eq!(a.min, one.min);
        assert_eq!(a.max, one.max);
        assert_eq!(a.volumetric_at, one.volumetric_at);
        assert_eq!(a.volumetric_max_squared, one.volumetric_max_squared);
        for c in 0..6 {
            assert!((a.squares[c] - one.squares[c]).abs() <= 1e-12 * one.squares[c].abs());
        }
    }
}
