//! FANUC tool centre point control (G43.4 / G43.5), table rotation type:
//! the parameters that place the two rotary table axes (five-axis spec,
//! "Output"; docs/export-controllers.md, "fanuc-tcp"; sources in
//! docs/rotary-controllers-sources.md, section 5).
//!
//! Parameters (FANUC Series 30i-MODEL A, *Tool center point control for
//! 5-axis machining*, A-79348E, pp. 72-84): 19680 the mechanical unit type
//! (12: two table rotation axes, the first the master carrying the second);
//! 19682 / 19687 the direction of the first / second rotation axis (1 = X,
//! 2 = Y, 3 = Z); 19684 / 19689 its rotation direction (0: right-handed
//! about the axis's positive direction, 1: left-handed; "normally 1 for a
//! table rotation axis"); 19700-19702 the rotary table position, a vector
//! from the machine coordinate system's origin to a point of the first
//! rotation axis with both axes at 0°; 19703-19705 the intersection offset
//! vector from that point to a point of the second rotation axis. Lengths
//! in mm (machine unit), angles in degrees.
//!
//! The model: a table point `w₀` (its place at zero angles) is at `w = T +
//! R₁(a)·(o + R₂(c)·(w₀ − T − o))`, `R_k` the table's rotation about axis
//! `k` in the sense of its 19684 / 19689, so the tool at machine position
//! `J` is at the table's `P = T + o + R₂(c)⁻¹·(R₁(a)⁻¹·(J − T) − o)`. The
//! point of each axis is free along it; chain writes the foot of the two
//! axes' common perpendicular on the first (so `o` is that perpendicular,
//! zero when the axes intersect), which makes the four numbers the axis
//! lines' positions.
//!
//! The directions are codes: an axis tilt cannot be held and remains, as
//! does an error motion along a rotary axis; the zero errors of the rotary
//! axes go to their reference positions, outside the TCP parameters.

use crate::compensation::{opening_line, ExportedFile};
use crate::model_trait::ErrorModel;

use super::rotary::{
    changes_text, orientations, rotate, KinematicsParameter, TableTable, TrtModel, Written,
};
use super::{decimals, num, ControllerError, Export};

/// The table rotation type's model: the first (master) axis along frame
/// axis `first.0`, the second along `second.0`, each with its rotation
/// direction (`+1`: 19684 = 0, right-handed; `−1`: 1, left-handed). Pins
/// `[T (3), o along first × second]`.
#[derive(Debug, Clone, Copy)]
struct TableType {
    first: (usize, f64),
    second: (usize, f64),
}

fn unit(k: usize) -> [f64; 3] {
    std::array::from_fn(|i| if i == k { 1.0 } else { 0.0 })
}

impl TableType {
    /// `T` and `o` of pins.
    fn vectors(&self, pins: &[f64]) -> ([f64; 3], [f64; 3]) {
        let (a, b) = (unit(self.first.0), unit(self.second.0));
        let n = [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ];
        ([pins[0], pins[1], pins[2]], n.map(|x| x * pins[3]))
    }

    /// The table's rotation about axis `(k, s)` by `deg`, applied to `x`
    /// (`inverse`: its inverse).
    fn turn(axis: (usize, f64), deg: f64, x: [f64; 3], inverse: bool) -> [f64; 3] {
        let sense = if inverse { -axis.1 } else { axis.1 };
        rotate(unit(axis.0), sense * deg, x)
    }
}

impl TrtModel for TableType {
    fn affine(&self) -> usize {
        4
    }

    fn forward(&self, pins: &[f64], j: [f64; 3], a: f64, c: f64) -> [f64; 3] {
        let (t, o) = self.vectors(pins);
        let inner = Self::turn(self.first, a, std::array::from_fn(|i| j[i] - t[i]), true);
        let outer = Self::turn(
            self.second,
            c,
            std::array::from_fn(|i| inner[i] - o[i]),
            true,
        );
        std::array::from_fn(|i| t[i] + o[i] + outer[i])
    }

    fn inverse(&self, pins: &[f64], p: [f64; 3], a: f64, c: f64) -> [f64; 3] {
        let (t, o) = self.vectors(pins);
        let inner = Self::turn(
            self.second,
            c,
            std::array::from_fn(|i| p[i] - t[i] - o[i]),
            false,
        );
        let outer = Self::turn(
            self.first,
            a,
            std::array::from_fn(|i| inner[i] + o[i]),
            false,
        );
        std::array::from_fn(|i| t[i] + outer[i])
    }
}

/// 19682 / 19687's code of frame axis `k`.
fn code(k: usize) -> u8 {
    k as u8 + 1
}

/// 19684 / 19689's value of a rotation direction.
fn direction(s: f64) -> u8 {
    u8::from(s < 0.0)
}

/// The decimals written: the IS-C increment (0.0001 mm) of a real
/// parameter in machine units (A-79348E, 19703: "the minimum unit depends on
/// the increment system").
const PLACES: usize = 4;

pub(super) fn export<M: ErrorModel + Sync>(
    tt: &TableTable<'_, M>,
) -> Result<Export, ControllerError> {
    let m = tt.machine;
    let candidates = orientations().map(|[first, second]| {
        let label = format!(
            "19682 = {}, 19684 = {}, 19687 = {}, 19689 = {}",
            code(first.0),
            direction(first.1),
            code(second.0),
            direction(second.1)
        );
        (TableType { first, second }, label)
    });
    let none = "no table rotation type (19680 = 12) with its axes along the machine's axes reproduces its nominal kinematics";
    let (model, mut fit) = tt.fit_first(candidates, &[], none)?;
    let rounding = tt.round_pins(&model, &mut fit, PLACES as i32);
    let var = |i: usize| m.variables[i].name.as_str();
    let letters = ['X', 'Y', 'Z'];
    let axes = tt.axis_names("first rotation axis", "second rotation axis");
    let (nt, no) = model.vectors(&fit.nominal);
    let (it, io) = model.vectors(&fit.pins);
    let mut parameters = Vec::new();
    let mut reals: Vec<(u32, f64, f64)> = Vec::new(); // (number, nominal, value)
    for (first, (n, v), what) in [
        (19700, (nt, it), "rotary table position"),
        (19703, (no, io), "intersection offset vector"),
    ] {
        for (i, letter) in letters.iter().enumerate() {
            reals.push((first + i as u32, n[i] + 0.0, v[i] + 0.0));
            parameters.push(KinematicsParameter {
                name: format!("{} ({what} {letter})", first + i as u32),
                nominal: n[i] + 0.0,
                value: v[i] + 0.0,
                unit: "mm",
            });
        }
    }
    parameters.extend(fit.zero_changes(
        ["first", "second"].map(|a| format!("reference position of the {a} rotation axis: change")),
        "deg",
    ));
    parameters.extend(fit.work_offset_changes("work offset", "mm (work offset)"));
    let bytes = [
        (19680u32, 12u8, "mechanical unit type: table rotation type"),
        (
            19682,
            code(model.first.0),
            "axis direction of the first rotation axis (1 = X, 2 = Y, 3 = Z)",
        ),
        (
            19684,
            direction(model.first.1),
            "rotation direction of the first rotation axis (0: right-handed, 1: left-handed)",
        ),
        (
            19687,
            code(model.second.0),
            "axis direction of the second rotation axis",
        ),
        (
            19689,
            direction(model.second.1),
            "rotation direction of the second rotation axis",
        ),
    ];
    let notes = vec![
        format!(
            "table rotation type: the first rotation axis `{}` (master) carries the second `{}`; 19681 / 19686 (their controlled-axis numbers) are the machine's own",
            var(tt.tilt),
            var(tt.rotary)
        ),
        "the machine file's axis variables are the machine coordinates (a `-` turns an axis that moves the workpiece) and its zero is the machine coordinate system's origin".to_string(),
        "the axis directions are codes: an axis tilt cannot be held and remains, with its tool-point effect in the report".to_string(),
        format!(
            "the positions are written to 0.0001 mm (the IS-C increment; round them to 0.001 mm for an IS-B machine): that moves the tool point by at most {:.4} µm over the grid",
            rounding * 1e3
        ),
        "the rotary axes' zero errors are not TCP parameters: shift each axis's reference position by its change (true angle = reading before + change) with the machine's reference-position setting".to_string(),
    ];
    let head = opening_line(
        &tt.provenance,
        &format!(
            "machine `{}`: FANUC tool centre point control, table rotation type",
            m.name
        ),
    );
    let mut text = String::from("%\n");
    for (n, v, _) in &bytes {
        text.push_str(&format!("N{n}Q1L1P{v}\n"));
    }
    for (n, _, v) in &reals {
        text.push_str(&format!("N{n}Q1L1P{}\n", decimals(*v, PLACES)));
    }
    text.push_str("%\n");
    let mut readme = format!("{head}\n\n");
    readme.push_str("TCP.PRM holds these parameters of path 1 in the reader/puncher interface's parameter format (N number, Q1 parameter data, L1 path, P value; reals in mm with a decimal point): compare it with the machine's own parameter output before reading it in, or key the values in on the parameter screen:\n");
    for (n, v, what) in &bytes {
        readme.push_str(&format!("{n} = {v}    {what}\n"));
    }
    for p in parameters.iter().filter(|p| p.unit == "mm") {
        readme.push_str(&format!(
            "{} = {} mm    nominal {}\n",
            p.name,
            decimals(p.value, PLACES),
            num(p.nominal)
        ));
    }
    readme.push_str(&format!(
        "\nmachine axes X = {}, Y = {}, Z = {}; first rotation axis = {}, second rotation axis = {}\n",
        axes[0].1, axes[1].1, axes[2].1, axes[3].1, axes[4].1
    ));
    for note in &notes {
        readme.push_str(&format!("- {note}\n"));
    }
    readme.push_str(&changes_text(
        &parameters,
        "deg",
        "The rotary axes' reference positions (degrees)",
        "The workpiece's zero moves with a location error of an axis that carries it: re-probe the part, or add to its work offset (mm)",
    ));
    let files = vec![
        ExportedFile {
            name: "TCP.PRM".into(),
            text,
        },
        ExportedFile {
            name: "TCP-README.txt".into(),
            text: readme,
        },
    ];
    let written = Written {
        module: "tool centre point control, table rotation type (19680 = 12)".to_string(),
        parameters,
        notes,
        zero_in_kinematics: false,
        comp: Vec::new(),
        resampling: 0.0,
    };
    Ok(tt.finish(files, model, fit, axes, written))
}
