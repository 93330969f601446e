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
        let Cosines { c01, c11, c20, c21, c22 } = Cosines::of(n_from_b);
        Self { pitch_rad: c21.clamp(-1.0, 1.0).asin(), roll_rad: (-c20).atan2(c22), heading_rad: c01.atan2(c11) }
    }

    /// Component-wise difference `self - truth`, with roll and heading wrapped into (-pi, pi].
    #[must_use]
    #[inline]
    pub fn error_from(&self, truth: &Self) -> AttitudeError {
        AttitudeError {
            pitch_rad: self.pitch_rad - truth.pitch_rad,
            roll_rad: wrap_pi(self.roll_rad - truth.roll_rad),
            heading_rad: wrap_pi(self.heading_rad - truth.heading_rad),
        }
    }
}

/// The five elements of C_b^n the Euler angles are read from (Jiang et al. 2017 eq. 19), straight
/// from the quaternion: the hot path needs no whole matrix.
struct Cosines {
    c01: f64,
    c11: f64,
    c20: f64,
    c21: f64,
    c22: f64,
}

impl Cosines {
    #[inline]
    fn of(n_from_b: &Rot<N, B>) -> Self {
        let q = n_from_b.quaternion();
        let (w, x, y, z) = (q.w, q.i, q.j, q.k);
        Self {
            c01: 2.0 * (x * y - w * z),
            c11: 1.0 - 2.0 * (x * x + z * z),
            c20: 2.0 * (x * z - w * y),
            c21: 2.0 * (y * z + w * x),
            c22: 1.0 - 2.0 * (x * x + y * y),
        }
    }
}

/// The direction cosines of one C_b^n that its Euler angles are read from, as a (sine, cosine) pair
/// per angle up to a positive factor: pitch (C21, √(C20² + C22²)), roll (−C20, C22) and heading
/// (C01, C11), each of the latter two scaled by cos θ. An attitude error read from two of these
/// needs no trigonometry of either attitude ([`AttitudeError::between`]): what the INS's error
/// statistics take at every update.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EulerParts {
    pitch: (f64, f64),
    roll: (f64, f64),
    heading: (f64, f64),
}

impl EulerParts {
    /// The parts of `n_from_b` (five DCM elements, straight from the quaternion).
    #[must_use]
    #[inline]
    pub fn of(n_from_b: &Rot<N, B>) -> Self {
        let Cosines { c01, c11, c20, c21, c22 } = Cosines::of(n_from_b);
        // sin θ = C21 and cos θ = √(C20² + C22²) ≥ 0 (the third column is a unit vector): pitch
        // stays in [−π/2, π/2], as asin(C21) reads it.
        Self { pitch: (c21, (c20 * c20 + c22 * c22).sqrt()), roll: (-c20, c22), heading: (c01, c11) }
    }

    /// The Euler angles.
    #[must_use]
    pub fn attitude(&self) -> Attitude {
        Attitude {
            pitch_rad: self.pitch.0.atan2(self.pitch.1),
            roll_rad: self.roll.0.atan2(self.roll.1),
            heading_rad: self.heading.0.atan2(self.heading.1),
        }
    }
}

/// The angle from the direction (c₂, s₂) to (c₁, s₁), in [−π, π]: atan2 of the sine and cosine of
/// the difference (s₁c₂ − c₁s₂, c₁c₂ + s₁s₂). Near zero — where an attitude error lives — the
/// arctangent is its series u − u³/3 + u⁵/5 − u⁷/7 (|u| ≤ 2⁻⁷: the next term, u⁹/9, is below 1.6·10⁻¹⁸
/// of u, under the rounding of a double); elsewhere libm's atan2.
#[inline]
fn angle_between((s1, c1): (f64, f64), (s2, c2): (f64, f64)) -> f64 {
    let s = s1 * c2 - c1 * s2;
    let c = c1 * c2 + s1 * s2;
    if c > 0.0 && s.abs() <= c * (1.0 / 128.0) {
        let u = s / c;
        let u2 = u * u;
        u * (1.0 - u2 * (1.0 / 3.0 - u2 * (1.0 / 5.0 - u2 * (1.0 / 7.0))))
    } else {
        s.atan2(c)
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
    /// `computed − truth` as [`Attitude::error_from`] gives it (roll and heading wrapped into
    /// [−π, π]), read from the two attitudes' [`EulerParts`]: the difference's sine and cosine per
    /// angle, no arctangent of either attitude.
    #[must_use]
    #[inline]
    pub fn between(computed: &EulerParts, truth: &EulerParts) -> Self {
        Self {
            pitch_rad: angle_between(computed.pitch, truth.pitch),
            roll_rad: angle_between(computed.roll, truth.roll),
            heading_rad: angle_between(computed.heading, truth.heading),
        }
    }

    /// The three components as an array ordered pitch, roll, heading.
    #[must_use]
    #[inline]
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
    #[inline]
    pub fn first_order(n_from_b: &Rot<N, B>, phi_n: V3<N>) -> Self {
        let Cosines { c01, c11, c21, .. } = Cosines::of(n_from_b);
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
    fn the_error_read_from_the_parts_is_the_difference_of_the_euler_angles() {
        // Independent computation: each attitude's Euler angles by libm's asin/atan2 (eq. 19), then
        // their difference wrapped (`error_from`). Errors from 1e-9 rad (the series branch) to
        // whole turns (atan2's), attitudes away from the pitch singularity.
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        let mut uniform = |lo: f64, hi: f64| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            lo + (hi - lo) * (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut series_branch = 0;
        for i in 0..4000 {
            let truth = att(uniform(-80.0, 80.0), uniform(-180.0, 180.0), uniform(-180.0, 180.0));
            let size = 10f64.powf(uniform(-9.0, 0.5));
            let phi = Vector3::new(uniform(-1.0, 1.0), uniform(-1.0, 1.0), uniform(-1.0, 1.0)) * size;
            // FRAME: a small rotation of the navigation frame applied to the true C_b^n.
            let computed = Rot::<N, B>::from_quaternion(rotvec::exp(&phi) * *truth.n_from_b().quaternion());
            let truth_rot = truth.n_from_b();
            let want = Attitude::from_n_from_b(&computed).error_from(&Attitude::from_n_from_b(&truth_rot));
            let got = AttitudeError::between(&EulerParts::of(&computed), &EulerParts::of(&truth_rot));
            // asin(C21) and the atan2 of roll and heading round to 4e-16 / cos θ (their
            // conditioning near the pitch singularity); a difference carries both attitudes'.
            let cos_pitch = [&computed, &truth_rot]
                .map(|r| Attitude::from_n_from_b(r).pitch_rad.cos())
                .into_iter()
                .fold(1.0, f64::min);
            let tol = 2e-15 / cos_pitch;
            for (g, w) in got.as_array().into_iter().zip(want.as_array()) {
                // A wrapped difference may land on the other side of ±π.
                assert!(
                    (g - w).abs() < tol || ((g - w).abs() - std::f64::consts::TAU).abs() < tol,
                    "{i}: {got:?} vs {want:?}"
                );
            }
            series_branch += usize::from(size < 1e-3);
        }
        assert!(series_branch > 1000, "{series_branch} small errors");
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
