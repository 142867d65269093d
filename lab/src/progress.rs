//! What the experiments show while they run: a spinner naming the step under way with its time,
//! or a bar while the levels are measured; nothing when standard error is not a terminal, so
//! that logs and CI output hold only the results' lines.

use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::time::Duration;

/// A spinner or bar on standard error, hidden when that is not a terminal.
pub struct Progress {
    bar: ProgressBar,
}

impl Progress {
    /// Shown if `show` and standard error is a terminal.
    pub fn new(show: bool) -> Progress {
        let bar = if show && std::io::stderr().is_terminal() {
            let bar = ProgressBar::new_spinner();
            bar.enable_steady_tick(Duration::from_millis(120));
            bar
        } else {
            ProgressBar::hidden()
        };
        let progress = Progress { bar };
        progress.spin();
        progress
    }

    /// Shown when standard error is a terminal.
    pub fn on_terminal() -> Progress {
        Progress::new(true)
    }

    fn spin(&self) {
        self.bar.set_style(
            ProgressStyle::with_template("{spinner} {msg} [{elapsed}]")
                .unwrap_or_else(|_| ProgressStyle::default_spinner()),
        );
    }

    /// A new step, `what`, timed from now.
    pub fn step(&self, what: impl Into<String>) {
        self.spin();
        self.bar.set_message(what.into());
        self.bar.reset_elapsed();
    }

    /// A step of `total` parts, `what`, counted with [`Progress::advance`].
    pub fn count(&self, what: impl Into<String>, total: usize, unit: &str) {
        self.bar.set_style(
            ProgressStyle::with_template(&format!(
                "{{msg}} [{{elapsed_precise}}] {{wide_bar}} {unit} {{pos}}/{{len}} (eta {{eta}})"
            ))
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        self.bar.set_message(what.into());
        self.bar.set_length(total as u64);
        self.bar.set_position(0);
        self.bar.reset_elapsed();
        self.bar.reset_eta();
    }

    /// A download of `total` bytes (0: unknown), `what`, advanced with [`Progress::at_byte`].
    pub fn bytes(&self, what: impl Into<String>, total: u64) {
        self.bar.set_style(
            ProgressStyle::with_template(
                "{msg} {wide_bar} {bytes}/{total_bytes} ({bytes_per_sec}, eta {eta})",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        self.bar.set_message(what.into());
        self.bar.set_length(total);
        self.bar.set_position(0);
        self.bar.reset_elapsed();
        self.bar.reset_eta();
    }

    /// `n` bytes of a [`Progress::bytes`] step in.
    pub fn at_byte(&self, n: u64) {
        self.bar.set_position(n);
    }

    /// One more part of a [`Progress::count`] step done.
    pub fn advance(&self) {
        self.bar.inc(1);
    }

    /// Prints `line` on standard error above the spinner (or alone when it is hidden).
    pub fn println(&self, line: &str) {
        if self.bar.is_hidden() {
            eprintln!("{line}");
        } else {
            self.bar.println(line);
        }
    }

    /// Runs `f` with the spinner cleared, for output on standard output.
    pub fn suspend<R>(&self, f: impl FnOnce() -> R) -> R {
        self.bar.suspend(f)
    }

    /// Clears the spinner.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        self.bar.finish_and_clear();
    }
}
