//! rinscope: see the errors of a rotational inertial navigation system in the Rerun viewer.
//!
//! ```text
//! rinscope                                   # embedded default scenario -> recordings/<scenario>.rrd
//! rinscope run --scenario NAME --spawn       # stream to a new viewer (pip install rerun-sdk==0.36.3)
//! rinscope run --config my.toml --save out.rrd --summary-json out.json
//! rinscope scenarios | check-config FILE | reproduce | bench
//! ```
//!
//! Exit codes: 0 success, 1 a failure while running (or a reproduction outside tolerance),
//! 2 bad input (config, path, viewer), 130 interrupted by Ctrl-C (what was simulated is saved).

use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use clap::{Args, Parser, Subcommand};

use rinscope::config::{self, ConfigError, Params};
use rinscope::sink::{self, SinkError, SinkRequest};
use rinscope::{bench, reproduce, run, scenarios};

#[derive(Parser)]
#[command(name = "rinscope", version, about = "See the errors of a rotational inertial navigation system (RINS) in the Rerun viewer")]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Simulate a scenario and record it (the default command).
    Run(RunArgs),
    /// Run in real time, streaming to a viewer, with the config file watched and a slider panel.
    Live(LiveArgs),
    /// Rotation modulation: static INS with constant biases, no rotation vs continuous vs 16-position,
    /// simulated together and recorded side by side.
    Modulation {
        /// Simulated hours.
        #[arg(long, default_value_t = 24.0)]
        hours: f64,
        /// Save to this .rrd (default recordings/rotation-modulation.rrd unless a viewer is asked for).
        #[arg(long)]
        save: Option<PathBuf>,
        /// Start a new Rerun viewer and stream to it.
        #[arg(long)]
        spawn: bool,
    },
    /// Static calibration of the swing cones and non-orthogonality (seed 000 §5): static Kalman
    /// filter and exact least squares, compensation before/after, a recording with ghost cones
    /// (default scenario: jiang2017-calibration).
    Calibrate(CalibrateArgs),
    /// Seed 000's Monte Carlo (Tables 2-3): many calibrations with drawn parameters, in parallel
    /// (default scenario: jiang2017-calibration).
    Montecarlo(MonteCarloArgs),
    /// Seed 003's Twice Position-fix Reset against the conventional reset, from one IMU stream
    /// (default scenario: zheng2016-tpr; needs [imu], [navigation] and two [position_fix] times).
    Tpr(TprArgs),
    /// Print the event log (reloads, errors, summary) of a saved recording.
    Events {
        /// The .rrd file.
        file: PathBuf,
    },
    /// List the scenario presets.
    Scenarios,
    /// Parse and validate a scenario file without running it.
    CheckConfig {
        /// The TOML file.
        file: PathBuf,
    },
    /// Run every scenario that reproduces a paper's number and compare (exit 1 on disagreement).
    Reproduce {
        /// Also write the table as markdown to this file (e.g. docs/reproduce.md).
        #[arg(long)]
        markdown: Option<PathBuf>,
    },
    /// Measure speed and recording size.
    Bench {
        /// Steps of each pure-simulation repetition.
        #[arg(long, default_value_t = 2_000_000)]
        steps: u64,
    },
}

#[derive(Args)]
struct LiveArgs {
    /// A preset: an editable copy is written to rinscope-live/<name>.toml (kept if it exists).
    #[arg(long, conflicts_with = "config")]
    scenario: Option<String>,
    /// The scenario file to run and watch.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Simulated seconds per wall-clock second (default: the file's [live] speed, else 1).
    #[arg(long)]
    speed: Option<f64>,
    /// Stop after this much simulated time, s (default: run until you quit).
    #[arg(long)]
    duration_s: Option<f64>,
    /// Start a new Rerun viewer (the default when no other viewer sink is given).
    #[arg(long)]
    spawn: bool,
    /// Stream to a running viewer (default URL rerun+http://127.0.0.1:9876/proxy).
    #[arg(long, num_args = 0..=1, default_missing_value = sink::DEFAULT_CONNECT_URL)]
    connect: Option<String>,
    /// Serve the stream over gRPC on this port (default 9876) for native or web viewers.
    #[arg(long, num_args = 0..=1, default_missing_value = "9876")]
    serve: Option<u16>,
    /// Also save everything streamed to this .rrd file.
    #[arg(long)]
    save: Option<PathBuf>,
    /// No viewer: only --save (for headless sessions and tests).
    #[arg(long, conflicts_with_all = ["spawn", "connect", "serve"])]
    no_viewer: bool,
    /// No terminal panel (edit the file by hand; Ctrl-C ends the session).
    #[arg(long)]
    no_panel: bool,
}

/// Where a command's scenario comes from (each command has its own default preset).
#[derive(Args, Default)]
struct Source {
    /// A preset from assets/scenarios (see `rinscope scenarios`).
    #[arg(long, conflicts_with = "config")]
    scenario: Option<String>,
    /// A scenario file.
    #[arg(long)]
    config: Option<PathBuf>,
}

impl Source {
    /// The scenario file if given, else the named preset, else `default`.
    fn load(&self, default: &str) -> Result<Params, ConfigError> {
        match &self.config {
            Some(path) => config::load_file(path),
            None => scenarios::load(self.scenario.as_deref().unwrap_or(default)),
        }
    }
}

#[derive(Args, Default)]
struct RunArgs {
    #[command(flatten)]
    source: Source,
    /// Save the recording to this .rrd file (default: recordings/<scenario>.rrd when no viewer is asked for).
    #[arg(long)]
    save: Option<PathBuf>,
    /// Start a new Rerun viewer and stream to it.
    #[arg(long)]
    spawn: bool,
    /// Stream to a running viewer (default URL rerun+http://127.0.0.1:9876/proxy).
    #[arg(long, num_args = 0..=1, default_missing_value = sink::DEFAULT_CONNECT_URL)]
    connect: Option<String>,
    /// Write RMS and peak errors, duration, steps and wall time as JSON.
    #[arg(long)]
    summary_json: Option<PathBuf>,
    /// Override the scenario's simulated duration, s.
    #[arg(long)]
    duration_s: Option<f64>,
}

#[derive(Args)]
struct CalibrateArgs {
    // Default jiang2017-calibration: a static vehicle; its [calibration] section, or the defaults.
    #[command(flatten)]
    source: Source,
    /// Save the recording to this .rrd (default recordings/<scenario>-calibration.rrd unless a viewer is asked for).
    #[arg(long)]
    save: Option<PathBuf>,
    /// Start a new Rerun viewer and stream to it.
    #[arg(long)]
    spawn: bool,
    /// Write the estimates, 1σ, observability and compensation as JSON.
    #[arg(long)]
    json: Option<PathBuf>,
    /// No recording (print and JSON only).
    #[arg(long, conflicts_with_all = ["save", "spawn"])]
    no_recording: bool,
}

#[derive(Args)]
struct MonteCarloArgs {
    // Default jiang2017-calibration.
    #[command(flatten)]
    source: Source,
    /// Number of runs (default: [calibration.montecarlo] runs).
    #[arg(long)]
    runs: Option<usize>,
    /// Give the filter an independent measurement of η with this 1σ, arcsec.
    #[arg(long)]
    eta_measured_sigma_arcsec: Option<f64>,
    /// Write the statistics as JSON.
    #[arg(long)]
    json: Option<PathBuf>,
}

#[derive(Args)]
struct TprArgs {
    // Default zheng2016-tpr.
    #[command(flatten)]
    source: Source,
    /// Save the recording to this .rrd (default recordings/<scenario>.rrd unless a viewer is asked for).
    #[arg(long)]
    save: Option<PathBuf>,
    /// Start a new Rerun viewer and stream to it.
    #[arg(long)]
    spawn: bool,
    /// Write the comparison (and the sampled traces) as JSON.
    #[arg(long)]
    json: Option<PathBuf>,
    /// Also run this many seeds (the scenario's and the following ones) in parallel and print the
    /// distribution: one realisation of the random walk says little.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..=10_000))]
    seeds: Option<u64>,
}

/// A failure with the exit code it deserves.
struct Failure {
    code: u8,
    message: String,
}

impl From<ConfigError> for Failure {
    fn from(e: ConfigError) -> Self {
        Self { code: 2, message: format!("config error: {e}") }
    }
}

impl From<SinkError> for Failure {
    fn from(e: SinkError) -> Self {
        let code = match e {
            SinkError::Rerun(_) | SinkError::Spawn(_) => 1,
            _ => 2,
        };
        Self { code, message: e.to_string() }
    }
}

impl From<anyhow::Error> for Failure {
    fn from(e: anyhow::Error) -> Self {
        Self { code: 1, message: format!("{e:#}") }
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command.unwrap_or(Command::Run(RunArgs::default())) {
        Command::Run(args) => run_command(&args),
        Command::Live(args) => live_command(&args),
        Command::Calibrate(args) => calibrate_command(&args),
        Command::Montecarlo(args) => montecarlo_command(&args),
        Command::Tpr(args) => tpr_command(&args),
        Command::Events { file } => events_command(&file),
        Command::Modulation { hours, save, spawn } => modulation_command(hours, save, spawn),
        Command::Scenarios => {
            list_scenarios();
            Ok(())
        }
        Command::CheckConfig { file } => check_config(&file),
        Command::Reproduce { markdown } => reproduce_command(markdown.as_deref()),
        Command::Bench { steps } => bench::run(steps).map_err(Failure::from),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(f) => {
            eprintln!("rinscope: {}", f.message);
            ExitCode::from(f.code)
        }
    }
}

fn load(args: &RunArgs) -> Result<Params, Failure> {
    let mut params = args.source.load(scenarios::DEFAULT_SCENARIO)?;
    if let Some(d) = args.duration_s {
        if !(d.is_finite() && d > 0.0 && d * params.step_hz <= 2.0e9) {
            return Err(Failure { code: 2, message: format!("--duration-s {d} s: must be > 0 and at most 2e9 steps at {} Hz", params.step_hz) });
        }
        params.duration_s = d;
    }
    Ok(params)
}

fn run_command(args: &RunArgs) -> Result<(), Failure> {
    let params = load(args)?;
    // The summary file is checked before anything runs, so a typo costs nothing.
    check_output_dir("--summary-json", args.summary_json.as_deref())?;
    let request = SinkRequest { save: args.save.clone(), spawn: args.spawn, connect: args.connect.clone(), ..Default::default() };
    let sinks = open_sinks(request, PathBuf::from("recordings").join(format!("{}.rrd", params.meta.name)), &format!("{}-seed{}", params.meta.name, params.meta.seed))?;

    let stop = Arc::new(AtomicBool::new(false));
    {
        let stop = Arc::clone(&stop);
        // A second Ctrl-C while finishing kills the process the usual way.
        let _ = ctrlc::set_handler(move || {
            if stop.swap(true, Ordering::SeqCst) {
                std::process::exit(130);
            }
        });
    }

    let mut summary = match run::run_recorded(&params, &sinks, &stop, true) {
        Ok(s) => s,
        Err(e) => {
            sinks.abandon();
            return Err(e.into());
        }
    };
    if let Some((path, bytes)) = sinks.finish()? {
        summary.recording_path = Some(path.display().to_string());
        summary.recording_bytes = Some(bytes);
    }
    print!("{}", summary.table());
    if let Some(path) = &args.summary_json {
        write_json("--summary-json", path, &summary)?;
    }
    if let Some(p) = &summary.recording_path {
        println!("open it with:  rerun {p}     (viewer: {})", sink::VIEWER_INSTALL_HINT);
    }
    if summary.interrupted {
        return Err(Failure { code: 130, message: "interrupted: the recording is complete up to the moment of Ctrl-C".into() });
    }
    Ok(())
}

/// Writes `bytes` to `path` through a temporary file and a rename: never a half-written file.
fn write_atomically(path: &std::path::Path, bytes: &[u8]) -> std::io::Result<()> {
    let tmp = sink::partial_path(path);
    std::fs::write(&tmp, bytes)?;
    std::fs::rename(&tmp, path)
}

fn live_command(args: &LiveArgs) -> Result<(), Failure> {
    use std::io::IsTerminal;
    let path = match (&args.config, &args.scenario) {
        (Some(p), _) => p.clone(),
        (None, name) => {
            let name = name.as_deref().unwrap_or(scenarios::DEFAULT_SCENARIO);
            scenarios::load(name)?; // a clear error for an unknown name
            let (path, created) = rinscope::live::ensure_preset_copy(name).map_err(|e| Failure { code: 2, message: format!("{e:#}") })?;
            eprintln!("rinscope live: {} {} — edit it, or move the sliders", if created { "wrote" } else { "using your edited" }, path.display());
            path
        }
    };
    let params = config::load_file(&path)?;
    if let Some(s) = args.speed
        && !(s.is_finite() && s > 0.0 && s <= 10_000.0)
    {
        return Err(Failure { code: 2, message: format!("--speed {s}: must be > 0 and <= 10000 (x real time)") });
    }
    if let Some(d) = args.duration_s
        && !(d.is_finite() && d > 0.0)
    {
        return Err(Failure { code: 2, message: format!("--duration-s {d} s: must be > 0") });
    }
    let viewer_given = args.spawn || args.connect.is_some() || args.serve.is_some();
    if args.no_viewer && args.save.is_none() {
        return Err(Failure { code: 2, message: "--no-viewer needs --save FILE (otherwise nothing would be kept)".into() });
    }
    // Two streams: small chunks for viewers, full-size chunks for the saved file (see live::Outputs).
    let viewer_request = SinkRequest {
        spawn: args.spawn || (!viewer_given && !args.no_viewer),
        connect: args.connect.clone(),
        serve: args.serve,
        ..Default::default()
    };
    let recording_id = format!("{}-seed{}-live", params.meta.name, params.meta.seed);
    let viewer_sinks = if viewer_request.spawn || viewer_request.connect.is_some() || viewer_request.serve.is_some() {
        Some(sink::open(&viewer_request, rinscope::record::APPLICATION_ID, &recording_id)?)
    } else {
        None
    };
    let file_sinks = match &args.save {
        Some(p) => Some(sink::open(&SinkRequest { save: Some(p.clone()), ..Default::default() }, rinscope::record::APPLICATION_ID, &recording_id)?),
        None => None,
    };
    for d in viewer_sinks.iter().chain(file_sinks.iter()).flat_map(|s| &s.description) {
        eprintln!("rinscope live: {d}");
    }
    let panel = !args.no_panel && std::io::stdout().is_terminal() && std::io::stdin().is_terminal();
    let stop = Arc::new(AtomicBool::new(false));
    if !panel {
        let stop = Arc::clone(&stop);
        let _ = ctrlc::set_handler(move || {
            if stop.swap(true, Ordering::SeqCst) {
                std::process::exit(130);
            }
        });
        eprintln!("rinscope live: running; edit {} to change parameters, Ctrl-C to stop", path.display());
    }
    let options = rinscope::live::LiveOptions { config_path: path, speed: args.speed, duration_s: args.duration_s, panel, log_to_stderr: true };
    let outputs = rinscope::live::Outputs { viewer: viewer_sinks.as_ref().map(|s| s.rec.clone()), file: file_sinks.as_ref().map(|s| s.rec.clone()) };
    let result = rinscope::live::run_session(&options, params, outputs, &stop);
    // Whatever happened, complete the saved file: it holds everything simulated so far.
    if let Some(v) = viewer_sinks {
        v.finish().ok();
    }
    let saved = match file_sinks {
        Some(f) => f.finish()?,
        None => None,
    };
    let summary = result?;
    println!(
        "live session: {:.1} s simulated ({} steps), {} reloads applied, save -> applied p95 {:.1} ms",
        summary.sim_t_s,
        summary.steps,
        summary.latencies_ms.len(),
        rinscope::live::p95(&summary.latencies_ms)
    );
    if let Some((p, bytes)) = saved {
        println!("recording: {} ({:.2} MB) — open with `rerun {}`, list its events with `rinscope events {}`", p.display(), bytes as f64 / 1e6, p.display(), p.display());
    }
    Ok(())
}

fn modulation_command(hours: f64, save: Option<PathBuf>, spawn: bool) -> Result<(), Failure> {
    if !(hours.is_finite() && hours > 0.0 && hours <= 24.0 * 30.0) {
        return Err(Failure { code: 2, message: format!("--hours {hours}: must be > 0 and at most 720 h") });
    }
    let sinks = open_sinks(SinkRequest { save, spawn, ..Default::default() }, PathBuf::from("recordings/rotation-modulation.rrd"), "rotation-modulation")?;
    let stop = stop_on_ctrl_c();
    let started = std::time::Instant::now();
    eprintln!("rinscope: simulating {hours} h three times in parallel (no rotation, continuous azimuth, 16-position)...");
    let traces = match rinscope::modulation::run(hours, &stop) {
        Ok(t) => t,
        Err(e) => {
            sinks.abandon();
            return Err(e.into());
        }
    };
    let table = rinscope::modulation::table(&traces, started.elapsed().as_secs_f64());
    if let Err(e) = rinscope::record::modulation::log(&sinks.rec, &traces, &table) {
        sinks.abandon();
        return Err(Failure { code: 1, message: format!("rerun: {e}") });
    }
    let saved = sinks.finish()?;
    print!("{table}");
    print_saved(saved);
    Ok(())
}

fn check_output_dir(flag: &str, path: Option<&std::path::Path>) -> Result<(), Failure> {
    if let Some(dir) = path.and_then(|p| p.parent()).filter(|d| !d.as_os_str().is_empty() && !d.is_dir()) {
        return Err(Failure { code: 2, message: format!("{flag}: directory {} does not exist", dir.display()) });
    }
    Ok(())
}

/// Opens the sinks a command asked for; with no viewer asked for, saves to `default_save`.
fn open_sinks(mut request: SinkRequest, default_save: PathBuf, recording_id: &str) -> Result<sink::OpenSinks, Failure> {
    if request.save.is_none() && !request.spawn && request.connect.is_none() {
        request.save = Some(default_save);
    }
    let sinks = sink::open(&request, rinscope::record::APPLICATION_ID, recording_id)?;
    for d in &sinks.description {
        eprintln!("rinscope: {d}");
    }
    Ok(sinks)
}

/// A flag Ctrl-C sets: long computations stop at their next check and keep what they have.
fn stop_on_ctrl_c() -> Arc<AtomicBool> {
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    let _ = ctrlc::set_handler(move || flag.store(true, Ordering::SeqCst));
    stop
}

/// Writes `value` as pretty JSON to the file given with `flag`, atomically.
fn write_json(flag: &str, path: &std::path::Path, value: &impl serde::Serialize) -> Result<(), Failure> {
    let json = serde_json::to_string_pretty(value).map_err(|e| Failure { code: 1, message: e.to_string() })?;
    write_atomically(path, json.as_bytes()).map_err(|e| Failure { code: 2, message: format!("{flag} {}: {e}", path.display()) })
}

/// The line that tells where a saved recording is and how to open it.
fn print_saved(saved: Option<(PathBuf, u64)>) {
    if let Some((p, bytes)) = saved {
        println!("recording: {} ({:.2} MB) — open with `rerun {}`", p.display(), bytes as f64 / 1e6, p.display());
    }
}

fn calibrate_command(args: &CalibrateArgs) -> Result<(), Failure> {
    let params = args.source.load("jiang2017-calibration")?;
    check_output_dir("--json", args.json.as_deref())?;
    let sinks = if args.no_recording {
        None
    } else {
        let request = SinkRequest { save: args.save.clone(), spawn: args.spawn, ..Default::default() };
        let default_save = PathBuf::from("recordings").join(format!("{}-calibration.rrd", params.meta.name));
        Some(open_sinks(request, default_save, &format!("{}-calibration-seed{}", params.meta.name, params.meta.seed))?)
    };
    let started = std::time::Instant::now();
    let outcome = match rinscope::calib::run(&params, sinks.is_some()) {
        Ok(o) => o,
        Err(e) => {
            if let Some(s) = sinks {
                s.abandon();
            }
            let code = if matches!(e, rinscope::calib::CalibError::VehicleMoves(_)) { 2 } else { 1 };
            return Err(Failure { code, message: format!("calibrate: {e}") });
        }
    };
    let wall = started.elapsed().as_secs_f64();
    print!("{}", outcome.report.text());
    println!("({wall:.2} s wall: two {:.0}-s runs simulated, filter and least squares)", params.duration_s);
    if let Some(path) = &args.json {
        write_json("--json", path, &outcome.report)?;
    }
    if let Some(sinks) = sinks {
        let traces = rinscope::record::calibration::ErrorTraces {
            t_s: outcome.validation.samples.iter().map(|s| s.t_s).collect(),
            errors: [&outcome.validation_errors[0], &outcome.validation_errors[1], &outcome.validation_errors[2]],
        };
        if let Err(e) = rinscope::record::calibration::log(sinks.rec.clone(), &params, &outcome.cal, &outcome.report, &traces) {
            sinks.abandon();
            return Err(Failure { code: 1, message: format!("rerun: {e}") });
        }
        print_saved(sinks.finish()?);
    }
    Ok(())
}

fn montecarlo_command(args: &MonteCarloArgs) -> Result<(), Failure> {
    let mut params = args.source.load("jiang2017-calibration")?;
    check_output_dir("--json", args.json.as_deref())?;
    let runs = args.runs.unwrap_or(params.calibration.montecarlo.runs as usize);
    if runs == 0 || runs > 1_000_000 {
        return Err(Failure { code: 2, message: format!("--runs {runs}: must be 1 ..= 1000000") });
    }
    if let Some(s) = args.eta_measured_sigma_arcsec {
        if !(s.is_finite() && s > 0.0 && s <= 3600.0) {
            return Err(Failure { code: 2, message: format!("--eta-measured-sigma-arcsec {s}: must be > 0 and <= 3600 arcsec") });
        }
        params.calibration.montecarlo.eta_measured_sigma_rad = Some(s * rinscope::units::RAD_PER_ARCSEC);
    }
    let stop = stop_on_ctrl_c();
    let bar = indicatif::ProgressBar::new(runs as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{spinner} {pos}/{len} calibrations [{bar:40}] {elapsed_precise} (eta {eta})")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    let tick = || bar.inc(1);
    let result = rinscope::calib::montecarlo::run(&params, runs, &tick, &stop);
    bar.finish_and_clear();
    let summary = result.map_err(|e| Failure { code: 1, message: format!("montecarlo: {e}") })?;
    print!("{}", summary.text());
    if let Some(path) = &args.json {
        write_json("--json", path, &summary)?;
    }
    if summary.runs < summary.runs_requested {
        return Err(Failure { code: 130, message: format!("interrupted after {} runs (statistics above are over those)", summary.runs) });
    }
    Ok(())
}

fn tpr_command(args: &TprArgs) -> Result<(), Failure> {
    let params = args.source.load("zheng2016-tpr")?;
    check_output_dir("--json", args.json.as_deref())?;
    rinscope::tpr::check(&params).map_err(|e| Failure { code: 2, message: format!("tpr: {e}") })?;
    let request = SinkRequest { save: args.save.clone(), spawn: args.spawn, ..Default::default() };
    let sinks = open_sinks(request, PathBuf::from("recordings").join(format!("{}.rrd", params.meta.name)), &format!("{}-seed{}", params.meta.name, params.meta.seed))?;
    let stop = stop_on_ctrl_c();
    eprintln!("rinscope: navigating {:.1} h (forking at the second fix)...", params.duration_s / 3600.0);
    let result = match rinscope::tpr::run(&params, 60.0, &stop) {
        Ok(r) => r,
        Err(e) => {
            sinks.abandon();
            return Err(Failure { code: 2, message: format!("tpr: {e}") });
        }
    };
    let text = result.text();
    if let Err(e) = rinscope::record::tpr::log(&sinks.rec, &params, &result, &text) {
        sinks.abandon();
        return Err(Failure { code: 1, message: format!("rerun: {e}") });
    }
    let saved = sinks.finish()?;
    print!("{text}");
    if let Some(path) = &args.json {
        write_json("--json", path, &result)?;
    }
    print_saved(saved);
    if !result.complete {
        return Err(Failure { code: 130, message: "interrupted: the recording holds what was simulated".into() });
    }
    if let Some(n) = args.seeds {
        eprintln!("rinscope: {n} seeds from {} in parallel...", params.meta.seed);
        let started = std::time::Instant::now();
        let rows = rinscope::tpr::sweep(&params, n, &stop).map_err(|e| Failure { code: 2, message: format!("tpr: {e}") })?;
        if stop.load(Ordering::SeqCst) {
            return Err(Failure { code: 130, message: "interrupted".into() });
        }
        print!("{}", rinscope::tpr::sweep_text(&rows));
        println!("  {n} runs of {:.1} h in {:.1} s", params.duration_s / 3600.0, started.elapsed().as_secs_f64());
    }
    Ok(())
}

fn events_command(file: &std::path::Path) -> Result<(), Failure> {
    let events = rinscope::record::read::events(file).map_err(|e| Failure { code: 2, message: format!("{e:#}") })?;
    for e in events {
        match e.t_s {
            Some(t) => println!("{t:>10.3} s  {:<5} {}", e.level, e.text),
            None => println!("{:>12}  {:<5} {}", "static", e.level, e.text),
        }
    }
    Ok(())
}

fn list_scenarios() {
    for (name, _) in scenarios::PRESETS {
        match scenarios::load(name) {
            Ok(p) => {
                let mark = if *name == scenarios::DEFAULT_SCENARIO { " (default)" } else { "" };
                println!("{name}{mark}\n    {}", p.meta.title);
            }
            Err(e) => println!("{name}\n    BROKEN: {e}"),
        }
    }
}

fn check_config(file: &std::path::Path) -> Result<(), Failure> {
    let p = config::load_file(file)?;
    let axes: Vec<String> = p.chain.axes().iter().map(|a| a.name.clone()).collect();
    println!(
        "{}: ok — scenario \"{}\", {} s at {} Hz ({} steps), axes {:?}, seed {}",
        file.display(),
        p.meta.name,
        p.duration_s,
        p.step_hz,
        p.steps(),
        axes,
        p.meta.seed
    );
    Ok(())
}

fn reproduce_command(markdown: Option<&std::path::Path>) -> Result<(), Failure> {
    let table = reproduce::run_all()?;
    print!("{}", table.text());
    if let Some(path) = markdown {
        write_atomically(path, table.markdown().as_bytes()).map_err(|e| Failure { code: 2, message: format!("--markdown {}: {e}", path.display()) })?;
    }
    if table.all_agree() {
        Ok(())
    } else {
        Err(Failure { code: 1, message: "some reproductions fall outside their tolerance (see the table)".into() })
    }
}
