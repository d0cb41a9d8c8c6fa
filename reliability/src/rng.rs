//! Reproducible random streams for the samplers.
//!
//! Every block of samples of every case draws from its own xoshiro256++
//! stream (Blackman & Vigna 2021; `rand::rngs::Xoshiro256PlusPlus`, which
//! `rand` documents as portable): the stream of `(seed, case, block)` is
//! seeded through SplitMix64 from the key
//! `seed ⊕ mix(case << 32 | block) ⊕ mix(sub)`, `mix` SplitMix64's output
//! bijection, so for one seed and one sub-stream every stream has its own
//! key. Work that splits one block over threads (subset simulation's Markov
//! chains) takes sub-streams `sub ≥ 1`; everything else draws from `sub = 0`. Which thread
//! runs a block therefore never changes what it draws, so results are
//! bit-identical for a given seed whatever the number of threads.
//!
//! The streams are xoshiro256++ rather than ChaCha8 (with the 64-bit stream
//! identifier `case << 32 | block`): ChaCha8 takes about 28 instructions per
//! 64-bit word against about 10 for xoshiro256++, and drawing is the larger
//! part of a subset-simulation step (docs/performance.md, "Subset
//! simulation"). The statistical tests (Monte Carlo, importance sampling,
//! subset and directional simulation against exact answers within their
//! standard errors) hold on these streams.
//!
//! [`CaseRng`] is itself a [`rand::Rng`], so any `rand`/`rand_distr`
//! distribution samples from it; uniforms are `rand`'s [`StandardUniform`]
//! (53 random bits on `[0, 1)`) and [`OpenClosed01`].
//!
//! Standard normal variates are the one hand-written kernel kept: a
//! 256-layer ziggurat (Marsaglia & Tsang 2000) that takes 32 random bits per
//! variate on its fast path (two variates per 64-bit word); the rare wedge
//! and tail steps use fresh 53-bit uniforms. `benches/kernels.rs` measures it
//! against `rand_distr`'s `StandardNormal` (a ziggurat that takes a whole
//! 64-bit word per variate) on one ChaCha8 stream, in one run:
//! 1024 variates in 5.3 µs (193 M/s) against 11.3 µs (91 M/s), 2.1× — above
//! the 1.3× bar, so the kernel stays (Monte Carlo draws 21 normals per
//! sample). A 64-word buffer in front of ChaCha8 is not worth keeping: it is
//! only 1.14× faster than `rand_chacha`'s own block buffer (1024 words in
//! 4.8 µs against 5.4 µs). Figures: `docs/performance.md`.

use std::convert::Infallible;
use std::sync::OnceLock;

use rand::distr::{OpenClosed01, StandardUniform};
use rand::rngs::Xoshiro256PlusPlus;
use rand::{Rng, RngExt, SeedableRng, TryRng};

/// The random stream of one block of one case, with fast standard-normal
/// variates.
///
/// ```
/// use rand::RngExt;
/// use reliability::rng::CaseRng;
/// let mut a = CaseRng::new(42, 7, 0);
/// let mut b = CaseRng::new(42, 7, 0);
/// let (mut x, mut y) = ([0.0; 5], [0.0; 5]);
/// a.fill_normal(&mut x);
/// b.fill_normal(&mut y);
/// assert_eq!(x, y);
/// // Any `rand` distribution draws from it.
/// let u: f64 = a.random();
/// assert!((0.0..1.0).contains(&u));
/// ```
#[derive(Debug, Clone)]
pub struct CaseRng {
    inner: Xoshiro256PlusPlus,
    tables: &'static Ziggurat,
}

impl CaseRng {
    /// The stream of block `block` of case `case` for the user's `seed`.
    pub fn new(seed: u64, case: u32, block: u32) -> CaseRng {
        CaseRng::substream(seed, case, block, 0)
    }

    /// Sub-stream `sub` of block `block` of case `case` (`sub = 0` is
    /// [`CaseRng::new`]'s stream): the samplers that split one block's work
    /// over threads (subset simulation's Markov chains) give each piece its
    /// own sub-stream, so what a piece draws never depends on the thread
    /// that runs it.
    pub fn substream(seed: u64, case: u32, block: u32, sub: u32) -> CaseRng {
        let key = stream_key(seed, case, block) ^ mix(u64::from(sub));
        CaseRng {
            inner: Xoshiro256PlusPlus::seed_from_u64(key),
            tables: ziggurat(),
        }
    }

    /// A uniform variate on `[0, 1)` with 53 random bits (`rand`'s
    /// [`StandardUniform`]).
    #[inline(always)]
    pub fn uniform(&mut self) -> f64 {
        self.sample(StandardUniform)
    }

    /// One standard normal variate.
    #[inline]
    pub fn normal(&mut self) -> f64 {
        let w = self.next_u64();
        self.normal_from_bits(w as u32)
    }

    /// Fills `out` with independent standard normal variates, two per 64-bit
    /// word on the ziggurat's fast path. For odd lengths the last word's upper
    /// half is discarded, so the stream consumed per call depends only on
    /// `out.len()` and the draws.
    #[inline]
    pub fn fill_normal(&mut self, out: &mut [f64]) {
        let mut pairs = out.chunks_exact_mut(2);
        for pair in &mut pairs {
            let w = self.next_u64();
            pair[0] = self.normal_from_bits(w as u32);
            pair[1] = self.normal_from_bits((w >> 32) as u32);
        }
        if let [last] = pairs.into_remainder() {
            let w = self.next_u64();
            *last = self.normal_from_bits(w as u32);
        }
    }

    /// The ziggurat step on 32 bits: 8 for the layer, 1 for the sign, 23 for
    /// the abscissa.
    #[inline(always)]
    fn normal_from_bits(&mut self, bits: u32) -> f64 {
        let t = self.tables;
        let layer = (bits & 0xff) as usize;
        let m = bits >> 9;
        if m < t.k[layer] {
            let x = (f64::from(m) + 0.5) * t.w[layer];
            // Branch-free sign: bit 8 of `bits` becomes the sign bit (a
            // data-dependent branch here would be mispredicted half the time).
            let sign = u64::from(bits & 0x100) << 55;
            return f64::from_bits(x.to_bits() ^ sign);
        }
        self.normal_slow(layer, bits & 0x100 != 0, m)
    }

    #[cold]
    #[inline(never)]
    fn normal_slow(&mut self, mut layer: usize, mut negative: bool, mut m: u32) -> f64 {
        let t = self.tables;
        loop {
            let x = (f64::from(m) + 0.5) * t.w[layer];
            if x < t.x[layer + 1] {
                return if negative { -x } else { x };
            }
            if layer == 0 {
                // Tail beyond r (Marsaglia 1964).
                let r = t.x[1];
                let x = loop {
                    let a = -self.sample::<f64, _>(OpenClosed01).ln() / r;
                    let b = -self.sample::<f64, _>(OpenClosed01).ln();
                    if 2.0 * b >= a * a {
                        break r + a;
                    }
                };
                return if negative { -x } else { x };
            }
            // Wedge between layers: accept under the density.
            let f_hi = t.f[layer + 1];
            let f_lo = t.f[layer];
            if f_lo + self.uniform() * (f_hi - f_lo) < (-0.5 * x * x).exp() {
                return if negative { -x } else { x };
            }
            let bits = self.next_u64() as u32;
            layer = (bits & 0xff) as usize;
            negative = bits & 0x100 != 0;
            m = bits >> 9;
            if m < t.k[layer] {
                let x = (f64::from(m) + 0.5) * t.w[layer];
                return if negative { -x } else { x };
            }
        }
    }
}

/// SplitMix64's output function of `z + φ` (Steele, Lea & Flood 2014): a
/// bijection of `u64` that is 0 at no small argument.
fn mix(z: u64) -> u64 {
    let mut z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The 64-bit key of stream `(case, block)` of `seed`: `seed` XOR
/// [`mix`]`(case << 32 | block)`, so for one seed distinct streams have
/// distinct keys (`mix` is a bijection); the key seeds xoshiro256++ through
/// SplitMix64 (`SeedableRng::seed_from_u64`).
fn stream_key(seed: u64, case: u32, block: u32) -> u64 {
    seed ^ mix((u64::from(case) << 32) | u64::from(block))
}

/// The raw stream: `CaseRng` is a [`rand::Rng`] (an infallible [`TryRng`]).
impl TryRng for CaseRng {
    type Error = Infallible;

    #[inline(always)]
    fn try_next_u32(&mut self) -> Result<u32, Infallible> {
        Ok(self.inner.next_u32())
    }

    #[inline(always)]
    fn try_next_u64(&mut self) -> Result<u64, Infallible> {
        Ok(self.inner.next_u64())
    }

    #[inline]
    fn try_fill_bytes(&mut self, dst: &mut [u8]) -> Result<(), Infallible> {
        self.inner.fill_bytes(dst);
        Ok(())
    }
}

/// Ziggurat tables: layer right edges `x[i]` (`x[0] = v/f(r)`, `x[1] = r`,
/// `x[256] = 0`), densities `f[i] = exp(−x[i]²/2)`, the abscissa scale
/// `w[i] = x[i]/2²³` and the fast-accept thresholds `k[i] = ⌊2²³·x[i+1]/x[i]⌋`.
#[derive(Debug)]
struct Ziggurat {
    x: [f64; 257],
    f: [f64; 257],
    w: [f64; 256],
    k: [u32; 256],
}

fn ziggurat() -> &'static Ziggurat {
    static TABLES: OnceLock<Ziggurat> = OnceLock::new();
    TABLES.get_or_init(|| {
        // Marsaglia & Tsang (2000), 256 layers of area v.
        const R: f64 = 3.654_152_885_361_009;
        const V: f64 = 4.928_673_233_99e-3;
        let f = |x: f64| (-0.5 * x * x).exp();
        let mut x = [0.0; 257];
        x[0] = V / f(R);
        x[1] = R;
        for i in 2..256 {
            x[i] = (-2.0 * (V / x[i - 1] + f(x[i - 1])).ln()).sqrt();
        }
        x[256] = 0.0;
        let mut fx = [0.0; 257];
        for i in 0..257 {
            fx[i] = f(x[i]);
        }
        // The base layer's pseudo-density is f(r) (its tail is handled apart).
        fx[0] = f(R);
        let scale = (1u64 << 23) as f64;
        let mut w = [0.0; 256];
        let mut k = [0u32; 256];
        for i in 0..256 {
            w[i] = x[i] / scale;
            // m < k[i] ⇔ (m + 0.5)·w[i] < x[i+1] for every integer m.
            k[i] = (x[i + 1] / x[i] * scale - 0.5).floor().max(0.0) as u32;
        }
        Ziggurat { x, f: fx, w, k }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::normal;

    #[test]
    fn tables_close_at_the_top() {
        let t = ziggurat();
        // The recursion ends at the mode: f(x[255]) + v/x[255] ≈ 1.
        let v = 4.928_673_233_99e-3;
        assert!((t.f[255] + v / t.x[255] - 1.0).abs() < 1e-6);
        for i in 0..256 {
            assert!(t.x[i + 1] < t.x[i]);
        }
    }

    #[test]
    fn moments_and_tails() {
        let mut rng = CaseRng::new(1, 0, 0);
        let n = 2_000_000;
        let mut buf = [0.0; 10];
        let (mut s1, mut s2, mut s4) = (0.0, 0.0, 0.0);
        let mut tail2 = 0u64;
        let mut tail3 = 0u64;
        for _ in 0..n / 10 {
            rng.fill_normal(&mut buf);
            for &z in &buf {
                s1 += z;
                s2 += z * z;
                s4 += z * z * z * z;
                if z.abs() > 2.0 {
                    tail2 += 1;
                }
                if z < -3.7 {
                    tail3 += 1;
                }
            }
        }
        let nf = n as f64;
        assert!((s1 / nf).abs() < 5.0 * (1.0 / nf).sqrt());
        assert!((s2 / nf - 1.0).abs() < 5.0 * (2.0 / nf).sqrt());
        assert!((s4 / nf - 3.0).abs() < 5.0 * (96.0 / nf).sqrt());
        let p2 = 2.0 * normal::sf(2.0);
        let e2 = tail2 as f64 / nf;
        assert!((e2 - p2).abs() < 5.0 * (p2 * (1.0 - p2) / nf).sqrt());
        // Beyond r = 3.654: exercises the tail algorithm.
        let p3 = normal::sf(3.7);
        let e3 = tail3 as f64 / nf;
        assert!((e3 - p3).abs() < 5.0 * (p3 / nf).sqrt(), "{e3} vs {p3}");
    }

    #[test]
    fn kolmogorov_smirnov() {
        let mut rng = CaseRng::new(2, 3, 1);
        let mut z: Vec<f64> = (0..1_000_000).map(|_| rng.normal()).collect();
        z.sort_by(f64::total_cmp);
        let n = z.len() as f64;
        let d = z
            .iter()
            .enumerate()
            .map(|(i, &x)| {
                let c = normal::cdf(x);
                (c - i as f64 / n).abs().max(((i + 1) as f64 / n - c).abs())
            })
            .fold(0.0, f64::max);
        // 1 % critical value 1.63/√n.
        assert!(d < 1.63 / n.sqrt(), "KS distance {d}");
    }

    #[test]
    fn the_stream_is_xoshiro256pp_keyed_by_seed_case_block_and_sub() {
        let mut a = CaseRng::new(9, 3, 5);
        let key = 9 ^ mix((3 << 32) | 5) ^ mix(0);
        let mut b = Xoshiro256PlusPlus::seed_from_u64(key);
        for _ in 0..100 {
            assert_eq!(a.next_u64(), b.next_u64());
        }
        let u = a.uniform();
        assert_eq!(u, (b.next_u64() >> 11) as f64 / (1u64 << 53) as f64);
        // Sub-stream 0 is the block's stream; others start elsewhere.
        let mut c = CaseRng::substream(9, 3, 5, 0);
        let mut d = CaseRng::new(9, 3, 5);
        assert_eq!(c.next_u64(), d.next_u64());
        let firsts: std::collections::HashSet<u64> = (0..1000)
            .flat_map(|sub| {
                (0..4).map(move |block| CaseRng::substream(9, 3, block, sub).next_u64())
            })
            .collect();
        assert_eq!(firsts.len(), 4000);
        // The keys of one seed are distinct: `mix` is a bijection (a
        // known value of SplitMix64's output at 0, Vigna's splitmix64.c).
        assert_eq!(mix(0), 0xe220_a839_7b1d_cdaf);
    }

    #[test]
    fn neighbouring_substreams_are_uncorrelated() {
        // The correlation of paired uniforms of sub-streams k and k + 1
        // over 10⁵ pairs: |r| < 4/√n (a 4-sigma bound).
        let n = 100_000;
        let mut worst = 0.0f64;
        for sub in 0..4 {
            let mut a = CaseRng::substream(1, 0, 0, sub);
            let mut b = CaseRng::substream(1, 0, 0, sub + 1);
            let (mut sab, mut sa, mut sb, mut saa, mut sbb) = (0.0, 0.0, 0.0, 0.0, 0.0);
            for _ in 0..n {
                let (x, y) = (a.uniform(), b.uniform());
                sab += x * y;
                sa += x;
                sb += y;
                saa += x * x;
                sbb += y * y;
            }
            let nf = n as f64;
            let cov = sab / nf - sa / nf * sb / nf;
            let r = cov / ((saa / nf - (sa / nf).powi(2)) * (sbb / nf - (sb / nf).powi(2))).sqrt();
            worst = worst.max(r.abs());
        }
        assert!(worst < 4.0 / (n as f64).sqrt(), "correlation {worst}");
    }

    #[test]
    fn streams_differ() {
        let mut a = CaseRng::new(5, 0, 0);
        let mut b = CaseRng::new(5, 0, 1);
        let mut c = CaseRng::new(5, 1, 0);
        let (x, y, z) = (a.next_u64(), b.next_u64(), c.next_u64());
        assert!(x != y && y != z && x != z);
    }
}
