//! The IMU's truth: the exact angular rate and specific force of the sensor frame s over the
//! rotating Earth, and their exact increments per IMU sample (integrated from the rates, never from
//! differenced attitudes — the difference between the two is the coning effect itself).

use nalgebra::{UnitQuaternion, Vector3};

use crate::model::earth::Earth;
use crate::math::frames::{Rot, N, S};
use crate::math::frames::axis_angle;
use crate::model::gimbal::ShaftRotations;
use crate::model::scheme::{AxisValues, MAX_AXES};
use crate::sim::Model;

/// The truth at one instant.
#[derive(Debug, Clone, Copy)]
pub struct TruthPoint {
    /// Time, s.
    pub t_s: f64,
    /// C_s^n.
    pub n_from_s: Rot<N, S>,
    /// ω_is^s, rad/s.
    pub omega_is_s: Vector3<f64>,
    /// Specific force in s, m/s².
    pub f_s: Vector3<f64>,
}

/// Generates exact IMU increments for a model at a fixed site (the vehicle rotates, it does not travel).
#[derive(Debug, Clone)]
pub struct TruthImu {
    model: Model,
    earth: Earth,
    last: TruthPoint,
    next_break: f64,
    /// Fastest oscillation or rotation of the motion, rad/s (sets the quadrature panels).
    max_omega: f64,
    /// With the vehicle at rest, the last gimbal state and its truth (a dwell of an indexed
    /// sequence repeats it for minutes: no trigonometry needed).
    memo: Option<(AxisValues, AxisValues, TruthPoint)>,
    shafts: ShaftCache,
}

/// Shaft rotations by angle stepping: successive quadrature nodes advance each gimbal by the same
/// small angle (constant rate), so R(a, λ + δ) = R(a, λ)·R(a, δ) with R(a, δ) reused — no
/// trigonometry. Re-anchored exactly every `REANCHOR` evaluations and whenever the step changes,
/// so rounding never accumulates beyond ~1e-12 rad.
#[derive(Debug, Clone, Copy)]
struct ShaftCache {
    angle: AxisValues,
    q: [UnitQuaternion<f64>; MAX_AXES],
    step: AxisValues,
    step_q: [UnitQuaternion<f64>; MAX_AXES],
    valid: bool,
    since_anchor: u32,
}

const REANCHOR: u32 = 4096;

impl ShaftCache {
    fn new() -> Self {
        Self {
            angle: [0.0; MAX_AXES],
            q: [UnitQuaternion::identity(); MAX_AXES],
            step: [f64::NAN; MAX_AXES],
            step_q: [UnitQuaternion::identity(); MAX_AXES],
            valid: false,
            since_anchor: 0,
        }
    }

    fn rotations(&mut self, chain: &crate::model::gimbal::Chain, angles: &AxisValues) -> ShaftRotations {
        let n = chain.axes().len();
        let reanchor = !self.valid || self.since_anchor >= REANCHOR;
        for k in 0..n {
            let axis = &chain.axes()[k].axis;
            let delta = angles[k] - self.angle[k];
            if delta == 0.0 && !reanchor {
                continue;
            }
            if !reanchor && (delta - self.step[k]).abs() <= 1e-15 * (1.0 + angles[k].abs()) {
                self.q[k] *= self.step_q[k];
            } else {
                self.q[k] = axis_angle(axis, angles[k]);
                if delta != 0.0 && delta.abs() < 0.1 {
                    self.step[k] = delta;
                    self.step_q[k] = axis_angle(axis, delta);
                }
            }
            self.angle[k] = angles[k];
        }
        self.since_anchor = if reanchor { 0 } else { self.since_anchor + 1 };
        self.valid = true;
        ShaftRotations(self.q)
    }
}

/// Phase advance of the fastest motion per Simpson panel: its relative error is ~λ⁴/2880, so 0.01
/// keeps the increments exact to ~1e-12 relative, well below every algorithm error studied.
const MAX_PANEL_PHASE: f64 = 0.01;

impl TruthImu {
    /// Starts at `t0_s`.
    #[must_use]
    pub fn new(model: Model, earth: Earth, t0_s: f64) -> Self {
        let max_omega = model.vehicle.max_angular_frequency().max(model.scheme.max_rate());
        let mut me = Self {
            last: TruthPoint { t_s: t0_s, n_from_s: Rot::identity(), omega_is_s: Vector3::zeros(), f_s: Vector3::zeros() },
            model,
            earth,
            next_break: 0.0,
            max_omega,
            memo: None,
            shafts: ShaftCache::new(),
        };
        me.last = me.eval(t0_s);
        me.next_break = me.breakpoint_after(t0_s);
        me
    }

    /// The model.
    #[must_use]
    pub fn model(&self) -> &Model {
        &self.model
    }

    /// The truth at the end of the last increment.
    #[must_use]
    pub fn last(&self) -> &TruthPoint {
        &self.last
    }

    fn breakpoint_after(&self, t: f64) -> f64 {
        let m = &self.model;
        m.vehicle.next_breakpoint_after(t).min(m.scheme.next_breakpoint_after(t - m.scheme_t0_s) + m.scheme_t0_s)
    }

    /// The exact state of s at `t_s`.
    #[must_use]
    pub fn eval(&mut self, t_s: f64) -> TruthPoint {
        let m = &self.model;
        // A vehicle at rest: its attitude is computed once, its rate is zero.
        let (n_from_b, omega_nb_b) = match m.fixed_state() {
            Some((_, r)) => (r, Vector3::zeros()),
            None => (m.vehicle.n_from_b(t_s), m.vehicle.omega_nb_b(t_s)),
        };
        let (angles, rates) = m.scheme.state(t_s - m.scheme_t0_s);
        let fixed = m.fixed_state().is_some();
        if fixed
            && let Some((a, r, point)) = &self.memo
            && *a == angles
            && *r == rates
        {
            return TruthPoint { t_s, ..*point };
        }
        let shafts = self.shafts.rotations(&m.chain, &angles);
        let (b_from_s, omega_bs_s) = m.chain.b_from_s_and_rate(m.truth_rotations(), &shafts, &rates);
        let n_from_s = n_from_b * b_from_s;
        let s_from_n: UnitQuaternion<f64> = n_from_s.quaternion().inverse();
        // ω_is^s = C_n^s ω_ie^n + C_b^s ω_nb^b + ω_bs^s (the site is fixed: ω_en = 0).
        let mut omega_is_s = s_from_n * self.earth.omega_ie_n + omega_bs_s.v;
        if omega_nb_b != Vector3::zeros() {
            omega_is_s += b_from_s.quaternion().inverse() * omega_nb_b;
        }
        // At rest on the Earth the specific force is the reaction to gravity: f^n = −g^n.
        let f_s = s_from_n * -self.earth.gravity_n;
        let point = TruthPoint { t_s, n_from_s, omega_is_s, f_s };
        if fixed {
            self.memo = Some((angles, rates, point));
        }
        point
    }

    /// Gyro and accelerometer increments (Δθ_s, Δv_s) from the last instant to `t1_s`: Simpson's rule
    /// on each smooth piece (split at the motion's breakpoints), error O(h⁵·ω⁽⁴⁾).
    pub fn increments(&mut self, t1_s: f64) -> (Vector3<f64>, Vector3<f64>) {
        let (mut dtheta, mut dv) = (Vector3::zeros(), Vector3::zeros());
        loop {
            let t0 = self.last.t_s;
            let at_break = self.next_break > t0 && self.next_break <= t1_s;
            let end = if at_break { self.next_break } else { t1_s };
            let h = end - t0;
            // Composite Simpson: enough panels that the fastest motion turns < 0.01 rad per panel.
            let panels = ((self.max_omega * h / MAX_PANEL_PHASE).ceil() as usize).max(1);
            let hp = h / panels as f64;
            let mut left = self.last;
            for p in 1..=panels {
                let t_end = t0 + p as f64 * hp;
                let mid = self.eval(t_end - 0.5 * hp);
                // At a breakpoint the rate jumps: the piece ends with its left limit.
                let right = if p == panels && at_break { self.eval(end - 1e-9f64.min(0.25 * hp)) } else { self.eval(if p == panels { end } else { t_end }) };
                dtheta += (left.omega_is_s + 4.0 * mid.omega_is_s + right.omega_is_s) * (hp / 6.0);
                dv += (left.f_s + 4.0 * mid.f_s + right.f_s) * (hp / 6.0);
                left = right;
            }
            let right = left;
            if at_break {
                self.last = self.eval(end);
                self.next_break = self.breakpoint_after(end);
            } else {
                self.last = right;
            }
            if end >= t1_s {
                return (dtheta, dv);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ins::coning::Algorithm;
    use crate::ins::strapdown::AttitudeIntegrator;
    use crate::math::units::ARCSEC_PER_RAD;

    fn model(name: &str) -> (Model, Earth) {
        let p = crate::scenario::presets::load(name).expect("preset");
        (p.table_model(), Earth::at(p.site))
    }

    #[test]
    fn at_rest_the_increments_are_earth_rate_and_gravity() {
        // Analytic anchor: a static table on a static vehicle senses Ω and g only.
        let (mut m, earth) = model("jiang2017-dual-axis");
        m.scheme = crate::model::scheme::Scheme::continuous(vec![0.3, -0.4], vec![0.0, 0.0]);
        let mut imu = TruthImu::new(m, earth, 0.0);
        let s_from_n = imu.last().n_from_s.quaternion().inverse();
        let (dtheta, dv) = imu.increments(1.0);
        assert!((dtheta - s_from_n * earth.omega_ie_n).norm() < 1e-18, "{dtheta:?}");
        assert!((dv + s_from_n * earth.gravity_n).norm() < 1e-12);
        // 9.80 m/s² at Beijing (39.9° N), Somigliana.
        assert!((earth.gravity_n.z + 9.8015).abs() < 1e-3, "{}", earth.gravity_n.z);
    }

    /// Integrates the truth's own increments with a high-order algorithm and compares with the
    /// truth's attitude: the increments and the frames agree (to the algorithm's tiny error).
    fn integrate_and_compare(name: &str, seconds: f64) -> f64 {
        let (m, earth) = model(name);
        let rate = 2000.0;
        let mut imu = TruthImu::new(m, earth, 0.0);
        let mut integ = AttitudeIntegrator::new(Algorithm::TwoSampleP1, imu.last().n_from_s);
        let zeta = earth.omega_ie_n * (2.0 / rate);
        let mut worst = 0.0f64;
        for i in 1..=(seconds * rate) as usize {
            let t = i as f64 / rate;
            let (dtheta, _) = imu.increments(t);
            if integ.push(dtheta, &zeta).is_some() {
                let err = (imu.last().n_from_s.inverse() * integ.n_from_s).angle_rad();
                worst = worst.max(err);
            }
        }
        worst * ARCSEC_PER_RAD
    }

    #[test]
    fn the_increments_integrate_back_to_the_true_attitude() {
        // Dual-axis continuous rotation at 10°/s with swing cones (coning of the sensor frame):
        // after 60 s the strapdown attitude from the truth's increments is within 1e-4″ of the truth.
        let worst = integrate_and_compare("jiang2017-dual-axis", 60.0);
        assert!(worst < 1e-4, "worst attitude difference {worst}″");
        // Indexed table with instant rate steps and a manoeuvring vehicle: the piecewise quadrature
        // keeps the rate steps exact (without the split at breakpoints this is ~3″ per step).
        let worst = integrate_and_compare("rotary-table-2016-installation", 620.0);
        assert!(worst < 1e-3, "worst attitude difference {worst}″");
    }
}
