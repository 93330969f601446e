//! Viewers: starting one (`--spawn`) and streaming to one without ever letting it stall the run.
//!
//! A viewer is another process that can be missing, have no display, exit at start, freeze or go
//! away mid-run. [`spawn`] checks for a display and for the viewer's port, and reports an early
//! exit with its last words. [`Detachable`] puts a viewer's sink behind a thread and a bounded
//! queue: a viewer that has not taken data for [`STALL`] is detached (reported at once, the
//! stream to it stops) while the saved file and the other sinks go on.

use std::io::Read;
use std::net::{Ipv4Addr, SocketAddr, TcpStream};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use crossbeam_channel::{SendTimeoutError, Sender};
use rerun::external::re_log_types::{BlueprintActivationCommand, LogMsg};
use rerun::log::ChunkBatcherConfig;
use rerun::sink::{LogSink, SinkFlushError};

use super::{SinkError, find_on_path};

/// A viewer that takes no data for this long is detached.
pub const STALL: Duration = Duration::from_secs(5);

/// How long a spawned viewer has to start listening.
const START_TIMEOUT: Duration = Duration::from_secs(15);

/// What the alternatives to a local viewer are, for messages.
pub const WITHOUT_A_VIEWER: &str = "save the recording with --save FILE and open it where there is a screen, or serve it with --serve (then `rerun --connect` from another machine, e.g. through `ssh -L 9876:127.0.0.1:9876`)";

/// Problems the viewers had during the run, for the end-of-run summary.
pub type Problems = Arc<Mutex<Vec<String>>>;

enum Cmd {
    Message(Box<LogMsg>),
    Blueprint(Vec<LogMsg>, BlueprintActivationCommand),
    Flush(Duration, Sender<Result<(), SinkFlushError>>),
}

/// A viewer's sink behind a thread: see the module docs.
pub struct Detachable {
    name: String,
    tx: Sender<Cmd>,
    detached: Arc<AtomicBool>,
    problems: Problems,
    batcher: ChunkBatcherConfig,
    /// Whether anything but viewers keeps the data (for the message).
    file_kept: bool,
}

impl Detachable {
    /// Wraps `inner`, named `name` in messages ("the viewer at rerun+http://…").
    pub fn new(inner: Box<dyn LogSink>, name: String, problems: Problems, file_kept: bool) -> Self {
        let batcher = inner.default_batcher_config();
        let (tx, rx) = crossbeam_channel::bounded::<Cmd>(32);
        let spawned = std::thread::Builder::new().name("viewer_sink".into()).spawn(move || {
            // This thread may block for ever inside a frozen viewer's sink; it is never joined.
            while let Ok(cmd) = rx.recv() {
                match cmd {
                    Cmd::Message(m) => inner.send(*m),
                    Cmd::Blueprint(b, a) => inner.send_blueprint(b, a),
                    Cmd::Flush(timeout, reply) => {
                        reply.send(inner.flush_blocking(timeout)).ok();
                    }
                }
            }
        });
        let detached = Arc::new(AtomicBool::new(spawned.is_err()));
        Self { name, tx, detached, problems, batcher, file_kept }
    }

    fn detach(&self, why: &str) {
        if self.detached.swap(true, Ordering::SeqCst) {
            return;
        }
        let rest = if self.file_kept {
            "the saved file goes on"
        } else {
            "nothing else keeps this run's data: use --save FILE"
        };
        let message = format!("{}: {why}; streaming to it stopped ({rest})", self.name);
        errln!("rinscope: {message}");
        self.problems.lock().unwrap_or_else(std::sync::PoisonError::into_inner).push(message);
    }

    fn submit(&self, cmd: Cmd) {
        if self.detached.load(Ordering::Relaxed) {
            return;
        }
        match self.tx.send_timeout(cmd, STALL) {
            Ok(()) => {}
            Err(SendTimeoutError::Timeout(_)) => {
                self.detach(&format!("took no data for {} s (frozen, or its machine is overloaded)", STALL.as_secs()))
            }
            Err(SendTimeoutError::Disconnected(_)) => self.detach("its sink ended"),
        }
    }
}

impl LogSink for Detachable {
    fn send(&self, msg: LogMsg) {
        self.submit(Cmd::Message(Box::new(msg)));
    }

    fn send_blueprint(&self, blueprint: Vec<LogMsg>, activation_cmd: BlueprintActivationCommand) {
        self.submit(Cmd::Blueprint(blueprint, activation_cmd));
    }

    fn flush_blocking(&self, timeout: Duration) -> Result<(), SinkFlushError> {
        if self.detached.load(Ordering::Relaxed) {
            // Already reported; the file and the other sinks are not held up by it.
            return Ok(());
        }
        let wait = timeout.min(STALL);
        let (tx, rx) = crossbeam_channel::bounded(1);
        self.submit(Cmd::Flush(wait, tx));
        match rx.recv_timeout(wait + Duration::from_millis(200)) {
            Ok(Ok(())) => Ok(()),
            Ok(Err(SinkFlushError::Failed { message })) => {
                self.detach(&format!("is gone ({message})"));
                Ok(())
            }
            Ok(Err(SinkFlushError::Timeout)) | Err(_) if timeout < STALL => Err(SinkFlushError::Timeout),
            Ok(Err(SinkFlushError::Timeout)) | Err(_) => {
                self.detach(&format!("took no data for {} s (frozen, or its machine is overloaded)", STALL.as_secs()));
                Ok(())
            }
        }
    }

    fn default_batcher_config(&self) -> ChunkBatcherConfig {
        self.batcher
    }
}

/// Whether this session can open a window (Linux: an X11 or Wayland display is named).
fn has_display() -> bool {
    if !cfg!(target_os = "linux") {
        return true;
    }
    ["DISPLAY", "WAYLAND_DISPLAY"].iter().any(|v| std::env::var_os(v).is_some_and(|s| !s.is_empty()))
}

/// Starts a new viewer on a free port and waits until it listens; returns the port.
pub fn spawn() -> Result<u16, SinkError> {
    let Some(exe) = find_on_path("rerun") else {
        return Err(SinkError::NoViewer);
    };
    if !has_display() {
        return Err(SinkError::Spawn(format!(
            "no display to open a viewer window on (DISPLAY and WAYLAND_DISPLAY are unset: SSH, a container, WSL without WSLg?); {WITHOUT_A_VIEWER}"
        )));
    }
    let port = std::net::TcpListener::bind((Ipv4Addr::LOCALHOST, 0))
        .and_then(|l| l.local_addr())
        .map_err(|e| SinkError::Spawn(format!("no free port: {e}")))?
        .port();
    let mut child = {
        use std::os::unix::process::CommandExt as _;
        Command::new(&exe)
            .arg(format!("--port={port}"))
            .args(["--expect-data-soon", "--hide-welcome-screen"])
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            // Its own process group: a Ctrl-C meant for rinscope does not close the viewer.
            .process_group(0)
            .spawn()
            .map_err(|e| SinkError::Spawn(format!("cannot start {}: {e}", exe.display())))?
    };
    // Keep the viewer's last words (and never let its stderr pipe fill up).
    let last_words = Arc::new(Mutex::new(String::new()));
    if let Some(mut err) = child.stderr.take() {
        let sink = Arc::clone(&last_words);
        std::thread::spawn(move || {
            let mut buf = [0u8; 4096];
            while let Ok(n) = err.read(&mut buf) {
                if n == 0 {
                    break;
                }
                let mut s = sink.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
                s.push_str(&String::from_utf8_lossy(&buf[..n]));
                if s.len() > 4000 {
                    let cut = s.len() - 2000;
                    let cut = (cut..s.len()).find(|&i| s.is_char_boundary(i)).unwrap_or(s.len());
                    s.drain(..cut);
                }
            }
        });
    }
    let addr = SocketAddr::from((Ipv4Addr::LOCALHOST, port));
    let started = Instant::now();
    let words = || {
        std::thread::sleep(Duration::from_millis(100));
        let w = last_words.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        let lines: Vec<&str> = w.lines().filter(|l| !l.trim().is_empty()).collect();
        let tail = lines[lines.len().saturating_sub(3)..].join(" | ");
        if tail.is_empty() { String::new() } else { format!(": {tail}") }
    };
    loop {
        if TcpStream::connect_timeout(&addr, Duration::from_millis(200)).is_ok() {
            return Ok(port);
        }
        if let Ok(Some(status)) = child.try_wait()
            && !status.success()
        {
            return Err(SinkError::Spawn(format!(
                "the viewer ({}) exited at start with {status}{}; {WITHOUT_A_VIEWER}",
                exe.display(),
                words()
            )));
        }
        if started.elapsed() > START_TIMEOUT {
            child.kill().ok();
            return Err(SinkError::Spawn(format!(
                "the viewer ({}) did not start listening on port {port} within {} s{}; {WITHOUT_A_VIEWER}",
                exe.display(),
                START_TIMEOUT.as_secs(),
                words()
            )));
        }
        std::thread::sleep(Duration::from_millis(100));
    }
}
