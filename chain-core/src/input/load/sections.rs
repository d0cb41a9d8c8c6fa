//! The `parameters`, `statistics` and `reliability` sections.

use std::collections::HashMap;

use super::bodies::Tree;
use super::{join, Fields, Loader, TreeReader};
use crate::diagnostic::{closest, Problem};
use crate::model::{
    Component, CorrelationEntry, Distribution, Parameter, ReliabilitySpec, Requirement, Sided,
    Statistic,
};
use crate::yaml::Node;

/// Keys of a statistics entry.
pub const STATISTICS_KEYS: &[&str] = &[
    "dist",
    "mean",
    "std",
    "tolerance",
    "sigma_rule",
    "min",
    "max",
    "shift",
    "scale",
    "shape",
    "mode",
    "cost_weight",
    "min_std",
];
/// Distributions (`machine-format.md` v1 and `reliability-v2.md` §1).
pub const DISTRIBUTIONS: &[&str] = &[
    "normal",
    "uniform",
    "lognormal",
    "truncated_normal",
    "weibull",
    "gumbel",
    "triangular",
    "rayleigh",
];
/// The keys of each v2 family (besides `dist`, `cost_weight`, `min_std`).
const FAMILY_KEYS: &[(&str, &[&str])] = &[
    (
        "lognormal",
        &["mean", "std", "tolerance", "sigma_rule", "shift"],
    ),
    (
        "truncated_normal",
        &["mean", "std", "tolerance", "sigma_rule", "min", "max"],
    ),
    ("weibull", &["scale", "shape", "shift"]),
    ("gumbel", &["mode", "scale"]),
    ("triangular", &["min", "mode", "max"]),
    ("rayleigh", &["scale", "shift"]),
];
/// The keys of the v2 families that neither `normal` nor `uniform` takes.
const V2_KEYS: &[&str] = &["shift", "scale", "shape", "mode"];
/// Keys of the reliability section.
pub const RELIABILITY_KEYS: &[&str] = &["tolerance", "sided", "grid", "requirement", "acceptance"];
/// The largest magnitude of a statistics number (`mean`, `std`, `min`, ...):
/// squared and summed over the errors in the moments, larger ones would
/// overflow to `inf`.
pub const MAX_STATISTIC: f64 = 1e100;

/// Keys of a reliability requirement.
pub const REQUIREMENT_KEYS: &[&str] = &["min", "mean"];
/// Component names.
pub const COMPONENTS: &[&str] = &crate::model::Component::NAMES;
/// Values of `sided`.
pub const SIDED: &[&str] = &["upper", "two"];

/// `sigma_rule` when `tolerance` is given without it.
pub const DEFAULT_SIGMA_RULE: f64 = 6.0;

/// The numeric keys of one statistics entry, as read (`None` absent,
/// `Some(None)` invalid and reported).
#[derive(Clone, Copy)]
struct Given {
    mean: Option<Option<f64>>,
    /// `std`, or `tolerance / sigma_rule`.
    spread: Option<Option<f64>>,
    min: Option<Option<f64>>,
    max: Option<Option<f64>>,
    shift: Option<Option<f64>>,
    scale: Option<Option<f64>>,
    shape: Option<Option<f64>>,
    mode: Option<Option<f64>>,
}

impl Loader {
    /// `parameters: {name: value | null}`.
    pub(super) fn parameters_section(&mut self, node: &Node) {
        let Some(entries) = self.entries(node, "parameters") else {
            return;
        };
        for (k, v) in entries {
            let path = join("parameters", k.as_str().unwrap_or(""));
            let Some(name) = self.ident(k, &path, "parameter") else {
                continue;
            };
            let value = if v.is_null() {
                None
            } else {
                self.finite(v, &path, "a parameter value")
            };
            let value = match value {
                Some(x) if x.abs() > super::PHYSICAL_SIZE => {
                    let problem = Problem::OutOfRange {
                        what: "a parameter value",
                        value: x,
                        range: super::PHYSICAL_RANGE,
                    };
                    self.report(v.span, &path, problem);
                    None
                }
                other => other,
            };
            self.parameter_index
                .entry(name.clone())
                .or_insert(self.parameters.len());
            self.parameters.push(Parameter {
                name,
                value,
                origin: k.span.origin(path),
            });
        }
    }

    /// `sensors:` (`docs/thermal.md`): the named conditions the thermal
    /// terms read, as a list of names (reference 20 °C, ISO 1) or a mapping
    /// of name → reference temperature (°C) or `{reference: °C}`. A sensor
    /// may not share a parameter's name (a measurement file's columns name
    /// both).
    pub(super) fn sensors_section(&mut self, node: &Node) {
        let named: Vec<(&Node, Option<&Node>)> = match (node.as_sequence(), node.as_mapping()) {
            (Some(items), _) => items.iter().map(|n| (n, None)).collect(),
            (None, Some(entries)) => entries.iter().map(|(k, v)| (k, Some(v))).collect(),
            _ => {
                self.wrong_type(
                    node,
                    "sensors",
                    "a list of sensor names or a mapping of name → reference °C",
                );
                return;
            }
        };
        for (i, (k, v)) in named.into_iter().enumerate() {
            let path = match v {
                None => crate::input::load::index("sensors", i),
                Some(_) => join("sensors", k.as_str().unwrap_or("")),
            };
            let Some(name) = self.ident(k, &path, "sensor") else {
                continue;
            };
            let reference = match v {
                None => Some(crate::model::REFERENCE_TEMPERATURE),
                Some(v) if v.is_null() => Some(crate::model::REFERENCE_TEMPERATURE),
                Some(v) if v.as_mapping().is_some() => {
                    let Some(f) = self.fields(v, v.span, &path, &["reference"]) else {
                        continue;
                    };
                    match f.get("reference") {
                        Some(r) => self.finite(r, &f.path("reference"), "a reference temperature"),
                        None => Some(crate::model::REFERENCE_TEMPERATURE),
                    }
                }
                Some(v) => self.finite(v, &path, "a reference temperature"),
            };
            let Some(reference) = reference else { continue };
            if let Some(first) = self.sensors.iter().find(|s| s.name == name) {
                let line = first.origin.line;
                self.report(k.span, path, Problem::SensorTwice { name, line });
                continue;
            }
            if self.parameter_index.contains_key(&name) {
                let problem = Problem::NameCollision {
                    name,
                    what: "sensor",
                    other: "parameter",
                };
                self.report(k.span, path, problem);
                continue;
            }
            self.sensors.push(crate::model::Sensor {
                name,
                reference,
                origin: k.span.origin(path),
            });
        }
    }

    /// `statistics: {error: {dist, ...}}`. `None` if any entry is invalid.
    pub(super) fn statistics_section(
        &mut self,
        node: &Node,
        tree: Option<&Tree>,
    ) -> Option<Vec<Statistic>> {
        let entries = self.entries(node, "statistics")?;
        let mut out = Vec::new();
        let mut complete = true;
        let error_index: HashMap<&str, usize> = tree
            .map(|t| {
                t.errors
                    .iter()
                    .enumerate()
                    .map(|(i, e)| (e.name.as_str(), i))
                    .collect()
            })
            .unwrap_or_default();
        for (k, v) in entries {
            let name = k.as_str().unwrap_or("");
            let path = join("statistics", name);
            // A sensor's entry: its temperature's distribution (°C).
            if let Some(sensor) = self.sensors.iter().position(|s| s.name == name) {
                for key in ["cost_weight", "min_std"] {
                    let given = (v.as_mapping().unwrap_or(&[]).iter())
                        .find(|(kk, _)| kk.as_str() == Some(key));
                    if let Some((kk, _)) = given {
                        let problem = Problem::SensorStatisticKey {
                            key,
                            sensor: name.to_string(),
                        };
                        self.report(kk.span, join(&path, key), problem);
                        complete = false;
                    }
                }
                match self.statistic(k, v, &path) {
                    Some((distribution, _, _)) => {
                        self.sensor_statistics.push(crate::model::SensorStatistic {
                            sensor,
                            distribution,
                            origin: k.span.origin(path),
                        })
                    }
                    None => complete = false,
                }
                continue;
            }
            let error = error_index.get(name).copied();
            if let Some(t) = tree {
                let function = t.functions.iter().find(|f| f.name == name);
                let known = self.seen_errors.contains(name) || self.refused(name);
                if error.is_none() && (function.is_some() || !known) {
                    let problem = match function {
                        // A function's name: its coefficients take statistics.
                        Some(f) => Problem::FunctionStatistics {
                            name: name.to_string(),
                            coefficients: f
                                .coefficients
                                .iter()
                                .filter_map(|(j, _)| t.errors.get(*j))
                                .map(|e| e.name.clone())
                                .collect(),
                        },
                        None => Problem::UnknownError {
                            name: name.to_string(),
                            suggestion: closest(name, t.errors.iter().map(|e| e.name.as_str()))
                                .map(str::to_string),
                        },
                    };
                    self.report(k.span, path.clone(), problem);
                }
            }
            let entry = self.statistic(k, v, &path);
            match (error, entry) {
                (Some(error), Some((distribution, cost_weight, min_std))) => out.push(Statistic {
                    error,
                    distribution,
                    cost_weight,
                    min_std,
                    origin: k.span.origin(path),
                }),
                _ => complete = false,
            }
        }
        complete.then_some(out)
    }

    /// True for the name of a refused function slot or one of its possible
    /// coefficients `<name>_…`: already reported where it was declared.
    fn refused(&self, name: &str) -> bool {
        self.failed_functions.iter().any(|f| {
            name == f
                || name
                    .strip_prefix(f.as_str())
                    .is_some_and(|rest| rest.starts_with('_'))
        })
    }

    /// An optional number-valued key: `None` if absent, `Some(None)` if
    /// invalid (reported).
    fn opt_num(
        &mut self,
        f: &Fields<'_>,
        key: &'static str,
        positive: bool,
    ) -> Option<Option<f64>> {
        let node = f.get(key)?;
        let path = f.path(key);
        let v = if positive {
            self.positive(node, &path, key)
        } else {
            self.finite(node, &path, key)
        };
        // Moments square these numbers and sum them over the errors: a
        // magnitude above `MAX_STATISTIC` would overflow to `inf`.
        Some(match v {
            Some(x) if x.abs() > MAX_STATISTIC => {
                self.report(
                    node.span,
                    &path,
                    Problem::OutOfRange {
                        what: key,
                        value: x,
                        range: "[-1e100, 1e100] (its square enters the moments)",
                    },
                );
                None
            }
            v => v,
        })
    }

    /// The key node of `key` (for locating conflicts), or the owner.
    fn key_span(f: &Fields<'_>, key: &str) -> crate::yaml::Span {
        f.entry(key).map_or(f.owner, |(k, _)| k.span)
    }

    /// One statistics entry: distribution, cost weight, min_std.
    fn statistic(
        &mut self,
        key: &Node,
        value: &Node,
        path: &str,
    ) -> Option<(Distribution, f64, Option<f64>)> {
        let before = self.errors.len();
        let f = self.fields(value, key.span, path, STATISTICS_KEYS)?;
        let dist = match f.get("dist") {
            Some(n) => self.keyword(n, &f.path("dist"), "distribution", DISTRIBUTIONS),
            None => Some("normal"),
        };
        let mean = self.opt_num(&f, "mean", false);
        let std = self.opt_num(&f, "std", true);
        let tolerance = self.opt_num(&f, "tolerance", true);
        let sigma_rule = self.opt_num(&f, "sigma_rule", true);
        let min = self.opt_num(&f, "min", false);
        let max = self.opt_num(&f, "max", false);
        let shift = self.opt_num(&f, "shift", false);
        let scale = self.opt_num(&f, "scale", true);
        let shape = self.opt_num(&f, "shape", true);
        let mode = self.opt_num(&f, "mode", false);
        let cost_weight = self.opt_num(&f, "cost_weight", true);
        let min_std = self.opt_num(&f, "min_std", true);
        if let Some(d @ ("normal" | "uniform")) = dist {
            for key in V2_KEYS {
                if let Some((k, _)) = f.entry(key) {
                    self.report(
                        k.span,
                        f.path(key),
                        Problem::KeyNotForDistribution { key, dist: d },
                    );
                }
            }
        }

        let conflict = |l: &mut Loader, first: &'static str, second: &'static str| {
            let span = Self::key_span(&f, second);
            l.report(span, f.path(second), Problem::Conflict { first, second });
        };
        if std.is_some() && tolerance.is_some() {
            conflict(self, "std", "tolerance");
        } else if std.is_some() && sigma_rule.is_some() {
            conflict(self, "std", "sigma_rule");
        }
        // The spread, from std or tolerance / sigma_rule.
        let spread = match (std, tolerance) {
            (Some(s), None) => Some(s),
            (None, Some(t)) => Some(match (t, sigma_rule) {
                (Some(t), None) => Some(t / DEFAULT_SIGMA_RULE),
                (Some(t), Some(Some(r))) => Some(t / r),
                _ => None,
            }),
            (None, None) => None,
            (Some(_), Some(_)) => Some(None),
        };

        let misspelt_spread = ["std", "tolerance", "min", "max"]
            .iter()
            .any(|k| f.suggested.contains(k));
        let distribution = match dist {
            Some("uniform") => {
                let bounds = min.is_some() || max.is_some();
                if bounds && spread.is_some() {
                    let first = if min.is_some() { "min" } else { "max" };
                    let second = if std.is_some() { "std" } else { "tolerance" };
                    conflict(self, first, second);
                    None
                } else if bounds && mean.is_some() {
                    conflict(self, if min.is_some() { "min" } else { "max" }, "mean");
                    None
                } else if bounds {
                    if min.is_none() {
                        self.missing(&f, "min");
                    }
                    if max.is_none() {
                        self.missing(&f, "max");
                    }
                    match (min.flatten(), max.flatten()) {
                        (Some(lo), Some(hi)) if lo < hi => {
                            Some(Distribution::Uniform { min: lo, max: hi })
                        }
                        (Some(lo), Some(hi)) => {
                            let span = f.get("max").map_or(f.owner, |n| n.span);
                            self.report(
                                span,
                                f.path("max"),
                                Problem::UniformBounds { min: lo, max: hi },
                            );
                            None
                        }
                        _ => None,
                    }
                } else if let Some(s) = spread {
                    let m = mean.unwrap_or(Some(0.0));
                    match (m, s) {
                        (Some(m), Some(s)) => {
                            let half = 3f64.sqrt() * s;
                            Some(Distribution::Uniform {
                                min: m - half,
                                max: m + half,
                            })
                        }
                        _ => None,
                    }
                } else {
                    if !misspelt_spread {
                        self.report(f.owner, path, Problem::MissingSpread { dist: "uniform" });
                    }
                    None
                }
            }
            Some(d) if d != "normal" => {
                let given = Given {
                    mean,
                    spread,
                    min,
                    max,
                    shift,
                    scale,
                    shape,
                    mode,
                };
                self.v2_distribution(&f, d, given, misspelt_spread)
            }
            Some(_) => {
                for key in ["min", "max"] {
                    if let Some((k, _)) = f.entry(key) {
                        let key = if key == "min" { "min" } else { "max" };
                        self.report(
                            k.span,
                            f.path(key),
                            Problem::KeyNotForDistribution {
                                key,
                                dist: "normal",
                            },
                        );
                    }
                }
                match (spread, mean.unwrap_or(Some(0.0))) {
                    (None, _) => {
                        if !misspelt_spread {
                            self.report(f.owner, path, Problem::MissingSpread { dist: "normal" });
                        }
                        None
                    }
                    (Some(Some(std)), Some(mean)) => Some(Distribution::Normal { mean, std }),
                    _ => None,
                }
            }
            None => None,
        };
        let cost_weight = cost_weight.unwrap_or(Some(1.0));
        let min_std = min_std.unwrap_or(Some(f64::NAN));
        if self.errors.len() != before {
            return None;
        }
        let min_std = min_std.filter(|v| !v.is_nan());
        Some((distribution?, cost_weight?, min_std))
    }

    /// A v2 family (`reliability-v2.md` §1): its keys only, the required
    /// ones present, the values defining a distribution. `None` when
    /// anything was reported.
    fn v2_distribution(
        &mut self,
        f: &Fields<'_>,
        dist: &'static str,
        g: Given,
        misspelt_spread: bool,
    ) -> Option<Distribution> {
        let allowed = FAMILY_KEYS
            .iter()
            .find(|(d, _)| *d == dist)
            .map_or(&[][..], |(_, k)| *k);
        for key in STATISTICS_KEYS {
            if matches!(*key, "dist" | "cost_weight" | "min_std") || allowed.contains(key) {
                continue;
            }
            if let Some((k, _)) = f.entry(key) {
                self.report(
                    k.span,
                    f.path(key),
                    Problem::KeyNotForDistribution { key, dist },
                );
            }
        }
        // A required key: its value (`None` if absent, reported, or invalid).
        // (What was reported makes the caller drop the entry.)
        let need = |l: &mut Loader, key: &'static str, v: Option<Option<f64>>| match v {
            Some(v) => v,
            None => {
                l.missing(f, key);
                None
            }
        };
        let spread = |l: &mut Loader| match g.spread {
            Some(s) => s,
            None => {
                if !misspelt_spread {
                    l.report(f.owner, f.path.clone(), Problem::MissingSpread { dist });
                }
                None
            }
        };
        let bad = |l: &mut Loader, key: &str, detail: String| {
            let span = f.get(key).map_or(f.owner, |n| n.span);
            l.report(
                span,
                f.path(key),
                Problem::DistributionParameters { dist, detail },
            );
            None
        };
        let out = match dist {
            "lognormal" => {
                let mean = need(self, "mean", g.mean);
                let std = spread(self);
                let shift = g.shift.unwrap_or(Some(0.0));
                match (mean, std, shift) {
                    (Some(mean), Some(std), Some(shift)) if mean > shift => {
                        Some(Distribution::Lognormal { mean, std, shift })
                    }
                    (Some(mean), Some(_), Some(shift)) => bad(
                        self,
                        "mean",
                        format!("mean > shift (the support is (shift, ∞)), got mean = {mean}, shift = {shift}"),
                    ),
                    _ => None,
                }
            }
            "truncated_normal" => {
                let mean = g.mean.unwrap_or(Some(0.0));
                let std = spread(self);
                if g.min.is_none() && g.max.is_none() {
                    need(self, "min", None);
                }
                let (lo, hi) = (
                    g.min.unwrap_or(Some(f64::NEG_INFINITY)),
                    g.max.unwrap_or(Some(f64::INFINITY)),
                );
                match (mean, std, lo, hi) {
                    (Some(mean), Some(std), Some(lo), Some(hi)) if lo < hi => {
                        Some(Distribution::TruncatedNormal {
                            mean,
                            std,
                            min: g.min.flatten(),
                            max: g.max.flatten(),
                        })
                    }
                    (Some(_), Some(_), Some(lo), Some(hi))
                        if g.min.is_some() || g.max.is_some() =>
                    {
                        bad(
                            self,
                            "max",
                            format!("min < max, got min = {lo}, max = {hi}"),
                        )
                    }
                    _ => None,
                }
            }
            "weibull" => {
                let scale = need(self, "scale", g.scale);
                let shape = need(self, "shape", g.shape);
                let shift = g.shift.unwrap_or(Some(0.0));
                match (scale, shape, shift) {
                    (Some(scale), Some(shape), Some(shift)) => Some(Distribution::Weibull {
                        scale,
                        shape,
                        shift,
                    }),
                    _ => None,
                }
            }
            "gumbel" => {
                let mode = need(self, "mode", g.mode);
                let scale = need(self, "scale", g.scale);
                match (mode, scale) {
                    (Some(mode), Some(scale)) => Some(Distribution::Gumbel { mode, scale }),
                    _ => None,
                }
            }
            "triangular" => {
                let lo = need(self, "min", g.min);
                let mode = need(self, "mode", g.mode);
                let hi = need(self, "max", g.max);
                match (lo, mode, hi) {
                    (Some(lo), Some(_), Some(hi)) if lo >= hi => bad(
                        self,
                        "max",
                        format!("min < max, got min = {lo}, max = {hi}"),
                    ),
                    (Some(lo), Some(mode), Some(hi)) if !(lo..=hi).contains(&mode) => bad(
                        self,
                        "mode",
                        format!("min ≤ mode ≤ max, got min = {lo}, mode = {mode}, max = {hi}"),
                    ),
                    (Some(min), Some(mode), Some(max)) => {
                        Some(Distribution::Triangular { min, mode, max })
                    }
                    _ => None,
                }
            }
            "rayleigh" => {
                let scale = need(self, "scale", g.scale);
                let shift = g.shift.unwrap_or(Some(0.0));
                match (scale, shift) {
                    (Some(scale), Some(shift)) => Some(Distribution::Rayleigh { scale, shift }),
                    _ => None,
                }
            }
            _ => None,
        };
        out
    }

    /// `correlation: [[name, name, rho], …]` (`reliability-v2.md` §2): each
    /// name an error with statistics, `ρ ∈ (−1, 1)`, no error with itself,
    /// no pair twice. `None` if any entry is invalid (reported).
    pub(super) fn correlation_section(
        &mut self,
        node: &Node,
        statistics: Option<&[crate::model::Statistic]>,
        tree: Option<&Tree>,
    ) -> Option<Vec<CorrelationEntry>> {
        let before = self.errors.len();
        let Some(items) = node.as_sequence() else {
            self.report(
                node.span,
                "correlation",
                Problem::WrongType {
                    expected: "a list of [error, error, rho]",
                    found: node.describe(),
                },
            );
            return None;
        };
        let mut out: Vec<CorrelationEntry> = Vec::new();
        for (i, item) in items.iter().enumerate() {
            let path = format!("correlation[{i}]");
            let Some([na, nb, nr]) = self.items::<3>(item, &path, "a list [error, error, rho]")
            else {
                continue;
            };
            let index = |l: &mut Loader, n: &Node| -> Option<usize> {
                let name = l.name(n, &path, "an error name")?;
                let t = tree?;
                let Some(j) = t.errors.iter().position(|e| e.name == name) else {
                    let suggestion = closest(&name, t.errors.iter().map(|e| e.name.as_str()))
                        .map(str::to_string);
                    l.report(
                        n.span,
                        path.clone(),
                        Problem::UnknownError { name, suggestion },
                    );
                    return None;
                };
                if statistics.is_some_and(|s| !s.iter().any(|st| st.error == j)) {
                    l.report(
                        n.span,
                        path.clone(),
                        Problem::BadCorrelation {
                            detail: format!("`{name}` has no `statistics` entry: only errors with statistics can be correlated"),
                        },
                    );
                    return None;
                }
                Some(j)
            };
            let a = index(self, na);
            let b = index(self, nb);
            let rho = self.finite(nr, &path, "a correlation");
            let (Some(a), Some(b), Some(rho)) = (a, b, rho) else {
                continue;
            };
            let names = tree.map_or((String::new(), String::new()), |t| {
                (t.errors[a].name.clone(), t.errors[b].name.clone())
            });
            if a == b {
                self.report(
                    nb.span,
                    path,
                    Problem::BadCorrelation {
                        detail: format!("`{}` is correlated with itself", names.0),
                    },
                );
                continue;
            }
            if rho.abs() >= 1.0 {
                self.report(
                    nr.span,
                    path,
                    Problem::BadCorrelation {
                        detail: format!(
                            "the correlation of `{}` and `{}` is {rho}: it must be strictly between -1 and 1",
                            names.0, names.1
                        ),
                    },
                );
                continue;
            }
            if let Some(first) = out
                .iter()
                .find(|c| (c.a, c.b) == (a, b) || (c.a, c.b) == (b, a))
            {
                let line = first.origin.line;
                self.report(
                    item.span,
                    path,
                    Problem::BadCorrelation {
                        detail: format!(
                            "the pair `{}`, `{}` is given twice (first on line {line})",
                            names.0, names.1
                        ),
                    },
                );
                continue;
            }
            out.push(CorrelationEntry {
                a,
                b,
                rho,
                origin: item.span.origin(path),
            });
        }
        (self.errors.len() == before).then_some(out)
    }

    /// `reliability: {tolerance, sided, grid, requirement}`.
    pub(super) fn reliability_section(
        &mut self,
        key: &Node,
        value: &Node,
        tree: Option<&Tree>,
    ) -> Option<ReliabilitySpec> {
        let before = self.errors.len();
        let f = self.fields(value, key.span, "reliability", RELIABILITY_KEYS)?;

        let mut tolerance = Vec::new();
        match f.entry("tolerance") {
            Some((k, v)) => {
                let path = f.path("tolerance");
                if let Some(entries) = self.entries(v, &path) {
                    if entries.is_empty() {
                        self.report(
                            k.span,
                            path.clone(),
                            Problem::EmptyList {
                                what: "the reliability tolerance",
                            },
                        );
                    }
                    for (ck, cv) in entries {
                        let cpath = join(&path, ck.as_str().unwrap_or(""));
                        let comp = self
                            .keyword(ck, &cpath, "component", COMPONENTS)
                            .and_then(Component::from_name);
                        let val = self.positive(cv, &cpath, "a tolerance");
                        if let (Some(c), Some(v)) = (comp, val) {
                            tolerance.push((c, v));
                        }
                    }
                }
            }
            None => self.missing(&f, "tolerance"),
        }

        let sided = match f.get("sided") {
            Some(n) => match self.keyword(n, &f.path("sided"), "`sided` value", SIDED) {
                Some("two") => Sided::Two,
                _ => Sided::Upper,
            },
            None => Sided::Upper,
        };

        let mut grid = Vec::new();
        if let Some(g) = f.get("grid") {
            let path = f.path("grid");
            for (gk, gv) in self.entries(g, &path).unwrap_or(&[]) {
                let name = gk.as_str().unwrap_or("");
                let gpath = join(&path, name);
                let var = tree.and_then(|t| t.variables.iter().position(|v| v.name == name));
                if let Some(t) = tree {
                    if var.is_none() && !self.seen_variables.contains(name) {
                        let suggestion = closest(name, t.variables.iter().map(|v| v.name.as_str()))
                            .map(str::to_string);
                        self.report(
                            gk.span,
                            gpath.clone(),
                            Problem::UnknownVariable {
                                name: name.to_string(),
                                suggestion,
                            },
                        );
                    }
                }
                let Some(items) = gv.as_sequence() else {
                    self.report(
                        gv.span,
                        gpath,
                        Problem::WrongType {
                            expected: "a list of numbers",
                            found: gv.describe(),
                        },
                    );
                    continue;
                };
                if items.is_empty() {
                    self.report(
                        gv.span,
                        gpath.clone(),
                        Problem::EmptyList { what: "a grid" },
                    );
                }
                let values: Vec<Option<f64>> = items
                    .iter()
                    .enumerate()
                    .map(|(i, n)| self.finite(n, &super::index(&gpath, i), "a grid value"))
                    .collect();
                if let (Some(var), Some(values)) = (var, values.into_iter().collect()) {
                    grid.push((var, values));
                }
            }
        }

        let requirement = match f.entry("requirement") {
            Some((k, v)) => {
                let path = f.path("requirement");
                self.fields(v, k.span, &path, REQUIREMENT_KEYS)
                    .and_then(|rf| {
                        let get = |l: &mut Loader, key: &'static str| match rf.get(key) {
                            Some(n) => {
                                let p = rf.path(key);
                                let v = l.number(n, &p)?;
                                if v > 0.0 && v <= 1.0 {
                                    Some(v)
                                } else {
                                    l.report(
                                        n.span,
                                        p,
                                        Problem::OutOfRange {
                                            what: "a required reliability",
                                            value: v,
                                            range: "(0, 1]",
                                        },
                                    );
                                    None
                                }
                            }
                            None => {
                                l.missing(&rf, key);
                                None
                            }
                        };
                        let min = get(self, "min");
                        let mean = get(self, "mean");
                        Some(Requirement {
                            min: min?,
                            mean: mean?,
                        })
                    })
            }
            None => None,
        };

        // `acceptance: true|false` (reliability-v2 §4): also the
        // whole-machine acceptance probability.
        let acceptance = match f.get("acceptance") {
            Some(n) => match n.as_scalar().map(|s| (s.style, s.text.as_str())) {
                Some((crate::yaml::ScalarStyle::Plain, "true" | "True" | "TRUE")) => true,
                Some((crate::yaml::ScalarStyle::Plain, "false" | "False" | "FALSE")) => false,
                _ => {
                    self.wrong_type(n, &f.path("acceptance"), "true or false");
                    false
                }
            },
            None => false,
        };

        if self.errors.len() != before {
            return None;
        }
        Some(ReliabilitySpec {
            tolerance,
            sided,
            grid,
            requirement,
            acceptance,
            origin: key.span.origin("reliability"),
        })
    }
}
