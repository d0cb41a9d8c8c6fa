//! The inline machine syntax of `machine!`: Rust tokens → the loader's located
//! tree ([`crate::yaml::Node`]).
//!
//! The syntax mirrors the YAML file one to one, so every rule and message of
//! the loader applies unchanged:
//!
//! - a mapping is `{ key: value, key: value }`; `key { ... }` (no colon) is
//!   shorthand for `key: { ... }`, and the comma after a braced value may be
//!   left out;
//! - a list is `[a, b, c]`;
//! - anything else up to the next comma is a scalar: `bed`, `+x`, `0.05/6`,
//!   `-L`, `90deg`, `"a string"`, `null`.
//!
//! Each node's [`Span::offset`] is an index into a table of token spans, so a
//! diagnostic's [`crate::model::Origin`] maps back to the offending token.

use proc_macro2::{Delimiter, Span as TokenSpan, TokenStream, TokenTree};

use crate::yaml::{Node, NodeKind, Scalar, ScalarStyle, Span};

/// A syntax error in the inline form, at a token.
#[derive(Debug, Clone)]
pub struct SyntaxError {
    /// Where.
    pub span: TokenSpan,
    /// What.
    pub message: String,
}

/// Converts tokens to a located tree, recording token spans.
#[derive(Debug, Default)]
pub struct Converter {
    /// Token spans; a node's `span.offset` indexes this table.
    pub spans: Vec<TokenSpan>,
}

impl Converter {
    /// A node location: `offset` indexes the token table; `line` and
    /// `column` are 0 (tokens have no lines of a file), so messages that
    /// refer to an earlier place name its key path instead of a line.
    fn locate(&mut self, span: TokenSpan) -> Span {
        self.spans.push(span);
        Span {
            offset: self.spans.len() - 1,
            len: 1,
            line: 0,
            column: 0,
        }
    }

    /// The token span of a node location (call site if unknown).
    pub fn span_of(&self, offset: usize) -> TokenSpan {
        self.spans
            .get(offset)
            .copied()
            .unwrap_or_else(TokenSpan::call_site)
    }

    /// Parses the contents of a `{ ... }` group as a mapping.
    pub fn mapping(&mut self, tokens: TokenStream, at: TokenSpan) -> Result<Node, SyntaxError> {
        let span = self.locate(at);
        let tokens: Vec<TokenTree> = tokens.into_iter().collect();
        let mut entries = Vec::new();
        let mut i = 0;
        while i < tokens.len() {
            let key_token = &tokens[i];
            let key_text = match key_token {
                TokenTree::Ident(id) => id.to_string(),
                TokenTree::Literal(lit) => literal_text(lit).0,
                other => {
                    return Err(SyntaxError {
                        span: other.span(),
                        message: format!("expected a key (a name), found `{other}`"),
                    })
                }
            };
            let key_span = self.locate(key_token.span());
            let key = Node {
                kind: NodeKind::Scalar(Scalar {
                    text: key_text.clone(),
                    style: ScalarStyle::Plain,
                    verbatim: false,
                }),
                span: key_span,
            };
            i += 1;
            let value = match tokens.get(i) {
                Some(TokenTree::Punct(p)) if p.as_char() == ':' => {
                    i += 1;
                    let (value, next) = self.value(&tokens, i, key_token.span(), &key_text)?;
                    i = next;
                    value
                }
                Some(TokenTree::Group(g)) if g.delimiter() == Delimiter::Brace => {
                    i += 1;
                    self.mapping(g.stream(), g.span())?
                }
                Some(other) => {
                    return Err(SyntaxError {
                        span: other.span(),
                        message: format!(
                            "expected `:` or `{{` after key `{key_text}`, found `{other}`"
                        ),
                    })
                }
                None => {
                    return Err(SyntaxError {
                        span: key_token.span(),
                        message: format!(
                            "key `{key_text}` has no value: write `{key_text}: value`"
                        ),
                    })
                }
            };
            let braced = value.as_mapping().is_some() || value.as_sequence().is_some();
            entries.push((key, value));
            match tokens.get(i) {
                None => {}
                Some(TokenTree::Punct(p)) if p.as_char() == ',' => i += 1,
                Some(_) if braced => {}
                Some(other) => {
                    return Err(SyntaxError {
                        span: other.span(),
                        message: format!(
                            "expected `,` after the value of `{key_text}`, found `{other}`"
                        ),
                    })
                }
            }
        }
        Ok(Node {
            kind: NodeKind::Mapping(entries),
            span,
        })
    }

    /// Parses one value starting at `tokens[i]`; returns it and the index of
    /// the token after it (the separating comma, if any, is not consumed).
    fn value(
        &mut self,
        tokens: &[TokenTree],
        i: usize,
        key_span: TokenSpan,
        key: &str,
    ) -> Result<(Node, usize), SyntaxError> {
        match tokens.get(i) {
            Some(TokenTree::Group(g)) if g.delimiter() == Delimiter::Brace => {
                Ok((self.mapping(g.stream(), g.span())?, i + 1))
            }
            Some(TokenTree::Group(g)) if g.delimiter() == Delimiter::Bracket => {
                Ok((self.sequence(g.stream(), g.span())?, i + 1))
            }
            Some(first) => {
                let start = i;
                let mut end = i;
                while end < tokens.len()
                    && !matches!(&tokens[end], TokenTree::Punct(p) if p.as_char() == ',')
                {
                    end += 1;
                }
                let run = &tokens[start..end];
                let span = self.locate(first.span());
                let scalar = match run {
                    [TokenTree::Literal(lit)] => {
                        let (text, quoted) = literal_text(lit);
                        Scalar {
                            text,
                            style: if quoted {
                                ScalarStyle::DoubleQuoted
                            } else {
                                ScalarStyle::Plain
                            },
                            verbatim: false,
                        }
                    }
                    _ => Scalar {
                        text: tokens_text(run),
                        style: ScalarStyle::Plain,
                        verbatim: false,
                    },
                };
                Ok((
                    Node {
                        kind: NodeKind::Scalar(scalar),
                        span,
                    },
                    end,
                ))
            }
            None => Err(SyntaxError {
                span: key_span,
                message: format!("key `{key}` has no value after `:`"),
            }),
        }
    }

    /// Parses the contents of a `[ ... ]` group as a list.
    fn sequence(&mut self, tokens: TokenStream, at: TokenSpan) -> Result<Node, SyntaxError> {
        let span = self.locate(at);
        let tokens: Vec<TokenTree> = tokens.into_iter().collect();
        let mut items = Vec::new();
        let mut i = 0;
        while i < tokens.len() {
            let (item, next) = self.value(&tokens, i, at, "list item")?;
            items.push(item);
            i = next;
            if let Some(TokenTree::Punct(p)) = tokens.get(i) {
                if p.as_char() == ',' {
                    i += 1;
                }
            }
        }
        Ok(Node {
            kind: NodeKind::Sequence(items),
            span,
        })
    }
}

/// The text of a literal and whether it was a string literal (unquoted).
fn literal_text(lit: &proc_macro2::Literal) -> (String, bool) {
    let raw = lit.to_string();
    if raw.starts_with('"') || raw.starts_with("r\"") || raw.starts_with("r#") {
        if let Ok(s) = syn::parse2::<syn::LitStr>(TokenTree::Literal(lit.clone()).into()) {
            return (s.value(), true);
        }
    }
    (raw, false)
}

/// Concatenates tokens into scalar text: `0.05 / 6` → `0.05/6`, `- L` → `-L`,
/// `(a + b) * 2` → `(a+b)*2`.
fn tokens_text(tokens: &[TokenTree]) -> String {
    let mut out = String::new();
    for t in tokens {
        match t {
            TokenTree::Group(g) => {
                let (open, close) = match g.delimiter() {
                    Delimiter::Parenthesis => ("(", ")"),
                    Delimiter::Bracket => ("[", "]"),
                    Delimiter::Brace => ("{", "}"),
                    Delimiter::None => ("", ""),
                };
                out.push_str(open);
                let inner: Vec<TokenTree> = g.stream().into_iter().collect();
                out.push_str(&tokens_text(&inner));
                out.push_str(close);
            }
            TokenTree::Literal(lit) => out.push_str(&literal_text(lit).0),
            other => out.push_str(&other.to_string()),
        }
    }
    out
}
