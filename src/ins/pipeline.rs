//! The INS in the loop on a simulated table: exact IMU truth → sensor errors and dither → the
//! navigation computer (`core`); and, on demand, the INS body attitude and its error against the
//! truth.

use nalgebra::Vector3;

use super::InsParams;
use super::coning::Algorithm;
use super::core::{InsCore, SampleOut};
use super::nav::NavState;
use super::sensor::Sensors;
use super::truth::TruthImu;
pub use super::view::{AlgorithmErrors, AttitudeOutput, InsOutputs, InsView, InsViewer};
use crate::math::attitude::Attitude;
use crate::math::frames::{B, N, Rot, S};
use crate::math::rotvec;
use crate::model::earth::{Earth, Site};
use crate::sim::Model;

/// The INS in the loop (cloned to fork one IMU stream into two navigation strategies).
#[derive(Clone)]
pub struct InsRun {
    truth: TruthImu,
    sensors: Sensors,
    core: InsCore,
    h: f64,
    index: u64,
    /// The measured (end time, Δθ, Δv) before t = 0 that pre-rolled the computer.
    pre_roll: Vec<(f64, Vector3<f64>, Vector3<f64>)>,
    /// The computer's initial C_s^n (at −d, with the alignment error).
    start: Rot<N, S>,
    /// The errors against the truth (the table's demodulation state).
    viewer: InsViewer,
    /// The algorithms' outputs of the latest view (kept: no allocation per view).
    attitudes: Vec<AttitudeOutput>,
    /// IMU errors the computer removes from every sample before using it (a self-calibration's
    /// estimates), if any.
    compensation: Option<super::imu_errors::ImuErrors>,
    /// The instant sample 0 ends at, s (0, or where a computer at another rate took over).
    t0_s: f64,
    /// The site and the noise seed it was built with (a computer at another rate takes them on).
    site: Site,
    seed: u64,
}

impl InsRun {
    /// Builds the INS `cfg` at `site` on the table `model` (sensor noise seeded with `seed`) and
    /// pre-rolls the FIR: the filter has been running before t = 0 on the same motion, and the
    /// algorithms that use previous samples have them.
    #[must_use]
    pub fn new(cfg: &InsParams, site: Site, seed: u64, model: Model) -> Self {
        Self::new_at(cfg, site, seed, model, 0.0)
    }

    /// [`Self::new`] with its samples ending at `t0_s` + k·h.
    fn new_at(cfg: &InsParams, site: Site, seed: u64, model: Model, t0_s: f64) -> Self {
        let h = 1.0 / cfg.rate_hz;
        let pre = InsCore::pre_roll_samples(cfg);
        let t_start = t0_s - (pre as f64) * h;
        let mut truth = TruthImu::new(model, Earth::at(site), t_start);
        let mut sensors = Sensors::selected(&cfg.errors, h, seed, t_start, &cfg.sources);
        let pre_roll: Vec<(f64, Vector3<f64>, Vector3<f64>)> = (0..pre)
            .map(|i| {
                let t1 = t_start + (i + 1) as f64 * h;
                let (g, a) = truth.increments(t1);
                let (g, a) = sensors.measure(&g, &a, t1);
                (t1, g, a)
            })
            .collect();
        // The filtered stream now stands at the truth of t = −d: start the attitude there, with the
        // alignment error φ applied as C = (I − [φ×]) C_true.
        let fir_delay_s = super::fir::Fir::new(&cfg.fir_taps).group_delay_samples() * h;
        let start = truth.eval(t0_s - fir_delay_s).n_from_s;
        // FRAME: the alignment error is a small rotation of the navigation frame (C = (I − [φ×]) C_true).
        let start: Rot<N, S> = Rot::<N, N>::from_quaternion(rotvec::exp(&-cfg.initial_error_rad)) * start;
        // A computer that compensates its IMU with a calibration's estimates reads increments in the
        // accelerometer triad's frame (docs/selfcal.md): it starts aligned in that frame, as a
        // perfect alignment of the compensated IMU would find it (ρ turned into n).
        let start = match cfg.imu_compensation {
            Some(_) => {
                let ((bg, ba), (kg, ka)) = (sensors.drawn_bias, sensors.drawn_gain_errors());
                let rho = super::imu_errors::ImuErrors { bg, kg, ba, ka }.accelerometer_frame_rotation();
                // FRAME: C_{s'}^n = C_s^n · C_{s'}^s with C_{s'}^s = exp(ρ) (docs/selfcal.md).
                Rot::<N, S>::from_quaternion(start.quaternion() * rotvec::exp(&rho))
            }
            None => start,
        };
        let samples: Vec<(Vector3<f64>, Vector3<f64>)> = pre_roll.iter().map(|(_, g, a)| (*g, *a)).collect();
        let core = InsCore::compensated(cfg, site, start, &samples, cfg.imu_compensation);
        let viewer = InsViewer::new(truth.model().clone(), h, core.algorithms().len());
        Self {
            truth,
            sensors,
            core,
            h,
            index: 0,
            pre_roll,
            start,
            viewer,
            attitudes: Vec::new(),
            // The computer (the core) removes `cfg.imu_compensation` itself: the samples stay raw.
            compensation: None,
            t0_s,
            site,
            seed,
        }
    }

    /// True when every algorithm has just completed an update: where the sample rate can change
    /// ([`Self::at_rate`]).
    #[must_use]
    pub fn between_updates(&self) -> bool {
        self.core.between_updates()
    }

    /// This INS going on at the rate of `cfg` from the end of its latest sample: a live session's
    /// new sample rate. Each algorithm keeps its attitude (its error goes on from where it was);
    /// the algorithms that use previous samples get them from the truth at the new rate, as a new
    /// run's do; the sensor noise is drawn anew at the new rate.
    ///
    /// # Errors
    /// Between two updates only; and not with a FIR or a decimation (their state is in samples of
    /// the old rate), with navigation (its state too), or with other algorithms.
    pub fn at_rate(&self, cfg: &InsParams) -> Result<Self, String> {
        if cfg.fir_taps.len() > 1 || cfg.decimation != 1 {
            return Err(
                "the sample rate of an IMU with a FIR or a decimation cannot change in a running session".into()
            );
        }
        if cfg.navigation.is_some() {
            return Err("the sample rate of a navigating INS cannot change in a running session".into());
        }
        let t0 = self.truth.t_last_s();
        let mut next = Self::new_at(cfg, self.site, self.seed, self.truth.model().clone(), t0);
        next.core.continue_attitudes(&self.core)?;
        next.compensation = self.compensation;
        Ok(next)
    }

    /// The measured (end time, Δθ, Δv) samples before t = 0 that pre-rolled the computer (what a log
    /// of this run starts with).
    #[must_use]
    pub fn pre_roll(&self) -> &[(f64, Vector3<f64>, Vector3<f64>)] {
        &self.pre_roll
    }

    /// The true C_s^n at `t_s` (what an alignment or a log's reference is checked against).
    pub fn true_n_from_s(&mut self, t_s: f64) -> Rot<N, S> {
        self.truth.n_from_s(t_s)
    }

    /// The computer's initial C_s^n (the truth at −d with the alignment error applied).
    #[must_use]
    pub fn start_attitude(&self) -> Rot<N, S> {
        self.start
    }

    /// The navigation computer.
    #[must_use]
    pub fn core(&self) -> &InsCore {
        &self.core
    }

    /// The navigation computer, for resets.
    pub fn core_mut(&mut self) -> &mut InsCore {
        &mut self.core
    }

    /// The configuration.
    #[must_use]
    pub fn config(&self) -> &InsParams {
        self.core.config()
    }

    /// The algorithms run, in order.
    #[must_use]
    pub fn algorithms(&self) -> Vec<Algorithm> {
        self.core.algorithms()
    }

    /// A live session's reload: the table (its errors, compensation, motion) is `model` from the
    /// next sample on; the sensors and the computer go on as they were.
    pub fn replace_model(&mut self, model: Model) {
        self.viewer.replace_model(model.clone());
        self.truth.replace_model(model);
    }

    /// The model (truth).
    #[must_use]
    pub fn model(&self) -> &Model {
        self.truth.model()
    }

    /// Navigation solution, if navigating.
    #[must_use]
    pub fn nav_state(&self) -> Option<&NavState> {
        self.core.nav_state()
    }

    /// The measured increments (Δθ, Δv) of the next IMU sample and its end time, without feeding
    /// them to the computer (for writing a log); compensated if [`Self::set_imu_compensation`] was.
    pub fn next_measurement(&mut self) -> (f64, Vector3<f64>, Vector3<f64>) {
        let (t1, g, a, _, _) = self.next_measurement_and_truth();
        (t1, g, a)
    }

    /// From the next sample on, the computer removes the IMU errors `c` from every sample
    /// (`(I + K)⁻¹(measured − b·h)`), or nothing with None.
    pub fn set_imu_compensation(&mut self, c: Option<super::imu_errors::ImuErrors>) {
        self.compensation = c;
    }

    /// The IMU's drawn constant errors (gyro bias rad/s, gain error; accelerometer bias m/s², gain
    /// error), for comparing a calibration with the truth.
    #[must_use]
    pub fn drawn_imu_errors(&self) -> super::imu_errors::ImuErrors {
        let (bg, ba) = self.sensors.drawn_bias;
        let (kg, ka) = self.sensors.drawn_gain_errors();
        super::imu_errors::ImuErrors { bg, kg, ba, ka }
    }

    /// Samples the sensors' saturation clipped so far, per axis: (gyros, accelerometers).
    #[must_use]
    pub fn saturation_counts(&self) -> ([u64; 3], [u64; 3]) {
        self.sensors.saturation_counts()
    }

    /// [`Self::next_measurement`] with the true increments it was measured from:
    /// (end time, Δθ, Δv, true Δθ, true Δv).
    pub fn next_measurement_and_truth(&mut self) -> (f64, Vector3<f64>, Vector3<f64>, Vector3<f64>, Vector3<f64>) {
        self.index += 1;
        let t1 = self.t0_s + self.index as f64 * self.h;
        let (g_true, a_true) = self.truth.increments(t1);
        let (g, a) = self.sensors.measure(&g_true, &a_true, t1);
        let (g, a) = match &self.compensation {
            Some(c) => c.compensate(&(g, a), self.h),
            None => (g, a),
        };
        (t1, g, a, g_true, a_true)
    }

    /// One IMU sample.
    pub fn step(&mut self) -> SampleOut {
        let (t1, g, a) = self.next_measurement();
        self.core.push(t1, g, a)
    }

    /// Integrator `k`'s C_s^n as output after its latest update, and the instant it represents.
    #[must_use]
    #[inline]
    pub fn output_attitude(&self, k: usize) -> (f64, Rot<N, S>) {
        self.core.output_attitude(k)
    }

    /// The INS body attitude errors (call right after a primary update at `t_s`). Each algorithm is
    /// compared at the instant its own latest output stands for (algorithms with more samples per
    /// update update less often), against the truth `output_compensation` earlier.
    pub fn view(&mut self, t_s: f64) -> InsView {
        self.view_with(t_s, true)
    }

    /// [`Self::view`] without the true IMU attitude (`imu_true` is None): the errors and the
    /// navigation, what statistics and plots take at every update.
    pub fn errors_view(&mut self, t_s: f64) -> InsView {
        self.view_with(t_s, false)
    }

    fn view_with(&mut self, t_s: f64, with_truth: bool) -> InsView {
        let mut attitudes = std::mem::take(&mut self.attitudes);
        attitudes.clear();
        let o = self.outputs(t_s, with_truth, &mut attitudes);
        let view = self.viewer.view(&o, &attitudes);
        self.attitudes = attitudes;
        view
    }

    /// The computer's outputs after a primary update at `t_s` (what [`Self::view`] shows), with
    /// the true C_s^n if `with_truth`, its algorithms' appended to `attitudes`: for an
    /// [`InsViewer`] elsewhere ([`Self::viewer`]).
    pub fn outputs(&mut self, t_s: f64, with_truth: bool, attitudes: &mut Vec<AttitudeOutput>) -> InsOutputs {
        let imu_true = with_truth.then(|| self.truth.n_from_s(self.core.output_attitude(0).0));
        InsOutputs::of(&self.core, t_s, imu_true, attitudes)
    }

    /// A viewer of this INS's outputs in its present state (a run's statistics' thread views the
    /// outputs [`Self::outputs`] sends it; this INS's own views are then not to be taken).
    #[must_use]
    pub fn viewer(&self) -> InsViewer {
        self.viewer.clone()
    }

    /// The body attitude the primary INS outputs (for tests and resets).
    #[must_use]
    pub fn body_attitude(&self, b_from_s: Rot<B, S>) -> Attitude {
        self.core.body_attitude(b_from_s)
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

    const STATIC_TABLE: &str =
        "[turntable]\n[[turntable.axis]]\nname = \"table\"\naxis = \"z\"\n[scheme]\nkind = \"static\"\n";

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
    fn a_view_repeated_at_the_same_instant_gives_the_same_errors() {
        // A table turning at 10°/s with a 2 ms encoder latch delay, compensated (the compensation
        // defaults to the truth), all five algorithms: each view is asked twice. The delay
        // correction takes its rate from successive readings; asked again for the same instant it
        // used to see a zero interval and drop the correction (10°/s × 2 ms = 72″). Every view must
        // also stay near zero: an error-free IMU with every table error compensated.
        let table = "[turntable]\n[[turntable.axis]]\nname = \"table\"\naxis = \"z\"\nencoder_delay_ms = 2.0\n[scheme]\nkind = \"continuous\"\n[[scheme.rate]]\naxis = \"table\"\nrate_deg_per_s = 10.0\n";
        let p = params("[imu]\ncompare = true\n", table);
        let mut worst = 0.0f64;
        let mut views = 0;
        run(&p, 5.0, |ins, t| {
            let a = ins.view(t);
            let b = ins.view(t);
            assert_eq!(a.errors, b.errors, "at {t} s");
            // The table starts turning at t = 0 from rest: the delay correction's rate, from
            // successive readings, needs a few updates after that step.
            if t > 0.1 {
                for e in &a.errors {
                    worst = worst.max(e.as_array().iter().fold(0.0f64, |m, x| m.max(x.abs())));
                }
            }
            views += 1;
        });
        assert!(views > 400 && p.ins.as_ref().is_some_and(|i| i.compare), "{views} views");
        // The delay is corrected to first order in the rate's change over one sample: far below 1″.
        assert!(worst * ARCSEC_PER_RAD < 1.0, "worst error {:.3}″", worst * ARCSEC_PER_RAD);
    }

    #[test]
    fn phase_lag_theorem_holds_for_the_fir_and_the_zero_order_hold() {
        // Li et al. 2014 eq. 16/19: a 7°, 0.5 Hz single-axis wobble seen through a 6.25 ms lag (FIR 12
        // samples at 2 kHz + ZOH 0.25 ms) has an error amplitude A·ω·t_d = 0.1374°. The theorem is
        // first order: the neglected (ωτ)²/2 = 2e-4 and the 2 kHz sampling of the peak; within 1e-3.
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
        assert!(
            (peak / expected - 1.0).abs() < 1e-3,
            "peak {:.5}° vs {:.5}°",
            peak.to_degrees(),
            expected.to_degrees()
        );
    }
}

#[cfg(test)]
mod bias_tests {
    use super::tests::params;
    use super::*;
    use crate::model::earth::{EARTH_RATE, normal_gravity};

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
            assert!(
                (e - me).abs() < 0.02 * peak_pos && (n - mn).abs() < 0.02 * peak_pos,
                "position ({e:.1}, {n:.1}) vs model ({me:.1}, {mn:.1})"
            );
            assert!((psi - mpsi).abs() < 0.02 * peak_psi, "heading {psi:e} vs model {mpsi:e}");
        }
    }
}
