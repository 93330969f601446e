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
//! With the table's encoder readings the filter also measures the IMU's attitude on the base
//! (`selfcal_table`): the navigation's attitude error φ directly, and the table's errors in the
//! combinations the shafts' motion separates (per axis: the rotation after the shaft across it,
//! the encoder's scale and delay), with the base's own attitude ψ as a nuisance.
//!
//! Why a filter and no smoother: every calibrated parameter is a constant, and for a linear
//! Gaussian model the forward filter's final estimate of a constant is its smoothed estimate (the
//! backward pass changes only the time-varying navigation states). The estimator never reads the
//! truth; the sequence is known only as the IMU measures it.

use nalgebra::{SMatrix, SVector, UnitQuaternion, Vector3};

use super::selfcal_table::{MAX_TABLE, TableStates};
pub use super::sequence::{INITIAL_DWELL_S, Sequence};
use crate::ins::align::Increment;
use crate::ins::imu_errors::KA_UPPER;
pub use crate::ins::imu_errors::{ImuErrors, Kind, N_PARAMS, param, param_names};
use crate::ins::sensor::{ImuErrorSpec, Spec};
use crate::math::rotvec;
use crate::math::units::{ARCSEC_PER_RAD, MPS2_PER_UG, RAD_PER_S_PER_DEG_PER_H};
use crate::model::earth::Earth;
use crate::model::scheme::AxisValues;

/// The parameters: the IMU's 21, the table's (at most [`MAX_TABLE`]; unused ones have no
/// variance) and the base's attitude ψ (3).
const NP: usize = N_PARAMS + MAX_TABLE + 3;
/// Filter states: φ, δv, then the parameters.
const N: usize = 6 + NP;
/// Where the table's states start, and ψ's.
const TABLE0: usize = 6 + N_PARAMS;
const PSI0: usize = TABLE0 + MAX_TABLE;
type Mat = SMatrix<f64, N, N>;
type StateVec = SVector<f64, N>;
type Block = SMatrix<f64, 6, N_PARAMS>;

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
    /// The table's estimates and 1σ, SI (empty without encoders).
    pub table_estimate: Vec<f64>,
    /// Their 1σ.
    pub table_sigma: Vec<f64>,
}

/// What the filter knows of the table: its chain (the states) and its encoders' noise.
#[derive(Debug, Clone)]
pub struct TableConfig {
    /// The states of the table's chain.
    pub states: TableStates,
    /// Each encoder's reading noise, 1σ, rad (the table's datasheet).
    pub encoder_sigma_rad: Vec<f64>,
    /// The states' prior mean (empty: zero). An extended Kalman filter's first updates are
    /// linearized about its prior, and a constant keeps their error: a second pass about the
    /// first's result removes it (the prior's 1σ stays as wide, so the data still decide).
    pub linearized_at: Vec<f64>,
}

/// The table's part of an estimate.
#[derive(Debug, Clone)]
pub struct TableEstimate {
    /// The states (the chain they belong to: their names and priors).
    pub states: TableStates,
    /// The estimates, SI.
    pub params: Vec<f64>,
    /// Their 1σ.
    pub sigma: Vec<f64>,
    /// The covariance of the IMU's 21 and the table's states together (correlations: aliasing).
    pub covariance: nalgebra::DMatrix<f64>,
}

/// The self-calibration filter: feed it the IMU's increments in order.
pub struct SelfCal {
    cfg: Config,
    /// C_s^n of the navigation and its velocity (ENU), m/s.
    q: UnitQuaternion<f64>,
    v: Vector3<f64>,
    /// The last sample's Δθ (the coning correction).
    last_dtheta: Vector3<f64>,
    x: StateVec,
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
    /// The table's states, and the encoder readings of the last 2m + 1 samples with the
    /// navigation's attitude at each (newest last).
    table: Option<TableConfig>,
    readings: std::collections::VecDeque<(AxisValues, UnitQuaternion<f64>)>,
    /// The base's attitude the encoder measurements are referred to (the first's).
    c_ref: Option<UnitQuaternion<f64>>,
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
    /// The table's part (with encoder readings).
    pub table: Option<TableEstimate>,
}

impl SelfCal {
    /// Aligned on `align` (the first samples of the initial dwell, coarse alignment); None if they
    /// cannot give an attitude (too few, or no Earth-rate signature).
    /// With `table`, every sample comes with its encoder readings ([`Self::push_with_encoders`]).
    #[must_use]
    pub fn new(cfg: Config, table: Option<TableConfig>, align: &[Increment]) -> Option<Self> {
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
        let mut x = StateVec::zeros();
        // Coarse alignment: tilt to ~accelerometer bias / g, heading to ~gyro bias / Earth rate.
        for (i, s) in [3e-4, 3e-4, 3e-3, 1e-3, 1e-3, 1e-3].into_iter().enumerate() {
            p[(i, i)] = s * s;
        }
        for k in 0..N_PARAMS {
            p[(6 + k, 6 + k)] = cfg.prior[k] * cfg.prior[k];
        }
        if let Some(t) = &table {
            for (j, s) in t.states.priors().into_iter().enumerate() {
                p[(TABLE0 + j, TABLE0 + j)] = s * s;
            }
            for (j, m) in t.linearized_at.iter().enumerate() {
                x[TABLE0 + j] = *m;
            }
            // The base's attitude: anything up to half a degree (installation, first encoder's
            // offset, the coarse alignment's error).
            for i in 0..3 {
                p[(PSI0 + i, PSI0 + i)] = 1e-2 * 1e-2;
            }
        }
        Some(Self {
            cfg,
            q,
            v: Vector3::zeros(),
            last_dtheta: Vector3::zeros(),
            x,
            p,
            f_nn,
            a,
            s: Block::zeros(),
            w: Block::zeros(),
            k: 0,
            t_s: 0.0,
            history: Vec::new(),
            next_history_s: 0.0,
            table,
            readings: std::collections::VecDeque::new(),
            c_ref: None,
        })
    }

    /// Takes one sample's (Δθ, Δv) and the encoders' readings at its end, rad (used by a filter
    /// made with a table).
    pub fn push_with_encoders(&mut self, m: &Increment, readings: &AxisValues) {
        self.integrate(m);
        if self.readings.len() == 2 * self.half_window() + 1 {
            self.readings.pop_front();
        }
        self.readings.push_back((*readings, self.q));
        self.step_if_due();
    }

    /// Takes one sample's (Δθ, Δv).
    pub fn push(&mut self, m: &Increment) {
        self.integrate(m);
        self.step_if_due();
    }

    /// m: the encoder measurement is made m samples back, its shafts' rates from the readings m
    /// samples either side (20 ms).
    fn half_window(&self) -> usize {
        ((0.02 / self.cfg.h).round() as usize).max(1)
    }

    fn step_if_due(&mut self) {
        if self.k == self.cfg.samples_per_update {
            self.step();
        }
    }

    /// The navigation and the parameters' input matrices over one sample.
    fn integrate(&mut self, (dtheta, dv): &Increment) {
        let h = self.cfg.h;
        let c = (self.q * rotvec::exp(&(dtheta * 0.5))).to_rotation_matrix().into_inner();
        // The navigation at the site: C_s^n turned by the IMU and by the Earth under it.
        self.v += c * dv + (self.cfg.earth.gravity_n - 2.0 * self.cfg.earth.omega_ie_n.cross(&self.v)) * h;
        // The attitude by the rotation vector of the sample, not its increment: a gyro's Δθ is ∫ω dt,
        // and while a shaft turns the Earth's rate turns with it in the IMU's axes (coning; the
        // one-sample-back correction Δθ + Δθ₋₁ × Δθ / 12, Savage 1998). Uncorrected it is 0.05″ a
        // move, which biased the encoder scales.
        let rotation = dtheta + self.last_dtheta.cross(dtheta) / 12.0;
        self.last_dtheta = *dtheta;
        self.q = rotvec::exp(&(-self.cfg.earth.omega_ie_n * h)) * self.q * rotvec::exp(&rotation);
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
    }

    /// One filter step: propagation over the step, the zero-velocity update, the reset of φ and
    /// δv into the navigation.
    fn step(&mut self) {
        let big_t = self.cfg.h * self.k as f64;
        let b = self.s + self.f_nn * self.w;
        let a = self.a;
        let p = &mut self.p;
        // Only the IMU's parameters drive φ and δv: Φ = [[A, B, 0], [0, I, 0], [0, 0, I]].
        let pnn = p.fixed_view::<6, 6>(0, 0).into_owned();
        let pnp = p.fixed_view::<6, NP>(0, 6).into_owned();
        let pimu = p.fixed_view::<N_PARAMS, NP>(6, 6).into_owned();
        let pnp_new = a * pnp + b * pimu;
        let mut pnn_new = (a * pnn + b * pnp.fixed_columns::<N_PARAMS>(0).transpose()) * a.transpose()
            + pnp_new.fixed_columns::<N_PARAMS>(0) * b.transpose();
        let (arw, vrw) = self.cfg.random_walk;
        for i in 0..3 {
            pnn_new[(i, i)] += arw * arw * big_t;
            pnn_new[(3 + i, 3 + i)] += vrw * vrw * big_t;
        }
        p.fixed_view_mut::<6, 6>(0, 0).copy_from(&pnn_new);
        p.fixed_view_mut::<6, NP>(0, 6).copy_from(&pnp_new);
        p.fixed_view_mut::<NP, 6>(6, 0).copy_from(&pnp_new.transpose());
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
        self.encoder_update();
        // Feedback: C_s^n ← exp(φ) C̃, v ← ṽ − δv.
        let phi = self.x.fixed_rows::<3>(0).into_owned();
        let turn = rotvec::exp(&phi);
        self.q = turn * self.q;
        for (_, q) in &mut self.readings {
            *q = turn * *q;
        }
        self.v -= self.x.fixed_rows::<3>(3);
        self.x.fixed_rows_mut::<6>(0).fill(0.0);
        self.s = Block::zeros();
        self.w = Block::zeros();
        self.k = 0;
        if self.t_s + 1e-9 >= self.next_history_s {
            let (table_estimate, table_sigma) = self.table_values();
            self.history.push(HistoryRow {
                t_s: self.t_s,
                estimate: self.params(),
                sigma: self.sigma(),
                table_estimate,
                table_sigma,
            });
            self.next_history_s += 1.0;
        }
    }

    /// The encoders' measurement of the IMU's attitude on the base (module doc): y =
    /// log(C̃_s^n · C_s^b(λ̂; p̂)ᵀ · C_refᵀ) ≈ −φ + C_ref·J·(p − p̂) + ψ, the chain evaluated exactly
    /// at the current estimate p̂ (an extended Kalman filter).
    fn encoder_update(&mut self) {
        let m = self.half_window();
        let Some(table) = &self.table else { return };
        if self.readings.len() < 2 * m + 1 {
            return;
        }
        // The measurement is made m samples back (φ does not change in 20 ms), the shafts' rates
        // by the central difference of the readings m samples either side: no lag, and no reading
        // in both the angle and the rate (its noise would bias the delay: errors in the variables).
        let (readings, q) = self.readings[m];
        let (first, last) = (self.readings[0].0, self.readings[2 * m].0);
        let n_t = table.states.len();
        let p_hat: Vec<f64> = (0..n_t).map(|j| self.x[TABLE0 + j]).collect();
        // A shaft at rest is at rest: a rate inside its noise (4σ, and 0.006°/s) is zero, or the
        // noise alone would make a never-turning shaft's delay look observable.
        let span = 2.0 * m as f64 * self.cfg.h;
        let mut rates = [0.0; crate::model::scheme::MAX_AXES];
        for (k, (r, (a, b))) in rates.iter_mut().zip(last.iter().zip(&first)).enumerate() {
            let noise = table.encoder_sigma_rad.get(k).copied().unwrap_or(0.0) * std::f64::consts::SQRT_2 / span;
            let rate = (a - b) / span;
            *r = if rate.abs() > 4.0 * noise + 1e-4 { rate } else { 0.0 };
        }
        let c_bs = table.states.b_from_s(&p_hat, &readings, &rates);
        let c_nb = q * c_bs.inverse();
        let c_ref = *self.c_ref.get_or_insert(c_nb);
        let y = rotvec::log(&(c_nb * c_ref.inverse()));
        let j = c_ref.to_rotation_matrix().into_inner() * table.states.jacobian(&p_hat, &readings, &rates);
        let mut h = SMatrix::<f64, 3, N>::zeros();
        for i in 0..3 {
            h[(i, i)] = -1.0;
            h[(i, PSI0 + i)] = 1.0;
        }
        h.fixed_view_mut::<3, MAX_TABLE>(0, TABLE0).copy_from(&j);
        let phi = self.x.fixed_rows::<3>(0).into_owned();
        let psi = self.x.fixed_rows::<3>(PSI0).into_owned();
        let innovation = y + phi - psi;
        let ph = self.p * h.transpose();
        let c = c_ref.to_rotation_matrix().into_inner();
        let r = c * table.states.measurement_variance(&table.encoder_sigma_rad, &readings) * c.transpose();
        let s = h * ph + r;
        if let Some(s_inv) = s.try_inverse() {
            let gain = ph * s_inv;
            self.x += gain * innovation;
            // Joseph's form keeps P symmetric positive semi-definite whatever the gain's rounding
            // (the encoders are far more precise than the priors: 0.05″ against 600″). Measured, it
            // gives the same 1σ as P − K·H·P here; it costs two dense 42×42 products a step.
            let ikh = Mat::identity() - gain * h;
            self.p = ikh * self.p * ikh.transpose() + gain * r * gain.transpose();
            self.p = (self.p + self.p.transpose()) * 0.5;
        }
    }

    fn table_values(&self) -> (Vec<f64>, Vec<f64>) {
        let n_t = self.table.as_ref().map_or(0, |t| t.states.len());
        (
            (0..n_t).map(|j| self.x[TABLE0 + j]).collect(),
            (0..n_t).map(|j| self.p[(TABLE0 + j, TABLE0 + j)].max(0.0).sqrt()).collect(),
        )
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
        let table = self.table.as_ref().map(|t| {
            let (params, sigma) = self.table_values();
            let n = N_PARAMS + t.states.len();
            TableEstimate {
                states: t.states.clone(),
                params,
                sigma,
                covariance: nalgebra::DMatrix::from_fn(n, n, |i, j| self.p[(6 + i, 6 + j)]),
            }
        });
        Estimate {
            params: self.params(),
            sigma: self.sigma(),
            covariance: self.p.fixed_view::<N_PARAMS, N_PARAMS>(6, 6).into_owned(),
            prior: self.cfg.prior,
            history: self.history,
            table,
        }
    }
}

/// What parameter k is, in [`Estimate::names`]'s order (the IMU's 21, then the table's).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ParamKind {
    /// One of the IMU's.
    Imu(Kind),
    /// One of the table's.
    Table(super::selfcal_table::TableKind),
}

impl ParamKind {
    /// Parameter `k`'s kind.
    #[must_use]
    pub fn of(k: usize) -> Self {
        if k < N_PARAMS { Self::Imu(param(k).0) } else { Self::Table(TableStates::kind(k - N_PARAMS)) }
    }

    /// The display unit and how many of it one SI unit is.
    #[must_use]
    pub fn unit(self) -> (&'static str, f64) {
        match self {
            Self::Imu(k) => k.unit(),
            Self::Table(k) => k.unit(),
        }
    }

    /// The unit as an entity or column name suffix.
    #[must_use]
    pub fn unit_key(self) -> &'static str {
        match self {
            Self::Imu(k) => k.unit_key(),
            Self::Table(k) => k.unit_key(),
        }
    }

    /// The group a plot gathers.
    #[must_use]
    pub fn group(self) -> &'static str {
        match self {
            Self::Imu(k) => k.group(),
            Self::Table(_) => "table",
        }
    }
}

/// How well a sequence sees each parameter (the IMU's 21, then the table's): its 1σ over its prior
/// at the end, and when it first fell under a tenth of the prior.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Observability {
    /// The parameters, in the order of the lists below.
    pub parameters: Vec<String>,
    /// Per parameter: σ_end / σ_0.
    pub ratio: Vec<f64>,
    /// Per parameter: the time σ first fell under a tenth of σ_0, s (None: never).
    pub observable_from_s: Vec<Option<f64>>,
    /// Parameters whose 1σ fell by less than half: not observable from this sequence.
    pub unobservable: Vec<String>,
    /// Parameters whose 1σ fell by half but stayed above a tenth of the prior: weakly observable.
    pub weak: Vec<String>,
    /// Pairs the data cannot tell apart (|correlation| ≥ 0.9), with the combination they can see.
    pub aliased: Vec<String>,
}

impl Estimate {
    /// Every parameter's name: the IMU's 21, then the table's.
    #[must_use]
    pub fn names(&self) -> Vec<String> {
        names_with(self.table.as_ref().map(|t| &t.states))
    }

    /// Every estimate (SI), in [`Self::names`]'s order.
    #[must_use]
    pub fn all_params(&self) -> Vec<f64> {
        let mut v = self.params.to_vec();
        if let Some(t) = &self.table {
            v.extend(&t.params);
        }
        v
    }

    /// Every 1σ (SI), in [`Self::names`]'s order.
    #[must_use]
    pub fn all_sigma(&self) -> Vec<f64> {
        let mut v = self.sigma.to_vec();
        if let Some(t) = &self.table {
            v.extend(&t.sigma);
        }
        v
    }

    /// Every prior 1σ (SI), in [`Self::names`]'s order.
    #[must_use]
    pub fn all_prior(&self) -> Vec<f64> {
        let mut v = self.prior.to_vec();
        if let Some(t) = &self.table {
            v.extend(t.states.priors());
        }
        v
    }
}

/// Every parameter's name of a filter with the table's states `table`: the IMU's 21, then the table's.
#[must_use]
pub fn names_with(table: Option<&TableStates>) -> Vec<String> {
    let mut n = param_names();
    if let Some(t) = table {
        n.extend(t.names());
    }
    n
}

impl HistoryRow {
    /// Parameter `k`'s 1σ in [`Estimate::names`]'s order.
    #[must_use]
    pub fn sigma_of(&self, k: usize) -> f64 {
        if k < N_PARAMS { self.sigma[k] } else { self.table_sigma[k - N_PARAMS] }
    }

    /// Parameter `k`'s estimate in [`Estimate::names`]'s order.
    #[must_use]
    pub fn estimate_of(&self, k: usize) -> f64 {
        if k < N_PARAMS { self.estimate[k] } else { self.table_estimate[k - N_PARAMS] }
    }
}

/// The observability of `e` (a run on data or a plan on the sequence's noise-free motion).
#[must_use]
pub fn observability(e: &Estimate) -> Observability {
    let names = e.names();
    let (sigma, prior) = (e.all_sigma(), e.all_prior());
    let n = names.len();
    let ratio: Vec<f64> = (0..n).map(|k| sigma[k] / prior[k]).collect();
    let observable_from_s =
        (0..n).map(|k| e.history.iter().find(|r| r.sigma_of(k) < 0.1 * prior[k]).map(|r| r.t_s)).collect();
    let unobservable = (0..n).filter(|&k| ratio[k] > 0.5).map(|k| names[k].clone()).collect();
    let weak = (0..n).filter(|&k| ratio[k] > 0.1 && ratio[k] <= 0.5).map(|k| names[k].clone()).collect();
    let cov = |i: usize, j: usize| match &e.table {
        Some(t) => t.covariance[(i, j)],
        None => e.covariance[(i, j)],
    };
    let mut aliased = Vec::new();
    for i in 0..n {
        for j in i + 1..n {
            let rho = cov(i, j) / (cov(i, i) * cov(j, j)).sqrt();
            if rho.abs() >= 0.9 {
                // The combination with the smaller variance: x_i/σ_i ∓ x_j/σ_j.
                let sign = if rho > 0.0 { "−" } else { "+" };
                let (a, b) = (&names[i], &names[j]);
                aliased.push(format!("{a} and {b} (correlation {rho:+.3}): the data see {a}/σ {sign} {b}/σ"));
            }
        }
    }
    Observability { parameters: names, ratio, observable_from_s, unobservable, weak, aliased }
}
