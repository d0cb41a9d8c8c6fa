//! A machine as it is measured: measurement records, their design matrix,
//! the identification of the error parameters from them and the planning of
//! where to measure (measured-machines spec, sections 4-5;
//! `docs/identify.md`, `docs/plan.md`).
//!
//! [`measurements`] reads a measurement (or `chain plan` candidate) CSV
//! against a [`crate::Machine`] and gives each record's design rows from a
//! model's exact sensitivity; [`identify`] solves the weighted least-squares
//! problem (or its Gaussian-prior posterior) through an SVD; [`plan`] chooses
//! where to measure (a D-optimal subset of the candidates); [`positioning`]
//! reads an axis's ISO 230-2 positioning runs and evaluates them, and
//! [`positioning_values`] writes them into a values file; [`spheres`] reads
//! sphere-probing records, whose sphere positions are unknowns of the fit
//! beside the errors ([`Setup`]).

pub mod circular;
mod estimate;
pub mod exact;
pub mod identify;
pub mod iterate;
pub mod measurements;
pub mod plan;
pub mod positioning;
pub mod positioning_temperature;
pub mod positioning_values;
pub mod predict;
pub mod spheres;
pub mod subset;
pub mod thermal;
pub mod thermal_fit;
pub mod thermal_values;

pub use identify::{
    identify, Identification, IdentifyError, IdentifyOptions, NoiseRule, SubsetProblem, SubsetSide,
};
pub use measurements::{
    design_rows, Design, DesignError, Holdout, HoldoutError, Layout, MeasuredComponent,
    Measurement, MeasurementKind, Measurements, MeasurementsError, Observed, Setup, SetupKind,
};
pub use predict::{predict, ErrorStats, Prediction};
pub use subset::{ChosenBy, Fixed, FixedStatus, Subset, SubsetChoice};
