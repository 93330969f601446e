//! `rinscope allan`: a static IMU log gathered into the six channels' cumulative sums — simulated
//! from a scenario's `[imu]`, or read from a log set — and analysed the IEEE way (`ins::allan`,
//! docs/allan.md). Memory: 8 bytes per sample and channel (10 h at 200 Hz: 346 MB).

mod command;
pub use command::{AllanCommand, AllanExport, AllanReport, AllanSource, execute};

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use nalgebra::Vector3;

use super::playback::{ImuItem, ImuSamples, PlaybackError};
use crate::ins::InsParams;
use crate::ins::allan::{ChannelError, ImuAllan, Sensor, Truth, analyze_channel, analyze_imu};
use crate::io::imu::series::{Sampling, SeriesColumn, read_series_until};
use crate::io::imu::units::Quantity;
use crate::math::allan::estimators::Estimator;
use crate::math::allan::{AllanOptions, MIN_SAMPLES, Phase, TauSpacing, averaging_factors};
use crate::math::units::RAD_PER_DEG;
use crate::scenario::Params;
use crate::scenario::logset::LogSet;

/// The cluster times `text` asks for: octave, decade, all, or N per decade (1 ..= 1000).
///
/// # Errors
/// Anything else, quoted.
pub fn parse_taus(text: &str) -> Result<TauSpacing, String> {
    match text.trim() {
        "octave" => Ok(TauSpacing::Octave),
        "decade" => Ok(TauSpacing::Decade),
        "all" => Ok(TauSpacing::All),
        t => match t.parse::<u32>() {
            Ok(n) if (1..=1000).contains(&n) => Ok(TauSpacing::PerDecade(n)),
            _ => Err(format!("{t:?}: give octave, decade, all, or a number of cluster times per decade (1 ..= 1000)")),
        },
    }
}

/// The estimators of a comma-separated list of Stable32's names, or all.
///
/// # Errors
/// A name that is not an estimator, quoted.
pub fn parse_estimators(text: &str) -> Result<Vec<Estimator>, String> {
    if text.trim() == "all" {
        return Ok(Estimator::ALL.to_vec());
    }
    let mut list = Vec::new();
    for name in text.split(',').map(str::trim).filter(|n| !n.is_empty()) {
        let e = Estimator::parse(&name.to_lowercase()).ok_or_else(|| {
            format!("{name:?} is not an estimator (adev, oadev, mdev, tdev, hdev, ohdev, totdev, or all)")
        })?;
        if !list.contains(&e) {
            list.push(e);
        }
    }
    Ok(list)
}

/// How to analyse.
#[derive(Debug, Clone, PartialEq)]
pub struct AllanRequest {
    /// Cluster times (`--taus`).
    pub spacing: TauSpacing,
    /// The curves asked for (`--estimator`; OADEV, with the IEEE fit, by default).
    pub estimators: Vec<Estimator>,
    /// Sum this many samples into one first (1: none).
    pub decimate: usize,
    /// Half-width of the confidence intervals, normal sigmas.
    pub ci_sigma: f64,
    /// A simulation: analyse the sensor errors alone (output − truth), so that a scenario whose
    /// table moves can be characterised; else what the IMU outputs, as a static test logs it.
    pub errors_only: bool,
}

impl Default for AllanRequest {
    fn default() -> Self {
        Self {
            spacing: TauSpacing::Octave,
            estimators: vec![Estimator::Oadev],
            decimate: 1,
            ci_sigma: 1.0,
            errors_only: false,
        }
    }
}

/// Why the analysis cannot be done.
#[derive(Debug, thiserror::Error)]
pub enum AllanRunError {
    /// The scenario or the request does not allow it.
    #[error("{0}")]
    Config(String),
    /// The log set's files.
    #[error("{0}")]
    Data(#[from] PlaybackError),
    /// A channel's analysis.
    #[error("{0}")]
    Analysis(#[from] ChannelError),
    /// Stopped before enough samples were gathered.
    #[error("stopped after {0} samples, too few to analyse")]
    Interrupted(usize),
}

/// The largest memory the cumulative sums may take, bytes (beyond it, --decimate).
const MAX_PHASE_BYTES: f64 = 16e9;

/// Angular rate over one second above which the IMU is taken to have turned, rad/s.
const MOTION_RAD_PER_S: f64 = 0.5 * RAD_PER_DEG;

/// The six channels being gathered: decimation, the cumulative sums, a motion check.
struct Gather {
    phases: Vec<Phase>,
    decimate: usize,
    block: [f64; 6],
    in_block: usize,
    /// Samples per second (the motion check's window) and the running second.
    per_second: usize,
    window_s: f64,
    second: Vector3<f64>,
    in_second: usize,
    max_rate_rad_per_s: f64,
}

impl Gather {
    fn new(expected: usize, decimate: usize, rate_hz: f64) -> Self {
        Self {
            phases: (0..6).map(|_| Phase::with_capacity(expected / decimate + 1)).collect(),
            decimate,
            block: [0.0; 6],
            in_block: 0,
            per_second: (rate_hz.round() as usize).max(1),
            window_s: (rate_hz.round()).max(1.0) / rate_hz,
            second: Vector3::zeros(),
            in_second: 0,
            max_rate_rad_per_s: 0.0,
        }
    }

    #[inline]
    fn push(&mut self, dtheta: &Vector3<f64>, dv: &Vector3<f64>) {
        self.second += dtheta;
        self.in_second += 1;
        if self.in_second == self.per_second {
            self.max_rate_rad_per_s = self.max_rate_rad_per_s.max(self.second.amax() / self.window_s);
            self.second = Vector3::zeros();
            self.in_second = 0;
        }
        if self.decimate == 1 {
            for i in 0..3 {
                self.phases[i].push(dtheta[i]);
                self.phases[3 + i].push(dv[i]);
            }
            return;
        }
        for i in 0..3 {
            self.block[i] += dtheta[i];
            self.block[3 + i] += dv[i];
        }
        self.in_block += 1;
        if self.in_block == self.decimate {
            for (p, b) in self.phases.iter_mut().zip(self.block.iter_mut()) {
                p.push(*b);
                *b = 0.0;
            }
            self.in_block = 0;
        }
    }

    fn len(&self) -> usize {
        self.phases[0].len()
    }
}

/// `--ci-sigma`: > 0 and at most 3 normal sigmas (99.7 %: wider intervals say nothing more of a
/// curve).
pub const CI_SIGMA: crate::io::validity::Range =
    crate::io::validity::Range::positive(3.0, "σ", "a confidence half-width");

/// The analysis options of a request, checked.
///
/// # Errors
/// A decimation, confidence width or spacing out of range, named by its flag.
pub fn options(req: &AllanRequest) -> Result<AllanOptions, AllanRunError> {
    if req.decimate == 0 || req.decimate > 1_000_000 {
        return Err(AllanRunError::Config(format!("--decimate {}: must be 1 ..= 1000000 samples", req.decimate)));
    }
    crate::io::validity::check_number(req.ci_sigma, &CI_SIGMA)
        .map_err(|e| AllanRunError::Config(format!("--ci-sigma {e}")))?;
    if req.spacing == TauSpacing::PerDecade(0) {
        return Err(AllanRunError::Config(
            "--taus 0: give at least 1 cluster time per decade (or octave, decade, all)".into(),
        ));
    }
    if req.estimators.is_empty() {
        return Err(AllanRunError::Config(
            "--estimator: name at least one (adev, oadev, mdev, tdev, hdev, ohdev, totdev, or all)".into(),
        ));
    }
    Ok(AllanOptions { spacing: req.spacing.clone(), ci_sigma: req.ci_sigma, ..AllanOptions::default() })
}

/// Most series points × cluster times the analysis takes on (about a minute on one core).
const MAX_WORK: f64 = 3e10;

/// Refuses a τ set whose cost is out of reach (`--taus all` on millions of samples), naming the
/// way out.
fn check_work(n: usize, opts: &AllanOptions, req: &AllanRequest) -> Result<(), AllanRunError> {
    let taus = averaging_factors(n / opts.min_clusters.max(2), &opts.spacing)
        .map_err(|e| AllanRunError::Config(e.to_string()))?
        .len();
    let work = n as f64 * taus as f64 * req.estimators.len().max(1) as f64;
    if work > MAX_WORK {
        return Err(AllanRunError::Config(format!(
            "{taus} cluster times × {n} samples × {} estimator(s) = {work:.1e} operations, beyond the {MAX_WORK:.0e} this command takes on: give --taus octave, decade or N per decade, or --decimate",
            req.estimators.len()
        )));
    }
    Ok(())
}

/// The configured noise of an `[imu]` (None if it configures none: nothing to compare with).
fn truth_of(ins: &InsParams) -> Option<[Truth; 2]> {
    let t = [Truth::gyro(&ins.errors.gyro), Truth::accel(&ins.errors.accel)];
    t.iter().any(|t| t.terms.is_active() || t.has_markov()).then_some(t)
}

/// The notes every analysis carries: motion, how short the log is.
fn common_notes(g: &Gather, rate_hz: f64) -> Vec<String> {
    let mut notes = Vec::new();
    if g.max_rate_rad_per_s > MOTION_RAD_PER_S {
        notes.push(format!(
            "the IMU turned (up to {:.2}°/s over one second): the motion is in the curves. The Allan deviation characterises a sensor at rest (or at a constant rate).",
            g.max_rate_rad_per_s / RAD_PER_DEG
        ));
    }
    let hours = g.len() as f64 * g.decimate as f64 / rate_hz / 3600.0;
    if hours < 2.0 {
        notes.push(format!("{hours:.2} h of data: a rate random walk K needs hours to be read to 10 % (docs/allan.md), so a short log may not show it."));
    }
    notes
}

/// The scenario's IMU, or why it cannot be analysed.
///
/// # Errors
/// A scenario without an `[imu]` section.
pub fn check_scenario(params: &Params) -> Result<&InsParams, AllanRunError> {
    params.ins.as_ref().ok_or_else(|| AllanRunError::Config(format!("{}: needs an [imu] section (the Allan deviation is of the IMU's noise; see assets/scenarios/static-imu-10h.toml)", params.meta.name)))
}

/// Simulates `params`' IMU at rest for its duration and analyses it.
///
/// # Errors
/// No `[imu]`, a bad request, a stop before enough samples, a channel that cannot be analysed.
pub fn simulate(
    params: &Params,
    req: &AllanRequest,
    stop: &AtomicBool,
    progress: &dyn Fn(u64),
) -> Result<ImuAllan, AllanRunError> {
    let ins = check_scenario(params)?;
    let opts = options(req)?;
    let steps = params.timeline().intervals();
    let bytes = 48.0 * steps as f64 / req.decimate as f64;
    if bytes > MAX_PHASE_BYTES {
        return Err(AllanRunError::Config(format!(
            "{}: {steps} samples would need {:.1} GB for the six channels' sums; give --decimate {} (or more) or a shorter --duration-s",
            params.meta.name,
            bytes / 1e9,
            (bytes / MAX_PHASE_BYTES).ceil()
        )));
    }
    let started = Instant::now();
    let mut run = crate::ins::pipeline::InsRun::new(ins, params.site, params.meta.seed, params.table_model());
    let mut g = Gather::new(steps as usize, req.decimate, ins.rate_hz);
    let mut interrupted = false;
    for i in 0..steps {
        if req.errors_only {
            let (_, dtheta, dv, true_dtheta, true_dv) = run.next_measurement_and_truth();
            g.push(&(dtheta - true_dtheta), &(dv - true_dv));
        } else {
            let (_, dtheta, dv) = run.next_measurement();
            g.push(&dtheta, &dv);
        }
        if i % 200_000 == 199_999 {
            progress(i + 1);
            if stop.load(Ordering::Relaxed) {
                interrupted = true;
                break;
            }
        }
    }
    progress(steps);
    let gather_s = started.elapsed().as_secs_f64();
    let mut notes = common_notes(&g, ins.rate_hz);
    if g.max_rate_rad_per_s > MOTION_RAD_PER_S {
        notes.push(
            "--errors-only analyses the simulated sensor errors alone (output − truth), without the motion.".into(),
        );
    }
    let (sat_g, sat_a) = run.saturation_counts();
    if sat_g.iter().chain(&sat_a).any(|n| *n > 0) {
        notes.push(format!("saturation clipped samples: gyros {sat_g:?}, accelerometers {sat_a:?} (x, y, z)"));
    }
    let source = format!(
        "scenario {} ({})",
        params.meta.name,
        if req.errors_only { "simulated; sensor errors alone, output − truth" } else { "simulated IMU output" }
    );
    finish(g, source, Some(params.meta.seed), ins.rate_hz, truth_of(ins), &opts, req, notes, interrupted, gather_s)
}

/// Reads `log`'s IMU file and analyses it: the longest stretch without a gap if it has gaps.
///
/// # Errors
/// Unreadable data, a bad request, too few samples, a channel that cannot be analysed.
pub fn log_set(
    log: &LogSet,
    req: &AllanRequest,
    stop: &AtomicBool,
    progress: &dyn Fn(u64),
) -> Result<ImuAllan, AllanRunError> {
    let opts = options(req)?;
    let started = Instant::now();
    let rate_hz = log.imu.rate_hz;
    let mut samples = ImuSamples::open(log)?;
    let new = || Gather::new(1 << 16, req.decimate, rate_hz);
    let (mut best, mut current) = (None::<(Gather, f64, f64)>, new());
    let (mut first_t, mut last_t, mut gaps, mut read) = (None, 0.0, 0usize, 0u64);
    let mut interrupted = false;
    let keep_longer = |best: &mut Option<(Gather, f64, f64)>, g: Gather, from: f64, to: f64| {
        if best.as_ref().is_none_or(|(b, _, _)| g.len() > b.len()) {
            *best = Some((g, from, to));
        }
    };
    loop {
        match samples.next_item()? {
            None => break,
            Some(ImuItem::Gap { .. }) => {
                gaps += 1;
                let from = first_t.take().unwrap_or(last_t);
                keep_longer(&mut best, std::mem::replace(&mut current, new()), from, last_t);
            }
            Some(ImuItem::Sample { t_s, dtheta, dv }) => {
                first_t.get_or_insert(t_s);
                last_t = t_s;
                current.push(&dtheta, &dv);
                read += 1;
                if read.is_multiple_of(200_000) {
                    progress(read);
                    if stop.load(Ordering::Relaxed) {
                        interrupted = true;
                        break;
                    }
                }
            }
        }
    }
    let from = first_t.unwrap_or(last_t);
    keep_longer(&mut best, current, from, last_t);
    let gather_s = started.elapsed().as_secs_f64();
    let Some((g, from, to)) = best else { return Err(AllanRunError::Interrupted(0)) };
    let mut notes = common_notes(&g, rate_hz);
    if gaps > 0 {
        notes.push(format!("the IMU data have {gaps} gap(s): the longest stretch without one is analysed ({from:.3} s to {to:.3} s of the file's clock, {} samples)", g.len() * req.decimate));
    }
    let truth = truth_of(&log.table.ins);
    if truth.is_some() {
        notes.push("\"configured\" is the noise of the log set's table.toml [imu] (what export-log wrote for a simulated log), not a property of the data.".into());
    }
    let source = format!("log set {}", log.dir.display());
    finish(g, source, log.seed, rate_hz, truth, &opts, req, notes, interrupted, gather_s)
}

#[allow(clippy::too_many_arguments)]
fn finish(
    g: Gather,
    source: String,
    seed: Option<u64>,
    rate_hz: f64,
    truth: Option<[Truth; 2]>,
    opts: &AllanOptions,
    req: &AllanRequest,
    notes: Vec<String>,
    interrupted: bool,
    gather_s: f64,
) -> Result<ImuAllan, AllanRunError> {
    let n = g.len();
    if n < MIN_SAMPLES.max(2 * opts.min_clusters) && interrupted {
        return Err(AllanRunError::Interrupted(n * req.decimate));
    }
    let started = Instant::now();
    let tau0_s = req.decimate as f64 / rate_hz;
    check_work(n, opts, req)?;
    let channels = analyze_imu(&g.phases, tau0_s, opts, &req.estimators, truth, true)?;
    Ok(ImuAllan {
        source,
        seed,
        rate_hz,
        decimate: req.decimate,
        samples: n,
        ci_sigma: req.ci_sigma,
        channels,
        notes,
        interrupted,
        gather_s,
        analysis_s: started.elapsed().as_secs_f64(),
    })
}

/// `allan --series`: the columns of one table file, each its own channel (a gyro for angular
/// units, an accelerometer for linear ones, a clock for time and fractional frequency), analysed
/// as far as each estimator is defined (m up to N/2: no 16-sample minimum; the IEEE fit needs 16).
///
/// # Errors
/// The file, a column, the sampling, a request out of range, a channel with too few samples.
/// `stop` ends the reading at its next batch of rows: the analysis is then of the rows read, and
/// says so (`interrupted`).
pub fn series(
    path: &std::path::Path,
    columns: &[SeriesColumn],
    sampling: &Sampling,
    req: &AllanRequest,
    stop: &AtomicBool,
) -> Result<ImuAllan, AllanRunError> {
    options(req)?;
    let started = Instant::now();
    let data = read_series_until(path, columns, sampling, stop).map_err(|e| match e {
        crate::io::imu::series::SeriesError::Interrupted { rows, .. } => AllanRunError::Interrupted(rows),
        e => AllanRunError::Config(e.to_string()),
    })?;
    let source = format!("series {}", path.display());
    analyze_series(data, &source, req, started.elapsed().as_secs_f64())
}

/// The columns of a series already read (a file's, or arrays in memory: `series_in_memory`),
/// each its own channel, as [`series`] analyses them; `source` names where they came from.
///
/// # Errors
/// A request out of range, a channel with too few samples.
pub fn analyze_series(
    data: crate::io::imu::series::Series,
    source: &str,
    req: &AllanRequest,
    gather_s: f64,
) -> Result<ImuAllan, AllanRunError> {
    let mut opts = options(req)?;
    opts.min_clusters = 2;
    let started = Instant::now();
    let mut notes = Vec::new();
    if data.interrupted {
        notes.push(format!("stopped after {} rows: the analysis is of the series read until then", data.rows));
    }
    let mut channels = Vec::new();
    for ((spec, name), increments) in data.columns.iter().zip(&data.names).zip(&data.increments) {
        let sensor = match spec.increment_quantity() {
            Quantity::Angle => Sensor::Gyro,
            Quantity::Velocity => Sensor::Accel,
            _ => Sensor::Clock,
        };
        let phase = decimated(increments, req.decimate);
        check_work(phase.len(), &opts, req)?;
        let channel =
            analyze_channel(sensor, name, &phase, data.tau0_s * req.decimate as f64, &opts, &req.estimators, None)?;
        if sensor.is_inertial() && channel.report.is_none() {
            notes.push(format!("{}: {} samples, fewer than the {MIN_SAMPLES} the IEEE fit needs: the curves only, as far as each estimator is defined", channel.name(), phase.len()));
        }
        if !sensor.is_inertial() {
            notes.push(format!("{}: a clock ({} {}): the power-law noise type per τ is in the table; no IEEE 952 fit (an inertial-sensor standard)", channel.name(), spec.unit_text(), spec.kind.name()));
        }
        for k in &channel.curves {
            let limit = k.estimator.max_m(phase.len() + 1).min(phase.len() / 2);
            if phase.len() < 64 {
                notes.push(format!(
                    "{}: {} samples: {} defined up to m = {limit} (τ = {} s)",
                    channel.name(),
                    phase.len(),
                    k.estimator.name(),
                    limit as f64 * data.tau0_s * req.decimate as f64
                ));
            }
        }
        channels.push(channel);
    }
    let source = format!(
        "{source} ({})",
        data.columns
            .iter()
            .zip(&data.names)
            .map(|(c, n)| format!("{n}: {} ({})", c.kind.name(), c.unit_text()))
            .collect::<Vec<_>>()
            .join("; ")
    );
    Ok(ImuAllan {
        source,
        seed: None,
        rate_hz: 1.0 / data.tau0_s,
        decimate: req.decimate,
        samples: data.increments.first().map_or(0, Vec::len) / req.decimate,
        ci_sigma: req.ci_sigma,
        channels,
        notes,
        interrupted: data.interrupted,
        gather_s,
        analysis_s: started.elapsed().as_secs_f64(),
    })
}

/// The phase of `increments` summed `by` at a time (a partial last block dropped).
fn decimated(increments: &[f64], by: usize) -> Phase {
    if by <= 1 {
        return Phase::from_increments(increments);
    }
    let sums: Vec<f64> = increments.chunks_exact(by).map(|c| c.iter().sum()).collect();
    Phase::from_increments(&sums)
}
