//! Thermal compensation for controllers (`docs/export-controllers.md`,
//! "Thermal compensation"): a machine's thermal terms (`docs/thermal.md`)
//! as the per-axis law a controller's temperature compensation holds.
//!
//! # The law
//!
//! A machine with sensors errs at a thermal state by
//! `E(q, T) = Σ_s ΔT_s · E_s(q)`, `E_s(q) = Σ_{j of s} c_j(q) · v_j` (the
//! thermal coefficients `v_j` per kelvin of sensor `s`, their geometric
//! coefficients `c_j(q)`). A linear axis `a` that moves the tool point along
//! frame axis `k_a` with sign `σ_a` cancels the error along `k_a` when the
//! controller adds `Δq_a = −E_{k_a}/σ_a` to its command. The controllers'
//! temperature compensation holds, per axis, a straight line in the axis's
//! own position whose offset and slope the PLC sets from the temperatures
//! (Siemens K3: `ΔK = K0 + tanβ·(P − P0)`; Beckhoff P-AXIS-00272..274 the
//! same): so per axis and sensor the law is
//!
//!   Δq_a(q, T) = Σ_s ΔT_s · (k0_{a,s} + m_{a,s} · (q_a − P0_a)),
//!
//! `k0` and `m` the least-squares line of `−E_{s,k_a}(q)/σ_a` over the
//! grid's points (every axis moving), `P0_a` the first grid value of the
//! axis. What the line cannot hold (an error along `k_a` that depends on
//! another axis's position or bends along its own, an error along a
//! direction no linear axis moves) remains: [`ThermalLaw::remainder`] per
//! sensor per kelvin over the grid, and at a stated thermal state.
//!
//! # Formats
//!
//! - [`ThermalFormat::Siemens`]: `TEMP_COMP.SPF`, the setting data of
//!   SINUMERIK's temperature compensation (Function Manual Extended
//!   Functions, K3 §4.2: MD32750 `$MA_TEMP_COMP_TYPE`, SD43900
//!   `$SA_TEMP_COMP_ABS_VALUE` = K0 in mm, SD43910 `$SA_TEMP_COMP_SLOPE` =
//!   tanβ as a ratio, SD43920 `$SA_TEMP_COMP_REF_POSITION` = P0 in mm) as a
//!   subprogram the PLC (or an ASUP) calls after each temperature reading,
//!   the sensors' temperatures in R parameters.
//! - [`ThermalFormat::Linuxcnc`]: a HAL component (`thermal_comp.comp`, for
//!   `halcompile`), its HAL file and INI lines: LinuxCNC's external axis
//!   offsets (`axis.L.eoffset-counts`, `-scale`, `-enable`,
//!   `[AXIS_L]OFFSET_AV_RATIO`), the offset computed from temperature pins
//!   and the axis position, held at zero until the machine is on and
//!   homed.

//! - [`ThermalFormat::Beckhoff`]: TwinCAT CNC's axis temperature
//!   compensation (P-AXIS-00271..00274, `lr_param.temp_comp*`:
//!   `Δs = offset_0 + coefficient·(s − s0)`, offset and s0 in 0.1 µm, the
//!   coefficient in µm/m): the axis-list lines (`temp_comp_axes.lis`) and a
//!   PLC function block (`FB_TempComp.st`, IEC 61131-3 Structured Text)
//!   that computes each axis's offset and coefficient from the sensors.
//! - [`ThermalFormat::Heidenhain`]: the `TEMPCOMP` column of the iTNC 530
//!   kinematics description (Technical Manual §6.5.3): one `Trans` row per
//!   frame axis, `COORD 0`, its TEMPCOMP a formula of PLC words holding the
//!   sensors' °C, at most 31 characters. It has no axis-position term: per
//!   axis the least-squares constant, the sensors and digits that fit.
//! - [`ThermalFormat::Klipper`]: `[z_thermal_adjust]` (Klipper
//!   Config_Reference): Z only, one sensor, `z − temp_coeff·(T − T_ref)`,
//!   `T_ref` the temperature at Z homing: the constant of the sensor that
//!   leaves the least.
//!
//! Every format's law is stated as the axes' corrections it holds
//! ([`ThermalLaw::axes`], the values as written where a format rounds
//! them) and what they leave ([`ThermalLaw::remainder`]), computed from
//! that law.

use serde::Serialize;

use crate::compensation::ExportedFile;
use crate::model::{JointKind, Machine};
use crate::model_trait::{ErrorModel, ErrorValues, OutOfRange};
use crate::values::Values;

/// The thermal compensation formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ThermalFormat {
    /// SINUMERIK 840D sl temperature compensation (K3).
    Siemens,
    /// LinuxCNC external axis offsets from a HAL component.
    Linuxcnc,
    /// TwinCAT CNC axis temperature compensation (P-AXIS-00271..00274).
    Beckhoff,
    /// HEIDENHAIN iTNC 530 kinematics description `TEMPCOMP` formulas.
    Heidenhain,
    /// Klipper `[z_thermal_adjust]`.
    Klipper,
}

/// The longest TEMPCOMP formula (iTNC 530 HSCI Technical Manual §6.5.3:
/// 31 characters).
pub const TEMPCOMP_CHARS: usize = 31;

/// The most variables in one TEMPCOMP formula (TNC 426/430 Technical
/// Manual p. 6-75: 16 per formula).
pub const TEMPCOMP_VARIABLES: usize = 16;

/// The PLC word of the first sensor in a TEMPCOMP formula (the Technical
/// Manual's example `W486`, a Pt100 in °C); the next sensors take the
/// next words (`W488`, …).
pub const TEMPCOMP_FIRST_WORD: usize = 486;

/// Klipper's range of `temp_coeff` (mm/K; `z_thermal_adjust.py`,
/// `getfloat('temp_coeff', minval=-1, maxval=1)`).
pub const KLIPPER_COEFFICIENT: f64 = 1.0;

impl ThermalFormat {
    /// Every format, in the order of `--controller`'s values.
    pub const ALL: [ThermalFormat; 5] = [
        ThermalFormat::Siemens,
        ThermalFormat::Linuxcnc,
        ThermalFormat::Beckhoff,
        ThermalFormat::Heidenhain,
        ThermalFormat::Klipper,
    ];

    /// `siemens`, `linuxcnc`, `beckhoff`, `heidenhain` or `klipper`.
    pub fn name(self) -> &'static str {
        match self {
            ThermalFormat::Siemens => "siemens",
            ThermalFormat::Linuxcnc => "linuxcnc",
            ThermalFormat::Beckhoff => "beckhoff",
            ThermalFormat::Heidenhain => "heidenhain",
            ThermalFormat::Klipper => "klipper",
        }
    }

    /// Whether the format's law has a slope along the axis.
    fn slope(self) -> bool {
        matches!(
            self,
            ThermalFormat::Siemens | ThermalFormat::Linuxcnc | ThermalFormat::Beckhoff
        )
    }

    /// What the format holds, in words.
    pub fn holds(self) -> &'static str {
        match self {
            ThermalFormat::Siemens => "per linear axis a straight line in its own position, K0 + tanβ·(P − P0), K0 and tanβ set by the PLC from any number of sensors (K3 §4.2)",
            ThermalFormat::Linuxcnc => "per linear axis a straight line in its own position from any number of sensors, computed by the HAL component every servo period and added as an external offset (counts of 1e-5 mm)",
            ThermalFormat::Beckhoff => "per linear axis a straight line in its own position, offset_0 + coefficient·(s − s0), set by the PLC from any number of sensors (P-AXIS-00272..00274; offset in 0.1 µm)",
            ThermalFormat::Heidenhain => "per frame axis an offset, a TEMPCOMP formula of the sensors' PLC words of at most 31 characters: no dependence on the axis position",
            ThermalFormat::Klipper => "Z only, one sensor, an offset per kelvin from the temperature at Z homing: no dependence on the position",
        }
    }
}

/// One sensor's share of an axis's law.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SensorLine {
    /// The sensor.
    pub sensor: String,
    /// Its reference (°C).
    pub reference: f64,
    /// `k0`: the axis correction at `P0` per kelvin (mm/K).
    pub offset: f64,
    /// `m`: the correction's slope along the axis per kelvin (mm/mm/K);
    /// 0 for a format without one.
    pub slope: f64,
}

/// One linear axis's law.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AxisLaw {
    /// The axis variable.
    pub variable: String,
    /// `X`, `Y` or `Z`: the frame axis it moves the tool point along.
    pub axis: char,
    /// `+1` or `−1`: the direction it moves the tool point along `axis`.
    pub sign: f64,
    /// `P0` (mm): the first grid value of the axis.
    pub p0: f64,
    /// Per sensor the format holds for this axis, its line.
    pub lines: Vec<SensorLine>,
    /// The formula the format writes for the axis, where it writes one
    /// (HEIDENHAIN's TEMPCOMP: the table's displacement along `axis`, mm).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub formula: Option<String>,
}

/// What a law leaves per sensor: the largest tool-point error per kelvin
/// over the grid after the law's correction (mm/K), and where.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SensorRemainder {
    /// The sensor.
    pub sensor: String,
    /// The largest `|E_s(q)|` (mm/K) over the grid, before.
    pub before: f64,
    /// The largest `|E_s(q) + J·Δq_s(q)|` after the law's correction.
    pub after: f64,
    /// Where `after` is largest (machine-ordered axis values).
    pub at: Vec<f64>,
}

/// The law of a format, and what it leaves.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ThermalLaw {
    /// The machine.
    pub machine: String,
    /// The format.
    pub format: ThermalFormat,
    /// What the format holds ([`ThermalFormat::holds`]).
    pub holds: String,
    /// Per linear axis the format corrects.
    pub axes: Vec<AxisLaw>,
    /// Per sensor with thermal terms.
    pub remainder: Vec<SensorRemainder>,
    /// What the format could not hold of this machine, its resolution and
    /// its conventions, in words.
    pub notes: Vec<String>,
}

/// Why a machine's thermal terms cannot be written as a controller's law.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ThermalExportError {
    /// The machine has no thermal coefficient.
    #[error("machine `{machine}` has no thermal terms (`per:` in a slot, docs/thermal.md): there is no temperature to compensate")]
    NoThermalTerms {
        /// The machine.
        machine: String,
    },
    /// A linear axis that does not move the tool point along one frame
    /// axis.
    #[error("axis `{variable}` moves the tool point along ({:.6}, {:.6}, {:.6}) per mm at {at:?}: a per-axis temperature compensation needs each linear axis along one of X, Y, Z", direction[0], direction[1], direction[2])]
    NotAligned {
        /// The axis.
        variable: String,
        /// Its direction.
        direction: [f64; 3],
        /// Where.
        at: Vec<f64>,
    },
    /// Fewer than two grid values along an axis: no slope to fit.
    #[error(
        "axis `{variable}` has {count} grid value(s): the law's slope along it needs at least 2"
    )]
    Grid {
        /// The axis.
        variable: String,
        /// Its grid values.
        count: usize,
    },
    /// Klipper corrects Z only, and the machine has no linear axis along
    /// Z.
    #[error("machine `{machine}` has no linear axis along Z: Klipper's [z_thermal_adjust] corrects Z only")]
    NoZAxis {
        /// The machine.
        machine: String,
    },
    /// Klipper's `temp_coeff` outside the range Klipper accepts.
    #[error("the Z correction of sensor `{sensor}` is {value} mm/K: Klipper's temp_coeff must lie in [-1, 1] mm/K")]
    KlipperCoefficient {
        /// The sensor.
        sensor: String,
        /// The coefficient.
        value: f64,
    },
    /// A values table read outside its range.
    #[error("{0}")]
    OutOfTable(String),
}

impl From<OutOfRange> for ThermalExportError {
    fn from(e: OutOfRange) -> Self {
        ThermalExportError::OutOfTable(e.to_string())
    }
}

/// Per sensor, `E_s(q)` (position, machine frame, mm/K) at `q`.
fn per_sensor<M: ErrorModel>(
    machine: &Machine,
    model: &M,
    params: &[f64],
    values: &Values,
    q: &[f64],
    scratch: &mut [f64],
    e: &mut [f64],
) -> Result<Vec<[f64; 3]>, OutOfRange> {
    let n = machine.errors.len();
    model.sensitivity(q, params, scratch);
    values.values_at(q, e)?;
    let mut out = vec![[0.0; 3]; machine.sensors.len()];
    for (j, err) in machine.errors.iter().enumerate() {
        if let Some(s) = err.sensor {
            for (c, o) in out[s].iter_mut().enumerate() {
                *o += scratch[c * n + j] * e[j];
            }
        }
    }
    Ok(out)
}

/// The linear axes: (machine variable, frame axis, sign), checked aligned
/// at every grid point.
fn linear_axes<M: ErrorModel>(
    machine: &Machine,
    model: &M,
    params: &[f64],
    points: &[Vec<f64>],
) -> Result<Vec<(usize, usize, f64)>, ThermalExportError> {
    let mut out: Vec<(usize, usize, f64)> = Vec::new();
    for (v, var) in machine.variables.iter().enumerate() {
        if var.kind != JointKind::Prismatic {
            continue;
        }
        let mut axis: Option<(usize, f64)> = None;
        for q in points {
            let mut up = q.clone();
            up[v] += 1.0;
            let (a, b) = (model.nominal(q, params), model.nominal(&up, params));
            let d: [f64; 3] = std::array::from_fn(|i| b.position[i] - a.position[i]);
            let k = (0..3)
                .max_by(|&x, &y| d[x].abs().total_cmp(&d[y].abs()))
                .unwrap_or(0);
            let aligned = (d[k].abs() - 1.0).abs() < 1e-9
                && (0..3).all(|i| i == k || d[i].abs() < 1e-9)
                && axis.is_none_or(|(k0, s0)| k0 == k && s0 == d[k].signum());
            if !aligned {
                return Err(ThermalExportError::NotAligned {
                    variable: var.name.clone(),
                    direction: d,
                    at: q.clone(),
                });
            }
            axis = Some((k, d[k].signum()));
        }
        if let Some((k, s)) = axis {
            out.push((v, k, s));
        }
    }
    Ok(out)
}

/// What a set of axis laws leaves per sensor of `active` over the grid.
struct Grid<'a> {
    machine: &'a Machine,
    points: &'a [Vec<f64>],
    /// Per point, per sensor, `E_s(q)`.
    sensed: Vec<Vec<[f64; 3]>>,
    active: Vec<usize>,
}

impl Grid<'_> {
    /// Per active sensor, what `laws` (each with its machine variable)
    /// leave.
    fn remainders(&self, laws: &[(usize, AxisLaw)]) -> Vec<SensorRemainder> {
        let norm = |p: [f64; 3]| (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        let k_of = |c: char| (c as u8 - b'X') as usize;
        (self.active.iter())
            .map(|&s| {
                let name = &self.machine.sensors[s].name;
                let mut r = SensorRemainder {
                    sensor: name.clone(),
                    before: 0.0,
                    after: 0.0,
                    at: Vec::new(),
                };
                for (q, es) in self.points.iter().zip(&self.sensed) {
                    let mut left = es[s];
                    for (v, law) in laws {
                        if let Some(l) = law.lines.iter().find(|l| &l.sensor == name) {
                            left[k_of(law.axis)] +=
                                law.sign * (l.offset + l.slope * (q[*v] - law.p0));
                        }
                    }
                    r.before = r.before.max(norm(es[s]));
                    if norm(left) >= r.after {
                        r.after = norm(left);
                        r.at = q.clone();
                    }
                }
                r
            })
            .collect()
    }
}

/// The `format` law of `machine`'s thermal terms over `points`
/// (machine-ordered axis values; a full factorial grid, every linear axis
/// with at least two values), `model` compiled from it, `values` its
/// values (the thermal coefficients per kelvin).
pub fn fit<M: ErrorModel>(
    machine: &Machine,
    model: &M,
    params: &[f64],
    values: &Values,
    points: &[Vec<f64>],
    format: ThermalFormat,
) -> Result<ThermalLaw, ThermalExportError> {
    if !machine.is_thermal() {
        return Err(ThermalExportError::NoThermalTerms {
            machine: machine.name.clone(),
        });
    }
    let axes = linear_axes(machine, model, params, points)?;
    let n = machine.errors.len();
    let (mut scratch, mut e) = (vec![0.0; 6 * n], vec![0.0; n]);
    let grid = Grid {
        machine,
        points,
        sensed: points
            .iter()
            .map(|q| per_sensor(machine, model, params, values, q, &mut scratch, &mut e))
            .collect::<Result<_, _>>()?,
        active: (0..machine.sensors.len())
            .filter(|&s| machine.errors.iter().any(|e| e.sensor == Some(s)))
            .collect(),
    };
    let mut laws: Vec<(usize, AxisLaw)> = Vec::new();
    for &(v, k, sign) in &axes {
        let xs: Vec<f64> = points.iter().map(|q| q[v]).collect();
        let p0 = xs.iter().copied().fold(f64::INFINITY, f64::min);
        let distinct = {
            let mut d = xs.clone();
            d.sort_by(f64::total_cmp);
            d.dedup();
            d.len()
        };
        if format.slope() && distinct < 2 {
            return Err(ThermalExportError::Grid {
                variable: machine.variables[v].name.clone(),
                count: distinct,
            });
        }
        let lines = (grid.active.iter())
            .map(|&s| {
                let ys: Vec<f64> = grid.sensed.iter().map(|es| -es[s][k] / sign).collect();
                let (offset, slope) = if format.slope() {
                    line(&xs, &ys, p0)
                } else {
                    (ys.iter().sum::<f64>() / ys.len() as f64, 0.0)
                };
                // The least squares' rounding of an exact zero (below
                // 1e-12 µm/K and 1e-12 µm/m/K) is written as zero.
                let (offset, slope) = (
                    if offset.abs() < 1e-15 { 0.0 } else { offset },
                    if slope.abs() < 1e-18 { 0.0 } else { slope },
                );
                let sensor = &machine.sensors[s];
                SensorLine {
                    sensor: sensor.name.clone(),
                    reference: sensor.reference,
                    offset,
                    slope,
                }
            })
            .collect();
        laws.push((
            v,
            AxisLaw {
                variable: machine.variables[v].name.clone(),
                axis: ['X', 'Y', 'Z'][k],
                sign,
                p0,
                lines,
                formula: None,
            },
        ));
    }
    let mut notes = Vec::new();
    match format {
        ThermalFormat::Siemens | ThermalFormat::Linuxcnc | ThermalFormat::Beckhoff => {
            notes.push("what depends on another axis's position, bends along the axis or lies along a direction no linear axis moves remains".to_string());
        }
        ThermalFormat::Heidenhain => heidenhain_formulas(&grid, &mut laws, &mut notes),
        ThermalFormat::Klipper => klipper_sensor(machine, &grid, &mut laws, &mut notes)?,
    }
    notes.extend(resolution(format));
    let remainder = grid.remainders(&laws);
    Ok(ThermalLaw {
        machine: machine.name.clone(),
        format,
        holds: format.holds().to_string(),
        axes: laws.into_iter().map(|(_, l)| l).collect(),
        remainder,
        notes,
    })
}

/// What a format's numbers resolve, in words.
fn resolution(format: ThermalFormat) -> Option<String> {
    Some(match format {
        ThermalFormat::Siemens => return None,
        ThermalFormat::Linuxcnc => "the offset is rounded to counts of 1e-5 mm (the component's k = 100000 per mm): at most 0.005 µm per axis".to_string(),
        ThermalFormat::Beckhoff => "offset_0 is an integer of 0.1 µm (SGN32): at most 0.05 µm per axis; the PLC writes the coefficient as REAL64 over ADS (TEMPC::coefficient), where the axis list's SGN32 µm/m would round it".to_string(),
        ThermalFormat::Heidenhain => "a PLC word holding whole °C rounds each temperature by up to 0.5 K: the formula's coefficient times 0.5 K per sensor; the TNC reads the words once a second".to_string(),
        ThermalFormat::Klipper => "Klipper moves Z only in steps larger than one Z step distance and smooths the temperature over smooth_time (2 s by default)".to_string(),
    })
}

/// Klipper: the Z axis only, with the one sensor whose constant leaves the
/// least of its own error.
fn klipper_sensor(
    machine: &Machine,
    grid: &Grid<'_>,
    laws: &mut Vec<(usize, AxisLaw)>,
    notes: &mut Vec<String>,
) -> Result<(), ThermalExportError> {
    let Some(z) = laws.iter().position(|(_, l)| l.axis == 'Z') else {
        return Err(ThermalExportError::NoZAxis {
            machine: machine.name.clone(),
        });
    };
    let (v, mut law) = laws.swap_remove(z);
    let skipped: Vec<String> = laws.iter().map(|(_, l)| l.variable.clone()).collect();
    laws.clear();
    // Per sensor: how much of its own largest error its constant removes.
    let gain = |line: &SensorLine| {
        let mut alone = law.clone();
        alone.lines = vec![line.clone()];
        let r = grid.remainders(&[(v, alone)]);
        let r = r
            .iter()
            .find(|r| r.sensor == line.sensor)
            .map_or(0.0, |r| r.before - r.after);
        r
    };
    let best = (law.lines.iter())
        .map(|l| (gain(l), l))
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, l)| l.clone());
    let Some(best) = best else {
        return Ok(());
    };
    let coefficient = -law.sign * best.offset;
    if coefficient.is_nan() || coefficient.abs() > KLIPPER_COEFFICIENT {
        return Err(ThermalExportError::KlipperCoefficient {
            sensor: best.sensor.clone(),
            value: coefficient,
        });
    }
    let others: Vec<String> = (law.lines.iter())
        .filter(|l| l.sensor != best.sensor)
        .map(|l| l.sensor.clone())
        .collect();
    notes.push(format!(
        "sensor `{}` corrects Z: of the sensors, its constant removes the most of its own error",
        best.sensor
    ));
    if !others.is_empty() {
        notes.push(format!(
            "not held (one sensor only): {}; their errors remain",
            others.join(", ")
        ));
    }
    if !skipped.is_empty() {
        notes.push(format!(
            "not held (Z only): the axes {}; their errors remain",
            skipped.join(", ")
        ));
    }
    notes.push("the reference is the sensor's temperature when Z homes, not the model's: homing takes up the error there, the law corrects its change since".to_string());
    law.lines = vec![best];
    laws.push((v, law));
    Ok(())
}

/// HEIDENHAIN: per axis the TEMPCOMP formula within its length, the
/// law's offsets replaced by what it writes.
fn heidenhain_formulas(grid: &Grid<'_>, laws: &mut [(usize, AxisLaw)], notes: &mut Vec<String>) {
    let word = |s: &str| {
        let i = (grid.active.iter())
            .position(|&a| grid.machine.sensors[a].name == s)
            .unwrap_or(0);
        format!("W{}", TEMPCOMP_FIRST_WORD + 2 * i)
    };
    for (_, law) in laws.iter_mut() {
        // The table's displacement along the axis per kelvin: −E_k, the
        // axis correction times its sign.
        let terms: Vec<(f64, f64, String)> = (law.lines.iter())
            .map(|l| (law.sign * l.offset, l.reference, word(&l.sensor)))
            .collect();
        let (text, written) = tempcomp(&terms);
        let mut dropped = Vec::new();
        let mut kept = Vec::new();
        for (l, w) in law.lines.iter().zip(&written) {
            match w {
                Some(c) => kept.push(SensorLine {
                    offset: c / law.sign,
                    ..l.clone()
                }),
                None if l.offset != 0.0 => dropped.push(l.sensor.clone()),
                None => {}
            }
        }
        if !dropped.is_empty() {
            notes.push(format!(
                "axis {}: the 31 characters hold no room for {}; their share along {} remains",
                law.axis,
                dropped.join(", "),
                law.axis
            ));
        }
        law.lines = kept;
        law.formula = Some(text);
    }
}

/// The shortest-error TEMPCOMP formula of `Σ c_s·(W_s − ref_s)` (`terms`:
/// per sensor `c_s` in mm/K, `ref_s`, the word) within
/// [`TEMPCOMP_CHARS`]: `ĉ₁*W486+ĉ₂*W488−K`, the coefficients to as many
/// significant digits and the sensors (largest first) as fit, `K = Σ ĉ_s
/// ref_s` exact in decimal (the formula is 0 at the references). Returns
/// the formula and, per term, the coefficient written (`None`: left out).
pub fn tempcomp(terms: &[(f64, f64, String)]) -> (String, Vec<Option<f64>>) {
    let mut order: Vec<usize> = (0..terms.len()).filter(|&i| terms[i].0 != 0.0).collect();
    order.sort_by(|&a, &b| terms[b].0.abs().total_cmp(&terms[a].0.abs()));
    order.truncate(TEMPCOMP_VARIABLES);
    let total: f64 = order.iter().map(|&i| terms[i].0.abs()).sum();
    let mut best = (total, "0".to_string(), vec![None; terms.len()]);
    for n in 1..=order.len() {
        for digits in 1..=8usize {
            let kept = &order[..n];
            let mut written = vec![None; terms.len()];
            let mut text = String::new();
            let mut places = 0i32;
            let mut constant = 0.0;
            for &i in kept {
                let c = format!("{:.*e}", digits - 1, terms[i].0);
                let value: f64 = c.parse().unwrap_or(terms[i].0);
                let exponent: i32 = (c.split_once('e').map(|(_, e)| e))
                    .and_then(|e| e.parse().ok())
                    .unwrap_or(0);
                let reference = format!("{}", terms[i].1);
                let reference_places = reference.split_once('.').map_or(0, |(_, d)| d.len());
                places = places.max(digits as i32 - 1 - exponent + reference_places as i32);
                constant += value * terms[i].1;
                if !text.is_empty() && !c.starts_with('-') {
                    text.push('+');
                }
                text.push_str(&c);
                text.push('*');
                text.push_str(&terms[i].2);
                written[i] = Some(value);
            }
            let scale = 10f64.powi(places.clamp(0, 15));
            let constant = (constant * scale).round() / scale;
            if constant != 0.0 {
                let (plain, exp) = (
                    format!("{}", constant.abs()),
                    format!("{:e}", constant.abs()),
                );
                text.push(if constant > 0.0 { '-' } else { '+' });
                text.push_str(if exp.len() < plain.len() {
                    &exp
                } else {
                    &plain
                });
            }
            if text.len() > TEMPCOMP_CHARS {
                continue;
            }
            let error: f64 = (0..terms.len())
                .map(|i| (written[i].unwrap_or(0.0) - terms[i].0).abs())
                .sum();
            if error < best.0 || (error == best.0 && text.len() < best.1.len()) {
                best = (error, text, written);
            }
        }
    }
    (best.1, best.2)
}

/// The least-squares line `y ≈ a + b·(x − x0)`.
fn line(xs: &[f64], ys: &[f64], x0: f64) -> (f64, f64) {
    let k = xs.len() as f64;
    let mx = xs.iter().map(|x| x - x0).sum::<f64>() / k;
    let my = ys.iter().sum::<f64>() / k;
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (x, y) in xs.iter().zip(ys) {
        sxy += (x - x0 - mx) * (y - my);
        sxx += (x - x0 - mx) * (x - x0 - mx);
    }
    let b = if sxx > 0.0 { sxy / sxx } else { 0.0 };
    (my - b * mx, b)
}

impl ThermalLaw {
    /// The files of the law's format.
    pub fn files(&self, provenance: &str) -> Vec<ExportedFile> {
        match self.format {
            ThermalFormat::Siemens => vec![self.siemens(provenance)],
            ThermalFormat::Linuxcnc => self.linuxcnc(provenance),
            ThermalFormat::Beckhoff => self.beckhoff(provenance),
            ThermalFormat::Heidenhain => self.heidenhain(provenance),
            ThermalFormat::Klipper => vec![self.klipper(provenance)],
        }
    }

    /// The sensors the laws hold, in the order of their first appearance.
    fn sensors(&self) -> Vec<(&str, f64)> {
        let mut out: Vec<(&str, f64)> = Vec::new();
        for l in self.axes.iter().flat_map(|a| &a.lines) {
            if !out.iter().any(|(n, _)| *n == l.sensor) {
                out.push((l.sensor.as_str(), l.reference));
            }
        }
        out
    }

    /// The notes as comment lines opened by `mark`.
    fn noted(&self, mark: &str) -> String {
        let mut out = format!("{mark} holds: {}\n", self.holds);
        for n in &self.notes {
            out.push_str(&format!("{mark} note: {n}\n"));
        }
        for r in &self.remainder {
            out.push_str(&format!(
                "{mark} remainder per kelvin of {}: {:.4} um/K before, {:.4} um/K after\n",
                r.sensor,
                r.before * 1e3,
                r.after * 1e3
            ));
        }
        out
    }

    /// `Σ_s c_s·(T_s − ref_s)` with `T_s` named by `var(i)`.
    fn formula(
        &self,
        coefficient: impl Fn(&SensorLine) -> f64,
        law: &AxisLaw,
        var: impl Fn(usize) -> String,
    ) -> String {
        let terms: Vec<String> = (law.lines.iter().enumerate())
            .filter(|(_, l)| coefficient(l) != 0.0)
            .map(|(i, l)| format!("{:e}*({}-{})", short(coefficient(l)), var(i), l.reference))
            .collect();
        signed_sum(terms, "+", "-", "0")
    }

    /// `temp_comp_axes.lis` and `FB_TempComp.st` (module docs): s0 rounded
    /// to 0.1 µm, the offset at it moved along the line.
    fn beckhoff(&self, provenance: &str) -> Vec<ExportedFile> {
        use std::fmt::Write;
        let sensors = self.sensors();
        let ident = |s: &str| {
            let mut i: String = (s.chars())
                .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
                .collect();
            if !i.starts_with(|c: char| c.is_ascii_alphabetic()) {
                i.insert_str(0, "T_");
            }
            i
        };
        let mut lis = format!(
            "# temp_comp_axes.lis - written by {provenance}\n# machine {}: TwinCAT CNC axis temperature compensation (P-AXIS-00271..00274), delta_s = offset_0 + coefficient*(s - s0)\n# add each block to the axis parameter list of its axis; FB_TempComp sets offset_0 and coefficient from the temperatures\n",
            self.machine
        );
        lis.push_str(&self.noted("#"));
        let mut st = format!(
            "(* FB_TempComp - written by {provenance} (docs/export-controllers.md, \"Thermal compensation\")\n   machine {}: per axis the temperature compensation of TwinCAT CNC, delta_s = offset_0 + coefficient*(s - s0)\n   (P-AXIS-00272..00274): offset_0 in 0.1 um, coefficient in um/m. Call it after each temperature reading and\n   write each axis's outputs to its lr_param.temp_comp_offset_0 and lr_param.temp_comp_coefficient\n   (at run time over ADS, GEO task port 551, index group 16#120300: TEMPC::coefficient, REAL64 um/m, at\n   index offset 16#<AID>0043). *)\nFUNCTION_BLOCK FB_TempComp\nVAR_INPUT\n",
            self.machine
        );
        for (name, reference) in &sensors {
            let _ = writeln!(
                st,
                "    {} : LREAL := {}; (* {name}, degC; at its reference {reference} no correction *)",
                ident(name),
                st_real(*reference)
            );
        }
        st.push_str("END_VAR\nVAR_OUTPUT\n");
        let mut body = String::new();
        for law in &self.axes {
            let a = law.axis;
            let s0 = (law.p0 * 1e4).round();
            let shift = s0 * 1e-4 - law.p0;
            let _ = writeln!(
                st,
                "    offset_0_{a} : DINT; (* 0.1 um: lr_param.temp_comp_offset_0 of axis {a} *)\n    coefficient_{a} : LREAL; (* um/m: lr_param.temp_comp_coefficient of axis {a} *)"
            );
            let term = |c: f64, l: &SensorLine| {
                format!(
                    "{}*({} - {})",
                    st_real(c),
                    ident(&l.sensor),
                    st_real(l.reference)
                )
            };
            let offsets: Vec<String> = (law.lines.iter())
                .filter(|l| l.offset + l.slope * shift != 0.0)
                .map(|l| term((l.offset + l.slope * shift) * 1e4, l))
                .collect();
            let slopes: Vec<String> = (law.lines.iter())
                .filter(|l| l.slope != 0.0)
                .map(|l| term(l.slope * 1e6, l))
                .collect();
            let sum = |t: Vec<String>| signed_sum(t, " + ", " - ", "0.0");
            let _ = writeln!(
                body,
                "offset_0_{a} := LREAL_TO_DINT({});\ncoefficient_{a} := {};",
                sum(offsets),
                sum(slopes)
            );
            let _ = writeln!(
                lis,
                "# axis {a} (variable {}, moves the tool along {}{a})\nlr_param.temp_comp                 1\n# s0 = {} mm, in 0.1 um\nlr_param.temp_comp_position_0      {}\n# at the reference temperatures; FB_TempComp sets them\nlr_param.temp_comp_offset_0        0\nlr_param.temp_comp_coefficient     0",
                law.variable,
                if law.sign > 0.0 { "+" } else { "-" },
                s0 * 1e-4,
                s0 as i64
            );
        }
        st.push_str("END_VAR\n");
        st.push_str(&body);
        st.push_str("END_FUNCTION_BLOCK\n");
        vec![
            ExportedFile {
                name: "temp_comp_axes.lis".to_string(),
                text: lis,
            },
            ExportedFile {
                name: "FB_TempComp.st".to_string(),
                text: st,
            },
        ]
    }

    /// `KINEMATICS_TEMPCOMP.TAB` and its README (module docs).
    fn heidenhain(&self, provenance: &str) -> Vec<ExportedFile> {
        use std::fmt::Write;
        let rows: Vec<[String; 5]> = (self.axes.iter().enumerate())
            .map(|(nr, a)| {
                [
                    nr.to_string(),
                    "Trans".to_string(),
                    a.axis.to_string(),
                    "0".to_string(),
                    a.formula.clone().unwrap_or_else(|| "0".to_string()),
                ]
            })
            .collect();
        let tab = crate::compensation::controllers::tnc_table(
            "KINEMATICS_TEMPCOMP.TAB",
            ["NR", "KEY", "AXIS", "COORD", "TEMPCOMP"],
            &rows,
        );
        let mut readme = format!(
            "{provenance}: machine `{}`: HEIDENHAIN kinematics description, temperature compensation (TEMPCOMP)\n\n",
            self.machine
        );
        readme.push_str("KINEMATICS_TEMPCOMP.TAB: one Trans row per axis, COORD 0, its TEMPCOMP the table's displacement along the axis (mm) as a formula of the sensors (iTNC 530 HSCI Technical Manual 6.5.3: at most 31 characters, PLC words as variables, evaluated every second)\n");
        readme.push_str("- put the rows first on the workpiece side of the machine's description (the machine base end, before the first MachAxis of the axes that carry the workpiece): they move the workpiece in machine coordinates, so the control's commands follow it\n");
        readme.push_str("- a row needs an entry in TEMPCOMP to be compensated (0 counts); the TNC stops at the first row without one: enter 0 in the rows before these\n");
        readme.push_str("- the PLC words hold the sensors' temperatures in degC:\n");
        for (i, r) in self.remainder.iter().enumerate() {
            let _ = writeln!(readme, "  W{} = {}", TEMPCOMP_FIRST_WORD + 2 * i, r.sensor);
        }
        readme.push_str(&self.noted("-"));
        vec![
            ExportedFile {
                name: "KINEMATICS_TEMPCOMP.TAB".to_string(),
                text: tab,
            },
            ExportedFile {
                name: "KINEMATICS_TEMPCOMP-README.txt".to_string(),
                text: readme,
            },
        ]
    }

    /// `z_thermal_adjust.cfg` (module docs).
    fn klipper(&self, provenance: &str) -> ExportedFile {
        use std::fmt::Write;
        let mut out = format!(
            "# z_thermal_adjust.cfg - written by {provenance}\n# machine {}: Klipper's [z_thermal_adjust] (Config_Reference): z = z - temp_coeff*(T - T_ref), T_ref the sensor's temperature when Z homes\n",
            self.machine
        );
        out.push_str(&self.noted("#"));
        let line = self
            .axes
            .first()
            .and_then(|a| a.lines.first().map(|l| (a, l)));
        out.push_str("[z_thermal_adjust]\n");
        match line {
            Some((a, l)) => {
                let _ = writeln!(out, "temp_coeff: {}", short(-a.sign * l.offset));
                let _ = writeln!(out, "# the sensor {} (required; keys as in [extruder]): sensor_type, sensor_pin, min_temp, max_temp", l.sensor);
            }
            None => out.push_str("temp_coeff: 0\n"),
        }
        out.push_str("#sensor_type:\n#sensor_pin:\n#min_temp:\n#max_temp:\n");
        ExportedFile {
            name: "z_thermal_adjust.cfg".to_string(),
            text: out,
        }
    }

    /// `TEMP_COMP.SPF` (module docs).
    fn siemens(&self, provenance: &str) -> ExportedFile {
        use std::fmt::Write;
        let mut out = String::new();
        let _ = writeln!(
            out,
            "; TEMP_COMP.SPF - temperature compensation (SINUMERIK K3 4.2) of machine {}",
            self.machine
        );
        let _ = writeln!(
            out,
            "; written by {provenance} (docs/export-controllers.md, \"Thermal compensation\")"
        );
        out.push_str("; per axis: delta_K = K0 + tan(beta)*(P - P0), K0 in mm, tan(beta) a ratio, P0 in mm\n");
        out.push_str(&self.noted(";"));
        out.push_str("; set MD32750 $MA_TEMP_COMP_TYPE = 3 (position-independent and -dependent part) for each axis below\n");
        out.push_str("; the PLC writes each sensor's temperature (degC) to its R parameter and calls this subprogram:\n");
        for (i, (name, reference)) in self.sensors().iter().enumerate() {
            let _ = writeln!(out, ";   R{} = {name} (reference {reference} degC)", i + 1);
        }
        for law in &self.axes {
            let ax = format!("{}1", law.axis);
            let r = |i: usize| format!("R{}", i + 1);
            let _ = writeln!(
                out,
                "; axis {} (variable {}, moves the tool along {}{})",
                ax,
                law.variable,
                if law.sign > 0.0 { "+" } else { "-" },
                law.axis
            );
            let _ = writeln!(
                out,
                "$SA_TEMP_COMP_ABS_VALUE[{ax}]={}",
                self.formula(|l| l.offset, law, r)
            );
            let _ = writeln!(
                out,
                "$SA_TEMP_COMP_SLOPE[{ax}]={}",
                self.formula(|l| l.slope, law, r)
            );
            let _ = writeln!(out, "$SA_TEMP_COMP_REF_POSITION[{ax}]={}", law.p0);
        }
        out.push_str("M17\n");
        ExportedFile {
            name: "TEMP_COMP.SPF".to_string(),
            text: out,
        }
    }

    /// The HAL component, its HAL file and the INI lines (module docs).
    fn linuxcnc(&self, provenance: &str) -> Vec<ExportedFile> {
        use std::fmt::Write;
        let sensors = self.sensors();
        let pin = |s: &str| {
            s.to_lowercase()
                .replace(|c: char| !c.is_ascii_alphanumeric(), "_")
        };
        let mut comp = String::new();
        let _ = writeln!(comp, "component thermal_comp \"Thermal compensation of machine {} through external axis offsets\";", self.machine);
        let _ = writeln!(
            comp,
            "// written by {provenance} (docs/export-controllers.md, \"Thermal compensation\")"
        );
        for (name, reference) in &sensors {
            let _ = writeln!(
                comp,
                "pin in float temp_{} = {reference} \"{name} (degC; unconnected: its reference, no offset)\";",
                pin(name)
            );
        }
        for law in &self.axes {
            let a = law.axis.to_ascii_lowercase();
            let _ = writeln!(
                comp,
                "pin in float pos_{a} \"axis {} position (axis.{a}.pos-cmd)\";",
                law.axis
            );
            let _ = writeln!(
                comp,
                "pin out s32 counts_{a} \"to axis.{a}.eoffset-counts\";"
            );
            let _ = writeln!(comp, "pin out float offset_{a} \"the offset (mm)\";");
        }
        comp.push_str("pin in bit is_on \"halui.machine.is-on\";\npin in bit homed \"motion.is-all-homed\";\n");
        comp.push_str("param rw float k = 100000 \"counts per mm; axis.L.eoffset-scale = 1/k\";\n");
        comp.push_str("option period no;\nfunction _;\nlicense \"GPL\";\n;;\n");
        comp.push_str("static int counts(double mm, double k) { return mm >= 0 ? (int)(mm * k + 0.5) : (int)(mm * k - 0.5); }\n");
        comp.push_str("FUNCTION(_) {\n    double d;\n");
        for law in &self.axes {
            let a = law.axis.to_ascii_lowercase();
            let var = |i: usize| format!("temp_{}", pin(sensors[i].0));
            let offset = self.formula(|l| l.offset, law, var);
            let slope = self.formula(|l| l.slope, law, var);
            let _ = writeln!(
                comp,
                "    d = ({offset}) + ({slope})*(pos_{a} - {});",
                law.p0
            );
            let _ = writeln!(comp, "    if (!is_on || !homed) d = 0;");
            let _ = writeln!(comp, "    offset_{a} = d;\n    counts_{a} = counts(d, k);");
        }
        comp.push_str("}\n");
        let mut hal = String::new();
        let _ = writeln!(
            hal,
            "# thermal_comp.hal - written by {provenance}; the integrator connects each temp pin"
        );
        hal.push_str(&self.noted("#"));
        hal.push_str(
            "loadrt thermal_comp\naddf thermal-comp servo-thread\nsetp thermal-comp.k 100000\n",
        );
        hal.push_str("net tc-on halui.machine.is-on => thermal-comp.is-on\nnet tc-homed motion.is-all-homed => thermal-comp.homed\n");
        for (name, _) in &sensors {
            let _ = writeln!(
                hal,
                "# net tc-{p} <your temperature pin, degC> => thermal-comp.temp-{p}",
                p = pin(name).replace('_', "-")
            );
        }
        for law in &self.axes {
            let a = law.axis.to_ascii_lowercase();
            let _ = writeln!(
                hal,
                "net tc-pos-{a} axis.{a}.pos-cmd => thermal-comp.pos-{a}"
            );
            let _ = writeln!(
                hal,
                "net tc-counts-{a} thermal-comp.counts-{a} => axis.{a}.eoffset-counts"
            );
            let _ = writeln!(
                hal,
                "setp axis.{a}.eoffset-scale 0.00001\nsetp axis.{a}.eoffset-enable 1"
            );
        }
        let mut ini = format!(
            "# thermal_comp.ini - written by {provenance}\n# add to each compensated axis's section of the INI file\n"
        );
        for law in &self.axes {
            let _ = writeln!(ini, "[AXIS_{}]\nOFFSET_AV_RATIO = 0.1", law.axis);
        }
        ini.push_str("[HAL]\nHALUI = halui\nHALFILE = thermal_comp.hal\n");
        vec![
            ExportedFile {
                name: "thermal_comp.comp".to_string(),
                text: comp,
            },
            ExportedFile {
                name: "thermal_comp.hal".to_string(),
                text: hal,
            },
            ExportedFile {
                name: "thermal_comp.ini".to_string(),
                text: ini,
            },
        ]
    }
}

/// `x` to 12 significant digits, the shortest decimal that reads back as
/// that (a written coefficient: its relative rounding at most 5e-13).
fn short(x: f64) -> f64 {
    format!("{x:.11e}").parse().unwrap_or(x)
}

/// An IEC 61131-3 real literal of [`short`]`(x)` (its mantissa with a
/// decimal point).
fn st_real(x: f64) -> String {
    let s = format!("{:e}", short(x));
    match s.split_once('e') {
        Some((m, e)) if !m.contains('.') => format!("{m}.0e{e}"),
        _ => s,
    }
}

/// `terms` (each a product, a negative one opening with `-`) summed with
/// `plus` and `minus` between them; `zero` for none.
fn signed_sum(terms: Vec<String>, plus: &str, minus: &str, zero: &str) -> String {
    let mut out = String::new();
    for term in terms {
        match (out.is_empty(), term.strip_prefix('-')) {
            (true, _) => out = term,
            (false, Some(negated)) => out = format!("{out}{minus}{negated}"),
            (false, None) => out = format!("{out}{plus}{term}"),
        }
    }
    if out.is_empty() {
        zero.to_string()
    } else {
        out
    }
}
