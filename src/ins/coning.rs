//! Coning-compensated attitude algorithms of the family of Li et al. 2014 eq. (1): the rotation vector
//! over one update of N gyro samples, using P samples of the previous update,
//!
//! ```text
//! ΔΦ = Σ Δθ_i + Σ_{m=1-P}^{N-1} K_m (Δθ_m × Δθ_N)
//! ```
//!
//! The coefficients are derived here (the seed's Table 1 is garbled in signs and indices) by making
//! the algorithm's coning error vanish to the highest order under pure coning (docs/coning.md):
//! `Σ_r K_r [(r+1)^{2k+1} + (r-1)^{2k+1} - 2 r^{2k+1}] = N^{2k+1} / 2`, k = 1..N+P-1, r = N - m.

/// The algorithms the issue asks for, by name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Algorithm {
    /// One sample per update, no coning term: the plain quaternion update.
    SingleSample,
    /// Two samples, K = 2/3.
    TwoSample,
    /// Two samples and one previous sample (Li et al. 2014's choice).
    TwoSampleP1,
    /// Two samples and two previous samples.
    TwoSampleP2,
    /// Three samples.
    ThreeSample,
}

impl Algorithm {
    /// Every algorithm, in display order.
    pub const ALL: [Self; 5] =
        [Self::SingleSample, Self::TwoSample, Self::TwoSampleP1, Self::TwoSampleP2, Self::ThreeSample];

    /// (N, P).
    #[must_use]
    pub fn n_p(self) -> (usize, usize) {
        match self {
            Self::SingleSample => (1, 0),
            Self::TwoSample => (2, 0),
            Self::TwoSampleP1 => (2, 1),
            Self::TwoSampleP2 => (2, 2),
            Self::ThreeSample => (3, 0),
        }
    }

    /// The config and recording name.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::SingleSample => "single-sample",
            Self::TwoSample => "two-sample",
            Self::TwoSampleP1 => "two-sample-p1",
            Self::TwoSampleP2 => "two-sample-p2",
            Self::ThreeSample => "three-sample",
        }
    }

    /// Parses a config name.
    #[must_use]
    pub fn from_name(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|a| a.name() == s)
    }
}

/// Coefficients K_m, m = 1-P ..= N-1 (index 0 is m = 1-P), solving the order conditions.
#[must_use]
pub fn coefficients(n: usize, p: usize) -> Vec<f64> {
    let count = n + p - 1;
    if count == 0 {
        return Vec::new();
    }
    // Unknown j corresponds to m = 1 - P + j, i.e. r = N - m.
    let r_of = |j: usize| (n as i64 - (1 - p as i64 + j as i64)) as f64;
    let mut a = vec![vec![0.0; count + 1]; count];
    for (row, k) in (1..=count).enumerate() {
        let e = (2 * k + 1) as i32;
        for j in 0..count {
            let r = r_of(j);
            a[row][j] = (r + 1.0).powi(e) + (r - 1.0).powi(e) - 2.0 * r.powi(e);
        }
        a[row][count] = 0.5 * (n as f64).powi(e);
    }
    // Gauss-Jordan with partial pivoting (tiny, well-conditioned systems).
    for i in 0..count {
        let pivot = (i..count).max_by(|&x, &y| a[x][i].abs().total_cmp(&a[y][i].abs())).unwrap_or(i);
        a.swap(i, pivot);
        for r in 0..count {
            if r != i {
                let f = a[r][i] / a[i][i];
                for c in i..=count {
                    a[r][c] -= f * a[i][c];
                }
            }
        }
    }
    (0..count).map(|i| a[i][count] / a[i][i]).collect()
}

/// Exact coning error of the algorithm per update, divided by sin²(cone half-angle), for pure
/// coning at `lambda` = cone angular frequency × gyro sample interval (rad):
/// `ε/sin²α = ½(Nλ − sin Nλ) − 2(1 − cos λ) Σ_r K_r sin(rλ)`.
/// Positive: the computed attitude lags the true one about the cone axis.
#[must_use]
pub fn coning_error_per_update(n: usize, p: usize, k: &[f64], lambda: f64) -> f64 {
    let nl = n as f64 * lambda;
    let mut correction = 0.0;
    for (j, kj) in k.iter().enumerate() {
        let r = n as f64 - (1.0 - p as f64 + j as f64);
        correction += kj * (r * lambda).sin();
    }
    0.5 * (nl - nl.sin()) - 2.0 * (1.0 - lambda.cos()) * correction
}

/// Drift rate about the cone axis, rad/s, of an algorithm under pure coning of half-angle `alpha`
/// at `freq_hz`, with gyro samples every `sample_s` seconds (the formula the tests check against).
#[must_use]
pub fn coning_drift_rate(algorithm: Algorithm, alpha_rad: f64, freq_hz: f64, sample_s: f64) -> f64 {
    let (n, p) = algorithm.n_p();
    let k = coefficients(n, p);
    let lambda = std::f64::consts::TAU * freq_hz * sample_s;
    alpha_rad.sin().powi(2) * coning_error_per_update(n, p, &k, lambda) / (n as f64 * sample_s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coefficients_match_the_exact_fractions() {
        // Exact rational solutions of the order conditions (docs/coning.md; computed with Python's
        // fractions): two-sample 2/3 (Miller 1983); N=2,P=1: 11/15, -1/30 (Li et al. 2014 eq. 7 up to the
        // garbled sign/index); N=2,P=2: 323/420, -13/210, 1/140 (Li et al. 2014 Table 1 magnitudes);
        // three-sample 9/20, 27/20.
        let close = |a: &[f64], b: &[f64]| a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-12);
        assert!(coefficients(1, 0).is_empty());
        assert!(close(&coefficients(2, 0), &[2.0 / 3.0]));
        // Order: m = 1-P ..= N-1.
        assert!(close(&coefficients(2, 1), &[-1.0 / 30.0, 11.0 / 15.0]));
        assert!(close(&coefficients(2, 2), &[1.0 / 140.0, -13.0 / 210.0, 323.0 / 420.0]));
        assert!(close(&coefficients(3, 0), &[9.0 / 20.0, 27.0 / 20.0]));
    }

    #[test]
    fn coning_error_has_the_expected_order() {
        // The error per update falls as λ^(2(N+P)+1): halving λ divides it by 2^(2(N+P)+1). (λ small
        // enough for the leading term, large enough that double precision resolves a λ^9 error.)
        for alg in Algorithm::ALL {
            let (n, p) = alg.n_p();
            let k = coefficients(n, p);
            let e1 = coning_error_per_update(n, p, &k, 0.1);
            let e2 = coning_error_per_update(n, p, &k, 0.05);
            let order = (e1 / e2).log2();
            let expected = (2 * (n + p) + 1) as f64;
            assert!((order - expected).abs() < 0.1, "{alg:?}: order {order}, expected {expected}");
        }
    }
}
