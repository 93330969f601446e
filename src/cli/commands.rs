//! The commands: each turns its arguments into parameters and sinks, runs the orchestration in
//! `app`, prints what a user reads and maps failures to exit codes.

use std::path::{Path, PathBuf};

use super::{
    CalibrateArgs, Failure, LiveArgs, ModulationArgs, MonteCarloAction, MonteCarloArgs, RunArgs, ScenarioSource,
    SweepArgs, TprArgs,
};
use crate::app::outputs::read_small_file;
use crate::app::terminate::stop_flag;
use crate::app::{live, modulation, reproduce};
use crate::calib::montecarlo::Shard;
use crate::record::sink;
use crate::scenario::{Params, presets};

fn load(args: &RunArgs) -> Result<Params, Failure> {
    let mut params = args.source.load(presets::DEFAULT_SCENARIO)?;
    if let Some(d) = args.duration_s {
        // The parser held it to `scenario::DURATION`.
        params.set_duration(d);
    }
    Ok(params)
}

/// `rinscope run`.
pub(super) fn run(args: &RunArgs) -> Result<(), Failure> {
    use crate::app::run::{RunRequest, execute};
    let request = RunRequest {
        params: load(args)?,
        recording: args.sinks.recording()?,
        summary_json: args.summary_json.clone(),
        progress: true,
        compensation: match &args.compensation {
            Some(path) => Some((read_small_file(path, "--compensation")?, path.display().to_string())),
            None => None,
        },
    };
    let report = execute(&request, &stop_flag())?;
    let summary = &report.summary;
    out!("{}", summary.table());
    print_exported(&report.saved);
    if let Some(p) = &summary.recording_path {
        outln!("open it with:  rerun {p}     (viewer: {})", sink::VIEWER_INSTALL_HINT);
    }
    if summary.interrupted {
        return Err(Failure::interrupted("the recording is complete up to that moment"));
    }
    Ok(())
}

/// `rinscope live`.
pub(super) fn live(args: &LiveArgs) -> Result<(), Failure> {
    let request = live::LiveRequest {
        config: args.config.clone(),
        scenario: args.scenario.clone(),
        sinks: args.sinks.recording()?.sinks,
        speed: args.speed,
        duration_s: args.duration_s,
        no_viewer: args.no_viewer,
        panel: !args.no_panel,
        compensation: match &args.compensation {
            Some(path) => Some((read_small_file(path, "--compensation")?, path.display().to_string())),
            None => None,
        },
    };
    let report = live::execute(&request, &stop_flag())?;
    let summary = &report.summary;
    outln!(
        "live session: {:.1} s simulated ({} steps), {} reloads applied, save -> applied p95 {:.1} ms",
        summary.sim_t_s,
        summary.steps,
        summary.latencies_ms.len(),
        live::p95(&summary.latencies_ms)
    );
    if let Some((p, bytes)) = &report.recording {
        outln!(
            "recording: {} ({:.2} MB) — open with `rerun {}`, list its events with `rinscope events {}`",
            p.display(),
            *bytes as f64 / 1e6,
            p.display(),
            p.display()
        );
    }
    print_tables(&report.exported);
    // Ended by a signal (not by `q` or its length): 128 + the signal, as every command.
    if report.interrupted {
        return Err(Failure::interrupted("the session's recording is complete up to that moment"));
    }
    Ok(())
}

/// `rinscope modulation`.
pub(super) fn modulation(args: &ModulationArgs) -> Result<(), Failure> {
    let report = modulation::execute(args.hours, &args.sinks.recording()?, &stop_flag())?;
    out!("{}", report.table);
    print_saved(&report.saved);
    if report.interrupted {
        return Err(Failure::interrupted("the table and the recording cover the simulated part only"));
    }
    Ok(())
}

/// The line that tells where a saved recording is and how to open it (the owner refused a run
/// whose data nothing kept: `app::outputs::finish`).
pub(super) fn print_saved(saved: &sink::Saved) {
    if let Some((p, bytes)) = &saved.recording {
        outln!("recording: {} ({:.2} MB) — open with `rerun {}`", p.display(), *bytes as f64 / 1e6, p.display());
    }
    print_exported(saved);
}

/// The lines that tell where the export tables and the figures are.
pub(super) fn print_exported(saved: &sink::Saved) {
    print_tables(&saved.exported);
    if let Some(f) = &saved.figures {
        let dir = f.files.first().and_then(|p| p.parent()).map_or_else(|| ".".into(), |d| d.display().to_string());
        outln!("figures: {} plots drawn to {dir} (SVG and PNG)", f.plots);
        if let Some(w) = &f.warning {
            errln!("rinscope: --figures: {w}");
        }
    }
}

/// The line that tells where the tables `written` are.
pub(super) fn print_tables(written: &[std::path::PathBuf]) {
    if let Some(first) = written.first() {
        let dir = first.parent().map_or_else(|| ".".into(), |d| d.display().to_string());
        outln!(
            "exported {} tables to {dir} (pandas: pd.read_parquet(path); MATLAB: parquetread(path); docs/export.md)",
            written.len()
        );
    }
}

/// `rinscope calibrate`.
pub(super) fn calibrate(args: &CalibrateArgs) -> Result<(), Failure> {
    use crate::app::calibrate::{CalibrateInput, CalibrateRequest, execute};
    let input = match &args.log {
        Some(dir) => CalibrateInput::Log(Box::new(crate::scenario::logset::load(dir)?)),
        None => CalibrateInput::Scenario(Box::new(args.source.load("jiang2017-calibration")?)),
    };
    let recording = if args.no_recording { None } else { Some(args.sinks.recording()?) };
    let report = execute(&CalibrateRequest { input, recording, json: args.json.clone() }, &stop_flag())?;
    out!("{}", report.text);
    if let Some(saved) = &report.saved {
        print_saved(saved);
    }
    if report.interrupted {
        return Err(Failure::interrupted(
            "the estimates above are complete; the recording's table motion stops where it was cut short",
        ));
    }
    Ok(())
}

/// The calibration preset with `--eta-measured-sigma-arcsec` applied.
fn monte_carlo_params(source: &ScenarioSource, eta_measured_sigma_arcsec: Option<f64>) -> Result<Params, Failure> {
    let mut params = source.load("jiang2017-calibration")?;
    if let Some(s) = eta_measured_sigma_arcsec {
        params
            .calibration
            .montecarlo
            .set_eta_measured_sigma_arcsec(s)
            .map_err(|e| Failure::input(format!("--eta-measured-sigma-arcsec {e}")))?;
    }
    Ok(params)
}

/// `rinscope montecarlo`.
pub(super) fn montecarlo(args: &MonteCarloArgs) -> Result<(), Failure> {
    use crate::app::montecarlo::{MonteCarloRequest, execute, merge};
    if let Some(MonteCarloAction::Merge { files, source, eta_measured_sigma_arcsec, json }) = &args.action {
        let params = monte_carlo_params(source, *eta_measured_sigma_arcsec)?;
        out!("{}", merge(&params, files, json.as_deref())?.text());
        return Ok(());
    }
    let shard = match &args.shard {
        Some(text) => Shard::parse(text).map_err(|e| Failure::input(format!("--shard {e}")))?,
        None => Shard::WHOLE,
    };
    let request = MonteCarloRequest {
        params: monte_carlo_params(&args.source, args.eta_measured_sigma_arcsec)?,
        runs: args.runs,
        shard,
        json: args.json.clone(),
    };
    let bar = indicatif::ProgressBar::new(0);
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{spinner} {pos}/{len} calibrations [{bar:40}] {elapsed_precise} (eta {eta})",
        )
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
        .progress_chars("=> "),
    );
    let runs = request.runs.unwrap_or(request.params.calibration.montecarlo.runs as usize);
    bar.set_length(shard.indices(runs as u64).len() as u64);
    let tick = || bar.inc(1);
    let report = execute(&request, &stop_flag(), &tick);
    bar.finish_and_clear();
    let report = report?;
    if shard != Shard::WHOLE {
        outln!(
            "shard {}/{}: {} of the {} runs (i mod {} == {})",
            shard.index,
            shard.count,
            report.mine,
            report.runs,
            shard.count,
            shard.index
        );
    }
    out!("{}", report.summary.text());
    if report.interrupted() {
        return Err(Failure::interrupted(format!(
            "after {} of {} runs (the statistics above are over those only)",
            report.done.len(),
            report.mine
        )));
    }
    Ok(())
}

/// `rinscope tpr`.
pub(super) fn tpr(args: &TprArgs) -> Result<(), Failure> {
    use crate::app::tpr::{TprRequest, execute};
    let params = args.source.load("zheng2016-tpr")?;
    let request = TprRequest { params, recording: args.sinks.recording()?, json: args.json.clone(), seeds: args.seeds };
    let report = execute(&request, &stop_flag())?;
    out!("{}", report.text);
    print_saved(&report.saved);
    if let Some((table, wall_s)) = &report.sweep {
        out!("{table}");
        outln!("  {} runs of {:.1} h in {wall_s:.1} s", args.seeds.unwrap_or(0), request.params.duration_s / 3600.0);
    }
    if report.interrupted {
        return Err(Failure::interrupted("the recording holds what was simulated until then"));
    }
    Ok(())
}

/// `rinscope sweep`.
pub(super) fn sweep(args: &SweepArgs) -> Result<(), Failure> {
    use crate::app::sweep::{SweepRequest, execute, merge};
    if !args.merge.is_empty() {
        out!("{}", merge(&args.merge, args.json.as_deref())?.text());
        return Ok(());
    }
    if args.vary.is_empty() && args.seeds == 1 {
        return Err(Failure::input("sweep: nothing to sweep: give --vary KEY=V1,V2,... or --seeds N"));
    }
    let request = SweepRequest {
        params: args.source.load(presets::DEFAULT_SCENARIO)?,
        vary: args.vary.clone(),
        seeds: args.seeds,
        duration_s: args.duration_s,
        threads: args.threads.map(|t| t as usize),
        json: args.json.clone(),
        shard: match &args.shard {
            Some(text) => Shard::parse(text).map_err(|e| Failure::input(format!("--shard {e}")))?,
            None => Shard::WHOLE,
        },
    };
    let report = execute(&request, &stop_flag())?;
    out!("{}", report.text());
    if report.interrupted {
        return Err(Failure::interrupted("the points run before it are in the table"));
    }
    Ok(())
}

/// `rinscope events`.
pub(super) fn events(file: &Path) -> Result<(), Failure> {
    let (events, incomplete) = crate::app::inspect::events(file)?;
    if let Some(note) = incomplete {
        errln!("rinscope: note: {note}");
    }
    for e in events {
        match e.t_s {
            Some(t) => outln!("{t:>10.3} s  {:<5} {}", e.level, e.text),
            None => outln!("{:>12}  {:<5} {}", "static", e.level, e.text),
        }
    }
    Ok(())
}

/// `rinscope scenarios`.
pub(super) fn list_scenarios() {
    for (name, loaded) in crate::app::inspect::scenarios() {
        match loaded {
            Ok(p) => {
                let mark = if name == presets::DEFAULT_SCENARIO { " (default)" } else { "" };
                outln!("{name}{mark}\n    {}", p.meta.title);
            }
            Err(e) => outln!("{name}\n    BROKEN: {e}"),
        }
    }
}

/// `rinscope check-config`.
pub(super) fn check_config(file: &Path) -> Result<(), Failure> {
    let p = crate::app::inspect::check_config(file)?;
    let axes: Vec<String> = p.table.chain.axes().iter().map(|a| a.name.clone()).collect();
    outln!(
        "{}: ok — scenario \"{}\", {} s at {} Hz ({} steps), axes {:?}, seed {}",
        file.display(),
        p.meta.name,
        p.duration_s,
        p.step_hz,
        p.timeline().instants(),
        axes,
        p.meta.seed
    );
    Ok(())
}

/// `rinscope reproduce`.
pub(super) fn reproduce(markdown: Option<&Path>) -> Result<(), Failure> {
    let table = reproduce::execute(markdown, &stop_flag())?;
    out!("{}", table.text());
    if table.all_agree() {
        Ok(())
    } else {
        Err(Failure::run("some reproductions fall outside their tolerance (see the table)"))
    }
}

/// `rinscope bench` (with `--peer`: against another tool).
pub(super) fn bench(benchmark: crate::app::bench::Benchmark, json: Option<PathBuf>) -> Result<(), Failure> {
    use crate::app::bench::{BenchRequest, execute};
    let report = execute(&BenchRequest { benchmark, json }, &stop_flag())?;
    out!("{}", report.text());
    Ok(())
}
