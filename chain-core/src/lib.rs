//! The core of `chain`: the machine model, the symbolic first-order error
//! derivation, code emission and the runtime evaluator.
//!
//! Data flow: YAML text ([`load`]) or `machine!` tokens → validated
//! [`Machine`] → [`derive()`] → [`SymbolicModel`] (exact coefficients as
//! canonical polynomials) → export (text / JSON / LaTeX / Rust) or
//! [`compile`] → [`CompiledModel`], an [`ErrorModel`] evaluated from a flat tape.

pub mod algebra;
pub mod derive;
pub mod dmm;
pub mod emit;
pub mod export;
pub mod eval;
pub mod model;
mod model_trait;

pub use derive::{derive, derive_in, SymbolicModel};
pub use eval::{compile, CompiledModel};
pub use model::Machine;
pub use model_trait::{ErrorModel, Pose};
