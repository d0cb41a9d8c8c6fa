//! How a study's results read in words, shared by the commands that run
//! studies (`reliability`, `sensitivity`, `path`): the posterior's
//! listing, the line on how FORM ended and what the cases cost, the sides'
//! names and the requirement's line. The warnings on cases that did not
//! converge are `chain::ops::study::unconverged_warnings`; the per-target
//! maps the tables and the plots show are `chain::ops::views::target_map`.

use chain_core::model::Sided;
use reliability::{CaseTally, Method, Posterior};

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
