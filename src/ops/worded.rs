//! How an `ops` error reads, written once per error type: the code and the
//! help of the refusals this layer words, and the wrapped error that words
//! the rest. The CLI's `miette::Diagnostic` ([`diagnostic!`], feature
//! `cli`) and Python's text ([`Worded::with_help`]) both come from it, so a
//! refusal has one wording whichever way in.

/// The wording of an `ops` error.
pub trait Worded: std::fmt::Display {
    /// The code (`chain::…`) of a refusal worded here (`None`: the wrapped
    /// error's own, if any).
    fn own_code(&self) -> Option<&'static str> {
        None
    }

    /// What to do about it, where this layer says more than the message
    /// (the wrapped `ops` error's help included).
    fn own_help(&self) -> Option<String> {
        None
    }

    /// The error this one wraps, which words the rest: its code and help
    /// where this layer has none, its source text and labels.
    #[cfg(feature = "cli")]
    fn inner(&self) -> Option<&dyn miette::Diagnostic> {
        None
    }

    /// The message with its help, as one text (Python's exceptions, and
    /// any renderer without miette).
    fn with_help(&self) -> String {
        match self.own_help() {
            Some(help) => format!("{self}\nhelp: {help}"),
            None => self.to_string(),
        }
    }
}

/// `miette::Diagnostic` for [`Worded`] types: this layer's code and help,
/// else the wrapped error's, and the wrapped error's source text, labels,
/// severity and related diagnostics.
macro_rules! diagnostic {
    ($($t:ty),* $(,)?) => {$(
        #[cfg(feature = "cli")]
        impl miette::Diagnostic for $t {
            fn code<'a>(&'a self) -> Option<Box<dyn std::fmt::Display + 'a>> {
                use $crate::ops::worded::Worded;
                match self.own_code() {
                    Some(code) => Some(Box::new(code)),
                    None => self.inner().and_then(|d| d.code()),
                }
            }

            fn help<'a>(&'a self) -> Option<Box<dyn std::fmt::Display + 'a>> {
                use $crate::ops::worded::Worded;
                match self.own_help() {
                    Some(help) => Some(Box::new(help)),
                    None => self.inner().and_then(|d| d.help()),
                }
            }

            fn source_code(&self) -> Option<&dyn miette::SourceCode> {
                $crate::ops::worded::Worded::inner(self).and_then(|d| d.source_code())
            }

            fn labels(&self) -> Option<Box<dyn Iterator<Item = miette::LabeledSpan> + '_>> {
                $crate::ops::worded::Worded::inner(self).and_then(|d| d.labels())
            }

            fn related<'a>(
                &'a self,
            ) -> Option<Box<dyn Iterator<Item = &'a dyn miette::Diagnostic> + 'a>> {
                $crate::ops::worded::Worded::inner(self).and_then(|d| d.related())
            }

            fn severity(&self) -> Option<miette::Severity> {
                $crate::ops::worded::Worded::inner(self).and_then(|d| d.severity())
            }

            fn url<'a>(&'a self) -> Option<Box<dyn std::fmt::Display + 'a>> {
                $crate::ops::worded::Worded::inner(self).and_then(|d| d.url())
            }

            fn diagnostic_source(&self) -> Option<&dyn miette::Diagnostic> {
                $crate::ops::worded::Worded::inner(self).and_then(|d| d.diagnostic_source())
            }
        }
    )*};
}
pub(crate) use diagnostic;
