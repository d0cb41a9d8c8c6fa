//! The integration tests of the `reliability` crate, in one binary: one
//! module per subject, its tests under the module's path (`cargo test
//! --release -p reliability --test it -- sorm::`).

mod marginals;
mod nataf;
mod sorm;
