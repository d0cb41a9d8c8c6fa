//! An ISO 230-4 circular test (a telescoping ballbar, or a grid encoder):
//! the run file and its evaluation (`../shared/spec/circular.md`;
//! `docs/circular.md`).
//!
//! A run file holds, per sample, the nominal angle `θ` on the circle
//! (degrees, from the plane's first axis towards its second), the direction
//! of travel and the radial deviation `Δr` (the measured radius less the
//! nominal `R`). [`CircularTest::parse`] reads and checks it (every refusal
//! located by file, line and column) and groups the samples by run and
//! direction; [`evaluate`] gives per run and direction the least-squares
//! circle (ISO 230-4's LSC centre), the circular deviation `G` about it and
//! the radial deviations `F_max`, `F_min` against the nominal radius, and
//! for a run with both directions the bidirectional circular deviation
//! `G(b)` and the circular hysteresis `H`.

use serde::Serialize;

pub mod diagnosis;
pub mod records;

use crate::diagnostic::Diagnostics;
#[cfg(feature = "csv")]
use crate::diagnostic::{CircularProblem, Problem};
#[cfg(feature = "csv")]
use crate::model::Origin;

/// Circular-test files larger than this are refused.
pub const MAX_CIRCULAR_BYTES: usize = crate::bounded::MEASUREMENT_BYTES;

/// The fewest distinct angles a direction of a run needs.
pub const MIN_SAMPLES: usize = 8;

/// The shortest arc a run may cover (degrees): shorter, its circle is not
/// determined (ISO 230-4 arcs are 90° or more).
pub const MIN_ARC: f64 = 45.0;

/// The largest radial deviation as a part of the radius: a ballbar's are
/// micrometres on a radius of 50 mm or more; a tenth of the radius is a
/// wrong unit (µm read as mm) or a wrong radius.
pub const MAX_DEVIATION_PART: f64 = 0.1;

/// The widest gap between neighbouring angles of a direction (degrees):
/// wider, the trace does not show what happens there (a ballbar samples
/// every degree or less).
pub const MAX_GAP: f64 = 10.0;

/// The direction of travel around the circle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Direction {
    /// Counter-clockwise: `θ` increasing.
    Ccw,
    /// Clockwise: `θ` decreasing.
    Cw,
}

impl Direction {
    /// `ccw` or `cw`.
    pub fn name(self) -> &'static str {
        match self {
            Direction::Ccw => "ccw",
            Direction::Cw => "cw",
        }
    }
}

/// The plane of the circle: its first and second axes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Plane {
    /// X then Y.
    Xy,
    /// Y then Z.
    Yz,
    /// Z then X.
    Zx,
}

impl Plane {
    /// `xy`, `yz` or `zx`.
    pub fn name(self) -> &'static str {
        match self {
            Plane::Xy => "xy",
            Plane::Yz => "yz",
            Plane::Zx => "zx",
        }
    }

    /// The plane named `text` (`xy`, `yz`, `zx`, any case).
    pub fn parse(text: &str) -> Option<Plane> {
        match text.to_ascii_lowercase().as_str() {
            "xy" => Some(Plane::Xy),
            "yz" => Some(Plane::Yz),
            "zx" => Some(Plane::Zx),
            _ => None,
        }
    }

    /// The indices (0 = X, 1 = Y, 2 = Z) of its first and second axes.
    pub fn axes(self) -> [usize; 2] {
        match self {
            Plane::Xy => [0, 1],
            Plane::Yz => [1, 2],
            Plane::Zx => [2, 0],
        }
    }
}

/// One sample of a run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// The nominal angle (degrees), as written.
    pub angle: f64,
    /// The radial deviation (mm).
    pub deviation: f64,
    /// Its line in the file.
    pub line: usize,
}

/// One run: a circle of one radius, feed and plane, in one or both
/// directions.
#[derive(Debug, Clone, PartialEq)]
pub struct Run {
    /// Its identifier (the `run` column; `1` for a file without one).
    pub id: String,
    /// The plane.
    pub plane: Plane,
    /// The nominal radius (mm).
    pub radius: f64,
    /// The feed (mm/min), when given.
    pub feed: Option<f64>,
    /// The counter-clockwise samples, in file order.
    pub ccw: Vec<Sample>,
    /// The clockwise samples, in file order.
    pub cw: Vec<Sample>,
}

impl Run {
    /// The sample points of direction `d`: per sample its angle (degrees)
    /// and its measured radius `R + Δr` (mm).
    pub fn points(&self, d: Direction) -> Vec<(f64, f64)> {
        (self.samples(d).iter())
            .map(|s| (s.angle, self.radius + s.deviation))
            .collect()
    }

    /// The samples of direction `d`.
    pub fn samples(&self, d: Direction) -> &[Sample] {
        match d {
            Direction::Ccw => &self.ccw,
            Direction::Cw => &self.cw,
        }
    }
}

/// What the command line gives for every run (a column of the file wins).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunOptions {
    /// `--radius` (mm).
    pub radius: Option<f64>,
    /// `--feed` (mm/min).
    pub feed: Option<f64>,
    /// `--plane` (default `xy`).
    pub plane: Plane,
    /// `--arc` (degrees, default 360): the arc every direction covers.
    pub arc: f64,
}

impl Default for RunOptions {
    fn default() -> RunOptions {
        RunOptions {
            radius: None,
            feed: None,
            plane: Plane::Xy,
            arc: 360.0,
        }
    }
}

/// A circular-test file: its runs in order of first appearance.
#[derive(Debug, Clone, PartialEq)]
pub struct CircularTest {
    /// The file as named in messages.
    pub file: String,
    /// The runs.
    pub runs: Vec<Run>,
    /// The arc each direction covers (degrees).
    pub arc: f64,
}

/// Why a circular-test file was refused: its problems, located.
#[derive(Debug, thiserror::Error)]
#[cfg_attr(feature = "miette", derive(miette::Diagnostic))]
#[error(transparent)]
#[cfg_attr(feature = "miette", diagnostic(transparent))]
pub struct CircularFileError(pub Diagnostics);

impl CircularFileError {
    /// The located problems.
    pub fn diagnostics(&self) -> &Diagnostics {
        &self.0
    }
}

/// The columns of a run file (indices in the header).
#[cfg(feature = "csv")]
struct Columns {
    angle: usize,
    direction: usize,
    deviation: usize,
    /// Millimetres per unit of the deviation column.
    scale: f64,
    run: Option<usize>,
    radius: Option<usize>,
    feed: Option<usize>,
    plane: Option<usize>,
}

/// One row read: (run, direction, sample, radius, feed, plane), each of the
/// last three with its cell's origin when the file gives it.
#[cfg(feature = "csv")]
type Row = (
    String,
    Direction,
    Sample,
    Option<(f64, Origin)>,
    Option<(f64, Origin)>,
    Option<(Plane, Origin)>,
);

#[cfg(feature = "csv")]
impl CircularTest {
    /// Reads a circular-test file (CSV; spec `circular.md`).
    pub fn read(
        path: &std::path::Path,
        options: &RunOptions,
    ) -> Result<CircularTest, CircularFileError> {
        let file = path.display().to_string();
        let bytes =
            crate::load::read_file(path, &file, MAX_CIRCULAR_BYTES).map_err(CircularFileError)?;
        let text = crate::load::decode(&bytes, &file).map_err(CircularFileError)?;
        CircularTest::parse(text, &file, options)
    }

    /// [`CircularTest::read`] over CSV text named `file`.
    pub fn parse(
        text: &str,
        file: &str,
        options: &RunOptions,
    ) -> Result<CircularTest, CircularFileError> {
        let csv = crate::values::csv::CsvFile::parse_with(
            text,
            file,
            crate::diagnostic::CIRCULAR_FILE_HEADER,
        )
        .map_err(CircularFileError)?;
        let fail = |problems: Vec<(Origin, Problem)>| {
            CircularFileError(Diagnostics::located(file, text, problems).expect("a problem"))
        };
        let header = csv.header_origin();
        let names: Vec<String> = csv.names().map(str::to_string).collect();
        let find = |name: &'static str| csv.column(name);
        let missing = |name: &'static str| {
            (
                header.clone(),
                CircularProblem::MissingColumn {
                    name,
                    columns: names.clone(),
                }
                .into(),
            )
        };
        let mut problems = Vec::new();
        let angle = find("angle").or_else(|| find("angle(deg)"));
        let direction = find("direction");
        let deviation = [
            ("deviation", 1.0),
            ("deviation(mm)", 1.0),
            ("deviation(um)", 1e-3),
        ]
        .into_iter()
        .find_map(|(n, s)| find(n).map(|c| (c, s)));
        if angle.is_none() {
            problems.push(missing("angle"));
        }
        if direction.is_none() {
            problems.push(missing("direction"));
        }
        if deviation.is_none() {
            problems.push(missing("deviation"));
        }
        if !problems.is_empty() {
            return Err(fail(problems));
        }
        let (deviation, scale) = deviation.expect("checked");
        let columns = Columns {
            angle: angle.expect("checked"),
            direction: direction.expect("checked"),
            deviation,
            scale,
            run: find("run"),
            radius: find("radius").or_else(|| find("radius(mm)")),
            feed: find("feed").or_else(|| find("feed(mm/min)")),
            plane: find("plane"),
        };
        let rows = csv.read_rows(|row| read_row(row, &columns)).map_err(fail)?;
        let runs = group(rows, options, &header).map_err(fail)?;
        Ok(CircularTest {
            file: file.to_string(),
            runs,
            arc: options.arc,
        })
    }
}

/// One row of the file, its cells checked.
#[cfg(feature = "csv")]
fn read_row(row: &[(String, Origin)], c: &Columns) -> Result<Row, Box<(Origin, Problem)>> {
    let number = |k: usize| {
        let (text, origin) = &row[k];
        crate::tabular::number(text, &origin.key)
            .map_err(|p| Box::new((origin.clone(), Problem::from(p))))
    };
    let positive =
        |k: usize, what: &'static str| -> Result<(f64, Origin), Box<(Origin, Problem)>> {
            let x = number(k)?;
            if x > 0.0 {
                Ok((x, row[k].1.clone()))
            } else {
                Err(Box::new((
                    row[k].1.clone(),
                    CircularProblem::NotPositive { what, value: x }.into(),
                )))
            }
        };
    let angle = number(c.angle)?;
    let (text, origin) = &row[c.direction];
    let direction = match text.to_ascii_lowercase().as_str() {
        "ccw" => Direction::Ccw,
        "cw" => Direction::Cw,
        _ => {
            let problem = CircularProblem::Direction {
                found: text.clone(),
            };
            return Err(Box::new((origin.clone(), problem.into())));
        }
    };
    let deviation = number(c.deviation)? * c.scale;
    let run = c.run.map_or_else(|| "1".to_string(), |k| row[k].0.clone());
    let radius = c.radius.map(|k| positive(k, "radius")).transpose()?;
    let feed = c.feed.map(|k| positive(k, "feed")).transpose()?;
    let plane = match c.plane {
        Some(k) => {
            let (text, origin) = &row[k];
            match Plane::parse(text) {
                Some(p) => Some((p, origin.clone())),
                None => {
                    let problem = CircularProblem::Plane {
                        found: text.clone(),
                    };
                    return Err(Box::new((origin.clone(), problem.into())));
                }
            }
        }
        None => None,
    };
    let sample = Sample {
        angle,
        deviation,
        line: origin.line,
    };
    Ok((run, direction, sample, radius, feed, plane))
}

/// The rows grouped into runs (in order of first appearance), each run's
/// radius, feed and plane one value, and each direction covering its arc.
#[cfg(feature = "csv")]
fn group(
    rows: Vec<Row>,
    options: &RunOptions,
    header: &Origin,
) -> Result<Vec<Run>, Vec<(Origin, Problem)>> {
    struct Building {
        run: Run,
        radius: Option<(f64, usize)>,
        feed: Option<(f64, usize)>,
        plane: Option<(Plane, usize)>,
        first: Origin,
    }
    let mut runs: Vec<Building> = Vec::new();
    let mut problems: Vec<(Origin, Problem)> = Vec::new();
    for (id, direction, sample, radius, feed, plane) in rows {
        let k = match runs.iter().position(|b| b.run.id == id) {
            Some(k) => k,
            None => {
                runs.push(Building {
                    run: Run {
                        id: id.clone(),
                        plane: options.plane,
                        radius: f64::NAN,
                        feed: options.feed,
                        ccw: Vec::new(),
                        cw: Vec::new(),
                    },
                    radius: None,
                    feed: None,
                    plane: None,
                    first: Origin {
                        line: sample.line,
                        ..header.clone()
                    },
                });
                runs.len() - 1
            }
        };
        let b = &mut runs[k];
        // One radius, feed and plane per run: each row's as its first's.
        let mut same =
            |what: &'static str, value: String, first: Option<(String, usize)>, origin: &Origin| {
                if let Some((f, line)) = first.filter(|(f, _)| *f != value) {
                    problems.push((
                        origin.clone(),
                        CircularProblem::RunDiffers {
                            what,
                            value,
                            first: f,
                            first_line: line,
                            run: id.clone(),
                        }
                        .into(),
                    ));
                }
            };
        if let Some((r, o)) = radius {
            same(
                "radius",
                r.to_string(),
                b.radius.map(|(v, l)| (v.to_string(), l)),
                &o,
            );
            b.radius.get_or_insert((r, o.line));
        }
        if let Some((f, o)) = feed {
            same(
                "feed",
                f.to_string(),
                b.feed.map(|(v, l)| (v.to_string(), l)),
                &o,
            );
            b.feed.get_or_insert((f, o.line));
        }
        if let Some((p, o)) = plane {
            let first = b.plane.map(|(v, l)| (v.name().to_string(), l));
            same("plane", p.name().to_string(), first, &o);
            b.plane.get_or_insert((p, o.line));
        }
        match direction {
            Direction::Ccw => b.run.ccw.push(sample),
            Direction::Cw => b.run.cw.push(sample),
        }
    }
    let mut out = Vec::with_capacity(runs.len());
    for b in runs {
        let mut run = b.run;
        match b.radius.map(|(r, _)| r).or(options.radius) {
            Some(r) => run.radius = r,
            None => problems.push((
                header.clone(),
                CircularProblem::NoRadius {
                    run: run.id.clone(),
                }
                .into(),
            )),
        }
        if let Some((f, _)) = b.feed {
            run.feed = Some(f);
        }
        if let Some((p, _)) = b.plane {
            run.plane = p;
        }
        for d in [Direction::Ccw, Direction::Cw] {
            let samples = run.samples(d);
            if samples.is_empty() {
                continue;
            }
            let at = Origin {
                line: samples[0].line,
                ..b.first.clone()
            };
            let mut angles: Vec<f64> = samples.iter().map(|s| s.angle.rem_euclid(360.0)).collect();
            angles.sort_by(f64::total_cmp);
            angles.dedup();
            let large = (samples.iter()).find(|s| {
                run.radius.is_finite() && s.deviation.abs() >= MAX_DEVIATION_PART * run.radius
            });
            if let Some(s) = large {
                problems.push((
                    Origin {
                        line: s.line,
                        ..b.first.clone()
                    },
                    CircularProblem::TooLarge {
                        deviation: s.deviation,
                        radius: run.radius,
                    }
                    .into(),
                ));
            } else if angles.len() < MIN_SAMPLES {
                problems.push((
                    at,
                    CircularProblem::TooFewSamples {
                        run: run.id.clone(),
                        direction: d.name(),
                        count: angles.len(),
                    }
                    .into(),
                ));
            } else if let Some((from, to)) = widest_gap(samples, options.arc) {
                problems.push((
                    at,
                    CircularProblem::NotCovered {
                        run: run.id.clone(),
                        direction: d.name(),
                        from,
                        to,
                        arc: options.arc,
                        allowed: MAX_GAP,
                    }
                    .into(),
                ));
            }
        }
        out.push(run);
    }
    if problems.is_empty() {
        Ok(out)
    } else {
        problems.sort_by_key(|(o, _)| o.line);
        Err(problems)
    }
}

/// The gap `(from, to)` (degrees) that keeps `samples` from covering `arc`,
/// if one does: for the whole circle the widest gap between neighbouring
/// angles taken modulo 360° (the last to the first around); for a part of
/// it, the widest between neighbouring angles as written, or the arc's
/// shortfall past the last. Allowed: [`MAX_GAP`].
pub fn widest_gap(samples: &[Sample], arc: f64) -> Option<(f64, f64)> {
    if samples.is_empty() {
        return Some((0.0, arc));
    }
    let allowed = MAX_GAP;
    let full = arc >= 360.0;
    let mut a: Vec<f64> = samples
        .iter()
        .map(|s| {
            if full {
                s.angle.rem_euclid(360.0)
            } else {
                s.angle
            }
        })
        .collect();
    a.sort_by(f64::total_cmp);
    let mut widest = (0.0, (a[0], a[0]));
    for w in a.windows(2) {
        if w[1] - w[0] > widest.0 {
            widest = (w[1] - w[0], (w[0], w[1]));
        }
    }
    let (first, last) = (a[0], a[a.len() - 1]);
    if full {
        let around = first + 360.0 - last;
        if around > widest.0 {
            widest = (around, (last, first + 360.0));
        }
    } else if last - first < arc - allowed {
        let short = (last, first + arc);
        if short.1 - short.0 > widest.0 {
            widest = (short.1 - short.0, short);
        }
    }
    (widest.0 > allowed).then_some(widest.1)
}

/// The least-squares circle through points given by their angle (degrees)
/// and radius: centre `(c₁, c₂)` (mm, along the plane's first and second
/// axes) and radius, minimising `Σ (|p_i − c| − ρ)²` (ISO 230-4's LSC),
/// by Gauss-Newton from the one-harmonic linear fit
/// `Δr ≈ c₁ cos θ + c₂ sin θ + ρ − R` (its first-order form).
fn least_squares_circle(points: &[(f64, f64)]) -> ([f64; 2], f64) {
    use nalgebra::{Matrix3, Vector3};
    let xy: Vec<(f64, f64, f64, f64)> = points
        .iter()
        .map(|&(deg, r)| {
            let (s, c) = deg.to_radians().sin_cos();
            (r * c, r * s, c, s)
        })
        .collect();
    // The linear start: r ≈ c₁ cos θ + c₂ sin θ + ρ.
    let mut a = Matrix3::zeros();
    let mut b = Vector3::zeros();
    for (&(_, r), &(_, _, c, s)) in points.iter().zip(&xy) {
        let row = Vector3::new(c, s, 1.0);
        a += row * row.transpose();
        b += row * r;
    }
    let mut x = a.lu().solve(&b).unwrap_or_else(Vector3::zeros);
    for _ in 0..20 {
        let mut jtj = Matrix3::zeros();
        let mut jtf = Vector3::zeros();
        for &(px, py, _, _) in &xy {
            let (dx, dy) = (px - x[0], py - x[1]);
            let d = dx.hypot(dy);
            let f = d - x[2];
            let j = Vector3::new(-dx / d, -dy / d, -1.0);
            jtj += j * j.transpose();
            jtf += j * f;
        }
        let Some(step) = jtj.lu().solve(&(-jtf)) else {
            break;
        };
        x += step;
        if step.norm() <= 1e-15 * x[2].abs().max(1.0) {
            break;
        }
    }
    ([x[0], x[1]], x[2])
}

/// The radii of `points` (angle in degrees, radius) about `centre`.
fn radii_about(points: &[(f64, f64)], centre: [f64; 2]) -> Vec<f64> {
    points
        .iter()
        .map(|&(deg, r)| {
            let (s, c) = deg.to_radians().sin_cos();
            (r * c - centre[0]).hypot(r * s - centre[1])
        })
        .collect()
}

/// The trace of direction `d` of `run` about `centre` (mm, as
/// [`DirectionResult::centre`]): per sample its angle (degrees, as written)
/// and its radial deviation from the nominal radius about that centre (mm,
/// what `F_max` and `F_min` bound), in file order.
pub fn trace(run: &Run, d: Direction, centre: [f64; 2]) -> Vec<(f64, f64)> {
    let points = run.points(d);
    let radii = radii_about(&points, centre);
    (points.iter().zip(radii))
        .map(|(&(deg, _), r)| (deg, r - run.radius))
        .collect()
}

/// One direction of a run evaluated (ISO 230-4, the LSC centre).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DirectionResult {
    /// The circular deviation `G` (mm): the radial range of the path about
    /// its least-squares centre.
    #[serde(rename = "G")]
    pub g: f64,
    /// The largest radial deviation from the nominal radius about that
    /// centre (mm).
    #[serde(rename = "F_max")]
    pub f_max: f64,
    /// The smallest (mm; negative inside the nominal circle).
    #[serde(rename = "F_min")]
    pub f_min: f64,
    /// The least-squares centre (mm), along the plane's first and second
    /// axes, from the nominal centre (the set-up offset removed).
    pub centre: [f64; 2],
    /// The least-squares radius less the nominal radius (mm).
    pub radius_offset: f64,
    /// Its samples.
    pub samples: usize,
}

/// The two directions of a run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Directions {
    /// Counter-clockwise, when measured.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ccw: Option<DirectionResult>,
    /// Clockwise, when measured.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cw: Option<DirectionResult>,
}

/// One run evaluated.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunResult {
    /// The run's identifier.
    pub run: String,
    /// The plane.
    pub plane: Plane,
    /// The nominal radius (mm).
    pub radius: f64,
    /// The feed (mm/min), when given.
    pub feed: Option<f64>,
    /// Each direction's evaluation.
    pub directions: Directions,
    /// The bidirectional circular deviation `G(b)` (mm): the radial range
    /// of both paths about the least-squares centre of both (a run with
    /// both directions).
    #[serde(rename = "G_b")]
    pub g_b: Option<f64>,
    /// The circular hysteresis `H` (mm): the largest radial difference
    /// between the two paths at one angle (each clockwise radius
    /// interpolated linearly in angle at the counter-clockwise samples'
    /// angles, both about the common centre).
    #[serde(rename = "H")]
    pub h: Option<f64>,
    /// The least-squares centre of both paths (mm), when both are measured.
    pub centre_both: Option<[f64; 2]>,
}

/// Evaluates every run of `test`.
pub fn evaluate(test: &CircularTest) -> Vec<RunResult> {
    test.runs
        .iter()
        .map(|r| evaluate_run(r, test.arc))
        .collect()
}

/// Evaluates one run (its directions covering `arc` degrees).
pub fn evaluate_run(run: &Run, arc: f64) -> RunResult {
    let (ccw, cw) = (run.points(Direction::Ccw), run.points(Direction::Cw));
    let one = |p: &[(f64, f64)]| {
        if p.is_empty() {
            return None;
        }
        let (centre, rho) = least_squares_circle(p);
        let radii = radii_about(p, centre);
        let (lo, hi) = range(&radii);
        Some(DirectionResult {
            g: hi - lo,
            f_max: hi - run.radius,
            f_min: lo - run.radius,
            centre,
            radius_offset: rho - run.radius,
            samples: p.len(),
        })
    };
    let directions = Directions {
        ccw: one(&ccw),
        cw: one(&cw),
    };
    let (mut g_b, mut h, mut centre_both) = (None, None, None);
    if directions.ccw.is_some() && directions.cw.is_some() {
        let both: Vec<(f64, f64)> = ccw.iter().chain(&cw).copied().collect();
        let (centre, _) = least_squares_circle(&both);
        let (lo, hi) = range(&radii_about(&both, centre));
        g_b = Some(hi - lo);
        h = hysteresis(
            &ccw,
            &radii_about(&ccw, centre),
            &cw,
            &radii_about(&cw, centre),
            arc,
        );
        centre_both = Some(centre);
    }
    RunResult {
        run: run.id.clone(),
        plane: run.plane,
        radius: run.radius,
        feed: run.feed,
        directions,
        g_b,
        h,
        centre_both,
    }
}

/// The least and largest of `values`.
fn range(values: &[f64]) -> (f64, f64) {
    values
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        })
}

/// `H`: the largest `|r_ccw(θ) − r_cw(θ)|` over the counter-clockwise
/// samples' angles where the clockwise path has samples on both sides
/// (around the circle when `arc` is the whole of it).
fn hysteresis(
    ccw: &[(f64, f64)],
    r_ccw: &[f64],
    cw: &[(f64, f64)],
    r_cw: &[f64],
    arc: f64,
) -> Option<f64> {
    let full = arc >= 360.0;
    let key = |deg: f64| if full { deg.rem_euclid(360.0) } else { deg };
    let mut line: Vec<(f64, f64)> = cw.iter().zip(r_cw).map(|(p, &r)| (key(p.0), r)).collect();
    line.sort_by(|a, b| a.0.total_cmp(&b.0));
    if full {
        // Closed around: the last before the first, the first after the last.
        let (first, last) = (line[0], line[line.len() - 1]);
        line.insert(0, (last.0 - 360.0, last.1));
        line.push((first.0 + 360.0, first.1));
    }
    let mut worst: Option<f64> = None;
    for (p, &r) in ccw.iter().zip(r_ccw) {
        let t = key(p.0);
        let k = line.partition_point(|q| q.0 <= t);
        if k == 0 || k == line.len() {
            continue;
        }
        let (a, b) = (line[k - 1], line[k]);
        let at = if b.0 > a.0 {
            a.1 + (b.1 - a.1) * (t - a.0) / (b.0 - a.0)
        } else {
            a.1
        };
        let d = (r - at).abs();
        worst = Some(worst.map_or(d, |w: f64| w.max(d)));
    }
    worst
}

#[cfg(all(test, feature = "csv"))]
mod tests {
    use super::*;

    /// A run file of `n` samples per direction: `f(θ, ccw)` the deviation.
    fn file(n: usize, f: impl Fn(f64, bool) -> f64) -> String {
        let mut s = String::from("angle,direction,deviation(um)\n");
        for (dir, ccw) in [("ccw", true), ("cw", false)] {
            for k in 0..n {
                let t = if ccw {
                    360.0 * k as f64 / n as f64
                } else {
                    360.0 - 360.0 * k as f64 / n as f64
                };
                s.push_str(&format!("{t},{dir},{}\n", 1e3 * f(t, ccw)));
            }
        }
        s
    }

    fn options() -> RunOptions {
        RunOptions {
            radius: Some(100.0),
            ..RunOptions::default()
        }
    }

    /// A set-up offset (c₁, c₂) on an otherwise perfect circle: the exact
    /// radial deviation of the offset circle, `√(R² − (c×u)²) + c·u − R`.
    /// The LSC recovers the offset and G, F are zero.
    #[test]
    fn an_offset_circle_is_centred_and_round() {
        let (c1, c2, r) = (0.012, -0.007, 100.0);
        let text = file(720, |t, _| {
            let (s, c) = t.to_radians().sin_cos();
            let along = c1 * c + c2 * s;
            let across = -c1 * s + c2 * c;
            (r * r - across * across).sqrt() + along - r
        });
        let test = CircularTest::parse(&text, "t.csv", &options()).unwrap();
        let out = evaluate(&test);
        let d = out[0].directions.ccw.as_ref().unwrap();
        assert!(
            (d.centre[0] - c1).abs() < 1e-12 && (d.centre[1] - c2).abs() < 1e-12,
            "{d:?}"
        );
        assert!(
            d.g < 1e-12 && d.f_max.abs() < 1e-12 && d.f_min.abs() < 1e-12,
            "{d:?}"
        );
        assert!(out[0].g_b.unwrap() < 1e-12 && out[0].h.unwrap() < 1e-12);
    }

    /// An ellipse `Δr = A cos 2θ` about the nominal centre: G = 2A,
    /// F = ±A; the other direction shifted by a constant `s` (a pure
    /// radius change): H = s and G(b) = 2A + s.
    #[test]
    fn an_ellipse_and_a_shifted_return_give_g_f_h_and_g_b() {
        let (a, s) = (0.004, 0.0015);
        let text = file(1440, |t, ccw| {
            a * (2.0 * t.to_radians()).cos() + if ccw { 0.0 } else { s }
        });
        let test = CircularTest::parse(&text, "t.csv", &options()).unwrap();
        let r = &evaluate(&test)[0];
        let ccw = r.directions.ccw.as_ref().unwrap();
        // First order: the ellipse's own second-order terms are (A/R)²·R.
        assert!((ccw.g - 2.0 * a).abs() < 1e-9, "{ccw:?}");
        assert!((ccw.f_max - a).abs() < 1e-9 && (ccw.f_min + a).abs() < 1e-9);
        assert!(ccw.centre[0].abs() < 1e-9 && ccw.centre[1].abs() < 1e-9);
        let cw = r.directions.cw.as_ref().unwrap();
        assert!((cw.radius_offset - s).abs() < 1e-9, "{cw:?}");
        assert!((r.h.unwrap() - s).abs() < 1e-9, "{r:?}");
        assert!((r.g_b.unwrap() - (2.0 * a + s)).abs() < 1e-9, "{r:?}");
    }

    #[test]
    fn refusals_are_located() {
        let bad = |text: &str, o: &RunOptions| {
            CircularTest::parse(text, "b.csv", o)
                .unwrap_err()
                .to_string()
        };
        let ok = file(72, |_, _| 0.0);
        // No radius.
        let e = bad(&ok, &RunOptions::default());
        assert!(e.contains("run 1 has no radius"), "{e}");
        // A missing column.
        let e = bad("angle,deviation\n0,1\n", &options());
        assert!(e.contains("no `direction` column"), "{e}");
        // An unknown direction, at its line.
        let broken = ok.replacen("0,ccw,", "0,up,", 1);
        let e = bad(&broken, &options());
        assert!(
            e.contains("`up` is not a direction") && e.contains("b.csv:2:"),
            "{e}"
        );
        // A gap: the ccw samples from 90° to 180° dropped.
        let gap: String = ok
            .lines()
            .filter(|l| {
                let t: f64 = l.split(',').next().unwrap().parse().unwrap_or(-1.0);
                !(l.contains(",ccw,") && t > 90.0 && t < 180.0)
            })
            .map(|l| format!("{l}\n"))
            .collect();
        let e = bad(&gap, &options());
        assert!(e.contains("no sample between 90° and 180°"), "{e}");
        // ... which a 90° arc does not need.
        let arc = "angle,direction,deviation\n".to_string()
            + &(0..=18)
                .flat_map(|k| {
                    [
                        format!("{},ccw,0\n", 5 * k),
                        format!("{},cw,0\n", 90 - 5 * k),
                    ]
                })
                .collect::<String>();
        let o = RunOptions {
            arc: 90.0,
            ..options()
        };
        assert!(CircularTest::parse(&arc, "a.csv", &o).is_ok());
        // A run whose radius changes.
        let two = "angle,direction,deviation,radius\n".to_string()
            + &(0..40)
                .map(|k| format!("{},ccw,0,{}\n", 9 * k, if k == 4 { 150 } else { 100 }))
                .collect::<String>();
        let e = bad(&two, &RunOptions::default());
        assert!(
            e.contains("radius 150 differs from its first row's 100 (line 2)"),
            "{e}"
        );
        // A non-finite deviation names its column.
        let e = bad(&ok.replacen("0,ccw,0", "0,ccw,nan", 1), &options());
        assert!(e.contains("deviation(um)"), "{e}");
    }
}
