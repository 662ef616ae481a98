//! Inputs of readers that take a path: written into one temporary folder per thread, kept for
//! the life of the process (a fuzzer runs millions of inputs; creating a folder each time would
//! dominate).

use std::cell::RefCell;
use std::path::PathBuf;

thread_local! {
    static DIR: RefCell<Option<tempfile::TempDir>> = const { RefCell::new(None) };
}

/// Writes `data` to `name` in this thread's temporary folder and returns its path.
///
/// # Panics
/// If the temporary folder cannot be made or written (the harness cannot run at all).
pub fn write(name: &str, data: &[u8]) -> PathBuf {
    DIR.with(|d| {
        let mut d = d.borrow_mut();
        let dir = d.get_or_insert_with(|| tempfile::tempdir().expect("a temporary folder"));
        let path = dir.path().join(name);
        std::fs::write(&path, data).expect("write the fuzz input");
        path
    })
}
