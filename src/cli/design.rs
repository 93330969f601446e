//! `rinscope budget`, `rinscope schemes` and `rinscope design`: which error source causes which
//! drift, which rotation scheme cancels it, and a search for a better one (the owners are
//! `app::budget::execute`, `app::schemes::execute` and `app::design::execute`; the mechanisms
//! `ins::budget`, `ins::averaged`, `model::sequences`).

use std::path::PathBuf;

use clap::Args;

use super::commands::print_saved;
use super::numbers::{DWELL_S, HOURS, MOVE_DEG, RATE_DEG_PER_S, SAMPLE_S, WRAP_DEG, count, number};
use super::{Failure, ScenarioSource, SinkArgs};
use crate::app::terminate::stop_flag;

#[derive(Args)]
pub(super) struct BudgetArgs {
    #[command(flatten)]
    source: ScenarioSource,
    #[command(flatten)]
    sinks: SinkArgs,
    /// Override the scenario's simulated duration, h.
    #[arg(long, allow_negative_numbers = true, value_parser = |t: &str| number(t, &HOURS))]
    hours: Option<f64>,
    /// The interval between the instants the errors are sampled at, s (default: 4000 over the run,
    /// at most 60 s).
    #[arg(long, allow_negative_numbers = true, value_parser = |t: &str| number(t, &SAMPLE_S))]
    sample_s: Option<f64>,
    /// Threads (default: every core).
    #[arg(long, allow_negative_numbers = true, value_parser = |t: &str| count(t, 1, 1024, "threads").map(|n| n as usize))]
    threads: Option<usize>,
    /// Write the budget (every row's value at the end, peak and RMS per channel) as JSON.
    #[arg(long)]
    json: Option<PathBuf>,
}

#[derive(Args)]
pub(super) struct SchemesArgs {
    #[command(flatten)]
    source: ScenarioSource,
    #[command(flatten)]
    sinks: SinkArgs,
    /// The schemes, comma-separated: built-in names (none, single-axis-4, continuous, dual-axis-8,
    /// dual-axis-16, dual-axis-32, dual-axis-64) or files with a [scheme] table (a scenario or a
    /// scheme file). Default: every built-in.
    #[arg(long, value_delimiter = ',')]
    schemes: Vec<String>,
    /// Override the scenario's simulated duration, h.
    #[arg(long, allow_negative_numbers = true, value_parser = |t: &str| number(t, &HOURS))]
    hours: Option<f64>,
    /// Seeds per scheme: a Monte Carlo over the IMU's error draws and noise.
    #[arg(long, default_value_t = 4, allow_negative_numbers = true, value_parser = |t: &str| count(t, 1, 10_000, "seeds"))]
    seeds: u64,
    /// Threads (default: every core).
    #[arg(long, allow_negative_numbers = true, value_parser = |t: &str| count(t, 1, 1024, "threads").map(|n| n as usize))]
    threads: Option<usize>,
    /// Write the comparison as JSON.
    #[arg(long)]
    json: Option<PathBuf>,
    /// Also each scheme's error budget (the first seed; as `budget`, one run per source): the
    /// sources each leaves unmodulated.
    #[arg(long)]
    budget: bool,
    /// Only the errors a scheme can modulate (biases, scale factors, misalignments, g-sensitivity,
    /// the table's): no noise, no alignment error — the seeds then differ by those draws alone,
    /// and the schemes' differences are not hidden by the random walks' luck.
    #[arg(long)]
    modulable_only: bool,
}

#[derive(Args)]
pub(super) struct DesignArgs {
    #[command(flatten)]
    source: ScenarioSource,
    #[command(flatten)]
    sinks: SinkArgs,
    /// Override the scenario's simulated duration, h.
    #[arg(long, allow_negative_numbers = true, value_parser = |t: &str| number(t, &HOURS))]
    hours: Option<f64>,
    /// The axes that may move, comma-separated names (default: every axis).
    #[arg(long, value_delimiter = ',')]
    axes: Vec<String>,
    /// Moves per period, comma-separated even numbers.
    #[arg(long, value_delimiter = ',', default_values_t = [8, 16, 32], allow_negative_numbers = true, value_parser = |t: &str| count(t, 2, 256, "moves").map(|n| n as usize))]
    moves: Vec<usize>,
    /// Move sizes, deg, comma-separated.
    #[arg(long, value_delimiter = ',', default_values_t = [180.0], allow_negative_numbers = true, value_parser = |t: &str| number(t, &MOVE_DEG))]
    angles_deg: Vec<f64>,
    /// Cruise rates, deg/s, comma-separated (default: the scenario's).
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true, value_parser = |t: &str| number(t, &RATE_DEG_PER_S))]
    rates_deg_per_s: Vec<f64>,
    /// Dwells after each move, s, comma-separated (default: the scenario's).
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true, value_parser = |t: &str| number(t, &DWELL_S))]
    dwells_s: Vec<f64>,
    /// The largest excursion of an axis from its start (the cable's wrap), deg.
    #[arg(long, default_value_t = 360.0, allow_negative_numbers = true, value_parser = |t: &str| number(t, &WRAP_DEG))]
    max_wrap_deg: f64,
    /// Sequences drawn (duplicates dropped) and ranked by the averaged model.
    #[arg(long, default_value_t = 1000, allow_negative_numbers = true, value_parser = |t: &str| count(t, 1, 1_000_000, "candidates").map(|n| n as usize))]
    candidates: usize,
    /// Local moves (two moves exchanged, an axis reversed) tried from each of the model's 8 best
    /// drawn sequences, each kept when the model scores it lower (0: no local search).
    #[arg(long, default_value_t = 300, allow_negative_numbers = true, value_parser = |t: &str| count(t, 0, 1_000_000, "moves").map(|n| n as usize))]
    refine: usize,
    /// The model's best this many are confirmed by the exact simulation, beside every built-in.
    #[arg(long, default_value_t = 4, allow_negative_numbers = true, value_parser = |t: &str| count(t, 1, 100, "schemes").map(|n| n as usize))]
    confirm: usize,
    /// Seeds per confirmed scheme.
    #[arg(long, default_value_t = 4, allow_negative_numbers = true, value_parser = |t: &str| count(t, 1, 10_000, "seeds"))]
    seeds: u64,
    /// Threads (default: every core).
    #[arg(long, allow_negative_numbers = true, value_parser = |t: &str| count(t, 1, 1024, "threads").map(|n| n as usize))]
    threads: Option<usize>,
    /// Write the design (every ranked scheme, its model terms and exact row) as JSON.
    #[arg(long)]
    json: Option<PathBuf>,
    /// Write the best scheme's `[scheme]` to this file (run it with `schemes --schemes FILE`).
    #[arg(long)]
    save_scheme: Option<PathBuf>,
}

/// `rinscope budget`.
pub(super) fn budget(args: &BudgetArgs) -> Result<(), Failure> {
    use crate::app::budget::{BudgetRequest, execute};
    let mut params = args.source.load("budget-dual-axis-16")?;
    if let Some(h) = args.hours {
        params.set_duration(h * 3600.0);
    }
    let request = BudgetRequest {
        params,
        sample_s: args.sample_s,
        threads: args.threads,
        json: args.json.clone(),
        recording: args.sinks.recording()?,
    };
    let report = execute(&request, &stop_flag())?;
    print_report(&report.text(), report.saved.as_ref(), report.interrupted, "the budget")
}

/// `rinscope schemes`.
pub(super) fn schemes(args: &SchemesArgs) -> Result<(), Failure> {
    use crate::app::schemes::{SchemesRequest, execute, resolve};
    let mut params = args.source.load("budget-dual-axis-16")?;
    if let Some(h) = args.hours {
        params.set_duration(h * 3600.0);
    }
    let schemes = resolve(&args.schemes)?;
    let request = SchemesRequest {
        params,
        schemes,
        seeds: args.seeds,
        threads: args.threads,
        json: args.json.clone(),
        budget: args.budget,
        modulable_only: args.modulable_only,
        preface: None,
        recording: args.sinks.recording()?,
    };
    let report = execute(&request, &stop_flag())?;
    print_report(&report.text(), report.saved.as_ref(), report.interrupted, "the comparison")
}

/// `rinscope design`.
pub(super) fn design(args: &DesignArgs) -> Result<(), Failure> {
    use crate::app::design::{DesignRequest, DesignSpace, execute};
    let mut params = args.source.load("budget-dual-axis-16")?;
    if let Some(h) = args.hours {
        params.set_duration(h * 3600.0);
    }
    let request = DesignRequest {
        params,
        space: DesignSpace {
            axes: args.axes.clone(),
            steps: args.moves.clone(),
            angles_deg: args.angles_deg.clone(),
            rates_deg_per_s: args.rates_deg_per_s.clone(),
            dwells_s: args.dwells_s.clone(),
            max_wrap_deg: args.max_wrap_deg,
        },
        candidates: args.candidates,
        refine: args.refine,
        confirm: args.confirm,
        seeds: args.seeds,
        threads: args.threads,
        json: args.json.clone(),
        save_scheme: args.save_scheme.clone(),
        recording: args.sinks.recording()?,
    };
    let report = execute(&request, &stop_flag())?;
    print_report(&report.text(), report.saved.as_ref(), report.interrupted, "the design")
}

/// Prints a report's table and where its recording went; stopped early, the interrupted exit (what
/// was printed covers the simulated part only).
fn print_report(
    text: &str,
    saved: Option<&crate::record::sink::Saved>,
    interrupted: bool,
    what: &str,
) -> Result<(), Failure> {
    out!("{text}");
    if let Some(saved) = saved {
        print_saved(saved);
    }
    if interrupted {
        return Err(Failure::interrupted(format!("{what} covers the simulated part only")));
    }
    Ok(())
}
