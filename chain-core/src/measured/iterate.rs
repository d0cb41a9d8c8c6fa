//! The first-order fit checked against the exact kinematics, and the
//! exact fit by Levenberg–Marquardt (`chain identify`'s iteration;
//! `docs/identify.md`, "When first order is not enough").
//!
//! # Formulas
//!
//! With `f_i(x)` the exact model of scalar row `i` (a component of the
//! exact deviation [`super::exact::ExactChain`], less the position of its
//! record's set-up if it has one, or `uᵀ` of it along a direction) and
//! `a_i x` its first-order model:
//!
//! - **check**: `δ_i = f_i(x̂) − a_i x̂` at the measured poses with the
//!   linear estimate `x̂`; the first order is **not adequate** when some
//!   `|δ_i| / σ_i` exceeds the noise scale (`σ_i` the row's std, 1
//!   without a `std` column; the noise scale `s` of the fit, or 1 with a
//!   `std` column when the fit has no degree of freedom).
//! - **angles**: an angular error motion whose largest angle at the measured
//!   poses, `max_q |Σ_j w_j(q) x_j|` over its slot's errors (one constant, or
//!   a function slot's coefficients), exceeds [`ANGLE_LIMIT`] is flagged by
//!   its name (the function's for a slot): beyond it the
//!   dropped second-order terms (`θ²/2` of the angle times the lever) are
//!   no longer negligible against the first-order ones on a metre-sized
//!   machine.
//! - **iteration**: Levenberg–Marquardt on `Σ ((b_i − f_i(x))/σ_i)²` over
//!   the estimated errors (the others fixed at 0), started from the linear
//!   estimate, with the exact Jacobian of [`super::exact::ExactChain`]:
//!   `(H + μ diag H) δ = Jᵀ W r`, `H = Jᵀ W J` (equilibrated Cholesky); a
//!   step that lowers the sum is taken and `μ /= 3`, else `μ *= 4`.
//!   Converged when an accepted step lowers the sum by less than 1e-12 of
//!   it, or no step can (`μ > 1e10`); at most [`MAX_ITERATIONS`]; not
//!   converged when the exact model is not finite. The
//!   covariance is `s² H⁻¹` (`s² = RSS/(m − k)`) without a `std` column,
//!   `H⁻¹` with one, at the solution.

use nalgebra::{DMatrix, DVector};
use serde::Serialize;

use super::estimate::{covariance, noise_scale2, Estimate};
use super::exact::ExactChain;
use super::identify::Identification;
use super::measurements::{Design, Measurement};
use crate::model::{ErrorKind, Machine};

/// Identified angles beyond this (rad) are outside the first-order range.
pub const ANGLE_LIMIT: f64 = 1e-2;
/// The most Levenberg–Marquardt iterations.
pub const MAX_ITERATIONS: usize = 100;

/// The first-order fit against the exact kinematics at the measured poses.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FirstOrderCheck {
    /// `max |f_i(x̂) − a_i x̂|` (measurement units).
    pub max: f64,
    /// Its root mean square over the rows.
    pub rms: f64,
    /// The noise scale it is compared with (weighted units).
    pub noise: Option<f64>,
    /// Whether some row's difference exceeds the noise.
    pub exceeds_noise: bool,
    /// The angular error motions beyond [`ANGLE_LIMIT`] at the measured
    /// poses (a constant error by its name, a function slot by the
    /// function's: its whole value, not each coefficient), with their
    /// largest angle (rad).
    pub large_angles: Vec<(String, f64)>,
}

/// The exact fit.
#[derive(Debug, Clone, PartialEq)]
pub struct Iteration {
    /// Iterations taken (Jacobian evaluations).
    pub iterations: usize,
    /// Whether the convergence test was met.
    pub converged: bool,
    /// The weighted sum of squares of the exact model at the linear
    /// estimate.
    pub rss_linear: f64,
    /// The same at the solution.
    pub rss: f64,
    /// Root mean square of `b − f(x)` at the solution (measurement units).
    pub rms: f64,
    /// The largest `|b − f(x)|` at the solution.
    pub max: f64,
    /// The estimated errors (indices).
    pub estimated: Vec<usize>,
    /// Every error's value (fixed ones 0) and std.
    pub estimates: Vec<Estimate>,
    /// The covariance (`n × n`, zero for fixed errors).
    pub covariance: DMatrix<f64>,
    /// The solution less the linear estimate, per error.
    pub change: Vec<f64>,
}

/// The exact rows at `x`: `f(x)` and, with `jacobian`, `∂f/∂x` (`m × n`),
/// each record's rows [`super::Observed::row`] of the exact deviation and
/// of its Jacobian, as the design's rows are of the sensitivity.
pub fn exact_rows(
    machine: &Machine,
    records: &[Measurement],
    design: &Design,
    x: &[f64],
    jacobian: bool,
) -> (Vec<f64>, Option<DMatrix<f64>>) {
    let chain = ExactChain::new(machine);
    let m = design.b.len();
    let n = x.len();
    let ne = design.machine_errors();
    let (errors, setups) = x.split_at(ne);
    let thermal = machine.is_thermal();
    let mut f = vec![0.0; m];
    let mut jac = jacobian.then(|| DMatrix::zeros(m, n));
    let mut i = 0;
    while i < m {
        let r = design.origin[i].0;
        let rec = &records[r];
        // At the record's thermal state a thermal coefficient acts as its
        // value times ΔT, and its Jacobian column is scaled alike
        // (docs/thermal.md).
        let factors = thermal.then(|| rec.thermal_factors(machine));
        let scaled: Vec<f64>;
        let at_state = match &factors {
            Some(fs) => {
                scaled = errors.iter().zip(fs).map(|(e, f)| e * f).collect();
                &scaled[..]
            }
            None => errors,
        };
        let (mut dev, j) = if jacobian {
            let (d, mut j) = chain.deviation_and_jacobian(&rec.q, &rec.p, at_state);
            if let Some(fs) = &factors {
                for (k, f) in fs.iter().enumerate() {
                    j.column_mut(k).scale_mut(*f);
                }
            }
            (d, Some(j))
        } else {
            (chain.deviation(&rec.q, &rec.p, at_state), None)
        };
        // A set-up's unknowns: their columns weighted by them added to
        // the deviation ([`super::Setup::columns`]: a position s is −s in
        // the machine's frame, `docs/five-axis.md`).
        let setup = (rec.setup).map(|g| {
            let nominal = chain.nominal(&rec.q, &rec.p);
            (g, design.setups[g].columns(&nominal, &rec.observed))
        });
        if let Some((g, columns)) = &setup {
            for (l, col) in columns.iter().enumerate() {
                for (d, c) in dev.iter_mut().zip(col) {
                    *d += setups[3 * g + l] * c;
                }
            }
        }
        let observed = &rec.observed;
        let rows = observed.rows();
        for c in 0..rows {
            f[i + c] = observed.row(c, dev);
            if let (Some(out), Some(j)) = (jac.as_mut(), &j) {
                for k in 0..ne {
                    out[(i + c, k)] = observed.row(c, [j[(0, k)], j[(1, k)], j[(2, k)]]);
                }
                if let Some((g, columns)) = &setup {
                    for (l, col) in columns.iter().enumerate() {
                        out[(i + c, ne + 3 * g + l)] = observed.row(c, *col);
                    }
                }
            }
        }
        i += rows;
    }
    (f, jac)
}

/// `1/σ_i` per row.
fn inv_sigma(design: &Design) -> Vec<f64> {
    match &design.std {
        Some(s) => s.iter().map(|s| 1.0 / s).collect(),
        None => vec![1.0; design.b.len()],
    }
}

/// Checks the first-order fit `x` (every error) against the exact
/// kinematics at the measured poses (module docs).
pub fn check(
    machine: &Machine,
    records: &[Measurement],
    design: &Design,
    r: &Identification,
    x: &[f64],
) -> FirstOrderCheck {
    let (f, _) = exact_rows(machine, records, design, x, false);
    let w = inv_sigma(design);
    let ax = &design.a * DVector::from_column_slice(x);
    let diff: Vec<f64> = f.iter().zip(ax.iter()).map(|(f, a)| f - a).collect();
    let m = diff.len().max(1);
    let max = diff.iter().fold(0.0f64, |a, d| a.max(d.abs()));
    let rms = (diff.iter().map(|d| d * d).sum::<f64>() / m as f64).sqrt();
    let noise = r.residual.scale.or(r.weighted.then_some(1.0));
    let worst = diff
        .iter()
        .zip(&w)
        .fold(0.0f64, |a, (d, w)| a.max((d * w).abs()));
    let exceeds_noise = noise.is_some_and(|s| worst > s);
    // Each angular error motion's largest angle at the measured poses: a
    // function slot's value Σ_k w_k(q) x_k (named by the function), or a
    // constant error's value; in the order of their first error.
    let chain = ExactChain::new(machine);
    let ne = design.machine_errors();
    let angular = |j: usize| {
        matches!(
            machine.errors[j].kind,
            ErrorKind::Angular | ErrorKind::Squareness
        )
    };
    let mut motions: Vec<(usize, String, Vec<usize>)> = Vec::new();
    let mut in_function = vec![false; ne];
    for f in &machine.functions {
        let members: Vec<usize> = f.coefficients.iter().map(|(j, _)| *j).collect();
        for &j in &members {
            in_function[j] = true;
        }
        if let Some(&first) = members.iter().min() {
            if angular(first) {
                motions.push((first, f.name.clone(), members));
            }
        }
    }
    for j in (0..ne).filter(|&j| angular(j) && !in_function[j]) {
        motions.push((j, r.errors[j].clone(), vec![j]));
    }
    motions.sort_by_key(|(first, _, _)| *first);
    let mut largest = vec![0.0f64; motions.len()];
    for rec in records {
        let factors = rec.thermal_factors(machine);
        let wj: Vec<f64> = (chain.weights(&rec.q).iter())
            .zip(&factors)
            .map(|(w, f)| w * f)
            .collect();
        for ((_, _, members), l) in motions.iter().zip(largest.iter_mut()) {
            let angle: f64 = members.iter().map(|&j| wj[j] * x[j]).sum();
            *l = l.max(angle.abs());
        }
    }
    let large_angles = (motions.into_iter().zip(largest))
        .filter(|(_, l)| *l > ANGLE_LIMIT)
        .map(|((_, name, _), l)| (name, l))
        .collect();
    FirstOrderCheck {
        max,
        rms,
        noise,
        exceeds_noise,
        large_angles,
    }
}

/// Levenberg–Marquardt on the exact kinematics over `estimated`, from the
/// linear estimate `start` (module docs).
pub fn iterate(
    machine: &Machine,
    records: &[Measurement],
    design: &Design,
    estimated: &[usize],
    start: &[f64],
) -> Iteration {
    let k = estimated.len();
    let m = design.b.len();
    let w = inv_sigma(design);
    let weighted = design.std.is_some();
    let rss_of = |f: &[f64]| -> f64 {
        (design.b.iter().zip(f).zip(&w))
            .map(|((b, f), w)| ((b - f) * w).powi(2))
            .sum()
    };
    let mut x = start.to_vec();
    let (f0, _) = exact_rows(machine, records, design, &x, false);
    let rss_linear = rss_of(&f0);
    let mut rss = rss_linear;
    let mut mu = 1e-3;
    let mut iterations = 0;
    let mut converged = false;
    let mut h = DMatrix::zeros(k, k);
    let mut finite = rss_linear.is_finite();
    while k > 0 && finite && iterations < MAX_ITERATIONS {
        iterations += 1;
        let (f, jac) = exact_rows(machine, records, design, &x, true);
        let Some(jac) = jac else { break };
        if !jac.iter().chain(&f).all(|v| v.is_finite()) {
            finite = false;
            break;
        }
        // Weighted rows of the estimated columns.
        let js = DMatrix::from_fn(m, k, |i, a| jac[(i, estimated[a])] * w[i]);
        let r = DVector::from_fn(m, |i, _| (design.b[i] - f[i]) * w[i]);
        h = js.tr_mul(&js);
        let g = js.tr_mul(&r);
        let mut improved = false;
        while mu <= 1e10 {
            let e: Vec<f64> = (0..k)
                .map(|a| {
                    let d = h[(a, a)];
                    if d > 0.0 {
                        1.0 / d.sqrt()
                    } else {
                        1.0
                    }
                })
                .collect();
            let a_mat = DMatrix::from_fn(k, k, |a, b| {
                e[a] * (h[(a, b)] + if a == b { mu * h[(a, a)] } else { 0.0 }) * e[b]
            });
            let Some(ch) = nalgebra::Cholesky::new(a_mat) else {
                mu *= 4.0;
                continue;
            };
            let z = ch.solve(&DVector::from_fn(k, |a, _| e[a] * g[a]));
            let mut trial = x.clone();
            for (a, &j) in estimated.iter().enumerate() {
                trial[j] += e[a] * z[a];
            }
            let (ft, _) = exact_rows(machine, records, design, &trial, false);
            let rt = rss_of(&ft);
            if rt < rss {
                let gain = rss - rt;
                x = trial;
                rss = rt;
                mu = (mu / 3.0).max(1e-12);
                improved = true;
                if gain <= 1e-12 * rss {
                    converged = true;
                }
                break;
            }
            mu *= 4.0;
        }
        if !improved {
            // No step lowers the sum: a minimum to the model's precision.
            converged = true;
        }
        if converged {
            break;
        }
    }
    // The Hessian at the solution (the loop's is that of the point before
    // its last step).
    let (f, jac) = exact_rows(machine, records, design, &x, true);
    if let Some(jac) = jac {
        let js = DMatrix::from_fn(m, k, |i, a| jac[(i, estimated[a])] * w[i]);
        h = js.tr_mul(&js);
    }
    let converged = converged && finite;
    let res: Vec<f64> = design.b.iter().zip(&f).map(|(b, f)| b - f).collect();
    let rms = (res.iter().map(|r| r * r).sum::<f64>() / m.max(1) as f64).sqrt();
    let max = res.iter().fold(0.0f64, |a, r| a.max(r.abs()));
    let scale2 = noise_scale2(weighted, rss, m, k);
    // Equilibrated Cholesky; a singular H leaves the std unknown (NaN),
    // never 0.
    let e: Vec<f64> = (0..k)
        .map(|a| 1.0 / h[(a, a)].max(f64::MIN_POSITIVE).sqrt())
        .collect();
    let scaled = DMatrix::from_fn(k, k, |a, b| e[a] * h[(a, b)] * e[b]);
    let hinv = match nalgebra::Cholesky::new(scaled) {
        Some(ch) => {
            let inv = ch.inverse();
            DMatrix::from_fn(k, k, |a, b| e[a] * inv[(a, b)] * e[b])
        }
        None => DMatrix::from_element(k, k, f64::NAN),
    };
    let (covariance, estimates) = covariance(&x, estimated, &hinv, scale2);
    Iteration {
        iterations,
        converged,
        rss_linear,
        rss,
        rms,
        max,
        estimated: estimated.to_vec(),
        estimates,
        covariance,
        change: x.iter().zip(start).map(|(a, b)| a - b).collect(),
    }
}
