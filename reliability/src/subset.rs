//! Subset simulation (Au & Beck 2001) with adaptive conditional sampling
//! (Papaioannou, Betz, Zwirglmaier & Straub 2015).
//!
//! The failure probability is written as a product of conditional
//! probabilities of nested events `F_1 ⊃ F_2 ⊃ … ⊃ F_m = F`,
//! `F_j = {G(u) ≤ b_j}` in standard normal space (Au & Beck 2001, Eq. 1):
//!
//! `p_f = P(F_1) · Π_{j=1}^{m−1} P(F_{j+1} | F_j)`.
//!
//! Level 0 draws `N` independent samples of `u ~ N(0, I)`; each threshold
//! `b_j` is the `p0`-quantile of the current level's `G` values (so every
//! intermediate conditional probability is `p0`, 0.1 by default), until at
//! least `p0·N` samples fail (`G ≤ 0`), when the last factor is the failing
//! fraction. The `N_c = p0·N` samples below the threshold seed `N_c` Markov
//! chains of `N_s = 1/p0` states each (the seed is the first), which
//! populate the next level conditional on `F_j`.
//!
//! # The Markov chains: adaptive conditional sampling (aCS)
//!
//! Papaioannou et al. (2015), Section 4.3 and their Algorithm 5: the
//! candidate of a state `u` is drawn component-wise from the conditional
//! normal `v_k ~ N(ρ_k·u_k, σ_k²)`, `ρ_k = √(1 − σ_k²)`, which leaves
//! `N(0, I)` invariant, so the candidate is accepted exactly when it lies in
//! `F_j` (no ratio of densities). The spreads are `σ_k = min(λ·σ̂_k, 1)`
//! with `σ̂_k` the sample standard deviation of the seeds in coordinate `k`;
//! the seeds are taken in random order, and after every group of
//! `N_a = p_a·N_c` chains (`p_a = 0.1`) the scale is adapted towards the
//! target acceptance rate `a* = 0.44`:
//! `log λ_{i+1} = log λ_i + (â_i − a*)/√i` (their Eq. 27), `â_i` being the
//! group's mean acceptance; `λ` starts at 0.6 and carries over from level
//! to level.
//!
//! # Coefficient of variation
//!
//! Au & Beck (2001), Eq. 27-29: the coefficient of variation of the
//! estimate of level `j`'s conditional probability `P_j` is
//!
//! `δ_j² = (1 − P_j)/(N·P_j) · (1 + γ_j)`,
//! `γ_j = 2·Σ_{k=1}^{N_s−1} (1 − k/N_s)·ρ_j(k)`,
//!
//! with `ρ_j(k) = R_j(k)/R_j(0)` the correlation at lag `k` of the failure
//! indicator along the chains, estimated by
//! `R_j(k) = (1/(N − k·N_c))·Σ_chains Σ_{l=1}^{N_s−k} I_l·I_{l+k} − P_j²`
//! (level 0 is independent: `γ_0 = 0`). The coefficient of variation of
//! `p_f` is taken as `δ² = Σ_j δ_j²` (their Eq. 30 with the levels
//! uncorrelated, the usual estimate; the levels' positive correlation makes
//! it a slight under-estimate, their Section 6), and `std_error = p_f·δ`.
//!
//! # Stopping
//!
//! With [`SubsetSimulation::cov`] set, independent runs (each with `N`
//! samples per level, its own random streams) are repeated until the
//! coefficient of variation of their mean, `√(Σ_r (p_r·δ_r)²)/R / p̄`, is at
//! most the target, or until the next run would exceed the sample budget
//! ([`SubsetSimulation::budget`]): then the result is marked not converged
//! ([`Stop::Budget`]). A run that reaches [`SubsetSimulation::max_levels`]
//! without `p0·N` failing samples is not converged either ([`Stop::Levels`];
//! its `p_f` is the product so far, an upper bound, not an estimate).

use serde::Serialize;

use crate::error::ReliabilityError;
use crate::limit_state::{Event, LimitState};
use crate::method::Method;
use crate::normal;
use crate::par::prelude::*;
use crate::rng::CaseRng;
use crate::sampler::{check_cov, Progress, Sampler, Stop, Stopping, Streams};
use crate::standard::Standard;

/// The target acceptance rate of the aCS adaptation (Papaioannou et al.
/// 2015, Section 4.3: 0.44, optimal for one-dimensional random walks).
const TARGET_ACCEPTANCE: f64 = 0.44;
/// The initial scale `λ` of the proposal spreads.
const INITIAL_SCALE: f64 = 0.6;
/// The fraction of the chains after which `λ` is adapted (`p_a`).
const ADAPT_FRACTION: f64 = 0.1;
/// Random streams per run (levels) in the block index of [`CaseRng`].
const LEVEL_STREAMS: u32 = 64;
/// Samples per parallel block of level 0 (each its own sub-stream).
const LEVEL0_BLOCK: usize = 1024;

/// Subset simulation with adaptive conditional sampling.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SubsetSimulation {
    /// Samples per level `N` (a multiple of `1/p0`).
    pub samples: u64,
    /// The intermediate conditional probability `p0` (0.1).
    pub p0: f64,
    /// The seed of the random streams.
    pub seed: u64,
    /// The most levels of one run (20: `p0^20 = 1e-20` with `p0 = 0.1`).
    pub max_levels: usize,
    /// A target coefficient of variation of `p_f`: independent runs are
    /// repeated until it is reached (or [`SubsetSimulation::budget`] is).
    pub cov: Option<f64>,
    /// With a target, the largest total number of samples over all runs.
    pub budget: u64,
}

impl SubsetSimulation {
    /// `samples` per level, `p0 = 0.1`, 20 levels at most, no target.
    pub fn new(samples: u64, seed: u64) -> SubsetSimulation {
        SubsetSimulation {
            samples,
            p0: 0.1,
            seed,
            max_levels: 20,
            cov: None,
            budget: 0,
        }
    }
}

/// One level of a subset-simulation run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SubsetLevel {
    /// The threshold `b_{j+1}` chosen on this level (0 on the last: the
    /// failure set itself).
    pub threshold: f64,
    /// Samples of the level (`N`).
    pub samples: u64,
    /// The conditional probability `P(F_{j+1} | F_j)` (`p0`, or the failing
    /// fraction on the last level).
    pub conditional_probability: f64,
    /// The acceptance rate of the Markov chains that populated the level
    /// (`null` on level 0, drawn independently).
    pub acceptance_rate: Option<f64>,
    /// The aCS scale `λ` at the end of the level's chains (`null` on level 0).
    pub spread: Option<f64>,
    /// Au & Beck's correlation factor `γ_j` (Eq. 28; 0 on level 0).
    pub gamma: f64,
    /// The coefficient of variation `δ_j` of the level's conditional
    /// probability (Eq. 27).
    pub cov: f64,
}

/// The result of subset simulation.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SubsetResult {
    /// The failure-probability estimate (the mean over the runs).
    pub pf: f64,
    /// `1 − p_f`.
    pub reliability: f64,
    /// The standard error of `p_f` (`p_f·δ`, the chains' correlation
    /// counted through `γ_j`).
    pub std_error: f64,
    /// The coefficient of variation `δ`.
    pub cov: f64,
    /// The generalised reliability index `−Φ⁻¹(p_f)`.
    pub beta: f64,
    /// Samples (states of all levels of all runs).
    pub samples: u64,
    /// Limit-state evaluations (the seeds are not evaluated again).
    pub calls: u64,
    /// Independent runs averaged.
    pub runs: u64,
    /// The levels of the first run.
    pub levels: Vec<SubsetLevel>,
    /// How it stopped and whether it converged.
    pub stopping: Stopping,
}

/// One run's outcome.
struct Run {
    pf: f64,
    delta2: f64,
    samples: u64,
    calls: u64,
    levels: Vec<SubsetLevel>,
    reached: bool,
}

impl SubsetSimulation {
    pub(crate) fn check(&self) -> Result<(usize, usize), ReliabilityError> {
        if !(self.p0 > 0.0 && self.p0 < 1.0) {
            return Err(ReliabilityError::InvalidSampler(format!(
                "the level probability p0 must be in (0, 1) (found {})",
                self.p0
            )));
        }
        let ns = (1.0 / self.p0).round();
        if (ns * self.p0 - 1.0).abs() > 1e-9 {
            return Err(ReliabilityError::InvalidSampler(format!(
                "1/p0 must be a whole number (p0 = {})",
                self.p0
            )));
        }
        let ns = ns as u64;
        if self.samples < ns || self.samples % ns != 0 || self.samples > (1 << 32) {
            return Err(ReliabilityError::InvalidSampler(format!(
                "the samples per level must be a positive multiple of 1/p0 = {ns}, at most 2^32 (found {})",
                self.samples
            )));
        }
        if self.max_levels == 0 || self.max_levels > LEVEL_STREAMS as usize {
            return Err(ReliabilityError::InvalidSampler(format!(
                "the number of levels must be between 1 and {LEVEL_STREAMS} (found {})",
                self.max_levels
            )));
        }
        if let Some(c) = self.cov {
            check_cov(c)?;
            if self.budget < self.samples {
                return Err(ReliabilityError::InvalidSampler(format!(
                    "the sample budget ({}) is smaller than one level ({})",
                    self.budget, self.samples
                )));
            }
        }
        Ok(((self.samples / ns) as usize, ns as usize))
    }

    /// Independent runs until the target CoV or the budget; runs go in
    /// parallel batches, the rule is checked after each run in run order
    /// (so the result does not depend on the thread count).
    fn until_cov<L: LimitState>(
        &self,
        std: &Standard<'_, '_, L>,
        case_id: u32,
        nc: usize,
        ns: usize,
        target: f64,
        progress: &dyn Progress,
    ) -> SubsetResult {
        let width = crate::par::threads().max(1) as u32;
        let mut runs: Vec<Run> = Vec::new();
        let mut used = 0u64;
        let mut next = 0u32;
        loop {
            let batch: Vec<Run> = (next..next + width)
                .into_par_iter()
                .map(|r| self.one_run(std, case_id, r, nc, ns, progress))
                .collect();
            next += width;
            for r in batch {
                if used + r.samples > self.budget {
                    return combine(runs, Stop::Budget, Some(target));
                }
                used += r.samples;
                let reached = r.reached;
                runs.push(r);
                if !reached {
                    return combine(runs, Stop::Levels, Some(target));
                }
                let (pf, se) = mean_and_error(&runs);
                if pf > 0.0 && se <= target * pf {
                    return combine(runs, Stop::TargetCov, Some(target));
                }
            }
            if next >= u32::MAX / LEVEL_STREAMS - width {
                return combine(runs, Stop::Budget, Some(target));
            }
        }
    }

    /// One run of subset simulation.
    fn one_run<L: LimitState>(
        &self,
        std: &Standard<'_, '_, L>,
        case_id: u32,
        run: u32,
        nc: usize,
        ns: usize,
        progress: &dyn Progress,
    ) -> Run {
        let n_level = nc * ns;
        let na = std.dim();
        let mut scratch = std.scratch();
        if na == 0 {
            // G does not depend on u: p_f is 0 or 1 exactly.
            let g = std.value(&[], &mut scratch);
            let pf = if g <= 0.0 { 1.0 } else { 0.0 };
            return Run {
                pf,
                delta2: 0.0,
                samples: 0,
                calls: 1,
                levels: Vec::new(),
                reached: true,
            };
        }
        let block = |level: usize| run * LEVEL_STREAMS + level as u32;
        // Level 0: independent draws, in blocks of `LEVEL0_BLOCK` samples
        // in parallel, block `k` from sub-stream `k + 1` of the level's
        // stream.
        let mut u = vec![0.0; n_level * na];
        let mut g = vec![0.0; n_level];
        u.par_chunks_mut(LEVEL0_BLOCK * na)
            .zip(g.par_chunks_mut(LEVEL0_BLOCK))
            .enumerate()
            .map_init(
                || std.scratch(),
                |scratch, (k, (u, g))| {
                    let mut rng = CaseRng::substream(self.seed, case_id, block(0), k as u32 + 1);
                    rng.fill_normal(u);
                    for (ui, gi) in u.chunks_exact(na).zip(g.iter_mut()) {
                        *gi = std.value(ui, scratch);
                    }
                },
            )
            .for_each(drop);
        progress.advance(n_level as u64);
        let mut calls = n_level as u64;
        let mut samples = n_level as u64;
        let mut levels = Vec::new();
        let mut pf = 1.0;
        let mut delta2 = 0.0;
        let mut chains = false;
        let mut acceptance = None;
        let mut spread = None;
        let mut lambda = INITIAL_SCALE;
        let mut order: Vec<usize> = (0..n_level).collect();
        let mut next_u = vec![0.0; n_level * na];
        let mut next_g = vec![0.0; n_level];
        for level in 0..self.max_levels {
            let failing = g.iter().filter(|&&v| v <= 0.0).count();
            let last = failing >= nc;
            let (threshold, p) = if last {
                (0.0, failing as f64 / n_level as f64)
            } else {
                // The nc lowest first (a selection, not a sort): the
                // threshold halves the gap between the nc-th and the next.
                order.select_nth_unstable_by(nc - 1, |&a, &b| g[a].total_cmp(&g[b]));
                let below = g[order[nc - 1]];
                let above = order[nc..]
                    .iter()
                    .map(|&i| g[i])
                    .fold(f64::INFINITY, f64::min);
                (0.5 * (below + above), self.p0)
            };
            let gamma = if chains {
                gamma_factor(&g, threshold, nc, ns, p)
            } else {
                0.0
            };
            let d2 = if p > 0.0 {
                (1.0 - p) / (n_level as f64 * p) * (1.0 + gamma)
            } else {
                0.0
            };
            pf *= p;
            delta2 += d2;
            levels.push(SubsetLevel {
                threshold,
                samples: n_level as u64,
                conditional_probability: p,
                acceptance_rate: acceptance,
                spread,
                gamma,
                cov: d2.sqrt(),
            });
            if last {
                return Run {
                    pf,
                    delta2,
                    samples,
                    calls,
                    levels,
                    reached: true,
                };
            }
            if level + 1 == self.max_levels {
                break;
            }
            // The seeds (the nc lowest), in random order (Fisher-Yates).
            let mut rng = CaseRng::new(self.seed, case_id, block(level + 1));
            let seeds = &mut order[..nc];
            for i in (1..nc).rev() {
                let j = (rng.uniform() * (i + 1) as f64) as usize;
                seeds.swap(i, j.min(i));
            }
            // σ̂_k: the seeds' sample standard deviation per coordinate.
            let mut sigma_hat = vec![1.0; na];
            if nc > 1 {
                for (k, s) in sigma_hat.iter_mut().enumerate() {
                    let mean = seeds.iter().map(|&i| u[i * na + k]).sum::<f64>() / nc as f64;
                    let var = seeds
                        .iter()
                        .map(|&i| (u[i * na + k] - mean).powi(2))
                        .sum::<f64>()
                        / (nc - 1) as f64;
                    *s = var.sqrt();
                }
            }
            let level_data = Level {
                seeds,
                u: &u,
                g: &g,
                sigma_hat: &sigma_hat,
                threshold,
                ns,
            };
            let out = (&mut next_u[..], &mut next_g[..]);
            let streams = (self.seed, case_id, block(level + 1));
            // The dimension as a constant for the common small cases, so
            // the per-state loops are unrolled.
            let (accepted, proposed) = match na {
                1 => level_data.populate::<1, L>(std, streams, &mut lambda, out),
                2 => level_data.populate::<2, L>(std, streams, &mut lambda, out),
                3 => level_data.populate::<3, L>(std, streams, &mut lambda, out),
                4 => level_data.populate::<4, L>(std, streams, &mut lambda, out),
                5 => level_data.populate::<5, L>(std, streams, &mut lambda, out),
                6 => level_data.populate::<6, L>(std, streams, &mut lambda, out),
                7 => level_data.populate::<7, L>(std, streams, &mut lambda, out),
                8 => level_data.populate::<8, L>(std, streams, &mut lambda, out),
                _ => level_data.populate::<0, L>(std, streams, &mut lambda, out),
            };
            let new = (nc * (ns - 1)) as u64;
            calls += new;
            samples += n_level as u64;
            progress.advance(n_level as u64);
            acceptance = Some(if proposed > 0 {
                accepted as f64 / proposed as f64
            } else {
                0.0
            });
            spread = Some(lambda);
            std::mem::swap(&mut u, &mut next_u);
            std::mem::swap(&mut g, &mut next_g);
            chains = true;
        }
        // The levels ran out before p0·N samples failed.
        Run {
            pf,
            delta2,
            samples,
            calls,
            levels,
            reached: false,
        }
    }
}

impl Sampler for SubsetSimulation {
    type Output = SubsetResult;

    fn method(&self) -> Method {
        Method::Subset
    }

    /// Runs the events in parallel; case `i` draws from streams
    /// `streams.id(i) << 32 | (run·64 + level)`.
    fn run_streams<L: LimitState>(
        &self,
        events: &[Event<'_, L>],
        streams: Streams<'_>,
        progress: &dyn Progress,
    ) -> Result<Vec<SubsetResult>, ReliabilityError> {
        let (nc, ns) = self.check()?;
        let case = |i: usize| -> SubsetResult {
            let std = Standard::new(&events[i]);
            let case_id = streams.id(i);
            match self.cov {
                None => {
                    let r = self.one_run(&std, case_id, 0, nc, ns, progress);
                    let stop = if r.reached {
                        Stop::Samples
                    } else {
                        Stop::Levels
                    };
                    combine(vec![r], stop, None)
                }
                Some(target) => self.until_cov(&std, case_id, nc, ns, target, progress),
            }
        };
        Ok(crate::par::in_pool(|| {
            if events.len() == 1 {
                vec![case(0)]
            } else {
                (0..events.len()).into_par_iter().map(case).collect()
            }
        }))
    }
}

/// What the Markov chains of one level start from.
struct Level<'a> {
    /// The seeds (indices into `u` and `g`), in the order the chains run.
    seeds: &'a [usize],
    /// The states of the previous level, `na` coordinates each.
    u: &'a [f64],
    /// Their values of `G`.
    g: &'a [f64],
    /// The seeds' standard deviation per coordinate.
    sigma_hat: &'a [f64],
    /// The level's threshold `b_j`.
    threshold: f64,
    /// States per chain `N_s` (the seed is the first).
    ns: usize,
}

impl Level<'_> {
    /// Runs the aCS chains of one level (Papaioannou et al. 2015,
    /// Algorithm 5), writing chain `c` to states `c·N_s..(c+1)·N_s` of
    /// `next` (coordinates and values); adapts `λ` after every group of
    /// chains. Returns the accepted and the proposed moves. `N` is the
    /// dimension when known at compile time (0: `sigma_hat.len()`).
    fn populate<const N: usize, L: LimitState>(
        &self,
        std: &Standard<'_, '_, L>,
        streams: (u64, u32, u32),
        lambda: &mut f64,
        (next_u, next_g): (&mut [f64], &mut [f64]),
    ) -> (u64, u64) {
        let na = if N > 0 { N } else { self.sigma_hat.len() };
        let ns = self.ns;
        let nc = self.seeds.len();
        let group = ((ADAPT_FRACTION * nc as f64).floor() as usize).max(1);
        let spreads = |lambda: f64| -> (Vec<f64>, Vec<f64>) {
            let s: Vec<f64> = self
                .sigma_hat
                .iter()
                .map(|h| (lambda * h).min(1.0))
                .collect();
            let r = s.iter().map(|s| (1.0 - s * s).max(0.0).sqrt()).collect();
            (s, r)
        };
        let mut adapt_step = 1.0f64;
        let (mut accepted, mut proposed) = (0u64, 0u64);
        let (seed, case_id, block) = streams;
        for first in (0..nc).step_by(group) {
            let last = (first + group).min(nc);
            let (sig, rho) = spreads(*lambda);
            let (r, s) = (&rho[..na], &sig[..na]);
            // The chains of one group share the spreads and run in
            // parallel; chain `c` draws from sub-stream `c + 1` of the
            // level's block.
            let chain_u = &mut next_u[first * ns * na..last * ns * na];
            let chain_g = &mut next_g[first * ns..last * ns];
            let accepted_group: u64 = chain_u
                .par_chunks_mut(ns * na)
                .zip(chain_g.par_chunks_mut(ns))
                .enumerate()
                .map_init(
                    || (std.scratch(), vec![0.0; na], vec![0.0; na]),
                    |(scratch, cand, z), (k, (chain_u, chain_g))| {
                        let c = first + k;
                        let mut rng = CaseRng::substream(seed, case_id, block, c as u32 + 1);
                        self.chain::<N, L>(
                            std,
                            (r, s),
                            &mut rng,
                            (scratch, cand, z),
                            c,
                            (chain_u, chain_g),
                        )
                    },
                )
                .sum();
            let proposed_group = ((last - first) * (ns - 1)) as u64;
            accepted += accepted_group;
            proposed += proposed_group;
            if last - first == group && proposed_group > 0 {
                let rate = accepted_group as f64 / proposed_group as f64;
                *lambda = (lambda.ln() + (rate - TARGET_ACCEPTANCE) / adapt_step.sqrt()).exp();
                adapt_step += 1.0;
            }
        }
        (accepted, proposed)
    }

    /// One aCS chain from seed `c` (Papaioannou et al. 2015, Algorithm 5:
    /// `v_k = ρ_k·u_k + σ_k·z_k`, kept when `G(v) ≤ b_j`), its `N_s` states
    /// written to `chain_u` and `chain_g`; returns the accepted moves.
    #[inline]
    #[allow(clippy::too_many_arguments)]
    fn chain<const N: usize, L: LimitState>(
        &self,
        std: &Standard<'_, '_, L>,
        (r, s): (&[f64], &[f64]),
        rng: &mut CaseRng,
        (scratch, cand, z): (&mut crate::standard::Scratch, &mut [f64], &mut [f64]),
        c: usize,
        (chain_u, chain_g): (&mut [f64], &mut [f64]),
    ) -> u64 {
        let na = if N > 0 { N } else { self.sigma_hat.len() };
        let seed = self.seeds[c];
        chain_u[..na].copy_from_slice(&self.u[seed * na..(seed + 1) * na]);
        chain_g[0] = self.g[seed];
        let (r, s) = (&r[..na], &s[..na]);
        let mut accepted = 0u64;
        for t in 1..self.ns {
            let z = &mut z[..na];
            rng.fill_normal(z);
            let (done, rest) = chain_u.split_at_mut(t * na);
            let prev = &done[(t - 1) * na..t * na];
            let next = &mut rest[..na];
            let cand = &mut cand[..na];
            for k in 0..na {
                cand[k] = r[k] * prev[k] + s[k] * z[k];
            }
            let gc = std.value(cand, scratch);
            // Accept or stay, without a data-dependent branch (the
            // acceptance rate is near 0.44, the worst case for a branch
            // predictor).
            let accept = gc <= self.threshold;
            for k in 0..na {
                next[k] = if accept { cand[k] } else { prev[k] };
            }
            chain_g[t] = if accept { gc } else { chain_g[t - 1] };
            accepted += u64::from(accept);
        }
        accepted
    }
}

/// Au & Beck (2001) Eq. 28-29: `γ = 2·Σ_{k=1}^{N_s−1}(1 − k/N_s)·ρ(k)`
/// from the indicator `G ≤ b` along `nc` chains of `ns` states (chain-major).
fn gamma_factor(g: &[f64], b: f64, nc: usize, ns: usize, p: f64) -> f64 {
    let r0 = p * (1.0 - p);
    if r0 <= 0.0 || ns < 2 {
        return 0.0;
    }
    let n = (nc * ns) as f64;
    let sums: Vec<u64> = if ns <= 64 {
        lag_pairs_bits(g, b, ns)
    } else {
        lag_pairs_scan(g, b, ns)
    };
    sums.iter()
        .enumerate()
        .map(|(i, &sum)| {
            let k = i + 1;
            let rk = sum as f64 / (n - (k * nc) as f64) - p * p;
            2.0 * (1.0 - k as f64 / ns as f64) * rk / r0
        })
        .fold(0.0, |gamma, term| gamma + term)
}

/// For each lag `k = 1..ns`, the number of pairs `(l, l + k)` of states of
/// one chain both with `G ≤ b`, over all chains (`ns ≤ 64`): each chain's
/// indicators are the bits of one word, and the pairs at lag `k` are the
/// set bits of `m & (m >> k)`.
fn lag_pairs_bits(g: &[f64], b: f64, ns: usize) -> Vec<u64> {
    let masks: Vec<u64> = g
        .chunks_exact(ns)
        .map(|chain| {
            chain
                .iter()
                .enumerate()
                .fold(0u64, |m, (l, &v)| m | (u64::from(v <= b) << l))
        })
        .collect();
    (1..ns)
        .map(|k| {
            masks
                .iter()
                .map(|&m| u64::from((m & (m >> k)).count_ones()))
                .sum()
        })
        .collect()
}

/// [`lag_pairs_bits`] for any chain length, by a scan of the indicators.
fn lag_pairs_scan(g: &[f64], b: f64, ns: usize) -> Vec<u64> {
    let ind: Vec<bool> = g.iter().map(|&v| v <= b).collect();
    (1..ns)
        .map(|k| {
            ind.chunks_exact(ns)
                .map(|chain| (0..ns - k).filter(|&l| chain[l] && chain[l + k]).count() as u64)
                .sum()
        })
        .collect()
}

/// The mean of the runs' estimates and its standard error
/// `√(Σ_r (p_r·δ_r)²)/R`.
fn mean_and_error(runs: &[Run]) -> (f64, f64) {
    let r = runs.len().max(1) as f64;
    let pf = runs.iter().map(|x| x.pf).sum::<f64>() / r;
    let var: f64 = runs.iter().map(|x| x.pf * x.pf * x.delta2).sum();
    (pf, var.sqrt() / r)
}

fn combine(runs: Vec<Run>, stop: Stop, target: Option<f64>) -> SubsetResult {
    let (pf, se) = mean_and_error(&runs);
    let samples = runs.iter().map(|r| r.samples).sum();
    let calls = runs.iter().map(|r| r.calls).sum();
    let count = runs.len() as u64;
    let levels = runs
        .into_iter()
        .next()
        .map(|r| r.levels)
        .unwrap_or_default();
    SubsetResult {
        pf,
        reliability: 1.0 - pf,
        std_error: se,
        cov: if pf > 0.0 { se / pf } else { 0.0 },
        beta: normal::beta_from_pf(pf),
        samples,
        calls,
        runs: count,
        levels,
        stopping: Stopping::new(stop, target),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gamma_is_zero_for_chains_that_never_repeat_and_positive_for_constant_chains() {
        // Chains alternating in/out have negative lag-1 correlation; constant
        // chains (all in or all out) have γ = 2·Σ(1 − k/N_s) = N_s − 1.
        let (nc, ns) = (4, 10);
        let g: Vec<f64> = (0..nc * ns)
            .map(|i| if (i / ns) % 2 == 0 { -1.0 } else { 1.0 })
            .collect();
        let gamma = gamma_factor(&g, 0.0, nc, ns, 0.5);
        assert!((gamma - (ns as f64 - 1.0)).abs() < 1e-12, "{gamma}");
    }

    #[test]
    fn lag_pairs_by_bits_equal_the_scan() {
        // Pseudo-random indicators (a fixed LCG), chains of 10 and of 64.
        let mut state = 12345u64;
        for ns in [2, 10, 64] {
            let g: Vec<f64> = (0..50 * ns)
                .map(|_| {
                    state = state.wrapping_mul(6364136223846793005).wrapping_add(1);
                    (state >> 11) as f64 / (1u64 << 53) as f64 - 0.3
                })
                .collect();
            let bits = lag_pairs_bits(&g, 0.0, ns);
            assert_eq!(bits, lag_pairs_scan(&g, 0.0, ns), "ns = {ns}");
            assert!(bits.iter().any(|&s| s > 0), "ns = {ns}");
        }
    }

    #[test]
    fn settings_are_checked() {
        let mut s = SubsetSimulation::new(1005, 1);
        assert!(matches!(
            s.check(),
            Err(ReliabilityError::InvalidSampler(_))
        ));
        s.samples = 1000;
        assert_eq!(s.check().unwrap(), (100, 10));
        s.p0 = 0.3;
        assert!(s.check().is_err());
        s.p0 = 0.1;
        s.cov = Some(0.0);
        s.budget = 10_000;
        assert_eq!(s.check(), Err(ReliabilityError::InvalidTargetCov(0.0)));
    }
}
