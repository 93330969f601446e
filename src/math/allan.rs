//! Allan deviation of inertial-sensor increments the way the field reads it (IEEE Std 952-1997
//! Annex C for gyros, IEEE Std 1293-1998 Annex for accelerometers): the overlapping estimator, its
//! confidence interval from the equivalent degrees of freedom (NIST SP 1065), and the five noise
//! coefficients Q, N, B, K, R read off the curve (docs/allan.md).
//!
//! Input: increments (Δθ in rad, or Δv in m/s) every `tau0_s`, gathered into their cumulative sum
//! θ ([`Phase`], θ_0 = 0, N + 1 points for N samples). The "rate" is increment / τ0 (rad/s or m/s²)
//! and every deviation here is of the rate, in SI (the `_si` fields); conventional units are the
//! caller's business (`crate::math::units`).
//!
//! Estimator: σ²(τ = mτ0) = Σ_k (θ_{k+2m} − 2θ_{k+m} + θ_k)² / (2τ²(N + 1 − 2m)), k = 0..=N−2m —
//! fully overlapping, O(N) per τ from the cumulative sums. Cluster sizes stop at m ≤ N / 4 by
//! default (at least four non-overlapping clusters).
//!
//! Confidence: EDF per noise type from the simple formulas of Howe, Allan & Barnes (1981) for the
//! overlapping estimator (NIST SP 1065 Table 5, [`edf_overlapping`]); at each τ the fitted terms'
//! EDFs are mixed ([`fit_noise_model`]); the interval is σ·√(ν/χ²) with Wilson–Hilferty χ²
//! quantiles ([`chi2_quantile`]), ±1σ (68.3 %) by default.
//!
//! Coefficients: weighted non-negative least squares of σ²(τ) = 3Q²/τ² + N²/τ + (2 ln2/π)B² +
//! K²τ/3 + R²τ²/2 with model selection (the primary estimate, [`fit_noise_model`]), and the classic
//! slope-line readings (secondary, [`slope_readings`]).

use serde::{Deserialize, Serialize};

pub mod edf;
pub mod estimators;
mod fit;
#[cfg(test)]
mod tests;

pub use fit::{
    CLAIM_Z, Contradiction, NoiseFit, SIGNIFICANCE_Z, SLOPE_MATCH_TOLERANCE, SlopeReading, SlopeReadings, check_claims,
    fit_noise_model, slope_readings,
};

/// Fewest samples [`allan_curve`] accepts.
pub const MIN_SAMPLES: usize = 16;
/// Flicker floor factor: σ_min = B·√(2 ln2 / π) ≈ 0.664·B (IEEE 952 C.1.3).
pub const FLICKER_FLOOR: f64 = 0.664_282_943_346_9;

/// Bad input to the Allan analysis.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AllanError {
    /// Too short a series.
    #[error("{got} samples given, at least {min} needed")]
    TooFewSamples {
        /// Samples given.
        got: usize,
        /// Samples needed.
        min: usize,
    },
    /// A NaN or an infinity among the increments.
    #[error("sample {index} is not finite ({value})")]
    NonFinite {
        /// Index of the first bad sample.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// The sample interval is not a positive number.
    #[error("the sample interval must be finite and > 0 s (got {0} s)")]
    BadTau0(f64),
    /// An option out of its range.
    #[error("invalid option: {0}")]
    BadOption(&'static str),
}

/// Which cluster sizes m (τ = m·τ0) to evaluate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum TauSpacing {
    /// m = 1, 2, 3, ... (every averaging factor; Stable32's and allantools' "all").
    All,
    /// m = 1, 2, 4, 8, ...
    Octave,
    /// m = 1, 2, 4, 10, 20, 40, 100, ... (allantools' "decade", Stable32's spacing).
    Decade,
    /// m = round(10^(i/n)), i = 0, 1, ..., duplicates removed.
    PerDecade(u32),
    /// Exactly these m (sorted, deduplicated, those above the limit dropped).
    Explicit(Vec<usize>),
}

/// Options of [`analyze`] and [`allan_curve`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AllanOptions {
    /// The cluster sizes.
    pub spacing: TauSpacing,
    /// m ≤ N / min_clusters (≥ 2; default 4).
    pub min_clusters: usize,
    /// Half-width of the confidence interval in standard-normal units (1.0: 68.27 % two-sided), in (0, 3].
    pub ci_sigma: f64,
}

impl Default for AllanOptions {
    fn default() -> Self {
        Self { spacing: TauSpacing::Octave, min_clusters: 4, ci_sigma: 1.0 }
    }
}

/// The cumulative sum θ of a series of increments, built one sample at a time (θ_0 = 0): what the
/// estimator needs, 8 bytes per sample. Each increment is taken relative to the first one (a linear
/// trend in θ, which the second differences cancel), so θ stays small and the sums stay exact to
/// ~ε·|θ|·√(2m) whatever the bias or the Earth rate in the signal.
#[derive(Debug, Clone, Default)]
pub struct Phase {
    theta: Vec<f64>,
    reference: Option<f64>,
    running: f64,
    bad: Option<(usize, f64)>,
}

impl Phase {
    /// An empty series with room for `n` increments.
    #[must_use]
    pub fn with_capacity(n: usize) -> Self {
        let mut theta = Vec::with_capacity(n + 1);
        theta.push(0.0);
        Self { theta, reference: None, running: 0.0, bad: None }
    }

    /// The series of `increments`.
    #[must_use]
    pub fn from_increments(increments: &[f64]) -> Self {
        let mut p = Self::with_capacity(increments.len());
        for &x in increments {
            p.push(x);
        }
        p
    }

    /// Appends one increment (a non-finite one is remembered and reported by [`allan_curve`]).
    #[inline]
    pub fn push(&mut self, increment: f64) {
        if self.theta.is_empty() {
            self.theta.push(0.0);
        }
        if !increment.is_finite() {
            if self.bad.is_none() {
                self.bad = Some((self.theta.len() - 1, increment));
            }
            self.theta.push(self.running);
            return;
        }
        let r = *self.reference.get_or_insert(increment);
        self.running += increment - r;
        self.theta.push(self.running);
    }

    /// Number of increments.
    #[must_use]
    pub fn len(&self) -> usize {
        self.theta.len().saturating_sub(1)
    }

    /// No increments yet.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The phase: N + 1 cumulative sums (θ_0 = 0) of the increments taken relative to the first
    /// one (a linear trend removed, which every estimator here cancels).
    #[must_use]
    pub fn points(&self) -> &[f64] {
        &self.theta
    }

    /// The first non-finite increment, if any (its index and value).
    #[must_use]
    pub fn first_bad(&self) -> Option<(usize, f64)> {
        self.bad
    }

    /// The first increment, which every other one is taken relative to.
    #[must_use]
    pub fn reference(&self) -> f64 {
        self.reference.unwrap_or(0.0)
    }
}

/// Raw Allan variance curve of one channel (no EDF, no fit).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AllanCurve {
    /// Sample interval, s.
    pub tau0_s: f64,
    /// Number of increments N.
    pub n_samples: usize,
    /// Cluster sizes m.
    pub m: Vec<usize>,
    /// Cluster times τ = m·τ0, s.
    pub taus_s: Vec<f64>,
    /// Allan variance of the rate ((rad/s)² or (m/s²)²).
    pub avar_si: Vec<f64>,
    /// Number of second differences averaged (N + 1 − 2m).
    pub n_terms: Vec<usize>,
}

/// Cluster sizes for `n_samples` increments under `spacing`, limited to 1 ≤ m ≤ n_samples / min_clusters.
///
/// # Errors
/// [`AllanError::BadOption`] if `min_clusters < 2` or `PerDecade(0)`.
pub fn cluster_sizes(n_samples: usize, spacing: &TauSpacing, min_clusters: usize) -> Result<Vec<usize>, AllanError> {
    if min_clusters < 2 {
        return Err(AllanError::BadOption("min_clusters must be >= 2"));
    }
    averaging_factors(n_samples / min_clusters, spacing)
}

/// The averaging factors 1 ≤ m ≤ `m_max` of `spacing`, sorted, without duplicates.
///
/// # Errors
/// [`AllanError::BadOption`] for `PerDecade(0)`.
pub fn averaging_factors(m_max: usize, spacing: &TauSpacing) -> Result<Vec<usize>, AllanError> {
    let mut ms: Vec<usize> = match spacing {
        TauSpacing::All => (1..=m_max).collect(),
        TauSpacing::Octave => {
            std::iter::successors(Some(1usize), |&m| m.checked_mul(2)).take_while(|&m| m <= m_max).collect()
        }
        TauSpacing::Decade => std::iter::successors(Some(1usize), |&d| d.checked_mul(10))
            .take_while(|&d| d <= m_max)
            .flat_map(|d| [d, 2 * d, 4 * d])
            .filter(|&m| m <= m_max)
            .collect(),
        TauSpacing::PerDecade(0) => return Err(AllanError::BadOption("points per decade must be >= 1")),
        TauSpacing::PerDecade(n) => (0u32..)
            .map(|i| 10f64.powf(f64::from(i) / f64::from(*n)).round())
            .take_while(|&m| m <= m_max as f64)
            .map(|m| m as usize)
            .collect(),
        TauSpacing::Explicit(v) => v.iter().copied().filter(|&m| m >= 1 && m <= m_max).collect(),
    };
    ms.sort_unstable();
    ms.dedup();
    Ok(ms)
}

/// Σ (c_k − 2b_k + a_k)² over equal-length slices, in 8 independent lanes (the compiler vectorises them).
fn sum_sq_second_diff(a: &[f64], b: &[f64], c: &[f64]) -> f64 {
    let (a8, ar) = a.as_chunks::<8>();
    let (b8, br) = b.as_chunks::<8>();
    let (c8, cr) = c.as_chunks::<8>();
    let mut acc = [0.0f64; 8];
    for ((x, y), z) in a8.iter().zip(b8).zip(c8) {
        for (((s, &xi), &yi), &zi) in acc.iter_mut().zip(x).zip(y).zip(z) {
            let d = zi - 2.0 * yi + xi;
            *s += d * d;
        }
    }
    let mut rest = 0.0;
    for ((&xi, &yi), &zi) in ar.iter().zip(br).zip(cr) {
        let d = zi - 2.0 * yi + xi;
        rest += d * d;
    }
    ((acc[0] + acc[1]) + (acc[2] + acc[3])) + ((acc[4] + acc[5]) + (acc[6] + acc[7])) + rest
}

/// Σ (d_k − 3c_k + 3b_k − a_k)² over equal-length slices (third differences), 8 lanes as above.
fn sum_sq_third_diff(a: &[f64], b: &[f64], c: &[f64], d: &[f64]) -> f64 {
    let (a8, ar) = a.as_chunks::<8>();
    let (b8, br) = b.as_chunks::<8>();
    let (c8, cr) = c.as_chunks::<8>();
    let (d8, dr) = d.as_chunks::<8>();
    let mut acc = [0.0f64; 8];
    for (((w, x), y), z) in a8.iter().zip(b8).zip(c8).zip(d8) {
        for l in 0..8 {
            let v = z[l] - 3.0 * y[l] + 3.0 * x[l] - w[l];
            acc[l] += v * v;
        }
    }
    let mut rest = 0.0;
    for (((&w, &x), &y), &z) in ar.iter().zip(br).zip(cr).zip(dr) {
        let v = z - 3.0 * y + 3.0 * x - w;
        rest += v * v;
    }
    ((acc[0] + acc[1]) + (acc[2] + acc[3])) + ((acc[4] + acc[5]) + (acc[6] + acc[7])) + rest
}

/// For each m of `ms`: Σ_k (θ_{k+2m} − 2θ_{k+m} + θ_k)², k = 0..N+1−2m, and the number of terms.
/// Summed per block of 16 384 terms (partial sums keep the rounding small). Cluster sizes up to
/// 2048 share one pass over θ (each block of θ stays in cache for all of them); larger ones get
/// their own pass.
fn second_difference_sums(theta: &[f64], ms: &[usize]) -> Vec<(f64, usize)> {
    const BLOCK: usize = 16_384;
    const FUSED_MAX_M: usize = 2048;
    let terms = |m: usize| theta.len() - 2 * m;
    let mut out: Vec<(f64, usize)> = ms.iter().map(|&m| (0.0, terms(m))).collect();
    let block_sum = |m: usize, k0: usize, k1: usize| {
        sum_sq_second_diff(&theta[k0..k1], &theta[k0 + m..k1 + m], &theta[k0 + 2 * m..k1 + 2 * m])
    };
    let most = ms.iter().map(|&m| terms(m)).max().unwrap_or(0);
    for k0 in (0..most).step_by(BLOCK) {
        for (o, &m) in out.iter_mut().zip(ms).filter(|(_, m)| **m <= FUSED_MAX_M) {
            if k0 < o.1 {
                o.0 += block_sum(m, k0, (k0 + BLOCK).min(o.1));
            }
        }
    }
    for (o, &m) in out.iter_mut().zip(ms).filter(|(_, m)| **m > FUSED_MAX_M) {
        o.0 = (0..o.1).step_by(BLOCK).map(|k0| block_sum(m, k0, (k0 + BLOCK).min(o.1))).sum();
    }
    out
}

/// Overlapping Allan variance of the rate of `phase` (increments every `tau0_s` seconds).
///
/// # Errors
/// Too few samples, a non-finite sample (its index), a bad `tau0_s` or options.
pub fn allan_curve(phase: &Phase, tau0_s: f64, opts: &AllanOptions) -> Result<AllanCurve, AllanError> {
    if !(tau0_s.is_finite() && tau0_s > 0.0) {
        return Err(AllanError::BadTau0(tau0_s));
    }
    if !(opts.ci_sigma > 0.0 && opts.ci_sigma <= 3.0) {
        return Err(AllanError::BadOption("the confidence half-width must be in (0, 3] sigma"));
    }
    if let Some((index, value)) = phase.bad {
        return Err(AllanError::NonFinite { index, value });
    }
    let n = phase.len();
    let min = MIN_SAMPLES.max(2 * opts.min_clusters);
    if n < min {
        return Err(AllanError::TooFewSamples { got: n, min });
    }
    let ms = cluster_sizes(n, &opts.spacing, opts.min_clusters)?;
    let mut curve =
        AllanCurve { tau0_s, n_samples: n, m: ms.clone(), taus_s: vec![], avar_si: vec![], n_terms: vec![] };
    for (&m, (s, terms)) in ms.iter().zip(second_difference_sums(&phase.theta, &ms)) {
        let tau = m as f64 * tau0_s;
        curve.taus_s.push(tau);
        curve.avar_si.push(s / (2.0 * tau * tau * terms as f64));
        curve.n_terms.push(terms);
    }
    Ok(curve)
}

/// Power-law noise type, for the EDF (α = exponent of the rate PSD S(f) ∝ f^α; in the clock
/// literature the rate is "frequency" and the angle "phase").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum NoiseType {
    /// α = +2 (quantization: white angle noise).
    WhitePhase,
    /// α = +1.
    FlickerPhase,
    /// α = 0 (angle / velocity random walk).
    WhiteRate,
    /// α = −1 (bias instability).
    FlickerRate,
    /// α = −2 (rate random walk; also used for the rate ramp).
    RandomWalkRate,
}

/// Equivalent degrees of freedom of the overlapping Allan variance of `n_samples` increments
/// (N_x = n_samples + 1 phase points) at cluster size m: the simple approximations of Howe, Allan
/// & Barnes (1981) as tabulated in NIST SP 1065 (Riley 2008) Table 5. Flicker rate at m = 1 uses
/// 2(N−2)²/(2.3N−4.9). Clamped to [1, N_x − 2m].
#[must_use]
pub fn edf_overlapping(n_samples: usize, m: usize, noise: NoiseType) -> f64 {
    let n = n_samples as f64 + 1.0;
    let mf = m as f64;
    let edf = match noise {
        NoiseType::WhitePhase => (n + 1.0) * (n - 2.0 * mf) / (2.0 * (n - mf)),
        NoiseType::FlickerPhase => {
            let p = ((n - 1.0) / (2.0 * mf)).ln() * ((2.0 * mf + 1.0) * (n - 1.0) / 4.0).ln();
            if p > 0.0 { p.sqrt().exp() } else { 1.0 }
        }
        NoiseType::WhiteRate => {
            (3.0 * (n - 1.0) / (2.0 * mf) - 2.0 * (n - 2.0) / n) * (4.0 * mf * mf / (4.0 * mf * mf + 5.0))
        }
        NoiseType::FlickerRate if m == 1 => 2.0 * (n - 2.0) * (n - 2.0) / (2.3 * n - 4.9),
        NoiseType::FlickerRate => 5.0 * n * n / (4.0 * mf * (n + 3.0 * mf)),
        NoiseType::RandomWalkRate => {
            (n - 2.0) / mf * ((n - 1.0).powi(2) - 3.0 * mf * (n - 1.0) + 4.0 * mf * mf) / (n - 3.0).powi(2)
        }
    };
    let max = (n - 2.0 * mf).max(1.0);
    if edf.is_finite() { edf.clamp(1.0, max) } else { 1.0 }
}

/// Chi-squared quantile for `nu` degrees of freedom at the standard-normal quantile `z` (z = +1:
/// p = 0.8413), by Wilson & Hilferty (1931): χ²_p ≈ ν (1 − 2/(9ν) + z √(2/(9ν)))³. Within 0.5 % of
/// tabulated values for ν ≥ 10 (tested); for ν of a few units the lower tail is too small (ν = 1,
/// z = −1: 0.029 vs 0.040), i.e. upper bounds are conservative. The cube base is floored at 1e-3.
#[must_use]
pub fn chi2_quantile(nu: f64, z: f64) -> f64 {
    let h = 2.0 / (9.0 * nu);
    nu * (1.0 - h + z * h.sqrt()).max(1e-3).powi(3)
}

/// Confidence interval (lower, upper) of a deviation `adev` (any unit) with `edf` degrees of freedom
/// at ±`z` normal sigmas (NIST SP 1065 eq. 45: σ²ν/χ²), in the unit of `adev`.
#[must_use]
pub fn adev_confidence(adev: f64, edf: f64, z: f64) -> (f64, f64) {
    let nu = edf.max(1.0);
    (adev * (nu / chi2_quantile(nu, z)).sqrt(), adev * (nu / chi2_quantile(nu, -z)).sqrt())
}

/// Analytic Allan variance at τ (s) of a stationary first-order Gauss–Markov rate of standard
/// deviation `sigma_si` and correlation time T (s):
/// σ²(τ) = σ²(T/τ)(2 − (T/τ)(3 − 4e^{−τ/T} + e^{−2τ/T})) (IEEE 952-1997 C.1.6; → 2σ²T/τ for τ ≫ T,
/// → (2/3)σ²τ/T for τ ≪ T; a series for τ/T < 0.01, where the closed form cancels).
#[must_use]
pub fn gauss_markov_avar(sigma_si: f64, correlation_time_s: f64, tau_s: f64) -> f64 {
    let x = tau_s / correlation_time_s;
    let f = if x < 1e-2 {
        // f(x) = −Σ_{n≥3} (−x)^n (2^n − 4) / (n! x²)
        let (mut sum, mut pow, mut fact) = (0.0, -x, 1.0);
        for n in 1..=14 {
            fact *= f64::from(n);
            if n >= 3 {
                sum -= pow * (2f64.powi(n) - 4.0) / fact;
            }
            pow *= -x;
        }
        sum / (x * x)
    } else {
        (2.0 - (3.0 - 4.0 * (-x).exp() + (-2.0 * x).exp()) / x) / x
    };
    sigma_si * sigma_si * f
}

/// The five IEEE 952 / 1293 power-law terms of σ²(τ).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum NoiseTerm {
    /// Q: σ² = 3Q²/τ² (ADEV slope −1).
    Quantization,
    /// N: σ² = N²/τ (slope −1/2).
    RandomWalk,
    /// B: σ² = (2 ln2/π) B² (slope 0).
    BiasInstability,
    /// K: σ² = K²τ/3 (slope +1/2).
    RateRandomWalk,
    /// R: σ² = R²τ²/2 (slope +1).
    RateRamp,
}

/// All terms, in order of increasing τ exponent.
pub const TERMS: [NoiseTerm; 5] = [
    NoiseTerm::Quantization,
    NoiseTerm::RandomWalk,
    NoiseTerm::BiasInstability,
    NoiseTerm::RateRandomWalk,
    NoiseTerm::RateRamp,
];

impl NoiseTerm {
    /// Exponent p of τ in σ²(τ) (−2..=2); the ADEV slope is p/2.
    #[must_use]
    pub fn exponent(self) -> i32 {
        self as i32 - 2
    }

    /// Factor a in σ²(τ) = a·c²·τ^p for the coefficient c.
    #[must_use]
    pub fn avar_factor(self) -> f64 {
        [3.0, 1.0, FLICKER_FLOOR * FLICKER_FLOOR, 1.0 / 3.0, 0.5][self as usize]
    }

    /// The noise type whose EDF applies where this term dominates.
    #[must_use]
    pub fn noise_type(self) -> NoiseType {
        [
            NoiseType::WhitePhase,
            NoiseType::WhiteRate,
            NoiseType::FlickerRate,
            NoiseType::RandomWalkRate,
            NoiseType::RandomWalkRate,
        ][self as usize]
    }

    /// Contribution a·c²·τ^p of the coefficient c (SI) to σ² at τ (s).
    #[must_use]
    pub fn avar(self, coefficient_si: f64, tau_s: f64) -> f64 {
        self.avar_factor() * coefficient_si * coefficient_si * tau_s.powi(self.exponent())
    }

    /// The letter of the standard (Q, N, B, K, R).
    #[must_use]
    pub fn letter(self) -> &'static str {
        ["Q", "N", "B", "K", "R"][self as usize]
    }

    /// The ADEV slope as a reader writes it.
    #[must_use]
    pub fn slope_text(self) -> &'static str {
        ["-1", "-1/2", "0", "+1/2", "+1"][self as usize]
    }
}

/// A fitted value with its 1σ uncertainty, in the unit its field name states.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Estimate {
    /// The value.
    pub value: f64,
    /// 1σ; for a coefficient fitted to zero, the 1σ detection limit.
    pub sigma: f64,
    /// The fit found the term (see [`fit_noise_model`] for the rule).
    pub significant: bool,
}

impl Estimate {
    /// The estimate in another unit (`f` of the new unit per old unit).
    #[must_use]
    pub fn scaled(self, f: f64) -> Self {
        Self { value: self.value * f, sigma: self.sigma * f, ..self }
    }
}

/// The IEEE coefficients in SI. Gyro: Q rad, N rad/√s, B rad/s, K rad/s/√s, R rad/s².
/// Accelerometer: Q m/s, N m/s/√s, B m/s², K m/s²/√s, R m/s³.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct NoiseCoefficients {
    /// Quantization.
    pub q_si: Estimate,
    /// Angle / velocity random walk.
    pub n_si: Estimate,
    /// Bias instability.
    pub b_si: Estimate,
    /// Rate / acceleration random walk.
    pub k_si: Estimate,
    /// Rate / acceleration ramp.
    pub r_si: Estimate,
}

impl NoiseCoefficients {
    /// The estimate of one term.
    #[must_use]
    pub fn get(&self, term: NoiseTerm) -> Estimate {
        [self.q_si, self.n_si, self.b_si, self.k_si, self.r_si][term as usize]
    }

    /// The terms the fit found.
    #[must_use]
    pub fn significant_terms(&self) -> Vec<NoiseTerm> {
        TERMS.into_iter().filter(|&t| self.get(t).significant).collect()
    }

    /// The fitted model's Allan variance at τ (s): the sum of the significant terms.
    #[must_use]
    pub fn avar(&self, tau_s: f64) -> f64 {
        TERMS.iter().filter(|t| self.get(**t).significant).map(|t| t.avar(self.get(*t).value, tau_s)).sum()
    }
}

/// The whole Allan analysis of one channel.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AllanReport {
    /// Sample interval, s.
    pub tau0_s: f64,
    /// Number of increments.
    pub n_samples: usize,
    /// Cluster times, s.
    pub taus_s: Vec<f64>,
    /// Allan deviation of the rate (rad/s or m/s²).
    pub adev_si: Vec<f64>,
    /// Lower confidence bound at −`ci_sigma` (rad/s or m/s²).
    pub adev_lower_si: Vec<f64>,
    /// Upper confidence bound at +`ci_sigma` (rad/s or m/s²).
    pub adev_upper_si: Vec<f64>,
    /// Number of overlapping second differences per τ.
    pub n_terms: Vec<usize>,
    /// Equivalent degrees of freedom per τ of the fitted noise mixture.
    pub edf: Vec<f64>,
    /// Largest fitted term per τ.
    pub dominant: Vec<NoiseTerm>,
    /// Weighted-NNLS coefficients (the primary estimate).
    pub fit: NoiseCoefficients,
    /// Weighted residual sum of squares per degree of freedom of the fit.
    pub fit_chi2_per_dof: f64,
    /// Where the data contradict a term (then not reported as found) or every IEEE combination.
    #[serde(default)]
    pub fit_contradictions: Vec<Contradiction>,
    /// Slope-line readings (the secondary estimate).
    pub slope: SlopeReadings,
}

/// Allan analysis of one channel: curve, fit, EDF, confidence intervals, slope readings.
///
/// # Errors
/// See [`allan_curve`].
pub fn analyze(phase: &Phase, tau0_s: f64, opts: &AllanOptions) -> Result<AllanReport, AllanError> {
    let curve = allan_curve(phase, tau0_s, opts)?;
    let fit = fit_noise_model(&curve);
    let adev_si: Vec<f64> = curve.avar_si.iter().map(|v| v.sqrt()).collect();
    let (lo, hi): (Vec<f64>, Vec<f64>) =
        adev_si.iter().zip(&fit.edf).map(|(&s, &e)| adev_confidence(s, e, opts.ci_sigma)).unzip();
    let slope = slope_readings(&curve.taus_s, &adev_si, &lo, &hi);
    Ok(AllanReport {
        tau0_s,
        n_samples: curve.n_samples,
        taus_s: curve.taus_s,
        adev_si,
        adev_lower_si: lo,
        adev_upper_si: hi,
        n_terms: curve.n_terms,
        edf: fit.edf,
        dominant: fit.dominant,
        fit: fit.coefficients,
        fit_chi2_per_dof: fit.chi2_per_dof,
        fit_contradictions: fit.contradictions,
        slope,
    })
}
