//! The class page of `rinscope live --serve-web`: one URL with the Rerun web viewer beside the
//! same controls as the terminal panel. A slider moved in the browser writes the scenario file
//! through the terminal panel's own path ([`Panel::set_control`], then `edit::set_many_in_file`), so
//! the browser, the terminal and a text editor stay in step and a bad value is refused the same way.
//!
//! What the page can do, and nothing more (docs/live.md, "The class page"):
//! - `GET /` the page; `GET /controls` the controls (label, unit, range, step, value) and the
//!   session's status. Watching stays open to whoever reaches the port.
//! - `POST /set` with `{"control": N, "value": X}`: control N of the panel's list — never a file,
//!   a path or a config key — to a value inside its range. Bodies over [`MAX_BODY`] bytes, more
//!   than [`MAX_REQUESTS_PER_S`] requests a second, and anything else are refused.
//! - `POST /calibrate` (an empty body or `{}`): "calibrate now", the compensation frozen at the
//!   table's current errors ([`Panel::calibrate_now`]).
//! - Every request names this server in its `Host` (an IP address, `localhost` or this machine's
//!   name, with the page's port; on loopback only loopback or `localhost`): a page of another site
//!   that points its own domain name at us (DNS rebinding) is refused.
//! - A change is JSON (`Content-Type: application/json`, which another site's page cannot send
//!   without the browser asking first), from this page (`Origin`, when sent, is `http://` + the
//!   Host; `Sec-Fetch-Site: cross-site` is refused), and with `--bind` beyond loopback carries the
//!   session's random token (in the printed URL; the page sends it as `X-Rinscope-Token`).
//!
//! The server (hyper, HTTP/1) runs on a small tokio runtime of its own in a thread owned by
//! [`ClassPage`]; every connection is its own task, so a client that stalls or trickles delays
//! no one else: its headers must arrive within [`HEADER_TIMEOUT`], its body within
//! [`BODY_TIMEOUT`], a connection that moves no byte for [`IDLE_TIMEOUT`] is closed, and at most
//! [`MAX_CONNECTIONS`] are open at once (beyond, a new one is closed at once). Dropping the
//! [`ClassPage`] drops every connection with the runtime.

use std::convert::Infallible;
use std::io;
use std::net::{IpAddr, Ipv4Addr, Ipv6Addr, SocketAddr};
use std::path::{Path, PathBuf};
use std::pin::Pin;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, mpsc};
use std::task::{Context, Poll};
use std::time::{Duration, Instant};

use http_body_util::{BodyExt, Full, LengthLimitError, Limited};
use hyper::body::{Bytes, Incoming};
use hyper::header::{self, HeaderMap, HeaderValue};
use hyper::server::conn::http1;
use hyper::service::service_fn;
use hyper::{Method, Request, Response, StatusCode};
use hyper_util::rt::{TokioIo, TokioTimer};
use serde_json::{Value, json};
use tokio::io::{AsyncRead, AsyncWrite, ReadBuf};
use tokio::net::{TcpSocket, TcpStream};
use tokio::sync::{OwnedSemaphorePermit, Semaphore, oneshot};

use super::panel::{Action, Control, Panel};
use super::{SharedStatus, Status, edit, lock};
use crate::record::sink::address;

/// The page: the viewer in an iframe, the controls beside it (no build chain: one file).
const PAGE: &str = include_str!("../../../assets/web/class.html");

/// Largest request body accepted, bytes.
pub const MAX_BODY: usize = 1024;
/// Most requests served per second (a class of 60 polls 60 a second; a loop sends thousands).
pub const MAX_REQUESTS_PER_S: u32 = 200;
/// Most changes (`POST`) accepted per second (a slider released sends one).
pub const MAX_CHANGES_PER_S: u32 = 20;
/// A request's headers arrive within this time, counted from when the connection waits for them
/// (so a kept-alive connection with no new request is closed after it too).
pub const HEADER_TIMEOUT: Duration = Duration::from_secs(2);
/// A request's body arrives within this time of its headers.
pub const BODY_TIMEOUT: Duration = Duration::from_secs(2);
/// A connection that moves no byte either way for this long is closed (a client that stops
/// reading its answers).
pub const IDLE_TIMEOUT: Duration = Duration::from_secs(10);
/// Most connections open at once; beyond, a new one is closed at once.
pub const MAX_CONNECTIONS: usize = 256;
/// Largest buffer kept for a request's headers, bytes (hyper's minimum is 8 KiB).
const MAX_HEAD: usize = 16 * 1024;
/// How long dropping a [`ClassPage`] waits for its thread (which drops every connection at once).
const STOP_WAIT: Duration = Duration::from_millis(800);
/// The listening socket's queue of connections not yet accepted.
const BACKLOG: u32 = 1024;
const JSON: &str = "application/json";

/// The running page server (stops when dropped, within a second whatever its clients do).
pub struct ClassPage {
    stop: Option<oneshot::Sender<()>>,
    finished: mpsc::Receiver<()>,
    thread: Option<std::thread::JoinHandle<()>>,
    port: u16,
    token: Option<String>,
    /// The URL to print (with the token when there is one).
    pub url: String,
}

impl ClassPage {
    /// The page's URL with `host` (an IP address, bracketed for v6, or a name) in place of the
    /// printed one: for `--bind 0.0.0.0`, the URL other machines open.
    #[must_use]
    pub fn url_at(&self, host: &str) -> String {
        page_url(host, self.port, self.token.as_deref())
    }
}

impl Drop for ClassPage {
    fn drop(&mut self) {
        if let Some(stop) = self.stop.take() {
            stop.send(()).ok();
        }
        // The thread ends by dropping its runtime, and with it every connection (none is waited
        // for); one that does not end in time is left behind rather than waited for.
        if let Some(thread) = self.thread.take()
            && matches!(self.finished.recv_timeout(STOP_WAIT), Ok(()) | Err(mpsc::RecvTimeoutError::Disconnected))
        {
            thread.join().ok();
        }
    }
}

/// What the server needs.
pub struct PageConfig {
    /// Where the page listens (port 0: any free one). The viewer it shows is on the next port and
    /// the viewer's stream on the one after, on the same address.
    pub addr: SocketAddr,
    /// The host name the printed URL carries.
    pub host: String,
    /// The watched scenario file the controls write.
    pub config_path: PathBuf,
    /// Control requests need this token (None: loopback only, no token).
    pub token: Option<String>,
    /// Where to ask for the session so far (`GET /history.rrd`, which the viewer loads beside
    /// the live stream); None: the route answers 404 and the viewer gets the stream only.
    pub history: Option<crossbeam_channel::Sender<super::HistoryRequest>>,
}

/// How long a late viewer's copy of the session so far is served again to the next one (a class
/// opening the page at once is one encoding, not thirty).
const HISTORY_REUSE: Duration = Duration::from_secs(1);
/// How long the page waits for the recorder's copy of the session so far.
const HISTORY_WAIT: Duration = Duration::from_secs(5);

/// A random token of 128 bits from the operating system's generator, hex.
///
/// # Errors
/// The system's generator cannot be read.
pub fn random_token() -> anyhow::Result<String> {
    use rand::TryRngCore;
    let mut b = [0u8; 16];
    rand::rngs::OsRng.try_fill_bytes(&mut b).map_err(|e| anyhow::anyhow!("{e}"))?;
    Ok(b.iter().map(|x| format!("{x:02x}")).collect())
}

fn page_url(host: &str, port: u16, token: Option<&str>) -> String {
    match token {
        Some(t) => format!("http://{host}:{port}/?token={t}"),
        None => format!("http://{host}:{port}/"),
    }
}

/// Starts the page server on `cfg.addr`, its controls those of the terminal panel for the
/// configuration in `status`.
///
/// # Errors
/// The address cannot be listened on, its port leaves no room for the viewer's two, or the
/// server's runtime cannot be made.
pub fn start(cfg: PageConfig, status: SharedStatus, title: String) -> anyhow::Result<ClassPage> {
    let cannot = |e: io::Error| anyhow::anyhow!("the class page cannot listen on {}: {e}", cfg.addr);
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_io()
        .enable_time()
        .build()
        .map_err(|e| anyhow::anyhow!("the class page's server cannot start: {e}"))?;
    let listener = {
        let _runtime = runtime.enter();
        let socket = if cfg.addr.is_ipv4() { TcpSocket::new_v4() } else { TcpSocket::new_v6() }.map_err(cannot)?;
        socket.set_reuseaddr(true).map_err(cannot)?;
        socket.bind(cfg.addr).map_err(cannot)?;
        socket.listen(BACKLOG).map_err(cannot)?
    };
    let port = listener.local_addr().map_err(cannot)?.port();
    if port.checked_add(2).is_none() {
        anyhow::bail!("the class page's port {port} leaves no room for the viewer's and its stream's (the next two)");
    }
    let url = page_url(&cfg.host, port, cfg.token.as_deref());
    let panel = Panel::new(&lock(&status).resolved, title.clone());
    let state = State { panel, seen_generation: u64::MAX, window: Instant::now(), served: 0, changes: 0 };
    let token = cfg.token.clone();
    let server = Arc::new(Server {
        hostname: address::this_hostname(),
        cfg,
        port,
        title,
        status,
        state: Mutex::new(state),
        history: tokio::sync::Mutex::new(None),
    });
    let (stop, stopped) = oneshot::channel();
    let (finished_tx, finished) = mpsc::channel::<()>();
    let thread = std::thread::Builder::new().name("class page".into()).spawn(move || {
        runtime.block_on(serve(listener, server, stopped));
        // Every connection's task is dropped with the runtime, wherever it was.
        runtime.shutdown_timeout(Duration::from_millis(100));
        drop(finished_tx);
    })?;
    Ok(ClassPage { stop: Some(stop), finished, thread: Some(thread), port, token, url })
}

/// The server's state, shared by every connection.
struct Server {
    cfg: PageConfig,
    /// The port the page listens on (the viewer's is the next, its stream's the one after).
    port: u16,
    /// This machine's name, which a request's Host may carry beyond loopback.
    hostname: Option<String>,
    title: String,
    status: SharedStatus,
    state: Mutex<State>,
    /// The last copy of the session so far and when it was made (held across the wait for a new
    /// one, so that concurrent late viewers share it).
    history: tokio::sync::Mutex<Option<(Instant, Bytes)>>,
}

/// The panel and the rate counters (locked briefly, never across a wait).
struct State {
    panel: Panel,
    seen_generation: u64,
    window: Instant,
    served: u32,
    changes: u32,
}

/// Accepts connections until told to stop; each one its own task.
async fn serve(listener: tokio::net::TcpListener, server: Arc<Server>, mut stopped: oneshot::Receiver<()>) {
    let slots = Arc::new(Semaphore::new(MAX_CONNECTIONS));
    loop {
        let stream = tokio::select! {
            _ = &mut stopped => return,
            accepted = listener.accept() => match accepted {
                Ok((stream, _)) => stream,
                // Out of file descriptors and the like: a pause rather than a spin.
                Err(_) => {
                    tokio::time::sleep(Duration::from_millis(50)).await;
                    continue;
                }
            },
        };
        // Beyond the limit the connection is closed at once (dropped).
        let Ok(slot) = slots.clone().try_acquire_owned() else { continue };
        stream.set_nodelay(true).ok();
        tokio::spawn(connection(stream, server.clone(), slot));
    }
}

/// Serves one connection until it closes, times out or stays idle.
async fn connection(stream: TcpStream, server: Arc<Server>, _slot: OwnedSemaphorePermit) {
    let opened = tokio::time::Instant::now();
    let last_byte_ms = Arc::new(AtomicU64::new(0));
    let io = TokioIo::new(Watched { stream, opened, last_byte_ms: last_byte_ms.clone() });
    let service = service_fn(move |req| {
        let server = server.clone();
        async move { Ok::<_, Infallible>(server.answer(req).await) }
    });
    let conn = http1::Builder::new()
        .timer(TokioTimer::new())
        .header_read_timeout(HEADER_TIMEOUT)
        .max_buf_size(MAX_HEAD)
        .serve_connection(io, service);
    tokio::select! {
        _ = conn => {}
        () = idle(opened, &last_byte_ms) => {}
    }
}

/// Returns once no byte has moved for [`IDLE_TIMEOUT`].
async fn idle(opened: tokio::time::Instant, last_byte_ms: &AtomicU64) {
    loop {
        let deadline = opened + Duration::from_millis(last_byte_ms.load(Ordering::Relaxed)) + IDLE_TIMEOUT;
        if tokio::time::Instant::now() >= deadline {
            return;
        }
        tokio::time::sleep_until(deadline).await;
    }
}

/// A connection's socket that notes when a byte last moved.
struct Watched {
    stream: TcpStream,
    opened: tokio::time::Instant,
    last_byte_ms: Arc<AtomicU64>,
}

impl Watched {
    fn moved(&self) {
        self.last_byte_ms
            .store(u64::try_from(self.opened.elapsed().as_millis()).unwrap_or(u64::MAX), Ordering::Relaxed);
    }
}

impl AsyncRead for Watched {
    fn poll_read(self: Pin<&mut Self>, cx: &mut Context<'_>, buf: &mut ReadBuf<'_>) -> Poll<io::Result<()>> {
        let this = self.get_mut();
        let before = buf.filled().len();
        let poll = Pin::new(&mut this.stream).poll_read(cx, buf);
        if buf.filled().len() > before {
            this.moved();
        }
        poll
    }
}

impl AsyncWrite for Watched {
    fn poll_write(self: Pin<&mut Self>, cx: &mut Context<'_>, buf: &[u8]) -> Poll<io::Result<usize>> {
        let this = self.get_mut();
        let poll = Pin::new(&mut this.stream).poll_write(cx, buf);
        if matches!(poll, Poll::Ready(Ok(n)) if n > 0) {
            this.moved();
        }
        poll
    }

    fn poll_flush(self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        Pin::new(&mut self.get_mut().stream).poll_flush(cx)
    }

    fn poll_shutdown(self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        Pin::new(&mut self.get_mut().stream).poll_shutdown(cx)
    }
}

/// A request's Host, checked: the header as sent and its host part (`[v6]` bracketed).
struct Host {
    header: String,
    name: String,
}

/// What a `POST` asks for.
#[derive(Clone, Copy)]
enum Change {
    Set,
    Calibrate,
}

type Answer = Response<Full<Bytes>>;

impl Server {
    /// The answer to one request.
    async fn answer(&self, req: Request<Incoming>) -> Answer {
        let host = match self.host(req.headers(), req.uri().authority().map(hyper::http::uri::Authority::as_str)) {
            Ok(h) => h,
            Err(e) => return error(StatusCode::FORBIDDEN, &e),
        };
        if let Some(refused) = self.count(req.method() == Method::POST) {
            return refused;
        }
        let path = req.uri().path().to_owned();
        match (req.method(), path.as_str()) {
            (&Method::GET, "/") => {
                let mut page = reply(StatusCode::OK, self.page(&host), "text/html; charset=utf-8");
                // The page in an agent cluster of its own origin: the browser may then run it apart
                // from the viewer's frame (another origin on the same host), whose drawing without a
                // GPU would otherwise hold up a slider's release by a frame (~0.4 s).
                page.headers_mut()
                    .insert(header::HeaderName::from_static("origin-agent-cluster"), HeaderValue::from_static("?1"));
                page
            }
            (&Method::GET, "/controls") => {
                let body = self.with_panel(|panel, st| controls_json(panel, st, &self.cfg.config_path));
                reply(StatusCode::OK, body.to_string(), JSON)
            }
            (&Method::GET, address::HISTORY_PATH) => self.history(&host).await,
            (&Method::POST, "/set") => self.change(req, &host, Change::Set).await,
            (&Method::POST, "/calibrate") => self.change(req, &host, Change::Calibrate).await,
            (method, _) => error(
                StatusCode::NOT_FOUND,
                &format!(
                    "no {method} {path} here: the page is /, its controls /controls, a change POST /set, \"calibrate now\" POST /calibrate"
                ),
            ),
        }
    }

    /// The request's Host when it names this server ([`checked_host`]); why not otherwise.
    fn host(&self, headers: &HeaderMap, authority: Option<&str>) -> Result<Host, String> {
        let mut given = headers.get_all(header::HOST).iter();
        let (Some(value), None) = (given.next(), given.next()) else {
            return Err("a request names this page's host and port in one Host header".into());
        };
        let header = value.to_str().map_err(|_| "the Host header is not plain text".to_owned())?;
        if let Some(a) = authority
            && a != header
        {
            return Err(format!("the request's URL names {a} but its Host {header}"));
        }
        let name = checked_host(header, self.port, self.cfg.addr.ip().is_loopback(), self.hostname.as_deref())?;
        Ok(Host { header: header.to_owned(), name: name.to_owned() })
    }

    /// Counts a request (and a change); the refusal when over the rate.
    fn count(&self, change: bool) -> Option<Answer> {
        let mut state = self.state();
        if state.window.elapsed() >= Duration::from_secs(1) {
            (state.window, state.served, state.changes) = (Instant::now(), 0, 0);
        }
        state.served = state.served.saturating_add(1);
        if change {
            state.changes = state.changes.saturating_add(1);
        }
        (state.served > MAX_REQUESTS_PER_S || state.changes > MAX_CHANGES_PER_S).then(|| {
            error(
                StatusCode::TOO_MANY_REQUESTS,
                &format!("more than {MAX_REQUESTS_PER_S} requests or {MAX_CHANGES_PER_S} changes a second"),
            )
        })
    }

    fn state(&self) -> MutexGuard<'_, State> {
        // A poisoned lock only means a request panicked mid-update; the panel is still usable.
        self.state.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    /// Runs `f` on the panel, brought up to date with the session's status.
    fn with_panel<T>(&self, f: impl FnOnce(&mut Panel, &Status) -> T) -> T {
        let st = lock(&self.status).clone();
        let mut state = self.state();
        if st.generation != state.seen_generation {
            state.panel.sync(&st.resolved);
            state.seen_generation = st.generation;
        }
        state.panel.show_speed(st.speed);
        f(&mut state.panel, &st)
    }

    /// The session so far as one `.rrd` (compact chunks), for the viewer this page shows: it
    /// loads it beside the live stream, which keeps no history (a late viewer would otherwise
    /// replay every small chunk of it, slower than the session runs). Readable by the viewer's
    /// page (the next port, another origin).
    async fn history(&self, host: &Host) -> Answer {
        let Some(requests) = &self.cfg.history else {
            return error(StatusCode::NOT_FOUND, "this session keeps no history for late viewers");
        };
        let mut cached = self.history.lock().await;
        let bytes = match cached.as_ref().filter(|(at, _)| at.elapsed() < HISTORY_REUSE) {
            Some((_, bytes)) => bytes.clone(),
            None => {
                let (reply, answer) = oneshot::channel();
                if requests.send(super::HistoryRequest { reply }).is_err() {
                    return error(StatusCode::SERVICE_UNAVAILABLE, "the session has ended");
                }
                match tokio::time::timeout(HISTORY_WAIT, answer).await {
                    Ok(Ok(Ok(bytes))) => {
                        let bytes = Bytes::from(bytes);
                        *cached = Some((Instant::now(), bytes.clone()));
                        bytes
                    }
                    Ok(Ok(Err(e))) => {
                        return error(
                            StatusCode::INTERNAL_SERVER_ERROR,
                            &format!("the session so far could not be encoded: {e}"),
                        );
                    }
                    Ok(Err(_)) => return error(StatusCode::SERVICE_UNAVAILABLE, "the session has ended"),
                    Err(_) => return error(StatusCode::SERVICE_UNAVAILABLE, "the session did not answer in time"),
                }
            }
        };
        drop(cached);
        let mut r = Response::new(Full::new(bytes));
        let h = r.headers_mut();
        h.insert(header::CONTENT_TYPE, HeaderValue::from_static("application/octet-stream"));
        h.insert(header::CACHE_CONTROL, HeaderValue::from_static("no-store"));
        h.insert(header::X_CONTENT_TYPE_OPTIONS, HeaderValue::from_static("nosniff"));
        if let Ok(origin) =
            HeaderValue::from_str(&format!("http://{}:{}", self.viewer_host(host), self.port.saturating_add(1)))
        {
            h.insert(header::ACCESS_CONTROL_ALLOW_ORIGIN, origin);
        }
        r
    }

    /// The host of the viewer's and the stream's URLs: the one the browser asked for when the
    /// server listens on every address, the one it listens on otherwise.
    fn viewer_host(&self, host: &Host) -> String {
        let ip = self.cfg.addr.ip();
        if ip.is_unspecified() { host.name.clone() } else { address::url_host(ip) }
    }

    /// The page, its viewer on the host the browser asked for when the server listens on every
    /// address (the one it listens on otherwise). The viewer's URL asks for its dark theme (the
    /// page's script works around Rerun's first start).
    fn page(&self, host: &Host) -> String {
        let history = self.cfg.history.as_ref().map(|_| self.port);
        let viewer = address::web_viewer_page(
            &self.viewer_host(host),
            self.port.saturating_add(1),
            self.port.saturating_add(2),
            history,
        );
        PAGE.replace("{{VIEWER_URL}}", &html_escape(&viewer)).replace("{{TITLE}}", &html_escape(&self.title))
    }

    /// A change: checked, its body read (within [`BODY_TIMEOUT`]), applied through the panel.
    async fn change(&self, req: Request<Incoming>, host: &Host, what: Change) -> Answer {
        if let Some(refused) = self.change_refusal(req.headers(), host) {
            return refused;
        }
        let body = match read_body(req).await {
            Ok(b) => b,
            Err(refused) => return refused,
        };
        let path = &self.cfg.config_path;
        let done = match what {
            Change::Set => self.with_panel(|panel, _| set(panel, &body, path)),
            Change::Calibrate if is_empty_object(&body) => {
                self.with_panel(|panel, _| write(panel.calibrate_now(), path))
            }
            Change::Calibrate => Err("\"calibrate now\" takes no body (or {})".into()),
        };
        match done {
            Ok(()) => reply(StatusCode::OK, json!({"ok": true}).to_string(), JSON),
            Err(e) => error(StatusCode::BAD_REQUEST, &e),
        }
    }

    /// The answer refusing a change that is not this page's (None: it may go on).
    fn change_refusal(&self, headers: &HeaderMap, host: &Host) -> Option<Answer> {
        let text = |name: &str| headers.get(name).map(|v| v.to_str().unwrap_or("(not text)"));
        if text("sec-fetch-site").is_some_and(|s| s.eq_ignore_ascii_case("cross-site")) {
            return Some(error(
                StatusCode::FORBIDDEN,
                "a page of another site cannot change this session (Sec-Fetch-Site: cross-site)",
            ));
        }
        if let Some(origin) = text("origin")
            && origin != format!("http://{}", host.header)
        {
            return Some(error(
                StatusCode::FORBIDDEN,
                &format!("a change comes from this page: Origin {origin} is not http://{}", host.header),
            ));
        }
        if let Some(token) = &self.cfg.token
            && text("x-rinscope-token") != Some(token.as_str())
        {
            return Some(error(
                StatusCode::FORBIDDEN,
                "this session is shared beyond this machine: changing a parameter needs the token of the URL the terminal printed",
            ));
        }
        let json = text("content-type")
            .is_some_and(|t| t.split(';').next().unwrap_or_default().trim().eq_ignore_ascii_case(JSON));
        (!json).then(|| {
            error(StatusCode::UNSUPPORTED_MEDIA_TYPE, "a change is sent as JSON (Content-Type: application/json)")
        })
    }
}

/// The host part of `host` (a request's Host header: `name[:port]`, `[v6][:port]`) when it names
/// this server: an IP address (v4, or v6 in brackets), `localhost`, or this machine's `hostname`,
/// with the server's `port` (none: 80); on `loopback_only`, a loopback address or `localhost`.
/// A domain name pointing at us (DNS rebinding) is none of these.
fn checked_host<'a>(host: &'a str, port: u16, loopback_only: bool, hostname: Option<&str>) -> Result<&'a str, String> {
    let (name, given_port) = match host.strip_prefix('[') {
        Some(rest) => rest.split_once(']').map_or((host, ""), |(inner, after)| (&host[..inner.len() + 2], after)),
        None => host.split_once(':').map_or((host, ""), |(name, _)| (name, &host[name.len()..])),
    };
    let given_port = match given_port.strip_prefix(':') {
        None if given_port.is_empty() => Some(80),
        Some(p) if !p.is_empty() && p.bytes().all(|b| b.is_ascii_digit()) => p.parse::<u16>().ok(),
        _ => None,
    };
    if given_port != Some(port) {
        return Err(format!("Host {host}: this page is on port {port}"));
    }
    let ip: Option<IpAddr> = match name.strip_prefix('[').and_then(|n| n.strip_suffix(']')) {
        Some(v6) => v6.parse::<Ipv6Addr>().ok().map(IpAddr::V6),
        None => name.parse::<Ipv4Addr>().ok().map(IpAddr::V4),
    };
    let localhost = name.eq_ignore_ascii_case("localhost");
    let ok = match ip {
        Some(ip) => !loopback_only || ip.to_canonical().is_loopback(),
        None => localhost || (!loopback_only && hostname.is_some_and(|h| name.eq_ignore_ascii_case(h))),
    };
    match (ok, loopback_only) {
        (true, _) => Ok(name),
        (false, true) => Err(format!(
            "Host {host}: this page answers to a loopback address or localhost only (a site's name pointing here is refused)"
        )),
        (false, false) => Err(format!(
            "Host {host}: this page answers to an IP address, localhost or this machine's name only (a site's name pointing here is refused)"
        )),
    }
}

/// A change's body: at most [`MAX_BODY`] bytes, arrived within [`BODY_TIMEOUT`]; the refusal
/// otherwise (which closes the connection).
async fn read_body(req: Request<Incoming>) -> Result<Bytes, Answer> {
    let too_big =
        || closing(error(StatusCode::PAYLOAD_TOO_LARGE, &format!("a request body is at most {MAX_BODY} bytes")));
    let declared =
        req.headers().get(header::CONTENT_LENGTH).and_then(|v| v.to_str().ok()).and_then(|v| v.parse::<u64>().ok());
    if declared.is_some_and(|n| n > MAX_BODY as u64) {
        return Err(too_big());
    }
    match tokio::time::timeout(BODY_TIMEOUT, Limited::new(req.into_body(), MAX_BODY).collect()).await {
        Ok(Ok(body)) => Ok(body.to_bytes()),
        Ok(Err(e)) if e.downcast_ref::<LengthLimitError>().is_some() => Err(too_big()),
        Ok(Err(e)) => {
            Err(closing(error(StatusCode::BAD_REQUEST, &format!("the request's body could not be read: {e}"))))
        }
        Err(_) => Err(closing(error(
            StatusCode::REQUEST_TIMEOUT,
            &format!("the request's body did not arrive within {} s of its headers", BODY_TIMEOUT.as_secs()),
        ))),
    }
}

/// An empty body (blank) or `{}`.
fn is_empty_object(body: &[u8]) -> bool {
    body.iter().all(u8::is_ascii_whitespace)
        || serde_json::from_slice::<Value>(body).is_ok_and(|v| v.as_object().is_some_and(serde_json::Map::is_empty))
}

fn reply(code: StatusCode, body: String, kind: &'static str) -> Answer {
    let mut r = Response::new(Full::new(Bytes::from(body)));
    *r.status_mut() = code;
    let h = r.headers_mut();
    h.insert(header::CONTENT_TYPE, HeaderValue::from_static(kind));
    h.insert(header::CACHE_CONTROL, HeaderValue::from_static("no-store"));
    h.insert(header::X_CONTENT_TYPE_OPTIONS, HeaderValue::from_static("nosniff"));
    r
}

fn error(code: StatusCode, message: &str) -> Answer {
    reply(code, json!({ "error": message }).to_string(), JSON)
}

/// `answer` with the connection closed after it (its request's body was not read to the end).
fn closing(mut answer: Answer) -> Answer {
    answer.headers_mut().insert(header::CONNECTION, HeaderValue::from_static("close"));
    answer
}

/// Applies `{"control": N, "value": X}` through the panel and writes the file.
fn set(panel: &mut Panel, body: &[u8], config_path: &Path) -> Result<(), String> {
    let v: Value = serde_json::from_slice(body)
        .map_err(|e| format!("the body must be JSON {{\"control\": N, \"value\": X}}: {e}"))?;
    let obj = v.as_object().ok_or("the body must be a JSON object {\"control\": N, \"value\": X}")?;
    if let Some(extra) = obj.keys().find(|k| *k != "control" && *k != "value") {
        return Err(format!(
            "unknown field {extra:?}: a change names a control by its number and a value, nothing else"
        ));
    }
    let index =
        obj.get("control").and_then(Value::as_u64).ok_or("\"control\" must be a control's number (see /controls)")?;
    let value = match obj.get("value") {
        Some(Value::Bool(b)) => f64::from(u8::from(*b)),
        Some(x) => x.as_f64().ok_or("\"value\" must be a number (or true/false for a switch)")?,
        None => return Err("\"value\" is missing".into()),
    };
    write(panel.set_control(usize::try_from(index).unwrap_or(usize::MAX), value)?, config_path)
}

/// Writes a panel's action into the file, all its keys at once.
fn write(action: Action, config_path: &Path) -> Result<(), String> {
    match action {
        Action::Set(writes) => {
            let writes: Vec<_> = writes.into_iter().map(|(k, v)| (k, v.to_value())).collect();
            edit::set_many_in_file(config_path, &writes).map_err(|e| format!("not written: {e}"))
        }
        Action::None | Action::Quit => Ok(()),
    }
}

fn controls_json(panel: &Panel, st: &Status, config_path: &Path) -> Value {
    let controls: Vec<Value> = panel
        .controls
        .iter()
        .enumerate()
        .map(|(i, c)| match c {
            Control::Slider { label, unit, min, max, step, log, value, .. } => {
                json!({"id": i, "kind": "slider", "label": label, "unit": unit, "min": min, "max": max, "step": step, "log": log, "value": value})
            }
            Control::Toggle { label, value, .. } => json!({"id": i, "kind": "toggle", "label": label, "value": value}),
        })
        .collect();
    json!({
        "title": panel.title,
        "config": config_path.file_name().map(|f| f.to_string_lossy().into_owned()),
        "sim_t_s": st.sim_t_s,
        "speed": st.speed,
        "message": st.message,
        "running": st.running,
        "generation": st.generation,
        "controls": controls,
    })
}

fn html_escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

#[cfg(test)]
mod tests;
