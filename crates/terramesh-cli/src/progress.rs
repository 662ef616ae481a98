//! Progress on the terminal: a spinner per stage and a bar for counted work on a terminal,
//! plain log lines otherwise; nothing but warnings with `--quiet`.

use std::io::IsTerminal;
use std::sync::Mutex;
use std::time::Duration;

use indicatif::{ProgressBar, ProgressStyle};

/// The binary's [`terramesh::progress::Progress`]: `[k/n] name: detail (time)` lines.
pub struct Terminal {
    quiet: bool,
    bars: bool,
    state: Mutex<State>,
}

#[derive(Default)]
struct State {
    k: usize,
    total: usize,
    spinner: Option<ProgressBar>,
    bar: Option<ProgressBar>,
}

impl Terminal {
    /// A reporter; `bars` draws indicatif bars (only on a terminal).
    pub fn new(quiet: bool, bars: bool) -> Terminal {
        Terminal {
            quiet,
            bars: bars && !quiet && std::io::stderr().is_terminal(),
            state: Mutex::new(State::default()),
        }
    }

    fn state(&self) -> std::sync::MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// The closing line.
    pub fn finish(&self, text: &str) {
        if !self.quiet {
            eprintln!("terramesh: {text}");
        }
    }
}

impl terramesh::progress::Progress for Terminal {
    fn stage_start(&self, index: usize, total: usize, name: &str) {
        let mut s = self.state();
        s.k = index;
        s.total = total;
        if self.bars {
            let bar = ProgressBar::new_spinner();
            bar.set_style(
                ProgressStyle::with_template("{spinner} [{prefix}] {msg} {elapsed}")
                    .unwrap_or_else(|_| ProgressStyle::default_spinner()),
            );
            bar.set_prefix(format!("{index}/{total}"));
            bar.set_message(name.to_string());
            bar.enable_steady_tick(Duration::from_millis(100));
            s.spinner = Some(bar);
        }
    }

    fn stage_done(&self, name: &str, detail: &str, seconds: f64) {
        let mut s = self.state();
        if let Some(bar) = s.spinner.take() {
            bar.finish_and_clear();
        }
        if !self.quiet {
            eprintln!(
                "terramesh: [{}/{}] {name}: {detail} ({seconds:.2} s)",
                s.k, s.total
            );
        }
    }

    fn task_start(&self, what: &str, total: u64) {
        if self.bars {
            if let Some(spinner) = self.state().spinner.take() {
                spinner.finish_and_clear();
            }
            let b = ProgressBar::new(total);
            b.set_style(
                ProgressStyle::with_template(&format!(
                    "{{bar:40}} {{pos}}/{{len}} {what}  {{per_sec}}  ETA {{eta}}"
                ))
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
            );
            self.state().bar = Some(b);
        }
    }

    fn task_advance(&self, done: u64) {
        if let Some(b) = &self.state().bar {
            b.set_position(done);
        }
    }

    fn task_end(&self) {
        if let Some(b) = self.state().bar.take() {
            b.finish_and_clear();
        }
    }

    fn note(&self, text: &str) {
        if !self.quiet {
            eprintln!("terramesh: {text}");
        }
    }

    fn warn(&self, text: &str) {
        eprintln!("terramesh: {text}");
    }

    fn cancelled(&self) -> bool {
        terramesh::interrupt::cancelled()
    }
}
