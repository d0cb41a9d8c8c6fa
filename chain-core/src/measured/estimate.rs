//! What `identify` and `subset` both give: the estimate of one unknown
//! ([`Estimate`]) and why an identification could not be computed
//! ([`IdentifyError`]), in a module of their own so that `subset` need not
//! import `identify`, which runs it. `identify` re-exports them.

use serde::Serialize;

/// Which list of a chosen subset a refusal is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SubsetSide {
    /// The errors fixed at 0 (every other one estimated).
    Fixed,
    /// The errors estimated (every other one fixed at 0).
    Estimated,
}

impl std::fmt::Display for SubsetSide {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            SubsetSide::Fixed => "the fixed errors",
            SubsetSide::Estimated => "the estimated errors",
        })
    }
}

/// What is wrong with a chosen subset's list of errors.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum SubsetProblem {
    /// The list names no error (every name blank).
    #[error("names no error parameter")]
    NoName,
    /// A name that is not an unknown of the design.
    #[error("`{name}` is not an error parameter of these measurements{}", suggestion.as_ref().map_or(String::new(), |c| format!(" (did you mean `{c}`?)")))]
    Unknown {
        /// The name given.
        name: String,
        /// The closest unknown, if any is close.
        suggestion: Option<String>,
    },
    /// A name given twice.
    #[error("`{name}` is named twice")]
    Twice {
        /// The name.
        name: String,
    },
    /// Chosen unknowns the measurements cannot separate from the other
    /// estimated ones (sorted).
    #[error("the measurements cannot separate {} from the other estimated parameters; fix {} too", names.join(", "), if names.len() == 1 { "it" } else { "some of them" })]
    Inseparable {
        /// The unknowns.
        names: Vec<String>,
    },
}

/// Why an identification could not be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[cfg_attr(feature = "miette", derive(miette::Diagnostic))]
#[non_exhaustive]
pub enum IdentifyError {
    /// No measurement at all and no prior.
    #[error("there is no measurement to identify from")]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::identify::no_rows)))]
    NoRows,
    /// The statistics prior on a machine whose `statistics` miss some
    /// errors.
    #[error("the statistics prior needs an entry for every error parameter; machine `{machine}` has none for {}", missing.join(", "))]
    #[cfg_attr(
        feature = "miette",
        diagnostic(
            code(chain::identify::no_prior),
            help("add them to the machine file's `statistics`, or identify without the prior")
        )
    )]
    NoPrior {
        /// The machine.
        machine: String,
        /// The errors without a statistics entry.
        missing: Vec<String>,
    },
    /// The prior without a `std` column and no residual degree of freedom
    /// to estimate the noise from.
    #[error("the prior without a `std` column estimates the measurement noise from the least-squares residual, but there are {rows} rows for rank {rank}")]
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
    /// A chosen subset's list names an unknown that is not one, names
    /// none, or chooses unknowns the measurements cannot separate.
    #[error("{side}: {problem}")]
    #[cfg_attr(
        feature = "miette",
        diagnostic(
            code(chain::identify::subset),
            help("a chosen subset names error parameters of the design; the identification without one shows which parameters the measurements can separate")
        )
    )]
    Subset {
        /// The list.
        side: SubsetSide,
        /// What is wrong with it.
        problem: SubsetProblem,
    },
    /// A chosen subset with the prior.
    #[error("{side} choose the parameters of a least-squares fit; with the prior every parameter is estimated from the data and its statistics")]
    #[cfg_attr(
        feature = "miette",
        diagnostic(
            code(chain::identify::subset_with_prior),
            help("identify without the prior, or without the chosen subset")
        )
    )]
    SubsetWithPrior {
        /// The list chosen.
        side: SubsetSide,
    },
    /// The exact-kinematics iteration with the prior.
    #[error("the exact-kinematics iteration fits by least squares; it does not take the prior")]
    #[cfg_attr(
        feature = "miette",
        diagnostic(
            code(chain::identify::iterate_with_prior),
            help("iterate on the exact kinematics without the prior, or use the prior without iterating")
        )
    )]
    IterateWithPrior,
    /// A rank tolerance outside `(0, 1)`.
    #[error("the rank tolerance {0} is not a relative tolerance in (0, 1)")]
    #[cfg_attr(
        feature = "miette",
        diagnostic(
            code(chain::identify::rank_tol),
            help("e.g. 1e-6 (singular values of the equilibrated design below 1e-6 × the largest count as zero)")
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

/// The noise variance a least-squares fit of `k` unknowns to `m` rows
/// reports its covariance in: 1 with a `std` column (`weighted`: the rows
/// are in units of their stated std), `RSS/(m − k)` without one, `None`
/// when there is no residual degree of freedom.
pub(crate) fn noise_scale2(weighted: bool, rss: f64, m: usize, k: usize) -> Option<f64> {
    if weighted {
        Some(1.0)
    } else if m > k {
        Some(rss / (m - k) as f64)
    } else {
        None
    }
}

/// The covariance over all `n` unknowns and every unknown's estimate, from
/// the `estimated` ones' inverse information `inv` (`k × k`, in
/// `estimated`'s order, per unit noise) and the noise variance `scale2`
/// ([`noise_scale2`]): `scale2 · inv` on the estimated block, zero rows and
/// columns for the fixed unknowns, NaN when the noise is unknown; each
/// estimate's std the root of its diagonal, `None` for a fixed unknown, an
/// unknown noise or a non-finite diagonal.
pub(crate) fn covariance(
    values: &[f64],
    estimated: &[usize],
    inv: &nalgebra::DMatrix<f64>,
    scale2: Option<f64>,
) -> (nalgebra::DMatrix<f64>, Vec<Estimate>) {
    let n = values.len();
    let mut covariance = nalgebra::DMatrix::zeros(n, n);
    for (a, &i) in estimated.iter().enumerate() {
        for (b, &j) in estimated.iter().enumerate() {
            covariance[(i, j)] = scale2.map_or(f64::NAN, |s2| s2 * inv[(a, b)]);
        }
    }
    let estimates = (0..n)
        .map(|j| Estimate {
            value: values[j],
            std: (estimated.contains(&j) && scale2.is_some() && covariance[(j, j)].is_finite())
                .then(|| covariance[(j, j)].max(0.0).sqrt()),
        })
        .collect();
    (covariance, estimates)
}
