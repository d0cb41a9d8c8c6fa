//! An ISO 230-3 thermal drift test: the drift-test file, its evaluation
//! and the thermal model fitted per displacement channel
//! (`../shared/spec/thermal.md`; `docs/thermal.md`).
//!
//! A drift-test file is what a data logger writes during the test: one row
//! per sample, `time` in seconds, displacement channels (a sensor reading
//! the spindle-side artefact against the table side, in µm or mm),
//! temperatures (°C) and loads (spindle speed, ...). [`DriftTest::parse`]
//! reads and checks it (every refusal located by file, line and column);
//! [`evaluate`] gives, per displacement channel, the drift
//! `δ(t) = x(t) − x(0)`, its range (ISO 230-3's result for a direction),
//! its largest `|δ|` and when; per temperature its range; per sensor pair
//! (two sensors in one direction a distance `L` apart on the test mandrel,
//! ISO 230-3's five-sensor set-up) the tilt `(δ₁ − δ₂)/L`. The fit of a
//! thermal model is [`super::thermal_fit`].

use serde::Serialize;

use crate::diagnostic::Diagnostics;
#[cfg(feature = "csv")]
use crate::diagnostic::{closest, DriftProblem, Problem};
#[cfg(feature = "csv")]
use crate::model::Origin;

/// Drift-test files larger than this are refused.
pub const MAX_DRIFT_BYTES: usize = crate::bounded::MEASUREMENT_BYTES;

/// The names the time column may have.
pub const TIME_COLUMNS: [&str; 3] = ["time", "time(s)", "t(s)"];

/// What a column of a drift test holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ChannelKind {
    /// A displacement channel (µm or mm).
    Displacement,
    /// A temperature sensor (°C).
    Temperature,
    /// A load or condition (spindle speed, feed, ...).
    Load,
}

impl ChannelKind {
    /// `displacement`, `temperature` or `load`.
    pub fn name(self) -> &'static str {
        match self {
            ChannelKind::Displacement => "displacement",
            ChannelKind::Temperature => "temperature",
            ChannelKind::Load => "load",
        }
    }
}

/// One column of a drift test.
#[derive(Debug, Clone, PartialEq)]
pub struct Channel {
    /// Its header as written.
    pub name: String,
    /// What it holds.
    pub kind: ChannelKind,
    /// Its unit: `um` or `mm` (a displacement), `degC` (a temperature), or
    /// as its header says (a load; empty when it says none).
    pub unit: String,
    /// One value per sample.
    pub values: Vec<f64>,
}

impl Channel {
    /// Millimetres per unit of a displacement channel (1e-3 for µm).
    pub fn mm_per_unit(&self) -> f64 {
        if self.unit == "um" {
            1e-3
        } else {
            1.0
        }
    }
}

/// The columns the caller names for a role (where the headers carry no
/// unit); the others are classified by their header's unit.
#[derive(Debug, Clone, Default)]
pub struct Roles {
    /// Displacement channels.
    pub displacements: Vec<String>,
    /// Temperature sensors.
    pub temperatures: Vec<String>,
    /// Loads.
    pub loads: Vec<String>,
}

/// A drift test: the samples' times and every channel.
#[derive(Debug, Clone, PartialEq)]
pub struct DriftTest {
    /// The file as named in messages.
    pub file: String,
    /// Seconds since the start, increasing.
    pub time: Vec<f64>,
    /// The channels in the header's order.
    pub channels: Vec<Channel>,
}

/// Why a drift-test file was refused: its problems, located.
#[derive(Debug, thiserror::Error)]
#[cfg_attr(feature = "miette", derive(miette::Diagnostic))]
#[error(transparent)]
#[cfg_attr(feature = "miette", diagnostic(transparent))]
pub struct DriftFileError(pub Diagnostics);

impl DriftFileError {
    /// The located problems.
    pub fn diagnostics(&self) -> &Diagnostics {
        &self.0
    }
}

/// The kind and unit a header's unit suffix gives: `(um)`, `(µm)`, `(mm)`
/// a displacement, `(°C)`, `(degC)`, `(C)` a temperature.
pub fn classify(header: &str) -> Option<(ChannelKind, &'static str)> {
    let unit = header
        .trim_end()
        .strip_suffix(')')?
        .rsplit_once('(')?
        .1
        .trim();
    match unit {
        "um" | "µm" | "μm" => Some((ChannelKind::Displacement, "um")),
        "mm" => Some((ChannelKind::Displacement, "mm")),
        "°C" | "degC" | "C" | "ºC" => Some((ChannelKind::Temperature, "degC")),
        _ => None,
    }
}

/// A load's unit: what its header's parentheses say, if anything.
#[cfg(feature = "csv")]
fn load_unit(header: &str) -> String {
    (header.trim_end().strip_suffix(')'))
        .and_then(|h| h.rsplit_once('('))
        .map(|(_, u)| u.trim().to_string())
        .unwrap_or_default()
}

#[cfg(feature = "csv")]
impl DriftTest {
    /// Reads a drift-test file (CSV; spec `thermal.md`).
    pub fn read(path: &std::path::Path, roles: &Roles) -> Result<DriftTest, DriftFileError> {
        let file = path.display().to_string();
        let bytes = crate::load::read_file(path, &file, MAX_DRIFT_BYTES).map_err(DriftFileError)?;
        let text = crate::load::decode(&bytes, &file).map_err(DriftFileError)?;
        DriftTest::parse(text, &file, roles)
    }

    /// [`DriftTest::read`] over CSV text named `file`.
    pub fn parse(text: &str, file: &str, roles: &Roles) -> Result<DriftTest, DriftFileError> {
        let csv = crate::values::csv::CsvFile::parse_with(
            text,
            file,
            crate::diagnostic::DRIFT_FILE_HEADER,
        )
        .map_err(DriftFileError)?;
        let fail = |problems: Vec<(Origin, Problem)>| {
            DriftFileError(Diagnostics::located(file, text, problems).expect("a problem"))
        };
        let header = csv.header_origin();
        let names: Vec<String> = csv.names().map(str::to_string).collect();
        // Roles given by name, each a column, none twice.
        let mut given: Vec<(usize, ChannelKind)> = Vec::new();
        let mut problems = Vec::new();
        for (list, kind) in [
            (&roles.displacements, ChannelKind::Displacement),
            (&roles.temperatures, ChannelKind::Temperature),
            (&roles.loads, ChannelKind::Load),
        ] {
            for name in list {
                match csv.column(name) {
                    None => problems.push((
                        header.clone(),
                        DriftProblem::NotAColumn {
                            name: name.clone(),
                            role: kind.name(),
                            suggestion: closest(name, names.iter().map(String::as_str))
                                .map(str::to_string),
                        }
                        .into(),
                    )),
                    Some(c) => match given.iter().find(|(g, _)| *g == c) {
                        Some(&(_, first)) if first != kind => problems.push((
                            csv.header[c].1.clone(),
                            DriftProblem::TwoRoles {
                                name: name.clone(),
                                first: first.name(),
                                second: kind.name(),
                            }
                            .into(),
                        )),
                        Some(_) => {}
                        None => given.push((c, kind)),
                    },
                }
            }
        }
        let time = csv
            .header
            .iter()
            .position(|(h, _)| TIME_COLUMNS.contains(&h.as_str()));
        if time.is_none() {
            problems.push((header.clone(), DriftProblem::NoTime.into()));
        }
        if !problems.is_empty() {
            return Err(fail(problems));
        }
        let time = time.expect("checked");
        let mut channels: Vec<Channel> = Vec::new();
        for (c, (name, _)) in csv.header.iter().enumerate().filter(|&(c, _)| c != time) {
            // A column named for a role keeps its header's unit where the
            // header has one of that role's; a displacement without one is
            // in µm.
            let role = given.iter().find(|(g, _)| *g == c).map(|&(_, k)| k);
            let (kind, unit) = match (role, classify(name)) {
                (Some(kind), Some((k, unit))) if k == kind => (kind, unit.to_string()),
                (Some(ChannelKind::Displacement), _) => {
                    (ChannelKind::Displacement, "um".to_string())
                }
                (Some(ChannelKind::Temperature), _) => {
                    (ChannelKind::Temperature, "degC".to_string())
                }
                (Some(ChannelKind::Load), _) => (ChannelKind::Load, load_unit(name)),
                (None, Some((kind, unit))) => (kind, unit.to_string()),
                (None, None) => (ChannelKind::Load, load_unit(name)),
            };
            channels.push(Channel {
                name: name.clone(),
                kind,
                unit,
                values: Vec::with_capacity(csv.len()),
            });
        }
        if !channels.iter().any(|c| c.kind == ChannelKind::Displacement) {
            let problem = DriftProblem::NoDisplacement { columns: names };
            return Err(fail(vec![(header, problem.into())]));
        }
        // The rows: every cell a finite number, time increasing.
        let mut times: Vec<f64> = Vec::with_capacity(csv.len());
        let mut last: Option<(f64, usize)> = None;
        let rows = csv.read_rows(|row| {
            let mut values = Vec::with_capacity(row.len());
            for (text, origin) in row {
                let x = crate::tabular::number(text, &origin.key)
                    .map_err(|p| Box::new((origin.clone(), p.into())))?;
                values.push(x);
            }
            let (t, origin) = (values[time], &row[time].1);
            if let Some((previous, previous_line)) = last {
                if t <= previous {
                    let problem = DriftProblem::TimeNotIncreasing {
                        time: t,
                        previous,
                        previous_line,
                    };
                    return Err(Box::new((origin.clone(), problem.into())));
                }
            }
            last = Some((t, origin.line));
            Ok(values)
        });
        let rows = rows.map_err(fail)?;
        if rows.len() < 3 {
            let problem = DriftProblem::TooFewRows { rows: rows.len() };
            return Err(fail(vec![(header, problem.into())]));
        }
        for values in &rows {
            times.push(values[time]);
            let mut k = 0;
            for (c, x) in values.iter().enumerate() {
                if c != time {
                    channels[k].values.push(*x);
                    k += 1;
                }
            }
        }
        Ok(DriftTest {
            file: file.to_string(),
            time: times,
            channels,
        })
    }
}

impl DriftTest {
    /// The channels of `kind`, in the header's order.
    pub fn of(&self, kind: ChannelKind) -> impl Iterator<Item = &Channel> {
        self.channels.iter().filter(move |c| c.kind == kind)
    }

    /// The channel named `name`.
    pub fn channel(&self, name: &str) -> Option<&Channel> {
        self.channels.iter().find(|c| c.name == name)
    }

    /// The test's duration (s): the last time less the first.
    pub fn duration(&self) -> f64 {
        self.time[self.time.len() - 1] - self.time[0]
    }
}

/// Two displacement sensors in one direction a distance apart on the test
/// mandrel (ISO 230-3's five-sensor set-up): `first` the one nearer the
/// spindle nose.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Pair {
    /// The sensor nearer the spindle nose.
    pub first: String,
    /// The other.
    pub second: String,
    /// Their distance (mm).
    pub distance: f64,
}

/// Why a drift test cannot be evaluated as asked.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[cfg_attr(feature = "miette", derive(miette::Diagnostic))]
#[non_exhaustive]
pub enum ThermalError {
    /// A pair naming a channel that is not a displacement channel.
    #[error("pair `{first}:{second}`: `{name}` is not a displacement channel of {file} (they are {channels})")]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::thermal::pair)))]
    PairChannel {
        /// The pair's sensors.
        first: String,
        /// The other.
        second: String,
        /// The name that is not one.
        name: String,
        /// The file.
        file: String,
        /// Its displacement channels, listed.
        channels: String,
    },
    /// A pair's distance that is not a positive length, or a pair of one
    /// sensor.
    #[error("pair `{first}:{second}`: {reason}")]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::thermal::pair)))]
    PairShape {
        /// The pair's sensors.
        first: String,
        /// The other.
        second: String,
        /// What is wrong.
        reason: String,
    },
}

/// The drift of one displacement channel (its unit), and with a fit its
/// model and how well it predicts.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ChannelDrift {
    /// The column's header as written.
    pub name: String,
    /// `um` or `mm`.
    pub unit: String,
    /// `max δ − min δ` over the test.
    pub range: f64,
    /// The drift of the largest magnitude (signed).
    pub max_drift: f64,
    /// When it occurs (s).
    pub max_drift_at: f64,
    /// The fitted model (`--fit`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub model: Option<super::thermal_fit::ThermalModel>,
    /// How it fits the fit period.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fit: Option<super::thermal_fit::FitStats>,
    /// How it predicts the held-out samples.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub holdout: Option<super::thermal_fit::HoldoutStats>,
}

/// A temperature sensor's values over the test (°C).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TemperatureRange {
    /// The column's header.
    pub name: String,
    /// At the start.
    pub first: f64,
    /// Smallest.
    pub min: f64,
    /// Largest.
    pub max: f64,
    /// `max − min`.
    pub range: f64,
}

/// A sensor pair's tilt and the drift at the spindle nose.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PairDrift {
    /// The pair.
    #[serde(flatten)]
    pub pair: Pair,
    /// The range of the tilt `(δ₁ − δ₂)/L` (µrad).
    pub tilt_range: f64,
    /// The tilt of the largest magnitude (µrad, signed).
    pub max_tilt: f64,
    /// When (s).
    pub max_tilt_at: f64,
    /// The range of the drift at the spindle nose, the first sensor's (its
    /// unit).
    pub nose_range: f64,
}

/// The evaluation of a drift test (`chain thermal`), and with `--fit` the
/// models: the JSON document of the spec.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ThermalDocument {
    /// The drift-test file.
    pub file: String,
    /// The number of samples.
    pub samples: usize,
    /// The test's duration (s).
    pub duration: f64,
    /// The fit period (`--fit`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fit: Option<super::thermal_fit::FitPeriod>,
    /// Per displacement channel.
    pub channels: Vec<ChannelDrift>,
    /// Per temperature sensor.
    pub temperatures: Vec<TemperatureRange>,
    /// Per sensor pair.
    pub pairs: Vec<PairDrift>,
}

/// `δ(t) = x(t) − x(0)` of a channel.
pub fn drift(channel: &Channel) -> Vec<f64> {
    let x0 = channel.values[0];
    channel.values.iter().map(|x| x - x0).collect()
}

/// The smallest and largest of `values`, and the signed value of the
/// largest magnitude with its index.
fn extremes(values: &[f64]) -> (f64, f64, f64, usize) {
    let (mut lo, mut hi, mut big, mut at) = (f64::INFINITY, f64::NEG_INFINITY, 0.0f64, 0);
    for (k, &v) in values.iter().enumerate() {
        lo = lo.min(v);
        hi = hi.max(v);
        if v.abs() > big.abs() {
            big = v;
            at = k;
        }
    }
    (lo, hi, big, at)
}

/// Evaluates the drift test (module docs) with the sensor `pairs`.
pub fn evaluate(test: &DriftTest, pairs: &[Pair]) -> Result<ThermalDocument, ThermalError> {
    let displacements: Vec<&Channel> = test.of(ChannelKind::Displacement).collect();
    let channels = displacements
        .iter()
        .map(|c| {
            let d = drift(c);
            let (lo, hi, big, at) = extremes(&d);
            ChannelDrift {
                name: c.name.clone(),
                unit: c.unit.clone(),
                range: hi - lo,
                max_drift: big,
                max_drift_at: test.time[at],
                model: None,
                fit: None,
                holdout: None,
            }
        })
        .collect();
    let temperatures = test
        .of(ChannelKind::Temperature)
        .map(|c| {
            let (lo, hi, ..) = extremes(&c.values);
            TemperatureRange {
                name: c.name.clone(),
                first: c.values[0],
                min: lo,
                max: hi,
                range: hi - lo,
            }
        })
        .collect();
    let mut drifts = Vec::new();
    for pair in pairs {
        let find = |name: &str| {
            (displacements.iter().find(|c| c.name == name)).ok_or_else(|| {
                ThermalError::PairChannel {
                    first: pair.first.clone(),
                    second: pair.second.clone(),
                    name: name.to_string(),
                    file: test.file.clone(),
                    channels: (displacements.iter())
                        .map(|c| format!("`{}`", c.name))
                        .collect::<Vec<_>>()
                        .join(", "),
                }
            })
        };
        let shape = |reason: &str| ThermalError::PairShape {
            first: pair.first.clone(),
            second: pair.second.clone(),
            reason: reason.to_string(),
        };
        if pair.first == pair.second {
            return Err(shape("a pair is two sensors"));
        }
        if !(pair.distance.is_finite() && pair.distance > 0.0) {
            return Err(shape(&format!(
                "the distance {} mm is not a positive length",
                pair.distance
            )));
        }
        let (a, b) = (find(&pair.first)?, find(&pair.second)?);
        let (da, db) = (drift(a), drift(b));
        // (δ₁ − δ₂)/L in µrad, both in mm.
        let tilt: Vec<f64> = (da.iter().zip(&db))
            .map(|(x, y)| (x * a.mm_per_unit() - y * b.mm_per_unit()) / pair.distance * 1e6)
            .collect();
        let (lo, hi, big, at) = extremes(&tilt);
        let (nlo, nhi, ..) = extremes(&da);
        drifts.push(PairDrift {
            pair: pair.clone(),
            tilt_range: hi - lo,
            max_tilt: big,
            max_tilt_at: test.time[at],
            nose_range: nhi - nlo,
        });
    }
    Ok(ThermalDocument {
        file: test.file.clone(),
        samples: test.time.len(),
        duration: test.duration(),
        fit: None,
        channels,
        temperatures,
        pairs: drifts,
    })
}
