//! `chain compensate` as a request and a document (seed 003's swing-angle
//! workflow; docs/compensation.md): the error Δθ(θ) from tool-tip heights
//! measured at commanded angles, the polynomial fits, the selected law, and
//! optionally the compensation table over a grid of angles. The
//! measurements are read by the adapter (a file for the CLI, a path or
//! columns for Python) through [`crate::compensate::records`]; the adapter
//! writes the table and the figures and lists them in
//! [`CompensateRun::written`].

use serde::Serialize;

use crate::compensate::{self, Analysis, CompensateError, Grid, Measurements, Options, TableRow};

/// The compensation table of `--table-out`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct TableRequest {
    /// `--grid`: its angles (default: the measured range in 1° steps,
    /// [`Grid::unit`]).
    pub grid: Option<Grid>,
    /// `--allow-extrapolation`: let the grid extend beyond the measured
    /// angles.
    pub allow_extrapolation: bool,
}

/// The request of `chain compensate`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CompensateRequest {
    /// `--length`, `--min-order`, `--max-order`, `--select`, `--order`.
    pub options: Options,
    /// The compensation table, if one is asked for.
    pub table: Option<TableRequest>,
}

/// The document of `chain compensate`: the analysis (the spec's fields first,
/// in struct order), then the files the adapter wrote, if any. Its JSON is
/// the `--format json` output.
#[derive(Debug, Clone, Serialize)]
pub struct CompensateRun {
    /// Everything derived from the measurements.
    #[serde(flatten)]
    pub analysis: Analysis,
    /// The compensation table's rows, if one was asked for (written by the
    /// adapter with [`compensate::write_table_csv`]).
    #[serde(skip)]
    pub table: Option<Vec<TableRow>>,
    /// The files written (`--table-out`, `--plot`), in order.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub written: Vec<String>,
}

/// Runs `chain compensate` over `measurements`: the analysis, then the table
/// over the request's grid (refused where it leaves the measured angles
/// unless extrapolation is allowed).
pub fn run(
    measurements: &Measurements,
    request: &CompensateRequest,
) -> Result<CompensateRun, CompensateError> {
    let analysis = compensate::analyze(measurements, &request.options)?;
    let table = match &request.table {
        Some(t) => {
            let [lo, hi] = analysis.angle_range();
            let grid = t.grid.unwrap_or(Grid::unit(lo, hi));
            Some(
                analysis
                    .compensation
                    .table(&grid.points()?, t.allow_extrapolation)?,
            )
        }
        None => None,
    };
    Ok(CompensateRun {
        analysis,
        table,
        written: Vec::new(),
    })
}
