//! The `bodies` section: each body's keys, then the tree checks (parents,
//! cycles, roots), the variables and the error parameters, in the machine's
//! orders.

use std::collections::{HashMap, HashSet};

use super::{index, join, Fields, Loader, TreeReader, MAX_ORDER};
use crate::diagnostic::{closest, Message, Problem};
use crate::model::{
    Axis, Basis, Body, ErrorFunction, ErrorKind, ErrorParam, ErrorSlots, FixedRotation, Joint,
    JointKind, SignedAxis, Slot, Variable,
};
use crate::yaml::{Node, NodeKind, Span};

/// Keys of a body.
pub const BODY_KEYS: &[&str] = &[
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
/// Keys of a `dh` / `mdh` row (docs/yaml.md, "Denavit–Hartenberg bodies").
pub const DH_KEYS: &[&str] = &["theta", "d", "a", "alpha", "joint", "variable", "errors"];
/// Keys of a `dh` / `mdh` row's `errors`: one error per DH parameter, and
/// `beta`, Hayati's rotation about the link frame's y axis (the parameter a
/// DH table lacks for nearly parallel consecutive axes).
pub const DH_ERROR_KEYS: &[&str] = &["theta", "d", "a", "alpha", "beta"];
/// The body keys a `dh` / `mdh` row replaces (it gives the body's offset,
/// rotation, joint and location errors).
const DH_REPLACES: &[&str] = &["offset", "rotation", "joint", "location_errors"];
/// Keys of a joint.
pub const JOINT_KEYS: &[&str] = &["type", "axis", "variable"];
/// Keys of a fixed rotation.
pub const ROTATION_KEYS: &[&str] = &["about", "angle"];
/// Slots of `errors` and `location_errors`.
pub const SLOT_KEYS: &[&str] = &["dx", "dy", "dz", "ex", "ey", "ez"];
/// Slots of `squareness`.
pub const SQUARENESS_KEYS: &[&str] = &["ex", "ey", "ez"];
/// Keys of a function slot (measured-machines spec, section 1).
pub const FUNCTION_KEYS: &[&str] = &[
    "name",
    "powers",
    "basis",
    "degree",
    "range",
    "from",
    "harmonics",
];
/// Values of a function slot's `basis` (the power basis is `powers: [..]`).
pub const BASES: &[&str] = &["legendre", "chebyshev", "fourier"];
/// The ISO 230-1 letters of the six slots under `errors: iso`: `dx: EXV`,
/// `dy: EYV`, `dz: EZV`, `ex: EAV`, `ey: EBV`, `ez: ECV`.
pub const ISO_LETTERS: [char; 6] = ['X', 'Y', 'Z', 'A', 'B', 'C'];
/// Joint types.
pub const JOINT_TYPES: &[&str] = &["prismatic", "rotary"];
/// Signed axes.
pub const SIGNED_AXES: &[&str] = &["+x", "-x", "+y", "-y", "+z", "-z"];
/// Unsigned axes.
pub const AXES: &[&str] = &["x", "y", "z"];

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

/// A function slot as declared: its name and (valid) basis.
#[derive(Clone)]
struct RawFunction {
    /// The `name` value, located at it (key path `….name`).
    name: Use,
    /// The basis.
    basis: Basis,
}

/// One entry of a slot.
#[derive(Clone)]
enum Item {
    /// A constant error parameter by name.
    Name(Use),
    /// One of the six names of `errors: iso`.
    Iso(Use),
    /// A function of the body's joint variable.
    Function(RawFunction),
}

struct RawJoint {
    kind: Option<JointKind>,
    axis: Option<SignedAxis>,
    variable: Option<Use>,
    /// The variable as written, valid or not (for `errors: iso`).
    variable_text: Option<String>,
    span: Span,
    path: String,
}

/// What a body's slots know of its joint.
#[derive(Clone, Copy)]
enum JointState {
    /// A `joint` key (its kind, if valid).
    Present(Option<JointKind>),
    /// No `joint`, but a misspelt key that looked like it (reported there).
    Misspelt,
    /// No `joint`.
    Absent,
}

/// Where a slot is, for the checks of its items.
struct SlotContext<'a> {
    /// 0: location_errors (and a DH row's errors), 1: errors, 2: squareness.
    group: usize,
    /// The group's key as written, for messages.
    label: &'static str,
    /// The body's name.
    body: &'a str,
    /// The body's joint.
    joint: JointState,
}

impl SlotContext<'_> {
    /// What an item of this slot may be.
    fn expected(&self) -> &'static str {
        if self.group == 1 {
            "an error name, a function `{name: …, powers | basis: …}` or a list of them"
        } else {
            "an error name or a list of error names"
        }
    }
}

/// The name `errors: iso` gives slot letter `letter` (`X`..`C`) of a joint
/// driven by `variable`: `E` + letter + the variable upper-cased (`EXX`,
/// `EAX`; a multi-letter variable `x2` gives `EXX2`).
pub fn iso_name(letter: char, variable: &str) -> String {
    format!("E{letter}{}", variable.to_uppercase())
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

/// A `dh` / `mdh` row as read (docs/yaml.md, "Denavit–Hartenberg bodies").
struct RawDh<'n> {
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

/// Slot groups in the order errors are numbered within a body.
const GROUPS: [(&str, &[&str]); 3] = [
    ("location_errors", SLOT_KEYS),
    ("errors", SLOT_KEYS),
    ("squareness", SQUARENESS_KEYS),
];

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

    /// A `dh` / `mdh` row: its four parameters, its joint (`joint:
    /// rotary | prismatic` with `variable`, along +z; none for a fixed row)
    /// and the errors of its parameters.
    fn dh_row<'n>(
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
                match variable {
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
                    None => self.missing(&f, "variable"),
                }
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

    /// A group whose value is a scalar: `errors: iso`, or a mistake.
    fn group_scalar(
        &mut self,
        raw: &mut RawBody<'_>,
        g: usize,
        node: &Node,
        text: &str,
        path: &str,
        joint: JointState,
    ) {
        let group = GROUPS.get(g).map_or("errors", |(name, _)| *name);
        if g != 1 {
            if text == "iso" {
                self.report(node.span, path, Problem::IsoNotAllowed { group });
            } else {
                self.wrong_type(node, path, "a mapping");
            }
            return;
        }
        if text != "iso" {
            let suggestion = closest(text, ["iso"]).map(str::to_string);
            let found = text.to_string();
            self.report(node.span, path, Problem::ErrorsScalar { found, suggestion });
            return;
        }
        let variable = raw.joint.as_ref().and_then(|j| j.variable_text.clone());
        match joint {
            JointState::Absent => {
                let body = raw.name.clone();
                self.report(node.span, path, Problem::IsoWithoutJoint { body });
                return;
            }
            JointState::Misspelt => return,
            JointState::Present(_) => {}
        }
        let Some(variable) = variable else {
            // The joint's variable is missing (reported there).
            return;
        };
        let valid = raw.joint.as_ref().is_some_and(|j| j.variable.is_some());
        for (s, names) in raw.slots.get_mut(1).into_iter().flatten().enumerate() {
            let Some(letter) = ISO_LETTERS.get(s) else {
                continue;
            };
            let name = iso_name(*letter, &variable);
            self.seen_errors.insert(name.clone());
            if valid {
                names.push(Item::Iso(Use {
                    name,
                    span: node.span,
                    path: path.to_string(),
                }));
            }
        }
    }

    /// The items of one slot: a name, a function mapping, or a list of them.
    fn slot_items(&mut self, node: &Node, path: &str, ctx: &SlotContext<'_>) -> Vec<Item> {
        self.note_error_names(node);
        if let Some(items) = node.as_sequence() {
            let mut out = Vec::new();
            for (i, item) in items.iter().enumerate() {
                let p = index(path, i);
                if item.as_sequence().is_some() {
                    self.wrong_type(item, &p, ctx.expected());
                    continue;
                }
                out.extend(self.slot_item(item, &p, ctx));
            }
            return out;
        }
        self.slot_item(node, path, ctx).into_iter().collect()
    }

    /// One item of a slot: a name or (in `errors`) a function mapping.
    fn slot_item(&mut self, node: &Node, path: &str, ctx: &SlotContext<'_>) -> Option<Item> {
        if node.as_scalar().is_some() {
            let name = self.ident(node, path, "error")?;
            return Some(Item::Name(Use {
                name,
                span: node.span,
                path: path.to_string(),
            }));
        }
        if node.as_mapping().is_none() {
            self.wrong_type(node, path, ctx.expected());
            return None;
        }
        let refused = |l: &mut Loader, problem: Option<Problem>| {
            l.note_function_name(node);
            if let Some(p) = problem {
                l.report(node.span, path, p);
            }
            None
        };
        if ctx.group != 1 {
            let group = ctx.label;
            return refused(self, Some(Problem::FunctionNotAllowed { group }));
        }
        let kind = match ctx.joint {
            JointState::Present(kind) => kind,
            JointState::Misspelt => return refused(self, None),
            JointState::Absent => {
                let body = ctx.body.to_string();
                return refused(self, Some(Problem::FunctionWithoutJoint { body }));
            }
        };
        let function = self.function(node, path, kind, ctx.body);
        if function.is_none() {
            self.note_function_name(node);
        }
        function.map(Item::Function)
    }

    /// Remembers the `name` of a refused function mapping, so that
    /// statistics on it or its coefficients are not reported again.
    fn note_function_name(&mut self, node: &Node) {
        for (k, v) in node.as_mapping().unwrap_or(&[]) {
            if let (Some("name"), Some(name)) = (k.as_str(), v.as_str()) {
                self.failed_functions.insert(name.to_string());
            }
        }
    }

    /// A function slot `{name, powers | basis, ...}` (measured-machines
    /// spec, section 1); `kind` is the body's joint kind, if valid.
    fn function(
        &mut self,
        node: &Node,
        path: &str,
        kind: Option<JointKind>,
        body: &str,
    ) -> Option<RawFunction> {
        let before = self.errors.len();
        let f = self.fields(node, node.span, path, FUNCTION_KEYS)?;
        let name = match f.get("name") {
            Some(n) => {
                let p = f.path("name");
                self.ident(n, &p, "function").map(|name| Use {
                    name,
                    span: n.span,
                    path: p,
                })
            }
            None => {
                self.missing(&f, "name");
                None
            }
        };
        let basis = match (f.entry("powers"), f.entry("basis")) {
            (Some(_), Some((k, _))) => {
                let problem = Problem::Conflict {
                    first: "powers",
                    second: "basis",
                };
                self.report(k.span, f.path("basis"), problem);
                None
            }
            (Some((_, p)), None) => {
                self.not_for_basis(&f, "powers", &["degree", "range", "from", "harmonics"]);
                self.powers(p, &f.path("powers"))
                    .map(|powers| Basis::Powers { powers })
            }
            (None, Some((_, b))) => self.named_basis(&f, b, kind, body),
            (None, None) => {
                if !f.suggested.contains(&"powers") && !f.suggested.contains(&"basis") {
                    self.report(node.span, path, Problem::MissingBasis);
                }
                None
            }
        };
        if self.errors.len() != before {
            return None;
        }
        Some(RawFunction {
            name: name?,
            basis: basis?,
        })
    }

    /// `basis: legendre | chebyshev | fourier` and its keys.
    fn named_basis(
        &mut self,
        f: &Fields<'_>,
        node: &Node,
        kind: Option<JointKind>,
        body: &str,
    ) -> Option<Basis> {
        let path = f.path("basis");
        let text = self.name(node, &path, "a basis name")?;
        if text == "powers" {
            let message = Message::new(
                "unknown basis `powers`",
                "unknown value",
                "chain::unknown_value",
            )
            .help("the power basis is written `powers: [1, 2]`, without `basis`");
            self.report(node.span, path, message.into());
            return None;
        }
        match self.choice(node, &path, text, "basis", BASES)? {
            "fourier" => {
                self.not_for_basis(f, "fourier", &["degree", "range", "from"]);
                if kind == Some(JointKind::Prismatic) {
                    let body = body.to_string();
                    self.report(node.span, path, Problem::FourierOnPrismatic { body });
                }
                let harmonics = self.required_order(f, "harmonics", "the harmonic count");
                Some(Basis::Fourier {
                    harmonics: harmonics?,
                })
            }
            basis => {
                self.not_for_basis(f, basis, &["harmonics"]);
                let degree = self.required_order(f, "degree", "the degree");
                let range = self.basis_range(f, basis);
                let from = match f.get("from") {
                    Some(n) => {
                        let p = f.path("from");
                        let from = self.order(n, &p, "`from`")?;
                        if let Some(degree) = degree.filter(|&d| from > d) {
                            self.report(n.span, p, Problem::FromAboveDegree { from, degree });
                            return None;
                        }
                        from
                    }
                    None => 0,
                };
                let (degree, range) = (degree?, range?);
                Some(if basis == "legendre" {
                    Basis::Legendre {
                        degree,
                        range,
                        from,
                    }
                } else {
                    Basis::Chebyshev {
                        degree,
                        range,
                        from,
                    }
                })
            }
        }
    }

    /// Reports each of `keys` present in `f` as not applying to `basis`.
    fn not_for_basis(&mut self, f: &Fields<'_>, basis: &'static str, keys: &[&'static str]) {
        for &key in keys {
            if let Some((k, _)) = f.entry(key) {
                self.report(k.span, f.path(key), Problem::KeyNotForBasis { key, basis });
            }
        }
    }

    /// `range: [lo, hi]`, finite, `lo < hi`.
    fn basis_range(&mut self, f: &Fields<'_>, basis: &'static str) -> Option<[f64; 2]> {
        let Some(node) = f.get("range") else {
            if !f.suggested.contains(&"range") {
                self.report(f.owner, f.path.clone(), Problem::MissingRange { basis });
            }
            return None;
        };
        let path = f.path("range");
        let [a, b] = self.items(node, &path, "a range `[lo, hi]`")?;
        let lo = self.finite(a, &index(&path, 0), "a range end");
        let hi = self.finite(b, &index(&path, 1), "a range end");
        let (lo, hi) = (lo?, hi?);
        if lo >= hi {
            self.report(node.span, path, Problem::RangeOrder { lo, hi });
            return None;
        }
        Some([lo, hi])
    }

    /// `powers: [k, ...]`: non-empty, distinct orders.
    fn powers(&mut self, node: &Node, path: &str) -> Option<Vec<u32>> {
        let Some(items) = node.as_sequence() else {
            self.wrong_type(node, path, "a list of powers");
            return None;
        };
        if items.is_empty() {
            let what = "the power list";
            self.report(node.span, path, Problem::EmptyList { what });
            return None;
        }
        // (power, item index) of each valid item.
        let mut seen: Vec<(u32, usize)> = Vec::with_capacity(items.len());
        let mut complete = true;
        for (i, item) in items.iter().enumerate() {
            let p = index(path, i);
            let Some(k) = self.order(item, &p, "a power") else {
                complete = false;
                continue;
            };
            if let Some(&(_, first)) = seen.iter().find(|(power, _)| *power == k) {
                self.report(item.span, p, Problem::DuplicatePower { power: k, first });
                complete = false;
            } else {
                seen.push((k, i));
            }
        }
        let powers = seen.into_iter().map(|(k, _)| k).collect();
        complete.then_some(powers)
    }

    /// A required order (`degree`, `harmonics`).
    fn required_order(
        &mut self,
        f: &Fields<'_>,
        key: &'static str,
        what: &'static str,
    ) -> Option<u32> {
        let node = self.required(f, key)?;
        self.order(node, &f.path(key), what)
    }

    /// A whole number from 0 to [`MAX_ORDER`].
    fn order(&mut self, node: &Node, path: &str, what: &'static str) -> Option<u32> {
        let value = self.number(node, path)?;
        if value.fract() == 0.0 && (0.0..=f64::from(MAX_ORDER)).contains(&value) {
            // Exact: a whole number from 0 to 12.
            return Some(value as u32);
        }
        self.report(node.span, path, Problem::BadOrder { what, value });
        None
    }

    /// `joint: {type, axis, variable}`.
    fn joint(&mut self, key: &Node, value: &Node, path: &str) -> RawJoint {
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
        match f.get("variable") {
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
            None => self.missing(&f, "variable"),
        }
        j
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
    fn rotations(&mut self, node: &Node, path: &str) -> Vec<FixedRotation> {
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
    fn angle(&mut self, node: &Node, path: &str) -> Option<f64> {
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

    /// Parents, cycles and roots; returns each body's parent (file indices)
    /// and the body order (pre-order if the tree is valid, file order
    /// otherwise).
    fn tree(&mut self, raws: &[RawBody<'_>], bodies_key: Span) -> (Vec<Option<usize>>, Vec<usize>) {
        let n = raws.len();
        let by_name: HashMap<&str, usize> = raws
            .iter()
            .enumerate()
            .map(|(i, r)| (r.name.as_str(), i))
            .collect();
        let mut parents = vec![None; n];
        let mut detached = vec![false; n];
        let mut roots = Vec::new();
        for (i, raw) in raws.iter().enumerate() {
            match &raw.parent {
                Parent::Root => roots.push(i),
                Parent::Bad => detached[i] = true,
                Parent::Named(u) => match by_name.get(u.name.as_str()) {
                    Some(&p) => parents[i] = Some(p),
                    None => {
                        detached[i] = true;
                        let suggestion = closest(&u.name, raws.iter().map(|r| r.name.as_str()))
                            .map(str::to_string);
                        self.report(
                            u.span,
                            u.path.clone(),
                            Problem::UnknownBody {
                                role: "parent",
                                name: u.name.clone(),
                                suggestion,
                            },
                        );
                    }
                },
            }
        }

        // Cycles: follow parent links; 1 = on the current walk, 2 = reaches a
        // root or a detached body, 3 = in or below a cycle.
        let mut state = vec![0u8; n];
        let mut cycles = 0;
        for start in 0..n {
            let mut walk = Vec::new();
            let mut j = Some(start);
            while let Some(k) = j {
                if state.get(k).copied() != Some(0) {
                    break;
                }
                state[k] = 1;
                walk.push(k);
                j = parents.get(k).copied().flatten();
            }
            let fate = match j {
                None => 2,
                Some(k) if state.get(k).copied() == Some(1) => {
                    let pos = walk.iter().position(|&w| w == k).unwrap_or(0);
                    let cycle = walk.get(pos..).unwrap_or(&[]);
                    // Start the message at the cycle's first body in the file.
                    let first = cycle.iter().copied().min().unwrap_or(k);
                    let mut names = Vec::new();
                    let mut c = first;
                    for _ in 0..=cycle.len() {
                        names.push(raws.get(c).map(|r| r.name.clone()).unwrap_or_default());
                        c = parents.get(c).copied().flatten().unwrap_or(first);
                    }
                    if let Some(r) = raws.get(first) {
                        self.report(r.span, r.path.clone(), Problem::Cycle { bodies: names });
                    }
                    cycles += 1;
                    3
                }
                Some(k) => state.get(k).copied().unwrap_or(3),
            };
            for k in walk {
                state[k] = fate;
            }
        }

        if let Some((&first, others)) = roots.split_first() {
            for &other in others {
                if let (Some(f), Some(o)) = (raws.get(first), raws.get(other)) {
                    self.report(
                        o.span,
                        o.path.clone(),
                        Problem::SecondRoot {
                            first: f.name.clone(),
                            second: o.name.clone(),
                        },
                    );
                }
            }
        } else if cycles == 0 && !detached.contains(&true) {
            self.report(bodies_key, "bodies", Problem::NoRoot);
        }

        let valid = roots.len() == 1 && cycles == 0 && !detached.contains(&true);
        let order = match roots.first() {
            Some(&root) if valid => {
                let mut children = vec![Vec::new(); n];
                for (i, p) in parents.iter().enumerate() {
                    if let Some(c) = p.and_then(|p| children.get_mut(p)) {
                        c.push(i);
                    }
                }
                let mut order = Vec::with_capacity(n);
                let mut stack = vec![root];
                while let Some(b) = stack.pop() {
                    order.push(b);
                    if let Some(c) = children.get(b) {
                        stack.extend(c.iter().rev());
                    }
                }
                order
            }
            _ => (0..n).collect(),
        };
        (parents, order)
    }

    /// Variables in body order; each body's variable index (file indices).
    fn variables(
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

    /// Error parameters in order of first use, the function slots in order
    /// of first declaration, and each body's slots (`location_errors`,
    /// `errors` + `squareness`), by file index.
    fn errors(
        &mut self,
        raws: &[RawBody<'_>],
        order: &[usize],
        variables: &[Variable],
        var_of_body: &[Option<usize>],
    ) -> (
        Vec<ErrorParam>,
        Vec<ErrorFunction>,
        Vec<(ErrorSlots, ErrorSlots)>,
    ) {
        let mut r = Registry {
            variable_names: raws
                .iter()
                .filter_map(|r| r.joint.as_ref()?.variable.as_ref().map(|u| u.name.clone()))
                .collect(),
            variables,
            ..Registry::default()
        };
        let mut slots = vec![(ErrorSlots::default(), ErrorSlots::default()); raws.len()];
        for &old in order {
            let Some(raw) = raws.get(old) else { continue };
            let variable = var_of_body.get(old).copied().flatten();
            for (g, group) in raw.slots.iter().enumerate() {
                for (s, items) in group.iter().enumerate() {
                    let Some(&slot) = Slot::ALL.get(s) else {
                        continue;
                    };
                    let kind = if g == 2 {
                        ErrorKind::Squareness
                    } else if slot.is_linear() {
                        ErrorKind::Linear
                    } else {
                        ErrorKind::Angular
                    };
                    let mut indices = Vec::new();
                    for item in items {
                        match item {
                            Item::Name(u) => indices.extend(self.error_use(u, kind, &mut r)),
                            Item::Iso(u) => {
                                if let Some(other) = r.iso_owner.get(&u.name) {
                                    if *other != raw.name {
                                        let problem = Problem::IsoClash {
                                            name: u.name.clone(),
                                            body: raw.name.clone(),
                                            other: other.clone(),
                                        };
                                        self.report(u.span, u.path.clone(), problem);
                                        continue;
                                    }
                                }
                                r.iso_owner.insert(u.name.clone(), raw.name.clone());
                                indices.extend(self.error_use(u, kind, &mut r));
                            }
                            Item::Function(f) => {
                                // Without a valid variable the joint was
                                // reported already.
                                if let Some(v) = variable {
                                    indices.extend(self.function_use(f, kind, v, &mut r));
                                }
                            }
                        }
                    }
                    let Some((loc, err)) = slots.get_mut(old) else {
                        continue;
                    };
                    let target = if g == 0 { loc } else { err };
                    if let Some(list) = target.slots.get_mut(s) {
                        list.extend(indices);
                    }
                }
            }
        }
        (r.errors, r.functions, slots)
    }

    /// Registers one use of an error name; returns its index.
    fn error_use(&mut self, u: &Use, kind: ErrorKind, r: &mut Registry<'_>) -> Option<usize> {
        if r.coefficient_of.contains_key(&u.name) || r.function_by_name.contains_key(&u.name) {
            let other = r.describe(&u.name, &self.parameter_index)?;
            let problem = Problem::FunctionClash {
                what: format!("error parameter `{}`", u.name),
                other,
            };
            self.report(u.span, u.path.clone(), problem);
            return None;
        }
        if let Some(&i) = r.by_name.get(&u.name) {
            let e = r.errors.get_mut(i)?;
            let linear = |k: ErrorKind| k == ErrorKind::Linear;
            if linear(e.kind) != linear(kind) {
                let problem = Problem::ErrorKindConflict {
                    name: u.name.clone(),
                    first: e.kind,
                    second: kind,
                    first_line: e.origin.line,
                };
                self.report(u.span, u.path.clone(), problem);
            } else if kind == ErrorKind::Squareness {
                // An angle used both as a motion error and as squareness is a
                // squareness term.
                e.kind = ErrorKind::Squareness;
            }
            return Some(i);
        }
        if self.parameter_index.contains_key(&u.name) {
            self.report(
                u.span,
                u.path.clone(),
                Problem::NameCollision {
                    name: u.name.clone(),
                    what: "error",
                    other: "parameter",
                },
            );
        } else if r.variable_names.contains(&u.name) {
            self.report(
                u.span,
                u.path.clone(),
                Problem::NameCollision {
                    name: u.name.clone(),
                    what: "error",
                    other: "axis variable",
                },
            );
        }
        Some(r.push(ErrorParam {
            name: u.name.clone(),
            kind,
            origin: u.span.origin(u.path.clone()),
        }))
    }

    /// Registers one declaration of a function slot on the joint driven by
    /// variable `variable`, in a slot of `kind`; returns its coefficients'
    /// indices (empty if refused).
    fn function_use(
        &mut self,
        f: &RawFunction,
        kind: ErrorKind,
        variable: usize,
        r: &mut Registry<'_>,
    ) -> Vec<usize> {
        let name = &f.name.name;
        if let Some(&fi) = r.function_by_name.get(name) {
            let Some(first) = r.functions.get(fi) else {
                return Vec::new();
            };
            let first_kind = first
                .coefficients
                .first()
                .and_then(|(j, _)| r.errors.get(*j))
                .map(|e| e.kind);
            let difference = if first.basis != f.basis {
                Some(format!(
                    "with a different basis ({} here, {} first)",
                    describe_basis(&f.basis),
                    describe_basis(&first.basis)
                ))
            } else if first.variable != variable {
                let var = |i: usize| r.variables.get(i).map_or("?", |v| v.name.as_str());
                Some(format!(
                    "on another axis (variable `{}` here, `{}` first)",
                    var(variable),
                    var(first.variable)
                ))
            } else if first_kind
                .is_some_and(|k| (k == ErrorKind::Linear) != (kind == ErrorKind::Linear))
            {
                Some(format!(
                    "in a slot of another kind ({} here, {} first)",
                    slot_kind(kind),
                    slot_kind(first_kind.unwrap_or(kind))
                ))
            } else {
                None
            };
            if let Some(difference) = difference {
                let problem = Problem::FunctionRedeclared {
                    name: name.clone(),
                    difference,
                    first: place(&first.origin),
                };
                self.report(f.name.span, f.name.path.clone(), problem);
                return Vec::new();
            }
            return first.coefficients.iter().map(|(j, _)| *j).collect();
        }

        // A new function: its name and every coefficient's must be new.
        let terms = f.basis.terms();
        let names: Vec<String> = terms
            .iter()
            .map(|t| format!("{name}_{}", t.suffix()))
            .collect();
        let mut clashes = Vec::new();
        if let Some(other) = r.describe(name, &self.parameter_index) {
            clashes.push((format!("function `{name}`"), other));
        }
        for c in &names {
            if let Some(other) = r.describe(c, &self.parameter_index) {
                clashes.push((format!("coefficient `{c}` of function `{name}`"), other));
            }
        }
        if !clashes.is_empty() {
            for (what, other) in clashes {
                self.report(
                    f.name.span,
                    f.name.path.clone(),
                    Problem::FunctionClash { what, other },
                );
            }
            self.failed_functions.insert(name.clone());
            return Vec::new();
        }
        let origin = f.name.span.origin(f.name.path.clone());
        let coefficients: Vec<(usize, crate::model::BasisFn)> = names
            .into_iter()
            .zip(terms)
            .map(|(c, t)| {
                r.coefficient_of.insert(c.clone(), name.clone());
                let j = r.push(ErrorParam {
                    name: c,
                    kind,
                    origin: origin.clone(),
                });
                (j, t)
            })
            .collect();
        r.function_by_name.insert(name.clone(), r.functions.len());
        let indices = coefficients.iter().map(|(j, _)| *j).collect();
        r.functions.push(ErrorFunction {
            name: name.clone(),
            basis: f.basis.clone(),
            variable,
            coefficients,
            origin,
        });
        indices
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
fn split_dh<'n>(raw: RawBody<'n>, row: RawDh<'n>) -> Vec<RawBody<'n>> {
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

/// The error parameters and function slots found so far, in the walk over
/// the bodies of [`Loader::errors`].
#[derive(Default)]
struct Registry<'v> {
    errors: Vec<ErrorParam>,
    /// Error name → index into `errors`.
    by_name: HashMap<String, usize>,
    functions: Vec<ErrorFunction>,
    /// Function name → index into `functions`.
    function_by_name: HashMap<String, usize>,
    /// Coefficient name → its function's name.
    coefficient_of: HashMap<String, String>,
    /// Name given by `errors: iso` → the body whose `iso` gave it.
    iso_owner: HashMap<String, String>,
    /// Every variable name written in a joint.
    variable_names: HashSet<String>,
    /// The valid variables.
    variables: &'v [Variable],
}

impl Registry<'_> {
    /// Adds an error parameter; returns its index.
    fn push(&mut self, e: ErrorParam) -> usize {
        let i = self.errors.len();
        self.by_name.insert(e.name.clone(), i);
        self.errors.push(e);
        i
    }

    /// What `name` already is, if anything: an error parameter, a
    /// coefficient, a function, a parameter or an axis variable (for the
    /// messages of [`Problem::FunctionClash`]).
    fn describe(&self, name: &str, parameters: &HashMap<String, usize>) -> Option<String> {
        if let Some(function) = self.coefficient_of.get(name) {
            let at = self
                .function_by_name
                .get(function)
                .and_then(|&i| self.functions.get(i))
                .map_or_else(String::new, |f| format!(" (declared {})", place(&f.origin)));
            return Some(format!("a coefficient of function `{function}`{at}"));
        }
        if let Some(f) = self
            .function_by_name
            .get(name)
            .and_then(|&i| self.functions.get(i))
        {
            return Some(format!("function `{name}` (declared {})", place(&f.origin)));
        }
        if let Some(e) = self.by_name.get(name).and_then(|&i| self.errors.get(i)) {
            return Some(format!(
                "the error parameter `{name}` (first used {})",
                place(&e.origin)
            ));
        }
        if parameters.contains_key(name) {
            return Some(format!("the parameter `{name}`"));
        }
        if self.variable_names.contains(name) {
            return Some(format!("the axis variable `{name}`"));
        }
        None
    }
}

/// Where an earlier declaration is, for messages: `on line 8` in a file,
/// ``at `bodies.x_slide.errors.dy` `` in the inline `machine!` form (whose
/// tokens have no lines).
fn place(origin: &crate::model::Origin) -> String {
    if origin.line > 0 {
        format!("on line {}", origin.line)
    } else {
        format!("at `{}`", origin.key)
    }
}

/// A basis as it is written, for messages: `powers [1, 2]`, `legendre
/// degree 3 on [0, 1000]`, `fourier with 2 harmonics`.
fn describe_basis(basis: &Basis) -> String {
    match basis {
        Basis::Powers { powers } => {
            let list: Vec<String> = powers.iter().map(u32::to_string).collect();
            format!("powers [{}]", list.join(", "))
        }
        Basis::Legendre {
            degree,
            range,
            from,
        }
        | Basis::Chebyshev {
            degree,
            range,
            from,
        } => {
            let from = if *from == 0 {
                String::new()
            } else {
                format!(" from {from}")
            };
            format!(
                "{} degree {degree}{from} on [{}, {}]",
                basis.name(),
                range[0],
                range[1]
            )
        }
        Basis::Fourier { harmonics } => format!("fourier with {harmonics} harmonics"),
    }
}

/// The kind of a slot, for messages.
fn slot_kind(kind: ErrorKind) -> &'static str {
    if kind == ErrorKind::Linear {
        "a linear slot (dx, dy, dz)"
    } else {
        "an angular slot (ex, ey, ez)"
    }
}
