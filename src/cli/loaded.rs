//! The machine file a command works on, loaded once with its text (for
//! messages' snippets), and the rendering of the errors located in it:
//! reliability errors (worded by [`chain::ops::study::describe`]), a
//! study's refusals ([`chain::ops::study::StudyError`]) and an `ops` error
//! at the place it names ([`Loaded::located`]).

use std::path::Path;

use chain::ops::study::StudyError;
use chain_core::model::{Machine, Origin};
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
            e @ StudyError::Posterior(_) => miette::Report::new(e),
            e @ StudyError::Approach { .. } => miette::miette!("{e}"),
        }
    }

    /// The machine file's name as messages give it.
    pub(crate) fn file_name(&self) -> &str {
        &self.file
    }

    /// A located, rendered diagnostic for a reliability error (worded by
    /// [`chain::ops::study::describe`]).
    pub(crate) fn report(&self, err: ReliabilityError) -> miette::Report {
        let d = chain::ops::study::describe(&err, &self.file);
        let mut diag = MietteDiagnostic::new(d.message);
        if let Some(code) = miette::Diagnostic::code(&err) {
            diag = diag.with_code(code.to_string());
        }
        if !d.help.is_empty() {
            diag = diag.with_help(d.help);
        }
        self.with_snippet(diag, d.origin, d.label)
    }

    /// `e` (its message, code and help) shown at `origin` in the machine
    /// file with the snippet there labelled `label`: an `ops` error that
    /// carries its place in the file.
    pub(crate) fn located(
        &self,
        e: &dyn miette::Diagnostic,
        origin: &Origin,
        label: &str,
    ) -> miette::Report {
        let mut diag = MietteDiagnostic::new(e.to_string());
        if let Some(code) = e.code() {
            diag = diag.with_code(code.to_string());
        }
        if let Some(help) = e.help() {
            diag = diag.with_help(help.to_string());
        }
        self.with_snippet(diag, Some(origin), label)
    }

    /// `diag` with the machine file's text around `origin` (when it has a
    /// line and lies within the text).
    fn with_snippet(
        &self,
        mut diag: MietteDiagnostic,
        origin: Option<&Origin>,
        label: &str,
    ) -> miette::Report {
        if let Some(o) = origin.filter(|o| o.line > 0 && o.offset <= self.source.len()) {
            let len = o.len.min(self.source.len() - o.offset);
            diag = diag.with_label(LabeledSpan::at(o.offset..o.offset + len, label));
            return miette::Report::new(diag).with_source_code(
                chain_core::diagnostic::Snippet::new(self.file.clone(), self.source.clone()),
            );
        }
        miette::Report::new(diag)
    }
}
