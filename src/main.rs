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

#[derive(Args, Default)]
struct RunArgs {
    /// A preset from assets/scenarios (see `rinscope scenarios`).
    #[arg(long, conflicts_with = "config")]
    scenario: Option<String>,
    /// A scenario file.
    #[arg(long)]
    config: Option<PathBuf>,
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
    let mut params = match &args.config {
        Some(path) => config::load_file(path)?,
        None => scenarios::load(args.scenario.as_deref().unwrap_or(scenarios::DEFAULT_SCENARIO))?,
    };
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
    let mut request = SinkRequest { save: args.save.clone(), spawn: args.spawn, connect: args.connect.clone() };
    if request.save.is_none() && !request.spawn && request.connect.is_none() {
        request.save = Some(PathBuf::from("recordings").join(format!("{}.rrd", params.meta.name)));
    }
    // The summary file is checked before anything runs, so a typo costs nothing.
    if let Some(dir) = args.summary_json.as_deref().and_then(|p| p.parent()).filter(|d| !d.as_os_str().is_empty() && !d.is_dir()) {
        return Err(Failure { code: 2, message: format!("--summary-json: directory {} does not exist", dir.display()) });
    }
    let recording_id = format!("{}-seed{}", params.meta.name, params.meta.seed);
    let sinks = sink::open(&request, rinscope::record::APPLICATION_ID, &recording_id)?;
    for d in &sinks.description {
        eprintln!("rinscope: {d}");
    }

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
        let json = serde_json::to_string_pretty(&summary).map_err(|e| Failure { code: 1, message: e.to_string() })?;
        write_atomically(path, json.as_bytes()).map_err(|e| Failure { code: 2, message: format!("--summary-json {}: {e}", path.display()) })?;
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
