//! Limit states and events.
//!
//! A limit state `g(x)` separates the safe set `g > 0` from the failure set
//! `g ≤ 0` (the paper's Eq. 19 and 30: `Z = I − ΔE_T`). An [`Event`] is a
//! limit state together with its random [`Inputs`] (the OpenTURNS shape:
//! event = limit state + inputs + threshold, the threshold being the
//! tolerance inside the limit state). FORM, the importance sampling and Monte
//! Carlo are generic over [`LimitState`], the small problem trait that a user
//! implements for a limit state of their own.
//!
//! The machine-tool limit states are [`ToleranceLimitState`]s: functions of a
//! few error components `E_c = Σ_j S_cj·e_j`, linear in the errors because the
//! derived model is first order (`S` = the model's sensitivity at one point).

use chain_core::model::Sided;
use serde::Serialize;

use crate::error::ReliabilityError;
use crate::inputs::Inputs;

/// A limit state `g(x) = min_b g_b(x)` over the physical inputs `x`: failure
/// is `g ≤ 0`. Each branch `g_b` is smooth; a smooth limit state has one.
///
/// ```
/// use reliability::LimitState;
/// /// g = 3 − x₀ − x₁²
/// struct Parabola;
/// impl LimitState for Parabola {
///     fn dim(&self) -> usize { 2 }
///     fn branch(&self, _b: usize, x: &[f64], gradient: Option<&mut [f64]>) -> f64 {
///         if let Some(g) = gradient { g[0] = -1.0; g[1] = -2.0 * x[1]; }
///         3.0 - x[0] - x[1] * x[1]
///     }
/// }
/// assert_eq!(Parabola.value(&[1.0, 1.0]), 1.0);
/// ```
pub trait LimitState: Sync {
    /// Number of inputs `n`.
    fn dim(&self) -> usize;

    /// Number of smooth branches (1 unless `g` is a minimum of several).
    fn branches(&self) -> usize {
        1
    }

    /// `g_b(x)`, writing `∇_x g_b(x)` into `gradient` when given.
    fn branch(&self, b: usize, x: &[f64], gradient: Option<&mut [f64]>) -> f64;

    /// `g(x) = min_b g_b(x)`.
    fn value(&self, x: &[f64]) -> f64 {
        (0..self.branches())
            .map(|b| self.branch(b, x, None))
            .fold(f64::INFINITY, f64::min)
    }

    /// Whether `g` depends on input `j` at all. Samplers drop the inputs it
    /// does not depend on (they integrate out exactly).
    fn depends_on(&self, _j: usize) -> bool {
        true
    }

    /// The affine view `g = G(S·x)`, when the limit state has it: rows `S`
    /// of error components linear in `x`, judged by a [`Criterion`] against
    /// tolerances. It lets FORM use its closed form (Eq. 21-22), Monte Carlo
    /// evaluate the components on the normal draws and the importance
    /// sampling solve `g = 0` along a line exactly. A user's limit state
    /// that is affine offers one with [`AffineView::new`]; it must agree
    /// with [`LimitState::branch`] (same branches, same values).
    fn affine(&self) -> Option<AffineView<'_>> {
        None
    }
}

impl Criterion {
    /// The number of smooth branches over `k` components: `k` (upper),
    /// `2k` (two-sided: `+E_c` and `−E_c`), 1 (norm).
    pub fn branches(self, k: usize) -> usize {
        match self {
            Criterion::Each(Sided::Upper) => k,
            Criterion::Each(Sided::Two) => 2 * k,
            Criterion::Norm => 1,
        }
    }

    /// Branch `b` as a half-space `g_b = I_c − sign·E_c`: `(c, sign)`;
    /// `None` for the norm, which has no half-space branch.
    #[inline]
    pub fn half_space(self, b: usize) -> Option<(usize, f64)> {
        match self {
            Criterion::Each(Sided::Upper) => Some((b, 1.0)),
            Criterion::Each(Sided::Two) => Some((b / 2, if b % 2 == 0 { 1.0 } else { -1.0 })),
            Criterion::Norm => None,
        }
    }

    /// Whether the components `E_c = e(c)`, `c < k`, fail (`g ≤ 0`).
    #[inline]
    pub fn fails(self, tolerances: &[f64], k: usize, e: impl Fn(usize) -> f64) -> bool {
        match self {
            Criterion::Each(Sided::Upper) => (0..k).any(|c| e(c) >= tolerances[c]),
            Criterion::Each(Sided::Two) => (0..k).any(|c| e(c).abs() >= tolerances[c]),
            Criterion::Norm => {
                let t = tolerances[0];
                (0..k).map(|c| e(c).powi(2)).sum::<f64>() >= t * t
            }
        }
    }

    /// The safe set on the line `E_c(t) = b_c + t·d_c` (`b_c = offset(c)`,
    /// `c < k`): the interval `[lo, hi]` of `t` (possibly infinite ends), or
    /// `None` when the whole line fails. Half-spaces intersect to an
    /// interval; the norm's safe set is the chord of the ellipsoid
    /// `|b + t·d|² ≤ I²` (the stable roots of the quadratic).
    #[inline]
    pub fn safe_interval(
        self,
        tolerances: &[f64],
        k: usize,
        offset: impl Fn(usize) -> f64,
        d: &[f64],
    ) -> Option<(f64, f64)> {
        let mut lo = f64::NEG_INFINITY;
        let mut hi = f64::INFINITY;
        match self {
            Criterion::Each(sided) => {
                for c in 0..k {
                    let b = offset(c);
                    let dc = d[c];
                    let i = tolerances[c];
                    let (upper, lower) = match sided {
                        Sided::Upper => (i, f64::NEG_INFINITY),
                        Sided::Two => (i, -i),
                    };
                    // lower ≤ b + t·dc ≤ upper
                    if dc > 0.0 {
                        hi = hi.min((upper - b) / dc);
                        lo = lo.max((lower - b) / dc);
                    } else if dc < 0.0 {
                        hi = hi.min((lower - b) / dc);
                        lo = lo.max((upper - b) / dc);
                    } else if b > upper || b < lower {
                        return None;
                    }
                }
            }
            Criterion::Norm => {
                // |b + t·d|² ≤ I²  ⇔  A t² + 2B t + C ≤ 0.
                let (mut a2, mut b2, mut c2) = (0.0, 0.0, 0.0);
                for (c, &dc) in d.iter().enumerate().take(k) {
                    let b = offset(c);
                    a2 += dc * dc;
                    b2 += b * dc;
                    c2 += b * b;
                }
                let i = tolerances[0];
                c2 -= i * i;
                if a2 == 0.0 {
                    return if c2 > 0.0 { None } else { Some((lo, hi)) };
                }
                let disc = b2 * b2 - a2 * c2;
                if disc < 0.0 {
                    return None;
                }
                let r = disc.sqrt();
                // Stable roots: q = −(B + sign(B)·r), t = q/A and C/q.
                let q = -(b2 + if b2 >= 0.0 { r } else { -r });
                let (t1, t2) = if q != 0.0 {
                    (q / a2, c2 / q)
                } else {
                    (0.0, 0.0)
                };
                lo = t1.min(t2);
                hi = t1.max(t2);
            }
        }
        if lo >= hi {
            return None;
        }
        Some((lo, hi))
    }
}

/// The affine structure `g = G(S·x)` of a limit state: `k` rows `S_c` of
/// error components `E_c(x) = S_c·x`, their tolerances and the
/// [`Criterion`] that judges them (per-branch half-spaces for
/// [`Criterion::Each`], the norm for [`Criterion::Norm`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AffineView<'a> {
    n: usize,
    rows: &'a [f64],
    tolerances: &'a [f64],
    criterion: Criterion,
}

impl<'a> AffineView<'a> {
    /// A view over `rows` (`k × n`, row-major) and `tolerances` (`k` for
    /// [`Criterion::Each`], one for [`Criterion::Norm`]).
    pub fn new(
        n: usize,
        rows: &'a [f64],
        tolerances: &'a [f64],
        criterion: Criterion,
    ) -> Result<AffineView<'a>, ReliabilityError> {
        if n == 0 || rows.is_empty() || rows.len() % n != 0 {
            return Err(ReliabilityError::Dimension {
                what: "sensitivity rows (k × n)",
                expected: n.max(1),
                found: rows.len(),
            });
        }
        let expected = match criterion {
            Criterion::Each(_) => rows.len() / n,
            Criterion::Norm => 1,
        };
        if tolerances.len() != expected {
            return Err(ReliabilityError::Dimension {
                what: "tolerances",
                expected,
                found: tolerances.len(),
            });
        }
        Ok(AffineView {
            n,
            rows,
            tolerances,
            criterion,
        })
    }

    /// Number of inputs `n`.
    pub fn dim(&self) -> usize {
        self.n
    }

    /// Number of components `k`.
    pub fn components(&self) -> usize {
        self.rows.len() / self.n
    }

    /// Row `c` of `S`.
    #[inline]
    pub fn row(&self, c: usize) -> &'a [f64] {
        &self.rows[c * self.n..(c + 1) * self.n]
    }

    /// The tolerances.
    pub fn tolerances(&self) -> &'a [f64] {
        self.tolerances
    }

    /// The criterion.
    pub fn criterion(&self) -> Criterion {
        self.criterion
    }

    /// Branch `b` as a half-space `g_b = I_c − sign·S_c·x`:
    /// `(row S_c, offset I_c, sign)`; `None` for the norm.
    pub fn half_space(&self, b: usize) -> Option<(&'a [f64], f64, f64)> {
        let (c, sign) = self.criterion.half_space(b)?;
        Some((self.row(c), self.tolerances[c], sign))
    }

    /// True when the limit state is one half-space in `x` (one component,
    /// [`Sided::Upper`]): FORM is then exact for normal inputs.
    pub fn is_half_space(&self) -> bool {
        self.components() == 1 && self.criterion == Criterion::Each(Sided::Upper)
    }
}

/// How the components of a [`ToleranceLimitState`] are judged.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Criterion {
    /// Every component within its own tolerance (a series system; with one
    /// component, the paper's Eq. 30): `g = min_c (I_c − E_c)` for
    /// [`Sided::Upper`], `g = min_c (I_c − |E_c|)` for [`Sided::Two`].
    Each(Sided),
    /// The Euclidean norm of the components within one tolerance (the
    /// volumetric error): `g = I − √(Σ_c E_c²)`.
    Norm,
}

/// A limit state on error components that are linear in the inputs:
/// `E_c(x) = Σ_j S_cj·x_j`, judged by a [`Criterion`] against tolerances `I_c`.
///
/// ```
/// use reliability::{Criterion, LimitState, ToleranceLimitState};
/// use chain_core::model::Sided;
/// // Eq. 34, px at (y, z): one component, g = 0.03 − E.
/// let g = ToleranceLimitState::component(vec![-1.0, 600.0], 0.03, Sided::Upper).unwrap();
/// assert!((g.value(&[0.01, 1e-5]) - (0.03 - (-0.01 + 0.006))).abs() < 1e-15);
/// ```
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ToleranceLimitState {
    n: usize,
    rows: Vec<f64>,
    tolerances: Vec<f64>,
    criterion: Criterion,
    active: Vec<bool>,
}

impl ToleranceLimitState {
    /// A general tolerance limit state: `rows` is `k × n` row-major, one row
    /// of sensitivities per component; `tolerances` has `k` entries for
    /// [`Criterion::Each`] and one for [`Criterion::Norm`].
    pub fn new(
        n: usize,
        rows: Vec<f64>,
        tolerances: Vec<f64>,
        criterion: Criterion,
    ) -> Result<ToleranceLimitState, ReliabilityError> {
        // The dimensions are the affine view's.
        AffineView::new(n, &rows, &tolerances, criterion)?;
        for &t in &tolerances {
            if !t.is_finite() || t <= 0.0 {
                return Err(ReliabilityError::InvalidTolerance {
                    component: "limit state".into(),
                    value: t,
                });
            }
        }
        if rows.iter().any(|v| !v.is_finite()) {
            return Err(ReliabilityError::NonFinite("the sensitivity rows"));
        }
        let active = (0..n)
            .map(|j| rows.chunks_exact(n).any(|r| r[j] != 0.0))
            .collect();
        Ok(ToleranceLimitState {
            n,
            rows,
            tolerances,
            criterion,
            active,
        })
    }

    /// One component: `g = I − E` (upper, Eq. 30) or `g = I − |E|` (two-sided).
    pub fn component(
        row: Vec<f64>,
        tolerance: f64,
        sided: Sided,
    ) -> Result<ToleranceLimitState, ReliabilityError> {
        let n = row.len();
        ToleranceLimitState::new(n, row, vec![tolerance], Criterion::Each(sided))
    }

    /// Number of components `k`.
    pub fn components(&self) -> usize {
        self.rows.len() / self.n
    }

    /// Row `c` of the sensitivities.
    #[inline]
    pub fn row(&self, c: usize) -> &[f64] {
        &self.rows[c * self.n..(c + 1) * self.n]
    }

    /// The tolerances.
    pub fn tolerances(&self) -> &[f64] {
        &self.tolerances
    }

    /// The criterion.
    pub fn criterion(&self) -> Criterion {
        self.criterion
    }

    /// True when the limit state is one half-space in `x`
    /// (one component, [`Sided::Upper`]): FORM is then exact for normal inputs.
    pub fn is_half_space(&self) -> bool {
        self.view().is_half_space()
    }

    /// Its affine view (always there).
    pub fn view(&self) -> AffineView<'_> {
        AffineView {
            n: self.n,
            rows: &self.rows,
            tolerances: &self.tolerances,
            criterion: self.criterion,
        }
    }

    #[inline]
    fn dot(&self, c: usize, x: &[f64]) -> f64 {
        crate::util::dot(self.row(c), x)
    }
}

impl LimitState for ToleranceLimitState {
    fn dim(&self) -> usize {
        self.n
    }

    fn branches(&self) -> usize {
        self.criterion.branches(self.components())
    }

    fn branch(&self, b: usize, x: &[f64], gradient: Option<&mut [f64]>) -> f64 {
        match self.criterion.half_space(b) {
            Some((c, sign)) => {
                if let Some(g) = gradient {
                    for (g, s) in g.iter_mut().zip(self.row(c)) {
                        *g = -sign * s;
                    }
                }
                self.tolerances[c] - sign * self.dot(c, x)
            }
            None => {
                let k = self.components();
                let mut norm2 = 0.0;
                for c in 0..k {
                    let e = self.dot(c, x);
                    norm2 += e * e;
                }
                let norm = norm2.sqrt();
                if let Some(g) = gradient {
                    g.iter_mut().for_each(|v| *v = 0.0);
                    if norm > 0.0 {
                        for c in 0..k {
                            let w = self.dot(c, x) / norm;
                            for (g, s) in g.iter_mut().zip(self.row(c)) {
                                *g -= w * s;
                            }
                        }
                    }
                }
                self.tolerances[0] - norm
            }
        }
    }

    #[inline]
    fn value(&self, x: &[f64]) -> f64 {
        let k = self.components();
        if k == 1 {
            // The common case (one component): no iterator machinery.
            let e = crate::util::dot(&self.rows, x);
            return match self.criterion {
                Criterion::Each(Sided::Upper) => self.tolerances[0] - e,
                Criterion::Each(Sided::Two) | Criterion::Norm => self.tolerances[0] - e.abs(),
            };
        }
        match self.criterion {
            Criterion::Each(Sided::Upper) => (0..k)
                .map(|c| self.tolerances[c] - self.dot(c, x))
                .fold(f64::INFINITY, f64::min),
            Criterion::Each(Sided::Two) => (0..k)
                .map(|c| self.tolerances[c] - self.dot(c, x).abs())
                .fold(f64::INFINITY, f64::min),
            Criterion::Norm => {
                let norm2: f64 = (0..k).map(|c| self.dot(c, x).powi(2)).sum();
                self.tolerances[0] - norm2.sqrt()
            }
        }
    }

    fn depends_on(&self, j: usize) -> bool {
        self.active.get(j).copied().unwrap_or(false)
    }

    fn affine(&self) -> Option<AffineView<'_>> {
        Some(self.view())
    }
}

/// A limit state with its random inputs: what the algorithms run on.
#[derive(Debug, Clone)]
pub struct Event<'a, L: LimitState = ToleranceLimitState> {
    /// The limit state `g`.
    pub limit_state: L,
    /// The joint distribution of `x`.
    pub inputs: &'a Inputs,
}

impl<'a, L: LimitState> Event<'a, L> {
    /// An event, checking that the dimensions agree.
    pub fn new(inputs: &'a Inputs, limit_state: L) -> Result<Event<'a, L>, ReliabilityError> {
        if limit_state.dim() != inputs.len() {
            return Err(ReliabilityError::Dimension {
                what: "limit-state inputs",
                expected: inputs.len(),
                found: limit_state.dim(),
            });
        }
        Ok(Event {
            limit_state,
            inputs,
        })
    }

    /// The linear-normal view `E_c = m_c + a_c·u` of the event, when the
    /// limit state has the tolerance structure and every input is normal.
    pub fn affine(&self) -> Option<Affine<'_>> {
        let view = self.limit_state.affine()?;
        if !self.inputs.is_affine() {
            return None;
        }
        Some(Affine::new(view, self.inputs))
    }

    /// The exact failure probability when it has a closed form: one component
    /// in normal inputs, `Φ(−β)` for an upper tolerance (Eq. 21, 31) and
    /// `Φ(−β₊) + Φ(−β₋)` for a two-sided one.
    pub fn exact_pf(&self) -> Option<f64> {
        let a = self.affine()?;
        if a.view.components() != 1 {
            return None;
        }
        let s = a.std(0);
        let m = a.mean[0];
        let i = a.view.tolerances()[0];
        match a.view.criterion() {
            Criterion::Each(Sided::Upper) => Some(crate::normal::sf((i - m) / s)),
            Criterion::Each(Sided::Two) => {
                Some(crate::normal::sf((i - m) / s) + crate::normal::sf((i + m) / s))
            }
            Criterion::Norm => {
                Some(crate::normal::sf((i - m) / s) + crate::normal::sf((i + m) / s))
            }
        }
    }
}

/// An affine limit state over normal inputs, seen in standard space:
/// `E_c(u) = m_c + a_c·u` with `m_c = Σ_j S_cj·μ_j` and `a_cj = S_cj·σ_j`
/// (the `μ_ZL` and `σ_ZL` ingredients of Eq. 21); with correlated normal
/// inputs `a_c = S_cᵀ·D·L`, so `|a_c| = √(S_cᵀΣS_c)` ([`Inputs::project`]).
#[derive(Debug, Clone)]
pub struct Affine<'l> {
    /// The limit state's affine view.
    pub view: AffineView<'l>,
    /// `m_c`, one per component.
    pub mean: Vec<f64>,
    /// `a_cj`, `k × n` row-major.
    pub a: Vec<f64>,
}

impl<'l> Affine<'l> {
    fn new(ls: AffineView<'l>, inputs: &Inputs) -> Affine<'l> {
        let n = ls.n;
        let k = ls.components();
        let mut mean = vec![0.0; k];
        let mut a = vec![0.0; k * n];
        for c in 0..k {
            // a_c = S_cᵀ·∂x/∂u (S_cj·σ_j for independent inputs).
            mean[c] = inputs.project(ls.row(c), &mut a[c * n..(c + 1) * n]);
        }
        Affine { view: ls, mean, a }
    }

    /// Row `c` of `a`.
    pub fn row(&self, c: usize) -> &[f64] {
        let n = self.view.n;
        &self.a[c * n..(c + 1) * n]
    }

    /// `σ_E = |a_c|`, the standard deviation of component `c`.
    pub fn std(&self, c: usize) -> f64 {
        self.row(c).iter().map(|v| v * v).sum::<f64>().sqrt()
    }
}
