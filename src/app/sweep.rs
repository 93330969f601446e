//! `rinscope sweep`: one scenario run over a grid of parameter values (and seeds), every point a
//! whole `run` (its own exact IMU truth, the INS, the statistics at every update; no recording), the
//! points in parallel on every core (rayon). Each point is the scenario's own file with its keys
//! set, validated before anything runs, so a sweep point is exactly the `run` of that file.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use serde::{Deserialize, Serialize};

use super::failure::Failure;
use super::run::RunSummary;
use crate::app::live::edit::{KeyPath, float, set_in_text};
use crate::calib::montecarlo::Shard;
use crate::scenario::{self, Params};

/// `rinscope sweep`: the scenario, the keys it varies, the seeds at every point.
pub struct SweepRequest {
    /// The scenario (its file as written: the points are edits of it).
    pub params: Params,
    /// `--vary KEY=V1,V2,...`: each key's values; the grid is their product.
    pub vary: Vec<(String, Vec<f64>)>,
    /// Consecutive seeds from the scenario's at every point (1: the scenario's own).
    pub seeds: u64,
    /// Simulated time of every run, s (None: the scenario's).
    pub duration_s: Option<f64>,
    /// Threads (None: every core).
    pub threads: Option<usize>,
    /// `--json`: the report, every point's summary in full.
    pub json: Option<std::path::PathBuf>,
    /// `--shard K/M`: only the runs whose index is K modulo M (a cluster's array job), for `--merge`.
    pub shard: Shard,
}

/// What defines a sweep's runs (shards of one sweep share it).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Grid {
    /// `--vary`: each key's values.
    pub vary: Vec<(String, Vec<f64>)>,
    /// Seeds at every point.
    pub seeds: u64,
    /// The runs' simulated time, s (None: the scenario's).
    pub duration_s: Option<f64>,
}

/// A point of the grid: each varied key's value, in `--vary` order.
pub type Values = Vec<(String, f64)>;

/// One point of the grid and its run.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct SweepPoint {
    /// The run's index in the whole sweep (point-major, then seed).
    pub index: usize,
    /// The varied keys' values, in `--vary` order.
    pub values: Values,
    /// Its seed.
    pub seed: u64,
    /// The run's summary (as `run --summary-json` writes it).
    pub summary: RunSummary,
}

/// What a sweep gives.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct SweepReport {
    /// The scenario's name.
    pub scenario: String,
    /// What defines its runs.
    pub grid: Grid,
    /// The slice of the runs this report holds (the whole sweep: 0/1).
    pub shard: Shard,
    /// Every point run (all of them unless interrupted), in grid order.
    pub points: Vec<SweepPoint>,
    /// Runs in the whole sweep (every shard's).
    pub planned: usize,
    /// Threads used.
    pub threads: usize,
    /// Wall time of the sweep, s.
    pub wall_s: f64,
    /// One run's mean wall time on one thread, s (the sum of the runs' own times over their number).
    pub per_run_s: f64,
    /// Stopped by a signal before every point ran.
    pub interrupted: bool,
}

/// Parses `KEY=V1,V2,...` (values finite numbers; at least one).
///
/// # Errors
/// No `=`, an empty key, a value that is not a finite number.
pub fn parse_vary(text: &str) -> Result<(String, Vec<f64>), String> {
    let (key, values) =
        text.split_once('=').ok_or_else(|| format!("--vary {text:?}: expected KEY=V1,V2,... (a scenario key)"))?;
    let key = key.trim();
    if key.is_empty() {
        return Err(format!("--vary {text:?}: no key before '='"));
    }
    let values: Result<Vec<f64>, String> = values
        .split(',')
        .map(|v| match v.trim().parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(x),
            _ => Err(format!("--vary {key}: {:?} is not a finite number", v.trim())),
        })
        .collect();
    Ok((key.to_owned(), values?))
}

/// The scenario file of every point, in grid order (the first key varies slowest), each parsed
/// and validated: a key the scenario cannot take, or a value out of its range, is an error naming
/// it before anything runs.
///
/// # Errors
/// The scenario cannot be written as a file, a key has no place in it, a point does not validate.
pub fn points(req: &SweepRequest) -> Result<Vec<(Values, Params)>, Failure> {
    let base = toml::to_string(&req.params.written)
        .map_err(|e| Failure::input(format!("sweep: the scenario cannot be written as a file ({e})")))?;
    let mut grid: Vec<Values> = vec![Vec::new()];
    for (key, values) in &req.vary {
        grid = grid
            .into_iter()
            .flat_map(|p| {
                values.iter().map(move |v| {
                    let mut q = p.clone();
                    q.push((key.clone(), *v));
                    q
                })
            })
            .collect();
    }
    let mut out = Vec::with_capacity(grid.len());
    for point in grid {
        let mut text = base.clone();
        for (key, v) in &point {
            text = set_in_text(&text, &KeyPath::parse(key), float(*v))
                .map_err(|e| Failure::input(format!("--vary {key}: {e}")))?;
        }
        let shown = point.iter().map(|(k, v)| format!("{k} = {v}")).collect::<Vec<_>>().join(", ");
        let mut p = scenario::parse(&text, &format!("{} with {shown}", req.params.meta.name))?;
        if let Some(d) = req.duration_s {
            p.set_duration(d);
        }
        out.push((point, p));
    }
    Ok(out)
}

/// Runs every point (and seed) in parallel; a stop skips the runs not yet begun and ends those
/// running at their next look at it.
///
/// # Errors
/// A point that does not validate (before anything runs), a thread pool that cannot start, a run
/// that failed.
pub fn execute(req: &SweepRequest, stop: &AtomicBool) -> Result<SweepReport, Failure> {
    use rayon::prelude::*;
    super::outputs::check_output("--json", req.json.as_deref())?;
    let grid = points(req)?;
    let seeds = req.seeds.max(1);
    let all = grid.len() * seeds as usize;
    let runs: Vec<(usize, u64)> =
        req.shard.indices(all as u64).into_iter().map(|j| ((j / seeds) as usize, j % seeds)).collect();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(req.threads.unwrap_or(0))
        .build()
        .map_err(|e| Failure::run(format!("sweep: no thread pool ({e})")))?;
    let threads = pool.current_num_threads();
    let started = Instant::now();
    let results: Vec<Result<Option<SweepPoint>, String>> = pool.install(|| {
        runs.par_iter()
            .map(|&(i, k)| {
                if stop.load(Ordering::Relaxed) {
                    return Ok(None);
                }
                let (values, params) = &grid[i];
                let mut p = params.clone();
                p.meta.seed = params.meta.seed.wrapping_add(k);
                let sinks = crate::record::sink::open(
                    &crate::record::sink::SinkRequest::default(),
                    crate::record::APPLICATION_ID,
                    &format!("sweep-{i}-{k}"),
                )
                .map_err(|e| e.to_string())?;
                let summary = super::run::run_recorded(&p, &sinks, stop, false).map_err(|e| format!("{e:#}"))?;
                let index = i * seeds as usize + k as usize;
                Ok((!summary.interrupted).then(|| SweepPoint {
                    index,
                    values: values.clone(),
                    seed: p.meta.seed,
                    summary,
                }))
            })
            .collect()
    });
    let wall_s = started.elapsed().as_secs_f64();
    let mut points = Vec::with_capacity(results.len());
    for r in results {
        if let Some(p) = r.map_err(|e| Failure::run(format!("sweep: {e}")))? {
            points.push(p);
        }
    }
    let per_run_s = points.iter().map(|p| p.summary.wall_time_s).sum::<f64>() / points.len().max(1) as f64;
    let report = SweepReport {
        scenario: req.params.meta.name.clone(),
        grid: Grid { vary: req.vary.clone(), seeds, duration_s: req.duration_s },
        shard: req.shard,
        interrupted: points.len() < runs.len(),
        planned: all,
        points,
        threads,
        wall_s,
        per_run_s,
    };
    if let Some(path) = &req.json {
        super::outputs::write_json("--json", path, &report)?;
    }
    Ok(report)
}

impl SweepReport {
    /// The points as a table: the varied values, the seed, then what the scenario measures — the
    /// table's heading error uncompensated and compensated (RMS), the INS's primary algorithm's
    /// (RMS and peak), the navigation's peak drift.
    #[must_use]
    pub fn text(&self) -> String {
        let mut s = String::new();
        let keys: Vec<&str> =
            self.points.first().map(|p| p.values.iter().map(|(k, _)| k.as_str()).collect()).unwrap_or_default();
        for k in &keys {
            s.push_str(&format!("{k:>24} "));
        }
        s.push_str(&format!(
            "{:>8} {:>14} {:>14} {:>14} {:>14} {:>12}\n",
            "seed", "raw table hdg″", "comp. table″", "INS hdg RMS″", "INS hdg pk″", "peak drift m"
        ));
        let cell = |v: Option<f64>, w: usize| v.map_or_else(|| format!("{:>w$}", "—"), |x| format!("{x:>w$.4}"));
        for p in &self.points {
            for (_, v) in &p.values {
                s.push_str(&format!("{v:>24} "));
            }
            let table = |which: &str| {
                p.summary.attitude_error_arcsec.get(which).and_then(|a| a.get("heading")).map(|x| x.rms_arcsec)
            };
            let ins = p
                .summary
                .ins_attitude_error_arcsec
                .as_ref()
                .and_then(|m| m.values().next())
                .and_then(|a| a.get("heading"));
            s.push_str(&format!(
                "{:>8} {} {} {} {} {}\n",
                p.seed,
                cell(table("uncompensated"), 14),
                cell(table("compensated"), 14),
                cell(ins.map(|x| x.rms_arcsec), 14),
                cell(ins.map(|x| x.peak_arcsec), 14),
                cell(p.summary.navigation.as_ref().map(|n| n.peak_radial_m), 12),
            ));
        }
        let per = self.per_run_s;
        s.push_str(&format!(
            "{} runs of {} on {} threads in {:.2} s ({:.3} s per run on one thread){}\n",
            self.points.len(),
            self.scenario,
            self.threads,
            self.wall_s,
            per,
            if self.interrupted {
                ", interrupted: the runs not begun were skipped".to_owned()
            } else if self.shard.count > 1 {
                format!(" (shard {}/{} of {} runs)", self.shard.index, self.shard.count, self.planned)
            } else {
                String::new()
            }
        ));
        // What 1000 such runs cost, from the per-run time measured here, spread evenly.
        let span = |seconds: f64| {
            if seconds < 120.0 { format!("{seconds:.0} s") } else { format!("{:.1} min", seconds / 60.0) }
        };
        s.push_str(&format!(
            "1000 such runs: {} on these {} threads, {} on a 64-core node (the per-run time measured here, spread evenly)\n",
            span(1000.0 * per / self.threads.max(1) as f64),
            self.threads,
            span(1000.0 * per / 64.0)
        ));
        s
    }
}

/// Merges the shards of one sweep (`--shard K/M --json`) into the whole sweep's report: every
/// shard of the same scenario and grid once, every run once, in index order (each run's summary is
/// the one its shard computed: the same numbers as an unsharded sweep's).
///
/// # Errors
/// An unreadable file, shards of different sweeps, a shard missing or given twice, an interrupted
/// shard, an output that cannot be written.
pub fn merge(files: &[std::path::PathBuf], json: Option<&std::path::Path>) -> Result<SweepReport, Failure> {
    super::outputs::check_output("--json", json)?;
    let mut reports = Vec::with_capacity(files.len());
    for f in files {
        let text = super::outputs::read_small_file(f, "--merge")?;
        let r: SweepReport = serde_json::from_str(&text).map_err(|e| {
            Failure::input(format!("--merge {}: not a shard of `rinscope sweep --json` ({e})", f.display()))
        })?;
        reports.push((f, r));
    }
    let Some((_, first)) = reports.first() else { return Err(Failure::input("--merge: no shard files given")) };
    let (scenario, grid, count, planned) =
        (first.scenario.clone(), first.grid.clone(), first.shard.count, first.planned);
    for (f, r) in &reports {
        let bad = |why: String| Failure::input(format!("--merge {}: {why}", f.display()));
        if r.scenario != scenario || r.grid != grid || r.planned != planned || r.shard.count != count {
            return Err(bad(format!(
                "not a shard of the same sweep as {} (scenario, --vary, --seeds, --duration-s and the shard count must agree)",
                files[0].display()
            )));
        }
        if r.interrupted {
            return Err(bad("an interrupted shard: run it again".to_owned()));
        }
    }
    Shard::check_cover(reports.iter().map(|(_, r)| r.shard), count)
        .map_err(|e| Failure::input(format!("--merge: {e}")))?;
    let threads = reports.iter().map(|(_, r)| r.threads).sum();
    let wall_s = reports.iter().map(|(_, r)| r.wall_s).fold(0.0, f64::max);
    let mut points: Vec<SweepPoint> = reports.into_iter().flat_map(|(_, r)| r.points).collect();
    points.sort_by_key(|p| p.index);
    if points.len() != planned || points.iter().enumerate().any(|(i, p)| p.index != i) {
        return Err(Failure::input(format!(
            "--merge: the shards hold {} runs, not each of the sweep's {planned} once",
            points.len()
        )));
    }
    let per_run_s = points.iter().map(|p| p.summary.wall_time_s).sum::<f64>() / points.len().max(1) as f64;
    let report = SweepReport {
        scenario,
        grid,
        shard: Shard::WHOLE,
        points,
        planned,
        threads,
        wall_s,
        per_run_s,
        interrupted: false,
    };
    if let Some(path) = json {
        super::outputs::write_json("--json", path, &report)?;
    }
    Ok(report)
}
