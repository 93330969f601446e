//! The estimators on one static test's data: the static Kalman filter (seed 000 eq. 29-33) in
//! information form and the chord Gauss–Newton least squares on the exact chain.

use nalgebra::{DMatrix, DVector, Vector3};

use std::sync::atomic::AtomicBool;

use super::{CalibConfig, CalibError, Data, Measurement, Param, ParamSet, Thinned, MAX_PARAMS, MAX_TABLE};
use crate::math::frames::{Rot, B, N};
use crate::math::rotvec;
use crate::model::gimbal::{Chain, ErrorRotations, TableErrors};

/// Which of the filter's intermediate results a calibration keeps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum History {
    /// The estimates only, with the filter's residual RMS (the `calibrate` command without a recording).
    Final,
    /// Snapshots of the filter at this rate, Hz (for a recording; at most
    /// [`super::MAX_TRACE_ROWS`], thinned over long tests).
    Snapshots(f64),
    /// The Monte Carlo's lean mode: no snapshots, no filter residuals.
    Lean,
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
pub(crate) fn exact_residual(chain: &Chain, err: &ErrorRotations, s: &Measurement, ref_inv: &Rot<B, N>) -> Vector3<f64> {
    let b_from_s = chain.b_from_s_with(err, &s.shafts);
    let computed: Rot<N, B> = s.n_from_s * b_from_s.inverse();
    rotvec::log((computed * *ref_inv).quaternion())
}

fn solve(a: &DMatrix<f64>, b: &DVector<f64>) -> Result<(DVector<f64>, DMatrix<f64>), CalibError> {
    let chol = a.clone().cholesky().ok_or(CalibError::Singular)?;
    Ok((chol.solve(b), chol.inverse()))
}

/// Estimates the parameters from `data`: the static Kalman filter, then least squares on the exact
/// model. `known` holds every error not estimated; `history` says what to keep along the way;
/// `stop` ends it early ([`CalibError::Interrupted`]).
///
/// Memory is flat in the test's length: each pass (the filter's, then one per Gauss–Newton step)
/// streams the data ([`super::Samples`]) and accumulates the normal equations.
///
/// # Errors
/// No parameter, singular normal equations, the data source's error or the stop.
pub fn calibrate(chain: &Chain, known: &TableErrors, data: &Data, cfg: &CalibConfig, history: History, stop: &AtomicBool) -> Result<Calibration, CalibError> {
    let set = ParamSet::new(chain, cfg.nuisance);
    let p = set.len();
    if set.n_table == 0 || p > MAX_PARAMS {
        return Err(CalibError::Empty);
    }
    let (x0, s0) = set.prior(cfg);
    let x0 = DVector::from_vec(x0);
    let prior_info = DMatrix::from_diagonal(&DVector::from_iterator(p, s0.iter().map(|s| 1.0 / (s * s))));
    let w = 1.0 / cfg.measurement_sigma_rad.powi(2);
    let n_from_b = data.n_from_b.matrix();
    let ref_inv = data.n_from_b.inverse();

    // The measurement z: the demodulation with the estimated parameters at zero.
    let before = chain.error_rotations(&set.without_estimated(known));
    let n = data.samples.len();
    let nt = set.n_table;
    let mut h = [[0.0; MAX_TABLE]; 3];
    let mut sums = Sums::default();
    let mut snapshots = Thinned::new(match history {
        History::Snapshots(hz) => 1.0 / hz,
        _ => f64::INFINITY,
    });
    data.samples.each(stop, &mut |s| {
        set.table_rows(chain, &n_from_b, s, &mut h);
        let z = exact_residual(chain, &before, s, &ref_inv);
        sums.add(nt, &h, data.tau(s.t_s), &z, w);
        if matches!(history, History::Snapshots(_)) && snapshots.wants(s.t_s) {
            let (a, b) = sums.assemble(&set);
            // Early on the information can be singular: that snapshot is skipped.
            if let Ok((x, cov)) = solve(&(&prior_info + a), &(&prior_info * &x0 + b)) {
                snapshots.push(s.t_s, Snapshot { t_s: s.t_s, theta: x.iter().copied().collect(), sigma: cov.diagonal().iter().map(|v| v.max(0.0).sqrt()).collect() });
            }
        }
    })?;
    let (data_information, rhs) = sums.assemble(&set);
    let information = &prior_info + &data_information;
    let (x_kf, cov) = solve(&information, &(&prior_info * &x0 + rhs))?;
    let chol = information.clone().cholesky().ok_or(CalibError::Singular)?;

    // Residuals of a parameter vector under the exact model, and the Gauss–Newton right-hand side
    // Σ HᵀR⁻¹r.
    let pass = |theta: &DVector<f64>| -> Result<(DVector<f64>, [f64; 3]), CalibError> {
        let t: Vec<f64> = theta.iter().copied().collect();
        let err = chain.error_rotations(&set.errors(&t, known));
        let mut g = Sums::default();
        let mut sq = [0.0; 3];
        let mut h = [[0.0; MAX_TABLE]; 3];
        data.samples.each(stop, &mut |s| {
            // H again rather than kept: 3·n_table numbers per sample would make memory grow with the test.
            set.table_rows(chain, &n_from_b, s, &mut h);
            let tau = data.tau(s.t_s);
            let r = exact_residual(chain, &err, s, &ref_inv) - set.nuisance(&t, tau);
            for k in 0..3 {
                sq[k] += r[k] * r[k];
                let wr = w * r[k];
                for (gj, hj) in g.b_t[..nt].iter_mut().zip(&h[k][..nt]) {
                    *gj += hj * wr;
                }
                g.b_off[k] += wr;
                g.b_drift[k] += wr * tau;
            }
        })?;
        let nf = n.max(1) as f64;
        Ok((g.assemble(&set).1, sq.map(|v| (v / nf).sqrt())))
    };
    // The filter's residuals are reported, not needed by the estimate (the Monte Carlo skips them).
    let kf_rms = if history == History::Lean { [f64::NAN; 3] } else { pass(&x_kf)?.1 };
    let kf = Estimate { theta: x_kf.iter().copied().collect(), cov: cov.clone(), residual_rms_rad: kf_rms };

    // Chord Gauss–Newton from the filter's estimate. The residuals are exact; the Jacobian is the
    // first-order H (relative error ~ the error angles, 1e-3), so each step gains ~3 digits.
    let mut theta = x_kf;
    let mut iterations = 0;
    let mut rms = kf_rms;
    for _ in 0..8 {
        let (g, r) = pass(&theta)?;
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
        history: snapshots.rows,
        samples: data.samples.len(),
        measurement_sigma_rad: cfg.measurement_sigma_rad,
    })
}

