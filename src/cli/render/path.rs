//! The table and CSV of `chain path` ([`PathOutput`]): one row per instant
//! (the error statistics and the reliabilities), then the summary. Both are
//! written a block of records at a time as the path runs; the
//! JSON is the output's own `Serialize` (`chain::ops::path`).

use std::io::{self, Write};

use chain::ops::path::{PathHead, PathOutput};
use chain::ops::views::quantity_label;
use reliability::{Extreme, FormCase, PathSummary, Quantity};

use crate::cli::report::{self, Csv, Report};
use crate::cli::study_text::{calls_text, requirement_text, sided_title};

impl Report for PathOutput<'_> {
    fn table(&self) -> String {
        let mut out = Vec::new();
        // Writing into a vector fails only when the run does (kept in the
        // output for the command to report).
        let _ = self.write_table(&mut out);
        String::from_utf8_lossy(&out).into_owned()
    }

    fn write_table(&self, out: &mut dyn Write) -> io::Result<()> {
        write_table(self, out)
    }

    fn csv(&self, out: &mut Csv<'_>) -> Option<()> {
        let h = self.head;
        let names: Vec<&str> = h.targets.iter().map(|t| t.target.name()).collect();
        let mut header = vec!["row".to_string(), "t".to_string()];
        header.extend(h.variables.iter().cloned());
        header.push("status".into());
        header.extend(["nominal_x", "nominal_y", "nominal_z"].map(String::from));
        header.extend(Quantity::ALL.iter().map(|q| format!("mean_{q}")));
        header.extend(Quantity::ALL.iter().map(|q| format!("std_{q}")));
        header.extend(names.iter().map(|t| format!("reliability_{t}")));
        if h.sampled {
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
        // The Csv writer keeps its own first write error; a failed run is
        // kept in the output for the command to report.
        let _ = self.each_block(
            |r, _| {
                for rec in &r.records {
                    let i = &rec.instant;
                    let mut row = vec![i.row.to_string(), format!("{:?}", i.t)];
                    match &i.axes {
                        Some(q) => row.extend(q.iter().map(|x| format!("{x:?}"))),
                        None => row.extend(h.variables.iter().map(|_| String::new())),
                    }
                    row.push(i.status.name().into());
                    if let Some(e) = &rec.result {
                        row.extend(e.nominal.iter().map(|x| format!("{x:?}")));
                        row.extend(Quantity::ALL.iter().map(|&q| format!("{:?}", e.mean(q))));
                        row.extend(Quantity::ALL.iter().map(|&q| format!("{:?}", e.std(q))));
                        row.extend(r.cases_of(e).map(|c| format!("{:?}", c.reliability)));
                        if h.sampled {
                            match (r.cases_of(e))
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
                Ok::<(), ()>(())
            },
            |_| (),
        );
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

/// `row 7 (t = 0.35)`, or `row 7` when the input gave no `t`.
fn at_text(row: usize, t: f64, has_t: bool) -> String {
    if has_t {
        format!("row {row} (t = {})", num(t))
    } else {
        format!("row {row}")
    }
}

fn extreme_text(e: &Extreme, has_t: bool) -> String {
    at_text(e.row, e.t, has_t)
}

/// The table: title, tolerances, one row per instant (axis values, status,
/// mean and std of the toleranced components and `|p|`, the reliability of
/// every target), the cases FORM left at its iteration limit, the summary.
fn write_table(output: &PathOutput<'_>, out: &mut dyn Write) -> io::Result<()> {
    let h: &PathHead = output.head;
    let sided = sided_title(h.sided);
    writeln!(
        out,
        "{}: error and reliability along a path ({} instants from {}, {}, {sided}, frame {})",
        h.machine,
        h.instants,
        h.source,
        h.method.title(),
        h.frame
    )?;
    let tol: Vec<String> = (h.targets.iter())
        .filter_map(|t| t.tolerance.map(|v| format!("{} {}", t.target, num(v))))
        .collect();
    writeln!(out, "tolerances: {}", tol.join(", "))?;
    // Which error quantities to show: the toleranced components and |p|.
    let shown: Vec<Quantity> = (Quantity::ALL.iter().copied())
        .filter(|q| *q == Quantity::Volumetric || h.target_names().any(|t| t.name() == q.name()))
        .collect();
    writeln!(
        out,
        "\nmean and standard deviation of the error (lengths in the file's unit, angles in rad) and reliability (%)"
    )?;
    write!(out, "{:>5} {:>10}", "row", if h.has_t { "t" } else { "" })?;
    for v in &h.variables {
        write!(out, " {v:>10}")?;
    }
    write!(out, "  {:<11}", "status")?;
    for &q in &shown {
        write!(
            out,
            " {:>11} {:>10}",
            format!("{} mean", quantity_label(q)),
            "std"
        )?;
    }
    for t in h.target_names() {
        write!(out, " {:>10}", t.name())?;
    }
    writeln!(out)?;
    let mut bad = Vec::new();
    output.each_block(
        |r, _| {
            for rec in &r.records {
                let i = &rec.instant;
                let t = if h.has_t { num(i.t) } else { String::new() };
                write!(out, "{:>5} {t:>10}", i.row)?;
                match &i.axes {
                    Some(q) => q.iter().try_for_each(|x| write!(out, " {:>10}", num(*x)))?,
                    None => (h.variables.iter()).try_for_each(|_| write!(out, " {:>10}", "-"))?,
                }
                write!(out, "  {:<11}", i.status.name())?;
                if let Some(e) = &rec.result {
                    for &q in &shown {
                        write!(out, " {:>11} {:>10}", sci(e.mean(q)), sci(e.std(q)))?;
                    }
                    for c in r.cases_of(e) {
                        write!(out, " {:>10.3}", 100.0 * c.reliability)?;
                        if !c.converged() {
                            bad.push(format!("{} at {}", c.target, at_text(i.row, i.t, h.has_t)));
                        }
                    }
                }
                writeln!(out)?;
            }
            Ok(())
        },
        |e| io::Error::other(e.to_string()),
    )?;
    if !bad.is_empty() {
        writeln!(
            out,
            "* FORM stopped at the iteration limit (the value shown is the last iterate's, not a converged reliability): {}",
            bad.join(", ")
        )?;
    }
    let s = output
        .summary()
        .ok_or_else(|| io::Error::other("the path's summary before its records"))?;
    write_summary(h, &s, &shown, out)
}

/// The summary lines of the table.
fn write_summary(
    h: &PathHead,
    s: &PathSummary,
    shown: &[Quantity],
    out: &mut dyn Write,
) -> io::Result<()> {
    writeln!(
        out,
        "\nsummary over {} instants ({} evaluated, {} unreachable, {} singular)",
        s.instants, s.evaluated, s.unreachable, s.singular
    )?;
    for (t, target) in h.target_names().enumerate() {
        if let Some(ts) = s.target(t) {
            write!(
                out,
                "  {:<10} reliability min {:.3} % at {}, mean {:.3} %",
                target.name(),
                100.0 * ts.min.value,
                extreme_text(&ts.min, h.has_t),
                100.0 * ts.mean
            )?;
            if let (Some(req), Some(met)) = (s.requirement(), ts.met) {
                out.write_all(requirement_text(&req, met).as_bytes())?;
            }
            writeln!(out)?;
        }
    }
    for &q in shown {
        if let (Some(m), Some(sd)) = (s.max_mean(q), s.max_std(q)) {
            let what = if q == Quantity::Volumetric {
                "max mean"
            } else {
                "max |mean|"
            };
            writeln!(
                out,
                "  {:<10} {what} {} at {}, max std {} at {}",
                quantity_label(q),
                sci(m.value),
                extreme_text(&m, h.has_t),
                sci(sd.value),
                extreme_text(&sd, h.has_t)
            )?;
        }
    }
    if let Some(se) = s.tally.max_std_error {
        writeln!(out, "  sampling: largest standard error of p_f {se:.2e}")?;
    }
    if s.evaluated > 0 {
        writeln!(out, "  {}", calls_text(&s.tally, h.method))?;
    }
    Ok(())
}
