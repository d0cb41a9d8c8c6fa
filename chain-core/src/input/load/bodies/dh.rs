//! A `dh` / `mdh` row (docs/yaml.md, "Denavit–Hartenberg bodies"): its
//! parameters, joint and errors as read, and the two ordinary bodies it
//! stands for.

use super::joints::{RawJoint, JOINT_TYPES};
use super::slots::{Item, JointState, SlotContext};
use super::{Offset, Parent, RawBody, Use};
use crate::input::load::{Loader, TreeReader};
use crate::model::{Axis, FixedRotation, JointKind, SignedAxis};
use crate::yaml::Node;

/// Keys of a `dh` / `mdh` row (docs/yaml.md, "Denavit–Hartenberg bodies").
const DH_KEYS: &[&str] = &["theta", "d", "a", "alpha", "joint", "variable", "errors"];

/// Keys of a `dh` / `mdh` row's `errors`: one error per DH parameter, and
/// `beta`, Hayati's rotation about the link frame's y axis (the parameter a
/// DH table lacks for nearly parallel consecutive axes).
const DH_ERROR_KEYS: &[&str] = &["theta", "d", "a", "alpha", "beta"];

/// The body keys a `dh` / `mdh` row replaces (it gives the body's offset,
/// rotation, joint and location errors).
pub(super) const DH_REPLACES: &[&str] = &["offset", "rotation", "joint", "location_errors"];

/// A `dh` / `mdh` row as read (docs/yaml.md, "Denavit–Hartenberg bodies").
pub(super) struct RawDh<'n> {
    /// `mdh` (Craig's modified convention) rather than `dh`.
    modified: bool,
    /// `theta` as a rotation about z (`None` when 0 or invalid).
    theta: Option<FixedRotation>,
    /// `alpha` as a rotation about x (`None` when 0 or invalid).
    alpha: Option<FixedRotation>,
    /// `a`, with its key path.
    a: Option<(&'n Node, String)>,
    /// `d`, with its key path.
    d: Option<(&'n Node, String)>,
    /// The errors of `theta`, `d`, `a`, `alpha`, `beta` (in
    /// [`DH_ERROR_KEYS`] order).
    errors: [Vec<Item>; 5],
}

impl Loader {
    /// A `dh` / `mdh` row: its four parameters, its joint (`joint:
    /// rotary | prismatic` with `variable`, along +z; none for a fixed row)
    /// and the errors of its parameters.
    pub(super) fn dh_row<'n>(
        &mut self,
        key: &Node,
        value: &'n Node,
        path: &str,
        modified: bool,
        body: &str,
    ) -> (Option<RawDh<'n>>, Option<RawJoint>) {
        let Some(f) = self.fields(value, key.span, path, DH_KEYS) else {
            return (None, None);
        };
        for (_, node) in &f.unknown {
            self.note_all_names(node);
        }
        let rotation = |l: &mut Self, name: &'static str, about: Axis| {
            let node = l.required(&f, name)?;
            let p = f.path(name);
            let angle = l.angle(node, &p)?;
            (angle != 0.0).then(|| FixedRotation {
                about,
                angle,
                origin: node.span.origin(p),
            })
        };
        let theta = rotation(self, "theta", Axis::Z);
        let alpha = rotation(self, "alpha", Axis::X);
        let a = self.required(&f, "a").map(|n| (n, f.path("a")));
        let d = self.required(&f, "d").map(|n| (n, f.path("d")));
        let joint = match (f.entry("joint"), f.get("variable")) {
            (None, None) => None,
            (None, Some(variable)) => {
                self.missing(&f, "joint");
                self.note_all_names(variable);
                None
            }
            (Some((k, n)), variable) => {
                let kind = match self.keyword(n, &f.path("joint"), "joint type", JOINT_TYPES) {
                    Some("prismatic") => Some(JointKind::Prismatic),
                    Some(_) => Some(JointKind::Rotary),
                    None => None,
                };
                let mut j = RawJoint {
                    kind,
                    axis: Some(SignedAxis {
                        axis: Axis::Z,
                        negative: false,
                    }),
                    variable: None,
                    variable_text: None,
                    span: k.span,
                    path: f.path("joint"),
                };
                self.joint_variable(&f, variable, &mut j);
                Some(j)
            }
        };
        let mut errors: [Vec<Item>; 5] = Default::default();
        if let Some((k, v)) = f.entry("errors") {
            let epath = f.path("errors");
            if let Some(ef) = self.fields(v, k.span, &epath, DH_ERROR_KEYS) {
                let ctx = SlotContext {
                    group: 0,
                    label: if modified { "mdh.errors" } else { "dh.errors" },
                    body,
                    joint: JointState::Absent,
                };
                for (param, _, node) in &ef.known {
                    let items = self.slot_items(node, &ef.path(param), &ctx);
                    if let Some(i) = DH_ERROR_KEYS.iter().position(|k| k == param) {
                        if let Some(list) = errors.get_mut(i) {
                            list.extend(items);
                        }
                    }
                }
                for (_, node) in &ef.unknown {
                    self.note_error_names(node);
                }
            }
        }
        let row = RawDh {
            modified,
            theta,
            alpha,
            a,
            d,
            errors,
        };
        (Some(row), joint)
    }
}

/// The two bodies a `dh` / `mdh` row stands for (docs/yaml.md,
/// "Denavit–Hartenberg bodies"), each an ordinary body of the machine
/// format, `T = Trans(offset)·Rot(rotation)·E(location_errors)·J(q)·E(errors)`:
///
/// - `dh` (standard, `Rot_z(θ+q)·Trans_z(d)·Trans_x(a)·Rot_x(α)`):
///   `NAME.joint` = `Rot_z(θ)·E(dz: Δd, ez: Δθ)·J(q about/along +z)·E(errors)`
///   under the declared parent, then `NAME` = `Trans(a, 0, d)·Rot_x(α)·E(dx: Δa,
///   ex: Δα)·E(ey: β)`;
/// - `mdh` (Craig's modified, `Rot_x(α)·Trans_x(a)·Rot_z(θ+q)·Trans_z(d)`):
///   `NAME.link` = `Trans(a, 0, 0)·Rot_x(α)·E(dx: Δa, ex: Δα)·E(ey: β)` under
///   the declared parent, then `NAME` = `Trans(0, 0, d)·Rot_z(θ)·E(dz: Δd, ez:
///   Δθ)·J(q)·E(errors)`.
///
/// Translations along and rotations about one axis commute, so each DH
/// parameter's error is exactly a location error slot. β, Hayati's
/// `Rot_y(β)` after `Rot_x(α + Δα)`, is the `ey` slot of the link body's
/// `errors` (after its location errors; the body has no joint), so that the
/// product is exactly `Rot_x(α + Δα)·Rot_y(β)`: in the location slots
/// beside `ex: Δα` it would be the one rotation `exp(Δα·x + β·y)`. The
/// row's body keeps its name for the frame the DH convention calls frame
/// i, so children, the tool and the workpiece attach where a DH table puts
/// them.
pub(super) fn split_dh<'n>(raw: RawBody<'n>, row: RawDh<'n>) -> Vec<RawBody<'n>> {
    let [theta_e, d_e, a_e, alpha_e, beta_e] = row.errors;
    let link = |name: String, parent: Parent, generated_for: Option<String>| RawBody {
        name,
        generated_for,
        span: raw.span,
        path: raw.path.clone(),
        parent,
        offset: Offset::Dh { a: None, d: None },
        rotation: Vec::new(),
        joint: None,
        slots: Default::default(),
    };
    let (suffix, first_is_joint) = if row.modified {
        (".link", false)
    } else {
        (".joint", true)
    };
    let extra = format!("{}{suffix}", raw.name);
    let mut first = link(extra.clone(), raw.parent, Some(raw.name.clone()));
    let second_parent = Parent::Named(Use {
        name: extra,
        span: raw.span,
        path: raw.path.clone(),
    });
    let mut second = link(raw.name, second_parent, None);
    let (joint_body, link_body) = if first_is_joint {
        (&mut first, &mut second)
    } else {
        (&mut second, &mut first)
    };
    // The joint's body: θ, d's error, the joint and its motion errors.
    joint_body.rotation.extend(row.theta);
    joint_body.joint = raw.joint;
    // `location_errors` beside a DH row was refused and not read.
    let [_, errors, squareness] = raw.slots;
    joint_body.slots[1] = errors;
    joint_body.slots[2] = squareness;
    joint_body.slots[0][2] = d_e;
    joint_body.slots[0][5] = theta_e;
    // The link's body: a, α, their errors and β.
    link_body.rotation.extend(row.alpha);
    link_body.slots[0][0] = a_e;
    link_body.slots[0][3] = alpha_e;
    link_body.slots[1][4] = beta_e;
    // d goes where the convention puts it: on the link in `dh` (after the
    // joint), on the joint's body in `mdh` (before it, after α).
    if row.modified {
        link_body.offset = Offset::Dh { a: row.a, d: None };
        joint_body.offset = Offset::Dh { a: None, d: row.d };
    } else {
        link_body.offset = Offset::Dh { a: row.a, d: row.d };
    }
    vec![first, second]
}
