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

    /// The tolerance structure `g = G(S·x)`, when the limit state has it. It
    /// lets FORM use its closed form and the importance sampling solve
    /// `g = 0` along a line exactly.
    fn structure(&self) -> Option<&ToleranceLimitState> {
        None
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
        if n == 0 || rows.is_empty() || rows.len() % n != 0 {
            return Err(ReliabilityError::Dimension {
                what: "sensitivity rows (k × n)",
                expected: n.max(1),
                found: rows.len(),
            });
        }
        let k = rows.len() / n;
        let expected = match criterion {
            Criterion::Each(_) => k,
            Criterion::Norm => 1,
        };
        if tolerances.len() != expected {
            return Err(ReliabilityError::Dimension {
                what: "tolerances",
                expected,
                found: tolerances.len(),
            });
        }
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
        self.components() == 1 && self.criterion == Criterion::Each(Sided::Upper)
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
        match self.criterion {
            Criterion::Each(Sided::Upper) => self.components(),
            Criterion::Each(Sided::Two) => 2 * self.components(),
            Criterion::Norm => 1,
        }
    }

    fn branch(&self, b: usize, x: &[f64], gradient: Option<&mut [f64]>) -> f64 {
        match self.criterion {
            Criterion::Each(sided) => {
                let (c, sign) = match sided {
                    Sided::Upper => (b, 1.0),
                    Sided::Two => (b / 2, if b % 2 == 0 { 1.0 } else { -1.0 }),
                };
                if let Some(g) = gradient {
                    for (g, s) in g.iter_mut().zip(self.row(c)) {
                        *g = -sign * s;
                    }
                }
                self.tolerances[c] - sign * self.dot(c, x)
            }
            Criterion::Norm => {
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

    fn structure(&self) -> Option<&ToleranceLimitState> {
        Some(self)
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
        let ls = self.limit_state.structure()?;
        if !self.inputs.is_affine() {
            return None;
        }
        Some(Affine::new(ls, self.inputs))
    }

    /// The exact failure probability when it has a closed form: one component
    /// in normal inputs, `Φ(−β)` for an upper tolerance (Eq. 21, 31) and
    /// `Φ(−β₊) + Φ(−β₋)` for a two-sided one.
    pub fn exact_pf(&self) -> Option<f64> {
        let a = self.affine()?;
        if a.limit_state.components() != 1 {
            return None;
        }
        let s = a.std(0);
        let m = a.mean[0];
        let i = a.limit_state.tolerances[0];
        match a.limit_state.criterion {
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

/// A tolerance limit state over normal inputs, seen in standard space:
/// `E_c(u) = m_c + a_c·u` with `m_c = Σ_j S_cj·μ_j` and `a_cj = S_cj·σ_j`
/// (the `μ_ZL` and `σ_ZL` ingredients of Eq. 21).
#[derive(Debug, Clone)]
pub struct Affine<'l> {
    /// The limit state.
    pub limit_state: &'l ToleranceLimitState,
    /// `m_c`, one per component.
    pub mean: Vec<f64>,
    /// `a_cj`, `k × n` row-major.
    pub a: Vec<f64>,
}

impl<'l> Affine<'l> {
    fn new(ls: &'l ToleranceLimitState, inputs: &Inputs) -> Affine<'l> {
        let n = ls.n;
        let k = ls.components();
        let mut mean = vec![0.0; k];
        let mut a = vec![0.0; k * n];
        for c in 0..k {
            for (j, m) in inputs.marginals().iter().enumerate() {
                let s = ls.row(c)[j];
                mean[c] += s * m.mean();
                a[c * n + j] = s * m.std();
            }
        }
        Affine {
            limit_state: ls,
            mean,
            a,
        }
    }

    /// Row `c` of `a`.
    pub fn row(&self, c: usize) -> &[f64] {
        let n = self.limit_state.n;
        &self.a[c * n..(c + 1) * n]
    }

    /// `σ_E = |a_c|`, the standard deviation of component `c`.
    pub fn std(&self, c: usize) -> f64 {
        self.row(c).iter().map(|v| v * v).sum::<f64>().sqrt()
    }
}
