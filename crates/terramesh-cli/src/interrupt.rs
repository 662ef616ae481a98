//! Ctrl-C and SIGTERM: stop promptly, remove what was being written, keep what was there.
//!
//! The first signal sets a flag that the library polls between stages and steps
//! ([`terramesh::progress::Progress::cancelled`]): the command stops with
//! [`terramesh::Error::Cancelled`], its temporary files and folders removed, and exits with
//! code 130. If it has not stopped [`GRACE`] later (a stage deep in a kernel), or on a second
//! signal, the handler removes every registered temporary path itself
//! ([`terramesh_io::scratch::remove_all`]) and exits. Outputs already there are never touched
//! (every file is written atomically, a build is swapped in whole), and a web acquisition's
//! journal is kept for `--resume` (it is appended as answers arrive, not a temporary file).

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;
use std::time::Duration;

/// The exit code of a command stopped by a signal (128 + SIGINT, as shells report it).
pub const EXIT_INTERRUPTED: u8 = 130;

/// How long the command may take to stop by itself before the handler stops it.
pub const GRACE: Duration = Duration::from_millis(1500);

static CANCELLED: AtomicBool = AtomicBool::new(false);

/// Held by whichever thread ends the process, so the main thread and the handler never exit
/// at once.
static EXIT: Mutex<()> = Mutex::new(());

/// Installs the handler (a failure to install leaves the default: the signal kills).
pub fn install() {
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
    eprintln!("terramesh: interrupted: unfinished files removed, existing outputs untouched");
    std::mem::forget(guard);
    std::process::exit(EXIT_INTERRUPTED.into())
}

/// Called by `main` as it ends: from here the handler can no longer exit in between.
pub fn finishing() {
    std::mem::forget(EXIT.lock().unwrap_or_else(|p| p.into_inner()));
}
