//! The machine file a command works on, loaded once with its text (for
//! messages' snippets), and the rendering of the errors located in it:
//! reliability errors (worded by `reliability::document::describe`) and a
//! study's refusals ([`chain::ops::study::StudyError`]).

use std::path::Path;

use chain::ops::study::StudyError;
use chain_core::model::Machine;
use miette::{LabeledSpan, MietteDiagnostic};
use reliability::ReliabilityError;

/// A loaded machine with its source text (for diagnostics).
pub(crate) struct Loaded {
    pub(crate) machine: Machine,
    file: String,
    source: String,
}

impl Loaded {
    /// Loads and validates a machine file.
    pub(crate) fn new(path: &Path) -> miette::Result<Loaded> {
        // Read once: the text stays for the messages' snippets.
        let (machine, source) = chain_core::load_file_with_text(path)?;
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
