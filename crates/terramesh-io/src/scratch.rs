//! Temporary files and folders of a running command, registered so that a front end stopping
//! on a signal (Ctrl-C, SIGTERM) can remove them before it exits.
//!
//! Every [`Output`](crate::output::Output) file registers its temporary file here until it is
//! committed or dropped, and `terramesh build` registers its staging folder. A signal handler
//! calls [`remove_all`] and exits; work that must not be cut in half by that (swapping a
//! finished build folder in) runs inside [`critical`], which [`remove_all`] waits for.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, MutexGuard};

static PENDING: Mutex<Vec<(u64, PathBuf)>> = Mutex::new(Vec::new());
static CRITICAL: Mutex<()> = Mutex::new(());
static NEXT: AtomicU64 = AtomicU64::new(0);

fn pending() -> MutexGuard<'static, Vec<(u64, PathBuf)>> {
    PENDING.lock().unwrap_or_else(|p| p.into_inner())
}

/// A registered temporary path: listed for [`remove_all`] until this guard is dropped
/// (dropping it does not remove the path; its owner does that).
///
/// ```
/// let dir = tempfile::tempdir()?;
/// let tmp = dir.path().join("half-written.tmp");
/// std::fs::write(&tmp, "partial")?;
/// let guard = terramesh_io::scratch::register(&tmp);
/// assert_eq!(terramesh_io::scratch::remove_all(), 1); // what a signal handler does
/// assert!(!tmp.exists());
/// drop(guard);
/// # Ok::<(), std::io::Error>(())
/// ```
#[derive(Debug)]
pub struct Scratch {
    id: u64,
}

/// Registers `path` (a file or a folder) as temporary.
pub fn register(path: &Path) -> Scratch {
    let id = NEXT.fetch_add(1, Ordering::Relaxed);
    pending().push((id, path.to_path_buf()));
    Scratch { id }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        pending().retain(|(id, _)| *id != self.id);
    }
}

/// Removes every registered path (folders with their contents) and returns how many there
/// were; waits for a [`critical`] section in progress. For a signal handler about to exit.
pub fn remove_all() -> usize {
    let _critical = CRITICAL.lock().unwrap_or_else(|p| p.into_inner());
    let paths: Vec<PathBuf> = pending().drain(..).map(|(_, p)| p).collect();
    for p in &paths {
        // Another thread may still be adding files to a folder: try a few times.
        for _ in 0..5 {
            let gone = match std::fs::symlink_metadata(p) {
                Err(_) => true,
                Ok(m) if m.is_dir() => std::fs::remove_dir_all(p).is_ok(),
                Ok(_) => std::fs::remove_file(p).is_ok(),
            };
            if gone {
                break;
            }
        }
    }
    paths.len()
}

/// Runs `f` so that [`remove_all`] does not run in the middle of it (it waits until `f`
/// returns).
///
/// ```
/// let n = terramesh_io::scratch::critical(|| 2 + 2);
/// assert_eq!(n, 4);
/// ```
pub fn critical<T>(f: impl FnOnce() -> T) -> T {
    let _critical = CRITICAL.lock().unwrap_or_else(|p| p.into_inner());
    f()
}
