//! The table and CSV of `chain path` ([`PathDocument`]): one row per
//! instant, the error statistics and the reliabilities, then the summary.

use chain::ops::path::PathDocument;
use chain_core::inverse::Status;
use reliability::{FormCase, PathInstant, Quantity};

use crate::cli::report::{self, Csv, Report};
use crate::cli::study_text::{calls_text, requirement_text, sided_title};

impl Report for PathDocument {
    fn table(&self) -> String {
        to_table(self)
    }

    fn csv(&self, out: &mut Csv<'_>) -> Option<()> {
        let r = &self.result;
        let sampled = r.cases().any(|c| c.std_error.is_some());
        let names: Vec<&str> = r.targets.iter().map(|t| t.target.name()).collect();
        let mut header = vec!["row".to_string(), "t".to_string()];
        header.extend(self.variables.iter().cloned());
        header.push("status".into());
        header.extend(["nominal_x", "nominal_y", "nominal_z"].map(String::from));
        header.extend(Quantity::ALL.iter().map(|q| format!("mean_{q}")));
        header.extend(Quantity::ALL.iter().map(|q| format!("std_{q}")));
        header.extend(names.iter().map(|t| format!("reliability_{t}")));
        if sampled {
            header.extend(names.iter().map(|t| format!("std_error_{t}")));
        }
        for key in [
            "termination",
            "converged",
            "iterations",
            "value_calls",
            "gradient_calls",
        ] {
            header.extend(names.iter().map(|t| format!("{key}_{t}")));
        }
        let width = header.len();
        out.header(header);
        for rec in &r.records {
            let i = &rec.instant;
            let mut row = vec![i.row.to_string(), format!("{:?}", i.t)];
            match &i.axes {
                Some(q) => row.extend(q.iter().map(|x| format!("{x:?}"))),
                None => row.extend(self.variables.iter().map(|_| String::new())),
            }
            row.push(i.status.name().into());
            if let Some(e) = &rec.result {
                row.extend(e.nominal.iter().map(|x| format!("{x:?}")));
                row.extend(Quantity::ALL.iter().map(|&q| format!("{:?}", e.mean(q))));
                row.extend(Quantity::ALL.iter().map(|&q| format!("{:?}", e.std(q))));
                row.extend(r.cases_of(e).map(|c| format!("{:?}", c.reliability)));
                if sampled {
                    match r
                        .cases_of(e)
                        .map(|c| c.std_error)
                        .collect::<Option<Vec<_>>>()
                    {
                        Some(se) => row.extend(se.iter().map(|x| format!("{x:?}"))),
                        None => row.extend(names.iter().map(|_| String::new())),
                    }
                }
                let form = |f: fn(&FormCase) -> String| {
                    r.cases_of(e)
                        .map(move |c| c.form.as_ref().map(f).unwrap_or_default())
                };
                row.extend(form(|f| f.termination.to_string()));
                row.extend(form(|f| f.converged.to_string()));
                row.extend(form(|f| f.iterations.to_string()));
                row.extend(r.cases_of(e).map(|c| c.calls.values.to_string()));
                row.extend(r.cases_of(e).map(|c| c.calls.gradients.to_string()));
            }
            row.resize(width, String::new());
            out.row(row);
        }
        Some(())
    }
}

/// A compact number for the table: integers as such, others with up to six
/// decimals.
fn num(v: f64) -> String {
    match report::whole(v) {
        Some(i) => i.to_string(),
        None => {
            let s = format!("{v:.6}");
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        }
    }
}

/// Four significant digits in scientific notation; zero as `0`.
fn sci(v: f64) -> String {
    if v == 0.0 {
        "0".to_string()
    } else {
        format!("{v:.3e}")
    }
}

fn at_text(i: &PathInstant, has_t: bool) -> String {
    if has_t {
        format!("row {} (t = {})", i.row, num(i.t))
    } else {
        format!("row {}", i.row)
    }
}

/// `|p|` for the volumetric quantity, the component's name otherwise.
pub(crate) fn label(q: Quantity) -> &'static str {
    match q {
        Quantity::Volumetric => "|p|",
        Quantity::Component(c) => c.name(),
    }
}

fn to_table(doc: &PathDocument) -> String {
    use std::fmt::Write as _;
    let r = &doc.result;
    let mut out = String::new();
    let sided = sided_title(r.sided);
    let _ = writeln!(
        out,
        "{}: error and reliability along a path ({} instants from {}, {}, {sided}, frame {})",
        doc.machine,
        r.records.len(),
        doc.source,
        r.method.title(),
        doc.frame
    );
    let tol: Vec<String> = r
        .targets
        .iter()
        .filter_map(|t| t.tolerance.map(|v| format!("{} {}", t.target, num(v))))
        .collect();
    let _ = writeln!(out, "tolerances: {}", tol.join(", "));
    // Which error quantities to show: the toleranced components and |p|.
    let shown: Vec<Quantity> = Quantity::ALL
        .iter()
        .copied()
        .filter(|q| *q == Quantity::Volumetric || doc.targets().any(|t| t.name() == q.name()))
        .collect();
    let _ = writeln!(
        out,
        "\nmean and standard deviation of the error (lengths in the file's unit, angles in rad)"
    );
    let _ = write!(out, "{:>5} {:>10}", "row", if doc.has_t { "t" } else { "" });
    for v in &doc.variables {
        let _ = write!(out, " {v:>10}");
    }
    let _ = write!(out, "  {:<11}", "status");
    for &q in &shown {
        let _ = write!(out, " {:>11} {:>10}", format!("{} mean", label(q)), "std");
    }
    out.push('\n');
    for rec in &r.records {
        let i = &rec.instant;
        let t = if doc.has_t { num(i.t) } else { String::new() };
        let _ = write!(out, "{:>5} {t:>10}", i.row);
        match &i.axes {
            Some(q) => q.iter().for_each(|x| {
                let _ = write!(out, " {:>10}", num(*x));
            }),
            None => doc.variables.iter().for_each(|_| {
                let _ = write!(out, " {:>10}", "-");
            }),
        }
        let _ = write!(out, "  {:<11}", i.status.name());
        if let Some(e) = &rec.result {
            for &q in &shown {
                let _ = write!(out, " {:>11} {:>10}", sci(e.mean(q)), sci(e.std(q)));
            }
        }
        out.push('\n');
    }
    let _ = writeln!(out, "\nreliability (%)");
    let _ = write!(out, "{:>5} {:>10}", "row", if doc.has_t { "t" } else { "" });
    for t in doc.targets() {
        let _ = write!(out, " {:>10}", t.name());
    }
    out.push('\n');
    let mut bad = Vec::new();
    for rec in &r.records {
        let i = &rec.instant;
        let t = if doc.has_t { num(i.t) } else { String::new() };
        let _ = write!(out, "{:>5} {t:>10}", i.row);
        match &rec.result {
            Some(e) => r.cases_of(e).for_each(|c| {
                let _ = write!(out, " {:>10.3}", 100.0 * c.reliability);
                if !c.converged() {
                    bad.push(format!("{} at {}", c.target, at_text(i, doc.has_t)));
                }
            }),
            None => {
                let _ = write!(out, " {}", i.status.name());
            }
        }
        out.push('\n');
    }
    if !bad.is_empty() {
        let _ = writeln!(
            out,
            "* FORM stopped at the iteration limit (the value shown is the last iterate's, not a converged reliability): {}",
            bad.join(", ")
        );
    }
    let _ = writeln!(
        out,
        "\nsummary over {} instants ({} evaluated, {} unreachable, {} singular)",
        r.records.len(),
        r.evaluated(),
        r.count(Status::Unreachable),
        r.count(Status::Singular)
    );
    for (t, target) in doc.targets().enumerate() {
        if let Some(s) = r.summary(t) {
            let worst = &r.records[s.min.record].instant;
            let _ = write!(
                out,
                "  {:<10} reliability min {:.3} % at {}, mean {:.3} %",
                target.name(),
                100.0 * s.min.value,
                at_text(worst, doc.has_t),
                100.0 * s.mean
            );
            if let (Some(req), Some(met)) = (r.requirement(), s.met) {
                out.push_str(&requirement_text(&req, met));
            }
            out.push('\n');
        }
    }
    for &q in &shown {
        if let (Some(m), Some(s)) = (r.max_mean(q), r.max_std(q)) {
            let what = if q == Quantity::Volumetric {
                "max mean"
            } else {
                "max |mean|"
            };
            let _ = writeln!(
                out,
                "  {:<10} {what} {} at {}, max std {} at {}",
                label(q),
                sci(m.value),
                at_text(&r.records[m.record].instant, doc.has_t),
                sci(s.value),
                at_text(&r.records[s.record].instant, doc.has_t)
            );
        }
    }
    if let Some(se) = r.cases().filter_map(|c| c.std_error).reduce(f64::max) {
        let _ = writeln!(out, "  sampling: largest standard error of p_f {se:.2e}");
    }
    if r.evaluated() > 0 {
        let _ = writeln!(out, "  {}", calls_text(r.cases(), r.method));
    }
    out
}
