//! The estimators on one static test's data: the static Kalman filter (Jiang et al. 2017 eq. 29-33) in
//! information form and the chord Gauss–Newton least squares on the exact chain.

use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

use std::sync::atomic::AtomicBool;

use super::{
    CalibConfig, CalibError, Data, InsErrorModel, MAX_PARAMS, MAX_TABLE, Measurement, Param, ParamSet, Thinned,
};
use crate::math::frames::{B, N, Rot};
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

/// One sample's measurement model: the rows of H (3 × p, the table's columns then the nuisance's)
/// and the weight R⁻¹ of its noise.
///
/// R is built from where the noise enters: each encoder's white noise σ_k turns the demodulated
/// attitude about that shaft's axis u_k (nav frame), and the INS and everything else add σ² I:
/// R = Σ_k σ_k² u_k u_kᵀ + σ² I. (An isotropic R overstates the uncertainty of the states the
/// encoder noise does not reach, and understates the rest.)
pub struct SampleModel {
    /// H, row-major, p columns used.
    pub h: [[f64; MAX_PARAMS]; 3],
    /// R⁻¹.
    pub w: Matrix3<f64>,
    /// Orthonormal basis of the directions the encoders' noise acts in (the rest of a residual is
    /// the isotropic part's), and how many.
    encoder_basis: [Vector3<f64>; 3],
    encoder_rank: usize,
}

impl SampleModel {
    pub(crate) fn new() -> Self {
        Self {
            h: [[0.0; MAX_PARAMS]; 3],
            w: Matrix3::identity(),
            encoder_basis: [Vector3::zeros(); 3],
            encoder_rank: 0,
        }
    }

    /// Fills H and R⁻¹ for sample `s` (time τ).
    pub(crate) fn set(
        &mut self,
        set: &ParamSet,
        chain: &Chain,
        n_from_b: &Matrix3<f64>,
        s: &Measurement,
        tau: f64,
        cfg: &CalibConfig,
    ) {
        let mut table = [[0.0; MAX_TABLE]; 3];
        set.table_rows(chain, n_from_b, s, &mut table);
        let nt = set.n_table;
        for r in 0..3 {
            self.h[r] = [0.0; MAX_PARAMS];
            self.h[r][..nt].copy_from_slice(&table[r][..nt]);
        }
        for (j, p) in set.params.iter().enumerate().skip(nt) {
            match *p {
                Param::Offset(r) => self.h[r][j] = 1.0,
                Param::Drift(r) => self.h[r][j] = tau,
                _ => {}
            }
        }
        let mut r = Matrix3::identity() * cfg.measurement_sigma_rad.powi(2);
        self.encoder_rank = 0;
        for (u, sigma) in set.shaft_axes_n(chain, n_from_b, s).iter().zip(&cfg.encoder_noise_rad) {
            r += u * u.transpose() * sigma.powi(2);
            if *sigma > 0.0 && self.encoder_rank < 3 {
                // Gram–Schmidt: the part of u not yet spanned.
                let mut e = *u;
                for b in &self.encoder_basis[..self.encoder_rank] {
                    e -= b * b.dot(&e);
                }
                if e.norm() > 1e-6 {
                    self.encoder_basis[self.encoder_rank] = e.normalize();
                    self.encoder_rank += 1;
                }
            }
        }
        self.w = r.try_inverse().unwrap_or_else(Matrix3::zeros);
    }

    /// The squared part of residual `r` outside the encoders' directions, and its degrees of
    /// freedom (what the isotropic noise alone explains).
    fn isotropic_part(&self, r: &Vector3<f64>) -> (f64, usize) {
        let mut perp = *r;
        for b in &self.encoder_basis[..self.encoder_rank] {
            perp -= b * b.dot(r);
        }
        (perp.norm_squared(), 3 - self.encoder_rank)
    }

    /// R⁻¹ H, row-major.
    fn wh(&self, p: usize) -> [[f64; MAX_PARAMS]; 3] {
        let mut out = [[0.0; MAX_PARAMS]; 3];
        for (r, row) in out.iter_mut().enumerate() {
            for (j, x) in row.iter_mut().enumerate().take(p) {
                *x = (0..3).map(|c| self.w[(r, c)] * self.h[c][j]).sum();
            }
        }
        out
    }
}

/// The normal equations Σ HᵀR⁻¹H and Σ HᵀR⁻¹z (the information form of the static filter).
#[derive(Debug, Clone)]
struct Normal {
    a: [[f64; MAX_PARAMS]; MAX_PARAMS],
    b: [f64; MAX_PARAMS],
}

impl Normal {
    fn new() -> Self {
        Self { a: [[0.0; MAX_PARAMS]; MAX_PARAMS], b: [0.0; MAX_PARAMS] }
    }

    /// Adds one sample with its measurement z (or residual); `wh` = R⁻¹H of its model `m`.
    fn add(
        &mut self,
        p: usize,
        m: &SampleModel,
        wh: &[[f64; MAX_PARAMS]; 3],
        z: &Vector3<f64>,
        with_information: bool,
    ) {
        for i in 0..p {
            self.b[i] += (0..3).map(|r| wh[r][i] * z[r]).sum::<f64>();
            if with_information {
                for j in i..p {
                    self.a[i][j] += (0..3).map(|r| m.h[r][i] * wh[r][j]).sum::<f64>();
                }
            }
        }
    }

    fn assemble(&self, p: usize) -> (DMatrix<f64>, DVector<f64>) {
        let a = DMatrix::from_fn(p, p, |i, j| if i <= j { self.a[i][j] } else { self.a[j][i] });
        (a, DVector::from_column_slice(&self.b[..p]))
    }
}

/// The INS term of the estimate's covariance. The estimate is θ̂ = A⁻¹(P₀x₀ + Σ Gᵢᵀzᵢ) with
/// Gᵢ = R⁻¹Hᵢ and A = P₀ + Σ HᵢᵀR⁻¹Hᵢ; an INS error φᵢ common to the samples adds Σ Gᵢᵀφᵢ, whose
/// covariance M makes the estimate's A⁻¹ + A⁻¹MA⁻¹ (R covers only what is white from sample to
/// sample). With φᵢ = −Σ_{k≤i} C_k (ε Δt_k + w_k), w_k the random walk's increments
/// (E w wᵀ = N²Δt I) and ε the unknown bias (E ε εᵀ = σ_b² I):
///
/// - random walk: Σ_i Gᵢᵀφᵢ = −Σ_k S_kᵀ C_k w_k with the suffix sums S_k = Σ_{i≥k} Gᵢ = T − P_{k−1}
///   (T the total, P the prefix), so M_N = Σ_k N²Δt_k (T − P_{k−1})ᵀ(T − P_{k−1}), accumulated in
///   one pass from Σq, Σ q P and Σ q PᵀP;
/// - bias: Σ_i Gᵢᵀφᵢ = −(Σ_i Gᵢᵀ Dᵢ) ε with Dᵢ = Σ_{k≤i} C_k Δt_k, so M_b = σ_b² B Bᵀ.
///
/// (Earth rate's coupling −ω_ie×φ is left out: 1.5 % over 200 s.)
#[derive(Debug, Clone)]
struct InsTerm {
    model: InsErrorModel,
    last_t: Option<f64>,
    /// T = Σ Gᵢ (3 × p).
    total: [[f64; MAX_PARAMS]; 3],
    q_sum: f64,
    /// Σ q_k P_{k−1} (3 × p).
    u: [[f64; MAX_PARAMS]; 3],
    /// Σ q_k P_{k−1}ᵀ P_{k−1} (p × p, upper triangle).
    v: [[f64; MAX_PARAMS]; MAX_PARAMS],
    /// Dᵢ = Σ C_k Δt_k.
    d: Matrix3<f64>,
    /// B = Σ Gᵢᵀ Dᵢ (p × 3).
    b: [[f64; 3]; MAX_PARAMS],
}

impl InsTerm {
    fn new(model: InsErrorModel) -> Self {
        Self {
            model,
            last_t: None,
            total: [[0.0; MAX_PARAMS]; 3],
            q_sum: 0.0,
            u: [[0.0; MAX_PARAMS]; 3],
            v: [[0.0; MAX_PARAMS]; MAX_PARAMS],
            d: Matrix3::zeros(),
            b: [[0.0; 3]; MAX_PARAMS],
        }
    }

    /// Adds sample i at `t_s` with the INS attitude `n_from_s` and Gᵢ = `wh`.
    fn add(&mut self, p: usize, t_s: f64, n_from_s: &Matrix3<f64>, wh: &[[f64; MAX_PARAMS]; 3]) {
        if !self.model.is_some() {
            return;
        }
        // The first sample's interval is not known: the error before it is the offset's.
        let dt = self.last_t.map_or(0.0, |t| (t_s - t).max(0.0));
        self.last_t = Some(t_s);
        let q = self.model.random_walk_rad_per_sqrt_s.powi(2) * dt;
        if q > 0.0 {
            // P_{i−1} is the total before this sample.
            let t = &self.total;
            for r in 0..3 {
                for j in 0..p {
                    self.u[r][j] += q * t[r][j];
                }
            }
            for j in 0..p {
                for l in j..p {
                    self.v[j][l] += q * (t[0][j] * t[0][l] + t[1][j] * t[1][l] + t[2][j] * t[2][l]);
                }
            }
            self.q_sum += q;
        }
        self.d += n_from_s * dt;
        for r in 0..3 {
            for j in 0..p {
                self.total[r][j] += wh[r][j];
            }
        }
        if self.model.bias_sigma_rad_per_s > 0.0 {
            for j in 0..p {
                for c in 0..3 {
                    self.b[j][c] += (0..3).map(|r| wh[r][j] * self.d[(r, c)]).sum::<f64>();
                }
            }
        }
    }

    /// M (p × p) for the samples so far.
    fn covariance(&self, p: usize) -> DMatrix<f64> {
        let t = &self.total;
        let sb2 = self.model.bias_sigma_rad_per_s.powi(2);
        DMatrix::from_fn(p, p, |j, l| {
            let (a, c) = (j.min(l), j.max(l));
            let mut m = self.v[a][c];
            for r in 0..3 {
                m += self.q_sum * t[r][j] * t[r][l] - t[r][j] * self.u[r][l] - self.u[r][j] * t[r][l];
            }
            m + sb2 * (0..3).map(|k| self.b[j][k] * self.b[l][k]).sum::<f64>()
        })
    }

    /// A⁻¹ + A⁻¹MA⁻¹ from A⁻¹.
    fn widen(&self, a_inv: DMatrix<f64>) -> DMatrix<f64> {
        if !self.model.is_some() {
            return a_inv;
        }
        let m = self.covariance(a_inv.nrows());
        &a_inv + &a_inv * m * &a_inv
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
    /// RMS of the residuals outside the directions the encoders' noise acts in, rad (what the
    /// isotropic part of R must cover: the INS and the first-order model's error; NaN if not
    /// computed).
    pub isotropic_residual_rad: f64,
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
    /// The static Kalman filter (Jiang et al. 2017 eq. 29-33, first-order measurement model).
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
    /// The INS error the covariance allows for through the test.
    pub ins_error: InsErrorModel,
}

/// Exact residual of one sample for the table errors `err` (nav frame): the rotation from the known
/// attitude to the demodulated one.
pub(crate) fn exact_residual(
    chain: &Chain,
    err: &ErrorRotations,
    s: &Measurement,
    ref_inv: &Rot<B, N>,
) -> Vector3<f64> {
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
pub fn calibrate(
    chain: &Chain,
    known: &TableErrors,
    data: &Data,
    cfg: &CalibConfig,
    history: History,
    stop: &AtomicBool,
) -> Result<Calibration, CalibError> {
    let set = ParamSet::new(chain, cfg.nuisance);
    let p = set.len();
    if set.n_table == 0 || p > MAX_PARAMS {
        return Err(CalibError::Empty);
    }
    let (x0, s0) = set.prior(cfg);
    let x0 = DVector::from_vec(x0);
    let prior_info = DMatrix::from_diagonal(&DVector::from_iterator(p, s0.iter().map(|s| 1.0 / (s * s))));
    let n_from_b = data.n_from_b.matrix();
    let ref_inv = data.n_from_b.inverse();

    // The measurement z: the demodulation with the estimated parameters at zero.
    let before = chain.error_rotations(&set.without_estimated(known));
    let n = data.samples.len();
    let mut model = SampleModel::new();
    let mut sums = Normal::new();
    let mut snapshots = Thinned::new(match history {
        History::Snapshots(hz) => 1.0 / hz,
        _ => f64::INFINITY,
    });
    let mut ins = InsTerm::new(cfg.ins_error);
    data.samples.each(stop, &mut |s| {
        model.set(&set, chain, &n_from_b, s, data.tau(s.t_s), cfg);
        let z = exact_residual(chain, &before, s, &ref_inv);
        let wh = model.wh(p);
        sums.add(p, &model, &wh, &z, true);
        ins.add(p, s.t_s, &s.n_from_s.matrix(), &wh);
        if matches!(history, History::Snapshots(_)) && snapshots.wants(s.t_s) {
            let (a, b) = sums.assemble(p);
            // Early on the information can be singular: that snapshot is skipped.
            if let Ok((x, cov)) = solve(&(&prior_info + a), &(&prior_info * &x0 + b)) {
                let cov = ins.widen(cov);
                snapshots.push(
                    s.t_s,
                    Snapshot {
                        t_s: s.t_s,
                        theta: x.iter().copied().collect(),
                        sigma: cov.diagonal().iter().map(|v| v.max(0.0).sqrt()).collect(),
                    },
                );
            }
        }
    })?;
    let (data_information, rhs) = sums.assemble(p);
    let information = &prior_info + &data_information;
    let (x_kf, cov) = solve(&information, &(&prior_info * &x0 + rhs))?;
    let cov = ins.widen(cov);
    let chol = information.clone().cholesky().ok_or(CalibError::Singular)?;

    // Residuals of a parameter vector under the exact model, and the Gauss–Newton right-hand side
    // Σ HᵀR⁻¹r.
    let pass = |theta: &DVector<f64>| -> Result<(DVector<f64>, [f64; 3], f64), CalibError> {
        let t: Vec<f64> = theta.iter().copied().collect();
        let err = chain.error_rotations(&set.errors(&t, known));
        let mut g = Normal::new();
        let mut sq = [0.0; 3];
        let mut model = SampleModel::new();
        let (mut iso_sq, mut iso_dof) = (0.0, 0usize);
        data.samples.each(stop, &mut |s| {
            // H and R again rather than kept: 3·p numbers per sample would grow with the test.
            let tau = data.tau(s.t_s);
            model.set(&set, chain, &n_from_b, s, tau, cfg);
            let r = exact_residual(chain, &err, s, &ref_inv) - set.nuisance(&t, tau);
            for (k, q) in sq.iter_mut().enumerate() {
                *q += r[k] * r[k];
            }
            g.add(p, &model, &model.wh(p), &r, false);
            let (q, dof) = model.isotropic_part(&r);
            iso_sq += q;
            iso_dof += dof;
        })?;
        let nf = n.max(1) as f64;
        let iso = if iso_dof > 0 { (iso_sq / iso_dof as f64).sqrt() } else { f64::NAN };
        Ok((g.assemble(p).1, sq.map(|v| (v / nf).sqrt()), iso))
    };
    // The filter's residuals are reported, not needed by the estimate (the Monte Carlo skips them).
    let kf_rms = if history == History::Lean { [f64::NAN; 3] } else { pass(&x_kf)?.1 };
    let kf = Estimate {
        theta: x_kf.iter().copied().collect(),
        cov: cov.clone(),
        residual_rms_rad: kf_rms,
        isotropic_residual_rad: f64::NAN,
    };

    // Chord Gauss–Newton from the filter's estimate. The residuals are exact; the Jacobian is the
    // first-order H (relative error ~ the error angles, 1e-3), so each step gains ~3 digits.
    let mut theta = x_kf;
    let mut iterations = 0;
    let mut rms = kf_rms;
    let mut iso = f64::NAN;
    for _ in 0..8 {
        let (g, r, i) = pass(&theta)?;
        rms = r;
        iso = i;
        let step = chol.solve(&(g - &prior_info * (&theta - &x0)));
        theta += &step;
        iterations += 1;
        // Converged when every step is below 1e-4 of its parameter's 1σ (and 2e-7″): the next one
        // would change nothing a user could see.
        if step.iter().zip(cov.diagonal().iter()).take(set.n_table).all(|(d, v)| d.abs() < (1e-4 * v.sqrt()).max(1e-12))
        {
            break;
        }
    }
    let nls =
        Estimate { theta: theta.iter().copied().collect(), cov, residual_rms_rad: rms, isotropic_residual_rad: iso };
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
        ins_error: cfg.ins_error,
    })
}
