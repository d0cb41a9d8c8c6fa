//! The least-cost allocation as a smooth problem in `tᵢ = ln(σ0ᵢ/σᵢ)`: the
//! distinct grid cases of every toleranced component, their exact
//! reliability `Σ sign·Φ(c/√V)` with first and second derivatives, the
//! constraints (case minimum and component mean), the cost and the barrier.

use chain_core::model::{Component, Sided};

use super::point_name;
use crate::allocate::{AllocateError, ErrorBounds};
use crate::normal;
use crate::study::Study;

/// One distinct grid case of one component.
#[derive(Debug, Clone)]
pub(super) struct Case {
    pub(super) comp: usize,
    /// `aⱼ²` over the variables.
    pub(super) a2: Vec<f64>,
    /// Variance of the fixed errors' contribution.
    pub(super) vfix: f64,
    /// `R = Σ sign·Φ(c/√V)`.
    pub(super) terms: Vec<(f64, f64)>,
    /// Multiplicity / number of grid points.
    pub(super) weight: f64,
    /// The first grid point with these coefficients.
    pub(super) point: usize,
}

#[derive(Debug, Clone, Copy)]
pub(super) enum Con {
    /// Case `k` reaches `level`.
    Case(usize, f64),
    /// The grid mean of component `c` reaches `level`.
    Mean(usize, f64),
}

pub(super) struct Problem {
    /// Input index of each variable.
    pub(super) var: Vec<usize>,
    pub(super) w: Vec<f64>,
    pub(super) s0: Vec<f64>,
    pub(super) tmax: Vec<f64>,
    pub(super) cases: Vec<Case>,
    pub(super) comps: Vec<&'static str>,
    pub(super) cons: Vec<Con>,
}

/// Values and derivatives of one case at `t`.
pub(super) struct CaseEval {
    pub(super) r: f64,
    pub(super) grad: Vec<f64>,
    pub(super) hess: Vec<f64>,
}

impl Problem {
    pub(super) fn n(&self) -> usize {
        self.var.len()
    }

    pub(super) fn case(&self, k: usize, t: &[f64], second: bool) -> CaseEval {
        let c = &self.cases[k];
        let n = self.n();
        let v: Vec<f64> = (0..n)
            .map(|j| c.a2[j] * self.s0[j] * self.s0[j] * (-2.0 * t[j]).exp())
            .collect();
        let vv = c.vfix + v.iter().sum::<f64>();
        let mut grad = vec![0.0; n];
        let mut hess = if second { vec![0.0; n * n] } else { Vec::new() };
        if vv <= 0.0 {
            let r = c
                .terms
                .iter()
                .map(|&(s, cc)| if cc > 0.0 { s } else { 0.0 })
                .sum();
            return CaseEval { r, grad, hess };
        }
        let mut r = 0.0;
        for &(sign, cc) in &c.terms {
            let beta = cc / vv.sqrt();
            r += sign * normal::cdf(beta);
            let phi = sign * normal::pdf(beta) * beta;
            if phi == 0.0 {
                continue;
            }
            for j in 0..n {
                grad[j] += phi * v[j] / vv;
            }
            if second {
                let a = (3.0 - beta * beta) / (vv * vv);
                for j in 0..n {
                    for l in 0..n {
                        hess[j * n + l] += phi * a * v[j] * v[l];
                    }
                    hess[j * n + j] -= phi * 2.0 * v[j] / vv;
                }
            }
        }
        CaseEval { r, grad, hess }
    }

    /// `g`, `∇g` and (optionally) `∇²g` of every constraint.
    pub(super) fn constraints(&self, t: &[f64], second: bool) -> Vec<CaseEval> {
        let n = self.n();
        let evals: Vec<CaseEval> = (0..self.cases.len())
            .map(|k| self.case(k, t, second))
            .collect();
        self.cons
            .iter()
            .map(|con| match *con {
                Con::Case(k, level) => CaseEval {
                    r: evals[k].r - level,
                    grad: evals[k].grad.clone(),
                    hess: evals[k].hess.clone(),
                },
                Con::Mean(c, level) => {
                    let mut out = CaseEval {
                        r: -level,
                        grad: vec![0.0; n],
                        hess: if second { vec![0.0; n * n] } else { Vec::new() },
                    };
                    for (case, e) in self.cases.iter().zip(&evals) {
                        if case.comp != c {
                            continue;
                        }
                        out.r += case.weight * e.r;
                        for (a, b) in out.grad.iter_mut().zip(&e.grad) {
                            *a += case.weight * b;
                        }
                        for (a, b) in out.hess.iter_mut().zip(&e.hess) {
                            *a += case.weight * b;
                        }
                    }
                    out
                }
            })
            .collect()
    }

    pub(super) fn cost(&self, t: &[f64]) -> f64 {
        self.w.iter().zip(t).map(|(w, t)| w * (t.exp() - 1.0)).sum()
    }

    /// The barrier function, `+∞` outside the domain.
    pub(super) fn barrier(&self, t: &[f64], mu: f64) -> f64 {
        let mut phi = self.cost(t);
        for (j, &x) in t.iter().enumerate() {
            if x <= 0.0 || x >= self.tmax[j] {
                return f64::INFINITY;
            }
            phi -= mu * x.ln();
            if self.tmax[j].is_finite() {
                phi -= mu * (self.tmax[j] - x).ln();
            }
        }
        for g in self.constraints(t, false) {
            if g.r <= 0.0 {
                return f64::INFINITY;
            }
            phi -= mu * g.r.ln();
        }
        phi
    }

    pub(super) fn con_name(&self, study: &Study, con: Con) -> String {
        match con {
            Con::Case(k, _) => {
                let c = &self.cases[k];
                format!(
                    "{} min at {}",
                    self.comps[c.comp],
                    point_name(study, c.point)
                )
            }
            Con::Mean(c, _) => format!("{} mean", self.comps[c]),
        }
    }
}

/// The problem of `study` with `bounds`: the variables (errors that drive a
/// toleranced component and can be tightened), the distinct cases and the
/// constraints.
pub(super) fn build(study: &Study, bounds: &[ErrorBounds]) -> Result<Problem, AllocateError> {
    let spec = study.spec();
    let req = spec.requirement.ok_or(AllocateError::NoRequirement)?;
    let inputs = study.inputs();
    if let Some(j) = inputs.marginals().iter().position(|m| !m.is_normal()) {
        return Err(AllocateError::NotNormal {
            error: inputs.names()[j].clone(),
        });
    }
    let np = study.points().len();
    let ne = inputs.len();
    let comps: Vec<Component> = spec.tolerances.iter().map(|(c, _)| *c).collect();
    // Which errors drive a toleranced component.
    let mut used = vec![false; ne];
    for &c in &comps {
        for p in 0..np {
            for (j, a) in study.row(p, c)?.iter().enumerate() {
                if *a != 0.0 {
                    used[j] = true;
                }
            }
        }
    }
    let mut var = Vec::new();
    for j in 0..ne {
        let b = &bounds[j];
        if used[j] && b.min_std < b.std0 {
            if !(b.cost_weight > 0.0 && b.cost_weight.is_finite()) {
                return Err(AllocateError::Unsupported(format!(
                    "cost_weight of `{}` must be positive for the optimal allocation (found {})",
                    b.error, b.cost_weight
                )));
            }
            var.push(j);
        }
    }
    let means = inputs.means();
    let stds = inputs.stds();
    let mut cases: Vec<Case> = Vec::new();
    let mut keys: Vec<Vec<u64>> = Vec::new();
    for (ci, &(c, tol)) in spec.tolerances.iter().enumerate() {
        for p in 0..np {
            let row = study.row(p, c)?;
            let m: f64 = row.iter().zip(means).map(|(a, mu)| a * mu).sum();
            let a2: Vec<f64> = var.iter().map(|&j| row[j] * row[j]).collect();
            let vfix: f64 = (0..ne)
                .filter(|j| !var.contains(j))
                .map(|j| row[j] * row[j] * stds[j] * stds[j])
                .sum();
            let terms = match spec.sided {
                Sided::Upper => vec![(1.0, tol - m)],
                Sided::Two => vec![(1.0, tol - m), (-1.0, -tol - m)],
            };
            let mut key: Vec<u64> = vec![ci as u64, vfix.to_bits()];
            key.extend(a2.iter().map(|x| x.to_bits()));
            key.extend(terms.iter().map(|(_, c)| c.to_bits()));
            match keys.iter().position(|k| *k == key) {
                Some(k) => cases[k].weight += 1.0 / np as f64,
                None => {
                    keys.push(key);
                    cases.push(Case {
                        comp: ci,
                        a2,
                        vfix,
                        terms,
                        weight: 1.0 / np as f64,
                        point: p,
                    });
                }
            }
        }
    }
    let mut cons = Vec::new();
    for ci in 0..comps.len() {
        let ks: Vec<usize> = (0..cases.len()).filter(|&k| cases[k].comp == ci).collect();
        if ks.len() == 1 {
            // One distinct case: its mean is the case itself.
            cons.push(Con::Case(ks[0], req.min.max(req.mean)));
        } else {
            for &k in &ks {
                cons.push(Con::Case(k, req.min));
            }
            cons.push(Con::Mean(ci, req.mean));
        }
    }
    Ok(Problem {
        w: var.iter().map(|&j| bounds[j].cost_weight).collect(),
        s0: var.iter().map(|&j| bounds[j].std0).collect(),
        tmax: var
            .iter()
            .map(|&j| {
                let b = &bounds[j];
                if b.min_std > 0.0 {
                    (b.std0 / b.min_std).ln()
                } else {
                    f64::INFINITY
                }
            })
            .collect(),
        var,
        cases,
        comps: comps.iter().map(|c| c.name()).collect(),
        cons,
    })
}
