//! How a study's results read in words, shared by the commands that run
//! studies (`reliability`, `sensitivity`, `path`): the posterior's
//! listing, the per-target maps the plots draw, the line on how FORM ended
//! and what the cases cost, the sides' names and the requirement's line.
//! The warnings on cases that did not converge are
//! `chain::ops::study::unconverged_warnings`.

use chain_core::model::Sided;
use reliability::{CaseTally, Method, Posterior, Study, StudyResult};

use super::report;

/// The lines saying which inputs come from a posterior (before the table).
pub(crate) fn posterior_lines(p: &Posterior) -> String {
    let with_std = p.values.iter().filter(|v| v.std.is_some()).count();
    let mut out = format!(
        "posterior: {} ({} errors given, {with_std} with std, {} correlations{}; the others from `statistics`)\n",
        p.file.as_deref().unwrap_or("values"),
        p.values.len(),
        p.correlations.len(),
        match p.tables.len() {
            0 => String::new(),
            n => format!(", {n} table{}", if n == 1 { "" } else { "s" }),
        }
    );
    for v in &p.values {
        match v.std {
            Some(s) => out.push_str(&format!(
                "  {:<12} mean {:>12} std {}\n",
                v.name,
                fmt_num(v.mean),
                fmt_num(s)
            )),
            None => out.push_str(&format!(
                "  {:<12} mean {:>12} (statistics spread)\n",
                v.name,
                fmt_num(v.mean)
            )),
        }
    }
    for c in &p.correlations {
        out.push_str(&format!("  rho({}, {}) = {}\n", c.a, c.b, fmt_num(c.rho)));
    }
    for t in p.table_inputs() {
        out.push_str(&format!(
            "  {:<12} table along {} (approach {}): {}\n",
            t.name,
            t.variable,
            t.approach,
            if t.repeatability {
                "normal, the table's mean and repeatability at each point"
            } else {
                "its statistics spread about the table's value at each point"
            }
        ));
    }
    out.push('\n');
    out
}

/// One target's reliabilities as maps over the two grid axes it varies along
/// (further varying axes give one map per value), like Tables 2-4.
pub(crate) struct TargetMap {
    /// Row axis (name, values) and column axis, if the target varies along them.
    pub(crate) rows: Option<(String, Vec<f64>)>,
    pub(crate) cols: Option<(String, Vec<f64>)>,
    /// One map per combination of the other varying axes: (label, values[row][col]).
    pub(crate) maps: Vec<(String, Vec<Vec<f64>>)>,
    /// Parallel to `maps`: true where FORM did not converge.
    pub(crate) unconverged: Vec<Vec<Vec<bool>>>,
}

/// Builds the maps of target `t` from a study result.
pub(crate) fn target_map(study: &Study, r: &StudyResult, t: usize) -> TargetMap {
    let grid = &study.spec().grid;
    let np = study.points().len();
    let cases = r.target_cases(t);
    let dims: Vec<usize> = grid.axes.iter().map(|(_, v)| v.len()).collect();
    // Axes along which the limit state changes (decided on the model, not on
    // sampled values, which are noisy).
    let target = study.targets()[t];
    let varying: Vec<usize> = (0..dims.len())
        .filter(|&a| {
            (0..np).any(|p| {
                let mut idx = grid.index(p);
                if idx[a] == 0 {
                    return false;
                }
                idx[a] = 0;
                let q = flat(&idx, &dims);
                match (study.limit_state(target, p), study.limit_state(target, q)) {
                    (Ok(g1), Ok(g2)) => g1 != g2,
                    _ => true,
                }
            })
        })
        .collect();
    let row_axis = varying.first().copied();
    let col_axis = varying.get(1).copied();
    let others: Vec<usize> = varying.iter().skip(2).copied().collect();
    let len = |a: Option<usize>| a.map_or(1, |a| dims[a]);
    let other_count: usize = others.iter().map(|&a| dims[a]).product();
    let mut maps = Vec::new();
    let mut unconverged = Vec::new();
    for o in 0..other_count.max(1) {
        let mut idx = vec![0; dims.len()];
        let mut rest = o;
        let mut label = Vec::new();
        for &a in others.iter().rev() {
            idx[a] = rest % dims[a];
            rest /= dims[a];
        }
        for &a in &others {
            label.push(format!("{} = {}", grid.axes[a].0, grid.axes[a].1[idx[a]]));
        }
        let mut m = vec![vec![0.0; len(col_axis)]; len(row_axis)];
        let mut u = vec![vec![false; len(col_axis)]; len(row_axis)];
        for (i, (row, urow)) in m.iter_mut().zip(&mut u).enumerate() {
            for (j, (cell, ucell)) in row.iter_mut().zip(urow.iter_mut()).enumerate() {
                if let Some(a) = row_axis {
                    idx[a] = i;
                }
                if let Some(a) = col_axis {
                    idx[a] = j;
                }
                let case = &cases[flat(&idx, &dims)];
                *cell = case.reliability;
                *ucell = !case.converged();
            }
        }
        maps.push((label.join(", "), m));
        unconverged.push(u);
    }
    TargetMap {
        rows: row_axis.map(|a| grid.axes[a].clone()),
        cols: col_axis.map(|a| grid.axes[a].clone()),
        maps,
        unconverged,
    }
}

fn flat(idx: &[usize], dims: &[usize]) -> usize {
    idx.iter().zip(dims).fold(0, |acc, (i, d)| acc * d + i)
}

/// `closed form 45, converged 3` (the terminations that occur).
fn terminations_text(tally: &CaseTally) -> String {
    tally
        .terminations()
        .map(|(t, n)| format!("{} {n}", t.name().replace('_', " ")))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The table line on how FORM ended and what the cases cost: `FORM: 25 of
/// 25 cases converged (closed form 25); limit-state calls: 0 values, 0
/// gradients`.
pub(crate) fn calls_text(tally: &CaseTally, method: Method) -> String {
    let calls = format!(
        "limit-state calls: {} values, {} gradients",
        tally.calls.values, tally.calls.gradients
    );
    if tally.forms == 0 {
        return calls;
    }
    let what = match method {
        Method::Form => "FORM",
        Method::Sorm => "FORM (SORM's design points)",
        _ => "FORM (centring)",
    };
    format!(
        "{what}: {} of {} cases converged ({}); {calls}",
        tally.forms_converged,
        tally.forms,
        terminations_text(tally)
    )
}

/// `upper` or `two-sided`: how the tables name [`Sided`] (the JSON has
/// [`Sided::name`]).
pub(crate) fn sided_title(s: Sided) -> &'static str {
    match s {
        Sided::Upper => "upper",
        Sided::Two => "two-sided",
    }
}

pub(crate) fn fmt_num(v: f64) -> String {
    report::whole(v).map_or_else(|| v.to_string(), |i| i.to_string())
}

/// `; requirement min … %, mean … %: met` for the table summaries.
pub(crate) fn requirement_text(req: &chain_core::model::Requirement, met: bool) -> String {
    format!(
        "; requirement min {:.2} %, mean {:.2} %: {}",
        100.0 * req.min,
        100.0 * req.mean,
        if met { "met" } else { "NOT met" }
    )
}
