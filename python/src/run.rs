//! Long work off the GIL, stoppable by Ctrl-C, with panics caught.
//!
//! The work runs on a scoped worker thread; the calling thread waits without the GIL and, every
//! 50 ms, takes it back to run Python's signal handlers. A `KeyboardInterrupt` raised there
//! sets the [`Cancel`] flag that the work polls between its steps (the facade's
//! [`Progress::cancelled`], the chunks of [`chunked`]); the call then waits for the work to
//! stop and raises the `KeyboardInterrupt`.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::time::Duration;

use pyo3::prelude::*;
use terramesh::progress::Progress;

use crate::errors::InternalError;

/// The cancel flag of one call; also the [`Progress`] given to the facade.
#[derive(Default)]
pub(crate) struct Cancel {
    flag: AtomicBool,
    /// Print stage lines to standard error.
    pub verbose: bool,
}

impl Cancel {
    pub(crate) fn is_set(&self) -> bool {
        self.flag.load(Ordering::Relaxed)
    }

    /// `Err(Cancelled)` once the flag is set.
    pub(crate) fn check(&self) -> terramesh::Result<()> {
        if self.is_set() {
            Err(terramesh::Error::Cancelled)
        } else {
            Ok(())
        }
    }
}

impl Progress for Cancel {
    fn stage_start(&self, index: usize, total: usize, name: &str) {
        if self.verbose {
            eprintln!("terramesh: [{index}/{total}] {name}");
        }
    }
    fn stage_done(&self, name: &str, detail: &str, seconds: f64) {
        if self.verbose {
            eprintln!("terramesh: {name}: {detail} ({seconds:.2} s)");
        }
    }
    fn warn(&self, text: &str) {
        eprintln!("terramesh: warning: {text}");
    }
    fn cancelled(&self) -> bool {
        self.is_set()
    }
}

/// Runs `work` without the GIL; see the module docs.
pub(crate) fn run<T, F>(py: Python<'_>, verbose: bool, work: F) -> PyResult<T>
where
    T: Send,
    F: FnOnce(&Cancel) -> PyResult<T> + Send,
{
    let cancel = Cancel {
        flag: AtomicBool::new(false),
        verbose,
    };
    let (tx, rx) = mpsc::channel::<()>();
    // A `Receiver` is `Send` but not `Sync`: the waiting closure borrows it through a mutex.
    let rx = std::sync::Mutex::new(rx);
    std::thread::scope(|scope| {
        let cancel = &cancel;
        let handle = scope.spawn(move || {
            let out = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| work(cancel)));
            let _ = tx.send(());
            out
        });
        let mut interrupt: Option<PyErr> = None;
        loop {
            let done = py.allow_threads(|| {
                rx.lock()
                    .expect("only this thread locks it")
                    .recv_timeout(Duration::from_millis(50))
            });
            if done.is_ok() || matches!(done, Err(mpsc::RecvTimeoutError::Disconnected)) {
                break;
            }
            if interrupt.is_none() {
                if let Err(e) = py.check_signals() {
                    cancel.flag.store(true, Ordering::Relaxed);
                    interrupt = Some(e);
                }
            }
        }
        let out = handle.join().unwrap_or_else(Err);
        if let Some(e) = interrupt {
            return Err(e);
        }
        match out {
            Ok(r) => r,
            Err(panic) => {
                let what = panic
                    .downcast_ref::<&str>()
                    .map(|s| s.to_string())
                    .or_else(|| panic.downcast_ref::<String>().cloned())
                    .unwrap_or_else(|| "unknown panic".into());
                Err(InternalError::new_err(format!(
                    "internal error (please report it with the input): {what}"
                )))
            }
        }
    })
}

/// Targets per step of chunked work: the cancel flag is polled between steps.
pub(crate) const CHUNK: usize = 16_384;

/// Calls `step(range)` over `0..n` in chunks of [`CHUNK`], stopping when `cancel` is set.
pub(crate) fn chunked(
    n: usize,
    cancel: &Cancel,
    mut step: impl FnMut(std::ops::Range<usize>) -> terramesh::Result<()>,
) -> terramesh::Result<()> {
    let mut lo = 0;
    while lo < n {
        cancel.check()?;
        let hi = (lo + CHUNK).min(n);
        step(lo..hi)?;
        lo = hi;
    }
    cancel.check()
}

/// Floats borrowed from numpy, or copied.
pub(crate) type Floats<'a> = std::borrow::Cow<'a, [f64]>;

/// The float64 numpy array of the argument `name` as a slice: borrowed when contiguous, else
/// copied (its size checked first: a `TooLargeError`, never an abort). Every value must be
/// finite: a NaN or an infinity is refused naming the argument and the index.
pub(crate) fn floats<'a>(
    name: &str,
    a: &'a numpy::PyReadonlyArray1<'_, f64>,
) -> PyResult<Floats<'a>> {
    let s = match a.as_slice() {
        Ok(s) => std::borrow::Cow::Borrowed(s),
        Err(_) => {
            let view = a.as_array();
            let mut v = terramesh_core::limits::try_with_capacity(view.len(), "values")
                .map_err(|e| crate::errors::too_large_for(name, e))?;
            v.extend(view.iter().copied());
            std::borrow::Cow::Owned(v)
        }
    };
    finite(name, &s)?;
    Ok(s)
}

/// An error naming `name[i]` for the first value of `values` that is not finite.
pub(crate) fn finite(name: &str, values: &[f64]) -> PyResult<()> {
    match values.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(i) => Err(crate::errors::input(format!(
            "{name}[{i}] is {}: every value must be a finite number (drop or fill missing \
             values first)",
            values[i]
        ))),
    }
}

/// Room for `n` values of `T` for the results of the argument `name`, reserved after checking
/// the size: a `TooLargeError` naming `name`, never an abort.
pub(crate) fn room<T>(name: &str, n: usize) -> PyResult<Vec<T>> {
    terramesh_core::limits::try_with_capacity(n, "values")
        .map_err(|e| crate::errors::too_large_for(name, e))
}

/// Checks that `n` items of `bytes_each` bytes (`what`, for the argument `name`) fit the
/// memory ceiling before any of them is allocated.
pub(crate) fn fits(name: &str, what: &'static str, n: usize, bytes_each: f64) -> PyResult<()> {
    terramesh_core::limits::Estimate::new(what, n as f64, bytes_each)
        .check()
        .map(|_| ())
        .map_err(|e| crate::errors::too_large_for(name, e))
}

/// Two equally long, finite coordinate arrays, or an error naming them.
pub(crate) fn pair<'a>(
    names: (&str, &str),
    a: &'a numpy::PyReadonlyArray1<'_, f64>,
    b: &'a numpy::PyReadonlyArray1<'_, f64>,
) -> PyResult<(Floats<'a>, Floats<'a>)> {
    let (a, b) = (floats(names.0, a)?, floats(names.1, b)?);
    if a.len() != b.len() {
        return Err(crate::errors::input(format!(
            "{} and {} must have the same length ({} and {} given)",
            names.0,
            names.1,
            a.len(),
            b.len()
        )));
    }
    Ok((a, b))
}
