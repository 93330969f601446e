//! Every file a run reads or writes goes through here.
//!
//! Inputs (a scenario, a log set's manifest, table description and data files, a calibration, a
//! shard file, a recording) are opened by [`open_input`] only: without blocking, and refused at
//! once unless they are regular files, so a FIFO, a device or a directory never hangs a command.
//!
//! Outputs are written to `PATH.partial` and renamed onto `PATH` only
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
    /// The path is a FIFO, a socket or a device: the atomic rename would replace it with a file
    /// (`--json /dev/null` as root would replace /dev/null).
    #[error("{}: is {kind}, not a regular file; an output replaces its file when complete, which would remove it: give a file name", .path.display())]
    NotRegular {
        /// The output path.
        path: PathBuf,
        /// What it is ("a FIFO", "a device", ...).
        kind: &'static str,
    },
    /// A folder was asked for (`--export DIR`, `--figures DIR`) and the path is a file.
    #[error("{}: is a file; give a folder (a new one, or one of yours to add files to)", .0.display())]
    NotAFolder(PathBuf),
    /// The path is a symlink: an output is never written through one (its target could be anything).
    #[error("{}: is a symlink; give the real path (an output is never written through a symlink)", .0.display())]
    Symlink(PathBuf),
    /// The folder an output would go in cannot be written (a test file could not be created).
    #[error("{}: the folder {} cannot be written ({source}); choose another place", .path.display(), .dir.display())]
    ReadOnly {
        /// The output path.
        path: PathBuf,
        /// The folder tried.
        dir: PathBuf,
        /// The OS error of the test file.
        source: std::io::Error,
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

/// Opens a file this run reads: the one rule for every input a user names.
///
/// The file is opened with `O_NONBLOCK` (a FIFO without a writer would otherwise block `open` for
/// ever, beyond the reach of any signal's polite stop) and `O_NOCTTY`, then checked on the open
/// handle, so a path swapped between a check and the open cannot slip through: anything but a
/// regular file (a FIFO, a device such as `/dev/zero` that never ends, a directory, a socket) is
/// refused with an error that says what it is. `O_NONBLOCK` has no effect on a regular file's
/// reads (open(2)), so the handle reads as usual. The path is noted as an input ([`note_input`]):
/// no output of the same run may replace it.
///
/// # Errors
/// The OS error of the open (no such file, permission denied, ...), or
/// [`std::io::ErrorKind::InvalidInput`] for what is not a regular file. The message does not
/// name the path: the caller's error does.
pub fn open_input(path: &Path) -> std::io::Result<File> {
    use std::os::unix::fs::FileTypeExt as _;
    let file =
        OpenOptions::new().read(true).custom_flags(libc::O_NONBLOCK | libc::O_NOCTTY | libc::O_CLOEXEC).open(path)?;
    let kind = file.metadata()?.file_type();
    if !kind.is_file() {
        let what = if kind.is_fifo() {
            "a FIFO (named pipe)"
        } else if kind.is_dir() {
            "a directory"
        } else if kind.is_char_device() || kind.is_block_device() {
            "a device"
        } else if kind.is_socket() {
            "a socket"
        } else {
            "not a file"
        };
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!(
                "not a regular file but {what}; give a file (an input is never read from a pipe, a device or a directory)"
            ),
        ));
    }
    note_input(path);
    Ok(file)
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
/// ending in `/`), in a directory that exists and can be written, not a symlink, not a FIFO or a
/// device, not a file this run reads ([`note_input`]). The same as
/// `check_output(_, path, OutputKind::File)`.
///
/// # Errors
/// See [`OutputError`].
pub fn check_output_path(path: &Path) -> Result<(), OutputError> {
    check_output_kind(path, OutputKind::File)
}

/// What an output option names.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutputKind {
    /// A file, replaced atomically when complete (`--save`, `--json`, `--summary-json`).
    File,
    /// A folder files are written into (`--export DIR`, `--figures DIR`), new or existing.
    Folder,
}

/// An output option's path refused before any work, naming the option.
#[derive(Debug, thiserror::Error)]
#[error("{flag} {error}")]
pub struct OutputRefused {
    /// The option (`--json`, `--export`, ...).
    pub flag: String,
    /// Why.
    #[source]
    pub error: OutputError,
}

/// The one output rule: checks the path an output option `flag` names, before any work, the same
/// way for every option. Refused: a FIFO, a socket or a device; a symlink; a folder where a file
/// is wanted ([`OutputKind::File`]) or a file where a folder is wanted ([`OutputKind::Folder`]);
/// a parent folder that does not exist (no option creates missing folders: a typo in a folder's
/// name is not a new tree); a folder that cannot be written (tested by creating and removing a
/// file); a file this run reads.
///
/// # Errors
/// [`OutputRefused`]: the flag and the [`OutputError`].
pub fn check_output(flag: &str, path: &Path, kind: OutputKind) -> Result<(), OutputRefused> {
    check_output_kind(path, kind).map_err(|error| OutputRefused { flag: flag.to_owned(), error })
}

fn check_output_kind(path: &Path, kind: OutputKind) -> Result<(), OutputError> {
    let meta = std::fs::symlink_metadata(path).ok();
    if meta.as_ref().is_some_and(|m| m.file_type().is_symlink()) {
        return Err(OutputError::Symlink(path.to_path_buf()));
    }
    if let Some(kind) = meta.as_ref().and_then(|m| special_kind(&m.file_type())) {
        return Err(OutputError::NotRegular { path: path.to_path_buf(), kind });
    }
    match kind {
        OutputKind::File => {
            check_path(path, false)?;
            writable(path, parent_of(path))
        }
        OutputKind::Folder => match meta {
            Some(m) if m.is_dir() => writable(path, path),
            Some(_) => Err(OutputError::NotAFolder(path.to_path_buf())),
            None => {
                let dir = parent_of(path);
                if !dir.is_dir() {
                    return Err(OutputError::NoDirectory { path: path.to_path_buf(), dir: dir.to_path_buf() });
                }
                writable(path, dir)
            }
        },
    }
}

/// The folder `path` is in (`.` for a bare name).
fn parent_of(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// Whether a file can be created in `dir` (for the output `path`): one is created and removed
/// (permissions alone do not tell: a read-only mount, an ACL, root).
fn writable(path: &Path, dir: &Path) -> Result<(), OutputError> {
    static PROBES: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let n = PROBES.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let probe = dir.join(format!(".rinscope-write-test-{}-{n}", std::process::id()));
    match OpenOptions::new().write(true).create_new(true).custom_flags(libc::O_NOFOLLOW | libc::O_CLOEXEC).open(&probe)
    {
        Ok(_) => {
            std::fs::remove_file(&probe).ok();
            Ok(())
        }
        Err(source) => Err(OutputError::ReadOnly { path: path.to_path_buf(), dir: dir.to_path_buf(), source }),
    }
}

/// Makes the output folder `dir` an option named, checked by [`check_output`] up front: its
/// parent must exist (no option creates a tree); an existing folder is used as it is.
///
/// # Errors
/// [`OutputRefused`] as [`check_output`], or the OS error of the creation.
pub fn create_output_dir(flag: &str, dir: &Path) -> Result<(), OutputRefused> {
    check_output(flag, dir, OutputKind::Folder)?;
    match std::fs::create_dir(dir) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists && dir.is_dir() => Ok(()),
        Err(source) => Err(OutputRefused {
            flag: flag.to_owned(),
            error: OutputError::Io { path: dir.to_path_buf(), action: "create the folder", source },
        }),
    }
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
    if let Some(kind) = std::fs::metadata(path).ok().and_then(|m| special_kind(&m.file_type())) {
        return Err(OutputError::NotRegular { path: path.to_path_buf(), kind });
    }
    // Checked again when the partial is opened (O_NOFOLLOW); here so that a long run is not
    // wasted on an output that will be refused at its end.
    let partial = partial_path(path);
    if std::fs::symlink_metadata(&partial).is_ok_and(|m| m.file_type().is_symlink()) {
        return Err(OutputError::NotAFile { partial, problem: "is a symlink" });
    }
    Ok(())
}

/// What a file that is neither a regular file nor a directory is ("a FIFO", ...), or None.
fn special_kind(t: &std::fs::FileType) -> Option<&'static str> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt as _;
        if t.is_fifo() {
            return Some("a FIFO (named pipe)");
        }
        if t.is_socket() {
            return Some("a socket");
        }
        if t.is_char_device() || t.is_block_device() {
            return Some("a device");
        }
    }
    let _ = t;
    None
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

/// Makes the partial folder of the folder `path` (`PATH.partial/`, e.g. a log set being exported)
/// for this run, locked (`flock` on the folder) for as long as the returned handle is open: rename
/// it onto `PATH` while holding it. A partial folder left by a run that died (its lock is free) is
/// emptied and taken over, so a crash never blocks the next run; one that another run is writing
/// is refused at once ([`OutputError::Busy`]); a symlink or a file at that name is refused.
///
/// # Errors
/// See [`OutputError`].
pub fn create_partial_dir(path: &Path) -> Result<File, OutputError> {
    let partial = partial_path(path);
    let io = |action, source| OutputError::Io { path: partial.clone(), action, source };
    let fresh = match std::fs::create_dir(&partial) {
        Ok(()) => true,
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => false,
        Err(e) => return Err(io("create", e)),
    };
    let dir = OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_DIRECTORY | libc::O_NOFOLLOW | libc::O_CLOEXEC)
        .open(&partial)
        .map_err(|e| match e.raw_os_error() {
            Some(libc::ELOOP) => OutputError::NotAFile { partial: partial.clone(), problem: "is a symlink" },
            Some(libc::ENOTDIR) => OutputError::NotAFile { partial: partial.clone(), problem: "is not a folder" },
            _ => io("open", e),
        })?;
    match dir.try_lock() {
        Ok(()) => {}
        Err(std::fs::TryLockError::WouldBlock) => return Err(OutputError::Busy { path: path.to_path_buf(), partial }),
        Err(std::fs::TryLockError::Error(e)) => return Err(io("lock", e)),
    }
    if !fresh {
        // Left by a run that died: ours now, started afresh.
        for entry in std::fs::read_dir(&partial).map_err(|e| io("empty", e))? {
            let p = entry.map_err(|e| io("empty", e))?.path();
            let removed =
                if p.is_dir() && !p.is_symlink() { std::fs::remove_dir_all(&p) } else { std::fs::remove_file(&p) };
            removed.map_err(|e| io("empty", e))?;
        }
    }
    Ok(dir)
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
            Err(std::fs::TryLockError::WouldBlock) => {
                return Err(OutputError::Busy { path: path.to_path_buf(), partial });
            }
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
    out.file().write_all(bytes).map_err(|e| OutputError::Io {
        path: out.partial().to_path_buf(),
        action: "write",
        source: e,
    })?;
    out.commit().map(|_| ())
}

#[cfg(test)]
mod tests;
