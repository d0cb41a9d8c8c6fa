//! `chain positioning RUNS.csv [--k 2] [--rotary] [--format table|json|csv]
//! [--plot DIR]`: the ISO 230-2 evaluation of an axis's bidirectional
//! positioning runs (`../shared/spec/positioning.md`, `docs/positioning.md`),
//! through [`chain_core::measured::positioning`].

use std::path::PathBuf;

use chain::ops::positioning as ops;
use chain_core::measured::positioning::{self, Coverage, PositioningDocument, Runs};

use super::report::{self, Csv, Report};

#[path = "positioning_plot.rs"]
mod positioning_plot;

/// Output formats of `chain positioning`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum PositioningFormat {
    /// The per-target statistics and the axis values.
    Table,
    /// The document of the positioning spec.
    Json,
    /// One row per target.
    Csv,
}

report::formats!(PositioningFormat: Table, Json, Csv);

/// Arguments of `chain positioning`.
#[derive(Debug, clap::Args)]
pub struct PositioningArgs {
    /// The run file (CSV): `target`, `direction` (`up`/`down`, `+`/`-`),
    /// `run` (1..n), and `measured` (the reached position) or `deviation`
    /// (reached minus target); mm, or degrees with `--rotary`.
    pub runs: PathBuf,
    /// The coverage factor k: 2 (ISO 230-2:1997-2014) or 3 (the 1988
    /// edition, VDI/DGQ 3441); any number > 0.
    #[arg(long, default_value = "2", value_parser = coverage)]
    pub k: Coverage,
    /// A rotary axis: targets and deviations in degrees, statistics in
    /// arcseconds.
    #[arg(long)]
    pub rotary: bool,
    /// Output format.
    #[arg(long, value_enum, default_value = "table")]
    pub format: PositioningFormat,
    /// Write the standard's chart (mean deviation per direction with the
    /// ±k·s band, each run's points, the reversal) into DIR as PNG and SVG.
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
    /// Write the run into a values file: the mean deviation per approach
    /// direction and its standard deviation per target, in the error motion
    /// `--slot` of the machine `--machine` (docs/positioning.md).
    #[arg(long, value_name = "VALUES.yaml", requires_all = ["machine", "slot"])]
    pub values_out: Option<PathBuf>,
    /// The machine file the values are for (with `--values-out`).
    #[arg(long, value_name = "FILE", requires = "values_out")]
    pub machine: Option<PathBuf>,
    /// The machine's name for the axis's positioning error, e.g. `EXX`
    /// (with `--values-out`).
    #[arg(long, value_name = "NAME", requires = "values_out")]
    pub slot: Option<String>,
}

/// `--k`: a number the library takes as a coverage factor.
fn coverage(text: &str) -> Result<Coverage, String> {
    let k: f64 = text
        .parse()
        .map_err(|_| format!("`{text}` is not a number"))?;
    Coverage::new(k).map_err(|e| e.to_string())
}

/// Runs `chain positioning` ([`chain::ops::positioning`]).
pub fn exec(args: PositioningArgs) -> miette::Result<()> {
    let runs = Runs::read(&args.runs, ops::axis_kind(args.rotary))?;
    let machine = match &args.machine {
        Some(file) => Some(chain_core::load_file(file)?),
        None => None,
    };
    let machine_file = args.machine.as_ref().map(|f| f.display().to_string());
    let runs_file = args.runs.display().to_string();
    let values_out = match (&machine, &machine_file, &args.slot) {
        (Some(machine), Some(machine_file), Some(slot)) => Some(ops::ValuesOut {
            machine,
            machine_file,
            slot,
            runs_file: &runs_file,
        }),
        _ => None,
    };
    let done = ops::run(&ops::PositioningRequest {
        runs: &runs,
        k: args.k,
        values_out,
    })?;
    let doc = done.document;
    if let (Some(out), Some(text)) = (&args.values_out, &done.values_text) {
        super::atomic::write(out, text.as_bytes())
            .map_err(|e| miette::miette!("cannot write {}: {e}", out.display()))?;
        let slot = args.slot.as_deref().unwrap_or_default();
        eprintln!("wrote {} ({slot})", out.display());
    }
    if let Some(dir) = &args.plot {
        for f in positioning_plot::write(dir, &doc)? {
            eprintln!("wrote {}", f.display());
        }
    }
    report::emit(&doc, args.format.into())
}

/// A statistic in the table: 6 decimals in mm (0.001 µm), 3 in arcseconds.
fn cell(doc: &PositioningDocument, v: f64) -> String {
    match doc.unit {
        positioning::Unit::Mm => format!("{v:.6}"),
        positioning::Unit::Arcsec => format!("{v:.3}"),
    }
}

impl Report for PositioningDocument {
    fn table(&self) -> String {
        use std::fmt::Write;
        let u = self.unit.name();
        let mut out = String::new();
        let _ = writeln!(
            out,
            "ISO 230-2 positioning of {} ({} axis, {} targets, {} runs per direction, k = {}; deviations in {u})",
            if self.file.is_empty() { "the runs" } else { &self.file },
            self.axis_kind,
            self.targets.len(),
            self.runs,
            self.k,
        );
        let _ = writeln!(out);
        let header = [
            format!("target ({})", self.target_unit),
            "mean ↑".into(),
            "mean ↓".into(),
            "mean".into(),
            "reversal B".into(),
            "s ↑".into(),
            "s ↓".into(),
            "R ↑".into(),
            "R ↓".into(),
            "R".into(),
        ];
        let rows: Vec<[String; 10]> = self
            .targets
            .iter()
            .map(|t| {
                [
                    format!("{}", t.target),
                    cell(self, t.mean_up),
                    cell(self, t.mean_down),
                    cell(self, t.mean),
                    cell(self, t.reversal),
                    cell(self, t.s_up),
                    cell(self, t.s_down),
                    cell(self, t.repeatability_up),
                    cell(self, t.repeatability_down),
                    cell(self, t.repeatability),
                ]
            })
            .collect();
        let widths: Vec<usize> = (0..header.len())
            .map(|c| {
                rows.iter()
                    .map(|r| r[c].chars().count())
                    .chain([header[c].chars().count()])
                    .max()
                    .unwrap_or(0)
            })
            .collect();
        let line = |cells: &[String]| -> String {
            let parts: Vec<String> = cells
                .iter()
                .zip(&widths)
                .map(|(c, w)| format!("{c:>w$}", w = *w))
                .collect();
            parts.join("  ").trim_end().to_string()
        };
        let _ = writeln!(out, "{}", line(&header));
        for r in &rows {
            let _ = writeln!(out, "{}", line(r));
        }
        let a = &self.axis;
        let _ = writeln!(out);
        let _ = writeln!(out, "axis ({u}):");
        let pairs = [
            ("A  accuracy", a.A, a.A_up, a.A_down),
            ("E  systematic deviation", a.E, a.E_up, a.E_down),
            ("R  repeatability", a.R, a.R_up, a.R_down),
        ];
        for (name, both, up, down) in pairs {
            let _ = writeln!(
                out,
                "  {name:<26} {:>12}   ↑ {:>12}   ↓ {:>12}",
                cell(self, both),
                cell(self, up),
                cell(self, down)
            );
        }
        let _ = writeln!(
            out,
            "  {:<26} {:>12}",
            "M  mean deviation range",
            cell(self, a.M)
        );
        let _ = writeln!(
            out,
            "  {:<26} {:>12}   mean B̄ {:>12}",
            "B  reversal",
            cell(self, a.B),
            cell(self, a.B_mean)
        );
        out
    }

    fn csv(&self) -> Option<Csv> {
        let mut c = Csv::new([
            "target",
            "mean_up",
            "mean_down",
            "mean",
            "reversal",
            "s_up",
            "s_down",
            "repeatability_up",
            "repeatability_down",
            "repeatability",
        ]);
        for t in &self.targets {
            c.row(
                [
                    t.target,
                    t.mean_up,
                    t.mean_down,
                    t.mean,
                    t.reversal,
                    t.s_up,
                    t.s_down,
                    t.repeatability_up,
                    t.repeatability_down,
                    t.repeatability,
                ]
                .map(|v| format!("{v:?}")),
            );
        }
        Some(c)
    }
}
