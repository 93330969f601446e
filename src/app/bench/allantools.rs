//! `rinscope bench --peer allantools`: `rinscope allan --series` against allantools (the Python
//! package Stable32 users reach for), the same estimator on the same τ set of the same series,
//! whole processes alternated (docs/benchmarks.md).
//!
//! The series comes from `assets/bench/allantools/allantools_bench.py make` (numpy, not rinscope).
//! Each round runs, order alternating: `rinscope allan --series S.npy --column 0:frequency
//! --estimator E --taus octave --no-recording --json` (whole process: start, reading the file, the
//! analysis with noise identification and EDF, the JSON), then allantools' `E` on the τ values
//! rinscope evaluated (`allantools_bench.py run`; its process includes numpy's and allantools'
//! imports). Two ratios per round: whole process, and timed region (rinscope's analysis against
//! allantools' call, which favours allantools: its region excludes loading the file, rinscope's
//! includes neither loading nor the start either). The deviations of both are compared point by point.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use anyhow::{Context, anyhow, ensure};
use serde::Serialize;
use serde_json::Value;

use super::peer::Spread;

const SCRIPT: &str = include_str!("../../../assets/bench/allantools/allantools_bench.py");

/// The estimators compared: the default, and the two costlier ones the issue names.
pub const ESTIMATORS: [&str; 3] = ["oadev", "ohdev", "totdev"];

/// Sample rate of the series, Hz (any: both tools take it).
const RATE_HZ: f64 = 100.0;

/// One estimator's comparison.
#[derive(Debug, Clone, Serialize)]
pub struct EstimatorReport {
    /// allantools' name.
    pub estimator: String,
    /// τ values evaluated by both.
    pub taus: usize,
    /// allantools' process time / rinscope's, per round.
    pub process_ratio: Spread,
    /// allantools' timed call / rinscope's analysis, per round.
    pub region_ratio: Spread,
    /// rinscope's whole process, s.
    pub rinscope_process_s: Spread,
    /// allantools' whole process, s.
    pub allantools_process_s: Spread,
    /// Largest |rinscope / allantools − 1| over the τ values.
    pub max_relative_difference: f64,
}

/// Runs the comparison on `samples` samples, `rounds` rounds per estimator.
///
/// # Errors
/// Python or allantools missing, a process that fails, an interruption (`stop`).
pub fn compare(
    python: &Path,
    samples: u64,
    rounds: usize,
    stop: &std::sync::atomic::AtomicBool,
) -> anyhow::Result<Vec<EstimatorReport>> {
    ensure!(rounds >= 1, "--rounds must be at least 1");
    let dir = std::env::temp_dir().join(format!("rinscope-bench-allantools-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    let result = compare_in(&dir, python, samples, rounds, stop);
    std::fs::remove_dir_all(&dir).ok();
    result
}

fn compare_in(
    dir: &Path,
    python: &Path,
    samples: u64,
    rounds: usize,
    stop: &std::sync::atomic::AtomicBool,
) -> anyhow::Result<Vec<EstimatorReport>> {
    let script = dir.join("allantools_bench.py");
    std::fs::write(&script, SCRIPT)?;
    let series = dir.join("series.npy");
    let made = Command::new(python)
        .arg(&script)
        .arg("make")
        .arg(&series)
        .arg(samples.to_string())
        .arg("952")
        .output()
        .with_context(|| format!("running {}", python.display()))?;
    ensure!(made.status.success(), "making the series failed: {}", String::from_utf8_lossy(&made.stderr));
    let mut reports = Vec::new();
    for est in ESTIMATORS {
        let (mut proc_r, mut region_r, mut ours, mut theirs, mut diff, mut taus) =
            (vec![], vec![], vec![], vec![], 0.0f64, 0);
        for round in 0..rounds {
            ensure!(!stop.load(std::sync::atomic::Ordering::SeqCst), "interrupted");
            let run_ours = || run_rinscope(dir, &series, est);
            let (mine, peer) = if round % 2 == 0 {
                let m = run_ours()?;
                let p = run_allantools(python, &script, &series, est, &m.taus_json)?;
                (m, p)
            } else {
                // allantools first needs the τ list: take it from the previous round.
                let taus_json = dir.join(format!("{est}-taus.json"));
                let p = run_allantools(python, &script, &series, est, &taus_json)?;
                (run_ours()?, p)
            };
            ensure!(
                mine.devs.len() == peer.devs.len(),
                "{est}: rinscope evaluated {} τ, allantools returned {}",
                mine.devs.len(),
                peer.devs.len()
            );
            taus = mine.devs.len();
            for (a, b) in mine.devs.iter().zip(&peer.devs) {
                diff = diff.max((a / b - 1.0).abs());
            }
            proc_r.push(peer.process_s / mine.process_s);
            region_r.push(peer.region_s / mine.region_s.max(1e-6));
            ours.push(mine.process_s);
            theirs.push(peer.process_s);
        }
        reports.push(EstimatorReport {
            estimator: est.to_owned(),
            taus,
            process_ratio: Spread::of(proc_r),
            region_ratio: Spread::of(region_r),
            rinscope_process_s: Spread::of(ours),
            allantools_process_s: Spread::of(theirs),
            max_relative_difference: diff,
        });
    }
    Ok(reports)
}

struct Run {
    process_s: f64,
    region_s: f64,
    devs: Vec<f64>,
    taus_json: PathBuf,
}

fn run_rinscope(dir: &Path, series: &Path, est: &str) -> anyhow::Result<Run> {
    let json = dir.join(format!("{est}.json"));
    let started = Instant::now();
    let out = Command::new(std::env::current_exe()?)
        .args(["allan", "--series"])
        .arg(series)
        .args([
            "--column",
            "0:frequency",
            "--rate-hz",
            &RATE_HZ.to_string(),
            "--estimator",
            est,
            "--taus",
            "octave",
            "--no-recording",
            "--json",
        ])
        .arg(&json)
        .output()?;
    let process_s = started.elapsed().as_secs_f64();
    ensure!(out.status.success(), "rinscope allan failed: {}", String::from_utf8_lossy(&out.stderr));
    let v: Value = serde_json::from_str(&std::fs::read_to_string(&json)?)?;
    let curve = &v["clock"][0]["curves"][0];
    let list = |k: &str| -> anyhow::Result<Vec<f64>> {
        curve[k]
            .as_array()
            .ok_or_else(|| anyhow!("no {k} in rinscope's JSON"))?
            .iter()
            .map(|x| x.as_f64().ok_or_else(|| anyhow!("{k}: not a number")))
            .collect()
    };
    let taus = list("tau_s")?;
    let taus_json = dir.join(format!("{est}-taus.json"));
    std::fs::write(&taus_json, serde_json::to_string(&taus)?)?;
    let region_s = v["analysis_s"].as_f64().ok_or_else(|| anyhow!("no analysis_s in rinscope's JSON"))?;
    Ok(Run { process_s, region_s, devs: list("dev_frac")?, taus_json })
}

fn run_allantools(python: &Path, script: &Path, series: &Path, est: &str, taus_json: &Path) -> anyhow::Result<Run> {
    let started = Instant::now();
    let out = Command::new(python)
        .arg(script)
        .arg("run")
        .arg(series)
        .arg(RATE_HZ.to_string())
        .arg(est)
        .arg(taus_json)
        .output()?;
    let process_s = started.elapsed().as_secs_f64();
    ensure!(
        out.status.success(),
        "allantools {est} failed (pip install allantools==2024.6?): {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: Value = serde_json::from_str(String::from_utf8_lossy(&out.stdout).lines().last().unwrap_or_default())
        .context("allantools_bench.py's output")?;
    let devs = v["dev"].as_array().ok_or_else(|| anyhow!("no dev"))?.iter().filter_map(Value::as_f64).collect();
    Ok(Run {
        process_s,
        region_s: v["seconds"].as_f64().ok_or_else(|| anyhow!("no seconds"))?,
        devs,
        taus_json: taus_json.to_owned(),
    })
}

/// The comparison as text.
#[must_use]
pub fn text(reports: &[EstimatorReport], samples: u64) -> String {
    let mut s = format!(
        "rinscope allan --series vs allantools, one channel of {samples} samples, octave τ set (the same τ values), median (range) over rounds:\n"
    );
    s += "estimator  τ    whole process: rinscope s  allantools s  ratio            timed region ratio   largest deviation difference\n";
    for r in reports {
        s += &format!(
            "{:<10} {:<4} {:<26} {:<13} {:<16} {:<20} {:.1e}\n",
            r.estimator,
            r.taus,
            format!("{:.3}", r.rinscope_process_s.median),
            format!("{:.3}", r.allantools_process_s.median),
            format!("{:.1}× ({:.1}-{:.1})", r.process_ratio.median, r.process_ratio.min, r.process_ratio.max),
            format!("{:.1}× ({:.1}-{:.1})", r.region_ratio.median, r.region_ratio.min, r.region_ratio.max),
            r.max_relative_difference
        );
    }
    s
}
