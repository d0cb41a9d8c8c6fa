//! The integration tests of the `reliability` crate, in one binary: each
//! module is one former `tests/<name>.rs` file (same test names under the
//! module's path: `cargo test --release -p reliability --test it -- sorm::`).

mod marginals;
mod nataf;
mod sorm;
