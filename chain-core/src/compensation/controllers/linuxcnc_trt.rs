//! LinuxCNC's table-rotary-tilting kinematics, `xyzac-trt-kins` and
//! `xyzbc-trt-kins` (five-axis spec, "Output"; docs/export-controllers.md,
//! "linuxcnc-trt"): the HAL pins that place the two rotary axis lines and
//! the rotary joints' `HOME_OFFSET` change for their zero errors.
//!
//! The model is `src/emc/kinematics/trtfuncs.c` of LinuxCNC (master,
//! `xyzacKinematicsForward` / `xyzacKinematicsInverse` /
//! `xyzbcKinematicsForward` / `xyzbcKinematicsInverse`, transcribed term
//! by term below), with its pins `x-rot-point`, `y-rot-point`,
//! `z-rot-point` (the C axis's centre of rotation from the machine's zero),
//! `y-offset` (xyzac) or `x-offset` (xyzbc) and `z-offset` (the tilting
//! axis's centre from the C axis's), `tool-offset` (added to `z-offset`)
//! and `conventional-directions` (false: a positive joint angle turns the
//! table right-handed about +X, +Y, +Z; true: the other way, the tool's
//! right-handed rotation relative to the table). The two modules hold the
//! positions of the two axis lines only, parallel to the machine's axes:
//! an axis tilt (an orientation location error) and an error motion along
//! a rotary axis remain, with their tool-point effect in the report.
//!
//! The pins are fitted over the grid (`rotary.rs`): the nominal ones to the
//! machine file's nominal kinematics (which must be this module's, for one
//! of the two direction settings: the machine is refused otherwise), the
//! identified ones with the zero offsets to the built machine's error.

use serde::Serialize;

use crate::compensation::{opening_line, ExportedFile};
use crate::model_trait::ErrorModel;

use super::rotary::{KinematicsParameter, TableTable, TrtModel, Written};
use super::{interpolate_held, num, ControllerError, Export, LINUXCNC_MAX_POINTS, ROTARY_STEP_DEG};

/// `TO_RAD` of LinuxCNC (`rtapi_math.h`: `M_PI / 180`).
const TO_RAD: f64 = std::f64::consts::PI / 180.0;

/// One of the two LinuxCNC table-rotary-tilting modules.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum TrtModule {
    /// `xyzac-trt-kins`: A tilts about X and carries C.
    Xyzac,
    /// `xyzbc-trt-kins`: B tilts about Y and carries C.
    Xyzbc,
}

/// The pins of `trtfuncs.c`'s `struct haldata` (lengths in machine units,
/// mm here).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TrtPins {
    /// `x-rot-point`.
    pub x_rot_point: f64,
    /// `y-rot-point`.
    pub y_rot_point: f64,
    /// `z-rot-point`.
    pub z_rot_point: f64,
    /// `x-offset` (xyzbc only).
    pub x_offset: f64,
    /// `y-offset` (xyzac only).
    pub y_offset: f64,
    /// `z-offset`.
    pub z_offset: f64,
    /// `tool-offset` (`motion.tooloffset.z`).
    pub tool_offset: f64,
    /// `conventional-directions`.
    pub conventional_directions: bool,
}

impl TrtModule {
    /// The module's name (its HAL prefix).
    pub fn name(self) -> &'static str {
        match self {
            TrtModule::Xyzac => "xyzac-trt-kins",
            TrtModule::Xyzbc => "xyzbc-trt-kins",
        }
    }

    /// The tilting axis's letter.
    pub fn tilt(self) -> char {
        match self {
            TrtModule::Xyzac => 'A',
            TrtModule::Xyzbc => 'B',
        }
    }

    /// `xyz?cKinematicsForward`: the position from the joints `j` (X, Y,
    /// Z) and the angles `a` (A or B) and `c`, degrees.
    pub fn forward(self, p: &TrtPins, j: [f64; 3], a: f64, c: f64) -> [f64; 3] {
        let con = if p.conventional_directions { 1.0 } else { -1.0 };
        let (xr, yr, zr) = (p.x_rot_point, p.y_rot_point, p.z_rot_point);
        let dz = p.z_offset + p.tool_offset;
        let (sa, ca) = (a * TO_RAD).sin_cos();
        let (sc, cc) = (c * TO_RAD).sin_cos();
        match self {
            TrtModule::Xyzac => {
                let dy = p.y_offset;
                [
                    cc * (j[0] - xr) - con * sc * ca * (j[1] - dy - yr)
                        + sc * sa * (j[2] - dz - zr)
                        - con * sc * dy
                        + xr,
                    con * sc * (j[0] - xr) + cc * ca * (j[1] - dy - yr)
                        - con * cc * sa * (j[2] - dz - zr)
                        + cc * dy
                        + yr,
                    con * sa * (j[1] - dy - yr) + ca * (j[2] - dz - zr) + dz + zr,
                ]
            }
            TrtModule::Xyzbc => {
                let dx = p.x_offset;
                [
                    cc * ca * (j[0] - dx - xr) - con * sc * (j[1] - yr)
                        + con * cc * sa * (j[2] - dz - zr)
                        + cc * dx
                        + xr,
                    con * sc * ca * (j[0] - dx - xr)
                        + cc * (j[1] - yr)
                        + sc * sa * (j[2] - dz - zr)
                        + con * sc * dx
                        + yr,
                    -con * sa * (j[0] - dx - xr) + ca * (j[2] - dz - zr) + dz + zr,
                ]
            }
        }
    }

    /// `xyz?cKinematicsInverse` as LinuxCNC master writes it: the joints X,
    /// Y, Z for the position `pos` at the angles `a`, `c` (degrees). (The
    /// master's xyzbc inverse is the forward's inverse only for
    /// `conventional-directions` true or zero offsets: its `dpx`, `dpz`
    /// carry no direction sign; the export checks the round trip, and
    /// [`TrtModule::inverse_of_forward`] is the exact one.)
    pub fn inverse(self, p: &TrtPins, pos: [f64; 3], a: f64, c: f64) -> [f64; 3] {
        self.inverse_with(p, pos, a, c, false)
    }

    /// The exact inverse of [`TrtModule::forward`]: master's for xyzac and
    /// for xyzbc with `conventional-directions` true, LinuxCNC 2.9's
    /// `xyzbcKinematicsInverse` (`dpx = −cos b·dx − sin b·dz + dx`, `dpz =
    /// sin b·dx − cos b·dz + dz`) with it false: the direction sign in
    /// `dpx`, `dpz`.
    pub fn inverse_of_forward(self, p: &TrtPins, pos: [f64; 3], a: f64, c: f64) -> [f64; 3] {
        self.inverse_with(p, pos, a, c, true)
    }

    fn inverse_with(self, p: &TrtPins, pos: [f64; 3], a: f64, c: f64, exact: bool) -> [f64; 3] {
        let con = if p.conventional_directions { 1.0 } else { -1.0 };
        let (xr, yr, zr) = (p.x_rot_point, p.y_rot_point, p.z_rot_point);
        let dz = p.z_offset + p.tool_offset;
        let (sa, ca) = (a * TO_RAD).sin_cos();
        let (sc, cc) = (c * TO_RAD).sin_cos();
        let (x, y, z) = (pos[0] - xr, pos[1] - yr, pos[2] - zr);
        match self {
            TrtModule::Xyzac => {
                let dy = p.y_offset;
                [
                    cc * x + con * sc * y + xr,
                    -con * sc * ca * x + cc * ca * y + con * sa * z - ca * dy - con * sa * dz
                        + dy
                        + yr,
                    sc * sa * x - con * cc * sa * y + ca * z + con * sa * dy - ca * dz + dz + zr,
                ]
            }
            TrtModule::Xyzbc => {
                let dx = p.x_offset;
                let s = if exact { con } else { 1.0 };
                let dpx = -ca * dx + s * sa * dz + dx;
                let dpz = -s * sa * dx - ca * dz + dz;
                [
                    cc * ca * x + con * sc * ca * y - con * sa * z + dpx + xr,
                    -con * sc * x + cc * y + yr,
                    con * cc * sa * x + sc * sa * y + ca * z + dpz + zr,
                ]
            }
        }
    }
}

/// The module and direction setting under a pin vector `[x-rot-point,
/// y-rot-point, y-offset or x-offset, z-offset]` (`z-rot-point` 0: only
/// its sum with `z-offset` acts; `tool-offset` 0).
#[derive(Debug, Clone, Copy)]
struct Model {
    module: TrtModule,
    conventional: bool,
}

impl Model {
    fn pins(&self, v: &[f64]) -> TrtPins {
        let (x_offset, y_offset) = match self.module {
            TrtModule::Xyzac => (0.0, v[2]),
            TrtModule::Xyzbc => (v[2], 0.0),
        };
        TrtPins {
            x_rot_point: v[0],
            y_rot_point: v[1],
            z_rot_point: 0.0,
            x_offset,
            y_offset,
            z_offset: v[3],
            tool_offset: 0.0,
            conventional_directions: self.conventional,
        }
    }
}

impl TrtModel for Model {
    fn affine(&self) -> usize {
        4
    }

    fn forward(&self, pins: &[f64], j: [f64; 3], a: f64, c: f64) -> [f64; 3] {
        self.module.forward(&self.pins(pins), j, a, c)
    }

    /// The exact inverse ([`TrtModule::inverse_of_forward`]): what LinuxCNC
    /// 2.9 computes, and master where its inverse is right.
    fn inverse(&self, pins: &[f64], p: [f64; 3], a: f64, c: f64) -> [f64; 3] {
        self.module.inverse_of_forward(&self.pins(pins), p, a, c)
    }
}

pub(super) fn export<M: ErrorModel + Sync>(
    tt: &TableTable<'_, M>,
) -> Result<Export, ControllerError> {
    let m = tt.machine;
    // The rotary axes' positioning errors go into a COMP_FILE each.
    let comps: Vec<RotaryComp> = [tt.tilt, tt.rotary]
        .into_iter()
        .filter_map(|v| rotary_comp(tt, v).transpose())
        .collect::<Result<_, _>>()?;
    let held: Vec<String> = comps.iter().flat_map(|c| c.errors.clone()).collect();
    let candidates = [TrtModule::Xyzac, TrtModule::Xyzbc]
        .into_iter()
        .flat_map(|module| {
            [false, true].into_iter().map(move |conventional| {
                let label = format!(
                    "{} with conventional-directions {}",
                    module.name(),
                    u8::from(conventional)
                );
                (
                    Model {
                        module,
                        conventional,
                    },
                    label,
                )
            })
        });
    let none = "its nominal kinematics are neither LinuxCNC module's";
    let (model, fit) = tt.fit_first(candidates, &held, none)?;
    let module = model.module;
    let nominal = model.pins(&fit.nominal);
    let pins = model.pins(&fit.pins);
    let axes = tt.axis_names(&module.tilt().to_string(), "C");
    // The controller's own kinematics against themselves: the inverse of
    // the forward over the grid, with the identified pins.
    let round_trip = (tt.grid.iter())
        .map(|q| {
            let (j, a, c) = tt.joints(q);
            let back = module.inverse(&pins, module.forward(&pins, j, a, c), a, c);
            (0..3).map(|k| (back[k] - j[k]).abs()).fold(0.0, f64::max)
        })
        .fold(0.0, f64::max);
    let prefix = module.name();
    let mut notes = vec![format!(
        "conventional-directions {}: a positive {} or C joint angle turns the table {} about +{}, +Z (the machine file's rotary axes)",
        u8::from(model.conventional),
        module.tilt(),
        if model.conventional {
            "left-handed (the tool right-handed relative to the table)"
        } else {
            "right-handed"
        },
        if module == TrtModule::Xyzac { 'X' } else { 'Y' }
    )];
    notes.push(format!(
        "the pins are for tool-offset 0 with the machine file's tool point as LinuxCNC's controlled point; with {prefix}.tool-offset fed by motion.tooloffset.z = L, write z-offset − L"
    ));
    if round_trip > 1e-9 {
        notes.push(format!(
            "{prefix}'s inverse in LinuxCNC master's trtfuncs.c is not the inverse of its forward with conventional-directions {} and these offsets (the joints differ by up to {round_trip:.3e} mm after a round trip; xyzbcKinematicsInverse's dpx, dpz lack the direction sign since commit bfb687e): the pins are right for the module's forward, which LinuxCNC 2.9's trtfuncs.c inverts exactly; on master the controller misses by the same amount until that inverse is fixed",
            u8::from(model.conventional)
        ));
    }
    let mut parameters = vec![
        param("x-rot-point", nominal.x_rot_point, pins.x_rot_point, "mm"),
        param("y-rot-point", nominal.y_rot_point, pins.y_rot_point, "mm"),
        param("z-rot-point", nominal.z_rot_point, pins.z_rot_point, "mm"),
        match module {
            TrtModule::Xyzac => param("y-offset", nominal.y_offset, pins.y_offset, "mm"),
            TrtModule::Xyzbc => param("x-offset", nominal.x_offset, pins.x_offset, "mm"),
        },
        param("z-offset", nominal.z_offset, pins.z_offset, "mm"),
    ];
    let home = [module.tilt(), 'C'].map(|a| format!("{a} HOME_OFFSET change"));
    parameters.extend(fit.zero_changes(home, "deg"));
    parameters.extend(fit.work_offset_changes("G54", "mm (work offset)"));
    let mut hal = String::new();
    let head = opening_line(
        &tt.provenance,
        &format!("machine `{}`: the pins of LinuxCNC's {prefix}", m.name),
    );
    hal.push_str(&format!("# {head}\n"));
    hal.push_str(&format!(
        "# model: src/emc/kinematics/trtfuncs.c ({}KinematicsForward/Inverse); lengths in machine units (mm), angles in degrees\n",
        if module == TrtModule::Xyzac { "xyzac" } else { "xyzbc" }
    ));
    hal.push_str(&format!(
        "# joints: X = {}, Y = {}, Z = {}, {} = {}, C = {} (the machine file's axis variables; a `-` turns one so that each linear joint moves the tool along +X, +Y, +Z of the table at zero angles)\n",
        axes[0].1, axes[1].1, axes[2].1, axes[3].0, axes[3].1, axes[4].1
    ));
    for note in &notes {
        hal.push_str(&format!("# {note}\n"));
    }
    hal.push_str("# nominal (machine file) -> identified; z-rot-point and z-offset act only through their sum\n");
    for p in parameters.iter().filter(|p| p.unit == "mm") {
        hal.push_str(&format!(
            "setp {prefix}.{} {}    # nominal {}\n",
            p.name,
            num(p.value),
            num(p.nominal)
        ));
    }
    hal.push_str(&format!(
        "setp {prefix}.conventional-directions {}\n",
        u8::from(model.conventional)
    ));
    let mut readme = String::new();
    readme.push_str(&format!("# {head}\n"));
    readme.push_str("# The rotary joints' zero errors: add each change to the joint's [JOINT_n]HOME_OFFSET (degrees, INI) and home again;\n");
    readme.push_str("# after that the joint reads the angle the model puts the axis at (true angle = reading before + change).\n");
    for p in parameters.iter().filter(|p| p.unit == "deg") {
        readme.push_str(&format!(
            "{} = {}   # joint {}\n",
            p.name,
            num(p.value),
            p.name.split(' ').next().unwrap_or("")
        ));
    }
    readme.push_str("# The workpiece's zero: a location error of an axis that carries the table moves the part with it; re-probe the\n");
    readme.push_str("# part after writing the pins, or add these to its work offset (G54..G59.3, mm, table coordinates):\n");
    for p in parameters.iter().filter(|p| p.unit.starts_with("mm (")) {
        readme.push_str(&format!("{} = {}\n", p.name, num(p.value)));
    }
    for c in &comps {
        let name = &m.variables[c.variable].name;
        readme.push_str(&format!(
            "# joint {name}'s positioning error ({}): in its [JOINT_n] section COMP_FILE = {name}.comp and COMP_FILE_TYPE = 1\n",
            c.errors.join(" + ")
        ));
    }
    readme.push_str(&format!(
        "# {prefix}.hal holds the pins (loadrt {prefix}, then source or copy the setp lines into the machine's HAL file)\n"
    ));
    let mut files = vec![
        ExportedFile {
            name: format!("{prefix}.hal"),
            text: hal,
        },
        ExportedFile {
            name: format!("{prefix}-README.txt"),
            text: readme,
        },
    ];
    let mut resampling: f64 = 0.0;
    for c in &comps {
        files.push(ExportedFile {
            name: format!("{}.comp", m.variables[c.variable].name),
            text: c.text.clone(),
        });
        resampling = resampling.max(c.resampling);
    }
    let written = Written {
        module: prefix.to_string(),
        parameters,
        notes,
        zero_in_kinematics: false,
        comp: (comps.iter())
            .map(|c| (c.variable, c.nominal.clone(), c.trim.clone()))
            .collect(),
        resampling,
    };
    Ok(tt.finish(files, model, fit, axes, written))
}

/// A rotary joint's COMP_FILE.
struct RotaryComp {
    /// The machine variable.
    variable: usize,
    /// The error parameters or function slots it holds.
    errors: Vec<String>,
    /// Nominal positions (rad).
    nominal: Vec<f64>,
    /// Trims (rad).
    trim: Vec<f64>,
    /// The largest difference, at the midpoints, between the error and
    /// its linear reading (rad).
    resampling: f64,
    /// The file's text.
    text: String,
}

/// The COMP_FILE of rotary variable `v` when its body has a positioning
/// error (an error motion about the joint's own axis): trims `−s·e(q)` in
/// degrees at every 2° of its travel and at its table's positions (`s` the
/// joint axis's sign: the true angle is `q + s·e`), `COMP_FILE_TYPE = 1`,
/// the same trim both directions, the comments below the data (LinuxCNC
/// stops reading at the first line that is not three numbers;
/// `usrmotintf.cc` `usrmotLoadComp`, at most `EMCMOT_COMP_SIZE` = 256
/// lines).
fn rotary_comp<M: ErrorModel + Sync>(
    tt: &TableTable<'_, M>,
    v: usize,
) -> Result<Option<RotaryComp>, ControllerError> {
    let m = tt.machine;
    let body = &m.bodies[m.variables[v].body];
    let Some(joint) = &body.joint else {
        return Ok(None);
    };
    let slot = 3 + joint.axis.axis.index();
    let errors = super::slot_motions(m, &body.errors.slots[slot]);
    if errors.is_empty() {
        return Ok(None);
    }
    let (lo, hi) = tt.travel[v];
    let intervals = ((hi - lo).to_degrees() / ROTARY_STEP_DEG - 1e-9)
        .ceil()
        .max(1.0) as usize;
    let mut nominal: Vec<f64> = (0..=intervals)
        .map(|k| lo + (hi - lo) * k as f64 / intervals as f64)
        .collect();
    for name in &errors {
        for q in tt.built.values().table_positions(name).unwrap_or_default() {
            if q > lo && q < hi && nominal.iter().all(|n| (n - q).abs() > 1e-12) {
                nominal.push(q);
            }
        }
    }
    nominal.sort_by(f64::total_cmp);
    let name = &m.variables[v].name;
    if nominal.len() > LINUXCNC_MAX_POINTS {
        return Err(ControllerError::TooManyPoints {
            controller: "LinuxCNC (EMCMOT_COMP_SIZE)",
            variable: name.clone(),
            lo,
            hi,
            step: ROTARY_STEP_DEG,
            points: nominal.len(),
            limit: LINUXCNC_MAX_POINTS,
            hint: "; the positions of its table and the 2° steps of its travel exceed it: give a shorter travel",
        });
    }
    let sign = joint.axis.sign();
    let base = tt.grid[0].clone();
    let error_at = |x: f64| -> Result<f64, ControllerError> {
        let mut q = base.clone();
        q[v] = x;
        let parts = tt.parts(&q).map_err(|e| ControllerError::OutOfTable {
            variable: name.clone(),
            lo,
            hi,
            source: Box::new(e),
        })?;
        Ok((parts.iter())
            .filter(|p| errors.contains(&p.name))
            .map(|p| p.value)
            .sum())
    };
    let trim: Vec<f64> = (nominal.iter())
        .map(|&x| error_at(x).map(|e| -sign * e))
        .collect::<Result<_, _>>()?;
    let mut resampling: f64 = 0.0;
    for w in nominal.windows(2) {
        let x = 0.5 * (w[0] + w[1]);
        let lin = interpolate_held(&nominal, &trim, x);
        resampling = resampling.max((-sign * error_at(x)? - lin).abs());
    }
    let mut text = String::new();
    for (x, t) in nominal.iter().zip(&trim) {
        let (x, t) = (num(x.to_degrees()), num(t.to_degrees()));
        text.push_str(&format!("{x} {t} {t}\n"));
    }
    let opening = format!(
        "machine `{}`, rotary joint `{name}`: its positioning error {}",
        m.name,
        errors.join(" + ")
    );
    text.push_str(&format!("# {}\n", opening_line(&tt.provenance, &opening)));
    text.push_str("# [JOINT_n] COMP_FILE_TYPE = 1: columns nominal (commanded joint angle) | trim moving + | trim moving -, degrees\n");
    text.push_str(&format!(
        "# trim = {}, e the error about the body's +{} axis (the joint turns about {}{}: the true angle is the reading {} e); LinuxCNC adds the trim to the command\n",
        if sign > 0.0 { "-e" } else { "+e" },
        ['x', 'y', 'z'][joint.axis.axis.index()],
        if sign > 0.0 { "+" } else { "-" },
        ['x', 'y', 'z'][joint.axis.axis.index()],
        if sign > 0.0 { "+" } else { "-" }
    ));
    text.push_str(&format!(
        "# every {ROTARY_STEP_DEG}° of {} to {} and the error's table positions; the same trim both directions; held at the end values outside\n",
        num(lo.to_degrees()),
        num(hi.to_degrees())
    ));
    text.push_str("# these comments must stay below the data: LinuxCNC stops reading at the first line that is not three numbers\n");
    Ok(Some(RotaryComp {
        variable: v,
        errors,
        nominal,
        trim,
        resampling,
        text,
    }))
}

fn param(name: &str, nominal: f64, value: f64, unit: &'static str) -> KinematicsParameter {
    KinematicsParameter {
        name: name.to_string(),
        nominal,
        value,
        unit,
    }
}
