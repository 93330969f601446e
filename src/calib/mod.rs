//! Static calibration of the turntable's swing cones and non-orthogonality (seed 000 §5-6), by the
//! paper's static Kalman filter and by nonlinear least squares on the exact chain
//! (docs/calibration.md).
//!
//! The vehicle is at rest and its attitude is known (seed 000 §5: "the roll and pitch angles are
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

mod estimate;
pub mod montecarlo;
pub mod report;

pub use estimate::{calibrate, Calibration, Estimate, History, Snapshot};

use nalgebra::{Matrix3, Vector3};

use crate::math::attitude::Attitude;
use crate::math::frames::{Rot, B, N, S};
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

/// `[calibration]`, validated, SI.
#[derive(Debug, Clone, PartialEq)]
pub struct CalibConfig {
    /// R = σ² I for each nav-frame component of z, rad.
    pub measurement_sigma_rad: f64,
    /// Prior 1σ of every swing component, rad (prior mean 0).
    pub prior_swing_sigma_rad: f64,
    /// Prior mean of every non-orthogonality, rad.
    pub prior_eta_rad: f64,
    /// Its 1σ, rad.
    pub prior_eta_sigma_rad: f64,
    /// Reference errors estimated alongside.
    pub nuisance: Nuisance,
    /// Snapshots of the filter for the recording, Hz.
    pub record_hz: f64,
    /// The Monte Carlo's distributions.
    pub montecarlo: MonteCarloConfig,
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
    pub(crate) fn table_rows(&self, chain: &Chain, n_from_b: &Matrix3<f64>, s: &Measurement, out: &mut [[f64; MAX_TABLE]; 3]) {
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
    /// Time scaled to [−1, 1] over the test (for the drift state).
    pub tau: f64,
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

/// The data of one static test.
#[derive(Debug, Clone)]
pub struct Data {
    /// The samples, in time order.
    pub samples: Vec<Measurement>,
    /// The known body attitude C_b^n.
    pub n_from_b: Rot<N, B>,
    /// The known body attitude as Euler angles.
    pub attitude: Attitude,
    /// Source of the IMU attitude.
    pub source: AttitudeSource,
    /// Seed of the noise.
    pub seed: u64,
}

/// Why a calibration cannot run.
#[derive(Debug, thiserror::Error)]
pub enum CalibError {
    /// The vehicle moves.
    #[error("calibration needs the vehicle at rest (its attitude is the reference); remove [vehicle] ramp/wobble/coning from {0}")]
    VehicleMoves(String),
    /// No parameter.
    #[error("nothing to calibrate: the table has no axis")]
    Empty,
    /// Singular normal equations.
    #[error("the normal equations are singular (non-finite data?)")]
    Singular,
}

/// RMS and peak of the Euler-angle errors (pitch, roll, heading) of one demodulation, rad.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct ErrorSummary {
    /// RMS per axis (pitch, roll, heading), rad.
    pub rms_rad: [f64; 3],
    /// Largest |error| per axis, rad.
    pub peak_rad: [f64; 3],
}

/// The attitude errors of `data` demodulated with table errors `errors` (exact chain, Euler angles,
/// computed minus known), per sample; and their summary.
#[must_use]
pub fn attitude_errors(chain: &Chain, errors: &TableErrors, data: &Data) -> (Vec<[f64; 3]>, ErrorSummary) {
    let err = chain.error_rotations(errors);
    let mut out = Vec::with_capacity(data.samples.len());
    let mut sum = ErrorSummary::default();
    for s in &data.samples {
        let b_from_s = chain.b_from_s_with(&err, &s.shafts);
        let e = demodulate(s.n_from_s, b_from_s).error_from(&data.attitude).as_array();
        for i in 0..3 {
            sum.rms_rad[i] += e[i] * e[i];
            sum.peak_rad[i] = sum.peak_rad[i].max(e[i].abs());
        }
        out.push(e);
    }
    let n = data.samples.len().max(1) as f64;
    sum.rms_rad = sum.rms_rad.map(|v| (v / n).sqrt());
    (out, sum)
}

#[cfg(test)]
mod tests;
