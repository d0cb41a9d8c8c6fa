//! `chain map`'s preparation: the values read for the chosen approach, the
//! parameters, the points (the grid over `reliability.grid`, or rows), and
//! the built machine that maps them (measured-machines spec §3). The CLI
//! (which then maps or summarises, with a progress bar and `--compensated`)
//! and `Machine.map` run it.

use chain_core::built::{BuiltMachine, MapError, Points};
use chain_core::values::{Approach, ApproachError, Values};
use chain_core::Machine;
use reliability::ReliabilityError;

use super::resolve::{self, ResolveError};

/// The points of a map.
#[derive(Debug, Clone)]
pub enum MapPoints<'a> {
    /// `--grid` overrides of `reliability.grid`.
    Grid(&'a [(String, Vec<f64>)]),
    /// Rows of axis values in the machine's variable order, flat (`--axes`,
    /// an array).
    Rows(Vec<f64>),
}

/// The request of `chain map`.
#[derive(Debug, Clone)]
pub struct MapRequest<'a> {
    /// `--param NAME=VALUE`.
    pub params: &'a [(String, f64)],
    /// `--approach`.
    pub approach: &'a [(Option<String>, Approach)],
    /// The points.
    pub points: MapPoints<'a>,
}

/// A map ready to run.
#[derive(Debug, Clone)]
pub struct PreparedMap {
    /// The built machine.
    pub built: BuiltMachine,
    /// The points.
    pub points: Points,
    /// The grid's axes, when the points are a grid.
    pub grid: Option<Vec<(String, Vec<f64>)>>,
}

/// Why a map cannot be prepared.
#[derive(Debug, thiserror::Error)]
pub enum MapOpsError {
    /// An option does not match the machine.
    #[error(transparent)]
    Resolve(#[from] ResolveError),
    /// The parameters (located in the machine file).
    #[error(transparent)]
    Reliability(#[from] ReliabilityError),
    /// `--approach` names what the values do not have.
    #[error("--approach: {error} (values {values})")]
    Approach {
        /// The values file.
        values: String,
        /// What is wrong.
        error: ApproachError,
    },
    /// Rows that are not points of the machine.
    #[error("{source_name}: {error}")]
    Points {
        /// The rows' source.
        source_name: String,
        /// What is wrong.
        error: MapError,
    },
    /// The values and the machine do not go together.
    #[error("{values}: {message}")]
    Built {
        /// The values file.
        values: String,
        /// What is wrong.
        message: String,
    },
}

/// Prepares `chain map` of `machine` (`file` names it) with `values` (read
/// from `values_file`); `rows_name` names the rows of [`MapPoints::Rows`]
/// in messages.
pub fn prepare(
    machine: &Machine,
    file: &str,
    mut values: Values,
    values_file: &str,
    rows_name: &str,
    request: &MapRequest<'_>,
) -> Result<PreparedMap, MapOpsError> {
    let m = machine;
    if !request.approach.is_empty() {
        values
            .choose_approach(request.approach)
            .map_err(|error| MapOpsError::Approach {
                values: values_file.to_string(),
                error,
            })?;
    }
    resolve::check_parameters(m, request.params)?;
    let params = reliability::machine::parameters(m, request.params)?;
    let (points, grid) = match &request.points {
        MapPoints::Rows(flat) => {
            let points = Points::list(m.variables.len(), flat.clone()).map_err(|error| {
                MapOpsError::Points {
                    source_name: rows_name.to_string(),
                    error,
                }
            })?;
            (points, None)
        }
        MapPoints::Grid(overrides) => {
            let axes = resolve::grid_axes(m, file, overrides)?;
            let values = axes.iter().map(|(_, v)| v.clone()).collect();
            (Points::Grid(values), Some(axes))
        }
    };
    let built = BuiltMachine::compile(m, values, params).map_err(|e| MapOpsError::Built {
        values: values_file.to_string(),
        message: e.to_string(),
    })?;
    Ok(PreparedMap {
        built,
        points,
        grid,
    })
}
