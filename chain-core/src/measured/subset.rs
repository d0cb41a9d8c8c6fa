//! Which unknowns to estimate: an identifiable subset chosen by a
//! rank-revealing elimination, the ordinary least-squares estimates of that
//! subset with the others fixed at their nominal value (0), and each fixed
//! unknown's relation to the estimated ones (`docs/identify.md`, "What is
//! estimated and what is fixed").
//!
//! # Formulas
//!
//! With the information matrix `F = AᵀWA`, its equilibration
//! `D = diag(1/√F_jj)` and the eigen-decomposition `D F D = V Λ Vᵀ`
//! (largest first), the design truncated to the `r` directions the data
//! determine is, up to an orthogonal factor on the left, `C = Λ_r^{1/2}
//! V_rᵀ` (`r × n`: `CᵀC` is the rank-`r` part of `D F D`, so a QR of `C`
//! has the `R` of a QR of the truncated equilibrated design).
//!
//! - **Elimination**: column-pivoted QR of `C` (Businger & Golub 1965):
//!   at each of the `r` steps the column with the largest norm orthogonal
//!   to those already chosen is taken (a tie within 1e-9 relative goes to
//!   the first in the machine's order), by modified Gram–Schmidt with
//!   re-orthogonalisation. nalgebra's `ColPivQR` is not used: it pivots on
//!   the largest entry of the remaining block, not the largest column norm,
//!   and so does not reveal the rank.
//! - **Estimates**: `F_SS x_S = (AᵀWb)_S` (equilibrated Cholesky), the
//!   fixed unknowns at 0; the covariance `F_SS⁻¹` with a `std` column, else
//!   `s² F_SS⁻¹`, `s² = RSS/(m − |S|)`.
//! - **Relations**: for a fixed `j`, `c_j = F_SS⁻¹ F_Sj` (the weighted
//!   regression of its design column on the estimated ones): `a_j ≈ Σ_k
//!   c_jk a_k`, so the estimate of a kept `k` is unbiased for
//!   `x_k + Σ_j c_jk x_j` (its **combination**) whatever the fixed
//!   unknowns' true values: `E[x̂_S] = F_SS⁻¹ A_Sᵀ W (A_S x_S + A_F x_F)`.
//!   The relation's weights in equilibrated units, `ĉ_jk = c_jk d_j / d_k`
//!   (the share of `j`'s unit-norm effect carried by `k`), below
//!   [`TERM_CUTOFF`] are left out of the words (kept in the JSON). The part
//!   of `j`'s column the estimated ones do not carry, `ρ_j = √(1 −
//!   F_jS c_j / F_jj)`, is reported; the status is decided in the
//!   structural design (its determined and weak directions): the fixed
//!   column's norm left after the estimated ones by Gram–Schmidt at most
//!   the rank tolerance × `s_max` is **redundant** (structurally: the
//!   measurements cannot tell it from the combination), otherwise **weak**
//!   (chosen by the noise rule: the data do not determine it beyond their
//!   noise; never under a fixed `--rank-tol`, which has no weak
//!   directions) or **fixed**
//!   (by the caller's choice: fixing it biases the estimates by its true
//!   value times the part `ρ_j` the others do not carry).

use nalgebra::{DMatrix, DVector};
use serde::Serialize;

use super::estimate::{
    covariance, noise_scale2, Estimate, IdentifyError, SubsetProblem, SubsetSide,
};

/// Relation weights (in equilibrated units: the share of the fixed
/// unknown's unit-norm effect carried by an estimated one) below this are
/// left out of the relation's words and the combinations.
pub const TERM_CUTOFF: f64 = 1e-3;

/// Who chose the estimated subset.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ChosenBy {
    /// The column-pivoted QR of the truncated equilibrated design.
    Elimination,
    /// The fixed unknowns named: every other one is estimated.
    Fix,
    /// The estimated unknowns named: every other one is fixed.
    Estimate,
}

/// Which unknowns are estimated: the elimination's choice, or a list
/// chosen by the caller.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub enum SubsetChoice {
    /// The elimination's choice.
    #[default]
    Elimination,
    /// These are fixed at 0, every other one estimated.
    Fix(Vec<String>),
    /// These are estimated, every other one fixed at 0.
    Estimate(Vec<String>),
}

impl SubsetChoice {
    /// The list chosen and its names (`None`: the elimination's choice).
    pub fn chosen(&self) -> Option<(SubsetSide, &[String])> {
        match self {
            SubsetChoice::Elimination => None,
            SubsetChoice::Fix(names) => Some((SubsetSide::Fixed, names)),
            SubsetChoice::Estimate(names) => Some((SubsetSide::Estimated, names)),
        }
    }
}

/// Why a fixed unknown is not estimated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum FixedStatus {
    /// Its design column is zero: the measurements do not see it.
    Unseen,
    /// Its column is a combination of the estimated ones (structurally).
    Redundant,
    /// Left out by the noise rule: the data determine it only within their
    /// noise.
    Weak,
    /// Fixed by the caller's choice although the estimated ones do not
    /// carry all its effect.
    Fixed,
}

impl FixedStatus {
    /// The status in words, for the table.
    pub fn words(self) -> &'static str {
        match self {
            FixedStatus::Unseen => "not seen by the data",
            FixedStatus::Redundant => "redundant",
            FixedStatus::Weak => "weakly determined",
            FixedStatus::Fixed => "fixed by choice",
        }
    }
}

/// One fixed unknown.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Fixed {
    /// Its index in the unknowns.
    pub index: usize,
    /// Why it is fixed.
    pub status: FixedStatus,
    /// `(k, c_jk)`: its design column as a combination of the estimated
    /// ones' (every weight, in the unknowns' own units).
    pub relation: Vec<(usize, f64)>,
    /// The same weights in equilibrated units (`ĉ_jk`), in the same order.
    pub shares: Vec<f64>,
    /// `ρ_j`: the part of its (unit-norm) effect the estimated ones do not
    /// carry.
    pub residual: f64,
}

/// The estimated subset and its solution.
#[derive(Debug, Clone, PartialEq)]
pub struct Subset {
    /// Who chose it.
    pub chosen_by: ChosenBy,
    /// The estimated unknowns (indices, ascending).
    pub estimated: Vec<usize>,
    /// The fixed unknowns, ascending.
    pub fixed: Vec<Fixed>,
    /// Every unknown's value (0 for a fixed one) and std (`None` for a
    /// fixed one, or when the noise cannot be estimated).
    pub estimates: Vec<Estimate>,
    /// The covariance over every unknown (`n × n`, zero rows and columns
    /// for the fixed ones; NaN when the noise cannot be estimated).
    pub covariance: DMatrix<f64>,
    /// Root mean square of `b − A x` over the scalar rows.
    pub rms: f64,
    /// `Σ ((b − A x)/σ)²`.
    pub rss: f64,
}

impl Subset {
    /// The values of every unknown.
    pub fn values(&self) -> Vec<f64> {
        self.estimates.iter().map(|e| e.value).collect()
    }
}

/// The inputs of [`choose`] and [`solve`], from `identify`.
pub(crate) struct Problem<'a> {
    /// The design `A` (`m × n`).
    pub a: &'a DMatrix<f64>,
    /// The measured values `b`.
    pub b: &'a [f64],
    /// `1/σ_i` per row.
    pub inv_sigma: &'a [f64],
    /// Whether the rows had a `std` column.
    pub weighted: bool,
    /// `F = AᵀWA`.
    pub info: &'a DMatrix<f64>,
    /// `AᵀWb`.
    pub g: &'a DVector<f64>,
    /// The equilibration `d_j`.
    pub d: &'a [f64],
    /// The eigenvalues of `D F D`: the determined directions first, then
    /// the weak ones, then those beyond the structural rank.
    pub lambda: &'a [f64],
    /// Their eigenvectors, in the same order.
    pub vectors: &'a DMatrix<f64>,
    /// The largest singular value of the equilibrated design.
    pub s_max: f64,
    /// The relative rank tolerance in use.
    pub tolerance: f64,
    /// The unknowns' names.
    pub names: &'a [String],
    /// Each unknown's physical scale ([`super::measurements::physical_scales`]):
    /// what keeps the elimination's carriers plausible ([`plausible`]).
    pub scales: &'a [f64],
    /// The structural rank: the directions above the rank tolerance (the
    /// determined ones and the weak ones the noise rule left out).
    pub structural: usize,
    /// The last `forced` unknowns (set-up positions, [`super::Setup`]) are
    /// always estimated: the elimination takes them first, and the
    /// caller's lists name the others.
    pub forced: usize,
}

impl Problem<'_> {
    /// `C = Λ_k^{1/2} V_kᵀ`: the equilibrated design truncated to its `k`
    /// leading directions in [`Problem::lambda`]'s order (`k × n`).
    fn truncated(&self, k: usize) -> DMatrix<f64> {
        let n = self.d.len();
        DMatrix::from_fn(k, n, |i, j| {
            self.lambda[i].max(0.0).sqrt() * self.vectors[(j, i)]
        })
    }

    /// The largest singular value of the equilibrated design.
    fn s_max(&self) -> f64 {
        self.s_max
    }
}

/// Column-pivoted Gram–Schmidt on the columns `candidates` of `c`: up to
/// `steps` pivots, the first `forced` candidates in their order (each while
/// its remaining norm is above `floor`), then each the candidate with the
/// largest remaining norm (ties within 1e-9 relative to the first),
/// stopping when the largest is at most `floor`. Returns the pivots in
/// order and every candidate's remaining norm after them (infinite for a
/// pivot).
fn pivots(
    c: &DMatrix<f64>,
    candidates: &[usize],
    forced: usize,
    steps: usize,
    floor: f64,
) -> (Vec<usize>, Vec<f64>) {
    let mut cols: Vec<DVector<f64>> = candidates
        .iter()
        .map(|&j| c.column(j).into_owned())
        .collect();
    let mut chosen: Vec<usize> = Vec::new();
    let mut taken = vec![false; candidates.len()];
    for step in 0..steps {
        let norms: Vec<f64> = cols.iter().map(|v| v.norm()).collect();
        let p = if step < forced.min(cols.len()) {
            if norms[step] <= floor {
                continue;
            }
            step
        } else {
            let best = (0..cols.len())
                .filter(|&i| !taken[i])
                .map(|i| norms[i])
                .fold(0.0f64, f64::max);
            if best <= floor {
                break;
            }
            let Some(p) = (0..cols.len()).find(|&i| !taken[i] && norms[i] >= best * (1.0 - 1e-9))
            else {
                break;
            };
            p
        };
        taken[p] = true;
        chosen.push(candidates[p]);
        let q = &cols[p] / norms[p];
        for (i, v) in cols.iter_mut().enumerate() {
            if taken[i] {
                continue;
            }
            // Twice: modified Gram–Schmidt with re-orthogonalisation.
            for _ in 0..2 {
                let t = q.dot(v);
                v.axpy(-t, &q, 1.0);
            }
        }
        cols[p].fill(0.0);
    }
    let remaining = (cols.iter().zip(&taken))
        .map(|(v, &t)| if t { f64::INFINITY } else { v.norm() })
        .collect();
    (chosen, remaining)
}

/// The index of each name in `names`, or the refusal naming the list
/// (`side`) and the closest unknown.
fn indices(
    side: SubsetSide,
    given: &[String],
    names: &[String],
) -> Result<Vec<usize>, IdentifyError> {
    let refuse = |problem| IdentifyError::Subset { side, problem };
    let mut out = Vec::with_capacity(given.len());
    for g in given {
        match names.iter().position(|n| n == g) {
            Some(j) if !out.contains(&j) => out.push(j),
            Some(_) => return Err(refuse(SubsetProblem::Twice { name: g.clone() })),
            None => {
                let close = crate::input::diagnostic::closest(g, names.iter().map(String::as_str));
                return Err(refuse(SubsetProblem::Unknown {
                    name: g.clone(),
                    suggestion: close.map(str::to_string),
                }));
            }
        }
    }
    Ok(out)
}

/// The estimated unknowns: the elimination's `r` pivots on the design
/// truncated to its `r` determined directions, or the user's choice
/// (refused when the chosen ones are not separable by the measurements).
pub(crate) fn choose(
    p: &Problem<'_>,
    r: usize,
    structural: usize,
    choice: &SubsetChoice,
) -> Result<(ChosenBy, Vec<usize>), IdentifyError> {
    let n = p.d.len();
    let ne = n - p.forced;
    let forced: Vec<usize> = (ne..n).collect();
    let errors = &p.names[..ne];
    let (by, mut kept) = match choice {
        SubsetChoice::Elimination => {
            // The set-ups' positions first, then the errors.
            let order: Vec<usize> = forced.iter().copied().chain(0..ne).collect();
            let (chosen, _) = pivots(&p.truncated(r), &order, p.forced, r, 0.0);
            (ChosenBy::Elimination, plausible(p, chosen, r))
        }
        SubsetChoice::Fix(names) => {
            let fixed = indices(SubsetSide::Fixed, names, errors)?;
            (
                ChosenBy::Fix,
                (0..n).filter(|j| !fixed.contains(j)).collect(),
            )
        }
        SubsetChoice::Estimate(names) => {
            let mut estimated = indices(SubsetSide::Estimated, names, errors)?;
            estimated.extend(&forced);
            (ChosenBy::Estimate, estimated)
        }
    };
    kept.sort_unstable();
    if by != ChosenBy::Elimination {
        // Separable: every chosen column keeps a part above the rank
        // tolerance once the others are taken out (the structural design).
        let floor = p.tolerance * p.s_max();
        let c = p.truncated(structural);
        let (chosen, remaining) = pivots(&c, &kept, 0, kept.len(), floor);
        if chosen.len() < kept.len() {
            let mut names: Vec<String> = kept
                .iter()
                .zip(&remaining)
                .filter(|(_, &rest)| rest <= floor)
                .map(|(&j, _)| p.names[j].clone())
                .collect();
            names.sort_unstable();
            return Err(IdentifyError::Subset {
                side: choice
                    .chosen()
                    .map_or(SubsetSide::Estimated, |(side, _)| side),
                problem: SubsetProblem::Inseparable { names },
            });
        }
    }
    Ok((by, kept))
}

/// How far beyond its physical scale a kept error's estimate may be moved
/// by a fixed error of plausible size before the two change places
/// ([`plausible`]): two orders of magnitude.
pub const IMPLAUSIBLE: f64 = 100.0;

/// The elimination's subset `kept` with its carriers kept plausible
/// (`docs/identify.md`, "Subsets that stay physical"). For each fixed
/// error `j`, its relation `c_j = F_SS⁻¹ F_Sj` to the kept ones in the
/// design truncated to its `directions` determined directions says that a
/// kept `k`'s estimate stands for `x_k + c_jk x_j`: an error `j` of its
/// physical size `s_j` ([`Problem::scales`]) moves it by `|c_jk| s_j`. When
/// that exceeds [`IMPLAUSIBLE`] × `s_k` for some `k` (the machine's order
/// chose a carrier that cannot stay plausible: a flange angle standing for
/// a tool offset 0.09 mm off its axis), `j` is kept instead of the `k` it
/// moves most (the span is the same, `c_jk ≠ 0`). Repeated until no such
/// pair is left; an error once swapped out is not taken back, so at most
/// one swap per error. Exact ties and plausible carriers keep the machine's
/// order, as the elimination chose.
fn plausible(p: &Problem<'_>, mut kept: Vec<usize>, directions: usize) -> Vec<usize> {
    let n = p.d.len();
    let ne = n - p.forced;
    let c = p.truncated(directions);
    let info_t = |i: usize, j: usize| c.column(i).dot(&c.column(j)) / (p.d[i] * p.d[j]);
    let mut out = vec![false; n];
    loop {
        kept.sort_unstable();
        let k = kept.len();
        // Equilibrated F_SS (as `solve` forms it) and its Cholesky.
        let e: Vec<f64> = kept.iter().map(|&j| p.d[j]).collect();
        let fss = DMatrix::from_fn(k, k, |a, b| e[a] * info_t(kept[a], kept[b]) * e[b]);
        let Some(ch) = nalgebra::Cholesky::new(fss) else {
            return kept;
        };
        let mut best: Option<(f64, usize, usize)> = None;
        for j in (0..ne).filter(|j| !kept.contains(j) && !out[*j]) {
            if p.info[(j, j)] <= 0.0 {
                continue;
            }
            let fsj = DVector::from_fn(k, |a, _| e[a] * info_t(kept[a], j));
            let cj = ch.solve(&fsj);
            for (a, &kk) in kept.iter().enumerate() {
                if kk >= ne {
                    continue;
                }
                let moved = (cj[a] * e[a]).abs() * p.scales[j];
                let ratio = moved / p.scales[kk];
                if ratio > IMPLAUSIBLE && best.is_none_or(|(r, _, _)| ratio > r) {
                    best = Some((ratio, j, kk));
                }
            }
        }
        match best {
            Some((_, j, kk)) => {
                kept.retain(|&x| x != kk);
                kept.push(j);
                out[kk] = true;
            }
            None => return kept,
        }
    }
}

/// The least-squares solution of the subset `kept` (the others at 0) in
/// the design truncated to its `directions` leading directions (the
/// determined ones for the elimination, the structural ones for a chosen
/// subset), the fixed unknowns' relations and statuses (`weak` when `by` is
/// the elimination and the relation is not structural).
pub(crate) fn solve(p: &Problem<'_>, by: ChosenBy, kept: &[usize], directions: usize) -> Subset {
    let n = p.d.len();
    let k = kept.len();
    let (m, _) = p.a.shape();
    let floor = p.tolerance * p.s_max();
    // The truncated information F_t = D⁻¹ V_t Λ_t V_tᵀ D⁻¹ and right-hand
    // side g_t = D⁻¹ V_t V_tᵀ D g: E[g_t] = F_t x and cov(g_t) = σ² F_t, so
    // the estimates below are unbiased for their combinations with the
    // covariance σ² F_t,SS⁻¹ (a weak direction's share of a column is left
    // out instead of being fitted).
    let c = p.truncated(directions);
    let dg = DVector::from_fn(n, |i, _| p.d[i] * p.g[i]);
    let vg: Vec<f64> = (0..directions)
        .map(|i| p.vectors.column(i).dot(&dg))
        .collect();
    let info_t = |i: usize, j: usize| -> f64 { c.column(i).dot(&c.column(j)) / (p.d[i] * p.d[j]) };
    let g_t = |i: usize| -> f64 {
        (0..directions)
            .map(|l| p.vectors[(i, l)] * vg[l])
            .sum::<f64>()
            / p.d[i]
    };
    // Equilibrated F_t,SS and its inverse (Cholesky; the kept columns are
    // separable, so it is positive definite up to rounding).
    let e: Vec<f64> = kept.iter().map(|&j| p.d[j]).collect();
    let fss = DMatrix::from_fn(k, k, |a, b| e[a] * info_t(kept[a], kept[b]) * e[b]);
    let inv = match nalgebra::Cholesky::new(fss.clone()) {
        Some(ch) => ch.inverse(),
        None => fss
            .pseudo_inverse(1e-12)
            .unwrap_or_else(|_| DMatrix::zeros(k, k)),
    };
    let inv_phys = DMatrix::from_fn(k, k, |a, b| e[a] * inv[(a, b)] * e[b]);
    let gs = DVector::from_fn(k, |a, _| g_t(kept[a]));
    let xs = &inv_phys * gs;
    let mut x = DVector::zeros(n);
    for (a, &j) in kept.iter().enumerate() {
        x[j] = xs[a];
    }
    let ax = p.a * &x;
    let residuals: Vec<f64> = p.b.iter().zip(ax.iter()).map(|(b, v)| b - v).collect();
    let rss: f64 = (residuals.iter().zip(p.inv_sigma))
        .map(|(r, w)| (r * w) * (r * w))
        .sum();
    let rms = if m > 0 {
        (residuals.iter().map(|r| r * r).sum::<f64>() / m as f64).sqrt()
    } else {
        0.0
    };
    let scale2 = noise_scale2(p.weighted, rss, m, k);
    let (covariance, estimates) = covariance(x.as_slice(), kept, &inv_phys, scale2);
    // Whether the kept columns carry a fixed one structurally: its norm
    // left after them by Gram–Schmidt in the structural design (the
    // determined and the weak directions), against the rank floor.
    // Redundant at most the floor; otherwise it is separable and fixed only
    // because the noise rule left its directions out (weak) or by choice.
    // (The reported `residual` is the full design's part, from a
    // difference that cancels for a redundant one: it decides nothing.)
    let order: Vec<usize> = (kept.iter().copied())
        .chain((0..n).filter(|j| !kept.contains(j)))
        .collect();
    let (_, rest) = pivots(&p.truncated(p.structural), &order, k, k, 0.0);
    let mut structural_rest = vec![0.0; n];
    for (at, &j) in order.iter().enumerate() {
        structural_rest[j] = rest[at];
    }
    let fixed = (0..n)
        .filter(|j| !kept.contains(j))
        .map(|j| {
            let fjj = p.info[(j, j)];
            if fjj <= 0.0 {
                return Fixed {
                    index: j,
                    status: FixedStatus::Unseen,
                    relation: Vec::new(),
                    shares: Vec::new(),
                    residual: 0.0,
                };
            }
            let fsj = DVector::from_fn(k, |a, _| info_t(kept[a], j));
            let c = &inv_phys * &fsj;
            // The part of the column the relation leaves, in the full
            // design: ‖a_j − A_S c‖² / ‖a_j‖².
            let full_sj = DVector::from_fn(k, |a, _| p.info[(kept[a], j)]);
            let full_ss = DMatrix::from_fn(k, k, |a, b| p.info[(kept[a], kept[b])]);
            let left = fjj - 2.0 * c.dot(&full_sj) + c.dot(&(&full_ss * &c));
            let residual = (left / fjj).max(0.0).sqrt();
            let status = if structural_rest[j] <= floor {
                FixedStatus::Redundant
            } else if by == ChosenBy::Elimination {
                FixedStatus::Weak
            } else {
                FixedStatus::Fixed
            };
            Fixed {
                index: j,
                status,
                relation: kept.iter().zip(c.iter()).map(|(&i, &v)| (i, v)).collect(),
                shares: kept
                    .iter()
                    .zip(c.iter())
                    .map(|(&i, &v)| v * p.d[j] / p.d[i])
                    .collect(),
                residual,
            }
        })
        .collect();
    Subset {
        chosen_by: by,
        estimated: kept.to_vec(),
        fixed,
        estimates,
        covariance,
        rms,
        rss,
    }
}
