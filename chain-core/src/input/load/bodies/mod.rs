//! The `bodies` section: each body's keys, then the tree checks (parents,
//! cycles, roots), the variables and the error parameters, in the machine's
//! orders. By subject: `joints.rs` (joints, axes, fixed rotations, the
//! variables), `slots.rs` (the error slots: names, `errors: iso` and
//! function slots), `dh.rs` (a `dh` / `mdh` row and its two bodies),
//! `tree.rs` (parents, cycles, roots) and `registry.rs` (the error
//! parameters and function slots in order of first use).

mod dh;
mod joints;
mod registry;
mod slots;
mod tree;

use std::collections::HashMap;

use super::{join, Loader, TreeReader};
use crate::diagnostic::Problem;
use crate::model::{Body, ErrorFunction, ErrorParam, FixedRotation, Joint, Variable};
use crate::yaml::{Node, NodeKind, Span};
use dh::{split_dh, DH_REPLACES};
use joints::RawJoint;
use slots::{Item, JointState, SlotContext, GROUPS, SLOT_KEYS};

/// Keys of a body.
const BODY_KEYS: &[&str] = &[
    "parent",
    "offset",
    "rotation",
    "joint",
    "errors",
    "squareness",
    "location_errors",
    "dh",
    "mdh",
];

/// The checked bodies section.
pub(super) struct Tree {
    /// Every body name, in file order.
    pub all_names: Vec<String>,
    /// True when the whole section is valid; only then are the vectors below
    /// complete and consistent.
    pub ok: bool,
    /// Bodies in pre-order.
    pub bodies: Vec<Body>,
    /// Variables in body order.
    pub variables: Vec<Variable>,
    /// Error parameters in order of first use.
    pub errors: Vec<ErrorParam>,
    /// Function slots in order of first declaration.
    pub functions: Vec<ErrorFunction>,
}

impl Tree {
    /// Index of a body (in pre-order) by name.
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.bodies.iter().position(|b| b.name == name)
    }
}

/// A name as used somewhere, with its location.
#[derive(Clone)]
struct Use {
    name: String,
    span: Span,
    path: String,
}

enum Parent {
    /// No `parent` key: a root.
    Root,
    /// A parent by name.
    Named(Use),
    /// Invalid (already reported): neither a root nor placed in the tree.
    Bad,
}

/// A body's offset as written.
enum Offset<'n> {
    /// `offset: [x, y, z]` (absent: the origin).
    Written(Option<&'n Node>),
    /// From a DH row: `a` along x and `d` along z, each with its key path
    /// (absent: 0).
    Dh {
        a: Option<(&'n Node, String)>,
        d: Option<(&'n Node, String)>,
    },
}

struct RawBody<'n> {
    name: String,
    /// For the extra frame of a `dh` / `mdh` row: the row's body.
    generated_for: Option<String>,
    span: Span,
    path: String,
    parent: Parent,
    offset: Offset<'n>,
    rotation: Vec<FixedRotation>,
    joint: Option<RawJoint>,
    /// Items per group (0: location_errors, 1: errors, 2: squareness) and slot.
    slots: [[Vec<Item>; 6]; 3],
}

impl Loader {
    /// The `bodies` section. `None` if it is not a non-empty mapping (then
    /// nothing can be checked against body names).
    pub(super) fn bodies_section(&mut self, key: &Node, value: &Node) -> Option<Tree> {
        let errors_before = self.errors.len();
        let entries = self.entries(value, "bodies")?;
        if entries.is_empty() {
            self.report(key.span, "bodies", Problem::NoBodies);
            return None;
        }
        let mut raws = Vec::new();
        for (k, v) in entries {
            let name = k.as_str().unwrap_or("").to_string();
            let path = join("bodies", &name);
            if name.is_empty() {
                self.report(
                    k.span,
                    path,
                    Problem::WrongType {
                        expected: "a body name",
                        found: k.describe(),
                    },
                );
                continue;
            }
            raws.extend(self.body(k, v, name, path));
        }
        self.generated_clashes(&raws);
        let all_names: Vec<String> = raws.iter().map(|r| r.name.clone()).collect();

        // Offsets need every parameter and (for hints) every variable.
        let offsets: Vec<Option<[crate::model::Expr; 3]>> = raws
            .iter()
            .map(|r| match &r.offset {
                Offset::Written(node) => self.vec3(*node, &join(&r.path, "offset")),
                Offset::Dh { a, d } => {
                    let mut part = |v: &Option<(&Node, String)>| match v {
                        Some((node, path)) => self.expr(node, path),
                        None => Some(crate::model::Expr::Num(0.0)),
                    };
                    let (x, z) = (part(a), part(d));
                    Some([x?, crate::model::Expr::Num(0.0), z?])
                }
            })
            .collect();

        let (parents, order) = self.tree(&raws, key.span);
        let (variables, var_of_body) = self.variables(&raws, &order);
        let (errors, functions, slots) = self.errors(&raws, &order, &variables, &var_of_body);

        let mut position = vec![usize::MAX; raws.len()];
        for (new, &old) in order.iter().enumerate() {
            if let Some(p) = position.get_mut(old) {
                *p = new;
            }
        }
        let mut bodies = Vec::with_capacity(raws.len());
        let mut complete = true;
        for &old in &order {
            let (Some(raw), Some(offset)) = (raws.get(old), offsets.get(old).cloned().flatten())
            else {
                complete = false;
                continue;
            };
            let parent = parents
                .get(old)
                .copied()
                .flatten()
                .and_then(|p| position.get(p).copied());
            let joint = match (&raw.joint, var_of_body.get(old).copied().flatten()) {
                (None, _) => None,
                (Some(j), Some(variable)) => match (j.kind, j.axis) {
                    (Some(kind), Some(axis)) => Some(Joint {
                        kind,
                        axis,
                        variable,
                        origin: j.span.origin(j.path.clone()),
                    }),
                    _ => {
                        complete = false;
                        None
                    }
                },
                (Some(_), None) => {
                    complete = false;
                    None
                }
            };
            let (location_errors, errors) = slots.get(old).cloned().unwrap_or_default();
            bodies.push(Body {
                name: raw.name.clone(),
                parent,
                offset,
                rotation: raw.rotation.clone(),
                location_errors,
                joint,
                errors,
                origin: raw.span.origin(raw.path.clone()),
            });
        }
        Some(Tree {
            all_names,
            ok: complete && self.errors.len() == errors_before,
            bodies,
            variables,
            errors,
            functions,
        })
    }

    /// One body's keys: the body, or the two a `dh` / `mdh` row stands
    /// for.
    fn body<'n>(
        &mut self,
        key: &Node,
        value: &'n Node,
        name: String,
        path: String,
    ) -> Vec<RawBody<'n>> {
        let mut raw = RawBody {
            name,
            generated_for: None,
            span: key.span,
            path: path.clone(),
            parent: Parent::Bad,
            offset: Offset::Written(None),
            rotation: Vec::new(),
            joint: None,
            slots: Default::default(),
        };
        let Some(f) = self.fields(value, key.span, &path, BODY_KEYS) else {
            return vec![raw];
        };
        raw.parent = match f.get("parent") {
            // A misspelt `parent` key: neither a root nor placed.
            None if f.suggested.contains(&"parent") => Parent::Bad,
            None => Parent::Root,
            Some(n) => match self.name(n, &f.path("parent"), "a body name") {
                Some(name) => Parent::Named(Use {
                    name,
                    span: n.span,
                    path: f.path("parent"),
                }),
                None => Parent::Bad,
            },
        };
        // Names under misspelt keys are not reported again elsewhere.
        for (_, node) in &f.unknown {
            self.note_all_names(node);
        }
        let dh = match (f.entry("dh"), f.entry("mdh")) {
            (Some((_, first)), Some((k, second))) => {
                let problem = Problem::Conflict {
                    first: "dh",
                    second: "mdh",
                };
                self.report(k.span, f.path("mdh"), problem);
                // Neither row is read: their names are not reported again
                // (by `statistics` or a `grid`).
                self.note_all_names(first);
                self.note_all_names(second);
                None
            }
            (Some((k, v)), None) => Some((k, v, false)),
            (None, Some((k, v))) => Some((k, v, true)),
            (None, None) => None,
        };
        let dh = match dh {
            Some((k, v, modified)) => {
                let form = if modified { "mdh" } else { "dh" };
                for &other in DH_REPLACES {
                    if let Some((ok, refused)) = f.entry(other) {
                        let problem = Problem::Conflict {
                            first: form,
                            second: other,
                        };
                        self.report(ok.span, f.path(other), problem);
                        self.note_all_names(refused);
                    }
                }
                let (row, joint) = self.dh_row(k, v, &f.path(form), modified, &raw.name);
                raw.joint = joint;
                row
            }
            None => {
                raw.offset = Offset::Written(f.get("offset"));
                if let Some(n) = f.get("rotation") {
                    raw.rotation = self.rotations(n, &f.path("rotation"));
                }
                if let Some((k, v)) = f.entry("joint") {
                    raw.joint = Some(self.joint(k, v, &f.path("joint")));
                }
                None
            }
        };
        // A misspelt `joint` key is reported once, not again by every
        // function slot or `iso` that needs the joint.
        let joint = match &raw.joint {
            Some(j) => JointState::Present(j.kind),
            None if f.suggested.contains(&"joint") => JointState::Misspelt,
            None => JointState::Absent,
        };
        for (g, (group, allowed)) in GROUPS.iter().enumerate() {
            let Some((k, v)) = f.entry(group) else {
                continue;
            };
            if g == 0 && dh.is_some() {
                // Refused beside the DH row above.
                continue;
            }
            let gpath = f.path(group);
            if let Some(text) = v.as_str() {
                self.group_scalar(&mut raw, g, v, text, &gpath, joint);
                continue;
            }
            let Some(sf) = self.fields(v, k.span, &gpath, allowed) else {
                continue;
            };
            for (slot, _, node) in &sf.known {
                let Some(s) = SLOT_KEYS.iter().position(|k| k == slot) else {
                    continue;
                };
                let ctx = SlotContext {
                    group: g,
                    label: group,
                    body: &raw.name,
                    joint,
                };
                let items = self.slot_items(node, &sf.path(slot), &ctx);
                if let Some(list) = raw.slots.get_mut(g).and_then(|gr| gr.get_mut(s)) {
                    list.extend(items);
                }
            }
            for (_, node) in &sf.unknown {
                self.note_error_names(node);
            }
        }
        match dh {
            Some(row) => split_dh(raw, row),
            None => vec![raw],
        }
    }

    /// Reports a declared body whose name is one a `dh` / `mdh` row gives
    /// its extra frame (`NAME.joint`, `NAME.link`).
    fn generated_clashes(&mut self, raws: &[RawBody<'_>]) {
        let generated: HashMap<&str, &str> = raws
            .iter()
            .filter_map(|r| Some((r.name.as_str(), r.generated_for.as_deref()?)))
            .collect();
        for raw in raws.iter().filter(|r| r.generated_for.is_none()) {
            if let Some(owner) = generated.get(raw.name.as_str()) {
                let problem = Problem::GeneratedBodyName {
                    name: raw.name.clone(),
                    body: (*owner).to_string(),
                };
                self.report(raw.span, raw.path.clone(), problem);
            }
        }
    }

    /// Remembers the error names written in a node, valid or not, so that
    /// later checks do not report them again.
    fn note_error_names(&mut self, node: &Node) {
        if let Some(s) = node.as_str() {
            self.seen_errors.insert(s.to_string());
        }
        for item in node.as_sequence().unwrap_or(&[]) {
            if let Some(s) = item.as_str() {
                self.seen_errors.insert(s.to_string());
            }
        }
    }

    /// Remembers every scalar under `node` as a possible error or variable
    /// name (for values under misspelt keys).
    fn note_all_names(&mut self, node: &Node) {
        match &node.kind {
            NodeKind::Scalar(s) => {
                self.seen_errors.insert(s.text.clone());
                self.seen_variables.insert(s.text.clone());
            }
            NodeKind::Sequence(items) => items.iter().for_each(|n| self.note_all_names(n)),
            NodeKind::Mapping(entries) => entries.iter().for_each(|(_, v)| self.note_all_names(v)),
        }
    }
}
