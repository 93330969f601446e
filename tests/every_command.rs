//! One stop rule for every command (issue 31): a signal in any phase — simulating, estimating,
//! navigating, drawing figures — ends the command within seconds with 128 + the signal, says it
//! was interrupted, leaves no `.partial`, and a document it still writes says `interrupted: true`.
//! A table of commands, each run long enough to be caught in the phase named, times SIGINT and
//! SIGTERM.

mod common;
use common::{rinscope, scratch, stderr};
use std::path::Path;
use std::process::Stdio;
use std::time::{Duration, Instant};

/// A command caught in one phase: its arguments (`{dir}` is the case's scratch folder), the
/// document it writes (if any), and what must exist before the signal is sent (the phase has begun).
struct Case {
    name: &'static str,
    args: &'static [&'static str],
    document: Option<&'static str>,
    /// The document must carry `"interrupted": true` (commands whose document describes a partial run).
    says_interrupted: bool,
    /// Wait for this file (relative to the scratch folder) before signalling; else wait `after`.
    begun: Option<&'static str>,
    after: Duration,
}

const CASES: &[Case] = &[
    Case {
        name: "run-simulating",
        args: &["run", "--duration-s", "2000000", "--save", "{dir}/r.rrd", "--summary-json", "{dir}/r.json"],
        document: Some("r.json"),
        says_interrupted: true,
        begun: None,
        after: Duration::from_millis(1500),
    },
    Case {
        name: "run-drawing",
        args: &[
            "run",
            "--scenario",
            "rotation-modulation-16-position",
            "--save",
            "{dir}/r.rrd",
            "--figures",
            "{dir}/fig",
        ],
        document: None,
        says_interrupted: false,
        begun: Some("fig/01"),
        after: Duration::ZERO,
    },
    Case {
        name: "allan-simulating",
        args: &["allan", "--duration-s", "2000000", "--decimate", "100", "--no-recording", "--json", "{dir}/a.json"],
        document: Some("a.json"),
        says_interrupted: true,
        begun: None,
        after: Duration::from_millis(1500),
    },
    Case {
        name: "modulation",
        args: &["modulation", "--hours", "720", "--save", "{dir}/m.rrd"],
        document: None,
        says_interrupted: false,
        begun: None,
        after: Duration::from_millis(1500),
    },
    Case {
        name: "budget",
        args: &["budget", "--hours", "720", "--save", "{dir}/b.rrd", "--json", "{dir}/b.json"],
        document: Some("b.json"),
        says_interrupted: true,
        begun: None,
        after: Duration::from_millis(1500),
    },
    Case {
        name: "schemes",
        args: &["schemes", "--hours", "720", "--seeds", "2", "--save", "{dir}/x.rrd", "--json", "{dir}/x.json"],
        document: Some("x.json"),
        says_interrupted: true,
        begun: None,
        after: Duration::from_millis(1500),
    },
    Case {
        name: "design",
        args: &[
            "design",
            "--hours",
            "720",
            "--candidates",
            "50",
            "--seeds",
            "1",
            "--save",
            "{dir}/d.rrd",
            "--json",
            "{dir}/d.json",
        ],
        document: Some("d.json"),
        says_interrupted: true,
        begun: None,
        after: Duration::from_millis(1500),
    },
    Case {
        name: "selfcal-navigating",
        args: &["selfcal", "--navigate-hours", "720", "--save", "{dir}/s.rrd", "--json", "{dir}/s.json"],
        document: Some("s.json"),
        says_interrupted: false,
        begun: None,
        after: Duration::from_millis(2500),
    },
    Case {
        name: "selfcal-shard-estimating",
        args: &["selfcal", "--monte-carlo", "10000", "--shard", "1/4", "--no-recording", "--json", "{dir}/sh.json"],
        document: None,
        says_interrupted: false,
        begun: None,
        after: Duration::from_millis(1500),
    },
    Case {
        name: "sweep",
        args: &["sweep", "--scenario", "rotation-modulation-16-position", "--seeds", "64", "--json", "{dir}/sw.json"],
        document: Some("sw.json"),
        says_interrupted: true,
        begun: None,
        after: Duration::from_millis(1500),
    },
    Case {
        name: "montecarlo",
        args: &["montecarlo", "--runs", "100000", "--json", "{dir}/mc.json"],
        document: Some("mc.json"),
        says_interrupted: false,
        begun: None,
        after: Duration::from_millis(1500),
    },
    Case {
        name: "reproduce",
        args: &["reproduce", "--markdown", "{dir}/r.md"],
        document: None,
        says_interrupted: false,
        begun: None,
        after: Duration::from_millis(1500),
    },
    Case {
        name: "bench",
        args: &["bench", "--steps", "1000000000", "--json", "{dir}/b.json"],
        document: None,
        says_interrupted: false,
        begun: None,
        after: Duration::from_millis(1500),
    },
    Case {
        name: "tpr-sweeping",
        args: &["tpr", "--seeds", "500", "--save", "{dir}/t.rrd", "--json", "{dir}/t.json"],
        document: Some("t.json"),
        says_interrupted: false,
        begun: Some("t.json"),
        after: Duration::from_millis(300),
    },
];

fn partials(dir: &Path) -> Vec<String> {
    let mut found = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).into_iter().flatten().flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else if p.to_string_lossy().contains(".partial") {
                found.push(p.display().to_string());
            }
        }
    }
    found
}

/// The first file under `dir` whose path relative to it starts with `prefix`.
fn exists_with_prefix(dir: &Path, prefix: &str) -> bool {
    let (folder, stem) = match prefix.rsplit_once('/') {
        Some((f, s)) => (dir.join(f), s),
        None => (dir.to_path_buf(), prefix),
    };
    std::fs::read_dir(folder).into_iter().flatten().flatten().any(|e| {
        e.file_name().to_string_lossy().starts_with(stem) && !e.file_name().to_string_lossy().contains(".partial")
    })
}

#[test]
fn every_command_stopped_in_any_phase_exits_128_plus_the_signal_and_says_so() {
    let mut failures = Vec::new();
    for case in CASES {
        for (signal, code) in [(libc_signal::SIGINT, 130), (libc_signal::SIGTERM, 143)] {
            let dir = scratch(&format!("{}-{signal}", case.name));
            let args: Vec<String> = case.args.iter().map(|a| a.replace("{dir}", &dir.display().to_string())).collect();
            let mut child = rinscope()
                .args(&args)
                .current_dir(&dir)
                .stdout(Stdio::null())
                .stderr(Stdio::piped())
                .spawn()
                .expect("spawns");
            let started = Instant::now();
            if let Some(prefix) = case.begun {
                while !exists_with_prefix(&dir, prefix)
                    && started.elapsed() < Duration::from_secs(120)
                    && child.try_wait().expect("wait").is_none()
                {
                    std::thread::sleep(Duration::from_millis(20));
                }
            }
            std::thread::sleep(case.after);
            if child.try_wait().expect("wait").is_some() {
                failures.push(format!(
                    "{} ({signal}): ended before the signal ({:.1} s): the case is too short to test",
                    case.name,
                    started.elapsed().as_secs_f64()
                ));
                continue;
            }
            let signalled = Instant::now();
            assert!(
                std::process::Command::new("kill")
                    .arg(format!("-{signal}"))
                    .arg(child.id().to_string())
                    .status()
                    .expect("kill")
                    .success()
            );
            let out = loop {
                if child.try_wait().expect("wait").is_some() || signalled.elapsed() > Duration::from_secs(20) {
                    child.kill().ok();
                    break child.wait_with_output().expect("output");
                }
                std::thread::sleep(Duration::from_millis(20));
            };
            let took = signalled.elapsed().as_secs_f64();
            let err = stderr(&out);
            let mut wrong = Vec::new();
            if out.status.code() != Some(code) {
                wrong.push(format!("exit {:?}, not {code}", out.status.code()));
            }
            if took > 3.0 {
                wrong.push(format!("ended {took:.1} s after the signal"));
            }
            if !err.contains("interrupted") {
                wrong.push("no \"interrupted\" on stderr".to_owned());
            }
            let left = partials(&dir);
            if !left.is_empty() {
                wrong.push(format!("left {left:?}"));
            }
            if let Some(doc) = case.document {
                match std::fs::read_to_string(dir.join(doc)) {
                    Ok(text) => {
                        let v: serde_json::Value = serde_json::from_str(&text).unwrap_or_default();
                        if case.says_interrupted && v.get("interrupted") != Some(&serde_json::Value::Bool(true)) {
                            wrong.push(format!("{doc} lacks \"interrupted\": true"));
                        }
                        if v.get("interrupted") == Some(&serde_json::Value::Bool(false)) {
                            wrong.push(format!("{doc} says \"interrupted\": false"));
                        }
                    }
                    Err(_) if case.says_interrupted => wrong.push(format!("{doc} not written")),
                    Err(_) => {}
                }
            }
            if !wrong.is_empty() {
                failures.push(format!(
                    "{} ({signal}): {}\n  stderr: {}",
                    case.name,
                    wrong.join("; "),
                    err.lines().rev().take(3).collect::<Vec<_>>().join(" | ")
                ));
            }
            std::fs::remove_dir_all(&dir).ok();
        }
    }
    assert!(failures.is_empty(), "{} of {} cases:\n{}", failures.len(), 2 * CASES.len(), failures.join("\n"));
}

/// The signal names `kill` takes.
mod libc_signal {
    pub const SIGINT: &str = "INT";
    pub const SIGTERM: &str = "TERM";
}
