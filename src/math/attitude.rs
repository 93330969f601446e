//! Vehicle attitude as pitch, roll and heading (Jiang et al. 2017 eq. 18-19), and the first-order map from a
//! small attitude-error rotation vector to Euler-angle errors.
//!
//! Convention (Jiang et al. 2017 eq. 18, the rotary-table paper section 4.1): n = East-North-Up, b = right-forward-up,
//! `n_from_b = Rz(-heading) * Rx(pitch) * Ry(roll)` with active right-handed rotations, so heading is
//! measured clockwise from North (the forward axis has East component sin(heading)), pitch is the
//! nose-up angle and roll turns the right wing down.

use nalgebra::Vector3;

use crate::math::frames::{B, N, Rot, V3, axis_angle};
use crate::math::units::wrap_pi;

/// Pitch, roll and heading, in radians.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Attitude {
    /// Nose-up angle, in [-pi/2, pi/2].
    pub pitch_rad: f64,
    /// Right-wing-down angle, in (-pi, pi].
    pub roll_rad: f64,
    /// Clockwise from North, in (-pi, pi].
    pub heading_rad: f64,
}

impl Attitude {
    /// C_b^n for this attitude.
    #[must_use]
    pub fn n_from_b(&self) -> Rot<N, B> {
        let q = axis_angle(&Vector3::z(), -self.heading_rad)
            * axis_angle(&Vector3::x(), self.pitch_rad)
            * axis_angle(&Vector3::y(), self.roll_rad);
        // FRAME: Jiang et al. 2017 eq. 18 builds C_b^n from the three Euler angles in this order.
        Rot::from_quaternion(q)
    }

    /// Extracts the Euler angles from C_b^n (Jiang et al. 2017 eq. 19 with the slip T31/T32 read as T31/T33).
    #[must_use]
    pub fn from_n_from_b(n_from_b: &Rot<N, B>) -> Self {
        // Only five DCM elements are needed; computed straight from the quaternion (hot path).
        let q = n_from_b.quaternion();
        let (w, x, y, z) = (q.w, q.i, q.j, q.k);
        let c01 = 2.0 * (x * y - w * z);
        let c11 = 1.0 - 2.0 * (x * x + z * z);
        let c20 = 2.0 * (x * z - w * y);
        let c21 = 2.0 * (y * z + w * x);
        let c22 = 1.0 - 2.0 * (x * x + y * y);
        Self { pitch_rad: c21.clamp(-1.0, 1.0).asin(), roll_rad: (-c20).atan2(c22), heading_rad: c01.atan2(c11) }
    }

    /// Component-wise difference `self - truth`, with roll and heading wrapped into (-pi, pi].
    #[must_use]
    pub fn error_from(&self, truth: &Self) -> AttitudeError {
        AttitudeError {
            pitch_rad: self.pitch_rad - truth.pitch_rad,
            roll_rad: wrap_pi(self.roll_rad - truth.roll_rad),
            heading_rad: wrap_pi(self.heading_rad - truth.heading_rad),
        }
    }
}

/// An attitude error as differences of Euler angles (computed minus true), in radians.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct AttitudeError {
    /// Pitch error.
    pub pitch_rad: f64,
    /// Roll error.
    pub roll_rad: f64,
    /// Heading error.
    pub heading_rad: f64,
}

impl AttitudeError {
    /// The three components as an array ordered pitch, roll, heading.
    #[must_use]
    pub fn as_array(&self) -> [f64; 3] {
        [self.pitch_rad, self.roll_rad, self.heading_rad]
    }

    /// First-order Euler-angle errors caused by a small rotation error `phi_n`, where the computed
    /// attitude is `exp([phi_n x]) * n_from_b`.
    ///
    /// Derivation (docs/closed-form.md): with phi_h = Rz(heading) phi_n,
    /// d_pitch = phi_h.x, d_roll = phi_h.y / cos(pitch), d_heading = tan(pitch) * phi_h.y - phi_h.z.
    /// The sines and cosines come from the DCM itself (C01 = sin ψ cos θ, C11 = cos ψ cos θ,
    /// C21 = sin θ), so the hot path needs no trigonometry.
    #[must_use]
    pub fn first_order(n_from_b: &Rot<N, B>, phi_n: V3<N>) -> Self {
        let q = n_from_b.quaternion();
        let (w, x, y, z) = (q.w, q.i, q.j, q.k);
        let c01 = 2.0 * (x * y - w * z);
        let c11 = 1.0 - 2.0 * (x * x + z * z);
        let c21 = 2.0 * (y * z + w * x);
        let cos_pitch = c01.hypot(c11);
        let (sh, ch) = (c01 / cos_pitch, c11 / cos_pitch);
        let phi_hx = ch * phi_n.v.x - sh * phi_n.v.y;
        let phi_hy = sh * phi_n.v.x + ch * phi_n.v.y;
        Self { pitch_rad: phi_hx, roll_rad: phi_hy / cos_pitch, heading_rad: c21 / cos_pitch * phi_hy - phi_n.v.z }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::rotvec;
    use crate::math::units::RAD_PER_DEG;

    fn att(pitch_deg: f64, roll_deg: f64, heading_deg: f64) -> Attitude {
        Attitude {
            pitch_rad: pitch_deg * RAD_PER_DEG,
            roll_rad: roll_deg * RAD_PER_DEG,
            heading_rad: heading_deg * RAD_PER_DEG,
        }
    }

    #[test]
    fn euler_round_trip() {
        for a in [att(0.0, 0.0, 0.0), att(30.0, 30.0, 0.0), att(-45.0, 170.0, -120.0), att(80.0, -20.0, 179.0)] {
            let back = Attitude::from_n_from_b(&a.n_from_b());
            let e = back.error_from(&a);
            for c in e.as_array() {
                assert!(c.abs() < 1e-12, "{a:?} -> {back:?}");
            }
        }
    }

    #[test]
    fn extraction_from_the_quaternion_matches_the_full_matrix() {
        // Independent computation: nalgebra's rotation matrix, eq. 19 element by element.
        let a = att(23.0, -67.0, 131.0);
        let n_from_b = a.n_from_b();
        let c = n_from_b.matrix();
        let e = Attitude::from_n_from_b(&n_from_b);
        assert!((e.pitch_rad - c[(2, 1)].asin()).abs() < 1e-14);
        assert!((e.roll_rad - (-c[(2, 0)]).atan2(c[(2, 2)])).abs() < 1e-14);
        assert!((e.heading_rad - c[(0, 1)].atan2(c[(1, 1)])).abs() < 1e-14);
    }

    #[test]
    fn heading_is_clockwise_from_north() {
        // Heading 90 deg: the forward axis (body y) points East (Jiang et al. 2017 eq. 18: T12 = sin(psi)cos(theta)).
        let fwd = att(0.0, 0.0, 90.0).n_from_b().apply(V3::new(Vector3::y()));
        assert!((fwd.v - Vector3::x()).norm() < 1e-15);
        // Pitch 90 deg: forward points up.
        let fwd = att(90.0, 0.0, 0.0).n_from_b().apply(V3::new(Vector3::y()));
        assert!((fwd.v - Vector3::z()).norm() < 1e-15);
        // Roll 90 deg: the right wing (body x) points down.
        let right = att(0.0, 90.0, 0.0).n_from_b().apply(V3::new(Vector3::x()));
        assert!((right.v + Vector3::z()).norm() < 1e-15);
    }

    #[test]
    fn first_order_map_matches_finite_difference() {
        // Independent computation: perturb the DCM by a tiny rotation and difference the extracted angles.
        let truth = att(30.0, 30.0, 40.0);
        let eps = 1e-7;
        for axis in [Vector3::x(), Vector3::y(), Vector3::z(), Vector3::new(0.3, -0.5, 0.8).normalize()] {
            let phi = axis * eps;
            // FRAME: a small rotation applied on the navigation side of C_b^n.
            let perturbed: Rot<N, N> = Rot::from_quaternion(rotvec::exp(&phi));
            let computed = Attitude::from_n_from_b(&(perturbed * truth.n_from_b()));
            let exact = computed.error_from(&truth).as_array();
            let linear = AttitudeError::first_order(&truth.n_from_b(), V3::new(phi)).as_array();
            for (e, l) in exact.iter().zip(linear) {
                // Second-order remainder is O(eps^2) ~ 1e-14.
                assert!((e - l).abs() < 1e-12, "axis {axis:?}: exact {e} linear {l}");
            }
        }
    }
}
