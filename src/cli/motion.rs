//! `chain motion FILE --settings SETTINGS.yaml [--order N] [--tolerance TOL]
//! [--samples K] [--format table|json|csv] [--plot DIR]`.
//!
//! The motion conversion of seed 002: the CNC axis motions of `FILE` that
//! reproduce, at every instant of the roll, the tool pose of the generator
//! described by the settings file (`docs/motion.md`), checked instant by
//! instant, and their Maclaurin expansion at `t = 0` with its truncation error
//! over the roll and the order a tolerance needs.

#[path = "motion_plot.rs"]
mod motion_plot;

use std::fmt::Write as _;
use std::path::PathBuf;

use chain_core::model::JointKind;
use chain_core::motion::{self, Matching, Motion, PoseError, Series};
use chain_core::settings;
use serde_json::{json, Map, Value};

use super::reliability::{parse_assignment, resolve_fixed};
use super::report::write_stdout;

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
/// Converts the roll of a generating machine (the cradle-type generator of
/// seed 002 by default) into the motions of the CNC machine FILE, so that both
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

/// Everything computed for one run.
struct Run {
    motion: Motion,
    settings: settings::Settings,
    cnc_parameters: Vec<(String, f64)>,
    times: Vec<f64>,
    exact: Vec<Vec<f64>>,
    worst: PoseError,
    order: usize,
    series: Series,
    /// `errors[m][k]` for m = 0..=series order.
    errors: Vec<Vec<f64>>,
    tolerance: Option<Vec<f64>>,
    required: Option<(Option<usize>, Vec<Option<usize>>)>,
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
    let motion = Motion::new(&generator, &cnc, spec).map_err(|e| miette::miette!("{e}"))?;
    let times = motion.sample_times(args.samples);
    let q0 = motion.solve_cold(0.0).map_err(|e| miette::miette!("{e}"))?;
    let exact = motion
        .trajectory_from(&q0, &times)
        .map_err(|e| miette::miette!("{e}"))?;
    let mut worst = PoseError {
        position: 0.0,
        rotation: 0.0,
        axis: 0.0,
    };
    for (t, q) in times.iter().zip(&exact) {
        let e = motion.pose_error(q, *t);
        worst.position = worst.position.max(e.position);
        worst.rotation = worst.rotation.max(e.rotation);
        worst.axis = worst.axis.max(e.axis);
    }
    let tolerance: Option<Vec<f64>> = args.tolerance.map(|tol| {
        let ang = args.angular_tolerance.unwrap_or(tol);
        motion
            .kinds()
            .iter()
            .map(|k| if *k == JointKind::Rotary { ang } else { tol })
            .collect()
    });
    let computed = if tolerance.is_some() {
        args.order.max(args.max_order)
    } else {
        args.order
    };
    let series = motion
        .series_from(&q0, computed)
        .map_err(|e| miette::miette!("{e}"))?;
    let errors = motion::truncation_errors(&series, &times, &exact);
    let required = tolerance
        .as_ref()
        .map(|tol| motion::required_orders(&errors, tol));
    let run = Run {
        motion,
        settings,
        cnc_parameters,
        times,
        exact,
        worst,
        order: args.order,
        series,
        errors,
        tolerance,
        required,
    };
    if args.format == MotionFormat::Csv {
        let mut files = Vec::new();
        if let Some(dir) = &args.plot {
            files = motion_plot::write_all(dir, &run_view(&run))?;
        }
        for f in &files {
            eprintln!("wrote {}", f.display());
        }
        return write_stdout(&csv(&run));
    }
    let files = match &args.plot {
        Some(dir) => motion_plot::write_all(dir, &run_view(&run))?,
        None => Vec::new(),
    };
    let text = match args.format {
        MotionFormat::Json => {
            let mut s = serde_json::to_string_pretty(&json_document(&run, &files))
                .map_err(|e| miette::miette!("cannot serialise the result: {e}"))?;
            s.push('\n');
            s
        }
        _ => table(&run, &files),
    };
    write_stdout(&text)
}

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

fn run_view(run: &Run) -> motion_plot::View<'_> {
    motion_plot::View {
        title: format!(
            "{} → {} ({})",
            run.motion.generator_name(),
            run.motion.cnc_name(),
            run.settings.name
        ),
        variables: run.motion.variables(),
        kinds: run.motion.kinds(),
        times: &run.times,
        exact: &run.exact,
        series: &run.series,
        order: run.order,
        errors: &run.errors,
        tolerance: run.tolerance.as_deref(),
    }
}

fn unit(kind: JointKind) -> &'static str {
    match kind {
        JointKind::Rotary => "rad",
        JointKind::Prismatic => "mm",
    }
}

fn csv(run: &Run) -> String {
    let mut s = String::from("t");
    for v in run.motion.variables() {
        s.push(',');
        s.push_str(v);
    }
    s.push('\n');
    for (t, q) in run.times.iter().zip(&run.exact) {
        let _ = write!(s, "{t}");
        for x in q {
            let _ = write!(s, ",{x}");
        }
        s.push('\n');
    }
    s
}

fn per_axis(names: &[String], values: impl IntoIterator<Item = Value>) -> Value {
    let mut m = Map::new();
    for (n, v) in names.iter().zip(values) {
        m.insert(n.clone(), v);
    }
    Value::Object(m)
}

fn json_document(run: &Run, files: &[PathBuf]) -> Value {
    let m = &run.motion;
    let names = m.variables();
    let n = run.order;
    let laws: Map<String, Value> = m
        .generator_variables()
        .iter()
        .zip(m.laws())
        .map(|(v, l)| (v.clone(), json!({"start": l.start, "rate": l.rate})))
        .collect();
    let fixed: Map<String, Value> = m
        .fixed()
        .iter()
        .map(|&(i, v)| (names[i].clone(), json!(v)))
        .collect();
    let coefficients = per_axis(
        names,
        run.series
            .axes
            .iter()
            .map(|j| json!(j.coefficients()[..=n].to_vec())),
    );
    let derivatives = per_axis(
        names,
        run.series
            .axes
            .iter()
            .map(|j| json!((0..=n).map(|k| j.derivative(k)).collect::<Vec<f64>>())),
    );
    let errors_by_order: Vec<Value> = run
        .errors
        .iter()
        .enumerate()
        .map(|(order, e)| {
            json!({"order": order, "max_error": per_axis(names, e.iter().map(|x| json!(x)))})
        })
        .collect();
    let required = match (&run.tolerance, &run.required) {
        (Some(tol), Some((all, each))) => json!({
            "tolerance": per_axis(names, tol.iter().map(|x| json!(x))),
            "searched_up_to": run.series.order(),
            "all": all,
            "per_axis": per_axis(names, each.iter().map(|x| json!(x))),
        }),
        _ => Value::Null,
    };
    let mut doc = json!({
        "machine": m.cnc_name(),
        "generator": m.generator_name(),
        "settings": run.settings.name,
        "match": m.matching().name(),
        "variables": names,
        "units": per_axis(names, m.kinds().iter().map(|k| json!(unit(*k)))),
        "parameters": run.cnc_parameters.iter().map(|(k, v)| (k.clone(), json!(v))).collect::<Map<String, Value>>(),
        "fixed": fixed,
        "generator_laws": laws,
        "interval": [m.interval().0, m.interval().1],
        "samples": run.times.len(),
        "equivalence": {
            "max_position_error": run.worst.position,
            "max_rotation_error": run.worst.rotation,
            "max_axis_error": run.worst.axis,
        },
        "order": n,
        "at_zero": per_axis(names, run.series.axes.iter().map(|j| json!(j.value()))),
        "coefficients": coefficients,
        "derivatives": derivatives,
        "truncation_error": per_axis(names, run.errors[n].iter().map(|x| json!(x))),
        "errors_by_order": errors_by_order,
        "required_order": required,
    });
    if !files.is_empty() {
        doc["written"] = json!(files
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>());
    }
    doc
}

fn sci(x: f64) -> String {
    format!("{x:.3e}")
}

fn table(run: &Run, files: &[PathBuf]) -> String {
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
        run.settings.name,
        run.settings.file
    );
    if let Some(d) = &run.settings.description {
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
    let params: Vec<String> = run
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
    let shown = match &run.required {
        Some((Some(all), _)) => n.max(all + 3).min(last),
        Some((None, _)) => last,
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
    if let (Some(tol), Some((all, each))) = (&run.tolerance, &run.required) {
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
