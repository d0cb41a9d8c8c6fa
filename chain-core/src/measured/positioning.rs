//! Positioning runs of one axis and their ISO 230-2 evaluation
//! (`../shared/spec/positioning.md`; `docs/positioning.md`).
//!
//! A run file lists, for each target position `P_i` of an axis, the
//! deviation `x_ij = P_ij − P_i` reached in run `j` when the target was
//! approached moving up (↑) and moving down (↓). [`Runs`] holds them, read and
//! checked from CSV by [`Runs::read`] / [`Runs::parse`] (every refusal located
//! by file, line and column) or built from Rust by [`Runs::new`].
//! [`evaluate`] computes the statistics of ISO 230-2:2014 clause 2 (the
//! 1997 and 2006 editions use the same formulas) with coverage factor `k`
//! into a [`PositioningDocument`], the JSON document of `chain positioning`.
//!
//! Symbols (ISO 230-2:2014, 2.1-2.24; `n` runs per direction, `m` targets):
//!
//! - `x̄_i↑ = (1/n) Σ_j x_ij↑`, `x̄_i↓` likewise (2.12);
//! - `x̄_i = (x̄_i↑ + x̄_i↓)/2` (2.13);
//! - `B_i = x̄_i↑ − x̄_i↓` (2.14), `B = max |B_i|` (2.15),
//!   `B̄ = (1/m) Σ B_i` (2.16);
//! - `s_i↑ = √(Σ_j (x_ij↑ − x̄_i↑)² / (n − 1))`, `s_i↓` likewise (2.17);
//! - `R_i↑ = 2k·s_i↑`, `R_i↓` (2.18),
//!   `R_i = max(k·s_i↑ + k·s_i↓ + |B_i|, R_i↑, R_i↓)` (2.19);
//!   `R↑ = max R_i↑`, `R↓`, `R = max R_i` (2.20-2.21);
//! - `E↑ = max x̄_i↑ − min x̄_i↑`, `E↓` (2.22),
//!   `E = max(x̄_i↑, x̄_i↓) − min(x̄_i↑, x̄_i↓)` (2.23);
//! - `M = max x̄_i − min x̄_i` (2.24);
//! - `A↑ = max(x̄_i↑ + k·s_i↑) − min(x̄_i↑ − k·s_i↑)`, `A↓` (2.10),
//!   `A = max(x̄_i↑ + k·s_i↑, x̄_i↓ + k·s_i↓) − min(x̄_i↑ − k·s_i↑, x̄_i↓ − k·s_i↓)`
//!   (2.11).

use serde::{Serialize, Serializer};

use crate::diagnostic::Diagnostics;
#[cfg(feature = "csv")]
use crate::diagnostic::{closest, PositioningProblem as P, Problem};
#[cfg(feature = "csv")]
use crate::model::Origin;

/// Run files larger than this are refused.
pub const MAX_RUNS_BYTES: usize = crate::bounded::MEASUREMENT_BYTES;

/// Arcseconds in one degree: a rotary axis's deviations (degrees in the run
/// file) are reported in arcseconds.
pub const ARCSEC_PER_DEGREE: f64 = 3600.0;

/// The largest run number accepted.
#[cfg(feature = "csv")]
const MAX_RUN: f64 = 1e6;

/// The columns a run file may have.
pub const COLUMNS: [&str; 5] = ["target", "direction", "run", "measured", "deviation"];

/// The approach direction of a target.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Direction {
    /// Approached moving in the positive direction (ISO ↑).
    Up,
    /// Approached moving in the negative direction (ISO ↓).
    Down,
}

impl Direction {
    /// Both directions, up first.
    pub const BOTH: [Direction; 2] = [Direction::Up, Direction::Down];

    /// `up`, `down`, `+` or `-` (case-insensitive words).
    pub fn parse(text: &str) -> Option<Direction> {
        match text.to_ascii_lowercase().as_str() {
            "up" | "+" => Some(Direction::Up),
            "down" | "-" => Some(Direction::Down),
            _ => None,
        }
    }

    /// `up` or `down`.
    pub fn name(self) -> &'static str {
        match self {
            Direction::Up => "up",
            Direction::Down => "down",
        }
    }
}

/// The kind of axis: what the targets and deviations are measured in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum AxisKind {
    /// Targets and deviations in mm; statistics in mm.
    #[default]
    Linear,
    /// Targets and deviations in degrees in the run file; statistics in
    /// arcseconds.
    Rotary,
}

impl AxisKind {
    /// The unit of the statistics: `mm` or `arcsec`.
    pub fn unit(self) -> Unit {
        match self {
            AxisKind::Linear => Unit::Mm,
            AxisKind::Rotary => Unit::Arcsec,
        }
    }

    /// `linear` or `rotary`.
    pub fn name(self) -> &'static str {
        match self {
            AxisKind::Linear => "linear",
            AxisKind::Rotary => "rotary",
        }
    }

    /// The unit of the targets (and of the run file's values): `mm` or `deg`.
    pub fn target_unit(self) -> &'static str {
        match self {
            AxisKind::Linear => "mm",
            AxisKind::Rotary => "deg",
        }
    }
}

/// The unit of a positioning document's deviations and statistics.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Unit {
    /// Millimetres (a linear axis).
    Mm,
    /// Arcseconds (a rotary axis).
    Arcsec,
}

impl Unit {
    /// `mm` or `arcsec`.
    pub fn name(self) -> &'static str {
        match self {
            Unit::Mm => "mm",
            Unit::Arcsec => "arcsec",
        }
    }
}

/// The deviations of one target.
#[derive(Debug, Clone, PartialEq)]
pub struct TargetRuns {
    /// The target position `P_i` (mm, or degrees on a rotary axis).
    pub target: f64,
    /// `x_ij↑`, run `j` at index `j − 1` (in the run file's unit).
    pub up: Vec<f64>,
    /// `x_ij↓`, run `j` at index `j − 1`.
    pub down: Vec<f64>,
}

/// The positioning runs of one axis: every target approached `n` times from
/// each direction.
#[derive(Debug, Clone, PartialEq)]
pub struct Runs {
    /// The run file as named in messages (empty when built from Rust).
    pub file: String,
    /// Linear (mm) or rotary (degrees).
    pub kind: AxisKind,
    /// The targets in ascending order.
    pub targets: Vec<TargetRuns>,
}

/// Why runs built from Rust were refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum RunsError {
    /// Fewer than two targets.
    #[error("{count} target(s): an ISO 230-2 run needs at least 2 targets")]
    TooFewTargets {
        /// How many there are.
        count: usize,
    },
    /// Fewer than two runs per direction.
    #[error("{count} run(s) per direction: the standard uncertainty needs at least 2")]
    TooFewRuns {
        /// How many there are.
        count: usize,
    },
    /// A target whose directions or whose run count differ from the first
    /// target's.
    #[error("target {target} has {up} run(s) up and {down} down; every target and direction needs {runs}")]
    Unequal {
        /// The target.
        target: f64,
        /// Its runs up.
        up: usize,
        /// Its runs down.
        down: usize,
        /// The first target's runs per direction.
        runs: usize,
    },
    /// A target given twice.
    #[error("target {target} is given twice")]
    Repeated {
        /// The target.
        target: f64,
    },
    /// A non-finite target or deviation.
    #[error("target {target}: a target or deviation is not finite")]
    NotFinite {
        /// The target (possibly non-finite itself).
        target: f64,
    },
}

impl Runs {
    /// Runs from Rust: per target `(P_i, x_i↑ per run, x_i↓ per run)`, in any
    /// order (sorted here), deviations in mm (degrees for
    /// [`AxisKind::Rotary`]). Refused: fewer than 2 targets or runs, a target
    /// twice, unequal run counts, non-finite values.
    pub fn new(kind: AxisKind, targets: Vec<(f64, Vec<f64>, Vec<f64>)>) -> Result<Runs, RunsError> {
        let mut out: Vec<TargetRuns> = Vec::with_capacity(targets.len());
        for (target, up, down) in targets {
            if !target.is_finite() || up.iter().chain(&down).any(|x| !x.is_finite()) {
                return Err(RunsError::NotFinite { target });
            }
            out.push(TargetRuns { target, up, down });
        }
        out.sort_by(|a, b| a.target.total_cmp(&b.target));
        if let Some(w) = out.windows(2).find(|w| w[0].target == w[1].target) {
            return Err(RunsError::Repeated {
                target: w[0].target,
            });
        }
        if out.len() < 2 {
            return Err(RunsError::TooFewTargets { count: out.len() });
        }
        let runs = out[0].up.len().max(out[0].down.len());
        for t in &out {
            if t.up.len() != runs || t.down.len() != runs {
                return Err(RunsError::Unequal {
                    target: t.target,
                    up: t.up.len(),
                    down: t.down.len(),
                    runs,
                });
            }
        }
        if runs < 2 {
            return Err(RunsError::TooFewRuns { count: runs });
        }
        Ok(Runs {
            file: String::new(),
            kind,
            targets: out,
        })
    }

    /// Runs per direction (`n`).
    pub fn runs(&self) -> usize {
        self.targets.first().map_or(0, |t| t.up.len())
    }
}

/// Why a run file was refused: its problems, located (file, line, column,
/// column name).
#[derive(Debug, thiserror::Error)]
#[cfg_attr(feature = "miette", derive(miette::Diagnostic))]
#[error(transparent)]
#[cfg_attr(feature = "miette", diagnostic(transparent))]
pub struct RunsFileError(pub Diagnostics);

impl RunsFileError {
    /// The located problems.
    pub fn diagnostics(&self) -> &Diagnostics {
        &self.0
    }
}

#[cfg(feature = "csv")]
impl Runs {
    /// Reads a run file (CSV; spec `positioning.md`).
    pub fn read(path: &std::path::Path, kind: AxisKind) -> Result<Runs, RunsFileError> {
        let file = path.display().to_string();
        let bytes = crate::load::read_file(path, &file, MAX_RUNS_BYTES).map_err(RunsFileError)?;
        let text = crate::load::decode(&bytes, &file).map_err(RunsFileError)?;
        Runs::parse(text, &file, kind)
    }

    /// [`Runs::read`] over CSV text named `file`.
    pub fn parse(text: &str, file: &str, kind: AxisKind) -> Result<Runs, RunsFileError> {
        let csv =
            crate::values::csv::CsvFile::parse_with(text, file, crate::diagnostic::RUN_FILE_HEADER)
                .map_err(RunsFileError)?;
        let fail = |problems: Vec<(Origin, Problem)>| {
            RunsFileError(Diagnostics::located(file, text, problems).expect("a problem"))
        };
        let columns = RunColumns::classify(&csv).map_err(fail)?;
        // (target, direction, run) → (value, origin of the row's first cell).
        let cells: Vec<Cell> = csv.read_rows(|row| columns.cell(row)).map_err(fail)?;
        group(cells, kind, file).map_err(|p| fail(vec![*p]))
    }
}

/// One row of a run file.
#[cfg(feature = "csv")]
#[derive(Debug, Clone)]
struct Cell {
    target: f64,
    direction: Direction,
    run: usize,
    /// The deviation `x_ij` (run file's unit).
    deviation: f64,
    /// The origins of the row's target and run cells.
    target_origin: Origin,
    run_origin: Origin,
}

/// Where each quantity is in a run file's columns.
#[cfg(feature = "csv")]
struct RunColumns {
    target: usize,
    direction: usize,
    run: usize,
    /// The value column and whether it holds `measured` (`P_ij`) rather than
    /// `deviation` (`x_ij`).
    value: (usize, bool),
}

#[cfg(feature = "csv")]
type Located = Box<(Origin, Problem)>;

#[cfg(feature = "csv")]
fn located(origin: &Origin, problem: impl Into<Problem>) -> Located {
    Box::new((origin.clone(), problem.into()))
}

#[cfg(feature = "csv")]
impl RunColumns {
    fn classify(csv: &crate::values::csv::CsvFile) -> Result<RunColumns, Vec<(Origin, Problem)>> {
        let mut problems = Vec::new();
        for (name, origin) in &csv.header {
            if !COLUMNS.contains(&name.as_str()) {
                let problem = P::UnknownColumn {
                    column: name.clone(),
                    suggestion: closest(name, COLUMNS.iter().copied()).map(str::to_string),
                };
                problems.push((origin.clone(), problem.into()));
            }
        }
        let header = csv.header_origin();
        let find = |name: &str| csv.column(name);
        let mut missing = Vec::new();
        for name in ["target", "direction", "run"] {
            if find(name).is_none() {
                missing.push(name);
            }
        }
        let mut no_value = false;
        let value = match (find("measured"), find("deviation")) {
            (Some(m), None) => Some((m, true)),
            (None, Some(d)) => Some((d, false)),
            (Some(m), Some(d)) => {
                problems.push(*located(&csv.header[m.max(d)].1, P::BothValueColumns));
                None
            }
            (None, None) => {
                no_value = true;
                None
            }
        };
        if !missing.is_empty() || no_value {
            let problem = P::MissingColumns {
                columns: missing,
                value: no_value,
            };
            problems.push(*located(&header, problem));
        }
        match (find("target"), find("direction"), find("run"), value) {
            (Some(target), Some(direction), Some(run), Some(value)) if problems.is_empty() => {
                Ok(RunColumns {
                    target,
                    direction,
                    run,
                    value,
                })
            }
            _ => Err(problems),
        }
    }

    fn cell(&self, row: &[(String, Origin)]) -> Result<Cell, Located> {
        let number = |c: usize| -> Result<f64, Located> {
            let (text, origin) = &row[c];
            crate::tabular::number(text, &origin.key).map_err(|problem| located(origin, problem))
        };
        let target = number(self.target)?;
        let (dtext, dorigin) = &row[self.direction];
        let direction = Direction::parse(dtext).ok_or_else(|| {
            let text = dtext.clone();
            located(dorigin, P::Direction { text })
        })?;
        let (rtext, rorigin) = &row[self.run];
        // A whole number ≥ 1, also as a spreadsheet writes it (`2.0`).
        let run = match rtext.parse::<f64>() {
            Ok(j) if (1.0..=MAX_RUN).contains(&j) && j == j.trunc() => j as usize,
            _ => {
                let text = rtext.clone();
                return Err(located(rorigin, P::Run { text }));
            }
        };
        let (column, measured) = self.value;
        let value = number(column)?;
        let deviation = if measured { value - target } else { value };
        if !deviation.is_finite() {
            let cell = row[column].0.clone();
            return Err(located(&row[column].1, P::DeviationNotFinite { cell }));
        }
        Ok(Cell {
            target,
            direction,
            run,
            deviation,
            target_origin: row[self.target].1.clone(),
            run_origin: rorigin.clone(),
        })
    }
}

/// Groups the rows by target, checks the run structure and builds [`Runs`].
#[cfg(feature = "csv")]
fn group(mut cells: Vec<Cell>, kind: AxisKind, file: &str) -> Result<Runs, Located> {
    // Stable: rows of one (target, direction) keep their file order.
    cells.sort_by(|a, b| {
        (a.target.total_cmp(&b.target))
            .then(a.direction.cmp(&b.direction))
            .then(a.run.cmp(&b.run))
    });
    for w in cells.windows(2) {
        if w[0].target == w[1].target && w[0].direction == w[1].direction && w[0].run == w[1].run {
            let (first, second) = if w[0].run_origin.line <= w[1].run_origin.line {
                (&w[0], &w[1])
            } else {
                (&w[1], &w[0])
            };
            let problem = P::Repeated {
                target: first.target,
                direction: first.direction,
                run: first.run,
                first_line: first.run_origin.line,
            };
            return Err(located(&second.run_origin, problem));
        }
    }
    // One chunk per target, its up rows first (sorted above).
    let targets: Vec<(&[Cell], &[Cell])> = cells
        .chunk_by(|a, b| a.target == b.target)
        .map(|rows| rows.split_at(rows.partition_point(|c| c.direction == Direction::Up)))
        .collect();
    // A target's first row in the file: where its problems are reported.
    fn first_of<'a>(t: &(&'a [Cell], &'a [Cell])) -> &'a Cell {
        (t.0.iter().chain(t.1))
            .min_by_key(|c| c.target_origin.line)
            .expect("a chunk has a row")
    }
    if targets.len() < 2 {
        let only = first_of(&targets[0]);
        let problem = P::TooFewTargets {
            count: targets.len(),
            target: only.target,
        };
        return Err(located(&only.target_origin, problem));
    }
    // n: the most runs any (target, direction) has; each must have 1..=n.
    let runs = targets
        .iter()
        .flat_map(|(u, d)| [u.len(), d.len()])
        .max()
        .unwrap_or(0);
    for t in &targets {
        for (dir, list) in Direction::BOTH.iter().zip([t.0, t.1]) {
            let missing = (1..=runs).find(|j| !list.iter().any(|c| c.run == *j));
            if let Some(j) = missing {
                let first = first_of(t);
                let problem = P::UnequalRuns {
                    target: first.target,
                    up: t.0.len(),
                    down: t.1.len(),
                    missing: j,
                    direction: *dir,
                    runs,
                };
                return Err(located(&first.target_origin, problem));
            }
        }
    }
    if runs < 2 {
        let first = first_of(&targets[0]);
        return Err(located(&first.run_origin, P::TooFewRuns { runs }));
    }
    let targets = targets
        .iter()
        .map(|t| TargetRuns {
            target: first_of(t).target,
            up: t.0.iter().map(|c| c.deviation).collect(),
            down: t.1.iter().map(|c| c.deviation).collect(),
        })
        .collect();
    Ok(Runs {
        file: file.to_string(),
        kind,
        targets,
    })
}

/// The coverage factor `k` of the statistics: 2 (ISO 230-2 since 1997) or 3
/// (the 1988 edition, VDI/DGQ 3441); any finite value > 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coverage(f64);

/// A coverage factor that is not a finite number > 0.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error("the coverage factor k must be a finite number > 0, not {0}")]
pub struct CoverageError(pub f64);

impl Coverage {
    /// ISO 230-2:1997-2014's `k` = 2.
    pub const ISO: Coverage = Coverage(2.0);

    /// `k`, if finite and > 0.
    pub fn new(k: f64) -> Result<Coverage, CoverageError> {
        if k.is_finite() && k > 0.0 {
            Ok(Coverage(k))
        } else {
            Err(CoverageError(k))
        }
    }

    /// The value.
    pub fn get(self) -> f64 {
        self.0
    }
}

/// `2`, `3`, `2.5`: as the user wrote it (Rust prints a whole `f64` without
/// a fraction).
impl std::fmt::Display for Coverage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.0.fmt(f)
    }
}

impl Default for Coverage {
    fn default() -> Coverage {
        Coverage::ISO
    }
}

impl Serialize for Coverage {
    /// A whole `k` as an integer (`"k": 2`, as the spec writes it).
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        if self.0 == self.0.trunc() && self.0.abs() < 1e15 {
            s.serialize_i64(self.0 as i64)
        } else {
            s.serialize_f64(self.0)
        }
    }
}

/// The statistics of one target (spec `positioning.md`; ISO 230-2:2014
/// 2.12-2.19), in the document's unit.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TargetStats {
    /// `P_i` (mm, or degrees on a rotary axis).
    pub target: f64,
    /// `x̄_i↑`.
    pub mean_up: f64,
    /// `x̄_i↓`.
    pub mean_down: f64,
    /// `x̄_i = (x̄_i↑ + x̄_i↓)/2`.
    pub mean: f64,
    /// `B_i = x̄_i↑ − x̄_i↓`.
    pub reversal: f64,
    /// `s_i↑` (n − 1 in the denominator).
    pub s_up: f64,
    /// `s_i↓`.
    pub s_down: f64,
    /// `R_i↑ = 2k·s_i↑`.
    pub repeatability_up: f64,
    /// `R_i↓ = 2k·s_i↓`.
    pub repeatability_down: f64,
    /// `R_i = max(k·s_i↑ + k·s_i↓ + |B_i|, R_i↑, R_i↓)`.
    pub repeatability: f64,
}

/// The statistics of the axis (spec `positioning.md`; ISO 230-2:2014
/// 2.10-2.24), in the document's unit.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[allow(non_snake_case)]
pub struct AxisStats {
    /// Bidirectional accuracy `A`.
    pub A: f64,
    /// Unidirectional accuracy `A↑`.
    pub A_up: f64,
    /// `A↓`.
    pub A_down: f64,
    /// Bidirectional systematic positional deviation `E`.
    pub E: f64,
    /// `E↑`.
    pub E_up: f64,
    /// `E↓`.
    pub E_down: f64,
    /// Range of the mean bidirectional positional deviation `M`.
    pub M: f64,
    /// Bidirectional repeatability `R = max R_i`.
    pub R: f64,
    /// `R↑ = max R_i↑`.
    pub R_up: f64,
    /// `R↓ = max R_i↓`.
    pub R_down: f64,
    /// Reversal value `B = max |B_i|`.
    pub B: f64,
    /// Mean reversal value `B̄` (signed mean of the `B_i`).
    pub B_mean: f64,
}

/// One run's points: the deviation at each target (for the plot and the CSV).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunPoints {
    /// `up` or `down`.
    pub direction: Direction,
    /// `j`.
    pub run: usize,
    /// `x_ij` at each target, in target order (document's unit).
    pub deviations: Vec<f64>,
}

/// The result of `chain positioning` (spec `positioning.md`, "Output"):
/// `k`, `runs`, `unit`, `targets`, `axis` as the spec defines them, then
/// the additions of `docs/positioning.md` (`axis_kind`, `target_unit`,
/// `file`, and every run's points).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PositioningDocument {
    /// The coverage factor.
    pub k: Coverage,
    /// Runs per direction `n`.
    pub runs: usize,
    /// The unit of every deviation and statistic: `mm` or `arcsec`.
    pub unit: Unit,
    /// Per target, ascending.
    pub targets: Vec<TargetStats>,
    /// The axis values.
    pub axis: AxisStats,
    /// `linear` or `rotary`.
    pub axis_kind: &'static str,
    /// The unit of the targets: `mm` or `deg`.
    pub target_unit: &'static str,
    /// The run file (empty when the runs came from Rust or Python arrays).
    pub file: String,
    /// Every run's deviations, up runs first.
    pub points: Vec<RunPoints>,
    /// The correction to 20 °C, when the runs were corrected
    /// (`positioning_temperature`): every deviation above is corrected.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub temperature: Option<super::positioning_temperature::TemperatureCorrection>,
}

/// The mean of `x` (2.12).
fn mean(x: &[f64]) -> f64 {
    x.iter().sum::<f64>() / x.len() as f64
}

/// The estimator of the standard uncertainty (2.17): `n − 1` in the
/// denominator, about the mean (two passes).
fn std_dev(x: &[f64], mean: f64) -> f64 {
    let ss: f64 = x.iter().map(|v| (v - mean) * (v - mean)).sum();
    (ss / (x.len() - 1) as f64).sqrt()
}

/// `max − min` of the values.
fn range(values: impl Iterator<Item = f64> + Clone) -> f64 {
    let max = values.clone().fold(f64::NEG_INFINITY, f64::max);
    let min = values.fold(f64::INFINITY, f64::min);
    max - min
}

/// The ISO 230-2 evaluation of `runs` with coverage factor `k`.
pub fn evaluate(runs: &Runs, k: Coverage) -> PositioningDocument {
    let kf = k.get();
    let scale = match runs.kind {
        AxisKind::Linear => 1.0,
        AxisKind::Rotary => ARCSEC_PER_DEGREE,
    };
    let scaled = |x: &[f64]| -> Vec<f64> { x.iter().map(|v| v * scale).collect() };
    let targets: Vec<TargetStats> = runs
        .targets
        .iter()
        .map(|t| {
            let (up, down) = (scaled(&t.up), scaled(&t.down));
            let (mean_up, mean_down) = (mean(&up), mean(&down));
            let (s_up, s_down) = (std_dev(&up, mean_up), std_dev(&down, mean_down));
            let reversal = mean_up - mean_down;
            let (r_up, r_down) = (2.0 * kf * s_up, 2.0 * kf * s_down);
            TargetStats {
                target: t.target,
                mean_up,
                mean_down,
                mean: (mean_up + mean_down) / 2.0,
                reversal,
                s_up,
                s_down,
                repeatability_up: r_up,
                repeatability_down: r_down,
                repeatability: (kf * s_up + kf * s_down + reversal.abs())
                    .max(r_up)
                    .max(r_down),
            }
        })
        .collect();
    let ts = &targets;
    let up = ts.iter().map(|t| t.mean_up);
    let down = ts.iter().map(|t| t.mean_down);
    let hi = |t: &TargetStats| (t.mean_up + kf * t.s_up).max(t.mean_down + kf * t.s_down);
    let lo = |t: &TargetStats| (t.mean_up - kf * t.s_up).min(t.mean_down - kf * t.s_down);
    let max_of =
        |f: &dyn Fn(&TargetStats) -> f64| ts.iter().map(f).fold(f64::NEG_INFINITY, f64::max);
    let min_of = |f: &dyn Fn(&TargetStats) -> f64| ts.iter().map(f).fold(f64::INFINITY, f64::min);
    let axis = AxisStats {
        A: max_of(&hi) - min_of(&lo),
        A_up: max_of(&|t| t.mean_up + kf * t.s_up) - min_of(&|t| t.mean_up - kf * t.s_up),
        A_down: max_of(&|t| t.mean_down + kf * t.s_down) - min_of(&|t| t.mean_down - kf * t.s_down),
        E: range(up.clone().chain(down.clone())),
        E_up: range(up),
        E_down: range(down),
        M: range(ts.iter().map(|t| t.mean)),
        R: max_of(&|t| t.repeatability),
        R_up: max_of(&|t| t.repeatability_up),
        R_down: max_of(&|t| t.repeatability_down),
        B: max_of(&|t| t.reversal.abs()),
        B_mean: ts.iter().map(|t| t.reversal).sum::<f64>() / ts.len() as f64,
    };
    let n = runs.runs();
    let points = Direction::BOTH
        .iter()
        .flat_map(|&direction| {
            (0..n).map(move |j| RunPoints {
                direction,
                run: j + 1,
                deviations: runs
                    .targets
                    .iter()
                    .map(|t| {
                        scale
                            * match direction {
                                Direction::Up => t.up[j],
                                Direction::Down => t.down[j],
                            }
                    })
                    .collect(),
            })
        })
        .collect();
    PositioningDocument {
        k,
        runs: n,
        unit: runs.kind.unit(),
        targets,
        axis,
        axis_kind: match runs.kind {
            AxisKind::Linear => "linear",
            AxisKind::Rotary => "rotary",
        },
        target_unit: runs.kind.target_unit(),
        file: runs.file.clone(),
        points,
        temperature: None,
    }
}

#[cfg(all(test, feature = "csv"))]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Runs, String> {
        Runs::parse(text, "x.csv", AxisKind::Linear).map_err(|e| {
            let d = e.diagnostics().first();
            format!(
                "{}:{}: {}",
                d.origin.line,
                d.origin.column,
                d.problem.headline()
            )
        })
    }

    #[test]
    fn rows_in_any_order_group_by_target() {
        let text = "target,direction,run,deviation\n\
                    10,down,2,0.4\n0,up,1,0.1\n0,+,2,0.2\n0,-,1,0.3\n0,down,2,0.5\n\
                    10,up,2,0.6\n10,up,1,0.7\n10,down,1,0.8\n";
        let r = parse(text).unwrap();
        assert_eq!(r.runs(), 2);
        assert_eq!(r.targets[0].target, 0.0);
        assert_eq!(r.targets[0].up, [0.1, 0.2]);
        assert_eq!(r.targets[0].down, [0.3, 0.5]);
        assert_eq!(r.targets[1].up, [0.7, 0.6]);
        assert_eq!(r.targets[1].down, [0.8, 0.4]);
    }

    #[test]
    fn measured_is_reached_position() {
        let text = "target,direction,run,measured\n0,up,1,0.001\n0,up,2,0.003\n0,down,1,-0.001\n0,down,2,0\n\
                    5,up,1,5.002\n5,up,2,5.002\n5,down,1,5\n5,down,2,5.001\n";
        let r = parse(text).unwrap();
        assert_eq!(r.targets[1].up, [5.002 - 5.0, 5.002 - 5.0]);
    }

    #[test]
    fn refusals_are_located() {
        let h = "target,direction,run,deviation\n";
        let base = "0,up,1,0\n0,up,2,0\n0,down,1,0\n0,down,2,0\n";
        let cases = [
            (
                format!("{h}{base}1,up,1,0\n1,up,2,0\n1,down,1,0\n1,down,1,0\n"),
                "9:8: target 1, direction down, run 1 is given twice (first on line 8)",
            ),
            (
                format!("{h}{base}1,up,1,0\n1,up,2,0\n1,down,1,0\n"),
                "6:1: target 1 has 2 run(s) up and 1 down, no run 2 down",
            ),
            (format!("{h}{base}"), "2:1: the file has 1 target (0)"),
            (
                format!("{h}0,up,1,0\n0,down,1,0\n1,up,1,0\n1,down,1,0\n"),
                "2:6: the file has 1 run per direction",
            ),
            (
                format!("{h}{base}1,sideways,1,0\n"),
                "6:3: column `direction`: `sideways` is not a direction",
            ),
            (
                format!("{h}{base}1,up,0,0\n"),
                "6:6: column `run`: `0` is not a run number",
            ),
            (
                format!("{h}{base}1,up,1,nan\n"),
                "6:8: column `deviation`: `nan` is not finite",
            ),
            (
                format!("{h}{base}1,up,1,\n"),
                "6:8: column `deviation`: the cell is empty",
            ),
            (
                "target,direction,run,deviation,measured\n0,up,1,0,0\n".into(),
                "1:32: the header has both",
            ),
            (
                "target,direction,run\n0,up,1\n".into(),
                "1:1: the header has no column `measured` or `deviation`",
            ),
            (
                "target,direction,run,deviation,temp\n0,up,1,0,20\n".into(),
                "1:32: column `temp` is not a column",
            ),
        ];
        for (text, want) in cases {
            let got = parse(&text).unwrap_err();
            assert!(got.starts_with(want), "{got}\n  want {want}");
        }
    }

    #[test]
    fn runs_from_rust_are_checked() {
        let two = |t: f64| (t, vec![0.0, 0.1], vec![0.2, 0.3]);
        assert!(Runs::new(AxisKind::Linear, vec![two(0.0), two(1.0)]).is_ok());
        assert_eq!(
            Runs::new(AxisKind::Linear, vec![two(0.0)]),
            Err(RunsError::TooFewTargets { count: 1 })
        );
        assert_eq!(
            Runs::new(AxisKind::Linear, vec![two(1.0), two(1.0)]),
            Err(RunsError::Repeated { target: 1.0 })
        );
        assert!(matches!(
            Runs::new(
                AxisKind::Linear,
                vec![two(0.0), (1.0, vec![0.0], vec![0.0, 0.1])]
            ),
            Err(RunsError::Unequal { .. })
        ));
        assert_eq!(
            Runs::new(
                AxisKind::Linear,
                vec![(0.0, vec![0.0], vec![0.0]), (1.0, vec![0.0], vec![0.0])]
            ),
            Err(RunsError::TooFewRuns { count: 1 })
        );
    }

    #[cfg(feature = "json")]
    #[test]
    fn coverage_serialises_whole_values_as_integers() {
        assert_eq!(serde_json::to_string(&Coverage::ISO).unwrap(), "2");
        assert_eq!(
            serde_json::to_string(&Coverage::new(2.5).unwrap()).unwrap(),
            "2.5"
        );
        assert_eq!(
            format!("{} {}", Coverage::ISO, Coverage::new(2.5).unwrap()),
            "2 2.5"
        );
        assert_eq!(
            Coverage::new(0.0).unwrap_err().to_string(),
            "the coverage factor k must be a finite number > 0, not 0"
        );
        assert!(Coverage::new(f64::NAN).is_err() && Coverage::new(f64::INFINITY).is_err());
    }
}
