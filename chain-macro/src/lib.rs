//! The `machine!` procedural macro of `chain`.
//!
//! Not implemented yet: the macro lands with its own issue. The crate exists so
//! that the workspace layout is final and the facade can already re-export it.
