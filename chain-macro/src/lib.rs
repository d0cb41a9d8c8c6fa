//! The `machine!` procedural macro of `chain`: a thin shim over
//! [`chain_core::expand::expand`], which parses the invocation, validates the
//! machine with the same loader as YAML files, derives its exact first-order
//! model and emits straight-line Rust. Use it through the facade,
//! `chain::machine!`; see `docs/macro.md` for the inline syntax.

#![warn(missing_docs)]

use proc_macro::TokenStream;

/// Declares a machine and generates its error model at compile time.
///
/// ```ignore
/// chain::machine!(pub GantryGrinder = "machines/gantry_grinder.yaml");
/// chain::machine! {
///     pub Slide {
///         bodies {
///             bed {},
///             x_slide { parent: bed, joint: { type: prismatic, axis: +x, variable: x },
///                       errors: { dx: dxx, ez: ezx } },
///         },
///         workpiece: bed,
///         tool: x_slide,
///     }
/// }
/// ```
#[proc_macro]
pub fn machine(input: TokenStream) -> TokenStream {
    chain_core::expand::expand(input.into()).into()
}
