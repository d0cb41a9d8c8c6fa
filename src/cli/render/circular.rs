//! The table of `chain circular` ([`Circular`]): per run and direction the
//! ISO 230-4 results, in µm; per plane the diagnosis, what it could not
//! separate and the residual.

use chain::ops::circular::Circular;
use chain_core::measured::circular::diagnosis::{NotFitted, PerDirection, Residual};
use chain_core::measured::circular::DirectionResult;

use crate::cli::report::Report;

/// µm of a length in mm, to 0.01 µm.
fn um(mm: f64) -> String {
    format!("{:.2}", mm * 1e3)
}

impl Report for Circular {
    fn table(&self) -> String {
        use std::fmt::Write;
        let mut out = String::new();
        let _ = writeln!(
            out,
            "ISO 230-4 circular test {}: {} run(s), about the least-squares centre (µm)",
            self.file,
            self.runs.len()
        );
        for r in &self.runs {
            let feed = r
                .feed
                .map_or(String::new(), |f| format!(", feed {f} mm/min"));
            let _ = writeln!(
                out,
                "\nrun {}: plane {}, radius {} mm{feed}",
                r.run,
                r.plane.name(),
                r.radius
            );
            let _ = writeln!(
                out,
                "  {:<9}  {:>9}  {:>9}  {:>9}  {:>9}  {:>9}  {:>7}",
                "direction", "G", "F_max", "F_min", "centre 1", "centre 2", "samples"
            );
            let row = |name: &str, d: &DirectionResult| {
                format!(
                    "  {:<9}  {:>9}  {:>9}  {:>9}  {:>9}  {:>9}  {:>7}\n",
                    name,
                    um(d.g),
                    um(d.f_max),
                    um(d.f_min),
                    um(d.centre[0]),
                    um(d.centre[1]),
                    d.samples
                )
            };
            if let Some(d) = &r.directions.ccw {
                out.push_str(&row("ccw", d));
            }
            if let Some(d) = &r.directions.cw {
                out.push_str(&row("cw", d));
            }
            if let Some(g_b) = r.g_b {
                let h = r.h.map_or(String::new(), |h| {
                    format!(", circular hysteresis H {}", um(h))
                });
                let _ = writeln!(
                    out,
                    "  bidirectional circular deviation G(b) {}{h}",
                    um(g_b)
                );
            }
        }
        diagnosis(self, &mut out);
        out
    }
}

/// Per plane the diagnosed errors, what was not fitted, what is blurred,
/// the runs' radius offsets and residuals.
fn diagnosis(doc: &Circular, out: &mut String) {
    use std::fmt::Write;
    for fit in &doc.fit {
        let plane = fit.plane;
        let _ = writeln!(
            out,
            "\ndiagnosis, plane {} (a = {}, b = {}): {} samples fitted, {} in the {}° windows after the reversals left out, {} unknowns, residual RMS {} µm",
            plane.name(),
            fit.axes[0],
            fit.axes[1],
            fit.samples,
            fit.excluded,
            fit.window,
            fit.unknowns,
            fit.rms.map_or("- (no degree of freedom left)".to_string(), um)
        );
        let _ = writeln!(
            out,
            "  {:<34}  {:>10}  {:>8}  {:<5}  {:>6}",
            "error", "value", "± 1σ", "unit", "share"
        );
        for e in doc.diagnosis.iter().filter(|e| e.term.plane == plane) {
            let places = chain::ops::views::places(e.uncertainty);
            let se = e
                .uncertainty
                .map_or("-".to_string(), |u| format!("{u:.places$}"));
            let noise = if e.within_noise == Some(true) {
                "  within the noise"
            } else {
                ""
            };
            let _ = writeln!(
                out,
                "  {:<34}  {:>10.places$}  {:>8}  {:<5}  {:>5.0}%{noise}",
                e.term.label(),
                e.value,
                se,
                e.unit,
                100.0 * e.share
            );
        }
        for n in &fit.not_fitted {
            let line = match n {
                NotFitted::NotSeparated { term, with } => format!(
                    "{}: not separated by these runs from {} (which include it)",
                    term.label(),
                    with.join(", ")
                ),
                NotFitted::NoFeed { term } => {
                    format!("{}: not fitted (a run without a feed)", term.label())
                }
                NotFitted::NoPitch { term } => {
                    format!("{}: not fitted (no pitch given)", term.label())
                }
            };
            let _ = writeln!(out, "  {line}");
        }
        for c in &fit.correlated {
            let with: Vec<String> = (c.with.iter())
                .map(|p| format!("{} (r {:+.2})", p.term.label(), p.r))
                .collect();
            let _ = writeln!(
                out,
                "  {}: separated only weakly (r² {:.2} with the others: its variance ×{:.1}) from {}",
                c.term.label(),
                c.r2,
                1.0 / (1.0 - c.r2),
                with.join(", ")
            );
        }
        let _ = writeln!(
            out,
            "  per run: radius offset r0 (bar length, mean scale and servo radius loss together); residual range, RMS, share of G (µm)"
        );
        for r in &fit.runs {
            let res = |p: &PerDirection<Residual>| {
                [("ccw", &p.ccw), ("cw", &p.cw)]
                    .into_iter()
                    .filter_map(|(n, r)| {
                        r.as_ref().map(|r| {
                            format!("{n} {} {} {:.0}%", um(r.range), um(r.rms), 100.0 * r.share)
                        })
                    })
                    .collect::<Vec<_>>()
                    .join(", ")
            };
            let _ = writeln!(
                out,
                "    {}: r0 {}; {}",
                r.run,
                um(r.radius_offset),
                res(&r.residual)
            );
        }
    }
}
