//! The source text of a diagnostic as the renderer reads it.

use miette::{MietteError, MietteSpanContents, SourceCode, SourceSpan, SpanContents};

/// The widest source line handed to the diagnostic renderer whole: miette's
/// graphical handler pads with the column as a formatting width, which
/// panics beyond 65,535 ("Formatting argument out of range").
const SNIPPET_WIDE: usize = 4096;

/// Bytes of context kept either side of the located span on a wider line.
const SNIPPET_CONTEXT: usize = 120;

/// The source text of a diagnostic as the renderer reads it: a file's name
/// and text, whose snippets are the file's own lines, except that a line
/// wider than 4,096 bytes (a machine file written as one line of JSON) is
/// cut to a window around the located span, with the line and column of the
/// window's start, so that rendering never fails.
#[derive(Debug, Clone)]
pub struct Snippet {
    name: String,
    text: String,
}

impl Snippet {
    /// The source `text` of the file `name`.
    pub fn new(name: impl Into<String>, text: impl Into<String>) -> Snippet {
        Snippet {
            name: name.into(),
            text: text.into(),
        }
    }
}

impl SourceCode for Snippet {
    fn read_span<'a>(
        &'a self,
        span: &SourceSpan,
        before: usize,
        after: usize,
    ) -> Result<Box<dyn SpanContents<'a> + 'a>, MietteError> {
        let full = self.text.read_span(span, before, after)?;
        let wide = full
            .data()
            .split(|&b| b == b'\n')
            .any(|line| line.len() > SNIPPET_WIDE);
        if !wide {
            let contents = MietteSpanContents::new_named(
                self.name.clone(),
                full.data(),
                *full.span(),
                full.line(),
                full.column(),
                full.line_count(),
            );
            return Ok(Box::new(contents.with_language("yaml")));
        }
        // The window: the span's own line, SNIPPET_CONTEXT bytes either side
        // of the span, at most SNIPPET_WIDE bytes, on character boundaries.
        let text = self.text.as_str();
        let start = span.offset().min(text.len());
        let line_start = text[..start].rfind('\n').map_or(0, |i| i + 1);
        let line_end = text[start..].find('\n').map_or(text.len(), |i| start + i);
        let end = (start + span.len()).min(line_end);
        let mut a = start.saturating_sub(SNIPPET_CONTEXT).max(line_start);
        let mut b = (end + SNIPPET_CONTEXT).min(line_end).min(a + SNIPPET_WIDE);
        while !text.is_char_boundary(a) {
            a -= 1;
        }
        while !text.is_char_boundary(b) {
            b -= 1;
        }
        let line = text[..a].bytes().filter(|&c| c == b'\n').count();
        let column = text[line_start..a].chars().count();
        let contents = MietteSpanContents::new_named(
            self.name.clone(),
            &text.as_bytes()[a..b],
            (a, b - a).into(),
            line,
            column,
            1,
        );
        Ok(Box::new(contents.with_language("yaml")))
    }
}
