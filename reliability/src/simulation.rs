//! Simulation: the advanced importance sampling of the paper (Eq. 23-28) and
//! crude Monte Carlo, on one driver.
//!
//! Both split every case into blocks of [`BLOCK`] samples; block `b` of case
//! `c` draws from its own xoshiro256++ stream (`c << 32 | b`, see [`crate::rng`]),
//! rayon runs the blocks of all cases in parallel, and the per-block sums are
//! added in block order. Results are therefore bit-identical for a given seed
//! whatever the number of threads. Nothing is allocated inside the sampling
//! loops: each worker reuses one scratch buffer.
//!
//! # Importance sampling (Eq. 23-28)
//!
//! With the FORM design direction `α` (Eq. 22) the orthogonal matrix
//! `H = [H̃, α]` (a Householder reflection, Eq. 23-24) rotates standard space so
//! that the last coordinate `P_n` runs along `α`. For each sample `p̃` of the
//! other `n − 1` coordinates the line `u(t) = H̃·p̃ + t·α` is searched for the
//! failure set; the conditional failure probability along it is
//! `Φ(−h(p̃))` when the failure set is `t ≥ h` (Eq. 25-27) and in general the
//! standard normal mass of `{t : g(u(t)) ≤ 0}`. The estimate is the sample
//! mean of these probabilities (Eq. 28).
//!
//! For a tolerance limit state in normal inputs every component is affine in
//! `t`, so the safe set on the line is an interval found exactly (a half-line,
//! a slab or the chord of the volumetric ellipsoid). Otherwise (non-normal
//! inputs, a user's limit state) a bracketing scan refined by the Illinois
//! method finds every sign change of `g` on the line.

use crate::error::ReliabilityError;
use crate::form::{Form, FormResult, Termination};
use crate::limit_state::{Criterion, Event, LimitState};
use crate::method::Method;
use crate::normal;
use crate::par::prelude::*;
use crate::rng::CaseRng;
pub use crate::sampler::{check_cov, Progress, SimulationResult, Stop, Stopping, MAX_SAMPLES};
use crate::sampler::{check_samples, drive, finish, Sampler, Streams, Sums};
use crate::util::dot;
use chain_core::model::Sided;

/// Samples per block (the unit of parallel work and of random streams).
pub const BLOCK: u64 = 1 << 16;

/// Crude Monte Carlo: `p_f ≈ (1/N)·Σ 1[g(x_i) ≤ 0]` with `x_i` drawn from the
/// inputs; standard error `√(p_f(1 − p_f)/(N − 1))`. Run through
/// [`Sampler`]:
///
/// ```
/// use reliability::{Event, Inputs, Marginal, MonteCarlo, Sampler, ToleranceLimitState};
/// use chain_core::model::Sided;
/// let inputs = Inputs::new(vec!["e".into()], vec![Marginal::normal(0.0, 1.0).unwrap()]).unwrap();
/// let g = ToleranceLimitState::component(vec![1.0], 1.0, Sided::Upper).unwrap();
/// let r = MonteCarlo { samples: 100_000, seed: 1, cov: None }.run(&Event::new(&inputs, g).unwrap()).unwrap();
/// assert!((r.pf - 0.158_655).abs() < 4.0 * r.std_error);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MonteCarlo {
    /// Samples per case (with a target CoV: the largest number).
    pub samples: u64,
    /// The seed of the random streams.
    pub seed: u64,
    /// A target coefficient of variation of `p_f`: blocks are added until
    /// it is reached or `samples` are used.
    pub cov: Option<f64>,
}

/// The advanced importance sampling of Eq. 23-28, centred by FORM.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImportanceSampling {
    /// Samples per case (with a target CoV: the largest number).
    pub samples: u64,
    /// The seed of the random streams.
    pub seed: u64,
    /// The FORM settings for the design direction.
    pub form: Form,
    /// A target coefficient of variation of `p_f`: blocks are added until
    /// it is reached or `samples` are used.
    pub cov: Option<f64>,
}

impl Sampler for MonteCarlo {
    type Output = SimulationResult;

    fn method(&self) -> Method {
        Method::MonteCarlo
    }

    /// Case `i` draws from streams `streams.id(i) << 32 | block`.
    ///
    /// With a target coefficient of variation ([`MonteCarlo::cov`]) each
    /// case runs until its estimate's CoV is at most the target (checked
    /// after every block of [`BLOCK`] samples, in block order), `samples`
    /// being the budget: a case that uses it up first is marked not
    /// converged ([`Stop::Budget`]). A case with no failure yet has no CoV
    /// and goes on. The estimate is bit-identical to a run of the same seed
    /// with the number of samples it stopped at.
    fn run_streams<L: LimitState>(
        &self,
        events: &[Event<'_, L>],
        streams: Streams<'_>,
        progress: &dyn Progress,
    ) -> Result<Vec<SimulationResult>, ReliabilityError> {
        if let Some(target) = self.cov {
            check_cov(target)?;
        }
        check_samples(self.samples)?;
        let width = events.iter().map(|e| e.inputs.len()).max().unwrap_or(0);
        // Tolerance limit states in normal inputs are evaluated on the
        // standard normal draws directly, E_c = m_c + a_c·z: the same samples
        // (all n inputs drawn) without the x = μ + σ·z pass.
        let affine: Vec<Option<AffineMc>> = events.iter().map(AffineMc::new).collect();
        let block = |case: usize, block: u32, count: u64, x: &mut [f64]| {
            let event = &events[case];
            let x = &mut x[..event.inputs.len()];
            let mut rng = CaseRng::new(self.seed, streams.id(case), block);
            let mut fails = 0u64;
            if let Some(a) = &affine[case] {
                for _ in 0..count {
                    rng.fill_normal(x);
                    fails += u64::from(a.fails(x));
                }
            } else {
                for _ in 0..count {
                    event.inputs.sample(&mut rng, x);
                    if event.limit_state.value(x) <= 0.0 {
                        fails += 1;
                    }
                }
            }
            let f = fails as f64;
            Sums {
                s1: f,
                s2: f,
                calls: count,
            }
        };
        let estimate = |s: &Sums, samples: u64| {
            let n = samples as f64;
            let pf = s.s1 / n;
            let var = if samples > 1 {
                (pf * (1.0 - pf) * n / (n - 1.0)).max(0.0)
            } else {
                0.0
            };
            (pf, (var / n).sqrt())
        };
        let runs = drive(
            events.len(),
            self.samples,
            BLOCK,
            width,
            progress,
            block,
            self.cov.map(|t| {
                (t, move |_: usize, s: &Sums, n: u64| {
                    let (pf, se) = estimate(s, n);
                    s.s1 > 0.0 && se <= t * pf
                })
            }),
        );
        Ok(runs
            .into_iter()
            .map(|(s, samples, stopping)| {
                let (pf, se) = estimate(&s, samples);
                let mut r = finish(Method::MonteCarlo, pf, se, samples, s.calls, None);
                r.stopping = stopping;
                r
            })
            .collect())
    }
}

impl ImportanceSampling {
    /// Runs several events with their FORM results already computed; case
    /// `i` draws from streams `i << 32 | block`.
    ///
    /// With a target coefficient of variation ([`ImportanceSampling::cov`])
    /// each case runs until its CoV is at most the target (checked after
    /// every block of [`BLOCK`] samples, in block order), `samples` being
    /// the budget ([`Stop::Budget`]: not converged). A zero-variance
    /// estimate (the linear-normal case) stops after its first block.
    pub fn run_cases_with<L: LimitState>(
        &self,
        events: &[Event<'_, L>],
        forms: Vec<FormResult>,
        progress: &dyn Progress,
    ) -> Result<Vec<SimulationResult>, ReliabilityError> {
        self.run_forms(events, forms, Streams::ALL, progress)
    }

    /// [`ImportanceSampling::run_cases_with`], case `i` on the streams of
    /// `streams.id(i)`.
    fn run_forms<L: LimitState>(
        &self,
        events: &[Event<'_, L>],
        forms: Vec<FormResult>,
        streams: Streams<'_>,
        progress: &dyn Progress,
    ) -> Result<Vec<SimulationResult>, ReliabilityError> {
        if let Some(target) = self.cov {
            check_cov(target)?;
        }
        check_samples(self.samples)?;
        if forms.len() != events.len() {
            return Err(ReliabilityError::Dimension {
                what: "FORM results",
                expected: events.len(),
                found: forms.len(),
            });
        }
        let kernels: Vec<Kernel> = events
            .iter()
            .zip(&forms)
            .map(|(e, f)| Kernel::new(e, f))
            .collect();
        let width = kernels.iter().map(Kernel::scratch).max().unwrap_or(0);
        let block = |case: usize, block: u32, count: u64, scratch: &mut [f64]| {
            let mut rng = CaseRng::new(self.seed, streams.id(case), block);
            kernels[case].block(&events[case], &mut rng, count, scratch)
        };
        let estimate = |k: &Kernel, s: &Sums, samples: u64| {
            let n = samples as f64;
            let mean = s.s1 / n;
            let pf = k.shift + mean;
            let var = if samples > 1 {
                ((s.s2 - s.s1 * mean) / (n - 1.0)).max(0.0)
            } else {
                0.0
            };
            (pf.clamp(0.0, 1.0), (var / n).sqrt())
        };
        let runs = drive(
            events.len(),
            self.samples,
            BLOCK,
            width,
            progress,
            block,
            self.cov.map(|t| {
                let kernels = &kernels;
                (t, move |case: usize, s: &Sums, n: u64| {
                    let (pf, se) = estimate(&kernels[case], s, n);
                    // A zero-variance estimate (a linear limit state in
                    // normal inputs, or p_f = 0 or 1 exactly) is exact.
                    se == 0.0 || se <= t * pf
                })
            }),
        );
        Ok(runs
            .into_iter()
            .zip(&kernels)
            .zip(forms)
            .map(|(((s, samples, stopping), k), form)| {
                let (pf, se) = estimate(k, &s, samples);
                let mut r = finish(
                    Method::ImportanceSampling,
                    pf,
                    se,
                    samples,
                    s.calls,
                    Some(form),
                );
                r.stopping = stopping;
                r
            })
            .collect())
    }
}

impl Sampler for ImportanceSampling {
    type Output = SimulationResult;

    fn method(&self) -> Method {
        Method::ImportanceSampling
    }

    /// FORM on every event first (its design direction centres the
    /// sampling), then [`ImportanceSampling::run_cases_with`] on the streams
    /// of `streams`.
    fn run_streams<L: LimitState>(
        &self,
        events: &[Event<'_, L>],
        streams: Streams<'_>,
        progress: &dyn Progress,
    ) -> Result<Vec<SimulationResult>, ReliabilityError> {
        let forms = events
            .par_iter()
            .map(|e| self.form.run(e))
            .collect::<Result<Vec<_>, _>>()?;
        self.run_forms(events, forms, streams, progress)
    }
}

/// A tolerance limit state in normal inputs seen on standard normal draws:
/// `E_c = m_c + a_c·z`.
struct AffineMc {
    k: usize,
    n: usize,
    m: Vec<f64>,
    a: Vec<f64>,
    tolerances: Vec<f64>,
    criterion: Criterion,
}

impl AffineMc {
    fn new<L: LimitState>(event: &Event<'_, L>) -> Option<AffineMc> {
        let aff = event.affine()?;
        let ls = aff.view;
        Some(AffineMc {
            k: ls.components(),
            n: event.inputs.len(),
            m: aff.mean.clone(),
            a: aff.a.clone(),
            tolerances: ls.tolerances().to_vec(),
            criterion: ls.criterion(),
        })
    }

    /// Whether `g ≤ 0` at the draw `z`.
    #[inline]
    fn fails(&self, z: &[f64]) -> bool {
        let e = |c: usize| self.m[c] + dot(&self.a[c * self.n..(c + 1) * self.n], z);
        self.criterion.fails(&self.tolerances, self.k, e)
    }
}

/// What one case of the importance sampling needs, prepared once.
struct Kernel {
    /// The conditional `p_f` of the central line: samples accumulate
    /// `v − shift`, so an exact zero variance stays zero.
    shift: f64,
    kind: KernelKind,
}

enum KernelKind {
    /// `g` does not depend on the inputs, or only on one (no randomness left).
    Constant(f64),
    /// Tolerance structure in normal inputs: `E_c(t) = m_c + w_c·p̃ + t·d_c`.
    Affine {
        dim: usize,
        k: usize,
        m: Vec<f64>,
        w: Vec<f64>,
        d: Vec<f64>,
        tolerances: Vec<f64>,
        criterion: Criterion,
    },
    /// Anything else: scan and refine `g(T(H̃·p̃ + t·α))`.
    General {
        active: Vec<usize>,
        v: Vec<f64>,
        vv: f64,
        alpha: Vec<f64>,
        beta: f64,
        n: usize,
    },
}

impl Kernel {
    fn new<L: LimitState>(event: &Event<'_, L>, form: &FormResult) -> Kernel {
        let n = event.inputs.len();
        let ls = &event.limit_state;
        // The standard coordinates g depends on (with correlated inputs,
        // u_j moves every later member of the block, not x_j only).
        let depends: Vec<bool> = (0..n).map(|j| ls.depends_on(j)).collect();
        let depends = event.inputs.standard_dependence(&depends);
        let active: Vec<usize> = (0..n).filter(|&j| depends[j]).collect();
        if form.termination == Termination::Degenerate
            || active.is_empty()
            || !form.beta.is_finite()
        {
            // No usable direction: g does not depend on the inputs (or the
            // design point is at infinity), so p_f is 0 or 1.
            let u = vec![0.0; n];
            let mut x = vec![0.0; n];
            event.inputs.to_physical(&u, &mut x);
            let pf = if ls.value(&x) <= 0.0 { 1.0 } else { 0.0 };
            return Kernel {
                shift: pf,
                kind: KernelKind::Constant(pf),
            };
        }
        let na = active.len();
        let alpha: Vec<f64> = active.iter().map(|&j| form.alpha[j]).collect();
        // Householder: v = α + s·e_n, H₀ = I − 2vvᵀ/vᵀv maps e_n to −s·α;
        // H = H₀·diag(1, …, 1, −s) has α as its last column (Eq. 23).
        let s = if alpha[na - 1] >= 0.0 { 1.0 } else { -1.0 };
        let mut v = alpha.clone();
        v[na - 1] += s;
        let vv = dot(&v, &v);
        if let Some(aff) = event.affine() {
            let lsx = aff.view;
            let k = lsx.components();
            let dim = na - 1;
            let mut w = vec![0.0; k * dim];
            let mut d = vec![0.0; k];
            for c in 0..k {
                let a: Vec<f64> = active.iter().map(|&j| aff.row(c)[j]).collect();
                let va = dot(&v, &a);
                // w_c = H̃ᵀ·a_c: column i of H₀ is e_i − 2·v·v_i/vᵀv.
                for i in 0..dim {
                    w[c * dim + i] = a[i] - 2.0 * v[i] * va / vv;
                }
                d[c] = dot(&alpha, &a);
            }
            if dim == 0 {
                let p = line_pf_affine(
                    &aff.mean,
                    &[],
                    &d,
                    &[],
                    lsx.tolerances(),
                    lsx.criterion(),
                    0,
                    k,
                );
                return Kernel {
                    shift: p,
                    kind: KernelKind::Constant(p),
                };
            }
            // Centre the sums on the conditional p_f of the central line
            // (p̃ = 0): exact for a linear limit state, so its zero variance
            // is not spoilt by rounding.
            let zeros = vec![0.0; dim];
            let shift = line_pf_affine(
                &aff.mean,
                &w,
                &d,
                &zeros,
                lsx.tolerances(),
                lsx.criterion(),
                dim,
                k,
            );
            return Kernel {
                shift,
                kind: KernelKind::Affine {
                    dim,
                    k,
                    m: aff.mean.clone(),
                    w,
                    d,
                    tolerances: lsx.tolerances().to_vec(),
                    criterion: lsx.criterion(),
                },
            };
        }
        // Centre on the central line's conditional p_f, as above.
        let shift = {
            let mut u = vec![0.0; n];
            let mut x = vec![0.0; n];
            let mut line = |t: f64| {
                for (i, &j) in active.iter().enumerate() {
                    u[j] = t * alpha[i];
                }
                event.inputs.to_physical(&u, &mut x);
                ls.value(&x)
            };
            line_pf_scan(&mut line, form.beta)
        };
        Kernel {
            shift,
            kind: KernelKind::General {
                active,
                v,
                vv,
                alpha,
                beta: form.beta,
                n,
            },
        }
    }

    /// Scratch length needed by [`Kernel::block`].
    fn scratch(&self) -> usize {
        match &self.kind {
            KernelKind::Constant(_) => 0,
            KernelKind::Affine { dim, .. } => *dim,
            KernelKind::General { active, n, .. } => active.len() + 3 * n,
        }
    }

    fn block<L: LimitState>(
        &self,
        event: &Event<'_, L>,
        rng: &mut CaseRng,
        count: u64,
        scratch: &mut [f64],
    ) -> Sums {
        let mut s1 = 0.0;
        let mut s2 = 0.0;
        let mut calls = 0u64;
        match &self.kind {
            KernelKind::Constant(p) => {
                let v = p - self.shift;
                s1 = v * count as f64;
                s2 = v * v * count as f64;
            }
            KernelKind::Affine {
                dim,
                k,
                m,
                w,
                d,
                tolerances,
                criterion,
            } => {
                let z = &mut scratch[..*dim];
                if *k == 1 && *criterion == Criterion::Each(Sided::Upper) && d[0] > 0.0 {
                    // One upper tolerance (Eq. 25-28 as printed): failure is
                    // t ≥ h with h = (I − m − w·p̃)/d, and p = Φ(−h).
                    // In batches, so that the Φ evaluations of independent
                    // samples overlap in the pipeline.
                    let (inv_d, top) = (1.0 / d[0], tolerances[0] - m[0]);
                    let mut h = [0.0f64; 32];
                    let mut left = count;
                    while left > 0 {
                        let nb = left.min(32) as usize;
                        for hi in &mut h[..nb] {
                            rng.fill_normal(z);
                            *hi = (top - dot(w, z)) * inv_d;
                        }
                        for &hi in &h[..nb] {
                            let v = normal::sf(hi) - self.shift;
                            s1 += v;
                            s2 += v * v;
                        }
                        left -= nb as u64;
                    }
                } else {
                    for _ in 0..count {
                        rng.fill_normal(z);
                        let p = line_pf_affine(m, w, d, z, tolerances, *criterion, *dim, *k);
                        let v = p - self.shift;
                        s1 += v;
                        s2 += v * v;
                    }
                }
                calls = count;
            }
            KernelKind::General {
                active,
                v,
                vv,
                alpha,
                beta,
                n,
            } => {
                let na = active.len();
                let (z, rest) = scratch.split_at_mut(na);
                let (u, rest) = rest.split_at_mut(*n);
                let (x, rest) = rest.split_at_mut(*n);
                let y0 = &mut rest[..*n];
                // Inputs g does not depend on sit at their medians (u = 0).
                u.iter_mut().for_each(|e| *e = 0.0);
                for _ in 0..count {
                    // p̃ in the first na−1 slots, 0 in the last: y0 = H₀·(p̃, 0).
                    rng.fill_normal(&mut z[..na - 1]);
                    z[na - 1] = 0.0;
                    let vz = dot(v, z);
                    y0.iter_mut().for_each(|e| *e = 0.0);
                    for (i, &j) in active.iter().enumerate() {
                        y0[j] = z[i] - 2.0 * v[i] * vz / vv;
                    }
                    let mut line = |t: f64| {
                        for (i, &j) in active.iter().enumerate() {
                            u[j] = y0[j] + t * alpha[i];
                        }
                        event.inputs.to_physical(u, x);
                        calls += 1;
                        event.limit_state.value(x)
                    };
                    let p = line_pf_scan(&mut line, *beta);
                    let v = p - self.shift;
                    s1 += v;
                    s2 += v * v;
                }
            }
        }
        Sums { s1, s2, calls }
    }
}

/// The failure probability along `t ↦ E_c = m_c + w_c·z + t·d_c`, `t ~ N(0, 1)`:
/// the safe set is an interval `[lo, hi]`, so `p = Φ(lo) + Φ(−hi)`.
#[allow(clippy::too_many_arguments)]
#[inline]
fn line_pf_affine(
    m: &[f64],
    w: &[f64],
    d: &[f64],
    z: &[f64],
    tolerances: &[f64],
    criterion: Criterion,
    dim: usize,
    k: usize,
) -> f64 {
    let offset = |c: usize| {
        m[c] + if dim > 0 {
            dot(&w[c * dim..(c + 1) * dim], z)
        } else {
            0.0
        }
    };
    let Some((lo, hi)) = criterion.safe_interval(tolerances, k, offset, d) else {
        return 1.0;
    };
    let left = if lo == f64::NEG_INFINITY {
        0.0
    } else {
        normal::cdf(lo)
    };
    let right = if hi == f64::INFINITY {
        0.0
    } else {
        normal::sf(hi)
    };
    left + right
}

/// The standard normal mass of `{t : f(t) ≤ 0}` for a general `f`: a scan with
/// step 0.5 over `[min(−8, β−8), max(8, β+8)]`, each sign change refined by
/// the Illinois method; beyond the ends the end signs are assumed to persist.
fn line_pf_scan(f: &mut impl FnMut(f64) -> f64, beta: f64) -> f64 {
    const STEP: f64 = 0.5;
    let t_min = (-8.0f64).min(beta - 8.0);
    let t_max = 8.0f64.max(beta + 8.0);
    let steps = ((t_max - t_min) / STEP).ceil() as usize;
    let mut t0 = t_min;
    let mut f0 = f(t0);
    let mut p = if f0 <= 0.0 { normal::cdf(t0) } else { 0.0 };
    for i in 1..=steps {
        let t1 = (t_min + i as f64 * STEP).min(t_max);
        let f1 = f(t1);
        let fail0 = f0 <= 0.0;
        let fail1 = f1 <= 0.0;
        if fail0 && fail1 {
            p += normal::interval(t0, t1);
        } else if fail0 != fail1 {
            let r = illinois(f, t0, f0, t1, f1);
            p += if fail0 {
                normal::interval(t0, r)
            } else {
                normal::interval(r, t1)
            };
        }
        t0 = t1;
        f0 = f1;
    }
    if f0 <= 0.0 {
        p += normal::sf(t_max);
    }
    p.min(1.0)
}

/// A root of `f` in `[a, b]` with `f(a)·f(b) < 0`: regula falsi with the
/// Illinois modification (the bracket is kept, so it cannot escape).
pub(crate) fn illinois(
    f: &mut impl FnMut(f64) -> f64,
    mut a: f64,
    mut fa: f64,
    mut b: f64,
    mut fb: f64,
) -> f64 {
    let mut side = 0;
    for _ in 0..100 {
        let c = (a * fb - b * fa) / (fb - fa);
        let c = if c.is_finite() && c > a.min(b) && c < a.max(b) {
            c
        } else {
            0.5 * (a + b)
        };
        if (b - a).abs() <= 1e-12 * (1.0 + c.abs()) {
            return c;
        }
        let fc = f(c);
        if fc == 0.0 {
            return c;
        }
        if (fc > 0.0) == (fb > 0.0) {
            b = c;
            fb = fc;
            if side == -1 {
                fa *= 0.5;
            }
            side = -1;
        } else {
            a = c;
            fa = fc;
            if side == 1 {
                fb *= 0.5;
            }
            side = 1;
        }
    }
    0.5 * (a + b)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::inputs::Marginal;
    use crate::limit_state::ToleranceLimitState;

    #[test]
    fn scan_finds_both_sides() {
        // Safe on [-1, 2]: mass outside = Φ(−1) + Φ(−2).
        let mut f = |t: f64| (t + 1.0) * (2.0 - t);
        let p = line_pf_scan(&mut f, 2.0);
        assert!((p - (normal::sf(1.0) + normal::sf(2.0))).abs() < 1e-12);
    }

    #[test]
    fn two_sided_affine_is_exact() {
        let inputs = crate::util::fixtures::inputs(vec![
            Marginal::normal(0.001, 0.01).unwrap(),
            Marginal::normal(0.0, 0.02).unwrap(),
            Marginal::normal(0.0, 0.005).unwrap(),
        ]);
        let ls = ToleranceLimitState::component(vec![1.0, -1.0, 2.0], 0.05, Sided::Two).unwrap();
        let event = Event::new(&inputs, ls).unwrap();
        let exact = event.exact_pf().unwrap();
        let is = ImportanceSampling {
            samples: 1000,
            seed: 3,
            form: Form::default(),
            cov: None,
        }
        .run(&event)
        .unwrap();
        assert!((is.pf - exact).abs() < 1e-15, "{} vs {exact}", is.pf);
        assert!(is.std_error < 1e-15);
        // FORM alone misses the far side.
        assert!(is.form.unwrap().pf < 0.9 * exact);
    }

    #[test]
    fn uniform_inputs_agree_with_monte_carlo() {
        let inputs = crate::util::fixtures::inputs(vec![
            Marginal::uniform(-1.0, 1.0).unwrap(),
            Marginal::normal(0.0, 0.5).unwrap(),
        ]);
        let ls = ToleranceLimitState::component(vec![1.0, 1.0], 1.4, Sided::Two).unwrap();
        let event = Event::new(&inputs, ls).unwrap();
        let is = ImportanceSampling {
            samples: 20_000,
            seed: 1,
            form: Form::default(),
            cov: None,
        }
        .run(&event)
        .unwrap();
        let mc = MonteCarlo {
            samples: 400_000,
            seed: 1,
            cov: None,
        }
        .run(&event)
        .unwrap();
        let se = (is.std_error.powi(2) + mc.std_error.powi(2)).sqrt();
        assert!((is.pf - mc.pf).abs() < 4.0 * se, "{is:?} {mc:?}");
        assert!(is.std_error < mc.std_error);
    }

    #[cfg(feature = "parallel")]
    #[test]
    fn thread_count_does_not_change_results() {
        let inputs = crate::util::fixtures::inputs(vec![
            Marginal::normal(0.0, 1.0).unwrap(),
            Marginal::normal(0.0, 1.0).unwrap(),
        ]);
        let ls = ToleranceLimitState::new(2, vec![1.0, 0.2, -0.3, 1.0], vec![2.5], Criterion::Norm)
            .unwrap();
        let event = Event::new(&inputs, ls).unwrap();
        let run = |threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| {
                    let mc = MonteCarlo {
                        samples: 3 * BLOCK + 17,
                        seed: 11,
                        cov: None,
                    }
                    .run(&event)
                    .unwrap();
                    let is = ImportanceSampling {
                        samples: 2 * BLOCK + 5,
                        seed: 11,
                        form: Form::default(),
                        cov: None,
                    }
                    .run(&event)
                    .unwrap();
                    (mc.pf, is.pf, is.std_error)
                })
        };
        assert_eq!(run(1), run(2));
    }
}
