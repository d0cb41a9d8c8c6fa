//! Directional simulation (Bjerager 1988; Ditlevsen & Madsen 1996,
//! *Structural Reliability Methods*, ch. 9).
//!
//! In standard normal space `u = R·A` with `A` uniform on the unit sphere of
//! the `n` active coordinates and `R² ~ χ²_n` independent of `A`
//! (Bjerager 1988, Eq. 3-5), so
//!
//! `p_f = E_A[ P(R·A ∈ F | A) ]`, and for one direction `a`
//! `P(R·a ∈ F) = ∫_{r ≥ 0 : G(r·a) ≤ 0} f_R(r) dr`,
//!
//! a sum of `χ²_n` masses over the failing intervals of the ray. With a
//! safe set that contains the origin and one root `r*` on the ray this is
//! the `χ²_n` tail `1 − χ²_n(r*²)` of Bjerager's Eq. 7. The estimate is the
//! mean over independent directions `a_i = z_i/|z_i|`, `z_i ~ N(0, I)`,
//! its standard error the sample standard deviation over `√N`.
//!
//! The roots: for a tolerance limit state in normal inputs every component
//! is affine along the ray, `E_c(r) = m_c + r·(a_c·a)`, so the safe set is an
//! interval found in closed form ([`crate::Criterion::safe_interval`]: half-spaces,
//! slabs, the chord of the volumetric ellipsoid). Otherwise (any other
//! marginal, a user's limit state) the ray is scanned with step 0.5 from
//! `r = 0` to `√n + 10` (beyond which the `χ²_n` mass is below `1e-22`),
//! every sign change refined by the Illinois method (a bracketed root find).
//!
//! The `χ²_n` tails are the regularised incomplete gamma functions
//! `Q(n/2, r²/2)` (statrs, relative-accurate in the tail), with the closed
//! forms `2Φ(−r)` for `n = 1` and `e^{−r²/2}` for `n = 2`.
//!
//! Directions are drawn in blocks of [`BLOCK`] (block `b` of case `c` on the
//! stream `c << 32 | b`), so results are bit-identical for a seed whatever
//! the thread count; with a target coefficient of variation the blocks are
//! added in order and the rule is checked after each one.

use statrs::function::gamma::{gamma_lr, gamma_ur};

use crate::error::ReliabilityError;
use crate::limit_state::{Event, LimitState};
use crate::method::Method;
use crate::normal;
use crate::rng::CaseRng;
use crate::sampler::{
    check_cov, check_samples, drive, finish, Progress, Sampler, SimulationResult, Stop, Stopping,
    Streams, Sums,
};
use crate::simulation::illinois;
use crate::standard::{Scratch, Standard};

/// Directions per block (the unit of parallel work, random streams and the
/// stopping rule's checks).
pub const BLOCK: u64 = 4096;

/// Directional simulation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DirectionalSimulation {
    /// Directions per case (with a target CoV: the largest number).
    pub samples: u64,
    /// The seed of the random streams.
    pub seed: u64,
    /// A target coefficient of variation of `p_f`: blocks are added until
    /// it is reached or `samples` are used.
    pub cov: Option<f64>,
}

/// `P(χ²_n ≥ r²)`.
pub fn chi2_sf(n: usize, r: f64) -> f64 {
    if r <= 0.0 {
        return 1.0;
    }
    if r == f64::INFINITY {
        return 0.0;
    }
    match n {
        1 => 2.0 * normal::sf(r),
        2 => (-0.5 * r * r).exp(),
        _ => gamma_ur(0.5 * n as f64, 0.5 * r * r),
    }
}

/// `P(χ²_n ≤ r²)`.
pub fn chi2_cdf(n: usize, r: f64) -> f64 {
    if r <= 0.0 {
        return 0.0;
    }
    if r == f64::INFINITY {
        return 1.0;
    }
    match n {
        1 => normal::interval(-r, r),
        2 => -(-0.5 * r * r).exp_m1(),
        _ => gamma_lr(0.5 * n as f64, 0.5 * r * r),
    }
}

/// The `χ²_n` mass of `R ∈ [r0, r1]`, from the side that keeps its digits.
fn chi2_mass(n: usize, r0: f64, r1: f64) -> f64 {
    if r1 <= r0 {
        return 0.0;
    }
    if r0 * r0 > n as f64 {
        (chi2_sf(n, r0) - chi2_sf(n, r1)).max(0.0)
    } else {
        (chi2_cdf(n, r1) - chi2_cdf(n, r0)).max(0.0)
    }
}

impl Sampler for DirectionalSimulation {
    type Output = SimulationResult;

    fn method(&self) -> Method {
        Method::Directional
    }

    /// Case `i` draws from streams `streams.id(i) << 32 | block`.
    fn run_streams<L: LimitState>(
        &self,
        events: &[Event<'_, L>],
        streams: Streams<'_>,
        progress: &dyn Progress,
    ) -> Result<Vec<SimulationResult>, ReliabilityError> {
        check_samples(self.samples)?;
        if let Some(c) = self.cov {
            check_cov(c)?;
        }
        let stds: Vec<Standard<'_, '_, L>> = events.iter().map(Standard::new).collect();
        let block = |case: usize, block: u32, count: u64, _: &mut [f64]| {
            self.block(&stds[case], streams.id(case), block, count)
        };
        let runs = drive(
            events.len(),
            self.samples,
            BLOCK,
            0,
            progress,
            block,
            self.cov.map(|target| {
                let stds = &stds;
                (target, move |case: usize, s: &Sums, n: u64| {
                    let (pf, se) = estimate(s, n);
                    (pf > 0.0 && se <= target * pf) || (se == 0.0 && stds[case].dim() == 0)
                })
            }),
        );
        Ok(runs
            .into_iter()
            .map(|(sums, samples, stopping)| {
                let (pf, se) = estimate(&sums, samples);
                let mut r = finish(
                    Method::Directional,
                    pf.clamp(0.0, 1.0),
                    se,
                    samples,
                    sums.calls,
                    None,
                );
                r.stopping = Some(stopping.unwrap_or(Stopping::new(Stop::Samples, None)));
                r
            })
            .collect())
    }
}

impl DirectionalSimulation {
    fn block<L: LimitState>(
        &self,
        std: &Standard<'_, '_, L>,
        case_id: u32,
        block: u32,
        count: u64,
    ) -> Sums {
        let na = std.dim();
        let mut scratch = std.scratch();
        if na == 0 {
            let p = if std.value(&[], &mut scratch) <= 0.0 {
                1.0
            } else {
                0.0
            };
            return Sums {
                s1: p * count as f64,
                s2: p * p * count as f64,
                calls: 1,
            };
        }
        let mut rng = CaseRng::new(self.seed, case_id, block);
        let mut a = vec![0.0; na];
        let mut ray = vec![0.0; na];
        let mut d = vec![0.0; std.affine.as_ref().map_or(0, |f| f.k)];
        let mut s = Sums::default();
        for _ in 0..count {
            // A uniform direction: a normal vector normalised (zero has
            // probability zero; redraw if it occurs).
            let norm = loop {
                rng.fill_normal(&mut a);
                let n2: f64 = a.iter().map(|v| v * v).sum();
                if n2 > 0.0 {
                    break n2.sqrt();
                }
            };
            a.iter_mut().for_each(|v| *v /= norm);
            let p = match &std.affine {
                Some(aff) => {
                    for (c, dc) in d.iter_mut().enumerate() {
                        *dc = crate::util::dot(&aff.a[c * na..(c + 1) * na], &a);
                    }
                    s.calls += 1;
                    ray_pf_affine(aff, &d, na)
                }
                None => ray_pf_scan(std, &a, &mut ray, &mut scratch, &mut s.calls),
            };
            s.s1 += p;
            s.s2 += p * p;
        }
        s
    }
}

/// The failing `χ²` mass of the ray `E_c(r) = m_c + r·d_c`, `r ≥ 0`.
fn ray_pf_affine(aff: &crate::standard::AffineU, d: &[f64], na: usize) -> f64 {
    let Some((lo, hi)) = aff
        .criterion
        .safe_interval(&aff.tolerances, aff.k, |c| aff.m[c], d)
    else {
        return 1.0;
    };
    if hi <= 0.0 {
        // The whole ray fails.
        return 1.0;
    }
    let far = chi2_sf(na, hi);
    if lo > 0.0 {
        // The origin fails: [0, lo) fails too.
        chi2_cdf(na, lo) + far
    } else {
        far
    }
}

/// The failing `χ²` mass of the ray `r·a` for a general `G`: a scan and
/// Illinois refinement.
fn ray_pf_scan<L: LimitState>(
    std: &Standard<'_, '_, L>,
    a: &[f64],
    ray: &mut [f64],
    scratch: &mut Scratch,
    calls: &mut u64,
) -> f64 {
    const STEP: f64 = 0.5;
    let n = a.len();
    let r_max = (n as f64).sqrt() + 10.0;
    let mut f = |r: f64| {
        for (x, &ai) in ray.iter_mut().zip(a) {
            *x = r * ai;
        }
        *calls += 1;
        std.value(ray, scratch)
    };
    let steps = (r_max / STEP).ceil() as usize;
    let mut r0 = 0.0;
    let mut f0 = f(0.0);
    let mut p = 0.0;
    for i in 1..=steps {
        let r1 = (i as f64 * STEP).min(r_max);
        let f1 = f(r1);
        let (fail0, fail1) = (f0 <= 0.0, f1 <= 0.0);
        if fail0 && fail1 {
            p += chi2_mass(n, r0, r1);
        } else if fail0 != fail1 {
            let root = illinois(&mut f, r0, f0, r1, f1);
            p += if fail0 {
                chi2_mass(n, r0, root)
            } else {
                chi2_mass(n, root, r1)
            };
        }
        r0 = r1;
        f0 = f1;
    }
    if f0 <= 0.0 {
        p += chi2_sf(n, r_max);
    }
    p.min(1.0)
}

/// The mean of `count` values and its standard error `√(s²/N)`.
fn estimate(s: &Sums, count: u64) -> (f64, f64) {
    let n = count as f64;
    if count == 0 {
        return (0.0, 0.0);
    }
    let mean = s.s1 / n;
    let var = if count > 1 {
        ((s.s2 - s.s1 * mean) / (n - 1.0)).max(0.0)
    } else {
        0.0
    };
    (mean, (var / n).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chi2_tails_match_closed_forms() {
        // n = 3: Q(3/2, r²/2) = 2Φ(−r) + √(2/π)·r·e^{−r²/2};
        // n = 5: … + √(2/π)·r³/3·e^{−r²/2} (Abramowitz & Stegun 26.4.5).
        let c = (2.0 / std::f64::consts::PI).sqrt();
        for r in [0.3f64, 1.0, 2.5, 5.0, 7.5, 9.0] {
            let e = (-0.5 * r * r).exp();
            let q3 = 2.0 * normal::sf(r) + c * r * e;
            let q5 = q3 + c * r * r * r / 3.0 * e;
            assert!((chi2_sf(3, r) - q3).abs() <= 1e-13 * q3, "r {r}");
            assert!((chi2_sf(5, r) - q5).abs() <= 1e-13 * q5, "r {r}");
            assert!((chi2_cdf(3, r) + chi2_sf(3, r) - 1.0).abs() < 1e-14);
        }
        assert!((chi2_sf(1, 5.199) - 2.0 * normal::sf(5.199)).abs() < 1e-22);
    }
}
