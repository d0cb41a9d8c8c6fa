//! The errors of the reliability engine.

use chain_core::model::Origin;

/// Everything that can go wrong between a machine and a reliability result.
///
/// Variants that come from a machine file carry the [`Origin`] of the node
/// concerned so that the CLI can point at the file, line and key.
///
/// Each variant has its diagnostic code (`chain::reliability::…`); the binary
/// renders them (with the file's text where a variant has an [`Origin`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[cfg_attr(feature = "miette", derive(miette::Diagnostic))]
#[non_exhaustive]
pub enum ReliabilityError {
    /// The machine has no `reliability` section.
    #[error("the machine has no `reliability` section (tolerance, sided, grid)")]
    #[cfg_attr(
        feature = "miette",
        diagnostic(code(chain::reliability::no_reliability))
    )]
    NoReliabilitySection,
    /// An error parameter used by the model has no `statistics` entry.
    #[error("error parameter `{name}` has no `statistics` entry")]
    #[cfg_attr(
        feature = "miette",
        diagnostic(code(chain::reliability::missing_statistic))
    )]
    MissingStatistic {
        /// The error parameter.
        name: String,
        /// Where it is first used.
        origin: Origin,
    },
    /// A parameter is symbolic (`null`) and no value was supplied.
    #[error("parameter `{name}` is symbolic (null) and has no value")]
    #[cfg_attr(
        feature = "miette",
        diagnostic(code(chain::reliability::symbolic_parameter))
    )]
    SymbolicParameter {
        /// The parameter.
        name: String,
        /// Where it is declared.
        origin: Origin,
    },
    /// A distribution's numbers are out of range.
    #[error("invalid distribution: {0}")]
    #[cfg_attr(
        feature = "miette",
        diagnostic(code(chain::reliability::invalid_distribution))
    )]
    InvalidDistribution(String),
    /// A tolerance is not a positive finite number.
    #[error("tolerance of `{component}` must be positive and finite (found {value})")]
    #[cfg_attr(
        feature = "miette",
        diagnostic(code(chain::reliability::invalid_tolerance))
    )]
    InvalidTolerance {
        /// The component or system.
        component: String,
        /// The offending value.
        value: f64,
    },
    /// Sizes that must agree do not.
    #[error("{what}: expected {expected}, found {found}")]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::reliability::dimension)))]
    Dimension {
        /// What was being sized.
        what: &'static str,
        /// The expected size.
        expected: usize,
        /// The size found.
        found: usize,
    },
    /// A name (variable, error, parameter) is unknown.
    #[error("unknown {kind} `{name}`{}", hint.as_ref().map(|h| format!(" (did you mean `{h}`?)")).unwrap_or_default())]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::reliability::unknown_name)))]
    UnknownName {
        /// `variable`, `error`, `parameter` or `component`.
        kind: &'static str,
        /// The name given.
        name: String,
        /// A close known name.
        hint: Option<String>,
    },
    /// The reliability grid has no point, or an axis has no value.
    #[error("the reliability grid is empty: {0}")]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::reliability::empty_grid)))]
    EmptyGrid(String),
    /// The reliability grid has more points than an allocation strategy can
    /// run on within minutes ([`crate::allocate::check_grid`]); refused
    /// before anything is derived.
    #[error("the reliability grid has {points} points; {allocation} runs on at most {limit}")]
    #[cfg_attr(
        feature = "miette",
        diagnostic(code(chain::reliability::grid_too_large))
    )]
    GridTooLarge {
        /// The grid's points.
        points: usize,
        /// The allocation's limit.
        limit: usize,
        /// The allocation refused (its name and why it has a limit).
        allocation: crate::allocate::GridUse,
        /// The reliability section.
        origin: Origin,
    },
    /// A point misses a value for an axis variable.
    #[error("no value for axis variable `{0}`")]
    #[cfg_attr(
        feature = "miette",
        diagnostic(code(chain::reliability::missing_coordinate))
    )]
    MissingCoordinate(String),
    /// A computation produced a non-finite number.
    #[error("non-finite value in {0}")]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::reliability::non_finite)))]
    NonFinite(&'static str),
    /// The error's mean or standard deviation at a point is not finite
    /// (axis values too large for the model: sensitivities near 1e300
    /// times the inputs' spread), or the nominal tool point is not.
    #[error("the error at {at} overflows: its {what} is not finite (axis values beyond what the model can carry)")]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::reliability::overflow)))]
    Overflow {
        /// The point, `x = …, y = …`.
        at: String,
        /// What overflowed (`mean of px`, `standard deviation of py`, `nominal tool point`).
        what: String,
    },
    /// An error of the model has no input distribution.
    #[error("no input distribution for error `{0}`")]
    #[cfg_attr(
        feature = "miette",
        diagnostic(code(chain::reliability::missing_input))
    )]
    MissingInput(String),
    /// A sampler was asked for no samples, or for too many.
    #[error("the number of samples must be between 1 and {max} (found {found})")]
    #[cfg_attr(
        feature = "miette",
        diagnostic(code(chain::reliability::invalid_samples))
    )]
    InvalidSamples {
        /// The count asked for.
        found: u64,
        /// The largest allowed.
        max: u64,
    },
    /// A target coefficient of variation outside `(0, 1]` (or not finite).
    #[error("the target coefficient of variation must be in (0, 1] (found `{0}`)")]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::reliability::invalid_cov)))]
    InvalidTargetCov(f64),
    /// A sampler's settings are inconsistent (e.g. subset simulation's
    /// samples per level not a multiple of `1/p0`).
    #[error("invalid sampler settings: {0}")]
    #[cfg_attr(
        feature = "miette",
        diagnostic(code(chain::reliability::invalid_sampler))
    )]
    InvalidSampler(String),
    /// The study's inputs differ from point to point (tables in a values
    /// file), so it has none at an arbitrary point
    /// ([`crate::Study::sensitivity_point`]): a one-point grid has them.
    #[error("the inputs differ from point to point (tables in the values): there are none at an arbitrary point; take the point as a one-point grid instead")]
    #[cfg_attr(
        feature = "miette",
        diagnostic(code(chain::reliability::inputs_vary_at_point))
    )]
    InputsVaryAtPoint,
    /// A setting of an algorithm is out of range.
    #[error("{option}: {message}")]
    #[cfg_attr(
        feature = "miette",
        diagnostic(code(chain::reliability::invalid_option))
    )]
    InvalidOption {
        /// The setting.
        option: &'static str,
        /// What is wrong with it.
        message: String,
    },
}

impl ReliabilityError {
    /// An unknown `name` of this `kind`, with the closest of `known` as the
    /// hint when one is close enough (chain-core's did-you-mean rule).
    pub fn unknown<'a>(
        kind: &'static str,
        name: &str,
        known: impl IntoIterator<Item = &'a str>,
    ) -> ReliabilityError {
        ReliabilityError::UnknownName {
            kind,
            name: name.to_string(),
            hint: chain_core::diagnostic::closest(name, known).map(str::to_string),
        }
    }
}
