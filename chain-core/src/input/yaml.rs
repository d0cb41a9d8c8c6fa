//! A small located YAML tree, built from `yaml-rust2`'s event parser.
//!
//! This is the only module that touches a YAML library. It turns the text of a
//! machine file into a [`Node`] tree (mappings, sequences, scalars) in which
//! every node, keys included, knows its byte [`Span`], line and column, so that
//! the loader ([`crate::load`]) can point at any key or value.
//!
//! Guarantees, whatever the input:
//!
//! - aliases are expanded, but every node created counts against a budget of
//!   [`MAX_NODES`] (alias copies included), so an alias bomb ("billion laughs")
//!   stops with [`Problem::AliasLimit`] after a bounded amount of work;
//! - collections nest at most [`MAX_DEPTH`] levels (so walking or dropping a
//!   tree never overflows the stack);
//! - a key given twice in one mapping is an error ([`Problem::DuplicateKey`]);
//!   the first value is kept so that the rest of the file can still be checked;
//! - exactly one document per file; no panics.
//!
//! The tree types are public and free of `yaml-rust2` types, so another front
//! end (the `machine!` macro, say) can build the same tree from its own tokens
//! and reuse the loader's validation.

use std::collections::HashMap;

use yaml_rust2::parser::{Event, Parser};
use yaml_rust2::scanner::{Marker, TScalarStyle};

use crate::diagnostic::Problem;
use crate::model::Origin;

/// Maximum number of nodes a file may expand to (aliases included).
pub const MAX_NODES: usize = 100_000;

/// Maximum nesting depth of collections.
pub const MAX_DEPTH: usize = 64;

/// A location in the source text.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Span {
    /// Byte offset of the first byte.
    pub offset: usize,
    /// Length in bytes.
    pub len: usize,
    /// 1-based line.
    pub line: usize,
    /// 1-based column, in characters.
    pub column: usize,
}

impl Span {
    /// The model's [`Origin`] for this span, reached by `key`.
    pub fn origin(&self, key: impl Into<String>) -> Origin {
        Origin {
            offset: self.offset,
            len: self.len,
            line: self.line,
            column: self.column,
            key: key.into(),
        }
    }
}

/// How a scalar was written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ScalarStyle {
    /// Unquoted.
    Plain,
    /// `'single quoted'`.
    SingleQuoted,
    /// `"double quoted"`.
    DoubleQuoted,
    /// A `|` or `>` block scalar.
    Block,
}

/// A scalar: its text (after YAML unquoting and folding) and style.
#[derive(Debug, Clone, PartialEq)]
pub struct Scalar {
    /// The value.
    pub text: String,
    /// How it was written.
    pub style: ScalarStyle,
    /// True if `text` appears byte for byte in the source on one line, just
    /// after the opening quote if any, so that an offset into `text` is an
    /// offset into the source (see [`Node::span_at`]).
    pub verbatim: bool,
}

impl Scalar {
    /// True for a plain `~`, `null`, `Null`, `NULL` or empty scalar.
    pub fn is_null(&self) -> bool {
        self.style == ScalarStyle::Plain
            && matches!(self.text.as_str(), "" | "~" | "null" | "Null" | "NULL")
    }
}

/// What a node holds.
#[derive(Debug, Clone, PartialEq)]
pub enum NodeKind {
    /// A scalar.
    Scalar(Scalar),
    /// A sequence (list).
    Sequence(Vec<Node>),
    /// A mapping, entries in file order; keys are scalars and unique.
    Mapping(Vec<(Node, Node)>),
}

/// A located YAML node.
#[derive(Debug, Clone, PartialEq)]
pub struct Node {
    /// The content.
    pub kind: NodeKind,
    /// Where it is. For an alias, where the anchored node is.
    pub span: Span,
}

impl Node {
    /// The scalar, if this is one.
    pub fn as_scalar(&self) -> Option<&Scalar> {
        match &self.kind {
            NodeKind::Scalar(s) => Some(s),
            _ => None,
        }
    }

    /// The scalar text, if this is a scalar.
    pub fn as_str(&self) -> Option<&str> {
        self.as_scalar().map(|s| s.text.as_str())
    }

    /// True for a null scalar (see [`Scalar::is_null`]).
    pub fn is_null(&self) -> bool {
        self.as_scalar().is_some_and(Scalar::is_null)
    }

    /// The mapping entries, if this is a mapping.
    pub fn as_mapping(&self) -> Option<&[(Node, Node)]> {
        match &self.kind {
            NodeKind::Mapping(m) => Some(m),
            _ => None,
        }
    }

    /// The items, if this is a sequence.
    pub fn as_sequence(&self) -> Option<&[Node]> {
        match &self.kind {
            NodeKind::Sequence(s) => Some(s),
            _ => None,
        }
    }

    /// A short description for messages: `a mapping`, `a list`, `null`, or the
    /// scalar in backquotes.
    pub fn describe(&self) -> String {
        match &self.kind {
            NodeKind::Mapping(_) => "a mapping".into(),
            NodeKind::Sequence(_) => "a list".into(),
            NodeKind::Scalar(s) if s.is_null() => "nothing (null)".into(),
            NodeKind::Scalar(s) => format!("`{}`", crate::diagnostic::shortened(&s.text)),
        }
    }

    /// The span of byte `offset` of this scalar's text, when the text is
    /// [`Scalar::verbatim`]; otherwise the node's own span.
    pub fn span_at(&self, offset: usize) -> Span {
        let Some(s) = self.as_scalar() else {
            return self.span;
        };
        let Some(prefix) = s.text.get(..offset) else {
            return self.span;
        };
        if !s.verbatim {
            return self.span;
        }
        let quote = usize::from(s.style != ScalarStyle::Plain);
        Span {
            offset: self.span.offset + quote + offset,
            len: s
                .text
                .get(offset..)
                .and_then(|r| r.chars().next())
                .map_or(0, char::len_utf8),
            line: self.span.line,
            column: self.span.column + quote + prefix.chars().count(),
        }
    }
}

/// The result of [`parse`]: the tree (if the text could be parsed at all) and
/// the errors found, each with its span and key path.
#[derive(Debug, Clone, Default)]
pub struct Parsed {
    /// The document's root node; `None` after a fatal error or for an empty
    /// document.
    pub root: Option<Node>,
    /// Problems found, with the dotted key path where they occurred.
    pub errors: Vec<(Span, String, Problem)>,
}

/// Parses YAML text into a located tree. Never panics; see the module docs
/// for the limits it enforces.
pub fn parse(text: &str) -> Parsed {
    // yaml-rust2 does not skip a byte-order mark; do it here and shift offsets.
    let (body, base) = match text.strip_prefix('\u{feff}') {
        Some(rest) => (rest, '\u{feff}'.len_utf8()),
        None => (text, 0),
    };
    let mut builder = Builder::new(body, base);
    let run = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        builder.run();
        builder
    }));
    match run {
        Ok(b) => b.finish(),
        Err(_) => Parsed {
            root: None,
            errors: vec![(
                Span {
                    offset: 0,
                    len: 0,
                    line: 1,
                    column: 1,
                },
                String::new(),
                Problem::Syntax {
                    message: "the YAML parser failed on this input".into(),
                },
            )],
        },
    }
}

enum MapState {
    /// Waiting for a key.
    Key,
    /// Waiting for the value of this key (`None`: discard the value).
    Value(Option<Node>),
}

enum FrameKind {
    Seq(Vec<Node>),
    Map {
        entries: Vec<(Node, Node)>,
        seen: HashMap<String, usize>,
        state: MapState,
    },
}

struct Frame {
    kind: FrameKind,
    anchor: usize,
    span: Span,
    flow: bool,
}

struct Anchored {
    node: Node,
    size: usize,
    height: usize,
}

/// Stops the event loop.
struct Fatal;

struct Builder<'t> {
    text: &'t str,
    base: usize,
    char_bytes: Option<Vec<usize>>,
    /// Byte offset of the start of each line.
    line_starts: Vec<usize>,
    frames: Vec<Frame>,
    anchors: HashMap<usize, Anchored>,
    nodes: usize,
    documents: usize,
    root: Option<Node>,
    errors: Vec<(Span, String, Problem)>,
}

impl<'t> Builder<'t> {
    fn new(text: &'t str, base: usize) -> Self {
        let char_bytes = if text.is_ascii() {
            None
        } else {
            Some(text.char_indices().map(|(i, _)| i).collect())
        };
        let line_starts = std::iter::once(0)
            .chain(text.match_indices('\n').map(|(i, _)| i + 1))
            .collect();
        Builder {
            text,
            base,
            char_bytes,
            line_starts,
            frames: Vec::new(),
            anchors: HashMap::new(),
            nodes: 0,
            documents: 0,
            root: None,
            errors: Vec::new(),
        }
    }

    fn finish(self) -> Parsed {
        Parsed {
            root: self.root,
            errors: self.errors,
        }
    }

    /// Byte offset (in `self.text`) of a marker.
    fn byte(&self, m: &Marker) -> usize {
        let i = m.index();
        match &self.char_bytes {
            None => i.min(self.text.len()),
            Some(t) => t.get(i).copied().unwrap_or(self.text.len()),
        }
    }

    /// The span (length 0) of a marker. Line and column are computed from
    /// the byte offset (the scanner's own line is one too far at the end of
    /// a file without a final newline).
    fn span(&self, m: &Marker) -> Span {
        let byte = self.byte(m);
        let line = self.line_starts.partition_point(|&s| s <= byte).max(1);
        let start = self.line_starts.get(line - 1).copied().unwrap_or(0);
        let column = match &self.char_bytes {
            None => byte - start.min(byte),
            Some(t) => t.partition_point(|&b| b < byte) - t.partition_point(|&b| b < start),
        } + 1;
        Span {
            offset: self.base + byte,
            len: 0,
            line,
            column,
        }
    }

    /// Length of the rest of the line starting at text offset `byte`.
    fn line_rest(&self, byte: usize) -> usize {
        self.text.get(byte..).map_or(0, |r| {
            let line = r.split(['\n', '\r']).next().unwrap_or("");
            let line = line.split(" #").next().unwrap_or(line);
            line.trim_end().len()
        })
    }

    /// The dotted key path of the node being built.
    fn path(&self) -> String {
        let mut path = String::new();
        for f in &self.frames {
            match &f.kind {
                FrameKind::Seq(items) => path.push_str(&format!("[{}]", items.len())),
                FrameKind::Map { state, .. } => {
                    if let MapState::Value(Some(k)) = state {
                        if !path.is_empty() {
                            path.push('.');
                        }
                        path.push_str(k.as_str().unwrap_or(""));
                    }
                }
            }
        }
        path
    }

    fn error(&mut self, span: Span, problem: Problem) {
        let path = self.path();
        self.errors.push((span, path, problem));
    }

    fn fatal(&mut self, span: Span, problem: Problem) -> Fatal {
        self.root = None;
        self.error(span, problem);
        Fatal
    }

    fn count(&mut self, n: usize, span: Span) -> Result<(), Fatal> {
        self.nodes = self.nodes.saturating_add(n);
        if self.nodes > MAX_NODES {
            return Err(self.fatal(span, Problem::AliasLimit { limit: MAX_NODES }));
        }
        Ok(())
    }

    fn run(&mut self) {
        let mut parser = Parser::new_from_str(self.text);
        loop {
            match parser.next_token() {
                Ok((Event::StreamEnd, _)) => return,
                Ok((ev, mark)) => {
                    if self.event(ev, &mark).is_err() {
                        return;
                    }
                }
                Err(e) => {
                    let span = self.span(e.marker());
                    let path = self.path();
                    self.root = None;
                    self.errors.push((
                        span,
                        path,
                        Problem::Syntax {
                            message: e.info().to_string(),
                        },
                    ));
                    return;
                }
            }
        }
    }

    fn event(&mut self, ev: Event, mark: &Marker) -> Result<(), Fatal> {
        let span = self.span(mark);
        match ev {
            Event::DocumentStart => {
                self.documents += 1;
                if self.documents > 1 {
                    return Err(self.fatal(span, Problem::MultipleDocuments));
                }
            }
            Event::Scalar(text, style, anchor, _tag) => {
                self.count(1, span)?;
                let node = self.scalar(text, style, span);
                self.complete(node, anchor)?;
            }
            Event::SequenceStart(anchor, _) | Event::MappingStart(anchor, _) => {
                if self.frames.len() >= MAX_DEPTH {
                    return Err(self.fatal(span, Problem::TooDeep { limit: MAX_DEPTH }));
                }
                self.count(1, span)?;
                let start = span.offset - self.base;
                let is_map = matches!(ev, Event::MappingStart(..));
                let flow = self
                    .text
                    .get(start..)
                    .and_then(|r| r.chars().next())
                    .is_some_and(|c| c == if is_map { '{' } else { '[' });
                let kind = if is_map {
                    FrameKind::Map {
                        entries: Vec::new(),
                        seen: HashMap::new(),
                        state: MapState::Key,
                    }
                } else {
                    FrameKind::Seq(Vec::new())
                };
                self.frames.push(Frame {
                    kind,
                    anchor,
                    span,
                    flow,
                });
            }
            Event::SequenceEnd | Event::MappingEnd => {
                let Some(frame) = self.frames.pop() else {
                    return Ok(());
                };
                let end = span.offset - self.base;
                let mut span = frame.span;
                let kind = match frame.kind {
                    FrameKind::Seq(items) => NodeKind::Sequence(items),
                    FrameKind::Map { entries, .. } => NodeKind::Mapping(entries),
                };
                if frame.flow {
                    let start = span.offset - self.base;
                    span.len = end.saturating_sub(start) + 1;
                } else {
                    // A block mapping's start event points at the first
                    // colon; use the first key instead.
                    if let NodeKind::Mapping(entries) = &kind {
                        if let Some((k, _)) = entries.first() {
                            span = k.span;
                        }
                    }
                    span.len = self.line_rest(span.offset - self.base);
                }
                let node = Node { kind, span };
                self.complete(node, frame.anchor)?;
            }
            Event::Alias(id) => {
                let Some(a) = self.anchors.get(&id) else {
                    return Err(self.fatal(span, Problem::RecursiveAlias));
                };
                let (size, height) = (a.size, a.height);
                if self.frames.len() + height > MAX_DEPTH {
                    return Err(self.fatal(span, Problem::TooDeep { limit: MAX_DEPTH }));
                }
                self.count(size, span)?;
                let node = match self.anchors.get(&id) {
                    Some(a) => a.node.clone(),
                    None => return Ok(()),
                };
                self.complete(node, 0)?;
            }
            Event::StreamStart | Event::StreamEnd | Event::DocumentEnd | Event::Nothing => {}
        }
        Ok(())
    }

    fn scalar(&self, text: String, style: TScalarStyle, mut span: Span) -> Node {
        let style = match style {
            TScalarStyle::Plain => ScalarStyle::Plain,
            TScalarStyle::SingleQuoted => ScalarStyle::SingleQuoted,
            TScalarStyle::DoubleQuoted => ScalarStyle::DoubleQuoted,
            TScalarStyle::Literal | TScalarStyle::Folded => ScalarStyle::Block,
        };
        let start = span.offset - self.base;
        let quote = usize::from(matches!(
            style,
            ScalarStyle::SingleQuoted | ScalarStyle::DoubleQuoted
        ));
        let verbatim = style != ScalarStyle::Block
            && !text.contains(['\n', '\r'])
            && self
                .text
                .get(start + quote..start + quote + text.len())
                .is_some_and(|t| t == text);
        span.len = if verbatim {
            text.len() + 2 * quote
        } else {
            self.line_rest(start)
        };
        Node {
            kind: NodeKind::Scalar(Scalar {
                text,
                style,
                verbatim,
            }),
            span,
        }
    }

    /// Attaches a finished node to the open collection (or makes it the root).
    fn complete(&mut self, node: Node, anchor: usize) -> Result<(), Fatal> {
        if anchor != 0 {
            let (size, height) = measure(&node);
            // The stored copy counts against the budget too.
            self.count(size, node.span)?;
            self.anchors.insert(
                anchor,
                Anchored {
                    node: node.clone(),
                    size,
                    height,
                },
            );
        }
        let Some(frame) = self.frames.last_mut() else {
            if !node.is_null() {
                self.root = Some(node);
            }
            return Ok(());
        };
        let mut report: Option<(Span, Problem, Option<String>)> = None;
        match &mut frame.kind {
            FrameKind::Seq(items) => items.push(node),
            FrameKind::Map {
                entries,
                seen,
                state,
            } => match std::mem::replace(state, MapState::Key) {
                MapState::Key => match node.as_str() {
                    Some(key) => {
                        if let Some(&first_line) = seen.get(key) {
                            *state = MapState::Value(None);
                            let problem = Problem::DuplicateKey {
                                key: key.to_string(),
                                first_line,
                            };
                            report = Some((node.span, problem, Some(key.to_string())));
                        } else {
                            seen.insert(key.to_string(), node.span.line);
                            *state = MapState::Value(Some(node));
                        }
                    }
                    None => {
                        *state = MapState::Value(None);
                        report = Some((node.span, Problem::NonScalarKey, None));
                    }
                },
                MapState::Value(Some(key)) => entries.push((key, node)),
                MapState::Value(None) => {}
            },
        }
        if let Some((span, problem, key)) = report {
            let mut path = self.path();
            if let Some(key) = key {
                if !path.is_empty() {
                    path.push('.');
                }
                path.push_str(&key);
            }
            self.errors.push((span, path, problem));
        }
        Ok(())
    }
}

/// Number of nodes and height of a tree (bounded by [`MAX_DEPTH`]).
fn measure(node: &Node) -> (usize, usize) {
    match &node.kind {
        NodeKind::Scalar(_) => (1, 0),
        NodeKind::Sequence(items) => items.iter().fold((1, 1), |(n, h), c| {
            let (cn, ch) = measure(c);
            (n.saturating_add(cn), h.max(ch + 1))
        }),
        NodeKind::Mapping(entries) => entries.iter().fold((1, 1), |(n, h), (k, v)| {
            let (vn, vh) = measure(v);
            (
                n.saturating_add(vn).saturating_add(measure(k).0),
                h.max(vh + 1),
            )
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn root(text: &str) -> Node {
        let p = parse(text);
        assert!(p.errors.is_empty(), "{:?}", p.errors);
        p.root.expect("a root")
    }

    #[test]
    fn spans_of_keys_and_values() {
        let r = root("machine: \"gé\"\nbodies:\n  bed: {}\n  x: {parent: bed, offset: [1, -L]}\n");
        let m = r.as_mapping().unwrap();
        assert_eq!(m[0].0.span.line, 1);
        assert_eq!(m[0].0.span.column, 1);
        assert_eq!(m[0].1.span.column, 10);
        assert_eq!(m[1].0.span.offset, 15); // after the two-byte é
        let bodies = m[1].1.as_mapping().unwrap();
        let x = bodies[1].1.as_mapping().unwrap();
        let off = x[1].1.as_sequence().unwrap();
        assert_eq!(off[1].as_str(), Some("-L"));
        assert_eq!(off[1].span.line, 4);
        assert_eq!(off[1].span.column, 32);
        assert_eq!(bodies[1].1.span.len, "{parent: bed, offset: [1, -L]}".len());
    }

    #[test]
    fn inner_span_of_quoted_scalar() {
        let r = root("a: '1 + * 2'\n");
        let v = &r.as_mapping().unwrap()[0].1;
        let s = v.span_at(4);
        assert_eq!(s.column, 9);
        assert_eq!(s.offset, 8);
    }

    #[test]
    fn block_mapping_span_starts_at_first_key() {
        let r = root("top:\n  a: 1\n  b: 2\n");
        let v = &r.as_mapping().unwrap()[0].1;
        assert_eq!((v.span.line, v.span.column), (2, 3));
    }

    #[test]
    fn duplicate_key_keeps_first() {
        let p = parse("a: 1\nb: 2\na: 3\n");
        assert_eq!(p.errors.len(), 1);
        let (span, _, problem) = &p.errors[0];
        assert_eq!(span.line, 3);
        assert!(matches!(
            problem,
            Problem::DuplicateKey { first_line: 1, .. }
        ));
        let r = p.root.unwrap();
        assert_eq!(r.as_mapping().unwrap()[0].1.as_str(), Some("1"));
    }

    #[test]
    fn aliases_expand() {
        let r = root("a: &x [1, 2]\nb: *x\n");
        let m = r.as_mapping().unwrap();
        assert_eq!(m[1].1.as_sequence().unwrap().len(), 2);
    }

    #[test]
    fn alias_bomb_stops() {
        let mut text = String::from("a0: &a0 [x, x, x, x, x, x, x, x, x, x]\n");
        for i in 1..12 {
            let p = i - 1;
            text.push_str(&format!(
                "a{i}: &a{i} [*a{p}, *a{p}, *a{p}, *a{p}, *a{p}, *a{p}, *a{p}, *a{p}, *a{p}, *a{p}]\n"
            ));
        }
        let p = parse(&text);
        assert!(p.root.is_none());
        assert!(matches!(p.errors[0].2, Problem::AliasLimit { .. }));
    }

    #[test]
    fn too_deep() {
        let text = "[".repeat(10_000);
        let p = parse(&text);
        assert!(p.root.is_none());
        assert!(!p.errors.is_empty());
    }

    #[test]
    fn second_document() {
        let p = parse("a: 1\n---\nb: 2\n");
        assert!(matches!(p.errors[0].2, Problem::MultipleDocuments));
    }

    #[test]
    fn bom_is_skipped() {
        let p = parse("\u{feff}a: 1\n");
        assert!(p.errors.is_empty());
        let r = p.root.unwrap();
        assert_eq!(r.as_mapping().unwrap()[0].0.span.offset, 3);
    }

    #[test]
    fn syntax_error_is_located() {
        let p = parse("a: [1, 2\nb: 3\n");
        assert!(p.root.is_none());
        assert!(matches!(p.errors[0].2, Problem::Syntax { .. }));
        assert!(p.errors[0].0.line >= 1);
    }

    #[test]
    fn path_of_nested_error() {
        let p = parse("a:\n  b: [1, {c: 1, c: 2}]\n");
        assert_eq!(p.errors[0].1, "a.b[1].c");
    }
}
