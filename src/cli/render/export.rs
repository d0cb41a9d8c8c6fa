//! The table and CSV of `chain export` ([`ExportDocument`]): the grid
//! export's summary (its CSV is the grid file), or a per-axis format's
//! report.

use chain::ops::export::{ExportDocument, GridExport, TablesExport, ThermalExport};
use chain_core::compensation::controllers::Term;
use chain_core::compensation::grid;

use crate::cli::report::{Csv, Report};

impl Report for ExportDocument {
    fn table(&self) -> String {
        match self {
            ExportDocument::Grid(g) => g.table(),
            ExportDocument::Tables(t) => t.table(),
            ExportDocument::Thermal(t) => t.table(),
        }
    }

    fn csv(&self, out: &mut Csv<'_>) -> Option<()> {
        match self {
            ExportDocument::Grid(g) => g.csv(out),
            ExportDocument::Tables(t) => t.csv(out),
            ExportDocument::Thermal(t) => t.csv(out),
        }
    }
}

impl Report for GridExport {
    fn table(&self) -> String {
        use std::fmt::Write;
        let g = &self.grid;
        let s = &g.summary;
        let mut out = String::new();
        let _ = writeln!(
            out,
            "Compensation of {} for controller grid, values {}",
            g.machine, self.values_file
        );
        let _ = writeln!(out, "{} nodes; file {}", s.nodes, self.files.join(", "));
        let _ = writeln!(out);
        let _ = writeln!(out, "{:<28} {:>12} {:>12}", "", "max", "rms");
        let row = |out: &mut String, name: &str, x: &grid::Spread, f: f64| {
            let _ = writeln!(out, "{name:<28} {:>12.4} {:>12.4}", x.max * f, x.rms * f);
        };
        row(&mut out, "tool point before (µm)", &s.before, 1e3);
        row(&mut out, "tool point after (µm)", &s.residual, 1e3);
        row(&mut out, "tool axis before (µrad)", &s.axis_before, 1e6);
        row(&mut out, "tool axis after (µrad)", &s.axis_residual, 1e6);
        let _ = writeln!(out);
        let at: Vec<String> = (s.residual_at.0.iter())
            .map(|(n, v)| format!("{n} = {v}"))
            .collect();
        let _ = writeln!(
            out,
            "largest residual at {}; max residual / max error = {:.3e}",
            at.join(", "),
            s.ratio
        );
        let deltas: Vec<String> = (s.max_delta.0.iter().zip(&g.rotary))
            .map(|((n, v), r)| {
                if *r {
                    format!("{n} {:.3} µrad", v * 1e6)
                } else {
                    format!("{n} {:.3} µm", v * 1e3)
                }
            })
            .collect();
        let _ = writeln!(out, "largest |δq|: {}", deltas.join(", "));
        if s.axis_not_corrected > 0 {
            let _ = writeln!(
                out,
                "tool axis not fully correctable at {} of {} nodes (the axes leave fewer than two tool-axis directions once the tool point is met)",
                s.axis_not_corrected, s.nodes
            );
        }
        if s.continued > 0 {
            let _ = writeln!(
                out,
                "{} nodes: q + δq leaves a values table by |δq|; their residual continues it linearly (docs/export.md)",
                s.continued
            );
        }
        out
    }

    fn csv(&self, out: &mut Csv<'_>) -> Option<()> {
        let g = &self.grid;
        out.header(g.header());
        let nv = g.variables.len();
        let mut q = vec![0.0; nv];
        for i in 0..g.len() {
            g.points.point_into(i, &mut q);
            let mut row: Vec<String> = q.iter().map(|x| format!("{x}")).collect();
            row.extend(g.delta(i).iter().map(|x| format!("{x}")));
            row.push(format!("{}", g.residuals[i]));
            out.row(row);
        }
        Some(())
    }
}

impl Report for TablesExport {
    fn table(&self) -> String {
        use std::fmt::Write;
        let r = &self.report;
        let mut out = String::new();
        let _ = writeln!(
            out,
            "Compensation of {} for controller {}, values {}",
            r.machine,
            r.controller.name(),
            self.values_file
        );
        let _ = writeln!(out, "files: {}", r.files.join(", "));
        if !r.axes.is_empty() {
            let _ = writeln!(out);
            let _ = writeln!(
                out,
                "{:<8} {:>5} {:>12} {:>12} {:>10} {:>7}",
                "axis", "along", "min (mm)", "max (mm)", "step (mm)", "points"
            );
        }
        for a in &r.axes {
            let _ = writeln!(
                out,
                "{:<8} {:>5} {:>12} {:>12} {:>10} {:>7}",
                a.variable, a.axis, a.min, a.max, a.step, a.points
            );
        }
        if r.axes.iter().any(|a| matches!(a.axis, 'A' | 'B' | 'C')) {
            let _ = writeln!(out, "(the rotary axes A, B, C in degrees)");
        }
        if let Some(k) = &r.kinematics {
            let _ = writeln!(out);
            let axes: Vec<String> = k.axes.iter().map(|(c, v)| format!("{c} = {v}")).collect();
            let _ = writeln!(out, "{}: joints {}", k.module, axes.join(", "));
            let _ = writeln!(
                out,
                "  {:<28} {:>20} {:>22}  unit",
                "parameter", "nominal", "identified"
            );
            for p in &k.parameters {
                let _ = writeln!(
                    out,
                    "  {:<28} {:>20.9} {:>22.9}  {}",
                    p.name, p.nominal, p.value, p.unit
                );
            }
            for note in &k.notes {
                let _ = writeln!(out, "  note: {note}");
            }
            let at: Vec<String> = (k.residual_at.iter())
                .map(|(n, v)| format!("{n} = {v}"))
                .collect();
            let _ = writeln!(
                out,
                "  position error left over the grid (first order): rms {:.4} µm, largest at {}",
                k.residual_rms * 1e3,
                at.join(", ")
            );
        }
        let terms = |out: &mut String, title: &str, terms: &[Term]| {
            let _ = writeln!(out);
            let _ = writeln!(out, "{title}");
            if terms.is_empty() {
                let _ = writeln!(out, "  (none)");
                return;
            }
            let _ = writeln!(
                out,
                "  {:<52} {:>14} {:>16}",
                "term", "position (µm)", "orientation (µrad)"
            );
            for t in terms {
                let _ = writeln!(
                    out,
                    "  {:<52} {:>14.4} {:>16.4}",
                    t.name,
                    t.position * 1e3,
                    t.orientation * 1e6
                );
            }
        };
        terms(
            &mut out,
            "expressed (removed by the controller), largest effect over the check grid:",
            &r.expressed,
        );
        terms(
            &mut out,
            "remaining (not expressed by the format):",
            &r.remaining,
        );
        let _ = writeln!(out);
        let _ = writeln!(
            out,
            "left after compensation: position {:.4} µm, orientation {:.4} µrad (largest over the check grid)",
            r.residual.position * 1e3,
            r.residual.orientation * 1e6
        );
        if !r.axes.is_empty() && r.controller.capabilities().tables {
            let _ = writeln!(
                out,
                "linear resampling between table nodes: at most {:.4e} (mm, or rad for angular columns)",
                r.resampling
            );
        }
        for d in &r.directions {
            let _ = if d.bidirectional {
                writeln!(
                    out,
                    "{} ({}): forward and reverse columns from the two approach directions; mean reversal {:.4} µm (BACKLASH {:.6} mm without the COMP_FILE)",
                    d.variable,
                    d.error,
                    d.mean_reversal * 1e3,
                    d.backlash
                )
            } else {
                writeln!(
                    out,
                    "{} ({}): the same trim in both columns (no reverse direction in the values)",
                    d.variable, d.error
                )
            };
        }
        let grid: Vec<String> = (r.check_grid.iter())
            .map(|(n, v)| format!("{n} {} nodes", v.len()))
            .collect();
        let _ = writeln!(out, "check grid: {}", grid.join(", "));
        out
    }
}

impl Report for ThermalExport {
    fn table(&self) -> String {
        use std::fmt::Write;
        let l = &self.law;
        let mut out = String::new();
        let _ = writeln!(
            out,
            "Temperature compensation of {}, values {}; files: {}",
            l.machine,
            self.values_file,
            self.files.join(", ")
        );
        out.push_str("per axis: the correction added to its command, per kelvin of each sensor: offset at P0 + slope·(q − P0)\n\n");
        let _ = writeln!(
            out,
            "{:<6} {:>10} {:<14} {:>16} {:>18}",
            "axis", "P0 (mm)", "sensor", "offset (µm/K)", "slope (µm/m/K)"
        );
        for a in &l.axes {
            for s in &a.lines {
                let _ = writeln!(
                    out,
                    "{:<6} {:>10} {:<14} {:>16.4} {:>18.4}",
                    format!("{} ({})", a.axis, a.variable),
                    a.p0,
                    s.sensor,
                    s.offset * 1e3,
                    s.slope * 1e6
                );
            }
        }
        out.push_str("\nwhat the law leaves, per kelvin of each sensor (largest tool-point error over the grid):\n");
        let _ = writeln!(
            out,
            "{:<14} {:>14} {:>14}",
            "sensor", "before (µm/K)", "after (µm/K)"
        );
        for r in &l.remainder {
            let _ = writeln!(
                out,
                "{:<14} {:>14.4} {:>14.4}",
                r.sensor,
                r.before * 1e3,
                r.after * 1e3
            );
        }
        for a in l.axes.iter().filter(|a| a.formula.is_some()) {
            let _ = writeln!(
                out,
                "TEMPCOMP {}: {}",
                a.axis,
                a.formula.as_deref().unwrap_or("")
            );
        }
        let _ = writeln!(out, "\n{} holds {}", self.files.join(", "), l.holds);
        for n in &l.notes {
            let _ = writeln!(out, "- {n}");
        }
        out
    }

    fn csv(&self, out: &mut Csv<'_>) -> Option<()> {
        out.header(
            [
                "axis",
                "variable",
                "p0",
                "sensor",
                "reference",
                "offset",
                "slope",
            ]
            .map(String::from)
            .to_vec(),
        );
        for a in &self.law.axes {
            for s in &a.lines {
                out.row(vec![
                    a.axis.to_string(),
                    a.variable.clone(),
                    format!("{}", a.p0),
                    s.sensor.clone(),
                    format!("{}", s.reference),
                    format!("{}", s.offset),
                    format!("{}", s.slope),
                ]);
            }
        }
        Some(())
    }
}
