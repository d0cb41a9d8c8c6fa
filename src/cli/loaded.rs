//! The machine file a command works on, loaded once with its text (for
//! messages' snippets), and the rendering of the errors located in it:
//! reliability errors (worded by `reliability::document::describe`) and a
//! study's refusals ([`chain::ops::study::StudyError`]).

use std::path::Path;

use chain::ops::allocate::AllocateOpsError;
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

    /// The machine file's name as messages give it.
    pub(crate) fn file_name(&self) -> &str {
        &self.file
    }

    /// A located, rendered diagnostic for a reliability error (worded by
    /// [`reliability::document::describe`]).
    pub(crate) fn report(&self, err: ReliabilityError) -> miette::Report {
        let d = reliability::document::describe(&err, &self.file);
        let mut diag = MietteDiagnostic::new(d.message);
        if let Some(code) = miette::Diagnostic::code(&err) {
            diag = diag.with_code(code.to_string());
        }
        if !d.help.is_empty() {
            diag = diag.with_help(d.help);
        }
        self.with_snippet(diag, d.origin, d.label)
    }

    /// An allocation that cannot go on, located at the statistics entry of
    /// the error it names first (a stalled round's or an infeasible
    /// requirement's binding error: where its `min_std` is set), as
    /// `file:line:column: machine: …`.
    pub(crate) fn allocate_error(&self, e: AllocateOpsError) -> miette::Report {
        let AllocateOpsError::Allocate { error, .. } = &e else {
            return miette::Report::new(e);
        };
        let stat = error.statistic().and_then(|name| {
            let m = &self.machine;
            let j = m.errors.iter().position(|x| x.name == name)?;
            m.statistics.iter().find(|s| s.error == j)
        });
        let Some(stat) = stat else {
            return miette::Report::new(e);
        };
        let o = &stat.origin;
        let mut diag = MietteDiagnostic::new(format!("{}:{}:{}: {e}", self.file, o.line, o.column));
        if let Some(code) = miette::Diagnostic::code(&**error) {
            diag = diag.with_code(code.to_string());
        }
        if let Some(help) = miette::Diagnostic::help(&**error) {
            diag = diag.with_help(help.to_string());
        }
        self.with_snippet(diag, Some(o), "its statistics entry")
    }

    /// `diag` with the machine file's text around `origin` (when it has a
    /// line and lies within the text).
    fn with_snippet(
        &self,
        mut diag: MietteDiagnostic,
        origin: Option<&chain_core::model::Origin>,
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
