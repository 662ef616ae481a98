//! Progress of long work, reported through a trait the front end implements (the binary
//! draws indicatif bars; a library user may log, or ignore it).

/// Receives progress from the pipeline. Every method has a default that does nothing, so
/// `&()` (see [`Silent`]) is a valid reporter.
///
/// ```
/// use terramesh::progress::Progress;
/// struct Log(std::sync::Mutex<Vec<String>>);
/// impl Progress for Log {
///     fn stage_done(&self, name: &str, detail: &str, _seconds: f64) {
///         self.0.lock().unwrap().push(format!("{name}: {detail}"));
///     }
/// }
/// let log = Log(Default::default());
/// log.stage_done("mesh", "10 triangles", 0.1);
/// assert_eq!(log.0.lock().unwrap()[0], "mesh: 10 triangles");
/// ```
pub trait Progress: Sync {
    /// A stage begins: `index` of `total` (1-based).
    fn stage_start(&self, _index: usize, _total: usize, _name: &str) {}
    /// The current stage ended with a one-line summary after `seconds`.
    fn stage_done(&self, _name: &str, _detail: &str, _seconds: f64) {}
    /// A counted task begins (points fetched from a web service): `total` steps.
    fn task_start(&self, _what: &str, _total: u64) {}
    /// The counted task has done `done` steps.
    fn task_advance(&self, _done: u64) {}
    /// The counted task is over.
    fn task_end(&self) {}
    /// A note for the user (what was read, what was written); quiet front ends drop it.
    fn note(&self, _text: &str) {}
    /// A warning the user should see even when quiet (points left out).
    fn warn(&self, _text: &str) {}
    /// Whether the work should stop (the user pressed Ctrl-C). Long work asks between its
    /// stages and steps and then stops with [`Error::Cancelled`](crate::Error::Cancelled),
    /// removing what it was writing.
    ///
    /// ```
    /// use std::sync::atomic::{AtomicBool, Ordering};
    /// use terramesh::progress::Progress;
    /// struct Stop(AtomicBool);
    /// impl Progress for Stop {
    ///     fn cancelled(&self) -> bool {
    ///         self.0.load(Ordering::Relaxed)
    ///     }
    /// }
    /// let stop = Stop(AtomicBool::new(true));
    /// assert!(stop.cancelled());
    /// ```
    fn cancelled(&self) -> bool {
        false
    }
}

/// A reporter that reports nothing.
#[derive(Debug, Default, Clone, Copy)]
pub struct Silent;

impl Progress for Silent {}
