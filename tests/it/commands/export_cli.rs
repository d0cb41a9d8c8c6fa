//! `chain export` with the per-axis controllers and `chain map --compensated`
//! with them (measured-machines spec, section 6):
//! the command line reaches the library with the options it names (travel
//! from `--grid`, `--step`, the controller limits), the files it writes are
//! the library's, the compensated map agrees with this test's own reading of
//! the LinuxCNC tables applied to the uncompensated map (first order: the
//! nominal axis directions by the numeric product of `tests/it/common`), and
//! bad input is refused with a located message, a non-zero exit and nothing
//! on stdout.

use crate::common;

use std::path::Path;

use chain::core::built::BuiltMachine;
use chain::core::compensation::controllers::{export, Controller, ExportOptions, Takes};
use chain::core::values::Values;
use chain::ops::export::ExportController;
use common::cli::{fails, ok, ok_json, scratch, unwrapped, write};
use common::{example_file, load_example, Exact};

const MACHINE: &str = "examples/machines/vmc3.yaml";
const VALUES: &str = "examples/values/vmc3.yaml";

/// `chain export MACHINE --values VALUES --controller c` and `extra`.
fn export_args<'a>(controller: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut a = vec![
        "export",
        MACHINE,
        "--values",
        VALUES,
        "--controller",
        controller,
    ];
    a.extend_from_slice(extra);
    a
}

/// The library's export of vmc3 (tool length 150) with `options`, its
/// files opening with the words `chain export` writes.
fn library(controller: Controller, options: &ExportOptions) -> Vec<(String, String)> {
    let machine = load_example("vmc3.yaml");
    let values = Values::read(&example_file("values/vmc3.yaml"), &machine).unwrap();
    let built = BuiltMachine::compile(&machine, values, vec![150.0]).unwrap();
    let options = ExportOptions {
        provenance: ExportController::Tables(controller).provenance(),
        ..options.clone()
    };
    let e = export(controller, &built, &machine, &options).unwrap();
    e.files.into_iter().map(|f| (f.name, f.text)).collect()
}

/// The `nominal fwd rev` lines of a LinuxCNC comp file (data before the
/// first line that is not three numbers, as LinuxCNC reads it).
fn comp_lines(text: &str) -> Vec<[f64; 3]> {
    let mut out = Vec::new();
    for line in text.lines() {
        let v: Vec<f64> = line
            .split_whitespace()
            .map_while(|t| t.parse().ok())
            .collect();
        if v.len() != 3 || line.split_whitespace().count() != 3 {
            break;
        }
        out.push([v[0], v[1], v[2]]);
    }
    out
}

/// The comp table `t` read at `x`: linear between entries, the end values
/// held outside (LinuxCNC's `motion.c`).
fn comp_at(t: &[[f64; 3]], x: f64) -> f64 {
    if x <= t[0][0] {
        return t[0][1];
    }
    let last = t[t.len() - 1];
    if x >= last[0] {
        return last[1];
    }
    let k = t.iter().position(|r| r[0] > x).unwrap();
    let (a, b) = (t[k - 1], t[k]);
    a[1] + (b[1] - a[1]) * (x - a[0]) / (b[0] - a[0])
}

#[test]
fn the_command_writes_the_library_files_with_its_travel_and_step() {
    let mut linuxcnc = None;
    let per_axis = (Controller::ALL.into_iter())
        .filter(|c| matches!(c.capabilities().takes, Takes::LinearAxes { .. }));
    for c in per_axis {
        let dir = scratch(&format!("files-{}", c.name()));
        let out = ok(&export_args(
            c.name(),
            &[
                "--grid",
                "x=100,700",
                "--step",
                "25",
                "--out",
                dir.to_str().unwrap(),
            ],
        ));
        // The report goes to stdout (table by default), the files to DIR.
        let report = String::from_utf8(out.stdout).unwrap();
        assert!(
            report.starts_with(&format!(
                "Compensation of vmc3 for controller {}, values {VALUES}",
                c.name()
            )),
            "{report}"
        );
        let options = ExportOptions {
            step: 25.0,
            travel: vec![("x".into(), [100.0, 700.0])],
            ..ExportOptions::default()
        };
        let files = library(c, &options);
        assert!(!files.is_empty());
        for (name, text) in &files {
            let written = std::fs::read_to_string(dir.join(name)).unwrap();
            assert_eq!(&written, text, "{} {name}", c.name());
        }
        if c == Controller::Linuxcnc {
            linuxcnc = Some(dir);
        }
    }
    // Field by field: x's comp file runs 100 to 700 every 25 mm, with the
    // measured table's positions (every 40 mm) between (37 lines); y's keeps
    // the machine file's travel 0..500, at 25 mm, where its table's
    // positions are too (21 lines).
    let dir = linuxcnc.unwrap();
    let x = comp_lines(&std::fs::read_to_string(dir.join("x.comp")).unwrap());
    let mut nominals: Vec<f64> = (0..25).map(|k| 100.0 + 25.0 * k as f64).collect();
    nominals.extend((3..18).map(|m| 40.0 * m as f64).filter(|q| q % 25.0 != 0.0));
    nominals.sort_by(f64::total_cmp);
    assert_eq!(x.iter().map(|r| r[0]).collect::<Vec<_>>(), nominals);
    for row in &x {
        assert_eq!(row[1], row[2]);
    }
    let y = comp_lines(&std::fs::read_to_string(dir.join("y.comp")).unwrap());
    assert_eq!((y.len(), y[0][0], y[20][0]), (21, 0.0, 500.0));
}

#[test]
fn the_json_report_is_the_library_report() {
    let v = ok_json(&export_args("siemens-cec", &["--format", "json"]));
    assert_eq!(v["values_file"], VALUES);
    assert_eq!(v["controller"], "siemens-cec");
    assert_eq!(v["files"][0], "NC_CEC.INI");
    let axes = v["axes"].as_array().unwrap();
    let x = axes.iter().find(|a| a["variable"] == "x").unwrap();
    assert_eq!(
        (x["min"].as_f64(), x["max"].as_f64()),
        (Some(0.0), Some(800.0))
    );
    assert_eq!(
        (x["step"].as_f64(), x["points"].as_u64()),
        (Some(10.0), Some(81))
    );
    // The six straightness errors are what CEC expresses (docs/export-controllers.md).
    let mut expressed: Vec<&str> = (v["expressed"].as_array().unwrap().iter())
        .map(|t| t["name"].as_str().unwrap())
        .collect();
    expressed.sort_unstable();
    assert_eq!(expressed, ["EXY", "EXZ", "EYX", "EYZ", "EZX", "EZY"]);
}

#[test]
fn one_file_goes_to_stdout_and_several_need_out() {
    let out = ok(&export_args("siemens-cec", &[]));
    let text = String::from_utf8(out.stdout).unwrap();
    assert_eq!(
        text,
        library(Controller::SiemensCec, &ExportOptions::default())[0].1
    );
    let err = unwrapped(&fails(&export_args("linuxcnc", &[])));
    assert!(
        err.contains("--controller linuxcnc writes 4 files (y.comp, x.comp, z.comp, linuxcnc-"),
        "{err}"
    );
    assert!(err.contains("README.txt): give --out DIR"), "{err}");
}

/// `chain map --compensated linuxcnc` against this test's own reading of
/// the LinuxCNC files `chain export` writes: at each map point the error
/// after is the error before plus the nominal tool motion of the trims
/// (`Σ_i d_i · δq_i`, `d_i` by the numeric product), to first order (the
/// values' slope times the trim: below 1 nm here). A wrong sign would leave
/// twice the positioning error.
#[test]
fn map_compensated_linuxcnc_is_the_comp_tables_applied() {
    let dir = scratch("map-linuxcnc");
    ok(&export_args("linuxcnc", &["--out", dir.to_str().unwrap()]));
    let machine = load_example("vmc3.yaml");
    let tables: Vec<Vec<[f64; 3]>> = (machine.variables.iter())
        .map(|v| {
            let text = std::fs::read_to_string(dir.join(format!("{}.comp", v.name))).unwrap();
            comp_lines(&text)
        })
        .collect();
    let exact = Exact::new(&machine);
    let q0 = vec![0.0; 3];
    let d: Vec<[f64; 3]> = (0..3)
        .map(|i| {
            let mut q1 = q0.clone();
            q1[i] = 100.0;
            let a = exact.nominal(&q0, &[150.0]).1;
            let b = exact.nominal(&q1, &[150.0]).1;
            std::array::from_fn(|c| (b[c] - a[c]) / 100.0)
        })
        .collect();
    let v = ok_json(&[
        "map",
        MACHINE,
        "--values",
        VALUES,
        "--grid",
        "x=0:800:5",
        "--grid",
        "y=0:500:4",
        "--compensated",
        "linuxcnc",
        "--format",
        "json",
    ]);
    assert_eq!(v["compensated"]["controller"], "linuxcnc");
    let before = v["points"].as_array().unwrap();
    let after = v["compensated"]["points"].as_array().unwrap();
    assert_eq!(before.len(), after.len());
    let mut largest_trim: f64 = 0.0;
    for (b, a) in before.iter().zip(after) {
        let q: Vec<f64> = (machine.variables.iter())
            .map(|var| b["point"][var.name.as_str()].as_f64().unwrap())
            .collect();
        let trims: Vec<f64> = (0..3).map(|i| comp_at(&tables[i], q[i])).collect();
        for (c, key) in ["px", "py", "pz"].iter().enumerate() {
            let expect = b["error"][*key].as_f64().unwrap()
                + (0..3).map(|i| d[i][c] * trims[i]).sum::<f64>();
            let got = a["error"][*key].as_f64().unwrap();
            assert!(
                (got - expect).abs() < 1e-6,
                "{key} at {q:?}: {got} vs {expect}"
            );
        }
        largest_trim = trims.iter().fold(largest_trim, |m, t| m.max(t.abs()));
    }
    // The trims are the µm-size positioning errors, not zero.
    assert!(largest_trim > 5e-3, "{largest_trim}");
}

/// The report of `chain export --controller klipper` (the error minus what
/// the format expresses, first order) gives the same residual as the map's
/// largest `|p|` after `map --compensated klipper` (the correction applied
/// at `q + δq`) over the same nodes: equal to the second-order term, the
/// errors' slope times the 15 µm correction (below 1 nm).
#[test]
fn map_compensated_and_export_report_agree() {
    let report = ok_json(&export_args("klipper", &["--format", "json"]));
    let grid = report["check_grid"].as_array().unwrap();
    let mut args: Vec<String> = ["map", MACHINE, "--values", VALUES]
        .iter()
        .map(|s| s.to_string())
        .collect();
    for g in grid {
        let nodes: Vec<String> = (g[1].as_array().unwrap().iter())
            .map(|x| x.as_f64().unwrap().to_string())
            .collect();
        args.push("--grid".into());
        args.push(format!("{}={}", g[0].as_str().unwrap(), nodes.join(",")));
    }
    args.extend(["--compensated", "klipper", "--format", "json"].map(String::from));
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let v = ok_json(&args);
    let max_after = (v["compensated"]["points"].as_array().unwrap().iter())
        .map(|p| {
            let c = |k: &str| p["error"][k].as_f64().unwrap();
            (c("px").powi(2) + c("py").powi(2) + c("pz").powi(2)).sqrt()
        })
        .fold(0.0, f64::max);
    let reported = report["residual"]["position"].as_f64().unwrap();
    assert!(
        (max_after - reported).abs() < 1e-6,
        "{max_after} vs {reported}"
    );
}

/// Runs a refused `chain` and returns its unwrapped stderr, checking that
/// nothing reached stdout.
fn refused(args: &[&str]) -> String {
    let out = common::cli::chain(args);
    assert!(!out.status.success(), "{args:?} succeeded");
    assert!(out.stdout.is_empty(), "{args:?} wrote to stdout");
    unwrapped(&String::from_utf8_lossy(&out.stderr))
}

/// A 3-axis machine with straightness errors only, and its values.
fn straight3(dir: &Path) -> (String, String) {
    let m = write(
        dir,
        "straight3.yaml",
        "machine: straight3\nbodies:\n  bed: {}\n  y_saddle: {parent: bed, joint: {type: prismatic, axis: +y, variable: y}, errors: {dx: EXY, dz: EZY}}\n  x_table: {parent: y_saddle, joint: {type: prismatic, axis: +x, variable: x}, errors: {dy: EYX, dz: EZX}}\n  z_head: {parent: bed, offset: [0, 0, 300], joint: {type: prismatic, axis: +z, variable: z}, errors: {dx: EXZ, dy: EYZ}}\nworkpiece: x_table\ntool: z_head\nreliability:\n  tolerance: {px: 0.02}\n  grid: {x: [0, 500], y: [0, 400], z: [0, 300]}\n",
    );
    let v = write(
        dir,
        "v.yaml",
        "machine: straight3\nvalues: {EXY: 0.001, EZY: 0.002, EYX: 0.003, EZX: -0.001, EXZ: 0.0005, EYZ: 0.0015}\n",
    );
    (
        m.to_str().unwrap().to_string(),
        v.to_str().unwrap().to_string(),
    )
}

#[test]
fn bad_input_is_refused_clearly() {
    // A values table that does not cover the travel asked: located, the
    // values file named, nothing extrapolated.
    let err = refused(&export_args(
        "linuxcnc",
        &["--grid", "x=-100,800", "--out", "/tmp/never"],
    ));
    assert!(err.contains("chain::export::out_of_table"), "{err}");
    assert!(
        err.contains("the table of `EXX` (x_axis.csv, column EXX) covers x = 0 to 800, and the export needs x = -100"),
        "{err}"
    );
    assert!(
        err.contains("the values file examples/values/vmc3.yaml does not cover the travel"),
        "{err}"
    );
    assert!(!Path::new("/tmp/never").exists());
    // A controller that does not exist (clap: exit 2, the list).
    let out = common::cli::chain(&export_args("fanuc", &[]));
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains(
            "`fanuc` is not a controller: choose one of grid, beckhoff, linuxcnc, siemens-cec, klipper, linuxcnc-trt, heidenhain, siemens-carr, fanuc-tcp, siemens-thermal, linuxcnc-thermal, beckhoff-thermal, heidenhain-thermal, klipper-thermal"
        ),
        "{err}"
    );
    // A machine without the axes or errors a format needs.
    let dir = scratch("bad-export");
    let (m, v) = straight3(&dir);
    let base = |c: &'static str| -> Vec<String> {
        [
            "export",
            &m,
            "--values",
            &v,
            "--controller",
            c,
            "--format",
            "json",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect()
    };
    let run = |c: &'static str| {
        let a = base(c);
        refused(&a.iter().map(String::as_str).collect::<Vec<_>>())
    };
    let err = run("linuxcnc");
    assert!(err.contains("chain::export::nothing_to_export"), "{err}");
    assert!(err.contains("from its positioning error (the error slot along the joint's own axis), and machine `straight3` has none"), "{err}");
    let err = run("klipper");
    assert!(err.contains("`klipper` writes skew factors from the squareness errors, and machine `straight3` has none"), "{err}");
    let ac = write(&dir, "ac.yaml", "machine: ac_trunnion\nvalues: {}\n");
    let err = refused(&[
        "export",
        "examples/machines/ac_trunnion.yaml",
        "--values",
        ac.to_str().unwrap(),
        "--controller",
        "linuxcnc",
    ]);
    assert!(
        err.contains(
            "`linuxcnc` takes linear axes, each along one of X, Y, Z, and axis `A` is rotary"
        ),
        "{err}"
    );
    // Options the controller does not take.
    let err = refused(&export_args("linuxcnc", &["--axes", "poses.csv"]));
    assert!(
        err.contains("--controller linuxcnc does not take --axes"),
        "{err}"
    );
    let err = refused(&export_args("klipper", &["--format", "csv"]));
    assert!(
        err.contains("--controller klipper does not take --format csv"),
        "{err}"
    );
    let err = refused(&export_args("grid", &["--step", "5"]));
    assert!(
        err.contains("--controller grid does not take --step"),
        "{err}"
    );
    let err = refused(&export_args("linuxcnc", &["--cec-max-points", "400"]));
    assert!(
        err.contains("--controller linuxcnc does not take --cec-max-points"),
        "{err}"
    );
    // A --grid with values between the table's nodes: refused, not dropped.
    let err = refused(&export_args("siemens-cec", &["--grid", "x=0:800:41"]));
    assert!(
        err.contains("the siemens-cec tables sample `x` at 81 nodes every 10 mm from 0 to 800, and it has 41 values"),
        "{err}"
    );
    let err = refused(&export_args("siemens-cec", &["--grid", "x=0,15,800"]));
    assert!(err.contains("and 15 is not one of its nodes"), "{err}");
    // A step that needs more points than the controller takes.
    let err = refused(&export_args(
        "linuxcnc",
        &["--step", "1", "--format", "json"],
    ));
    assert!(err.contains("chain::export::too_many_points"), "{err}");
    let err = refused(&export_args(
        "siemens-cec",
        &["--step", "0", "--format", "json"],
    ));
    assert!(
        err.contains("the table step 0 is not a positive finite length (mm)"),
        "{err}"
    );
    // map --compensated with an option of the other kind.
    let err = refused(&[
        "map",
        MACHINE,
        "--values",
        VALUES,
        "--compensated",
        "grid",
        "--compensation-step",
        "5",
    ]);
    assert!(
        err.contains("--compensated grid does not take --compensation-step"),
        "{err}"
    );
}

/// `examples/export/grid/` is what `chain export --controller grid --out`
/// writes for the example values (the per-axis formats' examples are
/// regenerated by `tests/it/commands/export_controllers.rs`);
/// `CHAIN_REGENERATE=1` rewrites it. The file is also checked for the
/// spec's header and its sign-convention comment lines.
#[test]
fn the_grid_example_is_the_current_export() {
    let dir = scratch("grid-example");
    ok(&export_args(
        "grid",
        &["--out", dir.to_str().unwrap(), "--format", "json"],
    ));
    let name = "vmc3_grid.csv";
    let text = std::fs::read_to_string(dir.join(name)).unwrap();
    assert!(text.contains("\ny,x,z,delta_y,delta_x,delta_z,residual\n"));
    assert!(text.contains("# sign: command q + delta_q instead of q"));
    let committed = example_file("export").join("grid").join(name);
    if std::env::var_os("CHAIN_REGENERATE").is_some() {
        std::fs::create_dir_all(committed.parent().unwrap()).unwrap();
        std::fs::write(&committed, &text).unwrap();
    } else {
        let old = std::fs::read_to_string(&committed).unwrap_or_else(|_| {
            panic!(
                "{} is missing; rerun with CHAIN_REGENERATE=1",
                committed.display()
            )
        });
        assert!(
            old == text,
            "{} is not the current export; rerun with CHAIN_REGENERATE=1",
            committed.display()
        );
    }
}
