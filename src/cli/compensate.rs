//! `chain compensate`: swing-angle error identification and compensation
//! (seed 003) from tool-tip heights measured at commanded angles.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use chain::compensate::{
    self, Analysis, CompensateError, Grid, Measurements, Options, SelectionRule,
};

use super::report::{self, Report};

#[path = "compensate_plot.rs"]
mod compensate_plot;

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
    let measurements = read_measurements(&args.file)?;
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
        super::atomic::write_with(out, |file| {
            compensate::write_table_csv(&rows, std::io::BufWriter::new(file))
        })
        .map_err(write_error)?;
        files.push(out.clone());
        table_rows = Some(rows.len());
    } else if args.grid.is_some() {
        return Err(miette::miette!("--grid needs --table-out FILE.csv"));
    }
    if let Some(dir) = &args.plot {
        files.extend(compensate_plot::write_plots(&analysis, dir)?);
    }

    let document = CompensateReport {
        analysis,
        written: files.iter().map(|p| p.display().to_string()).collect(),
        table_rows,
    };
    report::emit(&document, args.format.into())
}

report::formats!(Format: Table, Json);

/// The measurements of a CSV file ([`chain::compensate::records`]).
pub(crate) fn read_measurements(path: &Path) -> Result<Measurements, CompensateError> {
    compensate::records::read_measurements(path)
}

/// The result document of `chain compensate`: the analysis (the spec's fields
/// first, in struct order), then the files written, if any. Its JSON is the
/// `--format json` output.
#[derive(serde::Serialize)]
pub struct CompensateReport {
    /// Everything derived from the measurement file.
    #[serde(flatten)]
    pub analysis: Analysis,
    /// The files written (`--table-out`, `--plot`), in order.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub written: Vec<String>,
    /// Rows of the compensation table written, if one was.
    #[serde(skip)]
    pub table_rows: Option<usize>,
}

impl Report for CompensateReport {
    /// The `--format table` report.
    fn table(&self) -> String {
        let (a, files, table_rows) = (&self.analysis, &self.written, self.table_rows);
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
            let coefficients: Vec<String> =
                f.coefficients.iter().map(|c| format!("{c:.6e}")).collect();
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
                let _ = writeln!(s, "wrote {f}");
            }
            if let Some(n) = table_rows {
                let _ = writeln!(s, "(compensation table: {n} angles)");
            }
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What `chain compensate` makes of the bytes of a file named `name`.
    fn parse(name: &str, data: &[u8]) -> Result<Measurements, CompensateError> {
        compensate::records::parse_measurements(name, data)
    }

    #[test]
    fn reader_skips_comments_blank_lines_and_a_byte_order_mark() {
        let m = parse(
            "mem.csv",
            b"# comment\n\nZ3, note, THETA_DEG ,z1\r\n-171.1,\"a, b\",1,-170.99\n\n# again\n-171.4275,b,2,-170.99\n",
        )
        .unwrap();
        assert_eq!(m.header_line, 3);
        assert_eq!(m.records.iter().map(|r| r.line).collect::<Vec<_>>(), [4, 7]);
        assert_eq!(m.records[1].theta_deg, 2.0);
        assert_eq!(m.records[1].z3, -171.4275);
        let m = parse("bom.csv", b"\xEF\xBB\xBFtheta_deg,z1,z3\n1,0,-0.1\n").unwrap();
        assert_eq!((m.header_line, m.records[0].line), (1, 2));
    }

    #[test]
    fn reader_errors_name_the_file_and_line() {
        let e = parse("bad.csv", b"theta_deg,z1,z3\n1,0,\xFF\n").unwrap_err();
        assert!(
            matches!(e, CompensateError::Malformed { line: 2, .. }),
            "{e}"
        );
        assert!(
            e.to_string()
                .starts_with("bad.csv:2: the line is not valid UTF-8"),
            "{e}"
        );
        let e = parse("empty.csv", b"# only a comment\n\n").unwrap_err();
        assert_eq!(
            e.to_string(),
            "empty.csv:1: the file is empty; expected a header line `theta_deg,z1,z3` (optionally with `z2`)"
        );
        let e = parse("short.csv", b"theta_deg,z1,z3\n1,0,-0.1\n2,0\n").unwrap_err();
        assert_eq!(
            e.to_string(),
            "short.csv:3: this row has 2 fields but the header has 3 columns"
        );
        let e = read_measurements(Path::new("/nonexistent/swing.csv")).unwrap_err();
        assert!(matches!(e, CompensateError::Io { .. }), "{e}");
        assert!(e
            .to_string()
            .starts_with("/nonexistent/swing.csv: cannot read the file: "));
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(256))]

        /// No byte string makes the reader or the row checks panic.
        #[test]
        fn reader_never_panics(bytes in proptest::collection::vec(proptest::prelude::any::<u8>(), 0..200)) {
            let _ = parse("fuzz.csv", &bytes);
        }
    }
}
