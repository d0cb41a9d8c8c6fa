//! The table of `chain circular` ([`Circular`]): per run and direction the
//! ISO 230-4 results, in µm.

use chain::ops::circular::Circular;
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
        out
    }
}
