//! The whole-machine acceptance probability in `chain reliability`
//! (`--acceptance` or `reliability.acceptance: true`, spec reliability-v2
//! §4): running it over a study (the run and its JSON object are the
//! library's, `reliability::document`), its table section and CSV row
//! (docs/acceptance.md).

use miette::MietteDiagnostic;
use reliability::acceptance::AcceptanceResult;
use reliability::{normal, Study};

use super::loaded::Loaded;

/// The acceptance probability of every point × toleranced component of
/// `study`, to an absolute error `tolerance` (three standard errors).
pub(crate) fn run(
    loaded: &Loaded,
    study: &Study,
    tolerance: f64,
    seed: u64,
) -> miette::Result<AcceptanceResult> {
    if !(tolerance.is_finite() && tolerance > 0.0 && tolerance < 1.0) {
        return Err(miette::Report::new(
            MietteDiagnostic::new(format!(
                "invalid value for `--acceptance-tolerance`: {tolerance} (an absolute error in (0, 1))"
            ))
            .with_code("chain::reliability::invalid_option"),
        ));
    }
    let r =
        reliability::document::acceptance(study, tolerance, seed).map_err(|e| loaded.report(e))?;
    if !r.converged {
        eprintln!(
            "warning: the acceptance probability did not converge: 3 standard errors = {:.2e} > {tolerance:.2e} after {} samples",
            3.0 * r.std_error,
            r.samples
        );
    }
    Ok(r)
}

/// The table section: the probability with its error and method, and the
/// sensitivities sorted by `|∂P/∂σ|·σ` (the change for a 100 % larger σ).
pub(crate) fn table(study: &Study, a: &AcceptanceResult) -> String {
    use std::fmt::Write as _;
    let mut out = String::new();
    let np = study.points().len();
    let comps: Vec<&str> = study
        .spec()
        .tolerances
        .iter()
        .map(|(c, _)| c.name())
        .collect();
    let _ = writeln!(
        out,
        "\nwhole-machine acceptance: {} at all {np} points at once ({} constraints, {} distinct, rank {})",
        comps.join(", "),
        a.constraints,
        a.distinct,
        a.rank
    );
    let status = if a.converged {
        String::new()
    } else {
        format!(
            "  NOT CONVERGED: 3 standard errors = {:.2e} exceed the tolerance {:.2e}",
            3.0 * a.std_error,
            a.tolerance.unwrap_or(0.0)
        )
    };
    let _ = writeln!(
        out,
        "  P(accept) = {:.4} % ± {:.4} % (1 standard error; {}, {} samples){status}",
        a.probability * 100.0,
        a.std_error * 100.0,
        a.method.title(),
        a.samples
    );
    let stds = study.inputs().stds();
    let mut order: Vec<usize> = (0..a.sensitivity.len()).collect();
    order.sort_by(|&i, &j| {
        (a.sensitivity[j].dr_dstd * stds[j])
            .abs()
            .total_cmp(&(a.sensitivity[i].dr_dstd * stds[i]).abs())
    });
    if !order.is_empty() {
        let _ = writeln!(
            out,
            "  {:<8} {:>13} {:>11} {:>13} {:>11} {:>10}",
            "error", "dP/dstd", "± se", "dP/dmean", "± se", "σ·dP/dstd"
        );
        for j in order {
            let s = &a.sensitivity[j];
            if s.dr_dstd == 0.0 && s.dr_dmean == 0.0 {
                continue;
            }
            let _ = writeln!(
                out,
                "  {:<8} {:>13.5e} {:>11.2e} {:>13.5e} {:>11.2e} {:>10.5}",
                s.error,
                s.dr_dstd,
                s.dr_dstd_std_error,
                s.dr_dmean,
                s.dr_dmean_std_error,
                s.dr_dstd * stds[j]
            );
        }
        let _ = writeln!(
            out,
            "  (errors no toleranced component depends on are not listed)"
        );
    }
    out
}

/// The CSV row `acceptance` in the columns of the case rows (no grid
/// coordinates; `std_error`, `cov` and `samples` of the estimate;
/// `converged`; the samples as value calls).
pub(crate) fn csv_row(a: &AcceptanceResult, axes: usize) -> Vec<String> {
    let pf = 1.0 - a.probability;
    let mut row = vec!["acceptance".to_string()];
    row.extend((0..axes).map(|_| String::new()));
    row.push(format!("{:?}", a.probability));
    row.push(format!("{pf:?}"));
    row.push(format!("{:?}", normal::beta_from_pf(pf)));
    row.push(format!("{:?}", a.std_error));
    row.push(format!(
        "{:?}",
        if pf > 0.0 { a.std_error / pf } else { 0.0 }
    ));
    row.push(a.samples.to_string());
    row.push(String::new());
    row.push(a.converged.to_string());
    row.push(String::new());
    row.push(String::new());
    row.push(a.samples.to_string());
    row.push("0".to_string());
    row
}
