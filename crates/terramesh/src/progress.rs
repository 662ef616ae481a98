//! Progress of long work, reported through a trait the front end implements (the binary
//! draws indicatif bars; a library user may log, or ignore it).

/// Receives progress from the pipeline. Every method has a default that does nothing, so
/// `&()` (see [`Silent`]) is a valid reporter.
///
/// ```
/// use terramesh::progress::Progress;
/// // reporters are Sync (stages may report from worker threads): a Mutex, not a RefCell
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
    /// A note for the user (what was read, what was skipped).
    fn note(&self, _text: &str) {}
}

/// A reporter that reports nothing.
#[derive(Debug, Default, Clone, Copy)]
pub struct Silent;

impl Progress for Silent {}
