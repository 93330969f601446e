//! The scenario file as written: serde structs in the user's units, parsed strictly (unknown keys are
//! errors). Every key's unit is in its name and its default here and in `assets/scenarios/`.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

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
    /// The INS gyros' angle random walk the 1σ allow for, °/√h (default: the `[imu]`'s; a log's
    /// table.toml states it or it is not modelled).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ins_random_walk_deg_per_sqrt_h: Option<f64>,
    /// 1σ of the INS gyros' unknown constant bias the 1σ allow for, °/h (default: the `[imu]`'s
    /// turn-on and Gauss–Markov bias; a log's table.toml states it or it is not modelled).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ins_bias_deg_per_h: Option<f64>,
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
            ins_random_walk_deg_per_sqrt_h: None,
            ins_bias_deg_per_h: None,
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
    /// Jiang et al. 2017 §6.1: "swaying angle S(−10°, +10°)", "phase A(−1°, +1°)", "non-orthogonal angle
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

/// `[position_fix]`: position fixes during a navigation run (Zheng et al. 2016 §4).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawPositionFix {
    /// Times of the fixes, hours; `rinscope reset` uses the first two (Zheng et al. 2016: 17 and 21).
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
    /// Δt of Li et al. 2014's synchronisation: outputs are compared with the truth Δt earlier, ms.
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

/// `[imu.gyro]`. The stochastic terms by IEEE Std 952's names and units (docs/allan.md): Q
/// `quantization_arcsec`, N `arw_deg_per_sqrt_h`, B `bias_instability_deg_per_h`, K
/// `rate_random_walk_deg_per_h_per_sqrt_h`, R `rate_ramp_deg_per_h2`.
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
    /// Q, arcsec (the Allan coefficient; a pulse weight w is Q = w/√12)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub quantization_arcsec: Option<f64>,
    /// The output pulse weight, arcsec (instead of `quantization_arcsec`)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pulse_weight_arcsec: Option<f64>,
    /// N, deg/√h
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub arw_deg_per_sqrt_h: Option<f64>,
    /// B, deg/h (flicker: the Allan floor is 0.664·B)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bias_instability_deg_per_h: Option<f64>,
    /// s, the τ range of B's flat floor (default [1, 1e4])
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bias_instability_range_s: Option<[f64; 2]>,
    /// K, deg/h/√h
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rate_random_walk_deg_per_h_per_sqrt_h: Option<f64>,
    /// R, deg/h² (signed)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rate_ramp_deg_per_h2: Option<f64>,
    /// deg/s, the measurement range
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub saturation_deg_per_s: Option<f64>,
    /// deg/h (1σ of a first-order Gauss-Markov bias)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub markov_sigma_deg_per_h: Option<f64>,
    /// s (its correlation time)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub correlation_time_s: Option<f64>,
    /// deg/h per g
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub g_sensitivity_deg_per_h_per_g: Option<f64>,
}

/// `[imu.accel]`. The stochastic terms by IEEE Std 1293's names (docs/allan.md): Q
/// `quantization_mps`, N `vrw_ug_per_sqrt_hz`, B `bias_instability_ug`, K
/// `acceleration_random_walk_ug_per_sqrt_h`, R `acceleration_ramp_ug_per_h`.
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
    /// Q, m/s (the Allan coefficient; a pulse weight w is Q = w/√12)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub quantization_mps: Option<f64>,
    /// The output pulse weight, m/s (instead of `quantization_mps`)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pulse_weight_mps: Option<f64>,
    /// N, µg/√Hz
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vrw_ug_per_sqrt_hz: Option<f64>,
    /// B, µg (flicker: the Allan floor is 0.664·B)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bias_instability_ug: Option<f64>,
    /// s, the τ range of B's flat floor (default [1, 1e4])
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bias_instability_range_s: Option<[f64; 2]>,
    /// K, µg/√h
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub acceleration_random_walk_ug_per_sqrt_h: Option<f64>,
    /// R, µg/h (signed)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub acceleration_ramp_ug_per_h: Option<f64>,
    /// g, the measurement range
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub saturation_g: Option<f64>,
    /// µg (1σ of a first-order Gauss-Markov bias)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub markov_sigma_ug: Option<f64>,
    /// s (its correlation time)
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
    /// Horizontal velocity damping toward zero velocity (Zheng et al. 2016).
    #[serde(default)]
    pub velocity_damping: bool,
    /// Alignment error (east tilt, north tilt, heading), arcmin.
    #[serde(default)]
    pub initial_attitude_error_arcmin: [f64; 3],
}

fn default_vertical() -> String {
    "held".into()
}

impl RawNavigation {
    /// `[navigation]` at its defaults: the vertical channel held, no damping, no initial error —
    /// what a log's table description without the section navigates with.
    #[must_use]
    pub fn held() -> Self {
        Self { vertical: default_vertical(), velocity_damping: false, initial_attitude_error_arcmin: [0.0; 3] }
    }
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
    /// Time-series output rate, Hz of simulated time (absent: chosen from the motion's bandwidth).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub series_hz: Option<f64>,
    /// 3D scene output rate, Hz of simulated time (absent: chosen from the motion and the length).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub scene_hz: Option<f64>,
    /// Unit of the attitude-error plots: "arcsec", "arcmin" or "deg" (absent: chosen from the
    /// table errors' size so the plot's numbers read naturally).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error_unit: Option<String>,
    /// Factor applied to every error angle when drawing the 3D scene.
    pub exaggeration: f64,
    /// Where a saved recording opens: "start" (it plays the run in about a minute) or "end" (the
    /// final state, the time cursor following the newest data). Default "start".
    #[serde(skip_serializing_if = "Option::is_none")]
    pub open_at: Option<String>,
    /// Which attitude algorithms' lines and needles are shown, by name (`"two-sample" = false`
    /// hides it; absent: shown). All of them run either way.
    #[serde(skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub show: std::collections::BTreeMap<String, bool>,
}

impl Default for RawRecording {
    fn default() -> Self {
        Self {
            series_hz: None,
            scene_hz: None,
            error_unit: None,
            exaggeration: 60.0,
            open_at: None,
            show: std::collections::BTreeMap::new(),
        }
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

impl RawTurntable {
    /// The stand-in of a strapdown IMU: one axis about z that never turns, no errors (b_from_s is
    /// the identity); a log set without `[turntable]` uses it and shows nothing of a table.
    #[must_use]
    pub fn strapdown() -> Self {
        Self {
            installation_x_arcsec: 0.0,
            installation_y_arcsec: 0.0,
            installation_z_arcsec: 0.0,
            imu_mount_x_arcsec: 0.0,
            imu_mount_y_arcsec: 0.0,
            imu_mount_z_arcsec: 0.0,
            axis: vec![RawAxis {
                name: "strapdown".into(),
                axis: "z".into(),
                initial_angle_deg: 0.0,
                swing_half_angle_arcsec: 0.0,
                swing_phase_deg: 0.0,
                non_orthogonality_arcsec: 0.0,
                encoder_offset_arcsec: 0.0,
                encoder_scale_ppm: 0.0,
                encoder_delay_ms: 0.0,
                encoder_noise_arcsec: 0.0,
            }],
        }
    }
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
