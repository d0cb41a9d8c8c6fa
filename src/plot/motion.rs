//! `--plot DIR` of `chain motion`: each CNC axis against time (the exact
//! motion and its Maclaurin series of the requested order), the error of that
//! series against time, and the truncation error over the roll against the
//! series order (log scales), each as PNG and SVG.

use super::{Figures, Legend, Series as Line, XyChart};
use crate::ops::motion::MotionDocument;
use chain_core::model::JointKind;
use chain_core::motion::Series;

/// What the charts show of a run.
struct View<'a> {
    /// Chart title prefix.
    title: String,
    /// CNC variables.
    variables: &'a [String],
    /// Their joint kinds.
    kinds: &'a [JointKind],
    /// Instants.
    times: &'a [f64],
    /// The exact motion at each instant.
    exact: &'a [Vec<f64>],
    /// The Maclaurin series.
    series: &'a Series,
    /// The requested order.
    order: usize,
    /// `errors[m][k]`.
    errors: &'a [Vec<f64>],
    /// Per-axis tolerance, if given.
    tolerance: Option<&'a [f64]>,
}

impl<'a> View<'a> {
    /// What the charts draw of `doc`'s run.
    fn of(doc: &'a MotionDocument) -> View<'a> {
        let run = &doc.conversion;
        View {
            title: format!(
                "{} → {} ({})",
                run.motion.generator_name(),
                run.motion.cnc_name(),
                doc.settings.name
            ),
            variables: run.motion.variables(),
            kinds: run.motion.kinds(),
            times: &run.times,
            exact: &run.exact,
            series: &run.series,
            order: run.order,
            errors: &run.errors,
            tolerance: run.required.as_ref().map(|r| r.tolerance.as_slice()),
        }
    }
}

/// `motion_<variable>` for every axis, `series_error` and
/// `truncation_error`.
pub fn charts(doc: &MotionDocument) -> Figures {
    let v = &View::of(doc);
    let mut files = Figures::default();
    for (k, name) in v.variables.iter().enumerate() {
        let unit = match v.kinds[k] {
            JointKind::Rotary => "rad",
            JointKind::Prismatic => "mm",
        };
        let exact: Vec<(f64, f64)> = v
            .times
            .iter()
            .zip(v.exact)
            .map(|(t, q)| (*t, q[k]))
            .collect();
        let approx: Vec<(f64, f64)> = v
            .times
            .iter()
            .map(|t| (*t, v.series.partial_sum(k, v.order, *t)))
            .collect();
        let chart = XyChart::new(
            format!("{}: axis {name}", v.title),
            "t (s)",
            format!("{name} ({unit})"),
        )
        .series(Line::line("exact", exact).width(5))
        .series(Line::line(format!("Maclaurin, order {}", v.order), approx))
        .legend(Legend::UpperLeft);
        files.push(format!("motion_{}", super::file_stem(name)), chart);
    }
    let mut chart = XyChart::new(
        format!("{}: error of the order-{} series", v.title, v.order),
        "t (s)",
        "log10 |exact − series| (mm, rad)",
    );
    for (k, name) in v.variables.iter().enumerate() {
        let points: Vec<(f64, f64)> = v
            .times
            .iter()
            .zip(v.exact)
            .map(|(t, q)| (*t, (q[k] - v.series.partial_sum(k, v.order, *t)).abs()))
            .filter(|(_, e)| *e > 0.0)
            .map(|(t, e)| (t, e.log10()))
            .collect();
        chart = chart.series(Line::line(name.clone(), points));
    }
    files.push("series_error", chart.legend(Legend::LowerRight));
    let mut chart = XyChart::new(
        format!("{}: truncation error over the roll", v.title),
        "series order m",
        "log10 max |exact − series| (mm, rad)",
    );
    for (k, name) in v.variables.iter().enumerate() {
        let points: Vec<(f64, f64)> = v
            .errors
            .iter()
            .enumerate()
            .filter(|(_, e)| e[k] > 0.0)
            .map(|(m, e)| (m as f64, e[k].log10()))
            .collect();
        chart = chart.series(Line::line_points(name.clone(), points));
    }
    if let Some(tol) = v.tolerance {
        let mut levels: Vec<f64> = tol.iter().map(|t| t.log10()).collect();
        levels.sort_by(f64::total_cmp);
        levels.dedup();
        for l in levels {
            chart = chart.hline(l);
        }
    }
    files.push("truncation_error", chart);
    files
}
