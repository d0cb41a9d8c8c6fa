//! The options that take one of a closed set of values (`--method`,
//! `--sided`, `--system`, `--controller`, `--frame`, `--kind`, `--select`,
//! `--strategy`, `--rank`, `--target`, `--setup`): each value's spelling and its
//! one-line help written once, here, as a [`Choice`]. The CLI parses them
//! with [`parser`] (clap lists the spellings and their help in `--help`);
//! Python parses the same strings with [`Choice::parse`]; both refuse an
//! unknown spelling in [`ChoiceError`]'s words.

use chain_core::diagnostic::shortened;
use chain_core::measured::{MeasurementKind, SetupKind};
use chain_core::model::{Frame, Sided};
use reliability::allocate::StrategyName;
use reliability::Method;

use super::allocate::AllocationTarget;
use super::export::ExportController;
use super::study::SystemKind;

/// A value of an option with a closed set of values.
pub trait Choice: Copy + Send + Sync + 'static {
    /// What a value is, with its article (`a method`), in refusals.
    const WHAT: &'static str;
    /// Every value, in the order the CLI lists them.
    const ALL: &'static [Self];

    /// The value's spelling.
    fn name(self) -> &'static str;

    /// What the value does, in one line (the CLI's `--help`).
    fn help(self) -> &'static str;

    /// Every spelling, in [`Choice::ALL`]'s order.
    fn names() -> Vec<&'static str> {
        Self::ALL.iter().map(|c| c.name()).collect()
    }

    /// The value spelt `given` (exactly: no other case, no abbreviation).
    fn parse(given: &str) -> Result<Self, ChoiceError> {
        (Self::ALL.iter())
            .find(|c| c.name() == given)
            .copied()
            .ok_or_else(|| ChoiceError {
                given: shortened(given).into_owned(),
                what: Self::WHAT,
                names: Self::names(),
            })
    }
}

/// A spelling that names no value of a [`Choice`].
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("`{given}` is not {what}: choose one of {}", names.join(", "))]
pub struct ChoiceError {
    /// The spelling given (shortened when long).
    pub given: String,
    /// What a value is (`a method`).
    pub what: &'static str,
    /// Every spelling.
    pub names: Vec<&'static str>,
}

/// clap's value parser of a [`Choice`]: [`Choice::parse`], refusing in
/// [`ChoiceError`]'s words, and the values with their help for `--help`.
#[cfg(feature = "cli")]
#[derive(Debug, Clone, Copy)]
pub struct ChoiceParser<T>(std::marker::PhantomData<fn() -> T>);

/// The value parser of the option whose values are `T`'s.
#[cfg(feature = "cli")]
pub fn parser<T: Choice>() -> ChoiceParser<T> {
    ChoiceParser(std::marker::PhantomData)
}

#[cfg(feature = "cli")]
impl<T: Choice> clap::builder::TypedValueParser for ChoiceParser<T> {
    type Value = T;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &std::ffi::OsStr,
    ) -> Result<T, clap::Error> {
        // clap's own function parser: its `invalid value 'x' for '--opt'`
        // with the refusal after it.
        let parse = |given: &str| T::parse(given);
        parse.parse_ref(cmd, arg, value)
    }

    fn possible_values(
        &self,
    ) -> Option<Box<dyn Iterator<Item = clap::builder::PossibleValue> + '_>> {
        Some(Box::new((T::ALL.iter()).map(|c| {
            clap::builder::PossibleValue::new(c.name()).help(c.help())
        })))
    }
}

impl Choice for Method {
    const WHAT: &'static str = "a method";
    const ALL: &'static [Method] = &Method::ALL;

    fn name(self) -> &'static str {
        Method::name(self)
    }

    fn help(self) -> &'static str {
        match self {
            Method::Form => "FORM / improved first-order second-moment (Eq. 19-22, 31)",
            Method::ImportanceSampling => {
                "The advanced importance sampling (Eq. 23-28), centred by FORM"
            }
            Method::MonteCarlo => "Crude Monte Carlo",
            Method::Subset => {
                "Subset simulation (Au & Beck 2001) with adaptive conditional sampling, p0 = 0.1; `--samples` per level"
            }
            Method::Directional => "Directional simulation (Bjerager 1988)",
            Method::Sorm => {
                "SORM: FORM, then the exact curvatures at its design point; Breitung, Hohenbichler–Rackwitz and Tvedt reported, Tvedt's the answer"
            }
        }
    }
}

impl Choice for Sided {
    const WHAT: &'static str = "a side";
    const ALL: &'static [Sided] = &[Sided::Upper, Sided::Two];

    fn name(self) -> &'static str {
        Sided::name(self)
    }

    fn help(self) -> &'static str {
        match self {
            Sided::Upper => "`g = I − E`",
            Sided::Two => "`|E| ≤ I`",
        }
    }
}

impl Choice for SystemKind {
    const WHAT: &'static str = "a system target";
    const ALL: &'static [SystemKind] = &[SystemKind::Series, SystemKind::Volumetric];

    fn name(self) -> &'static str {
        match self {
            SystemKind::Series => "series",
            SystemKind::Volumetric => "volumetric",
        }
    }

    fn help(self) -> &'static str {
        match self {
            SystemKind::Series => "All listed components within tolerance at once",
            SystemKind::Volumetric => {
                "`√(px² + py² + pz²) ≤ I` (`--system-tolerance`, default the smallest position tolerance)"
            }
        }
    }
}

impl Choice for ExportController {
    const WHAT: &'static str = "a controller";
    const ALL: &'static [ExportController] = &ExportController::ALL;

    fn name(self) -> &'static str {
        ExportController::name(self)
    }

    fn help(self) -> &'static str {
        match self {
            ExportController::Grid => "The universal grid CSV: `δq` at every node and the residual",
            ExportController::Tables(c) => c.capabilities().summary,
            ExportController::Thermal(chain_core::compensation::thermal::ThermalFormat::Siemens) => {
                "SINUMERIK temperature compensation: K0, tanβ and P0 per axis as formulas of the sensors (TEMP_COMP.SPF)"
            }
            ExportController::Thermal(chain_core::compensation::thermal::ThermalFormat::Linuxcnc) => {
                "LinuxCNC external axis offsets from a HAL component of the sensors (thermal_comp.comp, .hal, .ini)"
            }
            ExportController::Thermal(chain_core::compensation::thermal::ThermalFormat::Beckhoff) => {
                "TwinCAT CNC temperature compensation: offset_0, coefficient and s0 per axis (P-AXIS-00271..00274) and the PLC function block that sets them (temp_comp_axes.lis, FB_TempComp.st)"
            }
            ExportController::Thermal(chain_core::compensation::thermal::ThermalFormat::Heidenhain) => {
                "HEIDENHAIN TEMPCOMP formulas of the sensors' PLC words, an offset per axis within 31 characters (KINEMATICS_TEMPCOMP.TAB)"
            }
            ExportController::Thermal(chain_core::compensation::thermal::ThermalFormat::Klipper) => {
                "Klipper [z_thermal_adjust]: Z only, one sensor (z_thermal_adjust.cfg)"
            }
        }
    }
}

impl Choice for Frame {
    const WHAT: &'static str = "a frame";
    const ALL: &'static [Frame] = &[Frame::Tool, Frame::Workpiece];

    fn name(self) -> &'static str {
        Frame::name(self)
    }

    fn help(self) -> &'static str {
        match self {
            Frame::Tool => "The tool frame",
            Frame::Workpiece => "The workpiece frame",
        }
    }
}

impl Choice for MeasurementKind {
    const WHAT: &'static str = "a measurement kind";
    const ALL: &'static [MeasurementKind] = &MeasurementKind::ALL;

    fn name(self) -> &'static str {
        match self {
            MeasurementKind::Point => "point",
            MeasurementKind::Direction => "direction",
        }
    }

    fn help(self) -> &'static str {
        match self {
            MeasurementKind::Point => {
                "The tool-point deviation `px, py, pz` (three rows per candidate); the file must not have `ux,uy,uz`"
            }
            MeasurementKind::Direction => {
                "The deviation along the candidate's `ux, uy, uz` (one row); the file must have them"
            }
        }
    }
}

impl Choice for SetupKind {
    const WHAT: &'static str = "a set-up";
    // A sphere's set-up comes with a sphere file (`--spheres`); `--setup`
    // names the set-up of ordinary measurement records.
    const ALL: &'static [SetupKind] = &[SetupKind::Ball];

    fn name(self) -> &'static str {
        SetupKind::name(self)
    }

    fn help(self) -> &'static str {
        match self {
            SetupKind::Ball => {
                "An R-test: the ball's three set-up offsets on the table are unknowns of the fit (reported, not written into values)"
            }
            SetupKind::Sphere => "A sphere probed on the table (a sphere file)",
            SetupKind::Circle => "A circular test's run (a circular-test file)",
        }
    }
}

impl Choice for crate::compensate::SelectionRule {
    const WHAT: &'static str = "a selection rule";
    const ALL: &'static [Self] = &Self::ALL;

    fn name(self) -> &'static str {
        crate::compensate::SelectionRule::name(self)
    }

    fn help(self) -> &'static str {
        use crate::compensate::SelectionRule;
        match self {
            SelectionRule::Loocv => "Smallest leave-one-out cross-validation error (default)",
            SelectionRule::AdjustedR2 => "Largest adjusted R²",
            SelectionRule::Aicc => "Smallest small-sample AIC",
            SelectionRule::Bic => "Smallest BIC",
        }
    }
}

impl Choice for StrategyName {
    const WHAT: &'static str = "a strategy";
    const ALL: &'static [StrategyName] = &[StrategyName::Optimal, StrategyName::Paper];

    fn name(self) -> &'static str {
        StrategyName::name(self)
    }

    fn help(self) -> &'static str {
        match self {
            StrategyName::Optimal => {
                "Least cost `Σ w (σ0/σ − 1)` subject to the requirement (interior point + KKT check)"
            }
            StrategyName::Paper => {
                "Wang & Yuan 2021's procedure: tighten the errors within 10 % of the largest sensitivity by one step a round"
            }
        }
    }
}

/// How the paper's procedure ranks the errors it tightens (`--rank`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Rank {
    /// Each unmet component's errors separately.
    #[default]
    Component,
    /// The summed sensitivities of all unmet components.
    Pooled,
}

impl Rank {
    /// Whether the sensitivities are pooled.
    pub fn pooled(self) -> bool {
        self == Rank::Pooled
    }
}

impl Choice for Rank {
    const WHAT: &'static str = "a ranking";
    const ALL: &'static [Rank] = &[Rank::Component, Rank::Pooled];

    fn name(self) -> &'static str {
        match self {
            Rank::Component => "component",
            Rank::Pooled => "pooled",
        }
    }

    fn help(self) -> &'static str {
        match self {
            Rank::Component => {
                "Rank each unmet component's errors separately (Wang & Yuan 2021, Tables 5-7)"
            }
            Rank::Pooled => "Rank the summed sensitivities of all unmet components",
        }
    }
}

impl Choice for AllocationTarget {
    const WHAT: &'static str = "an allocation target";
    const ALL: &'static [AllocationTarget] =
        &[AllocationTarget::Requirement, AllocationTarget::Acceptance];

    fn name(self) -> &'static str {
        match self {
            AllocationTarget::Requirement => "requirement",
            AllocationTarget::Acceptance => "acceptance",
        }
    }

    fn help(self) -> &'static str {
        match self {
            AllocationTarget::Requirement => {
                "The reliability section's `requirement` (minimum and mean over the grid, per component)"
            }
            AllocationTarget::Acceptance => {
                "The whole-machine acceptance probability reaches `--level` (docs/acceptance.md)"
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every spelling parses back to its value, and an unknown one is
    /// refused with the list.
    fn round_trip<T: Choice + PartialEq + std::fmt::Debug>() {
        for &c in T::ALL {
            assert_eq!(T::parse(c.name()), Ok(c));
            assert!(!c.help().is_empty() && !c.help().ends_with('.'));
        }
        let e = T::parse("nope").unwrap_err();
        assert_eq!(
            e.to_string(),
            format!(
                "`nope` is not {}: choose one of {}",
                T::WHAT,
                T::names().join(", ")
            )
        );
    }

    #[test]
    fn every_choice_parses_its_spellings() {
        round_trip::<Method>();
        round_trip::<Sided>();
        round_trip::<SystemKind>();
        round_trip::<ExportController>();
        round_trip::<Frame>();
        round_trip::<MeasurementKind>();
        round_trip::<crate::compensate::SelectionRule>();
        round_trip::<StrategyName>();
        round_trip::<Rank>();
        round_trip::<AllocationTarget>();
        assert_eq!(
            Method::parse("sorm?").unwrap_err().to_string(),
            "`sorm?` is not a method: choose one of form, is, mc, subset, directional, sorm"
        );
    }
}
