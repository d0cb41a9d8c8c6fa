//! Swing-angle error identification and compensation (seed 003).
//!
//! A swing head of length `L` (rotation centre to tool tip) is commanded to
//! angles `θ`; at each angle the height of the tool tip is probed. With `Z1`
//! the height of the vertical tool, `Z2 = Z1 − L(1 − cos θ)` the height the tip
//! would have at exactly `θ`, and `Z3` the measured height, the seed's
//! equations 1-5 give the swing-angle error
//!
//! ```text
//! L(1 − cos θ)      = h  = Z1 − Z2            (Eq. 1)
//! L(1 − cos(θ+Δθ))  = h' = Z1 − Z3            (Eq. 2)
//! Δθ = acos(cos θ − ΔZ/L) − θ,   ΔZ = Z2 − Z3 (Eq. 5)
//! ```
//!
//! `Δθ > 0` means the head turned further than commanded (the measured tip is
//! lower than the theoretical one, `Z3 < Z2`). Because `Z2` is the theoretical
//! height, `cos θ − ΔZ/L = 1 − (Z1 − Z3)/L`, so only `Z1` and `Z3` are needed;
//! this module evaluates the equivalent, better-conditioned
//! `θ + Δθ = 2 asin(√((Z1 − Z3)/(2L)))`.
//!
//! The errors are then fitted by least-squares polynomials in `θ` (degrees) of
//! every order in a range ([`fit_polynomial`], Householder QR on a basis scaled
//! to `[-1, 1]`), one order is selected by a stated rule ([`SelectionRule`],
//! leave-one-out cross-validation by default), and the selected polynomial is
//! the compensation law ([`Compensation`]): the axis reaches
//! `θa = θt + Δθ(θt)` (Eq. 7) when `θt` is commanded, so the command that
//! reaches `θt` is the `c` with `c + Δθ(c) = θt`.
//!
//! The entry points are [`Measurements::from_records`] (the rows of a
//! measurement file, already split into records with their line numbers:
//! the `chain` binary reads the CSV), [`analyze`] (points, fits, selection,
//! law) and [`Compensation::table`] (a controller's compensation table).
//! The figures are drawn by the binary (`chain compensate --plot`).
//!
//! One job per file: [`error`] (what can go wrong, located), [`data`] (the
//! measured points as typed rows), [`law`] (Eq. 1-5 and the law, Eq. 7),
//! [`fit`] (least squares), [`fdist`] (the F distribution of the F-test),
//! [`select`] (order selection),
//! [`analysis`] (the workflow) and [`table`] (the compensation table).

pub mod analysis;
pub mod data;
pub mod error;
pub mod fdist;
pub mod fit;
pub mod law;
#[cfg(feature = "records")]
pub mod records;
pub mod select;
pub mod table;

pub use analysis::{analyze, Analysis, Options, Point, ResidualSummary, Spread};
pub use data::{Measurements, RawRecord, Record};
pub use error::{CompensateError, FitError};
pub use fdist::f_survival;
pub use fit::{fit_polynomial, PolyFit};
pub use law::{
    acos_argument, polynomial_text, swing_angle_error_deg, swing_angle_error_from_delta_z_deg,
    theoretical_drop, Compensation,
};
pub use select::{Selection, SelectionRule};
pub use table::{write_table_csv, Grid, TableRow, TABLE_HEADER};

/// Highest polynomial order [`analyze`] and [`fit_polynomial`] accept.
pub const MAX_SUPPORTED_ORDER: usize = 10;

/// Most rows a compensation-table grid may have.
pub const MAX_GRID_POINTS: usize = 100_000;
