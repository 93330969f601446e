//! One IMU sample at a time: truth increments → sensor errors and dither → FIR → decimation →
//! attitude algorithm(s) → navigation; and, on demand, the INS body attitude and its error.
//!
//! Timing (docs/ins.md): after the FIR, sample k represents the truth at k·h − d (d = group delay);
//! the navigation computer's zero-order hold is a further h/2 (seed 001 §3.1); the encoder angles
//! are taken at the same instant (matched synchronisation); outputs are compared with the truth
//! `output_compensation` earlier (seed 001 §3.2's Δt).

use nalgebra::Vector3;

use super::coning::Algorithm;
use super::fir::Fir;
use super::nav::{NavState, Navigator};
use super::sensor::Sensors;
use super::strapdown::AttitudeIntegrator;
use super::truth::TruthImu;
use crate::math::rotvec;
use crate::model::earth::Earth;
use super::InsParams;
use crate::math::attitude::{Attitude, AttitudeError};
use crate::math::frames::{Rot, B, N, S};
use crate::model::earth::Site;
use crate::sim::{demodulate, encoder_readings, DemodState, Model};

/// What one IMU sample produced.
#[derive(Debug, Clone, Copy)]
pub struct SampleOut {
    /// End of the sample, s.
    pub t_s: f64,
    /// True if the primary algorithm completed an attitude update with this sample.
    pub updated: bool,
    /// Measured gyro rate (raw, with dither), rad/s.
    pub raw_rate_s: Vector3<f64>,
    /// After the FIR, rad/s.
    pub filtered_rate_s: Vector3<f64>,
}

/// The INS's view of the body at one output instant.
#[derive(Debug, Clone)]
pub struct InsView {
    /// Output time, s.
    pub t_s: f64,
    /// Truth reference time (output time minus the compensation Δt), s.
    pub t_ref_s: f64,
    /// Body attitude error of each algorithm (computed minus true), in integrator order.
    pub errors: Vec<AttitudeError>,
    /// True C_s^n at the instant the INS output represents.
    pub imu_true: Rot<N, S>,
    /// The primary algorithm's C_s^n.
    pub imu_ins: Rot<N, S>,
    /// Navigation errors, when navigating.
    pub nav: Option<NavError>,
}

/// Navigation errors (computed − true) at one output instant.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct NavError {
    /// East position error, m.
    pub east_m: f64,
    /// North position error, m.
    pub north_m: f64,
    /// Horizontal (radial) position error, m.
    pub radial_m: f64,
    /// Velocity error (East, North, Up), m/s (the vehicle is at rest: this is the velocity).
    pub velocity_enu_mps: Vector3<f64>,
}

/// The attitude output `zoh` after the latest of two (time, attitude) updates, interpolated.
fn output_attitude(history: &[(f64, Rot<N, S>); 2], zoh: f64) -> (f64, Rot<N, S>) {
    let [(t0, q0), (t1, q1)] = *history;
    let t = t1 - zoh;
    if t1 > t0 && t < t1 {
        let f = ((t - t0) / (t1 - t0)).clamp(0.0, 1.0);
        // FRAME: between two C_s^n the interpolated rotation is C_s^n at the instant in between.
        (t, Rot::from_quaternion(q0.quaternion().slerp(q1.quaternion(), f)))
    } else {
        (t1, q1)
    }
}

/// The INS in the loop (cloned to fork one IMU stream into two navigation strategies).
#[derive(Clone)]
pub struct InsRun {
    cfg: InsParams,
    truth: TruthImu,
    earth: Earth,
    sensors: Sensors,
    fir_g: Fir,
    fir_a: Fir,
    h: f64,
    index: u64,
    acc: (Vector3<f64>, Vector3<f64>, usize),
    /// The integrators; `[0]` is the configured algorithm (the navigation's).
    integrators: Vec<AttitudeIntegrator>,
    /// (time, attitude) of each integrator's previous and latest update.
    history: Vec<[(f64, Rot<N, S>); 2]>,
    nav: Option<Navigator>,
    nav_start: Rot<N, S>,
    upd_g: Vec<Vector3<f64>>,
    upd_a: Vec<Vector3<f64>>,
    demod: Vec<DemodState>,
    /// FIR group delay, s.
    pub fir_delay_s: f64,
    /// Zero-order-hold delay, s.
    pub zoh_delay_s: f64,
}

impl InsRun {
    /// Builds the INS `cfg` at `site` on the table `model` (sensor noise seeded with `seed`) and
    /// pre-rolls the FIR.
    #[must_use]
    pub fn new(cfg: &InsParams, site: Site, seed: u64, model: Model) -> Self {
        let cfg = cfg.clone();
        let h = 1.0 / cfg.rate_hz;
        let earth = Earth::at(site);
        let fir_g = Fir::new(&cfg.fir_taps);
        let fir_a = Fir::new(&cfg.fir_taps);
        let fir_delay_s = fir_g.group_delay_samples() * h;
        let zoh_delay_s = if cfg.zero_order_hold { 0.5 * h } else { 0.0 };
        // Pre-roll: the filter has been running before t = 0 on the same motion, and the algorithms
        // that use previous samples have them.
        let pre = cfg.fir_taps.len().saturating_sub(1).max(2 * cfg.decimation);
        let t_start = -(pre as f64) * h;
        let truth = TruthImu::new(model, earth, t_start);
        let sensors = Sensors::new(&cfg.errors, h, seed, t_start);
        let algorithms = cfg.algorithms();
        let nav = cfg.navigation.map(|o| Navigator::new(&earth, o));
        let mut me = Self {
            truth,
            earth,
            sensors,
            fir_g,
            fir_a,
            h,
            index: 0,
            acc: (Vector3::zeros(), Vector3::zeros(), 0),
            integrators: Vec::new(),
            history: Vec::new(),
            nav,
            nav_start: Rot::identity(),
            upd_g: Vec::new(),
            upd_a: Vec::new(),
            demod: Vec::new(),
            fir_delay_s,
            zoh_delay_s,
            cfg,
        };
        let mut primed = Vec::new();
        let mut acc = (Vector3::zeros(), 0);
        for i in 0..pre {
            let t1 = t_start + (i + 1) as f64 * h;
            let (g, a) = me.truth.increments(t1);
            let (g, a) = me.sensors.measure(&g, &a, t1);
            acc.0 += me.fir_g.push(g);
            acc.1 += 1;
            me.fir_a.push(a);
            if acc.1 == me.cfg.decimation {
                primed.push(acc.0);
                acc = (Vector3::zeros(), 0);
            }
        }
        // The filtered stream now stands at the truth of t = −d: start the attitude there, with the
        // alignment error φ applied as C = (I − [φ×]) C_true.
        let start = me.truth.eval(-fir_delay_s).n_from_s;
        // FRAME: the alignment error is a small rotation of the navigation frame (C = (I − [φ×]) C_true).
        let start: Rot<N, S> = Rot::<N, N>::from_quaternion(rotvec::exp(&-me.cfg.initial_error_rad)) * start;
        me.integrators = algorithms
            .iter()
            .map(|a| {
                let mut i = AttitudeIntegrator::new(*a, start);
                i.prime(&primed);
                i
            })
            .collect();
        me.history = vec![[(-fir_delay_s, start), (-fir_delay_s, start)]; me.integrators.len()];
        me.demod = vec![DemodState::default(); me.integrators.len()];
        me.nav_start = start;
        me
    }

    /// The configuration.
    #[must_use]
    pub fn config(&self) -> &InsParams {
        &self.cfg
    }

    /// The algorithms run, in order.
    #[must_use]
    pub fn algorithms(&self) -> Vec<Algorithm> {
        self.integrators.iter().map(|i| i.algorithm).collect()
    }

    /// The model (truth).
    #[must_use]
    pub fn model(&self) -> &Model {
        self.truth.model()
    }

    /// Navigation solution, if navigating.
    #[must_use]
    pub fn nav_state(&self) -> Option<&NavState> {
        self.nav.as_ref().map(|n| &n.state)
    }

    /// Replaces the primary attitude (position-fix and azimuth resets of later issues).
    pub fn set_primary_attitude(&mut self, n_from_s: Rot<N, S>) {
        if let Some(i) = self.integrators.first_mut() {
            i.n_from_s = n_from_s;
        }
    }

    /// Position fix: the navigation's latitude and longitude set to the truth (the site), velocity
    /// and the attitude relative to local level kept (the usual reset; docs/tpr.md).
    pub fn reset_position(&mut self) {
        let site = self.earth.site;
        if let Some(nav) = self.nav.as_mut() {
            nav.state.latitude_rad = site.latitude_rad;
            nav.state.longitude_rad = site.longitude_rad;
        }
    }

    /// Turns the primary attitude about the local vertical by `angle_rad` (counter-clockwise seen from
    /// above: the heading decreases by `angle_rad`): an azimuth correction.
    pub fn rotate_azimuth(&mut self, angle_rad: f64) {
        // FRAME: a rotation of the computed navigation frame about its own vertical.
        let r: Rot<N, N> = Rot::from_quaternion(rotvec::exp(&(Vector3::z() * angle_rad)));
        if let Some(i) = self.integrators.first_mut() {
            i.n_from_s = r * i.n_from_s;
        }
        if let Some(h) = self.history.first_mut() {
            for (_, q) in h.iter_mut() {
                *q = r * *q;
            }
        }
    }

    /// One IMU sample.
    pub fn step(&mut self) -> SampleOut {
        self.index += 1;
        let t1 = self.index as f64 * self.h;
        let (g_true, a_true) = self.truth.increments(t1);
        let (g_meas, a_meas) = self.sensors.measure(&g_true, &a_true, t1);
        let g_filt = self.fir_g.push(g_meas);
        let a_filt = self.fir_a.push(a_meas);
        let mut out = SampleOut { t_s: t1, updated: false, raw_rate_s: g_meas / self.h, filtered_rate_s: g_filt / self.h };
        self.acc.0 += g_filt;
        self.acc.1 += a_filt;
        self.acc.2 += 1;
        if self.acc.2 < self.cfg.decimation {
            return out;
        }
        let (dg, da) = (self.acc.0, self.acc.1);
        self.acc = (Vector3::zeros(), Vector3::zeros(), 0);
        let h_alg = self.h * self.cfg.decimation as f64;
        // The attitude at the start of the primary update, for the velocity update.
        if self.upd_g.is_empty() {
            self.nav_start = self.integrators[0].n_from_s;
        }
        self.upd_g.push(dg);
        self.upd_a.push(da);
        let w_in = self.nav.as_ref().map_or(self.earth.omega_ie_n, Navigator::omega_in_n);
        let t_repr = t1 - self.fir_delay_s;
        for (k, integ) in self.integrators.iter_mut().enumerate() {
            let zeta = w_in * (h_alg * integ.samples_per_update() as f64);
            if integ.push(dg, &zeta).is_some() {
                self.history[k] = [self.history[k][1], (t_repr, integ.n_from_s)];
                if k == 0 {
                    out.updated = true;
                    let h_upd = h_alg * self.upd_g.len() as f64;
                    if let Some(nav) = self.nav.as_mut() {
                        nav.update(&self.nav_start, &self.upd_g, &self.upd_a, &zeta, h_upd);
                    }
                    self.upd_g.clear();
                    self.upd_a.clear();
                }
            }
        }
        out
    }

    /// Integrator `k`'s C_s^n as output at `t_s` (after its latest update): with the zero-order
    /// hold, the value h/2 earlier, interpolated between the two latest updates.
    #[must_use]
    pub fn output_attitude(&self, k: usize) -> (f64, Rot<N, S>) {
        output_attitude(&self.history[k], self.zoh_delay_s)
    }

    /// The INS body attitude errors (call right after a primary update at `t_s`). Each algorithm is
    /// compared at the instant its own latest output stands for (algorithms with more samples per
    /// update update less often), against the truth `output_compensation` earlier.
    pub fn view(&mut self, t_s: f64) -> InsView {
        let model = self.truth.model();
        let mut errors = Vec::with_capacity(self.integrators.len());
        for k in 0..self.integrators.len() {
            let (t_repr, n_from_s) = output_attitude(&self.history[k], self.zoh_delay_s);
            // The output left the computer d + zoh after the instant it represents.
            let t_ref = t_repr + self.fir_delay_s + self.zoh_delay_s - self.cfg.output_compensation_s;
            // The encoders are read for the instant the IMU data represent (matched synchronisation).
            let encoder = encoder_readings(model, t_repr);
            let corrected = self.demod[k].correct(model, t_repr, &encoder);
            let b_from_s_comp = model.chain.b_from_s(model.compensation_rotations(), &corrected);
            let (truth_att, _) = model.vehicle.state(t_ref);
            errors.push(demodulate(n_from_s, b_from_s_comp).error_from(&truth_att));
        }
        let (t_repr, imu_ins) = self.output_attitude(0);
        let imu_true = self.truth.eval(t_repr).n_from_s;
        let nav = self.nav.as_ref().map(|n| {
            let s = &n.state;
            let site = self.earth.site;
            let (rm, rn) = Earth::radii(site.latitude_rad);
            let north = (s.latitude_rad - site.latitude_rad) * (rm + site.height_m);
            let east = (s.longitude_rad - site.longitude_rad) * (rn + site.height_m) * site.latitude_rad.cos();
            NavError { east_m: east, north_m: north, radial_m: north.hypot(east), velocity_enu_mps: s.v_n }
        });
        InsView { t_s, t_ref_s: t_s - self.cfg.output_compensation_s, errors, imu_true, imu_ins, nav }
    }

    /// The body attitude the primary INS outputs (for tests and resets).
    #[must_use]
    pub fn body_attitude(&self, b_from_s: Rot<B, S>) -> Attitude {
        let n_from_s = self.output_attitude(0).1;
        // FRAME: C_b^n = C_s^n · C_b^s.
        Attitude::from_n_from_b(&(n_from_s * b_from_s.inverse()))
    }

    /// IMU sample period, s.
    #[must_use]
    pub fn sample_s(&self) -> f64 {
        self.h
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::units::{ARCSEC_PER_RAD, RAD_PER_DEG};
    use crate::scenario::Params;

    /// A scenario built from TOML text (the tests' one configuration mechanism, as users write it).
    pub(crate) fn params(extra: &str, table: &str) -> Params {
        let text = format!(
            "[scenario]\nname = \"t\"\ntitle = \"t\"\nseed = 5\n[simulation]\nduration_s = 100.0\nstep_hz = 200.0\n[site]\nlatitude_deg = 40.0\n{table}\n{extra}"
        );
        crate::scenario::parse(&text, "test").expect("test scenario")
    }

    const STATIC_TABLE: &str = "[turntable]\n[[turntable.axis]]\nname = \"table\"\naxis = \"z\"\n[scheme]\nkind = \"static\"\n";

    fn run(p: &Params, seconds: f64, mut each_update: impl FnMut(&mut InsRun, f64)) -> InsRun {
        let mut ins = p.ins_run().expect("ins");
        let n = (seconds * p.step_hz).round() as u64;
        for _ in 0..n {
            let out = ins.step();
            if out.updated {
                each_update(&mut ins, out.t_s);
            }
        }
        ins
    }

    #[test]
    fn a_static_error_free_imu_does_not_drift_over_24_hours() {
        // Issue: a static, error-free IMU over 24 h keeps the attitude error below 0.01″ and the
        // horizontal position error below a metre (vertical channel held).
        let p = params("[imu]\n[navigation]\nvertical = \"held\"\n", STATIC_TABLE);
        let mut worst_att = 0.0f64;
        let mut worst_pos = 0.0f64;
        let mut k = 0u64;
        run(&p, 86_400.0, |ins, t| {
            k += 1;
            if k.is_multiple_of(2000) {
                let v = ins.view(t);
                for e in &v.errors {
                    worst_att = worst_att.max(e.as_array().iter().fold(0.0f64, |m, x| m.max(x.abs())));
                }
                if let Some(e) = v.nav {
                    worst_pos = worst_pos.max(e.radial_m);
                }
            }
        });
        let worst_att = worst_att * ARCSEC_PER_RAD;
        assert!(worst_att < 0.01, "attitude error {worst_att}″");
        assert!(worst_pos < 1.0, "position error {worst_pos} m");
    }

    #[test]
    fn phase_lag_theorem_holds_for_the_fir_and_the_zero_order_hold() {
        // Seed 001 eq. 16/19: a 7°, 0.5 Hz single-axis wobble seen through a 6.25 ms lag (FIR 12
        // samples at 2 kHz + ZOH 0.25 ms) has an error amplitude A·ω·t_d = 0.1374°. Within 3%.
        let p = params(
            "[vehicle]\n[[vehicle.wobble]]\nangle = \"heading\"\namplitude_deg = 7.0\nfrequency_hz = 0.5\n[imu]\nfir = \"seed001\"\nzero_order_hold = true\n",
            STATIC_TABLE,
        );
        let mut p = p;
        p.step_hz = 2000.0;
        p.ins.as_mut().expect("imu").rate_hz = 2000.0;
        let mut peak = 0.0f64;
        run(&p, 8.0, |ins, t| {
            if t > 2.0 {
                let v = ins.view(t);
                peak = peak.max(v.errors[0].heading_rad.abs());
            }
        });
        let expected = 7.0 * RAD_PER_DEG * std::f64::consts::TAU * 0.5 * 6.25e-3;
        assert!((peak / expected - 1.0).abs() < 0.03, "peak {:.5}° vs {:.5}°", peak.to_degrees(), expected.to_degrees());
        assert!((expected.to_degrees() - 0.1374).abs() < 5e-5, "seed 001 eq. 19");
    }
}

#[cfg(test)]
mod bias_tests {
    use super::tests::params;
    use super::*;
    use crate::model::earth::{normal_gravity, EARTH_RATE};

    /// The textbook linear error model of a stationary INS (Titterton & Weston ch. 12, phi-angle form,
    /// ENU, vertical channel held), integrated with RK4 — an independent computation:
    /// φ̇ = −ω_ie×φ + δω_in − ε,  δv̇_h = (f×φ)_h − (2ω_ie×δv)_h,  δL̇ = δv_N/R_M,  δλ̇ = δv_E/(R_N cos L),
    /// with δω_in = (−δv_N/R_M, Ω cos… ) from the position and velocity errors.
    fn linear_model(eps_n: Vector3<f64>, lat: f64, t_end: f64, samples: &[f64]) -> Vec<(f64, f64, f64)> {
        let (rm, rn) = Earth::radii(lat);
        let g = normal_gravity(lat, 0.0);
        let (sl, cl) = lat.sin_cos();
        let w_ie = Vector3::new(0.0, EARTH_RATE * cl, EARTH_RATE * sl);
        // x = [φE, φN, φU, δvE, δvN, δL, δλ]
        let f = |x: &[f64; 7]| -> [f64; 7] {
            let phi = Vector3::new(x[0], x[1], x[2]);
            let (dve, dvn, dl) = (x[3], x[4], x[5]);
            let d_w_ie = Vector3::new(0.0, -EARTH_RATE * sl * dl, EARTH_RATE * cl * dl);
            let d_w_en = Vector3::new(-dvn / rm, dve / rn, dve * sl / (cl * rn));
            let dphi = -w_ie.cross(&phi) + d_w_ie + d_w_en - eps_n;
            let fxphi = Vector3::new(0.0, 0.0, g).cross(&phi);
            let cor = -2.0 * w_ie.cross(&Vector3::new(dve, dvn, 0.0));
            [dphi.x, dphi.y, dphi.z, fxphi.x + cor.x, fxphi.y + cor.y, dvn / rm, dve / (rn * cl)]
        };
        let mut x = [0.0; 7];
        let (mut t, dt) = (0.0, 1.0);
        let mut out = Vec::new();
        let mut next = 0;
        while t <= t_end + 1e-9 && next < samples.len() {
            if (t - samples[next]).abs() < 0.5 * dt {
                out.push(((x[6]) * rn * cl, x[5] * rm, x[2]));
                next += 1;
            }
            let add = |a: &[f64; 7], b: &[f64; 7], k: f64| -> [f64; 7] { std::array::from_fn(|i| a[i] + k * b[i]) };
            let k1 = f(&x);
            let k2 = f(&add(&x, &k1, dt / 2.0));
            let k3 = f(&add(&x, &k2, dt / 2.0));
            let k4 = f(&add(&x, &k3, dt));
            x = std::array::from_fn(|i| x[i] + dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]));
            t += dt;
        }
        out
    }

    #[test]
    fn a_constant_gyro_bias_gives_the_textbook_schuler_and_earth_rate_errors() {
        // Static, level vehicle heading North: sensor axes = East, North, Up. Gyro biases 0.01°/h on
        // each axis. The full nonlinear INS must follow the linear textbook model over 8 hours
        // (Schuler oscillation of 84 min on top of the Earth-rate terms): position within 2% of its
        // peak, heading (φ_U) within 2%.
        let bias = 0.01;
        let p = params(
            &format!("[imu]\n[imu.gyro]\nbias_deg_per_h = [{bias}, {bias}, {bias}]\n[navigation]\n"),
            "[turntable]\n[[turntable.axis]]\nname = \"table\"\naxis = \"z\"\n[scheme]\nkind = \"static\"\n",
        );
        let mut p = p;
        p.step_hz = 20.0;
        let eps = Vector3::repeat(bias * std::f64::consts::PI / 180.0 / 3600.0);
        let hours = 8.0;
        let times: Vec<f64> = (1..=32).map(|i| f64::from(i) * 900.0).collect();
        let model = linear_model(eps, p.site.latitude_rad, hours * 3600.0, &times);
        let mut ins = p.ins_run().expect("ins");
        let mut got = Vec::new();
        let mut next = 0;
        while next < times.len() {
            let out = ins.step();
            if out.updated && (out.t_s - times[next]).abs() < 0.5 / p.step_hz {
                let v = ins.view(out.t_s);
                let e = v.nav.expect("navigating");
                // Heading error = φ_U for a level vehicle heading North (computed = (I − [φ×]) true).
                got.push((e.east_m, e.north_m, v.errors[0].heading_rad));
                next += 1;
            }
        }
        let peak_pos = model.iter().map(|m| m.0.hypot(m.1)).fold(0.0f64, f64::max);
        let peak_psi = model.iter().map(|m| m.2.abs()).fold(0.0f64, f64::max);
        assert!(peak_pos > 100.0, "the biases matter: {peak_pos} m");
        for ((e, n, psi), (me, mn, mpsi)) in got.iter().zip(&model) {
            assert!((e - me).abs() < 0.02 * peak_pos && (n - mn).abs() < 0.02 * peak_pos, "position ({e:.1}, {n:.1}) vs model ({me:.1}, {mn:.1})");
            assert!((psi - mpsi).abs() < 0.02 * peak_psi, "heading {psi:e} vs model {mpsi:e}");
        }
    }
}
