//! HEIDENHAIN TNC kinematics description: the `Trans` rows that place the
//! rotary axes of a table-table machine, as KinematicsOpt's cycle 451 MEASURE
//! KINEMATICS adapts them (five-axis spec, "Output";
//! docs/export-controllers.md, "heidenhain"; sources in
//! docs/rotary-controllers-sources.md, section 2).
//!
//! A kinematics description is a chain of rows `KEY AXIS COORD`: `MachAxis`
//! where a machine axis acts, `Trans` a translation (mm) along or a rotation
//! (degrees) about X, Y, Z as A, B, C (iTNC 530 HSCI Technical Manual,
//! "description table"). chain writes the workpiece side of a table-table
//! machine in the layout the Technical Manual recommends for errors that
//! are "always defined before the affected axis" and undone after it
//! (KinematicsComp's chain): per rotary axis its two position rows (`Y0A`,
//! `Z0A` of an A axis, `X0C`, `Y0C` of a C axis: a point of the axis line
//! in machine coordinates at zero angles), with `--angles` its two angle
//! rows (`B0A`, `C0A`; `A0C`, `B0C`: the axis line turned about the two
//! other axes, degrees), the `MachAxis` row, and the same rows negated in
//! reverse order. The position rows are what cycle 451 optimises; the angle
//! rows are what its newer modes and KinematicsComp hold.
//!
//! The model: the table turns by the axis angle about the line through
//! `p_k` along `v_k` (the nominal direction turned by the angle rows) in
//! the sense the nominal kinematics show, so the tool at machine position
//! `J` is at the table's `P = p₂ + R₂⁻¹·(R₁⁻¹·(J − p₁) + p₁ − p₂)`. An
//! error motion along a rotary axis remains (a compensation table of the
//! axis, not the kinematics description); without `--angles` so do the
//! tilts. The zero errors go to the rotary axes' offsets, outside the
//! description.

use crate::compensation::{opening_line, ExportedFile};
use crate::model_trait::ErrorModel;

use super::rotary::{
    changes_text, orientations, rotate, KinematicsParameter, TableTable, TrtModel, Written,
};
use super::{decimals, num, ControllerError, Export};

/// Frame axis letters of a translation and of a rotation.
const LINEAR: [char; 3] = ['X', 'Y', 'Z'];
const ANGULAR: [char; 3] = ['A', 'B', 'C'];

/// The description's model: the tilting axis along frame axis `first.0`,
/// the rotary table along `second.0`, each turning the table in the sense
/// `.1` (+1 right-handed about the axis); pins `[p₁ ⊥ (2), p₂ ⊥ (2)]` and,
/// with `angles`, `[v₁'s two angles, v₂'s two angles]` (degrees).
#[derive(Debug, Clone, Copy)]
struct Description {
    first: (usize, f64),
    second: (usize, f64),
    angles: bool,
}

fn unit(k: usize) -> [f64; 3] {
    std::array::from_fn(|i| if i == k { 1.0 } else { 0.0 })
}

/// The two frame axes across axis `k`, in cyclic order.
fn across(k: usize) -> [usize; 2] {
    [(k + 1) % 3, (k + 2) % 3]
}

impl Description {
    /// Axis `which`'s point (at zero angles, machine coordinates) and
    /// direction.
    fn line(&self, pins: &[f64], which: usize) -> ([f64; 3], [f64; 3]) {
        let k = [self.first.0, self.second.0][which];
        let [u, w] = across(k);
        let mut p = [0.0; 3];
        p[u] = pins[2 * which];
        p[w] = pins[2 * which + 1];
        let mut v = unit(k);
        if self.angles {
            // The rows' order: Trans <u> θ₁, Trans <w> θ₂, MachAxis: the
            // axis is turned about w first, then about u.
            v = rotate(unit(w), pins[4 + 2 * which + 1], v);
            v = rotate(unit(u), pins[4 + 2 * which], v);
        }
        (p, v)
    }

    /// The table's rotation about axis `which` by `deg` applied to `x`
    /// about the line's direction (`inverse`: its inverse).
    fn turn(&self, pins: &[f64], which: usize, deg: f64, x: [f64; 3], inverse: bool) -> [f64; 3] {
        let s = [self.first.1, self.second.1][which];
        let (_, v) = self.line(pins, which);
        rotate(v, if inverse { -s * deg } else { s * deg }, x)
    }
}

impl TrtModel for Description {
    fn affine(&self) -> usize {
        4
    }

    fn fixed(&self) -> Vec<f64> {
        if self.angles {
            vec![0.0; 4]
        } else {
            Vec::new()
        }
    }

    fn forward(&self, pins: &[f64], j: [f64; 3], a: f64, c: f64) -> [f64; 3] {
        let ((p1, _), (p2, _)) = (self.line(pins, 0), self.line(pins, 1));
        let inner = self.turn(pins, 0, a, std::array::from_fn(|i| j[i] - p1[i]), true);
        let outer = self.turn(
            pins,
            1,
            c,
            std::array::from_fn(|i| inner[i] + p1[i] - p2[i]),
            true,
        );
        std::array::from_fn(|i| p2[i] + outer[i])
    }

    fn inverse(&self, pins: &[f64], p: [f64; 3], a: f64, c: f64) -> [f64; 3] {
        let ((p1, _), (p2, _)) = (self.line(pins, 0), self.line(pins, 1));
        let inner = self.turn(pins, 1, c, std::array::from_fn(|i| p[i] - p2[i]), false);
        let outer = self.turn(
            pins,
            0,
            a,
            std::array::from_fn(|i| inner[i] + p2[i] - p1[i]),
            false,
        );
        std::array::from_fn(|i| p1[i] + outer[i])
    }
}

/// One row of the description: key, axis, value (nominal, identified) and
/// its ISO 230-1 name.
struct Row {
    key: &'static str,
    axis: char,
    value: Option<(f64, f64)>,
    doc: String,
}

/// The decimals of a `COORD` written (mm and degrees).
const PLACES: usize = 6;

pub(super) fn export<M: ErrorModel + Sync>(
    tt: &TableTable<'_, M>,
    angles: bool,
) -> Result<Export, ControllerError> {
    let m = tt.machine;
    let candidates = orientations().map(|[first, second]| {
        let label = format!(
            "{} turning the table {}, {} turning it {}",
            ANGULAR[first.0],
            sense(first.1),
            ANGULAR[second.0],
            sense(second.1)
        );
        let model = Description {
            first,
            second,
            angles,
        };
        (model, label)
    });
    let none = "no description with a tilting axis about X or Y carrying a rotary table about Z reproduces its nominal kinematics";
    let (model, mut fit) = tt.fit_first(candidates, &[], none)?;
    let rounding = tt.round_pins(&model, &mut fit, PLACES as i32);
    let var = |i: usize| m.variables[i].name.as_str();
    let names = [
        ANGULAR[model.first.0].to_string(),
        ANGULAR[model.second.0].to_string(),
    ];
    let axes = tt.axis_names(&names[0], &names[1]);
    let mut rows: Vec<Row> = Vec::new();
    let mut parameters = Vec::new();
    for (which, axis) in [model.first.0, model.second.0].into_iter().enumerate() {
        let letter = ANGULAR[axis];
        let [u, w] = across(axis);
        let mut before: Vec<Row> = Vec::new();
        for (r, k) in [u, w].into_iter().enumerate() {
            let pair = (fit.nominal[2 * which + r], fit.pins[2 * which + r]);
            before.push(Row {
                key: "Trans",
                axis: LINEAR[k],
                value: Some(pair),
                doc: format!("{}0{letter}", LINEAR[k]),
            });
        }
        if angles {
            for (r, k) in [u, w].into_iter().enumerate() {
                let pair = (fit.nominal[4 + 2 * which + r], fit.pins[4 + 2 * which + r]);
                before.push(Row {
                    key: "Trans",
                    axis: ANGULAR[k],
                    value: Some(pair),
                    doc: format!("{}0{letter}", ANGULAR[k]),
                });
            }
        }
        for row in &before {
            let (nominal, value) = row.value.unwrap_or_default();
            parameters.push(KinematicsParameter {
                name: format!("{} (Trans {})", row.doc, row.axis),
                nominal,
                value,
                unit: if ANGULAR.contains(&row.axis) {
                    "deg"
                } else {
                    "mm"
                },
            });
        }
        let after: Vec<Row> = (before.iter().rev())
            .map(|r| Row {
                key: r.key,
                axis: r.axis,
                value: r.value.map(|(n, v)| (-n, -v)),
                doc: format!("-{}", r.doc),
            })
            .collect();
        rows.extend(before);
        rows.push(Row {
            key: "MachAxis",
            axis: letter,
            value: None,
            doc: String::new(),
        });
        rows.extend(after);
    }
    parameters.extend(fit.zero_changes(
        names.clone().map(|n| format!("{n} axis offset change")),
        "deg (axis offset)",
    ));
    parameters.extend(fit.work_offset_changes("preset", "mm (preset)"));
    let mut notes = vec![
        format!(
            "the workpiece side of the description: {} = `{}` (turning the table {} about +{}) carries {} = `{}` (turning it {} about +{}); the rows follow the machine's linear axes and end at the workpiece",
            names[0],
            var(tt.tilt),
            sense(model.first.1),
            LINEAR[model.first.0],
            names[1],
            var(tt.rotary),
            sense(model.second.1),
            LINEAR[model.second.0]
        ),
        "a position row is a point of the axis line in machine coordinates at zero angles, measured from the machine file's zero; the chain's inverse rows after each MachAxis undo it (the Technical Manual's KinematicsComp layout): carry the values into the machine's own description where its rows differ".to_string(),
    ];
    notes.push(if angles {
        "the angle rows hold each axis line's tilt (degrees), so the tilts' tool-point effect is corrected; their effect on the tool's direction is reported as orientation left".to_string()
    } else {
        "the position rows only, as cycle 451 optimises them: an axis tilt remains, with its tool-point effect in the report (the export writes the angle rows too when asked for them)".to_string()
    });
    notes.push(format!(
        "COORD to 6 decimals (mm, degrees): that moves the tool point by at most {:.4} µm over the grid",
        rounding * 1e3
    ));
    notes.push("the rotary axes' zero errors are not rows of the description: add each change to the axis's offset (true angle = reading before + change)".to_string());
    let head = opening_line(
        &tt.provenance,
        &format!(
            "machine `{}`: HEIDENHAIN kinematics description, the rotary axes' rows",
            m.name
        ),
    );
    let cells: Vec<[String; 5]> = (rows.iter().enumerate())
        .map(|(nr, row)| {
            let (coord, doc) = match row.value {
                Some((n, v)) => (
                    decimals(v, PLACES),
                    format!("{} (nominal {})", row.doc, num(n)),
                ),
                None => (String::new(), String::new()),
            };
            [
                nr.to_string(),
                row.key.to_string(),
                row.axis.to_string(),
                coord,
                doc,
            ]
        })
        .collect();
    let text = tnc_table(
        "KINEMATICS_ROTARY.TAB",
        ["NR", "KEY", "AXIS", "COORD", "DOC"],
        &cells,
    );
    let mut readme = format!("{head}\n\n");
    readme.push_str("KINEMATICS_ROTARY.TAB: the workpiece side of the kinematics description (COORD identified, the machine file's nominal in DOC; mm and degrees; a TNC table: BEGIN line, fixed columns set by the header, [END])\n");
    readme.push_str(&format!(
        "machine axes X = {}, Y = {}, Z = {}, {} = {}, {} = {}\n",
        axes[0].1, axes[1].1, axes[2].1, axes[3].0, axes[3].1, axes[4].0, axes[4].1
    ));
    for note in &notes {
        readme.push_str(&format!("- {note}\n"));
    }
    readme.push_str(&changes_text(
        &parameters,
        "deg (axis offset)",
        "The rotary axes' offsets (degrees)",
        "The workpiece's zero moves with a location error of an axis that carries it: probe the preset again, or add to it (mm)",
    ));
    let files = vec![
        ExportedFile {
            name: "KINEMATICS_ROTARY.TAB".into(),
            text,
        },
        ExportedFile {
            name: "KINEMATICS_ROTARY-README.txt".into(),
            text: readme,
        },
    ];
    let written = Written {
        module: "kinematics description (Trans rows of the rotary axes)".to_string(),
        parameters,
        notes,
        zero_in_kinematics: false,
        comp: Vec::new(),
        resampling: 0.0,
    };
    Ok(tt.finish(files, model, fit, axes, written))
}

/// A turning sense in words.
fn sense(s: f64) -> &'static str {
    if s > 0.0 {
        "right-handed"
    } else {
        "left-handed"
    }
}

/// A TNC table: its `BEGIN NAME MM` line, the header and the rows in fixed
/// columns (each header name padded to its column's width), `[END]`.
pub(crate) fn tnc_table<const C: usize>(
    name: &str,
    header: [&str; C],
    rows: &[[String; C]],
) -> String {
    let width: Vec<usize> = (0..C)
        .map(|c| {
            rows.iter()
                .map(|r| r[c].len())
                .fold(header[c].len(), usize::max)
                + 2
        })
        .collect();
    let line = |r: [&str; C]| -> String {
        let mut l: String = (0..C)
            .map(|c| format!("{:<w$}", r[c], w = width[c]))
            .collect();
        l.truncate(l.trim_end().len());
        l + "\n"
    };
    let mut text = format!("BEGIN {name} MM\n");
    text.push_str(&line(header));
    for r in rows {
        text.push_str(&line(std::array::from_fn(|c| r[c].as_str())));
    }
    text.push_str("[END]\n");
    text
}
