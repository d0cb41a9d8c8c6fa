//! What an entry of a values file gives: the kind of name it is for, a
//! constant or a table (with its approach directions and scatter), and the
//! reversal a choice of direction leaves out.

use serde::Serialize;

use super::Table;
use super::{Extrapolation, Interpolation};
use crate::model::Origin;

/// Values of `chain map --approach` and [`Approach`].
pub const APPROACHES: &[&str] = &["up", "down", "mean"];

/// What kind of name of the machine an entry is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum EntryKind {
    /// A constant error parameter (or an error motion given as a constant).
    Error,
    /// A coefficient `<F>_<suffix>` of a function slot.
    Coefficient,
    /// A function slot `F` (given as a table of `F(q)`).
    Function,
}

/// What an entry gives.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "given", rename_all = "lowercase")]
pub enum Given {
    /// A constant, in the machine's units.
    Constant {
        /// The value.
        value: f64,
        /// Its standard deviation, if the file gives one (`chain identify`
        /// writes it; nothing here uses it).
        #[serde(skip_serializing_if = "Option::is_none")]
        std: Option<f64>,
        /// `carried_by`: the estimated errors that carry this one's effect
        /// (a redundant error an identification fixed: docs/posterior.md,
        /// "Fixed and carried"); empty when the file does not say. A
        /// reliability study then takes the value as exact instead of
        /// keeping its `statistics` spread, which the carriers' `std`
        /// already holds.
        #[serde(skip_serializing_if = "Vec::is_empty")]
        carried_by: Vec<String>,
    },
    /// A table along an axis.
    Table {
        /// The axis variable.
        variable: String,
        /// Where the points came from: `points` or `FILE.csv, column NAME`.
        source: String,
        /// The number of points.
        points: usize,
        /// The first and last position.
        range: [f64; 2],
        /// How it is read between points.
        interpolation: Interpolation,
        /// What it gives outside its range.
        extrapolation: Extrapolation,
        /// Where the other approach direction's points came from
        /// (`reverse_points` or `FILE.csv, column NAME`), if given.
        #[serde(skip_serializing_if = "Option::is_none")]
        reverse: Option<String>,
        /// Where the per-position standard deviations came from, if given.
        #[serde(skip_serializing_if = "Option::is_none")]
        std: Option<String>,
        /// Where the other direction's standard deviations came from.
        #[serde(skip_serializing_if = "Option::is_none")]
        reverse_std: Option<String>,
    },
}

/// Which approach direction of a bidirectional error motion is read
/// (docs/values.md, "Direction"). A table without a reverse direction reads
/// the same for all three.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Approach {
    /// The position approached moving in the positive direction (ISO 230-2
    /// ↑): the table's main values.
    Up,
    /// Approached moving in the negative direction (↓): its `reverse` values.
    Down,
    /// The mean of the two, `(up + down)/2` (ISO 230-2:2014 2.13, the mean
    /// bidirectional positional deviation `x̄_i`): the default.
    #[default]
    Mean,
}

impl Approach {
    /// `up`, `down` or `mean`.
    pub fn name(self) -> &'static str {
        match self {
            Approach::Up => "up",
            Approach::Down => "down",
            Approach::Mean => "mean",
        }
    }
}

impl std::fmt::Display for Approach {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Approach {
    type Err = String;
    fn from_str(text: &str) -> Result<Approach, String> {
        match text {
            "up" | "+" => Ok(Approach::Up),
            "down" | "-" => Ok(Approach::Down),
            "mean" => Ok(Approach::Mean),
            _ => Err(format!(
                "`{text}` is not an approach direction: expected up, down or mean"
            )),
        }
    }
}

/// A table with where its points came from (for messages and reports).
#[derive(Debug, Clone, PartialEq)]
pub struct Sourced {
    /// The table.
    pub table: Table,
    /// `points`, or `FILE.csv, column NAME`.
    pub source: String,
}

/// A measured error motion with what a bidirectional positioning run gives
/// (docs/values.md, "Direction"): the deviation approached moving up, the
/// one approached moving down, and each one's standard deviation per
/// position (the run-to-run scatter, ISO 230-2:2014 2.17). Only `up` is
/// required; without `down` the motion is the same from either side.
#[derive(Debug, Clone, PartialEq)]
pub struct Motion {
    /// `v↑(q)`, or the only table.
    pub up: Sourced,
    /// `v↓(q)`.
    pub down: Option<Sourced>,
    /// `s↑(q)` (every value ≥ 0); without `std_down` it holds for both
    /// directions.
    pub std_up: Option<Sourced>,
    /// `s↓(q)` (needs `down`).
    pub std_down: Option<Sourced>,
}

impl Motion {
    /// One table, the same from either side, without a scatter.
    pub fn single(table: Table, source: &str) -> Motion {
        Motion {
            up: Sourced {
                table,
                source: source.to_string(),
            },
            down: None,
            std_up: None,
            std_down: None,
        }
    }
}

/// The largest difference between the two approach directions of one
/// bidirectional error motion: what a choice of [`Approach`] leaves out.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Reversal {
    /// The entry (error motion or function slot).
    pub name: String,
    /// Its axis variable.
    pub variable: String,
    /// The approach read.
    pub approach: Approach,
    /// `max |v↑(q) − v↓(q)|` over the positions of both tables inside
    /// their common range, in the machine's units (mm or rad).
    pub largest: f64,
    /// The position where it is largest.
    pub at: f64,
    /// What the choice leaves out at worst: the whole reversal for `up` or
    /// `down`, half of it for `mean`.
    pub left_out: f64,
    /// The unit of `largest` and `left_out`: `mm` or `rad`.
    pub unit: &'static str,
}

/// Parses a choice of approach directions: `DIR` for every axis, or
/// `VAR=DIR`, comma-separated (`x=up,y=down`); `DIR` is `up`, `down` or
/// `mean` (`chain map --approach`).
pub fn parse_approaches(text: &str) -> Result<Vec<(Option<String>, Approach)>, String> {
    text.split(',')
        .map(|item| {
            let item = item.trim();
            match item.split_once('=') {
                Some((var, dir)) if !var.trim().is_empty() => {
                    Ok((Some(var.trim().to_string()), dir.trim().parse()?))
                }
                Some(_) => Err(format!("`{item}` has no variable before `=`")),
                None => Ok((None, item.parse()?)),
            }
        })
        .collect()
}

/// One name of the machine and what the values gave it (for reports).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Entry {
    /// The name as written.
    pub name: String,
    /// What it is in the machine.
    pub kind: EntryKind,
    /// What it was given.
    #[serde(flatten)]
    pub given: Given,
    /// Where it was given (`None` when given from Rust).
    #[serde(skip)]
    pub origin: Option<Origin>,
}
