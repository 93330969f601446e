//! Vehicle motion of b relative to n: a static attitude, scripted ramps of single Euler angles
//! (the rotary-table paper section 5), sinusoidal wobble per angle, and pure coning (the classical analytic test of
//! attitude algorithms). Pure functions of time, with their angular rates.

use nalgebra::{Quaternion, UnitQuaternion, Vector3};

use crate::math::attitude::Attitude;
use crate::math::frames::{B, N, Rot, axis_angle};
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
    /// (cos α/2, sin α/2, sin α, 2 sin²(α/2)) of half-angle `alpha`: the constants of the cone's
    /// rotation and rate.
    fn constants_of(alpha: f64) -> [f64; 4] {
        let (s, c) = (0.5 * alpha).sin_cos();
        [c, s, alpha.sin(), 2.0 * s * s]
    }

    fn constants(&self) -> [f64; 4] {
        Self::constants_of(self.half_angle_rad)
    }
}

/// An oscillation (a cone, a wobble) changed while the body was moving (a live session): it goes
/// on from where the body is. Its size (the cone's half-angle, the wobble's amplitude) and its
/// angular frequency ease from the old values to the new over [`CONE_RAMP_S`] along
/// s(u) = (1 − cos πu)/2, and its phase is their integral — the attitude, the rate and the rate's
/// start and end are continuous (a jump in either would be a motion no real body makes: the INS
/// would integrate a jump it never felt, or the algorithms that use previous samples would see a
/// step in the rate). docs/coning.md, "A cone that changes".
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transition {
    /// Start and end, s.
    pub start_s: f64,
    /// End of the transition, s.
    pub end_s: f64,
    /// The phase at the start, rad.
    pub phase_rad: f64,
    /// Size and angular frequency at the start (rad, rad/s).
    pub from: (f64, f64),
    /// Size and angular frequency from the end on.
    pub to: (f64, f64),
}

impl Transition {
    /// (size, its rate, phase, its rate = the angular frequency) at `t_s` ≥ `start_s`.
    #[must_use]
    pub fn at(&self, t_s: f64) -> (f64, f64, f64, f64) {
        let span = self.end_s - self.start_s;
        let tau = (t_s - self.start_s).max(0.0);
        let (da, dw) = (self.to.0 - self.from.0, self.to.1 - self.from.1);
        if tau >= span {
            // ∫ s over the whole transition is span/2.
            let phase_end = self.phase_rad + self.from.1 * span + dw * 0.5 * span;
            return (self.to.0, 0.0, phase_end + self.to.1 * (tau - span), self.to.1);
        }
        let u = std::f64::consts::PI * tau / span;
        let s = 0.5 * (1.0 - u.cos());
        let s_dot = 0.5 * std::f64::consts::PI / span * u.sin();
        let integral_s = 0.5 * tau - span / (2.0 * std::f64::consts::PI) * u.sin();
        (self.from.0 + da * s, da * s_dot, self.phase_rad + self.from.1 * tau + dw * integral_s, self.from.1 + dw * s)
    }
}

/// How long a changed cone or wobble takes to reach its new size and frequency, s.
pub const CONE_RAMP_S: f64 = 1.0;

/// The vehicle's attitude over time.
#[derive(Debug, Clone)]
pub struct VehicleMotion {
    base: Attitude,
    knots: [Knots; 3],
    wobble: Vec<Wobble>,
    /// Per wobble, its change in a running session ([`Self::continuing_from`]).
    wobble_ramps: Vec<Option<Transition>>,
    coning: Option<Coning>,
    /// The constants of the cone ([`Coning::constants`]), computed once.
    cone_constants: [f64; 4],
    /// A cone changed in a running session.
    cone_continuation: Option<Transition>,
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
                return Err(format!(
                    "a {:?} ramp starts at {} s, before the previous {:?} ramp ends at {} s",
                    r.angle, r.start_s, r.angle, t_last
                ));
            }
            let duration = (r.target_rad - current).abs() / r.rate_rad_per_s;
            k.t_s.push(r.start_s);
            k.value_rad.push(current);
            k.t_s.push(r.start_s + duration);
            k.value_rad.push(r.target_rad);
        }
        Ok(Self {
            base,
            knots,
            wobble_ramps: vec![None; wobble.len()],
            wobble,
            coning: None,
            cone_constants: [1.0, 0.0, 0.0, 0.0],
            cone_continuation: None,
            euler_fixed: None,
        }
        .with_constants())
    }

    /// A vehicle at rest at `base`.
    #[must_use]
    pub fn fixed(base: Attitude) -> Self {
        Self {
            base,
            knots: Default::default(),
            wobble: Vec::new(),
            wobble_ramps: Vec::new(),
            coning: None,
            cone_constants: [1.0, 0.0, 0.0, 0.0],
            cone_continuation: None,
            euler_fixed: None,
        }
        .with_constants()
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

    /// Whether the body is coned (its attitude is C_b^n, without Euler angles of its own:
    /// [`Self::n_from_b_and_euler`] gives None for them).
    #[must_use]
    pub fn is_coned(&self) -> bool {
        self.coning.is_some()
    }

    /// Adds pure coning on top of the Euler-angle motion.
    #[must_use]
    pub fn with_coning(mut self, coning: Coning) -> Self {
        self.coning = (coning.half_angle_rad != 0.0 && coning.omega_rad_per_s != 0.0).then_some(coning);
        self.with_constants()
    }

    /// This motion continued from `old`'s at `t_s` (a live session's reload): its cone and each
    /// wobble that drives the same angle as `old`'s at the same place in the list go from `old`'s
    /// size and frequency to this one's through a [`Transition`] — the body goes on from where it
    /// is. A cone set to zero (half-angle or frequency) eases down to a standstill; a cone where
    /// there was none eases up from zero.
    #[must_use]
    pub fn continuing_from(mut self, old: &Self, t_s: f64) -> Self {
        for i in 0..self.wobble.len() {
            if old.wobble.get(i).is_none_or(|o| o.angle != self.wobble[i].angle) {
                continue;
            }
            let (amplitude, _, phase, omega) = old.wobble_state(i, t_s);
            let w = &self.wobble[i];
            self.wobble_ramps[i] = Some(Transition {
                start_s: t_s,
                end_s: t_s + CONE_RAMP_S,
                phase_rad: phase,
                from: (amplitude, omega),
                to: (w.amplitude_rad, w.omega_rad_per_s),
            });
        }
        if old.coning.is_none() && self.coning.is_none() {
            return self;
        }
        let (alpha, _, phase, omega) = old.cone_state_full(t_s);
        let to = self.coning.map_or((0.0, omega), |c| (c.half_angle_rad, c.omega_rad_per_s));
        self.coning = Some(Coning { half_angle_rad: to.0, omega_rad_per_s: to.1 });
        self.cone_continuation =
            Some(Transition { start_s: t_s, end_s: t_s + CONE_RAMP_S, phase_rad: phase, from: (alpha, omega), to });
        self.with_constants()
    }

    /// Wobble `i`'s (amplitude, its rate, phase, angular frequency) at `t_s`.
    fn wobble_state(&self, i: usize, t_s: f64) -> (f64, f64, f64, f64) {
        let w = &self.wobble[i];
        match self.wobble_ramps.get(i).copied().flatten() {
            Some(k) if t_s >= k.start_s => k.at(t_s),
            _ => (w.amplitude_rad, 0.0, w.omega_rad_per_s * t_s + w.phase_rad, w.omega_rad_per_s),
        }
    }

    /// The cone's half-angle and phase at `t_s` (0, 0 without a cone).
    #[must_use]
    pub fn cone_state(&self, t_s: f64) -> (f64, f64) {
        let (alpha, _, phase, _) = self.cone_state_full(t_s);
        (alpha, phase)
    }

    /// The cone's (half-angle, its rate, phase, angular frequency) at `t_s`.
    #[inline]
    fn cone_state_full(&self, t_s: f64) -> (f64, f64, f64, f64) {
        match (self.coning, self.cone_continuation) {
            (None, _) => (0.0, 0.0, 0.0, 0.0),
            (Some(_), Some(k)) if t_s >= k.start_s => k.at(t_s),
            (Some(c), _) => (c.half_angle_rad, 0.0, c.omega_rad_per_s * t_s, c.omega_rad_per_s),
        }
    }

    /// The cone's rotation K at `t_s` (body side of the Euler frame).
    #[inline]
    fn cone_rotation(&self, c: &Coning, t_s: f64) -> UnitQuaternion<f64> {
        let (alpha, _, phase, _) = self.cone_state_full(t_s);
        let k = if alpha == c.half_angle_rad { self.cone_constants } else { Coning::constants_of(alpha) };
        let (so, co) = phase.sin_cos();
        UnitQuaternion::new_normalize(Quaternion::new(k[0], k[1] * co, k[1] * so, 0.0))
    }

    /// The cone's rate of K relative to the Euler frame, in b, at `t_s`: with φ̇ the angular
    /// frequency now, (α̇ cos φ − φ̇ sin α sin φ, α̇ sin φ + φ̇ sin α cos φ, −2 φ̇ sin²(α/2)).
    fn cone_rate(&self, c: &Coning, t_s: f64) -> Vector3<f64> {
        let (alpha, alpha_dot, phase, w) = self.cone_state_full(t_s);
        let k = if alpha == c.half_angle_rad { self.cone_constants } else { Coning::constants_of(alpha) };
        let (so, co) = phase.sin_cos();
        Vector3::new(alpha_dot * co - w * k[2] * so, alpha_dot * so + w * k[2] * co, -w * k[3])
    }

    /// Whether a cone or wobble is changing at `t_s` (inside a [`Transition`]).
    fn in_transition(&self, t_s: f64) -> bool {
        self.cone_continuation
            .iter()
            .chain(self.wobble_ramps.iter().flatten())
            .any(|k| t_s >= k.start_s && t_s < k.end_s)
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
        let (r, euler) = self.n_from_b_and_euler(t_s);
        (euler.unwrap_or_else(|| Attitude::from_n_from_b(&r)), r)
    }

    /// C_b^n at `t_s`, with the Euler angles where the motion gives them (None for a coned body,
    /// whose angles are read from C_b^n: [`Attitude::from_n_from_b`], by whoever needs them).
    #[must_use]
    pub fn n_from_b_and_euler(&self, t_s: f64) -> (Rot<N, B>, Option<Attitude>) {
        match self.coning {
            None => {
                let a = self.euler(t_s);
                (a.n_from_b(), Some(a))
            }
            Some(_) => (self.n_from_b(t_s), None),
        }
    }

    /// C_b^n at `t_s`.
    #[must_use]
    #[inline]
    pub fn n_from_b(&self, t_s: f64) -> Rot<N, B> {
        let e = self.euler_fixed.unwrap_or_else(|| self.euler(t_s).n_from_b());
        match self.coning {
            None => e,
            // FRAME: the coned body b is the Euler frame turned by the cone rotation K (body side).
            Some(c) => Rot::from_quaternion(*e.quaternion() * self.cone_rotation(&c, t_s)),
        }
    }

    /// Angular rate of b relative to n, in b (rad/s).
    #[must_use]
    pub fn omega_nb_b(&self, t_s: f64) -> Vector3<f64> {
        if self.euler_fixed.is_some() {
            return self.coning.map_or_else(Vector3::zeros, |c| self.cone_rate(&c, t_s));
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
            Some(c) => self.cone_rotation(&c, t_s).inverse() * w_e + self.cone_rate(&c, t_s),
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
        let turning =
            |axis: Vector3<f64>, angle_rad: f64, rate_rad_per_s: f64| Link::Turning { axis, angle_rad, rate_rad_per_s };
        let mut links = vec![
            turning(Vector3::z(), -a.heading_rad, -dh),
            turning(Vector3::x(), a.pitch_rad, dp),
            turning(Vector3::y(), a.roll_rad, dr),
        ];
        if let Some(c) = self.coning {
            // A cone changing is not a link turning at a constant rate.
            if self.in_transition(rates_at_s) {
                return None;
            }
            links.push(Link::Cone {
                half_angle_rad: c.half_angle_rad,
                phase_rad: self.cone_state(t_s).1,
                rate_rad_per_s: c.omega_rad_per_s,
            });
        }
        Some(links)
    }

    /// (pitch, roll, heading) rates, rad/s.
    #[must_use]
    pub fn euler_rates(&self, t_s: f64) -> [f64; 3] {
        let mut r = [self.knots[0].slope(t_s), self.knots[1].slope(t_s), self.knots[2].slope(t_s)];
        for (i, w) in self.wobble.iter().enumerate() {
            let (amplitude, amplitude_rate, phase, omega) = self.wobble_state(i, t_s);
            let (s, c) = phase.sin_cos();
            r[w.angle.index()] += amplitude * omega * c + amplitude_rate * s;
        }
        r
    }

    /// Highest oscillation frequency of the motion (wobble, coning), rad/s.
    #[must_use]
    pub fn max_angular_frequency(&self) -> f64 {
        let w = self.wobble.iter().map(|w| w.omega_rad_per_s).fold(0.0, f64::max);
        // A transition passes through the frequencies between its ends.
        let changing = self
            .cone_continuation
            .iter()
            .chain(self.wobble_ramps.iter().flatten())
            .map(|k| k.from.1.abs().max(k.to.1.abs()))
            .fold(0.0, f64::max);
        w.max(self.coning.map_or(0.0, |c| c.omega_rad_per_s.abs())).max(changing)
    }

    /// First time after `t_s` where a rate jumps (a ramp starts or ends).
    #[must_use]
    pub fn next_breakpoint_after(&self, t_s: f64) -> f64 {
        let ramp = self
            .cone_continuation
            .iter()
            .chain(self.wobble_ramps.iter().flatten())
            .flat_map(|k| [k.start_s, k.end_s])
            .filter(|b| *b > t_s)
            .fold(f64::INFINITY, f64::min);
        self.knots.iter().map(|k| k.next_after(t_s)).fold(ramp, f64::min)
    }

    /// The Euler-angle part of the motion.
    #[must_use]
    pub fn euler(&self, t_s: f64) -> Attitude {
        let mut a = [
            self.knots[0].value(t_s, self.base.pitch_rad),
            self.knots[1].value(t_s, self.base.roll_rad),
            self.knots[2].value(t_s, self.base.heading_rad),
        ];
        for (i, w) in self.wobble.iter().enumerate() {
            let (amplitude, _, phase, _) = self.wobble_state(i, t_s);
            a[w.angle.index()] += amplitude * phase.sin();
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
        let ramp = |angle, start_s, target_deg: f64| Ramp {
            angle,
            start_s,
            target_rad: target_deg * RAD_PER_DEG,
            rate_rad_per_s: 6.0 * RAD_PER_DEG,
        };
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
    fn a_changed_cone_goes_on_from_where_the_body_is() {
        // A live session's cone 1° at 5 Hz changed to 2° at 10 Hz at t = 3.217 s: the attitude is
        // the same on both sides of the change (no jump the INS does not feel), and the rate is the
        // attitude's derivative (finite differences, as above) inside the ramp and after it.
        let cone = |deg: f64, hz: f64| {
            VehicleMotion::fixed(Attitude::default())
                .with_coning(Coning { half_angle_rad: deg * RAD_PER_DEG, omega_rad_per_s: std::f64::consts::TAU * hz })
        };
        let (old, t_c) = (cone(1.0, 5.0), 3.217);
        let new = cone(2.0, 10.0).continuing_from(&old, t_c);
        let jump = (old.n_from_b(t_c).inverse() * new.n_from_b(t_c)).quaternion().angle();
        assert!(jump < 1e-12, "the body jumps by {jump} rad at the change");
        for t in [t_c + 0.3, t_c + 0.9, t_c + CONE_RAMP_S + 0.7] {
            let h = 1e-6;
            let fd = (new.n_from_b(t - h).inverse() * new.n_from_b(t + h)).quaternion().scaled_axis() / (2.0 * h);
            let w = new.omega_nb_b(t);
            assert!((fd - w).norm() < 1e-6 * w.norm(), "t={t}: {fd:?} vs {w:?}");
        }
        // Halfway up the ramp 1.5°; after it the new cone's 2°; the phase goes on at 10 Hz.
        let deg = |t: f64| new.cone_state(t).0 / RAD_PER_DEG;
        assert!((deg(t_c + 0.5 * CONE_RAMP_S) - 1.5).abs() < 1e-12 && (deg(t_c + 5.0) - 2.0).abs() < 1e-12);
        let phase_rate = (new.cone_state(t_c + 4.0).1 - new.cone_state(t_c + 3.0).1) / std::f64::consts::TAU;
        assert!((phase_rate - 10.0).abs() < 1e-9, "{phase_rate}");
        // A cone set to zero ramps down and stops there, from where it was.
        let off = VehicleMotion::fixed(Attitude::default()).continuing_from(&old, t_c);
        assert!((old.n_from_b(t_c).inverse() * off.n_from_b(t_c)).quaternion().angle() < 1e-12);
        assert!(off.n_from_b(t_c + CONE_RAMP_S + 0.1).quaternion().angle() < 1e-12);
    }

    #[test]
    fn a_changed_wobble_goes_on_from_where_the_body_is() {
        // Li et al. 2014's two-axis wobble (6°, 1 Hz, 90° apart) changed to 3° at 2 Hz at t = 1.3 s:
        // no jump in the attitude, the rate its derivative inside the ramp and after.
        let wobble = |deg: f64, hz: f64| {
            let w = |angle, phase_rad| Wobble {
                angle,
                amplitude_rad: deg * RAD_PER_DEG,
                omega_rad_per_s: std::f64::consts::TAU * hz,
                phase_rad,
            };
            VehicleMotion::new(
                Attitude::default(),
                vec![],
                vec![w(AngleKind::Heading, 0.0), w(AngleKind::Roll, std::f64::consts::FRAC_PI_2)],
            )
            .expect("valid")
        };
        let (old, t_c) = (wobble(6.0, 1.0), 1.3);
        let new = wobble(3.0, 2.0).continuing_from(&old, t_c);
        assert!((old.n_from_b(t_c).inverse() * new.n_from_b(t_c)).quaternion().angle() < 1e-12);
        for t in [t_c + 0.4, t_c + CONE_RAMP_S + 0.3] {
            let h = 1e-6;
            let fd = (new.n_from_b(t - h).inverse() * new.n_from_b(t + h)).quaternion().scaled_axis() / (2.0 * h);
            let w = new.omega_nb_b(t);
            assert!((fd - w).norm() < 1e-6 * w.norm().max(1e-3), "t={t}: {fd:?} vs {w:?}");
        }
        assert!(new.next_breakpoint_after(t_c + 0.1) == t_c + CONE_RAMP_S);
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
