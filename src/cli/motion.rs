//! `chain motion FILE --settings SETTINGS.yaml [--order N] [--tolerance TOL]
//! [--samples K] [--format table|json|csv] [--plot DIR]`.
//!
//! The motion conversion of the five-axis jewelry machining paper (2022):
//! the CNC axis motions of `FILE` that
//! reproduce, at every instant of the roll, the tool pose of the generator
//! described by the settings file (`docs/motion.md`), checked instant by
//! instant, and their Maclaurin expansion at `t = 0` with its truncation error
//! over the roll and the order a tolerance needs.

#[path = "motion_plot.rs"]
mod motion_plot;

use std::fmt::Write as _;
use std::path::PathBuf;

use chain_core::conversion::{Conversion, RunOptions};
use chain_core::model::JointKind;
use chain_core::motion::{Law, Matching, Motion};
use chain_core::named::NameMap;
use chain_core::settings;
use serde::{Serialize, Serializer};

use super::args::parse_assignment;
use super::loaded::resolve_fixed;
use super::report::{self, Csv, Report};

/// Highest order accepted for `--order` and `--max-order`: the JSON lists
/// the derivatives `k!·a_k`, and 171! overflows `f64`.
pub const MAX_ORDER: usize = 170;
/// Most instants accepted for `--samples`.
pub const MAX_SAMPLES: usize = 1_000_000;

/// Output formats of `chain motion`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum MotionFormat {
    /// Settings, coefficients, truncation errors and the required order.
    Table,
    /// One JSON document (docs/motion.md).
    Json,
    /// The exact motion: header `t,<CNC variables>`, one line per instant
    /// (feeds `chain path FILE --axes motion.csv`).
    Csv,
}

/// Arguments of `chain motion`.
///
/// Converts the roll of a generating machine (by default the cradle-type
/// generator of "Precision Machining Technology of Jewelry on CNC Machine
/// Tool", 2022) into the motions of the CNC machine FILE, so that both
/// give the same tool pose relative to the workpiece at every instant, and
/// expands every axis motion in its Maclaurin series.
#[derive(Debug, clap::Args)]
pub struct MotionArgs {
    /// The CNC machine file (YAML).
    pub file: PathBuf,
    /// The machine settings and the roll (docs/motion.md).
    #[arg(long, value_name = "SETTINGS.yaml")]
    pub settings: PathBuf,
    /// Order n of the Maclaurin series.
    #[arg(long, default_value_t = 8, value_name = "N")]
    pub order: usize,
    /// Accuracy wanted of the series over the roll interval, in model units
    /// (mm for linear axes; also rad for rotary ones unless
    /// --angular-tolerance is given): reports the smallest order that meets it.
    #[arg(long, value_name = "TOL")]
    pub tolerance: Option<f64>,
    /// Accuracy wanted of the rotary axes (rad); default --tolerance.
    #[arg(long, value_name = "RAD")]
    pub angular_tolerance: Option<f64>,
    /// Highest order searched for --tolerance.
    #[arg(long, default_value_t = 40, value_name = "N")]
    pub max_order: usize,
    /// Instants, evenly spaced over the roll interval (both ends included).
    #[arg(long, default_value_t = 1000, value_name = "K")]
    pub samples: usize,
    /// Output format.
    #[arg(long, value_enum, default_value = "table")]
    pub format: MotionFormat,
    /// Write the axis motions and the truncation error against the order
    /// (PNG and SVG) into DIR.
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
    /// Value of a CNC machine parameter, `NAME=VALUE` (repeatable; overrides
    /// the settings file's `cnc.parameters`).
    #[arg(long = "param", value_name = "NAME=VALUE", value_parser = parse_assignment)]
    pub params: Vec<(String, f64)>,
    /// Hold a CNC variable, `NAME=VALUE` (repeatable): matches the tool point
    /// and axis only (`match: point_axis`), as in face milling with `mu=0`.
    #[arg(long = "fix", value_name = "NAME=VALUE", value_parser = parse_assignment)]
    pub fix: Vec<(String, f64)>,
}

/// Runs `chain motion`.
pub fn exec(args: MotionArgs) -> miette::Result<()> {
    check_args(&args)?;
    let settings = settings::load_settings_file(&args.settings)?;
    let cnc = chain_core::load_file(&args.file)?;
    let generator = settings.load_generator()?;
    let mut spec = settings.bind(&generator, &cnc, &args.params)?;
    if !args.fix.is_empty() {
        spec.matching = Matching::PointAxis;
        spec.fixed.clear();
        for (i, v) in resolve_fixed(&cnc, &args.fix)? {
            spec.fixed.push((i, v));
            spec.start[i] = v;
        }
    }
    let cnc_parameters: Vec<(String, f64)> = cnc
        .parameters
        .iter()
        .zip(&spec.cnc_parameters)
        .map(|(p, v)| (p.name.clone(), *v))
        .collect();
    let motion = Motion::new(&generator, &cnc, spec)?;
    let conversion = Conversion::run(
        motion,
        &RunOptions {
            samples: args.samples,
            order: args.order,
            max_order: args.max_order,
            tolerance: args.tolerance,
            angular_tolerance: args.angular_tolerance,
        },
    )?;
    let mut doc = MotionReport {
        conversion,
        settings,
        cnc_parameters,
        written: Vec::new(),
    };
    if let Some(dir) = &args.plot {
        doc.written = motion_plot::write_all(dir, &doc.view())?;
    }
    if args.format == MotionFormat::Csv {
        // The CSV is the motion alone: the files go to stderr.
        for f in &doc.written {
            eprintln!("wrote {}", f.display());
        }
    }
    report::emit(&doc, args.format.into())
}

report::formats!(MotionFormat: Table, Json, Csv);

fn check_args(args: &MotionArgs) -> miette::Result<()> {
    if args.order > MAX_ORDER {
        miette::bail!("--order {} is above the limit {MAX_ORDER}", args.order);
    }
    if args.max_order > MAX_ORDER {
        miette::bail!(
            "--max-order {} is above the limit {MAX_ORDER}",
            args.max_order
        );
    }
    if !(2..=MAX_SAMPLES).contains(&args.samples) {
        miette::bail!(
            "--samples {} must be between 2 and {MAX_SAMPLES}",
            args.samples
        );
    }
    for (flag, v) in [
        ("--tolerance", args.tolerance),
        ("--angular-tolerance", args.angular_tolerance),
    ] {
        if let Some(v) = v {
            if !(v.is_finite() && v > 0.0) {
                miette::bail!("{flag} must be a positive number, got {v}");
            }
        }
    }
    if args.angular_tolerance.is_some() && args.tolerance.is_none() {
        miette::bail!("--angular-tolerance needs --tolerance");
    }
    Ok(())
}

/// The result document of `chain motion`: one conversion run with the
/// settings it came from and the plot files written (docs/motion.md).
struct MotionReport {
    conversion: Conversion,
    settings: settings::Settings,
    cnc_parameters: Vec<(String, f64)>,
    written: Vec<PathBuf>,
}

impl MotionReport {
    fn view(&self) -> motion_plot::View<'_> {
        let run = &self.conversion;
        motion_plot::View {
            title: format!(
                "{} → {} ({})",
                run.motion.generator_name(),
                run.motion.cnc_name(),
                self.settings.name
            ),
            variables: run.motion.variables(),
            kinds: run.motion.kinds(),
            times: &run.times,
            exact: &run.exact,
            series: &run.series,
            order: run.order,
            errors: &run.errors,
            tolerance: run.required.as_ref().map(|r| r.tolerance.as_slice()),
        }
    }
}

fn unit(kind: JointKind) -> &'static str {
    match kind {
        JointKind::Rotary => "rad",
        JointKind::Prismatic => "mm",
    }
}

/// A value per CNC axis, keyed by the axis variable.
type PerAxis<'a, V> = NameMap<&'a str, V>;

/// The JSON document (field order = key order; docs/motion.md).
#[derive(Serialize)]
struct MotionDoc<'a> {
    machine: &'a str,
    generator: &'a str,
    settings: &'a str,
    #[serde(rename = "match")]
    matching: Matching,
    variables: &'a [String],
    units: PerAxis<'a, &'static str>,
    parameters: NameMap<&'a str, f64>,
    fixed: PerAxis<'a, f64>,
    generator_laws: NameMap<&'a str, Law>,
    interval: [f64; 2],
    samples: usize,
    equivalence: EquivalenceDoc,
    order: usize,
    at_zero: PerAxis<'a, f64>,
    coefficients: PerAxis<'a, &'a [f64]>,
    derivatives: PerAxis<'a, Vec<f64>>,
    truncation_error: PerAxis<'a, f64>,
    errors_by_order: Vec<OrderDoc<'a>>,
    required_order: Option<RequiredDoc<'a>>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    written: Vec<String>,
}

/// The worst pose difference of the two chains over the roll.
#[derive(Serialize)]
struct EquivalenceDoc {
    max_position_error: f64,
    max_rotation_error: f64,
    max_axis_error: f64,
}

/// The truncation error of one order.
#[derive(Serialize)]
struct OrderDoc<'a> {
    order: usize,
    max_error: PerAxis<'a, f64>,
}

/// The order a tolerance needs.
#[derive(Serialize)]
struct RequiredDoc<'a> {
    tolerance: PerAxis<'a, f64>,
    searched_up_to: usize,
    all: Option<usize>,
    per_axis: PerAxis<'a, Option<usize>>,
}

impl Serialize for MotionReport {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let run = &self.conversion;
        let m = &run.motion;
        let names = || m.variables().iter().map(String::as_str);
        let n = run.order;
        MotionDoc {
            machine: m.cnc_name(),
            generator: m.generator_name(),
            settings: &self.settings.name,
            matching: m.matching(),
            variables: m.variables(),
            units: NameMap::zip(names(), m.kinds().iter().map(|k| unit(*k))),
            parameters: self
                .cnc_parameters
                .iter()
                .map(|(k, v)| (k.as_str(), *v))
                .collect(),
            fixed: m
                .fixed()
                .iter()
                .map(|&(i, v)| (m.variables()[i].as_str(), v))
                .collect(),
            generator_laws: NameMap::zip(
                m.generator_variables().iter().map(String::as_str),
                m.laws().iter().copied(),
            ),
            interval: [m.interval().0, m.interval().1],
            samples: run.times.len(),
            equivalence: EquivalenceDoc {
                max_position_error: run.worst.position,
                max_rotation_error: run.worst.rotation,
                max_axis_error: run.worst.axis,
            },
            order: n,
            at_zero: NameMap::zip(names(), run.series.axes.iter().map(|j| j.value())),
            coefficients: NameMap::zip(
                names(),
                run.series.axes.iter().map(|j| &j.coefficients()[..=n]),
            ),
            derivatives: NameMap::zip(
                names(),
                run.series
                    .axes
                    .iter()
                    .map(|j| (0..=n).map(|k| j.derivative(k)).collect()),
            ),
            truncation_error: NameMap::zip(names(), run.truncation_error().iter().copied()),
            errors_by_order: run
                .errors
                .iter()
                .enumerate()
                .map(|(order, e)| OrderDoc {
                    order,
                    max_error: NameMap::zip(names(), e.iter().copied()),
                })
                .collect(),
            required_order: run.required.as_ref().map(|r| RequiredDoc {
                tolerance: NameMap::zip(names(), r.tolerance.iter().copied()),
                searched_up_to: r.searched_up_to,
                all: r.all,
                per_axis: NameMap::zip(names(), r.per_axis.iter().copied()),
            }),
            written: self
                .written
                .iter()
                .map(|p| p.display().to_string())
                .collect(),
        }
        .serialize(serializer)
    }
}

impl Report for MotionReport {
    /// Settings, laws, the equivalence check, the coefficients, the
    /// truncation errors and the required order.
    fn table(&self) -> String {
        table(self)
    }

    /// The exact motion: `t,<CNC variables>`, one line per instant.
    fn csv(&self) -> Option<Csv> {
        let run = &self.conversion;
        let mut csv =
            Csv::new(std::iter::once("t").chain(run.motion.variables().iter().map(String::as_str)));
        for (t, q) in run.times.iter().zip(&run.exact) {
            csv.row(std::iter::once(t.to_string()).chain(q.iter().map(f64::to_string)));
        }
        Some(csv)
    }
}

fn sci(x: f64) -> String {
    format!("{x:.3e}")
}

fn table(doc: &MotionReport) -> String {
    let run = &doc.conversion;
    let files = &doc.written;
    let m = &run.motion;
    let names = m.variables();
    let kinds = m.kinds();
    let n = run.order;
    let mut s = String::new();
    let (t0, t1) = m.interval();
    let _ = writeln!(
        s,
        "Motion conversion {} → {} (settings `{}`, {})",
        m.generator_name(),
        m.cnc_name(),
        doc.settings.name,
        doc.settings.file
    );
    if let Some(d) = &doc.settings.description {
        let _ = writeln!(s, "  {d}");
    }
    let _ = writeln!(
        s,
        "  match: {}   roll interval t ∈ [{t0}, {t1}] s, {} instants",
        match m.matching() {
            Matching::Pose => "pose (rotation and position; every axis determined)",
            Matching::PointAxis => "point_axis (tool point and tool axis; held variables fixed)",
        },
        run.times.len()
    );
    let _ = writeln!(s, "\nGenerator laws v(t) = start + rate·t (rad, mm, s):");
    for (v, l) in m.generator_variables().iter().zip(m.laws()) {
        if l.rate == 0.0 {
            let _ = writeln!(s, "  {v:>10} = {:.10}", l.start);
        } else {
            let _ = writeln!(s, "  {v:>10} = {:.10} + {:.10}·t", l.start, l.rate);
        }
    }
    let params: Vec<String> = doc
        .cnc_parameters
        .iter()
        .map(|(k, v)| format!("{k} = {v}"))
        .collect();
    if !params.is_empty() {
        let _ = writeln!(s, "CNC parameters: {}", params.join(", "));
    }
    if !m.fixed().is_empty() {
        let held: Vec<String> = m
            .fixed()
            .iter()
            .map(|&(i, v)| format!("{} = {v}", names[i]))
            .collect();
        let _ = writeln!(s, "CNC variables held: {}", held.join(", "));
    }
    let _ = writeln!(
        s,
        "\nEquivalence of the two chains at {} instants: position ≤ {} mm, rotation ≤ {} rad, tool axis ≤ {} rad",
        run.times.len(),
        sci(run.worst.position),
        sci(run.worst.rotation),
        sci(run.worst.axis)
    );

    let width = 16;
    let header = |s: &mut String, first: &str| {
        let _ = write!(s, "{first:>6}");
        for (v, k) in names.iter().zip(kinds) {
            let _ = write!(s, " {:>width$}", format!("{v} ({})", unit(*k)));
        }
        s.push('\n');
    };
    let _ = writeln!(
        s,
        "\nMaclaurin coefficients a_k = L^(k)(0)/k! (axis(t) = Σ a_k t^k):"
    );
    header(&mut s, "k");
    for k in 0..=n {
        let _ = write!(s, "{k:>6}");
        for j in &run.series.axes {
            let _ = write!(s, " {:>width$.9e}", j.coefficients()[k]);
        }
        s.push('\n');
    }
    let _ = writeln!(
        s,
        "\nTruncation error max |exact − series of order m| over [{t0}, {t1}]:"
    );
    header(&mut s, "m");
    // Up to the requested order, or a little past the required one.
    let last = run.errors.len() - 1;
    let shown = match run.required.as_ref().map(|r| r.all) {
        Some(Some(all)) => n.max(all + 3).min(last),
        Some(None) => last,
        None => n,
    };
    for (order, e) in run.errors.iter().enumerate().take(shown + 1) {
        let mark = if order == n { "*" } else { " " };
        let _ = write!(s, "{order:>5}{mark}");
        for x in e {
            let _ = write!(s, " {:>width$}", sci(*x));
        }
        s.push('\n');
    }
    if shown < last {
        let _ = writeln!(
            s,
            "  (* the requested order {n}; orders up to {last} computed, all in --format json)"
        );
    } else {
        let _ = writeln!(s, "  (* the requested order {n})");
    }
    if let Some(required) = &run.required {
        let (tol, all, each) = (&required.tolerance, required.all, &required.per_axis);
        let lin = kinds
            .iter()
            .zip(tol)
            .find(|(k, _)| **k == JointKind::Prismatic)
            .map(|(_, t)| *t);
        let ang = kinds
            .iter()
            .zip(tol)
            .find(|(k, _)| **k == JointKind::Rotary)
            .map(|(_, t)| *t);
        let mut what = Vec::new();
        if let Some(l) = lin {
            what.push(format!("{l:e} mm"));
        }
        if let Some(a) = ang {
            what.push(format!("{a:e} rad"));
        }
        let each: Vec<String> = names
            .iter()
            .zip(each)
            .map(|(v, o)| match o {
                Some(o) => format!("{v} {o}"),
                None => format!("{v} >{}", run.series.order()),
            })
            .collect();
        let _ = writeln!(
            s,
            "\nRequired order for {}: {} ({})",
            what.join(", "),
            match all {
                Some(o) => o.to_string(),
                None => format!(
                    "not reached up to order {} (the series may diverge on this interval, or the tolerance is below the rounding floor)",
                    run.series.order()
                ),
            },
            each.join(", ")
        );
    }
    if !files.is_empty() {
        let _ = writeln!(s, "\nPlots written:");
        for f in files {
            let _ = writeln!(s, "  {}", f.display());
        }
    }
    s
}
