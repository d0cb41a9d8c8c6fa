//! The machine file a command works on, loaded once with its text (for
//! messages' snippets), and what every study command builds from it: the
//! study ([`chain::ops::study`]), the posterior of `--values`, located
//! diagnostics of reliability errors; `--fix` names resolved.

use std::path::Path;

use chain::ops::study::{StudyError, StudyOptions};
use chain_core::model::Machine;
use miette::{LabeledSpan, MietteDiagnostic};
use reliability::{Posterior, ReliabilityError, Study, System};

use super::args::SidedArg;

/// A loaded machine with its source text (for diagnostics).
pub(crate) struct Loaded {
    pub(crate) machine: Machine,
    file: String,
    source: String,
}

impl Loaded {
    /// Loads and validates a machine file.
    pub(crate) fn new(path: &Path) -> miette::Result<Loaded> {
        let machine = chain_core::load_file(path)?;
        // Read again for the messages' snippets, within the loader's bound.
        let source = chain_core::bounded::read_path(path, chain_core::bounded::MACHINE_BYTES)
            .ok()
            .and_then(|b| String::from_utf8(b).ok())
            .unwrap_or_default();
        let file = machine
            .file
            .clone()
            .unwrap_or_else(|| path.display().to_string());
        Ok(Loaded {
            machine,
            file,
            source,
        })
    }

    /// The study of the machine's reliability section, with command-line
    /// parameter values, grid axes and `sided`.
    pub(crate) fn study(
        &self,
        params: &[(String, f64)],
        grid: &[(String, Vec<f64>)],
        sided: Option<SidedArg>,
        system: Option<System>,
    ) -> miette::Result<(Study, chain_core::CompiledModel)> {
        self.study_with(params, grid, sided, system, None)
    }

    /// A study's refusal rendered: a reliability error located in the
    /// machine file, the others as they are.
    pub(crate) fn study_error(&self, e: StudyError) -> miette::Report {
        match e {
            StudyError::Reliability(e) => self.report(e),
            StudyError::Resolve(e) => miette::Report::new(e),
            StudyError::Posterior(e) => e.into(),
            e @ StudyError::Approach { .. } => miette::miette!("{e}"),
        }
    }

    /// [`Loaded::study`] with the inputs of a posterior (`None`: the
    /// `statistics` section), through [`chain::ops::study`].
    pub(crate) fn study_with(
        &self,
        params: &[(String, f64)],
        grid: &[(String, Vec<f64>)],
        sided: Option<SidedArg>,
        system: Option<System>,
        posterior: Option<&Posterior>,
    ) -> miette::Result<(Study, chain_core::CompiledModel)> {
        let model = chain_core::compile(&self.machine);
        let options = StudyOptions {
            params,
            grid,
            sided: sided.map(Into::into),
            system,
            posterior,
        };
        let study = chain::ops::study::study(&self.machine, &self.file, &model, &options)
            .map_err(|e| self.study_error(e))?;
        Ok((study, model))
    }

    /// A located, rendered diagnostic for a reliability error (worded by
    /// [`reliability::document::describe`]).
    /// The machine file's name as messages give it.
    pub(crate) fn file_name(&self) -> &str {
        &self.file
    }

    pub(crate) fn report(&self, err: ReliabilityError) -> miette::Report {
        let d = reliability::document::describe(&err, &self.file);
        let mut diag = MietteDiagnostic::new(d.message);
        if let Some(code) = miette::Diagnostic::code(&err) {
            diag = diag.with_code(code.to_string());
        }
        if !d.help.is_empty() {
            diag = diag.with_help(d.help);
        }
        if let Some(o) = d
            .origin
            .filter(|o| o.line > 0 && o.offset <= self.source.len())
        {
            let len = o.len.min(self.source.len() - o.offset);
            diag = diag.with_label(LabeledSpan::at(o.offset..o.offset + len, d.label));
            return miette::Report::new(diag).with_source_code(
                chain_core::diagnostic::Snippet::new(self.file.clone(), self.source.clone()),
            );
        }
        miette::Report::new(diag)
    }
}
