//! Layer 4, the INS in the loop: IMU increments from the exact truth, sensor errors (constant ones,
//! white noise and the IEEE 952/1293 stochastic terms), dither and its FIR, coning-compensated
//! attitude algorithms, strapdown navigation, position resets.

pub mod align;
pub mod allan;
pub mod averaged;
pub mod budget;
pub mod coning;
pub mod core;
pub mod fir;
pub mod imu_errors;
pub mod nav;
pub mod noise;
pub mod phasor_truth;
pub mod pipeline;
pub mod reset;
pub mod sensor;
pub mod strapdown;
pub mod trace;
pub mod truth;
pub mod view;

use nalgebra::Vector3;

use coning::Algorithm;
use nav::NavOptions;
use sensor::ImuErrorSpec;

/// The INS in the loop (the validated `[imu]` and `[navigation]` sections), SI units.
#[derive(Debug, Clone, PartialEq)]
pub struct InsParams {
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
    /// The IMU errors the computer removes from every sample (a compensation document's IMU part,
    /// `run --compensation`), in the accelerometer triad's frame; None: nothing.
    pub imu_compensation: Option<imu_errors::ImuErrors>,
    /// Which of `errors`' terms act (all in a run; one at a time in an error budget's runs).
    pub sources: sensor::ImuSources,
}

impl InsParams {
    /// An ideal IMU at `rate_hz` feeding `algorithm`, without navigation.
    #[must_use]
    pub fn ideal(rate_hz: f64, algorithm: Algorithm) -> Self {
        Self {
            rate_hz,
            decimation: 1,
            algorithm,
            compare: false,
            errors: ImuErrorSpec::default(),
            fir_taps: vec![1.0],
            zero_order_hold: false,
            output_compensation_s: 0.0,
            signal_window_s: 0.25,
            navigation: None,
            initial_error_rad: Vector3::zeros(),
            sources: sensor::ImuSources::ALL,
            imu_compensation: None,
        }
    }

    /// The algorithms run, in integrator order: the configured one first, then (comparing) the rest.
    #[must_use]
    pub fn algorithms(&self) -> Vec<Algorithm> {
        if self.compare {
            std::iter::once(self.algorithm).chain(Algorithm::ALL.into_iter().filter(|a| *a != self.algorithm)).collect()
        } else {
            vec![self.algorithm]
        }
    }
}
