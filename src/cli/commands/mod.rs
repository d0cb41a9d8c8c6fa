//! One file per subcommand: its clap arguments, the request it builds, the
//! `chain::ops` call, and the document handed to the renderer and the plots.

pub mod allocate;
pub mod circular;
pub mod compensate;
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
pub mod report;
pub mod sensitivity;
pub mod sobol;
pub mod thermal;
