//! The rules of a settings file of `chain motion` (codes
//! `chain::settings::*`): its own keys, and the names it gives the generator
//! and the CNC machine.

use super::Description as D;

/// One thing wrong with a settings file, worded by
/// [`SettingsProblem::describe`].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum SettingsProblem {
    /// The file holds no YAML document (or only `null`).
    Empty,
    /// The file could not be read into settings, without a more precise
    /// problem.
    Invalid,
    /// An angle that does not parse.
    Angle {
        /// The angle as written.
        text: String,
        /// Why it does not parse.
        reason: String,
    },
    /// `cnc.fix` without `match: point_axis`.
    FixNeedsPointAxis,
    /// A roll interval `[t0, t1]` with `t0 >= t1`.
    Interval {
        /// Its start.
        t0: f64,
        /// Its end.
        t1: f64,
    },
    /// A machine file named by the settings that cannot be read.
    MachineFile {
        /// Which machine (`generator`, `CNC machine`).
        what: &'static str,
        /// The path read.
        path: String,
        /// Why.
        reason: String,
    },
    /// A name in `values` or `roll.drive` that the generator does not have.
    UnknownName {
        /// The name.
        name: String,
        /// The generator.
        generator: String,
        /// Where it is given (`` `values` ``, `` `roll.drive` ``).
        within: &'static str,
        /// The generator's parameters and variables.
        names: Vec<String>,
        /// The closest of them, if one is close.
        suggestion: Option<String>,
    },
    /// A parameter of the generator under `roll.drive`.
    DriveParameter {
        /// The parameter.
        name: String,
        /// The generator.
        generator: String,
    },
    /// `roll.drive` moves nothing: every `ratio` is 0.
    NoMotion,
    /// A name given as a parameter of the CNC machine that it does not have.
    UnknownParameter {
        /// The name.
        name: String,
        /// The CNC machine.
        machine: String,
        /// Whether it comes from the command line (`--param`) rather than
        /// `cnc.parameters`.
        command_line: bool,
        /// The closest parameter, if one is close.
        suggestion: Option<String>,
    },
    /// A name given as a variable of the CNC machine that it does not have.
    UnknownVariable {
        /// The name.
        name: String,
        /// Where it is given (`` `cnc.fix` ``, ...).
        within: &'static str,
        /// The CNC machine.
        machine: String,
        /// The closest variable, if one is close.
        suggestion: Option<String>,
    },
    /// A name in both `values` and `roll.drive`.
    Duplicate {
        /// The name.
        name: String,
        /// The line of its first occurrence.
        first_line: usize,
    },
    /// A parameter of the generator without a value.
    GeneratorParameterMissing {
        /// The parameter.
        name: String,
    },
    /// A variable of the generator neither held nor driven.
    GeneratorVariableMissing {
        /// The variable.
        name: String,
    },
    /// A parameter of the CNC machine without a value.
    CncParameterMissing {
        /// The parameter.
        name: String,
        /// The CNC machine.
        machine: String,
    },
    /// An angle (`deg`, degrees-minutes-seconds) given to a length.
    AngleOnLength {
        /// The name.
        name: String,
        /// What it is (`a parameter (a length) of `m``, ...).
        what: String,
    },
}

impl SettingsProblem {
    /// Every part of the message of this problem: one match arm per
    /// variant.
    pub fn describe(&self) -> D {
        match self {
            SettingsProblem::Empty => D::new("chain::settings::empty", "empty", "the settings file is empty")
                .help("expected a mapping with `settings`, `values` and `roll`".to_string()),
            SettingsProblem::Invalid => {
                D::new("chain::settings::invalid", "here", "invalid settings file")
            }
            SettingsProblem::Angle { text, reason } => D::new(
                "chain::settings::angle",
                "angle",
                format!("cannot read the angle `{text}`: {reason}"),
            )
            .help(
                "write degrees-minutes-seconds as \"-115°39′\" or \"12°30'15\\\"\", or degrees as -115.65deg"
                    .to_string(),
            ),
            SettingsProblem::FixNeedsPointAxis => D::new(
                "chain::settings::fix_needs_point_axis",
                "fix",
                "`cnc.fix` holds variables, which only `match: point_axis` allows (a full pose determines every axis)",
            )
            .help("add `match: point_axis` under `cnc`, or remove `fix`".to_string()),
            SettingsProblem::Interval { t0, t1 } => D::new(
                "chain::settings::interval",
                "empty interval",
                format!("the roll interval needs t0 < t1, got [{t0}, {t1}]"),
            ),
            SettingsProblem::MachineFile { what, path, reason } => D::new(
                "chain::settings::machine_file",
                "file",
                format!("cannot read the {what} file `{path}`: {reason}"),
            )
            .help("paths are relative to the settings file's directory".to_string()),
            SettingsProblem::UnknownName {
                name,
                generator,
                within,
                names,
                suggestion,
            } => D::new(
                "chain::settings::unknown_name",
                "unknown name",
                D::suggesting(
                    format!("`{name}` is not a parameter or variable of the generator `{generator}`"),
                    suggestion,
                ),
            )
            .help(format!(
                "{within} names the generator's parameters and variables: {}",
                names.join(", ")
            )),
            SettingsProblem::DriveParameter { name, generator } => D::new(
                "chain::settings::drive_parameter",
                "not a variable",
                format!("`{name}` is a parameter of the generator `{generator}`; only its variables can be driven"),
            )
            .help("give it under `values`".to_string()),
            SettingsProblem::NoMotion => D::new(
                "chain::settings::no_motion",
                "no motion",
                "no generator variable moves: every `ratio` is 0",
            ),
            SettingsProblem::UnknownParameter {
                name,
                machine,
                command_line,
                suggestion,
            } => D::new(
                "chain::settings::unknown_name",
                "unknown parameter",
                D::suggesting(
                    format!(
                        "{}`{name}` is not a parameter of the CNC machine `{machine}`",
                        if *command_line { "override " } else { "" }
                    ),
                    suggestion,
                ),
            ),
            SettingsProblem::UnknownVariable {
                name,
                within,
                machine,
                suggestion,
            } => D::new(
                "chain::settings::unknown_variable",
                "unknown variable",
                D::suggesting(
                    format!("`{name}` in {within} is not a variable of the CNC machine `{machine}`"),
                    suggestion,
                ),
            ),
            SettingsProblem::Duplicate { name, first_line } => D::new(
                "chain::settings::duplicate",
                "given twice",
                format!("`{name}` is given twice (first on line {first_line}): in `values` and in `roll.drive`"),
            )
            .help("a held setting goes in `values`, a moving one in `roll.drive`".to_string()),
            SettingsProblem::GeneratorParameterMissing { name } => missing(
                format!("generator parameter `{name}` has no value"),
                format!("add `{name}: <value>` under `values`"),
            ),
            SettingsProblem::GeneratorVariableMissing { name } => missing(
                format!("generator variable `{name}` has no value"),
                format!("hold it with `{name}: <value>` under `values`, or move it with `{name}: {{start: .., ratio: ..}}` under `roll.drive`"),
            ),
            SettingsProblem::CncParameterMissing { name, machine } => missing(
                format!("parameter `{name}` of the CNC machine `{machine}` has no value"),
                format!("add `cnc: {{parameters: {{{name}: <value>}}}}`, or give the run a value `{name}=VALUE`"),
            ),
            SettingsProblem::AngleOnLength { name, what } => D::new(
                "chain::settings::angle_on_length",
                "angle on a length",
                format!("`{name}` is {what}; angle units are not allowed"),
            ),
        }
    }
}

/// A setting without a value.
fn missing(headline: String, help: String) -> D {
    D::new("chain::settings::missing_value", "missing value", headline).help(help)
}
