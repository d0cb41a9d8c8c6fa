//! `chain plan FILE (--candidates C.csv | --spheres-candidates C.csv) --count K [--kind point|direction]
//! [--param NAME=VALUE]... [--format table|json]`.
//!
//! Where to measure (measured-machines spec, section 5): `K` of the candidate
//! poses maximising `det(AᵀA)` on the identifiable subspace, through
//! [`chain_core::plan::plan`], against `K` candidates taken evenly. The
//! candidate CSV has the measurement CSV's columns (section 4) without the
//! measured values: the axis variables, optionally parameters per row, and
//! for direction measurements `ux, uy, uz`. See `docs/plan.md`.

use std::path::{Path, PathBuf};

use chain::ops::plan::{self, PlanRequest};
use chain_core::measured::{Layout, Measurements};
use chain_core::plan::Kind;

use crate::cli::args::ParamArgs;
use crate::cli::loaded::Loaded;
use crate::cli::report;

/// Output formats of `chain plan`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum PlanFormat {
    /// The chosen candidates and the std per parameter, optimal against even.
    Table,
    /// The whole plan as JSON.
    Json,
}

report::formats!(PlanFormat: Table, Json);

/// Arguments of `chain plan`.
#[derive(Debug, clap::Args)]
pub struct PlanArgs {
    /// Machine file (YAML).
    pub file: PathBuf,
    /// Candidate poses (CSV): the measurement CSV's columns without the
    /// measured values: a column per axis variable (rotary in radians),
    /// optional columns of parameters given per row, `ux,uy,uz` for
    /// direction measurements, optionally `std`; `-` reads stdin.
    #[arg(
        long,
        value_name = "C.csv",
        required_unless_present = "spheres_candidates"
    )]
    pub candidates: Option<PathBuf>,
    /// Candidate sphere probings instead (the sphere file's columns: every
    /// axis variable, rotary ones in degrees, optionally `sphere` and
    /// `std`): the K probings that determine the location errors best,
    /// each sphere's position counted among the unknowns.
    #[arg(long, value_name = "C.csv", conflicts_with = "candidates")]
    pub spheres_candidates: Option<PathBuf>,
    /// How many candidates to choose.
    #[arg(long, value_name = "K")]
    pub count: usize,
    /// What each candidate measures (default: `direction` when the file has
    /// `ux,uy,uz`, else `point`; a `--kind` that contradicts the file is
    /// refused).
    #[arg(long, value_parser = chain::ops::choice::parser::<Kind>())]
    pub kind: Option<Kind>,
    #[command(flatten)]
    pub param: ParamArgs,
    /// Output format.
    #[arg(long, value_enum, default_value = "table")]
    pub format: PlanFormat,
}

/// Runs `chain plan` ([`chain::ops::plan`]).
pub fn exec(args: PlanArgs) -> miette::Result<()> {
    let loaded = Loaded::new(&args.file)?;
    let m = &loaded.machine;
    args.param.check_names(m)?;
    let candidates = match (&args.candidates, &args.spheres_candidates) {
        (_, Some(spheres)) => Measurements::read_spheres(spheres, m, &args.param.params)?,
        (Some(path), None) if path.as_os_str() == "-" => {
            let name = display(path);
            let (_, bytes) =
                crate::cli::csv_input::read_input(path, chain_core::bounded::MEASUREMENT_BYTES)?;
            let text = String::from_utf8(bytes).map_err(|e| {
                miette::miette!(code = "chain::utf8", "{name}: not UTF-8 text ({e})")
            })?;
            Measurements::parse(&text, &name, m, &args.param.params, Layout::Candidates)?
        }
        (Some(path), None) => {
            Measurements::read(path, m, &args.param.params, Layout::Candidates)?
        }
        (None, None) => {
            return Err(miette::miette!(
                code = "chain::plan::candidates",
                "--candidates: give the candidate CSV (--candidates C.csv) or sphere-probing candidates (--spheres-candidates C.csv)"
            ))
        }
    };
    let request = PlanRequest {
        count: args.count,
        kind: args.kind,
    };
    let doc = plan::run(m, &candidates, &request)?;
    report::emit(&doc, args.format.into())
}

fn display(path: &Path) -> String {
    if path.as_os_str() == "-" {
        "<stdin>".into()
    } else {
        path.display().to_string()
    }
}
