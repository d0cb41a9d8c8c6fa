//! The application layer under the command line and Python: what a
//! command resolves from its options before the libraries
//! run, written once. The `chain` binary and the Python package both call
//! these functions, so an option is checked by one rule and refused in one
//! wording.
//!
//! - [`resolve`]: parameter names, grid axes (the machine file's
//!   `reliability.grid` with overrides), one point given by name (`--at`),
//!   the points of a map or an export (a grid or rows).
//! - [`choice`]: the options with a closed set of values, each value's
//!   spelling and help written once, parsed by the CLI and Python alike.
//! - [`source`] (feature `records`): a file given as a path or as the
//!   caller's bytes, and the readers of every kind of input file.

//! - [`worded`]: how an `ops` error reads ([`Worded`]: its code and help,
//!   the error it wraps), for the CLI's diagnostics and Python's text.

//! - [`study`]: a reliability study from a machine and the options every
//!   study command takes (parameters, grid, sided, system, a posterior).

//! - [`derive`] (feature `json`): `chain derive`'s request and document;
//! - [`allocate`]: `chain allocate`'s request and document;
//! - [`compensate`]: `chain compensate`'s request (the fit's options, the table) and document;
//! - [`export`]: `chain export`'s request, document and the per-axis tables `map --compensated` shares;
//! - [`identify`]: `chain identify`'s request (options checked before any
//!   file is read, the measurement files read from a path or bytes), its
//!   refusals and document (with the values file);
//! - [`plan`]: `chain plan`'s request, refusals and document;
//! - [`inverse`]: `chain inverse`'s request, poses and document;
//! - [`positioning`]: `chain positioning`'s request, document and values file;
//! - [`map`]: `chain map`'s preparation (values, approach, points, the built machine);
//! - [`motion`]: `chain motion`'s request (the settings, the series' options) and document;
//! - [`reliability`]: `chain reliability`'s request, the prepared study and the run's document;
//! - [`sensitivity`]: `chain sensitivity`'s request (either kind) and document;
//! - [`sobol`]: `chain sobol`'s request and document;
//! - [`path`]: `chain path`'s request (axis values or poses) and document;
//! - [`tables`] (feature `records`): the numeric CSV tables of poses and
//!   axis values those commands read, from a path or from bytes;
//! - [`views`]: what the CLI's tables and the charts both show of a
//!   document (a target's reliability maps, where sensitivities hold).

pub mod allocate;
pub mod choice;
pub mod circular;
pub mod compensate;
#[cfg(feature = "json")]
pub mod derive;
pub mod export;
pub mod identify;
pub mod inverse;
pub mod map;
pub mod motion;
pub mod path;
pub mod plan;
pub mod positioning;
pub mod reliability;
pub mod resolve;
pub mod sensitivity;
pub mod sobol;
#[cfg(feature = "records")]
pub mod source;
pub mod study;
#[cfg(feature = "records")]
pub mod tables;
pub mod thermal;
pub mod views;
pub mod worded;

pub use worded::Worded;
