//! Direction in values files (docs/values.md, "Direction") and
//! `chain positioning --values-out` (docs/positioning.md): a run written into
//! the axis's positioning error and read back, the approach choice of
//! `chain map`, the repeatability, and every refusal with its location.
//!
//! The expected values are the test's own: the run file read by splitting
//! lines, per-target means and standard deviations by Welford's update
//! (`positioning::welford`), interpolation written out here.

use std::path::{Path, PathBuf};

use chain::core::values::{
    parse_approaches, Approach, Extrapolation, Interpolation, Motion, Sourced, Table, Values,
    ValuesBuilder,
};
use chain::core::ErrorValues;

use crate::commands::positioning::{read_runs, welford};
use crate::common::cli::{fails, ok, ok_json, scratch, unwrapped, write};
use crate::common::example_file;

/// A one-axis machine: the tool on an x slide along `axis`, the positioning
/// error `EXX` in `dx`, a straightness `EYX`, a squareness `S`, and a rotary
/// table `C` with `ECC` in `ez`.
fn machine(axis: &str) -> String {
    format!(
        "machine: m
bodies:
  bed: {{}}
  table: {{parent: bed, joint: {{type: rotary, axis: +z, variable: C}}, errors: {{ez: ECC, dx: EXC}}}}
  x_slide: {{parent: bed, joint: {{type: prismatic, axis: {axis}, variable: x}}, errors: {{dx: EXX, dy: EYX}}, squareness: {{ez: S}}}}
  tool: {{parent: x_slide, offset: [0, 0, -50]}}
workpiece: table
tool: tool
"
    )
}

/// The arguments of `chain positioning RUNS --values-out OUT --machine
/// MACHINE --slot SLOT [--rotary]`.
fn positioning_args(
    runs: &Path,
    out: &Path,
    machine: &Path,
    slot: &str,
    rotary: bool,
) -> Vec<String> {
    let mut args: Vec<String> = ["positioning", "--values-out", "--machine", "--slot"]
        .iter()
        .zip([runs, out, machine, Path::new(slot)])
        .flat_map(|(flag, v)| [flag.to_string(), v.display().to_string()])
        .collect();
    if rotary {
        args.push("--rotary".into());
    }
    args
}

/// `chain positioning RUNS --values-out` into `dir`; the values file.
fn values_out(dir: &Path, runs: &str, machine: &Path, slot: &str, rotary: bool) -> PathBuf {
    let out = dir.join(format!("{slot}.yaml"));
    let args = positioning_args(&example_file(runs), &out, machine, slot, rotary);
    ok(&args.iter().map(String::as_str).collect::<Vec<_>>());
    out
}

#[test]
fn values_out_reads_back_as_the_per_target_means_and_stds() {
    let dir = scratch("read_back");
    let table = read_runs("examples/positioning/x_axis_runs.csv", 1.0);
    for (axis, sign) in [("+x", 1.0), ("-x", -1.0)] {
        let m_path = write(&dir, &format!("m{sign}.yaml"), &machine(axis));
        let m = chain::core::load_file(&m_path).unwrap();
        let path = values_out(&dir, "positioning/x_axis_runs.csv", &m_path, "EXX", false);
        let mut v = Values::read(&path, &m).unwrap_or_else(|e| panic!("{e:?}"));
        let x = m.variables.iter().position(|v| v.name == "x").unwrap();
        let j = m.error_index("EXX").unwrap();
        let mut q = vec![0.0; m.variables.len()];
        let (mut e, mut s) = (vec![0.0; m.errors.len()], vec![0.0; m.errors.len()]);
        for (approach, pick) in [(Approach::Up, 0), (Approach::Down, 1), (Approach::Mean, 2)] {
            v.set_approach(x, approach);
            for (p, up, down) in &table {
                let ((mu, su), (md, sd)) = (welford(up), welford(down));
                let (want, want_s) = match pick {
                    0 => (mu, su),
                    1 => (md, sd),
                    _ => (0.5 * (mu + md), (0.5 * (su * su + sd * sd)).sqrt()),
                };
                q[x] = *p;
                v.values_at(&q, &mut e).unwrap();
                v.repeatability_at(&q, &mut s).unwrap();
                // The slot's value is the deviation times the axis's sign.
                assert!(
                    (e[j] - sign * want).abs() < 1e-12,
                    "{axis} {approach} at {p}: {} vs {}",
                    e[j],
                    sign * want
                );
                assert!(
                    (s[j] - want_s).abs() < 1e-12,
                    "{axis} {approach} std at {p}"
                );
            }
            // Between targets: linear in both directions.
            let (a, b) = (&table[3], &table[4]);
            let t = 0.3;
            q[x] = a.0 + t * (b.0 - a.0);
            v.values_at(&q, &mut e).unwrap();
            let at = |i: usize| {
                let (pa, pb) = (
                    (welford(&a.1).0, welford(&a.2).0),
                    (welford(&b.1).0, welford(&b.2).0),
                );
                let (va, vb) = match i {
                    0 => (pa.0, pb.0),
                    1 => (pa.1, pb.1),
                    _ => (0.5 * (pa.0 + pa.1), 0.5 * (pb.0 + pb.1)),
                };
                va + t * (vb - va)
            };
            assert!((e[j] - sign * at(pick)).abs() < 1e-12);
        }
        // Beyond the run's travel: an error naming the table.
        q[x] = 1000.5;
        let err = v.values_at(&q, &mut e).unwrap_err();
        assert!(err.to_string().contains("EXX"), "{err}");
        // The reversal: the largest |x̄↑ − x̄↓| at a target.
        let r = &v.reversals()[0];
        let (bmax, at) = (table.iter())
            .map(|(p, u, d)| ((welford(u).0 - welford(d).0).abs(), *p))
            .fold((0.0, 0.0), |a, b| if b.0 > a.0 { b } else { a });
        assert!((r.largest - bmax).abs() < 1e-12 && r.at == at, "{r:?}");
        assert_eq!(r.left_out, r.largest * 0.5); // mean (the last set)
    }
}

/// `chain map vmc3 --values VALUES --grid GRID --grid y=0 --grid z=0
/// EXTRA... --format json`.
fn vmc3_map_json(values: &Path, grid: &str, extra: &[&str]) -> serde_json::Value {
    let vmc3 = example_file("machines/vmc3.yaml");
    let mut args = vec![
        "map",
        vmc3.to_str().unwrap(),
        "--values",
        values.to_str().unwrap(),
        "--grid",
        grid,
        "--grid",
        "y=0",
        "--grid",
        "z=0",
        "--format",
        "json",
    ];
    args.extend(extra);
    ok_json(&args)
}

#[test]
fn map_with_each_approach_gives_the_per_target_means() {
    // vmc3's x table moves along −x: the map's px is the deviation itself
    // (the tool relative to the table), whatever the slot's sign.
    let dir = scratch("map_approach");
    let vmc3 = example_file("machines/vmc3.yaml");
    let path = values_out(&dir, "positioning/x_axis_runs.csv", &vmc3, "EXX", false);
    let table = read_runs("examples/positioning/x_axis_runs.csv", 1.0);
    let grid = format!(
        "x={}",
        table
            .iter()
            .map(|t| t.0.to_string())
            .collect::<Vec<_>>()
            .join(",")
    );
    for (flag, pick) in [
        (Some("x=up"), 0),
        (Some("down"), 1),
        (None, 2),
        (Some("mean"), 2),
    ] {
        let extra: Vec<&str> = flag.into_iter().flat_map(|f| ["--approach", f]).collect();
        let doc = vmc3_map_json(&path, &grid, &extra);
        let points = doc["points"].as_array().unwrap();
        assert_eq!(points.len(), table.len());
        for (pt, (p, up, down)) in points.iter().zip(&table) {
            assert_eq!(pt["point"]["x"].as_f64().unwrap(), *p);
            let (mu, md) = (welford(up).0, welford(down).0);
            let want = [mu, md, 0.5 * (mu + md)][pick];
            let px = pt["error"]["px"].as_f64().unwrap();
            assert!((px - want).abs() < 1e-12, "{flag:?} at {p}: {px} vs {want}");
        }
        let r = &doc["reversals"][0];
        assert_eq!(r["name"], "EXX");
        assert_eq!(
            r["approach"],
            ["up", "down", "mean", "mean"][pick + (flag == Some("mean")) as usize]
        );
    }
    // The summary says what the choice leaves out.
    let out = ok(&[
        "map",
        vmc3.to_str().unwrap(),
        "--values",
        path.to_str().unwrap(),
        "--grid",
        "x=0,500",
        "--grid",
        "y=0",
        "--grid",
        "z=0",
        "--approach",
        "up",
    ]);
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(
        text.contains("reversal of EXX along x: up to 4.987 µm between the approach directions (x = 599.9); the map reads `up`, leaving out up to 4.987 µm"),
        "{text}"
    );
}

#[test]
fn a_rotary_run_goes_in_radians_and_arcseconds() {
    let dir = scratch("rotary");
    let m_path = write(&dir, "m.yaml", &machine("+x"));
    let m = chain::core::load_file(&m_path).unwrap();
    let path = values_out(&dir, "positioning/c_axis_runs.csv", &m_path, "ECC", true);
    let table = read_runs("examples/positioning/c_axis_runs.csv", 1.0);
    let v = Values::read(&path, &m).unwrap();
    let c = m.variables.iter().position(|v| v.name == "C").unwrap();
    let j = m.error_index("ECC").unwrap();
    let (mut q, mut e) = (vec![0.0; 2], vec![0.0; m.errors.len()]);
    for (deg, up, down) in &table {
        q[c] = deg.to_radians();
        v.values_at(&q, &mut e).unwrap();
        // Degrees in the run file, radians in the machine.
        let want = (0.5 * (welford(up).0 + welford(down).0)).to_radians();
        assert!((e[j] - want).abs() < 1e-15, "{deg}: {} vs {want}", e[j]);
    }
}

#[test]
fn the_slot_must_be_the_axis_positioning_error() {
    let dir = scratch("slots");
    let m_path = write(&dir, "m.yaml", &machine("+x"));
    let runs = example_file("positioning/x_axis_runs.csv");
    let out = dir.join("v.yaml");
    let run = |slot: &str, rotary: bool| {
        let args = positioning_args(&runs, &out, &m_path, slot, rotary);
        unwrapped(&fails(&args.iter().map(String::as_str).collect::<Vec<_>>()))
    };
    let e = run("EYX", false);
    assert!(e.contains("`EYX` is in the `dy` slot of body `x_slide`, whose joint moves along +x: the positioning error of that axis is its `dx` slot (`EXX` is there)"), "{e}");
    assert!(
        e.contains("chain::positioning::not_along_axis") && e.contains("--slot EYX"),
        "{e}"
    );
    let e = run("EXXX", false);
    assert!(
        e.contains("did you mean `EXX`?") && e.contains("chain::positioning::unknown_slot"),
        "{e}"
    );
    let e = run("S", false);
    assert!(e.contains("chain::positioning::not_a_motion"), "{e}");
    let e = run("ECC", false);
    assert!(
        e.contains("`ECC` is an error of the rotary axis `C`, but the runs are of a linear axis"),
        "{e}"
    );
    let e = run("EXC", false);
    assert!(e.contains("chain::positioning::axis_kind"), "{e}");
    let e = run("EXX", true);
    assert!(
        e.contains("the prismatic axis `x`, but the runs are of a rotary axis"),
        "{e}"
    );
    assert!(!out.exists(), "nothing written on a refusal");
    // --values-out needs --machine and --slot.
    let e = fails(&[
        "positioning",
        runs.to_str().unwrap(),
        "--values-out",
        out.to_str().unwrap(),
    ]);
    assert!(e.contains("--machine") && e.contains("--slot"), "{e}");
}

/// `v` read from `values` for [`machine`]`("+x")` in a fresh directory.
fn read(name: &str, values: &str, csvs: &[(&str, &str)]) -> Result<Values, String> {
    let dir = scratch(name);
    let m = chain::core::load_file(&write(&dir, "m.yaml", &machine("+x"))).unwrap();
    for (f, t) in csvs {
        write(&dir, f, t);
    }
    Values::read(&write(&dir, "v.yaml", values), &m).map_err(|e| {
        let d = e.diagnostics();
        format!(
            "{}:{}:{} {} {}",
            Path::new(d.file()).file_name().unwrap().to_string_lossy(),
            d.first().origin.line,
            d.first().origin.column,
            d.first().origin.key,
            d.first().problem.code()
        ) + &format!(" | {e}")
    })
}

#[test]
fn csv_columns_per_direction() {
    let csv = "x,up,down,s_up,s_down,note\n0,1,3,0.5,0.1,a\n100,2,-2,0.3,0.2,b\n";
    let v = read(
        "csv_dir",
        "machine: m\nunits: {linear: um}\nvalues:\n  EXX: {table: x.csv, column: up, reverse: down, std: s_up, reverse_std: s_down}\n",
        &[("x.csv", csv)],
    )
    .unwrap();
    let mut v = v;
    let mut q = [0.0, 25.0];
    let j = 2; // ECC, EXC, EXX, ...
    assert_eq!(v.errors()[j], "EXX");
    let (mut e, mut s) = ([0.0; 5], [0.0; 5]);
    let x = 1;
    for (a, want, want_s) in [
        (Approach::Up, 1.25, 0.45),
        (Approach::Down, 1.75, 0.125),
        (
            Approach::Mean,
            1.5,
            (0.5f64 * (0.45 * 0.45 + 0.125 * 0.125)).sqrt(),
        ),
    ] {
        v.set_approach(x, a);
        v.values_at(&q, &mut e).unwrap();
        v.repeatability_at(&q, &mut s).unwrap();
        assert!((e[j] - want * 1e-3).abs() < 1e-15, "{a}: {}", e[j]);
        assert!((s[j] - want_s * 1e-3).abs() < 1e-15, "{a}: {}", s[j]);
        assert_eq!(v.approaches()[x], a);
    }
    q[1] = 100.0;
    v.set_approach(x, Approach::Mean);
    v.values_at(&q, &mut e).unwrap();
    assert_eq!(e[j], 0.0);
    let entry = &v.entries()[0];
    let json = serde_json::to_value(entry).unwrap();
    assert_eq!(json["reverse"], "x.csv, column down");
    assert_eq!(json["std"], "x.csv, column s_up");
    assert_eq!(json["reverse_std"], "x.csv, column s_down");
    // One `std` column serves both directions.
    let v = read(
        "csv_one_std",
        "machine: m\nvalues:\n  EXX: {table: x.csv, column: up, reverse: down, std: s_up}\n",
        &[("x.csv", csv)],
    )
    .unwrap();
    v.repeatability_at(&[0.0, 0.0], &mut s).unwrap();
    assert_eq!(s[j], 0.5);
    assert!(v.has_repeatability());
}

#[test]
fn the_builder_takes_a_motion() {
    let dir = scratch("builder");
    let m = chain::core::load_file(&write(&dir, "m.yaml", &machine("+x"))).unwrap();
    let t =
        |p: Vec<(f64, f64)>| Table::new(p, Interpolation::Linear, Extrapolation::Error).unwrap();
    let src = |table, s: &str| Sourced {
        table,
        source: s.into(),
    };
    let mut b = ValuesBuilder::new(&m);
    let motion = Motion {
        up: src(t(vec![(0.0, 1e-3), (10.0, 2e-3)]), "up"),
        down: Some(src(t(vec![(0.0, -1e-3), (20.0, 0.0)]), "down")),
        std_up: Some(src(t(vec![(0.0, 2e-4), (10.0, 2e-4)]), "su")),
        std_down: Some(src(t(vec![(0.0, 1e-4), (10.0, 1e-4)]), "s")),
    };
    b.motion("EXX", motion.clone()).unwrap();
    let mut v = b.build();
    let mut e = [0.0; 5];
    v.values_at(&[0.0, 5.0], &mut e).unwrap();
    assert!((e[2] - 0.5 * (1.5e-3 - 0.75e-3)).abs() < 1e-18);
    // The mean reads both tables: outside the shorter one is an error.
    let err = v.values_at(&[0.0, 15.0], &mut e).unwrap_err();
    assert_eq!((err.lo, err.hi), (0.0, 10.0));
    v.set_approach(1, Approach::Down);
    v.values_at(&[0.0, 15.0], &mut e).unwrap();
    assert!((e[2] + 0.25e-3).abs() < 1e-18);
    // Read downwards, the range is the reverse table's alone.
    let err = v.values_at(&[0.0, 25.0], &mut e).unwrap_err();
    assert_eq!((err.lo, err.hi), (0.0, 20.0));
    // A reverse std without a reverse direction; a negative std.
    let mut b = ValuesBuilder::new(&m);
    let no_std = Motion {
        std_up: None,
        ..motion.clone()
    };
    assert!(b
        .motion("EXX", no_std)
        .unwrap_err()
        .to_string()
        .contains("none for its main direction"));
    let bad = Motion {
        down: None,
        ..motion.clone()
    };
    assert!(b
        .motion("EXX", bad)
        .unwrap_err()
        .to_string()
        .contains("no reverse direction"));
    let neg = Motion {
        std_up: Some(src(t(vec![(0.0, 1e-4), (10.0, -1e-4)]), "s")),
        ..motion
    };
    let e = b.motion("EXX", neg).unwrap_err().to_string();
    assert!(e.contains("must be ≥ 0: point 1 is -0.0001"), "{e}");
}

#[test]
fn approach_choices() {
    assert_eq!(
        parse_approaches("x=up, y=down").unwrap(),
        vec![
            (Some("x".into()), Approach::Up),
            (Some("y".into()), Approach::Down)
        ]
    );
    assert_eq!(
        parse_approaches("mean").unwrap(),
        vec![(None, Approach::Mean)]
    );
    assert!(parse_approaches("x=sideways")
        .unwrap_err()
        .contains("`sideways` is not an approach direction"));
    assert!(parse_approaches("=up").is_err());
    let mut v = read(
        "choices",
        "machine: m\nvalues:\n  EXX: {points: [[0, 0], [1, 1]], reverse_points: [[0, 1], [1, 2]]}\n  EXC: {points: [[0, 0], [1, 1]]}\n",
        &[],
    )
    .unwrap();
    v.choose_approach(&parse_approaches("x=down").unwrap())
        .unwrap();
    assert_eq!(v.approaches(), &[Approach::Mean, Approach::Down]);
    let e = v
        .choose_approach(&parse_approaches("C=up").unwrap())
        .unwrap_err();
    assert!(
        e.to_string()
            .contains("no table along `C` has a reverse direction"),
        "{e}"
    );
    let e = v
        .choose_approach(&parse_approaches("xx=up").unwrap())
        .unwrap_err();
    assert!(
        e.to_string().contains("`xx` is not an axis variable"),
        "{e}"
    );
    let mut plain = read(
        "plain",
        "machine: m\nvalues:\n  EXC: {points: [[0, 0], [1, 1]]}\n",
        &[],
    )
    .unwrap();
    let e = plain.choose_approach(&[(None, Approach::Up)]).unwrap_err();
    assert!(
        e.to_string()
            .contains("no table of these values has a reverse direction"),
        "{e}"
    );
    assert!(plain.reversals().is_empty() && !plain.has_repeatability());
}

/// `(scratch name, values file, CSV files, the expected location and code)`.
type Case<'a> = (&'a str, &'a str, &'a [(&'a str, &'a str)], &'a str);

#[test]
fn direction_refusals_are_located() {
    let cases: &[Case] = &[
        (
            "rev_std_alone",
            "machine: m\nvalues:\n  EXX: {points: [[0, 0], [1, 1]], reverse_std_points: [[0, 0], [1, 1]]}\n",
            &[],
            "v.yaml:3:35 values.EXX.reverse_std_points chain::values::reverse_std_without_reverse",
        ),
        (
            "rev_std_without_std",
            "machine: m\nvalues:\n  EXX: {points: [[0, 0], [1, 1]], reverse_points: [[0, 0], [1, 1]], reverse_std_points: [[0, 0], [1, 1]]}\n",
            &[],
            "v.yaml:3:69 values.EXX.reverse_std_points chain::values::reverse_std_without_std",
        ),
        (
            "neg_std_points",
            "machine: m\nvalues:\n  EXX: {points: [[0, 0], [1, 1]], std_points: [[0, 0], [1, -1]]}\n",
            &[],
            "v.yaml:3:56 values.EXX.std_points[1] chain::values::negative_std",
        ),
        (
            "neg_std_csv",
            "machine: m\nvalues:\n  EXX: {table: x.csv, column: up, std: s}\n",
            &[("x.csv", "x,up,s\n0,0,0.1\n1,1,-0.1\n")],
            "x.csv:3:5 s chain::values::negative_std",
        ),
        (
            "reverse_in_points",
            "machine: m\nvalues:\n  EXX: {points: [[0, 0], [1, 1]], reverse: down}\n",
            &[],
            "v.yaml:3:35 values.EXX.reverse chain::values::key_not_for_points",
        ),
        (
            "reverse_points_in_table",
            "machine: m\nvalues:\n  EXX: {table: x.csv, reverse_points: [[0, 0], [1, 1]]}\n",
            &[("x.csv", "x,EXX\n0,0\n1,1\n")],
            "v.yaml:3:23 values.EXX.reverse_points chain::values::key_not_for_csv",
        ),
        (
            "std_number_on_table",
            "machine: m\nvalues:\n  EXX: {table: x.csv, std: 0.1}\n",
            &[("x.csv", "x,EXX\n0,0\n1,1\n")],
            "v.yaml:3:28 values.EXX.std chain::values::key_not_for_table",
        ),
        (
            "points_and_table",
            "machine: m\nvalues:\n  EXX: {points: [[0, 0], [1, 1]], table: x.csv}\n",
            &[],
            "v.yaml:3:35 values.EXX.table chain::conflicting_keys",
        ),
        (
            "reverse_column_missing",
            "machine: m\nvalues:\n  EXX: {table: x.csv, reverse: dwon}\n",
            &[("x.csv", "x,EXX,down\n0,0,0\n1,1,1\n")],
            "v.yaml:3:32 values.EXX.reverse chain::values::csv_no_column",
        ),
        (
            "reverse_too_few",
            "machine: m\nvalues:\n  EXX: {points: [[0, 0], [1, 1]], reverse_points: [[0, 0]]}\n",
            &[],
            "v.yaml:3:35 values.EXX.reverse_points chain::values::too_few_points",
        ),
        (
            "reverse_on_constant",
            "machine: m\nvalues:\n  EXX: {value: 1, reverse_points: [[0, 0], [1, 1]]}\n",
            &[],
            "v.yaml:3:19 values.EXX.reverse_points chain::values::key_not_for_constant",
        ),
    ];
    for (name, values, csvs, want) in cases {
        let got = read(name, values, csvs)
            .err()
            .unwrap_or_else(|| panic!("{name}: accepted"));
        assert!(got.starts_with(want), "{name}: {got}");
    }
}

/// The triplets LinuxCNC reads from a `COMP_FILE`: lines of three numbers
/// until the first line that is not (`usrmotLoadComp`).
fn comp_triplets(text: &str) -> Vec<[f64; 3]> {
    text.lines()
        .map_while(|line| {
            let f: Vec<f64> = line
                .split_whitespace()
                .map_while(|t| t.parse().ok())
                .collect();
            <[f64; 3]>::try_from(f).ok()
        })
        .collect()
}

/// LinuxCNC's reading of one column at `x`: linear between entries, the end
/// values held (`compute_screw_comp`).
fn comp_at(rows: &[[f64; 3]], column: usize, x: f64) -> f64 {
    if x <= rows[0][0] {
        return rows[0][column];
    }
    let k = rows
        .iter()
        .position(|r| r[0] >= x)
        .unwrap_or(rows.len() - 1);
    let (a, b) = (rows[k - 1], rows[k]);
    a[column] + (b[column] - a[column]) * (x - a[0]) / (b[0] - a[0])
}

#[test]
fn linuxcnc_forward_and_reverse_leave_only_the_scatter() {
    let dir = scratch("linuxcnc");
    let vmc3 = example_file("machines/vmc3.yaml");
    let values = values_out(&dir, "positioning/x_axis_runs.csv", &vmc3, "EXX", false);
    let out = dir.join("comp");
    let doc = ok_json(&[
        "export",
        vmc3.to_str().unwrap(),
        "--values",
        values.to_str().unwrap(),
        "--controller",
        "linuxcnc",
        "--out",
        out.to_str().unwrap(),
        "--format",
        "json",
    ]);
    let text = std::fs::read_to_string(out.join("x.comp")).unwrap();
    let rows = comp_triplets(&text);
    assert!(text.contains(
        "# directions: forward = -u approached moving up, reverse = -u approached moving down"
    ));
    // The run file read by this test, every run's deviation at every target
    // inside the travel (vmc3's x: 0 to 800 mm).
    let table = read_runs("examples/positioning/x_axis_runs.csv", 1.0);
    let mut scatter = [Vec::new(), Vec::new()];
    for (p, up, down) in table.iter().filter(|t| t.0 <= 800.0) {
        // The targets are entries of the table (written exactly).
        assert!(rows.iter().any(|r| r[0] == *p), "no entry at {p}");
        for (d, runs, column) in [(0, up, 1), (1, down, 2)] {
            let mean = welford(runs).0;
            for x in runs {
                // LinuxCNC adds the trim of the direction it moves in: the
                // position reached is off by the run's deviation plus it.
                let left = x + comp_at(&rows, column, *p);
                assert!(
                    (left - (x - mean)).abs() < 1e-12,
                    "{p} {d}: {left} vs {}",
                    x - mean
                );
                scatter[d].push(left);
            }
        }
    }
    // What is left has zero mean per direction: the run-to-run scatter.
    for s in &scatter {
        assert!(s.iter().sum::<f64>().abs() / (s.len() as f64) < 1e-12);
    }
    // The report says which it did and the BACKLASH of the mean reversal:
    // the mean of (x̄↑ − x̄↓) over the table's entries, negated.
    let d = doc["directions"]
        .as_array()
        .unwrap()
        .iter()
        .find(|d| d["variable"] == "x")
        .unwrap();
    assert_eq!(d["bidirectional"], true);
    let mean_reversal = rows.iter().map(|r| r[2] - r[1]).sum::<f64>() / rows.len() as f64;
    assert!((d["mean_reversal"].as_f64().unwrap() - mean_reversal).abs() < 1e-15);
    assert_eq!(
        d["backlash"].as_f64().unwrap(),
        -d["mean_reversal"].as_f64().unwrap()
    );
    // A table without a reverse direction has no entry (its file and
    // report are as before).
    assert_eq!(doc["directions"].as_array().unwrap().len(), 1);
    let readme = std::fs::read_to_string(out.join("linuxcnc-README.txt")).unwrap();
    assert!(readme.contains("BACKLASH = "), "{readme}");
    // `map --compensated linuxcnc --approach up`: the forward column removes
    // the up direction at the targets, to the second order of the errors
    // (the trim is looked up at the commanded position: the table's slope,
    // ≤ 4e-5, times the error, ≤ 9 µm).
    let grid = format!(
        "x={}",
        table
            .iter()
            .filter(|t| t.0 <= 800.0)
            .map(|t| t.0.to_string())
            .collect::<Vec<_>>()
            .join(",")
    );
    for approach in ["up", "down", "mean"] {
        let map = vmc3_map_json(
            &values,
            &grid,
            &["--approach", approach, "--compensated", "linuxcnc"],
        );
        let before = map["summary"]["volumetric"]["max"].as_f64().unwrap();
        let after = map["compensated"]["summary"]["volumetric"]["max"]
            .as_f64()
            .unwrap();
        assert!(
            before > 3e-3 && after < 4e-7,
            "{approach}: {before} -> {after}"
        );
    }
}

/// A one-axis machine with a reliability section: `px` within `tol` (upper)
/// at the targets.
fn one_axis(tol: f64, targets: &[f64]) -> String {
    let grid: Vec<String> = targets.iter().map(|t| t.to_string()).collect();
    format!(
        "machine: m
bodies:
  bed: {{}}
  x_slide: {{parent: bed, joint: {{type: prismatic, axis: +x, variable: x}}, errors: {{dx: EXX}}}}
workpiece: bed
tool: x_slide
reliability:
  tolerance: {{px: {tol}}}
  sided: upper
  grid:
    x: [{}]
",
        grid.join(", ")
    )
}

#[test]
fn reliability_with_the_repeatability_matches_resampling_the_runs() {
    // Runs of our own making: 400 per direction at three targets, normal
    // about a mean per direction with a spread per target (Box-Muller from
    // the tests' generator).
    let targets = [0.0, 250.0, 500.0];
    let (mean_up, mean_down) = ([0.0020, 0.0026, 0.0012], [-0.0004, 0.0003, -0.0010]);
    let (s_up, s_down) = ([0.0008, 0.0005, 0.0011], [0.0006, 0.0009, 0.0004]);
    let n = 400;
    let mut rng = crate::common::Rng::new(2302);
    let mut normal = move || {
        let (u, v) = (1.0 - rng.unit(), rng.unit());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    };
    let mut csv = String::from("target,direction,run,deviation\n");
    let mut runs = vec![(Vec::new(), Vec::new()); 3];
    for j in 1..=n {
        for (i, p) in targets.iter().enumerate() {
            let (u, d) = (
                mean_up[i] + s_up[i] * normal(),
                mean_down[i] + s_down[i] * normal(),
            );
            csv.push_str(&format!("{p},up,{j},{u:?}\n{p},down,{j},{d:?}\n"));
            runs[i].0.push(u);
            runs[i].1.push(d);
        }
    }
    let dir = scratch("repeatability");
    let tol = 0.003;
    let machine = write(&dir, "m.yaml", &one_axis(tol, &targets));
    let runs_file = write(&dir, "runs.csv", &csv);
    let values = dir.join("v.yaml");
    let args = positioning_args(&runs_file, &values, &machine, "EXX", false);
    ok(&args.iter().map(String::as_str).collect::<Vec<_>>());
    let mut rng = crate::common::Rng::new(7);
    for (approach, pick) in [("up", 0), ("down", 1)] {
        let doc = ok_json(&[
            "reliability",
            machine.to_str().unwrap(),
            "--values",
            values.to_str().unwrap(),
            "--approach",
            approach,
            "--format",
            "json",
        ]);
        for (i, r) in doc["results"].as_array().unwrap().iter().enumerate() {
            let got = r["reliability"].as_f64().unwrap();
            let x = if pick == 0 { &runs[i].0 } else { &runs[i].1 };
            // FORM is exact here: Φ((tol − x̄)/s) with the runs' own mean
            // and n − 1 standard deviation.
            let (m, s) = welford(x);
            let closed = crate::common::normal_cdf((tol - m) / s);
            assert!(
                (got - closed).abs() < 1e-12,
                "{approach} {i}: {got} vs {closed}"
            );
            // A Monte Carlo that resamples the runs: 200,000 draws with
            // replacement, the fraction within the tolerance. Its spread
            // about chain's normal model: the runs' own binomial error
            // (400 runs) and the draws'.
            let draws = 200_000;
            let inside = (0..draws)
                .filter(|_| x[(rng.unit() * x.len() as f64) as usize] <= tol)
                .count() as f64
                / draws as f64;
            let se = (got * (1.0 - got) / x.len() as f64).sqrt()
                + (got * (1.0 - got) / draws as f64).sqrt();
            assert!(
                (inside - got).abs() <= 4.0 * se,
                "{approach} at {}: resampled {inside} vs {got} (se {se})",
                targets[i]
            );
        }
    }
    // The mean approach: the mean of the two means, the pooled spread.
    let doc = ok_json(&[
        "reliability",
        machine.to_str().unwrap(),
        "--values",
        values.to_str().unwrap(),
        "--format",
        "json",
    ]);
    for (i, r) in doc["results"].as_array().unwrap().iter().enumerate() {
        let ((mu, su), (md, sd)) = (welford(&runs[i].0), welford(&runs[i].1));
        let closed =
            crate::common::normal_cdf((tol - 0.5 * (mu + md)) / (0.5 * (su * su + sd * sd)).sqrt());
        let got = r["reliability"].as_f64().unwrap();
        assert!((got - closed).abs() < 1e-12, "mean {i}: {got} vs {closed}");
    }
    assert_eq!(doc["posterior"]["tables"][0], "EXX");
    // Between the targets the mean and the spread are interpolated.
    let doc = ok_json(&[
        "reliability",
        machine.to_str().unwrap(),
        "--values",
        values.to_str().unwrap(),
        "--approach",
        "up",
        "--grid",
        "x=100",
        "--format",
        "json",
    ]);
    let t = 100.0 / 250.0;
    let ((m0, s0), (m1, s1)) = (welford(&runs[0].0), welford(&runs[1].0));
    let closed = crate::common::normal_cdf((tol - (m0 + t * (m1 - m0))) / (s0 + t * (s1 - s0)));
    let got = doc["results"][0]["reliability"].as_f64().unwrap();
    assert!((got - closed).abs() < 1e-12, "between: {got} vs {closed}");
    // Outside the run's travel: refused, naming the values file and table.
    let e = unwrapped(&fails(&[
        "reliability",
        machine.to_str().unwrap(),
        "--values",
        values.to_str().unwrap(),
        "--grid",
        "x=600",
    ]));
    assert!(
        e.contains("chain::posterior::table_point")
            && e.contains("x = 600 is outside the table of `EXX`"),
        "{e}"
    );
    // --at cannot take inputs that vary by point; a one-point grid can.
    let e = unwrapped(&fails(&[
        "sensitivity",
        machine.to_str().unwrap(),
        "--values",
        values.to_str().unwrap(),
        "--at",
        "x=100",
    ]));
    assert!(e.contains("one-point grid"), "{e}");
    // The whole-machine acceptance needs one set of inputs.
    let e = unwrapped(&fails(&[
        "reliability",
        machine.to_str().unwrap(),
        "--values",
        values.to_str().unwrap(),
        "--acceptance",
    ]));
    assert!(
        e.contains("acceptance: the inputs differ from point to point"),
        "{e}"
    );
    // Geometric sensitivity has no tables to read.
    let e = unwrapped(&fails(&[
        "sensitivity",
        machine.to_str().unwrap(),
        "--kind",
        "geometric",
        "--values",
        "linear=0.001",
        "--approach",
        "up",
    ]));
    assert!(
        e.contains("--kind geometric does not take --approach"),
        "{e}"
    );
}
