//! A class watching `rinscope live --serve-web`, with the real binary on loopback: the coning lesson
//! driven from the class page (the cone changed twice, read back from the saved session), a
//! stalled client that must not hold up a signal, and the exit codes of a session ended by one.

mod common;
use common::{rinscope, scratch};
use std::io::{Read, Write};
use std::net::{TcpListener, TcpStream};
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use rinscope::record::read::{events, plots, point_labels};

/// Three consecutive free ports on 127.0.0.1 (the page, the viewer, its stream), never the same
/// for two tests of this process (they run at once).
fn free_ports() -> u16 {
    use std::sync::atomic::{AtomicU16, Ordering};
    static NEXT: AtomicU16 = AtomicU16::new(0);
    let start = 21000 + (std::process::id() % 500) as u16 * 60;
    loop {
        let base = start + NEXT.fetch_add(7, Ordering::SeqCst);
        let held: Vec<_> = (0..3).map_while(|k| TcpListener::bind(("127.0.0.1", base + k)).ok()).collect();
        if held.len() == 3 {
            return base;
        }
    }
}

/// A session started in `dir`, its stderr collected.
struct Session {
    child: Child,
    stderr: Arc<Mutex<String>>,
    port: u16,
}

impl Session {
    fn start(dir: &Path, args: &[&str]) -> Self {
        let port = free_ports();
        let mut child = rinscope()
            .current_dir(dir)
            .args(["live", "--no-panel", "--serve-web", &port.to_string()])
            .args(args)
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .expect("starts");
        let stderr = Arc::new(Mutex::new(String::new()));
        let mut pipe = child.stderr.take().expect("stderr");
        let sink = stderr.clone();
        std::thread::spawn(move || {
            let mut buf = [0u8; 4096];
            while let Ok(n) = pipe.read(&mut buf) {
                if n == 0 {
                    break;
                }
                sink.lock().expect("lock").push_str(&String::from_utf8_lossy(&buf[..n]));
            }
        });
        let me = Self { child, stderr, port };
        let started = Instant::now();
        while !me.said("the class page") {
            assert!(started.elapsed() < Duration::from_secs(20), "no class page: {}", me.log());
            std::thread::sleep(Duration::from_millis(50));
        }
        me
    }

    fn log(&self) -> String {
        self.stderr.lock().expect("lock").clone()
    }

    fn said(&self, what: &str) -> bool {
        self.log().contains(what)
    }

    /// One request to the class page; the status code and the body.
    fn request(&self, method: &str, path: &str, body: &str) -> (u16, String) {
        let mut s = TcpStream::connect(("127.0.0.1", self.port)).expect("connects");
        s.set_read_timeout(Some(Duration::from_secs(5))).ok();
        let head = format!(
            "{method} {path} HTTP/1.1\r\nHost: 127.0.0.1:{}\r\nConnection: close\r\nContent-Type: application/json\r\nContent-Length: {}\r\n\r\n{body}",
            self.port,
            body.len()
        );
        s.write_all(head.as_bytes()).expect("writes");
        let mut out = Vec::new();
        s.read_to_end(&mut out).ok();
        let text = String::from_utf8_lossy(&out).into_owned();
        let code = text.split_whitespace().nth(1).and_then(|c| c.parse().ok()).unwrap_or(0);
        (code, text.split("\r\n\r\n").nth(1).unwrap_or_default().to_owned())
    }

    fn controls(&self) -> serde_json::Value {
        let (code, body) = self.request("GET", "/controls", "");
        assert_eq!(code, 200, "{body}");
        serde_json::from_str(&body).expect("json")
    }

    /// The number of the control labelled `label`.
    fn control(&self, label: &str) -> u64 {
        let c = self.controls();
        c["controls"]
            .as_array()
            .expect("controls")
            .iter()
            .find(|x| x["label"] == label)
            .and_then(|x| x["id"].as_u64())
            .unwrap_or_else(|| panic!("no control {label}: {c}"))
    }

    fn wait_for_sim_time(&self, t_s: f64) {
        let started = Instant::now();
        while self.controls()["sim_t_s"].as_f64().unwrap_or(0.0) < t_s {
            assert!(
                started.elapsed() < Duration::from_secs(60),
                "the session did not reach t = {t_s} s: {}",
                self.log()
            );
            std::thread::sleep(Duration::from_millis(50));
        }
    }

    fn set(&self, label: &str, value: f64) {
        let id = self.control(label);
        let (code, body) = self.request("POST", "/set", &format!("{{\"control\": {id}, \"value\": {value}}}"));
        assert_eq!(code, 200, "{label} = {value}: {body}");
    }

    /// Waits for the process to end (at most `limit`); its exit code.
    fn wait(&mut self, limit: Duration) -> i32 {
        let started = Instant::now();
        loop {
            if let Some(status) = self.child.try_wait().expect("wait") {
                return status.code().unwrap_or(-1);
            }
            assert!(started.elapsed() < limit, "still running after {limit:?}: {}", self.log());
            std::thread::sleep(Duration::from_millis(20));
        }
    }
}

impl Drop for Session {
    fn drop(&mut self) {
        self.child.kill().ok();
        self.child.wait().ok();
    }
}

fn signal(child: &Child, sig: &str) {
    let ok = Command::new("kill").args([sig, &child.id().to_string()]).status().expect("kill").success();
    assert!(ok, "kill {sig}");
}

#[test]
fn the_cone_changed_twice_from_the_class_page_goes_on_and_its_labels_and_rates_follow() {
    // Pure coning at 4× real time: at t ≥ 8 s the page sets the half-angle 1° → 2°, at t ≥ 20 s the
    // frequency 5 → 10 Hz; the session ends at 32 s and its saved recording is read back.
    use rinscope::ins::coning::{Algorithm, coning_drift_rate};
    let dir = scratch("coning");
    let rec = dir.join("coning.rrd");
    let mut s = Session::start(
        &dir,
        &["--scenario", "pure-coning", "--speed", "4", "--duration-s", "32", "--save", rec.to_str().expect("utf-8")],
    );
    s.wait_for_sim_time(8.0);
    s.set("cone half-angle", 2.0);
    s.wait_for_sim_time(20.0);
    s.set("cone frequency", 10.0);
    // The session ends at its length; its page stays for the class until Ctrl-C, which then
    // ends a complete session: 0.
    let started = Instant::now();
    while !s.said("the run is complete") {
        assert!(started.elapsed() < Duration::from_secs(60), "{}", s.log());
        std::thread::sleep(Duration::from_millis(50));
    }
    signal(&s.child, "-INT");
    assert_eq!(s.wait(Duration::from_secs(10)), 0, "{}", s.log());

    // The reloads, in words.
    let ev = events(&rec).expect("events");
    let at = |what: &str| {
        ev.iter()
            .find(|e| e.text.contains(what))
            .and_then(|e| e.t_s)
            .unwrap_or_else(|| panic!("no event {what}: {ev:?}"))
    };
    let (t1, t2) = (at("cone half-angle 1° → 2°"), at("cone frequency 5 Hz → 10 Hz"));
    assert!((8.0..12.0).contains(&t1) && (20.0..24.0).contains(&t2), "{t1} {t2}");

    // The 3D label says the cone there is (1° until the first change, then 2°).
    let labels = point_labels(&rec, "world/cone/label").expect("labels");
    let label_at =
        |t: f64| labels.iter().rfind(|(s, _)| s.is_none_or(|s| s <= t)).map(|(_, l)| l.clone()).unwrap_or_default();
    assert!(label_at(t1 - 0.5).contains("1.0000° cone") && label_at(t1 + 0.5).contains("2.0000° cone"), "{labels:?}");

    // The INS heading error of every algorithm goes on without a jump: no row (0.1 s apart) moves by
    // more than 3 rows of the crudest algorithm's drift there is (single-sample, 2° at 10 Hz at 100 Hz:
    // 509″/s); the reload moved it by 3000″ at once.
    let all = plots(&rec).expect("plots");
    let heading = all.iter().find(|p| p.origin == "ins/attitude_error_arcsec/heading").expect("INS heading plot");
    let per_s = coning_drift_rate(Algorithm::SingleSample, 2f64.to_radians(), 10.0, 0.01).abs() * 206_264.806;
    for line in heading.series.iter().filter(|l| l.line) {
        let worst = line
            .t
            .windows(2)
            .zip(line.y.windows(2))
            .filter(|(_, y)| y[0].is_finite() && y[1].is_finite())
            .map(|(t, y)| (y[1] - y[0]).abs() / (3.0 * (t[1] - t[0]) * per_s))
            .fold(0.0, f64::max);
        assert!(worst < 1.0, "{}: a jump of {worst:.2} × the bound", line.name);
    }

    // The analytic drift lines take each new rate from where they stand: their slope between the
    // changes is the analytic rate of the cone then (log10 of arcsec on the plot).
    let log_plot = all.iter().find(|p| p.origin == "ins/coning_drift_log10_arcsec").expect("coning plot");
    let analytic =
        log_plot.series.iter().find(|l| l.name == "single-sample: analytic coning drift").expect("analytic line");
    let value = |t: f64| {
        analytic.t.iter().zip(&analytic.y).find(|(s, _)| **s >= t).map(|(s, y)| (*s, 10f64.powf(*y))).expect("row")
    };
    for (from, to, deg, hz) in
        [(2.0, t1 - 0.5, 1.0_f64, 5.0), (t1 + 0.5, t2 - 0.5, 2.0, 5.0), (t2 + 0.5, 31.0, 2.0, 10.0)]
    {
        let ((ta, a), (tb, b)) = (value(from), value(to));
        let expected = coning_drift_rate(Algorithm::SingleSample, deg.to_radians(), hz, 0.01).abs() * 206_264.806;
        let slope = (b - a) / (tb - ta);
        assert!(
            (slope - expected).abs() < 1e-6 * expected,
            "{deg}° at {hz} Hz: the analytic line grows at {slope}″/s, the rate is {expected}″/s"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_stalled_client_holds_up_neither_the_page_nor_a_signal() {
    // The issue: a POST /set with a partial chunk (or Expect: 100-continue and no body) froze every
    // other client and SIGINT until it went. Now another client is answered, and SIGINT ends the
    // session within a second with 130 and a complete recording.
    let dir = scratch("stall");
    let rec = dir.join("stall.rrd");
    let mut s = Session::start(&dir, &["--scenario", "jiang2017-dual-axis", "--save", rec.to_str().expect("utf-8")]);
    let mut stalls = Vec::new();
    for head in [
        "POST /set HTTP/1.1\r\nHost: 127.0.0.1:{P}\r\nContent-Type: application/json\r\nTransfer-Encoding: chunked\r\n\r\n10\r\n{\"control\"",
        "POST /set HTTP/1.1\r\nHost: 127.0.0.1:{P}\r\nContent-Type: application/json\r\nExpect: 100-continue\r\nContent-Length: 100\r\n\r\n",
        "GET /controls HTTP/1.1\r\nHost: 127.0.0.1:{P}\r\nX-Slow: ",
    ] {
        let mut c = TcpStream::connect(("127.0.0.1", s.port)).expect("connects");
        c.write_all(head.replace("{P}", &s.port.to_string()).as_bytes()).expect("writes");
        stalls.push(c);
    }
    let asked = Instant::now();
    let (code, _) = s.request("GET", "/controls", "");
    assert_eq!(code, 200);
    assert!(asked.elapsed() < Duration::from_secs(1), "another client waited {:?}", asked.elapsed());
    signal(&s.child, "-INT");
    let asked = Instant::now();
    assert_eq!(s.wait(Duration::from_secs(10)), 130, "{}", s.log());
    assert!(asked.elapsed() < Duration::from_secs(1), "SIGINT took {:?} to end the session", asked.elapsed());
    rinscope::record::sink::verify_recording(&rec).expect("a complete recording");
    drop(stalls);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_session_ended_by_sigterm_exits_143_with_a_complete_recording() {
    let dir = scratch("term");
    let rec = dir.join("term.rrd");
    let mut s = Session::start(&dir, &["--scenario", "pure-coning", "--save", rec.to_str().expect("utf-8")]);
    s.wait_for_sim_time(1.0);
    signal(&s.child, "-TERM");
    assert_eq!(s.wait(Duration::from_secs(10)), 143, "{}", s.log());
    assert!(s.said("interrupted"), "{}", s.log());
    rinscope::record::sink::verify_recording(&rec).expect("a complete recording");
    std::fs::remove_dir_all(&dir).ok();
}
