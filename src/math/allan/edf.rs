//! Equivalent degrees of freedom of every estimator in [`super::estimators`], and the noise type
//! they need, as NIST SP 1065 (Riley 2008, §5.2) prescribes and Stable32 does:
//!
//! - **Noise identification** by the lag-1 autocorrelation of the data at each averaging factor
//!   (Riley & Greenhall, "Power law noise identification using the lag 1 autocorrelation", EFTF
//!   2004): the phase decimated by m, a quadratic removed, differenced d times until
//!   δ = r₁/(1 + r₁) < 0.25; then α = 2 − 2(δ + d), rounded. It needs 30 points (m ≤ N/30);
//!   beyond, the last identified type is carried (said per τ).
//! - **EDF of the Allan and Hadamard families** (ADEV, OADEV, MDEV, TDEV, HDEV, OHDEV) by the
//!   general algorithm of Greenhall & Riley, "Uncertainty of stability variances based on finite
//!   differences" (PTTI 2003), eqs. 7-13 and Tables 1-3: exact sums where they are short, its
//!   asymptotic forms where they are long.
//! - **EDF of the total deviation**: b·(T/τ) − c with SP 1065 Table 7's (b, c) for white,
//!   flicker and random-walk frequency noise; for white and flicker phase noise (no entry in the
//!   table) the overlapping Allan variance's EDF, which TOTVAR equals at those noises' short τ.

use super::estimators::Estimator;

/// Terms summed exactly before Greenhall & Riley's asymptotic forms take over (their J_max).
const J_MAX: f64 = 100.0;

/// The power-law noise of a rate series S_y(f) ∝ f^α: +2 white phase, +1 flicker phase, 0 white
/// rate (frequency), −1 flicker rate, −2 random-walk rate (−3, −4 only for the Hadamard family).
pub type Alpha = i32;

/// The noise type's short name as clock people write it: WPM, FPM, WFM, FFM, RWFM (white and flicker
/// phase; white, flicker and random-walk frequency), FWFM, RRFM. For inertial sensors WFM is the
/// angle/velocity random walk, FFM the bias instability, RWFM the rate random walk.
#[must_use]
pub fn alpha_code(alpha: Alpha) -> &'static str {
    match alpha {
        2 => "WPM",
        1 => "FPM",
        0 => "WFM",
        -1 => "FFM",
        -2 => "RWFM",
        -3 => "FWFM",
        _ => "RRFM",
    }
}

/// Greenhall & Riley eq. 7: the generalized autocovariance kernel sw(t) of power-law noise α.
fn sw(t: f64, alpha: Alpha) -> f64 {
    let log_term = |p: i32| if t == 0.0 { 0.0 } else { t.powi(p) * t.abs().ln() };
    match alpha {
        2 => -t.abs(),
        1 => log_term(2),
        0 => t.abs().powi(3),
        -1 => log_term(4),
        -2 => t.abs().powi(5),
        -3 => log_term(6),
        _ => t.abs().powi(7),
    }
}

/// Eq. 8: the kernel after the averaging filter of factor F (F = ∞: no averaging beyond sampling).
fn sx(t: f64, f: Option<f64>, alpha: Alpha) -> f64 {
    match f {
        None => sw(t, alpha + 2),
        Some(f) => f * f * (2.0 * sw(t, alpha) - sw(t - 1.0 / f, alpha) - sw(t + 1.0 / f, alpha)),
    }
}

/// Eq. 9: the kernel after d-th differencing, Σ_k (−1)^k C(2d, d+k) sx(t + k).
fn sz(t: f64, f: Option<f64>, alpha: Alpha, d: u32) -> f64 {
    let c: &[f64] = match d {
        1 => &[2.0, -1.0],
        2 => &[6.0, -4.0, 1.0],
        _ => &[20.0, -15.0, 6.0, -1.0],
    };
    c[0] * sx(t, f, alpha)
        + (1..c.len()).map(|k| c[k] * (sx(t - k as f64, f, alpha) + sx(t + k as f64, f, alpha))).sum::<f64>()
}

/// Eq. 10: sz(0)² + (1 − J/M) sz(J/S)² + 2 Σ_{j<J} (1 − j/M) sz(j/S)².
fn basic_sum(j_terms: f64, m_terms: f64, s: f64, f: Option<f64>, alpha: Alpha, d: u32) -> f64 {
    let sq = |t: f64| sz(t, f, alpha, d).powi(2);
    let mut sum = sq(0.0) + (1.0 - j_terms / m_terms) * sq(j_terms / s);
    for j in 1..j_terms as u64 {
        sum += 2.0 * (1.0 - j as f64 / m_terms) * sq(j as f64 / s);
    }
    sum
}

/// Greenhall & Riley Table 1 (modified variances, r > d + 1): (a0, a1).
fn table1(alpha: Alpha, d: u32) -> Option<(f64, f64)> {
    let rows: [[Option<(f64, f64)>; 3]; 7] = [
        [Some((2.0 / 3.0, 1.0 / 3.0)), Some((7.0 / 9.0, 0.5)), Some((22.0 / 25.0, 2.0 / 3.0))],
        [Some((0.840, 0.345)), Some((0.997, 0.616)), Some((1.141, 0.843))],
        [Some((1.079, 0.368)), Some((1.033, 0.607)), Some((1.184, 0.848))],
        [None, Some((1.048, 0.534)), Some((1.180, 0.816))],
        [None, Some((1.302, 0.535)), Some((1.175, 0.777))],
        [None, None, Some((1.194, 0.703))],
        [None, None, Some((1.489, 0.702))],
    ];
    rows.get((2 - alpha) as usize)?[(d - 1) as usize]
}

/// Table 2 (unmodified variances, r > d + 1): (a0, a1).
fn table2(alpha: Alpha, d: u32) -> Option<(f64, f64)> {
    let rows: [[Option<(f64, f64)>; 3]; 7] = [
        [Some((1.5, 0.5)), Some((35.0 / 18.0, 1.0)), Some((231.0 / 100.0, 1.5))],
        [Some((78.6, 25.2)), Some((790.0, 410.0)), Some((9950.0, 6520.0))],
        [Some((2.0 / 3.0, 1.0 / 6.0)), Some((2.0 / 3.0, 1.0 / 3.0)), Some((7.0 / 9.0, 0.5))],
        [None, Some((0.852, 0.375)), Some((0.997, 0.617))],
        [None, Some((1.079, 0.368)), Some((1.033, 0.607))],
        [None, None, Some((1.053, 0.553))],
        [None, None, Some((1.302, 0.535))],
    ];
    rows.get((2 - alpha) as usize)?[(d - 1) as usize]
}

/// Table 3 (unmodified, flicker phase α = +1): (b0, b1).
fn table3(d: u32) -> (f64, f64) {
    [(6.0, 4.0), (15.23, 12.0), (47.8, 40.0)][(d - 1) as usize]
}

/// Greenhall & Riley's EDF of a variance built from d-th differences (d = 2 Allan, 3 Hadamard)
/// of `n` phase points at averaging factor m, for noise α; `overlapping` (stride 1 instead of m)
/// and `modified` (the phase averaged over m first: MVAR, TVAR). None where the variance is not
/// defined (α + 2d ≤ 1, or fewer points than one term needs).
#[must_use]
pub fn edf_greenhall(alpha: Alpha, d: u32, m: usize, n: usize, overlapping: bool, modified: bool) -> Option<f64> {
    if !(1..=3).contains(&d) || !(-4..=2).contains(&alpha) || alpha + 2 * d as i32 <= 1 || m == 0 {
        return None;
    }
    let mf = m as f64;
    let f = if modified { 1.0 } else { mf };
    let s = if overlapping { mf } else { 1.0 };
    let l = mf / f + mf * f64::from(d);
    if (n as f64) < l {
        return None;
    }
    let m_terms = 1.0 + (s * (n as f64 - l) / mf).floor();
    let j_terms = m_terms.min(f64::from(d + 1) * s);
    let r = m_terms / s;
    let dd = f64::from(d);
    let inv = if modified {
        if j_terms <= J_MAX {
            basic_sum(j_terms, m_terms, s, Some(1.0), alpha, d) / (sz(0.0, Some(1.0), alpha, d).powi(2) * m_terms)
        } else if r > dd + 1.0 {
            let (a0, a1) = table1(alpha, d)?;
            (a0 - a1 / r) / r
        } else {
            basic_sum(J_MAX, J_MAX, J_MAX / r, Some(1.0), alpha, d) / (sz(0.0, Some(1.0), alpha, d).powi(2) * J_MAX)
        }
    } else if alpha <= 0 {
        if j_terms <= J_MAX {
            // F = ∞: the phase sampled without averaging, which is what a series of increments
            // (or of rate samples) is. Greenhall & Riley take F = m when m(d+1) ≤ J_max, a
            // continuous-time model of the same noise seen through a τ0 average; for discrete
            // white FM it overstates the EDF at m = 1 by 17 % (800 instead of the exact 2M/3 = 682
            // for 1024 samples), where F = ∞ is exact (the test below).
            basic_sum(j_terms, m_terms, s, None, alpha, d) / (sz(0.0, None, alpha, d).powi(2) * m_terms)
        } else if r > dd + 1.0 {
            let (a0, a1) = table2(alpha, d)?;
            (a0 - a1 / r) / r
        } else {
            basic_sum(J_MAX, J_MAX, J_MAX / r, None, alpha, d) / (sz(0.0, None, alpha, d).powi(2) * J_MAX)
        }
    } else if alpha == 1 {
        if j_terms <= J_MAX {
            basic_sum(j_terms, m_terms, s, Some(mf), 1, d) / (sz(0.0, Some(mf), 1, d).powi(2) * m_terms)
        } else {
            let (b0, b1) = table3(d);
            let norm = (b0 + b1 * mf.ln()).powi(2);
            if r > dd + 1.0 {
                let (a0, a1) = table2(1, d)?;
                (a0 - a1 / r) / (norm * r)
            } else {
                let mp = J_MAX / r;
                basic_sum(J_MAX, J_MAX, mp, Some(mp), 1, d) / (norm * J_MAX)
            }
        }
    } else if r.ceil() <= dd {
        // White phase with few terms: the exact sum (the paper's K ≤ d branch).
        basic_sum(j_terms, m_terms, s, Some(mf), 2, d) / (sz(0.0, Some(mf), 2, d).powi(2) * m_terms)
    } else {
        let a0 = binomial(4 * d, 2 * d) / binomial(2 * d, d).powi(2);
        (a0 - dd / 2.0 / r) / m_terms
    };
    (inv.is_finite() && inv > 0.0).then(|| 1.0 / inv)
}

fn binomial(n: u32, k: u32) -> f64 {
    (0..k).fold(1.0, |acc, i| acc * f64::from(n - i) / f64::from(i + 1))
}

/// NIST SP 1065 Table 7: TOTVAR's EDF b·(T/τ) − c for white, flicker and random-walk FM, with
/// T/τ = (N − 1)/m for `n` phase points; other noises: the overlapping Allan variance's EDF.
#[must_use]
pub fn edf_totdev(alpha: Alpha, m: usize, n: usize) -> Option<f64> {
    let (b, c) = match alpha {
        0 => (1.50, 0.0),
        -1 => (1.17, 0.22),
        -2 => (0.93, 0.36),
        _ => return edf_greenhall(alpha, 2, m, n, true, false),
    };
    let edf = b * (n as f64 - 1.0) / m as f64 - c;
    (edf.is_finite() && m >= 1).then_some(edf.max(1.0))
}

impl Estimator {
    /// The EDF of this estimator at averaging factor m of `n` phase points for noise α (see the
    /// module's documentation); at least 1.
    #[must_use]
    pub fn edf(self, alpha: Alpha, m: usize, n: usize) -> Option<f64> {
        let alpha = alpha.clamp(self.lowest_alpha(), 2);
        let edf = match self {
            Self::Adev => edf_greenhall(alpha, 2, m, n, false, false),
            Self::Oadev => edf_greenhall(alpha, 2, m, n, true, false),
            Self::Mdev | Self::Tdev => edf_greenhall(alpha, 2, m, n, true, true),
            Self::Hdev => edf_greenhall(alpha, 3, m, n, false, false),
            Self::Ohdev => edf_greenhall(alpha, 3, m, n, true, false),
            Self::Totdev => edf_totdev(alpha, m, n),
        };
        edf.map(|e| e.max(1.0))
    }

    /// The most divergent noise the estimator converges for: −2 for the Allan family (second
    /// differences), −4 for the Hadamard family (third differences).
    #[must_use]
    pub fn lowest_alpha(self) -> Alpha {
        match self {
            Self::Hdev | Self::Ohdev => -4,
            _ => -2,
        }
    }

    /// Differences the noise identification may take before it stops (2 Allan, 3 Hadamard).
    fn id_max_differences(self) -> u32 {
        match self {
            Self::Hdev | Self::Ohdev => 3,
            _ => 2,
        }
    }
}

/// Fewest decimated points the lag-1 autocorrelation identification uses (Riley & Greenhall).
pub const NOISE_ID_MIN_POINTS: usize = 30;
/// Most decimated points it uses (the first ones of the record).
pub const NOISE_ID_MAX_POINTS: usize = 100_000;

/// The power-law noise of the phase `x` at averaging factor m by the lag-1 autocorrelation
/// (module docs), for `estimator` (which bounds the differencing); None with fewer than
/// [`NOISE_ID_MIN_POINTS`] decimated points.
#[must_use]
pub fn identify_noise(x: &[f64], m: usize, estimator: Estimator) -> Option<Alpha> {
    if m == 0 {
        return None;
    }
    // The first NOISE_ID_MAX_POINTS decimated points: r₁'s standard error is then 1/√n ≤ 0.003,
    // far inside the 0.25-wide decision bins, and the cost per τ is bounded.
    let mut z: Vec<f64> = x.iter().step_by(m).take(NOISE_ID_MAX_POINTS).copied().collect();
    if z.len() < NOISE_ID_MIN_POINTS {
        return None;
    }
    remove_quadratic(&mut z);
    let dmax = estimator.id_max_differences();
    let mut d = 0u32;
    loop {
        let r1 = lag1_autocorrelation(&z);
        let delta = r1 / (1.0 + r1);
        if delta < 0.25 || d >= dmax {
            let alpha = 2 - (2.0 * delta).round() as i32 - 2 * d as i32;
            return Some(alpha.clamp(estimator.lowest_alpha(), 2));
        }
        z = z.windows(2).map(|w| w[1] - w[0]).collect();
        d += 1;
        if z.len() < 3 {
            return None;
        }
    }
}

/// r₁ = Σ (z_k − z̄)(z_{k+1} − z̄) / Σ (z_k − z̄)² (0 for a constant series).
fn lag1_autocorrelation(z: &[f64]) -> f64 {
    let mean = z.iter().sum::<f64>() / z.len() as f64;
    let den: f64 = z.iter().map(|v| (v - mean).powi(2)).sum();
    if den == 0.0 {
        return 0.0;
    }
    z.windows(2).map(|w| (w[0] - mean) * (w[1] - mean)).sum::<f64>() / den
}

/// Subtracts the least-squares quadratic in the index (a frequency offset and a drift).
fn remove_quadratic(z: &mut [f64]) {
    let n = z.len() as f64;
    // Orthogonal polynomials on t = k − (n−1)/2: p0 = 1, p1 = t, p2 = t² − (n² − 1)/12.
    let c = (n - 1.0) / 2.0;
    let p2_shift = (n * n - 1.0) / 12.0;
    let (mut s0, mut s1, mut s2, mut n1, mut n2) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for (k, v) in z.iter().enumerate() {
        let t = k as f64 - c;
        let p2 = t * t - p2_shift;
        s0 += v;
        s1 += v * t;
        s2 += v * p2;
        n1 += t * t;
        n2 += p2 * p2;
    }
    let (a0, a1, a2) = (s0 / n, if n1 > 0.0 { s1 / n1 } else { 0.0 }, if n2 > 0.0 { s2 / n2 } else { 0.0 });
    for (k, v) in z.iter_mut().enumerate() {
        let t = k as f64 - c;
        *v -= a0 + a1 * t + a2 * (t * t - p2_shift);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::allan::estimators::phase_of_rates;
    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};

    /// Power-law noise of a rate series with α = 2 (white phase), 0 (white FM) or −2 (random-walk
    /// FM), returned as phase (N + 1 points).
    fn phase(alpha: Alpha, n: usize, rng: &mut rand_chacha::ChaCha8Rng) -> Vec<f64> {
        let w: Vec<f64> = (0..n).map(|_| StandardNormal.sample(rng)).collect();
        match alpha {
            2 => w,
            0 => phase_of_rates(&w, 1.0),
            -2 => phase_of_rates(&phase_of_rates(&w, 1.0), 1.0),
            _ => unreachable!("not generated"),
        }
    }

    /// Monte Carlo check of the EDF: over R independent series the variance estimates are
    /// σ²·χ²_ν/ν, so ν = 2·mean²/var. With R = 4000 the relative 1σ of that ν is about
    /// √(2/R)·(1 + 3/ν) ≈ 2.3 %; the band is 4σ (9.5 %) for Greenhall & Riley's algorithm (exact
    /// for Gaussian noise where it sums exactly, as here), 15 % for SP 1065 Table 7 (an empirical fit).
    #[test]
    fn the_edf_of_each_estimator_matches_a_monte_carlo_of_its_spread() {
        const R: usize = 4000;
        const N: usize = 1024;
        let cases: [(Estimator, Alpha, usize, f64); 13] = [
            (Estimator::Oadev, 0, 2, 0.095),
            (Estimator::Oadev, 0, 4, 0.095),
            (Estimator::Oadev, 0, 8, 0.095),
            (Estimator::Oadev, 0, 64, 0.095),
            (Estimator::Adev, 0, 8, 0.095),
            (Estimator::Oadev, -2, 16, 0.095),
            (Estimator::Oadev, 2, 4, 0.095),
            (Estimator::Mdev, 0, 8, 0.095),
            (Estimator::Mdev, 2, 4, 0.095),
            (Estimator::Ohdev, -2, 8, 0.095),
            (Estimator::Hdev, 0, 4, 0.095),
            (Estimator::Totdev, 0, 16, 0.15),
            (Estimator::Totdev, -2, 16, 0.15),
        ];
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(952);
        for (est, alpha, m, band) in cases {
            let vars: Vec<f64> =
                (0..R).map(|_| est.variance(&phase(alpha, N, &mut rng), 1.0, m).expect("defined").0).collect();
            let mean = vars.iter().sum::<f64>() / R as f64;
            let var = vars.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (R - 1) as f64;
            let mc = 2.0 * mean * mean / var;
            let edf = est.edf(alpha, m, N + 1).expect("defined");
            assert!(
                (edf / mc - 1.0).abs() < band,
                "{} α = {alpha} m = {m}: EDF {edf:.1} vs Monte Carlo {mc:.1}",
                est.name()
            );
        }
    }

    #[test]
    fn the_edf_of_white_fm_at_m_1_is_the_exact_two_thirds_of_the_terms() {
        // m = 1, white FM of unit variance: the M = N − 2 second differences d_k = y_{k+1} − y_k
        // have variance 2, lag-1 covariance −1 and no other, so E Σd² = 2M and (Gaussian)
        // Var Σd² = Σ_jk 2 Cov(d_j, d_k)² = 2(4M + 2(M − 1)); ν = 2(E)²/Var = 4M²/(6M − 2) ≈ 2M/3.
        let n = 1025;
        let m_terms = (n - 2) as f64;
        let exact = 4.0 * m_terms * m_terms / (6.0 * m_terms - 2.0);
        let got = Estimator::Oadev.edf(0, 1, n).expect("defined");
        assert!((got / exact - 1.0).abs() < 1e-9, "EDF {got} vs exact {exact}");
        // And SP 1065 Table 5's simple formula, an approximation of the same, within 1 %.
        let simple = crate::math::allan::edf_overlapping(n - 1, 1, crate::math::allan::NoiseType::WhiteRate);
        assert!((got / simple - 1.0).abs() < 0.01, "EDF {got} vs SP 1065 {simple}");
    }

    #[test]
    fn the_lag1_autocorrelation_names_each_power_law() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(2004);
        for alpha in [2, 0, -2] {
            let x = phase(alpha, 4096, &mut rng);
            for m in [1, 8, 64] {
                assert_eq!(identify_noise(&x, m, Estimator::Oadev), Some(alpha), "α = {alpha}, m = {m}");
            }
            assert_eq!(identify_noise(&x, 4096 / 29 + 2, Estimator::Oadev), None, "29 points");
        }
    }
}
