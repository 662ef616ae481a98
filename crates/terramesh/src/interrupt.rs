//! Ctrl-C and SIGTERM for a command-line front end: stop promptly, remove what was being
//! written, keep what was there.
//!
//! [`install`] sets a handler whose first signal sets a flag ([`cancelled`]) that the front
//! end's [`Progress::cancelled`](crate::progress::Progress::cancelled) returns, so the library
//! stops between stages and steps with [`Error::Cancelled`](crate::Error::Cancelled), its
//! temporary files and folders removed. If the work has not stopped [`GRACE`] later (a stage
//! deep in a kernel), or on a second signal, the handler removes every registered temporary
//! path itself ([`terramesh_io::scratch::remove_all`]), prints its notice and exits with
//! [`EXIT_INTERRUPTED`]. Outputs already there are never touched (every file is written
//! atomically, a build is swapped in whole), and a web acquisition's journal is kept for
//! `--resume` (it is appended as answers arrive, not a temporary file).
//!
//! A host that handles signals itself (Python) does not install it.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Mutex, OnceLock};
use std::time::Duration;

/// The exit code of a command stopped by a signal (128 + SIGINT, as shells report it).
pub const EXIT_INTERRUPTED: u8 = 130;

/// How long the work may take to stop by itself before the handler stops it.
pub const GRACE: Duration = Duration::from_millis(1500);

static CANCELLED: AtomicBool = AtomicBool::new(false);

/// What the handler prints (on standard error) as it exits.
static NOTICE: OnceLock<&'static str> = OnceLock::new();

/// Held by whichever thread ends the process, so the main thread and the handler never exit
/// at once.
static EXIT: Mutex<()> = Mutex::new(());

/// Installs the handler, which prints `notice` if it has to end the process itself (a failure
/// to install leaves the default: the signal kills). Call it once per process.
pub fn install(notice: &'static str) {
    let _ = NOTICE.set(notice);
    let _ = ctrlc::set_handler(|| {
        if CANCELLED.swap(true, Ordering::SeqCst) {
            force();
        }
        std::thread::spawn(|| {
            std::thread::sleep(GRACE);
            force();
        });
    });
}

/// Whether a signal arrived.
pub fn cancelled() -> bool {
    CANCELLED.load(Ordering::SeqCst)
}

/// Removes the registered temporary paths and exits with [`EXIT_INTERRUPTED`].
fn force() -> ! {
    let guard = EXIT.lock().unwrap_or_else(|p| p.into_inner());
    terramesh_io::scratch::remove_all();
    if let Some(notice) = NOTICE.get() {
        eprintln!("{notice}");
    }
    std::mem::forget(guard);
    std::process::exit(EXIT_INTERRUPTED.into())
}

/// Called by the front end's `main` as it ends: from here the handler can no longer exit in
/// between.
pub fn finishing() {
    std::mem::forget(EXIT.lock().unwrap_or_else(|p| p.into_inner()));
}
