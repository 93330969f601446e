//! Unit conversions: SI and radians inside, units in the name at every edge.

/// Radians per degree.
pub const RAD_PER_DEG: f64 = std::f64::consts::PI / 180.0;
/// Radians per arcminute.
pub const RAD_PER_ARCMIN: f64 = RAD_PER_DEG / 60.0;
/// Radians per arcsecond.
pub const RAD_PER_ARCSEC: f64 = RAD_PER_DEG / 3600.0;
/// Arcseconds per radian.
pub const ARCSEC_PER_RAD: f64 = 1.0 / RAD_PER_ARCSEC;
/// Degrees per radian.
pub const DEG_PER_RAD: f64 = 1.0 / RAD_PER_DEG;
/// rad/s per deg/h (a gyro bias or a rate).
pub const RAD_PER_S_PER_DEG_PER_H: f64 = RAD_PER_DEG / 3600.0;
/// rad/√s per deg/√h (an angle random walk).
pub const RAD_PER_SQRT_S_PER_DEG_PER_SQRT_H: f64 = RAD_PER_DEG / 60.0;
/// rad/s/√s per deg/h/√h (a gyro's rate random walk K; √h = 60 √s).
pub const RAD_PER_S_PER_SQRT_S_PER_DEG_PER_H_PER_SQRT_H: f64 = RAD_PER_S_PER_DEG_PER_H / 60.0;
/// rad/s² per deg/h² (a gyro's rate ramp R).
pub const RAD_PER_S2_PER_DEG_PER_H2: f64 = RAD_PER_DEG / (3600.0 * 3600.0);
/// Standard gravity g₀, m/s² (the unit of "µg" and "per g").
pub const STANDARD_GRAVITY_MPS2: f64 = 9.806_65;
/// m/s² per µg.
pub const MPS2_PER_UG: f64 = 9.806_65e-6;
/// m/s/√s per µg/√Hz (an accelerometer's velocity random walk N: m/s²/√Hz is m/s/√s).
pub const MPS_PER_SQRT_S_PER_UG_PER_SQRT_HZ: f64 = MPS2_PER_UG;
/// m/s²/√s per µg/√h (an accelerometer's acceleration random walk K).
pub const MPS2_PER_SQRT_S_PER_UG_PER_SQRT_H: f64 = MPS2_PER_UG / 60.0;
/// m/s³ per µg/h (an accelerometer's acceleration ramp R).
pub const MPS3_PER_UG_PER_H: f64 = MPS2_PER_UG / 3600.0;

/// Wraps an angle difference into (-pi, pi].
#[must_use]
pub fn wrap_pi(angle_rad: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    // Differences of wrapped angles are within (-2pi, 2pi): one conditional turn suffices up to 3pi,
    // and the hot path needs no division.
    let a = if angle_rad.abs() <= 3.0 * PI { angle_rad } else { angle_rad - TAU * (angle_rad / TAU).round() };
    if a > PI {
        a - TAU
    } else if a <= -PI {
        a + TAU
    } else {
        a
    }
}

/// Formats an angle given in radians the way an inertial engineer reads it:
/// arcseconds below 1', arcminutes below 1 deg, degrees above.
#[must_use]
pub fn fmt_angle(angle_rad: f64) -> String {
    let arcsec = angle_rad * ARCSEC_PER_RAD;
    if arcsec.abs() < 60.0 {
        format!("{arcsec:.2}″")
    } else if arcsec.abs() < 3600.0 {
        format!("{:.3}′", arcsec / 60.0)
    } else {
        format!("{:.4}°", arcsec / 3600.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_pi_keeps_small_angles_and_folds_large_ones() {
        assert!((wrap_pi(0.1) - 0.1).abs() < 1e-15);
        assert!((wrap_pi(-0.1) + 0.1).abs() < 1e-15);
        // 350 deg - 0 deg is a -10 deg difference.
        assert!((wrap_pi(350.0 * RAD_PER_DEG) + 10.0 * RAD_PER_DEG).abs() < 1e-12);
        assert!((wrap_pi(-190.0 * RAD_PER_DEG) - 170.0 * RAD_PER_DEG).abs() < 1e-12);
        // Every result is in (-pi, pi] and differs from the input by whole turns.
        for i in -2000..=2000 {
            let a = f64::from(i) * 0.0137;
            let w = wrap_pi(a);
            assert!(w > -std::f64::consts::PI && w <= std::f64::consts::PI, "{a} -> {w}");
            let turns = (a - w) / std::f64::consts::TAU;
            assert!((turns - turns.round()).abs() < 1e-9, "{a} -> {w}");
        }
    }

    #[test]
    fn arcsec_conversions_round_trip() {
        // 1 deg = 3600 arcsec by definition.
        assert!((3600.0 * RAD_PER_ARCSEC - RAD_PER_DEG).abs() < 1e-18);
        assert!((RAD_PER_ARCMIN * 60.0 - RAD_PER_DEG).abs() < 1e-18);
    }
}
