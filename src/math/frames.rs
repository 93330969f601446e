//! Typed frames and rotations: `Rot<To, From>` multiplies only when the inner frames match.
//!
//! `n_from_b: Rot<N, B>` is C_b^n (it maps a vector expressed in b into n). Chains read right to left:
//! `n_from_s = n_from_b * b_from_s`. Intermediate gimbal frames of a configurable chain are not types
//! (their number is data); they stay local `UnitQuaternion`s inside `gimbal.rs`.

use std::fmt;
use std::marker::PhantomData;
use std::ops::{Add, Mul, Sub};

use nalgebra::{Matrix3, UnitQuaternion, Vector3};

/// Navigation frame: East-North-Up at the configured site.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct N;
/// Vehicle body frame: x right, y forward, z up.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct B;
/// IMU sensor frame (the orthogonalised gyro/accelerometer triad).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct S;

/// A rotation that maps vectors expressed in `From` into `To`.
pub struct Rot<To, From> {
    q: UnitQuaternion<f64>,
    _frames: PhantomData<(To, From)>,
}

// Manual impls: the markers need not be Clone/Copy/Debug for the rotation to be.
impl<To, From> Clone for Rot<To, From> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<To, From> Copy for Rot<To, From> {}
impl<To, From> fmt::Debug for Rot<To, From> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Rot<{}, {}>({:?})", short_type_name::<To>(), short_type_name::<From>(), self.q)
    }
}

fn short_type_name<T>() -> &'static str {
    let full = std::any::type_name::<T>();
    full.rsplit("::").next().unwrap_or(full)
}

impl<To, From> Rot<To, From> {
    /// The identity: only meaningful where `To` and `From` coincide at this instant.
    #[must_use]
    pub fn identity() -> Self {
        Self::from_quaternion(UnitQuaternion::identity())
    }

    /// Asserts that `q` maps vectors expressed in `From` into `To`.
    /// FRAME: the caller states that relationship; every call site says why it holds.
    #[must_use]
    pub fn from_quaternion(q: UnitQuaternion<f64>) -> Self {
        debug_assert!((q.norm() - 1.0).abs() < 1e-9, "rotation quaternion must be unit");
        Self { q, _frames: PhantomData }
    }

    /// The underlying quaternion (w, i, j, k in nalgebra's order).
    #[must_use]
    pub fn quaternion(&self) -> &UnitQuaternion<f64> {
        &self.q
    }

    /// The direction-cosine matrix C_From^To.
    #[must_use]
    pub fn matrix(&self) -> Matrix3<f64> {
        self.q.to_rotation_matrix().into_inner()
    }

    /// The reverse rotation.
    #[must_use]
    pub fn inverse(&self) -> Rot<From, To> {
        Rot::from_quaternion(self.q.inverse())
    }

    /// Expresses a vector given in `From` in `To`.
    #[must_use]
    pub fn apply(&self, v: V3<From>) -> V3<To> {
        V3::new(self.q * v.v)
    }

    /// Angle of the rotation, in radians, in [0, pi].
    #[must_use]
    pub fn angle_rad(&self) -> f64 {
        self.q.angle()
    }
}

impl<To, Mid, From> Mul<Rot<Mid, From>> for Rot<To, Mid> {
    type Output = Rot<To, From>;
    fn mul(self, rhs: Rot<Mid, From>) -> Rot<To, From> {
        Rot::from_quaternion(self.q * rhs.q)
    }
}

/// A vector expressed in frame `F` (a rate, an increment or a small rotation vector).
pub struct V3<F> {
    /// Components along the axes of `F`.
    pub v: Vector3<f64>,
    _frame: PhantomData<F>,
}

impl<F> Clone for V3<F> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<F> Copy for V3<F> {}
impl<F> fmt::Debug for V3<F> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "V3<{}>({}, {}, {})", short_type_name::<F>(), self.v.x, self.v.y, self.v.z)
    }
}

impl<F> V3<F> {
    /// FRAME: the caller states that `v` is expressed in `F`.
    #[must_use]
    pub fn new(v: Vector3<f64>) -> Self {
        Self { v, _frame: PhantomData }
    }

    /// The zero vector.
    #[must_use]
    pub fn zeros() -> Self {
        Self::new(Vector3::zeros())
    }
}

impl<F> Add for V3<F> {
    type Output = Self;
    fn add(self, rhs: Self) -> Self {
        Self::new(self.v + rhs.v)
    }
}

impl<F> Sub for V3<F> {
    type Output = Self;
    fn sub(self, rhs: Self) -> Self {
        Self::new(self.v - rhs.v)
    }
}

/// Rotation by `angle_rad` about the unit axis `axis` (right-handed, active).
#[must_use]
pub fn axis_angle(axis: &Vector3<f64>, angle_rad: f64) -> UnitQuaternion<f64> {
    let (s, c) = (0.5 * angle_rad).sin_cos();
    UnitQuaternion::new_unchecked(nalgebra::Quaternion::new(c, axis.x * s, axis.y * s, axis.z * s))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rot<To, From>(phi: [f64; 3]) -> Rot<To, From> {
        // FRAME: arbitrary test rotations between marker frames.
        Rot::from_quaternion(UnitQuaternion::from_scaled_axis(Vector3::from(phi)))
    }

    #[test]
    fn round_trip_through_inverse_is_identity() {
        let n_from_b: Rot<N, B> = rot([0.3, -1.2, 2.0]);
        let b_from_b = n_from_b.inverse() * n_from_b;
        assert!(b_from_b.angle_rad() < 1e-15);
        let n_from_n = n_from_b * n_from_b.inverse();
        assert!(n_from_n.angle_rad() < 1e-15);
    }

    #[test]
    fn chained_rotation_equals_sequential_application() {
        let n_from_b: Rot<N, B> = rot([0.1, 0.2, 0.3]);
        let b_from_s: Rot<B, S> = rot([-0.5, 0.4, 1.1]);
        let v_s: V3<S> = V3::new(Vector3::new(1.0, -2.0, 0.5));
        let chained = (n_from_b * b_from_s).apply(v_s);
        let sequential = n_from_b.apply(b_from_s.apply(v_s));
        assert!((chained.v - sequential.v).norm() < 1e-14);
    }

    #[test]
    fn axis_angle_matches_nalgebra() {
        // Independent computation: nalgebra's own axis-angle constructor.
        let axis = Vector3::new(1.0, 2.0, -0.5).normalize();
        let ours = axis_angle(&axis, 0.7);
        let theirs = UnitQuaternion::from_axis_angle(&nalgebra::Unit::new_normalize(axis), 0.7);
        assert!(ours.angle_to(&theirs) < 1e-15);
    }

    #[test]
    fn rotation_about_z_turns_east_into_north() {
        // A +90 deg rotation about up maps East (x) to North (y): right-handed, active.
        let q = axis_angle(&Vector3::z(), std::f64::consts::FRAC_PI_2);
        let v = q * Vector3::x();
        assert!((v - Vector3::y()).norm() < 1e-15);
    }
}
