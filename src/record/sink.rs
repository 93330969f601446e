//! Where a recording goes, following Rerun's conventions: `--save FILE`, `--spawn`, `--connect [URL]`
//! (several at once are allowed). Files are written to `FILE.partial` and renamed only when complete,
//! so a failed or interrupted run never leaves a half-written recording under the final name.

use std::net::{SocketAddr, TcpStream, ToSocketAddrs};
use std::path::PathBuf;
use std::time::Duration;

use rerun::sink::{FileSink, GrpcSink, LogSink};
use rerun::{RecordingStream, RecordingStreamBuilder};

pub use crate::io::files::partial_path;

use super::export::{ExportFormat, Exporter, SharedExporter};
use super::Stream;
use std::sync::{Arc, Mutex};

/// The viewer version that matches the SDK this binary is built with.
pub const VIEWER_INSTALL_HINT: &str = "pip install rerun-sdk==0.36.3";

/// Rerun's default gRPC URL for a viewer on this machine.
pub const DEFAULT_CONNECT_URL: &str = "rerun+http://127.0.0.1:9876/proxy";

/// A problem with a sink the user asked for.
#[derive(Debug, thiserror::Error)]
pub enum SinkError {
    /// `--spawn` but no viewer executable.
    #[error("--spawn: no `rerun` viewer found on PATH. Install the matching viewer with `{VIEWER_INSTALL_HINT}`, or drop --spawn to save a recording under recordings/ and open it later")]
    NoViewer,
    /// `--connect` to an address where nothing listens.
    #[error("--connect: no viewer is listening at {url}. Start one with `rerun` (install: `{VIEWER_INSTALL_HINT}`), use --spawn, or save a file with --save")]
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
    #[error("--save: cannot write {path}: {reason}")]
    File {
        /// The final path.
        path: String,
        /// Why.
        reason: String,
    },
    /// `--serve` on a port that is taken.
    #[error("--serve: cannot listen on port {port}: {reason}")]
    Serve {
        /// The port asked for.
        port: u16,
        /// Why.
        reason: String,
    },
    /// Spawning the viewer failed.
    #[error("--spawn: {0}")]
    Spawn(String),
    /// The export tables could not be written.
    #[error("--export: {0}")]
    Export(String),
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
    /// Also write every time series as tables into this folder.
    pub export: Option<(PathBuf, ExportFormat)>,
}

/// An open recording and the file it will become.
pub struct OpenSinks {
    /// The stream to log into.
    rec: RecordingStream,
    /// The export tables, if asked for.
    export: Option<SharedExporter>,
    /// (partial path, final path) of the saved file, if any.
    pub file: Option<(PathBuf, PathBuf)>,
    /// Human-readable description of where the data goes.
    pub description: Vec<String>,
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

/// Opens every requested sink; checks viewers and paths first so that nothing is created on error.
pub fn open(req: &SinkRequest, application_id: &'static str, recording_id: &str) -> Result<OpenSinks, SinkError> {
    let mut sinks: Vec<Box<dyn LogSink>> = Vec::new();
    let mut description = Vec::new();

    if let Some(url) = &req.connect {
        let uri: rerun::external::re_uri::ProxyUri = url.parse().map_err(|e: rerun::external::re_uri::Error| SinkError::BadUrl { url: url.clone(), reason: e.to_string() })?;
        let listening = socket_of(url).is_some_and(|addr| TcpStream::connect_timeout(&addr, Duration::from_millis(500)).is_ok());
        if !listening {
            return Err(SinkError::NotListening { url: url.clone() });
        }
        sinks.push(Box::new(GrpcSink::new(uri)));
        description.push(format!("streaming to the viewer at {url}"));
    }

    let mut file = None;
    if let Some(path) = &req.save {
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(|e| SinkError::File { path: path.display().to_string(), reason: e.to_string() })?;
        }
        let partial = partial_path(path);
        let sink = FileSink::new(&partial).map_err(|e| SinkError::File { path: path.display().to_string(), reason: e.to_string() })?;
        sinks.push(Box::new(sink));
        file = Some((partial, path.clone()));
        description.push(format!("saving to {}", path.display()));
    }

    if req.spawn {
        if find_on_path("rerun").is_none() {
            if let Some((partial, _)) = &file {
                drop(sinks);
                std::fs::remove_file(partial).ok();
            }
            return Err(SinkError::NoViewer);
        }
        // A new viewer on a free port: a viewer already listening on 9876 keeps its own data.
        let opts = rerun::SpawnOptions { new: true, wait_for_bind: true, hide_welcome_screen: true, ..Default::default() };
        let info = rerun::spawn(&opts).map_err(|e| SinkError::Spawn(e.to_string()))?;
        let url = format!("rerun+http://127.0.0.1:{}/proxy", info.port);
        let uri = url.parse().map_err(|e: rerun::external::re_uri::Error| SinkError::Rerun(e.to_string()))?;
        sinks.push(Box::new(GrpcSink::new(uri)));
        description.push(format!("streaming to a new viewer at {url}"));
    }

    if let Some(port) = req.serve {
        // Check the port first: the server binds in a background task and would fail silently.
        std::net::TcpListener::bind(("0.0.0.0", port)).map_err(|e| SinkError::Serve { port, reason: e.to_string() })?;
        let options = rerun::ServerOptions { memory_limit: rerun::MemoryLimit::from_bytes(1 << 30), ..Default::default() };
        let sink = rerun::grpc_server::GrpcServerSink::new("0.0.0.0", port, options).map_err(|e| SinkError::Serve { port, reason: e.to_string() })?;
        sinks.push(Box::new(sink));
        let url = format!("rerun+http://127.0.0.1:{port}/proxy");
        description.push(format!(
            "serving on {url}: `rerun --connect {url}`, or in a browser https://app.rerun.io/version/0.36.3/index.html?url={}",
            url.replace(':', "%3A").replace('/', "%2F").replace('+', "%2B")
        ));
    }

    let export = match &req.export {
        None => None,
        Some((dir, format)) => {
            let e = Exporter::new(dir, *format).map_err(|e| SinkError::Export(format!("{}: {e}", dir.display())))?;
            description.push(format!("exporting every time series as {format:?} tables to {}", dir.display()));
            Some(Arc::new(Mutex::new(e)))
        }
    };
    let rec = RecordingStreamBuilder::new(application_id)
        .recording_id(recording_id.to_owned())
        .set_sinks(sinks)
        .map_err(|e| SinkError::Rerun(e.to_string()))?;
    Ok(OpenSinks { rec, export, file, description })
}

/// What a finished run left.
#[derive(Debug, Clone, Default)]
pub struct Saved {
    /// The recording file and its size, bytes.
    pub recording: Option<(PathBuf, u64)>,
    /// The export tables.
    pub exported: Vec<PathBuf>,
}

impl OpenSinks {
    /// The stream (and export tables) the recorders log into.
    #[must_use]
    pub fn stream(&self) -> Stream {
        Stream::new(self.rec.clone(), self.export.clone())
    }

    /// Flushes, closes every sink, moves the saved file to its final name and finishes the export
    /// tables.
    pub fn finish(self) -> Result<Saved, SinkError> {
        let Self { rec, file, export, .. } = self;
        // A viewer that went away fails the flush; the file must still be completed and kept.
        if let Err(e) = rec.flush_with_timeout(std::time::Duration::from_secs(10)) {
            eprintln!("rinscope: not every sink received the whole stream ({e}); the saved file is complete");
        }
        // Dropping the last handle joins the batcher and the file writer, which writes the footer.
        drop(rec);
        let recording = match file {
            None => None,
            Some((partial, path)) => {
                std::fs::rename(&partial, &path).map_err(|e| SinkError::File { path: path.display().to_string(), reason: e.to_string() })?;
                let bytes = std::fs::metadata(&path).map(|m| m.len()).unwrap_or(0);
                Some((path, bytes))
            }
        };
        let exported = match export {
            None => Vec::new(),
            Some(e) => e.lock().unwrap_or_else(std::sync::PoisonError::into_inner).finish().map_err(|e| SinkError::Export(e.to_string()))?,
        };
        Ok(Saved { recording, exported })
    }

    /// Closes every sink and deletes the partial file (the run failed).
    pub fn abandon(self) {
        let Self { rec, file, .. } = self;
        drop(rec);
        if let Some((partial, _)) = file {
            std::fs::remove_file(partial).ok();
        }
    }
}
