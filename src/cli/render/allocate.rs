//! The table of `chain allocate` ([`AllocationRun`]): rounds like Wang &
//! Yuan 2021's Tables 5-7, the changed tolerances, the cost and the KKT
//! check.

use chain::ops::allocate::AllocationRun;
use chain_core::model::Requirement;
use reliability::allocate::{self, Allocation, ErrorBounds};
use reliability::Summary;

use crate::cli::report::Report;

impl Report for AllocationRun {
    /// Rounds like Tables 5-7, the changed tolerances, the cost and the KKT check.
    fn table(&self) -> String {
        to_table(
            &self.machine,
            self.study.spec().requirement,
            &self.bounds,
            &self.result,
        )
    }
}

/// σ in Table 1's tolerance units (σ·6 mm, σ·6000 or σ·3000 for angles).
fn tolerance_units(b: &ErrorBounds, s: f64) -> f64 {
    s / allocate::step_std(b.kind, 1.0)
}

fn to_table(
    machine: &str,
    req: Option<Requirement>,
    bounds: &[ErrorBounds],
    r: &Allocation,
) -> String {
    use std::fmt::Write as _;
    let mut out = String::new();
    let req_text = req.map_or("none".to_string(), |q| {
        format!(
            "min ≥ {:.2} %, mean ≥ {:.2} %",
            q.min * 100.0,
            q.mean * 100.0
        )
    });
    let _ = writeln!(
        out,
        "{machine}: precision allocation ({}), requirement {req_text}",
        r.strategy
    );
    let line = |out: &mut String, label: &str, s: &[Summary]| {
        let cells: Vec<String> = s
            .iter()
            .map(|s| format!("{} {:6.2}/{:6.2}", s.target, s.mean * 100.0, s.min * 100.0))
            .collect();
        let _ = writeln!(out, "  {label:<8} {}", cells.join("   "));
    };
    let _ = writeln!(out, "\nmean/min reliability (%):");
    line(&mut out, "initial", &r.initial);
    for s in &r.steps {
        line(&mut out, &format!("round {}", s.round), &s.summaries);
        let _ = writeln!(out, "           tightened: {}", s.tightened.join(", "));
    }
    if r.strategy == reliability::allocate::StrategyName::Optimal {
        line(&mut out, "optimal", &r.summaries);
    }
    let _ = writeln!(
        out,
        "\n  {:<8} {:>13} {:>13} {:>10} {:>10} {:>8}",
        "error", "std0", "std", "tol0", "tol", "std0/std"
    );
    for (b, (_, s)) in bounds.iter().zip(&r.std) {
        if (s - b.std0).abs() <= 1e-15 * b.std0 {
            continue;
        }
        let _ = writeln!(
            out,
            "  {:<8} {:>13.6e} {:>13.6e} {:>10.5} {:>10.5} {:>8.4}",
            b.error,
            b.std0,
            s,
            tolerance_units(b, b.std0),
            tolerance_units(b, *s),
            b.std0 / s
        );
    }
    let _ = writeln!(
        out,
        "  (tol in Table 1's units: std·6 mm, std·6000 angular, std·3000 squareness; unlisted errors unchanged)"
    );
    let _ = writeln!(
        out,
        "\ncost Σ w (std0/std − 1) = {:.6}; requirement {}",
        r.cost,
        if r.met { "met" } else { "NOT met" }
    );
    if let Some(a) = &r.acceptance {
        let _ = writeln!(
            out,
            "whole-machine acceptance: {:.4} % → {:.4} % ± {:.4} % (level {:.4} %, {}; independent re-evaluation{}; {} evaluations)",
            a.initial * 100.0,
            a.probability * 100.0,
            a.std_error * 100.0,
            a.level * 100.0,
            if r.met { "reached" } else { "NOT reached" },
            if a.converged { "" } else { ", NOT CONVERGED" },
            a.evaluations
        );
    }
    if let Some(k) = &r.kkt {
        let _ = writeln!(
            out,
            "KKT ({}): stationarity {:.2e}, complementarity {:.2e}, feasibility {:.2e}, dual feasibility {:.2e} ({} Newton iterations)",
            if k.polished { "active-set Newton" } else { "barrier" },
            k.stationarity,
            k.complementarity,
            k.feasibility,
            k.dual_feasibility,
            k.iterations
        );
        for (n, l) in &k.active {
            let _ = writeln!(out, "  active: {n:<40} multiplier {l:.6}");
        }
    }
    out
}
