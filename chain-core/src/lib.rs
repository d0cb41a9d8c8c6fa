//! The core of `chain`: the machine model, the symbolic first-order error
//! derivation, code emission and the runtime evaluator.
//!
//! Data flow: YAML text ([`load`]) or `machine!` tokens → validated
//! [`Machine`] → [`derive()`] → [`SymbolicModel`] (exact coefficients as
//! canonical polynomials) → export (text / JSON / LaTeX / Rust) or
//! [`compile`] → [`CompiledModel`], an [`ErrorModel`] evaluated from a flat tape.
//! A built machine ([`BuiltMachine`]) is such a model with the error values
//! of one machine ([`values`]: a values file, measured or identified), whose
//! error it evaluates at any axis values and maps over a grid.

#![warn(missing_docs)]

pub mod built;
pub mod compensation;
pub mod input;
pub mod kinematics;
pub mod lanes;
pub mod measured;
mod model_trait;
pub mod named;
pub mod symbolic;
pub mod thermal_state;

// The stages' modules also at flat paths (`chain_core::load`,
// `chain_core::inverse`, ...), which downstream code and the docs use.
pub use input::{bounded, diagnostic, expr, inline, load, model, settings, tabular, values, yaml};
pub use kinematics::{conversion, geometry, inverse, jet, motion};
pub use symbolic::{algebra, derive, dmm, emit, eval, expand, export, geometric};

pub use built::{BuiltMachine, MapResult};
pub use derive::{derive, derive_in, SymbolicModel};
pub use diagnostic::Diagnostics;
pub use eval::{compile, CompiledModel, BATCH_LANES};
pub use load::{load_bytes, load_file, load_file_with_text, load_str};
pub use measured::{identify, measurements, plan};
pub use model::Machine;
pub use model_trait::{BatchError, ErrorModel, ErrorValues, OutOfRange, Pose};
pub use values::Values;
