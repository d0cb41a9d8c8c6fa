//! Tests of the command-line subcommands and the library capabilities behind
//! them (derivation, the compiled and generated models, kinematics,
//! reliability and its samplers, allocation, values, map, export,
//! identification, planning, positioning, compensation), each against an
//! independent computation, and the library as a downstream crate sees it.

mod acceptance;
mod acceptance_rare;
mod allocate;
mod batch;
mod batch_kernels;
mod circular;
mod compensate;
mod cov_stopping;
mod derivation_routes;
mod dh;
mod directional;
mod downstream;
mod export_cli;
mod export_controllers;
mod export_grid;
mod export_rotary;
mod finite_difference;
mod function_slot_input;
mod function_slot_reliability;
mod function_slots;
mod generated_into;
mod geometric_sensitivity;
mod identify;
mod identify_iterate;
mod identify_spheres;
mod identify_subset;
mod inverse;
mod inverse_pose;
mod kinematics;
mod macro_models;
mod macro_ui;
mod map;
mod measurement_examples;
mod path;
mod plan;
mod positioning;
mod positioning_values;
mod posterior_reliability;
mod reliability_cli;
mod report;
mod samplers_cli;
mod sobol;
mod sorm_cli;
mod streamed;
mod subset;
mod thermal;
mod thermal_model;
mod values;
