//! The gimbal chain from body to IMU: one model for single-, dual- and three-axis tables.
//!
//! Exact chain (docs/model.md), from the body outward:
//!
//! ```text
//! b_from_s = B · Π_k [ T_k · R(a_k, λ_k) · W_k ] · M
//! ```
//!
//! - `B`   installation error: rotation of the table base on the body (the rotary-table paper section 3.1);
//! - `T_k` non-orthogonality: axis k tilted by η_k toward axis k-1, about (a_k × a_{k-1}) (Jiang et al. 2017 Fig. 4c);
//! - `R(a_k, λ_k)` the shaft rotation by the true gimbal angle about the nominal axis a_k;
//! - `W_k` swing cone: a rotor-fixed tilt of half-angle α_k and phase φ_k, i.e. in the parent frame the
//!   rotation vector α_k (cos(λ_k+φ_k) e1 + sin(λ_k+φ_k) e2), turning with the shaft (Jiang et al. 2017 eq. 4-7,
//!   the rotary-table paper section 3.2);
//! - `M`   IMU mounting error on the last gimbal.
//!
//! All error rotations are exact (exponential map); the small-angle forms live only in
//! [`Chain::first_order_phi_b`], the closed-form model.

use nalgebra::{UnitQuaternion, Vector3};

use crate::math::frames::{B, Rot, S, V3, axis_angle};
use crate::math::rotvec;
use crate::model::scheme::{AxisValues, MAX_AXES};
use crate::model::turning::Link;

/// Nominal geometry of one gimbal axis.
#[derive(Debug, Clone)]
pub struct AxisGeometry {
    /// Name used in configs and the recording.
    pub name: String,
    /// Nominal rotation axis, unit, in the parent frame.
    pub axis: Vector3<f64>,
    /// First reference direction perpendicular to `axis` (cyclic: z -> x, y -> z, x -> y).
    pub e1: Vector3<f64>,
    /// Second reference direction: `axis × e1`.
    pub e2: Vector3<f64>,
    /// Gimbal angle at t = 0, rad.
    pub initial_angle_rad: f64,
}

impl AxisGeometry {
    /// An axis along `axis` (a unit coordinate vector) with its cyclic reference directions.
    #[must_use]
    pub fn new(name: String, axis: Vector3<f64>, initial_angle_rad: f64) -> Self {
        // Cyclic successor: for z the swing components are along (x, y) as in Jiang et al. 2017 eq. 4-5.
        let e1 = Vector3::new(axis.z, axis.x, axis.y);
        let e2 = axis.cross(&e1);
        Self { name, axis, e1, e2, initial_angle_rad }
    }
}

/// Errors of one axis.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct AxisErrors {
    /// Swing-cone half-angle α, rad.
    pub swing_half_angle_rad: f64,
    /// Swing-cone initial phase φ, rad.
    pub swing_phase_rad: f64,
    /// Tilt toward the previous axis η, rad (0 on the first axis).
    pub non_orthogonality_rad: f64,
    /// Encoder constant offset, rad.
    pub encoder_offset_rad: f64,
    /// Encoder scale-factor error (dimensionless; 1e-6 = 1 ppm).
    pub encoder_scale: f64,
    /// Encoder latch time behind the IMU sample, s.
    pub encoder_delay_s: f64,
    /// Encoder white noise, 1σ per reading, rad (Jiang et al. 2017 Table 1: "Turntable (1σ) 12″").
    pub encoder_noise_rad: f64,
}

impl AxisErrors {
    /// The reading of an encoder whose shaft was at `angle_at_latch_rad` when latched.
    #[must_use]
    pub fn encoder_reading(&self, angle_at_latch_rad: f64) -> f64 {
        (1.0 + self.encoder_scale) * angle_at_latch_rad + self.encoder_offset_rad
    }

    /// Inverse of [`Self::encoder_reading`] with these (assumed) parameters.
    #[must_use]
    pub fn encoder_correct(&self, reading_rad: f64) -> f64 {
        (reading_rad - self.encoder_offset_rad) / (1.0 + self.encoder_scale)
    }
}

/// All turntable errors: a truth, an assumption for compensation, or a drawing (exaggerated).
#[derive(Debug, Clone, PartialEq)]
pub struct TableErrors {
    /// Installation rotation vector of the base on the body, rad, body axes.
    pub installation_rad: Vector3<f64>,
    /// IMU mounting rotation vector on the last gimbal, rad.
    pub imu_mount_rad: Vector3<f64>,
    /// Per axis, from the body outward.
    pub axes: Vec<AxisErrors>,
}

/// One number per geometric error class (a drawing factor, or a size).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClassFactors {
    /// Shaft swing cones.
    pub swing: f64,
    /// Axis non-orthogonality.
    pub non_orthogonality: f64,
    /// Installation of the base on the body.
    pub installation: f64,
    /// IMU mounting on the last gimbal.
    pub imu_mount: f64,
}

impl ClassFactors {
    /// The same factor for every class.
    #[must_use]
    pub fn uniform(x: f64) -> Self {
        Self { swing: x, non_orthogonality: x, installation: x, imu_mount: x }
    }
}

impl TableErrors {
    /// No error at all on `n_axes` axes.
    #[must_use]
    pub fn zero(n_axes: usize) -> Self {
        Self {
            installation_rad: Vector3::zeros(),
            imu_mount_rad: Vector3::zeros(),
            axes: vec![AxisErrors::default(); n_axes],
        }
    }

    /// Every geometric error angle multiplied by its class's factor (encoder errors dropped): what
    /// the 3D scene draws.
    #[must_use]
    pub fn exaggerated(&self, f: &ClassFactors) -> Self {
        Self {
            installation_rad: self.installation_rad * f.installation,
            imu_mount_rad: self.imu_mount_rad * f.imu_mount,
            axes: self
                .axes
                .iter()
                .map(|a| AxisErrors {
                    swing_half_angle_rad: a.swing_half_angle_rad * f.swing,
                    swing_phase_rad: a.swing_phase_rad,
                    non_orthogonality_rad: a.non_orthogonality_rad * f.non_orthogonality,
                    ..AxisErrors::default()
                })
                .collect(),
        }
    }

    /// The largest angle of each geometric error class, rad: swing half-angle, non-orthogonality,
    /// installation, IMU mounting.
    #[must_use]
    pub fn class_sizes(&self) -> ClassFactors {
        let max = |f: &dyn Fn(&AxisErrors) -> f64| self.axes.iter().map(|a| f(a).abs()).fold(0.0, f64::max);
        ClassFactors {
            swing: max(&|a| a.swing_half_angle_rad),
            non_orthogonality: max(&|a| a.non_orthogonality_rad),
            installation: self.installation_rad.norm(),
            imu_mount: self.imu_mount_rad.norm(),
        }
    }

    /// Every error angle (geometric and encoder offset) multiplied by `factor`; scale and delay too.
    #[must_use]
    pub fn scaled(&self, factor: f64) -> Self {
        Self {
            installation_rad: self.installation_rad * factor,
            imu_mount_rad: self.imu_mount_rad * factor,
            axes: self
                .axes
                .iter()
                .map(|a| AxisErrors {
                    swing_half_angle_rad: a.swing_half_angle_rad * factor,
                    swing_phase_rad: a.swing_phase_rad,
                    non_orthogonality_rad: a.non_orthogonality_rad * factor,
                    encoder_offset_rad: a.encoder_offset_rad * factor,
                    encoder_scale: a.encoder_scale * factor,
                    encoder_delay_s: a.encoder_delay_s * factor,
                    encoder_noise_rad: a.encoder_noise_rad * factor,
                })
                .collect(),
        }
    }
}

/// The constant error rotations of a [`TableErrors`] on a [`Chain`], precomputed for the hot path.
#[derive(Debug, Clone)]
pub struct ErrorRotations {
    installation: UnitQuaternion<f64>,
    mount: UnitQuaternion<f64>,
    tilt: [UnitQuaternion<f64>; MAX_AXES],
    swing_rotor: [UnitQuaternion<f64>; MAX_AXES],
    /// The constants between the shafts, folded: `B·T_0`, `W_0·T_1`, …, `W_{N-1}·M`.
    between: [UnitQuaternion<f64>; MAX_AXES + 1],
    /// (sin φ_k, cos φ_k) of each swing phase, for the closed form.
    swing_phase_sin_cos: [(f64, f64); MAX_AXES],
}

/// Local transforms of every link, parent_from_child, for drawing the chain.
#[derive(Debug, Clone)]
pub struct LinkRotations {
    /// body_from_base: the installation error.
    pub base: UnitQuaternion<f64>,
    /// parent_from_mount of each axis: the non-orthogonality tilt T_k.
    pub mount: [UnitQuaternion<f64>; MAX_AXES],
    /// mount_from_gimbal of each axis: R(a_k, λ_k) · W_k.
    pub gimbal: [UnitQuaternion<f64>; MAX_AXES],
    /// last_gimbal_from_s: the IMU mounting.
    pub imu: UnitQuaternion<f64>,
}

/// The nominal gimbal chain.
#[derive(Debug, Clone)]
pub struct Chain {
    axes: Vec<AxisGeometry>,
}

impl Chain {
    /// A chain of 1..=3 axes from the body outward.
    #[must_use]
    pub fn new(axes: Vec<AxisGeometry>) -> Self {
        assert!(!axes.is_empty() && axes.len() <= MAX_AXES, "1..=3 axes");
        Self { axes }
    }

    /// The axes from the body outward.
    #[must_use]
    pub fn axes(&self) -> &[AxisGeometry] {
        &self.axes
    }

    /// Index of the axis named `name`.
    #[must_use]
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.axes.iter().position(|a| a.name == name)
    }

    /// Unit rotation axis of the non-orthogonality tilt of axis k (k >= 1): a_k × a_{k-1}, so that a
    /// positive η turns a_k toward a_{k-1} (the angle between them becomes 90° - η).
    #[must_use]
    pub fn non_orthogonality_axis(&self, k: usize) -> Vector3<f64> {
        if k == 0 {
            return Vector3::zeros();
        }
        self.axes[k].axis.cross(&self.axes[k - 1].axis)
    }

    /// Rotation vector of the tilt T_k, rad, in the parent (gimbal k-1) frame.
    #[must_use]
    pub fn tilt_vector(&self, k: usize, e: &AxisErrors) -> Vector3<f64> {
        self.non_orthogonality_axis(k) * e.non_orthogonality_rad
    }

    /// Swing rotation vector of axis k, rad, in its mount frame, at shaft angle `angle_rad`:
    /// α (cos(λ+φ) e1 + sin(λ+φ) e2). At λ = 0 this is also its (constant) value in the rotor frame.
    #[must_use]
    pub fn swing_vector(&self, k: usize, e: &AxisErrors, angle_rad: f64) -> Vector3<f64> {
        let g = &self.axes[k];
        let (s, c) = (angle_rad + e.swing_phase_rad).sin_cos();
        (g.e1 * c + g.e2 * s) * e.swing_half_angle_rad
    }

    /// Precomputes the constant rotations of `errors`.
    #[must_use]
    pub fn error_rotations(&self, errors: &TableErrors) -> ErrorRotations {
        assert_eq!(errors.axes.len(), self.axes.len(), "one AxisErrors per axis");
        let mut tilt = [UnitQuaternion::identity(); MAX_AXES];
        let mut swing_rotor = [UnitQuaternion::identity(); MAX_AXES];
        for (k, e) in errors.axes.iter().enumerate() {
            tilt[k] = rotvec::exp(&self.tilt_vector(k, e));
            swing_rotor[k] = rotvec::exp(&self.swing_vector(k, e, 0.0));
        }
        let installation = rotvec::exp(&errors.installation_rad);
        let mount = rotvec::exp(&errors.imu_mount_rad);
        let n = self.axes.len();
        let mut between = [UnitQuaternion::identity(); MAX_AXES + 1];
        between[0] = installation * tilt[0];
        for k in 1..n {
            between[k] = swing_rotor[k - 1] * tilt[k];
        }
        between[n] = swing_rotor[n - 1] * mount;
        let mut swing_phase_sin_cos = [(0.0, 1.0); MAX_AXES];
        for (sc, e) in swing_phase_sin_cos.iter_mut().zip(&errors.axes) {
            *sc = e.swing_phase_rad.sin_cos();
        }
        ErrorRotations { installation, mount, tilt, swing_rotor, between, swing_phase_sin_cos }
    }

    /// The shaft rotations R(a_k, λ_k) for gimbal angles `angles_rad` (computed once per step and
    /// shared by the exact, nominal and closed-form chains).
    #[must_use]
    pub fn shaft_rotations(&self, angles_rad: &AxisValues) -> ShaftRotations {
        let mut r = [UnitQuaternion::identity(); MAX_AXES];
        for (k, g) in self.axes.iter().enumerate() {
            r[k] = axis_angle(&g.axis, angles_rad[k]);
        }
        ShaftRotations(r)
    }

    /// Exact IMU-to-body rotation for gimbal angles `angles_rad` and the given error rotations.
    #[must_use]
    pub fn b_from_s(&self, err: &ErrorRotations, angles_rad: &AxisValues) -> Rot<B, S> {
        self.b_from_s_with(err, &self.shaft_rotations(angles_rad))
    }

    /// [`Self::b_from_s`] with precomputed shaft rotations.
    #[must_use]
    pub fn b_from_s_with(&self, err: &ErrorRotations, shafts: &ShaftRotations) -> Rot<B, S> {
        // B·T_0·R_0·W_0·T_1·R_1·…·W_{N-1}·M with the constant neighbours folded together.
        let n = self.axes.len();
        let mut q = err.between[0];
        for k in 0..n {
            q = q * shafts.0[k] * err.between[k + 1];
        }
        // FRAME: the chain composes body <- base <- gimbals <- IMU link by link (module doc).
        Rot::from_quaternion(q)
    }

    /// [`Self::b_from_s_with`] and the angular rate of s relative to b, in s, for gimbal rates
    /// `rates_rad_per_s`: `ω_bs^s = Σ_k λ̇_k Q_kᵀ a_k` with Q_k everything in the chain after shaft k.
    #[must_use]
    pub fn b_from_s_and_rate(
        &self,
        err: &ErrorRotations,
        shafts: &ShaftRotations,
        rates_rad_per_s: &AxisValues,
    ) -> (Rot<B, S>, V3<S>) {
        let n = self.axes.len();
        let mut suffix = err.between[n];
        let mut omega = Vector3::zeros();
        for k in (0..n).rev() {
            omega += suffix.inverse() * (self.axes[k].axis * rates_rad_per_s[k]);
            suffix = err.between[k] * shafts.0[k] * suffix;
        }
        // FRAME: `suffix` is now the whole chain B·T_0·R_0·…·M = b_from_s; ω summed in s.
        (Rot::from_quaternion(suffix), V3::new(omega))
    }

    /// The exact chain `b_from_s` as links for shafts at `angles_rad` turning at the constant
    /// `rates_rad_per_s` (the constants between the shafts folded, as in [`Self::b_from_s_with`]).
    #[must_use]
    pub fn links(&self, err: &ErrorRotations, angles_rad: &AxisValues, rates_rad_per_s: &AxisValues) -> Vec<Link> {
        let n = self.axes.len();
        let mut links = vec![Link::Fixed(err.between[0])];
        for k in 0..n {
            links.push(Link::Turning {
                axis: self.axes[k].axis,
                angle_rad: angles_rad[k],
                rate_rad_per_s: rates_rad_per_s[k],
            });
            links.push(Link::Fixed(err.between[k + 1]));
        }
        links
    }

    /// The nominal (error-free) IMU-to-body rotation a real RINS uses to demodulate.
    #[must_use]
    pub fn b_from_s_nominal(&self, angles_rad: &AxisValues) -> Rot<B, S> {
        self.b_from_s_nominal_with(&self.shaft_rotations(angles_rad))
    }

    /// [`Self::b_from_s_nominal`] with precomputed shaft rotations.
    #[must_use]
    pub fn b_from_s_nominal_with(&self, shafts: &ShaftRotations) -> Rot<B, S> {
        let mut q = shafts.0[0];
        for r in &shafts.0[1..self.axes.len()] {
            q *= r;
        }
        // FRAME: the same chain with every error rotation set to identity.
        Rot::from_quaternion(q)
    }

    /// Each link's local rotation, for drawing the chain as an entity tree.
    #[must_use]
    pub fn link_rotations(&self, err: &ErrorRotations, angles_rad: &AxisValues) -> LinkRotations {
        let mut gimbal = [UnitQuaternion::identity(); MAX_AXES];
        for (k, g) in self.axes.iter().enumerate() {
            gimbal[k] = axis_angle(&g.axis, angles_rad[k]) * err.swing_rotor[k];
        }
        LinkRotations { base: err.installation, mount: err.tilt, gimbal, imu: err.mount }
    }

    /// Closed-form (first-order) body-frame attitude error Φ_b of the nominal demodulation, where the
    /// computed attitude is `exp([C_b^n Φ_b ×]) C_b^n` (docs/closed-form.md):
    ///
    /// ```text
    /// Φ_b = ι + Σ_k P_k [ t_k + (λ_k - λ̂_k) a_k + α_k (cos(λ_k+φ_k) e1_k + sin(λ_k+φ_k) e2_k) ] + P_{N+1} m
    /// ```
    /// with P_k the nominal rotation of the axes before k, ι the installation vector, t_k the tilt
    /// vector, m the mounting vector, and the encoder error λ̂_k - λ_k ≈ b_k + s_k λ_k - λ̇_k τ_k.
    #[must_use]
    pub fn first_order_phi_b(
        &self,
        errors: &TableErrors,
        angles_rad: &AxisValues,
        rates_rad_per_s: &AxisValues,
    ) -> V3<B> {
        self.first_order_phi_b_with(
            errors,
            &self.error_rotations(errors),
            angles_rad,
            rates_rad_per_s,
            &self.shaft_rotations(angles_rad),
        )
    }

    /// [`Self::first_order_phi_b`] with the shaft rotations of `angles_rad` and the error rotations of
    /// `errors` precomputed (the hot path: no trigonometry beyond the shafts').
    #[must_use]
    pub fn first_order_phi_b_with(
        &self,
        errors: &TableErrors,
        err: &ErrorRotations,
        angles_rad: &AxisValues,
        rates_rad_per_s: &AxisValues,
        shafts: &ShaftRotations,
    ) -> V3<B> {
        let mut phi = errors.installation_rad;
        let mut prefix = UnitQuaternion::identity();
        for (k, (g, e)) in self.axes.iter().zip(&errors.axes).enumerate() {
            let lambda = angles_rad[k];
            let encoder_error =
                e.encoder_offset_rad + e.encoder_scale * lambda - rates_rad_per_s[k] * e.encoder_delay_s;
            let mut local = self.tilt_vector(k, e) - g.axis * encoder_error;
            if e.swing_half_angle_rad != 0.0 {
                // sin λ, cos λ from the shaft quaternion (cos λ/2, sin λ/2 · a), then λ + φ by addition.
                let q = shafts.0[k];
                let (c, s) = (q.w, q.imag().dot(&g.axis));
                let (sin_l, cos_l) = (2.0 * c * s, c * c - s * s);
                let (sin_p, cos_p) = err.swing_phase_sin_cos[k];
                let (sin_lp, cos_lp) = (sin_l * cos_p + cos_l * sin_p, cos_l * cos_p - sin_l * sin_p);
                local += (g.e1 * cos_lp + g.e2 * sin_lp) * e.swing_half_angle_rad;
            }
            phi += prefix * local;
            prefix *= shafts.0[k];
        }
        phi += prefix * errors.imu_mount_rad;
        // FRAME: every term was carried into the body frame by its nominal prefix rotation.
        V3::new(phi)
    }
}

/// The shaft rotations R(a_k, λ_k) of one set of gimbal angles.
#[derive(Debug, Clone, Copy)]
pub struct ShaftRotations(pub [UnitQuaternion<f64>; MAX_AXES]);

/// The latest rotations C_b^s of one chain with one set of error rotations, and the angles each
/// was computed for (at most `capacity`, the oldest dropped): outputs demodulated at the same
/// angles (several algorithms at one instant, a table at rest or in a dwell) cost one chain
/// evaluation, not one each.
#[derive(Debug, Clone)]
pub struct ChainMemo {
    capacity: usize,
    entries: Vec<(AxisValues, Rot<B, S>)>,
}

impl ChainMemo {
    /// An empty memo keeping `capacity` (at least 1) rotations.
    #[must_use]
    pub fn new(capacity: usize) -> Self {
        Self { capacity: capacity.max(1), entries: Vec::new() }
    }

    /// `chain.b_from_s(err, angles)`, from the memo when these angles were asked for lately (the
    /// caller passes the same `chain` and `err` every time). The newest entry is looked at first.
    #[inline]
    pub fn get(&mut self, chain: &Chain, err: &ErrorRotations, angles: &AxisValues) -> Rot<B, S> {
        if let Some((_, b_from_s)) = self.entries.iter().rev().find(|(a, _)| a == angles) {
            return *b_from_s;
        }
        let b_from_s = chain.b_from_s(err, angles);
        if self.entries.len() == self.capacity {
            self.entries.remove(0);
        }
        self.entries.push((*angles, b_from_s));
        b_from_s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::units::{RAD_PER_ARCMIN, RAD_PER_ARCSEC, RAD_PER_DEG};

    fn dual_axis() -> Chain {
        Chain::new(vec![
            AxisGeometry::new("outer".into(), Vector3::y(), 0.0),
            AxisGeometry::new("inner".into(), Vector3::z(), 0.0),
        ])
    }

    fn seed000_errors() -> TableErrors {
        // Jiang et al. 2017 Table 2 (alpha2 read as 10', see seeds/README.md).
        let mut e = TableErrors::zero(2);
        e.axes[0].swing_half_angle_rad = 10.0 * RAD_PER_ARCMIN;
        e.axes[0].swing_phase_rad = RAD_PER_DEG;
        e.axes[1].swing_half_angle_rad = 5.0 * RAD_PER_ARCMIN;
        e.axes[1].swing_phase_rad = RAD_PER_DEG;
        e.axes[1].non_orthogonality_rad = 20.0 * RAD_PER_ARCSEC;
        e
    }

    #[test]
    fn reference_directions_are_right_handed() {
        for a in [Vector3::x(), Vector3::y(), Vector3::z()] {
            let g = AxisGeometry::new("a".into(), a, 0.0);
            assert!((g.e1.cross(&g.e2) - a).norm() < 1e-15);
            assert!(g.e1.dot(&a).abs() < 1e-15);
        }
        // z-axis swing components are along x then y (Jiang et al. 2017 eq. 4-5).
        let g = AxisGeometry::new("inner".into(), Vector3::z(), 0.0);
        assert_eq!(g.e1, Vector3::x());
        assert_eq!(g.e2, Vector3::y());
    }

    #[test]
    fn zero_errors_give_the_nominal_chain() {
        let chain = dual_axis();
        let rot = chain.error_rotations(&TableErrors::zero(2));
        let angles = [0.7, -2.1, 0.0];
        let exact = chain.b_from_s(&rot, &angles);
        let nominal = chain.b_from_s_nominal(&angles);
        assert!((exact.inverse() * nominal).angle_rad() < 1e-15);
    }

    #[test]
    fn non_orthogonality_tilts_the_inner_axis_toward_the_outer() {
        // η = 1 deg: the angle between the inner axis and the outer axis becomes 89 deg.
        let chain = dual_axis();
        let mut e = TableErrors::zero(2);
        e.axes[1].non_orthogonality_rad = RAD_PER_DEG;
        let rot = chain.error_rotations(&e);
        let links = chain.link_rotations(&rot, &[0.0; 3]);
        let inner_axis_in_outer = links.mount[1] * Vector3::z();
        let angle = inner_axis_in_outer.dot(&Vector3::y()).acos();
        assert!((angle - 89.0 * RAD_PER_DEG).abs() < 1e-12);
    }

    #[test]
    fn swing_cone_axis_traces_a_cone_of_the_right_half_angle() {
        // The rotor's own axis stays at α from the nominal axis for every shaft angle, and its tilt
        // direction turns with the shaft (the cone is swept once per revolution).
        let chain = dual_axis();
        let mut e = TableErrors::zero(2);
        e.axes[1].swing_half_angle_rad = 2.0 * RAD_PER_DEG;
        e.axes[1].swing_phase_rad = 30.0 * RAD_PER_DEG;
        let rot = chain.error_rotations(&e);
        for deg in [0.0, 45.0, 90.0, 200.0] {
            let lambda = deg * RAD_PER_DEG;
            let links = chain.link_rotations(&rot, &[0.0, lambda, 0.0]);
            let rotor_axis = links.gimbal[1] * Vector3::z();
            assert!((rotor_axis.dot(&Vector3::z()).acos() - 2.0 * RAD_PER_DEG).abs() < 1e-12);
            // Rotating z about u = (cos ψ, sin ψ, 0), ψ = λ+φ, leans it toward u × z = (sin ψ, -cos ψ, 0),
            // i.e. in direction ψ - 90°: perpendicular to the rotation vector, turning with the shaft.
            let lean = rotor_axis.y.atan2(rotor_axis.x);
            let expected = crate::math::units::wrap_pi(lambda + 30.0 * RAD_PER_DEG - std::f64::consts::FRAC_PI_2);
            assert!(crate::math::units::wrap_pi(lean - expected).abs() < 1e-12, "deg {deg}");
        }
    }

    #[test]
    fn closed_form_agrees_with_exact_to_second_order() {
        // Halving every error angle must cut the exact-minus-linear residual by ~4 (second order),
        // while the error itself halves (first order).
        let chain = dual_axis();
        let base = seed000_errors();
        let mut base = base;
        base.installation_rad = Vector3::new(3.0, -2.0, 1.0) * RAD_PER_ARCMIN;
        base.imu_mount_rad = Vector3::new(-1.0, 2.0, 0.5) * RAD_PER_ARCMIN;
        base.axes[0].encoder_offset_rad = 30.0 * RAD_PER_ARCSEC;
        base.axes[1].encoder_scale = 50e-6;
        let angles = [0.8, 2.3, 0.0];
        let residual = |f: f64| {
            let e = base.scaled(f);
            // The nominal chain sees the encoder readings, the true chain the true angles.
            let mut readings = [0.0; MAX_AXES];
            for (k, ax) in e.axes.iter().enumerate() {
                readings[k] = ax.encoder_reading(angles[k]);
            }
            let exact =
                chain.b_from_s(&chain.error_rotations(&e), &angles) * chain.b_from_s_nominal(&readings).inverse();
            let exact_vec = exact.quaternion().scaled_axis();
            let linear = chain.first_order_phi_b(&e, &angles, &[0.0; 3]).v;
            ((exact_vec - linear).norm(), exact_vec.norm())
        };
        let (r1, m1) = residual(1.0);
        let (r2, m2) = residual(0.5);
        assert!((m1 / m2 - 2.0).abs() < 0.01, "first order: {m1} / {m2}");
        assert!((r1 / r2 - 4.0).abs() < 0.2, "second order: {r1} / {r2}");
        // And the residual is tiny compared with the error (ratio ~ error angle ~ 1e-3).
        assert!(r1 < 5e-3 * m1, "{r1} vs {m1}");
    }

    #[test]
    fn gimbal_rate_matches_the_derivative_of_the_chain() {
        // Independent computation: finite difference of the exact chain along a gimbal trajectory.
        let chain = dual_axis();
        let rot = chain.error_rotations(&seed000_errors());
        let (a0, rates) = ([0.4, -1.2, 0.0], [0.3, -0.7, 0.0]);
        let at = |t: f64| {
            let mut a = a0;
            for k in 0..2 {
                a[k] += rates[k] * t;
            }
            chain.b_from_s(&rot, &a)
        };
        let h = 1e-6;
        let fd = (at(-h).inverse() * at(h)).quaternion().scaled_axis() / (2.0 * h);
        let (b_from_s, w) = chain.b_from_s_and_rate(&rot, &chain.shaft_rotations(&a0), &rates);
        assert!((fd - w.v).norm() < 1e-8, "{fd:?} vs {:?}", w.v);
        assert!((b_from_s.inverse() * at(0.0)).angle_rad() < 1e-14);
    }

    #[test]
    fn encoder_model_inverts() {
        let e = AxisErrors { encoder_offset_rad: 1e-4, encoder_scale: 2e-5, ..AxisErrors::default() };
        for a in [-10.0, 0.0, 3.0, 100.0] {
            assert!((e.encoder_correct(e.encoder_reading(a)) - a).abs() < 1e-12);
        }
    }
}
