//! The table and CSV of `chain reliability` ([`ReliabilityRun`]): per
//! target the reliability maps over the grid like the paper's Tables 2-4,
//! the summaries, the sampling and the calls; the whole-machine acceptance
//! probability (docs/acceptance.md); the posterior's listing. One CSV row
//! per (target, point), then the acceptance row.

use chain::ops::reliability::{
    CaseColumns, Done, ReliabilityOutput, ReliabilityRun, EXTREME_POINTS, TABLE_POINTS,
};
use chain::ops::views::target_map;
use reliability::acceptance::AcceptanceResult;
use reliability::{normal, CaseResult, CaseTally, Stopping, Study, StudyResult, SubsetLevel};

use crate::cli::report::{Csv, Report};
use crate::cli::study_text::{calls_text, fmt_num, posterior_lines, requirement_text, sided_title};

/// The grid axes in file order, as (name, index in the model's variables).
fn axes(study: &Study) -> Vec<(String, usize)> {
    study
        .spec()
        .grid
        .axes
        .iter()
        .filter_map(|(n, _)| {
            study
                .variables()
                .iter()
                .position(|v| v == n)
                .map(|i| (n.clone(), i))
        })
        .collect()
}

impl Report for ReliabilityRun {
    fn table(&self) -> String {
        self.output().table()
    }

    fn csv(&self, out: &mut Csv<'_>) -> Option<()> {
        self.output().csv(out)
    }
}

impl Report for ReliabilityOutput<'_> {
    fn table(&self) -> String {
        let study = self.study;
        let np = study.points().len();
        let mut table = if let (true, Some(r)) = (np <= TABLE_POINTS, self.kept()) {
            to_table(self.machine, study, r)
        } else if np <= TABLE_POINTS {
            // Every point's map: the cases of a small grid, collected.
            let mut cases = Vec::new();
            let _ = self.each_block(
                |b| {
                    cases.extend_from_slice(b);
                    Ok::<(), ()>(())
                },
                |_| (),
            );
            match self.done() {
                Some(d) => {
                    let mut r = d.result.clone();
                    r.cases = cases;
                    to_table(self.machine, study, &r)
                }
                None => String::new(),
            }
        } else {
            self.add_up();
            match self.done() {
                Some(d) => large_table(self, &d),
                None => String::new(),
            }
        };
        if let Some(a) = self.acceptance {
            table.push_str(&acceptance_table(study, a));
        }
        if let Some(t) = &self.temperatures {
            table = format!("{}{table}", temperature_lines(t));
        }
        match self.posterior {
            None => table,
            Some(p) => format!("{}{table}", posterior_lines(p)),
        }
    }

    fn csv(&self, out: &mut Csv<'_>) -> Option<()> {
        let ax = axes(self.study);
        let columns = self.columns;
        let mut header = vec!["component".to_string()];
        header.extend(ax.iter().map(|(n, _)| n.clone()));
        header.extend(["reliability", "pf", "beta"].map(String::from));
        if columns.sampled {
            header.extend(["std_error", "cov", "samples"].map(String::from));
        }
        header.extend(
            [
                "termination",
                "converged",
                "iterations",
                "exact",
                "value_calls",
                "gradient_calls",
            ]
            .map(String::from),
        );
        // The sampler's stopping rule, when it reports one (subset and
        // directional simulation, and any sampler run to a target CoV; not
        // FORM, SORM or a plain sample count).
        if columns.stopped {
            header.extend(["stopped_by", "sampler_converged"].map(String::from));
        }
        if columns.leveled {
            header.push("levels".to_string());
        }
        // SORM's three formulas (`--method sorm`), last.
        if columns.sorm {
            header.extend(
                [
                    "beta_breitung",
                    "beta_hohenbichler_rackwitz",
                    "beta_tvedt",
                    "sorm_converged",
                ]
                .map(String::from),
            );
        }
        let width = header.len();
        out.header(header);
        // The Csv writer keeps its own first write error; a failed run is
        // kept in the output for the command to report.
        let _ = self.each_block(
            |cases| {
                for c in cases {
                    out.row(csv_row(c, &ax, columns, self.acceptance.is_some()));
                }
                Ok::<(), ()>(())
            },
            |_| (),
        );
        if let Some(a) = self.acceptance {
            let mut row = acceptance_csv_row(a, ax.len());
            row.resize(width.max(row.len()), String::new());
            out.row(row);
        }
        Some(())
    }
}

/// One case's CSV row.
fn csv_row(
    c: &CaseResult,
    ax: &[(String, usize)],
    columns: CaseColumns,
    acceptance: bool,
) -> Vec<String> {
    let mut row = vec![c.target.to_string()];
    row.extend(ax.iter().map(|(_, i)| fmt_num(c.point[*i])));
    row.extend([c.reliability, c.pf, c.beta].map(csv_number));
    if columns.sampled && acceptance {
        row.push(c.std_error.map_or(String::new(), csv_number));
        row.push(c.cov.map_or(String::new(), csv_number));
        row.push(c.samples.map_or(String::new(), |v| v.to_string()));
    } else if columns.sampled {
        row.push(format!("{:?}", c.std_error.unwrap_or(0.0)));
        row.push(format!("{:?}", c.cov.unwrap_or(0.0)));
        row.push(c.samples.unwrap_or(0).to_string());
    }
    match &c.form {
        Some(f) => row.extend([
            f.termination.to_string(),
            f.converged.to_string(),
            f.iterations.to_string(),
            f.exact.to_string(),
        ]),
        None => row.extend((0..4).map(|_| String::new())),
    }
    row.push(c.calls.values.to_string());
    row.push(c.calls.gradients.to_string());
    if columns.stopped {
        match &c.stopping {
            Some(st) => row.extend([st.stopped_by.to_string(), st.converged.to_string()]),
            None => row.extend([String::new(), String::new()]),
        }
    }
    if columns.leveled {
        row.push(
            c.levels
                .as_ref()
                .map_or(String::new(), |l| l.len().to_string()),
        );
    }
    if columns.sorm {
        match &c.sorm {
            Some(so) => {
                row.extend(
                    [
                        so.beta_breitung,
                        so.beta_hohenbichler_rackwitz,
                        so.beta_tvedt,
                    ]
                    .map(csv_number),
                );
                row.push(so.converged.to_string());
            }
            None => row.extend((0..4).map(|_| String::new())),
        }
    }
    row
}

/// The table of a grid of more than [`TABLE_POINTS`] points: per target
/// its least reliable points and its most reliable one, the summary and
/// the calls (`--format csv` lists every point).
fn large_table(o: &ReliabilityOutput<'_>, d: &Done) -> String {
    use std::fmt::Write as _;
    let study = o.study;
    let r = &d.result;
    let ax = axes(study);
    let mut out = title_line(o.machine, study, r);
    let _ = writeln!(
        out,
        "grid of {} points: more than {TABLE_POINTS}, so per target its {EXTREME_POINTS} least reliable points and its most reliable one (--format csv or json lists every point)",
        study.points().len()
    );
    let at = |c: &CaseResult| -> String {
        (ax.iter())
            .map(|(n, i)| format!("{n} = {}", fmt_num(c.point[*i])))
            .collect::<Vec<_>>()
            .join(", ")
    };
    for (t, target) in study.targets().iter().enumerate() {
        let done = &d.targets[t];
        let _ = writeln!(out, "\n{target}: reliability (%)");
        for (k, c) in done.lowest.iter().enumerate() {
            let _ = writeln!(
                out,
                "  {:<9} {:>9.2}  at {}{}",
                if k == 0 { "lowest" } else { "" },
                100.0 * c.reliability,
                at(c),
                if c.converged() { "" } else { " *" }
            );
        }
        if let Some(c) = &done.highest {
            let _ = writeln!(
                out,
                "  {:<9} {:>9.2}  at {}{}",
                "highest",
                100.0 * c.reliability,
                at(c),
                if c.converged() { "" } else { " *" }
            );
        }
        out.push_str(&summary_line(r, t));
        if let Some((lo, hi)) = done.samples {
            let samples = samples_text(lo, hi);
            let _ = writeln!(
                out,
                "  sampling: {samples}, largest standard error {:.2e}",
                done.tally.max_std_error.unwrap_or(0.0)
            );
        }
        let _ = writeln!(out, "  {}", calls_text(&done.tally, r.method));
    }
    let unconverged = d.tally.form_unconverged() + d.tally.sampler_unconverged;
    if unconverged > 0 {
        let _ = writeln!(
            out,
            "\n* not converged there: the value shown is not a converged reliability ({unconverged} cases in all; --format csv marks each)"
        );
    }
    out
}

fn to_table(machine: &str, study: &Study, r: &StudyResult) -> String {
    use std::fmt::Write as _;
    let mut out = title_line(machine, study, r);
    let mut marked = false;
    for (t, target) in study.targets().iter().enumerate() {
        let map = target_map(study, r, t);
        let over = match (&map.rows, &map.cols) {
            (Some(a), Some(b)) => format!(" over ({}, {})", a.0, b.0),
            (Some(a), None) => format!(" over {}", a.0),
            _ => String::new(),
        };
        let _ = writeln!(out, "\n{target}: reliability (%){over}");
        for ((label, m), u) in map.maps.iter().zip(&map.unconverged) {
            if !label.is_empty() {
                let _ = writeln!(out, "  at {label}");
            }
            let corner = match (&map.rows, &map.cols) {
                (Some(a), Some(b)) => format!("{} \\ {}", a.0, b.0),
                (Some(a), None) => a.0.clone(),
                _ => String::new(),
            };
            let _ = write!(out, "  {corner:>10}");
            match &map.cols {
                Some((_, vals)) => vals.iter().for_each(|v| {
                    let _ = write!(out, " {:>9}", fmt_num(*v));
                }),
                None => {
                    let _ = write!(out, " {:>9}", "");
                }
            }
            out.push('\n');
            for (i, row) in m.iter().enumerate() {
                let head = map
                    .rows
                    .as_ref()
                    .map_or(String::new(), |(_, v)| fmt_num(v[i]));
                let _ = write!(out, "  {head:>10}");
                for v in row {
                    let _ = write!(out, " {:>9.2}", 100.0 * v);
                }
                out.push('\n');
            }
            // The cells FORM did not converge on, listed under the map (the
            // map's own lines stay those of a converged study).
            let mut bad = Vec::new();
            for (i, urow) in u.iter().enumerate() {
                for (j, unconverged) in urow.iter().enumerate() {
                    if *unconverged {
                        let coords: Vec<String> = [(&map.rows, i), (&map.cols, j)]
                            .iter()
                            .filter_map(|(axis, k)| {
                                axis.as_ref()
                                    .map(|(n, v)| format!("{n} = {}", fmt_num(v[*k])))
                            })
                            .collect();
                        bad.push(if coords.is_empty() {
                            "the point".to_string()
                        } else {
                            format!("({})", coords.join(", "))
                        });
                    }
                }
            }
            if !bad.is_empty() {
                marked = true;
                let _ = writeln!(out, "  * not converged at {}", bad.join(", "));
            }
        }
        out.push_str(&summary_line(r, t));
        let cases = r.target_cases(t);
        let se = cases
            .iter()
            .filter_map(|c| c.std_error)
            .fold(None, |m: Option<f64>, v| Some(m.map_or(v, |m| m.max(v))));
        let rule = cases.iter().filter_map(|c| c.stopping).next();
        match (se, cases.first().and_then(|c| c.samples), rule) {
            (Some(se), Some(n), None) => {
                let _ = writeln!(
                    out,
                    "  sampling: {n} samples per point, largest standard error {:.2e}",
                    se
                );
            }
            (Some(se), Some(_), Some(rule)) => {
                let _ = writeln!(out, "  {}", sampling_text(cases, rule, se));
            }
            _ => {}
        }
        let _ = writeln!(
            out,
            "  {}",
            calls_text(&CaseTally::of(cases.iter()), r.method)
        );
    }
    if marked {
        let sampler = r.cases.iter().any(|c| !c.sampler_converged());
        let form = r.cases.iter().any(|c| c.form.is_some_and(|f| !f.converged));
        if form {
            let _ = writeln!(
                out,
                "\n* FORM stopped at the iteration limit there: the value shown is the last iterate's, not a converged reliability"
            );
        }
        if sampler {
            let _ = writeln!(
                out,
                "\n* the {} stopped there without meeting its rule (sample budget or levels exhausted): the value shown is not a converged estimate",
                r.method.title()
            );
        }
    }
    out
}

/// The table line of a sampler that reports its stopping: the samples used
/// (a range when the rule stopped the points apart), the target and how
/// many points met it, the largest standard error; for subset simulation
/// the levels and the chains' mean acceptance rate.
fn sampling_text(cases: &[reliability::CaseResult], rule: Stopping, se: f64) -> String {
    let ns: Vec<u64> = cases.iter().filter_map(|c| c.samples).collect();
    let (lo, hi) = (
        ns.iter().copied().min().unwrap_or(0),
        ns.iter().copied().max().unwrap_or(0),
    );
    let samples = samples_text(lo, hi);
    let met = cases.iter().filter(|c| c.sampler_converged()).count();
    let target = match rule.target_cov {
        Some(t) => format!(", target CoV {t} met at {met} of {} points", cases.len()),
        None if met < cases.len() => format!(", converged at {met} of {} points", cases.len()),
        None => String::new(),
    };
    let mut text = format!("sampling: {samples}{target}, largest standard error {se:.2e}");
    let levels: Vec<&Vec<SubsetLevel>> = cases.iter().filter_map(|c| c.levels.as_ref()).collect();
    if !levels.is_empty() {
        let counts = levels.iter().map(|l| l.len());
        let (lmin, lmax) = (counts.clone().min().unwrap_or(0), counts.max().unwrap_or(0));
        let rates: Vec<f64> = levels
            .iter()
            .flat_map(|l| l.iter().filter_map(|x| x.acceptance_rate))
            .collect();
        let levels = if lmin == lmax {
            format!("{lmin} levels")
        } else {
            format!("{lmin} to {lmax} levels")
        };
        text.push_str(&format!("; subset: {levels}"));
        if !rates.is_empty() {
            let mean = rates.iter().sum::<f64>() / rates.len() as f64;
            text.push_str(&format!(", mean acceptance {mean:.2}"));
        }
    }
    text
}

/// A CSV cell of a number: shortest round-trip form when finite, an empty
/// cell otherwise, as the JSON writes `null` (a sampled `pf` of exactly 1
/// has `beta = −∞`; `docs/robustness.md`).
fn csv_number(v: f64) -> String {
    if v.is_finite() {
        format!("{v:?}")
    } else {
        String::new()
    }
}

/// The table section: the probability with its error and method, and the
/// sensitivities sorted by `|∂P/∂σ|·σ` (the change for a 100 % larger σ).
fn acceptance_table(study: &Study, a: &AcceptanceResult) -> String {
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
fn acceptance_csv_row(a: &AcceptanceResult, axes: usize) -> Vec<String> {
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

/// The thermal state of a study, in words: the fixed temperatures, the
/// random ones and the rule that integrated over them.
fn temperature_lines(t: &chain::ops::reliability::TemperaturesDocument) -> String {
    let mut out = String::new();
    if !t.fixed.0.is_empty() {
        let state: Vec<String> = (t.fixed.0.iter())
            .map(|(n, v)| format!("{n} = {v} °C"))
            .collect();
        out.push_str(&format!("thermal state: {}\n", state.join(", ")));
    }
    if !t.random.is_empty() {
        let random: Vec<String> = (t.random.iter())
            .map(|r| format!("{} {}", r.sensor, distribution_text(&r.distribution)))
            .collect();
        out.push_str(&format!("random temperature: {}\n", random.join(", ")));
        if let Some(q) = &t.quadrature {
            out.push_str(&format!(
                "  pf integrated over it by adaptive Gauss–Kronrod quadrature (docs/thermal.md): {} studies, estimated error ≤ {:.1e} relative\n",
                q.studies, q.max_relative
            ));
        }
    }
    out
}

/// A distribution as the machine file writes it: `uniform(16, 26)`.
fn distribution_text(d: &chain_core::model::Distribution) -> String {
    serde_json::to_value(d)
        .ok()
        .and_then(|v| {
            let o = v.as_object()?;
            let name = o.get("dist")?.as_str()?.to_string();
            let args: Vec<String> = (o.iter())
                .filter(|(k, _)| *k != "dist")
                .map(|(k, v)| format!("{k} {v}"))
                .collect();
            Some(format!("{name}({})", args.join(", ")))
        })
        .unwrap_or_default()
}

/// Target `t`'s summary line (mean, min, max; the requirement), or nothing
/// without a summary.
fn summary_line(r: &StudyResult, t: usize) -> String {
    let Some(s) = r.summaries.get(t) else {
        return String::new();
    };
    let mut out = format!(
        "  summary: mean {:.2} %, min {:.2} %, max {:.2} %",
        100.0 * s.mean,
        100.0 * s.min,
        100.0 * s.max
    );
    if let (Some(req), Some(met)) = (r.requirement, s.met) {
        out.push_str(&requirement_text(&req, met));
    }
    out.push('\n');
    out
}

/// `N samples per point`, or `LO to HI samples per point`.
fn samples_text(lo: u64, hi: u64) -> String {
    if lo == hi {
        format!("{lo} samples per point")
    } else {
        format!("{lo} to {hi} samples per point")
    }
}

/// The table's first line: the machine, the method, the sides.
fn title_line(machine: &str, study: &Study, r: &StudyResult) -> String {
    format!(
        "{machine}: machining-accuracy reliability ({}, {})\n",
        r.method.title(),
        sided_title(study.spec().sided)
    )
}
