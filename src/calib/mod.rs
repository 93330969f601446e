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
//! [`crate::gimbal::Chain::first_order_phi_b`]). Everything not estimated — installation, IMU mount,
//! encoder offset, scale and delay — is taken as known from `[compensation]`, as the paper assumes
//! ("after all kinds of the mounting errors and the angle errors of the angle encoders are
//! calibrated for").
//!
//! The filter (eq. 33) is kept in information form, which is the same recursion: Λ = P₀⁻¹ + Σ HᵀR⁻¹H,
//! x̂ = Λ⁻¹(P₀⁻¹x₀ + Σ HᵀR⁻¹z). The least-squares fit then iterates on the exact residuals (the whole
//! chain, exponential maps, no small angle) with the same Λ: a Gauss–Newton (chord) iteration that
//! converges to the exact model's solution.

pub mod montecarlo;
pub mod report;

use nalgebra::{DMatrix, DVector, Matrix3, UnitQuaternion, Vector3};

use crate::config::Params;
use crate::euler::Attitude;
use crate::frames::Rot;
use crate::gimbal::{Chain, ShaftRotations, TableErrors};
use crate::ins::pipeline::InsRun;
use crate::scheme::MAX_AXES;
use crate::sim::{DemodState, Model, encoder_readings};

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
    fn table_rows(&self, chain: &Chain, n_from_b: &Matrix3<f64>, s: &Sample, out: &mut [[f64; MAX_TABLE]; 3]) {
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
    fn nuisance(&self, theta: &[f64], tau: f64) -> Vector3<f64> {
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
pub struct Sample {
    /// Time, s.
    pub t_s: f64,
    /// Time scaled to [−1, 1] over the test (for the drift state).
    pub tau: f64,
    /// The IMU attitude C_s^n the INS reports.
    pub n_from_s: UnitQuaternion<f64>,
    /// Shaft rotations of the (corrected) encoder angles.
    pub shafts: ShaftRotations,
}

/// Where the IMU attitude comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Source {
    /// The scenario's `[imu]`: the INS in the loop with its sensor errors.
    Ins,
    /// No `[imu]`: the exact IMU attitude (only the encoder noise remains).
    Ideal,
}

/// The data of one static test.
#[derive(Debug, Clone)]
pub struct Data {
    /// The samples, in time order.
    pub samples: Vec<Sample>,
    /// The known body attitude C_b^n.
    pub n_from_b: UnitQuaternion<f64>,
    /// The known body attitude as Euler angles.
    pub attitude: Attitude,
    /// Source of the IMU attitude.
    pub source: Source,
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

/// Runs the static test of `params` with noise seed `seed` and collects one sample per INS output.
pub fn collect(params: &Params, seed: u64) -> Result<Data, CalibError> {
    let Some((attitude, n_from_b)) = Model::new(params).fixed_state() else {
        return Err(CalibError::VehicleMoves(params.meta.name.clone()));
    };
    let mut p = params.clone();
    p.meta.seed = seed;
    let mut model = Model::new(&p);
    // The demodulation knows every error it does not estimate: the compensation's values.
    let set = ParamSet::new(&p.chain, Nuisance::None);
    model.compensation = set.without_estimated(&p.compensation);
    let chain = p.chain.clone();
    let steps = p.steps();
    let duration = steps as f64 / p.step_hz;
    let tau = |t: f64| (2.0 * t / duration - 1.0).clamp(-1.0, 1.0);
    let mut samples = Vec::with_capacity(steps as usize);
    let mut demod = DemodState::default();
    let source = if p.ins.is_some() { Source::Ins } else { Source::Ideal };
    match InsRun::new(&p, model.clone()) {
        Some(mut ins) => {
            for _ in 0..steps {
                if ins.step().updated {
                    let (t, q) = ins.output_attitude(0);
                    // Matched synchronisation: the encoders are read for the instant the data represent.
                    let angles = demod.correct(&model, t, &encoder_readings(&model, t));
                    samples.push(Sample { t_s: t, tau: tau(t), n_from_s: q, shafts: chain.shaft_rotations(&angles) });
                }
            }
        }
        None => {
            let truth = model.truth_rotations().clone();
            for i in 1..=steps {
                let t = i as f64 / p.step_hz;
                let (lambda, _) = model.scheme.state(t - model.scheme_t0_s);
                let n_from_s = n_from_b * chain.b_from_s(&truth, &lambda);
                let angles = demod.correct(&model, t, &encoder_readings(&model, t));
                samples.push(Sample { t_s: t, tau: tau(t), n_from_s: *n_from_s.quaternion(), shafts: chain.shaft_rotations(&angles) });
            }
        }
    }
    Ok(Data { samples, n_from_b: *n_from_b.quaternion(), attitude, source, seed })
}

/// The filter's sums Σ HᵀR⁻¹H and Σ HᵀR⁻¹z, kept by blocks: table × table, table × nuisance, and the
/// nuisance blocks, which are scalar multiples of I (offset: I, drift: τ·I).
#[derive(Debug, Clone, Default)]
struct Sums {
    tt: [[f64; MAX_TABLE]; MAX_TABLE],
    t_off: [[f64; 3]; MAX_TABLE],
    t_drift: [[f64; 3]; MAX_TABLE],
    b_t: [f64; MAX_TABLE],
    b_off: [f64; 3],
    b_drift: [f64; 3],
    w: f64,
    w_tau: f64,
    w_tau2: f64,
}

impl Sums {
    fn add(&mut self, nt: usize, h: &[[f64; MAX_TABLE]; 3], tau: f64, z: &Vector3<f64>, w: f64) {
        for r in 0..3 {
            let row = &h[r];
            let zr = z[r];
            for i in 0..nt {
                let hi = w * row[i];
                self.b_t[i] += hi * zr;
                self.t_off[i][r] += hi;
                self.t_drift[i][r] += hi * tau;
                let tt = &mut self.tt[i];
                for j in i..nt {
                    tt[j] += hi * row[j];
                }
            }
            self.b_off[r] += w * zr;
            self.b_drift[r] += w * tau * zr;
        }
        self.w += w;
        self.w_tau += w * tau;
        self.w_tau2 += w * tau * tau;
    }

    /// The full information matrix and right-hand side in the order of `set`.
    fn assemble(&self, set: &ParamSet) -> (DMatrix<f64>, DVector<f64>) {
        let p = set.len();
        let nt = set.n_table;
        let mut a = DMatrix::zeros(p, p);
        let mut b = DVector::zeros(p);
        for i in 0..nt {
            b[i] = self.b_t[i];
            for j in i..nt {
                a[(i, j)] = self.tt[i][j];
                a[(j, i)] = self.tt[i][j];
            }
        }
        for (j, pj) in set.params.iter().enumerate().skip(nt) {
            match *pj {
                Param::Offset(r) => {
                    b[j] = self.b_off[r];
                    for i in 0..nt {
                        a[(i, j)] = self.t_off[i][r];
                        a[(j, i)] = self.t_off[i][r];
                    }
                }
                Param::Drift(r) => {
                    b[j] = self.b_drift[r];
                    for i in 0..nt {
                        a[(i, j)] = self.t_drift[i][r];
                        a[(j, i)] = self.t_drift[i][r];
                    }
                }
                _ => {}
            }
            for (k, pk) in set.params.iter().enumerate().skip(nt) {
                a[(j, k)] = match (*pj, *pk) {
                    (Param::Offset(r), Param::Offset(q)) if r == q => self.w,
                    (Param::Offset(r), Param::Drift(q)) | (Param::Drift(r), Param::Offset(q)) if r == q => self.w_tau,
                    (Param::Drift(r), Param::Drift(q)) if r == q => self.w_tau2,
                    _ => 0.0,
                };
            }
        }
        (a, b)
    }
}

/// One estimator's result.
#[derive(Debug, Clone)]
pub struct Estimate {
    /// Parameter values, rad.
    pub theta: Vec<f64>,
    /// Posterior covariance, rad².
    pub cov: DMatrix<f64>,
    /// RMS of the residuals per nav axis (E, N, U), rad.
    pub residual_rms_rad: [f64; 3],
}

impl Estimate {
    /// 1σ of parameter i, rad.
    #[must_use]
    pub fn sigma(&self, i: usize) -> f64 {
        self.cov[(i, i)].max(0.0).sqrt()
    }
}

/// The filter's state and 1σ at one instant (for the recording).
#[derive(Debug, Clone)]
pub struct Snapshot {
    /// Time, s.
    pub t_s: f64,
    /// Estimates, rad.
    pub theta: Vec<f64>,
    /// 1σ, rad.
    pub sigma: Vec<f64>,
}

/// Everything a calibration produces.
#[derive(Debug, Clone)]
pub struct Calibration {
    /// The parameters.
    pub set: ParamSet,
    /// Prior mean and 1σ.
    pub prior: (Vec<f64>, Vec<f64>),
    /// The static Kalman filter (seed 000 eq. 29-33, first-order measurement model).
    pub kf: Estimate,
    /// Nonlinear least squares on the exact chain.
    pub nls: Estimate,
    /// Gauss–Newton iterations the least squares took.
    pub nls_iterations: usize,
    /// The data's information matrix Σ HᵀR⁻¹H (no prior), for the observability analysis.
    pub data_information: DMatrix<f64>,
    /// The filter over time (empty unless asked for).
    pub history: Vec<Snapshot>,
    /// Number of measurements.
    pub samples: usize,
    /// Measurement 1σ used, rad.
    pub measurement_sigma_rad: f64,
}

/// Exact residual of one sample for the table errors `err` (nav frame): the rotation from the known
/// attitude to the demodulated one.
fn exact_residual(chain: &Chain, err: &crate::gimbal::ErrorRotations, s: &Sample, ref_inv: &UnitQuaternion<f64>) -> Vector3<f64> {
    let b_from_s = chain.b_from_s_with(err, &s.shafts);
    let computed = s.n_from_s * b_from_s.inverse().quaternion();
    rotation_vector(&(computed * ref_inv))
}

/// The rotation vector of a unit quaternion (its logarithm ×2). Small rotations (the hot path: every
/// residual is below a degree) use the series 2·asin(s)/s = 2(1 + s²/6 + 3s⁴/40 + 5s⁶/112 + …) of
/// the vector part's norm s; the first omitted term, 35s⁸/1152, is below 1e-17 for s < 0.01
/// (rotations under 1.1°); larger ones the library's atan2 form.
#[must_use]
pub fn rotation_vector(q: &UnitQuaternion<f64>) -> Vector3<f64> {
    let v = if q.w < 0.0 { -q.imag() } else { q.imag() };
    let s2 = v.norm_squared();
    if s2 < 1e-4 { v * (2.0 * (1.0 + s2 * (1.0 / 6.0 + s2 * (3.0 / 40.0 + s2 * (5.0 / 112.0))))) } else { q.scaled_axis() }
}

fn solve(a: &DMatrix<f64>, b: &DVector<f64>) -> Result<(DVector<f64>, DMatrix<f64>), CalibError> {
    let chol = a.clone().cholesky().ok_or(CalibError::Singular)?;
    Ok((chol.solve(b), chol.inverse()))
}

/// Estimates the parameters from `data`: the static Kalman filter, then least squares on the exact
/// model. `known` holds every error not estimated. `history_hz > 0` keeps snapshots of the filter;
/// `history_hz < 0` is the Monte Carlo's lean mode (no filter residuals either).
pub fn calibrate(chain: &Chain, known: &TableErrors, data: &Data, cfg: &CalibConfig, history_hz: f64) -> Result<Calibration, CalibError> {
    let set = ParamSet::new(chain, cfg.nuisance);
    let p = set.len();
    if set.n_table == 0 || p > MAX_PARAMS {
        return Err(CalibError::Empty);
    }
    let (x0, s0) = set.prior(cfg);
    let x0 = DVector::from_vec(x0);
    let prior_info = DMatrix::from_diagonal(&DVector::from_iterator(p, s0.iter().map(|s| 1.0 / (s * s))));
    let w = 1.0 / cfg.measurement_sigma_rad.powi(2);
    let n_from_b = data.n_from_b.to_rotation_matrix().into_inner();
    let ref_inv = data.n_from_b.inverse();

    // The measurement z: the demodulation with the estimated parameters at zero. H is kept for
    // the least-squares passes (3·p numbers per sample).
    let before = chain.error_rotations(&set.without_estimated(known));
    let n = data.samples.len();
    let nt = set.n_table;
    // The table's rows of H are kept for the least-squares passes (3·n_table numbers per sample).
    let mut rows = Vec::with_capacity(3 * nt * n);
    let mut h = [[0.0; MAX_TABLE]; 3];
    let mut sums = Sums::default();
    let mut history = Vec::new();
    let mut next_snapshot = 0.0;
    for s in &data.samples {
        set.table_rows(chain, &n_from_b, s, &mut h);
        for r in &h {
            rows.extend_from_slice(&r[..nt]);
        }
        let z = exact_residual(chain, &before, s, &ref_inv);
        sums.add(nt, &h, s.tau, &z, w);
        if history_hz > 0.0 && s.t_s >= next_snapshot {
            next_snapshot += 1.0 / history_hz;
            let (a, b) = sums.assemble(&set);
            if let Ok((x, cov)) = solve(&(&prior_info + a), &(&prior_info * &x0 + b)) {
                history.push(Snapshot { t_s: s.t_s, theta: x.iter().copied().collect(), sigma: cov.diagonal().iter().map(|v| v.max(0.0).sqrt()).collect() });
            }
        }
    }
    let (data_information, rhs) = sums.assemble(&set);
    let information = &prior_info + &data_information;
    let (x_kf, cov) = solve(&information, &(&prior_info * &x0 + rhs))?;
    let chol = information.clone().cholesky().ok_or(CalibError::Singular)?;

    // Residuals of a parameter vector under the exact model, and the Gauss–Newton right-hand side
    // Σ HᵀR⁻¹r.
    let pass = |theta: &DVector<f64>| -> (DVector<f64>, [f64; 3]) {
        let t: Vec<f64> = theta.iter().copied().collect();
        let err = chain.error_rotations(&set.errors(&t, known));
        let mut g = Sums::default();
        let mut sq = [0.0; 3];
        for (s, hr) in data.samples.iter().zip(rows.chunks_exact(3 * nt)) {
            let r = exact_residual(chain, &err, s, &ref_inv) - set.nuisance(&t, s.tau);
            for k in 0..3 {
                sq[k] += r[k] * r[k];
                let wr = w * r[k];
                for (gj, hj) in g.b_t[..nt].iter_mut().zip(&hr[k * nt..(k + 1) * nt]) {
                    *gj += hj * wr;
                }
                g.b_off[k] += wr;
                g.b_drift[k] += wr * s.tau;
            }
        }
        let nf = n.max(1) as f64;
        (g.assemble(&set).1, sq.map(|v| (v / nf).sqrt()))
    };
    // The filter's residuals are reported, not needed by the estimate (the Monte Carlo skips them).
    let kf_rms = if history_hz >= 0.0 { pass(&x_kf).1 } else { [f64::NAN; 3] };
    let kf = Estimate { theta: x_kf.iter().copied().collect(), cov: cov.clone(), residual_rms_rad: kf_rms };

    // Chord Gauss–Newton from the filter's estimate. The residuals are exact; the Jacobian is the
    // first-order H (relative error ~ the error angles, 1e-3), so each step gains ~3 digits.
    let mut theta = x_kf;
    let mut iterations = 0;
    let mut rms = kf_rms;
    for _ in 0..8 {
        let (g, r) = pass(&theta);
        rms = r;
        let step = chol.solve(&(g - &prior_info * (&theta - &x0)));
        theta += &step;
        iterations += 1;
        // Converged when every step is below 1e-4 of its parameter's 1σ (and 2e-7″): the next one
        // would change nothing a user could see.
        if step.iter().zip(cov.diagonal().iter()).take(set.n_table).all(|(d, v)| d.abs() < (1e-4 * v.sqrt()).max(1e-12)) {
            break;
        }
    }
    let nls = Estimate { theta: theta.iter().copied().collect(), cov, residual_rms_rad: rms };
    Ok(Calibration {
        set,
        prior: (x0.iter().copied().collect(), s0),
        kf,
        nls,
        nls_iterations: iterations,
        data_information,
        history,
        samples: data.samples.len(),
        measurement_sigma_rad: cfg.measurement_sigma_rad,
    })
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
        let n_from_s: Rot<crate::frames::N, crate::frames::S> = Rot::from_quaternion(s.n_from_s);
        let e = crate::sim::demodulate(n_from_s, b_from_s).error_from(&data.attitude).as_array();
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

/// A calibration as `rinscope calibrate` runs it: the test, an independent validation run (noise
/// seed + 1), both estimators, compensation before/after on the validation run, the report.
pub struct Outcome {
    /// The calibration data.
    pub data: Data,
    /// The validation run.
    pub validation: Data,
    /// The estimates.
    pub cal: Calibration,
    /// The report.
    pub report: report::Report,
    /// Per-sample attitude errors of the validation run: before, after KF, after LSQ.
    pub validation_errors: [Vec<[f64; 3]>; 3],
}

/// Runs the whole calibration of a scenario (`history`: keep the filter's snapshots for a recording).
pub fn run(params: &Params, history: bool) -> Result<Outcome, CalibError> {
    let seed = params.meta.seed;
    let (data, validation) = std::thread::scope(|scope| {
        let v = scope.spawn(|| collect(params, seed.wrapping_add(1)));
        let d = collect(params, seed);
        (d, v.join().unwrap_or(Err(CalibError::Singular)))
    });
    let (data, validation) = (data?, validation?);
    let cfg = &params.calibration;
    let cal = calibrate(&params.chain, &params.compensation, &data, cfg, if history { cfg.record_hz } else { 0.0 })?;
    let known = &params.compensation;
    let set = &cal.set;
    let before = attitude_errors(&params.chain, &set.without_estimated(known), &validation);
    let kf = attitude_errors(&params.chain, &set.errors(&cal.kf.theta, known), &validation);
    let nls = attitude_errors(&params.chain, &set.errors(&cal.nls.theta, known), &validation);
    let truth = attitude_errors(&params.chain, &set.errors(&set.values(&params.truth), known), &validation);
    let compensation = report::Compensation { before: before.1, after_kf: kf.1, after_nls: nls.1, with_truth: truth.1 };
    let report = report::build(&params.meta.name, &params.chain, &params.truth, &cal, &data, Some(compensation));
    Ok(Outcome { data, validation, cal, report, validation_errors: [before.0, kf.0, nls.0] })
}

#[cfg(test)]
mod tests;
