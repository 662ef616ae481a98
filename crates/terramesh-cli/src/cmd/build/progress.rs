//! Stage progress: a spinner per stage on a terminal, plain log lines otherwise.

use std::io::IsTerminal;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressStyle};

/// Reports stages `[k/n] name ... detail (time)`.
pub struct Progress {
    quiet: bool,
    tty: bool,
    total: usize,
    k: usize,
    name: String,
    started: Instant,
    bar: Option<ProgressBar>,
}

impl Progress {
    /// A reporter for `total` stages.
    pub fn new(quiet: bool, total: usize) -> Progress {
        Progress {
            quiet,
            tty: std::io::stderr().is_terminal(),
            total,
            k: 0,
            name: String::new(),
            started: Instant::now(),
            bar: None,
        }
    }

    /// Starts a stage; returns its start time.
    pub fn start(&mut self, name: &str) -> Instant {
        self.k += 1;
        self.name = name.to_string();
        self.started = Instant::now();
        if !self.quiet && self.tty {
            let bar = ProgressBar::new_spinner();
            bar.set_style(
                ProgressStyle::with_template("{spinner} [{prefix}] {msg} {elapsed}")
                    .unwrap_or_else(|_| ProgressStyle::default_spinner()),
            );
            bar.set_prefix(format!("{}/{}", self.k, self.total));
            bar.set_message(name.to_string());
            bar.enable_steady_tick(Duration::from_millis(100));
            self.bar = Some(bar);
        }
        self.started
    }

    /// Ends the current stage with a one-line summary.
    pub fn done(&mut self, detail: &str) {
        let line = format!(
            "[{}/{}] {}: {} ({:.2} s)",
            self.k,
            self.total,
            self.name,
            detail,
            self.started.elapsed().as_secs_f64()
        );
        if let Some(bar) = self.bar.take() {
            bar.finish_and_clear();
        }
        if !self.quiet {
            eprintln!("terramesh: {line}");
        }
    }

    /// The closing line.
    pub fn finish(&mut self, text: &str) {
        if !self.quiet {
            eprintln!("terramesh: {text}");
        }
    }
}
