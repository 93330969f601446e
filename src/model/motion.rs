//! Vehicle motion of b relative to n: a static attitude, scripted ramps of single Euler angles
//! (the rotary-table paper section 5), sinusoidal wobble per angle, and pure coning (the classical analytic test of
//! attitude algorithms). Pure functions of time, with their angular rates.

use nalgebra::{Quaternion, UnitQuaternion, Vector3};

use crate::math::attitude::Attitude;
use crate::math::frames::{axis_angle, Rot, B, N};
use crate::model::turning::Link;

/// Which Euler angle a ramp or a wobble drives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AngleKind {
    /// Nose up.
    Pitch,
    /// Right wing down.
    Roll,
    /// Clockwise from North.
    Heading,
}

impl AngleKind {
    fn index(self) -> usize {
        match self {
            Self::Pitch => 0,
            Self::Roll => 1,
            Self::Heading => 2,
        }
    }
}

/// Drive one angle from its value at `start_s` to `target_rad` at constant rate.
#[derive(Debug, Clone, Copy)]
pub struct Ramp {
    /// Driven angle.
    pub angle: AngleKind,
    /// Start time, s.
    pub start_s: f64,
    /// Target, rad.
    pub target_rad: f64,
    /// Rate magnitude, rad/s (> 0).
    pub rate_rad_per_s: f64,
}

/// `amplitude * sin(omega t + phase)` added to one angle.
#[derive(Debug, Clone, Copy)]
pub struct Wobble {
    /// Driven angle.
    pub angle: AngleKind,
    /// Amplitude, rad.
    pub amplitude_rad: f64,
    /// Angular frequency, rad/s.
    pub omega_rad_per_s: f64,
    /// Phase at t = 0, rad.
    pub phase_rad: f64,
}

/// Piecewise-linear angle history: knots (t, value), constant before the first and after the last.
#[derive(Debug, Clone, Default)]
struct Knots {
    t_s: Vec<f64>,
    value_rad: Vec<f64>,
}

impl Knots {
    fn value(&self, t: f64, base: f64) -> f64 {
        let n = self.t_s.len();
        if n == 0 || t <= self.t_s[0] {
            return if n == 0 { base } else { self.value_rad[0] };
        }
        if t >= self.t_s[n - 1] {
            return self.value_rad[n - 1];
        }
        // First knot strictly after t; n is small (a few ramps), partition_point is a binary search.
        let j = self.t_s.partition_point(|&tk| tk <= t);
        let (t0, t1) = (self.t_s[j - 1], self.t_s[j]);
        let (v0, v1) = (self.value_rad[j - 1], self.value_rad[j]);
        if t1 > t0 { v0 + (v1 - v0) * (t - t0) / (t1 - t0) } else { v1 }
    }

    /// Rate of change at `t` (right-hand slope at a knot).
    fn slope(&self, t: f64) -> f64 {
        let n = self.t_s.len();
        if n < 2 || t < self.t_s[0] || t >= self.t_s[n - 1] {
            return 0.0;
        }
        let j = self.t_s.partition_point(|&tk| tk <= t);
        let (t0, t1) = (self.t_s[j - 1], self.t_s[j]);
        if t1 > t0 { (self.value_rad[j] - self.value_rad[j - 1]) / (t1 - t0) } else { 0.0 }
    }

    /// First knot strictly after `t` (where the rate may jump).
    fn next_after(&self, t: f64) -> f64 {
        let j = self.t_s.partition_point(|&tk| tk <= t);
        self.t_s.get(j).copied().unwrap_or(f64::INFINITY)
    }

    fn max_abs(&self, base: f64) -> f64 {
        self.value_rad.iter().fold(base.abs(), |m, v| m.max(v.abs()))
    }
}

/// Pure coning of the body about its z axis: `n_from_b = E · K(t)` with
/// `K(t) = (cos α/2, sin α/2 cos Ωt, sin α/2 sin Ωt, 0)`, whose body rate is
/// `Ω (−sin α sin Ωt, sin α cos Ωt, −2 sin²(α/2))` (docs/coning.md).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coning {
    /// Cone half-angle α, rad.
    pub half_angle_rad: f64,
    /// Cone frequency Ω, rad/s.
    pub omega_rad_per_s: f64,
}

impl Coning {
    /// (cos α/2, sin α/2, sin α, 2 sin²(α/2)): the constants of [`Self::rotation`] and [`Self::rate`].
    fn constants(&self) -> [f64; 4] {
        let (s, c) = (0.5 * self.half_angle_rad).sin_cos();
        [c, s, self.half_angle_rad.sin(), 2.0 * s * s]
    }

    fn rotation(&self, k: &[f64; 4], t: f64) -> UnitQuaternion<f64> {
        let (so, co) = (self.omega_rad_per_s * t).sin_cos();
        UnitQuaternion::new_normalize(Quaternion::new(k[0], k[1] * co, k[1] * so, 0.0))
    }

    fn rate(&self, k: &[f64; 4], t: f64) -> Vector3<f64> {
        let (so, co) = (self.omega_rad_per_s * t).sin_cos();
        let w = self.omega_rad_per_s;
        Vector3::new(-w * k[2] * so, w * k[2] * co, -w * k[3])
    }
}

/// The vehicle's attitude over time.
#[derive(Debug, Clone)]
pub struct VehicleMotion {
    base: Attitude,
    knots: [Knots; 3],
    wobble: Vec<Wobble>,
    coning: Option<Coning>,
    /// The constants of the cone ([`Coning::constants`]), computed once.
    cone_constants: [f64; 4],
    /// C_b^n of the Euler part when it never changes (no ramp, no wobble), computed once.
    euler_fixed: Option<Rot<N, B>>,
}

impl VehicleMotion {
    /// Builds the motion; ramps of the same angle must not overlap in time.
    pub fn new(base: Attitude, mut ramps: Vec<Ramp>, wobble: Vec<Wobble>) -> Result<Self, String> {
        ramps.sort_by(|a, b| a.start_s.total_cmp(&b.start_s));
        let mut knots: [Knots; 3] = Default::default();
        let base_values = [base.pitch_rad, base.roll_rad, base.heading_rad];
        for r in &ramps {
            let k = &mut knots[r.angle.index()];
            let current = k.value_rad.last().copied().unwrap_or(base_values[r.angle.index()]);
            if let Some(&t_last) = k.t_s.last()
                && r.start_s < t_last
            {
                return Err(format!("a {:?} ramp starts at {} s, before the previous {:?} ramp ends at {} s", r.angle, r.start_s, r.angle, t_last));
            }
            let duration = (r.target_rad - current).abs() / r.rate_rad_per_s;
            k.t_s.push(r.start_s);
            k.value_rad.push(current);
            k.t_s.push(r.start_s + duration);
            k.value_rad.push(r.target_rad);
        }
        Ok(Self { base, knots, wobble, coning: None, cone_constants: [1.0, 0.0, 0.0, 0.0], euler_fixed: None }.with_constants())
    }

    /// A vehicle at rest at `base`.
    #[must_use]
    pub fn fixed(base: Attitude) -> Self {
        Self { base, knots: Default::default(), wobble: Vec::new(), coning: None, cone_constants: [1.0, 0.0, 0.0, 0.0], euler_fixed: None }.with_constants()
    }

    /// Computes the constant rotations and trigonometry once.
    fn with_constants(mut self) -> Self {
        self.cone_constants = self.coning.map_or([1.0, 0.0, 0.0, 0.0], |c| c.constants());
        let still = self.wobble.is_empty() && self.knots.iter().all(|k| k.t_s.is_empty());
        self.euler_fixed = still.then(|| self.base.n_from_b());
        self
    }

    /// The cone, when the motion is pure coning (no Euler-angle motion, no wobble on top): the
    /// classical test whose drift per algorithm has a closed form.
    #[must_use]
    pub fn pure_coning(&self) -> Option<Coning> {
        self.coning.filter(|_| self.euler_fixed.is_some())
    }

    /// Adds pure coning on top of the Euler-angle motion.
    #[must_use]
    pub fn with_coning(mut self, coning: Coning) -> Self {
        self.coning = (coning.half_angle_rad != 0.0 && coning.omega_rad_per_s != 0.0).then_some(coning);
        self.with_constants()
    }

    /// True when the vehicle never moves (no ramp, no wobble, no coning).
    #[must_use]
    pub fn is_fixed(&self) -> bool {
        self.wobble.is_empty() && self.knots.iter().all(|k| k.t_s.is_empty()) && self.coning.is_none()
    }

    /// Attitude at time `t_s`.
    #[must_use]
    pub fn attitude(&self, t_s: f64) -> Attitude {
        match self.coning {
            None => self.euler(t_s),
            Some(_) => Attitude::from_n_from_b(&self.n_from_b(t_s)),
        }
    }

    /// Euler angles and C_b^n at `t_s` (one evaluation for both).
    #[must_use]
    pub fn state(&self, t_s: f64) -> (Attitude, Rot<N, B>) {
        match self.coning {
            None => {
                let a = self.euler(t_s);
                (a, a.n_from_b())
            }
            Some(_) => {
                let r = self.n_from_b(t_s);
                (Attitude::from_n_from_b(&r), r)
            }
        }
    }

    /// C_b^n at `t_s`.
    #[must_use]
    pub fn n_from_b(&self, t_s: f64) -> Rot<N, B> {
        let e = self.euler_fixed.unwrap_or_else(|| self.euler(t_s).n_from_b());
        match self.coning {
            None => e,
            // FRAME: the coned body b is the Euler frame turned by the cone rotation K (body side).
            Some(c) => Rot::from_quaternion(*e.quaternion() * c.rotation(&self.cone_constants, t_s)),
        }
    }

    /// Angular rate of b relative to n, in b (rad/s).
    #[must_use]
    pub fn omega_nb_b(&self, t_s: f64) -> Vector3<f64> {
        if self.euler_fixed.is_some() {
            return self.coning.map_or_else(Vector3::zeros, |c| c.rate(&self.cone_constants, t_s));
        }
        let a = self.euler(t_s);
        let [dp, dr, dh] = self.euler_rates(t_s);
        // ω_nb^n = −z ψ̇ + Rz(−ψ) x θ̇ + Rz(−ψ) Rx(θ) y γ̇ (euler.rs, docs/closed-form.md §2).
        let rz = axis_angle(&Vector3::z(), -a.heading_rad);
        let rzx = rz * axis_angle(&Vector3::x(), a.pitch_rad);
        let w_n = -Vector3::z() * dh + rz * Vector3::x() * dp + rzx * Vector3::y() * dr;
        let w_e = a.n_from_b().quaternion().inverse() * w_n;
        match self.coning {
            None => w_e,
            Some(c) => c.rotation(&self.cone_constants, t_s).inverse() * w_e + c.rate(&self.cone_constants, t_s),
        }
    }

    /// C_b^n as links turning at constant rates from `t_s` to the next breakpoint (angles taken at
    /// `t_s`, τ counted from it, rates at `rates_at_s`, an instant inside the piece: at a breakpoint
    /// itself rounding may pick either side): `Rz(−ψ) · Rx(θ) · Ry(γ)` of the Euler angles, then the cone
    /// `K = Rz(Ωt) · Rx(α) · Rz(−Ωt)` (the rotation by α about (cos Ωt, sin Ωt, 0), the quaternion
    /// of [`Coning`]). None with a wobble (its angles are not linear in time).
    #[must_use]
    pub fn links_at(&self, t_s: f64, rates_at_s: f64) -> Option<Vec<Link>> {
        if !self.wobble.is_empty() {
            return None;
        }
        let a = self.euler(t_s);
        let [dp, dr, dh] = self.euler_rates(rates_at_s);
        let turning = |axis: Vector3<f64>, angle_rad: f64, rate_rad_per_s: f64| Link::Turning { axis, angle_rad, rate_rad_per_s };
        let mut links = vec![turning(Vector3::z(), -a.heading_rad, -dh), turning(Vector3::x(), a.pitch_rad, dp), turning(Vector3::y(), a.roll_rad, dr)];
        if let Some(c) = self.coning {
            links.push(Link::Cone { half_angle_rad: c.half_angle_rad, phase_rad: c.omega_rad_per_s * t_s, rate_rad_per_s: c.omega_rad_per_s });
        }
        Some(links)
    }

    /// (pitch, roll, heading) rates, rad/s.
    #[must_use]
    pub fn euler_rates(&self, t_s: f64) -> [f64; 3] {
        let mut r = [self.knots[0].slope(t_s), self.knots[1].slope(t_s), self.knots[2].slope(t_s)];
        for w in &self.wobble {
            r[w.angle.index()] += w.amplitude_rad * w.omega_rad_per_s * (w.omega_rad_per_s * t_s + w.phase_rad).cos();
        }
        r
    }

    /// Highest oscillation frequency of the motion (wobble, coning), rad/s.
    #[must_use]
    pub fn max_angular_frequency(&self) -> f64 {
        let w = self.wobble.iter().map(|w| w.omega_rad_per_s).fold(0.0, f64::max);
        w.max(self.coning.map_or(0.0, |c| c.omega_rad_per_s))
    }

    /// First time after `t_s` where a rate jumps (a ramp starts or ends).
    #[must_use]
    pub fn next_breakpoint_after(&self, t_s: f64) -> f64 {
        self.knots.iter().map(|k| k.next_after(t_s)).fold(f64::INFINITY, f64::min)
    }

    /// The Euler-angle part of the motion.
    #[must_use]
    pub fn euler(&self, t_s: f64) -> Attitude {
        let mut a = [
            self.knots[0].value(t_s, self.base.pitch_rad),
            self.knots[1].value(t_s, self.base.roll_rad),
            self.knots[2].value(t_s, self.base.heading_rad),
        ];
        for w in &self.wobble {
            a[w.angle.index()] += w.amplitude_rad * (w.omega_rad_per_s * t_s + w.phase_rad).sin();
        }
        Attitude { pitch_rad: a[0], roll_rad: a[1], heading_rad: a[2] }
    }

    /// An upper bound of |pitch| over the run (ramp extremes plus wobble amplitudes).
    #[must_use]
    pub fn max_abs_pitch_rad(&self, _duration_s: f64) -> f64 {
        let wobble: f64 = self.wobble.iter().filter(|w| w.angle == AngleKind::Pitch).map(|w| w.amplitude_rad).sum();
        self.knots[0].max_abs(self.base.pitch_rad) + wobble
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::units::RAD_PER_DEG;

    /// The rotary-table paper section 5: roll to 30 deg at 6 deg/s at 500 s, pitch to 30 deg at 1100 s,
    /// pitch back at 1700 s, roll back at 2300 s.
    fn seed004_profile() -> VehicleMotion {
        let ramp = |angle, start_s, target_deg: f64| Ramp { angle, start_s, target_rad: target_deg * RAD_PER_DEG, rate_rad_per_s: 6.0 * RAD_PER_DEG };
        VehicleMotion::new(
            Attitude::default(),
            vec![
                ramp(AngleKind::Roll, 500.0, 30.0),
                ramp(AngleKind::Pitch, 1100.0, 30.0),
                ramp(AngleKind::Pitch, 1700.0, 0.0),
                ramp(AngleKind::Roll, 2300.0, 0.0),
            ],
            vec![],
        )
        .expect("valid profile")
    }

    #[test]
    fn seed004_profile_reaches_its_plateaus() {
        let m = seed004_profile();
        let deg = |t| {
            let a = m.attitude(t);
            (a.pitch_rad / RAD_PER_DEG, a.roll_rad / RAD_PER_DEG)
        };
        let close = |a: (f64, f64), b: (f64, f64)| (a.0 - b.0).abs() < 1e-9 && (a.1 - b.1).abs() < 1e-9;
        assert!(close(deg(0.0), (0.0, 0.0)));
        // Halfway up the roll ramp: 2.5 s at 6 deg/s = 15 deg.
        assert!(close(deg(502.5), (0.0, 15.0)));
        assert!(close(deg(600.0), (0.0, 30.0)));
        assert!(close(deg(1200.0), (30.0, 30.0)));
        assert!(close(deg(2000.0), (0.0, 30.0)));
        assert!(close(deg(3599.0), (0.0, 0.0)));
    }

    #[test]
    fn overlapping_ramps_of_one_angle_are_rejected() {
        let ramp = |start_s| Ramp { angle: AngleKind::Roll, start_s, target_rad: 1.0, rate_rad_per_s: 0.01 };
        assert!(VehicleMotion::new(Attitude::default(), vec![ramp(0.0), ramp(10.0)], vec![]).is_err());
    }

    #[test]
    fn angular_rate_matches_the_derivative_of_the_attitude() {
        // Independent computation: finite differences of C_b^n, ω_b = log(C(t)ᵀ C(t+h)) / h.
        let m = VehicleMotion::new(
            Attitude { pitch_rad: 0.2, roll_rad: -0.3, heading_rad: 1.0 },
            vec![Ramp { angle: AngleKind::Roll, start_s: 0.0, target_rad: 1.0, rate_rad_per_s: 0.1 }],
            vec![Wobble { angle: AngleKind::Pitch, amplitude_rad: 0.1, omega_rad_per_s: 3.0, phase_rad: 0.2 }],
        )
        .expect("valid")
        .with_coning(Coning { half_angle_rad: 0.05, omega_rad_per_s: 20.0 });
        for t in [0.3, 1.7, 4.2] {
            let h = 1e-6;
            let a = m.n_from_b(t - h);
            let b = m.n_from_b(t + h);
            let fd = (a.inverse() * b).quaternion().scaled_axis() / (2.0 * h);
            let w = m.omega_nb_b(t);
            assert!((fd - w).norm() < 1e-6 * w.norm().max(1.0), "t={t}: {fd:?} vs {w:?}");
        }
    }

    #[test]
    fn wobble_adds_a_sinusoid() {
        let m = VehicleMotion::new(
            Attitude::default(),
            vec![],
            vec![Wobble { angle: AngleKind::Heading, amplitude_rad: 0.1, omega_rad_per_s: 2.0, phase_rad: 0.5 }],
        )
        .expect("valid");
        let t = 0.7;
        assert!((m.attitude(t).heading_rad - 0.1 * (2.0f64 * t + 0.5).sin()).abs() < 1e-15);
    }
}
