//! Reliability conditional on environmental inputs, integrated over them
//! (the theorem of total probability): a machine whose room temperature is
//! random fails with `p_f = E_T[p_f(T)] = ∫ p_f(T) dF(T)`, each `p_f(T)` the
//! study of the machine at the thermal state `T` (`docs/thermal.md`,
//! "Random temperatures").
//!
//! The integral runs over `u = F(T)` on `(0, 1)`, `T = F⁻¹(u)`
//! ([`Marginal::quantile`]), by adaptive Gauss–Kronrod quadrature (the
//! 7-point Gauss rule embedded in the 15-point Kronrod rule, QUADPACK's
//! QK15): the interval whose estimated error (|K15 − G7|, the largest over
//! the cases relative to each case's `p_f`) is largest is halved until every
//! case's estimated error is within [`RELATIVE_TOLERANCE`] of its `p_f` (or
//! below [`ABSOLUTE_FLOOR`]) or [`MAX_INTERVALS`] intervals are used. A
//! failure probability that rises steeply towards one end of a room's range
//! (the usual case: the hottest hours decide) is resolved there. Each node
//! is one study at that temperature; the cases are mixed case by case
//! ([`mix`]). One environmental input is integrated.

use serde::Serialize;

use crate::error::ReliabilityError;
use crate::marginal::Marginal;
use crate::normal;
use crate::study::{CaseResult, FormCase, Study, StudyResult};

/// The relative error each case's `p_f` is integrated to.
pub const RELATIVE_TOLERANCE: f64 = 1e-6;

/// Absolute errors of `p_f` below this count as met (a case whose `p_f` is
/// ~1e-300 needs no relative accuracy).
pub const ABSOLUTE_FLOOR: f64 = 1e-300;

/// The most intervals (15 studies each) the rule uses.
pub const MAX_INTERVALS: usize = 64;

/// Kronrod nodes on `[−1, 1]`, the 7-point Gauss nodes at the odd indices
/// (QUADPACK `qk15`, Piessens et al. 1983).
#[allow(clippy::excessive_precision)] // QUADPACK's digits, as published
const XGK: [f64; 8] = [
    0.991455371120812639206854697526329,
    0.949107912342758524526189684047851,
    0.864864423359769072789712788640926,
    0.741531185599394439863864773280788,
    0.586087235467691130294144845693013,
    0.405845151377397166906606412076961,
    0.207784955007898467600689403773245,
    0.000000000000000000000000000000000,
];

/// The Kronrod weights of [`XGK`].
#[allow(clippy::excessive_precision)] // QUADPACK's digits, as published
const WGK: [f64; 8] = [
    0.022935322010529224963732008058970,
    0.063092092629978553290700663189204,
    0.104790010322250183839876322541518,
    0.140653259715525918745189590510238,
    0.169004726639267902826583426598550,
    0.190350578064785409913256402421014,
    0.204432940075298892414161999234649,
    0.209482141084727828012999174891714,
];

/// The Gauss weights of the nodes `XGK[1], XGK[3], XGK[5], XGK[7]`.
#[allow(clippy::excessive_precision)] // QUADPACK's digits, as published
const WG: [f64; 4] = [
    0.129484966168869693270611432679082,
    0.279705391489276667901467771423780,
    0.381830050505118944950369775488975,
    0.417959183673469387755102040816327,
];

/// One interval's 15 nodes in `u`, their Kronrod weights and the Gauss
/// weights of the embedded 7 (0 elsewhere), for an interval `[a, b]`.
fn interval_nodes(a: f64, b: f64) -> Vec<(f64, f64, f64)> {
    let (c, h) = (0.5 * (a + b), 0.5 * (b - a));
    let mut out = Vec::with_capacity(15);
    for k in 0..8 {
        let g = if k % 2 == 1 { WG[k / 2] } else { 0.0 };
        if k == 7 {
            out.push((c, h * WGK[7], h * g));
        } else {
            out.push((c - h * XGK[k], h * WGK[k], h * g));
            out.push((c + h * XGK[k], h * WGK[k], h * g));
        }
    }
    out
}

/// One interval of the adaptive rule with its studies' results.
struct Interval {
    a: f64,
    b: f64,
    /// `(Kronrod weight, Gauss weight, result)` per node.
    nodes: Vec<(f64, f64, StudyResult)>,
    /// Per case, `|K15 − G7|`.
    errors: Vec<f64>,
}

/// The integral over the environmental input `marginal` of the studies
/// `run(T)` (every result of `study`'s shape), by the adaptive rule of the
/// module docs: the mixed result and the rule's account.
pub fn integrate<E: From<ReliabilityError>>(
    study: &Study,
    marginal: &Marginal,
    mut run: impl FnMut(f64) -> Result<StudyResult, E>,
) -> Result<(StudyResult, Quadrature), E> {
    let mut interval = |a: f64, b: f64| -> Result<Interval, E> {
        let nodes = interval_nodes(a, b)
            .into_iter()
            .map(|(u, wk, wg)| Ok((wk, wg, run(marginal.quantile(u))?)))
            .collect::<Result<Vec<_>, E>>()?;
        let cases = nodes.first().map_or(0, |n| n.2.cases.len());
        let errors = (0..cases)
            .map(|i| {
                let (k, g) = nodes.iter().fold((0.0, 0.0), |(k, g), (wk, wg, r)| {
                    (k + wk * r.cases[i].pf, g + wg * r.cases[i].pf)
                });
                (k - g).abs()
            })
            .collect();
        Ok(Interval {
            a,
            b,
            nodes,
            errors,
        })
    };
    let mut intervals = vec![interval(0.0, 1.0)?];
    let total = |intervals: &[Interval]| -> (Vec<f64>, Vec<f64>) {
        let cases = intervals[0].errors.len();
        let pf = (0..cases)
            .map(|i| {
                (intervals.iter())
                    .flat_map(|iv| iv.nodes.iter().map(move |(w, _, r)| w * r.cases[i].pf))
                    .sum::<f64>()
            })
            .collect();
        let err = (0..cases)
            .map(|i| intervals.iter().map(|iv| iv.errors[i]).sum::<f64>())
            .collect();
        (pf, err)
    };
    let tolerance = |pf: f64| (RELATIVE_TOLERANCE * pf).max(ABSOLUTE_FLOOR);
    loop {
        let (pf, err) = total(&intervals);
        let met = pf.iter().zip(&err).all(|(p, e)| *e <= tolerance(*p));
        if met || intervals.len() >= MAX_INTERVALS {
            break;
        }
        // The interval contributing most to the worst case's excess.
        let worst = (0..intervals.len())
            .max_by(|&x, &y| {
                let score = |iv: &Interval| {
                    (iv.errors.iter().zip(&pf))
                        .map(|(e, p)| e / tolerance(*p))
                        .fold(0.0f64, f64::max)
                };
                score(&intervals[x]).total_cmp(&score(&intervals[y]))
            })
            .unwrap_or(0);
        let old = intervals.swap_remove(worst);
        let mid = 0.5 * (old.a + old.b);
        intervals.push(interval(old.a, mid)?);
        intervals.push(interval(mid, old.b)?);
    }
    let (pf, err) = total(&intervals);
    let account = Quadrature {
        intervals: intervals.len(),
        studies: 15 * intervals.len(),
        max_error: err.iter().copied().fold(0.0, f64::max),
        max_relative: (pf.iter().zip(&err))
            .filter(|(p, _)| **p >= 1e-300)
            .map(|(p, e)| e / p)
            .fold(0.0, f64::max),
        converged: pf.iter().zip(&err).all(|(p, e)| *e <= tolerance(*p)),
    };
    let weighted: Vec<(f64, StudyResult)> = intervals
        .into_iter()
        .flat_map(|iv| iv.nodes.into_iter().map(|(w, _, r)| (w, r)))
        .collect();
    Ok((mix(study, &weighted)?, account))
}

/// The adaptive rule's account.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Quadrature {
    /// Intervals of `u` it ended with.
    pub intervals: usize,
    /// Studies it ran (15 per interval).
    pub studies: usize,
    /// The largest estimated error of a case's `p_f`.
    pub max_error: f64,
    /// The largest estimated error relative to the case's `p_f` (cases with
    /// `p_f ≥ 1e-300`).
    pub max_relative: f64,
    /// Every case within [`RELATIVE_TOLERANCE`] (or [`ABSOLUTE_FLOOR`]).
    pub converged: bool,
}

/// The cases of the studies at a rule's nodes, `(weight, result)` (every
/// result of the same study shape as `study`), mixed case by case:
/// `p_f = Σ w_k p_f,k`, `R = 1 − p_f`, `β = −Φ⁻¹(p_f)`; a sampler's standard
/// error `Σ w_k s_k`, the bound whatever the nodes' correlation (their runs
/// share the seed's streams), and its samples summed; every limit-state call summed; FORM's account: converged when
/// every node's is, the iterations summed, the termination of the node that
/// contributes most to `p_f`, never `exact` (a quadrature).
pub fn mix(study: &Study, results: &[(f64, StudyResult)]) -> Result<StudyResult, ReliabilityError> {
    let Some((_, first)) = results.first() else {
        return Err(ReliabilityError::Dimension {
            what: "quadrature nodes",
            expected: 1,
            found: 0,
        });
    };
    let cases = (0..first.cases.len())
        .map(|i| {
            let at = |k: usize| &results[k].1.cases[i];
            let pf: f64 = (0..results.len()).map(|k| results[k].0 * at(k).pf).sum();
            let pf = pf.clamp(0.0, 1.0);
            let dominant = (0..results.len())
                .max_by(|&a, &b| (results[a].0 * at(a).pf).total_cmp(&(results[b].0 * at(b).pf)))
                .unwrap_or(0);
            let sampled = at(0).std_error.is_some();
            let std_error = sampled.then(|| {
                (0..results.len())
                    .map(|k| results[k].0 * at(k).std_error.unwrap_or(0.0))
                    .sum::<f64>()
            });
            let form = at(0).form.map(|f0| FormCase {
                termination: at(dominant).form.map_or(f0.termination, |f| f.termination),
                converged: (0..results.len()).all(|k| at(k).form.is_none_or(|f| f.converged)),
                iterations: (0..results.len())
                    .map(|k| at(k).form.map_or(0, |f| f.iterations))
                    .sum(),
                exact: false,
            });
            let unconverged = (0..results.len()).find(|&k| !at(k).sampler_converged());
            CaseResult {
                target: at(0).target,
                point: at(0).point.clone(),
                reliability: 1.0 - pf,
                pf,
                beta: normal::beta_from_pf(pf),
                std_error,
                cov: std_error.map(|s| if pf > 0.0 { s / pf } else { f64::INFINITY }),
                samples: sampled
                    .then(|| (0..results.len()).map(|k| at(k).samples.unwrap_or(0)).sum()),
                form,
                calls: crate::form::Calls {
                    values: (0..results.len()).map(|k| at(k).calls.values).sum(),
                    gradients: (0..results.len()).map(|k| at(k).calls.gradients).sum(),
                },
                stopping: unconverged.and_then(|k| at(k).stopping).or(at(0).stopping),
                levels: None,
                sorm: None,
            }
        })
        .collect();
    Ok(study.finish(first.method, cases))
}
