//! The table of `chain sensitivity` ([`SensitivityReport`]): one ranked
//! list per component, of the reliability sensitivities or the geometric
//! coefficients.

use chain::ops::sensitivity::{ReliabilitySensitivity, SensitivityDocument, SensitivityReport};
use chain::ops::views::{at_text, where_text};
use chain_core::geometric::{GeometricSensitivity, NominalSizes, Where};

use crate::cli::report::Report;
use crate::cli::study_text::posterior_lines;

impl Report for SensitivityReport {
    fn table(&self) -> String {
        match self {
            SensitivityReport::Reliability(r) => reliability_table(r),
            SensitivityReport::Geometric(g) => {
                geometric_table(&g.machine, &g.where_, &g.nominal, &g.result)
            }
        }
    }
}

fn reliability_table(r: &ReliabilitySensitivity) -> String {
    {
        use std::fmt::Write as _;
        let d = SensitivityDocument::new(&r.machine, r.at.clone(), &r.result, r.posterior.as_ref());
        let mut out = String::new();
        let where_ = match &d.at {
            Some(a) => at_text(&a.0),
            None => "mean over the reliability grid".to_string(),
        };
        let _ = writeln!(
            out,
            "{}: reliability sensitivity (Eq. 32-33), {where_}",
            d.machine
        );
        if let Some(p) = d.posterior {
            let _ = write!(out, "{}", posterior_lines(p));
            if !p.correlations.is_empty() {
                let _ = writeln!(
                    out,
                    "dR/dstd with the correlations held fixed; importance: Der Kiureghian's gamma^2 (docs/posterior.md)"
                );
            }
        }
        for t in d.result {
            let _ = writeln!(
                out,
                "\n{} ({}), sorted by |dR/dstd|:",
                t.target,
                t.method.name()
            );
            let _ = writeln!(
                out,
                "  {:<8} {:>14} {:>14} {:>11}",
                "error", "dR/dstd", "dR/dmean", "importance"
            );
            for e in &t.errors {
                let _ = writeln!(
                    out,
                    "  {:<8} {:>14.6e} {:>14.6e} {:>11.6}",
                    e.error, e.dr_dstd, e.dr_dmean, e.importance
                );
            }
        }
        out
    }
}

fn geometric_table(
    machine: &str,
    where_: &Where,
    nominal: &NominalSizes,
    r: &GeometricSensitivity,
) -> String {
    use std::fmt::Write as _;
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{machine}: geometric error sensitivity (seed 004 Eq. 5-6), {}",
        where_text(where_)
    );
    let _ = writeln!(
        out,
        "S = |dE/de|, C = S·e / sum(S·e); e = {} (linear), {:.6e} rad = {}° (angular), {:.6e} rad (squareness)",
        nominal.linear,
        nominal.angular,
        round(nominal.angular.to_degrees()),
        nominal.squareness
    );
    let grid = matches!(where_, Where::Grid(_));
    for c in &r.components {
        let shown: Vec<_> = c.ranked.iter().filter(|e| e.s > 0.0).collect();
        if shown.is_empty() {
            let _ = writeln!(
                out,
                "\n{}: no error acts in this direction",
                c.component.name()
            );
            continue;
        }
        let _ = writeln!(
            out,
            "\n{} (sum of S·e = {:.6e}), sorted by C:",
            c.component.name(),
            c.total
        );
        if grid {
            let _ = writeln!(
                out,
                "  {:>4} {:<10} {:>14} {:>9} {:>9} {:>9}",
                "rank", "error", "S (mean)", "C %", "min %", "max %"
            );
        } else {
            let _ = writeln!(
                out,
                "  {:>4} {:<10} {:>14} {:>9}",
                "rank", "error", "S", "C %"
            );
        }
        for (i, e) in shown.iter().enumerate() {
            if grid {
                let _ = writeln!(
                    out,
                    "  {:>4} {:<10} {:>14.6} {:>9.2} {:>9.2} {:>9.2}",
                    i + 1,
                    e.error,
                    e.s,
                    100.0 * e.c,
                    100.0 * e.c_min,
                    100.0 * e.c_max
                );
            } else {
                let _ = writeln!(
                    out,
                    "  {:>4} {:<10} {:>14.6} {:>9.2}",
                    i + 1,
                    e.error,
                    e.s,
                    100.0 * e.c
                );
            }
        }
        let zero = c.ranked.len() - shown.len();
        if zero > 0 {
            let _ = writeln!(out, "  ({zero} errors with S = 0 not listed)");
        }
    }
    out
}

/// Rounds to 10 significant digits (no float noise in printed degrees).
fn round(x: f64) -> f64 {
    format!("{x:.9e}").parse().unwrap_or(x)
}
