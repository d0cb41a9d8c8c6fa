//! The figures of `chain compensate --plot` (seed 003's Figures 4-9 and the
//! residuals), drawn with the CLI's plotting layer ([`crate::cli::plot`]).

use std::path::{Path, PathBuf};

use chain::compensate::{Analysis, PolyFit};

use crate::cli::plot::{self, PlotError, Series, XyChart};

/// Writes the figures of an analysis into `dir` (created if missing), each as
/// PNG and SVG, and returns the paths written:
///
/// - `swing_fit_order{p}`: measured `Δθ` and the order-`p` fit, one per order
///   (the seed's Figures 4-8);
/// - `swing_fits`: the measured `Δθ` and every fit (Figure 9);
/// - `swing_residuals`: `Δθ` before and the residual predicted after
///   compensation with the selected law.
pub fn write_plots(analysis: &Analysis, dir: &Path) -> Result<Vec<PathBuf>, PlotError> {
    let measured: Vec<(f64, f64)> = analysis
        .points
        .iter()
        .map(|p| (p.theta_deg, p.delta_theta_deg))
        .collect();
    let [lo, hi] = analysis.angle_range();
    let curve = |fit: &PolyFit| -> Vec<(f64, f64)> {
        (0..=240)
            .map(|i| {
                let x = lo + (hi - lo) * i as f64 / 240.0;
                (x, fit.eval(x))
            })
            .collect()
    };
    let x_label = "commanded swing angle θ (°)";
    let y_label = "swing-angle error Δθ (°)";
    let mut written = Vec::new();
    for (i, fit) in analysis.fits.iter().enumerate() {
        let chart = XyChart::new(
            format!("Order-{} fit of Δθ (R² = {:.4})", fit.order, fit.r2),
            x_label,
            y_label,
        )
        .series(Series::points("measured Δθ", measured.clone()).color(plot::GREY))
        .series(
            Series::line(format!("order {} fit", fit.order), curve(fit))
                .color(plot::color(i))
                .width(3),
        )
        .hline(0.0);
        written.extend(chart.write(dir, &format!("swing_fit_order{}", fit.order))?);
    }
    let mut all = XyChart::new("Δθ fitted by polynomials of each order", x_label, y_label)
        .series(Series::points("measured Δθ", measured.clone()).color(plot::GREY))
        .hline(0.0);
    for (i, fit) in analysis.fits.iter().enumerate() {
        all = all.series(
            Series::line(
                format!("order {} (R² {:.4})", fit.order, fit.r2),
                curve(fit),
            )
            .color(plot::color(i))
            .width(2),
        );
    }
    written.extend(all.write(dir, "swing_fits")?);
    let residuals: Vec<(f64, f64)> = analysis
        .points
        .iter()
        .map(|p| (p.theta_deg, p.residual_deg))
        .collect();
    let residual_chart = XyChart::new(
        format!(
            "Δθ before and predicted after order-{} compensation",
            analysis.selected_order
        ),
        x_label,
        "error (°)",
    )
    .series(Series::line_points("before: measured Δθ", measured).color(plot::GREY))
    .series(
        Series::line_points(
            format!(
                "after: residual of the order-{} law",
                analysis.selected_order
            ),
            residuals,
        )
        .color(plot::color(0)),
    )
    .hline(0.0);
    written.extend(residual_chart.write(dir, "swing_residuals")?);
    Ok(written)
}
