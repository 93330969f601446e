//! Initial alignment of a strapdown IMU on a vehicle at rest (parked, rocked by wind or people, or
//! turned on an indexing table): where is North, where is down, and how sure are we.
//!
//! Three steps, each checkable on its own (tests in `align/tests.rs`, accuracy over seeds in
//! `tests/align.rs`, numbers in docs/logs.md):
//!
//! 1. [`scan_rest`]: which initial part of a log is at rest. The specific force is carried into the
//!    inertial frame of the first sample (b0) with the gyros, so a turning table or rocking does not
//!    look like motion; one-second means of it that change by more than a threshold mark motion.
//! 2. [`coarse`]: inertial-frame coarse alignment (the gravity vector seen to turn with the Earth in
//!    b0: Qin Yongyuan, *Inertial Navigation*, §8.2; PSINS `alignsb`/`aligni0`). The velocity the
//!    accelerometers integrate in b0 is matched with the one gravity integrates in the frame of the
//!    navigation frame at the start (i0) at half the window and at its end (TRIAD). Averaging
//!    increments (the analytic alignment) fails under rocking: its mean rate is not the Earth's.
//! 3. [`fine`]: a Kalman filter on zero velocity (PSINS `alignvn`; Groves, *Principles of GNSS,
//!    Inertial, and Multisensor Integrated Navigation Systems*, 2nd ed., §14.2.2): 12 states,
//!    attitude error φ^n, velocity error δv^n, gyro bias ε^s and accelerometer bias ∇^s in the sensor
//!    frame, closed loop. The biases live in s: when the IMU turns (an indexing table) their
//!    projection on East changes and the east gyro bias separates from the heading error, which on a
//!    fixed IMU it cannot (heading 1σ → ε_E / (Ω cos L)). Run twice: the first pass measures the
//!    velocity disturbance (the innovations), the second uses it as the measurement noise.
//!
//! Frames: n = East-North-Up, s = the IMU's axes; C = `n_from_s`; the attitude error φ is defined by
//! C_computed = (I − [φ×]) C_true, as everywhere in `ins`.

use nalgebra::{Matrix3, SMatrix, SVector, UnitQuaternion, Vector3};

use crate::math::attitude::{Attitude, AttitudeError};
use crate::math::frames::{B, N, Rot, S, V3};
use crate::math::rotvec;
use crate::model::earth::{EARTH_RATE, normal_gravity, omega_ie_n};

/// One IMU sample: angle increment (rad) and velocity increment (m/s), sensor frame, over the
/// nominal interval.
pub type Increment = (Vector3<f64>, Vector3<f64>);

/// What the alignment knows beyond the data.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AlignConfig {
    /// Latitude of the site, rad.
    pub latitude_rad: f64,
    /// Height, m.
    pub height_m: f64,
    /// The sampling interval, s.
    pub interval_s: f64,
    /// Gyro bias 1σ before alignment, rad/s (None: assumed from the measured noise, see
    /// [`assumed_gyro_bias`]).
    pub gyro_bias_sigma_rad_per_s: Option<f64>,
    /// Accelerometer bias 1σ before alignment, m/s² (None: assumed from the measured noise).
    pub accel_bias_sigma_mps2: Option<f64>,
    /// Gyro angle random walk, rad/√s (None: measured from the data).
    pub gyro_random_walk: Option<f64>,
    /// Accelerometer velocity random walk, m/s/√s (None: measured).
    pub accel_random_walk: Option<f64>,
}

/// A sensor's error level as the alignment used it, and where it came from.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Assumed {
    /// The value, in the unit of the key that holds it.
    pub value: f64,
    /// True if given (manifest, table description); false if assumed from the data.
    pub given: bool,
}

/// The initial part of a log that is at rest.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct RestScan {
    /// Length of the initial rest, s (0: the log starts moving).
    pub rest_s: f64,
    /// One-second means of the specific force (in b0) that change by more than this mark motion, m/s².
    pub threshold_mps2: f64,
    /// The largest change between consecutive one-second means within the rest, m/s².
    pub largest_change_mps2: f64,
    /// The change that ended the rest (None: the data ended first), m/s².
    pub ending_change_mps2: Option<f64>,
}

/// Block length of the rest scan and the latitude estimate, s.
const BLOCK_S: f64 = 1.0;

/// Default threshold of [`scan_rest`]: 0.05 m/s² between one-second means. Rocking by wind or
/// people and engine vibration average out over a second; a vehicle that starts, brakes or turns
/// changes its acceleration by more.
pub const REST_THRESHOLD_MPS2: f64 = 0.05;

/// The streaming form of [`scan_rest`]: blocks of about a second in, motion out.
#[derive(Debug, Clone)]
pub struct RestScanner {
    q: UnitQuaternion<f64>,
    previous: Option<Vector3<f64>>,
    threshold_mps2: f64,
    /// The largest change between consecutive block means so far that did not mark motion, m/s².
    pub largest_change_mps2: f64,
}

impl RestScanner {
    /// A scan with `threshold_mps2` between consecutive block means.
    #[must_use]
    pub fn new(threshold_mps2: f64) -> Self {
        Self { q: UnitQuaternion::identity(), previous: None, threshold_mps2, largest_change_mps2: 0.0 }
    }

    /// The mean specific force of a block of samples, carried into the inertial frame of the scan's
    /// first sample by the gyros, m/s².
    fn block_mean(&mut self, block: &[Increment], h: f64) -> Vector3<f64> {
        let mut sum = Vector3::zeros();
        for (dtheta, dv) in block {
            sum += self.q * (dv + 0.5 * dtheta.cross(dv));
            self.q *= rotvec::exp(dtheta);
        }
        sum / (block.len().max(1) as f64 * h)
    }

    /// One block (about [`BLOCK_S`]); `Some(change)` if its mean moved from the previous block's by
    /// more than the threshold (the vehicle moved).
    pub fn push_block(&mut self, block: &[Increment], h: f64) -> Option<f64> {
        let mean = self.block_mean(block, h);
        let change = self.previous.map(|p| (mean - p).norm());
        self.previous = Some(mean);
        match change {
            Some(c) if c > self.threshold_mps2 => Some(c),
            Some(c) => {
                self.largest_change_mps2 = self.largest_change_mps2.max(c);
                None
            }
            None => None,
        }
    }
}

/// Samples per block of the rest scan at interval `h`.
#[must_use]
pub fn block_samples(h: f64) -> usize {
    ((BLOCK_S / h).round() as usize).max(1)
}

/// One-second means of the specific force in the inertial frame of the first sample, m/s², with
/// their mid times (s from the first sample's start).
fn specific_force_blocks(samples: &[Increment], h: f64) -> Vec<(f64, Vector3<f64>)> {
    let per = block_samples(h);
    let mut scanner = RestScanner::new(f64::INFINITY);
    samples
        .chunks_exact(per)
        .enumerate()
        .map(|(j, chunk)| ((j as f64 + 0.5) * per as f64 * h, scanner.block_mean(chunk, h)))
        .collect()
}

/// Scans `samples` for the initial rest: one-second means of the specific force in the inertial
/// frame of the first sample whose change exceeds `threshold_mps2` end it.
#[must_use]
pub fn scan_rest(samples: &[Increment], h: f64, threshold_mps2: f64) -> RestScan {
    let per = block_samples(h);
    let mut scanner = RestScanner::new(threshold_mps2);
    for (j, chunk) in samples.chunks_exact(per).enumerate() {
        if let Some(change) = scanner.push_block(chunk, h) {
            // Blocks 0..j were at rest; block j moved.
            return RestScan {
                rest_s: j as f64 * BLOCK_S,
                threshold_mps2,
                largest_change_mps2: scanner.largest_change_mps2,
                ending_change_mps2: Some(change),
            };
        }
    }
    RestScan {
        rest_s: samples.len() as f64 * h,
        threshold_mps2,
        largest_change_mps2: scanner.largest_change_mps2,
        ending_change_mps2: None,
    }
}

/// The white noise of a triad, unit/√s, from differences of its increments: the k-th difference of
/// white noise has the variance C(2k, k)·σ², while a smooth motion (rocking, a turning table) loses a
/// factor (ωh)² with every order. The smallest normalised estimate over orders 1 to 6 is the noise's
/// (rocking at 1.3 Hz swamps the first difference of a navigation-grade gyro at 100 Hz 300-fold; the
/// fourth sees the noise). The mean over the three axes.
fn random_walk(samples: &[Increment], h: f64, gyro: bool) -> f64 {
    const ORDERS: usize = 6;
    let pick = |s: &Increment| if gyro { s.0 } else { s.1 };
    let mut best = f64::INFINITY;
    let mut diff: Vec<Vector3<f64>> = samples.iter().map(pick).collect();
    // C(2k, k) for k = 1..6.
    let central = [2.0, 6.0, 20.0, 70.0, 252.0, 924.0];
    for c in central.iter().take(ORDERS) {
        diff = diff.windows(2).map(|w| w[1] - w[0]).collect();
        if diff.len() < 10 {
            break;
        }
        let var = diff.iter().map(Vector3::norm_squared).sum::<f64>() / (diff.len() as f64 * 3.0 * c);
        best = best.min(var);
    }
    if best.is_finite() { best.sqrt() / h.sqrt() } else { 0.0 }
}

/// The gyro bias 1σ assumed when none is given: 30 h^{-1/2} × the angle random walk (navigation
/// grade: 0.001 °/√h → 0.03 °/h; tactical 0.05 °/√h → 1.5 °/h; MEMS 0.2 °/√h → 6 °/h — each at or
/// above its class's typical bias, so the reported heading 1σ errs on the safe side). Give
/// `gyro_bias_deg_per_h` for a number that is more than a class.
#[must_use]
pub fn assumed_gyro_bias(random_walk_rad_per_sqrt_s: f64) -> f64 {
    // rad/√s → rad/√h is ×60; × 30/√h → rad/h; /3600 → rad/s.
    (random_walk_rad_per_sqrt_s * 60.0 * 30.0 / 3600.0).max(1e-9)
}

/// The accelerometer bias 1σ assumed when none is given: 30 √s × the velocity random walk
/// (navigation grade 10 µg/√Hz → 300 µg; MEMS 100 µg/√Hz → 3 mg), at most the bias of the class
/// of sensor the gyros show ([`accel_bias_of_class`]): a parked vehicle's engine and people shake
/// the accelerometers far above their white noise (a ring-laser IMU in a car, PSINS's
/// `lasergyro.imu`, measures 1 760 µg/√Hz: 30× that, 53 mg, let the filter turn 7 mg of a level
/// into a bias).
#[must_use]
pub fn assumed_accel_bias(random_walk_mps_per_sqrt_s: f64, gyro_random_walk_rad_per_sqrt_s: f64) -> f64 {
    (30.0 * random_walk_mps_per_sqrt_s).clamp(1e-6, accel_bias_of_class(gyro_random_walk_rad_per_sqrt_s))
}

/// The accelerometer bias 1σ typical of the class of IMU whose gyros have this angle random walk
/// (rad/√s), m/s², taken at the top of the class: up to 0.02 °/√h (navigation grade: ring-laser,
/// fibre-optic gyros) 300 µg; up to 0.5 °/√h (tactical) 3 mg; above (MEMS) 30 mg.
#[must_use]
pub fn accel_bias_of_class(gyro_random_walk_rad_per_sqrt_s: f64) -> f64 {
    let arw_deg_per_sqrt_h = gyro_random_walk_rad_per_sqrt_s.to_degrees() * 60.0;
    let ug = if arw_deg_per_sqrt_h <= 0.02 {
        300.0
    } else if arw_deg_per_sqrt_h <= 0.5 {
        3_000.0
    } else {
        30_000.0
    };
    ug * crate::math::units::MPS2_PER_UG
}

/// C_n^{i0}(t): the navigation frame at time t seen from the navigation frame at the start, both
/// East-North-Up, turned with the Earth about its axis u = (0, cos L, sin L).
fn i0_from_n(latitude_rad: f64, t_s: f64) -> UnitQuaternion<f64> {
    let u = omega_ie_n(latitude_rad) / EARTH_RATE;
    rotvec::exp(&(u * (EARTH_RATE * t_s)))
}

fn triad(a: &Vector3<f64>, b: &Vector3<f64>) -> Option<Matrix3<f64>> {
    let x = a.try_normalize(1e-12)?;
    let y = a.cross(b).try_normalize(1e-30)?;
    Some(Matrix3::from_columns(&[x, y, x.cross(&y)]))
}

/// Inertial-frame coarse alignment over `samples`: C_s^n at the start of the first sample, or None
/// if the data have no horizontal Earth-rate signature (a pole, or no samples).
#[must_use]
pub fn coarse(samples: &[Increment], cfg: &AlignConfig) -> Option<Rot<N, S>> {
    let h = cfg.interval_s;
    let g = normal_gravity(cfg.latitude_rad, cfg.height_m);
    let f_n = Vector3::new(0.0, 0.0, g);
    let (mut q, mut v_b0, mut v_i0) = (UnitQuaternion::identity(), Vector3::zeros(), Vector3::zeros());
    let half = samples.len() / 2;
    let mut first = None;
    for (k, (dtheta, dv)) in samples.iter().enumerate() {
        v_b0 += q * (dv + 0.5 * dtheta.cross(dv));
        q *= rotvec::exp(dtheta);
        v_i0 += i0_from_n(cfg.latitude_rad, (k as f64 + 0.5) * h) * f_n * h;
        if k + 1 == half {
            first = Some((v_i0, v_b0));
        }
    }
    let (a_i0, a_b0) = first?;
    let (m_i0, m_b0) = (triad(&a_i0, &v_i0)?, triad(&a_b0, &v_b0)?);
    // FRAME: the two triads are the same physical directions in i0 (= n at the start) and in b0
    // (= s at the start).
    Some(Rot::from_quaternion(UnitQuaternion::from_matrix(&(m_i0 * m_b0.transpose()))))
}

/// The 12-state closed-loop filter's state.
type X = SVector<f64, 12>;
type P12 = SMatrix<f64, 12, 12>;

/// The result of [`fine`].
#[derive(Debug, Clone)]
pub struct Alignment {
    /// C_s^n at the end of the last sample.
    pub n_from_s: Rot<N, S>,
    /// Its covariance: attitude error φ^n (East, North, Up), rad².
    pub phi_covariance: Matrix3<f64>,
    /// The estimated gyro bias, sensor frame, rad/s, and its 1σ.
    pub gyro_bias_rad_per_s: (Vector3<f64>, Vector3<f64>),
    /// The estimated accelerometer bias, sensor frame, m/s², and its 1σ.
    pub accel_bias_mps2: (Vector3<f64>, Vector3<f64>),
    /// RMS of the zero-velocity innovations of the last pass (the velocity disturbance), m/s.
    pub velocity_residual_rms_mps: f64,
    /// The largest horizontal velocity the filter saw before correcting it (motion shows here), m/s.
    pub velocity_residual_peak_mps: f64,
    /// The gyro and accelerometer random walks used (rad/√s, m/s/√s) and whether they were given.
    pub random_walk: (Assumed, Assumed),
    /// The bias 1σ the filter started from (rad/s, m/s²) and whether they were given.
    pub bias_prior: (Assumed, Assumed),
    /// Attitude after the coarse step alone, at the end of the last sample (to compare).
    pub coarse_n_from_s: Rot<N, S>,
}

/// Attitude propagation at rest: one sample.
#[inline]
fn propagate(q: &mut UnitQuaternion<f64>, earth_turn: &UnitQuaternion<f64>, dtheta: &Vector3<f64>) {
    *q = earth_turn * *q * rotvec::exp(dtheta);
}

fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
    v.cross_matrix()
}

/// One pass of the filter from `start` (C_s^n at the start) with measurement noise `r_mps` (1σ).
struct Pass {
    q: UnitQuaternion<f64>,
    p: P12,
    eb: Vector3<f64>,
    db: Vector3<f64>,
    innovations: Vec<f64>,
    peak_mps: f64,
}

/// Kalman steps per second and zero-velocity updates per second.
const STEP_S: f64 = 0.1;
const UPDATE_S: f64 = 1.0;

fn run_pass(
    samples: &[Increment],
    cfg: &AlignConfig,
    start: &UnitQuaternion<f64>,
    r_mps: f64,
    noise: (f64, f64),
    prior: (f64, f64),
    heading_sigma: f64,
) -> Pass {
    let h = cfg.interval_s;
    let g = normal_gravity(cfg.latitude_rad, cfg.height_m);
    let w_ie = omega_ie_n(cfg.latitude_rad);
    let earth_turn = rotvec::exp(&(-w_ie * h));
    let per_step = ((STEP_S / h).round() as usize).max(1);
    let steps_per_update = ((UPDATE_S / (per_step as f64 * h)).round() as usize).max(1);
    let mut p = P12::zeros();
    let tilt = 1.0_f64.to_radians();
    for (i, s) in [tilt, tilt, heading_sigma, 0.1, 0.1, 0.1, prior.0, prior.0, prior.0, prior.1, prior.1, prior.1]
        .into_iter()
        .enumerate()
    {
        p[(i, i)] = s * s;
    }
    let mut q_c = P12::zeros();
    for i in 0..3 {
        q_c[(i, i)] = noise.0 * noise.0;
        q_c[(3 + i, 3 + i)] = noise.1 * noise.1;
    }
    let r = r_mps * r_mps;
    let (mut q, mut v) = (*start, Vector3::zeros());
    let (mut eb, mut db) = (Vector3::zeros(), Vector3::zeros());
    let mut innovations = Vec::new();
    let mut peak: f64 = 0.0;
    let gravity = Vector3::new(0.0, 0.0, -g);
    for (step, chunk) in samples.chunks(per_step).enumerate() {
        let c_mid = q.to_rotation_matrix().into_inner();
        let mut dv_n_sum = Vector3::zeros();
        for (dtheta, dv) in chunk {
            let (dtheta, dv) = (dtheta - eb * h, dv - db * h);
            let dv_n = q * (dv + 0.5 * dtheta.cross(&dv));
            dv_n_sum += dv_n;
            v += dv_n + (gravity - (2.0 * w_ie).cross(&v)) * h;
            propagate(&mut q, &earth_turn, &dtheta);
        }
        let step_dt = chunk.len() as f64 * h;
        let f_n = dv_n_sum / step_dt;
        let mut f = P12::zeros();
        f.fixed_view_mut::<3, 3>(0, 0).copy_from(&(-skew(&w_ie)));
        f.fixed_view_mut::<3, 3>(0, 6).copy_from(&(-c_mid));
        f.fixed_view_mut::<3, 3>(3, 0).copy_from(&skew(&f_n));
        f.fixed_view_mut::<3, 3>(3, 3).copy_from(&(-skew(&(2.0 * w_ie))));
        f.fixed_view_mut::<3, 3>(3, 9).copy_from(&c_mid);
        let fdt = f * step_dt;
        let phi = P12::identity() + fdt + 0.5 * fdt * fdt;
        p = phi * p * phi.transpose() + q_c * step_dt;
        if (step + 1) % steps_per_update != 0 {
            continue;
        }
        // Zero-velocity update: z = v (the true velocity is zero), H = [0 I 0 0].
        peak = peak.max(v.x.hypot(v.y));
        let s = p.fixed_view::<3, 3>(3, 3) + Matrix3::identity() * r;
        let Some(s_inv) = s.try_inverse() else { continue };
        let k: SMatrix<f64, 12, 3> = p.fixed_view::<12, 3>(0, 3) * s_inv;
        let x: X = k * v;
        for a in 0..3 {
            innovations.push(v[a]);
        }
        let mut ikh = P12::identity();
        let mut kh = ikh.fixed_view_mut::<12, 3>(0, 3);
        kh -= &k;
        // Joseph form: stays symmetric and positive through thousands of updates.
        let krk = k * (Matrix3::identity() * r) * k.transpose();
        p = ikh * p * ikh.transpose() + krk;
        // Feedback: C_true = exp(φ) C_computed; v − δv; the biases into the compensation.
        q = rotvec::exp(&x.fixed_rows::<3>(0).into_owned()) * q;
        v -= x.fixed_rows::<3>(3).into_owned();
        eb += x.fixed_rows::<3>(6).into_owned();
        db += x.fixed_rows::<3>(9).into_owned();
    }
    Pass { q, p, eb, db, innovations, peak_mps: peak }
}

/// Why an alignment could not be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AlignError {
    /// Too few samples.
    #[error("{0:.1} s of data: the alignment needs at least 10 s at rest")]
    TooShort(f64),
    /// The coarse step found no Earth rate.
    #[error(
        "the gravity direction does not turn with the Earth in these data (a pole, a gyro that reads nothing, or a vehicle that moved): no heading"
    )]
    NoEarthRate,
    /// The data are not a specific force of gravity's size.
    #[error(
        "the mean specific force is {measured:.4} m/s², gravity at the site is {gravity:.4} m/s²: the vehicle moved, or the accelerometers' unit is wrong"
    )]
    NotGravity {
        /// Measured, m/s².
        measured: f64,
        /// Expected, m/s².
        gravity: f64,
    },
}

/// Coarse then fine alignment over `samples` (all at rest): C_s^n at the end of the last sample
/// with its covariance and the bias estimates.
///
/// # Errors
/// Fewer than 10 s of samples, a mean specific force that is not gravity within 5 %, or no Earth
/// rate in the data.
pub fn fine(samples: &[Increment], cfg: &AlignConfig) -> Result<Alignment, AlignError> {
    let h = cfg.interval_s;
    let span = samples.len() as f64 * h;
    if span < 10.0 {
        return Err(AlignError::TooShort(span));
    }
    let g = normal_gravity(cfg.latitude_rad, cfg.height_m);
    let blocks = specific_force_blocks(samples, h);
    let mean_f = blocks.iter().map(|(_, f)| f.norm()).sum::<f64>() / blocks.len().max(1) as f64;
    if ((mean_f - g) / g).abs() > 0.05 {
        return Err(AlignError::NotGravity { measured: mean_f, gravity: g });
    }
    let start = coarse(samples, cfg).ok_or(AlignError::NoEarthRate)?;
    let arw = Assumed {
        value: cfg.gyro_random_walk.unwrap_or_else(|| random_walk(samples, h, true)),
        given: cfg.gyro_random_walk.is_some(),
    };
    let vrw = Assumed {
        value: cfg.accel_random_walk.unwrap_or_else(|| random_walk(samples, h, false)),
        given: cfg.accel_random_walk.is_some(),
    };
    let eb0 = Assumed {
        value: cfg.gyro_bias_sigma_rad_per_s.unwrap_or_else(|| assumed_gyro_bias(arw.value)),
        given: cfg.gyro_bias_sigma_rad_per_s.is_some(),
    };
    let db0 = Assumed {
        value: cfg.accel_bias_sigma_mps2.unwrap_or_else(|| assumed_accel_bias(vrw.value, arw.value)),
        given: cfg.accel_bias_sigma_mps2.is_some(),
    };
    let cos_lat = cfg.latitude_rad.cos().max(1e-3);
    // What a coarse alignment can do about heading with this gyro (bias over the horizontal Earth
    // rate), at least a degree: the filter's prior.
    let heading_sigma = (3.0 * eb0.value / (EARTH_RATE * cos_lat)).clamp(1.0_f64.to_radians(), 30.0_f64.to_radians());
    let noise = (arw.value.max(1e-12), vrw.value.max(1e-12));
    let prior = (eb0.value, db0.value);
    let first = run_pass(samples, cfg, start.quaternion(), 0.01, noise, prior, heading_sigma);
    // The disturbance: innovations after the first fifth (the filter has settled).
    let settled = &first.innovations[first.innovations.len() / 5..];
    let r = if settled.is_empty() {
        0.01
    } else {
        (settled.iter().map(|x| x * x).sum::<f64>() / settled.len() as f64).sqrt().max(1e-4)
    };
    let second = run_pass(samples, cfg, start.quaternion(), r, noise, prior, heading_sigma);
    let rest = &second.innovations[second.innovations.len() / 5..];
    let rms = if rest.is_empty() { 0.0 } else { (rest.iter().map(|x| x * x).sum::<f64>() / rest.len() as f64).sqrt() };
    // The coarse attitude carried to the end with the same gyros, for comparison.
    let w_ie = omega_ie_n(cfg.latitude_rad);
    let earth_turn = rotvec::exp(&(-w_ie * h));
    let mut qc = *start.quaternion();
    for (dtheta, _) in samples {
        propagate(&mut qc, &earth_turn, dtheta);
    }
    let sd = |i: usize| second.p[(i, i)].max(0.0).sqrt();
    Ok(Alignment {
        // FRAME: the filter integrated C_s^n from the coarse C_s^n with the gyros and corrected it.
        n_from_s: Rot::from_quaternion(second.q),
        phi_covariance: second.p.fixed_view::<3, 3>(0, 0).into_owned(),
        gyro_bias_rad_per_s: (second.eb, Vector3::new(sd(6), sd(7), sd(8))),
        accel_bias_mps2: (second.db, Vector3::new(sd(9), sd(10), sd(11))),
        velocity_residual_rms_mps: rms,
        velocity_residual_peak_mps: second.peak_mps,
        random_walk: (arw, vrw),
        bias_prior: (eb0, db0),
        // FRAME: the coarse C_s^n carried by the same gyro integration.
        coarse_n_from_s: Rot::from_quaternion(qc),
    })
}

impl Alignment {
    /// The attitude of the sensor axes read as a body (x right, y forward, z up) and the 1σ of its
    /// pitch, roll and heading (first order), rad.
    #[must_use]
    pub fn attitude_with_sigma(&self) -> (Attitude, [f64; 3]) {
        // FRAME: a strapdown IMU's axes are the body's (RFU); a table's body attitude is demodulated elsewhere.
        let n_from_b: Rot<N, B> = Rot::from_quaternion(*self.n_from_s.quaternion());
        let att = Attitude::from_n_from_b(&n_from_b);
        // J: φ^n → (pitch, roll, heading) errors, linear; Σ_euler = J Σ_φ Jᵀ.
        let column = |k: usize| {
            let e: AttitudeError = AttitudeError::first_order(&n_from_b, V3::new(Vector3::ith(k, 1.0)));
            Vector3::from(e.as_array())
        };
        let j = Matrix3::from_columns(&[column(0), column(1), column(2)]);
        let cov = j * self.phi_covariance * j.transpose();
        (att, [cov[(0, 0)].sqrt(), cov[(1, 1)].sqrt(), cov[(2, 2)].sqrt()])
    }
}

/// The latitude the data imply: the gravity direction, carried into the inertial frame of the first
/// sample by the gyros, turns at Ω cos L (it traces a cone about the Earth's axis). A least-squares
/// line through the one-second means gives the rate; the hemisphere is the site's.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ImpliedLatitude {
    /// |L| from the data, rad, signed as the site's latitude.
    pub latitude_rad: f64,
    /// Its 1σ (the fit's scatter and the gyro bias prior), rad.
    pub sigma_rad: f64,
}

/// See [`ImpliedLatitude`]; `gyro_bias_sigma` (rad/s) turns the gravity direction too.
#[must_use]
pub fn implied_latitude(
    samples: &[Increment],
    h: f64,
    site_latitude_rad: f64,
    gyro_bias_sigma: f64,
) -> Option<ImpliedLatitude> {
    let blocks = specific_force_blocks(samples, h);
    let n = blocks.len();
    if n < 10 {
        return None;
    }
    let units: Vec<(f64, Vector3<f64>)> =
        blocks.iter().filter_map(|(t, f)| f.try_normalize(1e-9).map(|u| (*t, u))).collect();
    let n = units.len() as f64;
    let t_mean = units.iter().map(|(t, _)| t).sum::<f64>() / n;
    let u_mean: Vector3<f64> = units.iter().map(|(_, u)| u).sum::<Vector3<f64>>() / n;
    let stt: f64 = units.iter().map(|(t, _)| (t - t_mean).powi(2)).sum();
    let slope: Vector3<f64> = units.iter().map(|(t, u)| (u - u_mean) * (t - t_mean)).sum::<Vector3<f64>>() / stt;
    let resid: f64 = units.iter().map(|(t, u)| (u - u_mean - slope * (t - t_mean)).norm_squared()).sum::<f64>()
        / (2.0 * (n - 2.0)).max(1.0);
    // The slope's 1σ per component; only the part across the gravity direction carries the rate.
    let slope_sigma = (resid / stt).sqrt();
    let rate = u_mean.normalize().cross(&slope).norm();
    let cos_l = (rate / EARTH_RATE).clamp(0.0, 1.0);
    let lat = cos_l.acos() * if site_latitude_rad < 0.0 { -1.0 } else { 1.0 };
    let sigma_rate = (slope_sigma * slope_sigma * 2.0 + gyro_bias_sigma * gyro_bias_sigma).sqrt();
    let sin_l = lat.sin().abs().max(0.05);
    Some(ImpliedLatitude {
        latitude_rad: lat,
        sigma_rad: (sigma_rate / (EARTH_RATE * sin_l)).min(std::f64::consts::FRAC_PI_2),
    })
}

#[cfg(test)]
mod tests;
