//! Where a recording goes, following Rerun's conventions: `--save FILE`, `--spawn`, `--connect [URL]`,
//! `--serve [PORT]` (several at once are allowed).
//!
//! - The file (file.rs) is written to `FILE.partial` by a writer of ours, verified, and renamed
//!   only when complete: a failed, interrupted or concurrent run never leaves a half-written
//!   recording under the final name, and never replaces a good one. A write error stops the run.
//! - Viewers (viewer.rs) are checked before anything is created (installed, a display, listening)
//!   and streamed to through [`viewer::Detachable`]: a viewer that freezes or goes away is
//!   reported and detached within seconds; it never holds up the file.

use std::net::{IpAddr, Ipv4Addr, SocketAddr, TcpStream, ToSocketAddrs};
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::time::Duration;

use rerun::sink::{GrpcSink, LogSink};
use rerun::{RecordingStream, RecordingStreamBuilder};

pub use crate::io::files::partial_path;

use super::Stream;
use super::export::{ExportFormat, Exporter, SharedExporter};
use std::sync::{Arc, Mutex};

pub mod address;
mod file;

pub(crate) use file::{Ending, ending};
pub mod viewer;

/// The viewer version that matches the SDK this binary is built with.
pub const VIEWER_INSTALL_HINT: &str = "pip install rerun-sdk==0.36.3";

/// Rerun's default gRPC URL for a viewer on this machine.
pub const DEFAULT_CONNECT_URL: &str = "rerun+http://127.0.0.1:9876/proxy";

/// A problem with a sink the user asked for.
#[derive(Debug, thiserror::Error)]
pub enum SinkError {
    /// `--spawn` but no viewer executable.
    #[error(
        "--spawn: no `rerun` viewer found on PATH. Install the matching viewer with `{VIEWER_INSTALL_HINT}`, or drop --spawn to save a recording under recordings/ and open it later"
    )]
    NoViewer,
    /// `--connect` to an address where nothing listens.
    #[error(
        "--connect: no viewer is listening at {url}. Start one with `rerun` (install: `{VIEWER_INSTALL_HINT}`), use --spawn, or save a file with --save"
    )]
    NotListening {
        /// The URL asked for.
        url: String,
    },
    /// A URL Rerun cannot parse.
    #[error("--connect: `{url}` is not a Rerun gRPC URL (expected e.g. {DEFAULT_CONNECT_URL}): {reason}")]
    BadUrl {
        /// The URL asked for.
        url: String,
        /// Why.
        reason: String,
    },
    /// The output file cannot be created.
    #[error("--save: {0}")]
    File(String),
    /// `--serve` on a port that is taken.
    #[error("--serve: cannot listen on {addr}: {reason}")]
    Serve {
        /// The address asked for.
        addr: SocketAddr,
        /// Why.
        reason: String,
    },
    /// The saved file could not be completed.
    #[error("--save: {0}; no recording was saved (a file already at that path was left as it was)")]
    Write(String),
    /// Spawning the viewer failed.
    #[error("--spawn: {0}")]
    Spawn(String),
    /// The export folder cannot be used.
    #[error("--export: {0}")]
    Export(String),
    /// The export tables could not be written to the end (disk full, ...).
    #[error("--export: {0}")]
    ExportWrite(String),
    /// The figures folder cannot be created.
    #[error("--figures: {0}")]
    Figures(String),
    /// The figures could not be drawn or written (the recording is kept).
    #[error("--figures: {0} (the recording itself was saved)")]
    FiguresWrite(String),
    /// A signal stopped a phase after the run (drawing the figures): what is done is kept.
    #[error("{0}")]
    Interrupted(String),
    /// Any other Rerun SDK error.
    #[error("rerun: {0}")]
    Rerun(String),
}

/// What the user asked for.
#[derive(Debug, Clone, Default)]
pub struct SinkRequest {
    /// Save to this file.
    pub save: Option<PathBuf>,
    /// Start a new viewer.
    pub spawn: bool,
    /// Stream to a viewer at this URL.
    pub connect: Option<String>,
    /// Serve the stream on this gRPC port for viewers (native or web) to connect to.
    pub serve: Option<u16>,
    /// The address `serve` and `serve_web` listen on (default 127.0.0.1: this machine only).
    pub bind: Option<IpAddr>,
    /// Serve the viewer itself (Wasm, for a browser) on this HTTP port, with the stream.
    pub serve_web: Option<u16>,
    /// A live session's class page port, which serves the session so far as one compact
    /// recording (`/history.rrd`, [`HistorySnapshot`]): the web viewer loads it beside the stream,
    /// and the stream keeps no history of its own (see [`open`]).
    pub serve_web_history: Option<u16>,
    /// Set when the saved file cannot be written, so the run stops at its next check.
    pub stop_on_failure: Option<Arc<AtomicBool>>,
    /// Also write every time series as tables into this folder.
    pub export: Option<(PathBuf, ExportFormat)>,
    /// Keep every time series as tables in memory (with no `export` folder): [`Saved::tables`].
    pub tables_in_memory: bool,
    /// Draw every plot of the saved recording into this folder when the run ends (needs `save`).
    pub figures: Option<PathBuf>,
}

/// An open recording and the file it will become. Dropped without [`OpenSinks::finish`] (a failed
/// run returning early), it is abandoned: every sink closed and the partial file removed.
pub struct OpenSinks {
    /// The stream to log into.
    rec: RecordingStream,
    /// The export tables, if asked for.
    export: Option<SharedExporter>,
    /// The saved file being written, if any.
    file: Option<file::RrdFile>,
    /// What went wrong with viewers during the run.
    viewer_problems: viewer::Problems,
    /// Human-readable description of where the data goes.
    pub description: Vec<String>,
    /// The web viewer's server (`--serve-web`), kept alive with the sinks.
    web: Option<WebServer>,
    /// The process's stop flag (ends the web viewer's wait after the run).
    stop: Option<Arc<AtomicBool>>,
    /// `--figures DIR`.
    figures: Option<PathBuf>,
}

/// The web viewer's HTTP server and the page that shows the stream.
impl OpenSinks {
    /// The browser viewer's URL (with its stream), when `serve_web` was asked for.
    #[must_use]
    pub fn web_page(&self) -> Option<&str> {
        self.web.as_ref().map(|w| w.page.as_str())
    }
}

struct WebServer {
    /// Rerun's `WebViewerServer`: serves while it lives.
    _server: Box<dyn std::any::Any + Send>,
    page: String,
}

/// Looks for an executable named `name` on PATH.
#[must_use]
pub fn find_on_path(name: &str) -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path).map(|dir| dir.join(name)).find(|p| p.is_file())
}

fn socket_of(url: &str) -> Option<SocketAddr> {
    // rerun+http://HOST:PORT/proxy -> HOST:PORT
    let rest = url.split("://").nth(1)?;
    let hostport = rest.split('/').next()?;
    hostport.to_socket_addrs().ok()?.next()
}

/// Opens every requested sink: viewers are checked (and spawned) first, then the file is created,
/// so that nothing is created when a viewer is missing.
pub fn open(req: &SinkRequest, application_id: &'static str, recording_id: &str) -> Result<OpenSinks, SinkError> {
    let mut sinks: Vec<Box<dyn LogSink>> = Vec::new();
    let mut description = Vec::new();
    let problems: viewer::Problems = Arc::default();
    let file_kept = req.save.is_some();
    if let Some(dir) = &req.figures {
        if req.save.is_none() {
            return Err(SinkError::Figures("the figures are drawn from the saved recording: add --save FILE".into()));
        }
        std::fs::create_dir_all(dir)
            .map_err(|e| SinkError::Figures(format!("{}: cannot create the folder: {e}", dir.display())))?;
        description.push(format!("figures (SVG and PNG) of every plot to {} when the run ends", dir.display()));
    }
    let guarded = |inner: Box<dyn LogSink>, name: String| -> Box<dyn LogSink> {
        Box::new(viewer::Detachable::new(inner, name, Arc::clone(&problems), file_kept))
    };

    if let Some(url) = &req.connect {
        let uri: rerun::external::re_uri::ProxyUri = url.parse().map_err(|e: rerun::external::re_uri::Error| {
            SinkError::BadUrl { url: url.clone(), reason: e.to_string() }
        })?;
        let listening =
            socket_of(url).is_some_and(|addr| TcpStream::connect_timeout(&addr, Duration::from_millis(500)).is_ok());
        if !listening {
            return Err(SinkError::NotListening { url: url.clone() });
        }
        sinks.push(guarded(Box::new(GrpcSink::new(uri)), format!("the viewer at {url}")));
        description.push(format!("streaming to the viewer at {url}"));
    }

    if req.spawn {
        // A new viewer on a free port: a viewer already listening on 9876 keeps its own data.
        let port = viewer::spawn()?;
        let url = format!("rerun+http://127.0.0.1:{port}/proxy");
        let uri = url.parse().map_err(|e: rerun::external::re_uri::Error| SinkError::Rerun(e.to_string()))?;
        sinks.push(guarded(Box::new(GrpcSink::new(uri)), format!("the spawned viewer at {url}")));
        description.push(format!("streaming to a new viewer at {url}"));
    }

    if let Some(port) = req.serve {
        let ip = req.bind.unwrap_or(IpAddr::V4(Ipv4Addr::LOCALHOST));
        let addr = SocketAddr::new(ip, port);
        // Check the port first: the server binds in a background task and would fail silently.
        std::net::TcpListener::bind(addr).map_err(|e| SinkError::Serve { addr, reason: e.to_string() })?;
        let options =
            rerun::ServerOptions { memory_limit: rerun::MemoryLimit::from_bytes(1 << 30), ..Default::default() };
        let sink = rerun::grpc_server::GrpcServerSink::new(&ip.to_string(), port, options)
            .map_err(|e| SinkError::Serve { addr, reason: e.to_string() })?;
        sinks.push(Box::new(sink));
        // For an unspecified address, a host other machines reach (127.0.0.1 would name theirs).
        let host = address::network_host(ip).unwrap_or_else(|| address::local_host(ip));
        let url = format!("rerun+http://{host}:{port}/proxy");
        if !ip.is_loopback() {
            errln!(
                "rinscope: WARNING: --bind {ip}: anyone who can reach port {port} of this machine can watch this session (there is no authentication)"
            );
        }
        description.push(format!(
            "serving on {addr}: `rerun --connect {url}`, or in a browser https://app.rerun.io/version/0.36.3/index.html?url={}",
            url.replace(':', "%3A").replace('/', "%2F").replace('+', "%2B").replace('[', "%5B").replace(']', "%5D")
        ));
    }

    let mut web = None;
    if let Some(web_port) = req.serve_web {
        let ip = req.bind.unwrap_or(IpAddr::V4(Ipv4Addr::LOCALHOST));
        let web_addr = SocketAddr::new(ip, web_port);
        std::net::TcpListener::bind(web_addr)
            .map_err(|e| SinkError::Serve { addr: web_addr, reason: e.to_string() })?;
        // The stream on the next port (known in advance: a firewall can be opened for both); the
        // page connects to it.
        let grpc_port = web_port
            .checked_add(1)
            .ok_or(SinkError::Serve { addr: web_addr, reason: "the stream needs the next port too".into() })?;
        // A late viewer is sent everything the server kept. A live stream is many small chunks (low
        // latency), which a web viewer ingests at a few dozen a second: 10 minutes of it took it
        // longer to replay than the session lasted. With the class page's compact history beside it,
        // the stream keeps none (static data and the layout are kept by the server anyway).
        let history_limit = if req.serve_web_history.is_some() { 0 } else { 1 << 30 };
        // The viewer's page (next port, any host the browser used) may read the stream: Rerun's
        // server allows only localhost and 127.0.0.1 by default, which a class beyond loopback is not.
        let options = rerun::ServerOptions {
            memory_limit: rerun::MemoryLimit::from_bytes(history_limit),
            cors_allowed_origins: vec![format!("http://*:{web_port}")],
            ..Default::default()
        };
        let sink = rerun::grpc_server::GrpcServerSink::new(&ip.to_string(), grpc_port, options)
            .map_err(|e| SinkError::Serve { addr: SocketAddr::new(ip, grpc_port), reason: e.to_string() })?;
        sinks.push(Box::new(sink));
        let host = address::local_host(ip);
        let grpc_url = format!("rerun+http://{host}:{grpc_port}/proxy");
        let config = rerun::web_viewer::WebViewerConfig {
            bind_ip: ip.to_string(),
            web_port: web_port.into(),
            connect_to: vec![grpc_url],
            open_browser: false,
            ..Default::default()
        };
        let server =
            config.host_web_viewer().map_err(|e| SinkError::Serve { addr: web_addr, reason: e.to_string() })?;
        // The viewer's dark theme whatever the browser's: the recording's 3D labels and colours are made
        // for it (on the light one white and yellow labels all but vanish).
        let page = address::web_viewer_page(&host, web_port, grpc_port, req.serve_web_history);
        if !ip.is_loopback() {
            errln!(
                "rinscope: WARNING: --bind {ip}: anyone who can reach ports {web_port} and {grpc_port} of this machine can watch this session (there is no authentication)"
            );
        }
        description.push(format!("viewer in the browser: open {page} (in its dark theme; Rerun 0.36 ignores that on a browser's very first start: reload once if it opens light)"));
        // For an unspecified address, the page other machines open names this one (the stream's URL too).
        if ip.is_unspecified() {
            match address::network_host(ip) {
                Some(h) => description.push(format!("from other machines: open {}", address::web_viewer_page(&h, web_port, grpc_port, req.serve_web_history))),
                None => description.push(format!("from other machines: open this machine's address in place of {host} (it has no route out and no name to print)")),
            }
        }
        web = Some(WebServer { _server: Box::new(server), page });
    }

    let mut file = None;
    if let Some(path) = &req.save {
        // recordings/ (the default) and any folder named in --save are created.
        if let Some(dir) =
            path.parent().filter(|d| !d.as_os_str().is_empty() && !path.as_os_str().to_string_lossy().ends_with('/'))
        {
            std::fs::create_dir_all(dir)
                .map_err(|e| SinkError::File(format!("{}: cannot create its folder: {e}", path.display())))?;
        }
        let (rrd, sink) = file::RrdFile::create(path, req.stop_on_failure.clone()).map_err(SinkError::File)?;
        sinks.push(Box::new(sink));
        description.push(format!("saving to {}", path.display()));
        file = Some(rrd);
    }

    let export = match &req.export {
        None if !req.tables_in_memory => None,
        Some((dir, format)) => {
            let e = Exporter::new(dir, *format).map_err(|e| SinkError::Export(e.to_string()))?;
            description.push(format!("exporting every time series as {format:?} tables to {}", dir.display()));
            Some(Arc::new(Mutex::new(e)))
        }
        None => Some(Arc::new(Mutex::new(Exporter::in_memory()))),
    };
    let rec = RecordingStreamBuilder::new(application_id)
        .recording_id(recording_id.to_owned())
        .set_sinks(sinks)
        .map_err(|e| SinkError::Rerun(e.to_string()))?;
    Ok(OpenSinks {
        rec,
        export,
        file,
        viewer_problems: problems,
        description,
        web,
        stop: req.stop_on_failure.clone(),
        figures: req.figures.clone(),
    })
}

/// A live session kept in memory as one compact recording (full-size chunks, like a saved file),
/// for viewers that open the session late: the class page serves it as `/history.rrd`
/// ([`address::HISTORY_PATH`]) beside the live stream, which then keeps no history of its own.
pub struct HistoryStore {
    storage: rerun::sink::MemorySinkStorage,
}

impl HistoryStore {
    /// Everything logged so far, as the bytes of an `.rrd` file.
    ///
    /// # Errors
    /// Rerun's encoder failed.
    pub fn rrd_bytes(&self) -> Result<Vec<u8>, String> {
        rerun::sink::MemorySinkStorage::concat_memory_sinks_as_bytes(&[&self.storage]).map_err(|e| e.to_string())
    }
}

/// Opens the in-memory recording `recording_id` of a live session ([`HistoryStore`]).
///
/// # Errors
/// Rerun could not create the stream.
pub fn open_history(application_id: &'static str, recording_id: &str) -> Result<(Stream, HistoryStore), SinkError> {
    let (rec, storage) = RecordingStreamBuilder::new(application_id)
        .recording_id(recording_id.to_owned())
        .memory()
        .map_err(|e| SinkError::Rerun(e.to_string()))?;
    Ok((Stream::new(rec, None), HistoryStore { storage }))
}

/// Checks that the `.rrd` at `path` is complete: its header, its stream footer and the footer's
/// checksum (what a saved file gets before it replaces anything).
///
/// # Errors
/// Why it is not.
pub fn verify_recording(path: &std::path::Path) -> Result<(), String> {
    let len = std::fs::metadata(path).map_err(|e| format!("{}: {e}", path.display()))?.len();
    file::verify(path, len).map_err(|e| format!("{}: {e}", path.display()))
}

/// What a finished run left.
#[derive(Debug, Clone, Default)]
pub struct Saved {
    /// The recording file and its size, bytes.
    pub recording: Option<(PathBuf, u64)>,
    /// The export tables.
    pub exported: Vec<PathBuf>,
    /// The tables kept in memory (`tables_in_memory`).
    pub tables: Vec<crate::record::export::Table>,
    /// What went wrong with viewers (already reported when it happened).
    pub viewer_problems: Vec<String>,
    /// `--figures`: what was drawn.
    pub figures: Option<crate::record::figures::Written>,
}

impl Saved {
    /// The recording's path as text and its size in bytes, as a summary states them (None without one).
    #[must_use]
    pub fn recording_fields(&self) -> (Option<String>, Option<u64>) {
        self.recording.as_ref().map_or((None, None), |(path, bytes)| (Some(path.display().to_string()), Some(*bytes)))
    }
}

impl OpenSinks {
    /// The stream (and export tables) the recorders log into.
    #[must_use]
    pub fn stream(&self) -> Stream {
        Stream::new(self.rec.clone(), self.export.clone())
    }

    /// Flushes, closes every sink, verifies the saved file and moves it to its final name, and
    /// finishes the export tables.
    ///
    /// # Errors
    /// The file could not be completed ([`SinkError::Write`]; nothing replaced) or an export
    /// table failed.
    pub fn finish(self) -> Result<Saved, SinkError> {
        let Self { rec, file, export, viewer_problems, web, stop, figures, .. } = self;
        // A stop set during the run ended the run (what was simulated is saved); one that comes
        // in a phase after it (the figures) ends that phase and is reported here.
        let never = std::sync::atomic::AtomicBool::new(false);
        let stop_flag: &std::sync::atomic::AtomicBool = stop.as_deref().unwrap_or(&never);
        let stopped_before = stop_flag.load(std::sync::atomic::Ordering::SeqCst);
        // Viewers that stall are detached by their own timeouts; the file's writer is waited for
        // by `RrdFile::finish`, so a flush timeout here loses nothing.
        rec.flush_with_timeout(Duration::from_secs(10)).ok();
        let recording = match file {
            None => None,
            Some(f) => Some(f.finish().map_err(SinkError::Write)?),
        };
        // A stop during the run: every table holds the run until then, and is finished. One that
        // comes while they are finished ends that phase (those done are whole, the rest removed).
        let crate::record::export::Finished { files: exported, tables, left } = match export {
            None => Default::default(),
            Some(e) => {
                let mut e = e.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
                if stopped_before { e.finish() } else { e.finish_until(stop_flag) }
                    .map_err(|e| SinkError::ExportWrite(e.to_string()))?
            }
        };
        if left > 0 {
            return Err(SinkError::Interrupted(format!(
                "--export: stopped after {} tables (each whole; {left} not written){}",
                exported.len(),
                recording
                    .as_ref()
                    .map_or(String::new(), |(path, _)| format!("; the recording {} was saved", path.display()))
            )));
        }
        let viewer_problems = viewer_problems.lock().unwrap_or_else(std::sync::PoisonError::into_inner).clone();
        let figures = match (&figures, &recording) {
            (Some(dir), Some((path, _))) => Some(
                crate::record::figures::write(path, dir, stop_flag)
                    .map_err(|e| SinkError::FiguresWrite(format!("{e:#}")))?,
            ),
            _ => None,
        };
        if let (Some(w), Some((path, _))) = (&figures, &recording)
            && w.interrupted
            && !stopped_before
        {
            return Err(SinkError::Interrupted(format!(
                "--figures: drawing stopped after {} of the figures ({} files, each whole); the recording {} was saved",
                w.plots,
                w.files.len(),
                path.display()
            )));
        }
        // A browser may still be reading: the page and the stream (held by `rec`) serve until the
        // stop flag (Ctrl-C) is set.
        if let (Some(w), Some(stop)) = (web, stop.filter(|s| !s.load(std::sync::atomic::Ordering::SeqCst))) {
            errln!("rinscope: the run is complete; its viewer stays at {} until Ctrl-C", w.page);
            while !stop.load(std::sync::atomic::Ordering::SeqCst) {
                std::thread::sleep(Duration::from_millis(100));
            }
            drop(w);
        }
        drop(rec);
        Ok(Saved { recording, exported, tables, viewer_problems, figures })
    }
}
