//! Options resolved against a machine, one rule each (docs/python.md and
//! the commands' docs name the options): `--param` names and values
//! ([`Parameters`]), the grid of a study or map (`--grid` over
//! `reliability.grid`), a point given by axis name (`--at`), and the points
//! of a map or a grid export ([`AxisPoints`]: the grid or rows, not both).
//! [`ResolveError`] words every refusal once; the CLI prints it and Python
//! raises it.

use chain_core::built::{MapError, Points};
use chain_core::diagnostic::closest;
use chain_core::Machine;
use reliability::ReliabilityError;

use super::worded::{diagnostic, Worded};

/// Why an option cannot be resolved against the machine.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ResolveError {
    /// `--param` names no parameter of the machine.
    #[error(
        "--param {name}: machine `{machine}` has no parameter `{name}`{}",
        did_you_mean(suggestion)
    )]
    UnknownParameter {
        /// The name given.
        name: String,
        /// The machine.
        machine: String,
        /// The closest parameter, if one is close.
        suggestion: Option<String>,
    },
    /// A parameter value that is infinite or NaN.
    #[error("--param {name}: {value} is not finite")]
    NonFiniteParameter {
        /// The parameter.
        name: String,
        /// The value.
        value: f64,
    },
    /// A parameter value beyond any physical size
    /// ([`chain_core::load::PHYSICAL_SIZE`]).
    #[error(
        "--param {name}: {value:e} is beyond any physical size: a parameter must be in {}",
        chain_core::load::PHYSICAL_RANGE
    )]
    ParameterBeyondSize {
        /// The parameter.
        name: String,
        /// The value.
        value: f64,
    },
    /// `--grid` names no axis variable of the machine.
    #[error("{file}: unknown axis variable `{name}`{}", did_you_mean(suggestion))]
    UnknownGridAxis {
        /// The machine file.
        file: String,
        /// The name given.
        name: String,
        /// The machine's axis variables.
        variables: Vec<String>,
        /// The closest variable, if one is close.
        suggestion: Option<String>,
    },
    /// A `--grid` axis without values.
    #[error("--grid {name}: the axis has no value")]
    EmptyGridAxis {
        /// The axis variable.
        name: String,
    },
    /// A `--grid` value that is infinite or NaN.
    #[error("--grid {name}: {value} is not finite")]
    NonFiniteGridValue {
        /// The axis variable.
        name: String,
        /// The value.
        value: f64,
    },
    /// An axis variable with neither `reliability.grid` values nor `--grid`.
    #[error("{file}: no grid values for axis variable `{variable}`")]
    MissingGrid {
        /// The machine file.
        file: String,
        /// The axis variable.
        variable: String,
    },
    /// `--at` names no axis variable of the machine.
    #[error("--at: `{name}` is not an axis variable{}", did_you_mean(suggestion))]
    UnknownAtVariable {
        /// The machine file.
        file: String,
        /// The name given.
        name: String,
        /// The machine's axis variables.
        variables: Vec<String>,
        /// The closest variable, if one is close.
        suggestion: Option<String>,
    },
    /// An `--at` value that is infinite or NaN.
    #[error("--at: `{name}` = {value} is not finite")]
    NonFiniteAt {
        /// The axis variable.
        name: String,
        /// The value.
        value: f64,
    },
    /// `--fix` names no axis variable of the machine.
    #[error(
        "--fix: `{name}` is not an axis variable of machine `{machine}`{}",
        did_you_mean(suggestion)
    )]
    UnknownFixed {
        /// The name given.
        name: String,
        /// The machine.
        machine: String,
        /// The closest variable, if one is close.
        suggestion: Option<String>,
    },
    /// `--at` leaves an axis variable without a value.
    #[error("--at has no value for axis variable `{variable}`")]
    MissingAt {
        /// The variable without a value.
        variable: String,
        /// Every axis variable.
        variables: Vec<String>,
    },
    /// `--at` with inputs that differ from point to point (a values file
    /// with tables): they are known at the grid's points only.
    #[error("--at: the inputs differ from point to point (tables in the values)")]
    AtVaryingInputs,
    /// `--at` (one point) and `--grid` (the grid of a mean) given together.
    #[error("--grid cannot be combined with --at")]
    AtWithGrid {
        /// What the grid is for: `the mean`, `pooling`.
        grid_for: &'static str,
    },
    /// A column of an axes table that names no axis variable.
    #[error(
        "{file}:1: column `{column}` is not an axis variable of machine `{machine}`{}{}; expected `t` (optional, first) and {}",
        did_you_mean(suggestion),
        if column == "t" { "; `t` (the instant) must be the first column" } else { "" },
        quoted(variables)
    )]
    UnknownAxisColumn {
        /// The table (file name, `<stdin>`, or Python's `axes`).
        file: String,
        /// The column's name.
        column: String,
        /// The machine.
        machine: String,
        /// The machine's axis variables.
        variables: Vec<String>,
        /// The closest variable, if one is close.
        suggestion: Option<String>,
    },
    /// A variable with a column of an axes table and a `--fix` value.
    #[error("{file}:1: variable `{variable}` has a column and a --fix value; give one of them")]
    ColumnAndFix {
        /// The table.
        file: String,
        /// The variable.
        variable: String,
    },
    /// Axis variables with neither a column nor (where the command takes
    /// one) a `--fix` value.
    #[error(
        "{file}:1: no column for axis variable{} {}; {}",
        if missing.len() > 1 { "s" } else { "" },
        quoted(missing),
        if *fixable {
            "add the column or hold it with --fix NAME=VALUE".to_string()
        } else {
            format!("the header names every axis variable ({})", quoted(variables))
        }
    )]
    MissingAxisColumns {
        /// The table.
        file: String,
        /// The variables without a column.
        missing: Vec<String>,
        /// Every axis variable.
        variables: Vec<String>,
        /// Whether the command takes `--fix`.
        fixable: bool,
    },
    /// `--grid` (the grid's axes) and `--axes` (rows of points) given
    /// together.
    #[error("--grid cannot be combined with --axes")]
    GridWithRows,
    /// `--temperature` does not match the machine's sensors.
    #[error("--temperature: {0}")]
    Temperature(chain_core::model::TemperatureError),
    /// Rows that do not make points of the machine.
    #[error("{name}: {error}")]
    Rows {
        /// The rows' name (the `--axes` file, Python's `points`).
        name: String,
        /// What is wrong.
        error: MapError,
    },
}

impl ResolveError {
    /// True when the machine file is what the option does not match (an
    /// unknown name): Python raises these as `MachineError` naming the file
    /// (a `ValueError`), the others as `ValueError`.
    pub fn names_the_machine(&self) -> bool {
        matches!(
            self,
            ResolveError::UnknownParameter { .. }
                | ResolveError::UnknownGridAxis { .. }
                | ResolveError::UnknownAtVariable { .. }
                | ResolveError::UnknownFixed { .. }
                | ResolveError::MissingGrid { .. }
                | ResolveError::Temperature(
                    chain_core::model::TemperatureError::Unknown { .. }
                        | chain_core::model::TemperatureError::NoSensors { .. }
                )
        )
    }
}

impl Worded for ResolveError {
    fn own_code(&self) -> Option<&'static str> {
        Some(match self {
            ResolveError::UnknownParameter { .. } => "chain::cli::unknown_parameter",
            ResolveError::NonFiniteParameter { .. } => "chain::cli::param_not_finite",
            ResolveError::ParameterBeyondSize { .. } => "chain::cli::param_out_of_range",
            ResolveError::UnknownGridAxis { .. } => "chain::reliability::unknown_name",
            ResolveError::EmptyGridAxis { .. } => "chain::cli::empty_grid_axis",
            ResolveError::NonFiniteGridValue { .. } => "chain::cli::grid_not_finite",
            ResolveError::MissingGrid { .. } => "chain::map::missing_grid",
            ResolveError::UnknownAtVariable { .. } => "chain::cli::at_unknown_variable",
            ResolveError::NonFiniteAt { .. } => "chain::cli::at_not_finite",
            ResolveError::UnknownFixed { .. } => "chain::cli::fix_unknown_variable",
            ResolveError::MissingAt { .. } => "chain::cli::at_missing_variable",
            ResolveError::AtVaryingInputs => "chain::cli::at_varying_inputs",
            ResolveError::AtWithGrid { .. } => "chain::cli::at_with_grid",
            ResolveError::UnknownAxisColumn { .. } => "chain::csv::unknown_column",
            ResolveError::ColumnAndFix { .. } => "chain::cli::fix_and_column",
            ResolveError::MissingAxisColumns { .. } => "chain::csv::missing_column",
            ResolveError::GridWithRows => "chain::cli::grid_with_axes",
            ResolveError::Rows { .. } => "chain::map::points",
            ResolveError::Temperature(_) => "chain::cli::temperature",
        })
    }

    fn own_help(&self) -> Option<String> {
        Some(match self {
            ResolveError::UnknownGridAxis { variables, .. } => {
                format!("the axis variables are {}", variables.join(", "))
            }
            ResolveError::MissingGrid { variable, .. } => format!(
                "add `{variable}: [...]` to `reliability.grid`, or pass --grid {variable}=V1,V2,... or --grid {variable}=LO:HI:N"
            ),
            ResolveError::UnknownAtVariable {
                file, variables, ..
            } => format!("the axis variables of {file} are {}", variables.join(", ")),
            ResolveError::AtVaryingInputs => {
                "give the point as a one-point grid (--grid VAR=VALUE for every axis) instead".into()
            }
            ResolveError::AtWithGrid { grid_for } => format!(
                "--at evaluates at one point, --grid sets the grid of {grid_for}; give one"
            ),
            ResolveError::GridWithRows => {
                "--axes gives the points, --grid the grid over `reliability.grid`; give one".into()
            }
            ResolveError::MissingAt { variables, .. } => format!(
                "give every axis variable: --at {}",
                (variables.iter())
                    .map(|v| format!("{v}=…"))
                    .collect::<Vec<_>>()
                    .join(",")
            ),
            _ => return None,
        })
    }
}

diagnostic!(ResolveError);

/// ` (did you mean `x`?)`, or nothing.
fn did_you_mean(suggestion: &Option<String>) -> String {
    suggestion
        .as_ref()
        .map(|s| format!(" (did you mean `{s}`?)"))
        .unwrap_or_default()
}

/// `` `a`, `b` ``: names quoted and joined.
fn quoted(names: &[String]) -> String {
    (names.iter())
        .map(|n| format!("`{n}`"))
        .collect::<Vec<_>>()
        .join(", ")
}

fn variables(m: &Machine) -> Vec<String> {
    m.variables.iter().map(|v| v.name.clone()).collect()
}

fn closest_variable(m: &Machine, name: &str) -> Option<String> {
    closest(name, m.variables.iter().map(|v| v.name.as_str())).map(str::to_string)
}

/// The thermal state of `--temperature NAME=VALUE,...` (°C; every sensor
/// not named at its reference), and each error's thermal factor there
/// ([`Machine::thermal_factors`]). The one rule of `--temperature`, for
/// every command and Python's `temperature`.
pub fn thermal_factors(
    m: &Machine,
    temperatures: &[(String, f64)],
) -> Result<Vec<f64>, ResolveError> {
    let t = m
        .temperatures(temperatures)
        .map_err(ResolveError::Temperature)?;
    Ok(m.thermal_factors(&t))
}

/// `values` at the thermal state of `--temperature` ([`thermal_factors`],
/// [`chain_core::values::Values::at_thermal_state`]) and the state itself,
/// every sensor named with its °C (empty for a machine without sensors).
pub fn at_thermal_state(
    m: &Machine,
    values: chain_core::values::Values,
    temperatures: &[(String, f64)],
) -> Result<(chain_core::values::Values, Vec<(String, f64)>), ResolveError> {
    let t = m
        .temperatures(temperatures)
        .map_err(ResolveError::Temperature)?;
    let state = (m.sensors.iter())
        .zip(&t)
        .map(|(s, t)| (s.name.clone(), *t))
        .collect();
    Ok((values.at_thermal_state(&m.thermal_factors(&t)), state))
}

/// Checks `--param NAME=VALUE` against the machine: every name one of its
/// parameters, every value finite. The one rule of `--param`, for every
/// command and Python's `params`; [`Parameters`] places the values, and the
/// commands whose parameters may also come per CSV row check the names
/// alone here.
pub fn check_parameters(m: &Machine, params: &[(String, f64)]) -> Result<(), ResolveError> {
    for (name, value) in params {
        if m.parameter_index(name).is_none() {
            return Err(ResolveError::UnknownParameter {
                name: name.clone(),
                machine: m.name.clone(),
                suggestion: closest(name, m.parameters.iter().map(|p| p.name.as_str()))
                    .map(str::to_string),
            });
        }
        if !value.is_finite() {
            return Err(ResolveError::NonFiniteParameter {
                name: name.clone(),
                value: *value,
            });
        }
        if value.abs() > chain_core::load::PHYSICAL_SIZE {
            return Err(ResolveError::ParameterBeyondSize {
                name: name.clone(),
                value: *value,
            });
        }
    }
    Ok(())
}

/// `--param NAME=VALUE` checked against a machine ([`check_parameters`]):
/// a set of parameter values that holds no unknown name and no value that
/// is not finite.
#[derive(Debug, Clone, Copy)]
pub struct Parameters<'a> {
    machine: &'a Machine,
    given: &'a [(String, f64)],
}

impl<'a> Parameters<'a> {
    /// The values `given` for `machine`'s parameters, checked.
    pub fn new(
        machine: &'a Machine,
        given: &'a [(String, f64)],
    ) -> Result<Parameters<'a>, ResolveError> {
        check_parameters(machine, given)?;
        Ok(Parameters { machine, given })
    }

    /// The values as given (later ones win).
    pub fn given(&self) -> &'a [(String, f64)] {
        self.given
    }

    /// Every parameter's value in the machine's order: the one given, else
    /// the file's; a symbolic parameter with neither is refused, located in
    /// the machine file ([`ReliabilityError::SymbolicParameter`]).
    pub fn values(&self) -> Result<Vec<f64>, ReliabilityError> {
        reliability::machine::parameters(self.machine, self.given)
    }
}

/// The grid axes in the machine's variable order: each axis of
/// `reliability.grid`, replaced by the last override that names it; every
/// axis variable must have at least one value (`chain map`, Python's
/// `Machine.map`). `file` names the machine file in messages.
pub fn grid_axes(
    m: &Machine,
    file: &str,
    overrides: &[(String, Vec<f64>)],
) -> Result<Vec<(String, Vec<f64>)>, ResolveError> {
    check_grid_overrides(m, file, overrides)?;
    let file_grid = m.reliability.as_ref().map(|r| &r.grid);
    (m.variables.iter().enumerate())
        .map(|(k, v)| {
            let given = overrides.iter().rev().find(|(n, _)| *n == v.name);
            let values = match given {
                Some((_, values)) => values.clone(),
                None => match file_grid.and_then(|g| g.iter().find(|(i, _)| *i == k)) {
                    Some((_, values)) => values.clone(),
                    None => {
                        return Err(ResolveError::MissingGrid {
                            file: file.to_string(),
                            variable: v.name.clone(),
                        })
                    }
                },
            };
            Ok((v.name.clone(), values))
        })
        .collect()
}

/// Checks `--grid` overrides: each names an axis variable and has values,
/// all finite.
pub fn check_grid_overrides(
    m: &Machine,
    file: &str,
    overrides: &[(String, Vec<f64>)],
) -> Result<(), ResolveError> {
    for (name, values) in overrides {
        if m.variable_index(name).is_none() {
            return Err(ResolveError::UnknownGridAxis {
                file: file.to_string(),
                name: name.clone(),
                variables: variables(m),
                suggestion: closest_variable(m, name),
            });
        }
        if values.is_empty() {
            return Err(ResolveError::EmptyGridAxis { name: name.clone() });
        }
        if let Some(&value) = values.iter().find(|x| !x.is_finite()) {
            return Err(ResolveError::NonFiniteGridValue {
                name: name.clone(),
                value,
            });
        }
    }
    Ok(())
}

/// A point given by axis name (`--at x=0,y=100,...`) in the machine's
/// variable order: every axis variable once (a repeated name: the last
/// value), no unknown name, every value finite. `file` names the machine
/// file in messages.
pub fn at_point(
    m: &Machine,
    file: &str,
    coords: &[(String, f64)],
) -> Result<Vec<f64>, ResolveError> {
    if let Some((name, _)) = coords.iter().find(|(n, _)| m.variable_index(n).is_none()) {
        return Err(ResolveError::UnknownAtVariable {
            file: file.to_string(),
            name: name.clone(),
            variables: variables(m),
            suggestion: closest_variable(m, name),
        });
    }
    if let Some((name, value)) = coords.iter().find(|(_, x)| !x.is_finite()) {
        return Err(ResolveError::NonFiniteAt {
            name: name.clone(),
            value: *value,
        });
    }
    (m.variables.iter())
        .map(|v| {
            (coords.iter().rev())
                .find(|(n, _)| *n == v.name)
                .map(|(_, x)| *x)
                .ok_or_else(|| ResolveError::MissingAt {
                    variable: v.name.clone(),
                    variables: variables(m),
                })
        })
        .collect()
}

/// `--fix NAME=VALUE` as `(variable index, value)`, each variable once
/// (given twice: the later value).
pub fn fixed(m: &Machine, fix: &[(String, f64)]) -> Result<Vec<(usize, f64)>, ResolveError> {
    let mut out: Vec<(usize, f64)> = Vec::new();
    for (name, v) in fix {
        let Some(i) = m.variable_index(name) else {
            return Err(ResolveError::UnknownFixed {
                name: name.clone(),
                machine: m.name.clone(),
                suggestion: closest_variable(m, name),
            });
        };
        match out.iter_mut().find(|(j, _)| *j == i) {
            Some(slot) => slot.1 = *v,
            None => out.push((i, *v)),
        }
    }
    Ok(out)
}

/// The points a map or a grid export is evaluated at: the full-factorial
/// grid of `reliability.grid` with `--grid` overrides, or rows of axis
/// values (`--axes`, Python's `points`), one or the other.
#[derive(Debug, Clone)]
pub enum AxisPoints<'a> {
    /// `--grid` overrides of `reliability.grid`.
    Grid(&'a [(String, Vec<f64>)]),
    /// Rows of axis values in the machine's variable order, flat.
    Rows {
        /// The rows' name in messages (the `--axes` file, `points`).
        name: String,
        /// The values, one row after another.
        values: Vec<f64>,
    },
}

/// Where the points of a map or an export came from, resolved.
#[derive(Debug, Clone, PartialEq)]
pub enum PointsInput {
    /// The full-factorial grid of these axes (machine variable order).
    Grid(Vec<(String, Vec<f64>)>),
    /// Rows, named so (`--axes` file, `points`).
    Rows(String),
}

impl<'a> AxisPoints<'a> {
    /// `--grid` overrides or `--axes` rows (`(name, values)`): refused when
    /// both are given.
    pub fn new(
        grid: &'a [(String, Vec<f64>)],
        rows: Option<(String, Vec<f64>)>,
    ) -> Result<AxisPoints<'a>, ResolveError> {
        match rows {
            Some(_) if !grid.is_empty() => Err(ResolveError::GridWithRows),
            Some((name, values)) => Ok(AxisPoints::Rows { name, values }),
            None => Ok(AxisPoints::Grid(grid)),
        }
    }

    /// The `--grid` overrides (none for rows).
    pub fn grid(&self) -> &'a [(String, Vec<f64>)] {
        match self {
            AxisPoints::Grid(g) => g,
            AxisPoints::Rows { .. } => &[],
        }
    }

    /// The library's points and where they came from: the grid's axes
    /// resolved ([`grid_axes`]; `file` names the machine file), or the rows
    /// as whole points of the machine.
    pub fn resolve(&self, m: &Machine, file: &str) -> Result<(Points, PointsInput), ResolveError> {
        match self {
            AxisPoints::Rows { name, values } => {
                let points = Points::list(m.variables.len(), values.clone()).map_err(|error| {
                    ResolveError::Rows {
                        name: name.clone(),
                        error,
                    }
                })?;
                Ok((points, PointsInput::Rows(name.clone())))
            }
            AxisPoints::Grid(overrides) => {
                let axes = grid_axes(m, file, overrides)?;
                let values = axes.iter().map(|(_, v)| v.clone()).collect();
                Ok((Points::Grid(values), PointsInput::Grid(axes)))
            }
        }
    }
}

/// Where each axis variable's values come from in a table of axis values
/// (`chain path --axes`, `chain map --axes`, `chain export --axes`,
/// Python's arrays with named columns): its column, or a `--fix` value.
#[derive(Debug, Clone, PartialEq)]
pub struct AxesColumns {
    /// Whether the first column is the instant `t`.
    pub has_t: bool,
    /// Per axis variable, its column.
    columns: Vec<Option<usize>>,
    /// `--fix` values of the variables without a column.
    fixed: Vec<(usize, f64)>,
}

impl AxesColumns {
    /// Resolves `header` against the machine: an optional first column `t`
    /// (when the machine has no variable `t`, or the header names `t` again
    /// later), then axis variables in any order; every variable has a column
    /// or, where the command takes `--fix` (`fixed` is `Some`), a fixed value,
    /// not both. `file` names the table in messages (line 1 is the header).
    pub fn resolve(
        m: &Machine,
        file: &str,
        header: &[String],
        fixed: Option<&[(usize, f64)]>,
    ) -> Result<AxesColumns, ResolveError> {
        let has_t = header.first().is_some_and(|h| h == "t")
            && (m.variable_index("t").is_none() || header[1..].iter().any(|h| h == "t"));
        let held = fixed.unwrap_or(&[]);
        let mut columns: Vec<Option<usize>> = vec![None; m.variables.len()];
        for (k, h) in header.iter().enumerate().skip(usize::from(has_t)) {
            let Some(v) = m.variable_index(h) else {
                return Err(ResolveError::UnknownAxisColumn {
                    file: file.to_string(),
                    column: h.clone(),
                    machine: m.name.clone(),
                    variables: variables(m),
                    suggestion: closest_variable(m, h),
                });
            };
            if held.iter().any(|(i, _)| *i == v) {
                return Err(ResolveError::ColumnAndFix {
                    file: file.to_string(),
                    variable: h.clone(),
                });
            }
            columns[v] = Some(k);
        }
        let missing: Vec<String> = (m.variables.iter().enumerate())
            .filter(|(v, _)| columns[*v].is_none() && !held.iter().any(|(i, _)| i == v))
            .map(|(_, x)| x.name.clone())
            .collect();
        if !missing.is_empty() {
            return Err(ResolveError::MissingAxisColumns {
                file: file.to_string(),
                missing,
                variables: variables(m),
                fixable: fixed.is_some(),
            });
        }
        Ok(AxesColumns {
            has_t,
            columns,
            fixed: held.to_vec(),
        })
    }

    /// The point of a row (in the header's column order), in the machine's
    /// variable order.
    pub fn point(&self, row: &[f64]) -> Vec<f64> {
        (self.columns.iter().enumerate())
            .map(|(v, c)| match c {
                Some(c) => row[*c],
                None => (self.fixed.iter())
                    .find(|(i, _)| *i == v)
                    .map_or(f64::NAN, |(_, x)| *x),
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn machine() -> Machine {
        let yaml = "machine: m\nparameters: {L: 100}\nbodies:\n  bed: {}\n  x_slide: {parent: bed, joint: {type: prismatic, axis: +x, variable: x}}\n  z_slide: {parent: x_slide, joint: {type: prismatic, axis: +z, variable: z}}\nworkpiece: bed\ntool: z_slide\nreliability:\n  tolerance: {px: 0.01}\n  grid: {x: [0, 10]}\n";
        chain_core::load_str(yaml, "m.yaml").unwrap()
    }

    #[test]
    fn grid_axes_are_the_file_s_with_overrides() {
        let m = machine();
        let e = grid_axes(&m, "m.yaml", &[]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "m.yaml: no grid values for axis variable `z`"
        );
        assert!(e
            .with_help()
            .ends_with("or pass --grid z=V1,V2,... or --grid z=LO:HI:N"));
        let g = grid_axes(
            &m,
            "m.yaml",
            &[("z".into(), vec![1.0]), ("z".into(), vec![2.0, 3.0])],
        )
        .unwrap();
        assert_eq!(
            g,
            vec![("x".into(), vec![0.0, 10.0]), ("z".into(), vec![2.0, 3.0])]
        );
        let e = grid_axes(&m, "m.yaml", &[("xx".into(), vec![1.0])]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "m.yaml: unknown axis variable `xx` (did you mean `x`?)"
        );
        assert!(e.names_the_machine());
        let e = grid_axes(&m, "m.yaml", &[("z".into(), vec![])]).unwrap_err();
        assert_eq!(e.to_string(), "--grid z: the axis has no value");
        let e = grid_axes(&m, "m.yaml", &[("z".into(), vec![f64::NAN])]).unwrap_err();
        assert_eq!(e.to_string(), "--grid z: NaN is not finite");
    }

    #[test]
    fn at_points_name_every_variable() {
        let m = machine();
        let p = at_point(
            &m,
            "m.yaml",
            &[("z".into(), 1.0), ("x".into(), 2.0), ("z".into(), 3.0)],
        )
        .unwrap();
        assert_eq!(p, vec![2.0, 3.0]);
        let e = at_point(&m, "m.yaml", &[("x".into(), 2.0)]).unwrap_err();
        assert_eq!(
            e.with_help(),
            "--at has no value for axis variable `z`\nhelp: give every axis variable: --at x=…,z=…"
        );
        let e = at_point(&m, "m.yaml", &[("w".into(), 2.0)]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "--at: `w` is not an axis variable (did you mean `x`?)"
        );
        let e = at_point(&m, "m.yaml", &[("x".into(), f64::INFINITY)]).unwrap_err();
        assert_eq!(e.to_string(), "--at: `x` = inf is not finite");
        assert!(!e.names_the_machine());
    }

    #[test]
    fn axes_columns_name_every_variable_once() {
        let m = machine();
        let h = |s: &str| s.split(',').map(String::from).collect::<Vec<_>>();
        let c = AxesColumns::resolve(&m, "a.csv", &h("t,z,x"), None).unwrap();
        assert!(c.has_t);
        assert_eq!(c.point(&[0.5, 1.0, 2.0]), vec![2.0, 1.0]);
        let c = AxesColumns::resolve(&m, "a.csv", &h("z"), Some(&[(0, 7.0)])).unwrap();
        assert_eq!(c.point(&[1.0]), vec![7.0, 1.0]);
        let e = AxesColumns::resolve(&m, "a.csv", &h("z,t"), None).unwrap_err();
        assert_eq!(
            e.to_string(),
            "a.csv:1: column `t` is not an axis variable of machine `m` (did you mean `x`?); `t` (the instant) must be the first column; expected `t` (optional, first) and `x`, `z`"
        );
        let e = AxesColumns::resolve(&m, "a.csv", &h("x,z"), Some(&[(0, 7.0)])).unwrap_err();
        assert_eq!(
            e.to_string(),
            "a.csv:1: variable `x` has a column and a --fix value; give one of them"
        );
        let e = AxesColumns::resolve(&m, "a.csv", &h("t"), Some(&[])).unwrap_err();
        assert_eq!(
            e.to_string(),
            "a.csv:1: no column for axis variables `x`, `z`; add the column or hold it with --fix NAME=VALUE"
        );
        let e = AxesColumns::resolve(&m, "a.csv", &h("xx"), None).unwrap_err();
        assert_eq!(
            e.to_string(),
            "a.csv:1: column `xx` is not an axis variable of machine `m` (did you mean `x`?); expected `t` (optional, first) and `x`, `z`"
        );
        let e = AxesColumns::resolve(&m, "a.csv", &h("x"), None).unwrap_err();
        assert_eq!(
            e.to_string(),
            "a.csv:1: no column for axis variable `z`; the header names every axis variable (`x`, `z`)"
        );
    }

    #[test]
    fn parameters_are_the_machine_s() {
        let m = machine();
        assert!(check_parameters(&m, &[("L".into(), 5.0)]).is_ok());
        let e = check_parameters(&m, &[("l".into(), 5.0)]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "--param l: machine `m` has no parameter `l` (did you mean `L`?)"
        );
        let e = check_parameters(&m, &[("L".into(), f64::NAN)]).unwrap_err();
        assert_eq!(e.to_string(), "--param L: NaN is not finite");
        let given = [("L".to_string(), 5.0)];
        let p = Parameters::new(&m, &given).unwrap();
        assert_eq!(p.values().unwrap(), vec![5.0]);
        assert!(Parameters::new(&m, &[("l".into(), 5.0)])
            .unwrap_err()
            .names_the_machine());
    }

    #[test]
    fn points_are_a_grid_or_rows() {
        let m = machine();
        let grid = [("z".to_string(), vec![1.0])];
        let e = AxisPoints::new(&grid, Some(("a.csv".into(), vec![]))).unwrap_err();
        assert_eq!(
            e.with_help(),
            "--grid cannot be combined with --axes\nhelp: --axes gives the points, --grid the grid over `reliability.grid`; give one"
        );
        let (points, input) = (AxisPoints::new(&grid, None).unwrap())
            .resolve(&m, "m.yaml")
            .unwrap();
        assert_eq!(points.len(), 2);
        assert_eq!(
            input,
            PointsInput::Grid(vec![("x".into(), vec![0.0, 10.0]), ("z".into(), vec![1.0])])
        );
        let rows = AxisPoints::new(&[], Some(("a.csv".into(), vec![1.0, 2.0, 3.0]))).unwrap();
        assert!(rows.grid().is_empty());
        let e = rows.resolve(&m, "m.yaml").unwrap_err();
        assert_eq!(
            e.to_string(),
            "a.csv: 3 axis values do not make whole points of 2 variables"
        );
    }
}
