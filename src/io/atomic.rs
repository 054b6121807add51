//! Atomic file writes: every file the crate writes (meshes, point sets, the `--report` JSON)
//! goes to a temporary file in the target's directory, created by `tempfile` under a name no
//! other writer can hold (so two processes or threads writing the same target never share a
//! temporary file), and is renamed onto the target only once it is complete and synced. A
//! reader never sees a half-written file; on failure the target keeps its old content (or stays
//! absent) and the temporary file is removed.
//!
//! [`write_atomically`] writes a file in one go; [`AtomicFile`] is the same for a file written
//! piece by piece (streamed point sets).

use std::ffi::OsString;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use tempfile::NamedTempFile;

use crate::error::{Error, Result};

/// Size of the write buffer in front of the temporary file, in bytes.
const BUFFER_BYTES: usize = 1 << 20;

/// A file being written at a temporary path beside its target, moved onto the target by
/// [`AtomicFile::commit`]. Dropped without a commit (an error on the way), it removes the
/// temporary file and leaves the target as it was.
///
/// Writes through [`std::io::Write`] are buffered; their errors are plain [`std::io::Error`]s,
/// which [`AtomicFile::error`] turns into an [`Error::Write`] naming the target.
pub struct AtomicFile {
    /// The path as given (for messages).
    path: PathBuf,
    /// Where the file goes: `path`, or the file a symbolic link at `path` points to.
    target: PathBuf,
    output: BufWriter<NamedTempFile>,
    /// The temporary file on the list an interrupted run removes.
    _registered: super::temporaries::Registered,
}

impl AtomicFile {
    /// Creates the temporary file for the target `path` in `path`'s directory (the current one
    /// for a bare file name), named `.NAME.XXXXXX.tmp` with a random `XXXXXX`, with the
    /// permissions a plain `File::create` would give (0o666 less the umask on Unix).
    ///
    /// # Errors
    /// [`Error::Write`] naming `path` when it names no file or the directory is missing or not
    /// writable.
    pub fn create(path: &Path) -> Result<AtomicFile> {
        let given = path;
        let target = write_target(path)?;
        let path = target.as_path();
        let file_name = path
            .file_name()
            .ok_or_else(|| write_error(given, "the path names no file".to_string()))?;
        let dir = match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        let mut prefix = OsString::from(".");
        prefix.push(file_name);
        prefix.push(".");
        let mut builder = tempfile::Builder::new();
        builder.prefix(&prefix).suffix(".tmp");
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            builder.permissions(std::fs::Permissions::from_mode(0o666));
        }
        let file = builder.tempfile_in(dir).map_err(|e| {
            write_error(
                given,
                format!("cannot create a temporary file in {}: {e}", dir.display()),
            )
        })?;
        Ok(AtomicFile {
            path: given.to_path_buf(),
            target,
            _registered: super::temporaries::register(file.path()),
            output: BufWriter::with_capacity(BUFFER_BYTES, file),
        })
    }

    /// The target path (not the temporary one).
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// An [`Error::Write`] naming the target, with `message`.
    pub fn error(&self, message: impl Into<String>) -> Error {
        write_error(&self.path, message.into())
    }

    /// Flushes and syncs the temporary file, then renames it onto the target, replacing an
    /// existing file there ([`AtomicFile::finish`], then [`FinishedFile::persist`]).
    ///
    /// # Errors
    /// [`Error::Write`] naming the target when flushing, syncing or renaming fails; the
    /// temporary file is removed and the target keeps its old content.
    pub fn commit(self) -> Result<()> {
        self.finish()?.persist()
    }

    /// Flushes and syncs the temporary file: every byte is on disk, nothing is renamed yet. For
    /// several files that go in together (a mesh and its report): each is finished before any is
    /// persisted, so a disk that fills up on the last one leaves every target as it was.
    ///
    /// # Errors
    /// [`Error::Write`] naming the target when flushing or syncing fails (a full disk, a file
    /// size limit); the temporary file is removed and the target keeps its old content.
    pub fn finish(self) -> Result<FinishedFile> {
        let AtomicFile {
            path,
            target,
            output,
            _registered,
        } = self;
        let file = output
            .into_inner()
            .map_err(|e| write_error(&path, e.error().to_string()))?;
        file.as_file()
            .sync_all()
            .map_err(|e| write_error(&path, e.to_string()))?;
        Ok(FinishedFile {
            path,
            target,
            file,
            _registered,
        })
    }
}

/// A temporary file written in full and synced ([`AtomicFile::finish`]), waiting to be renamed
/// onto its target by [`FinishedFile::persist`]. Dropped without it, it removes the temporary
/// file and leaves the target as it was.
pub struct FinishedFile {
    path: PathBuf,
    target: PathBuf,
    file: NamedTempFile,
    _registered: super::temporaries::Registered,
}

impl FinishedFile {
    /// Renames the temporary file onto the target, replacing an existing file there. A rename
    /// in one directory does not need room on the disk.
    ///
    /// # Errors
    /// [`Error::Write`] naming the target when the rename fails; the temporary file is removed
    /// and the target keeps its old content.
    pub fn persist(self) -> Result<()> {
        let FinishedFile {
            path, target, file, ..
        } = self;
        file.persist(&target).map_err(|e| {
            write_error(
                &path,
                format!(
                    "cannot rename {} onto it: {}",
                    e.file.path().display(),
                    e.error
                ),
            )
        })?;
        Ok(())
    }
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.output.write(buf)
    }

    fn write_all(&mut self, buf: &[u8]) -> std::io::Result<()> {
        self.output.write_all(buf)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.output.flush()
    }
}

/// Writes the file at `path` atomically: `write` fills a temporary file beside it (through a
/// buffer), which then replaces `path`. When `write` or the commit fails, the temporary file is
/// removed and `path` keeps its old content (or stays absent).
///
/// # Errors
/// [`Error::Write`] naming `path` when the directory is missing or not writable, the path names
/// no file, `write` returns an error, or syncing or renaming fails.
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<()> {
    let mut file = AtomicFile::create(path)?;
    write(&mut file).map_err(|e| file.error(e.to_string()))?;
    file.commit()
}

/// The file a write to `path` replaces: `path` itself, or, where `path` is a symbolic link
/// (a chain of them), the file it points to, so the link stays a link and its target gets the
/// content. Only regular files are replaced: a directory, a FIFO, a socket or a device at the
/// target (`/dev/null`, `/dev/full`) is refused, since the rename would put a regular file in
/// its place.
///
/// # Errors
/// [`Error::Write`] naming `path` for a target that is not a regular file, or a link that
/// cannot be followed.
fn write_target(path: &Path) -> Result<PathBuf> {
    let mut target = path.to_path_buf();
    // Follow a chain of links (a bounded one: a loop is an error).
    for _ in 0..40 {
        match std::fs::symlink_metadata(&target) {
            Ok(m) if m.file_type().is_symlink() => {
                let link = std::fs::read_link(&target)
                    .map_err(|e| write_error(path, format!("cannot follow the link: {e}")))?;
                target = match target.parent() {
                    Some(dir) if link.is_relative() => dir.join(link),
                    _ => link,
                };
            }
            Ok(m) if !m.file_type().is_file() => {
                return Err(write_error(
                    path,
                    format!(
                        "{} is not a regular file (a directory, device, FIFO or socket); \
                         outputs are written as regular files only",
                        target.display()
                    ),
                ));
            }
            // A regular file, or nothing yet.
            _ => return Ok(target),
        }
    }
    Err(write_error(
        path,
        "too many levels of symbolic links".to_string(),
    ))
}

fn write_error(path: &Path, message: String) -> Error {
    Error::Write {
        path: path.to_path_buf(),
        message,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The names in `dir`, sorted.
    fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn a_failed_write_keeps_the_old_file_and_leaves_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.txt");
        std::fs::write(&path, b"old").unwrap();
        let e = write_atomically(&path, |w| {
            w.write_all(b"half")?;
            Err(std::io::Error::other("disk on fire"))
        })
        .unwrap_err();
        assert!(
            matches!(&e, Error::Write { path: p, .. } if p == &path),
            "{e}"
        );
        assert!(e.to_string().contains("disk on fire"), "{e}");
        assert_eq!(std::fs::read(&path).unwrap(), b"old");
        assert_eq!(names(dir.path()), ["out.txt"]);
        // A dropped, uncommitted file leaves nothing either.
        let mut f = AtomicFile::create(&dir.path().join("never.txt")).unwrap();
        f.write_all(b"lost").unwrap();
        drop(f);
        assert_eq!(names(dir.path()), ["out.txt"]);
    }

    #[test]
    fn a_written_file_replaces_the_old_one_with_the_usual_permissions() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.txt");
        std::fs::write(&path, b"old content").unwrap();
        write_atomically(&path, |w| w.write_all(b"new")).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"new");
        assert_eq!(names(dir.path()), ["out.txt"]);
        #[cfg(unix)]
        {
            // The same mode as a file made by File::create (tempfile's own default is 0o600).
            use std::os::unix::fs::PermissionsExt;
            let plain = dir.path().join("plain.txt");
            std::fs::File::create(&plain).unwrap();
            let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode();
            assert_eq!(mode(&path), mode(&plain));
        }
    }

    #[test]
    fn errors_name_the_target() {
        let dir = tempfile::tempdir().unwrap();
        let missing = dir.path().join("no-such-dir").join("out.txt");
        let e = write_atomically(&missing, |w| w.write_all(b"x")).unwrap_err();
        assert!(
            matches!(&e, Error::Write { path, .. } if path == &missing),
            "{e}"
        );
        // The target is a directory: the rename fails and the temporary file goes.
        let taken = dir.path().join("taken");
        std::fs::create_dir(&taken).unwrap();
        let e = write_atomically(&taken, |w| w.write_all(b"x")).unwrap_err();
        assert!(
            matches!(&e, Error::Write { path, .. } if path == &taken),
            "{e}"
        );
        assert_eq!(names(dir.path()), ["taken"]);
    }

    /// Two writers of one target at once: each has its own temporary file, so the target ends
    /// up as one of the two contents, complete, and no temporary file is left.
    #[test]
    fn concurrent_writers_of_one_target_do_not_collide() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("shared.bin");
        let contents: Vec<Vec<u8>> = (0..2u8).map(|k| vec![b'a' + k; 3 << 20]).collect();
        for _ in 0..5 {
            let barrier = std::sync::Barrier::new(contents.len());
            std::thread::scope(|s| {
                for c in &contents {
                    let (path, barrier) = (&path, &barrier);
                    s.spawn(move || {
                        let mut f = AtomicFile::create(path).unwrap();
                        barrier.wait();
                        // Written in pieces so the two writers interleave.
                        for piece in c.chunks(4096) {
                            f.write_all(piece).unwrap();
                        }
                        f.commit().unwrap();
                    });
                }
            });
            let written = std::fs::read(&path).unwrap();
            assert!(contents.contains(&written), "a mixed or partial file");
            assert_eq!(names(dir.path()), ["shared.bin"]);
        }
    }

    /// Issue 14, item 10: the rename replaced whatever sat at the output path, so a symbolic
    /// link became a regular file and (as root) `/dev/full` was replaced. A link is now written
    /// through, and a FIFO or a directory is refused and left as it was.
    #[cfg(unix)]
    #[test]
    fn links_are_written_through_and_special_files_refused() {
        use std::os::unix::fs::{symlink, FileTypeExt};
        let dir = tempfile::tempdir().unwrap();
        let real = dir.path().join("real.obj");
        std::fs::write(&real, "old").unwrap();
        // A relative link, and a link to that link.
        let link = dir.path().join("link.obj");
        symlink("real.obj", &link).unwrap();
        let link2 = dir.path().join("link2.obj");
        symlink(&link, &link2).unwrap();
        write_atomically(&link2, |w| w.write_all(b"new")).unwrap();
        assert!(std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink());
        assert!(std::fs::symlink_metadata(&link2)
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(std::fs::read_to_string(&real).unwrap(), "new");
        // A dangling link: its target is created.
        let dangling = dir.path().join("dangling.obj");
        symlink("made.obj", &dangling).unwrap();
        write_atomically(&dangling, |w| w.write_all(b"made")).unwrap();
        assert_eq!(
            std::fs::read_to_string(dir.path().join("made.obj")).unwrap(),
            "made"
        );
        assert!(std::fs::symlink_metadata(&dangling)
            .unwrap()
            .file_type()
            .is_symlink());
        // A FIFO, directly and through a link: refused, still a FIFO, no temporary file left.
        let fifo = dir.path().join("fifo.obj");
        let made = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap();
        assert!(made.success(), "mkfifo failed");
        let to_fifo = dir.path().join("to-fifo.obj");
        symlink(&fifo, &to_fifo).unwrap();
        for p in [&fifo, &to_fifo] {
            let e = write_atomically(p, |w| w.write_all(b"x")).unwrap_err();
            assert!(matches!(e, Error::Write { .. }), "{e}");
            assert!(e.to_string().contains("not a regular file"), "{e}");
        }
        assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
        // A directory.
        let sub = dir.path().join("sub");
        std::fs::create_dir(&sub).unwrap();
        assert!(write_atomically(&sub, |w| w.write_all(b"x")).is_err());
        assert!(sub.is_dir());
        assert_eq!(
            names(dir.path()),
            [
                "dangling.obj",
                "fifo.obj",
                "link.obj",
                "link2.obj",
                "made.obj",
                "real.obj",
                "sub",
                "to-fifo.obj"
            ]
        );
    }
}
