//! Post-measurement reliability (`docs/posterior.md`):
//! `chain reliability --values` and `chain sensitivity --values` with the
//! posterior of a calibration, on the gantry grinder of seed 000.
//!
//! The posterior gives four errors with a `std` and a non-diagonal
//! correlation; the other 17 keep their `statistics` marginals (normal, mean
//! 0). Every error component is linear in the errors, `E_c = a_cᵀe`, so with
//! `e ~ N(μ, Σ)` an upper-sided component has the closed form
//! `R = Φ((I − a_cᵀμ)/√(a_cᵀΣa_c))`, with `∂R/∂μ_j = −φ(β)·a_j/s`,
//! `∂R/∂σ_j = −φ(β)·β·a_j(R D a)_j/s²` (`s = √(aᵀΣa)`, `R` the correlation
//! matrix held fixed) and the importance factors `γ_j² = (σ_j a_j)²/Σ_k(σ_k a_k)²`
//! (Der Kiureghian's `γ = L⁻ᵀα` for a linear `g`). The expected numbers
//! below are those closed forms with `a_c` from the finite difference of the
//! exact numeric 4×4 product of `tests/it/common` (not chain's derivation), `Σ`
//! assembled here and `Φ` from Cody's `erfc` in `tests/it/common`.

// Matrix loops read best with explicit indices.
#![allow(clippy::needless_range_loop)]

use crate::common;

use chain::core::Machine;
use common::cli::{chain, fails, ok_json, scratch, success, unwrapped, write};
use common::{example_path, load_example, normal_cdf, Exact};
use serde_json::Value;

const MACHINE: &str = "gantry_grinder.yaml";
/// Tolerance of each position component, mm (the file's).
const I: f64 = 0.03;

/// `(name, mean, std)` of the posterior.
const GIVEN: [(&str, f64, f64); 4] = [
    ("dxx", 0.004, 0.003),
    ("dxz", -0.002, 0.0025),
    ("eyx", 2.0e-6, 4.0e-6),
    ("dxy", 0.001, 0.004),
];
/// The correlations of the posterior.
const RHO: [(&str, &str, f64); 3] = [
    ("dxx", "dxz", -0.45),
    ("eyx", "dxx", 0.3),
    ("dxy", "dxz", 0.2),
];

const POSTERIOR: &str = "machine: gantry_grinder
values:
  dxx: {value: 0.004, std: 0.003}
  dxz: {value: -0.002, std: 0.0025}
  eyx: {value: 2.0e-6, std: 4.0e-6}
  dxy: {value: 0.001, std: 0.004}
correlation:
  - [dxx, dxz, -0.45]
  - [eyx, dxx, 0.3]
  - [dxy, dxz, 0.2]
";

/// `chain reliability` of the grinder with the posterior `values` and
/// `extra` options, as JSON.
fn reliability_json(values: &str, extra: &[&str]) -> Value {
    let machine = machine_path();
    let mut args = vec!["reliability", machine.as_str(), "--values", values];
    args.extend(extra);
    args.extend(["--format", "json"]);
    ok_json(&args)
}

fn machine_path() -> String {
    example_path(MACHINE).to_str().unwrap().to_string()
}

/// The posterior written into a scratch directory.
fn posterior_file(name: &str, text: &str) -> String {
    let dir = scratch(name);
    write(&dir, "posterior.yaml", text)
        .to_str()
        .unwrap()
        .to_string()
}

/// The test's own `μ`, `σ` and correlation matrix, in `machine.errors` order.
struct Law {
    mean: Vec<f64>,
    std: Vec<f64>,
    corr: Vec<Vec<f64>>,
}

impl Law {
    fn of(m: &Machine) -> Law {
        let n = m.errors.len();
        let mut mean = vec![0.0; n];
        let mut std = vec![0.0; n];
        for j in 0..n {
            match m.statistic(j).unwrap().distribution {
                chain::core::model::Distribution::Normal { mean: mu, std: s } => {
                    mean[j] = mu;
                    std[j] = s;
                }
                other => panic!("{other:?}"),
            }
        }
        for (name, mu, s) in GIVEN {
            let j = m.error_index(name).unwrap();
            mean[j] = mu;
            std[j] = s;
        }
        let mut corr = vec![vec![0.0; n]; n];
        for j in 0..n {
            corr[j][j] = 1.0;
        }
        for (a, b, r) in RHO {
            let (a, b) = (m.error_index(a).unwrap(), m.error_index(b).unwrap());
            corr[a][b] = r;
            corr[b][a] = r;
        }
        Law { mean, std, corr }
    }

    /// `aᵀΣa`.
    fn variance(&self, a: &[f64]) -> f64 {
        let n = a.len();
        let mut v = 0.0;
        for i in 0..n {
            for j in 0..n {
                v += a[i] * a[j] * self.std[i] * self.std[j] * self.corr[i][j];
            }
        }
        v
    }

    /// `(R D a)_j`.
    fn weight(&self, a: &[f64], j: usize) -> f64 {
        (0..a.len())
            .map(|k| self.corr[j][k] * self.std[k] * a[k])
            .sum()
    }

    /// `Φ((I − aᵀμ)/√(aᵀΣa))` and `β`.
    fn reliability(&self, a: &[f64]) -> (f64, f64) {
        let m: f64 = a.iter().zip(&self.mean).map(|(x, y)| x * y).sum();
        let beta = (I - m) / self.variance(a).sqrt();
        (normal_cdf(beta), beta)
    }
}

/// The sensitivity row of component `c` (0 = px) at machine-ordered `q`,
/// by the numeric transform product.
fn row(m: &Machine, q: &[f64], c: usize) -> Vec<f64> {
    let exact = Exact::new(m);
    let s = exact.fd_sensitivity(q, &exact.file_parameters(), 1e-3);
    let n = m.errors.len();
    s[c * n..(c + 1) * n].to_vec()
}

/// `q` in the machine's variable order from a JSON point `{x, y, z}`.
fn q_of(m: &Machine, point: &Value) -> Vec<f64> {
    m.variables
        .iter()
        .map(|v| point[&v.name].as_f64().unwrap())
        .collect()
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()) + 1e-300
}

const COMPONENTS: [&str; 3] = ["px", "py", "pz"];

#[test]
fn form_is_the_correlated_closed_form_at_grid_points() {
    let m = load_example(MACHINE);
    let law = Law::of(&m);
    // The correlation is really off-diagonal and changes the answer.
    assert!(
        law.corr
            .iter()
            .flatten()
            .filter(|r| **r != 0.0 && **r != 1.0)
            .count()
            == 6
    );
    let values = posterior_file("form", POSTERIOR);
    let doc = reliability_json(&values, &[]);
    let results = doc["results"].as_array().unwrap();
    assert_eq!(results.len(), 3 * 125);
    let mut checked = 0;
    let mut moved = 0.0f64;
    for (k, case) in results.iter().enumerate() {
        // Every 7th case: points all over the grid, all three components.
        if k % 7 != 0 {
            continue;
        }
        let c = COMPONENTS
            .iter()
            .position(|n| case["component"] == *n)
            .unwrap();
        let q = q_of(&m, &case["point"]);
        let a = row(&m, &q, c);
        let (want, beta) = law.reliability(&a);
        let got = case["reliability"].as_f64().unwrap();
        assert!(
            close(1.0 - got, 1.0 - want, 1e-8),
            "{} at {q:?}: {got} vs Φ((I − aᵀμ)/√(aᵀΣa)) = {want}",
            case["component"]
        );
        assert!(close(case["beta"].as_f64().unwrap(), beta, 1e-8));
        assert_eq!(case["exact"], true);
        // Against the same means without the correlations.
        let mut independent = Law::of(&m);
        independent.corr = (0..a.len())
            .map(|i| (0..a.len()).map(|j| f64::from(u8::from(i == j))).collect())
            .collect();
        moved = moved.max((independent.reliability(&a).0 - want).abs());
        checked += 1;
    }
    assert!(checked >= 50);
    // The correlations matter: R moves by 0.34 percentage points somewhere,
    // far beyond the tolerance above.
    assert!(moved > 3e-3, "{moved}");
    // The document says what the inputs were.
    assert_eq!(doc["posterior"]["values"].as_array().unwrap().len(), 4);
    assert_eq!(doc["posterior"]["correlations"][0]["rho"], -0.45);
    assert_eq!(doc["posterior"]["values"][0]["std"], 0.003);
}

#[test]
fn sampling_agrees_with_the_closed_form() {
    let m = load_example(MACHINE);
    let law = Law::of(&m);
    let values = posterior_file("sampling", POSTERIOR);
    let grid = [
        "--grid",
        "x=0,1000",
        "--grid",
        "y=-1500,750",
        "--grid",
        "z=1400",
    ];
    let run = |method: &str, samples: &str| {
        let mut args = vec!["reliability".to_string(), machine_path()];
        args.extend(
            [
                "--values",
                &values,
                "--format",
                "json",
                "--method",
                method,
                "--samples",
                samples,
                "--seed",
                "11",
            ]
            .map(String::from),
        );
        args.extend(grid.map(String::from));
        let refs: Vec<&str> = args.iter().map(String::as_str).collect();
        ok_json(&refs)
    };
    let mc = run("mc", "400000");
    let is = run("is", "2000");
    for (cm, ci) in mc["results"]
        .as_array()
        .unwrap()
        .iter()
        .zip(is["results"].as_array().unwrap())
    {
        let c = COMPONENTS
            .iter()
            .position(|n| cm["component"] == *n)
            .unwrap();
        let q = q_of(&m, &cm["point"]);
        let (want, _) = law.reliability(&row(&m, &q, c));
        let pf = 1.0 - want;
        let (got, se) = (
            cm["pf"].as_f64().unwrap(),
            cm["std_error"].as_f64().unwrap(),
        );
        // Monte Carlo: within 4 of its own standard errors.
        assert!(se > 0.0 || pf < 1e-7, "{cm}");
        assert!(
            (got - pf).abs() <= 4.0 * se + 1e-12,
            "{} at {q:?}: MC {got} ± {se} vs {pf}",
            cm["component"]
        );
        // The importance sampling on an affine limit state in normal inputs
        // (correlated or not) has zero variance: the closed form.
        assert!(
            close(ci["pf"].as_f64().unwrap(), pf, 1e-9),
            "IS {} vs {pf}",
            ci["pf"]
        );
    }
}

#[test]
fn sensitivities_are_the_correlated_closed_forms() {
    let m = load_example(MACHINE);
    let law = Law::of(&m);
    let values = posterior_file("sensitivity", POSTERIOR);
    for at in ["x=1000,y=-1500,z=1400", "x=250,y=750,z=800"] {
        let doc = ok_json(&[
            "sensitivity",
            &machine_path(),
            "--values",
            &values,
            "--at",
            at,
            "--format",
            "json",
        ]);
        let coords: Vec<(String, f64)> = at
            .split(',')
            .map(|p| {
                let (n, v) = p.split_once('=').unwrap();
                (n.to_string(), v.parse().unwrap())
            })
            .collect();
        let q: Vec<f64> = m
            .variables
            .iter()
            .map(|v| coords.iter().find(|(n, _)| *n == v.name).unwrap().1)
            .collect();
        for (c, name) in COMPONENTS.iter().enumerate() {
            assert_eq!(doc["methods"][name], "exact");
            let a = row(&m, &q, c);
            let (_, beta) = law.reliability(&a);
            let s = law.variance(&a).sqrt();
            let phi = (-0.5 * beta * beta).exp() / (2.0 * std::f64::consts::PI).sqrt();
            let total: f64 = (0..a.len()).map(|k| (law.std[k] * a[k]).powi(2)).sum();
            for e in doc["components"][name].as_array().unwrap() {
                let j = m.error_index(e["error"].as_str().unwrap()).unwrap();
                let dmu = -phi * a[j] / s;
                let dsd = -phi * beta * a[j] * law.weight(&a, j) / (s * s);
                let imp = (law.std[j] * a[j]).powi(2) / total;
                let scale = phi / s * 1e-6;
                let ok = |got: &Value, want: f64| {
                    let g = got.as_f64().unwrap();
                    (g - want).abs() <= 1e-7 * want.abs() + scale
                };
                assert!(
                    ok(&e["dr_dmean"], dmu),
                    "{name} {j}: {} vs {dmu}",
                    e["dr_dmean"]
                );
                assert!(
                    ok(&e["dr_dstd"], dsd),
                    "{name} {j}: {} vs {dsd}",
                    e["dr_dstd"]
                );
                assert!(
                    (e["importance"].as_f64().unwrap() - imp).abs() < 1e-9,
                    "{name} {j}"
                );
            }
            // ∂R/∂σ_j of dxx by a central difference of the closed form in σ_j.
            let j = m.error_index("dxx").unwrap();
            let h = 1e-7;
            let mut up = Law::of(&m);
            up.std[j] += h;
            let mut down = Law::of(&m);
            down.std[j] -= h;
            let fd = (up.reliability(&a).0 - down.reliability(&a).0) / (2.0 * h);
            let got = doc["components"][name]
                .as_array()
                .unwrap()
                .iter()
                .find(|e| e["error"] == "dxx")
                .unwrap()["dr_dstd"]
                .as_f64()
                .unwrap();
            assert!(
                (got - fd).abs() <= 1e-5 * fd.abs() + 1e-6,
                "{name}: {got} vs fd {fd}"
            );
        }
    }
}

/// `chain ARGS` succeeds; its stdout.
fn stdout(args: &[&str]) -> String {
    String::from_utf8(success(chain(args)).stdout).unwrap()
}

#[test]
fn means_without_std_or_correlation_are_the_statistics_bit_for_bit() {
    // The machine file with two statistics means moved, and a values file
    // giving the same two means without std: the same inputs.
    let text = std::fs::read_to_string(example_path(MACHINE)).unwrap();
    let shifted = text
        .replace(
            "dxx: {dist: normal, mean: 0, std: 0.05/6}",
            "dxx: {dist: normal, mean: 0.004, std: 0.05/6}",
        )
        .replace(
            "eyx: {dist: normal, mean: 0, std: 0.06/6000}",
            "eyx: {dist: normal, mean: -3.0e-6, std: 0.06/6000}",
        );
    assert_ne!(shifted, text);
    let dir = scratch("bits");
    let shifted = write(&dir, "gantry_grinder.yaml", &shifted);
    let shifted = shifted.to_str().unwrap();
    let means = write(
        &dir,
        "means.yaml",
        "machine: gantry_grinder\nvalues:\n  dxx: 0.004\n  eyx: -3.0e-6\n",
    );
    let empty = write(&dir, "empty.yaml", "machine: gantry_grinder\nvalues: {}\n");
    let (means, empty) = (means.to_str().unwrap(), empty.to_str().unwrap());
    let original = machine_path();
    for method in [
        &["--method", "form"][..],
        &["--method", "is", "--samples", "500"],
        &["--method", "mc", "--samples", "3000"],
    ] {
        let with = |file: &str, values: Option<&str>| {
            let mut args = vec!["reliability", file, "--format", "csv", "--system", "series"];
            args.extend_from_slice(method);
            if let Some(v) = values {
                args.extend(["--values", v]);
            }
            stdout(&args)
        };
        assert_eq!(
            with(&original, Some(means)),
            with(shifted, None),
            "{method:?}"
        );
        assert_eq!(
            with(&original, Some(empty)),
            with(&original, None),
            "{method:?}"
        );
    }
    // The sensitivities too (JSON, without the posterior listing).
    let sens = |file: &str, values: Option<&str>| {
        let mut args = vec!["sensitivity", file, "--format", "json"];
        if let Some(v) = values {
            args.extend(["--values", v]);
        }
        let mut doc: Value = serde_json::from_str(&stdout(&args)).unwrap();
        doc.as_object_mut().unwrap().remove("posterior");
        serde_json::to_string(&doc).unwrap()
    };
    assert_eq!(sens(&original, Some(means)), sens(shifted, None));
}

#[test]
fn bad_posteriors_are_located_refusals() {
    let run = |name: &str, text: &str| {
        let values = posterior_file(name, text);
        let r = unwrapped(&fails(&[
            "reliability",
            &machine_path(),
            "--values",
            &values,
        ]));
        let s = unwrapped(&fails(&[
            "sensitivity",
            &machine_path(),
            "--values",
            &values,
        ]));
        assert_eq!(r, s);
        r
    };
    let head = "machine: gantry_grinder\nvalues:\n  dxx: {value: 0.004, std: 0.003}\n  dxz: {value: -0.002, std: 0.0025}\n  dxy: {value: 0.001, std: 0.004}\n  eyx: 2.0e-6\n";
    // Each |ρ| < 1, but the matrix has eigenvalue 1 − 0.9 − 0.9 < 0.
    let e = run(
        "pd",
        &format!(
            "{head}correlation:\n  - [dxx, dxz, 0.9]\n  - [dxz, dxy, 0.9]\n  - [dxx, dxy, -0.9]\n"
        ),
    );
    assert!(e.contains("posterior.yaml:7:1"), "{e}");
    assert!(
        e.contains("not positive definite") && e.contains("dxx, dxz, dxy"),
        "{e}"
    );
    assert!(
        e.contains("chain::posterior::not_positive_definite") && e.contains("at key `correlation`"),
        "{e}"
    );
    // An unknown name, with the closest.
    let e = run(
        "unknown",
        &format!("{head}correlation:\n  - [dxx, dxq, 0.2]\n"),
    );
    assert!(e.contains("posterior.yaml:8:11"), "{e}");
    assert!(
        e.contains("unknown name `dxq` (did you mean `dxx`?)") && e.contains("`correlation[0][1]`"),
        "{e}"
    );
    // A name without std in the file; ρ out of range; a pair twice; a bad entry.
    let e = run(
        "several",
        &format!("{head}correlation:\n  - [eyx, dxx, 0.2]\n  - [dxx, dxz, 1.5]\n  - [dxz, dxx, 0.1]\n  - [dxz, dxx, 0.2]\n  - [dxx, 3]\n"),
    );
    assert!(
        e.contains("posterior.yaml:8:6") && e.contains("`eyx` has no `std`"),
        "{e}"
    );
    assert!(
        e.contains("posterior.yaml:9:16") && e.contains("strictly between -1 and 1"),
        "{e}"
    );
    assert!(
        e.contains("posterior.yaml:11:5") && e.contains("given twice"),
        "{e}"
    );
    assert!(
        e.contains("posterior.yaml:12:5") && e.contains("expected `[NAME, NAME, rho]`"),
        "{e}"
    );
    // std 0 is not a spread (a table beside it is read: its input varies
    // along the axis, tests/it/commands/positioning_values.rs).
    let e = run(
        "table",
        "machine: gantry_grinder\nvalues:\n  dxx: {points: [[0, 0], [1000, 0.005]]}\n  dxz: {value: 0.001, std: 0}\n",
    );
    assert!(!e.contains("`dxx`"), "{e}");
    assert!(
        e.contains("posterior.yaml:4:3") && e.contains("std 0"),
        "{e}"
    );
    // The values file's own rules come first (an unknown error name).
    let e = run(
        "values",
        "machine: gantry_grinder\nvalues:\n  dxq: {value: 0.001, std: 0.001}\n",
    );
    assert!(
        e.contains("posterior.yaml:3:3") && e.contains("did you mean `dxx`"),
        "{e}"
    );
}

#[test]
fn nominal_sizes_and_files_keep_their_kinds() {
    let values = posterior_file("kinds", POSTERIOR);
    let e = unwrapped(&fails(&[
        "sensitivity",
        &machine_path(),
        "--kind",
        "geometric",
        "--values",
        &values,
    ]));
    assert!(
        e.contains("a values file applies to --kind reliability"),
        "{e}"
    );
    let e = unwrapped(&fails(&[
        "sensitivity",
        &machine_path(),
        "--values",
        "linear=0.001",
    ]));
    assert!(
        e.contains("--values applies only to --kind geometric"),
        "{e}"
    );
    // The geometric kind still takes nominal sizes.
    let doc = ok_json(&[
        "sensitivity",
        &machine_path(),
        "--kind",
        "geometric",
        "--values",
        "linear=0.002,angular=0.001deg",
        "--at",
        "x=0,y=0,z=600",
        "--format",
        "json",
    ]);
    assert!(doc.is_object());
}

/// A tolerance limit state that hides its affine view, so that FORM iterates
/// (HL-RF through the correlated Jacobian), the importance sampling scans
/// its lines and Monte Carlo samples `x = T(u)`: the general routes.
struct Hidden(reliability::ToleranceLimitState);

impl reliability::LimitState for Hidden {
    fn dim(&self) -> usize {
        self.0.dim()
    }
    fn branch(&self, b: usize, x: &[f64], gradient: Option<&mut [f64]>) -> f64 {
        self.0.branch(b, x, gradient)
    }
    fn depends_on(&self, j: usize) -> bool {
        self.0.depends_on(j)
    }
}

#[test]
fn the_general_routes_meet_the_closed_form_with_correlated_inputs() {
    use reliability::{
        sensitivity, Event, Form, ImportanceSampling, MonteCarlo, Posterior, Sampler,
        SensitivityMethod, ToleranceLimitState,
    };
    let m = load_example(MACHINE);
    let law = Law::of(&m);
    let dir = scratch("general");
    let posterior = Posterior::read(&write(&dir, "p.yaml", POSTERIOR), &m).unwrap();
    let inputs = posterior.inputs(&m).unwrap();
    assert_eq!(inputs.correlations().len(), 3);
    for (q, c) in [
        ([1000.0, 1400.0, -1500.0], 0),
        ([250.0, 800.0, 750.0], 1),
        ([750.0, 1000.0, 0.0], 2),
    ] {
        let a = row(&m, &q, c);
        let (want, beta) = law.reliability(&a);
        let ls =
            ToleranceLimitState::component(a.clone(), I, chain_core::model::Sided::Upper).unwrap();
        let event = Event::new(&inputs, Hidden(ls)).unwrap();
        let form = Form::default().run(&event).unwrap();
        assert!(!form.exact && form.branches[0].iterations > 0);
        assert!(
            close(form.beta, beta, 1e-9),
            "HL-RF β {} vs {beta}",
            form.beta
        );
        assert!(close(1.0 - form.reliability, 1.0 - want, 1e-8));
        let is = ImportanceSampling {
            samples: 400,
            seed: 5,
            form: Form::default(),
            cov: None,
        }
        .run(&event)
        .unwrap();
        assert!(
            close(is.pf, 1.0 - want, 1e-8),
            "IS {} vs {}",
            is.pf,
            1.0 - want
        );
        let mc = MonteCarlo {
            samples: 200_000,
            seed: 9,
            cov: None,
        }
        .run(&event)
        .unwrap();
        assert!(
            (mc.pf - (1.0 - want)).abs() <= 4.0 * mc.std_error + 1e-12,
            "MC {} ± {} vs {}",
            mc.pf,
            mc.std_error,
            1.0 - want
        );
        // The FORM-route sensitivities equal the exact ones on a linear g.
        let s = sensitivity(&event, &form).unwrap();
        assert_eq!(s.method, SensitivityMethod::Form);
        let sd = law.variance(&a).sqrt();
        let phi = (-0.5 * beta * beta).exp() / (2.0 * std::f64::consts::PI).sqrt();
        for (j, e) in s.inputs.iter().enumerate() {
            let dsd = -phi * beta * a[j] * law.weight(&a, j) / (sd * sd);
            let dmu = -phi * a[j] / sd;
            let scale = phi / sd * 1e-7;
            assert!(
                (e.dr_dstd - dsd).abs() <= 1e-6 * dsd.abs() + scale,
                "{j}: {} vs {dsd}",
                e.dr_dstd
            );
            assert!((e.dr_dmean - dmu).abs() <= 1e-6 * dmu.abs() + scale, "{j}");
        }
        let total: f64 = s.inputs.iter().map(|e| e.importance).sum();
        assert!((total - 1.0).abs() < 1e-12);
    }
}

/// A redundant error written `carried_by` its carriers (what `chain identify
/// --values-out` writes for an error the least-squares subset fixed because
/// estimated ones carry its effect) is an exact input: FORM is the closed
/// form with its std 0 and its value as mean, the sampling methods agree
/// with it, and the acceptance probability lists no sensitivity for it
/// (docs/posterior.md, "Fixed and carried").
#[test]
fn carried_errors_are_exact_inputs() {
    let m = load_example(MACHINE);
    let text = POSTERIOR.replace(
        "correlation:",
        "  ezx: {value: 2.0e-6, carried_by: [dxx, eyx]}\ncorrelation:",
    );
    let values = posterior_file("carried", &text);
    let mut law = Law::of(&m);
    let j = m.error_index("ezx").unwrap();
    // Without carried_by the statistics spread (0.05/6000 rad) is kept.
    assert!(law.std[j] > 8e-6);
    law.mean[j] = 2.0e-6;
    law.std[j] = 0.0;
    let doc = reliability_json(&values, &[]);
    let mut checked = 0;
    let mut moved = 0.0f64;
    for (k, case) in doc["results"].as_array().unwrap().iter().enumerate() {
        if k % 11 != 0 {
            continue;
        }
        let c = (COMPONENTS.iter())
            .position(|n| case["component"] == *n)
            .unwrap();
        let q = q_of(&m, &case["point"]);
        let a = row(&m, &q, c);
        let (want, beta) = law.reliability(&a);
        assert!(close(case["beta"].as_f64().unwrap(), beta, 1e-8), "{case}");
        assert_eq!(case["exact"], true);
        let mut spread = Law::of(&m);
        spread.mean[j] = 2.0e-6;
        moved = moved.max((spread.reliability(&a).0 - want).abs());
        checked += 1;
    }
    assert!(checked >= 30);
    // Its spread would have mattered: the carried input changes R.
    assert!(moved > 1e-4, "{moved}");
    assert_eq!(doc["posterior"]["values"][4]["carried_by"][1], "eyx");
    // Monte Carlo over the same inputs agrees within its standard error.
    let mc = reliability_json(
        &values,
        &[
            "--method",
            "mc",
            "--samples",
            "20000",
            "--grid",
            "x=500",
            "--grid",
            "y=1000",
            "--grid",
            "z=0",
        ],
    );
    for case in mc["results"].as_array().unwrap() {
        let c = (COMPONENTS.iter())
            .position(|n| case["component"] == *n)
            .unwrap();
        let a = row(&m, &q_of(&m, &case["point"]), c);
        let want = law.reliability(&a).0;
        let pf = 1.0 - case["reliability"].as_f64().unwrap();
        let se = (pf.max(1e-5) * (1.0 - pf) / 20000.0).sqrt();
        assert!((pf - (1.0 - want)).abs() <= 4.0 * se, "{case}: {want}");
    }
    // The acceptance probability runs; a fixed input has no sensitivity.
    let acc = reliability_json(&values, &["--acceptance"]);
    let sens = acc["acceptance"]["sensitivity"].as_array().unwrap();
    assert_eq!(sens.len(), m.errors.len() - 1);
    assert!(sens.iter().all(|s| s["error"] != "ezx"));
    let p = acc["acceptance"]["probability"].as_f64().unwrap();
    assert!(p > 0.0 && p < 1.0, "{p}");
}

/// `carried_by`'s refusals, located: beside a std, an unknown carrier
/// (with the closest name), the entry itself, a table, and a carrier the
/// file gives without a std.
#[test]
fn carried_by_refusals_are_located() {
    let run = |name: &str, entry: &str| {
        let text = format!("machine: gantry_grinder\nvalues:\n  dxx: {{value: 0.004, std: 0.003}}\n  dxz: 0.001\n  {entry}\n");
        let values = posterior_file(&format!("carried-{name}"), &text);
        unwrapped(&fails(&[
            "reliability",
            &machine_path(),
            "--values",
            &values,
        ]))
    };
    let e = run("with-std", "ezx: {value: 0, std: 1e-6, carried_by: [dxx]}");
    assert!(
        e.contains("posterior.yaml:5:") && e.contains("both a `std` and `carried_by`"),
        "{e}"
    );
    let e = run("unknown", "ezx: {value: 0, carried_by: [dxq]}");
    assert!(
        e.contains("posterior.yaml:5:32") && e.contains("did you mean `dxx`"),
        "{e}"
    );
    assert!(e.contains("values.ezx.carried_by[0]"), "{e}");
    let e = run("self", "ezx: {value: 0, carried_by: [dxx, ezx]}");
    assert!(
        e.contains("posterior.yaml:5:37") && e.contains("`ezx` cannot carry itself"),
        "{e}"
    );
    let e = run("list", "ezx: {value: 0, carried_by: dxx}");
    assert!(e.contains("must be a list of error names"), "{e}");
    let e = run(
        "table",
        "ezx: {points: [[0, 0], [1000, 1e-6]], carried_by: [dxx]}",
    );
    assert!(
        e.contains("`carried_by` belongs to a constant `value`"),
        "{e}"
    );
    let e = run("no-std", "ezx: {value: 0, carried_by: [dxz]}");
    assert!(
        e.contains("posterior.yaml:5:3")
            && e.contains("`ezx` is carried by `dxz`, which has no `std`"),
        "{e}"
    );
}
