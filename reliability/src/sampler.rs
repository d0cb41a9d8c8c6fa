//! The samplers behind one small trait ([`Sampler`]) and one driver: what a
//! sampling run reports ([`SimulationResult`], how it stopped: [`Stopping`]),
//! the progress sink every sampler tells ([`Progress`]), and the driver that
//! runs every case's blocks in parallel on their own random streams, adds
//! the block sums in block order, counts the calls and applies the stop
//! rules (a sample count, or a target coefficient of variation within a
//! budget) for crude Monte Carlo, the importance sampling and directional
//! simulation alike. A sampler implements one run of many events on their
//! streams ([`Sampler::run_streams`]: on the driver, or on subset
//! simulation's own level loop); the trait provides the rest (one event,
//! [`Sampler::run`]; many on streams `0, 1, …`, [`Sampler::run_cases`]).
//! A study runs any of them through [`Sampler`] (as argmin's solvers are
//! generic over a small problem trait, and OpenTURNS keeps event, algorithm
//! and result apart).

use serde::Serialize;

use crate::error::ReliabilityError;
use crate::form::FormResult;
use crate::limit_state::{Event, LimitState};
use crate::method::Method;
use crate::normal;
use crate::par::prelude::*;

/// A sampling algorithm as a study runs it: its method, and a run of every
/// event under its own stop rule. A sampler implements [`Sampler::method`]
/// and [`Sampler::run_streams`]; [`Sampler::run_cases`] and [`Sampler::run`]
/// are provided.
pub trait Sampler: Sync {
    /// What the run of one event reports.
    type Output;

    /// The method it is.
    fn method(&self) -> Method;

    /// Runs every event (case `i` on the random streams of `streams.id(i)`)
    /// under the sampler's stop rule (its sample count, or its target
    /// coefficient of variation within a budget), telling `progress` of the
    /// samples drawn.
    fn run_streams<L: LimitState>(
        &self,
        events: &[Event<'_, L>],
        streams: Streams<'_>,
        progress: &dyn Progress,
    ) -> Result<Vec<Self::Output>, ReliabilityError>;

    /// Runs several events; case `i` draws from the streams of case `i`
    /// ([`Sampler::run_streams`] on [`Streams::ALL`]).
    fn run_cases<L: LimitState>(
        &self,
        events: &[Event<'_, L>],
        progress: &dyn Progress,
    ) -> Result<Vec<Self::Output>, ReliabilityError> {
        self.run_streams(events, Streams::ALL, progress)
    }

    /// Runs one event (on the streams of case 0).
    fn run<L: LimitState>(&self, event: &Event<'_, L>) -> Result<Self::Output, ReliabilityError> {
        let mut out = self.run_cases(std::slice::from_ref(event), &())?;
        Ok(out.remove(0))
    }
}

/// Which random streams the cases of a run sample: case `i` of the run
/// samples stream `i` ([`Streams::ALL`]) unless the run is a part of a larger
/// study and carries the study's case numbers ([`Streams::of`]: a path run a
/// block of instants at a time draws what the whole run would).
#[derive(Debug, Clone, Copy, Default)]
pub struct Streams<'a>(Option<&'a [usize]>);

impl<'a> Streams<'a> {
    /// Case `i` samples stream `i`.
    pub const ALL: Streams<'static> = Streams(None);

    /// Case `i` samples stream `ids[i]` (`ids` as long as the run's events).
    pub fn of(ids: &'a [usize]) -> Streams<'a> {
        Streams(Some(ids))
    }

    /// The stream of the run's case `case`.
    pub(crate) fn id(&self, case: usize) -> u32 {
        case_id(self.0.map_or(case, |ids| ids[case]))
    }
}

/// The largest number of samples per case (2³⁶ ≈ 6.9·10¹⁰).
pub const MAX_SAMPLES: u64 = 1 << 36;

/// A progress sink: told how much has been done, from any thread: samples
/// for the samplers, cases for FORM and SORM (which draw none).
pub trait Progress: Sync {
    /// `samples` more samples (FORM, SORM: cases) are done.
    fn advance(&self, samples: u64);
}

impl Progress for () {
    fn advance(&self, _samples: u64) {}
}

impl<F: Fn(u64) + Sync> Progress for F {
    fn advance(&self, samples: u64) {
        self(samples)
    }
}

/// The result of a simulation.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SimulationResult {
    /// [`Method::ImportanceSampling`] or [`Method::MonteCarlo`].
    pub method: Method,
    /// The failure-probability estimate.
    pub pf: f64,
    /// `1 − p_f`.
    pub reliability: f64,
    /// The standard error of `p_f`.
    pub std_error: f64,
    /// The coefficient of variation `std_error / p_f` (0 when `p_f = 0`).
    pub cov: f64,
    /// The generalised reliability index `−Φ⁻¹(p_f)`.
    pub beta: f64,
    /// Samples drawn.
    pub samples: u64,
    /// Limit-state evaluations.
    pub calls: u64,
    /// The FORM result that centred the importance sampling.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub form: Option<FormResult>,
    /// How the sampling stopped, when a stopping rule other than the plain
    /// sample count was in force (a target coefficient of variation) or the
    /// method always reports it (directional simulation).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stopping: Option<Stopping>,
}

/// What stopped a sampler.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Stop {
    /// The requested number of samples was drawn (no target in force).
    Samples,
    /// The target coefficient of variation was reached.
    TargetCov,
    /// The sample budget ran out before the target was reached: the
    /// estimate has not converged.
    Budget,
    /// Subset simulation used its largest number of levels without reaching
    /// the failure set: the estimate has not converged.
    Levels,
}

impl Stop {
    /// `samples`, `target_cov`, `budget` or `levels`.
    pub fn name(self) -> &'static str {
        match self {
            Stop::Samples => "samples",
            Stop::TargetCov => "target_cov",
            Stop::Budget => "budget",
            Stop::Levels => "levels",
        }
    }

    /// Whether a result stopped this way is converged.
    pub fn converged(self) -> bool {
        matches!(self, Stop::Samples | Stop::TargetCov)
    }
}

impl std::fmt::Display for Stop {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// How a sampler stopped and whether its estimate converged.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Stopping {
    /// False when the sampler stopped without meeting its rule (budget or
    /// levels exhausted): the estimate is not a converged result.
    pub converged: bool,
    /// Which rule stopped it.
    pub stopped_by: Stop,
    /// The target coefficient of variation, when one was set.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub target_cov: Option<f64>,
}

impl Stopping {
    /// The account of a run stopped by `stop` with target `target_cov`.
    pub fn new(stop: Stop, target_cov: Option<f64>) -> Stopping {
        Stopping {
            converged: stop.converged(),
            stopped_by: stop,
            target_cov,
        }
    }
}

/// Checks a target coefficient of variation: finite, in `(0, 1]`.
pub fn check_cov(cov: f64) -> Result<(), ReliabilityError> {
    if cov.is_finite() && cov > 0.0 && cov <= 1.0 {
        Ok(())
    } else {
        Err(ReliabilityError::InvalidTargetCov(cov))
    }
}

/// Per-block sums of `(v − shift)` and `(v − shift)²`, and calls.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Sums {
    /// `Σ (v − shift)`.
    pub(crate) s1: f64,
    /// `Σ (v − shift)²`.
    pub(crate) s2: f64,
    /// Limit-state evaluations.
    pub(crate) calls: u64,
}

pub(crate) fn finish(
    method: Method,
    pf: f64,
    std_error: f64,
    samples: u64,
    calls: u64,
    form: Option<FormResult>,
) -> SimulationResult {
    SimulationResult {
        method,
        pf,
        reliability: 1.0 - pf,
        std_error,
        cov: if pf > 0.0 { std_error / pf } else { 0.0 },
        beta: normal::beta_from_pf(pf),
        samples,
        calls,
        form,
        stopping: None,
    }
}

pub(crate) fn case_id(case: usize) -> u32 {
    u32::try_from(case).unwrap_or(u32::MAX)
}

/// Runs up to `samples` per case in blocks of `block` samples, in parallel, and
/// adds the block sums of each case in block order. Returns per case the
/// sums, the samples used and, under a stopping rule, how it stopped.
///
/// Without a rule every block runs (all in parallel). With `rule = (target,
/// done)` blocks run in parallel batches as wide as the thread pool;
/// `done(case, sums, samples)` is asked after each block in block order,
/// and the first block after which it holds ends the case
/// ([`Stop::TargetCov`]; blocks of its batch beyond it are dropped, so the
/// result does not depend on the thread count); running out of `samples`
/// first is [`Stop::Budget`]. Either way the estimate is bit-identical to a
/// fixed-count run of the samples used.
pub(crate) fn drive<F, D>(
    cases: usize,
    samples: u64,
    block_size: u64,
    width: usize,
    progress: &dyn Progress,
    run: F,
    rule: Option<(f64, D)>,
) -> Vec<(Sums, u64, Option<Stopping>)>
where
    F: Fn(usize, u32, u64, &mut [f64]) -> Sums + Sync,
    D: Fn(usize, &Sums, u64) -> bool + Sync,
{
    let blocks = samples.div_ceil(block_size);
    let batch = match rule {
        Some(_) => crate::par::threads().max(1) as u64,
        None => blocks.max(1),
    };
    let stopping = |stop| rule.as_ref().map(|(t, _)| Stopping::new(stop, Some(*t)));
    (0..cases)
        .into_par_iter()
        .map(|case| {
            let mut total = Sums::default();
            let mut used = 0u64;
            let mut next = 0u64;
            while next < blocks {
                let end = (next + batch).min(blocks);
                let parts: Vec<(Sums, u64)> = (next..end)
                    .into_par_iter()
                    .map_init(
                        // Padded by a cache line on each side: the scratch
                        // of two workers must not share a line (false
                        // sharing).
                        || vec![0.0; width + 16],
                        |scratch, block| {
                            let count = block_size.min(samples - block * block_size);
                            let block_id = u32::try_from(block).unwrap_or(u32::MAX);
                            let s = run(case, block_id, count, &mut scratch[8..8 + width]);
                            progress.advance(count);
                            (s, count)
                        },
                    )
                    .collect();
                next = end;
                // Block order, whatever thread ran which block.
                for (b, count) in parts {
                    total = Sums {
                        s1: total.s1 + b.s1,
                        s2: total.s2 + b.s2,
                        calls: total.calls + b.calls,
                    };
                    used += count;
                    if let Some((_, done)) = &rule {
                        if done(case, &total, used) {
                            return (total, used, stopping(Stop::TargetCov));
                        }
                    }
                }
            }
            (total, used, stopping(Stop::Budget))
        })
        .collect()
}

/// Checks a sample count: at least 1, at most [`MAX_SAMPLES`].
pub(crate) fn check_samples(samples: u64) -> Result<(), ReliabilityError> {
    if samples == 0 || samples > MAX_SAMPLES {
        return Err(ReliabilityError::InvalidSamples {
            found: samples,
            max: MAX_SAMPLES,
        });
    }
    Ok(())
}
