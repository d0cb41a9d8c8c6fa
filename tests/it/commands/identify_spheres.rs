//! Five-axis calibration by sphere probing and R-test (five-axis spec;
//! `docs/five-axis.md`): a simulated A/C trunnion whose rotary axes carry
//! location errors, a sphere at a place on the table the fit does not
//! know, and probe noise, evaluated through the independent numeric 4×4
//! product of `tests/it/common` (exact, not linearised): the probe
//! positions are solved on that product, and `chain identify --spheres`
//! must find the errors and the sphere within their std.

use serde_json::Value;

use crate::common::{self, cli, gauss, transform_point, Exact, Rng};
use chain::core::Machine;

/// The A/C trunnion example with only the location errors of its rotary
/// axes (the machine file's `errors:` and `squareness:` rows left out).
fn trunnion_text() -> String {
    let text = std::fs::read_to_string(common::example_file("machines/ac_trunnion.yaml")).unwrap();
    text.lines()
        .filter(|l| {
            let t = l.trim_start();
            !(t.starts_with("errors:") || t.starts_with("squareness:"))
        })
        .map(|l| format!("{l}\n"))
        .collect()
}

/// The true location errors (mm, rad): `examples/spheres/truth.yaml`.
pub(super) const TRUTH: [(&str, f64); 8] = [
    ("EY0A", 0.020),
    ("EZ0A", -0.015),
    ("EB0A", 3e-5),
    ("EC0A", -2e-5),
    ("EX0C", 0.010),
    ("EY0C", -0.025),
    ("EA0C", 4e-5),
    ("EB0C", -3e-5),
];

/// The linear axis positions at which the probe centre sits at `s` (the
/// sphere centre in the table frame) with the rotary axes at `a`, `c`
/// (rad), solved by Newton on the exact product (it is affine in the
/// slides, so the unit-step Jacobian is exact); the pose in the machine's
/// variable order.
fn probe(m: &Machine, e: &[f64], s: [f64; 3], a: f64, c: f64) -> Vec<f64> {
    let exact = Exact::new(m);
    let p = exact.file_parameters();
    let tp = exact.tool_point(&p);
    let at = |name: &str| m.variable_index(name).unwrap();
    let mut q = vec![0.0; m.variables.len()];
    q[at("A")] = a;
    q[at("C")] = c;
    let point = |q: &[f64]| transform_point(&exact.t_wt(q, &p, e), tp);
    let slides = [at("x"), at("y"), at("z")];
    for _ in 0..4 {
        let f0 = point(&q);
        let r: Vec<f64> = (0..3).map(|i| f0[i] - s[i]).collect();
        let jac: Vec<[f64; 3]> = slides
            .iter()
            .map(|&k| {
                let mut q1 = q.clone();
                q1[k] += 1.0;
                let f1 = point(&q1);
                std::array::from_fn(|i| f1[i] - f0[i])
            })
            .collect();
        // Solve J δ = −r (3 × 3, columns jac[k]) by Cramer's rule.
        let m3 = |c0: [f64; 3], c1: [f64; 3], c2: [f64; 3]| {
            c0[0] * (c1[1] * c2[2] - c1[2] * c2[1]) - c1[0] * (c0[1] * c2[2] - c0[2] * c2[1])
                + c2[0] * (c0[1] * c1[2] - c0[2] * c1[1])
        };
        let rhs = [-r[0], -r[1], -r[2]];
        let det = m3(jac[0], jac[1], jac[2]);
        let d = [
            m3(rhs, jac[1], jac[2]) / det,
            m3(jac[0], rhs, jac[2]) / det,
            m3(jac[0], jac[1], rhs) / det,
        ];
        for (k, &slot) in slides.iter().enumerate() {
            q[slot] += d[k];
        }
    }
    let f = point(&q);
    assert!((0..3).all(|i| (f[i] - s[i]).abs() < 1e-9), "{f:?} vs {s:?}");
    q
}

/// A sphere file of `spheres` (identifier, centre), each probed at A in
/// −60..60° and C in 0..270° through the true errors, x, y, z with noise
/// σ (mm); `with_std` adds the `std` column.
fn sphere_file(
    m: &Machine,
    e: &[f64],
    spheres: &[(&str, [f64; 3])],
    sigma: f64,
    rng: &mut Rng,
    with_std: bool,
) -> String {
    let at = |name: &str| m.variable_index(name).unwrap();
    let mut csv = String::from(if with_std {
        "sphere,A,C,x,y,z,std\n"
    } else {
        "sphere,A,C,x,y,z\n"
    });
    for (id, s) in spheres {
        for a in [-60.0f64, -30.0, 0.0, 30.0, 60.0] {
            for c in [0.0f64, 90.0, 180.0, 270.0] {
                let q = probe(m, e, *s, a.to_radians(), c.to_radians());
                let [x, y, z] = ["x", "y", "z"].map(|n| q[at(n)] + sigma * gauss(rng));
                csv.push_str(&format!("{id},{a},{c},{x:.6},{y:.6},{z:.6}"));
                if with_std {
                    csv.push_str(&format!(",{sigma}"));
                }
                csv.push('\n');
            }
        }
    }
    csv
}

/// The machine, its file and the true error vector.
fn setup(name: &str) -> (Machine, std::path::PathBuf, Vec<f64>) {
    let text = trunnion_text();
    let dir = cli::scratch(name);
    let file = cli::write(&dir, "trunnion.yaml", &text);
    let m = chain::core::load_file(&file).unwrap();
    let mut e = vec![0.0; m.errors.len()];
    for (n, v) in TRUTH {
        e[m.error_index(n).unwrap()] = v;
    }
    (m, file, e)
}

/// `chain identify MACHINE ARGS --format json`'s document.
fn identify_json(machine: &str, args: &[&str]) -> Value {
    let mut all = vec!["identify", machine];
    all.extend_from_slice(args);
    all.extend(["--format", "json"]);
    cli::ok_json(&all)
}

/// The estimate and std of `name` in a document's `estimates`.
fn estimate(doc: &Value, name: &str) -> (f64, f64) {
    let e = &doc["estimates"][name];
    (e["value"].as_f64().unwrap(), e["std"].as_f64().unwrap())
}

#[test]
fn one_sphere_finds_the_location_errors_and_the_sphere() {
    let (m, file, e) = setup("spheres_one");
    let mut rng = Rng::new(50);
    let sigma = 5e-4;
    let sphere = [80.0, -50.0, 60.0];
    let csv = sphere_file(&m, &e, &[("1", sphere)], sigma, &mut rng, true);
    let s = cli::write(file.parent().unwrap(), "spheres.csv", &csv);
    let doc = identify_json(file.to_str().unwrap(), &["--spheres", s.to_str().unwrap()]);
    // 8 errors + 3 sphere coordinates, 20 probings of 3 rows.
    assert_eq!(doc["parameters"], 11, "{doc:#}");
    assert_eq!(doc["rows"], 60);
    let rank = doc["rank"].as_u64().unwrap();
    let estimated: Vec<String> = doc["subset"]["estimated"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap().to_string())
        .collect();
    assert_eq!(estimated.len() as u64, rank);
    // The sphere's unknowns are always estimated.
    for c in ["x", "y", "z"] {
        assert!(
            estimated.contains(&format!("sphere 1.{c}")),
            "{estimated:?}"
        );
    }
    // Every estimated error within 3 std of the truth (the linear fit: the
    // errors are small enough that first order holds to well below σ).
    for (name, truth) in TRUTH {
        if !estimated.iter().any(|n| n == name) {
            continue;
        }
        let (v, sd) = estimate(&doc["subset"], name);
        assert!(
            (v - truth).abs() < 3.0 * sd + 1e-12,
            "{name}: {v} ± {sd} vs {truth}\n{doc:#}"
        );
    }
    // The sphere recovered, in the document's `setups`.
    let setups = doc["setups"].as_array().unwrap();
    assert_eq!(setups.len(), 1);
    assert_eq!(setups[0]["name"], "1");
    assert_eq!(setups[0]["kind"], "sphere");
    for l in 0..3 {
        let v = setups[0]["position"][l].as_f64().unwrap();
        let sd = setups[0]["std"][l].as_f64().unwrap();
        assert!(sd > 0.0 && sd < 0.01, "{sd}");
        assert!(
            (v - sphere[l]).abs() < 3.0 * sd,
            "{l}: {v} ± {sd} vs {}",
            sphere[l]
        );
    }
}

/// The poses of a sphere file's rows (rotary in rad), by the test's own
/// reading of its columns `sphere,A,C,x,y,z[,std]`: sphere, pose.
fn poses(m: &Machine, csv: &str) -> Vec<(String, Vec<f64>)> {
    let at = |name: &str| m.variable_index(name).unwrap();
    csv.lines()
        .skip(1)
        .map(|l| {
            let cells: Vec<&str> = l.split(',').collect();
            let v = |k: usize| cells[k].parse::<f64>().unwrap();
            let mut q = vec![0.0; m.variables.len()];
            q[at("A")] = v(1).to_radians();
            q[at("C")] = v(2).to_radians();
            q[at("x")] = v(3);
            q[at("y")] = v(4);
            q[at("z")] = v(5);
            (cells[0].to_string(), q)
        })
        .collect()
}

#[test]
fn two_spheres_iterate_and_predict_held_out_probings_as_the_product_does() {
    let (m, file, e) = setup("spheres_two");
    let dir = file.parent().unwrap().to_path_buf();
    let mut rng = Rng::new(51);
    let sigma = 5e-4;
    let spheres = [("low", [80.0, -50.0, 20.0]), ("high", [-60.0, 40.0, 180.0])];
    let fit = sphere_file(&m, &e, &spheres, sigma, &mut rng, false);
    // Held out: the same spheres at other positions (the generator's grid
    // shifted by 15°).
    let held: String = sphere_file(&m, &e, &spheres, sigma, &mut rng, false)
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if i == 0 {
                return format!("{l}\n");
            }
            let mut cells: Vec<String> = l.split(',').map(str::to_string).collect();
            let a: f64 = cells[1].parse().unwrap();
            let c: f64 = cells[2].parse().unwrap();
            let (a, c) = ((a + 15.0).min(75.0), c + 45.0);
            let s = spheres.iter().find(|(n, _)| *n == cells[0]).unwrap().1;
            let q = probe(&m, &e, s, a.to_radians(), c.to_radians());
            let at = |n: &str| m.variable_index(n).unwrap();
            cells[1] = a.to_string();
            cells[2] = c.to_string();
            for (k, n) in [(3, "x"), (4, "y"), (5, "z")] {
                cells[k] = format!("{:.6}", q[at(n)]);
            }
            format!("{}\n", cells.join(","))
        })
        .collect();
    let s = cli::write(&dir, "fit.csv", &fit);
    let v = cli::write(&dir, "held.csv", &held);
    let values = dir.join("values.yaml");
    let doc = identify_json(
        file.to_str().unwrap(),
        &[
            "--spheres",
            s.to_str().unwrap(),
            "--validate",
            v.to_str().unwrap(),
            "--iterate",
            "--values-out",
            values.to_str().unwrap(),
        ],
    );
    assert_eq!(doc["parameters"], 14, "{doc:#}");
    assert_eq!(doc["rank"], 14);
    let it = &doc["iteration"];
    assert_eq!(it["converged"], true);
    for (name, truth) in TRUTH {
        let (v, sd) = estimate(it, name);
        assert!(
            (v - truth).abs() < 3.0 * sd,
            "{name}: {v} ± {sd} vs {truth}"
        );
    }
    let names: Vec<&str> = doc["setups"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["low", "high"]);
    // The values file holds the machine's errors only.
    let text = std::fs::read_to_string(&values).unwrap();
    assert!(text.contains("  EY0C: {value: "), "{text}");
    let (_, entries) = text.split_once("values:").unwrap();
    assert!(!entries.contains("sphere"), "{text}");
    chain::core::values::Values::read(&values, &m).unwrap();
    // The prediction at the held-out probings, evaluated here through the
    // product with the iterated errors and sphere positions: after, the
    // probe centre T_wt(q, ê)·t against ŝ; before, T_wt(q, 0)·t against ŝ.
    let exact = Exact::new(&m);
    let p = exact.file_parameters();
    let tp = exact.tool_point(&p);
    let mut ehat = vec![0.0; m.errors.len()];
    for (j, err) in m.errors.iter().enumerate() {
        ehat[j] = it["estimates"][err.name.as_str()]["value"]
            .as_f64()
            .unwrap();
    }
    let shat = |id: &str| -> [f64; 3] {
        let at = |c: &str| {
            it["estimates"][format!("sphere {id}.{c}")]["value"]
                .as_f64()
                .unwrap()
        };
        [at("x"), at("y"), at("z")]
    };
    let zero = vec![0.0; m.errors.len()];
    let (mut after, mut before, mut rows) = (0.0, 0.0, 0.0);
    for (id, q) in poses(&m, &held) {
        let s = shat(&id);
        let a = transform_point(&exact.t_wt(&q, &p, &ehat), tp);
        let b = transform_point(&exact.t_wt(&q, &p, &zero), tp);
        for l in 0..3 {
            after += (s[l] - a[l]).powi(2);
            before += (s[l] - b[l]).powi(2);
            rows += 1.0;
        }
    }
    let got = &doc["validation"];
    let rms = |x: f64| (x / rows).sqrt();
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * b.abs().max(1e-6);
    let (after_doc, before_doc) = (
        got["after"]["rms"].as_f64().unwrap(),
        got["before"]["rms"].as_f64().unwrap(),
    );
    assert!(
        close(after_doc, rms(after)),
        "{after_doc} vs {}",
        rms(after)
    );
    assert!(
        close(before_doc, rms(before)),
        "{before_doc} vs {}",
        rms(before)
    );
    // Corrected, the held-out probings are within a few σ (the noise of
    // the probing, and of the fitted positions).
    assert!(rms(after) < 3.0 * sigma, "{}", rms(after));
    assert!(rms(before) > 10.0 * sigma, "{}", rms(before));
}

#[test]
fn the_whole_trunnion_names_what_one_sphere_cannot_separate() {
    // The example with all 41 errors: sphere probing sees the location
    // errors, but not, e.g., the linear axes' component errors apart from
    // each other.
    let file = common::example_file("machines/ac_trunnion.yaml");
    let m = common::load_example("ac_trunnion.yaml");
    let mut e = vec![0.0; m.errors.len()];
    for (n, v) in TRUTH {
        e[m.error_index(n).unwrap()] = v;
    }
    let mut rng = Rng::new(52);
    let csv = sphere_file(&m, &e, &[("1", [80.0, -50.0, 60.0])], 5e-4, &mut rng, true);
    let s = cli::scratch_file("whole.csv", &csv);
    let doc = identify_json(file.to_str().unwrap(), &["--spheres", s.to_str().unwrap()]);
    assert_eq!(doc["parameters"], 44);
    let groups = doc["groups"].as_array().unwrap();
    assert!(!groups.is_empty(), "{doc:#}");
    // The sphere's x acts as one offset in px with the x errors of the
    // axes that do not move with the table's rotations: named in words.
    let words: Vec<&str> = groups
        .iter()
        .map(|g| g["explanation"].as_str().unwrap())
        .collect();
    assert!(words.iter().any(|w| w.contains("sphere 1.")), "{words:#?}");
    let table = cli::ok_stdout(&[
        "identify",
        file.to_str().unwrap(),
        "--spheres",
        s.to_str().unwrap(),
    ]);
    assert!(
        table.contains("cannot be separated by these measurements"),
        "{table}"
    );
    assert!(table.contains("sphere 1: x = "), "{table}");
}

#[test]
fn an_r_test_estimates_the_ball_set_up_beside_the_errors() {
    let (m, file, e) = setup("rtest");
    let exact = Exact::new(&m);
    let p = exact.file_parameters();
    let tp = exact.tool_point(&p);
    let zero = vec![0.0; m.errors.len()];
    let ball = [60.0, 30.0, 90.0];
    let offset = [0.05, -0.03, 0.02];
    let sigma = 3e-4;
    let mut rng = Rng::new(53);
    let at = |n: &str| m.variable_index(n).unwrap();
    let mut csv = String::from("A,C,x,y,z,dpx,dpy,dpz\n");
    for a in [-45.0f64, -20.0, 0.0, 20.0, 45.0] {
        for c in [0.0f64, 72.0, 144.0, 216.0, 288.0] {
            // The nest is commanded onto the ball's nominal place.
            let q = probe(&m, &zero, ball, a.to_radians(), c.to_radians());
            let actual = transform_point(&exact.t_wt(&q, &p, &e), tp);
            let d: Vec<f64> = (0..3)
                .map(|l| actual[l] - ball[l] - offset[l] + sigma * gauss(&mut rng))
                .collect();
            csv.push_str(&format!(
                "{},{},{},{},{},{:.7},{:.7},{:.7}\n",
                q[at("A")],
                q[at("C")],
                q[at("x")],
                q[at("y")],
                q[at("z")],
                d[0],
                d[1],
                d[2]
            ));
        }
    }
    let r = cli::write(file.parent().unwrap(), "rtest.csv", &csv);
    let doc = identify_json(
        file.to_str().unwrap(),
        &["--measurements", r.to_str().unwrap(), "--setup", "ball"],
    );
    assert_eq!(doc["parameters"], 11, "{doc:#}");
    assert_eq!(doc["rank"], 11);
    for (name, truth) in TRUTH {
        let (v, sd) = estimate(&doc["subset"], name);
        assert!(
            (v - truth).abs() < 3.0 * sd,
            "{name}: {v} ± {sd} vs {truth}"
        );
    }
    let b = &doc["setups"][0];
    assert_eq!(b["kind"], "ball");
    for l in 0..3 {
        let v = b["position"][l].as_f64().unwrap();
        let sd = b["std"][l].as_f64().unwrap();
        assert!((v - offset[l]).abs() < 3.0 * sd, "{l}: {v} ± {sd}");
    }
}

#[test]
fn sphere_files_and_options_are_refused_located() {
    let (m, file, e) = setup("refusals");
    let dir = file.parent().unwrap().to_path_buf();
    let f = file.to_str().unwrap();
    let mut rng = Rng::new(54);
    let good = sphere_file(&m, &e, &[("1", [80.0, -50.0, 60.0])], 5e-4, &mut rng, true);
    let run = |name: &str, text: &str| {
        let s = cli::write(&dir, name, text);
        cli::unwrapped(&cli::fails(&[
            "identify",
            f,
            "--spheres",
            s.to_str().unwrap(),
        ]))
    };
    // A missing rotary column.
    let no_c: String = good
        .lines()
        .map(|l| {
            let cells: Vec<&str> = l.split(',').collect();
            format!("{},{}\n", cells[..2].join(","), cells[3..].join(","))
        })
        .collect();
    let err = run("no_c.csv", &no_c);
    assert!(err.contains("no_c.csv:1:1") && err.contains("`C`"), "{err}");
    // A std that is not positive, at its line and column.
    let lines: Vec<&str> = good.lines().collect();
    let mut bad_std = lines.clone();
    let third = lines[3].rsplit_once(',').unwrap().0.to_string() + ",0";
    bad_std[3] = &third;
    let err = run("bad_std.csv", &(bad_std.join("\n") + "\n"));
    assert!(err.contains("must be positive, got 0"), "{err}");
    assert!(err.contains("bad_std.csv:4:"), "{err}");
    // A sphere probed once.
    let once = format!(
        "{}{}\n",
        good.lines()
            .take(21)
            .map(|l| format!("{l}\n"))
            .collect::<String>(),
        lines[1].replacen('1', "2", 1)
    );
    let err = run("once.csv", &once);
    assert!(
        err.contains("once.csv:22:") && err.contains("sphere `2` is probed 1 time"),
        "{err}"
    );
    // An unknown column, with the closest one suggested.
    let err = run("typo.csv", &good.replacen("sphere,", "spere,", 1));
    assert!(
        err.contains("typo.csv:1:1") && err.contains("`spere`") && err.contains("sphere"),
        "{err}"
    );
    // A non-finite cell.
    let err = run("nan.csv", &good.replacen(",60,", ",nan,", 1));
    assert!(err.contains("nan.csv:"), "{err}");
    // Options: neither input, both, --setup with --spheres, a held-out
    // probing of another sphere.
    let s = cli::write(&dir, "good.csv", &good);
    let s = s.to_str().unwrap();
    let fails = |args: &[&str]| cli::unwrapped(&cli::fails(args));
    let err = fails(&["identify", f]);
    assert!(
        err.contains("--measurements M.csv") && err.contains("one of them"),
        "{err}"
    );
    let err = fails(&["identify", f, "--spheres", s, "--measurements", s]);
    assert!(err.contains("not both"), "{err}");
    let err = fails(&["identify", f, "--spheres", s, "--setup", "ball"]);
    assert!(err.contains("--setup: the spheres of --spheres"), "{err}");
    let err = fails(&["identify", f, "--measurements", s, "--setup", "bal"]);
    assert!(
        err.contains("`bal` is not a set-up: choose one of ball"),
        "{err}"
    );
    let other = cli::write(&dir, "other.csv", &good.replace("\n1,", "\n7,"));
    let err = fails(&[
        "identify",
        f,
        "--spheres",
        s,
        "--validate",
        other.to_str().unwrap(),
    ]);
    assert!(
        err.contains("line 2: sphere `7` is not among the fitted file's"),
        "{err}"
    );
}

/// The `NAME: VALUE` entries of a values file of constants (the
/// generator's truth files), read here without chain.
fn constants(path: &std::path::Path) -> Vec<(String, f64)> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter(|l| l.starts_with("  "))
        .map(|l| {
            let (name, value) = l.trim().split_once(": ").unwrap();
            (name.to_string(), value.parse().unwrap())
        })
        .collect()
}

/// `examples/spheres/` (made by its own generator, not by chain): every
/// location error within 3 std of `truth.yaml`, from the probings with
/// `--iterate` and from the R-test; the held-out probings corrected to the
/// probe's noise.
#[test]
fn the_examples_recover_their_truth() {
    let machine = common::example_file("machines/ac_trunnion_rotary.yaml");
    let dir = common::example_file("spheres");
    let truth = constants(&dir.join("truth.yaml"));
    assert_eq!(truth.len(), 8);
    let path = |f: &str| dir.join(f).to_str().unwrap().to_string();
    let m = machine.to_str().unwrap();
    let probed = identify_json(
        m,
        &[
            "--spheres",
            &path("probing.csv"),
            "--validate",
            &path("validate.csv"),
            "--iterate",
        ],
    );
    let rtest = identify_json(
        m,
        &["--measurements", &path("rtest.csv"), "--setup", "ball"],
    );
    for (name, v) in &truth {
        let (got, sd) = estimate(&probed["iteration"], name);
        assert!(
            (got - v).abs() < 3.0 * sd,
            "probing {name}: {got} ± {sd} vs {v}"
        );
        let (got, sd) = estimate(&rtest["subset"], name);
        assert!(
            (got - v).abs() < 3.0 * sd,
            "R-test {name}: {got} ± {sd} vs {v}"
        );
    }
    // The generator's noise is 0.5 µm per coordinate.
    let after = probed["validation"]["after"]["rms"].as_f64().unwrap();
    assert!(after < 1e-3, "{after}");
    // The B/C table: its B axis's location errors and the C axis's.
    let truth = constants(&dir.join("bc_truth.yaml"));
    assert_eq!(truth.len(), 8);
    let bc = common::example_file("machines/bc_table_rotary.yaml");
    let doc = identify_json(
        bc.to_str().unwrap(),
        &["--spheres", &path("bc_probing.csv"), "--iterate"],
    );
    assert_eq!(doc["rank"], 14);
    for (name, v) in &truth {
        let (got, sd) = estimate(&doc["iteration"], name);
        assert!(
            (got - v).abs() < 3.0 * sd,
            "B/C {name}: {got} ± {sd} vs {v}"
        );
    }
}

/// `chain plan --spheres-candidates`: the K probings of the example's grid
/// that determine the location errors best, the spheres' positions counted
/// among the unknowns (14 = 8 errors + 2 × 3); the chosen probings,
/// identified on their own, determine every unknown (rank 14), and their
/// information beats K taken evenly.
#[test]
fn plan_chooses_probings_with_the_spheres_counted() {
    let machine = common::example_file("machines/ac_trunnion_rotary.yaml");
    let probing = common::example_file("spheres/probing.csv");
    let m = machine.to_str().unwrap();
    let doc = cli::ok_json(&[
        "plan",
        m,
        "--spheres-candidates",
        probing.to_str().unwrap(),
        "--count",
        "8",
        "--format",
        "json",
    ]);
    let errors: Vec<&str> = doc["errors"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e.as_str().unwrap())
        .collect();
    assert_eq!(errors.len(), 14, "{errors:?}");
    assert!(errors.contains(&"sphere low.x") && errors.contains(&"sphere high.z"));
    assert_eq!(doc["rank"], 14);
    let optimal = doc["optimal"]["log_det"].as_f64().unwrap();
    let even = doc["even"]["log_det"].as_f64().unwrap_or(f64::NEG_INFINITY);
    assert!(optimal >= even, "{optimal} vs {even}");
    // The chosen probings as a sphere file of their own.
    let text = std::fs::read_to_string(&probing).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let mut chosen = format!("{}\n", lines[0]);
    for c in doc["optimal"]["candidates"].as_array().unwrap() {
        chosen.push_str(lines[1 + c.as_u64().unwrap() as usize]);
        chosen.push('\n');
    }
    let file = cli::scratch_file("chosen.csv", &chosen);
    let fit = identify_json(m, &["--spheres", file.to_str().unwrap()]);
    assert_eq!(fit["rank"], 14, "{fit:#}");
    // Every expected std of the plan is the fit's std on those probings
    // (the rows carry the file's std: absolute stds), within the linear
    // model's rounding.
    let stds = doc["optimal"]["std"].as_array().unwrap();
    for (name, sd) in errors.iter().zip(stds) {
        let want = sd.as_f64().unwrap();
        let got = fit["subset"]["estimates"][*name]["std"].as_f64().unwrap();
        assert!((got - want).abs() <= 1e-6 * want, "{name}: {got} vs {want}");
    }
}

/// `--prior` and `--holdout` with sphere probings: the trunnion with a
/// `statistics` entry for each location error (0.05 mm, 1e-4 rad); the
/// posterior keeps every error within 3 std of the truth and the spheres,
/// which have no prior, are estimated from the data alone (their std as
/// the least-squares fit's, within 10 %); a holdout of a quarter of the
/// probings is predicted to the probe's noise.
#[test]
fn spheres_with_a_prior_and_a_holdout() {
    let (m, file, e) = setup("spheres_prior");
    let mut text = std::fs::read_to_string(&file).unwrap();
    text.push_str("statistics:\n");
    for (name, _) in TRUTH {
        // EX0C, EY0A, ...: an offset; EA0C, EB0A, ...: a tilt.
        let std = if matches!(&name[1..2], "X" | "Y" | "Z") {
            "0.05"
        } else {
            "1e-4"
        };
        text.push_str(&format!(
            "  {name}: {{dist: normal, mean: 0, std: {std}}}\n"
        ));
    }
    let file = cli::write(file.parent().unwrap(), "trunnion_stats.yaml", &text);
    let mut rng = Rng::new(55);
    let csv = sphere_file(&m, &e, &[("1", [80.0, -50.0, 60.0])], 5e-4, &mut rng, true);
    let s = cli::write(file.parent().unwrap(), "spheres.csv", &csv);
    let (f, s) = (file.to_str().unwrap(), s.to_str().unwrap());
    let post = identify_json(f, &["--spheres", s, "--prior"]);
    assert_eq!(post["prior"], true);
    for (name, truth) in TRUTH {
        let (v, sd) = estimate(&post, name);
        assert!(
            (v - truth).abs() < 3.0 * sd,
            "{name}: {v} ± {sd} vs {truth}"
        );
    }
    let ls = identify_json(f, &["--spheres", s]);
    for l in 0..3 {
        let (a, b) = (
            post["setups"][0]["std"][l].as_f64().unwrap(),
            ls["setups"][0]["std"][l].as_f64().unwrap(),
        );
        assert!((a / b - 1.0).abs() < 0.1, "{l}: {a} vs {b}");
    }
    let held = identify_json(f, &["--spheres", s, "--holdout", "0.25"]);
    let v = &held["validation"];
    assert_eq!(v["measurements"], 5);
    assert!(v["after"]["rms"].as_f64().unwrap() < 2e-3, "{v:#}");
}
