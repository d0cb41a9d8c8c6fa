//! The `grid` export (measured-machines spec, section 6; `docs/export.md`):
//! at each node `q` of a grid (or of a list of commanded poses) the axis
//! corrections `δq` that cancel the built machine's predicted error to first
//! order, with the exact Jacobian of the nominal kinematics, and the
//! tool-point error left at each node.
//!
//! The solve at a node, with `J_p` (3×n) and `J_ω` (3×n) the position and
//! angular-velocity blocks of the nominal Jacobian ([`Kinematics::jacobian`]'s
//! columns `[∂p/∂q_k, ω_k]`), `e_p`, `e_o` the error in the workpiece frame
//! and `z = R₀(q)·e_z` the nominal tool axis:
//!
//! ```text
//! tool point:  J_p δq = −e_p                          (3 rows)
//! tool axis:   (J_ω δq + e_o) × z = 0,  i.e.  uᵢᵀ J_ω δq = −uᵢᵀ e_o,
//!              u₁, u₂ an orthonormal basis of the plane ⊥ z   (2 rows)
//! ```
//!
//! solved in that priority (the task-priority solution of Nakamura,
//! Hanafusa & Yoshikawa 1987, "Task-priority based redundancy control of
//! robot manipulators", and Siciliano & Slotine 1991, "A general framework
//! for managing multiple tasks in highly redundant robotic systems"):
//! `δ₁ = J_p⁺(−e_p)` (minimum norm), then
//! `δq = δ₁ + (A_o P)⁺ (b_o − A_o δ₁)` with `A_o = [u₁ᵀ; u₂ᵀ] J_ω`,
//! `b_o = −[u₁ᵀ; u₂ᵀ] e_o` and `P = I − J_p⁺ J_p` the projector onto the
//! motions that leave the tool point where it is. When the five rows can be
//! met (a five-axis machine away from its singularities) this is their exact
//! solution; a three-axis machine (`J_ω = 0`) gets its three offsets; in
//! between, the tool point is met and the tool axis in the least-squares
//! sense, with the minimum-norm `δq` where the axes cannot tell directions
//! apart. The pseudo-inverses come from a one-sided Jacobi SVD (Hestenes
//! 1958) of the ≤ 3 rows; singular values below `1e-9` of the largest row
//! norm count as zero.

use serde::Serialize;

use super::{opening_line, CompensationError, Correction, ExportedFile, Residual, ResidualScratch};
use crate::built::{BuiltMachine, Points, MAP_BLOCK};
use crate::kinematics::forward::{Kinematics, Scalar};
use crate::model::{Frame, JointKind};
use crate::model_trait::{ErrorModel, OutOfRange};
use crate::named::NameMap;

/// Lanes of [`Dual`]: the value and up to `LANES − 1` partial derivatives.
const LANES: usize = 8;

/// Relative rank tolerance of the solve (module docs).
const RANK_TOLERANCE: f64 = 1e-9;

/// A first-order dual number with a fixed number of partials: one pass of
/// [`Kinematics::pose_of`] over these gives the pose and all its partial
/// derivatives (forward-mode AD), where [`Kinematics::jacobian`] makes one
/// pass of allocated jets per variable. Same polynomials, same exact
/// derivative (tested against it).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Dual([f64; LANES]);

impl Scalar for Dual {
    fn constant(value: f64) -> Dual {
        let mut d = [0.0; LANES];
        d[0] = value;
        Dual(d)
    }
    fn constant_like(&self, value: f64) -> Dual {
        Dual::constant(value)
    }
    fn plus(&self, other: &Dual) -> Dual {
        Dual(std::array::from_fn(|i| self.0[i] + other.0[i]))
    }
    fn times(&self, other: &Dual) -> Dual {
        let (a, b) = (self.0[0], other.0[0]);
        let mut d: [f64; LANES] = std::array::from_fn(|i| a * other.0[i] + b * self.0[i]);
        d[0] = a * b;
        Dual(d)
    }
    fn times_f64(&self, k: f64) -> Dual {
        Dual(std::array::from_fn(|i| self.0[i] * k))
    }
    fn sin_cos(&self) -> (Dual, Dual) {
        let (s, c) = self.0[0].sin_cos();
        let mut ds = [0.0; LANES];
        let mut dc = [0.0; LANES];
        ds[0] = s;
        dc[0] = c;
        for i in 1..LANES {
            ds[i] = c * self.0[i];
            dc[i] = -s * self.0[i];
        }
        (Dual(ds), Dual(dc))
    }
}

/// The nominal pose and its exact Jacobian at `q` (columns `[∂p/∂q_k, ω_k]`,
/// [`Kinematics::jacobian`]'s convention): rotation, position, columns.
pub fn pose_and_jacobian(
    kin: &Kinematics,
    q: &[f64],
    p: &[f64],
) -> ([[f64; 3]; 3], [f64; 3], Vec<[f64; 6]>) {
    let n = q.len();
    if n >= LANES {
        let pose = kin.pose(q, p);
        return (pose.rotation, pose.position, kin.jacobian(q, p));
    }
    let duals: Vec<Dual> = (0..n)
        .map(|k| {
            let mut d = [0.0; LANES];
            d[0] = q[k];
            d[k + 1] = 1.0;
            Dual(d)
        })
        .collect();
    let pose = kin.pose_of(&duals, p);
    let r: [[f64; 3]; 3] =
        std::array::from_fn(|i| std::array::from_fn(|j| pose.rotation[i][j].0[0]));
    let position = std::array::from_fn(|i| pose.position[i].0[0]);
    let columns = (0..n)
        .map(|k| {
            let dr = |a: usize, m: usize| pose.rotation[a][m].0[k + 1];
            // W = dR Rᵀ (skew); ω = vee(W).
            let w = |a: usize, b: usize| -> f64 { (0..3).map(|m| dr(a, m) * r[b][m]).sum() };
            [
                pose.position[0].0[k + 1],
                pose.position[1].0[k + 1],
                pose.position[2].0[k + 1],
                0.5 * (w(2, 1) - w(1, 2)),
                0.5 * (w(0, 2) - w(2, 0)),
                0.5 * (w(1, 0) - w(0, 1)),
            ]
        })
        .collect();
    (r, position, columns)
}

/// The minimum-norm least-squares solution of `A x = b` for `m ≤ 3` rows
/// of `n` columns (`a[i]` row `i`), by a one-sided Jacobi SVD of the rows
/// (Hestenes 1958): rotations of row pairs until the rows are orthogonal,
/// `A' = G A` with rows `σᵢ uᵢᵀ`; then `x = Σ (G b)ᵢ / σᵢ · uᵢ` over the
/// `σᵢ > tol`. Returns the rank and leaves the unit row-space vectors `uᵢ`
/// of those in `basis[..rank]`.
fn solve_rows(
    a: &mut [Vec<f64>],
    b: &mut [f64],
    tol: f64,
    x: &mut [f64],
    basis: &mut [Vec<f64>],
) -> usize {
    let m = a.len();
    let dot = |u: &[f64], v: &[f64]| -> f64 { u.iter().zip(v).map(|(a, b)| a * b).sum() };
    for _sweep in 0..30 {
        let mut rotated = false;
        for i in 0..m {
            for j in i + 1..m {
                let alpha = dot(&a[i], &a[i]);
                let beta = dot(&a[j], &a[j]);
                let gamma = dot(&a[i], &a[j]);
                // Orthogonal to rounding, or a row that is zero to the rank
                // tolerance (rotating it against another only moves noise).
                if gamma == 0.0
                    || gamma.abs() <= 4.0 * f64::EPSILON * (alpha * beta).sqrt()
                    || alpha.min(beta) <= tol * tol
                {
                    continue;
                }
                rotated = true;
                let zeta = (beta - alpha) / (2.0 * gamma);
                let t = zeta.signum() / (zeta.abs() + (1.0 + zeta * zeta).sqrt());
                let c = 1.0 / (1.0 + t * t).sqrt();
                let s = c * t;
                let (lo, hi) = a.split_at_mut(j);
                for (u, v) in lo[i].iter_mut().zip(hi[0].iter_mut()) {
                    let (ui, vj) = (*u, *v);
                    *u = c * ui - s * vj;
                    *v = s * ui + c * vj;
                }
                let (bi, bj) = (b[i], b[j]);
                b[i] = c * bi - s * bj;
                b[j] = s * bi + c * bj;
            }
        }
        if !rotated {
            break;
        }
    }
    x.iter_mut().for_each(|v| *v = 0.0);
    let mut rank = 0;
    for i in 0..m {
        let sigma = dot(&a[i], &a[i]).sqrt();
        if sigma <= tol || sigma == 0.0 {
            continue;
        }
        let k = b[i] / (sigma * sigma);
        for (xv, av) in x.iter_mut().zip(&a[i]) {
            *xv += k * av;
        }
        for (u, av) in basis[rank].iter_mut().zip(&a[i]) {
            *u = av / sigma;
        }
        rank += 1;
    }
    rank
}

/// The per-node solver's scratch (one per thread).
struct Solver {
    rows_p: Vec<Vec<f64>>,
    rows_o: Vec<Vec<f64>>,
    basis: Vec<Vec<f64>>,
    basis_o: Vec<Vec<f64>>,
    x1: Vec<f64>,
    x2: Vec<f64>,
}

/// One node's solve: the correction and the ranks of the two tasks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Ranks {
    position: usize,
    axis: usize,
}

impl Solver {
    fn new(n: usize) -> Solver {
        Solver {
            rows_p: vec![vec![0.0; n]; 3],
            rows_o: vec![vec![0.0; n]; 2],
            basis: vec![vec![0.0; n]; 3],
            basis_o: vec![vec![0.0; n]; 2],
            x1: vec![0.0; n],
            x2: vec![0.0; n],
        }
    }

    /// `δq` at a node (module docs) from the nominal rotation, the Jacobian
    /// columns and the error in the workpiece frame.
    fn solve(
        &mut self,
        rotation: &[[f64; 3]; 3],
        columns: &[[f64; 6]],
        ep: [f64; 3],
        eo: [f64; 3],
        delta: &mut [f64],
    ) -> Ranks {
        let n = columns.len();
        let mut scale: f64 = 0.0;
        for (r, row) in self.rows_p.iter_mut().enumerate() {
            for (k, col) in columns.iter().enumerate() {
                row[k] = col[r];
            }
            scale = scale.max(row.iter().map(|v| v * v).sum::<f64>().sqrt());
        }
        let mut b = [-ep[0], -ep[1], -ep[2]];
        let rank_p = solve_rows(
            &mut self.rows_p,
            &mut b,
            RANK_TOLERANCE * scale,
            &mut self.x1,
            &mut self.basis,
        );
        // The tool axis z and two unit vectors across it.
        let z = [rotation[0][2], rotation[1][2], rotation[2][2]];
        let k = (0..3)
            .min_by(|&a, &b| z[a].abs().total_cmp(&z[b].abs()))
            .unwrap_or(0);
        let mut e = [0.0; 3];
        e[k] = 1.0;
        let u1 = unit(cross(z, e));
        let u2 = cross(z, u1);
        let mut bo = [0.0; 2];
        let mut scale_o: f64 = 0.0;
        for (r, u) in [u1, u2].iter().enumerate() {
            let row = &mut self.rows_o[r];
            for (kk, col) in columns.iter().enumerate() {
                row[kk] = u[0] * col[3] + u[1] * col[4] + u[2] * col[5];
            }
            scale_o = scale_o.max(row.iter().map(|v| v * v).sum::<f64>().sqrt());
            // b_o − A_o δ₁
            let a_x1: f64 = row.iter().zip(&self.x1).map(|(a, x)| a * x).sum();
            bo[r] = -(u[0] * eo[0] + u[1] * eo[1] + u[2] * eo[2]) - a_x1;
            // A_o P = A_o − (A_o U) Uᵀ
            for bvec in &self.basis[..rank_p] {
                let proj: f64 = row.iter().zip(bvec).map(|(a, u)| a * u).sum();
                for (a, u) in row.iter_mut().zip(bvec) {
                    *a -= proj * u;
                }
            }
        }
        let rank_o = if scale_o > 0.0 {
            solve_rows(
                &mut self.rows_o,
                &mut bo,
                RANK_TOLERANCE * scale_o,
                &mut self.x2,
                &mut self.basis_o,
            )
        } else {
            self.x2.iter_mut().for_each(|v| *v = 0.0);
            0
        };
        for ((d, a), b) in delta[..n].iter_mut().zip(&self.x1).zip(&self.x2) {
            *d = a + b;
        }
        Ranks {
            position: rank_p,
            axis: rank_o,
        }
    }
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn unit(a: [f64; 3]) -> [f64; 3] {
    let n = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    [a[0] / n, a[1] / n, a[2] / n]
}

/// The largest and the RMS of a quantity over the nodes.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Spread {
    /// The largest value.
    pub max: f64,
    /// `√(Σ x² / n)`.
    pub rms: f64,
}

/// The summary of a grid export.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GridSummary {
    /// The number of nodes.
    pub nodes: usize,
    /// The tool-point error `|e_p|` before compensation (mm).
    pub before: Spread,
    /// The tool-point error left after compensation (mm): the CSV's
    /// `residual`.
    pub residual: Spread,
    /// Where the largest residual is.
    pub residual_at: NameMap<String, f64>,
    /// `max residual / max before` over the nodes (0 when there is no
    /// error).
    pub ratio: f64,
    /// The tool-axis angle left after compensation (rad): the angle between
    /// the tool axis reached and the nominal one.
    pub axis_residual: Spread,
    /// The tool-axis angle error before compensation (rad).
    pub axis_before: Spread,
    /// The largest `|δq|` per axis variable (mm or rad).
    pub max_delta: NameMap<String, f64>,
    /// Nodes at which the tool axis could not be fully corrected (the axes
    /// leave fewer than two tool-axis directions free once the tool point
    /// is met); every node of a three-axis machine.
    pub axis_not_corrected: usize,
    /// Nodes at which `q + δq` left a values table and the residual used
    /// its linear continuation over `|δq|` (`docs/export.md`).
    pub continued: usize,
}

/// The grid export of a built machine (see the [module docs](self)): every
/// node's commanded axis values, corrections and residual, and the summary.
/// Serialises as `{"machine", "frame", "variables", "summary"}`; the nodes
/// are in [`GridCompensation::csv`].
#[derive(Debug, Clone, PartialEq)]
pub struct GridCompensation {
    /// The machine's name.
    pub machine: String,
    /// The frame of the machine's error (the solve works in the workpiece
    /// frame; the CSV's corrections are axis values, frame-free).
    pub frame: Frame,
    /// The axis variables, in a node's order.
    pub variables: Vec<String>,
    /// Which are rotary (their values and corrections in radians).
    pub rotary: Vec<bool>,
    /// The nodes.
    pub points: Points,
    /// `δq`, flat: node `i`'s are `deltas[i·n .. (i+1)·n]`.
    pub deltas: Vec<f64>,
    /// The tool-point error left at each node (mm).
    pub residuals: Vec<f64>,
    /// The summary.
    pub summary: GridSummary,
}

impl Serialize for GridCompensation {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let mut st = s.serialize_struct("GridCompensation", 5)?;
        st.serialize_field("machine", &self.machine)?;
        st.serialize_field("frame", &self.frame)?;
        st.serialize_field("controller", "grid")?;
        st.serialize_field("variables", &self.variables)?;
        st.serialize_field("summary", &self.summary)?;
        st.end()
    }
}

/// Per-node results of one block.
struct BlockOut {
    before: Vec<f64>,
    axis_before: Vec<f64>,
    axis_residual: Vec<f64>,
    not_corrected: usize,
    continued: usize,
}

/// The grid export of `built` at `points` (module docs), with `kin` the
/// nominal kinematics of the same machine ([`Kinematics::from_machine`]).
/// Nodes run in blocks of [`MAP_BLOCK`], in parallel under the `parallel`
/// feature (the same result, bit for bit).
pub fn export<M: ErrorModel + Sync>(
    built: &BuiltMachine<M>,
    kin: &Kinematics,
    points: Points,
) -> Result<GridCompensation, CompensationError> {
    let vars = built.variables();
    let nv = vars.len();
    let kin_vars: Vec<&str> = kin.variables().iter().map(|(n, _)| n.as_str()).collect();
    if kin_vars.iter().zip(vars).any(|(a, b)| *a != b) || kin_vars.len() != nv {
        return Err(CompensationError::Variables {
            kinematics: kin_vars.join(", "),
            model: vars.join(", "),
        });
    }
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
    let params = super::kinematics_parameters(kin, built);
    let mut deltas = vec![0.0; count * nv];
    let mut residuals = vec![0.0; count];
    let residual = Residual::new(built);
    let block = |(b, (d, r)): (usize, (&mut [f64], &mut [f64]))| {
        node_block(built, kin, &params, &residual, &points, b * MAP_BLOCK, d, r)
    };
    #[cfg(feature = "parallel")]
    let outs: Vec<Result<BlockOut, CompensationError>> = {
        use rayon::prelude::*;
        deltas
            .par_chunks_mut(MAP_BLOCK * nv.max(1))
            .zip(residuals.par_chunks_mut(MAP_BLOCK))
            .enumerate()
            .map(block)
            .collect()
    };
    #[cfg(not(feature = "parallel"))]
    let outs: Vec<Result<BlockOut, CompensationError>> = deltas
        .chunks_mut(MAP_BLOCK * nv.max(1))
        .zip(residuals.chunks_mut(MAP_BLOCK))
        .enumerate()
        .map(block)
        .collect();
    let outs = outs.into_iter().collect::<Result<Vec<_>, _>>()?;
    let spread = |it: &mut dyn Iterator<Item = f64>| {
        let (mut max, mut sq) = (0.0f64, 0.0);
        for x in it {
            max = max.max(x);
            sq += x * x;
        }
        Spread {
            max,
            rms: (sq / count as f64).sqrt(),
        }
    };
    let before = spread(&mut outs.iter().flat_map(|o| o.before.iter().copied()));
    let axis_before = spread(&mut outs.iter().flat_map(|o| o.axis_before.iter().copied()));
    let axis_residual = spread(&mut outs.iter().flat_map(|o| o.axis_residual.iter().copied()));
    let res = spread(&mut residuals.iter().copied());
    let at = (0..count)
        .fold((0, f64::NEG_INFINITY), |(k, m), i| {
            if residuals[i] > m {
                (i, residuals[i])
            } else {
                (k, m)
            }
        })
        .0;
    let max_delta = NameMap::zip(
        vars.iter().cloned(),
        (0..nv).map(|k| {
            (0..count)
                .map(|i| deltas[i * nv + k].abs())
                .fold(0.0, f64::max)
        }),
    );
    let summary = GridSummary {
        nodes: count,
        before,
        residual: res,
        residual_at: NameMap::zip(vars.iter().cloned(), points.point(at)),
        ratio: if before.max > 0.0 {
            res.max / before.max
        } else {
            0.0
        },
        axis_residual,
        axis_before,
        max_delta,
        axis_not_corrected: outs.iter().map(|o| o.not_corrected).sum(),
        continued: outs.iter().map(|o| o.continued).sum(),
    };
    Ok(GridCompensation {
        machine: built.machine().to_string(),
        frame: built.frame(),
        variables: vars.to_vec(),
        rotary: (kin.variables().iter())
            .map(|(_, k)| *k == JointKind::Rotary)
            .collect(),
        points,
        deltas,
        residuals,
        summary,
    })
}

/// The nodes `start..` of one block: their `δq` into `deltas` and residuals.
#[allow(clippy::too_many_arguments)]
fn node_block<M: ErrorModel>(
    built: &BuiltMachine<M>,
    kin: &Kinematics,
    params: &[f64],
    residual: &Residual<'_, M>,
    points: &Points,
    start: usize,
    deltas: &mut [f64],
    residuals: &mut [f64],
) -> Result<BlockOut, CompensationError> {
    let nv = built.variables().len();
    let mut solver = Solver::new(nv);
    let mut scratch = built.scratch();
    let mut rs: ResidualScratch = residual.scratch();
    let mut q = vec![0.0; nv];
    let mut out = BlockOut {
        before: Vec::with_capacity(residuals.len()),
        axis_before: Vec::with_capacity(residuals.len()),
        axis_residual: Vec::with_capacity(residuals.len()),
        not_corrected: 0,
        continued: 0,
    };
    for (k, r) in residuals.iter_mut().enumerate() {
        let i = start + k;
        points.point_into(i, &mut q);
        let fail = |e: OutOfRange| CompensationError::out_of_range(i, built.variables(), &q, e);
        let mut e = [0.0; 6];
        built.error_into(&q, &mut scratch, &mut e).map_err(fail)?;
        let (rot, _, columns) = pose_and_jacobian(kin, &q, params);
        let (mut ep, mut eo) = ([e[0], e[1], e[2]], [e[3], e[4], e[5]]);
        if built.frame() == Frame::Tool {
            ep = super::apply(&rot, ep);
            eo = super::apply(&rot, eo);
        }
        let delta = &mut deltas[k * nv..(k + 1) * nv];
        let ranks = solver.solve(&rot, &columns, ep, eo, delta);
        if ranks.axis < 2 {
            out.not_corrected += 1;
        }
        let (left, continued) = residual.at(&q, delta, &mut rs).map_err(fail)?;
        out.continued += usize::from(continued);
        *r = (left[0] * left[0] + left[1] * left[1] + left[2] * left[2]).sqrt();
        out.before
            .push((ep[0] * ep[0] + ep[1] * ep[1] + ep[2] * ep[2]).sqrt());
        // Tool-axis angles: |o × z| (first order), frame-free.
        let z = [rot[0][2], rot[1][2], rot[2][2]];
        out.axis_before.push(norm(cross(eo, z)));
        let mut lo = [left[3], left[4], left[5]];
        if built.frame() == Frame::Tool {
            lo = super::apply(&rot, lo);
        }
        out.axis_residual.push(norm(cross(lo, z)));
    }
    Ok(out)
}

fn norm(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

impl GridCompensation {
    /// The number of nodes.
    pub fn len(&self) -> usize {
        self.residuals.len()
    }

    /// Always false: an export has at least one node.
    pub fn is_empty(&self) -> bool {
        self.residuals.is_empty()
    }

    /// `δq` at node `i`.
    pub fn delta(&self, i: usize) -> &[f64] {
        let n = self.variables.len();
        &self.deltas[i * n..(i + 1) * n]
    }

    /// The CSV's header: `<variables...>,delta_<variable>...,residual`.
    pub fn header(&self) -> Vec<String> {
        let mut h = self.variables.clone();
        h.extend(self.variables.iter().map(|v| format!("delta_{v}")));
        h.push("residual".to_string());
        h
    }

    /// The comment lines of the file (each starting with `# `): what wrote
    /// it (`provenance`, see [`ExportOptions::provenance`]), what the
    /// columns are, their units and the sign convention.
    ///
    /// [`ExportOptions::provenance`]: crate::compensation::controllers::ExportOptions::provenance
    pub fn comments(&self, provenance: &str) -> Vec<String> {
        let units: Vec<String> = (self.variables.iter().zip(&self.rotary))
            .map(|(v, r)| format!("{v} {}", if *r { "rad" } else { "mm" }))
            .collect();
        vec![
            opening_line(
                provenance,
                &format!(
                    "machine {}, {} nodes (docs/export.md)",
                    self.machine,
                    self.len()
                ),
            ),
            format!("units: {}; residual mm", units.join(", ")),
            "sign: command q + delta_q instead of q; delta_q cancels the predicted error (actual - nominal) to first order".to_string(),
            "residual: |tool-point error| left when q + delta_q is commanded (workpiece frame, through the model)".to_string(),
            format!(
                "max residual {} mm, max uncompensated error {} mm",
                self.summary.residual.max, self.summary.before.max
            ),
        ]
    }

    /// The whole grid CSV: the comment lines (the first opening with
    /// `provenance`), the header, one row per node (numbers in Rust's
    /// shortest round-trip form).
    pub fn csv(&self, provenance: &str) -> String {
        use std::fmt::Write;
        let nv = self.variables.len();
        let mut s = String::with_capacity(64 + self.len() * nv * 2 * 22);
        for c in self.comments(provenance) {
            let _ = writeln!(s, "# {c}");
        }
        let _ = writeln!(s, "{}", self.header().join(","));
        let mut q = vec![0.0; nv];
        for i in 0..self.len() {
            self.points.point_into(i, &mut q);
            for x in &q {
                let _ = write!(s, "{x},");
            }
            for x in self.delta(i) {
                let _ = write!(s, "{x},");
            }
            let _ = writeln!(s, "{}", self.residuals[i]);
        }
        s
    }

    /// The file to write: `<machine>_grid.csv` with
    /// [`GridCompensation::csv`].
    pub fn file(&self, provenance: &str) -> ExportedFile {
        ExportedFile {
            name: format!("{}_grid.csv", self.machine),
            text: self.csv(provenance),
        }
    }

    /// The correction a controller reading this grid applies: multilinear
    /// interpolation of the nodes' `δq` inside the grid
    /// ([`GridCorrection`]). An export at a list of points
    /// (not a [`Points::Grid`]) has no grid to interpolate.
    pub fn correction(&self) -> Result<GridCorrection, GridError> {
        let Points::Grid(axes) = &self.points else {
            return Err(GridError::NotAGrid);
        };
        GridCorrection::new(&self.variables, axes, &self.deltas)
    }
}

/// Why a grid export gives no [`Correction`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[cfg_attr(feature = "miette", derive(miette::Diagnostic))]
#[non_exhaustive]
pub enum GridError {
    /// The nodes are a list of poses, not a grid.
    #[error(
        "the nodes are a list of points, not a grid: there is nothing to interpolate between them"
    )]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::export::not_a_grid)))]
    NotAGrid,
    /// An axis lists a value twice.
    #[error("the grid of `{variable}` lists {value} twice")]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::export::duplicate_node)))]
    Duplicate {
        /// The axis variable.
        variable: String,
        /// The value.
        value: f64,
    },
    /// Not one `δq` per node and variable.
    #[error("{found} corrections for {nodes} nodes of {variables} variables")]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::export::shape)))]
    Shape {
        /// The values given.
        found: usize,
        /// The number of nodes.
        nodes: usize,
        /// The number of variables.
        variables: usize,
    },
}

/// A grid of corrections read as a controller reads it: `δq(q)` by
/// multilinear interpolation of the nodes' `δq` in the cell holding `q`
/// (a node itself gives its own `δq` exactly); a `q` outside the grid on
/// any axis is [`OutOfRange`] (never extrapolated). An axis of one value
/// covers exactly that value.
#[derive(Debug, Clone, PartialEq)]
pub struct GridCorrection {
    variables: Vec<String>,
    /// Each axis's values, increasing.
    axes: Vec<Vec<f64>>,
    /// `δq` at every node of the sorted grid (last axis fastest), flat.
    deltas: Vec<f64>,
}

impl GridCorrection {
    /// From the axes of a grid (any order of values on an axis; sorted
    /// here) and `δq` at its nodes in [`Points::Grid`]'s order.
    pub fn new(
        variables: &[String],
        axes: &[Vec<f64>],
        deltas: &[f64],
    ) -> Result<GridCorrection, GridError> {
        let nv = variables.len();
        let nodes: usize = axes.iter().map(Vec::len).product();
        if axes.len() != nv || deltas.len() != nodes * nv {
            return Err(GridError::Shape {
                found: deltas.len(),
                nodes,
                variables: nv,
            });
        }
        // order[a][k]: the original index of the k-th smallest value.
        let mut order = Vec::with_capacity(nv);
        let mut sorted = Vec::with_capacity(nv);
        for (a, values) in axes.iter().enumerate() {
            let mut idx: Vec<usize> = (0..values.len()).collect();
            idx.sort_by(|&i, &j| values[i].total_cmp(&values[j]));
            for w in idx.windows(2) {
                if values[w[0]] == values[w[1]] {
                    return Err(GridError::Duplicate {
                        variable: variables[a].clone(),
                        value: values[w[0]],
                    });
                }
            }
            sorted.push(idx.iter().map(|&i| values[i]).collect::<Vec<f64>>());
            order.push(idx);
        }
        let mut out = vec![0.0; deltas.len()];
        let mut multi = vec![0usize; nv];
        for node in 0..nodes {
            // Sorted multi-index of `node` → original flat index.
            let mut rest = node;
            for a in (0..nv).rev() {
                multi[a] = rest % sorted[a].len();
                rest /= sorted[a].len();
            }
            let mut orig = 0;
            for a in 0..nv {
                orig = orig * axes[a].len() + order[a][multi[a]];
            }
            out[node * nv..(node + 1) * nv].copy_from_slice(&deltas[orig * nv..(orig + 1) * nv]);
        }
        Ok(GridCorrection {
            variables: variables.to_vec(),
            axes: sorted,
            deltas: out,
        })
    }

    /// The axis values of the grid, increasing.
    pub fn axes(&self) -> &[Vec<f64>] {
        &self.axes
    }
}

impl Correction for GridCorrection {
    fn delta(&self, q: &[f64], delta: &mut [f64]) -> Result<(), OutOfRange> {
        let nv = self.variables.len();
        // Per axis: the cell's lower index and the weight of the upper node.
        let mut cell = [(0usize, 0.0f64); 16];
        let mut big = Vec::new();
        let cells: &mut [(usize, f64)] = if nv <= 16 {
            &mut cell[..nv]
        } else {
            big.resize(nv, (0, 0.0));
            &mut big
        };
        for (a, values) in self.axes.iter().enumerate() {
            let x = q.get(a).copied().unwrap_or(f64::NAN);
            let (lo, hi) = (values[0], values[values.len() - 1]);
            if !(x >= lo && x <= hi) {
                return Err(OutOfRange {
                    name: "grid correction".to_string(),
                    table: format!("the correction grid of `{}`", self.variables[a]),
                    variable: self.variables[a].clone(),
                    value: x,
                    lo,
                    hi,
                });
            }
            if values.len() == 1 {
                cells[a] = (0, 0.0);
                continue;
            }
            // The last k with values[k] ≤ x, at most len − 2.
            let k = values.partition_point(|&v| v <= x).saturating_sub(1);
            let k = k.min(values.len() - 2);
            let t = (x - values[k]) / (values[k + 1] - values[k]);
            cells[a] = (k, t);
        }
        delta.iter_mut().for_each(|d| *d = 0.0);
        // Σ over the corners of the cell: two per axis strictly inside an
        // interval (t > 0), one per axis on a node (t = 0, or one value),
        // so a node costs one corner and a point on a grid line 2^(free axes).
        let free = cells.iter().filter(|(_, t)| *t > 0.0).count();
        for c in 0..1usize << free {
            let mut w = 1.0;
            let mut flat = 0;
            let mut bit = 0;
            for (&(k, t), axis) in cells.iter().zip(&self.axes) {
                let up = if t > 0.0 {
                    bit += 1;
                    (c >> (bit - 1)) & 1 == 1
                } else {
                    false
                };
                w *= if up { t } else { 1.0 - t };
                flat = flat * axis.len() + k + usize::from(up);
            }
            if w == 0.0 {
                continue;
            }
            for (d, v) in delta
                .iter_mut()
                .zip(&self.deltas[flat * nv..(flat + 1) * nv])
            {
                *d += w * v;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_dual_jacobian_is_the_jet_jacobian() {
        let yaml = "machine: m\nparameters: {L: 150}\nbodies:\n  bed: {}\n  y: {parent: bed, joint: {type: prismatic, axis: +y, variable: y}}\n  a: {parent: y, offset: [0, 0, 200], joint: {type: rotary, axis: +x, variable: A}}\n  c: {parent: a, offset: [0, 0, -200], joint: {type: rotary, axis: +z, variable: C}}\n  x: {parent: bed, joint: {type: prismatic, axis: +x, variable: x}}\n  z: {parent: x, joint: {type: prismatic, axis: +z, variable: z}}\n  s: {parent: z, offset: [0, 0, L]}\nworkpiece: c\ntool: s\n";
        let machine = crate::load_str(yaml, "m.yaml").unwrap();
        let kin = Kinematics::from_machine(&machine);
        let q: Vec<f64> = (kin.variables().iter())
            .enumerate()
            .map(|(i, _)| 0.3 + 0.7 * i as f64)
            .collect();
        let (r, p, j) = pose_and_jacobian(&kin, &q, &[150.0]);
        let pose = kin.pose(&q, &[150.0]);
        let jj = kin.jacobian(&q, &[150.0]);
        assert_eq!(r, pose.rotation);
        assert_eq!(p, pose.position);
        for (a, b) in j.iter().zip(&jj) {
            for c in 0..6 {
                assert!(
                    (a[c] - b[c]).abs() <= 1e-12 * (1.0 + b[c].abs()),
                    "{a:?} {b:?}"
                );
            }
        }
    }

    #[test]
    fn rows_solve_to_the_minimum_norm_solution() {
        // x + y = 2 twice (rank 1): minimum norm (1, 1, 0).
        let mut a = vec![vec![1.0, 1.0, 0.0], vec![2.0, 2.0, 0.0]];
        let mut b = [2.0, 4.0];
        let mut x = [0.0; 3];
        let mut basis = vec![vec![0.0; 3]; 2];
        let rank = solve_rows(&mut a, &mut b, 1e-12, &mut x, &mut basis);
        assert_eq!(rank, 1);
        for (v, e) in x.iter().zip([1.0, 1.0, 0.0]) {
            assert!((v - e).abs() < 1e-14, "{x:?}");
        }
        // A full-rank 3×3 system: exact.
        let mut a = vec![
            vec![2.0, 1.0, 0.0],
            vec![1.0, 3.0, 1.0],
            vec![0.0, 1.0, 4.0],
        ];
        let mut b = [3.0, 5.0, 5.0];
        let mut basis = vec![vec![0.0; 3]; 3];
        assert_eq!(solve_rows(&mut a, &mut b, 1e-12, &mut x, &mut basis), 3);
        for v in x {
            assert!((v - 1.0).abs() < 1e-14, "{x:?}");
        }
    }

    #[test]
    fn multilinear_interpolation_reproduces_a_multilinear_field() {
        // δ = (1 + 2x + 3y + 4xy, −x) on an unsorted grid.
        let axes = vec![vec![1.0, 0.0, 2.0], vec![0.0, 10.0]];
        let vars = vec!["x".to_string(), "y".to_string()];
        let f = |x: f64, y: f64| [1.0 + 2.0 * x + 3.0 * y + 4.0 * x * y, -x];
        let mut deltas = Vec::new();
        for &x in &axes[0] {
            for &y in &axes[1] {
                deltas.extend(f(x, y));
            }
        }
        let g = GridCorrection::new(&vars, &axes, &deltas).unwrap();
        let mut d = [0.0; 2];
        for (x, y) in [(0.0, 0.0), (0.25, 3.0), (1.5, 9.5), (2.0, 10.0), (1.0, 5.0)] {
            g.delta(&[x, y], &mut d).unwrap();
            let e = f(x, y);
            assert!((d[0] - e[0]).abs() < 1e-12 && (d[1] - e[1]).abs() < 1e-12);
        }
        let err = g.delta(&[2.0 + 1e-9, 0.0], &mut d).unwrap_err();
        assert_eq!((err.variable.as_str(), err.lo, err.hi), ("x", 0.0, 2.0));
        assert!(g.delta(&[f64::NAN, 0.0], &mut d).is_err());
        let dup = GridCorrection::new(&vars, &[vec![0.0, 0.0], vec![1.0]], &[0.0; 4]);
        assert!(matches!(dup, Err(GridError::Duplicate { .. })));
    }
}
