//! A log set played back: the IMU samples feed the navigation computer (`ins::core`, the one the
//! simulation uses), the encoder and reference files are looked up at the instants the computer asks
//! for. `replay` and `calibrate --log` both drive it. Memory stays flat in the log's length: the
//! files stream, the tracks keep a few readings around the instant asked for.
//!
//! Time: every instant is seconds after the end of the pre-roll (the first `pre` samples that fill
//! the FIR and give the algorithms their previous samples), or after the alignment interval.

use std::collections::VecDeque;
use std::path::{Path, PathBuf};

use nalgebra::{Matrix3, Vector3};

use crate::ins::core::{InsCore, SampleOut};
use crate::io::{BlockEnd, Col, ColumnReader, Format, ImuEvent, ImuOptions, ImuReader, ImuSample, LogError, ReadOptions, SampleKind, StartTime, StaticCheck};
use crate::math::attitude::Attitude;
use crate::math::frames::{Rot, N, S};
use crate::math::units::{wrap_pi, ARCSEC_PER_RAD};
use crate::model::earth::{normal_gravity, omega_ie_n};
use crate::model::gimbal::TableErrors;
use crate::model::scheme::{AxisValues, MAX_AXES};
use crate::scenario::logset::{Initial, LogSet, Reference};
use crate::sim::{demodulate, DemodState};

/// A problem with a log set's data, naming the file and where.
#[derive(Debug, thiserror::Error)]
pub enum PlaybackError {
    /// A file could not be read or holds bad data (the message names file, row, column, value).
    #[error("{0}")]
    Log(#[from] LogError),
    /// The data do not fit together (clocks, lengths, the vehicle moving during alignment...).
    #[error("{0}")]
    Data(String),
}

fn data_err(message: impl Into<String>) -> PlaybackError {
    PlaybackError::Data(message.into())
}

/// How a track's time column relates to the IMU's first stamp.
#[derive(Debug, Clone, Copy)]
enum Clock {
    /// Seconds: t − t0.
    Seconds(f64),
    /// Integer nanoseconds: (t − t0)·1e-9.
    Nanoseconds(i64),
    /// GPS seconds of week, with rollover.
    Gps(f64),
}

/// Readings of a file at the instants asked for: exact where a reading has that stamp (within a
/// nanosecond), linear between the two readings around it otherwise (angles across ±180° by the
/// shorter way).
struct Track {
    path: PathBuf,
    what: &'static str,
    reader: ColumnReader,
    /// Unit factor of each value column.
    to_si: Vec<f64>,
    /// Which value columns are angles that may wrap.
    wraps: Vec<bool>,
    clock: Clock,
    time_ns: bool,
    /// Seconds to add to a stamp (the encoders' latch delay, negative: the reading is older).
    shift_s: f64,
    buf: VecDeque<(f64, [f64; MAX_AXES])>,
    exhausted: bool,
    interpolate_gaps: bool,
    nominal_s: f64,
    gap_factor: f64,
}

const MATCH_S: f64 = 1e-9;

impl Track {
    fn at(&mut self, t: f64) -> Result<[f64; MAX_AXES], PlaybackError> {
        while !self.exhausted && self.buf.back().is_none_or(|(tb, _)| *tb < t - MATCH_S) {
            self.read_one()?;
        }
        // Keep the two readings around t (and one before, for a rate).
        while self.buf.len() > 3 && self.buf[1].0 <= t - MATCH_S {
            self.buf.pop_front();
        }
        let Some(&(t_first, v_first)) = self.buf.front() else {
            return Err(data_err(format!("{}: the {} file has no readings", self.path.display(), self.what)));
        };
        if let Some(&(_, v)) = self.buf.iter().find(|(tk, _)| (tk - t).abs() <= MATCH_S) {
            return Ok(v);
        }
        if t < t_first {
            // Half a nominal interval of slack before the first reading (a log starting with the IMU).
            if t_first - t <= 0.5 * self.nominal_s {
                return Ok(v_first);
            }
            return Err(data_err(format!(
                "{}: the {} readings start at {:.6} s, the IMU data need them from {:.6} s: the clocks do not overlap",
                self.path.display(),
                self.what,
                t_first,
                t
            )));
        }
        let j = self.buf.iter().position(|(tk, _)| *tk > t);
        let Some(j) = j else {
            let (t_last, v_last) = self.buf[self.buf.len() - 1];
            if t - t_last <= 0.5 * self.nominal_s {
                return Ok(v_last);
            }
            return Err(data_err(format!("{}: the {} readings end at {:.6} s, the IMU data go on to {:.6} s", self.path.display(), self.what, t_last, t)));
        };
        let (ta, va) = self.buf[j - 1];
        let (tb, vb) = self.buf[j];
        if tb - ta > self.gap_factor * self.nominal_s && !self.interpolate_gaps {
            return Err(data_err(format!(
                "{}: a gap of {:.6} s in the {} readings between {:.6} s and {:.6} s (gap_policy = \"refuse\"; \"interpolate\" bridges it)",
                self.path.display(),
                tb - ta,
                self.what,
                ta,
                tb
            )));
        }
        let f = (t - ta) / (tb - ta);
        let mut out = [0.0; MAX_AXES];
        for k in 0..self.to_si.len() {
            let d = if self.wraps[k] { wrap_pi(vb[k] - va[k]) } else { vb[k] - va[k] };
            out[k] = va[k] + f * d;
        }
        Ok(out)
    }

    fn read_one(&mut self) -> Result<(), PlaybackError> {
        let n = self.to_si.len();
        let mut row = [0.0; 1 + MAX_AXES];
        if !self.reader.next_row(&mut row[..=n])? {
            self.exhausted = true;
            return Ok(());
        }
        let t = match self.clock {
            Clock::Seconds(t0) => row[0] - t0,
            Clock::Gps(t0) => {
                let d = row[0] - t0;
                if d < -302_400.0 { d + 604_800.0 } else { d }
            }
            Clock::Nanoseconds(t0) => match (self.time_ns, self.reader.exact_integer(0)) {
                (true, Some(ns)) => (ns - t0) as f64 * 1e-9,
                _ => row[0] - t0 as f64 * 1e-9,
            },
        } + self.shift_s;
        if let Some(&(t_prev, _)) = self.buf.back()
            && t <= t_prev
        {
            return Err(data_err(format!(
                "{} ({}): time {:.9} s is not after the previous reading's {:.9} s; stamps must increase",
                self.path.display(),
                self.reader.location(),
                t,
                t_prev
            )));
        }
        let mut v = [0.0; MAX_AXES];
        for k in 0..n {
            v[k] = row[1 + k] * self.to_si[k];
        }
        self.buf.push_back((t, v));
        Ok(())
    }
}

/// Opens a track of `names` (value columns, each `<name>_<angle unit>`; in an .npy, columns 1..)
/// with a time column `t_s`, `t_ns` or `gps_sow_s` (an .npy: column 0, seconds).
fn open_track(path: &Path, what: &'static str, names: &[String], wraps: Vec<bool>, start: StartTime, nominal_s: f64) -> Result<Track, PlaybackError> {
    let probe = ColumnReader::open(path, &[], &ReadOptions::default())?;
    let all: Vec<String> = probe.all_columns().to_vec();
    let format = probe.format();
    drop(probe);
    let (cols, to_si, time_ns, time_gps) = if format == Format::Npy {
        if all.len() < 1 + names.len() {
            return Err(data_err(format!("{}: {} columns; the {what} .npy needs t_s then {} (rad)", path.display(), all.len(), names.join(", "))));
        }
        ((0..=names.len()).map(Col::from).collect::<Vec<_>>(), vec![1.0; names.len()], false, false)
    } else {
        let time = ["t_s", "t_ns", "gps_sow_s"].into_iter().find(|c| all.iter().any(|a| a == c)).ok_or_else(|| {
            data_err(format!("{}: no time column; the {what} file needs t_s, t_ns or gps_sow_s (columns: {})", path.display(), all.join(", ")))
        })?;
        let mut cols = vec![Col::from(time)];
        let mut to_si = Vec::new();
        for name in names {
            let found = all.iter().find_map(|a| crate::io::units::split_unit(a).filter(|(base, u)| base == name && u.quantity == crate::io::units::Quantity::Angle).map(|(_, u)| (a.clone(), u.to_si)));
            let Some((col, f)) = found else {
                return Err(data_err(format!(
                    "{}: no column for `{name}` in the {what} file; expected {name}_rad, {name}_deg or {name}_arcsec (columns: {})",
                    path.display(),
                    all.join(", ")
                )));
            };
            cols.push(Col::from(col.as_str()));
            to_si.push(f);
        }
        (cols, to_si, time == "t_ns", time == "gps_sow_s")
    };
    let reader = ColumnReader::open(path, &cols, &ReadOptions::default())?;
    let clock = match start {
        StartTime::Nanoseconds(ns) => Clock::Nanoseconds(ns),
        StartTime::Seconds(s) if time_ns => Clock::Nanoseconds((s * 1e9).round() as i64),
        StartTime::Seconds(s) => Clock::Seconds(s),
        StartTime::GpsSecondsOfWeek(s) if time_gps || !time_ns => Clock::Gps(s),
        StartTime::GpsSecondsOfWeek(s) => Clock::Nanoseconds((s * 1e9).round() as i64),
    };
    Ok(Track {
        path: path.to_path_buf(),
        what,
        reader,
        to_si,
        wraps,
        clock,
        time_ns,
        shift_s: 0.0,
        buf: VecDeque::new(),
        exhausted: false,
        interpolate_gaps: true,
        nominal_s,
        gap_factor: 3.0,
    })
}

/// A gap in the IMU data that the replay carried the attitude across.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct Gap {
    /// Last sample before it, s.
    pub from_s: f64,
    /// First sample after it, s.
    pub to_s: f64,
}

/// The IMU file read on a thread of its own, in blocks: parsing the file overlaps the navigation.
struct ImuStream {
    rx: crossbeam_channel::Receiver<Block>,
    samples: std::vec::IntoIter<ImuSample>,
}

/// What the reading thread sends.
enum Block {
    Samples(Vec<ImuSample>),
    Gap(ImuEvent),
    Error(LogError),
}

/// Samples per block handed from the reading thread.
const IMU_BLOCK: usize = 4096;

impl ImuStream {
    fn spawn(mut reader: ImuReader) -> Result<Self, PlaybackError> {
        let (tx, rx) = crossbeam_channel::bounded(4);
        std::thread::Builder::new()
            .name("imu-reader".into())
            .spawn(move || {
                loop {
                    let mut samples = Vec::with_capacity(IMU_BLOCK);
                    let end = reader.next_samples(&mut samples, IMU_BLOCK);
                    if !samples.is_empty() && tx.send(Block::Samples(samples)).is_err() {
                        return;
                    }
                    let next = match end {
                        Ok(BlockEnd::Full) => continue,
                        Ok(BlockEnd::Gap(g)) => Block::Gap(g),
                        Ok(BlockEnd::End) => return,
                        Err(e) => Block::Error(e),
                    };
                    let last = matches!(next, Block::Error(_));
                    if tx.send(next).is_err() || last {
                        return;
                    }
                }
            })
            .map_err(|e| data_err(format!("cannot start the IMU reader: {e}")))?;
        Ok(Self { rx, samples: Vec::new().into_iter() })
    }

    fn next(&mut self) -> Option<Result<ImuEvent, LogError>> {
        loop {
            if let Some(s) = self.samples.next() {
                return Some(Ok(ImuEvent::Sample(s)));
            }
            match self.rx.recv().ok()? {
                Block::Samples(v) => self.samples = v.into_iter(),
                Block::Gap(g) => return Some(Ok(g)),
                Block::Error(e) => return Some(Err(e)),
            }
        }
    }
}

/// One IMU sample as the computer gets it, with its instant.
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
    encoders: Option<Track>,
    initial_angles: AxisValues,
    reference: ReferenceTrack,
    /// IMU samples fed to the computer (after the pre-roll).
    pub samples: u64,
    /// Gaps carried across.
    pub gaps: Vec<Gap>,
}

enum ReferenceTrack {
    None,
    Static(Attitude),
    File(Box<Track>),
}

impl Playback {
    /// Opens `log` (its IMU file, tracks, pre-roll and initial attitude); `compensation` is the table
    /// model a body-attitude start is demodulated with.
    pub fn open(log: &LogSet, compensation: &TableErrors) -> Result<Self, PlaybackError> {
        let cfg = &log.table.ins;
        let f = &log.imu;
        let static_start = matches!(log.initial, Initial::Alignment { .. }) || matches!(log.reference, Reference::Static(_));
        // Rates declared as increments (or degrees as radians) show in a resting log's gravity and Earth rate.
        let (imu, start) = ImuSamples::open_checked(log, static_start)?;
        let nominal_s = 1.0 / f.rate_hz;
        let axis_names: Vec<String> = log.table.chain.axes().iter().map(|a| a.name.clone()).collect();
        let mut initial_angles = [0.0; MAX_AXES];
        for (k, a) in log.table.chain.axes().iter().enumerate() {
            initial_angles[k] = a.initial_angle_rad;
        }
        let encoders = match &log.encoders {
            None => None,
            Some(e) => {
                let mut t = open_track(&e.path, "encoder", &axis_names, vec![true; axis_names.len()], start, nominal_s)?;
                t.shift_s = -e.latch_delay_s;
                t.interpolate_gaps = e.interpolate_gaps;
                Some(t)
            }
        };
        let reference = match &log.reference {
            Reference::None => ReferenceTrack::None,
            Reference::Static(a) => ReferenceTrack::Static(*a),
            Reference::File(p) => {
                let names = ["pitch", "roll", "heading"].map(String::from);
                ReferenceTrack::File(Box::new(open_track(p, "reference attitude", &names, vec![false, true, true], start, nominal_s)?))
            }
        };
        let pre = InsCore::pre_roll_samples(cfg);
        // The alignment interval (static) comes first; its last `pre` samples are the pre-roll.
        let align_s = match log.initial {
            Initial::Alignment { duration_s } => duration_s,
            _ => 0.0,
        };
        let mut window: VecDeque<Sample> = VecDeque::new();
        let (mut sum_dtheta, mut sum_dv, mut span_s, mut first_t) = (Vector3::zeros(), Vector3::zeros(), 0.0, None);
        let mut me = Self {
            core: InsCore::new(cfg, log.table.site, Rot::identity(), &[]),
            imu,
            origin_s: 0.0,
            encoders,
            initial_angles,
            reference,
            samples: 0,
            gaps: Vec::new(),
        };
        loop {
            let Some(s) = me.read()? else {
                return Err(data_err(format!("{}: the log ends before the pre-roll ({pre} samples) and alignment ({align_s} s) are over", f.path.display())));
            };
            let t0 = *first_t.get_or_insert(s.t_s);
            if s.t_s - t0 <= align_s + 0.5 * nominal_s {
                sum_dtheta += s.dtheta;
                sum_dv += s.dv;
                span_s = s.t_s - t0 + nominal_s;
            }
            window.push_back(s);
            if window.len() > pre.max(1) {
                window.pop_front();
            }
            let t_last = window.back().map_or(0.0, |w| w.t_s);
            if window.len() >= pre && t_last - t0 >= align_s - 0.5 * nominal_s {
                break;
            }
        }
        me.origin_s = window.back().map_or(0.0, |w| w.t_s);
        let pre_roll: Vec<(Vector3<f64>, Vector3<f64>)> = window.iter().map(|s| (s.dtheta, s.dv)).collect();
        let site = log.table.site;
        let start_attitude = match log.initial {
            Initial::ImuQuaternion([w, x, y, z]) => {
                // FRAME: the manifest states C_s^n at the end of the pre-roll.
                Rot::from_quaternion(nalgebra::UnitQuaternion::new_normalize(nalgebra::Quaternion::new(w, x, y, z)))
            }
            Initial::BodyAttitude(att) => {
                let t_repr = -me.core.fir_delay_s;
                let enc = me.encoders_at(t_repr)?;
                let corrected = DemodState::default().correct(compensation, t_repr, &enc);
                let b_from_s = log.table.chain.b_from_s(&log.table.chain.error_rotations(compensation), &corrected);
                att.n_from_b() * b_from_s
            }
            Initial::Alignment { .. } => coarse_alignment(sum_dtheta / span_s, sum_dv / span_s, site.latitude_rad, site.height_m, &f.path)?,
        };
        me.core = InsCore::new(cfg, site, start_attitude, &pre_roll);
        Ok(me)
    }

    /// The next IMU sample through the computer; None at the end of the log.
    pub fn step(&mut self) -> Result<Option<SampleOut>, PlaybackError> {
        let Some(s) = self.read()? else { return Ok(None) };
        self.samples += 1;
        Ok(Some(self.core.push(s.t_s - self.origin_s, s.dtheta, s.dv)))
    }

    /// The raw encoder angles at instant `t_s` (the table's initial angles without an encoder file).
    pub fn encoders_at(&mut self, t_s: f64) -> Result<AxisValues, PlaybackError> {
        match self.encoders.as_mut() {
            None => Ok(self.initial_angles),
            Some(track) => track.at(t_s + self.origin_s),
        }
    }

    /// The reference body attitude at instant `t_s`, if the log has one.
    pub fn reference_at(&mut self, t_s: f64) -> Result<Option<Attitude>, PlaybackError> {
        Ok(match &mut self.reference {
            ReferenceTrack::None => None,
            ReferenceTrack::Static(a) => Some(*a),
            ReferenceTrack::File(track) => {
                let v = track.at(t_s + self.origin_s)?;
                Some(Attitude { pitch_rad: v[0], roll_rad: v[1], heading_rad: v[2] })
            }
        })
    }

    /// The body attitude the computer's integrator `k` gives through the table rotation of `corrected`
    /// encoder angles with errors `rot` of `errors`, at its latest output.
    #[must_use]
    pub fn body_attitude(&self, k: usize, chain: &crate::model::gimbal::Chain, rot: &crate::model::gimbal::ErrorRotations, angles: &AxisValues) -> Attitude {
        self.body_attitude_through(k, chain.b_from_s(rot, angles))
    }

    /// The body attitude integrator `k` gives through the table rotation C_b^s... as `b_from_s`.
    #[must_use]
    pub fn body_attitude_through(&self, k: usize, b_from_s: crate::math::frames::Rot<crate::math::frames::B, crate::math::frames::S>) -> Attitude {
        let (_, n_from_s) = self.core.output_attitude(k);
        demodulate(n_from_s, b_from_s)
    }

    /// One sample as increments in the RFU sensor frame, or None at the end (gaps recorded).
    fn read(&mut self) -> Result<Option<Sample>, PlaybackError> {
        loop {
            match self.imu.next_item()? {
                None => return Ok(None),
                Some(ImuItem::Gap { from_s, to_s }) => self.gaps.push(Gap { from_s: from_s - self.origin_s, to_s: to_s - self.origin_s }),
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

/// The IMU samples of a log set without the navigation computer (what `rinscope allan` reads):
/// increments in the RFU sensor frame (rates held over their interval), gaps reported, not bridged.
pub struct ImuSamples {
    imu: ImuStream,
    kind: SampleKind,
    nominal_s: f64,
    last_t: Option<f64>,
    pending_gap: bool,
}

impl ImuSamples {
    /// Opens `log`'s IMU file as its manifest describes it.
    pub fn open(log: &LogSet) -> Result<Self, PlaybackError> {
        Ok(Self::open_checked(log, false)?.0)
    }

    /// Opens it, with the static-segment plausibility check if `static_check`; also returns the
    /// first stamp.
    fn open_checked(log: &LogSet, static_check: bool) -> Result<(Self, StartTime), PlaybackError> {
        let f = &log.imu;
        let mut options = ImuOptions::new(f.layout.clone());
        options.frame = f.frame.clone();
        options.topic = f.topic.clone();
        options.gap_policy = f.gap_policy;
        options.gap_factor = f.gap_factor;
        options.nominal_dt_s = Some(1.0 / f.rate_hz);
        options.static_check = static_check.then(StaticCheck::default);
        let imu = ImuReader::open(&f.path, &options)?;
        if imu.kind() != f.kind {
            return Err(data_err(format!(
                "{}: the file holds {} (its columns {}), the manifest says kind = \"{}\"",
                f.path.display(),
                kind_name(imu.kind()),
                imu.columns().join(", "),
                kind_name(f.kind)
            )));
        }
        let kind = imu.kind();
        let start = imu.start_time().ok_or_else(|| data_err(format!("{}: no IMU samples", f.path.display())))?;
        let imu = ImuStream::spawn(imu)?;
        Ok((Self { imu, kind, nominal_s: 1.0 / f.rate_hz, last_t: None, pending_gap: false }, start))
    }

    /// The next sample or gap; None at the end of the file.
    pub fn next_item(&mut self) -> Result<Option<ImuItem>, PlaybackError> {
        let Some(event) = self.imu.next() else { return Ok(None) };
        match event? {
            ImuEvent::Gap { t_before_s, t_after_s, .. } => {
                self.pending_gap = true;
                Ok(Some(ImuItem::Gap { from_s: t_before_s, to_s: t_after_s }))
            }
            ImuEvent::Sample(s) => {
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
                Ok(Some(ImuItem::Sample { t_s: s.t_s, dtheta, dv }))
            }
        }
    }
}

fn kind_name(k: SampleKind) -> &'static str {
    match k {
        SampleKind::Increments => "increments",
        SampleKind::Rates => "rates",
    }
}

/// Analytic coarse alignment of a resting IMU from its mean angular rate `w_s` (rad/s) and specific
/// force `f_s` (m/s²): the frames built from (f, f × ω, f × (f × ω)) in s and in n (ENU, where
/// f^n = (0, 0, g) and ω^n = Ω (0, cos L, sin L)) give C_s^n (Titterton & Weston §10.2).
fn coarse_alignment(w_s: Vector3<f64>, f_s: Vector3<f64>, latitude_rad: f64, height_m: f64, path: &Path) -> Result<Rot<N, S>, PlaybackError> {
    let g = normal_gravity(latitude_rad, height_m);
    if ((f_s.norm() - g) / g).abs() > 0.05 {
        return Err(data_err(format!(
            "{}: the mean specific force over the alignment interval is {:.4} m/s², not gravity's {g:.4} m/s²: the vehicle moved, or the accelerometer's unit is wrong",
            path.display(),
            f_s.norm()
        )));
    }
    let f_n = Vector3::new(0.0, 0.0, g);
    let w_n = omega_ie_n(latitude_rad);
    let triad = |f: Vector3<f64>, w: Vector3<f64>| -> Option<Matrix3<f64>> {
        let a = f.try_normalize(1e-12)?;
        let b = f.cross(&w).try_normalize(1e-30)?;
        Some(Matrix3::from_columns(&[a, b, a.cross(&b)]))
    };
    let (Some(m_n), Some(m_s)) = (triad(f_n, w_n), triad(f_s, w_s)) else {
        return Err(data_err(format!("{}: the mean rate over the alignment interval is parallel to gravity: no heading (at a pole?)", path.display())));
    };
    let c = m_n * m_s.transpose();
    let q = nalgebra::UnitQuaternion::from_matrix(&c);
    if (w_s.norm() - crate::model::earth::EARTH_RATE).abs() > 20.0 * crate::model::earth::EARTH_RATE {
        return Err(data_err(format!(
            "{}: the mean angular rate over the alignment interval is {:.3e} rad/s ({:.1}″/s), not the Earth's 7.29e-5: the vehicle turned, or the gyro's unit is wrong",
            path.display(),
            w_s.norm(),
            w_s.norm() * ARCSEC_PER_RAD
        )));
    }
    // FRAME: the two triads describe the same physical directions in n and in s.
    Ok(Rot::from_quaternion(q))
}
