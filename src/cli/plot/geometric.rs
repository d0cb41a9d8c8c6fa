//! `--plot DIR` of `chain sensitivity --kind geometric`: one bar chart per
//! direction of the normalised coefficients `C` (in %), largest first, like
//! Figures 3-5 of seed 004, each as PNG and SVG.

use std::path::{Path, PathBuf};

use super::BarChart;
use chain_core::geometric::GeometricSensitivity;

/// Writes `geometric_<component>.{png,svg}` for every direction in which
/// some error acts; returns the files written.
pub(crate) fn write_all(
    dir: &Path,
    machine: &str,
    where_: &str,
    result: &GeometricSensitivity,
) -> miette::Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    for (k, c) in result.components.iter().enumerate() {
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
        files.extend(chart.write(dir, &format!("geometric_{}", c.component.name()))?);
    }
    Ok(files)
}
