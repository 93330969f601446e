//! System-level self-calibration of a RINS's IMU on its own gimbals (docs/selfcal.md).
//!
//! The table turns the IMU through a sequence of positions; at rest on the Earth the true
//! velocity is zero, so the free-inertial velocity the IMU's own navigation computes is a
//! measurement of the navigation errors, which the IMU's errors drive differently in every
//! orientation and during every move. A Kalman filter on the φ-angle error model
//! (attitude error φ, velocity error δv) augmented with the 21 constant IMU errors estimates them:
//! gyro bias b_g (3), the gyro gain error K_g (9: scale factors on the diagonal, the six
//! misalignments off it) and accelerometer bias b_a (3) with the upper triangle of K_a (6), where
//! measured = (I + K)·true + b. The lower triangle of K_a is not estimated: rotating both triads
//! together by ρ changes K_g and K_a by the same [ρ×] and only the IMU's attitude, which the
//! navigation estimates anyway; the accelerometer triad therefore defines the IMU frame
//! ([`ImuErrors::in_accelerometer_frame`]).
//!
//! Why a filter and no smoother: every calibrated parameter is a constant, and for a linear
//! Gaussian model the forward filter's final estimate of a constant is its smoothed estimate (the
//! backward pass changes only the time-varying navigation states). The estimator never reads the
//! truth; the sequence is known only as the IMU measures it.

use nalgebra::{SMatrix, SVector, UnitQuaternion, Vector3};

use crate::ins::align::Increment;
use crate::ins::imu_errors::KA_UPPER;
pub use crate::ins::imu_errors::{ImuErrors, Kind, N_PARAMS, param, param_names};
use crate::ins::sensor::{ImuErrorSpec, Spec};
use crate::math::rotvec;
use crate::math::units::{ARCSEC_PER_RAD, MPS2_PER_UG, RAD_PER_DEG, RAD_PER_S_PER_DEG_PER_H};
use crate::model::earth::Earth;
use crate::model::scheme::IndexedStep;

/// Filter states: φ, δv, then the parameters.
const N: usize = 6 + N_PARAMS;
type Mat = SMatrix<f64, N, N>;
type Vec27 = SVector<f64, N>;
type Block = SMatrix<f64, 6, N_PARAMS>;

/// A built-in calibration sequence of a dual-axis table (outer axis first in the chain, the inner
/// one carrying the IMU about its z): table moves and dwells.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sequence {
    /// 19 positions joined by 18 rotations of 90° and 180° about each IMU axis (z while
    /// horizontal), in both senses, 240 s at each, after PSINS's systematic calibration
    /// (`sysclbt`); 1.4 h.
    Positions19,
    /// 29 positions: about the IMU's z (held horizontal), y and x in turn, four quarter turns
    /// forward and four back, 160 s at each (the kind of sequence Cai et al. 2016 and Ren et al.
    /// 2019 use); 1.4 h.
    DualAxis29,
    /// Only the inner (azimuth) axis turns: what it cannot see is the point (a degenerate case).
    AzimuthOnly,
}

impl Sequence {
    /// Every built-in, with its command-line name.
    pub const ALL: [(Self, &'static str); 3] =
        [(Self::Positions19, "positions-19"), (Self::DualAxis29, "dual-axis-29"), (Self::AzimuthOnly, "azimuth-only")];

    /// By its command-line name.
    #[must_use]
    pub fn named(name: &str) -> Option<Self> {
        Self::ALL.iter().find(|(_, n)| *n == name).map(|(s, _)| *s)
    }

    /// Its command-line name.
    #[must_use]
    pub fn name(self) -> &'static str {
        Self::ALL.iter().find(|(s, _)| *s == self).map_or("", |(_, n)| n)
    }

    /// The table moves (outer axis 0, inner axis 1) and the dwell before the first move, s.
    #[must_use]
    pub fn steps(self) -> (f64, Vec<IndexedStep>) {
        // (axis, degrees): the inner axis is the IMU's z; the outer turns the IMU about its y
        // with the inner at 0° or 180°, about its x with the inner at ±90°.
        let (z, o) = (1usize, 0usize);
        let (moves, dwell): (Vec<(usize, f64)>, f64) = match self {
            Self::Positions19 => (
                vec![
                    (o, 90.0), // z horizontal
                    (z, 90.0),
                    (z, 90.0),
                    (z, 90.0),
                    (z, 90.0), // about z, gravity sweeping the x-y plane
                    (o, 90.0),
                    (o, 90.0),
                    (o, 90.0), // about y: z down, horizontal, up
                    (z, 90.0), // x onto the outer axis
                    (o, 90.0),
                    (o, 90.0),
                    (o, 90.0),
                    (o, 90.0), // about x
                    (o, -180.0),
                    (o, 180.0), // about x, back and forth
                    (z, -90.0), // y onto the outer axis
                    (o, -180.0),
                    (o, 180.0), // about y, back and forth
                ],
                240.0,
            ),
            Self::DualAxis29 => {
                let mut m = vec![(o, 90.0)];
                // About z with z horizontal (a z scale error then tilts the IMU, which the
                // accelerometers see; about a vertical z it would only turn the heading).
                m.extend(std::iter::repeat_n((z, 90.0), 4));
                m.extend(std::iter::repeat_n((z, -90.0), 4));
                m.push((o, -90.0));
                // About y (inner at 0°), then about x (inner at 90°).
                m.extend(std::iter::repeat_n((o, 90.0), 4));
                m.extend(std::iter::repeat_n((o, -90.0), 4));
                m.push((z, 90.0));
                m.extend(std::iter::repeat_n((o, 90.0), 4));
                m.extend(std::iter::repeat_n((o, -90.0), 4));
                m.push((z, -90.0));
                (m, 160.0)
            }
            Self::AzimuthOnly => (
                std::iter::repeat_n((z, 90.0), 4)
                    .chain(std::iter::repeat_n((z, -90.0), 4))
                    .chain(std::iter::repeat_n((z, 90.0), 4))
                    .collect(),
                300.0,
            ),
        };
        let rate = 10.0 * RAD_PER_DEG;
        let steps = moves
            .into_iter()
            .map(|(axis, deg)| IndexedStep {
                axis,
                angle_rad: deg * RAD_PER_DEG,
                rate_rad_per_s: rate,
                dwell_s: dwell,
                accel_rad_per_s2: rate,
            })
            .collect();
        (INITIAL_DWELL_S, steps)
    }
}

impl Sequence {
    /// The table's motion through the sequence (outer and inner axis from 0°, not repeated).
    #[must_use]
    pub fn scheme(self) -> crate::model::scheme::Scheme {
        let (dwell, steps) = self.steps();
        crate::model::scheme::Scheme::indexed(vec![0.0; 2], dwell, steps, false)
    }

    /// Its length, s: the first dwell and every move with its dwell.
    #[must_use]
    pub fn duration_s(self) -> f64 {
        let scheme = self.scheme();
        self.steps().0 + scheme.period_s()
    }
}

/// The dwell before the first move: the coarse alignment's data, s.
pub const INITIAL_DWELL_S: f64 = 300.0;

/// What the filter knows beyond the data.
#[derive(Debug, Clone, Copy)]
pub struct Config {
    /// The sample interval, s.
    pub h: f64,
    /// Samples per filter step (propagation and one velocity update).
    pub samples_per_update: usize,
    /// The site's Earth (rate and gravity).
    pub earth: Earth,
    /// Gyro angle random walk, rad/√s, and accelerometer velocity random walk, m/s/√s (the
    /// datasheet's).
    pub random_walk: (f64, f64),
    /// Prior 1σ of the 21 parameters, SI.
    pub prior: [f64; N_PARAMS],
    /// 1σ of the zero-velocity measurement, m/s (what the IMU's own base moves).
    pub velocity_sigma_mps: f64,
    /// Samples of the initial dwell used for the coarse alignment.
    pub align_samples: usize,
}

impl Config {
    /// The filter for samples every `h` s at `earth`, aligned on the first `align_samples`, knowing
    /// what the IMU's datasheet `imu` says: its random walks (process noise) and its 1σ (priors).
    #[must_use]
    pub fn for_datasheet(imu: &ImuErrorSpec, h: f64, earth: Earth, align_samples: usize) -> Self {
        let sigma = |s: Spec| match s {
            Spec::Sigma(x) if x > 0.0 => Some(x),
            _ => None,
        };
        let angle = |a: f64| (a > 0.0).then_some(a);
        let datasheet: [Option<f64>; N_PARAMS] = std::array::from_fn(|k| match param(k).0 {
            Kind::GyroBias => sigma(imu.gyro.bias_rad_per_s),
            Kind::GyroScale => sigma(imu.gyro.scale),
            Kind::GyroMisalignment => angle(imu.gyro.misalignment_rad),
            Kind::AccelBias => sigma(imu.accel.bias_mps2),
            Kind::AccelScale => sigma(imu.accel.scale),
            Kind::AccelMisalignment => angle(imu.accel.misalignment_rad),
        });
        Self {
            h,
            samples_per_update: ((0.1 / h).round() as usize).max(1),
            earth,
            random_walk: (imu.gyro.noise.random_walk_si.max(1e-9), imu.accel.noise.random_walk_si.max(1e-8)),
            prior: Self::priors(&datasheet),
            velocity_sigma_mps: 1e-5,
            align_samples,
        }
    }

    /// Priors wide enough for a navigation- to tactical-grade IMU, or three times the datasheet's
    /// 1σ where that is larger (`datasheet` in SI, None where it says nothing).
    #[must_use]
    pub fn priors(datasheet: &[Option<f64>; N_PARAMS]) -> [f64; N_PARAMS] {
        let mut p = [0.0; N_PARAMS];
        for (k, out) in p.iter_mut().enumerate() {
            let floor = match param(k).0 {
                Kind::GyroBias => 0.1 * RAD_PER_S_PER_DEG_PER_H,
                Kind::GyroScale | Kind::AccelScale => 300e-6,
                Kind::GyroMisalignment | Kind::AccelMisalignment => 300.0 / ARCSEC_PER_RAD,
                Kind::AccelBias => 1000.0 * MPS2_PER_UG,
            };
            *out = datasheet[k].map_or(floor, |s| (3.0 * s).max(floor));
        }
        p
    }
}

/// One row of the filter's history (1 Hz).
#[derive(Debug, Clone, serde::Serialize)]
pub struct HistoryRow {
    /// Time from the start, s.
    pub t_s: f64,
    /// Estimates, SI.
    pub estimate: [f64; N_PARAMS],
    /// 1σ, SI.
    pub sigma: [f64; N_PARAMS],
}

/// The self-calibration filter: feed it the IMU's increments in order.
pub struct SelfCal {
    cfg: Config,
    /// C_s^n of the navigation and its velocity (ENU), m/s.
    q: UnitQuaternion<f64>,
    v: Vector3<f64>,
    x: Vec27,
    p: Mat,
    /// F of (φ, δv) (constant at rest: f^n = −g^n).
    f_nn: SMatrix<f64, 6, 6>,
    /// Φ of (φ, δv) over one filter step.
    a: SMatrix<f64, 6, 6>,
    /// ∫ G dt and ∫ (T − t) G dt over the current step.
    s: Block,
    w: Block,
    k: usize,
    t_s: f64,
    history: Vec<HistoryRow>,
    next_history_s: f64,
}

/// What the filter found.
#[derive(Debug, Clone)]
pub struct Estimate {
    /// The 21 estimates, SI.
    pub params: [f64; N_PARAMS],
    /// Their 1σ, SI.
    pub sigma: [f64; N_PARAMS],
    /// Their final covariance (correlations: aliasing).
    pub covariance: SMatrix<f64, N_PARAMS, N_PARAMS>,
    /// The prior 1σ.
    pub prior: [f64; N_PARAMS],
    /// 1σ and estimates at 1 Hz.
    pub history: Vec<HistoryRow>,
}

impl SelfCal {
    /// Aligned on `align` (the first samples of the initial dwell, coarse alignment); None if they
    /// cannot give an attitude (too few, or no Earth-rate signature).
    #[must_use]
    pub fn new(cfg: Config, align: &[Increment]) -> Option<Self> {
        let align_cfg = crate::ins::align::AlignConfig {
            latitude_rad: cfg.earth.site.latitude_rad,
            height_m: cfg.earth.site.height_m,
            interval_s: cfg.h,
            gyro_bias_sigma_rad_per_s: None,
            accel_bias_sigma_mps2: None,
            gyro_random_walk: None,
            accel_random_walk: None,
        };
        let q = *crate::ins::align::coarse(align, &align_cfg)?.quaternion();
        let big_t = cfg.h * cfg.samples_per_update as f64;
        let omega = cfg.earth.omega_ie_n.cross_matrix();
        let f_n = (-cfg.earth.gravity_n).cross_matrix();
        let mut f_nn = SMatrix::<f64, 6, 6>::zeros();
        f_nn.fixed_view_mut::<3, 3>(0, 0).copy_from(&(-omega));
        f_nn.fixed_view_mut::<3, 3>(3, 0).copy_from(&f_n);
        f_nn.fixed_view_mut::<3, 3>(3, 3).copy_from(&(-2.0 * omega));
        let ft = f_nn * big_t;
        let a = SMatrix::<f64, 6, 6>::identity() + ft + ft * ft * 0.5 + ft * ft * ft / 6.0;
        let mut p = Mat::zeros();
        // Coarse alignment: tilt to ~accelerometer bias / g, heading to ~gyro bias / Earth rate.
        for (i, s) in [3e-4, 3e-4, 3e-3, 1e-3, 1e-3, 1e-3].into_iter().enumerate() {
            p[(i, i)] = s * s;
        }
        for k in 0..N_PARAMS {
            p[(6 + k, 6 + k)] = cfg.prior[k] * cfg.prior[k];
        }
        Some(Self {
            cfg,
            q,
            v: Vector3::zeros(),
            x: Vec27::zeros(),
            p,
            f_nn,
            a,
            s: Block::zeros(),
            w: Block::zeros(),
            k: 0,
            t_s: 0.0,
            history: Vec::new(),
            next_history_s: 0.0,
        })
    }

    /// Takes one sample's (Δθ, Δv).
    pub fn push(&mut self, (dtheta, dv): &Increment) {
        let h = self.cfg.h;
        let c = (self.q * rotvec::exp(&(dtheta * 0.5))).to_rotation_matrix().into_inner();
        // The navigation at the site: C_s^n turned by the IMU and by the Earth under it.
        self.v += c * dv + (self.cfg.earth.gravity_n - 2.0 * self.cfg.earth.omega_ie_n.cross(&self.v)) * h;
        self.q = rotvec::exp(&(-self.cfg.earth.omega_ie_n * h)) * self.q * rotvec::exp(dtheta);
        // How the parameters drive φ (−C δω) and δv (C δf) over this sample, and weighted by the
        // time left in the step (their effect on δv through f^n × φ).
        let weight = h * (self.cfg.samples_per_update - self.k) as f64 - 0.5 * h;
        for i in 0..3 {
            let col = c.column(i);
            for r in 0..3 {
                let g_bias = -col[r] * h;
                self.s[(r, i)] += g_bias;
                self.w[(r, i)] += g_bias * weight;
                for j in 0..3 {
                    let gk = -col[r] * dtheta[j];
                    self.s[(r, 3 + 3 * i + j)] += gk;
                    self.w[(r, 3 + 3 * i + j)] += gk * weight;
                }
                let a_bias = col[r] * h;
                self.s[(3 + r, 12 + i)] += a_bias;
                self.w[(3 + r, 12 + i)] += a_bias * weight;
            }
        }
        for (u, &(i, j)) in KA_UPPER.iter().enumerate() {
            for r in 0..3 {
                let g = c[(r, i)] * dv[j];
                self.s[(3 + r, 15 + u)] += g;
                self.w[(3 + r, 15 + u)] += g * weight;
            }
        }
        self.k += 1;
        self.t_s += h;
        if self.k == self.cfg.samples_per_update {
            self.step();
        }
    }

    /// One filter step: propagation over the step, the zero-velocity update, the reset of φ and
    /// δv into the navigation.
    fn step(&mut self) {
        let big_t = self.cfg.h * self.k as f64;
        let b = self.s + self.f_nn * self.w;
        let a = self.a;
        let p = &mut self.p;
        let pnn = p.fixed_view::<6, 6>(0, 0).into_owned();
        let pnp = p.fixed_view::<6, N_PARAMS>(0, 6).into_owned();
        let ppp = p.fixed_view::<N_PARAMS, N_PARAMS>(6, 6).into_owned();
        let pnp_new = a * pnp + b * ppp;
        let mut pnn_new = (a * pnn + b * pnp.transpose()) * a.transpose() + pnp_new * b.transpose();
        let (arw, vrw) = self.cfg.random_walk;
        for i in 0..3 {
            pnn_new[(i, i)] += arw * arw * big_t;
            pnn_new[(3 + i, 3 + i)] += vrw * vrw * big_t;
        }
        p.fixed_view_mut::<6, 6>(0, 0).copy_from(&pnn_new);
        p.fixed_view_mut::<6, N_PARAMS>(0, 6).copy_from(&pnp_new);
        p.fixed_view_mut::<N_PARAMS, 6>(6, 0).copy_from(&pnp_new.transpose());
        // The navigation errors the parameter estimates predict (φ and δv were reset to 0).
        let xp = self.x.fixed_rows::<N_PARAMS>(6).into_owned();
        let xn = b * xp;
        self.x.fixed_rows_mut::<6>(0).copy_from(&xn);
        // Zero velocity: z = v = δv.
        let r = self.cfg.velocity_sigma_mps.powi(2);
        let ph = p.fixed_columns::<3>(3).into_owned(); // P Hᵀ
        let mut s = ph.fixed_rows::<3>(3).into_owned();
        for i in 0..3 {
            s[(i, i)] += r;
        }
        if let Some(s_inv) = s.try_inverse() {
            let gain = ph * s_inv;
            let innovation = self.v - self.x.fixed_rows::<3>(3);
            self.x += gain * innovation;
            *p -= gain * ph.transpose();
            *p = (*p + p.transpose()) * 0.5;
        }
        // Feedback: C_s^n ← exp(φ) C̃, v ← ṽ − δv.
        let phi = self.x.fixed_rows::<3>(0).into_owned();
        self.q = rotvec::exp(&phi) * self.q;
        self.v -= self.x.fixed_rows::<3>(3);
        self.x.fixed_rows_mut::<6>(0).fill(0.0);
        self.s = Block::zeros();
        self.w = Block::zeros();
        self.k = 0;
        if self.t_s + 1e-9 >= self.next_history_s {
            self.history.push(HistoryRow { t_s: self.t_s, estimate: self.params(), sigma: self.sigma() });
            self.next_history_s += 1.0;
        }
    }

    fn params(&self) -> [f64; N_PARAMS] {
        std::array::from_fn(|k| self.x[6 + k])
    }

    fn sigma(&self) -> [f64; N_PARAMS] {
        std::array::from_fn(|k| self.p[(6 + k, 6 + k)].max(0.0).sqrt())
    }

    /// The estimates after the last sample.
    #[must_use]
    pub fn finish(self) -> Estimate {
        Estimate {
            params: self.params(),
            sigma: self.sigma(),
            covariance: self.p.fixed_view::<N_PARAMS, N_PARAMS>(6, 6).into_owned(),
            prior: self.cfg.prior,
            history: self.history,
        }
    }
}

/// How well a sequence sees each parameter: its 1σ over its prior at the end, and when it first
/// fell under half the prior.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Observability {
    /// Per parameter: σ_end / σ_0.
    pub ratio: [f64; N_PARAMS],
    /// Per parameter: the time σ first fell under a tenth of σ_0, s (None: never).
    pub observable_from_s: [Option<f64>; N_PARAMS],
    /// Parameters whose 1σ fell by less than half: not observable from this sequence.
    pub unobservable: Vec<String>,
    /// Parameters whose 1σ fell by half but stayed above a tenth of the prior: weakly observable.
    pub weak: Vec<String>,
    /// Pairs the data cannot tell apart (|correlation| ≥ 0.9), with the combination they can see.
    pub aliased: Vec<String>,
}

/// The observability of `e` (a run on data or a plan on the sequence's noise-free motion).
#[must_use]
pub fn observability(e: &Estimate) -> Observability {
    let ratio: [f64; N_PARAMS] = std::array::from_fn(|k| e.sigma[k] / e.prior[k]);
    let observable_from_s =
        std::array::from_fn(|k| e.history.iter().find(|r| r.sigma[k] < 0.1 * e.prior[k]).map(|r| r.t_s));
    let unobservable = (0..N_PARAMS).filter(|&k| ratio[k] > 0.5).map(|k| param(k).1).collect();
    let weak = (0..N_PARAMS).filter(|&k| ratio[k] > 0.1 && ratio[k] <= 0.5).map(|k| param(k).1).collect();
    let mut aliased = Vec::new();
    for i in 0..N_PARAMS {
        for j in i + 1..N_PARAMS {
            let rho = e.covariance[(i, j)] / (e.covariance[(i, i)] * e.covariance[(j, j)]).sqrt();
            if rho.abs() >= 0.9 {
                // The combination with the smaller variance: x_i/σ_i ∓ x_j/σ_j.
                let sign = if rho > 0.0 { "−" } else { "+" };
                aliased.push(format!(
                    "{} and {} (correlation {rho:+.3}): the data see {}/σ {sign} {}/σ",
                    param(i).1,
                    param(j).1,
                    param(i).1,
                    param(j).1
                ));
            }
        }
    }
    Observability { ratio, observable_from_s, unobservable, weak, aliased }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sequences_stay_within_two_hours_and_end_where_they_started() {
        for (s, _) in Sequence::ALL {
            let steps = s.steps().1;
            let total = s.duration_s();
            assert!(total <= 2.0 * 3600.0, "{}: {total} s", s.name());
            for axis in 0..2 {
                let turned: f64 = steps.iter().filter(|m| m.axis == axis).map(|m| m.angle_rad).sum();
                assert!(
                    (turned / std::f64::consts::TAU).fract().abs() < 1e-9,
                    "{}: axis {axis} ends at {turned} rad",
                    s.name()
                );
            }
        }
    }
}
