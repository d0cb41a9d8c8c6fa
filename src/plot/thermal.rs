//! The figure of `chain thermal --plot`: one page, the time axis in hours
//! shared by its panels: the displacement channels' drift (µm) with, after
//! a fit, each model's prediction and the end of the fit period; the
//! temperatures (°C); the loads, if any.

use chain_core::measured::thermal::{drift, ChannelKind, DriftTest};

use crate::ops::thermal::Thermal;
use crate::plot::{self, Chart, Figures, Legend, Series, XyChart};

/// The most points a series is drawn with (every k-th sample beyond).
const MAX_POINTS: usize = 2000;

/// Panel size (pixels): three make a printed page.
const PANEL: (u32, u32) = (1100, 420);

/// `(hours, value)` of every k-th sample, the last one always.
fn thinned(time: &[f64], values: &[f64]) -> Vec<(f64, f64)> {
    let step = time.len().div_ceil(MAX_POINTS).max(1);
    let mut out: Vec<(f64, f64)> = (0..time.len())
        .step_by(step)
        .map(|k| (time[k] / 3600.0, values[k]))
        .collect();
    let last = time.len() - 1;
    if last % step != 0 {
        out.push((time[last] / 3600.0, values[last]));
    }
    out
}

/// `thermal`: the drift, temperature and load panels of the test.
pub fn charts(test: &DriftTest, thermal: &Thermal) -> Figures {
    let doc = &thermal.document;
    let hours = "time (h)";
    let mut drift_panel = XyChart::new(
        format!(
            "ISO 230-3 drift test {}: {} samples over {:.2} h",
            doc.file,
            doc.samples,
            doc.duration / 3600.0
        ),
        hours,
        "drift δ = x(t) − x(0) (µm)",
    )
    .legend(Legend::UpperLeft)
    .hline(0.0);
    drift_panel.size = PANEL;
    let displacements: Vec<_> = test.of(ChannelKind::Displacement).collect();
    let (mut lo, mut hi) = (0.0f64, 0.0f64);
    for (i, c) in displacements.iter().enumerate() {
        let um = c.mm_per_unit() * 1e3;
        let d: Vec<f64> = drift(c).iter().map(|x| x * um).collect();
        lo = d.iter().fold(lo, |a, &b| a.min(b));
        hi = d.iter().fold(hi, |a, &b| a.max(b));
        let range = doc.channels.get(i).map_or(0.0, |ch| ch.range * um);
        drift_panel = drift_panel.series(
            Series::line(
                format!("{} (range {range:.2} µm)", c.name),
                thinned(&test.time, &d),
            )
            .color(plot::color(i))
            .width(1),
        );
        if let Some(p) = thermal.predictions.iter().find(|p| p.channel == c.name) {
            let predicted: Vec<f64> = p.predicted.iter().map(|x| x * um).collect();
            let after = doc.channels.get(i).and_then(|ch| ch.holdout.as_ref());
            let label = match after {
                Some(h) => format!("its model (held out: rms {:.2} µm)", h.rms_after * um),
                None => "its model".to_string(),
            };
            drift_panel = drift_panel.series(
                Series::line(label, thinned(&test.time, &predicted))
                    .color(plot::color(i))
                    .width(3),
            );
        }
    }
    if let Some(fit) = &doc.fit {
        if fit.until < test.time[test.time.len() - 1] {
            let at = fit.until / 3600.0;
            drift_panel = drift_panel.series(
                Series::line("end of the fit period", vec![(at, lo), (at, hi)])
                    .color(plot::GREY)
                    .width(1),
            );
        }
    }
    let mut temperature_panel =
        XyChart::new("Temperatures", hours, "temperature (°C)").legend(Legend::UpperLeft);
    temperature_panel.size = PANEL;
    for (i, c) in test.of(ChannelKind::Temperature).enumerate() {
        let range = doc.temperatures.get(i).map_or(0.0, |t| t.range);
        temperature_panel = temperature_panel.series(
            Series::line(
                format!("{} (range {range:.2} °C)", c.name),
                thinned(&test.time, &c.values),
            )
            .color(plot::color(i)),
        );
    }
    let mut panels = vec![drift_panel];
    if !temperature_panel.series.is_empty() {
        panels.push(temperature_panel);
    }
    let loads: Vec<_> = test.of(ChannelKind::Load).collect();
    if !loads.is_empty() {
        let mut load_panel =
            XyChart::new("Loads", hours, "load (the column's unit)").legend(Legend::UpperLeft);
        load_panel.size = PANEL;
        for (i, c) in loads.iter().enumerate() {
            load_panel = load_panel.series(
                Series::line(c.name.clone(), thinned(&test.time, &c.values)).color(plot::color(i)),
            );
        }
        panels.push(load_panel);
    }
    let mut figures = Figures::default();
    figures.push("thermal", Chart::Stack(panels));
    figures
}
