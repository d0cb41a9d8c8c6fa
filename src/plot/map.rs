//! `--plot DIR` of `chain map` (PNG and SVG, see `docs/map.md`).
//!
//! On a grid with at least two axes of several values, the plotting plane is
//! spanned by the two axes with the most values (the earlier axis when counts
//! tie), the one with more values horizontal; every other axis is held at its
//! middle value (the lower middle one for an even count), and the title says
//! where. In that plane:
//!
//! - `map_<component>` for `px … oz` and `map_volumetric`: heat maps over
//!   the two axes (µm, µrad), each cell centred on its grid node, a diverging
//!   scale symmetric about zero for the signed components and viridis for
//!   `|p|`;
//! - `map_distortion`: the CMM-style picture, the nominal tool-point grid
//!   (in the workpiece frame, projected on the coordinate plane in which it
//!   spreads most) and the same grid displaced by the in-plane part of the
//!   position error, magnified so that the largest displacement is about
//!   0.4 of the smallest spacing between drawn grid lines (a 1-2-5 factor,
//!   stated in the title); at most 12 lines per direction are drawn, evenly
//!   spread, each through every node along it.
//!
//! With one varying axis, or points from `--axes`, `map_position` and
//! `map_orientation` chart the components along that axis (or the row).

use chain_core::model::Frame;
use chain_core::{BuiltMachine, CompiledModel, ErrorModel, MapResult};
use plotters::coord::Shift;
use plotters::prelude::*;

use super::{ramp, viridis, Figures, Legend, Series, XyChart, GREY};
use crate::ops::map::{MapDocument, MapInput};

const HEAT_SIZE: (u32, u32) = (1000, 760);
const COMPONENTS: [&str; 6] = chain_core::model::Component::NAMES;
/// mm → µm, rad → µrad.
const MICRO: [f64; 6] = [1e3, 1e3, 1e3, 1e6, 1e6, 1e6];
const UNITS: [&str; 6] = ["µm", "µm", "µm", "µrad", "µrad", "µrad"];

/// The charts of a map document: those of its map, and with
/// `--compensated` those of the map after compensation under
/// `compensated/`; none when the document kept no point's error. `built`
/// is the machine that mapped it (the distorted grid's nominal tool points).
pub fn charts(doc: &MapDocument, built: &BuiltMachine<CompiledModel>) -> Figures {
    let Some(r) = doc.full() else {
        return Figures::default();
    };
    let mut figures = result_charts(r, &doc.input, built);
    if let Some(c) = &doc.compensated {
        let mut r = c.result.clone();
        r.machine = format!("{} compensated ({})", doc.machine, c.controller);
        figures.nest("compensated", result_charts(&r, &doc.input, built));
    }
    figures
}

/// The charts of one map over `input`'s points.
pub fn result_charts(
    r: &MapResult,
    input: &MapInput,
    built: &BuiltMachine<CompiledModel>,
) -> Figures {
    let mut figures = Figures::default();
    match input {
        MapInput::Grid(axes) => {
            let mut by_count: Vec<usize> =
                (0..axes.len()).filter(|&k| axes[k].1.len() > 1).collect();
            by_count.sort_by_key(|&k| std::cmp::Reverse(axes[k].1.len()));
            match by_count.as_slice() {
                [a, b, ..] => plane(&mut figures, r, built, axes, *a, *b),
                [a] => {
                    let lines = along_axis(axes, *a);
                    let slice = slice_text(axes, &[*a]);
                    lines_charts(&mut figures, r, &axes[*a].0, &lines, &slice);
                }
                [] => figures
                    .notes
                    .push("note: the map has one point; no chart written".to_string()),
            }
        }
        MapInput::Rows(_) => {
            let lines: Vec<(f64, usize)> = (0..r.len()).map(|i| ((i + 1) as f64, i)).collect();
            lines_charts(&mut figures, r, "row", &lines, "");
        }
    }
    figures
}

/// The flat index of a grid node (last axis fastest).
fn flat(idx: &[usize], axes: &[(String, Vec<f64>)]) -> usize {
    idx.iter()
        .zip(axes)
        .fold(0, |acc, (&i, (_, v))| acc * v.len() + i)
}

/// The index of every axis but the plotted ones: its middle value.
fn middle(axes: &[(String, Vec<f64>)]) -> Vec<usize> {
    axes.iter().map(|(_, v)| (v.len().max(1) - 1) / 2).collect()
}

/// `z = 200` for the held axes (not in `free`).
fn slice_text(axes: &[(String, Vec<f64>)], free: &[usize]) -> String {
    let mid = middle(axes);
    axes.iter()
        .enumerate()
        .filter(|(k, _)| !free.contains(k))
        .map(|(k, (n, v))| format!("{n} = {}", tick(v[mid[k]])))
        .collect::<Vec<_>>()
        .join(", ")
}

/// `(axis value, point index)` along axis `a`, the others held.
fn along_axis(axes: &[(String, Vec<f64>)], a: usize) -> Vec<(f64, usize)> {
    let mut idx = middle(axes);
    axes[a]
        .1
        .iter()
        .enumerate()
        .map(|(i, &x)| {
            idx[a] = i;
            (x, flat(&idx, axes))
        })
        .collect()
}

/// Position and orientation components along one axis (or the row).
fn lines_charts(
    figures: &mut Figures,
    r: &MapResult,
    x_label: &str,
    points: &[(f64, usize)],
    slice: &str,
) {
    let at = if slice.is_empty() {
        String::new()
    } else {
        format!(" at {slice}")
    };
    // The components `range` in `unit` (µm or µrad), one series each.
    let chart = |what: &str, unit: &str, range: std::ops::Range<usize>| {
        let mut chart = XyChart::new(
            format!("{}: {what} error{at}", r.machine),
            x_label,
            format!("error ({unit})"),
        )
        .legend(Legend::UpperLeft)
        .hline(0.0);
        for c in range {
            let pts = (points.iter())
                .map(|&(x, i)| (x, r.errors[i][c] * MICRO[c]))
                .collect();
            chart = chart.series(Series::line_points(COMPONENTS[c], pts));
        }
        chart
    };
    let vol = (points.iter())
        .map(|&(x, i)| (x, r.volumetric(i) * 1e3))
        .collect();
    let position = chart("position", "µm", 0..3).series(Series::line("|p|", vol).width(3));
    figures.push("map_position", position);
    figures.push("map_orientation", chart("orientation", "µrad", 3..6));
}

/// The heat maps and the distorted grid over axes `a` (columns) and `b`
/// (rows).
fn plane(
    figures: &mut Figures,
    r: &MapResult,
    built: &BuiltMachine<CompiledModel>,
    axes: &[(String, Vec<f64>)],
    a: usize,
    b: usize,
) {
    let slice = slice_text(axes, &[a, b]);
    let at = if slice.is_empty() {
        String::new()
    } else {
        format!(" at {slice}")
    };
    let mid = middle(axes);
    let node = |i: usize, j: usize| {
        let mut idx = mid.clone();
        idx[a] = i;
        idx[b] = j;
        flat(&idx, axes)
    };
    let (na, nb) = (axes[a].1.len(), axes[b].1.len());
    for c in 0..7 {
        let values: Vec<Vec<f64>> = (0..nb)
            .map(|j| {
                (0..na)
                    .map(|i| {
                        let k = node(i, j);
                        if c < 6 {
                            r.errors[k][c] * MICRO[c]
                        } else {
                            r.volumetric(k) * 1e3
                        }
                    })
                    .collect()
            })
            .collect();
        let (name, unit) = if c < 6 {
            (COMPONENTS[c], UNITS[c])
        } else {
            ("|p|", "µm")
        };
        let heat = HeatMap {
            title: format!("{}: {name} ({unit}){at}", r.machine),
            cols: axes[a].clone(),
            rows: axes[b].clone(),
            values,
            diverging: c < 6,
            unit: unit.to_string(),
            size: HEAT_SIZE,
        };
        let stem = if c < 6 {
            format!("map_{}", COMPONENTS[c])
        } else {
            "map_volumetric".to_string()
        };
        figures.push(stem, super::Chart::Heat(heat));
    }
    figures.push("map_distortion", distortion(r, built, axes, a, b, &at));
}

/// The nominal and the magnified displaced grid.
fn distortion(
    r: &MapResult,
    built: &BuiltMachine<CompiledModel>,
    axes: &[(String, Vec<f64>)],
    a: usize,
    b: usize,
    at: &str,
) -> XyChart {
    let mid = middle(axes);
    let (na, nb) = (axes[a].1.len(), axes[b].1.len());
    // Nominal tool point and position error in the workpiece frame, per node.
    let mut nominal = vec![vec![[0.0; 3]; na]; nb];
    let mut error = vec![vec![[0.0; 3]; na]; nb];
    for j in 0..nb {
        for i in 0..na {
            let mut idx = mid.clone();
            idx[a] = i;
            idx[b] = j;
            let k = flat(&idx, axes);
            let pose = built.model().nominal(&r.point(k), built.parameters());
            let p = [r.errors[k][0], r.errors[k][1], r.errors[k][2]];
            let p = match r.frame {
                Frame::Workpiece => p,
                Frame::Tool => {
                    let m = &pose.rotation;
                    std::array::from_fn(|row| (0..3).map(|col| m[row][col] * p[col]).sum())
                }
            };
            nominal[j][i] = pose.position;
            error[j][i] = p;
        }
    }
    // The coordinate plane in which the nominal grid spreads most.
    let spread = |d: usize| {
        let (lo, hi) = nominal
            .iter()
            .flatten()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p[d]), hi.max(p[d]))
            });
        hi - lo
    };
    let mut dims = [0usize, 1, 2];
    dims.sort_by(|&x, &y| spread(y).total_cmp(&spread(x)));
    let (u, w) = (dims[0].min(dims[1]), dims[0].max(dims[1]));
    let coord = ["X", "Y", "Z"];
    // The grid lines drawn: at most MAX_LINES per direction, evenly spread
    // (the ends included), each through every node along it.
    let (order_a, order_b) = (sorted(&axes[a].1), sorted(&axes[b].1));
    let (lines_a, lines_b) = (thin(&order_a), thin(&order_b));
    // Magnification: the largest in-plane displacement about 0.4 of the
    // smallest distance between neighbouring drawn lines.
    let mut largest: f64 = 0.0;
    for row in &error {
        for e in row {
            largest = largest.max(e[u].hypot(e[w]));
        }
    }
    let distance = |(i, j): (usize, usize), (k, l): (usize, usize)| {
        let (p, q) = (nominal[j][i], nominal[l][k]);
        (p[u] - q[u]).hypot(p[w] - q[w])
    };
    let mut spacing = f64::INFINITY;
    for pair in lines_a.windows(2) {
        for &j in &order_b {
            spacing = spacing.min(distance((pair[0], j), (pair[1], j)));
        }
    }
    for pair in lines_b.windows(2) {
        for &i in &order_a {
            spacing = spacing.min(distance((i, pair[0]), (i, pair[1])));
        }
    }
    let magnification = if largest > 0.0 && spacing.is_finite() && spacing > 1e-9 {
        nice_below(0.4 * spacing / largest)
    } else {
        1.0
    };
    let shown =
        |p: [f64; 3], e: [f64; 3]| (p[u] + magnification * e[u], p[w] + magnification * e[w]);
    let mut chart = XyChart::new(
        format!(
            "{}: distorted grid{at}, displacement ×{} (grey: nominal)",
            r.machine,
            tick(magnification)
        ),
        format!("{} (mm, workpiece frame)", coord[u]),
        format!("{} (mm, workpiece frame)", coord[w]),
    );
    // Every nominal line first, then every displaced one on top.
    let lines: Vec<Vec<(usize, usize)>> = (lines_b.iter())
        .map(|&j| order_a.iter().map(|&i| (i, j)).collect())
        .chain(
            lines_a
                .iter()
                .map(|&i| order_b.iter().map(|&j| (i, j)).collect()),
        )
        .collect();
    for (k, pts) in lines.iter().enumerate() {
        let label = if k == 0 { "nominal" } else { "" };
        let nominal_pts = pts
            .iter()
            .map(|&(i, j)| (nominal[j][i][u], nominal[j][i][w]))
            .collect();
        chart = chart.series(Series::line(label, nominal_pts).color(GREY).width(1));
    }
    let displaced = format!("displaced ×{}", tick(magnification));
    for (k, pts) in lines.iter().enumerate() {
        let label = if k == 0 { displaced.as_str() } else { "" };
        let moved: Vec<(f64, f64)> = pts
            .iter()
            .map(|&(i, j)| shown(nominal[j][i], error[j][i]))
            .collect();
        // Markers only where the line has few nodes.
        let series = if moved.len() <= MAX_LINES {
            Series::line_points(label, moved)
        } else {
            Series::line(label, moved)
        };
        chart = chart.series(series.color(super::color(0)).width(2));
    }
    // Roughly equal scales on both axes.
    let (su, sw) = (spread(u).max(1e-9), spread(w).max(1e-9));
    let height = (1000.0 * sw / su + 120.0).clamp(500.0, 1300.0) as u32;
    chart.size = (1000, height);
    chart.legend(Legend::UpperRight)
}

/// At most this many grid lines per direction in the distorted grid.
const MAX_LINES: usize = 12;

/// At most [`MAX_LINES`] of `order` (indices by increasing value), evenly
/// spread, the first and the last included.
fn thin(order: &[usize]) -> Vec<usize> {
    let n = order.len();
    if n <= MAX_LINES {
        return order.to_vec();
    }
    // k·(n − 1)/(MAX_LINES − 1), rounded: distinct, since n > MAX_LINES.
    (0..MAX_LINES)
        .map(|k| order[(k * (n - 1) + (MAX_LINES - 1) / 2) / (MAX_LINES - 1)])
        .collect()
}

/// Indices of `values` by increasing value.
fn sorted(values: &[f64]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..values.len()).collect();
    order.sort_by(|&x, &y| values[x].total_cmp(&values[y]));
    order
}

/// The largest 1, 2 or 5 × 10^k not above `x` (`x > 0`).
fn nice_below(x: f64) -> f64 {
    let e = x.log10().floor();
    let base = 10f64.powf(e);
    let f = x / base;
    let m = if f >= 5.0 {
        5.0
    } else if f >= 2.0 {
        2.0
    } else {
        1.0
    };
    // Round away the float noise of powf (×5000, not ×4999.999…).
    let v = m * base;
    let digits = (-(e as i32)).max(0) as usize;
    format!("{v:.digits$}").parse().unwrap_or(v)
}

/// A number for a title or label: whole numbers without decimals.
fn tick(v: f64) -> String {
    if v == v.trunc() && v.abs() < 1e15 {
        format!("{}", v as i64)
    } else {
        let rounded: f64 = format!("{v:.9e}").parse().unwrap_or(v);
        format!("{rounded}")
    }
}

/// A heat map over two numeric axes, each cell centred on its node, with a
/// colour bar: diverging (ColorBrewer's RdBu) and symmetric about zero, or
/// viridis from zero.
#[derive(Debug, Clone, PartialEq)]
pub struct HeatMap {
    /// Caption above the map.
    pub title: String,
    /// The horizontal axis: name and values.
    pub cols: (String, Vec<f64>),
    /// The vertical axis.
    pub rows: (String, Vec<f64>),
    /// `values[row][col]`, in display units.
    pub values: Vec<Vec<f64>>,
    /// A scale symmetric about zero (signed components) or from zero
    /// (`|p|`).
    pub diverging: bool,
    /// The colour bar's unit.
    pub unit: String,
    /// Image size in pixels (SVG user units).
    pub size: (u32, u32),
}

fn err<E: std::fmt::Display>(e: E) -> String {
    e.to_string()
}

/// Cell edges around sorted values: midpoints, the ends half a step out.
fn edges(sorted: &[f64]) -> Vec<f64> {
    let n = sorted.len();
    if n == 1 {
        let half = if sorted[0] == 0.0 {
            0.5
        } else {
            0.05 * sorted[0].abs()
        };
        return vec![sorted[0] - half, sorted[0] + half];
    }
    let mut e = Vec::with_capacity(n + 1);
    e.push(sorted[0] - 0.5 * (sorted[1] - sorted[0]));
    for k in 1..n {
        e.push(0.5 * (sorted[k - 1] + sorted[k]));
    }
    e.push(sorted[n - 1] + 0.5 * (sorted[n - 1] - sorted[n - 2]));
    e
}

/// ColorBrewer's RdBu, blue for negative, white at zero, red for positive
/// (`t` in [−1, 1]).
fn diverging(t: f64) -> RGBColor {
    const STOPS: [(f64, f64, f64); 5] = [
        (33.0, 102.0, 172.0),
        (146.0, 197.0, 222.0),
        (247.0, 247.0, 247.0),
        (244.0, 165.0, 130.0),
        (178.0, 24.0, 43.0),
    ];
    ramp(&STOPS, 0.5 * (t + 1.0))
}

impl HeatMap {
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

fn heat_on<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, heat: &HeatMap) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(err)?;
    let (width, _) = root.dim_in_pixel();
    let (left, right) = root.split_horizontally(width.saturating_sub(150));
    let finite = || {
        heat.values
            .iter()
            .flatten()
            .copied()
            .filter(|v| v.is_finite())
    };
    let (lo, hi) = if heat.diverging {
        let l = finite().fold(0.0f64, |m, v| m.max(v.abs()));
        let l = if l > 0.0 { l } else { 1.0 };
        (-l, l)
    } else {
        let h = finite().fold(0.0f64, f64::max);
        (0.0, if h > 0.0 { h } else { 1.0 })
    };
    let colour = |v: f64| {
        if heat.diverging {
            diverging(v / hi)
        } else {
            viridis(v / hi)
        }
    };
    let (oc, orow) = (sorted(&heat.cols.1), sorted(&heat.rows.1));
    let sorted_cols: Vec<f64> = oc.iter().map(|&i| heat.cols.1[i]).collect();
    let sorted_rows: Vec<f64> = orow.iter().map(|&j| heat.rows.1[j]).collect();
    let (ec, er) = (edges(&sorted_cols), edges(&sorted_rows));
    let mut chart = ChartBuilder::on(&left)
        .caption(&heat.title, ("sans-serif", 22))
        .margin(20)
        .x_label_area_size(50)
        .y_label_area_size(80)
        .build_cartesian_2d(ec[0]..ec[ec.len() - 1], er[0]..er[er.len() - 1])
        .map_err(err)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(heat.cols.0.as_str())
        .y_desc(heat.rows.0.as_str())
        .x_label_formatter(&|v| tick(*v))
        .y_label_formatter(&|v| tick(*v))
        .label_style(("sans-serif", 15))
        .axis_desc_style(("sans-serif", 18))
        .draw()
        .map_err(err)?;
    chart
        .draw_series(orow.iter().enumerate().flat_map(|(sj, &j)| {
            let (er, ec) = (&er, &ec);
            oc.iter().enumerate().map(move |(si, &i)| {
                Rectangle::new(
                    [(ec[si], er[sj]), (ec[si + 1], er[sj + 1])],
                    colour(heat.values[j][i]).filled(),
                )
            })
        }))
        .map_err(err)?;
    // The colour bar.
    let mut bar = ChartBuilder::on(&right)
        .margin_top(60)
        .margin_bottom(70)
        .margin_right(10)
        .y_label_area_size(70)
        .set_label_area_size(LabelAreaPosition::Right, 0)
        .build_cartesian_2d(0.0..1.0, lo..hi)
        .map_err(err)?;
    bar.configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_desc(heat.unit.as_str())
        .y_label_formatter(&|v| tick(*v))
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 16))
        .draw()
        .map_err(err)?;
    let steps = 120;
    bar.draw_series((0..steps).map(|k| {
        let y0 = lo + (hi - lo) * f64::from(k) / f64::from(steps);
        let y1 = lo + (hi - lo) * f64::from(k + 1) / f64::from(steps);
        Rectangle::new([(0.0, y0), (1.0, y1)], colour(0.5 * (y0 + y1)).filled())
    }))
    .map_err(err)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn magnifications_are_one_two_five() {
        assert_eq!(nice_below(7300.0), 5000.0);
        assert_eq!(nice_below(4999.0), 2000.0);
        assert_eq!(nice_below(1.0), 1.0);
        assert_eq!(nice_below(0.031), 0.02);
        assert_eq!(edges(&[0.0, 100.0, 300.0]), [-50.0, 50.0, 200.0, 400.0]);
        let order: Vec<usize> = (0..41).collect();
        let t = thin(&order);
        assert!(
            t.len() <= MAX_LINES && t[0] == 0 && t[t.len() - 1] == 40,
            "{t:?}"
        );
        assert_eq!(thin(&[2, 0, 1]), [2, 0, 1]);
    }
}
