//! `chain compensate`: swing-angle error identification and compensation
//! (seed 003) from tool-tip heights measured at commanded angles.

use std::path::PathBuf;

use chain::compensate::{self, CompensateError, Grid, Options, SelectionRule};
use chain::ops::{self, compensate::CompensateRequest, compensate::TableRequest};

use crate::cli::{plot, report};

/// Output format of `chain compensate`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    /// Readable tables.
    Table,
    /// The JSON document of the spec (section 3), on stdout only.
    Json,
}

/// Identify a swing-angle error from tool-tip heights measured at commanded
/// angles and derive its compensation law (seed 003).
///
/// Δθ = acos(cos θ − ΔZ/L) − θ per point, least-squares polynomial fits of
/// every order from --min-order to --max-order with R², the order selected by
/// --select, the law θa = θt + Δθ(θt) and the residual predicted after
/// compensation.
#[derive(Debug, clap::Args)]
pub struct CompensateArgs {
    /// Measurement CSV with header `theta_deg,z1,z3` (an optional `z2` column
    /// adds Table 2's Z1−Z2 and Z2−Z3); `#` starts a comment line.
    pub file: PathBuf,
    /// Distance L from the swing-axis rotation centre to the tool tip (mm).
    #[arg(long, value_name = "L", allow_hyphen_values = true)]
    pub length: f64,
    /// Highest polynomial order fitted.
    #[arg(long, default_value_t = 6, value_name = "N")]
    pub max_order: usize,
    /// Lowest polynomial order fitted.
    #[arg(long, default_value_t = 2, value_name = "N")]
    pub min_order: usize,
    /// Rule that selects the order of the compensation law.
    #[arg(long, value_parser = chain::ops::choice::parser::<SelectionRule>(), default_value = "loocv")]
    pub select: SelectionRule,
    /// Use this order for the law instead of the rule's choice.
    #[arg(long, value_name = "N")]
    pub order: Option<usize>,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    pub format: Format,
    /// Write the figures (PNG and SVG) into this directory.
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
    /// Write a compensation table (CSV) for the angles of --grid.
    #[arg(long, value_name = "FILE.csv")]
    pub table_out: Option<PathBuf>,
    /// Angles of the compensation table, START:STEP:END in degrees (default:
    /// the measured range in 1° steps).
    #[arg(long, value_name = "START:STEP:END", allow_hyphen_values = true)]
    pub grid: Option<Grid>,
    /// Let the table extend beyond the measured angles (polynomial
    /// extrapolation).
    #[arg(long)]
    pub allow_extrapolation: bool,
}

/// Runs `chain compensate` ([`chain::ops::compensate`]): everything that can
/// fail runs before anything is printed, so a failure leaves stdout empty.
pub fn exec(args: CompensateArgs) -> miette::Result<()> {
    if args.grid.is_some() && args.table_out.is_none() {
        return Err(miette::miette!("--grid needs --table-out FILE.csv"));
    }
    let measurements = ops::source::read_swing(ops::source::Source::Path(&args.file))?;
    let request = CompensateRequest {
        options: Options {
            length: args.length,
            min_order: args.min_order,
            max_order: args.max_order,
            rule: args.select,
            fixed_order: args.order,
        },
        table: args.table_out.as_ref().map(|_| TableRequest {
            grid: args.grid,
            allow_extrapolation: args.allow_extrapolation,
        }),
    };
    let mut run = ops::compensate::run(&measurements, &request)?;
    if let (Some(out), Some(rows)) = (&args.table_out, &run.table) {
        let write_error = |source| CompensateError::Write {
            file: out.display().to_string(),
            source,
        };
        crate::cli::atomic::write_with(out, |file| {
            compensate::write_table_csv(rows, std::io::BufWriter::new(file))
        })
        .map_err(write_error)?;
        run.written.push(out.display().to_string());
    }
    if let Some(dir) = &args.plot {
        let plots = plot::write(dir, &chain::plot::compensate::charts(&run.analysis))?;
        run.written
            .extend(plots.iter().map(|p| p.display().to_string()));
    }
    report::emit(&run, args.format.into())
}

report::formats!(Format: Table, Json);
