//! Progress display for one case: an indicatif bar on a terminal, plain lines otherwise (CI logs).

use std::io::IsTerminal;

use indicatif::{ProgressBar, ProgressStyle};

/// How progress is shown.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum ProgressMode {
    /// Nothing is shown (library use, gates).
    Hidden,
    /// A bar on standard error (interactive terminal).
    Bar,
    /// One line per stage and per quarter of a stage on standard error (CI, redirected output).
    Lines,
}

impl ProgressMode {
    /// `Bar` when standard error is a terminal, `Lines` otherwise.
    pub fn detect() -> Self {
        if std::io::stderr().is_terminal() {
            ProgressMode::Bar
        } else {
            ProgressMode::Lines
        }
    }
}

/// The progress of one case through its stages.
pub struct Progress {
    case: String,
    mode: ProgressMode,
    bar: Option<ProgressBar>,
    stage: String,
    len: u64,
    pos: u64,
    next_line_at: u64,
}

impl Progress {
    pub fn new(case: &str, mode: ProgressMode) -> Self {
        let bar = (mode == ProgressMode::Bar).then(|| {
            let bar = ProgressBar::new(0);
            let style = ProgressStyle::with_template(
                "{prefix:>10} {msg:<28} [{bar:30}] {pos}/{len} ({elapsed}, eta {eta})",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> ");
            bar.set_style(style);
            bar.set_prefix(case.to_string());
            bar
        });
        Progress {
            case: case.to_string(),
            mode,
            bar,
            stage: String::new(),
            len: 0,
            pos: 0,
            next_line_at: 0,
        }
    }

    /// Starts a stage of `len` units of work.
    pub fn stage(&mut self, name: &str, len: u64) {
        self.stage = name.to_string();
        self.len = len;
        self.pos = 0;
        self.next_line_at = len.div_ceil(4).max(1);
        if let Some(bar) = &self.bar {
            bar.set_message(name.to_string());
            bar.set_length(len);
            bar.set_position(0);
        }
        if self.mode == ProgressMode::Lines {
            eprintln!("[{}] {} (0/{})", self.case, name, len);
        }
    }

    /// Records `n` more units of work done in the current stage.
    pub fn inc(&mut self, n: u64) {
        self.pos += n;
        if let Some(bar) = &self.bar {
            bar.inc(n);
        }
        if self.mode == ProgressMode::Lines && self.pos >= self.next_line_at && self.pos < self.len
        {
            eprintln!("[{}] {} ({}/{})", self.case, self.stage, self.pos, self.len);
            self.next_line_at += self.len.div_ceil(4).max(1);
        }
    }

    /// Ends the case's progress display with a one-line summary.
    pub fn finish(&mut self, summary: &str) {
        if let Some(bar) = self.bar.take() {
            bar.finish_and_clear();
        }
        if self.mode != ProgressMode::Hidden {
            eprintln!("[{}] {}", self.case, summary);
        }
    }
}
