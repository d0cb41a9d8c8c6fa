//! `chain identify FILE --measurements M.csv [--prior] [--param NAME=VALUE]...
//! [--format table|json] [--values-out VALUES.yaml]`.
//!
//! The error parameters of a built machine from measurements
//! (measured-machines spec, section 4) through
//! [`chain_core::measured::identify`]: the measurement CSV read against the
//! machine ([`chain_core::measured::Measurements`]), the exact sensitivity
//! rows as the design matrix, weighted least squares through an SVD (or the
//! posterior of the `statistics` prior). See `docs/identify.md`.

use std::fmt::Write as _;
use std::path::PathBuf;

use chain_core::measured::document::{
    identify_document, values_file, DocumentError, IdentifyDocument,
};
use chain_core::measured::{Layout, Measurements};

use super::args::ParamArgs;
use super::loaded::Loaded;
use super::report::{self, Report};

/// Output formats of `chain identify`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum IdentifyFormat {
    /// Estimates, what the data cannot separate (in words), residuals.
    Table,
    /// The spec's JSON document.
    Json,
}

report::formats!(IdentifyFormat: Table, Json);

/// Arguments of `chain identify`.
#[derive(Debug, clap::Args)]
pub struct IdentifyArgs {
    /// Machine file (YAML).
    pub file: PathBuf,
    /// The measurement CSV: the axis variables (the pose; rotary in
    /// radians), any parameters per row, `dpx,dpy,dpz` or `ux,uy,uz,d`,
    /// optionally `std`.
    #[arg(long, value_name = "M.csv")]
    pub measurements: PathBuf,
    /// Use the machine file's `statistics` as a Gaussian prior (the answer
    /// is the posterior mean and covariance).
    #[arg(long)]
    pub prior: bool,
    #[command(flatten)]
    pub param: ParamArgs,
    /// Output format.
    #[arg(long, value_enum, default_value = "table")]
    pub format: IdentifyFormat,
    /// Write the estimates as a values file (with `std` per constant and a
    /// `correlation` list) that `chain map --values` and `chain reliability
    /// --values` read.
    #[arg(long, value_name = "VALUES.yaml")]
    pub values_out: Option<PathBuf>,
}

/// Runs `chain identify`.
pub fn exec(args: IdentifyArgs) -> miette::Result<()> {
    let loaded = Loaded::new(&args.file)?;
    let m = &loaded.machine;
    args.param.check_names(m)?;
    let measurements = Measurements::read(
        &args.measurements,
        m,
        &args.param.params,
        Layout::Measurements,
    )?;
    let (doc, result) = identify_document(m, &measurements, args.prior).map_err(|e| match e {
        DocumentError::Design { .. } => miette::miette!("{e}"),
        DocumentError::Identify(e) => miette::Report::new(e),
    })?;
    if let Some(path) = &args.values_out {
        let source = args.measurements.display().to_string();
        let text = values_file(m, &source, &result);
        super::atomic::write(path, text.as_bytes())
            .map_err(|e| miette::miette!("cannot write {}: {e}", path.display()))?;
        eprintln!("wrote {}", path.display());
    }
    report::emit(&doc, args.format.into())
}

/// `v` for a table: 4 significant digits.
fn num(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else if !v.is_finite() {
        "—".into()
    } else if (1e-3..1e5).contains(&v.abs()) {
        format!("{v:.6}")
            .trim_end_matches('0')
            .trim_end_matches('.')
            .to_string()
    } else {
        format!("{v:.4e}")
    }
}

impl Report for IdentifyDocument {
    fn table(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "machine {}: {} measurements ({} rows) from {}, frame {}{}",
            self.machine,
            self.measurements,
            self.rows,
            self.file,
            self.frame,
            if self.weighted {
                ", weighted by std"
            } else {
                ", equal weights"
            }
        );
        let _ = writeln!(
            s,
            "{} unknowns, rank {}, condition {}{}",
            self.parameters,
            self.rank,
            num(self.condition),
            if self.prior {
                "; posterior with the statistics prior"
            } else {
                ""
            }
        );
        let width = self
            .estimates
            .0
            .iter()
            .map(|(n, _)| n.len())
            .max()
            .unwrap_or(5)
            .max(5);
        let _ = writeln!(s, "\n{:<width$}  {:>14}  {:>14}", "error", "value", "std");
        for (name, e) in &self.estimates.0 {
            let std = e.std.map_or("—".to_string(), num);
            // Without a prior, an unknown in the null space has the
            // minimum-norm value and the std of that solution only.
            let note = if self.prior {
                ""
            } else {
                match self
                    .unidentifiable
                    .iter()
                    .filter(|v| v.0.iter().any(|(n, _)| n == name))
                    .map(|v| v.0.len())
                    .min()
                {
                    Some(1) => "  not seen by the data",
                    Some(_) => "  aliased (see below)",
                    None => "",
                }
            };
            let _ = writeln!(s, "{name:<width$}  {:>14}  {std:>14}{note}", num(e.value));
        }
        if !self.groups.is_empty() {
            let _ = writeln!(
                s,
                "\n{}",
                if self.prior {
                    "not informed by the data:"
                } else {
                    "cannot be separated by these measurements (estimates above: the minimum-norm solution):"
                }
            );
            for g in &self.groups {
                let _ = writeln!(s, "  - {}", g.explanation);
            }
            for (k, v) in self.unidentifiable.iter().enumerate() {
                let parts: Vec<String> = v.0.iter().map(|(n, c)| format!("{n}: {c:.5}")).collect();
                let _ = writeln!(s, "  vector {}: {{{}}}", k + 1, parts.join(", "));
            }
        }
        let _ = writeln!(
            s,
            "\nresidual: rms {}, max {}, {} degrees of freedom{}",
            num(self.residual.rms),
            num(self.residual.max),
            self.residual.dof,
            match (self.weighted, self.residual.scale) {
                (true, Some(k)) => format!(", scatter / stated std = {}", num(k)),
                (false, Some(k)) => format!(", noise estimate s = {}", num(k)),
                _ => String::new(),
            }
        );
        if !self.largest_residuals.is_empty() {
            let _ = writeln!(
                s,
                "largest standardised residuals (|t| > {} flagged as a likely outlier): {} flagged",
                chain_core::measured::identify::OUTLIER_LIMIT,
                self.outliers
            );
            for r in self.largest_residuals.iter().take(5) {
                let _ = writeln!(
                    s,
                    "  line {:>6} {:<3}  r = {:>12}  t = {:>8.3}{}",
                    r.line,
                    r.component,
                    num(r.residual),
                    r.standardised,
                    if r.outlier { "  likely outlier" } else { "" }
                );
            }
        }
        s
    }
}
