//! Scenario configuration: the TOML a user writes (user units, every key documented in `assets/`),
//! parsed strictly, validated once, and converted once into SI [`Params`].
//!
//! Every error names the key, the value and the unit (and the allowed range where there is one).

use std::collections::BTreeMap;
use std::path::Path;

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use crate::euler::Attitude;
use crate::gimbal::{AxisErrors, AxisGeometry, Chain, TableErrors};
use crate::motion::{AngleKind, Ramp, VehicleMotion, Wobble};
use crate::scheme::{IndexedStep, Scheme};
use crate::units::{RAD_PER_ARCSEC, RAD_PER_DEG};

/// A configuration problem a user can fix. Displayed as one line naming key, value and unit.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    /// The file could not be read.
    #[error("cannot read config file {path}: {source}")]
    Read {
        /// The path as given.
        path: String,
        /// The I/O error.
        source: std::io::Error,
    },
    /// TOML syntax, an unknown key or a wrong type (the toml crate's message shows the line).
    #[error("{origin}: {message}")]
    Parse {
        /// The file or scenario name.
        origin: String,
        /// toml's message, with the offending line and key.
        message: String,
    },
    /// A number that is not finite (nan, inf).
    #[error("{origin}: `{key}` = {value} {unit} is not a finite number")]
    NotFinite {
        /// The file or scenario name.
        origin: String,
        /// Dotted key path.
        key: String,
        /// The value as read.
        value: f64,
        /// The unit of the key.
        unit: &'static str,
    },
    /// A number outside its allowed range.
    #[error("{origin}: `{key}` = {value} {unit} is out of range: {range}")]
    OutOfRange {
        /// The file or scenario name.
        origin: String,
        /// Dotted key path.
        key: String,
        /// The value as read.
        value: f64,
        /// The unit of the key.
        unit: &'static str,
        /// The allowed range and a hint.
        range: String,
    },
    /// Any other inconsistency (duplicate axis names, an unknown axis referenced, ...).
    #[error("{origin}: `{key}`: {message}")]
    Invalid {
        /// The file or scenario name.
        origin: String,
        /// Dotted key path.
        key: String,
        /// What is wrong and how to fix it.
        message: String,
    },
}

// ---------------------------------------------------------------------------------------------
// The TOML as written (user units). Defaults live here, in one place, and in assets/ comments.
// ---------------------------------------------------------------------------------------------

/// The whole scenario file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawConfig {
    /// What the scenario is.
    pub scenario: RawScenario,
    /// Time span and step.
    #[serde(default)]
    pub simulation: RawSimulation,
    /// Output rates and drawing.
    #[serde(default)]
    pub recording: RawRecording,
    /// Where on Earth.
    #[serde(default)]
    pub site: RawSite,
    /// Vehicle attitude profile.
    #[serde(default)]
    pub vehicle: RawVehicle,
    /// The gimbal chain and its true errors.
    pub turntable: RawTurntable,
    /// How the gimbals move.
    pub scheme: RawScheme,
    /// Parameters the compensated demodulation assumes (each defaults to the true value).
    #[serde(default)]
    pub compensation: RawCompensation,
    /// Live mode only.
    #[serde(default)]
    pub live: RawLive,
    /// A simulated IMU and strapdown INS in the loop (absent: the IMU attitude is exact).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub imu: Option<RawImu>,
    /// Navigation of velocity and position (needs `[imu]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub navigation: Option<RawNavigation>,
    /// Static calibration of the swing cones and non-orthogonality (`rinscope calibrate`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub calibration: Option<RawCalibration>,
    /// Position fixes and resets (`rinscope reset`, needs `[navigation]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub position_fix: Option<RawPositionFix>,
}

/// `[calibration]`: the static Kalman filter and least-squares fit of `rinscope calibrate`
/// (docs/calibration.md). Everything the calibration does not estimate (installation, IMU mount,
/// encoder offset/scale/delay) is taken as known from `[compensation]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawCalibration {
    /// 1σ of each measured attitude-error component, arcsec (default: the encoders' noise, at least 1″).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub measurement_sigma_arcsec: Option<f64>,
    /// Prior 1σ of each swing component α·cos φ, α·sin φ, arcsec (prior mean 0).
    #[serde(default = "default_prior_swing")]
    pub prior_swing_sigma_arcsec: f64,
    /// Prior mean of each non-orthogonality, arcsec (an independent measurement, if there is one).
    #[serde(default)]
    pub prior_non_orthogonality_arcsec: f64,
    /// Its 1σ, arcsec.
    #[serde(default = "default_prior_eta")]
    pub prior_non_orthogonality_sigma_arcsec: f64,
    /// Slow errors of the attitude reference estimated alongside: "none", "offset" or "offset+drift".
    #[serde(default = "default_nuisance")]
    pub nuisance: String,
    /// Rate of the state/σ snapshots in the recording, Hz.
    #[serde(default = "default_calib_record_hz")]
    pub record_hz: f64,
    /// `rinscope montecarlo`: the distributions the true parameters are drawn from.
    #[serde(default)]
    pub montecarlo: RawMonteCarlo,
}

impl Default for RawCalibration {
    fn default() -> Self {
        Self {
            measurement_sigma_arcsec: None,
            prior_swing_sigma_arcsec: default_prior_swing(),
            prior_non_orthogonality_arcsec: 0.0,
            prior_non_orthogonality_sigma_arcsec: default_prior_eta(),
            nuisance: default_nuisance(),
            record_hz: default_calib_record_hz(),
            montecarlo: RawMonteCarlo::default(),
        }
    }
}

fn default_prior_swing() -> f64 {
    3600.0
}
fn default_prior_eta() -> f64 {
    60.0
}
fn default_nuisance() -> String {
    "offset+drift".into()
}
fn default_calib_record_hz() -> f64 {
    10.0
}

/// `[calibration.montecarlo]`: uniform distributions `[low, high]` of the true parameters (every
/// axis alike), and the number of runs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RawMonteCarlo {
    /// Runs.
    pub runs: u32,
    /// Swing half-angle α, arcsec.
    pub swing_half_angle_arcsec: [f64; 2],
    /// Swing phase φ, deg.
    pub swing_phase_deg: [f64; 2],
    /// Non-orthogonality η, arcsec.
    pub non_orthogonality_arcsec: [f64; 2],
    /// 1σ of an independent measurement of η given to the calibration as its prior, arcsec
    /// (absent: the prior is the distribution itself, i.e. nothing is known beyond its range).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub non_orthogonality_measured_sigma_arcsec: Option<f64>,
}

impl Default for RawMonteCarlo {
    /// Seed 000 §6.1: "swaying angle S(−10°, +10°)", "phase A(−1°, +1°)", "non-orthogonal angle
    /// Q(−20″, +20″)". Its Table 2 uses α of 5′ and 10′, so the printed "10°" is read as 10′, and a
    /// half-angle is taken in [0, 10′] (a negative half-angle is the same cone with φ + 180°).
    fn default() -> Self {
        Self {
            runs: 500,
            swing_half_angle_arcsec: [0.0, 600.0],
            swing_phase_deg: [-1.0, 1.0],
            non_orthogonality_arcsec: [-20.0, 20.0],
            non_orthogonality_measured_sigma_arcsec: None,
        }
    }
}

/// `[position_fix]`: position fixes during a navigation run (seed 003 §4).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawPositionFix {
    /// Times of the fixes, hours; `rinscope reset` uses the first two (seed 003: 17 and 21).
    pub at_h: Vec<f64>,
}

/// A per-axis value: a number is a 1σ drawn per axis with the seed, an array fixes the three values.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum RawSpec {
    /// 1σ.
    Sigma(f64),
    /// Per axis.
    Fixed([f64; 3]),
}

/// `[imu]`
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawImu {
    /// Starting values of the sensor errors: "none", "jiang2017-table1", "zheng2016", "li2014-table4".
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub preset: Option<String>,
    /// Attitude algorithm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub algorithm: Option<String>,
    /// Run every algorithm on the same IMU stream.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub compare: Option<bool>,
    /// IMU samples summed per algorithm sample, after the FIR.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub decimation: Option<u32>,
    /// "seed001", "none", or the taps.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fir: Option<RawFir>,
    /// Model the navigation computer's zero-order hold as a T/2 output delay.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub zero_order_hold: Option<bool>,
    /// Δt of seed 001's synchronisation: outputs are compared with the truth Δt earlier, ms.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub output_compensation_ms: Option<f64>,
    /// Raw and filtered gyro signals are recorded for this long, s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub signal_window_s: Option<f64>,
    /// Gyro errors.
    #[serde(default)]
    pub gyro: RawGyro,
    /// Accelerometer errors.
    #[serde(default)]
    pub accel: RawAccel,
    /// Ring-laser-gyro dither.
    #[serde(default)]
    pub dither: RawDither,
}

/// `[imu] fir`
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum RawFir {
    /// A named filter.
    Named(String),
    /// Taps.
    Taps(Vec<f64>),
}

/// `[imu.gyro]`
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawGyro {
    /// deg/h
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bias_deg_per_h: Option<RawSpec>,
    /// ppm
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale_ppm: Option<RawSpec>,
    /// arcsec (1σ of each small angle)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub misalignment_arcsec: Option<f64>,
    /// deg/√h
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub arw_deg_per_sqrt_h: Option<f64>,
    /// deg/h (1σ of a Gauss-Markov bias)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bias_instability_deg_per_h: Option<f64>,
    /// s
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub correlation_time_s: Option<f64>,
    /// deg/h per g
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub g_sensitivity_deg_per_h_per_g: Option<f64>,
}

/// `[imu.accel]`
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawAccel {
    /// µg
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bias_ug: Option<RawSpec>,
    /// ppm
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale_ppm: Option<RawSpec>,
    /// arcsec
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub misalignment_arcsec: Option<f64>,
    /// µg/√Hz
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vrw_ug_per_sqrt_hz: Option<f64>,
    /// µg (1σ of a Gauss-Markov bias)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bias_instability_ug: Option<f64>,
    /// s
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub correlation_time_s: Option<f64>,
}

/// `[imu.dither]`
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawDither {
    /// Hz, x/y/z gyro.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frequencies_hz: Option<[f64; 3]>,
    /// arcsec, x/y/z gyro.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub amplitudes_arcsec: Option<[f64; 3]>,
    /// Fraction sensed by the other gyros.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coupling: Option<f64>,
}

/// `[navigation]`
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawNavigation {
    /// "held" or "free".
    #[serde(default = "default_vertical")]
    pub vertical: String,
    /// Horizontal velocity damping toward zero velocity (seed 003).
    #[serde(default)]
    pub velocity_damping: bool,
    /// Alignment error (east tilt, north tilt, heading), arcmin.
    #[serde(default)]
    pub initial_attitude_error_arcmin: [f64; 3],
}

fn default_vertical() -> String {
    "held".into()
}

/// `[live]`: read by `rinscope live` only.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RawLive {
    /// Simulated seconds per wall-clock second.
    pub speed: f64,
}

impl Default for RawLive {
    fn default() -> Self {
        Self { speed: 1.0 }
    }
}

/// `[scenario]`
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawScenario {
    /// Identifier, also the recording's file name.
    pub name: String,
    /// One line shown by `rinscope scenarios`.
    pub title: String,
    /// Markdown shown beside the scene in the viewer.
    #[serde(default)]
    pub description: String,
    /// Seed of every random draw; stored in the recording.
    #[serde(default)]
    pub seed: u64,
}

/// `[simulation]`
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RawSimulation {
    /// Simulated time, s.
    pub duration_s: f64,
    /// Simulation (IMU) rate, Hz.
    pub step_hz: f64,
}

impl Default for RawSimulation {
    fn default() -> Self {
        Self { duration_s: 360.0, step_hz: 200.0 }
    }
}

/// `[recording]`
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RawRecording {
    /// Time-series output rate, Hz of simulated time.
    pub series_hz: f64,
    /// 3D scene output rate, Hz of simulated time.
    pub scene_hz: f64,
    /// Factor applied to every error angle when drawing the 3D scene.
    pub exaggeration: f64,
}

impl Default for RawRecording {
    fn default() -> Self {
        Self { series_hz: 100.0, scene_hz: 25.0, exaggeration: 60.0 }
    }
}

/// `[site]`
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RawSite {
    /// Geodetic latitude, deg.
    pub latitude_deg: f64,
    /// Longitude, deg.
    pub longitude_deg: f64,
    /// Height above the ellipsoid, m.
    pub height_m: f64,
}

impl Default for RawSite {
    fn default() -> Self {
        Self { latitude_deg: 0.0, longitude_deg: 0.0, height_m: 0.0 }
    }
}

/// `[vehicle]`
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RawVehicle {
    /// Initial pitch, deg.
    pub pitch_deg: f64,
    /// Initial roll, deg.
    pub roll_deg: f64,
    /// Initial heading (clockwise from North), deg.
    pub heading_deg: f64,
    /// Scripted ramps of one Euler angle to a target.
    pub ramp: Vec<RawRamp>,
    /// Sinusoidal wobble of one Euler angle.
    pub wobble: Vec<RawWobble>,
    /// Pure coning of the body about its z axis: half-angle, deg (0: none).
    pub coning_half_angle_deg: f64,
    /// Pure coning frequency, Hz.
    pub coning_frequency_hz: f64,
}

/// `[[vehicle.ramp]]`
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawRamp {
    /// Which Euler angle: "pitch", "roll" or "heading".
    pub angle: String,
    /// Start time, s.
    pub start_s: f64,
    /// Target value, deg.
    pub target_deg: f64,
    /// Rate magnitude, deg/s.
    pub rate_deg_per_s: f64,
}

/// `[[vehicle.wobble]]`
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawWobble {
    /// Which Euler angle: "pitch", "roll" or "heading".
    pub angle: String,
    /// Amplitude, deg.
    pub amplitude_deg: f64,
    /// Frequency, Hz.
    pub frequency_hz: f64,
    /// Phase at t = 0, deg.
    #[serde(default)]
    pub phase_deg: f64,
}

/// `[turntable]`
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawTurntable {
    /// Installation error of the table base on the body: rotation about body x, arcsec.
    #[serde(default)]
    pub installation_x_arcsec: f64,
    /// Installation error about body y, arcsec.
    #[serde(default)]
    pub installation_y_arcsec: f64,
    /// Installation error about body z, arcsec.
    #[serde(default)]
    pub installation_z_arcsec: f64,
    /// IMU mounting error on the last gimbal: rotation about its x, arcsec.
    #[serde(default)]
    pub imu_mount_x_arcsec: f64,
    /// IMU mounting error about y, arcsec.
    #[serde(default)]
    pub imu_mount_y_arcsec: f64,
    /// IMU mounting error about z, arcsec.
    #[serde(default)]
    pub imu_mount_z_arcsec: f64,
    /// The gimbal axes from the body outward (outer first).
    pub axis: Vec<RawAxis>,
}

/// `[[turntable.axis]]`
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawAxis {
    /// Name used by the scheme, the compensation and the recording ("outer", "inner", ...).
    pub name: String,
    /// Nominal rotation axis in the parent frame: "x", "y" or "z".
    pub axis: String,
    /// Gimbal angle at t = 0, deg.
    #[serde(default)]
    pub initial_angle_deg: f64,
    /// Swing-cone half-angle, arcsec.
    #[serde(default)]
    pub swing_half_angle_arcsec: f64,
    /// Swing-cone initial phase, deg.
    #[serde(default)]
    pub swing_phase_deg: f64,
    /// Tilt of this axis toward the previous axis (away from perpendicular), arcsec.
    #[serde(default)]
    pub non_orthogonality_arcsec: f64,
    /// Encoder constant offset, arcsec.
    #[serde(default)]
    pub encoder_offset_arcsec: f64,
    /// Encoder scale-factor error, ppm.
    #[serde(default)]
    pub encoder_scale_ppm: f64,
    /// Encoder latch time minus IMU sample time, ms (positive: the angle is older than the IMU data).
    #[serde(default)]
    pub encoder_delay_ms: f64,
    /// Encoder white noise, 1σ per reading, arcsec.
    #[serde(default)]
    pub encoder_noise_arcsec: f64,
}

/// `[scheme]`: one of "static", "continuous", "indexed".
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawScheme {
    /// "static", "continuous" or "indexed".
    pub kind: String,
    /// Continuous: one rate per axis.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub rate: Vec<RawRate>,
    /// Indexed: dwell at the start, s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial_dwell_s: Option<f64>,
    /// Indexed: repeat the sequence until the end of the run.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub repeat: Option<bool>,
    /// Indexed: the sequence of moves.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub step: Vec<RawStep>,
}

/// `[[scheme.rate]]`
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawRate {
    /// Axis name.
    pub axis: String,
    /// Rotation rate, deg/s (sign = direction).
    pub rate_deg_per_s: f64,
}

/// `[[scheme.step]]`
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawStep {
    /// Axis name.
    pub axis: String,
    /// Rotation of this move, deg (sign = direction).
    pub angle_deg: f64,
    /// Cruise rate magnitude, deg/s.
    pub rate_deg_per_s: f64,
    /// Dwell after the move, s.
    #[serde(default)]
    pub dwell_s: f64,
    /// Angular acceleration magnitude, deg/s^2 (0: the rate steps instantly).
    #[serde(default)]
    pub accel_deg_per_s2: f64,
}

/// `[compensation]`: every key is optional and defaults to the true value of the same key.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawCompensation {
    /// false: the "compensated" demodulation uses the nominal table (compensation switched off).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub enabled: Option<bool>,
    /// See `turntable.installation_x_arcsec`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub installation_x_arcsec: Option<f64>,
    /// See `turntable.installation_y_arcsec`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub installation_y_arcsec: Option<f64>,
    /// See `turntable.installation_z_arcsec`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub installation_z_arcsec: Option<f64>,
    /// See `turntable.imu_mount_x_arcsec`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub imu_mount_x_arcsec: Option<f64>,
    /// See `turntable.imu_mount_y_arcsec`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub imu_mount_y_arcsec: Option<f64>,
    /// See `turntable.imu_mount_z_arcsec`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub imu_mount_z_arcsec: Option<f64>,
    /// Per axis, by name.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub axis: BTreeMap<String, RawAxisCompensation>,
}

/// `[compensation.axis.NAME]`
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawAxisCompensation {
    /// arcsec
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub swing_half_angle_arcsec: Option<f64>,
    /// deg
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub swing_phase_deg: Option<f64>,
    /// arcsec
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub non_orthogonality_arcsec: Option<f64>,
    /// arcsec
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub encoder_offset_arcsec: Option<f64>,
    /// ppm
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub encoder_scale_ppm: Option<f64>,
    /// ms
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub encoder_delay_ms: Option<f64>,
}

// ---------------------------------------------------------------------------------------------
// The validated, SI form.
// ---------------------------------------------------------------------------------------------

/// What the scenario is, for people.
#[derive(Debug, Clone)]
pub struct ScenarioMeta {
    /// Identifier.
    pub name: String,
    /// One line.
    pub title: String,
    /// Markdown.
    pub description: String,
    /// Seed of every random draw.
    pub seed: u64,
}

/// Output rates and drawing.
#[derive(Debug, Clone, Copy)]
pub struct RecordingParams {
    /// Time-series output rate, Hz.
    pub series_hz: f64,
    /// Scene output rate, Hz.
    pub scene_hz: f64,
    /// Drawing factor for error angles.
    pub exaggeration: f64,
}

/// Site on Earth.
#[derive(Debug, Clone, Copy)]
pub struct Site {
    /// Geodetic latitude, rad.
    pub latitude_rad: f64,
    /// Longitude, rad.
    pub longitude_rad: f64,
    /// Height, m.
    pub height_m: f64,
}

/// A validated scenario in SI units.
#[derive(Debug, Clone)]
pub struct Params {
    /// Name, title, description, seed.
    pub meta: ScenarioMeta,
    /// Simulated time, s.
    pub duration_s: f64,
    /// Simulation rate, Hz.
    pub step_hz: f64,
    /// Output rates and drawing.
    pub recording: RecordingParams,
    /// Site.
    pub site: Site,
    /// Vehicle attitude over time.
    pub vehicle: VehicleMotion,
    /// Nominal gimbal geometry.
    pub chain: Chain,
    /// True turntable errors.
    pub truth: TableErrors,
    /// Errors assumed by the compensated demodulation.
    pub compensation: TableErrors,
    /// Gimbal angles over time.
    pub scheme: Scheme,
    /// The configuration as resolved (defaults and compensation filled in), as TOML.
    pub resolved_toml: String,
    /// The same, as data.
    pub resolved: RawConfig,
    /// The configuration as written (defaults of optional keys not filled in): live mode describes
    /// reloads as its differences.
    pub written: RawConfig,
    /// `[live] speed`: simulated seconds per wall-clock second.
    pub live_speed: f64,
    /// The INS in the loop, if any.
    pub ins: Option<crate::ins::InsConfig>,
    /// `[calibration]` (its defaults when the section is absent).
    pub calibration: crate::calib::CalibConfig,
    /// Times of the position fixes, s (`[position_fix]`).
    pub position_fix_s: Vec<f64>,
}

impl Params {
    /// Number of simulation steps (samples at t = k / step_hz, k = 0..steps).
    #[must_use]
    pub fn steps(&self) -> u64 {
        // Validation bounds duration * rate, so the cast cannot overflow or go negative.
        (self.duration_s * self.step_hz).round() as u64 + 1
    }
}

/// Reads and validates a scenario file.
pub fn load_file(path: &Path) -> Result<Params, ConfigError> {
    let text = std::fs::read_to_string(path).map_err(|source| ConfigError::Read {
        path: path.display().to_string(),
        source,
    })?;
    parse(&text, &path.display().to_string())
}

/// Parses and validates scenario text; `origin` names the file or the embedded scenario in errors.
pub fn parse(text: &str, origin: &str) -> Result<Params, ConfigError> {
    let raw: RawConfig = toml::from_str(text).map_err(|e| ConfigError::Parse {
        origin: origin.to_owned(),
        message: e.to_string().trim_end().to_owned(),
    })?;
    validate(raw, origin)
}

/// A helper that knows the file name and checks numbers with their keys and units.
struct Checker<'a> {
    origin: &'a str,
}

impl Checker<'_> {
    fn finite(&self, key: &str, value: f64, unit: &'static str) -> Result<f64, ConfigError> {
        if value.is_finite() {
            Ok(value)
        } else {
            Err(ConfigError::NotFinite { origin: self.origin.to_owned(), key: key.to_owned(), value, unit })
        }
    }

    /// Checks `lo <= value <= hi` (and finiteness).
    fn range(&self, key: &str, value: f64, unit: &'static str, lo: f64, hi: f64, hint: &str) -> Result<f64, ConfigError> {
        self.finite(key, value, unit)?;
        if value < lo || value > hi {
            let mut range = format!("allowed {lo} ..= {hi} {unit}");
            if !hint.is_empty() {
                range.push_str(" (");
                range.push_str(hint);
                range.push(')');
            }
            return Err(ConfigError::OutOfRange { origin: self.origin.to_owned(), key: key.to_owned(), value, unit, range });
        }
        Ok(value)
    }

    /// Checks `lo < value <= hi`.
    fn positive(&self, key: &str, value: f64, unit: &'static str, hi: f64) -> Result<f64, ConfigError> {
        self.finite(key, value, unit)?;
        if value <= 0.0 || value > hi {
            return Err(ConfigError::OutOfRange {
                origin: self.origin.to_owned(),
                key: key.to_owned(),
                value,
                unit,
                range: format!("must be > 0 and <= {hi} {unit}"),
            });
        }
        Ok(value)
    }

    fn invalid(&self, key: &str, message: impl Into<String>) -> ConfigError {
        ConfigError::Invalid { origin: self.origin.to_owned(), key: key.to_owned(), message: message.into() }
    }
}

/// Largest error angle accepted anywhere, arcsec: 10 deg. Turntable errors are arcseconds to
/// arcminutes; a value this large is a typo (degrees typed into an arcsec key, say).
pub const MAX_ERROR_ANGLE_ARCSEC: f64 = 36_000.0;
const ERROR_HINT: &str = "turntable errors are arcsec to arcmin; over 10 deg is a typo";

fn angle_kind(c: &Checker<'_>, key: &str, s: &str) -> Result<AngleKind, ConfigError> {
    match s {
        "pitch" => Ok(AngleKind::Pitch),
        "roll" => Ok(AngleKind::Roll),
        "heading" => Ok(AngleKind::Heading),
        other => Err(c.invalid(key, format!("\"{other}\" is not an Euler angle; use \"pitch\", \"roll\" or \"heading\""))),
    }
}

fn validate(raw: RawConfig, origin: &str) -> Result<Params, ConfigError> {
    let c = Checker { origin };

    // [scenario]
    if raw.scenario.name.trim().is_empty()
        || !raw.scenario.name.chars().all(|ch| ch.is_ascii_alphanumeric() || ch == '-' || ch == '_')
    {
        return Err(c.invalid(
            "scenario.name",
            format!("\"{}\" must be non-empty and use only letters, digits, '-' and '_' (it names the recording file)", raw.scenario.name),
        ));
    }

    // [simulation]
    let step_hz = c.range("simulation.step_hz", raw.simulation.step_hz, "Hz", 1.0, 100_000.0, "")?;
    let duration_s = c.positive("simulation.duration_s", raw.simulation.duration_s, "s", 30.0 * 86_400.0)?;
    if duration_s * step_hz > 2.0e9 {
        return Err(c.invalid(
            "simulation.duration_s",
            format!("{duration_s} s at {step_hz} Hz is {:.3e} steps; at most 2e9 are supported", duration_s * step_hz),
        ));
    }

    // [recording]
    let series_hz = c.positive("recording.series_hz", raw.recording.series_hz, "Hz", step_hz)?;
    let scene_hz = c.positive("recording.scene_hz", raw.recording.scene_hz, "Hz", step_hz)?;
    let exaggeration = c.range("recording.exaggeration", raw.recording.exaggeration, "x", 1.0, 100_000.0, "")?;

    // [site]
    let site = Site {
        latitude_rad: c.range("site.latitude_deg", raw.site.latitude_deg, "deg", -90.0, 90.0, "")? * RAD_PER_DEG,
        longitude_rad: c.range("site.longitude_deg", raw.site.longitude_deg, "deg", -180.0, 360.0, "")? * RAD_PER_DEG,
        height_m: c.range("site.height_m", raw.site.height_m, "m", -1000.0, 100_000.0, "")?,
    };

    // [vehicle]
    let pitch_hint = "Euler angles are singular at +-90 deg pitch";
    let base = Attitude {
        pitch_rad: c.range("vehicle.pitch_deg", raw.vehicle.pitch_deg, "deg", -85.0, 85.0, pitch_hint)? * RAD_PER_DEG,
        roll_rad: c.range("vehicle.roll_deg", raw.vehicle.roll_deg, "deg", -180.0, 180.0, "")? * RAD_PER_DEG,
        heading_rad: c.range("vehicle.heading_deg", raw.vehicle.heading_deg, "deg", -360.0, 360.0, "")? * RAD_PER_DEG,
    };
    let mut ramps = Vec::new();
    for (i, r) in raw.vehicle.ramp.iter().enumerate() {
        let k = |f: &str| format!("vehicle.ramp[{i}].{f}");
        let kind = angle_kind(&c, &k("angle"), &r.angle)?;
        let (lo, hi, hint) = match kind {
            AngleKind::Pitch => (-85.0, 85.0, pitch_hint),
            AngleKind::Roll => (-180.0, 180.0, ""),
            AngleKind::Heading => (-3600.0, 3600.0, ""),
        };
        ramps.push(Ramp {
            angle: kind,
            start_s: c.range(&k("start_s"), r.start_s, "s", 0.0, duration_s, "within the run")?,
            target_rad: c.range(&k("target_deg"), r.target_deg, "deg", lo, hi, hint)? * RAD_PER_DEG,
            rate_rad_per_s: c.positive(&k("rate_deg_per_s"), r.rate_deg_per_s, "deg/s", 1000.0)? * RAD_PER_DEG,
        });
    }
    let mut wobbles = Vec::new();
    for (i, w) in raw.vehicle.wobble.iter().enumerate() {
        let k = |f: &str| format!("vehicle.wobble[{i}].{f}");
        wobbles.push(Wobble {
            angle: angle_kind(&c, &k("angle"), &w.angle)?,
            amplitude_rad: c.range(&k("amplitude_deg"), w.amplitude_deg, "deg", 0.0, 45.0, "")? * RAD_PER_DEG,
            omega_rad_per_s: c.range(&k("frequency_hz"), w.frequency_hz, "Hz", 0.0, 0.25 * step_hz, "at most a quarter of simulation.step_hz")?
                * std::f64::consts::TAU,
            phase_rad: c.finite(&k("phase_deg"), w.phase_deg, "deg")? * RAD_PER_DEG,
        });
    }
    let coning = crate::motion::Coning {
        half_angle_rad: c.range("vehicle.coning_half_angle_deg", raw.vehicle.coning_half_angle_deg, "deg", 0.0, 45.0, "")? * RAD_PER_DEG,
        omega_rad_per_s: c.range("vehicle.coning_frequency_hz", raw.vehicle.coning_frequency_hz, "Hz", 0.0, 0.25 * step_hz, "at most a quarter of simulation.step_hz")?
            * std::f64::consts::TAU,
    };
    let vehicle = VehicleMotion::new(base, ramps, wobbles).map_err(|m| c.invalid("vehicle.ramp", m))?.with_coning(coning);
    // Pitch must stay clear of the Euler singularity over the whole profile (ramps + wobble).
    let max_pitch = vehicle.max_abs_pitch_rad(duration_s);
    if max_pitch > 85.0 * RAD_PER_DEG {
        return Err(c.invalid(
            "vehicle",
            format!("the pitch profile reaches {:.2} deg; keep |pitch| <= 85 deg ({pitch_hint})", max_pitch / RAD_PER_DEG),
        ));
    }

    // [turntable]
    let t = &raw.turntable;
    if t.axis.is_empty() || t.axis.len() > 3 {
        return Err(c.invalid("turntable.axis", format!("{} axes given; a table has 1, 2 or 3", t.axis.len())));
    }
    let err_angle = |key: &str, v: f64| -> Result<f64, ConfigError> {
        Ok(c.range(key, v, "arcsec", -MAX_ERROR_ANGLE_ARCSEC, MAX_ERROR_ANGLE_ARCSEC, ERROR_HINT)? * RAD_PER_ARCSEC)
    };
    let mut geometry = Vec::new();
    let mut axis_errors = Vec::new();
    for (i, a) in t.axis.iter().enumerate() {
        let k = |f: &str| format!("turntable.axis[{i}] (\"{}\").{f}", a.name);
        if a.name.trim().is_empty() || geometry.iter().any(|g: &AxisGeometry| g.name == a.name) {
            return Err(c.invalid(&k("name"), format!("\"{}\" must be non-empty and unique", a.name)));
        }
        let dir = match a.axis.as_str() {
            "x" => Vector3::x(),
            "y" => Vector3::y(),
            "z" => Vector3::z(),
            other => return Err(c.invalid(&k("axis"), format!("\"{other}\" is not an axis; use \"x\", \"y\" or \"z\""))),
        };
        if let Some(prev) = geometry.last() {
            let prev: &AxisGeometry = prev;
            if prev.axis.dot(&dir).abs() > 0.5 {
                return Err(c.invalid(
                    &k("axis"),
                    format!("\"{}\" is parallel to the previous axis \"{}\"; consecutive gimbal axes must be perpendicular", a.axis, prev.name),
                ));
            }
        }
        let swing = c.range(&k("swing_half_angle_arcsec"), a.swing_half_angle_arcsec, "arcsec", 0.0, MAX_ERROR_ANGLE_ARCSEC, ERROR_HINT)?;
        if i == 0 && a.non_orthogonality_arcsec != 0.0 {
            return Err(c.invalid(
                &k("non_orthogonality_arcsec"),
                format!(
                    "{} arcsec given on the first axis; its tilt against the body is the installation error (turntable.installation_*_arcsec)",
                    a.non_orthogonality_arcsec
                ),
            ));
        }
        geometry.push(AxisGeometry::new(a.name.clone(), dir, c.finite(&k("initial_angle_deg"), a.initial_angle_deg, "deg")? * RAD_PER_DEG));
        axis_errors.push(AxisErrors {
            swing_half_angle_rad: swing * RAD_PER_ARCSEC,
            swing_phase_rad: c.range(&k("swing_phase_deg"), a.swing_phase_deg, "deg", -360.0, 360.0, "")? * RAD_PER_DEG,
            non_orthogonality_rad: err_angle(&k("non_orthogonality_arcsec"), a.non_orthogonality_arcsec)?,
            encoder_offset_rad: err_angle(&k("encoder_offset_arcsec"), a.encoder_offset_arcsec)?,
            encoder_scale: c.range(&k("encoder_scale_ppm"), a.encoder_scale_ppm, "ppm", -10_000.0, 10_000.0, "1% at most")? * 1e-6,
            encoder_delay_s: c.range(&k("encoder_delay_ms"), a.encoder_delay_ms, "ms", -1000.0, 1000.0, "")? * 1e-3,
            encoder_noise_rad: c.range(&k("encoder_noise_arcsec"), a.encoder_noise_arcsec, "arcsec", 0.0, 3600.0, "1σ per reading, 1° at most")? * RAD_PER_ARCSEC,
        });
    }
    let chain = Chain::new(geometry);
    let truth = TableErrors {
        installation_rad: Vector3::new(
            err_angle("turntable.installation_x_arcsec", t.installation_x_arcsec)?,
            err_angle("turntable.installation_y_arcsec", t.installation_y_arcsec)?,
            err_angle("turntable.installation_z_arcsec", t.installation_z_arcsec)?,
        ),
        imu_mount_rad: Vector3::new(
            err_angle("turntable.imu_mount_x_arcsec", t.imu_mount_x_arcsec)?,
            err_angle("turntable.imu_mount_y_arcsec", t.imu_mount_y_arcsec)?,
            err_angle("turntable.imu_mount_z_arcsec", t.imu_mount_z_arcsec)?,
        ),
        axes: axis_errors,
    };

    // [scheme]
    let scheme = validate_scheme(&c, &raw.scheme, &chain)?;

    // [compensation]
    let (compensation, resolved_comp) = validate_compensation(&c, &raw.compensation, &raw.turntable, &chain, &truth)?;

    let meta = ScenarioMeta {
        name: raw.scenario.name.clone(),
        title: raw.scenario.title.clone(),
        description: raw.scenario.description.clone(),
        seed: raw.scenario.seed,
    };
    let live_speed = c.range("live.speed", raw.live.speed, "x real time", 0.01, 10_000.0, "")?;
    let ins = match &raw.imu {
        None => {
            if raw.navigation.is_some() {
                return Err(c.invalid("navigation", "needs an [imu] section (navigation runs on the simulated IMU)"));
            }
            None
        }
        Some(imu) => Some(validate_imu(&c, imu, raw.navigation.as_ref(), step_hz)?),
    };
    let calibration = validate_calibration(&c, &raw.calibration.clone().unwrap_or_default(), &truth)?;
    let mut position_fix_s = Vec::new();
    if let Some(fix) = &raw.position_fix {
        if raw.navigation.is_none() {
            return Err(c.invalid("position_fix", "needs a [navigation] section (a position fix resets the navigation)"));
        }
        for (i, h) in fix.at_h.iter().enumerate() {
            let key = format!("position_fix.at_h[{i}]");
            let t = c.positive(&key, *h, "h", duration_s / 3600.0)? * 3600.0;
            if position_fix_s.last().is_some_and(|prev| t <= *prev) {
                return Err(c.invalid(&key, format!("{h} h is not after the previous fix; list the fixes in increasing time")));
            }
            position_fix_s.push(t);
        }
    }
    let written = raw.clone();
    let mut resolved = raw;
    resolved.compensation = resolved_comp;
    let resolved_toml = toml::to_string_pretty(&resolved).unwrap_or_else(|e| format!("# could not serialise: {e}"));

    Ok(Params {
        meta,
        duration_s,
        step_hz,
        recording: RecordingParams { series_hz, scene_hz, exaggeration },
        site,
        vehicle,
        chain,
        truth,
        compensation,
        scheme,
        resolved_toml,
        resolved,
        written,
        live_speed,
        ins,
        calibration,
        position_fix_s,
    })
}

/// Every leaf of a resolved config as `dotted.key -> value text` (arrays of tables indexed `[i]`),
/// for describing what changed between two versions.
#[must_use]
pub fn flatten(raw: &RawConfig) -> BTreeMap<String, String> {
    fn walk(prefix: &str, v: &toml::Value, out: &mut BTreeMap<String, String>) {
        match v {
            toml::Value::Table(t) => {
                for (k, x) in t {
                    let key = if prefix.is_empty() { k.clone() } else { format!("{prefix}.{k}") };
                    walk(&key, x, out);
                }
            }
            toml::Value::Array(a) if a.iter().all(toml::Value::is_table) && !a.is_empty() => {
                for (i, x) in a.iter().enumerate() {
                    walk(&format!("{prefix}[{i}]"), x, out);
                }
            }
            other => {
                out.insert(prefix.to_owned(), other.to_string());
            }
        }
    }
    let mut out = BTreeMap::new();
    if let Ok(v) = toml::Value::try_from(raw) {
        walk("", &v, &mut out);
    }
    out
}

fn spec(c: &Checker<'_>, key: &str, v: RawSpec, unit: &'static str, max: f64, to_si: f64) -> Result<crate::ins::sensor::Spec, ConfigError> {
    use crate::ins::sensor::Spec;
    Ok(match v {
        RawSpec::Sigma(s) => Spec::Sigma(c.range(key, s, unit, 0.0, max, "a number is the 1σ of a per-axis draw")? * to_si),
        RawSpec::Fixed(a) => {
            let mut out = [0.0; 3];
            for (i, x) in a.iter().enumerate() {
                out[i] = c.range(&format!("{key}[{i}]"), *x, unit, -max, max, "")? * to_si;
            }
            Spec::Fixed(out)
        }
    })
}

fn validate_imu(c: &Checker<'_>, raw: &RawImu, nav: Option<&RawNavigation>, step_hz: f64) -> Result<crate::ins::InsConfig, ConfigError> {
    use crate::ins::coning::Algorithm;
    use crate::ins::nav::{NavOptions, Vertical};
    use crate::ins::preset;
    const DEG_PER_H: f64 = RAD_PER_DEG / 3600.0;
    const UG: f64 = 9.806_65e-6;
    let preset_name = raw.preset.as_deref().unwrap_or("none");
    let mut cfg = preset(preset_name).ok_or_else(|| {
        c.invalid("imu.preset", format!("\"{preset_name}\" is not a preset; use \"none\", \"jiang2017-table1\", \"zheng2016\" or \"li2014-table4\""))
    })?;
    cfg.rate_hz = step_hz;
    if let Some(a) = &raw.algorithm {
        cfg.algorithm = Algorithm::from_name(a).ok_or_else(|| {
            let names: Vec<&str> = Algorithm::ALL.iter().map(|a| a.name()).collect();
            c.invalid("imu.algorithm", format!("\"{a}\" is not an algorithm; use one of {names:?}"))
        })?;
    }
    if let Some(x) = raw.compare {
        cfg.compare = x;
    }
    if let Some(d) = raw.decimation {
        cfg.decimation = c.range("imu.decimation", f64::from(d), "samples", 1.0, 1000.0, "")? as usize;
    }
    match &raw.fir {
        None => {}
        Some(RawFir::Named(n)) if n == "seed001" => cfg.fir_taps = crate::ins::fir::SEED001_TAPS.to_vec(),
        Some(RawFir::Named(n)) if n == "none" => cfg.fir_taps = vec![1.0],
        Some(RawFir::Named(n)) => return Err(c.invalid("imu.fir", format!("\"{n}\" is not a filter; use \"seed001\", \"none\" or a list of taps"))),
        Some(RawFir::Taps(t)) => {
            if t.is_empty() || t.len() > 1001 {
                return Err(c.invalid("imu.fir", format!("{} taps given; 1 to 1001 are supported", t.len())));
            }
            for (i, x) in t.iter().enumerate() {
                c.finite(&format!("imu.fir[{i}]"), *x, "")?;
            }
            if t.iter().sum::<f64>().abs() < 1e-6 {
                return Err(c.invalid("imu.fir", "the taps sum to zero: the filter would remove the signal itself"));
            }
            cfg.fir_taps = t.clone();
        }
    }
    if let Some(z) = raw.zero_order_hold {
        cfg.zero_order_hold = z;
    }
    if let Some(ms) = raw.output_compensation_ms {
        cfg.output_compensation_s = c.range("imu.output_compensation_ms", ms, "ms", -1000.0, 1000.0, "")? * 1e-3;
    }
    if let Some(w) = raw.signal_window_s {
        cfg.signal_window_s = c.range("imu.signal_window_s", w, "s", 0.0, 60.0, "")?;
    }
    let g = &raw.gyro;
    let e = &mut cfg.errors;
    if let Some(v) = g.bias_deg_per_h {
        e.gyro.bias = spec(c, "imu.gyro.bias_deg_per_h", v, "deg/h", 3600.0, DEG_PER_H)?;
    }
    if let Some(v) = g.scale_ppm {
        e.gyro.scale = spec(c, "imu.gyro.scale_ppm", v, "ppm", 1e5, 1e-6)?;
    }
    if let Some(v) = g.misalignment_arcsec {
        e.gyro.misalignment_rad = c.range("imu.gyro.misalignment_arcsec", v, "arcsec", 0.0, MAX_ERROR_ANGLE_ARCSEC, ERROR_HINT)? * RAD_PER_ARCSEC;
    }
    if let Some(v) = g.arw_deg_per_sqrt_h {
        e.gyro.white = c.range("imu.gyro.arw_deg_per_sqrt_h", v, "deg/√h", 0.0, 100.0, "")? * RAD_PER_DEG / 60.0;
    }
    if let Some(v) = g.bias_instability_deg_per_h {
        e.gyro.instability = c.range("imu.gyro.bias_instability_deg_per_h", v, "deg/h", 0.0, 3600.0, "")? * DEG_PER_H;
    }
    if let Some(v) = g.correlation_time_s {
        e.gyro.correlation_s = c.positive("imu.gyro.correlation_time_s", v, "s", 1e9)?;
    }
    if let Some(v) = g.g_sensitivity_deg_per_h_per_g {
        e.g_sensitivity = c.range("imu.gyro.g_sensitivity_deg_per_h_per_g", v, "deg/h/g", -3600.0, 3600.0, "")? * DEG_PER_H / 9.806_65;
    }
    let a = &raw.accel;
    if let Some(v) = a.bias_ug {
        e.accel.bias = spec(c, "imu.accel.bias_ug", v, "µg", 1e5, UG)?;
    }
    if let Some(v) = a.scale_ppm {
        e.accel.scale = spec(c, "imu.accel.scale_ppm", v, "ppm", 1e5, 1e-6)?;
    }
    if let Some(v) = a.misalignment_arcsec {
        e.accel.misalignment_rad = c.range("imu.accel.misalignment_arcsec", v, "arcsec", 0.0, MAX_ERROR_ANGLE_ARCSEC, ERROR_HINT)? * RAD_PER_ARCSEC;
    }
    if let Some(v) = a.vrw_ug_per_sqrt_hz {
        e.accel.white = c.range("imu.accel.vrw_ug_per_sqrt_hz", v, "µg/√Hz", 0.0, 1e5, "")? * UG;
    }
    if let Some(v) = a.bias_instability_ug {
        e.accel.instability = c.range("imu.accel.bias_instability_ug", v, "µg", 0.0, 1e5, "")? * UG;
    }
    if let Some(v) = a.correlation_time_s {
        e.accel.correlation_s = c.positive("imu.accel.correlation_time_s", v, "s", 1e9)?;
    }
    let d = &raw.dither;
    if let Some(f) = d.frequencies_hz {
        for (i, x) in f.iter().enumerate() {
            e.dither.frequencies_hz[i] = c.range(&format!("imu.dither.frequencies_hz[{i}]"), *x, "Hz", 0.0, 0.5 * step_hz, "below half the IMU rate (simulation.step_hz)")?;
        }
    }
    if let Some(amp) = d.amplitudes_arcsec {
        for (i, x) in amp.iter().enumerate() {
            e.dither.amplitudes_rad[i] = c.range(&format!("imu.dither.amplitudes_arcsec[{i}]"), *x, "arcsec", 0.0, MAX_ERROR_ANGLE_ARCSEC, "")? * RAD_PER_ARCSEC;
        }
    }
    if let Some(k) = d.coupling {
        e.dither.coupling = c.range("imu.dither.coupling", k, "", 0.0, 1.0, "")?;
    }
    if let Some(n) = nav {
        let vertical = match n.vertical.as_str() {
            "held" => Vertical::Held,
            "free" => Vertical::Free,
            other => return Err(c.invalid("navigation.vertical", format!("\"{other}\" is not a mode; use \"held\" or \"free\""))),
        };
        let mut err = [0.0; 3];
        for (i, x) in n.initial_attitude_error_arcmin.iter().enumerate() {
            err[i] = c.range(&format!("navigation.initial_attitude_error_arcmin[{i}]"), *x, "arcmin", -600.0, 600.0, "")? * RAD_PER_DEG / 60.0;
        }
        cfg.navigation = Some(NavOptions { vertical, damping_per_s: if n.velocity_damping { crate::ins::nav::schuler_rate() } else { 0.0 } });
        cfg.initial_error_rad = Vector3::from(err);
    }
    Ok(cfg)
}

fn validate_calibration(c: &Checker<'_>, cal: &RawCalibration, truth: &TableErrors) -> Result<crate::calib::CalibConfig, ConfigError> {
    use crate::calib::{CalibConfig, MonteCarloConfig, Nuisance};
    let noise_rms = (truth.axes.iter().map(|a| a.encoder_noise_rad.powi(2)).sum::<f64>() / truth.axes.len().max(1) as f64).sqrt();
    let measurement_sigma_rad = match cal.measurement_sigma_arcsec {
        Some(v) => c.positive("calibration.measurement_sigma_arcsec", v, "arcsec", MAX_ERROR_ANGLE_ARCSEC)? * RAD_PER_ARCSEC,
        None => noise_rms.max(RAD_PER_ARCSEC),
    };
    let nuisance = match cal.nuisance.as_str() {
        "none" => Nuisance::None,
        "offset" => Nuisance::Offset,
        "offset+drift" => Nuisance::OffsetDrift,
        other => return Err(c.invalid("calibration.nuisance", format!("\"{other}\" is not a choice; use \"none\", \"offset\" or \"offset+drift\""))),
    };
    let mc = &cal.montecarlo;
    let pair = |key: &str, v: [f64; 2], unit: &'static str, lo: f64, hi: f64| -> Result<[f64; 2], ConfigError> {
        let a = c.range(&format!("calibration.montecarlo.{key}[0]"), v[0], unit, lo, hi, "")?;
        let b = c.range(&format!("calibration.montecarlo.{key}[1]"), v[1], unit, lo, hi, "")?;
        if b < a {
            return Err(c.invalid(&format!("calibration.montecarlo.{key}"), format!("[{a}, {b}]: the upper bound is below the lower one")));
        }
        Ok([a, b])
    };
    let montecarlo = MonteCarloConfig {
        runs: mc.runs,
        swing_half_angle_rad: pair("swing_half_angle_arcsec", mc.swing_half_angle_arcsec, "arcsec", 0.0, MAX_ERROR_ANGLE_ARCSEC)?.map(|x| x * RAD_PER_ARCSEC),
        swing_phase_rad: pair("swing_phase_deg", mc.swing_phase_deg, "deg", -360.0, 360.0)?.map(|x| x * RAD_PER_DEG),
        non_orthogonality_rad: pair("non_orthogonality_arcsec", mc.non_orthogonality_arcsec, "arcsec", -MAX_ERROR_ANGLE_ARCSEC, MAX_ERROR_ANGLE_ARCSEC)?.map(|x| x * RAD_PER_ARCSEC),
        eta_measured_sigma_rad: mc
            .non_orthogonality_measured_sigma_arcsec
            .map(|v| c.positive("calibration.montecarlo.non_orthogonality_measured_sigma_arcsec", v, "arcsec", MAX_ERROR_ANGLE_ARCSEC))
            .transpose()?
            .map(|v| v * RAD_PER_ARCSEC),
    };
    Ok(CalibConfig {
        measurement_sigma_rad,
        prior_swing_sigma_rad: c.positive("calibration.prior_swing_sigma_arcsec", cal.prior_swing_sigma_arcsec, "arcsec", MAX_ERROR_ANGLE_ARCSEC)? * RAD_PER_ARCSEC,
        prior_eta_rad: c.range("calibration.prior_non_orthogonality_arcsec", cal.prior_non_orthogonality_arcsec, "arcsec", -MAX_ERROR_ANGLE_ARCSEC, MAX_ERROR_ANGLE_ARCSEC, ERROR_HINT)?
            * RAD_PER_ARCSEC,
        prior_eta_sigma_rad: c.positive("calibration.prior_non_orthogonality_sigma_arcsec", cal.prior_non_orthogonality_sigma_arcsec, "arcsec", MAX_ERROR_ANGLE_ARCSEC)?
            * RAD_PER_ARCSEC,
        nuisance,
        record_hz: c.positive("calibration.record_hz", cal.record_hz, "Hz", 1000.0)?,
        montecarlo,
    })
}

fn axis_index(c: &Checker<'_>, key: &str, chain: &Chain, name: &str) -> Result<usize, ConfigError> {
    chain.index_of(name).ok_or_else(|| {
        let names: Vec<&str> = chain.axes().iter().map(|a| a.name.as_str()).collect();
        c.invalid(key, format!("no turntable axis is named \"{name}\"; the axes are {names:?}"))
    })
}

fn validate_scheme(c: &Checker<'_>, s: &RawScheme, chain: &Chain) -> Result<Scheme, ConfigError> {
    let n = chain.axes().len();
    let only_for = |key: &str, kind: &str| c.invalid(key, format!("is only read when scheme.kind = \"{kind}\"; remove it or change the kind"));
    match s.kind.as_str() {
        "static" | "continuous" => {
            if s.initial_dwell_s.is_some() {
                return Err(only_for("scheme.initial_dwell_s", "indexed"));
            }
            if s.repeat.is_some() {
                return Err(only_for("scheme.repeat", "indexed"));
            }
            if !s.step.is_empty() {
                return Err(only_for("scheme.step", "indexed"));
            }
        }
        "indexed" => {
            if !s.rate.is_empty() {
                return Err(only_for("scheme.rate", "continuous"));
            }
        }
        other => {
            return Err(c.invalid("scheme.kind", format!("\"{other}\" is not a scheme; use \"static\", \"continuous\" or \"indexed\"")));
        }
    }
    let initial: Vec<f64> = chain.axes().iter().map(|a| a.initial_angle_rad).collect();
    match s.kind.as_str() {
        "static" => {
            if !s.rate.is_empty() {
                return Err(only_for("scheme.rate", "continuous"));
            }
            Ok(Scheme::continuous(initial, vec![0.0; n]))
        }
        "continuous" => {
            if s.rate.is_empty() {
                return Err(c.invalid("scheme.rate", "a continuous scheme needs at least one [[scheme.rate]] entry"));
            }
            let mut rates = vec![0.0; n];
            for (i, r) in s.rate.iter().enumerate() {
                let idx = axis_index(c, &format!("scheme.rate[{i}].axis"), chain, &r.axis)?;
                rates[idx] = c.range(&format!("scheme.rate[{i}].rate_deg_per_s"), r.rate_deg_per_s, "deg/s", -1000.0, 1000.0, "")? * RAD_PER_DEG;
            }
            Ok(Scheme::continuous(initial, rates))
        }
        _ => {
            if s.step.is_empty() {
                return Err(c.invalid("scheme.step", "an indexed scheme needs at least one [[scheme.step]]"));
            }
            let dwell0 = c.range("scheme.initial_dwell_s", s.initial_dwell_s.unwrap_or(0.0), "s", 0.0, 1e7, "")?;
            let mut steps = Vec::new();
            for (i, st) in s.step.iter().enumerate() {
                let k = |f: &str| format!("scheme.step[{i}].{f}");
                steps.push(IndexedStep {
                    axis: axis_index(c, &k("axis"), chain, &st.axis)?,
                    angle_rad: c.range(&k("angle_deg"), st.angle_deg, "deg", -3600.0, 3600.0, "")? * RAD_PER_DEG,
                    rate_rad_per_s: c.positive(&k("rate_deg_per_s"), st.rate_deg_per_s, "deg/s", 1000.0)? * RAD_PER_DEG,
                    dwell_s: c.range(&k("dwell_s"), st.dwell_s, "s", 0.0, 1e7, "")?,
                    accel_rad_per_s2: c.range(&k("accel_deg_per_s2"), st.accel_deg_per_s2, "deg/s^2", 0.0, 1e5, "0 means the rate steps instantly")?
                        * RAD_PER_DEG,
                });
            }
            let scheme = Scheme::indexed(initial, dwell0, steps, s.repeat.unwrap_or(true));
            if scheme.period_s() <= 0.0 {
                return Err(c.invalid("scheme.step", "the sequence takes no time (all moves and dwells are zero)"));
            }
            Ok(scheme)
        }
    }
}

fn validate_compensation(
    c: &Checker<'_>,
    comp: &RawCompensation,
    table: &RawTurntable,
    chain: &Chain,
    truth: &TableErrors,
) -> Result<(TableErrors, RawCompensation), ConfigError> {
    let err_angle = |key: &str, v: f64| -> Result<f64, ConfigError> {
        Ok(c.range(key, v, "arcsec", -MAX_ERROR_ANGLE_ARCSEC, MAX_ERROR_ANGLE_ARCSEC, ERROR_HINT)? * RAD_PER_ARCSEC)
    };
    for name in comp.axis.keys() {
        axis_index(c, &format!("compensation.axis.{name}"), chain, name)?;
    }
    let pick = |v: Option<f64>, default: f64| v.unwrap_or(default);
    let enabled = comp.enabled.unwrap_or(true);
    let mut resolved = RawCompensation {
        enabled: Some(enabled),
        installation_x_arcsec: Some(pick(comp.installation_x_arcsec, table.installation_x_arcsec)),
        installation_y_arcsec: Some(pick(comp.installation_y_arcsec, table.installation_y_arcsec)),
        installation_z_arcsec: Some(pick(comp.installation_z_arcsec, table.installation_z_arcsec)),
        imu_mount_x_arcsec: Some(pick(comp.imu_mount_x_arcsec, table.imu_mount_x_arcsec)),
        imu_mount_y_arcsec: Some(pick(comp.imu_mount_y_arcsec, table.imu_mount_y_arcsec)),
        imu_mount_z_arcsec: Some(pick(comp.imu_mount_z_arcsec, table.imu_mount_z_arcsec)),
        axis: BTreeMap::new(),
    };
    let mut axes = Vec::new();
    for (i, a) in table.axis.iter().enumerate() {
        let given = comp.axis.get(&a.name).cloned().unwrap_or_default();
        let k = |f: &str| format!("compensation.axis.{}.{f}", a.name);
        let r = RawAxisCompensation {
            swing_half_angle_arcsec: Some(pick(given.swing_half_angle_arcsec, a.swing_half_angle_arcsec)),
            swing_phase_deg: Some(pick(given.swing_phase_deg, a.swing_phase_deg)),
            non_orthogonality_arcsec: Some(pick(given.non_orthogonality_arcsec, a.non_orthogonality_arcsec)),
            encoder_offset_arcsec: Some(pick(given.encoder_offset_arcsec, a.encoder_offset_arcsec)),
            encoder_scale_ppm: Some(pick(given.encoder_scale_ppm, a.encoder_scale_ppm)),
            encoder_delay_ms: Some(pick(given.encoder_delay_ms, a.encoder_delay_ms)),
        };
        if i == 0 && r.non_orthogonality_arcsec != Some(0.0) {
            return Err(c.invalid(&k("non_orthogonality_arcsec"), "the first axis has no non-orthogonality; compensate installation_*_arcsec instead"));
        }
        axes.push(AxisErrors {
            swing_half_angle_rad: c.range(
                &k("swing_half_angle_arcsec"),
                r.swing_half_angle_arcsec.unwrap_or_default(),
                "arcsec",
                0.0,
                MAX_ERROR_ANGLE_ARCSEC,
                ERROR_HINT,
            )? * RAD_PER_ARCSEC,
            swing_phase_rad: c.range(&k("swing_phase_deg"), r.swing_phase_deg.unwrap_or_default(), "deg", -360.0, 360.0, "")? * RAD_PER_DEG,
            non_orthogonality_rad: err_angle(&k("non_orthogonality_arcsec"), r.non_orthogonality_arcsec.unwrap_or_default())?,
            encoder_offset_rad: err_angle(&k("encoder_offset_arcsec"), r.encoder_offset_arcsec.unwrap_or_default())?,
            encoder_scale: c.range(&k("encoder_scale_ppm"), r.encoder_scale_ppm.unwrap_or_default(), "ppm", -10_000.0, 10_000.0, "1% at most")? * 1e-6,
            encoder_delay_s: c.range(&k("encoder_delay_ms"), r.encoder_delay_ms.unwrap_or_default(), "ms", -1000.0, 1000.0, "")? * 1e-3,
            // Noise is not a parameter a compensation can remove.
            encoder_noise_rad: 0.0,
        });
        resolved.axis.insert(a.name.clone(), r);
    }
    if !enabled {
        return Ok((TableErrors::zero(chain.axes().len()), resolved));
    }
    let errors = TableErrors {
        installation_rad: Vector3::new(
            err_angle("compensation.installation_x_arcsec", resolved.installation_x_arcsec.unwrap_or_default())?,
            err_angle("compensation.installation_y_arcsec", resolved.installation_y_arcsec.unwrap_or_default())?,
            err_angle("compensation.installation_z_arcsec", resolved.installation_z_arcsec.unwrap_or_default())?,
        ),
        imu_mount_rad: Vector3::new(
            err_angle("compensation.imu_mount_x_arcsec", resolved.imu_mount_x_arcsec.unwrap_or_default())?,
            err_angle("compensation.imu_mount_y_arcsec", resolved.imu_mount_y_arcsec.unwrap_or_default())?,
            err_angle("compensation.imu_mount_z_arcsec", resolved.imu_mount_z_arcsec.unwrap_or_default())?,
        ),
        axes,
    };
    debug_assert_eq!(errors.axes.len(), truth.axes.len());
    Ok((errors, resolved))
}
