//! Rotations that turn at constant rates. Between two breakpoints a vehicle without wobble and a
//! table whose shafts do not accelerate are a chain `C(τ) = L_1(τ) · L_2(τ) ⋯ L_m(τ)` of such links:
//! the Euler angles of a ramp, the two phases of a cone, the shafts of a continuous scheme or of a
//! cruise, and the constant rotations between them. The IMU truth integrates such a chain in closed
//! form (`ins::phasor_truth`).

use nalgebra::{UnitQuaternion, Vector3};

use crate::math::frames::axis_angle;

/// One link of a chain, `τ` seconds after the instant the chain was taken at.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Link {
    /// A constant rotation.
    Fixed(UnitQuaternion<f64>),
    /// `R(axis, angle_rad + rate_rad_per_s · τ)`.
    Turning {
        /// Unit rotation axis, the same in the link's parent and child frames.
        axis: Vector3<f64>,
        /// Angle at τ = 0, rad.
        angle_rad: f64,
        /// Constant rate, rad/s.
        rate_rad_per_s: f64,
    },
    /// Pure coning `K = Rz(φ) · Rx(α) · Rz(−φ)` (the rotation by α about (cos φ, sin φ, 0)),
    /// φ = `phase_rad + rate_rad_per_s · τ`. One link rather than three: its own rate
    /// `Ω (−sin α sin φ, sin α cos φ, −2 sin²(α/2))` has a constant part that the sum of the three
    /// links' rates, Ω(cos α − 1), would lose to cancellation for a small α.
    Cone {
        /// Half-angle α, rad.
        half_angle_rad: f64,
        /// φ at τ = 0, rad.
        phase_rad: f64,
        /// Ω, rad/s.
        rate_rad_per_s: f64,
    },
}

impl Link {
    /// The link's rotation (parent from child) at `tau_s`.
    #[must_use]
    pub fn rotation(&self, tau_s: f64) -> UnitQuaternion<f64> {
        match *self {
            Self::Fixed(q) => q,
            Self::Turning { axis, angle_rad, rate_rad_per_s } => axis_angle(&axis, angle_rad + rate_rad_per_s * tau_s),
            Self::Cone { half_angle_rad, phase_rad, rate_rad_per_s } => {
                let z = axis_angle(&Vector3::z(), phase_rad + rate_rad_per_s * tau_s);
                z * axis_angle(&Vector3::x(), half_angle_rad) * z.inverse()
            }
        }
    }

    /// The link's rate, rad/s (0 for a fixed link).
    #[must_use]
    pub fn rate_rad_per_s(&self) -> f64 {
        match *self {
            Self::Fixed(_) => 0.0,
            Self::Turning { rate_rad_per_s, .. } | Self::Cone { rate_rad_per_s, .. } => rate_rad_per_s,
        }
    }
}
