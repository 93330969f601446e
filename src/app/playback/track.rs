//! Tracks: the encoder and reference files of a log set, read at the instants the navigation
//! computer asks for (exact at a stamp, linear between two readings), streaming.

use std::collections::VecDeque;
use std::path::{Path, PathBuf};

use super::{PlaybackError, data_err};
use crate::io::validity::{check_angle, check_span};
use crate::io::{Col, ColumnReader, Format, Location, ReadOptions, StartTime, fixed_number};
use crate::math::units::wrap_pi;
use crate::model::scheme::MAX_AXES;

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
pub(super) struct Track {
    pub(super) path: PathBuf,
    what: &'static str,
    reader: ColumnReader,
    /// Unit factor of each value column.
    to_si: Vec<f64>,
    /// Which value columns are angles that may wrap.
    wraps: Vec<bool>,
    clock: Clock,
    time_ns: bool,
    /// Seconds to add to a stamp (the encoders' latch delay, negative: the reading is older).
    pub(super) shift_s: f64,
    /// Readings around the instant asked for: stamp (s after the IMU's first), values, where in the file.
    buf: VecDeque<(f64, [f64; MAX_AXES], Location)>,
    exhausted: bool,
    pub(super) interpolate_gaps: bool,
    /// Outside the file's span: nothing (a reference that starts late or ends early) instead of an error.
    pub(super) clip: bool,
    /// The file's first and last stamps seen (s after the IMU's first), for the one message.
    pub(super) span_seen: (Option<f64>, f64),
    nominal_s: f64,
    gap_factor: f64,
    /// The last stamp read (s after the IMU's first).
    last_t: Option<f64>,
}

const MATCH_S: f64 = 1e-9;

impl Track {
    pub(super) fn at(&mut self, t: f64) -> Result<Option<[f64; MAX_AXES]>, PlaybackError> {
        while !self.exhausted && self.buf.back().is_none_or(|(tb, _, _)| *tb < t - MATCH_S) {
            self.read_one()?;
        }
        // Keep the two readings around t (and one before, for a rate).
        while self.buf.len() > 3 && self.buf[1].0 <= t - MATCH_S {
            self.buf.pop_front();
        }
        let Some(&(t_first, v_first, _)) = self.buf.front() else {
            return Err(data_err(format!("{}: the {} file has no readings", self.path.display(), self.what)));
        };
        if let Some(&(_, v, _)) = self.buf.iter().find(|(tk, _, _)| (tk - t).abs() <= MATCH_S) {
            return Ok(Some(v));
        }
        if t < t_first {
            // Half a nominal interval of slack before the first reading (a log starting with the IMU).
            if t_first - t <= 0.5 * self.nominal_s {
                return Ok(Some(v_first));
            }
            if self.clip {
                return Ok(None);
            }
            return Err(data_err(format!(
                "{}: the {} readings start at {} s, the IMU data need them from {} s: the clocks do not overlap",
                self.path.display(),
                self.what,
                fixed_number(t_first, 6),
                fixed_number(t, 6)
            )));
        }
        let j = self.buf.iter().position(|(tk, _, _)| *tk > t);
        let Some(j) = j else {
            let (t_last, v_last, at) = self.buf[self.buf.len() - 1];
            if t - t_last <= 0.5 * self.nominal_s {
                return Ok(Some(v_last));
            }
            if self.clip {
                return Ok(None);
            }
            return Err(data_err(format!(
                "{}: the {} readings end at {} s ({at}), the IMU data go on to {} s",
                self.path.display(),
                self.what,
                fixed_number(t_last, 6),
                fixed_number(t, 6)
            )));
        };
        let (ta, va, _) = self.buf[j - 1];
        let (tb, vb, at) = self.buf[j];
        if tb - ta > self.gap_factor * self.nominal_s && !self.interpolate_gaps {
            return Err(data_err(format!(
                "{}: {at}: a gap of {} s in the {} readings between {} s and {} s (gap_policy = \"refuse\"; \"interpolate\" bridges it)",
                self.path.display(),
                fixed_number(tb - ta, 6),
                self.what,
                fixed_number(ta, 6),
                fixed_number(tb, 6)
            )));
        }
        let f = (t - ta) / (tb - ta);
        let mut out = [0.0; MAX_AXES];
        for k in 0..self.to_si.len() {
            let d = if self.wraps[k] { wrap_pi(vb[k] - va[k]) } else { vb[k] - va[k] };
            out[k] = va[k] + f * d;
        }
        Ok(Some(out))
    }

    fn read_one(&mut self) -> Result<(), PlaybackError> {
        let Some((t, v, at)) = self.next_reading()? else {
            self.exhausted = true;
            return Ok(());
        };
        self.buf.push_back((t, v, at));
        self.span_seen.0.get_or_insert(t);
        self.span_seen.1 = t;
        Ok(())
    }

    /// The next reading, checked: a number in every cell, a stamp after the previous one on the
    /// IMU's clock, angles inside [`crate::io::validity::MAX_ANGLE_RAD`].
    fn next_reading(&mut self) -> Result<Option<(f64, [f64; MAX_AXES], Location)>, PlaybackError> {
        let n = self.to_si.len();
        let mut row = [0.0; 1 + MAX_AXES];
        if !self.reader.next_row(&mut row[..=n])? {
            return Ok(None);
        }
        let at = self.reader.location();
        let t = match self.clock {
            Clock::Seconds(t0) => row[0] - t0,
            Clock::Gps(t0) => {
                let d = row[0] - t0;
                if d < -302_400.0 { d + 604_800.0 } else { d }
            }
            Clock::Nanoseconds(t0) => match (self.time_ns, self.reader.exact_integer(0)) {
                (true, Some(ns)) => (i128::from(ns) - i128::from(t0)) as f64 * 1e-9,
                _ => row[0] - t0 as f64 * 1e-9,
            },
        } + self.shift_s;
        let columns = self.reader.columns();
        let column = |k: usize| columns.get(k).map_or("", String::as_str);
        check_span(&self.path, at, column(0), row[0], t)?;
        if let Some(t_prev) = self.last_t
            && t <= t_prev
        {
            return Err(data_err(format!(
                "{} ({at}): time {} s is not after the previous reading's {} s; stamps must increase",
                self.path.display(),
                fixed_number(t, 9),
                fixed_number(t_prev, 9)
            )));
        }
        self.last_t = Some(t);
        let mut v = [0.0; MAX_AXES];
        for k in 0..n {
            v[k] = row[1 + k] * self.to_si[k];
            check_angle(&self.path, at, column(1 + k), row[1 + k], v[k])?;
        }
        Ok(Some((t, v, at)))
    }

    /// Reads what is left of the file, checking every reading as [`Self::at`] would and keeping
    /// none of them: damage after the last instant the IMU asked for is reported too.
    pub(super) fn read_to_end(&mut self) -> Result<(), PlaybackError> {
        while !self.exhausted {
            if self.next_reading()?.is_none() {
                self.exhausted = true;
            }
        }
        Ok(())
    }
}

/// Opens a track of `names` (value columns, each `<name>_<angle unit>`; in an .npy, columns 1..)
/// with a time column `t_s`, `t_ns` or `gps_sow_s` (an .npy: column 0, seconds).
pub(super) fn open_track(
    path: &Path,
    what: &'static str,
    names: &[String],
    wraps: Vec<bool>,
    start: StartTime,
    nominal_s: f64,
) -> Result<Track, PlaybackError> {
    let probe = ColumnReader::open(path, &[], &ReadOptions::default())?;
    let all: Vec<String> = probe.all_columns().to_vec();
    let format = probe.format();
    drop(probe);
    let (cols, to_si, time_ns, time_gps) = if format == Format::Npy {
        if all.len() != 1 + names.len() {
            return Err(data_err(format!(
                "{}: {} columns; the {what} .npy holds exactly {}: t_s then {} (rad) — an .npy has no column names, so an array of another width cannot be read",
                path.display(),
                all.len(),
                1 + names.len(),
                names.join(", ")
            )));
        }
        ((0..=names.len()).map(Col::from).collect::<Vec<_>>(), vec![1.0; names.len()], false, false)
    } else {
        let time = ["t_s", "t_ns", "gps_sow_s"].into_iter().find(|c| all.iter().any(|a| a == c)).ok_or_else(|| {
            data_err(format!(
                "{}: no time column; the {what} file needs t_s, t_ns or gps_sow_s (columns: {})",
                path.display(),
                all.join(", ")
            ))
        })?;
        let mut cols = vec![Col::from(time)];
        let mut to_si = Vec::new();
        for name in names {
            let found = all.iter().find_map(|a| {
                crate::io::imu::units::split_unit(a)
                    .filter(|(base, u)| base == name && u.quantity == crate::io::imu::units::Quantity::Angle)
                    .map(|(_, u)| (a.clone(), u.to_si))
            });
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
        clip: false,
        span_seen: (None, 0.0),
        nominal_s,
        gap_factor: 3.0,
        last_t: None,
    })
}
