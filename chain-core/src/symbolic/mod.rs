//! Stage 2, the symbolic engine and its outputs: canonical polynomials and
//! duals ([`algebra`]), the first-order derivation ([`derive`]) and its
//! differential-motion-matrix cross-check ([`dmm`]); the outputs of a
//! derived model: text, JSON and LaTeX ([`export`]), straight-line Rust
//! ([`emit`], [`expand`] for the `machine!` macro), the runtime tape
//! ([`eval`]) and the geometric sensitivity coefficients ([`geometric`]).

pub mod algebra;
pub mod derive;
pub mod dmm;
pub mod emit;
pub mod eval;
pub mod expand;
pub mod export;
pub mod geometric;
