//! The report as one self-contained HTML page (`docs/report.md`): no
//! script, no external reference (styles inline, charts inline SVG), A4
//! page breaks between sections for print. Every number shown from a
//! command's document carries `data-key` (its place in the report's JSON)
//! and `data-value` (the number in full), so that a reader — or a test —
//! can check the page against the documents.

use std::fmt::Write;

use super::{AxisSection, Report, Verdict};
use crate::ops::export::ExportDocument;

/// `&`, `<`, `>`, `"` and `'` escaped.
fn esc(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// A table cell of a number: shown with `places` decimals (scaled by
/// `scale`), its full value and key in attributes.
fn cell(key: &str, value: f64, scale: f64, places: usize) -> String {
    format!(
        "<td class=\"num\" data-key=\"{}\" data-value=\"{value:e}\">{:.places$}</td>",
        esc(key),
        value * scale
    )
}

/// A chart's SVG, without its XML declaration, inline.
fn figure(svg: &str) -> String {
    let body = match svg.find("<svg") {
        Some(at) => &svg[at..],
        None => svg,
    };
    format!("<figure class=\"chart\">{body}</figure>\n")
}

const STYLE: &str = "
@page { size: A4; margin: 14mm 12mm; }
body { font-family: 'DejaVu Sans', Helvetica, Arial, sans-serif; font-size: 10pt; color: #111; margin: 0 auto; max-width: 190mm; }
h1 { font-size: 18pt; margin: 0 0 4mm; }
h2 { font-size: 14pt; border-bottom: 1px solid #999; padding-bottom: 1mm; }
h3 { font-size: 11pt; }
section.page { break-before: page; page-break-before: always; }
table { border-collapse: collapse; margin: 2mm 0 4mm; }
th, td { border: 1px solid #bbb; padding: 1mm 2mm; text-align: left; vertical-align: top; }
td.num { text-align: right; font-variant-numeric: tabular-nums; }
td.pass { color: #0a6b12; font-weight: bold; }
td.fail { color: #b00020; font-weight: bold; }
code, .sum { font-family: 'DejaVu Sans Mono', monospace; font-size: 8pt; word-break: break-all; }
figure.chart { margin: 2mm 0; break-inside: avoid; page-break-inside: avoid; }
figure.chart svg { width: 100%; height: auto; max-height: 120mm; }
p.note { color: #444; }
";

/// The page.
pub fn html(report: &Report) -> String {
    let mut o = String::new();
    let title = (report.cover.title.clone())
        .unwrap_or_else(|| format!("Calibration report: {}", report.machine));
    let _ = write!(
        o,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{}</title>\n<style>{STYLE}</style>\n</head>\n<body>\n",
        esc(&title)
    );
    cover(&mut o, report, &title);
    summary(&mut o, report);
    for (index, axis) in report.positioning.iter().enumerate() {
        positioning(&mut o, index, axis);
    }
    map(&mut o, report);
    identify(&mut o, report);
    export(&mut o, report);
    circular(&mut o, report);
    thermal(&mut o, report);
    reproduce(&mut o, report);
    o.push_str("</body>\n</html>\n");
    o
}

fn cover(o: &mut String, r: &Report, title: &str) {
    let _ = writeln!(o, "<header id=\"cover\">\n<h1>{}</h1>", esc(title));
    let c = &r.cover;
    o.push_str("<table class=\"cover\">\n");
    let mut row = |name: &str, value: &Option<String>| {
        if let Some(v) = value {
            let _ = writeln!(o, "<tr><th>{name}</th><td>{}</td></tr>", esc(v));
        }
    };
    row("Customer", &c.customer);
    row("Machine serial", &c.machine_serial);
    row("Machine model", &Some(r.machine.clone()));
    row("Instrument", &c.instrument);
    row("Operator", &c.operator);
    row("Date", &c.date);
    for (i, (name, t)) in c.temperatures.iter().enumerate() {
        let _ = writeln!(
            o,
            "<tr><th>Temperature, {}</th>{}</tr>",
            esc(name),
            cell(&format!("cover.temperatures.{i}.1"), *t, 1.0, 2).replace("</td>", " °C</td>")
        );
    }
    o.push_str("</table>\n");
    if let Some(notes) = &c.notes {
        let _ = writeln!(o, "<p class=\"note\">{}</p>", esc(notes));
    }
    let _ = writeln!(
        o,
        "<p>Made by chain {} from the calibration file <code>{}</code>.</p>\n</header>",
        esc(r.chain_version),
        esc(&r.file)
    );
}

fn verdict_rows(o: &mut String, index: usize, axis: &str, verdicts: &[Verdict], unit: &str) {
    for (i, v) in verdicts.iter().enumerate() {
        let (class, word) = if v.pass {
            ("pass", "pass")
        } else {
            ("fail", "FAIL")
        };
        let key = format!("positioning.{index}.verdicts.{i}");
        let _ = writeln!(
            o,
            "<tr><td>{}</td><td>{}</td>{}{}<td>{unit}</td><td class=\"{class}\" data-key=\"{key}.pass\" data-value=\"{}\">{word}</td></tr>",
            esc(axis),
            esc(&v.figure),
            cell(&format!("{key}.value"), v.value, 1.0, 4),
            cell(&format!("{key}.tolerance"), v.tolerance, 1.0, 4),
            v.pass,
        );
    }
}

fn summary(o: &mut String, r: &Report) {
    o.push_str("<section class=\"page\" id=\"summary\">\n<h2>Summary</h2>\n");
    let with: Vec<(usize, &AxisSection)> = (r.positioning.iter().enumerate())
        .filter(|(_, a)| !a.verdicts.is_empty())
        .collect();
    if with.is_empty() {
        o.push_str("<p>The calibration file gives no tolerance for the positioning figures.</p>\n");
    } else {
        let all = with.iter().all(|(_, a)| a.verdicts.iter().all(|v| v.pass));
        let _ = writeln!(
            o,
            "<p>ISO 230-2 figures against the calibration file's tolerances: <strong>{}</strong>.</p>",
            if all { "every figure within tolerance" } else { "some figures out of tolerance" }
        );
        o.push_str("<table>\n<tr><th>axis</th><th>figure</th><th>value</th><th>tolerance</th><th>unit</th><th>verdict</th></tr>\n");
        for (index, a) in with {
            verdict_rows(o, index, &a.axis, &a.verdicts, unit_of(a));
        }
        o.push_str("</table>\n");
    }
    if let Some(m) = &r.map {
        let before = &m.document.full().map(|f| f.summary.volumetric.max);
        if let Some(b) = before {
            let after = m
                .document
                .compensated
                .as_ref()
                .map(|c| c.result.summary.volumetric.max);
            let _ = write!(o, "<p>Largest volumetric error over the map: <span data-key=\"map.document.summary.volumetric.max\" data-value=\"{b:e}\">{:.2} µm</span>", b * 1e3);
            if let Some(a) = after {
                let _ = write!(o, ", after compensation <span data-key=\"map.document.compensated.summary.volumetric.max\" data-value=\"{a:e}\">{:.2} µm</span>", a * 1e3);
            }
            o.push_str(".</p>\n");
        }
    }
    o.push_str("</section>\n");
}

fn unit_of(a: &AxisSection) -> &'static str {
    if a.document.axis_kind == "rotary" {
        "arcsec"
    } else {
        "mm"
    }
}

fn positioning(o: &mut String, index: usize, a: &AxisSection) {
    let axis = &a.axis;
    let d = &a.document;
    let unit = unit_of(a);
    let _ = writeln!(
        o,
        "<section class=\"page\" id=\"positioning-{}\">\n<h2>Positioning of axis {} (ISO 230-2)</h2>\n<p>Run file <code>{}</code>: {} targets, {} runs per direction, coverage factor k = {}.</p>",
        esc(axis),
        esc(axis),
        esc(&d.file),
        d.targets.len(),
        d.runs,
        d.k
    );
    if d.temperature.is_some() {
        o.push_str("<p>The deviations are corrected to 20 °C (ISO 230-2 and ISO 1; docs/positioning.md, \"At 20 °C\"), with the calibration file's temperatures.</p>\n");
    }
    o.push_str("<table>\n<tr><th>figure</th><th>value</th><th>unit</th></tr>\n");
    for (figure, value) in super::FIGURES {
        let value = value(&d.axis);
        let _ = writeln!(
            o,
            "<tr><td>{figure}</td>{}<td>{unit}</td></tr>",
            cell(
                &format!("positioning.{index}.document.axis.{figure}"),
                value,
                1.0,
                4
            )
        );
    }
    o.push_str("</table>\n");
    if !a.verdicts.is_empty() {
        o.push_str("<h3>Against the tolerances</h3>\n<table>\n<tr><th>axis</th><th>figure</th><th>value</th><th>tolerance</th><th>unit</th><th>verdict</th></tr>\n");
        verdict_rows(o, index, axis, &a.verdicts, unit);
        o.push_str("</table>\n");
    }
    for svg in &a.charts {
        o.push_str(&figure(svg));
    }
    o.push_str("</section>\n");
}

fn map(o: &mut String, r: &Report) {
    let Some(m) = &r.map else { return };
    let doc = &m.document;
    let _ = writeln!(
        o,
        "<section class=\"page\" id=\"map\">\n<h2>Volumetric error (values <code>{}</code>)</h2>",
        esc(&doc.values_file)
    );
    o.push_str("<table>\n<tr><th>over the map</th><th>px µm</th><th>py µm</th><th>pz µm</th><th>largest volumetric µm</th><th>RMS volumetric µm</th></tr>\n");
    let mut row = |name: &str, key: &str, s: &chain_core::built::MapSummary| {
        // Each component's deviation of the larger magnitude, signed.
        let big = |c: &chain_core::built::ComponentSummary, axis: &str| {
            let (end, v) = if c.max.abs() >= c.min.abs() {
                ("max", c.max)
            } else {
                ("min", c.min)
            };
            cell(&format!("{key}.summary.{axis}.{end}"), v, 1e3, 2)
        };
        let _ = writeln!(
            o,
            "<tr><td>{name}</td>{}{}{}{}{}</tr>",
            big(&s.px, "px"),
            big(&s.py, "py"),
            big(&s.pz, "pz"),
            cell(
                &format!("{key}.summary.volumetric.max"),
                s.volumetric.max,
                1e3,
                2
            ),
            cell(
                &format!("{key}.summary.volumetric.rms"),
                s.volumetric.rms,
                1e3,
                2
            ),
        );
    };
    if let Some(full) = doc.full() {
        row("before compensation", "map.document", &full.summary);
    }
    if let Some(c) = &doc.compensated {
        row(
            &format!("after {} compensation", c.controller),
            "map.document.compensated",
            &c.result.summary,
        );
    }
    o.push_str("</table>\n");
    for svg in &m.charts {
        o.push_str(&figure(svg));
    }
    o.push_str("</section>\n");
}

fn identify(o: &mut String, r: &Report) {
    let Some(run) = &r.identify else { return };
    let d = &run.document;
    let _ = writeln!(
        o,
        "<section class=\"page\" id=\"identify\">\n<h2>Identification</h2>\n<p>From <code>{}</code>: {} measurements, {} error parameters, rank {}; residual RMS <span data-key=\"identify.residual.rms\" data-value=\"{:e}\">{:.2} µm</span>.</p>",
        esc(&d.file),
        d.measurements,
        d.parameters,
        d.rank,
        d.residual.rms,
        d.residual.rms * 1e3
    );
    if let Some(v) = &d.validation {
        let p = &v.prediction;
        let _ = writeln!(
            o,
            "<h3>Prediction at held-out measurements</h3>\n<table>\n<tr><th>{} held-out records</th><th>RMS µm</th><th>largest µm</th></tr>\n<tr><td>measured (uncorrected)</td>{}{}</tr>\n<tr><td>after correction by the estimates</td>{}{}</tr>\n</table>",
            p.measurements,
            cell("identify.validation.before.rms", p.before.rms, 1e3, 2),
            cell("identify.validation.before.max", p.before.max, 1e3, 2),
            cell("identify.validation.after.rms", p.after.rms, 1e3, 2),
            cell("identify.validation.after.max", p.after.max, 1e3, 2),
        );
    }
    o.push_str("<h3>Estimates</h3>\n<table>\n<tr><th>error</th><th>value</th><th>std</th></tr>\n");
    for (name, e) in &d.estimates.0 {
        let std = match e.std {
            Some(s) => cell(&format!("identify.estimates.{name}.std"), s, 1.0, 9),
            None => "<td>—</td>".to_string(),
        };
        let _ = writeln!(
            o,
            "<tr><td>{}</td>{}{std}</tr>",
            esc(name),
            cell(&format!("identify.estimates.{name}.value"), e.value, 1.0, 9)
        );
    }
    o.push_str("</table>\n</section>\n");
}

fn export(o: &mut String, r: &Report) {
    let Some(x) = &r.export else { return };
    let _ = writeln!(
        o,
        "<section class=\"page\" id=\"export\">\n<h2>Written into the controller: {}</h2>\n<table>\n<tr><th>file</th><th>bytes</th><th>SHA-256</th></tr>",
        esc(x.controller)
    );
    for (i, f) in x.files.iter().enumerate() {
        let _ = writeln!(
            o,
            "<tr><td><code>{}</code></td><td class=\"num\">{}</td><td class=\"sum\" data-key=\"export.files.{i}.sha256\">{}</td></tr>",
            esc(&f.path),
            f.bytes,
            esc(&f.sha256)
        );
    }
    o.push_str("</table>\n");
    if let ExportDocument::Tables(t) = &x.document {
        let rep = &t.report;
        o.push_str("<table>\n<tr><th>term</th><th>largest position effect µm</th><th></th></tr>\n");
        for (what, key, terms) in [
            ("expressed", "expressed", &rep.expressed),
            ("left", "remaining", &rep.remaining),
        ] {
            for (j, term) in terms.iter().enumerate() {
                let _ = writeln!(
                    o,
                    "<tr><td>{}</td>{}<td>{what}</td></tr>",
                    esc(&term.name),
                    cell(
                        &format!("export.document.{key}.{j}.position"),
                        term.position,
                        1e3,
                        2
                    )
                );
            }
        }
        let _ = writeln!(
            o,
            "<tr><td>residual</td>{}<td>left at the check grid</td></tr>\n</table>",
            cell(
                "export.document.residual.position",
                rep.residual.position,
                1e3,
                2
            )
        );
    }
    o.push_str("</section>\n");
}

fn circular(o: &mut String, r: &Report) {
    let Some(c) = &r.circular else { return };
    let d = &c.document;
    let _ = writeln!(
        o,
        "<section class=\"page\" id=\"circular\">\n<h2>Circular tests (ISO 230-4)</h2>\n<p>Run file <code>{}</code>, about the least-squares centre.</p>\n<table>\n<tr><th>run</th><th>plane</th><th>feed mm/min</th><th>G ccw µm</th><th>G cw µm</th><th>G(b) µm</th><th>H µm</th></tr>",
        esc(&d.file)
    );
    for (i, run) in d.runs.iter().enumerate() {
        let g = |dir: Option<&chain_core::measured::circular::DirectionResult>, name: &str| {
            dir.map_or("<td>—</td>".to_string(), |x| {
                cell(
                    &format!("circular.document.runs.{i}.directions.{name}.G"),
                    x.g,
                    1e3,
                    2,
                )
            })
        };
        let opt = |v: Option<f64>, key: &str| {
            v.map_or("<td>—</td>".to_string(), |x| {
                cell(&format!("circular.document.runs.{i}.{key}"), x, 1e3, 2)
            })
        };
        let _ = writeln!(
            o,
            "<tr><td>{}</td><td>{}</td><td class=\"num\">{}</td>{}{}{}{}</tr>",
            esc(&run.run),
            run.plane.name(),
            run.feed.map_or("—".to_string(), |f| format!("{f}")),
            g(run.directions.ccw.as_ref(), "ccw"),
            g(run.directions.cw.as_ref(), "cw"),
            opt(run.g_b, "G_b"),
            opt(run.h, "H"),
        );
    }
    o.push_str("</table>\n<h3>Diagnosis</h3>\n<table>\n<tr><th>error</th><th>value</th><th>± 1σ</th><th>unit</th><th>share of G</th></tr>\n");
    for (i, e) in d.diagnosis.iter().enumerate() {
        if e.within_noise == Some(true) {
            continue;
        }
        let places = crate::ops::views::places(e.uncertainty);
        let _ = writeln!(
            o,
            "<tr><td>{}</td>{}<td class=\"num\">{}</td><td>{}</td><td class=\"num\">{:.0}%</td></tr>",
            esc(&e.term.label()),
            cell(&format!("circular.document.diagnosis.{i}.value"), e.value, 1.0, places),
            e.uncertainty.map_or("—".to_string(), |u| format!("{u:.places$}")),
            e.unit,
            100.0 * e.share
        );
    }
    o.push_str("</table>\n");
    for svg in &c.charts {
        o.push_str(&figure(svg));
    }
    o.push_str("</section>\n");
}

fn thermal(o: &mut String, r: &Report) {
    let Some(t) = &r.thermal else { return };
    let d = &t.document.document;
    let _ = writeln!(
        o,
        "<section class=\"page\" id=\"thermal\">\n<h2>Thermal drift (ISO 230-3)</h2>\n<p>Drift file <code>{}</code>: {} samples over {:.0} s.</p>\n<table>\n<tr><th>channel</th><th>unit</th><th>range</th><th>largest drift</th><th>fit RMS</th><th>held-out RMS before</th><th>held-out RMS after</th></tr>",
        esc(&d.file),
        d.samples,
        d.duration
    );
    for (i, c) in d.channels.iter().enumerate() {
        let key = format!("thermal.document.channels.{i}");
        let fit = c.fit.as_ref().map_or("<td>—</td>".to_string(), |f| {
            cell(&format!("{key}.fit.rms"), f.rms, 1.0, 3)
        });
        let (before, after) = match &c.holdout {
            Some(h) => (
                cell(&format!("{key}.holdout.rms_before"), h.rms_before, 1.0, 3),
                cell(&format!("{key}.holdout.rms_after"), h.rms_after, 1.0, 3),
            ),
            None => ("<td>—</td>".to_string(), "<td>—</td>".to_string()),
        };
        let _ = writeln!(
            o,
            "<tr><td>{}</td><td>{}</td>{}{}{fit}{before}{after}</tr>",
            esc(&c.name),
            esc(&c.unit),
            cell(&format!("{key}.range"), c.range, 1.0, 3),
            cell(&format!("{key}.max_drift"), c.max_drift, 1.0, 3),
        );
    }
    o.push_str("</table>\n");
    for svg in &t.charts {
        o.push_str(&figure(svg));
    }
    o.push_str("</section>\n");
}

fn reproduce(o: &mut String, r: &Report) {
    let _ = writeln!(
        o,
        "<section class=\"page\" id=\"reproduce\">\n<h2>Reproducing this report</h2>\n<p>chain {} made this page with <code>chain report {}</code>. The inputs, byte for byte:</p>\n<table>\n<tr><th>role</th><th>file</th><th>bytes</th><th>SHA-256</th></tr>",
        esc(r.chain_version),
        esc(&r.file)
    );
    for (i, f) in r.inputs.iter().enumerate() {
        let _ = writeln!(
            o,
            "<tr><td>{}</td><td><code>{}</code></td><td class=\"num\">{}</td><td class=\"sum\" data-key=\"inputs.{i}.sha256\">{}</td></tr>",
            esc(&f.role),
            esc(&f.path),
            f.bytes,
            esc(&f.sha256)
        );
    }
    o.push_str("</table>\n</section>\n");
}
