//! A circular test's samples as identification records (spec
//! `circular.md`, "Into identification"; `docs/circular.md`).
//!
//! A ballbar reads the distance between its two balls. With the tool ball at
//! the nominal tool point `P(q)` (workpiece frame) at a sample's pose `q`
//! and the table ball at the circle's centre `c₀`, its deviation from the
//! nominal radius is, to first order,
//!
//! `d = uᵀ (S_p(q) e − s) + L + (|P(q) − c₀| − R)`,  `u = (P(q) − c₀)/|P(q) − c₀|`,
//!
//! with `e` the machine's errors, `s` the table ball's offset from `c₀` and
//! `L` the bar's length offset (its calibration; the mean scale and the
//! servo's radius loss also land there). So each sample is a `ux,uy,uz,d`
//! record (its value less the nominal `|P(q) − c₀| − R`) whose set-up is
//! its run ([`SetupKind::Circle`]: unknowns `s` along the plane's two axes
//! and `L`).
//!
//! The poses: either the circle's centre as a machine pose, the plane's two
//! axes being the machine's linear variables named after them (`x`, `y`,
//! `z`, any case), a sample at `θ` moving them by `R cos θ`, `R sin θ`; or
//! each sample's pose in the run file's columns named after the machine's
//! variables (rotary ones in degrees), any path of the machine's axes
//! (a rotary axis interpolating with a linear one), `c₀` then the centre of
//! the circle through the run's nominal tool points.

#[cfg(feature = "csv")]
use std::collections::HashMap;

#[cfg(feature = "csv")]
use super::{CircularTest, RunOptions, Sample};
#[cfg(feature = "csv")]
use crate::diagnostic::{CircularProblem, Diagnostics, MeasurementsProblem, Problem};
#[cfg(feature = "csv")]
use crate::measured::exact::ExactChain;
#[cfg(feature = "csv")]
use crate::measured::measurements::{
    parameter_columns, Measurement, Measurements, MeasurementsError, Observed, Setup, SetupKind,
    MAX_MEASUREMENT_BYTES,
};
#[cfg(feature = "csv")]
use crate::model::Origin;
use crate::model::{JointKind, Machine};

/// Per variable of `m`, whether a rotary joint moves it (its columns and
/// values are in degrees).
pub(crate) fn rotary_variables(m: &Machine) -> Vec<bool> {
    (0..m.variables.len())
        .map(|k| {
            m.bodies.iter().any(|b| {
                b.joint
                    .as_ref()
                    .is_some_and(|j| j.variable == k && j.kind == JointKind::Rotary)
            })
        })
        .collect()
}

/// How far off its run's circle (relative to the radius) a sample's
/// nominal tool point may lie: further, the poses and the radius describe
/// different circles (a wrong radius, radians for degrees).
pub const ON_CIRCLE: f64 = 1e-3;

/// How far (degrees) the plane of a run's nominal tool points may tilt from
/// the run's plane: its table ball's offsets are taken along that plane's
/// axes.
pub const MAX_TILT: f64 = 1.0;

/// Where a circular test's samples are on the machine.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CirclePose<'a> {
    /// The circle's centre as a pose of the machine (its variables in
    /// order, rotary ones in radians: [`centre_pose`]).
    Centre(&'a [f64]),
    /// Each sample's pose in the run file's columns, one per variable of
    /// the machine named as it (rotary ones in degrees).
    Columns,
}

/// Why a circle's centre pose was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CentreError {
    /// A name that is no variable of the machine.
    #[error("the circle's centre names `{name}`, which is not a variable of machine `{machine}` (its variables: {variables})")]
    Unknown {
        /// The name.
        name: String,
        /// The machine.
        machine: String,
        /// Its variables, comma-separated.
        variables: String,
    },
    /// A variable given twice.
    #[error("the circle's centre gives `{name}` twice")]
    Twice {
        /// The variable.
        name: String,
    },
    /// A value that is not a finite number.
    #[error("the circle's centre gives `{name}` = {value}: not a finite number")]
    NotFinite {
        /// The variable.
        name: String,
        /// The value.
        value: f64,
    },
}

/// The circle's centre as a pose of `machine`: the named variables (rotary
/// ones in degrees), every other at 0.
pub fn centre_pose(machine: &Machine, named: &[(String, f64)]) -> Result<Vec<f64>, CentreError> {
    let rotary = rotary_variables(machine);
    let mut q = vec![0.0; machine.variables.len()];
    let mut seen = vec![false; q.len()];
    for (name, value) in named {
        let k = machine
            .variable_index(name)
            .ok_or_else(|| CentreError::Unknown {
                name: name.clone(),
                machine: machine.name.clone(),
                variables: (machine.variables.iter())
                    .map(|v| v.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", "),
            })?;
        if !value.is_finite() {
            return Err(CentreError::NotFinite {
                name: name.clone(),
                value: *value,
            });
        }
        if std::mem::replace(&mut seen[k], true) {
            return Err(CentreError::Twice { name: name.clone() });
        }
        q[k] = if rotary[k] {
            value.to_radians()
        } else {
            *value
        };
    }
    Ok(q)
}

/// A located problem.
#[cfg(feature = "csv")]
type Located = (Origin, Problem);

#[cfg(feature = "csv")]
impl Measurements {
    /// Reads a circular-test file (spec `circular.md`; at most
    /// [`MAX_MEASUREMENT_BYTES`]) as records of `machine` (module docs);
    /// `overrides` are values of parameters the file has no column for.
    pub fn read_circular(
        path: &std::path::Path,
        machine: &Machine,
        overrides: &[(String, f64)],
        options: &RunOptions,
        pose: CirclePose<'_>,
    ) -> Result<Measurements, MeasurementsError> {
        let file = path.display().to_string();
        let bytes = crate::load::read_file(path, &file, MAX_MEASUREMENT_BYTES)
            .map_err(MeasurementsError)?;
        Measurements::circular_from_bytes(&bytes, &file, machine, overrides, options, pose)
    }

    /// [`Measurements::read_circular`] over bytes named `file`.
    pub fn circular_from_bytes(
        bytes: &[u8],
        file: &str,
        machine: &Machine,
        overrides: &[(String, f64)],
        options: &RunOptions,
        pose: CirclePose<'_>,
    ) -> Result<Measurements, MeasurementsError> {
        let text = crate::load::decode(bytes, file).map_err(MeasurementsError)?;
        Measurements::parse_circular(text, file, machine, overrides, options, pose)
    }

    /// [`Measurements::read_circular`] over CSV text named `file`: the run
    /// file read and checked as `chain circular` reads it, then each
    /// sample's pose, every refusal located.
    pub fn parse_circular(
        text: &str,
        file: &str,
        machine: &Machine,
        overrides: &[(String, f64)],
        options: &RunOptions,
        pose: CirclePose<'_>,
    ) -> Result<Measurements, MeasurementsError> {
        let test = CircularTest::parse(text, file, options).map_err(|e| MeasurementsError(e.0))?;
        let csv = crate::values::csv::CsvFile::parse_with(
            text,
            file,
            crate::diagnostic::CIRCULAR_FILE_HEADER,
        )
        .map_err(MeasurementsError)?;
        let fail = |problems: Vec<Located>| {
            MeasurementsError(Diagnostics::located(file, text, problems).expect("a problem"))
        };
        let header = csv.header_origin();
        let mut problems: Vec<Located> = Vec::new();
        let p_columns = parameter_columns(machine, overrides, &csv.header, &header, &mut problems);
        let rotary = rotary_variables(machine);
        let q_columns: Vec<(usize, bool)> = match pose {
            CirclePose::Columns => {
                let missing: Vec<String> = (machine.variables.iter())
                    .filter(|v| csv.column(&v.name).is_none())
                    .map(|v| v.name.clone())
                    .collect();
                if !missing.is_empty() {
                    let problem = MeasurementsProblem::MissingPose { variables: missing };
                    problems.push((header.clone(), problem.into()));
                }
                (machine.variables.iter().zip(&rotary))
                    .filter_map(|(v, &r)| csv.column(&v.name).map(|c| (c, r)))
                    .collect()
            }
            CirclePose::Centre(_) => Vec::new(),
        };
        if !problems.is_empty() {
            return Err(fail(problems));
        }
        // Per data row: where it is, its pose (from columns) and parameters.
        type Read = (Origin, Vec<f64>, Vec<f64>);
        let rows: Vec<Read> = csv
            .read_rows(|cells| {
                let number = |c: usize| {
                    let (t, o) = &cells[c];
                    crate::tabular::number(t, &o.key)
                        .map_err(|problem| Box::new((o.clone(), problem.into())))
                };
                let q = (q_columns.iter())
                    .map(|&(c, rot)| number(c).map(|v| if rot { v.to_radians() } else { v }))
                    .collect::<Result<Vec<_>, _>>()?;
                let p = (p_columns.iter())
                    .map(|c| match c {
                        Ok(c) => number(*c),
                        Err(v) => Ok(*v),
                    })
                    .collect::<Result<Vec<_>, _>>()?;
                let origin = cells.first().map(|c| c.1.clone()).unwrap_or_default();
                Ok((origin, q, p))
            })
            .map_err(fail)?;
        // The run file's rows by line: the same text read by the same CSV
        // reader as `CircularTest::parse` read it, one record a line, so
        // every sample's line is here.
        let at: HashMap<usize, usize> = (rows.iter().enumerate())
            .map(|(i, r)| (r.0.line, i))
            .collect();
        let row = |s: &Sample| &rows[at[&s.line]];
        let chain = ExactChain::new(machine);
        let mut records = Vec::new();
        let mut setups = Vec::new();
        for (g, run) in test.runs.iter().enumerate() {
            setups.push(Setup {
                name: run.id.clone(),
                kind: SetupKind::Circle,
                plane: Some(run.plane),
            });
            let samples: Vec<&Sample> = run.ccw.iter().chain(&run.cw).collect();
            let first = row(samples[0]).0.clone();
            let poses: Vec<(Vec<f64>, Vec<f64>)> = match pose {
                CirclePose::Columns => (samples.iter())
                    .map(|s| (row(s).1.clone(), row(s).2.clone()))
                    .collect(),
                CirclePose::Centre(centre) => {
                    let [a, b] = run.plane.axes();
                    let var = |axis: usize| {
                        let name = ["x", "y", "z"][axis];
                        (machine.variables.iter().enumerate())
                            .position(|(k, v)| v.name.eq_ignore_ascii_case(name) && !rotary[k])
                            .ok_or_else(|| {
                                let problem = CircularProblem::NoAxis {
                                    run: run.id.clone(),
                                    axis: name,
                                    machine: machine.name.clone(),
                                    variables: machine
                                        .variables
                                        .iter()
                                        .map(|v| v.name.clone())
                                        .collect(),
                                };
                                Box::new((first.clone(), Problem::from(problem)))
                            })
                    };
                    let (va, vb) = match (var(a), var(b)) {
                        (Ok(va), Ok(vb)) => (va, vb),
                        (Err(e), _) | (_, Err(e)) => return Err(fail(vec![*e])),
                    };
                    (samples.iter())
                        .map(|s| {
                            let mut q = centre.to_vec();
                            let (sn, cs) = s.angle.to_radians().sin_cos();
                            q[va] += run.radius * cs;
                            q[vb] += run.radius * sn;
                            (q, row(s).2.clone())
                        })
                        .collect()
                }
            };
            // Each sample's nominal tool point and frame, once.
            let nominals: Vec<_> = (poses.iter()).map(|(q, p)| chain.nominal(q, p)).collect();
            let points: Vec<[f64; 3]> = nominals.iter().map(|n| n.point).collect();
            let c0 = match pose {
                CirclePose::Centre(centre) => chain.nominal(centre, &poses[0].1).point,
                CirclePose::Columns => match circle_centre(&points) {
                    Some((c, normal)) => {
                        // The set-up's offsets are along the run's plane's
                        // axes: the circle must lie in that plane.
                        let [a, b] = run.plane.axes();
                        let k = 3 - a - b;
                        let tilt = normal[k].abs().clamp(0.0, 1.0).acos().to_degrees();
                        if tilt > MAX_TILT {
                            let problem = CircularProblem::PlaneTilted {
                                run: run.id.clone(),
                                plane: run.plane.name(),
                                tilt,
                            };
                            return Err(fail(vec![(first, problem.into())]));
                        }
                        c
                    }
                    None => {
                        let problem = CircularProblem::NoCircle {
                            run: run.id.clone(),
                        };
                        return Err(fail(vec![(first, problem.into())]));
                    }
                },
            };
            for ((s, (q, p)), nominal) in samples.iter().zip(poses).zip(&nominals) {
                let point = &nominal.point;
                let v: [f64; 3] = std::array::from_fn(|i| point[i] - c0[i]);
                let distance = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                let on = (distance - run.radius).abs() <= ON_CIRCLE * run.radius;
                if !on {
                    let problem = CircularProblem::OffCircle {
                        run: run.id.clone(),
                        distance,
                        radius: run.radius,
                    };
                    problems.push((row(s).0.clone(), problem.into()));
                    if problems.len() >= crate::values::csv::MAX_ROW_PROBLEMS {
                        return Err(fail(problems));
                    }
                    continue;
                }
                let u = nominal.in_frame(v.map(|x| x / distance));
                records.push(Measurement {
                    line: s.line,
                    q,
                    p,
                    observed: Observed::Direction { u },
                    values: vec![s.deviation - (distance - run.radius)],
                    std: None,
                    setup: Some(g),
                    temperatures: Vec::new(),
                });
            }
        }
        if !problems.is_empty() {
            return Err(fail(problems));
        }
        Ok(Measurements {
            file: file.to_string(),
            machine: machine.name.clone(),
            weighted: false,
            rows: records,
            setups,
        })
    }
}

#[cfg(feature = "csv")]
/// The centre of the circle through `points` and the normal of its plane:
/// their least-squares plane through their centroid, then in it the
/// algebraic (Kåsa) circle; `None` for points on one line.
fn circle_centre(points: &[[f64; 3]]) -> Option<([f64; 3], [f64; 3])> {
    use nalgebra::{Matrix3, Vector3};
    let n = points.len() as f64;
    let m: Vector3<f64> = points
        .iter()
        .map(|p| Vector3::from(*p))
        .sum::<Vector3<f64>>()
        / n;
    let mut scatter = Matrix3::zeros();
    for p in points {
        let d = Vector3::from(*p) - m;
        scatter += d * d.transpose();
    }
    let eigen = scatter.symmetric_eigen();
    let mut order = [0, 1, 2];
    order.sort_by(|&i, &j| eigen.eigenvalues[j].total_cmp(&eigen.eigenvalues[i]));
    let (l1, l2) = (eigen.eigenvalues[order[0]], eigen.eigenvalues[order[1]]);
    if !(l2 > 1e-12 * l1 && l1 > 0.0) {
        return None;
    }
    let e1: Vector3<f64> = eigen.eigenvectors.column(order[0]).into();
    let e2: Vector3<f64> = eigen.eigenvectors.column(order[1]).into();
    // x² + y² + D x + E y + F = 0 in the plane, least squares.
    let mut a = Matrix3::zeros();
    let mut b = Vector3::zeros();
    for p in points {
        let d = Vector3::from(*p) - m;
        let (x, y) = (d.dot(&e1), d.dot(&e2));
        let row = Vector3::new(x, y, 1.0);
        a += row * row.transpose();
        b -= row * (x * x + y * y);
    }
    let s = a.lu().solve(&b)?;
    let c = m - e1 * (s[0] / 2.0) - e2 * (s[1] / 2.0);
    let n = e1.cross(&e2);
    Some(([c[0], c[1], c[2]], [n[0], n[1], n[2]]))
}
