//! The polar plots of `chain circular --plot`: per run, both directions'
//! traces about their least-squares centres, the deviation from the
//! nominal radius magnified on a ring, as ballbar software draws them, and
//! the diagnosis (the errors explaining most of the run's G) in the legend.

use chain_core::measured::circular::{trace, CircularTest, Direction, DirectionResult};

use crate::ops::circular::Circular;
use crate::plot::{self, Figures, Legend, RGBColor, Series, XyChart};

/// Image size (pixels): square, so the circle is round.
const SIZE: (u32, u32) = (820, 820);

/// The diagnosed errors a plot's legend names at most, by share of G.
const LEGEND_ERRORS: usize = 8;

/// The least share of G an error named in the legend explains.
const LEGEND_SHARE: f64 = 0.02;

/// The scale of the rings: the least of 1, 2, 5 × 10ⁿ µm at or above
/// `span` (the largest |deviation|).
fn nice(span: f64) -> f64 {
    let span = span.max(1e-3);
    let decade = 10f64.powf(span.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * decade)
        .find(|&s| s >= span)
        .unwrap_or(10.0 * decade)
}

/// `(x, y)` of a deviation `dev` (µm) at `deg` on the ring of radius
/// `ring` (µm): the magnified polar position.
fn polar(deg: f64, dev: f64, ring: f64) -> (f64, f64) {
    let (s, c) = deg.to_radians().sin_cos();
    ((ring + dev) * c, (ring + dev) * s)
}

/// A circle of deviation `dev` on the ring, closed.
fn circle(dev: f64, ring: f64) -> Vec<(f64, f64)> {
    (0..=360).map(|k| polar(f64::from(k), dev, ring)).collect()
}

/// `circular`: one polar plot per run (`circular_<run>`).
pub fn charts(test: &CircularTest, doc: &Circular) -> Figures {
    let mut figures = Figures::default();
    for (run, result) in test.runs.iter().zip(&doc.runs) {
        let directions: Vec<(Direction, &DirectionResult)> = [
            (Direction::Ccw, result.directions.ccw.as_ref()),
            (Direction::Cw, result.directions.cw.as_ref()),
        ]
        .into_iter()
        .filter_map(|(d, r)| r.map(|r| (d, r)))
        .collect();
        // Each direction about its own least-squares centre, in µm.
        let traces: Vec<Vec<(f64, f64)>> = (directions.iter())
            .map(|(d, r)| {
                trace(run, *d, r.centre)
                    .into_iter()
                    .map(|(deg, dev)| (deg, dev * 1e3))
                    .collect()
            })
            .collect();
        let span = (traces.iter().flatten()).fold(0.0f64, |m, &(_, dev)| m.max(dev.abs()));
        let scale = nice(span);
        // The ring three scales out: the trace stays clear of the centre.
        let ring = 3.0 * scale;
        let [a, b] = run.plane.axes().map(|k| ["X", "Y", "Z"][k]);
        let feed = run.feed.map_or(String::new(), |f| format!(", {f} mm/min"));
        let both = match (result.g_b, result.h) {
            (Some(g_b), Some(h)) => format!("; G(b) {:.2} µm, H {:.2} µm", g_b * 1e3, h * 1e3),
            (Some(g_b), None) => format!("; G(b) {:.2} µm", g_b * 1e3),
            _ => String::new(),
        };
        let mut chart = XyChart::new(
            format!(
                "run {}: {}, R {} mm{feed}{both}",
                run.id,
                run.plane.name(),
                run.radius
            ),
            format!(
                "{a}: deviation from R about the least-squares centre, µm, on a ring of {ring} µm"
            ),
            b.to_string(),
        )
        .legend(Legend::UpperRight);
        chart.size = SIZE;
        let reach = (ring + 1.6 * scale) * 1.05;
        chart.x_range = Some((-reach, reach));
        chart.y_range = Some((-reach, reach));
        chart = chart
            .series(
                Series::line("nominal radius (0 µm)", circle(0.0, ring))
                    .color(RGBColor(90, 90, 90))
                    .width(1),
            )
            .series(
                Series::line(format!("±{scale} µm"), circle(scale, ring))
                    .color(RGBColor(190, 190, 190))
                    .width(1),
            )
            .series(
                Series::line("", circle(-scale, ring))
                    .color(RGBColor(190, 190, 190))
                    .width(1),
            );
        for (k, ((d, r), t)) in directions.iter().zip(&traces).enumerate() {
            let mut points: Vec<(f64, f64)> =
                t.iter().map(|&(deg, dev)| polar(deg, dev, ring)).collect();
            // Closed round the whole circle; a partial arc stays open.
            if let (Some(&first), true) = (points.first(), doc.arc >= 360.0) {
                points.push(first);
            }
            chart = chart.series(
                Series::line(
                    format!(
                        "{} (G {:.2} µm, F {:+.2} / {:+.2} µm)",
                        d.name(),
                        r.g * 1e3,
                        r.f_max * 1e3,
                        r.f_min * 1e3
                    ),
                    points,
                )
                .color(plot::color(k))
                .width(2),
            );
        }
        // The diagnosis in the legend: the errors of the run's plane and
        // of the run, by the share of this run's G they explain.
        let mut named: Vec<(f64, String)> = (doc.diagnosis.iter())
            .filter(|e| e.term.plane == run.plane)
            .filter(|e| e.term.run.as_ref().is_none_or(|r| *r == run.id))
            .filter(|e| e.within_noise != Some(true))
            .filter_map(|e| {
                let share = e.shares.iter().find(|s| s.run == run.id)?.share;
                (share >= LEGEND_SHARE).then(|| {
                    let error = e.term.label().replace(&format!(" (run {})", run.id), "");
                    (
                        share,
                        format!(
                            "{error} {:.3} {} ({:.0}% of G)",
                            e.value,
                            e.unit.replace("urad", "µrad").replace("um", "µm"),
                            100.0 * share
                        ),
                    )
                })
            })
            .collect();
        named.sort_by(|a, b| b.0.total_cmp(&a.0));
        for (_, label) in named.into_iter().take(LEGEND_ERRORS) {
            chart = chart.series(
                Series::line(label, Vec::new())
                    .color(RGBColor(255, 255, 255))
                    .width(1),
            );
        }
        // Distinct stems for identifiers that read alike as file names.
        let mut name = format!("circular_{}", plot::file_stem(&run.id));
        while figures.figures.iter().any(|f| f.stem == name) {
            name.push('_');
        }
        figures.push(name, chart);
    }
    figures
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ring_scales_are_one_two_five() {
        assert_eq!(nice(3.7), 5.0);
        assert_eq!(nice(12.0), 20.0);
        assert_eq!(nice(0.08), 0.1);
        assert_eq!(nice(50.0), 50.0);
    }
}
