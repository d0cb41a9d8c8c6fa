//! The general fallback: damped Newton (Levenberg–Marquardt) on the tool
//! point and tool axis with the exact Jacobian of the symbolic engine
//! ([`Kinematics::jacobian`]), from several starts.
//!
//! It serves any chain the closed form does not: other numbers of free
//! variables (three rotary axes, redundant chains), orientations that are not
//! a product of two fixed-axis rotations, or linear axes whose directions
//! depend on each other. The residual is `[p(q) − p*, ℓ (z(q) − t)]` with
//! `ℓ = max(1, |p*|)` so that both parts weigh alike; its Jacobian is
//! `[∂p/∂q_k, ℓ ω_k × z]`. Starts: the previous row's values, then every
//! combination of the free rotary variables at `0, ±π/2, π` (at most 256).
//! Converged points (iterated to rounding level; accepted at position
//! `1e-11·max(1, |p*|)`, axis `1e-12` when no step improves further) are
//! wrapped, de-duplicated (1e-7) and sorted by their distance to the previous
//! row.

use nalgebra::{DMatrix, DVector};

use super::{held_variables, norm, sub, unit_axis, wrap, Held, InverseError, Solution, V3};
use crate::geometry::{col, cross};
use crate::kinematics::Kinematics;
use crate::model::JointKind;

/// Most starts tried per pose.
const MAX_STARTS: usize = 256;
/// Most iterations per start.
const MAX_ITERATIONS: usize = 100;
/// Most damped-Newton iterations per pose, over all its starts (each one
/// Jacobian and its damped trial steps): the bound on one pose's work. A
/// start that converges takes about a dozen, so the starts of a redundant
/// arm fit (257 × 12 ≈ 3,100); a pose that never converges (a target out of
/// reach, an offset whose rounding exceeds every tolerance) stops here
/// instead of running every start to its iteration limit (257 × 100).
pub const STEPS_PER_POSE: usize = 4_000;

/// Damped-Newton inverse kinematics for any machine.
#[derive(Debug, Clone, PartialEq)]
pub struct NewtonSolver {
    kinematics: Kinematics,
    params: Vec<f64>,
    base: Vec<f64>,
    free: Vec<usize>,
    rotary: Vec<bool>,
}

impl NewtonSolver {
    /// Prepares the solver: `params` the parameter values, `fixed` the held
    /// variables `(index, value)`. Free variables that move neither the tool
    /// point nor the tool axis (a spindle's spin) are held at 0.
    pub fn new(
        kinematics: Kinematics,
        params: &[f64],
        fixed: &[(usize, f64)],
    ) -> Result<NewtonSolver, InverseError> {
        let n = kinematics.variables().len();
        let Held { base, held, .. } = held_variables(&kinematics, n, params, fixed)?;
        let rotary: Vec<bool> = kinematics
            .variables()
            .iter()
            .map(|(_, k)| *k == JointKind::Rotary)
            .collect();
        let free: Vec<usize> = (0..n).filter(|&k| !held[k]).collect();
        if free.is_empty() {
            return Err(InverseError::NoFreeVariable);
        }
        Ok(NewtonSolver {
            kinematics,
            params: params.to_vec(),
            base,
            free,
            rotary,
        })
    }

    /// All solutions found for tool point `point` and tool axis `axis`
    /// (normalised here); `prev` are the previous row's values.
    pub fn solve(&self, point: V3, axis: V3, prev: &[f64]) -> Solution {
        let Some(t) = unit_axis(point, axis) else {
            return Solution::unreachable();
        };
        let mut start: Vec<f64> = self.base.clone();
        for &k in &self.free {
            start[k] = prev
                .get(k)
                .copied()
                .filter(|v| v.is_finite())
                .unwrap_or(0.0);
        }
        let mut found: Vec<Vec<f64>> = Vec::new();
        let mut singular = false;
        let mut budget = STEPS_PER_POSE;
        let starts = self.starts(&start);
        let count = starts.len();
        let mut tried = 0;
        for q0 in starts {
            if budget == 0 {
                break;
            }
            tried += 1;
            if let Some((q, rank_deficient)) = self.converge(q0, point, t, &mut budget) {
                if !found.iter().any(|o| same_point(o, &q, &self.rotary)) {
                    singular |= rank_deficient;
                    found.push(q);
                }
            }
        }
        let mut solution = Solution::ranked(found, prev, &self.rotary, singular);
        solution.stopped = tried < count || (budget == 0 && tried == count);
        solution
    }

    /// The previous values, then the rotary grid around them.
    fn starts(&self, start: &[f64]) -> Vec<Vec<f64>> {
        use std::f64::consts::{FRAC_PI_2, PI};
        let grid = [0.0, FRAC_PI_2, PI, -FRAC_PI_2];
        let rotary: Vec<usize> = self
            .free
            .iter()
            .copied()
            .filter(|&k| self.rotary[k])
            .collect();
        let mut out = vec![start.to_vec()];
        let combinations = grid.len().pow(rotary.len().min(4) as u32);
        for c in 0..combinations.min(MAX_STARTS) {
            let mut q = start.to_vec();
            let mut code = c;
            for &k in rotary.iter().take(4) {
                q[k] = grid[code % grid.len()];
                code /= grid.len();
            }
            out.push(q);
        }
        out
    }

    /// Levenberg–Marquardt from `q`; the wrapped solution and whether its
    /// Jacobian is rank deficient, or `None` if it does not converge.
    fn converge(
        &self,
        mut q: Vec<f64>,
        point: V3,
        t: V3,
        budget: &mut usize,
    ) -> Option<(Vec<f64>, bool)> {
        let scale = 1.0f64.max(norm(point));
        let m = self.free.len();
        let residual = |q: &[f64]| -> ([f64; 6], V3, V3) {
            let pose = self.kinematics.pose(q, &self.params);
            let z = col(&pose.rotation, 2);
            let dp = sub(pose.position, point);
            let dz = sub(z, t);
            (
                [
                    dp[0],
                    dp[1],
                    dp[2],
                    scale * dz[0],
                    scale * dz[1],
                    scale * dz[2],
                ],
                dp,
                z,
            )
        };
        let cost = |r: &[f64; 6]| r.iter().map(|v| v * v).sum::<f64>();
        let (mut r, mut dp, mut z) = residual(&q);
        let mut lambda = 1e-3;
        // Iterate to rounding level; a point where no step improves any more
        // is accepted if it is within the looser tolerance.
        let tight = |dp: V3, z: V3| norm(dp) <= 1e-13 * scale && norm(sub(z, t)) <= 1e-13;
        let loose = |dp: V3, z: V3| norm(dp) <= 1e-11 * scale && norm(sub(z, t)) <= 1e-12;
        for _ in 0..MAX_ITERATIONS {
            // Every iteration counts against the pose's budget.
            if *budget == 0 {
                break;
            }
            *budget -= 1;
            let j = self.weighted_jacobian(&q, z, scale);
            if tight(dp, z) {
                return Some(self.finish(q, &j));
            }
            let a = j.transpose() * &j;
            let g = j.transpose() * DVector::from_row_slice(&r);
            let mut improved = false;
            while lambda < 1e12 {
                let mut damped = a.clone();
                for i in 0..m {
                    damped[(i, i)] += lambda * a[(i, i)].max(1e-9);
                }
                let Some(chol) = damped.cholesky() else {
                    lambda *= 10.0;
                    continue;
                };
                let step = chol.solve(&(-&g));
                let mut trial = q.clone();
                for (i, &k) in self.free.iter().enumerate() {
                    trial[k] += step[i];
                }
                let (r2, dp2, z2) = residual(&trial);
                if cost(&r2) < cost(&r) {
                    q = trial;
                    (r, dp, z) = (r2, dp2, z2);
                    lambda = (lambda * 0.3).max(1e-12);
                    improved = true;
                    break;
                }
                lambda *= 10.0;
            }
            if !improved {
                break;
            }
        }
        if loose(dp, z) {
            let j = self.weighted_jacobian(&q, z, scale);
            return Some(self.finish(q, &j));
        }
        None
    }

    /// Wraps the rotary values and checks the rank of the Jacobian.
    fn finish(&self, mut q: Vec<f64>, j: &DMatrix<f64>) -> (Vec<f64>, bool) {
        for (k, v) in q.iter_mut().enumerate() {
            if self.rotary[k] {
                *v = wrap(*v);
            }
        }
        (q, rank_deficient(j))
    }

    /// `[∂p/∂q_k ; scale·(ω_k × z)]` over the free variables.
    fn weighted_jacobian(&self, q: &[f64], z: V3, scale: f64) -> DMatrix<f64> {
        let columns = self.kinematics.jacobian(q, &self.params);
        let mut j = DMatrix::zeros(6, self.free.len());
        for (i, &k) in self.free.iter().enumerate() {
            let c = columns[k];
            let dz = cross([c[3], c[4], c[5]], z);
            for r in 0..3 {
                j[(r, i)] = c[r];
                j[(r + 3, i)] = scale * dz[r];
            }
        }
        j
    }
}

/// True when the Jacobian has lost rank: the tool point and axis span at most
/// five directions, so the rank to expect is `min(columns, 5)`.
fn rank_deficient(j: &DMatrix<f64>) -> bool {
    let expected = j.ncols().min(5);
    let mut sv: Vec<f64> = j
        .clone()
        .svd(false, false)
        .singular_values
        .iter()
        .copied()
        .collect();
    sv.sort_by(|a, b| b.total_cmp(a));
    let largest = sv.first().copied().unwrap_or(0.0);
    expected == 0 || sv.get(expected - 1).is_none_or(|s| *s <= 1e-9 * largest)
}

/// Two converged points are one solution when they agree to 1e-7 (radians, or
/// relative to the length): far above the convergence tolerance, far below
/// the distance between distinct branches.
fn same_point(a: &[f64], b: &[f64], rotary: &[bool]) -> bool {
    a.iter().zip(b).zip(rotary).all(|((x, y), r)| {
        let d = if *r { wrap(x - y) } else { x - y };
        d.abs() < 1e-7 * 1.0f64.max(x.abs())
    })
}
