//! `--plot DIR` of `chain sensitivity --kind geometric`: one bar chart per
//! direction of the normalised coefficients `C` (in %), largest first, like
//! Figures 3-5 of seed 004, each as PNG and SVG.

use super::{BarChart, Figures};
use crate::ops::sensitivity::GeometricReport;
use crate::ops::views::where_text;

/// `geometric_<component>` for every direction in which some error acts.
pub fn charts(doc: &GeometricReport) -> Figures {
    let (machine, where_) = (&doc.machine, where_text(&doc.where_));
    let mut figures = Figures::default();
    for (k, c) in doc.result.components.iter().enumerate() {
        let ranked: Vec<_> = c.ranked.iter().filter(|e| e.c > 0.0).collect();
        if ranked.is_empty() {
            continue;
        }
        let chart = BarChart {
            color: super::color(k),
            value_decimals: Some(1),
            ..BarChart::new(
                format!(
                    "{machine}: {} sensitivity coefficients C, {where_}",
                    c.component.name()
                ),
                "C (%)",
                ranked.iter().map(|e| e.error.clone()).collect(),
                ranked.iter().map(|e| 100.0 * e.c).collect(),
            )
        };
        figures.push(format!("geometric_{}", c.component.name()), chart);
    }
    figures
}
