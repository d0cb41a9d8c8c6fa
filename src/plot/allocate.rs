//! `--plot DIR` of `chain allocate`: the reliability over the grid before
//! and after the allocation per component, and the tightening `σ0/σ` per
//! error.

use reliability::allocate::{self, Allocation, ErrorBounds};
use reliability::{Algorithm, Form, ReliabilityError, Study, StudyResult};

use super::{Figures, Legend, Series, XyChart};
use crate::ops::allocate::AllocationRun;

/// The charts of an allocation: the grid's reliability per component
/// before (FORM on the initial statistics) and after (the allocated
/// standard deviations), both evaluated here, and the tightening.
pub fn charts(run: &AllocationRun) -> Result<Figures, ReliabilityError> {
    let stds: Vec<f64> = run.result.std.iter().map(|(_, s)| *s).collect();
    let before = (run.study).run(&Algorithm::Form(Form::default()), &())?;
    let (_, after) = allocate::evaluate(&run.model, &run.parameters, &run.study, &stds)?;
    Ok(comparison(
        &run.machine,
        &run.study,
        &run.bounds,
        &run.result,
        &before,
        &after,
    ))
}

/// Before/after reliability over the grid per component, and the tightening
/// `σ0/σ` per error (per round for the paper's procedure).
fn comparison(
    machine: &str,
    study: &Study,
    bounds: &[ErrorBounds],
    r: &Allocation,
    before: &StudyResult,
    after: &StudyResult,
) -> Figures {
    let mut figures = Figures::default();
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
        let pts = |res: &StudyResult| -> Vec<(f64, f64)> {
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
        figures.push(format!("allocate_{}", target.name()), chart);
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
        figures.notes.push(
            "note: no error was tightened (the requirement holds as given); no tightening chart written"
                .to_string(),
        );
    } else {
        figures.push("allocate_tightening", chart);
    }
    figures
}
