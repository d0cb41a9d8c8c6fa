//! The integration tests of the `chain` package, in one binary, in three
//! folders by kind: `commands` (the subcommands and the library capabilities
//! behind them), `robustness` (bad, hostile and extreme input, output
//! errors, the recorded outputs) and `papers` (the source papers' equations
//! and tables reproduced). Each test file is one module; a filter on its path
//! runs it (`cargo test --profile ci --test it -- commands::map::`), or a
//! whole folder (`-- papers::`). `common` (the independent numeric transform
//! product and the CLI helpers) and `reference` (the tests' own reading of
//! the example tables) are compiled once for all of them.

mod common;
mod reference;

mod commands;
mod papers;
mod robustness;
