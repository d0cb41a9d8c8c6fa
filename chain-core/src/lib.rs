//! The core of `chain`: the machine model, the symbolic first-order error
//! derivation, code emission and the runtime evaluator.
//!
//! Data flow: YAML text ([`load`]) or `machine!` tokens → validated
//! [`Machine`] → [`derive()`] → [`SymbolicModel`] (exact coefficients as
//! canonical polynomials) → export (text / JSON / LaTeX / Rust) or
//! [`compile`] → [`CompiledModel`], an [`ErrorModel`] evaluated from a flat tape.

pub mod algebra;
pub mod derive;
pub mod diagnostic;
pub mod dmm;
pub mod emit;
pub mod eval;
pub mod expand;
pub mod export;
pub mod expr;
pub mod geometric;
pub mod geometry;
pub mod inline;
pub mod inverse;
pub mod jet;
pub mod kinematics;
pub mod load;
pub mod model;
mod model_trait;
pub mod motion;
pub mod settings;
pub mod yaml;

pub use derive::{derive, derive_in, SymbolicModel};
pub use diagnostic::Diagnostics;
pub use eval::{compile, CompiledModel};
pub use load::{load_bytes, load_file, load_str};
pub use model::Machine;
pub use model_trait::{ErrorModel, Pose};
