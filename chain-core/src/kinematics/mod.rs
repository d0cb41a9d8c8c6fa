//! Stage 3, kinematics of the nominal machine: forward kinematics with exact
//! Jacobians ([`forward`], re-exported here), the 3-D helpers
//! ([`geometry`]), Taylor jets ([`jet`]), inverse kinematics ([`inverse`])
//! and the motion conversion of the five-axis spiral bevel paper
//! ([`motion`], one run of it: [`conversion`]).

pub mod conversion;
pub mod forward;
pub mod geometry;
pub mod inverse;
pub mod jet;
pub mod motion;

pub use forward::*;
