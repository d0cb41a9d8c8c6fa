//! The rules of the measured files: measurement and candidate files (codes
//! `chain::measurements::*`) and positioning run files
//! (`chain::positioning::*`).

use super::Description as D;
use crate::measured::measurements::Layout;
use crate::measured::positioning::Direction;

/// What a positioning run file's header names (the help of an empty file or
/// an unknown column).
pub(crate) const RUN_FILE_HEADER: &str =
    "the header names `target`, `direction`, `run`, and `measured` or `deviation`";

/// One thing wrong with a measurement or candidate file, worded by
/// [`MeasurementsProblem::describe`].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum MeasurementsProblem {
    /// A header and no record.
    NoRows {
        /// Measurements or candidates.
        layout: Layout,
    },
    /// A measured value's column in a candidate file.
    MeasuredInCandidates {
        /// The column.
        column: String,
    },
    /// A column that is neither a variable, a parameter nor a measurement
    /// column.
    UnknownColumn {
        /// The column.
        column: String,
        /// The machine.
        machine: String,
        /// Its axis variables.
        variables: Vec<String>,
        /// The measurement columns of this layout, as a header names them
        /// (`` `dpx,dpy,dpz` or `ux,uy,uz,d` ``).
        measured: String,
        /// Measurements or candidates.
        layout: Layout,
        /// The closest valid column, if one is close.
        suggestion: Option<String>,
    },
    /// Axis variables without a column.
    MissingPose {
        /// The variables.
        variables: Vec<String>,
    },
    /// A symbolic parameter without a column.
    MissingParameter {
        /// The parameter.
        name: String,
    },
    /// Some but not all of one kind's columns.
    PartialColumns {
        /// The kind's columns, comma-separated.
        names: String,
    },
    /// No measured value column.
    NoValues {
        /// The measurement columns, as a header names them.
        expected: String,
    },
    /// The columns of two kinds of measurement.
    TwoKinds {
        /// Each kind's columns, as a header names them.
        kinds: Vec<String>,
    },
    /// A direction that is not a unit vector.
    NotUnit {
        /// Its length.
        norm: f64,
    },
    /// A standard deviation that is not positive.
    StdNotPositive {
        /// Its value.
        value: f64,
    },
    /// A sensor's cell that is not a temperature (°C above absolute zero).
    NotATemperature {
        /// Its value.
        value: f64,
    },
    /// A sphere file's column that is neither an axis variable, a
    /// parameter, `sphere` nor `std`.
    SphereUnknownColumn {
        /// The column.
        column: String,
        /// The machine.
        machine: String,
        /// Its axis variables.
        variables: Vec<String>,
        /// The closest valid column, if one is close.
        suggestion: Option<String>,
    },
    /// A sphere file with a header and no probing.
    SphereNoRows,
    /// A sphere probed fewer than [`crate::measured::spheres::MIN_PROBINGS`]
    /// times.
    SphereTooFew {
        /// The sphere's identifier.
        sphere: String,
        /// Its probings.
        probings: usize,
    },
    /// An empty `sphere` cell.
    SphereEmptyId,
    /// A probing whose nominal tool point is not finite.
    SphereNotFinite,
}

impl MeasurementsProblem {
    /// Every part of the message of this problem: one match arm per
    /// variant.
    pub fn describe(&self) -> D {
        match self {
            MeasurementsProblem::NoRows { layout } => {
                let (what, help) = match layout {
                    Layout::Measurements => {
                        ("measurement", "each row after the header is one measurement")
                    }
                    Layout::Candidates => (
                        "candidate pose",
                        "each row after the header is one candidate pose",
                    ),
                };
                D::new(
                    "chain::measurements::no_rows",
                    "no rows",
                    format!("the file has a header but no {what} row"),
                )
                .help(help.to_string())
            }
            MeasurementsProblem::MeasuredInCandidates { column } => D::new(
                "chain::measurements::measured_in_candidates",
                "measured value",
                format!("column `{column}` is a measured value: a candidate file gives only where to measure"),
            )
            .help("the candidate columns are the axis variables, parameters per row, `ux,uy,uz` for measurements along a direction, and optionally `std`".to_string()),
            MeasurementsProblem::UnknownColumn {
                column,
                machine,
                variables,
                measured,
                layout,
                suggestion,
            } => D::new(
                "chain::measurements::unknown_column",
                "unknown column",
                D::suggesting(
                    format!("column `{column}` is neither an axis variable, a parameter of machine `{machine}`, nor a measurement column"),
                    suggestion,
                ),
            )
            .help(format!(
                "the columns are the axis variables ({}), parameters, {}",
                variables.join(", "),
                match layout {
                    Layout::Measurements => format!("{measured}, and optionally `std`"),
                    Layout::Candidates => format!("optionally {measured} and `std`"),
                }
            )),
            MeasurementsProblem::MissingPose { variables } => D::new(
                "chain::measurements::missing_pose",
                "missing pose column",
                format!(
                    "the header has no column for the axis variable{} {}: every row needs the whole pose",
                    if variables.len() == 1 { "" } else { "s" },
                    quoted(variables.iter().map(String::as_str))
                ),
            ),
            MeasurementsProblem::MissingParameter { name } => D::new(
                "chain::measurements::missing_parameter",
                "missing parameter",
                format!("parameter `{name}` is symbolic in the machine file and the header has no column for it"),
            ),
            MeasurementsProblem::PartialColumns { names } => D::new(
                "chain::measurements::partial_columns",
                "partial columns",
                format!("the header has only some of `{names}`: give all of them"),
            ),
            MeasurementsProblem::NoValues { expected } => D::new(
                "chain::measurements::no_values",
                "no measured values",
                format!("the header has no measured values: expected {expected}"),
            ),
            MeasurementsProblem::TwoKinds { kinds } => D::new(
                "chain::measurements::two_kinds",
                "two kinds",
                format!(
                    "the header has both {}: a file holds one kind of measurement",
                    kinds.join(" and ")
                ),
            ),
            MeasurementsProblem::NotUnit { norm } => D::new(
                "chain::measurements::not_unit",
                "not a unit vector",
                format!("the direction (ux, uy, uz) has length {norm}, not 1"),
            ),
            MeasurementsProblem::NotATemperature { value } => D::new(
                "chain::measurements::not_a_temperature",
                "not a temperature",
                format!("{value} °C is below absolute zero"),
            )
            .help("a sensor's column holds the temperature of each record in °C".to_string()),
            MeasurementsProblem::StdNotPositive { value } => D::new(
                "chain::measurements::std_not_positive",
                "not positive",
                format!("the standard deviation must be positive, got {value}"),
            ),
            MeasurementsProblem::SphereUnknownColumn {
                column,
                machine,
                variables,
                suggestion,
            } => D::new(
                "chain::spheres::unknown_column",
                "unknown column",
                D::suggesting(
                    format!("column `{column}` is neither an axis variable, a parameter of machine `{machine}`, `sphere` nor `std`"),
                    suggestion,
                ),
            )
            .help(format!(
                "a sphere file's columns are the axis variables ({}; rotary ones in degrees), parameters, and optionally `sphere` and `std`",
                variables.join(", ")
            )),
            MeasurementsProblem::SphereNoRows => D::new(
                "chain::spheres::no_rows",
                "no rows",
                "the file has a header but no probing row".to_string(),
            )
            .help("each row after the header is one probing: the axis positions at which the probe centre sits at the sphere centre".to_string()),
            MeasurementsProblem::SphereTooFew { sphere, probings } => D::new(
                "chain::spheres::too_few",
                "too few probings",
                format!(
                    "sphere `{sphere}` is probed {probings} time{}: one probing only locates the sphere, at least {} are needed to tell anything of the machine",
                    if *probings == 1 { "" } else { "s" },
                    crate::measured::spheres::MIN_PROBINGS
                ),
            )
            .help("probe each sphere at several rotary positions, or leave this sphere's rows out".to_string()),
            MeasurementsProblem::SphereEmptyId => D::new(
                "chain::spheres::empty_id",
                "empty identifier",
                "the `sphere` cell is empty".to_string(),
            )
            .help("give every probing its sphere's identifier, or leave the `sphere` column out for one sphere".to_string()),
            MeasurementsProblem::SphereNotFinite => D::new(
                "chain::spheres::not_finite",
                "not finite",
                "the nominal tool point at this probing's axis positions is not finite (an axis position or a parameter out of range)".to_string(),
            ),
        }
    }
}

/// One thing wrong with a positioning run file, worded by
/// [`PositioningProblem::describe`].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum PositioningProblem {
    /// A column a run file does not have.
    UnknownColumn {
        /// The column.
        column: String,
        /// The closest valid column, if one is close.
        suggestion: Option<String>,
    },
    /// Both `measured` and `deviation`.
    BothValueColumns,
    /// Required columns missing.
    MissingColumns {
        /// The missing ones of `target`, `direction`, `run`.
        columns: Vec<&'static str>,
        /// Whether neither `measured` nor `deviation` is there.
        value: bool,
    },
    /// A `direction` cell that is not a direction.
    Direction {
        /// The cell as written.
        text: String,
    },
    /// A `run` cell that is not a run number.
    Run {
        /// The cell as written.
        text: String,
    },
    /// A `measured` value whose deviation from the target is not finite.
    DeviationNotFinite {
        /// The cell as written.
        cell: String,
    },
    /// A (target, direction, run) given twice.
    Repeated {
        /// The target.
        target: f64,
        /// The direction.
        direction: Direction,
        /// The run.
        run: usize,
        /// The line of its first occurrence.
        first_line: usize,
    },
    /// Fewer than two targets.
    TooFewTargets {
        /// The number of targets.
        count: usize,
        /// The one target.
        target: f64,
    },
    /// A target without a run that another (target, direction) has.
    UnequalRuns {
        /// The target.
        target: f64,
        /// Its runs moving up.
        up: usize,
        /// Its runs moving down.
        down: usize,
        /// The run it lacks.
        missing: usize,
        /// The direction that lacks it.
        direction: Direction,
        /// The most runs of any (target, direction).
        runs: usize,
    },
    /// Fewer than two runs per direction.
    TooFewRuns {
        /// The runs per direction.
        runs: usize,
    },
}

impl PositioningProblem {
    /// Every part of the message of this problem: one match arm per
    /// variant.
    pub fn describe(&self) -> D {
        match self {
            PositioningProblem::UnknownColumn { column, suggestion } => D::new(
                "chain::positioning::unknown_column",
                "unknown column",
                D::suggesting(
                    format!("column `{column}` is not a column of a positioning run file"),
                    suggestion,
                ),
            )
            .help(RUN_FILE_HEADER.to_string()),
            PositioningProblem::BothValueColumns => D::new(
                "chain::positioning::value_columns",
                "both",
                "the header has both `measured` and `deviation`: give exactly one",
            ),
            PositioningProblem::MissingColumns { columns, value } => {
                let mut missing = columns.clone();
                if *value {
                    missing.push("measured` or `deviation");
                }
                D::new(
                    "chain::positioning::missing_column",
                    "missing column",
                    format!("the header has no column {}", quoted(missing.into_iter())),
                )
            }
            PositioningProblem::Direction { text } => D::new(
                "chain::positioning::direction",
                "direction",
                if text.is_empty() {
                    "column `direction`: the cell is empty".to_string()
                } else {
                    format!("column `direction`: `{text}` is not a direction")
                },
            )
            .help("a direction is `up` (or `+`, approached moving in the positive direction) or `down` (or `-`)".to_string()),
            PositioningProblem::Run { text } => D::new(
                "chain::positioning::run",
                "run",
                if text.is_empty() {
                    "column `run`: the cell is empty".to_string()
                } else {
                    format!("column `run`: `{text}` is not a run number 1, 2, …")
                },
            ),
            PositioningProblem::DeviationNotFinite { cell } => D::new(
                "chain::csv::not_finite",
                "not finite",
                format!("column `measured`: `{cell}` minus the target is not finite"),
            ),
            PositioningProblem::Repeated {
                target,
                direction,
                run,
                first_line,
            } => D::new(
                "chain::positioning::repeated",
                "repeated",
                format!(
                    "target {target}, direction {}, run {run} is given twice (first on line {first_line})",
                    direction.name()
                ),
            ),
            PositioningProblem::TooFewTargets { count, target } => D::new(
                "chain::positioning::too_few_targets",
                "one target",
                format!("the file has {count} target ({target}): an ISO 230-2 run needs at least 2"),
            ),
            PositioningProblem::UnequalRuns {
                target,
                up,
                down,
                missing,
                direction,
                runs,
            } => D::new(
                "chain::positioning::unequal_runs",
                "unequal runs",
                format!(
                    "target {target} has {up} run(s) {} and {down} {}, no run {missing} {}: every target needs the same runs 1..{runs} in both directions",
                    Direction::Up.name(),
                    Direction::Down.name(),
                    direction.name(),
                ),
            ),
            PositioningProblem::TooFewRuns { runs } => D::new(
                "chain::positioning::too_few_runs",
                "one run",
                format!("the file has {runs} run per direction: the standard uncertainty s needs at least 2 (ISO 230-2 asks for 5)"),
            ),
        }
    }
}

/// Names as a message lists them: `` `a`, `b` ``.
fn quoted<'a>(names: impl Iterator<Item = &'a str>) -> String {
    names
        .map(|n| format!("`{n}`"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// What a drift-test file's header names (the help of an empty file or a
/// missing column).
pub(crate) const DRIFT_FILE_HEADER: &str = "the header names `time` (or `time(s)`, `t(s)`), the displacement channels (a unit `(um)`, `(µm)` or `(mm)` at the end of the name), the temperatures (`(°C)`, `(degC)` or `(C)`) and any load (`spindle(rpm)`)";

/// One thing wrong with an ISO 230-3 drift-test file, worded by
/// [`DriftProblem::describe`].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum DriftProblem {
    /// No `time` column.
    NoTime,
    /// A time not after the previous row's.
    TimeNotIncreasing {
        /// The time.
        time: f64,
        /// The previous row's.
        previous: f64,
        /// The previous row's line.
        previous_line: usize,
    },
    /// No displacement channel.
    NoDisplacement {
        /// The header's columns.
        columns: Vec<String>,
    },
    /// Fewer than 3 rows.
    TooFewRows {
        /// The rows.
        rows: usize,
    },
    /// A column named for a role that is not in the header.
    NotAColumn {
        /// The name.
        name: String,
        /// The role: `displacement`, `temperature`, `load`.
        role: &'static str,
        /// The closest column, if one is close.
        suggestion: Option<String>,
    },
    /// A column named for two roles.
    TwoRoles {
        /// The column.
        name: String,
        /// The roles.
        first: &'static str,
        /// The other.
        second: &'static str,
    },
}

impl DriftProblem {
    /// Every part of the message of this problem: one match arm per
    /// variant.
    pub fn describe(&self) -> D {
        match self {
            DriftProblem::NoTime => D::new(
                "chain::thermal::no_time",
                "no time",
                "the header has no `time` column (seconds since the start of the test)",
            )
            .help(DRIFT_FILE_HEADER.to_string()),
            DriftProblem::TimeNotIncreasing {
                time,
                previous,
                previous_line,
            } => D::new(
                "chain::thermal::time",
                "time",
                format!("{time} s is not after {previous} s (line {previous_line}): the rows must be in increasing time"),
            ),
            DriftProblem::NoDisplacement { columns } => D::new(
                "chain::thermal::no_displacement",
                "no displacement",
                format!(
                    "no displacement channel among the columns {}",
                    quoted(columns.iter().map(String::as_str))
                ),
            )
            .help("end a displacement channel's name with its unit, `(um)` or `(mm)`, or name it as a displacement channel".to_string()),
            DriftProblem::TooFewRows { rows } => D::new(
                "chain::thermal::too_few_rows",
                "rows",
                format!("the file has {rows} row(s): a drift test needs at least 3"),
            ),
            DriftProblem::NotAColumn {
                name,
                role,
                suggestion,
            } => D::new(
                "chain::thermal::not_a_column",
                "header",
                D::suggesting(
                    format!("`{name}` is named as a {role} column but the header has no such column"),
                    suggestion,
                ),
            ),
            DriftProblem::TwoRoles {
                name,
                first,
                second,
            } => D::new(
                "chain::thermal::two_roles",
                "header",
                format!("column `{name}` is named both as a {first} and as a {second} column"),
            ),
        }
    }
}

/// What the header of a circular-test file names (the help of its
/// refusals).
pub(crate) const CIRCULAR_FILE_HEADER: &str = "the header names `angle` (degrees), `direction` (`ccw` or `cw`) and `deviation` (mm; `deviation(um)` for µm), and optionally `run`, `radius` (mm), `feed` (mm/min) and `plane` (`xy`, `yz` or `zx`)";

/// A rule of an ISO 230-4 circular-test file (`chain circular`), worded by
/// [`CircularProblem::describe`].
#[derive(Debug, Clone, PartialEq)]
pub enum CircularProblem {
    /// A required column is missing.
    MissingColumn {
        /// The column (`angle`, `direction`, `deviation`).
        name: &'static str,
        /// The header's columns.
        columns: Vec<String>,
    },
    /// A direction other than `ccw` or `cw`.
    Direction {
        /// The text.
        found: String,
    },
    /// A plane other than `xy`, `yz`, `zx`.
    Plane {
        /// The text.
        found: String,
    },
    /// A radius or feed that is not positive.
    NotPositive {
        /// `radius` or `feed`.
        what: &'static str,
        /// The value.
        value: f64,
    },
    /// A run's radius, feed or plane differs from its first row's.
    RunDiffers {
        /// `radius`, `feed` or `plane`.
        what: &'static str,
        /// This row's.
        value: String,
        /// The first row's.
        first: String,
        /// The first row's line.
        first_line: usize,
        /// The run.
        run: String,
    },
    /// A run with no radius (no `radius` column and no `--radius`).
    NoRadius {
        /// The run.
        run: String,
    },
    /// A deviation of a tenth of the radius or more.
    TooLarge {
        /// The deviation (mm).
        deviation: f64,
        /// The run's radius (mm).
        radius: f64,
    },
    /// Too few distinct angles in a direction of a run to fit a circle.
    TooFewSamples {
        /// The run.
        run: String,
        /// `ccw` or `cw`.
        direction: &'static str,
        /// The samples.
        count: usize,
    },
    /// A direction of a run that does not cover its arc.
    NotCovered {
        /// The run.
        run: String,
        /// `ccw` or `cw`.
        direction: &'static str,
        /// The widest gap between neighbouring angles (degrees), from.
        from: f64,
        /// To.
        to: f64,
        /// The arc the run must cover (degrees).
        arc: f64,
        /// The widest gap allowed (degrees).
        allowed: f64,
    },
    /// A plane's axis with no prismatic variable of the machine named
    /// after it (a circle placed by its centre).
    NoAxis {
        /// The run.
        run: String,
        /// `x`, `y` or `z`.
        axis: &'static str,
        /// The machine.
        machine: String,
        /// Its variables.
        variables: Vec<String>,
    },
    /// A sample whose pose puts the nominal tool point off the run's
    /// nominal circle.
    OffCircle {
        /// The run.
        run: String,
        /// The distance from the circle's centre (mm).
        distance: f64,
        /// The run's radius (mm).
        radius: f64,
    },
    /// A run whose poses do not draw a circle (all on one line or point).
    NoCircle {
        /// The run.
        run: String,
    },
    /// A run whose poses draw a circle out of the run's plane.
    PlaneTilted {
        /// The run.
        run: String,
        /// Its plane.
        plane: &'static str,
        /// The tilt (degrees).
        tilt: f64,
    },
}

impl CircularProblem {
    /// Every part of the message of this problem: one match arm per
    /// variant.
    pub fn describe(&self) -> D {
        match self {
            CircularProblem::MissingColumn { name, columns } => D::new(
                "chain::circular::missing_column",
                "header",
                format!(
                    "the header has no `{name}` column (it has {})",
                    quoted(columns.iter().map(String::as_str))
                ),
            )
            .help(CIRCULAR_FILE_HEADER.to_string()),
            CircularProblem::Direction { found } => D::new(
                "chain::circular::direction",
                "direction",
                format!("`{found}` is not a direction: expected `ccw` (angle increasing) or `cw`"),
            ),
            CircularProblem::Plane { found } => D::new(
                "chain::circular::plane",
                "plane",
                format!("`{found}` is not a plane: expected `xy`, `yz` or `zx`"),
            ),
            CircularProblem::NotPositive { what, value } => D::new(
                "chain::circular::not_positive",
                "value",
                format!("the {what} must be positive, got {value}"),
            ),
            CircularProblem::RunDiffers {
                what,
                value,
                first,
                first_line,
                run,
            } => D::new(
                "chain::circular::run_differs",
                "value",
                format!("run {run}: {what} {value} differs from its first row's {first} (line {first_line}); a run has one {what}"),
            ),
            CircularProblem::NoRadius { run } => D::new(
                "chain::circular::no_radius",
                "header",
                format!("run {run} has no radius: the file has no `radius` column"),
            )
            .help("give the runs' nominal radius (mm): a `radius` column, or the radius every run without one takes".to_string()),
            CircularProblem::TooFewSamples {
                run,
                direction,
                count,
            } => D::new(
                "chain::circular::too_few_samples",
                "run",
                format!(
                    "run {run}, {direction}: {count} distinct angle(s); a circle needs at least {} around its arc",
                    crate::measured::circular::MIN_SAMPLES
                ),
            ),
            CircularProblem::NoAxis {
                run,
                axis,
                machine,
                variables,
            } => D::new(
                "chain::circular::no_axis",
                "plane",
                format!(
                    "run {run}: machine `{machine}` has no linear variable named `{axis}` to draw the circle with (its variables: {})",
                    quoted(variables.iter().map(String::as_str))
                ),
            )
            .help("a circle placed by its centre moves the machine's variables named after the plane's axes; for other axes give each sample's pose in columns named after the machine's variables".to_string()),
            CircularProblem::OffCircle {
                run,
                distance,
                radius,
            } => D::new(
                "chain::circular::off_circle",
                "pose",
                format!(
                    "run {run}: at this sample's pose the machine's nominal tool point is {distance} mm from the circle's centre, not the run's radius {radius} mm"
                ),
            )
            .help("the poses and the radius describe one circle: check the radius, the pose columns' units (rotary axes in degrees) and the centre".to_string()),
            CircularProblem::PlaneTilted { run, plane, tilt } => D::new(
                "chain::circular::plane_tilted",
                "pose",
                format!(
                    "run {run}: its poses draw a circle whose plane is tilted {tilt:.2}° from the run's plane {plane} (at most {}°)",
                    crate::measured::circular::records::MAX_TILT
                ),
            )
            .help("the run's `plane` names the plane its circle lies in (the table ball's offsets are taken along its axes)".to_string()),
            CircularProblem::NoCircle { run } => D::new(
                "chain::circular::no_circle",
                "pose",
                format!("run {run}: its poses put the nominal tool point on one line, not a circle"),
            ),
            CircularProblem::TooLarge { deviation, radius } => D::new(
                "chain::circular::too_large",
                "deviation",
                format!(
                    "a deviation of {deviation} mm on a radius of {radius} mm: a tenth of the radius or more is no ballbar reading"
                ),
            )
            .help("a deviation column in µm is named `deviation(um)`; `deviation` is in mm".to_string()),
            CircularProblem::NotCovered {
                run,
                direction,
                from,
                to,
                arc,
                allowed,
            } => D::new(
                "chain::circular::not_covered",
                "run",
                format!("run {run}, {direction}: no sample between {from}° and {to}°, so it does not cover its {arc}° arc (the widest gap allowed is {allowed}°)"),
            )
            .help("a run covers the whole circle unless the arc it covers (degrees) is given; measure the missing part, or give that arc".to_string()),
        }
    }
}
