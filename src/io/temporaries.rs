//! The temporary files and folders alive in this process (an [`AtomicFile`](super::AtomicFile)'s
//! file beside its target, `remesh simplify`'s bucket folder), so that an interrupted run can
//! remove them: the `remesh` binary's SIGINT/SIGTERM/SIGHUP handler calls
//! [`remove_temporaries`] before it exits. A normal run removes its temporaries itself (on
//! commit or drop); this list only serves the signal path.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;

static LIVE: Mutex<BTreeMap<u64, PathBuf>> = Mutex::new(BTreeMap::new());
static NEXT: AtomicU64 = AtomicU64::new(0);

/// A temporary path on the list; dropping it takes the path off the list (it does not remove
/// the file: its owner does).
#[derive(Debug)]
pub(crate) struct Registered(u64);

impl Drop for Registered {
    fn drop(&mut self) {
        if let Ok(mut live) = LIVE.lock() {
            live.remove(&self.0);
        }
    }
}

/// Puts `path` (a file or a folder) on the list of temporaries until the returned guard drops.
pub(crate) fn register(path: &Path) -> Registered {
    let id = NEXT.fetch_add(1, Ordering::Relaxed);
    if let Ok(mut live) = LIVE.lock() {
        live.insert(id, path.to_path_buf());
    }
    Registered(id)
}

/// The error of a temporary file or folder of this process's own (`what`, at `path`, in the
/// temporary directory: `TMPDIR`, else `/tmp`, where `from_tmpdir`; else the directory the caller
/// gave) that cannot be made, written or read back: the environment's fault, not the input's,
/// so an [`Error::Write`](crate::error::Error::Write) (exit code 4) naming the directory, never an input error.
pub(crate) fn temporary_error(
    path: &Path,
    what: &str,
    from_tmpdir: bool,
    e: std::io::Error,
) -> crate::error::Error {
    let which = if from_tmpdir {
        "the temporary directory (TMPDIR; set it to a writable directory with room)"
    } else {
        "the temporary directory given"
    };
    crate::error::Error::Write {
        path: path.to_path_buf(),
        message: format!("{what} in {which}: {e}"),
    }
}

/// Removes every temporary file and folder on the list (a folder with its content) and
/// empties the list; returns how many paths were removed. For a signal handler: it never
/// panics, and paths already gone are skipped.
pub fn remove_temporaries() -> usize {
    remove_where(|_| true)
}

/// Removes the temporaries on the list whose path `which` accepts and takes them off it.
fn remove_where(which: impl Fn(&Path) -> bool) -> usize {
    let mut live = LIVE.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    let ids: Vec<u64> = live
        .iter()
        .filter(|(_, p)| which(p))
        .map(|(&id, _)| id)
        .collect();
    let paths: Vec<PathBuf> = ids.iter().filter_map(|id| live.remove(id)).collect();
    drop(live);
    paths
        .iter()
        .filter(|p| {
            if p.is_dir() {
                std::fs::remove_dir_all(p).is_ok()
            } else {
                std::fs::remove_file(p).is_ok()
            }
        })
        .count()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn registered_paths_are_removed_and_dropped_guards_leave_the_list() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("a.tmp");
        let folder = dir.path().join("buckets");
        let kept = dir.path().join("kept.tmp");
        std::fs::write(&file, b"x").unwrap();
        std::fs::create_dir(&folder).unwrap();
        std::fs::write(folder.join("0.bin"), b"y").unwrap();
        std::fs::write(&kept, b"z").unwrap();
        let _a = register(&file);
        let _b = register(&folder);
        drop(register(&kept));
        // Other tests of this process hold temporaries of their own: only this folder's go.
        assert_eq!(remove_where(|p| p.starts_with(dir.path())), 2);
        assert!(!file.exists());
        assert!(!folder.exists());
        assert!(kept.exists());
    }
}
