//! The compensation table a controller loads: the command that reaches each
//! angle of a grid, and its CSV form.

use std::fmt;
use std::io::Write;
use std::str::FromStr;

use serde::Serialize;

use super::{CompensateError, Compensation, MAX_GRID_POINTS};

/// One row of a compensation table.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TableRow {
    /// Nominal angle `θt` (degrees): the target, and the uncompensated command.
    pub theta_deg: f64,
    /// The law's error `Δθ(θt)` (degrees).
    pub delta_theta_deg: f64,
    /// `θt + Δθ(θt)` (Eq. 7): where the axis goes when `θt` is commanded
    /// uncompensated (degrees).
    pub actual_deg: f64,
    /// The command `c` with `c + Δθ(c) = θt`: what to send to reach `θt`
    /// (degrees).
    pub command_deg: f64,
    /// `c − θt`: the offset a controller adds to the command (degrees).
    pub correction_deg: f64,
}

/// Header of [`write_table_csv`]'s output.
pub const TABLE_HEADER: &str = "theta_deg,delta_theta_deg,actual_deg,command_deg,correction_deg";

/// Writes a compensation table as CSV (header [`TABLE_HEADER`], 9 decimals).
pub fn write_table_csv<W: Write>(rows: &[TableRow], mut out: W) -> std::io::Result<()> {
    writeln!(out, "{TABLE_HEADER}")?;
    for r in rows {
        writeln!(
            out,
            "{},{:.9},{:.9},{:.9},{:.9}",
            r.theta_deg, r.delta_theta_deg, r.actual_deg, r.command_deg, r.correction_deg
        )?;
    }
    out.flush()
}

impl Compensation {
    /// The compensation table on `grid` (commanded/target angles, degrees).
    ///
    /// Every angle must lie in (0°, 90°) and, unless `allow_extrapolation`, in
    /// the range of measured angles the law was fitted on.
    pub fn table(
        &self,
        grid: &[f64],
        allow_extrapolation: bool,
    ) -> Result<Vec<TableRow>, CompensateError> {
        let [lo, hi] = self.fitted_range_deg;
        let slack = 1e-9 * (1.0 + hi.abs());
        grid.iter()
            .map(|&theta_deg| {
                if !(theta_deg > 0.0 && theta_deg < 90.0) {
                    return Err(CompensateError::InvalidGrid {
                        message: format!("angle {theta_deg}° is outside (0°, 90°)"),
                    });
                }
                if !allow_extrapolation && (theta_deg < lo - slack || theta_deg > hi + slack) {
                    return Err(CompensateError::InvalidGrid {
                        message: format!(
                            "angle {theta_deg}° is outside the measured range [{lo}°, {hi}°]; a polynomial law is not trustworthy there (allow it explicitly to extrapolate)"
                        ),
                    });
                }
                let command_deg = self
                    .command_deg(theta_deg)
                    .ok_or(CompensateError::NotInvertible { theta_deg })?;
                Ok(TableRow {
                    theta_deg,
                    delta_theta_deg: self.delta_theta_deg(theta_deg),
                    actual_deg: self.actual_deg(theta_deg),
                    command_deg,
                    correction_deg: command_deg - theta_deg,
                })
            })
            .collect()
    }
}

/// An angle grid `START:STEP:END` (degrees, `END` included when it falls on
/// the grid).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    /// First angle.
    pub start: f64,
    /// Spacing (positive).
    pub step: f64,
    /// Last angle (inclusive bound).
    pub end: f64,
}

impl Grid {
    /// A grid with unit steps over `[start, end]`.
    pub fn unit(start: f64, end: f64) -> Grid {
        Grid {
            start,
            step: 1.0,
            end,
        }
    }

    /// The grid's angles.
    pub fn points(&self) -> Result<Vec<f64>, CompensateError> {
        let bad = |message: String| CompensateError::InvalidGrid { message };
        if !(self.start.is_finite() && self.step.is_finite() && self.end.is_finite()) {
            return Err(bad("start, step and end must be finite".into()));
        }
        if self.step <= 0.0 {
            return Err(bad(format!("step {} must be positive", self.step)));
        }
        if self.end < self.start {
            return Err(bad(format!(
                "end {} is below start {}",
                self.end, self.start
            )));
        }
        let count = ((self.end - self.start) / self.step * (1.0 + 1e-12) + 1e-9).floor() + 1.0;
        if count.is_nan() || count > MAX_GRID_POINTS as f64 {
            return Err(bad(format!(
                "{count} angles is more than {MAX_GRID_POINTS}"
            )));
        }
        Ok((0..count as usize)
            .map(|i| self.start + i as f64 * self.step)
            .collect())
    }
}

impl FromStr for Grid {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let parts: Vec<&str> = s.split(':').map(str::trim).collect();
        let [start, step, end] = parts.as_slice() else {
            return Err(format!("`{s}` is not START:STEP:END (degrees)"));
        };
        let number = |t: &str| -> Result<f64, String> {
            t.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| format!("`{t}` in `{s}` is not a finite number"))
        };
        Ok(Grid {
            start: number(start)?,
            step: number(step)?,
            end: number(end)?,
        })
    }
}

impl fmt::Display for Grid {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}:{}", self.start, self.step, self.end)
    }
}
