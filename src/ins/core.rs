//! The navigation computer: measured IMU increments in, attitude and navigation out. One sample at
//! a time: FIR → decimation → attitude algorithm(s) → navigation. The simulation (`pipeline`) and
//! the replay of a log feed it the same way.
//!
//! Timing (docs/ins.md): after the FIR, sample k represents the truth at k·h − d (d = group delay);
//! the navigation computer's zero-order hold is a further h/2 (Li et al. 2014 §3.1); outputs are compared
//! with the truth `output_compensation` earlier (Li et al. 2014 §3.2's Δt).

use nalgebra::Vector3;

use super::InsParams;
use super::coning::Algorithm;
use super::fir::Fir;
use super::imu_errors::ImuErrors;
use super::nav::{NavState, Navigator};
use super::strapdown::AttitudeIntegrator;
use crate::math::attitude::Attitude;
use crate::math::frames::{B, N, Rot, S};
use crate::math::rotvec;
use crate::model::earth::{Earth, Site};

/// What one IMU sample produced. `repr(C)` keeps the flag beside the time: in Rust's own layout it
/// came last, and the replay's loop moved it and the bytes after it in overlapping 4-byte copies
/// that its next loads could not take from the stores in flight (a stall on every sample; the
/// replay of pyins' coning stream is 1.08× as fast with it, docs/benchmarks.md).
#[derive(Debug, Clone, Copy)]
#[repr(C)]
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

/// The navigation computer's state (cloned to fork one IMU stream into two navigation strategies).
#[derive(Debug, Clone)]
pub struct InsCore {
    cfg: InsParams,
    earth: Earth,
    fir_g: Fir,
    fir_a: Fir,
    h: f64,
    /// 1/h: the rates shown are increments × 1/h (two divisions per sample cost 3.5 % of the
    /// navigation computer's time on precomputed increments).
    inv_h: f64,
    acc: (Vector3<f64>, Vector3<f64>, usize),
    /// The integrators; `[0]` is the configured algorithm (the navigation's).
    integrators: Vec<AttitudeIntegrator>,
    /// (time, attitude) of each integrator's previous and latest update.
    history: Vec<[(f64, Rot<N, S>); 2]>,
    nav: Option<Navigator>,
    nav_start: Rot<N, S>,
    /// The primary update's samples so far (Δθ, Δv; at most N = 3, a fixed buffer: no heap on the hot path).
    upd_g: [Vector3<f64>; 3],
    upd_a: [Vector3<f64>; 3],
    upd_len: usize,
    /// Metres per radian of latitude and of longitude at the start site (R_M + h, (R_N + h) cos L):
    /// the navigation error is asked for at every update.
    site_m_per_rad: (f64, f64),
    /// FIR group delay, s.
    pub fir_delay_s: f64,
    /// Zero-order-hold delay, s.
    pub zoh_delay_s: f64,
    /// The sensor errors removed from every sample before anything else (a replay: the biases its
    /// alignment estimated, a calibration's estimates), or None.
    compensation: Option<ImuErrors>,
}

impl InsCore {
    /// IMU samples that fill the FIR and give the algorithms their previous samples before the
    /// first update (the first samples of a log, the samples before t = 0 of a simulation).
    #[must_use]
    pub fn pre_roll_samples(cfg: &InsParams) -> usize {
        cfg.fir_taps.len().saturating_sub(1).max(2 * cfg.decimation)
    }

    /// The computer at `site`, pre-rolled with `pre_roll` measured (Δθ, Δv) samples, its attitude
    /// C_s^n starting at `start` (the filtered stream's instant, −d).
    #[must_use]
    pub fn new(cfg: &InsParams, site: Site, start: Rot<N, S>, pre_roll: &[(Vector3<f64>, Vector3<f64>)]) -> Self {
        Self::compensated(cfg, site, start, pre_roll, None)
    }

    /// [`Self::new`] for a computer that removes the sensor errors `compensation` from every sample
    /// (`(I + K)⁻¹(measured − b·h)`), the pre-roll's included (a replay: the biases its alignment
    /// estimated).
    #[must_use]
    pub fn compensated(
        cfg: &InsParams,
        site: Site,
        start: Rot<N, S>,
        pre_roll: &[(Vector3<f64>, Vector3<f64>)],
        compensation: Option<ImuErrors>,
    ) -> Self {
        let cfg = cfg.clone();
        let h = 1.0 / cfg.rate_hz;
        let earth = Earth::at(site);
        let mut fir_g = Fir::new(&cfg.fir_taps);
        let mut fir_a = Fir::new(&cfg.fir_taps);
        let fir_delay_s = fir_g.group_delay_samples() * h;
        let zoh_delay_s = if cfg.zero_order_hold { 0.5 * h } else { 0.0 };
        let mut primed = Vec::new();
        let mut acc = (Vector3::zeros(), 0);
        for sample in pre_roll {
            let (g, a) = match &compensation {
                Some(c) => c.compensate(sample, h),
                None => *sample,
            };
            acc.0 += fir_g.push(g);
            acc.1 += 1;
            fir_a.push(a);
            if acc.1 == cfg.decimation {
                primed.push(acc.0);
                acc = (Vector3::zeros(), 0);
            }
        }
        let integrators: Vec<AttitudeIntegrator> = cfg
            .algorithms()
            .iter()
            .map(|a| {
                let mut i = AttitudeIntegrator::new(*a, start);
                i.prime(&primed);
                i
            })
            .collect();
        let history = vec![[(-fir_delay_s, start), (-fir_delay_s, start)]; integrators.len()];
        let nav = cfg.navigation.map(|o| Navigator::new(&earth, o));
        let (rm, rn) = Earth::radii(site.latitude_rad);
        let site_m_per_rad = (rm + site.height_m, (rn + site.height_m) * site.latitude_rad.cos());
        Self {
            site_m_per_rad,
            earth,
            fir_g,
            fir_a,
            h,
            inv_h: 1.0 / h,
            acc: (Vector3::zeros(), Vector3::zeros(), 0),
            integrators,
            history,
            nav,
            nav_start: start,
            upd_g: [Vector3::zeros(); 3],
            upd_a: [Vector3::zeros(); 3],
            upd_len: 0,
            fir_delay_s,
            zoh_delay_s,
            compensation,
            cfg,
        }
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

    /// How many algorithms run ([`Self::algorithms`] without its list: no allocation per update).
    #[must_use]
    pub fn algorithm_count(&self) -> usize {
        self.integrators.len()
    }

    /// Navigation solution, if navigating.
    #[must_use]
    pub fn nav_state(&self) -> Option<&NavState> {
        self.nav.as_ref().map(|n| &n.state)
    }

    /// The site the navigation started from.
    #[must_use]
    pub fn site(&self) -> Site {
        self.earth.site
    }

    /// Sets the navigation's velocity (East, North, Up), m/s: a start in motion.
    pub fn set_velocity(&mut self, v_enu_mps: Vector3<f64>) {
        if let Some(nav) = self.nav.as_mut() {
            nav.state.v_n = v_enu_mps;
        }
    }

    /// True when every algorithm has just completed an update (none holds part of the next).
    #[must_use]
    pub fn between_updates(&self) -> bool {
        self.acc.2 == 0 && self.upd_len == 0 && self.integrators.iter().all(AttitudeIntegrator::between_updates)
    }

    /// Each algorithm goes on from `from`'s attitude (the same algorithms, between two updates):
    /// a computer started anew at another rate continues the attitudes of the one it replaces.
    ///
    /// # Errors
    /// The algorithms differ, or `from` is in the middle of an update.
    pub fn continue_attitudes(&mut self, from: &Self) -> Result<(), String> {
        if self.algorithms() != from.algorithms() {
            return Err("the algorithms changed".into());
        }
        if !from.between_updates() {
            return Err("the computer is in the middle of an update".into());
        }
        for (k, integ) in self.integrators.iter_mut().enumerate() {
            integ.n_from_s = from.integrators[k].n_from_s;
            let latest = from.history[k][1];
            self.history[k] = [latest, latest];
        }
        Ok(())
    }

    /// Position fix: the navigation's latitude and longitude set to the truth (the site), velocity
    /// and the attitude relative to local level kept (the usual reset; docs/tpr.md).
    pub fn reset_position(&mut self) {
        let site = self.earth.site;
        if let Some(nav) = self.nav.as_mut() {
            nav.fix_position(&site);
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

    /// One measured IMU sample (Δθ, Δv in s) ending at `t1`.
    pub fn push(&mut self, t1: f64, g_meas: Vector3<f64>, a_meas: Vector3<f64>) -> SampleOut {
        let (g_meas, a_meas) = match &self.compensation {
            Some(c) => c.compensate(&(g_meas, a_meas), self.h),
            None => (g_meas, a_meas),
        };
        let g_filt = self.fir_g.push(g_meas);
        let a_filt = self.fir_a.push(a_meas);
        let out = SampleOut {
            t_s: t1,
            updated: false,
            raw_rate_s: g_meas * self.inv_h,
            filtered_rate_s: g_filt * self.inv_h,
        };
        if self.cfg.decimation == 1 {
            // No sums to keep (written and read back through memory they stalled the update).
            return self.push_decimated(t1, g_filt, a_filt, out);
        }
        self.acc.0 += g_filt;
        self.acc.1 += a_filt;
        self.acc.2 += 1;
        if self.acc.2 < self.cfg.decimation {
            return out;
        }
        let (dg, da) = (self.acc.0, self.acc.1);
        self.acc = (Vector3::zeros(), Vector3::zeros(), 0);
        self.push_decimated(t1, dg, da, out)
    }

    /// One algorithm sample (the decimated sums) ending at `t1`.
    #[inline]
    fn push_decimated(&mut self, t1: f64, dg: Vector3<f64>, da: Vector3<f64>, mut out: SampleOut) -> SampleOut {
        let h_alg = self.h * self.cfg.decimation as f64;
        // The attitude at the start of the primary update, for the velocity update.
        if self.upd_len == 0 {
            self.nav_start = self.integrators[0].n_from_s;
        }
        self.upd_g[self.upd_len] = dg;
        self.upd_a[self.upd_len] = da;
        self.upd_len += 1;
        let t_repr = t1 - self.fir_delay_s;
        // ω_in^n only for the updates that need it (it changes with the velocity: once per update).
        let w_in = if self.integrators.iter().any(AttitudeIntegrator::completes_with_next) {
            self.nav.as_ref().map_or(self.earth.omega_ie_n, Navigator::omega_in_n)
        } else {
            Vector3::zeros()
        };
        for (k, integ) in self.integrators.iter_mut().enumerate() {
            let zeta = w_in * (h_alg * integ.samples_per_update() as f64);
            if let Some(n_from_s) = integ.push(dg, &zeta) {
                self.history[k] = [self.history[k][1], (t_repr, n_from_s)];
                if k == 0 {
                    out.updated = true;
                    let m = self.upd_len;
                    if let Some(nav) = self.nav.as_mut() {
                        nav.update(&self.nav_start, &self.upd_g[..m], &self.upd_a[..m], &zeta, h_alg * m as f64);
                    }
                    self.upd_len = 0;
                }
            }
        }
        out
    }

    /// Integrator `k`'s C_s^n as output after its latest update, and the instant it represents:
    /// with the zero-order hold, the value h/2 earlier, interpolated between the two latest updates.
    #[must_use]
    #[inline]
    pub fn output_attitude(&self, k: usize) -> (f64, Rot<N, S>) {
        output_attitude(&self.history[k], self.zoh_delay_s)
    }

    /// Algorithm `k`'s latest attitude update, without the output's hold: (the instant it stands
    /// for, C_s^n) — the state to compare with another navigator run on the same samples.
    #[must_use]
    pub fn latest_attitude(&self, k: usize) -> (f64, Rot<N, S>) {
        self.history[k][1]
    }

    /// The instant the truth is taken at for an output representing `t_repr`: the output left the
    /// computer d + zoh after the instant it represents, and is compared `output_compensation` earlier.
    #[must_use]
    #[inline]
    pub fn reference_instant(&self, t_repr: f64) -> f64 {
        t_repr + self.fir_delay_s + self.zoh_delay_s - self.cfg.output_compensation_s
    }

    /// The navigation errors relative to the start site (the vehicle rests there), if navigating.
    #[must_use]
    #[inline]
    pub fn nav_error(&self) -> Option<NavError> {
        self.nav.as_ref().map(|n| {
            let s = &n.state;
            let site = self.earth.site;
            let (m_per_rad_north, m_per_rad_east) = self.site_m_per_rad;
            let north = (s.latitude_rad - site.latitude_rad) * m_per_rad_north;
            let east = (s.longitude_rad - site.longitude_rad) * m_per_rad_east;
            // metres: no overflow for hypot to guard against (and it cost 2.5 % of a replay).
            NavError {
                east_m: east,
                north_m: north,
                radial_m: (north * north + east * east).sqrt(),
                velocity_enu_mps: s.v_n,
            }
        })
    }

    /// The body attitude the primary INS outputs through the table rotation `b_from_s`.
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

    /// Whether every integrator's attitude and the navigation solution are finite numbers (what
    /// a replay checks after each update: a result is finite or not given).
    #[must_use]
    pub fn is_finite(&self) -> bool {
        // Without early exits (`&`, not `&&` or `all`): a replay asks after every update, and the
        // short-circuits were a branch per number (59 instructions a call, 4 % of the replay's loop).
        use crate::math::stats::all_finite;
        let attitudes =
            self.history.iter().fold(true, |all, h| all & all_finite(h[1].1.quaternion().coords.as_slice()));
        let nav = self.nav.as_ref().is_none_or(|n| {
            let s = &n.state;
            all_finite(&[s.latitude_rad, s.longitude_rad, s.height_m]) & all_finite(s.v_n.as_slice())
        });
        attitudes & nav
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_non_finite_sample_is_seen_at_the_next_update() {
        // Issue 20: the replay's last line of defence (`is_finite` after each update) must see a
        // NaN that got past the readers, in the attitude or in the navigation.
        let cfg = InsParams::ideal(200.0, crate::ins::coning::Algorithm::TwoSampleP1);
        let site = Site { latitude_rad: 0.6, longitude_rad: 1.9, height_m: 400.0 };
        let mut core = InsCore::new(&cfg, site, Rot::identity(), &[]);
        let (g, f) = (Vector3::new(1e-7, 0.0, 3e-7), Vector3::new(0.0, 0.0, 0.049));
        let mut t = 0.0;
        for _ in 0..10 {
            t += 0.005;
            core.push(t, g, f);
        }
        assert!(core.is_finite());
        let mut updated = false;
        for _ in 0..4 {
            t += 0.005;
            updated |= core.push(t, Vector3::new(f64::NAN, 0.0, 0.0), f).updated;
        }
        assert!(updated && !core.is_finite());
    }
}
