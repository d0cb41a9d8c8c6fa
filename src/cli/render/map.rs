//! The table and CSV of `chain map` ([`MapDocument`]): the ISO 230-1-style
//! summary per component, the reversals the approach read leaves out, the
//! map after compensation beside it, and the points of a small map.

use chain::ops::map::{MapDocument, MapInput};
use chain_core::model::Component;
use chain_core::values::{Approach, Given};

use crate::cli::report::{self, Csv, Report};

/// Maps with at most this many points also list every point in the table
/// format.
pub(crate) const TABLE_POINTS: usize = 60;

/// mm → µm, rad → µrad, for the table.
const MICRO: [f64; 6] = [1e3, 1e3, 1e3, 1e6, 1e6, 1e6];
/// The table's units.
const UNITS: [&str; 6] = ["µm", "µm", "µm", "µrad", "µrad", "µrad"];

/// The point `i` of `doc`, `x = 0, y = 500`.
fn point_text(doc: &MapDocument, i: usize) -> String {
    (doc.variables.iter().zip(doc.result.points().point(i)))
        .map(|(n, x)| format!("{n} = {}", number(x)))
        .collect::<Vec<_>>()
        .join(", ")
}

/// A coordinate: a whole number without decimals, else Rust's shortest form.
fn number(x: f64) -> String {
    match report::whole(x) {
        Some(i) => i.to_string(),
        None => format!("{x}"),
    }
}

impl Report for MapDocument {
    fn table(&self) -> String {
        use std::fmt::Write;
        let s = self.result.summary();
        let count = self.result.points().len();
        let mut out = String::new();
        let _ = writeln!(
            out,
            "Error map of {} (frame: {}), values {}",
            self.machine,
            self.frame.name(),
            self.values_file
        );
        let tables = (self.entries.iter())
            .filter(|e| matches!(e.given, Given::Table { .. }))
            .count();
        let constants = self.entries.len() - tables;
        let rest = match self.unset {
            0 => format!("all {} error parameters given", self.errors),
            n => format!(
                "{n} of the {} error parameters not given (zero)",
                self.errors
            ),
        };
        let _ = writeln!(
            out,
            "values: {} tabulated error motion{}, {} constant{}; {rest}",
            tables,
            if tables == 1 { "" } else { "s" },
            constants,
            if constants == 1 { "" } else { "s" },
        );
        if !self.temperatures.is_empty() {
            let state: Vec<String> = (self.temperatures.iter())
                .map(|(n, t)| format!("{n} = {t} °C"))
                .collect();
            let _ = writeln!(out, "thermal state: {}", state.join(", "));
        }
        for r in &self.reversals {
            let (f, unit) = if r.unit == "mm" {
                (1e3, "µm")
            } else {
                (1e6, "µrad")
            };
            let read = match r.approach {
                Approach::Mean => format!(
                    "the map reads their mean, leaving out ±{:.3} {unit}",
                    r.left_out * f
                ),
                a => format!(
                    "the map reads `{a}`, leaving out up to {:.3} {unit} when approached the other way",
                    r.left_out * f
                ),
            };
            let _ = writeln!(
                out,
                "reversal of {} along {}: up to {:.3} {unit} between the approach directions ({} = {}); {read}",
                r.name,
                r.variable,
                r.largest * f,
                r.variable,
                number(r.at)
            );
        }
        match &self.input {
            MapInput::Grid(axes) => {
                let desc: Vec<String> = axes
                    .iter()
                    .map(|(n, v)| match v.as_slice() {
                        [one] => format!("{n} = {}", number(*one)),
                        [first, .., last] => format!(
                            "{n} {} … {} ({} values)",
                            number(*first),
                            number(*last),
                            v.len()
                        ),
                        [] => format!("{n}: none"),
                    })
                    .collect();
                let _ = writeln!(out, "{count} points: {}", desc.join(", "));
            }
            MapInput::Rows(file) => {
                let _ = writeln!(out, "{count} points: the rows of {file}");
            }
        }
        let _ = writeln!(out);
        let _ = writeln!(
            out,
            "{:<12} {:>12} {:>12} {:>12}",
            "component", "min", "max", "rms"
        );
        for c in 0..6 {
            let cs = s.component(c);
            let f = MICRO[c];
            let _ = writeln!(
                out,
                "{:<12} {:>12.3} {:>12.3} {:>12.3}",
                format!("{} ({})", Component::NAMES[c], UNITS[c]),
                cs.min * f,
                cs.max * f,
                cs.rms * f
            );
        }
        let _ = writeln!(out);
        let _ = writeln!(
            out,
            "volumetric |p|: max {:.3} µm at {}; rms {:.3} µm",
            s.volumetric.max * 1e3,
            point_text(self, s.volumetric.index),
            s.volumetric.rms * 1e3
        );
        if let Some(c) = &self.compensated {
            let a = &c.result.summary;
            let _ = writeln!(out);
            let _ = writeln!(out, "After {} compensation ({}):", c.controller, c.source);
            let _ = writeln!(
                out,
                "{:<12} {:>12} {:>12} {:>12}   {:>12} {:>12} {:>12}",
                "component", "min", "max", "rms", "min after", "max after", "rms after"
            );
            for k in 0..6 {
                let (b, f) = (s.component(k), MICRO[k]);
                let ac = a.component(k);
                let _ = writeln!(
                    out,
                    "{:<12} {:>12.3} {:>12.3} {:>12.3}   {:>12.4} {:>12.4} {:>12.4}",
                    format!("{} ({})", Component::NAMES[k], UNITS[k]),
                    b.min * f,
                    b.max * f,
                    b.rms * f,
                    ac.min * f,
                    ac.max * f,
                    ac.rms * f
                );
            }
            let _ = writeln!(
                out,
                "volumetric |p| after: max {:.4} µm at {}; rms {:.4} µm (before: max {:.3} µm, rms {:.3} µm)",
                a.volumetric.max * 1e3,
                point_text(self, a.volumetric.index),
                a.volumetric.rms * 1e3,
                s.volumetric.max * 1e3,
                s.volumetric.rms * 1e3
            );
        }
        if let Some(r) = self.full().filter(|r| r.len() <= TABLE_POINTS) {
            let _ = writeln!(out);
            let mut header: Vec<String> = r.variables.clone();
            header.extend((0..6).map(|c| format!("{} ({})", Component::NAMES[c], UNITS[c])));
            header.push("|p| (µm)".to_string());
            let widths: Vec<usize> = header.iter().map(|h| h.chars().count().max(10)).collect();
            let line = |cells: &[String]| {
                cells
                    .iter()
                    .zip(&widths)
                    .map(|(c, w)| format!("{c:>w$}"))
                    .collect::<Vec<_>>()
                    .join("  ")
            };
            let _ = writeln!(out, "{}", line(&header));
            for i in 0..r.len() {
                let mut cells: Vec<String> = r.point(i).iter().map(|x| number(*x)).collect();
                cells.extend((0..6).map(|c| format!("{:.3}", r.errors[i][c] * MICRO[c])));
                cells.push(format!("{:.3}", r.volumetric(i) * 1e3));
                let _ = writeln!(out, "{}", line(&cells));
            }
        }
        out
    }

    fn csv(&self, out: &mut Csv<'_>) -> Option<()> {
        let r = self.full()?;
        let mut header: Vec<String> = r.variables.clone();
        header.extend(Component::NAMES.map(String::from));
        header.push("volumetric".into());
        let after = self.compensated.as_ref().map(|c| &c.result);
        if after.is_some() {
            let names = Component::NAMES.iter().chain(&["volumetric"]);
            header.extend(names.map(|c| format!("{c}_after")));
        }
        out.header(header);
        for i in 0..r.len() {
            let mut row: Vec<String> = r.point(i).iter().map(|x| format!("{x}")).collect();
            row.extend(r.errors[i].iter().map(|x| format!("{x}")));
            row.push(format!("{}", r.volumetric(i)));
            if let Some(a) = after {
                row.extend(a.errors[i].iter().map(|x| format!("{x}")));
                row.push(format!("{}", a.volumetric(i)));
            }
            out.row(row);
        }
        Some(())
    }
}
