//! The progress bar of the long commands (`reliability`'s samplers, large
//! maps): indicatif on stderr, only when stderr is a terminal and the
//! command was asked to show it (never with `--format json`).

use std::io::IsTerminal;

/// A progress bar on stderr, or nothing.
pub(crate) struct Progress(Option<indicatif::ProgressBar>);

impl Progress {
    /// No bar.
    pub(crate) fn hidden() -> Progress {
        Progress(None)
    }

    /// A bar over `total` `unit`s when the count is known in advance,
    /// otherwise a counter of the units done (`verb` says what is done:
    /// `sampling`, `mapping`); hidden unless `show` and stderr is a
    /// terminal.
    pub(crate) fn new(show: bool, total: Option<u64>, verb: &str, unit: &str) -> Progress {
        if !show || !std::io::stderr().is_terminal() {
            return Progress::hidden();
        }
        let bar = indicatif::ProgressBar::with_draw_target(
            total,
            indicatif::ProgressDrawTarget::stderr(),
        );
        let template = match total {
            Some(_) => format!(
                "{{spinner}} {verb} [{{bar:40}}] {{percent:>3}}% {{human_pos}}/{{human_len}} {unit}, eta {{eta}}"
            ),
            None => format!("{{spinner}} {verb}: {{human_pos}} {unit} done, {{elapsed}}"),
        };
        if let Ok(style) = indicatif::ProgressStyle::with_template(&template) {
            bar.set_style(style.progress_chars("=> "));
        }
        Progress(Some(bar))
    }

    /// `n` more done.
    pub(crate) fn inc(&self, n: u64) {
        if let Some(b) = &self.0 {
            b.inc(n);
        }
    }

    /// Removes the bar.
    pub(crate) fn finish(&self) {
        if let Some(b) = &self.0 {
            b.finish_and_clear();
        }
    }
}
