//! `chain positioning` (spec `positioning.md`, ISO 230-2:2014): every
//! statistic against the test's own computation, written differently from
//! chain's (one-pass Welford means and variances, the ranges by sorting, the
//! run file read by splitting lines), on runs with known answers and on the
//! examples, to 1e-12 mm; the rotary unit; `--k`; the formats and the plot;
//! every refusal with its file, line and column.

use chain::core::measured::positioning::{self, AxisKind, Coverage, Runs};
use serde_json::Value;

use crate::common::cli::{fails, ok, ok_json, ok_stdout, scratch, scratch_file, unwrapped};

/// Per target: `(P_i, x↑ per run, x↓ per run)`.
pub(crate) type Table = Vec<(f64, Vec<f64>, Vec<f64>)>;

/// Mean and `n − 1` standard deviation by Welford's one-pass update (chain
/// uses a sum, then a second pass about the mean).
pub(crate) fn welford(x: &[f64]) -> (f64, f64) {
    let (mut mean, mut m2) = (0.0, 0.0);
    for (i, &v) in x.iter().enumerate() {
        let d = v - mean;
        mean += d / (i + 1) as f64;
        m2 += d * (v - mean);
    }
    (mean, (m2 / (x.len() - 1) as f64).sqrt())
}

/// `max − min` by sorting.
fn spread(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() - 1] - v[0]
}

/// The test's own ISO 230-2 evaluation: the spec's keys as JSON.
fn independent(table: &Table, k: f64) -> Value {
    let mut targets = Vec::new();
    let (mut mu, mut md, mut m, mut b) = (vec![], vec![], vec![], vec![]);
    let (mut hi_u, mut lo_u, mut hi_d, mut lo_d) = (vec![], vec![], vec![], vec![]);
    let (mut ru, mut rd, mut r) = (vec![], vec![], vec![]);
    for (p, up, down) in table {
        let (xu, su) = welford(up);
        let (xd, sd) = welford(down);
        let bi = xu - xd;
        let riu = 4.0 * su * k / 2.0;
        let rid = 4.0 * sd * k / 2.0;
        let ri = [k * (su + sd) + bi.abs(), riu, rid]
            .into_iter()
            .fold(f64::MIN, f64::max);
        targets.push(serde_json::json!({
            "target": p, "mean_up": xu, "mean_down": xd, "mean": 0.5 * (xu + xd),
            "reversal": bi, "s_up": su, "s_down": sd, "repeatability_up": riu,
            "repeatability_down": rid, "repeatability": ri,
        }));
        mu.push(xu);
        md.push(xd);
        m.push(0.5 * (xu + xd));
        b.push(bi);
        hi_u.push(xu + k * su);
        lo_u.push(xu - k * su);
        hi_d.push(xd + k * sd);
        lo_d.push(xd - k * sd);
        ru.push(riu);
        rd.push(rid);
        r.push(ri);
    }
    let sorted = |v: &[f64]| {
        let mut v = v.to_vec();
        v.sort_by(f64::total_cmp);
        v
    };
    let max = |v: &[f64]| sorted(v)[v.len() - 1];
    let min = |v: &[f64]| sorted(v)[0];
    let both_hi: Vec<f64> = hi_u.iter().chain(&hi_d).copied().collect();
    let both_lo: Vec<f64> = lo_u.iter().chain(&lo_d).copied().collect();
    let axis = serde_json::json!({
        "A": max(&both_hi) - min(&both_lo),
        "A_up": max(&hi_u) - min(&lo_u),
        "A_down": max(&hi_d) - min(&lo_d),
        "E": spread(mu.iter().chain(&md).copied().collect()),
        "E_up": spread(mu.clone()),
        "E_down": spread(md.clone()),
        "M": spread(m.clone()),
        "R": max(&r),
        "R_up": max(&ru),
        "R_down": max(&rd),
        "B": max(&b.iter().map(|v| v.abs()).collect::<Vec<_>>()),
        "B_mean": b.iter().sum::<f64>() / b.len() as f64,
    });
    serde_json::json!({"targets": targets, "axis": axis})
}

/// Every number of `want` (targets and axis) equals `got`'s within `tol`.
#[track_caller]
fn assert_close(got: &Value, want: &Value, tol: f64) {
    let wt = want["targets"].as_array().unwrap();
    let gt = got["targets"].as_array().unwrap();
    assert_eq!(wt.len(), gt.len());
    for (w, g) in wt.iter().zip(gt) {
        for (key, wv) in w.as_object().unwrap() {
            let (a, b) = (g[key].as_f64().unwrap(), wv.as_f64().unwrap());
            assert!(
                (a - b).abs() <= tol,
                "target {}: {key} = {a}, want {b}",
                w["target"]
            );
        }
    }
    for (key, wv) in want["axis"].as_object().unwrap() {
        let (a, b) = (got["axis"][key].as_f64().unwrap(), wv.as_f64().unwrap());
        assert!((a - b).abs() <= tol, "axis {key} = {a}, want {b}");
    }
}

/// Runs with known answers: `x_ij↑ = a_i + b_i·d_j`, `x_ij↓ = c_i + e_i·d_j`
/// with `d = (−2, −1, 0, 1, 2)` (mean 0, `Σd² = 10`), so `x̄↑ = a_i` and
/// `s↑ = |b_i|·√(10/4)`.
fn constructed() -> (Table, Vec<[f64; 4]>) {
    let d = [-2.0, -1.0, 0.0, 1.0, 2.0];
    // (a, b, c, e) per target, in mm: a lead error, a reversal that changes
    // sign, and spreads that differ per direction.
    let coef = vec![
        [0.0010, 0.0002, -0.0020, 0.0001],
        [0.0030, 0.0001, 0.0010, 0.0003],
        [0.0045, 0.0004, 0.0050, 0.0002],
        [0.0020, 0.0003, -0.0005, 0.0001],
        [-0.0010, 0.0001, -0.0040, 0.0005],
    ];
    let targets = [0.0, 98.7, 201.3, 299.2, 400.0];
    let table = targets
        .iter()
        .zip(&coef)
        .map(|(&p, c)| {
            (
                p,
                d.iter().map(|dj| c[0] + c[1] * dj).collect(),
                d.iter().map(|dj| c[2] + c[3] * dj).collect(),
            )
        })
        .collect();
    (table, coef)
}

#[test]
fn known_answers_in_closed_form() {
    let (table, coef) = constructed();
    let runs = Runs::new(AxisKind::Linear, table.clone()).unwrap();
    let doc = serde_json::to_value(positioning::evaluate(&runs, Coverage::ISO)).unwrap();
    let root = (10.0f64 / 4.0).sqrt();
    for (t, c) in doc["targets"].as_array().unwrap().iter().zip(&coef) {
        let f = |k: &str| t[k].as_f64().unwrap();
        let (s_up, s_down, b) = (c[1] * root, c[3] * root, c[0] - c[2]);
        let close = |a: f64, b: f64| assert!((a - b).abs() < 1e-15, "{a} vs {b}");
        close(f("mean_up"), c[0]);
        close(f("mean_down"), c[2]);
        close(f("reversal"), b);
        close(f("s_up"), s_up);
        close(f("s_down"), s_down);
        close(f("repeatability_up"), 4.0 * s_up);
        close(
            f("repeatability"),
            (2.0 * s_up + 2.0 * s_down + b.abs())
                .max(4.0 * s_up)
                .max(4.0 * s_down),
        );
    }
    // Axis values by hand from the coefficients above (mm):
    // means ↑ 0.0010 0.0030 0.0045 0.0020 -0.0010, ↓ -0.0020 0.0010 0.0050 -0.0005 -0.0040.
    let axis = &doc["axis"];
    let close = |k: &str, v: f64| {
        let a = axis[k].as_f64().unwrap();
        assert!((a - v).abs() < 1e-15, "{k} = {a}, want {v}");
    };
    close("E_up", 0.0045 - -0.0010);
    close("E_down", 0.0050 - -0.0040);
    close("E", 0.0050 - -0.0040);
    close("M", 0.00475 - -0.0025);
    // B_i = 0.0030, 0.0020, -0.0005, 0.0025, 0.0030.
    close("B", 0.0030);
    close("B_mean", (0.0030 + 0.0020 - 0.0005 + 0.0025 + 0.0030) / 5.0);
    // A↑: max(x̄↑ + 2s↑) at target 3 (0.0045 + 0.0008·√2.5), min(x̄↑ − 2s↑)
    // at target 5 (−0.0010 − 0.0002·√2.5).
    close("A_up", 0.0045 + 0.0008 * root - (-0.0010 - 0.0002 * root));
    close("A_down", 0.0050 + 0.0004 * root - (-0.0040 - 0.0010 * root));
    // A: the largest upper end is the ↑ one of target 3, the lowest lower
    // end the ↓ one of target 5.
    close("A", 0.0045 + 0.0008 * root - (-0.0040 - 0.0010 * root));
    assert_close(&doc, &independent(&table, 2.0), 1e-15);
}

/// The test's own reading of a run file: split lines and commas.
pub(crate) fn read_runs(path: &str, scale: f64) -> Table {
    let text = std::fs::read_to_string(crate::common::root().join(path)).unwrap();
    let mut lines = text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty());
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let measured = header[3] == "measured";
    let mut rows: Vec<(f64, bool, usize, f64)> = lines
        .map(|l| {
            let c: Vec<&str> = l.split(',').collect();
            let p: f64 = c[0].parse().unwrap();
            let v: f64 = c[3].parse().unwrap();
            (
                p,
                c[1] == "up",
                c[2].parse().unwrap(),
                if measured { v - p } else { v },
            )
        })
        .collect();
    rows.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.2.cmp(&b.2)));
    let mut table: Table = Vec::new();
    for (p, up, _, x) in rows {
        if table.last().map(|t| t.0) != Some(p) {
            table.push((p, vec![], vec![]));
        }
        let t = table.last_mut().unwrap();
        if up {
            t.1.push(x * scale)
        } else {
            t.2.push(x * scale)
        }
    }
    table
}

#[test]
fn the_examples_against_the_independent_evaluation() {
    let x = ok_json(&[
        "positioning",
        "examples/positioning/x_axis_runs.csv",
        "--format",
        "json",
    ]);
    assert_eq!(
        (x["k"].clone(), x["runs"].clone(), x["unit"].clone()),
        (2.into(), 5.into(), "mm".into())
    );
    assert_eq!(x["targets"].as_array().unwrap().len(), 11);
    assert_close(
        &x,
        &independent(&read_runs("examples/positioning/x_axis_runs.csv", 1.0), 2.0),
        1e-12,
    );
    // The rotary table: degrees in, arcseconds out (tolerance: 1e-12 mm
    // scaled as the statistics are, 3600 × 1e-12).
    let c = ok_json(&[
        "positioning",
        "examples/positioning/c_axis_runs.csv",
        "--rotary",
        "--format",
        "json",
    ]);
    assert_eq!(
        (c["unit"].clone(), c["target_unit"].clone()),
        ("arcsec".into(), "deg".into())
    );
    assert_close(
        &c,
        &independent(
            &read_runs("examples/positioning/c_axis_runs.csv", 3600.0),
            2.0,
        ),
        3.6e-9,
    );
    // The ±3s variant (the 1988 edition): R_i↑ = 6 s.
    let x3 = ok_json(&[
        "positioning",
        "examples/positioning/x_axis_runs.csv",
        "--k",
        "3",
        "--format",
        "json",
    ]);
    assert_eq!(x3["k"], 3);
    assert_close(
        &x3,
        &independent(&read_runs("examples/positioning/x_axis_runs.csv", 1.0), 3.0),
        1e-12,
    );
    let t = &x3["targets"][4];
    assert!(
        (t["repeatability_up"].as_f64().unwrap() - 6.0 * t["s_up"].as_f64().unwrap()).abs() < 1e-15
    );
}

#[test]
fn the_points_are_the_runs_deviations() {
    let x = ok_json(&[
        "positioning",
        "examples/positioning/x_axis_runs.csv",
        "--format",
        "json",
    ]);
    let table = read_runs("examples/positioning/x_axis_runs.csv", 1.0);
    let points = x["points"].as_array().unwrap();
    assert_eq!(points.len(), 10);
    for p in points {
        let j = p["run"].as_u64().unwrap() as usize - 1;
        for (i, v) in p["deviations"].as_array().unwrap().iter().enumerate() {
            let want = if p["direction"] == "up" {
                table[i].1[j]
            } else {
                table[i].2[j]
            };
            assert!((v.as_f64().unwrap() - want).abs() < 1e-12);
        }
    }
}

#[test]
fn table_csv_and_plot() {
    let table = ok_stdout(&["positioning", "examples/positioning/x_axis_runs.csv"]);
    assert!(
        table.contains("11 targets, 5 runs per direction, k = 2; deviations in mm"),
        "{table}"
    );
    assert!(table.contains("A  accuracy"), "{table}");
    let x = ok_json(&[
        "positioning",
        "examples/positioning/x_axis_runs.csv",
        "--format",
        "json",
    ]);
    let a = x["axis"]["A"].as_f64().unwrap();
    assert!(
        table.contains(&format!("{a:.6}")),
        "A = {a:.6} not in\n{table}"
    );
    let csv = ok_stdout(&[
        "positioning",
        "examples/positioning/x_axis_runs.csv",
        "--format",
        "csv",
    ]);
    let mut lines = csv.lines();
    assert_eq!(
        lines.next().unwrap(),
        "target,mean_up,mean_down,mean,reversal,s_up,s_down,repeatability_up,repeatability_down,repeatability"
    );
    let first: Vec<f64> = lines
        .next()
        .unwrap()
        .split(',')
        .map(|c| c.parse().unwrap())
        .collect();
    assert_eq!(first[1], x["targets"][0]["mean_up"].as_f64().unwrap());
    assert_eq!(csv.lines().count(), 12);
    let dir = scratch("plot");
    let out = ok(&[
        "positioning",
        "examples/positioning/c_axis_runs.csv",
        "--rotary",
        "--plot",
        dir.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    for f in [
        "positioning.png",
        "positioning.svg",
        "positioning_reversal.png",
        "positioning_reversal.svg",
    ] {
        let path = dir.join(f);
        assert!(err.contains(&path.display().to_string()), "{err}");
        let bytes = std::fs::read(&path).unwrap();
        if f.ends_with(".png") {
            assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
        } else {
            assert!(String::from_utf8(bytes).unwrap().contains("arcsec"));
        }
    }
}

#[test]
fn refusals_name_file_line_and_column() {
    let h = "target,direction,run,deviation\n";
    let base = "0,up,1,0\n0,up,2,0.001\n0,down,1,0\n0,down,2,0.002\n";
    let cases: Vec<(&str, String, &str)> = vec![
        (
            "twice.csv",
            format!("{h}{base}5,up,1,0\n5,up,2,0\n5,down,1,0\n5,down,1,0\n"),
            "twice.csv:9:8",
        ),
        (
            "unequal.csv",
            format!("{h}{base}5,up,1,0\n5,up,2,0\n5,down,1,0\n"),
            "unequal.csv:6:1",
        ),
        ("one_target.csv", format!("{h}{base}"), "one_target.csv:2:1"),
        (
            "one_run.csv",
            format!("{h}0,up,1,0\n0,down,1,0\n5,up,1,0\n5,down,1,0\n"),
            "one_run.csv:2:6",
        ),
        ("nan.csv", format!("{h}{base}5,up,1,NaN\n"), "nan.csv:6:8"),
        (
            "empty_cell.csv",
            format!("{h}{base}5,up,,0\n"),
            "empty_cell.csv:6:6",
        ),
        (
            "direction.csv",
            format!("{h}{base}5,left,1,0\n"),
            "direction.csv:6:3",
        ),
        (
            "column.csv",
            "target,direction,run,deviation,temperature\n0,up,1,0,20\n".into(),
            "column.csv:1:32",
        ),
        (
            "both.csv",
            "target,direction,run,measured,deviation\n0,up,1,0,0\n".into(),
            "both.csv:1:31",
        ),
    ];
    for (name, text, at) in cases {
        let path = scratch_file(name, &text);
        let err = unwrapped(&fails(&["positioning", path.to_str().unwrap()]));
        assert!(err.contains(at), "{name}: want {at} in\n{err}");
    }
    let err = unwrapped(&fails(&[
        "positioning",
        "examples/positioning/x_axis_runs.csv",
        "--k",
        "0",
    ]));
    assert!(
        err.contains("--k")
            && err.contains("the coverage factor k must be a finite number > 0, not 0"),
        "{err}"
    );
    let err = unwrapped(&fails(&["positioning", "no/such/runs.csv"]));
    assert!(err.contains("no/such/runs.csv"), "{err}");
}

/// ISO 230-2 at 20 °C (docs/positioning.md, "At 20 °C"): the example X
/// axis measured with its scale at 23.5 °C (11.5 µm/(m·K)) and a laser's
/// material sensor at 22 °C compensating with 11.0: every target's means are
/// the uncorrected ones less `(P − P₀)·(α_s·ΔT_s − α_i·ΔT_i)`, the reversal
/// unchanged; the uncertainty contribution is the test's root sum of
/// squares of `α·L·u(T)` per temperature and `L·|ΔT|·α·r/√3` per
/// coefficient, times k; a rotary axis is refused.
#[test]
fn the_runs_corrected_to_20_degrees() {
    let path = "examples/positioning/x_axis_runs.csv";
    let raw = ok_json(&["positioning", path, "--format", "json"]);
    let at = ok_json(&[
        "positioning",
        path,
        "--axis-temperature",
        "23.5",
        "--axis-expansion",
        "11.5",
        "--instrument-temperature",
        "22",
        "--instrument-expansion",
        "11",
        "--temperature-uncertainty",
        "0.2",
        "--expansion-uncertainty",
        "0.1",
        "--format",
        "json",
    ]);
    let c = (11.5 * 3.5 - 11.0 * 2.0) * 1e-6;
    let (raw_t, at_t) = (
        raw["targets"].as_array().unwrap(),
        at["targets"].as_array().unwrap(),
    );
    let p0 = raw_t[0]["target"].as_f64().unwrap();
    for (r, a) in raw_t.iter().zip(at_t) {
        let l = r["target"].as_f64().unwrap() - p0;
        for key in ["mean_up", "mean_down", "mean"] {
            let want = r[key].as_f64().unwrap() - l * c;
            assert!(
                (a[key].as_f64().unwrap() - want).abs() < 1e-12,
                "{key} at {l}"
            );
        }
        assert!((a["reversal"].as_f64().unwrap() - r["reversal"].as_f64().unwrap()).abs() < 1e-12);
    }
    let span = raw_t.last().unwrap()["target"].as_f64().unwrap() - p0;
    let rect = 0.1 / 3f64.sqrt();
    let u = ((11.5e-6 * span * 0.2).powi(2)
        + (11.0e-6 * span * 0.2).powi(2)
        + (span * 11.5e-6 * 3.5 * rect).powi(2)
        + (span * 11.0e-6 * 2.0 * rect).powi(2))
    .sqrt();
    let t = &at["temperature"];
    assert!(
        (t["expanded"].as_f64().unwrap() - 2.0 * u).abs() < 1e-12,
        "{t}"
    );
    assert!((t["largest"].as_f64().unwrap() - span * c).abs() < 1e-12);
    assert!(raw.get("temperature").is_none());
    let e = unwrapped(&fails(&[
        "positioning",
        "examples/positioning/c_axis_runs.csv",
        "--rotary",
        "--axis-temperature",
        "23",
        "--axis-expansion",
        "11.5",
    ]));
    assert!(
        e.contains("a rotary axis's angles do not change with its temperature"),
        "{e}"
    );
}
