//! How an identification predicts measurements it was not fitted to
//! (held-out measurements, from a file or split off the fitted ones): the error a machine shows
//! at held-out poses before correction (the measured values `b`, from the
//! set-ups' estimated positions when there are set-ups) and after
//! it (`b − A x̂`, the
//! measured values less what the estimates predict through the same exact
//! sensitivity rows the fit used), the numbers a calibration engineer
//! reports for a calibration (`docs/identify.md`, "Prediction at held-out
//! poses").

use serde::Serialize;

use super::identify::Identification;
use super::measurements::Design;

/// The error of a set of measurements.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ErrorStats {
    /// The mean over the records of each record's error: `|dp|` for a
    /// tool-point deviation, `|d|` for a deviation along a direction (mm).
    pub mean: f64,
    /// The largest record error (mm).
    pub max: f64,
    /// The root mean square over the scalar rows (mm).
    pub rms: f64,
}

impl ErrorStats {
    /// The statistics of `values`, one per scalar row, each row's record
    /// given by `record` (rows of one record consecutive).
    fn of(values: &[f64], record: &[usize]) -> ErrorStats {
        let rms = (values.iter().map(|v| v * v).sum::<f64>() / values.len().max(1) as f64).sqrt();
        let mut magnitudes: Vec<f64> = Vec::new();
        let mut last = None;
        for (v, &r) in values.iter().zip(record) {
            if last != Some(r) {
                magnitudes.push(0.0);
                last = Some(r);
            }
            if let Some(m) = magnitudes.last_mut() {
                *m += v * v;
            }
        }
        let magnitudes: Vec<f64> = magnitudes.into_iter().map(f64::sqrt).collect();
        ErrorStats {
            mean: magnitudes.iter().sum::<f64>() / magnitudes.len().max(1) as f64,
            max: magnitudes.iter().copied().fold(0.0, f64::max),
            rms,
        }
    }
}

/// The prediction of an identification at other measurements.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Prediction {
    /// Measurement records (CSV rows).
    pub measurements: usize,
    /// Scalar rows (3 per point, 1 per direction).
    pub rows: usize,
    /// The measured error: what the machine shows uncorrected.
    pub before: ErrorStats,
    /// The measured error less the estimates' prediction: what the machine
    /// would show corrected by them.
    pub after: ErrorStats,
}

/// The prediction of `r`'s estimates at the rows of `design`, a design of
/// other measurements of the same machine (its columns `r`'s unknowns, in
/// the same order).
pub fn predict(design: &Design, r: &Identification) -> Prediction {
    let (x, _) = r.solution();
    let predicted: Vec<f64> = (0..design.b.len())
        .map(|i| design.a.row(i).iter().zip(&x).map(|(a, x)| a * x).sum())
        .collect();
    predict_rows(design, &predicted, &x)
}

/// The prediction at the rows of `design` when the model with the
/// unknowns `x` predicts `predicted` there (one value per scalar row): the
/// exact kinematics of the exact-kinematics iteration's values, say.
///
/// With set-ups ([`super::Setup`]: a sphere probed, an R-test ball) the
/// error the machine shows uncorrected is measured from the set-ups'
/// estimated positions: `b − A_s x_s` (the set-ups' columns of the design,
/// which are exact: a position enters linearly), not `b` (a sphere
/// record's `b` is the negated nominal tool point).
pub fn predict_rows(design: &Design, predicted: &[f64], x: &[f64]) -> Prediction {
    let ne = design.machine_errors();
    let before: Vec<f64> = (0..design.b.len())
        .map(|i| {
            let setup: f64 = (ne..x.len()).map(|j| design.a[(i, j)] * x[j]).sum();
            design.b[i] - setup
        })
        .collect();
    let after: Vec<f64> = (design.b.iter().zip(predicted))
        .map(|(b, p)| b - p)
        .collect();
    let record: Vec<usize> = design.origin.iter().map(|(r, _)| *r).collect();
    let mut records = record.clone();
    records.dedup();
    Prediction {
        measurements: records.len(),
        rows: design.b.len(),
        before: ErrorStats::of(&before, &record),
        after: ErrorStats::of(&after, &record),
    }
}
