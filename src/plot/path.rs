//! `--plot DIR` of `chain path`: the reliability of every target and the
//! standard deviation of the toleranced error components along the path
//! (PNG and SVG), as [`super::XyChart`]s.
//! Instants without axis values (unreachable poses) have no point.

use super::{Figures, Legend, Series, XyChart};
use reliability::Quantity;

use crate::ops::path::PathDocument;
use crate::ops::views::quantity_label;

/// `path_reliability`, `path_std` and, when an orientation component is
/// toleranced, `path_std_angular`; none (and a note) when no instant was
/// evaluated.
pub fn charts(doc: &PathDocument) -> Figures {
    let r = &doc.result;
    let mut files = Figures::default();
    if r.evaluated() == 0 {
        files
            .notes
            .push("note: no evaluated instant; no chart written".to_string());
        return files;
    }
    let x_label = if doc.head.has_t { "t" } else { "row" };
    let method = r.method.title();

    let mut chart = XyChart::new(
        format!(
            "{}: reliability along the path ({method})",
            doc.head.machine
        ),
        x_label,
        "reliability (%)",
    )
    .legend(Legend::LowerLeft);
    for (t, target) in r.targets.iter().enumerate() {
        let points = r
            .records
            .iter()
            .filter_map(|rec| {
                let e = rec.result.as_ref()?;
                Some((rec.instant.t, 100.0 * r.case(e, t).reliability))
            })
            .collect();
        chart = chart.series(Series::line_points(target.target.name(), points));
    }
    if let Some(req) = r.requirement() {
        chart = chart.hline(100.0 * req.min);
    }
    let chart = with_legend_room(chart, false);
    files.push("path_reliability", chart);

    // Standard deviations, lengths and angles on separate charts.
    let toleranced = |k: &usize| {
        r.targets
            .iter()
            .any(|t| t.target.name() == Quantity::ALL[*k].name())
    };
    let position: Vec<usize> = (0..3).filter(toleranced).chain([6]).collect();
    let angular: Vec<usize> = (3..6).filter(toleranced).collect();
    for (stem, ks, unit) in [
        ("path_std", position, "std (length unit)"),
        ("path_std_angular", angular, "std (rad)"),
    ] {
        if ks.is_empty() {
            continue;
        }
        let mut chart = XyChart::new(
            format!(
                "{}: error standard deviation along the path",
                doc.head.machine
            ),
            x_label,
            unit,
        )
        .legend(Legend::UpperLeft);
        for k in ks {
            let q = Quantity::ALL[k];
            let points = r
                .records
                .iter()
                .filter_map(|rec| rec.result.as_ref().map(|e| (rec.instant.t, e.std(q))))
                .collect();
            chart = chart.series(Series::line_points(quantity_label(q), points));
        }
        files.push(stem, with_legend_room(chart, true));
    }
    files
}

/// Fits the y range to the data and reference lines, with an empty band
/// above (`top`) or below for the legend so that it covers no series.
fn with_legend_room(chart: XyChart, top: bool) -> XyChart {
    let values = chart
        .series
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.1))
        .chain(chart.hlines.iter().copied())
        .filter(|v| v.is_finite());
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    });
    if !(lo.is_finite() && hi.is_finite()) {
        return chart;
    }
    let span = if hi > lo {
        hi - lo
    } else {
        lo.abs().max(1.0) * 0.1
    };
    if top {
        chart.y_range(lo - 0.08 * span, hi + 0.45 * span)
    } else {
        chart.y_range(lo - 0.45 * span, hi + 0.08 * span)
    }
}
