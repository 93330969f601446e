//! The INS in the loop: IMU increments from the exact truth, sensor errors, dither and its FIR,
//! coning-compensated attitude algorithms and strapdown navigation.

pub mod coning;
pub mod fir;
pub mod nav;
pub mod pipeline;
pub mod sensor;
pub mod strapdown;
pub mod truth;

use nalgebra::Vector3;

use coning::Algorithm;
use nav::NavOptions;
use sensor::{DitherSpec, ImuErrorSpec, Spec, TriadSpec};

/// The validated `[imu]` and `[navigation]` sections, in SI units.
#[derive(Debug, Clone, PartialEq)]
pub struct InsConfig {
    /// IMU sampling rate (= simulation.step_hz), Hz.
    pub rate_hz: f64,
    /// IMU samples summed per algorithm sample, after the FIR.
    pub decimation: usize,
    /// The algorithm the navigation uses (and the one recorded when not comparing).
    pub algorithm: Algorithm,
    /// Run every algorithm on the same stream.
    pub compare: bool,
    /// Sensor errors.
    pub errors: ImuErrorSpec,
    /// FIR taps (one tap: no filter).
    pub fir_taps: Vec<f64>,
    /// Zero-order hold as a T/2 output delay.
    pub zero_order_hold: bool,
    /// Outputs are compared with the truth this much earlier, s.
    pub output_compensation_s: f64,
    /// Raw and filtered gyro signals recorded for this long, s.
    pub signal_window_s: f64,
    /// Navigation of velocity and position, if asked for.
    pub navigation: Option<NavOptions>,
    /// Alignment error (east tilt, north tilt, heading), rad.
    pub initial_error_rad: Vector3<f64>,
}

const DEG_PER_H: f64 = std::f64::consts::PI / 180.0 / 3600.0;
const ARW: f64 = std::f64::consts::PI / 180.0 / 60.0;
const UG: f64 = 9.806_65e-6;
const ARCSEC: f64 = std::f64::consts::PI / 180.0 / 3600.0;

/// Starting values of the `[imu]` section; keys in the file override them.
#[must_use]
pub fn preset(name: &str) -> Option<InsConfig> {
    let mut cfg = InsConfig {
        rate_hz: 200.0,
        decimation: 1,
        algorithm: Algorithm::TwoSampleP1,
        compare: false,
        errors: ImuErrorSpec::default(),
        fir_taps: vec![1.0],
        zero_order_hold: false,
        output_compensation_s: 0.0,
        signal_window_s: 0.25,
        navigation: None,
        initial_error_rad: Vector3::zeros(),
    };
    match name {
        "none" => {}
        // Seed 000 Table 1 (the dual-axis RINS of Jiang et al.): biases 1σ, "<" limits taken as 1σ,
        // "50 µg/h^½" read as a velocity random walk of 50 µg/√Hz (docs/ins.md).
        "jiang2017-table1" => {
            cfg.errors.gyro = TriadSpec {
                bias: Spec::Sigma(0.005 * DEG_PER_H),
                scale: Spec::Sigma(20e-6),
                misalignment_rad: 5.0 * ARCSEC,
                white: 0.0005 * ARW,
                ..TriadSpec::default()
            };
            cfg.errors.accel = TriadSpec { bias: Spec::Sigma(100.0 * UG), scale: Spec::Sigma(20e-6), misalignment_rad: 5.0 * ARCSEC, white: 50.0 * UG, ..TriadSpec::default() };
            cfg.errors.g_sensitivity = 0.0001 * DEG_PER_H / 9.806_65;
        }
        // Seed 003 §4.3 simulation: gyro random walk 3e-3 °/√h, accelerometer noise 20 µg/√Hz.
        "zheng2016" => {
            cfg.errors.gyro.white = 3e-3 * ARW;
            cfg.errors.accel.white = 20.0 * UG;
        }
        // Seed 001 Table 4 (the DAMS laser INS), 2 kHz sampling, three dithered RLGs and the FIR.
        "li2014-table4" => {
            cfg.errors.gyro = TriadSpec {
                bias: Spec::Sigma(0.01 * DEG_PER_H),
                scale: Spec::Sigma(2e-6),
                misalignment_rad: ARCSEC,
                white: 0.0008 * ARW,
                instability: 0.005 * DEG_PER_H,
                correlation_s: 3600.0,
            };
            cfg.errors.accel = TriadSpec {
                bias: Spec::Sigma(2.0 * UG),
                scale: Spec::Sigma(5e-6),
                misalignment_rad: ARCSEC,
                white: 0.0,
                instability: 20.0 * UG,
                correlation_s: 3600.0,
            };
            cfg.errors.dither = DitherSpec { frequencies_hz: [335.4, 375.5, 425.7], amplitudes_rad: [500.0 * ARCSEC; 3], coupling: 0.3 };
            cfg.fir_taps = fir::SEED001_TAPS.to_vec();
            cfg.zero_order_hold = true;
        }
        _ => return None,
    }
    Some(cfg)
}
