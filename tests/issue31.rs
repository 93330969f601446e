//! Issue 31's defects, end to end through the binary: one number rule (every number on the
//! command line held to its physical range, said short, exit 2; negative numbers reach that rule),
//! one output rule (every output option checked up front), a stop in every phase (figures, the
//! series reader).

mod common;
use common::{rinscope, scratch, stderr};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn refused(args: &[&str], says: &[&str]) {
    let o = rinscope().args(args).output().expect("runs");
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
    for s in says {
        assert!(e.contains(s), "{args:?} should say {s:?}: {e}");
    }
    assert!(e.len() < 600, "short: {e}");
}

fn series(dir: &Path, rows: usize) -> PathBuf {
    let path = dir.join("s.csv");
    let mut text = String::with_capacity(rows * 8 + 8);
    text.push_str("x\n");
    for k in 0..rows {
        text.push_str(if k % 3 == 0 { "0.1\n" } else { "-0.2\n" });
    }
    std::fs::write(&path, text).expect("series");
    path
}

#[test]
fn numbers_on_the_command_line_are_held_to_their_range_and_said_short() {
    let d = scratch("numbers");
    let s = series(&d, 100);
    let s = s.to_str().expect("utf-8");
    // `--rate-hz 1e-308` exited 0 with inf/NaN; 1e308 and --ci-sigma 1e300 printed 300 digits.
    refused(
        &["allan", "--series", s, "--column", "x:rate:deg/s", "--rate-hz", "1e-308", "--no-recording"],
        &["--rate-hz", "1e-308 Hz"],
    );
    refused(
        &["allan", "--series", s, "--column", "x:rate:deg/s", "--rate-hz", "1e308", "--no-recording"],
        &["--rate-hz", "1e308 Hz"],
    );
    refused(
        &[
            "allan",
            "--series",
            s,
            "--column",
            "x:rate:deg/s",
            "--rate-hz",
            "10",
            "--ci-sigma",
            "1e300",
            "--no-recording",
        ],
        &["--ci-sigma", "1e300"],
    );
    // `run --duration-s -10` said "unexpected argument '-1'".
    refused(&["run", "--duration-s", "-10"], &["--duration-s", "-10 s"]);
    refused(&["live", "--no-viewer", "--duration-s", "-1e300"], &["--duration-s", "-1e300 s"]);
    refused(&["modulation", "--hours", "-3"], &["--hours", "-3 h"]);
    refused(&["replay", "--imu", s, "--rate-hz", "-100"], &["--rate-hz", "-100 Hz"]);
    refused(&["replay", "--imu", s, "--from", "-1e300"], &["--from", "-1e300 s"]);
    refused(&["allan", "--decimate", "-5"], &["--decimate", "-5"]);
    refused(&["montecarlo", "--runs", "-1"], &["--runs", "-1"]);
    refused(&["selfcal", "--navigate-hours", "nan"], &["--navigate-hours", "NaN h"]);
    // A good rate still analyses.
    let o = rinscope()
        .args(["allan", "--series", s, "--column", "x:rate:deg/s", "--rate-hz", "100", "--no-recording"])
        .output()
        .expect("runs");
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

#[test]
fn every_output_option_is_checked_before_any_work() {
    let d = scratch("outputs");
    let fifo = d.join("fifo");
    assert!(Command::new("mkfifo").arg(&fifo).status().is_ok_and(|s| s.success()));
    let file = d.join("file.txt");
    std::fs::write(&file, "x").expect("file");
    let (fifo, file) = (fifo.to_str().expect("utf-8"), file.to_str().expect("utf-8"));
    let missing = d.join("missing/fig");
    let missing = missing.to_str().expect("utf-8");
    // Said only "File exists (os error 17)" before, after the whole run.
    for (flag, path, says) in [
        ("--export", fifo, "is a FIFO"),
        ("--figures", fifo, "is a FIFO"),
        ("--export", file, "is a file; give a folder"),
        ("--figures", file, "is a file"),
        ("--figures", missing, "does not exist"),
    ] {
        let started = Instant::now();
        refused(&["run", "--duration-s", "3600", flag, path], &[flag, says]);
        assert!(started.elapsed() < Duration::from_secs(5), "{flag} refused before the run");
    }
    assert!(!d.join("missing").exists(), "no tree created");
}

/// Waits until `dir` holds a file whose name starts with `prefix` (or `limit` passes).
fn wait_for(dir: &Path, prefix: &str, limit: Duration) -> bool {
    let started = Instant::now();
    while started.elapsed() < limit {
        if std::fs::read_dir(dir)
            .is_ok_and(|r| r.flatten().any(|e| e.file_name().to_string_lossy().starts_with(prefix)))
        {
            return true;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    false
}

#[test]
fn sigterm_while_figures_are_drawn_stops_the_drawing() {
    // Issue 31: `replay --figures fig`, SIGTERM once fig/01*.svg existed: every figure drawn, exit 0.
    let d = scratch("figures");
    let fig = d.join("fig");
    let child = rinscope()
        .args(["run", "--scenario", "jiang2017-dual-axis", "--duration-s", "600", "--save"])
        .arg(d.join("r.rrd"))
        .arg("--figures")
        .arg(&fig)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn");
    assert!(wait_for(&fig, "01", Duration::from_secs(120)), "the first figure");
    let signalled = Instant::now();
    assert!(Command::new("kill").args(["-TERM", &child.id().to_string()]).status().expect("kill").success());
    let o = child.wait_with_output().expect("ends");
    let waited = signalled.elapsed();
    assert_eq!(o.status.code(), Some(143), "{}", stderr(&o));
    assert!(waited < Duration::from_secs(2), "stopped in {waited:?}");
    assert!(stderr(&o).contains("interrupted") && stderr(&o).contains("--figures"), "{}", stderr(&o));
    let names: Vec<String> =
        std::fs::read_dir(&fig).expect("fig").flatten().map(|e| e.file_name().to_string_lossy().into_owned()).collect();
    assert!(names.iter().all(|n| !n.ends_with(".partial")), "no partial: {names:?}");
    assert!(d.join("r.rrd").exists(), "the recording is kept");
}

#[test]
fn sigterm_while_a_series_is_read_ends_the_reading_and_says_interrupted() {
    // Issue 31: `allan --series` read a whole 20 M-row file after SIGTERM (4.6 s) and wrote
    // "interrupted": false.
    let d = scratch("series");
    let s = series(&d, 10_000_000);
    let json = d.join("a.json");
    let mut child = rinscope()
        .args(["allan", "--series"])
        .arg(&s)
        .args(["--column", "x:rate:deg/s", "--rate-hz", "100", "--no-recording", "--json"])
        .arg(&json)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn");
    // "rinscope: reading FILE ..." is said just before the reading starts.
    let mut err = std::io::BufReader::new(child.stderr.take().expect("stderr"));
    let mut first = String::new();
    std::io::BufRead::read_line(&mut err, &mut first).expect("a line");
    assert!(first.contains("reading"), "{first}");
    std::thread::sleep(Duration::from_millis(300));
    let signalled = Instant::now();
    assert!(Command::new("kill").args(["-TERM", &child.id().to_string()]).status().expect("kill").success());
    let mut rest = String::new();
    std::io::Read::read_to_string(&mut err, &mut rest).expect("stderr");
    let status = child.wait().expect("ends");
    let waited = signalled.elapsed();
    assert_eq!(status.code(), Some(143), "{rest}");
    assert!(waited < Duration::from_secs(1), "stopped in {waited:?} (a whole 10 M-row read takes ~2 s)");
    let text = std::fs::read_to_string(&json).expect("the analysis of the rows read is written");
    assert!(text.contains("\"interrupted\": true"), "{}", &text[..text.len().min(2000)]);
}
