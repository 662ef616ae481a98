//! A build is atomic as a whole: it is written into a temporary sibling of the output folder
//! and swapped in when every file is there, so the previous build stays complete until then.
//!
//! The folders, beside `OUT` on the same filesystem:
//!
//! * `.OUT.terramesh-tmp-PID-N`: the build in progress (removed on error, on a signal, and by
//!   the next build once the build that made it has ended, see below);
//! * `.OUT.terramesh-lock-PID-N`: an empty file the build holds an exclusive lock on
//!   (`std::fs::File::try_lock`: `flock` on Unix, `LockFileEx` on Windows) from before it
//!   creates its folders until it is done. The system releases the lock when the process
//!   ends in any way (a `SIGKILL` included) even while the process is a zombie nobody reaps
//!   or its PID is reused, so the next build takes a folder whose lock it can take for the
//!   remains of a stopped build, and one whose lock is held for a build still running. A
//!   folder without its lock file (left by a terramesh made before the lock) is judged by
//!   its PID as before;
//! * `.OUT.terramesh-old-PID-N`: the previous build during the swap (`OUT` is renamed to it,
//!   the new build renamed to `OUT`, then it is removed). A run killed between the two renames
//!   leaves it and no `OUT`: the next build renames it back to `OUT` first, so the previous
//!   build is never lost.
//!
//! Every build folder holds a [`MARKER`] file. An existing `OUT` is replaced only when it is a
//! build folder: it has the marker, or is empty, or holds nothing but the names a build
//! writes (folders of builds made before the marker). Any other folder is refused, never
//! deleted.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use terramesh_io::scratch::{self, Scratch};

use crate::error::{Context, Error, Result};
use crate::progress::Progress;
use crate::setting::Setting;

/// The file that marks a folder as one `terramesh build` wrote, and may replace.
pub const MARKER: &str = ".terramesh-build";

const MARKER_TEXT: &str = "This folder was written by `terramesh build`. The next build into it \
                           replaces it whole: keep your own files elsewhere.\n";

static SERIAL: AtomicU64 = AtomicU64::new(0);

/// The staging folder of one build of `out`.
#[derive(Debug)]
pub struct Staging {
    out: PathBuf,
    tmp: PathBuf,
    scratch: Option<Scratch>,
    /// The lock file, held for as long as this build runs, and its path.
    lock: Option<(std::fs::File, PathBuf, Scratch)>,
}

/// The lock file of the staging folders `.NAME.terramesh-{tmp,old}-PID-N` in `parent`.
fn lock_path(parent: &Path, name: &str, pid: u32, serial: &str) -> PathBuf {
    parent.join(format!(".{name}.terramesh-lock-{pid}-{serial}"))
}

/// Whether the build that made a staging folder still runs: `Some(true)` when another
/// process holds its lock file, `Some(false)` when the lock is free (the lock is then taken
/// and returned, so that no other build judges it meanwhile), `None` without a lock file.
fn held(lock: &Path) -> Option<std::result::Result<std::fs::File, ()>> {
    let f = std::fs::File::options()
        .read(true)
        .write(true)
        .open(lock)
        .ok()?;
    match f.try_lock() {
        Ok(()) => Some(Ok(f)),
        Err(std::fs::TryLockError::WouldBlock) => Some(Err(())),
        // A system without file locks: judge by the PID.
        Err(std::fs::TryLockError::Error(_)) => None,
    }
}

/// `out` made absolute (a symlink to a folder resolved), with its parent and its name.
fn split(out: &Path) -> Result<(PathBuf, PathBuf, String)> {
    let bad = |why: &str| Error::setting(Setting::Output, out.display(), why);
    let abs = std::path::absolute(out)
        .with_context(|| format!("cannot resolve the output folder {}", out.display()))?;
    let abs = match std::fs::symlink_metadata(&abs) {
        Ok(m) if m.file_type().is_symlink() => std::fs::canonicalize(&abs)
            .with_context(|| format!("cannot resolve the link {}", out.display()))?,
        _ => abs,
    };
    let (Some(parent), Some(name)) = (abs.parent(), abs.file_name()) else {
        return Err(bad(
            "is not a folder a build can be written to: name a folder",
        ));
    };
    if let Ok(cwd) = std::env::current_dir() {
        if cwd.starts_with(&abs) {
            return Err(bad(
                "is the current folder or contains it: a build replaces its output folder \
                 whole, so name a folder beside or below the current one",
            ));
        }
    }
    Ok((
        parent.to_path_buf(),
        abs.clone(),
        name.to_string_lossy().into_owned(),
    ))
}

/// Whether process `pid` still runs (on Linux; elsewhere a stale folder is taken as dead).
fn alive(pid: u32) -> bool {
    pid == std::process::id()
        || (cfg!(target_os = "linux") && Path::new(&format!("/proc/{pid}")).exists())
}

/// The sibling folders of earlier builds of `name` in `parent`: (kind, pid, serial, path);
/// `kind` is `tmp`, `old` or `lock` (a lock file).
fn siblings(parent: &Path, name: &str) -> Vec<(&'static str, u32, String, PathBuf)> {
    let prefix = format!(".{name}.terramesh-");
    let mut found = Vec::new();
    let Ok(entries) = std::fs::read_dir(parent) else {
        return found;
    };
    for e in entries.flatten() {
        let file = e.file_name().to_string_lossy().into_owned();
        let Some(rest) = file.strip_prefix(&prefix) else {
            continue;
        };
        let (kind, rest) = if let Some(r) = rest.strip_prefix("tmp-") {
            ("tmp", r)
        } else if let Some(r) = rest.strip_prefix("old-") {
            ("old", r)
        } else if let Some(r) = rest.strip_prefix("lock-") {
            ("lock", r)
        } else {
            continue;
        };
        let mut parts = rest.splitn(2, '-');
        if let (Some(pid), Some(serial)) = (parts.next().and_then(|p| p.parse().ok()), parts.next())
        {
            found.push((kind, pid, serial.to_string(), e.path()));
        }
    }
    found.sort();
    found
}

/// Whether `dir` may be replaced by a build: the marker, empty, or only the names a build
/// writes. `Err` names an entry that is not a build's.
fn replaceable(dir: &Path) -> Result<std::result::Result<(), (String, usize)>> {
    let entries: Vec<String> = std::fs::read_dir(dir)
        .with_context(|| format!("cannot read the output folder {}", dir.display()))?
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    if entries.iter().any(|e| e == MARKER) {
        return Ok(Ok(()));
    }
    let ours = |n: &str| {
        n.starts_with("dsm")
            || n.starts_with("samples.csv")
            || n.starts_with('.') && n.ends_with(".tmp")
            || [
                "mesh-quality.csv",
                "cross-validation.csv",
                "variogram.json",
                "report.html",
                "pictures",
            ]
            .contains(&n)
    };
    match entries.iter().find(|n| !ours(n)) {
        None => Ok(Ok(())),
        Some(n) => Ok(Err((n.clone(), entries.len()))),
    }
}

impl Staging {
    /// Checks that `out` may be replaced, cleans up after earlier runs that were stopped, and
    /// creates the staging folder (with its [`MARKER`]).
    pub fn begin(out: &Path, progress: &dyn Progress) -> Result<Staging> {
        let (parent, abs, name) = split(out)?;
        std::fs::create_dir_all(&parent)
            .with_context(|| format!("cannot create the folder {}", parent.display()))?;
        // This build's lock, taken before its folder exists.
        let serial = SERIAL.fetch_add(1, Ordering::Relaxed);
        let lock = lock_path(&parent, &name, std::process::id(), &serial.to_string());
        let lock_guard = scratch::register(&lock);
        let lock_file = std::fs::File::options()
            .create(true)
            .truncate(false)
            .write(true)
            .open(&lock)
            .with_context(|| format!("cannot create the lock file {}", lock.display()))?;
        // Where the system has no file locks, the PID test below stands alone.
        let _ = lock_file.try_lock();
        let mut staging = Staging {
            out: abs.clone(),
            tmp: parent.join(format!(
                ".{name}.terramesh-tmp-{}-{serial}",
                std::process::id()
            )),
            scratch: None,
            lock: Some((lock_file, lock.clone(), lock_guard)),
        };
        let mut stale_locks = Vec::new();
        for (kind, pid, serial, path) in siblings(&parent, &name) {
            if kind == "lock" {
                if path != lock {
                    stale_locks.push(path);
                }
                continue;
            }
            let (running, _taken) = match held(&lock_path(&parent, &name, pid, &serial)) {
                Some(Ok(f)) => (false, Some(f)),
                Some(Err(())) => (true, None),
                None => (alive(pid), None),
            };
            if running {
                progress.warn(&format!(
                    "{} belongs to another build of {} still running (process {pid})",
                    path.display(),
                    out.display()
                ));
                continue;
            }
            if kind == "old" && !abs.exists() {
                std::fs::rename(&path, &abs).with_context(|| {
                    format!(
                        "{} is the previous build, left by a build stopped while swapping \
                         folders; cannot rename it back to {}",
                        path.display(),
                        out.display()
                    )
                })?;
                progress.warn(&format!(
                    "restored {} from {}: a build was stopped while swapping folders",
                    out.display(),
                    path.display()
                ));
            } else if kind == "old" || path.join(MARKER).is_file() {
                std::fs::remove_dir_all(&path)
                    .with_context(|| format!("cannot remove the stale {}", path.display()))?;
                progress.note(&format!(
                    "removed {}, left by a build that was stopped (process {pid})",
                    path.display()
                ));
            }
        }
        // Lock files whose lock is free and whose folders are gone.
        for path in stale_locks {
            if let Some(Ok(_f)) = held(&path) {
                let _ = std::fs::remove_file(&path);
            }
        }
        check_replaceable(&abs, out)?;
        let tmp = staging.tmp.clone();
        staging.scratch = Some(scratch::register(&tmp));
        std::fs::create_dir(&tmp)
            .with_context(|| format!("cannot create the build folder {}", tmp.display()))?;
        std::fs::write(staging.tmp.join(MARKER), MARKER_TEXT)
            .with_context(|| format!("cannot write in {}", staging.tmp.display()))?;
        Ok(staging)
    }

    /// The folder the build writes into.
    pub fn dir(&self) -> &Path {
        &self.tmp
    }

    /// Swaps the finished build in: the previous build (if any) is renamed aside, the new one
    /// renamed to the output folder, the previous one removed.
    pub fn commit(mut self) -> Result<()> {
        let out = self.out.clone();
        check_replaceable(&out, &out)?;
        let old = self.tmp.with_file_name(
            self.tmp
                .file_name()
                .unwrap_or_default()
                .to_string_lossy()
                .replacen(".terramesh-tmp-", ".terramesh-old-", 1),
        );
        let old_guard = scratch::register(&old);
        let swapped = scratch::critical(|| -> Result<bool> {
            let had_old = out.exists();
            if had_old {
                std::fs::rename(&out, &old).with_context(|| {
                    format!("cannot move the previous build {} aside", out.display())
                })?;
            }
            if let Err(e) = std::fs::rename(&self.tmp, &out) {
                if had_old {
                    let _ = std::fs::rename(&old, &out);
                }
                return Err(e).with_context(|| {
                    format!("cannot rename {} to {}", self.tmp.display(), out.display())
                });
            }
            self.scratch = None;
            Ok(had_old)
        })?;
        if swapped {
            std::fs::remove_dir_all(&old).with_context(|| {
                format!(
                    "the build is complete, but the previous one {} could not be removed",
                    old.display()
                )
            })?;
        }
        drop(old_guard);
        Ok(())
    }
}

fn check_replaceable(abs: &Path, out: &Path) -> Result<()> {
    match std::fs::metadata(abs) {
        Err(_) => Ok(()),
        Ok(m) if !m.is_dir() => Err(Error::setting(
            Setting::Output,
            out.display(),
            "is a file, not a folder: name a new folder for the build",
        )),
        Ok(_) => match replaceable(abs)? {
            Ok(()) => Ok(()),
            Err((entry, n)) => Err(Error::setting(
                Setting::Output,
                out.display(),
                format!(
                    "exists and is not a terramesh build folder (no {MARKER} file; it holds \
                     '{}' among {n} entries): a build replaces its output folder whole, so \
                     name a new or empty folder",
                    crate::error::cut(&entry)
                ),
            )),
        },
    }
}

impl Drop for Staging {
    fn drop(&mut self) {
        if self.scratch.is_some() {
            let _ = std::fs::remove_dir_all(&self.tmp);
        }
        // The lock file last, still locked; the lock ends with the file.
        if let Some((file, path, _guard)) = self.lock.take() {
            let _ = std::fs::remove_file(&path);
            drop(file);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::progress::Silent;

    fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn a_dropped_build_leaves_the_previous_one_and_no_folder() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out");
        let s = Staging::begin(&out, &Silent).unwrap();
        std::fs::write(s.dir().join("a.txt"), "first").unwrap();
        s.commit().unwrap();
        assert_eq!(names(&out), [MARKER, "a.txt"]);
        let s = Staging::begin(&out, &Silent).unwrap();
        std::fs::write(s.dir().join("b.txt"), "second").unwrap();
        drop(s);
        assert_eq!(names(dir.path()), ["out"]);
        assert_eq!(names(&out), [MARKER, "a.txt"]);
        let s = Staging::begin(&out, &Silent).unwrap();
        std::fs::write(s.dir().join("b.txt"), "second").unwrap();
        s.commit().unwrap();
        assert_eq!(names(dir.path()), ["out"]);
        assert_eq!(names(&out), [MARKER, "b.txt"]);
    }

    #[test]
    fn a_folder_of_other_files_is_refused_and_kept() {
        let dir = tempfile::tempdir().unwrap();
        let home = dir.path().join("home");
        std::fs::create_dir(&home).unwrap();
        std::fs::write(home.join("thesis.tex"), "years of work").unwrap();
        std::fs::write(home.join("dsm.vtu"), "an old export").unwrap();
        let e = Staging::begin(&home, &Silent).unwrap_err().to_string();
        assert!(
            e.contains(&home.display().to_string())
                && e.contains("not a terramesh build folder")
                && e.contains("'thesis.tex' among 2 entries"),
            "{e}"
        );
        assert_eq!(names(&home), ["dsm.vtu", "thesis.tex"]);
        assert_eq!(names(dir.path()), ["home"]);
        // A file is refused as well.
        let e = Staging::begin(&home.join("thesis.tex"), &Silent).unwrap_err();
        assert!(e.to_string().contains("is a file"), "{e}");
        // An empty folder, and one with only a build's files, are replaced.
        let empty = dir.path().join("empty");
        std::fs::create_dir(&empty).unwrap();
        Staging::begin(&empty, &Silent).unwrap().commit().unwrap();
        assert_eq!(names(&empty), [MARKER]);
        std::fs::remove_file(home.join("thesis.tex")).unwrap();
        std::fs::create_dir(home.join("pictures")).unwrap();
        Staging::begin(&home, &Silent).unwrap().commit().unwrap();
        assert_eq!(names(&home), [MARKER]);
    }

    const HOLDER_VAR: &str = "TERRAMESH_TEST_STAGING_OUT";

    /// The child half of `a_killed_build_left_a_zombie_does_not_keep_its_folder`: begins a
    /// build of the folder its parent names and waits to be killed.
    #[test]
    #[ignore = "a helper process of a_killed_build_left_a_zombie_does_not_keep_its_folder"]
    fn staging_holder() {
        let Some(out) = std::env::var_os(HOLDER_VAR) else {
            return;
        };
        let s = Staging::begin(Path::new(&out), &Silent).unwrap();
        std::fs::write(s.dir().join("ready"), "").unwrap();
        loop {
            std::thread::sleep(std::time::Duration::from_secs(60));
        }
    }

    /// Issue 34 item 13: a build killed with SIGKILL whose process nobody reaps (a zombie:
    /// `/proc/PID` still exists, as in a container without an init) left its staging folder;
    /// the next build removes it, because the killed process's lock was released by the
    /// kernel. While that process ran, its folder was kept.
    #[cfg(target_os = "linux")]
    #[test]
    fn a_killed_build_left_a_zombie_does_not_keep_its_folder() {
        use std::time::{Duration, Instant};
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out");
        let mut child = std::process::Command::new(std::env::current_exe().unwrap())
            .args([
                "--exact",
                "build::staging::tests::staging_holder",
                "--ignored",
                "--test-threads=1",
            ])
            .env(HOLDER_VAR, &out)
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap();
        let pid = child.id();
        let tmp = dir.path().join(format!(".out.terramesh-tmp-{pid}-0"));
        let t0 = Instant::now();
        while !tmp.join("ready").exists() {
            assert!(
                t0.elapsed() < Duration::from_secs(60),
                "the child never began"
            );
            std::thread::sleep(Duration::from_millis(20));
        }
        // Running: its folder is kept.
        drop(Staging::begin(&out, &Silent).unwrap());
        assert!(tmp.join("ready").exists());
        child.kill().unwrap(); // SIGKILL, and no wait: a zombie
        let state = || {
            std::fs::read_to_string(format!("/proc/{pid}/stat"))
                .ok()
                .and_then(|s| s.rsplit(')').next().map(|r| r.trim().to_string()))
                .unwrap_or_default()
        };
        // The thread group's leader turns zombie as soon as it exits, while the harness's
        // other threads may still be dying and holding the shared file table (and so the
        // lock): a zombie is what it is once it is the only task left.
        let tasks = || {
            std::fs::read_dir(format!("/proc/{pid}/task"))
                .map(|d| d.count())
                .unwrap_or(0)
        };
        let t0 = Instant::now();
        while !(state().starts_with('Z') && tasks() == 1) {
            assert!(
                t0.elapsed() < Duration::from_secs(60),
                "not a zombie: {}",
                state()
            );
            std::thread::sleep(Duration::from_millis(20));
        }
        assert!(
            alive(pid),
            "a zombie's /proc entry is what fooled the PID test"
        );
        let s = Staging::begin(&out, &Silent).unwrap();
        assert!(!tmp.exists(), "the zombie's staging folder survived");
        let left = names(dir.path());
        assert_eq!(left.len(), 2, "{left:?}"); // this build's folder and lock only
        drop(s);
        assert_eq!(names(dir.path()), Vec::<String>::new());
        child.wait().unwrap();
    }

    #[test]
    fn the_next_build_cleans_up_after_a_stopped_one() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out");
        let s = Staging::begin(&out, &Silent).unwrap();
        std::fs::write(s.dir().join("a.txt"), "first").unwrap();
        s.commit().unwrap();
        // A process that no longer runs (pid 0 is never a user process) left a half-written
        // build, and was stopped between the two renames of a swap with another one.
        let dead_tmp = dir.path().join(".out.terramesh-tmp-0-7");
        std::fs::create_dir(&dead_tmp).unwrap();
        std::fs::write(dead_tmp.join(MARKER), MARKER_TEXT).unwrap();
        std::fs::write(dead_tmp.join("half.txt"), "half").unwrap();
        let dead_old = dir.path().join(".out.terramesh-old-0-8");
        std::fs::rename(&out, &dead_old).unwrap();
        assert_eq!(
            names(dir.path()),
            [".out.terramesh-old-0-8", ".out.terramesh-tmp-0-7"]
        );
        let s = Staging::begin(&out, &Silent).unwrap();
        // The previous build is back in place until this one is swapped in.
        assert_eq!(names(&out), [MARKER, "a.txt"]);
        assert!(!dead_tmp.exists() && !dead_old.exists());
        drop(s);
        assert_eq!(names(dir.path()), ["out"]);
    }
}
