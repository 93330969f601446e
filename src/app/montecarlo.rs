//! `montecarlo`'s one owner: Jiang et al. 2017's Monte Carlo (Tables 2-3), whole or one shard of
//! it (a cluster's array task), and the merge of the shards' files.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

use super::calibrate::{monte_carlo_runs, monte_carlo_setup};
use super::failure::Failure;
use super::outputs::{check_output, read_small_file, write_json};
use crate::calib::montecarlo::{self, RunErrors, Shard, ShardFile, Summary};
use crate::scenario::Params;

/// `rinscope montecarlo` (and Python's `montecarlo`).
pub struct MonteCarloRequest {
    /// The calibration scenario (its `[calibration.montecarlo]` draws the tables).
    pub params: Params,
    /// Runs of the whole Monte Carlo (default: the scenario's).
    pub runs: Option<usize>,
    /// The part of them to run here.
    pub shard: Shard,
    /// `--json`: the summary, or for a shard its file for `montecarlo merge`.
    pub json: Option<PathBuf>,
}

/// What `montecarlo` reports.
pub struct MonteCarloReport {
    /// Runs of the whole Monte Carlo.
    pub runs: usize,
    /// Runs of this shard.
    pub mine: usize,
    /// The runs' estimation errors (fewer than `mine` when stopped).
    pub done: Vec<RunErrors>,
    /// Their statistics.
    pub summary: Summary,
}

impl MonteCarloReport {
    /// Stopped before every run of the shard was done.
    #[must_use]
    pub fn interrupted(&self) -> bool {
        self.done.len() < self.mine
    }
}

/// `montecarlo`'s one owner: the runs of the shard in parallel (`tick` once per run), their summary
/// and its document.
///
/// # Errors
/// A run count out of range, a calibration the data cannot support, an output that cannot be written.
pub fn execute(
    req: &MonteCarloRequest,
    stop: &AtomicBool,
    tick: &(dyn Fn() + Sync),
) -> Result<MonteCarloReport, Failure> {
    check_output("--json", req.json.as_deref())?;
    let params = &req.params;
    let runs =
        crate::calib::MonteCarloConfig::check_runs(req.runs.unwrap_or(params.calibration.montecarlo.runs as usize))
            .map_err(|e| Failure::input(format!("--runs {e}")))?;
    let mine = req.shard.indices(runs as u64).len();
    let started = std::time::Instant::now();
    let done = monte_carlo_runs(params, runs, req.shard, tick, stop)
        .map_err(|e| Failure::calibration("montecarlo", e, "montecarlo did not finish"))?;
    let summary = montecarlo::summarize(&monte_carlo_setup(params), runs, &done, started.elapsed().as_secs_f64());
    if let Some(path) = &req.json {
        if req.shard == Shard::WHOLE {
            write_json("--json", path, &summary)?;
        } else {
            write_json("--json", path, &ShardFile { shard: req.shard, summary: summary.clone(), runs: done.clone() })?;
        }
    }
    Ok(MonteCarloReport { runs, mine, done, summary })
}

/// `montecarlo merge`: the shards' files of one Monte Carlo as the whole run's summary.
///
/// # Errors
/// A file that is not a shard file, shards that do not make one Monte Carlo, or ran with another
/// setup; an output that cannot be written.
pub fn merge(params: &Params, files: &[PathBuf], json: Option<&std::path::Path>) -> Result<Summary, Failure> {
    check_output("--json", json)?;
    let mut shards = Vec::new();
    for f in files {
        let text = read_small_file(f, "shard file")?;
        let shard: ShardFile = serde_json::from_str(&text).map_err(|e| {
            Failure::input(format!(
                "{}: not a shard file of `rinscope montecarlo --shard K/M --json` ({e})",
                f.display()
            ))
        })?;
        shards.push(shard);
    }
    let summary = montecarlo::merge(&monte_carlo_setup(params), &shards)
        .map_err(|e| Failure::input(format!("montecarlo merge: {e}")))?;
    if let Some(first) = shards.first()
        && first.summary.setup != summary.setup
    {
        return Err(Failure::input(format!(
            "montecarlo merge: the shards ran with \"{}\", this merge with \"{}\" (give the same --scenario/--config and --eta-measured-sigma-arcsec)",
            first.summary.setup, summary.setup
        )));
    }
    if let Some(path) = json {
        write_json("--json", path, &summary)?;
    }
    Ok(summary)
}
