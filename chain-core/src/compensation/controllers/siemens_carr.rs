//! SINUMERIK's swivel data record (`$TC_CARR1`..`$TC_CARR65`, an orientable
//! tool holder) of a table-table machine, kinematic type `P` (five-axis
//! spec, "Output"; docs/export-controllers.md, "siemens-carr"; sources in
//! docs/rotary-controllers-sources.md, section 3).
//!
//! Fields (840D sl Function Manual Tool Offset W1, "Orientable tool
//! holders"; Commissioning Manual IM9, CYCLE800 and 5-axis data): offset
//! vectors `l1` (1-3), `l2` (4-6), `l3` (15-17), `l4` (18-20) in mm, axis
//! vectors `v1` (7-9), `v2` (10-12), kinematic type (23), the rotary axes'
//! offsets (24, 25, degrees). For type `P`: `l2` runs from the machine
//! reference point to a point of the first rotary axis, `l3` from there to
//! the second, `l4 = −(l2 + l3)` closes the chain; rotary axis 2 is carried
//! by rotary axis 1; the angle counts clockwise looking along its vector
//! (right-handed about it); an axis that moves the workpiece has its vector
//! entered reversed. A table point `w₀` (its place at zero angles) is then at
//! `w = l2 + R₁⁻¹·(l3 + R₂⁻¹·(w₀ − l2 − l3))`, `R_k` the rotation by `α_k −
//! off_k` about `v_k` (the offset: "the initial state of the rotary axis is
//! the position specified by the parameter"), so the tool at machine
//! position `J` is at the table's `P = l2 + l3 + R₂·(R₁·(J − l2) − l3)`.
//!
//! The record holds the two axis lines' positions and directions (the
//! tilts, which LinuxCNC's trt modules cannot) and the zeros; an error
//! motion along a rotary axis remains. The vectors are fitted over the grid
//! (`rotary.rs`): the offsets affinely, the axis vectors through their
//! first-order effect; the controller is taken to drive the rotary axes to
//! the angles programmed (their positions pass through the
//! transformation), so a tilt's effect on the tool point is corrected, its
//! effect on the tool's direction is not (reported as orientation left).

use crate::compensation::{opening_line, ExportedFile};
use crate::model_trait::ErrorModel;

use super::rotary::{orientations, rotate, KinematicsParameter, TableTable, TrtModel, Written};
use super::{decimals, num, ControllerError, Export};

/// The record's model with its entered axis vectors' nominal values: pins
/// `[l2 (3), l3 (3), v1 (3), v2 (3)]`.
#[derive(Debug, Clone, Copy)]
struct Record {
    v1: [f64; 3],
    v2: [f64; 3],
}

fn vec3(p: &[f64], at: usize) -> [f64; 3] {
    [p[at], p[at + 1], p[at + 2]]
}

impl TrtModel for Record {
    fn affine(&self) -> usize {
        6
    }

    fn fixed(&self) -> Vec<f64> {
        self.v1.iter().chain(&self.v2).copied().collect()
    }

    fn forward(&self, pins: &[f64], j: [f64; 3], a: f64, c: f64) -> [f64; 3] {
        let (l2, l3, v1, v2) = (vec3(pins, 0), vec3(pins, 3), vec3(pins, 6), vec3(pins, 9));
        let r1 = rotate(v1, a, std::array::from_fn(|i| j[i] - l2[i]));
        let r2 = rotate(v2, c, std::array::from_fn(|i| r1[i] - l3[i]));
        std::array::from_fn(|i| l2[i] + l3[i] + r2[i])
    }

    fn inverse(&self, pins: &[f64], p: [f64; 3], a: f64, c: f64) -> [f64; 3] {
        let (l2, l3, v1, v2) = (vec3(pins, 0), vec3(pins, 3), vec3(pins, 6), vec3(pins, 9));
        let back = rotate(v2, -c, std::array::from_fn(|i| p[i] - l2[i] - l3[i]));
        let inner = rotate(v1, -a, std::array::from_fn(|i| back[i] + l3[i]));
        std::array::from_fn(|i| l2[i] + inner[i])
    }
}

pub(super) fn export<M: ErrorModel + Sync>(
    tt: &TableTable<'_, M>,
) -> Result<Export, ControllerError> {
    let m = tt.machine;
    let axis =
        |k: usize, s: f64| -> [f64; 3] { std::array::from_fn(|i| if i == k { s } else { 0.0 }) };
    let candidates = orientations().map(|[(k1, s1), (k2, s2)]| {
        let (v1, v2) = (axis(k1, s1), axis(k2, s2));
        (Record { v1, v2 }, format!("v1 = {v1:?}, v2 = {v2:?}"))
    });
    let none = "no swivel data record of type P with axis vectors along the machine's axes reproduces its nominal kinematics";
    let (record, mut fit) = tt.fit_first(candidates, &[], none)?;
    // To the nanometre (and 1e-9 of a unit vector): below that a value is
    // the fit's round-off.
    tt.round_pins(&record, &mut fit, 9);
    let var = |i: usize| m.variables[i].name.as_str();
    let letters = ['X', 'Y', 'Z'];
    let axes = tt.axis_names("rotary axis 1", "rotary axis 2");
    let l4 = |p: &[f64]| -> [f64; 3] { std::array::from_fn(|i| -(p[i] + p[3 + i])) };
    let (n4, i4) = (l4(&fit.nominal), l4(&fit.pins));
    let mut parameters = Vec::new();
    let mut fields: Vec<(usize, f64, f64)> = Vec::new(); // ($TC_CARRn, nominal, value)
    for (first, at, what) in [(4, 0, "l2"), (15, 3, "l3"), (7, 6, "v1"), (10, 9, "v2")] {
        for (i, letter) in letters.iter().enumerate() {
            fields.push((first + i, fit.nominal[at + i], fit.pins[at + i]));
            parameters.push(KinematicsParameter {
                name: format!("$TC_CARR{} ({what} {letter})", first + i),
                nominal: fit.nominal[at + i],
                value: fit.pins[at + i],
                unit: if what.starts_with('v') { "1" } else { "mm" },
            });
        }
    }
    for (i, letter) in letters.iter().enumerate() {
        fields.push((18 + i, n4[i], i4[i]));
        parameters.push(KinematicsParameter {
            name: format!("$TC_CARR{} (l4 {letter})", 18 + i),
            nominal: n4[i],
            value: i4[i],
            unit: "mm",
        });
    }
    // R_k turns by α − off: the true angle α + h asks off = −h.
    for (k, n) in [(0, 24), (1, 25)] {
        fields.push((n, 0.0, -fit.zero[k]));
        parameters.push(KinematicsParameter {
            name: format!("$TC_CARR{n} (offset of rotary axis {})", k + 1),
            nominal: 0.0,
            value: -fit.zero[k],
            unit: "deg",
        });
    }
    parameters.extend(fit.work_offset_changes("work offset", "mm (work offset)"));
    fields.sort_by_key(|f| f.0);
    let notes = vec![
        format!(
            "kinematic type P: rotary axis 1 = `{}` carries rotary axis 2 = `{}`; the vectors of axes that move the workpiece are entered reversed (v1 = ({}), v2 = ({}) nominal)",
            var(tt.tilt),
            var(tt.rotary),
            record.v1.map(num).join(", "),
            record.v2.map(num).join(", ")
        ),
        "the machine file's axis variables are the machine coordinates (a `-` turns an axis that moves the workpiece) and its tool point is the tool reference: l2 is measured from the machine file's zero".to_string(),
        "the rotary axes are taken to reach the angles programmed; the tilts' effect on the tool point is corrected, their effect on the tool's direction is reported as orientation left".to_string(),
    ];
    let head = opening_line(
        &tt.provenance,
        &format!("machine `{}`: SINUMERIK swivel data record 1", m.name),
    );
    let mut text = format!("; {head}\n");
    text.push_str("; $TC_CARRn[1]: offset vectors l2 (4-6), l3 (15-17), l4 (18-20) in mm; axis vectors v1 (7-9), v2 (10-12); type (23); rotary axis offsets (24, 25) in degrees\n");
    text.push_str(&format!(
        "; machine axes X = {}, Y = {}, Z = {}; rotary axis 1 = {}, rotary axis 2 = {}\n",
        axes[0].1, axes[1].1, axes[2].1, axes[3].1, axes[4].1
    ));
    for note in &notes {
        text.push_str(&format!("; {note}\n"));
    }
    text.push_str("$TC_CARR23[1]=\"P\"\n");
    for (n, nominal, value) in &fields {
        text.push_str(&format!(
            "$TC_CARR{n}[1]={}    ; nominal {}\n",
            decimals(*value, 9),
            num(*nominal)
        ));
    }
    text.push_str("; the workpiece's zero moves with a location error of an axis that carries it: re-probe the part, or add to its work offset (mm):\n");
    for p in parameters.iter().filter(|p| p.unit.starts_with("mm (")) {
        text.push_str(&format!("; {} = {}\n", p.name, num(p.value)));
    }
    text.push_str("M17\n");
    let files = vec![ExportedFile {
        name: "TC_CARR.SPF".into(),
        text,
    }];
    let written = Written {
        module: "$TC_CARR (type P)".to_string(),
        parameters,
        notes,
        zero_in_kinematics: true,
        comp: Vec::new(),
        resampling: 0.0,
    };
    Ok(tt.finish(files, record, fit, axes, written))
}
