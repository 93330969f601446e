//! `rinscope bench`'s owner: which benchmark, its JSON, one way to stop.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};

use super::{Figures, allantools, peer};
use crate::app::failure::Failure;
use crate::app::outputs::{check_output, write_json};

/// What to measure.
#[derive(Debug, Clone)]
pub enum Benchmark {
    /// rinscope's own figures: `steps` per simulation benchmark, the sections named in `only`
    /// (all when empty). They are printed as each is measured.
    Own {
        /// Steps per simulation benchmark.
        steps: u64,
        /// The sections to run (all when empty).
        only: Vec<String>,
    },
    /// `--peer allantools`: the Allan estimators against allantools, `rounds` alternated runs on
    /// `samples` samples with the interpreter `python`.
    Allantools {
        /// The interpreter that has allantools.
        python: PathBuf,
        /// Alternated rounds.
        rounds: usize,
        /// Samples per series.
        samples: u64,
    },
    /// `--peer pyins`: whole processes alternated with pyins.
    Pyins(peer::PeerOptions),
}

/// A `bench` request.
#[derive(Debug, Clone)]
pub struct BenchRequest {
    /// What to measure.
    pub benchmark: Benchmark,
    /// Where the figures go as JSON.
    pub json: Option<PathBuf>,
}

/// What a benchmark measured.
pub enum BenchReport {
    /// rinscope's own figures (already printed as measured).
    Own(Figures),
    /// Each estimator against allantools.
    Allantools {
        /// One per estimator.
        reports: Vec<allantools::EstimatorReport>,
        /// Samples per series.
        samples: u64,
    },
    /// Each stream against pyins.
    Pyins(Vec<peer::StreamReport>),
}

impl BenchReport {
    /// What the terminal shows at the end (rinscope's own figures were shown as they came).
    #[must_use]
    pub fn text(&self) -> String {
        match self {
            Self::Own(_) => String::new(),
            Self::Allantools { reports, samples } => allantools::text(reports, *samples),
            Self::Pyins(reports) => peer::text(reports),
        }
    }
}

/// Runs the benchmark of `req`; stopped by `stop`, it writes nothing and says so.
///
/// # Errors
/// An output that cannot be written (checked before anything runs), a peer that is not there, a
/// signal.
pub fn execute(req: &BenchRequest, stop: &AtomicBool) -> Result<BenchReport, Failure> {
    check_output("--json", req.json.as_deref())?;
    // A benchmark stopped by a signal is no benchmark: nothing is written, and that is said.
    let ended = |e: anyhow::Error, what: &str| {
        if stop.load(Ordering::SeqCst) { Failure::interrupted(what) } else { Failure::run(format!("{e:#}")) }
    };
    let unfinished = "the comparison did not finish; nothing written";
    let report = match &req.benchmark {
        Benchmark::Own { steps, only } => super::run_benchmarks(*steps, only, stop)
            .map(BenchReport::Own)
            .map_err(|e| ended(e, "the figures printed so far are not a whole benchmark; none written"))?,
        Benchmark::Allantools { python, rounds, samples } => allantools::compare(python, *samples, *rounds, stop)
            .map(|reports| BenchReport::Allantools { reports, samples: *samples })
            .map_err(|e| ended(e, unfinished))?,
        Benchmark::Pyins(opts) => {
            peer::compare(opts, stop).map(BenchReport::Pyins).map_err(|e| ended(e, unfinished))?
        }
    };
    if let Some(path) = &req.json {
        match &report {
            BenchReport::Own(f) => write_json("--json", path, f)?,
            BenchReport::Allantools { reports, .. } => write_json("--json", path, reports)?,
            BenchReport::Pyins(reports) => write_json("--json", path, reports)?,
        }
    }
    Ok(report)
}
