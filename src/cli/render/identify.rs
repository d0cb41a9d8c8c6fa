//! The table of `chain identify` ([`IdentifyRun`]): the estimates, what
//! the data cannot separate (in words), the residuals and the likely
//! outliers, and the prediction at held-out measurements (`--validate`).

use std::fmt::Write as _;

use chain::ops::identify::{IdentifyDocument, IdentifyRun};

use crate::cli::report::Report;

impl Report for IdentifyRun {
    fn table(&self) -> String {
        table(&self.document)
    }
}

/// `v` for a table: 4 significant digits.
fn num(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else if !v.is_finite() {
        "—".into()
    } else if (1e-3..1e5).contains(&v.abs()) {
        format!("{v:.6}")
            .trim_end_matches('0')
            .trim_end_matches('.')
            .to_string()
    } else {
        format!("{v:.4e}")
    }
}

fn table(d: &IdentifyDocument) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "machine {}: {} measurements ({} rows) from {}, frame {}{}",
        d.machine,
        d.measurements,
        d.rows,
        d.file,
        d.frame,
        if d.weighted {
            ", weighted by std"
        } else {
            ", equal weights"
        }
    );
    let _ = writeln!(
        s,
        "{} unknowns, rank {}, condition {}{}{}",
        d.parameters,
        d.rank,
        num(d.condition),
        if d.noise.weak > 0 {
            format!(
                " ({} structurally; {} weakly determined direction{} left out by the noise rule)",
                d.noise.structural_rank,
                d.noise.weak,
                if d.noise.weak == 1 { "" } else { "s" }
            )
        } else {
            String::new()
        },
        if d.prior {
            "; posterior with the statistics prior"
        } else {
            ""
        }
    );
    // The set-ups' unknowns are listed with their set-up below.
    let setup_unknowns: Vec<String> = (d.setups.iter()).flat_map(|u| u.unknowns.clone()).collect();
    let machine_error = |name: &String| !setup_unknowns.contains(name);
    let width = d
        .estimates
        .0
        .iter()
        .map(|(n, _)| n.len())
        .max()
        .unwrap_or(5)
        .max(5);
    let _ = writeln!(s, "\n{:<width$}  {:>14}  {:>14}", "error", "value", "std");
    match &d.subset {
        Some(sub) => {
            // With --iterate the values are the exact fit's.
            let values = d
                .iteration
                .as_ref()
                .map_or(&sub.estimates, |it| &it.estimates);
            for (name, e) in values.0.iter().filter(|(n, _)| machine_error(n)) {
                let std = e.std.map_or("—".to_string(), num);
                let note = match sub.fixed.iter().find(|f| &f.error == name) {
                    Some(f) => format!("  fixed, {}: {}", f.status.words(), f.words),
                    None => match sub.combination_words(name) {
                        Some(w) => format!("  estimated, stands for {w}"),
                        None => "  estimated".to_string(),
                    },
                };
                let _ = writeln!(s, "{name:<width$}  {:>14}  {std:>14}{note}", num(e.value));
            }
            if !sub.fixed.is_empty() {
                let _ = writeln!(
                    s,
                    "(least squares on {} of {} with the fixed ones at 0{}; relation weights below {} of a parameter's effect left out; JSON `estimates`: the minimum-norm solution)",
                    sub.estimated.len(),
                    d.parameters,
                    match sub.chosen_by {
                        chain_core::measured::ChosenBy::Elimination => ", chosen by a column-pivoted QR",
                        chain_core::measured::ChosenBy::Fix => ", as --fix chose",
                        chain_core::measured::ChosenBy::Estimate => ", as --estimate chose",
                    },
                    sub.term_cutoff
                );
            }
        }
        None => {
            for (name, e) in d.estimates.0.iter().filter(|(n, _)| machine_error(n)) {
                let std = e.std.map_or("—".to_string(), num);
                let _ = writeln!(s, "{name:<width$}  {:>14}  {std:>14}", num(e.value));
            }
        }
    }
    if !d.setups.is_empty() {
        let _ = writeln!(
            s,
            "
set-ups estimated beside the errors (workpiece frame, mm; not written into values):"
        );
        for u in &d.setups {
            let coords: Vec<String> = (u.coordinates.iter().enumerate())
                .map(|(l, c)| {
                    let std = u.std[l].map_or("—".to_string(), num);
                    format!("{c} = {} ± {std}", num(u.position[l]))
                })
                .collect();
            let label = match u.kind {
                chain_core::measured::SetupKind::Sphere => format!("sphere {}", u.name),
                chain_core::measured::SetupKind::Ball => u.name.clone(),
                chain_core::measured::SetupKind::Circle => format!("circle {}", u.name),
            };
            let _ = writeln!(s, "  {label}: {}", coords.join(", "));
        }
    }
    if !d.groups.is_empty() {
        let _ = writeln!(
            s,
            "\n{}",
            if d.prior {
                "not informed by the data:"
            } else {
                "cannot be separated by these measurements (JSON `unidentifiable`: an orthonormal basis):"
            }
        );
        for g in &d.groups {
            let _ = writeln!(s, "  - {}", g.explanation);
        }
    }
    let _ = writeln!(
        s,
        "\nresidual: rms {}, max {}, {} degrees of freedom{}",
        num(d.residual.rms),
        num(d.residual.max),
        d.residual.dof,
        match (d.weighted, d.residual.scale) {
            (true, Some(k)) => format!(", scatter / stated std = {}", num(k)),
            (false, Some(k)) => format!(", noise estimate s = {}", num(k)),
            _ => String::new(),
        }
    );
    let _ = writeln!(s, "first order: {}", d.first_order.words);
    if let Some(it) = &d.iteration {
        let _ = writeln!(
            s,
            "--iterate: {} Levenberg–Marquardt iterations{}, weighted residual sum of squares {} → {}; residual rms {}, max {} (the estimates above are the exact fit's)",
            it.iterations,
            if it.converged { ", converged" } else { ", not converged" },
            num(it.rss_linear),
            num(it.rss),
            num(it.rms),
            num(it.max)
        );
    }
    if !d.largest_residuals.is_empty() {
        let _ = writeln!(
            s,
            "largest standardised residuals (|t| > {} flagged as a likely outlier): {} flagged",
            chain_core::measured::identify::OUTLIER_LIMIT,
            d.outliers
        );
        for r in d.largest_residuals.iter().take(5) {
            let _ = writeln!(
                s,
                "  line {:>6} {:<3}  r = {:>12}  t = {:>8.3}{}",
                r.line,
                r.component,
                num(r.residual),
                r.standardised,
                if r.outlier { "  likely outlier" } else { "" }
            );
        }
    }
    if let Some(v) = &d.validation {
        let p = &v.prediction;
        let _ = writeln!(
            s,
            "\nprediction at {} ({} measurements held out of the fit, {} rows):",
            v.file, p.measurements, p.rows
        );
        for (label, e) in [("before", &p.before), ("after", &p.after)] {
            let _ = writeln!(
                s,
                "  {label:<6} mean |error| {}, max {}, rms {}",
                num(e.mean),
                num(e.max),
                num(e.rms)
            );
        }
    }
    s
}
