//! Variance-based global sensitivity: first-order and total Sobol indices of
//! the error components (and of the volumetric error `|p|`) with respect to
//! every error parameter, with bootstrap percentile intervals.
//!
//! # Estimators
//!
//! Saltelli et al. (2010), "Variance based sensitivity analysis of model
//! output. Design and estimator for the total sensitivity index", Computer
//! Physics Communications 181, 259-270. Two independent `N × k` sample
//! matrices `A` and `B` of the inputs, and for every input `i` the matrix
//! `A_B^(i)`: `A` with its column `i` taken from `B` (their Section 3). The
//! model is evaluated on `A`, `B` and the `k` matrices `A_B^(i)`:
//! `N·(k + 2)` evaluations. With `f` the output and `j` the row:
//!
//! - first-order effect, Table 2 (b) (Saltelli 2010's recommended form):
//!   `V_i = V[E(Y|X_i)] ≈ (1/N) Σ_j f(B)_j · (f(A_B^(i))_j − f(A)_j)`;
//! - total effect, Table 2 (f) (Jansen 1999):
//!   `V·T_i = E[V(Y|X_~i)] ≈ (1/(2N)) Σ_j (f(A)_j − f(A_B^(i))_j)²`;
//! - `V = V(Y)`: the unbiased sample variance of the `2N` values `f(A)`,
//!   `f(B)`.
//!
//! `S_i = V_i / V`, `T_i = V·T_i / V`. Every output is shifted by a constant
//! `c` before the sums (`f − c`; the estimators above are unchanged in
//! expectation by a shift and their variance is smallest when `c` is the
//! mean): `c` is the exact mean `a·μ` of a component and, for `|p|`, the mean
//! of a fixed pilot of 256 samples (its own random stream).
//!
//! # The error model
//!
//! At a fixed point `q` the model is linear in the errors: a component is the
//! dot product `E_c = a_c·x` of its sensitivity row (the model's
//! [`chain_core::ErrorModel::sensitivity`], through a [`Study`]) with the
//! errors. So `f(A_B^(i))_j = f(A)_j + a_ci (B_ji − A_ji)` exactly, and `|p|`
//! of `A_B^(i)` is the norm of `p(A)_j + (a_xi, a_yi, a_zi)(B_ji − A_ji)`: the
//! `N·(k + 2)` evaluations of the design cost `O(N·k)` per output, not
//! `O(N·k²)`. For such a model in independent errors the indices have the
//! closed form `S_i = T_i = a_i² σ_i² / Σ_j a_j² σ_j²` (the variance of a sum
//! of independent terms; any marginal family), reported as `exact` beside the
//! estimate.
//!
//! # Over a grid
//!
//! With several points the indices are those of the grid-pooled variance
//! decomposition: `S̄_i = Σ_p V_i(q_p) / Σ_p V(q_p)` and
//! `T̄_i = Σ_p V·T_i(q_p) / Σ_p V(q_p)`, the share of the output variance
//! summed over the points that input `i` explains (alone, or with its
//! interactions) — the indices of the expected conditional variance
//! `E_q[V(Y | q)]` over a uniformly chosen grid point. A point where the
//! output varies little weighs little; this is not the mean of per-point
//! indices. The same matrices `A`, `B` serve every point (the errors are the
//! same random variables everywhere).
//!
//! # Inputs
//!
//! Rows of `A` and `B` are drawn through [`Inputs::sample`], so every
//! marginal family of [`Inputs`] works. Sobol indices assume independent
//! inputs (the ANOVA decomposition is unique and the `V_i` add up only then);
//! correlated inputs are refused ([`SobolError::Correlated`]) rather than
//! given indices of an ill-defined decomposition.
//!
//! # Intervals and streams
//!
//! The `N` rows are split into at most [`MAX_BLOCKS`] consecutive blocks of
//! equal size (the last one shorter); block `b` draws from stream `(0, b)` of
//! the seed ([`CaseRng`]) and the blocks run in parallel (feature
//! `parallel`), their sums added in block order: the results are identical
//! for any thread count, per seed. The bootstrap (Efron & Tibshirani 1993,
//! percentile interval, Ch. 13) resamples whole blocks with replacement (the
//! rows are independent, so the blocks are independent and identically
//! distributed, and every estimator above is a smooth function of their
//! sums; with `N ≤ MAX_BLOCKS` a block is one row, the ordinary bootstrap):
//! replicate `r` draws its blocks from stream `(u32::MAX, r)`; the interval is
//! the `(1 ± level)/2` empirical quantiles (linear interpolation between
//! order statistics) of the replicates.

use chain_core::model::Component;
use serde::Serialize;

use crate::error::ReliabilityError;
use crate::inputs::Inputs;
use crate::par::prelude::*;
use crate::rng::CaseRng;
use crate::study::{Study, Target};

/// The most blocks the base samples are split into (and the bootstrap
/// resamples).
pub const MAX_BLOCKS: usize = 1000;

/// Rows of the pilot that gives the shift of the volumetric output.
const PILOT: usize = 256;

/// What can go wrong in a Sobol analysis.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[cfg_attr(feature = "miette", derive(miette::Diagnostic))]
#[non_exhaustive]
pub enum SobolError {
    /// A setting is out of range.
    #[error("{what} must be {rule} (found {found})")]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::sobol::invalid_setting)))]
    InvalidSetting {
        /// The setting (`samples`, `bootstrap`, `confidence`).
        what: &'static str,
        /// What it must be.
        rule: &'static str,
        /// The value given.
        found: String,
    },
    /// Some inputs are correlated.
    #[error(
        "Sobol indices need independent inputs, but {} correlated: the variance decomposition of dependent inputs is not unique",
        names.join(", ")
    )]
    #[cfg_attr(
        feature = "miette",
        diagnostic(
            code(chain::sobol::correlated),
            help("remove the correlation (or the posterior's correlations) to compute the indices of independent errors")
        )
    )]
    Correlated {
        /// The correlated inputs.
        names: Vec<String>,
    },
    /// An output does not vary: its indices are undefined.
    #[error("output `{output}` has zero variance{where_}: its Sobol indices are undefined")]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::sobol::zero_variance)))]
    ZeroVariance {
        /// The output.
        output: String,
        /// ` at the point` or ` over the grid`.
        where_: &'static str,
    },
    /// Sizes that must agree do not.
    #[error("{what}: expected {expected}, found {found}")]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::sobol::dimension)))]
    Dimension {
        /// What was being sized.
        what: &'static str,
        /// The expected size.
        expected: usize,
        /// The size found.
        found: usize,
    },
    /// The study has no output the analysis could use.
    #[error("no output to analyse: {0}")]
    #[cfg_attr(feature = "miette", diagnostic(code(chain::sobol::no_output)))]
    NoOutput(String),
    /// The study refused a point (its sensitivities not finite).
    #[error(transparent)]
    #[cfg_attr(feature = "miette", diagnostic(transparent))]
    Reliability(#[from] ReliabilityError),
}

/// The Saltelli-Jansen analysis: its sample size, seed and bootstrap.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Sobol {
    /// `N`, the rows of each of `A` and `B` (`N·(k + 2)` model evaluations
    /// per point).
    pub samples: usize,
    /// The seed of the random streams.
    pub seed: u64,
    /// Bootstrap replicates for the intervals.
    pub bootstrap: usize,
    /// Confidence level of the intervals, in `(0, 1)`.
    pub confidence: f64,
}

impl Default for Sobol {
    /// `N = 10⁴`, seed 0, 1000 bootstrap replicates, 95 % intervals.
    fn default() -> Sobol {
        Sobol {
            samples: 10_000,
            seed: 0,
            bootstrap: 1000,
            confidence: 0.95,
        }
    }
}

/// An estimated index with its bootstrap percentile interval.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Estimate {
    /// The estimate on all `N` rows.
    pub value: f64,
    /// Lower end of the interval.
    pub low: f64,
    /// Upper end of the interval.
    pub high: f64,
    /// The closed form for a linear output in independent inputs (components;
    /// `None` for `|p|`).
    pub exact: Option<f64>,
}

/// The indices of one output with respect to one input.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct InputIndices {
    /// The input (error parameter).
    pub error: String,
    /// First-order index `S_i`.
    pub first: Estimate,
    /// Total index `T_i`.
    pub total: Estimate,
}

/// The indices of one output.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OutputIndices {
    /// The output: a component, or `volumetric` (`|p|`).
    pub output: Target,
    /// The estimated output variance `V` (summed over the points for a grid).
    pub variance: f64,
    /// Per input, in the inputs' order.
    pub errors: Vec<InputIndices>,
    /// `Σ_i S_i` (1 for an additive model; less with interactions).
    pub sum_first: Estimate,
    /// `Σ_i T_i` (1 for an additive model; more with interactions).
    pub sum_total: Estimate,
}

/// The result of [`Sobol::run`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SobolResult {
    /// The settings.
    pub settings: Sobol,
    /// Points the indices pool (1: at a point).
    pub points: usize,
    /// Inputs `k`.
    pub inputs: usize,
    /// Model evaluations per point, `N·(k + 2)`.
    pub evaluations_per_point: u64,
    /// Blocks the rows are split into (the bootstrap's resampling units).
    pub blocks: usize,
    /// Per output.
    pub outputs: Vec<OutputIndices>,
}

/// The outputs of a study: its toleranced components and `|p|`.
pub fn study_outputs(study: &Study) -> Vec<Target> {
    let mut out: Vec<Target> = study
        .spec()
        .tolerances
        .iter()
        .map(|(c, _)| Target::Component(*c))
        .collect();
    out.push(Target::Volumetric);
    out
}

/// `(S_i per input, T_i per input, V)` of one output.
type Indices = (Vec<f64>, Vec<f64>, f64);

/// Per block: the sums of every output.
#[derive(Debug, Clone)]
struct BlockSums {
    rows: usize,
    /// Per output, per input: `Σ_p Σ_j (f(B) − c)(f(A_B^i) − f(A))`.
    first: Vec<Vec<f64>>,
    /// Per output, per input: `Σ_p Σ_j (f(A) − f(A_B^i))²`.
    total: Vec<Vec<f64>>,
    /// Per output: `Σ_p Σ_j [(f(A) − c)² + (f(B) − c)²]`.
    square: Vec<f64>,
    /// Per output, per point: `Σ_j [(f(A) − c) + (f(B) − c)]`.
    sum: Vec<Vec<f64>>,
}

impl BlockSums {
    fn zero(outputs: usize, k: usize, points: usize) -> BlockSums {
        BlockSums {
            rows: 0,
            first: vec![vec![0.0; k]; outputs],
            total: vec![vec![0.0; k]; outputs],
            square: vec![0.0; outputs],
            sum: vec![vec![0.0; points]; outputs],
        }
    }

    /// `self += w·other`.
    fn add(&mut self, other: &BlockSums, w: f64) {
        self.rows += (w as usize) * other.rows;
        for o in 0..self.first.len() {
            for (a, b) in self.first[o].iter_mut().zip(&other.first[o]) {
                *a += w * b;
            }
            for (a, b) in self.total[o].iter_mut().zip(&other.total[o]) {
                *a += w * b;
            }
            self.square[o] += w * other.square[o];
            for (a, b) in self.sum[o].iter_mut().zip(&other.sum[o]) {
                *a += w * b;
            }
        }
    }

    /// The indices of every output: `(S_i, T_i)` per input and `V`.
    fn indices(&self) -> Vec<Indices> {
        let n = self.rows as f64;
        let two_n = 2.0 * n;
        (0..self.first.len())
            .map(|o| {
                // Σ_p V(q_p) with the unbiased variance of the 2N values.
                let means2: f64 = self.sum[o].iter().map(|s| (s / two_n).powi(2)).sum();
                let v = (self.square[o] / two_n - means2) * two_n / (two_n - 1.0);
                let s: Vec<f64> = self.first[o].iter().map(|f| f / n / v).collect();
                let t: Vec<f64> = self.total[o].iter().map(|f| f / two_n / v).collect();
                (s, t, v)
            })
            .collect()
    }
}

/// One output at one point: what it reads of the point's rows.
#[derive(Debug, Clone)]
enum Kernel {
    /// `a·x − c`.
    Linear { row: Vec<f64>, shift: f64 },
    /// `|p(x)| − c`, `p = (a_x·x, a_y·x, a_z·x)`.
    Norm { rows: [Vec<f64>; 3], shift: f64 },
}

fn dot(a: &[f64], x: &[f64]) -> f64 {
    a.iter().zip(x).map(|(a, x)| a * x).sum()
}

impl Sobol {
    /// Checks the settings: `samples ≥ 2` (and below 2³²), `bootstrap` in
    /// `[10, 10⁶]`, `confidence` in `(0, 1)`.
    pub fn validate(&self) -> Result<(), SobolError> {
        if self.samples < 2 {
            return Err(SobolError::InvalidSetting {
                what: "samples",
                rule: "at least 2",
                found: self.samples.to_string(),
            });
        }
        if self.samples > (u32::MAX as usize) {
            return Err(SobolError::InvalidSetting {
                what: "samples",
                rule: "at most 4294967295",
                found: self.samples.to_string(),
            });
        }
        if self.bootstrap < 10 || self.bootstrap > 1_000_000 {
            return Err(SobolError::InvalidSetting {
                what: "bootstrap",
                rule: "between 10 and 1000000",
                found: self.bootstrap.to_string(),
            });
        }
        if !(self.confidence > 0.0 && self.confidence < 1.0) {
            return Err(SobolError::InvalidSetting {
                what: "confidence",
                rule: "strictly between 0 and 1",
                found: self.confidence.to_string(),
            });
        }
        Ok(())
    }

    /// The indices of the study's outputs ([`study_outputs`]: its toleranced
    /// components and `|p|`), pooled over all its points (one point: the
    /// indices at that point; see the module documentation).
    pub fn run_study(&self, study: &Study) -> Result<SobolResult, SobolError> {
        let k = study.inputs().len();
        let rows: Vec<Vec<f64>> = (0..study.points().len())
            .map(|p| Ok(study.sensitivities(p..p + 1)?.into_owned()))
            .collect::<Result<_, ReliabilityError>>()?;
        debug_assert!(rows.iter().all(|r| r.len() == 6 * k));
        self.run(study.inputs(), &rows, &study_outputs(study))
    }

    /// The indices of `outputs` (components, or [`Target::Volumetric`] for
    /// `|p|`; [`Target::Series`] is not an output) of the linear model whose
    /// `6 × k` sensitivity matrices (component-major, the layout of
    /// [`chain_core::ErrorModel::sensitivity`]) at each point are `rows`,
    /// pooled over the points.
    pub fn run(
        &self,
        inputs: &Inputs,
        rows: &[Vec<f64>],
        outputs: &[Target],
    ) -> Result<SobolResult, SobolError> {
        self.validate()?;
        let k = inputs.len();
        let correlated: Vec<String> = (0..k)
            .filter(|&j| inputs.is_correlated(j))
            .map(|j| inputs.names()[j].clone())
            .collect();
        if !correlated.is_empty() || !inputs.correlations().is_empty() {
            let mut names = correlated;
            for c in inputs.correlations() {
                for j in [c.a, c.b] {
                    let n = &inputs.names()[j];
                    if !names.contains(n) {
                        names.push(n.clone());
                    }
                }
            }
            return Err(SobolError::Correlated { names });
        }
        if rows.is_empty() {
            return Err(SobolError::NoOutput("no point is given".into()));
        }
        if outputs.is_empty() {
            return Err(SobolError::NoOutput("no output is asked for".into()));
        }
        if outputs.contains(&Target::Series) {
            return Err(SobolError::NoOutput(
                "the series system is an event, not an output; ask for its components".into(),
            ));
        }
        for r in rows {
            if r.len() != 6 * k {
                return Err(SobolError::Dimension {
                    what: "sensitivity matrix (6 × inputs)",
                    expected: 6 * k,
                    found: r.len(),
                });
            }
        }
        let where_ = if rows.len() == 1 {
            " at the point"
        } else {
            " over the grid"
        };
        let var: Vec<f64> = inputs.stds().iter().map(|s| s * s).collect();
        let means = inputs.means();
        let row = |p: usize, c: Component| &rows[p][c.index() * k..(c.index() + 1) * k];
        // The exact contributions a_i² σ_i², summed over the points.
        let mut exact: Vec<Option<Vec<f64>>> = Vec::with_capacity(outputs.len());
        for o in outputs {
            match o {
                Target::Component(c) => {
                    let mut e = vec![0.0; k];
                    for p in 0..rows.len() {
                        for (i, a) in row(p, *c).iter().enumerate() {
                            e[i] += a * a * var[i];
                        }
                    }
                    if e.iter().sum::<f64>() <= 0.0 {
                        return Err(SobolError::ZeroVariance {
                            output: c.name().into(),
                            where_,
                        });
                    }
                    exact.push(Some(e));
                }
                _ => {
                    let moving = (0..rows.len()).any(|p| {
                        [Component::Px, Component::Py, Component::Pz]
                            .iter()
                            .any(|c| row(p, *c).iter().zip(&var).any(|(a, v)| a * a * v > 0.0))
                    });
                    if !moving {
                        return Err(SobolError::ZeroVariance {
                            output: "volumetric".into(),
                            where_,
                        });
                    }
                    exact.push(None);
                }
            }
        }
        // The shifts: exact means of the components, a pilot's mean of |p|.
        let mut pilot = vec![0.0; PILOT * k];
        {
            let mut rng = CaseRng::new(self.seed, 1, 0);
            for x in pilot.chunks_exact_mut(k) {
                inputs.sample(&mut rng, x);
            }
        }
        let kernels: Vec<Vec<Kernel>> = (0..rows.len())
            .map(|p| {
                outputs
                    .iter()
                    .map(|o| match o {
                        Target::Component(c) => Kernel::Linear {
                            row: row(p, *c).to_vec(),
                            shift: dot(row(p, *c), means),
                        },
                        _ => {
                            let rs = [
                                row(p, Component::Px).to_vec(),
                                row(p, Component::Py).to_vec(),
                                row(p, Component::Pz).to_vec(),
                            ];
                            let shift = pilot
                                .chunks_exact(k)
                                .map(|x| {
                                    let (a, b, c) =
                                        (dot(&rs[0], x), dot(&rs[1], x), dot(&rs[2], x));
                                    (a * a + b * b + c * c).sqrt()
                                })
                                .sum::<f64>()
                                / PILOT as f64;
                            Kernel::Norm { rows: rs, shift }
                        }
                    })
                    .collect()
            })
            .collect();

        let n = self.samples;
        let size = n.div_ceil(MAX_BLOCKS);
        let blocks = n.div_ceil(size);
        let sums: Vec<BlockSums> = (0..blocks)
            .into_par_iter()
            .map(|b| {
                let count = size.min(n - b * size);
                self.block(inputs, &kernels, b as u32, count)
            })
            .collect();
        let mut all = BlockSums::zero(outputs.len(), k, rows.len());
        for s in &sums {
            all.add(s, 1.0);
        }
        let point = all.indices();
        for (o, (_, _, v)) in point.iter().enumerate() {
            if v.is_nan() || *v <= 0.0 {
                return Err(SobolError::ZeroVariance {
                    output: outputs[o].name().into(),
                    where_,
                });
            }
        }
        // Bootstrap replicates over the blocks.
        let replicates: Vec<Vec<Indices>> = (0..self.bootstrap)
            .into_par_iter()
            .map(|r| {
                let mut rng = CaseRng::new(self.seed, u32::MAX, r as u32);
                let mut counts = vec![0u32; blocks];
                for _ in 0..blocks {
                    let b = ((rng.uniform() * blocks as f64) as usize).min(blocks - 1);
                    counts[b] += 1;
                }
                let mut acc = BlockSums::zero(outputs.len(), k, rows.len());
                for (s, &c) in sums.iter().zip(&counts) {
                    if c > 0 {
                        acc.add(s, f64::from(c));
                    }
                }
                acc.indices()
            })
            .collect();
        let level = self.confidence;
        let interval = |values: &mut Vec<f64>| -> (f64, f64) {
            values.sort_by(f64::total_cmp);
            (
                quantile(values, (1.0 - level) / 2.0),
                quantile(values, (1.0 + level) / 2.0),
            )
        };
        let mut results = Vec::with_capacity(outputs.len());
        for (o, out) in outputs.iter().enumerate() {
            let (s, t, v) = &point[o];
            let ex = exact[o].as_ref().map(|e| {
                let sum: f64 = e.iter().sum();
                e.iter().map(|x| x / sum).collect::<Vec<f64>>()
            });
            let mut errors = Vec::with_capacity(k);
            for i in 0..k {
                let (fl, fh) = interval(&mut replicates.iter().map(|r| r[o].0[i]).collect());
                let (tl, th) = interval(&mut replicates.iter().map(|r| r[o].1[i]).collect());
                let e = ex.as_ref().map(|e| e[i]);
                errors.push(InputIndices {
                    error: inputs.names()[i].clone(),
                    first: Estimate {
                        value: s[i],
                        low: fl,
                        high: fh,
                        exact: e,
                    },
                    total: Estimate {
                        value: t[i],
                        low: tl,
                        high: th,
                        exact: e,
                    },
                });
            }
            let one = ex.as_ref().map(|_| 1.0);
            let (sl, sh) = interval(&mut replicates.iter().map(|r| r[o].0.iter().sum()).collect());
            let (ul, uh) = interval(&mut replicates.iter().map(|r| r[o].1.iter().sum()).collect());
            results.push(OutputIndices {
                output: *out,
                variance: *v,
                errors,
                sum_first: Estimate {
                    value: s.iter().sum(),
                    low: sl,
                    high: sh,
                    exact: one,
                },
                sum_total: Estimate {
                    value: t.iter().sum(),
                    low: ul,
                    high: uh,
                    exact: one,
                },
            });
        }
        Ok(SobolResult {
            settings: *self,
            points: rows.len(),
            inputs: k,
            evaluations_per_point: n as u64 * (k as u64 + 2),
            blocks,
            outputs: results,
        })
    }

    /// The sums of one block of `count` rows (stream `(0, block)`).
    fn block(
        &self,
        inputs: &Inputs,
        kernels: &[Vec<Kernel>],
        block: u32,
        count: usize,
    ) -> BlockSums {
        let k = inputs.len();
        let outputs = kernels[0].len();
        let mut s = BlockSums::zero(outputs, k, kernels.len());
        s.rows = count;
        let mut rng = CaseRng::new(self.seed, 0, block);
        let mut a = vec![0.0; k];
        let mut b = vec![0.0; k];
        let mut d = vec![0.0; k];
        for _ in 0..count {
            inputs.sample(&mut rng, &mut a);
            inputs.sample(&mut rng, &mut b);
            for ((d, a), b) in d.iter_mut().zip(&a).zip(&b) {
                *d = b - a;
            }
            for (p, point) in kernels.iter().enumerate() {
                for (o, kernel) in point.iter().enumerate() {
                    let first = &mut s.first[o];
                    let total = &mut s.total[o];
                    match kernel {
                        Kernel::Linear { row, shift } => {
                            let ya = dot(row, &a) - shift;
                            let yb = dot(row, &b) - shift;
                            for i in 0..k {
                                // f(A_B^i) − f(A) = a_i (B_i − A_i).
                                let delta = row[i] * d[i];
                                first[i] += yb * delta;
                                total[i] += delta * delta;
                            }
                            s.square[o] += ya * ya + yb * yb;
                            s.sum[o][p] += ya + yb;
                        }
                        Kernel::Norm { rows, shift } => {
                            let pa = [dot(&rows[0], &a), dot(&rows[1], &a), dot(&rows[2], &a)];
                            let pb = [dot(&rows[0], &b), dot(&rows[1], &b), dot(&rows[2], &b)];
                            let na = (pa[0] * pa[0] + pa[1] * pa[1] + pa[2] * pa[2]).sqrt();
                            let nb = (pb[0] * pb[0] + pb[1] * pb[1] + pb[2] * pb[2]).sqrt();
                            let yb = nb - shift;
                            for i in 0..k {
                                let q = [
                                    pa[0] + rows[0][i] * d[i],
                                    pa[1] + rows[1][i] * d[i],
                                    pa[2] + rows[2][i] * d[i],
                                ];
                                let delta = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt() - na;
                                first[i] += yb * delta;
                                total[i] += delta * delta;
                            }
                            let ya = na - shift;
                            s.square[o] += ya * ya + yb * yb;
                            s.sum[o][p] += ya + yb;
                        }
                    }
                }
            }
        }
        s
    }
}

/// The `q`-quantile of sorted `values` with linear interpolation between
/// order statistics (Hyndman & Fan 1996, definition 7).
fn quantile(sorted: &[f64], q: f64) -> f64 {
    let h = (sorted.len() - 1) as f64 * q;
    let lo = h.floor() as usize;
    let hi = (lo + 1).min(sorted.len() - 1);
    sorted[lo] + (h - lo as f64) * (sorted[hi] - sorted[lo])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::inputs::Marginal;

    fn inputs(stds: &[f64]) -> Inputs {
        Inputs::new(
            (0..stds.len()).map(|i| format!("e{i}")).collect(),
            stds.iter()
                .map(|&s| Marginal::normal(0.0, s).unwrap())
                .collect(),
        )
        .unwrap()
    }

    /// A 6 × k matrix with the px row `a` (and the others zero).
    fn px_rows(a: &[f64]) -> Vec<f64> {
        let mut r = vec![0.0; 6 * a.len()];
        r[..a.len()].copy_from_slice(a);
        r
    }

    #[test]
    fn quantile_interpolates() {
        let v = [0.0, 1.0, 2.0, 3.0, 4.0];
        assert_eq!(quantile(&v, 0.5), 2.0);
        assert_eq!(quantile(&v, 0.125), 0.5);
        assert_eq!(quantile(&v, 0.0), 0.0);
        assert_eq!(quantile(&v, 1.0), 4.0);
    }

    #[test]
    fn linear_model_matches_closed_form() {
        // Y = 1·X0 + 2·X1 + 3·X2, σ = (1, 1, 0.5): shares 1, 4, 2.25 of 7.25.
        let inp = inputs(&[1.0, 1.0, 0.5]);
        let rows = vec![px_rows(&[1.0, 2.0, 3.0])];
        let r = Sobol {
            samples: 20_000,
            ..Sobol::default()
        }
        .run(&inp, &rows, &[Target::Component(Component::Px)])
        .unwrap();
        let exact = [1.0 / 7.25, 4.0 / 7.25, 2.25 / 7.25];
        for (e, x) in r.outputs[0].errors.iter().zip(exact) {
            assert_eq!(e.first.exact, Some(x));
            // N = 2·10⁴: the first-order error is ≈ √S/√N ≤ 0.007.
            assert!((e.first.value - x).abs() < 0.03, "{e:?}");
            assert!((e.total.value - x).abs() < 0.03, "{e:?}");
            assert!(e.first.low <= e.first.value && e.first.value <= e.first.high);
        }
        assert!((r.outputs[0].variance - 7.25).abs() < 0.3);
    }

    #[test]
    fn refusals() {
        let inp = inputs(&[1.0, 1.0]);
        let rows = vec![px_rows(&[1.0, 2.0])];
        let px = [Target::Component(Component::Px)];
        let bad = |s: Sobol| s.run(&inp, &rows, &px).unwrap_err();
        assert!(matches!(
            bad(Sobol {
                samples: 0,
                ..Sobol::default()
            }),
            SobolError::InvalidSetting {
                what: "samples",
                ..
            }
        ));
        assert!(matches!(
            bad(Sobol {
                confidence: 1.0,
                ..Sobol::default()
            }),
            SobolError::InvalidSetting {
                what: "confidence",
                ..
            }
        ));
        assert!(matches!(
            bad(Sobol {
                bootstrap: 0,
                ..Sobol::default()
            }),
            SobolError::InvalidSetting {
                what: "bootstrap",
                ..
            }
        ));
        let err = Sobol::default()
            .run(&inp, &rows, &[Target::Component(Component::Py)])
            .unwrap_err();
        assert!(matches!(err, SobolError::ZeroVariance { .. }), "{err}");
        let corr = Inputs::correlated(
            vec!["e0".into(), "e1".into()],
            vec![
                Marginal::normal(0.0, 1.0).unwrap(),
                Marginal::normal(0.0, 1.0).unwrap(),
            ],
            &[crate::inputs::Correlation {
                a: 0,
                b: 1,
                rho: 0.5,
            }],
        )
        .unwrap();
        let err = Sobol::default().run(&corr, &rows, &px).unwrap_err();
        assert_eq!(
            err,
            SobolError::Correlated {
                names: vec!["e0".into(), "e1".into()]
            }
        );
    }
}
