//! The paper's procedure (Wang & Yuan 2021, Section 3.3, Tables 5-7): rank
//! the errors of every unmet component by their grid-mean `|∂R/∂σ|`, tighten
//! those within a fraction of the largest by one step, re-evaluate with FORM.

use chain_core::ErrorModel;

use super::{all_met, component_summaries, evaluate, step_std};
use super::{AllocateError, Allocation, ErrorBounds, Paper, Step};
use crate::form::Form;
use crate::study::Study;

/// The paper's procedure (Tables 5-7).
pub fn paper<M: ErrorModel + ?Sized>(
    model: &M,
    parameters: &[f64],
    study: &Study,
    bounds: &[ErrorBounds],
    options: &Paper,
) -> Result<Allocation, AllocateError> {
    if study.spec().requirement.is_none() {
        return Err(AllocateError::NoRequirement);
    }
    if !(options.step > 0.0 && options.step.is_finite()) {
        return Err(AllocateError::Unsupported(format!(
            "the step must be positive (found {})",
            options.step
        )));
    }
    let mut stds: Vec<f64> = bounds.iter().map(|b| b.std0).collect();
    let (mut current, result) = evaluate(model, parameters, study, &stds)?;
    let initial = component_summaries(&result);
    let mut summaries = initial.clone();
    let mut steps = Vec::new();
    let form = Form::default();
    let mut round = 0;
    while !all_met(&summaries) && round < options.max_rounds {
        round += 1;
        let sens = current.sensitivity_mean(&form)?;
        let unmet: Vec<crate::Target> = summaries
            .iter()
            .filter(|s| s.met == Some(false))
            .map(|s| s.target)
            .collect();
        let n = stds.len();
        // Per-error score lists, one per ranking group.
        let mut groups: Vec<(String, Vec<f64>)> = Vec::new();
        for t in sens.iter().filter(|t| unmet.contains(&t.target)) {
            let mut score = vec![0.0; n];
            for e in &t.errors {
                if let Some(j) = bounds.iter().position(|b| b.error == e.error) {
                    score[j] = e.mean_abs_dr_dstd;
                }
            }
            if options.pooled {
                match groups.first_mut() {
                    Some((name, g)) => {
                        name.push('+');
                        name.push_str(t.target.name());
                        for (a, b) in g.iter_mut().zip(&score) {
                            *a += b;
                        }
                    }
                    None => groups.push((t.target.to_string(), score)),
                }
            } else {
                groups.push((t.target.to_string(), score));
            }
        }
        let mut chosen = vec![false; n];
        for (name, score) in &groups {
            // Only errors that can still be tightened compete.
            let can = |j: usize| stds[j] > bounds[j].min_std * (1.0 + 1e-12) && stds[j] > 0.0;
            let max = (0..n)
                .filter(|&j| can(j))
                .map(|j| score[j])
                .fold(0.0, f64::max);
            if max <= 0.0 {
                let mut ranked: Vec<usize> = (0..n).filter(|&j| score[j] > 0.0).collect();
                ranked.sort_by(|&a, &b| score[b].total_cmp(&score[a]));
                return Err(AllocateError::Stalled {
                    round: round - 1,
                    component: name.clone(),
                    errors: ranked.iter().map(|&j| bounds[j].error.clone()).collect(),
                });
            }
            for j in 0..n {
                if can(j) && score[j] >= options.threshold * max {
                    chosen[j] = true;
                }
            }
        }
        let mut tightened = Vec::new();
        let mut changed = Vec::new();
        for j in 0..n {
            if !chosen[j] {
                continue;
            }
            let d = step_std(bounds[j].kind, options.step);
            let mut s = (stds[j] - d).max(bounds[j].min_std);
            if s <= 0.0 {
                // Never to zero: halve what is left instead.
                s = 0.5 * stds[j];
            }
            stds[j] = s;
            tightened.push(bounds[j].error.clone());
            changed.push((bounds[j].error.clone(), s));
        }
        let (next, result) = evaluate(model, parameters, study, &stds)?;
        current = next;
        summaries = component_summaries(&result);
        steps.push(Step {
            round,
            tightened,
            std: changed,
            summaries: summaries.clone(),
        });
    }
    Ok(Allocation::new(
        super::StrategyName::Paper,
        initial,
        steps,
        bounds,
        &stds,
        summaries,
        None,
    ))
}
