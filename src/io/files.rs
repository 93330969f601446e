//! Every output file goes through here: written to `PATH.partial` and renamed onto `PATH` only
//! when complete, so a failed, interrupted or concurrent run never leaves a half-written file
//! under the final name and never replaces a good one.
//!
//! The partial is opened without following a symlink (`O_NOFOLLOW`) and without blocking on a
//! FIFO (`O_NONBLOCK`), must be a regular file, and is locked (`flock`) for as long as it is
//! written: a second writer of the same path is refused at once. A partial left by a crashed
//! run (unlocked) is reused. Partials being written are registered, so a second interrupt
//! can remove them before the process ends ([`remove_unfinished`]).

use std::fs::{File, OpenOptions};
use std::io::Write;
use std::os::unix::fs::OpenOptionsExt;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// The partial-file name used while writing `path`.
#[must_use]
pub fn partial_path(path: &Path) -> PathBuf {
    let mut name = path.file_name().map(|n| n.to_os_string()).unwrap_or_default();
    name.push(".partial");
    path.with_file_name(name)
}

/// Why an output file cannot be written.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// The path names a directory, or has no file name.
    #[error("{}: is a directory; give a file name", .0.display())]
    IsDirectory(PathBuf),
    /// The directory it would go in does not exist.
    #[error("{}: directory {} does not exist", .path.display(), .dir.display())]
    NoDirectory {
        /// The output path.
        path: PathBuf,
        /// Its directory.
        dir: PathBuf,
    },
    /// `PATH.partial` is a symlink or not a regular file.
    #[error("{}: {problem}; refusing to write through it", .partial.display())]
    NotAFile {
        /// The partial path.
        partial: PathBuf,
        /// What it is.
        problem: &'static str,
    },
    /// The output would replace a file this run reads.
    #[error("{}: is an input of this run; choose another name for the output", .0.display())]
    IsInput(PathBuf),
    /// Another process is writing the same output.
    #[error("{}: another run is writing this file right now ({} is locked); wait for it or choose another name", .path.display(), .partial.display())]
    Busy {
        /// The output path.
        path: PathBuf,
        /// The locked partial.
        partial: PathBuf,
    },
    /// Any other I/O error, with what was being done.
    #[error("{}: cannot {action}: {source}", .path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// What was being done.
        action: &'static str,
        /// The OS error.
        source: std::io::Error,
    },
}

/// The files this process reads (canonical paths), so that no output replaces one of them.
static INPUTS: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Notes that this run reads `path` (a scenario, a log file, a calibration): an output of the same
/// run may not replace it.
pub fn note_input(path: &Path) {
    if let Ok(c) = std::fs::canonicalize(path) {
        let mut v = INPUTS.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        if !v.contains(&c) {
            v.push(c);
        }
    }
}

fn is_input(path: &Path, dir: &Path) -> bool {
    let Some(name) = path.file_name() else { return false };
    let Ok(dir) = std::fs::canonicalize(dir) else { return false };
    let out = dir.join(name);
    // A symlink at the output path is replaced by the rename, not followed: compare its own name.
    INPUTS.lock().unwrap_or_else(std::sync::PoisonError::into_inner).contains(&out)
}

/// Checks that `path` can name an output file, before anything runs: not a directory (nor a name
/// ending in `/`), in a directory that exists, not a file this run reads ([`note_input`]).
///
/// # Errors
/// See [`OutputError`].
pub fn check_output_path(path: &Path) -> Result<(), OutputError> {
    check_path(path, false)
}

fn check_path(path: &Path, may_replace_input: bool) -> Result<(), OutputError> {
    let text = path.as_os_str().to_string_lossy();
    if text.ends_with('/') || path.file_name().is_none() || path.is_dir() {
        return Err(OutputError::IsDirectory(path.to_path_buf()));
    }
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    if !dir.is_dir() {
        return Err(OutputError::NoDirectory { path: path.to_path_buf(), dir: dir.to_path_buf() });
    }
    if !may_replace_input && is_input(path, dir) {
        return Err(OutputError::IsInput(path.to_path_buf()));
    }
    // Checked again when the partial is opened (O_NOFOLLOW); here so that a long run is not
    // wasted on an output that will be refused at its end.
    let partial = partial_path(path);
    if std::fs::symlink_metadata(&partial).is_ok_and(|m| m.file_type().is_symlink()) {
        return Err(OutputError::NotAFile { partial, problem: "is a symlink" });
    }
    Ok(())
}

/// The partials this process is writing (removed by [`remove_unfinished`]).
static UNFINISHED: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn register(p: &Path) {
    UNFINISHED.lock().unwrap_or_else(std::sync::PoisonError::into_inner).push(p.to_path_buf());
}

fn unregister(p: &Path) {
    UNFINISHED.lock().unwrap_or_else(std::sync::PoisonError::into_inner).retain(|q| q != p);
}

/// Registers a partial *directory* (e.g. a log set being exported) for [`remove_unfinished`];
/// [`finished_dir`] takes it off the list.
pub fn unfinished_dir(p: &Path) {
    register(p);
}

/// The partial directory `p` was renamed or removed.
pub fn finished_dir(p: &Path) {
    unregister(p);
}

/// Removes every partial file and directory this process is still writing (a second interrupt:
/// the process ends now, and leaves no `.partial` behind).
pub fn remove_unfinished() {
    let list = std::mem::take(&mut *UNFINISHED.lock().unwrap_or_else(std::sync::PoisonError::into_inner));
    for p in list {
        if p.is_dir() {
            std::fs::remove_dir_all(&p).ok();
        } else {
            std::fs::remove_file(&p).ok();
        }
    }
}

/// An output being written: `PATH.partial`, locked; [`PartialFile::commit`] makes it `PATH`.
/// Dropped uncommitted, the partial is removed and `PATH` is untouched.
#[derive(Debug)]
pub struct PartialFile {
    file: File,
    path: PathBuf,
    partial: PathBuf,
    committed: bool,
}

impl PartialFile {
    /// Opens `PATH.partial` for writing (see the module docs).
    ///
    /// # Errors
    /// See [`OutputError`].
    pub fn create(path: &Path) -> Result<Self, OutputError> {
        Self::open(path, false)
    }

    fn open(path: &Path, may_replace_input: bool) -> Result<Self, OutputError> {
        check_path(path, may_replace_input)?;
        let partial = partial_path(path);
        let io = |action, source| OutputError::Io { path: partial.clone(), action, source };
        let file = OpenOptions::new()
            .write(true)
            .create(true)
            .truncate(false)
            .mode(0o644)
            .custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK | libc::O_CLOEXEC)
            .open(&partial)
            .map_err(|e| match e.raw_os_error() {
                Some(libc::ELOOP) => OutputError::NotAFile { partial: partial.clone(), problem: "is a symlink" },
                Some(libc::ENXIO) => OutputError::NotAFile { partial: partial.clone(), problem: "is a FIFO" },
                _ => io("create", e),
            })?;
        let meta = file.metadata().map_err(|e| io("inspect", e))?;
        if !meta.is_file() {
            return Err(OutputError::NotAFile { partial, problem: "is not a regular file" });
        }
        match file.try_lock() {
            Ok(()) => {}
            Err(std::fs::TryLockError::WouldBlock) => return Err(OutputError::Busy { path: path.to_path_buf(), partial }),
            Err(std::fs::TryLockError::Error(e)) => return Err(io("lock", e)),
        }
        // Ours now: a partial a crashed run left is started afresh.
        file.set_len(0).map_err(|e| io("truncate", e))?;
        register(&partial);
        Ok(Self { file, path: path.to_path_buf(), partial, committed: false })
    }

    /// The open partial.
    #[must_use]
    pub fn file(&self) -> &File {
        &self.file
    }

    /// The final path.
    #[must_use]
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The partial's path.
    #[must_use]
    pub fn partial(&self) -> &Path {
        &self.partial
    }

    /// Syncs the data, renames the partial onto the final path and syncs the directory; returns
    /// the file's size in bytes.
    ///
    /// # Errors
    /// The sync or the rename failed (the partial is then removed; the final path is untouched).
    pub fn commit(mut self) -> Result<u64, OutputError> {
        let io = |path: &Path, action, source| OutputError::Io { path: path.to_path_buf(), action, source };
        self.file.sync_all().map_err(|e| io(&self.partial, "write to disk", e))?;
        let bytes = self.file.metadata().map_err(|e| io(&self.partial, "inspect", e))?.len();
        std::fs::rename(&self.partial, &self.path).map_err(|e| io(&self.path, "rename the finished file onto", e))?;
        self.committed = true;
        unregister(&self.partial);
        let dir = match self.path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        if let Ok(d) = File::open(dir) {
            d.sync_all().ok();
        }
        Ok(bytes)
    }
}

impl Drop for PartialFile {
    fn drop(&mut self) {
        if !self.committed {
            std::fs::remove_file(&self.partial).ok();
            unregister(&self.partial);
        }
    }
}

/// Writes `bytes` to `path` through its partial file and a rename: never a half-written file.
///
/// # Errors
/// See [`OutputError`].
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    write_through(PartialFile::create(path)?, bytes)
}

/// [`write_atomically`] for a file this run reads and means to change (live mode's sliders
/// writing the scenario file).
///
/// # Errors
/// See [`OutputError`].
pub fn rewrite_input(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    write_through(PartialFile::open(path, true)?, bytes)
}

fn write_through(out: PartialFile, bytes: &[u8]) -> Result<(), OutputError> {
    out.file().write_all(bytes).map_err(|e| OutputError::Io { path: out.partial().to_path_buf(), action: "write", source: e })?;
    out.commit().map(|_| ())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("rinscope-files-{name}-{}", std::process::id()));
        std::fs::remove_dir_all(&d).ok();
        std::fs::create_dir_all(&d).expect("scratch dir");
        d
    }

    #[test]
    fn the_partial_file_sits_beside_the_final_one() {
        assert_eq!(partial_path(Path::new("out/x.rrd")), PathBuf::from("out/x.rrd.partial"));
        assert_eq!(partial_path(Path::new("x.json")), PathBuf::from("x.json.partial"));
    }

    #[test]
    fn a_symlink_at_the_partial_is_not_followed() {
        let d = scratch("symlink");
        let victim = d.join("victim.txt");
        std::fs::write(&victim, "precious").expect("victim");
        std::os::unix::fs::symlink(&victim, d.join("out.json.partial")).expect("symlink");
        let e = write_atomically(&d.join("out.json"), b"{}").expect_err("must refuse");
        assert!(matches!(e, OutputError::NotAFile { problem: "is a symlink", .. }), "{e}");
        assert_eq!(std::fs::read_to_string(&victim).expect("victim"), "precious");
        assert!(!d.join("out.json").exists());
    }

    #[test]
    fn a_second_writer_is_refused_and_an_abandoned_one_leaves_the_old_file() {
        let d = scratch("lock");
        let path = d.join("x.rrd");
        std::fs::write(&path, "old good file").expect("old");
        let first = PartialFile::create(&path).expect("first writer");
        let e = PartialFile::create(&path).expect_err("second writer");
        assert!(matches!(e, OutputError::Busy { .. }), "{e}");
        first.file().write_all(b"half").expect("write");
        drop(first); // abandoned
        assert!(!partial_path(&path).exists(), "partial removed");
        assert_eq!(std::fs::read_to_string(&path).expect("old"), "old good file");
        // A stale (unlocked) partial is reused; a committed write replaces the file.
        std::fs::write(partial_path(&path), "stale bytes from a crash").expect("stale");
        write_atomically(&path, b"new").expect("write");
        assert_eq!(std::fs::read_to_string(&path).expect("new"), "new");
    }

    #[test]
    fn directories_and_missing_directories_are_refused_up_front() {
        let d = scratch("dirs");
        assert!(matches!(check_output_path(&d), Err(OutputError::IsDirectory(_))));
        assert!(matches!(check_output_path(Path::new("new/")), Err(OutputError::IsDirectory(_))));
        assert!(matches!(check_output_path(&d.join("missing/x.json")), Err(OutputError::NoDirectory { .. })));
        assert!(check_output_path(&d.join("x.json")).is_ok());
    }

    #[test]
    fn a_fifo_at_the_partial_does_not_block() {
        let d = scratch("fifo");
        let fifo = d.join("x.json.partial");
        let status = std::process::Command::new("mkfifo").arg(&fifo).status().expect("mkfifo (coreutils) runs");
        assert!(status.success(), "mkfifo {}", fifo.display());
        let e = write_atomically(&d.join("x.json"), b"{}").expect_err("must refuse");
        assert!(matches!(e, OutputError::NotAFile { .. }), "{e}");
    }
}
