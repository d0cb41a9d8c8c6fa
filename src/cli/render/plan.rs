//! The table of `chain plan` ([`PlanDocument`]): the chosen candidates
//! and the std per parameter, optimal against even.

use chain::ops::plan::PlanDocument;
use chain_core::plan::Kind;

use crate::cli::report::{self, Report};

impl Report for PlanDocument {
    fn table(&self) -> String {
        use std::fmt::Write;
        let p = &self.plan;
        let mut out = String::new();
        let _ = writeln!(
            out,
            "Measurement plan for {}: {} of the {} candidates of {} ({} measurements)",
            self.machine,
            p.count,
            p.candidates,
            self.candidates_file,
            match self.kind {
                Kind::Point => "tool-point px, py, pz",
                Kind::Direction => "1-D, along each candidate's direction",
            }
        );
        let aliased = p.aliased.iter().filter(|&&a| a).count();
        let _ = writeln!(
            out,
            "identifiable: rank {} of {} error parameters{}",
            p.rank,
            p.errors.len(),
            if aliased == 0 {
                String::new()
            } else {
                format!(
                    "; {aliased} act only together with others (marked *; their std is that of the minimum-norm estimate)"
                )
            }
        );
        let ld = |x: Option<f64>| x.map_or("-inf (singular)".to_string(), |v| format!("{v:.4}"));
        let _ = writeln!(
            out,
            "ln det on the identifiable subspace: D-optimal {}, even spread {}",
            ld(p.optimal.log_det),
            ld(p.even.log_det)
        );
        if let (Some(a), Some(b)) = (p.optimal.log_det, p.even.log_det) {
            let _ = writeln!(
                out,
                "D-efficiency of the even spread: {:.4} (det ratio^(1/rank))",
                ((b - a) / p.rank as f64).exp()
            );
        }
        let _ = writeln!(
            out,
            "exchange: {} swaps in {} sweeps after the greedy start",
            p.swaps, p.sweeps
        );
        let _ = writeln!(out);
        let _ = writeln!(
            out,
            "expected std {}:\n{:<14} {:>14} {:>14} {:>8}",
            if p.weighted {
                "(the candidates' std column: in the errors' units)"
            } else {
                "per unit measurement std"
            },
            "parameter",
            "D-optimal",
            "even",
            "ratio"
        );
        for (j, e) in p.errors.iter().enumerate() {
            let (a, b) = (p.optimal.std[j], p.even.std[j]);
            let f = |x: Option<f64>| x.map_or("-".to_string(), |v| format!("{v:.4e}"));
            let ratio = match (a, b) {
                (Some(a), Some(b)) if a > 0.0 => format!("{:.3}", b / a),
                _ => "-".into(),
            };
            let mark = if p.aliased[j] { "*" } else { "" };
            let _ = writeln!(
                out,
                "{:<14} {:>14} {:>14} {:>8}",
                format!("{e}{mark}"),
                f(a),
                f(b),
                ratio
            );
        }
        let _ = writeln!(out);
        let _ = writeln!(out, "chosen candidates (line of {}):", self.candidates_file);
        let header: Vec<String> = std::iter::once("line".to_string())
            .chain(self.variables.iter().cloned())
            .collect();
        let _ = writeln!(
            out,
            "{}",
            header
                .iter()
                .map(|h| format!("{h:>12}"))
                .collect::<Vec<_>>()
                .join(" ")
        );
        for &i in &p.optimal.candidates {
            let mut cells = vec![format!("{:>12}", self.lines[i])];
            cells.extend(self.poses[i].iter().map(|x| format!("{:>12}", number(*x))));
            let _ = writeln!(out, "{}", cells.join(" "));
        }
        out
    }
}

fn number(x: f64) -> String {
    match report::whole(x) {
        Some(i) => i.to_string(),
        None => format!("{x:.6}"),
    }
}
