//! The table and CSV of `chain positioning` ([`PositioningDocument`]): the
//! per-target statistics of ISO 230-2 and the axis values.

use chain_core::measured::positioning::{self, PositioningDocument};

use crate::cli::report::{Csv, Report};

/// A statistic in the table: 6 decimals in mm (0.001 µm), 3 in arcseconds.
fn cell(doc: &PositioningDocument, v: f64) -> String {
    match doc.unit {
        positioning::Unit::Mm => format!("{v:.6}"),
        positioning::Unit::Arcsec => format!("{v:.3}"),
    }
}

impl Report for PositioningDocument {
    fn table(&self) -> String {
        use std::fmt::Write;
        let u = self.unit.name();
        let mut out = String::new();
        let _ = writeln!(
            out,
            "ISO 230-2 positioning of {} ({} axis, {} targets, {} runs per direction, k = {}; deviations in {u})",
            if self.file.is_empty() { "the runs" } else { &self.file },
            self.axis_kind,
            self.targets.len(),
            self.runs,
            self.k,
        );
        let _ = writeln!(out);
        let header = [
            format!("target ({})", self.target_unit),
            "mean ↑".into(),
            "mean ↓".into(),
            "mean".into(),
            "reversal B".into(),
            "s ↑".into(),
            "s ↓".into(),
            "R ↑".into(),
            "R ↓".into(),
            "R".into(),
        ];
        let rows: Vec<[String; 10]> = self
            .targets
            .iter()
            .map(|t| {
                [
                    format!("{}", t.target),
                    cell(self, t.mean_up),
                    cell(self, t.mean_down),
                    cell(self, t.mean),
                    cell(self, t.reversal),
                    cell(self, t.s_up),
                    cell(self, t.s_down),
                    cell(self, t.repeatability_up),
                    cell(self, t.repeatability_down),
                    cell(self, t.repeatability),
                ]
            })
            .collect();
        let widths: Vec<usize> = (0..header.len())
            .map(|c| {
                rows.iter()
                    .map(|r| r[c].chars().count())
                    .chain([header[c].chars().count()])
                    .max()
                    .unwrap_or(0)
            })
            .collect();
        let line = |cells: &[String]| -> String {
            let parts: Vec<String> = cells
                .iter()
                .zip(&widths)
                .map(|(c, w)| format!("{c:>w$}", w = *w))
                .collect();
            parts.join("  ").trim_end().to_string()
        };
        let _ = writeln!(out, "{}", line(&header));
        for r in &rows {
            let _ = writeln!(out, "{}", line(r));
        }
        let a = &self.axis;
        let _ = writeln!(out);
        let _ = writeln!(out, "axis ({u}):");
        let pairs = [
            ("A  accuracy", a.A, a.A_up, a.A_down),
            ("E  systematic deviation", a.E, a.E_up, a.E_down),
            ("R  repeatability", a.R, a.R_up, a.R_down),
        ];
        for (name, both, up, down) in pairs {
            let _ = writeln!(
                out,
                "  {name:<26} {:>12}   ↑ {:>12}   ↓ {:>12}",
                cell(self, both),
                cell(self, up),
                cell(self, down)
            );
        }
        let _ = writeln!(
            out,
            "  {:<26} {:>12}",
            "M  mean deviation range",
            cell(self, a.M)
        );
        let _ = writeln!(
            out,
            "  {:<26} {:>12}   mean B̄ {:>12}",
            "B  reversal",
            cell(self, a.B),
            cell(self, a.B_mean)
        );
        if let Some(t) = &self.temperature {
            let _ = writeln!(out);
            let _ = writeln!(
                out,
                "corrected to 20 °C (docs/positioning.md): scale at {} °C, {} µm/(m·K); instrument at {} °C, {} µm/(m·K)",
                t.at.axis, t.at.axis_expansion, t.at.instrument, t.at.instrument_expansion
            );
            let _ = writeln!(
                out,
                "  {:.4} µm/m from target {} (at the farthest target {}); its uncertainty U = {} (k = {}; u(T) = {} K, coefficients ±{} %)",
                t.per_metre,
                t.datum,
                cell(self, t.largest),
                cell(self, t.expanded),
                self.k,
                t.at.temperature_uncertainty,
                t.at.expansion_uncertainty * 100.0
            );
        }
        out
    }

    fn csv(&self, out: &mut Csv<'_>) -> Option<()> {
        out.header([
            "target",
            "mean_up",
            "mean_down",
            "mean",
            "reversal",
            "s_up",
            "s_down",
            "repeatability_up",
            "repeatability_down",
            "repeatability",
        ]);
        for t in &self.targets {
            out.row(
                [
                    t.target,
                    t.mean_up,
                    t.mean_down,
                    t.mean,
                    t.reversal,
                    t.s_up,
                    t.s_down,
                    t.repeatability_up,
                    t.repeatability_down,
                    t.repeatability,
                ]
                .map(|v| format!("{v:?}")),
            );
        }
        Some(())
    }
}
