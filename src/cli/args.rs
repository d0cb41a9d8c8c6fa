//! Command-line arguments shared by several subcommands, flattened into
//! their argument structs with `#[command(flatten)]`.

use chain::ops::choice::parser;
use chain::ops::study::SystemKind;
use chain_core::diagnostic::shortened;
use chain_core::model::Sided;
use reliability::Method;

/// `--param NAME=VALUE`: the values of the machine file's parameters.
#[derive(Debug, clap::Args)]
pub struct ParamArgs {
    /// Value of a parameter, `NAME=VALUE` (repeatable; required for symbolic ones).
    #[arg(long = "param", value_name = "NAME=VALUE", value_parser = parse_param)]
    pub params: Vec<(String, f64)>,
}

impl ParamArgs {
    /// Refuses a `--param` naming no parameter of `m` (with the closest
    /// name), or not finite, for the commands whose parameters may also
    /// come per CSV row (`identify`, `plan`): their values are placed where
    /// they are used.
    pub fn check_names(&self, m: &chain_core::Machine) -> miette::Result<()> {
        Ok(chain::ops::resolve::check_parameters(m, &self.params)?)
    }
}

/// How a circular-test file's runs are read where the file gives no column
/// (`chain circular`, `chain identify --circular`).
#[derive(Debug, clap::Args)]
pub struct RunFileArgs {
    /// The nominal radius (mm) of runs whose file gives none.
    #[arg(long, value_name = "R")]
    pub radius: Option<f64>,
    /// The feed (mm/min) of runs whose file gives none.
    #[arg(long, value_name = "F")]
    pub feed: Option<f64>,
    /// The plane of runs whose file gives none: xy (default), yz or zx.
    #[arg(long, value_name = "PLANE")]
    pub plane: Option<String>,
    /// The arc every direction covers, in degrees (default the whole
    /// circle, 360).
    #[arg(long, value_name = "DEG")]
    pub arc: Option<f64>,
}

/// `--temperature NAME=VALUE,...`: the thermal state at which a machine with
/// `sensors` is evaluated (docs/thermal.md).
#[derive(Debug, clap::Args)]
pub struct ThermalArgs {
    /// Temperature of a sensor of the machine file, `NAME=VALUE` in °C
    /// (comma-separated or repeated; sensors not named stay at their
    /// reference).
    #[arg(
        long = "temperature",
        value_name = "NAME=VALUE",
        value_delimiter = ',',
        value_parser = parse_param
    )]
    pub temperatures: Vec<(String, f64)>,
}

/// `--param` and `--sided`: the model of a machine file with `statistics`.
#[derive(Debug, clap::Args)]
pub struct ModelArgs {
    #[command(flatten)]
    pub param: ParamArgs,
    /// Override the file's `sided`.
    #[arg(long, value_parser = parser::<Sided>())]
    pub sided: Option<Sided>,
}

/// `--method`, `--samples`, `--seed`: the reliability algorithm of a study.
#[derive(Debug, clap::Args)]
pub struct AlgorithmArgs {
    /// Reliability algorithm.
    #[arg(long, value_parser = parser::<Method>(), default_value = "form")]
    pub method: Method,
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
    #[arg(long, value_name = "C", value_parser = parse_cov, allow_negative_numbers = true)]
    pub cov: Option<f64>,
}

impl AlgorithmArgs {
    /// The options as the application layer takes them.
    pub fn options(&self) -> chain::ops::study::AlgorithmOptions {
        chain::ops::study::AlgorithmOptions {
            method: self.method,
            samples: self.samples,
            seed: self.seed,
            cov: self.cov,
        }
    }

    /// The sampler options that need no model
    /// ([`chain::ops::study::AlgorithmOptions::check`]).
    pub fn check(&self) -> miette::Result<()> {
        Ok(self.options().check()?)
    }
}

/// `--system`, `--system-tolerance`: a system target besides the components.
#[derive(Debug, clap::Args)]
pub struct SystemArgs {
    /// Also assess a system limit state.
    #[arg(long, value_parser = parser::<SystemKind>())]
    pub system: Option<SystemKind>,
    /// Allowable volumetric error for `--system volumetric` (default: the
    /// smallest position tolerance).
    #[arg(
        long = "system-tolerance",
        value_name = "I",
        requires = "system",
        allow_negative_numbers = true
    )]
    pub tolerance: Option<f64>,
}

/// Parses `--cov` as a number; its range is the application layer's rule
/// ([`chain::ops::study::AlgorithmOptions::check`]).
pub(crate) fn parse_cov(s: &str) -> Result<f64, String> {
    s.trim()
        .parse()
        .map_err(|_| format!("`{}` is not a number", shortened(s)))
}

impl SystemArgs {
    /// The choice as the application layer takes it
    /// ([`chain::ops::study::SystemChoice::new`]).
    pub fn choice(
        &self,
    ) -> Result<Option<chain::ops::study::SystemChoice>, chain::ops::study::OptionError> {
        chain::ops::study::SystemChoice::new(self.system, self.tolerance)
    }
}

/// Parses `--param NAME=VALUE` as a name and a number; whether the name is
/// a parameter and the value finite is the application layer's rule
/// ([`chain::ops::resolve::check_parameters`]).
pub(crate) fn parse_param(s: &str) -> Result<(String, f64), String> {
    let (name, value) = s
        .split_once('=')
        .ok_or_else(|| format!("expected NAME=VALUE, found `{}`", shortened(s)))?;
    let v: f64 = value
        .trim()
        .parse()
        .map_err(|_| format!("`{}` is not a number", shortened(value)))?;
    Ok((name.trim().to_string(), v))
}

/// Parses `NAME=VALUE` with a finite value (`--fix`, `--at`).
pub(crate) fn parse_assignment(s: &str) -> Result<(String, f64), String> {
    let (name, v) = parse_param(s)?;
    if !v.is_finite() {
        let value = s.split_once('=').map_or(s, |(_, v)| v);
        return Err(format!("`{}` is not finite", shortened(value)));
    }
    Ok((name, v))
}

/// Parses `VAR=v1,v2,...` (a grid axis on the command line).
pub(crate) fn parse_axis(s: &str) -> Result<(String, Vec<f64>), String> {
    let (name, values) = s
        .split_once('=')
        .ok_or_else(|| format!("expected VAR=V1,V2,..., found `{}`", shortened(s)))?;
    let values = values
        .split(',')
        .map(|v| {
            v.trim()
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| format!("`{}` is not a finite number", shortened(v)))
        })
        .collect::<Result<Vec<_>, _>>()?;
    if values.is_empty() {
        return Err(format!("axis `{}` has no value", shortened(name)));
    }
    Ok((name.trim().to_string(), values))
}

/// Parses `VAR=V1,V2,...` or `VAR=LO:HI:N`.
pub(crate) fn parse_grid_axis(s: &str) -> Result<(String, Vec<f64>), String> {
    let Some((name, spec)) = s.split_once('=') else {
        return Err(format!(
            "expected VAR=V1,V2,... or VAR=LO:HI:N, found `{s}`"
        ));
    };
    if !spec.contains(':') {
        return parse_axis(s);
    }
    let parts: Vec<&str> = spec.split(':').map(str::trim).collect();
    let [lo, hi, n] = parts[..] else {
        return Err(format!(
            "expected LO:HI:N after `{}=`, found `{}`",
            shortened(name),
            shortened(spec)
        ));
    };
    let number = |t: &str| {
        t.parse::<f64>()
            .ok()
            .filter(|x| x.is_finite())
            .ok_or_else(|| format!("`{}` is not a finite number", shortened(t)))
    };
    let (lo, hi) = (number(lo)?, number(hi)?);
    let n: usize = n.parse().map_err(|_| {
        format!(
            "`{}` is not a count of values (a whole number ≥ 2)",
            shortened(n)
        )
    })?;
    if n < 2 {
        return Err(format!(
            "LO:HI:N needs N ≥ 2 values, found {n} (one value is `{name}=V`)"
        ));
    }
    if lo == hi {
        return Err(format!("LO:HI:N needs LO ≠ HI, found {lo} twice"));
    }
    let step = (hi - lo) / (n - 1) as f64;
    let values = (0..n)
        .map(|k| if k == n - 1 { hi } else { lo + step * k as f64 })
        .collect();
    Ok((name.trim().to_string(), values))
}

/// The coordinates of `--at`, `(variable, value)` in the order given.
#[derive(Debug, Clone, PartialEq)]
pub struct AtPoint(pub Vec<(String, f64)>);

/// Parses `x=0,y=1500,z=600`.
/// A coordinate given twice is refused (the last one would silently win).
pub(crate) fn parse_point(s: &str) -> Result<AtPoint, String> {
    let point = s
        .split(',')
        .filter(|p| !p.trim().is_empty())
        .map(parse_assignment)
        .collect::<Result<Vec<_>, _>>()?;
    for (i, (name, _)) in point.iter().enumerate() {
        if point[..i].iter().any(|(n, _)| n == name) {
            return Err(format!("`{}` is given twice", shortened(name)));
        }
    }
    Ok(AtPoint(point))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_ranges_are_evenly_spaced_and_end_at_hi() {
        let (n, v) = parse_grid_axis("x=0:1000:5").unwrap();
        assert_eq!(n, "x");
        assert_eq!(v, [0.0, 250.0, 500.0, 750.0, 1000.0]);
        let (_, v) = parse_grid_axis("z = 1:0:3").unwrap();
        assert_eq!(v, [1.0, 0.5, 0.0]);
        let (_, v) = parse_grid_axis("y=0.1:0.7:7").unwrap();
        assert_eq!(v.len(), 7);
        assert_eq!(v[6], 0.7);
        assert_eq!(parse_grid_axis("x=1,2").unwrap().1, [1.0, 2.0]);
        assert!(parse_grid_axis("x=0:1:1").unwrap_err().contains("N ≥ 2"));
        assert!(parse_grid_axis("x=0:1").unwrap_err().contains("LO:HI:N"));
        assert!(parse_grid_axis("x=0:0:3").unwrap_err().contains("LO ≠ HI"));
        assert!(parse_grid_axis("x=0:inf:3").is_err());
        assert!(parse_grid_axis("x=0:1:2.5").is_err());
    }
}
