//! The table of `chain compensate` ([`CompensateRun`]): the points with
//! their Δθ, the polynomial fits, the selected law and the residual it
//! leaves, and the files written.

use std::fmt::Write as _;

use chain::ops::compensate::CompensateRun;

use crate::cli::report::Report;

impl Report for CompensateRun {
    /// The `--format table` report.
    fn table(&self) -> String {
        let (a, files) = (&self.analysis, &self.written);
        let table_rows = self.table.as_ref().map(Vec::len);
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
