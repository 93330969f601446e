//! The page's server on loopback, spoken to as a browser, a hostile page or a stalled client would
//! (raw HTTP/1.1 over a socket): a slider's change writes the file; everything else is refused and
//! leaves the file as it was; no client delays another, and the server stops at once.

use std::io::{Read, Write};
use std::net::TcpStream;
use std::time::{Duration, Instant};

use super::*;
use crate::scenario;

const PRESET: &str = include_str!("../../../../assets/scenarios/jiang2017-dual-axis.toml");

/// "Not delayed" on a loaded 2-core machine: an answer within this.
const PROMPT: Duration = Duration::from_secs(1);

fn page_on(addr: &str, token: Option<&str>, name: &str) -> (ClassPage, PathBuf) {
    let dir = std::env::temp_dir().join(format!("rinscope-web-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let path = dir.join("class.toml");
    std::fs::write(&path, PRESET).expect("config");
    let params = scenario::parse(PRESET, "test").expect("preset");
    let status = super::super::new_status(&params, 1.0);
    let cfg = PageConfig {
        addr: addr.parse().expect("addr"),
        host: "127.0.0.1".into(),
        config_path: path.clone(),
        token: token.map(str::to_owned),
        history: None,
    };
    (start(cfg, status, "test page".into()).expect("listens"), path)
}

fn page(token: Option<&str>, name: &str) -> (ClassPage, PathBuf) {
    page_on("127.0.0.1:0", token, name)
}

/// `host:port` of a URL.
fn authority(url: &str) -> &str {
    url.trim_start_matches("http://").split('/').next().expect("host:port")
}

fn port(url: &str) -> u16 {
    authority(url).rsplit(':').next().and_then(|p| p.parse().ok()).expect("a port")
}

/// Sends one request to `to` (`host:port`); the status code and the body. The Host header is `to`
/// unless `headers` name one; a `POST` is sent as JSON unless `headers` name a Content-Type.
fn request_to(to: &str, method: &str, path: &str, headers: &[(&str, &str)], body: &[u8]) -> (u16, String) {
    let mut s = TcpStream::connect(to).expect("connects");
    s.set_read_timeout(Some(Duration::from_secs(5))).ok();
    let named = |name: &str| headers.iter().any(|(k, _)| k.eq_ignore_ascii_case(name));
    let mut head = format!("{method} {path} HTTP/1.1\r\nConnection: close\r\nContent-Length: {}\r\n", body.len());
    if !named("Host") {
        head += &format!("Host: {to}\r\n");
    }
    if method == "POST" && !named("Content-Type") {
        head += "Content-Type: application/json\r\n";
    }
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

fn request(url: &str, method: &str, path: &str, headers: &[(&str, &str)], body: &[u8]) -> (u16, String) {
    request_to(authority(url), method, path, headers, body)
}

/// The index of the control labelled `label` in /controls.
fn control(url: &str, label: &str) -> u64 {
    let (code, body) = request(url, "GET", "/controls", &[], b"");
    assert_eq!(code, 200, "{body}");
    let v: Value = serde_json::from_str(&body).expect("json");
    v["controls"]
        .as_array()
        .expect("controls")
        .iter()
        .find(|c| c["label"] == label)
        .and_then(|c| c["id"].as_u64())
        .unwrap_or_else(|| panic!("no control {label}: {body}"))
}

/// A connection that sent `opening` and then nothing more.
fn stalled(url: &str, opening: &str) -> TcpStream {
    let mut s = TcpStream::connect(authority(url)).expect("connects");
    s.write_all(opening.as_bytes()).expect("writes");
    s
}

/// A connection that sends `text` one byte every 500 ms (slowloris) until the server cuts it.
fn trickled(url: &str, text: &str) -> TcpStream {
    let s = TcpStream::connect(authority(url)).expect("connects");
    let mut writer = s.try_clone().expect("clone");
    let bytes = text.as_bytes().to_vec();
    std::thread::spawn(move || {
        for b in bytes {
            if writer.write_all(&[b]).is_err() {
                return;
            }
            std::thread::sleep(Duration::from_millis(500));
        }
    });
    s
}

/// Another client's `GET /controls`, again and again for `over`: each answered within [`PROMPT`].
fn others_served_promptly(url: &str, over: Duration, what: &str) {
    let started = Instant::now();
    let mut n = 0;
    while started.elapsed() < over {
        let t = Instant::now();
        let (code, body) = request(url, "GET", "/controls", &[], b"");
        assert!(
            code == 200 && t.elapsed() < PROMPT,
            "{what}: another client's GET /controls answered {code} after {:?}: {body}",
            t.elapsed()
        );
        n += 1;
        std::thread::sleep(Duration::from_millis(200));
    }
    assert!(n >= 3, "{what}: {n} requests");
}

/// What a connection receives until the server closes it, and when that was (None: still open
/// after `within`).
fn until_closed(s: &mut TcpStream, opened: Instant, within: Duration) -> (String, Option<Duration>) {
    s.set_read_timeout(Some(Duration::from_millis(100))).ok();
    let mut out = Vec::new();
    let mut buf = [0u8; 4096];
    while opened.elapsed() < within {
        match s.read(&mut buf) {
            Ok(0) => return (String::from_utf8_lossy(&out).into_owned(), Some(opened.elapsed())),
            Ok(n) => out.extend_from_slice(&buf[..n]),
            Err(e) if matches!(e.kind(), std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut) => {}
            Err(_) => return (String::from_utf8_lossy(&out).into_owned(), Some(opened.elapsed())),
        }
    }
    (String::from_utf8_lossy(&out).into_owned(), None)
}

#[test]
fn a_slider_moved_on_the_page_writes_the_file_as_the_terminal_panel_does() {
    let (p, path) = page(None, "set");
    let (code, html) = request(&p.url, "GET", "/", &[], b"");
    let port = port(&p.url);
    let viewer = format!(
        "http://127.0.0.1:{}/?url=rerun%2Bhttp%3A%2F%2F127.0.0.1%3A{}%2Fproxy&amp;theme=dark",
        port + 1,
        port + 2
    );
    assert!(code == 200 && html.contains(&viewer) && html.contains("test page"), "{code} {html}");
    let inner = control(&p.url, "inner swing half-angle");
    let (code, body) =
        request(&p.url, "POST", "/set", &[], format!("{{\"control\": {inner}, \"value\": 450}}").as_bytes());
    assert_eq!(code, 200, "{body}");
    let text = std::fs::read_to_string(&path).expect("config");
    let params = scenario::parse(&text, "edited").expect("still a valid scenario");
    assert_eq!(params.resolved.turntable.axis[1].swing_half_angle_arcsec, 450.0);
    // The user's comments and layout kept (the same editor the terminal panel uses).
    assert_eq!(text.lines().count(), PRESET.lines().count());
    // "Calibrate now": the compensation frozen at the current errors (the inner swing now 450″);
    // the page sends an empty JSON body, `{}` is the same.
    let (code, body) = request(&p.url, "POST", "/calibrate", &[], b"");
    assert_eq!(code, 200, "{body}");
    let (code, body) = request(&p.url, "POST", "/calibrate", &[], b"{}");
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
        (
            "a wrong token",
            "/set",
            vec![("X-Rinscope-Token", "guess")],
            json(&format!("{{\"control\": {inner}, \"value\": 450}}")),
            403,
            "token",
        ),
        (
            "a config key",
            "/set",
            ok_token.to_vec(),
            json("{\"key\": \"turntable.axis[1].swing_half_angle_arcsec\", \"value\": 450}"),
            400,
            "unknown field",
        ),
        (
            "a key beside the control",
            "/set",
            ok_token.to_vec(),
            json(&format!("{{\"control\": {inner}, \"value\": 450, \"path\": \"/etc/passwd\"}}")),
            400,
            "unknown field",
        ),
        (
            "a control that does not exist",
            "/set",
            ok_token.to_vec(),
            json("{\"control\": 9999, \"value\": 1}"),
            400,
            "no control",
        ),
        (
            "a value out of range",
            "/set",
            ok_token.to_vec(),
            json(&format!("{{\"control\": {inner}, \"value\": 1e9}}")),
            400,
            "outside",
        ),
        (
            "a value that is not a number",
            "/set",
            ok_token.to_vec(),
            json(&format!("{{\"control\": {inner}, \"value\": \"NaN\"}}")),
            400,
            "number",
        ),
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
    let (code, _) =
        request(&p.url, "POST", "/set", &ok_token, format!("{{\"control\": {inner}, \"value\": 450}}").as_bytes());
    assert_eq!(code, 200);
    assert_ne!(std::fs::read(&path).expect("config"), before);
}

#[test]
fn a_page_of_another_site_can_change_nothing() {
    // The browser's own defences, checked by the server: another site's page sends its Origin, a
    // cross-site fetch metadata, or (to avoid the browser's preflight) a non-JSON content type; a
    // page that points its domain name at us (DNS rebinding) sends that name as the Host.
    let (p, path) = page(None, "cross-site");
    let before = std::fs::read(&path).expect("config");
    let inner = control(&p.url, "inner swing half-angle");
    let change = format!("{{\"control\": {inner}, \"value\": 450}}");
    let port = port(&p.url);
    let (evil_with_port, other_port) = (format!("evil.example:{port}"), format!("127.0.0.1:{}", port + 1));
    let hostname = address::this_hostname().map(|h| format!("{h}:{port}"));
    let https = format!("https://127.0.0.1:{port}");
    type Case<'a> = (&'a str, Vec<(&'a str, &'a str)>, u16);
    let mut cases: Vec<Case<'_>> = vec![
        ("another site's Origin", vec![("Origin", "http://evil.example")], 403),
        ("Origin null (a sandboxed page)", vec![("Origin", "null")], 403),
        ("this page's origin over https", vec![("Origin", &https)], 403),
        ("Host evil.example", vec![("Host", "evil.example")], 403),
        ("Host evil.example with our port", vec![("Host", &evil_with_port)], 403),
        ("Host of another port", vec![("Host", &other_port)], 403),
        ("a text/plain body (no preflight)", vec![("Content-Type", "text/plain")], 415),
        ("a form", vec![("Content-Type", "application/x-www-form-urlencoded")], 415),
        ("Sec-Fetch-Site: cross-site", vec![("Sec-Fetch-Site", "cross-site")], 403),
    ];
    // On loopback even this machine's name is refused (it is not loopback).
    if let Some(h) = &hostname {
        cases.push(("this machine's name on a loopback page", vec![("Host", h)], 403));
    }
    for (what, headers, want) in &cases {
        let (code, answer) = request(&p.url, "POST", "/set", headers, change.as_bytes());
        assert_eq!(code, *want, "{what}: {answer}");
        assert!(answer.contains("\"error\""), "{what}: {answer}");
        assert_eq!(std::fs::read(&path).expect("config"), before, "{what} changed the file");
    }
    let (code, answer) = request(&p.url, "POST", "/calibrate", &[("Content-Type", "text/plain")], b"");
    assert_eq!(code, 415, "calibrate now as text/plain: {answer}");
    assert_eq!(std::fs::read(&path).expect("config"), before, "calibrate now as text/plain changed the file");
    // Watching too answers only to this server's names.
    assert_eq!(request(&p.url, "GET", "/", &[("Host", "evil.example")], b"").0, 403);
    assert_eq!(request(&p.url, "GET", "/controls", &[("Host", &evil_with_port)], b"").0, 403);
    assert_eq!(request(&p.url, "GET", "/controls", &[("Host", &format!("localhost:{port}"))], b"").0, 200);
    // The page itself (same origin, as a browser sends it) goes through.
    let origin = format!("http://127.0.0.1:{port}");
    let (code, answer) = request(
        &p.url,
        "POST",
        "/set",
        &[("Origin", &origin), ("Sec-Fetch-Site", "same-origin"), ("Content-Type", "application/json; charset=utf-8")],
        change.as_bytes(),
    );
    assert_eq!(code, 200, "{answer}");
}

#[test]
fn checked_hosts() {
    let h = Some("class-pc");
    assert_eq!(checked_host("127.0.0.1:9090", 9090, true, h), Ok("127.0.0.1"));
    assert_eq!(checked_host("LOCALHOST:9090", 9090, true, h), Ok("LOCALHOST"));
    assert_eq!(checked_host("[::1]:9090", 9090, true, h), Ok("[::1]"));
    assert_eq!(checked_host("192.168.1.5:9090", 9090, false, h), Ok("192.168.1.5"));
    assert_eq!(checked_host("class-pc:9090", 9090, false, h), Ok("class-pc"));
    assert_eq!(checked_host("[fe80::1]:9090", 9090, false, h), Ok("[fe80::1]"));
    assert_eq!(checked_host("127.0.0.1", 80, true, h), Ok("127.0.0.1"));
    for (bad, loopback_only) in [
        ("192.168.1.5:9090", true),
        ("class-pc:9090", true),
        ("evil.example:9090", false),
        ("127.0.0.1.nip.io:9090", false),
        ("127.0.0.1:9091", false),
        ("127.0.0.1", false),
        ("127.0.0.1:+9090", false),
        ("127.0.0.1:9090:9090", false),
        ("[::1:9090", false),
        ("::1:9090", false),
        ("", false),
    ] {
        assert!(checked_host(bad, 9090, loopback_only, h).is_err(), "{bad} accepted");
    }
}

#[test]
fn oversized_bodies_are_refused_however_they_come() {
    let (p, path) = page(None, "oversize");
    let before = std::fs::read(&path).expect("config");
    let (code, answer) = request(&p.url, "POST", "/set", &[], &[b' '; 2 * MAX_BODY]);
    assert_eq!(code, 413, "{answer}");
    // Chunked: no length declared, cut at the limit.
    let mut s = TcpStream::connect(authority(&p.url)).expect("connects");
    s.set_read_timeout(Some(Duration::from_secs(5))).ok();
    let chunk = " ".repeat(MAX_BODY);
    let head = format!(
        "POST /set HTTP/1.1\r\nHost: {}\r\nContent-Type: application/json\r\nTransfer-Encoding: chunked\r\n\r\n",
        authority(&p.url)
    );
    s.write_all(format!("{head}{:x}\r\n{chunk}\r\n{:x}\r\n{chunk}\r\n0\r\n\r\n", chunk.len(), chunk.len()).as_bytes())
        .expect("writes");
    let mut out = String::new();
    s.read_to_string(&mut out).ok();
    assert!(out.starts_with("HTTP/1.1 413"), "{out}");
    assert_eq!(std::fs::read(&path).expect("config"), before);
}

#[test]
fn a_stalled_request_head_delays_no_one_and_is_cut() {
    let (p, _) = page(None, "stall-head");
    let opened = Instant::now();
    let mut s = stalled(&p.url, &format!("GET /controls HTTP/1.1\r\nHost: {}\r\n", authority(&p.url)));
    others_served_promptly(&p.url, Duration::from_millis(1500), "a stalled head");
    let (_, closed) = until_closed(&mut s, opened, HEADER_TIMEOUT + Duration::from_secs(2));
    assert!(closed.is_some_and(|t| t >= HEADER_TIMEOUT - Duration::from_millis(200)), "cut after {closed:?}");
}

#[test]
fn slowloris_delays_no_one_and_is_cut() {
    // One byte every 500 ms, in the head and in a body.
    let (p, path) = page(None, "slowloris");
    let before = std::fs::read(&path).expect("config");
    let opened = Instant::now();
    let mut head = trickled(
        &p.url,
        &format!("GET /controls HTTP/1.1\r\nHost: {}\r\nX-Padding: {}\r\n\r\n", authority(&p.url), "x".repeat(40)),
    );
    let body = "{\"control\": 0, \"value\": 1}";
    let mut slow_body = stalled(
        &p.url,
        &format!(
            "POST /set HTTP/1.1\r\nHost: {}\r\nContent-Type: application/json\r\nContent-Length: {}\r\n\r\n",
            authority(&p.url),
            body.len()
        ),
    );
    let mut writer = slow_body.try_clone().expect("clone");
    let bytes = body.as_bytes().to_vec();
    std::thread::spawn(move || {
        for b in bytes {
            if writer.write_all(&[b]).is_err() {
                return;
            }
            std::thread::sleep(Duration::from_millis(500));
        }
    });
    others_served_promptly(&p.url, Duration::from_millis(1500), "slowloris");
    let (_, closed) = until_closed(&mut head, opened, HEADER_TIMEOUT + Duration::from_secs(2));
    assert!(closed.is_some(), "a head sent a byte every 500 ms is still read after {:?}", opened.elapsed());
    let (answer, closed) = until_closed(&mut slow_body, opened, BODY_TIMEOUT + Duration::from_secs(2));
    assert!(closed.is_some() && answer.starts_with("HTTP/1.1 408"), "{closed:?}: {answer}");
    assert_eq!(std::fs::read(&path).expect("config"), before);
}

#[test]
fn a_chunked_body_cut_short_delays_no_one() {
    let (p, path) = page(None, "chunked");
    let before = std::fs::read(&path).expect("config");
    let opened = Instant::now();
    let mut s = stalled(
        &p.url,
        &format!(
            "POST /set HTTP/1.1\r\nHost: {}\r\nContent-Type: application/json\r\nTransfer-Encoding: chunked\r\n\r\n20\r\n{{\"control\": 0,",
            authority(&p.url)
        ),
    );
    others_served_promptly(&p.url, Duration::from_millis(1500), "a partial chunk");
    let (answer, closed) = until_closed(&mut s, opened, BODY_TIMEOUT + Duration::from_secs(2));
    assert!(closed.is_some() && answer.starts_with("HTTP/1.1 408"), "{closed:?}: {answer}");
    assert_eq!(std::fs::read(&path).expect("config"), before);
}

#[test]
fn expect_100_continue_without_a_body_delays_no_one() {
    let (p, path) = page(None, "expect");
    let before = std::fs::read(&path).expect("config");
    let opened = Instant::now();
    let mut s = stalled(
        &p.url,
        &format!(
            "POST /set HTTP/1.1\r\nHost: {}\r\nContent-Type: application/json\r\nExpect: 100-continue\r\nContent-Length: 100\r\n\r\n",
            authority(&p.url)
        ),
    );
    others_served_promptly(&p.url, Duration::from_millis(1500), "Expect: 100-continue, no body");
    let (answer, closed) = until_closed(&mut s, opened, BODY_TIMEOUT + Duration::from_secs(2));
    assert!(
        closed.is_some() && answer.starts_with("HTTP/1.1 100 Continue") && answer.contains("HTTP/1.1 408"),
        "{closed:?}: {answer}"
    );
    assert_eq!(std::fs::read(&path).expect("config"), before);
}

#[test]
fn fifty_clients_at_once_are_all_answered() {
    let (p, _) = page(None, "fifty");
    let start = Arc::new(std::sync::Barrier::new(50));
    let clients: Vec<_> = (0..50)
        .map(|_| {
            let (url, start) = (p.url.clone(), start.clone());
            std::thread::spawn(move || {
                start.wait();
                request(&url, "GET", "/controls", &[], b"").0
            })
        })
        .collect();
    let codes: Vec<u16> = clients.into_iter().map(|c| c.join().expect("client")).collect();
    assert!(codes.iter().all(|c| *c == 200), "{codes:?}");
}

#[test]
fn beyond_the_connection_limit_a_new_connection_is_closed_at_once() {
    let (p, _) = page(None, "limit");
    let opened = Instant::now();
    let silent: Vec<TcpStream> =
        (0..MAX_CONNECTIONS).map(|_| TcpStream::connect(authority(&p.url)).expect("connects")).collect();
    let mut one_more = TcpStream::connect(authority(&p.url)).expect("connects");
    let (_, closed) = until_closed(&mut one_more, Instant::now(), PROMPT);
    assert!(opened.elapsed() < HEADER_TIMEOUT, "too slow to tell ({:?})", opened.elapsed());
    assert!(closed.is_some(), "connection {} still open", MAX_CONNECTIONS + 1);
    // The silent ones are cut by the header timeout; then the page answers again.
    std::thread::sleep(HEADER_TIMEOUT + Duration::from_millis(500));
    assert_eq!(request(&p.url, "GET", "/controls", &[], b"").0, 200);
    drop(silent);
}

#[test]
fn a_kept_alive_connection_with_no_new_request_is_closed() {
    // hyper's header timer runs while a kept-alive connection waits for its next request, so it
    // is closed after HEADER_TIMEOUT (well within IDLE_TIMEOUT; the page polls every second).
    let (p, _) = page(None, "idle");
    let mut s = TcpStream::connect(authority(&p.url)).expect("connects");
    s.write_all(format!("GET /controls HTTP/1.1\r\nHost: {}\r\n\r\n", authority(&p.url)).as_bytes()).expect("writes");
    let answered = Instant::now();
    let (answer, closed) = until_closed(&mut s, answered, IDLE_TIMEOUT + Duration::from_secs(2));
    assert!(answer.starts_with("HTTP/1.1 200"), "{answer}");
    assert!(closed.is_some_and(|t| t <= HEADER_TIMEOUT + PROMPT), "closed after {closed:?}");
}

#[test]
fn dropping_the_page_during_stalls_returns_at_once() {
    let (p, _) = page(None, "drop");
    let url = p.url.clone();
    let to = authority(&url);
    let _stalls = [
        stalled(&url, "GET / HTTP/1.1\r\nHost: x"),
        stalled(
            &url,
            &format!(
                "POST /set HTTP/1.1\r\nHost: {to}\r\nContent-Type: application/json\r\nTransfer-Encoding: chunked\r\n\r\n20\r\n{{"
            ),
        ),
        stalled(
            &url,
            &format!(
                "POST /set HTTP/1.1\r\nHost: {to}\r\nContent-Type: application/json\r\nExpect: 100-continue\r\nContent-Length: 100\r\n\r\n"
            ),
        ),
    ];
    // Let the server take them up (the body waits have begun).
    std::thread::sleep(Duration::from_millis(300));
    let t = Instant::now();
    drop(p);
    assert!(t.elapsed() < PROMPT, "dropping the page took {:?}", t.elapsed());
    assert!(TcpStream::connect(to).is_err(), "still listening after the drop");
}

#[test]
fn every_address_serves_the_viewer_on_the_host_the_browser_asked_for() {
    // --bind 0.0.0.0, reached from "another machine": a second loopback address (Linux routes all
    // of 127/8 to lo), named in the Host as a browser there would.
    let (p, path) = page_on("0.0.0.0:0", Some("s3cret"), "every-address");
    let before = std::fs::read(&path).expect("config");
    let port = port(&p.url);
    let there = format!("127.0.0.2:{port}");
    let (code, html) = request_to(&there, "GET", "/", &[], b"");
    let viewer = format!(
        "http://127.0.0.2:{}/?url=rerun%2Bhttp%3A%2F%2F127.0.0.2%3A{}%2Fproxy&amp;theme=dark",
        port + 1,
        port + 2
    );
    assert!(code == 200 && html.contains(&viewer), "{code}: no {viewer} in {html}");
    assert_eq!(p.url_at("127.0.0.2"), format!("http://127.0.0.2:{port}/?token=s3cret"));
    let inner = control(&format!("http://{there}/"), "inner swing half-angle");
    let change = format!("{{\"control\": {inner}, \"value\": 450}}");
    let origin = format!("http://{there}");
    let (code, answer) = request_to(&there, "POST", "/set", &[("Origin", &origin)], change.as_bytes());
    assert_eq!(code, 403, "without the token: {answer}");
    assert_eq!(request_to(&there, "GET", "/", &[("Host", &format!("evil.example:{port}"))], b"").0, 403);
    assert_eq!(std::fs::read(&path).expect("config"), before, "a refused change changed the file");
    // This machine's name is one of its names here.
    if let Some(h) = address::this_hostname() {
        let (code, html) = request_to(&there, "GET", "/", &[("Host", &format!("{h}:{port}"))], b"");
        assert!(code == 200 && html.contains(&format!("http://{h}:{}/", port + 1)), "{code}: {html}");
    }
    let (code, answer) =
        request_to(&there, "POST", "/set", &[("Origin", &origin), ("X-Rinscope-Token", "s3cret")], change.as_bytes());
    assert_eq!(code, 200, "with the token: {answer}");
    assert_ne!(std::fs::read(&path).expect("config"), before);
}

#[test]
fn a_flood_of_changes_is_refused_beyond_the_rate() {
    let (p, path) = page(None, "flood");
    let inner = control(&p.url, "inner swing half-angle");
    let codes: Vec<u16> = (0..3 * MAX_CHANGES_PER_S)
        .map(|i| {
            request(
                &p.url,
                "POST",
                "/set",
                &[],
                format!("{{\"control\": {inner}, \"value\": {}}}", 10 * (i % 50)).as_bytes(),
            )
            .0
        })
        .collect();
    assert!(
        codes.contains(&429) && codes.iter().filter(|c| **c == 200).count() as u32 >= MAX_CHANGES_PER_S / 2,
        "{codes:?}"
    );
    assert!(
        scenario::parse(&std::fs::read_to_string(&path).expect("config"), "flooded").is_ok(),
        "the file stays a valid scenario"
    );
}
