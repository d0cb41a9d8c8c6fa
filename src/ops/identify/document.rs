//! The result document of `chain identify` (measured-machines spec,
//! section 4, plus the additions of `docs/identify.md`): what the CLI prints
//! with `--format json` and the Python package returns, and the values file
//! `--values-out` writes. Assembled here, from the library's typed results,
//! so that every front end gives the same document for the same input.

use std::collections::BTreeSet;
use std::fmt::Write as _;

use chain_core::measured::identify::{Estimate, IdentifyOptions, NoiseRule, Prior, Residual};
use chain_core::measured::iterate::{self, FirstOrderCheck, Iteration, ANGLE_LIMIT};
use chain_core::measured::predict::{predict, predict_rows, Prediction};
use chain_core::measured::subset::{ChosenBy, FixedStatus, Subset, TERM_CUTOFF};
use chain_core::measured::{
    identify, Design, Holdout, Identification, MeasuredComponent, Measurements, SetupKind,
};
use chain_core::named::NameMap;
use chain_core::Machine;
use serde::Serialize;

use super::{check_fit, IdentifyOpsError};

/// One group of unknowns the data cannot separate.
#[derive(Debug, Clone, Serialize)]
pub struct GroupDoc {
    /// The unknowns of the group.
    pub errors: Vec<String>,
    /// How many independent combinations of them the data cannot tell.
    pub vectors: usize,
    /// How many of those the measurements see, but only within their noise
    /// (weak directions the noise rule left out; absent when none).
    #[serde(skip_serializing_if = "is_zero")]
    pub weak: usize,
    /// The same in words.
    pub explanation: String,
}

/// One of the largest standardised residuals.
#[derive(Debug, Clone, Serialize)]
pub struct ResidualDoc {
    /// The CSV line of its measurement.
    pub line: usize,
    /// Its component ([`MeasuredComponent::name`]:
    /// `dpx`, `dpy`, `dpz` or `d`).
    pub component: &'static str,
    /// `b − A x`.
    pub residual: f64,
    /// `t = r / (σ √(1 − h))`.
    pub standardised: f64,
    /// The row's leverage `h`.
    pub leverage: f64,
    /// `|t|` above [`chain_core::measured::identify::OUTLIER_LIMIT`].
    pub outlier: bool,
}

/// The result document (spec section 4's keys first, then additions).
#[derive(Debug, Clone, Serialize)]
pub struct IdentifyDocument {
    /// The machine's name.
    pub machine: String,
    /// Measurement records (CSV rows).
    pub measurements: usize,
    /// Unknowns.
    pub parameters: usize,
    /// The rank of the design.
    pub rank: usize,
    /// The condition of the equilibrated design on its identifiable part.
    pub condition: f64,
    /// The estimates, by name.
    pub estimates: NameMap<String, Estimate>,
    /// The null-space vectors as `{error: component}` maps.
    pub unidentifiable: Vec<NameMap<String, f64>>,
    /// The residual.
    pub residual: Residual,
    // --- additions ---
    /// The measurement file as named in messages.
    pub file: String,
    /// Scalar rows of the design (3 per point, 1 per direction).
    pub rows: usize,
    /// Whether the rows had a `std`.
    pub weighted: bool,
    /// Whether the statistics prior was used.
    pub prior: bool,
    /// The machine's frame.
    pub frame: &'static str,
    /// The groups of the null space, in words.
    pub groups: Vec<GroupDoc>,
    /// The largest standardised residuals.
    pub largest_residuals: Vec<ResidualDoc>,
    /// How many of them are flagged as likely outliers.
    pub outliers: usize,
    /// How the rank was decided (the noise rule or a fixed tolerance).
    pub noise: NoiseRule,
    /// The estimated subset, its least-squares solution and the fixed
    /// unknowns' relations (absent with `--prior`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub subset: Option<SubsetDoc>,
    /// The linear estimate against the exact kinematics at the measured
    /// poses.
    pub first_order: FirstOrderDoc,
    /// `--iterate`: the fit on the exact kinematics.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub iteration: Option<IterationDoc>,
    /// The prediction at held-out measurements (`--validate`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub validation: Option<Validation>,
    /// The set-ups whose positions were estimated beside the errors
    /// (`--spheres`, `--setup ball`; absent without them): never written
    /// into values.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub setups: Vec<SetupDoc>,
}

/// An estimated set-up position in the document: a sphere's centre, or an
/// R-test ball's set-up offset, in the workpiece (table) frame, mm.
#[derive(Debug, Clone, Serialize)]
pub struct SetupDoc {
    /// Its identifier.
    pub name: String,
    /// `sphere`, `ball` or `circle`.
    pub kind: SetupKind,
    /// A circle's plane.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub plane: Option<chain_core::measured::circular::Plane>,
    /// What its three unknowns are (`x`, `y`, `z`; a circle's plane's two
    /// axes and `length`).
    pub coordinates: [&'static str; 3],
    /// Their names among the estimates.
    pub unknowns: [String; 3],
    /// Its position `[x, y, z]` from the reported solution (`--iterate`'s
    /// exact fit when given, else the least-squares subset, else the
    /// posterior); a circle's offsets along the plane's two axes and the
    /// bar's length offset.
    pub position: [f64; 3],
    /// The std of each coordinate (null where it cannot be estimated).
    pub std: [Option<f64>; 3],
}

/// The first-order check in the document.
#[derive(Debug, Clone, Serialize)]
pub struct FirstOrderDoc {
    /// `max |f_i(x̂) − a_i x̂|` (measurement units).
    pub max: f64,
    /// Its root mean square.
    pub rms: f64,
    /// The noise scale it is compared with (weighted units).
    pub noise: Option<f64>,
    /// Whether some row's difference exceeds the noise.
    pub exceeds_noise: bool,
    /// The angle limit of the flags (rad).
    pub angle_limit: f64,
    /// Angular errors beyond it at the measured poses: the largest angle.
    pub large_angles: NameMap<String, f64>,
    /// The same in words.
    pub words: String,
}

impl FirstOrderDoc {
    fn new(c: &FirstOrderCheck, iterated: bool, prior: bool) -> FirstOrderDoc {
        let advice = if iterated {
            ""
        } else if prior {
            ": identify without --prior and with --iterate"
        } else {
            ": identify with --iterate"
        };
        let mut words = if c.noise.is_none() {
            format!(
                "the first-order model differs from the exact kinematics by up to {} at the measured poses (no noise estimate to compare with)",
                significant(c.max)
            )
        } else if c.exceeds_noise {
            format!(
                "the first-order model differs from the exact kinematics by up to {} at the measured poses, more than the noise{advice}",
                significant(c.max)
            )
        } else {
            format!(
                "the first-order model is within the noise of the exact kinematics at the measured poses (differences up to {})",
                significant(c.max)
            )
        };
        if !c.large_angles.is_empty() {
            let names: Vec<String> = (c.large_angles.iter())
                .map(|(n, a)| format!("{n} ({} rad)", significant(*a)))
                .collect();
            let _ = write!(
                words,
                "; beyond the first-order range of {ANGLE_LIMIT} rad: {}",
                and_list(&names)
            );
        }
        FirstOrderDoc {
            max: c.max,
            rms: c.rms,
            noise: c.noise,
            exceeds_noise: c.exceeds_noise,
            angle_limit: ANGLE_LIMIT,
            large_angles: c.large_angles.iter().cloned().collect(),
            words,
        }
    }
}

/// `--iterate` in the document.
#[derive(Debug, Clone, Serialize)]
pub struct IterationDoc {
    /// `levenberg-marquardt`.
    pub method: &'static str,
    /// Iterations (Jacobian evaluations).
    pub iterations: usize,
    /// Whether it converged.
    pub converged: bool,
    /// The weighted sum of squares of the exact model at the linear
    /// estimate, and at the solution.
    pub rss_linear: f64,
    /// At the solution.
    pub rss: f64,
    /// Root mean square of `b − f(x)` at the solution.
    pub rms: f64,
    /// The largest `|b − f(x)|` at the solution.
    pub max: f64,
    /// Every error's value and std at the solution (fixed ones 0, null).
    pub estimates: NameMap<String, Estimate>,
    /// The solution less the linear estimate, per estimated error.
    pub change: NameMap<String, f64>,
}

impl IterationDoc {
    fn new(it: &Iteration, names: &[String]) -> IterationDoc {
        IterationDoc {
            method: "levenberg-marquardt",
            iterations: it.iterations,
            converged: it.converged,
            rss_linear: it.rss_linear,
            rss: it.rss,
            rms: it.rms,
            max: it.max,
            estimates: names
                .iter()
                .cloned()
                .zip(it.estimates.iter().copied())
                .collect(),
            change: (it.estimated.iter())
                .map(|&j| (names[j].clone(), it.change[j]))
                .collect(),
        }
    }
}

/// The estimated subset in the document (`docs/identify.md`, "What is
/// estimated and what is fixed").
#[derive(Debug, Clone, Serialize)]
pub struct SubsetDoc {
    /// How the subset was chosen, in words.
    pub method: &'static str,
    /// `elimination`, `fix` or `estimate`.
    pub chosen_by: ChosenBy,
    /// Relation weights (equilibrated) below this are left out of `words`
    /// and `combinations`.
    pub term_cutoff: f64,
    /// The estimated unknowns.
    pub estimated: Vec<String>,
    /// The least-squares estimates of every unknown, the fixed ones at 0
    /// with `std` null.
    pub estimates: NameMap<String, Estimate>,
    /// The fixed unknowns.
    pub fixed: Vec<FixedDoc>,
    /// For each estimated unknown that carries fixed ones: the combination
    /// its estimate stands for, `{name: weight}` (itself with weight 1).
    pub combinations: NameMap<String, NameMap<String, f64>>,
    /// Root mean square of `b − A x` of this solution.
    pub rms: f64,
}

/// A fixed unknown in the document.
#[derive(Debug, Clone, Serialize)]
pub struct FixedDoc {
    /// Its name.
    pub error: String,
    /// `unseen`, `redundant`, `weak` or `fixed`.
    pub status: FixedStatus,
    /// Its design column as a combination of the estimated ones' (in the
    /// unknowns' own units), every weight whose equilibrated share is
    /// above the round-off [`ROUND_OFF`].
    pub relation: NameMap<String, f64>,
    /// The part of its effect the estimated ones do not carry (relative).
    pub residual: f64,
    /// The relation in words (weights below the cutoff left out).
    pub words: String,
}

/// Relation weights whose equilibrated share is below this are round-off
/// and left out of the JSON's `relation`.
pub const ROUND_OFF: f64 = 1e-12;

/// `c·NAME` in a sum: the sign as an operator unless first, a weight of ±1
/// left out, 4 significant digits otherwise.
fn term(c: f64, name: &str, first: bool) -> String {
    let sign = if c < 0.0 {
        if first {
            "−"
        } else {
            " − "
        }
    } else if first {
        ""
    } else {
        " + "
    };
    let a = c.abs();
    if (a - 1.0).abs() < 1e-9 {
        format!("{sign}{name}")
    } else {
        format!("{sign}{}·{name}", significant(a))
    }
}

/// `v` to 4 significant digits, without trailing zeros.
fn significant(v: f64) -> String {
    if (1e-3..1e5).contains(&v) {
        let digits = (3 - v.log10().floor() as i32).max(0) as usize;
        let t = format!("{v:.digits$}");
        if t.contains('.') {
            t.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            t
        }
    } else {
        format!("{v:.3e}")
    }
}

impl SubsetDoc {
    /// The document of `s` over the unknowns `names`.
    pub fn new(s: &Subset, names: &[String]) -> SubsetDoc {
        let fixed: Vec<FixedDoc> = s
            .fixed
            .iter()
            .map(|f| {
                let terms: Vec<(usize, f64)> = (f.relation.iter().zip(&f.shares))
                    .filter(|(_, share)| share.abs() >= TERM_CUTOFF)
                    .map(|(&(k, c), _)| (k, c))
                    .collect();
                let sum: String = (terms.iter().enumerate())
                    .map(|(i, &(k, c))| term(c, &names[k], i == 0))
                    .collect();
                let words = match f.status {
                    FixedStatus::Unseen => {
                        format!("{} has no effect on these measurements", names[f.index])
                    }
                    _ if terms.is_empty() => format!(
                        "{} acts on these measurements independently of the estimated parameters",
                        names[f.index]
                    ),
                    FixedStatus::Redundant => format!("{} acts as {sum}", names[f.index]),
                    FixedStatus::Weak | FixedStatus::Fixed => format!(
                        "{} acts almost as {sum} (its own part: {} of its effect)",
                        names[f.index],
                        significant(f.residual)
                    ),
                };
                FixedDoc {
                    error: names[f.index].clone(),
                    status: f.status,
                    relation: (f.relation.iter().zip(&f.shares))
                        .filter(|(_, share)| share.abs() >= ROUND_OFF)
                        .map(|(&(k, c), _)| (names[k].clone(), c))
                        .collect(),
                    residual: f.residual,
                    words,
                }
            })
            .collect();
        let combinations = s
            .estimated
            .iter()
            .filter_map(|&k| {
                let carried: Vec<(String, f64)> = (s.fixed.iter())
                    .filter_map(|f| {
                        let at = f.relation.iter().position(|&(i, _)| i == k)?;
                        (f.shares[at].abs() >= TERM_CUTOFF)
                            .then(|| (names[f.index].clone(), f.relation[at].1))
                    })
                    .collect();
                (!carried.is_empty()).then(|| {
                    let mut all = vec![(names[k].clone(), 1.0)];
                    all.extend(carried);
                    (names[k].clone(), NameMap(all))
                })
            })
            .collect();
        SubsetDoc {
            method: "column-pivoted QR (largest remaining column norm) of the weighted design, columns scaled to unit norm, truncated to the directions the data determine; least squares on the chosen columns with the others at 0",
            chosen_by: s.chosen_by,
            term_cutoff: TERM_CUTOFF,
            estimated: s.estimated.iter().map(|&k| names[k].clone()).collect(),
            estimates: names.iter().cloned().zip(s.estimates.iter().copied()).collect(),
            fixed,
            combinations,
            rms: s.rms,
        }
    }

    /// The combination the estimate of `name` stands for, in words
    /// (`DZ2 + DZ3 + DZ4`), when it carries fixed unknowns.
    pub fn combination_words(&self, name: &str) -> Option<String> {
        let (_, terms) = self.combinations.0.iter().find(|(n, _)| n == name)?;
        Some(
            (terms.0.iter().enumerate())
                .map(|(i, (n, c))| term(*c, n, i == 0))
                .collect(),
        )
    }
}

/// The prediction of the estimates at measurements not used in the fit
/// (`chain identify --validate M2.csv`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Validation {
    /// The held-out measurement file as named in messages.
    pub file: String,
    /// `--holdout`: the fraction and seed that chose the held-out records
    /// from the measurements (absent with `--validate`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub holdout: Option<Holdout>,
    /// `--holdout`: the CSV lines of the held-out records.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lines: Option<Vec<usize>>,
    /// Records, rows, the error before and after.
    #[serde(flatten)]
    pub prediction: Prediction,
}

/// What [`identify_document`] gives: the document, the typed
/// identification, the first-order check and `--iterate`'s fit.
#[derive(Debug, Clone)]
pub struct Identified {
    /// The document.
    pub document: IdentifyDocument,
    /// The identification.
    pub result: Identification,
    /// The first-order check.
    pub check: FirstOrderCheck,
    /// `--iterate`'s fit.
    pub iteration: Option<Iteration>,
    /// The count of set-ups whose positions are the last `3 × setups`
    /// unknowns.
    pub setups: usize,
}

/// `chain identify`: the design of `measurements` through the machine's
/// exact sensitivity, the weighted least-squares solve (or the posterior of
/// the `statistics` prior when `prior`), the first-order check against the
/// exact kinematics, with `iterate` the fit on the exact kinematics, and
/// the document.
pub fn identify_document(
    machine: &Machine,
    measurements: &Measurements,
    prior: bool,
    options: &IdentifyOptions,
    iterate: bool,
    validation: Option<&Measurements>,
) -> Result<Identified, IdentifyOpsError> {
    check_fit(prior, options, iterate)?;
    let model = chain_core::compile(machine);
    let design_of = |m: &Measurements| {
        Design::of(&model, machine, m).map_err(|reason| IdentifyOpsError::Design {
            file: m.file.clone(),
            reason,
        })
    };
    let design = design_of(measurements)?;
    let held_out = validation
        .map(|v| design_of(v).map(|d| (v, d)))
        .transpose()?;
    let prior = if prior {
        let ne = design.machine_errors();
        let prior = Prior::from_machine(machine, &design.errors[..ne])
            .map_err(IdentifyOpsError::Identify)?;
        Some(prior.with_free(design.errors.len() - ne))
    } else {
        None
    };
    let result = identify(&design, prior.as_ref(), options).map_err(IdentifyOpsError::Identify)?;
    let (linear, _) = result.solution();
    let check = iterate::check(machine, &measurements.rows, &design, &result, &linear);
    let iteration = match (&result.subset, iterate) {
        (Some(sub), true) => Some(iterate::iterate(
            machine,
            &measurements.rows,
            &design,
            &sub.estimated,
            &linear,
        )),
        _ => None,
    };
    let mut doc = IdentifyDocument::new(
        machine,
        &measurements.file,
        measurements,
        &design,
        &result,
        &check,
        iteration.as_ref(),
    );
    doc.validation = held_out.map(|(v, d)| Validation {
        file: v.file.clone(),
        holdout: None,
        lines: None,
        prediction: match &iteration {
            Some(it) => {
                let x: Vec<f64> = it.estimates.iter().map(|e| e.value).collect();
                let (rows, _) = iterate::exact_rows(machine, &v.rows, &d, &x, false);
                predict_rows(&d, &rows, &x)
            }
            None => predict(&d, &result),
        },
    });
    Ok(Identified {
        document: doc,
        result,
        check,
        iteration,
        setups: design.setups.len(),
    })
}

impl IdentifyDocument {
    /// The document of `r`, the identification from `measurements` (named
    /// `file`) through `design`, with its first-order check and
    /// `--iterate`'s fit.
    pub fn new(
        m: &Machine,
        file: &str,
        measurements: &Measurements,
        design: &Design,
        r: &Identification,
        check: &FirstOrderCheck,
        iteration: Option<&Iteration>,
    ) -> IdentifyDocument {
        let groups = r
            .groups
            .iter()
            .map(|g| {
                let errors: Vec<String> = g.members.iter().map(|&j| r.errors[j].clone()).collect();
                GroupDoc {
                    explanation: explain(design, r, &g.members, g.vectors.len(), g.weak),
                    vectors: g.vectors.len(),
                    weak: g.weak,
                    errors,
                }
            })
            .collect();
        IdentifyDocument {
            machine: m.name.clone(),
            measurements: measurements.rows.len(),
            parameters: r.parameters,
            rank: r.rank,
            condition: r.condition,
            estimates: r.estimates.clone(),
            unidentifiable: r.unidentifiable.clone(),
            residual: r.residual,
            file: file.to_string(),
            rows: r.rows,
            weighted: r.weighted,
            prior: r.prior,
            frame: m.frame.name(),
            groups,
            largest_residuals: (r.largest_residuals.iter())
                .map(|s| ResidualDoc {
                    line: measurements.rows[design.origin[s.row].0].line,
                    component: s.component,
                    residual: s.residual,
                    standardised: s.standardised,
                    leverage: s.leverage,
                    outlier: s.outlier,
                })
                .collect(),
            outliers: r.outliers,
            first_order: FirstOrderDoc::new(check, iteration.is_some(), r.prior),
            iteration: iteration.map(|it| IterationDoc::new(it, &r.errors)),
            noise: r.noise,
            subset: r.subset.as_ref().map(|s| SubsetDoc::new(s, &r.errors)),
            validation: None,
            setups: setup_docs(design, r, iteration),
        }
    }
}

/// The set-ups' estimated positions: the last `3 × setups` unknowns of the
/// reported solution.
fn setup_docs(design: &Design, r: &Identification, iteration: Option<&Iteration>) -> Vec<SetupDoc> {
    let estimates: Vec<Estimate> = match (iteration, &r.subset) {
        (Some(it), _) => it.estimates.clone(),
        (None, Some(sub)) => sub.estimates.clone(),
        (None, None) => r.estimates.0.iter().map(|(_, e)| *e).collect(),
    };
    let ne = design.machine_errors();
    (design.setups.iter().enumerate())
        .map(|(g, setup)| {
            let at = |l: usize| estimates[ne + 3 * g + l];
            SetupDoc {
                name: setup.name.clone(),
                kind: setup.kind,
                plane: setup.plane,
                coordinates: setup.coordinates(),
                unknowns: setup.unknowns(),
                position: std::array::from_fn(|l| at(l).value),
                std: std::array::from_fn(|l| at(l).std),
            }
        })
        .collect()
}

/// Whether a count is zero (a key left out of the document).
fn is_zero(n: &usize) -> bool {
    *n == 0
}

/// `a`, `a and b`, `a, b and c`.
fn and_list(names: &[String]) -> String {
    match names {
        [] => String::new(),
        [one] => one.clone(),
        [init @ .., last] => format!("{} and {last}", init.join(", ")),
    }
}

/// A group of the null space in words, derived from the design's columns
/// of its members: when they are all parallel (column rank 1), which
/// measured components they act on (named by the quantities they measure,
/// in the components' order) and whether as a constant (an offset);
/// otherwise how many independent combinations they act through. A group
/// with `weak` directions (seen, but only within the noise) says so instead
/// of "cannot be seen".
fn explain(
    design: &Design,
    r: &Identification,
    members: &[usize],
    vectors: usize,
    weak: usize,
) -> String {
    let names: Vec<String> = members.iter().map(|&j| r.errors[j].clone()).collect();
    let list = and_list(&names);
    if weak > 0 {
        // Seen, within the noise: not "cannot be seen".
        let combinations = |k: usize| {
            if k == 1 {
                "one combination".to_string()
            } else {
                format!("{k} combinations")
            }
        };
        let unseen = vectors - weak;
        return format!(
            "{list} act through {} independent combinations; {} of them {} seen by these measurements only within their noise (the noise rule leaves {} out){}",
            members.len() - unseen,
            combinations(weak),
            if weak == 1 { "is" } else { "are" },
            if weak == 1 { "it" } else { "them" },
            if unseen > 0 {
                format!("; {} cannot be seen at all", combinations(unseen))
            } else {
                String::new()
            }
        );
    }
    if r.prior {
        return format!(
            "the measurements leave {} of {list} at the prior (posterior std above {} × the prior std along {})",
            if vectors == 1 { "one combination".to_string() } else { format!("{vectors} combinations") },
            chain_core::measured::identify::UNINFORMED,
            if vectors == 1 { "it" } else { "them" }
        );
    }
    let rank = members.len() - vectors;
    if rank == 0 {
        return if names.len() == 1 {
            format!("{list} has no effect on these measurements")
        } else {
            format!("{list} have no effect on these measurements")
        };
    }
    if rank == 1 {
        // The member whose column is largest stands for the group.
        let a = &design.a;
        let best = members
            .iter()
            .copied()
            .max_by(|&i, &j| a.column(i).norm().total_cmp(&a.column(j).norm()))
            .unwrap_or(members[0]);
        let col = a.column(best);
        let scale = col.amax();
        // The design's components in their order (by kind, then row).
        let present: BTreeSet<MeasuredComponent> = design.origin.iter().map(|&(_, c)| c).collect();
        let mut on: Vec<String> = Vec::new();
        let mut constant = true;
        for comp in present {
            let values: Vec<f64> = (0..a.nrows())
                .filter(|&i| design.origin[i].1 == comp)
                .map(|i| col[i])
                .collect();
            if values.iter().any(|v| v.abs() > 1e-9 * scale) {
                on.push(comp.quantity().to_string());
                let first = values[0];
                if values.iter().any(|v| (v - first).abs() > 1e-9 * scale) {
                    constant = false;
                }
            }
        }
        let what = if constant {
            format!("one offset in {}", and_list(&on))
        } else {
            format!("one combined error in {}", and_list(&on))
        };
        return format!("{list} only act as {what}");
    }
    format!(
        "{list} only act through {rank} independent combinations; {vectors} combination{} of them cannot be seen in these measurements",
        if vectors == 1 { "" } else { "s" }
    )
}

/// The estimates as a values file (spec section 2, plus `std` per constant
/// and the `correlation` list, one `[NAME, NAME, ρ]` per pair with ρ ≠ 0:
/// the form `chain reliability --values` reads, docs/posterior.md);
/// `source` names the measurement file in its first comment. Without a
/// prior the values are the subset's least-squares solution: a fixed
/// unknown is written as its nominal value 0 without a `std`, with a
/// comment saying why it is fixed; a redundant one (its effect carried by
/// estimated errors) names them in `carried_by`, so that a reliability
/// study takes it as exact instead of counting its spread twice
/// (docs/posterior.md, "Fixed and carried"); the others keep their
/// `statistics` spread;
/// with `--iterate` the values are the exact fit's. Angular errors beyond
/// the first-order range are named in a comment.
pub fn values_file(m: &Machine, source: &str, identified: &Identified) -> String {
    let r = &identified.result;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# written by chain identify from {}: {} rows, rank {} of {} unknowns{}",
        source,
        r.rows,
        r.rank,
        r.parameters,
        if r.prior {
            ", posterior with the statistics prior"
        } else {
            ""
        }
    );
    // The set-ups' positions (the unknowns after the machine's errors) are
    // the instrument's, not the machine's: never written into values.
    let ne = r.parameters - 3 * identified.setups;
    let mut carried: Vec<(String, Vec<String>)> = Vec::new();
    let estimates: Vec<Estimate> = match &r.subset {
        Some(sub) => {
            let doc = SubsetDoc::new(sub, &r.errors);
            for f in (doc.fixed.iter()).filter(|f| f.status == FixedStatus::Redundant) {
                let carriers: Vec<String> = (f.relation.0.iter())
                    .map(|(name, _)| name.clone())
                    .filter(|name| r.errors[..ne].contains(name))
                    .collect();
                if !carriers.is_empty() {
                    carried.push((f.error.clone(), carriers));
                }
            }
            if !doc.fixed.is_empty() {
                let _ = writeln!(
                    s,
                    "# least squares on {} of {} unknowns; fixed at their nominal value 0 (no std; a redundant one is carried_by the estimates that carry its effect and taken as exact, the others keep their statistics spread):",
                    doc.estimated.len(),
                    r.parameters
                );
                for f in &doc.fixed {
                    let _ = writeln!(s, "#   {} ({}): {}", f.error, f.status.words(), f.words);
                }
                for name in &doc.estimated {
                    if let Some(w) = doc.combination_words(name) {
                        let _ = writeln!(s, "# {name} stands for {w}");
                    }
                }
            }
            match &identified.iteration {
                Some(it) => it.estimates.clone(),
                None => sub.estimates.clone(),
            }
        }
        None => r.estimates.0.iter().map(|(_, e)| *e).collect(),
    };
    let covariance = match &identified.iteration {
        Some(it) => &it.covariance,
        None => r.solution().1,
    };
    if let Some(it) = &identified.iteration {
        let _ = writeln!(
            s,
            "# --iterate: Levenberg-Marquardt on the exact kinematics from the linear estimate, {} iterations{}, weighted residual sum of squares {:e} -> {:e}",
            it.iterations,
            if it.converged { ", converged" } else { ", NOT converged" },
            it.rss_linear,
            it.rss
        );
    }
    for (name, angle) in &identified.check.large_angles {
        let _ = writeln!(
            s,
            "# {name} reaches {angle:e} rad at the measured poses: beyond the first-order range ({ANGLE_LIMIT} rad){}",
            if identified.iteration.is_some() {
                ""
            } else if r.prior {
                "; identify without --prior and with --iterate"
            } else {
                "; identify with --iterate"
            }
        );
    }
    let _ = writeln!(s, "machine: {}", m.name);
    let _ = writeln!(s, "units: {{linear: mm, angular: rad}}");
    let _ = writeln!(s, "values:");
    let fixed = |j: usize| {
        r.subset
            .as_ref()
            .is_some_and(|sub| !sub.estimated.contains(&j))
    };
    for (name, e) in r.errors.iter().zip(&estimates).take(ne) {
        let carriers = carried.iter().find(|(n, _)| n == name);
        match (e.std, carriers) {
            (Some(std), _) => {
                let _ = writeln!(s, "  {name}: {{value: {:?}, std: {:?}}}", e.value, std);
            }
            (None, Some((_, by))) => {
                let by = by.join(", ");
                let _ = writeln!(s, "  {name}: {{value: {:?}, carried_by: [{by}]}}", e.value);
            }
            (None, None) => {
                let _ = writeln!(s, "  {name}: {:?}", e.value);
            }
        }
    }
    let all_std = (0..ne).all(|j| fixed(j) || estimates[j].std.is_some());
    if all_std {
        let n = ne;
        let sd: Vec<f64> = (0..n).map(|j| covariance[(j, j)].max(0.0).sqrt()).collect();
        let mut pairs = Vec::new();
        for i in 0..n {
            for j in i + 1..n {
                if sd[i] > 0.0 && sd[j] > 0.0 && !fixed(i) && !fixed(j) {
                    let rho = (covariance[(i, j)] / (sd[i] * sd[j])).clamp(-1.0, 1.0);
                    if rho != 0.0 {
                        pairs.push((i, j, rho));
                    }
                }
            }
        }
        if !pairs.is_empty() {
            let _ = writeln!(
                s,
                "# the correlation of each pair of estimates (pairs not listed: exactly 0)"
            );
            let _ = writeln!(s, "correlation:");
            for (i, j, rho) in pairs {
                let _ = writeln!(s, "  - [{}, {}, {rho:?}]", r.errors[i], r.errors[j]);
            }
        }
    }
    s
}
