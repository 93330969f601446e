//! Watching the scenario file: every save (in place, truncate-and-write, or rename over the file)
//! becomes one parsed and validated [`WatchEvent`]; a deleted file is reported and awaited.
//!
//! The directory is watched, not the file: editors that save by rename replace the inode, and a
//! watch on the old inode would go silent.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use crossbeam_channel::{Receiver, RecvTimeoutError, Sender};
use notify::{RecursiveMode, Watcher as _};

use crate::scenario::{self, Params};

/// Quiet time after the last file-system event before the file is read: a truncate-and-write save
/// produces two events microseconds apart, and the empty file between them must not be reported.
pub const DEBOUNCE: Duration = Duration::from_millis(15);

/// How long an empty file waits for the write that follows its truncation before it is reported:
/// on a loaded machine the two halves of a save can be further apart than [`DEBOUNCE`].
const EMPTY_GRACE: Duration = Duration::from_secs(1);

/// What a save produced.
#[derive(Debug)]
pub enum WatchEvent {
    /// A valid configuration (its text differs from the previous one).
    Loaded {
        /// The validated parameters.
        params: Box<Params>,
        /// When the first file-system event of this save arrived.
        seen_at: Instant,
    },
    /// The file does not parse or validate; the message names key, value and unit.
    Invalid {
        /// The error.
        message: String,
        /// When the save was seen.
        seen_at: Instant,
    },
    /// The file is gone (the watcher keeps waiting for it).
    Deleted,
    /// The file is back (a `Loaded` or `Invalid` follows).
    Restored,
}

/// A running watcher; dropping it stops watching.
pub struct Watcher {
    _notify: notify::RecommendedWatcher,
    _debounce: std::thread::JoinHandle<()>,
}

/// Starts watching `path`; events go to `tx`. `initial_text` is the text already applied.
pub fn watch(path: &Path, initial_text: String, tx: Sender<WatchEvent>) -> notify::Result<Watcher> {
    let path = path.to_path_buf();
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let name = path.file_name().map(|n| n.to_os_string()).unwrap_or_default();
    let (poke_tx, poke_rx) = crossbeam_channel::unbounded::<Instant>();
    let mut w = notify::recommended_watcher(move |res: notify::Result<notify::Event>| {
        if let Ok(ev) = res
            && ev.paths.iter().any(|p| p.file_name() == Some(name.as_os_str()))
        {
            let _ = poke_tx.send(Instant::now());
        }
    })?;
    w.watch(&dir, RecursiveMode::NonRecursive)?;
    let debounce = std::thread::Builder::new()
        .name("config-watcher".into())
        .spawn(move || debounce_loop(&path, initial_text, &poke_rx, &tx))
        .map_err(|e| notify::Error::generic(&e.to_string()))?;
    Ok(Watcher { _notify: w, _debounce: debounce })
}

/// Whether another event arrives within [`EMPTY_GRACE`] (the write after a truncation).
fn pending_write(pokes: &Receiver<Instant>) -> bool {
    pokes.recv_timeout(EMPTY_GRACE).is_ok()
}

fn debounce_loop(path: &Path, initial_text: String, pokes: &Receiver<Instant>, tx: &Sender<WatchEvent>) {
    let origin = path.display().to_string();
    let mut last_text = Some(initial_text);
    let mut deleted = false;
    // An unreadable path (a directory, a FIFO, no permission) is reported once, not on every event.
    let mut last_error: Option<String> = None;
    // A save whose first read found the file empty (its write still to come).
    let mut pending: Option<Instant> = None;
    loop {
        // Wait for a save (or the watcher to go away).
        let seen_at = match pending.take() {
            Some(t) => t,
            None => match pokes.recv() {
                Ok(t) => t,
                Err(_) => return,
            },
        };
        // Then for quiet.
        loop {
            match pokes.recv_timeout(DEBOUNCE) {
                Ok(_) => {}
                Err(RecvTimeoutError::Timeout) => break,
                Err(RecvTimeoutError::Disconnected) => return,
            }
        }
        // read_text refuses what is not a regular file of configuration size: a FIFO put in the
        // config's place cannot block the watcher, /dev/zero cannot fill memory.
        let event = match scenario::read_text(path) {
            Err(scenario::ConfigError::Read { source, .. }) if source.kind() == std::io::ErrorKind::NotFound => {
                if deleted {
                    continue;
                }
                deleted = true;
                last_text = None;
                last_error = None;
                WatchEvent::Deleted
            }
            Err(e) => {
                let message = e.to_string();
                if last_error.as_deref() == Some(message.as_str()) {
                    continue;
                }
                last_error = Some(message.clone());
                last_text = None;
                WatchEvent::Invalid { message, seen_at }
            }
            Ok(text) if text.is_empty() && pending_write(pokes) => {
                pending = Some(seen_at);
                continue;
            }
            Ok(text) => {
                last_error = None;
                if deleted {
                    deleted = false;
                    if tx.send(WatchEvent::Restored).is_err() {
                        return;
                    }
                }
                if last_text.as_deref() == Some(text.as_str()) {
                    continue; // touched, not changed; or an error already reported once
                }
                let event = match scenario::parse(&text, &origin) {
                    Ok(params) => WatchEvent::Loaded { params: Box::new(params), seen_at },
                    Err(e) => WatchEvent::Invalid { message: e.to_string(), seen_at },
                };
                last_text = Some(text);
                event
            }
        };
        if tx.send(event).is_err() {
            return;
        }
    }
}
