//! The source papers reproduced (`../shared/seeds/`): their printed
//! equations written out by hand against the derived models, their tables
//! against the library's results, and the errata each proves
//! (docs/errata.md).
//!
//! - `gantry_equations`: Wang & Yuan 2021 (seed 000), the gantry guide-rail
//!   grinder's error model, Eq. 16-18;
//! - `reliability_gantry`: the same paper's reliability, Tables 1-4 and
//!   Figures 6-8;
//! - `bevel_pose`: the 5-axis spiral-bevel-gear machine (seed 002), the
//!   printed pose of its Figure 3;
//! - `bevel_motion`: the same paper's motion conversion between the cradle
//!   generator and the 5-axis machine, Eq. 1-2;
//! - `internal_grinder_model`: Fan et al. 2020 (seed 004), the internal
//!   cylindrical compound grinder's printed error model, Eq. 3.

mod bevel_motion;
mod bevel_pose;
mod gantry_equations;
mod internal_grinder_model;
mod reliability_gantry;
