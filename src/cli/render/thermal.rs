//! The table and CSV of `chain thermal` ([`Thermal`]): the drift of each
//! displacement channel, the temperatures, the pairs, and with a fit each
//! channel's model and its held-out prediction.

use chain::ops::thermal::Thermal;
use chain_core::measured::thermal_fit::{Selection, TermKind};

use crate::cli::report::{Csv, Report};

/// The width of a name column: its longest name or its header.
fn name_width<'a>(names: impl Iterator<Item = &'a str>, header: &str) -> usize {
    names
        .map(|n| n.chars().count())
        .fold(header.chars().count(), usize::max)
}

impl Report for Thermal {
    fn table(&self) -> String {
        use std::fmt::Write;
        let d = &self.document;
        let mut out = String::new();
        let _ = writeln!(
            out,
            "ISO 230-3 drift test {}: {} samples over {} s ({:.2} h)",
            d.file,
            d.samples,
            d.duration,
            d.duration / 3600.0
        );
        let _ = writeln!(out);
        let _ = writeln!(out, "drift δ = x(t) − x(0) per displacement channel:");
        let width = name_width(d.channels.iter().map(|c| c.name.as_str()), "channel");
        let _ = writeln!(
            out,
            "  {:<width$}  {:>4}  {:>12}  {:>12}  {:>10}",
            "channel", "unit", "range", "max |δ|", "at (s)"
        );
        for c in &d.channels {
            let _ = writeln!(
                out,
                "  {:<width$}  {:>4}  {:>12.4}  {:>12.4}  {:>10}",
                c.name, c.unit, c.range, c.max_drift, c.max_drift_at
            );
        }
        if !d.temperatures.is_empty() {
            let width = name_width(d.temperatures.iter().map(|t| t.name.as_str()), "sensor");
            let _ = writeln!(out);
            let _ = writeln!(out, "temperatures (°C):");
            let _ = writeln!(
                out,
                "  {:<width$}  {:>9}  {:>9}  {:>9}  {:>9}",
                "sensor", "at start", "min", "max", "range"
            );
            for t in &d.temperatures {
                let _ = writeln!(
                    out,
                    "  {:<width$}  {:>9.3}  {:>9.3}  {:>9.3}  {:>9.3}",
                    t.name, t.first, t.min, t.max, t.range
                );
            }
        }
        for p in &d.pairs {
            let _ = writeln!(out);
            let _ = writeln!(
                out,
                "pair {} : {} ({} mm apart): tilt range {:.3} µrad, largest {:.3} µrad at {} s; drift range at the spindle nose ({}) {:.4}",
                p.pair.first,
                p.pair.second,
                p.pair.distance,
                p.tilt_range,
                p.max_tilt,
                p.max_tilt_at,
                p.pair.first,
                p.nose_range
            );
        }
        if let Some(fit) = &d.fit {
            let _ = writeln!(out);
            let how = match fit.selection {
                Selection::BestSubset => "the best subset of sensors",
                Selection::Forward => "sensors by forward selection (too many subsets)",
            };
            let _ = writeln!(
                out,
                "thermal models (fitted on {} samples from {} s to before {} s; {how} on blocked cross-validation, docs/thermal.md):",
                fit.samples, fit.from, fit.until
            );
            for c in &d.channels {
                let (Some(model), Some(stats)) = (&c.model, &c.fit) else {
                    continue;
                };
                let mut terms = format!("{:.4}", model.intercept);
                for t in &model.terms {
                    let what = match t.kind {
                        TermKind::Temperature => {
                            format!("ΔT[{}]", t.sensor.as_deref().unwrap_or(""))
                        }
                        TermKind::Lag => format!(
                            "L[{}, τ = {:.0} s]",
                            t.load.as_deref().unwrap_or(""),
                            t.tau.unwrap_or(f64::NAN)
                        ),
                    };
                    let _ = write!(terms, " {:+.5}(±{:.5})·{what}", t.coefficient, t.std);
                }
                let _ = writeln!(out, "  {} ({}) = {terms}", c.name, c.unit);
                let _ = writeln!(
                    out,
                    "    fit rms {:.4}, cross-validated rms {:.4}",
                    stats.rms, stats.cv_rms
                );
                if let Some(h) = &c.holdout {
                    let _ = writeln!(
                        out,
                        "    held out ({} samples): rms {:.4} uncorrected, {:.4} after the model, largest {:.4}",
                        h.samples, h.rms_before, h.rms_after, h.max_after
                    );
                }
            }
        }
        out
    }

    fn csv(&self, out: &mut Csv<'_>) -> Option<()> {
        if self.predictions.is_empty() {
            return None;
        }
        out.header(["time", "channel", "measured", "predicted"]);
        for p in &self.predictions {
            for (k, t) in self.time.iter().enumerate() {
                out.row([
                    format!("{t:?}"),
                    p.channel.clone(),
                    format!("{:?}", p.measured[k]),
                    format!("{:?}", p.predicted[k]),
                ]);
            }
        }
        Some(())
    }
}
