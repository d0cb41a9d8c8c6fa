//! `--plot DIR` of `chain sensitivity --kind geometric`: one bar chart per
//! direction of the normalised coefficients `C` (in %), largest first, like
//! Figures 3-5 of seed 004, each as PNG and SVG.

use std::path::{Path, PathBuf};

use chain_core::geometric::{ComponentSensitivity, GeometricSensitivity};
use plotters::coord::ranged1d::SegmentValue;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

const SIZE: (u32, u32) = (1000, 600);

/// Writes `geometric_<component>.{png,svg}` for every direction in which
/// some error acts; returns the files written.
pub(super) fn write_all(
    dir: &Path,
    machine: &str,
    where_: &str,
    result: &GeometricSensitivity,
) -> miette::Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir)
        .map_err(|e| miette::miette!("{}: cannot create the plot directory: {e}", dir.display()))?;
    chain::plot::ensure_fonts();
    let mut files = Vec::new();
    for (k, c) in result.components.iter().enumerate() {
        if c.ranked.iter().all(|e| e.c <= 0.0) {
            continue;
        }
        let title = format!(
            "{machine}: {} sensitivity coefficients C, {where_}",
            c.component.name()
        );
        let stem = format!("geometric_{}", c.component.name());
        let png = dir.join(format!("{stem}.png"));
        let svg = dir.join(format!("{stem}.svg"));
        let fail =
            |p: &Path, e: String| miette::miette!("{}: cannot draw the chart: {e}", p.display());
        let color = chain::plot::color(k);
        {
            let root = BitMapBackend::new(&png, SIZE).into_drawing_area();
            bars_on(root, &title, c, color).map_err(|e| fail(&png, e))?;
        }
        {
            let root = SVGBackend::new(&svg, SIZE).into_drawing_area();
            bars_on(root, &title, c, color).map_err(|e| fail(&svg, e))?;
        }
        files.push(png);
        files.push(svg);
    }
    Ok(files)
}

fn err<E: std::fmt::Display>(e: E) -> String {
    e.to_string()
}

fn bars_on<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    title: &str,
    c: &ComponentSensitivity,
    color: RGBColor,
) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(err)?;
    let bars: Vec<(&str, f64)> = c
        .ranked
        .iter()
        .filter(|e| e.c > 0.0)
        .map(|e| (e.error.as_str(), 100.0 * e.c))
        .collect();
    let n = bars.len().max(1);
    let top = bars.iter().map(|b| b.1).fold(0.0f64, f64::max);
    let top = if top > 0.0 { top * 1.15 } else { 1.0 };
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 20))
        .margin(20)
        .x_label_area_size(50)
        .y_label_area_size(70)
        .build_cartesian_2d((0..n - 1).into_segmented(), 0.0..top)
        .map_err(err)?;
    let label = |v: &SegmentValue<usize>| match v {
        SegmentValue::CenterOf(j) => bars.get(*j).map(|b| b.0.to_string()).unwrap_or_default(),
        _ => String::new(),
    };
    chart
        .configure_mesh()
        .disable_x_mesh()
        .x_labels(n)
        .x_label_formatter(&label)
        .x_desc("error parameter")
        .y_desc("C (%)")
        .label_style(("sans-serif", 13))
        .axis_desc_style(("sans-serif", 16))
        .draw()
        .map_err(err)?;
    chart
        .draw_series(bars.iter().enumerate().map(|(j, &(_, v))| {
            Rectangle::new(
                [
                    (SegmentValue::Exact(j), 0.0),
                    (SegmentValue::Exact(j + 1), v),
                ],
                color.filled(),
            )
        }))
        .map_err(err)?;
    chart
        .draw_series(bars.iter().enumerate().map(|(j, &(_, v))| {
            Rectangle::new(
                [
                    (SegmentValue::Exact(j), 0.0),
                    (SegmentValue::Exact(j + 1), v),
                ],
                WHITE.stroke_width(3),
            )
        }))
        .map_err(err)?;
    chart
        .draw_series(bars.iter().enumerate().map(|(j, &(_, v))| {
            Text::new(
                format!("{v:.1}"),
                (SegmentValue::CenterOf(j), v + top * 0.01),
                ("sans-serif", 13)
                    .into_font()
                    .color(&BLACK)
                    .pos(Pos::new(HPos::Center, VPos::Bottom)),
            )
        }))
        .map_err(err)?;
    root.present().map_err(err)?;
    Ok(())
}
