//! `chain map FILE --values VALUES.yaml [--grid VAR=V1,V2,...|VAR=LO:HI:N]...
//! [--axes AXES.csv] [--param NAME=VALUE]... [--format table|json|csv]
//! [--plot DIR] [--compensated CONTROLLER [--compensation-grid VAR=...]...]`.
//!
//! The volumetric error of a built machine (measured-machines spec, section
//! 3): `E(q) = Σ_j c_j(q)·v_j(q)` at every point of the machine file's
//! `reliability.grid` (full factorial, each axis replaceable by `--grid`) or
//! at every row of `--axes`, with the error values `v_j` of a values file
//! (section 2), through [`chain_core::BuiltMachine::map`]. See `docs/map.md`.
//!
//! `--compensated CONTROLLER` adds the map after compensation (issue 14,
//! point 4; `docs/export.md`): the controller's correction
//! ([`chain_core::compensation::Correction`]) added to every commanded point,
//! the residual through [`chain_core::BuiltMachine::compensated_map`], shown
//! next to the uncompensated map (table, JSON `compensated`, CSV columns
//! `*_after`, plots in `DIR/compensated/`).

#[path = "map_plot.rs"]
mod map_plot;

use std::io::IsTerminal;
use std::path::PathBuf;

use chain::ops::map::{MapOpsError, MapPoints, MapRequest, PreparedMap};
use chain_core::built::{BuiltMachine, MapError, MapSummary, Points};
use chain_core::compensation::controllers::{Controller, ExportOptions, DEFAULT_STEP};
use chain_core::model::{Component, Frame};
use chain_core::values::{parse_approaches, Approach, Entry, EntryKind, Given, Reversal, Values};
use chain_core::MapResult;
use miette::MietteDiagnostic;
use serde::Serialize;

use super::args::ParamArgs;
use super::args::{parse_grid_axis, ControllerName};
use super::csv_input::axes_points;
use super::loaded::Loaded;
use super::report::{self, Csv, Report};

/// Maps with at most this many points also list every point in the table
/// format.
const TABLE_POINTS: usize = 60;

/// Maps with at least this many points show a progress bar (on a terminal).
const PROGRESS_POINTS: usize = 200_000;

/// Output formats of `chain map`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum MapFormat {
    /// The ISO 230-1-style summary (and the points of small maps).
    Table,
    /// The spec's JSON document.
    Json,
    /// One row per point.
    Csv,
}

report::formats!(MapFormat: Table, Json, Csv);

/// Arguments of `chain map`.
#[derive(Debug, clap::Args)]
pub struct MapArgs {
    /// Machine file (YAML).
    pub file: PathBuf,
    /// The error values of the built machine: a values file (YAML; its
    /// tables are relative to it).
    #[arg(long, value_name = "VALUES.yaml")]
    pub values: PathBuf,
    /// Replace (or add) the grid values of one axis: `VAR=V1,V2,...`, or
    /// `VAR=LO:HI:N` for N evenly spaced values from LO to HI (repeatable).
    #[arg(long = "grid", value_name = "VAR=V1,V2,...|VAR=LO:HI:N", value_parser = parse_grid_axis)]
    pub grid: Vec<(String, Vec<f64>)>,
    /// Which approach direction of the bidirectional tables to map:
    /// `up`, `down` or `mean` (the default) for every axis, or per axis
    /// `x=up,y=down` (repeatable; docs/values.md, "Direction").
    #[arg(long, value_name = "DIR|VAR=DIR,...", value_parser = parse_approaches)]
    pub approach: Vec<Vec<(Option<String>, Approach)>>,
    /// Points from a CSV instead of the grid: a header naming every axis
    /// variable (any order; rotary ones in radians), an optional leading
    /// column `t`; `-` reads stdin.
    #[arg(long, value_name = "AXES.csv", conflicts_with = "grid")]
    pub axes: Option<PathBuf>,
    #[command(flatten)]
    pub param: ParamArgs,
    /// Output format.
    #[arg(long, value_enum, default_value = "table")]
    pub format: MapFormat,
    /// Write heat maps of every component and a magnified distorted-grid
    /// picture (PNG and SVG) into DIR.
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
    /// Also map the error left after this controller's compensation
    /// (exported from the same values; see docs/export.md).
    #[arg(long, value_enum, value_name = "CONTROLLER")]
    pub compensated: Option<ControllerName>,
    /// The grid the `grid` correction is exported on, per axis (default:
    /// the map's grid, or the machine file's with --axes; repeatable). For
    /// the per-axis table formats: the travel of the axis's table (its
    /// smallest and largest value; default: the map's grid range, else the
    /// machine file's).
    #[arg(long = "compensation-grid", value_name = "VAR=V1,V2,...|VAR=LO:HI:N", value_parser = parse_grid_axis, requires = "compensated")]
    pub compensation_grid: Vec<(String, Vec<f64>)>,
    /// The largest table step (mm) of a per-axis table format's
    /// compensation (as `chain export --step`) [default: 10].
    #[arg(
        long = "compensation-step",
        value_name = "MM",
        requires = "compensated"
    )]
    pub compensation_step: Option<f64>,
}

/// Runs `chain map`.
pub fn exec(args: MapArgs) -> miette::Result<()> {
    let loaded = Loaded::new(&args.file)?;
    let m = &loaded.machine;
    let values = Values::read(&args.values, m)?;
    let choices: Vec<_> = args.approach.iter().flatten().cloned().collect();
    let (points, input_name) = match &args.axes {
        Some(path) => (
            MapPoints::Rows(axes_points(path, m)?),
            path.display().to_string(),
        ),
        None => (MapPoints::Grid(&args.grid), String::new()),
    };
    let request = MapRequest {
        params: &args.param.params,
        approach: &choices,
        points,
    };
    let file = args.file.display().to_string();
    let values_file = args.values.display().to_string();
    let prepared = chain::ops::map::prepare(m, &file, values, &values_file, &input_name, &request)
        .map_err(|e| match e {
            MapOpsError::Reliability(e) => loaded.report(e),
            MapOpsError::Resolve(e) => miette::Report::new(e),
            other => miette::miette!("{other}"),
        })?;
    let PreparedMap {
        built,
        points,
        grid,
    } = prepared;
    let input = match grid {
        Some(axes) => Input::Grid(axes),
        None => Input::Axes(input_name),
    };
    let compensated = match args.compensated {
        Some(controller) => Some(compensate(
            &args,
            controller,
            &loaded,
            &built,
            points.clone(),
        )?),
        None => None,
    };
    let count = points.len();
    let bar = Progress::new(count, args.format);
    // The table of a large map shows the summary only: it needs no point's
    // error kept (the plots and the other formats do).
    let keep = args.format != MapFormat::Table || args.plot.is_some() || count <= TABLE_POINTS;
    let result = if keep {
        built
            .map_with_progress(points, &|n| bar.inc(n))
            .map(Mapped::Full)
    } else {
        built
            .summary(&points, &|n| bar.inc(n))
            .map(|summary| Mapped::Summary { summary, points })
    };
    bar.finish();
    let result = result.map_err(|e| map_error(e, &args.values))?;
    // Error parameters the file gave a value: a function's table gives all
    // its coefficients.
    let given: usize = (built.values().entries().iter())
        .map(|e| match e.kind {
            EntryKind::Function => m
                .function_index(&e.name)
                .map_or(1, |f| m.functions[f].coefficients.len()),
            _ => 1,
        })
        .sum();
    let doc = MapDoc {
        values_file: args.values.display().to_string(),
        entries: built.values().entries().to_vec(),
        errors: m.errors.len(),
        unset: m.errors.len().saturating_sub(given),
        machine: m.name.clone(),
        frame: m.frame,
        variables: built.variables().to_vec(),
        input,
        result,
        compensated,
        reversals: built.values().reversals(),
    };
    if let Some(dir) = &args.plot {
        for f in map_plot::write_all(dir, &doc, &built)? {
            eprintln!("wrote {}", f.display());
        }
        if let Some(c) = &doc.compensated {
            let mut r = c.result.clone();
            r.machine = format!("{} compensated ({})", doc.machine, c.controller);
            let after = MapDoc {
                values_file: doc.values_file.clone(),
                entries: Vec::new(),
                errors: doc.errors,
                unset: doc.unset,
                machine: r.machine.clone(),
                frame: doc.frame,
                variables: doc.variables.clone(),
                input: doc.input.clone(),
                result: Mapped::Full(r),
                compensated: None,
                reversals: doc.reversals.clone(),
            };
            for f in map_plot::write_all(&dir.join("compensated"), &after, &built)? {
                eprintln!("wrote {}", f.display());
            }
        }
    }
    report::emit(&doc, args.format.into())
}

/// The map after `controller`'s compensation, at the map's points.
fn compensate(
    args: &MapArgs,
    controller: ControllerName,
    loaded: &Loaded,
    built: &BuiltMachine,
    points: Points,
) -> miette::Result<Compensated> {
    let m = &loaded.machine;
    if let Some(tables) = controller.tables() {
        // The map's own range of an axis, where it is one (a single value
        // keeps the machine file's travel); --compensation-grid over it.
        let mut travel = chain::ops::export::travel_of(&args.grid);
        travel.retain(|(_, [lo, hi])| lo < hi);
        for t in chain::ops::export::travel_of(&args.compensation_grid) {
            travel.retain(|(n, _)| *n != t.0);
            travel.push(t);
        }
        let options = ExportOptions {
            step: args.compensation_step.unwrap_or(DEFAULT_STEP),
            travel,
            ..ExportOptions::default()
        };
        let export = chain::ops::export::table_export(
            tables,
            built,
            &loaded.machine,
            &options,
            &args.compensation_grid,
            &args.values.display().to_string(),
        )?;
        let result = built
            .compensated_map(export.correction.as_ref(), points)
            .map_err(|e| export_error(e, &args.values))?;
        let (nodes, source) = match tables {
            Controller::Klipper => (0, "shear factors, docs/export-controllers.md".to_string()),
            _ => {
                let points: Vec<String> = (export.report.axes.iter())
                    .map(|a| format!("{} {}", a.variable, a.points))
                    .collect();
                (
                    export.report.axes.iter().map(|a| a.points).sum(),
                    format!(
                        "table points {}, docs/export-controllers.md",
                        points.join(", ")
                    ),
                )
            }
        };
        return Ok(Compensated {
            controller: controller.name(),
            nodes,
            source,
            result,
        });
    }
    if args.compensation_step.is_some() {
        let d = MietteDiagnostic::new("--compensated grid does not take --compensation-step")
            .with_code("chain::map::option")
            .with_help(
                "the grid correction is exported at the nodes of --compensation-grid VAR=LO:HI:N",
            );
        return Err(miette::Report::new(d));
    }
    // The correction grid: the map's (or the file's), each axis replaceable.
    let mut overrides = args.grid.clone();
    overrides.extend(args.compensation_grid.iter().cloned());
    let file = args.file.display().to_string();
    let axes = chain::ops::resolve::grid_axes(m, &file, &overrides)?;
    let nodes: usize = axes.iter().map(|(_, v)| v.len()).product();
    let source = format!("{nodes} correction nodes, docs/export.md");
    let kin = chain_core::kinematics::Kinematics::from_machine(m);
    let grid = chain_core::compensation::grid::export(
        built,
        &kin,
        Points::Grid(axes.iter().map(|(_, v)| v.clone()).collect()),
    )
    .map_err(|e| export_error(e, &args.values))?;
    let correction = grid.correction().map_err(miette::Report::new)?;
    let result = built
        .compensated_map(&correction, points)
        .map_err(|e| export_error(e, &args.values))?;
    Ok(Compensated {
        controller: controller.name(),
        nodes,
        source,
        result,
    })
}

/// A map error, rendered with its code and help.
fn map_error(e: MapError, values: &std::path::Path) -> miette::Report {
    let (code, help) = match &e {
        MapError::OutOfRange { source, .. } => (
            "chain::map::out_of_range",
            format!(
                "the table of `{}` in {} covers {} = {} to {}; map inside it (--grid), extend the table, or add `extrapolate: hold` to its entry to hold the end values",
                source.name,
                values.display(),
                source.variable,
                source.lo,
                source.hi
            ),
        ),
        MapError::NoPoints => (
            "chain::map::no_points",
            "give the points with --grid VAR=... or --axes AXES.csv".to_string(),
        ),
        _ => ("chain::map::points", String::new()),
    };
    let text = match &e {
        MapError::OutOfRange { point, at, source } => format!(
            "at point {} ({at}): {} = {} is outside the table of `{}` ({})",
            point + 1,
            source.variable,
            source.value,
            source.name,
            source.table
        ),
        other => other.to_string(),
    };
    let mut d = MietteDiagnostic::new(text).with_code(code);
    if !help.is_empty() {
        d = d.with_help(help);
    }
    miette::Report::new(d)
}

/// A progress bar on stderr for large maps, only when stderr is a terminal
/// and the output is not JSON.
struct Progress(Option<indicatif::ProgressBar>);

impl Progress {
    fn new(points: usize, format: MapFormat) -> Progress {
        if points < PROGRESS_POINTS || format == MapFormat::Json || !std::io::stderr().is_terminal()
        {
            return Progress(None);
        }
        let bar = indicatif::ProgressBar::with_draw_target(
            Some(points as u64),
            indicatif::ProgressDrawTarget::stderr(),
        );
        if let Ok(style) = indicatif::ProgressStyle::with_template(
            "{spinner} mapping [{bar:40}] {percent:>3}% {human_pos}/{human_len} points, eta {eta}",
        ) {
            bar.set_style(style.progress_chars("=> "));
        }
        Progress(Some(bar))
    }

    fn inc(&self, n: usize) {
        if let Some(b) = &self.0 {
            b.inc(n as u64);
        }
    }

    fn finish(&self) {
        if let Some(b) = &self.0 {
            b.finish_and_clear();
        }
    }
}

// ---------------------------------------------------------------------------
// Output.

/// Where the points came from.
#[derive(Clone)]
pub(crate) enum Input {
    /// The full-factorial grid of these axes (machine variable order).
    Grid(Vec<(String, Vec<f64>)>),
    /// The rows of this CSV file.
    Axes(String),
}

/// What the map computed: every point's error, or the summary alone.
pub(crate) enum Mapped {
    /// The library's whole result.
    Full(MapResult),
    /// The summary, and the points it is of.
    Summary { summary: MapSummary, points: Points },
}

impl Mapped {
    fn summary(&self) -> &MapSummary {
        match self {
            Mapped::Full(r) => &r.summary,
            Mapped::Summary { summary, .. } => summary,
        }
    }

    fn points(&self) -> &Points {
        match self {
            Mapped::Full(r) => &r.points,
            Mapped::Summary { points, .. } => points,
        }
    }
}

/// The report of `chain map`: the library's [`MapResult`] (its JSON is the
/// spec's document) with what the command knows of its input.
pub(crate) struct MapDoc {
    values_file: String,
    entries: Vec<Entry>,
    errors: usize,
    /// Error parameters the values file does not give (zero).
    unset: usize,
    pub(crate) machine: String,
    frame: Frame,
    variables: Vec<String>,
    pub(crate) input: Input,
    pub(crate) result: Mapped,
    /// The map after compensation (`--compensated`).
    compensated: Option<Compensated>,
    /// Per bidirectional table, the reversal the approach read leaves out.
    reversals: Vec<Reversal>,
}

/// The error left after a controller's compensation, at the map's points.
pub(crate) struct Compensated {
    /// The controller's name.
    controller: &'static str,
    /// The nodes of the correction grid (`grid`), or the points of the
    /// tables (per-axis formats; 0 for Klipper's factors).
    nodes: usize,
    /// Where the correction comes from, in words (the table's heading).
    source: String,
    /// The residual map.
    result: MapResult,
}

/// `compensated` of the JSON document.
#[derive(Serialize)]
struct CompensatedDoc<'a> {
    controller: &'a str,
    correction_nodes: usize,
    #[serde(flatten)]
    map: &'a MapResult,
}

/// The spec's JSON document, with `compensated` (`--compensated`) added.
#[derive(Serialize)]
struct MapJson<'a> {
    #[serde(flatten)]
    map: &'a MapResult,
    #[serde(skip_serializing_if = "Option::is_none")]
    compensated: Option<CompensatedDoc<'a>>,
}

impl MapDoc {
    /// The whole result (every format but a large map's table has it).
    pub(crate) fn full(&self) -> Option<&MapResult> {
        match &self.result {
            Mapped::Full(r) => Some(r),
            Mapped::Summary { .. } => None,
        }
    }
}

impl Serialize for MapDoc {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let Some(map) = self.full() else {
            return Err(serde::ser::Error::custom("the map kept no point"));
        };
        MapJson {
            map,
            compensated: self.compensated.as_ref().map(|c| CompensatedDoc {
                controller: c.controller,
                correction_nodes: c.nodes,
                map: &c.result,
            }),
        }
        .serialize(s)
    }
}

/// mm → µm, rad → µrad, for the table.
const MICRO: [f64; 6] = [1e3, 1e3, 1e3, 1e6, 1e6, 1e6];
/// The table's units.
const UNITS: [&str; 6] = ["µm", "µm", "µm", "µrad", "µrad", "µrad"];

impl MapDoc {
    fn point_text(&self, i: usize) -> String {
        (self.variables.iter().zip(self.result.points().point(i)))
            .map(|(n, x)| format!("{n} = {}", number(x)))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// A coordinate: a whole number without decimals, else Rust's shortest form.
fn number(x: f64) -> String {
    match report::whole(x) {
        Some(i) => i.to_string(),
        None => format!("{x}"),
    }
}

impl Report for MapDoc {
    fn table(&self) -> String {
        use std::fmt::Write;
        let s = self.result.summary();
        let count = self.result.points().len();
        let mut out = String::new();
        let _ = writeln!(
            out,
            "Error map of {} (frame: {}), values {}",
            self.machine,
            self.frame.name(),
            self.values_file
        );
        let tables = (self.entries.iter())
            .filter(|e| matches!(e.given, Given::Table { .. }))
            .count();
        let constants = self.entries.len() - tables;
        let rest = match self.unset {
            0 => format!("all {} error parameters given", self.errors),
            n => format!(
                "{n} of the {} error parameters not given (zero)",
                self.errors
            ),
        };
        let _ = writeln!(
            out,
            "values: {} tabulated error motion{}, {} constant{}; {rest}",
            tables,
            if tables == 1 { "" } else { "s" },
            constants,
            if constants == 1 { "" } else { "s" },
        );
        for r in &self.reversals {
            let (f, unit) = if r.unit == "mm" {
                (1e3, "µm")
            } else {
                (1e6, "µrad")
            };
            let read = match r.approach {
                Approach::Mean => format!(
                    "the map reads their mean, leaving out ±{:.3} {unit}",
                    r.left_out * f
                ),
                a => format!(
                    "the map reads `{a}`, leaving out up to {:.3} {unit} when approached the other way",
                    r.left_out * f
                ),
            };
            let _ = writeln!(
                out,
                "reversal of {} along {}: up to {:.3} {unit} between the approach directions ({} = {}); {read}",
                r.name,
                r.variable,
                r.largest * f,
                r.variable,
                number(r.at)
            );
        }
        match &self.input {
            Input::Grid(axes) => {
                let desc: Vec<String> = axes
                    .iter()
                    .map(|(n, v)| match v.as_slice() {
                        [one] => format!("{n} = {}", number(*one)),
                        [first, .., last] => format!(
                            "{n} {} … {} ({} values)",
                            number(*first),
                            number(*last),
                            v.len()
                        ),
                        [] => format!("{n}: none"),
                    })
                    .collect();
                let _ = writeln!(out, "{count} points: {}", desc.join(", "));
            }
            Input::Axes(file) => {
                let _ = writeln!(out, "{count} points: the rows of {file}");
            }
        }
        let _ = writeln!(out);
        let _ = writeln!(
            out,
            "{:<12} {:>12} {:>12} {:>12}",
            "component", "min", "max", "rms"
        );
        for c in 0..6 {
            let cs = s.component(c);
            let f = MICRO[c];
            let _ = writeln!(
                out,
                "{:<12} {:>12.3} {:>12.3} {:>12.3}",
                format!("{} ({})", Component::NAMES[c], UNITS[c]),
                cs.min * f,
                cs.max * f,
                cs.rms * f
            );
        }
        let _ = writeln!(out);
        let _ = writeln!(
            out,
            "volumetric |p|: max {:.3} µm at {}; rms {:.3} µm",
            s.volumetric.max * 1e3,
            self.point_text(s.volumetric.index),
            s.volumetric.rms * 1e3
        );
        if let Some(c) = &self.compensated {
            let a = &c.result.summary;
            let _ = writeln!(out);
            let _ = writeln!(out, "After {} compensation ({}):", c.controller, c.source);
            let _ = writeln!(
                out,
                "{:<12} {:>12} {:>12} {:>12}   {:>12} {:>12} {:>12}",
                "component", "min", "max", "rms", "min after", "max after", "rms after"
            );
            for k in 0..6 {
                let (b, f) = (s.component(k), MICRO[k]);
                let ac = a.component(k);
                let _ = writeln!(
                    out,
                    "{:<12} {:>12.3} {:>12.3} {:>12.3}   {:>12.4} {:>12.4} {:>12.4}",
                    format!("{} ({})", Component::NAMES[k], UNITS[k]),
                    b.min * f,
                    b.max * f,
                    b.rms * f,
                    ac.min * f,
                    ac.max * f,
                    ac.rms * f
                );
            }
            let _ = writeln!(
                out,
                "volumetric |p| after: max {:.4} µm at {}; rms {:.4} µm (before: max {:.3} µm, rms {:.3} µm)",
                a.volumetric.max * 1e3,
                self.point_text(a.volumetric.index),
                a.volumetric.rms * 1e3,
                s.volumetric.max * 1e3,
                s.volumetric.rms * 1e3
            );
        }
        if let Some(r) = self.full().filter(|r| r.len() <= TABLE_POINTS) {
            let _ = writeln!(out);
            let mut header: Vec<String> = r.variables.clone();
            header.extend((0..6).map(|c| format!("{} ({})", Component::NAMES[c], UNITS[c])));
            header.push("|p| (µm)".to_string());
            let widths: Vec<usize> = header.iter().map(|h| h.chars().count().max(10)).collect();
            let line = |cells: &[String]| {
                cells
                    .iter()
                    .zip(&widths)
                    .map(|(c, w)| format!("{c:>w$}"))
                    .collect::<Vec<_>>()
                    .join("  ")
            };
            let _ = writeln!(out, "{}", line(&header));
            for i in 0..r.len() {
                let mut cells: Vec<String> = r.point(i).iter().map(|x| number(*x)).collect();
                cells.extend((0..6).map(|c| format!("{:.3}", r.errors[i][c] * MICRO[c])));
                cells.push(format!("{:.3}", r.volumetric(i) * 1e3));
                let _ = writeln!(out, "{}", line(&cells));
            }
        }
        out
    }

    fn csv(&self) -> Option<Csv> {
        let r = self.full()?;
        let mut header: Vec<String> = r.variables.clone();
        header.extend(Component::NAMES.map(String::from));
        header.push("volumetric".into());
        let after = self.compensated.as_ref().map(|c| &c.result);
        if after.is_some() {
            let names = Component::NAMES.iter().chain(&["volumetric"]);
            header.extend(names.map(|c| format!("{c}_after")));
        }
        let mut csv = Csv::new(header);
        for i in 0..r.len() {
            let mut row: Vec<String> = r.point(i).iter().map(|x| format!("{x}")).collect();
            row.extend(r.errors[i].iter().map(|x| format!("{x}")));
            row.push(format!("{}", r.volumetric(i)));
            if let Some(a) = after {
                row.extend(a.errors[i].iter().map(|x| format!("{x}")));
                row.push(format!("{}", a.volumetric(i)));
            }
            csv.row(row);
        }
        Some(csv)
    }
}

/// A compensation error of the values file `values`, worded by
/// [`chain::ops::export::ExportOpsError`].
fn export_error(
    error: chain_core::compensation::CompensationError,
    values: &std::path::Path,
) -> miette::Report {
    miette::Report::new(chain::ops::export::ExportOpsError::Compensation {
        values: values.display().to_string(),
        error: Box::new(error),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_ranges_are_evenly_spaced_and_end_at_hi() {
        let (n, v) = parse_grid_axis("x=0:1000:5").unwrap();
        assert_eq!(n, "x");
        assert_eq!(v, [0.0, 250.0, 500.0, 750.0, 1000.0]);
        let (_, v) = parse_grid_axis("z = 1:0:3").unwrap();
        assert_eq!(v, [1.0, 0.5, 0.0]);
        let (_, v) = parse_grid_axis("y=0.1:0.7:7").unwrap();
        assert_eq!(v.len(), 7);
        assert_eq!(v[6], 0.7);
        assert_eq!(parse_grid_axis("x=1,2").unwrap().1, [1.0, 2.0]);
        assert!(parse_grid_axis("x=0:1:1").unwrap_err().contains("N ≥ 2"));
        assert!(parse_grid_axis("x=0:1").unwrap_err().contains("LO:HI:N"));
        assert!(parse_grid_axis("x=0:0:3").unwrap_err().contains("LO ≠ HI"));
        assert!(parse_grid_axis("x=0:inf:3").is_err());
        assert!(parse_grid_axis("x=0:1:2.5").is_err());
    }
}
