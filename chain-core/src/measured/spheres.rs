//! Sphere-probing records (five-axis spec, "Input: sphere probing
//! records"; `docs/five-axis.md`): a touch probe finds the centre of a
//! sphere fixed on the table at several rotary positions.
//!
//! A sphere file has one probing a row:
//!
//! - one column per axis variable of the machine: a rotary one in
//!   **degrees** (the controller's unit), a linear one in mm, named as the
//!   machine file names it (`x`, `y`, `z` for the usual machine): the axis
//!   positions at which the probe centre sits at the sphere centre;
//! - any of the machine's parameters (per row, as in a measurement file);
//! - optionally `sphere` (an identifier: several spheres or set-ups in one
//!   file; default one sphere) and `std` (each coordinate's standard
//!   deviation, mm, > 0).
//!
//! # The rows of a probing
//!
//! With `T_wt(q, 0)` the nominal tool pose in the workpiece frame, `t` the
//! tool point (the probe centre) and `s` the sphere centre in the
//! workpiece (table) frame, the probe centre sits at the sphere centre:
//! `T_wt(q, e) t = s`. To first order `T_wt(q, 0) t + S_p(q) e = s`, so a
//! probing is a tool-point record whose deviation is
//!
//! `S_p(q) e − s = −T_wt(q, 0) t`,
//!
//! three rows whose measured values are the negated nominal tool point and
//! whose set-up unknowns `s` enter with `−I` (the machine file's frame:
//! with `frame: tool` both sides are rotated by `R_wt(q, 0)ᵀ`). The sphere
//! position is an unknown of the fit beside the machine's errors
//! ([`super::Setup`]); the exact iteration uses the same equation with the
//! exact deviation.

#[cfg(feature = "csv")]
use std::collections::BTreeMap;

#[cfg(feature = "csv")]
use super::exact::ExactChain;
#[cfg(feature = "csv")]
use super::measurements::{Measurement, Measurements, MeasurementsError, Observed, Setup};
#[cfg(feature = "csv")]
use super::measurements::{SetupKind, MAX_MEASUREMENT_BYTES, STD_COLUMN};
#[cfg(feature = "csv")]
use crate::diagnostic::{closest, Diagnostics, MeasurementsProblem as P, Problem};
#[cfg(feature = "csv")]
use crate::model::{Machine, Origin};

/// The column of a probing's sphere identifier.
pub const SPHERE_COLUMN: &str = "sphere";

/// The identifier of the one sphere of a file without a `sphere` column.
pub const DEFAULT_SPHERE: &str = "1";

/// The fewest probings of one sphere: a single one only locates the
/// sphere (its three rows are taken by the sphere's three unknowns).
pub const MIN_PROBINGS: usize = 2;

#[cfg(feature = "csv")]
impl Measurements {
    /// Reads a sphere-probing CSV for `machine` (module docs; at most
    /// [`MAX_MEASUREMENT_BYTES`]); `overrides` are parameter values for
    /// parameters the CSV has no column for.
    pub fn read_spheres(
        path: &std::path::Path,
        machine: &Machine,
        overrides: &[(String, f64)],
    ) -> Result<Measurements, MeasurementsError> {
        let file = path.display().to_string();
        let bytes = crate::load::read_file(path, &file, MAX_MEASUREMENT_BYTES)
            .map_err(MeasurementsError)?;
        Measurements::spheres_from_bytes(&bytes, &file, machine, overrides)
    }

    /// [`Measurements::read_spheres`] over bytes named `file` the caller
    /// read.
    pub fn spheres_from_bytes(
        bytes: &[u8],
        file: &str,
        machine: &Machine,
        overrides: &[(String, f64)],
    ) -> Result<Measurements, MeasurementsError> {
        let text = crate::load::decode(bytes, file).map_err(MeasurementsError)?;
        Measurements::parse_spheres(text, file, machine, overrides)
    }

    /// [`Measurements::read_spheres`] over CSV text named `file`: every
    /// refusal located (line, column, header name).
    pub fn parse_spheres(
        text: &str,
        file: &str,
        machine: &Machine,
        overrides: &[(String, f64)],
    ) -> Result<Measurements, MeasurementsError> {
        let help = "the header names every axis variable (rotary ones in degrees), any per-row parameters, and optionally `sphere` and `std`";
        let csv =
            crate::values::csv::CsvFile::parse_with(text, file, help).map_err(MeasurementsError)?;
        let fail = |problems: Vec<(Origin, Problem)>| {
            MeasurementsError(
                Diagnostics::located(file, text, problems).expect("at least one problem"),
            )
        };
        let header_origin = csv.header_origin();
        let columns = SphereColumns::classify(machine, overrides, &csv.header, &header_origin)
            .map_err(fail)?;
        let chain = ExactChain::new(machine);
        let mut setups: Vec<Setup> = Vec::new();
        let mut first_line: BTreeMap<usize, Origin> = BTreeMap::new();
        let mut counts: Vec<usize> = Vec::new();
        let rows = csv
            .read_rows(|cells| {
                let (mut record, id) = columns.record(&chain, cells)?;
                let g = match setups.iter().position(|s| s.name == id) {
                    Some(g) => g,
                    None => {
                        setups.push(Setup::new(id, SetupKind::Sphere));
                        counts.push(0);
                        setups.len() - 1
                    }
                };
                counts[g] += 1;
                first_line.entry(g).or_insert_with(|| {
                    cells.first().map_or(header_origin.clone(), |c| c.1.clone())
                });
                record.setup = Some(g);
                Ok(record)
            })
            .map_err(fail)?;
        if rows.is_empty() {
            return Err(fail(vec![(header_origin, P::SphereNoRows.into())]));
        }
        let mut problems: Vec<(Origin, Problem)> = Vec::new();
        for (g, &count) in counts.iter().enumerate() {
            if count < MIN_PROBINGS {
                let problem = P::SphereTooFew {
                    sphere: setups[g].name.clone(),
                    probings: count,
                };
                problems.push((first_line[&g].clone(), problem.into()));
            }
        }
        if !problems.is_empty() {
            return Err(fail(problems));
        }
        Ok(Measurements {
            file: file.to_string(),
            machine: machine.name.clone(),
            weighted: columns.std.is_some(),
            rows,
            setups,
        })
    }
}

/// Where each quantity is in a sphere file's columns.
#[cfg(feature = "csv")]
struct SphereColumns {
    /// Per variable, its column and whether it is rotary (degrees).
    q: Vec<(usize, bool)>,
    /// Per parameter, its column or its fixed value.
    p: Vec<Result<usize, f64>>,
    sphere: Option<usize>,
    std: Option<usize>,
}

/// A located problem of a cell.
#[cfg(feature = "csv")]
type Located = Box<(Origin, Problem)>;

#[cfg(feature = "csv")]
impl SphereColumns {
    /// Classifies the header's columns.
    fn classify(
        m: &Machine,
        overrides: &[(String, f64)],
        header: &[(String, Origin)],
        header_origin: &Origin,
    ) -> Result<SphereColumns, Vec<(Origin, Problem)>> {
        let mut problems: Vec<(Origin, Problem)> = Vec::new();
        let find = |name: &str| header.iter().position(|(h, _)| h == name);
        for (name, origin) in header {
            let known = m.variable_index(name).is_some()
                || m.parameter_index(name).is_some()
                || name == SPHERE_COLUMN
                || name == STD_COLUMN;
            if !known {
                let names: Vec<&str> = (m.variables.iter().map(|v| v.name.as_str()))
                    .chain(m.parameters.iter().map(|p| p.name.as_str()))
                    .chain([SPHERE_COLUMN, STD_COLUMN])
                    .collect();
                let problem = P::SphereUnknownColumn {
                    column: name.clone(),
                    machine: m.name.clone(),
                    variables: m.variables.iter().map(|v| v.name.clone()).collect(),
                    suggestion: closest(name, names.iter().copied()).map(str::to_string),
                };
                problems.push((origin.clone(), problem.into()));
            }
        }
        let rotary = super::circular::records::rotary_variables(m);
        let missing: Vec<String> = (m.variables.iter())
            .filter(|v| find(&v.name).is_none())
            .map(|v| v.name.clone())
            .collect();
        let mut q = Vec::new();
        if missing.is_empty() {
            q = (m.variables.iter().enumerate())
                .filter_map(|(k, v)| find(&v.name).map(|c| (c, rotary[k])))
                .collect();
        } else {
            problems.push((
                header_origin.clone(),
                P::MissingPose { variables: missing }.into(),
            ));
        }
        let p = super::measurements::parameter_columns(
            m,
            overrides,
            header,
            header_origin,
            &mut problems,
        );
        if problems.is_empty() {
            Ok(SphereColumns {
                q,
                p,
                sphere: find(SPHERE_COLUMN),
                std: find(STD_COLUMN),
            })
        } else {
            Err(problems)
        }
    }

    /// One data row as a tool-point record (module docs) and its sphere's
    /// identifier.
    fn record(
        &self,
        chain: &ExactChain<'_>,
        cells: &[(String, Origin)],
    ) -> Result<(Measurement, String), Located> {
        let number = |c: usize| -> Result<f64, Located> {
            let (text, origin) = &cells[c];
            crate::tabular::number(text, &origin.key)
                .map_err(|problem| Box::new((origin.clone(), problem.into())))
        };
        let line = cells.first().map_or(0, |(_, o)| o.line);
        let q = (self.q.iter())
            .map(|&(c, rotary)| number(c).map(|v| if rotary { v.to_radians() } else { v }))
            .collect::<Result<Vec<_>, _>>()?;
        let p = (self.p.iter())
            .map(|c| match c {
                Ok(c) => number(*c),
                Err(v) => Ok(*v),
            })
            .collect::<Result<Vec<_>, _>>()?;
        let std = match self.std {
            None => None,
            Some(c) => {
                let s = number(c)?;
                if s <= 0.0 {
                    let problem = P::StdNotPositive { value: s };
                    return Err(Box::new((cells[c].1.clone(), problem.into())));
                }
                Some(s)
            }
        };
        let id = match self.sphere {
            Some(c) => {
                let (text, origin) = &cells[c];
                let id = text.trim();
                if id.is_empty() {
                    return Err(Box::new((origin.clone(), P::SphereEmptyId.into())));
                }
                id.to_string()
            }
            None => DEFAULT_SPHERE.to_string(),
        };
        let nominal = chain.nominal(&q, &p);
        let values = nominal.in_frame(nominal.point.map(|v| -v)).to_vec();
        if values.iter().any(|v| !v.is_finite()) {
            let origin = cells.first().map(|c| c.1.clone()).unwrap_or_default();
            return Err(Box::new((origin, P::SphereNotFinite.into())));
        }
        let record = Measurement {
            line,
            q,
            p,
            observed: Observed::Point,
            values,
            std,
            setup: None,
            temperatures: Vec::new(),
        };
        Ok((record, id))
    }
}
