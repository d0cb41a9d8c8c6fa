//! `chain compensate`: swing-angle error identification and compensation
//! (seed 003) from tool-tip heights measured at commanded angles.

use std::fmt::Write as _;
use std::path::PathBuf;

use chain::compensate::{self, Analysis, CompensateError, Grid, Options, SelectionRule};
use miette::IntoDiagnostic;

/// Output format of `chain compensate`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    /// Readable tables.
    Table,
    /// The JSON document of the spec (section 3), on stdout only.
    Json,
}

/// Order-selection rule (see docs/compensation.md).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Select {
    /// Smallest leave-one-out cross-validation error (default).
    Loocv,
    /// Largest adjusted R².
    AdjustedR2,
    /// Smallest small-sample AIC.
    Aicc,
    /// Smallest BIC.
    Bic,
}

impl From<Select> for SelectionRule {
    fn from(s: Select) -> Self {
        match s {
            Select::Loocv => SelectionRule::Loocv,
            Select::AdjustedR2 => SelectionRule::AdjustedR2,
            Select::Aicc => SelectionRule::Aicc,
            Select::Bic => SelectionRule::Bic,
        }
    }
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
    #[arg(long, value_enum, default_value_t = Select::Loocv)]
    pub select: Select,
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

/// Runs `chain compensate`: everything that can fail runs before anything is
/// printed, so a failure leaves stdout empty.
pub fn exec(args: CompensateArgs) -> miette::Result<()> {
    let measurements = compensate::read_csv(&args.file)?;
    let options = Options {
        length: args.length,
        min_order: args.min_order,
        max_order: args.max_order,
        rule: args.select.into(),
        fixed_order: args.order,
    };
    let analysis = compensate::analyze(&measurements, &options)?;

    let mut files: Vec<PathBuf> = Vec::new();
    let mut table_rows = None;
    if let Some(out) = &args.table_out {
        let [lo, hi] = analysis.angle_range();
        let grid = args.grid.unwrap_or(Grid::unit(lo, hi));
        let rows = analysis
            .compensation
            .table(&grid.points()?, args.allow_extrapolation)?;
        let write_error = |source| CompensateError::Write {
            file: out.display().to_string(),
            source,
        };
        let file = std::fs::File::create(out).map_err(write_error)?;
        compensate::write_table_csv(&rows, std::io::BufWriter::new(file)).map_err(write_error)?;
        files.push(out.clone());
        table_rows = Some(rows.len());
    } else if args.grid.is_some() {
        return Err(miette::miette!("--grid needs --table-out FILE.csv"));
    }
    if let Some(dir) = &args.plot {
        files.extend(compensate::write_plots(&analysis, dir)?);
    }

    let text = match args.format {
        Format::Json => {
            let document = JsonDocument {
                analysis: &analysis,
                written: files.iter().map(|p| p.display().to_string()).collect(),
            };
            let mut s = serde_json::to_string_pretty(&document).into_diagnostic()?;
            s.push('\n');
            s
        }
        Format::Table => render_table(&analysis, &files, table_rows),
    };
    use std::io::Write as _;
    let mut stdout = std::io::stdout().lock();
    // A closed pipe (`| head`) is not an error worth a message.
    let _ = stdout
        .write_all(text.as_bytes())
        .and_then(|()| stdout.flush());
    Ok(())
}

/// The `--format json` document: the analysis (spec fields first, in struct
/// order) and the files written, if any.
#[derive(serde::Serialize)]
struct JsonDocument<'a> {
    #[serde(flatten)]
    analysis: &'a Analysis,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    written: Vec<String>,
}

/// The `--format table` report.
fn render_table(a: &Analysis, files: &[PathBuf], table_rows: Option<usize>) -> String {
    let mut s = String::new();
    let has_z2 = a.points.iter().any(|p| p.z2.is_some());
    let _ = writeln!(
        s,
        "Swing-angle error from {} ({} points, L = {} mm)\n",
        a.file,
        a.points.len(),
        a.length
    );
    let _ = write!(s, "{:>8} {:>11}", "θ (°)", "Z1−Z3 (mm)");
    if has_z2 {
        let _ = write!(s, " {:>11} {:>11}", "Z1−Z2 (mm)", "Z2−Z3 (mm)");
    }
    let _ = writeln!(
        s,
        " {:>11} {:>11} {:>11} {:>11}",
        "ΔZ (mm)", "Δθ (°)", "fit (°)", "resid. (°)"
    );
    for p in &a.points {
        let _ = write!(s, "{:>8} {:>11.6}", p.theta_deg, p.z1_minus_z3);
        if has_z2 {
            let _ = write!(
                s,
                " {:>11.6} {:>11.6}",
                p.z1_minus_z2.unwrap_or(f64::NAN),
                p.z2_minus_z3.unwrap_or(f64::NAN)
            );
        }
        let _ = writeln!(
            s,
            " {:>11.6} {:>11.6} {:>11.6} {:>11.6}",
            p.delta_z_mm, p.delta_theta_deg, p.fitted_deg, p.residual_deg
        );
    }
    let _ = writeln!(
        s,
        "\nΔZ = Z2 − Z3 with the theoretical Z2 = Z1 − L(1 − cos θ); Δθ = acos(cos θ − ΔZ/L) − θ (Eq. 5)."
    );
    let _ = writeln!(s, "\nPolynomial fits of Δθ(θ), θ in degrees:\n");
    let _ = writeln!(
        s,
        "{:>5} {:>8} {:>8} {:>10} {:>11} {:>9} {:>9} {:>8}  coefficients (ascending powers of θ)",
        "order", "R²", "adj. R²", "RMSE (°)", "LOOCV (°)", "AICc", "BIC", "F-test p"
    );
    for f in &a.fits {
        let coefficients: Vec<String> = f.coefficients.iter().map(|c| format!("{c:.6e}")).collect();
        let mark = if f.order == a.selected_order {
            "*"
        } else {
            " "
        };
        let _ = writeln!(
            s,
            "{mark}{:>4} {:>8.4} {:>8.4} {:>10.6} {:>11.6} {:>9} {:>9.3} {:>8}  [{}]",
            f.order,
            f.r2,
            f.adjusted_r2,
            f.rmse,
            f.loocv_rmse,
            f.aicc
                .map_or_else(|| "-".to_string(), |v| format!("{v:.3}")),
            f.bic,
            f.f_test_p
                .map_or_else(|| "-".to_string(), |v| format!("{v:.3}")),
            coefficients.join(", ")
        );
    }
    let by_rule: Vec<String> = a
        .selection
        .by_rule
        .iter()
        .map(|(rule, order)| format!("{rule} → {order}"))
        .collect();
    let _ = writeln!(
        s,
        "\nSelected order: {} (rule: {}: {})\nOrders the rules pick: {}",
        a.selected_order,
        a.selection.rule,
        a.selection.description,
        by_rule.join(", ")
    );
    let c = &a.compensation;
    let _ = writeln!(s, "\nCompensation law (θ, Δθ in degrees):\n  {}", c.law);
    let _ = writeln!(
        s,
        "  commanding θt leaves the axis at θa = θt + Δθ(θt) (Eq. 7);\n  to reach θt, command c with c + Δθ(c) = θt (≈ θt − Δθ(θt))."
    );
    let r = &c.residual;
    let _ = writeln!(
        s,
        "\nError at the measured angles (°):\n  before: {:+.6} .. {:+.6}  (RMS {:.6})\n  after (predicted residual): {:+.6} .. {:+.6}  (RMS {:.6}; leave-one-out RMS {:.6})",
        r.before.min_deg,
        r.before.max_deg,
        r.before.rms_deg,
        r.after.min_deg,
        r.after.max_deg,
        r.after.rms_deg,
        r.loocv_rms_deg
    );
    if let Some(best) = a.fits.iter().filter_map(|f| f.f_test_p).reduce(f64::min) {
        if best > 0.05 {
            let _ = writeln!(
                s,
                "\nNote: no fit is significant against a constant error at the 5 % level (smallest F-test p = {best:.3})."
            );
        }
    }
    if !files.is_empty() {
        let _ = writeln!(s);
        for f in files {
            let _ = writeln!(s, "wrote {}", f.display());
        }
        if let Some(n) = table_rows {
            let _ = writeln!(s, "(compensation table: {n} angles)");
        }
    }
    s
}
