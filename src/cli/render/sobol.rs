//! The table and CSV of `chain sobol` ([`SobolRun`]): one table per output
//! sorted by the total index; one CSV row per output and error.

use chain::ops::sobol::{SobolDocument, SobolRun};
use reliability::sobol::Estimate;

use crate::cli::report::{Csv, Report};

fn cell(v: f64) -> String {
    format!("{v:.6}")
}

fn exact_cell(e: &Estimate) -> String {
    e.exact.map_or_else(|| "-".to_string(), cell)
}

impl Report for SobolRun {
    fn table(&self) -> String {
        let doc = self.document();
        table(&doc)
    }

    fn csv(&self, out: &mut Csv<'_>) -> Option<()> {
        csv(&self.document(), out)
    }
}

fn table(d: &SobolDocument<'_>) -> String {
    use std::fmt::Write as _;
    let mut out = String::new();
    let where_ = match &d.at {
        Some(a) => format!(
            "at {}",
            a.0.iter()
                .map(|(n, v)| format!("{n} = {v}"))
                .collect::<Vec<_>>()
                .join(", ")
        ),
        None => format!(
            "pooled over the {} grid points (sum of variances)",
            d.points
        ),
    };
    let _ = writeln!(
        out,
        "{}: Sobol indices (Saltelli 2010 first order, Jansen total), {where_}",
        d.machine
    );
    let _ = writeln!(
            out,
            "N = {} base samples ({} evaluations per point), seed {}, {} % bootstrap percentile intervals ({} replicates over {} blocks)",
            d.samples,
            d.evaluations_per_point,
            d.seed,
            d.confidence * 100.0,
            d.bootstrap,
            d.blocks
        );
    for o in &d.result.outputs {
        let name = match o.output {
            reliability::Target::Volumetric => "|p| (volumetric)".to_string(),
            t => t.name().to_string(),
        };
        let _ = writeln!(
            out,
            "\n{name}: variance {:.6e}, sum S = {} [{}, {}], sum T = {} [{}, {}]; sorted by T:",
            o.variance,
            cell(o.sum_first.value),
            cell(o.sum_first.low),
            cell(o.sum_first.high),
            cell(o.sum_total.value),
            cell(o.sum_total.low),
            cell(o.sum_total.high),
        );
        let _ = writeln!(
            out,
            "  {:<8} {:>9} {:>21} {:>9} {:>21} {:>9}",
            "error", "S", "interval", "T", "interval", "exact"
        );
        let mut order: Vec<usize> = (0..o.errors.len()).collect();
        order.sort_by(|&a, &b| o.errors[b].total.value.total_cmp(&o.errors[a].total.value));
        for i in order {
            let e = &o.errors[i];
            let _ = writeln!(
                out,
                "  {:<8} {:>9} {:>21} {:>9} {:>21} {:>9}",
                e.error,
                cell(e.first.value),
                format!("[{}, {}]", cell(e.first.low), cell(e.first.high)),
                cell(e.total.value),
                format!("[{}, {}]", cell(e.total.low), cell(e.total.high)),
                exact_cell(&e.first),
            );
        }
    }
    out
}

fn csv(d: &SobolDocument<'_>, out: &mut Csv<'_>) -> Option<()> {
    out.header([
        "output",
        "error",
        "first",
        "first_low",
        "first_high",
        "total",
        "total_low",
        "total_high",
        "exact",
    ]);
    let num = |v: f64| format!("{v:?}");
    for o in &d.result.outputs {
        for e in &o.errors {
            out.row([
                o.output.name().to_string(),
                e.error.clone(),
                num(e.first.value),
                num(e.first.low),
                num(e.first.high),
                num(e.total.value),
                num(e.total.low),
                num(e.total.high),
                e.first.exact.map(num).unwrap_or_default(),
            ]);
        }
    }
    Some(())
}
