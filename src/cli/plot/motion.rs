//! `--plot DIR` of `chain motion`: each CNC axis against time (the exact
//! motion and its Maclaurin series of the requested order), the error of that
//! series against time, and the truncation error over the roll against the
//! series order (log scales), each as PNG and SVG.

use std::path::{Path, PathBuf};

use super::{Legend, Series as Line, XyChart};
use chain_core::model::JointKind;
use chain_core::motion::Series;

/// What the charts show.
pub(crate) struct View<'a> {
    /// Chart title prefix.
    pub title: String,
    /// CNC variables.
    pub variables: &'a [String],
    /// Their joint kinds.
    pub kinds: &'a [JointKind],
    /// Instants.
    pub times: &'a [f64],
    /// The exact motion at each instant.
    pub exact: &'a [Vec<f64>],
    /// The Maclaurin series.
    pub series: &'a Series,
    /// The requested order.
    pub order: usize,
    /// `errors[m][k]`.
    pub errors: &'a [Vec<f64>],
    /// Per-axis tolerance, if given.
    pub tolerance: Option<&'a [f64]>,
}

/// Writes `motion_<variable>.{png,svg}` for every axis,
/// `series_error.{png,svg}` and `truncation_error.{png,svg}`; returns the
/// files written.
pub(crate) fn write_all(dir: &Path, v: &View<'_>) -> miette::Result<Vec<PathBuf>> {
    let mut files = Vec::new();
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
        files.extend(chart.write(dir, &format!("motion_{}", file_stem(name)))?);
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
    files.extend(
        chart
            .legend(Legend::LowerRight)
            .write(dir, "series_error")?,
    );
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
    files.extend(chart.write(dir, "truncation_error")?);
    Ok(files)
}

/// A file-name-safe form of a variable name.
fn file_stem(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect()
}
