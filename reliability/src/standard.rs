//! The limit state seen in standard normal space, `G(u) = g(T(u))`, on the
//! coordinates it depends on: what subset and directional simulation sample.
//!
//! The inputs `g` does not depend on integrate out exactly (their standard
//! coordinates sit at 0 and are never drawn), so the samplers work in the
//! dimension of the active coordinates only ([`crate::Inputs::standard_dependence`]
//! keeps the correlated block right). For a tolerance limit state in normal
//! inputs ([`Event::affine`]) `G` is evaluated on the components
//! `E_c = m_c + a_c·u` directly, without the `x = T(u)` pass; otherwise
//! through [`crate::Inputs::to_physical`] and [`LimitState::value`], so every
//! marginal the inputs know (and every user limit state) is handled.

use crate::limit_state::{Criterion, Event, LimitState};
use crate::util::dot;
use chain_core::model::Sided;

/// The affine view restricted to the active coordinates.
#[derive(Debug, Clone)]
pub(crate) struct AffineU {
    /// Components `k`.
    pub(crate) k: usize,
    /// `m_c`.
    pub(crate) m: Vec<f64>,
    /// `a_c` on the active coordinates, `k × na` row-major.
    pub(crate) a: Vec<f64>,
    /// Tolerances.
    pub(crate) tolerances: Vec<f64>,
    /// Criterion.
    pub(crate) criterion: Criterion,
    /// One component under a per-component criterion (the common case of
    /// one tolerance): `(m, tolerance, two-sided)`, evaluated without the
    /// general loop over components.
    pub(crate) single: Option<(f64, f64, bool)>,
}

/// `G(u) = g(T(u))` on the active standard coordinates.
pub(crate) struct Standard<'e, 'a, L: LimitState> {
    event: &'e Event<'a, L>,
    /// The active standard coordinates (indices into the inputs).
    pub(crate) active: Vec<usize>,
    /// The affine form, when the event has one.
    pub(crate) affine: Option<AffineU>,
}

/// Scratch buffers of the general path (`u` and `x` over all inputs).
#[derive(Debug, Clone)]
pub(crate) struct Scratch {
    u: Vec<f64>,
    x: Vec<f64>,
}

impl<'e, 'a, L: LimitState> Standard<'e, 'a, L> {
    pub(crate) fn new(event: &'e Event<'a, L>) -> Self {
        let n = event.inputs.len();
        let depends: Vec<bool> = (0..n).map(|j| event.limit_state.depends_on(j)).collect();
        let depends = event.inputs.standard_dependence(&depends);
        let active: Vec<usize> = (0..n).filter(|&j| depends[j]).collect();
        let affine = event.affine().map(|aff| {
            let k = aff.view.components();
            let mut a = Vec::with_capacity(k * active.len());
            for c in 0..k {
                a.extend(active.iter().map(|&j| aff.row(c)[j]));
            }
            let tolerances = aff.view.tolerances().to_vec();
            let criterion = aff.view.criterion();
            let single = match criterion {
                Criterion::Each(sided) if k == 1 => {
                    Some((aff.mean[0], tolerances[0], sided == Sided::Two))
                }
                _ => None,
            };
            AffineU {
                k,
                m: aff.mean.clone(),
                a,
                tolerances,
                criterion,
                single,
            }
        });
        Standard {
            event,
            active,
            affine,
        }
    }

    /// The number of active coordinates.
    pub(crate) fn dim(&self) -> usize {
        self.active.len()
    }

    /// Fresh scratch for [`Standard::value`].
    pub(crate) fn scratch(&self) -> Scratch {
        let n = self.event.inputs.len();
        Scratch {
            u: vec![0.0; n],
            x: vec![0.0; n],
        }
    }

    /// `G(u)` at the active coordinates `u` (the others at 0).
    #[inline(always)]
    pub(crate) fn value(&self, u: &[f64], s: &mut Scratch) -> f64 {
        if let Some(AffineU {
            single: Some((m, t, two)),
            a,
            ..
        }) = &self.affine
        {
            // The same operations, in the same order, as the general loop
            // of `value_general` with k = 1 (so the values are bit-identical).
            let e = m + dot(a, u);
            let margin = if *two { t - e.abs() } else { t - e };
            return f64::INFINITY.min(margin);
        }
        self.value_general(u, s)
    }

    /// [`Standard::value`] outside the one-component fast path.
    #[inline(never)]
    fn value_general(&self, u: &[f64], s: &mut Scratch) -> f64 {
        if let Some(aff) = &self.affine {
            let na = self.active.len();
            let e = |c: usize| aff.m[c] + dot(&aff.a[c * na..(c + 1) * na], u);
            return match aff.criterion {
                Criterion::Each(Sided::Upper) => (0..aff.k)
                    .map(|c| aff.tolerances[c] - e(c))
                    .fold(f64::INFINITY, f64::min),
                Criterion::Each(Sided::Two) => (0..aff.k)
                    .map(|c| aff.tolerances[c] - e(c).abs())
                    .fold(f64::INFINITY, f64::min),
                Criterion::Norm => {
                    let n2: f64 = (0..aff.k).map(|c| e(c).powi(2)).sum();
                    aff.tolerances[0] - n2.sqrt()
                }
            };
        }
        for (&j, &v) in self.active.iter().zip(u) {
            s.u[j] = v;
        }
        self.event.inputs.to_physical(&s.u, &mut s.x);
        self.event.limit_state.value(&s.x)
    }
}
