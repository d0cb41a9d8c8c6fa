//! The least-cost standard deviations (see [`crate::allocate`]): the problem
//! (`problem.rs`), the log-barrier Newton path (`barrier.rs`) and the
//! active-set polish with the KKT check (`kkt.rs`).

use chain_core::ErrorModel;

use super::{component_summaries, evaluate};
use super::{AllocateError, Allocation, ErrorBounds, Kkt, Optimal};
use crate::form::Form;
use crate::study::{Algorithm, Study, Summary};

mod barrier;
mod kkt;
mod problem;

use problem::{build, Con};

/// The least-cost standard deviations meeting the requirement.
pub fn optimal<M: ErrorModel + ?Sized>(
    model: &M,
    parameters: &[f64],
    study: &Study,
    bounds: &[ErrorBounds],
    options: &Optimal,
) -> Result<Allocation, AllocateError> {
    let mut problem = build(study, bounds)?;
    let initial = component_summaries(&study.run(&Algorithm::Form(Form::default()), &())?);
    let n = problem.n();
    let stds0: Vec<f64> = bounds.iter().map(|b| b.std0).collect();
    // Impose the requirement with a small margin.
    let levels: Vec<f64> = problem
        .cons
        .iter()
        .map(|c| match *c {
            Con::Case(_, l) | Con::Mean(_, l) => l,
        })
        .collect();
    for c in problem.cons.iter_mut() {
        match c {
            Con::Case(_, l) | Con::Mean(_, l) => *l = (*l + options.margin).min(1.0),
        }
    }
    // Already met: nothing to tighten.
    let zero = vec![0.0; n];
    if problem.constraints(&zero, false).iter().all(|g| g.r >= 0.0) {
        return finish(model, parameters, study, bounds, initial, stds0, None);
    }
    // Feasibility at the bounds (every reliability increases with every t).
    let big = 40.0;
    let t_hi: Vec<f64> = problem.tmax.iter().map(|&m| m.min(big)).collect();
    let g_hi = problem.constraints(&t_hi, false);
    if let Some((k, g)) = g_hi.iter().enumerate().find(|(_, g)| g.r < 0.0) {
        let con = problem.cons[k];
        let (comp, what, at, required) = match con {
            Con::Case(i, _) => {
                let c = &problem.cases[i];
                (
                    c.comp,
                    "minimum reliability",
                    Some(point_name(study, c.point)),
                    levels[k],
                )
            }
            Con::Mean(c, _) => (c, "mean reliability", None, levels[k]),
        };
        // The bounded errors that drive this component, by contribution.
        let mut contrib: Vec<(usize, f64)> = Vec::new();
        for case in problem.cases.iter().filter(|c| c.comp == comp) {
            for (i, &j) in problem.var.iter().enumerate() {
                let v = case.a2[i] * bounds[j].min_std * bounds[j].min_std;
                if v > 0.0 {
                    match contrib.iter_mut().find(|(x, _)| *x == j) {
                        Some(e) => e.1 = e.1.max(v),
                        None => contrib.push((j, v)),
                    }
                }
            }
        }
        // Errors held fixed (min_std ≥ std) bind too.
        let tol = study.spec().tolerances[comp].0;
        for j in 0..bounds.len() {
            if !problem.var.contains(&j)
                // (Every row was read when the problem was built.)
                && (0..study.points().len())
                    .any(|p| study.row(p, tol).is_ok_and(|r| r[j] != 0.0))
            {
                contrib.push((j, f64::MAX));
            }
        }
        contrib.sort_by(|a, b| b.1.total_cmp(&a.1));
        return Err(AllocateError::Infeasible {
            component: problem.comps[comp].to_string(),
            what,
            at,
            best: g.r + levels[k] + options.margin,
            required,
            binding: contrib
                .iter()
                .map(|&(j, _)| {
                    format!("{} (min_std {})", bounds[j].error, short(bounds[j].min_std))
                })
                .collect(),
        });
    }
    let (t, mu, iterations) = barrier::central_path(&problem, big)?;
    // Multipliers of the barrier solution.
    let gs = problem.constraints(&t, false);
    let lambda: Vec<f64> = gs.iter().map(|g| mu / g.r).collect();
    let (t, lambda, polished, extra) = match kkt::polish(&problem, &t, &lambda, &gs, mu) {
        Some((t, l, it)) => (t, l, true, it),
        None => (t, lambda, false, 0),
    };
    let kkt = kkt::kkt(
        &problem,
        study,
        &t,
        &lambda,
        polished,
        mu,
        iterations + extra,
    );
    let mut stds = stds0.clone();
    for (i, &j) in problem.var.iter().enumerate() {
        stds[j] = problem.s0[i] * (-t[i]).exp();
        if bounds[j].min_std > 0.0 {
            stds[j] = stds[j].max(bounds[j].min_std);
        }
    }
    finish(model, parameters, study, bounds, initial, stds, Some(kkt))
}

/// The grid point `p` as `x=…, y=…` (grid axes first).
pub(super) fn point_name(study: &Study, p: usize) -> String {
    let vars = study.variables();
    study
        .display_order()
        .iter()
        .map(|&i| format!("{}={}", vars[i], study.points().point(p)[i]))
        .collect::<Vec<_>>()
        .join(", ")
}

/// A short number: 6 significant digits, trailing zeros trimmed.
fn short(x: f64) -> String {
    let s = format!("{x:.5e}");
    match s.split_once('e') {
        Some((m, e)) if m.contains('.') => {
            format!("{}e{e}", m.trim_end_matches('0').trim_end_matches('.'))
        }
        _ => s,
    }
}

fn finish<M: ErrorModel + ?Sized>(
    model: &M,
    parameters: &[f64],
    study: &Study,
    bounds: &[ErrorBounds],
    initial: Vec<Summary>,
    stds: Vec<f64>,
    kkt: Option<Kkt>,
) -> Result<Allocation, AllocateError> {
    let (_, result) = evaluate(model, parameters, study, &stds)?;
    let summaries = component_summaries(&result);
    Ok(Allocation::new(
        super::StrategyName::Optimal,
        initial,
        Vec::new(),
        bounds,
        &stds,
        summaries,
        kkt,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::allocate::bounds;
    use crate::sensitivity::sensitivity;
    use crate::study::Target;
    use chain_core::model::Component;

    const YAML: &str = "
machine: m
bodies:
  bed: {}
  xs: {parent: bed, joint: {type: prismatic, axis: +x, variable: x}, errors: {dx: a, ez: b}}
  ys: {parent: xs, joint: {type: prismatic, axis: +y, variable: y}, errors: {dx: c}}
workpiece: bed
tool: ys
statistics:
  a: {dist: normal, mean: 0.001, std: 0.01}
  b: {dist: normal, mean: 0, std: 0.00005}
  c: {dist: normal, mean: -0.002, std: 0.008, min_std: 0.001}
reliability:
  tolerance: {px: 0.03}
  sided: SIDED
  grid: {x: [0], y: [100, 300, 500]}
  requirement: {min: 0.9, mean: 0.95}
";

    fn setup(sided: &str) -> (chain_core::CompiledModel, Study, Vec<ErrorBounds>) {
        let m = chain_core::load_str(&YAML.replace("SIDED", sided), "m.yaml").unwrap();
        let model = chain_core::compile(&m);
        let study = crate::machine::study(&m, &model, &[], None).unwrap();
        let b = bounds(&m, &study).unwrap();
        (model, study, b)
    }

    #[test]
    fn case_derivatives_match_finite_differences_and_the_sensitivities() {
        for sided in ["upper", "two"] {
            let (_, study, b) = setup(sided);
            let p = build(&study, &b).unwrap();
            let n = p.n();
            assert_eq!(n, 3);
            let t = [0.3, 0.7, 0.2];
            for k in 0..p.cases.len() {
                let e = p.case(k, &t, true);
                for j in 0..n {
                    let h = 1e-6;
                    let mut tp = t;
                    let mut tm = t;
                    tp[j] += h;
                    tm[j] -= h;
                    let (ep, em) = (p.case(k, &tp, true), p.case(k, &tm, true));
                    let fd = (ep.r - em.r) / (2.0 * h);
                    assert!((fd - e.grad[j]).abs() < 1e-7, "{sided} grad {k} {j}");
                    for l in 0..n {
                        let fd = (ep.grad[l] - em.grad[l]) / (2.0 * h);
                        assert!((fd - e.hess[j * n + l]).abs() < 1e-6, "{sided} hess");
                    }
                }
            }
        }
        // ∂R/∂t = −σ ∂R/∂σ with the engine's exact sensitivities (upper).
        let (_, study, b) = setup("upper");
        let p = build(&study, &b).unwrap();
        let zero = [0.0; 3];
        for (k, case) in p.cases.iter().enumerate() {
            let ev = study
                .event(Target::Component(Component::Px), case.point)
                .unwrap();
            let f = Form::default().run(&ev).unwrap();
            let s = sensitivity(&ev, &f).unwrap();
            let e = p.case(k, &zero, false);
            assert!((e.r - f.reliability).abs() < 1e-12);
            for (i, &j) in p.var.iter().enumerate() {
                let want = -b[j].std0 * s.inputs[j].dr_dstd;
                assert!((e.grad[i] - want).abs() < 1e-9 * (1.0 + want.abs()));
            }
        }
    }

    #[test]
    fn optimum_is_kkt_and_bounds_hold_with_nonzero_means() {
        for sided in ["upper", "two"] {
            let (model, study, b) = setup(sided);
            let r = optimal(&model, &[], &study, &b, &Optimal::default()).unwrap();
            let k = r.kkt.as_ref().unwrap();
            assert!(k.residual() < 1e-8, "{sided}: {k:?}");
            for (bb, (_, s)) in b.iter().zip(&r.std) {
                assert!(*s <= bb.std0 && *s >= bb.min_std);
            }
            assert!(r.cost > 0.0 && r.met);
        }
    }
}
