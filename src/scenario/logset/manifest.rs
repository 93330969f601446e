//! `log.toml` and `table.toml` as written: the serde structs, every key documented (docs/logs.md).

use serde::{Deserialize, Serialize};

use super::super::raw::{RawCalibration, RawCompensation, RawImu, RawNavigation, RawRecording, RawSite, RawTurntable};
use super::{Checker, ConfigError};
use crate::io::TimeUnit;

/// `log.toml` as written.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawManifest {
    /// What the log is.
    pub log: RawLogInfo,
    /// The IMU file.
    pub imu: RawImuFile,
    /// The encoder file (absent: the gimbals stand at their initial angles).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub encoders: Option<RawEncoderFile>,
    /// A reference attitude of the body (absent: the compensated demodulation is the reference).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reference: Option<RawReference>,
    /// The INS's initial attitude: given, or from a static alignment interval.
    #[serde(default)]
    pub initial: RawInitial,
}

/// `[log]`
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawLogInfo {
    /// Identifier, also the recording's name (letters, digits, '-' and '_').
    pub name: String,
    /// Markdown shown beside the scene in the viewer.
    #[serde(default)]
    pub description: String,
    /// The table description, relative to the folder (default "table.toml").
    #[serde(default = "default_table")]
    pub table: String,
    /// Seed of the simulation that wrote the log (export-log), for the record.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seed: Option<u64>,
    /// Replay from this time on the IMU file's clock (as written in its time column), s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub from_s: Option<f64>,
    /// Replay up to this time on the IMU file's clock, s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub to_s: Option<f64>,
}

pub(super) fn default_table() -> String {
    "table.toml".into()
}

/// `[imu]`
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawImuFile {
    /// The file, relative to the folder (.csv, .txt, .npy, .parquet, .mcap, PSINS .imu).
    pub file: String,
    /// "rinscope" (units in the column names), "psins", "psins-imu", "kf-gins", "kalibr", "npy7",
    /// "ros2"; empty (absent): "psins-imu" for a PSINS SIMU file (its first line names PSINS and
    /// SIMU), else "rinscope".
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub layout: String,
    /// "increments" or "rates" (checked against the layout's own).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kind: Option<String>,
    /// Nominal sample rate, Hz (must match the time stamps; absent: what the stamps say).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rate_hz: Option<f64>,
    /// The IMU axes in the file: "rfu" (rinscope's), "frd", "flu", ... (three letters of r/l, f/b,
    /// u/d) or a 3×3 matrix C with v_rfu = C · v_file, row by row.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frame: Option<RawFrame>,
    /// Time unit of the npy7 layout's first column: "s", "ms", "us", "ns", "gps_sow".
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time: Option<String>,
    /// MCAP: the topic (default: the only sensor_msgs/msg/Imu topic).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub topic: Option<String>,
    /// A foreign or headerless file described column by column (instead of a layout).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub columns: Option<RawColumns>,
    /// A gap longer than `gap_factor` nominal intervals: "refuse" or "split" (carry the attitude
    /// across, report the gap).
    #[serde(default = "default_refuse")]
    pub gap_policy: String,
    /// Nominal intervals beyond which an interval is a gap (default 3).
    #[serde(default = "default_gap_factor")]
    pub gap_factor: f64,
}

fn default_refuse() -> String {
    "refuse".into()
}
fn default_gap_factor() -> f64 {
    3.0
}

/// `[imu.columns]`: each column by 0-based position or header name, with its unit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawColumns {
    /// The time: unit "s", "ms", "us", "ns" or "gps_sow".
    pub time: RawColumn,
    /// Gyro x: a rate unit (rad_per_s, deg_per_s, deg_per_h) or an angle increment's (rad, mrad, urad, deg, arcsec).
    pub gyro_x: RawColumn,
    /// Gyro y.
    pub gyro_y: RawColumn,
    /// Gyro z.
    pub gyro_z: RawColumn,
    /// Accelerometer x: an acceleration unit (mps2, g, mg, ug) or a velocity increment's (mps).
    pub accel_x: RawColumn,
    /// Accelerometer y.
    pub accel_y: RawColumn,
    /// Accelerometer z.
    pub accel_z: RawColumn,
}

/// One column of `[imu.columns]`: `{ column = 3, unit = "deg_per_s" }` or `{ column = "GyroX", unit = ... }`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawColumn {
    /// 0-based position, or the header's name for it.
    pub column: RawColumnId,
    /// Its unit.
    pub unit: String,
}

/// A column by position or by name.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum RawColumnId {
    /// 0-based position.
    Index(usize),
    /// Header name.
    Name(String),
}

impl RawColumnId {
    pub(super) fn col(&self) -> crate::io::Col {
        match self {
            Self::Index(i) => crate::io::Col::Index(*i),
            Self::Name(n) => crate::io::Col::Name(n.clone()),
        }
    }
}

/// The time unit named `name` (`key` names it in errors).
pub(super) fn time_unit(c: &Checker<'_>, key: &str, name: &str) -> Result<TimeUnit, ConfigError> {
    Ok(match name {
        "s" => TimeUnit::Seconds,
        "ms" => TimeUnit::Milliseconds,
        "us" => TimeUnit::Microseconds,
        "ns" => TimeUnit::Nanoseconds,
        "gps_sow" => TimeUnit::GpsSecondsOfWeek,
        other => {
            return Err(c.invalid(
                key,
                format!("\"{other}\" is not a time unit; use \"s\", \"ms\", \"us\", \"ns\" or \"gps_sow\""),
            ));
        }
    })
}

/// A frame: a name or a matrix.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(untagged)]
pub enum RawFrame {
    /// "frd", "rfu", ...
    Named(String),
    /// Rows of C (v_rfu = C · v_file).
    Matrix([[f64; 3]; 3]),
}

/// Read by hand, so that a matrix of the wrong shape says what it is (serde's untagged enums say
/// only "did not match any variant").
impl<'de> Deserialize<'de> for RawFrame {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::Error;
        const EXPECTED: &str = "a frame name (\"rfu\", \"frd\", \"flu\", ...) or a 3×3 matrix [[c11, c12, c13], [c21, c22, c23], [c31, c32, c33]] (rows of C, v_rfu = C · v_file)";
        let value = toml::Value::deserialize(d)?;
        let rows = match value {
            toml::Value::String(name) => return Ok(Self::Named(name)),
            toml::Value::Array(rows) => rows,
            other => return Err(D::Error::custom(format!("frame: a {} is not {EXPECTED}", other.type_str()))),
        };
        if rows.len() != 3 {
            return Err(D::Error::custom(format!("frame: a matrix of {} rows is not {EXPECTED}", rows.len())));
        }
        let mut m = [[0.0; 3]; 3];
        for (r, row) in rows.iter().enumerate() {
            let Some(cells) = row.as_array().filter(|c| c.len() == 3) else {
                return Err(D::Error::custom(format!(
                    "frame: row {} is {}, not 3 numbers: {EXPECTED}",
                    r + 1,
                    row.as_array().map_or_else(|| format!("a {}", row.type_str()), |c| format!("{} values", c.len()))
                )));
            };
            for (k, cell) in cells.iter().enumerate() {
                m[r][k] = match cell {
                    toml::Value::Float(x) => *x,
                    toml::Value::Integer(i) => *i as f64,
                    other => {
                        return Err(D::Error::custom(format!(
                            "frame: row {} column {} is a {}, not a number",
                            r + 1,
                            k + 1,
                            other.type_str()
                        )));
                    }
                };
            }
        }
        Ok(Self::Matrix(m))
    }
}

/// `[encoders]`: time and one angle column per table axis, named `<axis>_deg`, `<axis>_rad` or
/// `<axis>_arcsec` (the axis names of the table description).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawEncoderFile {
    /// The file, relative to the folder (.csv, .npy with columns t_s then the axes in table order, .parquet).
    pub file: String,
    /// The readings were latched this long before their time stamps, ms (shifts the stamps).
    #[serde(default)]
    pub latch_delay_ms: f64,
    /// A gap in the encoder stamps: "interpolate" (linear between the readings around it) or "refuse".
    #[serde(default = "default_interpolate")]
    pub gap_policy: String,
}

fn default_interpolate() -> String {
    "interpolate".into()
}

/// `[reference]`: the true body attitude, from a file (`t_s, pitch_deg, roll_deg, heading_deg`), or
/// constant (a static site attitude).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawReference {
    /// Where it comes from, for people: "turntable controller", "reference INS", "static site attitude".
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub source: Option<String>,
    /// The file, relative to the folder.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<String>,
    /// A constant attitude [pitch, roll, heading], deg.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub attitude_deg: Option<[f64; 3]>,
}

/// `[initial]`: the attitude (at most one of the first three; none: an alignment over the rest the
/// data show at the start), velocity and position, and what the alignment may assume.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawInitial {
    /// C_s^n at the end of the pre-roll as a quaternion (w, x, y, z): exact (export-log writes it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub imu_quaternion_wxyz: Option<[f64; 4]>,
    /// The body attitude [pitch, roll, heading], deg, demodulated through the compensated table at
    /// the first encoder reading.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub body_attitude_deg: Option<[f64; 3]>,
    /// Align over the first this many seconds, declared at rest (absent: the rest the data show,
    /// at most 300 s), s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub alignment_s: Option<f64>,
    /// Velocity at the start [East, North, Up], m/s (a moving start; default at rest).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub velocity_enu_mps: Option<[f64; 3]>,
    /// Position at the start [latitude deg, longitude deg, height m] (default: the table
    /// description's [site]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub position: Option<[f64; 3]>,
    /// Alignment: the gyro bias 1σ before alignment, °/h (default: the table description's [imu],
    /// else assumed from the measured noise and said so).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gyro_bias_deg_per_h: Option<f64>,
    /// Alignment: the accelerometer bias 1σ, µg (default as the gyro's).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub accel_bias_ug: Option<f64>,
    /// Alignment: one-second means of the specific force that change by more mark motion, m/s²
    /// (default 0.05).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rest_threshold_mps2: Option<f64>,
}

/// `table.toml`: the scenario sections that describe the instrument, not its motion.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawTable {
    /// Output rates and drawing of the replay's recording.
    #[serde(default)]
    pub recording: RawRecording,
    /// Where on Earth.
    #[serde(default)]
    pub site: RawSite,
    /// The gimbal chain as the user knows it (nominal axes and the errors believed); absent: a
    /// strapdown IMU (its axes are the body's).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub turntable: Option<RawTurntable>,
    /// What the compensated demodulation assumes (each key defaults to the turntable's value).
    #[serde(default)]
    pub compensation: RawCompensation,
    /// The navigation computer (algorithm, FIR, zero-order hold, Δt); sensor-error keys are ignored.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub imu: Option<RawImu>,
    /// Navigation of velocity and position.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub navigation: Option<RawNavigation>,
    /// `calibrate --log`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub calibration: Option<RawCalibration>,
}
