//! Measurement planning: where to measure (measured-machines spec, section 5;
//! `docs/plan.md`).
//!
//! The exact sensitivity rows of a machine are the design matrix of its
//! calibration (spec section 4): a tool-point measurement at a pose gives the
//! three rows `px, py, pz` of `S(q, p)`; a 1-D measurement along a unit
//! direction `u` gives the one row `u · (px, py, pz)`. [`Design`] holds those
//! rows for every candidate pose; [`plan`] chooses `K` of them that maximise
//! the information `det(AᵀA)` on the identifiable subspace (D-optimal design),
//! and compares the choice with `K` candidates taken evenly.
//!
//! # The identifiable subspace
//!
//! The identifiable subspace is the row space of the whole candidate matrix
//! `A` (the span of its right singular vectors with non-negligible singular
//! values). The rank is decided on the column-equilibrated information
//! `Dₛ AᵀA Dₛ` (`Dₛ = diag(1/‖a_j‖)`, so that a linear error in mm and an
//! angular one in rad weigh alike): eigenvalues above [`RANK_TOLERANCE`]
//! times the largest count. With `Vₛ, Λₛ` the retained eigenpairs, the
//! candidates' rows are taken to the whitened coordinates `b = Tᵀ a`,
//! `T = Dₛ Vₛ Λₛ^{-1/2}`, in which the whole candidate set's information is
//! the identity: the search works there. The reported quantities are the
//! spec's, in an orthonormal basis `V` of the identifiable subspace (the
//! orthogonal complement of the null space `Dₛ · null(Dₛ AᵀA Dₛ)`):
//! `ln det(Vᵀ A_Sᵀ A_S V)` (equal to `ln det(A_Sᵀ A_S)` with full rank).
//!
//! # The search
//!
//! Greedy: starting from a ridge `ε I` (`ε =` [`RIDGE`]` · K/n`), add the
//! candidate with the largest `det(I + B_j M⁻¹ B_jᵀ)` (the matrix determinant
//! lemma), updating `M⁻¹` and every candidate's `B_j M⁻¹` by Woodbury's
//! identity. Then Fedorov's exchange (Fedorov 1972; Cook & Nachtsheim 1980's
//! sequential form): for each chosen candidate `i` in turn, the best
//! unchosen `j` by
//!
//! ```text
//! det(M − B_iᵀB_i + B_jᵀB_j) / det(M) = det [ I + B_j M⁻¹ B_jᵀ    B_j M⁻¹ B_iᵀ ]
//!                                           [ −B_i M⁻¹ B_jᵀ     I − B_i M⁻¹ B_iᵀ ]
//! ```
//!
//! (the determinant lemma for the rank-2r update `Uᵀ Σ U`, `U = [B_j; B_i]`,
//! `Σ = diag(I, −I)`), swapped when it improves the determinant by more than
//! [`SWAP_GAIN`]; until one whole sweep swaps nothing: then no single swap
//! improves the design by more than that factor (a local optimum).
//!
//! # Expected standard deviations
//!
//! Per unit measurement std, each parameter's std of the minimum-norm
//! estimate (spec section 4) is `sqrt((M_S⁺)_jj)` with the pseudo-inverse
//! `M_S⁺ = V (Vᵀ M_S V)⁻¹ Vᵀ`; with full rank, `(AᵀA)⁻¹`.

use nalgebra::{DMatrix, DVector, Matrix6, SymmetricEigen};
use serde::Serialize;

use crate::model_trait::ErrorModel;

/// Eigenvalues of the equilibrated information below this fraction of the
/// largest are taken as zero (singular values below about 3·10⁻⁶ of the
/// largest).
pub const RANK_TOLERANCE: f64 = 1e-11;

/// The ridge of the greedy start, relative to `K/n` (the information of `K`
/// average candidates in whitened coordinates).
pub const RIDGE: f64 = 1e-9;

/// A swap is taken when it multiplies the determinant by more than
/// `1 + SWAP_GAIN`.
pub const SWAP_GAIN: f64 = 1e-9;

/// The exchange stops after this many sweeps even if the last one swapped
/// (each swap multiplies the determinant by more than `1 + SWAP_GAIN`, so
/// the sweeps end; this bounds the time).
pub const MAX_SWEEPS: usize = 1000;

/// A direction `u` must be of unit length to this tolerance.
pub const UNIT_TOLERANCE: f64 = 1e-6;

/// What one candidate measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Kind {
    /// The tool-point deviation `px, py, pz` (three rows).
    Point,
    /// The deviation `u · p` along a unit direction (one row).
    Direction,
}

impl Kind {
    /// Design rows per candidate.
    pub fn rows(self) -> usize {
        match self {
            Kind::Point => 3,
            Kind::Direction => 1,
        }
    }
}

/// One candidate measurement: a pose, the parameter values of its row, and
/// for [`Kind::Direction`] its direction.
#[derive(Debug, Clone, PartialEq)]
pub struct Candidate {
    /// Axis values, in the model's variable order (rotary in radians).
    pub q: Vec<f64>,
    /// Parameter values, in the model's parameter order.
    pub p: Vec<f64>,
    /// The unit direction `u` of a 1-D measurement.
    pub direction: Option<[f64; 3]>,
}

/// Why a plan cannot be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[cfg_attr(feature = "miette", derive(miette::Diagnostic))]
#[non_exhaustive]
pub enum PlanError {
    /// No candidate.
    #[error("there is no candidate")]
    NoCandidates,
    /// `K` is zero or above the candidate count.
    #[error("--count {count} is not a count of candidates: choose 1 to {candidates}")]
    Count {
        /// The count asked for.
        count: usize,
        /// The candidates given.
        candidates: usize,
    },
    /// `K` candidates cannot inform the identifiable subspace.
    #[error("{count} candidates give {rows} design rows, fewer than the {rank} dimensions the candidates can identify; choose --count {minimum} or more")]
    TooFew {
        /// The count asked for.
        count: usize,
        /// Their design rows.
        rows: usize,
        /// The rank of the whole candidate set.
        rank: usize,
        /// The smallest count with as many rows as the rank.
        minimum: usize,
    },
    /// The candidates inform nothing.
    #[error("the candidates identify nothing: every design row is zero")]
    Uninformative,
    /// A candidate of the wrong dimension.
    #[error("candidate {index}: {found} {what} for a model of {expected}")]
    Dimension {
        /// The candidate (0-based).
        index: usize,
        /// `axis values` or `parameter values`.
        what: &'static str,
        /// Given.
        found: usize,
        /// Expected.
        expected: usize,
    },
    /// A non-finite pose, parameter or direction.
    #[error("candidate {index}: a value is not finite")]
    NonFinite {
        /// The candidate (0-based).
        index: usize,
    },
    /// A direction candidate without a direction.
    #[error("candidate {index}: no direction (ux, uy, uz) for a direction measurement")]
    NoDirection {
        /// The candidate (0-based).
        index: usize,
    },
    /// A direction that is not of unit length.
    #[error("candidate {index}: the direction (ux, uy, uz) has length {length}, not 1 (to 1e-6)")]
    NotUnit {
        /// The candidate (0-based).
        index: usize,
        /// Its length.
        length: f64,
    },
    /// No subset of the asked size gives a non-singular information.
    #[error("no {count} of the candidates found inform every identifiable direction")]
    Singular {
        /// The count asked for.
        count: usize,
    },
}

/// The design rows of every candidate.
#[derive(Debug, Clone, PartialEq)]
pub struct Design {
    kind: Kind,
    errors: Vec<String>,
    /// `(n · rows) × N`, candidate `i`'s rows at `rows·i ..`.
    a: DMatrix<f64>,
}

impl Design {
    /// The rows of `candidates` through `model`'s exact sensitivity.
    pub fn new<M: ErrorModel + ?Sized>(
        model: &M,
        candidates: &[Candidate],
        kind: Kind,
    ) -> Result<Design, PlanError> {
        let (nv, np, ne) = (
            model.variables().len(),
            model.parameters().len(),
            model.errors().len(),
        );
        let r = kind.rows();
        let mut a = DMatrix::zeros(candidates.len() * r, ne);
        let mut s = vec![0.0; 6 * ne];
        for (i, c) in candidates.iter().enumerate() {
            for (what, found, expected) in [
                ("axis values", c.q.len(), nv),
                ("parameter values", c.p.len(), np),
            ] {
                if found != expected {
                    return Err(PlanError::Dimension {
                        index: i,
                        what,
                        found,
                        expected,
                    });
                }
            }
            if !c.q.iter().chain(&c.p).all(|x| x.is_finite()) {
                return Err(PlanError::NonFinite { index: i });
            }
            model.sensitivity(&c.q, &c.p, &mut s);
            match kind {
                Kind::Point => {
                    for k in 0..3 {
                        for j in 0..ne {
                            a[(3 * i + k, j)] = s[k * ne + j];
                        }
                    }
                }
                Kind::Direction => {
                    let u = c.direction.ok_or(PlanError::NoDirection { index: i })?;
                    if !u.iter().all(|x| x.is_finite()) {
                        return Err(PlanError::NonFinite { index: i });
                    }
                    let length = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
                    if (length - 1.0).abs() > UNIT_TOLERANCE {
                        return Err(PlanError::NotUnit { index: i, length });
                    }
                    for j in 0..ne {
                        a[(i, j)] = (0..3).map(|k| u[k] / length * s[k * ne + j]).sum();
                    }
                }
            }
        }
        Ok(Design {
            kind,
            errors: model.errors().iter().map(|e| e.to_string()).collect(),
            a,
        })
    }

    /// A design from rows already computed: `a` is `(n · kind.rows()) × N`.
    pub fn from_rows(kind: Kind, errors: Vec<String>, a: DMatrix<f64>) -> Design {
        assert_eq!(a.nrows() % kind.rows(), 0, "whole candidates");
        assert_eq!(a.ncols(), errors.len(), "one column per error");
        Design { kind, errors, a }
    }

    /// The number of candidates.
    pub fn len(&self) -> usize {
        self.a.nrows() / self.kind.rows()
    }

    /// Whether there is no candidate.
    pub fn is_empty(&self) -> bool {
        self.a.nrows() == 0
    }

    /// The design rows, candidate `i`'s at `kind.rows() · i ..`.
    pub fn rows(&self) -> &DMatrix<f64> {
        &self.a
    }

    /// What each candidate measures.
    pub fn kind(&self) -> Kind {
        self.kind
    }

    /// The error parameters (the columns).
    pub fn errors(&self) -> &[String] {
        &self.errors
    }
}

/// One subset of candidates and what it would tell.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Subset {
    /// The candidates (0-based, ascending).
    pub candidates: Vec<usize>,
    /// `ln det(Vᵀ A_Sᵀ A_S V)` on the identifiable subspace; `None` when the
    /// subset leaves an identifiable direction uninformed (det = 0).
    pub log_det: Option<f64>,
    /// Each error parameter's expected std per unit measurement std
    /// (`None` when singular), in the design's error order.
    pub std: Vec<Option<f64>>,
}

/// The plan: the D-optimal choice and the even spread.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Plan {
    /// What the candidates measure.
    pub kind: Kind,
    /// The number of candidates.
    pub candidates: usize,
    /// The count chosen.
    pub count: usize,
    /// The error parameters.
    pub errors: Vec<String>,
    /// The rank of the whole candidate set (the identifiable dimensions).
    pub rank: usize,
    /// Per error parameter: whether it is aliased with others (has a
    /// component above 1e-9 in the null space of the whole candidate set),
    /// its std then being that of the minimum-norm estimate.
    pub aliased: Vec<bool>,
    /// The D-optimal choice.
    pub optimal: Subset,
    /// Every (n/K)-th candidate (`⌊k·n/K⌋`, k = 0..K−1).
    pub even: Subset,
    /// Swaps the exchange made after the greedy start.
    pub swaps: usize,
    /// Exchange sweeps (the last swapped nothing).
    pub sweeps: usize,
}

/// The identifiable subspace of a design, in whitened coordinates.
struct Subspace {
    rank: usize,
    /// `V` (N × r): an orthonormal basis of the identifiable subspace.
    v: DMatrix<f64>,
    /// The rows in its coordinates, `A V` ((n·rows) × r).
    av: DMatrix<f64>,
    /// Whitened rows `A T` ((n·rows) × r).
    b: DMatrix<f64>,
    aliased: Vec<bool>,
}

fn subspace(design: &Design) -> Result<Subspace, PlanError> {
    let a = &design.a;
    let n_e = a.ncols();
    let info = a.tr_mul(a);
    let scale: Vec<f64> = (0..n_e)
        .map(|j| {
            let d = info[(j, j)].sqrt();
            if d > 0.0 {
                1.0 / d
            } else {
                1.0
            }
        })
        .collect();
    let d = DMatrix::from_diagonal(&DVector::from_vec(scale));
    let eq = &d * &info * &d;
    let eigen = SymmetricEigen::new(eq);
    let max = eigen.eigenvalues.iter().copied().fold(0.0, f64::max);
    if max <= 0.0 {
        return Err(PlanError::Uninformative);
    }
    let keep: Vec<usize> = (0..n_e)
        .filter(|&k| eigen.eigenvalues[k] > RANK_TOLERANCE * max)
        .collect();
    let null: Vec<usize> = (0..n_e).filter(|k| !keep.contains(k)).collect();
    let rank = keep.len();
    let mut t = DMatrix::zeros(n_e, rank);
    for (c, &k) in keep.iter().enumerate() {
        let s = eigen.eigenvalues[k].sqrt();
        for j in 0..n_e {
            t[(j, c)] = d[(j, j)] * eigen.eigenvectors[(j, k)] / s;
        }
    }
    // The null space of A is Dₛ times the equilibrated one's; V is an
    // orthonormal basis of its orthogonal complement (the eigenvectors of
    // I − QQᵀ of eigenvalue 1).
    let mut aliased = vec![false; n_e];
    let v = if null.is_empty() {
        DMatrix::identity(n_e, n_e)
    } else {
        let mut z = DMatrix::zeros(n_e, null.len());
        for (c, &k) in null.iter().enumerate() {
            for j in 0..n_e {
                z[(j, c)] = d[(j, j)] * eigen.eigenvectors[(j, k)];
            }
        }
        let q = z.qr().q();
        for (j, flag) in aliased.iter_mut().enumerate() {
            *flag = q.row(j).norm() > 1e-9;
        }
        let p = DMatrix::identity(n_e, n_e) - &q * q.transpose();
        let pe = SymmetricEigen::new(p);
        let cols: Vec<usize> = (0..n_e).filter(|&k| pe.eigenvalues[k] > 0.5).collect();
        DMatrix::from_fn(n_e, cols.len(), |j, c| pe.eigenvectors[(j, cols[c])])
    };
    let av = a * &v;
    let b = a * &t;
    Ok(Subspace {
        rank,
        v,
        av,
        b,
        aliased,
    })
}

/// `ln det` of a symmetric positive definite matrix (`None` otherwise).
fn log_det(m: &DMatrix<f64>) -> Option<f64> {
    let c = m.clone().cholesky()?;
    let l = c.l_dirty();
    let mut s = 0.0;
    for k in 0..m.nrows() {
        let x = l[(k, k)];
        if !(x > 0.0) {
            return None;
        }
        s += 2.0 * x.ln();
    }
    Some(s)
}

impl Subspace {
    /// The whitened information of a subset, `Tᵀ A_Sᵀ A_S T`.
    fn info(&self, rows: usize, chosen: &[usize]) -> DMatrix<f64> {
        let mut g = DMatrix::zeros(self.rank, self.rank);
        for &i in chosen {
            let block = self.b.rows(rows * i, rows);
            g += block.tr_mul(&block);
        }
        g
    }

    fn subset(&self, rows: usize, mut chosen: Vec<usize>) -> Subset {
        chosen.sort_unstable();
        let n_e = self.v.nrows();
        // Regular when the whitened information's smallest eigenvalue is not
        // negligible against its largest (whitened, the whole candidate
        // set's information is I).
        let g = self.info(rows, &chosen);
        let eig = SymmetricEigen::new(g);
        let max = eig.eigenvalues.iter().copied().fold(0.0, f64::max);
        let min = eig
            .eigenvalues
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min);
        let regular = self.rank > 0 && min > 1e-12 * max.max(f64::MIN_POSITIVE);
        // Vᵀ M_S V, its log det and inverse.
        let mut h = DMatrix::zeros(self.rank, self.rank);
        for &i in &chosen {
            let block = self.av.rows(rows * i, rows);
            h += block.tr_mul(&block);
        }
        let ld = if regular { log_det(&h) } else { None };
        match ld.and_then(|ld| h.cholesky().map(|c| (ld, c))) {
            Some((ld, c)) => {
                let x = c.solve(&self.v.transpose()); // (Vᵀ M_S V)⁻¹ Vᵀ, r × N
                let std = (0..n_e)
                    .map(|j| Some(self.v.row(j).dot(&x.column(j).transpose()).max(0.0).sqrt()))
                    .collect();
                Subset {
                    candidates: chosen,
                    log_det: Some(ld),
                    std,
                }
            }
            None => Subset {
                candidates: chosen,
                log_det: None,
                std: vec![None; n_e],
            },
        }
    }
}

/// The `K` evenly taken candidates of `n`: `⌊k·n/K⌋`, k = 0..K−1.
pub fn even(n: usize, count: usize) -> Vec<usize> {
    (0..count).map(|k| k * n / count).collect()
}

/// Chooses `count` candidates of `design` maximising `det(AᵀA)` on the
/// identifiable subspace (greedy, then Fedorov exchange to a local optimum),
/// and reports them against the even spread of the same count.
pub fn plan(design: &Design, count: usize) -> Result<Plan, PlanError> {
    let n = design.len();
    if n == 0 {
        return Err(PlanError::NoCandidates);
    }
    if count == 0 || count > n {
        return Err(PlanError::Count {
            count,
            candidates: n,
        });
    }
    let rows = design.kind.rows();
    let sub = subspace(design)?;
    let r = sub.rank;
    if count * rows < r {
        return Err(PlanError::TooFew {
            count,
            rows: count * rows,
            rank: r,
            minimum: r.div_ceil(rows),
        });
    }
    let search = Search::new(&sub.b, rows, n, count);
    let (chosen, swaps, sweeps) = search.run(count)?;
    let optimal = sub.subset(rows, chosen);
    if optimal.log_det.is_none() {
        return Err(PlanError::Singular { count });
    }
    let even = sub.subset(rows, even(n, count));
    Ok(Plan {
        kind: design.kind,
        candidates: n,
        count,
        errors: design.errors.clone(),
        rank: r,
        aliased: sub.aliased.clone(),
        optimal,
        even,
        swaps,
        sweeps,
    })
}

/// The greedy and exchange search in whitened coordinates.
struct Search<'b> {
    b: &'b DMatrix<f64>,
    rows: usize,
    n: usize,
    /// `M⁻¹` (r × r).
    m_inv: DMatrix<f64>,
    /// `B M⁻¹` for every candidate ((n·rows) × r).
    z: DMatrix<f64>,
    ridge: f64,
}

/// A `rows × rows` block embedded in a 6 × 6 identity.
fn small(rows: usize, f: impl Fn(usize, usize) -> f64) -> Matrix6<f64> {
    let mut m = Matrix6::identity();
    for i in 0..rows {
        for j in 0..rows {
            m[(i, j)] = f(i, j);
        }
    }
    m
}

impl<'b> Search<'b> {
    fn new(b: &'b DMatrix<f64>, rows: usize, n: usize, count: usize) -> Search<'b> {
        let r = b.ncols();
        let ridge = RIDGE * count as f64 / n as f64;
        let m_inv = DMatrix::identity(r, r) / ridge;
        let z = b / ridge;
        Search {
            b,
            rows,
            n,
            m_inv,
            z,
            ridge,
        }
    }

    /// `B_j M⁻¹ B_kᵀ` (rows × rows, embedded).
    fn cross(&self, j: usize, k: usize, sign: f64) -> Matrix6<f64> {
        let (rows, r) = (self.rows, self.b.ncols());
        let mut m = Matrix6::zeros();
        for a in 0..rows {
            let zr = self.z.row(rows * j + a);
            for c in 0..rows {
                let br = self.b.row(rows * k + c);
                let mut s = 0.0;
                for x in 0..r {
                    s += zr[x] * br[x];
                }
                m[(a, c)] = sign * s;
            }
        }
        m
    }

    /// `M ← M + σ B_jᵀ B_j` (σ = ±1): Woodbury on `M⁻¹` and `Z = B M⁻¹`.
    fn update(&mut self, j: usize, sigma: f64) {
        let rows = self.rows;
        let bj = self.b.rows(rows * j, rows).into_owned();
        let zj = self.z.rows(rows * j, rows).into_owned(); // B_j M⁻¹
                                                           // (σ⁻¹ I + B_j M⁻¹ B_jᵀ)⁻¹
        let mut core = &zj * bj.transpose();
        for k in 0..rows {
            core[(k, k)] += sigma;
        }
        let Some(core_inv) = core.try_inverse() else {
            return;
        };
        // M⁻¹ ← M⁻¹ − (M⁻¹B_jᵀ) core⁻¹ (B_j M⁻¹)
        let left = zj.transpose() * &core_inv; // r × rows
        self.m_inv -= &left * &zj;
        // Z ← Z − (Z B_jᵀ) core⁻¹ (B_j M⁻¹)
        let zb = &self.z * bj.transpose(); // (n·rows) × rows
        self.z -= zb * core_inv * zj;
    }

    fn run(mut self, count: usize) -> Result<(Vec<usize>, usize, usize), PlanError> {
        let rows = self.rows;
        let mut chosen: Vec<usize> = Vec::with_capacity(count);
        let mut in_set = vec![false; self.n];
        for _ in 0..count {
            let mut best = (f64::NEG_INFINITY, usize::MAX);
            for j in (0..self.n).filter(|&j| !in_set[j]) {
                let h = self.cross(j, j, 1.0);
                let g = small(rows, |a, c| h[(a, c)] + if a == c { 1.0 } else { 0.0 });
                let det = g.determinant();
                if det > best.0 {
                    best = (det, j);
                }
            }
            let j = best.1;
            if j == usize::MAX {
                return Err(PlanError::Singular { count });
            }
            chosen.push(j);
            in_set[j] = true;
            self.update(j, 1.0);
        }
        // The exchange, on the same information `M_S + εI` (the ridge is
        // 10⁻⁹ of an average candidate's share: it decides nothing but
        // keeps an uninformed start invertible).
        let mut swaps = 0;
        let mut sweeps = 0;
        loop {
            sweeps += 1;
            let mut swapped = false;
            for slot in 0..count {
                let i = chosen[slot];
                let hii = self.cross(i, i, 1.0);
                let mut best = (1.0 + SWAP_GAIN, usize::MAX);
                for j in (0..self.n).filter(|&j| !in_set[j]) {
                    let hjj = self.cross(j, j, 1.0);
                    let cji = self.cross(j, i, 1.0);
                    let mut m = Matrix6::zeros();
                    for a in 0..rows {
                        for c in 0..rows {
                            m[(a, c)] = hjj[(a, c)] + if a == c { 1.0 } else { 0.0 };
                            m[(a, rows + c)] = cji[(a, c)];
                            m[(rows + a, c)] = -cji[(c, a)];
                            m[(rows + a, rows + c)] = -hii[(a, c)] + if a == c { 1.0 } else { 0.0 };
                        }
                    }
                    for k in 2 * rows..6 {
                        m[(k, k)] = 1.0;
                    }
                    let det = m.determinant();
                    if det > best.0 {
                        best = (det, j);
                    }
                }
                if best.1 != usize::MAX {
                    let j = best.1;
                    self.update(j, 1.0);
                    self.update(i, -1.0);
                    in_set[i] = false;
                    in_set[j] = true;
                    chosen[slot] = j;
                    swaps += 1;
                    swapped = true;
                }
            }
            if !swapped || sweeps >= MAX_SWEEPS {
                break;
            }
            // Refresh M⁻¹ and Z from the chosen rows (no drift).
            self.refresh(&chosen);
        }
        Ok((chosen, swaps, sweeps))
    }

    /// `M⁻¹` and `Z` recomputed from the chosen rows.
    fn refresh(&mut self, chosen: &[usize]) {
        let r = self.b.ncols();
        let mut m = DMatrix::identity(r, r) * self.ridge;
        for &i in chosen {
            let block = self.b.rows(self.rows * i, self.rows);
            m += block.tr_mul(&block);
        }
        if let Some(c) = m.cholesky() {
            self.m_inv = c.inverse();
            self.z = self.b * &self.m_inv;
        }
    }
}
