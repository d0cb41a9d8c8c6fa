//! The integration tests of the `chain` package, in one binary: each module
//! is one former `tests/<name>.rs` file (same test names under the module's
//! path, so `cargo test --release --test it -- map::` runs what
//! `--test map` ran). `common` (the independent numeric transform product and
//! the CLI helpers) and `reference` (the tests' own reading of the example
//! tables) are compiled once for all of them.

mod common;
mod reference;

mod acceptance;
mod acceptance_rare;
mod allocate;
mod atomic_writes;
mod batch;
mod batch_kernels;
mod bounded_reads;
mod compensate;
mod cov_stopping;
mod csv_messages;
mod derivation_routes;
mod dh;
mod directional;
mod downstream;
mod export_cli;
mod export_controllers;
mod export_grid;
mod extreme_values;
mod finite_difference;
mod function_slot_input;
mod function_slot_reliability;
mod function_slots;
mod fuzz;
mod fuzz_structured;
mod generated_into;
mod geometric_sensitivity;
mod golden_outputs;
mod identify;
mod identify_iterate;
mod identify_subset;
mod inverse;
mod inverse_pose;
mod kinematics;
mod macro_models;
mod macro_ui;
mod malformed_input;
mod map;
mod measurement_examples;
mod option_ranges;
mod output_errors;
mod path;
mod plan;
mod positioning;
mod positioning_values;
mod posterior_reliability;
mod reliability_cli;
mod reliability_gantry;
mod samplers_cli;
mod seed000_equations;
mod seed002_motion;
mod seed002_pose;
mod seed004_model;
mod sobol;
mod sorm_cli;
mod streamed;
mod subset;
mod values;
mod wide_lines;
