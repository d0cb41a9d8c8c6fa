//! Machining-accuracy reliability for `chain` error models.
//!
//! The reference is Wang & Yuan (2021), *Enhancing machining accuracy
//! reliability of multi-axis CNC machine tools using an advanced importance
//! sampling method* (seed 000), Section 3: the limit state `Z = I − ΔE_T`
//! (Eq. 30, 34), FORM (Eq. 19-22, 31), the advanced importance sampling
//! (Eq. 23-28) and the reliability sensitivity (Eq. 32-33).
//!
//! The pieces follow the OpenTURNS shape — event, algorithm and result are
//! separate — and the argmin habit of small problem traits:
//!
//! - [`Inputs`] / [`Marginal`]: the random error parameters and the map to
//!   standard normal space;
//! - [`LimitState`]: the problem trait (`g(x)`, its branches and gradients);
//!   [`ToleranceLimitState`] is the machine-tool one, over error components
//!   that are linear in the errors (`E_c = Σ_j S_cj·e_j`), one- or two-sided,
//!   per component, series or volumetric ([`Criterion`]);
//! - [`Event`]: a limit state with its inputs;
//! - algorithms [`Form`], [`ImportanceSampling`], [`MonteCarlo`] and the
//!   function [`sensitivity()`], returning plain serialisable results
//!   ([`FormResult`], [`SimulationResult`], [`SensitivityResult`]); the
//!   samplers run through the [`Sampler`] trait (`run`, `run_cases`);
//! - [`Study`]: all of it over a workspace grid for any
//!   [`chain_core::ErrorModel`] (runtime-compiled or `machine!`-generated),
//!   and [`machine`] to build one from a machine file;
//! - [`PathStudy`]: the same along a tool path, instant by instant, with the
//!   moments of the errors ([`PathResult`]).
//!
//! # Example
//!
//! ```
//! use reliability::{Event, Form, ImportanceSampling, Inputs, Marginal, Sampler, ToleranceLimitState};
//! use chain_core::model::Sided;
//! // px at (y, z) = (0, 600) of the gantry grinder, Eq. 34 with Table 1's σ:
//! // px = −δxx − z·εyx + y·εzx + δxz + δxy + y·Sxy − y·εzz.
//! let names = ["dxx", "eyx", "dxz", "dxy"].map(String::from).to_vec();
//! let stds = [0.05 / 6.0, 0.06 / 6000.0, 0.03 / 6.0, 0.04 / 6.0];
//! let inputs = Inputs::new(names, stds.iter().map(|&s| Marginal::normal(0.0, s).unwrap()).collect()).unwrap();
//! let g = ToleranceLimitState::component(vec![-1.0, -600.0, 1.0, 1.0], 0.03, Sided::Upper).unwrap();
//! let event = Event::new(&inputs, g).unwrap();
//! let form = Form::default().run(&event).unwrap();
//! assert!((form.reliability - 0.9884).abs() < 1e-4); // Table 2 prints 98.74 %
//! // The importance sampling has zero variance on a linear-normal limit state.
//! let is = ImportanceSampling { samples: 1000, seed: 1, form: Form::default(), cov: None }.run(&event).unwrap();
//! assert!((is.pf - form.pf).abs() < 1e-12 && is.std_error < 1e-12);
//! ```

#![warn(missing_docs)]

pub mod acceptance;
pub mod allocate;
pub mod conditional;
pub mod directional;
pub mod error;
mod families;
pub mod form;
pub mod inputs;
pub mod limit_state;
pub mod machine;
pub mod marginal;
pub mod method;
pub mod nataf;
pub mod normal;
mod par;
pub mod path;
pub mod posterior;
pub mod rng;
pub mod sampler;
pub mod sensitivity;
pub mod simulation;
pub mod sobol;
pub mod sorm;
mod standard;
pub mod study;
pub mod subset;
mod util;

pub use acceptance::{
    Acceptance, AcceptanceMethod, AcceptanceResult, AcceptanceSensitivity, Rectangles,
};
pub use allocate::{AllocateError, Allocation, ErrorBounds, Kkt, Optimal, Paper, Step};
pub use chain_core::ErrorModel;
pub use directional::DirectionalSimulation;
pub use error::ReliabilityError;
pub use form::{BranchResult, Calls, Form, FormResult, Termination};
pub use inputs::{Inputs, Marginal};
pub use limit_state::{Affine, AffineView, Criterion, Event, LimitState, ToleranceLimitState};
pub use path::{
    Extreme, InstantResult, PathBlocks, PathInstant, PathRecord, PathResult, PathStudy,
    PathSummary, PathTarget, Quantity, TargetSummary,
};
pub use posterior::{Posterior, PosteriorError};
pub use sampler::{Sampler, Streams};
pub use sensitivity::{sensitivity, InputSensitivity, SensitivityMethod, SensitivityResult};
pub use simulation::{ImportanceSampling, MonteCarlo, Progress, SimulationResult, Stop, Stopping};
pub use sobol::{Sobol, SobolError, SobolResult};
pub use study::{
    Algorithm, CaseResult, CaseTally, ErrorMoments, ErrorSensitivity, FormCase, FormLimit, Grid,
    Method, SormCase, Study, StudyResult, StudySpec, Summary, System, Target, TargetSensitivity,
    VolumetricMoments,
};
pub use subset::{SubsetLevel, SubsetResult, SubsetSimulation};
