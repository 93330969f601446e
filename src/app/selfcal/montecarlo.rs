//! `selfcal --monte-carlo`: random IMUs (the scenario's table, its errors drawn with seeds after
//! the scenario's) calibrated on every core, each parameter's reported 1σ against the spread of its
//! errors; whole, or one shard of it (a cluster's array task) and the merge of the shards' files.

use std::sync::atomic::AtomicBool;

use anyhow::{Result, anyhow, bail};
use rayon::prelude::*;

use super::{Setup, run_one};
use crate::calib::montecarlo::Shard;

/// Per parameter over a Monte Carlo: mean error, the spread of the errors and the mean reported 1σ.
#[derive(Debug, Clone, serde::Serialize)]
pub struct MonteCarlo {
    /// Runs.
    pub runs: usize,
    /// Mean of estimate − truth, SI.
    pub mean_error: Vec<f64>,
    /// Standard deviation of estimate − truth, SI.
    pub spread: Vec<f64>,
    /// Mean reported 1σ, SI.
    pub reported_sigma: Vec<f64>,
    /// Wall time, s.
    pub wall_s: f64,
}

/// One run of a Monte Carlo: its seed, every parameter's error (estimate − truth) and 1σ, SI.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct McRun {
    /// The IMU's seed.
    pub seed: u64,
    /// Estimate − truth, per parameter.
    pub error: Vec<f64>,
    /// The reported 1σ, per parameter.
    pub sigma: Vec<f64>,
}

impl MonteCarlo {
    /// The statistics of `runs` (in seed order, so that shards merged give the whole's sums).
    #[must_use]
    pub fn of(runs: &[McRun], wall_s: f64) -> Self {
        let n = runs.len() as f64;
        let m = runs.first().map_or(0, |r| r.error.len());
        let mean_error: Vec<f64> = (0..m).map(|k| runs.iter().map(|r| r.error[k]).sum::<f64>() / n).collect();
        let spread = (0..m)
            .map(|k| {
                (runs.iter().map(|r| (r.error[k] - mean_error[k]).powi(2)).sum::<f64>() / (n - 1.0).max(1.0)).sqrt()
            })
            .collect();
        let reported_sigma = (0..m).map(|k| runs.iter().map(|r| r.sigma[k]).sum::<f64>() / n).collect();
        Self { runs: runs.len(), mean_error, spread, reported_sigma, wall_s }
    }
}

/// The runs of `shard` of a Monte Carlo of `runs` IMUs drawn with seeds `first_seed..`, on every core.
///
/// # Errors
/// Interrupted, or a run that failed.
pub fn monte_carlo_runs(
    s: &Setup,
    runs: usize,
    first_seed: u64,
    shard: Shard,
    stop: &AtomicBool,
) -> Result<Vec<McRun>> {
    shard
        .indices(runs as u64)
        .into_par_iter()
        .map(|i| {
            let seed = first_seed + i;
            let o = run_one(s, seed, false, stop)?;
            let error = o.estimate.all_params().iter().zip(o.all_truth(s)).map(|(e, t)| e - t).collect();
            Ok(McRun { seed, error, sigma: o.estimate.all_sigma() })
        })
        .collect()
}

/// `runs` IMUs drawn with seeds `first_seed..`, on every core.
///
/// # Errors
/// Interrupted, or a run that failed.
pub fn monte_carlo(s: &Setup, runs: usize, first_seed: u64, stop: &AtomicBool) -> Result<MonteCarlo> {
    let started = std::time::Instant::now();
    let done = monte_carlo_runs(s, runs, first_seed, Shard::WHOLE, stop)?;
    Ok(MonteCarlo::of(&done, started.elapsed().as_secs_f64()))
}

/// One shard's file (`selfcal --monte-carlo N --shard K/M --json FILE`): what it ran and its runs.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShardFile {
    /// Which slice.
    pub shard: Shard,
    /// The scenario, its seed (the runs' are after it) and the sequence.
    pub scenario: String,
    /// The scenario's seed.
    pub seed: u64,
    /// The sequence's name.
    pub sequence: String,
    /// Runs of the whole Monte Carlo.
    pub runs_requested: usize,
    /// The parameters, in the runs' order.
    pub parameters: Vec<String>,
    /// This slice's runs.
    pub runs: Vec<McRun>,
}

/// The statistics of the whole Monte Carlo from its shards' files (every shard once, of the same
/// scenario, seed, sequence and size): the same numbers, bit for bit, as the unsharded run.
///
/// # Errors
/// No files, shards of different Monte Carlos, a shard missing or given twice.
pub fn merge_shards(files: &[ShardFile]) -> Result<(MonteCarlo, &ShardFile)> {
    let Some(first) = files.first() else { bail!("no shard files given") };
    let count = first.shard.count;
    for f in files {
        if f.shard.count != count
            || f.scenario != first.scenario
            || f.seed != first.seed
            || f.sequence != first.sequence
            || f.runs_requested != first.runs_requested
            || f.parameters != first.parameters
        {
            bail!(
                "shard {}/{} of {} (seed {}, {}, {} runs) does not belong with shard {}/{count} of {} (seed {}, {}, {} runs)",
                f.shard.index,
                f.shard.count,
                f.scenario,
                f.seed,
                f.sequence,
                f.runs_requested,
                first.shard.index,
                first.scenario,
                first.seed,
                first.sequence,
                first.runs_requested
            );
        }
    }
    Shard::check_cover(files.iter().map(|f| f.shard), count).map_err(|e| anyhow!(e))?;
    let mut runs: Vec<McRun> = files.iter().flat_map(|f| f.runs.iter().cloned()).collect();
    runs.sort_by_key(|r| r.seed);
    Ok((MonteCarlo::of(&runs, 0.0), first))
}
