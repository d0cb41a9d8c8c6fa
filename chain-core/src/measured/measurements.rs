//! Measurement records of one machine and their design-matrix rows
//! (measured-machines spec, section 4; `docs/identify.md`).
//!
//! A measurement CSV has one measurement a row. Its columns are
//!
//! - the machine's axis variables (every one of them: the pose; rotary in
//!   radians);
//! - any of the machine's parameters (that parameter's value for the row; a
//!   parameter not given as a column takes the caller's override, then the
//!   machine file's, and is refused if it has neither);
//! - either `dpx,dpy,dpz` (a measured tool-point deviation in the machine
//!   file's frame, as `derive` reports `px, py, pz`) or `ux,uy,uz,d` (a
//!   deviation `d = u · p` along the unit direction `u`);
//! - optionally `std` (that measurement's standard deviation, > 0, same
//!   units).
//!
//! A candidate CSV of `chain plan` (spec section 5) has the same columns
//! without the measured values (`dpx,dpy,dpz` and `d`): [`Layout::Candidates`].
//!
//! Every refusal is located in the CSV file (line, column, header name).
//! The design rows of a record are [`design_rows`]: `S_p(q, p)`, the three
//! position rows of the model's exact sensitivity (tool point), or
//! `uᵀ S_p(q, p)` (one row along a direction).
//!
//! What is particular to a kind of measurement (its columns, the names of
//! its design rows, how its rows take the position rows) is held by
//! [`MeasurementKind`] and [`Observed`]; the reader, the design and the
//! identification's document ask them.

use serde::Serialize;

use crate::diagnostic::Diagnostics;
#[cfg(feature = "csv")]
use crate::diagnostic::{closest, MeasurementsProblem as P, Problem};
use crate::model::Machine;
#[cfg(feature = "csv")]
use crate::model::Origin;
use crate::ErrorModel;

/// The measured columns of a tool-point deviation.
pub const POINT_COLUMNS: [&str; 3] = ["dpx", "dpy", "dpz"];
/// The direction columns of a deviation along a direction.
pub const DIRECTION_COLUMNS: [&str; 3] = ["ux", "uy", "uz"];
/// The measured column of a deviation along a direction.
pub const DISTANCE_COLUMN: &str = "d";
/// The column of a row's standard deviation.
pub const STD_COLUMN: &str = "std";
/// How far `|u|` may be from 1 (it is then normalised): direction cosines
/// written with five or more digits pass.
pub const UNIT_TOLERANCE: f64 = 1e-4;
/// Measurement CSV files larger than this are refused.
pub const MAX_MEASUREMENT_BYTES: usize = crate::bounded::MEASUREMENT_BYTES;

/// What a CSV must hold besides the poses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Layout {
    /// Measurements: `dpx,dpy,dpz` or `ux,uy,uz,d` (spec section 4).
    Measurements,
    /// Candidate poses of `chain plan` (spec section 5): no measured values;
    /// `ux,uy,uz` optional (then every row is a direction).
    Candidates,
}

/// A kind of measurement, without a record's data: what it measures, the
/// CSV columns that give it and the names of its design rows.
///
/// Everything a kind names (its given and measured columns, the quantities
/// its components measure) is one arm of a single match in this type; its
/// design rows are [`Observed::row`]; how a CSV row gives its data is the
/// measurement reader's match on the kind. A new kind is a variant here,
/// in [`MeasurementKind::ALL`] and in [`Observed`]; the compiler then asks
/// for its arm in each of those matches (none has a wildcard). Kinds order
/// as declared, which is the order the identification's words list the
/// measured components in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum MeasurementKind {
    /// The tool-point deviation `(px, py, pz)`: columns `dpx,dpy,dpz`,
    /// three design rows.
    Point,
    /// The deviation along a unit direction: columns `ux,uy,uz` (given,
    /// candidates have them too) and `d` (measured), one design row.
    Direction,
}

/// The names of one kind of measurement (see [`MeasurementKind`]).
struct KindNames {
    /// The columns that say how a record measures, besides its pose and
    /// parameters; a candidate file has them too.
    given: &'static [&'static str],
    /// The measured columns, one per design row, in row order.
    components: &'static [&'static str],
    /// The quantity each component measures, in the same order.
    quantities: &'static [&'static str],
}

impl MeasurementKind {
    /// Every kind, in declaration order: the kinds a CSV header is read
    /// for.
    pub const ALL: [MeasurementKind; 2] = [MeasurementKind::Point, MeasurementKind::Direction];

    /// Every name of the kind.
    fn names(self) -> KindNames {
        match self {
            MeasurementKind::Point => KindNames {
                given: &[],
                components: &POINT_COLUMNS,
                quantities: &["px", "py", "pz"],
            },
            MeasurementKind::Direction => KindNames {
                given: &DIRECTION_COLUMNS,
                components: &[DISTANCE_COLUMN],
                quantities: &["d"],
            },
        }
    }

    /// The columns that say how a record of this kind measures, besides
    /// its pose and parameters (`ux,uy,uz`; none for a tool point). A
    /// candidate file has them too.
    pub fn given(self) -> &'static [&'static str] {
        self.names().given
    }

    /// The measured columns, one per design row in row order: the names of
    /// the components (`dpx,dpy,dpz`; `d`).
    pub fn components(self) -> &'static [&'static str] {
        self.names().components
    }

    /// The quantity each component measures, in row order, as the
    /// identification's words name it (`px, py, pz`; `d`).
    pub fn quantities(self) -> &'static [&'static str] {
        self.names().quantities
    }

    /// Every column of a record of this kind besides its pose, parameters
    /// and std, as a measurement header has them: the given ones, then the
    /// measured ones (`dpx,dpy,dpz`; `ux,uy,uz,d`).
    pub fn columns(self) -> Vec<&'static str> {
        let names = self.names();
        (names.given.iter())
            .chain(names.components)
            .copied()
            .collect()
    }

    /// The number of design rows of one record (one per component: 3 or
    /// 1).
    pub fn rows(self) -> usize {
        self.names().components.len()
    }

    /// The components of one record, in row order.
    pub fn measured(self) -> impl Iterator<Item = MeasuredComponent> {
        (0..self.rows()).map(move |index| MeasuredComponent { kind: self, index })
    }
}

/// One design row of a record: which component of its kind's measurement
/// it is. Components order by kind (declaration order), then row.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct MeasuredComponent {
    /// The record's kind.
    pub kind: MeasurementKind,
    /// The row within the record (below `kind.rows()`).
    pub index: usize,
}

impl MeasuredComponent {
    /// Its measured column (`dpx`, `dpy`, `dpz` or `d`).
    pub fn name(self) -> &'static str {
        self.kind.components()[self.index]
    }

    /// The quantity it measures (`px`, `py`, `pz` or `d`).
    pub fn quantity(self) -> &'static str {
        self.kind.quantities()[self.index]
    }
}

/// What one record measures: its kind with the record's own data.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum Observed {
    /// The tool-point deviation `(px, py, pz)`: three design rows.
    Point,
    /// The deviation along the unit direction `u`: one design row `uᵀ S_p`.
    Direction {
        /// The unit direction (normalised).
        u: [f64; 3],
    },
}

impl Observed {
    /// Its kind.
    pub fn kind(&self) -> MeasurementKind {
        match self {
            Observed::Point => MeasurementKind::Point,
            Observed::Direction { .. } => MeasurementKind::Direction,
        }
    }

    /// The number of design rows of one record (3 or 1).
    pub fn rows(&self) -> usize {
        self.kind().rows()
    }

    /// Design row `k` (below [`Observed::rows`]) at one column, from that
    /// column's three position rows `p` (the `px, py, pz` rows of a
    /// sensitivity, a deviation or its Jacobian): `p[k]` for a tool point,
    /// `u · p` (summed x, y, z) along a direction.
    pub fn row(&self, k: usize, p: [f64; 3]) -> f64 {
        match self {
            Observed::Point => p[k],
            Observed::Direction { u } => u[0] * p[0] + u[1] * p[1] + u[2] * p[2],
        }
    }
}

/// What kind of instrument set-up a [`Setup`] is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum SetupKind {
    /// A sphere fixed on the table, probed at several rotary positions
    /// (five-axis spec, sphere probing records): its centre is the
    /// unknown.
    Sphere,
    /// The ball of an R-test (five-axis spec, `--setup ball`): its
    /// set-up offset on the table is the unknown.
    Ball,
    /// A circular test's run (spec `circular.md`, "Into identification"):
    /// its table ball's offset in the circle's plane and the bar's length
    /// offset are the unknowns.
    Circle,
}

impl SetupKind {
    /// The kind in words (`sphere`, `ball`, `circle`).
    pub fn name(self) -> &'static str {
        match self {
            SetupKind::Sphere => "sphere",
            SetupKind::Ball => "ball",
            SetupKind::Circle => "circle",
        }
    }
}

/// An instrument set-up whose position on the workpiece (table) is not
/// known: three unknowns of the fit beside the machine's errors, reported
/// but never written into values. A sphere's or a ball's are its position,
/// entering each of its records' tool-point rows with `−I` (in the machine
/// file's frame); a circle's are its table ball's offset along the plane's
/// two axes (with `−I`) and the bar's length offset (`+1` on the record's
/// distance).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Setup {
    /// Its identifier (a sphere file's `sphere` column; `ball`; a circular
    /// test's run).
    pub name: String,
    /// What it is.
    pub kind: SetupKind,
    /// A circle's plane.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub plane: Option<super::circular::Plane>,
}

impl Setup {
    /// A sphere's or a ball's set-up named `name`.
    pub fn new(name: impl Into<String>, kind: SetupKind) -> Setup {
        Setup {
            name: name.into(),
            kind,
            plane: None,
        }
    }

    /// What its three unknowns are: `x`, `y`, `z`; a circle's the plane's
    /// two axes and `length`.
    pub fn coordinates(&self) -> [&'static str; 3] {
        match self.plane {
            Some(plane) => {
                let [a, b] = plane.axes().map(|k| ["x", "y", "z"][k]);
                [a, b, "length"]
            }
            None => ["x", "y", "z"],
        }
    }

    /// The names of its three unknowns: `sphere 1.x`, `ball.y`,
    /// `circle xy_f1000.length`, …
    pub fn unknowns(&self) -> [String; 3] {
        let stem = match self.kind {
            SetupKind::Sphere => format!("sphere {}", self.name),
            SetupKind::Ball => self.name.clone(),
            SetupKind::Circle => format!("circle {}", self.name),
        };
        self.coordinates().map(|c| format!("{stem}.{c}"))
    }

    /// Its three unknowns' columns at a record measuring `observed` at
    /// `nominal`: vectors in the machine file's frame whose
    /// [`Observed::row`] is the record's design entry, and whose sum
    /// weighted by the unknowns is what they add to the record's
    /// deviation. A position's is `−(unit l)` of the workpiece frame; a
    /// circle's length is the record's own direction (its distance grows
    /// by the length: `uᵀu = 1`).
    pub fn columns(&self, nominal: &super::exact::Nominal, observed: &Observed) -> [[f64; 3]; 3] {
        let minus = |l: usize| {
            let mut unit = [0.0; 3];
            unit[l] = -1.0;
            nominal.in_frame(unit)
        };
        match self.plane {
            Some(plane) => {
                let [a, b] = plane.axes();
                let along = match observed {
                    Observed::Direction { u } => *u,
                    Observed::Point => [0.0; 3],
                };
                [minus(a), minus(b), along]
            }
            None => [minus(0), minus(1), minus(2)],
        }
    }
}

/// One measurement (or candidate pose).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Measurement {
    /// The CSV line it came from (1-based; 0 when built from Rust).
    pub line: usize,
    /// The axis values, in the machine's variable order.
    pub q: Vec<f64>,
    /// The parameter values, in the machine's parameter order.
    pub p: Vec<f64>,
    /// What it measures.
    pub observed: Observed,
    /// The measured values, one per component of its kind
    /// ([`MeasurementKind::components`]): `[dpx, dpy, dpz]` or `[d]` (empty
    /// for a candidate).
    pub values: Vec<f64>,
    /// Its standard deviation, if the CSV has a `std` column.
    pub std: Option<f64>,
    /// The set-up whose unknown position it measures against (an index
    /// into [`Measurements::setups`]), if any.
    pub setup: Option<usize>,
    /// The thermal state it was measured at (°C, one per sensor in the
    /// machine's order: a sensor's column, else the caller's value, else
    /// its reference); empty: every sensor at its reference
    /// (`docs/thermal.md`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub temperatures: Vec<f64>,
}

impl Measurement {
    /// Each error's thermal factor at this record's state
    /// ([`Machine::thermal_factors`]).
    pub fn thermal_factors(&self, machine: &Machine) -> Vec<f64> {
        if self.temperatures.is_empty() {
            return machine.thermal_factors(&machine.reference_temperatures());
        }
        machine.thermal_factors(&self.temperatures)
    }
}

/// The measurements (or candidates) of one CSV file.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Measurements {
    /// The file as named in messages.
    pub file: String,
    /// The machine they belong to.
    pub machine: String,
    /// Whether the file has a `std` column (every row then has a std).
    pub weighted: bool,
    /// The records in file order.
    pub rows: Vec<Measurement>,
    /// The set-ups the records' [`Measurement::setup`] index (none for an
    /// ordinary measurement file).
    pub setups: Vec<Setup>,
}

/// Why a measurement CSV was refused: its problems, located (file, line,
/// column, header name).
#[derive(Debug, thiserror::Error)]
#[cfg_attr(feature = "miette", derive(miette::Diagnostic))]
#[error(transparent)]
#[cfg_attr(feature = "miette", diagnostic(transparent))]
pub struct MeasurementsError(pub Diagnostics);

impl MeasurementsError {
    /// The located problems.
    pub fn diagnostics(&self) -> &Diagnostics {
        &self.0
    }
}

/// A held-out fraction outside `(0, 1)`, or a split that leaves no record
/// on one side.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[cfg_attr(feature = "miette", derive(miette::Diagnostic))]
#[cfg_attr(
    feature = "miette",
    diagnostic(
        code(chain::identify::holdout),
        help("the held-out fraction is that of the records held out of the fit, e.g. 0.2 (another seed chooses another split)")
    )
)]
#[non_exhaustive]
pub enum HoldoutError {
    /// The fraction is not in `(0, 1)`.
    #[error("the held-out fraction {0} is not a fraction in (0, 1)")]
    Fraction(f64),
    /// The fraction of these records holds out none or all of them.
    #[error("{fraction} of {records} records holds out {held}, leaving {} to fit: both sides need a record", records - held)]
    OneSided {
        /// The fraction.
        fraction: f64,
        /// The records.
        records: usize,
        /// How many it holds out.
        held: usize,
    },
}

/// The fraction of the records held out of the fit and the seed of the
/// split.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Holdout {
    /// The fraction held out.
    pub fraction: f64,
    /// The seed of the shuffle.
    pub seed: u64,
}

impl Holdout {
    /// The seed when none is given.
    pub const DEFAULT_SEED: u64 = 1;

    /// The fraction in `(0, 1)`.
    pub fn check(&self) -> Result<(), HoldoutError> {
        if self.fraction > 0.0 && self.fraction < 1.0 {
            Ok(())
        } else {
            Err(HoldoutError::Fraction(self.fraction))
        }
    }
}

impl Measurements {
    /// Every record measured against one set-up `setup` (an R-test's ball:
    /// `--setup ball`).
    pub fn on_setup(mut self, setup: Setup) -> Measurements {
        for r in &mut self.rows {
            r.setup = Some(0);
        }
        self.setups = vec![setup];
        self
    }

    /// The records with their set-ups indexed into `setups` (the fit's, for
    /// records held out of it), matched by name and kind; `Err` with the
    /// first record whose set-up is not among them.
    pub fn onto_setups(mut self, setups: &[Setup]) -> Result<Measurements, (usize, Setup)> {
        let map: Vec<Option<usize>> = (self.setups.iter())
            .map(|s| setups.iter().position(|t| t == s))
            .collect();
        for r in &mut self.rows {
            if let Some(g) = r.setup {
                match map[g] {
                    Some(to) => r.setup = Some(to),
                    None => return Err((r.line, self.setups[g].clone())),
                }
            }
        }
        self.setups = setups.to_vec();
        Ok(self)
    }

    /// Splits the records into those fitted and those held out:
    /// `round(fraction × n)`
    /// records chosen by a seeded shuffle (`rand`'s `SliceRandom::shuffle`,
    /// Fisher–Yates, over xoshiro256++ seeded from `seed` through
    /// SplitMix64, which `rand` documents as portable: the same split on
    /// every platform), each side kept in file order. The held-out side is
    /// named `FILE (held out)`.
    pub fn holdout(
        &self,
        fraction: f64,
        seed: u64,
    ) -> Result<(Measurements, Measurements), HoldoutError> {
        use rand::seq::SliceRandom;
        use rand::SeedableRng;
        Holdout { fraction, seed }.check()?;
        let n = self.rows.len();
        let held = (fraction * n as f64).round() as usize;
        if held == 0 || held == n {
            return Err(HoldoutError::OneSided {
                fraction,
                records: n,
                held,
            });
        }
        let mut order: Vec<usize> = (0..n).collect();
        let mut rng = rand::rngs::Xoshiro256PlusPlus::seed_from_u64(seed);
        order.shuffle(&mut rng);
        let mut out = vec![false; n];
        for &i in &order[..held] {
            out[i] = true;
        }
        let side = |keep: bool, file: String| Measurements {
            file,
            machine: self.machine.clone(),
            weighted: self.weighted,
            rows: (self.rows.iter().zip(&out))
                .filter(|(_, &o)| o == keep)
                .map(|(r, _)| r.clone())
                .collect(),
            setups: self.setups.clone(),
        };
        Ok((
            side(false, self.file.clone()),
            side(true, format!("{} (held out)", self.file)),
        ))
    }

    /// Reads a measurement or candidate CSV for `machine` (at most
    /// [`MAX_MEASUREMENT_BYTES`]); `overrides` are parameter values (later
    /// ones win), used for parameters the CSV has no column for.
    #[cfg(feature = "csv")]
    pub fn read(
        path: &std::path::Path,
        machine: &Machine,
        overrides: &[(String, f64)],
        layout: Layout,
    ) -> Result<Measurements, MeasurementsError> {
        let file = path.display().to_string();
        let bytes = crate::load::read_file(path, &file, MAX_MEASUREMENT_BYTES)
            .map_err(MeasurementsError)?;
        Measurements::from_bytes(&bytes, &file, machine, overrides, layout)
    }

    /// [`Measurements::read`] over bytes named `file` the caller read: text
    /// that is not UTF-8 or holds a NUL byte is refused, located.
    #[cfg(feature = "csv")]
    pub fn from_bytes(
        bytes: &[u8],
        file: &str,
        machine: &Machine,
        overrides: &[(String, f64)],
        layout: Layout,
    ) -> Result<Measurements, MeasurementsError> {
        let text = crate::load::decode(bytes, file).map_err(MeasurementsError)?;
        Measurements::parse(text, file, machine, overrides, layout)
    }

    /// [`Measurements::read`] over CSV text named `file`.
    #[cfg(feature = "csv")]
    pub fn parse(
        text: &str,
        file: &str,
        machine: &Machine,
        overrides: &[(String, f64)],
        layout: Layout,
    ) -> Result<Measurements, MeasurementsError> {
        let header_help = match layout {
            Layout::Measurements => format!(
                "the header names the pose variables, any per-row parameters, then {}, and optionally `std`",
                layout.named_columns(" or ")
            ),
            Layout::Candidates => format!(
                "the header names the pose variables, any per-row parameters, and optionally {} and `std`",
                layout.named_columns(" or ")
            ),
        };
        let csv = crate::values::csv::CsvFile::parse_with(text, file, &header_help)
            .map_err(MeasurementsError)?;
        let fail = |problems: Vec<(Origin, Problem)>| {
            MeasurementsError(
                Diagnostics::located(file, text, problems).expect("at least one problem"),
            )
        };
        let columns = classify(
            machine,
            overrides,
            layout,
            &csv.header,
            &csv.header_origin(),
        )
        .map_err(fail)?;
        let rows = csv.read_rows(|cells| columns.record(cells)).map_err(fail)?;
        if rows.is_empty() {
            let empty = P::NoRows { layout }.into();
            return Err(fail(vec![(csv.header_origin(), empty)]));
        }
        Ok(Measurements {
            file: file.to_string(),
            machine: machine.name.clone(),
            weighted: columns.std.is_some(),
            rows,
            setups: Vec::new(),
        })
    }
}

#[cfg(feature = "csv")]
impl Layout {
    /// The columns a file of this layout has for a record of `kind`: all
    /// of them for measurements, the given ones for candidates (not
    /// measured yet).
    fn columns(self, kind: MeasurementKind) -> Vec<&'static str> {
        match self {
            Layout::Measurements => kind.columns(),
            Layout::Candidates => kind.given().to_vec(),
        }
    }

    /// Each kind's columns in this layout as a header names them, joined
    /// by `sep` (`` `dpx,dpy,dpz` or `ux,uy,uz,d` ``); kinds without any
    /// are left out.
    fn named_columns(self, sep: &str) -> String {
        (MeasurementKind::ALL.into_iter())
            .map(|kind| self.columns(kind))
            .filter(|columns| !columns.is_empty())
            .map(|columns| quoted(&columns))
            .collect::<Vec<_>>()
            .join(sep)
    }
}

/// Columns as a header names them: `` `ux,uy,uz,d` ``.
#[cfg(feature = "csv")]
fn quoted(columns: &[&str]) -> String {
    format!("`{}`", columns.join(","))
}

/// Where each quantity is in a CSV's columns.
#[cfg(feature = "csv")]
struct Columns {
    /// Per variable, its column.
    q: Vec<usize>,
    /// Per parameter, its column or its fixed value.
    p: Vec<Result<usize, f64>>,
    /// Per sensor, its column or its fixed value (the caller's, else its
    /// reference).
    t: Vec<Result<usize, f64>>,
    /// What every record measures.
    kind: MeasurementKind,
    /// The kind's given columns (`ux,uy,uz`), in its order.
    given: Vec<usize>,
    /// The kind's measured value columns, in its order (none for
    /// candidates).
    values: Vec<usize>,
    std: Option<usize>,
}

#[cfg(feature = "csv")]
fn located(origin: &Origin, problem: impl Into<Problem>) -> Located {
    Box::new((origin.clone(), problem.into()))
}

/// A located problem of a CSV cell or header.
#[cfg(feature = "csv")]
type Located = Box<(Origin, Problem)>;

/// Classifies the header's columns.
#[cfg(feature = "csv")]
fn classify(
    m: &Machine,
    overrides: &[(String, f64)],
    layout: Layout,
    header: &[(String, Origin)],
    header_origin: &Origin,
) -> Result<Columns, Vec<(Origin, Problem)>> {
    let mut problems = Vec::new();
    let find = |name: &str| header.iter().position(|(h, _)| h == name);
    let measured: Vec<&str> = (MeasurementKind::ALL.into_iter())
        .flat_map(|kind| layout.columns(kind))
        .chain([STD_COLUMN])
        .collect();
    for (name, origin) in header {
        let known = m.variable_index(name).is_some()
            || m.parameter_index(name).is_some()
            || m.sensor_index(name).is_some()
            || measured.contains(&name.as_str());
        let measured_value = layout == Layout::Candidates
            && (MeasurementKind::ALL.iter()).any(|kind| kind.components().contains(&name.as_str()));
        if measured_value {
            let column = name.clone();
            problems.push((origin.clone(), P::MeasuredInCandidates { column }.into()));
        } else if !known {
            let names: Vec<&str> = (m.variables.iter().map(|v| v.name.as_str()))
                .chain(m.parameters.iter().map(|p| p.name.as_str()))
                .chain(m.sensors.iter().map(|s| s.name.as_str()))
                .chain(measured.iter().copied())
                .collect();
            let problem = P::UnknownColumn {
                column: name.clone(),
                machine: m.name.clone(),
                variables: m.variables.iter().map(|v| v.name.clone()).collect(),
                measured: layout.named_columns(" or "),
                layout,
                suggestion: closest(name, names.iter().copied()).map(str::to_string),
            };
            problems.push((origin.clone(), problem.into()));
        }
    }
    let mut q = Vec::new();
    let missing: Vec<&str> = m
        .variables
        .iter()
        .filter(|v| find(&v.name).is_none())
        .map(|v| v.name.as_str())
        .collect();
    if missing.is_empty() {
        q = m.variables.iter().filter_map(|v| find(&v.name)).collect();
    } else {
        let variables = missing.iter().map(|n| n.to_string()).collect();
        problems.push(*located(header_origin, P::MissingPose { variables }));
    }
    let p = parameter_columns(m, overrides, header, header_origin, &mut problems);
    let t = sensor_columns(m, overrides, header);
    // The records' kind: the one kind some of whose columns the header has,
    // else the one kind that has no column in this layout (a candidate
    // tool point); all of its columns are then needed.
    let named: Vec<_> = (MeasurementKind::ALL.into_iter())
        .map(|kind| {
            let names = layout.columns(kind);
            let at: Vec<Option<usize>> = names.iter().map(|c| find(c)).collect();
            (kind, names, at)
        })
        .collect();
    let mut kinds: Vec<_> = (named.iter())
        .filter(|(_, _, at)| at.iter().any(Option::is_some))
        .collect();
    if kinds.is_empty() {
        kinds = (named.iter())
            .filter(|(_, names, _)| names.is_empty())
            .collect();
    }
    let partial = |names: String| located(header_origin, P::PartialColumns { names });
    let mut read = None;
    match kinds.as_slice() {
        [] => {
            if problems.is_empty() {
                let expected = layout.named_columns(" or ");
                problems.push(*located(header_origin, P::NoValues { expected }));
            }
        }
        [(kind, names, at)] => {
            if at.iter().all(Option::is_some) {
                read = Some((*kind, at.iter().flatten().copied().collect::<Vec<usize>>()));
            } else {
                problems.push(*partial(names.join(",")));
            }
        }
        several => {
            let kinds = several.iter().map(|(_, names, _)| quoted(names)).collect();
            problems.push(*located(header_origin, P::TwoKinds { kinds }));
        }
    }
    match read {
        Some((kind, at)) if problems.is_empty() => {
            let (given, values) = at.split_at(kind.given().len());
            Ok(Columns {
                q,
                p,
                t,
                kind,
                given: given.to_vec(),
                values: values.to_vec(),
                std: find(STD_COLUMN),
            })
        }
        _ => Err(problems),
    }
}

/// Per parameter of `m`, its column in `header`, or the value it takes
/// without one (the last of `overrides` naming it, then the machine
/// file's); a symbolic parameter with neither is a problem located at the
/// header. The one rule of the measurement, candidate and sphere files.
#[cfg(feature = "csv")]
pub(crate) fn parameter_columns(
    m: &Machine,
    overrides: &[(String, f64)],
    header: &[(String, Origin)],
    header_origin: &Origin,
    problems: &mut Vec<(Origin, Problem)>,
) -> Vec<Result<usize, f64>> {
    let mut p = Vec::new();
    for param in &m.parameters {
        match header.iter().position(|(h, _)| *h == param.name) {
            Some(c) => p.push(Ok(c)),
            None => {
                let value = (overrides.iter().rev())
                    .find(|(n, _)| *n == param.name)
                    .map(|(_, v)| *v)
                    .or(param.value);
                match value {
                    Some(v) => p.push(Err(v)),
                    None => {
                        let name = param.name.clone();
                        problems.push(*located(header_origin, P::MissingParameter { name }));
                    }
                }
            }
        }
    }
    p
}

/// Per sensor of `m`, its column in `header`, or the temperature it takes
/// without one: the last of `overrides` naming it (the thermal state the
/// caller gives), else its reference (`docs/thermal.md`).
#[cfg(feature = "csv")]
pub(crate) fn sensor_columns(
    m: &Machine,
    overrides: &[(String, f64)],
    header: &[(String, Origin)],
) -> Vec<Result<usize, f64>> {
    (m.sensors.iter())
        .map(|s| match header.iter().position(|(h, _)| *h == s.name) {
            Some(c) => Ok(c),
            None => Err((overrides.iter().rev())
                .find(|(n, _)| *n == s.name)
                .map_or(s.reference, |(_, v)| *v)),
        })
        .collect()
}

#[cfg(feature = "csv")]
impl Columns {
    /// One data row as a record.
    fn record(&self, cells: &[(String, Origin)]) -> Result<Measurement, Located> {
        let number = |c: usize| -> Result<f64, Located> {
            let (text, origin) = &cells[c];
            crate::tabular::number(text, &origin.key).map_err(|problem| located(origin, problem))
        };
        let line = cells.first().map_or(0, |(_, o)| o.line);
        let q = self
            .q
            .iter()
            .map(|&c| number(c))
            .collect::<Result<Vec<_>, _>>()?;
        let p = (self.p.iter())
            .map(|c| match c {
                Ok(c) => number(*c),
                Err(v) => Ok(*v),
            })
            .collect::<Result<Vec<_>, _>>()?;
        let values = self
            .values
            .iter()
            .map(|&c| number(c))
            .collect::<Result<Vec<_>, _>>()?;
        let temperatures = (self.t.iter())
            .map(|c| match c {
                Ok(c) => {
                    let t = number(*c)?;
                    if t <= -273.15 {
                        return Err(located(&cells[*c].1, P::NotATemperature { value: t }));
                    }
                    Ok(t)
                }
                Err(v) => Ok(*v),
            })
            .collect::<Result<Vec<_>, _>>()?;
        let observed = match self.kind {
            MeasurementKind::Point => Observed::Point,
            MeasurementKind::Direction => {
                let cols = &self.given;
                let u = [number(cols[0])?, number(cols[1])?, number(cols[2])?];
                let norm = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
                if (norm - 1.0).abs() > UNIT_TOLERANCE {
                    return Err(located(&cells[cols[0]].1, P::NotUnit { norm }));
                }
                Observed::Direction {
                    u: [u[0] / norm, u[1] / norm, u[2] / norm],
                }
            }
        };
        let std = match self.std {
            None => None,
            Some(c) => {
                let s = number(c)?;
                if s <= 0.0 {
                    return Err(located(&cells[c].1, P::StdNotPositive { value: s }));
                }
                Some(s)
            }
        };
        Ok(Measurement {
            line,
            q,
            p,
            observed,
            values,
            std,
            setup: None,
            temperatures,
        })
    }
}

/// The design rows of one record at its pose, [`Observed::row`] of the
/// position rows of the model's exact sensitivity `S(q, p)`
/// (`∂(px, py, pz)/∂e`): those 3 rows for a tool point, `uᵀ S_p(q, p)`
/// along a direction (1 row). `out` receives `observed.rows() × N` values
/// row-major, `N` the model's error count; `scratch` is `6 × N` long. `q`
/// and `p` are in the model's orders.
///
/// The model's sensitivity is the design matrix of calibration (spec
/// section 4): a measured deviation is `S_p · e` plus noise.
pub fn design_rows<M: ErrorModel + ?Sized>(
    model: &M,
    q: &[f64],
    p: &[f64],
    observed: &Observed,
    scratch: &mut [f64],
    out: &mut [f64],
) {
    let n = model.errors().len();
    model.sensitivity(q, p, scratch);
    for k in 0..observed.rows() {
        for j in 0..n {
            out[k * n + j] = observed.row(k, [scratch[j], scratch[n + j], scratch[2 * n + j]]);
        }
    }
}

/// The largest magnitude of a design entry or a measured value, weighted
/// ([`DesignError::NotFinite`]): its square summed over millions of rows
/// stays finite (the limit of statistics numbers, docs/robustness.md).
pub const DESIGN_LIMIT: f64 = 1e100;

/// The design matrix of a set of records, in the model's orders.
#[derive(Debug, Clone, PartialEq)]
pub struct Design {
    /// The unknowns' names (columns): the model's errors in its order,
    /// then three per set-up ([`Setup::unknowns`]).
    pub errors: Vec<String>,
    /// `A`, one row per scalar measurement (row-major, `rows × N`).
    pub a: nalgebra::DMatrix<f64>,
    /// The measured values, one per row.
    pub b: Vec<f64>,
    /// Each row's standard deviation, if the records have one.
    pub std: Option<Vec<f64>>,
    /// Each row's record (index into the records) and component
    /// ([`MeasuredComponent::name`]: `dpx`, `dpy`, `dpz` or `d`).
    pub origin: Vec<(usize, MeasuredComponent)>,
    /// The set-ups whose positions are the last `3 × setups.len()`
    /// unknowns.
    pub setups: Vec<Setup>,
    /// Each unknown's physical scale ([`physical_scales`]): the size an
    /// error of it plausibly has, in its own unit.
    pub scales: Vec<f64>,
}

/// Each unknown's physical scale, for choosing among errors that act alike
/// (`docs/identify.md`, "Subsets that stay physical"):
///
/// - an error with a `statistics` entry in the machine file: its std;
/// - otherwise a linear error: the length `L`, the root mean square of the
///   given linear errors' stds (1 mm when none is given);
/// - otherwise an angle (angular or squareness): `L / R`, the angle that
///   moves a point at the lever arm `R` of the measured poses by `L`. `R`
///   is the root mean square distance of the records' nominal tool points
///   in the root body's frame (where the axes move them) from their
///   centroid; the distance from the root's origin when every record is
///   at one place; 1 mm for no record;
/// - a set-up's coordinate: `L` (they are always estimated);
///
/// and a function slot's coefficient without a statistic: its slot's scale
/// over the root mean square of its basis function at the records (a
/// power-basis coefficient of `y` at `y ≈ 300` mm is `L / 300` per mm).
pub fn physical_scales(
    machine: &Machine,
    names: &[&str],
    records: &[Measurement],
    setups: usize,
) -> Vec<f64> {
    use crate::model::ErrorKind;
    let chain = super::exact::ExactChain::new(machine);
    let error = |n: &str| machine.error_index(n);
    let linear = |n: &str| error(n).is_none_or(|j| machine.errors[j].kind == ErrorKind::Linear);
    let given = |n: &str| {
        (error(n).and_then(|j| machine.statistic(j)))
            .map(|s| s.distribution.std())
            .filter(|s| s.is_finite() && *s > 0.0)
    };
    let rms = |v: &[f64]| (v.iter().map(|x| x * x).sum::<f64>() / v.len().max(1) as f64).sqrt();
    let stds: Vec<f64> = names
        .iter()
        .filter(|n| linear(n))
        .filter_map(|n| given(n))
        .collect();
    let length = if stds.is_empty() { 1.0 } else { rms(&stds) };
    let points: Vec<[f64; 3]> = (records.iter())
        .map(|r| chain.nominal(&r.q, &r.p).in_root)
        .filter(|p| p.iter().all(|v| v.is_finite()))
        .collect();
    let k = points.len().max(1) as f64;
    let centroid: [f64; 3] = std::array::from_fn(|i| points.iter().map(|p| p[i]).sum::<f64>() / k);
    let distance = |c: [f64; 3]| {
        let d: Vec<f64> = (points.iter())
            .map(|p| ((0..3).map(|i| (p[i] - c[i]).powi(2)).sum::<f64>()).sqrt())
            .collect();
        rms(&d)
    };
    let lever = [distance(centroid), distance([0.0; 3]), 1.0]
        .into_iter()
        .find(|r| *r > 0.0 && r.is_finite())
        .unwrap_or(1.0);
    // A function slot's coefficient acts through its basis function w_j(q):
    // its size is the slot's over the root mean square of w_j at the
    // records (1 for a constant).
    let mut w2 = vec![0.0; machine.errors.len()];
    for r in records {
        let factors = r.thermal_factors(machine);
        for ((a, w), f) in w2.iter_mut().zip(chain.weights(&r.q)).zip(factors) {
            *a += (w * f) * (w * f);
        }
    }
    let basis = |n: &str| {
        error(n)
            .map(|j| (w2[j] / records.len().max(1) as f64).sqrt())
            .filter(|w| *w > 0.0 && w.is_finite())
            .unwrap_or(1.0)
    };
    (names.iter())
        .map(|n| match given(n) {
            Some(s) => s,
            None if linear(n) => length / basis(n),
            None => length / lever / basis(n),
        })
        .chain(std::iter::repeat_n(length, 3 * setups))
        .collect()
}

impl Design {
    /// The number of the machine's errors: the unknowns before the
    /// set-ups'.
    pub fn machine_errors(&self) -> usize {
        self.errors.len() - 3 * self.setups.len()
    }
}

/// Why a design could not be built from records.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum DesignError {
    /// The model's variables or parameters are not the machine's.
    #[error("the model's {what} ({model}) are not the measurements' machine's ({machine})")]
    Order {
        /// `variables` or `parameters`.
        what: &'static str,
        /// The model's names.
        model: String,
        /// The machine's names.
        machine: String,
    },
    /// Some records have a std and others not.
    #[error("some records have a standard deviation and others not")]
    MixedStd,
    /// A record's design rows (the model's sensitivity at its pose, divided
    /// by its std when weighted) or its weighted values are not finite or
    /// beyond [`DESIGN_LIMIT`]: a pose, parameter or std beyond what the
    /// model can evaluate. Refused here so that no solver sees an infinity,
    /// a NaN or a square that overflows (an SVD would not converge).
    #[error(
        "line {line}: the model's sensitivity at this record's pose{weighted} is not finite \
         or beyond 1e100 in magnitude (a pose value, a parameter or a std out of range)"
    )]
    NotFinite {
        /// The record's line in its CSV.
        line: usize,
        /// `, divided by its std,` when the record is weighted.
        weighted: &'static str,
    },
    /// A record measured against a set-up the design was not given.
    #[error("line {line}: the record's set-up is not among the design's")]
    Setup {
        /// The record's line in its CSV.
        line: usize,
    },
}

impl Design {
    /// The design of `records` (in `machine`'s orders) through `model`.
    /// Candidates (no values) give `b = 0`. Records with a set-up are
    /// refused ([`Design::with_setups`] takes them).
    pub fn new<M: ErrorModel + ?Sized>(
        model: &M,
        machine: &Machine,
        records: &[Measurement],
    ) -> Result<Design, DesignError> {
        Design::with_setups(model, machine, records, &[])
    }

    /// The design of the records of `measurements` with their set-ups.
    pub fn of<M: ErrorModel + ?Sized>(
        model: &M,
        machine: &Machine,
        measurements: &Measurements,
    ) -> Result<Design, DesignError> {
        Design::with_setups(model, machine, &measurements.rows, &measurements.setups)
    }

    /// The design of `records` whose set-up indices point into `setups`:
    /// a record on set-up `g` has, besides the model's rows, the rows of
    /// `−I` (in the machine file's frame at its pose:
    /// [`super::exact::Nominal::in_frame`]) in the columns of `g`'s three
    /// unknowns (`docs/five-axis.md`).
    pub fn with_setups<M: ErrorModel + ?Sized>(
        model: &M,
        machine: &Machine,
        records: &[Measurement],
        setups: &[Setup],
    ) -> Result<Design, DesignError> {
        let order = |what: &'static str, model: &[&str], machine: Vec<&str>| {
            if model == machine.as_slice() {
                Ok(())
            } else {
                Err(DesignError::Order {
                    what,
                    model: model.join(", "),
                    machine: machine.join(", "),
                })
            }
        };
        order(
            "variables",
            model.variables(),
            machine.variables.iter().map(|v| v.name.as_str()).collect(),
        )?;
        order(
            "parameters",
            model.parameters(),
            machine.parameters.iter().map(|p| p.name.as_str()).collect(),
        )?;
        let weighted = records.first().is_some_and(|r| r.std.is_some());
        if records.iter().any(|r| r.std.is_some() != weighted) {
            return Err(DesignError::MixedStd);
        }
        if let Some(r) = (records.iter()).find(|r| r.setup.is_some_and(|g| g >= setups.len())) {
            return Err(DesignError::Setup { line: r.line });
        }
        let chain = super::exact::ExactChain::new(machine);
        let n = model.errors().len();
        let thermal = machine.is_thermal();
        let width = n + 3 * setups.len();
        let m: usize = records.iter().map(|r| r.observed.rows()).sum();
        let mut flat = vec![0.0; m * width];
        let mut scratch = vec![0.0; 6 * n];
        let mut rows_n = vec![0.0; 3 * n];
        let mut b = Vec::with_capacity(m);
        let mut std = weighted.then(|| Vec::with_capacity(m));
        let mut origin = Vec::with_capacity(m);
        let mut at = 0;
        for (i, r) in records.iter().enumerate() {
            let k = r.observed.rows();
            design_rows(
                model,
                &r.q,
                &r.p,
                &r.observed,
                &mut scratch,
                &mut rows_n[..k * n],
            );
            let out = &mut flat[at * width..(at + k) * width];
            for c in 0..k {
                out[c * width..c * width + n].copy_from_slice(&rows_n[c * n..(c + 1) * n]);
            }
            // At the record's thermal state each thermal coefficient's
            // column is its geometric column times ΔT (docs/thermal.md).
            if thermal {
                let factors = r.thermal_factors(machine);
                for c in 0..k {
                    for (v, f) in out[c * width..c * width + n].iter_mut().zip(&factors) {
                        *v *= f;
                    }
                }
            }
            if let Some(g) = r.setup {
                // The set-up's unknowns' columns ([`Setup::columns`]).
                let nominal = chain.nominal(&r.q, &r.p);
                let columns = setups[g].columns(&nominal, &r.observed);
                for (l, col) in columns.into_iter().enumerate() {
                    for c in 0..k {
                        out[c * width + n + 3 * g + l] = r.observed.row(c, col);
                    }
                }
            }
            // Every value the solvers will see, weighted as they will see it.
            let w = r.std.map_or(1.0, |s| 1.0 / s);
            let rows = &flat[at * width..(at + k) * width];
            let within = |x: f64| x.abs() <= DESIGN_LIMIT;
            let finite = w.is_finite()
                && rows.iter().all(|a| within(a * w))
                && r.values.iter().all(|v| within(v * w));
            if !finite {
                return Err(DesignError::NotFinite {
                    line: r.line,
                    weighted: if r.std.is_some() {
                        ", divided by its std,"
                    } else {
                        ""
                    },
                });
            }
            for component in r.observed.kind().measured() {
                b.push(r.values.get(component.index).copied().unwrap_or(0.0));
                if let (Some(s), Some(v)) = (std.as_mut(), r.std) {
                    s.push(v);
                }
                origin.push((i, component));
            }
            at += k;
        }
        let mut errors: Vec<String> = model.errors().iter().map(|e| e.to_string()).collect();
        errors.extend(setups.iter().flat_map(Setup::unknowns));
        let scales = physical_scales(machine, model.errors(), records, setups.len());
        Ok(Design {
            errors,
            a: nalgebra::DMatrix::from_row_slice(m, width, &flat),
            b,
            std,
            origin,
            setups: setups.to_vec(),
            scales,
        })
    }
}
