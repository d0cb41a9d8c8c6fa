//! The charts of `chain positioning --plot`, the standard's picture: per
//! direction the mean deviation `x̄↑`, `x̄↓` with the band `x̄ ± k·s`, every
//! run's points, the bidirectional mean `x̄` (the reversal `B_i` is the gap
//! between the two means), the axis values in the title; and a second chart
//! of `B_i` per target. (Labels spell the means out: the renderer places a
//! combining macron badly.)

use chain_core::measured::positioning::{Direction, PositioningDocument};

use crate::plot::{self, Figures, Legend, Series, XyChart};

/// A statistic in a title: four significant digits.
fn short(v: f64) -> String {
    let digits = if v == 0.0 {
        0
    } else {
        (3 - v.abs().log10().floor() as i32).clamp(0, 9) as usize
    };
    format!("{v:.digits$}")
}

/// `positioning` and `positioning_reversal`.
pub fn charts(doc: &PositioningDocument) -> Figures {
    let u = doc.unit.name();
    let k = doc.k;
    let x_label = format!("target ({})", doc.target_unit);
    let a = &doc.axis;
    let up = plot::color(0);
    let down = plot::color(1);
    let curve = |f: &dyn Fn(usize) -> f64| -> Vec<(f64, f64)> {
        doc.targets
            .iter()
            .enumerate()
            .map(|(i, t)| (t.target, f(i)))
            .collect()
    };
    let ts = &doc.targets;
    let kf = doc.k.get();
    let chart = XyChart::new(
        format!(
            "A = {}, E = {}, R = {}, B = {}, M = {} {u}",
            short(a.A),
            short(a.E),
            short(a.R),
            short(a.B),
            short(a.M)
        ),
        x_label.clone(),
        format!(
            "positional deviation ({u}; k = {k}, {} runs per direction)",
            doc.runs
        ),
    )
    .series(Series::points("runs ↑", run_points(doc, Direction::Up)).color(up))
    .series(Series::points("runs ↓", run_points(doc, Direction::Down)).color(down))
    .series(
        Series::line_points("mean ↑", curve(&|i| ts[i].mean_up))
            .color(up)
            .width(3),
    )
    .series(
        Series::line_points("mean ↓", curve(&|i| ts[i].mean_down))
            .color(down)
            .width(3),
    )
    .series(
        Series::line(
            format!("mean ↑ ± {k}s"),
            curve(&|i| ts[i].mean_up + kf * ts[i].s_up),
        )
        .color(up)
        .width(1),
    )
    .series(
        Series::line("", curve(&|i| ts[i].mean_up - kf * ts[i].s_up))
            .color(up)
            .width(1),
    )
    .series(
        Series::line(
            format!("mean ↓ ± {k}s"),
            curve(&|i| ts[i].mean_down + kf * ts[i].s_down),
        )
        .color(down)
        .width(1),
    )
    .series(
        Series::line("", curve(&|i| ts[i].mean_down - kf * ts[i].s_down))
            .color(down)
            .width(1),
    )
    .series(
        Series::line("bidirectional mean", curve(&|i| ts[i].mean))
            .color(plot::GREY)
            .width(2),
    )
    .legend(Legend::UpperLeft)
    .hline(0.0);
    let mut written = Figures::default();
    written.push("positioning", chart);
    let reversal = XyChart::new(
        format!(
            "Reversal B_i = mean ↑ − mean ↓: B = {}, mean {} {u}",
            short(a.B),
            short(a.B_mean)
        ),
        x_label,
        format!("reversal ({u})"),
    )
    .series(Series::line_points("B_i", curve(&|i| ts[i].reversal)).color(plot::color(2)))
    .hline(0.0);
    written.push("positioning_reversal", reversal);
    written
}

/// The points of each direction's runs, for the chart.
fn run_points(doc: &PositioningDocument, direction: Direction) -> Vec<(f64, f64)> {
    doc.points
        .iter()
        .filter(|r| r.direction == direction)
        .flat_map(|r| {
            doc.targets
                .iter()
                .zip(&r.deviations)
                .map(|(t, &x)| (t.target, x))
        })
        .collect()
}
