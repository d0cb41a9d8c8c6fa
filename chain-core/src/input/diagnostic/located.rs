//! Problems located in a file: [`LoadError`] (one problem at a file, line,
//! column and key) and [`Diagnostics`] (every problem of one file, with its
//! text for the renderer).

use std::fmt;

#[cfg(feature = "miette")]
use miette::{LabeledSpan, SourceCode};

use super::Problem;
#[cfg(feature = "miette")]
use super::Snippet;
use crate::model::Origin;

/// One located error in a machine file (or another input file).
#[derive(Debug, Clone, PartialEq)]
pub struct LoadError {
    /// The file name as given to the loader.
    pub file: String,
    /// Where: byte span, line, column and key path. A `line` of 0 means the
    /// error concerns the file as a whole (it could not be read).
    pub origin: Origin,
    /// What is wrong.
    pub problem: Problem,
}

impl LoadError {
    /// A located error.
    pub fn new(file: impl Into<String>, origin: Origin, problem: Problem) -> LoadError {
        LoadError {
            file: file.into(),
            origin,
            problem,
        }
    }

    #[cfg(feature = "miette")]
    fn label(&self, source_len: usize) -> Option<LabeledSpan> {
        if self.origin.line == 0 {
            return None;
        }
        let offset = self.origin.offset.min(source_len);
        let len = self.origin.len.min(source_len - offset);
        Some(LabeledSpan::new_with_span(
            Some(self.problem.label().to_string()),
            (offset, len),
        ))
    }
}

impl fmt::Display for LoadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:", self.file)?;
        if self.origin.line > 0 {
            write!(f, "{}:{}:", self.origin.line, self.origin.column)?;
        }
        write!(f, " {}", self.problem.headline())?;
        if !self.origin.key.is_empty() {
            write!(f, " at key `{}`", self.origin.key)?;
        }
        if let Some(note) = self.problem.note() {
            write!(f, " ({note})")?;
        }
        Ok(())
    }
}

impl std::error::Error for LoadError {}

#[cfg(feature = "miette")]
impl miette::Diagnostic for LoadError {
    fn code<'a>(&'a self) -> Option<Box<dyn fmt::Display + 'a>> {
        Some(Box::new(self.problem.code()))
    }

    fn help<'a>(&'a self) -> Option<Box<dyn fmt::Display + 'a>> {
        self.problem
            .help()
            .map(|h| Box::new(h) as Box<dyn fmt::Display>)
    }

    fn labels(&self) -> Option<Box<dyn Iterator<Item = LabeledSpan> + '_>> {
        // Related errors render against the parent's source; without it we
        // cannot know the length, so the caller (`Diagnostics`) clamps.
        self.label(usize::MAX)
            .map(|l| Box::new(std::iter::once(l)) as Box<dyn Iterator<Item = LabeledSpan>>)
    }
}

/// A related error rendered against the parent's source text, with its span
/// clamped to that text.
#[cfg_attr(not(feature = "miette"), allow(dead_code))]
#[derive(Debug, Clone)]
struct Related {
    error: LoadError,
    source_len: usize,
}

impl fmt::Display for Related {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.error.fmt(f)
    }
}

impl std::error::Error for Related {}

#[cfg(feature = "miette")]
impl miette::Diagnostic for Related {
    fn code<'b>(&'b self) -> Option<Box<dyn fmt::Display + 'b>> {
        self.error.code()
    }

    fn help<'b>(&'b self) -> Option<Box<dyn fmt::Display + 'b>> {
        self.error.help()
    }

    fn labels(&self) -> Option<Box<dyn Iterator<Item = LabeledSpan> + '_>> {
        if self.source_len == 0 {
            return None;
        }
        self.error
            .label(self.source_len)
            .map(|l| Box::new(std::iter::once(l)) as Box<dyn Iterator<Item = LabeledSpan>>)
    }
}

/// All errors found in one machine file (or another input file): never
/// empty.
///
/// `Display` shows the first error (`file:line:column: message at key `k``)
/// followed by how many more there are; the alternate form (`{:#}`) lists every
/// error, one per line. As a [`miette::Diagnostic`] it renders the first error
/// with a labelled snippet of the file and the others as related diagnostics.
pub struct Diagnostics {
    // Boxed so that `Result<Machine, Diagnostics>` stays small.
    inner: Box<Inner>,
}

#[cfg_attr(not(feature = "miette"), allow(dead_code))]
struct Inner {
    file: String,
    #[cfg(feature = "miette")]
    source: Snippet,
    source_len: usize,
    errors: Vec<LoadError>,
    related: Vec<Related>,
}

impl fmt::Debug for Diagnostics {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Diagnostics")
            .field("errors", &self.inner.errors)
            .finish_non_exhaustive()
    }
}

impl Diagnostics {
    /// The diagnostics of `file` (whose text is `source`) from a list of
    /// errors; `None` if the list is empty. Errors are sorted by position
    /// (stable, so errors at one place keep their order).
    pub fn new(
        file: impl Into<String>,
        source: impl Into<String>,
        mut errors: Vec<LoadError>,
    ) -> Option<Diagnostics> {
        if errors.is_empty() {
            return None;
        }
        errors.sort_by_key(|e| (e.origin.line, e.origin.column));
        let file = file.into();
        let source = source.into();
        let source_len = source.len();
        let related = errors
            .iter()
            .skip(1)
            .map(|error| Related {
                error: error.clone(),
                source_len,
            })
            .collect();
        Some(Diagnostics {
            inner: Box::new(Inner {
                #[cfg(feature = "miette")]
                source: Snippet::new(file.clone(), source),
                file,
                source_len,
                errors,
                related,
            }),
        })
    }

    /// The diagnostics of `file` (whose text is `source`) from problems
    /// located in it; `None` if there are none.
    pub fn located(
        file: &str,
        source: impl Into<String>,
        problems: impl IntoIterator<Item = (Origin, Problem)>,
    ) -> Option<Diagnostics> {
        let errors = problems
            .into_iter()
            .map(|(origin, problem)| LoadError::new(file, origin, problem))
            .collect();
        Diagnostics::new(file, source, errors)
    }

    /// A single error.
    pub fn single(
        file: impl Into<String>,
        source: impl Into<String>,
        origin: Origin,
        problem: Problem,
    ) -> Diagnostics {
        let file = file.into();
        let error = LoadError::new(file.clone(), origin, problem);
        let source = source.into();
        let source_len = source.len();
        Diagnostics {
            inner: Box::new(Inner {
                #[cfg(feature = "miette")]
                source: Snippet::new(file.clone(), source),
                file,
                source_len,
                errors: vec![error],
                related: Vec::new(),
            }),
        }
    }

    /// The file name.
    pub fn file(&self) -> &str {
        &self.inner.file
    }

    /// The errors, in source order.
    pub fn errors(&self) -> &[LoadError] {
        &self.inner.errors
    }

    /// Iterates over the errors in source order.
    pub fn iter(&self) -> std::slice::Iter<'_, LoadError> {
        self.inner.errors.iter()
    }

    /// The first error.
    pub fn first(&self) -> &LoadError {
        // `errors` is never empty by construction; fall back defensively.
        &self.inner.errors[0]
    }

    /// The number of errors (at least 1).
    pub fn len(&self) -> usize {
        self.inner.errors.len()
    }

    /// Always false: a `Diagnostics` holds at least one error.
    pub fn is_empty(&self) -> bool {
        self.inner.errors.is_empty()
    }
}

impl<'a> IntoIterator for &'a Diagnostics {
    type Item = &'a LoadError;
    type IntoIter = std::slice::Iter<'a, LoadError>;

    fn into_iter(self) -> Self::IntoIter {
        self.inner.errors.iter()
    }
}

impl fmt::Display for Diagnostics {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if f.alternate() {
            for (i, e) in self.inner.errors.iter().enumerate() {
                if i > 0 {
                    writeln!(f)?;
                }
                write!(f, "{e}")?;
            }
            return Ok(());
        }
        write!(f, "{}", self.first())?;
        match self.inner.errors.len() {
            0 | 1 => Ok(()),
            2 => write!(f, " (and 1 more error)"),
            n => write!(f, " (and {} more errors)", n - 1),
        }
    }
}

impl std::error::Error for Diagnostics {}

#[cfg(feature = "miette")]
impl miette::Diagnostic for Diagnostics {
    fn code<'a>(&'a self) -> Option<Box<dyn fmt::Display + 'a>> {
        self.first().code()
    }

    fn help<'a>(&'a self) -> Option<Box<dyn fmt::Display + 'a>> {
        self.first().help()
    }

    fn source_code(&self) -> Option<&dyn SourceCode> {
        if self.inner.source_len == 0 {
            None
        } else {
            Some(&self.inner.source)
        }
    }

    fn labels(&self) -> Option<Box<dyn Iterator<Item = LabeledSpan> + '_>> {
        if self.inner.source_len == 0 {
            return None;
        }
        self.first()
            .label(self.inner.source_len)
            .map(|l| Box::new(std::iter::once(l)) as Box<dyn Iterator<Item = LabeledSpan>>)
    }

    fn related<'a>(&'a self) -> Option<Box<dyn Iterator<Item = &'a dyn miette::Diagnostic> + 'a>> {
        if self.inner.related.is_empty() {
            return None;
        }
        Some(Box::new(
            self.inner
                .related
                .iter()
                .map(|r| r as &dyn miette::Diagnostic),
        ))
    }
}
