//! Choosing the order of the law among the fits: the stated rules, and the
//! record of what each rule picks.

use std::fmt;
use std::str::FromStr;

use serde::Serialize;

use super::PolyFit;

/// How [`analyze`] chooses the order of the compensation law among the fits.
///
/// The default, [`SelectionRule::Loocv`], picks the order with the smallest
/// leave-one-out prediction error: the quantity a compensation law is for
/// (the error left at an angle when the law was fitted without that angle's
/// measurement). `R²` never decreases with the order, so it cannot choose.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum SelectionRule {
    /// Smallest leave-one-out cross-validation error (PRESS); ties go to the
    /// lower order.
    #[default]
    Loocv,
    /// Largest adjusted `R²`.
    AdjustedR2,
    /// Smallest small-sample Akaike criterion (orders where it is undefined
    /// are skipped).
    Aicc,
    /// Smallest Bayesian information criterion.
    Bic,
}

impl SelectionRule {
    /// Every rule, in the order of their names in [`SelectionRule::name`].
    pub const ALL: [SelectionRule; 4] = [
        SelectionRule::Loocv,
        SelectionRule::AdjustedR2,
        SelectionRule::Aicc,
        SelectionRule::Bic,
    ];

    /// The rule's name on the command line and in JSON.
    pub fn name(self) -> &'static str {
        match self {
            SelectionRule::Loocv => "loocv",
            SelectionRule::AdjustedR2 => "adjusted-r2",
            SelectionRule::Aicc => "aicc",
            SelectionRule::Bic => "bic",
        }
    }

    /// One sentence saying what the rule does.
    pub fn description(self) -> &'static str {
        match self {
            SelectionRule::Loocv => {
                "smallest leave-one-out cross-validation error (PRESS); ties go to the lower order"
            }
            SelectionRule::AdjustedR2 => "largest adjusted R² = 1 − (1 − R²)(n − 1)/(n − p − 1)",
            SelectionRule::Aicc => {
                "smallest AICc = n ln(RSS/n) + 2k + 2k(k + 1)/(n − k − 1), k = p + 2"
            }
            SelectionRule::Bic => "smallest BIC = n ln(RSS/n) + k ln n, k = p + 2",
        }
    }

    /// The order this rule picks among `fits` (`None` if no fit has a value
    /// for the rule's criterion, or `fits` is empty).
    pub fn select(self, fits: &[PolyFit]) -> Option<usize> {
        // Lower is better for every score; ties (within a relative 1e-12) go
        // to the lower order, which comes first.
        let score = |f: &PolyFit| -> Option<f64> {
            match self {
                SelectionRule::Loocv => Some(f.press),
                SelectionRule::AdjustedR2 => Some(-f.adjusted_r2),
                SelectionRule::Aicc => f.aicc,
                SelectionRule::Bic => Some(f.bic),
            }
        };
        let mut best: Option<(usize, f64)> = None;
        for fit in fits {
            let Some(s) = score(fit).filter(|s| s.is_finite()) else {
                continue;
            };
            match best {
                Some((_, b)) if s >= b - 1e-12 * b.abs().max(f64::MIN_POSITIVE) => {}
                _ => best = Some((fit.order, s)),
            }
        }
        best.map(|(order, _)| order)
    }
}

impl fmt::Display for SelectionRule {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for SelectionRule {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        SelectionRule::ALL
            .into_iter()
            .find(|r| r.name() == s)
            .ok_or_else(|| {
                format!(
                    "unknown selection rule `{s}` (expected one of: {})",
                    SelectionRule::ALL.map(SelectionRule::name).join(", ")
                )
            })
    }
}

/// How the order of the law was chosen, and what each rule would choose.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Selection {
    /// `fixed` when an order was imposed, else the rule's name.
    pub rule: String,
    /// What the rule does.
    pub description: String,
    /// The order each rule picks on these data (by rule name).
    pub by_rule: std::collections::BTreeMap<String, usize>,
}
