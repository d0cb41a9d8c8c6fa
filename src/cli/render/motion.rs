//! The table and CSV of `chain motion` ([`MotionDocument`]): the settings,
//! the laws, the equivalence check, the coefficients, the truncation errors
//! and the required order; the CSV is the exact motion.

use std::fmt::Write as _;

use chain::ops::motion::{unit, MotionDocument};
use chain_core::model::JointKind;
use chain_core::motion::Matching;

use crate::cli::report::{Csv, Report};

impl Report for MotionDocument {
    /// Settings, laws, the equivalence check, the coefficients, the
    /// truncation errors and the required order.
    fn table(&self) -> String {
        table(self)
    }

    /// The exact motion: `t,<CNC variables>`, one line per instant.
    fn csv(&self, out: &mut Csv<'_>) -> Option<()> {
        let run = &self.conversion;
        out.header(std::iter::once("t").chain(run.motion.variables().iter().map(String::as_str)));
        for (t, q) in run.times.iter().zip(&run.exact) {
            out.row(std::iter::once(t.to_string()).chain(q.iter().map(f64::to_string)));
        }
        Some(())
    }
}

fn sci(x: f64) -> String {
    format!("{x:.3e}")
}

fn table(doc: &MotionDocument) -> String {
    let run = &doc.conversion;
    let files = &doc.written;
    let m = &run.motion;
    let names = m.variables();
    let kinds = m.kinds();
    let n = run.order;
    let mut s = String::new();
    let (t0, t1) = m.interval();
    let _ = writeln!(
        s,
        "Motion conversion {} → {} (settings `{}`, {})",
        m.generator_name(),
        m.cnc_name(),
        doc.settings.name,
        doc.settings.file
    );
    if let Some(d) = &doc.settings.description {
        let _ = writeln!(s, "  {d}");
    }
    let _ = writeln!(
        s,
        "  match: {}   roll interval t ∈ [{t0}, {t1}] s, {} instants",
        match m.matching() {
            Matching::Pose => "pose (rotation and position; every axis determined)",
            Matching::PointAxis => "point_axis (tool point and tool axis; held variables fixed)",
        },
        run.times.len()
    );
    let _ = writeln!(s, "\nGenerator laws v(t) = start + rate·t (rad, mm, s):");
    for (v, l) in m.generator_variables().iter().zip(m.laws()) {
        if l.rate == 0.0 {
            let _ = writeln!(s, "  {v:>10} = {:.10}", l.start);
        } else {
            let _ = writeln!(s, "  {v:>10} = {:.10} + {:.10}·t", l.start, l.rate);
        }
    }
    let params: Vec<String> = doc
        .cnc_parameters
        .iter()
        .map(|(k, v)| format!("{k} = {v}"))
        .collect();
    if !params.is_empty() {
        let _ = writeln!(s, "CNC parameters: {}", params.join(", "));
    }
    if !m.fixed().is_empty() {
        let held: Vec<String> = m
            .fixed()
            .iter()
            .map(|&(i, v)| format!("{} = {v}", names[i]))
            .collect();
        let _ = writeln!(s, "CNC variables held: {}", held.join(", "));
    }
    let _ = writeln!(
        s,
        "\nEquivalence of the two chains at {} instants: position ≤ {} mm, rotation ≤ {} rad, tool axis ≤ {} rad",
        run.times.len(),
        sci(run.worst.position),
        sci(run.worst.rotation),
        sci(run.worst.axis)
    );

    let width = 16;
    let header = |s: &mut String, first: &str| {
        let _ = write!(s, "{first:>6}");
        for (v, k) in names.iter().zip(kinds) {
            let _ = write!(s, " {:>width$}", format!("{v} ({})", unit(*k)));
        }
        s.push('\n');
    };
    let _ = writeln!(
        s,
        "\nMaclaurin coefficients a_k = L^(k)(0)/k! (axis(t) = Σ a_k t^k):"
    );
    header(&mut s, "k");
    for k in 0..=n {
        let _ = write!(s, "{k:>6}");
        for j in &run.series.axes {
            let _ = write!(s, " {:>width$.9e}", j.coefficients()[k]);
        }
        s.push('\n');
    }
    let _ = writeln!(
        s,
        "\nTruncation error max |exact − series of order m| over [{t0}, {t1}]:"
    );
    header(&mut s, "m");
    // Up to the requested order, or a little past the required one.
    let last = run.errors.len() - 1;
    let shown = match run.required.as_ref().map(|r| r.all) {
        Some(Some(all)) => n.max(all + 3).min(last),
        Some(None) => last,
        None => n,
    };
    for (order, e) in run.errors.iter().enumerate().take(shown + 1) {
        let mark = if order == n { "*" } else { " " };
        let _ = write!(s, "{order:>5}{mark}");
        for x in e {
            let _ = write!(s, " {:>width$}", sci(*x));
        }
        s.push('\n');
    }
    if shown < last {
        let _ = writeln!(
            s,
            "  (* the requested order {n}; orders up to {last} computed, all in --format json)"
        );
    } else {
        let _ = writeln!(s, "  (* the requested order {n})");
    }
    if let Some(required) = &run.required {
        let (tol, all, each) = (&required.tolerance, required.all, &required.per_axis);
        let lin = kinds
            .iter()
            .zip(tol)
            .find(|(k, _)| **k == JointKind::Prismatic)
            .map(|(_, t)| *t);
        let ang = kinds
            .iter()
            .zip(tol)
            .find(|(k, _)| **k == JointKind::Rotary)
            .map(|(_, t)| *t);
        let mut what = Vec::new();
        if let Some(l) = lin {
            what.push(format!("{l:e} mm"));
        }
        if let Some(a) = ang {
            what.push(format!("{a:e} rad"));
        }
        let each: Vec<String> = names
            .iter()
            .zip(each)
            .map(|(v, o)| match o {
                Some(o) => format!("{v} {o}"),
                None => format!("{v} >{}", run.series.order()),
            })
            .collect();
        let _ = writeln!(
            s,
            "\nRequired order for {}: {} ({})",
            what.join(", "),
            match all {
                Some(o) => o.to_string(),
                None => format!(
                    "not reached up to order {} (the series may diverge on this interval, or the tolerance is below the rounding floor)",
                    run.series.order()
                ),
            },
            each.join(", ")
        );
    }
    if !files.is_empty() {
        let _ = writeln!(s, "\nPlots written:");
        for f in files {
            let _ = writeln!(s, "  {f}");
        }
    }
    s
}
