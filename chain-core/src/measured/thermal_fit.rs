//! The thermal model of a drift test's displacement channels
//! (`../shared/spec/thermal.md`, "`chain thermal RUN.csv --fit`";
//! `docs/thermal.md` for the method and the comparison that chose it).
//!
//! For each displacement channel `c` the model a controller can evaluate,
//!
//! `δ_c(t) = c₀ + Σ_i a_i·ΔT_i(t) + Σ_k b_k·L_k(t; τ_k)`,
//!
//! `ΔT_i(t) = T_i(t) − T_i(t₀)` at most K temperature sensors chosen from the
//! data, `L_k` the first-order response `τ·dL/dt = u(t) − L` (`L(t₀) = 0`) to
//! a load column `u`, exact for `u` held between samples:
//! `L_{n+1} = L_n·e^{−Δt/τ} + u_n·(1 − e^{−Δt/τ})`, its time constant one of
//! a log-spaced grid between four sample intervals and the fit period.
//!
//! The terms are chosen on time-blocked cross-validation inside the fit
//! period (the method and the comparison that chose it against forward
//! stepwise selection, a LASSO path, in-sample criteria and ridge on all
//! sensors: `docs/thermal.md`, `scripts/thermal_selection.py`). The fit
//! period is cut into `min(`[`BLOCKS`]`, n)` contiguous blocks of equal
//! sample counts; a set of terms is scored by the squared error of
//! predicting each block from the least-squares fit on the others (the
//! intercept always in, never counted). For each size k ≤ K the best
//! k-subset of the sensors is found by enumerating them all (the first in
//! the file's order wins a tie); the size grows while the next size's best
//! lowers the score by more than [`MARGIN`]. With lags asked for, the lag
//! term (load and τ) that scores best with the chosen sensors is added
//! while it lowers the score by more than [`MARGIN`], at most [`MAX_LAGS`].
//! So every term earns its place on time it was not fitted on. Where the
//! subsets of size ≤ K number more than [`MAX_SUBSETS`], the sensors are
//! chosen by forward selection on the same score instead, and the document
//! says so. The chosen terms are refitted by least squares on the whole fit
//! period. Every fit works on standardised columns from the blocks' Gram
//! matrices (the data is read once; each candidate set costs a few small
//! Cholesky solves).

use nalgebra::{DMatrix, DVector};
use serde::Serialize;

use super::thermal::{drift, ChannelKind, DriftTest, ThermalDocument};

/// The default of `--sensors`.
pub const DEFAULT_SENSORS: usize = 4;
/// The contiguous blocks of the fit period's cross-validation (fewer
/// when the period has fewer samples).
pub const BLOCKS: usize = 10;
/// The most sensor subsets the exhaustive search enumerates.
pub const MAX_SUBSETS: u64 = 1_000_000;
/// The relative decrease of the cross-validated error a term must bring.
pub const MARGIN: f64 = 0.01;
/// The most lag terms a model takes.
pub const MAX_LAGS: usize = 2;
/// The time constants tried per load.
pub const LAG_CANDIDATES: usize = 12;

/// Which samples the model is fitted on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Split {
    /// Every sample (no held-out prediction).
    None,
    /// The first `1 − F` of the test's duration (`--holdout F`).
    Holdout(f64),
    /// The samples before this time (s; `--fit-until`).
    Until(f64),
}

/// How to fit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitOptions {
    /// The most temperature sensors per channel (K).
    pub sensors: usize,
    /// Consider lag responses to the loads.
    pub lag: bool,
    /// The fit period.
    pub split: Split,
}

/// Why a fit cannot be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[cfg_attr(feature = "miette", derive(miette::Diagnostic))]
#[non_exhaustive]
pub enum FitError {
    /// A held-out fraction outside (0, 1).
    #[error("the held-out fraction {value} is not between 0 and 1")]
    Fraction {
        /// As given.
        value: f64,
    },
    /// A fit end outside the test.
    #[error("the fit ends at {value} s, outside the test ({from} s to {to} s)")]
    Until {
        /// As given.
        value: f64,
        /// The first sample's time.
        from: f64,
        /// The last's.
        to: f64,
    },
    /// Too few samples in the fit period.
    #[error(
        "the fit period has {samples} sample(s): the cross-validation needs at least {needed}"
    )]
    TooFewSamples {
        /// In the fit period.
        samples: usize,
        /// What it needs.
        needed: usize,
    },
    /// No temperature sensor and no load to fit with.
    #[error("the file has no temperature sensor{}", if *.lag { " and no load" } else { "" })]
    NothingToFit {
        /// Lags were asked for.
        lag: bool,
    },
}

impl FitError {
    /// What to do about it.
    pub fn help(&self) -> Option<String> {
        match self {
            FitError::Fraction { .. } => {
                Some("give the held-out share of the test's duration, e.g. 0.3".into())
            }
            FitError::Until { .. } => Some("give a time inside the test".into()),
            FitError::TooFewSamples { .. } => Some("fit on a longer part of the test".into()),
            FitError::NothingToFit { .. } => {
                Some("name the temperature columns whose headers carry no unit".into())
            }
        }
    }
}

/// The fit period.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FitPeriod {
    /// Its first sample's time (s).
    pub from: f64,
    /// Where it ends (s): its samples are before it, the held-out ones at
    /// or after it (the last sample's time when nothing is held out).
    pub until: f64,
    /// Its samples.
    pub samples: usize,
    /// How the sensors were chosen.
    pub selection: Selection,
}

/// What a term of a model responds to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum TermKind {
    /// A temperature sensor's change `ΔT`.
    Temperature,
    /// A first-order lag response to a load.
    Lag,
}

/// One term of a channel's model.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModelTerm {
    /// What it responds to.
    pub kind: TermKind,
    /// The temperature sensor (a temperature term).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sensor: Option<String>,
    /// The load (a lag term).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub load: Option<String>,
    /// The time constant (s; a lag term).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tau: Option<f64>,
    /// The coefficient: the channel's unit per °C (a temperature term) or
    /// per load unit (a lag term).
    pub coefficient: f64,
    /// Its standard error (least squares, the residuals taken as
    /// independent: a lower bound for autocorrelated drift residuals).
    pub std: f64,
}

/// A channel's model: `δ = intercept + Σ coefficient·term`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ThermalModel {
    /// `c₀` (the channel's unit).
    pub intercept: f64,
    /// The terms in the order chosen.
    pub terms: Vec<ModelTerm>,
}

/// How a model fits its fit period.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FitStats {
    /// The RMS of `δ` minus the prediction (the channel's unit).
    pub rms: f64,
    /// The cross-validated RMS of the chosen terms (blocked).
    pub cv_rms: f64,
}

/// How a model predicts the held-out samples.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HoldoutStats {
    /// The held-out samples.
    pub samples: usize,
    /// The RMS of `δ` there (the machine uncorrected).
    pub rms_before: f64,
    /// The RMS of `δ` minus the prediction there.
    pub rms_after: f64,
    /// The largest `|δ − prediction|` there.
    pub max_after: f64,
}

/// A channel's drift and its model's prediction at every sample.
#[derive(Debug, Clone, PartialEq)]
pub struct Prediction {
    /// The channel.
    pub channel: String,
    /// `δ` at every sample.
    pub measured: Vec<f64>,
    /// The model's prediction at every sample.
    pub predicted: Vec<f64>,
}

/// The fit of every displacement channel.
#[derive(Debug, Clone, PartialEq)]
pub struct Fitted {
    /// The fit period.
    pub period: FitPeriod,
    /// Per displacement channel (the file's order): the model and its
    /// statistics.
    pub models: Vec<(ThermalModel, FitStats, Option<HoldoutStats>)>,
    /// Per displacement channel, the drift and the prediction.
    pub predictions: Vec<Prediction>,
}

impl Fitted {
    /// Writes the fit into the evaluation's document.
    pub fn into_document(&self, document: &mut ThermalDocument) {
        document.fit = Some(self.period.clone());
        for (channel, (model, fit, holdout)) in document.channels.iter_mut().zip(&self.models) {
            channel.model = Some(model.clone());
            channel.fit = Some(fit.clone());
            channel.holdout = holdout.clone();
        }
    }
}

/// A candidate term: its description and its values at every sample.
struct Candidate {
    kind: TermKind,
    source: String,
    tau: Option<f64>,
    values: Vec<f64>,
}

/// The first-order lag response to `u` with time constant `tau` (module
/// docs), `L(t₀) = 0`.
pub fn lag_response(time: &[f64], u: &[f64], tau: f64) -> Vec<f64> {
    let mut out = Vec::with_capacity(u.len());
    let mut l = 0.0;
    out.push(l);
    for n in 1..u.len() {
        let a = (-(time[n] - time[n - 1]) / tau).exp();
        l = l * a + u[n - 1] * (1.0 - a);
        out.push(l);
    }
    out
}

/// The time constants tried for a fit period of `span` seconds sampled
/// every `dt` (median): log-spaced from `4·dt` to `span`.
pub fn lag_grid(dt: f64, span: f64) -> Vec<f64> {
    let (lo, hi) = (4.0 * dt, span.max(4.0 * dt));
    (0..LAG_CANDIDATES)
        .map(|k| lo * (hi / lo).powf(k as f64 / (LAG_CANDIDATES - 1) as f64))
        .collect()
}

/// The candidates' standardisation over the fit period and the Gram
/// matrices of their standardised values (with a leading column of ones)
/// per block, each fold's training Gram (the others' sum).
struct Folds {
    /// Per block: its sample range.
    ranges: Vec<std::ops::Range<usize>>,
    /// Per block: `XᵀX` over it.
    test: Vec<DMatrix<f64>>,
    /// Per block: `XᵀX` over the other blocks.
    train: Vec<DMatrix<f64>>,
    /// `XᵀX` over the fit period.
    total: DMatrix<f64>,
    mean: Vec<f64>,
    scale: Vec<f64>,
}

impl Folds {
    fn new(candidates: &[Candidate], n: usize) -> Folds {
        let f = candidates.len();
        let (mut mean, mut scale) = (vec![0.0; f], vec![1.0; f]);
        for (j, c) in candidates.iter().enumerate() {
            let m = c.values[..n].iter().sum::<f64>() / n as f64;
            let v = c.values[..n].iter().map(|x| (x - m).powi(2)).sum::<f64>() / n as f64;
            mean[j] = m;
            scale[j] = if v > 0.0 { v.sqrt() } else { 1.0 };
        }
        let blocks = BLOCKS.min(n);
        let ranges: Vec<std::ops::Range<usize>> = (0..blocks)
            .map(|b| (b * n / blocks)..((b + 1) * n / blocks))
            .collect();
        let standardised = |s: usize, row: &mut [f64]| {
            row[0] = 1.0;
            for (j, c) in candidates.iter().enumerate() {
                row[j + 1] = (c.values[s] - mean[j]) / scale[j];
            }
        };
        let gram = |r: &std::ops::Range<usize>| {
            let mut g = DMatrix::zeros(f + 1, f + 1);
            let mut row = vec![0.0; f + 1];
            for s in r.clone() {
                standardised(s, &mut row);
                for a in 0..=f {
                    let ra = row[a];
                    for b in a..=f {
                        g[(a, b)] += ra * row[b];
                    }
                }
            }
            for a in 0..=f {
                for b in 0..a {
                    g[(a, b)] = g[(b, a)];
                }
            }
            g
        };
        #[cfg(feature = "parallel")]
        let test: Vec<DMatrix<f64>> = {
            use rayon::prelude::*;
            ranges.par_iter().map(gram).collect()
        };
        #[cfg(not(feature = "parallel"))]
        let test: Vec<DMatrix<f64>> = ranges.iter().map(gram).collect();
        let total = test.iter().fold(DMatrix::zeros(f + 1, f + 1), |a, b| a + b);
        let train = test.iter().map(|g| &total - g).collect();
        Folds {
            ranges,
            test,
            train,
            total,
            mean,
            scale,
        }
    }

    /// The standardised value of candidate `j` at sample `s`.
    fn value(&self, candidates: &[Candidate], j: usize, s: usize) -> f64 {
        (candidates[j].values[s] - self.mean[j]) / self.scale[j]
    }
}

/// One channel's cross-products with the candidates: per block `Xᵀy` and
/// `yᵀy`, and over the other blocks `Xᵀy`.
struct Response {
    test_xty: Vec<Vec<f64>>,
    test_yty: Vec<f64>,
    train_xty: Vec<Vec<f64>>,
    total_xty: Vec<f64>,
    total_yty: f64,
}

impl Response {
    fn new(folds: &Folds, candidates: &[Candidate], y: &[f64]) -> Response {
        let f = candidates.len();
        let mut test_xty = Vec::with_capacity(folds.ranges.len());
        let mut test_yty = Vec::with_capacity(folds.ranges.len());
        for r in &folds.ranges {
            let mut xty = vec![0.0; f + 1];
            let mut yty = 0.0;
            for s in r.clone() {
                xty[0] += y[s];
                for (j, v) in xty[1..].iter_mut().enumerate() {
                    *v += folds.value(candidates, j, s) * y[s];
                }
                yty += y[s] * y[s];
            }
            test_xty.push(xty);
            test_yty.push(yty);
        }
        let total_xty: Vec<f64> = (0..=f)
            .map(|a| test_xty.iter().map(|x| x[a]).sum())
            .collect();
        let train_xty = (test_xty.iter())
            .map(|x| total_xty.iter().zip(x).map(|(t, v)| t - v).collect())
            .collect();
        Response {
            total_yty: test_yty.iter().sum(),
            test_xty,
            test_yty,
            train_xty,
            total_xty,
        }
    }
}

/// Reused buffers of the small solves.
#[derive(Default)]
struct Scratch {
    a: Vec<f64>,
    b: Vec<f64>,
}

/// Solves `a x = b` in place (`a` the `m × m` symmetric matrix, row-major;
/// `b` becomes `x`) by Cholesky; false where a pivot is not above 1e-12 of
/// its diagonal (a set with a column the others already span).
fn cholesky_solve(a: &mut [f64], m: usize, b: &mut [f64]) -> bool {
    for j in 0..m {
        let mut d = a[j * m + j];
        for k in 0..j {
            d -= a[j * m + k] * a[j * m + k];
        }
        if d.is_nan() || d <= 1e-12 * a[j * m + j].abs().max(f64::MIN_POSITIVE) {
            return false;
        }
        let d = d.sqrt();
        a[j * m + j] = d;
        for i in j + 1..m {
            let mut v = a[i * m + j];
            for k in 0..j {
                v -= a[i * m + k] * a[j * m + k];
            }
            a[i * m + j] = v / d;
        }
    }
    for i in 0..m {
        let mut v = b[i];
        for k in 0..i {
            v -= a[i * m + k] * b[k];
        }
        b[i] = v / a[i * m + i];
    }
    for i in (0..m).rev() {
        let mut v = b[i];
        for k in i + 1..m {
            v -= a[k * m + i] * b[k];
        }
        b[i] = v / a[i * m + i];
    }
    true
}

/// The least squares of `g` (a Gram) and `xty` over the columns `set`:
/// `β` into `scratch.b`; false where the set is singular.
fn least_squares(g: &DMatrix<f64>, xty: &[f64], set: &[usize], scratch: &mut Scratch) -> bool {
    let m = set.len();
    scratch.a.clear();
    scratch.b.clear();
    for &r in set {
        for &c in set {
            scratch.a.push(g[(r, c)]);
        }
        scratch.b.push(xty[r]);
    }
    cholesky_solve(&mut scratch.a, m, &mut scratch.b)
}

/// The blocked cross-validated squared error of the columns `set` (0 the
/// intercept, `j + 1` candidate `j`); infinite for a singular set.
fn cv_error(folds: &Folds, y: &Response, set: &[usize], scratch: &mut Scratch) -> f64 {
    let mut sse = 0.0;
    for b in 0..folds.ranges.len() {
        if !least_squares(&folds.train[b], &y.train_xty[b], set, scratch) {
            return f64::INFINITY;
        }
        // Σ (y − xβ)² over block b = yᵀy − 2βᵀXᵀy + βᵀXᵀXβ.
        let (g, xty, beta) = (&folds.test[b], &y.test_xty[b], &scratch.b);
        let mut e = y.test_yty[b];
        for (p, &r) in set.iter().enumerate() {
            e -= 2.0 * beta[p] * xty[r];
            for (q, &c) in set.iter().enumerate() {
                e += beta[p] * g[(r, c)] * beta[q];
            }
        }
        sse += e.max(0.0);
    }
    sse
}

/// `C(n, k)`, saturating.
fn choose(n: usize, k: usize) -> u64 {
    (0..k).fold(1u64, |acc, i| {
        acc.saturating_mul((n - i) as u64) / (i as u64 + 1)
    })
}

/// The k-subsets of `0..n` in lexicographic order, each passed to `f`.
fn for_each_subset(n: usize, k: usize, f: &mut dyn FnMut(&[usize])) {
    if k > n {
        return;
    }
    let mut idx: Vec<usize> = (0..k).collect();
    loop {
        f(&idx);
        let Some(i) = (0..k).rev().find(|&i| idx[i] < n - k + i) else {
            return;
        };
        idx[i] += 1;
        for j in i + 1..k {
            idx[j] = idx[j - 1] + 1;
        }
    }
}

/// How the sensors were chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Selection {
    /// Every subset of size ≤ K scored.
    BestSubset,
    /// Forward selection (more than [`MAX_SUBSETS`] subsets).
    Forward,
}

/// The chosen sensors (columns `j + 1`) among `sensors` (candidate
/// indices) and their score (module docs).
fn choose_sensors(
    folds: &Folds,
    y: &Response,
    sensors: &[usize],
    k: usize,
    selection: Selection,
    scratch: &mut Scratch,
) -> (Vec<usize>, f64) {
    let k = k.min(sensors.len());
    let mut best = vec![0usize];
    let mut score = cv_error(folds, y, &best, scratch);
    for size in 1..=k {
        let mut round: Option<(Vec<usize>, f64)> = None;
        let mut consider = |set: Vec<usize>, scratch: &mut Scratch| {
            let e = cv_error(folds, y, &set, scratch);
            if round.as_ref().is_none_or(|r| e < r.1) {
                round = Some((set, e));
            }
        };
        match selection {
            Selection::BestSubset => for_each_subset(sensors.len(), size, &mut |idx| {
                let set: Vec<usize> = std::iter::once(0)
                    .chain(idx.iter().map(|&i| sensors[i] + 1))
                    .collect();
                consider(set, scratch);
            }),
            Selection::Forward => {
                for &j in sensors.iter().filter(|&&j| !best.contains(&(j + 1))) {
                    let mut set = best.clone();
                    set.push(j + 1);
                    consider(set, scratch);
                }
            }
        }
        match round {
            Some((set, e)) if e < (1.0 - MARGIN) * score => {
                best = set;
                score = e;
            }
            _ => break,
        }
    }
    (best, score)
}

/// Fits every displacement channel of `test` (module docs).
pub fn fit(test: &DriftTest, options: &FitOptions) -> Result<Fitted, FitError> {
    let (t0, t1) = (test.time[0], test.time[test.time.len() - 1]);
    let until = match options.split {
        Split::None => f64::INFINITY,
        Split::Holdout(f) => {
            if !(f > 0.0 && f < 1.0) {
                return Err(FitError::Fraction { value: f });
            }
            t1 - f * (t1 - t0)
        }
        Split::Until(t) => {
            if !(t > t0 && t <= t1) {
                return Err(FitError::Until {
                    value: t,
                    from: t0,
                    to: t1,
                });
            }
            t
        }
    };
    let n = test.time.partition_point(|&t| t < until);
    let temperatures: Vec<_> = test.of(ChannelKind::Temperature).collect();
    let loads: Vec<_> = test.of(ChannelKind::Load).collect();
    let lags_possible = options.lag && !loads.is_empty();
    if temperatures.is_empty() && !lags_possible {
        return Err(FitError::NothingToFit { lag: options.lag });
    }
    let needed = (2 * BLOCKS).max(2 * (options.sensors + MAX_LAGS + 2));
    if n < needed {
        return Err(FitError::TooFewSamples { samples: n, needed });
    }
    // The candidates: every sensor's ΔT that varies over the fit period,
    // and with lags every load's responses over the τ grid.
    let mut candidates: Vec<Candidate> = temperatures
        .iter()
        .filter(|c| c.values[..n].iter().any(|&v| v != c.values[0]))
        .map(|c| Candidate {
            kind: TermKind::Temperature,
            source: c.name.clone(),
            tau: None,
            values: c.values.iter().map(|t| t - c.values[0]).collect(),
        })
        .collect();
    let sensors: Vec<usize> = (0..candidates.len()).collect();
    if options.lag {
        let mut steps: Vec<f64> = test.time[..n].windows(2).map(|w| w[1] - w[0]).collect();
        steps.sort_by(f64::total_cmp);
        let dt = steps[steps.len() / 2];
        let span = test.time[n - 1] - t0;
        for load in &loads {
            for tau in lag_grid(dt, span) {
                candidates.push(Candidate {
                    kind: TermKind::Lag,
                    source: load.name.clone(),
                    tau: Some(tau),
                    values: lag_response(&test.time, &load.values, tau),
                });
            }
        }
    }
    let lags: Vec<usize> = (sensors.len()..candidates.len()).collect();
    let subsets: u64 = (0..=options.sensors.min(sensors.len()))
        .map(|k| choose(sensors.len(), k))
        .fold(0u64, u64::saturating_add);
    let selection = if subsets <= MAX_SUBSETS {
        Selection::BestSubset
    } else {
        Selection::Forward
    };
    let folds = Folds::new(&candidates, n);
    let channels: Vec<_> = test.of(ChannelKind::Displacement).collect();
    let one = |channel: &&super::thermal::Channel| {
        let y = drift(channel);
        let response = Response::new(&folds, &candidates, &y);
        let mut scratch = Scratch::default();
        let (mut set, mut score) = choose_sensors(
            &folds,
            &response,
            &sensors,
            options.sensors,
            selection,
            &mut scratch,
        );
        for _ in 0..MAX_LAGS {
            let best = (lags.iter())
                .map(|&j| {
                    let mut with = set.clone();
                    with.push(j + 1);
                    (j, cv_error(&folds, &response, &with, &mut scratch))
                })
                .fold(None, |acc: Option<(usize, f64)>, (j, e)| match acc {
                    Some((_, b)) if b <= e => acc,
                    _ => Some((j, e)),
                });
            match best {
                Some((j, e)) if e < (1.0 - MARGIN) * score => {
                    set.push(j + 1);
                    score = e;
                }
                _ => break,
            }
        }
        fitted_channel(channel, y, &candidates, &folds, &response, &set, score, n)
    };
    #[cfg(feature = "parallel")]
    let fitted: Vec<_> = {
        use rayon::prelude::*;
        channels.par_iter().map(one).collect()
    };
    #[cfg(not(feature = "parallel"))]
    let fitted: Vec<_> = channels.iter().map(one).collect();
    let (models, predictions) = fitted.into_iter().unzip();
    Ok(Fitted {
        period: FitPeriod {
            from: t0,
            until: if until.is_finite() { until } else { t1 },
            samples: n,
            selection,
        },
        models,
        predictions,
    })
}

/// The refit of the chosen columns `set` on the fit period, its
/// statistics and its prediction at every sample.
#[allow(clippy::too_many_arguments)]
fn fitted_channel(
    channel: &super::thermal::Channel,
    y: Vec<f64>,
    candidates: &[Candidate],
    folds: &Folds,
    response: &Response,
    set: &[usize],
    score: f64,
    n: usize,
) -> ((ThermalModel, FitStats, Option<HoldoutStats>), Prediction) {
    let g = DMatrix::from_fn(set.len(), set.len(), |a, b| folds.total[(set[a], set[b])]);
    let xty = DVector::from_fn(set.len(), |a, _| response.total_xty[set[a]]);
    let beta = match g.clone().cholesky() {
        Some(c) => c.solve(&xty),
        None => {
            let svd = g.clone().svd(true, true);
            let tol = 1e-12 * svd.singular_values.max().max(f64::MIN_POSITIVE);
            svd.solve(&xty, tol)
                .unwrap_or_else(|_| DVector::zeros(set.len()))
        }
    };
    let sse = (response.total_yty - 2.0 * beta.dot(&xty) + beta.dot(&(&g * &beta))).max(0.0);
    let sigma2 = sse / (n as f64 - set.len() as f64).max(1.0);
    let variance: Vec<f64> = match g.try_inverse() {
        Some(inv) => (0..set.len()).map(|a| inv[(a, a)] * sigma2).collect(),
        None => vec![f64::NAN; set.len()],
    };
    let mut intercept = beta[0];
    let mut terms = Vec::new();
    for (a, &col) in set.iter().enumerate().skip(1) {
        let j = col - 1;
        let c = &candidates[j];
        let coefficient = beta[a] / folds.scale[j];
        intercept -= coefficient * folds.mean[j];
        terms.push(ModelTerm {
            kind: c.kind,
            sensor: (c.kind == TermKind::Temperature).then(|| c.source.clone()),
            load: (c.kind == TermKind::Lag).then(|| c.source.clone()),
            tau: c.tau,
            coefficient,
            std: variance[a].max(0.0).sqrt() / folds.scale[j],
        });
    }
    let predicted: Vec<f64> = (0..y.len())
        .map(|s| {
            intercept
                + (set.iter().skip(1))
                    .zip(&terms)
                    .map(|(&col, t)| t.coefficient * candidates[col - 1].values[s])
                    .sum::<f64>()
        })
        .collect();
    let rms = |r: std::ops::Range<usize>, f: &dyn Fn(usize) -> f64| -> f64 {
        let len = r.len().max(1) as f64;
        (r.map(|s| f(s).powi(2)).sum::<f64>() / len).sqrt()
    };
    let fit = FitStats {
        rms: rms(0..n, &|s| y[s] - predicted[s]),
        cv_rms: (score / n as f64).sqrt(),
    };
    let holdout = (n < y.len()).then(|| HoldoutStats {
        samples: y.len() - n,
        rms_before: rms(n..y.len(), &|s| y[s]),
        rms_after: rms(n..y.len(), &|s| y[s] - predicted[s]),
        max_after: (n..y.len())
            .map(|s| (y[s] - predicted[s]).abs())
            .fold(0.0, f64::max),
    });
    (
        (ThermalModel { intercept, terms }, fit, holdout),
        Prediction {
            channel: channel.name.clone(),
            measured: y,
            predicted,
        },
    )
}
