//! A machine as it is measured: measurement records, their design matrix
//! and the identification of the error parameters from them
//! (measured-machines spec, section 4; `docs/identify.md`).
//!
//! [`measurements`] reads a measurement (or `chain plan` candidate) CSV
//! against a [`crate::Machine`] and gives each record's design rows from a
//! model's exact sensitivity; [`identify`] solves the weighted least-squares
//! problem (or its Gaussian-prior posterior) through an SVD; [`positioning`]
//! reads an axis's ISO 230-2 positioning runs and evaluates them, and
//! [`positioning_values`] writes them into a values file.

pub mod document;
pub mod exact;
pub mod identify;
pub mod iterate;
pub mod measurements;
pub mod positioning;
pub mod positioning_values;
pub mod predict;
pub mod subset;

pub use identify::{identify, Identification, IdentifyError, IdentifyOptions, NoiseRule};
pub use measurements::{
    design_rows, Design, DesignError, Holdout, HoldoutError, Layout, MeasuredComponent,
    Measurement, MeasurementKind, Measurements, MeasurementsError, Observed,
};
pub use predict::{predict, ErrorStats, Prediction};
pub use subset::{ChosenBy, Fixed, FixedStatus, Subset, SubsetChoice};
