//! A log set: a folder of recorded data with a manifest (`log.toml`) naming its files, their
//! layout, units, frames and rates, and a table description (`table.toml`: the `[site]`,
//! `[turntable]`, `[compensation]`, `[imu]`, `[navigation]`, `[calibration]` and `[recording]`
//! sections of a scenario file). `rinscope export-log` writes exactly this; `replay` and
//! `calibrate --log` read it. Every key is documented in docs/logs.md.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::raw::{RawCalibration, RawCompensation, RawImu, RawNavigation, RawRecording, RawSite, RawTurntable};
use super::validate::{self, Checker};
use super::{instruments, ConfigError, RecordingParams};
use crate::calib::CalibConfig;
use crate::ins::InsParams;
use crate::io::{Frame, GapPolicy, Layout, SampleKind, TimeUnit};
use crate::math::attitude::Attitude;
use crate::math::units::RAD_PER_DEG;
use crate::model::earth::Site;
use crate::model::gimbal::{Chain, TableErrors};

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
}

fn default_table() -> String {
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
    /// Nominal sample rate, Hz (must match the time stamps).
    pub rate_hz: f64,
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

/// A frame: a name or a matrix.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum RawFrame {
    /// "frd", "rfu", ...
    Named(String),
    /// Rows of C (v_rfu = C · v_file).
    Matrix([[f64; 3]; 3]),
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

/// `[initial]`: at most one of the three.
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
    /// Coarse alignment over the first this many seconds (the vehicle must be at rest), s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub alignment_s: Option<f64>,
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
    /// The gimbal chain as the user knows it (nominal axes and the errors believed).
    pub turntable: RawTurntable,
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

/// How the INS starts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Initial {
    /// C_s^n given exactly (w, x, y, z).
    ImuQuaternion([f64; 4]),
    /// A body attitude, demodulated through the compensated table at the first encoder reading.
    BodyAttitude(Attitude),
    /// Coarse alignment over the first seconds.
    Alignment {
        /// Length of the static interval, s.
        duration_s: f64,
    },
}

/// The reference attitude of the body.
#[derive(Debug, Clone, PartialEq)]
pub enum Reference {
    /// None: the compensated demodulation is the reference.
    None,
    /// Constant.
    Static(Attitude),
    /// From a file of `t_s, pitch_deg, roll_deg, heading_deg`.
    File(PathBuf),
}

/// The IMU file.
#[derive(Debug, Clone, PartialEq)]
pub struct ImuFile {
    /// Absolute or relative to the working directory.
    pub path: PathBuf,
    /// Layout.
    pub layout: Layout,
    /// Increments or rates.
    pub kind: SampleKind,
    /// Nominal sample rate, Hz.
    pub rate_hz: f64,
    /// The file's axes.
    pub frame: Option<Frame>,
    /// MCAP topic.
    pub topic: Option<String>,
    /// Gap handling.
    pub gap_policy: GapPolicy,
    /// Intervals beyond this many nominal intervals are gaps.
    pub gap_factor: f64,
}

/// The encoder file.
#[derive(Debug, Clone, PartialEq)]
pub struct EncoderFile {
    /// Path.
    pub path: PathBuf,
    /// Latch time before the stamp, s.
    pub latch_delay_s: f64,
    /// Interpolate across gaps (else refuse them).
    pub interpolate_gaps: bool,
}

/// The validated table description.
#[derive(Debug, Clone)]
pub struct TableDescription {
    /// Site.
    pub site: Site,
    /// Nominal chain.
    pub chain: Chain,
    /// The errors the turntable section states (what `export-log` simulated; a real table: what is believed).
    pub stated: TableErrors,
    /// What the compensated demodulation assumes.
    pub compensation: TableErrors,
    /// The navigation computer.
    pub ins: InsParams,
    /// `[calibration]`.
    pub calibration: CalibConfig,
    /// Output rates and drawing.
    pub recording: RecordingParams,
    /// The table description as resolved, TOML (shown in the recording).
    pub resolved_toml: String,
}

/// A validated log set.
#[derive(Debug, Clone)]
pub struct LogSet {
    /// Its folder.
    pub dir: PathBuf,
    /// Name.
    pub name: String,
    /// Markdown.
    pub description: String,
    /// Seed of the simulation that wrote it, if any.
    pub seed: Option<u64>,
    /// The IMU file.
    pub imu: ImuFile,
    /// The encoders, if any.
    pub encoders: Option<EncoderFile>,
    /// The reference attitude.
    pub reference: Reference,
    /// How the INS starts.
    pub initial: Initial,
    /// The table.
    pub table: TableDescription,
    /// The table description as written (for the recording's scenario view and `--compensation`).
    pub raw_table: RawTable,
}

/// The manifest's file name in a log set's folder.
pub const MANIFEST: &str = "log.toml";

/// Reads and validates the log set in `dir`.
pub fn load(dir: &Path) -> Result<LogSet, ConfigError> {
    let manifest_path = dir.join(MANIFEST);
    let text = super::read_text(&manifest_path)?;
    let origin = manifest_path.display().to_string();
    let raw: RawManifest = toml::from_str(&text).map_err(|e| ConfigError::Parse { origin: origin.clone(), message: e.to_string().trim_end().to_owned() })?;
    let table_path = dir.join(&raw.log.table);
    let table_text = super::read_text(&table_path)?;
    let table_origin = table_path.display().to_string();
    let raw_table: RawTable = toml::from_str(&table_text).map_err(|e| ConfigError::Parse { origin: table_origin.clone(), message: e.to_string().trim_end().to_owned() })?;
    validate_manifest(dir, &raw, &origin, &raw_table, &table_origin)
}

/// Validates a manifest and its table description (`origin`s name the files in errors).
pub fn validate_manifest(dir: &Path, raw: &RawManifest, origin: &str, raw_table: &RawTable, table_origin: &str) -> Result<LogSet, ConfigError> {
    let c = Checker { origin };
    let name = &raw.log.name;
    if name.trim().is_empty() || !name.chars().all(|ch| ch.is_ascii_alphanumeric() || ch == '-' || ch == '_') {
        return Err(c.invalid("log.name", format!("\"{name}\" must be non-empty and use only letters, digits, '-' and '_' (it names the recording)")));
    }
    let imu = imu_file(&c, dir, &raw.imu)?;
    let table = table_description(&Checker { origin: table_origin }, raw_table, imu.rate_hz)?;
    let encoders = match &raw.encoders {
        None => None,
        Some(e) => Some(EncoderFile {
            path: dir.join(&e.file),
            latch_delay_s: c.range("encoders.latch_delay_ms", e.latch_delay_ms, "ms", -1000.0, 1000.0, "")? * 1e-3,
            interpolate_gaps: match e.gap_policy.as_str() {
                "interpolate" => true,
                "refuse" => false,
                other => return Err(c.invalid("encoders.gap_policy", format!("\"{other}\" is not a policy; use \"interpolate\" or \"refuse\""))),
            },
        }),
    };
    let reference = match &raw.reference {
        None => Reference::None,
        Some(r) => match (&r.file, r.attitude_deg) {
            (Some(f), None) => Reference::File(dir.join(f)),
            (None, Some(a)) => Reference::Static(attitude(&c, "reference.attitude_deg", a)?),
            _ => return Err(c.invalid("reference", "give either `file` or `attitude_deg`")),
        },
    };
    let i = &raw.initial;
    let initial = match (i.imu_quaternion_wxyz, i.body_attitude_deg, i.alignment_s) {
        (Some(q), None, None) => {
            for (k, x) in q.iter().enumerate() {
                c.finite(&format!("initial.imu_quaternion_wxyz[{k}]"), *x, "")?;
            }
            let norm = q.iter().map(|x| x * x).sum::<f64>().sqrt();
            if (norm - 1.0).abs() > 1e-6 {
                return Err(c.invalid("initial.imu_quaternion_wxyz", format!("norm {norm}: a rotation quaternion has norm 1")));
            }
            Initial::ImuQuaternion(q)
        }
        (None, Some(a), None) => Initial::BodyAttitude(attitude(&c, "initial.body_attitude_deg", a)?),
        (None, None, Some(s)) => Initial::Alignment { duration_s: c.positive("initial.alignment_s", s, "s", 86_400.0)? },
        (None, None, None) => match &reference {
            // A static reference is the initial body attitude too.
            Reference::Static(a) => Initial::BodyAttitude(*a),
            _ => Initial::Alignment { duration_s: 60.0 },
        },
        _ => return Err(c.invalid("initial", "give one of imu_quaternion_wxyz, body_attitude_deg or alignment_s")),
    };
    Ok(LogSet { dir: dir.to_path_buf(), name: name.clone(), description: raw.log.description.clone(), seed: raw.log.seed, imu, encoders, reference, initial, table, raw_table: raw_table.clone() })
}

fn attitude(c: &Checker<'_>, key: &str, a: [f64; 3]) -> Result<Attitude, ConfigError> {
    Ok(Attitude {
        pitch_rad: c.range(&format!("{key}[0]"), a[0], "deg", -90.0, 90.0, "pitch")? * RAD_PER_DEG,
        roll_rad: c.range(&format!("{key}[1]"), a[1], "deg", -180.0, 180.0, "roll")? * RAD_PER_DEG,
        heading_rad: c.range(&format!("{key}[2]"), a[2], "deg", -360.0, 360.0, "heading")? * RAD_PER_DEG,
    })
}

fn imu_file(c: &Checker<'_>, dir: &Path, raw: &RawImuFile) -> Result<ImuFile, ConfigError> {
    let rate_hz = c.range("imu.rate_hz", raw.rate_hz, "Hz", 1.0, 100_000.0, "")?;
    let time = match raw.time.as_deref().unwrap_or("s") {
        "s" => TimeUnit::Seconds,
        "ms" => TimeUnit::Milliseconds,
        "us" => TimeUnit::Microseconds,
        "ns" => TimeUnit::Nanoseconds,
        "gps_sow" => TimeUnit::GpsSecondsOfWeek,
        other => return Err(c.invalid("imu.time", format!("\"{other}\" is not a time unit; use \"s\", \"ms\", \"us\", \"ns\" or \"gps_sow\""))),
    };
    let path = dir.join(&raw.file);
    let layout = match raw.layout.as_str() {
        // No layout: the file's first line tells a PSINS SIMU file (an unreadable file is reported when read).
        "" if matches!(crate::io::detect_format(&path), Ok(crate::io::Format::PsinsImu)) => Layout::PsinsImu,
        "" | "rinscope" => Layout::Rinscope,
        "psins" => Layout::Psins,
        "psins-imu" => Layout::PsinsImu,
        "kf-gins" => Layout::KfGins,
        "kalibr" => Layout::Kalibr,
        "npy7" => Layout::Npy7 { time },
        "ros2" => Layout::Ros2,
        other => return Err(c.invalid("imu.layout", format!("\"{other}\" is not a layout; use \"rinscope\", \"psins\", \"psins-imu\", \"kf-gins\", \"kalibr\", \"npy7\" or \"ros2\""))),
    };
    if raw.time.is_some() && !matches!(layout, Layout::Npy7 { .. }) {
        return Err(c.invalid("imu.time", "is read by the npy7 layout only (the others say their time unit themselves)"));
    }
    let kind = match raw.kind.as_deref() {
        None | Some("increments") => SampleKind::Increments,
        Some("rates") => SampleKind::Rates,
        Some(other) => return Err(c.invalid("imu.kind", format!("\"{other}\" is not a kind; use \"increments\" or \"rates\""))),
    };
    let frame = match &raw.frame {
        None => None,
        Some(RawFrame::Named(n)) => Some(Frame::Named(n.clone())),
        Some(RawFrame::Matrix(m)) => Some(Frame::Matrix(nalgebra::Matrix3::from_fn(|r, k| m[r][k]))),
    };
    if let Some(f) = &frame {
        f.to_rfu().map_err(|e| c.invalid("imu.frame", e.to_string()))?;
    }
    let gap_policy = match raw.gap_policy.as_str() {
        "refuse" => GapPolicy::Refuse,
        "split" => GapPolicy::Split,
        other => return Err(c.invalid("imu.gap_policy", format!("\"{other}\" is not a policy; use \"refuse\" or \"split\""))),
    };
    Ok(ImuFile {
        path,
        layout,
        kind,
        rate_hz,
        frame,
        topic: raw.topic.clone(),
        gap_policy,
        gap_factor: c.range("imu.gap_factor", raw.gap_factor, "intervals", 1.5, 1e6, "")?,
    })
}

/// Validates a table description for an IMU at `rate_hz`.
fn table_description(c: &Checker<'_>, raw: &RawTable, rate_hz: f64) -> Result<TableDescription, ConfigError> {
    let site = validate::site(c, &raw.site)?;
    let (chain, stated) = validate::turntable(c, &raw.turntable)?;
    let (compensation, resolved_comp) = validate::validate_compensation(c, &raw.compensation, &raw.turntable, &chain, &stated)?;
    let ins = instruments::validate_ins(c, Some(&raw.imu.clone().unwrap_or_default()), raw.navigation.as_ref(), rate_hz)?.unwrap_or_else(|| InsParams::ideal(rate_hz, crate::ins::coning::Algorithm::TwoSampleP1));
    // The calibration allows for the INS error the [imu] section states (a datasheet's), if any.
    let calibration = instruments::validate_calibration(c, &raw.calibration.clone().unwrap_or_default(), &stated, raw.imu.is_some().then_some(&ins))?;
    // A log's motion is not known before it is read: the defaults of a table turning at 10°/s
    // (10 Hz series and scene) unless [recording] says otherwise.
    let recording = validate::recording(c, &raw.recording, rate_hz, validate::Bandwidth { shaft_deg_per_s: 10.0, motion_hz: 0.0, duration_s: 3600.0 }, 0.0)?;
    let mut resolved = raw.clone();
    resolved.compensation = resolved_comp;
    let resolved_toml = toml::to_string_pretty(&resolved).unwrap_or_else(|e| format!("# could not serialise: {e}"));
    Ok(TableDescription { site, chain, stated, compensation, ins, calibration, recording, resolved_toml })
}

impl LogSet {
    /// The log as a scenario for the recorder: its table at rest, its IMU rate, `duration_s` long
    /// (the recording's playback speed), the table description as its configuration.
    pub fn recording_params(&self, duration_s: f64) -> Result<super::Params, ConfigError> {
        use super::raw::{RawLive, RawScenario, RawScheme, RawSimulation, RawVehicle};
        let t = &self.raw_table;
        let raw = super::RawConfig {
            scenario: RawScenario { name: self.name.clone(), title: format!("replay of the log set {}", self.dir.display()), description: self.description.clone(), seed: self.seed.unwrap_or(0) },
            simulation: RawSimulation { duration_s: duration_s.max(1.0 / self.imu.rate_hz), step_hz: self.imu.rate_hz },
            recording: t.recording.clone(),
            site: t.site.clone(),
            vehicle: RawVehicle::default(),
            turntable: t.turntable.clone(),
            scheme: RawScheme { kind: "static".into(), rate: Vec::new(), initial_dwell_s: None, repeat: None, step: Vec::new() },
            compensation: t.compensation.clone(),
            live: RawLive::default(),
            imu: Some(t.imu.clone().unwrap_or_default()),
            navigation: t.navigation.clone(),
            calibration: t.calibration.clone(),
            position_fix: None,
        };
        let mut p = super::validate::validate(raw, &self.dir.join(MANIFEST).display().to_string())?;
        p.resolved_toml = self.table.resolved_toml.clone();
        Ok(p)
    }
}

/// The `estimated_compensation` of a calibration JSON (`rinscope calibrate --json`) as the table errors of
/// `table`: its keys are `[compensation]`'s, and the table's own values fill what it leaves out.
pub fn compensation_from_calibration(table: &RawTable, json_text: &str, origin: &str) -> Result<TableErrors, ConfigError> {
    #[derive(Deserialize)]
    struct WithCompensation {
        estimated_compensation: RawCompensation,
    }
    let parsed: WithCompensation = serde_json::from_str(json_text).map_err(|e| ConfigError::Parse { origin: origin.to_owned(), message: format!("not a calibration of `rinscope calibrate --json` ({e})") })?;
    let c = Checker { origin };
    let (chain, stated) = validate::turntable(&c, &table.turntable)?;
    let mut merged = table.compensation.clone();
    let given = parsed.estimated_compensation;
    merged.enabled = given.enabled.or(merged.enabled);
    for (k, v) in given.axis {
        merged.axis.insert(k, v);
    }
    macro_rules! take {
        ($($f:ident),*) => { $( if given.$f.is_some() { merged.$f = given.$f; } )* };
    }
    take!(installation_x_arcsec, installation_y_arcsec, installation_z_arcsec, imu_mount_x_arcsec, imu_mount_y_arcsec, imu_mount_z_arcsec);
    Ok(validate::validate_compensation(&c, &merged, &table.turntable, &chain, &stated)?.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn raw_imu(file: &str, layout: &str) -> RawImuFile {
        RawImuFile { file: file.into(), layout: layout.into(), kind: None, rate_hz: 100.0, frame: None, time: None, topic: None, gap_policy: "refuse".into(), gap_factor: 3.0 }
    }

    #[test]
    fn psins_imu_by_name_and_when_no_layout_is_given() {
        let dir = std::env::temp_dir().join(format!("rinscope-logset-psins-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("scratch dir");
        // imufile.m's first line; the reader checks the rest.
        std::fs::write(dir.join("trj.txt"), "% PSINS-format SIMU log file. (DO NOT MODIFY!)\n").expect("write");
        std::fs::write(dir.join("imu.csv"), "t_s,dtheta_x_rad\n").expect("write");
        let c = Checker { origin: "log.toml" };
        let layout = |file: &str, name: &str| imu_file(&c, &dir, &raw_imu(file, name)).map(|f| f.layout);
        assert_eq!(layout("trj.txt", "psins-imu").ok(), Some(Layout::PsinsImu));
        assert_eq!(layout("trj.txt", "").ok(), Some(Layout::PsinsImu));
        assert_eq!(layout("imu.csv", "").ok(), Some(Layout::Rinscope));
        assert_eq!(layout("missing.csv", "").ok(), Some(Layout::Rinscope));
        let e = layout("trj.txt", "psins-simu").expect_err("not a layout").to_string();
        assert!(e.contains("\"psins-imu\""), "{e}");
        // An absent key is the empty layout, and is not written back.
        let raw: RawImuFile = toml::from_str("file = \"trj.txt\"\nrate_hz = 100.0\n").expect("parse");
        assert_eq!(raw.layout, "");
        assert!(!toml::to_string(&raw).expect("serialise").contains("layout"));
        let _ = std::fs::remove_dir_all(&dir);
    }
}
