//! A build is atomic as a whole: it is written into a temporary sibling of the output folder
//! and swapped in when every file is there, so the previous build stays complete until then.
//!
//! The folders, beside `OUT` on the same filesystem:
//!
//! * `.OUT.terramesh-tmp-PID-N`: the build in progress (removed on error, on a signal, and by
//!   the next build when its process `PID` is gone);
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

/// The sibling folders of earlier builds of `name` in `parent`: (kind, pid, path).
fn siblings(parent: &Path, name: &str) -> Vec<(&'static str, u32, PathBuf)> {
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
        let (kind, rest) = match (rest.strip_prefix("tmp-"), rest.strip_prefix("old-")) {
            (Some(r), _) => ("tmp", r),
            (_, Some(r)) => ("old", r),
            _ => continue,
        };
        if let Some(pid) = rest.split('-').next().and_then(|p| p.parse().ok()) {
            found.push((kind, pid, e.path()));
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
        for (kind, pid, path) in siblings(&parent, &name) {
            if alive(pid) {
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
        check_replaceable(&abs, out)?;
        let tmp = parent.join(format!(
            ".{name}.terramesh-tmp-{}-{}",
            std::process::id(),
            SERIAL.fetch_add(1, Ordering::Relaxed)
        ));
        let scratch = scratch::register(&tmp);
        std::fs::create_dir(&tmp)
            .with_context(|| format!("cannot create the build folder {}", tmp.display()))?;
        let staging = Staging {
            out: abs,
            tmp,
            scratch: Some(scratch),
        };
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
