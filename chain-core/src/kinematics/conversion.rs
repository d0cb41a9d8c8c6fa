//! One run of the motion conversion of "Precision Machining Technology of
//! Jewelry on CNC Machine Tool" (2022; seed 002, see [`crate::motion`]): the exact CNC motion sampled over the
//! roll, how well it reproduces the generator, its Maclaurin series and the
//! truncation error of every order, and the order a tolerance needs.
//!
//! [`Conversion::run`] is what `chain motion` computes; the CLI only renders
//! it.

use crate::model::JointKind;
use crate::motion::{self, Motion, MotionError, PoseError, Series};

/// What a run computes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunOptions {
    /// Instants, evenly spaced over the roll interval (both ends included).
    pub samples: usize,
    /// The requested order of the Maclaurin series.
    pub order: usize,
    /// With a tolerance: the orders are computed up to
    /// `max(order, max_order)`, the search for the required order's bound.
    pub max_order: usize,
    /// The accuracy wanted of the prismatic axes (model units, mm) and, unless
    /// `angular_tolerance` is given, of the rotary ones (rad).
    pub tolerance: Option<f64>,
    /// The accuracy wanted of the rotary axes (rad); needs `tolerance`.
    pub angular_tolerance: Option<f64>,
}

/// The smallest series order that meets a per-axis tolerance over the roll.
#[derive(Debug, Clone, PartialEq)]
pub struct RequiredOrder {
    /// The tolerance of each CNC axis (in the CNC variables' order).
    pub tolerance: Vec<f64>,
    /// The highest order computed.
    pub searched_up_to: usize,
    /// The smallest order meeting every axis's tolerance (`None`: not within
    /// `searched_up_to`).
    pub all: Option<usize>,
    /// The smallest order meeting each axis's tolerance.
    pub per_axis: Vec<Option<usize>>,
}

/// Everything one run computes.
#[derive(Debug, Clone)]
pub struct Conversion {
    /// The conversion set up from the two machines.
    pub motion: Motion,
    /// The instants of the roll.
    pub times: Vec<f64>,
    /// The exact CNC axes at each instant (continuation from `t = 0`).
    pub exact: Vec<Vec<f64>>,
    /// The largest pose difference between the two chains over the instants.
    pub worst: PoseError,
    /// The requested order.
    pub order: usize,
    /// The Maclaurin series, up to `order` or, with a tolerance, up to
    /// `max(order, max_order)`.
    pub series: Series,
    /// `errors[m][k]`: `max |exact − series of order m|` over the roll, for
    /// `m = 0..=series.order()` and axis `k`.
    pub errors: Vec<Vec<f64>>,
    /// The order the tolerance needs, when one is given.
    pub required: Option<RequiredOrder>,
}

impl Conversion {
    /// Samples the exact motion of `motion`, checks it against the generator
    /// at every instant, expands it and measures the truncation errors.
    pub fn run(motion: Motion, options: &RunOptions) -> Result<Conversion, MotionError> {
        let times = motion.sample_times(options.samples);
        motion.check_instants(&times)?;
        let q0 = motion.solve_cold(0.0)?;
        let exact = motion.trajectory_from(&q0, &times)?;
        let mut worst = PoseError {
            position: 0.0,
            rotation: 0.0,
            axis: 0.0,
        };
        for (t, q) in times.iter().zip(&exact) {
            let e = motion.pose_error(q, *t);
            worst.position = worst.position.max(e.position);
            worst.rotation = worst.rotation.max(e.rotation);
            worst.axis = worst.axis.max(e.axis);
        }
        let tolerance: Option<Vec<f64>> = options.tolerance.map(|tol| {
            let ang = options.angular_tolerance.unwrap_or(tol);
            motion
                .kinds()
                .iter()
                .map(|k| if *k == JointKind::Rotary { ang } else { tol })
                .collect()
        });
        let computed = if tolerance.is_some() {
            options.order.max(options.max_order)
        } else {
            options.order
        };
        let series = motion.series_from(&q0, computed)?;
        let errors = motion::truncation_errors(&series, &times, &exact);
        let required = tolerance.map(|tolerance| {
            let (all, per_axis) = motion::required_orders(&errors, &tolerance);
            RequiredOrder {
                tolerance,
                searched_up_to: series.order(),
                all,
                per_axis,
            }
        });
        Ok(Conversion {
            motion,
            times,
            exact,
            worst,
            order: options.order,
            series,
            errors,
            required,
        })
    }

    /// The truncation error of the requested order, per axis.
    pub fn truncation_error(&self) -> &[f64] {
        &self.errors[self.order]
    }
}
