//! Compensation of a built machine for a controller (measured-machines
//! spec, section 6; `docs/export.md`): what a controller adds to the
//! commanded axes so that the tool point lands where the command aimed, and
//! the files each controller reads.
//!
//! One interface joins the exporters, the round trips and the compensated
//! error map ([`BuiltMachine::compensated_map`]): a [`Correction`] gives,
//! at commanded axis values `q`, the corrections `δq` the controller adds
//! to them (the machine's variables, in their order and units: mm, rad).
//! The grid export (`grid.rs`) and each controller format (`controllers/`)
//! produce one; the residual after compensation is the built machine's
//! error at `q + δq` plus the nominal motion `δq` causes, against the tool
//! point the uncorrected command aimed at.

use crate::model_trait::OutOfRange;
use serde::Serialize;

/// What a controller adds to the commanded axis values (module docs).
pub trait Correction: Sync {
    /// Writes into `delta` (one entry per machine variable, in the
    /// machine's order) the correction the controller adds at the commanded
    /// axis values `q`. A `q` outside what the correction covers is an
    /// error, never clamped or extrapolated silently (a controller that
    /// holds its end values says so in its own implementation).
    fn delta(&self, q: &[f64], delta: &mut [f64]) -> Result<(), OutOfRange>;
}

/// One file an export writes: its name (relative to the output folder) and
/// its whole text, comment lines with the sign convention included.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct ExportedFile {
    /// The file name, e.g. `X.comp` or `compensation.csv`.
    pub name: String,
    /// The file's text.
    pub text: String,
}

pub mod controllers;
pub mod grid;
pub mod thermal;

use crate::built::{
    BuiltMachine, ComponentSummary, MapResult, MapSummary, Points, VolumetricSummary, MAP_BLOCK,
};
use crate::model::Frame;
use crate::model_trait::ErrorModel;
use crate::named::NameMap;

/// Why a compensated evaluation failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[cfg_attr(feature = "miette", derive(miette::Diagnostic))]
#[non_exhaustive]
pub enum CompensationError {
    /// No point was given.
    #[error("no point to evaluate")]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::export::no_points)))]
    NoPoints,
    /// Points of another dimension than the machine's.
    #[error("points of {found} axis values for a machine of {variables} axis variables")]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::export::dimension)))]
    Dimension {
        /// The points' dimension.
        found: usize,
        /// The number of axis variables.
        variables: usize,
    },
    /// A point outside a values table, or outside what the correction covers.
    #[error("at point {} ({at}): {} = {} is outside {} ({} to {})", point + 1, source.variable, source.value, source.table, source.lo, source.hi)]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::export::out_of_range)))]
    OutOfRange {
        /// The point's index (0-based).
        point: usize,
        /// The point, `x = 0, y = 500`.
        at: String,
        /// The table (or the correction's grid) and the value.
        source: Box<OutOfRange>,
    },
    /// The kinematics and the model do not name the same axis variables.
    #[error("the kinematics' axis variables ({kinematics}) are not the model's ({model})")]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::export::variables)))]
    Variables {
        /// The kinematics' variables.
        kinematics: String,
        /// The model's variables.
        model: String,
    },
}

impl CompensationError {
    /// An [`OutOfRange`] at point `point` (`q` in `variables` order).
    pub(crate) fn out_of_range(
        point: usize,
        variables: &[String],
        q: &[f64],
        source: OutOfRange,
    ) -> CompensationError {
        CompensationError::OutOfRange {
            point,
            at: (variables.iter().zip(q))
                .map(|(n, x)| format!("{n} = {x}"))
                .collect::<Vec<_>>()
                .join(", "),
            source: Box::new(source),
        }
    }
}

/// The built machine's error values at `q = q0 + δq`, into `out`. When `q`
/// leaves a table by the correction (a node at a table's end commanded
/// `δq` beyond it), the tables of each axis variable `k` that `q_k` leaves
/// are continued linearly over `|δq_k|` from the uncorrected command `q0`:
/// `v(q0_k + δ_k) ≈ 2·v(q0_k) − v(q0_k − δ_k)` (exact to first order in
/// `δq`, so the residual it enters stays exact to second order in the
/// errors; `docs/export.md`). Every table depends on one axis variable, so
/// with `a` (the variables that leave a table mirrored to `q0 − δq`, the
/// others at `q`) and `b` (those at `q0`, the others at `q`),
/// `v = 2·v(b) − v(a)` is that continuation for the tables of the
/// variables that left, and `v(q)` for every other entry. Returns whether
/// the continuation was used. `q0 − δq` outside a table too is the error
/// of `q`.
pub(crate) fn values_near<M: ErrorModel>(
    built: &BuiltMachine<M>,
    q0: &[f64],
    q: &[f64],
    s: &mut ResidualScratch,
    out: &mut [f64],
) -> Result<bool, OutOfRange> {
    let values = built.values();
    let Err(first) = crate::ErrorValues::values_at(values, q, out) else {
        return Ok(false);
    };
    // Which variables take q out of a table: move them one at a time.
    s.mirror.copy_from_slice(q0);
    s.half.copy_from_slice(q0);
    for k in 0..q.len() {
        s.mirror[k] = q[k];
        let leaves = crate::ErrorValues::values_at(values, &s.mirror, out).is_err();
        s.mirror[k] = if leaves { 2.0 * q0[k] - q[k] } else { q[k] };
        s.half[k] = if leaves { q0[k] } else { q[k] };
    }
    if crate::ErrorValues::values_at(values, &s.mirror, &mut s.base).is_err() {
        return Err(first);
    }
    crate::ErrorValues::values_at(values, &s.half, out).map_err(|_| first)?;
    for (o, &a) in out.iter_mut().zip(&s.base) {
        *o = 2.0 * *o - a;
    }
    Ok(true)
}

/// Scratch space of [`Residual::at`], one per thread.
#[derive(Debug, Clone)]
pub struct ResidualScratch {
    base: Vec<f64>,
    values: Vec<f64>,
    q: Vec<f64>,
    mirror: Vec<f64>,
    half: Vec<f64>,
}

/// What is left of the error when the controller adds `δq` to the command:
/// the tool pose reached at `q + δq` (nominal pose there composed with the
/// built machine's error there) against the nominal pose at `q`
/// (`docs/export.md`, "The residual"):
///
/// ```text
/// p_res = p₀(q + δq) + e_p(q + δq) − p₀(q)
/// [o_res]× ≈ skew( (I + [e_o(q + δq)]×) · R₀(q + δq) · R₀(q)ᵀ )
/// ```
///
/// (`e` in the workpiece frame; both returned in the machine's frame like
/// `E`, so `δq = 0` gives back `E(q)` exactly.)
#[derive(Debug, Clone, Copy)]
pub struct Residual<'b, M> {
    built: &'b BuiltMachine<M>,
}

impl<'b, M: ErrorModel> Residual<'b, M> {
    /// The residual of `built`.
    pub fn new(built: &'b BuiltMachine<M>) -> Residual<'b, M> {
        Residual { built }
    }

    /// A scratch for [`Residual::at`].
    pub fn scratch(&self) -> ResidualScratch {
        let n = self.built.model().errors().len();
        let nv = self.built.variables().len();
        ResidualScratch {
            base: vec![0.0; n],
            values: vec![0.0; n],
            q: vec![0.0; nv],
            mirror: vec![0.0; nv],
            half: vec![0.0; nv],
        }
    }

    /// The residual `[px, py, pz, ox, oy, oz]` at the commanded `q` with the
    /// correction `delta` added, in the machine's frame; and whether a table
    /// was continued over `|δq|` past its end ([`values_near`]).
    pub fn at(
        &self,
        q: &[f64],
        delta: &[f64],
        s: &mut ResidualScratch,
    ) -> Result<([f64; 6], bool), OutOfRange> {
        let built = self.built;
        let model = built.model();
        let p = built.parameters();
        for ((c, &a), &d) in s.q.iter_mut().zip(q).zip(delta) {
            *c = a + d;
        }
        let mut values = std::mem::take(&mut s.values);
        let qd = std::mem::take(&mut s.q);
        let mirrored = values_near(built, q, &qd, s, &mut values);
        s.q = qd;
        s.values = values;
        let mirrored = mirrored?;
        let mut e = [0.0; 6];
        model.error(&s.q, p, &s.values, &mut e);
        let at = model.nominal(&s.q, p);
        let aim = model.nominal(q, p);
        let (mut ep, mut eo) = ([e[0], e[1], e[2]], [e[3], e[4], e[5]]);
        if built.frame() == Frame::Tool {
            ep = apply(&at.rotation, ep);
            eo = apply(&at.rotation, eo);
        }
        let pos: [f64; 3] = std::array::from_fn(|i| at.position[i] + ep[i] - aim.position[i]);
        // M = (I + [eo]×) · R₀(q + δq) · R₀(q)ᵀ; o = vee of its skew part.
        let rel: [[f64; 3]; 3] = std::array::from_fn(|i| {
            std::array::from_fn(|j| (0..3).map(|k| at.rotation[i][k] * aim.rotation[j][k]).sum())
        });
        let w = [
            [0.0, -eo[2], eo[1]],
            [eo[2], 0.0, -eo[0]],
            [-eo[1], eo[0], 0.0],
        ];
        let m: [[f64; 3]; 3] = std::array::from_fn(|i| {
            std::array::from_fn(|j| rel[i][j] + (0..3).map(|k| w[i][k] * rel[k][j]).sum::<f64>())
        });
        let mut ori = [
            0.5 * (m[2][1] - m[1][2]),
            0.5 * (m[0][2] - m[2][0]),
            0.5 * (m[1][0] - m[0][1]),
        ];
        let mut pos = pos;
        if built.frame() == Frame::Tool {
            pos = apply_transposed(&aim.rotation, pos);
            ori = apply_transposed(&aim.rotation, ori);
        }
        Ok(([pos[0], pos[1], pos[2], ori[0], ori[1], ori[2]], mirrored))
    }
}

/// The first comment line of a written file: `provenance` (the words
/// naming what wrote it), a colon, then `rest`; `rest` alone when
/// `provenance` is empty.
pub(crate) fn opening_line(provenance: &str, rest: &str) -> String {
    if provenance.is_empty() {
        rest.to_string()
    } else {
        format!("{provenance}: {rest}")
    }
}

/// The values of `kin`'s parameters from `built`'s, by name (NaN for one
/// the model does not have).
pub(crate) fn kinematics_parameters<M: ErrorModel>(
    kin: &crate::kinematics::forward::Kinematics,
    built: &BuiltMachine<M>,
) -> Vec<f64> {
    let model = built.model().parameters();
    (kin.parameters().iter())
        .map(|(n, _)| {
            (model.iter())
                .position(|m| m == n)
                .map_or(f64::NAN, |i| built.parameters()[i])
        })
        .collect()
}

/// `r · v`.
pub(crate) fn apply(r: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| r[i][0] * v[0] + r[i][1] * v[1] + r[i][2] * v[2])
}

/// `rᵀ · v`.
pub(crate) fn apply_transposed(r: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| r[0][i] * v[0] + r[1][i] * v[1] + r[2][i] * v[2])
}

impl<M: ErrorModel + Sync> BuiltMachine<M> {
    /// The error map after compensation: at every point `q` the residual of
    /// [`Residual::at`] with `δq` from `correction`, as a [`MapResult`] (the
    /// same document and summary as [`BuiltMachine::map`]'s, so it is shown
    /// and plotted the same way). Blocks of
    /// [`MAP_BLOCK`] points run in parallel under the `parallel` feature.
    pub fn compensated_map(
        &self,
        correction: &dyn Correction,
        points: Points,
    ) -> Result<MapResult, CompensationError> {
        let nv = self.variables().len();
        if points.dimension() != nv {
            return Err(CompensationError::Dimension {
                found: points.dimension(),
                variables: nv,
            });
        }
        let count = points.len();
        if count == 0 {
            return Err(CompensationError::NoPoints);
        }
        let residual = Residual::new(self);
        let mut errors = vec![[0.0; 6]; count];
        let block = |(b, out): (usize, &mut [[f64; 6]])| -> Result<(), CompensationError> {
            let mut s = residual.scratch();
            let mut q = vec![0.0; nv];
            let mut d = vec![0.0; nv];
            for (k, o) in out.iter_mut().enumerate() {
                let i = b * MAP_BLOCK + k;
                points.point_into(i, &mut q);
                let fail = |e| CompensationError::out_of_range(i, self.variables(), &q, e);
                correction.delta(&q, &mut d).map_err(fail)?;
                *o = residual.at(&q, &d, &mut s).map_err(fail)?.0;
            }
            Ok(())
        };
        #[cfg(feature = "parallel")]
        let done: Vec<Result<(), CompensationError>> = {
            use rayon::prelude::*;
            errors
                .par_chunks_mut(MAP_BLOCK)
                .enumerate()
                .map(block)
                .collect()
        };
        #[cfg(not(feature = "parallel"))]
        let done: Vec<Result<(), CompensationError>> = errors
            .chunks_mut(MAP_BLOCK)
            .enumerate()
            .map(block)
            .collect();
        done.into_iter().collect::<Result<(), _>>()?;
        let summary = summary_of(self.variables(), &points, &errors);
        Ok(MapResult {
            machine: self.machine().to_string(),
            frame: self.frame(),
            variables: self.variables().to_vec(),
            points,
            errors,
            summary,
            reversals: self.values().reversals(),
        })
    }
}

/// The ISO 230-1-style summary (per component min, max, RMS; the largest
/// volumetric error, where, its RMS) of errors at `points`, in point order
/// (the first of equal maxima), as [`BuiltMachine::map`] reports it.
pub fn summary_of(variables: &[String], points: &Points, errors: &[[f64; 6]]) -> MapSummary {
    let n = errors.len().max(1) as f64;
    let mut min = [f64::INFINITY; 6];
    let mut max = [f64::NEG_INFINITY; 6];
    let mut squares = [0.0; 6];
    let (mut vmax, mut at) = (f64::NEG_INFINITY, 0);
    for (i, e) in errors.iter().enumerate() {
        for c in 0..6 {
            if e[c] < min[c] {
                min[c] = e[c];
            }
            if e[c] > max[c] {
                max[c] = e[c];
            }
            squares[c] += e[c] * e[c];
        }
        let v2 = e[0] * e[0] + e[1] * e[1] + e[2] * e[2];
        if v2 > vmax {
            vmax = v2;
            at = i;
        }
    }
    let c = |k: usize| ComponentSummary {
        min: min[k],
        max: max[k],
        rms: (squares[k] / n).sqrt(),
    };
    MapSummary {
        px: c(0),
        py: c(1),
        pz: c(2),
        ox: c(3),
        oy: c(4),
        oz: c(5),
        volumetric: VolumetricSummary {
            max: vmax.max(0.0).sqrt(),
            at: NameMap::zip(variables.iter().cloned(), points.point(at)),
            rms: ((squares[0] + squares[1] + squares[2]) / n).sqrt(),
            index: at,
        },
    }
}
