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
}

impl ThermalFormat {
    /// `siemens` or `linuxcnc`.
    pub fn name(self) -> &'static str {
        match self {
            ThermalFormat::Siemens => "siemens",
            ThermalFormat::Linuxcnc => "linuxcnc",
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
    /// `m`: the correction's slope along the axis per kelvin (mm/mm/K).
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
    /// Per sensor, its line.
    pub lines: Vec<SensorLine>,
}

/// What a law leaves per sensor: the largest tool-point error per kelvin
/// over the grid after the law's correction (mm/K), and where.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SensorRemainder {
    /// The sensor.
    pub sensor: String,
    /// The largest `|E_s(q) + J·Δq_s(q)|` (mm/K) over the grid, before.
    pub before: f64,
    /// The same after the law's correction.
    pub after: f64,
    /// Where `after` is largest (machine-ordered axis values).
    pub at: Vec<f64>,
}

/// The law of every linear axis and what it leaves.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ThermalLaw {
    /// The machine.
    pub machine: String,
    /// Per linear axis.
    pub axes: Vec<AxisLaw>,
    /// Per sensor with thermal terms.
    pub remainder: Vec<SensorRemainder>,
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

/// The law of `machine`'s thermal terms over `points` (machine-ordered
/// axis values; a full factorial grid, every axis with at least two
/// values), `model` compiled from it, `values` its values (the thermal
/// coefficients per kelvin).
pub fn fit<M: ErrorModel>(
    machine: &Machine,
    model: &M,
    params: &[f64],
    values: &Values,
    points: &[Vec<f64>],
) -> Result<ThermalLaw, ThermalExportError> {
    if !machine.is_thermal() {
        return Err(ThermalExportError::NoThermalTerms {
            machine: machine.name.clone(),
        });
    }
    let axes = linear_axes(machine, model, params, points)?;
    let n = machine.errors.len();
    let (mut scratch, mut e) = (vec![0.0; 6 * n], vec![0.0; n]);
    let sensed: Vec<Vec<[f64; 3]>> = points
        .iter()
        .map(|q| per_sensor(machine, model, params, values, q, &mut scratch, &mut e))
        .collect::<Result<_, _>>()?;
    let active: Vec<usize> = (0..machine.sensors.len())
        .filter(|&s| machine.errors.iter().any(|e| e.sensor == Some(s)))
        .collect();
    let mut laws = Vec::new();
    for &(v, k, sign) in &axes {
        let xs: Vec<f64> = points.iter().map(|q| q[v]).collect();
        let p0 = xs.iter().copied().fold(f64::INFINITY, f64::min);
        let distinct = {
            let mut d = xs.clone();
            d.sort_by(f64::total_cmp);
            d.dedup();
            d.len()
        };
        if distinct < 2 {
            return Err(ThermalExportError::Grid {
                variable: machine.variables[v].name.clone(),
                count: distinct,
            });
        }
        let lines = active
            .iter()
            .map(|&s| {
                let ys: Vec<f64> = sensed.iter().map(|es| -es[s][k] / sign).collect();
                let (offset, slope) = line(&xs, &ys, p0);
                let sensor = &machine.sensors[s];
                SensorLine {
                    sensor: sensor.name.clone(),
                    reference: sensor.reference,
                    offset,
                    slope,
                }
            })
            .collect();
        laws.push(AxisLaw {
            variable: machine.variables[v].name.clone(),
            axis: ['X', 'Y', 'Z'][k],
            sign,
            p0,
            lines,
        });
    }
    let remainder = active
        .iter()
        .enumerate()
        .map(|(i, &s)| {
            let mut r = SensorRemainder {
                sensor: machine.sensors[s].name.clone(),
                before: 0.0,
                after: 0.0,
                at: Vec::new(),
            };
            for (q, es) in points.iter().zip(&sensed) {
                let mut left = es[s];
                for (law, &(v, k, sign)) in laws.iter().zip(&axes) {
                    let l = &law.lines[i];
                    left[k] += sign * (l.offset + l.slope * (q[v] - law.p0));
                }
                let norm = |p: [f64; 3]| (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
                r.before = r.before.max(norm(es[s]));
                if norm(left) >= r.after {
                    r.after = norm(left);
                    r.at = q.clone();
                }
            }
            r
        })
        .collect();
    Ok(ThermalLaw {
        machine: machine.name.clone(),
        axes: laws,
        remainder,
    })
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
    /// The correction `Δq_a` of axis `law` at axis position `x` and
    /// temperatures `t` (°C by sensor name; a sensor not given at its
    /// reference).
    pub fn correction(law: &AxisLaw, x: f64, t: &[(String, f64)]) -> f64 {
        law.lines
            .iter()
            .map(|l| {
                let dt = t
                    .iter()
                    .find(|(n, _)| *n == l.sensor)
                    .map_or(0.0, |(_, v)| v - l.reference);
                dt * (l.offset + l.slope * (x - law.p0))
            })
            .sum()
    }

    /// The files of `format`.
    pub fn files(&self, format: ThermalFormat, provenance: &str) -> Vec<ExportedFile> {
        match format {
            ThermalFormat::Siemens => vec![self.siemens(provenance)],
            ThermalFormat::Linuxcnc => self.linuxcnc(provenance),
        }
    }

    /// The sensors in the order of the laws' lines.
    fn sensors(&self) -> Vec<(&str, f64)> {
        self.axes
            .first()
            .map(|a| {
                a.lines
                    .iter()
                    .map(|l| (l.sensor.as_str(), l.reference))
                    .collect()
            })
            .unwrap_or_default()
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
            .map(|(i, l)| format!("{:e}*({}-{})", coefficient(l), var(i), l.reference))
            .collect();
        if terms.is_empty() {
            "0".to_string()
        } else {
            terms.join("+")
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
