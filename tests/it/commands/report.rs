//! `chain report` (docs/report.md): the example calibration's page against
//! the report's JSON (every number the page shows carries its place in the
//! JSON and its full value, and equals it), against each command run on its
//! own (the same documents), self-contained (no external reference, no
//! script), one section per part; and every refusal of a calibration file
//! located.

use crate::common;

use common::cli::{fails, ok_json, ok_stdout, scratch, unwrapped, write};
use serde_json::Value;

/// The JSON value at a dotted path (list items by index).
fn at<'a>(doc: &'a Value, key: &str) -> &'a Value {
    key.split('.').fold(doc, |node, part| match node {
        Value::Array(items) => &items[part.parse::<usize>().unwrap()],
        _ => &node[part],
    })
}

/// Every `data-key="K" data-value="V"` pair of the page.
fn keyed(html: &str) -> Vec<(String, String)> {
    let mut out = Vec::new();
    let mut rest = html;
    while let Some(i) = rest.find("data-key=\"") {
        rest = &rest[i + 10..];
        let key = &rest[..rest.find('"').unwrap()];
        let after = &rest[key.len() + 1..];
        if let Some(v) = after.strip_prefix(" data-value=\"") {
            out.push((key.to_string(), v[..v.find('"').unwrap()].to_string()));
        }
    }
    out
}

#[test]
fn the_example_report_is_its_documents() {
    let cal = common::example_file("calibration/vmc3.yaml");
    let cal = cal.to_str().unwrap();
    let html = ok_stdout(&["report", cal]);
    let doc = ok_json(&["report", cal, "--format", "json"]);
    // Every number shown is the JSON's.
    let pairs = keyed(&html);
    assert!(pairs.len() > 200, "{}", pairs.len());
    for (key, value) in &pairs {
        let want = at(&doc, key);
        match want {
            Value::Bool(b) => assert_eq!(value, &b.to_string(), "{key}"),
            // serde_json's float reading is within an ulp or two of the
            // exact one (the page's value is the shortest round trip).
            v => {
                let (got, want) = (value.parse::<f64>().unwrap(), v.as_f64().unwrap());
                assert!(
                    (got - want).abs() <= 1e-15 * want.abs(),
                    "{key}: {got} {want}"
                );
            }
        }
    }
    // One section per part, in order.
    let mut from = 0;
    for id in [
        "cover",
        "summary",
        "positioning-x",
        "map",
        "identify",
        "export",
        "circular",
        "thermal",
        "reproduce",
    ] {
        let at = html[from..]
            .find(&format!("id=\"{id}\""))
            .unwrap_or_else(|| panic!("section {id}"));
        from += at;
    }
    // Self-contained: no script, no reference out of the page (the SVG
    // namespace is a name, not a fetch).
    let lower = html.to_lowercase();
    for banned in ["<script", "src=", "@import", "url(", "<link", "href=\"http"] {
        assert!(!lower.contains(banned), "{banned}");
    }
    // The charts inline: the positioning run's, the map's, the circles'.
    assert!(lower.matches("<svg").count() >= 10);
    // The sections' documents are the commands' own documents.
    let ex = |p: &str| common::example_file(p).to_str().unwrap().to_string();
    let positioning = ok_json(&[
        "positioning",
        &ex("positioning/x_axis_runs.csv"),
        "--format",
        "json",
    ]);
    assert_eq!(
        doc["positioning"][0]["document"]["axis"],
        positioning["axis"]
    );
    let circular = ok_json(&["circular", &ex("circular/runs.csv"), "--format", "json"]);
    assert_eq!(doc["circular"]["document"]["runs"], circular["runs"]);
    assert_eq!(
        doc["circular"]["document"]["diagnosis"],
        circular["diagnosis"]
    );
    let identify = ok_json(&[
        "identify",
        &ex("measurements/vmc3_probe.yaml"),
        "--measurements",
        &ex("measurements/interferometer.csv"),
        "--holdout",
        "0.2",
        "--seed",
        "1",
        "--format",
        "json",
    ]);
    assert_eq!(doc["identify"]["estimates"], identify["estimates"]);
    assert_eq!(
        doc["identify"]["validation"]["after"],
        identify["validation"]["after"]
    );
    let map = ok_json(&[
        "map",
        &ex("machines/vmc3.yaml"),
        "--values",
        &ex("values/vmc3.yaml"),
        "--param",
        "L=150",
        "--compensated",
        "linuxcnc",
        "--format",
        "json",
    ]);
    assert_eq!(doc["map"]["document"]["summary"], map["summary"]);
    assert_eq!(
        doc["map"]["document"]["compensated"]["summary"],
        map["compensated"]["summary"]
    );
    let thermal = ok_json(&[
        "thermal",
        &ex("thermal/spindle_drift.csv"),
        "--fit",
        "--holdout",
        "0.25",
        "--lag",
        "--format",
        "json",
    ]);
    assert_eq!(doc["thermal"]["document"]["channels"], thermal["channels"]);
    // The controller's files: the committed example export's, by size
    // (python/tests/test_report.py compares their SHA-256).
    for f in doc["export"]["files"].as_array().unwrap() {
        let name = f["path"].as_str().unwrap();
        let bytes =
            std::fs::read(common::example_file(&format!("export/linuxcnc/{name}"))).unwrap();
        assert_eq!(f["bytes"].as_u64(), Some(bytes.len() as u64), "{name}");
    }
    // The verdicts: |value| <= tolerance, and the example's B (4.987 µm)
    // within its 5 µm.
    for v in doc["positioning"][0]["verdicts"].as_array().unwrap() {
        let (value, tol) = (
            v["value"].as_f64().unwrap(),
            v["tolerance"].as_f64().unwrap(),
        );
        assert_eq!(v["pass"].as_bool(), Some(value.abs() <= tol), "{v}");
    }
    // The inputs' checksums: the calibration file's own first.
    let first = &doc["inputs"][0];
    assert_eq!(first["role"], "calibration");
    assert_eq!(first["sha256"].as_str().unwrap().len(), 64);
}

/// A positioning axis corrected to 20 °C (`temperature`) is `chain
/// positioning --axis-temperature ... --axis-expansion ...`'s document.
#[test]
fn a_positioning_axis_at_20_c_is_the_command_s() {
    let dir = scratch("report-temperature");
    let ex = |p: &str| common::example_file(p).to_str().unwrap().to_string();
    let runs = ex("positioning/x_axis_runs.csv");
    let cal = write(
        &dir,
        "warm.yaml",
        &format!(
            "machine: {}\npositioning:\n  - axis: x\n    runs: {runs}\n    temperature: {{axis: 23.5, expansion: 11.5, instrument: 20.4}}\n",
            ex("machines/vmc3.yaml")
        ),
    );
    let doc = ok_json(&["report", cal.to_str().unwrap(), "--format", "json"]);
    let alone = ok_json(&[
        "positioning",
        &runs,
        "--axis-temperature",
        "23.5",
        "--axis-expansion",
        "11.5",
        "--instrument-temperature",
        "20.4",
        "--format",
        "json",
    ]);
    let got = &doc["positioning"][0]["document"];
    assert_eq!(got["axis"], alone["axis"]);
    assert_eq!(got["temperature"], alone["temperature"]);
    assert!(got["temperature"].is_object());
    let html = ok_stdout(&["report", cal.to_str().unwrap()]);
    assert!(html.contains("corrected to 20 °C"));
    // A missing expansion coefficient, located.
    let bad = write(
        &dir,
        "cold.yaml",
        &format!(
            "machine: {}\npositioning:\n  - axis: x\n    runs: {runs}\n    temperature: {{axis: 23.5}}\n",
            ex("machines/vmc3.yaml")
        ),
    );
    let err = unwrapped(&fails(&["report", bad.to_str().unwrap()]));
    assert!(
        err.contains("cold.yaml:5") && err.contains("has no `expansion`"),
        "{err}"
    );
}

#[test]
fn calibration_refusals_are_located() {
    let dir = scratch("report-refusals");
    let ex = |p: &str| common::example_file(p).to_str().unwrap().to_string();
    let check = |name: &str, text: &str, words: &[&str]| {
        let path = write(&dir, name, text);
        let err = unwrapped(&fails(&["report", path.to_str().unwrap()]));
        for w in words {
            assert!(err.contains(w), "{name}: `{w}` not in {err}");
        }
    };
    let machine = ex("machines/vmc3.yaml");
    check(
        "missing.yaml",
        &format!("machine: {machine}\nvalues: no/such/values.yaml\n"),
        &[
            "missing.yaml:2",
            "cannot read",
            "no/such/values.yaml",
            "values",
        ],
    );
    check(
        "unknown.yaml",
        &format!("machine: {machine}\ncustomr: X\n"),
        &["unknown.yaml:2", "unknown key `customr`", "customer"],
    );
    check(
        "nomachine.yaml",
        "title: x\n",
        &["nomachine.yaml:1", "no `machine`"],
    );
    check(
        "controller.yaml",
        &format!(
            "machine: {machine}\nvalues: {}\nexport: {{controller: fanuc}}\n",
            ex("values/vmc3.yaml")
        ),
        &[
            "controller.yaml:3",
            "`fanuc` is not a controller",
            "linuxcnc",
        ],
    );
    check(
        "novalues.yaml",
        &format!("machine: {machine}\nexport: {{controller: linuxcnc}}\n"),
        &["novalues.yaml:2", "give `values` too"],
    );
    check(
        "figure.yaml",
        &format!(
            "machine: {machine}\npositioning:\n  - axis: x\n    runs: {}\n    tolerances: {{A: 0.01, Q: 0.1}}\n",
            ex("positioning/x_axis_runs.csv")
        ),
        &["figure.yaml:5", "unknown key `Q`", "positioning[0].tolerances.Q"],
    );
    check(
        "negative.yaml",
        &format!(
            "machine: {machine}\npositioning:\n  - axis: x\n    runs: {}\n    tolerances: {{A: -0.01}}\n",
            ex("positioning/x_axis_runs.csv")
        ),
        &["negative.yaml:5", "must be positive"],
    );
    check(
        "holdout.yaml",
        &format!(
            "machine: {machine}\nidentify: {{measurements: {}, holdout: 2}}\n",
            ex("measurements/interferometer.csv")
        ),
        &["holdout.yaml:2", "a fraction in (0, 1)"],
    );
    check(
        "twice.yaml",
        &format!(
            "machine: {machine}\npositioning:\n  - {{axis: x, runs: {r}}}\n  - {{axis: x, runs: {r}}}\n",
            r = ex("positioning/x_axis_runs.csv")
        ),
        &["twice.yaml:4", "axis `x` has positioning runs twice"],
    );
    let runs = ex("positioning/x_axis_runs.csv");
    let measurements = ex("measurements/interferometer.csv");
    check(
        "plane.yaml",
        &format!(
            "machine: {machine}\ncircular: {{runs: {}, plane: xz}}\n",
            ex("circular/runs.csv")
        ),
        &["plane.yaml:2", "expected a plane: xy, yz or zx, found `xz`"],
    );
    check(
        "seed.yaml",
        &format!("machine: {machine}\nidentify: {{measurements: {measurements}, seed: 3}}\n"),
        &["seed.yaml:2", "give `holdout` too"],
    );
    check(
        "validate.yaml",
        &format!("machine: {machine}\nidentify: {{measurements: {measurements}, holdout: 0.2, validate: {measurements}}}\n"),
        &["validate.yaml:2", "`holdout` with `validate`"],
    );
    check(
        "k.yaml",
        &format!("machine: {machine}\npositioning:\n  - {{axis: x, runs: {runs}, k: 0}}\n"),
        &["k.yaml:3", "must be positive"],
    );
    // A refusal inside a named file is that file's, located there.
    let bad_runs = write(
        &dir,
        "bad_runs.csv",
        "target,direction,run,deviation\n0,up,1,x\n",
    );
    check(
        "badruns.yaml",
        &format!(
            "machine: {machine}\npositioning:\n  - {{axis: x, runs: {}}}\n",
            bad_runs.display()
        ),
        &["bad_runs.csv:2"],
    );
}
