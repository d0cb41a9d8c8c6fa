//! The charts of every command's `--plot`, computed from the command's
//! document and drawn with [`plotters`] (feature `plot`).
//!
//! A chart is data ([`XyChart`], [`BarChart`], [`map::HeatMap`],
//! [`reliability::CellMap`], one [`Chart`]); each command's module builds
//! its [`Figures`] (the charts with their file stems, and the notes on
//! charts left out) from the command's `ops` document: [`map::charts`],
//! [`reliability::charts`], [`sensitivity::charts`], [`allocate::charts`],
//! [`path::charts`], [`motion::charts`], [`positioning::charts`],
//! [`compensate::charts`]. A chart is drawn as an SVG string in memory
//! ([`Chart::svg`], what a report inlines) or as a PNG file
//! ([`Chart::png`]); [`Figures::write`] writes both files of every chart
//! into a directory through the caller's [`Files`] (the CLI's writes each
//! file atomically; [`Direct`] writes it in place).
//!
//! Text is rendered with DejaVu Sans, embedded in the library (the `dejavu`
//! crate) and registered with plotters' `ab_glyph` renderer, so no system
//! font or fontconfig is needed.
//!
//! ```
//! use chain::plot::{Chart, Series, XyChart};
//! let chart = XyChart::new("Δθ", "θ (°)", "Δθ (°)")
//!     .series(Series::points("measured", vec![(1.0, 0.1), (2.0, 0.2)]))
//!     .series(Series::line("fit", vec![(1.0, 0.1), (2.0, 0.2)]))
//!     .hline(0.0);
//! let svg = Chart::from(chart).svg()?;
//! assert!(svg.starts_with("<svg"));
//! # Ok::<(), chain::plot::PlotError>(())
//! ```

pub mod allocate;
pub mod circular;
pub mod compensate;
pub mod geometric;
pub mod map;
pub mod motion;
pub mod path;
pub mod positioning;
pub mod reliability;
pub mod sensitivity;
pub mod thermal;

use std::path::{Path, PathBuf};
use std::sync::Once;

use plotters::coord::Shift;
use plotters::prelude::*;

pub use plotters::style::RGBColor;

/// A file-name-safe form of a name (a variable, a run): ASCII letters,
/// digits, `_` and `-` kept, anything else `_`.
pub fn file_stem(name: &str) -> String {
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

/// Neutral grey for measured data.
pub const GREY: RGBColor = RGBColor(90, 90, 90);

/// The Okabe-Ito colour-blind-safe palette (without its yellow, which is
/// unreadable on white), used in turn by [`color`].
pub const PALETTE: [RGBColor; 7] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(0, 0, 0),
];

/// A colour ramp through five stops, linearly interpolated; `t` in `[0, 1]`
/// (a non-finite `t` gives the first stop). The heat maps' one colour rule.
pub fn ramp(stops: &[(f64, f64, f64); 5], t: f64) -> RGBColor {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let x = t * 4.0;
    let i = (x.floor() as usize).min(3);
    let f = x - i as f64;
    let (a, b) = (stops[i], stops[i + 1]);
    let mix = |p: f64, q: f64| (p + (q - p) * f).round().clamp(0.0, 255.0) as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// The `i`-th colour of [`PALETTE`], cycling.
pub fn color(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// Errors of drawing a chart.
#[derive(Debug, thiserror::Error)]
#[cfg_attr(feature = "cli", derive(miette::Diagnostic))]
#[non_exhaustive]
pub enum PlotError {
    /// The output directory could not be created.
    #[error("{path}: cannot create the plot directory: {source}")]
    #[cfg_attr(feature = "cli", diagnostic(code(chain::plot::io)))]
    Io {
        /// The directory.
        path: String,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// A chart's file could not be written.
    #[error("{path}: cannot write the chart: {source}")]
    #[cfg_attr(feature = "cli", diagnostic(code(chain::plot::write)))]
    Write {
        /// The image file.
        path: String,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// Drawing or writing the image failed.
    #[error("{path}: cannot draw the chart: {message}")]
    #[cfg_attr(feature = "cli", diagnostic(code(chain::plot::draw)))]
    Draw {
        /// The image file (`<stem>.svg` for an SVG drawn in memory).
        path: String,
        /// What the backend said.
        message: String,
    },
    /// No series has a finite point.
    #[error("chart `{title}` has no finite data to draw")]
    #[cfg_attr(feature = "cli", diagnostic(code(chain::plot::no_data)))]
    NoData {
        /// The chart's title.
        title: String,
    },
}

/// One chart, as data.
#[derive(Debug, Clone, PartialEq)]
pub enum Chart {
    /// Line and scatter series on linear axes.
    Xy(XyChart),
    /// Bars of named values.
    Bar(BarChart),
    /// A heat map over two numeric axes with a colour bar (`chain map`).
    Heat(map::HeatMap),
    /// A map of labelled cells, each printed with its value (the
    /// reliability maps).
    Cells(reliability::CellMap),
    /// Line charts stacked in one figure, top to bottom (`chain thermal`:
    /// the drift above the temperatures, on one time axis).
    Stack(Vec<XyChart>),
}

impl From<XyChart> for Chart {
    fn from(chart: XyChart) -> Chart {
        Chart::Xy(chart)
    }
}

impl From<BarChart> for Chart {
    fn from(chart: BarChart) -> Chart {
        Chart::Bar(chart)
    }
}

impl Chart {
    /// The image size in pixels (SVG user units).
    pub fn size(&self) -> (u32, u32) {
        match self {
            Chart::Xy(c) => c.size,
            Chart::Bar(c) => c.size,
            Chart::Heat(c) => c.size,
            Chart::Cells(c) => c.size,
            Chart::Stack(cs) => (
                cs.iter().map(|c| c.size.0).max().unwrap_or(0),
                cs.iter().map(|c| c.size.1).sum(),
            ),
        }
    }

    /// Refuses a chart without data before anything is drawn.
    fn check(&self) -> Result<(), PlotError> {
        match self {
            Chart::Xy(c) => c.ranges().map(|_| ()),
            Chart::Stack(cs) => cs.iter().try_for_each(|c| c.ranges().map(|_| ())),
            _ => Ok(()),
        }
    }

    fn draw<DB: DrawingBackend>(&self, root: DrawingArea<DB, Shift>) -> Result<(), String>
    where
        DB::ErrorType: 'static,
    {
        // Presented once, when the whole chart is drawn: the SVG backend
        // closes its document there (a panel presenting its own area would
        // close it after the first panel, the others drawn after `</svg>`).
        let whole = root.clone();
        match self {
            Chart::Xy(c) => c.draw(root, c.ranges().map_err(|e| e.to_string())?)?,
            Chart::Bar(c) => c.draw(root)?,
            Chart::Heat(c) => c.draw(root)?,
            Chart::Cells(c) => c.draw(root)?,
            Chart::Stack(cs) => {
                // Each panel its own height, top to bottom.
                let mut rest = root;
                for c in cs {
                    let (top, below) = rest.split_vertically(c.size.1);
                    c.draw(top, c.ranges().map_err(|e| e.to_string())?)?;
                    rest = below;
                }
            }
        }
        whole.present().map_err(|e| e.to_string())
    }

    /// The chart as an SVG document, in memory.
    pub fn svg(&self) -> Result<String, PlotError> {
        self.svg_named("chart.svg")
    }

    /// The SVG, a drawing error naming `path`.
    fn svg_named(&self, path: &str) -> Result<String, PlotError> {
        self.check()?;
        ensure_fonts();
        let mut text = String::new();
        {
            let root = SVGBackend::with_string(&mut text, self.size()).into_drawing_area();
            self.draw(root).map_err(|message| PlotError::Draw {
                path: path.to_string(),
                message,
            })?;
        }
        Ok(text)
    }

    /// Draws the chart as a PNG file at `path` (the bitmap backend encodes
    /// it by the path's extension, which must be `png`).
    pub fn png(&self, path: &Path) -> Result<(), PlotError> {
        self.check()?;
        ensure_fonts();
        let root = BitMapBackend::new(path, self.size()).into_drawing_area();
        self.draw(root).map_err(|message| PlotError::Draw {
            path: path.display().to_string(),
            message,
        })
    }
}

/// A chart and the stem of its files.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// The file name without its extension, relative to the plot directory
    /// (`/` separates a subdirectory: `compensated/map_px`).
    pub stem: String,
    /// The chart.
    pub chart: Chart,
}

impl Figure {
    /// A chart with its stem.
    pub fn new(stem: impl Into<String>, chart: impl Into<Chart>) -> Figure {
        Figure {
            stem: stem.into(),
            chart: chart.into(),
        }
    }

    /// `dir/<stem>.<extension>`.
    fn path(&self, dir: &Path, extension: &str) -> PathBuf {
        let mut parts: Vec<&str> = self.stem.split('/').collect();
        let last = parts.pop().unwrap_or_default();
        let mut path = parts.iter().fold(dir.to_path_buf(), |p, s| p.join(s));
        path.push(format!("{last}.{extension}"));
        path
    }
}

/// The charts of one command's document, and the notes on those left out
/// (each a line `note: …`, for the caller to show).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Figures {
    /// The charts, in the order their files are written.
    pub figures: Vec<Figure>,
    /// Why a chart is missing (a map of one point, nothing tightened, no
    /// evaluated instant).
    pub notes: Vec<String>,
}

impl Figures {
    /// Adds a chart.
    pub fn push(&mut self, stem: impl Into<String>, chart: impl Into<Chart>) {
        self.figures.push(Figure::new(stem, chart));
    }

    /// Adds the charts and notes of `other`, its stems under `subdir`.
    pub fn nest(&mut self, subdir: &str, other: Figures) {
        self.figures
            .extend(other.figures.into_iter().map(|f| Figure {
                stem: format!("{subdir}/{}", f.stem),
                chart: f.chart,
            }));
        self.notes.extend(other.notes);
    }

    /// Writes every chart as `dir/<stem>.png` and `dir/<stem>.svg` (creating
    /// `dir` and the subdirectories the stems name), each file through
    /// `files`; returns the paths written, PNG before SVG, in chart order.
    pub fn write(&self, dir: &Path, files: &dyn Files) -> Result<Vec<PathBuf>, PlotError> {
        create_dir(dir)?;
        let mut written = Vec::with_capacity(2 * self.figures.len());
        for figure in &self.figures {
            let png = figure.path(dir, "png");
            let svg = figure.path(dir, "svg");
            if let Some(parent) = png.parent() {
                create_dir(parent)?;
            }
            files.write(&png, &mut |at| figure.chart.png(at))?;
            let text = figure.chart.svg_named(&svg.display().to_string())?;
            files.write(&svg, &mut |at| {
                std::fs::write(at, text.as_bytes()).map_err(|source| PlotError::Write {
                    path: svg.display().to_string(),
                    source,
                })
            })?;
            written.extend([png, svg]);
        }
        Ok(written)
    }
}

/// `dir` and its parents, created if missing.
fn create_dir(dir: &Path) -> Result<(), PlotError> {
    std::fs::create_dir_all(dir).map_err(|source| PlotError::Io {
        path: dir.display().to_string(),
        source,
    })
}

/// How [`Figures::write`] puts a file at `path`: `fill` writes the file at
/// the path it is given (the bitmap backend opens that path itself), which
/// may be a temporary one the implementation then moves to `path`.
pub trait Files {
    /// Writes `path` through `fill`.
    fn write(
        &self,
        path: &Path,
        fill: &mut dyn FnMut(&Path) -> Result<(), PlotError>,
    ) -> Result<(), PlotError>;
}

/// Writes each file in place, at its own path.
#[derive(Debug, Clone, Copy, Default)]
pub struct Direct;

impl Files for Direct {
    fn write(
        &self,
        path: &Path,
        fill: &mut dyn FnMut(&Path) -> Result<(), PlotError>,
    ) -> Result<(), PlotError> {
        fill(path)
    }
}

/// Viridis, five stops, linearly interpolated (`t` in [0, 1]).
pub fn viridis(t: f64) -> RGBColor {
    const STOPS: [(f64, f64, f64); 5] = [
        (68.0, 1.0, 84.0),
        (59.0, 82.0, 139.0),
        (33.0, 145.0, 140.0),
        (94.0, 201.0, 98.0),
        (253.0, 231.0, 37.0),
    ];
    ramp(&STOPS, t)
}

/// `((x_min, x_max), (y_min, y_max))` of a chart's axes.
type Ranges = ((f64, f64), (f64, f64));

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mark {
    /// A polyline through the points.
    Line,
    /// A filled circle at each point.
    Points,
    /// A polyline with a circle at each point.
    LinePoints,
}

/// One data series of an [`XyChart`].
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend text (`None`: not in the legend).
    pub label: Option<String>,
    /// The points; non-finite ones are skipped.
    pub points: Vec<(f64, f64)>,
    /// How the series is drawn.
    pub mark: Mark,
    /// Colour (`None`: the palette colour of the series' index).
    pub color: Option<RGBColor>,
    /// Line width in pixels.
    pub width: u32,
}

impl Series {
    fn new(label: impl Into<String>, points: Vec<(f64, f64)>, mark: Mark) -> Series {
        let label = label.into();
        Series {
            label: (!label.is_empty()).then_some(label),
            points,
            mark,
            color: None,
            width: 2,
        }
    }

    /// A line series (an empty label keeps it out of the legend).
    pub fn line(label: impl Into<String>, points: Vec<(f64, f64)>) -> Series {
        Series::new(label, points, Mark::Line)
    }

    /// A scatter series.
    pub fn points(label: impl Into<String>, points: Vec<(f64, f64)>) -> Series {
        Series::new(label, points, Mark::Points)
    }

    /// A line with a marker at each point.
    pub fn line_points(label: impl Into<String>, points: Vec<(f64, f64)>) -> Series {
        Series::new(label, points, Mark::LinePoints)
    }

    /// Sets the colour.
    pub fn color(mut self, color: RGBColor) -> Series {
        self.color = Some(color);
        self
    }

    /// Sets the line width (pixels).
    pub fn width(mut self, width: u32) -> Series {
        self.width = width.max(1);
        self
    }
}

/// Where the legend goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Legend {
    /// Inside the plot, upper right.
    #[default]
    UpperRight,
    /// Inside the plot, upper left.
    UpperLeft,
    /// Inside the plot, lower right.
    LowerRight,
    /// Inside the plot, lower left.
    LowerLeft,
}

/// A 2-D chart of line and scatter series on linear axes.
#[derive(Debug, Clone, PartialEq)]
pub struct XyChart {
    /// Caption above the plot.
    pub title: String,
    /// Horizontal axis description.
    pub x_label: String,
    /// Vertical axis description.
    pub y_label: String,
    /// The series, drawn in order.
    pub series: Vec<Series>,
    /// Horizontal reference lines (e.g. zero).
    pub hlines: Vec<f64>,
    /// Explicit x range (`None`: fitted to the data).
    pub x_range: Option<(f64, f64)>,
    /// Explicit y range (`None`: fitted to the data and reference lines).
    pub y_range: Option<(f64, f64)>,
    /// Legend placement.
    pub legend: Legend,
    /// Image size in pixels (SVG user units).
    pub size: (u32, u32),
}

impl XyChart {
    /// An empty 1000 × 640 chart.
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
    ) -> XyChart {
        XyChart {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            series: Vec::new(),
            hlines: Vec::new(),
            x_range: None,
            y_range: None,
            legend: Legend::default(),
            size: (1000, 640),
        }
    }

    /// Adds a series.
    pub fn series(mut self, series: Series) -> XyChart {
        self.series.push(series);
        self
    }

    /// Adds a horizontal reference line at `y`.
    pub fn hline(mut self, y: f64) -> XyChart {
        self.hlines.push(y);
        self
    }

    /// Fixes the y range.
    pub fn y_range(mut self, lo: f64, hi: f64) -> XyChart {
        self.y_range = Some((lo, hi));
        self
    }

    /// Sets the legend placement.
    pub fn legend(mut self, legend: Legend) -> XyChart {
        self.legend = legend;
        self
    }

    /// Axis ranges: the explicit ones, or the finite data padded by 3 % (x)
    /// and 8 % (y).
    fn ranges(&self) -> Result<Ranges, PlotError> {
        let finite = || {
            self.series
                .iter()
                .flat_map(|s| s.points.iter())
                .filter(|(x, y)| x.is_finite() && y.is_finite())
        };
        if finite().next().is_none() {
            return Err(PlotError::NoData {
                title: self.title.clone(),
            });
        }
        let span = |values: &mut dyn Iterator<Item = f64>, pad: f64| -> (f64, f64) {
            let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(v), hi.max(v))
            });
            let width = hi - lo;
            if width > 0.0 {
                (lo - pad * width, hi + pad * width)
            } else {
                let half = if lo == 0.0 { 1.0 } else { 0.1 * lo.abs() };
                (lo - half, hi + half)
            }
        };
        let x = self
            .x_range
            .filter(|(a, b)| a.is_finite() && b.is_finite() && a < b)
            .unwrap_or_else(|| span(&mut finite().map(|p| p.0), 0.03));
        let y = self
            .y_range
            .filter(|(a, b)| a.is_finite() && b.is_finite() && a < b)
            .unwrap_or_else(|| {
                span(
                    &mut finite()
                        .map(|p| p.1)
                        .chain(self.hlines.iter().copied().filter(|v| v.is_finite())),
                    0.08,
                )
            });
        Ok((x, y))
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: DrawingArea<DB, Shift>,
        ((x0, x1), (y0, y1)): Ranges,
    ) -> Result<(), String> {
        let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
        root.fill(&WHITE).map_err(err)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(&self.title, ("sans-serif", 24).into_font())
            .margin(16)
            .x_label_area_size(50)
            .y_label_area_size(80)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc(self.x_label.as_str())
            .y_desc(self.y_label.as_str())
            .label_style(("sans-serif", 15))
            .axis_desc_style(("sans-serif", 17))
            .x_label_formatter(&|v| tick_label(*v, x0, x1))
            .y_label_formatter(&|v| tick_label(*v, y0, y1))
            .light_line_style(RGBColor(235, 235, 235))
            .bold_line_style(RGBColor(210, 210, 210))
            .draw()
            .map_err(err)?;
        for &y in self
            .hlines
            .iter()
            .filter(|y| y.is_finite() && **y >= y0 && **y <= y1)
        {
            chart
                .draw_series(LineSeries::new(
                    [(x0, y), (x1, y)],
                    BLACK.mix(0.55).stroke_width(1),
                ))
                .map_err(err)?;
        }
        let mut labelled = false;
        for (i, s) in self.series.iter().enumerate() {
            let colour = s.color.unwrap_or_else(|| color(i));
            let points: Vec<(f64, f64)> = s
                .points
                .iter()
                .copied()
                .filter(|(x, y)| x.is_finite() && y.is_finite())
                .collect();
            let line_style = colour.stroke_width(s.width);
            let radius = (s.width + 2).min(6) as i32;
            let anno = match s.mark {
                Mark::Line => chart
                    .draw_series(LineSeries::new(points, line_style))
                    .map_err(err)?,
                Mark::Points => chart
                    .draw_series(
                        points
                            .into_iter()
                            .map(|p| Circle::new(p, radius, colour.filled())),
                    )
                    .map_err(err)?,
                Mark::LinePoints => {
                    chart
                        .draw_series(LineSeries::new(points.iter().copied(), line_style))
                        .map_err(err)?;
                    chart
                        .draw_series(
                            points
                                .into_iter()
                                .map(|p| Circle::new(p, radius, colour.filled())),
                        )
                        .map_err(err)?
                }
            };
            if let Some(label) = &s.label {
                labelled = true;
                let mark = s.mark;
                anno.label(label.as_str()).legend(move |(x, y)| {
                    let line = PathElement::new(
                        vec![(x, y), (x + 24, y)],
                        match mark {
                            Mark::Points => colour.mix(0.0).stroke_width(1),
                            _ => colour.stroke_width(3),
                        },
                    );
                    let dot = Circle::new(
                        (x + 12, y),
                        if mark == Mark::Line { 0 } else { 4 },
                        colour.filled(),
                    );
                    EmptyElement::at((0, 0)) + line + dot
                });
            }
        }
        let position = match self.legend {
            Legend::UpperRight => SeriesLabelPosition::UpperRight,
            Legend::UpperLeft => SeriesLabelPosition::UpperLeft,
            Legend::LowerRight => SeriesLabelPosition::LowerRight,
            Legend::LowerLeft => SeriesLabelPosition::LowerLeft,
        };
        if labelled {
            chart
                .configure_series_labels()
                .position(position)
                .background_style(WHITE.mix(0.9))
                .border_style(RGBColor(160, 160, 160))
                .label_font(("sans-serif", 15))
                .draw()
                .map_err(err)?;
        }
        Ok(())
    }
}

/// A tick label without float noise or trailing zeros: `5`, `0.25`, `0`
/// (never `-0.0`), rounded to 10 significant digits.
fn tick_label(v: f64, lo: f64, hi: f64) -> String {
    if v.abs() <= 1e-9 * lo.abs().max(hi.abs()) {
        return "0".to_string();
    }
    let rounded: f64 = format!("{v:.9e}").parse().unwrap_or(v);
    format!("{rounded}")
}

/// Registers the embedded DejaVu Sans under the generic family names plotters
/// uses (`sans-serif`, `serif`, `monospace`). Idempotent; the drawing
/// functions call it.
pub fn ensure_fonts() {
    static FONTS: Once = Once::new();
    FONTS.call_once(|| {
        for family in ["sans-serif", "serif", "monospace"] {
            // The embedded font is a valid TrueType file; a failure here would
            // only mean that text is missing from the charts.
            let _ =
                plotters::style::register_font(family, FontStyle::Normal, dejavu::sans::regular());
            let _ = plotters::style::register_font(family, FontStyle::Bold, dejavu::sans::bold());
        }
    });
}

/// A bar chart of named values (sensitivities, shares), bars in the given
/// order, drawn to PNG and SVG like [`XyChart`].
#[derive(Debug, Clone, PartialEq)]
pub struct BarChart {
    /// Caption above the plot.
    pub title: String,
    /// Vertical axis description.
    pub y_label: String,
    /// One label per bar (the horizontal axis).
    pub labels: Vec<String>,
    /// One value per bar; negative and non-finite values draw no bar.
    pub values: Vec<f64>,
    /// Bar colour.
    pub color: RGBColor,
    /// Decimals of the value printed above each bar (`None`: no value labels).
    pub value_decimals: Option<usize>,
    /// Image size in pixels (SVG user units).
    pub size: (u32, u32),
}

impl BarChart {
    /// A 1000 × 600 chart in the first palette colour, without value labels.
    pub fn new(
        title: impl Into<String>,
        y_label: impl Into<String>,
        labels: Vec<String>,
        values: Vec<f64>,
    ) -> BarChart {
        BarChart {
            title: title.into(),
            y_label: y_label.into(),
            labels,
            values,
            color: color(0),
            value_decimals: None,
            size: (1000, 600),
        }
    }

    fn draw<DB: DrawingBackend>(&self, root: DrawingArea<DB, Shift>) -> Result<(), String>
    where
        DB::ErrorType: 'static,
    {
        use plotters::coord::ranged1d::SegmentValue;
        use plotters::style::text_anchor::{HPos, Pos, VPos};
        let err = |e: &dyn std::fmt::Display| e.to_string();
        root.fill(&WHITE).map_err(|e| err(&e))?;
        let n = self.values.len().max(1);
        let top = self
            .values
            .iter()
            .copied()
            .filter(|v| v.is_finite())
            .fold(0.0f64, f64::max);
        let top = if top > 0.0 { top * 1.1 } else { 1.0 };
        let mut chart = ChartBuilder::on(&root)
            .caption(&self.title, ("sans-serif", 22))
            .margin(20)
            .x_label_area_size(50)
            .y_label_area_size(80)
            .build_cartesian_2d((0..n - 1).into_segmented(), 0.0..top)
            .map_err(|e| err(&e))?;
        let label = |v: &SegmentValue<usize>| match v {
            SegmentValue::CenterOf(j) => self.labels.get(*j).cloned().unwrap_or_default(),
            _ => String::new(),
        };
        chart
            .configure_mesh()
            .disable_x_mesh()
            .x_labels(n)
            .x_label_formatter(&label)
            .x_desc("error parameter")
            .y_desc(self.y_label.as_str())
            .label_style(("sans-serif", 13))
            .axis_desc_style(("sans-serif", 16))
            .draw()
            .map_err(|e| err(&e))?;
        let bars: Vec<(usize, f64)> = self
            .values
            .iter()
            .copied()
            .enumerate()
            .filter(|(_, v)| v.is_finite() && *v > 0.0)
            .collect();
        let rect = |j: usize, v: f64| {
            [
                (SegmentValue::Exact(j), 0.0),
                (SegmentValue::Exact(j + 1), v),
            ]
        };
        chart
            .draw_series(
                bars.iter()
                    .map(|&(j, v)| Rectangle::new(rect(j, v), self.color.filled())),
            )
            .map_err(|e| err(&e))?;
        // White outlines keep neighbouring bars apart.
        chart
            .draw_series(
                bars.iter()
                    .map(|&(j, v)| Rectangle::new(rect(j, v), WHITE.stroke_width(3))),
            )
            .map_err(|e| err(&e))?;
        if let Some(decimals) = self.value_decimals {
            chart
                .draw_series(bars.iter().map(|&(j, v)| {
                    Text::new(
                        format!("{v:.decimals$}"),
                        (SegmentValue::CenterOf(j), v + top * 0.01),
                        ("sans-serif", 13)
                            .into_font()
                            .color(&BLACK)
                            .pos(Pos::new(HPos::Center, VPos::Bottom)),
                    )
                }))
                .map_err(|e| err(&e))?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A stacked chart is one SVG document: its panels inside the one
    /// `<svg>`, closed once at the end (a panel presenting its own area
    /// closed the document after the first panel).
    #[test]
    fn a_stack_is_one_svg_document() {
        let panel = |title: &str| {
            XyChart::new(title, "t", "v").series(Series::line("a", vec![(0.0, 1.0), (1.0, 2.0)]))
        };
        let chart = Chart::Stack(vec![panel("top"), panel("bottom")]);
        let svg = chart.svg().unwrap();
        assert_eq!(svg.matches("<svg").count(), 1);
        assert_eq!(svg.matches("</svg>").count(), 1);
        assert!(
            svg.trim_end().ends_with("</svg>"),
            "{}",
            &svg[svg.len() - 200..]
        );
        assert!(svg.contains(">\ntop\n<") && svg.contains(">\nbottom\n<"));
    }
}
