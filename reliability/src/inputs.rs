//! The random inputs of an event: one marginal distribution per error
//! parameter and the transformation to independent standard normal space.
//!
//! FORM, the importance sampling and the sensitivities all work in the
//! standard normal space `U` of the paper's Section 3.1 ("transforming basic
//! random variable X space into independent standard normal random variable Y
//! space"). [`Inputs`] owns that transformation `x = T(u)`: callers only use
//! [`Inputs::to_physical`], [`Inputs::jacobian`] and the parameter
//! derivatives, so adding marginals (lognormal, truncated normal) or a
//! correlation (Nataf: `u → L·u → Φ → F⁻¹`) changes this file and
//! `marginal.rs` only.
//!
//! Correlated normal inputs (the posterior of a calibration,
//! `docs/posterior.md`) are one block `B` of normal inputs with correlation
//! matrix `R` (positive definite, its lower Cholesky factor `L`, `R = L·Lᵀ`):
//! `x_B = μ_B + D_B·L·u_B`, `D_B = diag(σ_B)`, so that
//! `Cov(x_B) = D_B·R·D_B = Σ_B` (the map `x = μ + L_Σ·u` with `L_Σ = D_B·L`
//! the Cholesky factor of `Σ_B`). The other inputs keep their own marginal,
//! independent of the block and of each other. The map stays affine, so
//! FORM's closed form, the affine sampling kernels and the exact
//! sensitivities apply unchanged through [`Inputs::project`].

use serde::Serialize;

use crate::error::ReliabilityError;
use crate::rng::CaseRng;

pub use crate::marginal::{Family, Marginal};

/// The joint distribution of the inputs: named marginals, independent
/// except for one optional block of correlated normals
/// ([`Inputs::correlated`]).
///
/// ```
/// use reliability::{Inputs, Marginal};
/// let inputs = Inputs::new(
///     vec!["a".into(), "b".into()],
///     vec![Marginal::normal(0.0, 2.0).unwrap(), Marginal::uniform(-1.0, 1.0).unwrap()],
/// ).unwrap();
/// let mut x = [0.0; 2];
/// inputs.to_physical(&[1.0, 0.0], &mut x);
/// assert_eq!(x, [2.0, 0.0]);
/// ```
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Inputs {
    names: Vec<String>,
    marginals: Vec<Marginal>,
    all_normal: bool,
    #[serde(skip)]
    means: Vec<f64>,
    #[serde(skip)]
    stds: Vec<f64>,
    /// The correlated normal block, if any (serialised as its pairs).
    #[serde(skip_serializing_if = "Option::is_none")]
    correlation: Option<Block>,
}

/// One correlation coefficient between two inputs (by index).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Correlation {
    /// The first input.
    pub a: usize,
    /// The second input.
    pub b: usize,
    /// `ρ_ab`, in `(−1, 1)`.
    pub rho: f64,
}

/// The lower Cholesky factor of the `k × k` row-major `r`, or the
/// `(row, column)` of the given pair that makes it fail: the pivot of `row`
/// is not positive, named by its largest given coefficient `column < row`.
fn cholesky(r: &[f64], k: usize) -> Result<Vec<f64>, (usize, usize)> {
    let mut l = vec![0.0; k * k];
    for i in 0..k {
        for j in 0..=i {
            let dot: f64 = (0..j).map(|c| l[i * k + c] * l[j * k + c]).sum();
            if i == j {
                let d = r[i * k + i] - dot;
                if d.is_nan() || d <= 1e-14 {
                    let col = (0..i)
                        .max_by(|&a, &b| r[i * k + a].abs().total_cmp(&r[i * k + b].abs()))
                        .unwrap_or(0);
                    return Err((i, col));
                }
                l[i * k + i] = d.sqrt();
            } else {
                l[i * k + j] = (r[i * k + j] - dot) / l[j * k + j];
            }
        }
    }
    Ok(l)
}

/// The correlated block of an [`Inputs`]: `x_i = F_i⁻¹(Φ(z_i))`, `z = L·u_B`
/// (for normal members `x_B = μ_B + D_B·L·u_B`).
#[derive(Debug, Clone, PartialEq, Serialize)]
struct Block {
    /// The coefficients as given (serialised).
    pairs: Vec<Correlation>,
    /// The inputs of the block, ascending.
    #[serde(skip)]
    members: Vec<usize>,
    /// Per input, its position in `members`.
    #[serde(skip)]
    position: Vec<Option<usize>>,
    /// `R`, `k × k` row-major: the physical (Pearson) correlations.
    #[serde(skip)]
    matrix: Vec<f64>,
    /// `R₀`, the Nataf-adjusted correlations of the normal images
    /// (`crate::nataf`; `R₀ = R` when every member is normal).
    #[serde(skip)]
    adjusted: Vec<f64>,
    /// The lower Cholesky factor `L` of `R₀`, `k × k` row-major (zero above
    /// the diagonal).
    #[serde(skip)]
    factor: Vec<f64>,
}

impl Block {
    /// `z_i = Σ_{k ≤ i} L_ik·u_{m_k}`: the standardised correlated
    /// coordinate of member `i`.
    #[inline]
    fn z(&self, i: usize, u: &[f64]) -> f64 {
        let k = self.members.len();
        let row = &self.factor[i * k..i * k + i + 1];
        row.iter().zip(&self.members).map(|(l, &m)| l * u[m]).sum()
    }
}

impl Inputs {
    /// Independent inputs with the given names and marginals.
    pub fn new(names: Vec<String>, marginals: Vec<Marginal>) -> Result<Inputs, ReliabilityError> {
        if names.len() != marginals.len() {
            return Err(ReliabilityError::Dimension {
                what: "input names",
                expected: marginals.len(),
                found: names.len(),
            });
        }
        let all_normal = marginals.iter().all(Marginal::is_normal);
        let means = marginals.iter().map(Marginal::mean).collect();
        let stds = marginals.iter().map(Marginal::std).collect();
        Ok(Inputs {
            names,
            marginals,
            all_normal,
            means,
            stds,
            correlation: None,
        })
    }

    /// Inputs with the given marginals and physical (Pearson) correlation
    /// coefficients: the inputs named in `pairs` form one correlated block,
    /// the Nataf model `x_i = F_i⁻¹(Φ(z_i))`, `z_B = L·u_B`, `R₀ = L·Lᵀ` the
    /// adjusted correlations of [`crate::nataf::adjusted_correlation`]
    /// (`reliability-v2.md` §2; for normal members `x_B = μ_B + D_B·L·u_B`,
    /// module docs). Every other input stays independent; pairs not listed
    /// within the block are uncorrelated.
    ///
    /// Refused ([`ReliabilityError::InvalidDistribution`]): a pair naming an
    /// input out of range or an input with itself, a fixed input
    /// ([`Marginal::fixed`]), a pair given twice, a
    /// non-finite `ρ` or `|ρ| ≥ 1`, a `ρ` the two marginals cannot attain,
    /// and an adjusted matrix that is not positive definite (its smallest
    /// eigenvalue and the pair where the factorisation fails are named). No
    /// pairs give [`Inputs::new`]'s inputs.
    ///
    /// ```
    /// use reliability::{Inputs, Marginal};
    /// use reliability::inputs::Correlation;
    /// let m = |s| Marginal::normal(0.0, s).unwrap();
    /// let names = vec!["a".into(), "b".into()];
    /// let inputs = Inputs::correlated(names.clone(), vec![m(2.0), m(1.0)],
    ///     &[Correlation { a: 0, b: 1, rho: 0.6 }]).unwrap();
    /// let mut x = [0.0; 2];
    /// inputs.to_physical(&[1.0, 1.0], &mut x);
    /// // x_b = σ_b·(ρ·u_a + √(1 − ρ²)·u_b)
    /// assert!((x[0] - 2.0).abs() < 1e-15 && (x[1] - 1.4).abs() < 1e-15);
    /// let bad = [Correlation { a: 0, b: 1, rho: 1.0 }];
    /// assert!(Inputs::correlated(names, vec![m(2.0), m(1.0)], &bad).is_err());
    /// ```
    pub fn correlated(
        names: Vec<String>,
        marginals: Vec<Marginal>,
        pairs: &[Correlation],
    ) -> Result<Inputs, ReliabilityError> {
        let mut inputs = Inputs::new(names, marginals)?;
        if pairs.is_empty() {
            return Ok(inputs);
        }
        let n = inputs.len();
        let bad = |msg: String| Err(ReliabilityError::InvalidDistribution(msg));
        let mut members: Vec<usize> = Vec::new();
        for p in pairs {
            if p.a >= n || p.b >= n {
                return bad(format!(
                    "correlation between inputs {} and {}: there are {n} inputs",
                    p.a, p.b
                ));
            }
            let (na, nb) = (&inputs.names[p.a], &inputs.names[p.b]);
            if p.a == p.b {
                return bad(format!("correlation of `{na}` with itself"));
            }
            if let Some(f) = [p.a, p.b].into_iter().find(|&j| inputs.stds[j] == 0.0) {
                return bad(format!(
                    "correlation of `{na}` and `{nb}`: `{}` is a fixed value, which correlates with nothing",
                    inputs.names[f]
                ));
            }
            if !p.rho.is_finite() || p.rho.abs() >= 1.0 {
                return bad(format!(
                    "correlation of `{na}` and `{nb}` is {}: it must be strictly between -1 and 1",
                    p.rho
                ));
            }
            for j in [p.a, p.b] {
                if !members.contains(&j) {
                    members.push(j);
                }
            }
        }
        members.sort_unstable();
        let k = members.len();
        let mut position = vec![None; n];
        for (i, &m) in members.iter().enumerate() {
            position[m] = Some(i);
        }
        let mut matrix = vec![0.0; k * k];
        for i in 0..k {
            matrix[i * k + i] = 1.0;
        }
        let mut adjusted = matrix.clone();
        let mut given = vec![false; k * k];
        for p in pairs {
            let (i, j) = (
                position[p.a].unwrap_or_default(),
                position[p.b].unwrap_or_default(),
            );
            if given[i * k + j] {
                return bad(format!(
                    "correlation of `{}` and `{}` is given twice",
                    inputs.names[p.a], inputs.names[p.b]
                ));
            }
            given[i * k + j] = true;
            given[j * k + i] = true;
            matrix[i * k + j] = p.rho;
            matrix[j * k + i] = p.rho;
            let (ma, mb) = (&inputs.marginals[p.a], &inputs.marginals[p.b]);
            let r0 = crate::nataf::adjusted_correlation(ma, mb, p.rho).map_err(|e| {
                ReliabilityError::InvalidDistribution(format!(
                    "correlation of `{}` and `{}`: {e}",
                    inputs.names[p.a], inputs.names[p.b]
                ))
            })?;
            adjusted[i * k + j] = r0;
            adjusted[j * k + i] = r0;
        }
        // nalgebra's factor (the reference results hold its rounding to the
        // last bit); the hand-written one only to name the pair where a
        // failing factorisation stops.
        let factor = match nalgebra::Cholesky::new(nalgebra::DMatrix::from_row_slice(
            k, k, &adjusted,
        ))
        .map(|c| c.l())
        .ok_or_else(|| cholesky(&adjusted, k).err().unwrap_or((k - 1, 0)))
        {
            Ok(l) => {
                let mut factor = vec![0.0; k * k];
                for i in 0..k {
                    for j in 0..=i {
                        factor[i * k + j] = l[(i, j)];
                    }
                }
                factor
            }
            Err((row, col)) => {
                let r = nalgebra::DMatrix::from_row_slice(k, k, &adjusted);
                let smallest = r.symmetric_eigenvalues().min();
                let names: Vec<&str> = members.iter().map(|&m| inputs.names[m].as_str()).collect();
                let kind = if adjusted == matrix {
                    "correlation matrix"
                } else {
                    "Nataf-adjusted correlation matrix"
                };
                return bad(format!(
                    "the {kind} of {} is not positive definite (smallest eigenvalue {smallest:.3e}); it fails at the pair `{}`–`{}`",
                    names.join(", "),
                    inputs.names[members[col]],
                    inputs.names[members[row]],
                ));
            }
        };
        inputs.correlation = Some(Block {
            pairs: pairs.to_vec(),
            members,
            position,
            matrix,
            adjusted,
            factor,
        });
        Ok(inputs)
    }

    /// The correlation coefficients as given (empty for independent inputs).
    pub fn correlations(&self) -> &[Correlation] {
        self.correlation.as_ref().map_or(&[], |b| &b.pairs)
    }

    /// True when input `j` is in the correlated block.
    pub fn is_correlated(&self, j: usize) -> bool {
        self.correlation
            .as_ref()
            .is_some_and(|b| b.position.get(j).copied().flatten().is_some())
    }

    /// `ρ_ab` (1 on the diagonal, 0 between independent inputs).
    pub fn correlation(&self, a: usize, b: usize) -> f64 {
        if a == b {
            return 1.0;
        }
        match &self.correlation {
            Some(bl) => match (bl.position[a], bl.position[b]) {
                (Some(i), Some(j)) => bl.matrix[i * bl.members.len() + j],
                _ => 0.0,
            },
            None => 0.0,
        }
    }

    /// The affine projection of a row `s` of coefficients on the inputs:
    /// returns `m = Σ_j s_j·μ_j` and writes `a = sᵀ·∂x/∂u` into `a`, so that
    /// `sᵀx = m + a·u` when the map is affine ([`Inputs::is_affine`]);
    /// `|a| = √(sᵀΣs)` (for independent inputs `a_j = s_j·σ_j`).
    pub fn project(&self, s: &[f64], a: &mut [f64]) -> f64 {
        // (`means` and `stds` are the marginals' own, formed with them.)
        let mut mean = 0.0;
        for (((a, s), m), sd) in a.iter_mut().zip(s).zip(&self.means).zip(&self.stds) {
            mean += s * m;
            *a = s * sd;
        }
        if let Some(b) = &self.correlation {
            let k = b.members.len();
            // a_{m_k} = Σ_{i ≥ k} s_{m_i}·σ_{m_i}·L_ik.
            for c in 0..k {
                a[b.members[c]] = (c..k)
                    .map(|i| {
                        let m = b.members[i];
                        s[m] * self.stds[m] * b.factor[i * k + c]
                    })
                    .sum();
            }
        }
        mean
    }

    /// `(Σ·s)_j / σ_j = Σ_b ρ_jb·σ_b·s_b`: half the derivative of the
    /// variance `sᵀΣs` with respect to `σ_j`, over `s_j` (for an
    /// independent input `σ_j·s_j`).
    pub fn covariance_weight(&self, s: &[f64], j: usize) -> f64 {
        match &self.correlation {
            Some(b) if b.position[j].is_some() => b
                .members
                .iter()
                .map(|&m| self.correlation(j, m) * self.stds[m] * s[m])
                .sum(),
            _ => self.stds[j] * s[j],
        }
    }

    /// `Cov(rᵀx, sᵀx) = rᵀΣs`.
    pub fn covariance(&self, r: &[f64], s: &[f64]) -> f64 {
        let vars = self.stds.iter().map(|v| v * v);
        let diagonal: f64 = r.iter().zip(s).zip(vars).map(|((x, y), v)| x * y * v).sum();
        match &self.correlation {
            None => diagonal,
            Some(b) => {
                let mut off = 0.0;
                for &p in &b.members {
                    for &q in &b.members {
                        if p != q {
                            off +=
                                r[p] * s[q] * self.stds[p] * self.stds[q] * self.correlation(p, q);
                        }
                    }
                }
                diagonal + off
            }
        }
    }

    /// Number of inputs.
    pub fn len(&self) -> usize {
        self.marginals.len()
    }

    /// True when there are no inputs.
    pub fn is_empty(&self) -> bool {
        self.marginals.is_empty()
    }

    /// The names, in input order.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The marginals, in input order.
    pub fn marginals(&self) -> &[Marginal] {
        &self.marginals
    }

    /// Index of a named input.
    pub fn index(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }

    /// True when the map `u → x` is affine (every marginal normal, with or
    /// without the correlated normal block), so that straight lines in `U`
    /// stay straight in `X`.
    pub fn is_affine(&self) -> bool {
        self.all_normal
    }

    /// The means.
    pub fn means(&self) -> &[f64] {
        &self.means
    }

    /// The standard deviations.
    pub fn stds(&self) -> &[f64] {
        &self.stds
    }

    /// A copy with input `j`'s mean and standard deviation replaced.
    pub fn with_moments(&self, j: usize, mean: f64, std: f64) -> Result<Inputs, ReliabilityError> {
        let mut marginals = self.marginals.clone();
        let m = marginals.get_mut(j).ok_or(ReliabilityError::Dimension {
            what: "input index",
            expected: self.len(),
            found: j,
        })?;
        *m = m.with_moments(mean, std)?;
        let mut out = Inputs::new(self.names.clone(), marginals)?;
        // The correlation matrix and its factor are held (for non-normal
        // members the Gaussian-copula matrix R₀, so the derivatives at fixed
        // u are those of `dx_dstd`).
        out.correlation = self.correlation.clone();
        Ok(out)
    }

    /// A copy with every standard deviation replaced by `stds` (one per
    /// input), the means, families and correlations held: for non-normal
    /// members of the correlated block the Gaussian-copula matrix `R₀` is
    /// held, as in [`Inputs::with_moments`], so that derivatives at fixed `u`
    /// are those of [`Marginal::dx_dstd`].
    pub fn with_stds(&self, stds: &[f64]) -> Result<Inputs, ReliabilityError> {
        if stds.len() != self.len() {
            return Err(ReliabilityError::Dimension {
                what: "standard deviations",
                expected: self.len(),
                found: stds.len(),
            });
        }
        let marginals = self
            .marginals
            .iter()
            .zip(stds)
            .map(|(m, &s)| m.with_moments(m.mean(), s))
            .collect::<Result<Vec<Marginal>, _>>()?;
        let mut out = Inputs::new(self.names.clone(), marginals)?;
        out.correlation = self.correlation.clone();
        Ok(out)
    }

    /// The inputs `order[0], order[1], …` of these, in that order (the
    /// marginal of a subset: the correlations among the kept inputs are
    /// kept, those with dropped inputs dropped).
    pub fn select(&self, order: &[usize]) -> Result<Inputs, ReliabilityError> {
        let mut names = Vec::with_capacity(order.len());
        let mut marginals = Vec::with_capacity(order.len());
        for &j in order {
            let m = self.marginals.get(j).ok_or(ReliabilityError::Dimension {
                what: "input index",
                expected: self.len(),
                found: j,
            })?;
            names.push(self.names[j].clone());
            marginals.push(*m);
        }
        let new_of = |old: usize| order.iter().position(|&o| o == old);
        let pairs: Vec<Correlation> = self
            .correlations()
            .iter()
            .filter_map(|p| {
                Some(Correlation {
                    a: new_of(p.a)?,
                    b: new_of(p.b)?,
                    rho: p.rho,
                })
            })
            .collect();
        Inputs::correlated(names, marginals, &pairs)
    }

    /// Which standard coordinates `u_j` a function of `x` depends on, given
    /// which `x_j` it depends on: the same for independent inputs; in the
    /// correlated block `u_{m_c}` moves `x_{m_i}` for every `i ≥ c`
    /// (`L` is lower triangular).
    pub fn standard_dependence(&self, x_depends: &[bool]) -> Vec<bool> {
        let mut out = x_depends.to_vec();
        if let Some(b) = &self.correlation {
            let k = b.members.len();
            for c in 0..k {
                let any = (c..k).any(|i| x_depends[b.members[i]] && b.factor[i * k + c] != 0.0);
                out[b.members[c]] = any;
            }
        }
        out
    }

    /// `x = T(u)`.
    #[inline]
    pub fn to_physical(&self, u: &[f64], x: &mut [f64]) {
        for ((x, u), m) in x.iter_mut().zip(u).zip(&self.marginals) {
            *x = m.to_physical(*u);
        }
        if let Some(b) = &self.correlation {
            for (i, &m) in b.members.iter().enumerate() {
                x[m] = self.marginals[m].to_physical(b.z(i, u));
            }
        }
    }

    /// `u = T⁻¹(x)` (for the correlated block, forward substitution in `L`).
    pub fn to_standard(&self, x: &[f64], u: &mut [f64]) {
        for ((u, x), m) in u.iter_mut().zip(x).zip(&self.marginals) {
            *u = m.to_standard(*x);
        }
        if let Some(b) = &self.correlation {
            let k = b.members.len();
            for i in 0..k {
                let m = b.members[i];
                let y = self.marginals[m].to_standard(x[m]);
                let partial: f64 = (0..i).map(|c| b.factor[i * k + c] * u[b.members[c]]).sum();
                u[m] = (y - partial) / b.factor[i * k + i];
            }
        }
    }

    /// The diagonal of the Jacobian `dx/du` at `u` (the whole Jacobian when
    /// the inputs are independent; for the correlated block `σ_j·L_jj`).
    #[inline]
    pub fn jacobian(&self, u: &[f64], out: &mut [f64]) {
        for ((o, u), m) in out.iter_mut().zip(u).zip(&self.marginals) {
            *o = m.dx_du(*u);
        }
        if let Some(b) = &self.correlation {
            let k = b.members.len();
            for (i, &m) in b.members.iter().enumerate() {
                out[m] = self.marginals[m].dx_du(b.z(i, u)) * b.factor[i * k + i];
            }
        }
    }

    /// `∇_u g = (∂x/∂u)ᵀ·∇_x g` at `u` (into `out`): the chain rule through
    /// the whole Jacobian, lower triangular on the correlated block.
    #[inline]
    pub fn gradient_u(&self, u: &[f64], grad_x: &[f64], out: &mut [f64]) {
        for (((o, u), gx), m) in out.iter_mut().zip(u).zip(grad_x).zip(&self.marginals) {
            *o = gx * m.dx_du(*u);
        }
        if let Some(b) = &self.correlation {
            let k = b.members.len();
            // dx_m/dz of each member (σ for a normal one).
            let slope: Vec<f64> = if b.members.iter().all(|&m| self.marginals[m].is_normal()) {
                b.members.iter().map(|&m| self.stds[m]).collect()
            } else {
                (0..k)
                    .map(|i| self.marginals[b.members[i]].dx_du(b.z(i, u)))
                    .collect()
            };
            for c in 0..k {
                out[b.members[c]] = (c..k)
                    .map(|i| {
                        let m = b.members[i];
                        grad_x[m] * slope[i] * b.factor[i * k + c]
                    })
                    .sum();
            }
        }
    }

    /// The whole Jacobian `∂x/∂u` at `u`, `n × n` row-major (`out[j·n + c] =
    /// ∂x_j/∂u_c`): diagonal for independent inputs, `dx_i/dz_i·L_ic` in the
    /// correlated block.
    pub fn jacobian_matrix(&self, u: &[f64], out: &mut [f64]) {
        let n = self.len();
        out.iter_mut().for_each(|v| *v = 0.0);
        let mut diag = vec![0.0; n];
        self.jacobian(u, &mut diag);
        for j in 0..n {
            out[j * n + j] = diag[j];
        }
        if let Some(b) = &self.correlation {
            let k = b.members.len();
            for i in 0..k {
                let m = b.members[i];
                let slope = self.marginals[m].dx_du(b.z(i, u));
                for c in 0..=i {
                    out[m * n + b.members[c]] = slope * b.factor[i * k + c];
                }
            }
        }
    }

    /// Adds `Σ_j w_j·∇²_u x_j` at `u` to the `n × n` row-major `hess`: the
    /// second-order term of `∇²_u g = Jᵀ·∇²_x g·J + Σ_j ∂g/∂x_j·∇²_u x_j`
    /// (`w = ∇_x g`). Independent inputs: `w_j·d²x_j/du_j²` on the diagonal;
    /// in the block `∂²x_i/∂u_p∂u_q = d²x_i/dz_i²·L_ip·L_iq`.
    pub fn add_second_derivatives(&self, u: &[f64], w: &[f64], hess: &mut [f64]) {
        let n = self.len();
        for j in 0..n {
            if !self.is_correlated(j) {
                hess[j * n + j] += w[j] * self.marginals[j].d2x_du2(u[j]);
            }
        }
        if let Some(b) = &self.correlation {
            let k = b.members.len();
            for i in 0..k {
                let m = b.members[i];
                let c2 = w[m] * self.marginals[m].d2x_du2(b.z(i, u));
                if c2 == 0.0 {
                    continue;
                }
                for p in 0..=i {
                    for q in 0..=i {
                        hess[b.members[p] * n + b.members[q]] +=
                            c2 * b.factor[i * k + p] * b.factor[i * k + q];
                    }
                }
            }
        }
    }

    /// `∂x_j/∂μ_j` at fixed `u` (every other `x` is unmoved): the
    /// marginal's [`Marginal::dx_dmean`] at `u_j`, or at `z_j` in the block.
    pub fn dx_dmean(&self, j: usize, u: &[f64]) -> f64 {
        if let Some(b) = &self.correlation {
            if let Some(i) = b.position[j] {
                return self.marginals[j].dx_dmean(b.z(i, u));
            }
        }
        self.marginals[j].dx_dmean(u[j])
    }

    /// `∂x_j/∂σ_j` at fixed `u` (every other `x` is unmoved): the
    /// marginal's [`Marginal::dx_dstd`], in the correlated block at the
    /// coordinate `z_j = (L·u_B)_j` (`z_j` itself for a normal member), the
    /// Gaussian-copula matrix `R₀` held fixed.
    pub fn dx_dstd(&self, j: usize, u: &[f64]) -> f64 {
        if let Some(b) = &self.correlation {
            if let Some(i) = b.position[j] {
                return self.marginals[j].dx_dstd(b.z(i, u));
            }
        }
        self.marginals[j].dx_dstd(u[j])
    }

    /// The importance factors of the FORM unit vector `α` (in `U`), summing
    /// to 1. Independent inputs: `α_j²`. With the correlated block, the
    /// importance vector of Der Kiureghian (2005, "First- and second-order
    /// reliability methods", *Engineering Design Reliability Handbook*,
    /// ch. 14): `γᵀ = αᵀ·J_{u,x}·D̂ /
    /// |αᵀ·J_{u,x}·D̂|`, which for `x_B = μ_B + D_B·L·u_B` is `γ_B = L⁻ᵀ·α_B`
    /// (back substitution; `γ_j = α_j` outside the block), normalised, and
    /// squared: `γ_j²`.
    pub fn importance(&self, alpha: &[f64]) -> Vec<f64> {
        let Some(b) = &self.correlation else {
            return alpha.iter().map(|a| a * a).collect();
        };
        let k = b.members.len();
        let mut gamma = alpha.to_vec();
        for i in (0..k).rev() {
            let tail: f64 = (i + 1..k)
                .map(|r| b.factor[r * k + i] * gamma[b.members[r]])
                .sum();
            gamma[b.members[i]] = (alpha[b.members[i]] - tail) / b.factor[i * k + i];
        }
        let norm2: f64 = gamma.iter().map(|g| g * g).sum();
        if norm2 > 0.0 {
            gamma.iter().map(|g| g * g / norm2).collect()
        } else {
            vec![0.0; gamma.len()]
        }
    }

    /// One physical sample of every input.
    #[inline]
    pub fn sample(&self, rng: &mut CaseRng, x: &mut [f64]) {
        if let Some(b) = &self.correlation {
            // u ~ N(0, I) for every input, then x = T(u) in place: row i of
            // the block reads u of rows ≤ i only, so fill it from the last.
            rng.fill_normal(x);
            for i in (0..b.members.len()).rev() {
                let m = b.members[i];
                x[m] = self.marginals[m].to_physical(b.z(i, x));
            }
            for (j, (x, m)) in x.iter_mut().zip(&self.marginals).enumerate() {
                if b.position[j].is_none() {
                    *x = m.to_physical(*x);
                }
            }
        } else if self.all_normal {
            rng.fill_normal(x);
            for ((x, m), s) in x.iter_mut().zip(&self.means).zip(&self.stds) {
                *x = m + s * *x;
            }
        } else {
            for (x, m) in x.iter_mut().zip(&self.marginals) {
                *x = m.sample(rng);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::marginal::SQRT_3;

    #[test]
    fn marginals_are_validated_and_serialise_by_family() {
        assert!(Marginal::normal(0.0, 0.0).is_err());
        assert!(Marginal::normal(f64::NAN, 1.0).is_err());
        assert!(Marginal::uniform(1.0, 1.0).is_err());
        assert!(Marginal::uniform(0.0, f64::INFINITY).is_err());
        let n = Marginal::normal(0.5, 2.0).unwrap();
        let u = Marginal::uniform(-1.0, 3.0).unwrap();
        assert_eq!((n.family(), u.family()), (Family::Normal, Family::Uniform));
        assert_eq!((n.mean(), n.std()), (0.5, 2.0));
        assert_eq!(u.support(), (-1.0, 3.0));
        assert!((u.std() - 4.0 / (2.0 * SQRT_3)).abs() < 1e-15);
        // A moved moment keeps the family and is validated again.
        assert!(u.with_moments(0.0, -1.0).is_err());
        assert_eq!(u.with_moments(1.0, 1.0).unwrap().family(), Family::Uniform);
        assert_eq!(
            serde_json::to_string(&n).unwrap(),
            r#"{"dist":"normal","mean":0.5,"std":2.0}"#
        );
        assert_eq!(
            serde_json::to_string(&u).unwrap(),
            r#"{"dist":"uniform","min":-1.0,"max":3.0}"#
        );
    }

    fn correlated_three() -> Inputs {
        let names = ["a", "b", "c", "d"].map(String::from).to_vec();
        let marginals = vec![
            Marginal::normal(1.0, 2.0).unwrap(),
            Marginal::uniform(-1.0, 1.0).unwrap(),
            Marginal::normal(-0.5, 0.3).unwrap(),
            Marginal::normal(0.2, 0.7).unwrap(),
        ];
        let pairs = [
            Correlation {
                a: 3,
                b: 0,
                rho: 0.4,
            },
            Correlation {
                a: 2,
                b: 3,
                rho: -0.3,
            },
        ];
        Inputs::correlated(names, marginals, &pairs).unwrap()
    }

    #[test]
    fn the_correlated_map_has_the_given_covariance_and_inverts() {
        let inputs = correlated_three();
        // Cov(x) = J Jᵀ on the block: columns of J from unit u's.
        let n = inputs.len();
        let mut cols = vec![vec![0.0; n]; n];
        let (mut x0, mut x1) = (vec![0.0; n], vec![0.0; n]);
        inputs.to_physical(&vec![0.0; n], &mut x0);
        for (k, col) in cols.iter_mut().enumerate() {
            let mut u = vec![0.0; n];
            u[k] = 1.0;
            inputs.to_physical(&u, &mut x1);
            for j in 0..n {
                col[j] = x1[j] - x0[j];
            }
        }
        let sd = [2.0, 0.0, 0.3, 0.7];
        for p in [0, 2, 3] {
            for q in [0, 2, 3] {
                let cov: f64 = (0..n).map(|k| cols[k][p] * cols[k][q]).sum();
                let want = inputs.correlation(p, q) * sd[p] * sd[q];
                assert!((cov - want).abs() < 1e-14, "{p} {q}: {cov} vs {want}");
            }
        }
        assert_eq!(inputs.correlation(0, 2), 0.0);
        assert_eq!(inputs.correlation(3, 0), 0.4);
        // T⁻¹(T(u)) = u.
        let u = [0.3, -1.2, 0.8, 2.1];
        let mut x = [0.0; 4];
        let mut back = [0.0; 4];
        inputs.to_physical(&u, &mut x);
        inputs.to_standard(&x, &mut back);
        for (a, b) in u.iter().zip(&back) {
            assert!((a - b).abs() < 1e-12, "{u:?} {back:?}");
        }
        // The projection: |a| = √(sᵀΣs).
        let s = [0.5, 0.0, -2.0, 1.5];
        let mut a = [0.0; 4];
        let m = inputs.project(&s, &mut a);
        assert!((m - (0.5 * 1.0 + 2.0 * 0.5 + 1.5 * 0.2)).abs() < 1e-15);
        let var: f64 = a.iter().map(|v| v * v).sum();
        assert!((var - inputs.covariance(&s, &s)).abs() < 1e-13);
        // Importance factors sum to 1; without correlation they are α².
        let alpha = [0.5, 0.5, 0.5, 0.5];
        assert!((inputs.importance(&alpha).iter().sum::<f64>() - 1.0).abs() < 1e-14);
        // A subset keeps the kept pair only, in the new order.
        let sub = inputs.select(&[3, 1, 0]).unwrap();
        assert_eq!(sub.correlations().len(), 1);
        assert_eq!(sub.correlation(0, 2), 0.4);
    }

    #[test]
    fn the_u_gradient_is_the_transposed_jacobian() {
        let inputs = correlated_three();
        let u = [0.3, -0.4, 0.8, 1.1];
        let gx = [1.5, -0.5, 2.0, 0.25];
        let mut gu = [0.0; 4];
        inputs.gradient_u(&u, &gx, &mut gu);
        let (mut xp, mut xm) = ([0.0; 4], [0.0; 4]);
        for k in 0..4 {
            let h = 1e-6;
            let (mut up, mut um) = (u, u);
            up[k] += h;
            um[k] -= h;
            inputs.to_physical(&up, &mut xp);
            inputs.to_physical(&um, &mut xm);
            let fd: f64 = (0..4).map(|j| gx[j] * (xp[j] - xm[j]) / (2.0 * h)).sum();
            assert!((fd - gu[k]).abs() < 1e-8, "{k}: {fd} vs {}", gu[k]);
        }
        // ∂x_j/∂σ_j at fixed u: finite difference in σ_j.
        for j in [0, 2, 3] {
            let h = 1e-7;
            let sd = inputs.stds()[j];
            let mean = inputs.means()[j];
            let (mut xp, mut xm) = ([0.0; 4], [0.0; 4]);
            inputs
                .with_moments(j, mean, sd + h)
                .unwrap()
                .to_physical(&u, &mut xp);
            inputs
                .with_moments(j, mean, sd - h)
                .unwrap()
                .to_physical(&u, &mut xm);
            let fd = (xp[j] - xm[j]) / (2.0 * h);
            assert!((fd - inputs.dx_dstd(j, &u)).abs() < 1e-7, "{j}");
        }
    }

    #[test]
    fn samples_have_the_correlated_moments() {
        let inputs = correlated_three();
        let mut rng = CaseRng::new(7, 0, 0);
        let n = 200_000;
        let mut x = [0.0; 4];
        let (mut s1, mut s2, mut s03) = ([0.0; 4], [0.0; 4], 0.0);
        for _ in 0..n {
            inputs.sample(&mut rng, &mut x);
            for j in 0..4 {
                s1[j] += x[j];
                s2[j] += x[j] * x[j];
            }
            s03 += x[0] * x[3];
        }
        let nf = n as f64;
        let mean: Vec<f64> = s1.iter().map(|s| s / nf).collect();
        let var: Vec<f64> = (0..4).map(|j| s2[j] / nf - mean[j] * mean[j]).collect();
        for j in 0..4 {
            let sd = inputs.stds()[j];
            // 5 standard errors of the sample mean and variance.
            assert!(
                (mean[j] - inputs.means()[j]).abs() < 5.0 * sd / nf.sqrt(),
                "{j}"
            );
            assert!(
                (var[j] / (sd * sd) - 1.0).abs() < 5.0 * (2.0 / nf).sqrt(),
                "{j}"
            );
        }
        let rho = (s03 / nf - mean[0] * mean[3]) / (var[0] * var[3]).sqrt();
        assert!((rho - 0.4).abs() < 5.0 * (1.0 - 0.16) / nf.sqrt(), "{rho}");
        // The uniform stays in its support.
        assert!(inputs.marginals()[1].support() == (-1.0, 1.0));
    }

    #[test]
    fn a_fixed_value_is_the_normal_at_std_zero() {
        let f = Marginal::fixed(0.25).unwrap();
        assert_eq!((f.family(), f.mean(), f.std()), (Family::Fixed, 0.25, 0.0));
        assert!(f.is_normal() && Marginal::fixed(f64::NAN).is_err());
        for u in [-3.0, 0.0, 2.5] {
            assert_eq!(
                (f.to_physical(u), f.dx_du(u), f.d2x_du2(u)),
                (0.25, 0.0, 0.0)
            );
            assert_eq!((f.dx_dmean(u), f.dx_dstd(u)), (1.0, u));
        }
        assert_eq!(
            (f.cdf(0.2), f.cdf(0.25), f.sf(0.2), f.sf(0.25)),
            (0.0, 1.0, 1.0, 0.0)
        );
        assert_eq!(
            (f.to_standard(0.25), f.to_standard(0.3)),
            (0.0, f64::INFINITY)
        );
        assert_eq!(f.support(), (0.25, 0.25));
        // Its input takes a draw like any other, so the others' streams
        // are those without it.
        let names = ["a", "b"].map(String::from).to_vec();
        let n = Marginal::normal(1.0, 2.0).unwrap();
        let with = Inputs::new(names.clone(), vec![f, n]).unwrap();
        let without = Inputs::new(names, vec![n, n]).unwrap();
        let (mut x, mut y) = ([0.0; 2], [0.0; 2]);
        with.sample(&mut CaseRng::new(7, 0, 0), &mut x);
        without.sample(&mut CaseRng::new(7, 0, 0), &mut y);
        assert_eq!((x[0], x[1]), (0.25, y[1]));
        assert!(with.is_affine());
    }

    #[test]
    fn bad_correlations_are_refused() {
        let names = ["a", "b", "c"].map(String::from).to_vec();
        let m = vec![Marginal::normal(0.0, 1.0).unwrap(); 3];
        let run = |pairs: &[Correlation]| {
            Inputs::correlated(names.clone(), m.clone(), pairs)
                .unwrap_err()
                .to_string()
        };
        let c = |a, b, rho| Correlation { a, b, rho };
        assert!(run(&[c(0, 0, 0.5)]).contains("with itself"));
        assert!(run(&[c(0, 1, 1.0)]).contains("strictly between"));
        assert!(run(&[c(0, 1, f64::NAN)]).contains("strictly between"));
        assert!(run(&[c(0, 1, 0.5), c(1, 0, 0.2)]).contains("twice"));
        assert!(run(&[c(0, 5, 0.5)]).contains("3 inputs"));
        // A fixed value correlates with nothing.
        let mut fixed = m.clone();
        fixed[2] = Marginal::fixed(1.5).unwrap();
        let e = Inputs::correlated(names.clone(), fixed, &[c(0, 2, 0.5)]).unwrap_err();
        assert!(e.to_string().contains("`c` is a fixed value"), "{e}");
        // Each |ρ| < 1, but the matrix is not positive definite.
        let e = run(&[c(0, 1, 0.9), c(1, 2, 0.9), c(0, 2, -0.9)]);
        assert!(
            e.contains("not positive definite") && e.contains("a, b, c"),
            "{e}"
        );
        // Two lognormals cannot reach ρ = −0.9 (Liu & Der Kiureghian's
        // bound ln(1 − 0.9·δ²)/ζ² < −1 at δ = 1).
        let l = vec![Marginal::lognormal(1.0, 1.0, 0.0).unwrap(); 3];
        let e = Inputs::correlated(names.clone(), l, &[c(0, 1, -0.9)]).unwrap_err();
        assert!(e.to_string().contains("not attainable"), "{e}");
    }
}
