//! Command-line arguments shared by several subcommands, flattened into
//! their argument structs with `#[command(flatten)]`.

use super::reliability::{parse_assignment, MethodArg, SidedArg, SystemArg};

/// `--param NAME=VALUE`: the values of the machine file's parameters.
#[derive(Debug, clap::Args)]
pub struct ParamArgs {
    /// Value of a parameter, `NAME=VALUE` (repeatable; required for symbolic ones).
    #[arg(long = "param", value_name = "NAME=VALUE", value_parser = parse_assignment)]
    pub params: Vec<(String, f64)>,
}

impl ParamArgs {
    /// Refuses a `--param` naming no parameter of `m` (with the closest
    /// name), for the commands whose parameters may also come per CSV row
    /// (`identify`, `plan`): their values are checked where they are used.
    pub fn check_names(&self, m: &chain_core::Machine) -> miette::Result<()> {
        Ok(chain::ops::resolve::check_parameters(m, &self.params)?)
    }
}

/// `--param` and `--sided`: the model of a machine file with `statistics`.
#[derive(Debug, clap::Args)]
pub struct ModelArgs {
    #[command(flatten)]
    pub param: ParamArgs,
    /// Override the file's `sided`.
    #[arg(long, value_enum)]
    pub sided: Option<SidedArg>,
}

/// `--method`, `--samples`, `--seed`: the reliability algorithm of a study.
#[derive(Debug, clap::Args)]
pub struct AlgorithmArgs {
    /// Reliability algorithm.
    #[arg(long, value_enum, default_value = "form")]
    pub method: MethodArg,
    /// Samples per case, one case per target and point or instant (is: 10000,
    /// mc: 100000 by default).
    #[arg(long)]
    pub samples: Option<u64>,
    /// Seed of the random streams (results do not depend on the thread count).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Target coefficient of variation of each case's p_f, in (0, 1]: the
    /// sampler stops when it is reached, `--samples` being the budget (mc:
    /// 10^7, is and directional: 10^6 by default; subset: `--samples` per
    /// level, at most 1000 levels' worth); a case that runs out is marked
    /// not converged.
    #[arg(long, value_name = "C", value_parser = super::reliability::parse_cov, allow_negative_numbers = true)]
    pub cov: Option<f64>,
}

impl AlgorithmArgs {
    /// The sampler options that need no model (`reliability::document::check_options`):
    /// `--cov` with FORM or SORM, subset samples per level.
    pub fn check(&self) -> miette::Result<()> {
        let method = self.method.method();
        reliability::document::check_options(method, self.samples, self.cov).map_err(|p| {
            miette::miette!(
                code = "chain::cli::invalid_option",
                "invalid value for '--{}': {}",
                p.option,
                p.message
            )
        })
    }

    /// The library's algorithm for these options.
    pub fn algorithm(&self) -> reliability::Algorithm {
        let samples = self.method.samples(self.samples, self.cov.is_some());
        self.method.algorithm_with(samples, self.seed, self.cov)
    }
}

/// `--system`, `--system-tolerance`: a system target besides the components.
#[derive(Debug, clap::Args)]
pub struct SystemArgs {
    /// Also assess a system limit state.
    #[arg(long, value_enum)]
    pub system: Option<SystemArg>,
    /// Allowable volumetric error for `--system volumetric` (default: the
    /// smallest position tolerance).
    #[arg(long = "system-tolerance", value_name = "I", requires = "system")]
    pub tolerance: Option<f64>,
}
