//! Layer 9, the command line: clap's view of every command, the sink flags declared once and
//! flattened into each command that records, exit codes. `main` parses and dispatches; the
//! commands' work is in [`commands`] and the layers below.
//!
//! ```text
//! rinscope                                   # embedded default scenario -> recordings/<scenario>.rrd
//! rinscope run --scenario NAME --spawn       # stream to a new viewer (pip install rerun-sdk==0.36.3)
//! rinscope run --config my.toml --save out.rrd --summary-json out.json
//! rinscope allan --scenario static-imu-10h --json adev.json   # or: rinscope allan LOGSET_DIR
//! rinscope scenarios | check-config FILE | reproduce | bench
//! ```
//!
//! Exit codes, one policy for every command (docs/reliability.md):
//!
//! * 0 — success.
//! * 1 — the run failed though its input was good: an output could not be written (disk full,
//!   permission, a recording that did not verify), a viewer failed and nothing kept the data,
//!   `reproduce` outside its tolerance.
//! * 2 — bad input, refused with one message naming it: arguments, a configuration, a log set's
//!   manifest or data (a value that is not a number, too few samples, data an estimator cannot
//!   use), an input that is not a regular file, an output path that cannot be used, a viewer that
//!   cannot be reached.
//! * 128 + the signal when stopped by SIGINT (130), SIGTERM (143) or SIGHUP (129): what was
//!   simulated is saved, and the command says it was cut short; 141 when stdout's reader went away.

mod allan;
mod commands;
mod design;
mod logs;
mod numbers;
mod selfcal;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Args, Parser, Subcommand};

pub(crate) use crate::app::failure::Failure;
use crate::app::outputs::RecordingRequest;
use crate::io::files::{OutputKind, check_output};
use crate::io::validity;
use crate::record::export::ExportFormat;
use crate::record::sink::{self, SinkRequest};
use crate::scenario::{self, ConfigError, Params, presets};
use design::{BudgetArgs, DesignArgs, SchemesArgs};
use numbers::{
    ALIGN_S, ANGLE_DEG, CI_SIGMA, ETA_SIGMA_ARCSEC, HOURS, NAVIGATE_HOURS, POSITION_PART, SPEED, count, duration_s,
    number, port,
};

#[derive(Parser)]
#[command(
    name = "rinscope",
    version,
    about = "See the errors of a rotational inertial navigation system (RINS) in the Rerun viewer"
)]
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
    /// The error budget: which error source causes how much of the INS's attitude, velocity and
    /// position errors and of the table's — the scenario with each source alone, with none and with
    /// all, in parallel; the parts, their sum against the full run, the remainder (default scenario
    /// budget-dual-axis-16, 72 h; docs/budget.md).
    Budget(BudgetArgs),
    /// Rotation schemes side by side on one IMU and table: built-in (none, single-axis-4, continuous,
    /// dual-axis-8/16/32/64) and your own `[scheme]`s, each on the same seeds (a Monte Carlo over the
    /// error draws): position error at 24 h and at the end, peak heading error, degrees turned and
    /// cable wrap (default scenario budget-dual-axis-16; docs/schemes.md).
    Schemes(SchemesArgs),
    /// A rotation-scheme designer: draws indexing sequences under your constraints (axes, moves per
    /// period, angles, rates, dwells, cable wrap), ranks them and the built-ins with an averaged
    /// error model, confirms the best by simulation and prints the winner as a `[scheme]`
    /// (docs/schemes.md).
    Design(DesignArgs),
    /// Rotation modulation: static INS with constant biases, no rotation vs continuous vs 16-position,
    /// simulated together and recorded side by side.
    Modulation(ModulationArgs),
    /// Static calibration of the swing cones and non-orthogonality (Jiang et al. 2017 §5): static Kalman
    /// filter and exact least squares, compensation before/after, a recording with ghost cones
    /// (default scenario: jiang2017-calibration).
    Calibrate(CalibrateArgs),
    /// Jiang et al. 2017's Monte Carlo (Tables 2-3): many calibrations with drawn parameters, in parallel
    /// (default scenario: jiang2017-calibration).
    Montecarlo(MonteCarloArgs),
    /// A scenario over a grid of parameter values (and seeds): every point a whole `run` without
    /// a recording, in parallel on every core; a table of what each gives, and the cost of 1000.
    Sweep(SweepArgs),
    /// Zheng et al. 2016's Twice Position-fix Reset against the conventional reset, from one IMU stream
    /// (default scenario: zheng2016-tpr; needs [imu], [navigation] and two [position_fix] times).
    Tpr(TprArgs),
    /// Calibrate the IMU on its own gimbals: its 21 errors (gyro and accelerometer biases, scale
    /// factors, misalignments) from a calibration sequence, with their 1σ and what the sequence
    /// can see (default scenario selfcal-nav-grade; docs/selfcal.md).
    Selfcal(SelfcalArgs),
    /// Write a scenario as a log set (docs/logs.md): the IMU's measured increments, the encoder
    /// readings and the true attitude at every sample, the table description and the manifest.
    ExportLog(ExportLogArgs),
    /// Replay a log set (or an IMU file with --imu) through the INS and the table models: the same
    /// scene and plots as a simulation, from the files.
    Replay(ReplayArgs),
    /// Allan deviation of a static IMU log, every gyro and accelerometer axis, with the IEEE
    /// 952/1293 coefficients (Q, N, B, K, R) fitted: a log set, or a scenario simulated (default
    /// scenario: static-imu-10h; docs/allan.md).
    Allan(AllanArgs),
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
        #[arg(long, default_value_t = 2_000_000, allow_negative_numbers = true, value_parser = |t: &str| count(t, 1, 1_000_000_000, "steps"))]
        steps: u64,
        /// Instead: measure against a peer, whole processes alternated on the same input (`pyins`:
        /// `rinscope replay` vs python-ins 1.0.1; `allantools`: `rinscope allan --series` vs
        /// allantools 2024.6, per estimator; docs/benchmarks.md).
        #[arg(long, value_parser = ["pyins", "allantools"])]
        peer: Option<String>,
        /// --peer: the Python interpreter that has the peer installed.
        #[arg(long, default_value = "python3")]
        python: PathBuf,
        /// --peer: alternated rounds per stream.
        #[arg(long, default_value_t = 5, allow_negative_numbers = true, value_parser = |t: &str| count(t, 1, 1000, "rounds").map(|n| n as usize))]
        rounds: usize,
        /// --peer: samples per stream (pyins: at 2 kHz; allantools: the series' length).
        #[arg(long, default_value_t = 2_000_000, allow_negative_numbers = true, value_parser = |t: &str| count(t, 2, 1_000_000_000, "samples"))]
        samples: u64,
        /// Also write every figure as JSON (with --peer: every round's numbers), to compare a change
        /// against the last run.
        #[arg(long)]
        json: Option<PathBuf>,
        /// Only these sections (comma-separated): simulation, strapdown, pipeline, navigation,
        /// recorded, calibration, allan. Default: all.
        #[arg(long, value_delimiter = ',', value_parser = crate::app::bench::SECTIONS)]
        only: Vec<String>,
    },
}

/// Where a recording goes, as Rerun's tools spell it; several at once are allowed. With none, a
/// command saves to its default file (`recordings/<scenario>.rrd`).
#[derive(Args, Default, Clone)]
struct SinkArgs {
    /// Save the recording to this .rrd file (default: recordings/<name>.rrd when no viewer is asked for).
    #[arg(long)]
    save: Option<PathBuf>,
    /// Start a new Rerun viewer and stream to it.
    #[arg(long)]
    spawn: bool,
    /// Stream to a running viewer (default URL rerun+http://127.0.0.1:9876/proxy).
    #[arg(long, num_args = 0..=1, default_missing_value = sink::DEFAULT_CONNECT_URL)]
    connect: Option<String>,
    /// Serve the stream over gRPC on this port (default 9876) for native or web viewers.
    #[arg(long, num_args = 0..=1, default_missing_value = "9876", allow_negative_numbers = true, value_parser = port)]
    serve: Option<u16>,
    /// Serve the viewer itself for a browser on this HTTP port (default 9090), with the stream on
    /// the next port: open the printed URL, nothing to install. After a run the page stays until
    /// Ctrl-C. `live`: a class page on this port, the viewer beside the parameters' sliders (the
    /// viewer on the next port, the stream on the one after); it ends with the session.
    #[arg(long, num_args = 0..=1, default_missing_value = "9090", value_name = "PORT", allow_negative_numbers = true, value_parser = port)]
    serve_web: Option<u16>,
    /// --serve / --serve-web: the address to listen on (default 127.0.0.1, this machine only;
    /// 0.0.0.0 shares the session with the whole network: anyone can watch; live's class page
    /// then needs the random token of its printed URL to change a parameter).
    #[arg(long, value_name = "ADDR")]
    bind: Option<std::net::IpAddr>,
    /// Also write the numbers as tables into this folder: every recorded time series (one file per
    /// plot, a t_s column — a replay's also t_file_s, the IMU file's clock —, units in the column
    /// names); allan: its curves and fits (docs/export.md).
    #[arg(long, value_name = "DIR")]
    export: Option<PathBuf>,
    /// Table format of --export: parquet or csv.
    #[arg(long, default_value = "parquet", value_name = "FORMAT")]
    export_format: String,
    /// Also draw every plot of the recording into this folder, as SVG and PNG for reports (the
    /// same titles, names and colours; real logarithmic axes where the viewer plots log10 values).
    /// Drawn from the saved file: with a viewer and no --save, the default file is saved too.
    #[arg(long, value_name = "DIR")]
    figures: Option<PathBuf>,
}

impl SinkArgs {
    /// True if a viewer (spawned, connected or served) was asked for.
    fn viewer_asked(&self) -> bool {
        self.spawn || self.connect.is_some() || self.serve.is_some() || self.serve_web.is_some()
    }

    /// `--export DIR` and its format, if asked for; the folder checked up front by the one output
    /// rule ([`check_output`]).
    fn export_request(&self) -> Result<Option<(PathBuf, ExportFormat)>, Failure> {
        match &self.export {
            None => Ok(None),
            Some(dir) => {
                let format = ExportFormat::parse(&self.export_format)
                    .map_err(|e| Failure::input(format!("--export-format {e}")))?;
                check_output("--export", dir, OutputKind::Folder).map_err(|e| Failure::input(e.to_string()))?;
                Ok(Some((dir.clone(), format)))
            }
        }
    }

    /// Where the command's recording goes: saved under `recordings/` by default when no viewer
    /// was asked for (or `--figures`, which draws from the saved file). `--save`, `--export` and
    /// `--figures` are checked up front by the one output rule ([`check_output`]), before any
    /// work: every command that records gets it here.
    fn recording(&self) -> Result<RecordingRequest, Failure> {
        if let Some(path) = &self.save {
            check_output("--save", path, OutputKind::File).map_err(|e| Failure::input(e.to_string()))?;
        }
        if let Some(dir) = &self.figures {
            check_output("--figures", dir, OutputKind::Folder).map_err(|e| Failure::input(e.to_string()))?;
        }
        let export = self.export_request()?;
        if self.bind.is_some() && self.serve.is_none() && self.serve_web.is_none() {
            return Err(Failure::input("--bind ADDR goes with --serve or --serve-web"));
        }
        let sinks = SinkRequest {
            save: self.save.clone(),
            spawn: self.spawn,
            connect: self.connect.clone(),
            serve: self.serve,
            bind: self.bind,
            serve_web: self.serve_web,
            serve_web_history: None,
            export,
            figures: self.figures.clone(),
            stop_on_failure: Some(crate::app::terminate::stop_flag()),
            tables_in_memory: false,
        };
        Ok(RecordingRequest { sinks, save_by_default: !self.viewer_asked() || self.figures.is_some() })
    }
}

/// Where a command's scenario comes from (each command has its own default preset).
#[derive(Args, Default)]
struct ScenarioSource {
    /// A preset from assets/scenarios (see `rinscope scenarios`).
    #[arg(long, conflicts_with = "config")]
    scenario: Option<String>,
    /// A scenario file.
    #[arg(long)]
    config: Option<PathBuf>,
}

impl ScenarioSource {
    /// The scenario file if given, else the named preset, else `default`.
    fn load(&self, default: &str) -> Result<Params, ConfigError> {
        match &self.config {
            Some(path) => scenario::load_file(path),
            None => presets::load(self.scenario.as_deref().unwrap_or(default)),
        }
    }
}

#[derive(Args, Default)]
struct RunArgs {
    #[command(flatten)]
    source: ScenarioSource,
    #[command(flatten)]
    sinks: SinkArgs,
    /// Write RMS and peak errors, duration, steps and wall time as JSON.
    #[arg(long)]
    summary_json: Option<PathBuf>,
    /// Override the scenario's simulated duration, s.
    #[arg(long, allow_negative_numbers = true, value_parser = duration_s)]
    duration_s: Option<f64>,
    /// Compensate with a compensation document (`calibrate --json`, `selfcal --json`): its table
    /// part replaces the scenario's [compensation] keys it names, its IMU part is removed from
    /// every sample (docs/selfcal.md).
    #[arg(long, value_name = "FILE")]
    compensation: Option<PathBuf>,
}

#[derive(Args)]
struct LiveArgs {
    /// A preset: an editable copy is written to rinscope-live/<name>.toml (kept if it exists).
    #[arg(long, conflicts_with = "config")]
    scenario: Option<String>,
    /// The scenario file to run and watch.
    #[arg(long)]
    config: Option<PathBuf>,
    #[command(flatten)]
    sinks: SinkArgs,
    /// Simulated seconds per wall-clock second (default: the file's [live] speed, else 1).
    #[arg(long, allow_negative_numbers = true, value_parser = |t: &str| number(t, &SPEED))]
    speed: Option<f64>,
    /// Stop after this much simulated time, s (default: run until you quit).
    #[arg(long, allow_negative_numbers = true, value_parser = duration_s)]
    duration_s: Option<f64>,
    /// No viewer: only --save (for headless sessions and tests).
    #[arg(long, conflicts_with_all = ["spawn", "connect", "serve"])]
    no_viewer: bool,
    /// No terminal panel (edit the file by hand; Ctrl-C ends the session).
    #[arg(long)]
    no_panel: bool,
    /// Compensate with a compensation document (`calibrate --json`, `selfcal --json`): its table
    /// part is written into the config's [compensation] keys (the sliders, the editor and
    /// "calibrate now" take it from there), its IMU part is removed from every sample the INS
    /// reads for the whole session (docs/live.md).
    #[arg(long, value_name = "FILE")]
    compensation: Option<PathBuf>,
}

#[derive(Args)]
struct ModulationArgs {
    /// Simulated hours.
    #[arg(long, default_value_t = 24.0, allow_negative_numbers = true, value_parser = |t: &str| number(t, &HOURS))]
    hours: f64,
    #[command(flatten)]
    sinks: SinkArgs,
}

#[derive(Args)]
struct CalibrateArgs {
    // Default jiang2017-calibration: a static vehicle; its [calibration] section, or the defaults.
    #[command(flatten)]
    source: ScenarioSource,
    #[command(flatten)]
    sinks: SinkArgs,
    /// Calibrate a log set's static test instead of simulating one (its [reference] gives the
    /// known attitude).
    #[arg(long, value_name = "DIR", conflicts_with_all = ["scenario", "config"])]
    log: Option<PathBuf>,
    /// Write the estimates, 1σ, observability, compensation and the estimates as [compensation]
    /// keys (for replay --compensation) as JSON.
    #[arg(long)]
    json: Option<PathBuf>,
    /// No recording (print and JSON only).
    #[arg(long, conflicts_with_all = ["save", "spawn", "connect", "serve"])]
    no_recording: bool,
}

#[derive(Args)]
struct ExportLogArgs {
    #[command(flatten)]
    source: ScenarioSource,
    /// The new folder to write (refused if it exists).
    #[arg(long)]
    out: PathBuf,
    /// File format: csv, npy or parquet.
    #[arg(long, default_value = "csv")]
    format: String,
    /// Leave the initial attitude out of the manifest: the replay aligns on the data (as on a real
    /// log) instead of starting from the simulation's truth.
    #[arg(long)]
    no_initial_attitude: bool,
}

#[derive(Args)]
struct ReplayArgs {
    /// The log set's folder (with log.toml).
    #[arg(conflicts_with = "imu")]
    dir: Option<PathBuf>,
    #[command(flatten)]
    sinks: SinkArgs,
    /// Write the errors' RMS and peak, navigation, gaps and wall time as JSON.
    #[arg(long)]
    summary_json: Option<PathBuf>,
    /// Compensate with a calibration's estimates (`calibrate --json FILE`) instead of the table
    /// description's [compensation].
    #[arg(long, value_name = "FILE")]
    compensation: Option<PathBuf>,
    /// Without a log set: an IMU file (.csv, .txt, .npy, .parquet, .mcap, PSINS .imu).
    #[arg(long)]
    imu: Option<PathBuf>,
    /// --imu: its layout: rinscope, psins, psins-imu, kf-gins, kalibr, npy7, ros2 (default from the
    /// extension and the content).
    #[arg(long, requires = "imu")]
    imu_layout: Option<String>,
    /// --imu: increments or rates.
    #[arg(long, requires = "imu")]
    imu_kind: Option<String>,
    /// --imu: the file's axes (rfu, frd, flu, ...).
    #[arg(long, requires = "imu")]
    imu_frame: Option<String>,
    /// --imu: the sample rate, Hz (default: a PSINS header's, else what the time stamps say).
    #[arg(long, requires = "imu", allow_negative_numbers = true, value_parser = |t: &str| number(t, &validity::IMU_RATE_HZ))]
    rate_hz: Option<f64>,
    /// --imu: the table description (the [site], [turntable], [imu], ... sections of a scenario);
    /// without one the IMU is strapdown (its axes are the body's).
    #[arg(long, requires = "imu")]
    table: Option<PathBuf>,
    /// --imu: an encoder file (t_s and <axis>_deg columns).
    #[arg(long, requires = "imu")]
    encoders: Option<PathBuf>,
    /// The body attitude at the start [pitch, roll, heading], deg: the INS starts from it instead
    /// of aligning (a moving start, or a known attitude).
    #[arg(long, num_args = 3, value_names = ["PITCH", "ROLL", "HEADING"], allow_negative_numbers = true, value_parser = |t: &str| number(t, &ANGLE_DEG))]
    attitude_deg: Option<Vec<f64>>,
    /// A constant reference attitude of the body [pitch, roll, heading], deg, to measure the errors
    /// against (a vehicle at rest whose attitude is known); also the start, unless --attitude-deg.
    #[arg(long, num_args = 3, value_names = ["PITCH", "ROLL", "HEADING"], allow_negative_numbers = true, value_parser = |t: &str| number(t, &ANGLE_DEG))]
    reference_attitude_deg: Option<Vec<f64>>,
    /// The velocity at the start [East, North, Up], m/s (a moving start; needs --attitude-deg).
    #[arg(long, num_args = 3, value_names = ["EAST", "NORTH", "UP"], allow_negative_numbers = true, value_parser = |t: &str| number(t, &validity::VELOCITY_MPS))]
    velocity_enu_mps: Option<Vec<f64>>,
    /// The position at the start [latitude deg, longitude deg, height m] (the site).
    #[arg(long, num_args = 3, value_names = ["LAT_DEG", "LON_DEG", "HEIGHT_M"], allow_negative_numbers = true, value_parser = |t: &str| number(t, &POSITION_PART))]
    position: Option<Vec<f64>>,
    /// Replay from this time on the IMU file's clock (as written in its time column), s.
    #[arg(long, value_name = "T_S", allow_negative_numbers = true, value_parser = |t: &str| number(t, &validity::CLOCK_S))]
    from: Option<f64>,
    /// Replay up to this time on the IMU file's clock, s.
    #[arg(long, value_name = "T_S", allow_negative_numbers = true, value_parser = |t: &str| number(t, &validity::CLOCK_S))]
    to: Option<f64>,
    /// Align over the first this many seconds, declared at rest (default: the rest the data show,
    /// at most 300 s).
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true, value_parser = |t: &str| number(t, &ALIGN_S))]
    align_s: Option<f64>,
}

#[derive(Args)]
struct AllanArgs {
    /// A log set's folder (with log.toml) to analyse instead of simulating a scenario.
    #[arg(conflicts_with_all = ["scenario", "config", "duration_s", "series"])]
    dir: Option<PathBuf>,
    /// Any series instead: a table file (CSV/text, .npy, Parquet) whose --column(s) to analyse,
    /// sampled at --rate-hz or stamped by --time-column. No log set, no table.toml.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["scenario", "config", "duration_s", "errors_only"], requires = "column")]
    series: Option<PathBuf>,
    /// With --series: COLUMN:KIND[:UNIT], repeatable. COLUMN a header name or a 0-based position;
    /// KIND rate (deg/s, deg/h, rad/s, m/s2, g, mg, ug), increment (rad, deg, arcsec, m/s, s),
    /// phase (s, ns, ps; rad, deg; m/s) or frequency (fractional: 1, ppm, ppb, ppt).
    /// E.g. gyro_z:rate:deg/s, 2:frequency, x:phase:ns.
    #[arg(long, value_name = "COLUMN:KIND[:UNIT]", requires = "series")]
    column: Vec<String>,
    /// With --series: the sample rate, Hz (or --time-column).
    #[arg(long, value_name = "HZ", requires = "series", conflicts_with = "time_column", allow_negative_numbers = true, value_parser = |t: &str| number(t, &validity::SERIES_RATE_HZ))]
    rate_hz: Option<f64>,
    /// With --series: the column of sample times, COLUMN[:UNIT] (unit s, ms, us, ns; default s);
    /// the samples must be evenly spaced (to 1 %).
    #[arg(long, value_name = "COLUMN[:UNIT]", requires = "series")]
    time_column: Option<String>,
    /// The estimators, comma-separated, as Stable32 and allantools name them: adev, oadev
    /// (default), mdev, tdev, hdev, ohdev, totdev, or all. The IEEE coefficients are always read
    /// from the overlapping Allan variance (IEEE 952 defines them on it).
    #[arg(long, value_name = "LIST", default_value = "oadev")]
    estimator: String,
    /// Cluster times: octave (m = 1, 2, 4, ...; default), decade (1, 2, 4, 10, 20, 40, ...),
    /// all (every m), or N per decade.
    #[arg(long, value_name = "SET", conflicts_with = "per_decade")]
    taus: Option<String>,
    // Default static-imu-10h.
    #[command(flatten)]
    source: ScenarioSource,
    #[command(flatten)]
    sinks: SinkArgs,
    /// Write the curves, their confidence bounds and EDF, the fitted and configured coefficients as JSON.
    #[arg(long)]
    json: Option<PathBuf>,
    /// Override the scenario's simulated duration, s.
    #[arg(long, allow_negative_numbers = true, value_parser = duration_s)]
    duration_s: Option<f64>,
    /// Cluster times per decade (the same as --taus N).
    #[arg(long, value_name = "N", allow_negative_numbers = true, value_parser = |t: &str| count(t, 1, 1000, "cluster times per decade").map(|n| n as u32))]
    per_decade: Option<u32>,
    /// Sum this many samples into one before the analysis (a long, fast log in less memory).
    #[arg(long, default_value_t = 1, value_name = "N", allow_negative_numbers = true, value_parser = |t: &str| count(t, 1, 1_000_000, "samples").map(|n| n as usize))]
    decimate: usize,
    /// Half-width of the confidence intervals, normal sigmas (1: 68.3 %).
    #[arg(long, default_value_t = 1.0, value_name = "Z", allow_negative_numbers = true, value_parser = |t: &str| number(t, &CI_SIGMA))]
    ci_sigma: f64,
    /// A simulation: analyse the sensor errors alone (output − truth), e.g. of a scenario whose
    /// table turns (zheng2016-tpr); default: what the IMU outputs, as a static test logs it.
    #[arg(long)]
    errors_only: bool,
    /// No recording (print and JSON only).
    #[arg(long, conflicts_with_all = ["save", "spawn", "connect", "serve"])]
    no_recording: bool,
}

#[derive(Args)]
#[command(args_conflicts_with_subcommands = true)]
struct MonteCarloArgs {
    #[command(subcommand)]
    action: Option<MonteCarloAction>,
    // Default jiang2017-calibration.
    #[command(flatten)]
    source: ScenarioSource,
    /// Number of runs (default: [calibration.montecarlo] runs).
    #[arg(long, allow_negative_numbers = true, value_parser = |t: &str| count(t, 1, 1_000_000, "runs").map(|n| n as usize))]
    runs: Option<usize>,
    /// Give the filter an independent measurement of η with this 1σ, arcsec.
    #[arg(long, allow_negative_numbers = true, value_parser = |t: &str| number(t, &ETA_SIGMA_ARCSEC))]
    eta_measured_sigma_arcsec: Option<f64>,
    /// Run only the runs i with i mod M == K (K/M, K from 0), seeded as in the whole run; --json
    /// then writes the shard file that `montecarlo merge` combines (cluster array jobs).
    #[arg(long, value_name = "K/M")]
    shard: Option<String>,
    /// Write the statistics (with --shard: the shard file) as JSON.
    #[arg(long)]
    json: Option<PathBuf>,
}

#[derive(Subcommand)]
enum MonteCarloAction {
    /// Combine shard files into the statistics of the whole run (identical to running it unsharded,
    /// but for wall time).
    Merge {
        /// The shard files (`--shard K/M --json FILE` of every K).
        #[arg(required = true)]
        files: Vec<PathBuf>,
        // The scenario the shards ran (default jiang2017-calibration).
        #[command(flatten)]
        source: ScenarioSource,
        /// The η measurement the shards were given, arcsec.
        #[arg(long, allow_negative_numbers = true, value_parser = |t: &str| number(t, &ETA_SIGMA_ARCSEC))]
        eta_measured_sigma_arcsec: Option<f64>,
        /// Write the merged statistics as JSON.
        #[arg(long)]
        json: Option<PathBuf>,
    },
}

#[derive(Args)]
struct TprArgs {
    // Default zheng2016-tpr.
    #[command(flatten)]
    source: ScenarioSource,
    #[command(flatten)]
    sinks: SinkArgs,
    /// Write the comparison (and the sampled traces) as JSON.
    #[arg(long)]
    json: Option<PathBuf>,
    /// Also run this many seeds (the scenario's and the following ones) in parallel and print the
    /// distribution: one realisation of the random walk says little.
    #[arg(long, value_name = "N", allow_negative_numbers = true, value_parser = clap::value_parser!(u64).range(1..=10_000))]
    seeds: Option<u64>,
}

#[derive(Args)]
struct SweepArgs {
    // Default jiang2017-dual-axis (the default scenario).
    #[command(flatten)]
    source: ScenarioSource,
    /// KEY=V1,V2,...: a scenario key and its values (e.g. turntable.axis[1].swing_half_angle_arcsec=0,300,600);
    /// repeated, the grid is every combination.
    #[arg(long = "vary", value_name = "KEY=V1,V2,...", value_parser = crate::app::sweep::parse_vary)]
    vary: Vec<(String, Vec<f64>)>,
    /// Also this many consecutive seeds from the scenario's at every point.
    #[arg(long, default_value_t = 1, allow_negative_numbers = true, value_parser = clap::value_parser!(u64).range(1..=100_000))]
    seeds: u64,
    /// Override every run's simulated duration, s.
    #[arg(long, allow_negative_numbers = true, value_parser = duration_s)]
    duration_s: Option<f64>,
    /// Threads (default: every core).
    #[arg(long, allow_negative_numbers = true, value_parser = clap::value_parser!(u64).range(1..=4096))]
    threads: Option<u64>,
    /// Write every point's values and run summary as JSON.
    #[arg(long)]
    json: Option<PathBuf>,
    /// Only the runs whose index is K modulo M (a cluster's array job; needs --json), for --merge.
    #[arg(long, value_name = "K/M", requires = "json")]
    shard: Option<String>,
    /// Merge the shards' JSON files into the whole sweep (with --json: its document).
    #[arg(long, value_name = "FILES", num_args = 1.., conflicts_with_all = ["vary", "shard", "scenario", "config"])]
    merge: Vec<PathBuf>,
}

#[derive(Args)]
struct SelfcalArgs {
    // Default selfcal-nav-grade.
    #[command(flatten)]
    source: ScenarioSource,
    /// Calibrate from a log set instead (docs/logs.md): the IMU file of a sequence run on a vehicle
    /// at rest, starting with at least 60 s at rest; the table description's [imu] is the datasheet.
    #[arg(long, value_name = "DIR", conflicts_with_all = ["scenario", "config", "plan", "monte_carlo"])]
    log: Option<PathBuf>,
    /// The sequence: positions-19, dual-axis-29, azimuth-only (a degenerate one), or scenario (the
    /// scenario's indexed [scheme], for its simulation.duration_s).
    #[arg(long, default_value = "dual-axis-29")]
    sequence: String,
    /// Also calibrate this many random IMUs (seeds after the scenario's, on every core) and
    /// compare each parameter's reported 1σ with the spread of its errors.
    #[arg(long, value_name = "N", allow_negative_numbers = true, value_parser = clap::value_parser!(u64).range(crate::app::selfcal::MONTE_CARLO_RUNS))]
    monte_carlo: Option<u64>,
    /// Only the plan: what the sequence can see, from its noise-free motion (no IMU drawn).
    #[arg(long)]
    plan: bool,
    /// With --monte-carlo N: run only this slice K/M of the N runs (0 ≤ K < M; a cluster's array
    /// task) and write them to --json for --merge (docs/cluster.md).
    #[arg(long, value_name = "K/M", requires_all = ["monte_carlo", "json"], conflicts_with_all = ["log", "plan"])]
    shard: Option<String>,
    /// Merge the shard files of one `--monte-carlo N --shard K/M` into the whole Monte Carlo's
    /// statistics (the same numbers as unsharded).
    #[arg(long, value_name = "SHARD_FILE", num_args = 1.., conflicts_with_all = ["log", "plan", "monte_carlo", "shard", "scenario", "config"])]
    merge: Vec<PathBuf>,
    /// Leave the encoders out: the IMU's 21 errors from its own navigation alone, the table's not
    /// estimated (the comparison for what the encoders add; docs/selfcal.md).
    #[arg(long)]
    without_encoders: bool,
    /// What it buys: the same IMU navigates this many hours free-inertial, at rest and under the
    /// 16-position modulation, with no, estimated and true compensation (0: skip).
    #[arg(long, default_value_t = 24.0, value_name = "HOURS", allow_negative_numbers = true, value_parser = |t: &str| number(t, &NAVIGATE_HOURS))]
    navigate_hours: f64,
    #[command(flatten)]
    sinks: SinkArgs,
    /// No recording (the table and --json only).
    #[arg(long)]
    no_recording: bool,
    /// Write the result (estimates, 1σ, truth, observability, Monte Carlo) as JSON.
    #[arg(long)]
    json: Option<PathBuf>,
}

use crate::app::bench::Benchmark;
use crate::app::bench::peer::PeerOptions;

/// Parses the command line, runs the command, maps its outcome to an exit code.
#[must_use]
pub fn main() -> ExitCode {
    ExitCode::from(main_with(std::env::args_os()))
}

/// [`main`] on the command line `args` (the program's name first), its exit code as a number:
/// what the Python package's `rinscope` command runs. `--help`, `--version` and a malformed
/// command line end the process, as clap does.
#[must_use]
pub fn main_with<I, T>(args: I) -> u8
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    let cli = Cli::parse_from(args);
    let result = match cli.command.unwrap_or(Command::Run(RunArgs::default())) {
        Command::Run(args) => commands::run(&args),
        Command::Live(args) => commands::live(&args),
        Command::Calibrate(args) => commands::calibrate(&args),
        Command::Montecarlo(args) => commands::montecarlo(&args),
        Command::Tpr(args) => commands::tpr(&args),
        Command::Sweep(args) => commands::sweep(&args),
        Command::Selfcal(args) => selfcal::selfcal(&args),
        Command::Events { file } => commands::events(&file),
        Command::ExportLog(args) => logs::export_log(&args),
        Command::Replay(args) => logs::replay(&args),
        Command::Allan(args) => allan::allan(&args),
        Command::Budget(args) => design::budget(&args),
        Command::Schemes(args) => design::schemes(&args),
        Command::Design(args) => design::design(&args),
        Command::Modulation(args) => commands::modulation(&args),
        Command::Scenarios => {
            commands::list_scenarios();
            Ok(())
        }
        Command::CheckConfig { file } => commands::check_config(&file),
        Command::Reproduce { markdown } => commands::reproduce(markdown.as_deref()),
        Command::Bench { steps, peer: None, json, only, .. } => commands::bench(Benchmark::Own { steps, only }, json),
        Command::Bench { peer: Some(peer), python, rounds, samples, json, .. } if peer == "allantools" => {
            commands::bench(Benchmark::Allantools { python, rounds, samples }, json)
        }
        Command::Bench { peer: Some(_), python, rounds, samples, json, .. } => {
            commands::bench(Benchmark::Pyins(PeerOptions { python, rounds, samples }), json)
        }
    };
    match result {
        Ok(()) => 0,
        Err(f) => {
            errln!("rinscope: {}", f.message);
            f.code
        }
    }
}
