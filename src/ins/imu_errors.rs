//! The IMU's constant errors as a compensation model: gyro and accelerometer biases and gain
//! matrices, measured = (I + K)·true + b, their 21 calibrated parameters (K_a's lower triangle is
//! not one: the accelerometer triad defines the IMU frame) and the compensation a navigation
//! applies. Estimated by the self-calibration (`calib::selfcal`); applied by the pipeline.

use nalgebra::{Matrix3, Vector3};

use crate::ins::align::Increment;
use crate::math::units::{ARCSEC_PER_RAD, MPS2_PER_UG, RAD_PER_S_PER_DEG_PER_H};

/// The calibrated parameters.
pub const N_PARAMS: usize = 21;
/// The upper triangle of K_a, in parameter order.
pub(crate) const KA_UPPER: [(usize, usize); 6] = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)];

/// Which sensor a parameter belongs to, and what it is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Kind {
    /// Gyro bias.
    GyroBias,
    /// Gyro scale factor (a diagonal of K_g).
    GyroScale,
    /// Gyro misalignment (an off-diagonal of K_g).
    GyroMisalignment,
    /// Accelerometer bias.
    AccelBias,
    /// Accelerometer scale factor.
    AccelScale,
    /// Accelerometer misalignment.
    AccelMisalignment,
}

impl Kind {
    /// The display unit and how many of it one SI unit is.
    #[must_use]
    pub fn unit(self) -> (&'static str, f64) {
        match self {
            Self::GyroBias => ("°/h", 1.0 / RAD_PER_S_PER_DEG_PER_H),
            Self::GyroScale | Self::AccelScale => ("ppm", 1e6),
            Self::GyroMisalignment | Self::AccelMisalignment => ("″", ARCSEC_PER_RAD),
            Self::AccelBias => ("µg", 1.0 / MPS2_PER_UG),
        }
    }

    /// The unit as an entity or column name suffix (`crate::io::imu::units`): `deg_per_h`, `ppm`,
    /// `arcsec`, `ug`.
    #[must_use]
    pub fn unit_key(self) -> &'static str {
        match self {
            Self::GyroBias => "deg_per_h",
            Self::GyroScale | Self::AccelScale => "ppm",
            Self::GyroMisalignment | Self::AccelMisalignment => "arcsec",
            Self::AccelBias => "ug",
        }
    }

    /// The group a plot gathers.
    #[must_use]
    pub fn group(self) -> &'static str {
        match self {
            Self::GyroBias => "gyro bias",
            Self::GyroScale | Self::GyroMisalignment => "gyro scale and misalignment",
            Self::AccelBias => "accelerometer bias",
            Self::AccelScale | Self::AccelMisalignment => "accelerometer scale and misalignment",
        }
    }
}

/// Parameter `k`: its kind and its name (`gyro bias x`, `Kg_xy`, `Ka_zz`).
#[must_use]
pub fn param(k: usize) -> (Kind, String) {
    const AX: [&str; 3] = ["x", "y", "z"];
    match k {
        0..=2 => (Kind::GyroBias, format!("bg_{}", AX[k])),
        3..=11 => {
            let (i, j) = ((k - 3) / 3, (k - 3) % 3);
            (if i == j { Kind::GyroScale } else { Kind::GyroMisalignment }, format!("Kg_{}{}", AX[i], AX[j]))
        }
        12..=14 => (Kind::AccelBias, format!("ba_{}", AX[k - 12])),
        _ => {
            let (i, j) = KA_UPPER[k - 15];
            (if i == j { Kind::AccelScale } else { Kind::AccelMisalignment }, format!("Ka_{}{}", AX[i], AX[j]))
        }
    }
}

/// The 21 parameters' names, in order (the columns of `--json`).
#[must_use]
pub fn param_names() -> Vec<String> {
    (0..N_PARAMS).map(|k| param(k).1).collect()
}

/// The IMU's constant errors, SI: measured = (I + K)·true + b.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImuErrors {
    /// Gyro bias, rad/s.
    pub bg: Vector3<f64>,
    /// Gyro gain error.
    pub kg: Matrix3<f64>,
    /// Accelerometer bias, m/s².
    pub ba: Vector3<f64>,
    /// Accelerometer gain error.
    pub ka: Matrix3<f64>,
}

impl ImuErrors {
    /// Biases alone (gyro rad/s, accelerometer m/s²; no gain errors): what an alignment estimates.
    #[must_use]
    pub fn biases(bg: Vector3<f64>, ba: Vector3<f64>) -> Self {
        Self { bg, kg: Matrix3::zeros(), ba, ka: Matrix3::zeros() }
    }

    /// These errors with biases `bg`, `ba` found on the samples they compensated (an alignment's on
    /// a compensated replay) folded in: measured = (I + K)(true + δb) + b, so b' = b + (I + K)·δb.
    #[must_use]
    pub fn with_residual_biases(&self, bg: &Vector3<f64>, ba: &Vector3<f64>) -> Self {
        let one = Matrix3::identity();
        Self { bg: self.bg + (one + self.kg) * bg, kg: self.kg, ba: self.ba + (one + self.ka) * ba, ka: self.ka }
    }

    /// The same IMU described in the frame its accelerometer triad defines (K_a upper
    /// triangular): both gains change by the same small rotation [ρ×] (the rest is the IMU's
    /// attitude, which no calibration on the IMU's own motion can tell from the errors).
    #[must_use]
    pub fn in_accelerometer_frame(&self) -> Self {
        let r = self.accelerometer_frame_rotation().cross_matrix();
        Self { bg: self.bg, kg: self.kg + r, ba: self.ba, ka: self.ka + r }
    }

    /// ρ, the small rotation from this IMU's frame to the one its accelerometer triad defines:
    /// [ρ×] = [[0, −ρz, ρy], [ρz, 0, −ρx], [−ρy, ρx, 0]] cancels K_a's lower triangle.
    #[must_use]
    pub fn accelerometer_frame_rotation(&self) -> Vector3<f64> {
        let ka = &self.ka;
        Vector3::new(-ka[(2, 1)], ka[(2, 0)], -ka[(1, 0)])
    }

    /// The 21 parameters (K_a's lower triangle is dropped: see [`Self::in_accelerometer_frame`]).
    #[must_use]
    pub fn to_params(&self) -> [f64; N_PARAMS] {
        let mut p = [0.0; N_PARAMS];
        for i in 0..3 {
            p[i] = self.bg[i];
            p[12 + i] = self.ba[i];
            for j in 0..3 {
                p[3 + 3 * i + j] = self.kg[(i, j)];
            }
        }
        for (u, &(i, j)) in KA_UPPER.iter().enumerate() {
            p[15 + u] = self.ka[(i, j)];
        }
        p
    }

    /// From the 21 parameters.
    #[must_use]
    pub fn from_params(p: &[f64; N_PARAMS]) -> Self {
        let mut e = Self { bg: Vector3::zeros(), kg: Matrix3::zeros(), ba: Vector3::zeros(), ka: Matrix3::zeros() };
        for i in 0..3 {
            e.bg[i] = p[i];
            e.ba[i] = p[12 + i];
            for j in 0..3 {
                e.kg[(i, j)] = p[3 + 3 * i + j];
            }
        }
        for (u, &(i, j)) in KA_UPPER.iter().enumerate() {
            e.ka[(i, j)] = p[15 + u];
        }
        e
    }

    /// The true increments a sample of these errors measured as (Δθ, Δv) over `h` s:
    /// (I + K)⁻¹(measured − b·h) — the compensation a navigation applies.
    #[must_use]
    pub fn compensate(&self, measured: &Increment, h: f64) -> Increment {
        let inv = |k: &Matrix3<f64>| (Matrix3::identity() + k).try_inverse().unwrap_or_else(Matrix3::identity);
        (inv(&self.kg) * (measured.0 - self.bg * h), inv(&self.ka) * (measured.1 - self.ba * h))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_accelerometer_frame_form_differs_by_one_rotation_of_both_triads() {
        let ka = Matrix3::new(1e-4, 2e-5, 3e-5, 4e-5, -1e-4, 6e-5, 7e-5, 8e-5, 5e-5);
        let kg = Matrix3::new(2e-5, 1e-5, 0.0, -3e-5, 1e-5, 2e-5, 0.0, 4e-5, -2e-5);
        let e = ImuErrors { bg: Vector3::zeros(), kg, ba: Vector3::zeros(), ka }.in_accelerometer_frame();
        assert_eq!([e.ka[(1, 0)], e.ka[(2, 0)], e.ka[(2, 1)]], [0.0; 3]);
        // Same change in both: the difference K_g − K_a is kept, the diagonals (scale factors) too.
        assert!(((e.kg - e.ka) - (kg - ka)).norm() < 1e-18);
        assert_eq!((e.kg[(0, 0)], e.ka[(1, 1)]), (kg[(0, 0)], ka[(1, 1)]));
        let p = e.to_params();
        assert_eq!(ImuErrors::from_params(&p), e);
    }

    #[test]
    fn residual_biases_fold_into_one_compensation() {
        // Compensating with e, then removing biases found on what that left, is compensating once
        // with e.with_residual_biases: checked on a sample, not on the formula.
        let kg = Matrix3::new(2e-4, 1e-5, 0.0, -3e-5, 1e-4, 2e-5, 0.0, 4e-5, -2e-4);
        let ka = Matrix3::new(1e-4, 2e-5, 3e-5, 0.0, -1e-4, 6e-5, 0.0, 0.0, 5e-5);
        let e = ImuErrors { bg: Vector3::new(1e-6, -2e-6, 3e-7), kg, ba: Vector3::new(1e-3, 2e-4, -5e-4), ka };
        let (dg, da) = (Vector3::new(3e-7, 1e-7, -2e-7), Vector3::new(-2e-4, 1e-4, 3e-5));
        let (h, m) = (0.01, (Vector3::new(0.01, -0.02, 0.003), Vector3::new(0.05, 0.02, 0.098)));
        let once = e.compensate(&m, h);
        let twice = ImuErrors::biases(dg, da).compensate(&once, h);
        let folded = e.with_residual_biases(&dg, &da).compensate(&m, h);
        assert!((twice.0 - folded.0).norm() < 1e-17 && (twice.1 - folded.1).norm() < 1e-16, "{twice:?} {folded:?}");
    }
}
