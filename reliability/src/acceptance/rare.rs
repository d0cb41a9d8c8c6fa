//! Subset simulation of the acceptance probability when one side of it is
//! small (docs/acceptance.md, "Small probabilities").
//!
//! The series system "every constraint holds" is written as one limit state
//! in physical space over the distinct constraints of a [`Rectangles`]:
//!
//! `g(x) = min_i min(h_i − S_i·x, S_i·x − l_i) / s_i`, `s_i = √(S_iᵀΣS_i)`,
//!
//! (each margin in units of the standard deviation of its constraint, so
//! that the intermediate thresholds of subset simulation weigh the
//! constraints alike; `g ≥ 0` exactly when the machine is accepted). A
//! constraint on one input `x_j` only is measured where its probability
//! is, in `z_j = Φ⁻¹(F_j(x_j))`: its margin is `Φ⁻¹(F_j(h/c)) − z_j` (and
//! the lower one alike), so that a skewed or bounded marginal's tail is
//! not mis-weighted against the other constraints (a lognormal's
//! 4.5-σ-in-`z` threshold is 7 standard deviations in `x`, a uniform's edge
//! only 1.7: in `x` units the levels follow the uniform and lose the
//! lognormal's failure mode). When
//! the rejection probability `1 − P` is the small side, the failure event of
//! [`SubsetSimulation`] is `g ≤ 0` ("some constraint violated"); when the
//! acceptance probability `P` itself is the small side it is `−g ≤ 0`
//! ("every constraint holds"). Subset simulation works in the inputs'
//! standard normal space (`crate::standard`), so every marginal and the
//! Nataf-correlated block are handled through [`Inputs::to_physical`].
//!
//! This file only wraps the public API of [`crate::subset`].

use serde::Serialize;

use super::Rectangles;
use crate::error::ReliabilityError;
use crate::limit_state::{Event, LimitState};
use crate::sampler::Sampler;
use crate::simulation::Stopping;
use crate::subset::{SubsetLevel, SubsetSimulation};
use crate::util::dot;

/// Which side of the acceptance probability subset simulation estimated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum RareSide {
    /// The rejection probability `1 − P` ("some constraint violated").
    #[serde(rename = "rejection")]
    Rejection,
    /// The acceptance probability `P` itself ("every constraint holds").
    #[serde(rename = "acceptance")]
    Acceptance,
}

impl RareSide {
    /// `rejection` or `acceptance` (the JSON's spelling).
    pub fn name(self) -> &'static str {
        match self {
            RareSide::Rejection => "rejection",
            RareSide::Acceptance => "acceptance",
        }
    }
}

/// The subset-simulation account of an acceptance probability
/// ([`super::AcceptanceMethod::Subset`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AcceptanceSubset {
    /// The side estimated (the small one in the pilot).
    pub side: RareSide,
    /// The estimate of that side's probability.
    pub probability: f64,
    /// Its coefficient of variation (Au & Beck 2001, Eq. 27-30).
    pub cov: f64,
    /// Samples of subset simulation (every level of every run).
    pub samples: u64,
    /// Independent runs averaged.
    pub runs: u64,
    /// The levels of the first run (thresholds in units of the constraints'
    /// standard deviations).
    pub levels: Vec<SubsetLevel>,
    /// How subset simulation stopped.
    pub stopping: Stopping,
    /// Crude Monte Carlo samples of the pilot that chose this method.
    pub pilot_samples: u64,
    /// The pilot's samples on the small side (below the threshold
    /// [`super::RARE_EVENTS`]).
    pub pilot_events: u64,
}

/// The series system as a limit state (`g ≥ 0`: accepted), or its negation.
struct Series<'a> {
    system: &'a Rectangles,
    /// `1/s_i` per distinct constraint.
    inv_scale: Vec<f64>,
    /// Constraints on one input `j` only: `(j, z_lo, z_hi)`, the interval of
    /// `z_j = Φ⁻¹(F_j(x_j))` they allow (their margin is taken there).
    single: Vec<Option<(usize, f64, f64)>>,
    /// `-1` to make "accepted" the failure event.
    sign: f64,
    depends: Vec<bool>,
}

impl<'a> Series<'a> {
    fn new(system: &'a Rectangles, side: RareSide) -> Series<'a> {
        let inputs = system.inputs();
        let n = inputs.len();
        let inv_scale = (0..system.distinct())
            .map(|i| {
                let row = system.row(i).0;
                let s = inputs.covariance(row, row).sqrt();
                if s > 0.0 && s.is_finite() {
                    1.0 / s
                } else {
                    1.0
                }
            })
            .collect();
        let single = (0..system.distinct())
            .map(|i| {
                let (row, lo, hi) = system.row(i);
                let mut nz = (0..n).filter(|&j| row[j] != 0.0);
                let (Some(j), None) = (nz.next(), nz.next()) else {
                    return None;
                };
                let m = inputs.marginals()[j];
                if m.std() == 0.0 {
                    // A fixed input: the row is a constant, a general one.
                    return None;
                }
                let (s_lo, s_hi) = m.support();
                let z = |t: f64| {
                    if t.is_nan() || t <= s_lo {
                        f64::NEG_INFINITY
                    } else if t >= s_hi {
                        f64::INFINITY
                    } else {
                        m.to_standard(t)
                    }
                };
                let (a, b) = if row[j] > 0.0 {
                    (lo / row[j], hi / row[j])
                } else {
                    (hi / row[j], lo / row[j])
                };
                Some((j, z(a), z(b)))
            })
            .collect();
        let depends = (0..n)
            .map(|j| (0..system.distinct()).any(|i| system.row(i).0[j] != 0.0))
            .collect();
        Series {
            system,
            inv_scale,
            single,
            sign: match side {
                RareSide::Rejection => 1.0,
                RareSide::Acceptance => -1.0,
            },
            depends,
        }
    }

    /// The smallest standardised margin and the row and sign of its
    /// constraint (`+1`: the upper bound binds).
    fn margin(&self, x: &[f64]) -> (f64, usize, f64) {
        let mut best = (f64::INFINITY, 0, 1.0);
        for i in 0..self.system.distinct() {
            let (up, down) = match self.single[i] {
                Some((j, z_lo, z_hi)) => {
                    let z = self.system.inputs().marginals()[j].to_standard(x[j]);
                    (z_hi - z, z - z_lo)
                }
                None => {
                    let (row, lo, hi) = self.system.row(i);
                    let v = dot(row, x);
                    ((hi - v) * self.inv_scale[i], (v - lo) * self.inv_scale[i])
                }
            };
            if up < best.0 {
                best = (up, i, 1.0);
            }
            if down < best.0 {
                best = (down, i, -1.0);
            }
        }
        best
    }
}

impl LimitState for Series<'_> {
    fn dim(&self) -> usize {
        self.system.inputs().len()
    }

    fn branch(&self, _b: usize, x: &[f64], gradient: Option<&mut [f64]>) -> f64 {
        let (m, i, s) = self.margin(x);
        if let Some(g) = gradient {
            // The gradient of the binding margin (one-sided at a kink).
            match self.single[i] {
                Some((j, _, _)) => {
                    let mj = self.system.inputs().marginals()[j];
                    let slope = 1.0 / mj.dx_du(mj.to_standard(x[j]));
                    g.iter_mut().for_each(|v| *v = 0.0);
                    g[j] = -self.sign * s * slope;
                }
                None => {
                    let row = self.system.row(i).0;
                    for (g, r) in g.iter_mut().zip(row) {
                        *g = -self.sign * s * r * self.inv_scale[i];
                    }
                }
            }
        }
        self.sign * m
    }

    fn value(&self, x: &[f64]) -> f64 {
        self.sign * self.margin(x).0
    }

    fn depends_on(&self, j: usize) -> bool {
        self.depends[j]
    }
}

/// Subset simulation of `side` of `system` with `samples` per level until
/// the coefficient of variation `cov` (or `budget` samples).
pub(super) fn run(
    system: &Rectangles,
    side: RareSide,
    samples: u64,
    cov: f64,
    budget: u64,
    seed: u64,
) -> Result<(f64, f64, AcceptanceSubset), ReliabilityError> {
    let limit = Series::new(system, side);
    let event = Event::new(system.inputs(), limit)?;
    let sim = SubsetSimulation {
        cov: Some(cov),
        budget,
        ..SubsetSimulation::new(samples, seed)
    };
    let r = sim.run(&event)?;
    Ok((
        r.pf,
        r.std_error,
        AcceptanceSubset {
            side,
            probability: r.pf,
            cov: r.cov,
            samples: r.samples,
            runs: r.runs,
            levels: r.levels,
            stopping: r.stopping,
            pilot_samples: 0,
            pilot_events: 0,
        },
    ))
}
