//! Stage 3, kinematics of the nominal machine: forward kinematics with exact
//! Jacobians ([`forward`], re-exported here), the 3-D helpers
//! ([`geometry`]), Taylor jets ([`jet`]), inverse kinematics ([`inverse`])
//! and seed 002's motion conversion ([`motion`]).

pub mod forward;
pub mod geometry;
pub mod inverse;
pub mod jet;
pub mod motion;

pub use forward::*;
