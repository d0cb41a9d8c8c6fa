//! Joints (`type`, `axis`, `variable`), signed axes, fixed rotations and
//! angles, and the axis variables of the machine in body order.

use std::collections::HashMap;

use super::{RawBody, Use};
use crate::diagnostic::Problem;
use crate::input::load::{index, Loader, TreeReader};
use crate::model::{Axis, FixedRotation, JointKind, SignedAxis, Variable};
use crate::yaml::{Node, Span};

/// Keys of a joint.
const JOINT_KEYS: &[&str] = &["type", "axis", "variable"];

/// Keys of a fixed rotation.
const ROTATION_KEYS: &[&str] = &["about", "angle"];

/// Joint types.
pub(super) const JOINT_TYPES: &[&str] = &["prismatic", "rotary"];

/// Signed axes.
const SIGNED_AXES: &[&str] = &["+x", "-x", "+y", "-y", "+z", "-z"];

/// Unsigned axes.
const AXES: &[&str] = &["x", "y", "z"];

pub(super) struct RawJoint {
    pub(super) kind: Option<JointKind>,
    pub(super) axis: Option<SignedAxis>,
    pub(super) variable: Option<Use>,
    /// The variable as written, valid or not (for `errors: iso`).
    pub(super) variable_text: Option<String>,
    pub(super) span: Span,
    pub(super) path: String,
}

impl Loader {
    /// `joint: {type, axis, variable}`.
    pub(super) fn joint(&mut self, key: &Node, value: &Node, path: &str) -> RawJoint {
        let mut j = RawJoint {
            kind: None,
            axis: None,
            variable: None,
            variable_text: None,
            span: key.span,
            path: path.to_string(),
        };
        let Some(f) = self.fields(value, key.span, path, JOINT_KEYS) else {
            return j;
        };
        for (_, node) in &f.unknown {
            self.note_all_names(node);
        }
        match f.get("type") {
            Some(n) => {
                j.kind = match self.keyword(n, &f.path("type"), "joint type", JOINT_TYPES) {
                    Some("prismatic") => Some(JointKind::Prismatic),
                    Some(_) => Some(JointKind::Rotary),
                    None => None,
                }
            }
            None => self.missing(&f, "type"),
        }
        match f.get("axis") {
            Some(n) => j.axis = self.signed_axis(n, &f.path("axis")),
            None => self.missing(&f, "axis"),
        }
        self.joint_variable(&f, f.get("variable"), &mut j);
        j
    }

    /// A joint's `variable` entry `n` of the fields `f` (a missing one
    /// refused at `f`): the name noted as seen and kept for messages, and
    /// its use. The one rule of a joint and a DH row's joint.
    pub(super) fn joint_variable(
        &mut self,
        f: &crate::input::load::reader::Fields<'_>,
        n: Option<&Node>,
        j: &mut RawJoint,
    ) {
        match n {
            Some(n) => {
                if let Some(s) = n.as_str() {
                    self.seen_variables.insert(s.to_string());
                    j.variable_text = Some(s.to_string());
                }
                let p = f.path("variable");
                j.variable = self.ident(n, &p, "variable").map(|name| Use {
                    name,
                    span: n.span,
                    path: p,
                });
            }
            None => self.missing(f, "variable"),
        }
    }

    /// `+x` … `-z`.
    fn signed_axis(&mut self, node: &Node, path: &str) -> Option<SignedAxis> {
        let text = self.name(node, path, "an axis")?;
        let axis = |c: &str| match c {
            "x" => Some(Axis::X),
            "y" => Some(Axis::Y),
            "z" => Some(Axis::Z),
            _ => None,
        };
        let parsed = match text.split_at_checked(1) {
            Some(("+", a)) => axis(a).map(|axis| SignedAxis {
                axis,
                negative: false,
            }),
            Some(("-", a)) => axis(a).map(|axis| SignedAxis {
                axis,
                negative: true,
            }),
            _ => None,
        };
        if parsed.is_none() {
            // Only suggest a fix for a missing sign or a wrong case.
            let bare = text.trim_start_matches(['+', '-']).to_lowercase();
            let sign = if text.starts_with('-') { "-" } else { "+" };
            let suggestion = axis(&bare).map(|_| format!("{sign}{bare}"));
            self.report(
                node.span,
                path,
                Problem::UnknownValue {
                    what: "axis",
                    found: text,
                    expected: SIGNED_AXES,
                    suggestion,
                },
            );
        }
        parsed
    }

    /// `rotation`: a list of `{about, angle}` (a single mapping is a list of
    /// one).
    pub(super) fn rotations(&mut self, node: &Node, path: &str) -> Vec<FixedRotation> {
        let items: Vec<(&Node, String)> = match (node.as_sequence(), node.as_mapping()) {
            (Some(items), _) => items
                .iter()
                .enumerate()
                .map(|(i, n)| (n, index(path, i)))
                .collect(),
            (None, Some(_)) => vec![(node, path.to_string())],
            (None, None) => {
                self.report(
                    node.span,
                    path,
                    Problem::WrongType {
                        expected: "a list of rotations `{about: x|y|z, angle: …}`",
                        found: node.describe(),
                    },
                );
                return Vec::new();
            }
        };
        let mut out = Vec::new();
        for (item, ipath) in items {
            let Some(f) = self.fields(item, item.span, &ipath, ROTATION_KEYS) else {
                continue;
            };
            let about = match f.get("about") {
                Some(n) => match self.keyword(n, &f.path("about"), "axis", AXES) {
                    Some("x") => Some(Axis::X),
                    Some("y") => Some(Axis::Y),
                    Some(_) => Some(Axis::Z),
                    None => None,
                },
                None => {
                    self.missing(&f, "about");
                    None
                }
            };
            let angle = match f.get("angle") {
                Some(n) => self.angle(n, &f.path("angle")),
                None => {
                    self.missing(&f, "angle");
                    None
                }
            };
            if let (Some(about), Some(angle)) = (about, angle) {
                out.push(FixedRotation {
                    about,
                    angle,
                    origin: item.span.origin(ipath),
                });
            }
        }
        out
    }

    /// An angle: radians (a number or arithmetic, `pi` allowed) or `<n>deg`.
    pub(super) fn angle(&mut self, node: &Node, path: &str) -> Option<f64> {
        let degrees = node
            .as_str()
            .and_then(|t| t.trim_end().strip_suffix("deg"))
            .map(str::to_string);
        let v = match degrees {
            Some(prefix) => self.number_in(node, &prefix, path)?.to_radians(),
            None => self.number(node, path)?,
        };
        if v.is_finite() {
            Some(v)
        } else {
            self.report(node.span, path, Problem::NotFinite { what: "an angle" });
            None
        }
    }

    /// Variables in body order; each body's variable index (file indices).
    pub(super) fn variables(
        &mut self,
        raws: &[RawBody<'_>],
        order: &[usize],
    ) -> (Vec<Variable>, Vec<Option<usize>>) {
        // Duplicates and collisions in file order, so the later one is blamed.
        let mut owner: HashMap<&str, &str> = HashMap::new();
        let mut usable = vec![false; raws.len()];
        for (i, raw) in raws.iter().enumerate() {
            let Some(u) = raw.joint.as_ref().and_then(|j| j.variable.as_ref()) else {
                continue;
            };
            if let Some(body) = owner.get(u.name.as_str()) {
                self.report(
                    u.span,
                    u.path.clone(),
                    Problem::DuplicateVariable {
                        name: u.name.clone(),
                        body: body.to_string(),
                    },
                );
                continue;
            }
            owner.insert(&u.name, &raw.name);
            if self.parameter_index.contains_key(&u.name) {
                self.report(
                    u.span,
                    u.path.clone(),
                    Problem::NameCollision {
                        name: u.name.clone(),
                        what: "variable",
                        other: "parameter",
                    },
                );
            }
            usable[i] = true;
        }
        let mut variables = Vec::new();
        let mut of_body = vec![None; raws.len()];
        for (new, &old) in order.iter().enumerate() {
            let Some(raw) = raws.get(old) else { continue };
            let Some(j) = &raw.joint else { continue };
            let (Some(u), Some(kind)) = (&j.variable, j.kind) else {
                continue;
            };
            if !usable.get(old).copied().unwrap_or(false) {
                continue;
            }
            if let Some(slot) = of_body.get_mut(old) {
                *slot = Some(variables.len());
            }
            variables.push(Variable {
                name: u.name.clone(),
                kind,
                body: new,
                origin: u.span.origin(u.path.clone()),
            });
        }
        (variables, of_body)
    }
}
