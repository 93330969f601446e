//! A log set played back: the IMU samples feed the navigation computer (`ins::core`, the one the
//! simulation uses), the encoder and reference files are looked up at the instants the computer asks
//! for. `replay` and `calibrate --log` both drive it. Memory stays flat in the log's length: the
//! files stream, the tracks keep a few readings around the instant asked for.
//!
//! Time: every instant is seconds after the end of the pre-roll (the first `pre` samples that fill
//! the FIR and give the algorithms their previous samples), or after the alignment window
//! ([`Playback::file_time_s`] turns it back into the file's clock).

mod start;
mod track;

use std::collections::VecDeque;

use nalgebra::Vector3;

pub use start::AlignmentReport;
use track::{Track, open_track};

use crate::ins::core::{InsCore, SampleOut};
use crate::io::{BlockEnd, ImuEvent, ImuOptions, ImuReader, ImuSample, LogError, SampleKind, StartTime};
use crate::math::attitude::Attitude;
use crate::math::frames::{Rot, S};
use crate::math::units::{MPS2_PER_UG, RAD_PER_S_PER_DEG_PER_H};
use crate::model::gimbal::TableErrors;
use crate::model::scheme::{AxisValues, MAX_AXES};
use crate::scenario::logset::{Initial, LogSet, Reference};
use crate::sim::{DemodState, demodulate};

/// A problem with a log set's data, naming the file and where.
#[derive(Debug, thiserror::Error)]
pub enum PlaybackError {
    /// A file could not be read or holds bad data (the message names file, row, column, value).
    #[error("{0}")]
    Log(#[from] LogError),
    /// The data do not fit together (clocks, lengths, the vehicle moving during alignment...).
    #[error("{0}")]
    Data(String),
    /// The replay's recording failed (not the data's fault: exit 1, not 2).
    #[error("rerun: {0}")]
    Record(String),
}

/// One sample's (Δθ, Δv) increments.
type IncrementPair = (Vector3<f64>, Vector3<f64>);

fn data_err(message: impl Into<String>) -> PlaybackError {
    PlaybackError::Data(message.into())
}

/// A gap in the IMU data that the replay carried the attitude across.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct Gap {
    /// Last sample before it, s.
    pub from_s: f64,
    /// First sample after it, s.
    pub to_s: f64,
}

/// The IMU file read on a thread of its own, in blocks: parsing the file and turning its samples into
/// compensated increments overlap the navigation.
struct ImuStream {
    rx: crossbeam_channel::Receiver<Block>,
    items: std::vec::IntoIter<ImuItem>,
}

/// What the reading thread sends.
enum Block {
    Items(Vec<ImuItem>),
    Error(LogError),
}

/// Samples per block handed from the reading thread.
const IMU_BLOCK: usize = 4096;

impl ImuStream {
    fn spawn(mut reader: ImuReader, mut increments: Increments) -> Result<Self, PlaybackError> {
        let (tx, rx) = crossbeam_channel::bounded(4);
        std::thread::Builder::new()
            .name("imu-reader".into())
            .spawn(move || {
                let mut samples = Vec::with_capacity(IMU_BLOCK);
                loop {
                    samples.clear();
                    let end = reader.next_samples(&mut samples, IMU_BLOCK);
                    let mut items: Vec<ImuItem> = samples.iter().map(|s| increments.sample(s)).collect();
                    let (done, error) = match end {
                        Ok(BlockEnd::Full) => (false, None),
                        Ok(BlockEnd::Gap(g)) => {
                            items.extend(increments.gap(g));
                            (false, None)
                        }
                        Ok(BlockEnd::End) => (true, None),
                        Err(e) => (true, Some(e)),
                    };
                    if !items.is_empty() && tx.send(Block::Items(items)).is_err() {
                        return;
                    }
                    if let Some(e) = error {
                        let _ = tx.send(Block::Error(e));
                    }
                    if done {
                        return;
                    }
                }
            })
            .map_err(|e| data_err(format!("cannot start the IMU reader: {e}")))?;
        Ok(Self { rx, items: Vec::new().into_iter() })
    }

    #[inline]
    fn next(&mut self) -> Option<Result<ImuItem, LogError>> {
        loop {
            if let Some(item) = self.items.next() {
                return Some(Ok(item));
            }
            match self.rx.recv().ok()? {
                Block::Items(v) => self.items = v.into_iter(),
                Block::Error(e) => return Some(Err(e)),
            }
        }
    }
}

/// The file's samples as increments in the RFU sensor frame (rates held over their interval), the
/// IMU compensation removed.
struct Increments {
    kind: SampleKind,
    nominal_s: f64,
    last_t: Option<f64>,
    pending_gap: bool,
    /// The IMU errors removed from every sample ([`LogSet::imu_compensation`]).
    compensation: Option<crate::ins::imu_errors::ImuErrors>,
}

impl Increments {
    fn gap(&mut self, event: ImuEvent) -> Option<ImuItem> {
        match event {
            ImuEvent::Gap { t_before_s, t_after_s, .. } => {
                self.pending_gap = true;
                Some(ImuItem::Gap { from_s: t_before_s, to_s: t_after_s })
            }
            ImuEvent::Sample(_) => None,
        }
    }

    #[inline]
    fn sample(&mut self, s: &ImuSample) -> ImuItem {
        let (dtheta, dv) = match self.kind {
            SampleKind::Increments => (s.gyro, s.accel),
            SampleKind::Rates => {
                // A rate held over its interval; across a gap, over one nominal interval
                // (the gap itself is not integrated).
                let dt = match self.last_t {
                    Some(t) if !self.pending_gap => s.t_s - t,
                    _ => self.nominal_s,
                };
                (s.gyro * dt, s.accel * dt)
            }
        };
        self.pending_gap = false;
        self.last_t = Some(s.t_s);
        // The compensated IMU: (I + K)⁻¹(measured − b·h) over the nominal interval.
        let (dtheta, dv) = match &self.compensation {
            Some(c) => c.compensate(&(dtheta, dv), self.nominal_s),
            None => (dtheta, dv),
        };
        ImuItem::Sample { t_s: s.t_s, dtheta, dv }
    }
}

/// One IMU sample as the computer gets it, with its instant.
#[derive(Debug, Clone, Copy)]
struct Sample {
    t_s: f64,
    dtheta: Vector3<f64>,
    dv: Vector3<f64>,
}

/// A log set being played back through the navigation computer.
pub struct Playback {
    /// The navigation computer.
    pub core: InsCore,
    imu: ImuSamples,
    origin_s: f64,
    /// The IMU file's first stamp on its own clock, s (times out are `file_clock_s + origin_s + t`).
    file_start_s: f64,
    encoders: Option<Track>,
    initial_angles: AxisValues,
    reference: ReferenceTrack,
    /// Samples read ahead of the computer (the second of motion that ended an alignment window).
    pending: VecDeque<Sample>,
    /// The end of the span replayed, s after the IMU's first stamp.
    until_s: f64,
    /// IMU samples fed to the computer (after the pre-roll).
    pub samples: u64,
    /// Gaps carried across.
    pub gaps: Vec<Gap>,
    /// The alignment, when the INS was aligned on the data.
    pub alignment: Option<AlignmentReport>,
    /// Things said once about the data (a reference that starts late, a trimmed span...).
    pub notes: Vec<String>,
    /// Whether the last reference lookup found the reference inside its file's span.
    reference_inside: Option<bool>,
    /// The IMU file (for messages).
    imu_path: std::path::PathBuf,
    /// The IMU file was read to its end (not cut short by `--to`).
    imu_read_to_end: bool,
}

enum ReferenceTrack {
    None,
    Static(Attitude),
    File(Box<Track>),
}

/// The units check of a segment at rest (an alignment window, or a log whose reference declares the
/// body at rest): gravity's size in the accelerometers and, when no encoder file says the table
/// turns, at most a small rate in the gyros — rates declared as increments, degrees as radians, g as
/// m/s² are named. Over the first `span_s`: the whole alignment window, so that a vehicle rocking
/// back and forth nets out in the mean rate (5 s of it need not).
fn check_units_at_rest(log: &LogSet, span_s: f64) -> Result<(), PlaybackError> {
    let options = ImuSamples::options(log);
    let mut check = crate::io::StaticCheck { duration_s: span_s, ..crate::io::StaticCheck::default() };
    if log.encoders.is_some() {
        check.max_gyro_rad_per_s = f64::INFINITY;
    }
    let report = crate::io::check_static(&log.imu.path, &options, &check)?;
    if report.problems.is_empty() {
        return Ok(());
    }
    Err(PlaybackError::Log(LogError::Implausible { file: log.imu.path.clone(), message: report.problems.join("; ") }))
}

/// The file-clock seconds of a first stamp.
fn clock_s(start: StartTime) -> f64 {
    match start {
        StartTime::Seconds(s) | StartTime::GpsSecondsOfWeek(s) => s,
        StartTime::Nanoseconds(ns) => ns as f64 * 1e-9,
    }
}

impl Playback {
    /// Opens `log` (its IMU file, tracks, pre-roll and initial attitude); `compensation` is the table
    /// model a body-attitude start is demodulated with.
    pub fn open(log: &LogSet, compensation: &TableErrors) -> Result<Self, PlaybackError> {
        let cfg = &log.table.ins;
        let f = &log.imu;
        let (imu, start) = ImuSamples::open_checked(log)?;
        let nominal_s = 1.0 / f.rate_hz;
        let mut initial_angles = [0.0; MAX_AXES];
        for (k, a) in log.table.chain.axes().iter().enumerate() {
            initial_angles[k] = a.initial_angle_rad;
        }
        let encoders = encoder_track(log, start)?;
        let reference = match &log.reference {
            Reference::None => ReferenceTrack::None,
            Reference::Static(a) => ReferenceTrack::Static(*a),
            Reference::File(p) => {
                let names = ["pitch", "roll", "heading"].map(String::from);
                let mut t = open_track(p, "reference attitude", &names, vec![false, true, true], start, nominal_s)?;
                // A reference that starts late or ends early: the comparison covers its span.
                t.clip = true;
                ReferenceTrack::File(Box::new(t))
            }
        };
        let file_start_s = clock_s(start);
        let (from_rel, until_s) =
            (log.span_s.0.map(|t| t - file_start_s), log.span_s.1.map_or(f64::INFINITY, |t| t - file_start_s));
        let mut me = Self {
            core: InsCore::new(cfg, log.table.site, Rot::identity(), &[]),
            imu,
            origin_s: 0.0,
            file_start_s,
            encoders,
            initial_angles,
            reference,
            pending: VecDeque::new(),
            until_s,
            samples: 0,
            gaps: Vec::new(),
            alignment: None,
            notes: Vec::new(),
            reference_inside: None,
            imu_path: f.path.clone(),
            imu_read_to_end: false,
        };
        if let Some(from) = from_rel {
            let mut skipped = 0u64;
            loop {
                let Some(s) = me.read()? else {
                    return Err(data_err(format!(
                        "{}: log.from_s = {} s is after the file's last sample",
                        f.path.display(),
                        crate::io::fixed_number(from + file_start_s, 6)
                    )));
                };
                if s.t_s >= from - 0.5 * nominal_s {
                    me.pending.push_back(s);
                    break;
                }
                skipped += 1;
            }
            me.notes.push(format!(
                "replayed from {} s on the file's clock ({skipped} samples before it skipped)",
                crate::io::fixed_number(from + file_start_s, 6)
            ));
        }
        if until_s.is_finite() {
            me.notes.push(format!(
                "replayed up to {} s on the file's clock",
                crate::io::fixed_number(until_s + file_start_s, 6)
            ));
        }
        if matches!(log.reference, Reference::Static(_)) {
            check_units_at_rest(log, 5.0)?;
        }
        if log.table.navigation_absent {
            me.notes.push(
                "not navigated: the table description has no [navigation] (the INS integrates the attitude only, as the scenario it describes does in the loop); add `[navigation]` (e.g. vertical = \"held\") for position and velocity"
                    .to_owned(),
            );
        }
        let pre = InsCore::pre_roll_samples(cfg);
        let mut velocity = log.initial_velocity_enu_mps;
        let (start_attitude, pre_roll, biases) = match log.initial {
            Initial::Alignment { duration_s } => match start::aligned(&mut me, log, compensation, duration_s, pre)? {
                Some((attitude, pre_roll, report, biases)) => {
                    let (g, a) = (biases.bg / RAD_PER_S_PER_DEG_PER_H, biases.ba / MPS2_PER_UG);
                    me.notes.push(format!(
                        "the navigation removes the biases the alignment estimated (gyro {:.4}, {:.4}, {:.4} °/h; accelerometer {:.0}, {:.0}, {:.0} µg; sensor axes): they and its attitude are one solution of the data at rest",
                        g.x, g.y, g.z, a.x, a.y, a.z
                    ));
                    me.alignment = Some(report);
                    (attitude, pre_roll, Some(biases))
                }
                // Moving at the start, and the file's header says how it started (a PSINS .imu).
                None => {
                    let h = log.header_start.as_ref().ok_or_else(|| data_err("internal: no header start"))?;
                    me.notes.push(format!(
                        "the vehicle moves at the start: the INS starts from {}'s attitude (pitch {:.4}°, roll {:.4}°, heading {:.4}°) and velocity (E {:.3}, N {:.3}, U {:.3} m/s), not from an alignment",
                        h.source,
                        h.attitude.pitch_rad.to_degrees(),
                        h.attitude.roll_rad.to_degrees(),
                        h.attitude.heading_rad.to_degrees(),
                        h.velocity_enu_mps[0],
                        h.velocity_enu_mps[1],
                        h.velocity_enu_mps[2]
                    ));
                    velocity.get_or_insert(h.velocity_enu_mps);
                    let (attitude, pre_roll) =
                        me.given_start(log, compensation, &Initial::BodyAttitude(h.attitude), pre)?;
                    (attitude, pre_roll, None)
                }
            },
            given => {
                let (attitude, pre_roll) = me.given_start(log, compensation, &given, pre)?;
                (attitude, pre_roll, None)
            }
        };
        me.core = InsCore::compensated(cfg, log.table.site, start_attitude, &pre_roll, biases);
        if let Some(v) = velocity {
            me.core.set_velocity(Vector3::from(v));
        }
        Ok(me)
    }

    /// A start whose attitude is given: the pre-roll read, C_s^n at its end.
    fn given_start(
        &mut self,
        log: &LogSet,
        compensation: &TableErrors,
        given: &Initial,
        pre: usize,
    ) -> Result<(Rot<crate::math::frames::N, S>, Vec<IncrementPair>), PlaybackError> {
        let mut window = Vec::with_capacity(pre);
        while window.len() < pre {
            let Some(s) = self.read()? else {
                return Err(data_err(format!(
                    "{}: the log ends before the pre-roll ({pre} samples)",
                    log.imu.path.display()
                )));
            };
            window.push(s);
        }
        self.origin_s = window.last().map_or(0.0, |w| w.t_s);
        let pre_roll: Vec<(Vector3<f64>, Vector3<f64>)> = window.iter().map(|s| (s.dtheta, s.dv)).collect();
        let attitude = match *given {
            Initial::ImuQuaternion([w, x, y, z]) => {
                // FRAME: the manifest states C_s^n at the end of the pre-roll.
                Rot::from_quaternion(nalgebra::UnitQuaternion::new_normalize(nalgebra::Quaternion::new(w, x, y, z)))
            }
            Initial::BodyAttitude(att) => {
                att.n_from_b() * self.table_b_from_s(log, compensation, -self.core.fir_delay_s)?
            }
            Initial::Alignment { .. } => return Err(data_err("internal: an alignment is not a given start")),
        };
        Ok((attitude, pre_roll))
    }

    /// C_b^s... as `b_from_s`: the compensated table's rotation at instant `t_s` (seconds after the
    /// origin), from the encoder reading then.
    fn table_b_from_s(
        &mut self,
        log: &LogSet,
        compensation: &TableErrors,
        t_s: f64,
    ) -> Result<Rot<crate::math::frames::B, S>, PlaybackError> {
        let enc = self.encoders_at(t_s)?;
        let corrected = DemodState::default().correct(compensation, t_s, &enc);
        Ok(log.table.chain.b_from_s(&log.table.chain.error_rotations(compensation), &corrected))
    }

    /// How long the replay will be, s after its origin, as the file states or suggests its length
    /// (the span asked for taken into account); None where the format does not tell.
    #[must_use]
    pub fn length_hint_s(&self) -> Option<f64> {
        self.imu.duration_hint_s().map(|d| (d.min(self.until_s) - self.origin_s).max(0.0))
    }

    /// An instant (seconds after the replay's origin) on the IMU file's own clock, s.
    #[must_use]
    pub fn file_time_s(&self, t_s: f64) -> f64 {
        self.file_start_s + self.origin_s + t_s
    }

    /// The next IMU sample through the computer; None at the end of the log.
    #[inline]
    pub fn step(&mut self) -> Result<Option<SampleOut>, PlaybackError> {
        let Some(s) = self.read()? else { return Ok(None) };
        self.samples += 1;
        let out = self.core.push(s.t_s - self.origin_s, s.dtheta, s.dv);
        // Every sample is inside the readers' bounds (`io::validity`), so this is a last line of
        // defence: a result is finite, or the replay stops here and says where.
        if out.updated && !self.core.is_finite() {
            return Err(data_err(format!(
                "{}: the navigation solution stops being a finite number at {} s on the file's clock (IMU sample {}): the data drive the INS beyond what it can integrate",
                self.imu_path.display(),
                crate::io::fixed_number(self.file_time_s(out.t_s), 6),
                self.samples
            )));
        }
        Ok(Some(out))
    }

    /// After the last sample: reads what is left of the encoder and reference files (their
    /// readings after the IMU's last instant), so that damage anywhere in them is reported — when
    /// the IMU file was read to its end (a replay cut short by `--to` reads no file further).
    pub fn finish(&mut self) -> Result<(), PlaybackError> {
        if !self.imu_read_to_end {
            return Ok(());
        }
        if let Some(t) = self.encoders.as_mut() {
            t.read_to_end()?;
        }
        if let ReferenceTrack::File(t) = &mut self.reference {
            t.read_to_end()?;
        }
        Ok(())
    }

    /// The raw encoder angles at instant `t_s` (the table's initial angles without an encoder file).
    pub fn encoders_at(&mut self, t_s: f64) -> Result<AxisValues, PlaybackError> {
        match self.encoders.as_mut() {
            None => Ok(self.initial_angles),
            Some(track) => Ok(track.at(t_s + self.origin_s)?.unwrap_or(self.initial_angles)),
        }
    }

    /// The reference body attitude at instant `t_s`, if the log has one.
    pub fn reference_at(&mut self, t_s: f64) -> Result<Option<Attitude>, PlaybackError> {
        Ok(match &mut self.reference {
            ReferenceTrack::None => None,
            ReferenceTrack::Static(a) => Some(*a),
            ReferenceTrack::File(track) => {
                let v = track.at(t_s + self.origin_s)?;
                let inside = v.is_some();
                if self.reference_inside != Some(inside) {
                    let first = self.reference_inside.is_none();
                    let (from, to) = (track.span_seen.0.unwrap_or(0.0), track.span_seen.1);
                    let clock = |t: f64| self.file_start_s + t;
                    match (first, inside) {
                        (true, true) => {}
                        (true, false) => self.notes.push(format!("the reference in {} starts at {:.6} s (file clock), after the replay's start at {:.6} s: the comparison starts there", track.path.display(), clock(from), clock(t_s + self.origin_s))),
                        (false, true) => {}
                        (false, false) => self.notes.push(format!("the reference in {} ends at {:.6} s (file clock): the comparison stops there", track.path.display(), clock(to))),
                    }
                    self.reference_inside = Some(inside);
                }
                v.map(|v| Attitude { pitch_rad: v[0], roll_rad: v[1], heading_rad: v[2] })
            }
        })
    }

    /// The body attitude the computer's integrator `k` gives through the table rotation of `corrected`
    /// encoder angles with errors `rot` of `errors`, at its latest output.
    #[must_use]
    pub fn body_attitude(
        &self,
        k: usize,
        chain: &crate::model::gimbal::Chain,
        rot: &crate::model::gimbal::ErrorRotations,
        angles: &AxisValues,
    ) -> Attitude {
        self.body_attitude_through(k, chain.b_from_s(rot, angles))
    }

    /// The body attitude integrator `k` gives through the table rotation C_b^s... as `b_from_s`.
    #[must_use]
    pub fn body_attitude_through(
        &self,
        k: usize,
        b_from_s: crate::math::frames::Rot<crate::math::frames::B, crate::math::frames::S>,
    ) -> Attitude {
        let (_, n_from_s) = self.core.output_attitude(k);
        demodulate(n_from_s, b_from_s)
    }

    /// One sample as increments in the RFU sensor frame, or None at the end (gaps recorded).
    #[inline]
    fn read(&mut self) -> Result<Option<Sample>, PlaybackError> {
        if let Some(s) = self.pending.pop_front() {
            return Ok(Some(s));
        }
        loop {
            match self.imu.next_item()? {
                None => {
                    self.imu_read_to_end = true;
                    return Ok(None);
                }
                // The end of the span replayed (--to): the rest of the file is not read.
                Some(ImuItem::Sample { t_s, .. }) if t_s > self.until_s + 1e-9 => return Ok(None),
                Some(ImuItem::Gap { from_s, to_s }) => {
                    self.gaps.push(Gap { from_s: from_s - self.origin_s, to_s: to_s - self.origin_s })
                }
                Some(ImuItem::Sample { t_s, dtheta, dv }) => return Ok(Some(Sample { t_s, dtheta, dv })),
            }
        }
    }
}

/// What a log set's IMU file yields, in order.
#[derive(Debug, Clone, Copy)]
pub enum ImuItem {
    /// One sample as increments in the RFU sensor frame: its stamp (s, the file's clock),
    /// Δθ (rad) and Δv (m/s).
    Sample {
        /// Stamp, s.
        t_s: f64,
        /// Angle increment, rad.
        dtheta: Vector3<f64>,
        /// Velocity increment, m/s.
        dv: Vector3<f64>,
    },
    /// A gap in the samples (the file's clock), s.
    Gap {
        /// Last stamp before it.
        from_s: f64,
        /// First stamp after it.
        to_s: f64,
    },
}

/// The encoder file of `log` as a track on the IMU's clock (first stamp `start`), if it has one.
fn encoder_track(log: &LogSet, start: StartTime) -> Result<Option<Track>, PlaybackError> {
    let Some(e) = &log.encoders else { return Ok(None) };
    let names: Vec<String> = log.table.chain.axes().iter().map(|a| a.name.clone()).collect();
    let mut t = open_track(&e.path, "encoder", &names, vec![true; names.len()], start, 1.0 / log.imu.rate_hz)?;
    t.shift_s = -e.latch_delay_s;
    t.interpolate_gaps = e.interpolate_gaps;
    Ok(Some(t))
}

/// A log set's IMU samples, its encoder readings, and the span asked for (s after the first stamp).
pub type WithEncoders = (ImuSamples, Option<EncoderReadings>, (f64, f64));

/// A log set's encoder readings at the IMU's instants (what `selfcal --log` measures the table's
/// errors with), raw: no compensation.
pub struct EncoderReadings(Track);

impl EncoderReadings {
    /// The readings at `t_s` (an [`ImuItem::Sample`]'s stamp), rad.
    pub fn at(&mut self, t_s: f64) -> Result<AxisValues, PlaybackError> {
        self.0.at(t_s)?.ok_or_else(|| {
            data_err(format!(
                "{}: no encoder reading at {t_s:.6} s after the IMU's first sample",
                self.0.path.display()
            ))
        })
    }
}

/// The IMU samples of a log set without the navigation computer (what `rinscope allan` reads):
/// increments in the RFU sensor frame (rates held over their interval), gaps reported, not bridged.
pub struct ImuSamples {
    imu: ImuStream,
    /// The log's length as its file states or suggests it, s ([`ImuReader::duration_hint_s`]).
    duration_hint_s: Option<f64>,
}

impl ImuSamples {
    /// Opens `log`'s IMU file as its manifest describes it.
    pub fn open(log: &LogSet) -> Result<Self, PlaybackError> {
        Ok(Self::open_checked(log)?.0)
    }

    /// [`Self::open`], the log's encoder file on the same clock if it has one, and the span the
    /// manifest asks for (`log.from_s`, `log.to_s`) on that clock (s after the first stamp).
    pub fn open_with_encoders(log: &LogSet) -> Result<WithEncoders, PlaybackError> {
        let (me, start) = Self::open_checked(log)?;
        let first = clock_s(start);
        let span =
            (log.span_s.0.map_or(f64::NEG_INFINITY, |t| t - first), log.span_s.1.map_or(f64::INFINITY, |t| t - first));
        Ok((me, encoder_track(log, start)?.map(EncoderReadings), span))
    }

    /// The reader options of `log`'s IMU file.
    fn options(log: &LogSet) -> ImuOptions {
        let f = &log.imu;
        let mut options = ImuOptions::new(f.layout.clone());
        options.frame = f.frame.clone();
        options.topic = f.topic.clone();
        options.gap_policy = f.gap_policy;
        options.gap_factor = f.gap_factor;
        options.nominal_dt_s = Some(1.0 / f.rate_hz);
        options
    }

    /// Opens it, checks the declared rate against the stamps; also returns the first stamp.
    fn open_checked(log: &LogSet) -> Result<(Self, StartTime), PlaybackError> {
        let f = &log.imu;
        let imu = ImuReader::open(&f.path, &Self::options(log))?;
        if let Some(declared) = f.kind
            && imu.kind() != declared
        {
            return Err(data_err(format!(
                "{}: the file holds {} (its columns {}), the manifest says kind = \"{}\"",
                f.path.display(),
                kind_name(imu.kind()),
                imu.columns().join(", "),
                kind_name(declared)
            )));
        }
        let start = imu.start_time().ok_or_else(|| data_err(format!("{}: no IMU samples", f.path.display())))?;
        let increments = Increments {
            kind: imu.kind(),
            nominal_s: 1.0 / f.rate_hz,
            last_t: None,
            pending_gap: false,
            compensation: log.imu_compensation,
        };
        let duration_hint_s = imu.duration_hint_s();
        Ok((Self { imu: ImuStream::spawn(imu, increments)?, duration_hint_s }, start))
    }

    /// The log's length, s, as its file states it (.npy, Parquet, a summarised MCAP) or suggests
    /// it (text: its size); None where unknown.
    #[must_use]
    pub fn duration_hint_s(&self) -> Option<f64> {
        self.duration_hint_s
    }

    /// The next sample or gap; None at the end of the file.
    #[inline]
    pub fn next_item(&mut self) -> Result<Option<ImuItem>, PlaybackError> {
        Ok(self.imu.next().transpose()?)
    }
}

/// The largest relative difference accepted between the declared rate and the stamps' (checked when
/// the log set is loaded: `scenario::logset`).
pub use crate::io::RATE_TOLERANCE;

fn kind_name(k: SampleKind) -> &'static str {
    match k {
        SampleKind::Increments => "increments",
        SampleKind::Rates => "rates",
    }
}
