//! Rust code emission: a [`SymbolicModel`] → straight-line Rust.
//!
//! One emitter serves both the `machine!` macro and `chain derive`'s Rust
//! output. The generated type has the name lists, named index constants,
//! `error`, `sensitivity` and `nominal` as inherent functions over fixed-size
//! arrays (no heap, no panics), and an implementation of
//! `chain::core::ErrorModel` so it is interchangeable with a runtime model.
//! `sin`/`cos` of each rotary variable are computed once, every monomial of
//! two or more factors is hoisted into a local, and coefficient expressions
//! that occur more than once are computed once.

use std::collections::HashMap;

use proc_macro2::{Ident, Literal, Span, TokenStream};
use quote::{format_ident, quote};

use crate::algebra::{Monomial, Poly, Symbol};
use crate::derive::SymbolicModel;
use crate::model::{Component, JointKind};

/// How to emit a model.
#[derive(Debug, Clone)]
pub struct EmitOptions {
    /// Name of the generated type.
    pub type_name: String,
    /// Visibility of the type (`pub`, `pub(crate)` or empty).
    pub visibility: TokenStream,
    /// Path of the `chain` facade crate in the generated code (default `::chain`).
    pub crate_path: TokenStream,
    /// Which functions and bodies to emit.
    pub emission: Emission,
}

/// Which form of the generated API to emit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Emission {
    /// What `chain derive` prints as Rust: the functions `error`,
    /// `sensitivity` and `nominal`, each a self-contained body (the output
    /// is pinned byte for byte by `tests/golden/`).
    Derive,
    /// What `machine!` emits: the functions of [`Emission::Derive`], the
    /// same values, plus the functions that write into the caller's storage
    /// — `sensitivity_into`, `sensitivity_flat_into`, `NONZEROS` and
    /// `sensitivity_nonzeros`, `error_into` — with bodies in which a sum and
    /// its negation, and every inner sum of the factored coefficients, are
    /// computed once. The functions `error`, `sensitivity` and the
    /// `ErrorModel` impl write through them (`docs/macro.md`).
    #[default]
    Macro,
}

impl EmitOptions {
    /// Public type named after the machine (`gantry_grinder` → `GantryGrinder`)
    /// with `::chain` as the crate path.
    pub fn for_model(model: &SymbolicModel) -> EmitOptions {
        EmitOptions {
            type_name: type_name_for(&model.machine),
            visibility: quote!(pub),
            crate_path: quote!(::chain),
            emission: Emission::Derive,
        }
    }

    /// The same options with another [`Emission`].
    #[must_use]
    pub fn with_emission(mut self, emission: Emission) -> EmitOptions {
        self.emission = emission;
        self
    }
}

/// `gantry_grinder` → `GantryGrinder`; non-identifier characters split words.
pub fn type_name_for(machine: &str) -> String {
    let mut out = String::new();
    for word in machine.split(|c: char| !c.is_ascii_alphanumeric()) {
        let mut chars = word.chars();
        if let Some(first) = chars.next() {
            out.extend(first.to_uppercase());
            out.push_str(chars.as_str());
        }
    }
    if out.is_empty() || out.starts_with(|c: char| c.is_ascii_digit()) {
        out.insert_str(0, "Machine");
    }
    out
}

/// An upper-case constant name for an identifier (`ez_x2` → `EZ_X2`).
fn const_name(prefix: &str, name: &str) -> String {
    let body: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_uppercase()
            } else {
                '_'
            }
        })
        .collect();
    format!("{prefix}{body}")
}

/// Emits the generated type as tokens.
pub fn emit(model: &SymbolicModel, options: &EmitOptions) -> TokenStream {
    let ty = Ident::new(&options.type_name, Span::call_site());
    let krate = &options.crate_path;
    let vis = &options.visibility;
    let sizes = Sizes::of(model);
    let Sizes { v, p, n } = &sizes;
    let var_names: Vec<&str> = model.variables.iter().map(|x| x.0.as_str()).collect();
    let param_names: Vec<&str> = model.parameters.iter().map(|x| x.0.as_str()).collect();
    let error_names: Vec<&str> = model.errors.iter().map(String::as_str).collect();
    let param_values = parameter_values(model);
    let index_consts = index_constants(model);
    let direct = options.emission == Emission::Macro;

    let sens = SensitivityBody::new(model, direct);
    let err = ErrorBody::new(model, direct);
    let nominal = NominalBody::new(model);
    let nom_prelude = &nominal.prelude;
    let (rot, pos) = (&nominal.rotation, &nominal.position);

    let (error_fns, sensitivity_fns, model_fns) = if direct {
        macro_functions(model, krate, &sizes, &sens, &err)
    } else {
        derive_functions(&sizes, &sens, &err)
    };

    let Docs {
        components: component_docs,
        nominal: nominal_doc,
        type_doc,
        functions: function_docs,
    } = Docs::new(model);
    let vars_doc = format!(" Axis variables, in `q` order: {}.", var_names.join(", "));
    let error_at = error_at(model, krate, &sizes);

    quote! {
        #[doc = #type_doc]
        #(#[doc = #function_docs])*
        #[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
        #vis struct #ty;

        #[allow(clippy::all, clippy::pedantic, unused_parens, unused_variables, non_snake_case)]
        impl #ty {
            #[doc = #vars_doc]
            pub const VARIABLES: [&'static str; #v] = [#(#var_names),*];
            /// Parameter names, in `p` order.
            pub const PARAMETERS: [&'static str; #p] = [#(#param_names),*];
            /// Error parameter names, in `e` order.
            pub const ERRORS: [&'static str; #n] = [#(#error_names),*];
            /// Parameter values given with the machine (`None`: supplied at run time).
            pub const PARAMETER_VALUES: [::core::option::Option<f64>; #p] = [#(#param_values),*];
            #(#index_consts)*

            /// The error vector `[px, py, pz, ox, oy, oz]`:
            ///
            #(#[doc = #component_docs])*
            #error_fns

            #error_at

            /// The sensitivity matrix `s[c][j] = ∂E_c/∂e_j` (rows `px, py, pz, ox, oy, oz`):
            ///
            #(#[doc = #component_docs])*
            #sensitivity_fns

            /// The nominal pose `R_wt(q, 0)` and `T_wt(q, 0)·tool_point`:
            ///
            #(#[doc = #nominal_doc])*
            #[inline]
            #[must_use]
            pub fn nominal(q: &[f64; #v], p: &[f64; #p]) -> ([[f64; 3]; 3], [f64; 3]) {
                #nom_prelude
                ([#(#rot),*], [#(#pos),*])
            }
        }

        impl #krate::core::ErrorModel for #ty {
            fn variables(&self) -> &[&str] {
                &Self::VARIABLES
            }
            fn parameters(&self) -> &[&str] {
                &Self::PARAMETERS
            }
            fn errors(&self) -> &[&str] {
                &Self::ERRORS
            }
            #model_fns
            fn nominal(&self, q: &[f64], p: &[f64]) -> #krate::core::Pose {
                match (<&[f64; #v]>::try_from(q), <&[f64; #p]>::try_from(p)) {
                    (Ok(q), Ok(p)) => {
                        let (rotation, position) = Self::nominal(q, p);
                        #krate::core::Pose { rotation, position }
                    }
                    _ => #krate::core::Pose {
                        rotation: [[f64::NAN; 3]; 3],
                        position: [f64::NAN; 3],
                    },
                }
            }
        }
    }
}

/// The array lengths of the generated signatures: `q` (variables), `p`
/// (parameters) and `e` (errors), as literals.
struct Sizes {
    v: Literal,
    p: Literal,
    n: Literal,
}

impl Sizes {
    fn of(model: &SymbolicModel) -> Sizes {
        Sizes {
            v: lit(model.variables.len()),
            p: lit(model.parameters.len()),
            n: lit(model.errors.len()),
        }
    }
}

/// `PARAMETER_VALUES`: each parameter's value given with the machine
/// (`Some`), or `None` for one supplied at run time (or not finite).
fn parameter_values(model: &SymbolicModel) -> Vec<TokenStream> {
    model
        .parameters
        .iter()
        .map(|(_, value)| match value {
            Some(x) if x.is_finite() => {
                let lit = Literal::f64_unsuffixed(*x);
                quote!(::core::option::Option::Some(#lit))
            }
            _ => quote!(::core::option::Option::None),
        })
        .collect()
}

/// `value` or `-value`.
fn signed(negative: bool, e: &TokenStream) -> TokenStream {
    if negative {
        quote!(-#e)
    } else {
        quote!(#e)
    }
}

/// The sensitivity matrix's body: every non-zero coefficient (under
/// [`Emission::Macro`] the identically zero ones left out) as a signed
/// expression over the body's locals.
struct SensitivityBody<'a> {
    body: Body<'a>,
    /// `(row, error index, negated, expression)` per emitted entry, row-major.
    entries: Vec<(usize, usize, bool, TokenStream)>,
    /// `s[c][j] = value;` per entry.
    assign: Vec<TokenStream>,
    /// The body's `let` statements.
    prelude: TokenStream,
}

impl<'a> SensitivityBody<'a> {
    fn new(model: &'a SymbolicModel, direct: bool) -> SensitivityBody<'a> {
        let polys: Vec<(usize, usize, &Poly)> = model
            .components
            .iter()
            .enumerate()
            .flat_map(|(c, entries)| entries.iter().map(move |(j, poly)| (c, *j, poly)))
            .collect();
        let mut body = Body::new(model, direct);
        let entries: Vec<(usize, usize, bool, TokenStream)> = polys
            .iter()
            .filter(|(_, _, poly)| !(direct && poly.is_zero()))
            .map(|(c, j, poly)| {
                let (negative, e) = body.signed(poly);
                (*c, *j, negative, e)
            })
            .collect();
        let assign: Vec<TokenStream> = entries
            .iter()
            .map(|(c, j, negative, e)| {
                let value = signed(*negative, e);
                let (c, j) = (lit(*c), lit(*j));
                quote!(s[#c][#j] = #value;)
            })
            .collect();
        let prelude = body.prelude();
        SensitivityBody {
            body,
            entries,
            assign,
            prelude,
        }
    }
}

/// The error vector's body: one row expression `Σ_j coefficient · e[j]`
/// per component (`0.0` for a component without errors).
struct ErrorBody<'a> {
    body: Body<'a>,
    /// The expression of each component, in [`Component::ALL`] order.
    rows: Vec<TokenStream>,
    /// The body's `let` statements.
    prelude: TokenStream,
}

impl<'a> ErrorBody<'a> {
    fn new(model: &'a SymbolicModel, direct: bool) -> ErrorBody<'a> {
        let mut body = Body::new(model, direct);
        let rows: Vec<TokenStream> = Component::ALL
            .iter()
            .map(|c| {
                let mut row = TokenStream::new();
                for (k, (j, poly)) in model.components[c.index()].iter().enumerate() {
                    let (negative, ex) = body.signed(poly);
                    let j = lit(*j);
                    let factor = if ex.to_string() == "1.0" {
                        quote!(e[#j])
                    } else {
                        quote!(#ex * e[#j])
                    };
                    row.extend(match (k, negative) {
                        (0, false) => quote!(#factor),
                        (0, true) => quote!(-#factor),
                        (_, false) => quote!(+ #factor),
                        (_, true) => quote!(- #factor),
                    });
                }
                if row.is_empty() {
                    quote!(0.0)
                } else {
                    row
                }
            })
            .collect();
        let prelude = body.prelude();
        ErrorBody {
            body,
            rows,
            prelude,
        }
    }
}

/// The nominal pose's body: the rotation's rows and the position.
struct NominalBody {
    /// `[r0, r1, r2]` per row.
    rotation: Vec<TokenStream>,
    /// The tool point's coordinates.
    position: Vec<TokenStream>,
    /// The body's `let` statements.
    prelude: TokenStream,
}

impl NominalBody {
    fn new(model: &SymbolicModel) -> NominalBody {
        let mut nom = Body::new(model, false);
        let rotation: Vec<TokenStream> = model
            .nominal_rotation
            .iter()
            .map(|row| {
                let cells: Vec<TokenStream> = row.iter().map(|x| nom.expr(x)).collect();
                quote!([#(#cells),*])
            })
            .collect();
        let position: Vec<TokenStream> =
            model.nominal_position.iter().map(|x| nom.expr(x)).collect();
        let prelude = nom.prelude();
        NominalBody {
            rotation,
            position,
            prelude,
        }
    }
}

/// The functions of [`Emission::Macro`]: the inherent `error` and
/// `error_into`; `sensitivity`, the `*_into` writers, `NONZEROS` and
/// `sensitivity_nonzeros`, with the batched kernels ([`batch_functions`]);
/// and the `ErrorModel` methods that write through them.
/// The stores of a sensitivity into `out`: every one of the `6 × n`
/// entries of the dense layout (a zero written where no entry is), and the
/// non-zero `entries` (`(component, error, negative, expression)`) in their
/// order, the sparse layout. The one rule of the `machine!` type's kernels
/// and its batched ones.
fn sensitivity_stores(
    n: usize,
    entries: &[(usize, usize, bool, TokenStream)],
) -> (Vec<TokenStream>, Vec<TokenStream>) {
    let store = |k: usize, value: &TokenStream| {
        let k = lit(k);
        quote!(out[#k] = #value;)
    };
    let mut flat: Vec<TokenStream> = vec![quote!(0.0); 6 * n];
    for (c, j, negative, e) in entries {
        flat[c * n + j] = signed(*negative, e);
    }
    let dense = flat.iter().enumerate().map(|(k, v)| store(k, v)).collect();
    let sparse = (entries.iter().enumerate())
        .map(|(k, (_, _, negative, e))| store(k, &signed(*negative, e)))
        .collect();
    (dense, sparse)
}

fn macro_functions(
    model: &SymbolicModel,
    krate: &TokenStream,
    sizes: &Sizes,
    sens: &SensitivityBody<'_>,
    err: &ErrorBody<'_>,
) -> (TokenStream, TokenStream, TokenStream) {
    let Sizes { v, p, n } = sizes;
    let (err_prelude, sens_prelude) = (&err.prelude, &sens.prelude);
    let sens_assign = &sens.assign;
    let sens_entries = &sens.entries;
    let total = 6 * model.errors.len();
    let (flat_stores, nonzero_stores) = sensitivity_stores(model.errors.len(), sens_entries);
    let nonzeros = sens_entries.iter().map(|(c, j, _, _)| {
        let (c, j) = (lit(*c), lit(*j));
        quote!((#c, #j))
    });
    let k = lit(sens_entries.len());
    let total = lit(total);
    let error_stores = err.rows.iter().enumerate().map(|(c, row)| {
        let c = lit(c);
        quote!(out[#c] = #row;)
    });
    let error_fns = quote! {
        #[inline]
        #[must_use]
        pub fn error(q: &[f64; #v], p: &[f64; #p], e: &[f64; #n]) -> [f64; 6] {
            let mut out = [0.0f64; 6];
            Self::error_into(q, p, e, &mut out);
            out
        }

        /// [`Self::error`] written into `out` (every component).
        #[inline]
        pub fn error_into(q: &[f64; #v], p: &[f64; #p], e: &[f64; #n], out: &mut [f64; 6]) {
            #err_prelude
            #(#error_stores)*
        }
    };
    let sensitivity_fns = quote! {
        #[inline]
        #[must_use]
        pub fn sensitivity(q: &[f64; #v], p: &[f64; #p]) -> [[f64; #n]; 6] {
            // Its own body: zero-filling a returned array and then calling
            // `sensitivity_into` over it measured 1.5× slower.
            #sens_prelude
            let mut s = [[0.0f64; #n]; 6];
            #(#sens_assign)*
            s
        }

        /// [`Self::sensitivity`] written into `out`: every entry, the
        /// structural zeros included (no zero-filling needed, no copy).
        #[inline]
        pub fn sensitivity_into(q: &[f64; #v], p: &[f64; #p], out: &mut [[f64; #n]; 6]) {
            // `6 × N` elements: the conversion cannot fail.
            if let ::core::result::Result::Ok(flat) =
                <&mut [f64; #total]>::try_from(out.as_flattened_mut())
            {
                Self::sensitivity_flat_into(q, p, flat);
            }
        }

        /// [`Self::sensitivity`] written row-major into `out`
        /// (`out[c * N + j] = ∂E_c/∂e_j`), every entry in index order.
        #[inline]
        pub fn sensitivity_flat_into(q: &[f64; #v], p: &[f64; #p], out: &mut [f64; #total]) {
            #sens_prelude
            #(#flat_stores)*
        }

        /// The entries of the sensitivity matrix that are not identically
        /// zero, `(row, error index)`, row-major: the order of
        /// [`Self::sensitivity_nonzeros`]. Every other entry is exactly 0.
        pub const NONZEROS: [(usize, usize); #k] = [#(#nonzeros),*];

        /// The entries [`Self::NONZEROS`] of the sensitivity matrix, in
        /// that order: `out[k] = s[NONZEROS[k].0][NONZEROS[k].1]`.
        #[inline]
        pub fn sensitivity_nonzeros(q: &[f64; #v], p: &[f64; #p], out: &mut [f64; #k]) {
            #sens_prelude
            #(#nonzero_stores)*
        }
    };
    let batch_fns = batch_functions(
        model,
        krate,
        (&sens.body, sens_entries),
        (&err.body, &err.rows),
    );
    let model_fns = quote! {
        fn error(&self, q: &[f64], p: &[f64], e: &[f64], out: &mut [f64; 6]) {
            match (
                <&[f64; #v]>::try_from(q),
                <&[f64; #p]>::try_from(p),
                <&[f64; #n]>::try_from(e),
            ) {
                (Ok(q), Ok(p), Ok(e)) => Self::error_into(q, p, e, out),
                _ => *out = [f64::NAN; 6],
            }
        }
        fn sensitivity(&self, q: &[f64], p: &[f64], out: &mut [f64]) {
            match (<&[f64; #v]>::try_from(q), <&[f64; #p]>::try_from(p)) {
                (Ok(q), Ok(p)) => match <&mut [f64; #total]>::try_from(&mut *out) {
                    Ok(flat) => Self::sensitivity_flat_into(q, p, flat),
                    // A slice of another length (the trait asks for 6 × N):
                    // the entries that fit.
                    Err(_) => {
                        let s = Self::sensitivity(q, p);
                        for (slot, value) in out.iter_mut().zip(s.iter().flatten()) {
                            *slot = *value;
                        }
                    }
                },
                _ => out.iter_mut().for_each(|slot| *slot = f64::NAN),
            }
        }
        fn sparsity(&self) -> ::core::option::Option<&[(usize, usize)]> {
            ::core::option::Option::Some(&Self::NONZEROS)
        }
        fn sensitivity_nonzeros(&self, q: &[f64], p: &[f64], out: &mut [f64]) -> bool {
            match (
                <&[f64; #v]>::try_from(q),
                <&[f64; #p]>::try_from(p),
                <&mut [f64; #k]>::try_from(out),
            ) {
                (Ok(q), Ok(p), Ok(out)) => {
                    Self::sensitivity_nonzeros(q, p, out);
                    true
                }
                _ => false,
            }
        }
    };
    let (batch_fns, batch_model_fns) = batch_fns;
    let sensitivity_fns = quote!(#sensitivity_fns #batch_fns);
    let model_fns = quote!(#model_fns #batch_model_fns);
    (error_fns, sensitivity_fns, model_fns)
}

/// The functions of [`Emission::Derive`]: the inherent `error` and
/// `sensitivity`, each a self-contained body, and the `ErrorModel` methods
/// that call them.
fn derive_functions(
    sizes: &Sizes,
    sens: &SensitivityBody<'_>,
    err: &ErrorBody<'_>,
) -> (TokenStream, TokenStream, TokenStream) {
    let Sizes { v, p, n } = sizes;
    let (err_prelude, sens_prelude) = (&err.prelude, &sens.prelude);
    let (err_rows, sens_assign) = (&err.rows, &sens.assign);
    let error_fns = quote! {
        #[inline]
        #[must_use]
        pub fn error(q: &[f64; #v], p: &[f64; #p], e: &[f64; #n]) -> [f64; 6] {
            #err_prelude
            [#(#err_rows),*]
        }
    };
    let sensitivity_fns = quote! {
        #[inline]
        #[must_use]
        pub fn sensitivity(q: &[f64; #v], p: &[f64; #p]) -> [[f64; #n]; 6] {
            #sens_prelude
            let mut s = [[0.0f64; #n]; 6];
            #(#sens_assign)*
            s
        }
    };
    let model_fns = quote! {
        fn error(&self, q: &[f64], p: &[f64], e: &[f64], out: &mut [f64; 6]) {
            *out = match (
                <&[f64; #v]>::try_from(q),
                <&[f64; #p]>::try_from(p),
                <&[f64; #n]>::try_from(e),
            ) {
                (Ok(q), Ok(p), Ok(e)) => Self::error(q, p, e),
                _ => [f64::NAN; 6],
            };
        }
        fn sensitivity(&self, q: &[f64], p: &[f64], out: &mut [f64]) {
            match (<&[f64; #v]>::try_from(q), <&[f64; #p]>::try_from(p)) {
                (Ok(q), Ok(p)) => {
                    let s = Self::sensitivity(q, p);
                    for (slot, value) in out.iter_mut().zip(s.iter().flatten()) {
                        *slot = *value;
                    }
                }
                _ => out.iter_mut().for_each(|slot| *slot = f64::NAN),
            }
        }
    };
    (error_fns, sensitivity_fns, model_fns)
}

/// The doc lines of the generated type and its functions.
struct Docs {
    /// ` - `px = …`` per component: the error and sensitivity functions'.
    components: Vec<String>,
    /// The nominal rotation's rows and the position: `nominal`'s.
    nominal: Vec<String>,
    /// The type's first line.
    type_doc: String,
    /// The function slots' definitions (none without function slots).
    functions: Vec<String>,
}

impl Docs {
    fn new(model: &SymbolicModel) -> Docs {
        let text = |poly: &Poly| poly.to_text(&|s| model.symbol_name(s));
        let components: Vec<String> = Component::ALL
            .iter()
            .map(|c| {
                let terms: Vec<(bool, String)> = model.components[c.index()]
                    .iter()
                    .map(|(j, poly)| crate::export::term(&text(poly), &model.errors[*j]))
                    .collect();
                let rhs = crate::export::join_terms(&terms, (" + ", " - "));
                format!(" - `{} = {}`", c.name(), rhs)
            })
            .collect();
        let nominal: Vec<String> = model
            .nominal_rotation
            .iter()
            .map(|row| {
                let cells: Vec<String> = row.iter().map(&text).collect();
                format!(" - `R` row: `[{}]`", cells.join(", "))
            })
            .chain(std::iter::once(format!(
                " - position: `[{}]`",
                model
                    .nominal_position
                    .iter()
                    .map(&text)
                    .collect::<Vec<_>>()
                    .join(", ")
            )))
            .collect();
        let type_doc = format!(
            " First-order error model of machine `{}` (frame: {}), generated by `chain`.",
            model.machine,
            model.frame.name()
        );
        // Function slots: their definitions in the type's docs. Machines
        // without function slots have none.
        let functions: Vec<String> = if model.functions.is_empty() {
            Vec::new()
        } else {
            std::iter::once(String::new())
                .chain(std::iter::once(
                    " Error motions that vary along their axis (their coefficients are errors):"
                        .to_string(),
                ))
                .chain(
                    model
                        .functions
                        .iter()
                        .map(|f| format!(" - `{}`", crate::export::function_text(model, f))),
                )
                .collect()
        };
        Docs {
            components,
            nominal,
            type_doc,
            functions,
        }
    }
}

/// `error_at` of a model with function slots: a built machine's error from
/// error values that vary along the axes (nothing for a model without
/// function slots).
fn error_at(model: &SymbolicModel, krate: &TokenStream, sizes: &Sizes) -> TokenStream {
    if model.functions.is_empty() {
        return TokenStream::new();
    }
    let Sizes { v, p, n } = sizes;
    quote! {
        /// The error `[px, py, pz, ox, oy, oz]` of a built machine at `q`:
        /// `E(q) = Σ_j c_j(q)·v_j(q)`, with the error values `v(q)` from
        /// `values` (a closure `|q: &[f64], e: &mut [f64]| …` or any
        /// `ErrorValues`, e.g. a values file) in `ERRORS` order; the
        /// scratch is a stack array.
        ///
        /// # Errors
        ///
        /// `OutOfRange` when `values` has no value at `q` (a measured
        /// table that does not cover it).
        #[inline]
        pub fn error_at(
            q: &[f64; #v],
            p: &[f64; #p],
            values: &(impl #krate::core::ErrorValues + ?Sized),
        ) -> ::core::result::Result<[f64; 6], #krate::core::OutOfRange> {
            let mut e = [0.0f64; #n];
            #krate::core::ErrorValues::values_at(values, q, &mut e)?;
            ::core::result::Result::Ok(Self::error(q, p, &e))
        }
    }
}

/// Emits the generated type as formatted Rust source (prettyplease).
#[cfg(feature = "pretty")]
pub fn emit_pretty(model: &SymbolicModel, options: &EmitOptions) -> String {
    let tokens = emit(model, options);
    match syn::parse2::<syn::File>(tokens.clone()) {
        Ok(file) => prettyplease::unparse(&file),
        Err(_) => tokens.to_string(),
    }
}

/// The batched kernels of [`Emission::Macro`] (docs/macro.md,
/// "The generated type"): `sensitivity_batch_into`,
/// `sensitivity_nonzeros_batch_into`, `error_batch_into` and
/// `error_batch_each_into` over slices of points, and the `ErrorModel`
/// batch methods (`sensitivity_points`, `error_points`) through them.
///
/// Points go in groups of [`crate::lanes::LANES`]: `sin`/`cos` of each
/// rotary variable for the whole group at once with the vectorised
/// [`crate::lanes::sin_cos`], then the per-point body with those values
/// (`*_given` functions: the statements of the per-point functions, `sin`
/// and `cos` read from `sc`). A body of lane vectors throughout measured
/// slower than this (docs/performance.md, "Batched generated kernels"):
/// the per-point bodies' stores of adjacent entries merge into vector
/// stores, which lanes of different points cannot. Returns the inherent
/// functions and the trait methods.
fn batch_functions(
    model: &SymbolicModel,
    krate: &TokenStream,
    (sens, sens_entries): (&Body<'_>, &[(usize, usize, bool, TokenStream)]),
    (err, err_rows): (&Body<'_>, &[TokenStream]),
) -> (TokenStream, TokenStream) {
    let lanes = quote!(#krate::core::lanes);
    let (nv, np, n) = (
        model.variables.len(),
        model.parameters.len(),
        model.errors.len(),
    );
    let (v, p_len, n_len) = (lit(nv), lit(np), lit(n));
    let width = 6 * n;
    let k = sens_entries.len();
    let (flat_stores, nz_stores) = sensitivity_stores(n, sens_entries);
    let err_stores = err_rows.iter().enumerate().map(|(c, row)| {
        let c = lit(c);
        quote!(out[#c] = #row;)
    });
    let sens_prelude = sens.prelude_given_sin_cos();
    let err_prelude = err.prelude_given_sin_cos();
    // `sin`/`cos` of four points of each rotary variable `k` into `sc[l][k]`.
    let lane_sin_cos = |rotary: Vec<usize>| {
        let ks = rotary.into_iter().map(lit);
        quote! {
            let mut sc = [[[0.0f64; 2]; #v]; 4];
            #(
                let (s, c) = #lanes::sin_cos(#lanes::load(q4, #ks));
                for l in 0..4 {
                    sc[l][#ks] = [s[l], c[l]];
                }
            )*
        }
    };
    let (w, k_lit) = (lit(width), lit(k));
    // One group of four points over a flat output: whole groups in place,
    // the last partial group through a padded copy. `$per` writes one
    // point's `$width` values.
    let over = |name: &str, width: &TokenStream, rotary: Vec<usize>, call: TokenStream| {
        let name = Ident::new(name, Span::call_site());
        let loops = if rotary.is_empty() {
            // No `sin`/`cos` to share: point after point, `q` in place.
            quote! {
                let sc = &[[0.0f64; 2]; #v];
                for (i, o) in out.chunks_mut(#width).enumerate() {
                    let e = if broadcast {
                        es
                    } else {
                        es.get(i * #n_len..).unwrap_or(&[])
                    };
                    let _ = e;
                    if let (::core::option::Option::Some(q), ::core::result::Result::Ok(o)) = (
                        #lanes::row::<#v>(qs.get(i * #v..).unwrap_or(&[])),
                        <&mut [f64; #width]>::try_from(o),
                    ) {
                        #call
                    }
                }
            }
        } else {
            let sc = lane_sin_cos(rotary);
            quote! {
                for (g, group) in out.chunks_mut(4 * #width).enumerate() {
                    let q4 = &#lanes::points::<#v>(qs.get(g * 4 * #v..).unwrap_or(&[]));
                    #sc
                    for (l, o) in group.chunks_mut(#width).enumerate() {
                        let e = if broadcast {
                            es
                        } else {
                            es.get((4 * g + l) * #n_len..).unwrap_or(&[])
                        };
                        let _ = e;
                        let (q, sc) = (&q4[l], &sc[l]);
                        if let ::core::result::Result::Ok(o) = <&mut [f64; #width]>::try_from(o) {
                            #call
                        }
                    }
                }
            }
        };
        quote! {
            /// Every point of `qs` (flat, `V` values each) into `out` (its
            /// length gives the number of points; the callers check that
            /// it holds whole points, so every chunk converts): `sin`/`cos`
            /// for four points at a time when the body has rotary
            /// variables, then the per-point body.
            fn #name(qs: &[f64], p: &[f64; #p_len], es: &[f64], broadcast: bool, out: &mut [f64]) {
                if #width == 0 {
                    return;
                }
                let _ = (es, broadcast);
                #loops
            }
        }
    };
    let sens_over = over(
        "sensitivity_lanes_over",
        &quote!(#w),
        sens.rotary(),
        quote!(Self::sensitivity_given(q, p, sc, o);),
    );
    let nz_over = over(
        "nonzeros_lanes_over",
        &quote!(#k_lit),
        sens.rotary(),
        quote!(Self::nonzeros_given(q, p, sc, o);),
    );
    let err_over = over(
        "error_lanes_over",
        &quote!(6),
        err.rotary(),
        quote! {
            if let ::core::option::Option::Some(e) = #lanes::row::<#n_len>(e) {
                Self::error_given(q, p, sc, e, o);
            }
        },
    );

    let inherent = quote! {
        /// The sensitivity matrices at many points: `out[i]` is
        /// [`Self::sensitivity`] at `qs[i]` (every entry written). Four
        /// points at a time: `sin`/`cos` of the rotary variables by the
        /// vectorised kernel of `chain_core::lanes` (≤ 2 ulp from the
        /// standard library's, so values agree with the per-point
        /// functions to rounding, not bit for bit).
        ///
        /// # Panics
        /// When `out.len() != qs.len()`.
        #[inline]
        pub fn sensitivity_batch_into(qs: &[[f64; #v]], p: &[f64; #p_len], out: &mut [[[f64; #n_len]; 6]]) {
            assert!(
                qs.len() == out.len(),
                "sensitivity_batch_into: {} points but {} output matrices",
                qs.len(),
                out.len()
            );
            Self::sensitivity_lanes_over(qs.as_flattened(), p, &[], true, out.as_flattened_mut().as_flattened_mut());
        }

        /// [`Self::sensitivity_nonzeros`] at many points: `out[i]` holds the
        /// entries [`Self::NONZEROS`] at `qs[i]`, four points at a time as
        /// [`Self::sensitivity_batch_into`].
        ///
        /// # Panics
        /// When `out.len() != qs.len()`.
        #[inline]
        pub fn sensitivity_nonzeros_batch_into(qs: &[[f64; #v]], p: &[f64; #p_len], out: &mut [[f64; #k_lit]]) {
            assert!(
                qs.len() == out.len(),
                "sensitivity_nonzeros_batch_into: {} points but {} output rows",
                qs.len(),
                out.len()
            );
            Self::nonzeros_lanes_over(qs.as_flattened(), p, &[], true, out.as_flattened_mut());
        }

        /// [`Self::error`] at many points with one error vector `e` for all
        /// of them (a built machine's errors along a path or a grid), four
        /// points at a time as [`Self::sensitivity_batch_into`].
        ///
        /// # Panics
        /// When `out.len() != qs.len()`.
        #[inline]
        pub fn error_batch_into(qs: &[[f64; #v]], p: &[f64; #p_len], e: &[f64; #n_len], out: &mut [[f64; 6]]) {
            assert!(
                qs.len() == out.len(),
                "error_batch_into: {} points but {} output rows",
                qs.len(),
                out.len()
            );
            Self::error_lanes_over(qs.as_flattened(), p, e, true, out.as_flattened_mut());
        }

        /// [`Self::error`] at many points, each with its own error vector:
        /// `out[i]` is the error at `qs[i]` with `es[i]` (sampled errors).
        ///
        /// # Panics
        /// When `es.len()` or `out.len()` differs from `qs.len()`.
        #[inline]
        pub fn error_batch_each_into(qs: &[[f64; #v]], p: &[f64; #p_len], es: &[[f64; #n_len]], out: &mut [[f64; 6]]) {
            assert!(
                qs.len() == out.len() && qs.len() == es.len(),
                "error_batch_each_into: {} points, {} error vectors and {} output rows",
                qs.len(),
                es.len(),
                out.len()
            );
            Self::error_lanes_over(qs.as_flattened(), p, es.as_flattened(), false, out.as_flattened_mut());
        }

        /// [`Self::sensitivity_flat_into`] with `sin`/`cos` of each rotary
        /// variable `k` given as `sc[k]`.
        #[inline(always)]
        fn sensitivity_given(q: &[f64; #v], p: &[f64; #p_len], sc: &[[f64; 2]; #v], out: &mut [f64; #w]) {
            #sens_prelude
            #(#flat_stores)*
        }

        /// [`Self::sensitivity_nonzeros`] with `sin`/`cos` given.
        #[inline(always)]
        fn nonzeros_given(q: &[f64; #v], p: &[f64; #p_len], sc: &[[f64; 2]; #v], out: &mut [f64; #k_lit]) {
            #sens_prelude
            #(#nz_stores)*
        }

        /// [`Self::error_into`] with `sin`/`cos` given.
        #[inline(always)]
        fn error_given(q: &[f64; #v], p: &[f64; #p_len], sc: &[[f64; 2]; #v], e: &[f64; #n_len], out: &mut [f64; 6]) {
            #err_prelude
            #(#err_stores)*
        }

        #sens_over
        #nz_over
        #err_over
    };
    let trait_fns = quote! {
        fn sensitivity_points(
            &self,
            qs: &[f64],
            p: &[f64],
            out: &mut [f64],
        ) -> ::core::result::Result<(), #krate::core::BatchError> {
            #lanes::sensitivity_shape(#v, #n_len, qs.len(), out.len())?;
            match <&[f64; #p_len]>::try_from(p) {
                ::core::result::Result::Ok(p) => Self::sensitivity_lanes_over(qs, p, &[], true, out),
                ::core::result::Result::Err(_) => out.iter_mut().for_each(|slot| *slot = f64::NAN),
            }
            ::core::result::Result::Ok(())
        }
        fn error_points(
            &self,
            qs: &[f64],
            p: &[f64],
            es: &[f64],
            out: &mut [f64],
        ) -> ::core::result::Result<(), #krate::core::BatchError> {
            let broadcast = #lanes::error_shape(#v, #n_len, qs.len(), es.len(), out.len())?;
            match <&[f64; #p_len]>::try_from(p) {
                ::core::result::Result::Ok(p) => Self::error_lanes_over(qs, p, es, broadcast, out),
                ::core::result::Result::Err(_) => out.iter_mut().for_each(|slot| *slot = f64::NAN),
            }
            ::core::result::Result::Ok(())
        }
    };
    (inherent, trait_fns)
}

fn index_constants(model: &SymbolicModel) -> Vec<TokenStream> {
    let mut seen: HashMap<String, usize> = HashMap::new();
    let mut out = Vec::new();
    let groups: [(&str, Vec<&str>, &str); 3] = [
        (
            "VAR_",
            model.variables.iter().map(|v| v.0.as_str()).collect(),
            "axis variable",
        ),
        (
            "PARAM_",
            model.parameters.iter().map(|v| v.0.as_str()).collect(),
            "parameter",
        ),
        (
            "ERR_",
            model.errors.iter().map(String::as_str).collect(),
            "error parameter",
        ),
    ];
    for (prefix, names, what) in groups {
        for (i, name) in names.iter().enumerate() {
            let mut c = const_name(prefix, name);
            let count = seen.entry(c.clone()).or_insert(0);
            *count += 1;
            if *count > 1 {
                c = format!("{c}_{i}");
            }
            let ident = Ident::new(&c, Span::call_site());
            let doc = format!(" Index of the {what} `{name}`.");
            let i = lit(i);
            out.push(quote! {
                #[doc = #doc]
                pub const #ident: usize = #i;
            });
        }
    }
    out
}

/// Collects the hoisted locals of one generated function body.
struct Body<'a> {
    model: &'a SymbolicModel,
    symbols: Vec<Symbol>,
    monomials: Vec<(Monomial, Ident, TokenStream)>,
    monomial_index: HashMap<Monomial, Ident>,
    shared: HashMap<String, (Ident, TokenStream, usize)>,
    shared_order: Vec<String>,
    /// [`Emission::Macro`]: a sum and its negation share one local, and the
    /// inner sums of the factored form are shared too.
    direct: bool,
}

impl<'a> Body<'a> {
    fn new(model: &'a SymbolicModel, direct: bool) -> Body<'a> {
        Body {
            direct,
            model,
            symbols: Vec::new(),
            monomials: Vec::new(),
            monomial_index: HashMap::new(),
            shared: HashMap::new(),
            shared_order: Vec::new(),
        }
    }

    fn symbol(&mut self, s: Symbol) -> Ident {
        if !self.symbols.contains(&s) {
            self.symbols.push(s);
        }
        symbol_ident_in(self.model, s)
    }

    fn monomial(&mut self, m: &Monomial) -> TokenStream {
        if m.0.len() == 1 && m.0[0].1 == 1 {
            let id = self.symbol(m.0[0].0);
            return quote!(#id);
        }
        if let Some(id) = self.monomial_index.get(m) {
            return quote!(#id);
        }
        let Some((parent, sym)) = m.split_last() else {
            return quote!(1.0);
        };
        let a = self.monomial(&parent);
        let b = self.symbol(sym);
        let id = format_ident!("m{}", self.monomials.len());
        self.monomials
            .push((m.clone(), id.clone(), quote!(#a * #b)));
        self.monomial_index.insert(m.clone(), id.clone());
        quote!(#id)
    }

    fn poly_tokens(&mut self, poly: &Poly) -> TokenStream {
        if poly.is_zero() {
            return quote!(0.0);
        }
        self.horner(poly.terms().to_vec())
    }

    /// A sum of terms, factored greedily (multivariate Horner): the symbol
    /// that occurs in the most terms is taken out, `s·(…) + (…)`, recursively.
    /// Kinematic coefficients share `sin`/`cos` factors, so this saves most of
    /// the multiplications of the expanded form.
    fn horner(&mut self, terms: Vec<(Monomial, f64)>) -> TokenStream {
        let mut counts: Vec<(Symbol, usize)> = Vec::new();
        for (m, _) in &terms {
            for &(s, _) in &m.0 {
                match counts.iter_mut().find(|(t, _)| *t == s) {
                    Some((_, n)) => *n += 1,
                    None => counts.push((s, 1)),
                }
            }
        }
        let best = counts
            .iter()
            .filter(|(_, n)| *n >= 2)
            .max_by_key(|(s, n)| (*n, std::cmp::Reverse(*s)))
            .map(|(s, _)| *s);
        let Some(sym) = best else {
            return self.plain_sum(&terms);
        };
        let (with, without): (Vec<_>, Vec<_>) = terms
            .into_iter()
            .partition(|(m, _)| m.0.iter().any(|&(s, _)| s == sym));
        let reduced: Vec<(Monomial, f64)> = with
            .into_iter()
            .map(|(m, c)| {
                let rest: Vec<(Symbol, u16)> =
                    m.0.iter()
                        .filter_map(|&(s, e)| match (s == sym, e) {
                            (true, 1) => None,
                            (true, e) => Some((s, e - 1)),
                            _ => Some((s, e)),
                        })
                        .collect();
                (Monomial(rest), c)
            })
            .collect();
        let id = self.symbol(sym);
        let inner = if self.direct && reduced.len() > 1 {
            // The inner sum is parenthesised, so a shared local computes
            // exactly the same value (a negated one: the same magnitude).
            let (negative, local) = self.shared_signed(reduced);
            if negative {
                quote!(-#local)
            } else {
                local
            }
        } else {
            self.horner(reduced)
        };
        if without.is_empty() {
            quote!(#id * (#inner))
        } else {
            let rest = self.horner(without);
            if rest.to_string().starts_with('-') {
                quote!(#id * (#inner) #rest)
            } else {
                quote!(#id * (#inner) + #rest)
            }
        }
    }

    /// `c1·m1 ± c2·m2 …` without factoring, monomials hoisted.
    fn plain_sum(&mut self, terms: &[(Monomial, f64)]) -> TokenStream {
        let mut out = TokenStream::new();
        for (k, (m, c)) in terms.iter().enumerate() {
            let negative = *c < 0.0;
            let mag = c.abs();
            let sign = match (k, negative) {
                (0, true) => quote!(-),
                (0, false) => quote!(),
                (_, true) => quote!(-),
                (_, false) => quote!(+),
            };
            let term = if m.is_one() {
                let lit = Literal::f64_unsuffixed(mag);
                quote!(#lit)
            } else {
                let mono = self.monomial(m);
                if mag == 1.0 {
                    mono
                } else {
                    let lit = Literal::f64_unsuffixed(mag);
                    quote!(#lit * #mono)
                }
            };
            out.extend(quote!(#sign #term));
        }
        out
    }

    /// The expression of a polynomial with a leading minus split off, so that
    /// `-y` emits as `-v_y` and `-1` as a negated unit.
    fn signed(&mut self, poly: &Poly) -> (bool, TokenStream) {
        if let [(m, c)] = poly.terms() {
            let single = Poly::from_terms(vec![(m.clone(), c.abs())]);
            return (*c < 0.0, self.poly_tokens(&single));
        }
        if self.direct {
            return self.shared_signed(poly.terms().to_vec());
        }
        (false, self.expr(poly))
    }

    /// A multi-term polynomial as a shared local up to its sign: `P` and `−P`
    /// are one local (the one whose first term is positive), returned with
    /// `true` when `poly` is its negation. Negation is exact in IEEE 754
    /// (round to nearest is symmetric), so `−k` has the bits of `−P` computed
    /// directly, but for the sign of a zero result.
    fn shared_signed(&mut self, terms: Vec<(Monomial, f64)>) -> (bool, TokenStream) {
        // The terms as they are (no re-sorting, no `sin²` folding): the local
        // must evaluate exactly what the inline form did.
        let negative = terms.first().is_some_and(|(_, c)| *c < 0.0);
        let canonical: Vec<(Monomial, f64)> = if negative {
            terms.into_iter().map(|(m, c)| (m, -c)).collect()
        } else {
            terms
        };
        let key = format!("{canonical:?}");
        if let Some((id, _, uses)) = self.shared.get_mut(&key) {
            *uses += 1;
            let id = id.clone();
            return (negative, quote!(#id));
        }
        let body = self.horner(canonical);
        let id = format_ident!("k{}", self.shared_order.len());
        self.shared.insert(key.clone(), (id.clone(), body, 1));
        self.shared_order.push(key);
        (negative, quote!(#id))
    }

    /// The expression of a polynomial; repeated multi-term polynomials are
    /// hoisted into a shared local.
    fn expr(&mut self, poly: &Poly) -> TokenStream {
        let single = poly.terms().len() <= 1;
        let body = self.poly_tokens(poly);
        if single {
            return body;
        }
        let key = poly.to_text(&|s| self.model.symbol_name(s));
        if let Some((id, _, uses)) = self.shared.get_mut(&key) {
            *uses += 1;
            let id = id.clone();
            return quote!(#id);
        }
        let id = format_ident!("k{}", self.shared_order.len());
        self.shared.insert(key.clone(), (id.clone(), body, 1));
        self.shared_order.push(key);
        quote!(#id)
    }

    /// The rotary variables whose `sin`/`cos` the body uses, in index order.
    fn rotary(&self) -> Vec<usize> {
        let mut out: Vec<usize> = self
            .symbols
            .iter()
            .filter_map(|s| match s {
                Symbol::Sin(i) | Symbol::Cos(i) => Some(usize::from(*i)),
                _ => None,
            })
            .filter(|&k| {
                self.model
                    .variables
                    .get(k)
                    .is_some_and(|v| v.1 == JointKind::Rotary)
            })
            .collect();
        out.sort_unstable();
        out.dedup();
        out
    }

    /// The `let` statements: symbols, monomials, shared coefficients.
    fn prelude(&self) -> TokenStream {
        self.prelude_in(false)
    }

    /// The `let` statements of the same body with `sin`/`cos` of each
    /// rotary variable `k` taken from `sc[k] = [sin, cos]` (computed by the
    /// caller, four points at a time, in the batched kernels).
    fn prelude_given_sin_cos(&self) -> TokenStream {
        self.prelude_in(true)
    }

    fn prelude_in(&self, given_sin_cos: bool) -> TokenStream {
        let mut out = TokenStream::new();
        let mut symbols = self.symbols.clone();
        symbols.sort();
        let mut done_rotary = Vec::new();
        for s in symbols {
            match s {
                Symbol::Var(i) => {
                    let id = symbol_ident_in(self.model, s);
                    let i = lit(usize::from(i));
                    out.extend(quote!(let #id = q[#i];));
                }
                Symbol::Param(i) => {
                    let id = symbol_ident_in(self.model, s);
                    let i = lit(usize::from(i));
                    out.extend(quote!(let #id = p[#i];));
                }
                Symbol::Cos(i) | Symbol::Sin(i) => {
                    if done_rotary.contains(&i) {
                        continue;
                    }
                    done_rotary.push(i);
                    let (sn, cs) = (
                        symbol_ident_in(self.model, Symbol::Sin(i)),
                        symbol_ident_in(self.model, Symbol::Cos(i)),
                    );
                    let k = usize::from(i);
                    let is_rotary = self
                        .model
                        .variables
                        .get(k)
                        .is_some_and(|v| v.1 == JointKind::Rotary);
                    if is_rotary {
                        let k = lit(k);
                        out.extend(if given_sin_cos {
                            quote!(let [#sn, #cs] = sc[#k];)
                        } else {
                            quote!(let (#sn, #cs) = q[#k].sin_cos();)
                        });
                    }
                }
            }
        }
        for (_, id, expr) in &self.monomials {
            out.extend(quote!(let #id = #expr;));
        }
        for key in &self.shared_order {
            if let Some((id, body, _)) = self.shared.get(key) {
                out.extend(quote!(let #id = #body;));
            }
        }
        out
    }
}

/// An unsuffixed integer literal (`3`, not `3usize`).
fn lit(i: usize) -> Literal {
    Literal::usize_unsuffixed(i)
}

/// The local of a symbol in generated code, named after the user's names:
/// `v_x`, `p_L`, `cos_A`, `sin_A`.
fn symbol_ident_in(model: &SymbolicModel, s: Symbol) -> Ident {
    let var = |i: u16| {
        sanitize(
            model
                .variables
                .get(usize::from(i))
                .map_or("_", |v| v.0.as_str()),
        )
    };
    match s {
        Symbol::Var(i) => format_ident!("v_{}", var(i)),
        Symbol::Param(i) => format_ident!(
            "p_{}",
            sanitize(
                model
                    .parameters
                    .get(usize::from(i))
                    .map_or("_", |p| p.0.as_str())
            )
        ),
        Symbol::Cos(i) => format_ident!("cos_{}", var(i)),
        Symbol::Sin(i) => format_ident!("sin_{}", var(i)),
    }
}

fn sanitize(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

#[cfg(all(test, feature = "pretty"))]
mod tests {
    use super::*;

    /// `benches/generated/legendre5.rs` is this emitter's output for
    /// `examples/machines/legendre5.yaml`: the benchmark of generated code
    /// includes it (chain-core's benches cannot call the `machine!` macro of
    /// the facade crate). Run with `CHAIN_REGENERATE=1` to rewrite it after a
    /// change of the emitter.
    #[test]
    fn generated_benchmark_code_is_current() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        let file = root.join("../examples/machines/legendre5.yaml");
        let machine = crate::load_file(&file).unwrap_or_else(|d| panic!("{d}"));
        let model = crate::derive(&machine);
        let options = EmitOptions {
            type_name: "Legendre5".into(),
            visibility: quote!(pub),
            crate_path: quote!(crate::shim),
            emission: Emission::Macro,
        };
        let code = format!(
            "// Generated by `chain_core::emit` from examples/machines/legendre5.yaml\n\
             // (chain-core/src/symbolic/emit.rs, generated_benchmark_code_is_current).\n\
             // Do not edit; rerun that test with CHAIN_REGENERATE=1.\n{}",
            emit_pretty(&model, &options)
        );
        let path = root.join("benches/generated/legendre5.rs");
        if std::env::var_os("CHAIN_REGENERATE").is_some() {
            std::fs::create_dir_all(path.parent().expect("benches/generated")).expect("mkdir");
            std::fs::write(&path, &code).expect("write");
        }
        let recorded = std::fs::read_to_string(&path).unwrap_or_default();
        assert!(
            recorded == code,
            "{} is not the emitter's output; rerun with CHAIN_REGENERATE=1",
            path.display()
        );
    }
}
