//! `chain inverse` as a request and a document: the inverse kinematics of
//! tool poses (docs/inverse.md). The CLI reads the poses from a CSV, Python
//! from an array; both build [`PoseRow`]s by the same checks and get the
//! same [`InverseDocument`].

use chain_core::inverse::{Inverse, InverseError, Solution, Status};
use chain_core::named::NameMap;
use chain_core::Machine;
use reliability::ReliabilityError;
use serde::{Serialize, Serializer};

use super::resolve::{self, ResolveError};
use super::worded::{diagnostic, Worded};

/// The tool's orientation in a pose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Orientation {
    /// The tool axis `i, j, k` (non-zero; not normalised here).
    Axis([f64; 3]),
    /// The full rotation `r11 … r33` (row-major, orthonormal, det +1).
    Rotation([[f64; 3]; 3]),
}

/// Why a pose's orientation is refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PoseError {
    /// A tool axis of length 0.
    #[error("the tool axis (i, j, k) is zero")]
    ZeroAxis,
    /// A pose with neither 6 nor 12 values.
    #[error(
        "a pose has 6 values (px, py, pz, i, j, k) or 12 (px, py, pz, r11 … r33), found {found}"
    )]
    Width {
        /// The number of values given.
        found: usize,
    },
    /// A matrix that is not a rotation (to 1e-6, det +1).
    #[error("r11..r33 is not a rotation (|RᵀR − I| = {worst:.1e}, det = {det:.6})")]
    NotRotation {
        /// The largest entry of `|RᵀR − I|`.
        worst: f64,
        /// The determinant.
        det: f64,
    },
}

impl Orientation {
    /// A tool axis, refused when zero (below 1e-12).
    pub fn axis(axis: [f64; 3]) -> Result<Orientation, PoseError> {
        if (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt() < 1e-12 {
            return Err(PoseError::ZeroAxis);
        }
        Ok(Orientation::Axis(axis))
    }

    /// A rotation (row-major), refused unless orthonormal to 1e-6 with det
    /// +1, then replaced by the nearest rotation (the polar factor `U Vᵀ`:
    /// rows written with a few digits are orthonormal only to their
    /// rounding).
    pub fn rotation(r: [[f64; 3]; 3]) -> Result<Orientation, PoseError> {
        let mut worst = 0.0f64;
        for i in 0..3 {
            for j in 0..3 {
                let dot: f64 = (0..3).map(|k| r[k][i] * r[k][j]).sum();
                worst = worst.max((dot - if i == j { 1.0 } else { 0.0 }).abs());
            }
        }
        let det = r[0][0] * (r[1][1] * r[2][2] - r[1][2] * r[2][1])
            - r[0][1] * (r[1][0] * r[2][2] - r[1][2] * r[2][0])
            + r[0][2] * (r[1][0] * r[2][1] - r[1][1] * r[2][0]);
        // NaN never passes.
        if !(worst <= 1e-6 && det > 0.0) {
            return Err(PoseError::NotRotation { worst, det });
        }
        let m = nalgebra::Matrix3::from_fn(|i, j| r[i][j]);
        let svd = m.svd(true, true);
        let (Some(u), Some(v_t)) = (svd.u, svd.v_t) else {
            return Err(PoseError::NotRotation { worst, det });
        };
        let p = u * v_t;
        Ok(Orientation::Rotation(std::array::from_fn(|i| {
            std::array::from_fn(|j| p[(i, j)])
        })))
    }
}

/// One tool pose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PoseRow {
    /// The instant of an optional first column `t`.
    pub t: Option<f64>,
    /// The tool point `px, py, pz`.
    pub point: [f64; 3],
    /// The tool axis or the full rotation.
    pub orientation: Orientation,
}

/// The columns of a pose with a tool axis (docs/inverse.md).
pub const AXIS_COLUMNS: [&str; 6] = ["px", "py", "pz", "i", "j", "k"];
/// The columns of a pose with the tool frame's rotation, row-major.
pub const ROTATION_COLUMNS: [&str; 12] = [
    "px", "py", "pz", "r11", "r12", "r13", "r21", "r22", "r23", "r31", "r32", "r33",
];

impl PoseRow {
    /// A pose from its values: 6 (`px, py, pz, i, j, k`) or 12 (`px, py,
    /// pz, r11 … r33`, [`PoseError::Width`] otherwise); the orientation is
    /// checked by [`Orientation::axis`] or [`Orientation::rotation`].
    pub fn from_values(t: Option<f64>, values: &[f64]) -> Result<PoseRow, PoseError> {
        let orientation = match values.len() {
            6 => Orientation::axis([values[3], values[4], values[5]])?,
            12 => Orientation::rotation(std::array::from_fn(|i| {
                std::array::from_fn(|j| values[3 + 3 * i + j])
            }))?,
            found => return Err(PoseError::Width { found }),
        };
        Ok(PoseRow {
            t,
            point: [values[0], values[1], values[2]],
            orientation,
        })
    }
}

/// The poses of `flat`, rows of `width` values each (6 or 12; the width
/// is refused before any row otherwise); a row's refusal comes with its
/// 0-based index.
pub fn pose_rows(flat: &[f64], width: usize) -> Result<Vec<PoseRow>, (Option<usize>, PoseError)> {
    if width != 6 && width != 12 {
        return Err((None, PoseError::Width { found: width }));
    }
    (flat.chunks_exact(width).enumerate())
        .map(|(k, v)| PoseRow::from_values(None, v).map_err(|e| (Some(k), e)))
        .collect()
}

/// The request of `chain inverse`.
#[derive(Debug, Clone, Copy)]
pub struct InverseRequest<'a> {
    /// `--param NAME=VALUE`.
    pub params: &'a [(String, f64)],
    /// `--fix NAME=VALUE`: variables the pose does not determine.
    pub fix: &'a [(String, f64)],
    /// The poses, in order.
    pub poses: &'a [PoseRow],
}

/// Why `chain inverse` cannot run.
#[derive(Debug, thiserror::Error)]
pub enum InverseOpsError {
    /// An option does not match the machine.
    #[error(transparent)]
    Resolve(#[from] ResolveError),
    /// The parameters (located in the machine file).
    #[error(transparent)]
    Reliability(#[from] ReliabilityError),
    /// The machine has no inverse kinematics of this kind.
    #[error(transparent)]
    Machine(#[from] NoInverse),
}

/// The machine has no inverse kinematics of the kind asked (an
/// [`InverseError`] with the machine named).
#[derive(Debug, thiserror::Error)]
#[error("machine `{machine}`: {error}")]
pub struct NoInverse {
    /// The machine's name.
    pub machine: String,
    /// What went wrong.
    pub error: InverseError,
}

/// Worded by the [`InverseError`] (its code), with the help naming
/// `--fix` where holding variables is the remedy.
impl Worded for NoInverse {
    fn own_help(&self) -> Option<String> {
        match self.error {
            InverseError::Shape { .. } => {
                Some("hold the extra variables with --fix NAME=VALUE (e.g. mu=0)".into())
            }
            InverseError::NoFreeVariable => Some(
                "hold fewer variables (--fix), or check that the axes move the tool relative to the workpiece".into(),
            ),
            _ => None,
        }
    }

    #[cfg(feature = "cli")]
    fn inner(&self) -> Option<&dyn miette::Diagnostic> {
        Some(&self.error)
    }
}

diagnostic!(NoInverse);

/// The solver of `machine` for `params` and the `fixed` variables.
pub fn solver(
    machine: &Machine,
    params: &[f64],
    fixed: &[(usize, f64)],
) -> Result<Inverse, NoInverse> {
    Inverse::for_machine(machine, params, fixed).map_err(|error| NoInverse {
        machine: machine.name.clone(),
        error,
    })
}

/// The document of `chain inverse`: every pose row's status and solutions
/// (JSON: docs/inverse.md).
#[derive(Debug, Clone)]
pub struct InverseDocument {
    /// The machine.
    pub machine: String,
    /// The solver's method (`closed_form`, ...).
    pub method: &'static str,
    /// The axis variables, in a solution's order.
    pub variables: Vec<String>,
    /// Per pose row.
    pub rows: Vec<Solution>,
}

/// Runs `chain inverse`.
pub fn run(
    machine: &Machine,
    request: &InverseRequest<'_>,
) -> Result<InverseDocument, InverseOpsError> {
    let m = machine;
    resolve::check_parameters(m, request.params)?;
    let params = reliability::machine::parameters(m, request.params)?;
    let fixed = resolve::fixed(m, request.fix)?;
    let solver = solver(m, &params, &fixed)?;
    Ok(InverseDocument {
        machine: m.name.clone(),
        method: solver.method(),
        variables: m.variables.iter().map(|v| v.name.clone()).collect(),
        rows: solve_rows(&solver, request.poses, m.variables.len(), &fixed),
    })
}

/// Solves the pose rows in order, each row's solutions sorted by their
/// distance to the previous row's first solution (the first row: to the
/// fixed values, 0 elsewhere), so a smooth path stays on one branch.
pub fn solve_rows(
    solver: &Inverse,
    rows: &[PoseRow],
    variables: usize,
    fixed: &[(usize, f64)],
) -> Vec<Solution> {
    let mut prev = vec![0.0; variables];
    for &(i, v) in fixed {
        if let Some(p) = prev.get_mut(i) {
            *p = v;
        }
    }
    rows.iter()
        .map(|row| {
            let s = match row.orientation {
                Orientation::Axis(axis) => solver.solve(row.point, axis, &prev),
                Orientation::Rotation(r) => solver.solve_pose(row.point, &r, &prev),
            };
            if let Some(first) = s.solutions.first() {
                prev.clone_from(first);
            }
            s
        })
        .collect()
}

/// The JSON document (field order = key order).
#[derive(Serialize)]
struct InverseJson<'a> {
    machine: &'a str,
    method: &'static str,
    variables: &'a [String],
    rows: Vec<RowJson<'a>>,
}

/// One pose row: its 1-based number, status and solutions `{variable: value}`;
/// `stopped` (only when true) where the search gave up at its budget.
#[derive(Serialize)]
struct RowJson<'a> {
    row: usize,
    status: Status,
    solutions: Vec<NameMap<&'a str, f64>>,
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    stopped: bool,
}

/// The warning on the rows whose damped-Newton search gave up at its
/// budget (`rows`: every row's solution, in order), if any.
pub fn stopped_note(rows: &[Solution]) -> Option<String> {
    let stopped: Vec<String> = (rows.iter().enumerate())
        .filter(|(_, s)| s.stopped)
        .map(|(k, _)| (k + 1).to_string())
        .collect();
    if stopped.is_empty() {
        return None;
    }
    let shown = stopped.len().min(10);
    let more = if stopped.len() > shown {
        format!(" and {} more", stopped.len() - shown)
    } else {
        String::new()
    };
    Some(format!(
        "warning: row{} {}{more}: the damped-Newton search gave up after {} iterations before trying every start (`stopped` in the JSON): an `unreachable` there means no solution was found, not that none exists",
        if stopped.len() == 1 { "" } else { "s" },
        stopped[..shown].join(", "),
        chain_core::kinematics::inverse::STEPS_PER_POSE
    ))
}

impl InverseDocument {
    /// The warnings on the run: the rows whose search gave up.
    pub fn notes(&self) -> Vec<String> {
        stopped_note(&self.rows).into_iter().collect()
    }
}

impl Serialize for InverseDocument {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        InverseJson {
            machine: &self.machine,
            method: self.method,
            variables: &self.variables,
            rows: (self.rows.iter().enumerate())
                .map(|(k, s)| RowJson {
                    row: k + 1,
                    status: s.status,
                    solutions: (s.solutions.iter())
                        .map(|q| {
                            NameMap::zip(
                                self.variables.iter().map(String::as_str),
                                q.iter().copied(),
                            )
                        })
                        .collect(),
                    stopped: s.stopped,
                })
                .collect(),
        }
        .serialize(serializer)
    }
}
