//! `rinscope calibrate` and `montecarlo`: simulate Jiang et al. 2017's static test (vehicle at rest, gimbals
//! turning, INS and encoder noise in the loop), hand its data to the estimators of `calib`, validate
//! the compensation on an independent run.

use crate::app::playback::{Playback, PlaybackError};
use crate::calib::montecarlo::{self, RunErrors, Setup, Shard, Summary};
use crate::calib::report::{Compensation, Report, build as build_report};
use crate::calib::{
    AttitudeSource, CalibError, Calibration, Data, History, Measurement, Nuisance, ParamSet, Samples, Thinned,
    attitude_errors, calibrate,
};
use crate::ins::pipeline::InsRun;
use crate::model::gimbal::TableErrors;
use crate::scenario::Params;
use crate::scenario::logset::LogSet;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

use crate::app::failure::Failure;
use crate::app::outputs::{RecordingName, RecordingRequest, check_output, finish, logged, write_json};
use crate::record::sink::Saved;

use crate::app::run::record_run;
use crate::sim::{DemodState, encoder_readings};

/// Runs the static test of `params` with noise seed `seed` and collects one sample per INS output
/// (kept in memory while it fits, else simulated again for each pass: see [`Samples`]).
pub fn collect(params: &Params, seed: u64, stop: &AtomicBool) -> Result<Data, CalibError> {
    let Some((attitude, n_from_b)) = params.table_model().fixed_state() else {
        return Err(CalibError::VehicleMoves(params.meta.name.clone()));
    };
    let mut p = params.clone();
    p.meta.seed = seed;
    let source = if p.ins.is_some() { AttitudeSource::Ins } else { AttitudeSource::Ideal };
    let duration_s = p.timeline().end_s();
    let replay = move |sink: &mut dyn FnMut(&Measurement) -> bool| -> Result<(), CalibError> {
        let mut model = p.table_model();
        // The demodulation knows every error it does not estimate: the compensation's values.
        let set = ParamSet::new(&p.table.chain, Nuisance::None);
        model.compensation = set.without_estimated(&p.calibration_known);
        let chain = &p.table.chain;
        let timeline = p.timeline();
        let mut demod = DemodState::default();
        match &p.ins {
            Some(ins_params) => {
                let mut ins = InsRun::new(ins_params, p.site, p.meta.seed, model.clone());
                for _ in 0..timeline.intervals() {
                    if ins.step().updated {
                        let (t, q) = ins.output_attitude(0);
                        // Matched synchronisation: the encoders are read for the instant the data represent.
                        let angles = demod.correct(&model.compensation, t, &encoder_readings(&model, t));
                        if !sink(&Measurement { t_s: t, n_from_s: q, shafts: chain.shaft_rotations(&angles) }) {
                            return Ok(());
                        }
                    }
                }
            }
            None => {
                let truth = model.truth_rotations().clone();
                // The same instants as the INS's samples: t_1 ..= t_n.
                for k in 1..=timeline.intervals() {
                    let t = timeline.t_s(k);
                    let (lambda, _) = model.scheme.state(t - model.scheme_t0_s);
                    let n_from_s = n_from_b * chain.b_from_s(&truth, &lambda);
                    let angles = demod.correct(&model.compensation, t, &encoder_readings(&model, t));
                    if !sink(&Measurement { t_s: t, n_from_s, shafts: chain.shaft_rotations(&angles) }) {
                        return Ok(());
                    }
                }
            }
        }
        Ok(())
    };
    let samples = Samples::collect(Box::new(replay), stop)?;
    Ok(Data { samples, duration_s, n_from_b, attitude, source, seed })
}

/// The RMS attitude error (pitch, roll, heading, rad) that the encoders' white noise alone leaves on
/// the static test of `params` demodulated with the true table errors: the noise propagated
/// linearly through the exact chain at every sample (derivatives by central differences),
/// σ²_axis = mean over samples of Σ_k σ_k² (∂e_axis/∂λ_k)². An independent value for the floor
/// the calibration report measures by simulating the noise.
pub fn encoder_noise_floor(params: &Params, stop: &AtomicBool) -> Result<[f64; 3], CalibError> {
    let Some((attitude, n_from_b)) = params.table_model().fixed_state() else {
        return Err(CalibError::VehicleMoves(params.meta.name.clone()));
    };
    let model = params.table_model();
    let chain = &params.table.chain;
    let truth = chain.error_rotations(&params.table.truth);
    let timeline = params.timeline();
    let h = 1e-6;
    let mut var = [0.0; 3];
    let n = timeline.intervals();
    for k in 1..=n {
        if k.is_multiple_of(65_536) && stop.load(std::sync::atomic::Ordering::Relaxed) {
            return Err(CalibError::Interrupted);
        }
        let t = timeline.t_s(k);
        let (lambda, _) = model.scheme.state(t - model.scheme_t0_s);
        let n_from_s = n_from_b * chain.b_from_s(&truth, &lambda);
        for (j, axis) in params.table.truth.axes.iter().enumerate() {
            let e = |d: f64| {
                let mut l = lambda;
                l[j] += d;
                crate::sim::demodulate(n_from_s, chain.b_from_s(&truth, &l)).error_from(&attitude).as_array()
            };
            let (plus, minus) = (e(h), e(-h));
            for a in 0..3 {
                let d = (plus[a] - minus[a]) / (2.0 * h);
                var[a] += axis.encoder_noise_rad.powi(2) * d * d;
            }
        }
    }
    Ok(var.map(|v| (v / n.max(1) as f64).sqrt()))
}

/// The validation run's attitude errors kept for the recording: before, after KF, after LSQ.
pub type ValidationTrace = Thinned<Vec<[f64; 3]>>;

/// A calibration as `rinscope calibrate` runs it: the test, an independent validation run (noise
/// seed + 1), both estimators, compensation before/after on the validation run, the report.
pub struct Outcome {
    /// The calibration data.
    pub data: Data,
    /// The validation run.
    pub validation: Data,
    /// The estimates.
    pub cal: Calibration,
    /// The report.
    pub report: Report,
    /// The validation run's attitude errors (before, after KF, after LSQ), thinned for the recording.
    pub validation_trace: ValidationTrace,
}

/// The four demodulations a calibration is judged by, on `data`: before (the estimated errors
/// unknown), after the filter's and the least squares' estimates, and with the true values.
fn judge(
    chain: &crate::model::gimbal::Chain,
    cal: &Calibration,
    known: &TableErrors,
    truth: &TableErrors,
    data: &Data,
    series_hz: f64,
    stop: &AtomicBool,
) -> Result<(Compensation, ValidationTrace), CalibError> {
    let set = &cal.set;
    let variants = [
        set.without_estimated(known),
        set.errors(&cal.kf.theta, known),
        set.errors(&cal.nls.theta, known),
        set.errors(&set.values(truth), known),
    ];
    let mut trace = Thinned::new(1.0 / series_hz.max(1e-6));
    let s = attitude_errors(chain, &variants, data, stop, &mut trace)?;
    // The recording plots the first three.
    for row in &mut trace.rows {
        row.truncate(3);
    }
    Ok((Compensation { before: s[0], after_kf: s[1], after_nls: s[2], with_truth: s[3] }, trace))
}

/// Runs the whole calibration of a scenario (`history`: keep the filter's snapshots for a recording;
/// `stop` ends it early with [`CalibError::Interrupted`]).
pub fn calibrate_scenario(params: &Params, history: bool, stop: &AtomicBool) -> Result<Outcome, CalibError> {
    let seed = params.meta.seed;
    let (data, validation) = std::thread::scope(|scope| {
        let v = scope.spawn(|| collect(params, seed.wrapping_add(1), stop));
        let d = collect(params, seed, stop);
        // A panic is a bug, not bad data: it goes on as a panic (CalibError::Data is the data's).
        (d, v.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic)))
    });
    let (data, validation) = (data?, validation?);
    let cfg = &params.calibration;
    let cal = calibrate(
        &params.table.chain,
        &params.calibration_known,
        &data,
        cfg,
        if history { History::Snapshots(cfg.record_hz) } else { History::Final },
        stop,
    )?;
    let (compensation, validation_trace) = judge(
        &params.table.chain,
        &cal,
        &params.calibration_known,
        &params.table.truth,
        &validation,
        params.recording.series_hz,
        stop,
    )?;
    let mut report =
        build_report(&params.meta.name, &params.table.chain, &params.table.truth, &cal, &data, Some(compensation));
    report.aliases =
        crate::calib::alias::aliases(&params.table.chain, &params.calibration_known, &data, &cal, cfg, stop)?;
    Ok(Outcome { data, validation, cal, report, validation_trace })
}

/// The Monte Carlo's fixed part for `params`: its table, what the calibration knows, the seed.
#[must_use]
pub fn monte_carlo_setup(params: &Params) -> Setup<'_> {
    Setup {
        scenario: &params.meta.name,
        chain: &params.table.chain,
        truth: &params.table.truth,
        compensation: &params.calibration_known,
        cfg: &params.calibration,
        seed: params.meta.seed,
    }
}

/// Jiang et al. 2017's Monte Carlo on `params`' table, the runs of `shard` out of `runs`: each run a
/// calibration of a drawn table on its simulated static test, in parallel (`progress` ticks once
/// per run, `stop` ends early). Returns the runs' errors; `montecarlo::summarize` makes the table.
pub fn monte_carlo_runs(
    params: &Params,
    runs: usize,
    shard: Shard,
    progress: &(dyn Fn() + Sync),
    stop: &AtomicBool,
) -> Result<Vec<RunErrors>, CalibError> {
    let simulate = |truth: &TableErrors, seed: u64| {
        let mut p = params.clone();
        p.table.truth = truth.clone();
        collect(&p, seed, stop)
    };
    montecarlo::run_indices(&monte_carlo_setup(params), &shard.indices(runs as u64), &simulate, progress, stop)
}

/// The whole Monte Carlo of `params` (`runs` runs), summarised.
pub fn monte_carlo(
    params: &Params,
    runs: usize,
    progress: &(dyn Fn() + Sync),
    stop: &AtomicBool,
) -> Result<Summary, CalibError> {
    let started = std::time::Instant::now();
    let done = monte_carlo_runs(params, runs, Shard::WHOLE, progress, stop)?;
    Ok(montecarlo::summarize(&monte_carlo_setup(params), runs, &done, started.elapsed().as_secs_f64()))
}

/// Writes `outcome`'s recording into `rec`: the calibration's panels, then the table turning as in
/// a plain run of the ideal demodulation (the INS is the calibration's business here), whose error
/// plots the layout keeps in its tabs.
pub fn record_outcome(
    rec: crate::record::Stream,
    params: &Params,
    outcome: &Outcome,
    stop: &AtomicBool,
) -> anyhow::Result<()> {
    let recorder =
        crate::record::calibration::log(rec, params, &outcome.cal, &outcome.report, &outcome.validation_trace)?;
    recorder.event(
        params.duration_s,
        &format!(
            "calibration: {} samples, {} Gauss–Newton iterations",
            outcome.cal.samples, outcome.cal.nls_iterations
        ),
        "INFO",
    )?;
    for w in &outcome.report.warnings {
        recorder.event(params.duration_s, w, "WARN")?;
    }
    let mut table = params.clone();
    table.ins = None;
    record_run(recorder, &table, stop, false)?;
    Ok(())
}

/// The static test of a log set as calibration data: one measurement per primary update (the INS
/// output and the encoder angles corrected with what the calibration knows, `known`), the known
/// body attitude from the log's reference (it must be constant: the vehicle at rest). Kept in
/// memory while it fits, else read from the files again for each pass.
pub fn collect_from_log(log: &LogSet, known: &TableErrors, stop: &AtomicBool) -> Result<Data, LogCalibrationError> {
    let (log2, known2) = (log.clone(), known.clone());
    // The body attitude the first pass finds (every pass checks the same).
    let found: std::sync::Arc<std::sync::Mutex<Option<crate::math::attitude::Attitude>>> = std::sync::Arc::default();
    let found2 = std::sync::Arc::clone(&found);
    let replay = move |sink: &mut dyn FnMut(&Measurement) -> bool| -> Result<(), CalibError> {
        let fail = |e: LogCalibrationError| CalibError::Data(e.to_string());
        let mut pb = Playback::open(&log2, &log2.table.compensation).map_err(|e| fail(e.into()))?;
        let mut demod = DemodState::default();
        let mut attitude = None;
        let chain = &log2.table.chain;
        while let Some(s) = pb.step().map_err(|e| fail(e.into()))? {
            if !s.updated {
                continue;
            }
            let (t, n_from_s) = pb.core.output_attitude(0);
            let reference = pb
                .reference_at(t)
                .map_err(|e| fail(e.into()))?
                .ok_or_else(|| fail(LogCalibrationError::NoReference))?;
            let first = *attitude.get_or_insert(reference);
            let moved = (reference.pitch_rad - first.pitch_rad)
                .abs()
                .max(crate::math::units::wrap_pi(reference.roll_rad - first.roll_rad).abs())
                .max(crate::math::units::wrap_pi(reference.heading_rad - first.heading_rad).abs());
            if moved > 1e-9 {
                return Err(fail(LogCalibrationError::Moves {
                    t_s: t,
                    arcsec: moved * crate::math::units::ARCSEC_PER_RAD,
                }));
            }
            // Matched synchronisation: the encoders are read for the instant the data represent.
            let angles = demod.correct(&known2, t, &pb.encoders_at(t).map_err(|e| fail(e.into()))?);
            if !sink(&Measurement { t_s: t, n_from_s, shafts: chain.shaft_rotations(&angles) }) {
                return Ok(());
            }
        }
        pb.finish().map_err(|e| fail(e.into()))?;
        *found2.lock().unwrap_or_else(std::sync::PoisonError::into_inner) = attitude;
        Ok(())
    };
    let samples = Samples::collect(Box::new(replay), stop).map_err(|e| match e {
        CalibError::Interrupted => LogCalibrationError::Interrupted,
        other => LogCalibrationError::Calibration(other),
    })?;
    if samples.is_empty() {
        return Err(LogCalibrationError::NoMeasurements(log.imu.path.display().to_string()));
    }
    let attitude =
        found.lock().unwrap_or_else(std::sync::PoisonError::into_inner).ok_or(LogCalibrationError::NoReference)?;
    // τ ∈ [−1, 1] over the test, as the simulation's calibration has it.
    let duration_s = samples.last_t_s().max(1e-9);
    Ok(Data {
        samples,
        duration_s,
        n_from_b: attitude.n_from_b(),
        attitude,
        source: AttitudeSource::Log,
        seed: log.seed.unwrap_or(0),
    })
}

/// Why a log cannot be calibrated.
#[derive(Debug, thiserror::Error)]
pub enum LogCalibrationError {
    /// The log's data.
    #[error("{0}")]
    Playback(#[from] PlaybackError),
    /// No known body attitude.
    #[error(
        "calibration needs the body's attitude at rest: give the log set a [reference] (attitude_deg = [pitch, roll, heading], or a file)"
    )]
    NoReference,
    /// The IMU file ends before the INS's first update: nothing to calibrate on.
    #[error(
        "{0}: too few samples: the log ends before the INS's first update, so there is no measurement to calibrate on"
    )]
    NoMeasurements(String),
    /// The reference attitude changes.
    #[error(
        "the reference attitude changes by {arcsec:.3}″ at {t_s:.3} s: a static calibration needs the vehicle at rest"
    )]
    Moves {
        /// When, s.
        t_s: f64,
        /// By how much, arcsec.
        arcsec: f64,
    },
    /// The estimators failed.
    #[error("{0}")]
    Calibration(#[from] CalibError),
    /// Stopped by the user.
    #[error("interrupted")]
    Interrupted,
}

/// `calibrate --log`: Jiang et al. 2017's filter and the exact least squares on a log set, the compensation
/// before/after on the same data (a log has no independent second run).
pub fn calibrate_log(
    log: &LogSet,
    history: bool,
    stop: &AtomicBool,
) -> Result<(Calibration, Report, Data, ValidationTrace), LogCalibrationError> {
    calibrate_log_files(log, history, stop).map_err(|e| match e {
        // A pass over the log's files failed on their data (every pass reads them again when they
        // do not fit in memory): the data's error, as `replay` gives it, not the estimators'.
        LogCalibrationError::Calibration(CalibError::Data(message)) => {
            LogCalibrationError::Playback(PlaybackError::Data(message))
        }
        other => other,
    })
}

fn calibrate_log_files(
    log: &LogSet,
    history: bool,
    stop: &AtomicBool,
) -> Result<(Calibration, Report, Data, ValidationTrace), LogCalibrationError> {
    let cfg = &log.table.calibration;
    let set = ParamSet::new(&log.table.chain, Nuisance::None);
    let known = set.without_estimated(&log.table.compensation);
    let data = collect_from_log(log, &known, stop)?;
    let chain = &log.table.chain;
    let interrupted = |e: CalibError| match e {
        CalibError::Interrupted => LogCalibrationError::Interrupted,
        other => LogCalibrationError::Calibration(other),
    };
    let cal = calibrate(
        chain,
        &log.table.compensation,
        &data,
        cfg,
        if history { History::Snapshots(cfg.record_hz) } else { History::Final },
        stop,
    )
    .map_err(interrupted)?;
    let (compensation, trace) =
        judge(chain, &cal, &log.table.compensation, &log.table.stated, &data, log.table.recording.series_hz, stop)
            .map_err(interrupted)?;
    let mut report = build_report(&log.name, chain, &log.table.stated, &cal, &data, Some(compensation));
    report.aliases =
        crate::calib::alias::aliases(chain, &log.table.compensation, &data, &cal, cfg, stop).map_err(interrupted)?;
    Ok((cal, report, data, trace))
}

/// What `calibrate --json` writes: the report, and the estimates as `[compensation]` keys that
/// `replay --compensation FILE` and a scenario's `[compensation] from_calibration` read.
#[derive(Debug, Clone, serde::Serialize)]
pub struct CalibrationOutput<'a> {
    /// The report.
    #[serde(flatten)]
    pub report: &'a Report,
    /// The least-squares estimates over the known errors, as `[compensation]` keys.
    pub estimated_compensation: crate::scenario::raw::RawCompensation,
}

/// The `[compensation]` keys of a calibration's least-squares estimates over `known`.
#[must_use]
pub fn estimated_compensation(
    chain: &crate::model::gimbal::Chain,
    cal: &Calibration,
    known: &TableErrors,
) -> crate::scenario::raw::RawCompensation {
    crate::scenario::compensation_keys(chain, &cal.set.errors(&cal.nls.theta, known))
}

/// What `calibrate` calibrates: a scenario's simulated static test or a log set's recorded one.
pub enum CalibrateInput {
    /// A scenario (simulated twice: the test and an independent validation run).
    Scenario(Box<Params>),
    /// A log set with a table description.
    Log(Box<LogSet>),
}

/// `rinscope calibrate` (and Python's `calibrate`): what to calibrate and where its outputs go.
pub struct CalibrateRequest {
    /// The test.
    pub input: CalibrateInput,
    /// The recording's sinks; `None`: no recording.
    pub recording: Option<RecordingRequest>,
    /// `--json`: the report and the compensation.
    pub json: Option<PathBuf>,
}

/// What `calibrate` reports.
pub struct CalibrateReport {
    /// The estimates, their 1σ and the compensation before/after, as a user reads them.
    pub text: String,
    /// The `--json` document.
    pub document: serde_json::Value,
    /// The recording and tables kept.
    pub saved: Option<Saved>,
    /// A signal ended the recording's table motion early (the estimates are complete).
    pub interrupted: bool,
}

/// `calibrate`'s one owner: the outputs checked, the calibration, its document and recording.
///
/// # Errors
/// Bad input, a calibration the data cannot support, an output that cannot be written, or a stop
/// before the estimates were complete.
pub fn execute(req: &CalibrateRequest, stop: &AtomicBool) -> Result<CalibrateReport, Failure> {
    check_output("--json", req.json.as_deref())?;
    let started = std::time::Instant::now();
    let (name, seed) = match &req.input {
        CalibrateInput::Scenario(p) => (&p.meta.name, Some(p.meta.seed)),
        CalibrateInput::Log(log) => {
            if log.table.strapdown {
                return Err(Failure::input(format!(
                    "calibrate --log: {} has no table description with [turntable] (log.table): there is no table to calibrate",
                    log.dir.display()
                )));
            }
            (&log.name, None)
        }
    };
    // Dropped unfinished (any error below), the sinks are abandoned.
    let sinks =
        req.recording.as_ref().map(|r| r.open(RecordingName { name, kind: Some("calibration"), seed })).transpose()?;
    let (text, output, saved) = match &req.input {
        CalibrateInput::Scenario(params) => {
            let outcome = calibrate_scenario(params, sinks.is_some(), stop).map_err(|e| {
                Failure::calibration(
                    "calibrate",
                    e,
                    "calibrate did not finish; nothing was estimated and no recording was made",
                )
            })?;
            let text = format!(
                "{}({:.2} s wall: two {:.0}-s runs simulated, filter and least squares)\n",
                outcome.report.text(),
                started.elapsed().as_secs_f64(),
                params.duration_s
            );
            let compensation = estimated_compensation(&params.table.chain, &outcome.cal, &params.calibration_known);
            let output = serde_json::to_value(CalibrationOutput {
                report: &outcome.report,
                estimated_compensation: compensation,
            })
            .map_err(|e| Failure::run(e.to_string()))?;
            let saved = match sinks {
                Some(s) => {
                    logged(record_outcome(s.stream(), params, &outcome, stop))?;
                    Some(finish(s)?)
                }
                None => None,
            };
            (text, output, saved)
        }
        CalibrateInput::Log(log) => {
            let interrupted = "calibrate --log did not finish; nothing was estimated";
            let (cal, report, data, traces) = calibrate_log(log, sinks.is_some(), stop).map_err(|e| match e {
                LogCalibrationError::Interrupted => Failure::interrupted(interrupted),
                LogCalibrationError::Calibration(c) => Failure::calibration("calibrate --log", c, interrupted),
                other => Failure::input(format!("calibrate --log: {other}")),
            })?;
            let text = format!(
                "{}({:.2} s wall: {} measurements of {}, filter and least squares; before/after on the same data)\n",
                report.text(),
                started.elapsed().as_secs_f64(),
                data.samples.len(),
                log.dir.display()
            );
            let compensation = estimated_compensation(&log.table.chain, &cal, &log.table.compensation);
            let output =
                serde_json::to_value(CalibrationOutput { report: &report, estimated_compensation: compensation })
                    .map_err(|e| Failure::run(e.to_string()))?;
            let saved = match sinks {
                Some(s) => {
                    let params = log.recording_params(data.samples.last_t_s().max(1.0))?;
                    logged(
                        crate::record::calibration::log(s.stream(), &params, &cal, &report, &traces)
                            .and_then(|mut r| r.finish()),
                    )?;
                    Some(finish(s)?)
                }
                None => None,
            };
            (text, output, saved)
        }
    };
    if let Some(path) = &req.json {
        write_json("--json", path, &output)?;
    }
    Ok(CalibrateReport { text, document: output, saved, interrupted: stop.load(std::sync::atomic::Ordering::SeqCst) })
}
