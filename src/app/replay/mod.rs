//! `rinscope replay`: a recorded RINS through the same pipeline as a simulation — the navigation
//! computer on the logged IMU samples, the body attitude demodulated through the nominal and the
//! compensated table models at the logged encoder angles, the same 3D scene and plots. With a
//! reference attitude the plots are errors against it; without, the compensated demodulation is the
//! reference (the "uncompensated" plot then shows what the compensation changes).

use std::collections::BTreeMap;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use serde::Serialize;

mod views;
use views::{AlgorithmOutput, Batch, Item, Reached, Tallies, Update, Views};

use super::failure::Failure;
use super::feed::{self, Outbox};
use super::outputs::{RecordingName, RecordingRequest, check_output, finish, write_json};
use super::playback::{AlignmentReport, Gap, Playback, PlaybackError};
use super::run::{NavSummary, RmsPeak};
use crate::math::attitude::Attitude;
use crate::math::frames::Rot;
use crate::math::stats::RunningStat;
use crate::math::timeline::decimation;
use crate::math::units::ARCSEC_PER_RAD;
use crate::model::gimbal::ChainMemo;
use crate::model::gimbal::TableErrors;
use crate::record::Recorder;
use crate::scenario::logset::{LogSet, Reference};
use crate::sim::{DemodState, ERROR_AXES};

/// The result of a replay, as printed and as written by `--summary-json`.
#[derive(Debug, Clone, Serialize)]
pub struct ReplaySummary {
    /// The log set's name.
    pub log: String,
    /// What the errors are measured against.
    pub reference: String,
    /// A strapdown IMU (no table): only the INS is reported.
    pub strapdown: bool,
    /// The IMU file's clock at the replay's t = 0, s (every time in the recording and the export is
    /// seconds after it).
    pub t0_file_clock_s: f64,
    /// The alignment, when the INS was aligned on the data.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub alignment: Option<AlignmentReport>,
    /// What the alignment estimated as a compensation document's IMU part (its biases, folded into
    /// the IMU compensation the replay was given, if any): `--summary-json` is then a compensation
    /// document `run`, `replay` and `live` read (`--compensation`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub estimated_imu_compensation: Option<crate::scenario::compensation::RawImuCompensation>,
    /// What was said once about the data (a reference that starts late, a trimmed span, ...).
    pub notes: Vec<String>,
    /// IMU samples replayed (after the pre-roll / alignment).
    pub samples: u64,
    /// Replayed time, s.
    pub duration_s: f64,
    /// Wall time, s.
    pub wall_time_s: f64,
    /// IMU samples per wall-clock second.
    pub samples_per_second: f64,
    /// True if stopped before the end of the log.
    pub interrupted: bool,
    /// `[demodulation][axis]`: "nominal" and "compensated" table, against the reference (the primary
    /// algorithm at the output instants); without a reference, "nominal" is nominal − compensated.
    /// Empty for a strapdown IMU.
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub attitude_error_arcsec: BTreeMap<String, BTreeMap<String, RmsPeak>>,
    /// `[algorithm][axis]`: each algorithm's body attitude against the reference (empty without one).
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub ins_attitude_error_arcsec: BTreeMap<String, BTreeMap<String, RmsPeak>>,
    /// Updates compared with the reference (those inside its span).
    pub compared_updates: u64,
    /// The position relative to the start, when navigating: an error only if the vehicle stayed at
    /// rest.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub navigation: Option<NavSummary>,
    /// Gaps in the IMU data the replay carried the attitude across.
    pub gaps: Vec<Gap>,
    /// The navigation computer's state after the last sample (to compare with another INS). In a
    /// replay a signal stopped, after the last sample the computer took: its `t_s` may be a little
    /// later than `duration_s`, where the statistics and the recording end.
    pub final_state: FinalState,
    /// Peak resident memory of the process at the end of the replay, MB.
    pub peak_rss_mb: f64,
    /// Saved recording, if any.
    pub recording_path: Option<String>,
    /// Its size, bytes.
    pub recording_bytes: Option<u64>,
}

/// The primary algorithm's state after the last replayed sample.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct FinalState {
    /// The instant the attitude stands for, s (the last update, less the FIR's delay).
    pub t_s: f64,
    /// Attitude of the IMU's sensor axes in the local level frame, deg (heading clockwise from North).
    pub imu_pitch_deg: f64,
    /// Roll, deg.
    pub imu_roll_deg: f64,
    /// Heading, deg.
    pub imu_heading_deg: f64,
    /// Latitude, deg (navigating only).
    pub latitude_deg: Option<f64>,
    /// Longitude, deg.
    pub longitude_deg: Option<f64>,
    /// Height, m.
    pub height_m: Option<f64>,
    /// Velocity (East, North, Up), m/s.
    pub velocity_enu_mps: Option<[f64; 3]>,
}

fn table(names: &[String], stats: &[[RunningStat; 3]]) -> BTreeMap<String, BTreeMap<String, RmsPeak>> {
    names
        .iter()
        .zip(stats)
        .map(|(name, s)| {
            let row = ERROR_AXES
                .iter()
                .zip(s)
                .map(|(axis, st)| {
                    (
                        (*axis).to_owned(),
                        RmsPeak { rms_arcsec: st.rms() * ARCSEC_PER_RAD, peak_arcsec: st.peak() * ARCSEC_PER_RAD },
                    )
                })
                .collect();
            (name.clone(), row)
        })
        .collect()
}

impl ReplaySummary {
    /// The end-of-replay table.
    #[must_use]
    pub fn text(&self) -> String {
        let mut s = format!(
            "replay of {} — {:.1} s, {} IMU samples, {:.2} s wall ({:.2} M samples/s){}\nreference: {}\n",
            self.log,
            self.duration_s,
            self.samples,
            self.wall_time_s,
            self.samples_per_second / 1e6,
            if self.interrupted { " — INTERRUPTED" } else { "" },
            self.reference
        );
        if let Some(a) = &self.alignment {
            s.push_str(&a.text());
        }
        for n in &self.notes {
            s.push_str(&format!("note: {n}\n"));
        }
        if !self.attitude_error_arcsec.is_empty() || !self.ins_attitude_error_arcsec.is_empty() {
            s.push_str(
                "attitude error, arcsec     pitch rms  pitch peak    roll rms   roll peak  heading rms heading peak\n",
            );
        }
        let rows = |s: &mut String, label: &str, t: &BTreeMap<String, BTreeMap<String, RmsPeak>>| {
            for (name, row) in t {
                s.push_str(&format!("{:<24}", format!("{label}{name}")));
                for axis in ERROR_AXES {
                    let v = row[axis];
                    s.push_str(&format!(" {:>11.3} {:>11.3}", v.rms_arcsec, v.peak_arcsec));
                }
                s.push('\n');
            }
        };
        rows(&mut s, "", &self.attitude_error_arcsec);
        if self.strapdown && !self.ins_attitude_error_arcsec.is_empty() {
            rows(&mut s, "", &self.ins_attitude_error_arcsec);
        } else if self.ins_attitude_error_arcsec.len() > 1 {
            s.push_str("by algorithm (compensated)\n");
            rows(&mut s, "  ", &self.ins_attitude_error_arcsec);
        }
        let f = &self.final_state;
        s.push_str(&format!(
            "final IMU attitude: pitch {:.4}°, roll {:.4}°, heading {:.4}° at {:.3} s",
            f.imu_pitch_deg,
            f.imu_roll_deg,
            crate::math::units::heading_deg_0_360(f.imu_heading_deg.to_radians()),
            f.t_s
        ));
        if let (Some(lat), Some(lon), Some(h), Some(v)) =
            (f.latitude_deg, f.longitude_deg, f.height_m, f.velocity_enu_mps)
        {
            s.push_str(&format!(
                "; position {lat:.6}°, {lon:.6}°, {h:.1} m; velocity E {:.3} N {:.3} U {:.3} m/s",
                v[0], v[1], v[2]
            ));
        }
        s.push('\n');
        if let Some(n) = &self.navigation {
            s.push_str(&format!(
                "position relative to the start (an error if the vehicle stayed at rest): peak {:.1} m, final {:.1} m (east {:.1} m, north {:.1} m)\n",
                n.peak_radial_m, n.final_radial_m, n.final_east_m, n.final_north_m
            ));
        }
        for g in &self.gaps {
            s.push_str(&format!(
                "gap in the IMU data: {:.3} s → {:.3} s ({:.3} s), attitude carried across\n",
                g.from_s,
                g.to_s,
                g.to_s - g.from_s
            ));
        }
        s
    }
}

fn final_state(pb: &Playback) -> FinalState {
    let (t_s, n_from_s) = pb.core.latest_attitude(0);
    // The sensor frame read as a body frame: the same matrix, its Euler angles.
    let a = Attitude::from_n_from_b(&Rot::from_quaternion(*n_from_s.quaternion()));
    let nav = pb.core.nav_state();
    FinalState {
        t_s,
        imu_pitch_deg: a.pitch_rad.to_degrees(),
        imu_roll_deg: a.roll_rad.to_degrees(),
        imu_heading_deg: a.heading_rad.to_degrees(),
        latitude_deg: nav.map(|n| n.latitude_rad.to_degrees()),
        longitude_deg: nav.map(|n| n.longitude_rad.to_degrees()),
        height_m: nav.map(|n| n.height_m),
        velocity_enu_mps: nav.map(|n| [n.v_n.x, n.v_n.y, n.v_n.z]),
    }
}

/// Replays `log` with `compensation` into `sinks` (a recorder laid out for a replay, its layout
/// sent again once the length is known: a whole replay plays in about a minute); the sinks stay
/// open (the caller finishes or abandons them). `stop` and `bar` as in [`replay`].
///
/// # Errors
/// As [`replay`]; the recording's own failures are [`PlaybackError::Record`].
pub fn replay_recorded(
    log: &LogSet,
    compensation: &TableErrors,
    sinks: &crate::record::sink::OpenSinks,
    stop: &AtomicBool,
    bar: Option<&indicatif::ProgressBar>,
) -> Result<ReplaySummary, PlaybackError> {
    let rerun = |e: crate::record::RecordError| PlaybackError::Record(e.to_string());
    let params = log.recording_params(1.0).map_err(|e| PlaybackError::Data(e.to_string()))?;
    let kind =
        crate::record::ReplayKind { table: !log.table.strapdown, reference: !matches!(log.reference, Reference::None) };
    let mut recorder = Recorder::new_replay(sinks.stream(), &params, kind).map_err(rerun)?;
    let summary = replay(log, compensation, Some(&mut recorder), stop, bar)?;
    if let Ok(p) = log.recording_params(summary.duration_s) {
        recorder.resend_layout(&p).map_err(rerun)?;
    }
    Ok(summary)
}

/// Replays `log` with the compensation `compensation` (the table description's, or a calibration's)
/// into `recorder` if given; `stop` ends it early (the summary says so); `bar`, if given, shows the
/// replayed time.
pub fn replay(
    log: &LogSet,
    compensation: &TableErrors,
    mut recorder: Option<&mut Recorder>,
    stop: &AtomicBool,
    bar: Option<&indicatif::ProgressBar>,
) -> Result<ReplaySummary, PlaybackError> {
    let started = Instant::now();
    let mut pb = Playback::open(log, compensation)?;
    let rerun = |e: crate::record::RecordError| PlaybackError::Record(e.to_string());
    if let Some(r) = recorder.as_deref_mut() {
        r.set_file_clock(pb.file_time_s(0.0)).map_err(rerun)?;
        // The plots' envelopes get 3000 buckets over the log, as a run's over its duration (the
        // default series rate; a `[recording] series_hz` stays as written).
        if let Some(p) = pb.length_hint_s().and_then(|d| log.recording_params(d).ok()) {
            r.set_run_length(&p);
        }
    }
    let chain = &log.table.chain;
    let nominal = TableErrors::zero(chain.axes().len());
    let algorithms: Vec<String> = pb.core.algorithms().iter().map(|a| a.name().to_owned()).collect();
    let rate = log.table.ins.rate_hz;
    // The plots' envelopes and the export take every update at the statistics rate.
    let series_every = decimation(rate, log.table.recording.bandwidth.statistics_hz().min(rate));
    let scene_every = decimation(rate, log.table.recording.scene_hz);
    let window = log.table.ins.signal_window_s;
    let has_reference = !matches!(log.reference, Reference::None);
    let views = Views {
        chain,
        compensation,
        nominal_rot: chain.error_rotations(&nominal),
        comp_rot: chain.error_rotations(compensation),
        nominal,
        has_reference,
        demod: vec![DemodState::default(); algorithms.len()],
        demod_nominal: DemodState::default(),
        comp_cache: ChainMemo::new(algorithms.len()),
        nominal_cache: ChainMemo::new(1),
    };
    let (mut next_series, mut next_scene) = (0u64, 0u64);
    let mut interrupted = false;
    let mut t_end = 0.0;
    let mut i = 0u64;
    let recording = recorder.is_some();
    // Three threads besides the file's reader: this loop (the log through the navigation
    // computer), the errors, demodulations and statistics (`views`: a third of this loop's time
    // was theirs), and the recorder (`feed`): neither waits for the encoding.
    let tallies = std::thread::scope(|scope| -> Result<Tallies, PlaybackError> {
        let (tx, rx) = feed::channel();
        let consumer = recorder.as_deref_mut().map(|r| scope.spawn(move || feed::consume(r, rx)));
        // The loop may read the log to its end ~32 k updates before the views; a signal in that
        // time stops the views, which then decide where the replay ended.
        let (to_views, from_loop) = crossbeam_channel::bounded::<Batch>(feed::STAGE_BATCHES);
        // The views' thread holds the recorder's channel: the recorder stops when it does.
        let viewer = scope.spawn(move || views.consume(&from_loop, stop, Outbox::new(&tx)));
        const UPDATES_PER_BATCH: usize = 512;
        // Each batch at its full size from the start (grown item by item from empty, every item
        // was copied about twice more).
        let new_batch = || Batch::with_capacity(UPDATES_PER_BATCH, algorithms.len());
        let mut batch = new_batch();
        let looped = (|| -> Result<(), PlaybackError> {
            while let Some(s) = pb.step()? {
                i += 1;
                t_end = s.t_s;
                if i.is_multiple_of(65_536) {
                    if stop.load(Ordering::Relaxed) {
                        interrupted = true;
                        break;
                    }
                    if let Some(bar) = bar {
                        bar.set_message(format!(
                            "{:.0} s of the log replayed ({:.1} M samples/s)",
                            s.t_s,
                            i as f64 / started.elapsed().as_secs_f64().max(1e-9) / 1e6
                        ));
                    }
                }
                if s.t_s <= window && recording {
                    batch.items.push(Item::Signal(s));
                }
                if s.updated {
                    // Every update is demodulated and counted in the statistics (as a run does); the
                    // plots take the updates at the statistics rate (their envelopes), the scene its own.
                    let (want_series, want_scene) = (i >= next_series, i >= next_scene);
                    if want_series {
                        next_series = i.saturating_add(series_every);
                    }
                    if want_scene {
                        next_scene = i.saturating_add(scene_every);
                    }
                    // Each algorithm at the instant its own output stands for, with the encoder
                    // readings there and the reference at its truth instant (the files are read here).
                    let mut t_ref_s = 0.0;
                    for k in 0..algorithms.len() {
                        let (t_repr_s, n_from_s) = pb.core.output_attitude(k);
                        let t_ref = pb.core.reference_instant(t_repr_s);
                        if k == 0 {
                            t_ref_s = t_ref;
                        }
                        let encoder_rad = pb.encoders_at(t_repr_s)?;
                        let reference = pb.reference_at(t_ref)?;
                        batch.algorithms.push(AlgorithmOutput { t_repr_s, n_from_s, encoder_rad, reference });
                    }
                    let series_row = recording && want_series;
                    if let Some(state) = pb.core.nav_state().filter(|_| series_row) {
                        batch.nav_states.push(*state);
                    }
                    batch.items.push(Item::Update(Update {
                        t_s: s.t_s,
                        t_ref_s,
                        nav_error: pb.core.nav_error(),
                        series_row,
                        scene_row: recording && want_scene,
                    }));
                }
                // The views' thread stopped: a signal, or the recorder failed (it reports why).
                if batch.items.len() >= UPDATES_PER_BATCH {
                    batch.reached = Reached { samples: pb.samples, t_s: t_end };
                    if to_views.send(std::mem::replace(&mut batch, new_batch())).is_err() {
                        break;
                    }
                }
            }
            Ok(())
        })();
        batch.reached = Reached { samples: pb.samples, t_s: t_end };
        let _ = to_views.send(batch);
        drop(to_views);
        let tallies = viewer.join();
        // A data error first (the recording then holds what came before it); else the recorder's.
        let recorded = consumer.map(|h| h.join());
        looped?;
        let tallies = tallies.map_err(|_| PlaybackError::Record("the statistics' thread panicked".into()))?;
        match recorded {
            Some(Ok(Err(e))) => Err(rerun(e)),
            Some(Err(_)) => Err(PlaybackError::Record("the recorder's thread panicked".into())),
            _ => Ok(tallies),
        }
    })?;
    let Tallies { stats, ins_stats, nav, compared, stopped_at } = tallies;
    // A signal the views saw ends the replay where they did, which may be behind the loop.
    let mut samples = pb.samples;
    if let Some(r) = stopped_at {
        (interrupted, samples, t_end) = (true, r.samples, r.t_s);
    }
    if !interrupted {
        pb.finish()?;
    }
    let reference = match &log.reference {
        Reference::None if log.table.strapdown => {
            "none: the INS's own solution (give [reference] to compare it with one)".to_owned()
        }
        Reference::None => {
            "none: the compensated demodulation (the \"nominal\" row is nominal − compensated)".to_owned()
        }
        Reference::Static(a) => format!(
            "a static attitude (pitch {:.4}°, roll {:.4}°, heading {:.4}°)",
            a.pitch_rad.to_degrees(),
            a.roll_rad.to_degrees(),
            a.heading_rad.to_degrees()
        ),
        Reference::File(p) => format!("the attitude in {}", p.display()),
    };
    let wall = started.elapsed().as_secs_f64();
    let strapdown = log.table.strapdown;
    let summary = ReplaySummary {
        log: log.name.clone(),
        reference,
        strapdown,
        t0_file_clock_s: pb.file_time_s(0.0),
        alignment: pb.alignment.clone(),
        estimated_imu_compensation: pb
            .alignment
            .as_ref()
            .map(|a| alignment_compensation(a, log.imu_compensation.as_ref())),
        notes: pb.notes.clone(),
        compared_updates: compared,
        samples,
        duration_s: t_end,
        wall_time_s: wall,
        samples_per_second: samples as f64 / wall.max(1e-9),
        interrupted,
        attitude_error_arcsec: if strapdown {
            BTreeMap::new()
        } else {
            table(&["nominal".to_owned(), "compensated".to_owned()], &stats)
        },
        ins_attitude_error_arcsec: if has_reference { table(&algorithms, &ins_stats) } else { BTreeMap::new() },
        navigation: nav,
        gaps: pb.gaps.clone(),
        final_state: final_state(&pb),
        peak_rss_mb: crate::app::bench::peak_rss_bytes() as f64 / 1e6,
        recording_path: None,
        recording_bytes: None,
    };
    if let Some(r) = recorder {
        for g in &summary.gaps {
            r.event(
                g.to_s,
                &format!(
                    "gap in the IMU data from {:.3} s to {:.3} s: the attitude was carried across",
                    g.from_s, g.to_s
                ),
                "WARN",
            )
            .map_err(rerun)?;
        }
        if let Some(a) = &summary.alignment {
            r.event(0.0, &format!("alignment:\n{}", a.text()), if a.warnings.is_empty() { "INFO" } else { "WARN" })
                .map_err(rerun)?;
        }
        for n in &summary.notes {
            r.event(0.0, n, "INFO").map_err(rerun)?;
        }
        let end = if interrupted {
            format!(
                "replay interrupted by the user at {t_end:.3} s; the recording holds everything replayed until then"
            )
        } else {
            format!("replay finished at {t_end:.3} s")
        };
        r.event(t_end, &end, if interrupted { "WARN" } else { "INFO" }).map_err(rerun)?;
        r.event(t_end, &format!("summary:\n{}", summary.text()), "INFO").map_err(rerun)?;
        r.finish().map_err(rerun)?;
    }
    Ok(summary)
}

/// `rinscope replay` (and Python's `replay`).
pub struct ReplayRequest {
    /// The log set.
    pub log: LogSet,
    /// A calibration's estimates to compensate with (`calibrate --json`'s text and where it came
    /// from) instead of the table description's own compensation.
    pub compensation: Option<(String, String)>,
    /// The recording's sinks.
    pub recording: RecordingRequest,
    /// `--summary-json`.
    pub summary_json: Option<std::path::PathBuf>,
}

/// What `replay` reports.
pub struct ReplayReport {
    /// The summary, as `--summary-json` writes it.
    pub summary: ReplaySummary,
    /// The recording, tables and figures kept.
    pub saved: crate::record::sink::Saved,
}

/// `replay`'s one owner: the outputs checked, the log replayed into its recording, the summary.
///
/// # Errors
/// Bad data or compensation, a sink or output that cannot be opened or written.
pub fn execute(
    req: &ReplayRequest,
    stop: &AtomicBool,
    bar: Option<&indicatif::ProgressBar>,
) -> Result<ReplayReport, Failure> {
    check_output("--summary-json", req.summary_json.as_deref())?;
    // One compensation model: the table's (`calibrate --json`'s estimates) and the IMU's
    // (`selfcal --json`'s), from the same document or either alone.
    let mut log = req.log.clone();
    let mut imu_note = None;
    let compensation = match &req.compensation {
        None => log.table.compensation.clone(),
        Some((text, origin)) => {
            let imu = crate::scenario::compensation::from_document(text, origin)?;
            let table = crate::scenario::compensation::compensation_from_calibration(
                &log.raw_table,
                text,
                origin,
                imu.is_some(),
            )?;
            if let Some(c) = &imu {
                imu_note = Some(format!(
                    "the IMU is compensated with {origin}'s estimates (gyro bias {:.4}, {:.4}, {:.4} °/h; accelerometer bias {:.0}, {:.0}, {:.0} µg; gains too; in the accelerometer triad's frame) before anything else: the alignment works on the compensated IMU",
                    c.bg.x / crate::math::units::RAD_PER_S_PER_DEG_PER_H,
                    c.bg.y / crate::math::units::RAD_PER_S_PER_DEG_PER_H,
                    c.bg.z / crate::math::units::RAD_PER_S_PER_DEG_PER_H,
                    c.ba.x / crate::math::units::MPS2_PER_UG,
                    c.ba.y / crate::math::units::MPS2_PER_UG,
                    c.ba.z / crate::math::units::MPS2_PER_UG
                ));
            }
            log.imu_compensation = imu;
            table
        }
    };
    let log = &log;
    log.recording_params(1.0)?;
    let sinks = req.recording.open(RecordingName { name: &log.name, kind: Some("replay"), seed: None })?;
    let mut summary = replay_recorded(log, &compensation, &sinks, stop, bar)?;
    if let Some(note) = imu_note {
        summary.notes.insert(0, note);
    }
    let saved = finish(sinks)?;
    (summary.recording_path, summary.recording_bytes) = saved.recording_fields();
    if let Some(path) = &req.summary_json {
        write_json("--summary-json", path, &summary)?;
    }
    Ok(ReplayReport { summary, saved })
}

/// The alignment's biases as a compensation document's IMU part: on top of `given` (the IMU
/// compensation the replay applied, whose samples the alignment saw) when there was one. The gains
/// an alignment at rest does not estimate are the given ones, or zero and named not compensated;
/// the 1σ are the alignment's for the biases (stated only without a given compensation, whose own
/// 1σ the replay does not know; a gain's is then 0: not estimated).
fn alignment_compensation(
    a: &AlignmentReport,
    given: Option<&crate::ins::imu_errors::ImuErrors>,
) -> crate::scenario::compensation::RawImuCompensation {
    use crate::ins::imu_errors::ImuErrors;
    use crate::math::units::{MPS2_PER_UG, RAD_PER_S_PER_DEG_PER_H};
    let v = |x: [f64; 3], unit: f64| nalgebra::Vector3::from(x) * unit;
    let found = ImuErrors::biases(v(a.gyro_bias_deg_per_h, RAD_PER_S_PER_DEG_PER_H), v(a.accel_bias_ug, MPS2_PER_UG));
    match given {
        Some(g) => crate::scenario::compensation::RawImuCompensation::from_errors(
            &g.with_residual_biases(&found.bg, &found.ba),
            None,
            Vec::new(),
        ),
        None => {
            let sigma = ImuErrors::biases(
                v(a.gyro_bias_sigma_deg_per_h, RAD_PER_S_PER_DEG_PER_H),
                v(a.accel_bias_sigma_ug, MPS2_PER_UG),
            );
            crate::scenario::compensation::RawImuCompensation::from_errors(
                &found,
                Some(&sigma),
                vec!["gyro gains (Kg)".to_owned(), "accelerometer gains (Ka)".to_owned()],
            )
        }
    }
}
