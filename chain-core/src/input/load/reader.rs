//! The readers of the located YAML tree that report what is wrong as located
//! [`Problem`]s: mappings with a fixed set of keys (unknown keys with the
//! closest valid one, missing keys), free-form mappings, names, keywords,
//! lists of a fixed length and numbers. The machine loader
//! ([`super::from_tree`]) and the settings loader ([`crate::settings`]) both
//! read through them.

use crate::diagnostic::{closest, Problem};
use crate::expr;
use crate::model::Origin;
use crate::yaml::{Node, Span};

/// Dotted key path.
pub(crate) fn join(path: &str, key: &str) -> String {
    if path.is_empty() {
        key.to_string()
    } else {
        format!("{path}.{key}")
    }
}

/// The key path of item `i` of the list at `path`.
pub(crate) fn index(path: &str, i: usize) -> String {
    format!("{path}[{i}]")
}

/// The start of the file (line 1, column 1): where a top-level key is
/// reported missing.
pub(crate) fn start_span() -> Span {
    Span {
        offset: 0,
        len: 0,
        line: 1,
        column: 1,
    }
}

/// The start of the file, at key `key`.
pub(crate) fn start_origin(key: &str) -> Origin {
    start_span().origin(key)
}

/// The known entries of a mapping, with their key nodes.
pub(crate) struct Fields<'n> {
    /// `(key, key node, value node)` for keys in the allowed set.
    pub(crate) known: Vec<(&'n str, &'n Node, &'n Node)>,
    /// Entries with keys outside the allowed set (already reported).
    pub(crate) unknown: Vec<(&'n Node, &'n Node)>,
    /// The valid keys suggested for the unknown ones: a missing key that was
    /// suggested is probably misspelt, so it is not reported again.
    pub(crate) suggested: Vec<&'static str>,
    /// Where to report a missing key: the key that owns this mapping.
    pub(crate) owner: Span,
    /// The mapping's key path.
    pub(crate) path: String,
}

impl<'n> Fields<'n> {
    /// The value of `key`, unless absent or null.
    pub(crate) fn get(&self, key: &str) -> Option<&'n Node> {
        self.entry(key).map(|(_, v)| v)
    }

    /// The key node and value of `key`, unless absent or null.
    pub(crate) fn entry(&self, key: &str) -> Option<(&'n Node, &'n Node)> {
        self.known
            .iter()
            .find(|(k, _, v)| *k == key && !v.is_null())
            .map(|(_, k, v)| (*k, *v))
    }

    /// The key path of `key` in this mapping.
    pub(crate) fn path(&self, key: &str) -> String {
        join(&self.path, key)
    }
}

/// A reader of the located tree: the problems it found so far, and the
/// readers that add to them.
pub(crate) trait TreeReader {
    /// The problems found so far.
    fn problems(&mut self) -> &mut Vec<(Origin, Problem)>;

    /// Reports `problem` at `span`, key path `key`.
    fn report(&mut self, span: Span, key: impl Into<String>, problem: Problem) {
        self.problems().push((span.origin(key), problem));
    }

    /// Reports `node` as not `expected`.
    fn wrong_type(&mut self, node: &Node, path: &str, expected: &'static str) {
        let found = node.describe();
        self.report(node.span, path, Problem::WrongType { expected, found });
    }

    /// The entries of the top-level mapping, whose keys must be in `allowed`.
    fn top<'n>(&mut self, root: &'n Node, allowed: &'static [&'static str]) -> Option<Fields<'n>> {
        if root.as_mapping().is_none() {
            self.report(
                root.span,
                "",
                Problem::TopLevelNotMapping {
                    found: root.describe(),
                },
            );
            return None;
        }
        self.fields(root, start_span(), "", allowed)
    }

    /// The entries of a mapping whose keys must be in `allowed` (`null` is an
    /// empty mapping). Unknown keys are reported with the closest valid key.
    fn fields<'n>(
        &mut self,
        node: &'n Node,
        owner: Span,
        path: &str,
        allowed: &'static [&'static str],
    ) -> Option<Fields<'n>> {
        let mut f = Fields {
            known: Vec::new(),
            unknown: Vec::new(),
            suggested: Vec::new(),
            owner,
            path: path.to_string(),
        };
        for (k, v) in self.entries(node, path)? {
            let key = k.as_str().unwrap_or("");
            if let Some(&known) = allowed.iter().find(|a| **a == key) {
                f.known.push((known, k, v));
            } else {
                let suggested = closest(key, allowed.iter().copied());
                f.suggested.extend(suggested);
                let suggestion = suggested.map(str::to_string);
                self.report(
                    k.span,
                    join(path, key),
                    Problem::UnknownKey {
                        key: key.to_string(),
                        expected: allowed,
                        suggestion,
                    },
                );
                f.unknown.push((k, v));
            }
        }
        Some(f)
    }

    /// The entries of a free-form mapping (names as keys); `null` is empty.
    fn entries<'n>(&mut self, node: &'n Node, path: &str) -> Option<&'n [(Node, Node)]> {
        if node.is_null() {
            return Some(&[]);
        }
        match node.as_mapping() {
            Some(m) => Some(m),
            None => {
                self.wrong_type(node, path, "a mapping");
                None
            }
        }
    }

    /// The value of `key`; reported missing when absent or null.
    fn required<'n>(&mut self, fields: &Fields<'n>, key: &'static str) -> Option<&'n Node> {
        let node = fields.get(key);
        if node.is_none() {
            self.missing(fields, key);
        }
        node
    }

    /// Reports a missing key, unless an unknown key looked like it.
    fn missing(&mut self, fields: &Fields<'_>, key: &'static str) {
        if fields.suggested.contains(&key) {
            return;
        }
        self.report(
            fields.owner,
            fields.path.clone(),
            Problem::MissingKey { key },
        );
    }

    /// The text of a scalar that is not null and that `ok` accepts;
    /// anything else is reported as not `expected`.
    fn text(
        &mut self,
        node: &Node,
        path: &str,
        expected: &'static str,
        ok: impl Fn(&str) -> bool,
    ) -> Option<String> {
        match node.as_scalar() {
            Some(s) if !s.is_null() && ok(&s.text) => Some(s.text.clone()),
            _ => {
                self.wrong_type(node, path, expected);
                None
            }
        }
    }

    /// A non-empty string scalar.
    fn name(&mut self, node: &Node, path: &str, expected: &'static str) -> Option<String> {
        self.text(node, path, expected, |t| !t.is_empty())
    }

    /// One of a fixed set of keywords.
    fn keyword(
        &mut self,
        node: &Node,
        path: &str,
        what: &'static str,
        expected: &'static [&'static str],
    ) -> Option<&'static str> {
        let text = self.name(node, path, "a name")?;
        self.choice(node, path, text, what, expected)
    }

    /// `text`, the value of `node`, if it is one of `expected`; otherwise it
    /// is reported as an unknown `what` with the closest valid value.
    fn choice(
        &mut self,
        node: &Node,
        path: &str,
        text: String,
        what: &'static str,
        expected: &'static [&'static str],
    ) -> Option<&'static str> {
        if let Some(&k) = expected.iter().find(|e| **e == text) {
            return Some(k);
        }
        let suggestion = closest(&text, expected.iter().copied()).map(str::to_string);
        self.report(
            node.span,
            path,
            Problem::UnknownValue {
                what,
                found: text,
                expected,
                suggestion,
            },
        );
        None
    }

    /// The `N` items of a list; anything else is reported as not `expected`.
    fn items<'n, const N: usize>(
        &mut self,
        node: &'n Node,
        path: &str,
        expected: &'static str,
    ) -> Option<&'n [Node; N]> {
        let Some(items) = node.as_sequence() else {
            self.wrong_type(node, path, expected);
            return None;
        };
        let found = items.len();
        let items = items.try_into().ok();
        if items.is_none() {
            self.report(node.span, path, Problem::WrongLength { expected: N, found });
        }
        items
    }

    /// Reports an expression syntax error inside `node`.
    fn expr_error(&mut self, node: &Node, path: &str, e: expr::ExprError) {
        self.report(
            node.span_at(e.offset),
            path,
            Problem::Expression { message: e.message },
        );
    }

    /// A number: a numeric scalar or an arithmetic string of numbers
    /// (`0.05/6`, `pi/2`); YAML's `.inf` and `.nan` are read as such so that
    /// range checks can name them.
    fn number(&mut self, node: &Node, path: &str) -> Option<f64> {
        let text = self.text(node, path, "a number", |_| true)?;
        self.constant(node, &text, path)
    }

    /// Evaluates `text`, a prefix of `node`'s text, as a number: YAML's
    /// `.inf` and `.nan` or a numbers-only expression; errors point into
    /// `node`.
    fn constant(&mut self, node: &Node, text: &str, path: &str) -> Option<f64> {
        let t = text.trim();
        let special = match t.trim_start_matches(['+', '-']) {
            ".inf" | ".Inf" | ".INF" | "inf" | "infinity" | "Infinity" => Some(f64::INFINITY),
            ".nan" | ".NaN" | ".NAN" | "nan" | "NaN" => Some(f64::NAN),
            _ => None,
        };
        if let Some(v) = special {
            return Some(if t.starts_with('-') { -v } else { v });
        }
        self.number_in(node, text, path)
    }

    /// Evaluates `text`, a prefix of `node`'s text, as a numbers-only
    /// expression; errors point into `node`.
    fn number_in(&mut self, node: &Node, text: &str, path: &str) -> Option<f64> {
        let ast = match expr::parse(text) {
            Ok(a) => a,
            Err(e) => {
                self.expr_error(node, path, e);
                return None;
            }
        };
        match expr::eval_const(&ast) {
            Ok(v) => Some(v),
            Err(errs) => {
                for (offset, p) in errs {
                    self.report(node.span_at(offset), path, p);
                }
                None
            }
        }
    }
}
