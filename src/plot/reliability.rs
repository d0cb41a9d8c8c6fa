//! `--plot DIR` of `chain reliability`: a heat map of each target's
//! reliability over the grid (like Tables 2-4 of seed 000) and a bar chart of
//! the grid-mean reliability sensitivities `|∂R/∂σ|` (like Figures 6-8), each
//! as PNG and SVG.

use plotters::coord::ranged1d::SegmentValue;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use reliability::{Form, ReliabilityError, TargetSensitivity};

use super::{viridis, BarChart, Figures};
use crate::ops::reliability::ReliabilityRun;
use crate::ops::sensitivity::ReliabilitySensitivity;
use crate::ops::views::{at_text, target_map};

const HEAT_SIZE: (u32, u32) = (900, 700);
const BAR_SIZE: (u32, u32) = (1100, 600);

/// A map of labelled cells, each coloured by its value (viridis over the
/// map's range) and printed with it in %, like the paper's tables.
#[derive(Debug, Clone, PartialEq)]
pub struct CellMap {
    /// Caption above the map.
    pub title: String,
    /// The vertical axis: its name and one label per row.
    pub rows: (String, Vec<String>),
    /// The horizontal axis: its name and one label per column.
    pub cols: (String, Vec<String>),
    /// Reliability in [0, 1], `values[row][col]`.
    pub values: Vec<Vec<f64>>,
    /// Image size in pixels (SVG user units).
    pub size: (u32, u32),
}

/// The charts of a reliability run: each target's reliability map over the
/// grid (one per value of a third varying axis) and the grid-mean
/// reliability sensitivities `|∂R/∂σ|` per target, computed here by FORM.
pub fn charts(run: &ReliabilityRun) -> Result<Figures, ReliabilityError> {
    let sens = run.study.sensitivity_mean(&Form::default())?;
    let (machine, study, result) = (&run.machine, &run.study, &run.result);
    let method = result.method.title();
    let mut figures = Figures::default();
    for (t, target) in study.targets().iter().enumerate() {
        let map = target_map(study, result, t);
        let labels = |axis: &Option<(String, Vec<f64>)>| match axis {
            Some((name, v)) => (name.clone(), v.iter().map(|x| format!("{x}")).collect()),
            None => (String::new(), vec![String::new()]),
        };
        let several = map.maps.len() > 1;
        for (k, (label, values)) in map.maps.iter().enumerate() {
            let heat = CellMap {
                title: format!(
                    "{machine}: {} reliability (%), {method}{}",
                    target.name(),
                    if label.is_empty() {
                        String::new()
                    } else {
                        format!(", {label}")
                    }
                ),
                rows: labels(&map.rows),
                cols: labels(&map.cols),
                values: values.clone(),
                size: HEAT_SIZE,
            };
            let stem = if several {
                format!("reliability_{}_{}", target.name(), k + 1)
            } else {
                format!("reliability_{}", target.name())
            };
            figures.push(stem, super::Chart::Cells(heat));
        }
    }
    figures
        .figures
        .extend(sensitivity_bars(machine, study.inputs().names(), &sens, "grid mean").figures);
    Ok(figures)
}

/// The charts of `chain sensitivity --kind reliability`: the bars of
/// [`sensitivity_bars`] at the document's point or over its grid (`grid
/// mean`).
pub fn sensitivity_charts(doc: &ReliabilitySensitivity) -> Figures {
    let where_ = doc.at.as_deref().map_or("grid mean".to_string(), at_text);
    sensitivity_bars(&doc.machine, &doc.inputs, &doc.result, &where_)
}

/// One bar chart of `|∂R/∂σ|` per target (`sensitivity_<target>`, like
/// Figures 6-8), the errors in `order` (the model's error order, as in
/// Table 1); `where_` says where the values hold (`grid mean`, `at x = 0,
/// …`).
pub fn sensitivity_bars(
    machine: &str,
    order: &[String],
    sens: &[TargetSensitivity],
    where_: &str,
) -> Figures {
    let mut figures = Figures::default();
    for s in sens {
        let values: Vec<f64> = order
            .iter()
            .map(|n| {
                s.errors
                    .iter()
                    .find(|e| &e.error == n)
                    .map_or(0.0, |e| e.mean_abs_dr_dstd)
            })
            .collect();
        let chart = BarChart {
            size: BAR_SIZE,
            ..BarChart::new(
                format!(
                    "{machine}: {} reliability sensitivity |∂R/∂σ| ({where_})",
                    s.target
                ),
                "|∂R/∂σ| (per unit of the error)",
                order.to_vec(),
                values,
            )
        };
        figures.push(format!("sensitivity_{}", s.target), chart);
    }
    figures
}

impl CellMap {
    pub(super) fn draw<DB: DrawingBackend>(
        &self,
        root: DrawingArea<DB, Shift>,
    ) -> Result<(), String>
    where
        DB::ErrorType: 'static,
    {
        heat_on(root, self)
    }
}

fn err<E: std::fmt::Display>(e: E) -> String {
    e.to_string()
}

fn heat_on<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, heat: &CellMap) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(err)?;
    let nr = heat.values.len().max(1);
    let nc = heat.values.first().map_or(1, |r| r.len().max(1));
    let (lo, hi) = heat
        .values
        .iter()
        .flatten()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        });
    let span = if hi > lo { hi - lo } else { 1.0 };
    let mut chart = ChartBuilder::on(&root)
        .caption(&heat.title, ("sans-serif", 22))
        .margin(20)
        .x_label_area_size(50)
        .y_label_area_size(80)
        .build_cartesian_2d((0..nc - 1).into_segmented(), (0..nr - 1).into_segmented())
        .map_err(err)?;
    let col_label = |v: &SegmentValue<usize>| match v {
        SegmentValue::CenterOf(j) => heat.cols.1.get(*j).cloned().unwrap_or_default(),
        _ => String::new(),
    };
    let row_label = |v: &SegmentValue<usize>| match v {
        SegmentValue::CenterOf(i) => heat.rows.1.get(*i).cloned().unwrap_or_default(),
        _ => String::new(),
    };
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(heat.cols.0.as_str())
        .y_desc(heat.rows.0.as_str())
        .x_labels(nc)
        .y_labels(nr)
        .x_label_formatter(&col_label)
        .y_label_formatter(&row_label)
        .label_style(("sans-serif", 16))
        .axis_desc_style(("sans-serif", 18))
        .draw()
        .map_err(err)?;
    chart
        .draw_series(heat.values.iter().enumerate().flat_map(|(i, row)| {
            row.iter().enumerate().map(move |(j, &v)| {
                Rectangle::new(
                    [
                        (SegmentValue::Exact(j), SegmentValue::Exact(i)),
                        (SegmentValue::Exact(j + 1), SegmentValue::Exact(i + 1)),
                    ],
                    viridis((v - lo) / span).filled(),
                )
            })
        }))
        .map_err(err)?;
    chart
        .draw_series(heat.values.iter().enumerate().flat_map(|(i, row)| {
            row.iter().enumerate().map(move |(j, &v)| {
                let t = (v - lo) / span;
                let color = if t > 0.6 { BLACK } else { WHITE };
                Text::new(
                    format!("{:.2}", 100.0 * v),
                    (SegmentValue::CenterOf(j), SegmentValue::CenterOf(i)),
                    ("sans-serif", 16)
                        .into_font()
                        .color(&color)
                        .pos(Pos::new(HPos::Center, VPos::Center)),
                )
            })
        }))
        .map_err(err)?;
    Ok(())
}
