//! The reliability methods ([`Method`]): the name a study's result, its
//! document and `--method` use. The samplers and the study both name their
//! method through it, so neither imports the other for it.

use serde::Serialize;

/// The algorithm behind a [`StudyResult`].
///
/// It serialises as the short name of `--method` (`form`, `is`, `mc`);
/// [`Method::title`] is the name a report prints.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum Method {
    /// FORM (Eq. 19-22, 31).
    #[serde(rename = "form")]
    Form,
    /// The advanced importance sampling (Eq. 23-28), centred by FORM.
    #[serde(rename = "is")]
    ImportanceSampling,
    /// Crude Monte Carlo.
    #[serde(rename = "mc")]
    MonteCarlo,
    /// Subset simulation with adaptive conditional sampling
    /// ([`crate::subset`]).
    #[serde(rename = "subset")]
    Subset,
    /// Directional simulation ([`crate::directional`]).
    #[serde(rename = "directional")]
    Directional,
    /// SORM ([`crate::sorm`]): FORM's design point and the exact
    /// curvatures; the answer is Tvedt's.
    #[serde(rename = "sorm")]
    Sorm,
}

impl Method {
    /// Every method, in the order of `--method`'s values.
    pub const ALL: [Method; 6] = [
        Method::Form,
        Method::ImportanceSampling,
        Method::MonteCarlo,
        Method::Subset,
        Method::Directional,
        Method::Sorm,
    ];

    /// `form`, `is` or `mc` (the `--method` spelling, and the JSON's).
    pub fn name(self) -> &'static str {
        match self {
            Method::Form => "form",
            Method::ImportanceSampling => "is",
            Method::MonteCarlo => "mc",
            Method::Subset => "subset",
            Method::Directional => "directional",
            Method::Sorm => "sorm",
        }
    }

    /// `FORM`, `importance sampling` or `Monte Carlo` (for reports).
    pub fn title(self) -> &'static str {
        match self {
            Method::Form => "FORM",
            Method::ImportanceSampling => "importance sampling",
            Method::MonteCarlo => "Monte Carlo",
            Method::Subset => "subset simulation",
            Method::Directional => "directional simulation",
            Method::Sorm => "SORM (Tvedt)",
        }
    }
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}
