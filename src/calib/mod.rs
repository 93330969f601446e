//! Calibration. The IMU's system-level self-calibration on its own gimbals is [`selfcal`]; this
//! module is the static calibration of the turntable's swing cones and non-orthogonality (Jiang et al. 2017 §5-6), by the
//! paper's static Kalman filter and by nonlinear least squares on the exact chain
//! (docs/calibration.md).
//!
//! The vehicle is at rest and its attitude is known (Jiang et al. 2017 §5: "the roll and pitch angles are
//! zero ... the head angle is a fixed value"); the gimbals turn; the INS reports the IMU attitude. The
//! body attitude demodulated with the table model that leaves out the parameters being estimated
//! differs from the known attitude by a small rotation `z` (nav frame, the paper's
//! `Z = [φx φy φz]`, eq. 30). To first order `z = H(λ) θ`, with one column per parameter:
//!
//! ```text
//! swing of axis k, α cos φ:   C_b^n P_k ( cos λ_k e1 + sin λ_k e2)
//! swing of axis k, α sin φ:   C_b^n P_k (−sin λ_k e1 + cos λ_k e2)
//! non-orthogonality of k:     C_b^n P_k (a_k × a_{k−1})
//! ```
//!
//! (P_k the nominal rotation of the axes before k, the same first-order model as
//! [`crate::model::gimbal::Chain::first_order_phi_b`]). Everything not estimated — installation, IMU mount,
//! encoder offset, scale and delay — is taken as known from `[compensation]`, as the paper assumes
//! ("after all kinds of the mounting errors and the angle errors of the angle encoders are
//! calibrated for").
//!
//! The filter (eq. 33) is kept in information form, which is the same recursion: Λ = P₀⁻¹ + Σ HᵀR⁻¹H,
//! x̂ = Λ⁻¹(P₀⁻¹x₀ + Σ HᵀR⁻¹z). The least-squares fit then iterates on the exact residuals (the whole
//! chain, exponential maps, no small angle) with the same Λ: a Gauss–Newton (chord) iteration that
//! converges to the exact model's solution.

pub mod alias;
mod estimate;
pub mod montecarlo;
pub mod report;
pub mod selfcal;
pub mod selfcal_table;
mod sequence;

pub use estimate::{Calibration, Estimate, History, Snapshot, calibrate};

use std::sync::atomic::{AtomicBool, Ordering};

use nalgebra::{Matrix3, Vector3};

use crate::math::attitude::Attitude;
use crate::math::frames::{B, N, Rot, S};
use crate::model::gimbal::{Chain, ShaftRotations, TableErrors};
use crate::model::scheme::MAX_AXES;
use crate::sim::demodulate;

/// Most parameters a calibration estimates (three axes: 6 swing components, 2 non-orthogonalities,
/// 6 nuisance).
pub const MAX_PARAMS: usize = 16;
/// Most table parameters (three axes: 6 swing components and 2 non-orthogonalities).
pub const MAX_TABLE: usize = 8;

/// Slow errors of the attitude reference estimated alongside the table's parameters.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Nuisance {
    /// None (the paper's filter: five states).
    None,
    /// A constant rotation (3 states): the known attitude is off, or the INS started off.
    Offset,
    /// A constant and a drift rate (6 states): the INS attitude drifts during the test.
    OffsetDrift,
}

/// `[calibration.montecarlo]`, validated, SI.
#[derive(Debug, Clone, PartialEq)]
pub struct MonteCarloConfig {
    /// Runs.
    pub runs: u32,
    /// Uniform range of every swing half-angle, rad.
    pub swing_half_angle_rad: [f64; 2],
    /// Uniform range of every swing phase, rad.
    pub swing_phase_rad: [f64; 2],
    /// Uniform range of every non-orthogonality, rad.
    pub non_orthogonality_rad: [f64; 2],
    /// 1σ of an independent measurement of η used as the prior, rad (None: the distribution is the prior).
    pub eta_measured_sigma_rad: Option<f64>,
}

impl MonteCarloConfig {
    /// Sets the 1σ of an independent η measurement a user gives beside the file
    /// (`--eta-measured-sigma-arcsec`); the message says the value and the range, the caller names the flag.
    ///
    /// # Errors
    /// Not finite, not positive, or over 3600″.
    pub fn set_eta_measured_sigma_arcsec(&mut self, sigma_arcsec: f64) -> Result<(), String> {
        if !(sigma_arcsec.is_finite() && sigma_arcsec > 0.0 && sigma_arcsec <= 3600.0) {
            return Err(format!("{sigma_arcsec}: must be > 0 and <= 3600 arcsec"));
        }
        self.eta_measured_sigma_rad = Some(sigma_arcsec * crate::math::units::RAD_PER_ARCSEC);
        Ok(())
    }

    /// Checks a number of runs a user gives beside the file (`--runs`).
    ///
    /// # Errors
    /// 0, or over a million.
    pub fn check_runs(runs: usize) -> Result<usize, String> {
        if runs == 0 || runs > 1_000_000 { Err(format!("{runs}: must be 1 ..= 1000000")) } else { Ok(runs) }
    }
}

/// `[calibration]`, validated, SI.
#[derive(Debug, Clone, PartialEq)]
pub struct CalibConfig {
    /// The isotropic part of each sample's measurement noise (the INS, the reference), rad:
    /// R = Σ_k σ_k² u_k u_kᵀ + σ² I (see `estimate::SampleModel`).
    pub measurement_sigma_rad: f64,
    /// Each encoder's white noise σ_k, rad, per axis (the table's stated `encoder_noise_arcsec`).
    pub encoder_noise_rad: Vec<f64>,
    /// True if `measurement_sigma_rad` was stated (else the calibration reads it off its residuals).
    pub measurement_sigma_stated: bool,
    /// Prior 1σ of every swing component, rad (prior mean 0).
    pub prior_swing_sigma_rad: f64,
    /// Prior mean of every non-orthogonality, rad.
    pub prior_eta_rad: f64,
    /// Its 1σ, rad.
    pub prior_eta_sigma_rad: f64,
    /// The INS's attitude error common to the samples (a random walk and an unknown gyro bias): it
    /// is correlated over the whole test, so it enters the estimate's covariance through the test
    /// (`estimate::InsTerm`), not a per-sample R. Zeros: not modelled.
    pub ins_error: InsErrorModel,
    /// Reference errors estimated alongside.
    pub nuisance: Nuisance,
    /// Snapshots of the filter for the recording, Hz.
    pub record_hz: f64,
    /// The Monte Carlo's distributions.
    pub montecarlo: MonteCarloConfig,
}

/// The INS attitude error a calibration allows for: the gyros' angle random walk and a constant
/// bias it does not know (the turn-on bias; a Gauss–Markov bias whose correlation time is long
/// against the test counts here too). With the INS running on Earth rate only (no navigation),
/// over a test of minutes: φ(t) = −∫ C_s^n (ε + w) dt.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct InsErrorModel {
    /// Angle random walk N, rad/√s (isotropic: white rate noise stays white through C_s^n).
    pub random_walk_rad_per_sqrt_s: f64,
    /// 1σ of each axis's unknown constant gyro bias, rad/s (turned with the IMU by C_s^n).
    pub bias_sigma_rad_per_s: f64,
}

impl InsErrorModel {
    /// True if it models anything.
    #[must_use]
    pub fn is_some(&self) -> bool {
        self.random_walk_rad_per_sqrt_s > 0.0 || self.bias_sigma_rad_per_s > 0.0
    }
}

/// Prior 1σ of the nuisance states, rad: effectively uninformative (1°).
const NUISANCE_PRIOR_RAD: f64 = std::f64::consts::PI / 180.0;

/// One parameter of the calibration.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Param {
    /// α cos φ of axis k (the swing rotation vector's e1 component in the rotor), rad.
    SwingCos(usize),
    /// α sin φ of axis k, rad.
    SwingSin(usize),
    /// η of axis k (k ≥ 1), rad.
    NonOrth(usize),
    /// Constant reference error about nav axis i (East, North, Up), rad.
    Offset(usize),
    /// Reference drift about nav axis i: the rotation reached at the end of the test minus at its middle, rad.
    Drift(usize),
}

impl Param {
    /// True for the turntable's parameters (not nuisance).
    #[must_use]
    pub fn is_table(self) -> bool {
        matches!(self, Self::SwingCos(_) | Self::SwingSin(_) | Self::NonOrth(_))
    }

    /// Machine key, e.g. `inner.swing_cos`.
    #[must_use]
    pub fn key(self, chain: &Chain) -> String {
        const ENU: [&str; 3] = ["east", "north", "up"];
        match self {
            Self::SwingCos(k) => format!("{}.swing_cos", chain.axes()[k].name),
            Self::SwingSin(k) => format!("{}.swing_sin", chain.axes()[k].name),
            Self::NonOrth(k) => format!("{}.non_orthogonality", chain.axes()[k].name),
            Self::Offset(i) => format!("reference.offset_{}", ENU[i]),
            Self::Drift(i) => format!("reference.drift_{}", ENU[i]),
        }
    }

    /// Label for people, e.g. `inner α·cos φ`.
    #[must_use]
    pub fn label(self, chain: &Chain) -> String {
        const ENU: [&str; 3] = ["E", "N", "U"];
        match self {
            Self::SwingCos(k) => format!("{} α·cos φ", chain.axes()[k].name),
            Self::SwingSin(k) => format!("{} α·sin φ", chain.axes()[k].name),
            Self::NonOrth(k) => format!("{} η", chain.axes()[k].name),
            Self::Offset(i) => format!("reference offset {}", ENU[i]),
            Self::Drift(i) => format!("reference drift {}", ENU[i]),
        }
    }
}

/// The parameters of a calibration, in state order: the swings from the IMU inward (for the
/// dual-axis table: inner α1 cos φ1, α1 sin φ1, outer α2 cos φ2, α2 sin φ2 — the paper's order),
/// then the non-orthogonalities, then the nuisance.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamSet {
    /// The parameters.
    pub params: Vec<Param>,
    /// How many of them are the table's (they come first).
    pub n_table: usize,
}

impl ParamSet {
    /// The parameters of a chain.
    #[must_use]
    pub fn new(chain: &Chain, nuisance: Nuisance) -> Self {
        let n = chain.axes().len();
        let mut params = Vec::new();
        for k in (0..n).rev() {
            params.push(Param::SwingCos(k));
            params.push(Param::SwingSin(k));
        }
        for k in (1..n).rev() {
            params.push(Param::NonOrth(k));
        }
        let n_table = params.len();
        if nuisance != Nuisance::None {
            params.extend((0..3).map(Param::Offset));
        }
        if nuisance == Nuisance::OffsetDrift {
            params.extend((0..3).map(Param::Drift));
        }
        Self { params, n_table }
    }

    /// Number of parameters.
    #[must_use]
    pub fn len(&self) -> usize {
        self.params.len()
    }

    /// True if there is nothing to estimate.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.params.is_empty()
    }

    /// Index of a parameter.
    #[must_use]
    pub fn index(&self, p: Param) -> Option<usize> {
        self.params.iter().position(|q| *q == p)
    }

    /// Prior mean and 1σ of each parameter.
    #[must_use]
    pub fn prior(&self, cfg: &CalibConfig) -> (Vec<f64>, Vec<f64>) {
        self.params
            .iter()
            .map(|p| match p {
                Param::SwingCos(_) | Param::SwingSin(_) => (0.0, cfg.prior_swing_sigma_rad),
                Param::NonOrth(_) => (cfg.prior_eta_rad, cfg.prior_eta_sigma_rad),
                Param::Offset(_) | Param::Drift(_) => (0.0, NUISANCE_PRIOR_RAD),
            })
            .unzip()
    }

    /// The table errors with the estimated parameters set to `theta` and the rest from `known`.
    #[must_use]
    pub fn errors(&self, theta: &[f64], known: &TableErrors) -> TableErrors {
        let mut e = known.clone();
        let n = e.axes.len();
        let (mut cos, mut sin) = (vec![None; n], vec![None; n]);
        for (p, v) in self.params.iter().zip(theta) {
            match *p {
                Param::SwingCos(k) => cos[k] = Some(*v),
                Param::SwingSin(k) => sin[k] = Some(*v),
                Param::NonOrth(k) => e.axes[k].non_orthogonality_rad = *v,
                Param::Offset(_) | Param::Drift(_) => {}
            }
        }
        for k in 0..n {
            if let (Some(a), Some(b)) = (cos[k], sin[k]) {
                // The rotor-fixed swing rotation vector is exactly α(cos φ e1 + sin φ e2) = a e1 + b e2.
                e.axes[k].swing_half_angle_rad = a.hypot(b);
                e.axes[k].swing_phase_rad = b.atan2(a);
            }
        }
        e
    }

    /// The parameters' values in `errors` (nuisance: 0).
    #[must_use]
    pub fn values(&self, errors: &TableErrors) -> Vec<f64> {
        self.params
            .iter()
            .map(|p| match *p {
                Param::SwingCos(k) => errors.axes[k].swing_half_angle_rad * errors.axes[k].swing_phase_rad.cos(),
                Param::SwingSin(k) => errors.axes[k].swing_half_angle_rad * errors.axes[k].swing_phase_rad.sin(),
                Param::NonOrth(k) => errors.axes[k].non_orthogonality_rad,
                Param::Offset(_) | Param::Drift(_) => 0.0,
            })
            .collect()
    }

    /// `known` with every estimated table parameter set to zero: the model of "before calibration".
    #[must_use]
    pub fn without_estimated(&self, known: &TableErrors) -> TableErrors {
        self.errors(&vec![0.0; self.len()], known)
    }

    /// The table parameters' columns of H (nav frame) for one sample, as three rows. The nuisance
    /// columns are I (offset) and τ·I (drift) and never stored.
    pub(crate) fn table_rows(
        &self,
        chain: &Chain,
        n_from_b: &Matrix3<f64>,
        s: &Measurement,
        out: &mut [[f64; MAX_TABLE]; 3],
    ) {
        let axes = chain.axes();
        // M_k = C_b^n P_k for every axis, and the (sin, cos) of each shaft angle from its quaternion.
        let mut m = [*n_from_b; MAX_AXES + 1];
        let mut sc = [(0.0, 1.0); MAX_AXES];
        for (k, g) in axes.iter().enumerate() {
            let q = s.shafts.0[k];
            let (c, h) = (q.w, q.imag().dot(&g.axis));
            sc[k] = (2.0 * c * h, c * c - h * h);
            if k + 1 < axes.len() {
                m[k + 1] = m[k] * q.to_rotation_matrix().into_inner();
            }
        }
        for (j, p) in self.params[..self.n_table].iter().enumerate() {
            let col: Vector3<f64> = match *p {
                Param::SwingCos(k) => m[k] * (axes[k].e1 * sc[k].1 + axes[k].e2 * sc[k].0),
                Param::SwingSin(k) => m[k] * (axes[k].e2 * sc[k].1 - axes[k].e1 * sc[k].0),
                Param::NonOrth(k) => m[k] * chain.non_orthogonality_axis(k),
                Param::Offset(_) | Param::Drift(_) => Vector3::zeros(),
            };
            out[0][j] = col.x;
            out[1][j] = col.y;
            out[2][j] = col.z;
        }
    }

    /// Each shaft's axis in the navigation frame at sample `s` (the direction its encoder noise
    /// turns the demodulated attitude, to first order).
    pub(crate) fn shaft_axes_n(&self, chain: &Chain, n_from_b: &Matrix3<f64>, s: &Measurement) -> Vec<Vector3<f64>> {
        let mut m = *n_from_b;
        let mut out = Vec::with_capacity(chain.axes().len());
        for (k, g) in chain.axes().iter().enumerate() {
            out.push(m * g.axis);
            m *= s.shafts.0[k].to_rotation_matrix().into_inner();
        }
        out
    }

    /// The nuisance part of the model for one sample, nav frame.
    pub(crate) fn nuisance(&self, theta: &[f64], tau: f64) -> Vector3<f64> {
        let mut v = Vector3::zeros();
        for (p, x) in self.params[self.n_table..].iter().zip(&theta[self.n_table..]) {
            match *p {
                Param::Offset(i) => v[i] += x,
                Param::Drift(i) => v[i] += x * tau,
                _ => {}
            }
        }
        v
    }
}

/// One measurement: the INS's C_s^n and the gimbal angles the computer has for the same instant.
#[derive(Debug, Clone, Copy)]
pub struct Measurement {
    /// Time, s.
    pub t_s: f64,
    /// The IMU attitude C_s^n the INS reports.
    pub n_from_s: Rot<N, S>,
    /// Shaft rotations of the (corrected) encoder angles.
    pub shafts: ShaftRotations,
}

/// Where the IMU attitude comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AttitudeSource {
    /// The scenario's `[imu]`: the INS in the loop with its sensor errors.
    Ins,
    /// No `[imu]`: the exact IMU attitude (only the encoder noise remains).
    Ideal,
    /// A replayed log set's INS output.
    Log,
}

/// Measurements kept in memory up to this many (about 40 MB); a longer test is generated again
/// from its source for each pass, so a calibration's memory stays flat in the test's length.
pub const IN_MEMORY_SAMPLES: usize = 1 << 18;

/// One pass over a test's measurements: calls the sink with each, in time order, until it returns
/// `false` (then the pass ends early with `Ok`).
pub type Replay = dyn Fn(&mut dyn FnMut(&Measurement) -> bool) -> Result<(), CalibError> + Send + Sync;

/// A test's measurements: in memory while they fit [`IN_MEMORY_SAMPLES`], else replayed from their
/// source (a deterministic simulation, a log file) for every pass.
pub enum Samples {
    /// All of them.
    Memory(Vec<Measurement>),
    /// The source, and what its first pass counted.
    Replayed {
        /// Generates the measurements again.
        replay: Box<Replay>,
        /// How many one pass gives.
        count: usize,
        /// The last one's time, s.
        last_t_s: f64,
    },
}

impl std::fmt::Debug for Samples {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Memory(v) => write!(f, "Samples::Memory({} measurements)", v.len()),
            Self::Replayed { count, .. } => write!(f, "Samples::Replayed({count} measurements)"),
        }
    }
}

impl Samples {
    /// Runs `replay` once: keeps its measurements if they fit in memory, else keeps `replay`.
    /// `stop` ends the pass early ([`CalibError::Interrupted`]).
    ///
    /// # Errors
    /// The source's error, or the stop.
    pub fn collect(replay: Box<Replay>, stop: &AtomicBool) -> Result<Self, CalibError> {
        let mut kept = Vec::new();
        let (mut count, mut last_t_s, mut overflow) = (0usize, 0.0, false);
        let mut stopped = false;
        replay(&mut |m: &Measurement| {
            count += 1;
            last_t_s = m.t_s;
            if !overflow {
                if kept.len() < IN_MEMORY_SAMPLES {
                    kept.push(*m);
                } else {
                    overflow = true;
                    kept = Vec::new();
                }
            }
            if count.is_multiple_of(65_536) && stop.load(Ordering::Relaxed) {
                stopped = true;
                return false;
            }
            true
        })?;
        if stopped {
            return Err(CalibError::Interrupted);
        }
        Ok(if overflow { Self::Replayed { replay, count, last_t_s } } else { Self::Memory(kept) })
    }

    /// Calls `f` with every measurement in time order; `stop` ends the pass early.
    ///
    /// # Errors
    /// The source's error, or [`CalibError::Interrupted`].
    pub fn each(&self, stop: &AtomicBool, f: &mut dyn FnMut(&Measurement)) -> Result<(), CalibError> {
        match self {
            Self::Memory(v) => {
                for (i, m) in v.iter().enumerate() {
                    if i.is_multiple_of(65_536) && stop.load(Ordering::Relaxed) {
                        return Err(CalibError::Interrupted);
                    }
                    f(m);
                }
                Ok(())
            }
            Self::Replayed { replay, .. } => {
                let mut i = 0usize;
                let mut stopped = false;
                replay(&mut |m: &Measurement| {
                    i += 1;
                    if i.is_multiple_of(65_536) && stop.load(Ordering::Relaxed) {
                        stopped = true;
                        return false;
                    }
                    f(m);
                    true
                })?;
                if stopped { Err(CalibError::Interrupted) } else { Ok(()) }
            }
        }
    }

    /// How many measurements a pass gives.
    #[must_use]
    pub fn len(&self) -> usize {
        match self {
            Self::Memory(v) => v.len(),
            Self::Replayed { count, .. } => *count,
        }
    }

    /// True without measurements.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The last measurement's time, s (0 without any).
    #[must_use]
    pub fn last_t_s(&self) -> f64 {
        match self {
            Self::Memory(v) => v.last().map_or(0.0, |m| m.t_s),
            Self::Replayed { last_t_s, .. } => *last_t_s,
        }
    }
}

/// The data of one static test.
#[derive(Debug)]
pub struct Data {
    /// The measurements, in time order.
    pub samples: Samples,
    /// The test's length, s: the drift state's time τ = 2t/duration − 1 runs over [−1, 1].
    pub duration_s: f64,
    /// The known body attitude C_b^n.
    pub n_from_b: Rot<N, B>,
    /// The known body attitude as Euler angles.
    pub attitude: Attitude,
    /// Source of the IMU attitude.
    pub source: AttitudeSource,
    /// Seed of the noise.
    pub seed: u64,
}

impl Data {
    /// The same test's description with no measurements (for building a `Data` around other samples).
    #[must_use]
    pub fn clone_header(&self) -> Self {
        Self {
            samples: Samples::Memory(Vec::new()),
            duration_s: self.duration_s,
            n_from_b: self.n_from_b,
            attitude: self.attitude,
            source: self.source,
            seed: self.seed,
        }
    }

    /// The drift state's time of a measurement at `t_s`, in [−1, 1].
    #[must_use]
    pub fn tau(&self, t_s: f64) -> f64 {
        (2.0 * t_s / self.duration_s.max(1e-9) - 1.0).clamp(-1.0, 1.0)
    }
}

/// Why a calibration cannot run.
#[derive(Debug, thiserror::Error)]
pub enum CalibError {
    /// The vehicle moves.
    #[error(
        "calibration needs the vehicle at rest (its attitude is the reference); remove [vehicle] ramp/wobble/coning from {0}"
    )]
    VehicleMoves(String),
    /// No parameter.
    #[error("nothing to calibrate: the table has no axis")]
    Empty,
    /// Singular normal equations.
    #[error("the normal equations are singular (non-finite data?)")]
    Singular,
    /// The data source failed during a pass.
    #[error("{0}")]
    Data(String),
    /// Stopped (a signal) before the end.
    #[error("stopped before the end")]
    Interrupted,
}

/// RMS and peak of the Euler-angle errors (pitch, roll, heading) of one demodulation, rad.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct ErrorSummary {
    /// RMS per axis (pitch, roll, heading), rad.
    pub rms_rad: [f64; 3],
    /// Largest |error| per axis, rad.
    pub peak_rad: [f64; 3],
}

/// At most this many rows of a trace are kept (the interval between kept rows doubles when it
/// would exceed it): a recording's calibration plots stay bounded in the test's length.
pub const MAX_TRACE_ROWS: usize = 20_000;

/// Rows kept every `interval` (at least), at most [`MAX_TRACE_ROWS`]: thinned by two, interval
/// doubled, when full.
#[derive(Debug, Clone)]
pub struct Thinned<T> {
    /// The kept rows' times, s.
    pub t_s: Vec<f64>,
    /// The kept rows.
    pub rows: Vec<T>,
    interval_s: f64,
    next_s: f64,
}

impl<T> Thinned<T> {
    /// Keeps a row at most every `interval_s` (0: every row until thinning starts).
    #[must_use]
    pub fn new(interval_s: f64) -> Self {
        Self { t_s: Vec::new(), rows: Vec::new(), interval_s, next_s: f64::NEG_INFINITY }
    }

    /// True if a row at `t_s` would be kept (check before computing an expensive row).
    #[must_use]
    pub fn wants(&self, t_s: f64) -> bool {
        t_s >= self.next_s
    }

    /// Offers a row at `t_s`.
    pub fn push(&mut self, t_s: f64, row: T) {
        if !self.wants(t_s) {
            return;
        }
        if self.rows.len() >= MAX_TRACE_ROWS {
            let mut i = 0;
            self.rows.retain(|_| {
                i += 1;
                i % 2 == 1
            });
            let mut j = 0;
            self.t_s.retain(|_| {
                j += 1;
                j % 2 == 1
            });
            self.interval_s = if self.interval_s > 0.0 {
                2.0 * self.interval_s
            } else {
                2.0 * (t_s - self.t_s.first().copied().unwrap_or(0.0)) / MAX_TRACE_ROWS as f64
            };
        }
        self.t_s.push(t_s);
        self.rows.push(row);
        self.next_s = t_s + self.interval_s;
    }
}

/// The attitude errors of `data` demodulated with each of `variants` (table errors; exact chain,
/// Euler angles, computed minus known), one pass: their summaries, and the per-sample errors of
/// every variant thinned to `trace` (pitch, roll, heading, rad).
///
/// # Errors
/// The data source's, or the stop.
pub fn attitude_errors(
    chain: &Chain,
    variants: &[TableErrors],
    data: &Data,
    stop: &AtomicBool,
    trace: &mut Thinned<Vec<[f64; 3]>>,
) -> Result<Vec<ErrorSummary>, CalibError> {
    let err: Vec<_> = variants.iter().map(|e| chain.error_rotations(e)).collect();
    let mut sums = vec![ErrorSummary::default(); variants.len()];
    data.samples.each(stop, &mut |s| {
        let keep = trace.wants(s.t_s);
        let mut row = Vec::with_capacity(if keep { variants.len() } else { 0 });
        for (e, sum) in err.iter().zip(&mut sums) {
            let b_from_s = chain.b_from_s_with(e, &s.shafts);
            let v = demodulate(s.n_from_s, b_from_s).error_from(&data.attitude).as_array();
            for i in 0..3 {
                sum.rms_rad[i] += v[i] * v[i];
                sum.peak_rad[i] = sum.peak_rad[i].max(v[i].abs());
            }
            if keep {
                row.push(v);
            }
        }
        if keep {
            trace.push(s.t_s, row);
        }
    })?;
    let n = data.samples.len().max(1) as f64;
    for sum in &mut sums {
        sum.rms_rad = sum.rms_rad.map(|v| (v / n).sqrt());
    }
    Ok(sums)
}

#[cfg(test)]
mod tests;
