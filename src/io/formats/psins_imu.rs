//! PSINS SIMU text files (`.imu`, written by PSINS's `imufile.m`): the header, and a streaming
//! source of the increments `[wm vm t]` that `imufile.m` reads from them.
//!
//! # The format
//! PSINS toolbox `imufile.m` (Gongmin Yan, NWPU) writes `%` comment lines, the first of them
//! `% PSINS-format SIMU log file. (DO NOT MODIFY!)`, a blank line, then
//! ```text
//! pitch0 roll0 yaw0 VE0 VN0 VU0 [0]        deg deg deg m/s m/s m/s      '%f %f %f %f %f %f'
//! lat0 lon0 h0 t0 ts g [0]                 deg deg m s ms m/s²          '%.8f %.8f %.3f %.8f %.8f %f'
//! gf_x gf_y gf_z af_x af_y af_z [0]        arcsec and µg·s per count    '%f %f %f %.3f %.3f %.3f'
//!
//! g_x g_y g_z a_x a_y a_z [dt]             integer counts, one row per sample ('%d')
//! ```
//! The bracketed 7th column is there when the sampling times dither: every row then has 7 numbers,
//! the header rows ending in `0`. The read branch checks that the first line names "PSINS" and
//! "SIMU", loads the numbers as one matrix (MATLAB's `load`: `%` starts a comment, blank lines are
//! skipped, every row has as many numbers as the first) and returns, for data row k = 1..N,
//! * the gyro increment `g_* × gf_* × 1″` (rad; PSINS's `glv.sec` = π/180/60/60),
//! * the velocity increment `a_* × af_* × 1e-6·g` (m/s, with the g of header row 2),
//! * the time `t0 + k·ts + Σ_{j≤k} dt_j·1e-6` (s), or `t0 + k·ts` without the 7th column: the
//!   dither is in microseconds, although the file's comment says milliseconds (the code scales
//!   its cumulative sum by 1e-6, and the writer stores `diff(fix(t·1e6))`).
//!
//! The writer stores `diff(fix(cumsum(x / scale)))`, so a count carries the remainders of the
//! ones before it: the sum of the first k increments is within one count of the true sum. The
//! axes are x right, y forward, z up (rinscope's RFU). The yaw turns counter-clockwise from North
//! (about Up); [`PsinsHeader::heading_deg`] gives the clockwise heading.
//!
//! As a [`Source`], a file yields seven columns in `imufile.m`'s order: `dtheta_{x,y,z}_rad`,
//! `dv_{x,y,z}_mps` and `t_s` (absolute, s). The first line must be a `%` comment naming PSINS
//! and SIMU: `imufile.m` checks the names, and MATLAB's `load` refuses any other text line.

use crate::io::error::{Location, LogError, Result, cell_text};
use crate::io::formats::table::Source;
use crate::io::formats::text::{Delimiter, Line, LineReader, field, is_blank, split};
use std::path::{Path, PathBuf};

/// The columns of the stream: `imufile.m`'s `[wm vm t]` in SI units.
const COLUMNS: [&str; 7] = ["dtheta_x_rad", "dtheta_y_rad", "dtheta_z_rad", "dv_x_mps", "dv_y_mps", "dv_z_mps", "t_s"];

/// The header fields, named as the file's own comment lines name them.
const HEADER_FIELDS: [[&str; 6]; 3] = [
    ["pitch0(deg)", "roll0(deg)", "yaw0(deg)", "VE0(m/s)", "VN0(m/s)", "VU0(m/s)"],
    ["latitude0(deg)", "longitude0(deg)", "height0(m)", "t0(s)", "sampling-interval(ms)", "g(m/s^2)"],
    ["gf_x", "gf_y", "gf_z", "af_x", "af_y", "af_z"],
];

/// The data fields, named as the file's comment names them.
const DATA_FIELDS: [&str; 7] = ["g_x", "g_y", "g_z", "a_x", "a_y", "a_z", "dt"];

/// One arcsecond in radians, computed as PSINS's `glvs.m` does: `glv.deg = pi/180`,
/// `glv.min = glv.deg/60`, `glv.sec = glv.min/60`.
const ARCSEC_RAD: f64 = crate::math::units::RAD_PER_ARCSEC;

/// The g accepted in header row 2, m/s²: surface gravity is 9.78 (equator) to 9.83 (poles);
/// `imufile.m` writes PSINS's `glv.g0`, 9.7803267714, as `9.780327`.
const G_MIN_MPS2: f64 = 9.7;
const G_MAX_MPS2: f64 = 9.9;

/// The first line of every file `imufile.m` writes.
pub(crate) const FIRST_LINE: &str = "% PSINS-format SIMU log file. (DO NOT MODIFY!)";

/// The header of a PSINS SIMU file (see the module docs): initial attitude, velocity and
/// position "(maybe inaccurate)", the time base and the count scale factors, as written.
#[derive(Debug, Clone, PartialEq)]
pub struct PsinsHeader {
    /// Initial pitch, deg.
    pub pitch_deg: f64,
    /// Initial roll, deg.
    pub roll_deg: f64,
    /// Initial yaw, deg, as written: PSINS's yaw turns counter-clockwise from North, about Up
    /// ([`Self::heading_deg`] is the clockwise heading).
    pub yaw_deg: f64,
    /// Initial velocity East, North, Up, m/s.
    pub velocity_enu_mps: [f64; 3],
    /// Initial latitude, deg.
    pub latitude_deg: f64,
    /// Initial longitude, deg.
    pub longitude_deg: f64,
    /// Initial height, m.
    pub height_m: f64,
    /// t0, s: data row k is at `t0 + k·interval` (plus its dither): the first sample at t0 + interval.
    pub t0_s: f64,
    /// Sampling interval, s (written in ms).
    pub interval_s: f64,
    /// The g that scales the accelerometer counts, m/s².
    pub g_mps2: f64,
    /// Gyro scale factors x, y, z: arcsec per count.
    pub gyro_scale_arcsec: [f64; 3],
    /// Accelerometer scale factors x, y, z: µg·s per count (1 µg·s = 1e-6 × g m/s).
    pub accel_scale_ug_s: [f64; 3],
    /// The data rows carry a 7th column, the sampling-time dither (µs).
    pub has_dither: bool,
}

impl PsinsHeader {
    /// The initial heading, clockwise from North, deg in [0, 360): `-yaw_deg`, wrapped.
    #[must_use]
    pub fn heading_deg(&self) -> f64 {
        let heading = (-self.yaw_deg).rem_euclid(360.0);
        // A tiny negative yaw's remainder rounds to 360; `+ 0.0` turns -0 into 0.
        if heading >= 360.0 { 0.0 } else { heading + 0.0 }
    }

    /// One count of each data column in SI units: gyro x, y, z (rad), accelerometer x, y, z (m/s),
    /// computed as `imufile.m` does (`gf·glv.sec`, `af·(1e-6·g)`).
    #[must_use]
    pub fn count_scales(&self) -> [f64; 6] {
        let (gf, af) = (self.gyro_scale_arcsec, self.accel_scale_ug_s);
        let ug = 1e-6 * self.g_mps2;
        [gf[0] * ARCSEC_RAD, gf[1] * ARCSEC_RAD, gf[2] * ARCSEC_RAD, af[0] * ug, af[1] * ug, af[2] * ug]
    }
}

/// Whether a first line is `imufile.m`'s: a `%` comment naming PSINS and SIMU (case-sensitive, as
/// `strfind`).
pub(crate) fn names_psins_simu(first_line: &[u8]) -> bool {
    let contains = |needle: &[u8]| first_line.windows(needle.len()).any(|w| w == needle);
    first_line.trim_ascii_start().starts_with(b"%") && contains(b"PSINS") && contains(b"SIMU")
}

/// The error for a file asked to be read as PSINS SIMU whose first line is not `imufile.m`'s.
pub(crate) fn not_psins(path: &Path, first_line: Option<&[u8]>) -> LogError {
    let found = match first_line {
        None => "the file is empty".to_owned(),
        Some(line) => format!("line 1 is {:?}", cell_text(line)),
    };
    LogError::Layout {
        file: path.to_path_buf(),
        problem: format!(
            "not a PSINS SIMU file: {found}; layout psins-imu reads what PSINS's imufile.m writes, whose line 1 is a % comment naming PSINS and SIMU ({FIRST_LINE:?})"
        ),
    }
}

/// The first line of a text file (`None` if empty), for messages.
pub(crate) fn first_line(path: &Path) -> Result<Option<Vec<u8>>> {
    Ok(LineReader::open(path)?.next_line(Vec::new())?.map(|l| l.bytes))
}

/// The next line holding numbers: `%` comments cut off, blank lines skipped.
fn next_numbers(lines: &mut LineReader, buffer: Vec<u8>) -> Result<Option<Line>> {
    let mut buffer = buffer;
    loop {
        let Some(mut line) = lines.next_line(buffer)? else {
            return Ok(None);
        };
        if let Some(comment) = line.bytes.iter().position(|&b| b == b'%') {
            line.bytes.truncate(comment);
        }
        if !is_blank(&line.bytes) {
            return Ok(Some(line));
        }
        buffer = line.bytes;
    }
}

/// Reads the header of a PSINS SIMU file without streaming its data.
///
/// ```no_run
/// let header = rinscope::io::read_psins_header("trj.imu")?;
/// println!("{} Hz from t0 = {} s, heading {:.2}°", 1.0 / header.interval_s, header.t0_s, header.heading_deg());
/// # Ok::<(), rinscope::io::LogError>(())
/// ```
///
/// # Errors
/// An unreadable file; a first line that is not a `%` comment naming PSINS and SIMU; a header
/// row missing, with other than 6 numbers (7 with the dither column) or with a number that is
/// not one, NaN or infinite; a sampling interval ≤ 0; a g outside 9.7..9.9 m/s²; a latitude
/// beyond ±90°; a zero scale factor. Each error names the line, the field and the value.
pub fn read_psins_header(path: impl AsRef<Path>) -> Result<PsinsHeader> {
    let path = path.as_ref();
    read_header(path, &mut LineReader::open(path)?)
}

fn read_header(path: &Path, lines: &mut LineReader) -> Result<PsinsHeader> {
    let first = lines.next_line(Vec::new())?;
    let first = first.as_ref().map(|l| l.bytes.as_slice());
    if !first.is_some_and(names_psins_simu) {
        return Err(not_psins(path, first));
    }
    let mut rows = [[0.0; 6]; 3];
    let mut width = 0;
    let mut spans = Vec::new();
    for (r, values) in rows.iter_mut().enumerate() {
        let Some(line) = next_numbers(lines, Vec::new())? else {
            return Err(LogError::corrupt(
                path,
                format!(
                    "line {}: the file ends after {r} of the 3 PSINS header rows; imufile.m writes [pitch0 roll0 yaw0 VE0 VN0 VU0], [lat0 lon0 h0 t0 ts(ms) g] and [gf_x gf_y gf_z af_x af_y af_z] before the counts",
                    lines.line_number()
                ),
            ));
        };
        let at = Location { row: 0, line: Some(line.number) };
        split(&line.bytes, Delimiter::Whitespace, &mut spans);
        let found = spans.len();
        if r == 0 && (found == 6 || found == 7) {
            width = found;
        } else if r == 0 || found != width {
            return Err(LogError::FieldCount {
                file: path.to_path_buf(),
                at,
                expected: if r == 0 { 6 } else { width },
                found,
                reference: if r == 0 {
                    "PSINS SIMU header (7 with the dither column)"
                } else {
                    "first PSINS header row"
                },
                truncated_last_line: !line.terminated && found < width.max(6),
            });
        }
        for (k, &span) in spans.iter().enumerate() {
            let text = field(&line.bytes, span);
            let name = HEADER_FIELDS[r].get(k).copied().unwrap_or("the dither column's 0");
            let column = || format!("{name} (header row {}, field {})", r + 1, k + 1);
            let value = std::str::from_utf8(text).ok().and_then(|s| s.parse::<f64>().ok());
            let Some(value) = value else {
                return Err(LogError::NonNumeric {
                    file: path.to_path_buf(),
                    at,
                    column: column(),
                    value: cell_text(text),
                });
            };
            if !value.is_finite() {
                return Err(LogError::NonFinite {
                    file: path.to_path_buf(),
                    at,
                    column: column(),
                    value: cell_text(text),
                });
            }
            if let Some(problem) = header_problem(r, k, value) {
                return Err(LogError::BadValue {
                    file: path.to_path_buf(),
                    at,
                    column: column(),
                    value: cell_text(text),
                    problem,
                });
            }
            if let Some(v) = values.get_mut(k) {
                *v = value;
            }
        }
    }
    let [att_vel, pos_time, scales] = rows;
    Ok(PsinsHeader {
        pitch_deg: att_vel[0],
        roll_deg: att_vel[1],
        yaw_deg: att_vel[2],
        velocity_enu_mps: [att_vel[3], att_vel[4], att_vel[5]],
        latitude_deg: pos_time[0],
        longitude_deg: pos_time[1],
        height_m: pos_time[2],
        t0_s: pos_time[3],
        interval_s: pos_time[4] / 1000.0,
        g_mps2: pos_time[5],
        gyro_scale_arcsec: [scales[0], scales[1], scales[2]],
        accel_scale_ug_s: [scales[3], scales[4], scales[5]],
        has_dither: width == 7,
    })
}

/// Why header row `r`'s field `k` cannot be `value` (a finite number), if it cannot.
///
/// Every field passes the one number rule ([`crate::io::validity::check_number`]) with its
/// physical range: an attitude, a velocity, a position, a time base and scale factors that a
/// header can hold (`pitch = 1e300` was read, and printed back with 300 digits).
fn header_problem(r: usize, k: usize, value: f64) -> Option<String> {
    use crate::io::validity::{self as v, Range};
    /// A sampling interval, ms: 10 µs (100 kHz) to 1 s (1 Hz), the IMU rates a manifest accepts.
    const INTERVAL_MS: Range = Range::closed(0.01, 1000.0, "ms", "a sampling interval");
    /// t0, s: a time on the file's clock.
    const T0_S: Range = v::CLOCK_S;
    /// A gyro count, arcsec: a nonzero scale up to 1e6″ (278° per count; imufile.m's are ~1e-3″).
    const GYRO_SCALE: Range = Range::symmetric(1e6, "arcsec", "a gyro scale factor");
    /// An accelerometer count, µg·s: a nonzero scale up to 1e6 µg·s (1 g·s per count).
    const ACCEL_SCALE: Range = Range::symmetric(1e6, "µg·s", "an accelerometer scale factor");
    let range = match (r, k) {
        (0, 0) => Some(v::PITCH_DEG),
        (0, 1) => Some(v::ROLL_DEG),
        (0, 2) => Some(v::HEADING_DEG),
        (0, 3..6) => Some(v::VELOCITY_MPS),
        (1, 0) => Some(v::LATITUDE_DEG),
        (1, 1) => Some(v::LONGITUDE_DEG),
        (1, 2) => Some(v::HEIGHT_M),
        (1, 3) => Some(T0_S),
        (1, 4) => Some(INTERVAL_MS),
        (2, 0..3) => Some(GYRO_SCALE),
        (2, 3..6) => Some(ACCEL_SCALE),
        _ => None,
    };
    if let Some(range) = range
        && let Err(e) = v::check_number(value, &range)
    {
        return Some(e);
    }
    match (r, k) {
        (1, 5) if !(G_MIN_MPS2..=G_MAX_MPS2).contains(&value) => Some(format!(
            "is not the g that scales the accelerometer counts: it must be within {G_MIN_MPS2}..{G_MAX_MPS2} m/s² (imufile.m writes PSINS's glv.g0, 9.780327)"
        )),
        (2, 0..6) if value == 0.0 => Some("is a zero scale factor: every count of its column would read as 0".into()),
        _ => None,
    }
}

/// An integer count as `imufile.m` writes it (`%d`): the fast path of [`PsinsSource::count`].
fn parse_integer(text: &[u8]) -> Option<i64> {
    let (negative, digits) = match text.split_first() {
        Some((b'-', rest)) => (true, rest),
        Some((b'+', rest)) => (false, rest),
        _ => (false, text),
    };
    if digits.is_empty() || digits.len() > 18 {
        return None;
    }
    let mut value: i64 = 0;
    for &b in digits {
        if !b.is_ascii_digit() {
            return None;
        }
        value = value * 10 + i64::from(b - b'0');
    }
    Some(if negative { -value } else { value })
}

/// The largest integer an f64 holds exactly (2^53): counts beyond it are not whole numbers.
const MAX_EXACT: f64 = 9_007_199_254_740_992.0;

/// A PSINS SIMU file as a [`Source`] of `imufile.m`'s seven columns (see the module docs).
pub(crate) struct PsinsSource {
    path: PathBuf,
    lines: LineReader,
    header: PsinsHeader,
    /// SI value of one count, per data column.
    scales: [f64; 6],
    /// Numbers per row: 6, or 7 with the dither column.
    width: usize,
    names: Vec<String>,
    selected: Vec<usize>,
    spans: Vec<(usize, usize)>,
    buffer: Vec<u8>,
    row: u64,
    line: u64,
    /// Σ dt so far, µs.
    dither_us: i64,
}

impl PsinsSource {
    pub(crate) fn open(path: &Path) -> Result<Self> {
        let mut lines = LineReader::open(path)?;
        let header = read_header(path, &mut lines)?;
        let line = lines.line_number();
        Ok(Self {
            path: path.to_path_buf(),
            lines,
            scales: header.count_scales(),
            width: if header.has_dither { 7 } else { 6 },
            header,
            names: COLUMNS.iter().map(|&c| c.to_owned()).collect(),
            selected: Vec::new(),
            spans: Vec::new(),
            buffer: Vec::new(),
            row: 0,
            line,
            dither_us: 0,
        })
    }

    /// The count in field `k` of `bytes`: an integer (`%d`); an integral number such as `12.0` or
    /// `1e3` is taken as MATLAB's `load` would.
    fn count(&self, bytes: &[u8], k: usize) -> Result<f64> {
        let text = field(bytes, self.spans.get(k).copied().unwrap_or((0, 0)));
        if let Some(count) = parse_integer(text) {
            return Ok(count as f64);
        }
        let column = format!("{} (field {})", DATA_FIELDS.get(k).copied().unwrap_or("?"), k + 1);
        let (file, at, value) = (self.path.clone(), self.location(), cell_text(text));
        match std::str::from_utf8(text).ok().and_then(|s| s.parse::<f64>().ok()) {
            None => Err(LogError::NonNumeric { file, at, column, value }),
            Some(v) if !v.is_finite() => Err(LogError::NonFinite { file, at, column, value }),
            Some(v) if v.fract() != 0.0 || v.abs() > MAX_EXACT => Err(LogError::BadValue {
                file,
                at,
                column,
                value,
                problem: "is not an integer: a PSINS SIMU data row holds whole counts (imufile.m writes them with %d)"
                    .into(),
            }),
            Some(v) => Ok(v),
        }
    }
}

impl Source for PsinsSource {
    fn all_columns(&self) -> &[String] {
        &self.names
    }

    fn select(&mut self, indices: &[usize]) -> Result<()> {
        self.selected = indices.to_vec();
        Ok(())
    }

    fn next_row(&mut self, out: &mut [f64], exact: &mut [Option<i64>]) -> Result<bool> {
        let Some(line) = next_numbers(&mut self.lines, std::mem::take(&mut self.buffer))? else {
            return Ok(false);
        };
        self.row += 1;
        if self.row == 1 {
            self.lines.mark_first_row();
        }
        self.line = line.number;
        split(&line.bytes, Delimiter::Whitespace, &mut self.spans);
        let found = self.spans.len();
        if found != self.width {
            return Err(LogError::FieldCount {
                file: self.path.clone(),
                at: self.location(),
                expected: self.width,
                found,
                reference: "first PSINS header row",
                truncated_last_line: !line.terminated && found < self.width,
            });
        }
        if !line.terminated {
            return Err(LogError::TruncatedLine { file: self.path.clone(), at: self.location() });
        }
        let mut values = [0.0; 7];
        for k in 0..6 {
            values[k] = self.count(&line.bytes, k)? * self.scales[k];
        }
        if self.width == 7 {
            // Integral and within ±2^53 (checked by `count`): exact as i64.
            let dt_us = self.count(&line.bytes, 6)? as i64;
            self.dither_us = self.dither_us.checked_add(dt_us).ok_or_else(|| LogError::BadValue {
                file: self.path.clone(),
                at: self.location(),
                column: "dt (field 7)".into(),
                value: dt_us.to_string(),
                problem: "makes the cumulative dither overflow".into(),
            })?;
        }
        // imufile.m: t0 + (1:N)'*ts + cumsum(dt)*1e-6, in this order.
        let h = &self.header;
        values[6] = h.t0_s + self.row as f64 * h.interval_s + self.dither_us as f64 * 1e-6;
        for (k, &col) in self.selected.iter().enumerate() {
            if let (Some(o), Some(e)) = (out.get_mut(k), exact.get_mut(k)) {
                *o = values.get(col).copied().unwrap_or(f64::NAN);
                *e = None;
            }
        }
        self.buffer = line.bytes;
        Ok(true)
    }

    fn location(&self) -> Location {
        Location { row: self.row, line: Some(self.line) }
    }

    fn rows_hint(&self) -> Option<u64> {
        self.lines.rows_estimate(self.row)
    }

    fn selected_width(&self) -> usize {
        self.selected.len()
    }

    fn psins_header(&self) -> Option<&PsinsHeader> {
        Some(&self.header)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_lines() {
        assert!(names_psins_simu(FIRST_LINE.as_bytes()));
        // imufile.m's check is strfind(str,'PSINS') && strfind(str,'SIMU'): any % comment naming both.
        assert!(names_psins_simu(b"  %SIMU data, PSINS"));
        assert!(!names_psins_simu(b"% psins-format simu log file"));
        assert!(!names_psins_simu(b"# PSINS-format SIMU log file"));
        assert!(!names_psins_simu(b"% PSINS [wm vm t]"));
    }

    #[test]
    fn integers() {
        assert_eq!(parse_integer(b"-0"), Some(0));
        assert_eq!(parse_integer(b"+17"), Some(17));
        assert_eq!(parse_integer(b"-123456789012345678"), Some(-123_456_789_012_345_678));
        assert_eq!(parse_integer(b"1234567890123456789"), None);
        assert_eq!(parse_integer(b"1.0"), None);
        assert_eq!(parse_integer(b"-"), None);
        assert_eq!(parse_integer(b""), None);
    }

    #[test]
    fn heading_is_clockwise_in_0_360() {
        let mut h = PsinsHeader {
            pitch_deg: 0.0,
            roll_deg: 0.0,
            yaw_deg: 0.0,
            velocity_enu_mps: [0.0; 3],
            latitude_deg: 0.0,
            longitude_deg: 0.0,
            height_m: 0.0,
            t0_s: 0.0,
            interval_s: 0.01,
            g_mps2: 9.8,
            gyro_scale_arcsec: [1.0; 3],
            accel_scale_ug_s: [1.0; 3],
            has_dither: false,
        };
        // yaw counter-clockwise from North: 90° is West (heading 270°), -90° is East (90°).
        for (yaw, heading) in [
            (0.0, 0.0),
            (90.0, 270.0),
            (-90.0, 90.0),
            (180.0, 180.0),
            (-180.0, 180.0),
            (1e-20, 0.0),
            (360.0, 0.0),
            (-450.0, 90.0),
        ] {
            h.yaw_deg = yaw;
            assert_eq!(h.heading_deg().to_bits(), f64::to_bits(heading), "yaw {yaw}");
        }
    }
}
