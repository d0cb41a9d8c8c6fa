//! The figures of `chain compensate --plot` (seed 003's Figures 4-9 and the
//! residuals).

use crate::compensate::{Analysis, PolyFit};
use crate::plot::{self, Figures, Series, XyChart};

/// The figures of an analysis:
///
/// - `swing_fit_order{p}`: measured `Δθ` and the order-`p` fit, one per order
///   (the seed's Figures 4-8);
/// - `swing_fits`: the measured `Δθ` and every fit (Figure 9);
/// - `swing_residuals`: `Δθ` before and the residual predicted after
///   compensation with the selected law.
pub fn charts(analysis: &Analysis) -> Figures {
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
    let mut written = Figures::default();
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
        written.push(format!("swing_fit_order{}", fit.order), chart);
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
    written.push("swing_fits", all);
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
    written.push("swing_residuals", residual_chart);
    written
}
