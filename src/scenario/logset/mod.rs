//! A log set: a folder of recorded data with a manifest (`log.toml`) naming its files, their
//! layout, units, frames and rates, and a table description (`table.toml`: the `[site]`,
//! `[turntable]`, `[compensation]`, `[imu]`, `[navigation]`, `[calibration]` and `[recording]`
//! sections of a scenario file). `rinscope export-log` writes exactly this; `replay` and
//! `calibrate --log` read it. Every key is documented in docs/logs.md.

use std::path::{Path, PathBuf};

use super::raw::{RawCompensation, RawNavigation, RawRecording, RawSite, RawTurntable};
use super::validate::{self, Checker};
use super::{ConfigError, RecordingParams, instruments};
use crate::calib::CalibConfig;
use crate::ins::InsParams;
use crate::io::{Frame, GapPolicy, Layout, SampleKind};
use crate::math::attitude::Attitude;
use crate::math::units::RAD_PER_DEG;
use crate::model::earth::Site;
use crate::model::gimbal::{Chain, TableErrors};

mod manifest;

pub use manifest::*;

/// How the INS starts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Initial {
    /// C_s^n given exactly (w, x, y, z).
    ImuQuaternion([f64; 4]),
    /// A body attitude, demodulated through the compensated table at the first encoder reading.
    BodyAttitude(Attitude),
    /// Alignment at rest at the start.
    Alignment {
        /// The window declared at rest, s (None: the rest the data show, at most
        /// [`DEFAULT_ALIGNMENT_S`]).
        duration_s: Option<f64>,
    },
}

/// A start stated by the IMU file itself.
#[derive(Debug, Clone, PartialEq)]
pub struct HeaderStart {
    /// Where it comes from, for people ("the PSINS header of run.imu").
    pub source: String,
    /// The attitude.
    pub attitude: Attitude,
    /// The velocity (East, North, Up), m/s.
    pub velocity_enu_mps: [f64; 3],
}

/// The longest alignment window taken when the data decide, s.
pub const DEFAULT_ALIGNMENT_S: f64 = 300.0;

/// What the alignment may assume (SI; None: from the table description or the data).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AlignPriors {
    /// Gyro bias 1σ, rad/s.
    pub gyro_bias_rad_per_s: Option<f64>,
    /// Accelerometer bias 1σ, m/s².
    pub accel_bias_mps2: Option<f64>,
    /// Motion threshold of the rest scan, m/s².
    pub rest_threshold_mps2: f64,
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
    /// Increments or rates, if declared (checked against the file's own).
    pub kind: Option<SampleKind>,
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
    /// No turntable: a strapdown IMU whose axes are the body's (`chain` is a stand-in axis that
    /// never turns; nothing of a table is shown or exported).
    pub strapdown: bool,
    /// No `[navigation]` section: the INS integrates the attitude only (the replay says so).
    pub navigation_absent: bool,
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
    /// Velocity at the start (East, North, Up), m/s, if given (a moving start).
    pub initial_velocity_enu_mps: Option<[f64; 3]>,
    /// What the alignment may assume.
    pub align: AlignPriors,
    /// The start the IMU file's own header states (a PSINS .imu): used when the vehicle moves at
    /// the start and nothing else is given.
    pub header_start: Option<HeaderStart>,
    /// The part of the log replayed: from, to, on the IMU file's clock, s.
    pub span_s: (Option<f64>, Option<f64>),
    /// The table.
    pub table: TableDescription,
    /// The table description as written (for the recording's scenario view and `--compensation`).
    pub raw_table: RawTable,
    /// The IMU errors removed from every sample as it is read (a self-calibration's estimates,
    /// `replay --compensation`): everything downstream, the alignment first, sees the compensated
    /// IMU. None: the samples as logged.
    pub imu_compensation: Option<crate::ins::imu_errors::ImuErrors>,
}

/// The manifest's file name in a log set's folder.
pub const MANIFEST: &str = "log.toml";

/// Reads and validates the log set in `dir`.
pub fn load(dir: &Path) -> Result<LogSet, ConfigError> {
    load_overridden(dir, |_| {})
}

/// Reads the log set in `dir`, lets `edit` change its manifest (the command line's overrides), and
/// validates it.
pub fn load_overridden(dir: &Path, edit: impl FnOnce(&mut RawManifest)) -> Result<LogSet, ConfigError> {
    load_for(dir, edit, true)
}

/// Reads and validates the log set in `dir` for what reads its IMU file only (`allan`): a
/// strapdown log's start position may be absent (nothing navigates; the site is then the default,
/// unused).
pub fn load_imu(dir: &Path) -> Result<LogSet, ConfigError> {
    load_for(dir, |_| {}, false)
}

fn load_for(dir: &Path, edit: impl FnOnce(&mut RawManifest), navigates: bool) -> Result<LogSet, ConfigError> {
    let manifest_path = dir.join(MANIFEST);
    let text = super::read_text(&manifest_path)?;
    let origin = manifest_path.display().to_string();
    let mut raw: RawManifest = toml::from_str(&text)
        .map_err(|e| ConfigError::Parse { origin: origin.clone(), message: super::parse_message(&e) })?;
    edit(&mut raw);
    let table_path = dir.join(&raw.log.table);
    // A strapdown log needs no table description: the default name may be absent.
    if raw.log.table == default_table() && !table_path.exists() {
        return validate_manifest_for(
            dir,
            &raw,
            &origin,
            &RawTable::strapdown(),
            "(no table.toml: a strapdown IMU)",
            navigates,
        );
    }
    let (raw_table, table_origin) = read_table(&table_path)?;
    validate_manifest_for(dir, &raw, &origin, &raw_table, &table_origin, navigates)
}

/// Reads a table description file.
pub fn read_table(path: &Path) -> Result<(RawTable, String), ConfigError> {
    let text = super::read_text(path)?;
    let origin = path.display().to_string();
    let raw: RawTable = toml::from_str(&text)
        .map_err(|e| ConfigError::Parse { origin: origin.clone(), message: super::parse_message(&e) })?;
    Ok((raw, origin))
}

impl RawTable {
    /// The description of a strapdown IMU: no turntable, navigation on with the vertical channel
    /// held, everything else at its default.
    #[must_use]
    pub fn strapdown() -> Self {
        Self {
            recording: RawRecording::default(),
            site: RawSite::default(),
            turntable: None,
            compensation: RawCompensation::default(),
            imu: None,
            navigation: Some(RawNavigation::held()),
            calibration: None,
        }
    }
}

/// Validates a manifest and its table description (`origin`s name the files in errors).
pub fn validate_manifest(
    dir: &Path,
    raw: &RawManifest,
    origin: &str,
    raw_table: &RawTable,
    table_origin: &str,
) -> Result<LogSet, ConfigError> {
    validate_manifest_for(dir, raw, origin, raw_table, table_origin, true)
}

/// [`validate_manifest`]; `navigates`: the log will be navigated (a strapdown log needs its start position).
fn validate_manifest_for(
    dir: &Path,
    raw: &RawManifest,
    origin: &str,
    raw_table: &RawTable,
    table_origin: &str,
    navigates: bool,
) -> Result<LogSet, ConfigError> {
    let c = Checker { origin };
    let name = &raw.log.name;
    if name.trim().is_empty() || !name.chars().all(|ch| ch.is_ascii_alphanumeric() || ch == '-' || ch == '_') {
        return Err(c.invalid(
            "log.name",
            format!("\"{name}\" must be non-empty and use only letters, digits, '-' and '_' (it names the recording)"),
        ));
    }
    let imu = imu_file(&c, dir, &raw.imu)?;
    let mut table = table_description(&Checker { origin: table_origin }, raw_table, imu.rate_hz)?;
    let i = &raw.initial;
    // A PSINS .imu states its start: the position is the site unless [initial] gives one, the
    // attitude and velocity serve a start in motion ("maybe inaccurate", its writer says).
    let psins = if imu.layout == Layout::PsinsImu {
        Some(crate::io::read_psins_header(&imu.path).map_err(|e| c.invalid("imu.file", e.to_string()))?)
    } else {
        None
    };
    let header_start = psins.as_ref().map(|h| HeaderStart {
        source: format!("the PSINS header of {}", imu.path.display()),
        attitude: Attitude {
            pitch_rad: h.pitch_deg * RAD_PER_DEG,
            roll_rad: h.roll_deg * RAD_PER_DEG,
            heading_rad: h.heading_deg() * RAD_PER_DEG,
        },
        velocity_enu_mps: h.velocity_enu_mps,
    });
    if let (Some(h), None) = (&psins, i.position) {
        table.site = crate::model::earth::Site {
            latitude_rad: c.range("the PSINS header's latitude", h.latitude_deg, "deg", -89.0, 89.0, "latitude")?
                * RAD_PER_DEG,
            longitude_rad: h.longitude_deg * RAD_PER_DEG,
            height_m: h.height_m,
        };
    } else if let Some([lat, lon, h]) = i.position {
        table.site = crate::model::earth::Site {
            latitude_rad: c.range("initial.position[0]", lat, "deg", -89.0, 89.0, "latitude")? * RAD_PER_DEG,
            longitude_rad: c.range("initial.position[1]", lon, "deg", -360.0, 360.0, "longitude")? * RAD_PER_DEG,
            height_m: c.range("initial.position[2]", h, "m", -12_000.0, 100_000.0, "height")?,
        };
    } else if table.strapdown && navigates {
        return Err(c.invalid("initial.position", "a strapdown log without a table description needs its start position: [initial] position = [latitude_deg, longitude_deg, height_m] (or --position, or a table.toml with [site])"));
    }
    let initial_velocity_enu_mps = match i.velocity_enu_mps {
        None => None,
        Some(v) => {
            for (k, x) in v.iter().enumerate() {
                c.range(&format!("initial.velocity_enu_mps[{k}]"), *x, "m/s", -3000.0, 3000.0, "")?;
            }
            Some(v)
        }
    };
    let align = AlignPriors {
        gyro_bias_rad_per_s: i
            .gyro_bias_deg_per_h
            .map(|b| c.positive("initial.gyro_bias_deg_per_h", b, "°/h", 1e5))
            .transpose()?
            .map(|b| b * crate::math::units::RAD_PER_S_PER_DEG_PER_H),
        accel_bias_mps2: i
            .accel_bias_ug
            .map(|b| c.positive("initial.accel_bias_ug", b, "µg", 1e6))
            .transpose()?
            .map(|b| b * crate::math::units::MPS2_PER_UG),
        rest_threshold_mps2: i.rest_threshold_mps2.map_or(Ok(crate::ins::align::REST_THRESHOLD_MPS2), |t| {
            c.positive("initial.rest_threshold_mps2", t, "m/s²", 10.0)
        })?,
    };
    // Times on the file's clock: finite and within ±1e10 s (the one number rule's CLOCK_S).
    let clock = crate::io::validity::CLOCK_S;
    let span_s = (
        raw.log.from_s.map(|t| c.range("log.from_s", t, "s", clock.min, clock.max, "")).transpose()?,
        raw.log.to_s.map(|t| c.range("log.to_s", t, "s", clock.min, clock.max, "")).transpose()?,
    );
    if let (Some(a), Some(b)) = span_s
        && b <= a
    {
        return Err(c.invalid(
            "log.to_s",
            format!("{} s is not after log.from_s = {} s", crate::io::short_number(b), crate::io::short_number(a)),
        ));
    }
    let encoders = match &raw.encoders {
        None => None,
        Some(e) => Some(EncoderFile {
            path: readable(&c, "encoders.file", &dir.join(&e.file))?,
            latch_delay_s: c.range("encoders.latch_delay_ms", e.latch_delay_ms, "ms", -1000.0, 1000.0, "")? * 1e-3,
            interpolate_gaps: match e.gap_policy.as_str() {
                "interpolate" => true,
                "refuse" => false,
                other => {
                    return Err(c.invalid(
                        "encoders.gap_policy",
                        format!("\"{other}\" is not a policy; use \"interpolate\" or \"refuse\""),
                    ));
                }
            },
        }),
    };
    let reference = match &raw.reference {
        None => Reference::None,
        Some(r) => match (&r.file, r.attitude_deg) {
            (Some(f), None) => Reference::File(readable(&c, "reference.file", &dir.join(f))?),
            (None, Some(a)) => Reference::Static(attitude(&c, "reference.attitude_deg", a)?),
            _ => return Err(c.invalid("reference", "give either `file` or `attitude_deg`")),
        },
    };
    let initial = match (i.imu_quaternion_wxyz, i.body_attitude_deg, i.alignment_s) {
        (Some(q), None, None) => {
            for (k, x) in q.iter().enumerate() {
                c.finite(&format!("initial.imu_quaternion_wxyz[{k}]"), *x, "")?;
            }
            let norm = q.iter().map(|x| x * x).sum::<f64>().sqrt();
            if (norm - 1.0).abs() > 1e-6 {
                return Err(c.invalid(
                    "initial.imu_quaternion_wxyz",
                    format!("norm {}: a rotation quaternion has norm 1", crate::io::short_number(norm)),
                ));
            }
            Initial::ImuQuaternion(q)
        }
        (None, Some(a), None) => Initial::BodyAttitude(attitude(&c, "initial.body_attitude_deg", a)?),
        (None, None, Some(s)) => {
            Initial::Alignment { duration_s: Some(c.positive("initial.alignment_s", s, "s", 86_400.0)?) }
        }
        (None, None, None) => match &reference {
            // A static reference is the initial body attitude too.
            Reference::Static(a) => Initial::BodyAttitude(*a),
            _ => Initial::Alignment { duration_s: None },
        },
        _ => return Err(c.invalid("initial", "give one of imu_quaternion_wxyz, body_attitude_deg or alignment_s")),
    };
    if matches!(initial, Initial::Alignment { .. })
        && initial_velocity_enu_mps.is_some_and(|v| v.iter().any(|x| *x != 0.0))
    {
        return Err(c.invalid("initial.velocity_enu_mps", "a moving start cannot be aligned at rest: give its attitude too (initial.body_attitude_deg or imu_quaternion_wxyz)"));
    }
    if table.strapdown && encoders.is_some() {
        return Err(c.invalid("encoders", "an encoder file needs a table description with [turntable] (log.table)"));
    }
    Ok(LogSet {
        dir: dir.to_path_buf(),
        name: name.clone(),
        description: raw.log.description.clone(),
        seed: raw.log.seed,
        imu,
        encoders,
        reference,
        initial,
        initial_velocity_enu_mps,
        align,
        header_start,
        span_s,
        table,
        raw_table: raw_table.clone(),
        imu_compensation: None,
    })
}

/// `path` if it opens as an input ([`crate::io::files::open_input`]): a missing file, a FIFO, a
/// device or a directory named by `key` is refused with the manifest, before anything runs.
fn readable(c: &Checker<'_>, key: &str, path: &Path) -> Result<PathBuf, ConfigError> {
    match crate::io::files::open_input(path) {
        Ok(_) => Ok(path.to_path_buf()),
        Err(e) => Err(c.invalid(key, format!("{}: {e}", path.display()))),
    }
}

fn attitude(c: &Checker<'_>, key: &str, a: [f64; 3]) -> Result<Attitude, ConfigError> {
    Ok(Attitude {
        pitch_rad: c.range(&format!("{key}[0]"), a[0], "deg", -90.0, 90.0, "pitch")? * RAD_PER_DEG,
        roll_rad: c.range(&format!("{key}[1]"), a[1], "deg", -180.0, 180.0, "roll")? * RAD_PER_DEG,
        heading_rad: c.range(&format!("{key}[2]"), a[2], "deg", -360.0, 360.0, "heading")? * RAD_PER_DEG,
    })
}

fn imu_file(c: &Checker<'_>, dir: &Path, raw: &RawImuFile) -> Result<ImuFile, ConfigError> {
    let time = time_unit(c, "imu.time", raw.time.as_deref().unwrap_or("s"))?;
    let path = dir.join(&raw.file);
    readable(c, "imu.file", &path)?;
    // No layout: the file's content tells it where that is unambiguous (an ambiguous one is
    // refused here, with the candidates).
    let guessed = match raw.layout.as_str() {
        "" | "columns" if raw.columns.is_some() => "columns",
        "columns" => {
            return Err(c.invalid("imu.layout", "\"columns\" needs the [imu.columns] table that describes them"));
        }
        _ if raw.columns.is_some() => {
            return Err(c.invalid(
                "imu.columns",
                format!(
                    "describes a file of no named layout; drop layout = \"{}\" (or the [imu.columns] table)",
                    raw.layout
                ),
            ));
        }
        "" => match crate::io::guess_layout(&path) {
            Ok(name) => name,
            Err(e @ crate::io::LogError::Layout { .. }) => return Err(c.invalid("imu.layout", e.to_string())),
            Err(_) => "rinscope",
        },
        given => given,
    };
    let layout = match guessed {
        "rinscope" => Layout::Rinscope,
        "psins" => Layout::Psins,
        "psins-imu" => Layout::PsinsImu,
        "kf-gins" => Layout::KfGins,
        "kalibr" => Layout::Kalibr,
        "npy7" => Layout::Npy7 { time },
        "ros2" => Layout::Ros2,
        "columns" => {
            let Some(m) = &raw.columns else { return Err(c.invalid("imu.columns", "missing")) };
            if raw.frame.is_none() {
                return Err(c.invalid("imu.frame", "a file described by [imu.columns] has no standard axes: give frame = \"rfu\" (x right, y forward, z up), \"frd\", \"flu\", ... or a 3×3 matrix"));
            }
            let sensor = |r: &RawColumn| (r.column.col(), r.unit.clone());
            Layout::Columns(Box::new(crate::io::ColumnMap {
                time: (m.time.column.col(), time_unit(c, "imu.columns.time.unit", &m.time.unit)?),
                sensors: [sensor(&m.gyro_x), sensor(&m.gyro_y), sensor(&m.gyro_z), sensor(&m.accel_x), sensor(&m.accel_y), sensor(&m.accel_z)],
            }))
        }
        other => return Err(c.invalid("imu.layout", format!("\"{other}\" is not a layout; use \"rinscope\", \"psins\", \"psins-imu\", \"kf-gins\", \"kalibr\", \"npy7\" or \"ros2\""))),
    };
    if raw.time.is_some() && !matches!(layout, Layout::Npy7 { .. }) {
        return Err(
            c.invalid("imu.time", "is read by the npy7 layout only (the others say their time unit themselves)")
        );
    }
    let kind = match raw.kind.as_deref() {
        None => None,
        Some("increments") => Some(SampleKind::Increments),
        Some("rates") => Some(SampleKind::Rates),
        Some(other) => {
            return Err(c.invalid("imu.kind", format!("\"{other}\" is not a kind; use \"increments\" or \"rates\"")));
        }
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
        other => {
            return Err(
                c.invalid("imu.gap_policy", format!("\"{other}\" is not a policy; use \"refuse\" or \"split\""))
            );
        }
    };
    if raw.topic.is_some() && layout != Layout::Ros2 {
        return Err(c.invalid(
            "imu.topic",
            format!(
                "is read by the ros2 layout (MCAP) only, and this file's layout is {}: drop the key",
                layout.name()
            ),
        ));
    }
    let path = dir.join(&raw.file);
    let mut options = crate::io::ImuOptions::new(layout.clone());
    options.frame = frame.clone();
    options.topic = raw.topic.clone();
    let rate_hz = match raw.rate_hz {
        Some(r) => {
            let r = c.range("imu.rate_hz", r, "Hz", 1.0, 100_000.0, "")?;
            // A declared rate the stamps contradict would integrate every increment (or hold every
            // rate) over the wrong interval: refused here, before anything is derived from it. A
            // file that cannot be opened says why when a command reads it.
            if let Ok(reader) = crate::io::ImuReader::open(&path, &options)
                && let Some(why) = reader.rate_disagreement(r)
            {
                return Err(c.invalid("imu.rate_hz", why));
            }
            r
        }
        None => {
            // What the stamps say (the median of the first intervals).
            let dt = crate::io::ImuReader::open(&path, &options)
                .map_err(|e| {
                    c.invalid("imu.rate_hz", format!("absent, and the rate cannot be read from the stamps: {e}"))
                })?
                .measured_dt_s();
            let Some(dt) = dt else {
                return Err(c.invalid("imu.rate_hz", "absent, and the file has too few samples to measure it"));
            };
            c.range("imu.rate_hz (from the time stamps)", 1.0 / dt, "Hz", 1.0, 100_000.0, "")?
        }
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
    let turntable = raw.turntable.clone().unwrap_or_else(RawTurntable::strapdown);
    let (chain, stated) = validate::turntable(c, &turntable)?;
    let (compensation, resolved_comp) =
        validate::validate_compensation(c, &raw.compensation, &turntable, &chain, &stated)?;
    // Without `[navigation]` the INS integrates the attitude only, as the scenario it describes
    // does in the loop (a replay of an exported scenario reproduces its run); the replay says so.
    let ins =
        instruments::validate_ins(c, Some(&raw.imu.clone().unwrap_or_default()), raw.navigation.as_ref(), rate_hz)?
            .unwrap_or_else(|| InsParams::ideal(rate_hz, crate::ins::coning::Algorithm::TwoSampleP1));
    // The calibration allows for the INS error the [imu] section states (a datasheet's), if any.
    let calibration = instruments::validate_calibration(
        c,
        &raw.calibration.clone().unwrap_or_default(),
        &stated,
        raw.imu.is_some().then_some(&ins),
    )?;
    // A log's motion is not known before it is read: the defaults of a table turning at 10°/s
    // (10 Hz series and scene) unless [recording] says otherwise.
    let recording = validate::recording(
        c,
        &raw.recording,
        rate_hz,
        validate::Bandwidth { shaft_deg_per_s: 10.0, motion_hz: 0.0, duration_s: 3600.0 },
        0.0,
    )?;
    let mut resolved = raw.clone();
    resolved.compensation = resolved_comp;
    let resolved_toml = toml::to_string_pretty(&resolved).unwrap_or_else(|e| format!("# could not serialise: {e}"));
    Ok(TableDescription {
        site,
        chain,
        stated,
        compensation,
        ins,
        calibration,
        recording,
        resolved_toml,
        strapdown: raw.turntable.is_none(),
        navigation_absent: raw.navigation.is_none(),
    })
}

impl LogSet {
    /// The log as a scenario for the recorder: its table at rest, its IMU rate, `duration_s` long
    /// (the recording's playback speed), the table description as its configuration.
    pub fn recording_params(&self, duration_s: f64) -> Result<super::Params, ConfigError> {
        use super::raw::{RawLive, RawScenario, RawScheme, RawSimulation, RawVehicle};
        let t = &self.raw_table;
        let raw = super::RawConfig {
            scenario: RawScenario {
                name: self.name.clone(),
                title: if self.dir == Path::new(".") {
                    format!("replay of {}", self.imu.path.display())
                } else {
                    format!("replay of the log set {}", self.dir.display())
                },
                description: self.description.clone(),
                seed: self.seed.unwrap_or(0),
            },
            simulation: RawSimulation { duration_s: duration_s.max(1.0 / self.imu.rate_hz), step_hz: self.imu.rate_hz },
            recording: t.recording.clone(),
            site: t.site.clone(),
            vehicle: RawVehicle::default(),
            turntable: t.turntable.clone().unwrap_or_else(RawTurntable::strapdown),
            scheme: RawScheme {
                kind: "static".into(),
                rate: Vec::new(),
                initial_dwell_s: None,
                repeat: None,
                step: Vec::new(),
            },
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

#[cfg(test)]
mod tests;
