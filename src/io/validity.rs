//! One numeric-validity rule for every value that enters the navigation: finite, and inside what a
//! real instrument can give. A value beyond these bounds is a damaged file (a flipped byte, a cut
//! field, a column of something else) or a unit the file does not state — never data: the readers
//! refuse it naming the file, the row, the column and the value, before it can turn an attitude
//! into NaN.
//!
//! The bounds are chosen so that no real instrument reaches them, with a wide margin:
//!
//! | quantity | bound | the widest real range |
//! |---|---|---|
//! | angular rate | 100 rev/s = 628.3 rad/s | MEMS gyros for spinning projectiles ±20 000 °/s (56 rev/s); navigation gyros ±500–1000 °/s |
//! | specific force | 1000 g = 9806.65 m/s² | gun-hardened IMUs ±100 g (they survive 20 000 g of shock but do not measure it) |
//! | an increment | the bound above × its interval | — |
//! | an encoder or reference angle | 1e8 rad (16 million turns) | beyond it an f64 no longer resolves 0.01″ |
//! | a time stamp, from the log's first | 1e9 s (32 years) | — |

use crate::io::error::{Location, LogError, fixed_number, short_number};
use std::path::Path;

/// The fastest rotation any gyro measures: 100 revolutions per second, rad/s.
pub const MAX_RATE_RAD_PER_S: f64 = 100.0 * std::f64::consts::TAU;

/// The largest specific force any IMU's accelerometers measure: 1000 g, m/s².
pub const MAX_SPECIFIC_FORCE_MPS2: f64 = 1000.0 * crate::io::imu::units::STANDARD_GRAVITY_MPS2;

/// The largest angle an encoder or reference file may hold, rad: beyond 1e8 rad an f64 resolves
/// no better than 1.5e-8 rad (0.003″), and no table turns 16 million times in one log.
pub const MAX_ANGLE_RAD: f64 = 1e8;

/// The longest a log may last from its first stamp, s (32 years): a stamp beyond it is not on the
/// same clock.
pub const MAX_LOG_SPAN_S: f64 = 1e9;

/// What an IMU column measures, for its bound.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Sensor {
    /// A gyro (rate or angle increment).
    Gyro,
    /// An accelerometer (specific force or velocity increment).
    Accel,
}

/// Checks one IMU value `si` (SI units, rate or increment; `interval_s`: the interval an increment
/// covers, None for a rate) read as `cell` from `column` at `at`.
pub(crate) fn check_imu_value(
    file: &Path,
    at: Location,
    column: &str,
    cell: f64,
    si: f64,
    sensor: Sensor,
    interval_s: Option<f64>,
) -> Result<(), LogError> {
    let (rate_bound, unit, what) = match sensor {
        Sensor::Gyro => (MAX_RATE_RAD_PER_S, "rad", "gyro"),
        Sensor::Accel => (MAX_SPECIFIC_FORCE_MPS2, "m/s", "accelerometer"),
    };
    let bound = rate_bound * interval_s.unwrap_or(1.0);
    if si.abs() <= bound {
        return Ok(());
    }
    let limit = match sensor {
        Sensor::Gyro => "100 rev/s = 628.3 rad/s",
        Sensor::Accel => "1000 g = 9806.65 m/s²",
    };
    let (value, bound_text) = match interval_s {
        Some(dt) => (
            format!("{} {unit} in {} s", short_number(si), fixed_number(dt, 6)),
            format!("{limit}: {} {unit} in {} s", fixed_number(bound, 4), fixed_number(dt, 6)),
        ),
        None => (
            format!("{} {}", short_number(si), if sensor == Sensor::Gyro { "rad/s" } else { "m/s²" }),
            limit.to_owned(),
        ),
    };
    Err(bad_value(
        file,
        at,
        column,
        cell,
        format!(
            "({value}) is beyond what any {what} measures (at most {bound_text}): a damaged file, or a unit other than the column's"
        ),
    ))
}

/// The one refusal of the rule: `cell` as read from `column` at `at` of `file`, in short form, and why.
fn bad_value(file: &Path, at: Location, column: &str, cell: f64, problem: String) -> LogError {
    LogError::BadValue { file: file.to_path_buf(), at, column: column.to_owned(), value: short_number(cell), problem }
}

/// Checks an encoder or reference angle `si` (rad) read as `cell` from `column` at `at`.
///
/// # Errors
/// [`LogError::BadValue`] naming the value and the bound.
pub fn check_angle(file: &Path, at: Location, column: &str, cell: f64, si: f64) -> Result<(), LogError> {
    if si.abs() <= MAX_ANGLE_RAD {
        return Ok(());
    }
    Err(bad_value(
        file,
        at,
        column,
        cell,
        format!(
            "({} rad) is not an angle a table or a reference gives: beyond ±1e8 rad (16 million turns) an f64 no longer resolves 0.01″; a damaged file?",
            short_number(si)
        ),
    ))
}

/// Whether a time `t_s` after the first stamp lies within a log's span ([`MAX_LOG_SPAN_S`]; a NaN
/// does not): [`check_span`]'s rule, as a comparison.
#[inline]
#[must_use]
pub fn within_span(t_s: f64) -> bool {
    t_s.abs() <= MAX_LOG_SPAN_S
}

/// Checks a time stamp `t_s` (s after the log's first) read as `cell` from `column` at `at`.
///
/// # Errors
/// [`LogError::BadValue`] naming the value and the bound.
pub fn check_span(file: &Path, at: Location, column: &str, cell: f64, t_s: f64) -> Result<(), LogError> {
    if within_span(t_s) {
        return Ok(());
    }
    Err(bad_value(
        file,
        at,
        column,
        cell,
        format!(
            "is {} s from the IMU's first stamp: not a time on the same clock (a log spans at most 1e9 s); a damaged file?",
            short_number(t_s)
        ),
    ))
}

/// The physical range of one number a user gives — an option on the command line, a field of a
/// file's header, a key of a manifest — checked by [`check_number`], the same rule as a log's
/// samples: finite and inside what the quantity can physically be, or refused with a short message
/// naming the value and its unit (never a 300-digit echo, never a NaN or an infinity that travels).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Range {
    /// The smallest value allowed (see `min_inclusive`).
    pub min: f64,
    /// `min` itself is allowed; else only values above it (a rate, a duration: `> 0`).
    pub min_inclusive: bool,
    /// The largest value allowed.
    pub max: f64,
    /// The unit the value is given in, as the message shows it (`Hz`, `s`, `deg`).
    pub unit: &'static str,
    /// What the value is, for the message (`a sample rate`).
    pub what: &'static str,
}

impl Range {
    /// `min <= v <= max`.
    #[must_use]
    pub const fn closed(min: f64, max: f64, unit: &'static str, what: &'static str) -> Self {
        Self { min, min_inclusive: true, max, unit, what }
    }

    /// `0 < v <= max`.
    #[must_use]
    pub const fn positive(max: f64, unit: &'static str, what: &'static str) -> Self {
        Self { min: 0.0, min_inclusive: false, max, unit, what }
    }

    /// `-max <= v <= max`.
    #[must_use]
    pub const fn symmetric(max: f64, unit: &'static str, what: &'static str) -> Self {
        Self { min: -max, min_inclusive: true, max, unit, what }
    }

    /// Whether `v` is inside (a NaN never is).
    #[must_use]
    pub fn contains(&self, v: f64) -> bool {
        let above = if self.min_inclusive { v >= self.min } else { v > self.min };
        above && v <= self.max
    }

    /// The range in words: `> 0 and at most 1e9 Hz`.
    #[must_use]
    pub fn text(&self) -> String {
        let unit = self.unit;
        let sep = if unit.is_empty() { "" } else { " " };
        if self.min_inclusive && self.min == -self.max {
            format!("within ±{}{sep}{unit}", short_number(self.max))
        } else {
            let low = if self.min_inclusive { "at least" } else { ">" };
            format!("{low} {}{sep}{unit} and at most {}{sep}{unit}", short_number(self.min), short_number(self.max))
        }
    }
}

/// The rule of [`Range`]: `value` if finite and inside `range`.
///
/// # Errors
/// The message, short, naming the value and its unit, what it should be and the range (the
/// caller adds the option's or the field's name): `1e-308 Hz is not a sample rate: it must be at
/// least 1e-6 Hz and at most 1e9 Hz`.
pub fn check_number(value: f64, range: &Range) -> Result<f64, String> {
    if value.is_finite() && range.contains(value) {
        return Ok(value);
    }
    let sep = if range.unit.is_empty() { "" } else { " " };
    let (v, unit, what) = (short_number(value), range.unit, range.what);
    if value.is_finite() {
        Err(format!("{v}{sep}{unit} is out of range for {what}: it must be {}", range.text()))
    } else {
        Err(format!("{v}{sep}{unit} is not a finite number ({what} must be {})", range.text()))
    }
}

/// The sample rate of any series (`allan --series --rate-hz`), Hz. Up to 1 GHz (the fastest time
/// interval counters; the bound the reader always had); down to one sample per 11.6 days (1e-6
/// Hz): the interval 1/rate multiplies every rate sample, and below that an interval turns a
/// finite sample into an infinity (1e-308 Hz gave a 1e308 s interval and NaN deviations).
pub const SERIES_RATE_HZ: Range = Range::closed(1e-6, 1e9, "Hz", "a sample rate");

/// The sample rate of an IMU, Hz (`replay --rate-hz`, a manifest's `imu.rate_hz`): 1 Hz to 100
/// kHz, the manifest's bound (navigation IMUs log at 100 Hz to 2 kHz; none at 100 kHz).
pub const IMU_RATE_HZ: Range = Range::closed(1.0, 100_000.0, "Hz", "an IMU's sample rate");

/// A pitch, deg: ±90 (the attitude's definition).
pub const PITCH_DEG: Range = Range::symmetric(90.0, "deg", "a pitch");
/// A roll, deg: ±180.
pub const ROLL_DEG: Range = Range::symmetric(180.0, "deg", "a roll");
/// A heading or yaw, deg: ±360 (either convention, 0..360 or ±180).
pub const HEADING_DEG: Range = Range::symmetric(360.0, "deg", "a heading");
/// A latitude, deg: ±90.
pub const LATITUDE_DEG: Range = Range::symmetric(90.0, "deg", "a latitude");
/// A longitude, deg: ±360 (either convention).
pub const LONGITUDE_DEG: Range = Range::symmetric(360.0, "deg", "a longitude");
/// A height, m: from below the deepest trench (−12 km) to 100 km (the Kármán line; the manifest's
/// bound: the gravity model is not meant for orbits).
pub const HEIGHT_M: Range = Range::closed(-12_000.0, 100_000.0, "m", "a height");
/// A velocity component, m/s: ±3 km/s (the manifest's bound: beyond a rifle bullet's speed,
/// and no navigation grade vehicle flies faster in the atmosphere).
pub const VELOCITY_MPS: Range = Range::symmetric(3_000.0, "m/s", "a velocity");
/// A time on a file's clock, s: ±1e10 s (Unix time reaches 1e10 s in the year 2286; a larger
/// value is a unit other than seconds).
pub const CLOCK_S: Range = Range::symmetric(1e10, "s", "a time on the file's clock");

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_number_rule_refuses_the_absurd_in_a_short_message() {
        assert_eq!(check_number(100.0, &IMU_RATE_HZ), Ok(100.0));
        for v in [1e-308, 1e308, 1e300, -10.0, 0.0, f64::NAN, f64::INFINITY] {
            let e = check_number(v, &SERIES_RATE_HZ).expect_err("refused");
            assert!(e.len() < 120 && e.contains("Hz") && e.contains("1e9"), "{v}: {e}");
        }
        assert!(check_number(1e-308, &SERIES_RATE_HZ).expect_err("1e-308").starts_with("1e-308 Hz"));
        assert!(
            check_number(1e300, &PITCH_DEG)
                .expect_err("1e300")
                .starts_with("1e300 deg is out of range for a pitch: it must be within ±90 deg")
        );
        assert!(
            check_number(-90.0, &PITCH_DEG).is_ok()
                && check_number(0.0, &Range::positive(1.0, "s", "a duration")).is_err()
        );
    }

    #[test]
    fn bounds_refuse_the_absurd_and_say_it_short() {
        let f = Path::new("imu.csv");
        let at = Location { row: 12, line: Some(13) };
        assert!(check_imu_value(f, at, "gyro_x_rad_per_s", 600.0, 600.0, Sensor::Gyro, None).is_ok());
        assert!(check_imu_value(f, at, "dv_z_mps", 0.049, 0.049, Sensor::Accel, Some(0.005)).is_ok());
        let e = check_imu_value(f, at, "dtheta_x_rad", 1e300, 1e300, Sensor::Gyro, Some(0.005))
            .expect_err("1e300 rad")
            .to_string();
        assert!(
            e.contains("data row 12 (line 13), column dtheta_x_rad: \"1e300\"") && e.contains("gyro") && e.len() < 300,
            "{e}"
        );
        let e =
            check_imu_value(f, at, "accel_x_g", 2000.0, 19_613.3, Sensor::Accel, None).expect_err("2000 g").to_string();
        assert!(e.contains("1000 g") && e.contains("m/s²"), "{e}");
        assert!(
            check_imu_value(f, at, "gyro_x_rad_per_s", 1.0, f64::NAN, Sensor::Gyro, None).is_err(),
            "NaN fails every bound"
        );
        assert!(check_angle(f, at, "outer_rad", 6.0e7, 6.0e7).is_ok());
        let e = check_angle(f, at, "outer_deg", 1e300, 1e300f64.to_radians()).expect_err("1e300 deg").to_string();
        assert!(e.contains("\"1e300\"") && e.len() < 300, "{e}");
        assert!(check_span(f, at, "t_s", 1e300, 1e300).expect_err("1e300 s").to_string().len() < 300);
    }
}
