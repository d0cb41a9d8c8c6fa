//! What `identify` and `subset` both give: the estimate of one unknown
//! ([`Estimate`]) and why an identification could not be computed
//! ([`IdentifyError`]), in a module of their own so that `subset` need not
//! import `identify`, which runs it. `identify` re-exports both.

use serde::Serialize;

/// Why an identification could not be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[cfg_attr(feature = "miette", derive(miette::Diagnostic))]
#[non_exhaustive]
pub enum IdentifyError {
    /// No measurement at all and no prior.
    #[error("there is no measurement to identify from")]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::identify::no_rows)))]
    NoRows,
    /// `--prior` on a machine whose `statistics` miss some errors.
    #[error("--prior needs a statistics entry for every error parameter; machine `{machine}` has none for {}", missing.join(", "))]
    #[cfg_attr(
        feature = "miette",
        diagnostic(
            code(chain::identify::no_prior),
            help("add them to the machine file's `statistics`, or identify without --prior")
        )
    )]
    NoPrior {
        /// The machine.
        machine: String,
        /// The errors without a statistics entry.
        missing: Vec<String>,
    },
    /// `--prior` without a `std` column and no residual degree of freedom
    /// to estimate the noise from.
    #[error("--prior without a `std` column estimates the measurement noise from the least-squares residual, but there are {rows} rows for rank {rank}")]
    #[cfg_attr(
        feature = "miette",
        diagnostic(
            code(chain::identify::no_noise_scale),
            help("give each measurement its standard deviation (a `std` column), or more measurements")
        )
    )]
    NoNoiseScale {
        /// The scalar rows.
        rows: usize,
        /// The rank.
        rank: usize,
    },
    /// `--fix`/`--estimate` name an unknown that is not one, twice, or a
    /// set the measurements cannot separate.
    #[error("{option}: {message}")]
    #[cfg_attr(
        feature = "miette",
        diagnostic(
            code(chain::identify::subset),
            help("--fix and --estimate take error parameter names separated by commas; `chain identify` without them shows which parameters the measurements can separate")
        )
    )]
    Subset {
        /// The option.
        option: &'static str,
        /// What is wrong.
        message: String,
    },
    /// `--fix`/`--estimate` with `--prior`.
    #[error("{option} chooses the parameters of a least-squares fit; with --prior every parameter is estimated from the data and its statistics")]
    #[cfg_attr(
        feature = "miette",
        diagnostic(
            code(chain::identify::subset_with_prior),
            help("leave out --prior, or the subset option")
        )
    )]
    SubsetWithPrior {
        /// The option.
        option: &'static str,
    },
    /// `--iterate` with `--prior`.
    #[error("--iterate fits the exact kinematics by least squares; it does not take --prior")]
    #[cfg_attr(
        feature = "miette",
        diagnostic(
            code(chain::identify::iterate_with_prior),
            help("identify with --iterate alone, or with --prior alone")
        )
    )]
    IterateWithPrior,
    /// `--rank-tol` outside `(0, 1)`.
    #[error("--rank-tol: {0} is not a relative tolerance in (0, 1)")]
    #[cfg_attr(
        feature = "miette",
        diagnostic(
            code(chain::identify::rank_tol),
            help("e.g. --rank-tol 1e-6 (singular values of the equilibrated design below 1e-6 × the largest count as zero)")
        )
    )]
    RankTolerance(f64),
    /// A non-finite value in the design (a pose where the model is not
    /// finite).
    #[error("the design matrix or the measured values are not finite")]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::identify::not_finite)))]
    NotFinite,
    /// The prior's size does not match the design.
    #[error("the prior has {prior} entries for {unknowns} unknowns")]
    PriorSize {
        /// The prior's entries.
        prior: usize,
        /// The unknowns.
        unknowns: usize,
    },
}

/// One estimate.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Estimate {
    /// The estimated value (mm or rad).
    pub value: f64,
    /// Its standard deviation (`None`: without a `std` column and with as
    /// many rows as the rank, the noise cannot be estimated).
    pub std: Option<f64>,
}
