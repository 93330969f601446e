//! The class page of `rinscope live --serve-web`: one URL with the Rerun web viewer beside the
//! same controls as the terminal panel. A slider moved in the browser writes the scenario file
//! through the terminal panel's own path ([`Panel::set_control`], then `edit::set_in_file`), so the
//! browser, the terminal and a text editor stay in step and a bad value is refused the same way.
//!
//! What the page can do, and nothing more (docs/live.md, "The class page"):
//! - `GET /` the page; `GET /controls` the controls (label, unit, range, step, value) and the
//!   session's status. Watching stays open to whoever reaches the port.
//! - `POST /set` with `{"control": N, "value": X}`: control N of the panel's list — never a file,
//!   a path or a config key — to a value inside its range. Bodies over [`MAX_BODY`] bytes, more
//!   than [`MAX_REQUESTS_PER_S`] requests a second, and anything else are refused.
//! - `POST /calibrate` (no body): "calibrate now", the compensation frozen at the table's current
//!   errors ([`Panel::calibrate_now`]).
//! - With `--bind` beyond loopback, `POST` needs the session's random token (in the printed URL;
//!   the page sends it as `X-Rinscope-Token`).

use std::io::Read;
use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use serde_json::{json, Value};

use super::panel::{Action, Control, Panel};
use super::{edit, lock, SharedStatus};

/// The page: the viewer in an iframe, the controls beside it (no build chain: one file).
const PAGE: &str = include_str!("../../../assets/web/class.html");

/// Largest request body accepted, bytes.
pub const MAX_BODY: usize = 1024;
/// Most requests served per second (a class of 60 polls 60 a second; a loop sends thousands).
pub const MAX_REQUESTS_PER_S: u32 = 200;
/// Most changes (`POST`) accepted per second (a slider released sends one).
pub const MAX_CHANGES_PER_S: u32 = 20;

/// The running page server (stops when dropped).
pub struct ClassPage {
    stop: Arc<AtomicBool>,
    thread: Option<std::thread::JoinHandle<()>>,
    /// The URL to print (with the token when there is one).
    pub url: String,
}

impl Drop for ClassPage {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::SeqCst);
        if let Some(t) = self.thread.take() {
            t.join().ok();
        }
    }
}

/// What the server needs.
pub struct PageConfig {
    /// Where the page listens.
    pub addr: SocketAddr,
    /// The host name the URLs carry.
    pub host: String,
    /// The Rerun web viewer's URL (with its `?url=` of the stream), shown in the iframe.
    pub viewer_url: String,
    /// The watched scenario file the controls write.
    pub config_path: PathBuf,
    /// Control requests need this token (None: loopback only, no token).
    pub token: Option<String>,
}

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

/// Starts the page server on `cfg.addr`, its controls those of the terminal panel for the
/// configuration in `status`.
///
/// # Errors
/// The address cannot be listened on.
pub fn start(cfg: PageConfig, status: SharedStatus, title: String) -> anyhow::Result<ClassPage> {
    let server = tiny_http::Server::http(cfg.addr).map_err(|e| anyhow::anyhow!("the class page cannot listen on {}: {e}", cfg.addr))?;
    let port = server.server_addr().to_ip().map_or(cfg.addr.port(), |a| a.port());
    let url = match &cfg.token {
        Some(t) => format!("http://{}:{port}/?token={t}", cfg.host),
        None => format!("http://{}:{port}/", cfg.host),
    };
    let stop = Arc::new(AtomicBool::new(false));
    let thread = {
        let stop = stop.clone();
        std::thread::Builder::new().name("class page".into()).spawn(move || serve(&server, &cfg, &status, &title, &stop))?
    };
    Ok(ClassPage { stop, thread: Some(thread), url })
}

fn serve(server: &tiny_http::Server, cfg: &PageConfig, status: &SharedStatus, title: &str, stop: &AtomicBool) {
    let resolved = lock(status).resolved.clone();
    let mut panel = Panel::new(&resolved, title.to_owned());
    let mut seen_generation = u64::MAX;
    let (mut window, mut served, mut changes) = (Instant::now(), 0u32, 0u32);
    while !stop.load(Ordering::SeqCst) {
        let Ok(Some(mut req)) = server.recv_timeout(Duration::from_millis(100)) else { continue };
        if window.elapsed() >= Duration::from_secs(1) {
            (window, served, changes) = (Instant::now(), 0, 0);
        }
        served += 1;
        if *req.method() == tiny_http::Method::Post {
            changes += 1;
        }
        let (code, body, kind) = if served > MAX_REQUESTS_PER_S || changes > MAX_CHANGES_PER_S {
            (429, json!({"error": format!("more than {MAX_REQUESTS_PER_S} requests or {MAX_CHANGES_PER_S} changes a second")}).to_string(), "application/json")
        } else {
            let st = lock(status).clone();
            if st.generation != seen_generation {
                panel.sync(&st.resolved);
                seen_generation = st.generation;
            }
            panel.show_speed(st.speed);
            answer(&mut req, cfg, &mut panel, &st)
        };
        let response = tiny_http::Response::from_string(body)
            .with_status_code(code)
            .with_header(tiny_http::Header::from_bytes("Content-Type", kind).expect("a valid header"))
            .with_header(tiny_http::Header::from_bytes("Cache-Control", "no-store").expect("a valid header"));
        req.respond(response).ok();
    }
}

/// The answer to one request: status code, body, content type.
fn answer(req: &mut tiny_http::Request, cfg: &PageConfig, panel: &mut Panel, st: &super::Status) -> (u16, String, &'static str) {
    let err = |code: u16, message: String| (code, json!({ "error": message }).to_string(), "application/json");
    let path = req.url().split('?').next().unwrap_or("").to_owned();
    match (req.method(), path.as_str()) {
        // The viewer's URL asks for its dark theme (record::sink; the page's script works around
        // Rerun's first start).
        (tiny_http::Method::Get, "/") => (200, PAGE.replace("{{VIEWER_URL}}", &cfg.viewer_url).replace("{{TITLE}}", &html_escape(&panel.title)), "text/html; charset=utf-8"),
        (tiny_http::Method::Get, "/controls") => (200, controls_json(panel, st, &cfg.config_path).to_string(), "application/json"),
        (tiny_http::Method::Post, "/set") => {
            if let Some(e) = token_refusal(req, cfg) {
                return e;
            }
            if req.body_length().is_some_and(|n| n > MAX_BODY) {
                return err(413, format!("a request body is at most {MAX_BODY} bytes"));
            }
            let mut body = Vec::new();
            if req.as_reader().take(MAX_BODY as u64 + 1).read_to_end(&mut body).is_err() || body.len() > MAX_BODY {
                return err(413, format!("a request body is at most {MAX_BODY} bytes"));
            }
            match set(panel, &body, &cfg.config_path) {
                Ok(()) => (200, json!({"ok": true}).to_string(), "application/json"),
                Err(e) => err(400, e),
            }
        }
        (tiny_http::Method::Post, "/calibrate") => {
            if let Some(e) = token_refusal(req, cfg) {
                return e;
            }
            if req.body_length().is_some_and(|n| n > 0) {
                return err(400, "\"calibrate now\" takes no body".into());
            }
            match write(panel.calibrate_now(), &cfg.config_path) {
                Ok(()) => (200, json!({"ok": true}).to_string(), "application/json"),
                Err(e) => err(400, e),
            }
        }
        _ => err(404, format!("no {} {path} here: the page is /, its controls /controls, a change POST /set, \"calibrate now\" POST /calibrate", req.method())),
    }
}

/// The answer refusing a change without the session's token (None: it may go on).
fn token_refusal(req: &tiny_http::Request, cfg: &PageConfig) -> Option<(u16, String, &'static str)> {
    let token = cfg.token.as_ref()?;
    let given = req.headers().iter().find(|h| h.field.equiv("X-Rinscope-Token")).map(|h| h.value.as_str().to_owned());
    (given.as_deref() != Some(token.as_str())).then(|| {
        let message = "this session is shared beyond this machine: changing a parameter needs the token of the URL the terminal printed";
        (403, json!({ "error": message }).to_string(), "application/json")
    })
}

/// Applies `{"control": N, "value": X}` through the panel and writes the file.
fn set(panel: &mut Panel, body: &[u8], config_path: &Path) -> Result<(), String> {
    let v: Value = serde_json::from_slice(body).map_err(|e| format!("the body must be JSON {{\"control\": N, \"value\": X}}: {e}"))?;
    let obj = v.as_object().ok_or("the body must be a JSON object {\"control\": N, \"value\": X}")?;
    if let Some(extra) = obj.keys().find(|k| *k != "control" && *k != "value") {
        return Err(format!("unknown field {extra:?}: a change names a control by its number and a value, nothing else"));
    }
    let index = obj.get("control").and_then(Value::as_u64).ok_or("\"control\" must be a control's number (see /controls)")?;
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

fn controls_json(panel: &Panel, st: &super::Status, config_path: &Path) -> Value {
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
mod tests {
    //! The page's server on loopback, spoken to as a browser would (raw HTTP/1.1 over a socket):
    //! a slider's change writes the file; everything else is refused and leaves the file as it was.

    use std::io::{Read, Write};
    use std::net::TcpStream;

    use super::*;
    use crate::scenario;

    const PRESET: &str = include_str!("../../../assets/scenarios/jiang2017-dual-axis.toml");

    fn page(token: Option<&str>, name: &str) -> (ClassPage, PathBuf) {
        let dir = std::env::temp_dir().join(format!("rinscope-web-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("dir");
        let path = dir.join("class.toml");
        std::fs::write(&path, PRESET).expect("config");
        let params = scenario::parse(PRESET, "test").expect("preset");
        let status = super::super::new_status(&params, 1.0);
        let cfg = PageConfig { addr: "127.0.0.1:0".parse().expect("addr"), host: "127.0.0.1".into(), viewer_url: "http://127.0.0.1:1/?url=x".into(), config_path: path.clone(), token: token.map(str::to_owned) };
        (start(cfg, status, "test page".into()).expect("listens"), path)
    }

    /// Sends one request; the status code and the body.
    fn request(url: &str, method: &str, path: &str, headers: &[(&str, &str)], body: &[u8]) -> (u16, String) {
        let authority = url.trim_start_matches("http://").split('/').next().expect("host:port");
        let mut s = TcpStream::connect(authority).expect("connects");
        s.set_read_timeout(Some(Duration::from_secs(5))).ok();
        let mut head = format!("{method} {path} HTTP/1.1\r\nHost: {authority}\r\nConnection: close\r\nContent-Length: {}\r\n", body.len());
        for (k, v) in headers {
            head += &format!("{k}: {v}\r\n");
        }
        head += "\r\n";
        s.write_all(head.as_bytes()).expect("writes");
        s.write_all(body).ok();
        let mut out = Vec::new();
        s.read_to_end(&mut out).ok();
        let text = String::from_utf8_lossy(&out).into_owned();
        let code = text.split_whitespace().nth(1).and_then(|c| c.parse().ok()).unwrap_or(0);
        (code, text.split("\r\n\r\n").nth(1).unwrap_or_default().to_owned())
    }

    /// The index of the control labelled `label` in /controls.
    fn control(url: &str, label: &str) -> u64 {
        let (code, body) = request(url, "GET", "/controls", &[], b"");
        assert_eq!(code, 200, "{body}");
        let v: Value = serde_json::from_str(&body).expect("json");
        v["controls"].as_array().expect("controls").iter().find(|c| c["label"] == label).and_then(|c| c["id"].as_u64()).unwrap_or_else(|| panic!("no control {label}: {body}"))
    }

    #[test]
    fn a_slider_moved_on_the_page_writes_the_file_as_the_terminal_panel_does() {
        let (p, path) = page(None, "set");
        let (code, html) = request(&p.url, "GET", "/", &[], b"");
        assert!(code == 200 && html.contains("http://127.0.0.1:1/?url=x") && html.contains("test page"), "{code} {html}");
        let inner = control(&p.url, "inner swing half-angle");
        let (code, body) = request(&p.url, "POST", "/set", &[("Content-Type", "application/json")], format!("{{\"control\": {inner}, \"value\": 450}}").as_bytes());
        assert_eq!(code, 200, "{body}");
        let text = std::fs::read_to_string(&path).expect("config");
        let params = scenario::parse(&text, "edited").expect("still a valid scenario");
        assert_eq!(params.resolved.turntable.axis[1].swing_half_angle_arcsec, 450.0);
        // The user's comments and layout kept (the same editor the terminal panel uses).
        assert_eq!(text.lines().count(), PRESET.lines().count());
        // "Calibrate now": the compensation frozen at the current errors (the inner swing now 450″).
        let (code, body) = request(&p.url, "POST", "/calibrate", &[], b"");
        assert_eq!(code, 200, "{body}");
        let params = scenario::parse(&std::fs::read_to_string(&path).expect("config"), "calibrated").expect("valid");
        assert_eq!(params.resolved.compensation.axis.get("inner").and_then(|a| a.swing_half_angle_arcsec), Some(450.0));
        assert_eq!(params.resolved.compensation.enabled, Some(true));
    }

    #[test]
    fn the_page_can_change_nothing_but_the_panels_parameters() {
        let (p, path) = page(Some("s3cret"), "refusals");
        let before = std::fs::read(&path).expect("config");
        let inner = control(&p.url, "inner swing half-angle");
        let json = |body: &str| body.as_bytes().to_vec();
        let ok_token = [("X-Rinscope-Token", "s3cret")];
        type Case<'a> = (&'a str, &'a str, Vec<(&'a str, &'a str)>, Vec<u8>, u16, &'a str);
        let cases: Vec<Case<'_>> = vec![
            ("no token", "/set", vec![], json(&format!("{{\"control\": {inner}, \"value\": 450}}")), 403, "token"),
            ("calibrate now without the token", "/calibrate", vec![], vec![], 403, "token"),
            ("calibrate now with a body", "/calibrate", ok_token.to_vec(), json("{\"axis\": \"inner\"}"), 400, "no body"),
            ("a wrong token", "/set", vec![("X-Rinscope-Token", "guess")], json(&format!("{{\"control\": {inner}, \"value\": 450}}")), 403, "token"),
            ("a config key", "/set", ok_token.to_vec(), json("{\"key\": \"turntable.axis[1].swing_half_angle_arcsec\", \"value\": 450}"), 400, "unknown field"),
            ("a key beside the control", "/set", ok_token.to_vec(), json(&format!("{{\"control\": {inner}, \"value\": 450, \"path\": \"/etc/passwd\"}}")), 400, "unknown field"),
            ("a control that does not exist", "/set", ok_token.to_vec(), json("{\"control\": 9999, \"value\": 1}"), 400, "no control"),
            ("a value out of range", "/set", ok_token.to_vec(), json(&format!("{{\"control\": {inner}, \"value\": 1e9}}")), 400, "outside"),
            ("a value that is not a number", "/set", ok_token.to_vec(), json(&format!("{{\"control\": {inner}, \"value\": \"NaN\"}}")), 400, "number"),
            ("an oversized body", "/set", ok_token.to_vec(), vec![b' '; 64 * 1024], 413, "at most"),
            ("a path", "/../../etc/passwd", ok_token.to_vec(), vec![], 404, "no POST"),
            ("another route", "/config", ok_token.to_vec(), json("{}"), 404, "no POST"),
        ];
        for (what, route, headers, body, want, says) in cases {
            let (code, answer) = request(&p.url, "POST", route, &headers, &body);
            assert_eq!(code, want, "{what}: {answer}");
            assert!(answer.contains(says), "{what}: {answer}");
            assert_eq!(std::fs::read(&path).expect("config"), before, "{what} changed the file");
        }
        // The token in the printed URL; with it the same change goes through.
        assert!(p.url.ends_with("?token=s3cret"), "{}", p.url);
        let (code, _) = request(&p.url, "POST", "/set", &ok_token, format!("{{\"control\": {inner}, \"value\": 450}}").as_bytes());
        assert_eq!(code, 200);
        assert_ne!(std::fs::read(&path).expect("config"), before);
    }

    #[test]
    fn a_flood_of_changes_is_refused_beyond_the_rate() {
        let (p, path) = page(None, "flood");
        let inner = control(&p.url, "inner swing half-angle");
        let codes: Vec<u16> = (0..3 * MAX_CHANGES_PER_S).map(|i| request(&p.url, "POST", "/set", &[], format!("{{\"control\": {inner}, \"value\": {}}}", 10 * (i % 50)).as_bytes()).0).collect();
        assert!(codes.contains(&429) && codes.iter().filter(|c| **c == 200).count() as u32 >= MAX_CHANGES_PER_S / 2, "{codes:?}");
        assert!(scenario::parse(&std::fs::read_to_string(&path).expect("config"), "flooded").is_ok(), "the file stays a valid scenario");
    }
}
