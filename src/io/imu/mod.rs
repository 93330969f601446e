//! IMU logs as a stream of [`ImuSample`]s in SI units and rinscope's RFU frame, with time checks.
//!
//! # Layouts
//!
//! **rinscope** ([`Layout::Rinscope`], CSV or Parquet with a header; also what MCAP yields): units in
//! the column names (see [`crate::io::imu::units`]). One time column, `t_s`, `t_ms`, `t_us`, `t_ns` or
//! `gps_sow_s` (GPS seconds of week), and either rates
//! `gyro_{x,y,z}_<rad_per_s|deg_per_s|deg_per_h>` + `accel_{x,y,z}_<mps2|g|mg|ug>`, or increments
//! over the previous sample `dtheta_{x,y,z}_<rad|mrad|urad|deg|arcsec>` + `dv_{x,y,z}_<mps>`.
//! Other columns are ignored. Default frame: RFU.
//! ```text
//! # rinscope IMU log (comment lines allowed at the top)
//! t_s,dtheta_x_rad,dtheta_y_rad,dtheta_z_rad,dv_x_mps,dv_y_mps,dv_z_mps
//! 0.000,1.2e-7,-3.0e-8,3.6e-7,1.0e-4,-2.0e-5,0.049033
//! ```
//!
//! **PSINS** ([`Layout::Psins`]): 7 columns `[wm vm t]` = gyro increments x,y,z (rad), velocity
//! increments x,y,z (m/s), time (s); with or without a header. PSINS's `ap2imu`/`avp2imu` document
//! "Outputs: imu = \[wm,vm,t\]" (PSINS toolbox by Gongmin Yan, NWPU, `base/base1/ap2imu.m`);
//! its body frame is right-front-up (its `imurfu` turns other axis orders into RFU). Default frame RFU.
//!
//! **PSINS SIMU file** ([`Layout::PsinsImu`], `psins-imu`): the `.imu` text that PSINS's
//! `imufile.m` writes: `%` comment lines (the first names PSINS and SIMU), three header rows —
//! initial pitch, roll, yaw (deg), velocity E, N, U (m/s); latitude, longitude (deg), height (m),
//! t0 (s), sampling interval (ms), g (m/s²); gyro scale factors (arcsec) and accelerometer ones
//! (µg·s) — then one row of integer counts per sample, with an optional 7th column of time dither
//! (µs). Increments are count × scale; sample k (from 1) is at t0 + k·ts (+ Σ dither·1e-6), so
//! [`ImuReader::start_time`] is t0 + ts. The header: [`ImuReader::psins_header`],
//! [`crate::io::read_psins_header`]; the details: the `psins_imu` module. Found by its first
//! line whatever the extension; other layouts refuse it. Default frame RFU.
//!
//! **KF-GINS** ([`Layout::KfGins`]): text without a header, fields separated by spaces, tabs or
//! commas, 7 (or more; extra columns ignored) columns: GNSS seconds of week (s), X-Y-Z incremental
//! angles (rad), X-Y-Z incremental velocity (m/s) — the "IMU text file format" table in KF-GINS's
//! README §2.2 (i2Nav-WHU/KF-GINS), read by `src/fileio/imufileloader.h` as `time = data[0]`,
//! `dtheta = data[1..4]`, `dvel = data[4..7]`; `fileloader.cc` splits on any of `", \t"`. IMU frame
//! forward-right-down (README §2.1). Default frame FRD. Week rollovers are handled.
//!
//! **Kalibr** ([`Layout::Kalibr`]): CSV `timestamp,omega_x,omega_y,omega_z,alpha_x,alpha_y,alpha_z`
//! with timestamps in ns, omega in rad/s, alpha in m/s² (Kalibr wiki, "Bag format": "The imu0.csv
//! file uses the format below: (timestamps=\[ns\], omega=\[rad/s\], alpha=\[m/s^2\])";
//! `kalibr_bagcreater` skips the first line and takes `row[0]`, `row[1:4]`, `row[4:7]`). The
//! EuRoC/ASL variant's header is a comment, `#timestamp [ns],w_RS_S_x [rad s^-1],...,a_RS_S_z [m s^-2]`;
//! both are read (columns by position). The frame is the IMU's own: give it ([`ImuOptions::frame`]).
//!
//! **NumPy N×7** ([`Layout::Npy7`]): `[t, dtheta_x, dtheta_y, dtheta_z, dv_x, dv_y, dv_z]` in
//! (time unit given), rad, m/s; columns by position in any format. Give the frame.
//!
//! **ROS 2** ([`Layout::Ros2`]): MCAP `sensor_msgs/msg/Imu`, rates; default frame FLU (REP 103).
//!
//! # Time
//! [`ImuSample::t_s`] is seconds since the first sample. Nanosecond stamps are subtracted as
//! integers before becoming f64, so a 1.4e18 ns stamp keeps 1 ns resolution. GPS seconds of week
//! that jump back by more than half a week (302 400 s) are taken as a week rollover (+604 800 s).
//!
//! # Checks while streaming
//! A time stamp before the previous one, or equal to it, is an error naming both. An interval
//! longer than [`ImuOptions::gap_factor`] × the nominal interval (given, or the median of the
//! first eight intervals) is an error ([`GapPolicy::Refuse`]) or an [`ImuEvent::Gap`]
//! ([`GapPolicy::Split`]). NaN and infinite values are errors naming row and column.

pub mod axes;
pub(crate) mod clock;
pub mod guess;
pub(crate) mod layout;
pub mod plausibility;
pub mod series;
pub mod units;

use crate::io::error::{Location, LogError, Result};
use crate::io::formats::psins_imu::PsinsHeader;
use crate::io::formats::table::ColumnReader;
use crate::io::imu::axes::Frame;
use crate::io::imu::clock::{Clock, RawStamp};
pub use crate::io::imu::clock::{GPS_WEEK_S, StartTime, TimeUnit};
use crate::io::imu::layout::{plan_for, read_options};
use crate::io::validity::{Sensor, check_imu_value};
use nalgebra::{Matrix3, Vector3};
use std::collections::VecDeque;
use std::path::{Path, PathBuf};

const LOOKAHEAD: usize = 9;

/// One IMU sample in SI units and the RFU frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImuSample {
    /// Seconds since the stream's first sample.
    pub t_s: f64,
    /// Angular rate (rad/s) or angle increment over the previous sample (rad), RFU.
    pub gyro: Vector3<f64>,
    /// Specific force (m/s²) or velocity increment over the previous sample (m/s), RFU.
    pub accel: Vector3<f64>,
}

/// Whether a log holds increments or rates.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SampleKind {
    /// Angle (rad) and velocity (m/s) increments over the previous sample.
    Increments,
    /// Angular rate (rad/s) and specific force (m/s²).
    Rates,
}

/// A file layout (see the module docs for each).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Layout {
    /// rinscope's own: units in the column names.
    Rinscope,
    /// PSINS `[wm vm t]`.
    Psins,
    /// PSINS SIMU file (`.imu`) as PSINS's `imufile.m` writes it: header and integer counts.
    PsinsImu,
    /// KF-GINS IMU text file `(t_gps_sow, dtheta_xyz, dv_xyz)`.
    KfGins,
    /// Kalibr / EuRoC `imu0.csv`.
    Kalibr,
    /// N×7 `[t, dtheta_xyz, dv_xyz]` as Python tools dump it.
    Npy7 {
        /// Unit of column 0.
        time: TimeUnit,
    },
    /// MCAP with ROS 2 `sensor_msgs/msg/Imu`.
    Ros2,
    /// Any table, its columns described one by one (`[imu.columns]` of a log set).
    Columns(Box<ColumnMap>),
}

/// The columns of a foreign or headerless file, as a log set's `[imu.columns]` describes them:
/// each by header name or 0-based position, with its unit (the suffixes of [`crate::io::imu::units`]:
/// `deg_per_s`, `rad`, `g`, `mps`, ...). Angle and velocity units make increments, rate and
/// acceleration units rates; the two triads must agree.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ColumnMap {
    /// The time column and its unit.
    pub time: (crate::io::formats::table::Col, TimeUnit),
    /// Gyro x, y, z then accelerometer x, y, z: the column and its unit suffix.
    pub sensors: [(crate::io::formats::table::Col, String); 6],
}

/// What to do with a gap in the time stamps.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum GapPolicy {
    /// A gap is an error.
    #[default]
    Refuse,
    /// A gap is returned as [`ImuEvent::Gap`] before the sample after it.
    Split,
}

/// The static-segment plausibility check (see [`crate::io::check_static`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StaticCheck {
    /// Length of the initial static segment examined, s.
    pub duration_s: f64,
    /// Accepted relative deviation of the mean specific force from standard gravity.
    pub gravity_tolerance: f64,
    /// Largest accepted mean angular rate, rad/s (default 5 × Earth rate).
    pub max_gyro_rad_per_s: f64,
}

impl Default for StaticCheck {
    fn default() -> Self {
        Self {
            duration_s: 5.0,
            gravity_tolerance: 0.1,
            max_gyro_rad_per_s: 5.0 * crate::io::imu::plausibility::EARTH_RATE_RAD_PER_S,
        }
    }
}

/// How to read an IMU log.
#[derive(Debug, Clone, PartialEq)]
pub struct ImuOptions {
    /// The file's layout.
    pub layout: Layout,
    /// The file's body frame; `None` takes the layout's documented frame (an error for layouts without one).
    pub frame: Option<Frame>,
    /// MCAP: the topic (default: the only Imu topic).
    pub topic: Option<String>,
    /// Gap handling.
    pub gap_policy: GapPolicy,
    /// An interval longer than this many nominal intervals is a gap (default 3).
    pub gap_factor: f64,
    /// The nominal sampling interval, s; `None` takes a PSINS SIMU file's header interval, or
    /// estimates it from the first intervals.
    pub nominal_dt_s: Option<f64>,
    /// Run the static plausibility check when opening.
    pub static_check: Option<StaticCheck>,
}

impl ImuOptions {
    /// Defaults for a layout: its own frame, gaps refused beyond 3 × nominal, no static check.
    #[must_use]
    pub fn new(layout: Layout) -> Self {
        Self {
            layout,
            frame: None,
            topic: None,
            gap_policy: GapPolicy::Refuse,
            gap_factor: 3.0,
            nominal_dt_s: None,
            static_check: None,
        }
    }
}

/// What the stream yields.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ImuEvent {
    /// A sample.
    Sample(ImuSample),
    /// A gap ([`GapPolicy::Split`]); the sample after it comes next.
    Gap {
        /// Where the sample after the gap is.
        at: Location,
        /// Time of the sample before the gap, s since the first sample.
        t_before_s: f64,
        /// Time of the sample after the gap, s since the first sample.
        t_after_s: f64,
        /// The nominal interval, s.
        nominal_s: f64,
    },
}

struct Pending {
    sample: ImuSample,
    at: Location,
    raw_t: RawStamp,
    /// The six sensor cells as written (file units and axes), for the bounds' messages.
    cells: [f64; 6],
}

/// A stream of IMU events from a file; see the module docs. Iterate it: `Result<ImuEvent>` items,
/// ending after the first error.
pub struct ImuReader {
    path: PathBuf,
    reader: ColumnReader,
    kind: SampleKind,
    c: Matrix3<f64>,
    scale: [f64; 6],
    clock: Clock,
    lookahead: VecDeque<Pending>,
    read_error: Option<LogError>,
    prev: Option<(f64, RawStamp)>,
    nominal_dt_s: Option<f64>,
    /// The median of the first intervals (None: fewer than two samples).
    measured_dt_s: Option<f64>,
    held: Option<ImuSample>,
    done: bool,
    gap_policy: GapPolicy,
    gap_factor: f64,
    time_column: String,
    /// A PSINS SIMU file's header.
    psins: Option<PsinsHeader>,
    /// The frame conversion is the identity (skip the products).
    c_identity: bool,
    /// Formats without exact integers are read in blocks of rows (row-major).
    block: Vec<f64>,
    block_pos: usize,
    /// The data row of `block`'s first row (1-based).
    block_first_row: u64,
}

/// The largest relative difference accepted between a declared sampling rate and the rate the
/// time stamps show (jittery clocks and PSINS's dither stay well inside 2 %; a wrong rate or time
/// unit is off by factors).
pub const RATE_TOLERANCE: f64 = 0.02;

/// Rows read at once from formats that allow it.
const BLOCK_ROWS: usize = 4096;

impl std::fmt::Debug for ImuReader {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ImuReader").field("path", &self.path).field("kind", &self.kind).finish_non_exhaustive()
    }
}

impl ImuReader {
    /// Opens an IMU log (and runs the static check if asked).
    ///
    /// # Errors
    /// Everything [`ColumnReader::open`] reports; a layout whose columns or units do not fit; a
    /// bad or missing frame; a failed static check ([`LogError::Implausible`]); a first-rows error.
    pub fn open(path: impl AsRef<Path>, options: &ImuOptions) -> Result<Self> {
        let path = path.as_ref();
        if let Some(check) = &options.static_check {
            let report = crate::io::imu::plausibility::check_static(path, options, check)?;
            if !report.problems.is_empty() {
                return Err(LogError::Implausible { file: path.to_path_buf(), message: report.problems.join("; ") });
            }
        }
        let plan = plan_for(path, options)?;
        let frame = match (&options.frame, plan.frame) {
            (Some(f), _) => f.clone(),
            (None, Some(name)) => Frame::Named(name.to_owned()),
            (None, None) => {
                return Err(LogError::Layout {
                    file: path.to_path_buf(),
                    problem: format!(
                        "a headerless table (layout {}) says nothing of its axes: give its body frame, `imu.frame` in log.toml or `--imu-frame` (\"rfu\": x right, y forward, z up; \"frd\", \"flu\", ...)",
                        options.layout.name()
                    ),
                });
            }
        };
        let c = frame.to_rfu().map_err(|source| LogError::Frame { file: path.to_path_buf(), source })?;
        let reader = ColumnReader::open(path, &plan.cols, &read_options(options, plan.header))?;
        let time_column = reader.columns().first().cloned().unwrap_or_default();
        let psins = reader.psins_header().cloned();
        let mut this = Self {
            path: path.to_path_buf(),
            reader,
            kind: plan.kind,
            c,
            scale: plan.scale,
            clock: Clock {
                unit: plan.time,
                first_ns: None,
                first: None,
                prev_sow: f64::NEG_INFINITY,
                week_offset_s: 0.0,
            },
            lookahead: VecDeque::with_capacity(LOOKAHEAD),
            c_identity: c == Matrix3::identity(),
            block: Vec::new(),
            block_pos: 0,
            block_first_row: 1,
            read_error: None,
            prev: None,
            nominal_dt_s: options.nominal_dt_s.or(psins.as_ref().map(|h| h.interval_s)),
            measured_dt_s: None,
            psins,
            held: None,
            done: false,
            gap_policy: options.gap_policy,
            gap_factor: options.gap_factor,
            time_column,
        };
        while this.lookahead.len() < LOOKAHEAD {
            match this.read_one() {
                Ok(Some(p)) => this.lookahead.push_back(p),
                Ok(None) => break,
                Err(e) => {
                    this.read_error = Some(e);
                    break;
                }
            }
        }
        // A reader reports its own first error: a file whose first row cannot be read is that
        // error, not an empty log.
        if this.lookahead.is_empty()
            && let Some(e) = this.read_error.take()
        {
            return Err(e);
        }
        let mut dts: Vec<f64> = this
            .lookahead
            .iter()
            .zip(this.lookahead.iter().skip(1))
            .map(|(a, b)| b.sample.t_s - a.sample.t_s)
            .filter(|dt| *dt > 0.0)
            .collect();
        dts.sort_by(f64::total_cmp);
        this.measured_dt_s = dts.get(dts.len() / 2).copied();
        if this.nominal_dt_s.is_none() {
            this.nominal_dt_s = this.measured_dt_s;
        }
        Ok(this)
    }

    #[inline]
    fn read_one(&mut self) -> Result<Option<Pending>> {
        let mut row = [0.0; 7];
        let (exact, at) = if self.reader.reads_in_blocks() {
            if self.block_pos * 7 >= self.block.len() {
                self.block_first_row += (self.block.len() / 7) as u64;
                self.block.clear();
                self.block_pos = 0;
                if self.reader.next_batch(&mut self.block, BLOCK_ROWS)? == 0 {
                    return Ok(None);
                }
            }
            row.copy_from_slice(&self.block[self.block_pos * 7..self.block_pos * 7 + 7]);
            let at = Location { row: self.block_first_row + self.block_pos as u64, line: None };
            self.block_pos += 1;
            (None, at)
        } else {
            if !self.reader.next_row(&mut row)? {
                return Ok(None);
            }
            (self.reader.exact_integer(0), self.reader.location())
        };
        let (t_s, raw_t) = self.clock.convert(row[0], exact);
        let cells = [row[1], row[2], row[3], row[4], row[5], row[6]];
        Ok(Some(Pending { sample: self.sample_of(t_s, &cells), at, raw_t, cells }))
    }

    /// The sample at `t_s` of a row's six sensor `cells` (file units and axes): scaled to SI
    /// units, turned into RFU.
    #[inline]
    fn sample_of(&self, t_s: f64, cells: &[f64]) -> ImuSample {
        let s = &self.scale;
        let mut gyro = Vector3::new(cells[0] * s[0], cells[1] * s[1], cells[2] * s[2]);
        let mut accel = Vector3::new(cells[3] * s[3], cells[4] * s[4], cells[5] * s[5]);
        if !self.c_identity {
            gyro = self.c * gyro;
            accel = self.c * accel;
        }
        ImuSample { t_s, gyro, accel }
    }

    /// Increments or rates.
    #[must_use]
    pub fn kind(&self) -> SampleKind {
        self.kind
    }

    /// The file.
    #[must_use]
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The source columns: time, gyro x/y/z, accel x/y/z.
    #[must_use]
    pub fn columns(&self) -> &[String] {
        self.reader.columns()
    }

    /// `C` with `v_rfu = C · v_file`.
    #[must_use]
    pub fn frame_to_rfu(&self) -> Matrix3<f64> {
        self.c
    }

    /// The nominal sampling interval used for gap detection, s.
    #[must_use]
    pub fn nominal_dt_s(&self) -> Option<f64> {
        self.nominal_dt_s
    }

    /// The median of the first eight sampling intervals, s (what the stamps say, whatever was
    /// declared).
    #[must_use]
    pub fn measured_dt_s(&self) -> Option<f64> {
        self.measured_dt_s
    }

    /// Why `declared_hz` cannot be this file's rate: the median of its first intervals differs by
    /// more than [`RATE_TOLERANCE`] (None: they agree, or too few samples to tell). Every increment
    /// would be integrated, or every rate held, over the wrong interval without a word.
    #[must_use]
    pub fn rate_disagreement(&self, declared_hz: f64) -> Option<String> {
        let measured = self.measured_dt_s?;
        if (measured * declared_hz - 1.0).abs() <= RATE_TOLERANCE {
            return None;
        }
        let unit = self.clock.unit.symbol();
        Some(format!(
            "{} Hz is declared, but the time stamps of {} ({}, read in {unit}) step by {} s = {} Hz (the median of the first intervals): correct the rate (rate_hz, --rate-hz) or the time column's unit",
            crate::io::error::short_number(declared_hz),
            self.path.display(),
            self.time_column,
            crate::io::error::fixed_number(measured, 6),
            crate::io::error::fixed_number(1.0 / measured, 4)
        ))
    }

    /// The log's length, s: the rows the file holds ([`ColumnReader::rows_hint`]: exact for .npy,
    /// Parquet and a summarised MCAP, estimated for text) times the sampling interval; None where
    /// the file does not tell (an MCAP without a summary). What a recording sizes its plots'
    /// buckets by before the log is read.
    #[must_use]
    pub fn duration_hint_s(&self) -> Option<f64> {
        let dt = self.nominal_dt_s.or(self.measured_dt_s)?;
        self.reader.rows_hint().map(|rows| rows as f64 * dt)
    }

    /// The first time stamp as written in the file (known once a row has been read).
    #[must_use]
    pub fn start_time(&self) -> Option<StartTime> {
        self.clock.start()
    }

    /// The header of a PSINS SIMU file ([`Layout::PsinsImu`]); `None` for other layouts.
    #[must_use]
    pub fn psins_header(&self) -> Option<&PsinsHeader> {
        self.psins.as_ref()
    }

    #[inline]
    fn step(&mut self) -> Result<Option<ImuEvent>> {
        if let Some(s) = self.held.take() {
            return Ok(Some(ImuEvent::Sample(s)));
        }
        let p = match self.lookahead.pop_front() {
            Some(p) => p,
            None => match self.read_error.take() {
                Some(e) => return Err(e),
                None => match self.read_one()? {
                    Some(p) => p,
                    None => return Ok(None),
                },
            },
        };
        let t = p.sample.t_s;
        crate::io::validity::check_span(&self.path, p.at, &self.time_column, p.raw_t.value, t)?;
        // The interval the sample covers (the first: the nominal one), for the increments' bounds.
        let interval = match self.prev {
            Some((t_prev, _)) => t - t_prev,
            None => self.nominal_dt_s.unwrap_or(1.0),
        };
        if interval > 0.0 {
            self.check_values(&p, interval)?;
        }
        if let Some((t_prev, raw_prev)) = self.prev.take() {
            let dt = t - t_prev;
            if dt < 0.0 {
                return Err(LogError::NonMonotonicTime {
                    file: self.path.clone(),
                    at: p.at,
                    column: self.time_column.clone(),
                    t_prev: raw_prev.to_string(),
                    t: p.raw_t.to_string(),
                });
            }
            if dt == 0.0 {
                return Err(LogError::DuplicateTime {
                    file: self.path.clone(),
                    at: p.at,
                    column: self.time_column.clone(),
                    t: p.raw_t.to_string(),
                });
            }
            if let Some(nominal) = self.nominal_dt_s.filter(|n| dt > self.gap_factor * n) {
                let at = p.at;
                self.prev = Some((t, p.raw_t));
                match self.gap_policy {
                    GapPolicy::Refuse => {
                        return Err(LogError::Gap {
                            file: self.path.clone(),
                            at,
                            t_before_s: t_prev,
                            t_after_s: t,
                            gap_s: dt,
                            nominal_s: nominal,
                            multiple: dt / nominal,
                        });
                    }
                    GapPolicy::Split => {
                        self.held = Some(p.sample);
                        return Ok(Some(ImuEvent::Gap { at, t_before_s: t_prev, t_after_s: t, nominal_s: nominal }));
                    }
                }
            }
        }
        self.prev = Some((t, p.raw_t));
        Ok(Some(ImuEvent::Sample(p.sample)))
    }
}

impl ImuReader {
    /// The numeric-validity rule ([`crate::io::validity`]) on one sample's six values.
    #[inline]
    fn check_values(&self, p: &Pending, interval_s: f64) -> Result<()> {
        let increments = (self.kind == SampleKind::Increments).then_some(interval_s);
        for (k, cell) in p.cells.iter().enumerate() {
            let si = cell * self.scale[k];
            // The hot path: one comparison per value; the message only when it fails.
            if beyond_bounds(k, si, increments.unwrap_or(1.0)) {
                let column = self.reader.columns().get(k + 1).map_or("", String::as_str);
                let sensor = if k < 3 { Sensor::Gyro } else { Sensor::Accel };
                check_imu_value(&self.path, p.at, column, *cell, si, sensor, increments)?;
            }
        }
        Ok(())
    }
}

/// Whether sensor value `k` (0-2 gyros, 3-5 accelerometers), `si` in SI units, is NaN or beyond
/// what any instrument measures ([`crate::io::validity`]) over `per` seconds (an increment's
/// interval; 1 for a rate).
#[inline]
fn beyond_bounds(k: usize, si: f64, per: f64) -> bool {
    use crate::io::validity::{MAX_RATE_RAD_PER_S, MAX_SPECIFIC_FORCE_MPS2};
    let bound = if k < 3 { MAX_RATE_RAD_PER_S } else { MAX_SPECIFIC_FORCE_MPS2 };
    si.is_nan() || si.abs() > bound * per
}

impl ImuReader {
    /// [`Self::step`] over the current block's rows while every check passes — a block format's
    /// samples, none at a gap or out of bounds: the same conversion of the stamp and the values and
    /// the same checks, as comparisons, without a row's error context (its location, its cells)
    /// built and moved per sample (they were most of the reading thread's time). The first row a
    /// check refuses is left in the block for [`Self::step`], which reports it, or returns its gap,
    /// as it always does. For a reader that [`ColumnReader::reads_in_blocks`]; appends at most
    /// `max` samples to `out`; returns how many.
    fn clean_block_rows(&mut self, out: &mut Vec<ImuSample>, max: usize) -> usize {
        // After the first row (the clock's origin and `prev` set), nothing held or looked ahead,
        // and a stamp that converts without state (not GPS seconds of week, not exact integers).
        let (Some(first), Some((mut t_prev, mut raw_prev))) = (self.clock.stateless_origin(), self.prev) else {
            return 0;
        };
        if self.held.is_some() || !self.lookahead.is_empty() || self.read_error.is_some() {
            return 0;
        }
        let gap_s = self.nominal_dt_s.map_or(f64::INFINITY, |n| self.gap_factor * n);
        let increments = self.kind == SampleKind::Increments;
        let rows = self.block.len() / 7;
        let mut n = 0;
        while n < max && self.block_pos < rows {
            let row = &self.block[self.block_pos * 7..self.block_pos * 7 + 7];
            let t = self.clock.since(first, row[0]);
            let dt = t - t_prev;
            // `dt > 0` also refuses a NaN stamp; `step` says which check failed.
            if !(crate::io::validity::within_span(t) && dt > 0.0 && dt <= gap_s) {
                break;
            }
            let per = if increments { dt } else { 1.0 };
            let cells = &row[1..];
            if (0..6).any(|k| beyond_bounds(k, cells[k] * self.scale[k], per)) {
                break;
            }
            out.push(self.sample_of(t, cells));
            (t_prev, raw_prev.value) = (t, row[0]);
            self.block_pos += 1;
            n += 1;
        }
        self.prev = Some((t_prev, raw_prev));
        n
    }
}

/// What [`ImuReader::next_samples`] stopped at.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BlockEnd {
    /// `max` samples were read; there may be more.
    Full,
    /// A gap ([`GapPolicy::Split`]) follows the samples read; the sample after it comes next.
    Gap(ImuEvent),
    /// The end of the file.
    End,
}

impl ImuReader {
    /// Appends up to `max` samples to `out`, stopping early at a gap or at the end: the streaming
    /// form of the iterator for callers that take samples in blocks.
    ///
    /// # Errors
    /// As the iterator's items; the samples before the error are in `out`.
    pub fn next_samples(&mut self, out: &mut Vec<ImuSample>, max: usize) -> Result<BlockEnd> {
        if self.done {
            return Ok(BlockEnd::End);
        }
        // Text formats read row by row: every row through `step`.
        let blocks = self.reader.reads_in_blocks();
        let mut taken = 0;
        while taken < max {
            if blocks {
                taken += self.clean_block_rows(out, max - taken);
            }
            if taken == max {
                break;
            }
            taken += 1;
            match self.step() {
                Ok(Some(ImuEvent::Sample(s))) => out.push(s),
                Ok(Some(gap)) => return Ok(BlockEnd::Gap(gap)),
                Ok(None) => {
                    self.done = true;
                    return Ok(BlockEnd::End);
                }
                Err(e) => {
                    self.done = true;
                    return Err(e);
                }
            }
        }
        Ok(BlockEnd::Full)
    }
}

impl Iterator for ImuReader {
    type Item = Result<ImuEvent>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.done {
            return None;
        }
        let item = self.step().transpose();
        if !matches!(item, Some(Ok(_))) {
            self.done = true;
        }
        item
    }
}
