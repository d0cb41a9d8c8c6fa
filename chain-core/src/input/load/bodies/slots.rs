//! The error slots of a body: error names, `errors: iso` (the six ISO 230-1
//! names of a joint) and function slots (`{name, powers | basis, ...}`,
//! measured-machines spec, section 1) with their bases.

use super::{RawBody, Use};
use crate::diagnostic::{closest, Problem};
use crate::input::load::{index, Fields, Loader, TreeReader, MAX_ORDER};
use crate::model::{Basis, JointKind};
use crate::yaml::Node;

/// Slots of `errors` and `location_errors`.
pub(super) const SLOT_KEYS: &[&str] = &["dx", "dy", "dz", "ex", "ey", "ez"];

/// Slots of `squareness`.
const SQUARENESS_KEYS: &[&str] = &["ex", "ey", "ez"];

/// Keys of a function slot (measured-machines spec, section 1).
const FUNCTION_KEYS: &[&str] = &[
    "name",
    "powers",
    "basis",
    "degree",
    "range",
    "from",
    "harmonics",
    "per",
];

/// Values of a function slot's `basis` (the power basis is `powers: [..]`).
const BASES: &[&str] = &["legendre", "chebyshev", "fourier"];

/// The ISO 230-1 letters of the six slots under `errors: iso`: `dx: EXV`,
/// `dy: EYV`, `dz: EZV`, `ex: EAV`, `ey: EBV`, `ez: ECV`.
const ISO_LETTERS: [char; 6] = ['X', 'Y', 'Z', 'A', 'B', 'C'];

/// Slot groups in the order errors are numbered within a body.
pub(super) const GROUPS: [(&str, &[&str]); 3] = [
    ("location_errors", SLOT_KEYS),
    ("errors", SLOT_KEYS),
    ("squareness", SQUARENESS_KEYS),
];

/// A function slot as declared: its name and (valid) basis.
#[derive(Clone)]
pub(super) struct RawFunction {
    /// The `name` value, located at it (key path `….name`).
    pub(super) name: Use,
    /// The basis along the joint (`None`: a thermal term constant along
    /// the axis, `{name, per}` alone).
    pub(super) basis: Option<Basis>,
    /// `per:`: the sensors (indices into the machine's) whose deviations
    /// multiply it (`docs/thermal.md`); empty for a geometric function.
    pub(super) per: Vec<usize>,
}

/// One entry of a slot.
#[derive(Clone)]
pub(super) enum Item {
    /// A constant error parameter by name.
    Name(Use),
    /// One of the six names of `errors: iso`.
    Iso(Use),
    /// A function of the body's joint variable.
    Function(RawFunction),
}

/// What a body's slots know of its joint.
#[derive(Clone, Copy)]
pub(super) enum JointState {
    /// A `joint` key (its kind, if valid).
    Present(Option<JointKind>),
    /// No `joint`, but a misspelt key that looked like it (reported there).
    Misspelt,
    /// No `joint`.
    Absent,
}

/// Where a slot is, for the checks of its items.
pub(super) struct SlotContext<'a> {
    /// 0: location_errors (and a DH row's errors), 1: errors, 2: squareness.
    pub(super) group: usize,
    /// The group's key as written, for messages.
    pub(super) label: &'static str,
    /// The body's name.
    pub(super) body: &'a str,
    /// The body's joint.
    pub(super) joint: JointState,
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
fn iso_name(letter: char, variable: &str) -> String {
    format!("E{letter}{}", variable.to_uppercase())
}

impl Loader {
    /// A group whose value is a scalar: `errors: iso`, or a mistake.
    pub(super) fn group_scalar(
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
    pub(super) fn slot_items(
        &mut self,
        node: &Node,
        path: &str,
        ctx: &SlotContext<'_>,
    ) -> Vec<Item> {
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
        // A thermal term constant along the axis (`{name, per}` without a
        // basis) is a set of constants: any body, `errors` or
        // `location_errors`.
        let has = |key: &str| {
            (node.as_mapping().unwrap_or(&[]))
                .iter()
                .any(|(k, _)| k.as_str() == Some(key))
        };
        let constant = has("per") && !has("powers") && !has("basis");
        if ctx.group == 2 && has("per") {
            return refused(self, Some(Problem::ThermalNotAllowed));
        }
        if ctx.group != 1 && !constant {
            let group = ctx.label;
            return refused(self, Some(Problem::FunctionNotAllowed { group }));
        }
        let kind = match ctx.joint {
            JointState::Present(kind) => kind,
            JointState::Misspelt if !constant => return refused(self, None),
            JointState::Absent if !constant => {
                let body = ctx.body.to_string();
                return refused(self, Some(Problem::FunctionWithoutJoint { body }));
            }
            JointState::Misspelt | JointState::Absent => None,
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
        let per = match f.get("per") {
            Some(n) => self.per(n, &f.path("per")),
            None => Some(Vec::new()),
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
                    .map(|powers| Some(Basis::Powers { powers }))
            }
            (None, Some((_, b))) => self.named_basis(&f, b, kind, body).map(Some),
            (None, None) if f.get("per").is_some() => {
                self.not_for_basis(&f, "per", &["degree", "range", "from", "harmonics"]);
                Some(None)
            }
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
            per: per?,
        })
    }

    /// `per: SENSOR` or `per: [SENSOR, ...]`: declared sensors, each once.
    fn per(&mut self, node: &Node, path: &str) -> Option<Vec<usize>> {
        let items: Vec<(&Node, String)> = match node.as_sequence() {
            Some(items) => items
                .iter()
                .enumerate()
                .map(|(i, n)| (n, index(path, i)))
                .collect(),
            None => vec![(node, path.to_string())],
        };
        if items.is_empty() {
            let what = "the sensor list";
            self.report(node.span, path, Problem::EmptyList { what });
            return None;
        }
        let mut out: Vec<usize> = Vec::new();
        let mut complete = true;
        for (n, p) in items {
            let Some(name) = self.name(n, &p, "a sensor name") else {
                complete = false;
                continue;
            };
            match self.sensors.iter().position(|s| s.name == name) {
                Some(s) if out.contains(&s) => {
                    self.report(n.span, p, Problem::DuplicateSensor { name });
                    complete = false;
                }
                Some(s) => out.push(s),
                None => {
                    let sensors: Vec<String> =
                        self.sensors.iter().map(|s| s.name.clone()).collect();
                    let suggestion =
                        closest(&name, sensors.iter().map(String::as_str)).map(str::to_string);
                    let problem = Problem::UnknownSensor {
                        name,
                        sensors,
                        suggestion,
                    };
                    self.report(n.span, p, problem);
                    complete = false;
                }
            }
        }
        complete.then_some(out)
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
            self.report(node.span, path, Problem::PowersAsBasis);
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
}
