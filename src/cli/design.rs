//! `rinscope budget` and `rinscope schemes`: which error source causes which drift, and which rotation
//! scheme cancels it (the owners are `app::budget::execute` and `app::schemes::execute`, the
//! mechanism `ins::budget`).

use std::path::{Path, PathBuf};

use clap::Args;

use super::commands::print_saved;
use super::numbers::{HOURS, SAMPLE_S, count, number};
use super::{Failure, ScenarioSource, SinkArgs};
use crate::app::outputs::read_small_file;
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
    use crate::app::schemes::{BUILT_IN, SchemesRequest, built_in, execute};
    let mut params = args.source.load("budget-dual-axis-16")?;
    if let Some(h) = args.hours {
        params.set_duration(h * 3600.0);
    }
    let names: Vec<String> = if args.schemes.is_empty() {
        BUILT_IN.iter().map(|(n, _)| (*n).to_owned()).collect()
    } else {
        args.schemes.clone()
    };
    let mut schemes = Vec::new();
    for name in names {
        let text = match built_in(&name) {
            Some(t) => t.to_owned(),
            None if Path::new(&name).exists() => read_small_file(Path::new(&name), "--schemes")?,
            None => {
                let known: Vec<&str> = BUILT_IN.iter().map(|(n, _)| *n).collect();
                return Err(Failure::input(format!(
                    "--schemes {name}: neither a built-in scheme ({}) nor a file",
                    known.join(", ")
                )));
            }
        };
        schemes.push((name, text));
    }
    let request = SchemesRequest {
        params,
        schemes,
        seeds: args.seeds,
        threads: args.threads,
        json: args.json.clone(),
        budget: args.budget,
        recording: args.sinks.recording()?,
    };
    let report = execute(&request, &stop_flag())?;
    print_report(&report.text(), report.saved.as_ref(), report.interrupted, "the comparison")
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
