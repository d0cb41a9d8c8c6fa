//! Measurement planning: where to measure (measured-machines spec, section 5;
//! `docs/plan.md`).
//!
//! The exact sensitivity rows of a machine are the design matrix of its
//! calibration (spec section 4): a tool-point measurement at a pose gives the
//! three rows `px, py, pz` of `S(q, p)`; a 1-D measurement along a unit
//! direction `u` gives the one row `u · (px, py, pz)`. The candidates are
//! read and their rows built by `chain identify`'s own mechanism
//! ([`crate::measured::Measurements`] with
//! [`crate::measured::Layout::Candidates`], [`crate::measured::Design`]);
//! [`Rows`] holds them (weighted by `1/std` when the candidates have a std),
//! and [`plan`] chooses `K` candidates that maximise the information
//! `det(AᵀA)` on the identifiable subspace (D-optimal design), and compares
//! the choice with `K` candidates taken evenly.
//!
//! # The identifiable subspace
//!
//! The identifiable subspace is the row space of the whole candidate matrix
//! `A` (the span of its right singular vectors with non-negligible singular
//! values). The rank is decided on the column-equilibrated information
//! `Dₛ AᵀA Dₛ` (`Dₛ = diag(1/‖a_j‖)`, so that a linear error in mm and an
//! angular one in rad weigh alike), by `identify`'s rule (one spectrum
//! function for both): singular values above [`RANK_TOLERANCE`] times the
//! largest count. With `Vₛ, Λₛ` the retained eigenpairs, the
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
//! candidate with the largest `det(I + H_j)`, `H_j = B_j M⁻¹ B_jᵀ` (the
//! matrix determinant lemma), updating `M⁻¹` by Woodbury's identity and
//! every `H_l` by the rank-k term `G_l (I + H_j)⁻¹ G_lᵀ`,
//! `G = B M⁻¹ B_jᵀ` (one thin product per step, `O(m·r·k)`). Then Fedorov's
//! exchange (Fedorov 1972; Cook & Nachtsheim 1980's sequential form): for
//! each chosen candidate `i` in turn, the best unchosen `j` by
//!
//! ```text
//! det(M − B_iᵀB_i + B_jᵀB_j) / det(M) = det [ I + B_j M⁻¹ B_jᵀ    B_j M⁻¹ B_iᵀ ]
//!                                           [ −B_i M⁻¹ B_jᵀ     I − B_i M⁻¹ B_iᵀ ]
//!     = det(I − H_i) · det(I + H_j + C_ji (I − H_i)⁻¹ C_jiᵀ)
//! ```
//!
//! (the determinant lemma for the rank-2k update `Uᵀ Σ U`, `U = [B_j; B_i]`,
//! `Σ = diag(I, −I)`, then the Schur complement of `I − H_i`), with the
//! `H_j` and the cross terms `C = B M⁻¹ B_Sᵀ` (one gemm) kept from the
//! last refresh and updated by Woodbury after each accepted swap
//! (`X M⁻¹ Yᵀ ← X M⁻¹ Yᵀ − (X M⁻¹ Uᵀ) W (U M⁻¹ Yᵀ)`,
//! `W = (Σ + U M⁻¹ Uᵀ)⁻¹`): an evaluation costs `O(k³)`, a swap
//! `O(m·(r + K)·k)`. A swap is taken when it improves the determinant by
//! more than [`SWAP_GAIN`]; the search ends when a whole sweep on state
//! recomputed from the chosen rows (Cholesky, no drift) swaps nothing: then
//! no single swap improves the design by more than that factor (a local
//! optimum).
//!
//! # Expected standard deviations
//!
//! Per unit measurement std, each parameter's std of the minimum-norm
//! estimate (spec section 4) is `sqrt((M_S⁺)_jj)` with the pseudo-inverse
//! `M_S⁺ = V (Vᵀ M_S V)⁻¹ Vᵀ`; with full rank, `(AᵀA)⁻¹`.

use nalgebra::{DMatrix, Matrix3, Matrix3x6, Matrix6, SymmetricEigen};
use serde::Serialize;

use crate::measured::identify::{gram, spectrum};
use crate::measured::{Design, DesignError, Measurement};
use crate::model::Machine;
use crate::model_trait::ErrorModel;

/// The rank rule is `identify`'s: singular values of the equilibrated
/// design below this fraction of the largest are taken as zero.
pub use crate::measured::identify::RANK_TOLERANCE;

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

/// Why a plan cannot be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[cfg_attr(feature = "miette", derive(miette::Diagnostic))]
#[non_exhaustive]
pub enum PlanError {
    /// No candidate.
    #[error("there is no candidate")]
    NoCandidates,
    /// `K` is zero or above the candidate count.
    #[error("{count} is not a count of the {candidates} candidates: choose 1 to {candidates}")]
    Count {
        /// The count asked for.
        count: usize,
        /// The candidates given.
        candidates: usize,
    },
    /// `K` candidates cannot inform the identifiable subspace.
    #[error("{count} candidates give {rows} design rows, fewer than the {rank} dimensions the candidates can identify; choose {minimum} candidates or more")]
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
    /// The candidates' design could not be built (`measured::Design`).
    #[error(transparent)]
    Design(#[from] DesignError),
    /// The candidates do not all give the same number of design rows.
    #[error("candidate {index} gives {found} design rows, candidate 0 gives {expected}: plan points and directions separately")]
    MixedRows {
        /// The candidate (0-based).
        index: usize,
        /// Its rows.
        found: usize,
        /// The first candidate's rows.
        expected: usize,
    },
    /// A row matrix that is not whole candidates of 1 to 3 rows.
    #[error("{rows} design rows of {per} per candidate: a candidate has 1 to 3 rows and the rows are whole candidates")]
    RowsPerCandidate {
        /// The matrix's rows.
        rows: usize,
        /// Rows per candidate asked for.
        per: usize,
    },
    /// A row matrix whose columns are not the error names.
    #[error("{columns} design columns for {errors} error names")]
    Columns {
        /// The matrix's columns.
        columns: usize,
        /// The names given.
        errors: usize,
    },
    /// A design row with a non-finite entry.
    #[error("candidate {index}: a design row is not finite")]
    NonFinite {
        /// The candidate (0-based).
        index: usize,
    },
    /// No subset of the asked size gives a non-singular information.
    #[error("no {count} of the candidates found inform every identifiable direction")]
    Singular {
        /// The count asked for.
        count: usize,
    },
}

/// The design rows of every candidate: `per` consecutive rows a candidate
/// (3 for a tool-point measurement, 1 for one along a direction), weighted
/// by `1/std` when the candidates have a standard deviation.
#[derive(Debug, Clone, PartialEq)]
pub struct Rows {
    per: usize,
    weighted: bool,
    errors: Vec<String>,
    /// `(n · per) × N`, candidate `i`'s rows at `per·i ..`.
    a: DMatrix<f64>,
}

impl Rows {
    /// Rows already computed: `a` is `(n · per) × N`, one column per error
    /// name, `per` in 1..=3; `weighted` says the rows are already divided by
    /// their measurement std (the reported std are then absolute).
    pub fn new(
        per: usize,
        errors: Vec<String>,
        a: DMatrix<f64>,
        weighted: bool,
    ) -> Result<Rows, PlanError> {
        if !(1..=3).contains(&per) || a.nrows() % per != 0 {
            return Err(PlanError::RowsPerCandidate {
                rows: a.nrows(),
                per,
            });
        }
        if a.ncols() != errors.len() {
            return Err(PlanError::Columns {
                columns: a.ncols(),
                errors: errors.len(),
            });
        }
        if let Some(i) = (0..a.nrows()).find(|&i| !a.row(i).iter().all(|x| x.is_finite())) {
            return Err(PlanError::NonFinite { index: i / per });
        }
        Ok(Rows {
            per,
            weighted,
            errors,
            a,
        })
    }

    /// The rows of a candidate design built by [`crate::measured::Design`]
    /// (the one row rule of `chain identify`: `S_p` for a point, `uᵀ S_p`
    /// along a direction), each row divided by its record's std when the
    /// records have one (weighted D-optimality: the information is
    /// `AᵀWA`, `W = diag(1/std²)`, spec section 4).
    pub fn from_design(design: &Design) -> Result<Rows, PlanError> {
        // Rows per record, from each row's record index.
        let mut counts: Vec<usize> = Vec::new();
        for &(record, _) in &design.origin {
            if counts.len() <= record {
                counts.resize(record + 1, 0);
            }
            counts[record] += 1;
        }
        let Some(&per) = counts.first() else {
            return Err(PlanError::NoCandidates);
        };
        if let Some((index, &found)) = counts.iter().enumerate().find(|(_, &c)| c != per) {
            return Err(PlanError::MixedRows {
                index,
                found,
                expected: per,
            });
        }
        let mut a = design.a.clone();
        if let Some(std) = &design.std {
            for (i, s) in std.iter().enumerate() {
                a.row_mut(i).scale_mut(1.0 / s);
            }
        }
        Rows::new(per, design.errors.clone(), a, design.std.is_some())
    }

    /// The rows of candidate records (in `machine`'s orders, as
    /// [`crate::measured::Measurements`] reads them with
    /// [`crate::measured::Layout::Candidates`]) through `model`'s exact
    /// sensitivity: [`Design::new`] then [`Rows::from_design`].
    pub fn of<M: ErrorModel + ?Sized>(
        model: &M,
        machine: &Machine,
        records: &[Measurement],
    ) -> Result<Rows, PlanError> {
        Rows::from_design(&Design::new(model, machine, records)?)
    }

    /// The number of candidates.
    pub fn len(&self) -> usize {
        self.a.nrows() / self.per
    }

    /// Whether there is no candidate.
    pub fn is_empty(&self) -> bool {
        self.a.nrows() == 0
    }

    /// Design rows per candidate (3 for a point, 1 for a direction).
    pub fn per_candidate(&self) -> usize {
        self.per
    }

    /// Whether the rows are weighted by `1/std`.
    pub fn weighted(&self) -> bool {
        self.weighted
    }

    /// The design rows, candidate `i`'s at `per · i ..`.
    pub fn matrix(&self) -> &DMatrix<f64> {
        &self.a
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
    /// Design rows per candidate (3: a tool point, 1: along a direction).
    pub rows_per_candidate: usize,
    /// Whether the rows were weighted by `1/std` (the std below are then
    /// absolute, in the errors' units; else per unit measurement std).
    pub weighted: bool,
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
struct Subspace<'a> {
    rank: usize,
    /// `V` (N × r): an orthonormal basis of the identifiable subspace.
    v: DMatrix<f64>,
    /// The design rows (`A`, (n·rows) × N).
    a: &'a DMatrix<f64>,
    /// Whitened rows `A T` ((n·rows) × r).
    b: DMatrix<f64>,
    aliased: Vec<bool>,
}

fn subspace(design: &Rows) -> Result<Subspace<'_>, PlanError> {
    let a = &design.a;
    let n_e = a.ncols();
    // AᵀA over row blocks in parallel, and the rank rule of `identify`
    // (one spectrum for both).
    let spec = spectrum(&gram(a));
    if spec.rank == 0 {
        return Err(PlanError::Uninformative);
    }
    let rank = spec.rank;
    let d = &spec.d;
    let t = DMatrix::from_fn(n_e, rank, |j, c| {
        d[j] * spec.vectors[(j, c)] / spec.lambda[c].sqrt()
    });
    let null: Vec<usize> = (rank..n_e).collect();
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
                z[(j, c)] = d[j] * spec.vectors[(j, k)];
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
    let b = a * &t;
    Ok(Subspace {
        rank,
        v,
        a,
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
        if x.is_nan() || x <= 0.0 {
            return None;
        }
        s += 2.0 * x.ln();
    }
    Some(s)
}

impl Subspace<'_> {
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
        let mut a_s = DMatrix::zeros(chosen.len() * rows, self.a.ncols());
        for (t, &i) in chosen.iter().enumerate() {
            a_s.rows_mut(t * rows, rows)
                .copy_from(&self.a.rows(rows * i, rows));
        }
        let av = a_s * &self.v;
        let h = av.transpose() * &av;
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
pub fn plan(design: &Rows, count: usize) -> Result<Plan, PlanError> {
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
    let rows = design.per;
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
        rows_per_candidate: rows,
        weighted: design.weighted,
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

/// The greedy and exchange search in whitened coordinates `B` (m × r, `k`
/// rows a candidate, column-major). The state is `M⁻¹` (of
/// `M = εI + B_Sᵀ B_S`), every candidate's `H_l = B_l M⁻¹ B_lᵀ` (k × k, in
/// the top-left of a 3 × 3) and, in the exchange, the cross terms
/// `C = B M⁻¹ B_Sᵀ` (m × K·k, slot `s`'s columns at `k·s ..`), all kept
/// current by low-rank (Woodbury) updates after each accepted step, so a
/// step costs `O(m·r·k)` in thin products and an evaluation `O(k³)`.
struct Search<'b> {
    b: &'b DMatrix<f64>,
    k: usize,
    n: usize,
    ridge: f64,
    m_inv: DMatrix<f64>,
    h: Vec<Matrix3<f64>>,
    c: DMatrix<f64>,
}

/// The `k × k` block of `m` at `(r0, c0)`, in the top-left of a 3 × 3 of
/// zeros.
fn block(m: &DMatrix<f64>, r0: usize, c0: usize, k: usize) -> Matrix3<f64> {
    let (rows, data) = (m.nrows(), m.as_slice());
    let mut x = Matrix3::zeros();
    for col in 0..k {
        let src = &data[(c0 + col) * rows + r0..][..k];
        for (row, v) in src.iter().enumerate() {
            x[(row, col)] = *v;
        }
    }
    x
}

/// `I_k` in the top-left of a 3 × 3 of zeros.
fn eye(k: usize) -> Matrix3<f64> {
    Matrix3::from_fn(|a, c| if a == c && a < k { 1.0 } else { 0.0 })
}

/// `b · zᵀ` for a thin `z` (`t × r`, t ≤ 6): one pass over `b`'s columns
/// (nalgebra's generic product streams `b` once per column of the result
/// when a dimension is below its gemm threshold).
fn thin_product(b: &DMatrix<f64>, z: &DMatrix<f64>) -> DMatrix<f64> {
    if z.nrows() > 5 {
        return b * z.transpose();
    }
    let mut g = DMatrix::zeros(b.nrows(), z.nrows());
    for c in 0..b.ncols() {
        let col = b.column(c);
        for a in 0..z.nrows() {
            g.column_mut(a).axpy(z[(a, c)], &col, 1.0);
        }
    }
    g
}

impl<'b> Search<'b> {
    fn new(b: &'b DMatrix<f64>, k: usize, n: usize, count: usize) -> Search<'b> {
        let r = b.ncols();
        let ridge = RIDGE * count as f64 / n as f64;
        let mut h = vec![Matrix3::zeros(); n];
        // H_l = B_l B_lᵀ / ε, one pass over B's columns.
        for col in 0..r {
            let x = b.column(col);
            for (l, hl) in h.iter_mut().enumerate() {
                for c in 0..k {
                    let xc = x[k * l + c];
                    for a in 0..k {
                        hl[(a, c)] += x[k * l + a] * xc / ridge;
                    }
                }
            }
        }
        Search {
            b,
            k,
            n,
            ridge,
            m_inv: DMatrix::identity(r, r) / ridge,
            h,
            c: DMatrix::zeros(0, 0),
        }
    }

    /// The rows of candidates `list` stacked.
    fn stack(&self, list: &[usize]) -> DMatrix<f64> {
        let (k, r) = (self.k, self.b.ncols());
        let mut out = DMatrix::zeros(list.len() * k, r);
        for (t, &i) in list.iter().enumerate() {
            out.rows_mut(t * k, k).copy_from(&self.b.rows(i * k, k));
        }
        out
    }

    /// `M ← M + B_jᵀ B_j` (the greedy step): Woodbury on `M⁻¹`, the
    /// rank-k update `H_l ← H_l − G_l (I + H_j)⁻¹ G_lᵀ`,
    /// `G = B M⁻¹ B_jᵀ`.
    fn add(&mut self, j: usize) -> bool {
        let k = self.k;
        let z = self.stack(&[j]) * &self.m_inv; // B_j M⁻¹, k × r
        let g = thin_product(self.b, &z); // B M⁻¹ B_jᵀ, m × k
        let Some(core) = (Matrix3::identity() + block(&g, k * j, 0, k)).try_inverse() else {
            return false;
        };
        let core = core - (Matrix3::identity() - eye(k)); // k × k block only
        for (l, hl) in self.h.iter_mut().enumerate() {
            let gl = block(&g, k * l, 0, k);
            *hl -= gl * core * gl.transpose();
        }
        let core = DMatrix::from_fn(k, k, |a, c| core[(a, c)]);
        self.m_inv -= z.transpose() * core * z;
        true
    }

    /// `M⁻¹`, every `H_l` and the cross terms recomputed from the chosen
    /// rows (no drift).
    fn refresh(&mut self, chosen: &[usize]) -> bool {
        let (k, r) = (self.k, self.b.ncols());
        let bs = self.stack(chosen);
        let m = DMatrix::identity(r, r) * self.ridge + bs.transpose() * &bs;
        let Some(ch) = m.cholesky() else {
            return false;
        };
        self.m_inv = ch.inverse();
        let z = self.b * &self.m_inv; // B M⁻¹, m × r
        for hl in self.h.iter_mut() {
            *hl = Matrix3::zeros();
        }
        for col in 0..r {
            let (zc, bc) = (z.column(col), self.b.column(col));
            for (l, hl) in self.h.iter_mut().enumerate() {
                for c in 0..k {
                    let x = bc[k * l + c];
                    for a in 0..k {
                        hl[(a, c)] += zc[k * l + a] * x;
                    }
                }
            }
        }
        self.c = z * bs.transpose();
        true
    }

    /// The swap of slot `s` (candidate `i`) for candidate `j`:
    /// `M ← M + B_jᵀB_j − B_iᵀB_i`, with `U = [B_j; B_i]`,
    /// `Σ = diag(I, −I)`, `W = (Σ + U M⁻¹ Uᵀ)⁻¹`:
    /// `M⁻¹ ← M⁻¹ − M⁻¹Uᵀ W U M⁻¹` (Woodbury), so for any rows `X, Y`,
    /// `X M⁻¹ Yᵀ ← X M⁻¹ Yᵀ − (X M⁻¹ Uᵀ) W (U M⁻¹ Yᵀ)`.
    fn swap(&mut self, s: usize, i: usize, j: usize) -> bool {
        let k = self.k;
        let zu = self.stack(&[j, i]) * &self.m_inv; // U M⁻¹, 2k × r
        let g = thin_product(self.b, &zu); // B M⁻¹ Uᵀ, m × 2k
        let mut umu = DMatrix::zeros(2 * k, 2 * k);
        for t in 0..2 * k {
            let row = if t < k { k * j + t } else { k * i + t - k };
            umu.row_mut(t).copy_from(&g.row(row));
        }
        let mut sigma = umu.clone();
        for t in 0..2 * k {
            sigma[(t, t)] += if t < k { 1.0 } else { -1.0 };
        }
        let Some(w) = sigma.try_inverse() else {
            return false;
        };
        // H_l ← H_l − G_l W G_lᵀ (fixed-size, zero-padded to 3 × 6).
        let w6 = Matrix6::from_fn(|a, c| {
            if a < 2 * k && c < 2 * k {
                w[(a, c)]
            } else {
                0.0
            }
        });
        let (m, gs) = (g.nrows(), g.as_slice());
        for (l, hl) in self.h.iter_mut().enumerate() {
            let mut gl = Matrix3x6::zeros();
            for c in 0..2 * k {
                for a in 0..k {
                    gl[(a, c)] = gs[c * m + k * l + a];
                }
            }
            *hl -= gl * w6 * gl.transpose();
        }
        // C ← C − G W (U M⁻¹ B_Sᵀ); slot s's columns become B M'⁻¹ B_jᵀ.
        let mut us = DMatrix::zeros(2 * k, self.c.ncols());
        for t in 0..2 * k {
            let row = if t < k { k * j + t } else { k * i + t - k };
            us.row_mut(t).copy_from(&self.c.row(row));
        }
        let new_j = g.columns(0, k) - &g * (&w * umu.columns(0, k));
        // In place (one gemm; a temporary of C's size would cost more in
        // page faults than the product).
        self.c.gemm(-1.0, &g, &(&w * us), 1.0);
        self.c.columns_mut(k * s, k).copy_from(&new_j);
        self.m_inv -= zu.transpose() * &w * zu;
        true
    }

    fn run(mut self, count: usize) -> Result<(Vec<usize>, usize, usize), PlanError> {
        let k = self.k;
        let id = Matrix3::identity();
        let mut chosen: Vec<usize> = Vec::with_capacity(count);
        let mut in_set = vec![false; self.n];
        // Greedy: the largest det(I + H_j) (the matrix determinant lemma).
        for _ in 0..count {
            let mut best = (f64::NEG_INFINITY, usize::MAX);
            for j in (0..self.n).filter(|&j| !in_set[j]) {
                let det = (id + self.h[j]).determinant();
                if det > best.0 {
                    best = (det, j);
                }
            }
            let j = best.1;
            if j == usize::MAX || !self.add(j) {
                return Err(PlanError::Singular { count });
            }
            chosen.push(j);
            in_set[j] = true;
        }
        // The exchange, on the same information `M_S + εI` (the ridge is
        // 10⁻⁹ of an average candidate's share: it decides nothing but
        // keeps an uninformed start invertible), from exact state.
        if !self.refresh(&chosen) {
            return Err(PlanError::Singular { count });
        }
        let mut swaps = 0;
        let mut sweeps = 0;
        // Whether the state is exact (just refreshed) or carried through
        // Woodbury updates.
        let mut fresh = true;
        loop {
            sweeps += 1;
            let mut swapped = false;
            // `chosen[slot]` is replaced inside the loop.
            #[allow(clippy::needless_range_loop)]
            for slot in 0..count {
                let i = chosen[slot];
                // det [I + H_j, C_ji; −C_ij, I − H_i]
                //   = det(I − H_i) · det(I + H_j + C_ji (I − H_i)⁻¹ C_ij).
                let d = id - self.h[i];
                let det_d = d.determinant();
                let Some(p) = d.try_inverse().filter(|_| det_d > 0.0) else {
                    continue;
                };
                let mut best = (1.0 + SWAP_GAIN, usize::MAX);
                for j in (0..self.n).filter(|&j| !in_set[j]) {
                    let x = block(&self.c, k * j, k * slot, k); // B_j M⁻¹ B_iᵀ
                    let det = det_d * (id + self.h[j] + x * p * x.transpose()).determinant();
                    if det > best.0 {
                        best = (det, j);
                    }
                }
                if best.1 != usize::MAX && self.swap(slot, i, best.1) {
                    let j = best.1;
                    in_set[i] = false;
                    in_set[j] = true;
                    chosen[slot] = j;
                    swaps += 1;
                    swapped = true;
                }
            }
            if sweeps >= MAX_SWEEPS || (!swapped && fresh) {
                break;
            }
            if !swapped {
                // A sweep without a swap on updated state: confirm it on
                // state recomputed from the chosen rows (no drift) before
                // calling the design a local optimum.
                if !self.refresh(&chosen) {
                    return Err(PlanError::Singular { count });
                }
                fresh = true;
            } else {
                fresh = false;
            }
        }
        Ok((chosen, swaps, sweeps))
    }
}

// ---------------------------------------------------------------------------
// What the candidates measure.

/// What each candidate measures: the measurement kind of `chain identify`
/// (`point`, three rows per candidate; `direction`, one row along the
/// candidate's `ux, uy, uz`).
pub use crate::measured::MeasurementKind as Kind;

/// A measurement kind asked for that the candidate file contradicts.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[cfg_attr(feature = "miette", derive(miette::Diagnostic))]
pub enum KindError {
    /// Point asked for, the file has directions.
    #[error(
        "{file}:1: columns `ux,uy,uz` give directions, but point measurements measure px, py, pz"
    )]
    PointWithDirections {
        /// The candidate file.
        file: String,
    },
    /// Direction asked for, the file has none.
    #[error("{file}:1: direction measurements need the columns `ux,uy,uz` (the unit direction of each measurement)")]
    DirectionWithout {
        /// The candidate file.
        file: String,
    },
}

impl Kind {
    /// What the candidates of `file` measure (`ux,uy,uz` present: every row
    /// a direction), checked against the kind `asked` for. `None` when there
    /// is no candidate.
    pub fn of(
        candidates: &crate::measured::Measurements,
        asked: Option<Kind>,
    ) -> Result<Option<Kind>, KindError> {
        let Some(first) = candidates.rows.first() else {
            return Ok(None);
        };
        let kind = first.observed.kind();
        let file = candidates.file.clone();
        match (asked, kind) {
            (None, _)
            | (Some(Kind::Point), Kind::Point)
            | (Some(Kind::Direction), Kind::Direction) => Ok(Some(kind)),
            (Some(Kind::Point), Kind::Direction) => Err(KindError::PointWithDirections { file }),
            (Some(Kind::Direction), Kind::Point) => Err(KindError::DirectionWithout { file }),
        }
    }
}
