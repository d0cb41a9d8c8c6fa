//! `chain`: geometric-error models, machining-accuracy reliability and
//! precision allocation for machine tools.
//!
//! This facade re-exports the workspace crates:
//! - [`core`] (`chain-core`): machine model, symbolic derivation, emission, runtime evaluation;
//! - [`reliability`]: FORM, importance sampling, Monte Carlo, sensitivity;
//!
//! and holds the paper workflows that are not part of either
//! ([`compensate`]: swing-angle error identification and compensation).
//!
//! The library needs none of the command-line crates: with
//! `default-features = false` a dependent compiles the models, the
//! [`machine!`] macro, reliability and the workflows alone. The default
//! feature `cli` builds the `chain` binary (argument parsing, progress bars,
//! the diagnostic renderer, CSV input, plots, JSON output); `parallel` runs
//! sampling on all cores (see `docs/packaging.md`).
//!
//! The feature `plot` (on with `cli`) adds `plot`: every command's charts,
//! computed from its `ops` document and drawn to PNG files or SVG text.

pub use chain_core as core;
pub use reliability;

/// Declares a machine and generates its error model at compile time (see `docs/macro.md`).
pub use chain_macro::machine;

pub mod compensate;
pub mod ops;
#[cfg(feature = "plot")]
pub mod plot;
#[cfg(feature = "report")]
pub mod report;
