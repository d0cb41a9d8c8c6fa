//! `--plot DIR` of `chain allocate`: the reliability over the grid before
//! and after the allocation per component, and the tightening `σ0/σ` per
//! error.

use std::path::PathBuf;

use reliability::allocate::{Allocation, ErrorBounds};

use super::{Legend, PlotError, Series, XyChart};

/// Before/after reliability over the grid per component, and the tightening
/// `σ0/σ` per error (per round for the paper's procedure).
pub(crate) fn write_all(
    dir: &std::path::Path,
    machine: &str,
    study: &reliability::Study,
    bounds: &[ErrorBounds],
    r: &Allocation,
    before: &reliability::StudyResult,
    after: &reliability::StudyResult,
) -> Result<Vec<PathBuf>, PlotError> {
    let mut files = Vec::new();
    let np = study.points().len();
    let axes: Vec<&str> = study
        .spec()
        .grid
        .axes
        .iter()
        .map(|(n, _)| n.as_str())
        .collect();
    let req = study.spec().requirement;
    for (t, target) in study.targets().iter().enumerate() {
        let pts = |res: &reliability::StudyResult| -> Vec<(f64, f64)> {
            res.cases[t * np..(t + 1) * np]
                .iter()
                .enumerate()
                .map(|(i, c)| ((i + 1) as f64, c.reliability * 100.0))
                .collect()
        };
        let mut chart = XyChart::new(
            format!(
                "{machine}: {} reliability before and after allocation ({})",
                target.name(),
                r.strategy
            ),
            format!("grid point ({} order, first slowest)", axes.join(", ")),
            "reliability (%)",
        )
        .series(Series::line_points("before", pts(before)))
        .series(Series::line_points("after", pts(after)))
        .legend(Legend::LowerRight);
        if let Some(q) = req {
            chart = chart.hline(q.min * 100.0);
        }
        files.extend(chart.write(dir, &format!("allocate_{}", target.name()))?);
    }
    let mut chart = XyChart::new(
        format!("{machine}: tightening per error ({})", r.strategy),
        if r.steps.is_empty() {
            "initial (0) → allocated (1)"
        } else {
            "round"
        },
        "std0 / std",
    )
    .legend(Legend::UpperLeft);
    let mut tightened = 0;
    for (j, b) in bounds.iter().enumerate() {
        let last = r.std[j].1;
        if (last - b.std0).abs() <= 1e-15 * b.std0 {
            continue;
        }
        tightened += 1;
        let mut points = vec![(0.0, 1.0)];
        if r.steps.is_empty() {
            points.push((1.0, b.std0 / last));
        } else {
            let mut s = b.std0;
            for step in &r.steps {
                if let Some((_, v)) = step.std.iter().find(|(n, _)| *n == b.error) {
                    s = *v;
                }
                points.push((step.round as f64, b.std0 / s));
            }
        }
        chart = chart.series(Series::line_points(b.error.clone(), points));
    }
    // Nothing tightened (the requirement held as given): no tightening to
    // draw, said instead of a chart without data.
    if tightened == 0 {
        eprintln!("note: no error was tightened (the requirement holds as given); no tightening chart written");
    } else {
        files.extend(chart.write(dir, "allocate_tightening")?);
    }
    Ok(files)
}
