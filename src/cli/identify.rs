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
use std::path::{Path, PathBuf};

use chain_core::measured::identify::{Estimate, Prior, Residual};
use chain_core::measured::{identify, Design, Identification, Layout, Measurements};
use chain_core::named::NameMap;
use chain_core::{ErrorModel, Machine};
use serde::Serialize;

use super::args::ParamArgs;
use super::reliability::Loaded;
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
    let model = chain_core::compile(m);
    let design = Design::new(&model, m, &measurements.rows)
        .map_err(|e| miette::miette!("{}: {e}", args.measurements.display()))?;
    let prior = if args.prior {
        Some(Prior::from_machine(m, &design.errors)?)
    } else {
        None
    };
    let result = identify(&design, prior.as_ref())?;
    let doc = IdentifyDoc::new(m, &args, &measurements, &design, &result);
    if let Some(path) = &args.values_out {
        let text = values_file(m, &args.measurements, &result);
        std::fs::write(path, text)
            .map_err(|e| miette::miette!("cannot write {}: {e}", path.display()))?;
        eprintln!("wrote {}", path.display());
    }
    // The model is the machine's: its error names are the design's.
    debug_assert_eq!(model.errors().len(), design.errors.len());
    report::emit(&doc, args.format.into())
}

/// One group of unknowns the data cannot separate.
#[derive(Debug, Serialize)]
struct GroupDoc {
    /// The unknowns of the group.
    errors: Vec<String>,
    /// How many independent combinations of them the data cannot tell.
    vectors: usize,
    /// The same in words.
    explanation: String,
}

/// One of the largest standardised residuals.
#[derive(Debug, Serialize)]
struct ResidualDoc {
    /// The CSV line of its measurement.
    line: usize,
    /// `dpx`, `dpy`, `dpz` or `d`.
    component: &'static str,
    residual: f64,
    standardised: f64,
    leverage: f64,
    outlier: bool,
}

/// The result document (spec section 4's keys first, then additions).
#[derive(Debug, Serialize)]
struct IdentifyDoc {
    machine: String,
    /// Measurement records (CSV rows).
    measurements: usize,
    parameters: usize,
    rank: usize,
    condition: f64,
    estimates: NameMap<String, Estimate>,
    unidentifiable: Vec<NameMap<String, f64>>,
    residual: Residual,
    // --- additions ---
    file: String,
    /// Scalar rows of the design (3 per point, 1 per direction).
    rows: usize,
    weighted: bool,
    prior: bool,
    frame: &'static str,
    groups: Vec<GroupDoc>,
    largest_residuals: Vec<ResidualDoc>,
    outliers: usize,
}

impl IdentifyDoc {
    fn new(
        m: &Machine,
        args: &IdentifyArgs,
        measurements: &Measurements,
        design: &Design,
        r: &Identification,
    ) -> IdentifyDoc {
        let groups = r
            .groups
            .iter()
            .map(|g| {
                let errors: Vec<String> = g.members.iter().map(|&j| r.errors[j].clone()).collect();
                GroupDoc {
                    explanation: explain(design, r, &g.members, g.vectors.len()),
                    vectors: g.vectors.len(),
                    errors,
                }
            })
            .collect();
        IdentifyDoc {
            machine: m.name.clone(),
            measurements: measurements.rows.len(),
            parameters: r.parameters,
            rank: r.rank,
            condition: r.condition,
            estimates: r.estimates.clone(),
            unidentifiable: r.unidentifiable.clone(),
            residual: r.residual,
            file: args.measurements.display().to_string(),
            rows: r.rows,
            weighted: r.weighted,
            prior: r.prior,
            frame: m.frame.name(),
            groups,
            largest_residuals: (r.largest_residuals.iter())
                .map(|s| ResidualDoc {
                    line: measurements.rows[design.origin[s.row].0].line,
                    component: s.component,
                    residual: s.residual,
                    standardised: s.standardised,
                    leverage: s.leverage,
                    outlier: s.outlier,
                })
                .collect(),
            outliers: r.outliers,
        }
    }
}

/// `a`, `a and b`, `a, b and c`.
fn and_list(names: &[String]) -> String {
    match names {
        [] => String::new(),
        [one] => one.clone(),
        [init @ .., last] => format!("{} and {last}", init.join(", ")),
    }
}

/// The measured component's name in words (`dpx` → `px`).
fn component_name(c: &str) -> &str {
    c.strip_prefix("d").filter(|s| !s.is_empty()).unwrap_or(c)
}

/// A group of the null space in words, derived from the design's columns
/// of its members: when they are all parallel (column rank 1), which
/// measured components they act on and whether as a constant (an offset);
/// otherwise how many independent combinations they act through.
fn explain(design: &Design, r: &Identification, members: &[usize], vectors: usize) -> String {
    let names: Vec<String> = members.iter().map(|&j| r.errors[j].clone()).collect();
    let list = and_list(&names);
    if r.prior {
        return format!(
            "the measurements leave {} of {list} at the prior (posterior std above {} × the prior std along {})",
            if vectors == 1 { "one combination".to_string() } else { format!("{vectors} combinations") },
            chain_core::measured::identify::UNINFORMED,
            if vectors == 1 { "it" } else { "them" }
        );
    }
    let rank = members.len() - vectors;
    if rank == 0 {
        return if names.len() == 1 {
            format!("{list} has no effect on these measurements")
        } else {
            format!("{list} have no effect on these measurements")
        };
    }
    if rank == 1 {
        // The member whose column is largest stands for the group.
        let a = &design.a;
        let best = members
            .iter()
            .copied()
            .max_by(|&i, &j| a.column(i).norm().total_cmp(&a.column(j).norm()))
            .unwrap_or(members[0]);
        let col = a.column(best);
        let scale = col.amax();
        let mut components: Vec<&'static str> = Vec::new();
        let mut constant = true;
        for comp in ["dpx", "dpy", "dpz", "d"] {
            let values: Vec<f64> = (0..a.nrows())
                .filter(|&i| design.origin[i].1 == comp)
                .map(|i| col[i])
                .collect();
            if values.iter().any(|v| v.abs() > 1e-9 * scale) {
                components.push(comp);
                let first = values[0];
                if values.iter().any(|v| (v - first).abs() > 1e-9 * scale) {
                    constant = false;
                }
            }
        }
        let on: Vec<String> = components
            .iter()
            .map(|c| component_name(c).to_string())
            .collect();
        let what = if constant {
            format!("one offset in {}", and_list(&on))
        } else {
            format!("one combined error in {}", and_list(&on))
        };
        return format!("{list} only act as {what}");
    }
    format!(
        "{list} only act through {rank} independent combinations; {vectors} combination{} of them cannot be seen in these measurements",
        if vectors == 1 { "" } else { "s" }
    )
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

impl Report for IdentifyDoc {
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

/// The estimates as a values file (spec section 2, plus `std` per constant
/// and the `correlation` list, one `[NAME, NAME, ρ]` per pair with ρ ≠ 0:
/// the form `chain reliability --values` reads, docs/posterior.md).
pub(crate) fn values_file(m: &Machine, source: &Path, r: &Identification) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# written by chain identify from {}: {} rows, rank {} of {} unknowns{}",
        source.display(),
        r.rows,
        r.rank,
        r.parameters,
        if r.prior {
            ", posterior with the statistics prior"
        } else {
            ""
        }
    );
    if !r.unidentifiable.is_empty() && !r.prior {
        let _ = writeln!(
            s,
            "# rank deficient: the values are the minimum-norm solution; see `chain identify` for what cannot be separated"
        );
    }
    let _ = writeln!(s, "machine: {}", m.name);
    let _ = writeln!(s, "units: {{linear: mm, angular: rad}}");
    let _ = writeln!(s, "values:");
    let all_std = r.estimates.0.iter().all(|(_, e)| e.std.is_some());
    for (name, e) in &r.estimates.0 {
        match e.std {
            Some(std) => {
                let _ = writeln!(s, "  {name}: {{value: {:?}, std: {:?}}}", e.value, std);
            }
            None => {
                let _ = writeln!(s, "  {name}: {:?}", e.value);
            }
        }
    }
    if all_std {
        let n = r.parameters;
        let sd: Vec<f64> = (0..n)
            .map(|j| r.covariance[(j, j)].max(0.0).sqrt())
            .collect();
        let mut pairs = Vec::new();
        for i in 0..n {
            for j in i + 1..n {
                if sd[i] > 0.0 && sd[j] > 0.0 {
                    let rho = (r.covariance[(i, j)] / (sd[i] * sd[j])).clamp(-1.0, 1.0);
                    if rho != 0.0 {
                        pairs.push((i, j, rho));
                    }
                }
            }
        }
        if !pairs.is_empty() {
            let _ = writeln!(
                s,
                "# the correlation of each pair of estimates (pairs not listed: exactly 0)"
            );
            let _ = writeln!(s, "correlation:");
            for (i, j, rho) in pairs {
                let _ = writeln!(s, "  - [{}, {}, {rho:?}]", r.errors[i], r.errors[j]);
            }
        }
    }
    s
}
