//! The expansion of `chain::machine!`, kept here (over `proc_macro2`) so the
//! proc-macro crate is a one-line shim and the expansion is testable.
//!
//! Two forms:
//!
//! - `machine!(pub GantryGrinder = "machines/gantry_grinder.yaml");` — a YAML
//!   file, relative to the calling crate's `CARGO_MANIFEST_DIR`, loaded with
//!   [`crate::load_str`]; the expansion includes the file's bytes so that the
//!   build re-runs when it changes;
//! - `machine! { pub Spindle { bodies { ... }, workpiece: table, ... } }` —
//!   the inline syntax of [`crate::inline`], validated by the same loader
//!   ([`crate::load::from_tree`]), so the messages are the YAML ones, placed at
//!   the offending token.
//!
//! Either way the model is derived ([`crate::derive()`]) and emitted
//! ([`crate::emit::emit`]). On error the expansion is a stub type plus one
//! `compile_error!` per problem, so one mistake gives one message.

use proc_macro2::{Span, TokenStream};
use quote::{quote, quote_spanned};
use syn::parse::{Parse, ParseStream};

use crate::emit::{emit, EmitOptions};
use crate::inline::Converter;
use crate::yaml::{Node, NodeKind, Scalar, ScalarStyle};

enum Source {
    File(syn::LitStr),
    Inline(proc_macro2::Group),
}

struct MacroInput {
    vis: syn::Visibility,
    name: syn::Ident,
    source: Source,
}

impl Parse for MacroInput {
    fn parse(input: ParseStream) -> syn::Result<Self> {
        let vis: syn::Visibility = input.parse()?;
        let name: syn::Ident = input.parse()?;
        let source = if input.peek(syn::Token![=]) {
            input.parse::<syn::Token![=]>()?;
            Source::File(input.parse()?)
        } else {
            let group: proc_macro2::Group = input.parse()?;
            if group.delimiter() != proc_macro2::Delimiter::Brace {
                return Err(syn::Error::new(
                    group.span(),
                    "expected `{ ... }` with the machine, or `= \"path/to/machine.yaml\"`",
                ));
            }
            Source::Inline(group)
        };
        if input.peek(syn::Token![;]) {
            input.parse::<syn::Token![;]>()?;
        }
        if !input.is_empty() {
            return Err(input.error("unexpected tokens after the machine"));
        }
        Ok(MacroInput { vis, name, source })
    }
}

/// Expands a `machine!` invocation.
pub fn expand(input: TokenStream) -> TokenStream {
    let parsed: MacroInput = match syn::parse2(input) {
        Ok(p) => p,
        Err(e) => return e.to_compile_error(),
    };
    let vis = &parsed.vis;
    let name = &parsed.name;
    let stub = quote!(#vis struct #name;);
    let (machine, tracking) = match &parsed.source {
        Source::File(lit) => {
            // `CHAIN_MACRO_MANIFEST_DIR` overrides the base directory (compile-fail
            // tests run the macro from a generated crate elsewhere).
            let dir = std::env::var("CHAIN_MACRO_MANIFEST_DIR")
                .or_else(|_| std::env::var("CARGO_MANIFEST_DIR"))
                .unwrap_or_else(|_| ".".into());
            let path = std::path::Path::new(&dir).join(lit.value());
            let bytes = match std::fs::read(&path) {
                Ok(b) => b,
                Err(e) => {
                    let msg = format!("{}: cannot read the machine file: {e}", lit.value());
                    return quote_spanned!(lit.span()=> #stub ::core::compile_error!(#msg););
                }
            };
            let shown = lit.value();
            let machine = match crate::load_bytes(&bytes, &shown) {
                Ok(m) => m,
                Err(diags) => {
                    let errors: Vec<TokenStream> = diags
                        .iter()
                        .map(|e| {
                            let msg = e.to_string();
                            quote_spanned!(lit.span()=> ::core::compile_error!(#msg);)
                        })
                        .collect();
                    return quote!(#stub #(#errors)*);
                }
            };
            let abs = path.to_string_lossy().into_owned();
            (
                machine,
                quote!(
                    const _: &[u8] = include_bytes!(#abs);
                ),
            )
        }
        Source::Inline(group) => {
            let mut conv = Converter::default();
            let mut root = match conv.mapping(group.stream(), group.span()) {
                Ok(n) => n,
                Err(e) => {
                    let msg = e.message;
                    return quote_spanned!(e.span=> #stub ::core::compile_error!(#msg););
                }
            };
            add_default_name(&mut root, &name.to_string(), &mut conv, name.span());
            match crate::load::from_tree(&root) {
                Ok(m) => (m, TokenStream::new()),
                Err(problems) => {
                    let errors: Vec<TokenStream> = problems
                        .iter()
                        .map(|(origin, problem)| {
                            let mut msg = problem.headline();
                            if !origin.key.is_empty() {
                                msg.push_str(&format!(" at key `{}`", origin.key));
                            }
                            if let Some(note) = problem.note() {
                                msg.push_str(&format!(" ({note})"));
                            }
                            let span = conv.span_of(origin.offset);
                            quote_spanned!(span=> ::core::compile_error!(#msg);)
                        })
                        .collect();
                    return quote!(#stub #(#errors)*);
                }
            }
        }
    };
    let model = crate::derive(&machine);
    let options = EmitOptions {
        type_name: name.to_string(),
        visibility: quote!(#vis),
        crate_path: quote!(::chain),
        emission: crate::emit::Emission::Macro,
    };
    let generated = emit(&model, &options);
    quote!(#generated #tracking)
}

/// Inline machines may leave out `machine:`; it defaults to the type name.
fn add_default_name(root: &mut Node, type_name: &str, conv: &mut Converter, at: Span) {
    if let NodeKind::Mapping(entries) = &mut root.kind {
        if entries.iter().any(|(k, _)| k.as_str() == Some("machine")) {
            return;
        }
        let mut snake = String::new();
        for (i, c) in type_name.chars().enumerate() {
            if c.is_ascii_uppercase() && i > 0 {
                snake.push('_');
            }
            snake.extend(c.to_lowercase());
        }
        let span = {
            conv.spans.push(at);
            crate::yaml::Span {
                offset: conv.spans.len() - 1,
                len: 1,
                line: 1,
                column: 1,
            }
        };
        let scalar = |text: String| Node {
            kind: NodeKind::Scalar(Scalar {
                text,
                style: ScalarStyle::Plain,
                verbatim: false,
            }),
            span,
        };
        entries.insert(0, (scalar("machine".into()), scalar(snake)));
    }
}

/// [`expand`], formatted with prettyplease (what `chain derive --format rust`
/// prints for a file, plus the file-tracking `include_bytes!`).
#[cfg(feature = "pretty")]
pub fn expand_pretty(input: TokenStream) -> String {
    let tokens = expand(input);
    match syn::parse2::<syn::File>(tokens.clone()) {
        Ok(file) => prettyplease::unparse(&file),
        Err(_) => tokens.to_string(),
    }
}
