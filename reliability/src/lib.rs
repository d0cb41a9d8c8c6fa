//! Machining-accuracy reliability over `chain_core::ErrorModel` implementations.
//!
//! Not implemented yet: FORM, importance sampling, Monte Carlo and reliability
//! sensitivity land with their own issue. The crate depends on `chain-core`'s
//! [`chain_core::ErrorModel`] trait, which both runtime and macro-generated
//! models implement.

pub use chain_core::ErrorModel;
