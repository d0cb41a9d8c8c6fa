//! The `bodies` section: each body's keys, then the tree checks (parents,
//! cycles, roots), the variables and the error parameters, in the machine's
//! orders.

use std::collections::{HashMap, HashSet};

use super::{index, join, Loader, TreeReader};
use crate::diagnostic::{closest, Problem};
use crate::model::{
    Axis, Body, ErrorKind, ErrorParam, ErrorSlots, FixedRotation, Joint, JointKind, SignedAxis,
    Slot, Variable,
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
];
/// Keys of a joint.
pub const JOINT_KEYS: &[&str] = &["type", "axis", "variable"];
/// Keys of a fixed rotation.
pub const ROTATION_KEYS: &[&str] = &["about", "angle"];
/// Slots of `errors` and `location_errors`.
pub const SLOT_KEYS: &[&str] = &["dx", "dy", "dz", "ex", "ey", "ez"];
/// Slots of `squareness`.
pub const SQUARENESS_KEYS: &[&str] = &["ex", "ey", "ez"];
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
    pub functions: Vec<crate::model::ErrorFunction>,
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

struct RawJoint {
    kind: Option<JointKind>,
    axis: Option<SignedAxis>,
    variable: Option<Use>,
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

struct RawBody<'n> {
    name: String,
    span: Span,
    path: String,
    parent: Parent,
    offset: Option<&'n Node>,
    rotation: Vec<FixedRotation>,
    joint: Option<RawJoint>,
    /// Uses per group (0: location_errors, 1: errors, 2: squareness) and slot.
    slots: [[Vec<Use>; 6]; 3],
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
            raws.push(self.body(k, v, name, path));
        }
        let all_names: Vec<String> = raws.iter().map(|r| r.name.clone()).collect();

        // Offsets need every parameter and (for hints) every variable.
        let offsets: Vec<Option<[crate::model::Expr; 3]>> = raws
            .iter()
            .map(|r| self.vec3(r.offset, &join(&r.path, "offset")))
            .collect();

        let (parents, order) = self.tree(&raws, key.span);
        let (variables, var_of_body) = self.variables(&raws, &order);
        let (errors, slots) = self.errors(&raws, &order);

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
            functions: Vec::new(),
        })
    }

    /// One body's keys.
    fn body<'n>(&mut self, key: &Node, value: &'n Node, name: String, path: String) -> RawBody<'n> {
        let mut raw = RawBody {
            name,
            span: key.span,
            path: path.clone(),
            parent: Parent::Bad,
            offset: None,
            rotation: Vec::new(),
            joint: None,
            slots: Default::default(),
        };
        let Some(f) = self.fields(value, key.span, &path, BODY_KEYS) else {
            return raw;
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
        raw.offset = f.get("offset");
        if let Some(n) = f.get("rotation") {
            raw.rotation = self.rotations(n, &f.path("rotation"));
        }
        if let Some((k, v)) = f.entry("joint") {
            raw.joint = Some(self.joint(k, v, &f.path("joint")));
        }
        for (g, (group, allowed)) in GROUPS.iter().enumerate() {
            let Some((k, v)) = f.entry(group) else {
                continue;
            };
            let gpath = f.path(group);
            let Some(sf) = self.fields(v, k.span, &gpath, allowed) else {
                continue;
            };
            for (slot, _, node) in &sf.known {
                let Some(s) = SLOT_KEYS.iter().position(|k| k == slot) else {
                    continue;
                };
                let uses = self.slot_names(node, &sf.path(slot));
                if let Some(list) = raw.slots.get_mut(g).and_then(|gr| gr.get_mut(s)) {
                    list.extend(uses);
                }
            }
            for (_, node) in &sf.unknown {
                self.note_error_names(node);
            }
        }
        raw
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

    /// The error names of one slot: a name or a list of names.
    fn slot_names(&mut self, node: &Node, path: &str) -> Vec<Use> {
        self.note_error_names(node);
        if let Some(items) = node.as_sequence() {
            let mut uses = Vec::new();
            for (i, item) in items.iter().enumerate() {
                let p = index(path, i);
                if let Some(name) = self.ident(item, &p, "error") {
                    uses.push(Use {
                        name,
                        span: item.span,
                        path: p,
                    });
                }
            }
            return uses;
        }
        if node.as_scalar().is_some() {
            return self
                .ident(node, path, "error")
                .map(|name| Use {
                    name,
                    span: node.span,
                    path: path.to_string(),
                })
                .into_iter()
                .collect();
        }
        self.report(
            node.span,
            path,
            Problem::WrongType {
                expected: "an error name or a list of error names",
                found: node.describe(),
            },
        );
        Vec::new()
    }

    /// `joint: {type, axis, variable}`.
    fn joint(&mut self, key: &Node, value: &Node, path: &str) -> RawJoint {
        let mut j = RawJoint {
            kind: None,
            axis: None,
            variable: None,
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

    /// Error parameters in order of first use, and each body's slots
    /// (`location_errors`, `errors` + `squareness`), by file index.
    fn errors(
        &mut self,
        raws: &[RawBody<'_>],
        order: &[usize],
    ) -> (Vec<ErrorParam>, Vec<(ErrorSlots, ErrorSlots)>) {
        let variable_names: HashSet<String> = raws
            .iter()
            .filter_map(|r| r.joint.as_ref()?.variable.as_ref().map(|u| u.name.clone()))
            .collect();
        let mut errors: Vec<ErrorParam> = Vec::new();
        let mut by_name: HashMap<String, usize> = HashMap::new();
        let mut slots = vec![(ErrorSlots::default(), ErrorSlots::default()); raws.len()];
        for &old in order {
            let Some(raw) = raws.get(old) else { continue };
            for (g, group) in raw.slots.iter().enumerate() {
                for (s, uses) in group.iter().enumerate() {
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
                    for u in uses {
                        let Some(i) =
                            self.error_use(u, kind, &mut errors, &mut by_name, &variable_names)
                        else {
                            continue;
                        };
                        let Some((loc, err)) = slots.get_mut(old) else {
                            continue;
                        };
                        let target = if g == 0 { loc } else { err };
                        if let Some(list) = target.slots.get_mut(s) {
                            list.push(i);
                        }
                    }
                }
            }
        }
        (errors, slots)
    }

    /// Registers one use of an error name; returns its index.
    fn error_use(
        &mut self,
        u: &Use,
        kind: ErrorKind,
        errors: &mut Vec<ErrorParam>,
        by_name: &mut HashMap<String, usize>,
        variable_names: &HashSet<String>,
    ) -> Option<usize> {
        if let Some(&i) = by_name.get(&u.name) {
            let e = errors.get_mut(i)?;
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
        } else if variable_names.contains(&u.name) {
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
        let i = errors.len();
        by_name.insert(u.name.clone(), i);
        errors.push(ErrorParam {
            name: u.name.clone(),
            kind,
            origin: u.span.origin(u.path.clone()),
        });
        Some(i)
    }
}
